"""The robot's motion: free driving matches the kinematics, walls stop it or let it slide, and no
sequence of actions puts it into (or closer than its radius to) a wall."""

from __future__ import annotations

import copy
import gc
import math
import pickle
import re
import weakref
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import hippo_env
from hippo_env import HippoMazeEnv, MazeSpec, _pymunk_fast, physics

R = physics.ROBOT_RADIUS
STEP = physics.MAX_SPEED * physics.CONTROL_DT  # 0.15 m
TOL = 1e-3

_ENVS: dict[tuple[str, str], HippoMazeEnv] = {}


def env_for(maze: str, action_type: str = "discrete") -> HippoMazeEnv:
    """One environment per (maze, action type) for the whole module (construction checks connectivity)."""
    key = (maze, action_type)
    if key not in _ENVS:
        _ENVS[key] = HippoMazeEnv(maze=maze, action_type=action_type, n_rays=8)
    return _ENVS[key]


def place(env, start, heading=0.0):
    env.reset(seed=0, options={"goal": None, "start": list(start), "heading": heading})


# ---------------------------------------------------------------------- free motion
@pytest.mark.parametrize("k", range(8))
def test_discrete_action_turns_then_drives_one_step(k):
    env = env_for("open")
    place(env, (0.0, 0.0), heading=0.0)
    _, reward, terminated, truncated, info = env.step(k)
    angle = k * math.pi / 4
    np.testing.assert_allclose(info["position"], (STEP * math.cos(angle), STEP * math.sin(angle)), atol=1e-9)
    assert math.cos(info["heading"] - angle) == pytest.approx(1.0)
    assert info["path_length"] == pytest.approx(STEP)
    assert not info["collision"] and not terminated and not truncated and reward == 0.0
    turn = abs((angle + math.pi) % (2 * math.pi) - math.pi)
    assert info["sim_time"] == pytest.approx(turn / physics.TURN_RATE + physics.CONTROL_DT)


def test_heading_action():
    env = env_for("open", "heading")
    place(env, (1.0, -1.0), heading=2.0)
    _, _, _, _, info = env.step(np.array([-2.5], np.float32))
    heading = float(np.float32(-2.5))
    np.testing.assert_allclose(info["position"], (1.0 + STEP * math.cos(heading), -1.0 + STEP * math.sin(heading)), atol=1e-6)
    assert info["heading"] == pytest.approx(heading, abs=1e-6)


@pytest.mark.parametrize("left,right", [(1.0, 1.0), (-1.0, -1.0), (0.5, 0.5), (-1.0, 1.0), (1.0, -1.0), (1.0, 0.5), (0.2, 0.9), (0.0, 0.0)])
def test_wheels_follow_the_arc(left, right):
    env = env_for("open", "wheels")
    theta = 0.4
    place(env, (0.5, 0.5), heading=theta)
    _, _, _, _, info = env.step(np.array([left, right], np.float32))
    v = physics.MAX_SPEED * (left + right) / 2
    w = physics.MAX_SPEED * (right - left) / physics.AXLE_LENGTH
    t = physics.CONTROL_DT
    if w == 0:
        expected = (0.5 + v * t * math.cos(theta), 0.5 + v * t * math.sin(theta))
    else:  # the unicycle's circular arc
        expected = (0.5 + v / w * (math.sin(theta + w * t) - math.sin(theta)), 0.5 - v / w * (math.cos(theta + w * t) - math.cos(theta)))
    np.testing.assert_allclose(info["position"], expected, atol=1e-6)
    assert math.cos(info["heading"] - (theta + w * t)) == pytest.approx(1.0, abs=1e-9)
    assert not info["collision"]


def test_driving_parallel_to_a_wall_is_not_a_collision():
    env = env_for("open")
    place(env, (0.0, 5.0 - R - 0.03), heading=0.0)
    for n in range(1, 6):
        _, _, _, _, info = env.step(0)
        assert not info["collision"]
        np.testing.assert_allclose(info["position"], (n * STEP, 5.0 - R - 0.03), atol=1e-9)


