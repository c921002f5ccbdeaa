"""Directed exploration (:mod:`hippo_agent.faculties.exploration`): the dry run's sweep, transits and
rest, recruitment of place cells with the ground found, a run's search, and the faculty's own saved state."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from agent_helpers import make_env, same_state

import hippo_env  # noqa: F401  (registers HippoMaze-v0)
from hippo_agent import AgentConfig, ExplorationConfig, HippocampalAgent, ReflexConfig
from hippo_agent.faculties.exploration import Exploration
from hippo_env.dmtp import _CountingEnv
from hippo_env.maze import MazeSpec
from hippo_env.physics import ROBOT_RADIUS

RANDOM_WALK = AgentConfig(
    map=None, localisation=None, exploration=None, homing=None, worlds=None, reflexes=ReflexConfig(escape_after="exploiting")
)
"""The default model before directed exploration: path integration, no map, the paper's random walk."""


def dry_run(maze: str | MazeSpec = "open", seed: int = 0, values: dict | None = None, base: AgentConfig | None = None):
    """The dry run of an agent of ``base`` (the default model) changed by ``values`` (dotted names):
    the agent, the steps taken, the true positions (measured from outside) and the maze."""
    env = gym.make("HippoMaze-v0", maze=maze, odometry=True)
    env.reset(seed=seed, options={"goal": None})
    config = (AgentConfig() if base is None else base).with_values(values or {})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=seed)
    positions = []

    class Watch(_CountingEnv):
        def step(self, action):
            out = super().step(action)
            positions.append(out[4]["position"])
            return out

    counted = Watch(env, allow_goal=False)
    agent.dry_run(counted)
    return agent, counted.steps, np.array(positions), env.unwrapped.maze


def coverage(spec: MazeSpec, positions: np.ndarray, radius: float = 0.75) -> float:
    """Share of the free 0.25 m grid the robot's centre came within ``radius`` of (measured from outside)."""
    half = spec.size[0] / 2
    grid = np.array([(x, y) for x in np.arange(-half + 0.125, half, 0.25) for y in np.arange(-half + 0.125, half, 0.25)])
    grid = grid[[spec.clearance(p) >= ROBOT_RADIUS for p in grid]]
    nearest = np.min(np.hypot(grid[:, None, 0] - positions[None, :, 0], grid[:, None, 1] - positions[None, :, 1]), axis=1)
    return float(np.mean(nearest <= radius))


# ------------------------------------------------------------------ the dry run
def test_directed_dry_run_ends_by_itself_with_the_arena_covered():
    agent, steps, positions, spec = dry_run("open", seed=3)
    assert agent.exploration.stage == "done"
    assert steps < agent._dry_run_cap()
    assert agent.exploration.sweep_steps < steps  # the sweep, then transits
    assert coverage(spec, positions) > 0.95


def test_random_dry_run_takes_exactly_its_steps():
    agent, steps, _, _ = dry_run("open", seed=3, values={"model.dry_run_steps": 300}, base=RANDOM_WALK)
    assert steps == 300 and agent.map is None and agent.exploration is None


def test_rest_takes_no_step_and_lays_links():
    rested, steps_rested, _, _ = dry_run("maze1", seed=2, values={"exploration.rest_factor": 5.0})
    awake, steps_awake, _, _ = dry_run("maze1", seed=2, values={"exploration.rest_factor": 0.0})
    assert steps_rested == steps_awake
    assert rested.place.n_slots >= awake.place.n_slots
    assert np.abs(rested.place.W_pp_used).sum() > np.abs(awake.place.W_pp_used).sum()
    assert rested.exploration.codes == {}  # the dry run's memory of codes is let go


