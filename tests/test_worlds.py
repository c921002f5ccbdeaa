"""Several worlds (:mod:`hippo_agent.faculties.worlds`): each keeps its own map and memories, the
agent tells a known world from a new one by a glimpse of its first steps, and a known world needs
no second dry run; what it keeps is saved and loaded."""

from __future__ import annotations

import numpy as np
import pytest
from agent_helpers import make_env

from hippo_agent import AgentConfig, HippocampalAgent

CONFIG = AgentConfig().with_values({"model.n_place": 300})


@pytest.fixture(scope="module")
def two_worlds():
    """An agent that has learnt maze1 (a dry run and a goal), then was offered a dry run in maze3."""
    env = make_env("maze1", seed=0)
    agent = HippocampalAgent(env.observation_space, env.action_space, CONFIG, seed=0)
    agent.dry_run(env)
    agent.start_trial(0)
    agent.homing.remember(np.array([1.0, 2.0]))
    maze1_map = agent.map.hits.copy()
    env.reset(options={"maze": "maze3", "goal": None})
    before = agent.total_steps
    agent.dry_run(env)
    return env, agent, maze1_map, agent.total_steps - before


def test_a_world_never_seen_gets_a_new_map_and_a_dry_run(two_worlds):
    _, agent, maze1_map, steps = two_worlds
    worlds = agent.worlds
    assert worlds.count == 2 and worlds.current == 1 and worlds.names == [0]
    assert steps > 500  # a whole dry run in maze3
    assert np.array_equal(worlds.kept[0]["map.hits"], maze1_map)  # maze1's map kept as it was
    assert not np.array_equal(agent.map.hits, maze1_map)
    assert agent.homing.remembered() is None and agent.model.reward.n == 0  # maze3's memories start empty
    assert worlds.last_fits[0] < worlds.config.known_fit


def test_a_known_world_is_recognised_and_needs_no_dry_run(two_worlds):
    env, agent, maze1_map, _ = two_worlds
    env.reset(options={"maze": "maze1", "goal": None})
    before = agent.total_steps
    agent.dry_run(env)
    assert agent.worlds.current == 0 and agent.total_steps == before  # only the glimpse: no dry-run step learnt
    assert np.array_equal(agent.map.hits, maze1_map)
    assert np.allclose(agent.homing.remembered(), [1.0, 2.0])  # maze1's goal memory is back
    assert agent.worlds.names == [1]  # maze3 kept in turn


def test_a_run_begun_in_another_known_world_moves_there_after_the_glimpse(two_worlds):
    env, agent, _, _ = two_worlds
    current = agent.worlds.current
    other = 1 - current
    obs, info = env.reset(options={"maze": "maze3" if other == 1 else "maze1", "goal": [0.0, 0.0]})
    agent.reset(obs, info)
    for _ in range(agent.worlds.config.glimpse_steps):
        action = agent.act(obs)
        obs, _, _, _, info = env.step(action)
        agent.observe(action, obs, 0.0, False, False, info)
    assert agent.worlds.current == other and not agent.worlds.glimpse


def test_kept_worlds_are_saved_and_loaded(two_worlds, tmp_path):
    _, agent, _, _ = two_worlds
    agent.save(tmp_path / "agent.npz")
    loaded = HippocampalAgent.load(tmp_path / "agent.npz")
    assert loaded.worlds.current == agent.worlds.current and loaded.worlds.names == agent.worlds.names
    for kept, original in zip(loaded.worlds.kept, agent.worlds.kept):
        assert kept.keys() == original.keys() and all(np.array_equal(kept[k], original[k]) for k in kept)


def test_worlds_off_writes_the_second_dry_run_over_the_first():
    env = make_env("maze1", seed=0)
    agent = HippocampalAgent(env.observation_space, env.action_space, CONFIG.with_values({"worlds": None}), seed=0)
    agent.dry_run(env)
    area = agent.map.explored_area()
    env.reset(options={"maze": "maze3", "goal": None})
    agent.dry_run(env)
    assert agent.worlds is None and agent.map.explored_area() >= area  # one map holds both


def test_a_file_saved_before_worlds_and_map_revision_still_loads(tmp_path):
    """A version-5 file without the worlds' state and the map's change grids loads as one world."""
    import json

    env = make_env("open", seed=0)
    agent = HippocampalAgent(env.observation_space, env.action_space, CONFIG.with_values({"model.dry_run_steps": 200}), seed=0)
    agent.dry_run(env)
    agent.save(tmp_path / "new.npz")
    with np.load(tmp_path / "new.npz") as data:
        arrays = {k: data[k] for k in data.files if not k.startswith("worlds.") and k not in ("map.change", "map.new_walls")}
    meta = json.loads(str(arrays["__meta__"]))
    del meta["parts"]["worlds"]
    arrays["__meta__"] = np.array(json.dumps(meta))
    np.savez_compressed(tmp_path / "old.npz", **arrays)
    loaded = HippocampalAgent.load(tmp_path / "old.npz")
    assert loaded.worlds.kept == [] and not loaded.map.new_walls.any() and np.array_equal(loaded.map.hits, agent.map.hits)
