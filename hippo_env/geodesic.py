"""Shortest paths around a maze's obstacles: the one home of the geodesic.

Two ways, each exact for what it measures:

- :class:`VisibilityGraph`: the shortest path of a disc of ``radius`` between two points, around the
  obstacles inflated by ``radius``; a visibility graph over points placed around every convex
  obstacle corner, then Dijkstra. The environment's ``shortest_path_length`` (and so every run's
  indirectness) is this length.
- :class:`DistanceField`: geodesic distances to one goal over the free cells of a grid (an
  8-connected Dijkstra), for many positions at once: the dense reward and analyses.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from hippo_env.geometry import CHUNK, Point, Polygon, segment_distance, signed_area

# Points placed around each convex corner of an inflated obstacle: an arc every 15 degrees
# keeps the polygonal path within 2 mm of the true rounded one for a 0.17 m robot.
ARC_STEP = math.radians(15.0)
# Visibility segments may graze an inflated obstacle by this much (chords of those arcs).
GRAZE = 3e-3


class Walls(Protocol):
    """What a shortest path needs of a maze (a :class:`~hippo_env.maze.MazeSpec` is one): this
    module reads a maze through these alone, so it does not import the maze's module."""

    @property
    def obstacles(self) -> Sequence[Polygon]:
        """The obstacles, each a simple polygon."""
        ...

    @property
    def segments(self) -> np.ndarray:
        """Every wall as a segment ``(x0, y0, x1, y1)``: the arena's four walls first, then the obstacles' edges."""
        ...

    def clearances(self, points: Any) -> np.ndarray:
        """Each point's distance to the nearest wall; negative inside an obstacle or outside the arena."""
        ...


class VisibilityGraph:
    """Shortest paths of a disc of ``radius`` around ``maze``'s obstacles (inflated by ``radius``).

    The graph's nodes are points on an arc of ``radius`` around every convex obstacle corner (those
    clear of every wall) and its edges the straight segments between them that keep ``radius``
    from every obstacle; it is built once, and :meth:`length` joins the two end points to it.
    In an open arena a length is the straight line.
    """

    def __init__(self, maze: Walls, radius: float) -> None:
        self.radius = float(radius)
        self.walls = maze.segments[4:]  # the obstacles' edges (the arena's four walls come first)
        self.nodes = np.asarray(_corner_nodes(maze, self.radius)).reshape(-1, 2)
        k = len(self.nodes)
        a = np.repeat(self.nodes, k, axis=0)
        b = np.tile(self.nodes, (k, 1))
        seen = _visible_many(a, b, self.walls, self.radius - GRAZE).reshape(k, k)
        self.between = np.where(seen, np.linalg.norm(a - b, axis=1).reshape(k, k), np.inf)

    def length(self, start: Point, goal: Point) -> float:
        """The shortest path's length from ``start`` to ``goal`` (``inf`` if there is none)."""
        ends = np.asarray([start, goal], dtype=float)
        points = np.concatenate([ends, self.nodes])
        n = len(points)
        lengths = np.full((n, n), np.inf)
        lengths[2:, 2:] = self.between
        # Edges from the two end points to everything else.
        pairs_a = np.repeat(ends, n, axis=0)
        pairs_b = np.tile(points, (2, 1))
        seen = _visible_many(pairs_a, pairs_b, self.walls, self.radius - GRAZE).reshape(2, n)
        direct = np.linalg.norm(pairs_a - pairs_b, axis=1).reshape(2, n)
        lengths[:2] = np.where(seen, direct, np.inf)
        lengths[:, :2] = lengths[:2].T
        return _dijkstra(lengths, 0, 1)


def _corner_nodes(maze: Walls, radius: float) -> list[np.ndarray]:
    """Points on an arc of ``radius`` around every convex corner, those clear of every wall (by 3 mm grace)."""
    candidates = []
    margin = radius * (1 + 1e-6)
    for poly in maze.obstacles:
        pts = np.asarray(poly, float)
        orientation = 1.0 if signed_area(pts) > 0 else -1.0
        for k in range(len(pts)):
            prev_pt, corner, next_pt = pts[k - 1], pts[k], pts[(k + 1) % len(pts)]
            d_in, d_out = corner - prev_pt, next_pt - corner
            turn = orientation * (d_in[0] * d_out[1] - d_in[1] * d_out[0])
            if turn <= 0:  # a reflex (concave) corner: shortest paths never bend there
                continue
            # Outward normals of the two edges meeting at the corner; place points on the arc between them.
            n_in = orientation * np.array([d_in[1], -d_in[0]]) / np.linalg.norm(d_in)
            n_out = orientation * np.array([d_out[1], -d_out[0]]) / np.linalg.norm(d_out)
            # The arc turns the way the polygon turns at a convex corner: counter-clockwise for a
            # counter-clockwise polygon, clockwise for a clockwise one, the short way round in
            # both cases (a counter-clockwise sweep for every polygon would go the long way round
            # a clockwise polygon's corners and leave them uncovered).
            a0 = math.atan2(n_in[1], n_in[0])
            sweep = orientation * ((orientation * (math.atan2(n_out[1], n_out[0]) - a0)) % (2 * math.pi))
            steps = max(1, math.ceil(abs(sweep) / ARC_STEP))
            for s in range(steps + 1):
                angle = a0 + sweep * s / steps
                candidates.append(corner + margin * np.array([math.cos(angle), math.sin(angle)]))
    return [p for p, c in zip(candidates, maze.clearances(candidates)) if c >= radius - GRAZE]