def test_rests_compiled_imagined_steps_learn_as_the_place_cells_step_by_step(monkeypatch):
    """Each imagined transit of the rest (one compiled loop) leaves the place-place weights and the
    traces exactly as the place cells' own methods do, step by step (rates set to the code, the
    head-direction trace, eq. 7, eq. 6), slots given on the way included."""
    import copy

    imagine, transits = Exploration._imagine, []

    def step_by_step(exploration: Exploration, cells: list[int], xy: list[list[float]]) -> object:
        place, hd = exploration.model.place, exploration.model.hd
        for k in range(1, len(cells)):
            code = exploration.codes.get(cells[k])
            if code is None:
                continue
            dx, dy = xy[k][0] - xy[k - 1][0], xy[k][1] - xy[k - 1][1]
            place.v = np.zeros(place.n)
            place.v[code[0]] = code[1]
            place.update_hd_trace(hd.rates_for(np.array([dx / math.hypot(dx, dy), dy / math.hypot(dx, dy)])))
            place.learn_pp()
            place.update_trace()
        return place

    def checked(self: Exploration, cells: list[int], xy: list[list[float]]) -> int:
        if len(transits) % 2:  # every other transit starts with no cell holding a slot: slots are given on the way
            place = self.model.place
            place.load_W_pp(np.empty(0, dtype=np.int64), np.zeros((0, place.n_hd, 0), dtype=np.float32))
        reference = copy.deepcopy(self)
        done = imagine(self, cells, xy)
        expected = step_by_step(reference, cells, xy)
        for name in ("W_slots", "slot", "slot_cells", "trace", "hd_trace"):
            assert np.array_equal(getattr(self.model.place, name), getattr(expected, name)), name
        transits.append(done)
        return done

    monkeypatch.setattr(Exploration, "_imagine", checked)
    dry_run("maze1", seed=2, values={"model.n_place": 300})
    assert len(transits) > 20 and sum(transits) > 500


def test_recruitment_grows_the_place_cells_with_the_known_ground(tmp_path):
    agent, _, _, _ = dry_run("open", seed=1, values={"model.n_place": 300, "exploration.place_cells_per_m2": 5.0})
    assert agent.place.n > 300
    assert agent.place.n >= 5.0 * agent.map.explored_area() or agent.place.n == agent.config.exploration.max_place_cells
    assert agent.reward.W_rp.shape[1] == agent.place.n
    assert agent.pi.centres.shape == (agent.place.n, 2) and agent.pi.centre_mass.shape == (agent.place.n,)  # room for their centres
    agent.save(tmp_path / "grown.npz")
    loaded = HippocampalAgent.load(tmp_path / "grown.npz")
    assert loaded.place.n == agent.place.n
    np.testing.assert_array_equal(loaded.place.W_pb, agent.place.W_pb)
    np.testing.assert_array_equal(loaded.pi.centres, agent.pi.centres)
    np.testing.assert_array_equal(loaded.map.free, agent.map.free)
    np.testing.assert_array_equal(loaded.map.visited, agent.map.visited)


def test_recruits_enough_cells_for_the_ground_known_in_large_steps_up_to_the_most():
    env = make_env()
    config = AgentConfig().with_values({"model.n_place": 100, "exploration.recruit_min": 50, "exploration.max_place_cells": 400})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=0)
    exploration, m = agent.exploration, agent.map
    assert exploration.recruits(0) == 0  # nothing known yet
    m.free[m.index(0.0, 0.0)[0], :40] = 1  # 40 cells of 1/16 m^2: 2.5 m^2, 25 place cells wanted at 10 per m^2 ...
    assert exploration.recruits(0) == 0  # ... fewer than there are
    m.free[:10, :40] = 1  # 400 more cells: 27.5 m^2, 275 wanted
    assert exploration.recruits(1) == 0  # (only every recruit_every steps)
    assert exploration.recruits(50) == 175
    m.free[:20, :40] = 1  # 52.5 m^2: 525 wanted, at most 400
    assert exploration.recruits(100) == 300
    agent.grow_place_cells(280)
    assert exploration.recruits(100) == 20  # (at least recruit_min, but never past the most)


