"""Homing (:mod:`hippo_agent.faculties.homing`): back to where the goal was found, the search round
that place, giving the memory up, and the faculty's own saved state."""

from __future__ import annotations

import math

import numpy as np
import pytest
from agent_helpers import drive_run, finish_run, found_the_goal, make_env, same_state

from hippo_agent import AgentConfig, HippocampalAgent, HomingConfig, MapConfig, PathIntegrationConfig
from hippo_agent.faculties.homing import Homing
from hippo_agent.faculties.map import ExplorationMap
from hippo_agent.faculties.path_integration import PathIntegrator


def bare_homing(config: HomingConfig | None = None) -> Homing:
    """Homing on a map of a 4 m square of free ground, with an anchored path integrator at its middle."""
    m = ExplorationMap(MapConfig(extent=5.0))
    m.free[m.index(-2.0, -2.0)[0] : m.index(2.0, 2.0)[0], m.index(-2.0, -2.0)[1] : m.index(2.0, 2.0)[1]] = 1
    m.grids_replaced()
    pi = PathIntegrator(PathIntegrationConfig(), 4, 0.5, np.random.default_rng(0))
    pi.start_run()  # (the first run: anchored at the frame's origin)
    return Homing(HomingConfig() if config is None else config, m, pi, None)


def agent_reset(env, agent, options):
    """A run begins from ``options``: the first observation."""
    obs, info = env.reset(options=options)
    agent.reset(obs, info)
    return obs


# ------------------------------------------------------------------ the memory
def test_a_reward_found_far_from_the_memory_is_a_rival_until_it_outnumbers_it():
    homing = bare_homing()
    homing.remember(np.array([0.0, 0.0]))
    homing.remember(np.array([0.2, 0.0]))
    homing.remember(np.array([3.0, 0.0]))  # found while misplaced, say: the memory is not dragged off
    np.testing.assert_allclose(homing.remembered(), [0.1, 0.0])
    homing.remember(np.array([-3.0, 0.0]))  # farther than rival_radius from both: a new rival
    assert homing.rival_count[-1] == 1.0
    homing.remember(np.array([-3.2, 0.0]))
    np.testing.assert_allclose(homing.remembered(), [0.1, 0.0])  # a tie keeps the memory
    homing.remember(np.array([-3.1, 0.0]))  # the rival outnumbers it: the goal is there
    np.testing.assert_allclose(homing.remembered(), [-3.1, 0.0])
    np.testing.assert_allclose(homing.rival_sum[-1] / homing.rival_count[-1], [0.1, 0.0])
    homing.forget()
    assert homing.remembered() is None and homing.rival_count[-1] == 0.0


def test_homing_memory_saved_before_rivals_loads_with_none():
    homing = bare_homing()
    homing.restore_memory({"found_sum": np.array([[1.0, 2.0]]), "found_count": np.array([1.0])})
    np.testing.assert_allclose(homing.remembered(), [1.0, 2.0])
    assert homing.rival_count.tolist() == [0.0] and homing.rival_sum.shape == (1, 2)
    with pytest.raises(ValueError, match="found_count"):
        homing.restore_memory({"found_sum": np.zeros((1, 2))})
    with pytest.raises(ValueError, match="rival_sum"):
        homing.restore_memory({"found_sum": np.zeros((1, 2)), "found_count": np.ones(1), "rival_sum": np.zeros((2, 2))})


def test_homing_remembers_where_each_goal_was_found():
    homing = bare_homing()
    assert homing.remembered() is None
    homing.new_goal()
    assert homing.remembered() is None
    homing.remember(np.array([1.0, 2.0]))
    homing.remember(np.array([1.4, 2.6]))
    np.testing.assert_allclose(homing.remembered(), [1.2, 2.3])
    homing.new_goal()  # a new goal: nothing found yet, the old one kept
    assert homing.remembered() is None
    np.testing.assert_allclose(homing.found_sum[0] / homing.found_count[0], [1.2, 2.3])
    homing.remember(np.array([-1.0, 0.0]))
    homing.forget()  # the current goal's memory only
    assert homing.remembered() is None and homing.found_count.tolist() == [2.0, 0.0]
    unannounced = bare_homing()
    unannounced.remember(np.array([0.5, 0.5]))  # a reward before any trial began: a goal of its own
    np.testing.assert_allclose(unannounced.remembered(), [0.5, 0.5])


