"""The `hippomaze` console script: records, figures, printed table and clear errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from hippomaze.cli import main


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
    code = main(
        [
            "dmtp",
            "--maze",
            "maze1",
            "--trials",
            "2",
            "--runs",
            "2",
            "--seed",
            "3",
            "--agent",
            "random",
            "--max-steps",
            "150",
            "--out",
            str(out),
            "--no-progress",
        ]
    )
    assert code == 0
    record = json.loads((out / "dmtp.json").read_text())
    assert {"maze", "agent", "seed", "trials", "runs", "env_steps_total", "episodes"} <= set(record)
    assert record["maze"] == "maze1" and record["agent"] == "random" and record["seed"] == 3
    assert len(record["episodes"]) == 4
    keys = {"trial", "run", "steps", "success", "path_length", "shortest_path_length", "indirectness", "start", "goal"}
    for run in record["episodes"]:
        assert set(run) == keys
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
    code = main(
        [
            "dmtp",
            "--trials",
            "1",
            "--runs",
            "1",
            "--agent",
            "tests.test_cli:ForwardAgent",
            "--max-steps",
            "50",
            "--no-figures",
            "--no-progress",
            "--out",
            str(out),
        ]
    )
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


# ---------------------------------------------------------------------- output folder, Ctrl-C, atomic writes
QUICK = ["dmtp", "--trials", "1", "--runs", "1", "--agent", "random", "--max-steps", "20", "--no-progress"]


class InterruptingAgent(ForwardAgent):
    """Heads east; the third run it starts is interrupted as if by Ctrl-C deep inside the agent."""

    runs_started = 0

    def reset(self, observation, info):
        type(self).runs_started += 1

    def act(self, observation):
        if type(self).runs_started >= 3:
            raise KeyboardInterrupt
        return 0


def test_out_naming_a_file_fails_before_any_work(tmp_path, capsys, monkeypatch):
    target = tmp_path / "results.txt"
    target.write_text("mine")
    import hippo_env.dmtp

    monkeypatch.setattr(hippo_env.dmtp, "run_dmtp", lambda *a, **k: pytest.fail("the experiment ran"))
    assert main([*QUICK, "--out", str(target)]) == 2
    assert "is a file; give a folder" in capsys.readouterr().err
    assert target.read_text() == "mine"


def test_out_folder_with_results_is_refused_without_overwrite(tmp_path, capsys):
    out = tmp_path / "run"
    assert main([*QUICK, "--out", str(out)]) == 0
    before = (out / "dmtp.json").read_text()
    capsys.readouterr()
    assert main([*QUICK, "--seed", "5", "--out", str(out), "--no-figures"]) == 2
    err = capsys.readouterr().err
    assert "is not empty" in err and "--overwrite" in err
    assert (out / "dmtp.json").read_text() == before


def test_overwrite_clears_what_dmtp_wrote_and_nothing_else(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["dmtp", "--trials", "2", "--runs", "1", "--agent", "random", "--max-steps", "20", "--no-progress", "--out", str(out)]) == 0
    assert (out / "paths_trial02.png").exists()
    (out / "notes.txt").write_text("keep me")
    capsys.readouterr()
    assert main([*QUICK, "--seed", "5", "--out", str(out), "--overwrite"]) == 0
    assert "--overwrite: deleted" in capsys.readouterr().err
    assert not (out / "paths_trial02.png").exists(), "a stale figure of the earlier run was left behind"
    assert (out / "paths_trial01.png").exists() and (out / "notes.txt").read_text() == "keep me"
    assert json.loads((out / "dmtp.json").read_text())["seed"] == 5


def test_ctrl_c_saves_finished_runs_and_exits_130(tmp_path, capsys):
    InterruptingAgent.runs_started = 0
    out = tmp_path / "run"
    code = main(
        [
            "dmtp",
            "--trials",
            "3",
            "--runs",
            "1",
            "--agent",
            "tests.test_cli:InterruptingAgent",
            "--max-steps",
            "15",
            "--no-progress",
            "--out",
            str(out),
        ]
    )
    assert code == 130
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "saved the 2 finished runs of 3" in err
    record = json.loads((out / "dmtp.json").read_text())
    assert record["complete"] is False
    assert [e["trial"] for e in record["episodes"]] == [0, 1]
    assert not list(out.glob(".*.tmp")), "a temporary file was left behind"


def test_complete_runs_are_marked_complete(tmp_path):
    out = tmp_path / "run"
    assert main([*QUICK, "--no-figures", "--out", str(out)]) == 0
    assert "complete" not in json.loads((out / "dmtp.json").read_text())  # exactly the documented keys


def test_dmtp_json_is_written_atomically(tmp_path, monkeypatch):
    """A crash while writing leaves the earlier dmtp.json whole (a temporary file, then rename)."""
    import hippo_env.files
    from hippo_env.dmtp import DMTPResult

    result = DMTPResult(maze="open", agent="x", seed=0, trials=1, runs=1)
    result.save(tmp_path)
    before = (tmp_path / "dmtp.json").read_text()

    def crash(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(hippo_env.files.os, "replace", crash)
    result.seed = 1
    with pytest.raises(OSError, match="disk full"):
        result.save(tmp_path)
    assert (tmp_path / "dmtp.json").read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dmtp.json", "paths.npz"]


# ---------------------------------------------------------------------- plugging in an agent
class NoSeedAgent(ForwardAgent):
    """A third-party agent whose constructor has no ``seed`` keyword."""

    def __init__(self, observation_space, action_space):
        self.steps = 0


class NoSpacesAgent(ForwardAgent):
    """A constructor that cannot take the two spaces."""

    def __init__(self):
        self.steps = 0


def test_agent_without_seed_keyword_is_accepted(tmp_path):
    out = tmp_path / "noseed"
    assert main([*QUICK[:5], "--agent", "tests.test_cli:NoSeedAgent", *QUICK[7:], "--no-figures", "--out", str(out)]) == 0
    assert json.loads((out / "dmtp.json").read_text())["agent"] == "tests.test_cli:NoSeedAgent"


def test_agent_with_unusable_constructor_is_a_one_line_error(tmp_path, capsys):
    code = main([*QUICK[:5], "--agent", "tests.test_cli:NoSpacesAgent", *QUICK[7:], "--out", str(tmp_path / "x")])
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "must be __init__(self, observation_space, action_space, seed=None)" in err


def test_agent_module_in_the_current_folder_is_found(tmp_path, monkeypatch):
    """``--agent mymodule:MyAgent`` imports ./mymodule.py without PYTHONPATH=., as ``python -m`` would."""
    (tmp_path / "my_local_agent_module.py").write_text(
        "class Mine:\n"
        "    def __init__(self, observation_space, action_space, seed=None): pass\n"
        "    def reset(self, observation, info): pass\n"
        "    def act(self, observation): return 2\n"
        "    def observe(self, *args): pass\n"
    )
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in ("", str(tmp_path), ".")])
    monkeypatch.delitem(sys.modules, "my_local_agent_module", raising=False)
    assert main([*QUICK[:5], "--agent", "my_local_agent_module:Mine", *QUICK[7:], "--no-figures", "--out", "out"]) == 0
    assert (tmp_path / "out" / "dmtp.json").exists()


@pytest.mark.parametrize("command", [["dmtp"], ["paper"]])
def test_negative_seed_names_the_option(command, capsys):
    with pytest.raises(SystemExit) as exit_:
        main([*command, "--seed", "-1"])
    assert exit_.value.code == 2
    assert "argument --seed: must be a non-negative integer, got '-1'" in capsys.readouterr().err


def test_paper_help_describes_the_command_and_seed(capsys):
    with pytest.raises(SystemExit):
        main(["paper", "--help"])
    printed = capsys.readouterr().out
    assert "Reproduce the paper's experiments" in printed
    assert "base seed" in printed
