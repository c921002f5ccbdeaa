"""The map and its planner: a grid of what the rangefinder has shown, and searches over it.

A faculty of the default model (``AgentConfig.map``; off in the paper's model). It is built
from the agent's own senses only: the rangefinder scan, the compass, and the path-integration
estimate (:mod:`hippo_agent.faculties.path_integration`), never the true position. Directed
exploration, homing and localisation read it.

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
  changes to what they say of a cell: known free, a wall), the path is the same: it is searched
  once; so is a path to a given cell. Whether a cell is walkable, which every search asks of the
  cells it reaches, is likewise worked out once per revision.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from hippo_agent.faculties._fit_kernel import scan_agreement, wall_kinds
from hippo_agent.faculties._map_kernels import (
    enter_scan,
    known_with_steps,
    lines_clear,
    mark_disk,
    mark_disks,
    path_to,
    search,
    search_disk,
    start_free_is_walkable,
    walkable_points,
    waypoint,
)
from hippo_agent.faculties._revise_kernel import revise_scan
from hippo_agent.sections import Section, param

__all__ = ["ExplorationMap", "MapConfig"]


@dataclass(frozen=True)
class MapConfig(Section):
    """The map: its grid, what a scan writes into it, and the planner's lookahead."""

    name: ClassVar[str] = "map"

    extent: float = param(45.0, gt=0)
    """The map covers this many metres each way round the frame's origin (the dry run's first
    position): room for a 40 m arena from any start."""
    cell: float = param(0.25, gt=0)
    """Side (m) of a map cell; the robot (0.17 m radius) fits in one."""
    visit_radius: float = param(0.7, gt=0)
    """Ground within this distance (m) of the robot counts as visited: the dry run's sweep runs
    lanes about this far apart."""
    search_radius: float = param(0.6, gt=0)
    """Ground within this distance (m) counts as searched in a run: twice the goal disk's
    radius, so a run that has searched everywhere has passed over the goal."""
    lookahead: float = param(2.0, gt=0)
    """The planner heads for the farthest cell of its path, up to this far along it (m), that a
    straight line reaches over walkable ground (the search's 8-connected paths zig-zag)."""
    free_range: float = param(4.0, gt=0)
    """A ray marks cells free up to this distance (m): farther ones are seen at too coarse an angle."""
    hit_range: float = param(6.0, gt=0)
    """A ray ending nearer than this (m) marks a wall, and enters the fit of a scan to the map."""
    ray_stride_deg: float = param(5.0, gt=0)
    """One ray of the scan every this many degrees enters the map."""
    agreement_stride_deg: float = param(10.0, gt=0)
    """One ray every this many degrees is compared with the map (:meth:`ExplorationMap.scan_agreement`)."""
    bump_distance: float = param(0.3, gt=0)
    """A bump marks a wall this far (m) ahead of the robot's centre: the robot's radius and a
    little more, in the cell it bumped into."""
    run_every: int = param(2, ge=1)
    """In runs, a scan enters the map every this many steps (the dry run maps every scan): at
    0.15 m a step, every second scan lands within a cell of the last."""
    new_wall_evidence: int | None = param(5, ge=1)
    """In runs, while the robot is well placed, a boundary seen on ground the map holds free, with
    no wall beside it, in this many scans in a row becomes a wall; a bump on such ground makes it
    one at once (``None``: runs enter only cells the map knows nothing of)."""
    gone_wall_evidence: int | None = param(5, ge=1)
    """In runs, while the robot is well placed, a wall the map holds that rays cross in this many
    scans in a row, each from another cell than the last, is cleared (``None``: never). A ray
    grazing a wall's cell at a small error in the estimate crosses it too, and a wall wrongly
    cleared costs a bump: with ``gone_paired`` such lone crossings do not count."""
    gone_range: float = param(6.0, gt=0)
    """A ray crossing a wall the map holds counts toward clearing it up to this distance (m); above
    ``free_range``: a door is seen through from farther than the map is filled in."""
    dry_reachable_only: bool = param(True)
    """In runs, an estimate anchors, and a scan enters unknown cells, only where walkable ground joins
    the ground the last dry run found: cells a misplaced scan entered beyond the maze's walls are
    known ground too, and an estimate anchored there would map a ghost of the maze round it."""
    gone_paired: bool = param(True)
    """A ray counts toward clearing a wall only if a ray beside it in the scan (``ray_stride_deg``
    to either side) first crossed a wall within two cells of it too: an opening is seen through over
    several rays; a ray grazing a thin wall at a small error in the estimate, or passing a wall's
    end, is alone."""


