"""The command line: ``python -m benchmarks.sample_efficiency [options]`` (see the package docstring)."""

from __future__ import annotations

import dataclasses
import datetime
import json
import os
import platform
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import benchmarks.sample_efficiency as package
from benchmarks.common import parse_dataclass_args
from benchmarks.sample_efficiency.figures import plot_curves, plot_switch
from benchmarks.sample_efficiency.jobs import make_jobs
from benchmarks.sample_efficiency.report import headline_markdown, switch_markdown
from benchmarks.sample_efficiency.runner import run_jobs
from benchmarks.sample_efficiency.summary import analyse, sweep_summary
from hippo_env.files import write_json


@dataclass
class Args:
    agents: tuple[str, ...] = ("hippo", "random", "dqn", "ppo", "dynaq")
    """agents to run (hippo, random, dqn, ppo, dynaq = privileged Dyna-Q)"""
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
    """fresh-agent DMTP trials per seed for the hippocampal agent (replicates)"""
    hippo_runs: int = 40
    """runs per hippocampal trial (run 1 explores; the rest show whether it stays direct)"""
    window: int = 10
    """runs pooled per seed for success rate and median indirectness"""
    max_episode_steps: int = 0
    """per-run step limit (0: the environment's 10,000)"""
    engine: str = "local"
    """local (process pool) or ray"""
    address: str = ""
    """Ray cluster address (empty: start a local Ray)"""
    workers: int = 2
    """parallel jobs (local pool size; CPUs for a local Ray)"""
    out: str = "benchmarks/results"
    """output directory (job records go to <out>/sample_efficiency/)"""
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


def parse_args(argv: list[str] | None = None) -> Args:
    args = parse_dataclass_args(Args, package.__doc__.splitlines()[0], argv)
    if args.engine not in ("local", "ray"):
        raise SystemExit(f"--engine must be local or ray, got {args.engine!r}")
    return args


def main(argv: list[str] | None = None) -> dict[str, Any]:
    args = parse_args(argv)
    out = Path(args.out)
    if not out.is_absolute():
        out = Path.cwd() / out
    jobs = make_jobs(args)
    began = time.perf_counter()
    records = run_jobs(jobs, args, out)
    wall = time.perf_counter() - began
    command = "python -m benchmarks.sample_efficiency " + shlex.join(sys.argv[1:] if argv is None else argv)
    meta = {
        "command": command.strip(), "args": dataclasses.asdict(args), "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "python": platform.python_version(), "machine": platform.machine(), "cpus": os.cpu_count(),
        "jobs": len(jobs), "wall_seconds_this_invocation": round(wall, 1),
        "cpu_seconds_all_jobs": round(sum(r.seconds for r in records.values()), 1),
    }  # fmt: skip
    if not args.aggregate:
        return {"meta": meta, "records": records}
    if args.sweep:
        sweep = {**meta, **sweep_summary(records, args).to_dict()}
        write_json(out / "sample_efficiency_sweep.json", sweep)
        print(json.dumps(sweep["rows"], indent=1))
        return sweep
    summary = analyse({j.name: records[j.name] for j in jobs}, args)
    document = {**meta, **summary.to_dict(), "headline_markdown": headline_markdown(summary), "switch_markdown": switch_markdown(summary)}
    stem = "sample_efficiency_quick" if args.quick else "sample_efficiency"
    write_json(out / f"{stem}.json", document)
    plot_curves(summary, out / f"{stem}.png", window=args.window, trials=args.hippo_days)
    plot_switch(summary, out / f"{stem}_goal_switch.png")
    print(document["headline_markdown"])
    print()
    print(document["switch_markdown"])
    return document
