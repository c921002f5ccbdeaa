"""Jobs: what one job is, making one for a protocol, running it, and its record on disk.

A job is one (agent, maze, seed, reward type) under one of two protocols:

- **learner**: one long DMTP trial, the goal held, random starts, ``budget`` environment steps in
  all (the dry run included), one agent throughout;
- **one-shot**: ``trials`` DMTP trials of ``runs`` runs, a fresh agent (and its dry run) each
  trial, so each trial is one replicate of "an agent from birth" (the hippocampal agent's protocol).

Either way, an agent that became direct on its goal gets a goal-switch trial (at most
``switch_budget`` steps) on a goal at least 2 m away.
"""

from __future__ import annotations

import dataclasses
import datetime
import gzip
import json
import math
import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeGuard

import numpy as np

from hippo_env.files import atomic_write
from hippomaze.bench.ledger import Ledger, ProgressFile
from hippomaze.bench.metrics import SWITCH_WINDOW, replicates, steps_to_criterion
from hippomaze.runinfo import code_fingerprint

#: The protocols a job can follow (see the module docstring).
PROTOCOLS = ("learner", "one-shot")
#: The built-in agents measured as one-shot learners by default: fresh-agent trials.
ONE_SHOT_AGENTS = ("hippo", "hippo-paper")
#: A run takes at least this many steps (>= 1 m at 0.15 m/step, less the goal radius): a budget of
#: B steps holds at most B // MIN_RUN_STEPS + 1 runs.
MIN_RUN_STEPS = 5


@dataclass(frozen=True)
class Job:
    """One unit of work: an agent on a maze with a seed and a reward type (build one with :func:`make_job`).

    ``agent`` is what :func:`hippomaze.registry.agent_factory` takes; ``label`` names the agent
    variant in tables (default: ``agent``); ``budget`` 0 means the one-shot protocol.
    """

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
    def protocol(self) -> str:
        """``"one-shot"`` (fresh-agent trials, no step budget) or ``"learner"`` (one trial within ``budget``)."""
        return "learner" if self.budget else "one-shot"

    @property
    def name(self) -> str:
        label = self.label or self.agent
        return f"{label}__{self.maze}__{self.reward_type}__seed{self.seed}"

    def spec(self) -> dict[str, Any]:
        d = {("days" if k == "trials" else k): v for k, v in dataclasses.asdict(self).items()}
        d["overrides"] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.overrides}
        return d


def learning_overrides(agent: str, budget: int, switch_budget: int) -> dict[str, Any]:
    """The learners' schedules run over the budget they are given."""
    if agent in ("dqn", "ppo"):
        return {"n_timesteps": int(budget), "switch_timesteps": int(max(switch_budget, 1))}
    return {}


def default_protocol(agent: str) -> str:
    """The protocol an agent is measured with unless told otherwise: one-shot for the hippocampal agents."""
    return "one-shot" if agent in ONE_SHOT_AGENTS else "learner"


def make_job(
    agent: str,
    maze: str,
    seed: int,
    *,
    protocol: str,
    budget: int,
    switch_budget: int,
    trials: int,
    runs: int,
    reward_type: str = "sparse",
    max_episode_steps: int = 0,
    overrides: dict[str, Any] | None = None,
    label: str = "",
) -> Job:
    """One job of ``agent`` under ``protocol``: ``budget`` steps for a learner, ``trials`` x ``runs`` one-shot.

    ``overrides`` go to the agent's factory (:func:`hippomaze.registry.agent_factory`); DQN's and
    PPO's schedules are set to run over the budget.
    """
    if protocol not in PROTOCOLS:
        raise ValueError(f"protocol {protocol!r} is unknown; protocols: {', '.join(PROTOCOLS)}")
    if protocol == "one-shot":
        agent_budget = 0
    else:
        agent_budget, trials, runs = int(budget), 1, int(budget) // MIN_RUN_STEPS + 1
    settings = learning_overrides(agent, agent_budget, switch_budget) if protocol == "learner" else {}
    settings.update(overrides or {})
    return Job(agent, maze, int(seed), reward_type, agent_budget, int(switch_budget), int(trials), int(runs), int(max_episode_steps),
               tuple(sorted(settings.items())), label)  # fmt: skip


