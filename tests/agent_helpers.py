"""What the HippocampalAgent tests share: spaces, environments, driving a run, an agent that has found a goal."""

from __future__ import annotations

import json
from typing import Any

import gymnasium as gym
import numpy as np

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_agent import AgentConfig, HippocampalAgent, ModelConfig

SMALL = AgentConfig(model=ModelConfig(n_place=300, dry_run_steps=1500))

DISCRETE = gym.spaces.Discrete(8)
HEADING = gym.spaces.Box(-np.pi, np.pi, (1,), np.float32)


def obs_space(n_rays: int = 720, max_range: float = 10.0, odometry: bool = True) -> gym.spaces.Dict:
    spaces = {
        "ranges": gym.spaces.Box(0.0, max_range, (n_rays,), np.float32),
        "heading": gym.spaces.Box(-1.0, 1.0, (2,), np.float32),
    }
    if odometry:
        spaces["odometry"] = gym.spaces.Box(-0.3, 0.3, (2,), np.float32)
    return gym.spaces.Dict(spaces)


def make_env(maze: Any = "open", action_type: str = "discrete", seed: int = 0, **kw: Any) -> gym.Env:
    kw.setdefault("odometry", True)
    env = gym.make("HippoMaze-v0", maze=maze, n_rays=720, max_range=10.0, action_type=action_type, **kw)
    env.reset(seed=seed)
    return env


def drive_run(env, agent, options=None, max_steps=10_000):
    """Reset ``env`` and ``agent`` for a run and drive it to its end; the last info, the positions and the actions."""
    obs, info = env.reset(options=options)
    agent.reset(obs, info)
    positions, actions = [info["position"]], []
    for _ in range(max_steps):
        action = agent.act(obs)
        actions.append(action)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        positions.append(info["position"])
        if terminated or truncated:
            break
    return info, np.array(positions), actions


def finish_run(env, agent, obs, max_steps):
    """Drive an agent already reset for a run to its end; returns the last info and the
    decision behind each step (``agent.last_decision``)."""
    decisions, info = [], {}
    for _ in range(max_steps):
        action = agent.act(obs)
        decisions.append(agent.last_decision)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        if terminated or truncated:
            break
    return info, decisions


def found_the_goal(maze, values: dict[str, Any] | None = None):
    """A default agent (changed by ``values``, dotted names) after a 1,500-step dry run and a run 1
    that found the goal at (1.2, 1.2)."""
    env = make_env(maze, seed=1)
    config = AgentConfig().with_values({"model.dry_run_steps": 1500, **(values or {})})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    info, _, _ = drive_run(env, agent, options={"goal": [1.2, 1.2], "start": [-1.3, -1.3], "heading": 0.0})
    assert info["is_success"]
    return env, agent


def ring_scan(n_rays: int = 720, radius: float = 2.0) -> np.ndarray:
    """What a robot at the centre of a round room of ``radius`` sees."""
    return np.full(n_rays, radius, dtype=np.float32)


def same_state(a: tuple[dict, dict], b: tuple[dict, dict]) -> None:
    """Two ``state()`` results are equal: the JSON-able part, and every array (values, shape and dtype)."""
    (meta_a, arrays_a), (meta_b, arrays_b) = a, b
    assert json.loads(json.dumps(meta_a)) == json.loads(json.dumps(meta_b))
    assert set(arrays_a) == set(arrays_b)
    for name in arrays_a:
        x, y = np.asarray(arrays_a[name]), np.asarray(arrays_b[name])
        assert x.dtype == y.dtype and x.shape == y.shape, name
        np.testing.assert_array_equal(x, y, err_msg=name)
