"""Plane geometry shared by the maze, the generator, the physics, the rangefinder and analyses:
the bottom layer, and the one home of every geometric primitive.

Angles are wrapped here; polygons' signed areas, orientation and containment, segment
intersection and the distances between points, segments and polygons are computed here. The
distance from a point to a wall segment is one compiled kernel that every caller uses (a point's
clearance, the free cells of a grid), so that the maze's free-space tests, the robot's wall
checks and any analysis agree to the last bit. Shortest paths are in :mod:`hippo_env.geodesic`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numba import njit

#: The most (point, segment) or (segment, wall) combinations worked on at once: bounds the memory
#: of the vectorised tests whatever the maze's size.
CHUNK = 1 << 18

Polygon = Sequence[Sequence[float]]  # vertices (x, y), either orientation, the first not repeated at the end
Point = tuple[float, float] | np.ndarray  # a position (x, y) in metres


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


# ---------------------------------------------------------------------- polygons
def signed_area(polygon: Polygon | np.ndarray) -> float:
    """The shoelace area of a polygon: positive when its vertices run counter-clockwise."""
    pts = np.asarray(polygon, dtype=float)
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def counter_clockwise(polygon: Sequence[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    """The polygon's vertices in counter-clockwise order (reversed if they run clockwise)."""
    vertices = tuple(polygon)
    return vertices if signed_area(vertices) > 0 else vertices[::-1]


def points_in_polygon(points: np.ndarray, polygon: Polygon | np.ndarray) -> np.ndarray:
    """Whether each of ``points`` (``(k, 2)``) lies inside ``polygon``: the even-odd rule, vectorised over the points."""
    px, py = points[:, 0], points[:, 1]
    inside = np.zeros(len(points), dtype=bool)
    pts = np.asarray(polygon, float)
    for (x0, y0), (x1, y1) in zip(pts, np.roll(pts, -1, axis=0)):
        crosses = (y0 > py) != (y1 > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_at = x0 + (py - y0) * (x1 - x0) / (y1 - y0)
        inside ^= crosses & (px < x_at)
    return inside


def convex_hull_area(points: np.ndarray) -> float:
    """Area of the convex hull of ``points`` (``(k, 2)``; Andrew's monotone chain), 0 for fewer than 3 distinct points."""
    pts = np.unique(np.round(points, 9), axis=0)
    if len(pts) < 3:
        return 0.0
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]

    def half(seq: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray] = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    hull = np.array(half(pts)[:-1] + half(pts[::-1])[:-1])
    return abs(signed_area(hull))


def point_in_polygon(x: float, y: float, polygon: Polygon | np.ndarray) -> bool:
    """Whether the point ``(x, y)`` lies inside ``polygon`` (:func:`points_in_polygon` for one point)."""
    return bool(points_in_polygon(np.array([[x, y]]), polygon)[0])


# ---------------------------------------------------------------------- segments
def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def segments_intersect(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> bool:
    """Whether the segments a-b and c-d share a point: they cross, or one touches or overlaps the other."""
    d1, d2, d3, d4 = _cross(c, d, a), _cross(c, d, b), _cross(a, b, c), _cross(a, b, d)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and d1 != 0 and d2 != 0 and d3 != 0 and d4 != 0:
        return True
    eps = 1e-12

    def on_segment(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> bool:  # r collinear with p-q and between them
        return bool(min(p[0], q[0]) - eps <= r[0] <= max(p[0], q[0]) + eps and min(p[1], q[1]) - eps <= r[1] <= max(p[1], q[1]) + eps)

    return (
        (abs(d1) < eps and on_segment(c, d, a))
        or (abs(d2) < eps and on_segment(c, d, b))
        or (abs(d3) < eps and on_segment(a, b, c))
        or (abs(d4) < eps and on_segment(a, b, d))
    )


def point_segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points to segments a-b, broadcasting over leading axes."""
    ab = b - a
    t = np.clip(((points - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-18), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[..., None] * ab), axis=-1)


def segment_distance(p: np.ndarray, q: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance between segments p-q and a-b (0 where they cross), broadcasting over leading axes."""

    def cross(o: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return (u[..., 0] - o[..., 0]) * (v[..., 1] - o[..., 1]) - (u[..., 1] - o[..., 1]) * (v[..., 0] - o[..., 0])

    crossing = (np.sign(cross(a, b, p)) * np.sign(cross(a, b, q)) < 0) & (np.sign(cross(p, q, a)) * np.sign(cross(p, q, b)) < 0)
    distance = np.minimum.reduce(
        [point_segment_distance(p, a, b), point_segment_distance(q, a, b), point_segment_distance(a, p, q), point_segment_distance(b, p, q)]
    )
    return np.where(crossing, 0.0, distance)


def polygon_distance(p: Polygon | np.ndarray, q: Polygon | np.ndarray) -> float:
    """Distance between two simple polygons (0 when they touch, cross or one holds the other)."""
    pa, qa = np.asarray(p, float), np.asarray(q, float)
    if point_in_polygon(qa[0, 0], qa[0, 1], pa) or point_in_polygon(pa[0, 0], pa[0, 1], qa):
        return 0.0
    edges_p = (pa[:, None, :], np.roll(pa, -1, axis=0)[:, None, :])
    edges_q = (qa[None, :, :], np.roll(qa, -1, axis=0)[None, :, :])
    return float(segment_distance(*edges_p, *edges_q).min())
