"""Nothing done through the environment's API kills the interpreter (issue 20).

pymunk frees its C objects when Python's garbage collector gets to its Python objects, which sit
in reference cycles; an object that owns a C object's lifetime wrongly shows up as a segmentation
fault or a Chipmunk assertion (abort), and only for some timings of the collector. So every case
runs in its own Python process (a crash fails the test instead of killing pytest), and each
process runs under one of two collector schedules (:data:`GC_MODES`): every maze kind (built-in,
generated, a JSON file) x every action type x ``gym.make``, ``gym.make_vec`` sync and async x
resets with and without start/goal options, repeated, plus copies (``copy.deepcopy``,
``pickle``) of a stepped environment. One process runs all the cases of one maze and prints a
marker after each, so a failure names the last case that finished.

A collection at nearly every allocation (``gc.set_threshold(1, 1, 1)``) frees garbage as soon as
it appears, so it misses a collection that lands inside pymunk's own freeing of a space (where
the physics of the first releases crashed). The second schedule therefore collects at every
n-th function event inside pymunk's code, destructors and iterator callbacks included: it finds
that crash in every maze.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

import hippo_env

ACTION_TYPES = ("discrete", "heading", "wheels")
MODES = ("make", "sync", "async")
CASES = len(ACTION_TYPES) * (len(MODES) + 2)  # + deepcopy and pickle, per maze
DONE = "CASE-DONE"
GC_MODES = ("threshold-1", "in-pymunk:29")
"""``threshold-1``: ``gc.set_threshold(1, 1, 1)``; ``in-pymunk:N``: a full collection at every N-th
function event (call, return, C call) inside pymunk's code (both after the imports and a warm-up, with the warm-up's
objects frozen for the second so that a collection stays cheap)."""

# The cases of one maze, run in a fresh process. argv: maze kind ("builtin", "generated", "json"),
# the maze (name, seed, path), steps between resets, resets, GC_MODES key.
WORKER = textwrap.dedent(
    """
    import copy, gc, pickle, sys

    import gymnasium as gym
    import numpy as np

    import hippo_env
    from hippo_env.generate import generate_maze
    from hippo_env.maze import MazeSpec

    kind, arg, steps, resets, gc_mode = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
    maze = generate_maze(int(arg), kind="corridors") if kind == "generated" else arg
    spec = maze if isinstance(maze, MazeSpec) else MazeSpec.load(maze)
    rng = np.random.default_rng(0)
    for action_type in ("discrete", "heading", "wheels"):  # numba's compiled code loaded, before the collector is set
        warm = gym.make("HippoMaze-v0", maze=maze, action_type=action_type, n_rays=16)
        warm.reset(seed=0)
        warm.step(warm.action_space.sample())
        warm.close()
    del warm
    gc.collect()
    if gc_mode == "threshold-1":  # a collection at nearly every allocation
        gc.set_threshold(1, 1, 1)
    else:  # "in-pymunk:STRIDE": a full collection at every STRIDE-th function event inside pymunk's own code
        stride, events = int(gc_mode.split(":")[1]), [0]
        gc.freeze()  # the imports' objects are not scanned again: a full collection takes little time

        def collect_inside_pymunk(frame, event, arg):
            if "/pymunk/" in frame.f_code.co_filename:
                events[0] += 1
                if events[0] % stride == 0:
                    gc.collect()

        sys.setprofile(collect_inside_pymunk)


    def options(k):
        \"\"\"Resets in turn: plain, a goal, a start and a goal, a start, heading and goal (a start
        alone could fall in the goal disk of a sub-env).\"\"\"
        goal = spec.sample_free(rng, 0.5)
        start = [float(v) for v in spec.sample_free(rng, 0.4, away_from=goal, min_distance=1.0)]
        goal = [float(v) for v in goal]
        heading = float(rng.uniform(-3, 3))
        return [None, {"goal": goal}, {"start": start, "goal": goal}, {"start": start, "heading": heading, "goal": goal}][k % 4]


    def drive(env, n):
        for _ in range(n):
            env.step(env.action_space.sample())


    for action_type in ("discrete", "heading", "wheels"):
        for mode in ("make", "sync", "async"):
            kwargs = dict(maze=maze, action_type=action_type, n_rays=16, max_episode_steps=25)
            if mode == "make":
                env = gym.make("HippoMaze-v0", **kwargs)
            else:
                env = gym.make_vec("HippoMaze-v0", num_envs=2, vectorization_mode=mode, **kwargs)
            env.reset(seed=0)
            env.action_space.seed(0)
            for k in range(resets):
                drive(env, steps)  # past max_episode_steps: the vector envs reset sub-envs themselves
                env.reset(options=options(k))
            env.reset(seed=1)
            drive(env, steps)
            env.close()
            del env
            gc.collect()
            print("CASE-DONE", kind, arg, action_type, mode, flush=True)

        env = gym.make("HippoMaze-v0", maze=maze, action_type=action_type, n_rays=16)
        env.reset(seed=2, options=options(3))
        env.action_space.seed(2)
        drive(env, steps)
        for how, copier in (("deepcopy", copy.deepcopy), ("pickle", lambda e: pickle.loads(pickle.dumps(e)))):
            twin = copier(env)
            drive(twin, steps)
            twin.reset(options=options(2))
            drive(twin, steps)
            del twin
            gc.collect()
            drive(env, steps)
            print("CASE-DONE", kind, arg, action_type, how, flush=True)
        del env
        gc.collect()
    """
)


def run_worker(*args: str, timeout: float = 600.0, env: dict[str, str] | None = None) -> int:
    """Runs :data:`WORKER` in a fresh interpreter; fails (showing its stderr) unless it exits
    cleanly. Returns the number of cases it finished."""
    done = subprocess.run([sys.executable, "-c", WORKER, *args], capture_output=True, text=True, timeout=timeout, check=False, env=env)
    cases = [line for line in done.stdout.splitlines() if line.startswith(DONE)]
    assert done.returncode == 0, (
        f"the process running {args} ended with exit code {done.returncode} (negative: killed by that signal) "
        f"after {len(cases)} cases; last finished: {cases[-1] if cases else 'none'}\nstderr:\n{done.stderr[-4000:]}"
    )
    return len(cases)


@pytest.fixture
def json_maze(tmp_path):
    path = tmp_path / "bar.json"
    path.write_text(json.dumps({"name": "bar", "size": [6.0, 5.0], "obstacles": [[[-1.5, -0.2], [1.5, -0.2], [1.5, 0.2], [-1.5, 0.2]]]}))
    return str(path)


@pytest.mark.parametrize("gc_mode", GC_MODES)
@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
def test_builtin_maze(maze, gc_mode):
    assert run_worker("builtin", maze, "30", "3", gc_mode) == CASES


@pytest.mark.parametrize("gc_mode", GC_MODES)
def test_generated_maze(gc_mode):
    assert run_worker("generated", "3", "30", "3", gc_mode) == CASES


@pytest.mark.parametrize("gc_mode", GC_MODES)
def test_json_maze(json_maze, gc_mode):
    assert run_worker("json", json_maze, "30", "3", gc_mode) == CASES


ISSUE_20 = """
import gc, sys
import gymnasium as gym, hippo_env
gc.set_threshold(*map(int, sys.argv[1:4]))
envs = gym.make_vec("HippoMaze-v0", num_envs=2, vectorization_mode="sync")
envs.reset(seed=0)
envs.reset(seed=1)
env = gym.make("HippoMaze-v0", maze=sys.argv[4])
for k in range(6):
    env.reset(seed=k, options={"start": [-2.0 + 0.5 * k, -1.5], "goal": [2.0, 1.5]})
    env.step(k % 8)