# ---------------------------------------------------------------------- collisions
def test_driving_into_a_wall_stops_the_robot():
    env = env_for("open")
    place(env, (4.4, 0.0), heading=0.0)
    collisions = []
    xs = []
    for _ in range(10):
        _, _, _, _, info = env.step(0)
        collisions.append(info["collision"])
        xs.append(info["position"][0])
        assert env.maze.clearance(info["position"]) >= R - TOL
        assert info["position"][1] == pytest.approx(0.0, abs=1e-9)
    assert collisions[:2] == [False, False]  # 4.55, 4.70: clear of the wall
    assert all(collisions[3:])  # pushing against the wall
    assert 5.0 - R - 0.02 < xs[-1] <= 5.0 - R
    assert max(xs[3:]) - min(xs[3:]) < 0.02  # stopped: pushing on does not move it


def test_driving_into_an_obstacle_stops_the_robot():
    """maze1's wall spans y in [1.35, 1.65] for x < -1: driving +y from below stops under it."""
    env = env_for("maze1")
    place(env, (-3.0, 0.5), heading=0.0)
    for _ in range(12):
        _, _, _, _, info = env.step(2)
        assert env.maze.clearance(info["position"]) >= R - TOL
    assert info["collision"]
    assert 1.35 - R - 0.02 < info["position"][1] <= 1.35 - R
    assert info["position"][0] == pytest.approx(-3.0, abs=1e-6)


def test_robot_slides_along_a_wall():
    """Heading 45 degrees into the +x wall: x is blocked, y keeps moving at 0.15 * sin(45 deg) per step."""
    env = env_for("open")
    place(env, (4.6, 0.0), heading=0.0)
    previous = None
    slid = 0
    for _ in range(8):
        _, _, _, _, info = env.step(1)
        x, y = info["position"]
        assert x <= 5.0 - R + 1e-9
        if info["collision"]:
            assert y - previous[1] == pytest.approx(STEP * math.sqrt(0.5), abs=0.01)
            slid += 1
        previous = (x, y)
    assert slid >= 4


def test_wheels_into_a_wall_collide_and_keep_turning():
    env = env_for("open", "wheels")
    place(env, (4.6, 0.0), heading=0.3)
    headings = []
    for _ in range(6):
        _, _, _, _, info = env.step(np.array([1.0, 0.8], np.float32))
        assert env.maze.clearance(info["position"]) >= R - TOL
        headings.append(info["heading"])
    assert info["collision"]
    np.testing.assert_allclose(np.diff(headings), -physics.MAX_SPEED * 0.2 / physics.AXLE_LENGTH * physics.CONTROL_DT, atol=1e-6)


def test_corner():
    env = env_for("open")
    place(env, (4.5, 4.5))
    for _ in range(5):
        _, _, _, _, info = env.step(1)
        assert env.maze.clearance(info["position"]) >= R - TOL
    assert info["collision"]
    np.testing.assert_allclose(info["position"], (5 - R, 5 - R), atol=0.02)


def test_a_slower_wheel_command_at_a_wall_does_not_kick_the_robot_through_it():
    # Found by the property below: a step against a wall whose substeps did not divide the control
    # step ended on a sliver of a substep, and pymunk scaled the contact impulses cached in it by
    # (next substep / sliver) at the next step: the robot left the arena by 25 m.
    env = gym.make("HippoMaze-v0", maze="maze3", action_type="wheels", n_rays=16)
    env.reset(seed=1613, options={"goal": None})
    for left, right, repeat in [(0.0, 1.0, 6), (0.0, 0.533408522605896, 3)]:
        for _ in range(repeat):
            _, _, _, _, info = env.step(np.array([left, right], np.float32))
            assert env.unwrapped.maze.clearance(info["position"]) >= R - TOL


# ---------------------------------------------------------------------- properties
repeats = st.integers(1, 25)
ACTION_PLANS = {
    "discrete": st.lists(st.tuples(st.integers(0, 7), repeats), min_size=1, max_size=8),
    "heading": st.lists(st.tuples(st.floats(-math.pi, math.pi), repeats), min_size=1, max_size=8),
    "wheels": st.lists(st.tuples(st.floats(-1, 1, width=32), st.floats(-1, 1, width=32), repeats), min_size=1, max_size=8),
}


def _action(action_type, item):
    if action_type == "discrete":
        return item[0]
    return np.array(item[:-1], np.float32)


