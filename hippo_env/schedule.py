"""A schedule of DMTP phases: a world that changes while the goal stays, or moves, announced or not.

A :class:`Schedule` is a list of :class:`Phase` es, run in order by one agent (a fresh agent for
each of the schedule's ``repeats``, independent replicates). Each phase says in which maze its
runs happen, how many trials of how many runs it has, where the goal is (a new one per trial, the
one kept from the phase before, that of an earlier phase, or a point), whether the agent is
offered a dry run at its start and whether it is told (``start_trial``) when the goal moves::

    {"repeats": 2,
     "phases": [
       {"maze": "open", "trials": 1, "runs": 4},
       {"maze": {"base": "open", "change": "blocks", "seed": 1, "count": 12},
        "goal": "kept", "announce": false, "dry_run": false, "runs": 10, "max_steps": 300}
     ]}

Run one with ``run_dmtp(make_agent, schedule=...)`` (:mod:`hippo_env.dmtp`) or
``hippomaze dmtp --schedule FILE.json``. The goals and starts are drawn by the runner from its
seed, so every agent given the same seed faces the same ones.

This module also holds what the runner runs: :class:`TrialPlan`, one trial planned (its goal,
starts, maze, agent and dry run), made by :func:`plain_plans` for plain DMTP and by
:class:`SchedulePlanner` for a schedule, and :func:`schedule_summary`, a schedule result's summary.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from hippo_env.changes import CHANGES, change_maze
from hippo_env.env import GOAL_CLEARANCE, START_CLEARANCE
from hippo_env.maze import BUILTIN_MAZES, MazeSpec
from hippo_env.physics import ROBOT_RADIUS

__all__ = ["GOAL_MODES", "Phase", "Schedule", "SchedulePlanner", "TrialPlan", "plain_plans", "resolve_maze", "schedule_summary"]

#: The goal of a phase, besides ``{"phase": k}`` and ``[x, y]``.
GOAL_MODES = ("new", "kept")
PHASE_KEYS = ("name", "maze", "trials", "runs", "goal", "dry_run", "announce", "min_start_distance", "max_steps")
SCHEDULE_KEYS = ("phases", "repeats", "description")
CHANGE_KEYS = ("base", "change", "seed", "count", "side", "width")
MAZE_KEYS = ("name", "size", "obstacles", "goal")


# ------------------------------------------------------------------ the schedule
@dataclass(frozen=True)
class Phase:
    """One phase of a :class:`Schedule`. Every field as in the schedule's JSON.

    Args:
        maze: A built-in maze name, a path to a maze JSON file, a maze as a JSON object
            (``{"name", "size", "obstacles"}``) or a :class:`~hippo_env.maze.MazeSpec`, or a change of
            one: ``{"base": <maze>, "change": "blocks" | "door" | "barrier", "seed": int}`` with
            optionally ``count``, ``side``, ``width`` (see :func:`hippo_env.changes.change_maze`; the
            change keeps clear of the phase's goal when that is known beforehand, and a new goal is
            drawn in the changed maze). None: the previous phase's maze (the first phase must give one).
        trials: Trials (>= 1).
        runs: Runs per trial (>= 1).
        goal: ``"new"``: a new goal drawn for each trial; ``"kept"``: the goal of the previous
            phase's last trial, for every trial; ``{"phase": k}``: the last goal of the earlier
            phase ``k`` (a return to an earlier world with its goal); or a point ``[x, y]``.
        dry_run: Offer the agent its ``dry_run(env)`` at the phase's start. None: True for the first
            phase and for a phase whose ``maze`` differs from the previous phase's, else False.
        announce: Call the agent's ``start_trial(trial)`` when the goal moves at a trial's start.
        min_start_distance: Starts are drawn at least this far from the goal (m).
        max_steps: Steps per run before it is cut off (the agent sees ``truncated=True``, the run is
            recorded unsuccessful). None: the runner's limit.
        name: Shown in records, tables and figures. None: ``"phase k"``.
    """

    maze: Any = None
    trials: int = 1
    runs: int = 4
    goal: Any = "new"
    dry_run: bool | None = None
    announce: bool = True
    min_start_distance: float = 1.0
    max_steps: int | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        if self.maze is not None:
            set_(self, "maze", _check_maze(self.maze, "'maze'"))
        set_(self, "trials", _int(self.trials, "trials", 1))
        set_(self, "runs", _int(self.runs, "runs", 1))
        set_(self, "goal", _check_goal(self.goal))
        for key in ("dry_run", "announce"):
            value = getattr(self, key)
            if not (isinstance(value, bool) or (key == "dry_run" and value is None)):
                raise ValueError(f"'{key}' must be true or false, got {value!r}")
        distance = self.min_start_distance
        if isinstance(distance, bool) or not isinstance(distance, (int, float)) or not math.isfinite(distance) or distance < 0:
            raise ValueError(f"'min_start_distance' must be a finite number of metres >= 0, got {distance!r}")
        set_(self, "min_start_distance", float(distance))
        if self.max_steps is not None:
            set_(self, "max_steps", _int(self.max_steps, "max_steps", 1))
        if self.name is not None and (not isinstance(self.name, str) or not self.name):
            raise ValueError(f"'name' must be a non-empty string, got {self.name!r}")

    @classmethod
    def from_dict(cls, data: Any) -> Phase:
        """A phase from its JSON object (the keys of :data:`PHASE_KEYS`)."""
        if not isinstance(data, Mapping):
            raise ValueError(f"must be a JSON object with keys among {', '.join(PHASE_KEYS)}, got {data!r}")  # noqa: TRY004 (a document's content)
        unknown = sorted(set(data) - set(PHASE_KEYS))
        if unknown:
            raise ValueError(f"unknown key(s) {', '.join(map(repr, unknown))}; allowed: {', '.join(PHASE_KEYS)}")
        return cls(**dict(data))

    def to_dict(self) -> dict[str, Any]:
        """The phase as JSON (a maze given as a spec is written out in full)."""
        data = {key: getattr(self, key) for key in PHASE_KEYS}
        data["maze"] = _maze_json(self.maze)
        data["goal"] = list(self.goal) if isinstance(self.goal, tuple) else json.loads(json.dumps(self.goal))
        return {key: value for key, value in data.items() if value is not None}


@dataclass(frozen=True)
class Schedule:
    """Phases run in order by one agent; the whole schedule ``repeats`` times, a fresh agent each time.

    Built from a list of :class:`Phase` (or their JSON objects), it fills in what each phase left
    to its default (``maze``: the previous phase's; ``dry_run``; ``name``: ``"phase k"``), so that
    :meth:`to_dict` says exactly what is run. Anything wrong is a ``ValueError`` naming the phase
    (counted from 0), the field and what is allowed.

    Args:
        phases: The phases, at least one.
        repeats: Independent replicates of the whole schedule (>= 1), each with a fresh agent and
            its own goals and starts.
        description: Free text, kept in the record.
        base_dir: Where relative maze paths are looked for first (the schedule file's folder, when
            loaded from one); then the working directory.
    """

    phases: tuple[Phase, ...]
    repeats: int = 1
    description: str | None = None
    base_dir: Path | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        if isinstance(self.phases, (str, bytes, Mapping)) or not hasattr(self.phases, "__iter__"):
            raise ValueError(f"schedule 'phases' must be a list of phases, got {self.phases!r}")
        phases: list[Phase] = []
        for index, given in enumerate(self.phases):
            try:
                phase = given if isinstance(given, Phase) else Phase.from_dict(given)
                phases.append(self._complete(phase, index, phases))
            except (ValueError, TypeError) as err:
                raise ValueError(f"schedule phase {index}: {err}") from None
        if not phases:
            raise ValueError("schedule 'phases' must hold at least one phase")
        object.__setattr__(self, "phases", tuple(phases))
        try:
            object.__setattr__(self, "repeats", _int(self.repeats, "repeats", 1))
        except ValueError as err:
            raise ValueError(f"schedule: {err}") from None
        if self.description is not None and not isinstance(self.description, str):
            raise ValueError(f"schedule 'description' must be a string, got {self.description!r}")

    def _complete(self, phase: Phase, index: int, before: list[Phase]) -> Phase:
        """``phase`` with its defaults filled in and checked against the phases ``before`` it."""
        previous = before[-1] if before else None
        if phase.maze is None and previous is None:
            raise ValueError("'maze' is missing; the first phase must name its maze (later ones default to the previous phase's)")
        maze = previous.maze if phase.maze is None and previous is not None else phase.maze
        _check_sources(maze, self.base_dir)
        goal = phase.goal
        if goal == "kept" and previous is None:
            raise ValueError("'goal' is 'kept', but the first phase has no previous phase to keep a goal from; give 'new' or [x, y]")
        if isinstance(goal, dict) and goal["phase"] >= index:
            earlier = f"0 to {index - 1}" if index else "and the first phase has none; give 'new' or [x, y]"
            raise ValueError(f"'goal' {{'phase': {goal['phase']}}} must name an earlier phase, {earlier}")
        dry_run = phase.dry_run
        if dry_run is None:
            dry_run = previous is None or _maze_json(maze) != _maze_json(previous.maze)
        return dataclasses.replace(phase, maze=maze, dry_run=dry_run, name=phase.name or f"phase {index}")

    @classmethod
    def load(cls, source: Schedule | str | Path | Mapping[str, Any]) -> Schedule:
        """A schedule from a JSON file, its JSON object, or itself. Relative maze paths in a file
        are looked for beside it first."""
        if isinstance(source, Schedule):
            return source
        base_dir = None
        if isinstance(source, (str, Path)):
            path = Path(source)
            try:
                text = path.read_text()
            except OSError as err:
                raise ValueError(f"schedule file {str(path)!r} cannot be read ({err.strerror or err}); give a JSON file") from err
            try:
                source = json.loads(text)
            except json.JSONDecodeError as err:
                raise ValueError(f"schedule file {str(path)!r} is not valid JSON: {err}") from err
            base_dir = path.resolve().parent
        if not isinstance(source, Mapping):
            raise ValueError(f"a schedule must be a JSON object {{'phases': [...], 'repeats': R}}, got {type(source).__name__}")  # noqa: TRY004
        unknown = sorted(set(source) - set(SCHEDULE_KEYS))
        if unknown:
            raise ValueError(f"schedule: unknown key(s) {', '.join(map(repr, unknown))}; allowed: {', '.join(SCHEDULE_KEYS)}")
        if "phases" not in source:
            raise ValueError("schedule: missing key 'phases' (a list of phases)")
        return cls(source["phases"], source.get("repeats", 1), source.get("description"), base_dir)

    def to_dict(self) -> dict[str, Any]:
        """The schedule as JSON, every default filled in: what was run."""
        data: dict[str, Any] = {"phases": [p.to_dict() for p in self.phases], "repeats": self.repeats}
        if self.description is not None:
            data["description"] = self.description
        return data

    @property
    def total_runs(self) -> int:
        """Runs in the whole schedule, every repeat included."""
        return self.repeats * sum(p.trials * p.runs for p in self.phases)

    @property
    def total_trials(self) -> int:
        """Trials in the whole schedule, every repeat included."""
        return self.repeats * sum(p.trials for p in self.phases)


def _int(value: Any, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"'{name}' must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _check_goal(goal: Any) -> Any:
    """A phase's goal, normalised: ``"new"``, ``"kept"``, ``{"phase": k}`` or a point ``(x, y)``."""
    allowed = "'new', 'kept', {\"phase\": k} (an earlier phase's last goal) or a point [x, y] in metres"
    if isinstance(goal, str):
        if goal not in GOAL_MODES:
            raise ValueError(f"'goal' {goal!r} is unknown; allowed: {allowed}")
        return goal
    if isinstance(goal, Mapping):
        k = goal.get("phase")
        if set(goal) != {"phase"} or isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 0:
            raise ValueError(f"'goal' {dict(goal)!r} is not allowed; give {{\"phase\": k}} with k an earlier phase's index, or {allowed}")
        return {"phase": int(k)}
    numbers = isinstance(goal, (list, tuple, np.ndarray)) and len(goal) == 2
    if numbers and all(isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) and math.isfinite(v) for v in goal):
        return (float(goal[0]), float(goal[1]))
    raise ValueError(f"'goal' {goal!r} is not allowed; give {allowed}")


