"""The delayed-match-to-place (DMTP) experiment: the runner, its records, and the act -> step ->
observe loop every agent is driven by.

:func:`run_dmtp` runs ``trials`` trials, each with a new goal, of ``runs`` runs each, with any agent
that follows the Agent protocol (:mod:`hippo_env.agent_protocol`); or a schedule of phases
(:mod:`hippo_env.schedule`): mazes that change, goals kept or moved, announced or not. Goals and
starts are drawn by the runner from its own seeded generator, so every agent given the same seed
faces exactly the same goals and starts. :func:`rollout` is the loop itself, for anyone who drives an agent."""

from __future__ import annotations

import dataclasses
import importlib.metadata
import inspect
import io
import json
import math
import platform
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np

from hippo_env.agent_protocol import AgentFactory, missing_methods
from hippo_env.checks import check_int
from hippo_env.env import HippoMazeEnv, add_indirectness, maze_env
from hippo_env.files import atomic_write, finite_or_none, jsonable, write_json
from hippo_env.maze import MazeSpec
from hippo_env.schedule import Schedule, SchedulePlanner, TrialPlan, plain_plans, schedule_summary


@dataclass
class Run:
    """One run of one trial, as recorded in ``dmtp.json`` (under its key ``"episodes"``). ``trial`` counts
    over the whole experiment; ``phase`` and ``repeat`` place a schedule's run (written only for those)."""

    trial: int
    run: int
    steps: int
    success: bool
    path_length: float
    shortest_path_length: float
    indirectness: float
    start: list[float]
    goal: list[float]
    phase: int = 0
    repeat: int = 0


