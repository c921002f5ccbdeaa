"""Figures and printed tables of a DMTP result (any agent): paths, indirectness per run, run 1 vs run 2;
for a schedule of phases, every run's indirectness episode by episode, coloured by phase, and each
phase's paths in its own maze.

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
    """Save the indirectness box plot, the run 1 / run 2 scatter and each trial's paths as PNGs; for a
    schedule, :func:`write_schedule_figures` (``maze`` is then not used)."""
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if result.schedule is not None:
        return write_schedule_figures(result, out, max_phases=max_trials)
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
    """Each trial's indirectness run by run (a '*' marks a run that missed the goal), then medians;
    for a schedule, :func:`format_schedule_table`."""
    if result.schedule is not None:
        return format_schedule_table(result)
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


# ------------------------------------------------------------------ schedules
INDIRECTNESS_FLOOR = 0.01  # a log axis cannot show 0: indirectness below this is drawn at it


def plot_indirectness_by_episode(result: DMTPResult, ax: Any = None, title: str | None = None) -> tuple[Any, Any]:
    """A schedule's every run: its indirectness (log axis; below 0.01 drawn at 0.01) against its
    episode (its place among its repeat's runs), coloured by phase; a run that missed the goal as a
    cross. Dotted lines part the phases, and with several repeats each repeat's runs are joined."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(max(6.0, min(14.0, 0.12 * _episodes_per_repeat(result) + 4)), 4)) if ax is None else (ax.figure, ax)
    names = [p["name"] for p in (result.schedule or {}).get("phases", [])]
    colours = plt.get_cmap("tab10")
    repeats = sorted({r.repeat for r in result.run_records})
    missed = False
    for repeat in repeats:
        records = [r for r in result.run_records if r.repeat == repeat]
        x = np.arange(1, len(records) + 1)
        y = np.maximum(np.array([r.indirectness for r in records], dtype=float), INDIRECTNESS_FLOOR)
        if len(repeats) > 1:
            ax.plot(x, y, color="grey", linewidth=0.5, alpha=0.4, zorder=1)
        for phase in sorted({r.phase for r in records}):
            hit = np.array([r.phase == phase and r.success for r in records])
            miss = np.array([r.phase == phase and not r.success for r in records])
            label = (names[phase] if phase < len(names) else f"phase {phase}") if repeat == repeats[0] else None
            ax.scatter(x[hit], y[hit], s=16, color=colours(phase % 10), zorder=3, label=label)
            if miss.any():
                ax.scatter(x[miss], y[miss], s=30, marker="x", color=colours(phase % 10), zorder=3)
                missed = True
        if repeat == repeats[0]:
            for k in range(1, len(records)):
                if records[k].phase != records[k - 1].phase:
                    ax.axvline(k + 0.5, color="grey", linestyle=":", linewidth=1)
    if missed:
        ax.scatter([], [], s=30, marker="x", color="black", label="goal not reached (cut off)")
    ax.set_yscale("log")
    ax.axhline(1.0, color="grey", linestyle="--", linewidth=0.8)
    ax.set_xlabel("episode (run of the schedule)" + (f", {len(repeats)} repeats" if len(repeats) > 1 else ""))
    ax.set_ylabel("indirectness (path / shortest - 1)")
    ax.set_title(title or f"{result.agent}: a schedule of {len(names)} phases")
    if result.run_records:
        ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize="small")
    return fig, ax


