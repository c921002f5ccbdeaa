"""The seeded maze generator: determinism, geometry guarantees, connectivity, the env and the CLI."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_env import MazeSpec
from hippo_env.generate import KINDS, generate_maze, main

R = 0.17  # the robot's radius
SEEDS = range(20)
TOL = 1e-3  # m: vertices are rounded to 0.1 mm
# gym.make checks connectivity on a 5 cm grid (about 0.3 s a maze): the default run builds the
# environment for the first few seeds; `-m slow` does all of them.
ENV_SEEDS = range(3)


@pytest.fixture(scope="module")
def mazes() -> dict[str, list[MazeSpec]]:
    return {kind: [generate_maze(seed, kind) for seed in SEEDS] for kind in KINDS}


# ---------------------------------------------------------------------- geometry helpers (independent of the generator's)
def signed_area(poly) -> float:
    pts = np.asarray(poly, float)
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def point_segment(p, a, b) -> float:
    p, a, b = map(np.asarray, (p, a, b))
    ab = b - a
    t = np.clip((p - a) @ ab / (ab @ ab), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * ab)))


def edges(poly):
    pts = [np.asarray(p, float) for p in poly]
    return list(zip(pts, pts[1:] + pts[:1]))


def crosses(a, b, c, d) -> bool:
    def cross(o, p, q):
        return (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0])

    return cross(a, b, c) * cross(a, b, d) < 0 and cross(c, d, a) * cross(c, d, b) < 0


def polygon_distance(p, q) -> float:
    """Distance between two polygons; 0 when they touch, cross or one holds the other."""
    if MazeSpec("p", (100, 100), [p]).inside_obstacle(q[0]) or MazeSpec("q", (100, 100), [q]).inside_obstacle(p[0]):
        return 0.0
    best = math.inf
    for a, b in edges(p):
        for c, d in edges(q):
            if crosses(a, b, c, d):
                return 0.0
            best = min(best, point_segment(a, c, d), point_segment(b, c, d), point_segment(c, a, b), point_segment(d, a, b))
    return best


def side_distances(poly, half) -> list[float]:
    """Distance of a polygon inside the arena to its bottom, right, top and left sides."""
    pts = np.asarray(poly, float)
    return [
        float((pts[:, 1] + half).min()),
        float((half - pts[:, 0]).min()),
        float((half - pts[:, 1]).min()),
        float((pts[:, 0] + half).min()),
    ]


# ---------------------------------------------------------------------- determinism
@pytest.mark.parametrize("kind", KINDS)
def test_same_seed_same_maze(kind, mazes):
    again = generate_maze(7, kind)
    assert again == mazes[kind][7]
    assert again.to_dict() == mazes[kind][7].to_dict()
    assert generate_maze(7, kind, size=12.0) == generate_maze(7, kind, size=12.0)


def test_no_global_randomness(mazes):
    np.random.seed(123)
    before = np.random.random()
    np.random.seed(123)
    assert generate_maze(3, "walls") == mazes["walls"][3]
    assert np.random.random() == before  # the global generator was neither used nor reseeded


@pytest.mark.parametrize("kind", KINDS)
def test_different_seeds_different_mazes(kind, mazes):
    layouts = {spec.obstacles for spec in mazes[kind]}
    assert len(layouts) == len(SEEDS)
    assert len({spec.name for spec in mazes[kind]}) == len(SEEDS)


def test_name_and_size(mazes):
    assert mazes["walls"][4].name == "gen-walls-4"
    assert mazes["corridors"][4].name == "gen-corridors-4"
    assert generate_maze(4, "walls", size=8.0).name == "gen-walls-4-8m"
    assert generate_maze(4, "corridors", name="mine").name == "mine"
    for kind in KINDS:
        for size in (5.0, 7.5, 12.0):
            spec = generate_maze(1, kind, size=size)
            assert spec.size == (size, size)


# ---------------------------------------------------------------------- guarantees, every seed
@pytest.mark.parametrize("kind", KINDS)
def test_polygons_valid_ccw_inside(kind, mazes):
    for spec in mazes[kind]:
        assert spec.size == (10.0, 10.0)
        assert spec.obstacles
        assert MazeSpec.from_dict(json.loads(json.dumps(spec.to_dict()))) == spec  # validates: simple, inside the arena
        for poly in spec.obstacles:
            assert signed_area(poly) > 0, f"{spec.name}: obstacle {poly} is clockwise"
            assert all(abs(x) <= 5.0 and abs(y) <= 5.0 for x, y in poly)


def test_walls_shape_and_spacing(mazes):
    for spec in mazes["walls"]:
        assert 2 <= len(spec.obstacles) <= 4, spec.name
        for poly in spec.obstacles:
            assert len(poly) == 4
            sides = sorted(edges(poly), key=lambda e: -np.linalg.norm(e[1] - e[0]))
            (a, b), (c, d) = sides[:2]  # the two long edges, parallel
            u, v = b - a, d - c
            assert abs(u[0] * v[1] - u[1] * v[0]) / (np.linalg.norm(u) * np.linalg.norm(v)) < 1e-3
            length = (np.linalg.norm(u) + np.linalg.norm(v)) / 2  # the centre line
            thickness = signed_area(poly) / length
            assert 2.5 - TOL <= length <= 6.0 + TOL, (spec.name, length)
            assert 0.2 - TOL <= thickness <= 0.3 + TOL, (spec.name, thickness)
            angle = math.degrees(math.atan2(u[1], u[0])) % 45.0
            assert min(angle, 45.0 - angle) < 0.05, (spec.name, angle)  # axis-aligned or diagonal
            # Flush with at most one side, and at least 1 m from the others (no narrow gap at the boundary).
            distances = side_distances(poly, 5.0)
            touching = [d for d in distances if d < TOL]
            assert len(touching) <= 1, spec.name
            assert all(d >= 1.0 - TOL for d in distances if d >= TOL), (spec.name, distances)
            if touching:  # flush: a whole end edge lies on the side
                side = distances.index(touching[0])
                axis, value = (1, -5.0) if side == 0 else (0, 5.0) if side == 1 else (1, 5.0) if side == 2 else (0, -5.0)
                assert sum(p[axis] == value for p in poly) == 2, (spec.name, poly)
        for i, p in enumerate(spec.obstacles):
            for q in spec.obstacles[i + 1 :]:
                assert polygon_distance(p, q) >= 1.0 - TOL, (spec.name, p, q)


def test_corridors_grid_and_doors(mazes):
    for spec in mazes["corridors"]:
        for poly in spec.obstacles:
            xs, ys = sorted({x for x, _ in poly}), sorted({y for _, y in poly})
            assert len(poly) == 4 and len(xs) == 2 and len(ys) == 2  # axis-aligned rectangles
            assert abs(min(xs[1] - xs[0], ys[1] - ys[0]) - 0.2) < TOL  # 0.2 m thick
            for d in side_distances(poly, 5.0):
                assert d < TOL or d >= 1.2 - TOL, spec.name
        # Walls either touch (a junction) or leave a door of at least 1.2 m.
        for i, p in enumerate(spec.obstacles):
            for q in spec.obstacles[i + 1 :]:
                d = polygon_distance(p, q)
                assert d < TOL or d >= 1.2 - TOL, (spec.name, d)


@pytest.mark.parametrize("kind", KINDS)
def test_connected(kind, mazes):
    for spec in mazes[kind]:
        spec.check_connected(R, resolution=0.1)  # gym.make (test_env_runs) checks on the default 5 cm grid


def grid_of(spec: MazeSpec) -> int:
    """The corridor grid's cells per side: the one whose lines carry every wall's centre line."""
    centres = []
    for poly in spec.obstacles:
        (x0, x1), (y0, y1) = ((min(c), max(c)) for c in zip(*poly))
        centres.append((x0 + x1) / 2 if x1 - x0 < y1 - y0 else (y0 + y1) / 2)  # across the wall
    for k in (3, 4):
        lines = [-5.0 + 10.0 * m / k for m in range(1, k)]
        if all(any(abs(c - line) < TOL for line in lines) for c in centres):
            return k
    raise AssertionError(f"{spec.name}: walls on no 3 x 3 or 4 x 4 grid")


def test_corridors_are_spanning_tree_plus_loops(mazes):
    """Every cell edge covered by a wall is closed; a spanning tree opens k*k - 1 edges, loops open more."""
    for spec in mazes["corridors"]:
        k = grid_of(spec)
        cell = 10.0 / k
        closed = 0
        for line in range(1, k):
            for m in range(k):
                mid_line, mid_edge = -5.0 + cell * line, -5.0 + cell * (m + 0.5)
                closed += spec.inside_obstacle((mid_line, mid_edge)) + spec.inside_obstacle((mid_edge, mid_line))
        opened = 2 * k * (k - 1) - closed
        assert opened >= k * k, f"{spec.name}: {opened} open cell edges in a {k} x {k} grid, no loop"
        assert opened <= k * k - 1 + 2, spec.name  # at most 2 extra openings


# ---------------------------------------------------------------------- the environment
def check_env(spec: MazeSpec) -> None:
    env = gym.make("HippoMaze-v0", maze=spec, n_rays=16)  # checks connectivity on a 5 cm grid
    try:
        _, info = env.reset(seed=0)
        assert math.isfinite(info["shortest_path_length"]) and info["shortest_path_length"] >= 0
    finally:
        env.close()


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("seed", ENV_SEEDS)
def test_env_runs(kind, seed, mazes):
    check_env(mazes[kind][seed])


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
def test_env_runs_every_seed(kind, mazes):
    for spec in mazes[kind]:
        check_env(spec)


# ---------------------------------------------------------------------- errors
def test_bad_kind_names_allowed_kinds():
    with pytest.raises(ValueError, match="'spiral' is unknown; allowed kinds: walls, corridors"):
        generate_maze(0, "spiral")


@pytest.mark.parametrize("seed", [-1, 1.5, "3", True, None])
def test_bad_seed(seed):
    with pytest.raises(ValueError, match="seed must be a non-negative integer"):
        generate_maze(seed)


@pytest.mark.parametrize("size", [4.0, 16.0, math.nan, "10"])
def test_bad_size(size):
    with pytest.raises(ValueError, match="size must be"):
        generate_maze(0, size=size)


# ---------------------------------------------------------------------- command line
def test_cli_writes_loadable_json(tmp_path, mazes, capsys):
    out = tmp_path / "maze.json"
    assert main(["--seed", "3", "--kind", "corridors", "--out", str(out)]) == 0
    assert MazeSpec.load(out) == mazes["corridors"][3]
    assert str(out) in capsys.readouterr().out
    assert main(["--seed", "3"]) == 0  # walls, to stdout
    assert MazeSpec.from_dict(json.loads(capsys.readouterr().out)) == mazes["walls"][3]


def test_cli_module_entry_point(tmp_path, mazes):
    out = tmp_path / "maze.json"
    done = subprocess.run(
        [sys.executable, "-m", "hippo_env.generate", "--seed", "3", "--kind", "walls", "--out", str(out)],
        check=False,
        capture_output=True,
        text=True,
        cwd=Path(__file__).resolve().parents[1],
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert MazeSpec.load(out) == mazes["walls"][3]
    assert json.loads(out.read_text())["name"] == "gen-walls-3"


@pytest.mark.parametrize(
    "args, message",
    [(["--seed", "1", "--kind", "spiral"], "allowed kinds: walls, corridors"), (["--seed", "-2"], "seed must be a non-negative integer")],
)
def test_cli_errors(args, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
