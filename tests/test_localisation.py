"""Localisation against the map (:mod:`hippo_agent.faculties.localisation`): no learning while the
scan fits the map poorly, look-alike places that fit better, surprising bumps, and the faculty's
own saved state."""

from __future__ import annotations

import copy
import math

import gymnasium as gym
import numpy as np
import pytest
from agent_helpers import make_env, ring_scan, same_state

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_agent import AgentConfig, HippocampalAgent
from hippo_agent.faculties.localisation import Localisation
from hippo_agent.spaces import unpack


def test_a_run_whose_scan_fits_the_map_poorly_learns_nothing():
    """An estimate the map doubts (running fit below ``learn_agreement``, above ``lost_agreement``)
    keeps the place code as it is; one it trusts learns."""
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    env.reset(seed=0, options={"goal": None})
    config = AgentConfig().with_values(
        {
            "model.n_place": 300,
            "exploration.place_cells_per_m2": 0.0,
            "model.dry_run_steps": 600,
            "localisation.learn_agreement": 0.9,
            "localisation.lost_agreement": 0.3,
        }
    )
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=0)
    agent.dry_run(env)
    obs, info = env.reset(options={"goal": None})
    agent.reset(obs, info)
    while not agent.pi.anchored:
        action = agent.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)

    def one_step(fit: float) -> bool:
        nonlocal obs
        before = agent.pi.centre_mass.copy()
        agent.localisation.fit = fit
        action = agent.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        assert agent.pi.anchored
        return not np.array_equal(before, agent.pi.centre_mass)

    assert not one_step(0.5)
    assert one_step(1.0)


def two_rooms(agent: HippocampalAgent, estimate: np.ndarray, look_alike_ring: str) -> None:
    """Two round rooms of 2 m 10 m apart on the agent's map: the one at ``estimate`` mapped on its
    west half only, its look-alike to the east on its west half or (``"whole"``) all round."""
    m = agent.map
    for angle in np.linspace(0.0, 2.0 * math.pi, 400, endpoint=False):
        west = math.cos(angle) < 0.0
        for centre, whole in ((estimate, False), (estimate + (10.0, 0.0), look_alike_ring == "whole")):
            if whole or west:  # the estimate's room: only its west half is mapped
                m.hits[m.index(centre[0] + 2.0 * math.cos(angle), centre[1] + 2.0 * math.sin(angle))] = 3
    m.grids_replaced()


@pytest.mark.parametrize("doubt_nearby", [None, 0.25])
def test_a_look_alike_place_that_fits_the_scan_better_ends_the_anchoring(doubt_nearby):
    """Once anchored, the scan's fit to the map is followed at the estimate and at its look-alike
    places; when one fits better by ``doubt_margin``, the robot anchors afresh, ruling out where
    it was (also when places near the estimate are fitted: none fits as well). One that fits as
    well changes nothing."""
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    config = AgentConfig().with_values({"model.n_place": 50, "localisation.doubt_nearby": doubt_nearby})
    ranges = ring_scan(n_rays=env.observation_space["ranges"].shape[0])  # a round room of 2 m
    estimate = np.array([-5.0, 0.0])

    def doubted(look_alike_ring: str) -> bool:
        agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=0)
        two_rooms(agent, estimate, look_alike_ring)
        localisation = agent.localisation
        agent.phase = "trial"
        agent.pi.anchored, agent.pi.estimate = True, estimate.copy()
        localisation.look_alikes, localisation.look_alike_fit = np.array([[10.0, 0.0]]), np.array([0.5])
        localisation.own_fit = localisation.fit = 0.5
        for _ in range(30):
            localisation.check(ranges, 0.0, step=0, dry=False, just_anchored=False)
            if not agent.pi.anchored:
                np.testing.assert_array_equal(agent.pi.ruled_out, [estimate])
                return True
        assert localisation.fit > config.localisation.lost_agreement
        return False

    assert doubted("whole")  # the look-alike's room fits all round, the estimate's only half
    assert not doubted("half")


