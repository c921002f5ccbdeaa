"""What the benchmark scripts share: their command line from a dataclass, and what a record says
about the machine it ran on (``hippomaze.runinfo``), with paths relative to the repository."""

from __future__ import annotations

from pathlib import Path

from hippomaze import runinfo
from hippomaze.runinfo import ArgsT, cpu_model, load_average, machine_info, parse_dataclass_args

__all__ = ["REPO", "ArgsT", "command_line", "cpu_model", "load_average", "machine_info", "output_path", "parse_dataclass_args"]

REPO = Path(__file__).resolve().parent.parent


def command_line() -> str:
    """The command that ran this script, with the script's path relative to the repository."""
    return runinfo.command_line(REPO)


def output_path(out: str) -> Path:
    """Where a script's ``--out`` goes (relative to the repository unless absolute), its folder made."""
    path = Path(out) if Path(out).is_absolute() else REPO / out
    path.parent.mkdir(parents=True, exist_ok=True)
    return path
