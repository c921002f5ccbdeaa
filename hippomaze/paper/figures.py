"""The report's figures (matplotlib, imported lazily), each drawn from the experiments' records,
and ``FIGURES``: every figure's file name, heading and caption in the report's order."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from hippo_env.dmtp import DMTPResult
from hippo_env.maze import MazeSpec
from hippomaze.stats import median_or_none

from .design import EXAMPLE_CELLS, MAZES, SCENARIOS
from .formatting import fmt
from .results import FieldsResult, GeneralisationResult, TrialResult

FIGURES = [
    (
        "fig1_place_fields.png",
        "1. Place fields",
        (
            "Example place fields after the dry run in the open arena and every maze: each cell's rate over the positions of an "
            "aimless roam (learning off), hexagonal bins, unvisited bins empty (paper Fig. 2). Four cells drawn at random among "
            "those with a field."
        ),
    ),
    (
        "fig2a_reward_maps_open.png",
        "2. Reward maps after run 1 (open arena)",
        (
            "Top: run 1 of each same-start trial; bottom: the reward cell's rate over an aimless roam after run 1, learning off "
            "(paper Fig. 3). Red: the goal."
        ),
    ),
    ("fig2b_reward_maps_mazes.png", "2. Reward maps after run 1 (mazes)", "The same in maze1-maze4 (paper Fig. 8)."),
    (
        "fig3a_same_start_open.png",
        "3. Same start, open arena",
        "Each column a trial, each row a run from the same start; titles give the indirectness (paper Fig. 4).",
    ),
    (
        "fig3b_same_start_mazes.png",
        "3. Same start, mazes",
        "One trial per maze, four runs from one start (paper Fig. 7; the paper's Maze 3 is our maze4).",
    ),
    (
        "fig4_indirectness.png",
        "4. Indirectness per run, open arena",
        "Random starts, every trial a dot; hollow red = goal not reached (paper Fig. 5).",
    ),
    ("fig5_length_vs_indirectness.png", "5. Run 1 length vs run 2 indirectness", "With the Pearson r (paper Fig. 6: -0.53)."),
    (
        "fig6_generalisation.png",
        "6. Generalisation",
        (
            "Top: the goal-free exploration ((a) the agent's own, 5,000 steps by default; (b) one scripted pass along an L; (c) the "
            "agent's own in maze2). Below: the map inferred by replay alone at the green goal, sampled by roaming (paper Fig. 10). "
            "Titles: share of the roamed places where the value exceeds the exploit threshold; runs from random starts (up to the "
            "step limit) that reached the goal, and their median indirectness."
        ),
    ),
    (
        "fig7_aliasing_maze4.png",
        "7. Perceptual aliasing in maze4",
        (
            "Cells whose fields have separate pieces in several quadrants (rates on a grid so every compartment is sampled), and "
            "the distribution over cells, maze4 against the open arena (paper Fig. 9)."
        ),
    ),
    (
        "fig8_mazes_indirectness.png",
        "Beyond the paper: indirectness per run in every maze",
        "Random starts, as figure 4 above but in each obstacle maze.",
    ),
]


def _save(fig: Any, path: Path, dpi: int = 90) -> Path:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def _bare(ax: Any) -> None:
    ax.set_xticks([])
    ax.set_yticks([])


def fig_place_fields(fields: dict[str, FieldsResult], out: Path) -> Path:
    import matplotlib.pyplot as plt

    from hippo_agent.plots import plot_place_field

    mazes = [m for m in MAZES if m in fields]
    fig, axes = plt.subplots(len(mazes), EXAMPLE_CELLS, figsize=(2.7 * EXAMPLE_CELLS, 2.7 * len(mazes)), squeeze=False)
    for row, m in enumerate(mazes):
        f = fields[m]
        spec = MazeSpec.load(m)
        for col in range(EXAMPLE_CELLS):
            ax = axes[row, col]
            if col < len(f.examples):
                cell = f.examples[col]
                plot_place_field(f.roam_positions, f.roam_rates[cell], ax, maze=spec, colorbar=False, gridsize=30)
                ax.set_title(f"{m}: cell {cell}", fontsize="small")
            else:
                ax.set_visible(False)
            _bare(ax)
    fig.suptitle("Place fields after the dry run (rate over positions of an aimless roam; unvisited bins empty)", fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / "fig1_place_fields.png")


def fig_reward_maps(entries: list[tuple[str, TrialResult]], out: Path, name: str, title: str) -> Path:
    import matplotlib.pyplot as plt

    from hippo_agent.plots import plot_reward_map, plot_trajectories

    n = max(len(entries), 1)
    fig, axes = plt.subplots(2, n, figsize=(3.3 * n, 6.6), squeeze=False)
    for col, (label, entry) in enumerate(entries):
        spec = MazeSpec.load(entry.maze)
        mp = entry.map
        assert mp is not None  # the entries are the trials whose map was sampled
        plot_trajectories(
            [mp.run1_path],
            axes[0, col],
            maze=spec,
            goal=mp.goal,
            title=f"{label}: run 1",
        )
        vmax = float(np.nanmax(mp.values)) if np.isfinite(mp.values).any() else 0.0
        plot_reward_map(
            mp.positions,
            mp.values,
            axes[1, col],
            maze=spec,
            goal=mp.goal,
            colorbar=False,
            gridsize=30,
            title=f"value after run 1 (max {vmax:.2f})",
        )
        for ax in axes[:, col]:
            _bare(ax)
            ax.title.set_fontsize("small")
    fig.suptitle(title, fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / name)


def fig_same_start(results: list[tuple[str, DMTPResult, str]], out: Path, name: str, title: str) -> Path:
    import matplotlib.pyplot as plt

    from hippomaze.report import plot_trial_paths

    runs = max(r.runs for _, r, _ in results)
    fig, axes = plt.subplots(runs, len(results), figsize=(2.9 * len(results), 2.9 * runs), squeeze=False)
    for col, (label, result, maze) in enumerate(results):
        plot_trial_paths(result, 0, maze, axes=axes[: len(result.paths[0]), col])
        for record in result.run_records:
            mark = "" if record.success else " (not reached)"
            axes[record.run, col].set_title(f"{label}, run {record.run + 1}: {record.indirectness:.2f}{mark}", fontsize="small")
        for ax in axes[len(result.paths[0]) :, col]:
            ax.set_visible(False)
    fig.suptitle(title, fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / name)


def fig_dmtp(result: DMTPResult, out: Path) -> list[Path]:
    import matplotlib.pyplot as plt

    from hippomaze.report import plot_indirectness, plot_length_vs_indirectness

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        fig, ax = plot_indirectness(result, title=f"open arena: {result.trials} trials, random starts")
    if ax.get_legend() is not None and not ax.get_legend_handles_labels()[1]:
        ax.get_legend().remove()
    fig.tight_layout()
    a = _save(fig, out / "fig4_indirectness.png", dpi=110)
    fig, ax = plot_length_vs_indirectness(result)
    ax.set_title(ax.get_title() + " (paper: -0.53)")
    fig.tight_layout()
    b = _save(fig, out / "fig5_length_vs_indirectness.png", dpi=110)
    plt.close("all")
    return [a, b]


def fig_mazes_dmtp(results: dict[str, DMTPResult], out: Path) -> Path:
    import matplotlib.pyplot as plt

    from hippomaze.report import plot_indirectness

    fig, axes = plt.subplots(1, len(results), figsize=(4.2 * len(results), 3.8), squeeze=False)
    for ax, (m, result) in zip(axes[0], results.items()):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # an empty legend when no run failed
            plot_indirectness(result, ax=ax, title=f"{m}: {result.trials} trials")
        if ax.get_legend() is not None and not ax.get_legend_handles_labels()[1]:
            ax.get_legend().remove()
    fig.tight_layout()
    return _save(fig, out / "fig8_mazes_indirectness.png", dpi=100)


def fig_generalisation(gen: dict[str, GeneralisationResult], out: Path) -> Path:
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle

    from hippo_agent.plots import plot_reward_map, plot_trajectories

    names = [n for n in SCENARIOS if n in gen]
    rows = 1 + max(len(gen[n].goals) for n in names)
    fig, axes = plt.subplots(rows, len(names), figsize=(3.3 * len(names), 3.2 * rows), squeeze=False)
    for col, name in enumerate(names):
        g = gen[name]
        spec = MazeSpec.load(g.maze)
        plot_trajectories([g.path], axes[0, col], maze=spec, title=f"{SCENARIOS[name].title}: exploration")
        for row in range(1, rows):
            ax = axes[row, col]
            if row - 1 >= len(g.goals):
                ax.set_visible(False)
                continue
            goal = g.goals[row - 1]
            plot_reward_map(g.positions, goal.values, ax, maze=spec, colorbar=False, gridsize=30)
            ax.add_patch(Circle((goal.goal[0], goal.goal[1]), 0.3, facecolor="none", edgecolor="lime", lw=2.5, zorder=6))
            where = "visited" if goal.visited else f"{goal.distance_to_explored:.1f} m from explored"
            ok = sum(n.success for n in goal.nav)
            ind = median_or_none(n.indirectness for n in goal.nav)
            ax.set_title(
                f"goal {tuple(goal.goal)} ({where})\ncovers {fmt(goal.stats.coverage, pct=True)}; runs: {ok}/{len(goal.nav)} "
                f"reached, median ind. {fmt(ind, 1)}",
                fontsize="small",
            )
        for ax in axes[:, col]:
            _bare(ax)
            ax.title.set_fontsize("small")
    fig.suptitle("Generalisation: replay only at each green goal, maps sampled by roaming", fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / "fig6_generalisation.png")


def fig_aliasing(fields: dict[str, FieldsResult], out: Path) -> Path:
    import matplotlib.pyplot as plt

    from hippo_agent.plots import plot_place_field

    f4 = fields["maze4"]
    spec = MazeSpec.load("maze4")
    cells = f4.alias_examples
    fig, axes = plt.subplots(1, EXAMPLE_CELLS + 1, figsize=(2.9 * (EXAMPLE_CELLS + 1), 3.2), squeeze=False)
    by_id = {c.cell: c for c in f4.cells}
    spacing = np.min(np.diff(np.unique(f4.grid_positions[:, 0]))) if len(f4.grid_positions) > 1 else 0.2
    for k in range(EXAMPLE_CELLS):
        ax = axes[0, k]
        if k < len(cells):
            c = cells[k]
            plot_place_field(
                f4.grid_positions, f4.grid_rates[c], ax, maze=spec, colorbar=False, gridsize=max(10, round(10 / spacing * 0.7))
            )
            ax.set_title(f"cell {c}: {by_id[c].quadrants} quadrants", fontsize="small")
        else:
            ax.set_visible(False)
        _bare(ax)
    ax = axes[0, -1]
    width = 0.38
    ks = np.arange(1, 5)
    for shift, (m, colour) in zip((-width / 2, width / 2), (("maze4", "tab:red"), ("open", "tab:grey"))):
        if m in fields and fields[m].summary.with_field:
            hist = np.asarray(fields[m].summary.quadrants_hist, float)
            ax.bar(ks + shift, hist / hist.sum(), width, color=colour, label=m)
    ax.set_yscale("log")
    ax.set_xticks(ks)
    ax.set_xlabel("quadrants with a piece of the field")
    ax.set_ylabel("share of cells with a field")
    ax.legend(fontsize="small")
    fig.suptitle("maze4: place fields at alike places of several compartments (rates on a grid)", fontsize="medium")
    fig.tight_layout()
    return _save(fig, out / "fig7_aliasing_maze4.png")


def draw_figures(
    fields: dict[str, FieldsResult],
    same_open: list[TrialResult],
    same_mazes: dict[str, TrialResult],
    open_result: DMTPResult,
    gen: dict[str, GeneralisationResult],
    maze_results: dict[str, DMTPResult],
    out: Path,
) -> list[Path]:
    """Every figure of the report, in ``out``; returns their paths."""
    import matplotlib

    matplotlib.use("Agg")
    figures = [fig_place_fields(fields, out)]
    figures.append(
        fig_reward_maps(
            [(f"open trial {t + 1}", x) for t, x in enumerate(same_open)],
            out,
            "fig2a_reward_maps_open.png",
            "Open arena: reward maps after run 1, sampled by roaming with learning off",
        )
    )
    figures.append(
        fig_reward_maps(
            list(same_mazes.items()),
            out,
            "fig2b_reward_maps_mazes.png",
            "Mazes: reward maps after run 1, sampled by roaming with learning off",
        )
    )
    figures.append(
        fig_same_start(
            [(f"open trial {t + 1}", x.result, "open") for t, x in enumerate(same_open)],
            out,
            "fig3a_same_start_open.png",
            "Open arena: four runs from the same start",
        )
    )
    figures.append(
        fig_same_start(
            [(m, x.result, m) for m, x in same_mazes.items()], out, "fig3b_same_start_mazes.png", "Mazes: four runs from the same start"
        )
    )
    figures += fig_dmtp(open_result, out)
    figures.append(fig_generalisation(gen, out))
    figures.append(fig_aliasing(fields, out))
    if maze_results:
        figures.append(fig_mazes_dmtp(maze_results, out))
    return figures
