"""MazeSpec: the built-in mazes, JSON round trips, geometry helpers, connectivity and geodesics."""

from __future__ import annotations

import json
import math

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import hippo_env
from hippo_env import MazeSpec

R = 0.17  # the robot's radius


@pytest.fixture(scope="module")
def specs():
    return {name: MazeSpec.load(name) for name in hippo_env.BUILTIN_MAZES}


# ---------------------------------------------------------------------- loading
@pytest.mark.parametrize("name", hippo_env.BUILTIN_MAZES)
def test_builtin_mazes_load_and_round_trip(name, tmp_path):
    spec = MazeSpec.load(name)
    assert spec.name == name
    assert spec.size == (10.0, 10.0)
    assert MazeSpec.from_dict(spec.to_dict()) == spec
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(spec.to_dict()))
    assert MazeSpec.load(path) == spec  # a pathlib.Path
    assert MazeSpec.load(str(path)) == spec  # a string path
    assert MazeSpec.load(spec) is spec
    spec.check_connected(R)


def test_builtin_list():
    assert hippo_env.BUILTIN_MAZES == ("open", "maze1", "maze2", "maze3", "maze4")
    assert len(MazeSpec.load("open").obstacles) == 0
    assert all(len(MazeSpec.load(m).obstacles) > 0 for m in hippo_env.BUILTIN_MAZES[1:])


def test_gym_make_takes_name_path_or_spec(tmp_path):
    spec = MazeSpec(name="box", size=(4.0, 3.0), obstacles=(((0.5, -0.5), (1.0, -0.5), (1.0, 0.5)),))
    path = tmp_path / "box.json"
    path.write_text(json.dumps(spec.to_dict()))
    for maze in ("maze2", path, str(path), spec):
        env = gym.make("HippoMaze-v0", maze=maze, n_rays=16)
        env.reset(seed=0)
        assert env.unwrapped.maze.name == ("maze2" if maze == "maze2" else "box")
        env.close()


def test_segments_layout():
    spec = MazeSpec.load("maze3")
    segs = spec.segments
    assert segs.shape == (4 + sum(len(p) for p in spec.obstacles), 4)
    # The four arena walls come first and close the rectangle.
    np.testing.assert_array_equal(segs[:4], [[-5, -5, 5, -5], [5, -5, 5, 5], [5, 5, -5, 5], [-5, 5, -5, -5]])
    np.testing.assert_array_equal(segs[4], [*spec.obstacles[0][0], *spec.obstacles[0][1]])


def test_clearance_and_inside(specs):
    open_ = specs["open"]
    assert open_.clearance((0.0, 0.0)) == pytest.approx(5.0)
    assert open_.clearance((4.0, -1.0)) == pytest.approx(1.0)
    assert open_.clearance((6.0, 0.0)) < 0  # outside the arena
    maze1 = specs["maze1"]
    assert maze1.inside_obstacle((-3.0, 1.5))
    assert maze1.clearance((-3.0, 1.5)) == pytest.approx(-0.15)
    assert not maze1.inside_obstacle((-3.0, 1.0))
    assert maze1.clearance((-3.0, 1.0)) == pytest.approx(0.35)
    assert maze1.is_free((-3.0, 1.0), R) and not maze1.is_free((-3.0, 1.25), R)


@pytest.mark.parametrize("name", hippo_env.BUILTIN_MAZES)
def test_sample_free(name, specs):
    spec = specs[name]
    rng = np.random.default_rng(0)
    for _ in range(50):
        p = spec.sample_free(rng, 0.5, away_from=(0.0, 0.0), min_distance=2.0)
        assert spec.clearance(p) >= 0.5
        assert math.dist(p, (0.0, 0.0)) >= 2.0


# ---------------------------------------------------------------------- geodesics
def _wrap(point, centre, r, out_angle):
    """Tangent from ``point`` to the circle (centre, r), then the arc to the circle point at ``out_angle``."""
    v = np.subtract(point, centre)
    d = float(np.hypot(*v))
    alpha = math.acos(r / d)
    base = math.atan2(v[1], v[0])
    arcs = [abs((base + s * alpha - out_angle + math.pi) % (2 * math.pi) - math.pi) for s in (1, -1)]
    return math.sqrt(d * d - r * r) + r * min(arcs)


