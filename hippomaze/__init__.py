"""hippomaze, the application: the ``hippomaze`` console script, the agent registry and the DMTP
report and figures, which serve any agent that follows the Agent protocol (``hippo_env``)."""

from hippo_env import __version__ as __version__
