"""Config sections: frozen dataclasses whose fields declare their own ranges.

Every part of the agent (the paper's model and each faculty) has one section, a dataclass
deriving from :class:`Section`. A field is declared with :func:`param`, which holds its default
and the values it allows; :meth:`Section.__post_init__` checks the field's type (from its
annotation) and range on construction, so no section writes its own checks but for what ties two
fields together (:meth:`Section._check`).
"""

from __future__ import annotations

import dataclasses
import math
import typing
from dataclasses import dataclass, field
from typing import Any, ClassVar

__all__ = ["Section", "param"]


def param(
    default: Any,
    *,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
) -> Any:
    """A section field with its default and its range: ``ge``/``gt`` (at least / more than) and
    ``le``/``lt`` (at most / less than). ``None`` always passes the range (for fields typed
    ``X | None``, where ``None`` means off)."""
    return field(default=default, metadata={"ge": ge, "gt": gt, "le": le, "lt": lt})


def _allowed(f: dataclasses.Field) -> str:
    """A field's range in words, e.g. ``a value > 0 and <= 1``."""
    words = {"ge": ">=", "gt": ">", "le": "<=", "lt": "<"}
    bounds = [f"{words[key]} {f.metadata[key]}" for key in words if f.metadata.get(key) is not None]
    return "a value " + " and ".join(bounds) if bounds else "any value of its type"


@dataclass(frozen=True)
class Section:
    """A frozen group of parameters (see the module docstring). ``name`` is the section's field
    name in :class:`~hippo_agent.AgentConfig`, used in error messages."""

    name: ClassVar[str] = "section"
    _hints: ClassVar[dict[type, dict[str, Any]]] = {}

    def __post_init__(self) -> None:
        hints = Section._hints.get(type(self))
        if hints is None:
            hints = Section._hints[type(self)] = typing.get_type_hints(type(self))
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            self._check_type(f.name, value, hints[f.name])
            if value is not None and not isinstance(value, str) and not self._in_range(value, f):
                raise self.invalid(f.name, _allowed(f))
        self._check()

    def _check(self) -> None:
        """Checks that tie several fields together (none by default)."""

    def invalid(self, field_name: str, allowed: str) -> ValueError:
        """The error for a field's value outside what is allowed."""
        return ValueError(f"AgentConfig.{self.name}.{field_name}={getattr(self, field_name)!r} is invalid; allowed: {allowed}")

    @staticmethod
    def _in_range(value: float, f: dataclasses.Field) -> bool:
        m = f.metadata
        return (
            (m.get("ge") is None or value >= m["ge"])
            and (m.get("gt") is None or value > m["gt"])
            and (m.get("le") is None or value <= m["le"])
            and (m.get("lt") is None or value < m["lt"])
        )

    def _check_type(self, field_name: str, value: Any, hint: Any) -> None:
        """``value`` against the field's annotation: bool, int, float (finite), a Literal of
        strings, or one of them ``| None``."""
        options = typing.get_args(hint) if typing.get_origin(hint) in (typing.Union, type(int | None)) else (hint,)
        if value is None and type(None) in options:
            return
        for option in options:
            if option is bool and isinstance(value, bool):
                return
            if option is int and isinstance(value, int) and not isinstance(value, bool):
                return
            if option is float and isinstance(value, (int, float)) and not isinstance(value, bool):
                if not math.isfinite(value):
                    raise self.invalid(field_name, "a finite number (not NaN or inf)")
                return
            if typing.get_origin(option) is typing.Literal:
                if value in typing.get_args(option):
                    return
                if isinstance(value, str):
                    raise self.invalid(field_name, " or ".join(repr(a) for a in typing.get_args(option)))
        words = {bool: "True or False", int: "an integer", float: "a finite number", type(None): "None"}
        allowed = " or ".join(words.get(o, "one of " + ", ".join(repr(a) for a in typing.get_args(o))) for o in options)
        raise TypeError(f"AgentConfig.{self.name}.{field_name}={value!r} is of the wrong type; allowed: {allowed}")

    # ------------------------------------------------------------------ conversions
    def to_dict(self) -> dict[str, Any]:
        """The section as a JSON-serialisable dict (field name -> value)."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: Any) -> Any:
        """The section from :meth:`to_dict` output; fields left out keep their defaults, unknown
        ones raise ``ValueError``."""
        if not isinstance(data, dict):
            raise TypeError(f"AgentConfig.{cls.name} must be a dict of its fields (or None: off), got {type(data).__name__}")
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"unknown field(s) {unknown} in AgentConfig.{cls.name}; its fields: {sorted(known)}")
        return cls(**data)

    def replace(self, **changes: Any) -> Any:
        """A copy with some fields changed (checked like the original)."""
        return dataclasses.replace(self, **changes)
