"""Plane geometry shared by the maze, the physics and the rangefinder: the bottom layer.

Angles are wrapped here, and the distance from a point to the nearest wall segment (the
clearance) is computed here, once, by one compiled kernel that every caller uses, so that the
maze's free-space tests, the robot's wall checks and any analysis agree to the last bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


def wrap_angle(angle: float) -> float:
    """Wrap an angle (rad) to [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


@njit(cache=True)
def segments_clearance(x: float, y: float, segments: np.ndarray) -> float:  # pragma: no cover - compiled
    """Distance from ``(x, y)`` to the nearest of ``segments`` (rows ``(x0, y0, x1, y1)``), unsigned."""
    best = math.inf
    for m in range(segments.shape[0]):
        ax, ay = segments[m, 0], segments[m, 1]
        ex, ey = segments[m, 2] - ax, segments[m, 3] - ay
        length2 = ex * ex + ey * ey
        t = ((x - ax) * ex + (y - ay) * ey) / length2 if length2 > 0.0 else 0.0
        t = min(1.0, max(0.0, t))
        d = math.hypot(x - ax - t * ex, y - ay - t * ey)
        best = min(best, d)
    return best


def clearance(position: np.ndarray | tuple[float, float], segments: np.ndarray) -> float:
    """Distance from ``position`` to the nearest wall segment (unsigned)."""
    return float(segments_clearance(float(position[0]), float(position[1]), segments))


__all__ = ["clearance", "segments_clearance", "wrap_angle"]
