"""Figures of a world that changes: paths round new blocks, the agent's map before and after, a
shortcut taken, and the runs back in a known world.

``python -m benchmarks.world_figures --seed 11`` runs the default model through the barriers
schedule and one maze's schedule of :mod:`benchmarks.changing_world` (the same layouts, drawn
from the seed), and through its several-worlds schedule, and writes to
``benchmarks/results/changing_world/``:

- ``barriers_paths.png``: the first run in each new layout of blocks, the goal kept;
- ``map_before_after.png``: the agent's map (walls and free ground, in the world's coordinates) after
  learning the goal in the open arena, and after the last layout's runs, over the true layouts;
- ``shortcut_paths.png``: runs in the maze with a door cut in a wall;
- ``worlds_paths.png``: the runs back in the first world, unannounced and with no dry run.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.common import REPO, parse_dataclass_args
from hippo_agent import HippocampalAgent
from hippo_env.dmtp import run_dmtp
from hippomaze.changing_world import WORLDS_SCHEDULE, Watched, barriers_schedule, maze_schedule
from hippomaze.report import plot_phase_paths


@dataclasses.dataclass
class FigureArgs:
    seed: int = 11
    """runner seed (the layouts are drawn from it)"""
    maze: str = "maze2"
    """the maze whose door layout shows the shortcut"""
    out: str = ""
    """output folder ('' = benchmarks/results/changing_world)"""


def run_with_maps(schedule: dict[str, Any], seed: int) -> tuple[Any, list[tuple[np.ndarray, np.ndarray]], Watched]:
    """Run ``schedule`` with the default model; the agent's map (its wall and free grids) at the
    end of each phase, and the watcher (its frame's origin)."""
    watched: list[Watched] = []
    maps: list[tuple[np.ndarray, np.ndarray]] = []
    last_run = {k: p.get("runs", 4) - 1 for k, p in enumerate(schedule["phases"])}

    def make(observation_space: Any, action_space: Any, *, seed: int) -> Watched:
        watched.append(Watched(HippocampalAgent(observation_space, action_space, seed=seed)))
        return watched[-1]

    def on_run_end(trial: int, run: int, agent: Any, env: Any) -> None:
        phase = len(maps)
        if phase in last_run and run == last_run[phase]:
            m = agent.agent.map
            maps.append(((m.hits > 0) & (m.hits >= m.free), (m.free > 0) & (m.hits < m.free)))

    result = run_dmtp(make, schedule=schedule, seed=seed, progress=False, on_run_end=on_run_end, env_kwargs={"odometry": True})
    return result, maps, watched[0]


def save_phase_firsts(result: Any, phases: list[int], path: Path, title: str) -> None:
    """The first run of each phase in ``phases``, side by side."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(phases), figsize=(3.2 * len(phases), 3.6), squeeze=False, layout="constrained")
    for ax, phase in zip(axes[0], phases):
        plot_phase_paths(result, phase, max_panels=1, axes=np.array([[ax]]))
        name = result.phases[[p["phase"] for p in result.phases].index(phase)]["name"]
        ax.set_title(f"{name}\n{ax.get_title()}", fontsize="small")
    fig.suptitle(title, fontsize="medium")
    fig.savefig(path, dpi=90)
    plt.close(fig)


def save_phase_runs(result: Any, phase: int, path: Path, max_panels: int = 5) -> None:
    import matplotlib.pyplot as plt

    fig, _ = plot_phase_paths(result, phase, max_panels=max_panels)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def save_maps(result: Any, maps: list[tuple[np.ndarray, np.ndarray]], origin: np.ndarray, cell: float, extent: float, path: Path) -> None:
    """The map after the learn phase and after the last layout, drawn in the world's coordinates
    (the frame's origin is where the dry run began) over the true layouts."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Polygon, Rectangle

    shown = [(0, "after learning the goal"), (len(maps) - 1, "after the last layout's runs")]
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 4.6), layout="constrained")
    for ax, (k, label) in zip(axes, shown):
        walls, free = maps[k]
        image = np.where(walls, 2, np.where(free, 1, 0)).astype(float)
        image[image == 0] = np.nan
        x0, y0 = origin[0] - extent, origin[1] - extent
        n = walls.shape[0]
        ax.imshow(
            image.T, origin="lower", extent=(x0, x0 + n * cell, y0, y0 + n * cell), cmap=ListedColormap(["#dfe9f5", "#1f3b73"]),
            vmin=1, vmax=2, interpolation="nearest",
        )  # fmt: skip
        begun = [i for i, p in enumerate(result.phases) if p["phase"] == k]
        maze = result.phase_mazes[begun[0]]
        w, h = maze.size
        ax.add_patch(Rectangle((-w / 2, -h / 2), w, h, fill=False, edgecolor="#d62728", lw=1.2))
        for poly in maze.obstacles:
            ax.add_patch(Polygon(np.asarray(poly), closed=True, fill=False, edgecolor="#d62728", lw=1.2))
        ax.set_xlim(-w / 2 - 0.5, w / 2 + 0.5)
        ax.set_ylim(-h / 2 - 0.5, h / 2 + 0.5)
        ax.set_aspect("equal")
        ax.set_title(f"the agent's map {label}\n(dark: walls, light: free; red: the true layout)", fontsize="small")
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(FigureArgs, __doc__.splitlines()[0], argv)
    out = Path(args.out) if args.out else REPO / "benchmarks" / "results" / "changing_world"
    out.mkdir(parents=True, exist_ok=True)
    barriers = barriers_schedule(args.seed)
    result, maps, watcher = run_with_maps(barriers, args.seed)
    layouts = list(range(1, len(barriers["phases"])))
    save_phase_firsts(result, layouts, out / "barriers_paths.png", "new blocks round a known goal: the first run in each layout")
    m = watcher.agent.map
    assert watcher.origin is not None
    save_maps(result, maps, watcher.origin, m.cell, m.extent, out / "map_before_after.png")
    shortcut = maze_schedule(args.maze, args.seed)
    result, _, _ = run_with_maps(shortcut, args.seed)
    save_phase_runs(result, [p["name"] for p in shortcut["phases"]].index("door"), out / "shortcut_paths.png")
    result, _, _ = run_with_maps(WORLDS_SCHEDULE, args.seed)
    save_phase_runs(result, 3, out / "worlds_paths.png", max_panels=4)
    print(f"wrote {sorted(p.name for p in out.glob('*.png'))} to {out}")


if __name__ == "__main__":
    main()
