"""hippo_agent: the hippocampal place-cell navigation model as a policy object.

>>> from hippo_agent import HippocampalAgent, AgentConfig
>>> agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(), seed=0)

``AgentConfig()`` is the default model (the paper's model plus its faculties), ``AgentConfig.paper()``
the paper's model.
"""

from hippo_agent.agent import HippocampalAgent
from hippo_agent.config import (
    AgentConfig,
    ExplorationConfig,
    HomingConfig,
    LocalisationConfig,
    MapConfig,
    ModelConfig,
    PathIntegrationConfig,
    ReflexConfig,
    WorldsConfig,
)
from hippo_agent.paper_model import PaperModel
from hippo_env import __version__ as __version__

__all__ = [
    "AgentConfig",
    "ExplorationConfig",
    "HippocampalAgent",
    "HomingConfig",
    "LocalisationConfig",
    "MapConfig",
    "ModelConfig",
    "PaperModel",
    "PathIntegrationConfig",
    "ReflexConfig",
    "WorldsConfig",
]
