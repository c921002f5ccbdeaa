"""Schedules of DMTP phases: validation, what the runner does in each phase, the record, the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hippomaze.baselines.random_agent import RandomAgent

from hippo_env.agent_protocol import AgentBase
from hippo_env.dmtp import DMTPFailed, run_dmtp
from hippo_env.maze import MazeSpec
from hippo_env.schedule import Phase, Schedule, SchedulePlanner
from hippomaze.cli import main

SMALL = {"name": "small", "size": [4.0, 4.0], "obstacles": []}
BLOCKS = {"base": SMALL, "change": "blocks", "seed": 3, "count": 2}


class Recorder(AgentBase):
    """Random steps; records every call the runner makes. ``dry_steps`` steps in each dry run."""

    built: list[Recorder] = []  # noqa: RUF012 (a test's log)
    dry_steps = 5

    def __init__(self, observation_space, action_space, seed=None, speed=1):
        super().__init__(observation_space, action_space, seed)
        self.rng = np.random.default_rng(seed)
        self.speed = speed
        self.config = {"speed": speed}  # recorded as dmtp.json's agent_config
        self.calls: list[tuple] = []
        self.truncated: list[bool] = []
        Recorder.built.append(self)

    def dry_run(self, env):
        self.calls.append(("dry_run",))
        env.reset(options={"goal": None})
        for _ in range(self.dry_steps):
            env.step(int(self.rng.integers(8)))

    def start_trial(self, trial):
        self.calls.append(("start_trial", trial))

    def reset(self, observation, info):
        self.calls.append(("reset", tuple(np.round(info["goal"], 6))))

    def act(self, observation):
        return int(self.rng.integers(8))

    def observe(self, action, observation, reward, terminated, truncated, info):
        if terminated or truncated:
            self.truncated.append(bool(truncated))


class Stuck(Recorder):
    """Drives into the east wall for ever: never reaches the goal (unless it starts next to it)."""

    def act(self, observation):
        return 0


@pytest.fixture(autouse=True)
def _fresh_log():
    Recorder.built = []


def _run(phases, agent=Recorder, seed=0, repeats=1, **kwargs):
    return run_dmtp(agent, schedule={"phases": phases, "repeats": repeats}, seed=seed, progress=False, max_episode_steps=60, **kwargs)


# ------------------------------------------------------------------ validation
@pytest.mark.parametrize(
    ("schedule", "message"),
    [
        ({"phases": []}, "at least one phase"),
        ({"phases": {"maze": "open"}}, "'phases' must be a list"),
        ({"phase": [{"maze": "open"}]}, "unknown key(s) 'phase'; allowed: phases, repeats, description"),
        ({"phases": [{"maze": "open"}], "repeats": 0}, "schedule: 'repeats' must be an integer >= 1, got 0"),
        ({"phases": [{"trials": 2}]}, "schedule phase 0: 'maze' is missing"),
        ({"phases": [{"maze": "open", "trials": 0}]}, "schedule phase 0: 'trials' must be an integer >= 1, got 0"),
        ({"phases": [{"maze": "open"}, {"runs": "4"}]}, "schedule phase 1: 'runs' must be an integer >= 1, got '4'"),
        ({"phases": [{"maze": "open", "goal": "kept"}]}, "schedule phase 0: 'goal' is 'kept', but the first phase has no previous"),
        (
            {"phases": [{"maze": "open"}, {"goal": {"phase": 1}}]},
            "schedule phase 1: 'goal' {'phase': 1} must name an earlier phase, 0 to 0",
        ),
        ({"phases": [{"maze": "open", "goal": {"phase": 0}}]}, "must name an earlier phase, and the first phase has none"),
        ({"phases": [{"maze": "open", "goal": {"phase": -1}}]}, "'goal' {'phase': -1} is not allowed"),
        ({"phases": [{"maze": "open", "goal": "there"}]}, "'goal' 'there' is unknown; allowed: 'new', 'kept'"),
        ({"phases": [{"maze": "open", "goal": [1, "x"]}]}, "schedule phase 0: 'goal' [1, 'x'] is not allowed"),
        ({"phases": [{"maze": "open", "dry_run": "yes"}]}, "schedule phase 0: 'dry_run' must be true or false, got 'yes'"),
        ({"phases": [{"maze": "open", "announce": 1}]}, "'announce' must be true or false"),
        ({"phases": [{"maze": "open", "min_start_distance": -1}]}, "'min_start_distance' must be a finite number of metres >= 0"),
        ({"phases": [{"maze": "open", "max_steps": 0}]}, "schedule phase 0: 'max_steps' must be an integer >= 1, got 0"),
        ({"phases": [{"maze": "open", "trails": 2}]}, "schedule phase 0: unknown key(s) 'trails'; allowed: name, maze, trials"),
        ({"phases": [{"maze": "maze9"}]}, "schedule phase 0: maze 'maze9' is unknown"),
        ({"phases": [{"maze": {"base": "open", "change": "tunnel", "seed": 1}}]}, "'change' must be one of blocks, door, barrier"),
        ({"phases": [{"maze": {"base": "open", "change": "blocks"}}]}, "'seed' must be an integer >= 0, got None"),
        ({"phases": [{"maze": {"base": "open", "change": "blocks", "seed": 1, "size": 2}}]}, "a change has unknown key(s) 'size'"),
        ({"phases": [{"maze": 3}]}, "schedule phase 0: 'maze' must be a built-in maze"),
        ({"phases": [{"maze": "open", "name": ""}]}, "'name' must be a non-empty string"),
    ],
)
def test_schedule_errors_name_the_phase_the_field_and_what_is_allowed(schedule, message):
    with pytest.raises(ValueError) as err:
        Schedule.load(schedule)
    assert message in str(err.value)


def test_schedule_file_errors(tmp_path):
    with pytest.raises(ValueError, match="cannot be read"):
        Schedule.load(tmp_path / "none.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{phases: ")
    with pytest.raises(ValueError, match="is not valid JSON"):
        Schedule.load(bad)


def test_defaults_are_filled_in_and_the_dict_round_trips():
    schedule = Schedule.load(
        {"phases": [{"maze": "open"}, {"goal": "kept"}, {"maze": "maze1", "goal": [0.0, -3.0]}, {"maze": "maze1", "dry_run": True}]}
    )
    assert [p.maze for p in schedule.phases] == ["open", "open", "maze1", "maze1"]
    assert [p.dry_run for p in schedule.phases] == [True, False, True, True]  # first; same maze; new maze; asked for
    assert [p.name for p in schedule.phases] == ["phase 0", "phase 1", "phase 2", "phase 3"]
    assert schedule.phases[0].trials == 1 and schedule.phases[0].runs == 4 and schedule.phases[0].announce
    assert schedule.phases[2].goal == (0.0, -3.0)
    assert Schedule.load(schedule.to_dict()) == schedule
    assert json.loads(json.dumps(schedule.to_dict())) == schedule.to_dict()
    assert schedule.total_runs == 16 and schedule.total_trials == 4


def test_relative_maze_paths_are_found_beside_the_schedule_file(tmp_path):
    (tmp_path / "mazes").mkdir()
    (tmp_path / "mazes" / "small.json").write_text(json.dumps(SMALL))
    (tmp_path / "s.json").write_text(json.dumps({"phases": [{"maze": "mazes/small.json", "runs": 1}]}))
    planner = SchedulePlanner(Schedule.load(tmp_path / "s.json"), seed=0)
    assert planner.first_maze.name == "small"


def test_the_example_schedules_load():
    docs = Path(__file__).resolve().parent.parent / "docs" / "schedules"
    barriers = Schedule.load(docs / "barriers.json")
    assert [p.runs for p in barriers.phases] == [4, 10, 10, 10]
    assert [p.announce for p in barriers.phases] == [True, False, False, False]
    assert [p.maze["count"] for p in barriers.phases[1:]] == [8, 12, 16]
    assert all(p.goal == "kept" and p.max_steps == 300 and p.min_start_distance == 3.0 for p in barriers.phases[1:])
    worlds = Schedule.load(docs / "worlds.json")
    assert [p.maze for p in worlds.phases] == ["maze1", "maze3", "maze2", "maze1"]
    assert [p.dry_run for p in worlds.phases] == [True, True, True, False]
    assert worlds.phases[3].goal == {"phase": 0} and not worlds.phases[3].announce
    planner = SchedulePlanner(worlds, seed=0)  # plans the first repeat: the return finds maze1's goal free
    assert np.array_equal(planner.first[3].goal, planner.first[0].goal)


def test_a_kept_goal_the_new_layout_covers_is_a_clear_error():
    wall = {"name": "walled", "size": [4.0, 4.0], "obstacles": [[[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]]]}
    phases = [{"maze": SMALL, "goal": [1.0, 1.0], "runs": 1}, {"maze": wall, "goal": "kept", "runs": 1}]
    with pytest.raises(
        ValueError, match=r"schedule phase 1 \('phase 1'\): the goal kept from the previous phase \(1, 1\) lies inside a wall"
    ):
        _run(phases)
    with pytest.raises(ValueError, match="schedule phase 0 .* lies inside a wall of maze 'walled'"):
        _run([{"maze": wall, "goal": [1.0, 1.0]}])


def test_a_schedule_excludes_maze_trials_and_runs():
    with pytest.raises(ValueError, match="give either a schedule or maze, trials, not both"):
        run_dmtp(Recorder, "open", 2, schedule={"phases": [{"maze": "open"}]}, progress=False)


# ------------------------------------------------------------------ running
def test_a_kept_goal_across_a_changed_maze_runs_and_records_its_phases():
    phases = [
        {"name": "learn", "maze": SMALL, "runs": 2},
        {"name": "blocked", "maze": BLOCKS, "runs": 3, "goal": "kept", "announce": False, "dry_run": False},
        {"name": "moved", "runs": 2, "goal": "new"},
    ]
    result = _run(phases, agent=RandomAgent)
    record = result.to_dict()
    assert [e["phase"] for e in record["episodes"]] == [0, 0, 1, 1, 1, 2, 2]
    assert {e["repeat"] for e in record["episodes"]} == {0}
    assert [e["trial"] for e in record["episodes"]] == [0, 0, 1, 1, 1, 2, 2]
    goals = [tuple(e["goal"]) for e in record["episodes"]]
    assert len(set(goals[:5])) == 1 and goals[5] != goals[0]  # kept across the change, then moved
    assert [p["maze"] for p in record["phases"]] == ["small", "small+blocks2-3", "small+blocks2-3"]
    assert [p["name"] for p in record["phases"]] == ["learn", "blocked", "moved"]
    assert record["phases"][1]["goals"] == [list(goals[0])]
    assert record["schedule"]["phases"][2]["maze"] == BLOCKS  # the previous phase's, filled in
    assert record["dry_run_steps"] == [0, 0, 0] and record["trials"] == 3 and record["runs"] == 3
    blocked = result.phase_mazes[1]
    assert len(blocked.obstacles) == 2 and blocked.clearance(goals[0]) >= 0.6 - 1e-9
    assert record["env_steps_total"] == sum(e["steps"] for e in record["episodes"])
    summary = result.summary()
    assert [p["runs"] for p in summary["phases"]] == [2, 3, 2]
    assert "first_run_success_rate" in summary["phases"][1] and "first_run_success_rate" not in summary["phases"][2]


def test_start_trial_only_when_the_goal_moves_and_the_phase_announces_it():
    phases = [
        {"maze": SMALL, "trials": 2, "runs": 1},  # announced: told at each trial
        {"goal": "kept", "runs": 1},  # the goal did not move: nothing to tell
        {"goal": "new", "trials": 2, "runs": 1, "announce": False},  # moved, not told
        {"goal": {"phase": 0}, "runs": 1},  # moved back, told
    ]
    _run(phases)
    (agent,) = Recorder.built
    told = [c[1] for c in agent.calls if c[0] == "start_trial"]
    assert told == [0, 1, 5]  # the agent's own trials: 0-1 phase 0, 2 phase 1, 3-4 phase 2, 5 phase 3


def test_the_dry_run_is_offered_when_it_should_be():
    phases = [
        {"maze": SMALL, "runs": 1},  # the first phase: a dry run
        {"maze": SMALL, "runs": 1},  # the same maze: none
        {"maze": BLOCKS, "runs": 1},  # a changed maze: a dry run
        {"maze": BLOCKS, "runs": 1, "dry_run": True},  # asked for
        {"maze": SMALL, "runs": 1, "dry_run": False},  # refused
    ]
    result = _run(phases)
    (agent,) = Recorder.built
    kinds = [c[0] for c in agent.calls if c[0] != "start_trial"]
    assert kinds == ["dry_run", "reset", "reset", "dry_run", "reset", "dry_run", "reset", "reset"]
    assert result.dry_run_steps == [5, 0, 5, 5, 0]
    assert [p["dry_run_steps"] for p in result.phases] == [5, 0, 5, 5, 0]
    assert [p["dry_run"] for p in result.phases] == [True, False, True, True, False]
    assert result.env_steps_total == 15 + sum(r.steps for r in result.run_records)


def test_the_maze_changes_at_the_dry_run_or_the_first_run():
    """The dry run already happens in the phase's maze; without one, the first run does."""
    seen = []

    class Looker(Recorder):
        def dry_run(self, env):
            super().dry_run(env)
            seen.append(env.unwrapped.maze.name)

    _run([{"maze": SMALL, "runs": 1}, {"maze": BLOCKS, "runs": 1, "goal": "kept", "dry_run": True}], agent=Looker)
    assert seen == ["small", "small+blocks2-3"]


