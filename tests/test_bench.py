"""``hippomaze bench``: a tiny run of a third-party agent beside the shipped references (JSON, figure,
table), the shipped references themselves, the statistics against rliable's own, and clear
errors for bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from hippomaze import stats
from hippomaze.bench import references, report
from hippomaze.bench.summary import ALL
from hippomaze.cli import main

pytest.importorskip("rliable", reason="the bench needs the 'bench' extra: pip install -e .[bench]")


class WanderingAgent:
    """A third-party agent as a user writes one: heads one way, turns at random now and then."""

    def __init__(self, observation_space, action_space, seed=None):
        self.rng = np.random.default_rng(seed)
        self.n = action_space.n
        self.action = 0

    def reset(self, observation, info):
        pass

    def act(self, observation):
        if self.rng.random() < 0.2:
            self.action = int(self.rng.integers(self.n))
        return self.action

    def observe(self, action, observation, reward, terminated, truncated, info):
        pass


TINY = ["--agent", "tests.test_bench:WanderingAgent", "--maze", "open", "--maze", "maze1", "--seeds", "3", "--budget", "3000",
        "--switch-budget", "500", "--reference", "hippo", "--reference", "random", "--engine", "serial", "--no-progress"]  # fmt: skip


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "b"
    assert main(["bench", *TINY, "--out", str(out)]) == 0
    return out, json.loads((out / "bench.json").read_text())


def test_a_tiny_run_writes_json_figure_and_table(tiny):
    out, document = tiny
    assert (out / "bench.png").stat().st_size > 20_000
    table = (out / "bench.md").read_text()
    assert "| tests.test_bench:WanderingAgent |" in table and "| hippo |" in table and "| random |" in table
    assert document["protocol"] == "learner" and document["settings"]["budget"] == 3000
    assert document["jobs_run"] == 6 and document["versions"]["python"]
    shown = document["statistics"]["variants"]
    assert list(shown) == ["tests.test_bench:WanderingAgent", "hippo", "random"]
    for name in ("hippo", "random"):  # every reference: its IQM and interval, per maze and over both
        assert set(shown[name]["steps_to_direct"]) == {"open", "maze1", ALL}, name
        assert len(shown[name]["steps_to_direct"][ALL]) == 3
        assert document["references"][name]["made"]["command"].startswith("python -m benchmarks.sample_efficiency")
    low, high = shown["hippo"]["steps_to_direct"][ALL][1:]
    assert 0 < low <= shown["hippo"]["steps_to_direct"][ALL][0] <= high < 10_000  # the hippo is direct within thousands
    # the agent never got there within 3,000 steps: its IQM is "> budget", and the hippocampal agent is faster
    assert shown["tests.test_bench:WanderingAgent"]["steps_to_direct"][ALL][0] is None
    assert "> 3,000" in table
    assert shown["hippo"]["focus_faster"][0] < 0.5 and shown["random"]["focus_faster"][0] == pytest.approx(0.5)
    agent = document["agent"]
    assert agent["mazes"]["open"]["seeds"] == [0, 1, 2]
    assert all(t <= 3000 for t in agent["mazes"]["open"]["env_steps_total"])
    assert set(agent["curves"]) == {"open", "maze1", ALL}


def test_the_out_folder_is_not_overwritten_but_can_be_resumed(tiny, capsys):
    out, document = tiny
    assert main(["bench", *TINY, "--out", str(out)]) == 2
    assert "is not empty" in capsys.readouterr().err
    assert main(["bench", *TINY, "--out", str(out), "--resume"]) == 0
    again = json.loads((out / "bench.json").read_text())
    assert again["jobs_run"] == 0 and again["jobs_reused"] == 6
    assert again["statistics"] == document["statistics"]


def test_shipped_references_say_how_they_were_made():
    shipped = references.load_references()
    assert set(shipped) == set(references.REFERENCE_VARIANTS)
    for name, ref in shipped.items():
        assert set(ref.result.mazes) == {"open", "maze1"}, name
        assert all(len(m.seeds) == 5 for m in ref.result.mazes.values()), name
        assert ref.made["records"], name
        for origin in ref.made["records"]:
            assert origin["jobs"] and origin["versions"] and origin["command"].startswith("python -m benchmarks.sample_efficiency"), name
    assert shipped["ppo"].result.protocol["budget"] == 300_000
    assert shipped["hippo"].result.protocol["kind"] == "one-shot"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--agent", "no_such_module:Agent"], "cannot import module 'no_such_module'"),
        (["--agent", "tests.test_bench:NoSuchAgent"], "has no attribute 'NoSuchAgent'"),
        (["--agent", "greedy"], "agent 'greedy' is unknown"),
        (["--agent", "random", "--maze", "maze9"], "maze 'maze9' is unknown"),
        (["--agent", "random", "--reference", "sac"], "no shipped reference 'sac'"),
        (["--agent", "random", "--seeds", "0"], "--seeds: must be a positive integer"),
    ],
)
def test_bad_input_is_a_clear_error(tmp_path, capsys, args, message):
    code = None
    try:
        code = main(["bench", *args, "--out", str(tmp_path / "b")])
    except SystemExit as exit_:  # argparse's own errors
        code = exit_.code
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "b").exists()  # refused before any work


def test_every_option_has_help(capsys):
    with pytest.raises(SystemExit):
        main(["bench", "--help"])
    text = capsys.readouterr().out
    for option in ("--agent", "--maze", "--seeds", "--protocol", "--budget", "--switch-budget", "--trials", "--runs", "--quick",
                   "--label", "--reference", "--out", "--resume", "--engine", "--workers", "--no-progress"):  # fmt: skip
        assert option in text
    import argparse

    from hippomaze.bench.cli import add_parser

    parser = add_parser(argparse.ArgumentParser().add_subparsers())
    assert all(action.help for action in parser._actions), [a.dest for a in parser._actions if not a.help]


# -------------------------------------------------------------------------------------------- statistics
def test_iqm_and_interval_are_rliables():
    from rliable import metrics

    scores = np.array([[1000.0, 1500.0], [2000.0, 2500.0], [3000.0, 2000.0], [4000.0, 1800.0], [90_000.0, 2200.0]])
    interval = stats.iqm_interval(scores)
    assert interval.point == pytest.approx(metrics.aggregate_iqm(scores))
    assert interval.low <= interval.point <= interval.high
    assert stats.iqm_interval(scores) == interval  # seeded: the same on every call
    state = np.random.get_state()[1].copy()
    stats.iqm_interval(scores, seed=5)
    assert np.array_equal(np.random.get_state()[1], state)  # NumPy's global generator left as it was


def test_iqm_at_each_x_is_rliables_iqm_at_each_x():
    from rliable import metrics

    points = np.random.default_rng(0).random((5, 2, 7))
    assert np.allclose(stats.iqm_at_each_x(points), [metrics.aggregate_iqm(points[..., j]) for j in range(7)])


def test_never_direct_is_slower_than_any_and_shown_as_beyond_the_budget():
    some = stats.steps_matrix([[1000.0, None, 2000.0, 3000.0, 4000.0]])
    assert stats.iqm_interval(some).point == pytest.approx(3000.0)  # one never of five is trimmed away
    most = stats.steps_matrix([[1000.0, None, None, None, 4000.0]])
    interval = stats.iqm_interval(most)
    assert interval.point is None and interval.high is None
    assert report.steps_cell(interval, report.Reached(2, 5), 300_000).startswith("> 300,000")
    fast, slow = stats.steps_matrix([[100.0, 200.0, 300.0]]), stats.steps_matrix([[None, None, 250.0]])
    assert stats.probability_of_improvement(fast, slow).point == pytest.approx(8 / 9, abs=1e-4)  # all but 300 against 250
    share, low, high = stats.performance_profile(stats.steps_matrix([[100.0, 1000.0, None, 5000.0]]), np.array([50, 500, 2000, 10_000]))
    assert share == [0.0, 0.25, 0.5, 0.75]
    assert all(lo <= s <= hi for s, lo, hi in zip(share, low, high))


def test_the_performance_profile_is_rliables():
    from rliable import library

    scores = stats.steps_matrix([[100.0, 1000.0, None, 5000.0], [300.0, 200.0, 7000.0, None]])
    taus = np.geomspace(50, 10_000, 20)
    share, low, high = stats.performance_profile(scores, taus)
    state = np.random.get_state()  # rliable's own bootstrap draws from NumPy's global generator
    np.random.seed(0)
    try:
        profile, interval = library.create_performance_profile({"x": -scores}, -taus, reps=stats.REPS)
    finally:
        np.random.set_state(state)
    assert np.allclose(share, profile["x"]) and np.allclose(low, interval["x"][0]) and np.allclose(high, interval["x"][1])


def test_mazes_with_different_seed_counts_have_no_stratified_matrix():
    assert stats.steps_matrix([[1.0, 2.0], [3.0]]) is None
    assert math.isclose(stats.steps_matrix([[1.0, 2.0], [3.0, None]])[1, 1], stats.NEVER)


def test_the_stratified_bootstrap_draws_rliables_resamples_without_its_global_generator():
    """The intervals equal rliable's (its bootstrap drawing from NumPy's global generator, seeded),
    for one sample and for two independent ones, and NumPy's global generator is left alone."""
    from rliable import library, metrics

    rng = np.random.default_rng(3)
    scores, other = rng.integers(100, 5000, (5, 2)).astype(float), rng.integers(100, 5000, (4, 2)).astype(float)
    before = np.random.get_state()[1].copy()
    mine = stats.iqm_interval(scores, seed=7)
    faster = stats.probability_of_improvement(scores, other, seed=7)
    assert np.array_equal(np.random.get_state()[1], before)
    state = np.random.get_state()
    try:
        np.random.seed(7)
        _, one = library.get_interval_estimates({"x": scores}, lambda s: np.array([metrics.aggregate_iqm(s)]), reps=stats.REPS)
        np.random.seed(7)
        _, two = library.get_interval_estimates(
            {"xy": [-scores, -other]}, lambda a, b: np.array([metrics.probability_of_improvement(a, b)]), reps=stats.REPS
        )
    finally:
        np.random.set_state(state)
    assert [mine.low, mine.high] == pytest.approx(list(one["x"][:, 0]), abs=1e-4)
    assert [faster.low, faster.high] == pytest.approx(list(two["xy"][:, 0]), abs=1e-4)
