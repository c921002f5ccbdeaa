"""The measures of a job record: replicates, the curves' points, steps to criterion, goal-switch cost.

A replicate (one-shot: a trial; learner: its one trial) is *direct* from x on when the ``window``
runs from its run in progress at x on have >= 90 % successes and median indirectness <= 1.0,
the one in progress being a direct success itself; its *steps to criterion* are the first run
start from which it is, and a seed's are the median over its replicates. The statistics over
seeds (IQM, intervals) are :mod:`hippomaze.stats`'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hippomaze.stats import median_counting_misses


@dataclass
class Replicate:
    """One agent life: its runs' start and end steps (from the agent's creation), outcomes."""

    start: np.ndarray
    end: np.ndarray
    success: np.ndarray
    indirectness: np.ndarray


def replicates(phase: dict[str, Any]) -> list[Replicate]:
    """The replicates of a phase record: one per trial, each trial's agent being fresh (hippo) or the only one."""
    runs = phase["episodes"]  # the record's key for its runs
    trials = np.asarray(runs["trial"], int)
    steps = np.asarray(runs["steps"], float)
    success = np.asarray(runs["success"], bool)
    ind = np.array([np.inf if v is None else v for v in runs["indirectness"]], float)
    dry_run = phase["prepare_steps"]  # the record's key for the dry runs' steps
    out = []
    for t in range(len(dry_run)):  # one entry per agent created: one per trial
        mask = trials == t
        end = dry_run[t] + np.cumsum(steps[mask])
        out.append(Replicate(end - steps[mask], end, success[mask], ind[mask]))
    return out


WINDOW = 10  # runs: the window of the curves and of steps to criterion (the shipped references use it)
MIN_POOL = 5  # fewer pooled runs than this: no measurement (NaN)
SWITCH_WINDOW = 10  # runs: the window of "direct on the first goal" inside a job


def recent_at(reps: list[Replicate], x: float, window: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Each replicate's ``window`` latest runs at step x: the one in progress (or next) and those before it.

    A learning curve that looks no further than the run under way. Every replicate is measured
    alike, by runs: a learner's one trial and each hippocampal trial give the same statistic, and
    a wandering run of thousands of steps counts once. A replicate whose runs are all done keeps
    its last window. Returns successes, indirectness, and how many replicates are still running at x.
    """
    heads = [(r, int(np.searchsorted(r.end, x, side="right"))) for r in reps]  # the run in progress at x
    running = sum(i < r.end.size for r, i in heads)
    heads = [(r, min(i, r.end.size - 1)) for r, i in heads if r.end.size]
    if not heads:
        return np.zeros(0, bool), np.zeros(0), running
    ok = np.concatenate([r.success[max(i + 1 - window, 0) : i + 1] for r, i in heads])
    ind = np.concatenate([r.indirectness[max(i + 1 - window, 0) : i + 1] for r, i in heads])
    return ok, ind, running


def metrics_at(reps: list[Replicate], x: float, window: int) -> tuple[float, float]:
    """(success rate, median indirectness) of the latest runs at x, the curves' point.

    NaN when the pool holds fewer than MIN_POOL runs, or fewer than half of the replicates are still
    running: the trials left late are the slow ones (wandering runs), and the curve would be theirs.
    """
    ok, ind, running = recent_at(reps, x, window)
    if ok.size < min(MIN_POOL, window) or 2 * running < len(reps):
        return math.nan, math.nan
    return float(ok.mean()), float(np.median(ind))


def direct_at(rep: Replicate, x: float, window: int) -> bool:
    """One replicate is direct from x on: its run in progress at x is a direct success, and so are the
    ``window`` runs from it on (>= 90 % successes, median indirectness <= 1).

    Looking at the run in progress keeps the window that looks ahead from hiding it (a
    hippocampal trial's exploring first run is not hidden by the direct runs after it).
    """
    head = int(np.searchsorted(rep.end, x, side="right"))
    ok, ind = rep.success[head : head + window], rep.indirectness[head : head + window]
    if ok.size < min(MIN_POOL, window):
        return False
    return direct(float(ok.mean()), float(np.median(ind))) and direct(float(ok[0]), float(ind[0]))


def direct(success: float, indirectness: float) -> bool:
    return success >= 0.9 and indirectness <= 1.0


def replicate_steps_to_criterion(rep: Replicate, window: int) -> float | None:
    """The first run start (steps since the agent's creation) at which the replicate is direct; None if never."""
    for x in rep.start:
        if direct_at(rep, x, window):
            return float(x)
    return None


def steps_to_criterion(reps: list[Replicate], window: int) -> float | None:
    """A seed's steps to criterion: the median over its replicates (hippo: its trials), None if that is never."""
    return median_counting_misses(replicate_steps_to_criterion(r, window) for r in reps)


def switch_cost(phase: dict[str, Any], window: int) -> tuple[int | None, int | None]:
    """(runs, steps) of the switch trial before it is direct again; (None, None) if it never is."""
    (rep,) = replicates(phase)
    for i in range(rep.end.size):
        if direct_at(rep, rep.start[i], window):
            return i, int(rep.start[i])
    return None, None
