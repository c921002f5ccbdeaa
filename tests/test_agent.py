"""HippocampalAgent: spaces and config validation, the protocol, exploration, preplay/exploitation,
determinism, analysis helpers and plots, and the agent in the real environment."""

from __future__ import annotations

import dataclasses
import json
import math

import gymnasium as gym
import numpy as np
import pytest

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_agent import AgentConfig, HippocampalAgent, plots

SMALL = AgentConfig(n_place=300, dry_run_steps=1500)


def obs_space(n_rays=720, max_range=10.0, odometry=True):
    spaces = {
        "ranges": gym.spaces.Box(0.0, max_range, (n_rays,), np.float32),
        "heading": gym.spaces.Box(-1.0, 1.0, (2,), np.float32),
    }
    if odometry:
        spaces["odometry"] = gym.spaces.Box(-0.3, 0.3, (2,), np.float32)
    return gym.spaces.Dict(spaces)


DISCRETE = gym.spaces.Discrete(8)
HEADING = gym.spaces.Box(-np.pi, np.pi, (1,), np.float32)


@pytest.fixture
def small_maze(tmp_path):
    path = tmp_path / "small.json"
    path.write_text(json.dumps({"name": "small", "size": [4.0, 4.0], "obstacles": []}))
    return str(path)


def make_env(maze="open", action_type="discrete", seed=0, **kw):
    kw.setdefault("odometry", True)
    env = gym.make("HippoMaze-v0", maze=maze, n_rays=720, max_range=10.0, action_type=action_type, **kw)
    env.reset(seed=seed)
    return env


def drive_run(env, agent, options=None, max_steps=10_000):
    obs, info = env.reset(options=options)
    agent.reset(obs, info)
    positions, actions = [info["position"]], []
    for _ in range(max_steps):
        action = agent.act(obs)
        actions.append(action)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        positions.append(info["position"])
        if terminated or truncated:
            break
    return info, np.array(positions), actions


def found_the_goal(maze, **config):
    """A default agent after a 1,500-step dry run and a run 1 that found the goal at (1.2, 1.2)."""
    env = make_env(maze, seed=1)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(dry_run_steps=1500, **config), seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    info, _, _ = drive_run(env, agent, options={"goal": [1.2, 1.2], "start": [-1.3, -1.3], "heading": 0.0})
    assert info["is_success"]
    return env, agent


def finish_run(env, agent, obs, max_steps):
    """Drive an agent already reset for a run to its end; returns the last info and the
    decision behind each step (``agent.last_decision``)."""
    decisions, info = [], {}
    for _ in range(max_steps):
        action = agent.act(obs)
        decisions.append(agent.last_decision)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        if terminated or truncated:
            break
    return info, decisions


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


@pytest.mark.parametrize(
    "field, value, allowed",
    [
        ("n_place", -5, ">= 1"),
        ("k", float("nan"), "finite"),
        ("k", 1.5, "(0, 1]"),
        ("trace_rate", 0.0, "(0, 1]"),
        ("lambda_", float("inf"), "finite"),
        ("lambda_", -0.1, "[0, 1]"),
        ("p_pb", 2.0, "[0, 1]"),
        ("bvc_sigma_r", -0.5, "> 0"),
        ("n_hd", 7, "even"),
        ("dry_run_steps", -1, ">= 0"),
        ("segment_max", 2, "segment_min"),
        ("discrete_rounding", "floor", "'stochastic' or 'nearest'"),
        ("xi", -1e-3, ">= 0"),
        ("home_radius", -1.0, ">= 0"),
        ("home_arrived", 0.0, "> 0"),
        ("home_attempts", 0, ">= 1"),
        ("home_search_radius", 0.0, "> 0"),
        ("home_search_mark", -0.1, "> 0"),
        ("home_bump_limit", 0, ">= 1"),
        ("lost_bump_rate", -0.1, ">= 0"),
        ("bump_rate_steps", 0, ">= 1"),
    ],
)
def test_bad_config_raises_naming_the_field(field, value, allowed):
    with pytest.raises(ValueError) as err:
        AgentConfig(**{field: value})
    assert f"AgentConfig.{field}=" in str(err.value) and allowed in str(err.value)


