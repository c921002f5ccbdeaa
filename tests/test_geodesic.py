"""Geodesics in random mazes: the visibility graph agrees with a fine-grid Dijkstra on the free space.

Random mazes of random simple polygons (star-shaped, so convex or not, with acute corners), in
both orientations, some pushed against the arena walls. The reference is Dijkstra on a 2 cm grid
of the inflated free space with 16-connected moves, which overestimates a true shortest path by
at most a few percent (its directions are 0, 26.6, 45, ... degrees) plus a cell or two at the ends.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from brute_force import free_by_brute_force
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_env import MazeSpec

R = 0.17  # the robot's radius
CELL = 0.02  # m, the reference grid
# The 16 moves (d_row, d_col) and, for each, the cells the straight move passes over.
MOVES = [(dr, dc) for dr in range(-2, 3) for dc in range(-2, 3) if (dr, dc) != (0, 0) and math.gcd(abs(dr), abs(dc)) == 1]


def _polygon(cx: float, cy: float, radii: list[float], gaps: list[float], clockwise: bool) -> list[list[float]]:
    """A star-shaped polygon around (cx, cy): vertex k at angle sum(gaps[:k]) (scaled to 2 pi), radius radii[k]."""
    angles = np.cumsum(gaps) / np.sum(gaps) * 2 * math.pi
    points = [[cx + r * math.cos(a), cy + r * math.sin(a)] for r, a in zip(radii, angles)]
    return points[::-1] if clockwise else points


@st.composite
def random_mazes(draw) -> MazeSpec:
    """3-5 m arenas with one to three random simple polygons, either orientation, some touching the walls."""
    width, height = draw(st.floats(3.0, 5.0)), draw(st.floats(3.0, 5.0))
    obstacles = []
    for _ in range(draw(st.integers(1, 3))):
        n = draw(st.integers(3, 7))
        radii = draw(st.lists(st.floats(0.1, 1.0), min_size=n, max_size=n))
        gaps = draw(st.lists(st.floats(0.2, 1.0), min_size=n, max_size=n))
        cx = draw(st.floats(-width / 2, width / 2))
        cy = draw(st.floats(-height / 2, height / 2))
        polygon = _polygon(cx, cy, radii, gaps, clockwise=draw(st.booleans()))
        # Vertices beyond the arena are pulled onto its walls: obstacles that touch (and run along) them.
        obstacles.append([[min(max(x, -width / 2), width / 2), min(max(y, -height / 2), height / 2)] for x, y in polygon])
    try:
        return MazeSpec(name="random", size=(width, height), obstacles=obstacles)
    except ValueError:  # clamping can make a polygon degenerate or self-touching
        assume(False)
        raise


def grid_distances(spec: MazeSpec, goal: np.ndarray, clearance: float = R) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Dijkstra from the cell nearest ``goal`` over the cells whose centres have at least ``clearance``.

    Returns the cell centres (n, 2), which cells are free, each cell's distance (inf if
    unreachable) and its predecessor on the way to the goal (-9999 at the goal and beyond reach).
    """
    hw, hh = spec.half_extent
    cols, rows = int(2 * hw / CELL), int(2 * hh / CELL)
    xs = -hw + (np.arange(cols) + 0.5) * 2 * hw / cols
    ys = -hh + (np.arange(rows) + 0.5) * 2 * hh / rows
    gx, gy = np.meshgrid(xs, ys)
    centres = np.stack([gx.ravel(), gy.ravel()], axis=1)
    free = free_by_brute_force(spec, centres, clearance).reshape(rows, cols)
    dx, dy = 2 * hw / cols, 2 * hh / rows
    index = np.arange(rows * cols).reshape(rows, cols)
    sources, targets, weights = [], [], []
    for dr, dc in MOVES:
        # A move is allowed when every cell its straight line passes over is free.
        ok = np.ones((rows, cols), dtype=bool)
        steps = max(abs(dr), abs(dc))
        for s in range(1, 2 * steps + 1):
            t = s / (2 * steps)
            ok &= _shift(free, round(dr * t + 1e-9 * np.sign(dr)), round(dc * t + 1e-9 * np.sign(dc)))
            ok &= _shift(free, math.floor(dr * t), math.floor(dc * t)) & _shift(free, math.ceil(dr * t), math.ceil(dc * t))
        ok &= free
        r0, c0 = np.nonzero(ok)
        sources.append(index[r0, c0])
        targets.append(index[r0 + dr, c0 + dc])
        weights.append(np.full(len(r0), math.hypot(dr * dy, dc * dx)))
    graph = coo_matrix(
        (np.concatenate(weights), (np.concatenate(sources), np.concatenate(targets))), shape=(rows * cols, rows * cols)
    ).tocsr()
    goal_cell = _nearest_free(centres, free.ravel(), goal)
    distance, predecessors = dijkstra(graph, indices=goal_cell, return_predecessors=True)
    return centres, free.ravel(), distance + float(np.linalg.norm(centres[goal_cell] - goal)), predecessors


