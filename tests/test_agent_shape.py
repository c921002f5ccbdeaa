"""The agent's shape: a loop short enough to read, a config in few sections, files of bounded size."""

from __future__ import annotations

import dataclasses
import inspect
from pathlib import Path

import pytest

from hippo_agent import AgentConfig, HippocampalAgent

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("hippo_env", "hippo_agent", "hippomaze", "baselines", "benchmarks")


@pytest.mark.parametrize("method", ["reset", "act", "observe"])
def test_the_agents_loop_methods_are_short(method):
    lines = inspect.getsource(getattr(HippocampalAgent, method)).splitlines()
    assert len(lines) <= 40, f"HippocampalAgent.{method} has {len(lines)} lines; the loop should read at a glance (<= 40)"


def test_the_config_has_few_top_level_sections():
    assert len(dataclasses.fields(AgentConfig)) <= 20


def test_no_source_file_is_over_600_lines():
    long = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            n = len(path.read_text().splitlines())
            if n > 600:
                long[str(path.relative_to(ROOT))] = n
    assert not long, f"files over 600 lines (split them by responsibility): {long}"