@pytest.mark.parametrize("action_type", ["discrete", "heading", "wheels"])
@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
@settings(max_examples=25, deadline=None)
@given(data=st.data(), seed=st.integers(0, 2**31 - 1))
def test_robot_never_enters_a_wall(maze, action_type, data, seed):
    env = env_for(maze, action_type)
    plan = data.draw(ACTION_PLANS[action_type])
    _, info = env.reset(seed=seed, options={"goal": None})
    hw, hh = env.maze.half_extent
    for item in plan:
        action = _action(action_type, item)
        for _ in range(item[-1]):
            _, _, terminated, _, info = env.step(action)
            position = info["position"]
            # clearance() is negative inside an obstacle or outside the arena, so this one check covers all three.
            clearance = env.maze.clearance(position)
            assert clearance >= R - TOL, (
                f"at {position}: {clearance:.4f} m from a wall; inside an obstacle: {env.maze.inside_obstacle(position)}; "
                f"outside the arena: {abs(position[0]) >= hw or abs(position[1]) >= hh}"
            )
            assert not terminated


# ---------------------------------------------------------------------- pymunk calls and the world's lifetime
needs_c_path = pytest.mark.skipif(_pymunk_fast.CFFI is None, reason=f"no C path here: {_pymunk_fast.CFFI_UNAVAILABLE}")


def trajectory(maze, action_type, steps=400, seed=0):
    """Positions, headings, collisions and simulated times of seeded random actions, with resets
    (plain, with a start and heading, with a goal) every 100 steps."""
    env = HippoMazeEnv(maze=maze, action_type=action_type, n_rays=8)
    env.action_space.seed(seed)
    rng = np.random.default_rng(seed)
    _, info = env.reset(seed=seed)
    rows = []
    for t in range(1, steps + 1):
        # Wheel commands mostly forward, to meet walls.
        action = np.clip(rng.normal(0.7, 0.4, 2), -1, 1).astype(np.float32) if action_type == "wheels" else env.action_space.sample()
        _, _, terminated, _, info = env.step(action)
        rows.append((*info["position"], info["heading"], info["collision"], info["sim_time"]))
        if terminated or t % 100 == 0:
            start = env.maze.sample_free(rng, 0.4, away_from=env.goal, min_distance=1.0)
            options = [None, {"start": list(start), "heading": float(rng.uniform(-3, 3))}, {"goal": list(env.maze.sample_free(rng, 0.5))}][
                t // 100 % 3
            ]
            _, info = env.reset(options=options)
            rows.append((*info["position"], info["heading"], -1, info["sim_time"]))
    return env.world.pymunk_calls, np.array(rows)


@needs_c_path
@pytest.mark.parametrize("action_type", ["discrete", "heading", "wheels"])
@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
def test_c_path_and_public_api_agree_bit_for_bit(maze, action_type, monkeypatch):
    monkeypatch.delenv(_pymunk_fast.ENV_VAR, raising=False)
    fast, expected = trajectory(maze, action_type)
    monkeypatch.setenv(_pymunk_fast.ENV_VAR, "public")
    public, got = trajectory(maze, action_type)
    assert (fast, public) == ("cffi", "public")
    assert (got[:, 3] == 1).sum() > 5  # the robot met walls
    np.testing.assert_array_equal(got, expected)


def test_the_c_path_is_used_on_the_checked_pymunk_versions():
    major_minor = ".".join(pymunk_version().split(".")[:2])
    assert (_pymunk_fast.CFFI is not None) == (major_minor in _pymunk_fast.CHECKED_PYMUNK), _pymunk_fast.CFFI_UNAVAILABLE


def pymunk_version():
    import pymunk

    return pymunk.version


def test_choosing_the_pymunk_calls(monkeypatch):
    monkeypatch.delenv(_pymunk_fast.ENV_VAR, raising=False)
    assert _pymunk_fast.choose("public") is _pymunk_fast.PUBLIC
    assert _pymunk_fast.choose() is (_pymunk_fast.CFFI or _pymunk_fast.PUBLIC)
    assert _pymunk_fast.choose("cffi") is (_pymunk_fast.CFFI or _pymunk_fast.PUBLIC)
    monkeypatch.setenv(_pymunk_fast.ENV_VAR, "public")
    assert _pymunk_fast.choose() is _pymunk_fast.PUBLIC
    assert physics.RobotWorld(MazeSpec.load("open")).pymunk_calls == "public"
    with pytest.raises(ValueError, match="unknown; allowed: auto, cffi, public"):
        _pymunk_fast.choose("fast")
    monkeypatch.setenv(_pymunk_fast.ENV_VAR, "fast")
    with pytest.raises(ValueError, match="HIPPO_ENV_PYMUNK='fast' is unknown"):
        _pymunk_fast.choose()


