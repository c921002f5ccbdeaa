"""Independent brute-force references the tests check the library against."""

from __future__ import annotations

import numpy as np

from hippo_env.geometry import points_in_polygon
from hippo_env.maze import MazeSpec


def free_by_brute_force(spec: MazeSpec, points: np.ndarray, radius: float) -> np.ndarray:
    """Whether a disc of ``radius`` fits at each point: every point against every wall segment, in numpy."""
    a, b = spec.segments[:, :2], spec.segments[:, 2:]
    ab = b - a
    rel = points[:, None, :] - a[None, :, :]
    t = np.clip((rel * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-18), 0.0, 1.0)
    nearest = a[None] + t[..., None] * ab[None]
    free = np.linalg.norm(points[:, None, :] - nearest, axis=-1).min(axis=1) >= radius
    for polygon in spec.obstacles:
        free &= ~points_in_polygon(points, polygon)
    return free