def test_the_dry_run_sweep_squeezes_through_a_doorway_the_map_holds_too_narrow():
    """The map of the search test in ``test_map.py``, in a dry run: with no walkable path to the
    unvisited side of a one-cell doorway, the sweep plans through it instead of counting toward
    its end (as a run's search does), so the ground beyond it is mapped."""
    env = gym.make("HippoMaze-v0", maze="open", odometry=True)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig().with_values({"model.n_place": 50}), seed=0)
    m = agent.map
    m.free[:] = 1
    wall_row, door = m.index(0.0, 0.0)
    m.hits[wall_row, :] = 5  # a wall along x = 0 ...
    m.hits[wall_row, door] = 0  # ... with a one-cell gap at y = 0
    m.visited[: wall_row + 1, :] = True  # this side visited
    m.grids_replaced()
    agent.phase, agent.exploration.stage, agent.pi.estimate = "dry", "sweep", np.array([-2.0, 0.0])
    assert m.heading_to_unvisited(agent.pi.estimate) is None
    heading = agent.exploration.plan(dry=True)
    assert heading is not None and abs(heading) < math.pi / 4, heading  # toward the gap, at +x
    assert agent.exploration.stage == "sweep" and agent.exploration.plan_failures == 0


# ------------------------------------------------------------------ a run's search
def test_a_run_search_that_has_searched_everything_starts_afresh(small_maze):
    env = make_env(small_maze, seed=1)
    agent = HippocampalAgent(env.observation_space, env.action_space, AgentConfig().with_values({"model.dry_run_steps": 1500}), seed=1)
    agent.dry_run(env)
    agent.start_trial(0)
    obs, info = env.reset(options={"goal": [1.2, 1.2], "start": [-1.3, -1.3], "heading": 0.0})
    agent.reset(obs, info)
    agent.map.searched[:] = True
    agent.map.grids_replaced()  # (written directly)
    assert agent.exploration.plan(dry=False) is not None
    assert not agent.map.searched.any()


# ------------------------------------------------------------------ save / load
def planned_exploration(seed: int = 0) -> tuple[HippocampalAgent, Exploration]:
    """An agent's exploration that has swept a hand-made map and gone over to transits."""
    env = make_env()
    config = AgentConfig().with_values({"model.n_place": 50, "exploration.transit_min_distance": 1.0})
    agent = HippocampalAgent(env.observation_space, env.action_space, config, seed=seed)
    m, exploration = agent.map, agent.exploration
    m.free[m.index(-2.0, -2.0)[0] : m.index(2.0, 2.0)[0], m.index(-2.0, -2.0)[1] : m.index(2.0, 2.0)[1]] = 1  # a 4 m square of free ground
    m.grids_replaced()
    exploration.start_dry_run()
    agent.pi.estimate = np.zeros(2)
    assert exploration.plan(dry=True) is not None  # the sweep ...
    m.visited[:] = True
    m.grids_replaced()  # (written directly)
    for _ in range(config.exploration.sweep_patience):
        exploration.plan(dry=True)
    assert exploration.stage == "transit" and exploration.transit_target >= 0  # ... then transits
    return agent, exploration


def test_the_state_of_exploration_loads_into_a_fresh_one():
    agent, exploration = planned_exploration()
    saved = exploration.state()
    assert saved[0] == {
        "stage": "transit",
        "sweep_steps": 4,
        "transit_left": 3,
        "transit_target": exploration.transit_target,
        "plan_failures": 3,
    }
    fresh = Exploration(agent.config.exploration, agent.map, agent.pi, agent.model, np.random.default_rng(7))
    fresh.load_state(*saved)
    same_state(fresh.state(), saved)
    assert fresh.plan(dry=True) == exploration.plan(dry=True)  # the same transit, toward the same cell


@pytest.mark.parametrize(
    "spoil", [{"stage": "wander"}, {"sweep_steps": "many"}, {"transit_target": "somewhere"}], ids=["stage", "sweep_steps", "target"]
)
def test_a_malformed_exploration_state_raises_value_error(spoil):
    agent, exploration = planned_exploration()
    state, arrays = exploration.state()
    fresh = Exploration(ExplorationConfig(), agent.map, agent.pi, agent.model, np.random.default_rng(0))
    with pytest.raises(ValueError):
        fresh.load_state({**state, **spoil}, arrays)
