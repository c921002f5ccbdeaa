"""Saving and loading a :class:`~hippo_agent.HippocampalAgent`: one npz file with every array, the
generator's state and a JSON metadata entry (format tag and version), so a loaded agent behaves
exactly as the saved one would have."""

from __future__ import annotations

import json
import os
import zipfile
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np

from hippo_agent.config import AgentConfig
from hippo_env.env import ODOMETRY_BOUND

__all__ = ["FORMAT_TAG", "FORMAT_VERSION", "load", "save"]

FORMAT_TAG = "hippomaze.HippocampalAgent"
FORMAT_VERSION = 4  # raised whenever what a file holds changes; files of another version are refused

# Every saved array: its name in the file -> (the agent's part holding it, the attribute).
ARRAY_HOME: dict[str, tuple[str, str]] = {
    "W_pb": ("place", "W_pb"),
    "W_rp": ("reward", "W_rp"),
    "W_eff": ("reward", "W_eff"),
    "s": ("place", "s"),
    "v": ("place", "v"),
    "trace": ("place", "trace"),
    "hd_trace": ("place", "hd_trace"),
    "hd_rates": ("hd", "rates"),
    "bvc_rates": ("bvc", "rates"),
    "last_values": ("agent", "last_values"),
    "s_sense": ("place", "s_sense"),
    "v_sense": ("place", "v_sense"),
    "centres": ("place", "centres"),
    "centre_mass": ("place", "centre_mass"),
    "spread": ("place", "spread"),
    "spread_mass": ("place", "spread_mass"),
    "pi_particles": ("pi", "particles"),
    "pi_weights": ("pi", "weights"),
    "pi_estimate": ("pi", "estimate"),
    "pi_last_step": ("pi", "last_step"),
}
ARRAYS = (*ARRAY_HOME, "W_pp_slots", "W_pp_cells")
# Arrays added within format version 4: a file without them loads as if no reward had been found
# anywhere yet (name in the file -> the reward cells' attribute; one row per goal).
REWARD_PLACE_ARRAYS = {"found_sum": "found_sum", "found_count": "found_count"}
# The exploration map's grids (directed exploration only): name in the file -> the map's attribute.
MAP_ARRAYS = {"map_free": "free", "map_hits": "hits", "map_visited": "visited", "map_searched": "searched"}
# The behaviour state in the file's "state" entry: (attribute, how load reads it back), in the file's order.
STATE: tuple[tuple[str, Callable[[Any], Any]], ...] = (
    ("phase", str),
    ("trial", int),
    ("goal_rewarded", bool),
    ("started", bool),
    ("intended_heading", float),
    ("segment_left", int),
    ("escape_left", int),
    ("heading", float),
    ("last_decision", str),
    ("episode_stats", lambda counts: {str(k): int(v) for k, v in counts.items()}),
    ("total_steps", int),
)
# Behaviour state added within format version 4, with the value a file without it loads.
LATER_STATE: tuple[tuple[str, Callable[[Any], Any], Any], ...] = (
    ("homing_done", bool, False),
    ("memory_failures", int, 0),
    ("homing_bumps", int, 0),
    ("bump_rate", float, 0.0),
    ("fit", float, 1.0),
    ("own_fit", float, 1.0),
    ("look_alikes", lambda offsets: np.asarray(offsets, dtype=np.float64).reshape(-1, 2), []),
    ("look_alike_fit", lambda fits: np.asarray(fits, dtype=np.float64).reshape(-1), []),
)
# The path integrator's, under "state" -> "pi".
PI_STATE: tuple[tuple[str, Callable[[Any], Any]], ...] = (
    ("frame_started", bool),
    ("anchored", bool),
    ("fresh", bool),
    ("confidence", float),
    ("lost_steps", int),
)


def _plain(value: Any) -> Any:
    """``value`` as JSON can hold it (an array as nested lists)."""
    return value.tolist() if isinstance(value, np.ndarray) else value