@dataclass
class JobRecord:
    """What one job did: stored as ``<folder>/<job>.json.gz`` (:func:`job_path`), one JSON object with these keys in this order.

    A phase (``learn``, and ``switch`` if the agent had a goal-switch trial) is the runner's dmtp.json
    fields with the runs as columns (under ``episodes``, the dmtp.json key), and the step ledger:
    ``prepare_steps`` (the dry run's steps, one entry per agent created), ``cut_steps`` (a run cut by
    the step budget); ``learn`` adds ``direct_at`` (steps to
    criterion on the first goal, or None), ``switch`` adds ``old_goal``. ``made``: the date, the
    package versions (:func:`versions`) and the code's fingerprint
    (:func:`hippomaze.runinfo.code_fingerprint`) of the run.
    """

    job: dict[str, Any]  # Job.spec()
    name: str
    privileged: bool
    learn: dict[str, Any]
    agent_config: dict[str, Any] | None = None
    switch: dict[str, Any] | None = None  # absent from the JSON when there was no goal-switch trial
    seconds: float = 0.0
    made: dict[str, Any] | None = None  # when, with which versions and which code the job ran (absent from older records)

    def to_dict(self) -> dict[str, Any]:
        record = {"job": self.job, "name": self.name, "privileged": self.privileged, "learn": self.learn, "agent_config": self.agent_config}
        if self.switch is not None:
            record["switch"] = self.switch
        record["seconds"] = self.seconds
        if self.made is not None:
            record["made"] = self.made
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
    """Roughly the steps a job will take (for the progress bar): its budgets, or its one-shot trials."""
    learn = job.budget or job.trials * (job.runs * 300 + 6000)
    return learn + (job.switch_budget if job.budget else min(job.switch_budget, job.runs * 300 + 1000))


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
    env_kwargs = {**sensors, "reward_type": job.reward_type}
    max_episode_steps = job.max_episode_steps or None
    learn = run_dmtp(
        factory, job.maze, trials=job.trials, runs=job.runs, seed=job.seed, agent_name=job.agent,
        fresh_agent_per_trial=job.trials > 1, step_budget=job.budget or None,
        env_kwargs=env_kwargs, max_episode_steps=max_episode_steps, progress=False,
    )  # fmt: skip
    record = JobRecord(job.spec(), job.name, job.agent in PRIVILEGED, _columns(learn, [m.dry_run_steps for m in made]))
    record.agent_config = agent_config(made[-1].agent)
    record.made = {"date": datetime.datetime.now().isoformat(timespec="seconds"), "versions": versions(), "code": code_fingerprint()}
    record.learn["direct_at"] = steps_to_criterion(replicates(record.learn)[-1:], window=SWITCH_WINDOW)
    if job.switch_budget > 0 and learn.run_records and record.learn["direct_at"] is not None:
        agent = made[-1]
        agent.skip_dry_run = True
        agent.trial_offset = job.trials
        old_goal = learn.run_records[-1].goal
        sseed = switch_seed(job.maze, job.seed, old_goal)
        runs = job.runs if job.protocol == "one-shot" else job.switch_budget // MIN_RUN_STEPS + 1
        switch = run_dmtp(
            lambda observation_space, action_space, seed: agent,
            job.maze,
            trials=1,
            runs=runs,
            seed=sseed,
            agent_name=job.agent,
            step_budget=job.switch_budget,
            env_kwargs=env_kwargs,
            max_episode_steps=max_episode_steps,
            progress=False,
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
    elif config is not None and hasattr(config, "to_dict"):
        config = config.to_dict()
    return None if config is None else json.loads(json.dumps(config))


def versions() -> dict[str, str | None]:
    """Python's version and those of the packages a job's numbers depend on (None: not installed)."""
    from hippo_env.dmtp import package_versions

    return package_versions(("gymnasium", "numpy", "pymunk", "numba", "torch", "stable-baselines3"))


#: Built-in agents whose parameters :func:`current_config` knows without building one.
CONFIGURED_AGENTS = ("hippo", "hippo-paper", "dqn", "ppo", "dynaq", "random")


def current_config(job: Job) -> dict[str, Any] | None:
    """The parameters a built-in agent would run with now (None for one without parameters)."""
    overrides = dict(job.overrides)
    if job.agent in ("dqn", "ppo", "dynaq"):
        from hippomaze.baselines.hyperparams import make_params, params_dict

        return json.loads(json.dumps(params_dict(make_params(job.agent, **overrides))))
    if job.agent in ("hippo", "hippo-paper"):
        from hippo_agent import AgentConfig

        base = AgentConfig.paper() if job.agent == "hippo-paper" else AgentConfig()
        return json.loads(json.dumps(base.with_values(overrides).to_dict()))
    return None


def reusable(record: JobRecord | None, job: Job) -> TypeGuard[JobRecord]:
    """Whether a record on disk stands for ``job``: made by the same job, by today's code (the same
    :func:`~hippomaze.runinfo.code_fingerprint` of the environment, the model and the baselines; a
    record without one was made before it was kept, so by code that may have changed) and, for a
    built-in agent, with today's defaults (the code of an agent named ``module:Class`` is taken to
    be unchanged)."""
    if record is None or record.job != job.spec() or (record.made or {}).get("code") != code_fingerprint():
        return False
    return job.agent not in CONFIGURED_AGENTS or record.agent_config == current_config(job)


def job_path(folder: Path, job: Job) -> Path:
    """Where a job's record lives in ``folder`` (its name made safe for a file name)."""
    return folder / f"{re.sub(r'[^A-Za-z0-9_.-]+', '.', job.name)}.json.gz"


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
