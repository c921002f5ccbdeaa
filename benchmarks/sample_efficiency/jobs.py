"""Jobs: what one job is, the benchmark's list of them, running one, and its record on disk."""

from __future__ import annotations

import dataclasses
import gzip
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from benchmarks.sample_efficiency.ledger import Ledger, ProgressFile
from benchmarks.sample_efficiency.metrics import SWITCH_WINDOW, replicates, steps_to_criterion
from hippo_env.files import atomic_write

if TYPE_CHECKING:
    from benchmarks.sample_efficiency.cli import Args


@dataclass(frozen=True)
class Job:
    """One unit of work: an agent on a maze with a seed and a reward type."""

    agent: str
    maze: str
    seed: int
    reward_type: str = "sparse"
    budget: int = 300_000
    switch_budget: int = 100_000
    trials: int = 1  # "days" in the record's ``job`` (the key committed records have)
    runs: int = 1
    max_episode_steps: int = 0
    overrides: tuple[tuple[str, Any], ...] = ()
    label: str = ""

    @property
    def name(self) -> str:
        label = self.label or self.agent
        return f"{label}__{self.maze}__{self.reward_type}__seed{self.seed}"

    def spec(self) -> dict[str, Any]:
        d = {("days" if k == "trials" else k): v for k, v in dataclasses.asdict(self).items()}
        d["overrides"] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.overrides}
        return d


QUICK_OVERRIDES: dict[str, dict[str, Any]] = {
    "dqn": {
        "learning_starts": 100,
        "buffer_size": 2000,
        "batch_size": 32,
        "train_freq": 8,
        "gradient_steps": 1,
        "target_update_interval": 200,
    },
    "ppo": {"n_steps": 128, "batch_size": 32, "n_epochs": 2},
    "hippo": {"dry_run_steps": 300},
}


def learning_overrides(agent: str, budget: int, switch_budget: int) -> dict[str, Any]:
    """The learners' schedules run over the budget they are given."""
    if agent in ("dqn", "ppo"):
        return {"n_timesteps": int(budget), "switch_timesteps": int(max(switch_budget, 1))}
    return {}


def make_jobs(args: Args) -> list[Job]:
    """Every job of the benchmark (or of the sweep), in a fixed order."""
    mep = args.max_episode_steps
    if args.quick:
        mep = mep or 300
    jobs: list[Job] = []

    def add(
        agent: str,
        maze: str,
        seed: int,
        reward_type: str,
        extra: dict[str, Any] | None = None,
        label: str = "",
        budget: int | None = None,
        switch_budget: int | None = None,
    ) -> None:
        switch = args.switch_budget if switch_budget is None else switch_budget
        if agent == "hippo":
            trials, runs, agent_budget = args.hippo_days, args.hippo_runs, 0
        else:
            agent_budget = budget if budget is not None else (args.dynaq_budget if agent == "dynaq" else args.budget)
            trials, runs = 1, agent_budget // 5 + 1  # a run takes >= 5 steps (>= 1 m at 0.15 m/step, less the goal radius)
        overrides = dict(QUICK_OVERRIDES.get(agent, {})) if args.quick else {}
        overrides.update(learning_overrides(agent, agent_budget, switch))
        overrides.update(extra or {})
        jobs.append(Job(agent, maze, seed, reward_type, agent_budget, switch, trials, runs, mep, tuple(sorted(overrides.items())), label))

    if args.sweep:
        from hippomaze.baselines.hyperparams import SWEEP

        for point in SWEEP:
            for seed in point.seeds:
                add(
                    point.agent,
                    "open",
                    seed,
                    "sparse",
                    dict(point.overrides),
                    label=f"sweep-{point.name}",
                    budget=args.sweep_budget,
                    switch_budget=0,
                )
        return jobs
    # Cheap agents first, then the expensive ones seed by seed, so that a partial run has the same
    # seeds for every agent and maze; the dense variant last.
    cheap = [a for a in args.agents if a not in ("dqn", "ppo")]
    for agent in cheap:
        for maze in args.mazes:
            for seed in range(args.seeds):
                add(agent, maze, seed, "sparse")
    for seed in range(args.seeds):
        for agent in [a for a in args.agents if a in ("dqn", "ppo")]:
            for maze in args.mazes:
                add(agent, maze, seed, "sparse")
    for seed in range(args.dense_seeds):
        for agent in args.dense_agents:
            for maze in args.dense_mazes:
                add(agent, maze, seed, "dense")
    return jobs


