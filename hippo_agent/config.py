"""The hippocampal agent's configuration: the paper's model's section plus one section per faculty.

``AgentConfig()`` is the default model: every faculty on. ``AgentConfig.paper()`` is the paper's
model: every faculty off (``None``) but the escape reflex, and the paper's values in ``model``.
Each section is a frozen dataclass defined beside the code it configures; its fields declare
their ranges, and a wrong value raises an error naming the field and what is allowed::

    AgentConfig(model=ModelConfig(n_place=500), homing=None)   # the default model, fewer cells, no homing
    AgentConfig().with_values({"model.n_place": 500, "homing": None})  # the same, by dotted names

``docs/parameters.md`` gives every value's source and why.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from hippo_agent.faculties.exploration import ExplorationConfig
from hippo_agent.faculties.homing import HomingConfig
from hippo_agent.faculties.localisation import LocalisationConfig
from hippo_agent.faculties.map import MapConfig
from hippo_agent.faculties.path_integration import PathIntegrationConfig
from hippo_agent.faculties.reflexes import ReflexConfig
from hippo_agent.faculties.worlds import WorldsConfig
from hippo_agent.paper_model import ModelConfig
from hippo_agent.sections import Section

__all__ = [
    "AgentConfig",
    "ExplorationConfig",
    "HomingConfig",
    "LocalisationConfig",
    "MapConfig",
    "ModelConfig",
    "PathIntegrationConfig",
    "ReflexConfig",
    "WorldsConfig",
]

CONFIG_VERSION = 2
"""Raised whenever the layout of :meth:`AgentConfig.to_dict` changes (1: one flat dict of fields)."""

# what each faculty needs switched on
_NEEDS = {
    "map": ("path_integration",),
    "localisation": ("path_integration", "map"),
    "exploration": ("path_integration", "map"),
    "homing": ("path_integration", "map"),
    "worlds": ("path_integration", "map"),
}


@dataclass(frozen=True)
class AgentConfig:
    """Parameters of :class:`hippo_agent.HippocampalAgent`: the paper's model and its faculties.

    A faculty set to ``None`` is off. Construct with keyword arguments (sections left out keep
    their defaults); ``AgentConfig.from_dict(cfg.to_dict())`` round-trips exactly.
    """

    model: ModelConfig = field(default_factory=ModelConfig)
    """The paper's model: its cells, learning rules, replay, preplay and random walk (:mod:`hippo_agent.paper_model`)."""
    reflexes: ReflexConfig | None = field(default_factory=ReflexConfig)
    """The escape after a bump and clearance from walls (:mod:`hippo_agent.faculties.reflexes`)."""
    path_integration: PathIntegrationConfig | None = field(default_factory=PathIntegrationConfig)
    """Odometry into a belief of where the robot is, driving the place cells (:mod:`hippo_agent.faculties.path_integration`).
    Needs the environment's odometry observation (``gym.make("HippoMaze-v0", odometry=True)``)."""
    map: MapConfig | None = field(default_factory=MapConfig)
    """A map from the agent's own senses, and its planner (:mod:`hippo_agent.faculties.map`)."""
    localisation: LocalisationConfig | None = field(default_factory=LocalisationConfig)
    """The belief checked against the map (:mod:`hippo_agent.faculties.localisation`)."""
    exploration: ExplorationConfig | None = field(default_factory=ExplorationConfig)
    """Directed exploration, rest, and recruitment (:mod:`hippo_agent.faculties.exploration`); ``None``: the random walk."""
    homing: HomingConfig | None = field(default_factory=HomingConfig)
    """Back to where the goal was found (:mod:`hippo_agent.faculties.homing`)."""
    worlds: WorldsConfig | None = field(default_factory=WorldsConfig)
    """Several worlds, each with its own map and memories, recognised by the scan (:mod:`hippo_agent.faculties.worlds`)."""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value, kind = getattr(self, f.name), _SECTIONS[f.name]
            if not (isinstance(value, kind) or (value is None and f.name != "model")):
                allowed = f"a {kind.__name__}" + ("" if f.name == "model" else " or None (off)")
                raise TypeError(f"AgentConfig.{f.name}={value!r} is of the wrong type; allowed: {allowed}")
        for faculty, needs in _NEEDS.items():
            missing = [n for n in needs if getattr(self, faculty) is not None and getattr(self, n) is None]
            if missing:
                raise ValueError(
                    f"AgentConfig.{faculty} needs {' and '.join(missing)}: turn {faculty} off (None) or {' and '.join(missing)} on"
                )

    @classmethod
    def paper(cls, **changes: Any) -> AgentConfig:
        """The model as the paper describes it: every faculty off but the escape reflex after a
        bump while exploiting, and the paper's values in ``model`` (:meth:`ModelConfig.paper`)."""
        paper: dict[str, Any] = {
            "model": ModelConfig.paper(),
            "reflexes": ReflexConfig(escape_after="exploiting", clearance=None),
            **{name: None for name in ("path_integration", "map", "localisation", "exploration", "homing", "worlds")},
        }
        return cls(**{**paper, **changes})

    def replace(self, **changes: Any) -> AgentConfig:
        """A copy with some sections replaced (checked like the original)."""
        return dataclasses.replace(self, **changes)

    def with_values(self, values: dict[str, Any]) -> AgentConfig:
        """A copy with fields changed by dotted name (``{"model.n_place": 500}``) or sections by name:
        ``{"homing": None}`` turns a faculty off, ``{"homing": {"radius": 5.0}}`` changes those fields
        of the section (of its defaults if it was off)."""
        sections: dict[str, Any] = {}
        for key, value in values.items():
            section, _, field_name = key.partition(".")
            if section not in _SECTIONS:
                raise ValueError(f"{key!r} names no section of AgentConfig; sections: {', '.join(_SECTIONS)}")
            if not field_name:  # a whole section: None (off), a section, or a dict of fields to change in it
                if isinstance(value, dict):
                    current = sections.get(section, getattr(self, section))
                    value = _SECTIONS[section].from_dict({**({} if current is None else current.to_dict()), **value})
                sections[section] = value
                continue
            current = sections.get(section, getattr(self, section))
            if current is None:
                current = _SECTIONS[section]()  # a faculty that was off, on with the defaults
            if field_name not in {f.name for f in dataclasses.fields(current)}:
                raise ValueError(f"{key!r}: AgentConfig.{section} has no field {field_name!r}; its fields: {_field_names(current)}")
            sections[section] = current.replace(**{field_name: value})
        return self.replace(**sections)

    def to_dict(self) -> dict[str, Any]:
        """The config as a JSON-serialisable dict: each section a dict of its fields, ``None`` if off."""
        return {"version": CONFIG_VERSION, **{name: None if s is None else s.to_dict() for name, s in self._sections()}}

    @classmethod
    def from_dict(cls, data: Any) -> AgentConfig:
        """Build a config from :meth:`to_dict` output (sections left out keep their defaults);
        unknown sections or fields raise ``ValueError``, a flat dict of an earlier version says so."""
        if not isinstance(data, dict):
            raise TypeError(f"AgentConfig.from_dict needs a dict, got {type(data).__name__}")
        version = data.get("version", 1)
        if version != CONFIG_VERSION:
            raise ValueError(
                f"this AgentConfig dict is of layout version {version} (version 1: one flat dict of fields, "
                f"hippomaze 0.1); this hippo_agent reads version {CONFIG_VERSION}: one dict per section ({', '.join(_SECTIONS)})"
            )
        unknown = sorted(set(data) - set(_SECTIONS) - {"version"})
        if unknown:
            raise ValueError(f"unknown AgentConfig section(s) {unknown}; sections: {', '.join(_SECTIONS)}")
        sections: dict[str, Any] = {
            name: None if value is None else _SECTIONS[name].from_dict(value) for name, value in data.items() if name != "version"
        }
        return cls(**sections)

    def _sections(self) -> list[tuple[str, Section | None]]:
        return [(f.name, getattr(self, f.name)) for f in dataclasses.fields(self)]


def _field_names(section: Section) -> str:
    return ", ".join(f.name for f in dataclasses.fields(section))


_SECTIONS: dict[str, type[Any]] = {
    "model": ModelConfig,
    "reflexes": ReflexConfig,
    "path_integration": PathIntegrationConfig,
    "map": MapConfig,
    "localisation": LocalisationConfig,
    "exploration": ExplorationConfig,
    "homing": HomingConfig,
    "worlds": WorldsConfig,
}
