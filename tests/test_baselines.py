"""The baselines: the registry, the observation features, DQN / PPO / Dyna-Q behind the Agent
protocol (online learning, determinism, the goal-switch signal), and the hyperparameter file."""

from __future__ import annotations

import builtins
import math

import gymnasium as gym
import numpy as np
import pytest
from hippomaze.baselines import RandomAgent
from hippomaze.baselines.hyperparams import SWEEP, DQNParams, PPOParams, make_params

import hippo_env  # noqa: F401
from hippo_env.dmtp import run_dmtp
from hippomaze.registry import AGENT_NAMES, PRIVILEGED, agent_factory

pytest.importorskip("stable_baselines3", reason="the DQN/PPO baselines need the 'baselines' extra")

TINY_DQN = {
    "learning_starts": 50,
    "buffer_size": 500,
    "batch_size": 16,
    "train_freq": 4,
    "gradient_steps": 1,
    "target_update_interval": 100,
    "n_timesteps": 600,
}
TINY_PPO = {"n_steps": 64, "batch_size": 16, "n_epochs": 1, "n_timesteps": 600}
RUN = {"trials": 1, "runs": 200, "max_episode_steps": 150, "progress": False, "fresh_agent_per_trial": False}


def _runs(result):
    """Every run's outcome and the positions it went through."""
    ends = [np.round(path, 9).tolist() for runs in result.paths for path in runs]
    return [(e.steps, e.success, round(e.path_length, 9)) for e in result.run_records], ends


@pytest.fixture(scope="module")
def env():
    environment = gym.make("HippoMaze-v0", maze="maze1")
    yield environment
    environment.close()


# ------------------------------------------------------------------------------------------ registry
class TestRegistry:
    def test_names(self):
        assert set(AGENT_NAMES) == {"hippo", "hippo-paper", "random", "dqn", "ppo", "dynaq"}
        assert PRIVILEGED == {"dynaq"}

    def test_unknown_name_lists_the_allowed_ones(self):
        with pytest.raises(ValueError, match="hippo, hippo-paper, random, dqn, ppo, dynaq"):
            agent_factory("a2c")

    def test_dense_is_not_an_agent(self):
        with pytest.raises(ValueError, match="reward_type='dense'"):
            agent_factory("dqn-dense")

    def test_unknown_parameter(self):
        with pytest.raises(ValueError, match="no parameter.*learning_rat"):
            agent_factory("dqn", learning_rat=1e-3)
        with pytest.raises(ValueError, match="takes no parameters"):
            agent_factory("random", epsilon=0.1)

    def test_module_class(self, env):
        agent = agent_factory("hippomaze.baselines.random_agent:RandomAgent")(env.observation_space, env.action_space, seed=3)
        assert isinstance(agent, RandomAgent)
        with pytest.raises(ValueError, match="cannot import"):
            agent_factory("no_such_module_xyz:Agent")

    @pytest.mark.parametrize("name", ["random", "dqn", "ppo", "dynaq"])
    def test_factories_follow_the_protocol(self, env, name):
        agent = agent_factory(name)(env.observation_space, env.action_space, seed=0)
        for method in ("reset", "act", "observe"):
            assert callable(getattr(agent, method))

    def test_hippo_is_lazy(self):
        make = agent_factory("hippo")  # builds nothing, imports nothing heavy
        assert callable(make)

    def test_hippo_asks_the_runner_for_odometry_and_hippo_paper_does_not(self):
        assert agent_factory("hippo").env_kwargs == {"odometry": True}
        assert agent_factory("hippo-paper").env_kwargs == {}
        no_odometry = {name: None for name in ("path_integration", "map", "localisation", "exploration", "homing", "worlds")}
        assert agent_factory("hippo", **no_odometry).env_kwargs == {}
        small = agent_factory("hippo", **{"model.n_place": 200, "model.dry_run_steps": 100})
        result = run_dmtp(small, "open", trials=1, runs=1, seed=0, max_episode_steps=200, progress=False)
        assert len(result.run_records) == 1 and result.env_steps_total > 100