@dataclass
class JobRecord:
    """What one job did: stored as ``<out>/sample_efficiency/<job>.json.gz``, one JSON object with these keys in this order.

    A phase (``learn``, and ``switch`` if the agent had a goal-switch trial) is the runner's dmtp.json
    fields with the runs as columns (under ``episodes``, the dmtp.json key), and the step ledger:
    ``prepare_steps`` (the dry run's steps, one entry per agent created), ``cut_steps`` (a run cut by
    the step budget); ``learn`` adds ``direct_at`` (steps to
    criterion on the first goal, or None), ``switch`` adds ``old_goal``.
    """

    job: dict[str, Any]  # Job.spec()
    name: str
    privileged: bool
    learn: dict[str, Any]
    agent_config: dict[str, Any] | None = None
    switch: dict[str, Any] | None = None  # absent from the JSON when there was no goal-switch trial
    seconds: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        record = {"job": self.job, "name": self.name, "privileged": self.privileged, "learn": self.learn, "agent_config": self.agent_config}
        if self.switch is not None:
            record["switch"] = self.switch
        record["seconds"] = self.seconds
        return record

    @classmethod
    def from_dict(cls, record: dict[str, Any]) -> JobRecord:
        return cls(**record)


def switch_seed(maze: str, seed: int, old_goal: list[float], min_distance: float = 2.0) -> int:
    """A runner seed whose goal lies at least ``min_distance`` from ``old_goal`` (deterministic).

    ``run_dmtp`` draws a trial's goal first from ``numpy.random.default_rng(seed)``; this replays that draw.
    """
    from hippo_env.env import GOAL_CLEARANCE
    from hippo_env.maze import MazeSpec

    spec = MazeSpec.load(maze)
    for k in range(1, 1000):
        candidate = 1_000_003 * (seed + 1) + k
        goal = spec.sample_free(np.random.default_rng(candidate), GOAL_CLEARANCE)
        if math.dist(goal, old_goal) >= min_distance:
            return candidate
    raise RuntimeError(f"no goal at least {min_distance} m from {old_goal} in maze {maze!r}")


def _columns(result: Any, dry_run_steps: list[int]) -> dict[str, Any]:
    """A DMTP result as a record: the dmtp.json fields, the runs as columns, and the step ledger."""
    record = result.to_dict()
    runs = record.pop("episodes")
    keys = ("trial", "run", "steps", "success", "path_length", "shortest_path_length", "indirectness", "start", "goal")
    record["episodes"] = {k: [r[k] for r in runs] for k in keys}
    record["prepare_steps"] = [int(s) for s in dry_run_steps]
    record["cut_steps"] = int(result.env_steps_total - sum(dry_run_steps) - sum(r["steps"] for r in runs))
    return record


def expected_steps(job: Job) -> int:
    """Roughly the steps a job will take (for the progress bar): its budgets, or the hippo's trials."""
    learn = job.budget or job.trials * (job.runs * 300 + 6000)
    return learn + (job.switch_budget if job.agent != "hippo" else min(job.switch_budget, job.runs * 300 + 1000))


