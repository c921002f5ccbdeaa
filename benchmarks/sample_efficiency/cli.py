"""The command line, ``python -m benchmarks.sample_efficiency [options]``, top to bottom (see the package docstring)."""

from __future__ import annotations

import dataclasses
import datetime
import json
import math
import os
import platform
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import benchmarks.sample_efficiency as package
from benchmarks.common import parse_dataclass_args
from hippo_env.files import write_json
from hippomaze.bench.figures import plot_bench
from hippomaze.bench.jobs import Job, JobRecord, make_job
from hippomaze.bench.metrics import replicates, steps_to_criterion
from hippomaze.bench.references import REFERENCE_VARIANTS, folder, reference_document
from hippomaze.bench.report import comparison_markdown
from hippomaze.bench.runner import run_jobs
from hippomaze.bench.summary import analyse, compare


@dataclass
class Args:
    agents: tuple[str, ...] = ("hippo", "hippo-paper", "random", "dqn", "ppo", "dynaq")
    """agents to run (hippo, hippo-paper, random, dqn, ppo, dynaq = privileged Dyna-Q)"""
    mazes: tuple[str, ...] = ("open", "maze1")
    """mazes (sparse reward)"""
    seeds: int = 5
    """seeds 0 .. seeds-1 per agent and maze"""
    budget: int = 300_000
    """environment steps per seed for dqn, ppo and random in the learning trial"""
    dynaq_budget: int = 100_000
    """environment steps per seed for the privileged Dyna-Q (it converges long before)"""
    switch_budget: int = 50_000
    """at most this many steps in the goal-switch trial (0: no goal switch)"""
    dense_agents: tuple[str, ...] = ("dqn", "ppo")
    """agents also run with reward_type='dense' (the generous variant)"""
    dense_mazes: tuple[str, ...] = ("open",)
    """mazes for the dense variant"""
    dense_seeds: int = 3
    """seeds for the dense variant"""
    hippo_days: int = 10
    """fresh-agent DMTP trials per seed for the hippocampal agents (replicates)"""
    hippo_runs: int = 40
    """runs per hippocampal trial (run 1 explores; the rest show whether it stays direct)"""
    window: int = 10
    """runs pooled per seed for success rate and median indirectness"""
    max_episode_steps: int = 0
    """per-run step limit (0: the environment's 10,000)"""
    engine: str = "local"
    """local (process pool), serial or ray"""
    address: str = ""
    """Ray cluster address (empty: start a local Ray)"""
    workers: int = 2
    """parallel jobs (local pool size; CPUs for a local Ray)"""
    out: str = "sample_efficiency_out"
    """output folder (job records go to <out>/sample_efficiency/); benchmarks/results for the committed results"""
    quick: bool = False
    """a tiny smoke run: tiny budgets and agents, 2 seeds, 300-step runs"""
    sweep: bool = False
    """run the hyperparameter sweep of baselines/hyperparams.py instead"""
    sweep_budget: int = 100_000
    """steps per sweep job"""
    progress: bool = True
    """show a progress bar over jobs"""
    aggregate: bool = True
    """write the summary JSON and figures after the jobs"""
    write_references: bool = False
    """also write the references hippomaze bench ships (hippomaze/bench/reference_results/) from hippo, hippo-paper, dqn, ppo, random"""


#: ``--quick``: small networks and schedules, so that a smoke run of every agent takes seconds.
QUICK_OVERRIDES: dict[str, dict[str, Any]] = {
    "dqn": {
        "learning_starts": 100,
        "buffer_size": 2000,
        "batch_size": 32,
        "train_freq": 8,
        "gradient_steps": 1,
        "target_update_interval": 200,
    },
    "ppo": {"n_steps": 128, "batch_size": 32, "n_epochs": 2},
    "hippo": {"model.dry_run_steps": 300},
    "hippo-paper": {"model.dry_run_steps": 300},
}
#: What records made before job records kept their own date and versions are known by (``provenance.json``).
PROVENANCE_FILE = "provenance.json"


