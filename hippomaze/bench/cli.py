"""``hippomaze bench``: the command line (every option has its help text) and the command."""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Any

from hippomaze.bench.jobs import PROTOCOLS
from hippomaze.bench.run import FULL, QUICK, BenchArgs, run_bench
from hippomaze.runinfo import non_negative_int, positive_int

DESCRIPTION = """Measure an agent on the DMTP sample-efficiency protocol and set it beside the shipped reference
results of hippo, hippo-paper, DQN, PPO and a random agent: environment steps until the agent is
first direct (its run under way a direct success, and >= 90 % of its 10 runs from there, median
indirectness <= 1), steps until direct again after the goal moves, and the learning curves.
Writes OUT/bench.json (IQM and 95 % intervals by rliable, for the agent and the references),
OUT/bench.png and OUT/bench.md. Needs the 'bench' extra: pip install 'hippomaze[bench]'."""


def add_parser(commands: Any) -> argparse.ArgumentParser:
    """Add ``bench`` to the ``hippomaze`` subcommands."""
    p = commands.add_parser("bench", help="measure an agent's sample efficiency beside the shipped references", description=DESCRIPTION)
    p.add_argument(
        "--agent",
        required=True,
        help="the agent: module:Class (a class following hippo_env.agent_protocol; ./module.py is found), module:make_agent "
        "(a factory), a name registered in the hippomaze.agents entry points, or a built-in: hippo, hippo-paper, random, dqn, ppo",
    )
    p.add_argument(
        "--maze",
        dest="mazes",
        action="append",
        metavar="MAZE",
        help="a maze to run in (repeatable): open, maze1 ... maze4 or a JSON path; the references cover open and maze1 "
        "(default: --maze open --maze maze1)",
    )
    p.add_argument("--seeds", type=positive_int, help=f"seeds per maze, 0 .. N-1 (default: {FULL['seeds']}; --quick: {QUICK['seeds']})")
    p.add_argument(
        "--protocol",
        default="auto",
        choices=("auto", *PROTOCOLS),
        help="learner: one long trial per seed, the goal held, within --budget steps; one-shot: --trials fresh-agent trials of "
        "--runs runs per seed; auto: one-shot for hippo and hippo-paper, learner otherwise (default: auto)",
    )
    p.add_argument(
        "--budget",
        type=positive_int,
        help=f"learner: environment steps per seed, the dry run included (default: {FULL['budget']:,}, as the references; "
        f"--quick: {QUICK['budget']:,})",
    )
    p.add_argument(
        "--switch-budget",
        type=non_negative_int,
        help=f"at most this many steps to become direct again after the goal moves; 0: no goal switch "
        f"(default: {FULL['switch_budget']:,}; --quick: {QUICK['switch_budget']:,})",
    )
    p.add_argument("--trials", type=positive_int, help=f"one-shot: trials per seed (default: {FULL['trials']}; --quick: {QUICK['trials']})")
    p.add_argument("--runs", type=positive_int, help=f"one-shot: runs per trial (default: {FULL['runs']}; --quick: {QUICK['runs']})")
    p.add_argument(
        "--quick",
        action="store_true",
        help=f"smaller defaults for a first look: {QUICK['seeds']} seeds, a {QUICK['budget']:,}-step budget "
        f"(one-shot: {QUICK['trials']} trials of {QUICK['runs']} runs)",
    )
    p.add_argument("--label", default="", help="the agent's name in the table and figure (default: the --agent text)")
    p.add_argument(
        "--reference",
        dest="references",
        action="append",
        metavar="NAME",
        help="a shipped reference to compare with (repeatable): hippo, hippo-paper, dqn, ppo, random (default: all of them)",
    )
    p.add_argument("--out", default="bench_out", help="output folder, new or empty (default: bench_out)")
    p.add_argument(
        "--resume", action="store_true", help="continue an interrupted run in --out: jobs whose records are there are not run again"
    )
    p.add_argument(
        "--engine",
        default="local",
        choices=("local", "serial", "ray"),
        help="local: a pool of --workers processes; serial: one job after another in this process; ray: a local Ray (default: local)",
    )
    p.add_argument("--workers", type=positive_int, default=2, help="jobs run at once (default: 2)")
    p.add_argument(
        "--changing-world",
        action="store_true",
        help="instead of sample efficiency, measure the agent in a world that changes (new blocks round a known goal, walls added "
        "or removed in mazes, a shortcut, several worlds) beside the shipped references, on --seeds runner seeds from 11 "
        "(default 3); writes OUT/changing_world.json and changing_world.md",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    return p


def bench_command(args: argparse.Namespace) -> int:
    """Run ``hippomaze bench`` from parsed arguments; print the table and what was written."""
    if ":" in args.agent and "" not in sys.path and os.getcwd() not in sys.path:
        sys.path.insert(0, os.getcwd())  # --agent mymodule:MyAgent finds ./mymodule.py, as `python -m` would
    if args.changing_world:
        from hippomaze.bench.changing import run_changing_world

        began = time.perf_counter()
        document = run_changing_world(args.agent, args.seeds or 3, args.out, args.workers, args.label)
        print(document["table_markdown"])
        print(
            f"wrote {args.out}/changing_world.json, changing_world.md and changing_world_by_layout.png in {time.perf_counter() - began:.0f} s"
        )
        return 0
    bench = BenchArgs(
        agent=args.agent, mazes=tuple(args.mazes or ("open", "maze1")), seeds=args.seeds, protocol=args.protocol,
        budget=args.budget, switch_budget=args.switch_budget, trials=args.trials, runs=args.runs, quick=args.quick,
        label=args.label, references=None if args.references is None else tuple(args.references), out=args.out,
        resume=args.resume, engine=args.engine, workers=args.workers, progress=not args.no_progress,
    )  # fmt: skip
    began = time.perf_counter()
    document = run_bench(bench)
    print(document["table_markdown"])
    for note in document["notes"]:
        print(f"note: {note}")
    print(f"wrote {args.out}/bench.json, bench.png and bench.md in {time.perf_counter() - began:.0f} s")
    return 0
