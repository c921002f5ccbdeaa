"""``hippomaze bench``, top to bottom: the user's agent measured, then set beside the shipped references.

1. the jobs: the agent on each maze and seed, under its protocol (:mod:`hippomaze.bench.jobs`);
2. run on the engine, each record saved to ``<out>/jobs/`` as it finishes (``--resume`` reuses them);
3. the records as a variant result, beside the shipped references (:mod:`hippomaze.bench.summary`);
4. written to ``<out>/``: ``bench.json``, ``bench.png`` and ``bench.md``.
"""

from __future__ import annotations

import dataclasses
import datetime
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hippo_env.files import write_json
from hippomaze.bench.jobs import default_protocol, make_job, versions
from hippomaze.bench.metrics import WINDOW

#: What a full run measures, and what ``--quick`` measures instead (a first look).
FULL = {"seeds": 5, "budget": 300_000, "switch_budget": 50_000, "trials": 10, "runs": 40}
QUICK = {"seeds": 3, "budget": 50_000, "switch_budget": 10_000, "trials": 3, "runs": 15}
#: What ``hippomaze bench`` writes into ``--out`` (besides the job records under ``jobs/``).
OUTPUTS = ("bench.json", "bench.png", "bench.md")


@dataclass
class BenchArgs:
    """What ``hippomaze bench`` is asked to do (the command line's options; ``None``: the full or quick default)."""

    agent: str
    """the agent: a built-in name, ``module:Class``, ``module:make_agent`` or an entry-point name"""
    mazes: tuple[str, ...] = ("open", "maze1")
    """mazes, each a built-in name or a JSON path (the references cover open and maze1)"""
    seeds: int | None = None
    """seeds 0 .. seeds-1 per maze"""
    protocol: str = "auto"
    """learner, one-shot, or auto (one-shot for hippo and hippo-paper, learner otherwise)"""
    budget: int | None = None
    """environment steps per seed for a learner (the dry run included)"""
    switch_budget: int | None = None
    """at most this many steps in the goal-switch trial (0: none)"""
    trials: int | None = None
    """one-shot: fresh-agent trials per seed"""
    runs: int | None = None
    """one-shot: runs per trial"""
    quick: bool = False
    """smaller defaults: 3 seeds, a 50,000-step budget (one-shot: 3 trials of 15 runs)"""
    label: str = ""
    """the agent's name in the table and figure (default: --agent)"""
    references: tuple[str, ...] | None = None
    """shipped references to compare with (default: all)"""
    out: str = "bench_out"
    """output folder"""
    resume: bool = False
    """reuse the job records an interrupted run with the same settings left in --out"""
    engine: str = "local"
    """local (process pool), serial (this process) or ray"""
    workers: int = 2
    """parallel jobs"""
    progress: bool = True
    """progress bars"""

    def setting(self, name: str) -> int:
        """An option's value: as given, else the quick or full default."""
        value = getattr(self, name)
        return (QUICK if self.quick else FULL)[name] if value is None else int(value)


def prepare_out(out: Path, resume: bool) -> Path:
    """The output folder, checked before any work: new or empty, or (``resume``) holding an earlier bench's files."""
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {str(out)!r} is a file; give a folder (new or empty)")
    if out.is_dir() and any(out.iterdir()) and not resume:
        found = sorted(p.name for p in out.iterdir())
        raise ValueError(
            f"--out {str(out)!r} is not empty ({', '.join(found[:4])}{', ...' if len(found) > 4 else ''}); give a new or empty "
            "folder, or add --resume to continue an interrupted run there"
        )
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ValueError(f"--out {str(out)!r} cannot be created ({err.strerror or err}); give a writable folder") from err
    return out