print("ok")
"""


def run_issue_20(threshold: tuple[int, int, int], json_maze: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", ISSUE_20, *map(str, threshold), json_maze], capture_output=True, text=True, timeout=300, check=False
    )


@pytest.mark.parametrize("threshold", [(700, 10, 10), (1, 1, 1)], ids=["default-gc", "gc-every-allocation"])
def test_issue_20_reproduction(threshold, json_maze):
    """The reported snippet (``gym.make_vec`` with its defaults, then reset; it crashed every time
    with the collector's default thresholds), and repeated resets with start and goal options in a
    JSON maze."""
    done = run_issue_20(threshold, json_maze)
    assert done.returncode == 0 and done.stdout.strip() == "ok", f"exit code {done.returncode}\nstderr:\n{done.stderr[-4000:]}"


# ---------------------------------------------------------------------- the longer sweep
SWEEP = [(mode, "auto") for mode in ("threshold-1", "in-pymunk:1", "in-pymunk:7", "in-pymunk:17")] + [
    (mode, "public")
    for mode in ("threshold-1", "in-pymunk:7")  # the public calls are many more pymunk events
]


@pytest.mark.slow
@pytest.mark.parametrize(("gc_mode", "pymunk_calls"), SWEEP)
@pytest.mark.parametrize("maze", [*(("builtin", m) for m in hippo_env.BUILTIN_MAZES), ("generated", "0"), ("generated", "1")], ids=str)
def test_sweep(maze, gc_mode, pymunk_calls):
    """Longer drives, more resets, more collector schedules, on both implementations of the pymunk
    calls (``hippo_env._pymunk_fast``)."""
    env = os.environ | {"HIPPO_ENV_PYMUNK": pymunk_calls}
    assert run_worker(*maze, "100", "8", gc_mode, env=env) == CASES


@pytest.mark.slow
def test_sweep_issue_20_in_fresh_processes(json_maze):
    """The reported snippet in 20 fresh processes."""
    failures = [
        (done.returncode, done.stderr[-1000:])
        for done in (run_issue_20((700, 10, 10), json_maze) for _ in range(20))
        if done.returncode != 0
    ]
    assert not failures, f"{len(failures)} of 20 processes failed: {failures[:3]}"
