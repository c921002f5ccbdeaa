"""The omnidirectional rangefinder: exact ray casting against the maze's wall segments.

Each ray is tested only against the walls inside its direction: for every segment the kernel
works out the angular interval it subtends from the robot and visits just the rays in that
interval (an angular sweep), compiled with numba. In a walled room every ray meets about
two segments, so a 720-ray scan costs a few microseconds instead of 720 x n_segments tests.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_TWO_PI = 2.0 * math.pi


@njit(cache=True)
def _scan(
    x: float, y: float, heading: float, ray_cos: np.ndarray, ray_sin: np.ndarray, segments: np.ndarray, max_range: float, out: np.ndarray
) -> None:
    n = ray_cos.shape[0]
    step = _TWO_PI / n
    c, s = math.cos(heading), math.sin(heading)
    for k in range(n):
        out[k] = max_range
    for m in range(segments.shape[0]):
        ax = segments[m, 0] - x
        ay = segments[m, 1] - y
        ex = segments[m, 2] - segments[m, 0]
        ey = segments[m, 3] - segments[m, 1]
        # Egocentric angles of the two end points, and the (shorter) arc between them.
        a0 = math.atan2(ay, ax) - heading
        a1 = math.atan2(ay + ey, ax + ex) - heading
        span = (a1 - a0 + math.pi) % _TWO_PI - math.pi
        if span < 0.0:
            a0 = a1
            span = -span
        first = math.ceil(a0 / step - 1e-9)
        last = math.floor((a0 + span) / step + 1e-9)
        for i in range(first, last + 1):
            k = i % n
            # Ray direction: the egocentric unit vector rotated by the heading.
            dx = c * ray_cos[k] - s * ray_sin[k]
            dy = s * ray_cos[k] + c * ray_sin[k]
            denom = dx * ey - dy * ex
            if denom == 0.0:
                continue
            t = (ax * ey - ay * ex) / denom
            u = (ax * dy - ay * dx) / denom
            if t >= 0.0 and -1e-9 <= u <= 1.0 + 1e-9 and t < out[k]:
                out[k] = t


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
        if not isinstance(n_rays, (int, np.integer)) or isinstance(n_rays, bool) or n_rays < 1:
            raise ValueError(f"n_rays must be a positive integer, got {n_rays!r}")
        if not isinstance(max_range, (int, float, np.number)) or not (math.isfinite(max_range) and max_range > 0):
            raise ValueError(f"max_range must be a positive number of metres, got {max_range!r}")
        self.segments = np.ascontiguousarray(segments, dtype=np.float64)
        self.n_rays = int(n_rays)
        self.max_range = float(max_range)
        angles = np.arange(self.n_rays) * (_TWO_PI / self.n_rays)
        self._cos, self._sin = np.cos(angles), np.sin(angles)
        self._out = np.empty(self.n_rays, dtype=np.float64)

    def scan(self, position: np.ndarray | tuple[float, float], heading: float) -> np.ndarray:
        """Noise-free ranges (float64, a fresh array) from ``position`` facing ``heading``."""
        _scan(float(position[0]), float(position[1]), float(heading), self._cos, self._sin, self.segments, self.max_range, self._out)
        return self._out.copy()
