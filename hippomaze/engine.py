"""One way to run many independent tasks: a local process pool, Ray, or this process.

:func:`map_tasks` calls ``fn(item)`` for every item and returns the results in the items' order. As each
task finishes, the driver hands its result to ``on_result(item, result)`` (in the order they
finish), so a caller can save it at once and skip it when run again: that makes a long run
resumable. Every ``poll_seconds`` while tasks are running, ``on_poll(pending_items)`` is called
(e.g. to refresh a progress bar).

Engines:

- ``"local"``: a :class:`concurrent.futures.ProcessPoolExecutor` of ``workers`` *spawned*
  processes (no state inherited from the driver beyond the environment variables, so ``fn`` and
  the items must be picklable, and ``fn`` importable by name). ``worker_env`` sets environment
  variables the workers start with (e.g. one BLAS thread each); the driver's own are restored after.
- ``"ray"``: ``ray.remote(num_cpus=1)(fn)``, on the cluster at ``address`` or, without one, on a
  local Ray started with ``workers`` CPUs (and shut down after). A cluster's workers may not share
  the driver's file system: see :func:`shares_filesystem`.
- ``"serial"``: one task after the other in this process, in the items' order.

The engine knows nothing of what the tasks are; it imports no other part of the project.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping
from typing import Any, TypeVar

T = TypeVar("T")
R = TypeVar("R")

ENGINES = ("local", "ray", "serial")


def check_engine(engine: str) -> None:
    """Raise ``ValueError`` unless ``engine`` is one of :data:`ENGINES`."""
    if engine not in ENGINES:
        raise ValueError(f"engine {engine!r} is unknown; engines: {', '.join(ENGINES)}")


def shares_filesystem(engine: str, address: str = "") -> bool:
    """Whether the tasks run where the driver's files are (not so on a Ray cluster at ``address``)."""
    return not (engine == "ray" and address)


def map_tasks(
    fn: Callable[[T], R],
    items: Iterable[T],
    *,
    engine: str = "local",
    workers: int = 2,
    address: str = "",
    on_result: Callable[[T, R], None] | None = None,
    on_poll: Callable[[list[T]], None] | None = None,
    poll_seconds: float = 2.0,
    worker_env: Mapping[str, str] | None = None,
) -> list[R]:
    """``[fn(item) for item in items]`` on the chosen engine; see the module docstring."""
    check_engine(engine)
    items = list(items)
    results: dict[int, R] = {}

    def finished(index: int, result: R) -> None:
        results[index] = result
        if on_result is not None:
            on_result(items[index], result)

    def poll(pending: Iterable[int]) -> None:
        if on_poll is not None:
            on_poll([items[i] for i in pending])

    if not items:
        return []
    if engine == "serial":
        for index, item in enumerate(items):
            finished(index, fn(item))
    elif engine == "ray":
        _map_ray(fn, items, workers, address, finished, poll, poll_seconds)
    else:
        _map_local(fn, items, workers, finished, poll, poll_seconds, worker_env or {})
    return [results[i] for i in range(len(items))]


def _map_local(
    fn: Callable[[Any], Any], items: list[Any], workers: int, finished: Any, poll: Any, poll_seconds: float, worker_env: Mapping[str, str]
) -> None:
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    saved = {k: os.environ.get(k) for k in worker_env}
    os.environ.update(worker_env)  # spawned workers read their environment when they start
    try:
        with ProcessPoolExecutor(max_workers=max(1, workers), mp_context=multiprocessing.get_context("spawn")) as pool:
            pending = {pool.submit(fn, item): index for index, item in enumerate(items)}
            while pending:
                done, _ = wait(pending, timeout=poll_seconds, return_when=FIRST_COMPLETED)
                for future in done:
                    finished(pending.pop(future), future.result())
                poll(list(pending.values()))
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _map_ray(fn: Callable[[Any], Any], items: list[Any], workers: int, address: str, finished: Any, poll: Any, poll_seconds: float) -> None:
    try:
        import ray
    except ImportError as err:
        raise ImportError(f"engine 'ray' needs Ray, which is not installed: pip install 'hippomaze[ray]' ({err})") from err
    started_here = False
    if not ray.is_initialized():
        if address:
            ray.init(address=address)
        else:
            ray.init(num_cpus=max(1, workers), include_dashboard=False)
        started_here = True
    try:
        remote = ray.remote(num_cpus=1)(fn)
        pending = {remote.remote(item): index for index, item in enumerate(items)}
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1, timeout=poll_seconds)
            for ref in done:
                finished(pending.pop(ref), ray.get(ref))
            poll(list(pending.values()))
    finally:
        if started_here:
            ray.shutdown()
