"""HippocampalAgent.save / load: exact round trip (each part saves its own state), a loaded agent
that chooses what the original would have, and clear errors on bad files."""

from __future__ import annotations

import json
import zipfile

import gymnasium as gym
import numpy as np
import pytest
from agent_helpers import SMALL, drive_run, make_env, same_state

from hippo_agent import AgentConfig, HippocampalAgent, ModelConfig
from hippo_agent.persistence import FORMAT_TAG, FORMAT_VERSION, PARTS

TRAINED = AgentConfig(model=ModelConfig(n_place=300, dry_run_steps=0))


def square_ranges(pos, heading, n_rays=360, half=3.0, max_range=8.0):
    ang = heading + 2 * np.pi * np.arange(n_rays) / n_rays
    c, s = np.cos(ang), np.sin(ang)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(c > 0, (half - pos[0]) / c, np.where(c < 0, (-half - pos[0]) / c, np.inf))
        ty = np.where(s > 0, (half - pos[1]) / s, np.where(s < 0, (-half - pos[1]) / s, np.inf))
    return np.minimum(np.minimum(tx, ty), max_range).astype(np.float32)


class TinyRoom:
    """A 6 m square room, a point robot, 360 rays: enough to drive the agent without hippo_env."""

    def __init__(self, action_space, goal=(1.5, 1.5)):
        self.observation_space = gym.spaces.Dict(
            {
                "ranges": gym.spaces.Box(0.0, 8.0, (360,), np.float32),
                "heading": gym.spaces.Box(-1.0, 1.0, (2,), np.float32),
                "odometry": gym.spaces.Box(-0.3, 0.3, (2,), np.float32),
            }
        )
        self.action_space = action_space
        self.moved = np.zeros(2)
        self.goal = np.array(goal)
        self.pos, self.heading = np.array([-1.5, -1.5]), 0.0

    def obs(self):
        c, s = np.cos(self.heading), np.sin(self.heading)
        return {
            "ranges": square_ranges(self.pos, self.heading),
            "heading": np.array([c, s], np.float32),
            "odometry": np.array([c * self.moved[0] + s * self.moved[1], -s * self.moved[0] + c * self.moved[1]], np.float32),
        }

    def reset(self, start=(-1.5, -1.5)):
        self.pos, self.heading, self.moved = np.array(start, float), 0.0, np.zeros(2)
        return self.obs(), {}

    def step(self, action):
        if isinstance(self.action_space, gym.spaces.Discrete):
            self.heading = int(action) * np.pi / 4
        else:
            self.heading = float(action[0])
        new = self.pos + 0.15 * np.array([np.cos(self.heading), np.sin(self.heading)])
        collision = bool(np.any(np.abs(new) > 2.8))
        new = np.clip(new, -2.8, 2.8)
        self.moved, self.pos = new - self.pos, new
        done = bool(np.linalg.norm(self.pos - self.goal) < 0.3)
        return self.obs(), float(done), done, False, {"collision": collision}


def part(agent, path):
    """The agent's part at a dotted ``path`` (``"model.walk"``)."""
    for name in path.split("."):
        agent = getattr(agent, name)
    return agent


def play(env, agent, steps, start=(-1.5, -1.5)):
    obs, info = env.reset(start)
    agent.reset(obs, info)
    actions = []
    for _ in range(steps):
        a = agent.act(obs)
        actions.append(np.asarray(a, dtype=float).ravel().tolist())
        obs, r, term, trunc, info = env.step(a)
        agent.observe(a, obs, r, term, trunc, info)
        if term:
            obs, info = env.reset(start)
            agent.reset(obs, info)
    return actions, obs


def trained_agent(action_space=None):
    action_space = gym.spaces.Discrete(8) if action_space is None else action_space
    env = TinyRoom(action_space)
    agent = HippocampalAgent(env.observation_space, action_space, TRAINED, seed=6)
    agent.start_trial(0)
    for _ in range(8):  # until a replay has written a reward map (the goal reached with a place cell active)
        play(env, agent, 1500)
        if agent.model.goal_rewarded:
            break
    assert agent.model.goal_rewarded, "the fixture should have found the goal at least once"
    return env, agent


