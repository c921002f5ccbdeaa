"""What the benchmark scripts share: their command line from a dataclass, and what a record says
about the machine it ran on (``hippomaze.runinfo``), with paths relative to the repository."""

from __future__ import annotations

from pathlib import Path

from hippomaze import runinfo
from hippomaze.runinfo import ArgsT, cpu_model, load_average, machine_info, parse_dataclass_args

__all__ = ["REPO", "ArgsT", "command_line", "cpu_model", "load_average", "machine_info", "parse_dataclass_args"]

REPO = Path(__file__).resolve().parent.parent


def command_line() -> str:
    """The command that ran this script, with the script's path relative to the repository."""
    return runinfo.command_line(REPO)
