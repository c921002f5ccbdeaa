"""From job records to results: one :class:`VariantResult` per agent variant, and the comparison of variants.

A *variant* is an agent label plus ``-dense`` for the dense reward. Its result holds, per maze,
the per-seed figures (steps to criterion, the goal switch, the steps counted), and its learning
curves: success rate and median indirectness against environment steps, the IQM over seeds with
95 % intervals (:mod:`hippomaze.stats`), per maze and over all mazes (mazes as strata).
The shipped references are variant results too (:mod:`hippomaze.bench.references`).

:func:`compare` puts variants side by side: IQM steps to direct (per maze, all mazes), after a
goal switch, the probability that the focus variant (the user's agent; the hippocampal agent in
the research benchmark) is direct in fewer steps, and the performance profiles.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hippomaze import stats
from hippomaze.bench.jobs import JobRecord
from hippomaze.bench.metrics import WINDOW, metrics_at, replicates, steps_to_criterion, switch_cost

#: Points of a learning curve (log-spaced from FIRST_STEP to the variant's last step).
CURVE_POINTS = 80
FIRST_STEP = 100
#: Points of a performance profile (log-spaced over the steps every variant covers).
PROFILE_POINTS = 60
#: The panel and key of every maze together.
ALL = "all"


# ------------------------------------------------------------------------------- one variant
@dataclass
class Band:
    """A curve: the IQM over seeds at each x and its 95 % interval (None: no point)."""

    iqm: list[float | None]
    low: list[float | None]
    high: list[float | None]


@dataclass
class Curve:
    """A variant's success-rate and median-indirectness curves over its step grid, in one maze (or all)."""

    steps: list[float]
    success: Band
    indirectness: Band


@dataclass
class MazeResult:
    """One variant in one maze, seed by seed (each list has one entry per seed)."""

    seeds: list[int]
    env_steps_total: list[int]
    dry_run_steps: list[list[int]]  # one entry per agent created (one-shot: per trial)
    runs: list[int]  # runs finished on the first goal
    steps_to_criterion: list[float | None]  # None: never direct within the budget
    switched: list[bool]  # had a goal-switch trial (only a seed direct on its first goal has one)
    switch_runs_to_direct: list[int | None]  # runs of the switch trial before direct again
    switch_steps: list[int | None]  # steps of the switch trial before direct again
    switch_runs: list[int | None]  # runs the switch trial had (None: no switch trial)
    seconds: list[float]


@dataclass
class VariantResult:
    """Everything measured of one agent variant (see the module docstring)."""

    variant: str
    agent: str  # what hippomaze.registry.agent_factory was given
    privileged: bool
    protocol: dict[str, Any]  # kind, budget, switch_budget, trials, runs, max_episode_steps, reward_type, window
    mazes: dict[str, MazeResult]
    curves: dict[str, Curve]  # by maze, and ALL when there are two mazes or more
    agent_config: dict[str, Any] | None = None

    @property
    def horizon(self) -> int:
        """The steps its measurement covers: a learner's budget, else its longest life."""
        return int(self.protocol.get("budget") or max((max(m.env_steps_total) for m in self.mazes.values()), default=0))

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> VariantResult:
        curves = {
            k: Curve(c["steps"], Band(**c["success"]), Band(**c["indirectness"])) for k, c in data["curves"].items()
        }  # fmt: skip
        mazes = {k: MazeResult(**m) for k, m in data["mazes"].items()}
        return cls(**{**data, "curves": curves, "mazes": mazes})


def variant_name(record: JobRecord) -> str:
    """A record's variant: its label (or agent), ``-dense`` added for the dense reward."""
    job = record.job
    return (job.get("label") or job["agent"]) + ("-dense" if job["reward_type"] == "dense" else "")


def analyse(records: list[JobRecord], window: int = WINDOW, maze_order: tuple[str, ...] = ()) -> dict[str, VariantResult]:
    """The job records as variant results, by variant name (mazes in ``maze_order`` first)."""
    groups: dict[str, dict[str, list[JobRecord]]] = {}
    for record in records:
        groups.setdefault(variant_name(record), {}).setdefault(record.job["maze"], []).append(record)
    results = {}
    for variant, by_maze in groups.items():
        mazes = [m for m in maze_order if m in by_maze] + sorted(set(by_maze) - set(maze_order))
        results[variant] = _variant(variant, {m: sorted(by_maze[m], key=lambda r: r.job["seed"]) for m in mazes}, window)
    return results


