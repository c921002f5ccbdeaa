"""HippocampalAgent, the loop: its spaces and actions, its parts per config, the protocol and the dry
run in the real environment, the choice of a step, determinism, exploitation after one rewarded run,
and the analysis helpers and plots. Each faculty has its own tests (test_<faculty>.py), the paper's
model test_paper_model.py, the config test_config.py."""

from __future__ import annotations

import copy
import math

import gymnasium as gym
import numpy as np
import pytest
from agent_helpers import DISCRETE, HEADING, SMALL, drive_run, make_env, obs_space

import hippo_agent.agent as agent_module
import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_agent import AgentConfig, HippocampalAgent, ModelConfig, PaperModel, plots, spaces
from hippo_agent.faculties.exploration import Exploration
from hippo_agent.faculties.homing import Homing
from hippo_agent.faculties.localisation import Localisation
from hippo_agent.faculties.map import ExplorationMap
from hippo_agent.faculties.path_integration import PathIntegrator
from hippo_agent.faculties.reflexes import Reflexes
from hippo_env.geometry import wrap_angle


# ------------------------------------------------------------------ spaces and config
def test_rejects_unsupported_action_spaces():
    with pytest.raises(ValueError, match="action space .* is unsupported; allowed: Discrete"):
        HippocampalAgent(obs_space(), gym.spaces.Box(-1, 1, (2,), np.float32))  # wheels
    with pytest.raises(ValueError, match="unsupported"):
        HippocampalAgent(obs_space(), gym.spaces.Box(-1, 1, (1,), np.float32))  # not a full circle
    with pytest.raises(TypeError, match="unsupported"):
        HippocampalAgent(obs_space(), gym.spaces.MultiDiscrete([8, 8]))


def test_rejects_unsupported_observation_spaces():
    with pytest.raises(TypeError, match="observation space"):
        HippocampalAgent(gym.spaces.Box(0, 1, (720,)), DISCRETE)
    with pytest.raises(TypeError, match="observation space 'heading'"):
        HippocampalAgent(gym.spaces.Dict({"ranges": gym.spaces.Box(0, 10, (720,)), "heading": gym.spaces.Discrete(8)}), DISCRETE)
    bad = gym.spaces.Dict({"ranges": gym.spaces.Box(0, np.inf, (720,)), "heading": gym.spaces.Box(-1, 1, (2,))})
    with pytest.raises(ValueError, match="finite max range"):
        HippocampalAgent(bad, DISCRETE)
    bad = gym.spaces.Dict({"ranges": gym.spaces.Box(0, 10, (720,)), "heading": gym.spaces.Box(-1, 1, (1,))})
    with pytest.raises(ValueError, match="'heading'"):
        HippocampalAgent(bad, DISCRETE)


def test_the_agent_takes_only_an_agent_config():
    with pytest.raises(TypeError, match="config must be an AgentConfig"):
        HippocampalAgent(obs_space(), DISCRETE, config={"n_place": 3})
    with pytest.raises(TypeError, match="config must be an AgentConfig"):
        HippocampalAgent(obs_space(), DISCRETE, config=ModelConfig(n_place=3))


@pytest.mark.parametrize("paper", [False, True])
def test_the_agent_has_the_parts_its_config_turns_on(paper):
    config = AgentConfig.paper() if paper else AgentConfig()
    agent = HippocampalAgent(obs_space(odometry=not paper), DISCRETE, config.with_values({"model.n_place": 20}), seed=0)
    assert isinstance(agent.model, PaperModel) and agent.model.config == agent.config.model
    assert (agent.hd, agent.bvc, agent.place, agent.reward) == (agent.model.hd, agent.model.bvc, agent.model.place, agent.model.reward)
    assert isinstance(agent.reflexes, Reflexes)  # (the paper's model escapes after a bump while exploiting)
    parts = {"pi": PathIntegrator, "map": ExplorationMap, "localisation": Localisation, "exploration": Exploration, "homing": Homing}
    for name, kind in parts.items():
        assert getattr(agent, name) is None if paper else isinstance(getattr(agent, name), kind), name
    if not paper:  # the faculties share the agent's one map, belief and generator
        assert agent.localisation.map is agent.map is agent.exploration.map is agent.homing.map
        assert agent.localisation.pi is agent.pi is agent.exploration.pi is agent.homing.pi
        assert agent.pi.rng is agent.rng is agent.model.rng is agent.localisation.rng is agent.exploration.rng
    no_map = AgentConfig(map=None, localisation=None, exploration=None, homing=None, worlds=None)
    alone = HippocampalAgent(obs_space(), DISCRETE, no_map.with_values({"model.n_place": 20}), seed=0)
    assert isinstance(alone.pi, PathIntegrator) and alone.map is None and alone.homing is None