@pytest.mark.parametrize(
    "field, value, allowed", [("n_place", 2.5, "an integer"), ("bvc_distance_scaled", 1, "True or False"), ("k", "0.5", "number")]
)
def test_config_of_the_wrong_type_raises_type_error(field, value, allowed):
    with pytest.raises(TypeError) as err:
        AgentConfig(**{field: value})
    assert f"AgentConfig.{field}=" in str(err.value) and allowed in str(err.value)


def test_config_round_trips_through_dict_and_rejects_unknown_keys():
    cfg = AgentConfig(n_place=123, lambda_=0.1, bvc_max_distance=8.0)
    assert AgentConfig.from_dict(json.loads(json.dumps(cfg.to_dict()))) == cfg
    with pytest.raises(ValueError, match="unknown AgentConfig field"):
        AgentConfig.from_dict({"n_cells": 3})
    with pytest.raises(dataclasses.FrozenInstanceError):
        cfg.n_place = 5  # frozen
    with pytest.raises(TypeError, match="config must be an AgentConfig"):
        HippocampalAgent(obs_space(), DISCRETE, config={"n_place": 3})


# ------------------------------------------------------------------ actions
def test_circular_mean_of_negative_angles_maps_to_the_right_action():
    agent = HippocampalAgent(obs_space(), DISCRETE, AgentConfig(n_place=20, discrete_rounding="nearest"), seed=0)
    assert agent._to_action(-math.pi / 4) == 7
    assert agent._to_action(-math.pi / 2 - 0.1) == 6
    assert agent._to_action(math.pi - 0.01) == 4 and agent._to_action(-math.pi + 0.01) == 4
    assert agent._to_action(0.1) == 0 and agent._to_action(-0.1) == 0
    h = HippocampalAgent(obs_space(), HEADING, AgentConfig(n_place=20), seed=0)
    a = h._to_action(-3 * math.pi / 4)
    assert a.shape == (1,) and a.dtype == np.float32 and a[0] == pytest.approx(-3 * math.pi / 4)
    assert HEADING.contains(h._to_action(7.0))  # wrapped into [-pi, pi)


def test_stochastic_rounding_is_unbiased():
    agent = HippocampalAgent(obs_space(), DISCRETE, AgentConfig(n_place=20), seed=0)
    target = math.radians(10.0)  # between action 0 (0 deg) and 1 (45 deg)
    acts = np.array([agent._to_action(target) for _ in range(4000)])
    assert set(acts) == {0, 1}
    assert np.mean(acts == 1) == pytest.approx(10 / 45, abs=0.03)
    acts = np.array([agent._to_action(-target) for _ in range(2000)])
    assert set(acts) == {0, 7}


# ------------------------------------------------------------------ preplay / exploitation decision
def test_preplay_picks_the_direction_of_higher_value():
    agent = HippocampalAgent(obs_space(), DISCRETE, AgentConfig(n_place=6, discrete_rounding="nearest"), seed=0)
    agent.start_trial(0)
    pc = agent.place
    # learnt topology: from cell 0, south-east (direction 7, -45 deg) leads to cell 1, north to cell 2
    pc.set_W_pp(0, 1, 2.0 * np.cos(-math.pi / 4 - agent._directions))
    pc.set_W_pp(0, 2, 2.0 * np.cos(math.pi / 2 - agent._directions))
    agent.reward.W_rp[0] = [0.2, 1.0, 0.3, 0, 0, 0]
    agent.reward.reset_effective()
    agent.goal_rewarded = True
    pc.v = np.array([0.8, 0, 0, 0, 0, 0])
    heading = agent._exploit_heading()
    assert heading is not None and -math.pi / 2 < heading < 0  # toward the higher value, south-east
    assert agent._to_action(heading) == 7
    assert agent.reward.W_eff[0] == pytest.approx(0.2 * (1 - 0.8 * agent.config.lambda_))  # eq. 11
    # with no value anywhere (below xi) the agent explores
    agent.reward.W_eff[:] = 0.0
    assert agent._exploit_heading() is None


