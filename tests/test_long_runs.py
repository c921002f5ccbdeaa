"""Long runs: what the environment records per run is bounded (a goal-free run may last any number of steps)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_env.path_record import PathRecord


def test_path_keeps_at_most_path_limit_latest_positions():
    env = gym.make("HippoMaze-v0", maze="maze2", n_rays=8, path_limit=50, max_episode_steps=None)
    env.reset(seed=0, options={"goal": None})
    positions = [env.unwrapped.world.position]
    for k in range(120):
        _, _, _, _, info = env.step(k % 8)
        positions.append(tuple(info["position"]))
    path = env.unwrapped.path
    assert path.shape == (50, 2)
    np.testing.assert_array_equal(path, np.asarray(positions[-50:]))
    assert env.unwrapped._path.total == 121
    assert env.unwrapped._path.array().nbytes == 50 * 16
    env.close()


def test_path_is_complete_for_runs_within_the_limit():
    env = gym.make("HippoMaze-v0", maze="maze1", n_rays=8, max_episode_steps=30)
    _, info = env.reset(seed=1)
    positions = [tuple(info["position"])]
    for _ in range(30):
        _, _, terminated, truncated, info = env.step(3)
        positions.append(tuple(info["position"]))
        if terminated or truncated:
            break
    np.testing.assert_array_equal(env.unwrapped.path, np.asarray(positions))
    path = env.unwrapped.path
    path[0] = 99.0  # a copy: changing it changes nothing
    assert env.unwrapped.path[0, 0] != 99.0
    env.reset()
    assert env.unwrapped.path.shape == (1, 2)
    env.close()


def test_memory_of_a_long_goal_free_run_is_bounded():
    """Before: a list of tuples growing by ~100 bytes a step, without limit."""
    record = PathRecord(limit=1000)
    record.reset((0.0, 0.0))
    for k in range(20_000):
        record.append((k * 1e-3, -k * 1e-3))
    assert len(record) == 1000 and record._data.shape == (1000, 2)
    assert record[-1] == (19_999e-3, -19_999e-3) and record[0] == (19_000e-3, -19_000e-3)
    np.testing.assert_allclose(record.array()[:, 0], np.arange(19_000, 20_000) * 1e-3)


def test_unbounded_when_asked():
    record = PathRecord(limit=None)
    record.reset((0.0, 0.0))
    for k in range(3000):
        record.append((float(k), 0.0))
    assert len(record) == 3001 and record.array()[-1, 0] == 2999.0


@pytest.mark.parametrize("bad,error", [(0, ValueError), (-5, ValueError), (2.5, TypeError), (True, TypeError), ("10", TypeError)])
def test_bad_path_limit_is_a_clear_error(bad, error):
    with pytest.raises(error, match="path_limit must be a positive integer"):
        gym.make("HippoMaze-v0", path_limit=bad)
