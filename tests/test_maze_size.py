"""Large arenas: a documented maximum size, and set-up whose cost does not grow with walls x area."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from brute_force import free_by_brute_force

from hippo_env import MazeSpec
from hippo_env.maze import MAX_SIZE

R = 0.17


@pytest.mark.parametrize("size", [[MAX_SIZE + 1, 10.0], [10.0, 1000.0], [1e9, 1e9]])
def test_sizes_beyond_the_maximum_are_a_clear_error(size):
    with pytest.raises(ValueError, match=rf"'size' .* is too large; width and height may be at most {MAX_SIZE:g} m"):
        MazeSpec.from_dict({"name": "huge", "size": size, "obstacles": []})


def test_the_maximum_size_is_accepted():
    spec = MazeSpec(name="largest", size=(MAX_SIZE, MAX_SIZE), obstacles=(((-1.0, -1.0), (1.0, -1.0), (0.0, 1.0)),))
    spec.check_connected(R)


def _rectangles(size: float, count: int, seed: int) -> list:
    rng = np.random.default_rng(seed)
    obstacles = []
    for _ in range(count):
        cx, cy = rng.uniform(-size / 2 + 3, size / 2 - 3, 2)
        w, h = rng.uniform(0.3, 3.0, 2)
        obstacles.append([[cx - w / 2, cy - h / 2], [cx + w / 2, cy - h / 2], [cx + w / 2, cy + h / 2], [cx - w / 2, cy + h / 2]])
    return obstacles


def test_connectivity_check_memory_is_bounded_for_a_40_m_maze():
    """Before: every grid point against every wall at once, 2.9 GB for 40 m x 40 m with 12 obstacles."""
    spec = MazeSpec(name="big", size=(40.0, 40.0), obstacles=_rectangles(40.0, 12, 0))
    spec.check_connected(R)  # compile once
    tracemalloc.start()
    spec.check_connected(R)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < 100e6, f"peak {peak / 1e6:.0f} MB"


@pytest.mark.parametrize("seed", range(3))
def test_free_grid_equals_every_point_against_every_wall(seed):
    """The bounded-box rasterisation marks exactly the cells a brute-force check marks."""
    rng = np.random.default_rng(seed)
    size = (float(rng.uniform(3, 8)), float(rng.uniform(3, 8)))
    touching = [[size[0] / 2, 0.0], [size[0] / 2 - 1.0, 0.3], [size[0] / 2 - 0.4, -0.8]]  # against the right wall
    spec = MazeSpec(name="x", size=size, obstacles=[[[-1.0, -0.5], [0.7, -1.2], [1.5, 1.0], [0.2, 0.1]], touching])
    xs, ys, free = spec.free_grid(R, 0.05)
    gx, gy = np.meshgrid(xs, ys)
    points = np.stack([gx.ravel(), gy.ravel()], axis=1)
    np.testing.assert_array_equal(free, free_by_brute_force(spec, points, R).reshape(free.shape))
    np.testing.assert_array_equal(free, spec.free_mask(points, R).reshape(free.shape))