# ------------------------------------------------------------------ in the environment
@pytest.mark.parametrize("paper", [True, False])
def test_protocol_and_dry_run_in_the_real_env(paper):
    env = make_env(seed=3)
    config = AgentConfig.paper(n_place=200, dry_run_steps=400) if paper else AgentConfig(n_place=200, dry_run_steps=400)
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=3)
    W0 = agent.place.W_pb.copy()
    agent.dry_run(env)
    assert not np.array_equal(agent.place.W_pb, W0)  # eq. 5 learnt in the dry run
    if paper:
        assert np.all(agent.place.W_pp == 0)  # ... and only eq. 5 (the paper's dry run)
    else:
        assert np.any(agent.place.W_pp != 0)  # the default model also learns eq. 7 while exploring
        assert np.all(agent.place.centre_mass[agent.place.centre_mass > 0] > 0)
        assert (agent.place.centre_mass > 0).sum() > 20  # cells learnt where they fire
    assert agent.reward.n == 0
    agent.start_trial(0)
    _, _, actions = drive_run(env, agent, options={"new_goal": True}, max_steps=300)
    assert all(env.action_space.contains(a) for a in actions)
    assert np.any(agent.place.W_pp != 0)  # eq. 7 learns in runs
    assert agent.reward.n == 1


def test_dry_run_resets_on_truncation():
    env = make_env(seed=0, max_episode_steps=50)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(n_place=100, dry_run_steps=180), seed=0)
    agent.dry_run(env)
    assert agent.total_steps == 180


def test_exploration_is_a_random_walk_of_straight_segments():
    env = make_env(seed=1)
    agent = HippocampalAgent(
        env.observation_space, env.action_space, AgentConfig(n_place=100, discrete_rounding="nearest", exploration="random"), seed=1
    )
    _, positions, actions = drive_run(env, agent, options={"goal": None}, max_steps=2000)
    actions = np.array(actions)
    assert set(actions) == set(range(8))  # all directions get used
    runs = np.diff(np.flatnonzero(np.diff(actions) != 0))
    assert np.median(runs) >= 4  # straight segments, not a jitter
    assert agent.episode_stats["explore"] == 2000 and agent.episode_stats["bumps"] > 0
    spread = positions.max(axis=0) - positions.min(axis=0)
    assert np.all(spread > 5.0)  # it covers the 10 m arena


def test_bump_starts_a_new_segment_in_a_random_direction():
    agent = HippocampalAgent(obs_space(), HEADING, AgentConfig(n_place=20), seed=0)
    ranges = np.full(720, 3.0, np.float32)
    obs = {"ranges": ranges, "heading": np.array([1.0, 0.0], np.float32), "odometry": np.zeros(2, np.float32)}
    agent.reset(obs, {})
    headings = set()
    for _ in range(20):
        agent.observe(agent.act(obs), obs, 0.0, False, False, {"collision": True})
        headings.add(round(agent.intended_heading, 6))
    assert len(headings) == 20


def test_bump_while_exploiting_escapes_for_a_few_steps():
    cfg = AgentConfig.paper(n_place=6, bump_escape_steps=3)  # the rates are held fixed below: no path integration
    agent = HippocampalAgent(obs_space(), HEADING, cfg, seed=0)
    obs = {"ranges": np.full(720, 3.0, np.float32), "heading": np.array([1.0, 0.0], np.float32)}
    agent.reset(obs, {})
    agent.start_trial(0)
    agent.goal_rewarded = True
    # force exploitation: every preplayed direction leads to cell 1, which holds value
    agent.place.set_W_pp(0, 1, np.full(8, 2.0))
    agent.reward.W_rp[0] = [0.5, 1.0, 0, 0, 0, 0]
    agent.reward.reset_effective()
    agent.place.v = np.array([0.8, 0, 0, 0, 0, 0])
    agent.place.s = agent.place.v.copy()
    agent.place.step = lambda b, n_steps=1: agent.place.v  # hold the rates fixed for this test
    agent.act(obs)
    assert agent.last_decision == "exploit"
    agent.observe(np.array([0.0], np.float32), obs, 0.0, False, False, {"collision": True})
    decisions = []
    for _ in range(5):
        agent.act(obs)
        decisions.append(agent.last_decision)
        agent.observe(np.array([0.0], np.float32), obs, 0.0, False, False, {"collision": False})
    assert decisions == ["explore"] * 3 + ["exploit"] * 2