def parse_args(argv: list[str] | None = None) -> Args:
    args = parse_dataclass_args(Args, package.__doc__.splitlines()[0], argv, prog="python -m benchmarks.sample_efficiency")
    if args.engine not in ("local", "serial", "ray"):
        raise SystemExit(f"--engine must be local, serial or ray, got {args.engine!r}")
    return args


def make_jobs(args: Args) -> list[Job]:
    """Every job of the benchmark (or of the sweep), in a fixed order."""
    mep = args.max_episode_steps or (300 if args.quick else 0)

    def job(agent: str, maze: str, seed: int, reward_type: str = "sparse", **kw: Any) -> Job:
        overrides = dict(QUICK_OVERRIDES.get(agent, {})) if args.quick else {}
        overrides.update(kw.pop("extra", {}))
        one_shot = agent in ("hippo", "hippo-paper")
        budget = kw.pop("budget", args.dynaq_budget if agent == "dynaq" else args.budget)
        return make_job(agent, maze, seed, protocol="one-shot" if one_shot else "learner", budget=budget,
                        switch_budget=kw.pop("switch_budget", args.switch_budget), trials=args.hippo_days, runs=args.hippo_runs,
                        reward_type=reward_type, max_episode_steps=mep, overrides=overrides, **kw)  # fmt: skip

    if args.sweep:
        from hippomaze.baselines.hyperparams import SWEEP

        return [job(p.agent, "open", seed, extra=dict(p.overrides), label=f"sweep-{p.name}", budget=args.sweep_budget, switch_budget=0)
                for p in SWEEP for seed in p.seeds]  # fmt: skip
    # Cheap agents first, then the expensive ones seed by seed, so that a partial run has the same
    # seeds for every agent and maze; the dense variant last.
    deep = [a for a in args.agents if a in ("dqn", "ppo")]
    jobs = [job(a, m, s) for a in args.agents if a not in deep for m in args.mazes for s in range(args.seeds)]
    jobs += [job(a, m, s) for s in range(args.seeds) for a in deep for m in args.mazes]
    jobs += [job(a, m, s, "dense") for s in range(args.dense_seeds) for a in args.dense_agents for m in args.dense_mazes]
    return jobs


def main(argv: list[str] | None = None) -> dict[str, Any]:
    args = parse_args(argv)
    out = Path(args.out).resolve()
    jobs = make_jobs(args)
    command = ("python -m benchmarks.sample_efficiency " + shlex.join(sys.argv[1:] if argv is None else argv)).strip()
    began = time.perf_counter()
    records_folder = out / ("sample_efficiency_sweep" if args.sweep else "sample_efficiency")
    records, ran = run_jobs(jobs, records_folder, engine=args.engine, workers=args.workers, address=args.address,
                            progress=args.progress, command=command)  # fmt: skip
    wall = time.perf_counter() - began
    meta = {
        "command": command, "args": dataclasses.asdict(args), "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "python": platform.python_version(), "machine": platform.machine(), "cpus": os.cpu_count(),
        "jobs": len(jobs), "jobs_run": len(ran), "wall_seconds_this_invocation": round(wall, 1),
        "cpu_seconds_all_jobs": round(sum(r.seconds for r in records.values()), 1),
    }  # fmt: skip
    if not args.aggregate:
        return {"meta": meta, "records": records}
    if args.sweep:
        sweep = {**meta, **sweep_summary([records[j.name] for j in jobs], args)}
        write_json(out / "sample_efficiency_sweep.json", sweep)
        print(json.dumps(sweep["rows"], indent=1))
        return sweep
    results = analyse([records[j.name] for j in jobs], args.window, tuple(args.mazes))
    order = sorted(results, key=_variant_order)
    results = {v: results[v] for v in order}
    focus = "hippo" if "hippo" in results else order[0]
    comparison = compare(results, focus, list(args.mazes))
    table = comparison_markdown(comparison, results)
    document = {
        **meta,
        "table_markdown": table,
        "statistics": comparison.to_dict(),
        "results": {k: r.to_dict() for k, r in results.items()},
    }
    stem = "sample_efficiency_quick" if args.quick else "sample_efficiency"
    write_json(out / f"{stem}.json", document)
    plot_bench(results, comparison, out / f"{stem}.png")
    if args.write_references:
        written = write_references(results, [records[j.name] for j in jobs], set(ran), records_folder, meta)
        print(f"wrote {len(written)} references to {folder()}/: {', '.join(p.stem for p in written)}")
    print(table)
    return document


