"""Seeded maze generator: random but reproducible :class:`~hippo_env.maze.MazeSpec` arenas.

Two kinds of maze, both in a square arena (10 x 10 m by default) centred on the origin:

``"walls"``
    2-4 straight thin walls (rectangles 0.2-0.3 m thick and 2.5-6 m long in a 10 m arena; the
    length scales with the arena), each axis-aligned or diagonal (at 45 degrees). A wall either
    floats or touches the arena boundary with one end flush against it (a diagonal wall's end
    is cut along the boundary). Guarantees: no two walls overlap or come closer than 1.0 m to
    each other, and no wall comes closer than 1.0 m to any part of the boundary except the side
    it is flush with, so every gap a robot must pass is at least 1.0 m wide.

``"corridors"``
    A coarse grid maze: the arena is cut into k x k cells of 2.5-3.4 m (3 x 3 or 4 x 4 in a 10 m
    arena), a randomised depth-first search carves a spanning tree of open cell edges, and 1-2
    further edges are opened so that there are loops (one on a 3 x 3 grid, so that it keeps three
    walls; none on the 2 x 2 grid of a 5-6.6 m arena). The closed interior edges become walls
    0.2 m thick (collinear edges merged into one rectangle; walls meeting at a junction touch
    but do not overlap). Every door gap (an open cell edge) is at least 1.2 m wide (in fact at
    least the cell size minus 0.2 m).

Guarantees for every kind: each obstacle is a simple polygon listed counter-clockwise (positive
signed area) with every vertex inside the arena (vertices rounded to 0.1 mm); the free space is
connected for the robot (a disc of ``physics.ROBOT_RADIUS`` = 0.17 m), checked with
:meth:`MazeSpec.check_connected` and re-drawn on failure; the same ``(seed, kind, size)``
always gives the same maze, as all randomness comes from one ``numpy.random.default_rng(seed)``.

From the command line::

    python -m hippo_env.generate --seed 3 --kind walls --out maze.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS

KINDS = ("walls", "corridors")
MIN_SIZE = 5.0  # m: the smallest arena side (a 2 x 2 corridor grid, walls 1.25-3 m long)
MAX_SIZE = 15.0  # m: the largest arena side (beyond it, corridor mazes make the env slow: geodesics, connectivity)

# kind="walls"
WALL_COUNT = (2, 4)  # walls per maze, inclusive
WALL_THICKNESS = (0.2, 0.3)  # m
WALL_LENGTH = (2.5, 6.0)  # m in a 10 m arena; scaled with the arena's side
WALL_GAP = 1.0  # m: the narrowest gap between two walls, or a wall and the boundary
WALL_ANGLES = (0.0, 45.0, 90.0, 135.0)  # degrees: axis-aligned or diagonal
TOUCH_PROBABILITY = 0.5  # a wall touches the boundary (else it floats)

# kind="corridors"
CELL_SIZE = (2.5, 3.4)  # m: cells per side are chosen so that a cell's side falls in this range
CORRIDOR_THICKNESS = 0.2  # m
EXTRA_OPENINGS = (1, 2)  # cell edges opened beyond the spanning tree, inclusive
MIN_DOOR = 1.2  # m: the narrowest door gap

_DECIMALS = 4  # vertices rounded to 0.1 mm (readable JSON)
_MAX_ATTEMPTS = 1000  # whole-maze draws before giving up (a guard: a few suffice)
_PLACE_TRIES = 50  # draws per wall before the whole maze is drawn anew
# m: grid of the generator's connectivity check. Coarser than the environment's 5 cm (which it repeats):
# neighbouring free grid points are joined by a path with clearance >= sqrt(r^2 - (0.15/2)^2) = 0.15 m, so the
# check errs only for passages within 4 cm of the robot's diameter, and every gap here is >= 1 m.
_CONNECTIVITY_RESOLUTION = 0.15

Polygon = tuple[tuple[float, float], ...]


def generate_maze(seed: int, kind: str = "walls", size: float = 10.0, name: str | None = None) -> MazeSpec:
    """Draw a random maze, reproducibly from ``seed``.

    Args:
        seed: A non-negative integer; the same ``(seed, kind, size)`` always gives the same maze.
        kind: ``"walls"`` (2-4 straight thin walls, axis-aligned or diagonal, floating or flush
            with the boundary, at least 1.0 m from each other and from the rest of the boundary)
            or ``"corridors"`` (a 3 x 3 or 4 x 4 grid maze carved by a randomised depth-first
            search, plus extra openings for loops; 0.2 m walls, doors at least 1.2 m wide).
            See the module docstring for the details.
        size: The side of the square arena in metres, from 5 to 15 (default 10). Wall lengths of
            ``"walls"`` scale with it; gaps, thicknesses and corridor cells (2.5-3.4 m) do not.
        name: The maze's name; defaults to ``"gen-{kind}-{seed}"`` (with ``"-{size}m"`` appended
            when the arena is not 10 m).

    Returns:
        A :class:`MazeSpec` whose obstacles are simple counter-clockwise polygons inside the arena
        and whose free space is connected for the robot (radius 0.17 m).

    Raises:
        ValueError: for a negative or non-integer seed, an unknown kind, a size outside 5-15 m,
            or an empty name.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    if seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed}")
    if kind not in KINDS:
        raise ValueError(f"maze kind {kind!r} is unknown; allowed kinds: {', '.join(KINDS)}")
    if isinstance(size, bool) or not isinstance(size, (int, float, np.integer, np.floating)) or not math.isfinite(size):
        raise ValueError(f"size must be a number of metres from {MIN_SIZE:g} to {MAX_SIZE:g}, got {size!r}")
    size = float(size)
    if not MIN_SIZE <= size <= MAX_SIZE:
        raise ValueError(f"size must be from {MIN_SIZE:g} to {MAX_SIZE:g} m, got {size:g}")
    if name is None:
        name = f"gen-{kind}-{int(seed)}" + ("" if size == 10.0 else f"-{size:g}m")
    elif not isinstance(name, str) or not name:
        raise ValueError(f"name must be a non-empty string or None, got {name!r}")

    rng = np.random.default_rng(int(seed))
    draw = _draw_walls if kind == "walls" else _draw_corridors
    for _ in range(_MAX_ATTEMPTS):
        obstacles = draw(rng, size)
        if obstacles is None:
            continue
        spec = MazeSpec(name=name, size=(size, size), obstacles=obstacles)
        try:
            spec.check_connected(ROBOT_RADIUS, resolution=_CONNECTIVITY_RESOLUTION)
        except ValueError:
            continue
        return spec
    raise RuntimeError(f"found no valid {kind!r} maze for seed {seed} in a {size:g} m arena after {_MAX_ATTEMPTS} attempts")


