"""The scaling benchmarks (``--scaling`` of ``benchmarks.agent_throughput`` and
``benchmarks.env_throughput``) and what they share in ``benchmarks.common``, at tiny sizes: the
tables' shape, the split of a step into parts, the slopes. Nothing here asserts a speed."""

from __future__ import annotations

import functools
import json
import math
import os
import time

import numpy as np
import pytest

from benchmarks import agent_throughput, agent_timing, env_throughput, records, targets
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
    monkeypatch.setattr(agent_timing, "rollout", functools.partial(rollout, max_steps=100))  # run 1 need not find the goal
    monkeypatch.setattr(agent_throughput, "target_sizes", lambda: (80, 40))  # not the targets' 10,000 cells
    args = agent_throughput.Args(scaling_cells=(40,), steps=20, scaling_repeats=1, dry_run_steps=20, peer_steps=0)
    table = agent_throughput.scaling_table(args, fresh_process=False)
    assert [r["n_place"] for r in table["rows"]] == [40, 80]
    for row in table["rows"]:
        for mode in ("exploiting", "exploring"):
            split = row[f"{mode}_split_us_per_step"]
            assert set(agent_timing.AGENT_TERMS) | {"other", "total"} <= set(split)
            assert "methods_not_found" not in split, split.get("methods_not_found")
            assert row[f"{mode}_steps_per_second"] > 0
        assert row["exploring_split_us_per_step"]["preplay"] == 0.0  # exploring never preplays
        assert row["replay_ms"] >= 0 and row["peak_rss_mb"] > 0
        assert {"replay_weights", "other", "total"} <= set(row["replay_split_ms"])
        assert "methods_not_found" not in row["replay_split_ms"]
        assert row["dry_run_steps"] == 20 and row["dry_run_agent_steps_per_second"] >= row["dry_run_steps_per_second"] > 0
    growth = table["growth"]
    assert growth["exploiting"]["dominant_at_largest"] in (*agent_timing.AGENT_TERMS, "other")
    assert "replay" not in growth and growth["replay_ms_slope"] is None  # run 1 was cut short: nothing replayed
    figures = records.scaling_figures(table)  # the targets' sizes (10,000 and 1,000) are not in this table
    assert not figures["measured"] and "why" in figures
    agent_throughput.plot_scaling(table, args, tmp_path / "agent.png")
    assert (tmp_path / "agent.png").stat().st_size > 0
    json.dumps(table)  # the record is plain JSON


def test_agent_targets_are_read_only_on_a_walk_that_exploited():
    at, against = agent_throughput.target_sizes()
    row = {
        "n_place": at,
        "exploiting_steps_per_second": 3000,
        "exploring_steps_per_second": 2500,
        "exploit_decisions": {"explore": 10, "exploit": 90, "bumps": 0, "replays": 0},
        "found_goal": True,
        "peak_rss_mb": 1200.0,
        "replay_ms": 50.0,
    }
    smaller = {**row, "n_place": against, "exploiting_steps_per_second": 9000, "exploring_steps_per_second": 10_000}
    figures = records.scaling_figures({"rows": [smaller, row]})
    assert figures == {
        "n_place": at,
        "against_n_place": against,
        "measured": True,
        "speed_ratio": round(2500 / 9000, 3),
        "peak_rss_mb": 1200.0,
        "replay_ms": 50.0,
    }
    assert not targets.target("scaling_memory_mb").met(figures["peak_rss_mb"])
    explored = {**row, "exploit_decisions": {"explore": 90, "exploit": 10, "bumps": 0, "replays": 0}}
    for bad in (explored, {**row, "found_goal": False}, {**row, "replay_from_cells": 0}):
        assert not records.scaling_figures({"rows": [smaller, bad]})["measured"]
    assert "no row" in records.scaling_figures({"rows": [row]})["why"]


def test_side_by_side_times_every_program_in_turn_repeat_by_repeat(monkeypatch):
    monkeypatch.setattr(agent_timing, "rollout", functools.partial(rollout, max_steps=50))  # run 1 need not find the goal
    args = agent_throughput.Args(steps=20, repeats=3, dry_run_steps=20, peer_steps=0)
    row = agent_throughput.side_by_side(40, args)
    assert len(row["repeats"]) == 3 and not row["ratinabox_timed"]
    assert [r["order"] for r in row["repeats"]] == [
        ["default", "paper", "dry_run"],
        ["paper", "dry_run", "default"],
        ["dry_run", "default", "paper"],
    ]
    for repeat, ratio in zip(row["repeats"], row["ratios"]["default_x_paper"]["per_repeat"], strict=True):
        assert repeat["default"] > 0 and repeat["paper"] > 0 and repeat["dry_run_steps"] == 20
        assert ratio == pytest.approx(repeat["default"] / repeat["paper"], rel=1e-3)
    for key in ("default_x_paper", "dry_run_step_x_exploiting_step"):
        summary = row["ratios"][key]
        assert summary["n"] == 3 and summary["median"] == pytest.approx(sorted(summary["per_repeat"])[1], abs=1e-3)
        assert summary["quartiles"][0] <= summary["median"] <= summary["quartiles"][1]
    assert "default_x_ratinabox" not in row["ratios"]
    json.dumps(row)


def test_side_by_side_times_ratinabox_beside_the_models(monkeypatch):
    pytest.importorskip("ratinabox", reason="the peers extra: pip install -e .[peers]")
    monkeypatch.setattr(agent_timing, "rollout", functools.partial(rollout, max_steps=50))
    args = agent_throughput.Args(steps=20, repeats=2, dry_run_steps=20, peer_steps=3)
    row = agent_throughput.side_by_side(40, args)
    assert row["ratinabox_timed"] and all(r["ratinabox"] > 0 for r in row["repeats"])
    assert row["ratios"]["default_x_ratinabox"]["per_repeat"] == pytest.approx(
        [r["default"] / r["ratinabox"] for r in row["repeats"]], rel=1e-3
    )


def test_the_exploring_walk_hides_the_remembered_place_so_the_default_model_searches():
    """The default model homes to where it found the goal whether or not its reward map is on:
    the exploring walk hides that place (and puts it back after), so it times a run 1's search."""
    env, agent, *_ = agent_timing.trained("default", 60, dry_run_steps=30, n_rays=720, seed=0)
    recorded = agent_timing.recorded_walk(env, 30, seed=0)
    agent.homing.remember(np.zeros(2))  # (whether or not run 1 found the goal)
    place = agent.homing.remembered().copy()
    for exploit in (False, True):
        with agent_timing.heading_for_the_goal(agent, exploit):
            agent_timing.walk(agent, recorded)
            decisions = dict(agent.episode_stats)
        assert (decisions["home"] > 0) == exploit, decisions
        assert np.array_equal(agent.homing.remembered(), place)


def test_the_exploiting_walk_keeps_heading_for_the_goal_past_homings_stall_check():
    """The recorded walk does not follow the agent's heading, so it seldom comes nearer the goal;
    the timed agent's homing does not give up for that (``homing.stall_steps`` off), and the walk
    stays goal-directed. (With the stall check on, 64 % of these steps were; with it off, 89 %.)"""
    env, agent, *_ = agent_timing.trained("default", 300, dry_run_steps=3000, n_rays=720, seed=0)
    recorded = agent_timing.recorded_walk(env, 3000, seed=0)
    with agent_timing.heading_for_the_goal(agent, exploit=True):
        agent_timing.walk(agent, recorded)
    assert records.exploit_share(agent.episode_stats) >= 0.8, agent.episode_stats
