"""benchmarks.door_probe: which map cells a door cut in a wall widened (its run is a benchmark)."""

from __future__ import annotations

import numpy as np

from benchmarks.door_probe import door_cells
from hippo_env.changes import change_maze
from hippo_env.maze import MazeSpec


def _grid(spec: MazeSpec, cell: float = 0.25) -> np.ndarray:
    half = spec.size[0] / 2
    ticks = np.arange(-half + cell / 2, half, cell)
    return np.array([(x, y) for x in ticks for y in ticks])


def test_an_unchanged_maze_has_no_door_cells_and_a_door_widens_one_opening():
    before = MazeSpec.load("maze2")
    centres = _grid(before)
    assert not door_cells(before, before, centres).any()
    after = change_maze(before, "door", 11002)
    widened = centres[door_cells(before, after, centres)]
    assert 4 <= len(widened) <= 60
    spread = np.max(np.linalg.norm(widened[:, None, :] - widened[None, :, :], axis=2))
    assert spread < 3.0  # one door of 1.2 m and the cells beside it, not walls thinned all over a 10 m maze
    assert all(before.clearance(tuple(p)) < after.clearance(tuple(p)) for p in widened)
