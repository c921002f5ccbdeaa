"""A world that changes, for any agent: the tasks, the runner and the measures.

Each task is a DMTP schedule (:mod:`hippo_env.schedule`) run by :func:`hippo_env.dmtp.run_dmtp`;
the agent is never told the world changed:

- ``barriers``: the goal learned in the open 10 m arena (a dry run, one trial of 4 runs), then
  four layouts of 8, 11, 14 and 18 blocks of 1 m (:mod:`hippo_env.changes`, drawn from the seed),
  10 runs each from starts at least 3 m from the goal, cut at 300 steps (45 m of driving);
- ``mazes``: the goal learned in a maze, then the same maze with blocks added, with a path closed
  (a detour) and with a door cut (a shortcut), 10 runs each, cut at 300 steps per 10 m of side;
- ``worlds``: maze1, maze3, maze2 (each with a dry run and a new goal), back to maze1 with its
  goal kept, unannounced and with no dry run, then a new goal in maze1 (announced, no dry run).

The measures: success on the first run in each new layout and over all its runs, the median
indirectness of the successes, the share of run steps whose position estimate lies within 0.5 m
of the truth (agents with a path integrator ``pi``, as ``HippocampalAgent``; the harness reads the
true position, the agent never does), the shortcut taken, and the return to a known world.
``python -m benchmarks.changing_world`` writes them for the project's agents;
``hippomaze bench --changing-world`` for yours, beside those.
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

from hippo_env.changes import change_maze
from hippo_env.dmtp import DMTPFailed, run_dmtp
from hippo_env.generate import generate_maze
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS
from hippo_env.schedule import Schedule
from hippomaze.registry import agent_factory
from hippomaze.stats import median_or_none

__all__ = ["MAZES", "TASKS", "WORLDS_SCHEDULE", "Watched", "barriers_schedule", "maze_schedule", "run_task", "summarise"]

TASKS = ("barriers", "mazes", "worlds")
BLOCK_COUNTS = (8, 11, 14, 18)
MAZES = ("maze1", "maze2", "maze3", "maze4", "gen-rooms-130-15m", "gen-perfect-131", "gen-corridors-132", "gen-arena-133-20m")
MAZE_CHANGES = ("blocks", "barrier", "door")
RUNS_PER_LAYOUT = 10
POSITION_TOLERANCE = 0.5  # m
SHORTCUT_GAIN = 0.3  # the door shortens the way by at least this share
GOAL_RADIUS = 0.3  # m: HippoMaze-v0's default goal_radius


# ------------------------------------------------------------------ the schedules
def maze_spec(name: str) -> MazeSpec:
    """A built-in maze, or a generated one by its suite name ``gen-<kind>-<seed>[-<size>m]``."""
    if name.startswith("gen-"):
        parts = name.split("-")
        size = float(parts[3][:-1]) if len(parts) > 3 else 10.0
        return generate_maze(int(parts[2]), parts[1], size, name=name)
    return MazeSpec.load(name)


def barriers_schedule(seed: int) -> dict[str, Any]:
    """The ``barriers`` task's schedule for runner seed ``seed``."""
    layouts = [
        _kept_goal(f"{count} blocks", {"base": "open", "change": "blocks", "seed": 1000 * seed + k, "count": count, "side": 1.0}, 300)
        for k, count in enumerate(BLOCK_COUNTS)
    ]
    return {"phases": [{"name": "learn", "maze": "open", "runs": 4, "goal": "new", "dry_run": True}, *layouts]}


