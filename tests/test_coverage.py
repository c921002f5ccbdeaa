"""benchmarks.coverage: coverage against dry-run steps, measured from outside."""

from __future__ import annotations

import json

import numpy as np

from benchmarks.coverage import coverage_curve, free_cells, main, steps_to
from hippo_env.maze import MazeSpec


def test_coverage_curve_counts_each_cell_once_when_first_reached():
    spec = MazeSpec.load("open")
    cells = free_cells(spec)
    # standing still covers a disk of 0.5 m; walking on covers more; nothing is ever lost
    positions = np.array([[0.0, 0.0]] * 3 + [[x, 0.0] for x in np.arange(0.15, 3.0, 0.15)])
    curve = coverage_curve(spec, positions)
    assert curve.shape == (len(positions),)
    assert np.all(np.diff(curve) >= 0) and 0 < curve[0] == curve[2] < curve[-1] < 1
    assert abs(curve[0] * len(cells) - np.sum(np.hypot(cells[:, 0], cells[:, 1]) <= 0.5)) < 1e-9
    assert steps_to(curve, 1.0) is None and steps_to(curve, curve[5]) <= 6


def test_a_tiny_run_writes_its_json_and_figures(tmp_path):
    main(["--mazes", "open", "--seeds", "0", "--random-steps", "200", "--out", str(tmp_path)])
    record = json.loads((tmp_path / "coverage.json").read_text())
    (row,) = record["rows"]
    assert row["random"]["steps"] == 200 and 0 < row["random"]["final"] <= 1
    assert row["directed"]["sweep_steps"] < row["directed"]["steps"]
    assert (tmp_path / "coverage.png").stat().st_size > 0 and (tmp_path / "paths.png").stat().st_size > 0
