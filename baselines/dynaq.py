"""PRIVILEGED reference: tabular Dyna-Q on a grid over the arena, given the robot's true position.

This agent does **not** navigate from its senses: it reads ``info["position"]`` (the true (x, y))
and ignores the rangefinder. It shows what a classical planner with a perfect localiser and a
learned map does on the same protocol, and is labelled ``dynaq (privileged)`` in every table.

Algorithm: Sutton & Barto (2018), section 8.2, "Tabular Dyna-Q": Q-learning on each real
transition, plus ``planning_steps`` simulated Q-learning updates per real step from a learned
deterministic model (the last ``(reward, next cell, terminal)`` seen for each (cell, action)).
The state is the grid cell of the position; actions are the env's ``Discrete(8)`` headings.
On a goal switch the model's transitions (the map) are kept and only rewards and values are
forgotten (``keep_model_on_new_goal``), the analogue of the hippocampal agent keeping its
place-cell map and starting a new reward cell.
"""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np

from .hyperparams import DynaQParams, make_params, params_dict


class DynaQAgent:
    """Tabular Dyna-Q on the true position (PRIVILEGED: reads ``info["position"]``).

    Args:
        observation_space: The env's observation space (unused: this agent reads the position).
        action_space: ``Discrete(n)``.
        seed: Seeds the epsilon-greedy draws, tie-breaking and planning samples.
        params: A :class:`~hippomaze.baselines.hyperparams.DynaQParams`; ``None`` = the defaults.
        **overrides: Fields of ``DynaQParams`` to change.
    """

    privileged = True

    def __init__(
        self,
        observation_space: gym.spaces.Space,
        action_space: gym.spaces.Space,
        seed: int | None = None,
        params: DynaQParams | None = None,
        **overrides: Any,
    ) -> None:
        if not isinstance(action_space, gym.spaces.Discrete):
            raise TypeError(f"DynaQAgent needs a Discrete action space (action_type='discrete'), got {action_space}")
        self.params = make_params("dynaq", **overrides) if params is None else make_params("dynaq", **{**params_dict(params), **overrides})
        self.n_actions = int(action_space.n)
        self.rng = np.random.default_rng(seed)
        self.cells: dict[tuple[int, int], int] = {}  # grid cell -> state index, grown as cells are visited
        n = 256
        self.q = np.full((n, self.n_actions), self.params.q_init)
        self.known = np.zeros((n, self.n_actions), bool)  # model entries seen
        self.next_state = np.zeros((n, self.n_actions), np.int64)
        self.reward = np.zeros((n, self.n_actions))
        self.terminal = np.zeros((n, self.n_actions), bool)
        self.visited: list[int] = []  # flat (state * n_actions + action) indices with a model entry
        self.state = 0
        self.num_timesteps = 0

    def config(self) -> dict[str, Any]:
        """The hyperparameters in force, as a JSON-ready dict."""
        return params_dict(self.params)

    def _cell(self, position: Any) -> int:
        key = (math.floor(float(position[0]) / self.params.cell), math.floor(float(position[1]) / self.params.cell))
        index = self.cells.get(key)
        if index is None:
            index = self.cells[key] = len(self.cells)
            if index >= self.q.shape[0]:  # grow every table
                for name in ("q", "known", "next_state", "reward", "terminal"):
                    table = getattr(self, name)
                    setattr(self, name, np.concatenate([table, np.full_like(table, self.params.q_init if name == "q" else 0)]))
        return index

    def start_trial(self, trial: int) -> None:
        """The goal moved: forget rewards and values; keep the transitions if configured."""
        if self.num_timesteps == 0:
            return
        self.q[:] = self.params.q_init
        self.reward[:] = 0.0
        self.terminal[:] = False
        if not self.params.keep_model_on_new_goal:
            self.known[:] = False
            self.visited = []

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        self.state = self._cell(info["position"])

    def act(self, observation: Any) -> int:
        if self.rng.random() < self.params.epsilon:
            return int(self.rng.integers(self.n_actions))
        q = self.q[self.state]
        best = np.flatnonzero(q == q.max())
        return int(best[self.rng.integers(best.size)])

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        p = self.params
        s, a, s2 = self.state, int(action), self._cell(info["position"])
        self._update(s, a, float(reward), s2, bool(terminated))
        if not self.known[s, a]:
            self.known[s, a] = True
            self.visited.append(s * self.n_actions + a)
        self.next_state[s, a], self.reward[s, a], self.terminal[s, a] = s2, float(reward), bool(terminated)
        if p.planning_steps and self.visited:
            picks = self.rng.integers(len(self.visited), size=p.planning_steps).tolist()
            for i in picks:  # sequential, as in the algorithm: each update builds on the last
                ps, pa = divmod(self.visited[i], self.n_actions)
                self._update(ps, pa, float(self.reward[ps, pa]), int(self.next_state[ps, pa]), bool(self.terminal[ps, pa]))
        self.state = s2
        self.num_timesteps += 1

    def _update(self, s: int, a: int, r: float, s2: int, term: bool) -> None:
        """One Q-learning update (Sutton & Barto eq. 6.8)."""
        target = r if term else r + self.params.gamma * float(self.q[s2].max())
        self.q[s, a] += self.params.alpha * (target - self.q[s, a])


__all__ = ["DynaQAgent"]
