"""Reference agents behind the same Agent protocol as the hippocampal agent (see
:mod:`hippo_env.agent_protocol`), installed as ``hippomaze.baselines``.

- :class:`RandomAgent`: a uniformly random action every step.
- :class:`DQNAgent`, :class:`PPOAgent`: stable-baselines3, learning online (need the ``baselines``
  extra; imported lazily).
- :class:`DynaQAgent`: tabular Dyna-Q on the true position, a PRIVILEGED reference.

Build any of them by name with :func:`hippomaze.registry.agent_factory`.
"""

from typing import Any

from .random_agent import RandomAgent

__all__ = ["DQNAgent", "DynaQAgent", "PPOAgent", "RandomAgent"]


def __getattr__(name: str) -> Any:
    if name in ("DQNAgent", "PPOAgent"):
        from . import sb3_agents

        return getattr(sb3_agents, name)
    if name == "DynaQAgent":
        from .dynaq import DynaQAgent

        return DynaQAgent
    raise AttributeError(f"module 'hippomaze.baselines' has no attribute {name!r}")