@pytest.mark.parametrize("action_space", [gym.spaces.Discrete(8), gym.spaces.Box(-np.pi, np.pi, (1,), np.float32)])
def test_round_trip_is_exact(tmp_path, action_space):
    env, agent = trained_agent(action_space)
    path = tmp_path / "agent.hippo"  # any name: no suffix is added
    agent.save(path)
    assert path.exists()
    loaded = HippocampalAgent.load(path)
    assert loaded.config == agent.config and loaded.seed == agent.seed
    for a, b in [
        (agent.place.W_pb, loaded.place.W_pb),
        (agent.place.W_pp, loaded.place.W_pp),
        (agent.reward.W_rp, loaded.reward.W_rp),
        (agent.reward.W_eff, loaded.reward.W_eff),
        (agent.place.s, loaded.place.s),
        (agent.place.v, loaded.place.v),
        (agent.place.trace, loaded.place.trace),
        (agent.place.hd_trace, loaded.place.hd_trace),
        (agent.homing.found_sum, loaded.homing.found_sum),
        (agent.homing.found_count, loaded.homing.found_count),
        (agent.pi.centres, loaded.pi.centres),
        (agent.pi.particles, loaded.pi.particles),
        (agent.map.free, loaded.map.free),
        (agent.map.searched, loaded.map.searched),
    ]:
        assert a.dtype == b.dtype
        np.testing.assert_array_equal(a, b)
    assert loaded.rng.bit_generator.state == agent.rng.bit_generator.state
    assert agent.homing.remembered() is not None  # where the fixture's goal was found
    later = (
        ("model.walk", "heading"),
        ("model.walk", "segment_left"),
        ("model", "goal_rewarded"),
        ("homing", "searching"),
        ("homing", "failures"),
        ("homing", "bumps"),
        ("localisation", "bump_rate"),
        ("localisation", "fit"),
        ("localisation", "own_fit"),
        ("exploration", "stage"),
        ("reflexes", "escape_left"),
        ("pi", "anchored"),
    )
    assert [getattr(part(loaded, path), name) for path, name in later] == [getattr(part(agent, path), name) for path, name in later]
    for name in ("look_alikes", "look_alike_fit"):
        np.testing.assert_array_equal(getattr(loaded.localisation, name), getattr(agent.localisation, name))
    for name in PARTS:  # every part's whole state
        same_state(getattr(loaded, name).state(), getattr(agent, name).state())
    assert type(loaded.action_space) is type(agent.action_space)
    # the future is identical: same actions from the same observations, same weights after
    pos, heading = env.pos.copy(), env.heading
    acts_a, _ = play(env, agent, 300, start=tuple(pos))
    env.pos, env.heading = pos, heading
    acts_b, _ = play(env, loaded, 300, start=tuple(pos))
    assert acts_a == acts_b
    np.testing.assert_array_equal(agent.place.W_pp, loaded.place.W_pp)
    np.testing.assert_array_equal(agent.reward.W_rp, loaded.reward.W_rp)


def test_round_trip_mid_run_continues_identically(tmp_path):
    env, agent = trained_agent()
    obs = env.obs()
    agent.save(tmp_path / "mid.npz")
    loaded = HippocampalAgent.load(tmp_path / "mid.npz")
    assert loaded.started == agent.started
    assert [agent.act(obs) for _ in range(50)] == [loaded.act(obs) for _ in range(50)]


#: Fields a file's config section may leave out (say, written before they were added): they load with their defaults.
LATER_FIELDS = (
    "exploration.sweep_patience", "exploration.recruit_every", "exploration.recruit_min", "map.free_range", "map.hit_range",
    "map.ray_stride_deg", "map.agreement_stride_deg", "map.bump_distance", "localisation.fit_rate", "localisation.check_every",
    "path_integration.min_mass", "path_integration.vote_floor", "path_integration.min_mapped", "path_integration.resample_ess",
    "localisation.look_alikes", "localisation.doubt_margin", "homing.approach_radius", "reflexes.escape_after",
)  # fmt: skip


def read(path):
    """An agent file's metadata and arrays."""
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    return json.loads(str(arrays.pop("__meta__"))), arrays


def write(path, meta, arrays):
    np.savez(path, __meta__=np.array(json.dumps(meta)), **arrays)


def test_a_file_whose_config_lacks_later_fields_loads_with_their_defaults(tmp_path):
    env, agent = trained_agent()
    path = tmp_path / "agent.npz"
    agent.save(path)
    meta, arrays = read(path)
    for name in LATER_FIELDS:
        section, field = name.split(".")
        del meta["config"][section][field]
    write(tmp_path / "older.npz", meta, arrays)
    loaded = HippocampalAgent.load(tmp_path / "older.npz")
    assert loaded.config == agent.config == TRAINED
    obs = env.obs()
    assert [agent.act(obs) for _ in range(50)] == [loaded.act(obs) for _ in range(50)]


def test_places_ruled_out_while_re_anchoring_survive_a_save(tmp_path):
    _, agent = trained_agent()
    agent.pi.estimate = np.array([1.0, -0.5])
    agent.homing._failed()  # a search round the remembered place failed: the estimate's place is ruled out
    agent.localisation.relocalise(rule_out=True)
    agent.save(tmp_path / "agent.npz")
    loaded = HippocampalAgent.load(tmp_path / "agent.npz")
    np.testing.assert_array_equal(loaded.pi.ruled_out, [[1.0, -0.5]])
    assert not loaded.pi.anchored and loaded.homing.failures == agent.homing.failures == 1


