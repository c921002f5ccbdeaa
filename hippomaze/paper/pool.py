"""The process pool that runs the experiment tasks: results by task name, independent of the order
and of the number of workers."""

from __future__ import annotations

import multiprocessing
import os
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from typing import Any


@dataclass
class Task:
    name: str
    fn: Callable[..., Any]
    kwargs: dict[str, Any]
    cost: float  # rough seconds, to start the long ones first


def _timed(fn: Callable[..., Any], kwargs: dict[str, Any]) -> tuple[Any, float]:
    began = time.perf_counter()
    out = fn(**kwargs)
    return out, time.perf_counter() - began


def run_tasks(tasks: list[Task], workers: int, progress: bool) -> tuple[dict[str, Any], dict[str, float]]:
    """Run every task (in ``workers`` processes); results by task name, independent of the order."""
    from tqdm.auto import tqdm

    results: dict[str, Any] = {}
    seconds: dict[str, float] = {}
    order = sorted(tasks, key=lambda t: -t.cost)
    bar = tqdm(total=len(tasks), desc="paper experiments", unit="task", disable=not progress)
    if workers <= 1:
        for task in order:
            bar.set_postfix_str(task.name)
            results[task.name], seconds[task.name] = _timed(task.fn, task.kwargs)
            bar.update(1)
    else:
        # One BLAS thread per worker: the workers already fill the cores. Spawned workers read
        # these variables when they import numpy; the parent's own values are restored after.
        saved = {k: os.environ.get(k) for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}
        os.environ.update({k: "1" for k in saved})
        try:
            with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn")) as pool:
                futures = {pool.submit(_timed, task.fn, task.kwargs): task.name for task in order}
                for future in as_completed(futures):
                    name = futures[future]
                    results[name], seconds[name] = future.result()
                    bar.set_postfix_str(name)
                    bar.update(1)
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
    bar.close()
    return results, seconds
