"""The experiment tasks: each runs in a worker process, is seeded by its arguments only, and
returns a typed record (``results``). ``build_tasks`` lists every task of a run."""

from __future__ import annotations

import copy
import dataclasses
import functools
from typing import Any

import numpy as np

from hippo_agent import AgentConfig
from hippo_env.dmtp import DMTPResult, run_dmtp
from hippo_env.maze import MazeSpec

from .analysis import aliasing_examples, analyse_fields, map_stats, random_examples, summarise_fields
from .args import PaperArgs
from .design import EXAMPLE_CELLS, LIMITED_PATH, MAZES, OBSTACLE_MAZES, SCENARIOS, TRIAL_SEED_STRIDE, trial_seed
from .geometry import distance_to_path, grid_for
from .pool import Task
from .procedures import drive_scripted, explore_without_goal, make_agent, make_env, navigate, replay_at, roam
from .results import FieldsResult, GeneralisationResult, GoalResult, RewardMap, TrialResult

VISITED = 0.5  # m: a goal this close to the exploration path was visited


def task_fields(maze: str, seed: int, config: AgentConfig, roam_steps: int, spacing: float) -> FieldsResult:
    """Experiments 1 and 7: place fields after the dry run, on a roam and on a grid."""
    env = make_env(maze)
    env.reset(seed=seed, options={"goal": None})
    agent = make_agent(env.observation_space, env.action_space, seed=seed, config=config)
    agent.dry_run(env)  # only W_pb learns
    grid = grid_for(maze, spacing)
    grid_rates = agent.place_field_map(env, grid.positions)
    cells = analyse_fields(grid, grid_rates)
    rng = np.random.default_rng(seed)
    examples = random_examples(cells, EXAMPLE_CELLS, rng)
    alias_examples = aliasing_examples(cells, EXAMPLE_CELLS)
    positions = roam(maze, roam_steps, seed + 1)
    roam_rates = agent.place_field_map(env, positions)
    keep = sorted(set(examples) | set(alias_examples))
    env.close()
    spec = MazeSpec.load(maze)
    return FieldsResult(
        maze=maze,
        seed=seed,
        summary=summarise_fields(cells, config.model.n_place, spec.size[0] * spec.size[1]),
        cells=cells,
        examples=examples,
        alias_examples=alias_examples,
        roam_positions=positions.astype(np.float32),
        roam_rates={c: roam_rates[:, c].astype(np.float32) for c in keep},
        grid_positions=grid.positions.astype(np.float32),
        grid_rates={c: grid_rates[:, c].astype(np.float32) for c in keep},
    )


def task_dmtp_trial(
    maze: str, seed: int, runs: int, same_start: bool, config: AgentConfig, max_episode_steps: int | None, map_roam_steps: int
) -> TrialResult:
    """Experiments 2-5: one DMTP trial through the protocol runner; optionally the reward map after run 1."""
    captured: list[RewardMap] = []

    def on_run_end(trial: int, run: int, agent: Any, env: Any) -> None:
        if run != 0 or not map_roam_steps:
            return
        positions = roam(maze, map_roam_steps, seed + 1)
        # the reward cell's rate, no learning; the run's own env, so that a path-integrating agent's
        # frame is placed where the robot stands (observation_at moves nothing)
        values = agent.reward_map(env, positions)
        goal = env.unwrapped.goal
        path = env.unwrapped.path.copy()
        captured.append(
            RewardMap(
                positions=positions.astype(np.float32),
                values=values.astype(np.float32),
                run1_path=path.astype(np.float32),
                goal=[float(goal[0]), float(goal[1])],
                stats=map_stats(maze, positions, values, goal, path, agent.config.model.xi),
            )
        )

    result = run_dmtp(
        functools.partial(make_agent, config=config),
        maze,
        trials=1,
        runs=runs,
        seed=seed,
        agent_name="hippo",
        same_start=same_start,
        max_episode_steps=max_episode_steps,
        progress=False,
        on_run_end=on_run_end,
        env_kwargs={"odometry": True},
    )
    return TrialResult(maze=maze, seed=seed, same_start=same_start, result=result, map=captured[-1] if captured else None)


