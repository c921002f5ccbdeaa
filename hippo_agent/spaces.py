"""What the agent accepts from the environment: its spaces, its observations, and the actions it gives back."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from hippo_env.geometry import wrap_angle

__all__ = ["check_action_space", "check_observation_space", "to_action", "unpack"]


def check_observation_space(space: Any) -> tuple[int, float, bool]:
    """(rays, max range, whether it holds odometry) of a supported observation space; else an error saying what is allowed."""
    import gymnasium as gym

    allowed = "a gymnasium Dict(ranges=Box(0, max_range, (n_rays,)), heading=Box(-1, 1, (2,))), optionally with odometry=Box(..., (2,))"
    if not isinstance(space, gym.spaces.Dict):
        raise TypeError(f"observation space {space} is unsupported; allowed: {allowed}")
    keys = set(space.spaces)
    if keys not in ({"ranges", "heading"}, {"ranges", "heading", "odometry"}):
        raise ValueError(f"observation space {space} is unsupported; allowed: {allowed}")
    boxes: dict[str, gym.spaces.Box] = {}
    for key, box in space.spaces.items():
        if not isinstance(box, gym.spaces.Box):
            raise TypeError(f"observation space {key!r} {box} is unsupported; allowed: a Box")
        boxes[key] = box
    ranges, heading, odometry = boxes["ranges"], boxes["heading"], boxes.get("odometry")
    if len(ranges.shape) != 1 or ranges.shape[0] < 8:
        raise ValueError(f"observation space 'ranges' {ranges} is unsupported; allowed: a 1-D Box with at least 8 rays")
    if heading.shape != (2,):
        raise ValueError(
            f"observation space 'heading' {heading} is unsupported; allowed: Box(-1, 1, (2,)) holding (cos, sin) of the heading"
        )
    max_range = float(np.max(ranges.high))
    if not (math.isfinite(max_range) and max_range > 0):
        raise ValueError(f"observation space 'ranges' has upper bound {max_range}; allowed: a finite max range > 0")
    if odometry is not None and odometry.shape != (2,):
        raise ValueError(
            f"observation space 'odometry' {odometry} is unsupported; "
            "allowed: Box(low, high, (2,)) holding the (forward, left) displacement in metres"
        )
    return int(ranges.shape[0]), max_range, odometry is not None


def check_action_space(space: Any) -> tuple[str, int]:
    """(``"discrete"`` or ``"heading"``, the number of actions) of a supported action space; else an error saying what is allowed."""
    import gymnasium as gym

    allowed = (
        "Discrete(n) with start 0 (action k = heading 2*pi*k/n, the env's action_type='discrete') "
        "or Box(-pi, pi, (1,)) (action_type='heading')"
    )
    if isinstance(space, gym.spaces.Discrete):
        if int(space.start) != 0 or int(space.n) < 4:
            raise ValueError(f"action space {space} is unsupported; allowed: {allowed}")
        return "discrete", int(space.n)
    if isinstance(space, gym.spaces.Box) and space.shape == (1,):
        lo, hi = float(space.low[0]), float(space.high[0])
        if lo <= -math.pi + 1e-3 and hi >= math.pi - 1e-3:
            return "heading", 1
    if not isinstance(space, gym.spaces.Box):
        raise TypeError(f"action space {space} is unsupported; allowed: {allowed}")
    raise ValueError(f"action space {space} is unsupported; allowed: {allowed}")


def unpack(observation: Any) -> tuple[np.ndarray, np.ndarray, float]:
    """(ranges, heading as (cos, sin), heading in radians) of an observation."""
    try:
        ranges = np.asarray(observation["ranges"])
        heading_vec = np.asarray(observation["heading"], dtype=np.float64)
    except (KeyError, TypeError, IndexError) as exc:
        raise ValueError("observation must be a dict with 'ranges' (n_rays,) and 'heading' (cos, sin)") from exc
    if heading_vec.shape != (2,):
        raise ValueError(f"observation 'heading' has shape {heading_vec.shape}; expected (2,)")
    hx, hy = heading_vec.tolist()  # (floats: faster than indexing the array)
    return ranges, heading_vec, math.atan2(hy, hx)


def to_action(heading: float, kind: str, n_actions: int, rounding: str, rng: np.random.Generator) -> Any:
    """An allocentric heading as an action: itself (``kind="heading"``), or one of ``n_actions``
    discrete headings, rounded to the nearest or stochastically (the neighbour toward the heading
    with probability equal to the fraction of the gap: the expected direction is the heading)."""
    if kind == "heading":
        return np.array([wrap_angle(heading)], dtype=np.float32)
    x = (heading % (2.0 * math.pi)) / (2.0 * math.pi / n_actions)
    if rounding == "nearest":
        k = math.floor(x + 0.5)
    else:
        lo = math.floor(x)
        k = lo + int(rng.random() < x - lo)
    return int(k % n_actions)
