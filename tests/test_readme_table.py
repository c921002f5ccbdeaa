"""README.md's results table: made by ``python -m benchmarks.readme_table`` from the committed
results and the targets file, so it cannot drift from them; short, measured, and free of issue numbers."""

from __future__ import annotations

import re

import pytest

from benchmarks import readme_table, records
from benchmarks.targets import targets

README = readme_table.README


def test_the_readme_table_is_what_the_script_makes():
    """Fails when README.md's table differs from the committed results: run ``python -m benchmarks.readme_table``."""
    assert readme_table.in_readme(README.read_text()) == readme_table.block(), (
        "README.md's results table is out of date: run python -m benchmarks.readme_table"
    )


def test_the_table_is_short():
    rows = readme_table.rows()
    assert 0 < len(rows) <= readme_table.MAX_ROWS
    for row in rows:
        assert len(row) == 3 and all("\n" not in cell and "|" not in cell for cell in row), row
        assert all(len(cell) <= 110 for cell in row), row


def test_the_readme_names_no_issue():
    """A user cannot look up "issue 21": the README says what a target is instead."""
    text = README.read_text()
    assert not re.search(r"\bissues?\b|#\d+|GH-?\d+", text, re.IGNORECASE), re.search(r"\bissues?\b|#\d+|GH-?\d+", text, re.IGNORECASE)


def test_the_readme_types_in_no_target():
    """Every target the table shows comes from benchmarks/targets.toml: the file's bounds are there."""
    table = readme_table.block()
    for name in ("agent_vs_ratinabox", "default_vs_paper", "dry_run_step", "env_vs_pointmaze", "scaling_speed"):
        assert targets()[name].text(unit="x") in table, name


def _side_by_side(ratios: dict[str, float], exploit: float = 1.0) -> dict:
    return {
        "command": "python -m benchmarks.agent_throughput",
        "side_by_side": [
            {
                "n_place": 1000,
                "exploit_share": {"default": exploit, "paper": 1.0},
                "ratios": {
                    key: {"n": 3, "median": value, "quartiles": [round(value - 0.1, 2), round(value + 0.1, 2)]}
                    for key, value in ratios.items()
                },
            }
        ],
    }


def test_a_speed_is_a_ratio_timed_side_by_side(monkeypatch):
    """With side-by-side ratios in the record the rows show them against their targets; without, "not measured yet"."""
    committed = records.load
    measured = _side_by_side({"default_x_ratinabox": 43.2, "default_x_paper": 0.5, "dry_run_step_x_exploiting_step": 1.2})
    monkeypatch.setattr(
        records, "load", lambda name, results=None: measured if name == "agent_throughput.json" else committed(name, results)
    )
    rows = readme_table.agent_speed_rows()
    assert [row[1] for row in rows] == ["43.20x (43.10-43.30x)", "0.50x (0.40-0.60x)", "1.20x (1.10-1.30x)"]
    assert [row[2].split(": ")[1] for row in rows] == ["met", "**missed**", "met"]

    old = {"command": "python benchmarks/agent_throughput.py --model paper", "rows": []}  # written before side-by-side timing
    monkeypatch.setattr(records, "load", lambda name, results=None: old if name == "agent_throughput.json" else committed(name, results))
    assert {row[1] for row in readme_table.agent_speed_rows()} == {readme_table.NOT_MEASURED}

    idle = _side_by_side({"default_x_ratinabox": 43.2, "default_x_paper": 0.5, "dry_run_step_x_exploiting_step": 1.2}, exploit=0.1)
    monkeypatch.setattr(records, "load", lambda name, results=None: idle if name == "agent_throughput.json" else committed(name, results))
    assert all(row[1].startswith("not measured") for row in readme_table.agent_speed_rows())


def test_check_reports_a_stale_readme(tmp_path, monkeypatch, capsys):
    stale = tmp_path / "README.md"
    stale.write_text(f"# x\n\n{readme_table.BEGIN}\nan old table\n{readme_table.END}\n\nthe rest\n")
    monkeypatch.setattr(readme_table, "README", stale)
    assert readme_table.main(["--check"]) == 1
    assert readme_table.main([]) == 0
    assert readme_table.main(["--check"]) == 0
    assert stale.read_text().endswith(f"{readme_table.END}\n\nthe rest\n")
    stale.write_text("no markers")
    with pytest.raises(ValueError, match="no results table"):
        readme_table.main(["--check"])


def test_a_maze_whose_runs_mostly_miss_the_goal_misses_its_target(monkeypatch):
    """The maze suite records an infinite median (most later runs missed the goal) as null: a miss, not a gap."""
    committed = records.load
    suite = committed("maze_suite_default.json")
    rows = [{**row, "runs_2_4_median_miss_inf": None} if row["maze"] == "maze2" else row for row in suite["rows"]]
    monkeypatch.setattr(
        records,
        "load",
        lambda name, results=None: {**suite, "rows": rows} if name == "maze_suite_default.json" else committed(name, results),
    )
    built_in = readme_table.maze_rows()[0]
    assert "inf" in built_in[1].split(" / ") and built_in[2].endswith("**missed**")
