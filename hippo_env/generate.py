"""Seeded maze generator: random but reproducible :class:`~hippo_env.maze.MazeSpec` arenas.

Five kinds of maze, each in a square arena of side ``size`` (5-40 m, 10 m by default) centred on
the origin. Three are grids of cells with walls 0.2 m thick on the closed cell edges: a grid line's
closed edges in a row become one rectangle, and walls meeting at a junction touch but do not
overlap.

``"walls"``
    2-4 straight thin walls (rectangles 0.2-0.3 m thick and 2.5-6 m long in a 10 m arena; the
    length scales with the arena), each axis-aligned or diagonal (at 45 degrees). A wall either
    floats or touches the arena boundary with one end flush against it (a diagonal wall's end
    is cut along the boundary). Guarantees: no two walls overlap or come closer than 1.0 m to
    each other, and no wall comes closer than 1.0 m to any part of the boundary except the side
    it is flush with, so every gap a robot must pass is at least 1.0 m wide.

``"corridors"``
    A coarse grid maze with loops: the arena is cut into k x k cells of 2.5-3.4 m (k drawn
    among the grids that fit: 3 x 3 or 4 x 4 in a 10 m arena, 12 x 12 to 16 x 16 in a 40 m one), a
    randomised depth-first search carves a spanning tree of open cell edges, and 1-2 further
    edges are opened so that there are loops (one on a 3 x 3 grid, so that it keeps three walls;
    none on the 2 x 2 grid of a 5-6.8 m arena). Every door gap (an open cell edge) is at least
    1.2 m wide (in fact at least the cell size minus 0.2 m). Its cells do not grow with the
    arena, so beyond about 20 m it holds so many walls that the environment's first shortest
    path (a visibility graph over every wall corner) is slow to build; ``"perfect"`` (at most
    8 x 8 cells) suits large arenas better.

``"perfect"``
    A perfect maze: k x k cells (``cells=k``, 2 to 8; by default the k nearest to 2 m cells,
    at most 8: 5 x 5 in a 10 m arena, 8 x 8 from 15 m), carved by a randomised depth-first
    search. Guarantees: the open cell edges form a spanning tree (exactly k*k - 1 of them: every
    cell reachable, no loops, one way between any two cells), and every closed interior edge
    carries a wall. A cell is at least 1.25 m (``MIN_CELL``), so every door gap is at least
    1.05 m wide for the robot of radius 0.17 m.

``"rooms"``
    r x r rooms (``cells=r``, 2 or 3; by default 2 x 2 below 15 m and 3 x 3 from 15 m), each at
    least 2.5 m across, walled off from each other. The room graph is a spanning tree drawn by a
    randomised depth-first search plus, on a 3 x 3 grid, exactly one extra door (so one loop; a
    2 x 2 grid keeps one solid wall and no loop). The wall between two rooms joined in that graph
    has exactly one door, 1.0-1.5 m wide, at a random place along it (leaving at least 0.25 m of
    wall beside the junction at each end); every other wall between rooms is solid.

``"arena"``
    An open arena (7-40 m: ``MIN_ARENA_SIZE``) with free-standing rectangular blocks of 0.5-2 m
    a side, each turned by a random angle: 3 blocks in arenas up to 10 m, 8 from 20 m, and in
    between in proportion to the area (:func:`block_count`). No block comes closer than 1.0 m to
    another or to the boundary, so every gap is at least 1.0 m wide.

Guarantees for every kind: each obstacle is a simple polygon listed counter-clockwise (positive
signed area) with every vertex inside the arena (vertices rounded to 0.1 mm); the free space is
connected for the robot (a disc of ``physics.ROBOT_RADIUS`` = 0.17 m), checked with
:meth:`MazeSpec.check_connected` and re-drawn on failure; the same ``(seed, kind, size, cells)``
always gives the same maze, as all randomness comes from one ``numpy.random.default_rng(seed)``.

From the command line::

    python -m hippo_env.generate --seed 3 --kind walls --out maze.json
    python -m hippo_env.generate --seed 3 --kind perfect --cells 5 --size 10 --out m.json
    python -m hippo_env.generate --seed 3 --kind rooms --size 20 --out rooms.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from hippo_env.checks import check_int, check_number
from hippo_env.geometry import counter_clockwise, polygon_distance
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS

KINDS = ("walls", "corridors", "perfect", "rooms", "arena")
MIN_SIZE = 5.0  # m: the smallest arena side (a 2 x 2 corridor grid, walls 1.25-3 m long)
MAX_SIZE = 40.0  # m: the largest arena side

# kind="walls" (and the gaps of kind="arena")
WALL_COUNT = (2, 4)  # walls per maze, inclusive
WALL_THICKNESS = (0.2, 0.3)  # m
WALL_LENGTH = (2.5, 6.0)  # m in a 10 m arena; scaled with the arena's side
WALL_GAP = 1.0  # m: the narrowest gap between two walls or blocks, or a wall or block and the boundary
WALL_ANGLES = (0.0, 45.0, 90.0, 135.0)  # degrees: axis-aligned or diagonal
TOUCH_PROBABILITY = 0.5  # a wall touches the boundary (else it floats)

# the grid kinds: "corridors", "perfect", "rooms"
GRID_THICKNESS = 0.2  # m: every wall on a grid line

# kind="corridors"
CELL_SIZE = (2.5, 3.4)  # m: cells per side are chosen so that a cell's side falls in this range
EXTRA_OPENINGS = (1, 2)  # cell edges opened beyond the spanning tree, inclusive
MIN_DOOR = 1.2  # m: the narrowest door gap

# kind="perfect"
PERFECT_CELLS = (2, 8)  # cells per side, inclusive
PERFECT_CELL = 2.0  # m: the default cells per side make a cell about this wide
MIN_CELL = 1.25  # m: the smallest cell, so that a door gap (cell - 0.2 m) is >= 1.05 m

# kind="rooms"
ROOM_GRIDS = (2, 3)  # rooms per side
ROOMS_3X3_FROM = 15.0  # m: the default is 3 x 3 rooms from this arena side, 2 x 2 below it
MIN_ROOM = 2.5  # m: the smallest room
DOOR_WIDTH = (1.0, 1.5)  # m
DOOR_STUB = 0.25  # m: the least wall left between a door and the face of a junction

# kind="arena"
BLOCK_COUNT = (3, 8)  # blocks in arenas up to 10 m and from 20 m; in proportion to the area between
BLOCK_SIDE = (0.5, 2.0)  # m
MIN_ARENA_SIZE = 7.0  # m: the smallest arena side for kind="arena" (in less, 3 blocks 1 m apart rarely fit)

_DECIMALS = 4  # vertices rounded to 0.1 mm (readable JSON)
_MAX_ATTEMPTS = 1000  # whole-maze draws before giving up (a guard: a few suffice)
_PLACE_TRIES = 50  # draws per wall or block before the whole maze is drawn anew
# m: grid of the generator's connectivity check. Coarser than the environment's 5 cm (which it repeats):
# neighbouring free grid points are joined by a path with clearance >= sqrt(r^2 - (0.15/2)^2) = 0.15 m, so the
# check errs only for passages within 4 cm of the robot's diameter, and every gap here is >= 1 m.
_CONNECTIVITY_RESOLUTION = 0.15

Polygon = tuple[tuple[float, float], ...]
Box = tuple[float, float, float, float]  # an axis-aligned rectangle (x0, y0, x1, y1)
Cell = tuple[int, int]  # (column, row) of a grid cell
Edge = tuple[Cell, Cell]  # two neighbouring cells, sorted


def generate_maze(seed: int, kind: str = "walls", size: float = 10.0, name: str | None = None, cells: int | None = None) -> MazeSpec:
    """Draw a random maze, reproducibly from ``seed``.

    Args:
        seed: A non-negative integer; the same ``(seed, kind, size, cells)`` always gives the same maze.
        kind: ``"walls"`` (2-4 straight thin walls, at least 1.0 m from each other and from the
            rest of the boundary), ``"corridors"`` (a grid maze of 2.5-3.4 m cells with a few
            loops, doors at least 1.2 m wide), ``"perfect"`` (a k x k grid maze without loops,
            doors at least 1.05 m wide), ``"rooms"`` (r x r rooms joined by 1.0-1.5 m doors) or
            ``"arena"`` (3-8 free-standing blocks of 0.5-2 m, at least 1.0 m apart). See the
            module docstring for what each guarantees.
        size: The side of the square arena in metres, from 5 to 40 (7 to 40 for ``"arena"``;
            default 10). Wall lengths of ``"walls"``, the cells of ``"perfect"`` and ``"rooms"``
            and the number of blocks of ``"arena"`` scale with it; gaps, thicknesses, door widths
            and corridor cells do not.
        name: The maze's name; defaults to ``"gen-{kind}-{seed}"`` (with ``"-{size}m"`` appended
            when the arena is not 10 m, and ``"-{cells}x{cells}"`` when ``cells`` is not the default).
        cells: Cells per side of ``"perfect"`` (2 to 8, each cell at least 1.25 m) or rooms per
            side of ``"rooms"`` (2 or 3, each room at least 2.5 m); None (default) chooses from
            the size (:func:`default_cells`). The other kinds take no ``cells``.

    Returns:
        A :class:`MazeSpec` whose obstacles are simple counter-clockwise polygons inside the arena
        and whose free space is connected for the robot (radius 0.17 m).

    Raises:
        ValueError: for a negative or non-integer seed, an unknown kind, a size outside 5-40 m
            (7-40 m for ``"arena"``), ``cells`` out of range, too many cells for the size, or
            given to a kind without cells, or an empty name.
    """
    check_int(seed, "seed", 0, "a non-negative integer")
    if kind not in KINDS:
        raise ValueError(f"maze kind {kind!r} is unknown; allowed kinds: {', '.join(KINDS)}")
    size = check_number(size, "size", f"a number of metres from {MIN_SIZE:g} to {MAX_SIZE:g}")
    if not MIN_SIZE <= size <= MAX_SIZE:
        raise ValueError(f"size must be from {MIN_SIZE:g} to {MAX_SIZE:g} m, got {size:g}")
    if kind == "arena" and size < MIN_ARENA_SIZE:
        raise ValueError(
            f"size must be from {MIN_ARENA_SIZE:g} to {MAX_SIZE:g} m for kind 'arena' (room for 3 blocks 1.0 m apart), got {size:g}"
        )
    k = _check_cells(kind, size, cells)
    if name is None:
        name = f"gen-{kind}-{int(seed)}" + ("" if size == 10.0 else f"-{size:g}m")
        if cells is not None and k != default_cells(kind, size):
            name += f"-{k}x{k}"
    elif not isinstance(name, str):
        raise TypeError(f"name must be a non-empty string or None, got {name!r}")
    elif not name:
        raise ValueError(f"name must be a non-empty string or None, got {name!r}")

    rng = np.random.default_rng(int(seed))
    per_side = k if k is not None else 0  # cells or rooms per side: only "perfect" and "rooms" have them
    draw: Callable[[np.random.Generator, float], list[Polygon] | None] = {
        "walls": _draw_walls,
        "corridors": _draw_corridors,
        "perfect": lambda rng, size: _draw_perfect(rng, size, per_side),
        "rooms": lambda rng, size: _draw_rooms(rng, size, per_side),
        "arena": _draw_arena,
    }[kind]
    for _ in range(_MAX_ATTEMPTS):
        obstacles = draw(rng, size)
        if obstacles is None:
            continue
        spec = MazeSpec(name=name, size=(size, size), obstacles=tuple(obstacles))
        try:
            spec.check_connected(ROBOT_RADIUS, resolution=_CONNECTIVITY_RESOLUTION)
        except ValueError:
            continue
        return spec
    raise RuntimeError(f"found no valid {kind!r} maze for seed {seed} in a {size:g} m arena after {_MAX_ATTEMPTS} attempts")


def default_cells(kind: str, size: float) -> int | None:
    """The cells (``"perfect"``) or rooms (``"rooms"``) per side that ``generate_maze`` uses when not told; None for other kinds.

    ``"perfect"``: the count nearest to cells of ``PERFECT_CELL`` (2 m), from 2 to 8 (5 in a 10 m
    arena, 8 from 15 m). ``"rooms"``: 2 below ``ROOMS_3X3_FROM`` (15 m), 3 from it.
    """
    if kind == "perfect":
        return int(min(max(math.floor(size / PERFECT_CELL + 0.5), PERFECT_CELLS[0]), PERFECT_CELLS[1]))
    if kind == "rooms":
        return ROOM_GRIDS[0] if size < ROOMS_3X3_FROM else ROOM_GRIDS[1]
    return None


def block_count(size: float) -> int:
    """Blocks in an ``"arena"`` maze: 3 up to 10 m, 8 from 20 m, in proportion to the area between."""
    low, high = BLOCK_COUNT
    share = (size * size - 100.0) / (400.0 - 100.0)
    return int(min(max(math.floor(low + (high - low) * share + 0.5), low), high))


def _check_cells(kind: str, size: float, cells: int | None) -> int | None:
    """``cells`` validated for ``kind`` and ``size`` (None: the default); a ValueError naming what is allowed."""
    if kind not in ("perfect", "rooms"):
        if cells is not None:
            raise ValueError(
                f"cells is only for kinds 'perfect' (2-8 cells) and 'rooms' (2 or 3 rooms); kind {kind!r} takes none, got {cells!r}"
            )
        return None
    if cells is None:
        return default_cells(kind, size)
    low, high, smallest, what = (*PERFECT_CELLS, MIN_CELL, "cell") if kind == "perfect" else (*ROOM_GRIDS, MIN_ROOM, "room")
    allowed = f"an integer from {low} to {high} for kind {kind!r}"
    if check_int(cells, "cells", low, allowed) > high:
        raise ValueError(f"cells must be {allowed}, got {cells!r}")
    if size / cells < smallest - 1e-9:
        raise ValueError(
            f"cells={cells} is too many for a {size:g} m arena: a {what} would be {size / cells:.2f} m, less than the "
            f"{smallest:g} m a {what} needs; give a size of at least {smallest * cells:g} m or fewer cells "
            f"(at most {math.floor(size / smallest + 1e-9)})"
        )
    return int(cells)


# ---------------------------------------------------------------------- kind="walls"
def _draw_walls(rng: np.random.Generator, size: float) -> list[Polygon] | None:
    """2-4 walls at least WALL_GAP apart, or None when one of them found no room (draw again)."""
    half = size / 2
    scale = size / 10.0
    count = int(rng.integers(WALL_COUNT[0], WALL_COUNT[1] + 1))
    return _spaced(count, lambda: _draw_wall(rng, half, scale))


def _spaced(count: int, draw: Callable[[], Polygon | None]) -> list[Polygon] | None:
    """``count`` polygons from ``draw`` (None: no room), each at least WALL_GAP from the others; None if one found no room."""
    placed: list[Polygon] = []
    for _ in range(count):
        for _ in range(_PLACE_TRIES):
            polygon = draw()
            if polygon is not None and all(polygon_distance(polygon, other) >= WALL_GAP for other in placed):
                placed.append(polygon)
                break
        else:
            return None
    return placed


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
        polygon = tuple((_on_side(p, axis, edge) if k in (0, 3) else p) for k, p in enumerate(polygon))
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
    return counter_clockwise(polygon)


def _on_side(point: tuple[float, float], axis: int, edge: float) -> tuple[float, float]:
    """``point`` with its coordinate ``axis`` set to ``edge``: moved onto the side of the arena."""
    return (edge, point[1]) if axis == 0 else (point[0], edge)


def _side_distance(polygon: Polygon, half: float, side: int) -> float:
    """Distance from a polygon inside the arena to one of its sides (0 bottom, 1 right, 2 top, 3 left)."""
    pts = np.asarray(polygon)
    return float({0: pts[:, 1] + half, 1: half - pts[:, 0], 2: half - pts[:, 1], 3: pts[:, 0] + half}[side].min())


# ---------------------------------------------------------------------- kind="arena"
def _draw_arena(rng: np.random.Generator, size: float) -> list[Polygon] | None:
    """block_count(size) blocks at least WALL_GAP apart and from the boundary, or None (draw again)."""
    return _spaced(block_count(size), lambda: _draw_block(rng, size / 2))


def _draw_block(rng: np.random.Generator, half: float) -> Polygon | None:
    """One rectangle of BLOCK_SIDE sides turned by a random angle; None when it comes too close to the boundary."""
    width, height = rng.uniform(*BLOCK_SIDE, size=2)
    angle = rng.uniform(0.0, math.pi / 2)
    u = np.array([math.cos(angle), math.sin(angle)])
    n = np.array([-u[1], u[0]])
    centre = rng.uniform(-half + WALL_GAP, half - WALL_GAP, size=2)
    polygon = _rounded([centre + su * width / 2 * u + sn * height / 2 * n for su, sn in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    if min(_side_distance(polygon, half, s) for s in range(4)) < WALL_GAP:
        return None
    return counter_clockwise(polygon)


# ---------------------------------------------------------------------- the grid kinds
def _draw_corridors(rng: np.random.Generator, size: float) -> list[Polygon]:
    """A k x k grid maze: randomised DFS spanning tree, extra openings, walls for the closed edges."""
    choices = [k for k in range(2, int(size // CELL_SIZE[0]) + 1) if CELL_SIZE[0] <= size / k <= CELL_SIZE[1]]
    k = choices[int(rng.integers(len(choices)))]
    assert size / k - GRID_THICKNESS >= MIN_DOOR
    closed = sorted(set(_grid_edges(k)) - _spanning_tree(rng, k))
    # 1-2 extra openings make loops; at most a third of the closed edges, so that a 3 x 3 grid (4 closed
    # edges) keeps 3 walls and a 2 x 2 grid (1 closed edge) keeps its only wall.
    extra = min(int(rng.integers(EXTRA_OPENINGS[0], EXTRA_OPENINGS[1] + 1)), len(closed) // 3)
    for index in sorted(rng.choice(len(closed), size=extra, replace=False).tolist(), reverse=True):
        del closed[index]
    return [_rectangle(*box) for box in _grid_walls(k, size, closed)]


def _draw_perfect(rng: np.random.Generator, size: float, k: int) -> list[Polygon]:
    """A k x k perfect maze: a randomised DFS spanning tree, a wall on every other interior edge."""
    closed = sorted(set(_grid_edges(k)) - _spanning_tree(rng, k))
    return [_rectangle(*box) for box in _grid_walls(k, size, closed)]


def _draw_rooms(rng: np.random.Generator, size: float, r: int) -> list[Polygon]:
    """r x r walled rooms; one door in each wall between rooms joined by a spanning tree (plus one extra edge on 3 x 3)."""
    doors = _spanning_tree(rng, r)
    if r >= 3:  # one loop
        closed = sorted(set(_grid_edges(r)) - doors)
        doors.add(closed[int(rng.integers(len(closed)))])
    room = size / r
    coord = _grid_lines(r, size)
    boxes = _grid_walls(r, size, _grid_edges(r))
    margin = GRID_THICKNESS / 2 + DOOR_STUB  # from the edge's end vertex to the door
    for (i, j), (a, _) in sorted(doors):
        width = rng.uniform(*DOOR_WIDTH)
        start = rng.uniform(margin, room - margin - width)
        if a == i + 1:  # rooms side by side: a door in the vertical line a, along row j
            boxes = _cut(boxes, 1, coord[a], coord[j] + start, coord[j] + start + width)
        else:  # rooms one above the other: a door in the horizontal line j + 1, along column i
            boxes = _cut(boxes, 0, coord[j + 1], coord[i] + start, coord[i] + start + width)
    return [_rectangle(*box) for box in boxes]


def _grid_edges(k: int) -> list[Edge]:
    """Every interior edge of a k x k grid of cells (column i, row j), as sorted pairs of neighbouring cells."""
    return sorted({_edge(c, d) for c in ((i, j) for i in range(k) for j in range(k)) for d in _neighbours(c, k)})


def _edge(c: Cell, d: Cell) -> Edge:
    """The edge between neighbouring cells ``c`` and ``d``, as the sorted pair."""
    return (c, d) if c <= d else (d, c)


def _neighbours(cell: Cell, k: int) -> list[Cell]:
    i, j = cell
    return [(a, b) for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)) if 0 <= a < k and 0 <= b < k]


def _spanning_tree(rng: np.random.Generator, k: int) -> set[Edge]:
    """The open edges of a randomised depth-first search from a random cell: a spanning tree, k*k - 1 edges."""
    start = (int(rng.integers(k)), int(rng.integers(k)))
    visited = {start}
    stack = [start]
    tree: set[Edge] = set()
    while stack:
        current = stack[-1]
        fresh = [c for c in _neighbours(current, k) if c not in visited]
        if not fresh:
            stack.pop()
            continue
        nxt = fresh[int(rng.integers(len(fresh)))]
        tree.add(_edge(current, nxt))
        visited.add(nxt)
        stack.append(nxt)
    return tree


def _grid_lines(k: int, size: float) -> list[float]:
    """The k + 1 grid line coordinates of a k x k grid over the arena, the outer two exactly on the boundary."""
    half, cell = size / 2, size / k
    coord = [-half + cell * m for m in range(k + 1)]
    coord[0], coord[k] = -half, half
    return coord


def _grid_walls(k: int, size: float, closed: Sequence[Edge]) -> list[Box]:
    """Walls GRID_THICKNESS thick on the ``closed`` edges of a k x k grid, collinear edges merged into one box.

    Horizontal walls run through junctions; vertical ones stop at the face of a horizontal wall,
    so that walls touch but never overlap. Walls reaching the boundary end flush with it.
    """
    half = size / 2
    # Closed edges on grid lines: vertical line x_i (i = 1..k-1) between rows j, horizontal y_j between columns i.
    vertical = {(c[0] + 1, c[1]) for c, d in closed if d[0] == c[0] + 1}  # (line i, row j)
    horizontal = {(c[1] + 1, c[0]) for c, d in closed if d[1] == c[1] + 1}  # (line j, column i)
    t = GRID_THICKNESS
    coord = _grid_lines(k, size)

    boxes: list[Box] = []
    # Horizontal walls run through junctions: a run of edges ends t/2 past its end vertices (flush at the boundary).
    for line in range(1, k):
        for a, b in _runs(sorted(i for ln, i in horizontal if ln == line)):
            x0 = -half if a == 0 else coord[a] - t / 2
            x1 = half if b == k else coord[b] + t / 2
            boxes.append((x0, coord[line] - t / 2, x1, coord[line] + t / 2))
    # Vertical walls stop at the face of a horizontal wall covering their end vertex.
    for line in range(1, k):
        for a, b in _runs(sorted(j for ln, j in vertical if ln == line)):
            start_covered = (a, line - 1) in horizontal or (a, line) in horizontal
            end_covered = (b, line - 1) in horizontal or (b, line) in horizontal
            y0 = -half if a == 0 else coord[a] + (t / 2 if start_covered else -t / 2)
            y1 = half if b == k else coord[b] - (t / 2 if end_covered else -t / 2)
            boxes.append((coord[line] - t / 2, y0, coord[line] + t / 2, y1))
    return boxes


def _cut(boxes: list[Box], axis: int, line: float, low: float, high: float) -> list[Box]:
    """Cut the gap ``low``-``high`` (along ``axis``: 0 x, 1 y) out of the wall on the grid line at ``line``."""
    across = 1 - axis
    out: list[Box] = []
    for box in boxes:
        on_line = abs((box[across] + box[across + 2]) / 2 - line) < 1e-9 and box[across + 2] - box[across] < GRID_THICKNESS + 1e-9
        if not on_line or box[axis + 2] <= low or high <= box[axis]:
            out.append(box)
            continue
        for lo, hi in ((box[axis], low), (high, box[axis + 2])):
            if hi > lo:
                piece = list(box)
                piece[axis], piece[axis + 2] = lo, hi
                out.append((piece[0], piece[1], piece[2], piece[3]))
    return out


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


# ---------------------------------------------------------------------- vertices
def _rounded(points: Sequence[Sequence[float]]) -> Polygon:
    return tuple((round(float(x), _DECIMALS) + 0.0, round(float(y), _DECIMALS) + 0.0) for x, y in points)


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
_KINDS_HELP = """kinds (every gap at least 1.0 m for the 0.17 m robot; free space connected):
  walls      2-4 straight thin walls, axis-aligned or diagonal, floating or flush with one side
  corridors  grid maze of 2.5-3.4 m cells, spanning tree plus up to 2 loops; doors >= 1.2 m
  perfect    k x k grid maze (--cells 2-8, default ~2 m cells), spanning tree: no loops; doors >= 1.05 m
  rooms      r x r rooms (--cells 2 or 3, default 3 from 15 m), joined by 1.0-1.5 m doors along a
             spanning tree (plus one extra door on 3 x 3)
  arena      open arena (7-40 m) with 3-8 free-standing blocks of 0.5-2 m (more in larger arenas)

