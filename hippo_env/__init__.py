"""hippo_env: a Gymnasium Morris water maze (DMTP) for a simulated iRobot Create 2.

``import hippo_env`` registers ``HippoMaze-v0``::

    import gymnasium as gym
    import hippo_env

    env = gym.make("HippoMaze-v0", maze="maze1")
"""

from gymnasium.envs.registration import WrapperSpec, register, registry

from hippo_env.env import HippoMazeEnv
from hippo_env.files import atomic_write, write_json
from hippo_env.maze import BUILTIN_MAZES, MazeSpec

__all__ = ["BUILTIN_MAZES", "HippoMazeEnv", "MazeSpec", "atomic_write", "write_json"]
__version__ = "0.1.0"  # the distribution's one version (pyproject.toml reads it)

if "HippoMaze-v0" not in registry:
    register(
        id="HippoMaze-v0",
        entry_point="hippo_env.env:HippoMazeEnv",
        max_episode_steps=10_000,
        additional_wrappers=(WrapperSpec("EpisodeEndInfo", "hippo_env.env:EpisodeEndInfo", {}),),
    )
