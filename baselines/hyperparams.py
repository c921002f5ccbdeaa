"""Every hyperparameter of the baselines, in one documented place.

Sources
-------
The starting points are the published rl-baselines3-zoo settings
(https://github.com/DLR-RM/rl-baselines3-zoo, ``hyperparams/dqn.yml`` and ``hyperparams/ppo.yml``):

- PPO: the zoo's MiniGrid block (``MiniGrid-DoorKey-5x5-v0`` / ``MiniGrid-FourRooms-v0``, "following
  rl-starter-files"), the zoo's only small sparse-reward navigation tasks: ``n_steps`` 128 x 8 envs,
  ``batch_size`` 64, ``gae_lambda`` 0.95, ``gamma`` 0.99, ``n_epochs`` 10, ``ent_coef`` 0.0,
  ``learning_rate`` 2.5e-4, ``clip_range`` 0.2, ``normalize: true``. Our agents learn online from
  one environment (the DMTP runner drives a single robot), so a rollout is ``n_steps = 1024``
  steps of that one env: the same 1024 transitions per update as 128 x 8.
- DQN: the zoo has no DQN entry for a navigation task; its tuned ``MountainCar-v0`` entry (a
  sparse-reward, exploration-bound control task with a small discrete action set) is the closest:
  ``learning_rate`` 4e-3, ``batch_size`` 128, ``buffer_size`` 10,000, ``learning_starts`` 1000,
  ``gamma`` 0.98, ``target_update_interval`` 600, ``train_freq`` 16, ``gradient_steps`` 8,
  ``exploration_fraction`` 0.2, ``exploration_final_eps`` 0.07, ``net_arch`` [256, 256].

What the zoo's ``normalize: true`` (a running ``VecNormalize``) does is done here by a fixed,
non-learned scaling: the scan is divided by ``max_range`` so every input lies in [0, 1].

Observation
-----------
The baselines get exactly the hippocampal agent's observation, ``Dict(ranges, heading)``, turned into
one flat vector by :class:`hippomaze.baselines.sb3_agents.ScanFeatures` (the brief allows "flattened"):

- ``allocentric=True`` rotates the egocentric scan by the compass heading so that bin ``j`` looks
  along the world direction ``2*pi*j/n_bins``. This is the same use of the compass that the
  hippocampal model's head-direction -> boundary-vector layer makes; it does not add information,
  it only saves the network from learning the rotation.
- ``n_bins`` mean-pools the 720 rays into ``n_bins`` equal sectors (720 -> 90: 4 degrees each).
- The (cos, sin) heading is appended.

Trial structure and the goal switch
-----------------------------------
The agents learn online from every ``observe`` call during one long DMTP trial (``n_timesteps``
sets the length of the schedules: DQN's epsilon decay and any ``lin_`` schedule). When the goal
moves (``start_trial`` after experience, the same signal the hippocampal agent gets) and
``reset_on_new_goal`` is true, DQN empties its replay buffer (its rewards belong to the old goal)
and restarts its warm-up and epsilon schedule over ``switch_timesteps`` steps, keeping its network;
PPO drops its partial rollout. This is the generous choice: the learners are told, as the
hippocampal agent is, that the goal has moved.

The tuning sweep
----------------
``python -m benchmarks.sample_efficiency --sweep --out benchmarks/results`` (see :data:`SWEEP` for the grid and
``docs/baselines.md`` for its outcome and what it taught). Run on ``open`` with the sparse reward, 100,000
steps, seeds 100 and 101 (not the benchmark's seeds 0-4), scored by the number of steps to the
criterion (median indirectness <= 1 with >= 90 % success over a window of 10 runs) and, failing
that, by the success rate of the last 50 runs. The defaults below are the winners.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any, Literal, overload

from hippo_env.files import unknown_fields


@dataclass(frozen=True)
class _OnlineParams:
    """The fields DQN and PPO share (each documents them for itself)."""

    net_arch: tuple[int, ...] = (64, 64)
    n_bins: int = 90
    allocentric: bool = True
    n_timesteps: int = 300_000
    reset_on_new_goal: bool = True
    switch_timesteps: int = 100_000


@dataclass(frozen=True)
class DQNParams(_OnlineParams):
    """DQN (stable-baselines3 ``DQN`` with ``MlpPolicy``) driven online; see the module doc for sources.

    Args:
        learning_rate: Adam step size (zoo MountainCar-v0: 4e-3).
        buffer_size: Replay buffer capacity in transitions (zoo: 10,000).
        learning_starts: Uniformly random actions, and no training, for this many steps (zoo: 1000).
        batch_size: Transitions per gradient step (zoo: 128).
        gamma: Discount factor (zoo: 0.98).
        target_update_interval: Steps between hard target-network updates (zoo: 600).
        train_freq: Environment steps between training phases (zoo: 16).
        gradient_steps: Gradient steps per training phase (zoo MountainCar: 8; zoo CartPole / Acrobot,
            also tuned: 4 per 16 steps, chosen here: see the sweep).
        exploration_fraction: Fraction of ``n_timesteps`` over which epsilon decays (zoo: 0.2).
        exploration_initial_eps: Epsilon at the start (SB3 default: 1.0).
        exploration_final_eps: Epsilon after the decay (zoo: 0.07).
        max_grad_norm: Gradient clipping (SB3 default: 10).
        net_arch: Hidden layer sizes of the Q-network (SB3 default [64, 64]; the zoo's [256, 256] is
            in the sweep; it costs several times the compute per gradient step).
        n_bins: Sectors the 720-ray scan is mean-pooled into (720 = no pooling).
        allocentric: Rotate the scan into the world frame with the compass heading.
        n_timesteps: Steps over which the schedules run (the benchmark sets it to its budget).
        reset_on_new_goal: On a goal switch, empty the replay buffer and restart the warm-up and the
            epsilon schedule (over ``switch_timesteps``), keeping the network.
        switch_timesteps: Length of the restarted schedule after a goal switch.
    """

    learning_rate: float = 4e-3
    buffer_size: int = 10_000
    learning_starts: int = 1000
    batch_size: int = 128
    gamma: float = 0.98
    target_update_interval: int = 600
    train_freq: int = 16
    gradient_steps: int = 4
    exploration_fraction: float = 0.2
    exploration_initial_eps: float = 1.0
    exploration_final_eps: float = 0.07
    max_grad_norm: float = 10.0


@dataclass(frozen=True)
class PPOParams(_OnlineParams):
    """PPO (stable-baselines3 ``PPO`` with ``MlpPolicy``) driven online; see the module doc for sources.

    Args:
        learning_rate: Adam step size (zoo MiniGrid: 2.5e-4).
        n_steps: Transitions per rollout (zoo MiniGrid: 128 x 8 envs = 1024).
        batch_size: Minibatch size (zoo MiniGrid: 64; zoo Atari: 256, chosen here: see the sweep).
        n_epochs: Passes over each rollout (zoo: 10).
        gamma: Discount factor (zoo: 0.99).
        gae_lambda: GAE lambda (zoo: 0.95).
        clip_range: PPO clipping (zoo: 0.2).
        ent_coef: Entropy bonus (zoo: 0.0).
        vf_coef: Value loss weight (SB3 default: 0.5).
        max_grad_norm: Gradient clipping (SB3 default: 0.5).
        normalize_advantage: Scale each minibatch's advantages to unit variance (SB3 default: True).
        zero_init_critic: Start the value head at zero weights and bias (SB3: orthogonal, gain 1).
            Before the first reward every return is 0, and a randomly initialised critic's output
            acts as a potential that the policy climbs: it drifts to one side of the arena and is
            pinned against a wall long before a random walk would have found the goal (see the sweep).
            A zero critic predicts those returns exactly, so the advantages are 0 and the policy
            stays uniform until the goal is found.
        net_arch: Hidden layer sizes of the policy and value networks (SB3 default: [64, 64]).
        n_bins: Sectors the 720-ray scan is mean-pooled into (720 = no pooling).
        allocentric: Rotate the scan into the world frame with the compass heading.
        n_timesteps: Steps over which any schedule runs (the benchmark sets it to its budget).
        reset_on_new_goal: On a goal switch, drop the partial rollout (it mixes two goals).
        switch_timesteps: Unused by PPO (constant schedules); kept so both agents take the same keys.
    """

    learning_rate: float = 2.5e-4
    n_steps: int = 1024
    batch_size: int = 256
    n_epochs: int = 10
    gamma: float = 0.99
    gae_lambda: float = 0.95
    clip_range: float = 0.2
    ent_coef: float = 0.0
    vf_coef: float = 0.5
    max_grad_norm: float = 0.5
    normalize_advantage: bool = True
    zero_init_critic: bool = True


@dataclass(frozen=True)
class DynaQParams:
    """Tabular Dyna-Q on a grid over the arena: the PRIVILEGED reference (it reads ``info["position"]``).

    Sutton & Barto (2018), section 8.2, "Tabular Dyna-Q", with an epsilon-greedy behaviour policy
    and optimistic initial values; the settings tried are recorded in ``docs/baselines.md``.

    Args:
        cell: Grid cell size in metres (a discrete step moves 0.15 m).
        alpha: Q-learning step size.
        gamma: Discount factor.
        epsilon: Exploration probability.
        planning_steps: Simulated updates from the learned model per real step (Sutton & Barto: n).
        q_init: Initial action value; above 0 it is "optimistic" and drives systematic exploration
            (Sutton & Barto section 2.6).
        keep_model_on_new_goal: On a goal switch keep the learned transitions (the map) and forget
            only rewards and values; otherwise start from scratch.
    """

    cell: float = 0.25
    alpha: float = 0.5
    gamma: float = 0.98
    epsilon: float = 0.02
    planning_steps: int = 30
    q_init: float = 0.5
    keep_model_on_new_goal: bool = True


PARAMS = {"dqn": DQNParams, "ppo": PPOParams, "dynaq": DynaQParams}


@overload
def make_params(agent: Literal["dqn"], **overrides: Any) -> DQNParams: ...
@overload
def make_params(agent: Literal["ppo"], **overrides: Any) -> PPOParams: ...
@overload
def make_params(agent: Literal["dynaq"], **overrides: Any) -> DynaQParams: ...
@overload
def make_params(agent: str, **overrides: Any) -> DQNParams | PPOParams | DynaQParams: ...
def make_params(agent: str, **overrides: Any) -> DQNParams | PPOParams | DynaQParams:
    """The default parameters of ``agent`` (``dqn``, ``ppo``, ``dynaq``) with ``overrides`` applied.

    Raises:
        ValueError: An unknown agent or an unknown parameter name.
    """
    if agent not in PARAMS:
        raise ValueError(f"no hyperparameters for agent {agent!r}; known: {', '.join(PARAMS)}")
    cls = PARAMS[agent]
    unknown = unknown_fields(cls, overrides)
    if unknown:
        allowed = sorted(f.name for f in fields(cls))
        raise ValueError(f"{cls.__name__} has no parameter(s) {', '.join(unknown)}; allowed: {', '.join(allowed)}")
    if "net_arch" in overrides:
        overrides["net_arch"] = tuple(int(v) for v in overrides["net_arch"])
    return replace(cls(), **overrides)


def params_dict(params: Any) -> dict[str, Any]:
    """A JSON-ready dict of a params dataclass."""
    out = asdict(params)
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in out.items()}


@dataclass(frozen=True)
class SweepPoint:
    """One configuration of the tuning sweep: an agent, the overrides tried, the seeds it ran with."""

    name: str
    agent: str
    overrides: dict[str, Any] = field(default_factory=dict)
    seeds: tuple[int, ...] = (100, 101)


#: The tuning sweep that was run (open, sparse, 100,000 steps; seeds 100 and 101, not the benchmark's).
SWEEP: tuple[SweepPoint, ...] = (
    SweepPoint("dqn-zoo", "dqn", {"gradient_steps": 8}),
    SweepPoint("dqn-grad4", "dqn", {"gradient_steps": 4}),
    SweepPoint("dqn-grad4-egocentric", "dqn", {"gradient_steps": 4, "allocentric": False}, seeds=(100,)),
    SweepPoint("ppo-zoo", "ppo", {"batch_size": 64, "zero_init_critic": False}),
    SweepPoint("ppo-batch256", "ppo", {"batch_size": 256, "zero_init_critic": False}),
    SweepPoint("ppo-ent0.01", "ppo", {"batch_size": 64, "ent_coef": 0.01, "zero_init_critic": False}, seeds=(100,)),
    SweepPoint("ppo-raw-advantage", "ppo", {"normalize_advantage": False, "zero_init_critic": False}),
    SweepPoint(
        "ppo-raw-advantage-ent0.01", "ppo", {"normalize_advantage": False, "ent_coef": 0.01, "zero_init_critic": False}, seeds=(100,)
    ),
    SweepPoint("ppo-zero-critic", "ppo", {"batch_size": 256, "zero_init_critic": True}),
    SweepPoint("ppo-zero-critic-batch64", "ppo", {"batch_size": 64, "zero_init_critic": True}),
)

__all__ = ["PARAMS", "SWEEP", "DQNParams", "DynaQParams", "PPOParams", "SweepPoint", "make_params", "params_dict"]