def test_homing_steers_only_with_a_memory_near_enough_and_a_trusted_estimate():
    homing = bare_homing(HomingConfig(radius=2.0))
    assert not homing.plan() and homing.heading is None  # nothing remembered
    homing.remember(np.array([1.5, 0.0]))
    assert not homing.plan() and homing.heading == 0.0  # in sight: straight at it
    homing.pi.estimate = np.array([-1.0, -1.5])
    assert not homing.plan() and homing.heading is None  # farther than radius
    homing.pi.estimate = np.array([0.0, 0.0])
    homing.pi.lose()
    assert not homing.plan() and homing.heading is None  # lost


def test_the_last_bumps_while_homing_start_the_search_and_surprising_ones_give_up_the_estimate():
    homing = bare_homing(HomingConfig(bump_limit=2))
    homing.remember(np.array([2.0, 0.0]))
    assert not homing.bumped(surprising=False) and not homing.searching  # far from the place
    homing.pi.estimate = np.array([1.5, 0.0])  # within approach_radius of it
    assert not homing.bumped(surprising=False) and homing.searching and homing.search_mark == homing.config.search_mark
    assert not homing.bumped(surprising=True)
    assert homing.bumped(surprising=True)  # bump_limit surprising bumps: the estimate must be wrong
    assert homing.failures == 1 and homing.bumps == 0 and not homing.searching and homing.search_mark is None


def test_homing_that_comes_no_nearer_for_stall_steps_fails_as_a_search_does():
    """Steering toward the place without coming ``stall_progress`` nearer for ``stall_steps``
    steps is a failed search (the map's way is not the world's); coming nearer is not."""
    homing = bare_homing(HomingConfig(stall_steps=5, stall_progress=0.5))
    homing.remember(np.array([1.5, 0.0]))
    homing.pi.estimate = np.array([-1.5, 0.0])
    assert [homing.plan() for _ in range(5)] == [False] * 5  # the first step sets the nearest; four more
    assert homing.plan() and homing.failures == 1 and homing.heading is None
    for x in (-1.5, -0.9, -0.3, 0.3, 0.9):  # 0.6 m nearer each step
        homing.pi.estimate = np.array([x, 0.0])
        for _ in range(4):
            assert not homing.plan()
    assert homing.failures == 1
    homing.pi.lose()  # a new anchoring starts the count afresh
    assert not homing.plan() and homing.stalled == 0


# ------------------------------------------------------------------ in the environment
@pytest.mark.parametrize("radius", [None, 1.5])
def test_near_where_the_goal_was_found_the_agent_homes_there(small_maze, radius):
    """Run 1 finds the goal and remembers where by path integration; run 2, put down within
    ``radius`` of it, heads there (decision "home") and reaches it; with homing off, never."""
    goal, start = [1.2, 1.2], {"start": [-1.4, -1.2], "heading": 0.0}  # far enough to be anchored before it is near
    env = make_env(small_maze, seed=1)
    homing = None if radius is None else HomingConfig(radius=radius)
    agent = HippocampalAgent(
        env.observation_space, env.action_space, AgentConfig(homing=homing).with_values({"model.dry_run_steps": 1500}), seed=1
    )
    agent.dry_run(env)
    agent.start_trial(0)
    info1, _, _ = drive_run(env, agent, options={"goal": goal, "start": [-1.3, 1.3], "heading": 0.0})
    assert info1["is_success"]
    if radius is not None:
        remembered = agent.homing.remembered() + agent.frame_offset(env.unwrapped)
        assert np.hypot(*(remembered - goal)) < 0.3 + 0.1  # where the robot entered the goal disk
    obs = agent_reset(env, agent, start)
    info, decisions = finish_run(env, agent, obs, 400)
    assert ("home" in decisions) == (radius is not None), decisions
    if radius is not None:
        assert info["is_success"] and len(decisions) < 100, len(decisions)


