"""The seeded maze generator: determinism, geometry guarantees, connectivity, the env and the CLI."""

from __future__ import annotations

import hashlib
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
from hippo_env.generate import KINDS, block_count, default_cells, generate_maze, main, maze_json

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
    assert generate_maze(4, "perfect", size=20.0, cells=6).name == "gen-perfect-4-20m-6x6"
    assert generate_maze(4, "perfect", size=20.0, cells=8).name == "gen-perfect-4-20m"  # the default grid
    for kind in KINDS:
        for size in (5.0, 7.5, 12.0, 40.0):
            if kind == "arena" and size < 7.0:
                continue
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


# ---------------------------------------------------------------------- the older kinds are unchanged
# Recorded from the generator before "perfect", "rooms" and "arena" shared its grid and spacing code:
# sha256 over maze_json of every (size, seed), sizes outer, seeds 0-19 (walls: sizes 5, 10, 15, seeds 0-9).
CORRIDORS_SHA256 = "ddb16c7e62187ea3d28bd07bdd6bfd4cf3e83f355805af8422d76abf66b12ad5"
WALLS_SHA256 = "07eb614eac18f09aa8fcae8c659dcae023fc75eba35ea7144bc850b65e13356e"
CORRIDORS_SEED_0 = [
    [[-2.6, -2.6], [2.6, -2.6], [2.6, -2.4], [-2.6, -2.4]],
    [[-5.0, -0.1], [0.1, -0.1], [0.1, 0.1], [-5.0, 0.1]],
    [[-2.6, 2.4], [2.6, 2.4], [2.6, 2.6], [-2.6, 2.6]],
    [[2.4, -0.1], [2.6, -0.1], [2.6, 2.4], [2.4, 2.4]],
]


def mazes_sha256(kind: str, sizes, seeds) -> str:
    digest = hashlib.sha256()
    for size in sizes:
        for seed in seeds:
            digest.update(maze_json(generate_maze(seed, kind, size=size)).encode())
    return digest.hexdigest()


def test_corridors_unchanged(mazes):
    assert mazes["corridors"][0].to_dict()["obstacles"] == CORRIDORS_SEED_0
    assert mazes_sha256("corridors", (5.0, 7.5, 10.0, 12.0, 15.0), range(20)) == CORRIDORS_SHA256


def test_walls_unchanged():
    assert mazes_sha256("walls", (5.0, 10.0, 15.0), range(10)) == WALLS_SHA256


# ---------------------------------------------------------------------- perfect, rooms, arena at 10, 20, 40 m
NEW_KINDS = ("perfect", "rooms", "arena")
SIZES = (10.0, 20.0, 40.0)
NEW_SEEDS = range(4)


@pytest.fixture(scope="module")
def sized() -> dict[tuple[str, float], list[MazeSpec]]:
    return {(kind, size): [generate_maze(seed, kind, size=size) for seed in NEW_SEEDS] for kind in NEW_KINDS for size in SIZES}


@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("kind", NEW_KINDS)
def test_new_kinds_valid_connected_deterministic(kind, size, sized):
    specs = sized[kind, size]
    half = size / 2
    for seed, spec in zip(NEW_SEEDS, specs):
        assert spec.size == (size, size)
        assert spec.obstacles
        assert MazeSpec.from_dict(json.loads(maze_json(spec))) == spec  # validates: simple, inside the arena
        for poly in spec.obstacles:
            assert signed_area(poly) > 0, f"{spec.name}: obstacle {poly} is clockwise"
            assert all(abs(x) <= half and abs(y) <= half for x, y in poly)
        spec.check_connected(R, resolution=0.1)
        assert generate_maze(seed, kind, size=size) == spec
    assert len({spec.obstacles for spec in specs}) == len(specs)


def test_default_cells_and_block_count():
    assert [default_cells("perfect", s) for s in (5.0, 7.5, 10.0, 13.0, 15.0, 20.0, 40.0)] == [3, 4, 5, 7, 8, 8, 8]
    assert [default_cells("rooms", s) for s in (5.0, 10.0, 14.9, 15.0, 40.0)] == [2, 2, 2, 3, 3]
    assert default_cells("walls", 10.0) is None
    assert [block_count(s) for s in (7.0, 10.0, 12.0, 15.0, 20.0, 40.0)] == [3, 3, 4, 5, 8, 8]


def rectangles(spec: MazeSpec) -> list[tuple[float, float, float, float]]:
    """Every obstacle as (x0, y0, x1, y1), checking that it is an axis-aligned rectangle."""
    boxes = []
    for poly in spec.obstacles:
        xs, ys = sorted({x for x, _ in poly}), sorted({y for _, y in poly})
        assert len(poly) == 4 and len(xs) == 2 and len(ys) == 2, (spec.name, poly)
        boxes.append((xs[0], ys[0], xs[1], ys[1]))
    return boxes