@pytest.mark.parametrize("action_type", ["discrete", "heading"])
def test_determinism_by_seed(action_type):
    def trajectory(agent_seed):
        env = make_env(action_type=action_type, seed=7)
        agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(n_place=200, dry_run_steps=300), seed=agent_seed)
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
    config = (
        AgentConfig.paper(n_place=SMALL.n_place, dry_run_steps=SMALL.dry_run_steps)
        if paper
        else AgentConfig(dry_run_steps=SMALL.dry_run_steps)
    )
    for seed in range(5):
        env = make_env(small_maze, seed=seed)
        agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=seed)
        agent.dry_run(env)
        agent.start_trial(0)
        start = {"start": [-1.3, -1.3], "heading": 0.0}
        info1, _, _ = drive_run(env, agent, options={"goal": [1.2, 1.2], **start})
        assert info1["is_success"] and agent.goal_rewarded
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


def test_reward_cells_remember_where_each_goal_was_found():
    from hippo_agent.cells.reward import RewardCells

    cells = RewardCells(4)
    assert cells.remembered_place() is None
    cells.add_goal()
    assert cells.remembered_place() is None
    cells.remember_place(np.array([1.0, 2.0]))
    cells.remember_place(np.array([2.0, 4.0]))
    np.testing.assert_allclose(cells.remembered_place(), [1.5, 3.0])
    cells.add_goal()  # a new goal: nothing found yet, the old one kept
    assert cells.remembered_place() is None
    np.testing.assert_allclose(cells.found_sum[0] / cells.found_count[0], [1.5, 3.0])


@pytest.mark.parametrize("home_radius", [0.0, 1.5])
def test_near_where_the_goal_was_found_the_agent_homes_there(small_maze, home_radius):
    """Run 1 finds the goal and remembers where by path integration; run 2, put down within
    ``home_radius`` of it, heads there (decision "home") and reaches it; with 0, never."""
    goal, start = [1.2, 1.2], {"start": [-1.4, -1.2], "heading": 0.0}  # far enough to be anchored before it is near
    env = make_env(small_maze, seed=1)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(dry_run_steps=1500, home_radius=home_radius), seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    info1, _, _ = drive_run(env, agent, options={"goal": goal, "start": [-1.3, 1.3], "heading": 0.0})
    assert info1["is_success"]
    remembered = agent.reward.remembered_place() + agent.frame_offset(env.unwrapped)
    assert np.hypot(*(remembered - goal)) < 0.3 + 0.1  # where the robot entered the goal disk
    obs, info = env.reset(options=start)
    agent.reset(obs, info)
    info, decisions = finish_run(env, agent, obs, 400)
    assert ("home" in decisions) == (home_radius > 0), decisions
    if home_radius > 0:
        assert info["is_success"] and len(decisions) < 100, len(decisions)


def test_a_search_round_the_remembered_place_that_finds_nothing_anchors_afresh(small_maze):
    """Searched all round where the goal was found, without the reward: the estimate is taken to be
    at a look-alike place, so the agent anchors afresh (and may home again once anchored)."""
    _, agent = found_the_goal(small_maze)
    assert agent.pi.anchored
    agent.pi.estimate = agent.reward.remembered_place() + 0.05
    agent.homing_done = True
    agent.map.searched[:] = False
    assert agent._home_heading() is not None and agent.pi.anchored  # ground round the place left to search
    agent.map.searched[:] = True
    assert agent._home_heading() is None
    assert not agent.pi.anchored and not agent.homing_done