@pytest.mark.parametrize(("doubt_nearby", "doubted_expected"), [(None, True), ("default", False)])
def test_a_look_alike_fitting_better_than_an_estimate_a_little_off_the_truth_does_not_end_the_anchoring(doubt_nearby, doubted_expected):
    """Two identical round rooms 10 m apart, both mapped all round; the robot at the centre of the
    first, its estimate 0.5 m east of it, and its look-alike place at the centre of the second.
    The look-alike fits the scan better than the estimate; with ``doubt_nearby`` (the default
    model's) the estimate stands, as a place that near it fits as well."""
    estimate_off = 0.5
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    nearby = {} if doubt_nearby == "default" else {"localisation.doubt_nearby": doubt_nearby}
    config = AgentConfig().with_values({"model.n_place": 50, **nearby})
    ranges = ring_scan(n_rays=env.observation_space["ranges"].shape[0])
    centre = np.array([-5.0, 0.0])
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=0)
    two_rooms(agent, centre, "whole")
    for angle in np.linspace(0.0, 2.0 * math.pi, 400, endpoint=False):  # (the east half of the first room too)
        agent.map.hits[agent.map.index(centre[0] + 2.0 * math.cos(angle), centre[1] + 2.0 * math.sin(angle))] = 3
    agent.map.grids_replaced()
    localisation = agent.localisation
    agent.phase = "trial"
    estimate = centre + (estimate_off, 0.0)
    agent.pi.anchored, agent.pi.estimate = True, estimate.copy()
    localisation.look_alikes, localisation.look_alike_fit = np.array([[10.0 - estimate_off, 0.0]]), np.array([0.5])
    localisation.own_fit = localisation.fit = 0.5
    for _ in range(30):
        localisation.check(ranges, 0.0, step=0, dry=False, just_anchored=False)
        if not agent.pi.anchored:
            break
    assert (not agent.pi.anchored) == doubted_expected
    assert doubted_expected or localisation.look_alike_fit[0] > localisation.own_fit + config.localisation.doubt_margin  # (raised)
    if doubt_nearby is not None:  # where the scan holds short readings (the world may have changed) the doubt stands as it is
        localisation._judged[1] = 0.0
        assert localisation._fits_nearby(0.0, ranges, 1.0)
        localisation._judged[1] = config.localisation.changed_share
        assert not localisation._fits_nearby(0.0, ranges, 1.0)


@pytest.mark.parametrize(
    ("lost_crossing", "inner_arc", "changed"), [(0.4, True, True), (None, True, True), (0.4, False, True), (0.4, True, False)]
)
def test_a_scan_that_crosses_walls_the_map_holds_where_the_world_changed_anchors_afresh(lost_crossing, inner_arc, changed):
    """A round room of 2 m round the estimate; with ``changed``, its wall is gone from a quarter of
    the circle, where the map knows the floor free (the scan, 2 m all round, has short readings
    there: something the map does not hold), else mapped all round. With ``inner_arc``, an eighth of
    a circle of wall 1 m from the estimate, which the scan's rays pass through. The running fit
    stays above ``lost_agreement``, so only the share of checks that cross the map's walls where the
    world changed (``lost_crossing``) can end the anchoring: it does, within a few checks, ruling
    out where the estimate was. With no arc, no short readings (a maze's walls clipped at the true
    place), or the rule off, the robot stays anchored."""
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    config = AgentConfig().with_values({"model.n_place": 50, "localisation.lost_crossing": lost_crossing})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=0)
    estimate = np.array([-5.0, 0.0])
    m = agent.map
    for angle in np.linspace(0.0, 2.0 * math.pi, 400, endpoint=False):
        direction = np.array([math.cos(angle), math.sin(angle)])
        if changed and angle >= 1.5 * math.pi:
            for r in np.arange(0.0, 2.5, m.cell / 2):
                m.free[m.index(*(estimate + r * direction))] = 1
        else:
            m.hits[m.index(*(estimate + 2.0 * direction))] = 3
        if inner_arc and angle < math.pi / 4:
            m.hits[m.index(*(estimate + direction))] = 3
    m.grids_replaced()
    agent.phase = "trial"
    agent.pi.anchored, agent.pi.estimate = True, estimate.copy()
    localisation = agent.localisation
    ranges = ring_scan(n_rays=env.observation_space["ranges"].shape[0])
    for step in range(0, 40, 2):
        localisation.check(ranges, 0.0, step=step, dry=False, just_anchored=False)
        if not agent.pi.anchored:
            break
    if lost_crossing is not None and inner_arc and changed:
        assert not agent.pi.anchored and step <= 10
        np.testing.assert_array_equal(agent.pi.ruled_out, [estimate])
    else:
        assert agent.pi.anchored and localisation.fit > config.localisation.lost_agreement


