"""Running the jobs not yet on disk, on the shared engine, with progress bars; finished jobs are skipped (resumable)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from benchmarks.sample_efficiency.jobs import (
    Job,
    JobRecord,
    current_config,
    expected_steps,
    job_path,
    load_record,
    run_job_task,
    save_record,
)
from hippomaze import engine

if TYPE_CHECKING:
    from benchmarks.sample_efficiency.cli import Args


def _read_progress(path: Path) -> int:
    try:
        return int(path.read_text() or 0)
    except (OSError, ValueError):
        return 0


def run_jobs(jobs: list[Job], args: Args, out: Path) -> dict[str, JobRecord]:
    """Run the jobs not yet on disk (on the chosen engine); return every job's record by name."""
    records: dict[str, JobRecord] = {}
    todo: list[Job] = []
    for job in jobs:
        record = load_record(job_path(out, job, args.sweep))
        # a record is reused only if it was made by the same job with today's defaults
        if record is not None and record.job == job.spec() and record.agent_config == current_config(job):
            records[job.name] = record
        else:
            todo.append(job)
    bar = steps_bar = None
    progress_dir = job_path(out, todo[0], args.sweep).parent if todo else None
    if args.progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(jobs), initial=len(jobs) - len(todo), desc="jobs ", unit="job", position=0)
        steps_bar = tqdm(total=sum(expected_steps(j) for j in todo), desc="steps", unit="step", unit_scale=True, position=1, smoothing=0.05)
    done_steps = 0

    def progress_path(job: Job) -> Path:
        assert progress_dir is not None
        return progress_dir / f"{job.name}.progress"

    def poll(running: list[Job]) -> None:
        if steps_bar is not None:
            steps_bar.n = min(done_steps + sum(_read_progress(progress_path(j)) for j in running), steps_bar.total)
            steps_bar.refresh()

    def finished(job: Job, record: JobRecord) -> None:
        nonlocal done_steps
        save_record(job_path(out, job, args.sweep), record)
        progress_path(job).unlink(missing_ok=True)
        records[job.name] = record
        done_steps += expected_steps(job)
        if bar is not None:
            bar.set_postfix_str(f"{job.name} {record.seconds:.0f}s")
            bar.update(1)

    if todo:
        assert progress_dir is not None
        progress_dir.mkdir(parents=True, exist_ok=True)
        # a job on a Ray cluster cannot write its progress where the driver reads it
        local_files = engine.shares_filesystem(args.engine, args.address)
        tasks = [(job, str(progress_path(job)) if local_files else None) for job in todo]
        engine.map_tasks(run_job_task, tasks, engine=args.engine, workers=args.workers, address=args.address,
                   on_result=lambda task, record: finished(task[0], record), on_poll=lambda running: poll([job for job, _ in running]))  # fmt: skip
    for b in (steps_bar, bar):
        if b is not None:
            b.close()
    return records
