"""The summary of the job records: curves, per-seed figures and the headline table (and the sweep's rows).

The summary travels as typed records (:class:`Summary` and what it holds); ``to_dict`` gives what
``sample_efficiency.json`` (and ``sample_efficiency_sweep.json``) keeps of each, in its key order.
Some keys keep the words the committed files were written with (``episodes`` for runs,
``prepare_steps`` for the dry run's steps); the fields say which.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from benchmarks.sample_efficiency.metrics import iqm_ci, metrics_at, replicates, steps_to_criterion, switch_cost

if TYPE_CHECKING:
    from benchmarks.sample_efficiency.cli import Args
    from benchmarks.sample_efficiency.jobs import JobRecord


# ------------------------------------------------------------------------------- curves
@dataclass
class Band:
    """A curve over the step grid: the IQM over seeds at each x and its 95 % interval (None: no point)."""

    iqm: list[float | None]
    low: list[float | None]
    high: list[float | None]


@dataclass
class CurvePair:
    """One agent variant's success-rate and median-indirectness curves in one maze (or all mazes)."""

    success: Band
    indirectness: Band


@dataclass
class Curves:
    """The step grid and the curves on it, by ``"<variant>/<maze>"`` (and ``"<variant>/all"``: mazes as strata)."""

    steps: list[float]
    series: dict[str, CurvePair]


# ------------------------------------------------------------------------------- per seed
@dataclass
class SeedFigures:
    """One variant in one maze, seed by seed (each list has one entry per seed)."""

    variant: str
    maze: str
    seeds: list[int]
    budget: int | None
    privileged: bool
    env_steps_total: list[int]
    dry_run_steps: list[list[int]]  # JSON key "prepare_steps": one entry per agent created (hippo: per trial)
    runs: list[int]  # JSON key "episodes": runs finished on the first goal
    steps_to_criterion: list[float | None]
    switch_runs_to_direct: list[int | None]  # JSON key "switch_episodes": runs of the switch trial before direct again
    switch_steps: list[int | None]
    switch_budget: int
    switched: list[bool]
    switch_runs: list[int | None]  # runs the switch trial had (None: no switch trial)
    direct_on_first_goal_at: list[float | None]
    seconds: list[float]

    def to_dict(self) -> dict[str, Any]:
        return {
            "variant": self.variant, "maze": self.maze, "seeds": self.seeds, "budget": self.budget, "privileged": self.privileged,
            "env_steps_total": self.env_steps_total, "prepare_steps": self.dry_run_steps, "episodes": self.runs,
            "steps_to_criterion": self.steps_to_criterion,
            "switch_episodes": self.switch_runs_to_direct, "switch_steps": self.switch_steps,
            "switch_budget": self.switch_budget, "switched": self.switched, "switch_runs": self.switch_runs,
            "direct_on_first_goal_at": self.direct_on_first_goal_at, "seconds": self.seconds,
        }  # fmt: skip


# ------------------------------------------------------------------------------- headline
@dataclass
class StepsToDirect:
    """Median steps to criterion over seeds; ``median_steps`` None (shown "> budget") if fewer than half got there."""

    median_steps: float | None
    reached: int
    seeds: int
    budget: int | None


@dataclass
class SwitchCost:
    """After a goal switch: median runs and steps before direct again, over the seeds that had a switch trial."""

    median_runs: float | None  # JSON key "median_episodes"
    median_steps: float | None
    reached: int
    seeds: int
    budget: int

    def to_dict(self) -> dict[str, Any]:
        return {"median_episodes": self.median_runs, "median_steps": self.median_steps, "reached": self.reached,
                "seeds": self.seeds, "budget": self.budget}  # fmt: skip


@dataclass
class HeadlineCell:
    """One agent in one maze: steps to direct, as a multiple of the hippocampal agent's, and the goal switch."""

    steps: StepsToDirect
    ratio_to_hippo: str | float | None = None  # "> N" when the agent never got there within its budget
    switch: SwitchCost | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {**dataclasses.asdict(self.steps), "ratio_to_hippo": self.ratio_to_hippo}
        if self.switch is not None:
            out["switch"] = self.switch.to_dict()
        return out


@dataclass
class HeadlineRow:
    """One agent variant's row of the headline table: a cell per maze it ran in."""

    agent: str
    privileged: bool
    mazes: dict[str, HeadlineCell]

    def to_dict(self) -> dict[str, Any]:
        return {"agent": self.agent, "privileged": self.privileged, **{m: c.to_dict() for m, c in self.mazes.items()}}


