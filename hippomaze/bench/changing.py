"""``hippomaze bench --changing-world``: an agent in a world that changes, beside the shipped references.

The tasks and measures are :mod:`hippomaze.changing_world`'s (new blocks round a known goal, walls
added or removed in mazes, a shortcut, several worlds), run on the runner seeds the references
were measured on (11, 12, ...), so the agent faces the same layouts, goals and starts. Writes
``OUT/changing_world.json`` (the measures, the references', every run), ``OUT/changing_world.md``
and ``OUT/changing_world_by_layout.png`` (each changed layout's measures, beside the references').
"""

from __future__ import annotations

import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from hippo_env.files import write_json
from hippomaze.bench.references import CHANGING_WORLD, folder
from hippomaze.changing_world import MAZES, TASKS, run_task, summarise

#: The first runner seed of the references; ``--seeds N`` runs seeds FIRST_SEED .. FIRST_SEED + N - 1.
FIRST_SEED = 11
#: The table's columns: (heading, task, measure).
COLUMNS = (
    ("blocks: first run", "barriers", "first_run_success"),
    ("blocks: all runs", "barriers", "success"),
    ("blocks: indirectness", "barriers", "median_indirectness_of_successes"),
    ("blocks: position", "barriers", "position_within_0_5m"),
    ("mazes: first run", "mazes", "first_run_success"),
    ("mazes: indirectness", "mazes", "median_indirectness_of_successes"),
    ("shortcut taken", "shortcut", "taken"),
    ("worlds: run 1 back", "worlds", "run1_back_median"),
)


def reference_summary() -> dict[str, Any]:
    """The shipped references' measures, by agent (empty if none are shipped)."""
    path = folder() / f"{CHANGING_WORLD}.json"
    return json.loads(path.read_text())["summary"] if path.exists() else {}


def measure(summary: dict[str, Any], task: str, name: str) -> float | None:
    """One measure of an agent's summary (:func:`hippomaze.changing_world.summarise`)."""
    entry = summary.get(task, {})
    return (entry.get("all", {}) if task == "mazes" else entry).get(name)


def table(summaries: dict[str, dict[str, Any]]) -> str:
    """A markdown table: one row per agent, one column per measure."""
    lines = ["| agent | " + " | ".join(c[0] for c in COLUMNS) + " |", "|---" * (len(COLUMNS) + 1) + "|"]
    for agent, summary in summaries.items():
        cells = [measure(summary, task, name) for _, task, name in COLUMNS]
        lines.append(f"| {agent} | " + " | ".join("-" if v is None else f"{v:.2f}" for v in cells) + " |")
    return "\n".join(lines)


def run_changing_world(agent: str, seeds: int, out: str | Path, workers: int = 2, label: str = "") -> dict[str, Any]:
    """Run the changing-world tasks for ``agent`` (a registry name or ``module:Class``) on ``seeds``
    runner seeds, write the results to ``out`` and return them."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    label = label or agent
    jobs = [
        (agent, seed, task, maze)
        for seed in range(FIRST_SEED, FIRST_SEED + seeds)
        for task in TASKS
        for maze in (MAZES if task == "mazes" else ("",))
    ]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        rows = list(pool.map(run_task, *zip(*jobs)))
    summary = summarise(rows)[agent]
    references = reference_summary()
    document = {
        "agent": agent,
        "label": label,
        "seeds": list(range(FIRST_SEED, FIRST_SEED + seeds)),
        "summary": summary,
        "references": references,
        "table_markdown": table({label: summary, **references}),
        "rows": rows,
    }
    write_json(out / "changing_world.json", document)
    (out / "changing_world.md").write_text(document["table_markdown"] + "\n")
    plot_by_layout({label: summary, **references}, out / "changing_world_by_layout.png")
    return document


def plot_by_layout(summary: dict[str, Any], path: Path) -> bool:
    """Bars of each changed layout's measures (``barriers_by_layout``, ``mazes_by_change``) per
    agent: runs reaching the goal, anchored steps within 0.5 m and the successes' median
    indirectness, with the targets dashed. ``False`` (nothing drawn) if no agent has such measures."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    layouts: dict[str, dict[str, dict[str, Any]]] = {}  # agent -> layout label -> measures
    for agent, entry in summary.items():
        mine = {name: m for name, m in entry.get("barriers_by_layout", {}).items()}
        mine.update({f"maze: {name}": m for name, m in entry.get("mazes_by_change", {}).items()})
        if mine:
            layouts[agent] = mine
    if not layouts:
        return False
    labels = list(dict.fromkeys(label for mine in layouts.values() for label in mine))
    panels = (
        ("success", "runs reaching the goal", 0.95),
        ("position_within_0_5m", "anchored steps within 0.5 m", 0.95),
        ("median_indirectness_of_successes", "median indirectness of successes", 0.3),
    )
    fig, axes = plt.subplots(len(panels), 1, figsize=(max(7.0, 0.9 * len(labels)), 8.5), sharex=True)
    width = 0.8 / len(layouts)
    x = np.arange(len(labels))
    for k, (agent, mine) in enumerate(layouts.items()):
        for ax, (key, _, _) in zip(axes, panels):
            values = [mine.get(label, {}).get(key) for label in labels]
            ax.bar(x + (k - (len(layouts) - 1) / 2) * width, [np.nan if v is None else v for v in values], width, label=agent)
    for ax, (_, title, goal) in zip(axes, panels):
        ax.axhline(goal, color="k", ls="--", lw=1)
        ax.set_ylabel(title, fontsize=9)
    axes[-1].set_yscale("log")  # (a random walk's rare successes are tens of times the shortest way)
    axes[0].legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    axes[-1].set_xticks(x, labels, rotation=30, ha="right", fontsize=9)
    axes[0].set_title("each changed layout apart (targets dashed)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True