def run_job(job: Job, progress_file: str | None = None) -> JobRecord:
    """Run one job (both phases) and return its record. Deterministic for a given job.

    ``progress_file``: where to write the number of steps taken so far (for a progress bar); the
    record does not depend on it.
    """
    import hippo_env  # noqa: F401  (registers the environment in this process)
    from hippo_env.dmtp import run_dmtp
    from hippomaze.registry import PRIVILEGED, agent_factory

    began = time.perf_counter()
    base = agent_factory(job.agent, **dict(job.overrides))
    made: list[Ledger] = []
    progress = ProgressFile(progress_file)

    def factory(observation_space: Any, action_space: Any, *, seed: int) -> Ledger:
        ledger = Ledger(base(observation_space, action_space, seed=seed), progress)
        made.append(ledger)
        return ledger

    sensors = getattr(base, "env_kwargs", {})  # e.g. the hippocampal agent's odometry
    common = {
        "env_kwargs": {**sensors, "reward_type": job.reward_type},
        "max_episode_steps": job.max_episode_steps or None,
        "progress": False,
    }
    learn = run_dmtp(
        factory, job.maze, trials=job.trials, runs=job.runs, seed=job.seed, agent_name=job.agent,
        fresh_agent_per_trial=job.trials > 1, step_budget=job.budget or None, **common,
    )  # fmt: skip
    record = JobRecord(job.spec(), job.name, job.agent in PRIVILEGED, _columns(learn, [m.dry_run_steps for m in made]))
    record.agent_config = agent_config(made[-1].agent)
    record.learn["direct_at"] = steps_to_criterion(replicates(record.learn)[-1:], window=SWITCH_WINDOW)
    if job.switch_budget > 0 and learn.run_records and record.learn["direct_at"] is not None:
        agent = made[-1]
        agent.skip_dry_run = True
        agent.trial_offset = job.trials
        old_goal = learn.run_records[-1].goal
        sseed = switch_seed(job.maze, job.seed, old_goal)
        runs = job.runs if job.agent == "hippo" else job.switch_budget // 5 + 1
        switch = run_dmtp(
            lambda observation_space, action_space, seed: agent,
            job.maze,
            trials=1,
            runs=runs,
            seed=sseed,
            agent_name=job.agent,
            step_budget=job.switch_budget,
            **common,
        )
        record.switch = _columns(switch, [0])
        record.switch["old_goal"] = [float(v) for v in old_goal]
    record.seconds = time.perf_counter() - began
    return record


def run_job_task(task: tuple[Job, str | None]) -> JobRecord:
    """:func:`run_job` on ``(job, progress_file)``: one argument, as the engine calls it."""
    job, progress_file = task
    return run_job(job, progress_file)


def agent_config(agent: Any) -> dict[str, Any] | None:
    """The parameters an agent ran with, as JSON data: its ``config()``, or its ``config.to_dict()``."""
    config = getattr(agent, "config", None)
    if callable(config):
        config = config()
    elif hasattr(config, "to_dict"):
        config = config.to_dict()
    return None if config is None else json.loads(json.dumps(config))


def current_config(job: Job) -> dict[str, Any] | None:
    """The parameters a job's agent would run with now (None for an agent without parameters)."""
    overrides = dict(job.overrides)
    if job.agent in ("dqn", "ppo", "dynaq"):
        from hippomaze.baselines.hyperparams import make_params, params_dict

        return json.loads(json.dumps(params_dict(make_params(job.agent, **overrides))))
    if job.agent == "hippo":
        from hippo_agent import AgentConfig

        return json.loads(json.dumps(dataclasses.replace(AgentConfig(), **overrides).to_dict()))
    return None


def job_path(out: Path, job: Job, sweep: bool = False) -> Path:
    folder = out / ("sample_efficiency_sweep" if sweep else "sample_efficiency")
    return folder / f"{job.name}.json.gz"


def save_record(path: Path, record: JobRecord) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, gzip.compress(json.dumps(record.to_dict(), separators=(",", ":")).encode("utf-8")))


def load_record(path: Path) -> JobRecord | None:
    """The record at ``path``; None if there is none, or it cannot be read as one."""
    try:
        with gzip.open(path, "rt") as fh:
            return JobRecord.from_dict(json.load(fh))
    except (OSError, EOFError, json.JSONDecodeError, TypeError):
        return None
