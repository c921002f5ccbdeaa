"""The figures: learning curves, and the cost of a goal switch."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from benchmarks.sample_efficiency.summary import Summary

COLORS = {"hippo": "C3", "dqn": "C0", "ppo": "C2", "random": "0.5", "dynaq": "C4"}


def plot_curves(summary: Summary, path: Path, window: int, trials: int) -> None:
    """Success rate and median indirectness against steps, a column per maze (``window``: runs pooled per
    replicate; ``trials``: the hippocampal agent's fresh-agent trials per seed, for the title)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curves = summary.curves
    x = np.asarray(curves.steps)
    panels = list(summary.mazes) + (["all"] if any(k.endswith("/all") for k in curves.series) else [])
    fig, axes = plt.subplots(2, len(panels), figsize=(4.6 * len(panels), 7.2), sharex=True, squeeze=False)
    for col, maze in enumerate(panels):
        for row, metric in enumerate(("success", "indirectness")):
            ax = axes[row, col]
            for v in summary.variants:
                pair = curves.series.get(f"{v}/{maze}")
                if pair is None:
                    continue
                base = v.removesuffix("-dense")
                band = getattr(pair, metric)
                y, lo, hi = (np.array([np.nan if a is None else a for a in values], float) for values in (band.iqm, band.low, band.high))
                style = "--" if v.endswith("-dense") else "-"
                label = v + (" (privileged)" if base == "dynaq" else "")
                ax.plot(x, y, style, color=COLORS.get(base, None), label=label, lw=1.8)
                ax.fill_between(x, lo, hi, color=COLORS.get(base, None), alpha=0.15, lw=0)
            ax.set_xscale("log")
            ax.set_xlim(x[0], x[-1])
            if metric == "success":
                ax.axhline(0.9, color="k", lw=0.7, ls=":")
                ax.set_ylim(-0.03, 1.03)
                ax.set_title(maze if maze != "all" else "all mazes (stratified)")
                ax.set_ylabel("success rate" if col == 0 else "")
            else:
                ax.axhline(1.0, color="k", lw=0.7, ls=":")
                ax.set_yscale("log")
                ax.set_ylim(0.05, 1000)
                ax.set_ylabel("median indirectness" if col == 0 else "")
                ax.set_xlabel("environment steps (dry run included)")
            ax.grid(alpha=0.3, which="both", lw=0.4)
    axes[0, 0].legend(fontsize=8, loc="upper left")
    fig.suptitle(
        f"IQM over seeds, 95 % stratified-bootstrap CI\n(per seed at x: each replicate's run in progress and the {window - 1} before it; hippo: {trials} fresh-agent trials per seed)",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_switch(summary: Summary, path: Path) -> None:
    """The cost of a goal switch, one point per seed: runs and steps before direct again."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mazes = summary.mazes
    variants = summary.variants
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    width = 0.8 / max(len(mazes), 1)
    for k, label in enumerate(("runs", "steps")):
        ax = axes[k]
        for j, maze in enumerate(mazes):
            for i, v in enumerate(variants):
                p = summary.per_seed.get(f"{v}/{maze}")
                if p is None:
                    continue
                keep = [k for k, sw in enumerate(p.switched) if sw]
                if not keep:
                    continue
                values = p.switch_steps if label == "steps" else p.switch_runs_to_direct
                caps = [p.switch_budget if label == "steps" else p.switch_runs[k] for k in keep]
                vals = np.array([np.nan if values[k] is None else values[k] for k in keep], float)
                cap = np.asarray(caps, float)
                xs = i + (j - (len(mazes) - 1) / 2) * width
                never = ~np.isfinite(vals)
                shown = np.where(never, cap, vals) + (1 if label != "steps" else 0)
                ax.scatter(np.full(shown.size, xs), np.maximum(shown, 1), marker="o" if j == 0 else "s", s=22,
                           facecolors=np.where(never, "none", COLORS.get(v.removesuffix("-dense"), "k")).tolist(),
                           edgecolors=COLORS.get(v.removesuffix("-dense"), "k"), label=maze if i == 0 else None)  # fmt: skip
        ax.set_xticks(range(len(variants)), [v + (" (priv.)" if v == "dynaq" else "") for v in variants], rotation=30, ha="right")
        ax.set_yscale("log")
        ax.set_ylim(0.8, None)
        ax.set_ylabel(("runs + 1" if label == "runs" else "steps") + " before direct again")
        ax.grid(alpha=0.3, which="both", lw=0.4)
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(title="maze (open marker: never)", fontsize=8)
    fig.suptitle(
        "Goal switch: once an agent is direct on its goal, the goal moves; cost of becoming direct again\n"
        "(one point per seed that was direct on the first goal; open marker: not direct again within the switch trial)",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
