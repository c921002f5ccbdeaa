"""Seeded changes of a maze: a world that changes while the goal stays.

Three kinds, each a new :class:`~hippo_env.maze.MazeSpec` drawn from a seed (the same seed, the
same change), its free space still connected for the robot, never covering the points given in
``keep_clear`` (a goal, say):

``"blocks"``
    New barriers: ``count`` square blocks of ``side`` metres on the arena's grid of that side
    (a 10 m arena holds 10 x 10 cells of 1 m), each at least 0.5 m from the maze's obstacles.
``"door"``
    A shortcut: a gap of ``width`` metres cut in a straight wall, where it shortens the way
    between the two sides of the wall the most.
``"barrier"``
    A detour: a bar across a gap of 0.6-3 m between an obstacle's corner and another wall,
    where it lengthens the way between the two sides of the gap the most.

Use :func:`change_maze` (``reset(options={"maze": changed})`` puts the change in an environment),
or from the shell ``python -m hippo_env.changes open blocks --seed 3 --count 12 > changed.json``.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

import numpy as np

from hippo_env.geometry import segments_clearance
from hippo_env.maze import MazeSpec

__all__ = ["CHANGES", "add_blocks", "change_maze", "close_gap", "open_door"]

CHANGES = ("blocks", "door", "barrier")
ROBOT_RADIUS = 0.17  # m (hippo_env.physics.ROBOT_RADIUS; physics imports this package's maze module, not the reverse)
BLOCK_GAP = 0.5  # m: a new block keeps this far from the maze's obstacles
KEEP_CLEAR = 0.6  # m: a change keeps this far from every point given in keep_clear
DOOR_STUB = 0.25  # m: the least wall a door leaves between itself and the wall's end, unless it opens the end
GAP_RANGE = (0.6, 3.0)  # m: the gaps a barrier may close
BAR_THICKNESS = 0.2  # m
CANDIDATES = 60  # doors or barriers weighed per change
MIN_EFFECT = 1.0  # m: the least a door must shorten, or a barrier lengthen, the way across it

Point = tuple[float, float]
Polygon = tuple[Point, ...]


def change_maze(
    spec: MazeSpec | str,
    change: str,
    seed: int,
    *,
    keep_clear: Sequence[Sequence[float]] = (),
    count: int = 12,
    side: float = 1.0,
    width: float = 1.2,
    name: str | None = None,
) -> MazeSpec:
    """``spec`` changed by ``change`` (one of :data:`CHANGES`; see the module docstring), drawn
    from ``seed``. ``count`` and ``side`` are the blocks', ``width`` the door's."""
    spec = MazeSpec.load(spec)
    if change not in CHANGES:
        raise ValueError(f"change {change!r} is unknown; allowed: {', '.join(CHANGES)}")
    rng = np.random.default_rng(seed)
    clear = [(float(p[0]), float(p[1])) for p in keep_clear]
    if change == "blocks":
        obstacles = _blocks(spec, rng, count, side, clear)
        label = f"blocks{count}"
    elif change == "door":
        obstacles = _door(spec, rng, width)
        label = "door"
    else:
        obstacles = _barrier(spec, rng, clear)
        label = "barrier"
    changed = MazeSpec(name or f"{spec.name}+{label}-{seed}", spec.size, tuple(obstacles), spec.goal)
    changed.check_connected(ROBOT_RADIUS)
    return changed


def add_blocks(spec: MazeSpec | str, seed: int, count: int = 12, side: float = 1.0, keep_clear: Sequence[Sequence[float]] = ()) -> MazeSpec:
    """New barriers: :func:`change_maze` with ``"blocks"``."""
    return change_maze(spec, "blocks", seed, keep_clear=keep_clear, count=count, side=side)


def open_door(spec: MazeSpec | str, seed: int, width: float = 1.2) -> MazeSpec:
    """A shortcut: :func:`change_maze` with ``"door"``."""
    return change_maze(spec, "door", seed, width=width)


def close_gap(spec: MazeSpec | str, seed: int, keep_clear: Sequence[Sequence[float]] = ()) -> MazeSpec:
    """A detour: :func:`change_maze` with ``"barrier"``."""
    return change_maze(spec, "barrier", seed, keep_clear=keep_clear)


# ------------------------------------------------------------------ blocks
def _blocks(spec: MazeSpec, rng: np.random.Generator, count: int, side: float, clear: list[Point]) -> list[Polygon]:
    if count < 1 or side <= 0:
        raise ValueError(f"blocks: count={count} and side={side} are invalid; allowed: count >= 1 and side > 0")
    hw, hh = spec.half_extent
    columns, rows = round(2 * hw / side), round(2 * hh / side)
    walls = spec.segments[4:]  # the obstacles' edges (the arena's four walls come first)
    cells = [(i, j) for i in range(columns) for j in range(rows)]
    order = rng.permutation(len(cells))
    obstacles = list(spec.obstacles)
    added = 0
    for k in order.tolist():
        i, j = cells[k]
        x0, y0 = -hw + i * side, -hh + j * side
        block = _rectangle(x0, y0, x0 + side, y0 + side)
        if not _clear_of(block, walls, spec, BLOCK_GAP) or any(_distance_to_box(p, x0, y0, side) < KEEP_CLEAR for p in clear):
            continue
        trial = MazeSpec(spec.name, spec.size, (*obstacles, block))
        try:
            trial.check_connected(ROBOT_RADIUS)
        except ValueError:
            continue
        obstacles.append(block)
        added += 1
        if added == count:
            return obstacles
    raise ValueError(f"maze {spec.name!r}: only {added} of {count} blocks of {side} m fit with the free space connected")


def _clear_of(polygon: Polygon, walls: np.ndarray, spec: MazeSpec, gap: float) -> bool:
    """Whether ``polygon`` stays ``gap`` from the maze's obstacles (tested along its edges and inside)."""
    xs = [p[0] for p in polygon]
    ys = [p[1] for p in polygon]
    samples = [(x, y) for x in np.linspace(min(xs), max(xs), 5) for y in np.linspace(min(ys), max(ys), 5)]
    if any(spec.inside_obstacle(p) for p in samples):
        return False
    return walls.size == 0 or min(segments_clearance(x, y, walls) for x, y in samples) >= gap