@pytest.mark.parametrize("model", ["default", "paper"])
def test_an_agent_saved_mid_run_and_loaded_chooses_the_same_actions(tmp_path, model):
    """An agent of each model (``AgentConfig()`` and ``AgentConfig.paper()``), saved after its dry
    run and 30 steps into run 2, loaded, fed the same observations for 300 steps, chooses the same
    actions: both are fed the observations the original's actions produce, and the loaded agent
    chooses the original's action at every step (and the same behaviour); their generators end in
    the same state, and so does every part of them."""
    paper = model == "paper"
    maze = tmp_path / "walled.json"  # 6 m square, a wall from the west across the middle: run 2 goes round its east end
    maze.write_text(
        json.dumps({"name": "walled", "size": [6.0, 6.0], "obstacles": [[[-3.0, -0.15], [1.0, -0.15], [1.0, 0.15], [-3.0, 0.15]]]})
    )
    env = make_env(str(maze), seed=4, odometry=not paper)
    base = AgentConfig.paper() if paper else AgentConfig()
    values = {"model.n_place": SMALL.model.n_place, "model.dry_run_steps": SMALL.model.dry_run_steps}
    agent = HippocampalAgent(env.observation_space, env.action_space, base.with_values(values), seed=4)
    agent.dry_run(env)
    agent.start_trial(0)
    goal, start = {"goal": [-2.0, 2.0]}, {"start": [-2.0, -2.0], "heading": 0.0}
    info, _, _ = drive_run(env, agent, options={**goal, **start})  # run 1
    assert info["is_success"] and agent.model.goal_rewarded
    obs, info = env.reset(options=start)  # run 2
    agent.reset(obs, info)
    for _ in range(30):
        action = agent.act(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        agent.observe(action, obs, reward, terminated, truncated, info)
        assert not (terminated or truncated)
    agent.save(tmp_path / "agent.npz")
    loaded = HippocampalAgent.load(tmp_path / "agent.npz")
    decisions, runs, bumps = [], 2, 0
    for step in range(300):
        action, loaded_action = agent.act(obs), loaded.act(obs)
        assert np.array_equal(loaded_action, action), (step, action, loaded_action)
        assert loaded.last_decision == agent.last_decision, step
        decisions.append(agent.last_decision)
        obs, reward, terminated, truncated, info = env.step(action)
        bumps += info["collision"]
        for a in (agent, loaded):
            a.observe(action, obs, reward, terminated, truncated, info)
        if terminated or truncated:  # another run from the same start (replay on the reward, for both)
            obs, info = env.reset(options=start)
            agent.reset(obs, info)
            loaded.reset(obs, info)
            runs += 1
    assert loaded.rng.bit_generator.state == agent.rng.bit_generator.state
    for name in PARTS:
        if getattr(agent, name) is not None:
            same_state(getattr(loaded, name).state(), getattr(agent, name).state())
    assert (loaded.total_steps, loaded.episode_stats) == (agent.total_steps, agent.episode_stats)
    # (the steps exercised every behaviour the model has, bumps, and for the default model runs that found the goal)
    assert set(decisions) == ({"explore", "exploit"} if paper else {"explore", "exploit", "home"}) and bumps > 0
    assert paper or runs > 3


def test_corrupt_truncated_and_foreign_files_raise_value_error(tmp_path):
    _, agent = trained_agent()
    good = tmp_path / "good.npz"
    agent.save(good)
    raw = good.read_bytes()

    (tmp_path / "garbage.npz").write_bytes(b"not a zip file at all" * 10)
    (tmp_path / "truncated.npz").write_bytes(raw[: len(raw) // 2])
    (tmp_path / "empty.npz").write_bytes(b"")
    np.savez(tmp_path / "foreign.npz", weights=np.zeros(3))
    cases = ["garbage.npz", "truncated.npz", "empty.npz", "foreign.npz"]

    def rewrite(name, mutate_meta=None, mutate_arrays=None):
        meta, arrays = read(good)
        if mutate_meta:
            mutate_meta(meta)
        if mutate_arrays:
            mutate_arrays(arrays)
        write(tmp_path / name, meta, arrays)
        cases.append(name)

    rewrite("wrong_tag.npz", lambda m: m.update(format="someone.else"))
    rewrite("future.npz", lambda m: m.update(version=99))
    rewrite("version4.npz", lambda m: m.update(version=4))
    rewrite("bad_config.npz", lambda m: m["config"]["model"].update(n_place=-3))
    rewrite("flat_config.npz", lambda m: m.update(config={"n_place": 300, "dry_run_steps": 0}))
    rewrite("no_parts.npz", lambda m: m.pop("parts"))
    rewrite("no_pi_state.npz", lambda m: m["parts"].pop("pi"))
    rewrite("no_homing_count.npz", lambda m: m["parts"]["homing"].pop("failures"))
    rewrite("bad_stage.npz", lambda m: m["parts"]["exploration"].update(stage="wander"))
    rewrite("bad_phase.npz", lambda m: m["agent"].update(phase="asleep"))
    rewrite("too_many_cells.npz", lambda m: m["parts"]["model"].update(place_cells=10**6))
    rewrite("missing_array.npz", mutate_arrays=lambda a: a.pop("model.W_pp_slots"))
    rewrite("missing_map.npz", mutate_arrays=lambda a: a.pop("map.visited"))
    rewrite("bad_shape.npz", mutate_arrays=lambda a: a.update({"model.W_pp_slots": a["model.W_pp_slots"][:10]}))
    rewrite("bad_found.npz", mutate_arrays=lambda a: a.update({"homing.found_sum": np.zeros((3, 2))}))
    rewrite("bad_centres.npz", mutate_arrays=lambda a: a.update({"pi.centres": a["pi.centres"][:5]}))

    for name in cases:
        with pytest.raises(ValueError, match="is not a readable hippomaze agent file"):
            HippocampalAgent.load(tmp_path / name)
    with pytest.raises(ValueError, match="format tag"):
        HippocampalAgent.load(tmp_path / "wrong_tag.npz")
    with pytest.raises(ValueError, match="version 99"):
        HippocampalAgent.load(tmp_path / "future.npz")
    with pytest.raises(ValueError, match="format version 4 is unsupported; this hippo_agent reads version 5"):
        HippocampalAgent.load(tmp_path / "version4.npz")
    with pytest.raises(ValueError, match="n_place"):
        HippocampalAgent.load(tmp_path / "bad_config.npz")
    with pytest.raises(ValueError, match="layout version 1"):
        HippocampalAgent.load(tmp_path / "flat_config.npz")
    with pytest.raises(ValueError, match="the state of 'pi' is missing"):
        HippocampalAgent.load(tmp_path / "no_pi_state.npz")
    with pytest.raises(ValueError, match=r"homing's arrays 'found_sum' \(3 places\)"):
        HippocampalAgent.load(tmp_path / "bad_found.npz")
    with pytest.raises(ValueError, match="path integration's array 'centres'"):
        HippocampalAgent.load(tmp_path / "bad_centres.npz")
    with pytest.raises(ValueError, match="the map's array 'visited'"):
        HippocampalAgent.load(tmp_path / "missing_map.npz")
    with pytest.raises(ValueError):
        HippocampalAgent.load(tmp_path / "does_not_exist.npz")


def test_file_is_a_plain_npz_with_json_metadata(tmp_path):
    _, agent = trained_agent()
    agent.save(tmp_path / "a.npz")
    assert zipfile.is_zipfile(tmp_path / "a.npz")
    with np.load(tmp_path / "a.npz", allow_pickle=False) as data:
        meta = json.loads(str(data["__meta__"]))
        files = set(data.files)
    assert meta["format"] == FORMAT_TAG and meta["version"] == FORMAT_VERSION == 5
    assert meta["config"] == agent.config.to_dict() and meta["config"]["version"] == 2
    assert meta["config"]["model"]["n_place"] == 300
    assert set(meta["parts"]) == set(PARTS)  # (every part is on in the default model)
    prefixes = {name.split(".")[0] for name in files - {"__meta__"}}
    assert prefixes <= {*PARTS, "senses"} and {"model", "pi", "map", "localisation", "homing"} <= prefixes


def test_a_paper_agent_saves_only_the_parts_it_has(tmp_path):
    env = TinyRoom(gym.spaces.Discrete(8))
    space = gym.spaces.Dict({key: box for key, box in env.observation_space.spaces.items() if key != "odometry"})
    agent = HippocampalAgent(
        space, env.action_space, AgentConfig.paper().with_values({"model.n_place": 50, "model.dry_run_steps": 0}), seed=1
    )
    agent.start_trial(0)
    obs, info = env.reset()
    obs.pop("odometry")
    agent.reset(obs, info)
    agent.save(tmp_path / "paper.npz")
    meta, _ = read(tmp_path / "paper.npz")
    assert set(meta["parts"]) == {"model", "reflexes"}
    loaded = HippocampalAgent.load(tmp_path / "paper.npz")
    assert loaded.config == agent.config and loaded.pi is None and loaded.map is None and not loaded.has_odometry
    assert [agent.act(obs) for _ in range(20)] == [loaded.act(obs) for _ in range(20)]
