"""The README's results table, made from the committed records and the targets; nothing typed in.

Every row is a figure measured and committed under ``benchmarks/results/`` (read by
:mod:`benchmarks.records`) beside its target (``benchmarks/targets.toml``); a speed is a ratio
of two programs timed side by side in one run, and where the committed record holds no such
ratio the row says "not measured yet". The table sits in README.md between two marker comments
(:data:`BEGIN`, :data:`END`); ``tests/test_readme_table.py`` fails when it differs from what this
module makes.

    python -m benchmarks.readme_table           # rewrites the table in README.md
    python -m benchmarks.readme_table --check   # exits 1 if README.md's table is not what it makes
"""

from __future__ import annotations

import argparse
import re
import sys
import textwrap
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from benchmarks import records
from benchmarks.records import MIN_EXPLOIT_SHARE, num, pct, spread, table
from benchmarks.targets import generated_maze, shown, target

README = Path(__file__).resolve().parent.parent / "README.md"
BEGIN = "<!-- results table: made by `python -m benchmarks.readme_table` from benchmarks/results and benchmarks/targets.toml -->"
END = "<!-- end of the results table -->"
#: The most rows the table may have.
MAX_ROWS = 12
NOT_MEASURED = "not measured yet"
INTRO = (
    "Measured and committed under `benchmarks/results/`: the default model (`AgentConfig()`) unless said otherwise,"
    " each figure beside its target (`benchmarks/targets.toml`). DMTP figures are from runner seeds never used in tuning."
    " A speed is a ratio of two programs timed in turn in one run, repeat by repeat: the median over the repeats"
    " (quartiles in brackets)."
)


def outcome(checks: Iterable[bool | None]) -> str:
    """One verdict for several checks: ``met`` if all are, ``**missed**`` if any is not, else ``not measured``."""
    checks = list(checks)
    if any(c is False for c in checks):
        return "**missed**"
    return "met" if checks and all(c is True for c in checks) else "not measured"


def mazes_label(keys: list[str]) -> str:
    """The mazes one bound is for, short: ``open``, ``maze1-4``, ``10 m perfect``."""
    numbered = sorted((k for k in keys if re.fullmatch(r"maze\d+", k)), key=lambda k: int(k[4:]))
    numbers = [int(k[4:]) for k in numbered]
    labels = []
    if len(numbered) > 2 and numbers == list(range(numbers[0], numbers[-1] + 1)):
        labels.append(f"{numbered[0]}-{numbers[-1]}")
    else:
        labels += numbered
    for key in keys:
        match = re.fullmatch(r"gen-([a-z]+)-(\d+)m", key)
        if key not in numbered:
            labels.append(f"{match[2]} m {match[1]}" if match else key)
    return ", ".join(labels)


# ------------------------------------------------------------------ the model's behaviour


def maze_rows() -> list[list[str]]:
    """The maze suite: the built-in and the generated mazes (runs 2-4 median indirectness), and the dry run's length."""
    data = records.load("maze_suite_default.json")
    by_maze: dict[str, list[dict[str, Any]]] = {}
    for row in data["rows"]:
        by_maze.setdefault(row["maze"], []).append(row)
    seeds = " / ".join(str(s) for s in sorted({row["seed"] for row in data["rows"]}))
    indirectness, reached, dry_run = target("indirectness"), target("reached"), target("dry_run_length")
    built_in = [m for m in by_maze if generated_maze(m) is None]
    generated = [m for m in by_maze if generated_maze(m) is not None]
    rows = [
        [
            f"{' / '.join(built_in)}: runs 2-4 median indirectness, the worse of seeds {seeds}",
            " / ".join(num(max(records.later_runs_median(r) for r in by_maze[m])) for m in built_in),
            "<= "
            + " / ".join(shown(indirectness.bound(m)) for m in built_in)
            + ": "
            + outcome(indirectness.met(records.later_runs_median(r), m) for m in built_in for r in by_maze[m]),
        ]
    ]
    if generated:
        sizes = sorted({generated_maze(m)[1] for m in generated})
        medians = [records.later_runs_median(r) for m in generated for r in by_maze[m]]
        shares = [r["runs_2_4_reached"] for m in generated for r in by_maze[m]]
        bounds = sorted({b for b in (indirectness.bound(m) for m in generated) if b is not None})
        checks = [indirectness.met(v, m) for m in generated for v in map(records.later_runs_median, by_maze[m])]
        checks += [reached.met(r["runs_2_4_reached"], m) for m in generated for r in by_maze[m]]
        rows.append(
            [
                f"{len(generated)} generated mazes, {num(sizes[0])}-{num(sizes[-1])} m: the same; runs 2-4 reaching the goal",
                f"{num(min(medians))}-{num(max(medians))}; "
                + (f"{pct(min(shares))} reached" if min(shares) == max(shares) else f"{pct(min(shares))}-{pct(max(shares))} reached"),
                f"<= {' / '.join(shown(b) for b in bounds)}, {reached.op} {pct(reached.bound(generated[0]))} reached: {outcome(checks)}",
            ]
        )
    groups: dict[float, list[str]] = {}
    for key, bound in dry_run.limits.items():
        groups.setdefault(bound, []).append(key)
    longest = [
        max((r["dry_run_steps_median"] for m in by_maze if dry_run.bound(m) == b for r in by_maze[m]), default=None) for b in sorted(groups)
    ]
    unnamed = [r["dry_run_steps_median"] for m in by_maze if dry_run.bound(m) is None for r in by_maze[m]]
    rows.append(
        [
            "dry-run length, median steps: the longest under each target",
            " / ".join(num(v) for v in longest) + (f" ({num(max(unnamed))} in a maze no target names)" if unnamed else ""),
            "<= "
            + " / ".join(f"{shown(bound)} ({mazes_label(keys)})" for bound, keys in sorted(groups.items()))
            + ": "
            + outcome(dry_run.met(r["dry_run_steps_median"], m) for m in by_maze for r in by_maze[m] if dry_run.bound(m) is not None),
        ]
    )
    return rows