def test_runs_cut_at_max_steps_reach_the_agent_truncated_and_count_as_misses():
    phases = [{"maze": "open", "runs": 2, "max_steps": 7}, {"goal": "kept", "runs": 2, "max_steps": 90, "min_start_distance": 3.0}]
    result = _run(phases, agent=Stuck)  # the env's own limit: 60 steps (max_episode_steps)
    (agent,) = Recorder.built
    assert [r.steps for r in result.run_records] == [7, 7, 90, 90]  # a phase may run longer than the runner's limit
    assert not any(r.success for r in result.run_records)
    assert agent.truncated == [True] * 4
    assert all(np.isfinite(r.indirectness) for r in result.run_records)
    assert result.max_episode_steps == 60 and result.env_kwargs["max_episode_steps"] == 90
    assert result.summary()["phases"][1]["first_run_success_rate"] == 0.0


def test_a_phase_without_max_steps_is_cut_at_the_runners_limit():
    result = _run([{"maze": "open", "runs": 1, "min_start_distance": 3.0}, {"goal": "kept", "runs": 1, "max_steps": 80}], agent=Stuck)
    assert [r.steps for r in result.run_records] == [60, 80]


def test_the_same_seed_gives_the_same_episodes_and_another_seed_others():
    phases = [{"maze": SMALL, "runs": 2}, {"maze": BLOCKS, "goal": "kept", "runs": 2, "announce": False}]
    first, again, other = (_run(phases, seed=s, repeats=2).to_dict() for s in (4, 4, 5))
    assert first == again
    assert first["episodes"] != other["episodes"]


