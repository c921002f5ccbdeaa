"""How :mod:`benchmarks.agent_throughput` times the hippocampal agent and RatInABox.

The agent is trained in the open arena (a dry run, then runs from one start until a run finds a
fixed goal and replays), then timed on a recorded random walk of real observations, act +
observe, learning on: exploiting (it knows the goal, so it preplays or homes at every step) or
exploring (it searches as in a run 1). A dry run is timed with the environment's own time taken
out (:class:`TimedEnv`). :func:`measure` makes one row of the scaling table; with ``split`` it
also splits the time of a step and of a replay into its parts by timing the agent's methods.
"""

from __future__ import annotations

import contextlib
import copy
import json
import time
from collections.abc import Iterator
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from benchmarks.common import SplitTimer, peak_resident_megabytes, resident_megabytes
from hippo_agent import AgentConfig, HippocampalAgent
from hippo_env.dmtp import rollout

#: The models this benchmark builds (:func:`make_config`).
MODELS = ("default", "paper")
#: Runs from the same start to find the goal before a row gives up on timing an exploiting agent.
MAX_GOAL_RUNS = 5

# The parts of a step, as the agent's methods (attribute path from the agent, method) whose
# exclusive time each part is; what none of them covers (act/observe themselves, exploration,
# unpacking the observation) is "other".
AGENT_TERMS: dict[str, tuple[tuple[str, str], ...]] = {
    "bvc_hd_rates": (("bvc", "update"), ("hd", "update")),
    "place_settle": (
        ("place", "step"),
        ("place", "step_sense"),
        ("place", "step_driven"),
        ("place", "step_driven_by_centres"),
        ("place", "settle"),
        ("place", "settle_sense"),
        ("place", "reset_state"),
    ),
    "path_integration": (
        ("pi", "move"),
        ("pi", "move_by_odometry"),
        ("pi", "correct"),
        ("pi", "start_run"),
        ("pi", "lagged_estimate"),
        ("pi", "vote"),
        ("pi", "drive"),
        ("pi", "learn_centres"),
    ),
    "localisation": (("localisation", "check"), ("localisation", "count_bump")),
    "map_and_plans": (("map", "observe"), ("map", "wall_near"), ("homing", "plan"), ("exploration", "plan")),
    "learning": (("place", "learn"), ("place", "learn_pb"), ("place", "learn_pp"), ("place", "update_trace"), ("place", "update_hd_trace")),
    "preplay": (("place", "imagined_values"), ("reward", "value"), ("reward", "depress")),
}
# The parts of one replay (``HippocampalAgent.learn_reward``); the rest is "other".
REPLAY_TERMS: dict[str, tuple[tuple[str, str], ...]] = {"replay_weights": (("place", "replay_links"),)}


def make_config(model: str, n_place: int, dry_run_steps: int, overrides: dict[str, Any] | None = None) -> AgentConfig:
    """The one place this benchmark builds an :class:`AgentConfig`: ``model`` with ``n_place`` cells
    and, for the default model, ``overrides`` (AgentConfig fields by dotted name; the paper's model
    stays the paper's, the reference it is timed against)."""
    if model not in MODELS:
        raise ValueError(f"model {model!r} is unknown; allowed: {', '.join(MODELS)}")
    sizes = {"model.n_place": n_place, "model.dry_run_steps": dry_run_steps}
    if model == "paper":
        return AgentConfig.paper().with_values(sizes)
    # the cost of n_place cells: no recruitment beyond them; and homing that never gives up for want
    # of progress: the recorded walk does not follow the agent's heading, so it comes no nearer the
    # goal, and the stall check (one comparison a step) would end homing, and the exploiting, after
    # homing.stall_steps steps of it
    timing = {"exploration.place_cells_per_m2": 0.0, "homing.stall_steps": None}
    return AgentConfig().with_values({**sizes, **timing, **(overrides or {})})


