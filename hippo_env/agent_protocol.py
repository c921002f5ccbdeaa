"""The Agent protocol: what every hippomaze agent is, for the DMTP runner (:mod:`hippo_env.dmtp`).

An agent is any object with these methods (structural typing: no base class needed; subclass
:class:`AgentBase` to get the optional hooks as no-ops)::

    class MyAgent:
        def __init__(self, observation_space, action_space, seed=None): ...
        def reset(self, observation, info) -> None: ...   # a run begins
        def act(self, observation): ...                   # an action from env.action_space
        def observe(self, action, observation, reward, terminated, truncated, info) -> None: ...
        # optional:
        def dry_run(self, env) -> None: ...               # the dry run, with no goal
        def start_trial(self, trial: int) -> None: ...    # a new trial: the goal has moved

When each is called, for every trial of a DMTP experiment:

1. the agent is built (a fresh one per trial unless the runner is told otherwise) and, if it has
   ``dry_run``, given the environment with no goal in it for its dry run;
2. ``start_trial(trial)``: the goal has moved;
3. for each run: ``reset(observation, info)``, then ``act`` / ``observe`` for every step until the
   run ends (the goal reached, or the step limit).

``dry_run`` receives the environment with no goal in it (``info["goal"]`` is NaN, nothing
terminates) and may step and reset it as often as it likes; every one of those steps counts in
``env_steps_total``. An agent that claims to navigate from its senses reads, of ``info``, only
``is_success``, ``collision``, ``heading`` and ``sim_time``; not ``position``, ``goal``,
``path_length``, ``shortest_path_length`` or ``indirectness``. The runner does not hide them, so
that privileged reference agents can be written too (label them so).
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import gymnasium as gym

#: The methods without which an object is not an agent.
REQUIRED_METHODS = ("reset", "act", "observe")


@runtime_checkable
class Agent(Protocol):
    """Every method the runner may call; ``dry_run`` and ``start_trial`` are optional (the runner
    calls them only if the agent has them), so ``isinstance`` checks the three required ones."""

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        """A run begins at ``observation``."""

    def act(self, observation: Any) -> Any:
        """The action to take, from the environment's action space."""

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        """What ``action`` led to."""


class AgentBase:
    """A convenience base class: the optional hooks as no-ops, the required methods to write."""

    def __init__(self, observation_space: gym.spaces.Space, action_space: gym.spaces.Space, seed: int | None = None) -> None:
        self.observation_space = observation_space
        self.action_space = action_space
        self.seed = seed

    def dry_run(self, env: gym.Env) -> None:
        """The dry run: exploration with no goal in ``env`` (optional; does nothing here)."""

    def start_trial(self, trial: int) -> None:
        """A new trial: the goal has moved (optional; does nothing here)."""

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        raise NotImplementedError

    def act(self, observation: Any) -> Any:
        raise NotImplementedError

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        raise NotImplementedError


class AgentFactory(Protocol):
    """What the runner builds agents with: ``factory(observation_space, action_space, seed=seed)``.

    An agent class whose constructor takes ``seed`` is one. A factory may carry an ``env_kwargs``
    attribute: the sensors its agent needs (e.g. ``{"odometry": True}``).
    """

    def __call__(self, observation_space: gym.spaces.Space, action_space: gym.spaces.Space, *, seed: int) -> Any: ...


def missing_methods(agent_or_class: Any) -> list[str]:
    """The required methods ``agent_or_class`` lacks (empty if it follows the protocol)."""
    return [m for m in REQUIRED_METHODS if not callable(getattr(agent_or_class, m, None))]


__all__ = ["REQUIRED_METHODS", "Agent", "AgentBase", "AgentFactory", "missing_methods"]