def sample_efficiency_rows() -> list[list[str]]:
    """Steps until the model runs directly to the goal, and again after the goal moves, beside DQN and PPO."""
    data = records.load("sample_efficiency.json")
    variants, args = data["statistics"]["variants"], data["args"]
    goal = target("steps_to_direct")
    mazes = [m for m in data["statistics"]["mazes"] if goal.bound(m) is not None]

    def steps(variant: str, key: str, budget: int) -> str:
        return " / ".join(num(p) if p is not None else f"> {num(budget)}" for p in (variants[variant][key][m][0] for m in mazes))

    hippo = variants["hippo"]
    seeds = max(hippo["direct"][m][1] for m in mazes)
    peers = [v for v in ("ppo", "dqn") if v in variants]
    direct = [
        f"steps to a direct run (the dry run included), IQM of {seeds} seeds: {' / '.join(mazes)}",
        steps("hippo", "steps_to_direct", args["budget"])
        + (" (" + "; ".join(f"{v.upper()} {steps(v, 'steps_to_direct', args['budget'])}" for v in peers) + ")" if peers else ""),
        "<= "
        + " / ".join(shown(goal.bound(m)) for m in mazes)
        + ": "
        + outcome(goal.met(hippo["steps_to_direct"][m][0], m) for m in mazes),
    ]
    never = [v.upper() for v in peers if all(variants[v]["after_switch"][m][0] is None for m in mazes)]
    again = [
        f"after the goal moves, steps until direct again: {' / '.join(mazes)}",
        steps("hippo", "after_switch", args["switch_budget"])
        + (f"; {' and '.join(never)} not within {num(args['switch_budget'])}" if never else ""),
        "-",
    ]
    return [direct, again]


def paper_row() -> list[str]:
    """The paper's claims: how many each model reproduces (the project's own targets, ids ``T...``, left out)."""
    counts = []
    for name in ("paper/paper.json", "paper_default/paper.json"):
        claims = [c for c in records.load(name)["claims"] if not c["id"].startswith("T")]
        counts.append(
            {v: sum(c["verdict"] == v for c in claims) for v in ("reproduced", "partly", "not reproduced")} | {"all": len(claims)}
        )
    paper, default = counts
    return [
        f"the paper's {paper['all']} claims: the paper's model / the default model",
        ", ".join(f"{v} {paper[v]} / {default[v]}" for v in ("reproduced", "partly", "not reproduced")),
        "-",
    ]


# ------------------------------------------------------------------ speed


def agent_speed_rows() -> list[list[str]]:
    """The ratios ``benchmarks.agent_throughput`` timed side by side; "not measured yet" where the record has none."""
    data = records.load("agent_throughput.json")
    out = []
    for name, key, what in (
        ("agent_vs_ratinabox", "default_x_ratinabox", "steps/s over RatInABox's"),
        ("default_vs_paper", "default_x_paper", "steps/s over the paper's model's"),
        ("dry_run_step", "dry_run_step_x_exploiting_step", "time of a dry-run step over an exploiting step's"),
    ):
        goal = target(name)
        row = records.side_by_side(data, goal["place_cells"])
        summary = None if row is None else row["ratios"].get(key)
        idle = row is not None and min(row["exploit_share"].values()) < MIN_EXPLOIT_SHARE
        label = f"the default model at {num(goal['place_cells'])} place cells: {what}"
        if summary is None or idle:
            out.append([label, NOT_MEASURED if not idle else "not measured: the agent hardly exploited", goal.text(unit="x")])
        else:
            out.append([label, spread(summary), f"{goal.text(unit='x')}: {outcome([goal.met(summary['median'])])}"])
    return out


