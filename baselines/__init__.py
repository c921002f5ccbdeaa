"""Reference agents behind the same Agent protocol as the hippocampal agent (see hippo_env.protocol).

- :class:`RandomAgent`: a uniformly random action every step.
- :class:`DQNAgent`, :class:`PPOAgent`: stable-baselines3, learning online (need the ``baselines``
  extra; imported lazily).
- :class:`DynaQAgent`: tabular Dyna-Q on the true position, a PRIVILEGED reference.
- :func:`agent_factory`: any of these (or ``hippo``, or ``module:Class``) by name.
"""

from typing import Any

from baselines.random_agent import RandomAgent
from baselines.registry import AGENT_NAMES, agent_factory

__all__ = ["AGENT_NAMES", "DQNAgent", "DynaQAgent", "PPOAgent", "RandomAgent", "agent_factory"]


def __getattr__(name: str) -> Any:
    if name in ("DQNAgent", "PPOAgent"):
        from baselines import sb3_agents

        return getattr(sb3_agents, name)
    if name == "DynaQAgent":
        from baselines.dynaq import DynaQAgent

        return DynaQAgent
    raise AttributeError(f"module 'baselines' has no attribute {name!r}")