def line_gaps(boxes, axis: int, at: float, low: float, high: float) -> list[tuple[float, float]]:
    """The stretches of the line {coordinate 1 - axis == at} between low and high (along axis) that no box covers."""
    covered = sorted((b[axis], b[axis + 2]) for b in boxes if b[1 - axis] - TOL <= at <= b[3 - axis] + TOL)
    gaps, reach = [], low
    for lo, hi in covered:
        if lo > reach + TOL:
            gaps.append((reach, min(lo, high)))
        reach = max(reach, hi)
    if reach < high - TOL:
        gaps.append((reach, high))
    return [(lo, hi) for lo, hi in gaps if hi - lo > TOL]


def grid_openings(spec: MazeSpec, k: int) -> dict[tuple[int, int, int], list[tuple[float, float]]]:
    """For a k x k grid of cells over the arena: the gaps on each interior cell edge, keyed (axis, line, index).

    Checks that every gap lies within one cell edge, so a door never spans a junction.
    """
    size = spec.size[0]
    coord = [-size / 2 + size * m / k for m in range(k + 1)]
    boxes = rectangles(spec)
    openings = {}
    for axis in (0, 1):  # 0: the horizontal line y = coord[line], along x; 1: the vertical line x = coord[line]
        for line in range(1, k):
            gaps = line_gaps(boxes, axis, coord[line], -size / 2, size / 2)
            for m in range(k):
                inside = [(lo, hi) for lo, hi in gaps if coord[m] - TOL <= lo and hi <= coord[m + 1] + TOL]
                openings[axis, line, m] = inside
            assert sum(len(v) for (a, ln, _), v in openings.items() if a == axis and ln == line) == len(gaps), spec.name
    return openings


def tree_check(openings, k: int) -> int:
    """The number of open edges of the cell graph, asserting that they join every cell."""
    parent = list(range(k * k))

    def find(c):
        while parent[c] != c:
            c = parent[c]
        return c

    opened = 0
    for (axis, line, m), gaps in openings.items():
        if gaps:
            opened += 1
            # horizontal line `line` between rows line-1 and line, in column m; vertical between columns, in row m
            a, b = ((m, line - 1), (m, line)) if axis == 0 else ((line - 1, m), (line, m))
            parent[find(a[0] * k + a[1])] = find(b[0] * k + b[1])
    assert len({find(c) for c in range(k * k)}) == 1, "some cells cannot be reached"
    return opened


@pytest.mark.parametrize("size, cells", [(10.0, None), (10.0, 2), (10.0, 8), (20.0, None), (40.0, None), (40.0, 3), (5.0, 4)])
def test_perfect_is_a_spanning_tree_with_wide_doors(size, cells):
    k = cells or default_cells("perfect", size)
    cell = size / k
    for seed in range(3):
        spec = generate_maze(seed, "perfect", size=size, cells=cells)
        for x0, y0, x1, y1 in rectangles(spec):
            assert abs(min(x1 - x0, y1 - y0) - 0.2) < TOL  # 0.2 m thick
        openings = grid_openings(spec, k)
        for gaps in openings.values():
            # An edge is either wholly closed or open from the face of one wall to the next: a door >= 1.0 m.
            assert len(gaps) <= 1
            assert all(hi - lo >= cell - 0.2 - TOL and hi - lo >= 1.0 for lo, hi in gaps), (spec.name, gaps)
        assert tree_check(openings, k) == k * k - 1, f"{spec.name}: not a spanning tree (a loop or a closed-off cell)"
        assert generate_maze(seed, "perfect", size=size, cells=cells) == spec


@pytest.mark.parametrize("size, cells", [(10.0, None), (20.0, None), (40.0, None), (5.0, None), (7.5, 3), (20.0, 2)])
def test_rooms_doors(size, cells):
    r = cells or default_cells("rooms", size)
    for seed in range(4):
        spec = generate_maze(seed, "rooms", size=size, cells=cells)
        openings = grid_openings(spec, r)
        for gaps in openings.values():
            assert len(gaps) <= 1, (spec.name, gaps)  # one door per wall between rooms, or none
            for lo, hi in gaps:
                assert 1.0 - TOL <= hi - lo <= 1.5 + TOL, (spec.name, hi - lo)
        doors = tree_check(openings, r)
        assert doors == r * r - 1 + (1 if r == 3 else 0), spec.name  # a spanning tree, plus one loop on 3 x 3