def scaling_rows() -> list[list[str]]:
    """Both models at 10,000 place cells (``agent_scaling_<model>.json``)."""
    figures = [records.scaling_figures(records.load(f"agent_scaling_{model}.json")) for model in ("default", "paper")]
    speed, memory, replay = target("scaling_speed"), target("scaling_memory_mb"), target("scaling_replay_ms")
    cells = f"{num(speed['place_cells'])} place cells, default / paper's model"

    def measured(key: str, unit: str, digits: int = 2) -> str:
        return " / ".join(num(round(f[key], digits)) if f["measured"] else NOT_MEASURED for f in figures) + unit

    def verdicts(goal: Any, key: str) -> str:
        return " / ".join(outcome([goal.met(f[key]) if f["measured"] else None]) for f in figures)

    return [
        [
            f"{cells}: speed over {num(speed['against_place_cells'])} cells' (slower walk); peak memory; one replay",
            f"{measured('speed_ratio', 'x')}; {measured('peak_rss_mb', ' MB', 0)}; {measured('replay_ms', ' ms', 0)}",
            f"{speed.text(unit='x')}; {memory.text(unit=' MB')}; {replay.text(unit=' ms')}: "
            + outcome(
                [speed.met(f["speed_ratio"]) if f["measured"] else None for f in figures]
                + [memory.met(f["peak_rss_mb"]) if f["measured"] else None for f in figures]
                + [replay.met(f["replay_ms"]) if f["measured"] else None for f in figures]
            ),
        ],
    ]


# ------------------------------------------------------------------ a world that changes


def share(goal: Any) -> str:
    """A target on a share, as a percentage: ``>= 95 %``."""
    return f"{goal.op} {pct(goal.bound())}"


def changing_world_row() -> list[str]:
    """New blocks round a known goal, a door cut, a known world again (``changing_world.json``, the default model)."""
    summary = records.load("changing_world.json")["summary"]["hippo"]
    blocks, shortcut, worlds = summary["barriers"], summary["shortcut"], summary["worlds"]
    first, success, indirect = target("changed_first_run_success"), target("changed_success"), target("changed_indirectness")
    door, back = target("shortcut_taken"), target("worlds_return")
    label = "changed world: new blocks, first / all runs reached, indirectness; a door taken; run 1 back in a known world"
    measured = (
        f"{pct(blocks['first_run_success'])} / {pct(blocks['success'])}, {num(blocks['median_indirectness_of_successes'])};"
        f" {pct(shortcut['taken'])}; {num(worlds['run1_back_median'])}"
    )
    return [
        label,
        measured,
        f"{share(first)} / {share(success)}, {indirect.text()}; {share(door)}; {back.text()}: "
        + outcome(
            [
                first.met(blocks["first_run_success"]),
                success.met(blocks["success"]),
                indirect.met(blocks["median_indirectness_of_successes"]),
                door.met(shortcut["taken"]),
                back.met(worlds["run1_back_median"]),
            ]
        ),
    ]


def env_row() -> list[str]:
    """The environment beside Gymnasium-Robotics' point maze (``env_throughput.json``)."""
    goal = target("env_vs_pointmaze")
    peer = records.env_peer(records.load("env_throughput.json"))
    label = "the environment, 720 rays: steps/s over PointMaze_UMaze's, the slowest maze"
    if peer is None:
        return [label, NOT_MEASURED, goal.text(unit="x")]
    spread_text = f"{num(min(peer['per_maze'].values()))}-{num(max(peer['per_maze'].values()))}x over the mazes"
    if peer["slowest_quartiles"]:
        spread_text = f"{num(peer['slowest_quartiles'][0])}-{num(peer['slowest_quartiles'][1])}x; {spread_text}"
    return [label, f"{num(peer['slowest'])}x ({spread_text})", f"{goal.text(unit='x')}: {outcome([goal.met(peer['slowest'])])}"]


# ------------------------------------------------------------------ the README


def rows() -> list[list[str]]:
    return [
        *maze_rows(), *sample_efficiency_rows(), changing_world_row(), paper_row(), *agent_speed_rows(), *scaling_rows(), env_row(),
    ]  # fmt: skip


def block() -> str:
    """What stands between the markers: the introduction and the table."""
    made = rows()
    if len(made) > MAX_ROWS:
        raise ValueError(f"the README's results table has {len(made)} rows; at most {MAX_ROWS}")
    return f"{textwrap.fill(INTRO, 99)}\n\n{table(['what', 'measured', 'target'], made)}"


def in_readme(text: str) -> str:
    """The block between the markers of a README's text.

    Raises:
        ValueError: the markers are missing or out of order.
    """
    begin, end = text.find(BEGIN), text.find(END)
    if begin < 0 or end < begin:
        raise ValueError(f"README.md has no results table between {BEGIN!r} and {END!r}")
    return text[begin + len(BEGIN) : end].strip("\n")


def updated(text: str) -> str:
    """A README's text with the block between the markers made anew."""
    in_readme(text)  # the markers are there
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{BEGIN}\n{block()}\n{END}{tail}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if README.md's table is not what this makes; write nothing")
    args = parser.parse_args(argv)
    text = README.read_text()
    new = updated(text)
    if args.check:
        if new != text:
            print("README.md's results table is out of date: run python -m benchmarks.readme_table", file=sys.stderr)
            return 1
        return 0
    if new != text:
        README.write_text(new)
        print(f"rewrote the results table in {README}")
    else:
        print("README.md's results table is up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main())