def test_on_anchoring_the_best_fitting_places_far_enough_away_are_picked_as_look_alikes():
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig().with_values({"model.n_place": 50}), seed=0)
    estimate = np.array([-5.0, 0.0])
    two_rooms(agent, estimate, "whole")
    m = agent.map
    for centre in (estimate, estimate + (10.0, 0.0)):  # the rooms' floors known free
        for x in np.arange(-1.5, 1.6, m.cell):
            for y in np.arange(-1.5, 1.6, m.cell):
                if math.hypot(x, y) < 1.6:
                    m.free[m.index(centre[0] + x, centre[1] + y)] = 1
    m.grids_replaced()
    agent.pi.anchored, agent.pi.estimate = True, estimate.copy()
    agent.localisation.check(ring_scan(n_rays=env.observation_space["ranges"].shape[0]), 0.0, step=1, dry=False, just_anchored=True)
    offsets = agent.localisation.look_alikes
    assert 1 <= len(offsets) <= agent.config.localisation.look_alikes and len(offsets) == len(agent.localisation.look_alike_fit)
    radius = agent.config.path_integration.rule_out_radius
    assert np.all(np.hypot(*offsets.T) > radius)  # at least rule_out_radius from the estimate ...
    assert np.linalg.norm(offsets[0] - (10.0, 0.0)) < 0.5  # ... the best the middle of the look-alike room
    assert all(np.linalg.norm(a - b) > radius for i, a in enumerate(offsets) for b in offsets[:i])  # ... and apart
    assert agent.pi.anchored


def thirty_steps_into_a_run(maze: str, values: dict) -> tuple[HippocampalAgent, dict]:
    """An agent after a 1,500-step dry run in ``maze`` and 30 steps of a run from its corner; its last observation."""
    env = make_env(maze, seed=1)
    config = AgentConfig().with_values({"model.dry_run_steps": 1500, **values})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    obs, info = env.reset(options={"goal": [1.2, 1.2], "start": [-1.3, -1.3], "heading": 0.0})
    agent.reset(obs, info)
    for _ in range(30):
        action = agent.act(obs)
        obs, _, _, _, info = env.step(action)
        agent.observe(action, obs, 0.0, False, False, info)
    return agent, obs


@pytest.mark.parametrize(("lost_bump_rate", "facing_a_known_wall"), [(None, False), (0.15, False), (0.15, True)])
def test_a_run_that_keeps_bumping_into_walls_anchors_afresh(small_maze, lost_bump_rate, facing_a_known_wall):
    """Bumps where the map shows free ground mean a look-alike place: once the running mean of
    bumps per step passes ``lost_bump_rate`` (9 bumps in a row at 0.15 over 50 steps), the
    estimate is dropped; with ``None``, never. Bumps into a wall the map holds are explained by it
    and do not count. (The world taken not to change: a bump does not write a wall.)"""
    values = {"localisation.lost_bump_rate": lost_bump_rate, "map.new_wall_evidence": None}
    agent, obs = thirty_steps_into_a_run(small_maze, values)
    assert agent.pi.anchored
    heading = unpack(obs)[2]
    bump_distance = agent.config.map.bump_distance
    if facing_a_known_wall:  # the map holds a wall where the robot bumps
        ahead = agent.pi.estimate + bump_distance * np.array([math.cos(heading), math.sin(heading)])
        agent.map.hits[agent.map.index(*ahead)] = 1000
        agent.map.grids_replaced()
    assert agent.map.wall_near(agent.pi.estimate, heading, bump_distance) == facing_a_known_wall
    still = {**obs, "odometry": np.zeros(2, dtype=np.float32)}  # pushing at a wall: the scan stays, the wheels slip
    anchored = []
    for _ in range(9):
        agent.observe(0, still, 0.0, False, False, {"collision": True})
        anchored.append(agent.pi.anchored)
    expected_drop = lost_bump_rate is not None and not facing_a_known_wall
    assert anchored == [True] * 8 + [False] if expected_drop else anchored == [True] * 9


# ------------------------------------------------------------------ save / load
ESTIMATE = np.array([-5.0, 0.0])