# ------------------------------------------------------------------ actions
def test_circular_mean_of_negative_angles_maps_to_the_right_action():
    agent = HippocampalAgent(
        obs_space(), DISCRETE, AgentConfig().with_values({"model.n_place": 20, "model.discrete_rounding": "nearest"}), seed=0
    )

    def to_action(h, agent=agent):
        return spaces.to_action(h, agent.action_kind, agent.n_actions, agent.config.model.discrete_rounding, agent.rng)

    assert to_action(-math.pi / 4) == 7
    assert to_action(-math.pi / 2 - 0.1) == 6
    assert to_action(math.pi - 0.01) == 4 and to_action(-math.pi + 0.01) == 4
    assert to_action(0.1) == 0 and to_action(-0.1) == 0
    h = HippocampalAgent(obs_space(), HEADING, AgentConfig().with_values({"model.n_place": 20}), seed=0)
    assert h.action_kind == "heading"
    a = to_action(-3 * math.pi / 4, h)
    assert a.shape == (1,) and a.dtype == np.float32 and a[0] == pytest.approx(-3 * math.pi / 4)
    assert HEADING.contains(to_action(7.0, h))  # wrapped into [-pi, pi)


def test_stochastic_rounding_is_unbiased():
    agent = HippocampalAgent(obs_space(), DISCRETE, AgentConfig().with_values({"model.n_place": 20}), seed=0)
    target = math.radians(10.0)  # between action 0 (0 deg) and 1 (45 deg)

    def to_action(h):
        return spaces.to_action(h, agent.action_kind, agent.n_actions, agent.config.model.discrete_rounding, agent.rng)

    acts = np.array([to_action(target) for _ in range(4000)])
    assert set(acts) == {0, 1}
    assert np.mean(acts == 1) == pytest.approx(10 / 45, abs=0.03)
    acts = np.array([to_action(-target) for _ in range(2000)])
    assert set(acts) == {0, 7}


def test_an_observation_must_hold_the_scan_and_the_heading():
    ranges, heading_vec, heading = spaces.unpack({"ranges": np.ones(8), "heading": np.array([0.0, 2.0])})
    assert ranges.shape == (8,) and heading_vec.tolist() == [0.0, 2.0] and heading == pytest.approx(math.pi / 2)
    with pytest.raises(ValueError, match="'ranges'"):
        spaces.unpack({"heading": np.array([1.0, 0.0])})
    with pytest.raises(ValueError, match="expected \\(2,\\)"):
        spaces.unpack({"ranges": np.ones(8), "heading": np.array([1.0, 0.0, 0.0])})


# ------------------------------------------------------------------ the choice of a step
def test_act_turns_the_heading_chosen_into_the_action_and_counts_the_decision():
    """``act`` is ``_choose`` (the behaviours in priority order) and the heading as an action."""
    agent = HippocampalAgent(obs_space(), HEADING, AgentConfig().with_values({"model.n_place": 20}), seed=0)
    obs = {"ranges": np.full(720, 3.0, np.float32), "heading": np.array([1.0, 0.0], np.float32), "odometry": np.zeros(2, np.float32)}
    agent.reset(obs, {})
    twin = copy.deepcopy(agent)
    for _ in range(12):
        heading, decision = twin._choose()
        action = agent.act(obs)
        assert action[0] == np.float32(wrap_angle(heading)) and agent.last_decision == decision
        for a in (agent, twin):
            a.observe(action, obs, 0.0, False, False, {"collision": False})
    assert agent.episode_stats["explore"] == 12 and agent.rng.bit_generator.state == twin.rng.bit_generator.state


