"""The scaling benchmarks (``--scaling`` of ``benchmarks.agent_throughput`` and
``benchmarks.env_throughput``) and what they share in ``benchmarks.common``, at tiny sizes: the
tables' shape, the split of a step into parts, the slopes. Nothing here asserts a speed."""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import os
import time

import numpy as np
import pytest

from benchmarks import agent_throughput, env_throughput
from benchmarks.common import SplitTimer, cost_growth, growth_verdict, in_fresh_process, log_log_slope
from hippo_env.dmtp import rollout


class _Work:
    def outer(self, inner_calls: int) -> int:
        for _ in range(inner_calls):
            self.inner()
        time.sleep(0.002)
        return inner_calls

    def inner(self) -> None:
        time.sleep(0.002)


def test_split_timer_counts_nested_calls_once_and_puts_methods_back():
    work = _Work()
    timer = SplitTimer()
    timer.wrap(work, "outer", "outer")
    timer.wrap(work, "inner", "inner")
    timer.wrap(work, "no_such_method", "inner")
    began = time.perf_counter()
    assert work.outer(3) == 3  # results pass through
    total = time.perf_counter() - began
    split = timer.split(total)
    assert timer.calls == {"outer": 1, "inner": 3}
    assert split["inner"] > split["outer"] > 0.0  # three inner sleeps, one outer sleep of its own
    assert split["other"] >= 0.0
    assert math.isclose(sum(split.values()), total)
    assert timer.missing == ["_Work.no_such_method"]
    timer.unwrap()
    assert "outer" not in vars(work) and "inner" not in vars(work)
    timer.reset()
    assert timer.seconds == {"outer": 0.0, "inner": 0.0}


def test_log_log_slope_and_verdict():
    n = [250, 500, 1000, 2000]
    assert log_log_slope(n, [3.0 * x for x in n]) == pytest.approx(1.0)
    assert log_log_slope(n, [x * x for x in n]) == pytest.approx(2.0)
    assert log_log_slope([1000], [1.0]) is None
    assert growth_verdict(1.0).startswith("linear")
    assert growth_verdict(0.3).startswith("sublinear")
    assert growth_verdict(2.0).startswith("superlinear")


def test_cost_growth_names_the_dominant_part_at_each_end():
    sizes = [100, 200, 400, 800]
    splits = [{"fixed": 50.0, "linear": 0.1 * n, "total": 50.0 + 0.1 * n, "methods_not_found": ["x"]} for n in sizes]
    g = cost_growth(sizes, [s["total"] * 1e-6 for s in splits], splits)
    assert g["dominant_at_smallest"] == "fixed" and g["dominant_at_largest"] == "linear"
    assert set(g["part_slopes"]) == {"fixed", "linear"}
    assert g["part_slopes"]["linear"]["all_sizes"] == pytest.approx(1.0)
    assert g["part_slopes"]["fixed"]["all_sizes"] == pytest.approx(0.0)
    assert g["larger_half_from"] == 400
    assert sum(g["shares_at_largest"].values()) == pytest.approx(1.0, abs=1e-2)


def test_in_fresh_process_runs_elsewhere():
    assert in_fresh_process(os.getpid) != os.getpid()


def test_scaled_maze_scales_every_wall():
    small = env_throughput.scaled_maze("maze2", 10.0)
    assert small.name == "maze2"
    large = env_throughput.scaled_maze("maze2", 40.0)
    assert large.size == (40.0, 40.0)
    assert np.allclose(large.segments, 4.0 * small.segments)


def test_env_scaling_table_tiny(tmp_path):
    args = env_throughput.Args(
        scaling_mazes=("open",), scaling_rays=(16, 32), scaling_sizes=(10.0, 20.0), steps=40, warmup=5, repeats=1, peer=""
    )
    table = env_throughput.scaling_table(args, fresh_process=False)
    rows = table["rows"]
    assert [(r["axis"], r["size_m"], r["n_rays"]) for r in rows] == [
        ("rays", 10.0, 16),
        ("rays", 10.0, 32),
        ("size", 10.0, 720),
        ("size", 20.0, 720),
    ]
    for row in rows:
        split = row["split_us_per_step"]
        assert {"ray_cast", "physics", "reset", "step_overhead", "total"} <= set(split)
        assert "methods_not_found" not in split
        assert split["ray_cast"] > 0 and split["physics"] > 0
        assert row["steps_per_second"] > 0 and row["peak_rss_mb"] > 0
    assert set(table["growth"]) == {"open_rays", "open_size"}
    assert table["growth"]["open_rays"]["sizes"] == [16, 32]
    env_throughput.plot_scaling(table, tmp_path / "env.png")
    assert (tmp_path / "env.png").stat().st_size > 0