def _visible_many(p0: np.ndarray, p1: np.ndarray, walls: np.ndarray, radius: float) -> np.ndarray:
    """Whether each segment p0[k]-p1[k] keeps at least ``radius`` from every wall.

    Only walls whose bounding box comes within ``radius`` of a segment's bounding box can be
    nearer than ``radius``; the exact distance is computed for those pairs only, in bounded chunks.
    """
    seen = np.ones(len(p0), dtype=bool)
    if len(walls) == 0:
        return seen
    low, high = np.minimum(p0, p1) - radius, np.maximum(p0, p1) + radius
    wall_low, wall_high = np.minimum(walls[:, :2], walls[:, 2:]), np.maximum(walls[:, :2], walls[:, 2:])
    step = max(1, CHUNK // len(walls))
    for start in range(0, len(p0), step):
        part = slice(start, start + step)
        near = np.all(low[part, None] <= wall_high[None], axis=-1) & np.all(wall_low[None] <= high[part, None], axis=-1)
        pair, wall = np.nonzero(near)
        close = segment_distance(p0[part][pair], p1[part][pair], walls[wall, :2], walls[wall, 2:]) < radius
        seen[start + pair[close]] = False
    return seen


def _dijkstra(lengths: np.ndarray, source: int, target: int) -> float:
    """Shortest path on a small dense graph (inf = no edge)."""
    n = len(lengths)
    best = np.full(n, np.inf)
    best[source] = 0.0
    done = np.zeros(n, dtype=bool)
    for _ in range(n):
        u = int(np.argmin(np.where(done, np.inf, best)))
        if done[u] or not np.isfinite(best[u]):
            break
        if u == target:
            break
        done[u] = True
        best = np.minimum(best, best[u] + lengths[u])
    return float(best[target])


@dataclass(frozen=True)
class DistanceField:
    """Geodesic distances to a goal over the free cells of a grid (8-connected Dijkstra).

    The grid's cells are squares of side ``spacing``; cell ``(row, col)`` has its lower-left
    corner at ``corner + spacing * (col, row)`` and its centre at ``(xs[col], ys[row])``.
    ``distances[row, col]`` is ``inf`` at cells the robot cannot occupy or reach.
    """

    corner: np.ndarray
    spacing: float
    xs: np.ndarray
    ys: np.ndarray
    distances: np.ndarray

    @classmethod
    def from_grid(
        cls, xs: np.ndarray, ys: np.ndarray, free: np.ndarray, corner: np.ndarray, spacing: float, goal: np.ndarray
    ) -> DistanceField:
        """Dijkstra over the ``free`` cells from the free cell whose centre is nearest ``goal``
        (of equally near ones, the first in row-major order: a goal on a cell border is not ambiguous)."""
        field = cls(np.asarray(corner, float), spacing, xs, ys, np.full(free.shape, np.inf))
        if not free.any():
            return field
        rows, cols = free.shape
        gx, gy = np.meshgrid(xs, ys)
        flat = np.flatnonzero(free)
        centres = np.column_stack([gx.ravel(), gy.ravel()])[flat]
        start_row, start_col = divmod(int(flat[np.argmin(np.linalg.norm(centres - np.asarray(goal, float), axis=1))]), cols)
        distances = field.distances
        distances[start_row, start_col] = 0.0
        queue = [(0.0, start_row, start_col)]
        moves = [(dr, dc, spacing * math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
        while queue:
            dist, r, c = heapq.heappop(queue)
            if dist > distances[r, c]:
                continue
            for dr, dc, cost in moves:
                rr, cc = r + dr, c + dc
                if 0 <= rr < rows and 0 <= cc < cols and free[rr, cc] and dist + cost < distances[rr, cc]:
                    distances[rr, cc] = dist + cost
                    heapq.heappush(queue, (dist + cost, rr, cc))
        return field

    def cell(self, positions: np.ndarray | Point) -> tuple[np.ndarray, np.ndarray]:
        """Row and column of the cell holding each of ``positions`` (``(k, 2)`` or one point), clipped to the grid."""
        xy = np.asarray(positions, float).reshape(-1, 2)
        rows, cols = self.distances.shape
        index = ((xy - self.corner) / self.spacing).astype(int)
        return np.clip(index[:, 1], 0, rows - 1), np.clip(index[:, 0], 0, cols - 1)

    def at(self, positions: np.ndarray | Point) -> np.ndarray:
        """Geodesic distance from each position to the goal: over the cell holding it and the 8 around,
        the least of a cell's distance plus the step to that cell (``inf`` when none is reachable)."""
        rows, cols = self.cell(positions)
        padded = np.pad(self.distances, 1, constant_values=np.inf)
        steps = [(dr, dc, self.spacing * math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1)]
        return np.min([padded[rows + 1 + dr, cols + 1 + dc] + step for dr, dc, step in steps], axis=0)
