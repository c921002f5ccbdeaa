"""Path integration: the env's odometry sensor, the integrator, and the agent that uses them."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from agent_helpers import same_state
from gymnasium.utils.env_checker import check_env

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_agent import AgentConfig, HippocampalAgent, ModelConfig, PathIntegrationConfig
from hippo_agent.cells import PlaceCells
from hippo_agent.faculties.path_integration import PathIntegrator


# ------------------------------------------------------------------ the odometry sensor
def test_odometry_is_opt_in_and_leaves_the_default_observation_alone():
    plain = gym.make("HippoMaze-v0")
    with_odometry = gym.make("HippoMaze-v0", odometry=True)
    assert "odometry" not in plain.observation_space.spaces
    assert with_odometry.observation_space["odometry"].shape == (2,)
    a, _ = plain.reset(seed=3)
    b, _ = with_odometry.reset(seed=3)
    np.testing.assert_array_equal(a["ranges"], b["ranges"])
    for action in (0, 3, 5, 5, 1):
        a, *_ = plain.step(action)
        b, *_ = with_odometry.step(action)
        np.testing.assert_array_equal(a["ranges"], b["ranges"])  # same trajectory: no extra random draws


def test_odometry_integrates_to_the_true_displacement():
    env = gym.make("HippoMaze-v0", maze="maze2", odometry=True)
    obs, info = env.reset(seed=0, options={"goal": None})
    np.testing.assert_array_equal(obs["odometry"], [0.0, 0.0])
    start, estimate = np.array(info["position"]), np.zeros(2)
    rng = np.random.default_rng(0)
    bumps = 0
    for _ in range(1500):
        obs, _, _, _, info = env.step(int(rng.integers(8)))
        bumps += info["collision"]
        (c, s), (forward, left) = obs["heading"].astype(float), obs["odometry"].astype(float)
        estimate += (c * forward - s * left, s * forward + c * left)
    assert bumps > 10  # the walk slid along walls too
    assert np.linalg.norm(estimate - (np.array(info["position"]) - start)) < 1e-3


def test_odometry_noise_scales_with_the_distance_moved():
    env = gym.make("HippoMaze-v0", odometry=True, odometry_noise=0.1)
    env.reset(seed=0, options={"start": [0.0, 0.0], "heading": 0.0})
    forwards = [env.step(0)[0]["odometry"][0] for _ in range(20)]
    assert np.std(forwards) > 0.003 and abs(np.mean(forwards) - 0.15) < 0.02


def test_env_checker_passes_with_odometry():
    check_env(gym.make("HippoMaze-v0", odometry=True).unwrapped, skip_render_check=True)


@pytest.mark.parametrize(
    "kwargs,error", [({"odometry": 1}, TypeError), ({"odometry_noise": -0.1}, ValueError), ({"heading_noise": float("nan")}, ValueError)]
)
def test_bad_sensor_arguments_are_rejected(kwargs, error):
    with pytest.raises(error, match=next(iter(kwargs))):
        gym.make("HippoMaze-v0", **kwargs)


# ------------------------------------------------------------------ the integrator
def integrator(lag: float = 0.0, n_place: int = 10, **kw):
    """A path integrator of 100 samples with no motion noise and no lag, and without the default
    model's aids while lost (no proposals, the same vote floor, no collapse on anchoring, nothing
    ruled out) unless ``kw`` turns them on."""
    args = {
        "particles": 100,
        "motion_noise": 0.0,
        "min_motion_noise": 0.0,
        "vote_sigma": 0.4,
        "anchor_radius": 0.3,
        "anchor_weight": 0.8,
        "redraw_fraction": 0.2,
        "min_anchor_steps": 0,
        "vote_floor": 1e-3,
        "lost_vote_floor": 1e-3,
        "min_mapped": 0.8,
        "resample_ess": 0.5,
        "proposal_share": 0.0,
        "collapse_on_anchor": False,
        "rule_out_radius": 0.0,
        **kw,
    }
    pi = PathIntegrator(PathIntegrationConfig(**args), n_place, 1.0, np.random.default_rng(0))  # (k = 1: no lag)
    pi.lag = lag  # (as eq. 3 with k = 1 / (1 + lag) gives it)
    return pi


def test_first_run_sets_the_frame_and_odometry_moves_it():
    pi = integrator()
    pi.start_run()
    assert pi.anchored and np.array_equal(pi.estimate, [0.0, 0.0])
    for _ in range(10):
        pi.move(np.array([0.1, 0.05]))
        pi.correct(np.zeros(0), np.zeros((0, 2)))  # no evidence: the belief keeps its weights
    np.testing.assert_allclose(pi.estimate, [1.0, 0.5])


def test_a_kidnapped_integrator_anchors_on_the_vote_not_on_where_it_was():
    pi = integrator()
    pi.start_run()
    pi.move(np.array([3.0, 3.0]))
    pi.correct(np.zeros(0), np.zeros((0, 2)))
    pi.start_run()  # put down elsewhere
    assert not pi.anchored
    pi.correct(np.zeros(0), np.zeros((0, 2)))
    assert not pi.anchored  # no evidence yet: the old place is no anchor
    centres = np.array([[-1.0, 2.0], [-1.1, 2.1], [-0.9, 1.9]])
    for _ in range(20):
        pi.correct(np.array([0.5, 0.4, 0.3]), centres)
    assert pi.anchored
    assert np.linalg.norm(pi.estimate - [-1.0, 2.0]) < 0.15


def test_two_look_alike_places_stay_unresolved_until_the_senses_differ():
    pi = integrator()
    pi.start_run()
    pi.start_run()
    twins = np.array([[-2.0, 0.0], [2.0, 0.0]])
    for _ in range(3):
        pi.correct(np.array([0.5, 0.5]), twins)
    assert not pi.anchored  # half the belief at each twin
    for _ in range(10):
        pi.move(np.array([0.0, 0.1]))
        pi.correct(np.array([0.5]), np.array([[2.0, 0.1 * (_ + 1)]]))  # now only the east one fits
    assert pi.anchored and pi.estimate[0] > 1.5


def test_a_place_the_vote_leaves_out_wins_when_proposed_and_the_map_fits_it_better():
    """Look-alike rooms: the place code votes for the wrong room only. Proposals from the map put
    samples in the right one, the map's fit there (the likelihood) outweighs the weakened vote,
    and once anchored there the vote for the wrong room no longer pulls the estimate away."""
    wrong, right = np.array([-2.5, 0.0]), np.array([2.5, 0.0])

    def fit(particles):  # the scan fits the map best at the right place
        return 1.0 + 9.0 * np.exp(-np.sum((particles - right) ** 2, axis=1) / (2 * 0.3**2))

    def run(**kw):
        pi = integrator(**kw)
        pi.start_run()
        pi.start_run()
        for _ in range(25):
            pi.correct(np.array([0.5]), wrong[None, :], likelihood=fit, proposals=lambda: right[None, :])
        return pi

    unaided = run()  # no proposals drawn, the vote's floor low: the right room never holds a sample
    assert unaided.anchored and np.linalg.norm(unaided.estimate - wrong) < 0.5
    aided = run(proposal_share=0.5, lost_vote_floor=0.2, collapse_on_anchor=True)
    assert aided.anchored and np.linalg.norm(aided.estimate - right) < 0.5


def test_a_belief_spread_round_one_place_by_the_vote_anchors_there_without_delay():
    """With the agent's defaults, a kidnapped integrator whose vote comes from cells round one place
    (and a little from a look-alike 5 m away) anchors there as soon as it may (``min_anchor_steps``):
    its candidate place is as wide as the vote spreads the samples."""
    config = AgentConfig()
    for seed in range(5):
        pi = PathIntegrator(config.path_integration, 14, config.model.k, np.random.default_rng(seed))
        pi.start_run()
        pi.start_run()
        cells = np.random.default_rng(100 + seed)
        centres = np.vstack((cells.normal([0.0, 0.0], 0.3, (12, 2)), cells.normal([5.0, 0.0], 0.3, (2, 2))))
        for _ in range(config.path_integration.min_anchor_steps):
            pi.correct(np.full(len(centres), 0.5), centres)
        assert pi.anchored and np.linalg.norm(pi.estimate) < 0.4


def test_an_estimate_found_wrong_is_ruled_out_when_anchoring_afresh():
    """Twin rooms whose scans favour the wrong one: anchored there and found wrong (a search that
    failed), the integrator anchors afresh at the other twin only if it rules out where it was,
    carried along by the odometry while it re-anchors."""
    wrong, right = np.array([-2.5, 0.0]), np.array([2.5, 0.0])

    def fit(particles):  # the scans fit the wrong twin a little better
        return 1.0 + 0.5 * np.exp(-np.sum((particles - wrong) ** 2, axis=1) / (2 * 0.5**2))

    def anchor_afresh(rule_out):
        pi = integrator(proposal_share=0.5, lost_vote_floor=0.2, collapse_on_anchor=True, rule_out_radius=2.0)
        pi.start_run()
        pi.start_run()
        twins = np.vstack((wrong, right))
        for _ in range(25):
            pi.correct(np.array([0.5, 0.5]), twins, likelihood=fit)
        assert pi.anchored and np.linalg.norm(pi.estimate - wrong) < 0.5
        pi.lose(rule_out=rule_out)
        step = np.array([0.0, 0.1])
        for i in range(1, 26):
            pi.move(step)
            moved = i * step  # the rooms as the odometry now places them
            pi.correct(np.array([0.5, 0.5]), twins + moved, likelihood=lambda p, moved=moved: fit(p - moved))
        return pi

    again = anchor_afresh(rule_out=False)
    assert again.anchored and np.linalg.norm(again.estimate - (wrong + [0.0, 2.5])) < 0.5
    ruled = anchor_afresh(rule_out=True)
    assert ruled.anchored and np.linalg.norm(ruled.estimate - (right + [0.0, 2.5])) < 0.5
    assert len(ruled.ruled_out) == 0  # anchored again: the evidence was used up


def test_cells_that_also_fire_at_a_look_alike_place_vote_weakly():
    pi = integrator()
    pi.start_run()
    pi.start_run()
    # two cells vote for the west place, one for the east; the two have been seen firing 4 m from
    # their centres (they fire at a look-alike place too), the east one only at its centre
    rates, centres = np.array([0.5, 0.5, 0.5]), np.array([[-2.0, 0.0], [-2.05, 0.0], [2.0, 0.0]])
    for _ in range(30):
        pi.correct(rates, centres, 1.0, np.array([16.0, 16.0, 0.01]))
    assert pi.anchored and pi.estimate[0] > 1.5
    without = integrator()
    without.start_run()
    without.start_run()
    for _ in range(30):
        without.correct(rates, centres)
    assert without.anchored and without.estimate[0] < -1.5  # every vote alike: the majority wins


def place_cells(n: int) -> PlaceCells:
    return PlaceCells(n, 4, 8, np.random.default_rng(0), **ModelConfig().place_kwargs())


def test_place_cells_learn_how_far_from_their_centre_the_boundary_code_fires_them():
    pi = integrator(n_place=3)
    place = place_cells(3)
    pi.centres[:] = [[0.0, 0.0], [1.0, 0.0], [5.0, 5.0]]
    pi.centre_mass[:] = [1.0, 1.0, 0.0]  # the third has no centre yet
    assert pi.config.centre_max_mass == 1000.0
    for position in ([0.0, 0.0], [4.0, 0.0]) * 20:  # cell 0 fires at its centre and 4 m away, on boundary input alone
        place.v_sense[:] = [1.0, 0.0, 1.0]
        place.v[:] = 0.0  # (no rate: the centres stay)
        pi.estimate = np.array(position)
        pi.learn_centres(place)
    np.testing.assert_array_equal(pi.centres, [[0.0, 0.0], [1.0, 0.0], [5.0, 5.0]])
    assert 6.0 < pi.spread[0] < 10.0  # about the mean of 0 and 16 m^2
    assert pi.spread[1] == 0.0 and pi.spread[2] == 0.0  # silent, and without a centre


def test_an_active_cell_learns_its_centre_where_the_estimate_was_when_its_rate_formed():
    pi = integrator(lag=1.0, n_place=3)
    place = place_cells(3)
    pi.estimate, pi.last_step = np.array([1.0, 2.0]), np.array([0.1, 0.0])  # one step ago it was at (0.9, 2)
    place.v[:] = [0.5, 0.0, 0.25]
    pi.learn_centres(place)
    np.testing.assert_allclose(pi.centres, [[0.9, 2.0], [0.0, 0.0], [0.9, 2.0]])  # a first centre: where it fired
    np.testing.assert_array_equal(pi.centre_mass, [0.5, 0.0, 0.25])
    pi.estimate = np.array([2.1, 2.0])  # now at (2, 2), one step ago
    place.v[:] = [0.5, 0.0, 0.0]
    pi.learn_centres(place)
    np.testing.assert_allclose(pi.centres[0], [1.45, 2.0])  # the running mean of the two, weighted by the rates


def test_a_place_cell_is_silenced_beyond_its_field_radius():
    gain, sigma, threshold = 3.0, 0.7, 0.7
    pi = integrator(n_place=3, gain=gain, sigma=sigma, threshold=threshold, field_radius=2.0, far_inhibition=10.0)
    pi.centres[:] = [[0.0, 0.0], [1.5, 0.0], [3.0, 0.0]]
    pi.centre_mass[:] = [1.0, 1.0, 0.0]  # the third has no centre yet
    drive = pi.drive(np.zeros(2))
    near = gain * (np.exp(-(np.array([0.0, 1.5]) ** 2) / (2 * sigma**2)) - threshold)
    np.testing.assert_allclose(drive[:2], near)  # within the radius: the Gaussian drive alone
    assert drive[2] == 0.0  # no centre, no drive
    farther = pi.drive(np.array([-1.0, 0.0]))
    assert farther[1] == pytest.approx(gain * (np.exp(-(2.5**2) / (2 * sigma**2)) - threshold) - 10.0)
    assert farther[0] > -gain  # cell 0 is 1 m away: not silenced
    pi.estimate = np.array([-1.0, 0.0])
    np.testing.assert_array_equal(pi.drive(), farther)  # (no position: the estimate's)


@pytest.mark.parametrize("sigma, threshold", [(0.7, 0.7), (0.3, 0.05), (1.5, 0.9), (0.7, 1e-6)])
def test_the_path_integration_drive_skips_only_exponentials_too_small_to_change_it(sigma, threshold):
    """``drive`` does not compute the Gaussian of a cell so far away that subtracting the threshold
    from it would leave the threshold exactly: every cell's drive, at every distance up to and past
    that bound, equals the formula computed in full."""
    n = 4000
    gain = 3.0
    pi = integrator(n_place=n, gain=gain, sigma=sigma, threshold=threshold, far_inhibition=0.0)
    two_var = 2.0 * sigma * sigma
    bound = math.sqrt(two_var * (54.0 * math.log(2.0) - math.log(threshold) + 1.0))
    distance = np.random.default_rng(1).uniform(0.0, 2.0 * bound, n)
    distance[:10] = bound * (1.0 + np.array([-1e-3, -1e-9, 0.0, 1e-9, 1e-3, -0.05, -0.2, -0.5, 0.05, 0.5]))
    pi.centres[:] = np.column_stack((distance, np.zeros(n))) + 0.3
    pi.centre_mass[:] = 1.0
    drive = pi.drive(np.array([0.3, 0.3]))
    dx, dy = pi.centres[:, 0] - 0.3, pi.centres[:, 1] - 0.3
    full = [gain * (math.exp(-(x * x + y * y) / two_var) - threshold) for x, y in zip(dx.tolist(), dy.tolist())]
    np.testing.assert_array_equal(drive, full)
    assert np.count_nonzero(distance > bound) > n // 3  # (a third of the cells skipped)


def test_the_vote_is_of_cells_active_on_boundary_input_alone_whose_centres_have_mass_enough():
    pi = integrator(n_place=4, min_mass=1.0)
    place = place_cells(4)
    pi.centres[:] = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]
    pi.centre_mass[:] = [2.0, 0.5, 1.0, 5.0]
    pi.spread[:] = [0.1, 0.2, 0.3, 0.4]
    place.v_sense[:] = [0.4, 0.3, 0.2, 0.0]
    place.v[:] = [0.0, 0.0, 0.0, 0.9]  # (the rates with path integration's drive do not vote)
    rates, centres, share, spreads = pi.vote(place)
    np.testing.assert_array_equal(rates, [0.4, 0.2])  # cell 1: too little mass; cell 3: silent on boundary input
    np.testing.assert_array_equal(centres, [[0.0, 0.0], [2.0, 0.0]])
    np.testing.assert_array_equal(spreads, [0.1, 0.3])
    assert share == pytest.approx(0.6 / 0.9)


def test_the_trace_holds_nothing_from_before_the_robot_knows_where_it_is():
    """A run's code before anchoring comes from the boundary code alone and may be a look-alike
    place's: linking it (eq. 7) to the anchored code would join two distant places."""
    env = gym.make("HippoMaze-v0", maze="maze2", odometry=True)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(model=ModelConfig(n_place=400, dry_run_steps=0)), seed=0)
    for run in range(2):  # the first run sets the frame; the second starts lost
        obs, info = env.reset(seed=run, options={"goal": None})
        agent.reset(obs, info)
        traced_while_lost = []
        for _ in range(60):
            action = agent.act(obs)
            obs, reward, terminated, truncated, info = env.step(action)
            agent.observe(action, obs, reward, terminated, truncated, info)
            if not agent.pi.anchored:
                traced_while_lost.append(agent.place.trace.sum())
    assert traced_while_lost and max(traced_while_lost) == 0.0
    assert agent.pi.anchored and agent.place.trace.sum() > 0.0  # anchored: the trace runs again


