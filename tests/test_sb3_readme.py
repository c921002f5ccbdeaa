"""The README's "Train with Stable-Baselines3" example runs (shortened), and envs made alike share their goal."""

from __future__ import annotations

import re
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import hippo_env  # noqa: F401  (registers HippoMaze-v0)

README = Path(__file__).resolve().parent.parent / "README.md"


def _sb3_example() -> str:
    text = README.read_text()
    section = text.split("## Train with Stable-Baselines3", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.DOTALL).group(1)


def test_readme_sb3_example_runs(tmp_path, monkeypatch, capsys):
    code = _sb3_example()
    # A few hundred timesteps instead of the real budget; everything else as printed.
    shortened = code.replace("total_timesteps=200_000", "total_timesteps=256").replace("eval_freq=10_000", "eval_freq=128")
    shortened = shortened.replace("max_episode_steps=500", "max_episode_steps=40")
    # One short rollout and one epoch instead of PPO's 2048-step rollouts and 10 epochs.
    shortened = shortened.replace("seed=0, verbose=0)", "seed=0, verbose=0, n_steps=128, batch_size=64, n_epochs=1)")
    assert (
        shortened.count("256") == 1 and "eval_freq=128" in shortened and "max_episode_steps=40" in shortened and "n_steps=128" in shortened
    )
    monkeypatch.chdir(tmp_path)
    exec(compile(shortened, "README.md", "exec"), {"__name__": "readme"})  # noqa: S102 (the README example, as printed)
    assert "success rate, last evaluation:" in capsys.readouterr().out
    assert (tmp_path / "sb3_eval" / "evaluations.npz").exists()


def test_envs_made_alike_share_their_goal():
    """The SB3 pitfall: a training and an evaluation env made alike must face the same goal."""
    goals = []
    for reset_seed in (0, 1, None):
        env = gym.make("HippoMaze-v0", maze="maze2", n_rays=8, goal_seed=4)
        _, info = env.reset(seed=reset_seed)
        goals.append(info["goal"])
        env.close()
    np.testing.assert_array_equal(goals[0], goals[1])
    np.testing.assert_array_equal(goals[0], goals[2])
    other = gym.make("HippoMaze-v0", maze="maze2", n_rays=8, goal_seed=5)
    assert not np.array_equal(other.reset(seed=0)[1]["goal"], goals[0])
    other.close()


def test_goal_argument_and_its_errors():
    env = gym.make("HippoMaze-v0", maze="maze1", n_rays=8, goal=[3.0, 3.0])
    _, info = env.reset(seed=0)
    np.testing.assert_array_equal(info["goal"], [3.0, 3.0])
    _, info = env.reset(seed=9)  # the goal is held across resets (DMTP) ...
    np.testing.assert_array_equal(info["goal"], [3.0, 3.0])
    _, info = env.reset(options={"new_goal": True})  # ... until moved
    assert not np.array_equal(info["goal"], [3.0, 3.0])
    env.close()
    with pytest.raises(ValueError, match="either goal=\\[x, y\\] or goal_seed=int, not both"):
        gym.make("HippoMaze-v0", goal=[1.0, 1.0], goal_seed=0)
    with pytest.raises(ValueError, match="argument 'goal' \\(-3, 1.5\\) is inside a wall"):
        gym.make("HippoMaze-v0", maze="maze1", goal=[-3.0, 1.5])
    with pytest.raises(ValueError, match="goal_seed must be a non-negative integer"):
        gym.make("HippoMaze-v0", goal_seed=-1)


def test_without_goal_arguments_nothing_changes():
    """The default is as before: the first reset draws the goal with its own seed."""
    a = gym.make("HippoMaze-v0", maze="maze1", n_rays=8)
    b = gym.make("HippoMaze-v0", maze="maze1", n_rays=8)
    assert not np.array_equal(a.reset(seed=0)[1]["goal"], b.reset(seed=1)[1]["goal"])
    np.testing.assert_array_equal(
        a.reset(seed=0, options={"new_goal": True})[1]["goal"], b.reset(seed=0, options={"new_goal": True})[1]["goal"]
    )
    a.close()
    b.close()
