"""Stable-Baselines3 DQN and PPO behind the Agent protocol, learning online while the runner drives them.

How SB3 is driven
-----------------
SB3's ``learn()`` owns the environment loop; the DMTP runner owns it here. The two agents therefore
reimplement the *collection* side of ``learn()`` and call SB3 for everything else:

- :class:`DQNAgent`: each ``observe`` adds the transition to SB3's ``ReplayBuffer`` (with the
  ``TimeLimit.truncated`` flag, so a time-out is not a terminal state), copies the Q-network into
  the target network every ``target_update_interval`` steps (SB3's public ``polyak_update``) and
  sets epsilon from DQN's ``exploration_schedule``, as ``DQN`` does after each step of its own
  loop; every ``train_freq`` steps after ``learning_starts`` it calls
  ``DQN.train(gradient_steps, batch_size)``, exactly as ``OffPolicyAlgorithm.learn`` /
  ``collect_rollouts`` do for one environment.
- :class:`PPOAgent`: each ``act`` evaluates SB3's ``ActorCriticPolicy`` (action, value, log-prob),
  each ``observe`` adds to SB3's ``RolloutBuffer`` (bootstrapping a time-out with the value of the
  last observation, as ``OnPolicyAlgorithm.collect_rollouts`` does); after ``n_steps`` it calls
  ``compute_returns_and_advantage`` and ``PPO.train()``.

Only SB3's public API is used: the progress through a schedule, which SB3 keeps privately and
updates only inside ``learn()``, is computed here; the learning rate and PPO's clip range are
constants (floats in :mod:`hippomaze.baselines.hyperparams`), so ``train()`` does not read it.

Acting goes through a NumPy copy of the torch network (:class:`_NumpyMLP`, refreshed after every
training phase): one observation at a time, torch's per-call overhead costs more than the
environment step, and the copy computes the same function.

Why not ``learn()`` in a thread against a proxy environment: this way there are no threads, no
hand-over protocol, nothing to deadlock when a run is cut by the step budget, and the agent never
needs to know when the runner will stop.

Determinism: ``torch.set_num_threads(1)``; each agent draws its actions from its own
``numpy.random.Generator``; SB3's own uses of the global NumPy / torch / ``random`` generators
(network initialisation, replay sampling, minibatch shuffling) run inside :class:`_OwnRandomState`,
which swaps in the agent's private copy of those states. Same seed -> same numbers, whatever else
runs in the process.
"""

from __future__ import annotations

import math
import random
from typing import Any

import gymnasium as gym
import numpy as np

from .hyperparams import DQNParams, PPOParams, make_params, params_dict

INSTALL_HINT = (
    "pip install torch==2.13.0 && pip install 'hippomaze[baselines]' (torch first: it is the CPU build, a bare torch "
    "requirement pulls CUDA wheels); in a checkout of the repository: pip install torch==2.13.0 && pip install -e .[baselines]"
)


def _import_sb3():
    """Import torch and stable-baselines3 lazily, with an error that names the extra."""
    try:
        import stable_baselines3
        import torch
    except ImportError as err:  # pragma: no cover - exercised only without the extra
        raise ImportError(
            f"the DQN and PPO baselines need torch and stable-baselines3 (the 'baselines' extra): {INSTALL_HINT} ({err})"
        ) from err
    return torch, stable_baselines3


