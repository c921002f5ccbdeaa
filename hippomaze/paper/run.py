"""A paper run from end to end: the tasks through the pool, their records gathered, the claims
assessed, then the figures, REPORT.md and paper.json written."""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path
from typing import Any

import hippo_env
from hippo_env.files import jsonable
from hippomaze.runinfo import source_digest

from .analysis import dmtp_summary
from .args import PaperArgs, parse_args
from .claims import assess
from .design import MAZES, OBSTACLE_MAZES, SCENARIOS, TRIAL_SEED_STRIDE, trial_seed
from .experiments import build_tasks, merge_trials
from .figures import draw_figures
from .pool import run_tasks
from .report import write_report
from .results import DMTPOutcome, FieldsResult, GeneralisationResult, MapEntry, PaperData, SameStart, SameStartTrial, TrialResult


def run_paper(args: PaperArgs) -> dict[str, Any]:
    """Run every experiment, write the figures, REPORT.md and paper.json into ``args.out``; return paper.json's content."""
    began = time.perf_counter()
    requested = args
    args = args.resolved()
    args.validate()
    Path(args.out).mkdir(parents=True, exist_ok=True)
    sources = source_digest()  # before the workers import the code: this is what runs
    results, seconds = run_tasks(build_tasks(args), args.workers, args.progress)
    return write_outputs(requested, results, seconds, began, sources)


def _same_start_trial(task: TrialResult) -> SameStartTrial:
    records = task.result.run_records
    return SameStartTrial(seed=task.seed, indirectness=[r.indirectness for r in records], success=[r.success for r in records])


def _map_entry(task: TrialResult) -> MapEntry:
    run1 = task.result.run_records[0]
    assert task.map is not None  # a map entry is made of a trial whose map was sampled
    return MapEntry(maze=task.maze, seed=task.seed, found_goal=bool(run1.success), run1_steps=run1.steps, stats=task.map.stats)


def write_outputs(
    requested: PaperArgs, results: dict[str, Any], seconds: dict[str, float], began: float, sources: dict[str, str] | None = None
) -> dict[str, Any]:
    """Analyse the tasks' results (by task name, see ``experiments.build_tasks``); write the figures, REPORT.md and paper.json."""
    args = requested.resolved()
    out = Path(args.out)
    command = requested.command()

    fields: dict[str, FieldsResult] = {m: results[f"fields/{m}"] for m in MAZES}
    same_open: list[TrialResult] = [results[f"same_start/open/{t}"] for t in range(args.same_start_trials)]
    same_mazes: dict[str, TrialResult] = {m: results[f"same_start/{m}"] for m in OBSTACLE_MAZES}
    open_result = merge_trials([results[f"dmtp/open/{t}"].result for t in range(args.trials)], args.seed)
    maze_results = (
        {m: merge_trials([results[f"dmtp/{m}/{t}"].result for t in range(args.maze_trials)], args.seed) for m in OBSTACLE_MAZES}
        if args.maze_trials
        else {}
    )
    gen: dict[str, GeneralisationResult] = {name: results[f"generalisation/{name}"] for name in SCENARIOS}

    data = PaperData(
        place_fields={m: f.summary for m, f in fields.items()},
        reward_maps_after_run1={
            **{f"open trial {t + 1}": _map_entry(x) for t, x in enumerate(same_open)},
            **{m: _map_entry(x) for m, x in same_mazes.items()},
        },
        same_start=SameStart(
            open=[_same_start_trial(x) for x in same_open], mazes={m: _same_start_trial(x) for m, x in same_mazes.items()}
        ),
        open_dmtp=DMTPOutcome(open_result, dmtp_summary(open_result, args.seed)),
        maze_dmtp={m: DMTPOutcome(r, dmtp_summary(r, args.seed)) for m, r in maze_results.items()},
        generalisation=gen,
    )
    rows = assess(args, data)
    figures = draw_figures(fields, same_open, same_mazes, open_result, gen, maze_results, out)

    wall = time.perf_counter() - began
    report = write_report(args, data, rows, figures, out, wall, command)
    paper = {
        "command": command,
        "source_sha256": sources if sources is not None else source_digest(),
        "args": dataclasses.asdict(args),
        "agent_config": args.agent_config().to_dict(),
        "seeds": {
            "dmtp_trial": f"{TRIAL_SEED_STRIDE} * seed + trial (open arena and every maze)",
            "same_start": {**{f"open/{t}": x.seed for t, x in enumerate(same_open)}, **{m: x.seed for m, x in same_mazes.items()}},
            "fields": {m: f.seed for m, f in fields.items()},
            "generalisation": {n: g.seed for n, g in gen.items()},
        },
        "wall_seconds": wall,
        "task_seconds": seconds,
        "claims": [dataclasses.asdict(row) for row in rows],
        "experiments": experiments_record(args, data, fields),
        "figures": [p.name for p in figures],
        "report": report.name,
    }
    paper = jsonable(paper)
    hippo_env.atomic_write(out / "paper.json", json.dumps(paper, indent=1) + "\n")
    if args.progress:
        print(f"wrote {report} and {out / 'paper.json'} ({len(figures)} figures) in {wall / 60:.1f} min")
    return paper


def experiments_record(args: PaperArgs, data: PaperData, fields: dict[str, FieldsResult]) -> dict[str, Any]:
    """paper.json's ``experiments``: every measurement, without the arrays the figures are drawn from."""
    return {
        "place_fields": {m: s.to_dict() for m, s in data.place_fields.items()},
        "reward_maps_after_run1": {k: dataclasses.asdict(v) for k, v in data.reward_maps_after_run1.items()},
        "same_start": dataclasses.asdict(data.same_start),
        "open_dmtp": {
            **data.open_dmtp.result.to_dict(),
            "summary": data.open_dmtp.summary.to_dict(),
            "trial_seeds": [trial_seed(args.seed, t) for t in range(args.trials)],
        },
        "maze_dmtp": {m: {**v.result.to_dict(), "summary": v.summary.to_dict()} for m, v in data.maze_dmtp.items()},
        "generalisation": {n: g.to_dict(SCENARIOS[n].explore) for n, g in data.generalisation.items()},
        "aliasing_examples": {m: {"examples": f.examples, "alias_examples": f.alias_examples} for m, f in fields.items()},
    }


def main(argv: list[str] | None = None) -> int:
    run_paper(parse_args(argv))
    return 0
