"""Geometry of the paper's experiments: the free grid over a maze, geodesic distances on it (both
hippo_env's, cached per maze and goal) and the distance to a path."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from hippo_env.geodesic import DistanceField
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS


@dataclass
class Grid:
    """A regular grid over a maze: ``positions`` are the free cells' centres, row-major; ``shape`` is
    (rows, cols) and ``flat`` each free position's flat cell index."""

    spacing: float
    shape: tuple[int, int]
    flat: np.ndarray
    positions: np.ndarray


@functools.lru_cache(maxsize=16)
def grid_for(maze: str, spacing: float) -> Grid:
    """The free positions (clearance >= the robot's radius) of a grid with ``spacing``."""
    xs, ys, free = MazeSpec.load(maze).free_grid(ROBOT_RADIUS, spacing)
    gx, gy = np.meshgrid(xs, ys)
    points = np.column_stack([gx.ravel(), gy.ravel()])
    flat = np.flatnonzero(free)
    return Grid(spacing, free.shape, flat, points[flat])


@functools.lru_cache(maxsize=64)
def _distance_field(maze: str, goal: tuple[float, float], spacing: float = 0.1) -> DistanceField:
    return MazeSpec.load(maze).distance_field(np.array(goal), ROBOT_RADIUS, spacing)


def geodesic_to(maze: str, goal: Any, positions: np.ndarray) -> np.ndarray:
    """Geodesic distance from ``goal`` to each position, on a 0.1 m grid (:meth:`DistanceField.at`)."""
    return _distance_field(maze, (float(goal[0]), float(goal[1]))).at(positions)


def distance_to_path(positions: np.ndarray, path: np.ndarray, chunk: int = 512) -> np.ndarray:
    """Each position's distance to the nearest point of ``path``."""
    positions = np.asarray(positions, float).reshape(-1, 2)
    path = np.asarray(path, float).reshape(-1, 2)
    if len(path) == 0:
        return np.full(len(positions), np.inf)
    out = np.empty(len(positions))
    for s in range(0, len(positions), chunk):
        dx = positions[s : s + chunk, 0, None] - path[None, :, 0]
        dy = positions[s : s + chunk, 1, None] - path[None, :, 1]
        out[s : s + chunk] = np.sqrt((dx * dx + dy * dy).min(axis=1))  # the root of the least square: one root per position
    return out