@dataclass
class DMTPResult:
    """Everything a DMTP experiment produced. ``paths[trial][run]`` is an (n, 2) array of positions.

    ``run_records`` holds one :class:`Run` per finished run, in order (``dmtp.json`` keeps them under
    ``"episodes"``). ``complete`` is False when the experiment was interrupted (Ctrl-C) or an
    exception stopped it (``error`` then names it) before every trial ran: ``run_records`` then
    holds only the runs that finished.

    ``dry_run_steps`` has one entry per trial begun: the environment steps of that trial's dry run
    (0 when the agent has none, or was kept from an earlier trial). ``env_steps_total`` is their sum
    plus the recorded runs' steps, plus those of a run cut short (by the step budget, Ctrl-C or an
    exception), which is not recorded.
    The remaining fields say what reproduces the result: ``max_episode_steps``, ``action_type``,
    ``env_kwargs`` (every argument given to ``gym.make`` besides the maze), ``agent_spec`` (what
    names the agent, e.g. ``module:Class``), ``agent_config`` (its configuration as JSON, or None),
    ``agent_overrides`` (the parameters its factory was given, if any) and ``versions`` (of Python
    and the packages that decide the result).

    A schedule's result also has ``schedule`` (as run) and ``phases`` (per phase begun, in each
    repeat: its maze's name, dry-run steps and goals; ``phase_mazes``, not written, its mazes);
    its ``dry_run_steps`` has one entry per phase begun, ``trials`` counts every phase's trials in
    every repeat, ``runs`` is the most runs of a phase, ``maze`` names the first phase's maze.
    """

    maze: str
    agent: str
    seed: int
    trials: int
    runs: int
    env_steps_total: int = 0
    run_records: list[Run] = field(default_factory=list)
    paths: list[list[np.ndarray]] = field(default_factory=list)
    seconds: float = 0.0
    complete: bool = True
    dry_run_steps: list[int] = field(default_factory=list)
    max_episode_steps: int | None = None
    action_type: str | None = None
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    agent_spec: str | None = None
    agent_config: Any = None
    versions: dict[str, str | None] = field(default_factory=dict)
    error: str | None = None
    agent_overrides: dict[str, Any] | None = None
    schedule: dict[str, Any] | None = None
    phases: list[dict[str, Any]] = field(default_factory=list)
    phase_mazes: list[MazeSpec] = field(default_factory=list, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """The ``dmtp.json`` record (paths and timing left out).

        An incomplete experiment's record also has ``"complete": false`` (and, if an exception
        stopped it, ``"error"``); a complete one has exactly the documented keys.
        """
        record: dict[str, Any] = {
            "maze": self.maze,
            "agent": self.agent,
            "seed": self.seed,
            "trials": self.trials,
            "runs": self.runs,
            "env_steps_total": self.env_steps_total,
            "dry_run_steps": list(self.dry_run_steps),
            "max_episode_steps": self.max_episode_steps,
            "action_type": self.action_type,
            "env_kwargs": _plain(self.env_kwargs),
            "agent_spec": self.agent_spec,
            "agent_config": self.agent_config,
            "versions": dict(self.versions),
        }
        if self.agent_overrides:
            record["agent_overrides"] = _plain(self.agent_overrides)
        if self.schedule is not None:
            record["schedule"] = self.schedule
            record["phases"] = jsonable(self.phases)
        if not self.complete:
            record["complete"] = False
        if self.error is not None:
            record["error"] = self.error
        hidden = ("phase", "repeat") if self.schedule is None else ()  # a plain run's episodes keep exactly their documented keys
        record["episodes"] = [{k: v for k, v in jsonable(asdict(r)).items() if k not in hidden} for r in self.run_records]
        return record

    def planned_runs(self) -> int:
        """Runs the experiment set out to record."""
        if self.schedule is None:
            return self.trials * self.runs
        return int(self.schedule["repeats"]) * sum(p["trials"] * p["runs"] for p in self.schedule["phases"])

    def save(self, out_dir: str | Path) -> Path:
        """Write ``dmtp.json`` and ``paths.npz`` (every run's positions) into ``out_dir``, each atomically."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        buffer = io.BytesIO()
        arrays: dict[str, Any] = {f"trial{t}_run{r}": p for t, runs in enumerate(self.paths) for r, p in enumerate(runs)}
        np.savez_compressed(buffer, **arrays)
        atomic_write(out / "paths.npz", buffer.getvalue())
        return write_json(out / "dmtp.json", self.to_dict())

    def indirectness(self) -> np.ndarray:
        """A (trials, runs) array of indirectness (NaN where not recorded)."""
        table = np.full((self.trials, self.runs), np.nan)
        for r in self.run_records:
            table[r.trial, r.run] = r.indirectness
        return table

    def success(self) -> np.ndarray:
        """A (trials, runs) boolean array: which runs reached the goal."""
        table = np.zeros((self.trials, self.runs), dtype=bool)
        for r in self.run_records:
            table[r.trial, r.run] = r.success
        return table

    def summary(self) -> dict[str, Any]:
        """Per-run medians, success rates, and the run-1 length vs run-2 indirectness correlation;
        for a schedule, per phase (:func:`hippo_env.schedule.schedule_summary`)."""
        if self.schedule is not None:
            return schedule_summary(self)
        ind, ok = self.indirectness(), self.success()
        lengths = np.full((self.trials, self.runs), np.nan)
        for r in self.run_records:
            lengths[r.trial, r.run] = r.path_length
        later = ind[:, 1:]
        summary: dict[str, Any] = {
            "median_indirectness": [
                finite_or_none(float(np.nanmedian(ind[:, r]))) if np.isfinite(ind[:, r]).any() else None for r in range(self.runs)
            ],
            "success_rate": [float(ok[:, r].mean()) for r in range(self.runs)],
        }
        if self.runs > 1:
            summary["later_runs_success_rate"] = float(ok[:, 1:].mean())
            summary["later_runs_below_1"] = float((later < 1.0).mean())
            if self.trials > 2 and np.std(lengths[:, 0]) > 0 and np.std(ind[:, 1]) > 0:
                summary["pearson_run1_length_run2_indirectness"] = float(np.corrcoef(lengths[:, 0], ind[:, 1])[0, 1])
        return summary


@dataclass
class RolloutEnd:
    """How a :func:`rollout` ended: the last step's outcome and the number of steps taken."""

    observation: Any
    reward: float
    terminated: bool
    truncated: bool
    info: dict[str, Any]
    steps: int


def rollout(
    env: gym.Env, agent: Any, observation: Any, *, max_steps: int | None = None, keep_going: Callable[[], bool] | None = None
) -> RolloutEnd:
    """Drive ``agent`` from ``observation``: ``act``, ``env.step``, ``observe``, until the run ends
    (terminated or truncated), ``max_steps`` steps were taken, or ``keep_going()`` (asked after each step) is False.

    The caller resets the env and the agent first. With ``max_steps=0`` nothing happens.
    """
    reward: SupportsFloat = 0.0
    terminated, truncated, steps = False, False, 0
    info: dict[str, Any] = {}
    while max_steps is None or steps < max_steps:
        action = agent.act(observation)
        observation, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, observation, reward, terminated, truncated, info)
        steps += 1
        if terminated or truncated or (keep_going is not None and not keep_going()):
            break
    return RolloutEnd(observation, float(reward), bool(terminated), bool(truncated), info, steps)