def _check_maze(maze: Any, where: str) -> Any:
    """A maze source, checked for form: a name or path (as a string), a maze object, a change, or a spec."""
    if isinstance(maze, MazeSpec):
        return maze
    if isinstance(maze, Path):
        return str(maze)
    if isinstance(maze, str) and maze:
        return maze
    if isinstance(maze, Mapping) and "base" in maze:
        unknown = sorted(set(maze) - set(CHANGE_KEYS))
        if unknown:
            raise ValueError(f"{where}: a change has unknown key(s) {', '.join(map(repr, unknown))}; allowed: {', '.join(CHANGE_KEYS)}")
        if maze.get("change") not in CHANGES:
            raise ValueError(f"{where}: 'change' must be one of {', '.join(CHANGES)}, got {maze.get('change')!r}")
        change = dict(maze)
        change["base"] = _check_maze(maze["base"], f"{where} 'base'")
        change["seed"] = _int(maze.get("seed"), "seed", 0)
        if "count" in maze:
            change["count"] = _int(maze["count"], "count", 1)
        for key in ("side", "width"):
            value = maze.get(key, 1.0)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise ValueError(f"{where}: '{key}' must be a number of metres > 0, got {value!r}")
        return change
    if isinstance(maze, Mapping) and "size" in maze:
        return MazeSpec.from_dict(dict(maze), source=f"{where} (a maze object)")
    raise ValueError(
        f"{where} must be a built-in maze ({', '.join(BUILTIN_MAZES)}), a path to a maze JSON file, a maze object "
        f"{{'name', 'size', 'obstacles'}}, or a change {{'base': <maze>, 'change': {' | '.join(CHANGES)}, 'seed': int}}; got {maze!r}"
    )


