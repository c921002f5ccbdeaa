"""Envs made alike share their goal: the Stable-Baselines3 pitfall that docs/sb3.md warns of.

The page's example itself runs in tests/test_docs_code.py, with a shortened budget.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import hippo_env  # noqa: F401  (registers HippoMaze-v0)


def test_envs_made_alike_share_their_goal():
    """The SB3 pitfall: a training and an evaluation env made alike must face the same goal."""
    goals = []
    for reset_seed in (0, 1, None):
        env = gym.make("HippoMaze-v0", maze="maze2", n_rays=8, goal_seed=4)
        _, info = env.reset(seed=reset_seed)
        goals.append(info["goal"])
        env.close()
    np.testing.assert_array_equal(goals[0], goals[1])
    np.testing.assert_array_equal(goals[0], goals[2])
    other = gym.make("HippoMaze-v0", maze="maze2", n_rays=8, goal_seed=5)
    assert not np.array_equal(other.reset(seed=0)[1]["goal"], goals[0])
    other.close()


def test_goal_argument_and_its_errors():
    env = gym.make("HippoMaze-v0", maze="maze1", n_rays=8, goal=[3.0, 3.0])
    _, info = env.reset(seed=0)
    np.testing.assert_array_equal(info["goal"], [3.0, 3.0])
    _, info = env.reset(seed=9)  # the goal is held across resets (DMTP) ...
    np.testing.assert_array_equal(info["goal"], [3.0, 3.0])
    _, info = env.reset(options={"new_goal": True})  # ... until moved
    assert not np.array_equal(info["goal"], [3.0, 3.0])
    env.close()
    with pytest.raises(ValueError, match="either goal=\\[x, y\\] or goal_seed=int, not both"):
        gym.make("HippoMaze-v0", goal=[1.0, 1.0], goal_seed=0)
    with pytest.raises(ValueError, match="argument 'goal' \\(-3, 1.5\\) is inside a wall"):
        gym.make("HippoMaze-v0", maze="maze1", goal=[-3.0, 1.5])
    with pytest.raises(ValueError, match="goal_seed must be a non-negative integer"):
        gym.make("HippoMaze-v0", goal_seed=-1)


def test_without_goal_arguments_nothing_changes():
    """The default is as before: the first reset draws the goal with its own seed."""
    a = gym.make("HippoMaze-v0", maze="maze1", n_rays=8)
    b = gym.make("HippoMaze-v0", maze="maze1", n_rays=8)
    assert not np.array_equal(a.reset(seed=0)[1]["goal"], b.reset(seed=1)[1]["goal"])
    np.testing.assert_array_equal(
        a.reset(seed=0, options={"new_goal": True})[1]["goal"], b.reset(seed=0, options={"new_goal": True})[1]["goal"]
    )
    a.close()
    b.close()
