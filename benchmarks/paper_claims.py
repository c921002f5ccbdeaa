"""The paper's claims with one column per model: what ``benchmarks.paper`` measured for each.

Reads the ``paper.json`` that ``python -m benchmarks.paper --model paper`` and ``--model default``
wrote and puts their claims side by side in one table (the measurements and the criteria are
those of ``benchmarks/paper.py``; nothing is re-run here).

    python -m benchmarks.paper_claims   # benchmarks/results/REPORT.md from results/paper and results/paper_default
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

from benchmarks.common import REPO, parse_dataclass_args
from hippo_env.files import atomic_write


@dataclasses.dataclass
class ClaimsArgs:
    paper: str = "benchmarks/results/paper"
    """folder of the paper's model's paper.json (``--model paper``)"""
    default: str = "benchmarks/results/paper_default"
    """folder of the default model's paper.json (``--model default``)"""
    out: str = "benchmarks/results/REPORT.md"
    """the Markdown file to write"""


def _cell(text: str) -> str:
    return text.replace("|", "/").replace("\n", " ")


def claims_table(paper: dict[str, Any], default: dict[str, Any]) -> str:
    """One row per claim: the paper's words, then each model's measurement and verdict."""
    by_id = {row["id"]: row for row in default["claims"]}
    lines = [
        "| # | the paper | the paper's model (`AgentConfig.paper()`) | verdict | the default model (`AgentConfig()`) | verdict |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for row in paper["claims"]:
        other = by_id.get(row["id"])
        measured = _cell(other["measured"]) if other else "not measured"
        verdict = f"**{other['verdict']}**" if other else ""
        lines.append(f"| {row['id']} | {_cell(row['paper'])} | {_cell(row['measured'])} | **{row['verdict']}** | {measured} | {verdict} |")
    return "\n".join(lines)


def write_claims(args: ClaimsArgs) -> Path:
    """Write the side-by-side report; returns its path."""
    folders = {"paper": REPO / args.paper, "default": REPO / args.default}
    records = {}
    for model, folder in folders.items():
        path = folder / "paper.json"
        if not path.exists():
            raise SystemExit(f"{path} is missing: run `python -m benchmarks.paper --model {model} --out {folder}` first")
        records[model] = json.loads(path.read_text())
    out = REPO / args.out
    lines = [
        "# The paper's claims, model by model",
        "",
        (
            "Each claim of the paper beside what `benchmarks/paper.py` measured with the model as the paper describes it "
            "(`AgentConfig.paper()`: the rangefinder and the compass only) and with the default model (`AgentConfig()`: "
            "wheel odometry integrated into a position estimate, a dry run directed by the agent's own map with `W_pp` "
            "learning, and homing along its map to where the goal was found). "
            "The criteria behind each verdict, the figures and the details are in each model's own report; which verdicts "
            "moved with each change of the model, and why, is in [CHANGELOG.md](../../CHANGELOG.md)."
        ),
        "",
        *[
            f"- {model}: [{folder.relative_to(out.parent) if folder.is_relative_to(out.parent) else folder}/REPORT.md]"
            f"({folder.relative_to(out.parent) if folder.is_relative_to(out.parent) else folder}/REPORT.md), made by "
            f"`{records[model]['command']}`"
            for model, folder in folders.items()
        ],
        "",
        claims_table(records["paper"], records["default"]),
        "",
        "Made by `python -m benchmarks.paper_claims`.",
        "",
    ]
    atomic_write(out, "\n".join(lines))
    return out


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(ClaimsArgs, __doc__.splitlines()[0], argv)
    print(f"wrote {write_claims(args)}")


if __name__ == "__main__":
    main()