def test_a_search_round_the_remembered_place_that_finds_nothing_anchors_afresh(small_maze):
    """Searched all round where the goal was found, without the reward: the estimate is taken to be
    at a look-alike place, so the agent anchors afresh (and may home again once anchored)."""
    _, agent = found_the_goal(small_maze)
    homing = agent.homing
    assert agent.pi.anchored
    agent.pi.estimate = homing.remembered() + 0.05
    homing.searching = True
    agent.map.searched[:] = False
    agent.map.grids_replaced()  # (written directly)
    assert not homing.plan() and homing.heading is not None and agent.pi.anchored  # ground round the place left to search
    agent.map.searched[:] = True
    agent.map.grids_replaced()
    assert homing.plan() and homing.heading is None  # searched all round: the estimate must be wrong ...
    assert not homing.searching and homing.failures == 1
    homing.searching = True  # ... and the agent, choosing its step, anchors afresh away from it
    agent.reflexes.escape_left = 0
    estimate = agent.pi.estimate.copy()
    _, decision = agent._choose()
    assert decision != "home" and not agent.pi.anchored and not homing.searching and homing.failures == 2
    np.testing.assert_array_equal(agent.pi.ruled_out, [estimate])


def test_homing_heads_straight_at_the_place_in_sight_and_leaves_the_segment_length_to_exploration(small_maze):
    """With walkable ground all the way to within ``approach_radius`` of the remembered place, homing
    heads straight at it. It draws no segment length: if exploration takes over, it goes on the
    same way for a length drawn then, without a turn."""
    _, agent = found_the_goal(small_maze, {"homing.radius": 10.0})
    place = agent.homing.remembered()
    agent.pi.estimate = place + np.array([-2.0, -1.5])
    assert agent.map.in_sight(agent.pi.estimate, place + np.array([-2.0, -1.5]) * (agent.config.homing.approach_radius / 2.5))
    agent.reflexes.escape_left = 0
    state = agent.rng.bit_generator.state
    heading, decision = agent._choose()
    here = agent.pi.estimate
    assert decision == "home" and heading == math.atan2(place[1] - here[1], place[0] - here[0])
    walk = agent.model.walk
    assert agent.rng.bit_generator.state == state and walk.segment_left == -1
    assert walk.step() == heading  # exploration goes on the same way ...
    c = agent.config.model
    assert c.segment_min - 1 <= walk.segment_left <= c.segment_max - 1  # ... for a length drawn now


def test_homing_to_a_place_by_a_wall_paths_beside_it_and_a_bump_there_starts_the_search(small_maze):
    """A remembered place by a wall lies off the map's walkable ground: homing plans to walkable
    ground beside it (not straight at it through whatever is in the way), never pushes when no
    path is known, and a bump on the last straight stretch counts as arriving."""
    env, agent = found_the_goal(small_maze, {"homing.radius": 10.0})
    homing = agent.homing
    offset = agent.frame_offset(env.unwrapped)
    by_the_wall = np.array([1.95, 0.0]) - offset  # the arena's east wall is at x = 2
    homing.found_sum[-1] = by_the_wall * homing.found_count[-1]
    agent.pi.estimate = np.array([-1.0, 0.0]) - offset
    assert agent.map.heading_to(agent.pi.estimate, agent.map.flat_index(*by_the_wall)) is None  # off the walkable map
    homing.plan()
    assert homing.heading is not None and math.cos(homing.heading) > 0.5, homing.heading
    free = agent.map.free.copy()
    agent.map.free[:] = 0  # no known ground: no path
    agent.map.grids_replaced()
    assert not homing.plan() and homing.heading is None
    agent.map.free[:] = free
    agent.map.grids_replaced()
    obs = agent_reset(env, agent, {"goal": [-1.2, -1.2], "start": [1.2, 0.0], "heading": 0.0})  # (a goal elsewhere)
    homing.found_sum[-1] = (np.array([1.95, 0.0]) - agent.frame_offset(env.unwrapped)) * homing.found_count[-1]
    for _ in range(80):  # home until the first bump
        action = agent.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        if info["collision"]:
            break
    assert agent.last_decision == "home" and info["collision"]
    assert homing.searching  # the robot's centre cannot come within homing.arrived of the place: the bump ended homing


