"""The few pymunk calls on the simulator's hot path, in two implementations with one signature.

``"cffi"`` calls the C functions that pymunk's own properties and ``Space.step`` call
(``pymunk._chipmunk_cffi.lib``), without the Python around each call (a ``Vec2d`` built on every
read, argument checks). It is used only on the pymunk versions in :data:`CHECKED_PYMUNK`: the C
bindings are private and may change in any release. ``"public"`` is pymunk's public API and is used
everywhere else (and when ``HIPPO_ENV_PYMUNK=public`` is set, or on request). Both give the same
results bit for bit (``tests/test_physics.py`` checks it).

This module owns no lifetime. A handle (:meth:`PymunkCalls.handles`) is, on the C path, a
non-owning cast of the pointer inside a pymunk object: it neither keeps the C object alive nor
frees it, so pymunk alone decides when its objects are freed. A handle is valid only while the
pymunk object it came from is alive: whoever takes one keeps that object and takes the handles
again whenever it replaces the object (or is unpickled). Holding pymunk's own owning pointers
instead (``space._space``, ``body._body``) keeps a C space alive past its Python wrapper, and
freeing it later, in whatever order the cyclic garbage collector chooses, crashes the interpreter.

Only this module names pymunk's private attributes.
"""

from __future__ import annotations

import operator
import os
from collections.abc import Callable
from typing import Any

import pymunk

CHECKED_PYMUNK: tuple[str, ...] = ("7.3",)
"""pymunk versions (major.minor) on which the C path was checked against the public API, bit for bit."""

ENV_VAR = "HIPPO_ENV_PYMUNK"
"""Set to ``public`` to make every new world use the public API; ``auto`` (or unset) picks the C path where checked."""

IMPLEMENTATIONS = ("cffi", "public")


class PymunkCalls:
    """One implementation of the calls. Bodies and spaces are passed as :meth:`handles` returns them.

    Readers of vectors return an object with float attributes ``x`` and ``y``; setters of vectors
    take an ``(x, y)`` tuple.
    """

    name: str
    """``"cffi"`` or ``"public"``."""
    handles: Callable[[pymunk.Space, pymunk.Body], tuple[Any, Any]]
    """``(space, body)`` as the other calls take them."""
    get_position: Callable[[Any], Any]
    get_angle: Callable[[Any], float]
    get_velocity: Callable[[Any], Any]
    get_angular_velocity: Callable[[Any], float]
    set_angle: Callable[[Any, float], None]
    set_velocity: Callable[[Any, tuple[float, float]], None]
    set_angular_velocity: Callable[[Any, float], None]
    set_force: Callable[[Any, tuple[float, float]], None]
    set_torque: Callable[[Any, float], None]
    space_step: Callable[[Any, float], None]
    """Advances the space by a time step (the space handle and seconds)."""

    def __init__(self, name: str, **calls: Callable[..., Any]) -> None:
        self.name = name
        for key, call in calls.items():
            setattr(self, key, call)

    def __repr__(self) -> str:
        return f"PymunkCalls({self.name!r})"


def _setter(attribute: str) -> Callable[[Any, Any], None]:
    def set_attribute(obj: Any, value: Any) -> None:
        setattr(obj, attribute, value)

    set_attribute.__name__ = f"set_{attribute}"
    return set_attribute


def _step(space: pymunk.Space, dt: float) -> None:
    space.step(dt)


PUBLIC = PymunkCalls(
    "public",
    handles=lambda space, body: (space, body),
    get_position=operator.attrgetter("position"),
    get_angle=operator.attrgetter("angle"),
    get_velocity=operator.attrgetter("velocity"),
    get_angular_velocity=operator.attrgetter("angular_velocity"),
    set_angle=_setter("angle"),
    set_velocity=_setter("velocity"),
    set_angular_velocity=_setter("angular_velocity"),
    set_force=_setter("force"),
    set_torque=_setter("torque"),
    space_step=_step,
)
"""pymunk's public API."""


def _cffi_calls() -> tuple[PymunkCalls | None, str]:
    """The C path, or None and why it is not used with this pymunk."""
    major_minor = ".".join(pymunk.version.split(".")[:2])
    if major_minor not in CHECKED_PYMUNK:
        return None, f"pymunk {pymunk.version} is not among the versions the C path was checked on ({', '.join(CHECKED_PYMUNK)})"
    try:
        from pymunk._chipmunk_cffi import ffi, lib

        cast = ffi.cast

        def handles(space: pymunk.Space, body: pymunk.Body) -> tuple[Any, Any]:
            return cast("cpSpace *", space._space), cast("cpBody *", body._body)

        calls = PymunkCalls(
            "cffi",
            handles=handles,
            get_position=lib.cpBodyGetPosition,
            get_angle=lib.cpBodyGetAngle,
            get_velocity=lib.cpBodyGetVelocity,
            get_angular_velocity=lib.cpBodyGetAngularVelocity,
            set_angle=lib.cpBodySetAngle,
            set_velocity=lib.cpBodySetVelocity,
            set_angular_velocity=lib.cpBodySetAngularVelocity,
            set_force=lib.cpBodySetForce,
            set_torque=lib.cpBodySetTorque,
            space_step=lib.cpSpaceStep,
        )
    except (ImportError, AttributeError) as err:
        return None, f"pymunk's C bindings are not as expected: {type(err).__name__}: {err}"
    return calls, ""


CFFI, CFFI_UNAVAILABLE = _cffi_calls()
"""The C path (None where it is not used) and, if None, why."""


def choose(implementation: str | None = None) -> PymunkCalls:
    """The calls to use: ``"cffi"`` (falling back to the public API where the C path is not
    available), ``"public"``, or ``None``/``"auto"``: the C path where available unless the
    environment variable ``HIPPO_ENV_PYMUNK`` is ``public``."""
    if implementation in (None, "auto"):
        implementation = os.environ.get(ENV_VAR, "auto") or "auto"
        if implementation not in ("auto", *IMPLEMENTATIONS):
            raise ValueError(f"{ENV_VAR}={implementation!r} is unknown; allowed: auto, cffi, public")
    elif implementation not in IMPLEMENTATIONS:
        raise ValueError(f"pymunk implementation {implementation!r} is unknown; allowed: auto, cffi, public")
    if implementation == "public" or CFFI is None:
        return PUBLIC
    return CFFI


def settle(space: pymunk.Space) -> None:
    """pymunk's own bookkeeping of ``Space.step`` without advancing time.

    ``Space.step`` checks the bodies added since the last step and lets go of the shapes removed
    since; the C path's step skips that, so a caller that adds or removes objects calls this
    afterwards (or the removed shapes stay referenced by the space). Chipmunk ignores a step of
    zero seconds, so nothing moves and no solver state changes.
    """
    space.step(0.0)