def _check_sources(maze: Any, base_dir: Path | None) -> None:
    """Load every maze named by path or name in ``maze`` now: a missing file is an error before any run."""
    if isinstance(maze, str):
        MazeSpec.load(_locate(maze, base_dir))
    elif isinstance(maze, dict):
        _check_sources(maze["base"], base_dir)


def _locate(maze: str, base_dir: Path | None) -> str | Path:
    """A built-in name as is; a relative path beside the schedule file if it is there, else as given."""
    if maze in BUILTIN_MAZES or base_dir is None or Path(maze).is_absolute():
        return maze
    beside = base_dir / maze
    return beside if beside.exists() else maze


def _maze_json(maze: Any) -> Any:
    """A maze source as JSON (a spec written out)."""
    if isinstance(maze, MazeSpec):
        return maze.to_dict()
    if isinstance(maze, dict):
        return {**maze, "base": _maze_json(maze["base"])}
    return maze


def resolve_maze(maze: Any, keep_clear: list[np.ndarray] | tuple = (), base_dir: Path | None = None) -> MazeSpec:
    """The :class:`~hippo_env.maze.MazeSpec` a phase's maze source stands for; a change is drawn
    from its seed, keeping clear of the points in ``keep_clear``."""
    if isinstance(maze, MazeSpec):
        return maze
    if isinstance(maze, Mapping) and "base" in maze:
        base = resolve_maze(maze["base"], keep_clear, base_dir)
        extra = {key: maze[key] for key in ("count", "side", "width") if key in maze}
        return change_maze(base, maze["change"], maze["seed"], keep_clear=[tuple(p) for p in keep_clear], **extra)
    return MazeSpec.load(_locate(maze, base_dir))