@pytest.mark.parametrize("facing_a_known_wall", [False, True])
def test_bumping_into_walls_while_homing_counts_as_a_failed_search(small_maze, facing_a_known_wall):
    """The map showed the way free, yet the robot kept bumping: its estimate is taken to be at a
    look-alike place, as when the search round the place finds nothing. Bumps into a wall the map
    holds do not count."""
    env, agent = found_the_goal(small_maze, {"homing.bump_limit": 3})
    obs = agent_reset(env, agent, {"start": [-1.3, 1.3], "heading": 0.0})
    if facing_a_known_wall:
        agent.map.hits[agent.map.index(*(agent.pi.estimate + [agent.config.map.bump_distance, 0.0]))] = 1000
        agent.map.grids_replaced()
    agent.last_decision = "home"
    for bumps in range(1, 4):
        agent.observe(0, obs, 0.0, False, False, {"collision": True})
        agent.last_decision = "home"
        assert agent.homing.failures == (bumps == 3 and not facing_a_known_wall)
    assert agent.homing.bumps == 0 and agent.homing.failures == (not facing_a_known_wall)


def test_after_failed_searches_the_agent_searches_the_map_and_the_new_find_replaces_the_memory(small_maze):
    """Its memory of the goal led nowhere ``homing.attempts`` times in a run (most likely written
    while misplaced): for the rest of the run neither homing nor the reward map steers, and the
    reward found then replaces the old memory instead of being averaged with it."""
    env = make_env(small_maze, seed=1)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig().with_values({"model.dry_run_steps": 1500}), seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    goal = {"goal": [1.2, 1.2], "heading": 0.0}
    info, _, _ = drive_run(env, agent, options={**goal, "start": [-1.3, -1.3]})
    homing = agent.homing
    assert info["is_success"] and homing.found_count[-1] == 1
    homing.found_sum[-1] = [-1.0, 1.0]  # a wrong place (the reward map still leads to the goal)
    assert np.isclose(agent.reward.W_rp[-1].max(), 1.0)  # one replay's weights peak at 1
    obs = agent_reset(env, agent, {**goal, "start": [-1.3, 1.3]})
    homing.failures = agent.config.homing.attempts
    assert homing.gave_up
    info, decisions = finish_run(env, agent, obs, 5000)
    assert info["is_success"] and set(decisions) == {"explore"}, set(decisions)
    assert homing.found_count[-1] == 1  # replaced, not averaged with the wrong place
    np.testing.assert_allclose(homing.remembered() + agent.frame_offset(env.unwrapped), [1.2, 1.2], atol=0.45)
    assert np.isclose(agent.reward.W_rp[-1].max(), 1.0)  # the old map forgotten, one new replay's learnt


# ------------------------------------------------------------------ save / load
def homed() -> Homing:
    """Homing with memories of two goals, searching round the second's place after a surprising bump."""
    homing = bare_homing()
    homing.remember(np.array([1.0, 1.0]))
    homing.new_goal()
    homing.remember(np.array([1.5, 0.0]))
    homing.remember(np.array([1.5, 0.4]))
    homing.pi.estimate = np.array([1.2, 0.1])
    homing.bumped(surprising=True)
    assert homing.searching and homing.bumps == 1
    return homing


def test_the_state_of_homing_loads_into_a_fresh_one_that_steers_the_same():
    homing = homed()
    saved = homing.state()
    fresh = Homing(homing.config, homing.map, homing.pi, None)
    fresh.load_state(*saved)
    same_state(fresh.state(), saved)
    np.testing.assert_array_equal(fresh.remembered(), homing.remembered())
    assert fresh.search_mark == homing.search_mark
    assert (fresh.plan(), fresh.heading) == (homing.plan(), homing.heading)
    assert homing.heading is not None


@pytest.mark.parametrize(
    "spoil",
    [
        lambda state, arrays: arrays.update(found_sum=np.zeros((3, 2))),
        lambda state, arrays: arrays.update(found_count=np.array([1.0, np.nan])),
        lambda state, arrays: arrays.update(found_sum=np.full((2, 2), np.inf)),
        lambda state, arrays: state.update(failures="twice"),
        lambda state, arrays: state.update(stalled="long"),
    ],
    ids=["lengths", "nan", "inf", "failures", "stalled"],
)
def test_a_malformed_homing_state_raises_value_error(spoil):
    homing = homed()
    state, arrays = homing.state()
    state, arrays = dict(state), dict(arrays)
    spoil(state, arrays)
    with pytest.raises(ValueError):
        Homing(homing.config, homing.map, homing.pi, None).load_state(state, arrays)
