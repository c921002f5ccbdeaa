"""DMTP in every maze: the hippocampal agent's runs 2-4 indirectness, per maze and seed.

``python -m benchmarks.maze_suite --model default --seeds 3 4`` runs 20 trials x 4 runs in the
built-in mazes and 10 trials x 4 runs in 12 generated ones (``hippo_env.generate``: walls,
corridors, perfect grid mazes, rooms joined by doors and arenas with blocks, 10-20 m, maze seeds
100-111, never looked at while tuning) and writes ``benchmarks/results/maze_suite_<model>.json``: per maze and seed the median
indirectness of each run, of runs 2-4 together, the share of runs 2-4 that reached the goal, and
the run-1 length vs run-2 indirectness correlation; per maze, over all seeds, that correlation
with its bootstrap interval. ``--model paper`` runs ``AgentConfig.paper()``.
"""

from __future__ import annotations

import dataclasses
import json
import os
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.common import REPO, command_line, load_average, machine_info, parse_dataclass_args
from hippomaze.stats import median_counting_misses, pearson_with_ci

BUILT_IN = ("open", "maze1", "maze2", "maze3", "maze4")
# (kind, maze seed, arena side in m)
GENERATED = (
    ("walls", 100, 10),
    ("corridors", 101, 10),
    ("perfect", 102, 10),
    ("perfect", 103, 10),
    ("perfect", 104, 10),
    ("rooms", 105, 10),
    ("perfect", 106, 15),
    ("rooms", 107, 15),
    ("arena", 108, 20),
    ("arena", 109, 20),
    ("rooms", 110, 20),
    ("perfect", 111, 20),
)


def generated_name(kind: str, seed: int, size: float) -> str:
    """The suite's name of a generated maze: ``gen-<kind>-<seed>``, plus ``-<size>m`` unless 10 m."""
    return f"gen-{kind}-{seed}" + ("" if size == 10 else f"-{size:g}m")


@dataclasses.dataclass
class SuiteArgs:
    model: str = "default"
    """default (path integration) or paper (AgentConfig.paper())"""
    seeds: tuple[int, ...] = (3, 4)
    """runner seeds"""
    trials: int = 20
    """trials per built-in maze and seed"""
    generated_trials: int = 10
    """trials per generated maze and seed"""
    mazes: tuple[str, ...] = ()
    """mazes to run ('' = the built-in ones and the generated ones); gen-walls-100 names a generated one"""
    workers: int = 2
    """processes"""
    dry_run_steps: int = -1
    """dry-run steps (-1: the config's default)"""
    config: str = ""
    """more AgentConfig fields as JSON, by dotted name, e.g. '{"path_integration.motion_noise": 0.05}'"""
    env: str = ""
    """more environment arguments as JSON, e.g. '{"odometry_noise": 0.05, "heading_noise": 0.035}'"""
    out: str = ""
    """output JSON ('' = benchmarks/results/maze_suite_<model>.json)"""


def maze_source(name: str) -> str:
    """A built-in name, or a generated maze (``gen-<kind>-<seed>[-<size>m]``) written to a
    temporary JSON file."""
    if not name.startswith("gen-"):
        return name
    from hippo_env.generate import generate_maze, maze_json

    parts = name.split("-")
    if len(parts) not in (3, 4) or (len(parts) == 4 and not parts[3].endswith("m")):
        raise ValueError(f"maze {name!r} is not of the form gen-<kind>-<seed>[-<size>m], e.g. gen-perfect-3 or gen-arena-3-20m")
    size = float(parts[3][:-1]) if len(parts) == 4 else 10.0
    path = Path(tempfile.gettempdir()) / f"hippomaze-{name}.json"
    path.write_text(maze_json(generate_maze(int(parts[2]), parts[1], size)))
    return str(path)