def test_an_escape_comes_before_every_other_behaviour():
    agent = HippocampalAgent(
        obs_space(),
        HEADING,
        AgentConfig().with_values({"model.n_place": 20, "reflexes.escape_steps": 2, "map.new_wall_evidence": None}),
        seed=0,
    )
    obs = {"ranges": np.full(720, 3.0, np.float32), "heading": np.array([1.0, 0.0], np.float32), "odometry": np.zeros(2, np.float32)}
    agent.reset(obs, {})
    agent.start_trial(0)
    agent.map.observe(agent.pi.estimate, 0.0, obs["ranges"], 10.0)  # the round room the scan shows, on the map
    agent.homing.remember(agent.pi.estimate + (1.0, 0.0))  # homing would steer east ...
    assert agent._choose() == (0.0, "home")
    agent.observe(np.zeros(1, np.float32), obs, 0.0, False, False, {"collision": True})  # ... but a bump (into the map's free ground)
    walk = agent.model.walk
    assert [agent._choose() for _ in range(2)] == [(walk.heading, "explore")] * 2  # the escape: the walk's random turn
    heading, decision = agent._choose()  # the escape over, homing steers again
    assert decision == "home" and heading == pytest.approx(0.0, abs=0.01)


# ------------------------------------------------------------------ in the environment
@pytest.mark.parametrize("paper", [True, False])
def test_protocol_and_dry_run_in_the_real_env(paper):
    env = make_env(seed=3)
    values = {"model.n_place": 200, "model.dry_run_steps": 400}
    config = (AgentConfig.paper() if paper else AgentConfig()).with_values(values)
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=3)
    W0 = agent.place.W_pb.copy()
    agent.dry_run(env)
    assert not np.array_equal(agent.place.W_pb, W0)  # eq. 5 learnt in the dry run
    if paper:
        assert np.all(agent.place.W_pp == 0)  # ... and only eq. 5 (the paper's dry run)
    else:
        assert np.any(agent.place.W_pp != 0)  # the default model also learns eq. 7 while exploring
        assert (agent.pi.centre_mass > 0).sum() > 20  # cells learnt where they fire
    assert agent.reward.n == 0
    agent.start_trial(0)
    _, _, actions = drive_run(env, agent, options={"new_goal": True}, max_steps=300)
    assert all(env.action_space.contains(a) for a in actions)
    assert np.any(agent.place.W_pp != 0)  # eq. 7 learns in runs
    assert agent.reward.n == 1


def test_dry_run_resets_on_truncation():
    env = make_env(seed=0, max_episode_steps=50)
    config = AgentConfig(model=ModelConfig(n_place=100, dry_run_steps=180))
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=0)
    agent.dry_run(env)
    assert agent.total_steps == 180


def test_the_dry_run_cap_grows_with_the_ground_found(monkeypatch):
    """By default (``model.dry_run_steps`` None) the cap is DRY_RUN_STEPS, or more as the map's
    free ground grows; a number given is the cap."""
    monkeypatch.setattr(agent_module, "DRY_RUN_STEPS", 200)  # (a small floor, for a short test)
    env = make_env(seed=0)
    config = AgentConfig(model=ModelConfig(n_place=100)).with_values({"exploration.dry_run_steps_per_m2": 20.0})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=0)
    assert agent._dry_run_cap() == 200  # nothing mapped yet
    agent.dry_run(env)
    area = agent.map.explored_area()
    assert area > 20.0 and agent.total_steps > 200  # went on past 200 steps as the ground grew
    assert agent.total_steps <= int(20.0 * area) and agent._dry_run_cap() == int(20.0 * area)
    fixed = HippocampalAgent(env.observation_space, env.action_space, config.with_values({"model.dry_run_steps": 150}), seed=0)
    fixed.dry_run(env)
    assert fixed.total_steps == 150 and fixed._dry_run_cap() == 150