class _CountingEnv(gym.Wrapper):
    """Counts every step taken through it and cuts a run at ``limit`` steps (``truncated=True``, as
    a time limit does); during the dry run it refuses to place a goal or change the maze."""

    def __init__(self, env: gym.Env, allow_goal: bool, limit: int | None = None) -> None:
        super().__init__(env)
        self.steps = 0
        self.run_steps = 0
        self.allow_goal = allow_goal
        self.limit = limit

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        if not self.allow_goal and options and (options.get("goal") is not None or options.get("new_goal") or "maze" in options):
            raise ValueError("an agent may not place a goal during its dry run, nor swap the maze: omit 'goal', 'new_goal', 'maze'")
        self.run_steps = 0
        return self.env.reset(seed=seed, options=options)

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        self.steps += 1
        self.run_steps += 1
        observation, reward, terminated, truncated, info = self.env.step(action)
        if self.limit is not None and self.run_steps >= self.limit and not (terminated or truncated):
            truncated = True
            add_indirectness(info)
        return observation, reward, terminated, truncated, info


def run_dmtp(
    make_agent: AgentFactory,
    maze: str | Path | MazeSpec | None = None,
    trials: int | None = None,
    runs: int | None = None,
    seed: int = 0,
    *,
    schedule: Schedule | str | Path | dict[str, Any] | None = None,
    agent_name: str = "agent",
    agent_spec: str | None = None,
    agent_overrides: dict[str, Any] | None = None,
    same_start: bool = False,
    fresh_agent_per_trial: bool = True,
    env_kwargs: dict[str, Any] | None = None,
    max_episode_steps: int | None = None,
    step_budget: int | None = None,
    progress: bool = True,
    on_run_end: Callable[[int, int, Any, gym.Env], None] | None = None,
) -> DMTPResult:
    """Run the delayed-match-to-place protocol, or a schedule of phases, and record every run.

    Args:
        make_agent: ``make_agent(observation_space, action_space, seed=seed)`` returns an agent
            (an agent class taking ``seed=`` fits, e.g. ``HippocampalAgent``).
        maze: A built-in maze name, a JSON path or a spec (default ``"open"``).
        trials: Trials, each with a new goal (default 20).
        runs: Runs per trial; the first is naive about the new goal (default 4).
        seed: Seeds the goals, starts, environment and agents.
        schedule: Instead of ``maze``, ``trials`` and ``runs`` (an error with any of them): a
            :class:`~hippo_env.schedule.Schedule`, its JSON object or a path to its file. One agent
            lives through a repeat's phases; each phase's maze is put in the environment with
            ``reset(options={"maze": ...})`` at its first reset; ``fresh_agent_per_trial`` is not used.
        agent_name: The name recorded in the result.
        agent_spec: What names the agent for someone reproducing the result (``hippomaze dmtp``
            gives its ``--agent``); by default ``module:Name`` of ``make_agent`` where that can be
            imported, else ``agent_name``.
        agent_overrides: The parameters ``make_agent`` was made with, for the record only.
        same_start: Start every run of a trial from the same place (the paper's Fig. 3).
        fresh_agent_per_trial: A new agent (and its dry run) for each trial, making trials
            independent replicates; otherwise one agent lives through every trial.
        env_kwargs: More arguments for ``gym.make("HippoMaze-v0", ...)``. A factory may carry its
            own ``env_kwargs`` attribute, the sensors its agent needs (the hippocampal agent's
            factory asks for ``odometry=True``); these come first, ``env_kwargs`` overrides them.
        max_episode_steps: Overrides the registered limit of 10,000 steps per run.
        step_budget: Stop once this many environment steps (the dry run included) have been
            taken; the run cut short by the budget is not recorded, its steps are counted.
        progress: Show a progress bar.
        on_run_end: Called as ``on_run_end(trial, run, agent, env)`` after every run.

    Raises:
        TypeError: ``trials`` or ``runs`` not an integer, or an agent that does not follow the protocol.
        ValueError: ``trials`` or ``runs`` below 1, a bad maze or schedule, or an environment argument ``HippoMaze-v0`` does not take.
        DMTPInterrupted: On Ctrl-C (a ``KeyboardInterrupt``); its ``result`` holds the finished runs.
        DMTPFailed: When an exception escapes the agent, the environment or ``on_run_end`` once the
            experiment has begun; raised from that exception (its traceback is kept), with the
            finished runs in its ``result``.
    """
    plans: Iterable[TrialPlan]
    if schedule is not None:
        plans = planner = SchedulePlanner.instead_of(schedule, int(seed), same_start, maze=maze, trials=trials, runs=runs)
        spec, trials, runs = planner.first_maze, planner.schedule.total_trials, max(p.runs for p in planner.schedule.phases)
        run_limit, make_limit = planner.step_limits(max_episode_steps, gym.spec("HippoMaze-v0").max_episode_steps or 10_000)
    else:
        trials, runs, planner = (20 if trials is None else trials), (4 if runs is None else runs), None
        check_int(trials, "trials", 1, "a positive integer")
        check_int(runs, "runs", 1, "a positive integer")
        spec = MazeSpec.load("open" if maze is None else maze)
        run_limit, make_limit = None, max_episode_steps
        plans = plain_plans(spec, trials, runs, int(seed), same_start, fresh_agent_per_trial)
    env, make_kwargs = _make_env(spec, make_agent, env_kwargs, make_limit)
    result = DMTPResult(
        maze=spec.name,
        agent=agent_name,
        seed=int(seed),
        trials=int(trials),
        runs=int(runs),
        max_episode_steps=run_limit if planner is not None else (env.spec.max_episode_steps if env.spec is not None else max_episode_steps),
        action_type=maze_env(env).action_type,
        env_kwargs=dict(make_kwargs),
        agent_spec=agent_spec or _importable_name(make_agent) or agent_name,
        versions=package_versions(),
        agent_overrides=dict(agent_overrides) if agent_overrides else None,
        schedule=planner.schedule.to_dict() if planner is not None else None,
    )
    bar = _progress(result.planned_runs(), f"{agent_name} on {spec.name}" if planner is None else f"{agent_name}: schedule", progress)
    experiment = _Experiment(env, result, make_agent, step_budget, on_run_end, bar, run_limit)
    env.reset(seed=int(seed), options={"goal": None})
    experiment.run(plans)
    return result


