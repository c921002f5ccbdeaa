"""Coverage against dry-run steps: the default agent's directed dry run beside a random walk.

For each maze and seed, the default agent's dry run (``AgentConfig()``: a sweep to unvisited
ground, transits, rest; it ends by itself) and the previous default's random walk
(:func:`random_walk_config`: path integration, no map) are run, and this harness records the
robot's TRUE position each step from outside (the agent never sees it). Coverage after t steps is
the share of the free 0.25 m grid cells (centre at least the robot's radius from every wall) that
the robot's centre has come within 0.5 m of.

``python -m benchmarks.coverage --mazes open maze4 gen-perfect-7 --seeds 0 1 2`` writes
``benchmarks/results/coverage/coverage.json`` (steps to 80 % and 95 % coverage, the dry run's
length, coverage at its end), ``coverage.png`` (coverage against steps) and ``paths.png`` (a
directed dry run beside a random walk of the same length, the directed path coloured by stage).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import gymnasium as gym
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from benchmarks.common import command_line, machine_info, output_path, parse_dataclass_args
from benchmarks.maze_suite import maze_source
from hippo_agent import AgentConfig, HippocampalAgent, ReflexConfig
from hippo_env.dmtp import _CountingEnv
from hippo_env.files import write_json
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS
from hippo_env.render import plot_maze

GRID = 0.25  # m between the grid cells coverage counts
REACH = 0.5  # m: a cell is covered once the robot's centre came this close
STAGE_COLOURS = {"sweep": "tab:blue", "transit": "tab:orange", "done": "tab:gray"}


@dataclasses.dataclass
class CoverageArgs:
    mazes: tuple[str, ...] = ("open", "maze4", "gen-perfect-7")
    """built-in mazes, JSON paths or generated ones (gen-<kind>-<seed>[-<size>m])"""
    seeds: tuple[int, ...] = (0, 1, 2)
    """seeds of the env and the agents"""
    random_steps: int = 5000
    """length of the random walk (the previous default dry run)"""
    out: str = "benchmarks/results/coverage"
    """output folder (relative to the repository root unless absolute)"""


def random_walk_config(steps: int) -> AgentConfig:
    """The default model before directed exploration: path integration, no map, a random walk of ``steps`` steps."""
    return AgentConfig(
        map=None, localisation=None, exploration=None, homing=None, worlds=None, reflexes=ReflexConfig(escape_after="exploiting")
    ).with_values({"model.dry_run_steps": steps, "path_integration.min_anchor_steps": 0})


def dry_run(maze: str, seed: int, config: AgentConfig) -> tuple[np.ndarray, list[str], MazeSpec]:
    """The agent's dry run in ``maze``: the true positions, the dry-run stage at each step, the maze."""
    env = gym.make("HippoMaze-v0", maze=maze_source(maze), odometry=True)
    env.reset(seed=seed, options={"goal": None})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=seed)
    positions: list[np.ndarray] = []
    stages: list[str] = []

    class Watched(_CountingEnv):
        def step(self, action: Any):
            out = super().step(action)
            positions.append(np.asarray(out[4]["position"], dtype=float))
            stages.append(agent.exploration.stage if agent.exploration is not None else "random")
            return out

    agent.dry_run(Watched(env, allow_goal=False))
    spec = env.unwrapped.maze
    env.close()
    return np.array(positions).reshape(-1, 2), stages, spec


def free_cells(spec: MazeSpec, spacing: float = GRID) -> np.ndarray:
    """Centres of the grid cells the robot can stand on."""
    w, h = spec.size
    xs = np.arange(-w / 2 + spacing / 2, w / 2, spacing)
    ys = np.arange(-h / 2 + spacing / 2, h / 2, spacing)
    grid = np.array([(x, y) for x in xs for y in ys])
    return grid[np.array([spec.clearance(p) >= ROBOT_RADIUS for p in grid])]


def coverage_curve(spec: MazeSpec, positions: np.ndarray, reach: float = REACH) -> np.ndarray:
    """Coverage after each step: ``curve[t]`` is the share of free cells covered by steps 0..t."""
    cells = free_cells(spec)
    first = np.full(len(cells), np.inf)
    for start in range(0, len(positions), 1000):  # chunks keep the distance matrix small
        chunk = positions[start : start + 1000]
        near = np.hypot(cells[:, None, 0] - chunk[None, :, 0], cells[:, None, 1] - chunk[None, :, 1]) <= reach
        hit = near.any(axis=1) & ~np.isfinite(first)
        first[hit] = start + near[hit].argmax(axis=1)
    counts = np.bincount(first[np.isfinite(first)].astype(int), minlength=len(positions))[: len(positions)]
    return np.cumsum(counts) / len(cells)


