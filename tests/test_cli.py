"""The `hippomaze` console script: records, figures, printed table and clear errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from hippo_agent.cli import main


class ForwardAgent:
    """A third-party agent: always heads east (action 0). Follows the protocol, nothing else."""

    def __init__(self, observation_space, action_space, seed=None):
        self.steps = 0

    def reset(self, observation, info):
        pass

    def act(self, observation):
        return 0

    def observe(self, action, observation, reward, terminated, truncated, info):
        self.steps += 1


def test_dmtp_writes_contract_record_and_figures(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["dmtp", "--maze", "maze1", "--trials", "2", "--runs", "2", "--seed", "3", "--agent", "random", "--max-steps", "150", "--out", str(out), "--no-progress"])
    assert code == 0
    record = json.loads((out / "dmtp.json").read_text())
    assert {"maze", "agent", "seed", "trials", "runs", "env_steps_total", "episodes"} <= set(record)
    assert record["maze"] == "maze1" and record["agent"] == "random" and record["seed"] == 3
    assert len(record["episodes"]) == 4
    keys = {"trial", "run", "steps", "success", "path_length", "shortest_path_length", "indirectness", "start", "goal"}
    for episode in record["episodes"]:
        assert set(episode) == keys
    assert record["env_steps_total"] == sum(e["steps"] for e in record["episodes"])
    for name in ("indirectness.png", "run1_length_vs_run2_indirectness.png", "paths_trial01.png", "paths_trial02.png"):
        assert (out / name).stat().st_size > 1000
    printed = capsys.readouterr().out
    assert "run 1" in printed and "median" in printed


def test_same_seed_same_record(tmp_path):
    args = ["dmtp", "--trials", "1", "--runs", "2", "--agent", "random", "--max-steps", "100", "--no-figures", "--no-progress"]
    main(args + ["--out", str(tmp_path / "a")])
    main(args + ["--out", str(tmp_path / "b")])
    assert (tmp_path / "a" / "dmtp.json").read_text() == (tmp_path / "b" / "dmtp.json").read_text()


def test_third_party_agent_by_module_path(tmp_path):
    out = tmp_path / "mine"
    code = main(["dmtp", "--trials", "1", "--runs", "1", "--agent", "tests.test_cli:ForwardAgent", "--max-steps", "50", "--no-figures", "--no-progress", "--out", str(out)])
    assert code == 0
    record = json.loads((out / "dmtp.json").read_text())
    assert record["agent"] == "tests.test_cli:ForwardAgent"
    assert record["episodes"][0]["steps"] <= 50


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--maze", "maze9"], "maze 'maze9' is unknown"),
        (["--agent", "nobody"], "agent 'nobody' is unknown"),
        (["--agent", "tests.test_cli:Missing"], "has no attribute 'Missing'"),
        (["--trials", "0"], "trials must be a positive integer"),
    ],
)
def test_bad_arguments_are_clear_errors(tmp_path, capsys, args, message):
    code = main(["dmtp", "--out", str(tmp_path), "--no-progress", *args])
    assert code == 2
    assert message in capsys.readouterr().err


def test_console_script_is_installed():
    script = Path(sys.executable).parent / "hippomaze"
    assert script.exists(), "the editable install should put the hippomaze console script beside python"
    done = subprocess.run([str(script), "dmtp", "--help"], capture_output=True, text=True, check=True)
    assert "--trials" in done.stdout
