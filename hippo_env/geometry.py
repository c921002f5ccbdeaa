"""Plane geometry shared by the maze, the physics, the rangefinder and analyses: the bottom layer.

Angles are wrapped here, and the distance from a point to a wall segment is computed here, once,
by one compiled kernel that every caller uses (a point's clearance, the free cells of a grid), so
that the maze's free-space tests, the robot's wall checks and any analysis agree to the last bit.
Geodesic distances over a grid of free cells are computed here too, by one Dijkstra.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numpy as np
from numba import njit


def wrap_angle(angle: float) -> float:
    """Wrap an angle (rad) to [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


@njit(cache=True)
def _segment_distance(x: float, y: float, ax: float, ay: float, bx: float, by: float) -> float:  # pragma: no cover - compiled
    """Distance from ``(x, y)`` to the segment from ``(ax, ay)`` to ``(bx, by)``."""
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    t = ((x - ax) * ex + (y - ay) * ey) / length2 if length2 > 0.0 else 0.0
    t = min(1.0, max(0.0, t))
    return math.hypot(x - ax - t * ex, y - ay - t * ey)


@njit(cache=True)
def segments_clearance(x: float, y: float, segments: np.ndarray) -> float:  # pragma: no cover - compiled
    """Distance from ``(x, y)`` to the nearest of ``segments`` (rows ``(x0, y0, x1, y1)``), unsigned."""
    best = math.inf
    for m in range(segments.shape[0]):
        d = _segment_distance(x, y, segments[m, 0], segments[m, 1], segments[m, 2], segments[m, 3])
        best = min(best, d)
    return best


@njit(cache=True)
def clear_of_segments(free: np.ndarray, xs: np.ndarray, ys: np.ndarray, segments: np.ndarray, radius: float) -> None:  # pragma: no cover
    """Set ``free[row, col]`` False where the point ``(xs[col], ys[row])`` is nearer than ``radius`` to a segment.

    Each segment visits only the cells within ``radius`` of its bounding box (``xs`` and ``ys``
    ascending), so the cost is the walls' surroundings, not the grid times the walls.
    """
    for m in range(segments.shape[0]):
        ax, ay, bx, by = segments[m, 0], segments[m, 1], segments[m, 2], segments[m, 3]
        c0 = np.searchsorted(xs, min(ax, bx) - radius)
        c1 = np.searchsorted(xs, max(ax, bx) + radius, side="right")
        r0 = np.searchsorted(ys, min(ay, by) - radius)
        r1 = np.searchsorted(ys, max(ay, by) + radius, side="right")
        for r in range(r0, r1):
            for c in range(c0, c1):
                if free[r, c] and _segment_distance(xs[c], ys[r], ax, ay, bx, by) < radius:
                    free[r, c] = False


def clearance(position: np.ndarray | tuple[float, float], segments: np.ndarray) -> float:
    """Distance from ``position`` to the nearest wall segment (unsigned)."""
    return float(segments_clearance(float(position[0]), float(position[1]), segments))


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

    def cell(self, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Row and column of the cell holding each of ``positions`` (``(k, 2)`` or one point), clipped to the grid."""
        xy = np.asarray(positions, float).reshape(-1, 2)
        rows, cols = self.distances.shape
        index = ((xy - self.corner) / self.spacing).astype(int)
        return np.clip(index[:, 1], 0, rows - 1), np.clip(index[:, 0], 0, cols - 1)

    def at(self, positions: np.ndarray) -> np.ndarray:
        """Geodesic distance from each position to the goal: over the cell holding it and the 8 around,
        the least of a cell's distance plus the step to that cell (``inf`` when none is reachable)."""
        rows, cols = self.cell(positions)
        padded = np.pad(self.distances, 1, constant_values=np.inf)
        steps = [(dr, dc, self.spacing * math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1)]
        return np.min([padded[rows + 1 + dr, cols + 1 + dc] + step for dr, dc, step in steps], axis=0)