class ScanFeatures:
    """Turns the ``Dict(ranges, heading)`` observation into one flat float32 vector.

    Args:
        observation_space: The environment's ``Dict(ranges=Box, heading=Box)`` space.
        n_bins: Equal angular sectors the rays are mean-pooled into (must divide the ray count).
        allocentric: Rotate the scan by the compass heading so that bin ``j`` looks along the
            world direction ``2*pi*j/n_bins`` (see :mod:`hippomaze.baselines.hyperparams`).
    """

    def __init__(self, observation_space: gym.spaces.Space, n_bins: int = 90, allocentric: bool = True) -> None:
        if not isinstance(observation_space, gym.spaces.Dict):
            raise TypeError(f"the baselines need the HippoMaze observation Dict(ranges=Box, heading=Box), got {observation_space}")
        if not {"ranges", "heading"} <= set(observation_space.spaces):
            raise ValueError(f"the baselines need the HippoMaze observation Dict(ranges=Box, heading=Box), got {observation_space}")
        ranges = observation_space["ranges"]
        if not isinstance(ranges, gym.spaces.Box):
            raise TypeError(f"the baselines need the HippoMaze observation Dict(ranges=Box, heading=Box), got {observation_space}")
        self.n_rays = int(ranges.shape[0])
        if n_bins < 1 or self.n_rays % n_bins:
            raise ValueError(f"n_bins={n_bins} must divide the number of rays ({self.n_rays}); e.g. 90, 180 or {self.n_rays}")
        self.n_bins = int(n_bins)
        self.allocentric = bool(allocentric)
        self.max_range = float(np.max(ranges.high))
        self.space = gym.spaces.Box(-1.0, 1.0, (self.n_bins + 2,), np.float32)

    def __call__(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        ranges = np.asarray(observation["ranges"], np.float32) / self.max_range
        heading = np.asarray(observation["heading"], np.float32)
        if self.allocentric:
            # ranges[i] looks along heading + 2*pi*i/n; world bin j = i + shift.
            shift = round(math.atan2(float(heading[1]), float(heading[0])) / (2 * math.pi) * self.n_rays) % self.n_rays
            ranges = np.roll(ranges, shift)
        if self.n_bins != self.n_rays:
            ranges = ranges.reshape(self.n_bins, -1).mean(axis=1)
        return np.concatenate([ranges, heading]).astype(np.float32)


class _SpacesEnv(gym.Env):
    """A stand-in that only carries the spaces SB3 builds its networks and buffers from."""

    def __init__(self, observation_space: gym.spaces.Space, action_space: gym.spaces.Space) -> None:
        self.observation_space = observation_space
        self.action_space = action_space

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        raise RuntimeError("the baselines are driven by the DMTP runner; SB3's own environment loop is not used")

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        raise RuntimeError("the baselines are driven by the DMTP runner; SB3's own environment loop is not used")


class _OwnRandomState:
    """Swap the global ``random`` / NumPy / torch generator states for an agent's private ones.

    SB3 draws from the global generators (replay sampling, exploration), so each agent keeps its
    own seeded copies and swaps them in only while SB3 runs; the caller's states are restored.
    """

    def __init__(self, torch_module: Any, seed: int) -> None:
        self.torch = torch_module
        # The states the global generators would have if seeded with ``seed``, made without touching them.
        self.state = (
            random.Random(seed).getstate(),
            np.random.RandomState(seed % 2**32).get_state(),
            torch_module.Generator().manual_seed(seed).get_state(),
        )
        self._outer: tuple | None = None

    def _get(self) -> tuple:
        return random.getstate(), np.random.get_state(), self.torch.get_rng_state()

    def _set(self, state: tuple) -> None:
        random.setstate(state[0])
        np.random.set_state(state[1])
        self.torch.set_rng_state(state[2])

    def __enter__(self) -> _OwnRandomState:  # noqa: PYI034
        self._outer = self._get()
        self._set(self.state)
        return self

    def __exit__(self, *exc: object) -> None:
        self.state = self._get()
        assert self._outer is not None
        self._set(self._outer)
        self._outer = None


class _NumpyMLP:
    """A NumPy copy of a torch ``Sequential`` of Linear / ReLU / Tanh / Flatten layers, for fast acting.

    Acting one observation at a time through torch costs more than the environment step; the
    copy is refreshed after every training phase, so it always equals the torch network.
    """

    def __init__(self, *modules: Any) -> None:
        self.modules = modules
        self.layers: list[tuple[str, Any]] = []
        self.refresh()

    def refresh(self) -> None:
        from torch import nn

        layers: list[tuple[str, Any]] = []

        def add(module: Any) -> None:
            if isinstance(module, nn.Sequential):
                for child in module:
                    add(child)
            elif isinstance(module, nn.Linear):
                bias = module.bias.detach().numpy().copy() if module.bias is not None else 0.0
                layers.append(("linear", (module.weight.detach().numpy().copy(), bias)))
            elif isinstance(module, nn.ReLU):
                layers.append(("relu", None))
            elif isinstance(module, nn.Tanh):
                layers.append(("tanh", None))
            elif isinstance(module, (nn.Flatten, nn.Identity)):
                pass
            else:
                raise TypeError(f"_NumpyMLP supports Linear, ReLU, Tanh and Flatten layers, not {type(module).__name__}")

        for module in self.modules:
            add(module)
        self.layers = layers

    def __call__(self, x: np.ndarray) -> np.ndarray:
        for kind, weights in self.layers:
            if kind == "linear":
                x = weights[0] @ x + weights[1]
            elif kind == "relu":
                x = np.maximum(x, 0.0)
            else:
                x = np.tanh(x)
        return x


def _quiet_logger():
    from stable_baselines3.common.logger import Logger

    return Logger(folder=None, output_formats=[])


def _update_target_network(model: Any) -> None:
    """Move DQN's target network toward its Q-network by ``tau`` (1 by default: a copy), batch-norm
    statistics copied outright, as ``DQN`` does every ``target_update_interval`` steps."""
    from stable_baselines3.common.utils import polyak_update

    polyak_update(model.q_net.parameters(), model.q_net_target.parameters(), model.tau)
    polyak_update(model.batch_norm_stats, model.batch_norm_stats_target, 1.0)


def _check_discrete(action_space: gym.spaces.Space, name: str) -> gym.spaces.Discrete:
    if not isinstance(action_space, gym.spaces.Discrete):
        raise TypeError(f"{name} needs a Discrete action space (the env's action_type='discrete'), got {action_space}")
    return action_space


class _SB3Agent:
    """What DQNAgent and PPOAgent share: features, seeding, step counting, the goal-switch signal."""

    algo = ""

    def __init__(
        self, observation_space: gym.spaces.Space, action_space: gym.spaces.Space, seed: int | None, params: Any, overrides: dict[str, Any]
    ) -> None:
        params = make_params(self.algo, **overrides) if params is None else make_params(self.algo, **{**params_dict(params), **overrides})
        torch, _ = _import_sb3()
        torch.set_num_threads(1)
        self.torch = torch
        discrete = _check_discrete(action_space, type(self).__name__)
        self.params = params
        self.seed = int(np.random.SeedSequence(seed).generate_state(1)[0]) if seed is None else int(seed)
        self.features = ScanFeatures(observation_space, params.n_bins, params.allocentric)
        self.action_space = action_space
        self.n_actions = int(discrete.n)
        self.rng = np.random.default_rng(self.seed)
        self.random_state = _OwnRandomState(torch, self.seed)
        self.num_timesteps = 0  # every transition observed
        self.schedule_origin = 0  # num_timesteps when the current schedule (re)started
        self.schedule_length = int(params.n_timesteps)
        self.goal_switches = 0
        self._x: np.ndarray | None = None

    def config(self) -> dict[str, Any]:
        """The hyperparameters in force, as a JSON-ready dict."""
        return params_dict(self.params)

    def _progress_remaining(self) -> float:
        return 1.0 - (self.num_timesteps - self.schedule_origin) / max(self.schedule_length, 1)

    def start_trial(self, trial: int) -> None:
        """A new DMTP trial. After any experience this means the goal has moved (see ``reset_on_new_goal``)."""
        if self.num_timesteps > 0:
            self.goal_switches += 1
            if self.params.reset_on_new_goal:
                self._on_new_goal()

    def _on_new_goal(self) -> None:
        raise NotImplementedError

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        """A run begins."""
        self._x = self.features(observation)


class DQNAgent(_SB3Agent):
    """stable-baselines3 DQN, learning online from every transition the runner hands it.

    Args:
        observation_space: The env's ``Dict(ranges, heading)`` space.
        action_space: ``Discrete(n)``.
        seed: Seeds the network, the replay sampling and the epsilon-greedy draws.
        params: A :class:`~hippomaze.baselines.hyperparams.DQNParams`; ``None`` = the defaults.
        **overrides: Fields of ``DQNParams`` to change (e.g. ``learning_rate=1e-3``).
    """

    algo = "dqn"

    def __init__(
        self,
        observation_space: gym.spaces.Space,
        action_space: gym.spaces.Space,
        seed: int | None = None,
        params: DQNParams | None = None,
        **overrides: Any,
    ) -> None:
        super().__init__(observation_space, action_space, seed, params, overrides)
        params = self.params
        from stable_baselines3 import DQN

        with self.random_state:
            self.model = DQN(
                "MlpPolicy",
                _SpacesEnv(self.features.space, action_space),
                learning_rate=params.learning_rate,
                buffer_size=params.buffer_size,
                learning_starts=params.learning_starts,
                batch_size=params.batch_size,
                gamma=params.gamma,
                train_freq=params.train_freq,
                gradient_steps=params.gradient_steps,
                target_update_interval=params.target_update_interval,
                exploration_fraction=params.exploration_fraction,
                exploration_initial_eps=params.exploration_initial_eps,
                exploration_final_eps=params.exploration_final_eps,
                max_grad_norm=params.max_grad_norm,
                policy_kwargs={"net_arch": list(params.net_arch)},
                device="cpu",
                verbose=0,
            )
        self.model.set_logger(_quiet_logger())
        self.model.policy.set_training_mode(False)
        self.q_net = _NumpyMLP(self.model.q_net.q_net)  # the features extractor is a Flatten
        assert self.model.replay_buffer is not None  # DQN makes it on construction
        self.replay_buffer = self.model.replay_buffer
        self.exploration_rate = params.exploration_initial_eps
        self._action = 0

    def act(self, observation: Any) -> int:
        """Epsilon-greedy on the Q-network (uniformly random during the warm-up)."""
        x = self.features(observation)
        self._x = x
        warmup = self.num_timesteps - self.schedule_origin < self.params.learning_starts
        if warmup or self.rng.random() < self.exploration_rate:
            action = int(self.rng.integers(self.n_actions))
        else:
            action = int(np.argmax(self.q_net(x)))
        self._action = action
        return action

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        """Store the transition; every ``train_freq`` steps after the warm-up, train."""
        p = self.params
        next_x = self.features(observation)
        timeout = bool(truncated and not terminated)
        assert self._x is not None, "observe() before act()"
        self.replay_buffer.add(
            self._x[None], next_x[None], np.array([[int(action)]]), np.array([float(reward)], np.float32),
            np.array([bool(terminated or truncated)]), [{"TimeLimit.truncated": timeout}],
        )  # fmt: skip
        self._x = next_x
        self.num_timesteps += 1
        self.model.num_timesteps = self.num_timesteps
        if self.num_timesteps % max(self.model.target_update_interval, 1) == 0:
            _update_target_network(self.model)
        self.model.exploration_rate = self.model.exploration_schedule(self._progress_remaining())
        self.exploration_rate = float(self.model.exploration_rate)
        since = self.num_timesteps - self.schedule_origin
        if since % p.train_freq == 0 and since > p.learning_starts:
            self.model.policy.set_training_mode(True)
            with self.random_state:
                self.model.train(gradient_steps=p.gradient_steps, batch_size=p.batch_size)
            self.model.policy.set_training_mode(False)
            self.q_net.refresh()

    def _on_new_goal(self) -> None:
        self.replay_buffer.reset()
        self.schedule_origin = self.num_timesteps
        self.schedule_length = int(self.params.switch_timesteps)
        self.exploration_rate = self.params.exploration_initial_eps


class PPOAgent(_SB3Agent):
    """stable-baselines3 PPO, learning online: a ``PPO.train()`` after every ``n_steps`` transitions.

    Args:
        observation_space: The env's ``Dict(ranges, heading)`` space.
        action_space: ``Discrete(n)``.
        seed: Seeds the networks, the minibatch shuffling and the action draws.
        params: A :class:`~hippomaze.baselines.hyperparams.PPOParams`; ``None`` = the defaults.
        **overrides: Fields of ``PPOParams`` to change (e.g. ``ent_coef=0.01``).
    """

    algo = "ppo"

    def __init__(
        self,
        observation_space: gym.spaces.Space,
        action_space: gym.spaces.Space,
        seed: int | None = None,
        params: PPOParams | None = None,
        **overrides: Any,
    ) -> None:
        super().__init__(observation_space, action_space, seed, params, overrides)
        params = self.params
        from stable_baselines3 import PPO

        with self.random_state:
            self.model = PPO(
                "MlpPolicy",
                _SpacesEnv(self.features.space, action_space),
                learning_rate=params.learning_rate,
                n_steps=params.n_steps,
                batch_size=params.batch_size,
                n_epochs=params.n_epochs,
                gamma=params.gamma,
                gae_lambda=params.gae_lambda,
                clip_range=params.clip_range,
                ent_coef=params.ent_coef,
                vf_coef=params.vf_coef,
                max_grad_norm=params.max_grad_norm,
                normalize_advantage=params.normalize_advantage,
                policy_kwargs={"net_arch": list(params.net_arch)},
                device="cpu",
                verbose=0,
            )
        self.model.set_logger(_quiet_logger())
        self.policy = self.model.policy
        if params.zero_init_critic:
            with self.torch.no_grad():
                self.policy.value_net.weight.zero_()
                self.policy.value_net.bias.zero_()
        self.policy.set_training_mode(False)
        from stable_baselines3.common.distributions import CategoricalDistribution

        if not isinstance(self.policy.action_dist, CategoricalDistribution):
            raise TypeError("PPOAgent supports the categorical policy of a Discrete action space only")
        extractor = self.policy.mlp_extractor
        self.pi_net = _NumpyMLP(extractor.policy_net, self.policy.action_net)
        self.vf_net = _NumpyMLP(extractor.value_net, self.policy.value_net)
        self.buffer = self.model.rollout_buffer
        self.buffer.reset()
        self._episode_start = True
        self._step: tuple[int, Any, Any] | None = None

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        super().reset(observation, info)
        self._episode_start = True

    def act(self, observation: Any) -> int:
        """Sample from the policy (with the agent's own generator) and remember value and log-prob."""
        x = self.features(observation)
        self._x = x
        logits = self.pi_net(x).astype(np.float64)
        log_probs = logits - logits.max()
        log_probs -= math.log(np.exp(log_probs).sum())
        cdf = np.cumsum(np.exp(log_probs))
        action = int(min(np.searchsorted(cdf, self.rng.random() * cdf[-1], side="right"), self.n_actions - 1))
        value = self.torch.as_tensor(self.vf_net(x).reshape(1, 1), dtype=self.torch.float32)
        self._step = (action, value, self.torch.as_tensor([log_probs[action]], dtype=self.torch.float32))
        return action

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        """Add the transition to the rollout; when it is full, compute GAE and train."""
        assert self._step is not None and self._x is not None, "observe() before act()"
        p = self.params
        stored_action, value, log_prob = self._step
        reward = float(reward)
        if truncated and not terminated:  # a time-out is not a terminal state: bootstrap (SB3 GH#633)
            reward += p.gamma * float(self.vf_net(self.features(observation))[0])
        self.buffer.add(
            self._x[None], np.array([[stored_action]]), np.array([reward], np.float32), np.array([self._episode_start]), value, log_prob
        )
        done = bool(terminated or truncated)
        self._episode_start = done
        self.num_timesteps += 1
        self.model.num_timesteps = self.num_timesteps
        if self.buffer.full:
            last_value = self.torch.as_tensor(self.vf_net(self.features(observation)).reshape(1, 1), dtype=self.torch.float32)
            self.buffer.compute_returns_and_advantage(last_values=last_value, dones=np.array([done]))
            with self.random_state:
                self.model.train()
            self.policy.set_training_mode(False)
            self.pi_net.refresh()
            self.vf_net.refresh()
            self.buffer.reset()

    def _on_new_goal(self) -> None:
        self.buffer.reset()
        self._episode_start = True


__all__ = ["INSTALL_HINT", "DQNAgent", "PPOAgent", "ScanFeatures"]