def write_references(
    results: dict[str, Any], records: list[JobRecord], ran: set[str], records_folder: Path, meta: dict[str, Any]
) -> list[Path]:
    """Write the reference files of the variants in REFERENCE_VARIANTS, each saying how it was made."""
    legacy_path = records_folder / PROVENANCE_FILE
    legacy = json.loads(legacy_path.read_text()) if legacy_path.exists() else None
    written = []
    for variant in REFERENCE_VARIANTS:
        if variant not in results:
            continue
        mine = [r for r in records if (r.job.get("label") or r.job["agent"]) == variant and r.job["reward_type"] == "sparse"]
        origins: dict[str, dict[str, Any]] = {}  # the records grouped by how they were made
        for r in mine:
            if r.made is not None:
                origin = {"run": "by this invocation" if r.name in ran else "by an earlier invocation (its record reused)", **r.made}
            else:
                known = {k: v for k, v in (legacy or {}).items() if k not in ("about", "records")}
                origin = {"run": f"by an earlier invocation; converted from its job record, which has no date or versions ({PROVENANCE_FILE})",
                          **known, **(legacy or {}).get("records", {}).get(r.name, {})}  # fmt: skip
            key = json.dumps(origin, sort_keys=True)
            origins.setdefault(key, {**origin, "jobs": []})["jobs"].append(r.name)
        made = {
            "command": meta["command"], "date": meta["date"], "python": meta["python"], "machine": meta["machine"],
            "jobs_run_by_this_command": sum(r.name in ran for r in mine), "jobs_from_earlier_records": sum(r.name not in ran for r in mine),
            "records": list(origins.values()),
        }  # fmt: skip
        path = folder() / f"{variant}.json"
        write_json(path, reference_document(results[variant], made))
        written.append(path)
    return written


def _variant_order(v: str) -> tuple[int, str]:
    order = ["hippo", "hippo-paper", "dqn", "ppo", "dqn-dense", "ppo-dense", "random", "dynaq"]
    return (order.index(v) if v in order else len(order), v)


def sweep_summary(records: list[JobRecord], args: Args) -> dict[str, Any]:
    """One row per sweep point (its seeds in the order the records come), all in the open arena with the sparse reward."""
    rows = []
    for label in sorted({r.job["label"] for r in records}):
        recs = [r for r in records if r.job["label"] == label]
        stc, final_s, final_i = [], [], []
        for r in recs:
            (rep,) = replicates(r.learn)
            stc.append(steps_to_criterion([rep], args.window))
            final_s.append(float(rep.success[-50:].mean()) if rep.end.size else 0.0)
            final_i.append(float(np.median(rep.indirectness[-50:])) if rep.end.size else math.inf)
        rows.append({
            "name": label.removeprefix("sweep-"), "agent": recs[0].job["agent"], "overrides": recs[0].job["overrides"],
            "seeds": [r.job["seed"] for r in recs], "steps_to_criterion": stc, "final_success_rate": final_s,
            "final_median_indirectness": [round(v, 4) if math.isfinite(v) else None for v in final_i],
            "episodes": [len(r.learn["episodes"]["steps"]) for r in recs], "seconds": [round(r.seconds, 1) for r in recs],
        })  # fmt: skip
    return {"budget": args.sweep_budget, "maze": "open", "reward_type": "sparse", "rows": rows}