def task_generalisation(
    name: str, seed: int, config: AgentConfig, explore_steps: int, roam_steps: int, nav_runs: int, nav_max_steps: int
) -> GeneralisationResult:
    """Experiment 6: explore with no goal, then for each goal replay only and sample the map."""
    scenario = SCENARIOS[name]
    maze = scenario.maze
    env = make_env(maze)
    env.reset(seed=seed, options={"goal": None})
    agent = make_agent(env.observation_space, env.action_space, seed=seed, config=config)
    agent.dry_run(env)  # as before every DMTP trial
    if scenario.explore == "scripted":
        path = drive_scripted(env, agent, LIMITED_PATH)
    else:
        path = explore_without_goal(env, agent, explore_steps)
    positions = roam(maze, roam_steps, seed + 1)
    rates = agent.place_field_map(env, positions)
    nav_env = make_env(maze, max_episode_steps=nav_max_steps)
    goals = []
    for k, goal in enumerate(scenario.goals):
        replayed = copy.deepcopy(agent)
        learnt = replay_at(replayed, env, goal)
        values = np.asarray(replayed.reward.value(rates, replayed.reward.W_rp[-1]), float)  # eq. 9, undepressed
        nav = navigate(replayed, nav_env, goal, nav_runs, seed + 10 + k)
        to_path = float(distance_to_path(np.asarray([goal], float), path)[0])
        goals.append(
            GoalResult(
                goal=[float(goal[0]), float(goal[1])],
                distance_to_explored=to_path,
                visited=to_path <= VISITED,
                replay_learnt=bool(learnt),
                values=values.astype(np.float32),
                stats=map_stats(maze, positions, values, goal, path, config.model.xi),
                nav=nav,
            )
        )
    env.close()
    nav_env.close()
    return GeneralisationResult(
        name=name, maze=maze, seed=seed, path=path.astype(np.float32), positions=positions.astype(np.float32), goals=goals
    )


def build_tasks(args: PaperArgs) -> list[Task]:
    """Every task of a run, each with its own seed (see the package docstring); ``cost`` is rough seconds."""
    cfg = args.agent_config()
    base = TRIAL_SEED_STRIDE * args.seed

    def trial(maze: str, seed: int, same_start: bool, map_roam_steps: int) -> dict[str, Any]:
        return {
            "maze": maze,
            "seed": seed,
            "runs": args.runs,
            "same_start": same_start,
            "config": cfg,
            "max_episode_steps": args.max_episode_steps,
            "map_roam_steps": map_roam_steps,
        }

    tasks = [
        Task(
            f"fields/{m}",
            task_fields,
            {"maze": m, "seed": base + 300 + i, "config": cfg, "roam_steps": args.roam_steps, "spacing": args.grid_spacing},
            20,
        )
        for i, m in enumerate(MAZES)
    ]
    for t in range(args.same_start_trials):
        tasks.append(Task(f"same_start/open/{t}", task_dmtp_trial, trial("open", base + 100 + t, True, args.roam_steps), 12))
    for i, m in enumerate(OBSTACLE_MAZES):
        tasks.append(Task(f"same_start/{m}", task_dmtp_trial, trial(m, base + 110 + i, True, args.roam_steps), 25))
    for t in range(args.trials):
        tasks.append(Task(f"dmtp/open/{t}", task_dmtp_trial, trial("open", trial_seed(args.seed, t), False, 0), 4))
    for m in OBSTACLE_MAZES:
        for t in range(args.maze_trials):
            tasks.append(Task(f"dmtp/{m}/{t}", task_dmtp_trial, trial(m, trial_seed(args.seed, t), False, 0), 25 if m == "maze4" else 10))
    for i, name in enumerate(SCENARIOS):
        tasks.append(
            Task(
                f"generalisation/{name}",
                task_generalisation,
                {
                    "name": name,
                    "seed": base + 400 + i,
                    "config": cfg,
                    "explore_steps": args.explore_steps,
                    "roam_steps": args.roam_steps,
                    "nav_runs": args.nav_runs,
                    "nav_max_steps": args.nav_max_steps,
                },
                60,
            )
        )
    return tasks


def merge_trials(results: list[DMTPResult], seed: int) -> DMTPResult:
    """Single-trial results as one ``DMTPResult`` (trial ``t`` = the ``t``-th result)."""
    first = results[0]
    merged = dataclasses.replace(
        first, seed=seed, trials=len(results), run_records=[], paths=[], dry_run_steps=[], env_steps_total=0, seconds=0.0
    )
    for t, r in enumerate(results):
        merged.dry_run_steps += r.dry_run_steps
        merged.run_records += [dataclasses.replace(record, trial=t) for record in r.run_records]
        merged.paths += r.paths
        merged.env_steps_total += r.env_steps_total
        merged.seconds += r.seconds
    return merged
