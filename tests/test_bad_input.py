"""Every bad input raises an error whose message names the problem: TypeError for a wrong type,
ValueError for a wrong value (anything wrong in a maze file is a value)."""

from __future__ import annotations

import json
import math

import gymnasium as gym
import numpy as np
import pytest

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_env import HippoMazeEnv, MazeSpec

SQUARE = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]


def maze_dict(**changes):
    data = {"name": "test", "size": [10.0, 10.0], "obstacles": [SQUARE]}
    data.update(changes)
    return data


def write(tmp_path, data, name="bad.json"):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data))
    return path


# ---------------------------------------------------------------------- maze files
def test_unknown_maze_name():
    with pytest.raises(ValueError, match=r"maze 'maze9' is unknown; built-in mazes: open, maze1, maze2, maze3, maze4"):
        MazeSpec.load("maze9")
    with pytest.raises(ValueError, match="unknown"):
        gym.make("HippoMaze-v0", maze="maze9")


def test_wrong_maze_type():
    with pytest.raises(TypeError, match="built-in name"):
        MazeSpec.load(42)
    with pytest.raises(TypeError, match="a maze must be a JSON object"):
        MazeSpec.from_dict([1, 2, 3])
    with pytest.raises(TypeError, match="'name' must be a non-empty string"):
        MazeSpec(name=5, size=(10.0, 10.0))


def test_unreadable_file(tmp_path):
    with pytest.raises(ValueError, match="cannot be read"):
        MazeSpec.load(tmp_path / "missing.json")
    (tmp_path / "folder.json").mkdir()
    with pytest.raises(ValueError, match="cannot be read"):
        MazeSpec.load(tmp_path / "folder.json")


def test_invalid_json(tmp_path):
    with pytest.raises(ValueError, match="is not valid JSON"):
        MazeSpec.load(write(tmp_path, '{"name": "x", "size": [10, 10], "obstacles": [}'))


def test_not_an_object(tmp_path):
    with pytest.raises(ValueError, match="must be a JSON object"):
        MazeSpec.load(write(tmp_path, [1, 2, 3]))


@pytest.mark.parametrize("key", ["name", "size", "obstacles"])
def test_missing_field(tmp_path, key):
    data = maze_dict()
    del data[key]
    with pytest.raises(ValueError, match=f"missing key '{key}'"):
        MazeSpec.load(write(tmp_path, data))


@pytest.mark.parametrize(
    "changes,message",
    [
        ({"name": 5}, "'name' must be a non-empty string"),
        ({"name": ""}, "'name' must be a non-empty string"),
        ({"size": "big"}, "'size' must be a pair of numbers"),
        ({"size": [10.0]}, "'size' must be a pair of numbers"),
        ({"size": [10.0, -2.0]}, "'size' must be two positive numbers"),
        ({"size": [10.0, "5"]}, "'size' must be a pair of finite numbers"),
        ({"size": [10.0, None]}, "'size' must be a pair of numbers"),
        ({"obstacles": 5}, "'obstacles' must be a list of polygons"),
        ({"obstacles": "square"}, "'obstacles' must be a list of polygons"),
        ({"obstacles": [5]}, "obstacle 0 must be a list of \\[x, y\\] vertices"),
        ({"obstacles": [[[0, 0], [1, 0], "a"]]}, "obstacle 0, vertex 2 must be a pair of numbers"),
        ({"obstacles": [[[0, 0], [1, 0], [1, True]]]}, "obstacle 0, vertex 2 must be a pair of finite numbers"),
        ({"goal": "centre"}, "'goal' must be a pair of numbers"),
        ({"goal": [1.0, float("nan")]}, "'goal' must be a pair of finite numbers"),
    ],
)
def test_mistyped_field(tmp_path, changes, message):
    with pytest.raises(ValueError, match=message):
        MazeSpec.load(write(tmp_path, maze_dict(**changes)))


def test_unknown_key(tmp_path):
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['colour'\]; allowed keys"):
        MazeSpec.load(write(tmp_path, maze_dict(colour="red")))


def test_obstacle_outside_arena():
    with pytest.raises(ValueError, match=r"obstacle 0, vertex 1 \(6.0, 0.0\) lies outside the arena"):
        MazeSpec.from_dict(maze_dict(obstacles=[[[0, 0], [6, 0], [0, 1]]]))