# ------------------------------------------------------------------ what the runner runs
@dataclass
class TrialPlan:
    """One trial as the runner will run it (:class:`hippo_env.dmtp._Experiment`).

    ``trial`` is its row in the result's tables (counted over the whole experiment);
    ``life_trial`` what ``start_trial`` is told (counted over the agent's life). ``agent_seed``:
    build a new agent with it first (None: keep the agent). ``maze``: the layout from this trial's
    first reset on (None, or the env's current one: no change). ``dry_run``: offer the agent its
    dry run. ``announce``: call ``start_trial``. ``max_steps``: cut each run there (None: the
    env's limit). ``new_phase``: open a new entry of ``dry_run_steps`` (every plain trial does; a
    schedule's phase on its first trial), and ``record`` (the phase's record) with it.
    """

    trial: int
    life_trial: int
    goal: np.ndarray
    starts: list[np.ndarray]
    agent_seed: int | None = None
    maze: MazeSpec | None = None
    dry_run: bool = False
    announce: bool = True
    max_steps: int | None = None
    new_phase: bool = True
    record: dict[str, Any] | None = None
    phase: int = 0
    repeat: int = 0
    label: str = ""


def _starts(
    spec: MazeSpec, rng: np.random.Generator, goal: np.ndarray, runs: int, min_distance: float, same_start: bool
) -> list[np.ndarray]:
    starts = [spec.sample_free(rng, START_CLEARANCE, away_from=goal, min_distance=min_distance) for _ in range(runs)]
    return [starts[0]] * runs if same_start else starts


