"""The experiment tasks and how they run (on :mod:`hippomaze.engine`): results by task name,
independent of the order and of the number of workers."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from hippomaze import engine


@dataclass
class Task:
    name: str
    fn: Callable[..., Any]
    kwargs: dict[str, Any]
    cost: float  # rough seconds, to start the long ones first


def _timed(task: Task) -> tuple[Any, float]:
    began = time.perf_counter()
    out = task.fn(**task.kwargs)
    return out, time.perf_counter() - began


# One BLAS thread per worker: the workers already fill the cores.
ONE_BLAS_THREAD = {k: "1" for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}


def run_tasks(tasks: list[Task], workers: int, progress: bool) -> tuple[dict[str, Any], dict[str, float]]:
    """Run every task (in ``workers`` processes, on :func:`hippomaze.engine.map_tasks`); results by task
    name, independent of the order."""
    from tqdm.auto import tqdm

    bar = tqdm(total=len(tasks), desc="paper experiments", unit="task", disable=not progress)

    def finished(task: Task, _: Any) -> None:
        bar.set_postfix_str(task.name)
        bar.update(1)

    order = sorted(tasks, key=lambda t: -t.cost)  # the long ones first
    outs = engine.map_tasks(
        _timed, order, engine="serial" if workers <= 1 else "local", workers=workers, on_result=finished, worker_env=ONE_BLAS_THREAD
    )
    bar.close()
    return {t.name: out for t, (out, _) in zip(order, outs)}, {t.name: seconds for t, (_, seconds) in zip(order, outs)}