def check(args: BenchArgs) -> tuple[str, list[str]]:
    """Check the arguments before any work; return the protocol and the reference names.

    Raises:
        ValueError: an unknown agent, maze, protocol, engine or reference, or a bad number.
    """
    from hippo_env.maze import MazeSpec
    from hippomaze import engine
    from hippomaze.bench.jobs import PROTOCOLS
    from hippomaze.bench.references import available
    from hippomaze.registry import agent_factory

    for name in ("seeds", "budget", "trials", "runs"):
        if args.setting(name) < 1:
            raise ValueError(f"--{name.replace('_', '-')} must be a positive integer, got {args.setting(name)}")
    if args.setting("switch_budget") < 0:
        raise ValueError(f"--switch-budget must be 0 or more, got {args.setting('switch_budget')}")
    if args.workers < 1:
        raise ValueError(f"--workers must be a positive integer, got {args.workers}")
    engine.check_engine(args.engine)
    protocol = default_protocol(args.agent) if args.protocol == "auto" else args.protocol
    if protocol not in PROTOCOLS:
        raise ValueError(f"--protocol {args.protocol!r} is unknown; protocols: auto, {', '.join(PROTOCOLS)}")
    if not args.mazes:
        raise ValueError("give at least one --maze")
    for maze in args.mazes:
        MazeSpec.load(maze)  # an unknown maze: its ValueError names the built-in ones
    try:
        agent_factory(args.agent)  # an unknown agent, or one not following the protocol: a clear error now
    except ImportError as err:  # a missing optional extra (dqn, ppo): one line says how to install it
        raise ValueError(str(err)) from err
    shipped = available()
    references = list(shipped if args.references is None else args.references)
    unknown = [r for r in references if r not in shipped]
    if unknown:
        raise ValueError(f"--reference: no shipped reference {', '.join(map(repr, unknown))}; references: {', '.join(shipped)}")
    return protocol, references


def run_bench(args: BenchArgs, command: str | None = None) -> dict[str, Any]:
    """Measure ``args.agent``, compare it with the shipped references, write ``bench.json``,
    ``bench.png`` and ``bench.md`` into ``args.out``; return the JSON document."""
    from hippomaze.bench.figures import plot_bench
    from hippomaze.bench.references import load_references
    from hippomaze.bench.report import comparison_markdown
    from hippomaze.bench.runner import run_jobs
    from hippomaze.bench.summary import analyse, compare

    protocol, reference_names = check(args)
    out = prepare_out(Path(args.out), args.resume)
    label = args.label or args.agent
    jobs = [
        make_job(args.agent, maze, seed, protocol=protocol, budget=args.setting("budget"), switch_budget=args.setting("switch_budget"),
                 trials=args.setting("trials"), runs=args.setting("runs"), label=label)
        for maze in args.mazes for seed in range(args.setting("seeds"))
    ]  # fmt: skip
    command = command or "hippomaze bench " + shlex.join(sys.argv[1:])
    began = time.perf_counter()
    records, ran = run_jobs(jobs, out / "jobs", engine=args.engine, workers=args.workers, progress=args.progress, command=command)
    results = analyse([records[j.name] for j in jobs], WINDOW, tuple(args.mazes))
    (yours,) = results.values()
    references = load_references(reference_names)
    focus = f"{label} (this run)" if label in references else label
    yours.variant = focus
    everything = {focus: yours, **{name: ref.result for name, ref in references.items()}}
    comparison = compare(everything, focus, list(args.mazes))
    table = comparison_markdown(comparison, everything)
    missing = [m for m in args.mazes if not any(m in ref.result.mazes for ref in references.values())]
    notes = [f"no shipped reference ran in {', '.join(missing)}"] if missing else []
    document = {
        "command": command,
        "args": dataclasses.asdict(args),
        "protocol": protocol,
        "settings": {name: args.setting(name) for name in FULL},
        "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "versions": versions(),
        "wall_seconds": round(time.perf_counter() - began, 1),
        "jobs_run": len(ran),
        "jobs_reused": len(jobs) - len(ran),
        "notes": notes,
        "table_markdown": table,
        "statistics": comparison.to_dict(),
        "agent": yours.to_dict(),
        "references": {name: {"made": ref.made, "result": ref.result.to_dict()} for name, ref in references.items()},
    }
    write_json(out / "bench.json", document)
    plot_bench(everything, comparison, out / "bench.png")
    (out / "bench.md").write_text(_markdown(document, comparison.focus))
    return document


def _markdown(document: dict[str, Any], focus: str) -> str:
    settings = document["settings"]
    if document["protocol"] == "learner":
        how = f"one long trial of {settings['budget']:,} steps per seed"
    else:
        how = f"{settings['trials']} fresh-agent trials of {settings['runs']} runs per seed"
    lines = [
        f"# {focus} beside the shipped references",
        "",
        (
            f"`{document['command']}` ({document['date']}): {how}, {settings['seeds']} seeds per maze, "
            f"goal switch within {settings['switch_budget']:,} steps."
        ),
        "",
        (
            "Steps (every environment step, the dry run included) until the agent is direct: its run under way is a "
            "direct success and so are >= 90 % of its 10 runs from there, with median indirectness <= 1. "
            "IQM over seeds [95 % stratified-bootstrap interval] (seeds that got there / seeds); "
            "P(faster): rliable's probability of improvement over the mazes."
        ),
        "",
        document["table_markdown"],
        "",
    ]
    lines += [f"Note: {note}." for note in document["notes"]]
    return "\n".join(lines) + "\n"