def _make_env(
    spec: MazeSpec, make_agent: AgentFactory, env_kwargs: dict[str, Any] | None, max_episode_steps: int | None
) -> tuple[gym.Env, dict[str, Any]]:
    """The experiment's environment and every argument it was made with besides the maze: the
    factory's own ``env_kwargs``, then ``env_kwargs`` over them, then ``max_episode_steps``."""
    make_kwargs = {**getattr(make_agent, "env_kwargs", {}), **(env_kwargs or {})}
    if max_episode_steps is not None:
        make_kwargs["max_episode_steps"] = max_episode_steps
    _check_make_kwargs(make_kwargs)
    return gym.make("HippoMaze-v0", maze=spec, **make_kwargs), make_kwargs


class _Experiment:
    """One :func:`run_dmtp` call under way: the environment, the agent, the step count and the record.

    ``doing`` says what the runner is doing, for the message of an exception that stops it.
    ``run_limit`` (a schedule's) cuts each dry-run episode, as the environment's time limit would.
    """

    def __init__(
        self,
        env: gym.Env,
        result: DMTPResult,
        make_agent: AgentFactory,
        step_budget: int | None,
        on_run_end: Callable[[int, int, Any, gym.Env], None] | None,
        bar: Any,
        run_limit: int | None = None,
    ) -> None:
        self.env = env
        self.counted = _CountingEnv(env, allow_goal=True)
        self.result = result
        self.make_agent = make_agent
        self.step_budget = step_budget
        self.on_run_end = on_run_end
        self.bar = bar
        self.agent: Any = None
        self.run_limit = run_limit
        self.maze: dict[str, Any] = {}  # {"maze": spec} until the reset that puts a new maze in the env
        self.doing = "starting"
        self.began = time.perf_counter()

    def run(self, plans: Iterable[TrialPlan]) -> None:
        """Every trial planned and its runs; on Ctrl-C or an exception, keep what finished and raise
        :class:`DMTPInterrupted` or :class:`DMTPFailed`."""
        result = self.result
        try:
            for plan in plans:
                if not self.budget_left():
                    break
                self.begin(plan)
                for run, start in enumerate(plan.starts):
                    if not self.budget_left() or not self.run_once(plan, run, start):
                        break
                self.doing = "planning the next trial"
        except KeyboardInterrupt:
            _keep_finished(result)
            self.finish()
            raise DMTPInterrupted(result) from None
        except Exception as err:
            _keep_finished(result)
            result.error = f"{type(err).__name__}: {err}"
            self.finish()
            raise DMTPFailed(result, self.doing) from err
        self.finish()

    def budget_left(self) -> bool:
        """Whether the step budget (the dry runs' steps included) allows another step."""
        return self.step_budget is None or sum(self.result.dry_run_steps) + self.counted.steps < self.step_budget

    def begin(self, plan: TrialPlan) -> None:
        """Open a trial: its phase's records, a new maze, a new agent, a dry run and ``start_trial``, as planned."""
        if plan.new_phase:
            self.result.dry_run_steps.append(0)
            if plan.record is not None:
                self.result.phases.append(plan.record)
        if plan.maze is not None:
            self.result.phase_mazes.append(plan.maze)
            self.maze = {} if plan.maze == maze_env(self.env).maze else {"maze": plan.maze}
        if plan.agent_seed is not None:
            self.doing = f"building the agent for {plan.label}"
            self.agent = self.make_agent(self.env.observation_space, self.env.action_space, seed=plan.agent_seed)
            _check_agent(self.agent)
            if plan.trial == 0:
                self.result.agent_config = agent_config(self.agent)
        dry_run = dry_run_method(self.agent) if plan.dry_run else None
        if dry_run is not None:
            self.doing = f"the dry run of {plan.label}"
            self.env.reset(options={"goal": None, **self.maze})
            self.maze = {}
            explorer = _CountingEnv(self.env, allow_goal=False, limit=self.run_limit)
            try:
                dry_run(explorer)
            finally:
                self.result.dry_run_steps[-1] = explorer.steps
                if plan.record is not None:
                    plan.record["dry_run_steps"] = explorer.steps
        self.doing = f"starting {plan.label}"
        if plan.announce and callable(getattr(self.agent, "start_trial", None)):
            self.agent.start_trial(plan.life_trial)
        self.result.paths.append([])

    def run_once(self, plan: TrialPlan, run: int, start: np.ndarray) -> bool:
        """One run from ``start``, recorded; False if the step budget cut it short (not a run: not recorded)."""
        self.doing = f"{plan.label}, run {run + 1}"
        self.counted.limit = plan.max_steps or self.run_limit
        observation, info = self.counted.reset(options={"goal": plan.goal, "start": start, **self.maze})
        self.maze = {}
        self.agent.reset(observation, info)
        steps_before = self.counted.steps
        end = rollout(self.counted, self.agent, observation, keep_going=self.budget_left)
        if not (end.terminated or end.truncated):
            return False
        self.result.paths[-1].append(maze_env(self.env).path.copy())
        self.result.run_records.append(
            Run(
                trial=plan.trial,
                run=run,
                steps=self.counted.steps - steps_before,
                success=bool(end.info["is_success"]),
                path_length=float(end.info["path_length"]),
                shortest_path_length=float(end.info["shortest_path_length"]),
                indirectness=float(end.info.get("indirectness", math.nan)),
                start=[float(v) for v in start],
                goal=[float(v) for v in plan.goal],
                phase=plan.phase,
                repeat=plan.repeat,
            )
        )
        if self.on_run_end is not None:
            self.doing = f"on_run_end after {plan.label}, run {run + 1}"
            self.on_run_end(plan.trial, run, self.agent, self.env)
        if self.bar is not None:
            self.bar.set_postfix_str(f"{plan.label}, run {run + 1}, indirectness {self.result.run_records[-1].indirectness:.2f}")
            self.bar.update(1)
        return True

    def finish(self) -> None:
        """Count the steps, stop the clock, close the progress bar and the environment."""
        self.result.env_steps_total = sum(self.result.dry_run_steps) + self.counted.steps
        self.result.seconds = time.perf_counter() - self.began
        if self.bar is not None:
            self.bar.close()
        self.env.close()