def test_self_intersecting_polygon():
    bowtie = [[-1, -1], [2, 2], [2, -1], [-1, 1]]
    with pytest.raises(ValueError, match=r"obstacle 1 is self-intersecting \(edges 0 and 2 cross\)"):
        MazeSpec.from_dict(maze_dict(obstacles=[SQUARE, bowtie]))
    figure_eight = [[-2, -2], [0, -2], [0, 0], [2, 0], [2, 2], [0, 2], [0, 0], [-2, 0]]  # touches itself at (0, 0)
    with pytest.raises(ValueError, match="self-intersecting"):
        MazeSpec.from_dict(maze_dict(obstacles=[figure_eight]))


def test_fewer_than_three_vertices():
    with pytest.raises(ValueError, match="obstacle 0 has 2 vertices; a polygon needs at least 3"):
        MazeSpec.from_dict(maze_dict(obstacles=[[[0, 0], [1, 1]]]))


def test_degenerate_polygons():
    with pytest.raises(ValueError, match="zero area"):
        MazeSpec.from_dict(maze_dict(obstacles=[[[0, 0], [1, 1], [2, 2]]]))
    with pytest.raises(ValueError, match="repeats vertex 1"):
        MazeSpec.from_dict(maze_dict(obstacles=[[[0, 0], [1, 0], [1, 0], [0, 1]]]))
    # The usual slip: closing the polygon by repeating the first vertex at the end.
    with pytest.raises(ValueError, match=r"repeats vertex 3; list each vertex once \(the polygon closes itself\)"):
        MazeSpec.from_dict(maze_dict(obstacles=[[[0, 0], [1, 0], [0, 1], [0, 0]]]))


def test_free_space_split():
    """A wall across the whole arena leaves two rooms that cannot reach each other."""
    spec = MazeSpec.from_dict(maze_dict(obstacles=[[[-5, -0.1], [5, -0.1], [5, 0.1], [-5, 0.1]]]))
    with pytest.raises(ValueError, match="split into 2 parts that cannot reach each other"):
        HippoMazeEnv(maze=spec)
    # A gap narrower than the robot also splits it.
    spec = MazeSpec.from_dict(maze_dict(obstacles=[[[-5, -0.1], [4.7, -0.1], [4.7, 0.1], [-5, 0.1]]]))
    with pytest.raises(ValueError, match="split into 2 parts"):
        gym.make("HippoMaze-v0", maze=spec)


def test_goal_in_maze_file_inside_obstacle(tmp_path):
    path = write(tmp_path, maze_dict(goal=[0.0, 0.0]))
    spec = MazeSpec.load(path)  # the spec alone does not know the robot
    with pytest.raises(ValueError, match=r"the maze's goal \(0, 0\) is inside a wall or obstacle"):
        HippoMazeEnv(maze=spec)
    with pytest.raises(ValueError, match="the maze's goal"):
        gym.make("HippoMaze-v0", maze=path)
    with pytest.raises(ValueError, match="the maze's goal"):
        HippoMazeEnv(maze=MazeSpec.from_dict(maze_dict(goal=[9.0, 0.0])))  # outside the arena


# ---------------------------------------------------------------------- constructor arguments
@pytest.mark.parametrize(
    "kwargs,message",
    [
        ({"action_type": "joystick"}, "action_type 'joystick' is unknown; choose one of discrete, heading, heading_normalized, wheels"),
        ({"reward_type": "shaped"}, "reward_type 'shaped' is unknown; choose one of sparse, dense"),
        ({"render_mode": "ascii"}, "render_mode 'ascii' is unknown; choose None or one of human, rgb_array"),
        ({"n_rays": 0}, "n_rays must be a positive integer"),
        ({"max_range": -1.0}, "max_range must be a positive number"),
        ({"range_noise": -0.1}, "range_noise must be a finite number >= 0"),
        ({"goal_radius": 0.0}, "goal_radius must be positive"),
        ({"min_start_distance": float("nan")}, "min_start_distance must be a finite number"),
    ],
)
def test_bad_constructor_argument(kwargs, message):
    with pytest.raises(ValueError, match=message):
        HippoMazeEnv(**kwargs)


@pytest.mark.parametrize(
    "kwargs,message",
    [
        ({"n_rays": 2.5}, "n_rays must be a positive integer, got 2.5"),
        ({"max_range": "far"}, "max_range must be a positive number"),
        ({"range_noise": True}, "range_noise must be a finite number >= 0"),
        ({"odometry": "yes"}, "odometry must be True or False"),
        ({"goal_seed": 1.5}, "goal_seed must be a non-negative integer"),
        ({"path_limit": 2.5}, "path_limit must be a positive integer"),
    ],
)
def test_constructor_argument_of_the_wrong_type(kwargs, message):
    with pytest.raises(TypeError, match=message):
        HippoMazeEnv(**kwargs)


