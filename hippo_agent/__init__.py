"""hippo_agent: the hippocampal place-cell navigation model as a policy object.

>>> from hippo_agent import HippocampalAgent, AgentConfig
>>> agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(), seed=0)
"""

from hippo_agent.agent import HippocampalAgent
from hippo_agent.config import AgentConfig
from hippo_env import __version__ as __version__

__all__ = ["AgentConfig", "HippocampalAgent"]
