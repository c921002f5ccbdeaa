"""The sample-efficiency benchmark (``python -m benchmarks.sample_efficiency``, on :mod:`hippomaze.bench`):
tiny-budget smoke runs (records complete and well-formed for every agent, the dry run counted,
resumable), the local pool and Ray giving the same records, and the measures (pooling, steps to
criterion, the goal switch)."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hippomaze.baselines import RandomAgent

from benchmarks.sample_efficiency import cli
from hippomaze import runinfo
from hippomaze.bench import jobs, metrics, report

# only the runs of DQN and PPO need stable-baselines3: the analysis tests run without it
needs_sb3 = pytest.mark.skipif(
    importlib.util.find_spec("stable_baselines3") is None or importlib.util.find_spec("rliable") is None,
    reason="the DQN/PPO baselines need the 'baselines' extra, the summary the 'bench' extra",
)

HIPPO = importlib.util.find_spec("hippo_agent") is not None
AGENTS = ["random", "dqn", "ppo", "dynaq"] + (["hippo", "hippo-paper"] if HIPPO else [])
BUDGET, SWITCH = 1200, 500
QUICK = ["--quick", "--seeds", "1", "--mazes", "open", "--dense-agents", "dqn", "--dense-seeds", "1",
         "--budget", str(BUDGET), "--dynaq-budget", str(BUDGET), "--switch-budget", str(SWITCH),
         "--hippo-days", "2", "--hippo-runs", "3", "--no-progress"]  # fmt: skip
EPISODE_KEYS = {"trial", "run", "steps", "success", "path_length", "shortest_path_length", "indirectness", "start", "goal"}


def _strip(record: dict) -> dict:
    """A record without what differs between two runs of the same job: its time and date."""
    return {k: v for k, v in record.items() if k not in ("seconds", "made")}


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("se")
    summary = cli.main([*QUICK, "--agents", *AGENTS, "--out", str(out)])
    return out, summary


def _records(out: Path) -> dict[str, dict]:
    """Every job record under ``out``, as the JSON objects stored (None for one that cannot be read)."""
    loaded = {p.name.removesuffix(".json.gz"): jobs.load_record(p) for p in sorted((out / "sample_efficiency").glob("*.json.gz"))}
    return {name: None if record is None else record.to_dict() for name, record in loaded.items()}


@needs_sb3
class TestQuickRun:
    def test_every_job_has_a_well_formed_record(self, quick):
        out, _ = quick
        records = _records(out)
        expected = {f"{a}__open__sparse__seed0" for a in AGENTS} | {"dqn__open__dense__seed0"}
        assert set(records) == expected
        for name, record in records.items():
            assert record is not None, name
            assert {"job", "name", "privileged", "learn", "agent_config", "seconds"} <= set(record)
            assert record["privileged"] == (record["job"]["agent"] == "dynaq")
            assert record["made"]["versions"]["numpy"]
            # a goal-switch trial only for an agent that became direct on its first goal
            assert ("switch" in record) == (record["learn"]["direct_at"] is not None)
            for phase in [p for p in ("learn", "switch") if p in record]:
                p = record[phase]
                assert {"maze", "agent", "seed", "trials", "runs", "env_steps_total", "episodes", "prepare_steps", "cut_steps"} <= set(p)
                columns = p["episodes"]
                assert set(columns) == EPISODE_KEYS
                n = len(columns["steps"])
                assert n > 0 and all(len(v) == n for v in columns.values()), name
                assert all(isinstance(s, int) and s > 0 for s in columns["steps"])
                assert all(isinstance(b, bool) for b in columns["success"])
                assert all(v is None or (isinstance(v, float) and math.isfinite(v)) for v in columns["indirectness"])
                assert all(len(xy) == 2 for xy in columns["start"] + columns["goal"])
                # every step is accounted for: dry run + recorded runs + a run cut by the budget
                assert p["cut_steps"] >= 0
                assert p["env_steps_total"] == sum(p["prepare_steps"]) + sum(columns["steps"]) + p["cut_steps"]
            job = record["job"]
            if job["agent"] not in ("hippo", "hippo-paper"):
                assert record["learn"]["env_steps_total"] == job["budget"] == BUDGET

    @pytest.mark.skipif(not HIPPO, reason="hippo_agent is not importable")
    def test_hippo_dry_run_is_counted(self, quick):
        out, _ = quick
        record = _records(out)["hippo__open__sparse__seed0"]
        dry = cli.QUICK_OVERRIDES["hippo"]["model.dry_run_steps"]
        learn = record["learn"]
        assert learn["prepare_steps"] == [dry, dry]  # a fresh agent, and its dry run, per trial
        assert learn["env_steps_total"] >= 2 * dry + sum(learn["episodes"]["steps"])
        reps = metrics.replicates(learn)
        assert [r.start[0] for r in reps] == [dry, dry]  # each trial's first run starts after its dry run

    def test_summary_and_figure(self, quick):
        out, _ = quick
        data = json.loads((out / "sample_efficiency_quick.json").read_text())
        assert {"command", "jobs_run", "table_markdown", "statistics", "results"} <= set(data)
        assert set(data["results"]) == set(AGENTS) | {"dqn-dense"}
        assert data["statistics"]["focus"] == ("hippo" if HIPPO else "dqn")
        for name, s in data["statistics"]["variants"].items():
            assert "open" in s["steps_to_direct"] and "open" in s["after_switch"], name
        assert "(privileged)" in data["table_markdown"]
        assert (out / "sample_efficiency_quick.png").stat().st_size > 10_000

    def test_resume_skips_finished_jobs(self, quick):
        out, _ = quick
        files = sorted((out / "sample_efficiency").glob("*.json.gz"))
        before = {p: p.stat().st_mtime_ns for p in files}
        cli.main([*QUICK, "--agents", *AGENTS, "--out", str(out), "--no-aggregate"])
        assert {p: p.stat().st_mtime_ns for p in files} == before

    def test_a_record_made_with_other_defaults_is_rerun(self, quick):
        out, _ = quick
        path = out / "sample_efficiency" / "dqn__open__sparse__seed0.json.gz"
        original = jobs.load_record(path)
        stale = dataclasses.replace(original, agent_config={**original.agent_config, "gamma": 0.5})  # as if a default had changed since
        jobs.save_record(path, stale)
        cli.main([*QUICK, "--agents", *AGENTS, "--out", str(out), "--no-aggregate"])
        assert _strip(jobs.load_record(path).to_dict()) == _strip(original.to_dict())


class DryRunningAgent(RandomAgent):
    """A random agent with a 123-step dry run."""

    def dry_run(self, env):
        env.reset()
        for _ in range(123):
            env.step(env.action_space.sample())


class GoalSeeker(RandomAgent):
    """A privileged test agent that heads straight for the goal: direct from its first run."""

    def reset(self, observation, info):
        self.info = info

    def act(self, observation):
        (x, y), (gx, gy) = self.info["position"], self.info["goal"]
        return round(math.atan2(gy - y, gx - x) / (math.pi / 4)) % 8

    def observe(self, action, observation, reward, terminated, truncated, info):
        self.info = info


def test_goal_switch_trial():
    job = jobs.Job(
        "test_sample_efficiency:GoalSeeker", "open", 0, budget=1500, switch_budget=600, trials=1, runs=400, max_episode_steps=300
    )
    record = jobs.run_job(job)
    assert record.learn["direct_at"] == 0
    switch = record.switch
    assert switch["env_steps_total"] == 600 and switch["prepare_steps"] == [0]
    assert math.dist(switch["episodes"]["goal"][0], switch["old_goal"]) >= 2.0  # the goal moved
    assert switch["old_goal"] == record.learn["episodes"]["goal"][-1]
    assert metrics.switch_cost(switch, window=10) == (0, 0)


def test_the_dry_run_counts_for_any_agent():
    job = jobs.Job("test_sample_efficiency:DryRunningAgent", "open", 0, budget=0, switch_budget=0, trials=2, runs=2, max_episode_steps=100)
    assert job.spec()["days"] == 2  # the key the committed records have
    record = jobs.run_job(job)
    learn = record.learn
    assert learn["prepare_steps"] == [123, 123]
    assert learn["env_steps_total"] == 246 + sum(learn["episodes"]["steps"])


@needs_sb3
def test_a_record_made_by_other_code_is_not_reused():
    """The job cache keys on the code as well as the config: a record whose code fingerprint is not
    today's (or that has none) is run again, even when its job and config are the same."""
    job = jobs.make_job("random", "open", 0, protocol="learner", budget=100, switch_budget=0, trials=1, runs=1)
    made = {"date": "2026-01-01T00:00:00", "versions": jobs.versions(), "code": runinfo.code_fingerprint()}
    record = jobs.JobRecord(job.spec(), job.name, False, {}, agent_config=jobs.current_config(job), made=made)
    assert jobs.reusable(record, job)
    assert not jobs.reusable(dataclasses.replace(record, made={**made, "code": "0" * 16}), job)
    assert not jobs.reusable(dataclasses.replace(record, made=None), job)  # made before the fingerprint was kept