# ---------------------------------------------------------------------- reset options
@pytest.fixture(scope="module")
def env():
    return HippoMazeEnv(maze="maze1", n_rays=16)


def test_unknown_reset_option(env):
    with pytest.raises(ValueError, match=r"reset options \['goal_position'\] are unknown; allowed: maze, goal, new_goal, start, heading"):
        env.reset(options={"goal_position": [1, 1]})


@pytest.mark.parametrize("goal", [[-3.0, 1.5], [-3.0, 1.25], [5.0, 0.0], [7.0, 7.0]])
def test_goal_option_inside_obstacle(env, goal):
    """Inside maze1's wall, closer to it than the robot's radius, on the arena wall, outside the arena."""
    with pytest.raises(ValueError, match="reset option 'goal' .* is inside a wall or obstacle, or too close"):
        env.reset(options={"goal": goal})


@pytest.mark.parametrize("goal", ["here", [1.0], [1.0, 2.0, 3.0], [math.inf, 0.0], [[1.0, 2.0]]])
def test_goal_option_malformed(env, goal):
    with pytest.raises(ValueError, match="reset option 'goal' must be a point"):
        env.reset(options={"goal": goal})


@pytest.mark.parametrize("start", [[-3.0, 1.5], [4.9, 0.0], [0.0, -6.0]])
def test_start_option_inside_obstacle(env, start):
    with pytest.raises(ValueError, match="reset option 'start' .* puts the robot inside or against a wall"):
        env.reset(options={"start": start})


def test_start_option_malformed_or_in_goal(env):
    with pytest.raises(ValueError, match="reset option 'start' must be a point"):
        env.reset(options={"start": None})
    with pytest.raises(ValueError, match="lies inside the goal disk"):
        env.reset(options={"goal": [2.0, 2.0], "start": [2.1, 2.0]})


@pytest.mark.parametrize("heading,error", [("north", TypeError), (math.nan, ValueError), (None, TypeError), ([0.0], TypeError)])
def test_heading_option_bad(env, heading, error):
    with pytest.raises(error, match="reset option 'heading' must be a finite angle"):
        env.reset(options={"heading": heading})


# ---------------------------------------------------------------------- actions
@pytest.fixture(scope="module")
def envs():
    made = {a: HippoMazeEnv(maze="open", n_rays=8, action_type=a) for a in ("discrete", "heading", "wheels")}
    for e in made.values():
        e.reset(seed=0)
    return made


@pytest.mark.parametrize("action", [8, -1, 2.5, "a", None, True, np.array([1, 2]), np.float64(3.0), [3], 1e9])
def test_discrete_action_outside_space(envs, action):
    with pytest.raises(ValueError, match=r"outside the action space Discrete\(8\); give an integer 0..7"):
        envs["discrete"].step(action)


def _step_moves(env, action):
    """Step from the arena's centre; True if the robot's position or heading changed."""
    _, before = env.reset(options={"start": [0.0, 0.0], "heading": 0.0})
    _, _, _, _, after = env.step(action)
    return not (np.allclose(after["position"], before["position"]) and math.isclose(after["heading"], before["heading"]))


@pytest.mark.parametrize("action", [0, 7, np.int64(3), np.array(5), np.array([2])])
def test_discrete_action_accepted(envs, action):
    assert _step_moves(envs["discrete"], action)


@pytest.mark.parametrize(
    "action",
    [np.array([4.0], np.float32), np.array([-3.2]), np.array([np.nan]), np.array([0.1, 0.2]), "a", None, [math.inf]],
)
def test_heading_action_outside_space(envs, action):
    with pytest.raises(ValueError, match=r"outside the action space Box.*\[heading in radians\]"):
        envs["heading"].step(action)


@pytest.mark.parametrize(
    "action",
    [np.array([1.5, 0.0]), np.array([0.0, -1.01]), np.array([np.nan, 0.0]), np.array([0.5]), np.zeros(3), np.zeros((2, 2)), "ab", None],
)
def test_wheels_action_outside_space(envs, action):
    with pytest.raises(ValueError, match=r"outside the action space Box.*\[left, right\] wheel speeds with values in \[-1, 1\]"):
        envs["wheels"].step(action)


def test_box_actions_accepted(envs):
    assert _step_moves(envs["heading"], np.array([math.pi], np.float32))
    assert _step_moves(envs["heading"], [-math.pi])
    assert _step_moves(envs["wheels"], np.array([-1.0, 1.0], np.float32))  # turns in place
    assert _step_moves(envs["wheels"], [0.25, 0.5])


def test_bad_action_through_gym_make():
    env = gym.make("HippoMaze-v0", n_rays=8)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="outside the action space"):
        env.step(8)