def test_homing_heads_straight_at_the_place_in_sight_and_leaves_the_segment_length_to_exploration(small_maze):
    """With walkable ground all the way to within ``search_radius`` of the remembered place, homing
    heads straight at it. It draws no segment length: if exploration takes over, it goes on the
    same way for a length drawn then, without a turn."""
    _, agent = found_the_goal(small_maze, home_radius=10.0)
    place = agent.reward.remembered_place()
    agent.pi.estimate = place + np.array([-2.0, -1.5])
    assert agent.map.in_sight(agent.pi.estimate, place + np.array([-2.0, -1.5]) * (agent.config.search_radius / 2.5))
    state = agent.rng.bit_generator.state
    heading = agent._home_heading()
    here = agent.pi.estimate
    assert heading == math.atan2(place[1] - here[1], place[0] - here[0])
    assert agent.rng.bit_generator.state == state and agent.segment_left == -1
    assert agent._random_heading() == heading  # exploration goes on the same way ...
    c = agent.config
    assert c.segment_min - 1 <= agent.segment_left <= c.segment_max - 1  # ... for a length drawn now


def test_homing_to_a_place_by_a_wall_paths_beside_it_and_a_bump_there_starts_the_search(small_maze):
    """A remembered place by a wall lies off the map's walkable ground: homing plans to walkable
    ground beside it (not straight at it through whatever is in the way), never pushes when no
    path is known, and a bump on the last straight stretch counts as arriving."""
    env, agent = found_the_goal(small_maze, home_radius=10.0)
    offset = agent.frame_offset(env.unwrapped)
    by_the_wall = np.array([1.95, 0.0]) - offset  # the arena's east wall is at x = 2
    agent.reward.found_sum[-1] = by_the_wall * agent.reward.found_count[-1]
    agent.pi.estimate = np.array([-1.0, 0.0]) - offset
    assert agent.map.heading_to(agent.pi.estimate, agent.map.flat_index(*by_the_wall)) is None  # off the walkable map
    heading = agent._home_heading()
    assert heading is not None and math.cos(heading) > 0.5, heading
    free = agent.map.free.copy()
    agent.map.free[:] = 0  # no known ground: no path
    agent.map.grids_replaced()
    assert agent._home_heading() is None
    agent.map.free[:] = free
    agent.map.grids_replaced()
    obs, info = env.reset(options={"goal": [-1.2, -1.2], "start": [1.2, 0.0], "heading": 0.0})  # (a goal elsewhere)
    agent.reset(obs, info)
    agent.reward.found_sum[-1] = (np.array([1.95, 0.0]) - agent.frame_offset(env.unwrapped)) * agent.reward.found_count[-1]
    for _ in range(80):  # home until the first bump
        action = agent.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        if info["collision"]:
            break
    assert agent.last_decision == "home" and info["collision"]
    assert agent.homing_done  # the robot's centre cannot come within home_arrived of the place: the bump ended homing


@pytest.mark.parametrize("facing_a_known_wall", [False, True])
def test_bumping_into_walls_while_homing_counts_as_a_failed_search(small_maze, facing_a_known_wall):
    """The map showed the way free, yet the robot kept bumping: its estimate is taken to be at a
    look-alike place, as when the search round the place finds nothing. Bumps into a wall the map
    holds do not count."""
    env, agent = found_the_goal(small_maze, home_bump_limit=3)
    obs, info = env.reset(options={"start": [-1.3, 1.3], "heading": 0.0})
    agent.reset(obs, info)
    if facing_a_known_wall:
        agent.map.hits[agent.map.index(*(agent.pi.estimate + [agent.config.map_bump_distance, 0.0]))] = 1000
        agent.map.grids_replaced()
    agent.last_decision = "home"
    for bumps in range(1, 4):
        agent.observe(0, obs, 0.0, False, False, {"collision": True})
        agent.last_decision = "home"
        assert agent.memory_failures == (bumps == 3 and not facing_a_known_wall)
    assert agent.homing_bumps == 0 and agent.memory_failures == (not facing_a_known_wall)


