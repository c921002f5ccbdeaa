"""Sample efficiency: success and indirectness against environment steps, and a goal switch.

Every agent goes through :func:`hippo_env.dmtp.run_dmtp`, on the same goals and starts for the
same seed. A job is one (agent, maze, seed, reward type):

1. **learn.** The hippocampal agent: ``--hippo-days`` DMTP days of ``--hippo-runs`` runs, a fresh
   agent (and its dry run, counted) each day, so each day is one replicate of "an agent from birth".
   The learners (DQN, PPO, random, and the privileged Dyna-Q): one long day, the goal held, random
   starts, ``step_budget`` steps in all (``run_dmtp(..., trials=1, runs=<many>, step_budget=budget,
   fresh_agent_per_trial=False)``).
2. **switch.** If that agent became direct on its goal (the criterion below, within its life), it
   gets a new DMTP day: the goal moves (at least 2 m, a seed of the runner chosen for that) and the
   agent is told (``start_trial``), as the hippocampal agent always is. At most ``--switch-budget``
   steps. An agent that never became direct has nothing to become direct *again* on: no switch day.

Measuring. Steps are counted from the agent's creation, pre-exploration included; every agent is
measured by episodes alike (a wandering run of thousands of steps counts once). A replicate (hippo:
a day; learners: their one day) is *direct* from x on when the ``--window`` episodes from its
episode in progress at x on have >= 90 % successes and median indirectness <= 1.0, the one in
progress being a direct success itself; its *steps to criterion* are the first episode start from
which it is, and a seed's are the median over its replicates (hippo: its 10 days). The curves show,
at x, each replicate's ``--window`` latest episodes (the one in progress and those before it: no
looking past the run under way), pooled over the seed's replicates; no point once fewer than half
of them are still running (the days left late are the slow ones). The headline is the median over
seeds ("> budget" when fewer than half the seeds got there); the curves, the IQM over seeds with
95 % bootstrap intervals (stratified over mazes for the "all mazes" panel),
``scipy.stats.bootstrap``, percentile method. Goal switch: the episodes and steps of the new day
before the first episode that starts a direct window.

Jobs run on a local process pool (``--engine local``, default) or on Ray (``--engine ray``, local
``ray.init()`` or ``--address`` of a cluster). Each job's record is written to
``<out>/sample_efficiency/<job>.json.gz`` as soon as it finishes; finished jobs are skipped when the
command is run again (resumable). Then the summary ``<out>/sample_efficiency.json`` and the figures.

    python -m benchmarks.sample_efficiency                           # the committed results
    python -m benchmarks.sample_efficiency --quick --out /tmp/se     # a tiny smoke run
    python -m benchmarks.sample_efficiency --sweep                   # the hyperparameter sweep
    python -m benchmarks.sample_efficiency --engine ray --address auto
"""

from __future__ import annotations

import dataclasses
import datetime
import gzip
import json
import math
import os
import platform
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.common import parse_dataclass_args
from hippo_env.files import atomic_write, write_json

REPO = Path(__file__).resolve().parent.parent
LEARNERS = ("random", "dqn", "ppo", "dynaq")  # one long day with a step budget


@dataclass
class Args:
    agents: tuple[str, ...] = ("hippo", "random", "dqn", "ppo", "dynaq")
    """agents to run (hippo, random, dqn, ppo, dynaq = privileged Dyna-Q)"""
    mazes: tuple[str, ...] = ("open", "maze1")
    """mazes (sparse reward)"""
    seeds: int = 5
    """seeds 0 .. seeds-1 per agent and maze"""
    budget: int = 300_000
    """environment steps per seed for dqn, ppo and random in the learning day"""
    dynaq_budget: int = 100_000
    """environment steps per seed for the privileged Dyna-Q (it converges long before)"""
    switch_budget: int = 50_000
    """at most this many steps in the goal-switch day (0: no goal switch)"""
    dense_agents: tuple[str, ...] = ("dqn", "ppo")
    """agents also run with reward_type='dense' (the generous variant)"""
    dense_mazes: tuple[str, ...] = ("open",)
    """mazes for the dense variant"""
    dense_seeds: int = 3
    """seeds for the dense variant"""
    hippo_days: int = 10
    """fresh-agent DMTP days per seed for the hippocampal agent (replicates)"""
    hippo_runs: int = 40
    """runs per hippocampal day (run 1 explores; the rest show whether it stays direct)"""
    window: int = 10
    """episodes pooled per seed for success rate and median indirectness"""
    max_episode_steps: int = 0
    """per-run step limit (0: the environment's 10,000)"""
    engine: str = "local"
    """local (process pool) or ray"""
    address: str = ""
    """Ray cluster address (empty: start a local Ray)"""
    workers: int = 2
    """parallel jobs (local pool size; CPUs for a local Ray)"""
    out: str = "benchmarks/results"
    """output directory (job records go to <out>/sample_efficiency/)"""
    quick: bool = False
    """a tiny smoke run: tiny budgets and agents, 2 seeds, 300-step runs"""
    sweep: bool = False
    """run the hyperparameter sweep of baselines/hyperparams.py instead"""
    sweep_budget: int = 100_000
    """steps per sweep job"""
    progress: bool = True
    """show a progress bar over jobs"""
    aggregate: bool = True
    """write the summary JSON and figures after the jobs"""