def maze_schedule(name: str, seed: int) -> dict[str, Any]:
    """The ``mazes`` task's schedule in maze ``name`` for runner seed ``seed``."""
    spec = maze_spec(name)
    base = spec.to_dict()
    cut = int(300 * max(1.0, spec.size[0] / 10.0))
    changes = []
    for k, change in enumerate(MAZE_CHANGES):
        extra: dict[str, Any] = {"count": 6} if change == "blocks" else {}
        try:
            change_maze(spec, change, 1000 * seed + k, count=extra.get("count", 12))
        except ValueError:
            continue  # no such change in this maze (no wall to cut a door in, no gap to close)
        changes.append(_kept_goal(change, {"base": base, "change": change, "seed": 1000 * seed + k, **extra}, cut))
    return {"phases": [{"name": "learn", "maze": base, "runs": 4, "goal": "new", "dry_run": True}, *changes]}


def _kept_goal(name: str, maze: dict[str, Any], max_steps: int) -> dict[str, Any]:
    """A phase of a changed layout: the goal kept, unannounced, no dry run, starts >= 3 m from the goal."""
    return {
        "name": name, "maze": maze, "runs": RUNS_PER_LAYOUT, "goal": "kept", "announce": False, "dry_run": False,
        "min_start_distance": 3.0, "max_steps": max_steps,
    }  # fmt: skip


WORLDS_SCHEDULE: dict[str, Any] = {
    "phases": [
        {"name": "maze1", "maze": "maze1", "runs": 4, "goal": "new", "dry_run": True},
        {"name": "maze3", "maze": "maze3", "runs": 4, "goal": "new", "dry_run": True},
        {"name": "maze2", "maze": "maze2", "runs": 4, "goal": "new", "dry_run": True},
        {"name": "maze1 again", "maze": "maze1", "runs": 4, "goal": {"phase": 0}, "announce": False, "dry_run": False},
        {"name": "maze1 new goal", "runs": 4, "goal": "new", "announce": True, "dry_run": False},
    ]
}


# ------------------------------------------------------------------ watching the estimate
class _FirstReset:
    """Passes an env through, telling ``on_reset`` the info of every reset."""

    def __init__(self, env: Any, on_reset: Any) -> None:
        self.env, self.on_reset = env, on_reset

    def reset(self, **kwargs: Any) -> Any:
        obs, info = self.env.reset(**kwargs)
        self.on_reset(info)
        return obs, info

    def __getattr__(self, name: str) -> Any:
        return getattr(self.env, name)


class Watched:
    """An agent passed through, with each run step's position error (PRIVILEGED, read from the
    env's ``info["position"]``; the frame's origin is where the agent's first dry run began)."""

    def __init__(self, agent: Any, forget_at: frozenset[int] = frozenset()) -> None:
        self.agent = agent
        self.origin: np.ndarray | None = None
        self.runs: list[dict[str, int]] = []  # per run: steps, anchored steps, those within tolerance, those off the map
        self.forget_at = forget_at  # PRIVILEGED: runs (0-based) before which the map forgets the walls runs wrote

    def dry_run(self, env: Any) -> None:
        def first(info: dict[str, Any]) -> None:
            if self.origin is None:
                self.origin = np.asarray(info["position"], dtype=np.float64)

        dry_run = getattr(self.agent, "dry_run", None)
        if callable(dry_run):  # (an agent without a dry run is offered none)
            dry_run(_FirstReset(env, first))

    def start_trial(self, trial: int) -> None:
        start_trial = getattr(self.agent, "start_trial", None)
        if callable(start_trial):
            start_trial(trial)

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        map_ = getattr(self.agent, "map", None)
        if map_ is not None and len(self.runs) in self.forget_at:
            map_.forget_new_walls()
        estimates = getattr(self.agent, "pi", None) is not None  # (an agent with no estimate has no position figures)
        self.runs.append({"steps": 0, **({"anchored": 0, "placed": 0, "off_map": 0} if estimates else {})})
        self.agent.reset(observation, info)

    def act(self, observation: Any) -> Any:
        return self.agent.act(observation)

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        self.agent.observe(action, observation, reward, terminated, truncated, info)
        pi, run = getattr(self.agent, "pi", None), self.runs[-1]
        run["steps"] += 1
        if pi is None or self.origin is None or not pi.anchored:
            return
        truth = np.asarray(info["position"], dtype=np.float64) - self.origin
        run["anchored"] += 1
        run["placed"] += int(math.dist(pi.estimate, truth) <= POSITION_TOLERANCE)
        map_ = getattr(self.agent, "map", None)
        run["off_map"] += int(map_ is not None and not map_.known_ground(pi.estimate))