# ---------------------------------------------------------------------- kind="walls"
def _draw_walls(rng: np.random.Generator, size: float) -> list[Polygon] | None:
    """2-4 walls at least WALL_GAP apart, or None when one of them found no room (draw again)."""
    half = size / 2
    scale = size / 10.0
    count = int(rng.integers(WALL_COUNT[0], WALL_COUNT[1] + 1))
    walls: list[Polygon] = []
    for _ in range(count):
        for _ in range(_PLACE_TRIES):
            wall = _draw_wall(rng, half, scale)
            if wall is not None and all(_polygon_distance(wall, other) >= WALL_GAP for other in walls):
                walls.append(wall)
                break
        else:
            return None
    return walls


def _draw_wall(rng: np.random.Generator, half: float, scale: float) -> Polygon | None:
    """One thin wall, floating or flush with a side; None when it comes too close to the boundary."""
    thickness = rng.uniform(*WALL_THICKNESS)
    length = rng.uniform(*WALL_LENGTH) * scale
    if rng.random() < TOUCH_PROBABILITY:
        side = int(rng.integers(4))  # 0 bottom, 1 right, 2 top, 3 left
        inward = np.array([(0.0, 1.0), (-1.0, 0.0), (0.0, -1.0), (1.0, 0.0)][side])
        along = np.array([inward[1], -inward[0]])  # the side's direction
        tilt = math.radians(float((0.0, 45.0, -45.0)[int(rng.integers(3))]))
        u = math.cos(tilt) * inward + math.sin(tilt) * along  # the wall's direction, into the arena
        n = np.array([-u[1], u[0]])
        base = -half * inward + rng.uniform(-half, half) * along  # where the centre line meets the side
        # The wall's two long edges run from the side (where they cross it) to the far end cap.
        offset = thickness / 2 * (n.dot(inward) / u.dot(inward))
        far = base + length * u
        points = [
            base - thickness / 2 * n + offset * u,
            far - thickness / 2 * n,
            far + thickness / 2 * n,
            base + thickness / 2 * n - offset * u,
        ]
        polygon = _rounded(points)
        # The end on the side lies exactly on it (no rounding error outside the arena).
        axis = 0 if side in (1, 3) else 1
        edge = -half * inward[axis]
        polygon = tuple(tuple(edge if k in (0, 3) and i == axis else c for i, c in enumerate(p)) for k, p in enumerate(polygon))
        others = [s for s in range(4) if s != side]
    else:
        angle = math.radians(float(WALL_ANGLES[int(rng.integers(len(WALL_ANGLES)))]))
        u = np.array([math.cos(angle), math.sin(angle)])
        n = np.array([-u[1], u[0]])
        centre = rng.uniform(-half, half, size=2)
        points = [centre + su * length / 2 * u + sn * thickness / 2 * n for su, sn in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        polygon = _rounded(points)
        others = [0, 1, 2, 3]
    if min(_side_distance(polygon, half, s) for s in others) < WALL_GAP:
        return None
    return _counter_clockwise(polygon)


def _side_distance(polygon: Polygon, half: float, side: int) -> float:
    """Distance from a polygon inside the arena to one of its sides (0 bottom, 1 right, 2 top, 3 left)."""
    pts = np.asarray(polygon)
    return float({0: pts[:, 1] + half, 1: half - pts[:, 0], 2: half - pts[:, 1], 3: pts[:, 0] + half}[side].min())


# ---------------------------------------------------------------------- kind="corridors"
def _draw_corridors(rng: np.random.Generator, size: float) -> list[Polygon]:
    """A k x k grid maze: randomised DFS spanning tree, extra openings, walls for the closed edges."""
    half = size / 2
    choices = [k for k in range(2, int(size // CELL_SIZE[0]) + 1) if CELL_SIZE[0] <= size / k <= CELL_SIZE[1]]
    k = choices[int(rng.integers(len(choices)))]
    cell = size / k
    assert cell - CORRIDOR_THICKNESS >= MIN_DOOR

    # Edges between neighbouring cells (i, j) (column i, row j), as sorted pairs of cells.
    def neighbours(c: tuple[int, int]) -> list[tuple[int, int]]:
        i, j = c
        return [(a, b) for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)) if 0 <= a < k and 0 <= b < k]

    start = (int(rng.integers(k)), int(rng.integers(k)))
    visited = {start}
    stack = [start]
    open_edges: set[tuple[tuple[int, int], tuple[int, int]]] = set()
    while stack:
        current = stack[-1]
        fresh = [c for c in neighbours(current) if c not in visited]
        if not fresh:
            stack.pop()
            continue
        nxt = fresh[int(rng.integers(len(fresh)))]
        open_edges.add(tuple(sorted((current, nxt))))
        visited.add(nxt)
        stack.append(nxt)
    closed = sorted({tuple(sorted((c, d))) for c in ((i, j) for i in range(k) for j in range(k)) for d in neighbours(c)} - open_edges)
    # 1-2 extra openings make loops; at most a third of the closed edges, so that a 3 x 3 grid (4 closed
    # edges) keeps 3 walls and a 2 x 2 grid (1 closed edge) keeps its only wall.
    extra = min(int(rng.integers(EXTRA_OPENINGS[0], EXTRA_OPENINGS[1] + 1)), len(closed) // 3)
    for index in sorted(rng.choice(len(closed), size=extra, replace=False).tolist(), reverse=True):
        del closed[index]

    # Closed edges on grid lines: vertical line x_i (i = 1..k-1) between rows j, horizontal y_j between columns i.
    vertical = {(c[0] + 1, c[1]) for c, d in closed if d[0] == c[0] + 1}  # (line i, row j)
    horizontal = {(c[1] + 1, c[0]) for c, d in closed if d[1] == c[1] + 1}  # (line j, column i)
    t = CORRIDOR_THICKNESS
    coord = [-half + cell * m for m in range(k + 1)]
    coord[0], coord[k] = -half, half

    walls: list[Polygon] = []
    # Horizontal walls run through junctions: a run of edges ends t/2 past its end vertices (flush at the boundary).
    for line in range(1, k):
        for a, b in _runs(sorted(i for ln, i in horizontal if ln == line)):
            x0 = -half if a == 0 else coord[a] - t / 2
            x1 = half if b == k else coord[b] + t / 2
            walls.append(_rectangle(x0, coord[line] - t / 2, x1, coord[line] + t / 2))
    # Vertical walls stop at the face of a horizontal wall covering their end vertex.
    for line in range(1, k):
        for a, b in _runs(sorted(j for ln, j in vertical if ln == line)):
            start_covered = (a, line - 1) in horizontal or (a, line) in horizontal
            end_covered = (b, line - 1) in horizontal or (b, line) in horizontal
            y0 = -half if a == 0 else coord[a] + (t / 2 if start_covered else -t / 2)
            y1 = half if b == k else coord[b] - (t / 2 if end_covered else -t / 2)
            walls.append(_rectangle(coord[line] - t / 2, y0, coord[line] + t / 2, y1))
    return walls


def _runs(indices: list[int]) -> list[tuple[int, int]]:
    """Maximal runs of consecutive edge indices, as (first vertex, last vertex): [0, 1, 3] -> [(0, 2), (3, 4)]."""
    runs: list[tuple[int, int]] = []
    for i in indices:
        if runs and runs[-1][1] == i:
            runs[-1] = (runs[-1][0], i + 1)
        else:
            runs.append((i, i + 1))
    return runs


def _rectangle(x0: float, y0: float, x1: float, y1: float) -> Polygon:
    return _rounded([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])  # counter-clockwise


# ---------------------------------------------------------------------- geometry helpers
def _rounded(points: Sequence[Sequence[float]]) -> Polygon:
    return tuple((round(float(x), _DECIMALS) + 0.0, round(float(y), _DECIMALS) + 0.0) for x, y in points)


def _signed_area(polygon: Polygon) -> float:
    return 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1]))