# ------------------------------------------------------------------ the agent
def test_the_default_agent_needs_odometry_and_says_how_to_get_it():
    env = gym.make("HippoMaze-v0")
    with pytest.raises(ValueError, match="odometry=True.*AgentConfig.paper"):
        HippocampalAgent(env.observation_space, env.action_space)
    HippocampalAgent(env.observation_space, env.action_space, AgentConfig.paper())  # the paper's model does not


def test_the_agent_keeps_its_estimate_within_a_few_centimetres_while_exploring():
    env = gym.make("HippoMaze-v0", maze="maze2", odometry=True)
    env.reset(seed=0, options={"goal": None})
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig(model=ModelConfig(n_place=400, dry_run_steps=0)), seed=0)
    obs, info = env.reset(options={"goal": None})
    agent.reset(obs, info)
    origin, errors = np.array(info["position"]), []
    for _ in range(800):
        action = agent.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        errors.append(np.linalg.norm(agent.pi.estimate - (np.array(info["position"]) - origin)))
    assert agent.pi.anchored
    assert np.median(errors) < 0.1 and max(errors) < 0.5
    assert (agent.pi.centre_mass > 0).sum() > 30  # cells learnt where they fire


def test_the_vote_and_the_estimate_are_the_formulas_written_in_numpy():
    pi = integrator(lag=2.0)
    pi.start_run()
    rng = np.random.default_rng(1)
    pi.particles = rng.normal(0.0, 0.5, (100, 2))
    pi.weights = rng.uniform(0.5, 1.0, 100)
    pi.weights /= pi.weights.sum()
    pi.last_step = np.array([0.05, -0.02])
    rates, centres, spreads = rng.uniform(0.1, 0.9, 4), rng.normal(0.0, 0.5, (4, 2)), rng.uniform(0.0, 0.3, 4)
    before = pi.weights.copy()
    pi.correct(rates, centres, 1.0, spreads)
    # each cell's normalised Gaussian vote around its centre, where the sample was lag steps ago
    variance = 0.4**2 + spreads
    d2 = (((pi.particles - 2.0 * pi.last_step)[:, None, :] - centres[None]) ** 2).sum(axis=2)
    vote = np.exp(-d2 / (2 * variance)) @ (rates * 0.4**2 / variance) / rates.sum()
    w = before * (vote + 1e-3)
    w /= w.sum()
    assert 1.0 / np.sum(w**2) >= 50  # no resampling happened, so the weights compare one to one
    np.testing.assert_allclose(pi.weights, w, rtol=1e-12)
    near = np.linalg.norm(pi.particles - pi.particles[np.argmax(w)], axis=1) <= 0.3
    np.testing.assert_allclose(pi.estimate, w[near] @ pi.particles[near] / w[near].sum(), rtol=1e-12)
    assert pi.confidence == pytest.approx(w[near].sum(), rel=1e-12)