@pytest.mark.parametrize("size", SIZES)
def test_arena_blocks(size, sized):
    half = size / 2
    for spec in sized["arena", size]:
        assert len(spec.obstacles) == block_count(size)
        assert 3 <= len(spec.obstacles) <= 8
        for poly in spec.obstacles:
            assert len(poly) == 4
            sides = [float(np.linalg.norm(b - a)) for a, b in edges(poly)]
            assert all(0.5 - TOL <= s <= 2.0 + TOL for s in sides), (spec.name, sides)
            assert abs(sides[0] - sides[2]) < TOL and abs(sides[1] - sides[3]) < TOL
            assert abs(signed_area(poly) - sides[0] * sides[1]) < 1e-2  # a rectangle
            assert min(side_distances(poly, half)) >= 1.0 - TOL, spec.name
        for i, p in enumerate(spec.obstacles):
            for q in spec.obstacles[i + 1 :]:
                assert polygon_distance(p, q) >= 1.0 - TOL, spec.name


def test_env_runs_in_a_40_m_perfect_maze():
    check_env(generate_maze(0, "perfect", size=40.0, cells=8))


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
    with pytest.raises(ValueError, match="'spiral' is unknown; allowed kinds: walls, corridors, perfect, rooms, arena"):
        generate_maze(0, "spiral")


@pytest.mark.parametrize("seed,error", [(-1, ValueError), (1.5, TypeError), ("3", TypeError), (True, TypeError), (None, TypeError)])
def test_bad_seed(seed, error):
    with pytest.raises(error, match="seed must be a non-negative integer"):
        generate_maze(seed)


@pytest.mark.parametrize("size,error", [(4.0, ValueError), (41.0, ValueError), (math.nan, ValueError), ("10", TypeError)])
def test_bad_size(size, error):
    with pytest.raises(error, match="size must be"):
        generate_maze(0, size=size)


def test_arena_kind_needs_7_m():
    with pytest.raises(ValueError, match="size must be from 7 to 40 m for kind 'arena'"):
        generate_maze(0, "arena", size=6.5)


@pytest.mark.parametrize(
    "kind, size, cells, message",
    [
        ("perfect", 10.0, 1, "cells must be an integer from 2 to 8 for kind 'perfect', got 1"),
        ("perfect", 20.0, 9, "cells must be an integer from 2 to 8 for kind 'perfect', got 9"),
        ("perfect", 5.0, 5, r"cells=5 is too many for a 5 m arena: a cell would be 1.00 m, less than the 1.25 m .* \(at most 4\)"),
        ("rooms", 10.0, 4, "cells must be an integer from 2 to 3 for kind 'rooms', got 4"),
        ("rooms", 7.0, 3, r"cells=3 is too many for a 7 m arena: a room would be 2.33 m, less than the 2.5 m"),
        ("walls", 10.0, 3, "cells is only for kinds 'perfect' .* and 'rooms' .*; kind 'walls' takes none"),
        ("corridors", 10.0, 3, "kind 'corridors' takes none"),
        ("arena", 10.0, 2, "kind 'arena' takes none"),
    ],
)
def test_bad_cells(kind, size, cells, message):
    with pytest.raises(ValueError, match=message):
        generate_maze(0, kind, size=size, cells=cells)


@pytest.mark.parametrize("cells", [2.5, True, "3"])
def test_cells_of_the_wrong_type(cells):
    with pytest.raises(TypeError, match="cells must be an integer from 2 to 8"):
        generate_maze(0, "perfect", cells=cells)


# ---------------------------------------------------------------------- command line
def test_cli_writes_loadable_json(tmp_path, mazes, capsys):
    out = tmp_path / "maze.json"
    assert main(["--seed", "3", "--kind", "corridors", "--out", str(out)]) == 0
    assert MazeSpec.load(out) == mazes["corridors"][3]
    assert str(out) in capsys.readouterr().out
    assert main(["--seed", "3"]) == 0  # walls, to stdout
    assert MazeSpec.from_dict(json.loads(capsys.readouterr().out)) == mazes["walls"][3]
    # The example of the module docstring.
    assert main(["--kind", "perfect", "--cells", "5", "--size", "10", "--seed", "3", "--out", str(out)]) == 0
    assert MazeSpec.load(out) == generate_maze(3, "perfect", size=10.0, cells=5)


def test_cli_help_documents_every_kind(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    for word in (*KINDS, "--cells", "spanning tree", "no loops", "1.0-1.5 m doors", "blocks"):
        assert word in text, word


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
    [
        (["--seed", "1", "--kind", "spiral"], "allowed kinds: walls, corridors, perfect, rooms, arena"),
        (["--seed", "-2"], "seed must be a non-negative integer"),
        (["--seed", "1", "--kind", "perfect", "--cells", "9"], "cells must be an integer from 2 to 8"),
        (["--seed", "1", "--kind", "perfect", "--size", "5", "--cells", "5"], "cells=5 is too many for a 5 m arena"),
        (["--seed", "1", "--size", "50"], "size must be from 5 to 40 m"),
    ],
)
def test_cli_errors(args, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