@dataclass
class Summary:
    """Everything :func:`analyse` makes of the job records: what the report, the figures and the JSON read."""

    curves: Curves
    per_seed: dict[str, SeedFigures]  # by "<variant>/<maze>"
    headline: list[HeadlineRow]
    variants: list[str]
    mazes: list[str]

    def to_dict(self) -> dict[str, Any]:
        return {
            "curves": dataclasses.asdict(self.curves),
            "per_seed": {k: p.to_dict() for k, p in self.per_seed.items()},
            "headline": [row.to_dict() for row in self.headline],
            "variants": self.variants,
            "mazes": self.mazes,
        }


# ------------------------------------------------------------------------------- the sweep
@dataclass
class SweepRow:
    """One point of the hyperparameter sweep, seed by seed."""

    name: str
    agent: str
    overrides: dict[str, Any]
    seeds: list[int]
    steps_to_criterion: list[float | None]
    final_success_rate: list[float]
    final_median_indirectness: list[float | None]
    runs: list[int]  # JSON key "episodes"
    seconds: list[float]

    def to_dict(self) -> dict[str, Any]:
        out = dataclasses.asdict(self)
        del out["runs"], out["seconds"]
        return {**out, "episodes": self.runs, "seconds": self.seconds}


@dataclass
class SweepSummary:
    """The sweep: one row per point, all in the open arena with the sparse reward."""

    budget: int
    rows: list[SweepRow]
    maze: str = "open"
    reward_type: str = "sparse"

    def to_dict(self) -> dict[str, Any]:
        return {"budget": self.budget, "maze": self.maze, "reward_type": self.reward_type, "rows": [r.to_dict() for r in self.rows]}


# ------------------------------------------------------------------------------- making them
def variant(record: JobRecord) -> str:
    job = record.job
    label = job.get("label") or job["agent"]
    return label + ("-dense" if job["reward_type"] == "dense" else "")


def analyse(records: dict[str, JobRecord], args: Args) -> Summary:
    """Curves, headline table and goal-switch figures from the job records."""
    groups: dict[tuple[str, str], list[JobRecord]] = {}
    for record in records.values():
        groups.setdefault((variant(record), record.job["maze"]), []).append(record)
    top = max((r.learn["env_steps_total"] for r in records.values()), default=1000)
    grid = np.unique(np.round(np.geomspace(100, max(top, 200), 120)))
    variants = sorted({v for v, _ in groups}, key=_variant_order)
    mazes = [m for m in args.mazes if any(k[1] == m for k in groups)] + sorted({m for _, m in groups} - set(args.mazes))

    per_seed: dict[str, SeedFigures] = {}
    points: dict[str, dict[str, np.ndarray]] = {}  # (seeds, grid) arrays of success and indirectness
    for (v, maze), recs in sorted(groups.items()):
        recs = sorted(recs, key=lambda r: r.job["seed"])
        reps = [replicates(r.learn) for r in recs]
        succ = np.array([[metrics_at(rp, x, args.window)[0] for x in grid] for rp in reps])
        ind = np.array([[metrics_at(rp, x, args.window)[1] for x in grid] for rp in reps])
        switch = [switch_cost(r.switch, args.window) if r.switch is not None else (None, None) for r in recs]
        per_seed[f"{v}/{maze}"] = SeedFigures(
            variant=v, maze=maze, seeds=[r.job["seed"] for r in recs], budget=recs[0].job["budget"] or None,
            privileged=recs[0].privileged,
            env_steps_total=[r.learn["env_steps_total"] for r in recs],
            dry_run_steps=[r.learn["prepare_steps"] for r in recs],
            runs=[len(r.learn["episodes"]["steps"]) for r in recs],
            steps_to_criterion=[steps_to_criterion(rp, args.window) for rp in reps],
            switch_runs_to_direct=[s[0] for s in switch], switch_steps=[s[1] for s in switch],
            switch_budget=recs[0].job["switch_budget"], switched=[r.switch is not None for r in recs],
            switch_runs=[len(r.switch["episodes"]["steps"]) if r.switch is not None else None for r in recs],
            direct_on_first_goal_at=[r.learn.get("direct_at") for r in recs],
            seconds=[r.seconds for r in recs],
        )  # fmt: skip
        points[f"{v}/{maze}"] = {"success": succ, "indirectness": ind}

    def curve_pair(keys: list[str]) -> CurvePair:  # keys: the strata
        bands = {}
        for metric in ("success", "indirectness"):
            stats = [iqm_ci([points[k][metric][:, j] for k in keys], seed=j) for j in range(grid.size)]
            bands[metric] = Band([_r(s[0]) for s in stats], [_r(s[1]) for s in stats], [_r(s[2]) for s in stats])
        return CurvePair(**bands)

    curves = Curves(steps=grid.tolist(), series={key: curve_pair([key]) for key in points})
    for v in variants:  # all mazes together: strata = mazes
        keys = [f"{v}/{m}" for m in mazes if f"{v}/{m}" in points]
        if len(keys) >= 2:
            curves.series[f"{v}/all"] = curve_pair(keys)

    headline = []
    for v in variants:
        row = HeadlineRow(agent=v, privileged=any(p.privileged for p in per_seed.values() if p.variant == v), mazes={})
        for maze in mazes:
            p = per_seed.get(f"{v}/{maze}")
            if p is None:
                continue
            steps = summarize_steps(p.steps_to_criterion, p.budget)
            hippo = per_seed.get(f"hippo/{maze}")
            row.mazes[maze] = HeadlineCell(
                steps=steps,
                ratio_to_hippo=ratio(steps, summarize_steps(hippo.steps_to_criterion, hippo.budget)) if hippo and v != "hippo" else None,
                switch=summarize_switch(
                    [e for e, sw in zip(p.switch_runs_to_direct, p.switched) if sw],
                    [st for st, sw in zip(p.switch_steps, p.switched) if sw],
                    p.switch_budget,
                ),
            )
        headline.append(row)
    return Summary(curves=curves, per_seed=per_seed, headline=headline, variants=variants, mazes=mazes)


