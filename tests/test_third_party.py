"""What a third party meets: its own agent (a class or a factory) and its environment settings,
the error it gets when its code raises, a record that reproduces its run, and clear errors for
a human window with no display, stepping before reset and a missing optional extra."""

from __future__ import annotations

import dataclasses
import importlib
import json
from typing import Any, ClassVar

import gymnasium as gym
import pytest

import hippo_env
from hippo_env.dmtp import DMTPFailed, agent_config, run_dmtp
from hippomaze import registry
from hippomaze.cli import main

QUICK = ["dmtp", "--trials", "1", "--runs", "1", "--max-steps", "20", "--no-progress", "--no-figures"]


def as_the_cli_loads_it() -> Any:
    """This module as ``--agent tests.test_third_party:...`` imports it (pytest imports it under another name)."""
    return importlib.import_module("tests.test_third_party")


class SensingAgent:
    """Heads east; remembers which observation keys each instance was given."""

    env_kwargs: ClassVar[dict[str, Any]] = {"odometry": True}
    seen: ClassVar[list[list[str]]] = []

    def __init__(self, observation_space, action_space, seed=None):
        type(self).seen.append(sorted(observation_space.spaces))

    def reset(self, observation, info):
        pass

    def act(self, observation):
        return 0

    def observe(self, action, observation, reward, terminated, truncated, info):
        pass


def make_agent(observation_space, action_space, *, seed):
    """A documented AgentFactory: a function, not a class."""
    return SensingAgent(observation_space, action_space, seed=seed)


make_agent.env_kwargs = {"odometry": True, "n_rays": 24}


@dataclasses.dataclass(frozen=True)
class CountingConfig:
    dry_run_steps: int = 13
    label: str = "mine"


class DryRunningAgent(SensingAgent):
    """Takes ``config.dry_run_steps`` goal-free steps before its first trial."""

    env_kwargs: ClassVar[dict[str, Any]] = {}

    def __init__(self, observation_space, action_space, seed=None):
        super().__init__(observation_space, action_space, seed)
        self.config = CountingConfig()

    def dry_run(self, env):
        env.reset()
        for _ in range(self.config.dry_run_steps):
            env.step(3)


class FailingAgent(SensingAgent):
    """Heads east; the third run it starts fails inside its own code."""

    env_kwargs: ClassVar[dict[str, Any]] = {}
    runs_started = 0

    def reset(self, observation, info):
        type(self).runs_started += 1

    def act(self, observation):
        if type(self).runs_started >= 3:
            return self.choose_badly()
        return 0

    def choose_badly(self):
        raise RuntimeError("my agent's bug")


def dmtp_record(out) -> dict:
    return json.loads((out / "dmtp.json").read_text())


# ---------------------------------------------------------------------- 1. agent classes, factories, --env
def test_agent_class_env_kwargs_reach_gym_make(tmp_path):
    agents = as_the_cli_loads_it().SensingAgent
    agents.seen = []
    assert registry.agent_factory("tests.test_third_party:SensingAgent").env_kwargs == {"odometry": True}
    assert main([*QUICK, "--agent", "tests.test_third_party:SensingAgent", "--out", str(tmp_path / "out")]) == 0
    assert agents.seen == [["heading", "odometry", "ranges"]]
    assert dmtp_record(tmp_path / "out")["env_kwargs"]["odometry"] is True


def test_agent_factory_function_by_module_path(tmp_path):
    agents = as_the_cli_loads_it().SensingAgent
    agents.seen = []
    assert main([*QUICK, "--trials", "2", "--agent", "tests.test_third_party:make_agent", "--out", str(tmp_path / "out")]) == 0
    assert agents.seen == [["heading", "odometry", "ranges"]] * 2
    record = dmtp_record(tmp_path / "out")
    assert record["agent"] == record["agent_spec"] == "tests.test_third_party:make_agent"
    assert record["env_kwargs"] == {"odometry": True, "n_rays": 24, "max_episode_steps": 20}
    assert len(record["episodes"]) == 2