def _shift(mask: np.ndarray, dr: int, dc: int) -> np.ndarray:
    """``out[r, c] = mask[r + dr, c + dc]`` (False beyond the edge)."""
    out = np.zeros_like(mask)
    rows, cols = mask.shape
    out[max(-dr, 0) : rows - max(dr, 0), max(-dc, 0) : cols - max(dc, 0)] = mask[
        max(dr, 0) : rows - max(-dr, 0) or None, max(dc, 0) : cols - max(-dc, 0) or None
    ]
    return out


def _nearest_free(centres: np.ndarray, free: np.ndarray, point: np.ndarray) -> int:
    distance = np.where(free, np.linalg.norm(centres - point, axis=1), np.inf)
    return int(np.argmin(distance))


def _free_points(spec: MazeSpec, rng: np.random.Generator, clearance: float, count: int) -> list[np.ndarray]:
    points = []
    for _ in range(count):
        try:
            points.append(spec.sample_free(rng, clearance, tries=2000))
        except ValueError:
            break
    return points


# Counted by the test itself, reported in the test's output: how many geodesics were checked.
CHECKED = {"mazes": 0, "pairs": 0}


@settings(max_examples=60, deadline=None)
@given(spec=random_mazes(), seed=st.integers(0, 2**16))
def test_geodesic_matches_fine_grid_dijkstra(spec, seed):
    """Sandwiched between two grids: cells with clearance >= R (a subset of the free space, so never
    shorter, bar a cell at each end) and cells with clearance >= R - 1.5 cells (which contain a
    chain of cells along every true path, so never longer than it by more than 16-connectivity's
    few percent). Narrow gaps the first grid cannot resolve are then no false alarm."""
    rng = np.random.default_rng(seed)
    goals = _free_points(spec, rng, R, 1)
    assume(goals)
    goal = goals[0]
    starts = _free_points(spec, rng, R + 0.01, 4)
    assume(starts)
    strict = grid_distances(spec, goal)
    loose = grid_distances(spec, goal, clearance=R - 1.5 * CELL)
    CHECKED["mazes"] += 1
    for start in starts:
        upper, lower = (_grid_length(grid, start) for grid in (strict, loose))
        geodesic = spec.geodesic(start, goal, R)
        assert geodesic >= math.dist(start, goal) - 1e-9
        if math.isfinite(upper):
            CHECKED["pairs"] += 1
            assert math.isfinite(geodesic), f"the grid finds a path of {upper:.3f} m from {start} to {goal}, the geodesic none"
            assert geodesic <= upper + 2 * CELL, f"geodesic {geodesic:.3f} m, longer than the grid's {upper:.3f} m"
        if math.isfinite(geodesic):
            assert lower <= 1.04 * geodesic + 4 * CELL, f"geodesic {geodesic:.3f} m, shorter than any path the grid finds ({lower:.3f} m)"


def _grid_length(grid: tuple, start: np.ndarray) -> float:
    """The grid's distance from ``start`` to the goal: through the free cell nearest the start."""
    centres, free, distance, _ = grid
    cell = _nearest_free(centres, free, start)
    return float(distance[cell] + np.linalg.norm(centres[cell] - start))


def test_geodesic_case_count(capsys):
    """Runs after the property test (same module): it checked many mazes and pairs, not a handful."""
    if CHECKED["mazes"] == 0:
        pytest.skip("run with the property test above")
    with capsys.disabled():
        print(f"\n[geodesic property test: {CHECKED['mazes']} random mazes, {CHECKED['pairs']} start/goal pairs checked against the grid]")
    assert CHECKED["mazes"] >= 40 and CHECKED["pairs"] >= 100


def test_clockwise_triangle_corner_from_the_issue():
    """The issue's example: a clockwise triangle's acute corner must be rounded, not cut."""
    wall = [[-5.0, 3.0], [-0.5, 3.0], [-0.5, 3.2], [-5.0, 3.2]]
    triangle = [[-1.0, 3.6], [0.0, 4.4], [1.0, 3.6]]  # clockwise
    start, goal = (-3.3, 4.1), (-3.3, 0.0)
    clockwise = MazeSpec(name="cw", size=(10.0, 10.0), obstacles=(triangle, wall))
    counter = MazeSpec(name="ccw", size=(10.0, 10.0), obstacles=(triangle[::-1], wall[::-1]))
    length = clockwise.geodesic(start, goal, R)
    assert math.isfinite(length)
    assert length == pytest.approx(counter.geodesic(start, goal, R), abs=1e-9)


