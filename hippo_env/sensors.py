"""The omnidirectional rangefinder: exact ray casting against the maze's wall segments.

Each ray is tested only against the walls inside its direction: for every segment the kernel
works out the angular interval it subtends from the robot and visits just the rays in that
interval (an angular sweep), compiled with numba. In a walled room every ray meets about
two segments, so a scan costs about one test per ray instead of one per ray and segment.
The rays well inside a segment's ends are tested in one branch-free loop over consecutive rays,
which the compiler vectorises (the division per test is most of a scan's time); a ray's range is
the least distance over the segments, so the order of the tests does not change it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from hippo_env.checks import check_int, check_number

_TWO_PI = 2.0 * math.pi


@njit(cache=True, error_model="numpy", inline="always")
def _visit(lo: int, hi: int, dxs: np.ndarray, dys: np.ndarray, ex: float, ey: float, cross: float, ranges: np.ndarray) -> None:
    """Rays ``lo`` to ``hi - 1`` against a segment they meet well inside its ends (no wall-side
    test): one branch-free loop the compiler vectorises. It runs over slices, whose indices are never
    negative (no wraparound check), and divides under NumPy's error model (a zero denominator gives
    inf or nan, masked out, not a check that would stop the vectorising)."""
    xs, ys, rs = dxs[lo:hi], dys[lo:hi], ranges[lo:hi]
    for j in range(rs.shape[0]):
        denom = xs[j] * ey - ys[j] * ex
        t = cross / denom
        r = rs[j]
        rs[j] = t if (denom != 0.0) & (t >= 0.0) & (t < r) else r


@njit(cache=True, error_model="numpy", inline="always")
def _visit_ends(
    lo: int, hi: int, dxs: np.ndarray, dys: np.ndarray, ax: float, ay: float, ex: float, ey: float, cross: float, ranges: np.ndarray
) -> None:
    """Rays ``lo`` to ``hi - 1`` against a segment, each with the wall-side test ``u``."""
    for k in range(lo, hi):
        dx, dy = dxs[k], dys[k]
        denom = dx * ey - dy * ex
        if denom != 0.0:
            t = cross / denom
            if t >= 0.0 and t < ranges[k]:
                u = (ax * dy - ay * dx) / denom
                if -1e-9 <= u <= 1.0 + 1e-9:
                    ranges[k] = t


@njit(cache=True, error_model="numpy", inline="always")
def _visit_wrapped(
    first: int,
    stop: int,
    dxs: np.ndarray,
    dys: np.ndarray,
    ax: float,
    ay: float,
    ex: float,
    ey: float,
    cross: float,
    ranges: np.ndarray,
    ends: bool,
) -> None:
    """Rays ``first`` to ``stop - 1`` counted round the circle (ray ``i`` is ray ``i % n``) against a
    segment: in runs of consecutive rays, with the wall-side test if ``ends``."""
    n = ranges.shape[0]
    i = first
    while i < stop:
        lo = i % n
        hi = min(lo + stop - i, n)
        if ends:
            _visit_ends(lo, hi, dxs, dys, ax, ay, ex, ey, cross, ranges)
        else:
            _visit(lo, hi, dxs, dys, ex, ey, cross, ranges)
        i += hi - lo


@njit(cache=True, error_model="numpy")
def _scan(
    x: float, y: float, heading: float, rays: np.ndarray, segments: np.ndarray, max_range: float, ranges: np.ndarray, ranges32: np.ndarray
) -> None:
    """The ranges into ``ranges`` and, rounded, into ``ranges32`` (if it is not empty).

    ``rays`` holds the egocentric unit vectors (cos, sin) in rows 0 and 1; rows 2 and 3 are
    scratch for the allocentric ones.
    """
    n = rays.shape[1]
    step = _TWO_PI / n
    c, s = math.cos(heading), math.sin(heading)
    dxs, dys = rays[2], rays[3]
    for k in range(n):
        # Ray direction: the egocentric unit vector rotated by the heading.
        dxs[k] = c * rays[0, k] - s * rays[1, k]
        dys[k] = s * rays[0, k] + c * rays[1, k]
        ranges[k] = max_range
    for m in range(segments.shape[0]):
        ax = segments[m, 0] - x
        ay = segments[m, 1] - y
        ex = segments[m, 2] - segments[m, 0]
        ey = segments[m, 3] - segments[m, 1]
        cross = ax * ey - ay * ex
        # Egocentric angles of the two end points, and the (shorter) arc between them.
        a0 = math.atan2(ay, ax) - heading
        a1 = math.atan2(ay + ey, ax + ex) - heading
        span = (a1 - a0 + math.pi) % _TWO_PI - math.pi
        if span < 0.0:
            a0 = a1
            span = -span
        first = math.ceil(a0 / step - 1e-9)
        last = math.floor((a0 + span) / step + 1e-9)
        # A ray strictly between the first and the last (at least one ray step inside the arc)
        # meets the segment well inside its ends: its wall-side test u passes by a margin far
        # beyond rounding, provided neither end is too close to the robot for the segment's
        # length (u's rounding error is about eps * |e| / (|a| * step)), so it is skipped.
        near2 = min(ax * ax + ay * ay, (ax + ex) * (ax + ex) + (ay + ey) * (ay + ey))
        inside_sure = near2 * step * step > 1e-10 * (ex * ex + ey * ey)
        if inside_sure and last - first >= 2:
            _visit_wrapped(first, first + 1, dxs, dys, ax, ay, ex, ey, cross, ranges, True)
            _visit_wrapped(first + 1, last, dxs, dys, ax, ay, ex, ey, cross, ranges, False)
            _visit_wrapped(last, last + 1, dxs, dys, ax, ay, ex, ey, cross, ranges, True)
        else:
            _visit_wrapped(first, last + 1, dxs, dys, ax, ay, ex, ey, cross, ranges, True)
    for k in range(ranges32.shape[0]):
        ranges32[k] = ranges[k]


class Rangefinder:
    """An omnidirectional rangefinder of ``n_rays`` evenly spaced rays.

    ``scan(position, heading)[i]`` is the distance to the nearest wall along the egocentric
    angle ``2*pi*i/n_rays`` counter-clockwise from the heading, capped at ``max_range``.

    Args:
        segments: Walls as rows ``(x0, y0, x1, y1)`` (see :attr:`hippo_env.maze.MazeSpec.segments`).
        n_rays: Number of rays over 360 degrees.
        max_range: Largest distance reported, in metres.
    """

    def __init__(self, segments: np.ndarray, n_rays: int = 720, max_range: float = 10.0) -> None:
        check_int(n_rays, "n_rays", 1, "a positive integer")
        check_number(max_range, "max_range", "a positive number of metres", 0.0, strict=True)
        self.segments = np.ascontiguousarray(segments, dtype=np.float64)
        self.n_rays = int(n_rays)
        self.max_range = float(max_range)
        angles = np.arange(self.n_rays) * (_TWO_PI / self.n_rays)
        self._rays = np.empty((4, self.n_rays))
        self._rays[0], self._rays[1] = np.cos(angles), np.sin(angles)
        self._last = np.empty(self.n_rays, dtype=np.float64)
        self._no_float32 = np.empty(0, dtype=np.float32)

    def scan(self, position: np.ndarray | tuple[float, float], heading: float) -> np.ndarray:
        """Noise-free ranges (float64, a fresh array) from ``position`` facing ``heading``."""
        ranges = np.empty(self.n_rays, dtype=np.float64)
        _scan(float(position[0]), float(position[1]), float(heading), self._rays, self.segments, self.max_range, ranges, self._no_float32)
        return ranges

    def scan_float32(self, x: float, y: float, heading: float) -> np.ndarray:
        """:meth:`scan` rounded to float32 (a fresh array), as an observation holds it.

        The float64 ranges stay in :attr:`last_ranges` until the next call.
        """
        ranges32 = np.empty(self.n_rays, dtype=np.float32)
        _scan(x, y, heading, self._rays, self.segments, self.max_range, self._last, ranges32)
        return ranges32

    @property
    def last_ranges(self) -> np.ndarray:
        """The float64 ranges of the latest :meth:`scan_float32` (overwritten by the next; copy to keep them)."""
        return self._last