example: python -m hippo_env.generate --kind perfect --cells 5 --size 10 --seed 3 --out m.json"""


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m hippo_env.generate --seed S [--kind K] [--size M] [--cells C] [--name N] [--out FILE]``."""
    parser = argparse.ArgumentParser(
        prog="python -m hippo_env.generate",
        description="Write a seeded random maze as JSON (loadable with MazeSpec.load or gym.make('HippoMaze-v0', maze=FILE)).",
        epilog=_KINDS_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--seed", type=int, required=True, help="non-negative integer; the same arguments give the same maze")
    parser.add_argument("--kind", default="walls", help=f"one of: {', '.join(KINDS)} (default walls; see below)")
    parser.add_argument("--size", type=float, default=10.0, help=f"arena side in metres, {MIN_SIZE:g}-{MAX_SIZE:g} (default 10)")
    parser.add_argument(
        "--cells",
        type=int,
        default=None,
        help=f"perfect: cells per side, {PERFECT_CELLS[0]}-{PERFECT_CELLS[1]}, each >= {MIN_CELL:g} m; "
        f"rooms: rooms per side, {ROOM_GRIDS[0]} or {ROOM_GRIDS[1]}, each >= {MIN_ROOM:g} m (default: from the size)",
    )
    parser.add_argument("--name", default=None, help="maze name (default gen-KIND-SEED)")
    parser.add_argument("--out", type=Path, default=None, help="JSON file to write (default: print to stdout)")
    args = parser.parse_args(argv)
    try:
        spec = generate_maze(args.seed, kind=args.kind, size=args.size, name=args.name, cells=args.cells)
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
