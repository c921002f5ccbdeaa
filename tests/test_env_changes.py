"""A changing world: ``reset(options={"maze": ...})`` swaps the layout from that run on and keeps the goal."""

from __future__ import annotations

import math
import warnings
from importlib import resources

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

import hippo_env  # noqa: F401 (registers HippoMaze-v0)
from hippo_env import HippoMazeEnv, MazeSpec
from hippo_env.physics import ROBOT_RADIUS

GOAL_RADIUS = 0.3
# A bar across most of the open arena, from the west wall to x = 3: north and south meet only east of it.
WALL = MazeSpec("wall", (10.0, 10.0), [[(-5.0, -0.1), (3.0, -0.1), (3.0, 0.1), (-5.0, 0.1)]])
BLOCKED = MazeSpec("blocked", (10.0, 10.0), [[(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]])
SOUTH, NORTH = [-3.0, -2.0], [-3.0, 2.0]


def make(maze="open", **kwargs):
    return gym.make("HippoMaze-v0", maze=maze, **kwargs)


def _maze1_path():
    return str(resources.files("hippo_env.mazes").joinpath("maze1.json"))


@pytest.mark.parametrize("form", ["name", "path", "spec"])
def test_a_new_maze_keeps_the_goal(form):
    maze = {"name": "maze1", "path": _maze1_path(), "spec": MazeSpec.load("maze1")}[form]
    goal = [-3.0, -3.0]
    assert MazeSpec.load("maze1").clearance(goal) > 0.5  # free in both mazes
    env = make()
    env.reset(seed=0, options={"goal": goal})
    _, info = env.reset(options={"maze": maze})
    assert env.unwrapped.maze.name == "maze1"
    np.testing.assert_array_equal(info["goal"], goal)
    _, info = env.reset()  # and from then on
    assert env.unwrapped.maze.name == "maze1"
    np.testing.assert_array_equal(info["goal"], goal)
    env.close()


def test_the_geodesic_follows_the_new_layout():
    env = make()
    _, info = env.reset(seed=0, options={"goal": NORTH, "start": SOUTH})
    assert info["shortest_path_length"] == pytest.approx(4.0 - GOAL_RADIUS)
    _, info = env.reset(options={"maze": WALL, "start": SOUTH})
    expected = WALL.geodesic(SOUTH, NORTH, ROBOT_RADIUS) - GOAL_RADIUS
    assert info["shortest_path_length"] == pytest.approx(expected)
    assert info["shortest_path_length"] > 10.0  # around the bar's east end
    _, info = env.reset(options={"maze": "open", "start": SOUTH})  # and back
    assert info["shortest_path_length"] == pytest.approx(4.0 - GOAL_RADIUS)
    env.close()


def test_the_senses_and_the_physics_follow_the_new_layout():
    env = make()
    env.reset(seed=0, options={"goal": [4.0, 4.0], "start": SOUTH, "heading": math.pi / 2})
    observation, _ = env.reset(options={"maze": WALL, "start": SOUTH, "heading": math.pi / 2})
    assert observation["ranges"][0] == pytest.approx(-0.1 - SOUTH[1], abs=0.02)  # the bar, straight ahead
    for _ in range(30):  # drive north into the bar
        _, _, _, _, info = env.step(2)
    assert info["position"][1] < -0.1 - ROBOT_RADIUS + 0.01
    env.close()


def test_a_kept_goal_inside_the_new_walls_is_refused_and_leaves_the_env_as_it_was():
    env = make()
    _, before = env.reset(seed=0, options={"goal": [0.0, 0.0], "start": SOUTH})
    inner = env.unwrapped
    old_maze = inner.maze
    with pytest.raises(ValueError, match=r"the goal kept in maze 'blocked' \(0, 0\) is inside a wall or obstacle"):
        env.reset(options={"maze": BLOCKED})
    assert inner.maze is old_maze
    np.testing.assert_array_equal(inner.goal, [0.0, 0.0])
    _, after = env.reset(options={"start": SOUTH})
    assert after["shortest_path_length"] == before["shortest_path_length"]
    env.step(0)
    # moving the goal in the same reset is allowed: it is checked against the new walls instead
    _, info = env.reset(options={"maze": BLOCKED, "goal": [2.0, 2.0]})
    np.testing.assert_array_equal(info["goal"], [2.0, 2.0])
    with pytest.raises(ValueError, match="reset option 'goal' \\(0, 0\\) is inside a wall"):
        env.reset(options={"maze": BLOCKED, "goal": [0.0, 0.0]})
    env.close()


def test_a_new_goal_is_drawn_in_the_new_maze():
    env = make()
    env.reset(seed=0)
    for seed in range(5):
        _, info = env.reset(seed=seed, options={"maze": BLOCKED, "new_goal": True})
        assert BLOCKED.clearance(info["goal"]) >= 0.5
    env.close()


@pytest.mark.parametrize(
    ("maze", "error", "message"),
    [
        ("maze9", ValueError, "maze 'maze9' is unknown; built-in mazes: open, maze1"),
        (42, TypeError, "reset option 'maze' must be a built-in maze name, a path to a maze JSON file or a MazeSpec"),
        (
            MazeSpec("split", (4.0, 4.0), [[(-2.0, -0.1), (2.0, -0.1), (2.0, 0.1), (-2.0, 0.1)]]),
            ValueError,
            "maze .split.: the free space is split into 2 parts",
        ),
    ],
)
def test_a_bad_maze_raises_and_changes_nothing(maze, error, message):
    env = make()
    env.reset(seed=0)
    inner = env.unwrapped
    old_maze, old_goal = inner.maze, inner.goal.copy()
    with pytest.raises(error, match=message):
        env.reset(options={"maze": maze})
    assert inner.maze is old_maze
    np.testing.assert_array_equal(inner.goal, old_goal)
    env.close()


def test_gymnasium_check_env_passes_after_a_maze_change():
    env = HippoMazeEnv(maze="open", render_mode="rgb_array")
    env.reset(seed=0, options={"maze": "maze2"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        gym_check_env(env)
    assert env.maze.name == "maze2"
    env.close()


def test_rendering_follows_the_new_maze():
    env = HippoMazeEnv(maze="open", render_mode="rgb_array")
    env.reset(seed=0, options={"goal": [4.0, 4.0], "start": SOUTH})
    before = env.render()
    env.reset(options={"maze": WALL, "start": SOUTH})
    after = env.render()
    assert before.shape == after.shape and not np.array_equal(before, after)
    env.close()