def _variant(variant: str, by_maze: dict[str, list[JobRecord]], window: int) -> VariantResult:
    first = next(iter(by_maze.values()))[0]
    job = first.job
    top = max(r.learn["env_steps_total"] for recs in by_maze.values() for r in recs)
    grid = np.unique(np.round(np.geomspace(FIRST_STEP, max(top, 2 * FIRST_STEP), CURVE_POINTS)))
    mazes: dict[str, MazeResult] = {}
    points: dict[str, dict[str, np.ndarray]] = {}  # maze -> metric -> (seeds, x)
    for maze, recs in by_maze.items():
        reps = [replicates(r.learn) for r in recs]
        at = np.array([[metrics_at(rp, x, window) for x in grid] for rp in reps]).reshape(len(recs), grid.size, 2)
        points[maze] = {"success": at[..., 0], "indirectness": at[..., 1]}
        switch = [switch_cost(r.switch, window) if r.switch is not None else (None, None) for r in recs]
        mazes[maze] = MazeResult(
            seeds=[r.job["seed"] for r in recs],
            env_steps_total=[r.learn["env_steps_total"] for r in recs],
            dry_run_steps=[r.learn["prepare_steps"] for r in recs],
            runs=[len(r.learn["episodes"]["steps"]) for r in recs],
            steps_to_criterion=[steps_to_criterion(rp, window) for rp in reps],
            switched=[r.switch is not None for r in recs],
            switch_runs_to_direct=[s[0] for s in switch],
            switch_steps=[s[1] for s in switch],
            switch_runs=[len(r.switch["episodes"]["steps"]) if r.switch is not None else None for r in recs],
            seconds=[round(r.seconds, 1) for r in recs],
        )

    def curve(keys: list[str]) -> Curve:  # keys: the mazes, as strata
        bands = {}
        for metric in ("success", "indirectness"):
            stacked = np.stack([points[k][metric] for k in keys], axis=1)  # (seeds, mazes, x)
            bands[metric] = Band(*stats.curve_band(stacked))
        return Curve(grid.tolist(), **bands)

    curves = {maze: curve([maze]) for maze in mazes}
    if len(mazes) >= 2 and len({len(m.seeds) for m in mazes.values()}) == 1:
        curves[ALL] = curve(list(mazes))
    protocol = {
        "kind": "learner" if job["budget"] else "one-shot", "budget": job["budget"] or None, "switch_budget": job["switch_budget"],
        "trials": job["days"], "runs": job["runs"], "max_episode_steps": job["max_episode_steps"] or None,
        "reward_type": job["reward_type"], "window": window,
    }  # fmt: skip
    return VariantResult(
        variant=variant, agent=job["agent"], privileged=first.privileged, protocol=protocol, mazes=mazes, curves=curves,
        agent_config=first.agent_config,
    )  # fmt: skip


# ------------------------------------------------------------------------------- side by side
@dataclass
class Reached:
    """How many seeds got there, of how many."""

    reached: int
    seeds: int


@dataclass
class VariantStats:
    """One variant beside the others (see :func:`compare`). Keys of the dicts: mazes and :data:`ALL`."""

    steps_to_direct: dict[str, stats.Interval]
    direct: dict[str, Reached]
    after_switch: dict[str, stats.Interval]  # steps before direct again, over the seeds that had a switch trial (ALL: pooled)
    direct_again: dict[str, Reached]
    focus_faster: stats.Interval | None  # P(the focus variant is direct in fewer steps than this one), over common mazes
    profile: dict[str, list[float | None]] = field(default_factory=dict)  # share direct within each of Comparison.taus

    def to_dict(self) -> dict[str, Any]:
        return {
            "steps_to_direct": {k: v.to_list() for k, v in self.steps_to_direct.items()},
            "direct": {k: [v.reached, v.seeds] for k, v in self.direct.items()},
            "after_switch": {k: v.to_list() for k, v in self.after_switch.items()},
            "direct_again": {k: [v.reached, v.seeds] for k, v in self.direct_again.items()},
            "focus_faster": None if self.focus_faster is None else self.focus_faster.to_list(),
            "profile": self.profile,
        }