def doubting(seed: int = 0) -> tuple[HippocampalAgent, Localisation]:
    """A localisation that follows two look-alike places (one as good as the estimate, the west
    half of each room mapped) and has counted a bump."""
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig().with_values({"model.n_place": 50}), seed=seed)
    two_rooms(agent, ESTIMATE, "half")
    estimate = ESTIMATE
    agent.pi.anchored, agent.pi.estimate = True, estimate.copy()
    localisation = agent.localisation
    localisation.look_alikes, localisation.look_alike_fit = np.array([[10.0, 0.0], [3.0, 4.0]]), np.array([0.5, 0.1])
    localisation.own_fit = localisation.fit = 0.5
    ranges = ring_scan(n_rays=env.observation_space["ranges"].shape[0])
    for step in range(3):
        localisation.check(ranges, 0.0, step=2 * step, dry=False, just_anchored=False)
        localisation.count_bump(step == 1)
    assert agent.pi.anchored and 0.0 < localisation.bump_rate < 0.1
    return agent, localisation


def test_the_state_of_localisation_loads_into_a_fresh_one_that_doubts_the_same():
    agent, localisation = doubting()
    saved = localisation.state()
    pi = copy.deepcopy(agent.pi)  # (its own belief, so that each may lose it)
    fresh = Localisation(agent.config.localisation, agent.map, pi, agent.max_range, np.random.default_rng(5))
    fresh.load_state(*saved)
    same_state(fresh.state(), saved)
    ranges = ring_scan(n_rays=agent.n_rays)
    two_rooms(agent, ESTIMATE, "whole")  # the look-alike place's room mapped all round: it fits better ...
    for step in range(4, 60, 2):  # ... and both doubt the estimate, at the same step
        localisation.check(ranges, 0.0, step=step, dry=False, just_anchored=False)
        fresh.check(ranges, 0.0, step=step, dry=False, just_anchored=False)
        same_state(fresh.state(), localisation.state())
        assert pi.anchored == agent.pi.anchored
        if not pi.anchored:
            break
    assert not pi.anchored and len(pi.ruled_out) == 1


@pytest.mark.parametrize(
    "spoil",
    [
        lambda state, arrays: arrays.update(look_alikes=np.zeros((3, 2))),
        lambda state, arrays: arrays.update(look_alike_fit=np.array([np.nan, 0.1])),
        lambda state, arrays: state.update(fit="good"),
    ],
    ids=["lengths", "nan", "fit"],
)
def test_a_malformed_localisation_state_raises_value_error(spoil):
    agent, localisation = doubting()
    state, arrays = localisation.state()
    state, arrays = dict(state), dict(arrays)
    spoil(state, arrays)
    fresh = Localisation(agent.config.localisation, agent.map, agent.pi, agent.max_range, np.random.default_rng(0))
    with pytest.raises(ValueError):
        fresh.load_state(state, arrays)


def test_in_a_world_that_may_change_a_bump_on_free_ground_writes_a_wall(small_maze):
    """Well placed in a run, a bump where the map shows free ground is a new obstacle: the map
    holds a wall there at once, later bumps there are explained, and the estimate stays anchored."""
    agent, obs = thirty_steps_into_a_run(small_maze, {})
    assert agent.localisation.trusted
    heading, distance = unpack(obs)[2], agent.config.map.bump_distance
    assert not agent.map.wall_near(agent.pi.estimate, heading, distance)
    still = {**obs, "odometry": np.zeros(2, dtype=np.float32)}
    for _ in range(12):
        agent.observe(0, still, 0.0, False, False, {"collision": True})
    assert agent.map.wall_near(agent.pi.estimate, heading, distance) and agent.pi.anchored