def plain_plans(spec: MazeSpec, trials: int, runs: int, seed: int, same_start: bool, fresh_agent_per_trial: bool) -> list[TrialPlan]:
    """Plain DMTP: ``trials`` trials, each with a new goal (announced), of ``runs`` runs; a new
    agent (and its dry run) for each trial, or only the first. Every agent given the same seed
    faces the same goals and starts."""
    rng = np.random.default_rng(seed)
    agent_seeds = np.random.SeedSequence(seed).generate_state(trials)
    plans = []
    for trial in range(trials):
        goal = spec.sample_free(rng, GOAL_CLEARANCE)
        starts = _starts(spec, rng, goal, runs, 1.0, same_start)
        fresh = trial == 0 or fresh_agent_per_trial
        seed_ = int(agent_seeds[trial]) if fresh else None
        plans.append(TrialPlan(trial, trial, goal, starts, agent_seed=seed_, dry_run=fresh, label=f"trial {trial + 1}"))
    return plans


class SchedulePlanner:
    """The trials of a :class:`Schedule`, repeat after repeat, drawn from ``seed``.

    One generator draws every repeat's goals and starts in turn (a repeat's first, so the first
    repeat is planned, and its errors raised, before anything runs); a repeat's agent is seeded
    with ``SeedSequence(seed).generate_state(repeats)[repeat]``. A changed maze is drawn once per
    goal it keeps clear of.
    """

    @classmethod
    def instead_of(cls, schedule: Schedule | str | Path | Mapping[str, Any], seed: int, same_start: bool, **plain: Any) -> SchedulePlanner:
        """The planner for ``schedule``; a ``ValueError`` if any of ``plain`` (``maze``, ``trials``,
        ``runs``: plain DMTP's arguments, which a schedule's phases replace) is given too."""
        given = [name for name, value in plain.items() if value is not None]
        if given:
            raise ValueError(
                f"give either a schedule or {', '.join(given)}, not both: each phase of a schedule names its maze, trials and runs"
            )
        return cls(Schedule.load(schedule), seed, same_start)

    def __init__(self, schedule: Schedule, seed: int, same_start: bool = False) -> None:
        self.schedule = schedule
        self.same_start = same_start
        self.rng = np.random.default_rng(seed)
        self.agent_seeds = np.random.SeedSequence(seed).generate_state(schedule.repeats)
        self._mazes: dict[str, MazeSpec] = {}
        self._trial = 0
        self.first = self.plan_repeat(0)

    @property
    def first_maze(self) -> MazeSpec:
        """The maze the experiment starts in."""
        maze = self.first[0].maze
        assert maze is not None
        return maze

    def step_limits(self, given: int | None, registered: int) -> tuple[int, int | None]:
        """``(run_limit, make_limit)``: the steps a run of a phase without ``max_steps`` may take
        (the runner's ``given`` limit, else the ``registered`` one), and the ``max_episode_steps``
        to make the environment with, so that its time limit cuts no phase's run first."""
        default = given or registered
        longest = max(default, *(p.max_steps or 0 for p in self.schedule.phases))
        return default, (longest if longest > default else given)

    def __iter__(self) -> Iterator[TrialPlan]:
        yield from self.first
        for repeat in range(1, self.schedule.repeats):
            yield from self.plan_repeat(repeat)

    def plan_repeat(self, repeat: int) -> list[TrialPlan]:
        """Every trial of one repeat, its goals and starts drawn."""
        plans: list[TrialPlan] = []
        last_goals: list[np.ndarray] = []
        for index, phase in enumerate(self.schedule.phases):
            where = f"schedule phase {index} ({phase.name!r})"
            fixed = self._fixed_goal(phase.goal, last_goals)
            maze = self._maze(phase.maze, fixed, where)
            if fixed is not None:
                _check_goal_fits(maze, fixed, phase.goal, index, where)
            goals: list[list[float]] = []
            record: dict[str, Any] = {
                "repeat": repeat,
                "phase": index,
                "name": phase.name,
                "maze": maze.name,
                "dry_run": bool(phase.dry_run),
                "dry_run_steps": 0,
                "goals": goals,
            }
            for t in range(phase.trials):
                try:
                    goal = fixed if fixed is not None else maze.sample_free(self.rng, GOAL_CLEARANCE)
                    starts = _starts(maze, self.rng, goal, phase.runs, phase.min_start_distance, self.same_start)
                except ValueError as err:
                    raise ValueError(f"{where}: {err}") from None
                moved = not plans or not np.array_equal(goal, plans[-1].goal)
                label = f"repeat {repeat + 1}, {phase.name}, trial {t + 1}" if self.schedule.repeats > 1 else f"{phase.name}, trial {t + 1}"
                plans.append(
                    TrialPlan(
                        trial=self._trial,
                        life_trial=len(plans),
                        goal=goal,
                        starts=starts,
                        agent_seed=int(self.agent_seeds[repeat]) if not plans else None,
                        maze=maze if t == 0 else None,
                        dry_run=bool(phase.dry_run) and t == 0,
                        announce=phase.announce and moved,
                        max_steps=phase.max_steps,
                        new_phase=t == 0,
                        record=record if t == 0 else None,
                        phase=index,
                        repeat=repeat,
                        label=label,
                    )
                )
                goals.append([float(v) for v in goal])
                self._trial += 1
            last_goals.append(plans[-1].goal)
        return plans

    @staticmethod
    def _fixed_goal(goal: Any, last_goals: list[np.ndarray]) -> np.ndarray | None:
        """The goal a phase holds for all its trials (None for ``"new"``)."""
        if goal == "new":
            return None
        if goal == "kept":
            return last_goals[-1]
        if isinstance(goal, dict):
            return last_goals[goal["phase"]]
        return np.array(goal, dtype=np.float64)

    def _maze(self, source: Any, goal: np.ndarray | None, where: str) -> MazeSpec:
        """The phase's maze (a change kept clear of ``goal``), drawn once per source and goal."""
        key = json.dumps([_maze_json(source), None if goal is None else [float(v) for v in goal]], default=repr)
        if key not in self._mazes:
            try:
                self._mazes[key] = resolve_maze(source, [] if goal is None else [goal], self.schedule.base_dir)
            except ValueError as err:
                raise ValueError(f"{where}: 'maze': {err}") from None
        return self._mazes[key]


