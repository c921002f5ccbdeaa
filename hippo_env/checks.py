"""Checking arguments: one rule everywhere, and messages that say what is allowed.

An argument of a type that is not accepted (a string where a number is needed, a float where an
integer is, a bool anywhere a number is) raises ``TypeError``; an argument of an accepted type
whose value is not allowed (negative, out of range, not finite, an unknown name) raises
``ValueError``. The content of a document (a maze's JSON, a saved agent's metadata) is a value:
anything wrong in it is a ``ValueError``, whatever its type. Both messages name the argument, what
it got and what is allowed: ``TypeError("n_rays must be a positive integer, got 2.5")``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def check_int(value: Any, name: str, minimum: int, allowed: str) -> int:
    """``value`` as an ``int``: ``TypeError`` unless it is an integer (a bool is not), ``ValueError``
    if it is below ``minimum``; both messages read ``"{name} must be {allowed}, got {value!r}"``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be {allowed}, got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be {allowed}, got {value!r}")
    return int(value)


def check_number(value: Any, name: str, allowed: str, minimum: float = -math.inf, *, strict: bool = False) -> float:
    """``value`` as a finite ``float``: ``TypeError`` unless it is a real number (a bool is not),
    ``ValueError`` if it is not finite or below ``minimum`` (or equal to it, with ``strict``);
    both messages read ``"{name} must be {allowed}, got {value!r}"``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be {allowed}, got {value!r}")
    if not math.isfinite(value) or value < minimum or (strict and value == minimum):
        raise ValueError(f"{name} must be {allowed}, got {value!r}")
    return float(value)


__all__ = ["check_int", "check_number"]
