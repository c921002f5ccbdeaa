"""The summary of the job records: curves, per-seed figures and the headline table (and the sweep's rows)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from benchmarks.sample_efficiency.metrics import iqm_ci, metrics_at, replicates, steps_to_criterion, switch_cost

if TYPE_CHECKING:
    from benchmarks.sample_efficiency.cli import Args
    from benchmarks.sample_efficiency.jobs import JobRecord


def variant(record: JobRecord) -> str:
    job = record.job
    label = job.get("label") or job["agent"]
    return label + ("-dense" if job["reward_type"] == "dense" else "")


def analyse(records: dict[str, JobRecord], args: Args) -> dict[str, Any]:
    """Curves, headline table and goal-switch figures from the job records."""
    groups: dict[tuple[str, str], list[JobRecord]] = {}
    for record in records.values():
        groups.setdefault((variant(record), record.job["maze"]), []).append(record)
    top = max((r.learn["env_steps_total"] for r in records.values()), default=1000)
    grid = np.unique(np.round(np.geomspace(100, max(top, 200), 120)))
    variants = sorted({v for v, _ in groups}, key=_variant_order)
    mazes = [m for m in args.mazes if any(k[1] == m for k in groups)] + sorted({m for _, m in groups} - set(args.mazes))

    per_seed: dict[str, dict[str, Any]] = {}
    curves: dict[str, dict[str, Any]] = {}
    for (v, maze), recs in sorted(groups.items()):
        recs = sorted(recs, key=lambda r: r.job["seed"])
        reps = [replicates(r.learn) for r in recs]
        succ = np.array([[metrics_at(rp, x, args.window)[0] for x in grid] for rp in reps])
        ind = np.array([[metrics_at(rp, x, args.window)[1] for x in grid] for rp in reps])
        stc = [steps_to_criterion(rp, args.window) for rp in reps]
        switch = [switch_cost(r.switch, args.window) if r.switch is not None else (None, None) for r in recs]
        switched = [r.switch is not None for r in recs]
        budget = recs[0].job["budget"] or None
        per_seed[f"{v}/{maze}"] = {
            "variant": v, "maze": maze, "seeds": [r.job["seed"] for r in recs], "budget": budget,
            "privileged": recs[0].privileged,
            "env_steps_total": [r.learn["env_steps_total"] for r in recs],
            "prepare_steps": [r.learn["prepare_steps"] for r in recs],
            "episodes": [len(r.learn["episodes"]["steps"]) for r in recs],
            "steps_to_criterion": stc,
            "switch_episodes": [s[0] for s in switch], "switch_steps": [s[1] for s in switch],
            "switch_budget": recs[0].job["switch_budget"], "switched": switched,
            "switch_runs": [len(r.switch["episodes"]["steps"]) if r.switch is not None else None for r in recs],
            "direct_on_first_goal_at": [r.learn.get("direct_at") for r in recs],
            "seconds": [r.seconds for r in recs],
        }  # fmt: skip
        curves[f"{v}/{maze}"] = {"success": succ, "indirectness": ind}

    out_curves: dict[str, Any] = {"steps": grid.tolist(), "series": {}}
    for key, c in curves.items():
        series = {}
        for metric in ("success", "indirectness"):
            stats = [iqm_ci([c[metric][:, j]], seed=j) for j in range(grid.size)]
            series[metric] = {"iqm": [_r(s[0]) for s in stats], "low": [_r(s[1]) for s in stats], "high": [_r(s[2]) for s in stats]}
        out_curves["series"][key] = series
    for v in variants:  # all mazes together: strata = mazes
        keys = [f"{v}/{m}" for m in mazes if f"{v}/{m}" in curves]
        if len(keys) < 2:
            continue
        series = {}
        for metric in ("success", "indirectness"):
            stats = [iqm_ci([curves[k][metric][:, j] for k in keys], seed=j) for j in range(grid.size)]
            series[metric] = {"iqm": [_r(s[0]) for s in stats], "low": [_r(s[1]) for s in stats], "high": [_r(s[2]) for s in stats]}
        out_curves["series"][f"{v}/all"] = series

    headline = []
    for v in variants:
        row: dict[str, Any] = {"agent": v, "privileged": any(per_seed[k]["privileged"] for k in per_seed if per_seed[k]["variant"] == v)}
        for maze in mazes:
            key = f"{v}/{maze}"
            if key not in per_seed:
                continue
            p = per_seed[key]
            row[maze] = summarize_steps(p["steps_to_criterion"], p["budget"])
            hippo = per_seed.get(f"hippo/{maze}")
            row[maze]["ratio_to_hippo"] = (
                ratio(row[maze], summarize_steps(hippo["steps_to_criterion"], hippo["budget"])) if hippo and v != "hippo" else None
            )
            row[maze]["switch"] = summarize_switch(
                [e for e, sw in zip(p["switch_episodes"], p["switched"]) if sw],
                [st for st, sw in zip(p["switch_steps"], p["switched"]) if sw],
                p["switch_budget"],
            )
        headline.append(row)
    return {"curves": out_curves, "per_seed": per_seed, "headline": headline, "variants": variants, "mazes": mazes}


def _variant_order(v: str) -> tuple[int, str]:
    order = ["hippo", "dqn", "ppo", "dqn-dense", "ppo-dense", "random", "dynaq"]
    return (order.index(v) if v in order else len(order), v)


def _r(value: float) -> float | None:
    return None if not math.isfinite(value) else round(float(value), 4)


def summarize_steps(values: list[float | None], budget: int | None) -> dict[str, Any]:
    """Median steps to criterion over seeds; ``None`` (shown "> budget") if fewer than half got there."""
    n = len(values)
    reached = sorted(v for v in values if v is not None)
    median = None
    if len(reached) * 2 > n or (len(reached) * 2 == n and n > 0):
        padded = reached + [math.inf] * (n - len(reached))
        m = float(np.median(padded))
        median = m if math.isfinite(m) else None
    return {"median_steps": median, "reached": len(reached), "seeds": n, "budget": budget}


def ratio(row: dict[str, Any], hippo: dict[str, Any]) -> str | float | None:
    if hippo["median_steps"] is None or hippo["median_steps"] <= 0:
        return None
    if row["median_steps"] is None:
        budget = row["budget"]
        return f"> {budget / hippo['median_steps']:.0f}" if budget else None
    return round(row["median_steps"] / hippo["median_steps"], 2)


def summarize_switch(episodes: list[int | None], steps: list[int | None], budget: int) -> dict[str, Any]:
    n = len(episodes)
    done_e = [e for e in episodes if e is not None]
    done_s = [s for s in steps if s is not None]
    enough = len(done_e) * 2 >= n > 0
    pad = [math.inf] * (n - len(done_e))
    return {
        "median_episodes": float(np.median(done_e + pad)) if enough and math.isfinite(np.median(done_e + pad)) else None,
        "median_steps": float(np.median(done_s + pad)) if enough and math.isfinite(np.median(done_s + pad)) else None,
        "reached": len(done_e), "seeds": n, "budget": budget,
    }  # fmt: skip


def sweep_summary(records: dict[str, JobRecord], args: Args) -> dict[str, Any]:
    rows = []
    for label in sorted({r.job["label"] for r in records.values()}):
        recs = [r for r in records.values() if r.job["label"] == label]
        stc, final_s, final_i = [], [], []
        for r in recs:
            (rep,) = replicates(r.learn)
            stc.append(steps_to_criterion([rep], args.window))
            final_s.append(float(rep.success[-50:].mean()) if rep.end.size else 0.0)
            final_i.append(float(np.median(rep.indirectness[-50:])) if rep.end.size else math.inf)
        rows.append({
            "name": label.removeprefix("sweep-"), "agent": recs[0].job["agent"], "overrides": recs[0].job["overrides"],
            "seeds": [r.job["seed"] for r in recs], "steps_to_criterion": stc,
            "final_success_rate": final_s, "final_median_indirectness": [_r(v) for v in final_i],
            "episodes": [len(r.learn["episodes"]["steps"]) for r in recs], "seconds": [round(r.seconds, 1) for r in recs],
        })  # fmt: skip
    return {"budget": args.sweep_budget, "maze": "open", "reward_type": "sparse", "rows": rows}
