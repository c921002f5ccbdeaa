"""Reflexes: a short escape after a bump, and clearance from walls while preplay steers.

``AgentConfig.reflexes``. The paper does not say what an exploiting robot does at a wall:
preplay, whose broad cosine-tuned slices also predict sliding along a wall, can keep choosing a
blocked heading. So after a bump the robot takes ``escape_steps`` steps of the random walk (which
has turned to a random heading) before the other behaviours steer again: after any bump, or, in
the paper's model, only after one while exploiting. And eq. 10's mean of two open directions at
the corner of a corridor points at the corner's wall: with ``clearance``, preplay's heading turns
to the nearest one the rangefinder shows clear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np

from hippo_agent.sections import Section, param

__all__ = ["ReflexConfig", "Reflexes"]


@dataclass(frozen=True)
class ReflexConfig(Section):
    """The escape after a bump and clearance from walls."""

    name: ClassVar[str] = "reflexes"

    escape_steps: int = param(3, ge=0)
    """Steps of the random walk after a bump before the other behaviours steer again."""
    escape_after: Literal["any bump", "exploiting"] = "any bump"
    """Which bumps start an escape: any, or only those while preplay steers."""
    clearance: float | None = param(0.6, gt=0)
    """While preplay steers, a heading whose 30 degree cone the rangefinder shows blocked nearer
    than this (m) turns to the nearest clear one (``None``: off)."""


class Reflexes:
    """The reflexes (module docstring)."""

    def __init__(self, config: ReflexConfig) -> None:
        self.config = config
        self.escape_left = 0  # escape steps still to take

    def reset(self) -> None:
        """A run begins: no escape under way."""
        self.escape_left = 0

    def bumped(self, decision: str) -> None:
        """A bump while ``decision`` (``"explore"``, ``"exploit"``, ``"home"``) steered."""
        if self.config.escape_after == "any bump" or decision == "exploit":
            self.escape_left = self.config.escape_steps

    def escape(self) -> bool:
        """Whether this step is one of an escape (and count it)."""
        if self.escape_left <= 0:
            return False
        self.escape_left -= 1
        return True

    def clear(self, heading: float, ranges: np.ndarray, facing: float) -> float:
        """``heading`` if the scan (``ranges``, ray 0 along ``facing``) shows ``clearance`` metres
        free within 15 degrees of it; else the nearest heading (in 15 degree steps, up to 90
        either way) that does, or ``heading`` if none does (or ``clearance`` is off)."""
        clearance = self.config.clearance
        if clearance is None:
            return heading
        n = ranges.size
        half_cone = max(1, n // 24)
        for turn in (0.0, 15.0, -15.0, 30.0, -30.0, 45.0, -45.0, 60.0, -60.0, 75.0, -75.0, 90.0, -90.0):
            a = heading + math.radians(turn)
            centre = round(((a - facing) % (2.0 * math.pi)) / (2.0 * math.pi) * n)
            if np.min(ranges.take(np.arange(centre - half_cone, centre + half_cone + 1), mode="wrap")) >= clearance:
                return a
        return heading

    def state(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """(JSON-able state, arrays): what :meth:`load_state` restores."""
        return {"escape_left": self.escape_left}, {}

    def load_state(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`state`."""
        self.escape_left = int(state["escape_left"])