def _array_slots(agent: Any) -> list[tuple[str, Any, str]]:
    """(name in the file, object holding it, attribute) for every saved array."""
    return [(name, agent if owner == "agent" else getattr(agent, owner), attr) for name, (owner, attr) in ARRAY_HOME.items()]


def save(agent: Any, path: str | os.PathLike) -> None:
    """Write the whole agent (weights, state, generator state, config) to ``path`` (npz).

    The file holds the arrays plus a JSON metadata entry with a format tag and version;
    :meth:`load` restores an agent whose future behaviour is identical.
    """
    meta = {
        "format": FORMAT_TAG,
        "version": FORMAT_VERSION,
        "config": agent.config.to_dict(),
        "seed": agent.seed,
        "observation": {"n_rays": agent.n_rays, "max_range": agent.max_range, "odometry": agent.has_odometry},
        "place_cells": agent.place.n,
        "action": {"kind": agent.action_kind, "n": agent.n_actions},
        "rng_state": agent.rng.bit_generator.state,
        "rng_kind": type(agent.rng.bit_generator).__name__,
        "state": {
            **{name: getattr(agent, name) for name, _ in STATE},
            **{name: _plain(getattr(agent, name)) for name, _, _ in LATER_STATE},
            "pi": {**{name: getattr(agent.pi, name) for name, _ in PI_STATE}, "ruled_out": agent.pi.ruled_out.tolist()},
        },
    }
    arrays = {name: getattr(target, attr) for name, target, attr in _array_slots(agent)}
    arrays["W_pp_slots"] = agent.place.W_pp_used  # the compact W_pp (see PlaceCells)
    arrays["W_pp_cells"] = agent.place.slot_cells
    arrays.update({name: getattr(agent.reward, attr) for name, attr in REWARD_PLACE_ARRAYS.items()})
    if agent.map is not None:
        arrays.update({name: getattr(agent.map, attr) for name, attr in MAP_ARRAYS.items()})
    with open(path, "wb") as f:
        np.savez_compressed(f, __meta__=np.array(json.dumps(meta)), **arrays)