def test_env_option_values_are_json_and_override_the_agents(tmp_path):
    agents = as_the_cli_loads_it().SensingAgent
    agents.seen = []
    args = ["--env", "odometry=false", "--env", "n_rays=32", "--env", "range_noise=0.01", "--env", "reward_type=dense"]
    assert main([*QUICK, "--agent", "tests.test_third_party:SensingAgent", *args, "--out", str(tmp_path / "out")]) == 0
    assert agents.seen == [["heading", "ranges"]]  # --env odometry=false won over the agent's odometry=True
    record = dmtp_record(tmp_path / "out")
    assert record["env_kwargs"] == {"odometry": False, "n_rays": 32, "range_noise": 0.01, "reward_type": "dense", "max_episode_steps": 20}
    from hippomaze.cli import _env_argument

    assert _env_argument("goal=[1, 2]") == ("goal", [1, 2])
    assert _env_argument("render_mode=rgb_array") == ("render_mode", "rgb_array")


@pytest.mark.parametrize("bad", ["n_rays", "=3", "n rays=3"])
def test_bad_env_option_is_an_argparse_error(bad, capsys):
    with pytest.raises(SystemExit) as exit_:
        main([*QUICK, "--env", bad])
    assert exit_.value.code == 2
    assert (
        f"argument --env: must be KEY=VALUE with KEY an argument name, e.g. n_rays=360 or odometry=true; got {bad!r}"
        in capsys.readouterr().err
    )