@pytest.mark.parametrize("clockwise", [False, True])
def test_orientation_does_not_change_any_geodesic(clockwise):
    """The same maze with every polygon reversed gives the same geodesics."""
    rng = np.random.default_rng(3)
    polygons = [
        _polygon(x, y, list(rng.uniform(0.2, 0.9, 5)), list(rng.uniform(0.2, 1.0, 5)), clockwise)
        for x, y in ((-1.5, 0.5), (1.2, -0.8), (0.5, 1.8))
    ]
    spec = MazeSpec(name="a", size=(6.0, 6.0), obstacles=polygons)
    reversed_spec = MazeSpec(name="b", size=(6.0, 6.0), obstacles=[p[::-1] for p in polygons])
    for _ in range(30):
        a, b = spec.sample_free(rng, R + 0.01), spec.sample_free(rng, R)
        assert spec.geodesic(a, b, R) == pytest.approx(reversed_spec.geodesic(a, b, R), abs=1e-9)


def _follow(env: gym.Env, path: np.ndarray, max_steps: int = 400) -> dict:
    """Drive with heading actions along a polyline of waypoints; the last step's info."""
    info: dict = {}
    k = 0
    for _ in range(max_steps):
        position = np.asarray(env.unwrapped.world.position)
        while k < len(path) - 1 and np.linalg.norm(path[k] - position) < 0.12:
            k += 1
        heading = math.atan2(path[k][1] - position[1], path[k][0] - position[0])
        _, _, terminated, truncated, info = env.step(np.array([heading], np.float32))
        if terminated or truncated:
            break
    return info


def test_no_successful_run_is_shorter_than_the_geodesic():
    """Drive the robot to the goal along grid paths in random mazes: every run that arrives is at least as long."""
    rng = np.random.default_rng(11)
    arrived = 0
    for _ in range(8):
        polygons = [
            _polygon(*rng.uniform(-1.5, 1.5, 2), list(rng.uniform(0.2, 0.8, 5)), list(rng.uniform(0.2, 1.0, 5)), bool(rng.integers(2)))
            for _ in range(2)
        ]
        try:
            spec = MazeSpec(name="drive", size=(5.0, 5.0), obstacles=polygons)
            env = gym.make("HippoMaze-v0", maze=spec, n_rays=8, action_type="heading")
        except ValueError:
            continue
        goal = spec.sample_free(rng, 0.5)
        _, info = env.reset(seed=0, options={"goal": goal})
        start = np.asarray(info["position"])
        # A grid path with room to spare, so the robot does not scrape along the walls.
        centres, free, distance, predecessors = grid_distances(spec, goal, clearance=R + 0.06)
        cell = _nearest_free(centres, free, start)
        if not math.isfinite(distance[cell]):
            env.close()
            continue
        cells = [cell]
        while predecessors[cells[-1]] >= 0:
            cells.append(int(predecessors[cells[-1]]))
        info = _follow(env, np.vstack([centres[cells], goal]))
        env.close()
        if info.get("is_success"):
            arrived += 1
            assert info["path_length"] >= info["shortest_path_length"] - 1e-9
            assert math.isfinite(info["indirectness"]) and info["indirectness"] >= 0
    assert arrived >= 6  # 8 of 8 arrive as written


def test_reset_raises_when_no_geodesic_can_be_computed(monkeypatch):
    """An infinite geodesic is a clear error at reset, never a missing indirectness in the record."""
    env = gym.make("HippoMaze-v0", maze="maze1", n_rays=8)
    monkeypatch.setattr(MazeSpec, "geodesic", lambda self, start, goal, radius: math.inf)
    with pytest.raises(ValueError, match="no shortest path could be computed from the start"):
        env.reset(seed=0, options={"goal": [3.0, 3.0]})
    env.close()


def test_a_start_on_the_goal_disks_edge_is_refused():
    """There the shortest path is 0 m, so a successful run's indirectness would be undefined (None in the record)."""
    env = gym.make("HippoMaze-v0", maze="open", n_rays=8, goal_radius=0.5)
    with pytest.raises(ValueError, match="inside the goal disk or on its edge; start more than 0.5 m from the goal"):
        env.reset(seed=0, options={"goal": [1.0, 1.0], "start": [1.5, 1.0]})
    _, info = env.reset(seed=0, options={"goal": [1.0, 1.0], "start": [1.51, 1.0]})
    assert info["shortest_path_length"] > 0
    env.close()