def test_an_anchored_correction_by_the_vote_is_the_general_correction_bit_for_bit():
    # two copies of one anchored belief, one corrected by correct(*vote(place)), the other by correct_anchored(place):
    # votes heeded, votes ignored at the edge of the map (a cell active without a centre), none at all, and resamplings
    beliefs = [integrator(n_place=6, min_motion_noise=0.05, particles=200, resample_ess=0.9) for _ in range(2)]
    place = place_cells(6)
    for pi in beliefs:
        pi.start_run()
        pi.centres[:] = [[0.0, 0.0], [0.5, 0.1], [1.0, 0.3], [1.5, 0.2], [2.0, 0.0], [0.0, 0.0]]
        pi.centre_mass[:] = [5.0, 5.0, 5.0, 5.0, 5.0, 0.0]
        pi.spread[:] = [0.0, 0.1, 0.0, 0.3, 0.0, 0.0]
    rng = np.random.default_rng(3)
    for step in range(40):
        place.v_sense[:] = np.where(rng.random(6) < 0.4, rng.random(6), 0.0)
        for pi, by_vote in zip(beliefs, (True, False)):
            assert pi.anchored
            pi.move(np.array([0.05, 0.01]))
            if by_vote:
                pi.correct(*pi.vote(place))
            else:
                pi.correct_anchored(place)
        same_state(beliefs[1].state(), beliefs[0].state())
        np.testing.assert_array_equal(beliefs[1].estimate, beliefs[0].estimate)
    beliefs[0].lose()
    with pytest.raises(ValueError, match="anchored"):
        beliefs[0].correct_anchored(place)


