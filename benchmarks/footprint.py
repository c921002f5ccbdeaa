"""Footprint: what a large maze costs to set up, and whether a long run's memory stays bounded.

1. **Set-up**: ``gym.make("HippoMaze-v0", maze=...)`` and its first ``reset`` for a 40 m x 40 m
   arena with a dozen rectangular obstacles (and the built-in 10 m mazes for scale), each in a
   fresh process: wall seconds and the process's peak resident memory above a bare interpreter
   that has imported the package.
2. **Long run**: a goal-free run (``options={"goal": None}``, one reset, no time limit) of
   ``--steps`` steps of the default hippocampal agent in ``--maze`` (the bare env, without the
   registered 10,000-step time limit), its resident memory sampled
   every ``--every`` steps.

    python -m benchmarks.footprint                      # benchmarks/results/footprint.json
    python -m benchmarks.footprint --steps 20000        # a quick look
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.common import (
    REPO,
    command_line,
    in_fresh_process,
    load_average,
    machine_info,
    parse_dataclass_args,
    peak_resident_megabytes,
    resident_megabytes,
)
from hippo_env.files import write_json


@dataclasses.dataclass
class FootprintArgs:
    size: float = 40.0
    """side of the large arena (m)"""
    obstacles: int = 12
    """rectangular obstacles in the large arena"""
    maze: str = "maze2"
    """maze of the long run"""
    steps: int = 1_000_000
    """steps of the long run (0: skip it)"""
    every: int = 50_000
    """steps between memory samples"""
    seed: int = 0
    """seeds the obstacles, the env and the agent"""
    out: str = ""
    """output JSON ('' = benchmarks/results/footprint.json)"""


def rectangles(size: float, count: int, seed: int) -> list[list[list[float]]]:
    """``count`` axis-aligned rectangles of 0.3-3 m sides, at least 3 m from the arena's walls."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        cx, cy = rng.uniform(-size / 2 + 3, size / 2 - 3, 2)
        w, h = rng.uniform(0.3, 3.0, 2)
        out.append([[cx - w / 2, cy - h / 2], [cx + w / 2, cy - h / 2], [cx + w / 2, cy + h / 2], [cx - w / 2, cy + h / 2]])
    return out


def _set_up(maze: Any) -> dict[str, Any]:
    """In a fresh process: import, note the memory, then make and reset the env."""
    import gymnasium as gym

    import hippo_env  # noqa: F401  (registers HippoMaze-v0)

    before = resident_megabytes()
    began = time.perf_counter()
    env = gym.make("HippoMaze-v0", maze=maze)
    made = time.perf_counter()
    env.reset(seed=0)
    result = {
        "make_seconds": made - began,
        "make_and_reset_seconds": time.perf_counter() - began,
        "resident_before_mb": before,
        "peak_mb": peak_resident_megabytes(),
        "peak_above_import_mb": peak_resident_megabytes() - before,
    }
    env.close()
    return result


def set_up_cost(maze: Any) -> dict[str, Any]:
    return in_fresh_process(_set_up, maze)


def long_run(maze: str, steps: int, every: int, seed: int) -> dict[str, Any]:
    """A goal-free run of the default agent; resident memory every ``every`` steps."""
    import gymnasium as gym

    import hippo_env  # noqa: F401
    from hippo_agent import HippocampalAgent
    from hippo_env.dmtp import rollout

    env = gym.make("HippoMaze-v0", maze=maze, odometry=True).unwrapped  # no time limit
    agent = HippocampalAgent(env.observation_space, env.action_space, seed=seed)
    obs, info = env.reset(seed=seed, options={"goal": None})
    agent.reset(obs, info)
    samples = [{"step": 0, "resident_mb": resident_megabytes()}]
    began = time.perf_counter()
    step = 0
    while step < steps:
        end = rollout(env, agent, obs, max_steps=min(every, steps - step))
        obs, step = end.observation, step + end.steps
        if end.terminated or end.truncated:
            raise RuntimeError(f"the goal-free run ended at step {step}; it should not end")
        samples.append({"step": step, "resident_mb": resident_megabytes(), "seconds": time.perf_counter() - began})
        print(f"  step {step:>9,}: {samples[-1]['resident_mb']:.0f} MB resident", flush=True)
    return {
        "maze": maze,
        "steps": steps,
        "samples": samples,
        "peak_mb": peak_resident_megabytes(),
        "path_rows_kept": len(env.unwrapped.path),
        "steps_per_second": steps / (time.perf_counter() - began),
    }


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(FootprintArgs, __doc__.splitlines()[0], argv)
    from hippo_env.maze import MazeSpec

    load_start = load_average()
    large = MazeSpec.from_dict(
        {"name": f"large-{args.size:g}", "size": [args.size, args.size], "obstacles": rectangles(args.size, args.obstacles, args.seed)}
    )
    set_up = {}
    for name, maze in (("open", "open"), ("maze2", "maze2"), (large.name, large)):
        set_up[name] = set_up_cost(maze)
        print(
            f"set-up {name}: {set_up[name]['make_and_reset_seconds']:.2f} s, "
            f"peak {set_up[name]['peak_above_import_mb']:.0f} MB above the imports",
            flush=True,
        )
    record: dict[str, Any] = {
        "command": command_line(),
        "machine": machine_info(),
        "load_start": load_start,
        "set_up": set_up,
        "large_maze": {"size": args.size, "obstacles": args.obstacles, "seed": args.seed},
    }
    if args.steps:
        print(f"long goal-free run: {args.steps:,} steps in {args.maze}", flush=True)
        record["long_run"] = long_run(args.maze, args.steps, args.every, args.seed)
    record["load_end"] = load_average()
    out = Path(args.out) if args.out else REPO / "benchmarks" / "results" / "footprint.json"
    write_json(out, record)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
