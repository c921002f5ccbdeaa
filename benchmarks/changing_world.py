"""A world that changes: new barriers round a known goal, walls added or removed in mazes, a
shortcut opened, and several worlds in turn, for the project's agents.

``python -m benchmarks.changing_world --agents hippo hippo-paper random --seeds 11 12 13`` runs,
per agent and runner seed, the tasks of :mod:`hippomaze.changing_world` (``barriers``: blocks
round a known goal in the open arena; ``mazes``: blocks, a detour and a door in maze1..maze4 and
generated 10-20 m mazes; ``worlds``: maze1, maze3, maze2 and back) and writes their measures, per
agent over seeds, to ``benchmarks/results/changing_world.json`` with the targets they answer,
and each changed layout's apart (``barriers_by_layout``, ``mazes_by_change``).
``benchmarks.world_figures`` draws the figures. ``--forget-new-walls`` (privileged, a diagnosis)
makes the agents' maps forget the walls their runs wrote whenever a new layout begins; ``--env``
runs the tasks on other environment arguments (another ``action_type``, sensor noise).
"""

from __future__ import annotations

import dataclasses
import json
import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from benchmarks.common import REPO, command_line, load_average, machine_info, parse_dataclass_args
from benchmarks.targets import target
from hippo_env.files import write_json
from hippomaze.bench.changing import plot_by_layout
from hippomaze.bench.references import CHANGING_WORLD, folder
from hippomaze.changing_world import MAZES, TASKS, layout_measures, run_task, summarise, worlds_measures
from hippomaze.registry import agent_factory

TARGET_NAMES = (
    "changed_first_run_success",
    "changed_success",
    "changed_indirectness",
    "changed_position",
    "shortcut_taken",
    "worlds_return",
)


@dataclasses.dataclass
class ChangingWorldArgs:
    agents: tuple[str, ...] = ("hippo", "hippo-paper", "random")
    """agents by registry name (hippomaze.registry) or module:Class"""
    seeds: tuple[int, ...] = (11, 12, 13)
    """runner seeds (the changes are drawn from them too)"""
    tasks: tuple[str, ...] = TASKS
    """tasks to run: barriers, mazes, worlds"""
    mazes: tuple[str, ...] = MAZES
    """mazes of the 'mazes' task: built-in names or gen-<kind>-<seed>[-<size>m]"""
    config: str = ""
    """AgentConfig fields by dotted name as JSON, for every agent that takes them, e.g. '{"map.new_wall_evidence": 3}'"""
    env: str = ""
    """more environment arguments as JSON, e.g. '{"action_type": "heading"}' (the bench's reference is made with none)"""
    workers: int = 2
    """processes"""
    out: str = ""
    """output JSON ('' = benchmarks/results/changing_world.json)"""
    write_reference: bool = False
    """also write the summary as the reference hippomaze bench --changing-world compares with"""
    forget_new_walls: bool = False
    """PRIVILEGED, a diagnosis only: the agents' maps forget the walls their runs wrote whenever a new
    layout begins (no block of an earlier layout lingers; the agent is still not told of the change)"""


def main(argv: list[str] | None = None) -> None:
    args = parse_dataclass_args(ChangingWorldArgs, __doc__.splitlines()[0], argv)
    unknown = sorted(set(args.tasks) - set(TASKS))
    if unknown:
        raise SystemExit(f"--tasks {unknown} unknown; allowed: {', '.join(TASKS)}")
    for agent in args.agents:
        agent_factory(agent, **(json.loads(args.config) if args.config else {}))  # an unknown agent or field fails now, not in a worker
    overrides = json.loads(args.config) if args.config else {}
    if args.forget_new_walls and args.write_reference:
        raise SystemExit("--forget-new-walls is a privileged diagnosis: it cannot write the bench's reference")
    env_kwargs = json.loads(args.env) if args.env else {}
    if env_kwargs and args.write_reference:
        raise SystemExit("--env changes the tasks: it cannot write the bench's reference, which is made on the default environment")
    jobs = [
        (agent, seed, task, maze, overrides, args.forget_new_walls, env_kwargs)
        for agent in args.agents
        for seed in args.seeds
        for task in args.tasks
        for maze in (args.mazes if task == "mazes" else ("",))
    ]
    load_start = load_average()
    rows = []
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        for row in pool.map(run_task, *zip(*jobs)):
            rows.append(row)
            summary = layout_measures([row]) if row["task"] != "worlds" else worlds_measures([row])
            print(f"{row['agent']:>12} seed {row['seed']} {row['task']} {row['maze']}: {json.dumps(summary)}", flush=True)
    summary = summarise(rows)
    print(json.dumps(summary, indent=1))
    record = {
        "command": command_line(),
        "machine": machine_info(),
        "load_start": load_start,
        "load_end": load_average(),
        "forget_new_walls": args.forget_new_walls,
        "env": env_kwargs,
        "targets": {name: {"what": target(name).what, "target": target(name).text()} for name in TARGET_NAMES},
        "summary": summary,
        "rows": rows,
    }
    out = Path(args.out) if args.out else REPO / "benchmarks" / "results" / "changing_world.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(f".tmp{os.getpid()}")
    tmp.write_text(json.dumps(record, indent=1) + "\n")
    tmp.replace(out)
    print(f"wrote {out}")
    figure = out.with_name(f"{out.stem}_by_layout.png")
    if plot_by_layout(summary, figure):
        print(f"wrote {figure}")
    if args.write_reference:
        reference = folder() / f"{CHANGING_WORLD}.json"
        write_json(reference, {"command": record["command"], "seeds": list(args.seeds), "summary": summary})
        print(f"wrote {reference}")


if __name__ == "__main__":
    main()