def _check_goal_fits(maze: MazeSpec, goal: np.ndarray, mode: Any, index: int, where: str) -> None:
    if maze.clearance(goal) >= ROBOT_RADIUS:
        return
    what = {"kept": "the goal kept from the previous phase"}.get(
        mode, f"the goal of phase {mode['phase']}" if isinstance(mode, dict) else "the goal"
    )
    raise ValueError(
        f"{where}: {what} ({goal[0]:g}, {goal[1]:g}) lies inside a wall of maze {maze.name!r}, or within the robot's radius "
        f"({ROBOT_RADIUS} m) of one; give this phase 'goal': 'new' or a free point [x, y], or a maze that leaves the goal free"
    )


# ------------------------------------------------------------------ the summary
def schedule_summary(result: Any) -> dict[str, Any]:
    """Per phase (over every repeat): runs recorded, success rate, median indirectness of the
    successful runs, the same by run of the phase, and for a phase whose goal is not new, the
    success rate of its first run (the goal remembered, or found again, in the phase's world)."""
    phases = result.schedule["phases"]
    summary: dict[str, Any] = {"repeats": result.schedule["repeats"], "runs": len(result.run_records), "phases": []}
    for index, phase in enumerate(phases):
        records = [r for r in result.run_records if r.phase == index]
        entry: dict[str, Any] = {
            "phase": index,
            "name": phase["name"],
            "mazes": sorted({p["maze"] for p in result.phases if p["phase"] == index}),
            "goal": phase["goal"],
            "runs": len(records),
            "success_rate": _mean([r.success for r in records]),
            "median_indirectness_of_successes": _median([r.indirectness for r in records if r.success]),
        }
        if phase["goal"] != "new":
            firsts: dict[int, Any] = {}  # per repeat, the phase's first run
            for r in records:
                if r.run == 0 and (r.repeat not in firsts or r.trial < firsts[r.repeat].trial):
                    firsts[r.repeat] = r
            entry["first_run_success_rate"] = _mean([r.success for r in firsts.values()])
            entry["first_run_median_indirectness"] = _median([r.indirectness for r in firsts.values()])
        by_run = [[r for r in records if r.run == k] for k in range(phase["runs"])]
        entry["success_rate_by_run"] = [_mean([r.success for r in rs]) for rs in by_run]
        entry["median_indirectness_by_run"] = [_median([r.indirectness for r in rs]) for rs in by_run]
        summary["phases"].append(entry)
    return summary


def _mean(values: list[bool]) -> float | None:
    return float(np.mean(values)) if values else None


def _median(values: list[float]) -> float | None:
    finite = [v for v in values if math.isfinite(v)]
    return float(np.median(finite)) if finite else None
