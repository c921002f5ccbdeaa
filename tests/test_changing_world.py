"""The changing-world tasks and measures (:mod:`hippomaze.changing_world`) and the bench's table of them."""

from __future__ import annotations

import math

import pytest

from hippo_env.schedule import Schedule
from hippomaze.bench.changing import table
from hippomaze.changing_world import (
    WORLDS_SCHEDULE,
    barriers_schedule,
    by_layout,
    layout_measures,
    maze_schedule,
    shortcut_measures,
    summarise,
    worlds_measures,
)


def run(phase: int, run: int, success: bool, indirectness: float, **more):
    return {"phase": phase, "run": run, "trial": phase, "success": success, "indirectness": indirectness, **more}


def test_the_schedules_are_valid_and_drawn_from_the_seed():
    for schedule in (barriers_schedule(11), maze_schedule("maze2", 11), maze_schedule("gen-perfect-131", 11), WORLDS_SCHEDULE):
        Schedule.load(schedule)
    assert barriers_schedule(11) == barriers_schedule(11) != barriers_schedule(12)
    names = [p["name"] for p in maze_schedule("maze2", 11)["phases"]]
    assert names[0] == "learn" and set(names[1:]) <= {"blocks", "barrier", "door"}


def test_layout_measures_count_the_changed_layouts_only():
    rows = [
        {
            "runs": [
                run(0, 0, False, math.inf),  # the learn phase: not counted
                run(1, 0, True, 0.2, steps=10, anchored=8, placed=8, off_map=0),
                run(1, 1, False, 3.0, steps=10, anchored=10, placed=5, off_map=1),
                run(2, 0, False, 2.0, steps=10, anchored=2, placed=1, off_map=0),
                run(2, 1, True, 0.4, steps=10, anchored=10, placed=10, off_map=0),
            ]
        }
    ]
    m = layout_measures(rows)
    assert m["layouts"] == 2 and m["runs"] == 4
    assert m["first_run_success"] == 0.5 and m["success"] == 0.5
    assert m["median_indirectness_of_successes"] == pytest.approx(0.3)
    assert m["anchored_share"] == 0.75 and m["position_within_0_5m"] == pytest.approx(24 / 30) and m["anchored_off_map_steps"] == 1


def test_a_shortcut_counts_runs_after_the_first_where_the_door_shortened_the_way():
    door = {"shortest_path_length": 5.0, "shortest_before_change": 10.0}
    rows = [
        {
            "phases": ["learn", "door"],
            "runs": [
                run(1, 0, True, 0.1, **door),  # the first run: not counted
                run(1, 1, True, 0.3, **door),  # taken
                run(1, 2, True, 0.9, **door),  # the old way
                run(1, 3, False, 0.1, **door),  # missed
                run(1, 4, True, 0.1, shortest_path_length=9.0, shortest_before_change=10.0),  # no shortcut for this start
            ],
        }
    ]
    assert shortcut_measures(rows) == {"runs": 3, "taken": pytest.approx(1 / 3)}


def test_worlds_measures_count_a_missed_return_as_infinitely_indirect():
    rows = [{"runs": [run(0, 1, True, 0.2), run(0, 2, True, 0.1), run(3, 0, True, 0.4), run(4, 1, True, 0.3)]}]
    rows.append({"runs": [run(3, 0, False, 1.0)]})
    m = worlds_measures(rows)
    assert m["returns"] == 2 and m["run1_back_median"] is None  # half missed: the median is infinite, written as None
    assert m["first_visit_runs_2_4_median"] == pytest.approx(0.15) and m["new_goal_back_runs_2_4_median"] == 0.3


def test_by_layout_measures_each_changed_layout_apart_by_name():
    placed = {"steps": 4, "anchored": 4, "off_map": 0}
    rows = [
        {
            "phases": ["learn", "8 blocks", "18 blocks"],
            "runs": [run(0, 0, True, 1.0), run(1, 0, True, 0.2, placed=4, **placed), run(2, 0, False, 2.0, placed=1, **placed)],
        },
        {
            "phases": ["learn", "8 blocks", "18 blocks"],
            "runs": [run(1, 0, False, 2.0, placed=2, **placed), run(2, 0, True, 0.5, placed=3, **placed)],
        },
    ]
    m = by_layout(rows)
    assert list(m) == ["8 blocks", "18 blocks"]
    assert m["8 blocks"]["layouts"] == 2 and m["8 blocks"]["success"] == 0.5 and m["8 blocks"]["position_within_0_5m"] == 0.75
    assert m["18 blocks"]["median_indirectness_of_successes"] == 0.5 and m["18 blocks"]["position_within_0_5m"] == 0.5


