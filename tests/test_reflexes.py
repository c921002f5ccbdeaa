"""The reflexes (:mod:`hippo_agent.faculties.reflexes`): the escape after a bump and clearance from walls."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from agent_helpers import HEADING, obs_space, same_state

from hippo_agent import AgentConfig, HippocampalAgent, ReflexConfig
from hippo_agent.faculties.reflexes import Reflexes


# ------------------------------------------------------------------ the escape
def test_bump_while_exploiting_escapes_for_a_few_steps():
    cfg = AgentConfig.paper().with_values({"model.n_place": 6, "reflexes.escape_steps": 3})  # no path integration: rates held fixed below
    agent = HippocampalAgent(obs_space(), HEADING, cfg, seed=0)
    obs = {"ranges": np.full(720, 3.0, np.float32), "heading": np.array([1.0, 0.0], np.float32)}
    agent.reset(obs, {})
    agent.start_trial(0)
    agent.model.goal_rewarded = True
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


@pytest.mark.parametrize("escape_after", ["any bump", "exploiting"])
def test_which_bumps_start_an_escape(escape_after):
    reflexes = Reflexes(ReflexConfig(escape_steps=2, escape_after=escape_after))
    for decision in ("explore", "home"):
        reflexes.bumped(decision)
        assert reflexes.escape_left == (2 if escape_after == "any bump" else 0), decision
        reflexes.reset()
    reflexes.bumped("exploit")
    assert [reflexes.escape() for _ in range(3)] == [True, True, False]
    reflexes.bumped("exploit")
    reflexes.reset()  # a new run: no escape under way
    assert not reflexes.escape()


# ------------------------------------------------------------------ clearance
def test_an_exploiting_heading_into_a_near_wall_turns_to_the_nearest_clear_one():
    reflexes = Reflexes(ReflexConfig())  # clearance 0.6 m
    ranges = np.full(720, 3.0, dtype=np.float32)
    ranges[690:720] = ranges[0:31] = 0.3  # a wall 0.3 m ahead, 15 degrees either side of east (ray 0 = the facing)
    turned = reflexes.clear(0.0, ranges, 0.0)
    assert math.isclose(abs(turned), math.radians(45.0))  # at 15 and 30 degrees its 30 degree cone still meets the wall
    assert reflexes.clear(math.pi, ranges, 0.0) == math.pi  # open: unchanged
    assert math.isclose(reflexes.clear(math.pi, ranges, math.pi), math.pi + math.radians(45.0))  # the wall ahead of the facing
    assert reflexes.clear(1.0, np.full(720, 0.3, dtype=np.float32), 0.0) == 1.0  # blocked everywhere: unchanged
    assert Reflexes(ReflexConfig(clearance=None)).clear(0.0, ranges, 0.0) == 0.0  # off: unchanged


def test_the_agent_turns_an_exploiting_heading_clear_of_the_wall_it_faces():
    """Preplay steers about east, into a wall 0.3 m ahead; with the default reflexes the agent
    turns clear of it, with ``clearance=None`` it heads where preplay said."""
    space = gym.spaces.Dict(
        {"ranges": gym.spaces.Box(0.0, 10.0, (720,), np.float32), "heading": gym.spaces.Box(-1.0, 1.0, (2,), np.float32)}
    )
    ranges = np.full(720, 3.0, np.float32)
    ranges[690:720] = ranges[0:31] = 0.3
    obs = {"ranges": ranges, "heading": np.array([1.0, 0.0], np.float32)}
    headings = []
    for clearance in (0.6, None):
        config = AgentConfig.paper().with_values({"model.n_place": 6, "reflexes.clearance": clearance})
        agent = HippocampalAgent(space, HEADING, config, seed=0)
        agent.reset(obs, {})
        agent.start_trial(0)
        agent.model.goal_rewarded = True
        agent.place.set_W_pp(0, 1, 2.0 * np.cos(0.0 - agent.hd.preferred))  # east leads to cell 1, which holds value
        agent.reward.W_rp[0] = [0.5, 1.0, 0, 0, 0, 0]
        agent.reward.reset_effective()
        agent.place.v = np.array([0.8, 0, 0, 0, 0, 0])
        headings.append(float(agent.act(obs)[0]))
        assert agent.last_decision == "exploit"
    cleared, preplayed = headings
    assert abs(preplayed) < math.radians(30.0)  # into the wall
    assert abs(cleared - preplayed) >= math.radians(15.0) - 1e-6  # turned ...
    assert cleared == pytest.approx(Reflexes(ReflexConfig()).clear(preplayed, ranges, 0.0), abs=1e-6)  # ... as the reflex turns it


# ------------------------------------------------------------------ save / load
def test_the_state_of_the_reflexes_loads_into_fresh_ones():
    reflexes = Reflexes(ReflexConfig(escape_steps=4))
    reflexes.bumped("explore")
    reflexes.escape()
    fresh = Reflexes(ReflexConfig(escape_steps=4))
    fresh.load_state(*reflexes.state())
    same_state(fresh.state(), reflexes.state())
    assert fresh.escape_left == 3


def test_a_malformed_reflex_state_raises_value_error():
    with pytest.raises(ValueError):
        Reflexes(ReflexConfig()).load_state({"escape_left": "three"}, {})
