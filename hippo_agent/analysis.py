"""Maps of a trained :class:`~hippo_agent.HippocampalAgent` over many positions, for figures and
analysis: its place fields and its reward map. They read positions the agent never sees while it
acts (privileged, analysis only) and leave its state untouched."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["place_field_map", "reward_map"]


def place_field_map(agent: Any, env: Any, positions: np.ndarray, heading: float = 0.0) -> np.ndarray:
    """Place rates at each position, shape ``(len(positions), n_place)``.

    Uses ``env.unwrapped.observation_at(position, heading)`` and, with path integration, the
    position in the agent's frame as if it were localised there (:meth:`~hippo_agent.HippocampalAgent.frame_offset`):
    analysis only, the agent never sees positions while acting. Positions the environment
    rejects (inside an obstacle) get NaN rows.
    """
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    out = np.full((len(positions), agent.place.n), np.nan)
    base = env.unwrapped
    offset = agent.frame_offset(env) if agent.pi is not None else None
    for n, pos in enumerate(positions):
        try:
            obs = base.observation_at(pos, heading)
        except ValueError:
            continue
        out[n] = agent.place_rates_at(obs, None if offset is None else pos - offset)
    return out


def reward_map(agent: Any, env: Any, positions: np.ndarray, goal: int = -1, heading: float = 0.0) -> np.ndarray:
    """Reward cell ``goal``'s value (eq. 9) at each position, NaN where the env rejects it."""
    rates = place_field_map(agent, env, positions, heading)
    if agent.reward.n == 0:
        return np.where(np.isnan(rates[:, 0]), np.nan, 0.0)
    W = agent.reward.W_rp[goal]
    total = rates.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        val = np.where(total > 0, (rates @ W) / np.where(total > 0, total, 1.0), 0.0)
    return np.where(np.isnan(total), np.nan, val)