class ExplorationMap:
    """The occupancy and visit map in the path-integration frame, and the planner (module docstring).

    Args:
        config: the map's parameters.
    """

    def __init__(self, config: MapConfig) -> None:
        self.config = config
        extent, cell, lookahead = config.extent, config.cell, config.lookahead
        self.extent = float(extent)
        self.cell = float(cell)
        # 1 / cell where multiplying by it is exactly dividing by cell (cell a power of two, as the
        # default 0.25 m), else 0: the compiled ray marches then divide (see _grid_index)
        self._inv_cell = 1.0 / self.cell if math.frexp(self.cell)[0] == 0.5 else 0.0
        self.visit_radius, self.search_radius = float(config.visit_radius), float(config.search_radius)
        self.lookahead_cells = max(1, round(lookahead / cell))
        self.free_range, self.hit_range = float(config.free_range), float(config.hit_range)
        self.gone_range = float(config.gone_range)
        self.ray_stride_deg, self.agreement_stride_deg = float(config.ray_stride_deg), float(config.agreement_stride_deg)
        n = math.ceil(2 * self.extent / self.cell)
        self.n = n
        self.free = np.zeros((n, n), dtype=np.uint16)
        self.hits = np.zeros((n, n), dtype=np.uint16)
        self.visited = np.zeros((n, n), dtype=np.bool_)
        self.searched = np.zeros((n, n), dtype=np.bool_)
        # walls written in runs (revise, bumps): the world changed there, and may change back
        self.new_walls = np.zeros((n, n), dtype=np.bool_)
        # scans in a row that disagreed with a cell (revise), and the last scan that counted there
        self.change = np.zeros((n, n), dtype=np.uint16)
        self.vantage = np.full((n, n), -1, dtype=np.int32)  # where the robot stood at a wall's last count (revise)
        self._scan_stamp = np.zeros((n, n), dtype=np.int32)
        self._hit_stamp = np.zeros((n, n), dtype=np.int32)  # the last scan with a ray ending in the cell
        self._scan_id = 0
        # scratch for the search: a stamp per cell (which search reached it), its parent, a queue
        self._stamp = np.zeros(n * n, dtype=np.int32)
        self._parent = np.zeros(n * n, dtype=np.int32)
        self._queue = np.zeros(n * n, dtype=np.int32)
        self._depth = np.zeros(n * n, dtype=np.int32)
        # and whether a cell is walkable, worked out once per state of the grids (_walk_id)
        self._walk_cache = np.zeros(n * n, dtype=np.int32)
        self._walk_ids, self._walk_revision = 0, -1
        # the search into a disk (A*): path lengths so far, cells done, and its priority queue
        self._steps = np.zeros(n * n, dtype=np.int32)
        self._closed = np.zeros(n * n, dtype=np.int32)
        self._heap = np.zeros(8 * n * n, dtype=np.int64)
        self._heap_cells = np.zeros(8 * n * n, dtype=np.int32)
        self._search_id = np.zeros(1, dtype=np.int32)
        self._nothing = np.zeros((n, n), dtype=np.bool_)  # "none done" for a search into a disk (never written)
        # counts the changes to what the grids say of a cell (known free, a wall): all the searches,
        # walkability and the scan's fit read of free and hits (a count that changes neither is not one)
        self.revision = 0
        # each cell's kind of wall (wall_kinds), as of the revision in _wall_kinds_revision: what
        # the scan's fit reads, worked out again only when the grids have changed
        self._wall_kinds = np.zeros((n, n), dtype=np.uint8)
        self._wall_kinds_revision = -1
        # the last search whose result the grids and the ground it looks for decide (to a cell, to
        # ground not yet visited or searched, into a disk): its start cell, target, disk, squeeze,
        # the grids' revision and that ground's changes (_marks), and the cell found (its path back
        # is in _parent until the next search)
        self._last_plan: tuple[Any, ...] | None = None
        self._last_found = -1
        # (start cell, revision) of the last search everywhere reachable (reachable_visited) while its
        # paths, still in _parent, are those a search to any cell it reached would find; else None
        self._tree: tuple[int, int, int] | None = None
        self._marks = 0  # changes to visited and searched, which a search for ground they do not hold depends on
        self.dry_ground: np.ndarray | None = None  # the free ground the last dry run found (dry_reachable_only)
        # reaches_dry_ground's search: its own stamp, parent and queue, so that the planner's cached paths stay
        self._reach, self._reach_id = np.zeros((3, n * n), dtype=np.int32), 0

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
        current = self._walk_revision == self.revision  # (the walkability remembered is that of these grids)
        if enter_scan(
            self.free, self.hits, float(position[0]), float(position[1]), float(heading), ranges, stride,
            float(max_range), self.extent, self.cell, self._inv_cell, self.free_range, self.hit_range, unknown_only,
            self._walk_cache,
        ):  # fmt: skip
            self.revision += 1
            if current:  # the scan forgot what its changes touch: the rest holds for the new grids
                self._walk_revision = self.revision
        self.mark(position, search_radius)

    def mark(self, position: np.ndarray, search_radius: float | None = None) -> None:
        """Mark the ground round ``position`` visited, and searched within ``search_radius`` (by default the map's)."""
        x, y = float(position[0]), float(position[1])
        radius = self.search_radius if search_radius is None else float(search_radius)
        if mark_disks(self.visited, self.searched, x, y, self.visit_radius, radius, self.extent, self.cell):
            self._marks += 1

    def revise(
        self,
        position: np.ndarray,
        heading: float,
        ranges: np.ndarray,
        max_range: float,
        search_radius: float | None = None,
        write_new: bool = True,
    ) -> None:
        """Enter a run's scan seen from ``position`` as :meth:`observe` does with ``unknown_only``,
        and revise what the map holds where the scan keeps disagreeing with it: a boundary on free
        ground becomes a wall after ``new_wall_evidence`` scans in a row, a wall that rays cross is
        cleared after ``gone_wall_evidence`` (call only while the position is trusted: a misplaced
        scan disagrees everywhere)."""
        new, gone = self.config.new_wall_evidence, self.config.gone_wall_evidence
        if new is None and gone is None:
            self.observe(position, heading, ranges, max_range, unknown_only=True, search_radius=search_radius)
            return
        stride = max(1, round(ranges.size * self.ray_stride_deg / 360.0))
        self._scan_id += 1
        if revise_scan(
            self.free, self.hits, self.new_walls, self.change, self.vantage, self._scan_stamp, self._hit_stamp, self._scan_id, float(position[0]), float(position[1]),
            float(heading), ranges, stride, float(max_range), self.extent, self.cell, self._inv_cell, self.free_range,
            self.gone_range, self.hit_range, new or 0, gone or 0, bool(write_new), bool(self.config.gone_paired),
            self.reaches_dry_ground(position),
        ):  # fmt: skip
            self.revision += 1
        self.mark(position, search_radius)

    def forget_searched_near(self, centre: np.ndarray, radius: float) -> None:
        """Count the ground within ``radius`` of ``centre`` as not searched in this run."""
        inside = np.zeros_like(self.searched)
        mark_disk(inside, float(centre[0]), float(centre[1]), float(radius), self.extent, self.cell)
        self.searched[inside] = False
        self._marks += 1

    def forget_new_walls(self) -> None:
        """Make every wall a run wrote where the map held none (:attr:`new_walls`) free ground again:
        what :mod:`hippomaze.changing_world`'s privileged ``forget_new_walls`` does when a new layout
        begins, to measure what such walls cost once the world has changed again."""
        self.free[self.new_walls] = np.maximum(self.free[self.new_walls], 1)
        self.hits[self.new_walls] = 0
        self.change[self.new_walls] = 0
        self.new_walls[:] = False
        self.grids_replaced()

    def mark_bump(self, position: np.ndarray, heading: float, distance: float, new: bool = False) -> None:
        """A bump: the cell ``distance`` ahead is a wall, whatever the rays said (``new``: a wall
        written in a run, which the world may take away again)."""
        i, j = self.index(position[0] + distance * math.cos(heading), position[1] + distance * math.sin(heading))
        if 0 <= i < self.n and 0 <= j < self.n:
            wall = self.hits[i, j] > 0 and self.hits[i, j] >= self.free[i, j]
            self.hits[i, j] = min(int(self.hits[i, j]) + int(self.free[i, j]) + 1, 65535)
            self.new_walls[i, j] |= new and not wall
            self.revision += 1

    def wall_near(self, position: np.ndarray, heading: float, distance: float) -> bool:
        """Whether the map holds a wall within one cell of the point ``distance`` ahead of
        ``position`` along ``heading``: where a bump there was to be expected."""
        i, j = self.index(position[0] + distance * math.cos(heading), position[1] + distance * math.sin(heading))
        rows, cols = slice(max(i - 1, 0), max(i + 2, 0)), slice(max(j - 1, 0), max(j + 2, 0))
        hits, free = self.hits[rows, cols], self.free[rows, cols]
        return bool(np.any((hits > 0) & (hits >= free)))

    def grids_replaced(self) -> None:
        """Call after writing ``free``, ``hits``, ``visited`` or ``searched`` other than through this
        class's methods (as loading a saved agent does): searches made on the old grids, and the
        walkability they worked out, are not reused."""
        self.revision += 1

    def scan_agreement(
        self,
        points: np.ndarray,
        heading: float,
        ranges: np.ndarray,
        max_range: float,
        around: np.ndarray | None = None,
        short_weight: float = 1.0,
        judged_only: bool = False,
        judged: np.ndarray | None = None,
        new_wall_weight: float = 1.0,
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
        comes first: ``len(points) + 1`` fits.

        ``short_weight`` is how much a *short reading* (a boundary where the map knows free ground)
        counts, against 1 for every other judged ray. In the beam model of a rangefinder (Thrun,
        Burgard and Fox, *Probabilistic Robotics*, ch. 6) a reading shorter than the map predicts
        is also explained by an object the map does not hold (its "short" component): with
        ``short_weight`` below 1, a new obstacle costs a place less of its fit than a ray through a
        wall, which nothing but a wrong place (or a wall since removed) explains. A ray through a
        wall written in a run (:attr:`new_walls`: a new obstacle, seen or bumped into) does not
        count against a place: such walls come and go (the blocks of one layout gone in the next).
        For the same reason a ray ending by such a wall, and by no wall from the dry run, weighs
        ``new_wall_weight`` (for the place, as a hit does).
        ``judged_only``: rays ending where the map knows nothing are left out, and a place where no
        ray is judged fits 1 (nothing the map holds says it is wrong).

        ``judged`` (a one- or three-element array): the first place's fit with ``short_weight`` 0
        and ``judged_only`` is written there too, from the same ray march, and, with three elements,
        the share of its rays that were short readings and how many crossed a wall through its
        middle (a wrong place's evidence where the world changed)."""
        x, y = (0.0, 0.0) if around is None else (float(around[0]), float(around[1]))
        out = np.empty(points.shape[0] + (around is not None))
        stride = max(1, round(ranges.size * self.agreement_stride_deg / 360.0))
        scan_agreement(
            self.free, self.hits, self._walls(), x, y, around is not None, points, float(heading), ranges, stride, float(max_range), self.extent,
            self.cell, self._inv_cell, self.hit_range, float(short_weight), bool(judged_only), out,
            _NO_JUDGED if judged is None else judged, float(new_wall_weight),
        )  # fmt: skip
        return out

    def new_run(self) -> None:
        """Forget which cells were searched: a new run searches afresh."""
        self.searched[:] = False
        self._marks += 1

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
        return bool(lines_clear(self.free, self.hits, gx, gy, tx, ty, nx, ny, margin, self._walk_cache, self._walk_id()))

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
        walk_id = self._walk_id()
        _, reached = search(
            self.free, self.hits, self.visited, i, j, -2, self._stamp, self._parent, self._queue, self._search_id[0], False,
            self._walk_cache, walk_id,
        )  # fmt: skip
        # the paths to every cell reached are those a search to that cell would find, unless the
        # robot stands by a wall (the searches to a cell let it leave by free cells): kept for _find
        self._tree = (
            (i, j, self.revision) if reached and start_free_is_walkable(self.free, self.hits, i, j, self._walk_cache, walk_id) else None
        )
        return known_with_steps(self.visited, self._parent, self._queue, reached, self._depth, self.n)

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
        return np.empty(0, dtype=np.int64) if found < 0 else path_to(self._parent, found)

    def _find(
        self, position: np.ndarray, target: int, known: np.ndarray | None, squeeze: bool, disk: tuple[np.ndarray, float] | None
    ) -> int:
        """The search of :meth:`path`: the flat index of the cell found (its path back through
        ``_parent``), or -1."""
        if target < -1:
            raise ValueError(f"target={target}; allowed: a cell's flat index, or -1 for the nearest cell that known does not hold")
        i, j = self.index(float(position[0]), float(position[1]))
        known = self.visited if known is None else known
        plan: tuple[Any, ...] | None = None
        if disk is None and target >= 0:  # (known is not read)
            plan = (i, j, int(target), squeeze, self.revision)
        elif known is self.visited or known is self.searched or known is self._nothing:  # (they change only with _marks)
            where = None if disk is None else (float(disk[0][0]), float(disk[0][1]), float(disk[1]))
            plan = (i, j, int(target), where, squeeze, self.revision, id(known), 0 if known is self._nothing else self._marks)
        if plan is not None and plan == self._last_plan:
            return self._last_found  # the same start cell, target, grids and ground to reach: the same path
        if (
            disk is None
            and target >= 0
            and not squeeze
            and self._tree == (i, j, self.revision)
            and self._stamp[target] == self._search_id[0]
            and target != i * self.n + j
        ):
            self._last_plan, self._last_found = plan, int(target)  # reached by the search everywhere from here: its path
            return int(target)
        self._tree = None  # (this search overwrites the paths)
        self._search_id[0] += 1
        if disk is None:
            found, _ = search(
                self.free, self.hits, known, i, j, int(target), self._stamp, self._parent, self._queue, self._search_id[0], squeeze,
                self._walk_cache, self._walk_id(),
            )  # fmt: skip
        else:  # the disk in grid units, as mark_disk draws it
            cx, cy = float(disk[0][0]), float(disk[0][1])
            dx, dy, dr = (cx + self.extent) / self.cell, (cy + self.extent) / self.cell, float(disk[1]) / self.cell
            found = search_disk(
                self.free, self.hits, known, i, j, float(dx), float(dy), float(dr), squeeze, self._search_id[0],
                self._stamp, self._closed, self._parent, self._steps, self._heap, self._heap_cells, self._walk_cache,
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
            waypoint(
                self.free, self.hits, self._parent, found, gx, gy, self.lookahead_cells, squeeze, self._depth,
                self._walk_cache, self._walk_id(),
            )
        )  # fmt: skip
        return math.atan2(wy - y, wx - x)

    def _walls(self) -> np.ndarray:
        """Each cell's kind of wall (:func:`wall_kinds`) for the grids as they are (:attr:`revision`)."""
        if self._wall_kinds_revision != self.revision:
            wall_kinds(self.free, self.hits, self.new_walls, self._wall_kinds)
            self._wall_kinds_revision = self.revision
        return self._wall_kinds

    def _walk_id(self) -> int:
        """The id under which the searches cache walkability: a new one whenever the grids have
        changed (:attr:`revision`), as walkability depends on them alone."""
        if self._walk_revision != self.revision:
            self._walk_revision = self.revision
            self._walk_ids += 1
            if self._walk_ids >= 2**30:  # (the cache holds 2 id + 1 in an int32: start the ids afresh)
                self._walk_cache[:] = 0
                self._walk_ids = 1
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

    def flat_indices(self, points: np.ndarray) -> np.ndarray:
        """:meth:`flat_index` of each of ``points`` (an (m, 2) array), the same numbers."""
        ij = np.floor((np.asarray(points, dtype=np.float64) + self.extent) / self.cell).astype(np.int64)
        return ij[:, 0] * self.n + ij[:, 1]

    def centres(self, flat: np.ndarray) -> np.ndarray:
        """:meth:`centre` of each flat index in ``flat``: an (m, 2) array, the same numbers."""
        i, j = np.divmod(np.asarray(flat, dtype=np.int64), self.n)
        return np.column_stack(((i + 0.5) * self.cell - self.extent, (j + 0.5) * self.cell - self.extent))

    def centre(self, flat: int) -> tuple[float, float]:
        """The frame coordinates of a cell's centre, from its flat index."""
        i, j = divmod(int(flat), self.n)
        return (i + 0.5) * self.cell - self.extent, (j + 0.5) * self.cell - self.extent

    def walkable_points(self, stride: int = 2) -> np.ndarray:
        """Frame coordinates (an (m, 2) array) of the centres of the walkable cells, every
        ``stride``-th cell along each axis: the places the map says the robot could stand."""
        n = self.n
        out = np.empty((n * n // (stride * stride) + n, 2))
        m = walkable_points(self.free, self.hits, stride, self.extent, self.cell, out)
        return out[:m].copy()

    def known_ground(self, point: np.ndarray, known_free: np.ndarray | None = None) -> bool:
        """Whether the map knows the cell holding ``point``, or one beside it, as free ground (or,
        given ``known_free``, a copy of :attr:`known_free` taken earlier, whether that grid did)."""
        i, j = self.index(float(point[0]), float(point[1]))
        rows, cols = slice(max(i - 1, 0), max(i + 2, 0)), slice(max(j - 1, 0), max(j + 2, 0))
        if known_free is not None:
            return bool(np.any(known_free[rows, cols]))
        free, hits = self.free[rows, cols], self.hits[rows, cols]
        return bool(np.any((free > 0) & (hits < free)))

    def end_dry_run(self) -> None:
        """The dry run is over: with ``dry_reachable_only``, the ground it found is kept (:meth:`reaches_dry_ground`)."""
        if self.config.dry_reachable_only:
            self.dry_ground = self.known_free

    def reaches_dry_ground(self, point: np.ndarray) -> bool:
        """Whether walkable ground joins ``point`` to the ground the last dry run found (``True`` before one)."""
        if self.dry_ground is None or self.known_ground(point, self.dry_ground):
            return True
        i, j = self.index(float(point[0]), float(point[1]))
        self._reach_id += 1
        stamp, parent, queue = self._reach
        found, _ = search(
            self.free, self.hits, ~self.dry_ground, i, j, -1, stamp, parent, queue, self._reach_id, False, self._walk_cache, self._walk_id(),
        )  # fmt: skip
        return bool(found >= 0)

    @property
    def known_free(self) -> np.ndarray:
        """Cells the rays have shown free (a boolean grid)."""
        return (self.free > 0) & (self.hits < self.free)

    def explored_area(self) -> float:
        """Square metres of free ground the map knows."""
        return float(np.count_nonzero(self.known_free)) * self.cell**2

    # ------------------------------------------------------------------ save / load
    def state(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(JSON-able state, arrays): what :meth:`load_state` restores."""
        dry = {} if self.dry_ground is None else {"dry_ground": self.dry_ground}
        return {}, {**{name: getattr(self, name) for name in _GRIDS}, **dry}

    def load_state(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state`."""
        for name in ("change", "new_walls", "vantage"):  # (a save from before the map revised itself)
            if name not in arrays:
                arrays = {**arrays, name: np.full_like(getattr(self, name), -1 if name == "vantage" else 0)}
        for name in _GRIDS:
            ref, arr = getattr(self, name), arrays.get(name)
            if arr is None or arr.shape != ref.shape:
                raise ValueError(f"the map's array {name!r} is missing or not of shape {ref.shape}")
            setattr(self, name, arr.astype(ref.dtype))
        if (dry_ground := arrays.get("dry_ground")) is not None and dry_ground.shape != self.free.shape:  # (none before a dry run)
            raise ValueError(f"the map's array 'dry_ground' is not of shape {self.free.shape}")
        self.dry_ground = None if dry_ground is None else dry_ground.astype(np.bool_)
        self.grids_replaced()


_GRIDS = ("free", "hits", "visited", "searched", "change", "new_walls", "vantage")
_NO_JUDGED = np.empty(0)  # scan_agreement's judged, not asked for