def test_the_code_fingerprint_follows_the_source(tmp_path, monkeypatch):
    """:func:`hippomaze.runinfo.source_digest` changes with a file's content, and only then."""
    package = tmp_path / "fingerprinted"
    package.mkdir()
    (package / "__init__.py").write_text("X = 1\n")
    (package / "maze.json").write_text("{}")
    monkeypatch.syspath_prepend(str(tmp_path))
    first, code_only = runinfo.source_digest(("fingerprinted",), (".py", ".json")), runinfo.source_digest(("fingerprinted",))
    assert runinfo.source_digest(("fingerprinted",), (".py", ".json")) == first
    (package / "maze.json").write_text('{"size": [10, 10]}')
    assert runinfo.source_digest(("fingerprinted",), (".py", ".json")) != first
    assert runinfo.source_digest(("fingerprinted",)) == code_only  # the .py files alone are unchanged


def test_ray_and_local_pool_give_the_same_records(quick, tmp_path):
    ray = pytest.importorskip("ray", reason="Ray is an optional extra: pip install -e .[ray]")
    out, _ = quick
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        cli.main(
            [
                *QUICK,
                "--agents",
                "dqn",
                "ppo",
                "--mazes",
                "open",
                "--dense-seeds",
                "0",
                "--engine",
                "ray",
                "--out",
                str(tmp_path),
                "--no-aggregate",
            ]
        )
    finally:
        ray.shutdown()
    local, remote = _records(out), _records(tmp_path)
    assert set(remote) == {"dqn__open__sparse__seed0", "ppo__open__sparse__seed0"}
    for name, record in remote.items():
        assert _strip(record) == _strip(local[name]), name