class TimedEnv(gym.Wrapper):
    """Counts the steps taken through it and the seconds spent in the environment (steps and resets)."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.steps = 0
        self.seconds = 0.0

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        began = time.perf_counter()
        try:
            return self.env.reset(seed=seed, options=options)
        finally:
            self.seconds += time.perf_counter() - began

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        began = time.perf_counter()
        try:
            return self.env.step(action)
        finally:
            self.seconds += time.perf_counter() - began
            self.steps += 1


def new_agent(
    model: str, n_place: int, dry_run_steps: int, n_rays: int, seed: int, overrides: dict[str, Any] | None = None
) -> tuple[TimedEnv, HippocampalAgent]:
    """A fresh ``model`` agent (:func:`make_config`) and its environment (the open arena, reset with
    ``seed``), before its dry run."""
    env = TimedEnv(gym.make("HippoMaze-v0", maze="open", n_rays=n_rays, odometry=True))
    env.reset(seed=seed)
    config = make_config(model, n_place, dry_run_steps, overrides)
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=seed)
    return env, agent


def timed_dry_run(env: TimedEnv, agent: HippocampalAgent) -> tuple[int, float, float]:
    """The agent's dry run: its steps, the agent's own seconds (the environment's taken out), and
    of those the seconds of the rest at its end (imagined transits, no step taken; 0 without the
    faculty ``exploration``)."""
    steps, env_seconds = env.steps, env.seconds
    timer = SplitTimer()
    timer.wrap(agent.exploration, "rest", "rest")  # (absent without exploration: then 0)
    began = time.perf_counter()
    try:
        agent.dry_run(env)
    finally:
        total = time.perf_counter() - began
        timer.unwrap()
    return env.steps - steps, total - (env.seconds - env_seconds), timer.seconds.get("rest", 0.0)


def trained(
    model: str, n_place: int, dry_run_steps: int, n_rays: int, seed: int, overrides: dict[str, Any] | None = None
) -> tuple[TimedEnv, HippocampalAgent, dict[str, Any], Any]:
    """The ``model`` agent with ``n_place`` cells (:func:`make_config`) after its dry run and the
    runs that find the goal at the arena's centre (which replay), and its environment; the dry
    run's figures and the last run."""
    env, agent = new_agent(model, n_place, dry_run_steps, n_rays, seed, overrides)
    began = time.perf_counter()
    steps, agent_seconds, _ = timed_dry_run(env, agent)
    dry = {"steps": steps, "seconds": time.perf_counter() - began, "agent_seconds": agent_seconds}
    agent.start_trial(0)
    for goal_runs in range(1, MAX_GOAL_RUNS + 1):  # explore until the goal, which triggers the replay
        observation, info = env.reset(options={"goal": [0.0, 0.0]})
        agent.reset(observation, info)
        run = rollout(env, agent, observation)
        if agent.model.goal_rewarded:  # (a goal reached with no place cell active there teaches nothing: run again)
            break
    dry["goal_runs"] = goal_runs
    return env, agent, dry, run


def recorded_walk(env: gym.Env, steps: int, seed: int) -> list:
    """A random walk of ``steps`` steps with no goal, as (action, observation, info); closes ``env``."""
    walk = np.random.default_rng(seed).integers(0, 8, steps)
    recorded = []
    observation, info = env.reset(options={"goal": None})
    for action in walk.tolist():
        observation, _, _, _, info = env.step(action)
        recorded.append((action, observation, info))
    env.close()
    return recorded


@contextlib.contextmanager
def heading_for_the_goal(agent: HippocampalAgent, exploit: bool) -> Iterator[None]:
    """Exploiting: the agent knows the goal (its reward map, and in the default model the place
    where it found it), so it preplays or homes at every step. Exploring: it knows neither (the
    remembered place is hidden for the walk, or the default model would home), so it searches as
    in a run 1."""
    memory = np.zeros(0) if agent.homing is None else agent.homing.found_count
    found = memory.copy()
    agent.model.goal_rewarded = exploit
    if not exploit:
        memory[:] = 0.0
    try:
        yield
    finally:
        memory[:] = found


def walk(agent: HippocampalAgent, recorded: list) -> tuple[float, float]:
    """Wall and CPU seconds of act + observe over the recorded walk (after a reset, untimed)."""
    agent.reset(recorded[0][1], recorded[0][2])
    began, began_cpu = time.perf_counter(), time.process_time()
    for action, observation, info in recorded:
        agent.act(observation)
        agent.observe(action, observation, 0.0, False, False, info)
    return time.perf_counter() - began, time.process_time() - began_cpu


def measure(n_place: int, args: Any, split: bool = False) -> dict[str, Any]:
    """One row of the scaling table: the ``args.model`` agent with ``n_place`` place cells (:func:`trained`),
    timed on a recorded random walk exploiting and exploring (best of ``args.scaling_repeats``); one
    replay timed; its memory. With ``split``, one more (instrumented) pass of each walk splits the
    time of a step into :data:`AGENT_TERMS` (microseconds per step), and a replay into :data:`REPLAY_TERMS`."""
    resident_at_start = resident_megabytes()
    env, agent, dry, run = trained(args.model, n_place, args.dry_run_steps, args.n_rays, args.seed, overrides(args))
    before_timing = copy.deepcopy(agent.reward)  # replaying again adds to the reward weights: put them back after
    replay_from_cells = int(np.count_nonzero(agent.place.v > 0))  # replay spreads from the cells active at the goal
    replay_ms = []
    for _ in range(args.scaling_repeats):
        began = time.perf_counter()
        agent.learn_reward()
        replay_ms.append(1e3 * (time.perf_counter() - began))
    replay_split = _replay_split(agent) if split else None
    agent.model.reward = before_timing
    recorded = recorded_walk(env, args.steps, args.seed)
    row: dict[str, Any] = {"n_place": n_place, "n_bvc": agent.bvc.n}
    for mode, exploit in (("exploiting", True), ("exploring", False)):
        best_wall = best_cpu = 0.0
        with heading_for_the_goal(agent, exploit):
            for _ in range(args.scaling_repeats):
                wall, cpu = walk(agent, recorded)
                best_wall, best_cpu = max(best_wall, len(recorded) / wall), max(best_cpu, len(recorded) / max(cpu, 1e-9))
            row["exploit_decisions" if exploit else "explore_decisions"] = dict(agent.episode_stats)
            if split:
                row[f"{mode}_split_us_per_step"] = _split_walk(agent, recorded)
        row[f"{mode}_steps_per_second"] = round(best_wall)
        row[f"{mode}_steps_per_cpu_second"] = round(best_cpu)
    w_pp_bytes = sum(a.nbytes for a in vars(agent.place).values() if isinstance(a, np.ndarray) and a.ndim == 3)
    w_pb = getattr(agent.place, "W_pb", None)
    row |= {
        "replay_ms": round(min(replay_ms), 2),
        **({} if replay_split is None else {"replay_split_ms": replay_split}),
        "dry_run_steps": dry["steps"],
        "dry_run_steps_per_second": round(dry["steps"] / dry["seconds"]) if dry["steps"] else None,
        "dry_run_agent_steps_per_second": round(dry["steps"] / dry["agent_seconds"]) if dry["steps"] else None,
        "goal_runs": dry["goal_runs"],
        "goal_run_steps": run.steps,
        "found_goal": bool(run.terminated),
        "replay_from_cells": replay_from_cells,
        "W_pp_megabytes": round(w_pp_bytes / 2**20, 1),
        "W_pb_megabytes": None if w_pb is None else round(w_pb.nbytes / 2**20, 1),
        "max_rss_megabytes": round(peak_resident_megabytes() * 1e6 / 2**20, 1),  # MiB
        "peak_rss_mb": round(peak_resident_megabytes(), 1),
        "peak_rss_above_start_mb": round(peak_resident_megabytes() - resident_at_start, 1),
    }
    return row


def overrides(args: Any) -> dict[str, Any]:
    """The default model's AgentConfig fields from ``args.config`` (JSON; '' for none)."""
    return json.loads(args.config) if getattr(args, "config", "") else {}


def _split_walk(agent: HippocampalAgent, recorded: list) -> dict[str, Any]:
    """Microseconds per step in each of :data:`AGENT_TERMS` and ``other``, from one instrumented
    walk (slightly slower than the timed ones: the shares are what to read)."""
    timer = SplitTimer()
    for term, methods in AGENT_TERMS.items():
        for owner, name in methods:
            timer.wrap(getattr(agent, owner, None), name, term)
    agent.reset(recorded[0][1], recorded[0][2])
    timer.reset()  # the reset's own settling is not a step
    began = time.perf_counter()
    for action, observation, info in recorded:
        agent.act(observation)
        agent.observe(action, observation, 0.0, False, False, info)
    total = time.perf_counter() - began
    timer.unwrap()
    out: dict[str, Any] = {term: round(1e6 * seconds / len(recorded), 2) for term, seconds in timer.split(total).items()}
    out["total"] = round(1e6 * total / len(recorded), 2)
    if timer.missing:
        out["methods_not_found"] = timer.missing
    return out


def _replay_split(agent: HippocampalAgent) -> dict[str, Any]:
    """One more (instrumented) replay, in milliseconds: building the rows of ``max_k W_pp`` it reaches
    (:data:`REPLAY_TERMS`) and the rest ("other": spreading the activity through those rows, with
    the replay's own buffers, and adding to the reward weights)."""
    timer = SplitTimer()
    for term, methods in REPLAY_TERMS.items():
        for owner, name in methods:
            timer.wrap(getattr(agent, owner, None), name, term)
    began = time.perf_counter()
    agent.learn_reward()
    total = time.perf_counter() - began
    timer.unwrap()
    out: dict[str, Any] = {term: round(1e3 * seconds, 3) for term, seconds in timer.split(total).items()}
    out["total"] = round(1e3 * total, 3)
    if timer.missing:
        out["methods_not_found"] = timer.missing
    return out


class RatInABox:
    """RatInABox (the ``peers`` extra) with an agent moving in a 10 m arena and ``n_place`` place
    cells and ``n_bvc`` BVCs updating (its defaults otherwise; it does not learn)."""

    def __init__(self, n_place: int, n_bvc: int) -> None:
        try:
            from ratinabox.Agent import Agent
            from ratinabox.Environment import Environment
            from ratinabox.Neurons import BoundaryVectorCells, PlaceCells
        except ImportError as err:
            raise ImportError(
                f"RatInABox is not installed ({err}): pip install -e '.[peers]', or --peer-steps 0 to time the models without it"
            ) from err
        environment = Environment(params={"scale": 10.0, "dimensionality": "2D"})
        self.rat = Agent(environment)  # its default time step: a longer one makes its random motion diverge
        self.cells = [BoundaryVectorCells(self.rat, params={"n": n_bvc}), PlaceCells(self.rat, params={"n": n_place})]

    def seconds(self, steps: int) -> float:
        """Wall seconds of ``steps`` updates of the agent and its cells."""
        began = time.perf_counter()
        for _ in range(steps):
            self.rat.update()
            for population in self.cells:
                population.update()
        return time.perf_counter() - began
