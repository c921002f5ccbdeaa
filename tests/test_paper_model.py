"""The paper's model (:mod:`hippo_agent.paper_model`): preplay and depression (eqs. 8-11), the random
walk, and the model's own saved state. The equations cell by cell are in ``test_cells.py``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from agent_helpers import HEADING, drive_run, make_env, obs_space, same_state

from hippo_agent import AgentConfig, HippocampalAgent, ModelConfig, ReflexConfig
from hippo_agent.paper_model import PaperModel, RandomWalk
from hippo_agent.spaces import to_action


def small_model(seed: int = 0, **changes) -> PaperModel:
    return PaperModel(ModelConfig(**{"n_place": 6, "discrete_rounding": "nearest", **changes}), 720, 10.0, np.random.default_rng(seed))


# ------------------------------------------------------------------ preplay (eqs. 8-11)
def test_preplay_picks_the_direction_of_higher_value():
    model = small_model()
    model.new_goal()
    pc = model.place
    # learnt topology: from cell 0, south-east (direction 7, -45 deg) leads to cell 1, north to cell 2
    pc.set_W_pp(0, 1, 2.0 * np.cos(-math.pi / 4 - model.hd.preferred))
    pc.set_W_pp(0, 2, 2.0 * np.cos(math.pi / 2 - model.hd.preferred))
    model.reward.W_rp[0] = [0.2, 1.0, 0.3, 0, 0, 0]
    model.reward.reset_effective()
    model.goal_rewarded = True
    pc.v = np.array([0.8, 0, 0, 0, 0, 0])
    heading = model.preplay()
    assert heading is not None and -math.pi / 2 < heading < 0  # toward the higher value, south-east
    assert to_action(heading, "discrete", 8, model.config.discrete_rounding, model.rng) == 7
    assert model.last_values.shape == (8,) and model.last_values[7] == model.last_values.max()  # eq. 9's values, kept
    assert model.reward.W_eff[0] == 0.2  # preplay itself depresses nothing ...
    model.depress()
    assert model.reward.W_eff[0] == pytest.approx(0.2 * (1 - 0.8 * model.config.lambda_))  # ... eq. 11 does
    # with no value anywhere (below xi) the agent explores
    model.reward.W_eff[:] = 0.0
    assert model.preplay() is None


def test_preplay_is_silent_before_the_goal_was_rewarded_and_where_the_reward_map_is():
    model = small_model()
    assert model.preplay() is None  # no reward cell yet
    model.new_goal()
    model.reward.W_rp[0] = [0.0, 1.0, 0.0, 0, 0, 0]
    model.reward.reset_effective()
    model.place.set_W_pp(0, 1, np.full(8, 2.0))
    model.place.v = np.array([0.8, 0, 0, 0, 0, 0])
    assert model.preplay() is None  # not rewarded yet in this trial
    model.goal_rewarded = True
    assert model.preplay() is None  # the value here is 0: the reward map never reached this place
    model.reward.W_rp[0, 0] = model.reward.W_eff[0] = 0.5
    assert model.preplay() is not None


# ------------------------------------------------------------------ the random walk
def test_the_walk_turns_between_segments_of_its_lengths():
    config = ModelConfig(segment_min=3, segment_max=4, turn_sigma_deg=30.0)
    walk = RandomWalk(config, np.random.default_rng(0))
    walk.new_segment(1.0)
    assert 3 <= walk.segment_left <= 4
    headings = [walk.step() for _ in range(200)]
    changes = np.flatnonzero(np.diff(headings) != 0)
    assert set(np.diff(changes)) <= {3, 4}  # a turn every 3 or 4 steps
    assert headings[0] == 1.0 and len(set(headings)) > 40


def test_the_walk_goes_on_the_way_another_behaviour_steered():
    walk = RandomWalk(ModelConfig(), np.random.default_rng(0))
    walk.new_segment(0.0)
    left = walk.segment_left
    walk.follow(2.0)  # (directed exploration: the segment goes on)
    assert walk.heading == 2.0 and walk.segment_left == left
    state = walk.rng.bit_generator.state
    walk.follow(-1.0, length_later=True)  # (homing: the length is drawn when the walk next steps)
    assert walk.segment_left == -1 and walk.rng.bit_generator.state == state
    assert walk.step() == -1.0 and 4 <= walk.segment_left <= 9


def test_exploration_is_a_random_walk_of_straight_segments():
    """The paper's exploration (no map, no directed exploration): straight segments, all directions, the arena covered."""
    env = make_env(seed=1)
    config = AgentConfig(
        model=ModelConfig(n_place=100, discrete_rounding="nearest"),
        reflexes=ReflexConfig(escape_after="exploiting"),
        map=None,
        localisation=None,
        exploration=None,
        homing=None,
        worlds=None,
    )
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=1)
    _, positions, actions = drive_run(env, agent, options={"goal": None}, max_steps=2000)
    actions = np.array(actions)
    assert set(actions) == set(range(8))  # all directions get used
    runs = np.diff(np.flatnonzero(np.diff(actions) != 0))
    assert np.median(runs) >= 4  # straight segments, not a jitter
    assert agent.episode_stats["explore"] == 2000 and agent.episode_stats["bumps"] > 0
    spread = positions.max(axis=0) - positions.min(axis=0)
    assert np.all(spread > 5.0)  # it covers the 10 m arena