def load(cls: type, path: str | os.PathLike) -> Any:
    """Read an agent written by :meth:`save`; a corrupt, truncated or foreign file raises
    ``ValueError``."""
    what = f"'{os.fspath(path)}' is not a readable hippomaze agent file"
    try:
        with np.load(path, allow_pickle=False) as data:
            if "__meta__" not in data.files:
                raise ValueError(f"{what}: it has no '__meta__' entry (not written by HippocampalAgent.save)")
            meta = json.loads(str(data["__meta__"]))
            missing = [k for k in ARRAYS if k not in data.files]
            if missing:
                raise ValueError(f"{what}: arrays {missing} are missing")
            arrays = {k: data[k] for k in ARRAYS}
            arrays.update({k: data[k] for k in (*MAP_ARRAYS, *REWARD_PLACE_ARRAYS) if k in data.files})
    except ValueError as exc:
        if str(exc).startswith(what):
            raise
        raise ValueError(f"{what}: {exc}") from exc
    except (OSError, EOFError, zipfile.BadZipFile, KeyError, json.JSONDecodeError) as exc:
        raise ValueError(f"{what}: {type(exc).__name__}: {exc}") from exc
    if not isinstance(meta, dict) or meta.get("format") != FORMAT_TAG:
        raise ValueError(f"{what}: format tag is {meta.get('format') if isinstance(meta, dict) else meta!r}, expected {FORMAT_TAG!r}")
    if meta.get("version") != FORMAT_VERSION:
        raise ValueError(f"{what}: format version {meta.get('version')!r} is unsupported; this hippo_agent reads version {FORMAT_VERSION}")
    try:
        config = AgentConfig.from_dict(meta["config"])
        n_rays, max_range = int(meta["observation"]["n_rays"]), float(meta["observation"]["max_range"])
        spaces: dict[str, gym.spaces.Space] = {
            "ranges": gym.spaces.Box(0.0, max_range, (n_rays,), np.float32),
            "heading": gym.spaces.Box(-1.0, 1.0, (2,), np.float32),
        }
        if meta["observation"]["odometry"]:
            spaces["odometry"] = gym.spaces.Box(-ODOMETRY_BOUND, ODOMETRY_BOUND, (2,), np.float32)
        obs_space = gym.spaces.Dict(spaces)
        act_space: gym.spaces.Space
        if meta["action"]["kind"] == "discrete":
            act_space = gym.spaces.Discrete(int(meta["action"]["n"]))
        else:
            act_space = gym.spaces.Box(-np.pi, np.pi, (1,), np.float32)
        agent = cls(obs_space, act_space, config, seed=meta["seed"])
        recruited = int(meta["place_cells"]) - config.n_place
        if recruited < 0 or recruited > max(config.max_place_cells - config.n_place, 0):
            raise ValueError(
                f"place_cells={meta['place_cells']!r} does not fit n_place={config.n_place}, max_place_cells={config.max_place_cells}"
            )
        if recruited:
            agent.grow_place_cells(recruited)  # (the generator's state is restored below)
        for name, target, attr in _array_slots(agent):
            ref, arr = getattr(target, attr), arrays[name]
            ok = (arr.ndim == 2 and arr.shape[1] == agent.place.n) if name == "W_rp" else arr.shape == ref.shape
            if not ok or not np.all(np.isfinite(arr)):
                raise ValueError(f"array {name!r} has shape {arr.shape} or non-finite values")
            setattr(target, attr, arr.astype(ref.dtype))
        goals = agent.reward.W_rp.shape[0]
        for name, attr in REWARD_PLACE_ARRAYS.items():
            ref = np.zeros((goals, *getattr(agent.reward, attr).shape[1:]))
            arr = arrays.get(name, ref)
            if arr.shape != ref.shape or not np.all(np.isfinite(arr)):
                raise ValueError(f"array {name!r} has shape {arr.shape} (expected {ref.shape}) or non-finite values")
            setattr(agent.reward, attr, arr.astype(np.float64))
        if not np.all(np.isfinite(arrays["W_pp_slots"])):
            raise ValueError("array 'W_pp_slots' has non-finite values")
        agent.place.load_W_pp(arrays["W_pp_cells"], arrays["W_pp_slots"])
        if agent.map is not None:
            for name, attr in MAP_ARRAYS.items():
                ref = getattr(agent.map, attr)
                if name not in arrays or arrays[name].shape != ref.shape:
                    raise ValueError(f"the exploration map's array {name!r} is missing or not of shape {ref.shape}")
                setattr(agent.map, attr, arrays[name].astype(ref.dtype))
            agent.map.grids_replaced()
        if meta["rng_kind"] != type(agent.rng.bit_generator).__name__:
            raise ValueError(f"generator {meta['rng_kind']!r} is not {type(agent.rng.bit_generator).__name__}")
        agent.rng.bit_generator.state = meta["rng_state"]
        st = meta["state"]
        if st["phase"] not in ("dry", "trial"):
            raise ValueError(f"phase {st['phase']!r} is not 'dry' or 'trial'")
        for name, read in STATE:
            setattr(agent, name, read(st[name]))
        for name, read, default in LATER_STATE:
            setattr(agent, name, read(st.get(name, default)))
        for name, read in PI_STATE:
            setattr(agent.pi, name, read(st["pi"][name]))
        if len(agent.look_alikes) != len(agent.look_alike_fit):
            raise ValueError(f"{len(agent.look_alikes)} look-alike places but {len(agent.look_alike_fit)} fits to them")
        ruled_out = np.asarray(st["pi"].get("ruled_out", []), dtype=np.float64).reshape(-1, 2)  # (added within version 4)
        if not np.all(np.isfinite(ruled_out)):
            raise ValueError("the path integrator's 'ruled_out' places are not finite")
        agent.pi.ruled_out = ruled_out
    except ValueError as exc:
        raise ValueError(f"{what}: {exc}") from exc
    except (KeyError, TypeError, AttributeError) as exc:
        raise ValueError(f"{what}: metadata is incomplete or malformed ({type(exc).__name__}: {exc})") from exc
    return agent