def test_agent_scaling_table_tiny(tmp_path, monkeypatch):
    monkeypatch.setattr(agent_throughput, "rollout", functools.partial(rollout, max_steps=100))  # run 1 need not find the goal
    args = agent_throughput.Args(scaling_cells=(40,), target_cells=80, steps=20, repeats=1, dry_run_steps=20, peer_steps=0)
    table = agent_throughput.scaling_table(args, fresh_process=False)
    assert [r["n_place"] for r in table["rows"]] == [40, 80]
    for row in table["rows"]:
        for mode in ("exploiting", "exploring"):
            split = row[f"{mode}_split_us_per_step"]
            assert set(agent_throughput.AGENT_TERMS) | {"other", "total"} <= set(split)
            assert "methods_not_found" not in split, split.get("methods_not_found")
            assert row[f"{mode}_steps_per_second"] > 0
        assert row["exploring_split_us_per_step"]["preplay"] == 0.0  # exploring never preplays
        assert row["replay_ms"] >= 0 and row["peak_rss_mb"] > 0
        assert {"replay_weights", "other", "total"} <= set(row["replay_split_ms"])
        assert "methods_not_found" not in row["replay_split_ms"]
    growth = table["growth"]
    assert growth["exploiting"]["dominant_at_largest"] in (*agent_throughput.AGENT_TERMS, "other")
    assert "replay" not in growth and growth["replay_ms_slope"] is None  # run 1 was cut short: nothing replayed
    assert table["targets"]["n_place"] == 80  # measured or, as here (run 1 cut short), not, saying why
    assert table["targets"]["measured"] or "why" in table["targets"]
    agent_throughput.plot_scaling(table, args, tmp_path / "agent.png")
    assert (tmp_path / "agent.png").stat().st_size > 0
    json.dumps(table)  # the record is plain JSON


def test_agent_targets_are_judged_only_on_a_walk_that_exploited():
    args = agent_throughput.Args(target_cells=100)
    row = {
        "n_place": 100,
        "exploiting_steps_per_second": 3000,
        "exploring_steps_per_second": 2500,
        "exploit_decisions": {"explore": 10, "exploit": 90, "bumps": 0, "replays": 0},
        "found_goal": True,
        "peak_rss_mb": 1200.0,
        "replay_ms": 50.0,
    }
    judged = agent_throughput.targets([row], args)
    assert judged["measured"]
    assert judged["steps_per_second"] == {"target": args.target_scaling, "slowest_walk": 2500, "met": 2500 >= args.target_scaling}
    assert not judged["peak_rss_mb"]["met"] and judged["replay_ms"]["met"]
    explored = {**row, "exploit_decisions": {"explore": 90, "exploit": 10, "bumps": 0, "replays": 0}}
    assert not agent_throughput.targets([explored], args)["measured"]
    assert "10%" in agent_throughput.targets([explored], args)["why"]
    assert not agent_throughput.targets([{**row, "found_goal": False}], args)["measured"]
    assert not agent_throughput.targets([{**row, "replay_from_cells": 0}], args)["measured"]
    assert agent_throughput.targets([row], agent_throughput.Args(target_cells=7)) == {"n_place": 7, "measured": False}


def test_agent_targets_at_1000_cells_judge_the_exploiting_walk_and_the_ratio_to_ratinabox():
    args = agent_throughput.Args()
    row = {"n_place": 1000, "exploiting_steps_per_second": 10_500, "exploring_steps_per_second": 13_000, "exploiting_x_ratinabox": 24.9}
    judged = agent_throughput.targets_1000_cells([row], args)
    assert judged["steps_per_second"] == {"target": 10_000.0, "measured": 10_500, "met": True}
    assert judged["x_ratinabox"] == {"target": 25.0, "measured": 24.9, "met": False}
    assert agent_throughput.targets_1000_cells([{**row, "exploiting_x_ratinabox": None}], args)["x_ratinabox"]["met"] is None
    assert agent_throughput.targets_1000_cells([{**row, "n_place": 250}], args) is None
    assert "steps_per_second_at_reference" not in judged  # no alternating timing, no estimate
    alternated = {**row, "alternating": {"estimate_at_reference": 7_900}}
    assert agent_throughput.targets_1000_cells([alternated], agent_throughput.Args(target=8_000))["steps_per_second_at_reference"] == {
        "target": 8_000,
        "estimated": 7_900,
        "met": False,
    }


def test_alternating_timing_pairs_the_two_models_repeat_by_repeat(monkeypatch):
    monkeypatch.setattr(agent_throughput, "rollout", functools.partial(rollout, max_steps=50))  # run 1 need not find the goal
    args = agent_throughput.Args(steps=20, repeats=3, dry_run_steps=20, peer_steps=0, model="default", against="paper")
    alt = agent_throughput.alternating(40, args)
    assert alt["against"] == "paper" and len(alt["steps_per_second_pairs"]) == 3 and len(alt["ratios"]) == 3
    for (ours, theirs), ratio in zip(alt["steps_per_second_pairs"], alt["ratios"], strict=True):
        assert ours > 0 and theirs > 0 and ratio == pytest.approx(ours / theirs, rel=0.01)
    assert alt["median_ratio"] == sorted(alt["ratios"])[1]
    assert alt["estimate_at_reference"] is None  # (an estimate only for the 1000-cell row the reference was measured at)
    with pytest.raises(ValueError, match="allowed: default, paper"):
        agent_throughput.alternating(40, dataclasses.replace(args, against="fast"))


def test_the_exploring_walk_hides_the_remembered_place_so_the_default_model_searches():
    """The default model homes to where it found the goal whether or not its reward map is on:
    the exploring walk hides that place (and puts it back after), so it times a run 1's search."""
    args = agent_throughput.Args(steps=30, repeats=1, dry_run_steps=30, peer_steps=0)
    env, agent, *_ = agent_throughput._trained("default", 60, args)
    recorded = agent_throughput._recorded_walk(env, args)
    agent.homing.remember(np.zeros(2))  # (whether or not run 1 found the goal)
    place = agent.homing.remembered().copy()
    for exploit in (False, True):
        *_, decisions = agent_throughput._timed(agent, recorded, exploit, 1)
        assert (decisions["home"] > 0) == exploit, decisions
        assert np.array_equal(agent.homing.remembered(), place)
