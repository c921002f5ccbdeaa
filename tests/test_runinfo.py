"""hippomaze.runinfo: what a record says about how it was made."""

from __future__ import annotations

import sys

from benchmarks.common import REPO
from hippomaze import runinfo


def test_a_benchmark_records_the_command_that_runs_it_from_the_repository(monkeypatch):
    """A module of the benchmarks package is recorded as ``python -m benchmarks.<module>``: run as a
    file from the repository, its ``from benchmarks...`` imports would fail. A script elsewhere keeps its path."""
    monkeypatch.setattr(sys, "argv", [str(REPO / "benchmarks" / "changing_world.py"), "--seeds", "1"])
    assert runinfo.command_line(REPO) == "python -m benchmarks.changing_world --seeds 1"
    monkeypatch.setattr(sys, "argv", ["tools/my script.py", "--x"])
    assert runinfo.command_line(REPO) == "python 'tools/my script.py' --x"
