"""The ``hippomaze`` console script.

``hippomaze dmtp --maze open --trials 20 --runs 4 --seed 0 --agent hippo --out out/`` runs the
delayed-match-to-place experiment, prints each run's indirectness and writes ``out/dmtp.json``
with its figures; ``hippomaze dmtp --schedule FILE.json`` runs a schedule of phases instead
(:mod:`hippo_env.schedule`). ``hippomaze paper --out DIR`` reproduces the paper's experiments.
``hippomaze bench --agent module:Class --out DIR`` measures an agent's sample efficiency beside
the shipped references (:mod:`hippomaze.bench`); ``hippomaze animate --out FILE.gif`` animates
one DMTP trial (:mod:`hippomaze.animate`).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from hippo_env.env import ACTION_TYPES
from hippo_env.files import write_json
from hippo_env.physics import ROBOT_RADIUS
from hippomaze.runinfo import non_negative_int

# What `hippomaze dmtp` writes into its --out folder (cleared by --overwrite, nothing else is).
DMTP_OUTPUTS = (
    "dmtp.json",
    "paths.npz",
    "summary.json",
    "indirectness.png",
    "run1_length_vs_run2_indirectness.png",
    "paths_trial*.png",
    "reward_map_after_run1.png",
    "place_fields.png",
    "indirectness_by_episode.png",
    "paths_phase*.png",
)
DEFAULT_MAZE, DEFAULT_TRIALS, DEFAULT_RUNS = "open", 20, 4
# Exit status after Ctrl-C, as a shell reports a process ended by SIGINT.
EXIT_INTERRUPTED = 130
# Exit status when an exception inside the experiment (the agent's code, most likely) stopped it.
EXIT_FAILED = 1
# Analysis maps sample at most this many positions (each costs a place-cell settle).
MAX_MAP_POSITIONS = 2500
EXAMPLE_PLACE_CELLS = 6


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="hippomaze", description="Hippocampal navigation in a Morris water maze (DMTP).")
    commands = parser.add_subparsers(dest="command", required=True)

    dmtp = commands.add_parser("dmtp", help="run the delayed-match-to-place experiment", description=run_dmtp_command.__doc__)
    dmtp.add_argument("--maze", help="built-in maze (open, maze1 ... maze4) or a path to a maze JSON file (default: open)")
    dmtp.add_argument("--trials", type=int, help="trials, each with a new goal (default: 20)")
    dmtp.add_argument("--runs", type=int, help="runs per trial (default: 4)")
    dmtp.add_argument(
        "--schedule",
        metavar="FILE.json",
        help="run a schedule of phases instead of --maze/--trials/--runs: each phase its maze (or a seeded change of one), "
        "trials, runs, goal (new, kept, an earlier phase's, or [x, y]), dry run and whether the agent is told the goal moved "
        "(see hippo_env.schedule and docs/schedules/)",
    )
    dmtp.add_argument("--seed", type=non_negative_int, default=0, help="seeds goals, starts, environment and agents (default: 0)")
    dmtp.add_argument(
        "--agent",
        default="hippo",
        help="hippo (the default model), hippo-paper (the paper's model), random, dqn, ppo, module:Class for an agent class, "
        "or module:make_agent for a factory function (default: hippo)",
    )
    dmtp.add_argument("--out", default="out", help="folder for dmtp.json and figures, new or empty (default: out)")
    dmtp.add_argument(
        "--overwrite", action="store_true", help="allow a non-empty --out folder: first delete what an earlier dmtp run wrote there"
    )
    dmtp.add_argument("--same-start", action="store_true", help="start every run of a trial from the same place")
    dmtp.add_argument(
        "--max-steps",
        type=int,
        default=None,
        help="steps per run before it is cut off (default: 10,000; a schedule's phase may set its own max_steps)",
    )
    dmtp.add_argument(
        "--action-type", default=None, choices=ACTION_TYPES, help="the action space (default: what the agent asks for, else discrete)"
    )
    dmtp.add_argument(
        "--env",
        action="append",
        default=[],
        type=_env_argument,
        metavar="KEY=VALUE",
        help="an argument for gym.make('HippoMaze-v0', ...), e.g. --env n_rays=360 --env odometry=true; VALUE is read as JSON "
        "(true, 3, 0.5, [1, 2]) where it parses, else as a string; overrides the agent's env_kwargs (repeatable)",
    )
    dmtp.add_argument(
        "--agent-config",
        action="append",
        default=[],
        type=_agent_config_argument,
        metavar="KEY=VALUE",
        help="a parameter of the agent, e.g. --agent-config model.n_place=500 --agent-config homing=null for hippo (dotted names "
        "of AgentConfig), or a hyperparameter of dqn/ppo/dynaq; VALUE is read as JSON where it parses, else as a string (repeatable)",
    )
    dmtp.add_argument("--no-figures", action="store_true", help="write dmtp.json only")
    dmtp.add_argument("--no-progress", action="store_true", help="no progress bar")

    paper = commands.add_parser(
        "paper", help="reproduce the paper's experiments and write REPORT.md", description=run_paper_command.__doc__
    )
    paper.add_argument("--out", default="paper_out", help="output folder (default: paper_out)")
    paper.add_argument("--quick", action="store_true", help="few trials: a smoke run of every experiment")
    paper.add_argument("--seed", type=non_negative_int, default=0, help="base seed; every experiment's seed derives from it (default: 0)")
    paper.add_argument("--workers", type=int, default=2, help="processes for independent trials (default: 2)")
    paper.add_argument(
        "--model",
        default="paper",
        choices=("paper", "default"),
        help="paper: AgentConfig.paper(), the model as the paper describes it; default: AgentConfig(), with path integration (default: paper)",
    )

    from hippomaze.animate import add_parser as add_animate_parser
    from hippomaze.bench.cli import add_parser as add_bench_parser

    add_bench_parser(commands)
    add_animate_parser(commands)

    args = parser.parse_args(argv)
    try:
        if args.command == "dmtp":
            return run_dmtp_command(args)
        if args.command == "bench":
            from hippomaze.bench.cli import bench_command

            return bench_command(args)
        if args.command == "animate":
            from hippomaze.animate import animate_command

            return animate_command(args)
        return run_paper_command(args)
    except (ValueError, TypeError) as err:  # a bad argument, named in the message
        print(f"hippomaze: error: {err}", file=sys.stderr)
        return 2
    except ImportError as err:  # an optional extra the command needs (bench: rliable; animate to mp4: imageio-ffmpeg)
        if args.command not in ("bench", "animate"):
            raise
        print(f"hippomaze: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("hippomaze: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def run_dmtp_command(args: argparse.Namespace) -> int:
    """Run DMTP trials with one agent, or a schedule of phases (--schedule), print each run's
    indirectness and write dmtp.json, summary.json and figures.

    If the agent raises, its traceback is printed and the runs that finished are saved to dmtp.json,
    marked "complete": false, with the exception under "error"."""
    from hippo_env.dmtp import DMTPFailed, DMTPInterrupted, run_dmtp
    from hippo_env.maze import MazeSpec
    from hippo_env.schedule import Schedule
    from hippomaze.registry import agent_factory
    from hippomaze.report import format_table, write_dmtp_figures

    if ":" in args.agent and "" not in sys.path and os.getcwd() not in sys.path:
        sys.path.insert(0, os.getcwd())  # --agent mymodule:MyAgent finds ./mymodule.py, as `python -m` would
    schedule, maze = None, None
    if args.schedule is not None:
        given = [f"--{name}" for name in ("maze", "trials", "runs") if getattr(args, name) is not None]
        if given:
            raise ValueError(f"--schedule names each phase's maze, trials and runs: drop {', '.join(given)}, or drop --schedule")
        schedule = Schedule.load(args.schedule)
    else:
        maze = MazeSpec.load(args.maze if args.maze is not None else DEFAULT_MAZE)
    overrides = dict(args.agent_config)
    try:
        factory = agent_factory(args.agent, **overrides)
    except ImportError as err:  # a missing optional extra (dqn, ppo): one line says how to install it
        raise ValueError(str(err)) from err
    env_kwargs = dict(args.env)  # run_dmtp puts the agent's own env_kwargs under these
    if args.action_type is not None:
        env_kwargs = {"action_type": args.action_type, **env_kwargs}
    out = prepare_out_dir(Path(args.out), args.overwrite)  # before any work: never run, then fail to save
    maps: dict[str, Any] = {}
    plain: dict[str, Any] = {}  # a schedule's phases name their own trials and runs
    if schedule is None:
        plain = {"trials": DEFAULT_TRIALS if args.trials is None else args.trials, "runs": DEFAULT_RUNS if args.runs is None else args.runs}
    try:
        result = run_dmtp(
            factory,
            maze,
            **plain,
            schedule=schedule,
            seed=args.seed,
            agent_name=args.agent,
            agent_spec=args.agent,
            agent_overrides=overrides,
            same_start=args.same_start,
            env_kwargs=env_kwargs,
            max_episode_steps=args.max_steps,
            progress=not args.no_progress,
            on_run_end=None if args.no_figures else _collect_maps(maps),
        )
    except DMTPInterrupted as interrupt:
        partial = interrupt.result
        path = partial.save(out)
        print(
            f"hippomaze: interrupted; saved the {len(partial.run_records)} finished runs of {partial.planned_runs()} "
            f'to {path} (marked "complete": false)',
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    except DMTPFailed as failure:
        partial = failure.result
        path = partial.save(out)
        traceback.print_exception(failure.__cause__, file=sys.stderr)
        print(
            f"hippomaze: error: {partial.error} ({failure.doing}); saved the {len(partial.run_records)} finished runs "
            f'of {partial.planned_runs()} to {path} (marked "complete": false)',
            file=sys.stderr,
        )
        return EXIT_FAILED
    path = result.save(out)
    write_json(out / "summary.json", result.summary())
    print(format_table(result))
    print(f"wrote {path}")
    if not args.no_figures:
        try:
            first_maze = maze if maze is not None else result.phase_mazes[0]  # a schedule's: its first phase's
            written = write_dmtp_figures(result, first_maze, out)
            written += _write_agent_maps(maps, result, first_maze, out)
        except KeyboardInterrupt:
            print(f"hippomaze: interrupted while drawing figures; the complete {path} was saved", file=sys.stderr)
            return EXIT_INTERRUPTED
        print(f"wrote {len(written)} figures to {out}/")
    return 0


def prepare_out_dir(out: Path, overwrite: bool) -> Path:
    """Check (and create) the output folder before any work starts.

    A file in the way, or a folder already holding files, is a ``ValueError``, unless
    ``overwrite``: then the files an earlier ``hippomaze dmtp`` wrote there are deleted first
    (and only those), so no stale figure sits beside the new ones.
    """
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {str(out)!r} is a file; give a folder (new or empty) for dmtp.json and its figures")
    if out.is_dir() and any(out.iterdir()):
        if not overwrite:
            found = sorted(p.name for p in out.iterdir())
            shown = ", ".join(found[:4]) + (", ..." if len(found) > 4 else "")
            raise ValueError(
                f"--out {str(out)!r} is not empty ({shown}); give a new or empty folder, or add --overwrite to replace an earlier run's results"
            )
        stale = sorted({p for pattern in DMTP_OUTPUTS for p in out.glob(pattern) if p.is_file()})
        for p in stale:
            p.unlink()
        if stale:
            print(f"hippomaze: --overwrite: deleted {len(stale)} files of an earlier run from {out}/", file=sys.stderr)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ValueError(f"--out {str(out)!r} cannot be created ({err.strerror or err}); give a writable folder") from err
    return out


def _collect_maps(maps: dict[str, Any]) -> Callable[[int, int, Any, Any], None]:
    """After trial 1's first run, sample the reward map; after its last, the place fields along its paths.

    Only for agents that offer ``reward_map`` / ``place_field_map`` (the hippocampal agent does).
    """

    def on_run_end(trial: int, run: int, agent: Any, env: Any) -> None:
        if trial != 0 or not hasattr(agent, "reward_map"):
            return
        if run == 0:
            grid = _grid(env.unwrapped.maze)
            maps["reward_grid"], maps["reward_values"] = grid, agent.reward_map(env, grid)
            maps["run1_path"] = env.unwrapped.path.copy()
        maps.setdefault("visited", []).append(env.unwrapped.path.copy())
        maps["agent"] = agent

    return on_run_end


def _write_agent_maps(maps: dict[str, Any], result: Any, maze: Any, out: Path) -> list[Path]:
    import matplotlib.pyplot as plt

    from hippo_agent.plots import plot_place_field, plot_reward_map, plot_trajectories

    written: list[Path] = []
    if "reward_values" in maps:
        goal = result.run_records[0].goal
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.4))
        plot_trajectories([maps["run1_path"]], axes[0], maze=maze, goal=goal, title="trial 1, run 1 (exploring)")
        plot_reward_map(maps["reward_grid"], maps["reward_values"], axes[1], maze=maze, goal=goal, title="reward map after run 1")
        fig.tight_layout()
        fig.savefig(out / "reward_map_after_run1.png", dpi=110)
        plt.close(fig)
        written.append(out / "reward_map_after_run1.png")
    if "visited" in maps and hasattr(maps["agent"], "place_field_map"):
        positions = np.concatenate(maps["visited"])
        if len(positions) > MAX_MAP_POSITIONS:
            positions = positions[np.linspace(0, len(positions) - 1, MAX_MAP_POSITIONS).astype(int)]
        env = _analysis_env(maze)
        rates = maps["agent"].place_field_map(env, positions)
        cells = _example_cells(rates, EXAMPLE_PLACE_CELLS)
        if len(cells):
            fig, axes = plt.subplots(2, (len(cells) + 1) // 2, figsize=(4 * ((len(cells) + 1) // 2), 7.6), squeeze=False)
            for ax, cell in zip(axes.ravel(), cells):
                plot_place_field(positions, rates[:, cell], ax, maze=maze, title=f"place cell {cell}")
            for ax in axes.ravel()[len(cells) :]:
                ax.set_visible(False)
            fig.tight_layout()
            fig.savefig(out / "place_fields.png", dpi=100)
            plt.close(fig)
            written.append(out / "place_fields.png")
        env.close()
    return written


def _analysis_env(maze: Any) -> Any:
    import gymnasium as gym

    return gym.make("HippoMaze-v0", maze=maze)


def _example_cells(rates: np.ndarray, count: int) -> np.ndarray:
    """The cells with the strongest fields along the visited positions, spread over the arena."""
    peak = np.nanmax(np.nan_to_num(rates, nan=0.0), axis=0)
    ranked = np.argsort(peak)[::-1]
    ranked = ranked[peak[ranked] > 0]
    return ranked[np.linspace(0, max(len(ranked) // 2, 1) - 1, min(count, len(ranked))).astype(int)] if len(ranked) else ranked


def _grid(maze: Any, spacing: float = 0.2) -> np.ndarray:
    """Free positions on a grid over the maze (at most ``MAX_MAP_POSITIONS``)."""
    from hippo_agent.plots import grid_positions

    grid = grid_positions(maze.size, spacing=spacing)
    grid = grid[maze.free_mask(grid, ROBOT_RADIUS)]
    if len(grid) > MAX_MAP_POSITIONS:
        grid = grid[np.linspace(0, len(grid) - 1, MAX_MAP_POSITIONS).astype(int)]
    return grid


def _env_argument(text: str) -> tuple[str, Any]:
    """An argparse type: ``KEY=VALUE`` for gym.make, VALUE read as JSON where it parses, else kept as a string."""
    key, equals, value = text.partition("=")
    key = key.strip()
    if not equals or not key.isidentifier():
        raise argparse.ArgumentTypeError(f"must be KEY=VALUE with KEY an argument name, e.g. n_rays=360 or odometry=true; got {text!r}")
    try:
        return key, json.loads(value)
    except json.JSONDecodeError:
        return key, value


def _agent_config_argument(text: str) -> tuple[str, Any]:
    """An argparse type: ``KEY=VALUE`` for the agent's factory, KEY a dotted name (``model.n_place``),
    VALUE read as JSON where it parses (``null`` is None), else kept as a string."""
    key, equals, value = text.partition("=")
    key = key.strip()
    if not equals or not key or not all(part.isidentifier() for part in key.split(".")):
        raise argparse.ArgumentTypeError(
            f"must be KEY=VALUE with KEY a parameter name, dotted for a section's, e.g. model.n_place=500 or homing=null; got {text!r}"
        )
    try:
        return key, json.loads(value)
    except json.JSONDecodeError:
        return key, value


def run_paper_command(args: argparse.Namespace) -> int:
    """Reproduce the paper's experiments (hippomaze.paper): the model's figures and tables, written
    with REPORT.md and paper.json into --out. --quick runs every experiment briefly."""
    from hippomaze.paper import PaperArgs, run_paper

    run_paper(PaperArgs(out=args.out, quick=args.quick, seed=args.seed, workers=args.workers, model=args.model))
    return 0


if __name__ == "__main__":
    sys.exit(main())