# ------------------------------------------------------------------------------------------ features
class TestScanFeatures:
    def test_allocentric_scan_does_not_depend_on_heading(self, env):
        from hippomaze.baselines.sb3_agents import ScanFeatures

        features = ScanFeatures(env.observation_space, n_bins=90, allocentric=True)
        u = env.unwrapped
        scans = [features(u.observation_at((1.0, 2.0), k * math.pi / 4)) for k in range(8)]
        for scan in scans[1:]:
            np.testing.assert_allclose(scan[:-2], scans[0][:-2], atol=1e-5)
        # bin 0 looks along +x: 4 m to the east wall from x = 1, scaled by max_range
        assert scans[0][0] == pytest.approx(4.0 / 10.0, abs=0.01)
        assert features.space.shape == (92,)
        assert np.all((scans[0] >= -1) & (scans[0] <= 1))

    def test_egocentric_scan_turns_with_the_robot(self, env):
        from hippomaze.baselines.sb3_agents import ScanFeatures

        features = ScanFeatures(env.observation_space, n_bins=720, allocentric=False)
        u = env.unwrapped
        a, b = features(u.observation_at((1.0, 2.0), 0.0)), features(u.observation_at((1.0, 2.0), math.pi / 2))
        np.testing.assert_allclose(np.roll(b[:-2], 180), a[:-2], atol=1e-5)

    def test_bins_must_divide_the_rays(self, env):
        from hippomaze.baselines.sb3_agents import ScanFeatures

        with pytest.raises(ValueError, match="must divide the number of rays"):
            ScanFeatures(env.observation_space, n_bins=7)


# --------------------------------------------------------------------------------------- SB3 agents
@pytest.mark.parametrize("name, tiny", [("dqn", TINY_DQN), ("ppo", TINY_PPO)])
class TestSB3Agents:
    def test_learns_online_and_counts_every_step(self, name, tiny):
        made = []

        def factory(observation_space, action_space, seed):
            made.append(agent_factory(name, **tiny)(observation_space, action_space, seed=seed))
            return made[-1]

        result = run_dmtp(factory, "open", seed=0, step_budget=600, **RUN)
        agent = made[0]
        assert len(made) == 1
        assert result.env_steps_total == 600 == agent.num_timesteps
        assert agent.model._n_updates > 0  # SB3's train() ran, driven from observe()

    def test_same_seed_same_numbers_even_interleaved(self, name, tiny):
        first = run_dmtp(agent_factory(name, **tiny), "open", seed=1, step_budget=500, **RUN)
        # Another agent working in between (touching the global generators) must not change anything.
        env = gym.make("HippoMaze-v0")
        other = agent_factory(name, **tiny)(env.observation_space, env.action_space, seed=99)
        np.random.seed(123)
        obs, info = env.reset(seed=5)
        other.reset(obs, info)
        for _ in range(200):
            action = other.act(obs)
            obs, reward, terminated, truncated, info = env.step(action)
            other.observe(action, obs, reward, terminated, truncated, info)
            if terminated or truncated:
                obs, info = env.reset()
                other.reset(obs, info)
        second = run_dmtp(agent_factory(name, **tiny), "open", seed=1, step_budget=500, **RUN)
        assert _runs(first) == _runs(second) and first.run_records
        third = run_dmtp(agent_factory(name, **tiny), "open", seed=2, step_budget=500, **RUN)
        assert _runs(third) != _runs(first)

    def test_goal_switch_signal(self, name, tiny, env):
        agent = agent_factory(name, **tiny)(env.observation_space, env.action_space, seed=0)
        agent.start_trial(0)  # before any experience: not a switch
        assert agent.goal_switches == 0
        obs, info = env.reset(seed=0)
        agent.reset(obs, info)
        for _ in range(100):
            action = agent.act(obs)
            obs, reward, terminated, truncated, info = env.step(action)
            agent.observe(action, obs, reward, terminated, truncated, info)
        agent.start_trial(1)
        assert agent.goal_switches == 1
        if name == "dqn":
            assert agent.model.replay_buffer.size() == 0 and agent.schedule_origin == 100
            assert agent.exploration_rate == agent.params.exploration_initial_eps
        else:
            assert agent.buffer.pos == 0

    def test_acting_copy_equals_the_torch_network(self, name, tiny, env):
        import torch

        agent = agent_factory(name, **tiny)(env.observation_space, env.action_space, seed=0)
        obs, _ = env.reset(seed=0)
        x = agent.features(obs)
        with torch.no_grad():
            if name == "dqn":
                expected = agent.model.q_net(torch.as_tensor(x[None]))[0].numpy()
                got = agent.q_net(x)
            else:
                _, values, _ = agent.policy(torch.as_tensor(x[None]))
                expected, got = values[0].numpy(), agent.vf_net(x)
        np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-6)

    def test_needs_discrete_actions(self, name, tiny):
        env = gym.make("HippoMaze-v0", action_type="heading")
        with pytest.raises(TypeError, match="Discrete action space"):
            agent_factory(name, **tiny)(env.observation_space, env.action_space, seed=0)


