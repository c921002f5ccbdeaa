"""Gymnasium's and Stable-Baselines3's environment checkers pass for every maze and action type."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import hippo_env
from hippo_env import HippoMazeEnv

ACTION_TYPES = ["discrete", "heading", "heading_normalized", "wheels"]


@pytest.mark.parametrize("action_type", ACTION_TYPES)
@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
def test_gymnasium_check_env(maze, action_type):
    env = HippoMazeEnv(maze=maze, action_type=action_type, render_mode="rgb_array")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # e.g. "use a symmetric, normalised Box" for heading
        gym_check_env(env)
    env.close()


@pytest.mark.parametrize("action_type", ACTION_TYPES)
@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
def test_sb3_check_env(maze, action_type):
    env = HippoMazeEnv(maze=maze, action_type=action_type)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        sb3_check_env(env, warn=True)
    env.close()


def test_gymnasium_check_env_with_spec(monkeypatch):
    """Through gym.make the checker also builds the env in every declared render mode (human included)."""
    monkeypatch.setattr(hippo_env.render, "check_human_display", lambda: None)  # as if a display were there
    env = gym.make("HippoMaze-v0", maze="maze1", n_rays=64, render_mode="rgb_array")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        gym_check_env(env.unwrapped)
    env.close()


def test_registered():
    assert "HippoMaze-v0" in gym.registry
    spec = gym.spec("HippoMaze-v0")
    assert spec.max_episode_steps == 10_000
    env = gym.make("HippoMaze-v0")
    assert isinstance(env.unwrapped, HippoMazeEnv)
    assert type(env).__name__ == "EpisodeEndInfo"
    assert env.unwrapped.maze.name == "open" and env.unwrapped.rangefinder.n_rays == 720
    assert env.unwrapped.action_type == "discrete" and env.unwrapped.reward_type == "sparse"
    env.close()


@pytest.mark.parametrize(
    "action_type,space",
    [
        ("discrete", "Discrete(8)"),
        ("heading", "Box(-3.1415927, 3.1415927, (1,), float32)"),
        ("heading_normalized", "Box(-1.0, 1.0, (1,), float32)"),
        ("wheels", "Box(-1.0, 1.0, (2,), float32)"),
    ],
)
def test_spaces(action_type, space):
    env = HippoMazeEnv(n_rays=100, max_range=7.5, action_type=action_type)
    assert str(env.action_space) == space
    obs_space = env.observation_space
    assert set(obs_space.spaces) == {"ranges", "heading"}
    assert obs_space["ranges"].shape == (100,) and obs_space["ranges"].dtype.name == "float32"
    assert float(obs_space["ranges"].low.min()) == 0.0 and float(obs_space["ranges"].high.max()) == 7.5
    assert obs_space["heading"].shape == (2,) and float(obs_space["heading"].low.min()) == -1.0
    obs, _ = env.reset(seed=0)
    assert obs_space.contains(obs)


@pytest.mark.parametrize("action_type", ["discrete", "heading_normalized", "wheels"])
def test_checkers_do_not_warn_for_normalised_spaces(action_type):
    """Only "heading" (kept as it was) draws the checkers' "use a symmetric, normalised Box" warning."""
    env = HippoMazeEnv(maze="maze1", n_rays=32, action_type=action_type)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sb3_check_env(env, warn=True)
    assert not [w for w in caught if "normalized" in str(w.message) or "symmetric" in str(w.message)]
    env.close()


@pytest.mark.parametrize("unit", [-1.0, -0.5, 0.0, 0.25, 0.5, 1.0])
def test_heading_normalized_unit_is_pi_radians(unit):
    """One unit of the normalised heading is pi radians: the same trajectory as "heading" given unit * pi."""
    poses = []
    for action_type, action in (("heading", unit * math.pi), ("heading_normalized", unit)):
        env = HippoMazeEnv(maze="maze1", n_rays=8, action_type=action_type)
        env.reset(seed=3)
        for _ in range(3):
            env.step(np.array([action], np.float32))
        poses.append((*env.world.position, math.cos(env.world.heading), math.sin(env.world.heading)))
        env.close()
    np.testing.assert_allclose(poses[0], poses[1], atol=1e-6)


def test_heading_normalized_outside_its_box_is_a_clear_error():
    env = HippoMazeEnv(maze="open", n_rays=8, action_type="heading_normalized")
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"heading in units of pi radians\] with values in \[-1, 1\]"):
        env.step(np.array([1.5], np.float32))
    env.close()
