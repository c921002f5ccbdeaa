"""hippo_env: a Gymnasium Morris water maze (DMTP) for a simulated iRobot Create 2.

``import hippo_env`` registers ``HippoMaze-v0``::

    import gymnasium as gym
    import hippo_env

    env = gym.make("HippoMaze-v0", maze="maze1")

The public API: the environment (:class:`HippoMazeEnv`), mazes (:class:`MazeSpec`,
:func:`generate_maze`), the Agent protocol every agent follows (:class:`Agent`,
:class:`AgentBase`, :class:`AgentFactory`) and the DMTP runner (:func:`run_dmtp`, its
:class:`DMTPResult` of :class:`Run` records, and :func:`rollout`, the loop it drives agents with).
"""

from gymnasium.envs.registration import WrapperSpec, register, registry

from hippo_env.agent_protocol import Agent, AgentBase, AgentFactory
from hippo_env.dmtp import DMTPFailed, DMTPInterrupted, DMTPResult, Run, rollout, run_dmtp
from hippo_env.env import HippoMazeEnv
from hippo_env.files import atomic_write, write_json
from hippo_env.generate import generate_maze
from hippo_env.maze import BUILTIN_MAZES, MazeSpec

__all__ = [
    "BUILTIN_MAZES",
    "Agent",
    "AgentBase",
    "AgentFactory",
    "DMTPFailed",
    "DMTPInterrupted",
    "DMTPResult",
    "HippoMazeEnv",
    "MazeSpec",
    "Run",
    "atomic_write",
    "generate_maze",
    "rollout",
    "run_dmtp",
    "write_json",
]
__version__ = "0.26.0"  # the distribution's one version (pyproject.toml reads it)

if "HippoMaze-v0" not in registry:
    register(
        id="HippoMaze-v0",
        entry_point="hippo_env.env:HippoMazeEnv",
        max_episode_steps=10_000,
        additional_wrappers=(WrapperSpec("EpisodeEndInfo", "hippo_env.env:EpisodeEndInfo", {}),),
    )