def _counter_clockwise(polygon: Polygon) -> Polygon:
    return polygon if _signed_area(polygon) > 0 else polygon[::-1]


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = float(np.clip((p - a).dot(ab) / max(ab.dot(ab), 1e-18), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def _segments_cross(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> bool:
    def cross(o, p, q):
        return (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0])

    return cross(a, b, c) * cross(a, b, d) < 0 and cross(c, d, a) * cross(c, d, b) < 0


def _polygon_distance(p: Polygon, q: Polygon) -> float:
    """Distance between two simple polygons (0 when they touch, cross or one holds the other)."""
    pa, qa = np.asarray(p, float), np.asarray(q, float)
    if _inside(pa[0], qa) or _inside(qa[0], pa):
        return 0.0
    best = math.inf
    for a, b in zip(pa, np.roll(pa, -1, axis=0)):
        for c, d in zip(qa, np.roll(qa, -1, axis=0)):
            if _segments_cross(a, b, c, d):
                return 0.0
            best = min(
                best,
                _point_segment_distance(a, c, d),
                _point_segment_distance(b, c, d),
                _point_segment_distance(c, a, b),
                _point_segment_distance(d, a, b),
            )
    return best


def _inside(point: np.ndarray, polygon: np.ndarray) -> bool:
    x, y = point
    inside = False
    for (x0, y0), (x1, y1) in zip(polygon, np.roll(polygon, -1, axis=0)):
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def maze_json(spec: MazeSpec) -> str:
    """A maze as JSON text in the layout of the built-in maze files (one obstacle a line)."""
    data = spec.to_dict()
    lines = ["{", f'  "name": {json.dumps(data["name"])},', f'  "size": {json.dumps(data["size"])},']
    if "goal" in data:
        lines.append(f'  "goal": {json.dumps(data["goal"])},')
    if data["obstacles"]:
        lines.append('  "obstacles": [')
        lines.append(",\n".join(f"    {json.dumps(poly)}" for poly in data["obstacles"]))
        lines.append("  ]")
    else:
        lines.append('  "obstacles": []')
    lines.append("}")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------- command line
def main(argv: Sequence[str] | None = None) -> int:
    """``python -m hippo_env.generate --seed S --kind K [--size M] [--name N] [--out FILE]``."""
    parser = argparse.ArgumentParser(
        prog="python -m hippo_env.generate",
        description="Write a seeded random maze as JSON (loadable with MazeSpec.load or gym.make('HippoMaze-v0', maze=FILE)).",
    )
    parser.add_argument("--seed", type=int, required=True, help="non-negative integer; the same seed gives the same maze")
    parser.add_argument("--kind", default="walls", help=f"one of: {', '.join(KINDS)} (default walls)")
    parser.add_argument("--size", type=float, default=10.0, help=f"arena side in metres, {MIN_SIZE:g}-{MAX_SIZE:g} (default 10)")
    parser.add_argument("--name", default=None, help="maze name (default gen-KIND-SEED)")
    parser.add_argument("--out", type=Path, default=None, help="JSON file to write (default: print to stdout)")
    args = parser.parse_args(argv)
    try:
        spec = generate_maze(args.seed, kind=args.kind, size=args.size, name=args.name)
    except ValueError as err:
        parser.error(str(err))
    text = maze_json(spec)
    if args.out is None:
        sys.stdout.write(text)
    else:
        args.out.write_text(text)
        print(f"wrote {spec.name} ({len(spec.obstacles)} obstacles) to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