def test_repeats_are_independent_replicates_with_a_fresh_agent_each():
    result = _run([{"maze": SMALL, "runs": 2}, {"maze": BLOCKS, "goal": "kept", "runs": 1}], repeats=3)
    assert len(Recorder.built) == 3
    assert [r.repeat for r in result.run_records] == [0, 0, 0, 1, 1, 1, 2, 2, 2]
    assert [r.trial for r in result.run_records] == [0, 0, 1, 2, 2, 3, 4, 4, 5]
    goals = {tuple(r.goal) for r in result.run_records if r.phase == 0}
    assert len(goals) == 3  # each repeat its own goal
    assert [(p["repeat"], p["phase"]) for p in result.phases] == [(r, k) for r in range(3) for k in range(2)]
    # each repeat's changed maze keeps clear of that repeat's goal
    for p, maze in zip(result.phases, result.phase_mazes):
        assert maze.clearance(p["goals"][0]) >= 0.6 - 1e-9
    assert [b.calls[0] for b in Recorder.built] == [("dry_run",)] * 3
    summary = result.summary()
    assert summary["repeats"] == 3 and summary["phases"][1]["runs"] == 3


def test_a_one_phase_schedule_is_plain_dmtp():
    small = MazeSpec.from_dict(SMALL)
    plain = run_dmtp(RandomAgent, small, trials=1, runs=3, seed=7, progress=False, max_episode_steps=60)
    scheduled = _run([{"maze": small, "runs": 3}], agent=RandomAgent, seed=7)
    strip = [{k: v for k, v in e.items() if k not in ("phase", "repeat")} for e in scheduled.to_dict()["episodes"]]
    assert strip == plain.to_dict()["episodes"]
    assert "phase" not in plain.to_dict()["episodes"][0] and "schedule" not in plain.to_dict()


