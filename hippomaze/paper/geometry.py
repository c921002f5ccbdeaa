"""Geometry of the paper's experiments: the free grid over a maze, geodesic distances on it, the
distance to a path (the free test and angle wrapping are hippo_env's)."""

from __future__ import annotations

import functools
import heapq
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS


@dataclass
class Grid:
    """A regular grid over a maze: ``positions`` are the free cells' centres, row-major; ``origin`` is
    the centre of cell (0, 0), ``shape`` is (rows, cols) and ``flat`` each free position's flat cell index."""

    spacing: float
    origin: np.ndarray
    shape: tuple[int, int]
    flat: np.ndarray
    positions: np.ndarray


@functools.lru_cache(maxsize=16)
def grid_for(maze: str, spacing: float) -> Grid:
    """The free positions (clearance >= the robot's radius) of a grid with ``spacing``."""
    spec = MazeSpec.load(maze)
    hw, hh = spec.half_extent
    xs = np.arange(-hw + spacing / 2, hw - 1e-9, spacing)
    ys = np.arange(-hh + spacing / 2, hh - 1e-9, spacing)
    gx, gy = np.meshgrid(xs, ys)
    points = np.column_stack([gx.ravel(), gy.ravel()])
    free = spec.free_mask(points, ROBOT_RADIUS)
    return Grid(spacing, np.array([xs[0], ys[0]]), (len(ys), len(xs)), np.flatnonzero(free), points[free])


@functools.lru_cache(maxsize=64)
def distance_field(maze: str, goal: tuple[float, float], spacing: float = 0.1) -> tuple[Grid, np.ndarray]:
    """Geodesic distance (8-connected Dijkstra on a 0.1 m grid of free cells) from ``goal`` to every cell."""
    grid = grid_for(maze, spacing)
    rows, cols = grid.shape
    dist = np.full(rows * cols, np.inf)
    free = np.zeros(rows * cols, bool)
    free[grid.flat] = True
    start = grid.flat[np.argmin(np.linalg.norm(grid.positions - np.asarray(goal), axis=1))]
    dist[start] = 0.0
    queue = [(0.0, int(start))]
    moves = [(dr, dc, spacing * math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
    while queue:
        d, cell = heapq.heappop(queue)
        if d > dist[cell]:
            continue
        r, c = divmod(cell, cols)
        for dr, dc, cost in moves:
            rr, cc = r + dr, c + dc
            if 0 <= rr < rows and 0 <= cc < cols:
                nxt = rr * cols + cc
                if free[nxt] and d + cost < dist[nxt]:
                    dist[nxt] = d + cost
                    heapq.heappush(queue, (d + cost, nxt))
    return grid, dist.reshape(rows, cols)


def geodesic_to(maze: str, goal: Any, positions: np.ndarray) -> np.ndarray:
    """Geodesic distance from ``goal`` to each position (the nearest reachable grid cell's)."""
    grid, field = distance_field(maze, (float(goal[0]), float(goal[1])))
    rows, cols = grid.shape
    padded = np.pad(field, 1, constant_values=np.inf)
    rc = np.rint((np.asarray(positions) - grid.origin) / grid.spacing).astype(int)
    col = np.clip(rc[:, 0], 0, cols - 1) + 1
    row = np.clip(rc[:, 1], 0, rows - 1) + 1
    near = np.stack([padded[row + dr, col + dc] + (grid.spacing * math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1)])
    return near.min(axis=0)


def distance_to_path(positions: np.ndarray, path: np.ndarray, chunk: int = 512) -> np.ndarray:
    """Each position's distance to the nearest point of ``path``."""
    path = np.asarray(path, float).reshape(-1, 2)
    if len(path) == 0:
        return np.full(len(positions), np.inf)
    out = np.empty(len(positions))
    for s in range(0, len(positions), chunk):
        d = np.linalg.norm(positions[s : s + chunk, None, :] - path[None, :, :], axis=2)
        out[s : s + chunk] = d.min(axis=1)
    return out