def test_only_the_fast_module_names_pymunk_privates():
    pattern = re.compile(r"_chipmunk_cffi|\._space\b|\._body\b|\._shape\b")
    package = Path(hippo_env.__file__).parent
    offenders = [
        f"{path.name}:{n}: {line.strip()}"
        for path in sorted(package.rglob("*.py"))
        if path.name != "_pymunk_fast.py"
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if pattern.search(line)
    ]
    assert not offenders


@pytest.mark.parametrize("pymunk_calls", ["cffi", "public"])
def test_one_space_for_the_worlds_life(pymunk_calls):
    """Resets put a new robot into the same space; the old robot is let go (nothing piles up)."""
    world = physics.RobotWorld(MazeSpec.load("maze1"), pymunk_calls=pymunk_calls)
    space, walls = world.space, len(world.space.shapes)
    old = [weakref.ref(world.body), weakref.ref(world.shape)]
    for k in range(5):
        world.reset((-3.0, 0.5 + 0.1 * k), 1.0)
        world.drive_heading(math.pi / 2)  # into maze1's wall: contacts, substeps
        world.drive_heading(math.pi / 2)
    assert world.space is space and len(space.shapes) == walls and list(space.bodies) == [world.body]
    gc.collect()
    assert all(ref() is None for ref in old)


@pytest.mark.parametrize("pymunk_calls", ["cffi", "public"])
def test_a_reset_world_moves_as_a_new_one(pymunk_calls):
    """After a reset, nothing of the last episode (contacts, solver state) changes the motion."""
    maze = MazeSpec.load("maze1")
    used = physics.RobotWorld(maze, pymunk_calls=pymunk_calls)
    used.reset((-3.0, 0.9), 1.5)
    for _ in range(6):
        used.drive_wheels(1.0, 0.7)  # pushing into the wall above
    commands = [(1.0, 0.9), (0.4, 1.0), (1.0, 1.0), (-0.5, 1.0), (1.0, 1.0), (1.0, 0.2)] * 3
    paths = []
    for world in (used, physics.RobotWorld(maze, pymunk_calls=pymunk_calls)):
        world.reset((-3.0, 1.05), 1.4)
        paths.append([(world.drive_wheels(*c), world.position, world.heading) for c in commands])
    assert any(collision for collision, _, _ in paths[0])
    assert paths[0] == paths[1]


@pytest.mark.parametrize("copier", [copy.deepcopy, lambda w: pickle.loads(pickle.dumps(w))], ids=["deepcopy", "pickle"])
def test_a_copied_world_has_its_own_robot(copier):
    world = physics.RobotWorld(MazeSpec.load("open"))
    world.reset((0.0, 0.0), 0.0)
    world.drive_heading(0.5)
    state = world.__getstate__()
    assert not {"_calls", "_h_space", "_h_body"} & set(state)  # no C pointers in a pickle
    twin = copier(world)
    assert twin.pymunk_calls == world.pymunk_calls and twin.position == world.position and twin.heading == world.heading
    twin.drive_heading(2.0)
    assert twin.position != world.position  # the copy drives its own body, not the original's
    world.drive_heading(2.0)
    assert twin.position == world.position  # in the open, a copy continues exactly


def test_an_unpickled_world_chooses_its_calls_again(monkeypatch):
    """A pickle holds no C pointers: the unpickled world takes its calls (and handles) in the new process."""
    monkeypatch.delenv(_pymunk_fast.ENV_VAR, raising=False)
    fast, public = (pickle.dumps(physics.RobotWorld(MazeSpec.load("open"), pymunk_calls=c)) for c in ("auto", "public"))
    assert pickle.loads(public).pymunk_calls == "public"
    assert pickle.loads(fast).pymunk_calls == _pymunk_fast.choose().name
    monkeypatch.setenv(_pymunk_fast.ENV_VAR, "public")
    assert pickle.loads(fast).pymunk_calls == "public"