def test_unknown_env_option_is_a_one_line_error(tmp_path, capsys):
    assert main([*QUICK, "--agent", "random", "--env", "n_rayz=32", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "HippoMaze-v0 takes no argument(s) n_rayz; allowed: n_rays" in err


# ---------------------------------------------------------------------- 2. an exception in the user's agent
def test_agent_exception_prints_its_traceback_and_saves_the_finished_runs(tmp_path, capsys):
    as_the_cli_loads_it().FailingAgent.runs_started = 0
    out = tmp_path / "out"
    code = main([*QUICK, "--trials", "3", "--agent", "tests.test_third_party:FailingAgent", "--max-steps", "15", "--out", str(out)])
    assert code == 1
    err = capsys.readouterr().err
    assert err.startswith("Traceback (most recent call last):")
    assert "test_third_party.py" in err and "in choose_badly" in err and "RuntimeError: my agent's bug" in err
    assert err.strip().splitlines()[-1] == (
        f"hippomaze: error: RuntimeError: my agent's bug (trial 3, run 1); saved the 2 finished runs of 3 to {out / 'dmtp.json'} "
        '(marked "complete": false)'
    )
    record = dmtp_record(out)
    assert record["complete"] is False and record["error"] == "RuntimeError: my agent's bug"
    assert [e["trial"] for e in record["episodes"]] == [0, 1]


def test_run_dmtp_raises_dmtp_failed_from_the_agents_exception():
    FailingAgent.runs_started = 0
    with pytest.raises(DMTPFailed, match="my agent's bug") as failed:
        run_dmtp(FailingAgent, "open", trials=2, runs=2, max_episode_steps=10, progress=False)
    assert isinstance(failed.value.__cause__, RuntimeError)
    result = failed.value.result
    assert not result.complete and len(result.run_records) == 2 and len(result.paths) == 1
    assert result.to_dict()["error"] == "RuntimeError: my agent's bug"
    assert result.env_steps_total == sum(result.dry_run_steps) + sum(r.steps for r in result.run_records)  # the failing run took none


# ---------------------------------------------------------------------- 3. a record that reproduces the run
def test_record_says_what_reproduces_the_run(tmp_path):
    out = tmp_path / "out"
    args = ["--trials", "2", "--runs", "2", "--agent", "tests.test_third_party:DryRunningAgent", "--action-type", "heading"]
    assert main([*QUICK, *args, "--env", "n_rays=16", "--out", str(out)]) == 0
    record = dmtp_record(out)
    assert record["versions"]["hippomaze"] == hippo_env.__version__  # (the source's, not an editable install's metadata)
    assert record["versions"]["gymnasium"] == gym.__version__
    assert record["max_episode_steps"] == 20 and record["action_type"] == "heading"
    assert record["env_kwargs"] == {"action_type": "heading", "n_rays": 16, "max_episode_steps": 20}
    assert record["agent_spec"] == "tests.test_third_party:DryRunningAgent"
    assert record["agent_config"] == {"dry_run_steps": 13, "label": "mine"}
    assert record["dry_run_steps"] == [13, 13]
    assert record["env_steps_total"] == sum(record["dry_run_steps"]) + sum(e["steps"] for e in record["episodes"])


def test_dry_run_steps_of_an_agent_kept_across_trials():
    result = run_dmtp(DryRunningAgent, "open", trials=3, runs=1, fresh_agent_per_trial=False, max_episode_steps=10, progress=False)
    assert result.dry_run_steps == [13, 0, 0]
    assert result.env_steps_total == 13 + sum(r.steps for r in result.run_records)
    assert result.agent_spec == f"{DryRunningAgent.__module__}:DryRunningAgent"  # what --agent would take


def test_hippocampal_agent_config_is_recorded():
    factory = registry.agent_factory("hippo", **{"model.dry_run_steps": 30, "model.n_place": 50})
    result = run_dmtp(factory, "open", trials=1, runs=1, max_episode_steps=10, agent_name="hippo", progress=False)
    record = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    assert record["agent_config"]["model"]["n_place"] == 50 and record["agent_config"]["model"]["dry_run_steps"] == 30
    assert record["env_kwargs"] == {"odometry": True, "max_episode_steps": 10}
    assert 0 < record["dry_run_steps"][0] <= 30
    assert record["env_steps_total"] == sum(record["dry_run_steps"]) + sum(e["steps"] for e in record["episodes"])
    env = gym.make("HippoMaze-v0", odometry=True)
    agent = factory(env.observation_space, env.action_space, seed=0)
    assert agent_config(agent) == json.loads(json.dumps(dataclasses.asdict(agent.config)))


# ---------------------------------------------------------------------- 4. a human window with no display
def test_human_render_mode_without_a_display_is_a_clear_error(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(RuntimeError, match=r'needs a display .*neither DISPLAY nor WAYLAND_DISPLAY.*render_mode="rgb_array"'):
        gym.make("HippoMaze-v0", render_mode="human")


def test_human_render_mode_with_a_non_interactive_backend_is_a_clear_error(monkeypatch):
    import matplotlib

    monkeypatch.setenv("DISPLAY", ":0")
    monkeypatch.setattr(matplotlib, "get_backend", lambda: "agg")
    with pytest.raises(RuntimeError, match=r"interactive matplotlib backend, but matplotlib uses 'agg'.*render_mode=\"rgb_array\""):
        gym.make("HippoMaze-v0", render_mode="human")


# ---------------------------------------------------------------------- 5. step before reset
@pytest.mark.parametrize("maze", ["maze2", "maze4"])
def test_unwrapped_step_before_reset_is_an_error(maze):
    env = gym.make("HippoMaze-v0", maze=maze, n_rays=16).unwrapped
    with pytest.raises(gym.error.ResetNeeded, match=r"call reset\(\) before step\(\)"):
        env.step(0)
    env.reset(seed=0)
    env.step(0)


# ---------------------------------------------------------------------- 6. the install hint for dqn / ppo
def test_missing_sb3_names_the_pip_extra(monkeypatch, tmp_path, capsys):
    real_find_spec = registry.find_spec
    monkeypatch.setattr(registry, "find_spec", lambda name: None if name == "stable_baselines3" else real_find_spec(name))
    assert main([*QUICK, "--agent", "dqn", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "agent 'dqn' needs torch and stable-baselines3" in err
    assert "pip install torch==2.13.0 && pip install 'hippomaze[baselines]'" in err
    assert "pip install -e .[baselines]" in err  # and the checkout's way
