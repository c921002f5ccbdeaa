"""Directed exploration: a map of what the rangefinder has shown, and a planner that heads for
what the map does not know yet.

Rats do not random-walk a new place: they explore it systematically. This module gives the
agent that ability from its own senses only: the rangefinder scan, the compass, and the
path-integration estimate (:mod:`hippo_agent.cells.path_integration`), never the true position.

The map is a grid in the path-integration frame (``cell`` metres a side) holding, per cell,

- how often a ray passed through it (*free*) and how often a ray ended in it (*hits*): a cell
  hit at least as often as passed is a wall;
- whether the robot has ever been within ``visit_radius`` of it (*visited*), and whether it has
  been within ``search_radius`` of it in the current run (*searched*).

A cell is *walkable* when it is known free and no wall lies within one cell of it (the robot's
radius, 0.17 m, fits inside a 0.25 m cell). The planner runs a breadth-first search over walkable
cells from the robot's cell and heads straight for the farthest point of the path, at most
``lookahead`` metres along it, that a straight line from the robot reaches over walkable cells
(the search's 8-connected paths zig-zag; the robot need not), along a path to

- the nearest walkable cell not yet visited (:meth:`ExplorationMap.heading_to_unvisited`: the
  dry run's sweep), or not yet searched in this run (the search for a hidden goal), or
- a given cell (:meth:`ExplorationMap.heading_to`: a transit across known ground), or
- walkable ground near a place (:meth:`ExplorationMap.heading_to_near`: homing, and the local
  search round the place). This search, made at every step of homing, is an A* search toward
  the place: it finds paths exactly as short as the breadth-first search's over the same cells,
  but expands only the cells along its way, not every cell nearer than the place. While the
  robot stays in one cell and the grids do not change (the map's *revision* counts the
  changes), the path is the same: it is searched once. Whether a cell is walkable, which every
  search asks of the cells it reaches, is likewise worked out once per revision.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["ExplorationMap"]


class ExplorationMap:
    """The occupancy and visit map in the path-integration frame, and the planner (module docstring).

    Args:
        extent: the map covers ``[-extent, extent]`` metres on both axes around the frame's origin.
        cell: grid cell side (m).
        visit_radius: cells within this distance (m) of the robot count as visited.
        search_radius: cells within this distance (m) count as searched in the current run.
        lookahead: the planner heads for the farthest point in sight at most this far (m) along its path.
        free_range: a ray marks cells free up to this distance (m).
        hit_range: a ray ending nearer than this (m) marks a wall.
        ray_stride_deg: one ray of a scan every this many degrees enters the map.
        agreement_stride_deg: one ray every this many degrees is compared with the map (:meth:`scan_agreement`).
    (The agent's values are :meth:`hippo_agent.AgentConfig.map_kwargs`.)
    """

    def __init__(
        self,
        extent: float,
        cell: float,
        visit_radius: float,
        search_radius: float,
        lookahead: float,
        *,
        free_range: float,
        hit_range: float,
        ray_stride_deg: float,
        agreement_stride_deg: float,
    ) -> None:
        self.extent = float(extent)
        self.cell = float(cell)
        # 1 / cell where multiplying by it is exactly dividing by cell (cell a power of two, as the
        # default 0.25 m), else 0: the compiled ray marches then divide (see _grid_index)
        self._inv_cell = 1.0 / self.cell if math.frexp(self.cell)[0] == 0.5 else 0.0
        self.visit_radius = float(visit_radius)
        self.search_radius = float(search_radius)
        self.lookahead_cells = max(1, round(lookahead / cell))
        self.free_range = float(free_range)
        self.hit_range = float(hit_range)
        self.ray_stride_deg = float(ray_stride_deg)
        self.agreement_stride_deg = float(agreement_stride_deg)
        n = math.ceil(2 * self.extent / self.cell)
        self.n = n
        self.free = np.zeros((n, n), dtype=np.uint16)
        self.hits = np.zeros((n, n), dtype=np.uint16)
        self.visited = np.zeros((n, n), dtype=np.bool_)
        self.searched = np.zeros((n, n), dtype=np.bool_)
        # scratch for the search: a stamp per cell (which search reached it), its parent, a queue
        self._stamp = np.zeros(n * n, dtype=np.int32)
        self._parent = np.zeros(n * n, dtype=np.int32)
        self._queue = np.zeros(n * n, dtype=np.int32)
        self._depth = np.zeros(n * n, dtype=np.int32)
        # and whether a cell is walkable, worked out once per state of the grids (_walk_id)
        self._walk_stamp = np.zeros(n * n, dtype=np.int32)
        self._walk = np.zeros(n * n, dtype=np.bool_)
        self._walk_ids, self._walk_revision = 0, -1
        # the search into a disk (A*): path lengths so far, cells done, and its priority queue
        self._steps = np.zeros(n * n, dtype=np.int32)
        self._closed = np.zeros(n * n, dtype=np.int32)
        self._heap = np.zeros(8 * n * n, dtype=np.int64)
        self._heap_cells = np.zeros(8 * n * n, dtype=np.int32)
        self._search_id = np.zeros(1, dtype=np.int32)
        self._nothing = np.zeros((n, n), dtype=np.bool_)  # "none done" for a search into a disk (never written)
        self.revision = 0  # counts the changes to free and hits
        # the last search into a disk with nothing done: its start cell, disk, squeeze and the
        # grids' revision, and the cell found (its path back is in _parent until the next search)
        self._last_plan: tuple[int, int, float, float, float, bool, int] | None = None
        self._last_found = -1

    # ------------------------------------------------------------------ senses
    def observe(
        self,
        position: np.ndarray,
        heading: float,
        ranges: np.ndarray,
        max_range: float,
        unknown_only: bool = False,
        search_radius: float | None = None,
    ) -> None:
        """Enter one scan (egocentric ``ranges``, ray ``i`` at ``heading + 2 pi i / n``) seen from
        ``position`` (frame metres), and mark the cells around ``position`` visited and searched
        (within ``search_radius``, by default the map's). With ``unknown_only``, the scan enters
        only the cells the map knows nothing of yet: what it knows stays as it is."""
        n_rays = ranges.size
        stride = max(1, round(n_rays * self.ray_stride_deg / 360.0))
        if _enter_scan(
            self.free, self.hits, float(position[0]), float(position[1]), float(heading), ranges, stride,
            float(max_range), self.extent, self.cell, self._inv_cell, self.free_range, self.hit_range, unknown_only,
        ):  # fmt: skip
            self.revision += 1
        _mark_disk(self.visited, float(position[0]), float(position[1]), self.visit_radius, self.extent, self.cell)
        radius = self.search_radius if search_radius is None else float(search_radius)
        _mark_disk(self.searched, float(position[0]), float(position[1]), radius, self.extent, self.cell)

    def forget_searched_near(self, centre: np.ndarray, radius: float) -> None:
        """Count the ground within ``radius`` of ``centre`` as not searched in this run."""
        inside = np.zeros_like(self.searched)
        _mark_disk(inside, float(centre[0]), float(centre[1]), float(radius), self.extent, self.cell)
        self.searched[inside] = False

    def mark_bump(self, position: np.ndarray, heading: float, distance: float) -> None:
        """A bump: the cell ``distance`` ahead is a wall, whatever the rays said."""
        i, j = self.index(position[0] + distance * math.cos(heading), position[1] + distance * math.sin(heading))
        if 0 <= i < self.n and 0 <= j < self.n:
            self.hits[i, j] = min(int(self.hits[i, j]) + int(self.free[i, j]) + 1, 65535)
            self.revision += 1

    def wall_near(self, position: np.ndarray, heading: float, distance: float) -> bool:
        """Whether the map holds a wall within one cell of the point ``distance`` ahead of
        ``position`` along ``heading``: where a bump there was to be expected."""
        i, j = self.index(position[0] + distance * math.cos(heading), position[1] + distance * math.sin(heading))
        rows, cols = slice(max(i - 1, 0), max(i + 2, 0)), slice(max(j - 1, 0), max(j + 2, 0))
        hits, free = self.hits[rows, cols], self.free[rows, cols]
        return bool(np.any((hits > 0) & (hits >= free)))

    def grids_replaced(self) -> None:
        """Call after writing ``free`` or ``hits`` other than through :meth:`observe` and
        :meth:`mark_bump` (as loading a saved agent does): searches made on the old grids, and the
        walkability they worked out, are not reused."""
        self.revision += 1

    def scan_agreement(
        self, points: np.ndarray, heading: float, ranges: np.ndarray, max_range: float, around: np.ndarray | None = None
    ) -> np.ndarray:
        """How well a scan seen from each of ``points`` (an (n, 2) array, frame metres) fits the
        map, in [-1, 1]: per ray, -1 if it passed through a wall the map holds; else, for a ray
        that ended on a boundary within ``hit_range``, +1 if the map has a wall within one cell of
        its end, -1 if the map knows that cell as free ground (a boundary where the map has none), 0
        where the map knows nothing; averaged over the rays so judged (a longer ray that passed
        through no wall is left out: its end is too far to place on the map).
        Look-alike places that the place code confuses differ here, as the map holds their
        surroundings beyond the nearest walls, and a long ray out through a door passes through a
        wall from a look-alike room whose door is elsewhere.

        With ``around`` (a position), ``points`` are offsets from it, and the fit at ``around`` itself
        comes first: ``len(points) + 1`` fits."""
        x, y = (0.0, 0.0) if around is None else (float(around[0]), float(around[1]))
        out = np.empty(points.shape[0] + (around is not None))
        stride = max(1, round(ranges.size * self.agreement_stride_deg / 360.0))
        _scan_agreement(
            self.free, self.hits, x, y, around is not None, points, float(heading), ranges, stride, float(max_range), self.extent,
            self.cell, self._inv_cell, self.hit_range, out,
        )  # fmt: skip
        return out

    def new_run(self) -> None:
        """Forget which cells were searched: a new run searches afresh."""
        self.searched[:] = False

    # ------------------------------------------------------------------ planning
    def heading_to_unvisited(self, position: np.ndarray, this_run: bool = False, squeeze: bool = False) -> float | None:
        """The heading (rad) toward the nearest walkable cell not yet visited (``this_run``: not
        yet searched in this run); ``None`` if no such cell can be reached. The sweep's lanes come
        out about a marking radius apart. ``squeeze``: the path may pass any free cell that is not
        a wall, not only walkable ones (past a doorway too narrow for walkable cells)."""
        return self._plan(position, self.searched if this_run else self.visited, -1, squeeze)

    def heading_to_unsearched_near(self, position: np.ndarray, centre: np.ndarray, radius: float) -> float | None:
        """The heading (rad) toward the nearest walkable cell within ``radius`` of ``centre`` not
        yet searched in this run; ``None`` if none can be reached: a local search."""
        return self._plan_into_disk(position, centre, radius, self.searched)

    def heading_to_near(self, position: np.ndarray, centre: np.ndarray, radius: float) -> float | None:
        """The heading (rad) along the walkable path to the first walkable cell within ``radius``
        of ``centre`` other than the robot's own (a place by a wall is not walkable itself), or,
        when there is no such path, through any free cell that is not a wall (a doorway too narrow
        for walkable cells may wall the place off); ``None`` if there is no path either way."""
        heading = self._plan_into_disk(position, centre, radius, self._nothing)
        return self._plan_into_disk(position, centre, radius, self._nothing, squeeze=True) if heading is None else heading

    def in_sight(self, position: np.ndarray, point: np.ndarray | tuple[float, float], margin: int = 1) -> bool:
        """Whether the straight line from ``position`` to ``point`` (frame metres), and the lines
        beside it up to ``margin`` cells to either side, pass over walkable cells only (free cells
        that are not walls within two cells of their start): a line the robot can follow with room
        to spare, where the planner's path may hug a wall (:meth:`heading_to_near`)."""
        gx, gy = (float(position[0]) + self.extent) / self.cell, (float(position[1]) + self.extent) / self.cell
        tx, ty = (float(point[0]) + self.extent) / self.cell, (float(point[1]) + self.extent) / self.cell
        length = math.hypot(tx - gx, ty - gy)
        if length == 0.0:
            return True
        nx, ny = (gy - ty) / length, (tx - gx) / length  # the unit normal, in cells
        return bool(_lines_clear(self.free, self.hits, gx, gy, tx, ty, nx, ny, margin, self._walk_stamp, self._walk, self._walk_id()))

    def heading_to(self, position: np.ndarray, target: int) -> float | None:
        """The heading (rad) along the walkable path to the flat cell index ``target``; ``None``
        if it cannot be reached or the robot is there."""
        return self._plan(position, self.visited, int(target))

    def reachable_visited(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Flat indices of the visited walkable cells reachable from ``position``, and their path
        lengths in cells (for choosing transits)."""
        i, j = self.index(float(position[0]), float(position[1]))
        self._search_id[0] += 1
        self._last_plan = None  # (this search overwrites the last one's paths)
        _, reached = _search(
            self.free, self.hits, self.visited, i, j, -2, self._stamp, self._parent, self._queue, self._search_id[0], False,
            self._walk_stamp, self._walk, self._walk_id(),
        )  # fmt: skip
        return _known_with_steps(self.visited, self._parent, self._queue, reached, self._depth, self.n)

    def path(
        self,
        position: np.ndarray,
        target: int,
        known: np.ndarray | None = None,
        squeeze: bool = False,
        disk: tuple[np.ndarray, float] | None = None,
    ) -> np.ndarray:
        """Flat indices of the cells along the shortest walkable path from ``position`` to the cell
        ``target`` (``-1``: to the nearest walkable cell that ``known`` does not hold, and with
        ``disk = (centre, radius)`` that lies within ``radius`` m of ``centre``); empty if there is
        none. ``squeeze``: through any free cell that is not a wall."""
        found = self._find(position, target, known, squeeze, disk)
        return np.empty(0, dtype=np.int64) if found < 0 else _path_to(self._parent, found)

    def _find(
        self, position: np.ndarray, target: int, known: np.ndarray | None, squeeze: bool, disk: tuple[np.ndarray, float] | None
    ) -> int:
        """The search of :meth:`path`: the flat index of the cell found (its path back through
        ``_parent``), or -1."""
        if target < -1:
            raise ValueError(f"target={target}; allowed: a cell's flat index, or -1 for the nearest cell that known does not hold")
        i, j = self.index(float(position[0]), float(position[1]))
        known = self.visited if known is None else known
        plan = None
        if disk is not None and known is self._nothing:
            plan = (i, j, float(disk[0][0]), float(disk[0][1]), float(disk[1]), squeeze, self.revision)
            if plan == self._last_plan:
                return self._last_found  # the same start cell, disk and grids: the same path
        self._search_id[0] += 1
        if disk is None:
            found, _ = _search(
                self.free, self.hits, known, i, j, int(target), self._stamp, self._parent, self._queue, self._search_id[0], squeeze,
                self._walk_stamp, self._walk, self._walk_id(),
            )  # fmt: skip
        else:  # the disk in grid units, as _mark_disk draws it
            cx, cy = float(disk[0][0]), float(disk[0][1])
            dx, dy, dr = (cx + self.extent) / self.cell, (cy + self.extent) / self.cell, float(disk[1]) / self.cell
            found = _search_disk(
                self.free, self.hits, known, i, j, float(dx), float(dy), float(dr), squeeze, self._search_id[0],
                self._stamp, self._closed, self._parent, self._steps, self._heap, self._heap_cells, self._walk_stamp, self._walk,
                self._walk_id(),
            )  # fmt: skip
        self._last_plan, self._last_found = plan, int(found)
        return int(found)

    def _plan_into_disk(
        self, position: np.ndarray, centre: np.ndarray, radius: float, done: np.ndarray, squeeze: bool = False
    ) -> float | None:
        """Plan to the nearest walkable cell within ``radius`` of ``centre`` that ``done`` does not hold."""
        return self._plan(position, done, -1, squeeze, (centre, float(radius)))

    def _plan(
        self, position: np.ndarray, known: np.ndarray, target: int, squeeze: bool = False, disk: tuple[np.ndarray, float] | None = None
    ) -> float | None:
        found = self._find(position, target, known, squeeze, disk)
        if found < 0:
            return None
        x, y = float(position[0]), float(position[1])
        gx, gy = (x + self.extent) / self.cell, (y + self.extent) / self.cell
        wx, wy = self.centre(
            _waypoint(
                self.free, self.hits, self._parent, found, gx, gy, self.lookahead_cells, squeeze, self._depth,
                self._walk_stamp, self._walk, self._walk_id(),
            )
        )  # fmt: skip
        return math.atan2(wy - y, wx - x)

    def _walk_id(self) -> int:
        """The id under which the searches cache walkability: a new one whenever the grids have
        changed (:attr:`revision`), as walkability depends on them alone."""
        if self._walk_revision != self.revision:
            self._walk_revision = self.revision
            self._walk_ids += 1
        return self._walk_ids

    # ------------------------------------------------------------------ measures
    def index(self, x: float, y: float) -> tuple[int, int]:
        """The (row, column) of the cell holding frame point (x, y); row = x."""
        x, y = float(x), float(y)  # (arithmetic on NumPy scalars is several times slower)
        return math.floor((x + self.extent) / self.cell), math.floor((y + self.extent) / self.cell)

    def flat_index(self, x: float, y: float) -> int:
        """The flat index of the cell holding frame point (x, y)."""
        i, j = self.index(x, y)
        return i * self.n + j

    def centre(self, flat: int) -> tuple[float, float]:
        """The frame coordinates of a cell's centre, from its flat index."""
        i, j = divmod(int(flat), self.n)
        return (i + 0.5) * self.cell - self.extent, (j + 0.5) * self.cell - self.extent

    def walkable_points(self, stride: int = 2) -> np.ndarray:
        """Frame coordinates (an (m, 2) array) of the centres of the walkable cells, every
        ``stride``-th cell along each axis: the places the map says the robot could stand."""
        n = self.n
        out = np.empty((n * n // (stride * stride) + n, 2))
        m = _walkable_points(self.free, self.hits, stride, self.extent, self.cell, out)
        return out[:m].copy()

    @property
    def known_free(self) -> np.ndarray:
        """Cells the rays have shown free (a boolean grid)."""
        return (self.free > 0) & (self.hits < self.free)

    def explored_area(self) -> float:
        """Square metres of free ground the map knows."""
        return float(np.count_nonzero(self.known_free)) * self.cell**2


# ---------------------------------------------------------------------------- compiled loops
@njit(cache=True, inline="always")
def _grid_index(v, cell, inv_cell):  # pragma: no cover - compiled
    """``floor(v / cell)``: by multiplying with ``inv_cell`` when that is exact (``inv_cell > 0``,
    a power-of-two cell): a division is the slowest step of the ray marches' inner loops."""
    return math.floor(v * inv_cell) if inv_cell > 0.0 else math.floor(v / cell)


@njit(cache=True)
def _enter_scan(
    free, hits, x, y, heading, ranges, stride, max_range, extent, cell, inv_cell, free_range, hit_range, unknown_only
):  # pragma: no cover - compiled
    """Ray march every ``stride``-th ray: cells it passes are counted free, the cell it ends in hit
    (with ``unknown_only``, only cells neither free nor hit so far). Returns how many counts changed."""
    n = free.shape[0]
    changed = 0
    n_rays = ranges.size
    step = cell * 0.5
    for r in range(0, n_rays, stride):
        angle = heading + 2.0 * math.pi * r / n_rays
        c, s = math.cos(angle), math.sin(angle)
        d = float(ranges[r])
        reach = min(d - step, free_range)
        t = 0.0
        last_i, last_j = -1, -1
        while t < reach:
            i = _grid_index(x + t * c + extent, cell, inv_cell)
            j = _grid_index(y + t * s + extent, cell, inv_cell)
            if i < 0 or j < 0 or i >= n or j >= n:
                break
            if i != last_i or j != last_j:
                if free[i, j] < 65535 and not (unknown_only and (free[i, j] > 0 or hits[i, j] > 0)):
                    free[i, j] += 1
                    changed += 1
                last_i, last_j = i, j
            t += step
        if d < hit_range and d < max_range * 0.999:
            i = _grid_index(x + d * c + extent, cell, inv_cell)
            j = _grid_index(y + d * s + extent, cell, inv_cell)
            if 0 <= i < n and 0 <= j < n and hits[i, j] < 65535 and not (unknown_only and (free[i, j] > 0 or hits[i, j] > 0)):
                hits[i, j] += 1
                changed += 1
    return changed


@njit(cache=True)
def _scan_agreement(
    free, hits, ox, oy, with_origin, points, heading, ranges, stride, max_range, extent, cell, inv_cell, hit_range, out
):  # pragma: no cover - compiled
    """:meth:`ExplorationMap.scan_agreement` from ``(ox, oy)`` plus each of ``points``, after
    ``(ox, oy)`` itself ``with_origin``."""
    n = free.shape[0]
    n_rays = ranges.size
    m = (n_rays + stride - 1) // stride
    cos_, sin_, dist = np.empty(m), np.empty(m), np.empty(m)
    for q in range(m):
        angle = heading + 2.0 * math.pi * (q * stride) / n_rays
        cos_[q], sin_[q], dist[q] = math.cos(angle), math.sin(angle), ranges[q * stride]
    for p in range(out.size):
        k = p - 1 if with_origin else p
        x = (ox if k < 0 else ox + points[k, 0]) + extent
        y = (oy if k < 0 else oy + points[k, 1]) + extent
        total = 0.0
        counted = 0
        for q in range(m):
            d = dist[q]
            far = not (d < hit_range and d < max_range * 0.999)
            c, s = cos_[q], sin_[q]
            through = False  # the ray passed through a wall the map holds
            t = 0.5
            while t < d - 0.5:
                a = _grid_index(x + t * c, cell, inv_cell)
                b = _grid_index(y + t * s, cell, inv_cell)
                if 0 <= a < n and 0 <= b < n and hits[a, b] > 0 and hits[a, b] >= free[a, b]:  # (a wall, written out: faster)
                    through = True
                    break
                t += 0.5
            if through:
                counted += 1
                total -= 1.0
                continue
            if far:  # a long ray's end is too far to place on the map; only its free stretch counts
                continue
            counted += 1
            i = _grid_index(x + d * c, cell, inv_cell)
            j = _grid_index(y + d * s, cell, inv_cell)
            if i < 1 or j < 1 or i >= n - 1 or j >= n - 1:
                continue
            wall = False
            for a in range(i - 1, i + 2):
                for b in range(j - 1, j + 2):
                    if hits[a, b] > 0 and hits[a, b] >= free[a, b]:
                        wall = True
            if wall:
                total += 1.0
            elif free[i, j] > 0:
                total -= 1.0
        out[p] = total / counted if counted else 0.0


@njit(cache=True)
def _walkable_points(free, hits, stride, extent, cell, out):  # pragma: no cover - compiled
    n = free.shape[0]
    m = 0
    for i in range(1, n - 1, stride):
        for j in range(1, n - 1, stride):
            if free[i, j] > 0 and _walkable(free, hits, i, j):
                out[m, 0] = (i + 0.5) * cell - extent
                out[m, 1] = (j + 0.5) * cell - extent
                m += 1
    return m


@njit(cache=True)
def _mark_disk(grid, x, y, radius, extent, cell):  # pragma: no cover - compiled
    n = grid.shape[0]
    ci = (x + extent) / cell
    cj = (y + extent) / cell
    r = radius / cell
    for i in range(max(0, int(ci - r) - 1), min(n, int(ci + r) + 2)):
        for j in range(max(0, int(cj - r) - 1), min(n, int(cj + r) + 2)):
            if (i + 0.5 - ci) ** 2 + (j + 0.5 - cj) ** 2 <= r * r:
                grid[i, j] = True


@njit(cache=True, inline="always")  # (a call passing arrays costs reference counting)
def _is_wall(free, hits, i, j):  # pragma: no cover - compiled
    return hits[i, j] > 0 and hits[i, j] >= free[i, j]


@njit(cache=True, inline="always")  # (a call passing arrays costs reference counting)
def _walkable(free, hits, i, j):  # pragma: no cover - compiled
    """Known free, and no wall in the 3 x 3 block around it."""
    n = free.shape[0]
    if i < 1 or j < 1 or i >= n - 1 or j >= n - 1:
        return False
    if free[i, j] == 0 or _is_wall(free, hits, i, j):
        return False
    for di in range(-1, 2):
        for dj in range(-1, 2):
            if _is_wall(free, hits, i + di, j + dj):
                return False
    return True


@njit(cache=True, inline="always")  # (a call passing arrays costs reference counting)
def _free_not_wall(free, hits, i, j):  # pragma: no cover - compiled
    n = free.shape[0]
    return 1 <= i < n - 1 and 1 <= j < n - 1 and free[i, j] > 0 and not _is_wall(free, hits, i, j)


@njit(cache=True, inline="always")
def _walkable_once(free, hits, i, j, walk_stamp, walk, walk_id):  # pragma: no cover - compiled
    """:func:`_walkable`, remembered in ``walk`` under ``walk_id`` (``walk_stamp``): one id per
    state of the grids, so that searches on unchanged grids reuse what earlier ones worked out."""
    n = free.shape[0]
    if i < 0 or j < 0 or i >= n or j >= n:
        return False
    k = i * n + j
    if walk_stamp[k] != walk_id:
        walk_stamp[k] = walk_id
        walk[k] = _walkable(free, hits, i, j)
    return walk[k]


@njit(cache=True, inline="always")
def _passable_once(free, hits, i, j, near_start, walk_stamp, walk, walk_id):  # pragma: no cover - compiled
    """Walkable (:func:`_walkable_once`), or (near the start: within two steps of it, or ``squeeze``)
    at least free and not a wall."""
    return _walkable_once(free, hits, i, j, walk_stamp, walk, walk_id) or (near_start and _free_not_wall(free, hits, i, j))


# the 8 neighbours of a cell, in the order the searches try them
_NEIGHBOURS = ((-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1))


@njit(cache=True, inline="always")
def _can_step(free, hits, ci, cj, di, dj, near, walk_stamp, walk, walk_id):  # pragma: no cover - compiled
    """Whether a search may step from (ci, cj) by (di, dj): onto a passable cell
    (:func:`_passable_once`), and diagonally only between two passable cells (no corner cutting)."""
    if not _passable_once(free, hits, ci + di, cj + dj, near, walk_stamp, walk, walk_id):
        return False
    return (
        di == 0
        or dj == 0
        or (
            _passable_once(free, hits, ci + di, cj, near, walk_stamp, walk, walk_id)
            and _passable_once(free, hits, ci, cj + dj, near, walk_stamp, walk, walk_id)
        )
    )


@njit(cache=True)
def _search(
    free, hits, known, i0, j0, target, stamp, parent, queue, search_id, squeeze, walk_stamp, walk, walk_id
):  # pragma: no cover - compiled
    """Breadth-first search over walkable cells (8-connected, no corner cutting) from (i0, j0) to
    ``target`` (a flat index); if ``target == -1``, to the nearest walkable cell that ``known``
    does not hold; if ``target == -2``, everywhere reachable. ``squeeze``: over every free cell
    that is not a wall. Returns the flat index of the cell found (its path back to the start
    through ``parent``), or -1 if there is none (or the robot is there), and the number of cells
    reached (``queue[:reached]``, in the order reached). ``walk_stamp``, ``walk`` and ``walk_id``:
    each cell's walkability, worked out once per state of the grids (:func:`_walkable_once`)."""
    n = free.shape[0]
    if i0 < 1 or j0 < 1 or i0 >= n - 1 or j0 >= n - 1:
        return -1, 0
    start = i0 * n + j0
    stamp[start] = search_id
    parent[start] = -1
    head, tail = 0, 1
    queue[0] = start
    found = -1
    while head < tail:
        cur = queue[head]
        head += 1
        ci, cj = cur // n, cur % n
        # a robot beside a wall stands on cells that are not walkable: leave them by free ones
        near = squeeze or (target != -2 and (cur == start or parent[cur] == start))
        if cur != start:
            if target >= 0:
                if cur == target:
                    found = cur
                    break
            elif target == -1 and not known[ci, cj] and _walkable_once(free, hits, ci, cj, walk_stamp, walk, walk_id):
                found = cur
                break
        for di, dj in _NEIGHBOURS:
            nxt = (ci + di) * n + cj + dj
            if stamp[nxt] == search_id or not _can_step(free, hits, ci, cj, di, dj, near, walk_stamp, walk, walk_id):
                continue
            stamp[nxt] = search_id
            parent[nxt] = cur
            queue[tail] = nxt
            tail += 1
    return found, tail


@njit(cache=True)
def _search_disk(
    free, hits, known, i0, j0, dx, dy, dr, squeeze, search_id, stamp, closed, parent, steps, heap, heap_cells, walk_stamp, walk, walk_id
):  # pragma: no cover - compiled
    """A shortest path (in steps, over the same cells and moves as :func:`_search`) from (i0, j0)
    to the nearest walkable cell that ``known`` does not hold and whose centre lies within ``dr``
    of ``(dx, dy)`` (grid units): an A* search, which heads for the disk instead of spreading in
    every direction as the breadth-first search does. Its lower bound on the steps left from a
    cell is the Chebyshev distance of its centre to the disk's centre less ``dr``, rounded up (a
    step moves at most one cell along each axis). Of the open cells with the least bound, the one
    farthest along is taken first, then the one nearest the disk's centre in a straight line (of
    the many paths equally short in steps, one near the straight line). Returns the flat index of
    the cell found (its path back through ``parent``), or -1 if there is none (or the robot is
    there). ``stamp`` marks the cells reached, ``closed`` those done, ``steps`` their path lengths;
    ``heap`` holds the queue's priorities (:func:`_priority`) and ``heap_cells`` their cells;
    ``walk_stamp`` / ``walk`` / ``walk_id`` as in :func:`_search`."""
    n = free.shape[0]
    if i0 < 1 or j0 < 1 or i0 >= n - 1 or j0 >= n - 1:
        return -1
    start = i0 * n + j0
    stamp[start] = search_id
    parent[start] = -1
    steps[start] = 0
    size = _heap_push(heap, heap_cells, 0, _priority(i0, j0, 0, dx, dy, dr), start)
    while size > 0:
        cur = heap_cells[0]
        size = _heap_pop(heap, heap_cells, size)
        if closed[cur] == search_id:
            continue  # an older entry of a cell since reached by a shorter path
        closed[cur] = search_id
        ci, cj = cur // n, cur % n
        if (
            cur != start
            and not known[ci, cj]
            and (ci + 0.5 - dx) ** 2 + (cj + 0.5 - dy) ** 2 <= dr * dr
            and _walkable_once(free, hits, ci, cj, walk_stamp, walk, walk_id)
        ):
            return cur
        near = squeeze or cur == start or parent[cur] == start
        g = steps[cur] + 1
        for di, dj in _NEIGHBOURS:
            nxt = (ci + di) * n + cj + dj
            if closed[nxt] == search_id or (stamp[nxt] == search_id and steps[nxt] <= g):
                continue
            if not _can_step(free, hits, ci, cj, di, dj, near, walk_stamp, walk, walk_id):
                continue
            stamp[nxt] = search_id
            parent[nxt] = cur
            steps[nxt] = g
            if size == heap.size:
                return -1  # (cannot happen: a cell enters the queue at most once from each neighbour)
            size = _heap_push(heap, heap_cells, size, _priority(ci + di, cj + dj, g, dx, dy, dr), nxt)
    return -1


# the disk search's priority, an int64 packing 21 bits each of the bound on a path's steps, the
# steps so far (complemented: more steps, a smaller priority) and the straight distance to the
# disk's centre (in 1/256 cells), so that comparing priorities orders them in that order
_BITS = 21
_MASK = (1 << _BITS) - 1


@njit(cache=True, inline="always")
def _priority(i, j, g, dx, dy, dr):  # pragma: no cover - compiled
    ex, ey = i + 0.5 - dx, j + 0.5 - dy
    bound = g + max(0, math.ceil(max(abs(ex), abs(ey)) - dr - 1e-9))  # Chebyshev distance to the disk, at least
    straight = min(_MASK, int(256.0 * math.sqrt(ex * ex + ey * ey)))
    return (bound << (2 * _BITS)) | ((_MASK - g) << _BITS) | straight


@njit(cache=True, inline="always")
def _heap_push(heap, cells, size, priority, cell):  # pragma: no cover - compiled
    """Push ``cell`` with ``priority`` onto the binary min-heap ``heap[:size]`` (``cells`` beside
    it); the new size."""
    k = size
    while k > 0:
        up = (k - 1) >> 1
        if heap[up] <= priority:
            break
        heap[k] = heap[up]
        cells[k] = cells[up]
        k = up
    heap[k] = priority
    cells[k] = cell
    return size + 1


@njit(cache=True, inline="always")
def _heap_pop(heap, cells, size):  # pragma: no cover - compiled
    """Drop the least entry of the binary min-heap ``heap[:size]`` (``cells`` beside it); the new size."""
    size -= 1
    priority, cell = heap[size], cells[size]
    k = 0
    while True:
        child = 2 * k + 1
        if child >= size:
            break
        if child + 1 < size and heap[child + 1] < heap[child]:
            child += 1
        if heap[child] >= priority:
            break
        heap[k] = heap[child]
        cells[k] = cells[child]
        k = child
    heap[k] = priority
    cells[k] = cell
    return size


@njit(cache=True)
def _farthest_in_sight(free, hits, path, gx, gy, most, squeeze, walk_stamp, walk, walk_id):  # pragma: no cover - compiled
    """The index of the farthest cell along ``path`` (at most ``most`` cells on, at least 1) that a
    straight line from ``(gx, gy)`` (grid units) reaches over passable cells only: the planner heads
    straight for it, not along the search's 8-connected zig-zags. ``walk_stamp`` / ``walk`` /
    ``walk_id`` as in :func:`_search`."""
    n = free.shape[0]
    best = 1
    for k in range(2, min(most, path.size - 1) + 1):
        if not _line_clear(free, hits, gx, gy, path[k] // n + 0.5, path[k] % n + 0.5, squeeze, walk_stamp, walk, walk_id):
            break
        best = k
    return best


@njit(cache=True)
def _lines_clear(free, hits, gx, gy, tx, ty, nx, ny, margin, walk_stamp, walk, walk_id):  # pragma: no cover - compiled
    """:func:`_line_clear` for the line from ``(gx, gy)`` to ``(tx, ty)`` shifted by ``k`` times
    ``(nx, ny)``, for every ``k`` from ``-margin`` to ``margin``."""
    for k in range(-margin, margin + 1):
        if not _line_clear(free, hits, gx + k * nx, gy + k * ny, tx + k * nx, ty + k * ny, False, walk_stamp, walk, walk_id):
            return False
    return True


@njit(cache=True)
def _line_clear(free, hits, gx, gy, tx, ty, squeeze, walk_stamp, walk, walk_id):  # pragma: no cover - compiled
    """Whether the straight line from ``(gx, gy)`` to ``(tx, ty)`` (grid units), sampled every third
    of a cell, passes over passable cells only (:func:`_passable_once`: near the start, or with
    ``squeeze``, free cells that are not walls will do)."""
    samples = int(3.0 * math.hypot(tx - gx, ty - gy)) + 1
    for s in range(1, samples + 1):
        x = gx + (tx - gx) * s / samples
        y = gy + (ty - gy) * s / samples
        near = squeeze or (x - gx) ** 2 + (y - gy) ** 2 <= 4.0  # a robot by a wall leaves it over free cells
        if not _passable_once(free, hits, int(x), int(y), near, walk_stamp, walk, walk_id):
            return False
    return True


@njit(cache=True)
def _waypoint(free, hits, parent, found, gx, gy, most, squeeze, scratch, walk_stamp, walk, walk_id):  # pragma: no cover - compiled
    """The cell the planner heads for (:func:`_farthest_in_sight`) along the path from the search's
    start to ``found`` (written into ``scratch``)."""
    length = 0
    cur = found
    while parent[cur] != -1:
        length += 1
        cur = parent[cur]
    cur = found
    for k in range(length, -1, -1):
        scratch[k] = cur
        cur = parent[cur]
    return scratch[_farthest_in_sight(free, hits, scratch[: length + 1], gx, gy, most, squeeze, walk_stamp, walk, walk_id)]


@njit(cache=True)
def _path_to(parent, found):  # pragma: no cover - compiled
    """The flat indices from the search's start to ``found``, in order."""
    length = 0
    cur = found
    while parent[cur] != -1:
        length += 1
        cur = parent[cur]
    path = np.empty(length + 1, dtype=np.int64)
    cur = found
    for k in range(length, -1, -1):
        path[k] = cur
        cur = parent[cur]
    return path


@njit(cache=True)
def _known_with_steps(known, parent, queue, reached, depth, n):  # pragma: no cover - compiled
    """Of the cells a search reached (``queue[:reached]``, in the order reached), those ``known``
    holds, with their path lengths in steps (``depth``: scratch, one entry per cell)."""
    count = 0
    for k in range(reached):
        c = queue[k]
        depth[c] = 0 if k == 0 else depth[parent[c]] + 1
        if known[c // n, c % n]:
            count += 1
    cells = np.empty(count, dtype=np.int64)
    steps = np.empty(count, dtype=np.int64)
    m = 0
    for k in range(reached):
        c = queue[k]
        if known[c // n, c % n]:
            cells[m] = c
            steps[m] = depth[c]
            m += 1
    return cells, steps
