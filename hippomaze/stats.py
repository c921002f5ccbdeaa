"""The project's statistics, in one place: everything that summarises repeated measurements.

Plain summaries (NumPy only):

- :func:`median_or_none`: the median of the values that exist; :func:`median_counting_misses`:
  the median where a miss (``None``, or ``inf``) counts as worse than every value;
- :func:`median_and_quartiles`: the median and the spread (first and third quartiles) of repeats,
  e.g. of speed ratios timed side by side;
- :func:`spearman`, :func:`pearson_with_ci`: rank and linear correlation, the latter with a
  bootstrap interval over its pairs.

The statistics over seeds, by rliable (Agarwal et al. 2021, "Deep RL at the edge of the
statistical precipice"; the ``bench`` extra):

- **IQM** (interquartile mean: the 25 % trimmed mean over every seed of every maze) with a 95 %
  **stratified bootstrap** interval: seeds are resampled within each maze, as
  ``rliable.library.get_interval_estimates`` does (percentile method), here drawn from a
  generator of the estimate's own (:func:`stratified_bootstrap`);
- **probability of improvement** P(X faster than Y) (``rliable.metrics.probability_of_improvement``:
  the Mann-Whitney statistic per maze, averaged over mazes), with its interval from independent stratified resamples;
- **performance profiles**: the share of (seed, maze) pairs direct within x steps, for every x
  (rliable's score distribution), with intervals.

Steps to criterion are "lower is better", and a seed may never get there within its budget.
Such a seed counts as slower than every seed that did: it enters as :data:`NEVER`, and an
estimate that :data:`NEVER` reaches (above :data:`NEVER_ABOVE`) is reported as ``None``, shown
"> budget". For P(improvement) and the profiles, steps enter negated (higher is better).

rliable's own bootstrap draws from NumPy's global generator, whatever ``random_state`` it is
given; the resamples here are drawn the same way from a generator seeded per estimate, so the
numbers are rliable's and the same on every call, and no global state is touched. The point
estimates are rliable's.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

# ---------------------------------------------------------------------- plain summaries


def median_or_none(values: Iterable[float | None]) -> float | None:
    """The median of the finite values among ``values`` (None entries skipped); None if there are none."""
    v = np.asarray([x for x in values if x is not None], float)
    v = v[np.isfinite(v)]
    return float(np.median(v)) if len(v) else None


def median_counting_misses(values: Iterable[float | None]) -> float | None:
    """The median where a miss (``None`` or ``inf``: never got there) counts as worse than every
    value; None if the median itself is a miss, or there are no values."""
    v = np.asarray([math.inf if x is None else x for x in values], float)
    if not len(v):
        return None
    median = float(np.median(v))
    return median if math.isfinite(median) else None


def median_and_quartiles(values: Sequence[float], digits: int = 3) -> dict[str, Any]:
    """The median of repeated measurements and their spread: ``{"n", "median", "quartiles": [first, third]}``
    (NumPy's linear-interpolation percentiles), rounded to ``digits``; median and quartiles None without values."""
    v = np.asarray(values, float)
    if not len(v):
        return {"n": 0, "median": None, "quartiles": None}
    q1, median, q3 = (round(float(q), digits) for q in np.percentile(v, [25, 50, 75]))
    return {"n": len(v), "median": median, "quartiles": [q1, q3]}


def spearman(x: np.ndarray, y: np.ndarray) -> float | None:
    """Spearman's rank correlation (NaN-free inputs; None if either is constant or too short)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 5 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return None
    rx, ry = np.argsort(np.argsort(x)), np.argsort(np.argsort(y))
    return float(np.corrcoef(rx, ry)[0, 1])


def pearson_with_ci(x: np.ndarray, y: np.ndarray, seed: int, n_boot: int = 4000) -> dict[str, Any]:
    """Pearson r with a 95 % bootstrap interval over the pairs, and Spearman's rho; pairs with a
    non-finite value are left out.

    Keys: ``n``, ``r``, ``ci95``, ``spearman`` and ``leave_one_out`` (the range of r with one pair left out).
    """
    x, y = np.asarray(x, float), np.asarray(y, float)
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    if len(x) < 3 or np.std(x) == 0 or np.std(y) == 0:
        return {"n": len(x), "r": None, "ci95": None, "spearman": None, "leave_one_out": None}
    rng = np.random.default_rng(seed)
    boots = []
    for _ in range(n_boot):
        idx = rng.integers(0, len(x), len(x))
        if np.std(x[idx]) > 0 and np.std(y[idx]) > 0:
            boots.append(np.corrcoef(x[idx], y[idx])[0, 1])
    ci = [float(np.quantile(boots, 0.025)), float(np.quantile(boots, 0.975))] if boots else None
    loo = [np.corrcoef(np.delete(x, k), np.delete(y, k))[0, 1] for k in range(len(x)) if len(x) > 3]
    loo = [v for v in loo if np.isfinite(v)]
    return {
        "n": len(x),
        "r": float(np.corrcoef(x, y)[0, 1]),
        "ci95": ci,
        "spearman": spearman(x, y),
        "leave_one_out": [float(min(loo)), float(max(loo))] if loo else None,
    }


# ---------------------------------------------------------------------- over seeds, by rliable

#: Bootstrap resamples per interval.
REPS = 2000
#: Coverage of every interval.
CONFIDENCE = 0.95
#: Steps to criterion of a seed never direct within its budget.
NEVER = 1e12
#: An estimate above this stands for "never within the budget" (NEVER / NEVER_ABOVE exceeds any seed count).
NEVER_ABOVE = 1e9
#: The share of values the IQM trims at each end (rliable's ``aggregate_iqm``).
TRIM = 0.25


def _rliable() -> tuple[Any, Any]:
    """rliable's ``library`` and ``metrics`` modules, or an ImportError saying how to install them."""
    try:
        from rliable import library, metrics
    except ImportError as err:
        raise ImportError(f"the bench's statistics need rliable (the 'bench' extra): pip install 'hippomaze[bench]' ({err})") from err
    return library, metrics


def method() -> dict[str, Any]:
    """How the intervals were made, for the JSON."""
    import importlib.metadata

    try:
        version = importlib.metadata.version("rliable")
    except importlib.metadata.PackageNotFoundError:
        version = None
    return {
        "library": "rliable",
        "rliable": version,
        "point": f"IQM ({TRIM:.0%} trimmed mean) over seeds x mazes",
        "interval": f"{CONFIDENCE:.0%} stratified bootstrap (seeds resampled within each maze), percentile method",
        "reps": REPS,
        "never": "a seed never direct within its budget counts as slower than any that was; an estimate it decides is null",
    }


def stratified_bootstrap(samples: Sequence[np.ndarray], statistic: Callable[..., np.ndarray], seed: int, reps: int = REPS) -> np.ndarray:
    """The ``(1 - CONFIDENCE) / 2`` and ``(1 + CONFIDENCE) / 2`` percentiles of ``statistic`` over
    ``reps`` stratified resamples: each of ``samples`` (``(seeds, mazes, ...)``, their seed counts
    may differ) has its seeds resampled with replacement within each maze, independently of the
    others. Returns a ``(2, ...)`` array: the lower and the upper bounds of each of the statistic's
    values.

    The resamples are those of rliable's ``StratifiedBootstrap`` (one sample) and
    ``StratifiedIndependentBootstrap`` (several), drawn in the same order from the generator
    ``numpy.random.RandomState(seed)`` that this function owns, where rliable draws them from NumPy's
    global one: the intervals equal rliable's with the global generator seeded with ``seed``."""
    rng = np.random.RandomState(seed)
    grids = [np.ogrid[tuple(slice(n) for n in (0, *x.shape[1:]))][1:] for x in samples]
    values = []
    for _ in range(reps):
        resampled = [x[(rng.choice(x.shape[0], x.shape, replace=True), *grid)] for x, grid in zip(samples, grids)]
        values.append(np.asarray(statistic(*resampled), dtype=float))
    tail = 100 * (1 - CONFIDENCE) / 2
    return np.percentile(np.array(values), [tail, 100 - tail], axis=0)


@dataclass
class Interval:
    """A point estimate and its interval (``None``: not defined, or "never within the budget" for steps)."""

    point: float | None
    low: float | None
    high: float | None

    def to_list(self) -> list[float | None]:
        return [self.point, self.low, self.high]


def _shown(value: float, steps: bool) -> float | None:
    if not math.isfinite(value) or (steps and value > NEVER_ABOVE):
        return None
    return round(float(value), 4)


def steps_matrix(columns: Sequence[Sequence[float | None]]) -> np.ndarray | None:
    """Steps to criterion as rliable's ``(seeds, mazes)`` matrix, never -> :data:`NEVER`; None if the
    mazes have different numbers of seeds (no stratified matrix) or there is no seed."""
    if not columns or len({len(c) for c in columns}) != 1 or not columns[0]:
        return None
    return np.array([[NEVER if v is None else float(v) for v in c] for c in columns], float).T


def iqm_interval(scores: np.ndarray, seed: int = 0, steps: bool = True) -> Interval:
    """The IQM of ``scores`` (``(seeds, mazes)``) and its stratified-bootstrap interval (none with fewer than 3 values)."""
    _, metrics = _rliable()
    point = float(metrics.aggregate_iqm(scores))
    if scores.size < 3:
        return Interval(_shown(point, steps), None, None)
    low, high = stratified_bootstrap([scores], metrics.aggregate_iqm, seed)
    return Interval(_shown(point, steps), _shown(low, steps), _shown(high, steps))


def iqm_at_each_x(scores: np.ndarray) -> np.ndarray:
    """rliable's ``aggregate_iqm`` of ``scores[..., j]`` for every j at once (``scores``: ``(seeds, mazes, x)``)."""
    from scipy.stats import trim_mean

    return trim_mean(scores.reshape(-1, scores.shape[-1]), TRIM, axis=0)


def curve_band(points: np.ndarray, seed: int = 0) -> tuple[list[float | None], list[float | None], list[float | None]]:
    """A learning curve's IQM over seeds at each x, and its interval.

    ``points``: ``(seeds, mazes, x)``, NaN where a seed has no point. A point and its interval are
    given only where every seed of every maze has one (the bootstrap resamples a fixed set of
    seeds); elsewhere ``None``. No interval with fewer than 3 seeds x mazes.
    """
    n = points.shape[-1]
    iqm: list[float | None] = [None] * n
    low: list[float | None] = [None] * n
    high: list[float | None] = [None] * n
    keep = np.flatnonzero(np.all(np.isfinite(points), axis=(0, 1)))
    if keep.size == 0:
        return iqm, low, high
    scores = points[..., keep]
    centre = iqm_at_each_x(scores)
    if scores.shape[0] * scores.shape[1] >= 3:
        bounds = stratified_bootstrap([scores], iqm_at_each_x, seed)
    else:
        bounds = np.full((2, keep.size), np.nan)
    for k, j in enumerate(keep):
        iqm[j], low[j], high[j] = _shown(centre[k], False), _shown(bounds[0, k], False), _shown(bounds[1, k], False)
    return iqm, low, high


def probability_of_improvement(faster: np.ndarray, slower: np.ndarray, seed: int = 0) -> Interval:
    """P(an agent with steps ``faster`` gets there in fewer steps than one with ``slower``), and its interval.

    Both ``(seeds, mazes)`` with the same mazes in the same order (their seed counts may differ).
    Ties (both never, say) count one half.
    """
    _, metrics = _rliable()
    x, y = -faster, -slower  # rliable: higher is better
    point = float(metrics.probability_of_improvement(x, y))
    if x.shape[0] < 2 or y.shape[0] < 2:
        return Interval(_shown(point, False), None, None)
    low, high = stratified_bootstrap([x, y], metrics.probability_of_improvement, seed)
    return Interval(_shown(point, False), _shown(low, False), _shown(high, False))


def performance_profile(scores: np.ndarray, taus: np.ndarray, seed: int = 0) -> tuple[list[float], list[float], list[float]]:
    """The share of (seed, maze) pairs direct within each of ``taus`` steps, and its interval.

    ``scores``: steps to criterion, ``(seeds, mazes)``, never = :data:`NEVER`.
    """
    taus = np.asarray(taus, float)

    def share_within(steps: np.ndarray) -> np.ndarray:  # rliable's score distribution of -steps at -taus
        return np.mean(-steps.reshape(-1, 1) > -taus, axis=0)

    profile = share_within(scores)
    low, high = stratified_bootstrap([scores], share_within, seed)
    return [round(float(v), 4) for v in profile], [round(float(v), 4) for v in low], [round(float(v), 4) for v in high]
