"""The bench figure: learning curves per maze, the performance profiles and the IQM steps to direct."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hippomaze.bench.summary import ALL, Comparison, VariantResult

#: Colours of the known variants; any other (the user's agent) is drawn in FOCUS_COLOUR.
COLOURS = {"hippo": "C3", "hippo-paper": "C1", "dqn": "C0", "ppo": "C2", "random": "0.55", "dynaq": "C4"}
FOCUS_COLOUR = "k"


def _colour(variant: str, focus: str) -> str:
    base = variant.removesuffix("-dense")
    return COLOURS.get(base, FOCUS_COLOUR if variant == focus else "C5")


def _wrapped(name: str, width: int = 14) -> str:
    """A long variant name on two lines, after its ``module:`` part (``mypackage.agents:\nGreedyAgent``)."""
    module, colon, rest = name.rpartition(":")
    return f"{module}{colon}\n{rest}" if colon and len(name) > width else name


def _values(values: list[float | None]) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], float)


def plot_bench(results: dict[str, VariantResult], comparison: Comparison, path: Path, names: dict[str, str] | None = None) -> None:
    """Write the figure to ``path``: a column per maze (and all mazes), success rate above, median
    indirectness below; a last column with the performance profiles and the IQM steps to direct.

    ``names``: how to label a variant (default: its name).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = names or {}
    focus = comparison.focus
    panels = comparison.mazes + ([ALL] if len(comparison.mazes) >= 2 else [])
    order = [v for v in comparison.variants if v != focus] + [focus]  # the focus drawn last, on top
    fig, axes = plt.subplots(2, len(panels) + 1, figsize=(4.3 * (len(panels) + 1), 7.4), squeeze=False)
    for col, maze in enumerate(panels):
        for row, metric in enumerate(("success", "indirectness")):
            ax = axes[row, col]
            for v in order:
                curve = results[v].curves.get(maze)
                if curve is None:
                    continue
                band = getattr(curve, metric)
                x, y = np.asarray(curve.steps), _values(band.iqm)
                colour, wide = _colour(v, focus), 2.4 if v == focus else 1.5
                ax.plot(x, y, "--" if v.endswith("-dense") else "-", color=colour, lw=wide, label=names.get(v, v))
                ax.fill_between(x, _values(band.low), _values(band.high), color=colour, alpha=0.15, lw=0)
            ax.set_xscale("log")
            ax.grid(alpha=0.3, which="both", lw=0.4)
            if metric == "success":
                ax.axhline(0.9, color="k", lw=0.7, ls=":")
                ax.set_ylim(-0.03, 1.03)
                ax.set_title(maze if maze != ALL else "all mazes (stratified)")
                ax.set_ylabel("success rate (last 10 runs)" if col == 0 else "")
            else:
                ax.axhline(1.0, color="k", lw=0.7, ls=":")
                ax.set_yscale("log")
                ax.set_ylim(0.03, 1000)
                ax.set_ylabel("median indirectness (last 10 runs)" if col == 0 else "")
                ax.set_xlabel("environment steps (dry run included)")
    axes[0, 0].legend(fontsize=7.5, loc="upper left")

    ax = axes[0, -1]  # performance profiles
    taus = np.asarray(comparison.taus)
    for v in order:
        profile = comparison.variants[v].profile
        if not profile:
            continue
        colour = _colour(v, focus)
        ax.plot(taus, _values(profile["share"]), color=colour, lw=2.4 if v == focus else 1.5, drawstyle="steps-post")
        ax.fill_between(taus, _values(profile["low"]), _values(profile["high"]), color=colour, alpha=0.15, lw=0, step="post")
    ax.set_xscale("log")
    ax.set_ylim(-0.03, 1.03)
    ax.grid(alpha=0.3, which="both", lw=0.4)
    ax.set_title("performance profile")
    ax.set_ylabel("share of seeds x mazes direct")
    ax.set_xlabel("within this many steps")

    ax = axes[1, -1]  # IQM steps to direct, all mazes (or the one maze), and after a goal switch
    key = ALL if len(comparison.mazes) >= 2 else comparison.mazes[0]
    rows = [v for v, s in comparison.variants.items() if key in s.steps_to_direct]  # those that ran in every maze
    for i, v in enumerate(rows):
        s, colour = comparison.variants[v], _colour(v, focus)
        switched = s.direct_again.get(key)
        after = s.after_switch.get(key) if switched is not None and switched.seeds else None
        caps = (results[v].horizon, results[v].protocol.get("switch_budget") or results[v].horizon)
        for offset, interval, marker, cap in ((-0.15, s.steps_to_direct.get(key), "o", caps[0]), (0.15, after, "s", caps[1])):
            if interval is None:
                continue
            never = interval.point is None  # drawn at its budget, hollow
            shown = cap if never else interval.point
            low = shown if interval.low is None else interval.low
            high = cap if interval.high is None and interval.low is not None else (shown if interval.high is None else interval.high)
            ax.plot([low, high], [i + offset] * 2, color=colour, lw=2)
            ax.plot([shown], [i + offset], marker=marker, color=colour, mfc="none" if never else colour, ms=6)
    ax.set_yticks(range(len(rows)), [_wrapped(names.get(v, v)) for v in rows], fontsize=8)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.grid(alpha=0.3, which="both", lw=0.4, axis="x")
    ax.set_xlabel("steps (o: to direct, s: after a switch)")
    ax.set_title("IQM, 95 % interval" + (" (all mazes)" if key == ALL else ""), fontsize=10)
    fig.suptitle(
        "IQM over seeds with 95 % stratified-bootstrap intervals (rliable); open marker: not direct within the budget",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
