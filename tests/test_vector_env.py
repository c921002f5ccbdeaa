"""Vectorised and wrapped use: gym.make_vec (sync and async) and FlattenObservation."""

from __future__ import annotations

import math
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

import hippo_env  # noqa: F401  (registers HippoMaze-v0)


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_make_vec(mode):
    envs = gym.make_vec("HippoMaze-v0", num_envs=2, vectorization_mode=mode, maze="maze1", n_rays=64, max_episode_steps=30)
    try:
        assert envs.num_envs == 2
        assert envs.single_observation_space["ranges"].shape == (64,)
        obs, infos = envs.reset(seed=0)
        assert obs["ranges"].shape == (2, 64) and obs["ranges"].dtype == np.float32
        assert obs["heading"].shape == (2, 2)
        positions = infos["position"]
        assert positions.shape == (2, 2) and positions.dtype == np.float64  # float arrays, not an object array of tuples
        assert infos["goal"].shape == (2, 2) and infos["goal"].dtype == np.float64
        # Each sub-env gets its own seed: different starts.
        assert not np.array_equal(positions[0], positions[1])
        envs.action_space.seed(0)
        saw_truncation = False
        for _ in range(35):
            obs, rewards, terminated, truncated, infos = envs.step(envs.action_space.sample())
            assert envs.observation_space.contains(obs)
            assert rewards.shape == (2,) and terminated.shape == (2,) and truncated.shape == (2,)
            assert infos["collision"].shape == (2,)
            if truncated.any():
                saw_truncation = True
                ended = truncated | terminated
                assert np.all(np.isfinite(infos["indirectness"][ended]))  # EpisodeEndInfo applies inside make_vec
        assert saw_truncation
    finally:
        envs.close()


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_make_vec_with_its_defaults_survives_resets(mode):
    """Issue 20: ``gym.make_vec`` with its defaults, then ``reset``, killed the interpreter. In a
    fresh process, so that a crash fails this test instead of pytest."""
    code = """
import sys
import gymnasium as gym, hippo_env
envs = gym.make_vec("HippoMaze-v0", num_envs=2, vectorization_mode=sys.argv[1])
envs.reset(seed=0)
for k in range(4):
    envs.step(envs.action_space.sample())
    envs.reset(seed=k, options={"start": [-1.0 + 0.5 * k, 2.0], "heading": 0.3 * k})
envs.close()
print("ok")
"""
    done = subprocess.run([sys.executable, "-c", code, mode], capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0 and done.stdout.strip() == "ok", f"exit code {done.returncode}\nstderr:\n{done.stderr[-4000:]}"


def test_make_vec_is_reproducible():
    runs = []
    for _ in range(2):
        envs = gym.make_vec("HippoMaze-v0", num_envs=2, vectorization_mode="sync", maze="maze2", n_rays=16)
        obs, _ = envs.reset(seed=42)
        envs.action_space.seed(42)
        for _ in range(20):
            obs, *_ = envs.step(envs.action_space.sample())
        runs.append(obs["ranges"])
        envs.close()
    np.testing.assert_array_equal(runs[0], runs[1])


def test_make_vec_async_matches_sync():
    results = {}
    for mode in ("sync", "async"):
        envs = gym.make_vec("HippoMaze-v0", num_envs=2, vectorization_mode=mode, maze="maze4", n_rays=16, action_type="wheels")
        try:
            obs, _ = envs.reset(seed=7)
            actions = np.random.default_rng(0).uniform(-1, 1, (15, 2, 2)).astype(np.float32)
            for a in actions:
                obs, *_ = envs.step(a)
            results[mode] = obs["ranges"]
        finally:
            envs.close()
    np.testing.assert_array_equal(results["sync"], results["async"])


@pytest.mark.parametrize("action_type", ["discrete", "wheels"])
def test_flatten_observation(action_type):
    env = gym.wrappers.FlattenObservation(gym.make("HippoMaze-v0", maze="maze3", n_rays=90, action_type=action_type))
    assert env.observation_space.shape == (92,)
    obs, _info = env.reset(seed=0)
    assert obs.shape == (92,) and env.observation_space.contains(obs)
    for _ in range(10):
        obs, *_ = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs)
    # gymnasium flattens a Dict in key order: heading (cos, sin), then the ranges.
    np.testing.assert_allclose(obs[:2], [math.cos(env.unwrapped.world.heading), math.sin(env.unwrapped.world.heading)], atol=1e-6)
    env.close()


def test_sb3_vec_env():
    from stable_baselines3.common.env_util import make_vec_env

    vec = make_vec_env("HippoMaze-v0", n_envs=2, seed=0, env_kwargs={"maze": "open", "n_rays": 32})
    obs = vec.reset()
    assert obs["ranges"].shape == (2, 32)
    obs, _rewards, _dones, infos = vec.step(np.array([0, 4]))
    assert len(infos) == 2 and "position" in infos[0]
    vec.close()


def test_info_points_are_float_arrays():
    env = gym.make("HippoMaze-v0", maze="maze1", n_rays=16)
    _, info = env.reset(seed=0)
    for key in ("position", "goal"):
        assert isinstance(info[key], np.ndarray) and info[key].shape == (2,) and info[key].dtype == np.float64
    _, _, _, _, info = env.step(0)
    np.testing.assert_allclose(info["position"], env.unwrapped.world.position)
    info["position"][0] = 99.0  # a copy: the caller may keep or change it
    assert env.unwrapped.world.position[0] != 99.0
    _, info = env.reset(options={"goal": None})
    assert info["goal"].dtype == np.float64 and np.isnan(info["goal"]).all()
    env.close()
