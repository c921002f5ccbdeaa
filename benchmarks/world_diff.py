"""Two records of :mod:`benchmarks.changing_world` compared layout by layout: where a change to an
agent moved the figures, and whether by more than the runs' own scatter.

``python -m benchmarks.world_diff --base BASE.json --new NEW.json`` pairs the records' changed
layouts (same agent, seed, task, maze and phase: both records made with the same seeds) and prints,
per agent and task:

- each record's headline measures (first runs and all runs reaching the goal, the successes'
  median indirectness, anchored steps within 0.5 m, and in the ``mazes`` task the door taken);
- the layouts whose first run reached the goal in one record only, with an exact two-sided sign
  test (McNemar's) on those discordant pairs: any change to the course of a run moves the runs
  after it, so a first run or two either way among a few hundred layouts is what every change gives;
- how many schedules ran identically in both (every run's steps and path length the same): a change
  that never acts leaves them so.

``--out FILE`` writes the same as JSON.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

from benchmarks.common import command_line, parse_dataclass_args
from hippo_env.files import write_json
from hippomaze.changing_world import layout_measures, shortcut_measures

MEASURES = (
    ("first_run_success", "first runs reaching the goal", "share"),
    ("success", "runs reaching the goal", "share"),
    ("median_indirectness_of_successes", "median indirectness of successes", "value"),
    ("position_within_0_5m", "anchored steps within 0.5 m", "share"),
)


@dataclasses.dataclass
class WorldDiffArgs:
    base: str = ""
    """the first record (changing_world.py --out), e.g. the code before a change"""
    new: str = ""
    """the second record, made with the same seeds and tasks"""
    out: str = ""
    """also write the comparison as JSON here ('' = print only)"""


def sign_test(only_base: int, only_new: int) -> float:
    """Exact two-sided p-value of a sign test on ``only_base`` against ``only_new`` discordant pairs
    (1.0 with none): how often a fair coin splits them at least this unevenly."""
    n = only_base + only_new
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, k) for k in range(min(only_base, only_new) + 1)) / 2**n
    return min(1.0, 2.0 * tail)


def first_runs(rows: list[dict[str, Any]]) -> dict[tuple[Any, ...], bool]:
    """Whether each changed layout's first run reached the goal, by (seed, task, maze, phase name)
    (the first runs :func:`hippomaze.changing_world.layout_measures` counts)."""
    out = {}
    for row in rows:
        for r in row["runs"]:
            if r["phase"] > 0 and r["run"] == 0:
                out[(row["seed"], row["task"], row["maze"], row["phases"][r["phase"]])] = bool(r["success"])
    return out


def _course(row: dict[str, Any]) -> list[tuple[int, float]]:
    return [(r["steps"], r["path_length"]) for r in row["runs"]]


def compare(base_rows: list[dict[str, Any]], new_rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Per agent and task present in both records: each one's measures, the discordant first runs
    with their sign test, and the schedules that ran identically."""
    out: dict[str, Any] = {}
    for agent in dict.fromkeys(r["agent"] for r in base_rows):
        for task in dict.fromkeys(r["task"] for r in base_rows if r["agent"] == agent):
            if task == "worlds":
                continue  # (no changed layouts to pair: hippomaze bench reports the return)
            base = {(r["seed"], r["maze"]): r for r in base_rows if r["agent"] == agent and r["task"] == task}
            new = {(r["seed"], r["maze"]): r for r in new_rows if r["agent"] == agent and r["task"] == task}
            shared = [k for k in base if k in new]
            if not shared:
                continue
            a, b = [base[k] for k in shared], [new[k] for k in shared]
            firsts_a, firsts_b = first_runs(a), first_runs(b)
            paired = [k for k in firsts_a if k in firsts_b]
            only_base = [k for k in paired if firsts_a[k] and not firsts_b[k]]
            only_new = [k for k in paired if firsts_b[k] and not firsts_a[k]]
            entry = {
                "schedules": len(shared),
                "identical_schedules": sum(_course(x) == _course(y) for x, y in zip(a, b)),
                "base": layout_measures(a),
                "new": layout_measures(b),
                "first_run_reached_in_base_only": [list(k) for k in only_base],
                "first_run_reached_in_new_only": [list(k) for k in only_new],
                "first_runs_sign_test_p": sign_test(len(only_base), len(only_new)),
            }
            if task == "mazes":
                entry["base"]["door"] = shortcut_measures(a)
                entry["new"]["door"] = shortcut_measures(b)
            out.setdefault(agent, {})[task] = entry
    return out


def report(comparison: dict[str, Any]) -> str:
    """The comparison as text."""
    lines = []
    for agent, tasks in comparison.items():
        for task, e in tasks.items():
            lines.append(f"{agent}, {task}: {e['base']['layouts']} changed layouts in {e['schedules']} schedules")
            for key, label, kind in MEASURES:
                x, y = e["base"][key], e["new"][key]
                lines.append(f"  {label:34s} {_fmt(x, kind):>8s} -> {_fmt(y, kind)}")
            if "door" in e["base"]:
                xd, yd = e["base"]["door"], e["new"]["door"]
                lines.append(f"  {'door taken (runs after the first)':34s} {_taken(xd):>8s} -> {_taken(yd)}")
            lines.append(
                f"  first runs reaching the goal in one record only: base {len(e['first_run_reached_in_base_only'])}, "
                f"new {len(e['first_run_reached_in_new_only'])} (sign test p = {e['first_runs_sign_test_p']:.2f})"
            )
            for which in ("base", "new"):
                for seed, _, maze, phase in e[f"first_run_reached_in_{which}_only"]:
                    lines.append(f"    {which} only: seed {seed} {maze or 'open arena'}, {phase}")
            lines.append(f"  schedules that ran identically: {e['identical_schedules']} of {e['schedules']}")
    return "\n".join(lines)


def _fmt(x: float | None, kind: str) -> str:
    if x is None:
        return "-"
    return f"{100 * x:.1f} %" if kind == "share" else f"{x:.3f}"


def _taken(door: dict[str, Any]) -> str:
    share = door["taken"]
    return "-" if share is None else f"{round(share * door['runs'])} of {door['runs']}"


def _record(path: str) -> dict[str, Any]:
    """A record of :mod:`benchmarks.changing_world` read from ``path``; exits naming what was wrong."""
    try:
        record = json.loads(Path(path).read_text())
    except (OSError, ValueError) as exc:
        raise SystemExit(f"{path}: not a record of benchmarks.changing_world ({exc})") from exc
    if not isinstance(record, dict) or not isinstance(record.get("rows"), list):
        raise SystemExit(f"{path}: not a record of benchmarks.changing_world (no 'rows' list)")
    return record


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(WorldDiffArgs, __doc__, argv)
    if not args.base or not args.new:
        raise SystemExit("world_diff needs --base and --new: two records of python -m benchmarks.changing_world")
    records = [_record(path) for path in (args.base, args.new)]
    comparison = compare(records[0]["rows"], records[1]["rows"])
    if not comparison:
        raise SystemExit("the two records share no agent, task and seed to compare")
    print(report(comparison))
    if args.out:
        made_by = {"base": records[0].get("command"), "new": records[1].get("command")}  # (each record's own command)
        write_json(args.out, {"command": command_line(), "base": args.base, "new": args.new, "made_by": made_by, "comparison": comparison})
        print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