def _distance_to_box(p: Point, x0: float, y0: float, side: float) -> float:
    dx = max(x0 - p[0], 0.0, p[0] - (x0 + side))
    dy = max(y0 - p[1], 0.0, p[1] - (y0 + side))
    return math.hypot(dx, dy)


# ------------------------------------------------------------------ doors
def _door(spec: MazeSpec, rng: np.random.Generator, width: float) -> list[Polygon]:
    """Cut the most useful of ``CANDIDATES`` random doors in the maze's straight walls."""
    walls = [(n, r) for n, poly in enumerate(spec.obstacles) if (r := _as_rectangle(poly)) is not None and r[2] >= width + DOOR_STUB]
    if not walls:
        raise ValueError(f"maze {spec.name!r} has no straight wall at least {width + DOOR_STUB:g} m long to cut a door in")
    best: tuple[float, int, list[Polygon]] | None = None
    for _ in range(CANDIDATES):
        n, (origin, along, length, across, thickness) = walls[int(rng.integers(len(walls)))]
        start = float(rng.uniform(0.0, length - width))
        if 0.0 < start < DOOR_STUB:
            start = 0.0  # (a stub this short is no wall: open the end)
        end = start + width if length - (start + width) >= DOOR_STUB else length
        pieces = [_strip(origin, along, across, a, b, thickness) for a, b in ((0.0, start), (end, length)) if b - a > 1e-9]
        centre = origin + along * (start + end) / 2 + across * thickness / 2
        sides = [tuple(centre + s * across * (thickness / 2 + 0.6)) for s in (1.0, -1.0)]
        if min(spec.clearances(sides)) < ROBOT_RADIUS + 0.05:
            continue
        effect = spec.geodesic(sides[0], sides[1], ROBOT_RADIUS) - math.dist(sides[0], sides[1])
        if best is None or effect > best[0]:
            best = (effect, n, pieces)
    if best is None or best[0] < MIN_EFFECT:
        raise ValueError(f"maze {spec.name!r}: no door of {width:g} m found that shortens the way by {MIN_EFFECT:g} m or more")
    _, n, pieces = best
    return [poly for k, poly in enumerate(spec.obstacles) if k != n] + pieces


def _as_rectangle(poly: Polygon) -> tuple[np.ndarray, np.ndarray, float, np.ndarray, float] | None:
    """A 4-vertex rectangle as (a corner, the unit vector along its long side, that side's length,
    the unit vector across it, its thickness); ``None`` for any other polygon."""
    if len(poly) != 4:
        return None
    p = np.asarray(poly, dtype=float)
    e1, e2 = p[1] - p[0], p[3] - p[0]
    if abs(float(e1 @ e2)) > 1e-6 * (np.linalg.norm(e1) * np.linalg.norm(e2)) or np.linalg.norm(p[0] + e1 + e2 - p[2]) > 1e-6:
        return None
    if np.linalg.norm(e1) < np.linalg.norm(e2):
        e1, e2 = e2, e1
    length, thickness = float(np.linalg.norm(e1)), float(np.linalg.norm(e2))
    return p[0], e1 / length, length, e2 / thickness, thickness


def _strip(origin: np.ndarray, along: np.ndarray, across: np.ndarray, a: float, b: float, thickness: float) -> Polygon:
    """The part of a rectangle from ``a`` to ``b`` along it."""
    corners = [origin + along * a, origin + along * b, origin + along * b + across * thickness, origin + along * a + across * thickness]
    return tuple((round(float(c[0]), 4), round(float(c[1]), 4)) for c in corners)