def test_summaries_per_agent_and_the_bench_table():
    row = {
        "agent": "a",
        "task": "barriers",
        "maze": "",
        "phases": ["learn", "8 blocks"],
        "runs": [run(1, 0, True, 0.2, steps=5, anchored=5, placed=5, off_map=0)],
    }
    summary = summarise([row])
    assert summary["a"]["barriers"]["success"] == 1.0 and "mazes" not in summary["a"]
    assert summary["a"]["barriers_by_layout"]["8 blocks"] == summary["a"]["barriers"]
    text = table(summary)
    assert text.splitlines()[0].startswith("| agent | blocks: first run") and "| a | 1.00 | 1.00 | 0.20 | 1.00 | - |" in text


def test_a_failed_dmtp_run_pickles_as_a_runtime_error_with_its_message():
    """A process pool sends the failure back to the parent (a DMTPFailed holds its result, which stays behind)."""
    import pickle

    from hippo_env.dmtp import DMTPFailed, run_dmtp

    def broken(observation_space, action_space, *, seed):
        raise ValueError("no agent today")

    with pytest.raises(DMTPFailed) as failed:
        run_dmtp(broken, maze="open", trials=1, runs=1, progress=False)
    again = pickle.loads(pickle.dumps(failed.value))
    assert type(again) is RuntimeError and "no agent today" in str(again)


def test_the_by_layout_figure_is_drawn_from_a_summary(tmp_path):
    from hippomaze.bench.changing import plot_by_layout

    measures = {"success": 1.0, "position_within_0_5m": 0.5, "median_indirectness_of_successes": 0.3}
    summary = {"a": {"barriers_by_layout": {"8 blocks": measures}, "mazes_by_change": {"door": measures}}, "b": {"worlds": {}}}
    path = tmp_path / "by_layout.png"
    assert plot_by_layout(summary, path) and path.stat().st_size > 0
    assert not plot_by_layout({"b": {"worlds": {}}}, tmp_path / "none.png") and not (tmp_path / "none.png").exists()


def test_the_privileged_forgetting_clears_the_map_before_the_runs_it_is_asked_to():
    from hippomaze.changing_world import Watched

    class Map:
        forgotten = 0

        def forget_new_walls(self):
            self.forgotten += 1

    class Agent:
        def __init__(self, with_map: bool):
            self.map = Map() if with_map else None

        def reset(self, observation, info):
            pass

    watched = Watched(Agent(with_map=True), forget_at=frozenset({1, 3}))
    counts = []
    for _ in range(4):
        watched.reset(None, {})
        counts.append(watched.agent.map.forgotten)
    assert counts == [0, 1, 1, 2]
    Watched(Agent(with_map=False), forget_at=frozenset({0})).reset(None, {})  # an agent with no map: nothing to forget


def test_environment_arguments_reach_every_schedule_run_and_cannot_make_the_reference(monkeypatch):
    """``--env`` (e.g. continuous headings) goes to ``run_dmtp`` for each job; the bench's reference
    is made on the default environment only."""
    from types import SimpleNamespace

    import hippomaze.changing_world as cw
    from benchmarks import changing_world as bench

    seen = []

    def fake_run_dmtp(make, **kwargs):
        seen.append(kwargs["env_kwargs"])
        return SimpleNamespace(run_records=[], schedule={"phases": []})

    monkeypatch.setattr(cw, "run_dmtp", fake_run_dmtp)
    row = cw.run_task("random", 1, "barriers", env_kwargs={"action_type": "heading"})
    assert seen == [{"action_type": "heading"}] and row["runs"] == []
    with pytest.raises(SystemExit, match="--env"):
        bench.main(["--agents", "random", "--env", '{"action_type": "heading"}', "--write-reference"])
