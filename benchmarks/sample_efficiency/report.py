"""The headline and goal-switch tables as Markdown."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from benchmarks.sample_efficiency.summary import Summary


def fmt_steps(value: float | None, budget: int | None) -> str:
    if value is None:
        return f"> {budget:,}" if budget else "never"
    return f"{value:,.0f}"


def headline_markdown(summary: Summary) -> str:
    """The headline table as Markdown."""
    mazes = summary.mazes
    head = "| agent | " + " | ".join(f"{m}: steps to direct | {m}: x hippo" for m in mazes) + " |"
    lines = [head, "|" + "---|" * (1 + 2 * len(mazes))]
    for row in summary.headline:
        name = row.agent + (" (privileged)" if row.privileged else "")
        cells = []
        for m in mazes:
            cell = row.mazes.get(m)
            if cell is None:
                cells += ["", ""]
                continue
            steps = cell.steps
            cells.append(f"{fmt_steps(steps.median_steps, steps.budget)} ({steps.reached}/{steps.seeds})")
            r = cell.ratio_to_hippo
            if row.agent == "hippo":
                cells.append("1" if steps.median_steps is not None else "n/a")
            else:
                cells.append("n/a" if r is None else (r if isinstance(r, str) else f"{r:g}"))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def switch_markdown(summary: Summary) -> str:
    """The goal-switch table as Markdown: runs and steps before direct again."""
    mazes = summary.mazes
    lines = ["| agent | " + " | ".join(f"{m}: runs | {m}: steps" for m in mazes) + " |", "|" + "---|" * (1 + 2 * len(mazes))]
    for row in summary.headline:
        name = row.agent + (" (privileged)" if row.privileged else "")
        cells = []
        for m in mazes:
            cell = row.mazes[m].switch if m in row.mazes else None
            if cell is None:
                cells += ["", ""]
                continue
            if cell.seeds == 0:
                cells += ["n/a: never direct on the first goal", ""]
                continue
            r = "never" if cell.median_runs is None else f"{cell.median_runs:g}"
            cells.append(f"{r} ({cell.reached}/{cell.seeds})")
            cells.append(fmt_steps(cell.median_steps, cell.budget))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