@pytest.mark.parametrize("action_type", ["discrete", "heading"])
def test_determinism_by_seed(action_type):
    def trajectory(agent_seed):
        env = make_env(action_type=action_type, seed=7)
        agent = HippocampalAgent(
            env.observation_space, env.action_space, AgentConfig(model=ModelConfig(n_place=200, dry_run_steps=300)), seed=agent_seed
        )
        agent.dry_run(env)
        agent.start_trial(0)
        _, positions, actions = drive_run(env, agent, options={"goal": [1.0, 1.0]}, max_steps=400)
        return positions, np.asarray(actions, dtype=float), agent

    p1, a1, ag1 = trajectory(11)
    p2, a2, ag2 = trajectory(11)
    np.testing.assert_array_equal(a1, a2)
    np.testing.assert_array_equal(p1, p2)
    np.testing.assert_array_equal(ag1.place.W_pp, ag2.place.W_pp)
    _, _, ag3 = trajectory(12)
    assert not np.array_equal(ag1.place.W_pb, ag3.place.W_pb)


@pytest.mark.parametrize("paper", [True, False])
def test_exploitation_reaches_the_goal_after_one_rewarded_run(small_maze, paper):
    """A 4 m x 4 m arena: run 1 explores to the goal; run 2 from the same start exploits."""
    results = []
    # the default model at its default 1000 cells: with 300, a 4 m arena has holes where the goal
    # may be reached with no place cell active (nothing to replay)
    small = {"model.dry_run_steps": SMALL.model.dry_run_steps}
    config = AgentConfig.paper().with_values({**small, "model.n_place": SMALL.model.n_place}) if paper else AgentConfig().with_values(small)
    for seed in range(5):
        env = make_env(small_maze, seed=seed)
        agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=seed)
        agent.dry_run(env)
        agent.start_trial(0)
        start = {"start": [-1.3, -1.3], "heading": 0.0}
        info1, _, _ = drive_run(env, agent, options={"goal": [1.2, 1.2], **start})
        assert info1["is_success"] and agent.model.goal_rewarded
        info2, _, _ = drive_run(env, agent, options=start, max_steps=400)
        results.append((info2["is_success"], info2.get("indirectness", np.inf), agent.episode_stats["exploit"]))
    assert all(ok for ok, _, _ in results), results
    assert all(n_exploit > 0 for _, _, n_exploit in results), results
    assert np.median([ind for _, ind, _ in results]) < 1.0, results  # median run 2 is near-direct


def test_analysis_maps_and_plots(small_maze):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    env = make_env(small_maze, seed=0)
    agent = HippocampalAgent(env.observation_space, env.action_space, SMALL, seed=0)
    agent.dry_run(env)
    agent.start_trial(0)
    _, positions, _ = drive_run(env, agent, options={"goal": [1.0, 1.0]})
    grid = plots.grid_positions((4.0, 4.0), spacing=0.4)
    fields = agent.place_field_map(env, grid)
    assert fields.shape == (len(grid), 300) and np.all(fields >= 0)
    at = grid[3] - agent.frame_offset(env)  # where grid[3] lies in the agent's path-integration frame
    np.testing.assert_allclose(agent.place_rates_at(env.unwrapped.observation_at(grid[3], 0.0), at), fields[3])
    values = agent.reward_map(env, grid)
    assert values.shape == (len(grid),) and np.nanmax(values) > 0
    near = np.argmin(np.linalg.norm(grid - [1.0, 1.0], axis=1))
    far = np.argmin(np.linalg.norm(grid - [-1.6, -1.6], axis=1))
    assert values[near] > values[far]  # the reward map peaks toward the goal
    assert agent.value_at(env.unwrapped.observation_at(grid[near], 0.0), pi_position=grid[near] - agent.frame_offset(env)) == pytest.approx(
        values[near]
    )

    cell = int(np.nanargmax(fields.max(axis=0)))
    fig, ax = plots.plot_place_field(grid, fields[:, cell], maze=env.unwrapped.maze, goal=[1.0, 1.0])
    assert ax.figure is fig
    fig2, axes = plt.subplots(1, 2)
    f, a = plots.plot_reward_map(grid, values, ax=axes[0], size=(4.0, 4.0))
    assert a is axes[0] and f is fig2
    f, a = plots.plot_trajectories([positions], ax=axes[1], size=(4.0, 4.0), goal=[1.0, 1.0], labels=["run 1"])
    assert a is axes[1]
    with pytest.raises(ValueError, match="one value per position"):
        plots.plot_place_field(grid, fields[:3, 0])
    plt.close("all")
