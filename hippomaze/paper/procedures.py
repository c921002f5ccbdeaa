"""The procedures the experiments are built from: the environment and the agent, an aimless roam
over which maps are sampled, goal-free exploration, a scripted drive, replay at a chosen goal,
and navigation runs with the inferred map."""

from __future__ import annotations

import copy
import math
from typing import Any

import gymnasium as gym
import numpy as np

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_agent import AgentConfig, HippocampalAgent
from hippo_env.dmtp import rollout
from hippo_env.env import maze_env
from hippo_env.geometry import wrap_angle

from .results import NavRun


def make_agent(observation_space: Any, action_space: Any, seed: int | None = None, config: AgentConfig | None = None) -> HippocampalAgent:
    """The agent factory ``run_dmtp`` calls."""
    return HippocampalAgent(observation_space, action_space, config=config, seed=seed)


def make_env(maze: str, **kwargs: Any) -> gym.Env:
    """The environment with the odometry sensor (the paper's model ignores it; nothing else changes)."""
    return gym.make("HippoMaze-v0", maze=maze, odometry=True, **kwargs)


def roam(maze: str, steps: int, seed: int, legs: int = 16) -> np.ndarray:
    """Positions of an aimless walk (no agent is stepped, so nothing learns).

    ``legs`` walks from random starts, each of straight segments of 5-10 steps with N(0, 30 deg)
    turns between them and a random new heading after a bump: the agent's own exploration
    statistics (model-figures), driven by heading actions.
    """
    env = make_env(maze, action_type="heading")
    rng = np.random.default_rng(seed)
    env.reset(seed=int(seed), options={"goal": None})
    positions = []
    per_leg = max(1, math.ceil(steps / legs))
    for _ in range(legs):
        _, info = env.reset(options={"goal": None})
        heading, left = float(info["heading"]), int(rng.integers(5, 11))
        positions.append(info["position"])
        for _ in range(per_leg):
            if left <= 0:
                heading += rng.normal(0.0, math.radians(30.0))
                left = int(rng.integers(5, 11))
            heading = wrap_angle(heading)
            _, _, _, truncated, info = env.step(np.array([heading], np.float32))
            positions.append(info["position"])
            left -= 1
            if info["collision"]:
                heading, left = float(rng.uniform(-math.pi, math.pi)), int(rng.integers(5, 11))
            if truncated:
                break
    env.close()
    return np.asarray(positions, dtype=float)[:steps]


class ScriptedDriver:
    """Drives the robot along waypoints while the agent learns from what it senses.

    Follows the Agent protocol: ``reset`` and ``observe`` go to the agent unchanged (so it learns
    exactly as on its own walks: eq. 5 and eq. 7 in ``observe``), only ``act`` is replaced by the
    script, which (as the experimenter) reads the robot's position from ``info``.
    """

    def __init__(self, agent: HippocampalAgent, waypoints: Any, tolerance: float = 0.08) -> None:
        self.agent, self.waypoints, self.tolerance = agent, [np.asarray(w, float) for w in waypoints], tolerance
        self.target, self.position = 1, self.waypoints[0]

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        self.position = np.asarray(info["position"], float)
        self.agent.reset(observation, info)

    def done(self) -> bool:
        while self.target < len(self.waypoints) and np.linalg.norm(self.waypoints[self.target] - self.position) < self.tolerance:
            self.target += 1
        return self.target >= len(self.waypoints)

    def act(self, observation: Any) -> int:
        dx, dy = self.waypoints[self.target] - self.position
        return round(math.atan2(dy, dx) / (math.pi / 4)) % 8

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        self.position = np.asarray(info["position"], float)
        self.agent.observe(action, observation, reward, terminated, truncated, info)


def explore_without_goal(env: gym.Env, agent: HippocampalAgent, steps: int) -> np.ndarray:
    """The agent explores on its own with no goal anywhere (learning on); returns the path."""
    obs, info = env.reset(options={"goal": None})
    agent.reset(obs, info)
    path = [maze_env(env).path[:1]]
    remaining = steps
    while remaining > 0:
        end = rollout(env, agent, obs, max_steps=remaining)
        remaining -= end.steps
        path.append(maze_env(env).path[-end.steps :])
        obs = end.observation
        if end.terminated or end.truncated:
            obs, info = env.reset(options={"goal": None})
            agent.reset(obs, info)
    return np.concatenate(path).astype(float)


def drive_scripted(env: gym.Env, agent: HippocampalAgent, waypoints: Any) -> np.ndarray:
    """Drive along ``waypoints`` once while the agent learns; returns the path."""
    start, nxt = np.asarray(waypoints[0], float), np.asarray(waypoints[1], float)
    heading = math.atan2(*(nxt - start)[::-1])
    obs, info = env.reset(options={"goal": None, "start": start, "heading": heading})
    driver = ScriptedDriver(agent, waypoints)
    driver.reset(obs, info)
    limit = int(sum(np.linalg.norm(np.diff(np.asarray(waypoints, float), axis=0), axis=1)) / 0.1) + 50
    rollout(env, driver, obs, max_steps=limit, keep_going=lambda: not driver.done())
    return np.asarray(maze_env(env).path, float)


def replay_at(agent: HippocampalAgent, env: gym.Env, goal: Any) -> bool:
    """Put the reward at ``goal`` with no further exploration: a new reward cell, the place cells
    set to their steady-state rates there, then the agent's backward replay (Algorithm 1).

    The agent has no public way to set its place-cell state, so this writes ``agent.place.v``
    (the one attribute touched); everything else is the agent's public API.
    """
    agent.start_trial(agent.trial + 1)
    goal = np.asarray(goal, float)  # (with path integration: as if localised at the goal)
    where = None if agent.pi is None else goal - agent.frame_offset(env)  # (in the agent's own frame)
    agent.place.v = agent.place_rates_at(maze_env(env).observation_at(goal), pi_position=where)
    return agent.learn_reward()


def navigate(agent: HippocampalAgent, env: gym.Env, goal: Any, runs: int, seed: int) -> list[NavRun]:
    """Runs from random starts toward ``goal`` with the inferred map (each run from a copy of the
    agent as it was after the replay, so runs do not learn from each other)."""
    env.reset(seed=seed, options={"goal": [float(goal[0]), float(goal[1])]})
    out = []
    for _ in range(runs):
        runner = copy.deepcopy(agent)
        obs, info = env.reset()
        runner.reset(obs, info)
        info = rollout(env, runner, obs).info
        out.append(
            NavRun(
                success=bool(info["is_success"]), indirectness=float(info.get("indirectness", math.nan)), steps=len(maze_env(env).path) - 1
            )
        )
    return out
