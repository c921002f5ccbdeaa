"""The random agent: a uniformly random action every step (the floor every agent must beat)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np


class RandomAgent:
    """Draws each action uniformly from the action space with its own seeded generator.

    Args:
        observation_space: The environment's observation space (unused).
        action_space: The space actions are drawn from.
        seed: Seeds the draws.
    """

    def __init__(self, observation_space: gym.spaces.Space, action_space: gym.spaces.Space, seed: int | None = None) -> None:
        self.action_space = action_space
        self.rng = np.random.default_rng(seed)

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        pass

    def act(self, observation: Any) -> Any:
        space = self.action_space
        if isinstance(space, gym.spaces.Discrete):
            return int(space.start + self.rng.integers(space.n))
        if isinstance(space, gym.spaces.Box):
            return self.rng.uniform(space.low, space.high).astype(space.dtype)
        raise ValueError(f"RandomAgent supports Discrete and Box action spaces, got {space}")

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        pass