def parse_args(argv: list[str] | None = None) -> Args:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    if args.engine not in ("local", "ray"):
        raise SystemExit(f"--engine must be local or ray, got {args.engine!r}")
    return args


# ----------------------------------------------------------------------------------------------- jobs
@dataclass(frozen=True)
class Job:
    """One unit of work: an agent on a maze with a seed and a reward type."""

    agent: str
    maze: str
    seed: int
    reward_type: str = "sparse"
    budget: int = 300_000
    switch_budget: int = 100_000
    days: int = 1
    runs: int = 1
    max_episode_steps: int = 0
    overrides: tuple[tuple[str, Any], ...] = ()
    label: str = ""

    @property
    def name(self) -> str:
        label = self.label or self.agent
        return f"{label}__{self.maze}__{self.reward_type}__seed{self.seed}"

    def spec(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["overrides"] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.overrides}
        return d


QUICK_OVERRIDES: dict[str, dict[str, Any]] = {
    "dqn": {"learning_starts": 100, "buffer_size": 2000, "batch_size": 32, "train_freq": 8, "gradient_steps": 1, "target_update_interval": 200},
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

    def add(agent: str, maze: str, seed: int, reward_type: str, extra: dict[str, Any] | None = None, label: str = "", budget: int | None = None, switch_budget: int | None = None) -> None:
        switch = args.switch_budget if switch_budget is None else switch_budget
        if agent == "hippo":
            days, runs, agent_budget = args.hippo_days, args.hippo_runs, 0
        else:
            agent_budget = budget if budget is not None else (args.dynaq_budget if agent == "dynaq" else args.budget)
            days, runs = 1, agent_budget // 5 + 1  # a run takes >= 5 steps (>= 1 m at 0.15 m/step, less the goal radius)
        overrides = dict(QUICK_OVERRIDES.get(agent, {})) if args.quick else {}
        overrides.update(learning_overrides(agent, agent_budget, switch))
        overrides.update(extra or {})
        jobs.append(Job(agent, maze, seed, reward_type, agent_budget, switch, days, runs, mep, tuple(sorted(overrides.items())), label))

    if args.sweep:
        from hippomaze.baselines.hyperparams import SWEEP

        for point in SWEEP:
            for seed in point.seeds:
                add(point.agent, "open", seed, "sparse", dict(point.overrides), label=f"sweep-{point.name}", budget=args.sweep_budget, switch_budget=0)
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


class _Ledger:
    """Wraps an agent for the runner: counts its pre-exploration steps, and can continue a life.

    ``prepare`` and ``start_trial`` exist on the wrapper only if the agent has them (the runner
    looks them up with ``getattr``). ``skip_prepare`` hides ``prepare`` (an agent that lives on into
    a goal-switch day does not get a second dry run); ``trial_offset`` numbers its days on.
    """

    def __init__(self, agent: Any, progress: Any = None) -> None:
        self.agent = agent
        self.prepare_steps = 0
        self.skip_prepare = False
        self.trial_offset = 0
        self.progress = progress

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        self.agent.reset(observation, info)

    def act(self, observation: Any) -> Any:
        return self.agent.act(observation)

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        self.agent.observe(action, observation, reward, terminated, truncated, info)
        if self.progress is not None:
            self.progress.step()

    def __getattr__(self, name: str) -> Any:
        if name == "prepare" and not self.skip_prepare and callable(getattr(self.agent, "prepare", None)):

            def prepare(env: Any) -> None:
                before = env.steps
                self.agent.prepare(env)
                self.prepare_steps += env.steps - before
                if self.progress is not None:
                    self.progress.step(env.steps - before)

            return prepare
        if name == "start_trial" and callable(getattr(self.agent, "start_trial", None)):
            return lambda trial: self.agent.start_trial(trial + self.trial_offset)
        raise AttributeError(name)


def switch_seed(maze: str, seed: int, old_goal: list[float], min_distance: float = 2.0) -> int:
    """A runner seed whose goal lies at least ``min_distance`` from ``old_goal`` (deterministic).

    ``run_dmtp`` draws a day's goal first from ``numpy.random.default_rng(seed)``; this replays that draw.
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


def _columns(result: Any, prepare_steps: list[int]) -> dict[str, Any]:
    """A DMTP result as a record: the dmtp.json fields, episodes as columns, and the step ledger."""
    record = result.to_dict()
    episodes = record.pop("episodes")
    keys = ("trial", "run", "steps", "success", "path_length", "shortest_path_length", "indirectness", "start", "goal")
    record["episodes"] = {k: [e[k] for e in episodes] for k in keys}
    record["prepare_steps"] = [int(s) for s in prepare_steps]
    record["cut_steps"] = int(result.env_steps_total - sum(prepare_steps) - sum(e["steps"] for e in episodes))
    return record


class _ProgressFile:
    """Writes a job's step count to a small file now and then, for the driver's progress bar."""

    def __init__(self, path: str | None, every: int = 2000) -> None:
        self.path = path
        self.every = every
        self.steps = 0
        self._last = 0

    def step(self, n: int = 1) -> None:
        self.steps += n
        if self.path and self.steps - self._last >= self.every:
            self._last = self.steps
            try:
                Path(self.path).write_text(str(self.steps))
            except OSError:
                pass


def _read_progress(path: Path) -> int:
    try:
        return int(path.read_text() or 0)
    except (OSError, ValueError):
        return 0


def expected_steps(job: Job) -> int:
    """Roughly the steps a job will take (for the progress bar): its budgets, or the hippo's days."""
    learn = job.budget or job.days * (job.runs * 300 + 6000)
    return learn + (job.switch_budget if job.agent != "hippo" else min(job.switch_budget, job.runs * 300 + 1000))


def run_job(job: Job, progress_file: str | None = None) -> dict[str, Any]:
    """Run one job (both phases) and return its record. Deterministic for a given job.

    ``progress_file``: where to write the number of steps taken so far (for a progress bar); the
    record does not depend on it.
    """
    import hippo_env  # noqa: F401  (registers the environment in this process)
    from hippomaze.registry import PRIVILEGED, agent_factory
    from hippo_env.dmtp import run_dmtp

    began = time.perf_counter()
    base = agent_factory(job.agent, **dict(job.overrides))
    made: list[_Ledger] = []
    progress = _ProgressFile(progress_file)

    def factory(observation_space: Any, action_space: Any, *, seed: int) -> _Ledger:
        ledger = _Ledger(base(observation_space, action_space, seed=seed), progress)
        made.append(ledger)
        return ledger

    sensors = getattr(base, "env_kwargs", {})  # e.g. the hippocampal agent's odometry
    common = {"env_kwargs": {**sensors, "reward_type": job.reward_type}, "max_episode_steps": job.max_episode_steps or None, "progress": False}
    learn = run_dmtp(
        factory, job.maze, trials=job.days, runs=job.runs, seed=job.seed, agent_name=job.agent,
        fresh_agent_per_trial=job.days > 1, step_budget=job.budget or None, **common,
    )  # fmt: skip
    record: dict[str, Any] = {
        "job": job.spec(),
        "name": job.name,
        "privileged": job.agent in PRIVILEGED,
        "learn": _columns(learn, [m.prepare_steps for m in made]),
    }
    record["agent_config"] = agent_config(made[-1].agent)
    record["learn"]["direct_at"] = steps_to_criterion(replicates(record["learn"])[-1:], window=SWITCH_WINDOW)
    if job.switch_budget > 0 and learn.episodes and record["learn"]["direct_at"] is not None:
        agent = made[-1]
        agent.skip_prepare = True
        agent.trial_offset = job.days
        old_goal = learn.episodes[-1].goal
        sseed = switch_seed(job.maze, job.seed, old_goal)
        runs = job.runs if job.agent == "hippo" else job.switch_budget // 5 + 1
        switch = run_dmtp(lambda observation_space, action_space, seed: agent, job.maze, trials=1, runs=runs, seed=sseed, agent_name=job.agent, step_budget=job.switch_budget, **common)
        record["switch"] = _columns(switch, [0])
        record["switch"]["old_goal"] = [float(v) for v in old_goal]
    record["seconds"] = time.perf_counter() - began
    return record


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


# --------------------------------------------------------------------------------------- job storage
def job_path(out: Path, job: Job, sweep: bool = False) -> Path:
    folder = out / ("sample_efficiency_sweep" if sweep else "sample_efficiency")
    return folder / f"{job.name}.json.gz"


def save_record(path: Path, record: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(path, gzip.compress(json.dumps(record, separators=(",", ":")).encode("utf-8")))


def load_record(path: Path) -> dict[str, Any] | None:
    try:
        with gzip.open(path, "rt") as fh:
            return json.load(fh)
    except (OSError, EOFError, json.JSONDecodeError):
        return None


def run_jobs(jobs: list[Job], args: Args, out: Path) -> dict[str, dict[str, Any]]:
    """Run the jobs not yet on disk (on the chosen engine); return every job's record by name."""
    records: dict[str, dict[str, Any]] = {}
    todo: list[Job] = []
    for job in jobs:
        record = load_record(job_path(out, job, args.sweep))
        # a record is reused only if it was made by the same job with today's defaults
        if record is not None and record.get("job") == job.spec() and record.get("agent_config") == current_config(job):
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

    def finished(job: Job, record: dict[str, Any]) -> None:
        nonlocal done_steps
        save_record(job_path(out, job, args.sweep), record)
        progress_path(job).unlink(missing_ok=True)
        records[job.name] = record
        done_steps += expected_steps(job)
        if bar is not None:
            bar.set_postfix_str(f"{job.name} {record['seconds']:.0f}s")
            bar.update(1)

    if todo:
        assert progress_dir is not None
        progress_dir.mkdir(parents=True, exist_ok=True)
        runner = _run_ray if args.engine == "ray" else _run_local
        runner(todo, args, finished, poll, lambda job: str(progress_path(job)))
    for b in (steps_bar, bar):
        if b is not None:
            b.close()
    return records


def _run_local(todo: list[Job], args: Args, finished: Any, poll: Any, progress_file: Any) -> None:
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    with ProcessPoolExecutor(max_workers=max(1, args.workers), mp_context=multiprocessing.get_context("spawn")) as pool:
        pending = {pool.submit(run_job, job, progress_file(job)): job for job in todo}
        while pending:
            done, _ = wait(pending, timeout=2.0, return_when=FIRST_COMPLETED)
            for future in done:
                finished(pending.pop(future), future.result())
            poll(list(pending.values()))


def _run_ray(todo: list[Job], args: Args, finished: Any, poll: Any, progress_file: Any) -> None:
    try:
        import ray
    except ImportError as err:
        raise SystemExit(f"--engine ray needs Ray: pip install -e .[ray] ({err})") from err
    started_here = False
    if not ray.is_initialized():
        if args.address:
            ray.init(address=args.address)
        else:
            ray.init(num_cpus=max(1, args.workers), include_dashboard=False)
        started_here = True
    try:
        remote = ray.remote(num_cpus=1)(run_job)
        pending = {remote.remote(job, progress_file(job) if not args.address else None): job for job in todo}
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1, timeout=2.0)
            for ref in done:
                finished(pending.pop(ref), ray.get(ref))
            poll(list(pending.values()))
    finally:
        if started_here:
            ray.shutdown()


# -------------------------------------------------------------------------------------------- analysis
@dataclass
class Replicate:
    """One agent life: its episodes' start and end steps (from the agent's creation), outcomes."""

    start: np.ndarray
    end: np.ndarray
    success: np.ndarray
    indirectness: np.ndarray


def replicates(phase: dict[str, Any]) -> list[Replicate]:
    """The replicates of a phase record: one per day, each day's agent being fresh (hippo) or the only one."""
    ep = phase["episodes"]
    trials = np.asarray(ep["trial"], int)
    steps = np.asarray(ep["steps"], float)
    success = np.asarray(ep["success"], bool)
    ind = np.array([np.inf if v is None else v for v in ep["indirectness"]], float)
    prepare = phase["prepare_steps"]
    out = []
    for t in range(len(prepare)):  # one entry per agent created: one per day
        mask = trials == t
        end = prepare[t] + np.cumsum(steps[mask])
        out.append(Replicate(end - steps[mask], end, success[mask], ind[mask]))
    return out


MIN_POOL = 5  # fewer pooled episodes than this: no measurement (NaN)
SWITCH_WINDOW = 10  # episodes: the window of "direct on the first goal" inside a job


def recent_at(reps: list[Replicate], x: float, window: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Each replicate's ``window`` latest episodes at step x: the one in progress (or next) and those before it.

    A learning curve that looks no further than the run under way. Every replicate is measured
    alike, by episodes: a learner's one day and each hippocampal day give the same statistic, and
    a wandering run of thousands of steps counts once. A replicate whose runs are all done keeps
    its last window. Returns successes, indirectness, and how many replicates are still running at x.
    """
    heads = [(r, int(np.searchsorted(r.end, x, side="right"))) for r in reps]  # the episode in progress at x
    running = sum(i < r.end.size for r, i in heads)
    heads = [(r, min(i, r.end.size - 1)) for r, i in heads if r.end.size]
    if not heads:
        return np.zeros(0, bool), np.zeros(0), running
    ok = np.concatenate([r.success[max(i + 1 - window, 0) : i + 1] for r, i in heads])
    ind = np.concatenate([r.indirectness[max(i + 1 - window, 0) : i + 1] for r, i in heads])
    return ok, ind, running


def metrics_at(reps: list[Replicate], x: float, window: int) -> tuple[float, float]:
    """(success rate, median indirectness) of the latest episodes at x, the curves' point.

    NaN when the pool holds fewer than MIN_POOL episodes, or fewer than half of the replicates are still
    running: the days left late are the slow ones (wandering runs), and the curve would be theirs.
    """
    ok, ind, running = recent_at(reps, x, window)
    if ok.size < min(MIN_POOL, window) or 2 * running < len(reps):
        return math.nan, math.nan
    return float(ok.mean()), float(np.median(ind))


def direct_at(rep: Replicate, x: float, window: int) -> bool:
    """One replicate is direct from x on: its episode in progress at x is a direct success, and so are the
    ``window`` episodes from it on (>= 90 % successes, median indirectness <= 1).

    Looking at the episode in progress keeps the window that looks ahead from hiding it (a
    hippocampal day's exploring first run is not hidden by the direct runs after it).
    """
    head = int(np.searchsorted(rep.end, x, side="right"))
    ok, ind = rep.success[head : head + window], rep.indirectness[head : head + window]
    if ok.size < min(MIN_POOL, window):
        return False
    return direct(float(ok.mean()), float(np.median(ind))) and direct(float(ok[0]), float(ind[0]))


def direct(success: float, indirectness: float) -> bool:
    return success >= 0.9 and indirectness <= 1.0


def replicate_steps_to_criterion(rep: Replicate, window: int) -> float | None:
    """The first episode start (steps since the agent's creation) at which the replicate is direct; None if never."""
    for x in rep.start:
        if direct_at(rep, x, window):
            return float(x)
    return None


def steps_to_criterion(reps: list[Replicate], window: int) -> float | None:
    """A seed's steps to criterion: the median over its replicates (hippo: its days), None if that is never."""
    steps = [replicate_steps_to_criterion(r, window) for r in reps]
    median = float(np.median([math.inf if s is None else s for s in steps]))
    return median if math.isfinite(median) else None


def switch_cost(phase: dict[str, Any], window: int) -> tuple[int | None, int | None]:
    """(episodes, steps) of the switch day before it is direct again; (None, None) if it never is."""
    (rep,) = replicates(phase)
    for i in range(rep.end.size):
        if direct_at(rep, rep.start[i], window):
            return i, int(rep.start[i])
    return None, None


def iqm(values: np.ndarray, axis: int = -1) -> np.ndarray | float:
    """Interquartile mean (rliable's IQM: the 25 % trimmed mean)."""
    from scipy.stats import trim_mean

    return trim_mean(values, 0.25, axis=axis)


def iqm_ci(strata: list[np.ndarray], seed: int = 0) -> tuple[float, float, float]:
    """IQM over all values and its 95 % stratified-bootstrap interval (percentile; strata resampled apart)."""
    from scipy.stats import bootstrap

    strata = [s[np.isfinite(s)] for s in strata]
    strata = [s for s in strata if s.size]
    if not strata:
        return math.nan, math.nan, math.nan
    point = float(iqm(np.concatenate(strata)))
    if sum(s.size for s in strata) < 3:  # too few seeds for an interval
        return point, math.nan, math.nan
    samples = tuple(s for s in strata if s.size >= 2)
    if not samples or all(np.ptp(s) == 0 for s in samples) and len({float(s[0]) for s in samples}) == 1:
        return point, point, point
    res = bootstrap(
        samples, lambda *xs, axis=-1: iqm(np.concatenate(xs, axis=axis), axis=axis), n_resamples=2000, confidence_level=0.95,
        method="percentile", vectorized=True, random_state=np.random.default_rng(seed),
    )  # fmt: skip
    return point, float(res.confidence_interval.low), float(res.confidence_interval.high)


def variant(record: dict[str, Any]) -> str:
    job = record["job"]
    label = job.get("label") or job["agent"]
    return label + ("-dense" if job["reward_type"] == "dense" else "")


def analyse(records: dict[str, dict[str, Any]], args: Args) -> dict[str, Any]:
    """Curves, headline table and goal-switch figures from the job records."""
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for record in records.values():
        groups.setdefault((variant(record), record["job"]["maze"]), []).append(record)
    top = max((r["learn"]["env_steps_total"] for r in records.values()), default=1000)
    grid = np.unique(np.round(np.geomspace(100, max(top, 200), 120)))
    variants = sorted({v for v, _ in groups}, key=_variant_order)
    mazes = [m for m in args.mazes if any(k[1] == m for k in groups)] + sorted({m for _, m in groups} - set(args.mazes))

    per_seed: dict[str, dict[str, Any]] = {}
    curves: dict[str, dict[str, Any]] = {}
    for (v, maze), recs in sorted(groups.items()):
        recs = sorted(recs, key=lambda r: r["job"]["seed"])
        reps = [replicates(r["learn"]) for r in recs]
        succ = np.array([[metrics_at(rp, x, args.window)[0] for x in grid] for rp in reps])
        ind = np.array([[metrics_at(rp, x, args.window)[1] for x in grid] for rp in reps])
        stc = [steps_to_criterion(rp, args.window) for rp in reps]
        switch = [switch_cost(r["switch"], args.window) if "switch" in r else (None, None) for r in recs]
        switched = ["switch" in r for r in recs]
        budget = recs[0]["job"]["budget"] or None
        per_seed[f"{v}/{maze}"] = {
            "variant": v, "maze": maze, "seeds": [r["job"]["seed"] for r in recs], "budget": budget,
            "privileged": recs[0]["privileged"],
            "env_steps_total": [r["learn"]["env_steps_total"] for r in recs],
            "prepare_steps": [r["learn"]["prepare_steps"] for r in recs],
            "episodes": [len(r["learn"]["episodes"]["steps"]) for r in recs],
            "steps_to_criterion": stc,
            "switch_episodes": [s[0] for s in switch], "switch_steps": [s[1] for s in switch],
            "switch_budget": recs[0]["job"]["switch_budget"], "switched": switched,
            "switch_runs": [len(r["switch"]["episodes"]["steps"]) if "switch" in r else None for r in recs],
            "direct_on_first_goal_at": [r["learn"].get("direct_at") for r in recs],
            "seconds": [r["seconds"] for r in recs],
        }  # fmt: skip
        curves[f"{v}/{maze}"] = {"success": succ, "indirectness": ind}

    out_curves: dict[str, Any] = {"steps": grid.tolist(), "series": {}}
    for key, c in curves.items():
        series = {}
        for metric in ("success", "indirectness"):
            stats = [iqm_ci([c[metric][:, j]], seed=j) for j in range(grid.size)]
            series[metric] = {"iqm": [_r(s[0]) for s in stats], "low": [_r(s[1]) for s in stats], "high": [_r(s[2]) for s in stats]}
        out_curves["series"][key] = series
    for v in variants:  # all mazes together: strata = mazes
        keys = [f"{v}/{m}" for m in mazes if f"{v}/{m}" in curves]
        if len(keys) < 2:
            continue
        series = {}
        for metric in ("success", "indirectness"):
            stats = [iqm_ci([curves[k][metric][:, j] for k in keys], seed=j) for j in range(grid.size)]
            series[metric] = {"iqm": [_r(s[0]) for s in stats], "low": [_r(s[1]) for s in stats], "high": [_r(s[2]) for s in stats]}
        out_curves["series"][f"{v}/all"] = series

    headline = []
    for v in variants:
        row: dict[str, Any] = {"agent": v, "privileged": any(per_seed[k]["privileged"] for k in per_seed if per_seed[k]["variant"] == v)}
        for maze in mazes:
            key = f"{v}/{maze}"
            if key not in per_seed:
                continue
            p = per_seed[key]
            row[maze] = summarize_steps(p["steps_to_criterion"], p["budget"])
            hippo = per_seed.get(f"hippo/{maze}")
            row[maze]["ratio_to_hippo"] = ratio(row[maze], summarize_steps(hippo["steps_to_criterion"], hippo["budget"])) if hippo and v != "hippo" else None
            row[maze]["switch"] = summarize_switch(
                [e for e, sw in zip(p["switch_episodes"], p["switched"]) if sw], [st for st, sw in zip(p["switch_steps"], p["switched"]) if sw], p["switch_budget"]
            )
        headline.append(row)
    return {"curves": out_curves, "per_seed": per_seed, "headline": headline, "variants": variants, "mazes": mazes}


def _variant_order(v: str) -> tuple[int, str]:
    order = ["hippo", "dqn", "ppo", "dqn-dense", "ppo-dense", "random", "dynaq"]
    return (order.index(v) if v in order else len(order), v)


def _r(value: float) -> float | None:
    return None if not math.isfinite(value) else round(float(value), 4)


def summarize_steps(values: list[float | None], budget: int | None) -> dict[str, Any]:
    """Median steps to criterion over seeds; ``None`` (shown "> budget") if fewer than half got there."""
    n = len(values)
    reached = sorted(v for v in values if v is not None)
    median = None
    if len(reached) * 2 > n or (len(reached) * 2 == n and n > 0):
        padded = reached + [math.inf] * (n - len(reached))
        m = float(np.median(padded))
        median = m if math.isfinite(m) else None
    return {"median_steps": median, "reached": len(reached), "seeds": n, "budget": budget}


def ratio(row: dict[str, Any], hippo: dict[str, Any]) -> str | float | None:
    if hippo["median_steps"] is None or hippo["median_steps"] <= 0:
        return None
    if row["median_steps"] is None:
        budget = row["budget"]
        return f"> {budget / hippo['median_steps']:.0f}" if budget else None
    return round(row["median_steps"] / hippo["median_steps"], 2)


def summarize_switch(episodes: list[int | None], steps: list[int | None], budget: int) -> dict[str, Any]:
    n = len(episodes)
    done_e = [e for e in episodes if e is not None]
    done_s = [s for s in steps if s is not None]
    enough = len(done_e) * 2 >= n > 0
    pad = [math.inf] * (n - len(done_e))
    return {
        "median_episodes": float(np.median(done_e + pad)) if enough and math.isfinite(np.median(done_e + pad)) else None,
        "median_steps": float(np.median(done_s + pad)) if enough and math.isfinite(np.median(done_s + pad)) else None,
        "reached": len(done_e), "seeds": n, "budget": budget,
    }  # fmt: skip


def fmt_steps(value: float | None, budget: int | None) -> str:
    if value is None:
        return f"> {budget:,}" if budget else "never"
    return f"{value:,.0f}"


def headline_markdown(summary: dict[str, Any]) -> str:
    """The headline table as Markdown."""
    mazes = summary["mazes"]
    head = "| agent | " + " | ".join(f"{m}: steps to direct | {m}: x hippo" for m in mazes) + " |"
    lines = [head, "|" + "---|" * (1 + 2 * len(mazes))]
    for row in summary["headline"]:
        name = row["agent"] + (" (privileged)" if row["privileged"] else "")
        cells = []
        for m in mazes:
            cell = row.get(m)
            if cell is None:
                cells += ["", ""]
                continue
            steps = fmt_steps(cell["median_steps"], cell["budget"])
            cells.append(f"{steps} ({cell['reached']}/{cell['seeds']})")
            r = cell["ratio_to_hippo"]
            if row["agent"] == "hippo":
                cells.append("1" if cell["median_steps"] is not None else "n/a")
            else:
                cells.append("n/a" if r is None else (r if isinstance(r, str) else f"{r:g}"))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def switch_markdown(summary: dict[str, Any]) -> str:
    mazes = summary["mazes"]
    lines = ["| agent | " + " | ".join(f"{m}: episodes | {m}: steps" for m in mazes) + " |", "|" + "---|" * (1 + 2 * len(mazes))]
    for row in summary["headline"]:
        name = row["agent"] + (" (privileged)" if row["privileged"] else "")
        cells = []
        for m in mazes:
            cell = (row.get(m) or {}).get("switch")
            if not cell:
                cells += ["", ""]
                continue
            if cell["seeds"] == 0:
                cells += ["n/a: never direct on the first goal", ""]
                continue
            e = "never" if cell["median_episodes"] is None else f"{cell['median_episodes']:g}"
            cells.append(f"{e} ({cell['reached']}/{cell['seeds']})")
            cells.append(fmt_steps(cell["median_steps"], cell["budget"]))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


# -------------------------------------------------------------------------------------------- figures
COLORS = {"hippo": "C3", "dqn": "C0", "ppo": "C2", "random": "0.5", "dynaq": "C4"}


def plot_curves(summary: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curves = summary["curves"]
    x = np.asarray(curves["steps"])
    panels = list(summary["mazes"]) + (["all"] if any(k.endswith("/all") for k in curves["series"]) else [])
    fig, axes = plt.subplots(2, len(panels), figsize=(4.6 * len(panels), 7.2), sharex=True, squeeze=False)
    for col, maze in enumerate(panels):
        for row, metric in enumerate(("success", "indirectness")):
            ax = axes[row, col]
            for v in summary["variants"]:
                s = curves["series"].get(f"{v}/{maze}")
                if s is None:
                    continue
                base = v.removesuffix("-dense")
                y, lo, hi = (np.array([np.nan if a is None else a for a in s[metric][k]], float) for k in ("iqm", "low", "high"))
                style = "--" if v.endswith("-dense") else "-"
                label = v + (" (privileged)" if base == "dynaq" else "")
                ax.plot(x, y, style, color=COLORS.get(base, None), label=label, lw=1.8)
                ax.fill_between(x, lo, hi, color=COLORS.get(base, None), alpha=0.15, lw=0)
            ax.set_xscale("log")
            ax.set_xlim(x[0], x[-1])
            if metric == "success":
                ax.axhline(0.9, color="k", lw=0.7, ls=":")
                ax.set_ylim(-0.03, 1.03)
                ax.set_title(maze if maze != "all" else "all mazes (stratified)")
                ax.set_ylabel("success rate" if col == 0 else "")
            else:
                ax.axhline(1.0, color="k", lw=0.7, ls=":")
                ax.set_yscale("log")
                ax.set_ylim(0.05, 1000)
                ax.set_ylabel("median indirectness" if col == 0 else "")
                ax.set_xlabel("environment steps (pre-exploration included)")
            ax.grid(alpha=0.3, which="both", lw=0.4)
    axes[0, 0].legend(fontsize=8, loc="upper left")
    fig.suptitle(f"IQM over seeds, 95 % stratified-bootstrap CI\n(per seed at x: each replicate's run in progress and the {summary['args']['window'] - 1} before it; hippo: {summary['args']['hippo_days']} fresh-agent days per seed)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_switch(summary: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mazes = summary["mazes"]
    variants = summary["variants"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    width = 0.8 / max(len(mazes), 1)
    for k, (metric, label) in enumerate((("switch_episodes", "episodes"), ("switch_steps", "steps"))):
        ax = axes[k]
        for j, maze in enumerate(mazes):
            for i, v in enumerate(variants):
                p = summary["per_seed"].get(f"{v}/{maze}")
                if p is None:
                    continue
                keep = [k for k, sw in enumerate(p["switched"]) if sw]
                if not keep:
                    continue
                caps = [p["switch_budget"] if metric == "switch_steps" else p["switch_runs"][k] for k in keep]
                vals = np.array([np.nan if p[metric][k] is None else p[metric][k] for k in keep], float)
                cap = np.asarray(caps, float)
                xs = i + (j - (len(mazes) - 1) / 2) * width
                never = ~np.isfinite(vals)
                shown = np.where(never, cap, vals) + (1 if metric == "switch_episodes" else 0)
                ax.scatter(np.full(shown.size, xs), np.maximum(shown, 1), marker="o" if j == 0 else "s", s=22,
                           facecolors=np.where(never, "none", COLORS.get(v.removesuffix("-dense"), "k")).tolist(),
                           edgecolors=COLORS.get(v.removesuffix("-dense"), "k"), label=maze if i == 0 else None)  # fmt: skip
        ax.set_xticks(range(len(variants)), [v + (" (priv.)" if v == "dynaq" else "") for v in variants], rotation=30, ha="right")
        ax.set_yscale("log")
        ax.set_ylim(0.8, None)
        ax.set_ylabel(("episodes + 1" if label == "episodes" else "steps") + " before direct again")
        ax.grid(alpha=0.3, which="both", lw=0.4)
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(title="maze (open marker: never)", fontsize=8)
    fig.suptitle("Goal switch: once an agent is direct on its goal, the goal moves; cost of becoming direct again\n"
                 "(one point per seed that was direct on the first goal; open marker: not direct again within the switch day)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------ main
def sweep_summary(records: dict[str, dict[str, Any]], args: Args) -> dict[str, Any]:
    rows = []
    for label in sorted({r["job"]["label"] for r in records.values()}):
        recs = [r for r in records.values() if r["job"]["label"] == label]
        stc, final_s, final_i = [], [], []
        for r in recs:
            (rep,) = replicates(r["learn"])
            stc.append(steps_to_criterion([rep], args.window))
            final_s.append(float(rep.success[-50:].mean()) if rep.end.size else 0.0)
            final_i.append(float(np.median(rep.indirectness[-50:])) if rep.end.size else math.inf)
        rows.append({
            "name": label.removeprefix("sweep-"), "agent": recs[0]["job"]["agent"], "overrides": recs[0]["job"]["overrides"],
            "seeds": [r["job"]["seed"] for r in recs], "steps_to_criterion": stc,
            "final_success_rate": final_s, "final_median_indirectness": [_r(v) for v in final_i],
            "episodes": [len(r["learn"]["episodes"]["steps"]) for r in recs], "seconds": [round(r["seconds"], 1) for r in recs],
        })  # fmt: skip
    return {"budget": args.sweep_budget, "maze": "open", "reward_type": "sparse", "rows": rows}


def main(argv: list[str] | None = None) -> dict[str, Any]:
    args = parse_args(argv)
    out = Path(args.out)
    if not out.is_absolute():
        out = Path.cwd() / out
    jobs = make_jobs(args)
    began = time.perf_counter()
    records = run_jobs(jobs, args, out)
    wall = time.perf_counter() - began
    command = "python -m benchmarks.sample_efficiency " + shlex.join(sys.argv[1:] if argv is None else argv)
    meta = {
        "command": command.strip(), "args": dataclasses.asdict(args), "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "python": platform.python_version(), "machine": platform.machine(), "cpus": os.cpu_count(),
        "jobs": len(jobs), "wall_seconds_this_invocation": round(wall, 1),
        "cpu_seconds_all_jobs": round(sum(r["seconds"] for r in records.values()), 1),
    }  # fmt: skip
    if not args.aggregate:
        return {"meta": meta, "records": records}
    if args.sweep:
        summary = {**meta, **sweep_summary(records, args)}
        write_json(out / "sample_efficiency_sweep.json", summary)
        print(json.dumps(summary["rows"], indent=1))
        return summary
    summary = {**meta, **analyse({j.name: records[j.name] for j in jobs}, args)}
    summary["headline_markdown"] = headline_markdown(summary)
    summary["switch_markdown"] = switch_markdown(summary)
    stem = "sample_efficiency_quick" if args.quick else "sample_efficiency"
    write_json(out / f"{stem}.json", summary)
    plot_curves(summary, out / f"{stem}.png")
    plot_switch(summary, out / f"{stem}_goal_switch.png")
    print(summary["headline_markdown"])
    print()
    print(summary["switch_markdown"])
    return summary


if __name__ == "__main__":
    main()