# ------------------------------------------------------------------ one job
def run_task(
    agent: str,
    seed: int,
    task: str,
    maze: str = "",
    overrides: dict[str, Any] | None = None,
    forget_new_walls: bool = False,
    env_kwargs: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """One schedule run for one agent and seed: its run records and the position figures.
    ``forget_new_walls`` (PRIVILEGED, a diagnosis only: the agent is not told the layout changed):
    the agent's map forgets the walls its runs wrote whenever a new layout begins, so that no block
    of an earlier layout lingers in it. ``env_kwargs``: more arguments for ``gym.make`` (e.g. another
    ``action_type``), over the agent's own."""
    began = time.process_time()
    schedules = {"barriers": lambda: barriers_schedule(seed), "worlds": lambda: WORLDS_SCHEDULE, "mazes": lambda: maze_schedule(maze, seed)}
    schedule = schedules[task]()
    factory = agent_factory(agent, **(overrides or {}))
    watchers: list[Watched] = []
    forget_at: frozenset[int] = frozenset()
    if forget_new_walls:  # (before the first run of each phase after the first)
        runs_per_phase = [phase.trials * phase.runs for phase in Schedule(schedule["phases"]).phases]
        forget_at = frozenset(np.cumsum(runs_per_phase)[:-1].tolist())

    def make(observation_space: Any, action_space: Any, *, seed: int) -> Watched:
        watchers.append(Watched(factory(observation_space, action_space, seed=seed), forget_at))
        return watchers[-1]

    make.env_kwargs = getattr(factory, "env_kwargs", {})  # type: ignore[attr-defined]

    error = None
    try:
        result = run_dmtp(make, schedule=schedule, seed=seed, agent_name=agent, progress=False, env_kwargs=env_kwargs)
    except DMTPFailed as failed:  # (a change that cannot keep clear of the goal drawn, say): the runs so far
        result, error = failed.result, str(failed)
    runs = [dataclasses.asdict(r) for r in result.run_records]
    watched = watchers[0].runs if watchers else []
    for record, counts in zip(runs, watched):
        record.update(counts)
    if task == "mazes":
        add_old_geodesic(runs, result)
    names = [p["name"] for p in (result.schedule or {}).get("phases", [])]
    return {
        "agent": agent,
        "seed": seed,
        "task": task,
        "maze": maze,
        "phases": names,
        "runs": runs,
        "error": error,
        "cpu_seconds": time.process_time() - began,
    }


def add_old_geodesic(runs: list[dict[str, Any]], result: Any) -> None:
    """Each run's shortest way in the maze before its change (the learn phase's maze): a door
    layout's run took a shortcut only if the door shortened the way."""
    before = result.phase_mazes[0]
    goal_radius = float(result.env_kwargs.get("goal_radius", GOAL_RADIUS))
    for r in runs:  # (as the environment measures the shortest way: to the goal disk's edge)
        length = before.geodesic(np.asarray(r["start"]), np.asarray(r["goal"]), ROBOT_RADIUS)
        r["shortest_before_change"] = max(float(length) - goal_radius, 0.0)


# ------------------------------------------------------------------ the measures
def changed_runs(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The runs of every phase after the first (the layouts the goal was kept through)."""
    return [r for row in rows for r in row["runs"] if r["phase"] > 0]


def layout_measures(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Success on the first run in each new layout and on all its runs, the successes' median
    indirectness, and the position figures, over ``rows``' changed layouts."""
    runs = changed_runs(rows)
    firsts = [r for r in runs if r["run"] == 0]
    steps = sum(r.get("steps", 0) for r in runs if "anchored" in r)
    anchored = sum(r.get("anchored", 0) for r in runs)
    placed = sum(r.get("placed", 0) for r in runs)
    return {
        "layouts": len(firsts),
        "runs": len(runs),
        "first_run_success": _share([r["success"] for r in firsts]),
        "success": _share([r["success"] for r in runs]),
        "median_indirectness_of_successes": median_or_none(r["indirectness"] for r in runs if r["success"]),
        "anchored_share": anchored / steps if steps else None,
        "position_within_0_5m": placed / anchored if anchored else None,
        "anchored_off_map_steps": sum(r["off_map"] for r in runs if "off_map" in r) if steps else None,
    }


def by_layout(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """:func:`layout_measures` of each changed layout apart, by its phase's name (``"18 blocks"``,
    ``"door"``), in the order they first come."""
    names = dict.fromkeys(row["phases"][r["phase"]] for row in rows for r in row["runs"] if r["phase"] > 0)
    return {
        name: layout_measures(
            [{**row, "runs": [r for r in row["runs"] if r["phase"] > 0 and row["phases"][r["phase"]] == name]} for row in rows]
        )
        for name in names
    }


def shortcut_measures(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Door layouts: of the runs after the first whose door shortened the way by at least 30 %,
    the share at most 0.5 indirect against the new geodesic (a failed run counts as not taken)."""
    taken = []
    for row in rows:
        door = row["phases"].index("door") if "door" in row["phases"] else -1
        for r in row["runs"]:
            if r["phase"] == door and r["run"] > 0 and r["shortest_path_length"] <= (1 - SHORTCUT_GAIN) * r["shortest_before_change"]:
                taken.append(bool(r["success"]) and r["indirectness"] <= 0.5)
    return {"runs": len(taken), "taken": _share(taken)}


def worlds_measures(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Run 1 back in the first world (median indirectness, a failed run counted as infinite), and a
    new goal there: runs 2-4's median against the first visit's."""

    def indirectness(r: dict[str, Any]) -> float:
        return r["indirectness"] if r["success"] else math.inf

    def runs_of(phase: int, later: bool) -> list[float]:
        return [indirectness(r) for row in rows for r in row["runs"] if r["phase"] == phase and (r["run"] > 0) == later]

    back = runs_of(3, later=False)
    return {
        "returns": len(back),
        "run1_back_median": _median(back),
        "first_visit_runs_2_4_median": _median(runs_of(0, later=True)),
        "new_goal_back_runs_2_4_median": _median(runs_of(4, later=True)),
    }


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per agent: the measures of each task, over its seeds."""
    out: dict[str, Any] = {}
    for agent in dict.fromkeys(r["agent"] for r in rows):
        mine = [r for r in rows if r["agent"] == agent]
        entry: dict[str, Any] = {}
        barriers = [r for r in mine if r["task"] == "barriers"]
        mazes = [r for r in mine if r["task"] == "mazes"]
        worlds = [r for r in mine if r["task"] == "worlds"]
        if barriers:
            entry["barriers"] = layout_measures(barriers)
            entry["barriers_by_layout"] = by_layout(barriers)
        if mazes:
            entry["mazes"] = {
                "all": layout_measures(mazes),
                **{m: layout_measures([r for r in mazes if r["maze"] == m]) for m in dict.fromkeys(r["maze"] for r in mazes)},
            }
            entry["mazes_by_change"] = by_layout(mazes)
            entry["shortcut"] = shortcut_measures(mazes)
        if worlds:
            entry["worlds"] = worlds_measures(worlds)
        out[agent] = entry
    return out


def _share(values: list[bool]) -> float | None:
    return float(np.mean(values)) if values else None


def _median(values: list[float]) -> float | None:
    """The median (a miss counted as infinite); None if there are none or more than half missed (JSON has no infinity)."""
    if not values:
        return None
    median = float(np.median(values))
    return median if math.isfinite(median) else None
