"""End to end: wall and CPU seconds of whole ``hippomaze`` commands, each run as a subprocess.

Times ``hippomaze dmtp --maze open --trials 20 --runs 4 --seed 0 --out TMP`` and ``hippomaze paper
--out TMP`` (``--which``), each into a fresh temporary folder deleted afterwards. CPU seconds are
the children's user + system time (``resource.getrusage(RUSAGE_CHILDREN)`` before and after: every
process the command starts and waits for, ``hippomaze paper``'s workers included), so on a machine
with other load CPU seconds say more than wall seconds do. Several checkouts (``--repos``) are timed
side by side, alternating (the order flips every repeat), so that "before" and "after" a change see
the same machine: a folder runs its own code (its ``.venv/bin/python`` if it has one, else this
interpreter, with the folder first on ``PYTHONPATH`` and as the working directory, as ``python -m
hippomaze.cli``), and ``git:REV`` is that revision of this repository, exported with ``git archive``
into a temporary folder. Each record holds the revision (and whether the folder had uncommitted
changes) and the load average before and after each command.

    python -m benchmarks.end_to_end                                  # this checkout, dmtp and paper
    python -m benchmarks.end_to_end --repos . git:b583adf --repeats 2 --out benchmarks/results/end_to_end.json
    python -m benchmarks.end_to_end --which dmtp --quick --out /tmp/e2e.json   # a smoke run (--trials 2, paper --quick)
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import os
import resource
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import hippo_env
from benchmarks.common import REPO, command_line, load_average, machine_info, output_path, parse_dataclass_args

COMMANDS = ("dmtp", "paper")


@dataclass
class Args:
    which: tuple[str, ...] = COMMANDS
    """the commands to time: dmtp, paper"""
    repos: tuple[str, ...] = (".",)
    """checkouts to time, side by side: folders (relative to this repository unless absolute) or git:REV"""
    repeats: int = 1
    """times each command is timed per checkout (the order of the checkouts flips every repeat)"""
    quick: bool = False
    """a smoke run: dmtp with --trials 2, paper with --quick"""
    warmup: bool = True
    """first an untimed dmtp of one trial and one run per checkout (numba compiles and caches its kernels)"""
    out: str = "benchmarks/results/end_to_end.json"
    """where the JSON goes (relative to the repository root unless absolute)"""


def command_args(which: str, out: str, quick: bool) -> list[str]:
    """The ``hippomaze`` arguments of one timed command, writing into ``out``."""
    if which == "dmtp":
        return ["dmtp", "--maze", "open", "--trials", "2" if quick else "20", "--runs", "4", "--seed", "0", "--out", out]
    if which == "paper":
        return ["paper", "--out", out, *(["--quick"] if quick else [])]
    raise ValueError(f"command {which!r} is unknown; allowed: {', '.join(COMMANDS)}")


@dataclass
class Checkout:
    """Code to run: its folder, the interpreter that runs it, and what it is."""

    name: str
    folder: Path
    python: str
    revision: str | None
    dirty: bool | None


@contextlib.contextmanager
def checkouts(specs: tuple[str, ...]) -> Iterator[list[Checkout]]:
    """The checkouts named by ``specs`` (exported revisions live as long as the ``with``)."""
    with contextlib.ExitStack() as stack:
        found = []
        for spec in specs:
            if spec.startswith("git:"):
                revision = _git(REPO, "rev-parse", "--verify", f"{spec[4:]}^{{commit}}")
                if revision is None:
                    raise ValueError(f"{spec!r}: {spec[4:]!r} is not a revision of {REPO}")
                folder = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix=f"hippomaze-{revision[:8]}-")))
                export(revision, folder)
                found.append(Checkout(spec, folder, sys.executable, revision, False))
            else:
                folder = Path(spec) if Path(spec).is_absolute() else (REPO / spec).resolve()
                if not (folder / "hippomaze" / "cli.py").exists():
                    raise ValueError(f"{spec!r}: {folder} holds no hippomaze/cli.py; give a hippomaze checkout or git:REV")
                venv = folder / ".venv" / "bin" / "python"
                status = _git(folder, "status", "--porcelain", "--untracked-files=no")
                found.append(
                    Checkout(
                        spec,
                        folder,
                        str(venv) if venv.exists() else sys.executable,
                        _git(folder, "rev-parse", "HEAD"),
                        None if status is None else bool(status),
                    )
                )
        yield found


def export(revision: str, folder: Path) -> None:
    """``git archive revision`` unpacked into ``folder`` (no .git: the repository is not touched)."""
    with tempfile.TemporaryFile() as archive:
        subprocess.run(["git", "-C", str(REPO), "archive", "--format=tar", revision], stdout=archive, check=True)
        archive.seek(0)
        with tarfile.open(fileobj=archive) as tar:
            tar.extractall(folder, filter="data")


def _git(folder: Path, *args: str) -> str | None:
    done = subprocess.run(["git", "-C", str(folder), *args], capture_output=True, text=True, check=False)
    return done.stdout.strip() if done.returncode == 0 else None


def run(checkout: Checkout, hippomaze_args: list[str]) -> dict[str, Any]:
    """Run ``hippomaze ARGS`` from ``checkout``: wall seconds, the children's CPU seconds, the load."""
    environment = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(checkout.folder), os.environ.get("PYTHONPATH")])))
    environment["MPLBACKEND"] = "Agg"
    load_before = load_average()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    began = time.perf_counter()
    done = subprocess.run(
        [checkout.python, "-m", "hippomaze.cli", *hippomaze_args],
        cwd=checkout.folder,
        env=environment,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        check=False,
    )
    wall = time.perf_counter() - began
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    user, system = after.ru_utime - before.ru_utime, after.ru_stime - before.ru_stime
    return {
        "wall_seconds": round(wall, 3),
        "cpu_seconds": round(user + system, 3),
        "user_seconds": round(user, 3),
        "system_seconds": round(system, 3),
        "returncode": done.returncode,
        "stderr_tail": None if done.returncode == 0 else done.stderr[-2000:],
        "load_average_before": load_before,
        "load_average_after": load_average(),
    }