def steps_to(curve: np.ndarray, share: float) -> int | None:
    """Steps until coverage reached ``share`` (None if it never did)."""
    reached = np.flatnonzero(curve >= share)
    return int(reached[0]) + 1 if reached.size else None


def summarise(curve: np.ndarray) -> dict[str, Any]:
    return {"steps": int(curve.size), "steps_to_80": steps_to(curve, 0.8), "steps_to_95": steps_to(curve, 0.95), "final": float(curve[-1])}


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(CoverageArgs, __doc__.splitlines()[0], argv)
    rows: list[dict[str, Any]] = []
    curves: dict[str, dict[str, list[np.ndarray]]] = {}
    paths: dict[str, tuple[MazeSpec, np.ndarray, list[str], np.ndarray]] = {}
    for maze in args.mazes:
        curves[maze] = {"directed": [], "random": []}
        for seed in args.seeds:
            directed, stages, spec = dry_run(maze, seed, AgentConfig())
            walk, _, _ = dry_run(maze, seed, random_walk_config(args.random_steps))
            d_curve, r_curve = coverage_curve(spec, directed), coverage_curve(spec, walk)
            curves[maze]["directed"].append(d_curve)
            curves[maze]["random"].append(r_curve)
            sweep = sum(s == "sweep" for s in stages)
            row = {"maze": maze, "seed": seed, "directed": {**summarise(d_curve), "sweep_steps": sweep}, "random": summarise(r_curve)}
            rows.append(row)
            print(
                f"{maze:>14} seed {seed}: directed {row['directed']['steps']} steps (sweep {sweep}), 80/95 % at "
                f"{row['directed']['steps_to_80']}/{row['directed']['steps_to_95']}, end {row['directed']['final']:.0%}; "
                f"random walk 80/95 % at {row['random']['steps_to_80']}/{row['random']['steps_to_95']}, "
                f"after {args.random_steps} steps {row['random']['final']:.0%}",
                flush=True,
            )
            if seed == args.seeds[0]:
                paths[maze] = (spec, directed, stages, walk[: len(directed)])
    out = output_path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(
        out / "coverage.json", {"command": command_line(), "machine": machine_info(), "args": dataclasses.asdict(args), "rows": rows}
    )
    plot_curves(curves, out / "coverage.png")
    plot_paths(paths, out / "paths.png")
    print(f"wrote {out / 'coverage.json'}, coverage.png and paths.png")


def plot_curves(curves: dict[str, dict[str, list[np.ndarray]]], path: Any) -> None:
    """Coverage against steps per maze: each seed thin, directed and random walk."""
    fig, axes = plt.subplots(1, len(curves), figsize=(4.2 * len(curves), 3.6), squeeze=False)
    for ax, (maze, by_kind) in zip(axes[0], curves.items()):
        for kind, colour in (("directed", "tab:blue"), ("random", "tab:red")):
            for k, curve in enumerate(by_kind.get(kind, [])):
                label = ("directed dry run" if kind == "directed" else "random walk") if k == 0 else None
                ax.plot(np.arange(1, curve.size + 1), curve, color=colour, lw=1.0, alpha=0.8, label=label)
        ax.axhline(0.95, color="k", lw=0.5, ls=":")
        ax.set_title(maze)
        ax.set_xlabel("dry-run steps")
        ax.set_ylim(0, 1.02)
    axes[0][0].set_ylabel(f"share of free ground within {REACH} m")
    axes[0][0].legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_paths(paths: dict[str, tuple[MazeSpec, np.ndarray, list[str], np.ndarray]], path: Any) -> None:
    """Per maze, the directed dry run (coloured by stage) above a random walk of the same length."""
    fig, axes = plt.subplots(2, len(paths), figsize=(3.8 * len(paths), 7.6), squeeze=False)
    for col, (maze, (spec, directed, stages, walk)) in enumerate(paths.items()):
        top, bottom = axes[0][col], axes[1][col]
        plot_maze(spec, ax=top)
        stage = np.array(stages)
        for name, colour in STAGE_COLOURS.items():
            pts = np.where((stage == name)[:, None], directed, np.nan)
            top.plot(pts[:, 0], pts[:, 1], color=colour, lw=0.6, label=name)
        top.set_title(f"{maze}: directed, {len(directed)} steps", fontsize=9)
        top.legend(loc="upper right", fontsize=7)
        plot_maze(spec, ax=bottom)
        bottom.plot(walk[:, 0], walk[:, 1], color="tab:red", lw=0.6)
        bottom.set_title(f"{maze}: random walk, {len(walk)} steps", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