def test_an_exception_in_a_later_phase_keeps_the_finished_runs():
    class Breaks(Recorder):
        def start_trial(self, trial):
            if trial == 1:
                raise RuntimeError("no")

    with pytest.raises(DMTPFailed) as failed:
        _run([{"maze": SMALL, "runs": 2, "name": "first"}, {"goal": "new", "runs": 2, "name": "second"}], agent=Breaks)
    assert failed.value.doing == "starting second, trial 1"
    assert "2 of 4 runs finished" in str(failed.value)
    record = failed.value.result.to_dict()
    assert record["complete"] is False and [e["phase"] for e in record["episodes"]] == [0, 0]


def test_an_agent_may_not_swap_the_maze_in_its_dry_run():
    class Swapper(Recorder):
        def dry_run(self, env):
            env.reset(options={"maze": "maze1"})

    with pytest.raises(DMTPFailed, match="nor swap the maze") as failed:
        _run([{"maze": SMALL, "runs": 1}], agent=Swapper)
    assert failed.value.doing == "the dry run of phase 0, trial 1"


def test_phase_records_its_name_from_a_phase_object():
    schedule = Schedule((Phase(maze="open", runs=1, name="only"),))
    assert schedule.to_dict()["phases"][0]["name"] == "only"


# ------------------------------------------------------------------ the CLI
def _write_schedule(tmp_path, phases, repeats=1):
    path = tmp_path / "schedule.json"
    path.write_text(json.dumps({"phases": phases, "repeats": repeats}))
    return path