@pytest.mark.parametrize("zero_critic", [True, False])
def test_ppo_policy_moves_before_any_reward_only_with_a_random_critic(zero_critic):
    # No goal, so every reward is 0. A zero critic predicts that exactly: zero advantages, no policy update.
    env = gym.make("HippoMaze-v0")
    agent = agent_factory("ppo", **TINY_PPO, zero_init_critic=zero_critic)(env.observation_space, env.action_space, seed=0)
    obs, info = env.reset(seed=0, options={"goal": None})
    x = agent.features(obs)
    logits_before = agent.pi_net(x).copy()
    agent.reset(obs, info)
    for _ in range(2 * TINY_PPO["n_steps"]):
        action = agent.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
    assert agent.model._n_updates > 0
    assert np.array_equal(agent.pi_net(x), logits_before) == zero_critic


def test_dqn_truncation_is_not_terminal(env):
    agent = agent_factory("dqn", **TINY_DQN)(env.observation_space, env.action_space, seed=0)
    obs, info = env.reset(seed=0)
    agent.reset(obs, info)
    action = agent.act(obs)
    obs, reward, _, _, info = env.step(action)
    agent.observe(action, obs, reward, False, True, info)
    buffer = agent.model.replay_buffer
    assert buffer.dones[0, 0] == 1 and buffer.timeouts[0, 0] == 1  # SB3 masks the done with the timeout


def test_missing_sb3_names_the_extra(monkeypatch, env):
    real_import = builtins.__import__

    def fake_import(name, *args, **kwargs):
        if name.startswith("stable_baselines3"):
            raise ImportError("No module named 'stable_baselines3'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake_import)
    from hippomaze.baselines.sb3_agents import DQNAgent

    with pytest.raises(ImportError, match=r"pip install -e \.\[baselines\]"):
        DQNAgent(env.observation_space, env.action_space, seed=0)


# -------------------------------------------------------------------------------------------- Dyna-Q
class TestDynaQ:
    def test_privileged_and_learns_a_goal(self):
        made = []

        def factory(observation_space, action_space, seed):
            made.append(agent_factory("dynaq")(observation_space, action_space, seed=seed))
            return made[-1]

        result = run_dmtp(factory, "open", trials=1, runs=2000, seed=0, progress=False, fresh_agent_per_trial=False, step_budget=25_000)
        assert made[0].privileged
        late = result.run_records[-10:]
        assert all(e.success for e in late)
        assert np.median([e.indirectness for e in late]) < 3.0 < result.run_records[0].indirectness

    def test_goal_switch_keeps_the_map(self, env):
        agent = agent_factory("dynaq")(env.observation_space, env.action_space, seed=0)
        obs, info = env.reset(seed=0)
        agent.reset(obs, info)
        for _ in range(300):
            action = agent.act(obs)
            obs, reward, terminated, truncated, info = env.step(action)
            agent.observe(action, obs, reward, terminated, truncated, info)
        known = agent.known.sum()
        agent.q[:] = 1.0
        agent.start_trial(1)
        assert agent.known.sum() == known > 0 and np.all(agent.q == agent.params.q_init)


# --------------------------------------------------------------------------------------- hyperparams
def test_hyperparams_are_documented_and_checked():
    import hippomaze.baselines.hyperparams as hp

    assert "rl-baselines3-zoo" in hp.__doc__
    for cls in (DQNParams, PPOParams):
        for name in cls.__dataclass_fields__:
            assert f"{name}:" in cls.__doc__, f"{cls.__name__}.{name} is not documented"
    with pytest.raises(ValueError, match="has no parameter"):
        make_params("ppo", gama=0.9)
    assert make_params("dqn", net_arch=[32, 32]).net_arch == (32, 32)
    assert len({p.name for p in SWEEP}) == len(SWEEP)
    for point in SWEEP:
        make_params(point.agent, **point.overrides)