def test_bump_starts_a_new_segment_in_a_random_direction():
    agent = HippocampalAgent(obs_space(), HEADING, AgentConfig().with_values({"model.n_place": 20}), seed=0)
    ranges = np.full(720, 3.0, np.float32)
    obs = {"ranges": ranges, "heading": np.array([1.0, 0.0], np.float32), "odometry": np.zeros(2, np.float32)}
    agent.reset(obs, {})
    headings = set()
    for _ in range(20):
        agent.observe(agent.act(obs), obs, 0.0, False, False, {"collision": True})
        headings.add(round(agent.model.walk.heading, 6))
    assert len(headings) == 20


# ------------------------------------------------------------------ save / load
def lived_model(seed: int = 3, extra: int = 0) -> PaperModel:
    """A model that has sensed, learnt, replayed and preplayed on random scans (and grown ``extra`` cells)."""
    model = PaperModel(ModelConfig(n_place=40, n_bvc_distances=10), 72, 10.0, np.random.default_rng(seed))
    rng = np.random.default_rng(seed + 1)
    model.new_goal()
    for step in range(60):
        heading = rng.uniform(-math.pi, math.pi)
        b, h = model.sense(rng.uniform(0.5, 10.0, 72).astype(np.float32), np.array([math.cos(heading), math.sin(heading)]), heading)
        if step == 0:
            model.settle(b)
            model.start_run(h, heading)
        model.step(b)
        model.learn(b, h, trusted=True, dry=False, bumped=False)
        model.walk.step()
    if extra:
        model.grow(extra)
    assert model.replay()
    model.preplay()
    model.depress()
    return model


@pytest.mark.parametrize("extra", [0, 5])
def test_the_state_of_the_model_loads_into_a_fresh_one(extra):
    model = lived_model(extra=extra)
    saved = model.state()
    assert saved[0]["place_cells"] == 40 + extra and saved[0]["goal_rewarded"]
    fresh = PaperModel(model.config, 72, 10.0, np.random.default_rng(99))
    fresh.grow(extra)  # (the agent grows the cells before the state is loaded)
    fresh.new_goal()
    fresh.load_state(*saved)
    same_state(fresh.state(), saved)
    np.testing.assert_array_equal(fresh.place.W_pp, model.place.W_pp)
    np.testing.assert_array_equal(fresh.place.imagined_values(fresh.reward.W_eff), model.place.imagined_values(model.reward.W_eff))
    assert (fresh.walk.heading, fresh.walk.segment_left) == (model.walk.heading, model.walk.segment_left)


@pytest.mark.parametrize(
    "spoil",
    [
        lambda meta, arrays: arrays.update(W_pb=arrays["W_pb"][:-1]),
        lambda meta, arrays: arrays.update(v=np.full_like(arrays["v"], np.nan)),
        lambda meta, arrays: arrays.pop("trace"),
        lambda meta, arrays: arrays.update(W_rp=np.zeros((1, 7))),
        lambda meta, arrays: arrays.update(W_rp=np.full_like(arrays["W_rp"], np.inf)),
        lambda meta, arrays: arrays.update(W_pp_slots=np.full_like(arrays["W_pp_slots"], np.nan)),
        lambda meta, arrays: arrays.update(W_pp_cells=arrays["W_pp_cells"][:-1]),
        lambda meta, arrays: arrays.update(W_pp_cells=arrays["W_pp_cells"] + 1000),
        lambda meta, arrays: arrays.update(last_values=np.zeros(3)),
        lambda meta, arrays: meta["walk"].update(segment_left="many"),
    ],
    ids=[
        "W_pb-shape",
        "v-nan",
        "trace-missing",
        "W_rp-shape",
        "W_rp-inf",
        "W_pp-nan",
        "W_pp-cells",
        "W_pp-cell-range",
        "last_values",
        "walk",
    ],
)
def test_a_malformed_model_state_raises_value_error(spoil):
    meta, arrays = lived_model().state()
    arrays = {name: np.array(value) for name, value in arrays.items()}
    meta = {**meta, "walk": dict(meta["walk"])}
    spoil(meta, arrays)
    fresh = PaperModel(ModelConfig(n_place=40, n_bvc_distances=10), 72, 10.0, np.random.default_rng(0))
    with pytest.raises(ValueError):
        fresh.load_state(meta, arrays)
