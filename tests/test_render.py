"""Rendering: rgb_array frames, rays, the human mode, video recording, and plot_maze."""

from __future__ import annotations

import warnings

import gymnasium as gym
import matplotlib
import numpy as np
import pytest

import hippo_env
from hippo_env import HippoMazeEnv
from hippo_env.render import plot_maze

matplotlib.use("Agg")


def test_rgb_array_frame_changes_when_robot_moves():
    env = HippoMazeEnv(maze="maze1", n_rays=32, render_mode="rgb_array")
    env.reset(seed=0, options={"start": [0.0, 0.0], "heading": 0.0})
    first = env.render()
    assert isinstance(first, np.ndarray) and first.dtype == np.uint8
    assert first.ndim == 3 and first.shape[2] == 3 and first.shape[0] > 100 and first.shape[1] > 100
    assert env.render().tobytes() == first.tobytes()  # nothing moved
    for _ in range(3):
        env.step(0)
    moved = env.render()
    assert moved.shape == first.shape
    assert (moved != first).any(axis=2).sum() > 50
    env.close()


def test_render_rays_draws_more():
    frames = {}
    for rays in (False, True):
        env = HippoMazeEnv(maze="open", n_rays=360, render_mode="rgb_array", render_rays=rays)
        env.reset(seed=0, options={"start": [0.0, 0.0], "heading": 0.0})
        frames[rays] = env.render()
        env.close()
    assert frames[True].shape == frames[False].shape
    assert (frames[True] != frames[False]).any(axis=2).sum() > 500


def test_goal_free_render():
    env = HippoMazeEnv(maze="maze2", n_rays=32, render_mode="rgb_array", render_rays=True)
    env.reset(seed=0, options={"goal": None})
    env.step(1)
    assert env.render().dtype == np.uint8


def test_render_through_gym_make():
    env = gym.make("HippoMaze-v0", maze="maze3", n_rays=32, render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.shape[2] == 3
    env.close()


def test_render_without_mode_warns_and_returns_none():
    env = HippoMazeEnv(maze="open", n_rays=8)
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode"):
        assert env.render() is None


def test_human_mode_runs_headless(monkeypatch):
    monkeypatch.setattr(hippo_env.render, "check_human_display", lambda: None)  # as if a display were there
    env = HippoMazeEnv(maze="maze4", n_rays=32, render_mode="human")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # Agg is non-interactive
        env.reset(seed=0)
        env.step(0)
        assert env.render() is None
    env.close()


def test_record_video(tmp_path):
    """gymnasium's RecordVideo writes an mp4 (it needs moviepy: the ``video`` extra, which ``make test`` installs)."""
    env = gym.make("HippoMaze-v0", maze="maze1", n_rays=32, render_mode="rgb_array", max_episode_steps=20)
    env = gym.wrappers.RecordVideo(env, str(tmp_path / "videos"), episode_trigger=lambda e: True, disable_logger=True)
    env.reset(seed=0)
    for _ in range(20):
        *_, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            break
    env.close()
    assert list((tmp_path / "videos").glob("*.mp4"))


@pytest.mark.parametrize("maze", hippo_env.BUILTIN_MAZES)
def test_plot_maze(maze):
    import matplotlib.pyplot as plt

    fig, ax = plot_maze(maze)
    assert ax.get_title() == maze
    assert len(ax.patches) == 1 + len(hippo_env.MazeSpec.load(maze).obstacles)  # the floor and each obstacle
    plt.close(fig)
    fig, axes = plt.subplots(1, 2)
    fig2, ax2 = plot_maze(maze, ax=axes[1], goal=(1.0, 1.0), title="x")
    assert fig2 is fig and ax2 is axes[1] and ax2.get_title() == "x"
    plt.close(fig)


def test_render_collection_wrapper():
    """Frame-collecting wrappers (what RecordVideo builds on) get one frame per reset and step."""
    env = gym.wrappers.RenderCollection(gym.make("HippoMaze-v0", maze="maze1", n_rays=32, render_mode="rgb_array"))
    env.reset(seed=0)
    for _ in range(4):
        env.step(env.action_space.sample())
    frames = env.render()
    assert len(frames) == 5 and all(f.dtype == np.uint8 and f.shape == frames[0].shape for f in frames)
    assert any((f != frames[0]).any() for f in frames[1:])
    env.close()
