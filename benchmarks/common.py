"""What the benchmark scripts share: their command line from a dataclass, what a record says
about the machine it ran on (``hippomaze.runinfo``), with paths relative to the repository; a
measurement in a fresh process, its resident memory, exclusive time per part of a step, and the
log-log slope of a cost against a size."""

from __future__ import annotations

import concurrent.futures
import math
import multiprocessing
import resource
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from hippomaze import runinfo
from hippomaze.runinfo import ArgsT, cpu_model, load_average, machine_info, parse_dataclass_args

__all__ = [
    "REPO",
    "ArgsT",
    "SplitTimer",
    "command_line",
    "cost_growth",
    "cpu_model",
    "in_fresh_process",
    "load_average",
    "log_log_slope",
    "machine_info",
    "output_path",
    "parse_dataclass_args",
    "peak_resident_megabytes",
    "resident_megabytes",
]

REPO = Path(__file__).resolve().parent.parent


def command_line() -> str:
    """The command that ran this script, with the script's path relative to the repository."""
    return runinfo.command_line(REPO)


def output_path(out: str) -> Path:
    """Where a script's ``--out`` goes (relative to the repository unless absolute), its folder made."""
    path = Path(out) if Path(out).is_absolute() else REPO / out
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def resident_megabytes() -> float:
    """This process's resident memory now (Linux), in MB (10^6 bytes)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 1e6


def peak_resident_megabytes() -> float:
    """This process's peak resident memory so far, in MB (``ru_maxrss`` is in KB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3


def in_fresh_process(target: Callable[..., Any], *args: Any) -> Any:
    """``target(*args)`` in a new spawned interpreter, its result returned (an exception re-raised):
    its peak memory and caches then belong to this one measurement. ``target`` must be a module-level
    function and its arguments and result picklable."""
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
        return pool.submit(target, *args).result()


class SplitTimer:
    """Exclusive wall time per named part ("term") of a computation, by wrapping methods of live
    objects: ``wrap(obj, "name", term)`` replaces ``obj.name`` on that instance only (the class is
    untouched) by a timed call. A wrapped call that runs inside another wrapped call is counted in
    its own term and taken out of the outer one, so the terms add up to no more than the total;
    the rest of a measured total is ``other`` (:meth:`split`). A method the object does not have
    is listed in :attr:`missing`, not an error (the measured code may have changed)."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}
        self.calls: dict[str, int] = {}
        self.missing: list[str] = []
        self._children: list[float] = []  # per open wrapped call: time spent in wrapped calls inside it
        self._wrapped: list[tuple[Any, str, Any]] = []

    def wrap(self, obj: Any, name: str, term: str) -> None:
        method = getattr(obj, name, None)
        if not callable(method):
            self.missing.append(f"{type(obj).__name__}.{name}")
            return
        self.seconds.setdefault(term, 0.0)
        self.calls.setdefault(term, 0)
        children = self._children

        def timed(*args: Any, **kwargs: Any) -> Any:
            children.append(0.0)
            began = time.perf_counter()
            try:
                return method(*args, **kwargs)
            finally:
                elapsed = time.perf_counter() - began
                self.seconds[term] += elapsed - children.pop()
                self.calls[term] += 1
                if children:
                    children[-1] += elapsed

        self._wrapped.append((obj, name, vars(obj).get(name, _ABSENT)))
        setattr(obj, name, timed)

    def unwrap(self) -> None:
        """Put every wrapped method back."""
        for obj, name, before in reversed(self._wrapped):
            if before is _ABSENT:
                delattr(obj, name)
            else:
                setattr(obj, name, before)
        self._wrapped.clear()

    def reset(self) -> None:
        """Zero the times and counts (the wrapping stays)."""
        for term in self.seconds:
            self.seconds[term], self.calls[term] = 0.0, 0

    def split(self, total: float) -> dict[str, float]:
        """Seconds per term, and ``other``: ``total`` (the measured whole) less every term."""
        return {**self.seconds, "other": total - sum(self.seconds.values())}


_ABSENT = object()


def log_log_slope(sizes: Sequence[float], costs: Sequence[float]) -> float | None:
    """Least-squares slope of log(cost) against log(size): 1 is linear growth, 0 constant cost.
    ``None`` with fewer than two usable (positive) points."""
    points = [(math.log(x), math.log(y)) for x, y in zip(sizes, costs, strict=True) if x > 0 and y > 0]
    if len({x for x, _ in points}) < 2:
        return None
    mx = sum(x for x, _ in points) / len(points)
    my = sum(y for _, y in points) / len(points)
    return sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x, _ in points)


def cost_growth(sizes: Sequence[float], seconds_per_step: Sequence[float], splits: Sequence[dict[str, float]]) -> dict[str, Any]:
    """How a cost per step grows with a size (smallest size first): its log-log slope over all
    sizes and over the larger half (1 = linear; a fixed overhead flattens the small end), a verdict
    on the larger half, each part's slope (``splits``: one ``{part: time per step}`` per size, as
    :meth:`SplitTimer.split` gives; other keys than numbers are ignored), and the part that takes
    most of a step at the smallest and at the largest size, with every part's share there."""
    sizes = list(sizes)
    larger = [i for i, x in enumerate(sizes) if x >= sizes[len(sizes) // 2]] if len(sizes) > 2 else list(range(len(sizes)))

    def slopes(costs: Sequence[float]) -> dict[str, float | None]:
        return {
            "all_sizes": _rounded(log_log_slope(sizes, costs)),
            "larger_half": _rounded(log_log_slope([sizes[i] for i in larger], [costs[i] for i in larger])),
        }

    parts = [_parts(split) for split in splits]
    slope = slopes(seconds_per_step)
    return {
        "sizes": sizes,
        "larger_half_from": sizes[larger[0]] if larger else None,
        "seconds_per_step_slope": slope,
        "verdict": growth_verdict(slope["larger_half"]),
        "part_slopes": {t: slopes([max(p.get(t, 0.0), 0.0) for p in parts]) for t in parts[0]} if parts else {},
        "dominant_at_smallest": max(parts[0], key=parts[0].get) if parts else None,
        "dominant_at_largest": max(parts[-1], key=parts[-1].get) if parts else None,
        "shares_at_smallest": _shares(parts[0]) if parts else {},
        "shares_at_largest": _shares(parts[-1]) if parts else {},
    }


def growth_verdict(slope: float | None) -> str:
    """``linear`` for a log-log slope within 0.85-1.15, else ``sublinear`` or ``superlinear``."""
    if slope is None:
        return "unknown (fewer than two sizes)"
    if slope < 0.85:
        return f"sublinear (slope {slope:.2f} < 0.85)"
    if slope <= 1.15:
        return f"linear (slope {slope:.2f} within 0.85-1.15)"
    return f"superlinear (slope {slope:.2f} > 1.15)"


def _parts(split: dict[str, Any]) -> dict[str, float]:
    return {t: float(v) for t, v in split.items() if t != "total" and isinstance(v, (int, float)) and not isinstance(v, bool)}


def _shares(parts: dict[str, float]) -> dict[str, float]:
    total = sum(max(v, 0.0) for v in parts.values()) or 1.0
    return {t: round(max(v, 0.0) / total, 3) for t, v in parts.items()}


def _rounded(x: float | None) -> float | None:
    return None if x is None else round(x, 3)
