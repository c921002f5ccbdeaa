"""HippocampalAgent.save / load: exact round trip, and clear errors on bad files."""

from __future__ import annotations

import json
import zipfile

import gymnasium as gym
import numpy as np
import pytest

from hippo_agent import AgentConfig, HippocampalAgent
from hippo_agent.persistence import FORMAT_TAG


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
    agent = HippocampalAgent(env.observation_space, action_space, AgentConfig(n_place=300, dry_run_steps=0), seed=6)
    agent.start_trial(0)
    for _ in range(8):  # until a replay has written a reward map (the goal reached with a place cell active)
        play(env, agent, 1500)
        if agent.goal_rewarded:
            break
    assert agent.goal_rewarded, "the fixture should have found the goal at least once"
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
        (agent.reward.found_sum, loaded.reward.found_sum),
        (agent.reward.found_count, loaded.reward.found_count),
    ]:
        assert a.dtype == b.dtype
        np.testing.assert_array_equal(a, b)
    assert loaded.rng.bit_generator.state == agent.rng.bit_generator.state
    assert agent.reward.remembered_place() is not None  # where the fixture's goal was found
    later = (
        "intended_heading",
        "segment_left",
        "goal_rewarded",
        "homing_done",
        "memory_failures",
        "homing_bumps",
        "bump_rate",
        "fit",
        "own_fit",
    )
    assert [getattr(loaded, name) for name in later] == [getattr(agent, name) for name in later]
    for name in ("look_alikes", "look_alike_fit"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(agent, name))
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


#: AgentConfig fields added after agent files of format version 4 were first written.
LATER_FIELDS = (
    "sweep_patience", "recruit_every", "recruit_min", "map_free_range", "map_hit_range", "map_ray_stride_deg",
    "map_agreement_stride_deg", "map_bump_distance", "map_fit_rate", "pi_min_mass", "pi_vote_floor", "pi_min_mapped", "pi_resample_ess",
    "doubt_look_alikes", "doubt_margin",
)  # fmt: skip


def test_a_file_whose_config_lacks_later_fields_loads_with_their_defaults(tmp_path):
    env, agent = trained_agent()
    path = tmp_path / "agent.npz"
    agent.save(path)
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays["__meta__"]))
    for name in LATER_FIELDS:
        del meta["config"][name]
    arrays["__meta__"] = np.array(json.dumps(meta))
    np.savez(tmp_path / "older.npz", **arrays)
    loaded = HippocampalAgent.load(tmp_path / "older.npz")
    assert loaded.config == agent.config == AgentConfig(n_place=300, dry_run_steps=0)
    obs = env.obs()
    assert [agent.act(obs) for _ in range(50)] == [loaded.act(obs) for _ in range(50)]


def test_places_ruled_out_while_re_anchoring_survive_a_save_and_older_files_have_none(tmp_path):
    _, agent = trained_agent()
    agent.pi.estimate = np.array([1.0, -0.5])
    agent._memory_failed()  # a search round the remembered place failed: the estimate's place is ruled out
    agent.save(tmp_path / "agent.npz")
    np.testing.assert_array_equal(HippocampalAgent.load(tmp_path / "agent.npz").pi.ruled_out, [[1.0, -0.5]])
    with np.load(tmp_path / "agent.npz") as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays["__meta__"]))
    del meta["state"]["pi"]["ruled_out"]
    arrays["__meta__"] = np.array(json.dumps(meta))
    np.savez(tmp_path / "older.npz", **arrays)
    assert HippocampalAgent.load(tmp_path / "older.npz").pi.ruled_out.shape == (0, 2)


def test_a_file_without_the_remembered_goal_places_loads_with_none_found(tmp_path):
    _, agent = trained_agent()
    path = tmp_path / "agent.npz"
    agent.save(path)
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files if k not in ("found_sum", "found_count")}
    meta = json.loads(str(arrays["__meta__"]))
    for name in ("homing_done", "memory_failures", "homing_bumps", "bump_rate", "fit", "own_fit", "look_alikes", "look_alike_fit"):
        del meta["state"][name]
    arrays["__meta__"] = np.array(json.dumps(meta))
    np.savez(tmp_path / "older.npz", **arrays)
    loaded = HippocampalAgent.load(tmp_path / "older.npz")
    assert loaded.reward.remembered_place() is None and not loaded.homing_done and loaded.memory_failures == 0
    assert loaded.homing_bumps == 0 and loaded.bump_rate == 0.0
    np.testing.assert_array_equal(loaded.reward.W_rp, agent.reward.W_rp)
    # a remembered place of the wrong shape is refused, naming the array
    arrays["found_sum"] = np.zeros((3, 2))
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(ValueError, match="found_sum"):
        HippocampalAgent.load(tmp_path / "bad.npz")


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

    def rewrite(name, mutate_meta=None, drop=None):
        with np.load(good) as data:
            arrays = {k: data[k] for k in data.files}
        meta = json.loads(str(arrays["__meta__"]))
        if mutate_meta:
            mutate_meta(meta)
        arrays["__meta__"] = np.array(json.dumps(meta))
        if drop:
            del arrays[drop]
        np.savez(tmp_path / name, **arrays)
        cases.append(name)

    rewrite("wrong_tag.npz", lambda m: m.update(format="someone.else"))
    rewrite("future.npz", lambda m: m.update(version=99))
    rewrite("bad_config.npz", lambda m: m["config"].update(n_place=-3))
    rewrite("no_state.npz", lambda m: m.pop("state"))
    rewrite("missing_array.npz", drop="W_pp_slots")
    with np.load(good) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["W_pp_slots"] = arrays["W_pp_slots"][:10]
    np.savez(tmp_path / "bad_shape.npz", **arrays)
    cases.append("bad_shape.npz")

    for name in cases:
        with pytest.raises(ValueError, match="is not a readable hippomaze agent file"):
            HippocampalAgent.load(tmp_path / name)
    with pytest.raises(ValueError, match="format tag"):
        HippocampalAgent.load(tmp_path / "wrong_tag.npz")
    with pytest.raises(ValueError, match="version 99"):
        HippocampalAgent.load(tmp_path / "future.npz")
    with pytest.raises(ValueError, match="n_place"):
        HippocampalAgent.load(tmp_path / "bad_config.npz")
    with pytest.raises(ValueError):
        HippocampalAgent.load(tmp_path / "does_not_exist.npz")


def test_file_is_a_plain_npz_with_json_metadata(tmp_path):
    _, agent = trained_agent()
    agent.save(tmp_path / "a.npz")
    assert zipfile.is_zipfile(tmp_path / "a.npz")
    with np.load(tmp_path / "a.npz", allow_pickle=False) as data:
        meta = json.loads(str(data["__meta__"]))
    assert meta["format"] == FORMAT_TAG and meta["version"] == 4
    assert meta["config"]["n_place"] == 300