def _keep_finished(result: DMTPResult) -> None:
    """Mark ``result`` incomplete, keeping what finished consistently: a run counts once it is recorded."""
    result.complete = False
    done = [sum(r.trial == t for r in result.run_records) for t in range(len(result.paths))]
    result.paths = [paths[:n] for paths, n in zip(result.paths, done)]
    while result.paths and not result.paths[-1]:
        result.paths.pop()


class DMTPInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`run_dmtp`. ``result`` holds every run that finished, ``complete=False``.

    A subclass of ``KeyboardInterrupt``, so code that does not look for it still stops as usual.
    """

    def __init__(self, result: DMTPResult) -> None:
        super().__init__(f"interrupted after {len(result.run_records)} of {result.planned_runs()} runs")
        self.result = result


class DMTPFailed(Exception):
    """An exception stopped :func:`run_dmtp`: raised from it (``__cause__``, with its traceback).

    ``result`` holds every run that finished, with ``complete=False`` and ``error`` naming the
    exception; ``doing`` says what the runner was doing (e.g. ``"trial 2, run 1"``). Pickled (out of
    a worker process), it is a RuntimeError with the same message."""

    def __init__(self, result: DMTPResult, doing: str) -> None:
        super().__init__(f"{result.error} ({doing}; {len(result.run_records)} of {result.planned_runs()} runs finished)")
        self.result = result
        self.doing = doing

    def __reduce__(self) -> tuple[Any, tuple[str]]:
        return RuntimeError, (str(self),)


def agent_config(agent: Any) -> Any:
    """The agent's configuration as JSON, for the record: its ``config`` attribute (a dataclass,
    or what a ``config()`` method returns), or None when it has none or it cannot be written as JSON."""
    config = getattr(agent, "config", None)
    if inspect.ismethod(config):
        try:
            config = config()
        except TypeError:  # a method that needs arguments: not a config the record can hold
            return None
    if dataclasses.is_dataclass(config) and not isinstance(config, type):
        config = dataclasses.asdict(config)
    config = jsonable(config)
    try:
        json.dumps(config, allow_nan=False)
    except (TypeError, ValueError):
        return None
    return config


def _plain(value: Any) -> Any:
    """``value`` as JSON types, with anything JSON cannot hold written as its ``repr``."""
    return json.loads(json.dumps(jsonable(value), default=repr))


def _importable_name(obj: Any) -> str | None:
    """``module:Name`` for a module-level class or function, which ``--agent`` can import; else None."""
    module, name = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    if not isinstance(module, str) or not isinstance(name, str) or module == "__main__" or "<" in name:
        return None
    return f"{module}:{name}"


def package_versions(packages: tuple[str, ...] = ("gymnasium", "numpy", "pymunk")) -> dict[str, str | None]:
    """Python's version, hippomaze's (the source's, not an editable install's stale metadata) and ``packages``' (None: not installed)."""
    from hippo_env import __version__

    versions: dict[str, str | None] = {"python": platform.python_version(), "hippomaze": __version__}
    for package in packages:
        try:
            versions[package] = importlib.metadata.version(package)
        except importlib.metadata.PackageNotFoundError:
            versions[package] = None
    return versions