# ------------------------------------------------------------------ save / load
def kidnapped(n_place: int = 5) -> PathIntegrator:
    """An integrator with centres learnt, anchored, found wrong (a place ruled out) and moved on while lost."""
    pi = integrator(n_place=n_place, rule_out_radius=1.0, min_motion_noise=0.01)
    pi.start_run()
    place = place_cells(n_place)
    for step in range(10):
        pi.move(np.array([0.1, 0.05]))
        place.v[:] = place.v_sense[:] = np.where(np.arange(n_place) == step % n_place, 0.6, 0.0)
        pi.learn_centres(place)
        pi.correct(*pi.vote(place))
    pi.lose(rule_out=True)
    pi.move(np.array([0.0, 0.1]))
    pi.correct(*pi.vote(place))
    assert not pi.anchored and len(pi.ruled_out) == 1 and np.all(pi.centre_mass > 0) and np.any(pi.spread > 0)
    return pi


def test_the_state_of_path_integration_loads_into_a_fresh_integrator_that_goes_on_the_same():
    pi = kidnapped()
    saved = pi.state()
    fresh = PathIntegrator(pi.config, 5, 1.0, np.random.default_rng(123))
    fresh.load_state(*saved)
    same_state(fresh.state(), saved)
    fresh.rng.bit_generator.state = pi.rng.bit_generator.state  # (the agent restores its one generator)
    place = place_cells(5)
    place.v_sense[:] = [0.0, 0.0, 0.5, 0.5, 0.0]
    for belief in (pi, fresh):
        for _ in range(8):
            belief.move(np.array([0.05, 0.0]))
            belief.correct(*belief.vote(place))
    same_state(fresh.state(), pi.state())
    np.testing.assert_array_equal(fresh.drive(), pi.drive())


@pytest.mark.parametrize(
    "spoil",
    [
        lambda state, arrays: arrays.update(centres=arrays["centres"][:-1]),
        lambda state, arrays: arrays.update(particles=np.full_like(arrays["particles"], np.nan)),
        lambda state, arrays: arrays.pop("weights"),
        lambda state, arrays: state.update(ruled_out=[[0.0, float("inf")]]),
        lambda state, arrays: state.update(ruled_out=[1.0, 2.0, 3.0]),
        lambda state, arrays: state.update(lost_steps="few"),
    ],
    ids=["centres-shape", "particles-nan", "weights-missing", "ruled-out-inf", "ruled-out-shape", "lost_steps"],
)
def test_a_malformed_path_integration_state_raises_value_error(spoil):
    state, arrays = kidnapped().state()
    state, arrays = dict(state), dict(arrays)
    spoil(state, arrays)
    with pytest.raises(ValueError):
        PathIntegrator(kidnapped().config, 5, 1.0, np.random.default_rng(0)).load_state(state, arrays)
