"""Every built-in maze side by side, for the README: ``docs/mazes.png``.

python -m benchmarks.maze_pictures
python -m benchmarks.maze_pictures --mazes open maze1 --out /tmp/mazes.png
"""

from __future__ import annotations

from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import hippo_env
from benchmarks.common import output_path, parse_dataclass_args
from hippo_env.render import plot_maze


@dataclass
class Args:
    mazes: tuple[str, ...] = hippo_env.BUILTIN_MAZES
    """built-in names or paths to maze JSON files, drawn left to right"""
    panel_inches: float = 3.2
    """width (and height) of one panel"""
    dpi: int = 120
    """resolution of the PNG"""
    out: str = "docs/mazes.png"
    """where the PNG goes (relative to the repository root unless absolute)"""


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    fig, axes = plt.subplots(1, len(args.mazes), figsize=(args.panel_inches * len(args.mazes), args.panel_inches + 0.4), squeeze=False)
    for ax, maze in zip(axes[0], args.mazes):
        plot_maze(maze, ax=ax)
        ax.set_xticks([-5, 0, 5])
        ax.set_yticks([-5, 0, 5])
        if ax is not axes[0][0]:
            ax.set_ylabel("")
    fig.tight_layout()
    out = output_path(args.out)
    fig.savefig(out, dpi=args.dpi)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
