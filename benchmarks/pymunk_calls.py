"""What the private pymunk fast path buys: the simulator's physics through pymunk's C bindings
(``"cffi"``) against pymunk's public API (``"public"``), timed side by side.

``python -m benchmarks.pymunk_calls`` drives a ``RobotWorld`` (``hippo_env.physics``) in each maze
with the same seeded headings through both implementations of ``hippo_env._pymunk_fast``, in
turn, repeat by repeat, checks that both end where they began to differ nowhere (the same
positions, bit for bit), and writes ``benchmarks/results/pymunk_calls.json``: per maze, each
implementation's steps per second (median over repeats) and the median of the per-repeat ratios
with its quartiles. Where the C path is not available (a pymunk version not checked), it says so.
"""

from __future__ import annotations

import dataclasses
import json
import time
from typing import Any

import numpy as np
import pymunk

from benchmarks.common import REPO, command_line, machine_info, parse_dataclass_args
from hippo_env import _pymunk_fast
from hippo_env.maze import BUILTIN_MAZES, MazeSpec
from hippo_env.physics import RobotWorld
from hippomaze.stats import median_and_quartiles


@dataclasses.dataclass
class Args:
    steps: int = 2_000
    """physics steps per timing"""
    repeats: int = 9
    """timings per implementation and maze, in alternation"""
    seed: int = 0
    """seed of the headings driven"""
    out: str = ""
    """output JSON ('' = benchmarks/results/pymunk_calls.json)"""


def drive(maze: MazeSpec, calls: str, headings: np.ndarray) -> tuple[float, list[tuple[float, float]]]:
    """Seconds to drive ``headings`` from the maze's centre through ``calls``, and the positions."""
    world = RobotWorld(maze, pymunk_calls=calls)
    world.reset((0.0, 0.0) if maze.name == "open" else _free_start(maze), 0.0)
    positions = []
    began = time.perf_counter()
    for heading in headings:
        world.drive_heading(float(heading))
        positions.append(tuple(world.position))
    return time.perf_counter() - began, positions


def _free_start(maze: MazeSpec) -> tuple[float, float]:
    """A start clear of the maze's walls: the environment's own draw, seeded."""
    import gymnasium as gym

    env = gym.make("HippoMaze-v0", maze=maze)
    _, info = env.reset(seed=0)
    return tuple(info["position"])


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    record: dict[str, Any] = {"command": command_line(), "args": dataclasses.asdict(args), "machine": machine_info(pymunk=pymunk.version)}
    if _pymunk_fast.CFFI is None:
        record["c_path"] = f"not available here: {_pymunk_fast.CFFI_UNAVAILABLE}"
    else:
        headings = np.random.default_rng(args.seed).uniform(-np.pi, np.pi, args.steps)
        mazes = {}
        for name in BUILTIN_MAZES:
            maze = MazeSpec.load(name)
            seconds: dict[str, list[float]] = {"cffi": [], "public": []}
            paths = {}
            for repeat in range(args.repeats):
                for calls in ("cffi", "public") if repeat % 2 == 0 else ("public", "cffi"):
                    spent, paths[calls] = drive(maze, calls, headings)
                    seconds[calls].append(spent)
            ratios = [p / c for c, p in zip(seconds["cffi"], seconds["public"])]
            mazes[name] = {
                "same_positions": paths["cffi"] == paths["public"],
                "steps_per_second": {k: round(args.steps / float(np.median(v)), 1) for k, v in seconds.items()},
                "cffi_over_public": median_and_quartiles(ratios),
            }
            print(f"{name:>6}: C path {mazes[name]['cffi_over_public']} x the public API; same positions: {mazes[name]['same_positions']}")
        record["mazes"] = mazes
    out = REPO / "benchmarks" / "results" / "pymunk_calls.json" if not args.out else args.out
    with open(out, "w") as fh:
        fh.write(json.dumps(record, indent=1) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