def plot_phase_paths(result: DMTPResult, phase: int, repeat: int = 0, max_panels: int = 20, axes: Any = None) -> tuple[Any, Any]:
    """One phase's runs (of one repeat) side by side in the phase's maze, each titled with its
    indirectness; at most ``max_panels``, five to a row."""
    import matplotlib.pyplot as plt

    begun = [k for k, p in enumerate(result.phases) if p["phase"] == phase and p["repeat"] == repeat]
    if not begun:
        raise ValueError(f"phase {phase} of repeat {repeat} did not begin; phases begun: {len(result.phases)}")
    maze = result.phase_mazes[begun[0]] if begun[0] < len(result.phase_mazes) else MazeSpec.load(result.phases[begun[0]]["maze"])
    records = [r for r in result.run_records if r.phase == phase and r.repeat == repeat][:max_panels]
    columns = max(1, min(5, len(records)))
    rows = max(1, -(-len(records) // columns))
    if axes is None:
        fig, axes = plt.subplots(rows, columns, figsize=(3.0 * columns, 3.3 * rows), squeeze=False, layout="constrained")
    else:
        fig = np.ravel(axes)[0].figure
    panels = np.ravel(axes)
    for ax, record in zip(panels, records):
        plot_trajectories([result.paths[record.trial][record.run]], ax, maze=maze, goal=record.goal)
        mark = "" if record.success else " (not reached)"
        ax.set_title(f"run {record.run + 1}: {record.indirectness:.2f}{mark}", fontsize="small")
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in panels[len(records) :]:
        ax.set_visible(False)
    name = result.phases[begun[0]]["name"]
    fig.suptitle(f"{name} ({maze.name})" + (f", repeat {repeat + 1}" if repeat else ""), fontsize="medium")
    return fig, axes


def write_schedule_figures(result: DMTPResult, out_dir: str | Path, max_phases: int = 20) -> list[Path]:
    """Save ``indirectness_by_episode.png`` and, for the first repeat, each phase's paths
    (``paths_phaseKK.png``, at most ``max_phases``)."""
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, _ = plot_indirectness_by_episode(result)
    fig.tight_layout()
    fig.savefig(out / "indirectness_by_episode.png", dpi=110)
    plt.close(fig)
    written = [out / "indirectness_by_episode.png"]
    for phase in sorted({r.phase for r in result.run_records if r.repeat == 0})[:max_phases]:
        fig, _ = plot_phase_paths(result, phase)
        path = out / f"paths_phase{phase:02d}.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        written.append(path)
    return written


def format_schedule_table(result: DMTPResult) -> str:
    """A schedule's runs, a line per trial (its repeat, phase, maze; a '*' marks a run that missed
    the goal), then per phase: runs, success rate, median indirectness of the successes, and for a
    phase whose goal is not new, how often its first run reached the goal."""
    begun = {(p["repeat"], p["phase"]): p for p in result.phases}
    lines = []
    trials = sorted({(r.repeat, r.phase, r.trial) for r in result.run_records})
    for repeat, phase, trial in trials:
        record = begun.get((repeat, phase), {"name": f"phase {phase}", "maze": "?"})
        runs = [r for r in result.run_records if r.trial == trial]
        cells = " ".join(f"{_fmt(r.indirectness)}{'' if r.success else '*'}".rjust(7) for r in runs)
        prefix = f"repeat {repeat + 1} " if result.schedule and result.schedule["repeats"] > 1 else ""
        lines.append(f"{prefix}{record['name']} ({record['maze']}): {cells}")
    lines.append("(* the run missed the goal)")
    for entry in result.summary()["phases"]:
        median = entry["median_indirectness_of_successes"]
        rate = entry["success_rate"]
        line = f"{entry['name']}: {entry['runs']} runs, {'-' if rate is None else f'{rate:.0%}'} reached the goal"
        line += f", median indirectness of those {median:.2f}" if median is not None else ""
        if "first_run_success_rate" in entry and entry["first_run_success_rate"] is not None:
            line += f"; its first run reached the goal {entry['first_run_success_rate']:.0%} of the time"
        lines.append(line)
    lines.append(f"environment steps, the dry runs included: {result.env_steps_total:,}")
    return "\n".join(lines)


def _episodes_per_repeat(result: DMTPResult) -> int:
    return max((sum(1 for r in result.run_records if r.repeat == k) for k in {r.repeat for r in result.run_records}), default=0)
