"""hippomaze.paper (``python -m benchmarks.paper``): the --quick run end to end (REPORT.md, paper.json, every figure), and its helpers."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest

import hippomaze.paper
from hippo_env.geometry import convex_hull_area
from hippomaze.paper import PaperArgs, parse_args, run_paper
from hippomaze.paper.analysis import analyse_fields, components
from hippomaze.paper.design import SCENARIOS, trial_seed
from hippomaze.paper.figures import FIGURES
from hippomaze.paper.geometry import geodesic_to, grid_for
from hippomaze.paper.procedures import drive_scripted, make_env, replay_at
from hippomaze.stats import spearman

VERDICTS = {"reproduced", "partly", "not reproduced", "met", "not met"}


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper")
    paper = run_paper(PaperArgs(out=str(out), quick=True, workers=2, progress=False))
    return out, paper


def test_quick_run_writes_report_json_and_every_figure(quick_run):
    out, paper = quick_run
    assert json.loads((out / "paper.json").read_text()) == paper
    report = (out / "REPORT.md").read_text()
    expected = {name for name, _, _ in FIGURES}
    assert set(paper["figures"]) == expected
    for name in paper["figures"]:
        image = mpimg.imread(out / name)
        assert image.ndim == 3 and image.shape[0] >= 200 and image.shape[1] >= 200, name
        assert np.ptp(image[..., :3]) > 0, f"{name} is blank"
        assert f"]({name})" in report, f"REPORT.md does not show {name}"
    assert paper["command"] in report and "--quick" in paper["command"]


def test_quick_run_puts_every_claim_beside_a_measurement(quick_run):
    out, paper = quick_run
    report = (out / "REPORT.md").read_text()
    ids = [row["id"] for row in paper["claims"]]
    for rid in ("P1", "R1", "R2", "S1", "D1", "D2", "T1", "T2", "T3", "T4", "M1", "M2", "M3", "G1", "G2", "G3", "G4", "A1"):
        assert rid in ids
    for row in paper["claims"]:
        assert row["verdict"] in VERDICTS
        assert row["measured"] and row["paper"] and row["criterion"]
        assert f"| {row['id']} |" in report
    open_dmtp = paper["experiments"]["open_dmtp"]
    assert open_dmtp["trials"] == 3 and len(open_dmtp["episodes"]) == 3 * 2
    assert set(paper["experiments"]["generalisation"]) == set(SCENARIOS)


def test_parse_args_maps_flags_to_the_dataclass():
    args = parse_args(
        ["--out", "x", "--quick", "--seed", "3", "--workers", "1", "--trials", "5", "--no-progress", "--dry-run-steps", "100"]
    )
    assert args == PaperArgs(out="x", quick=True, seed=3, workers=1, trials=5, progress=False, dry_run_steps=100)
    assert parse_args([]) == PaperArgs()
    assert "--quick" in args.command() and "--trials 5" in args.command()


def test_quick_shrinks_everything():
    quick = PaperArgs(quick=True).resolved()
    full = PaperArgs()
    assert quick.trials < full.trials and quick.roam_steps < full.roam_steps and quick.dry_run_steps is not None
    assert full.resolved() == full


def test_cli_paper_subcommand_calls_run_paper(monkeypatch, tmp_path):
    from hippomaze import cli

    seen = []
    monkeypatch.setattr(hippomaze.paper, "run_paper", lambda args: seen.append(args) or {})
    assert cli.main(["paper", "--out", str(tmp_path), "--quick", "--seed", "2", "--workers", "1"]) == 0
    assert seen == [PaperArgs(out=str(tmp_path), quick=True, seed=2, workers=1)]


def test_the_app_imports_no_benchmark_and_importing_runs_nothing():
    # hippomaze.paper ships in the wheel, benchmarks/ does not; importing the wrapper script must not start a run
    code = "import sys, hippomaze.paper.run; print(sorted(m for m in sys.modules if m.startswith('benchmarks')))"
    root = Path(__file__).resolve().parent.parent
    app = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=root)
    assert app.stdout.strip() == "[]"
    script = subprocess.run([sys.executable, "-c", "import benchmarks.paper"], capture_output=True, text=True, check=True, cwd=root)
    assert script.stdout == "" and script.stderr == ""


def test_trial_seeds_match_the_dmtp_command():
    assert trial_seed(0, 7) == 7 and trial_seed(2, 7) == 2007


# ------------------------------------------------------------------------------- helpers
def test_geodesic_goes_around_walls():
    # maze4: from the NE compartment's centre to the NW one's the robot must go around the wall's end.
    d = geodesic_to("maze4", (2.5, 2.5), np.array([[2.5, 2.0], [-2.5, 2.5]]))
    assert d[0] == pytest.approx(0.5, abs=0.15)
    assert d[1] > 5.5  # straight line 5 m; around the wall end at y = 3.5 it is longer


def test_components_hull_and_rank_helpers():
    grid = grid_for("open", 0.5)
    left = np.flatnonzero((grid.positions[:, 0] < -3) & (np.abs(grid.positions[:, 1]) < 1))
    right = np.flatnonzero((grid.positions[:, 0] > 3) & (np.abs(grid.positions[:, 1]) < 1))
    pieces = components(grid, np.concatenate([left, right]))
    assert sorted(len(p) for p in pieces) == sorted([len(left), len(right)])
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]], float)
    assert convex_hull_area(square) == pytest.approx(1.0)
    x = np.arange(10.0)
    assert spearman(x, x**3) == pytest.approx(1.0)
    assert spearman(x, -x) == pytest.approx(-1.0)
    assert spearman(x, np.ones(10)) is None


def test_analyse_fields_sees_aliasing_across_quadrants():
    grid = grid_for("maze4", 0.25)
    pos = grid.positions
    # one cell firing at alike places of three compartments, one with a single blob, one silent
    alike = sum(np.exp(-np.sum((pos - c) ** 2, axis=1) / 0.1) for c in ((2.5, 2.5), (-2.5, 2.5), (-2.5, -2.5)))
    single = np.exp(-np.sum((pos - (2.0, -2.0)) ** 2, axis=1) / 0.1)
    rates = np.column_stack([alike, single, np.zeros(len(pos))])
    cells = {c.cell: c for c in analyse_fields(grid, rates)}
    assert set(cells) == {0, 1}
    assert cells[0].quadrants == 3 and cells[0].folded_spread < 0.3
    assert cells[1].quadrants == 1 and cells[1].pieces == 1 and cells[1].solidity > 0.8


def test_scripted_driver_walks_the_path_and_the_agent_learns():
    from hippo_agent import AgentConfig, HippocampalAgent

    env = make_env("open")
    env.reset(seed=0, options={"goal": None})
    agent = HippocampalAgent(
        env.observation_space, env.action_space, config=AgentConfig.paper().with_values({"model.dry_run_steps": 200}), seed=0
    )
    agent.dry_run(env)
    before = agent.place.W_pp.copy()
    path = drive_scripted(env, agent, ((-2.0, -2.0), (2.0, -2.0), (2.0, 1.0)))
    assert np.linalg.norm(path[0] - (-2.0, -2.0)) < 1e-6 and np.linalg.norm(path[-1] - (2.0, 1.0)) < 0.1
    assert np.all(np.abs(path[: len(path) // 2, 1] + 2.0) < 0.05)  # the first leg is straight
    assert not np.array_equal(before, agent.place.W_pp)  # W_pp learnt along the way
    assert replay_at(agent, env, (0.0, -2.0))
    assert agent.reward.W_rp[-1].max() == pytest.approx(1.0)


@pytest.mark.slow
def test_results_do_not_depend_on_the_number_of_workers(tmp_path):
    one = run_paper(PaperArgs(out=str(tmp_path / "one"), quick=True, workers=1, progress=False))
    two = run_paper(PaperArgs(out=str(tmp_path / "two"), quick=True, workers=2, progress=False))
    assert one["claims"] == two["claims"]
    assert one["experiments"] == two["experiments"]