def _check_make_kwargs(make_kwargs: dict[str, Any]) -> None:
    """Refuse, with the allowed names, arguments that ``gym.make("HippoMaze-v0", maze=...)`` cannot take."""
    allowed = [p for p in inspect.signature(HippoMazeEnv).parameters if p != "maze"] + ["max_episode_steps", "disable_env_checker"]
    if "maze" in make_kwargs:
        raise ValueError("env_kwargs may not hold 'maze': give the maze as run_dmtp's maze argument (hippomaze dmtp --maze)")
    unknown = sorted(set(make_kwargs) - set(allowed))
    if unknown:
        raise ValueError(f"HippoMaze-v0 takes no argument(s) {', '.join(map(str, unknown))}; allowed: {', '.join(allowed)}")


def dry_run_method(agent: Any) -> Callable[[gym.Env], None] | None:
    """The agent's dry run (its ``dry_run`` method), or None if it has none."""
    dry_run = getattr(agent, "dry_run", None)
    return dry_run if callable(dry_run) else None


def _check_agent(agent: Any) -> None:
    missing = missing_methods(agent)
    if missing:
        raise TypeError(
            f"{type(agent).__name__} does not follow the Agent protocol: it lacks {', '.join(missing)} (see hippo_env.agent_protocol)"
        )


def _progress(total: int, description: str, enabled: bool) -> Any:
    if not enabled:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=description, unit="run")


__all__ = ["DMTPFailed", "DMTPInterrupted", "DMTPResult", "RolloutEnd", "Run", "agent_config", "dry_run_method", "rollout", "run_dmtp"]