@pytest.mark.parametrize(("lost_bump_rate", "facing_a_known_wall"), [(0.0, False), (0.15, False), (0.15, True)])
def test_a_run_that_keeps_bumping_into_walls_anchors_afresh(small_maze, lost_bump_rate, facing_a_known_wall):
    """Bumps where the map shows free ground mean a look-alike place: once the running mean of
    bumps per step passes ``lost_bump_rate`` (9 bumps in a row at 0.15 over 50 steps), the
    estimate is dropped; with 0, never. Bumps into a wall the map holds are explained by it and
    do not count."""
    env = make_env(small_maze, seed=1)
    config = AgentConfig(dry_run_steps=1500, lost_bump_rate=lost_bump_rate)
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    obs, info = env.reset(options={"goal": [1.2, 1.2], "start": [-1.3, -1.3], "heading": 0.0})
    agent.reset(obs, info)
    for _ in range(30):
        action = agent.act(obs)
        obs, _, _, _, info = env.step(action)
        agent.observe(action, obs, 0.0, False, False, info)
    assert agent.pi.anchored
    heading = agent._unpack(obs)[2]
    if facing_a_known_wall:  # the map holds a wall where the robot bumps
        ahead = agent.pi.estimate + agent.config.map_bump_distance * np.array([math.cos(heading), math.sin(heading)])
        agent.map.hits[agent.map.index(*ahead)] = 1000
        agent.map.grids_replaced()
    assert agent.map.wall_near(agent.pi.estimate, heading, agent.config.map_bump_distance) == facing_a_known_wall
    still = {**obs, "odometry": np.zeros(2, dtype=np.float32)}  # pushing at a wall: the scan stays, the wheels slip
    anchored = []
    for _ in range(9):
        agent.observe(0, still, 0.0, False, False, {"collision": True})
        anchored.append(agent.pi.anchored)
    expected_drop = lost_bump_rate > 0 and not facing_a_known_wall
    assert anchored == [True] * 8 + [False] if expected_drop else anchored == [True] * 9


def test_after_home_attempts_failed_searches_the_agent_searches_the_map_and_the_new_find_replaces_the_memory(small_maze):
    """Its memory of the goal led nowhere ``home_attempts`` times in a run (most likely written
    while misplaced): for the rest of the run neither homing nor the reward map steers, and the
    reward found then replaces the old memory instead of being averaged with it."""
    env = make_env(small_maze, seed=1)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(dry_run_steps=1500), seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    goal = {"goal": [1.2, 1.2], "heading": 0.0}
    info, _, _ = drive_run(env, agent, options={**goal, "start": [-1.3, -1.3]})
    assert info["is_success"] and agent.reward.found_count[-1] == 1
    agent.reward.found_sum[-1] = [-1.0, 1.0]  # a wrong place (the reward map still leads to the goal)
    assert np.isclose(agent.reward.W_rp[-1].max(), 1.0)  # one replay's weights peak at 1
    obs, info = env.reset(options={**goal, "start": [-1.3, 1.3]})
    agent.reset(obs, info)
    agent.memory_failures = agent.config.home_attempts
    info, decisions = finish_run(env, agent, obs, 5000)
    assert info["is_success"] and set(decisions) == {"explore"}, set(decisions)
    assert agent.reward.found_count[-1] == 1  # replaced, not averaged with the wrong place
    np.testing.assert_allclose(agent.reward.remembered_place() + agent.frame_offset(env.unwrapped), [1.2, 1.2], atol=0.45)
    assert np.isclose(agent.reward.W_rp[-1].max(), 1.0)  # the old map forgotten, one new replay's learnt


def test_a_run_search_that_has_searched_everything_starts_afresh(small_maze):
    env = make_env(small_maze, seed=1)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(dry_run_steps=1500), seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    obs, info = env.reset(options={"goal": [1.2, 1.2], "start": [-1.3, -1.3], "heading": 0.0})
    agent.reset(obs, info)
    agent.map.searched[:] = True
    assert agent._directed_heading() is not None
    assert not agent.map.searched.any()
