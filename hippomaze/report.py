"""Figures and printed tables of a DMTP result (any agent): paths, indirectness per run, run 1 vs run 2.

Each ``plot_*`` function returns ``(fig, ax)`` and accepts ``ax=``, like :mod:`hippo_agent.plots`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from hippo_agent.plots import plot_trajectories
from hippo_env.dmtp import DMTPResult
from hippo_env.maze import MazeSpec


def plot_indirectness(result: DMTPResult, ax: Any = None, title: str | None = None) -> tuple[Any, Any]:
    """Box plots of indirectness per run (the paper's Fig. 6), every trial as a dot; failures hollow."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 4)) if ax is None else (ax.figure, ax)
    table, ok = result.indirectness(), result.success()
    runs = np.arange(1, result.runs + 1)
    data = [table[:, r][np.isfinite(table[:, r])] for r in range(result.runs)]
    ax.boxplot(data, positions=runs, widths=0.5, showfliers=False)
    jitter = np.asarray(np.random.default_rng(0).uniform(-0.12, 0.12, table.shape[0]))
    failed_label: str | None = "goal not reached"
    for r in range(result.runs):
        ax.scatter(runs[r] + jitter[ok[:, r]], table[ok[:, r], r], s=12, color="tab:blue", zorder=3)
        if (~ok[:, r]).any():
            ax.scatter(
                runs[r] + jitter[~ok[:, r]], table[~ok[:, r], r], s=12, facecolor="none", edgecolor="tab:red", zorder=3, label=failed_label
            )
            failed_label = None  # one legend entry
    ax.set_yscale("symlog", linthresh=1.0)
    ax.axhline(1.0, color="grey", linestyle=":", linewidth=1)
    ax.set_xlabel("run")
    ax.set_ylabel("indirectness (path / shortest - 1)")
    ax.set_title(title or f"{result.agent} on {result.maze}: {result.trials} trials")
    if (~ok).any():
        ax.legend(loc="upper right", fontsize="small")
    return fig, ax


def plot_length_vs_indirectness(result: DMTPResult, ax: Any = None) -> tuple[Any, Any]:
    """Run 1's path length against run 2's indirectness, with the Pearson r (the paper's Fig. 7)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 4)) if ax is None else (ax.figure, ax)
    lengths = np.full(result.trials, np.nan)
    second = np.full(result.trials, np.nan)
    for r in result.run_records:
        if r.run == 0:
            lengths[r.trial] = r.path_length
        elif r.run == 1:
            second[r.trial] = r.indirectness
    ax.scatter(lengths, second, s=15)
    pearson = result.summary().get("pearson_run1_length_run2_indirectness")
    ax.set_xlabel("run 1 path length (m)")
    ax.set_ylabel("run 2 indirectness")
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_title(f"Pearson r = {pearson:.2f}" if pearson is not None else "Pearson r: too few trials")
    return fig, ax


def plot_trial_paths(result: DMTPResult, trial: int, maze: MazeSpec | str, axes: Any = None) -> tuple[Any, Any]:
    """One trial's runs side by side (the paper's Fig. 3), each titled with its indirectness."""
    import matplotlib.pyplot as plt

    spec = MazeSpec.load(maze)
    runs = result.paths[trial]
    if axes is None:
        fig, axes = plt.subplots(1, len(runs), figsize=(3.2 * len(runs), 3.4), squeeze=False)
        axes = axes[0]
    else:
        fig = np.ravel(axes)[0].figure
    records = {r.run: r for r in result.run_records if r.trial == trial}
    for run, (ax, path) in enumerate(zip(np.ravel(axes), runs)):
        record = records[run]
        plot_trajectories([path], ax, maze=spec, goal=record.goal)
        mark = "" if record.success else " (not reached)"
        ax.set_title(f"trial {trial + 1}, run {run + 1}: {record.indirectness:.2f}{mark}", fontsize="small")
        ax.set_xticks([])
        ax.set_yticks([])
    return fig, axes


def write_dmtp_figures(result: DMTPResult, maze: MazeSpec | str, out_dir: str | Path, max_trials: int = 20) -> list[Path]:
    """Save the indirectness box plot, the run 1 / run 2 scatter and each trial's paths as PNGs."""
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, plot in (("indirectness.png", plot_indirectness), ("run1_length_vs_run2_indirectness.png", plot_length_vs_indirectness)):
        fig, _ = plot(result)
        fig.tight_layout()
        fig.savefig(out / name, dpi=110)
        plt.close(fig)
        written.append(out / name)
    for trial in range(min(len(result.paths), max_trials)):
        fig, _ = plot_trial_paths(result, trial, maze)
        fig.tight_layout()
        path = out / f"paths_trial{trial + 1:02d}.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        written.append(path)
    return written


def format_table(result: DMTPResult) -> str:
    """Each trial's indirectness run by run (a '*' marks a run that missed the goal), then medians."""
    table, ok = result.indirectness(), result.success()
    header = "trial " + " ".join(f"{'run ' + str(r + 1):>9}" for r in range(result.runs))
    lines = [header]
    for t in range(table.shape[0]):
        cells = [f"{_fmt(table[t, r])}{'' if ok[t, r] else '*'}".rjust(9) for r in range(result.runs)]
        lines.append(f"{t + 1:>5} " + " ".join(cells))
    summary = result.summary()
    lines.append("median " + " ".join(f"{_fmt(m if m is not None else math.nan):>9}" for m in summary["median_indirectness"]))
    lines.append("reached" + " ".join(f"{rate:>9.0%}" for rate in summary["success_rate"]))
    if "later_runs_below_1" in summary:
        later = "run 2" if result.runs == 2 else f"runs 2-{result.runs}"
        lines.append(
            f"{later}: {summary['later_runs_success_rate']:.0%} reached the goal, {summary['later_runs_below_1']:.0%} with indirectness < 1"
        )
    if "pearson_run1_length_run2_indirectness" in summary:
        lines.append(
            f"Pearson r, run 1 path length vs run 2 indirectness: {summary['pearson_run1_length_run2_indirectness']:.2f} (paper: -0.53)"
        )
    lines.append(f"environment steps, the dry run included: {result.env_steps_total:,}")
    return "\n".join(lines)


def _fmt(value: float) -> str:
    return "nan" if not math.isfinite(value) else f"{value:.2f}"
