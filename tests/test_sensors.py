"""The rangefinder: exact ranges in known geometry, against brute force, the egocentric convention,
max_range capping and seeded range noise."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import hippo_env
from hippo_env import HippoMazeEnv, MazeSpec
from hippo_env.sensors import Rangefinder

TOL = 1e-3  # 1 mm


def open_room_ranges(position, heading, n_rays, half=5.0, max_range=10.0):
    """Closed form: distance from ``position`` to the walls of the square [-half, half]^2 along each ray."""
    x, y = position
    angles = heading + 2 * np.pi * np.arange(n_rays) / n_rays
    c, s = np.cos(angles), np.sin(angles)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(c > 1e-15, (half - x) / c, np.where(c < -1e-15, (-half - x) / c, np.inf))
        ty = np.where(s > 1e-15, (half - y) / s, np.where(s < -1e-15, (-half - y) / s, np.inf))
    return np.minimum(np.minimum(tx, ty), max_range)


def brute_force_ranges(segments, position, heading, n_rays, max_range=10.0):
    """Every ray against every segment (NumPy), the nearest hit along each ray."""
    angles = heading + 2 * np.pi * np.arange(n_rays) / n_rays
    d = np.stack([np.cos(angles), np.sin(angles)], axis=1)[:, None, :]  # (n, 1, 2)
    a = segments[None, :, :2]  # (1, m, 2)
    e = segments[None, :, 2:] - segments[None, :, :2]
    w = a - np.asarray(position, float)[None, None, :]
    # Solve position + t d = a + u e for (t, u) by Cramer's rule.
    denom = d[..., 0] * (-e[..., 1]) - d[..., 1] * (-e[..., 0])
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t = (w[..., 0] * (-e[..., 1]) - w[..., 1] * (-e[..., 0])) / denom
        u = (d[..., 0] * w[..., 1] - d[..., 1] * w[..., 0]) / denom
    hit = (np.abs(denom) > 1e-15) & (t >= 0) & (u >= -1e-9) & (u <= 1 + 1e-9)
    t = np.where(hit, t, np.inf)
    return np.minimum(t.min(axis=1), max_range)


@pytest.fixture(scope="module")
def specs():
    return {name: MazeSpec.load(name) for name in hippo_env.BUILTIN_MAZES}


@pytest.mark.parametrize("n_rays", [4, 64, 720, 1000])
@pytest.mark.parametrize("pose", [(0.0, 0.0, 0.0), (3.0, -1.0, 0.7), (-4.8, 4.8, -2.5), (1.234, 4.5, math.pi), (-2.0, -3.9, 1e-3)])
def test_open_arena_closed_form(pose, n_rays):
    x, y, heading = pose
    finder = Rangefinder(MazeSpec.load("open").segments, n_rays=n_rays, max_range=10.0)
    ranges = finder.scan((x, y), heading)
    assert ranges.shape == (n_rays,)
    np.testing.assert_allclose(ranges, open_room_ranges((x, y), heading, n_rays), atol=TOL, rtol=0)


def test_egocentric_counter_clockwise():
    """ranges[i] is along heading + 2*pi*i/n: facing +y from (3, 0), ahead is 5 m, left (-x) 8 m, right (+x) 2 m."""
    env = HippoMazeEnv(maze="open", n_rays=8)
    obs, _ = env.reset(seed=0, options={"goal": None, "start": [3.0, 0.0], "heading": math.pi / 2})
    ranges = obs["ranges"]
    assert ranges[0] == pytest.approx(5.0, abs=TOL)  # ahead: +y
    assert ranges[2] == pytest.approx(8.0, abs=TOL)  # 90 deg counter-clockwise: -x
    assert ranges[4] == pytest.approx(5.0, abs=TOL)  # behind: -y
    assert ranges[6] == pytest.approx(2.0, abs=TOL)  # 90 deg clockwise: +x
    assert ranges[1] == pytest.approx(math.hypot(5.0, 5.0), abs=TOL)  # 45 deg CCW of +y: toward (-2, 5), the corner
    assert ranges[7] == pytest.approx(2.0 * math.sqrt(2.0), abs=TOL)  # 45 deg CW of +y: x wall at +2 m
    np.testing.assert_allclose(obs["heading"], [0.0, 1.0], atol=1e-6)


def test_heading_rotates_the_scan():
    """Turning by one ray step shifts the scan by one index (the room does not move)."""
    n = 36
    finder = Rangefinder(MazeSpec.load("maze1").segments, n_rays=n)
    base = finder.scan((0.5, -0.5), 0.3)
    turned = finder.scan((0.5, -0.5), 0.3 + 2 * math.pi / n)
    np.testing.assert_allclose(turned, np.roll(base, -1), atol=1e-9)


@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
def test_brute_force_random_poses(maze, specs):
    spec = specs[maze]
    finder = Rangefinder(spec.segments, n_rays=720, max_range=10.0)
    rng = np.random.default_rng(123)
    for _ in range(20):
        position = spec.sample_free(rng, 0.17)
        heading = rng.uniform(-math.pi, math.pi)
        np.testing.assert_allclose(
            finder.scan(position, heading),
            brute_force_ranges(spec.segments, position, heading, 720),
            atol=TOL,
            rtol=0,
            err_msg=f"{maze} at {position}, heading {heading}",
        )


@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
@settings(max_examples=25, deadline=None)
@given(x=st.floats(-4.99, 4.99), y=st.floats(-4.99, 4.99), heading=st.floats(-math.pi, math.pi), n_rays=st.sampled_from([7, 90, 360]))
def test_brute_force_any_free_point(maze, specs, x, y, heading, n_rays):
    spec = specs[maze]
    if spec.clearance((x, y)) < 1e-3:  # inside or on a wall: not a place a robot can be
        return
    finder = Rangefinder(spec.segments, n_rays=n_rays, max_range=10.0)
    np.testing.assert_allclose(finder.scan((x, y), heading), brute_force_ranges(spec.segments, (x, y), heading, n_rays), atol=TOL, rtol=0)


def test_max_range_caps():
    env = HippoMazeEnv(maze="maze1", n_rays=360, max_range=3.0)
    assert env.observation_space["ranges"].high.max() == pytest.approx(3.0)
    obs, info = env.reset(seed=4)
    for _ in range(30):
        obs, *_, info = env.step(env.action_space.sample())
        truth = brute_force_ranges(env.maze.segments, info["position"], info["heading"], 360, max_range=3.0)
        assert obs["ranges"].max() <= 3.0
        np.testing.assert_allclose(obs["ranges"], truth, atol=TOL, rtol=0)
    assert (obs["ranges"] == np.float32(3.0)).any() and (obs["ranges"] < 3.0).any()


def test_observation_matches_brute_force_through_env():
    env = HippoMazeEnv(maze="maze3", n_rays=720)
    env.action_space.seed(0)
    obs, info = env.reset(seed=1)
    for _ in range(50):
        obs, *_, info = env.step(env.action_space.sample())
    truth = brute_force_ranges(env.maze.segments, info["position"], info["heading"], 720)
    assert obs["ranges"].dtype == np.float32 and obs["ranges"].shape == (720,)
    np.testing.assert_allclose(obs["ranges"], truth, atol=TOL, rtol=0)
    np.testing.assert_allclose(obs["heading"], [math.cos(info["heading"]), math.sin(info["heading"])], atol=1e-6)
    at = env.observation_at(info["position"], info["heading"])
    np.testing.assert_array_equal(at["ranges"], obs["ranges"])


def _noisy_rollout(seed, noise=0.05, steps=10):
    env = HippoMazeEnv(maze="open", n_rays=64, range_noise=noise)
    obs, info = env.reset(seed=seed)
    scans = [obs["ranges"]]
    for k in range(steps):
        obs, *_ = env.step(k % 8)
        scans.append(obs["ranges"])
    return env, np.array(scans), info


def test_range_noise_is_seeded():
    _, a, _ = _noisy_rollout(seed=5)
    _, b, _ = _noisy_rollout(seed=5)
    _, c, _ = _noisy_rollout(seed=6)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_range_noise_size_and_bounds():
    env = HippoMazeEnv(maze="open", n_rays=720, range_noise=0.05)
    obs, info = env.reset(seed=0, options={"goal": None, "start": [0.0, 0.0], "heading": 0.0})
    clean = env.observation_at(info["position"], info["heading"])["ranges"]
    error = obs["ranges"].astype(float) - clean
    assert 0.04 < error.std() < 0.06
    assert abs(error.mean()) < 0.01
    assert env.observation_space.contains(obs)
    # Noise never pushes a range outside [0, max_range].
    env = HippoMazeEnv(maze="open", n_rays=720, range_noise=5.0, max_range=4.0)
    obs, _ = env.reset(seed=0)
    assert obs["ranges"].min() >= 0.0 and obs["ranges"].max() <= 4.0


def test_no_noise_by_default_is_exact():
    env = HippoMazeEnv(maze="open", n_rays=90)
    obs, info = env.reset(seed=3)
    np.testing.assert_allclose(obs["ranges"], open_room_ranges(info["position"], info["heading"], 90), atol=TOL, rtol=0)


@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
def test_float32_scan_is_the_float64_scan_rounded(maze, specs):
    """The observation's fused float32 scan equals scan() rounded to float32, to the bit; the float64 ranges are kept."""
    spec = specs[maze]
    finder = Rangefinder(spec.segments, 720, 10.0)
    rng = np.random.default_rng(3)
    for _ in range(50):
        x, y = spec.sample_free(rng, 0.17)
        heading = float(rng.uniform(-math.pi, math.pi))
        ranges = finder.scan((x, y), heading)
        ranges32 = finder.scan_float32(float(x), float(y), heading)
        assert ranges32.dtype == np.float32
        assert ranges32.tobytes() == ranges.astype(np.float32).tobytes()
        assert finder.last_ranges.tobytes() == ranges.tobytes()
