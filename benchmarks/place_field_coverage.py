"""Place fields after the dry run: how much of the free space they cover, and how big each is.

For each maze a fresh agent does its goal-free dry run; then the place cells' steady-state rates
are sampled on a grid over the free space (``env.unwrapped.observation_at``). Coverage is the
share of grid points where at least one place cell fires; a cell's field is the share of the
arena where it fires (rate > 0) and where it fires above half its peak. Each maze's figures are
printed beside the targets (``benchmarks/targets.toml``).

    python benchmarks/place_field_coverage.py   # writes benchmarks/results/place_field_coverage.json
"""

from __future__ import annotations

import datetime
from dataclasses import asdict, dataclass

import gymnasium as gym
import numpy as np

import hippo_env  # registers HippoMaze-v0
from benchmarks.common import command_line, machine_info, output_path, parse_dataclass_args
from benchmarks.targets import target, verdict
from hippo_agent import HippocampalAgent
from hippo_agent.plots import grid_positions
from hippo_env.physics import ROBOT_RADIUS


@dataclass
class Args:
    mazes: tuple[str, ...] = ("open", "maze1", "maze2")
    """mazes to sample"""
    spacing: float = 0.2
    """grid spacing in metres"""
    seed: int = 0
    """seeds the agent and its dry run"""
    out: str = "benchmarks/results/place_field_coverage.json"
    """where the JSON goes (relative to the repository root unless absolute)"""


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    rows = []
    for maze in args.mazes:
        env = gym.make("HippoMaze-v0", maze=maze, odometry=True)
        env.reset(seed=args.seed)
        agent = HippocampalAgent(env.observation_space, env.action_space, seed=args.seed)
        agent.dry_run(env)
        spec = env.unwrapped.maze
        grid = grid_positions(spec.size, spacing=args.spacing, margin=0.0)
        grid = grid[spec.free_mask(grid, ROBOT_RADIUS)]
        rates = agent.place_field_map(env, grid)
        active = rates > 0
        fired = active.any(axis=0)
        arena = spec.size[0] * spec.size[1]
        cell_area = args.spacing**2
        field_share = active[:, fired].sum(axis=0) * cell_area / arena
        half_share = (rates[:, fired] > 0.5 * rates[:, fired].max(axis=0)).sum(axis=0) * cell_area / arena
        rows.append(
            {
                "maze": maze,
                "grid_points": len(grid),
                "coverage": float(active.any(axis=1).mean()),
                "cells_with_a_field": int(fired.sum()),
                "median_field_share_of_arena": float(np.median(field_share)),
                "median_half_peak_field_share_of_arena": float(np.median(half_share)),
                "max_field_share_of_arena": float(field_share.max()),
                "median_cells_active_per_point": float(np.median(active.sum(axis=1))),
            }
        )
        coverage, size = target("place_field_coverage"), target("place_field_size")
        print(
            f"  {maze}: coverage {rows[-1]['coverage']:.1%} (target {coverage.text()}: {verdict(coverage.met(rows[-1]['coverage']))}), "
            f"{fired.sum()} cells with a field, median field {np.median(field_share):.2%} of the arena "
            f"(target {size.text()}: {verdict(size.met(rows[-1]['median_field_share_of_arena']))})"
        )
        env.close()

    record = {
        "command": command_line(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "args": asdict(args),
        "machine": machine_info(numpy=np.__version__),
        "rows": rows,
    }
    out = output_path(args.out)
    hippo_env.write_json(out, record)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
