"""Saving and loading a :class:`~hippo_agent.HippocampalAgent`: one npz file.

The file holds a JSON metadata entry (format tag and version, the config, the spaces, the
generator's state, the agent's own state) and every part's state: the paper's model and each
faculty give theirs (``state()``: a JSON-able dict and named arrays) and take it back
(``load_state()``), so a part's state lives with its code. Arrays are stored as
``"<part>.<name>"``. A loaded agent behaves exactly as the saved one would have.
"""

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

__all__ = ["FORMAT_TAG", "FORMAT_VERSION", "PARTS", "load", "save"]

FORMAT_TAG = "hippomaze.HippocampalAgent"
FORMAT_VERSION = 5
"""Raised whenever what a file holds changes; files of another version are refused, naming it.
Version 4 (hippomaze 0.1) kept the agent as one flat object; version 5 saves each part's own state."""

PARTS = ("model", "pi", "map", "localisation", "exploration", "homing", "reflexes", "worlds")
"""The agent's attributes that save their own state (``None`` ones, faculties that are off, are skipped)."""

# the agent's own state: attribute -> how load reads it back
_AGENT_STATE: dict[str, Callable[[Any], Any]] = {
    "phase": str,
    "trial": int,
    "started": bool,
    "last_decision": str,
    "total_steps": int,
    "episode_stats": lambda counts: {str(k): int(v) for k, v in counts.items()},
}


def save(agent: Any, path: str | os.PathLike) -> None:
    """Write the whole agent to ``path`` (npz); :func:`load` restores it."""
    parts, arrays = {}, {}
    for name in PARTS:
        part = getattr(agent, name)
        if part is not None:
            parts[name], part_arrays = part.state()
            arrays.update({f"{name}.{key}": value for key, value in part_arrays.items()})
    if agent.senses is not None:  # the last scan: the clearance reflex reads it when the agent next acts
        arrays["senses.ranges"], arrays["senses.heading_vec"] = agent.senses.ranges, agent.senses.heading_vec
    meta = {
        "format": FORMAT_TAG,
        "version": FORMAT_VERSION,
        "config": agent.config.to_dict(),
        "seed": agent.seed,
        "observation": {"n_rays": agent.n_rays, "max_range": agent.max_range, "odometry": agent.has_odometry},
        "action": {"kind": agent.action_kind, "n": agent.n_actions},
        "rng": {"kind": type(agent.rng.bit_generator).__name__, "state": agent.rng.bit_generator.state},
        "agent": {name: getattr(agent, name) for name in _AGENT_STATE},
        "parts": parts,
    }
    with open(path, "wb") as f:
        np.savez_compressed(f, __meta__=np.array(json.dumps(meta)), **arrays)


def load(cls: type, path: str | os.PathLike) -> Any:
    """Read an agent written by :func:`save`; a corrupt, truncated or foreign file, or one of
    another format version, raises ``ValueError`` saying what is wrong."""
    what = f"'{os.fspath(path)}' is not a readable hippomaze agent file"
    try:
        with np.load(path, allow_pickle=False) as data:
            if "__meta__" not in data.files:
                raise ValueError(f"{what}: it has no '__meta__' entry (not written by HippocampalAgent.save)")
            meta = json.loads(str(data["__meta__"]))
            arrays = {key: data[key] for key in data.files if key != "__meta__"}
    except ValueError as exc:
        if str(exc).startswith(what):
            raise
        raise ValueError(f"{what}: {exc}") from exc
    except (OSError, EOFError, zipfile.BadZipFile, KeyError, json.JSONDecodeError) as exc:
        raise ValueError(f"{what}: {type(exc).__name__}: {exc}") from exc
    if not isinstance(meta, dict) or meta.get("format") != FORMAT_TAG:
        raise ValueError(f"{what}: format tag is {meta.get('format') if isinstance(meta, dict) else meta!r}, expected {FORMAT_TAG!r}")
    if meta.get("version") != FORMAT_VERSION:
        raise ValueError(
            f"{what}: format version {meta.get('version')!r} is unsupported; this hippo_agent reads version {FORMAT_VERSION} "
            "(version 4 files, from hippomaze 0.1, can be read by that release only)"
        )
    try:
        agent = cls(
            _observation_space(meta["observation"]), _action_space(meta["action"]), AgentConfig.from_dict(meta["config"]), seed=meta["seed"]
        )
        _restore(agent, meta, arrays)
    except ValueError as exc:
        raise ValueError(f"{what}: {exc}") from exc
    except (KeyError, TypeError, AttributeError) as exc:
        raise ValueError(f"{what}: metadata is incomplete or malformed ({type(exc).__name__}: {exc})") from exc
    return agent


def _restore(agent: Any, meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
    """Every part's state, the agent's own and the generator's, from the file."""
    parts = meta["parts"]
    place_cells = int(parts["model"]["place_cells"])
    recruited = place_cells - agent.config.model.n_place
    most = agent.config.exploration.max_place_cells if agent.config.exploration is not None else agent.config.model.n_place
    if recruited < 0 or place_cells > max(most, agent.config.model.n_place):
        raise ValueError(f"place_cells={place_cells} does not fit model.n_place={agent.config.model.n_place} and max_place_cells={most}")
    if recruited:
        agent.grow_place_cells(recruited)  # (the generator's state is restored below)
    for name in PARTS:
        part = getattr(agent, name)
        if part is None:
            continue
        if name not in parts:
            if name == "worlds":
                continue  # (a save from before the agent kept several worlds: it knows one)
            raise ValueError(f"the state of {name!r} is missing")
        prefix = f"{name}."
        part.load_state(parts[name], {key[len(prefix) :]: value for key, value in arrays.items() if key.startswith(prefix)})
    rng = meta["rng"]
    if rng["kind"] != type(agent.rng.bit_generator).__name__:
        raise ValueError(f"generator {rng['kind']!r} is not {type(agent.rng.bit_generator).__name__}")
    agent.rng.bit_generator.state = rng["state"]
    state = meta["agent"]
    if state["phase"] not in ("dry", "trial"):
        raise ValueError(f"phase {state['phase']!r} is not 'dry' or 'trial'")
    for name, read in _AGENT_STATE.items():
        setattr(agent, name, read(state[name]))
    if "senses.ranges" in arrays:
        agent.restore_senses(arrays["senses.ranges"], arrays["senses.heading_vec"])


def _observation_space(observation: dict[str, Any]) -> gym.spaces.Dict:
    n_rays, max_range = int(observation["n_rays"]), float(observation["max_range"])
    spaces: dict[str, gym.spaces.Space] = {
        "ranges": gym.spaces.Box(0.0, max_range, (n_rays,), np.float32),
        "heading": gym.spaces.Box(-1.0, 1.0, (2,), np.float32),
    }
    if observation["odometry"]:
        spaces["odometry"] = gym.spaces.Box(-ODOMETRY_BOUND, ODOMETRY_BOUND, (2,), np.float32)
    return gym.spaces.Dict(spaces)


def _action_space(action: dict[str, Any]) -> gym.spaces.Space:
    if action["kind"] == "discrete":
        return gym.spaces.Discrete(int(action["n"]))
    return gym.spaces.Box(-np.pi, np.pi, (1,), np.float32)
