"""hippomaze, the application: the ``hippomaze`` console script, the agent registry and the DMTP
report and figures, which serve any agent that follows the Agent protocol (``hippo_env``).

The public API is the registry: :func:`agent_factory` builds agents by name (:data:`AGENT_NAMES`,
``module:Class``, or an entry point), :func:`load_agent` imports ``module:Class``.
"""

from hippo_env import __version__ as __version__
from hippomaze.registry import AGENT_NAMES, agent_factory, load_agent

__all__ = ["AGENT_NAMES", "agent_factory", "load_agent"]
