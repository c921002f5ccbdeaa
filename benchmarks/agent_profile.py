"""Where the hippocampal agent's time goes: cProfile over the walks and the dry run that
:mod:`benchmarks.agent_throughput` times.

Four programs, each after an untimed pass (which compiles the kernels and fills the caches):

- the default model exploiting on a recorded random walk (act + observe, learning on);
- the paper's model the same way;
- the default model's dry run from scratch (the environment's steps included in the profile but
  listed apart, as ``hippo_env`` and ``gymnasium``);
- a whole DMTP trial of the default model in the open arena, as ``hippomaze dmtp`` runs it (its
  dry run, then ``--dmtp-runs`` runs to a hidden goal; the environment included).

For each, the record holds the profiled time per step and the functions with the most time of
their own (exclusive), in microseconds per step and as a share of the profiled total, with their
call counts per step. cProfile slows Python-level calls more than compiled kernels, so the shares
of the small Python functions read high; :mod:`benchmarks.agent_throughput` gives the unprofiled
speeds.

    python -m benchmarks.agent_profile          # writes benchmarks/results/agent_profile.json
    python -m benchmarks.agent_profile --steps 500 --dry-run-steps 500 --out /tmp/profile.json   # a quick look
"""

from __future__ import annotations

import cProfile
import dataclasses
import datetime
import pstats
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import hippo_env
from benchmarks.agent_timing import heading_for_the_goal, new_agent, recorded_walk, timed_dry_run, trained, walk
from benchmarks.common import command_line, load_average, machine_info, output_path, parse_dataclass_args
from hippo_env.dmtp import run_dmtp
from hippomaze.registry import agent_factory


@dataclass
class Args:
    cells: int = 1000
    """place cells"""
    steps: int = 3_000
    """recorded steps of each exploiting walk"""
    dry_run_steps: int = 3_000
    """the longest dry run"""
    n_rays: int = 720
    """rangefinder rays"""
    seed: int = 0
    """seeds the environment, the agents and the recorded walks"""
    dmtp_runs: int = 4
    """runs of the profiled DMTP trial (its first finds the goal, the others go to it)"""
    top: int = 25
    """functions listed per program"""
    out: str = ""
    """where the JSON goes; '' = benchmarks/results/agent_profile.json"""


def profiled(run: Any) -> tuple[pstats.Stats, float]:
    """``run()`` under cProfile: its statistics and total seconds."""
    profile = cProfile.Profile()
    profile.enable()
    try:
        run()
    finally:
        profile.disable()
    stats = pstats.Stats(profile)
    return stats, stats.total_tt  # type: ignore[attr-defined]


def summary(stats: pstats.Stats, total: float, steps: int, top: int) -> dict[str, Any]:
    """The ``top`` functions by their own time: microseconds and calls per step, share of the total."""
    rows = []
    for (path, line, name), (_, calls, own, cumulative, _) in stats.stats.items():  # type: ignore[attr-defined]
        rows.append(
            {
                "function": f"{_short(path)}:{line}({name})",
                "own_us_per_step": round(1e6 * own / steps, 2),
                "cumulative_us_per_step": round(1e6 * cumulative / steps, 2),
                "calls_per_step": round(calls / steps, 3),
                "own_share": round(own / total, 4),
            }
        )
    rows.sort(key=lambda r: -r["own_us_per_step"])
    return {"steps": steps, "profiled_us_per_step": round(1e6 * total / steps, 2), "top": rows[:top]}


def _short(path: str) -> str:
    """A source path from its package on (``hippo_agent/...``, ``numpy/...``), or as it is."""
    parts = Path(path).parts
    for anchor in ("hippo_agent", "hippo_env", "benchmarks", "site-packages"):
        if anchor in parts:
            i = parts.index(anchor)
            return "/".join(parts[i + (anchor == "site-packages") :])
    return path


def dmtp_trial(args: Args) -> Callable[[], int]:
    """One DMTP trial of the default model (``AgentConfig()``) in the open arena, as ``hippomaze
    dmtp --agent hippo`` runs it: a fresh agent, its dry run and ``args.dmtp_runs`` runs. A function
    returning the environment steps it took."""

    def trial() -> int:
        result = run_dmtp(agent_factory("hippo"), "open", trials=1, runs=args.dmtp_runs, seed=args.seed, progress=False)
        return int(result.env_steps_total)

    return trial


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    load_at_start = load_average()
    programs: dict[str, Any] = {}
    for model in ("default", "paper"):
        env, agent, _, _ = trained(model, args.cells, args.dry_run_steps, args.n_rays, args.seed)
        recorded = recorded_walk(env, args.steps, args.seed)
        with heading_for_the_goal(agent, exploit=True):
            walk(agent, recorded)  # untimed
            stats, total = profiled(lambda: walk(agent, recorded))  # noqa: B023 (called at once)
        programs[f"{model}_exploiting"] = summary(stats, total, len(recorded), args.top)
        print(f"  {model} model, exploiting: {programs[f'{model}_exploiting']['profiled_us_per_step']} us per profiled step")
    env, fresh = new_agent("default", args.cells, args.dry_run_steps, args.n_rays, args.seed)
    timed_dry_run(env, fresh)  # untimed: loads the dry run's kernels
    env.close()
    env, fresh = new_agent("default", args.cells, args.dry_run_steps, args.n_rays, args.seed)
    steps: list[int] = []
    stats, total = profiled(lambda: steps.append(timed_dry_run(env, fresh)[0]))
    env.close()
    programs["default_dry_run"] = summary(stats, total, steps[0], args.top)
    print(f"  default model, dry run: {programs['default_dry_run']['profiled_us_per_step']} us per profiled step (environment included)")
    trial = dmtp_trial(args)
    trial()  # untimed
    trial_steps: list[int] = []
    stats, total = profiled(lambda: trial_steps.append(trial()))
    programs["default_dmtp_trial"] = summary(stats, total, trial_steps[0], args.top)
    print(
        f"  default model, a DMTP trial: {programs['default_dmtp_trial']['profiled_us_per_step']} us per profiled step (environment included)"
    )
    record = {
        "command": command_line(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "args": dataclasses.asdict(args),
        "machine": machine_info(numpy=np.__version__, gymnasium=gym.__version__, hippo_env=hippo_env.__version__)
        | {"load_average_at_start": load_at_start, "load_average_at_end": load_average()},
        "programs": programs,
    }
    out = output_path(args.out or "benchmarks/results/agent_profile.json")
    hippo_env.write_json(out, record)
    for name, program in programs.items():
        print(f"  {name}: largest own times " + ", ".join(f"{r['function']} {r['own_us_per_step']}" for r in program["top"][:4]))
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
