"""The DMTP runner and the Agent protocol: well-formed records, reproducibility, step counting,
pre-exploration rules and agent loading."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hippomaze.baselines import RandomAgent

from hippo_env.dmtp import DMTPResult, run_dmtp
from hippomaze.registry import load_agent_class

EPISODE_KEYS = {"trial", "run", "steps", "success", "path_length", "shortest_path_length", "indirectness", "start", "goal"}
TINY = {"trials": 2, "runs": 2, "max_episode_steps": 200, "progress": False, "env_kwargs": {"n_rays": 32}}


class PreparingAgent(RandomAgent):
    """A random agent whose pre-exploration takes exactly ``PREPARE_STEPS`` steps (with a reset midway)."""

    PREPARE_STEPS = 37

    def __init__(self, observation_space, action_space, seed=None):
        super().__init__(observation_space, action_space, seed=seed)
        self.prepared_goals = []

    def prepare(self, env):
        _, info = env.reset()
        self.prepared_goals.append(info["goal"])
        for k in range(self.PREPARE_STEPS):
            if k == 20:
                env.reset(options={"goal": None})  # allowed: still goal-free
            _, _, terminated, _, info = env.step(self.act(None))
            assert not terminated and math.isnan(info["goal"][0])


class GoalPlacingAgent(RandomAgent):
    def prepare(self, env):
        env.reset(options={"goal": [1.0, 1.0]})


class NewGoalAgent(RandomAgent):
    def prepare(self, env):
        env.reset(options={"new_goal": True})


class NotAnAgent:
    def act(self, observation):
        return 0


@pytest.fixture(scope="module")
def random_result():
    return run_dmtp(RandomAgent, maze="maze1", seed=3, agent_name="random", **TINY)


def test_records_are_complete_and_well_formed(random_result, tmp_path):
    result = random_result
    assert isinstance(result, DMTPResult)
    record = result.to_dict()
    assert set(record) == {"maze", "agent", "seed", "trials", "runs", "env_steps_total", "episodes"}
    assert (record["maze"], record["agent"], record["seed"], record["trials"], record["runs"]) == ("maze1", "random", 3, 2, 2)
    episodes = record["episodes"]
    assert [(e["trial"], e["run"]) for e in episodes] == [(0, 0), (0, 1), (1, 0), (1, 1)]
    for e in episodes:
        assert set(e) == EPISODE_KEYS
        assert isinstance(e["steps"], int) and 1 <= e["steps"] <= 200
        assert isinstance(e["success"], bool)
        assert e["success"] or e["steps"] == 200
        assert len(e["start"]) == 2 and len(e["goal"]) == 2
        assert math.dist(e["start"], e["goal"]) >= 1.0
        assert 0 < e["shortest_path_length"] and 0 <= e["path_length"] <= e["steps"] * 0.15 + 1e-9
        assert e["indirectness"] == pytest.approx((e["path_length"] - e["shortest_path_length"]) / e["shortest_path_length"])
    # The goal is the same within a trial and moves between trials.
    assert episodes[0]["goal"] == episodes[1]["goal"] != episodes[2]["goal"] == episodes[3]["goal"]
    assert record["env_steps_total"] == sum(e["steps"] for e in episodes)
    # Paths: one (steps + 1, 2) array per run, starting at the start.
    for e in episodes:
        path = result.paths[e["trial"]][e["run"]]
        assert path.shape == (e["steps"] + 1, 2)
        np.testing.assert_allclose(path[0], e["start"])
    # Saved as strict JSON (NaN written as null), with the paths alongside.
    saved = result.save(tmp_path)
    assert json.loads(saved.read_text()) == json.loads(json.dumps(record, allow_nan=False))
    with np.load(tmp_path / "paths.npz") as paths:
        assert set(paths.files) == {"trial0_run0", "trial0_run1", "trial1_run0", "trial1_run1"}
    assert result.indirectness().shape == (2, 2) and result.success().shape == (2, 2)
    summary = result.summary()
    assert len(summary["median_indirectness"]) == 2 and len(summary["success_rate"]) == 2


def test_same_seed_same_records(random_result):
    again = run_dmtp(RandomAgent, maze="maze1", seed=3, agent_name="random", **TINY)
    assert again.to_dict() == random_result.to_dict()
    for a, b in zip(again.paths, random_result.paths):
        for p, q in zip(a, b):
            np.testing.assert_array_equal(p, q)
    other = run_dmtp(RandomAgent, maze="maze1", seed=4, agent_name="random", **TINY)
    assert other.to_dict()["episodes"] != random_result.to_dict()["episodes"]


def test_same_start_option():
    result = run_dmtp(RandomAgent, maze="open", seed=0, same_start=True, **TINY)
    episodes = result.to_dict()["episodes"]
    assert episodes[0]["start"] == episodes[1]["start"] and episodes[2]["start"] == episodes[3]["start"]


@pytest.mark.parametrize("fresh", [True, False])
def test_env_steps_total_counts_pre_exploration(fresh):
    agents = []

    def make(observation_space, action_space, seed=None):
        agents.append(PreparingAgent(observation_space, action_space, seed=seed))
        return agents[-1]

    result = run_dmtp(make, maze="open", seed=1, fresh_agent_per_trial=fresh, **TINY)
    preparations = 2 if fresh else 1
    assert len(agents) == preparations
    assert all(math.isnan(g[0]) for a in agents for g in a.prepared_goals)  # no goal during pre-exploration
    run_steps = sum(e.steps for e in result.episodes)
    assert result.env_steps_total == preparations * PreparingAgent.PREPARE_STEPS + run_steps


@pytest.mark.parametrize("agent", [GoalPlacingAgent, NewGoalAgent])
def test_placing_a_goal_during_prepare_is_refused(agent):
    with pytest.raises(ValueError, match="may not place a goal during pre-exploration"):
        run_dmtp(agent, maze="open", seed=0, **TINY)


def test_agent_missing_methods_is_refused():
    with pytest.raises(TypeError, match="NotAnAgent does not follow the Agent protocol: it lacks reset, observe"):
        run_dmtp(lambda o, a, seed=None: NotAnAgent(), maze="open", seed=0, **TINY)


@pytest.mark.parametrize("value", [0, -1, 1.5, "2"])
def test_bad_trials_or_runs(value):
    with pytest.raises(ValueError, match="trials must be a positive integer"):
        run_dmtp(RandomAgent, trials=value, runs=1, progress=False)
    with pytest.raises(ValueError, match="runs must be a positive integer"):
        run_dmtp(RandomAgent, trials=1, runs=value, progress=False)


def test_load_agent_class():
    assert load_agent_class("hippomaze.baselines:RandomAgent") is RandomAgent
    assert load_agent_class("hippomaze.baselines.random_agent:RandomAgent") is RandomAgent
    with pytest.raises(ValueError, match="agent 'greedy' is unknown; give hippo, random, dqn, ppo, or module:Class"):
        load_agent_class("greedy")
    with pytest.raises(ValueError, match="cannot import module 'no_such_module_xyz'"):
        load_agent_class("no_such_module_xyz:Agent")
    with pytest.raises(ValueError, match="module 'hippomaze.baselines' has no attribute 'Nope'"):
        load_agent_class("hippomaze.baselines:Nope")
    with pytest.raises(ValueError, match="does not follow the Agent protocol: it lacks reset, act, observe"):
        load_agent_class("json:JSONDecoder")


def test_agent_base_gives_the_optional_hooks():
    from hippo_env.agent_protocol import Agent, AgentBase

    class Still(AgentBase):
        def reset(self, observation, info):
            self.runs = getattr(self, "runs", 0) + 1

        def act(self, observation):
            return 0

        def observe(self, action, observation, reward, terminated, truncated, info):
            pass

    result = run_dmtp(Still, maze="open", trials=1, runs=2, max_episode_steps=5, progress=False)
    assert [e.steps for e in result.episodes] == [5, 5]
    assert isinstance(Still(None, None), Agent)
    with pytest.raises(NotImplementedError):
        AgentBase(None, None).act(None)


def test_agents_registered_by_entry_point(monkeypatch):
    from importlib.metadata import EntryPoint

    from hippomaze import registry

    points = [
        EntryPoint(name="mine", value="hippomaze.baselines.random_agent:RandomAgent", group=registry.ENTRY_POINT_GROUP),
        EntryPoint(name="broken", value="no_such_module_xyz:Agent", group=registry.ENTRY_POINT_GROUP),
    ]
    monkeypatch.setattr(registry, "entry_points", lambda group: [p for p in points if p.group == group])
    result = run_dmtp(registry.agent_factory("mine"), maze="open", trials=1, runs=1, max_episode_steps=5, progress=False)
    assert result.episodes[0].steps == 5
    with pytest.raises(ValueError, match="agent 'broken' .*did not load"):
        registry.agent_factory("broken")
    with pytest.raises(ValueError, match="one registered by an installed package \\(broken, mine\\)"):
        registry.agent_factory("nobody")
