"""The diagnosis tool's measures and the maze suite's plumbing, on small hand-made cases."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.diagnose import DiagnoseArgs, across_walls, diagnose, path_distances, spec_name, twin_share
from benchmarks.maze_suite import maze_source, one
from hippo_env.maze import MazeSpec

WALL = MazeSpec.from_dict({"name": "wall", "size": [6.0, 6.0], "obstacles": [[[-3.0, -0.15], [2.0, -0.15], [2.0, 0.15], [-3.0, 0.15]]]})


def test_geodesic_goes_around_the_wall():
    d = path_distances(WALL, np.array([[-2.0, -1.0]]), np.array([[-2.0, 1.0], [-2.0, -2.0]]))[0]
    assert d[0] > 2 * np.hypot(4.2, 1.0) - 0.3  # around the wall's free end at x = 2
    assert abs(d[1] - 1.0) < 0.1  # within a cell of the 0.1 m grid (both points lie on cell corners)


def test_twins_and_similarity_across_walls():
    places = np.array([[0.0, 0.0], [0.0, 1.0], [5.0, 0.0]])
    far = np.array([[0.0, 3.0, 5.0], [3.0, 0.0, 5.0], [5.0, 5.0, 0.0]])  # by path
    distinct = np.eye(3)
    assert twin_share(distinct, far) == 0.0
    alike = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 0.1]])  # place 2 looks like place 0, 5 m away
    assert twin_share(alike, far) == pytest.approx(2 / 3)
    assert across_walls(distinct, places, far) == 0.0  # places 0 and 1: 1 m apart, 3 m by path
    assert across_walls(np.ones((3, 2)), places, far) == pytest.approx(1.0)
    assert across_walls(distinct, places, np.zeros((3, 3))) is None  # no pair far by path


def test_diagnose_runs_and_reports_every_measure(tmp_path):
    path = tmp_path / "small.json"
    path.write_text('{"name": "small", "size": [4.0, 4.0], "obstacles": []}')
    record, coverage = diagnose(DiagnoseArgs(maze=str(path), trials=1, dry_run_steps=300, config='{"model.n_place": 300}'))
    for key in (
        "twins",
        "reward_map_spearman",
        "replay_reach_median_m",
        "preplay_progress",
        "pi_error_median_m",
        "pi_error_dry_run_median_m",
        "runs_misplaced_share",
        "anchor_steps_median",
        "exploit_fallback_share",
        "dry_run_coverage_at_end",
    ):
        assert key in record
    assert len(coverage) == 1 and 0 < record["dry_run_coverage_at_end"] <= 1
    assert np.all(np.diff(coverage[0]) >= 0)  # coverage never falls
    assert record["pi_error_dry_run_median_m"] is not None and record["pi_error_dry_run_median_m"] < 0.2
    assert record["pi_error_median_m"] is not None and record["runs_misplaced_share"] is not None
    assert 0.0 <= record["run_steps_within_half_metre_share"] <= record["pi_within_half_metre_share"] <= 1.0
    assert 0.0 <= record["anchored_off_known_ground_share"] <= 1.0 and 0.0 <= record["anchored_off_dry_run_ground_share"] <= 1.0
    assert record["trials"] == 1 and len(record["indirectness_median_per_run"]) == 4


def test_maze_suite_runs_a_generated_maze():
    assert maze_source("open") == "open"
    assert MazeSpec.load(maze_source("gen-walls-100")).name == "gen-walls-100"
    row = one("paper", "open", seed=0, trials=1, dry_run_steps=200, config_json='{"model.n_place": 200}')
    assert row["trials"] == 1 and len(row["median_per_run"]) == 4 and row["env_steps_total"] > 200


def test_diagnose_names_a_generated_maze_as_the_suite_does():
    assert spec_name("gen-rooms-105") == "gen-rooms-105"
    with pytest.raises(ValueError, match="gen-<kind>-<seed>"):
        spec_name("gen-rooms")


def test_oracle_diagnosis_runs_with_the_true_position(tmp_path):
    path = tmp_path / "small.json"
    path.write_text('{"name": "small", "size": [4.0, 4.0], "obstacles": []}')
    record, _ = diagnose(DiagnoseArgs(maze=str(path), trials=1, dry_run_steps=300, oracle=True, config='{"model.n_place": 300}'))
    assert record["oracle_privileged"] and record["pi_error_median_m"] < 1e-9
    assert record["pi_within_half_metre_share"] == 1.0 and record["anchored_off_known_ground_share"] == 0.0
    assert record["anchored_off_dry_run_ground_share"] == 0.0