def _variant_order(v: str) -> tuple[int, str]:
    order = ["hippo", "dqn", "ppo", "dqn-dense", "ppo-dense", "random", "dynaq"]
    return (order.index(v) if v in order else len(order), v)


def _r(value: float) -> float | None:
    return None if not math.isfinite(value) else round(float(value), 4)


def summarize_steps(values: list[float | None], budget: int | None) -> StepsToDirect:
    """Median steps to criterion over seeds; ``None`` (shown "> budget") if fewer than half got there."""
    n = len(values)
    reached = sorted(v for v in values if v is not None)
    median = None
    if len(reached) * 2 > n or (len(reached) * 2 == n and n > 0):
        padded = reached + [math.inf] * (n - len(reached))
        m = float(np.median(padded))
        median = m if math.isfinite(m) else None
    return StepsToDirect(median_steps=median, reached=len(reached), seeds=n, budget=budget)


def ratio(steps: StepsToDirect, hippo: StepsToDirect) -> str | float | None:
    """``steps`` as a multiple of the hippocampal agent's; "> N" for an agent never direct within its budget."""
    if hippo.median_steps is None or hippo.median_steps <= 0:
        return None
    if steps.median_steps is None:
        return f"> {steps.budget / hippo.median_steps:.0f}" if steps.budget else None
    return round(steps.median_steps / hippo.median_steps, 2)


def summarize_switch(runs: list[int | None], steps: list[int | None], budget: int) -> SwitchCost:
    """Medians over the seeds that had a switch trial; None when fewer than half of them became direct again."""
    n = len(runs)
    done_r = [e for e in runs if e is not None]
    done_s = [s for s in steps if s is not None]
    enough = len(done_r) * 2 >= n > 0
    pad = [math.inf] * (n - len(done_r))
    return SwitchCost(
        median_runs=float(np.median(done_r + pad)) if enough and math.isfinite(np.median(done_r + pad)) else None,
        median_steps=float(np.median(done_s + pad)) if enough and math.isfinite(np.median(done_s + pad)) else None,
        reached=len(done_r), seeds=n, budget=budget,
    )  # fmt: skip


def sweep_summary(records: dict[str, JobRecord], args: Args) -> SweepSummary:
    """One row per sweep point (its seeds in the order the records come)."""
    rows = []
    for label in sorted({r.job["label"] for r in records.values()}):
        recs = [r for r in records.values() if r.job["label"] == label]
        stc, final_s, final_i = [], [], []
        for r in recs:
            (rep,) = replicates(r.learn)
            stc.append(steps_to_criterion([rep], args.window))
            final_s.append(float(rep.success[-50:].mean()) if rep.end.size else 0.0)
            final_i.append(float(np.median(rep.indirectness[-50:])) if rep.end.size else math.inf)
        rows.append(SweepRow(
            name=label.removeprefix("sweep-"), agent=recs[0].job["agent"], overrides=recs[0].job["overrides"],
            seeds=[r.job["seed"] for r in recs], steps_to_criterion=stc,
            final_success_rate=final_s, final_median_indirectness=[_r(v) for v in final_i],
            runs=[len(r.learn["episodes"]["steps"]) for r in recs], seconds=[round(r.seconds, 1) for r in recs],
        ))  # fmt: skip
    return SweepSummary(budget=args.sweep_budget, rows=rows)