def time_all(args: Args, found: list[Checkout]) -> list[dict[str, Any]]:
    """Every (repeat, command, checkout), the checkouts' order flipped every repeat; a fresh
    output folder for each run, deleted after it."""
    for which in args.which:
        command_args(which, "TMP", args.quick)  # an unknown command fails before anything runs
    if args.warmup:
        for checkout in found:
            with tempfile.TemporaryDirectory(prefix="hippomaze-e2e-") as out:
                warm = run(
                    checkout, ["dmtp", "--maze", "open", "--trials", "1", "--runs", "1", "--seed", "0", "--out", out, "--no-figures"]
                )
            print(f"  warm-up {checkout.name}: {warm['wall_seconds']:.1f} s" + ("" if warm["returncode"] == 0 else " (failed)"), flush=True)
    runs = []
    for repeat in range(args.repeats):
        order = found if repeat % 2 == 0 else found[::-1]
        for which in args.which:
            for checkout in order:
                with tempfile.TemporaryDirectory(prefix="hippomaze-e2e-") as out:
                    measured = run(checkout, command_args(which, out, args.quick))
                runs.append(
                    {
                        "repeat": repeat,
                        "command": which,
                        "checkout": checkout.name,
                        "hippomaze": " ".join(["hippomaze", *command_args(which, "TMP", args.quick)]),
                        **measured,
                    }
                )
                print(
                    f"  {which:5s} {checkout.name:>16s} (repeat {repeat + 1}): {measured['wall_seconds']:8.1f} s wall, "
                    f"{measured['cpu_seconds']:8.1f} CPU s"
                    + ("" if measured["returncode"] == 0 else f"  FAILED ({measured['returncode']})"),
                    flush=True,
                )
    return runs


def summarise(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Median wall and CPU seconds of the successful runs, per command and checkout."""
    out = []
    for which in dict.fromkeys(r["command"] for r in runs):
        for name in dict.fromkeys(r["checkout"] for r in runs):
            mine = [r for r in runs if r["command"] == which and r["checkout"] == name]
            ok = [r for r in mine if r["returncode"] == 0]
            out.append(
                {
                    "command": which,
                    "checkout": name,
                    "runs": len(mine),
                    "failed": len(mine) - len(ok),
                    "median_wall_seconds": round(statistics.median(r["wall_seconds"] for r in ok), 3) if ok else None,
                    "median_cpu_seconds": round(statistics.median(r["cpu_seconds"] for r in ok), 3) if ok else None,
                }
            )
    return out


def main(argv: list[str] | None = None) -> int:
    args = parse_dataclass_args(Args, __doc__.splitlines()[0], argv)
    load_at_start = load_average()
    print(
        f"hippomaze end to end: {', '.join(args.which)} x {args.repeats} for {', '.join(args.repos)}" + (" (quick)" if args.quick else "")
    )
    with checkouts(args.repos) as found:
        runs = time_all(args, found)
        described = [
            {"name": c.name, "revision": c.revision, "uncommitted_changes": c.dirty, "python": c.python, "folder": str(c.folder)}
            for c in found
        ]
    record = {
        "command": command_line(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "args": dataclasses.asdict(args),
        "machine": machine_info(hippo_env=hippo_env.__version__)
        | {"load_average_at_start": load_at_start, "load_average_at_end": load_average()},
        "checkouts": described,
        "runs": runs,
        "summary": summarise(runs),
    }
    out = output_path(args.out)
    hippo_env.write_json(out, record)
    for row in record["summary"]:
        print(
            f"  {row['command']:5s} {row['checkout']:>16s}: median {row['median_wall_seconds']} s wall, {row['median_cpu_seconds']} CPU s"
        )
    print(f"wrote {out}")
    return 1 if any(r["returncode"] != 0 for r in runs) else 0


if __name__ == "__main__":
    sys.exit(main())