def test_a_bump_writes_no_wall_while_the_scan_crosses_a_wall_the_map_holds(small_maze):
    """The map gains walls only from scans that cross fewer walls it holds than
    ``new_wall_agreement`` allows (a robot a block's width off sees the map's walls through the
    gaps): the same bumps as above, with rays that pass through the map's walls, write nothing,
    though the scan is still good enough to revise the map (``revise_agreement``)."""
    values = {"localisation.revise_agreement": 0.0, "localisation.new_wall_agreement": 1.0}
    agent, obs = thirty_steps_into_a_run(small_maze, values)
    ranges, heading = unpack(obs)[0], unpack(obs)[2]
    through = ranges.copy()
    through[::40] = float(agent.max_range)  # one ray in 40 goes on through the map's walls
    judged = agent.map.scan_agreement(agent.pi.estimate[None, :], heading, through, agent.max_range, short_weight=0.0, judged_only=True)[0]
    assert 0.0 <= judged < 1.0
    assert agent.localisation.placement(through, heading) == (True, False)
    distance = agent.config.map.bump_distance
    assert not agent.map.wall_near(agent.pi.estimate, heading, distance)
    still = {**obs, "ranges": through.astype(obs["ranges"].dtype), "odometry": np.zeros(2, dtype=np.float32)}
    for _ in range(12):
        agent.observe(0, still, 0.0, False, False, {"collision": True})
    assert not agent.map.wall_near(agent.pi.estimate, heading, distance)


@pytest.mark.parametrize("dry_reachable_only", [False, True])
def test_an_anchoring_where_the_dry_runs_ground_cannot_be_walked_to_is_taken_to_be_wrong(dry_reachable_only):
    """The map holds the dry run's round room and a few cells a scan entered 4 m away, beyond the
    room's wall (where a misplaced run wrote them). An estimate anchored there stands on known
    ground; with ``map.dry_reachable_only`` it is taken to be wrong all the same (the robot cannot
    walk there from the ground the dry run found), and the robot anchors afresh."""
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    config = AgentConfig().with_values({"model.n_place": 50, "map.dry_reachable_only": dry_reachable_only})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=0)
    ranges = ring_scan(n_rays=env.observation_space["ranges"].shape[0])  # a round room of 2 m
    agent.map.observe(np.zeros(2), 0.0, ranges, max_range=agent.max_range)
    agent.map.end_dry_run()
    outside = np.array([4.0, 0.0])
    i, j = agent.map.index(*outside)
    agent.map.free[i - 1 : i + 2, j - 1 : j + 2] = 1  # the ghost's first cells
    agent.map.grids_replaced()
    agent.phase = "trial"
    agent.pi.anchored, agent.pi.estimate = True, outside.copy()
    assert agent.map.known_ground(outside)
    agent.localisation.check(ranges, 0.0, step=1, dry=False, just_anchored=True)  # (an odd step: no fit is checked)
    assert agent.pi.anchored != dry_reachable_only


@pytest.mark.parametrize("lost_new_wall_weight", [0.0, 0.5])
def test_while_lost_walls_written_in_runs_count_lost_new_wall_weight(lost_new_wall_weight):
    """A round room of 2 m from the dry run, and a wall a run wrote 1 m east of the centre (a block
    that may have moved since). The samples' weights while lost read the scan's fit with such walls
    counting ``lost_new_wall_weight``; once anchored, the check's fit counts ``new_wall_weight``."""
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    values = {"model.n_place": 50, "localisation.lost_new_wall_weight": lost_new_wall_weight}
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig().with_values(values), seed=0)
    n_rays = env.observation_space["ranges"].shape[0]
    agent.map.observe(np.zeros(2), 0.0, ring_scan(n_rays=n_rays), max_range=agent.max_range)
    i, j = agent.map.index(1.0, 0.0)
    agent.map.hits[i, j - 1 : j + 2] = agent.map.free[i, j - 1 : j + 2] + 1
    agent.map.new_walls[i, j - 1 : j + 2] = True
    agent.map.grids_replaced()
    scan = ring_scan(n_rays=n_rays)
    east = np.cos(np.arange(n_rays) * 2 * math.pi / n_rays) > math.cos(math.radians(20))
    scan[east] = 1.0  # (the block, seen from the centre)
    agent.pi.anchored = False
    points = np.array([[0.0, 0.0], [0.5, 0.5]])

    def fit(weight: float) -> np.ndarray:
        return agent.map.scan_agreement(points, 0.0, scan, agent.max_range, None, 0.25, new_wall_weight=weight)

    assert not np.array_equal(fit(0.0), fit(0.5))  # (rays ending by the run's wall count in the fits)
    likelihood, _ = agent.localisation.evidence(scan, 0.0, dry=False)
    np.testing.assert_allclose(likelihood(points), np.exp(agent.config.localisation.beta * fit(lost_new_wall_weight)))
    np.testing.assert_array_equal(agent.localisation._fit(points, 0.0, scan), fit(agent.config.localisation.new_wall_weight))
