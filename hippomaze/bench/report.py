"""The comparison as a short Markdown table."""

from __future__ import annotations

from hippomaze.bench.summary import ALL, Comparison, Reached, VariantResult
from hippomaze.stats import Interval


def fmt_steps(value: float | None, budget: int | None) -> str:
    """Steps with thousands separators; ``None`` (never within the budget) as "> budget"."""
    if value is None:
        return f"> {budget:,}" if budget else "never"
    return f"{value:,.0f}"


def steps_cell(interval: Interval | None, reached: Reached | None, budget: int | None) -> str:
    """``IQM [low, high] (reached/seeds)``; "n/a" where there is nothing to measure."""
    if interval is None or reached is None or reached.seeds == 0:
        return "n/a"
    text = fmt_steps(interval.point, budget)
    if interval.low is not None or interval.high is not None:
        text += f" [{fmt_steps(interval.low, budget)}, {fmt_steps(interval.high, budget)}]"
    return f"{text} ({reached.reached}/{reached.seeds})"


def probability_cell(interval: Interval | None) -> str:
    if interval is None or interval.point is None:
        return ""
    if interval.low is None or interval.high is None:
        return f"{interval.point:.2f}"
    return f"{interval.point:.2f} [{interval.low:.2f}, {interval.high:.2f}]"


def comparison_markdown(comparison: Comparison, results: dict[str, VariantResult], names: dict[str, str] | None = None) -> str:
    """One row per variant: IQM steps to direct per maze and over all mazes, steps to direct again
    after a goal switch per maze, and P(the focus variant is faster). ``names``: how to show a variant."""
    names = names or {}
    mazes = comparison.mazes
    columns = [f"{m}: steps to direct" for m in mazes] + (["all mazes"] if len(mazes) >= 2 else [])
    columns += [f"{m}: after a goal switch" for m in mazes] + [f"P({names.get(comparison.focus, comparison.focus)} faster)"]
    lines = ["| agent | " + " | ".join(columns) + " |", "|" + "---|" * (1 + len(columns))]
    for variant, s in comparison.variants.items():
        result = results[variant]
        budget, switch_budget = result.protocol.get("budget"), result.protocol.get("switch_budget")
        name = names.get(variant, variant) + (" (privileged)" if result.privileged else "")
        cells = [steps_cell(s.steps_to_direct.get(m), s.direct.get(m), budget) for m in mazes]
        if len(mazes) >= 2:
            cells.append(steps_cell(s.steps_to_direct.get(ALL), s.direct.get(ALL), budget))
        for m in mazes:
            again = s.direct_again.get(m)
            if again is not None and again.seeds == 0:
                cells.append("n/a: never direct")
            else:
                cells.append(steps_cell(s.after_switch.get(m), again, switch_budget))
        cells.append("" if variant == comparison.focus else probability_cell(s.focus_faster))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