def test_cli_runs_a_schedule_and_writes_record_summary_and_figure(tmp_path, capsys):
    (tmp_path / "small.json").write_text(json.dumps(SMALL))
    change = {"base": "small.json", "change": "blocks", "seed": 3, "count": 2}
    schedule = _write_schedule(
        tmp_path,
        [
            {"name": "learn", "maze": "small.json", "runs": 2},
            {"name": "blocks", "maze": change, "goal": "kept", "runs": 2, "max_steps": 40},
        ],
    )
    out = tmp_path / "out"
    code = main(["dmtp", "--schedule", str(schedule), "--agent", "random", "--max-steps", "50", "--out", str(out), "--no-progress"])
    assert code == 0
    record = json.loads((out / "dmtp.json").read_text())
    assert [e["phase"] for e in record["episodes"]] == [0, 0, 1, 1]
    assert record["schedule"]["phases"][1]["maze"]["base"] == "small.json"
    assert [p["maze"] for p in record["phases"]] == ["small", "small+blocks2-3"]
    assert all(e["steps"] <= 40 for e in record["episodes"][2:])
    summary = json.loads((out / "summary.json").read_text())
    assert [p["name"] for p in summary["phases"]] == ["learn", "blocks"]
    assert {"runs", "success_rate", "median_indirectness_of_successes"} <= set(summary["phases"][0])
    assert "first_run_success_rate" in summary["phases"][1]
    assert (out / "indirectness_by_episode.png").stat().st_size > 1000
    assert (out / "paths_phase01.png").stat().st_size > 1000
    printed = capsys.readouterr().out
    assert "learn (small):" in printed and "blocks (small+blocks2-3):" in printed


