"""benchmarks.world_diff: two records of the changing world paired layout by layout."""

from __future__ import annotations

import json

import pytest

from benchmarks.world_diff import compare, main, report, sign_test


def _run(phase: int, run: int, success: bool, steps: int = 50) -> dict:
    return {
        "phase": phase, "run": run, "success": success, "steps": steps, "path_length": 0.15 * steps,
        "indirectness": 0.2 if success else 3.0, "shortest_path_length": 5.0, "shortest_before_change": 10.0,
        "anchored": steps, "placed": steps, "off_map": 0,
    }  # fmt: skip


def _row(seed: int, firsts: dict[str, bool], later_steps: int = 50) -> dict:
    """A mazes-task schedule: the learn phase, then one phase per name in ``firsts`` (its first
    run's success as given, two later runs that reach the goal)."""
    runs = [_run(0, r, True) for r in range(2)]
    for phase, success in enumerate(firsts.values(), start=1):
        runs += [_run(phase, 0, success, 50 if success else 300), _run(phase, 1, True, later_steps), _run(phase, 2, True)]
    return {"agent": "hippo", "seed": seed, "task": "mazes", "maze": "maze2", "phases": ["learn", *firsts], "runs": runs}


def test_the_sign_test_is_exact_and_two_sided():
    assert sign_test(0, 0) == 1.0
    assert sign_test(1, 0) == 1.0  # (one pair either way: anything)
    assert sign_test(5, 0) == pytest.approx(2 / 32)
    assert sign_test(0, 5) == sign_test(5, 0)
    assert sign_test(3, 3) == 1.0
    assert sign_test(10, 1) == pytest.approx(2 * 12 / 2**11)


def test_layouts_are_paired_and_the_discordant_first_runs_named():
    base = [_row(1, {"blocks": True, "barrier": False, "door": True}), _row(2, {"blocks": True, "barrier": True, "door": True})]
    new = [_row(1, {"blocks": True, "barrier": True, "door": True}), _row(2, {"blocks": False, "barrier": True, "door": True}, 60)]
    e = compare(base, new)["hippo"]["mazes"]
    assert e["first_run_reached_in_base_only"] == [[2, "mazes", "maze2", "blocks"]]
    assert e["first_run_reached_in_new_only"] == [[1, "mazes", "maze2", "barrier"]]
    assert e["first_runs_sign_test_p"] == 1.0
    assert e["identical_schedules"] == 0  # (both rows changed)
    assert e["base"]["layouts"] == e["new"]["layouts"] == 6
    assert e["base"]["first_run_success"] == pytest.approx(5 / 6)
    assert "door" in e["base"]
    text = report(compare(base, new))
    assert "base only: seed 2 maze2, blocks" in text and "new only: seed 1 maze2, barrier" in text


def test_the_same_record_twice_differs_nowhere():
    rows = [_row(1, {"blocks": True, "barrier": False})]
    e = compare(rows, rows)["hippo"]["mazes"]
    assert e["identical_schedules"] == e["schedules"] == 1
    assert e["first_run_reached_in_base_only"] == e["first_run_reached_in_new_only"] == []
    assert e["base"] == e["new"]


def test_the_command_writes_its_comparison_and_refuses_records_that_are_not_ones(tmp_path, capsys):
    a, b, out = tmp_path / "a.json", tmp_path / "b.json", tmp_path / "diff.json"
    a.write_text(json.dumps({"rows": [_row(1, {"barrier": False})]}))
    b.write_text(json.dumps({"rows": [_row(1, {"barrier": True})]}))
    main(["--base", str(a), "--new", str(b), "--out", str(out)])
    assert "first runs reaching the goal in one record only: base 0, new 1" in capsys.readouterr().out
    written = json.loads(out.read_text())
    assert written["comparison"]["hippo"]["mazes"]["first_run_reached_in_new_only"] == [[1, "mazes", "maze2", "barrier"]]
    assert written["made_by"] == {"base": None, "new": None}  # (these records say no command)
    (tmp_path / "bad.json").write_text("{}")
    with pytest.raises(SystemExit, match="not a record"):
        main(["--base", str(tmp_path / "bad.json"), "--new", str(b)])
    with pytest.raises(SystemExit, match="needs --base and --new"):
        main(["--base", str(a)])
