"""``benchmarks.end_to_end``: the commands it times, the checkouts it runs, the record it writes;
with ``hippomaze --help`` standing in for the long commands. Nothing here asserts a speed."""

from __future__ import annotations

import json

import pytest

from benchmarks import end_to_end
from benchmarks.common import REPO

pytestmark = pytest.mark.skipif(end_to_end._git(REPO, "rev-parse", "HEAD") is None, reason="needs the git repository (git:REV checkouts)")


def test_command_args():
    assert end_to_end.command_args("dmtp", "OUT", quick=False) == [
        "dmtp", "--maze", "open", "--trials", "20", "--runs", "4", "--seed", "0", "--out", "OUT",
    ]  # fmt: skip
    assert "2" in end_to_end.command_args("dmtp", "OUT", quick=True)
    assert end_to_end.command_args("paper", "OUT", quick=False) == ["paper", "--out", "OUT"]
    assert end_to_end.command_args("paper", "OUT", quick=True) == ["paper", "--out", "OUT", "--quick"]
    with pytest.raises(ValueError, match="unknown; allowed: dmtp, paper"):
        end_to_end.command_args("train", "OUT", quick=False)


def test_checkouts_this_folder_and_an_exported_revision():
    with end_to_end.checkouts((".", "git:HEAD")) as (here, exported):
        assert here.folder == REPO and len(here.revision) == 40
        assert exported.revision == here.revision and exported.dirty is False
        assert (exported.folder / "hippomaze" / "cli.py").exists() and not (exported.folder / ".git").exists()
        folder = exported.folder
    assert not folder.exists()  # the export is removed afterwards
    with pytest.raises(ValueError, match="not a revision"), end_to_end.checkouts(("git:no-such-revision",)):
        pass
    with pytest.raises(ValueError, match="no hippomaze/cli.py"), end_to_end.checkouts(("/",)):
        pass


def test_main_times_each_checkout_alternating(tmp_path, monkeypatch):
    monkeypatch.setattr(end_to_end, "command_args", lambda which, out, quick: ["--help"])
    out = tmp_path / "e2e.json"
    status = end_to_end.main(["--which", "dmtp", "--repos", ".", "git:HEAD", "--repeats", "2", "--no-warmup", "--out", str(out)])
    assert status == 0
    record = json.loads(out.read_text())
    assert [(r["repeat"], r["checkout"]) for r in record["runs"]] == [(0, "."), (0, "git:HEAD"), (1, "git:HEAD"), (1, ".")]
    for run in record["runs"]:
        assert run["returncode"] == 0 and run["wall_seconds"] > 0 and run["cpu_seconds"] > 0
        assert run["load_average_before"] is not None
    assert [(s["checkout"], s["runs"], s["failed"]) for s in record["summary"]] == [(".", 2, 0), ("git:HEAD", 2, 0)]
    assert record["command"].startswith("python") and record["checkouts"][1]["revision"] == record["checkouts"][0]["revision"]
    assert record["machine"]["load_average_at_start"] is not None