def test_geodesic_around_a_thin_wall():
    """A wall x in [-0.05, 0.05], y in [-3, 3]: from (-2, 0) to (2, 0) the robot rounds its end."""
    spec = MazeSpec(name="wall", size=(10.0, 10.0), obstacles=(((-0.05, -3.0), (0.05, -3.0), (0.05, 3.0), (-0.05, 3.0)),))
    start, goal = (-2.0, 0.0), (2.0, 0.0)
    c1, c2 = (-0.05, 3.0), (0.05, 3.0)
    expected = _wrap(start, c1, R, math.pi / 2) + 0.1 + _wrap(goal, c2, R, math.pi / 2)
    assert spec.geodesic(start, goal, R) == pytest.approx(expected, abs=3e-3)
    assert spec.geodesic(goal, start, R) == pytest.approx(expected, abs=3e-3)
    assert expected > 4.0 + 2.0  # really a detour


def test_geodesic_around_maze1_wall(specs):
    """maze1's left wall (x in [-5, -1], y in [1.35, 1.65]) from (-3, 0) to (-3, 3): around its end at x = -1."""
    spec = specs["maze1"]
    start, goal = (-3.0, 0.0), (-3.0, 3.0)
    expected = _wrap(start, (-1.0, 1.35), R, 0.0) + 0.3 + _wrap(goal, (-1.0, 1.65), R, 0.0)
    assert spec.geodesic(start, goal, R) == pytest.approx(expected, abs=3e-3)


def test_geodesic_trivial_cases(specs):
    assert specs["maze2"].geodesic((1.0, 1.0), (1.0, 1.0), R) == pytest.approx(0.0, abs=1e-12)
    assert specs["open"].geodesic((-4.0, -4.0), (4.0, 4.0), R) == pytest.approx(8 * math.sqrt(2))


def _segment_distance(p, q, segments):
    """Smallest distance between segment p-q and any of ``segments`` (brute force, 0 if they cross)."""

    def point_seg(x, a, b):
        ab = b - a
        t = np.clip(np.dot(x - a, ab) / max(np.dot(ab, ab), 1e-18), 0, 1)
        return float(np.linalg.norm(x - (a + t * ab)))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    p, q = np.asarray(p, float), np.asarray(q, float)
    best = math.inf
    for x0, y0, x1, y1 in segments:
        a, b = np.array([x0, y0]), np.array([x1, y1])
        if cross(a, b, p) * cross(a, b, q) < 0 and cross(p, q, a) * cross(p, q, b) < 0:
            return 0.0
        best = min(best, point_seg(p, a, b), point_seg(q, a, b), point_seg(a, p, q), point_seg(b, p, q))
    return best


coordinate = st.floats(-5.0 + R, 5.0 - R)


@settings(max_examples=25, deadline=None)
@given(x0=coordinate, y0=coordinate, x1=coordinate, y1=coordinate)
def test_geodesic_is_straight_in_open_arena(specs, x0, y0, x1, y1):
    assert specs["open"].geodesic((x0, y0), (x1, y1), R) == pytest.approx(math.dist((x0, y0), (x1, y1)), abs=1e-9)


@pytest.mark.parametrize("name", hippo_env.BUILTIN_MAZES[1:])
@settings(max_examples=25, deadline=None)
@given(x0=coordinate, y0=coordinate, x1=coordinate, y1=coordinate)
def test_geodesic_at_least_straight_line(name, specs, x0, y0, x1, y1):
    spec = specs[name]
    assume(spec.clearance((x0, y0)) >= R and spec.clearance((x1, y1)) >= R)
    straight = math.dist((x0, y0), (x1, y1))
    length = spec.geodesic((x0, y0), (x1, y1), R)
    assert math.isfinite(length), "free points must be connected"
    assert length >= straight - 1e-9
    assert spec.geodesic((x1, y1), (x0, y0), R) == pytest.approx(length, abs=1e-6)
    gap = _segment_distance((x0, y0), (x1, y1), spec.segments[4:])
    if gap >= R:
        assert length == pytest.approx(straight, abs=1e-9)
    elif gap < R - 5e-3:  # clearly blocked (the geodesic lets segments graze by up to 3 mm)
        assert length > straight


@pytest.mark.parametrize("name", hippo_env.BUILTIN_MAZES[1:])
def test_geodesic_straight_when_clear_random_pairs(name, specs):
    """Many random pairs (not only what hypothesis picks): clear straight segments give the straight length."""
    spec = specs[name]
    rng = np.random.default_rng(7)
    n_clear = 0
    for _ in range(60):
        a, b = spec.sample_free(rng, R), spec.sample_free(rng, R)
        straight = math.dist(a, b)
        length = spec.geodesic(a, b, R)
        assert length >= straight - 1e-9
        if _segment_distance(a, b, spec.segments[4:]) >= R:
            n_clear += 1
            assert length == pytest.approx(straight, abs=1e-9)
    assert n_clear > 0