# -------------------------------------------------------------------------------------------- analysis
def _rep(steps, success, indirectness, offset=0):
    steps = np.asarray(steps, float)
    end = offset + np.cumsum(steps)
    return metrics.Replicate(end - steps, end, np.asarray(success, bool), np.asarray(indirectness, float))


class TestAnalysis:
    def test_steps_to_criterion_of_a_learner(self):
        # 3 long failures, then short direct runs. The window of 10 that starts with the last failure
        # already has 9/10 successes and a median of 0.2, but the run in progress is a failure:
        # direct from the first direct run on.
        rep = _rep([1000, 1000, 1000] + [40] * 20, [False] * 3 + [True] * 20, [50.0] * 3 + [0.2] * 20)
        assert not metrics.direct_at(rep, 2000, window=10)
        assert metrics.direct_at(rep, 3000, window=10)
        assert metrics.steps_to_criterion([rep], window=10) == 3000

    def test_the_curve_looks_no_further_than_the_run_in_progress(self):
        # the same learner: at 3000 steps its 4th run is under way (too few runs for a point); during
        # its 10th run, its latest 10 are the 3 failures and 7 direct successes
        rep = _rep([1000, 1000, 1000] + [40] * 20, [False] * 3 + [True] * 20, [50.0] * 3 + [0.2] * 20)
        assert all(math.isnan(v) for v in metrics.metrics_at([rep], 3000, window=10))
        assert metrics.metrics_at([rep], 3000 + 6 * 40 + 1, window=10) == (0.7, 0.2)

    def test_the_run_in_progress_counts(self):
        # hippo-like trials: a dry run, one exploring run, then direct runs. A trial is not direct before its
        # run 2 starts (trial t: at 2500 + 100 t); the seed's figure is the median over its 10 trials.
        trials = [_rep([2000 + 100 * t] + [40] * 40, [True] * 41, [20.0] + [0.1] * 40, offset=500) for t in range(10)]
        assert [metrics.replicate_steps_to_criterion(t, window=10) for t in trials] == [2500.0 + 100 * t for t in range(10)]
        assert metrics.steps_to_criterion(trials, window=10) == 2950.0
        same = [trials[0]] * 10  # run 1 ends at 2500, then a run every 40 steps
        ok, ind, running = metrics.recent_at(same, 1000, window=10)  # the dry run or run 1 under way
        assert running == 10 and ok.size == 10 and np.all(ind == 20.0)
        ok, ind, _ = metrics.recent_at(same, 2500 + 4 * 40, window=10)
        assert ok.size == 60 and np.sum(ind == 20.0) == 10  # run 1, 4 more done, the 6th in progress
        ok, ind, _ = metrics.recent_at(same, 2500 + 20 * 40, window=10)
        assert ok.size == 100 and np.all(ind == 0.1)  # run 1 has left every trial's window of 10

    def test_seeds_whose_trials_are_mostly_never_direct_never_are(self):
        direct_trial = _rep([1000] + [40] * 20, [True] * 21, [20.0] + [0.1] * 20)
        wandering_trial = _rep([1000] * 21, [True] * 21, [20.0] * 21)
        assert metrics.steps_to_criterion([direct_trial] * 2 + [wandering_trial] * 3, window=10) is None
        assert metrics.steps_to_criterion([direct_trial] * 3 + [wandering_trial] * 2, window=10) == 1000.0

    def test_no_measurement_once_most_replicates_have_ended(self):
        # 4 fast trials end at 1000 steps, 1 slow trial runs on: past 1000 only the slow trial is left
        trials = [_rep([500, 500], [True, True], [0.5, 0.5]) for _ in range(4)] + [_rep([500] + [2000] * 5, [True] * 6, [0.5] + [30.0] * 5)]
        assert metrics.metrics_at(trials, 600, window=1) == (1.0, 0.5)
        assert all(math.isnan(v) for v in metrics.metrics_at(trials, 1500, window=1))

    def test_never_direct(self):
        rep = _rep([100] * 30, [True] * 30, [3.0] * 30)
        assert metrics.steps_to_criterion([rep], window=10) is None
        assert report.fmt_steps(None, 300_000) == "> 300,000"
        assert report.fmt_steps(None, None) == "never"

    def test_switch_cost(self):
        # an exploring first run, then direct ones: one run (and its steps) to be direct again
        phase = {"trials": 1, "prepare_steps": [0], "episodes": {"trial": [0] * 12, "steps": [900] + [40] * 11,
                 "success": [True] * 12, "indirectness": [25.0] + [0.3] * 11}}  # fmt: skip
        assert metrics.switch_cost(phase, window=10) == (1, 900)


def test_bad_engine_is_refused():
    with pytest.raises(SystemExit):
        cli.parse_args(["--engine", "dask"])


def test_every_option_has_its_field_docstring_as_help(capsys):
    with pytest.raises(SystemExit):
        cli.parse_args(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    for f in dataclasses.fields(cli.Args):
        assert f"--{f.name.replace('_', '-')}" in text
    assert "also write the references hippomaze bench ships" in text and "(default: 300000)" in text
