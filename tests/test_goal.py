"""DMTP goal handling: the goal persists across resets until moved; starts, rewards, termination,
truncation, ``info`` keys and indirectness."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import hippo_env
from hippo_env import HippoMazeEnv, MazeSpec

STEP = 0.15
INFO_KEYS = {"position", "heading", "goal", "is_success", "path_length", "shortest_path_length", "collision"}


def make(maze="open", **kwargs):
    kwargs.setdefault("n_rays", 16)
    return gym.make("HippoMaze-v0", maze=maze, **kwargs)


def test_goal_stays_across_resets():
    env = make("maze1")
    _, info = env.reset(seed=0)
    goal = tuple(info["goal"])
    assert all(math.isfinite(g) for g in goal)
    starts = set()
    for _ in range(10):
        _, info = env.reset()
        assert tuple(info["goal"]) == goal
        starts.add(tuple(info["position"]))
    assert len(starts) == 10
    # Even a seeded reset keeps the trial's goal.
    _, info = env.reset(seed=123)
    assert tuple(info["goal"]) == goal


def test_goal_option_moves_the_goal_and_it_stays():
    env = make("maze2")
    env.reset(seed=0)
    _, info = env.reset(options={"goal": [2.0, -3.0]})
    assert tuple(info["goal"]) == (2.0, -3.0)
    for _ in range(3):
        assert tuple(env.reset()[1]["goal"]) == (2.0, -3.0)
    _, info = env.reset(options={"goal": np.array([-1.0, 4.0])})
    assert tuple(info["goal"]) == (-1.0, 4.0)


def test_new_goal_draws_a_new_goal():
    env = make("maze3")
    _, info = env.reset(seed=0)
    goals = {tuple(info["goal"])}
    for _ in range(5):
        _, info = env.reset(options={"new_goal": True})
        goals.add(tuple(info["goal"]))
        assert env.unwrapped.maze.clearance(info["goal"]) >= 0.5  # drawn goals keep 0.5 m from walls
        assert tuple(env.reset()[1]["goal"]) == tuple(info["goal"])
    assert len(goals) == 6


def test_maze_file_goal_is_the_first_goal():
    spec = MazeSpec(name="with_goal", size=(6.0, 6.0), goal=(1.5, 1.0))
    env = make(spec)
    assert tuple(env.reset(seed=0)[1]["goal"]) == (1.5, 1.0)
    assert tuple(env.reset()[1]["goal"]) == (1.5, 1.0)
    assert tuple(env.reset(options={"new_goal": True})[1]["goal"]) != (1.5, 1.0)


def test_goal_free_episode_never_terminates():
    env = make("open", max_episode_steps=400)
    _, info = env.reset(seed=0, options={"goal": None})
    assert all(math.isnan(g) for g in info["goal"])
    assert math.isnan(info["shortest_path_length"])
    for t in range(400):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert reward == 0.0 and not terminated and not info["is_success"]
        assert all(math.isnan(g) for g in info["goal"])
        assert truncated == (t == 399)
    assert "indirectness" not in info or math.isnan(info["indirectness"])
    # Still goal-free on the next reset, until a goal is given.
    assert math.isnan(env.reset()[1]["goal"][0])
    assert tuple(env.reset(options={"goal": [1.0, 1.0]})[1]["goal"]) == (1.0, 1.0)


@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
def test_random_starts_keep_away_from_the_goal(maze):
    env = make(maze)
    env.reset(seed=1)
    for k in range(30):
        _, info = env.reset(options={"new_goal": True} if k % 10 == 0 else None)
        assert math.dist(info["position"], info["goal"]) >= 1.0
        assert env.unwrapped.maze.clearance(info["position"]) >= 0.17


def test_min_start_distance_argument():
    env = make("open", min_start_distance=4.0)
    env.reset(seed=0, options={"goal": [0.0, 0.0]})
    for _ in range(20):
        assert math.dist(env.reset()[1]["position"], (0.0, 0.0)) >= 4.0


def test_start_and_heading_options():
    env = make("maze1")
    _, info = env.reset(seed=0, options={"start": [3.0, 3.5], "heading": 1.25})
    assert info["position"] == pytest.approx((3.0, 3.5))
    assert info["heading"] == pytest.approx(1.25)
    assert info["path_length"] == 0.0
    _, info = env.reset(options={"start": (-3.0, -3.0)})  # alone: a random heading
    assert info["position"] == pytest.approx((-3.0, -3.0))
    _, info = env.reset(options={"heading": -2.0})  # alone: a random start
    assert info["heading"] == pytest.approx(-2.0)
    assert info["position"] != pytest.approx((-3.0, -3.0))


def test_reaching_the_goal():
    """From (0, 0) toward a goal at (1.25, 0) of radius 0.3: the 7th step (x = 1.05) enters the disk."""
    env = make("open")
    _, info = env.reset(seed=0, options={"goal": [1.25, 0.0], "start": [0.0, 0.0], "heading": 0.0})
    assert info["shortest_path_length"] == pytest.approx(1.25 - 0.3)
    for _ in range(6):
        _, reward, terminated, truncated, info = env.step(0)
        assert reward == 0.0 and not terminated and not info["is_success"]
        assert "indirectness" not in info
    _, reward, terminated, truncated, info = env.step(0)
    assert reward == 1.0 and terminated and not truncated and info["is_success"]
    assert info["path_length"] == pytest.approx(7 * STEP)
    assert info["indirectness"] == pytest.approx((7 * STEP - 0.95) / 0.95)


def test_truncation_carries_indirectness():
    env = make("open", max_episode_steps=5)
    _, info = env.reset(seed=0, options={"goal": [4.0, 4.0], "start": [-4.0, -4.0], "heading": 0.0})
    shortest = math.dist((-4, -4), (4, 4)) - 0.3
    assert info["shortest_path_length"] == pytest.approx(shortest)
    for t in range(5):
        _, _reward, terminated, truncated, info = env.step(4)  # away from the goal
        assert truncated == (t == 4) and not terminated
    assert info["indirectness"] == pytest.approx((5 * STEP - shortest) / shortest)


@pytest.mark.parametrize("seed", range(5))
def test_shortest_path_is_straight_minus_goal_radius_in_open_arena(seed):
    env = make("open", goal_radius=0.4)
    _, info = env.reset(seed=seed)
    assert info["shortest_path_length"] == pytest.approx(math.dist(info["position"], info["goal"]) - 0.4, abs=1e-9)


def test_shortest_path_is_the_geodesic_in_a_maze():
    env = make("maze1")
    _, info = env.reset(seed=0, options={"goal": [-3.0, 3.0], "start": [-3.0, 0.0]})
    geodesic = env.unwrapped.maze.geodesic((-3.0, 0.0), (-3.0, 3.0), 0.17)
    assert info["shortest_path_length"] == pytest.approx(geodesic - 0.3)
    assert info["shortest_path_length"] > 3.0  # the wall makes it a detour


@pytest.mark.parametrize("action_type", ["discrete", "heading", "wheels"])
def test_info_keys_on_every_step(action_type):
    env = make("maze4", action_type=action_type)
    _, info = env.reset(seed=0)
    assert INFO_KEYS <= info.keys()
    for _ in range(30):
        _, reward, _terminated, _truncated, info = env.step(env.action_space.sample())
        assert INFO_KEYS <= info.keys()
        assert isinstance(info["collision"], bool) and isinstance(info["is_success"], bool)
        assert len(info["position"]) == 2 and len(info["goal"]) == 2
        assert -math.pi <= info["heading"] <= math.pi
        assert info["path_length"] >= 0
        assert isinstance(reward, float)


def test_path_length_accumulates():
    env = HippoMazeEnv(maze="open", n_rays=8)
    env.reset(seed=0, options={"goal": None, "start": [0.0, 0.0], "heading": 0.0})
    for k in (0, 2, 4, 6):
        _, _, _, _, info = env.step(k)
    assert info["path_length"] == pytest.approx(4 * STEP)
    assert info["position"] == pytest.approx((0.0, 0.0), abs=1e-9)
    assert env.path.shape == (5, 2)


def test_dense_reward_rewards_progress():
    env = make("open", reward_type="dense")
    env.reset(seed=0, options={"goal": [3.0, 0.0], "start": [0.0, 0.0], "heading": 0.0})
    toward = env.step(0)[1]
    away = env.step(4)[1]
    assert toward > 0 > away
    assert toward == pytest.approx(0.1, abs=0.05)


def test_dense_reward_follows_a_moved_goal_and_keeps_the_field_for_the_same_goal():
    env = make("open", reward_type="dense")
    env.reset(seed=0, options={"goal": [3.0, 0.0], "start": [0.0, 0.0], "heading": 0.0})
    assert env.step(0)[1] > 0  # east, toward (3, 0)
    field = env.unwrapped._distance_field
    env.reset(options={"goal": [3.0, 0.0], "start": [0.0, 0.0]})  # the runner passes the goal on every run
    assert env.unwrapped._distance_field is field
    env.reset(options={"goal": [-3.0, 0.0], "start": [0.0, 0.0]})
    assert env.step(0)[1] < 0 < env.step(4)[1]  # east is now away from the goal, west toward it


def test_a_goal_given_as_an_array_is_copied_not_kept():
    """The caller's array may change after the reset; the env's goal does not."""
    env = make()
    goal = np.array([1.0, 1.0])
    env.reset(seed=0, options={"goal": goal})
    goal[:] = 4.0
    assert np.array_equal(env.unwrapped.goal, [1.0, 1.0])
    env.close()
