"""The statistics the paper's experiments report: medians that skip missing values, rank and
linear correlations with a bootstrap interval."""

from __future__ import annotations

from typing import Any

import numpy as np


def median_or_none(values: Any) -> float | None:
    """The median of the finite values among ``values`` (None entries skipped); None if there are none."""
    v = np.asarray([x for x in values if x is not None], float)
    v = v[np.isfinite(v)]
    return float(np.median(v)) if len(v) else None


def spearman(x: np.ndarray, y: np.ndarray) -> float | None:
    """Spearman's rank correlation (NaN-free inputs; None if either is constant or too short)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 5 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return None
    rx, ry = np.argsort(np.argsort(x)), np.argsort(np.argsort(y))
    return float(np.corrcoef(rx, ry)[0, 1])


def pearson_with_ci(x: np.ndarray, y: np.ndarray, seed: int, n_boot: int = 4000) -> dict[str, Any]:
    """Pearson r with a 95 % bootstrap interval over trials, and Spearman's rho.

    Keys: ``n``, ``r``, ``ci95``, ``spearman`` and ``leave_one_out`` (the range of r with one trial left out).
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
