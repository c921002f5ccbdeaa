"""The DMTP runner and the Agent protocol: well-formed records, reproducibility, step counting,
dry-run rules and agent loading."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hippomaze.baselines import RandomAgent

from hippo_env.dmtp import DMTPFailed, DMTPResult, run_dmtp
from hippomaze.registry import load_agent

RUN_KEYS = {"trial", "run", "steps", "success", "path_length", "shortest_path_length", "indirectness", "start", "goal"}
# The documented keys, and those that reproduce the run.
RECORD_KEYS = {"maze", "agent", "seed", "trials", "runs", "env_steps_total", "dry_run_steps", "episodes"} | {
    "max_episode_steps", "action_type", "env_kwargs", "agent_spec", "agent_config", "versions",
}  # fmt: skip
TINY = {"trials": 2, "runs": 2, "max_episode_steps": 200, "progress": False, "env_kwargs": {"n_rays": 32}}


class DryRunningAgent(RandomAgent):
    """A random agent whose dry run takes exactly ``DRY_RUN_STEPS`` steps (with a reset midway)."""

    DRY_RUN_STEPS = 37

    def __init__(self, observation_space, action_space, seed=None):
        super().__init__(observation_space, action_space, seed=seed)
        self.dry_run_goals = []

    def dry_run(self, env):
        _, info = env.reset()
        self.dry_run_goals.append(info["goal"])
        for k in range(self.DRY_RUN_STEPS):
            if k == 20:
                env.reset(options={"goal": None})  # allowed: still goal-free
            _, _, terminated, _, info = env.step(self.act(None))
            assert not terminated and math.isnan(info["goal"][0])


class GoalPlacingAgent(RandomAgent):
    def dry_run(self, env):
        env.reset(options={"goal": [1.0, 1.0]})


class NewGoalAgent(RandomAgent):
    def dry_run(self, env):
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
    assert set(record) == RECORD_KEYS
    assert (record["maze"], record["agent"], record["seed"], record["trials"], record["runs"]) == ("maze1", "random", 3, 2, 2)
    runs = record["episodes"]
    assert [(r["trial"], r["run"]) for r in runs] == [(0, 0), (0, 1), (1, 0), (1, 1)]
    for r in runs:
        assert set(r) == RUN_KEYS
        assert isinstance(r["steps"], int) and 1 <= r["steps"] <= 200
        assert isinstance(r["success"], bool)
        assert r["success"] or r["steps"] == 200
        assert len(r["start"]) == 2 and len(r["goal"]) == 2
        assert math.dist(r["start"], r["goal"]) >= 1.0
        assert 0 < r["shortest_path_length"] and 0 <= r["path_length"] <= r["steps"] * 0.15 + 1e-9
        assert r["indirectness"] == pytest.approx((r["path_length"] - r["shortest_path_length"]) / r["shortest_path_length"])
    # The goal is the same within a trial and moves between trials.
    assert runs[0]["goal"] == runs[1]["goal"] != runs[2]["goal"] == runs[3]["goal"]
    assert record["env_steps_total"] == sum(r["steps"] for r in runs)
    # Paths: one (steps + 1, 2) array per run, starting at the start.
    for r in runs:
        path = result.paths[r["trial"]][r["run"]]
        assert path.shape == (r["steps"] + 1, 2)
        np.testing.assert_allclose(path[0], r["start"])
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
    runs = result.to_dict()["episodes"]
    assert runs[0]["start"] == runs[1]["start"] and runs[2]["start"] == runs[3]["start"]


@pytest.mark.parametrize("fresh", [True, False])
def test_env_steps_total_counts_the_dry_run(fresh):
    agents = []

    def make(observation_space, action_space, seed=None):
        agents.append(DryRunningAgent(observation_space, action_space, seed=seed))
        return agents[-1]

    result = run_dmtp(make, maze="open", seed=1, fresh_agent_per_trial=fresh, **TINY)
    dry_runs = 2 if fresh else 1
    assert len(agents) == dry_runs
    assert all(math.isnan(g[0]) for a in agents for g in a.dry_run_goals)  # no goal during the dry run
    run_steps = sum(r.steps for r in result.run_records)
    assert result.env_steps_total == dry_runs * DryRunningAgent.DRY_RUN_STEPS + run_steps


@pytest.mark.parametrize("agent", [GoalPlacingAgent, NewGoalAgent])
def test_placing_a_goal_during_the_dry_run_is_refused(agent):
    with pytest.raises(DMTPFailed, match="may not place a goal during its dry run") as failed:
        run_dmtp(agent, maze="open", seed=0, **TINY)
    assert isinstance(failed.value.__cause__, ValueError)


def test_agent_missing_methods_is_refused():
    with pytest.raises(DMTPFailed, match="NotAnAgent does not follow the Agent protocol: it lacks reset, observe") as failed:
        run_dmtp(lambda o, a, seed=None: NotAnAgent(), maze="open", seed=0, **TINY)
    assert isinstance(failed.value.__cause__, TypeError)


@pytest.mark.parametrize("value,error", [(0, ValueError), (-1, ValueError), (1.5, TypeError), ("2", TypeError)])
def test_bad_trials_or_runs(value, error):
    with pytest.raises(error, match="trials must be a positive integer"):
        run_dmtp(RandomAgent, trials=value, runs=1, progress=False)
    with pytest.raises(error, match="runs must be a positive integer"):
        run_dmtp(RandomAgent, trials=1, runs=value, progress=False)


def test_load_agent():
    assert load_agent("hippomaze.baselines:RandomAgent") is RandomAgent
    assert load_agent("hippomaze.baselines.random_agent:RandomAgent") is RandomAgent
    with pytest.raises(ValueError, match="agent 'greedy' is unknown; give hippo, random, dqn, ppo, or module:Class"):
        load_agent("greedy")
    with pytest.raises(ValueError, match="cannot import module 'no_such_module_xyz'"):
        load_agent("no_such_module_xyz:Agent")
    with pytest.raises(ValueError, match="module 'hippomaze.baselines' has no attribute 'Nope'"):
        load_agent("hippomaze.baselines:Nope")
    with pytest.raises(TypeError, match="does not follow the Agent protocol: it lacks reset, act, observe"):
        load_agent("json:JSONDecoder")


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
    assert [r.steps for r in result.run_records] == [5, 5]
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
    assert result.run_records[0].steps == 5
    with pytest.raises(ValueError, match="agent 'broken' .*did not load"):
        registry.agent_factory("broken")
    with pytest.raises(ValueError, match="one registered by an installed package \\(broken, mine\\)"):
        registry.agent_factory("nobody")
