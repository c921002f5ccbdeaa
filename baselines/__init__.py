"""Reference agents behind the same Agent protocol as the hippocampal agent (see hippo_env.protocol)."""

from baselines.random_agent import RandomAgent

__all__ = ["RandomAgent"]
