"""Every built-in maze side by side, for the README: ``docs/mazes.png``.

python -m benchmarks.maze_pictures
python -m benchmarks.maze_pictures --mazes open maze1 --out /tmp/mazes.png
python -m benchmarks.maze_pictures --suite --columns 6 --out docs/generated_mazes.png   # the maze suite's generated mazes
"""

from __future__ import annotations

from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import hippo_env
from benchmarks.common import output_path, parse_dataclass_args
from benchmarks.maze_suite import GENERATED, generated_name, maze_source
from hippo_env.maze import MazeSpec
from hippo_env.render import plot_maze


@dataclass
class Args:
    mazes: tuple[str, ...] = hippo_env.BUILTIN_MAZES
    """built-in names, paths to maze JSON files or generated names (gen-<kind>-<seed>[-<size>m]), drawn left to right"""
    suite: bool = False
    """draw the generated mazes of benchmarks.maze_suite instead"""
    columns: int = 0
    """panels per row (0: all in one row)"""
    panel_inches: float = 3.2
    """width (and height) of one panel"""
    dpi: int = 120
    """resolution of the PNG"""
    out: str = "docs/mazes.png"
    """where the PNG goes (relative to the repository root unless absolute)"""


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    mazes = [generated_name(*g) for g in GENERATED] if args.suite else list(args.mazes)
    columns = args.columns or len(mazes)
    rows = -(-len(mazes) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(args.panel_inches * columns, (args.panel_inches + 0.4) * rows), squeeze=False)
    for ax in axes.flat[len(mazes) :]:
        ax.set_axis_off()
    for k, (ax, maze) in enumerate(zip(axes.flat, mazes)):
        spec = MazeSpec.load(maze_source(maze))
        plot_maze(spec, ax=ax)
        half = spec.size[0] / 2
        ax.set_xticks([-half, 0, half])
        ax.set_yticks([-half, 0, half])
        ax.set_title(maze if maze.startswith("gen-") else spec.name, fontsize=9)
        if k % columns:
            ax.set_ylabel("")
    fig.tight_layout()
    out = output_path(args.out)
    fig.savefig(out, dpi=args.dpi)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
