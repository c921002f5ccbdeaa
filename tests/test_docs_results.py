"""The documentation's results tables (``docs/hooks.py``): every table is made from the committed
results, and a results file that is missing or malformed fails ``make docs`` instead of leaving a
note on the page."""

from __future__ import annotations

import importlib.util
import json
import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest

from benchmarks.records import RecordError

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture
def hooks():
    spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "docs" / "hooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_table_is_made_from_the_committed_results(hooks):
    for name in hooks.TABLES:
        assert hooks.render(name).strip(), name


def test_a_missing_results_file_fails(hooks, monkeypatch, tmp_path):
    monkeypatch.setattr(hooks, "RESULTS", tmp_path)  # no results at all
    for name in hooks.TABLES:
        with pytest.raises(RecordError, match=name):
            hooks.render(name)


def test_a_malformed_results_file_fails(hooks, monkeypatch, tmp_path):
    shutil.copytree(hooks.RESULTS, tmp_path, dirs_exist_ok=True)
    monkeypatch.setattr(hooks, "RESULTS", tmp_path)
    (tmp_path / "maze_suite_default.json").write_text("{ not json")
    with pytest.raises(RecordError, match="cannot be read as JSON"):
        hooks.render("maze_suite")
    (tmp_path / "env_throughput.json").write_text(json.dumps({"command": "x", "single_env": [{"maze": "open"}]}))
    with pytest.raises(RecordError, match="env_throughput"):
        hooks.render("env_throughput")


def test_the_build_stops_on_a_missing_results_file(hooks, monkeypatch, tmp_path):
    """mkdocs aborts a build on a PluginError, with or without --strict."""
    exceptions = pytest.importorskip("mkdocs.exceptions", reason="the docs extra: pip install -e .[docs]")
    monkeypatch.setattr(hooks, "RESULTS", tmp_path)
    page = SimpleNamespace(file=SimpleNamespace(src_uri="benchmarks.md"))
    config = {"docs_dir": str(ROOT / "docs")}
    with pytest.raises(exceptions.PluginError, match="benchmarks.md"):
        hooks.on_page_markdown("# Speed\n\n<!-- results: agent_scaling -->\n", page, config, None)
    assert hooks.on_page_markdown("# No table here\n", page, config, None).startswith("# No table here")
