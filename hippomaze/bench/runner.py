"""Running the jobs not yet on disk, on :mod:`hippomaze.engine`, with progress bars; finished jobs are skipped (resumable)."""

from __future__ import annotations

from pathlib import Path

from hippomaze import engine as engines
from hippomaze.bench.jobs import Job, JobRecord, expected_steps, job_path, load_record, reusable, run_job_task, save_record


def _read_progress(path: Path) -> int:
    try:
        return int(path.read_text() or 0)
    except (OSError, ValueError):
        return 0


def run_jobs(
    jobs: list[Job],
    folder: Path,
    *,
    engine: str = "local",
    workers: int = 2,
    address: str = "",
    progress: bool = True,
    command: str | None = None,
) -> tuple[dict[str, JobRecord], list[str]]:
    """Run the jobs whose record is not yet in ``folder`` (:func:`~hippomaze.bench.jobs.reusable`),
    saving each record as it finishes.

    Args:
        jobs: what to run.
        folder: where the job records are kept (``<folder>/<job>.json.gz``) and looked up.
        engine: ``local`` (a process pool), ``serial`` (this process) or ``ray`` (:mod:`hippomaze.engine`).
        workers: parallel jobs (local pool size; CPUs for a local Ray).
        address: a Ray cluster's address (empty: a local Ray).
        progress: show progress bars over jobs and steps.
        command: the command line running the jobs, kept in each new record's ``made``.

    Returns:
        Every job's record by job name, and the names of the jobs run now (the others were on disk).
    """
    records: dict[str, JobRecord] = {}
    todo: list[Job] = []
    for job in jobs:
        record = load_record(job_path(folder, job))
        if reusable(record, job):
            records[job.name] = record
        else:
            todo.append(job)
    bar = steps_bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(jobs), initial=len(jobs) - len(todo), desc="jobs ", unit="job", position=0)
        steps_bar = tqdm(total=sum(expected_steps(j) for j in todo), desc="steps", unit="step", unit_scale=True, position=1, smoothing=0.05)
    done_steps = 0

    def progress_path(job: Job) -> Path:
        return job_path(folder, job).with_suffix(".progress")

    def poll(running: list[Job]) -> None:
        if steps_bar is not None:
            steps_bar.n = min(done_steps + sum(_read_progress(progress_path(j)) for j in running), steps_bar.total)
            steps_bar.refresh()

    def finished(job: Job, record: JobRecord) -> None:
        nonlocal done_steps
        if command is not None and record.made is not None:
            record.made = {"command": command, **record.made}
        save_record(job_path(folder, job), record)
        progress_path(job).unlink(missing_ok=True)
        records[job.name] = record
        done_steps += expected_steps(job)
        if bar is not None:
            bar.set_postfix_str(f"{job.name} {record.seconds:.0f}s")
            bar.update(1)

    try:
        if todo:
            folder.mkdir(parents=True, exist_ok=True)
            # a job on a Ray cluster cannot write its progress where the driver reads it
            local_files = engines.shares_filesystem(engine, address)
            tasks = [(job, str(progress_path(job)) if local_files else None) for job in todo]
            engines.map_tasks(run_job_task, tasks, engine=engine, workers=workers, address=address,
                        on_result=lambda task, record: finished(task[0], record), on_poll=lambda running: poll([job for job, _ in running]))  # fmt: skip
    finally:
        for b in (steps_bar, bar):
            if b is not None:
                b.close()
    return records, [job.name for job in todo]