# ------------------------------------------------------------------ barriers
def _barrier(spec: MazeSpec, rng: np.random.Generator, clear: list[Point]) -> list[Polygon]:
    """Close the gap that lengthens the way across it the most, of ``CANDIDATES`` random obstacle corners."""
    corners = [(n, c) for n, poly in enumerate(spec.obstacles) for c in poly]
    if not corners:
        raise ValueError(f"maze {spec.name!r} has no obstacle: no gap to close (add blocks instead)")
    best: tuple[float, Polygon] | None = None
    for k in rng.permutation(len(corners))[:CANDIDATES].tolist():
        n, corner = corners[k]
        target = _nearest_other_wall(spec, n, corner)
        if target is None:
            continue
        gap = math.dist(corner, target)
        if not GAP_RANGE[0] <= gap <= GAP_RANGE[1] or spec.clearance(((corner[0] + target[0]) / 2, (corner[1] + target[1]) / 2)) < 0.2:
            continue
        bar = _bar(corner, target)
        if any(_point_segment_distance(p, corner, target) < KEEP_CLEAR for p in clear):
            continue
        trial = MazeSpec(spec.name, spec.size, (*spec.obstacles, bar))
        try:
            trial.check_connected(ROBOT_RADIUS)
        except ValueError:
            continue
        mid = np.array([(corner[0] + target[0]) / 2, (corner[1] + target[1]) / 2])
        normal = np.array([corner[1] - target[1], target[0] - corner[0]]) / gap
        sides = [tuple(mid + s * normal * 0.6) for s in (1.0, -1.0)]
        if min(trial.clearances(sides)) < ROBOT_RADIUS + 0.05:
            continue
        effect = trial.geodesic(sides[0], sides[1], ROBOT_RADIUS) - spec.geodesic(sides[0], sides[1], ROBOT_RADIUS)
        if best is None or effect > best[0]:
            best = (effect, bar)
    if best is None or best[0] < MIN_EFFECT:
        raise ValueError(
            f"maze {spec.name!r}: no gap of {GAP_RANGE[0]:g}-{GAP_RANGE[1]:g} m found whose closing leaves the maze connected and lengthens the way by {MIN_EFFECT:g} m or more"
        )
    return [*spec.obstacles, best[1]]


def _nearest_other_wall(spec: MazeSpec, own: int, corner: Point) -> Point | None:
    """The nearest point to ``corner`` on a wall that is not of obstacle ``own`` (the arena's included)."""
    best, where = math.inf, None
    hw, hh = spec.half_extent
    edges = [((-hw, -hh), (hw, -hh)), ((hw, -hh), (hw, hh)), ((hw, hh), (-hw, hh)), ((-hw, hh), (-hw, -hh))]
    for n, poly in enumerate(spec.obstacles):
        if n != own:
            edges += list(zip(poly, poly[1:] + poly[:1]))
    for a, b in edges:
        q = _closest_on_segment(corner, a, b)
        d = math.dist(corner, q)
        if 1e-6 < d < best:
            best, where = d, q
    return where


def _closest_on_segment(p: Point, a: Point, b: Point) -> Point:
    ax, ay, bx, by = *a, *b
    dx, dy = bx - ax, by - ay
    length_sq = dx * dx + dy * dy
    t = 0.0 if length_sq == 0 else min(1.0, max(0.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / length_sq))
    return ax + t * dx, ay + t * dy


def _point_segment_distance(p: Point, a: Point, b: Point) -> float:
    return math.dist(p, _closest_on_segment(p, a, b))


def _bar(a: Point, b: Point) -> Polygon:
    """A bar of ``BAR_THICKNESS`` from ``a`` to ``b``."""
    length = math.dist(a, b)
    nx, ny = (a[1] - b[1]) / length * BAR_THICKNESS / 2, (b[0] - a[0]) / length * BAR_THICKNESS / 2
    corners = [(a[0] + nx, a[1] + ny), (b[0] + nx, b[1] + ny), (b[0] - nx, b[1] - ny), (a[0] - nx, a[1] - ny)]
    return tuple((round(x, 4), round(y, 4)) for x, y in corners)


def _rectangle(x0: float, y0: float, x1: float, y1: float) -> Polygon:
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m hippo_env.changes MAZE CHANGE --seed S``: the changed maze as JSON on stdout."""
    from hippo_env.generate import maze_json

    parser = argparse.ArgumentParser(prog="python -m hippo_env.changes", description=__doc__.split("\n\n")[0])
    parser.add_argument("maze", help="a built-in maze name or a maze JSON file")
    parser.add_argument("change", choices=CHANGES)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--count", type=int, default=12, help="blocks (default: 12)")
    parser.add_argument("--side", type=float, default=1.0, help="a block's side, m (default: 1)")
    parser.add_argument("--width", type=float, default=1.2, help="a door's width, m (default: 1.2)")
    parser.add_argument(
        "--keep-clear",
        type=float,
        nargs=2,
        action="append",
        default=[],
        metavar=("X", "Y"),
        help="a point the change leaves free (repeatable)",
    )
    args = parser.parse_args(argv)
    try:
        changed = change_maze(
            args.maze, args.change, args.seed, keep_clear=args.keep_clear, count=args.count, side=args.side, width=args.width
        )
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(maze_json(changed))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