@pytest.mark.parametrize("extra", [["--maze", "open"], ["--trials", "2"], ["--runs", "3", "--maze", "maze1"]])
def test_cli_schedule_refuses_maze_trials_runs(tmp_path, capsys, extra):
    schedule = _write_schedule(tmp_path, [{"maze": "open"}])
    code = main(["dmtp", "--schedule", str(schedule), *extra, "--out", str(tmp_path / "out"), "--no-progress"])
    assert code == 2
    err = capsys.readouterr().err
    assert "--schedule names each phase's maze, trials and runs: drop --" in err
    assert not (tmp_path / "out").exists()


def test_cli_bad_schedule_is_a_clear_error(tmp_path, capsys):
    schedule = _write_schedule(tmp_path, [{"maze": "open", "goal": "kept"}])
    assert main(["dmtp", "--schedule", str(schedule), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    assert "schedule phase 0: 'goal' is 'kept'" in capsys.readouterr().err


def test_cli_agent_config_reaches_the_factory_and_the_record(tmp_path):
    out = tmp_path / "out"
    args = ["dmtp", "--trials", "1", "--runs", "1", "--max-steps", "20", "--no-figures", "--no-progress", "--out", str(out)]
    code = main([*args, "--agent", "tests.test_schedule:Recorder", "--agent-config", "speed=2.5"])
    assert code == 0
    record = json.loads((out / "dmtp.json").read_text())
    assert record["agent_overrides"] == {"speed": 2.5} and record["agent_config"] == {"speed": 2.5}


def test_cli_agent_config_for_hippo_takes_dotted_names(tmp_path):
    out = tmp_path / "out"
    code = main(
        [
            "dmtp", "--trials", "1", "--runs", "1", "--max-steps", "30", "--no-figures", "--no-progress", "--out", str(out),
            "--agent", "hippo-paper", "--agent-config", "model.dry_run_steps=0", "--agent-config", "model.n_place=40",
        ]
    )  # fmt: skip
    assert code == 0
    record = json.loads((out / "dmtp.json").read_text())
    assert record["agent_overrides"] == {"model.dry_run_steps": 0, "model.n_place": 40}
    assert record["agent_config"]["model"]["n_place"] == 40 and record["dry_run_steps"] == [0]


def test_cli_agent_config_the_agent_does_not_take_is_a_clear_error(tmp_path, capsys):
    code = main(["dmtp", "--agent", "random", "--agent-config", "speed=2", "--out", str(tmp_path / "out"), "--no-progress"])
    assert code == 2
    assert "the random agent takes no parameters, got speed" in capsys.readouterr().err


@pytest.mark.parametrize("text", ["model..n=2", "novalue", "=3"])
def test_cli_agent_config_must_be_key_value(tmp_path, capsys, text):
    with pytest.raises(SystemExit) as exited:
        main(["dmtp", "--agent-config", text, "--out", str(tmp_path / "out"), "--no-progress"])
    assert exited.value.code == 2
    assert "must be KEY=VALUE with KEY a parameter name" in capsys.readouterr().err