@dataclass
class Comparison:
    """Every variant's statistics beside the focus variant's, in the mazes the focus ran in."""

    focus: str
    mazes: list[str]
    taus: list[float]
    variants: dict[str, VariantStats]

    def to_dict(self) -> dict[str, Any]:
        return {
            "focus": self.focus,
            "mazes": self.mazes,
            "columns": "[point, low, high]: IQM over seeds (x mazes for 'all') and its 95% interval; null: never within the budget",
            "focus_faster": f"P({self.focus} direct in fewer steps than the variant), rliable's probability of improvement",
            "profile_steps": self.taus,
            "method": stats.method(),
            "variants": {k: v.to_dict() for k, v in self.variants.items()},
        }


def _iqm(columns: Sequence[Sequence[float | None]]) -> stats.Interval:
    """The IQM and interval of steps to criterion (:func:`stats.steps_matrix`'s columns); undefined without a stratified matrix."""
    matrix = stats.steps_matrix(columns)
    return stats.Interval(None, None, None) if matrix is None else stats.iqm_interval(matrix)


def compare(results: dict[str, VariantResult], focus: str, mazes: list[str] | None = None) -> Comparison:
    """The statistics of every variant in ``results`` beside ``focus``'s (see the module docstring).

    ``mazes``: the mazes compared (default: the focus's); a variant that lacks one of them is
    compared in the mazes it shares with them.
    """
    mazes = list(mazes or results[focus].mazes)
    top = max(r.horizon for r in results.values())
    taus = np.unique(np.round(np.geomspace(FIRST_STEP, max(top, 2 * FIRST_STEP), PROFILE_POINTS))).tolist()
    out: dict[str, VariantStats] = {}
    for name, result in results.items():
        shared = [m for m in mazes if m in result.mazes]
        steps, direct, after, again = {}, {}, {}, {}
        for m in shared:
            r = result.mazes[m]
            steps[m] = _iqm([r.steps_to_criterion])
            direct[m] = Reached(sum(v is not None for v in r.steps_to_criterion), len(r.seeds))
            switched = [s for s, sw in zip(r.switch_steps, r.switched) if sw]
            again[m] = Reached(sum(v is not None for v in switched), len(switched))
            after[m] = _iqm([switched])
        matrix = stats.steps_matrix([result.mazes[m].steps_to_criterion for m in shared])
        if len(shared) >= 2 and matrix is not None:
            steps[ALL] = stats.iqm_interval(matrix)
            direct[ALL] = Reached(sum(d.reached for d in direct.values()), sum(d.seeds for d in direct.values()))
        if len(shared) >= 2:  # the seeds with a switch trial differ by maze: pooled, not stratified
            pooled = [s for m in shared for s, sw in zip(result.mazes[m].switch_steps, result.mazes[m].switched) if sw]
            again[ALL] = Reached(sum(v is not None for v in pooled), len(pooled))
            after[ALL] = _iqm([pooled])
        faster = None
        common = [m for m in shared if m in results[focus].mazes]
        mine = stats.steps_matrix([results[focus].mazes[m].steps_to_criterion for m in common])
        if name != focus and common and matrix is not None and mine is not None:
            theirs = stats.steps_matrix([result.mazes[m].steps_to_criterion for m in common])
            faster = stats.probability_of_improvement(mine, theirs) if theirs is not None else None
        profile: dict[str, list[float | None]] = {}
        if matrix is not None:
            share, low, high = stats.performance_profile(matrix, np.asarray(taus))
            covered = [t <= result.horizon for t in taus]  # past its budget a variant's share is unknown
            profile = {
                key: [v if c else None for v, c in zip(values, covered)] for key, values in (("share", share), ("low", low), ("high", high))
            }
        out[name] = VariantStats(steps, direct, after, again, faster, profile)
    return Comparison(focus=focus, mazes=mazes, taus=taus, variants=out)