def one(model: str, maze: str, seed: int, trials: int, dry_run_steps: int, config_json: str = "", env_json: str = "") -> dict[str, Any]:
    from hippo_agent import AgentConfig, HippocampalAgent
    from hippo_env.dmtp import run_dmtp

    overrides = {} if dry_run_steps < 0 else {"model.dry_run_steps": dry_run_steps}
    overrides.update(json.loads(config_json) if config_json else {})
    config = (AgentConfig.paper() if model == "paper" else AgentConfig()).with_values(overrides)
    env_kwargs = {"odometry": True} if config.path_integration is not None else {}
    env_kwargs.update(json.loads(env_json) if env_json else {})
    began = time.process_time()
    place_cells: list[int] = []  # per trial, after the dry run (recruitment grows them with the arena)
    result = run_dmtp(
        lambda o, a, seed: HippocampalAgent(o, a, config, seed=seed),
        maze_source(maze),
        trials=trials,
        runs=4,
        seed=seed,
        env_kwargs=env_kwargs,
        progress=False,
        on_run_end=lambda trial, run, agent, env: place_cells.append(agent.place.n) if run == 0 else None,
    )
    ind, ok = result.indirectness(), result.success()
    summary = result.summary()
    later = ind[:, 1:]
    return {
        "maze": maze,
        "seed": seed,
        "trials": trials,
        "median_per_run": summary["median_indirectness"],
        "runs_2_4_median": float(np.nanmedian(later)),
        # the issue's measure: a run that never reached the goal counts as infinitely indirect
        "runs_2_4_median_miss_inf": median_counting_misses(np.where(ok[:, 1:], later, np.inf).ravel()),
        "runs_2_4_reached": float(ok[:, 1:].mean()),
        "dry_run_steps_median": float(np.median(result.dry_run_steps)),
        "place_cells": sorted(set(place_cells)),
        "runs_2_4_below_1": float((later < 1).mean()),
        "pearson_run1_length_run2_indirectness": summary.get("pearson_run1_length_run2_indirectness"),
        "run1_lengths": [r.path_length for r in result.run_records if r.run == 0],
        "run2_indirectness": [r.indirectness for r in result.run_records if r.run == 1],
        "env_steps_total": result.env_steps_total,
        "cpu_seconds": time.process_time() - began,
    }


def pool_seeds(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per maze, every seed's trials together: the run-1 length vs run-2 indirectness correlation
    (Pearson r with a 95 % bootstrap interval over trials; the paper's Fig. 6 gives r = -0.53)."""
    out: dict[str, dict[str, Any]] = {}
    for maze in dict.fromkeys(r["maze"] for r in rows):
        mine = [r for r in rows if r["maze"] == maze]
        lengths = [x for r in mine for x in r["run1_lengths"]]
        second = [np.nan if x is None else x for r in mine for x in r["run2_indirectness"]]
        out[maze] = {
            "seeds": [r["seed"] for r in mine],
            "days": len(lengths),  # trials (the key committed results have)
            "pearson_run1_length_run2_indirectness": pearson_with_ci(np.array(lengths), np.array(second), seed=0),
        }
    return out


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(SuiteArgs, __doc__.splitlines()[0], argv)
    if args.model not in ("default", "paper"):
        raise SystemExit(f"--model {args.model!r} is unknown; allowed: default, paper")
    mazes = args.mazes or (*BUILT_IN, *(generated_name(*g) for g in GENERATED))
    load_start = load_average()
    jobs = [
        (args.model, m, s, args.generated_trials if m.startswith("gen-") else args.trials, args.dry_run_steps, args.config, args.env)
        for m in mazes
        for s in args.seeds
    ]
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        futures = [pool.submit(one, *job) for job in jobs]
        rows = []
        for f in futures:
            rows.append(f.result())
            r = rows[-1]
            print(
                f"{r['maze']:>18} seed {r['seed']}: runs 2-4 median {r['runs_2_4_median']:.2f} "
                f"(misses as inf: {r['runs_2_4_median_miss_inf']}), reached {r['runs_2_4_reached']:.0%}, "
                f"dry run {r['dry_run_steps_median']:.0f} steps, "
                f"per run {[None if x is None else round(x, 2) for x in r['median_per_run']]}",
                flush=True,
            )
    pooled = pool_seeds(rows)
    for maze, p in pooled.items():
        r = p["pearson_run1_length_run2_indirectness"]
        if r["r"] is not None:
            print(
                f"{maze:>18} seeds {p['seeds']}: run-1 length vs run-2 indirectness r = {r['r']:.2f} "
                f"(95 % CI {r['ci95'][0]:.2f} to {r['ci95'][1]:.2f}, n = {r['n']})"
            )
    record = {
        "command": command_line(),
        "model": args.model,
        "machine": machine_info(),
        "load_start": load_start,
        "load_end": load_average(),
        "rows": rows,
        "pooled": pooled,
    }
    out = Path(args.out) if args.out else REPO / "benchmarks" / "results" / f"maze_suite_{args.model}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(f".tmp{os.getpid()}")
    tmp.write_text(json.dumps(record, indent=1) + "\n")
    tmp.replace(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
