"""AgentConfig: one section per part (the paper's model and each faculty), ranges declared per
field, ``None`` = a faculty off, the faculties' dependencies, ``with_values``, ``paper()`` and the
``to_dict`` / ``from_dict`` round trip with its layout version."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from hippo_agent import (
    AgentConfig,
    ExplorationConfig,
    HomingConfig,
    LocalisationConfig,
    MapConfig,
    ModelConfig,
    PathIntegrationConfig,
    ReflexConfig,
    WorldsConfig,
)
from hippo_agent.config import CONFIG_VERSION

SECTIONS = {
    "model": ModelConfig,
    "reflexes": ReflexConfig,
    "path_integration": PathIntegrationConfig,
    "map": MapConfig,
    "localisation": LocalisationConfig,
    "exploration": ExplorationConfig,
    "homing": HomingConfig,
    "worlds": WorldsConfig,
}
FACULTIES = ("path_integration", "map", "localisation", "exploration", "homing", "worlds")


def everything_off(**changes):
    """The default model with path integration and every faculty that needs it off."""
    return AgentConfig(**{**{name: None for name in FACULTIES}, **changes})


# ------------------------------------------------------------------ sections
def test_the_default_config_has_every_section_on_with_its_defaults():
    config = AgentConfig()
    assert [f.name for f in dataclasses.fields(config)] == list(SECTIONS)
    for name, kind in SECTIONS.items():
        section = getattr(config, name)
        assert type(section) is kind and section == kind() and kind.name == name


def test_sections_are_frozen():
    config = AgentConfig()
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.model = ModelConfig(n_place=5)  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.model.n_place = 5  # type: ignore[misc]


@pytest.mark.parametrize(
    "name, value, allowed",
    [
        ("model.n_place", -5, ">= 1"),
        ("model.k", float("nan"), "finite"),
        ("model.k", 1.5, "a value > 0 and <= 1"),
        ("model.trace_rate", 0.0, "a value > 0 and <= 1"),
        ("model.lambda_", float("inf"), "finite"),
        ("model.lambda_", -0.1, "a value >= 0 and <= 1"),
        ("model.p_pb", 2.0, "a value >= 0 and <= 1"),
        ("model.bvc_sigma_r", -0.5, "> 0"),
        ("model.n_hd", 7, "even"),
        ("model.dry_run_steps", -1, ">= 0"),
        ("model.segment_max", 2, "segment_min"),
        ("model.discrete_rounding", "floor", "'stochastic' or 'nearest'"),
        ("model.xi", -1e-3, ">= 0"),
        ("homing.radius", -1.0, "> 0"),
        ("homing.radius", 0.0, "> 0"),  # (off is homing=None, no longer a radius of 0)
        ("homing.arrived", 0.0, "> 0"),
        ("homing.attempts", 0, ">= 1"),
        ("homing.search_radius", 0.0, "> 0"),
        ("homing.search_mark", -0.1, "> 0"),
        ("homing.bump_limit", 0, ">= 1"),
        ("homing.approach_radius", 0.0, "> 0"),
        ("localisation.lost_bump_rate", 0.0, "> 0"),
        ("localisation.bump_rate_steps", 0, ">= 1"),
        ("localisation.lost_agreement", 1.5, ">= -1 and <= 1"),
        ("reflexes.clearance", 0.0, "> 0"),  # (off is None)
        ("reflexes.escape_after", "never", "'any bump' or 'exploiting'"),
        ("reflexes.escape_steps", -1, ">= 0"),
        ("path_integration.anchor_weight", 0.0, "> 0 and <= 1"),
        ("path_integration.particles", 1, ">= 2"),
        ("map.cell", 0.0, "> 0"),
        ("map.run_every", 0, ">= 1"),
        ("exploration.max_place_cells", 0, ">= 1"),
    ],
)
def test_a_bad_value_raises_naming_the_section_the_field_and_what_is_allowed(name, value, allowed):
    section, field = name.split(".")
    message = f"AgentConfig.{section}.{field}={value!r} is invalid; allowed: "
    with pytest.raises(ValueError) as by_name:
        AgentConfig().with_values({name: value})
    assert str(by_name.value).startswith(message) and allowed in str(by_name.value)
    with pytest.raises(ValueError) as by_section:
        SECTIONS[section](**{field: value})
    assert str(by_section.value) == str(by_name.value)


@pytest.mark.parametrize(
    "name, value, allowed",
    [
        ("model.n_place", 2.5, "an integer"),
        ("model.n_place", True, "an integer"),
        ("model.learn_pp_in_dry_run", 1, "True or False"),
        ("path_integration.collapse_on_anchor", "yes", "True or False"),
        ("model.k", "0.5", "a finite number"),
        ("model.bvc_max_distance", "far", "a finite number or None"),
        ("localisation.lost_bump_rate", [0.1], "a finite number or None"),
    ],
)
def test_a_value_of_the_wrong_type_raises_type_error(name, value, allowed):
    section, field = name.split(".")
    with pytest.raises(TypeError) as err:
        SECTIONS[section](**{field: value})
    assert str(err.value) == f"AgentConfig.{section}.{field}={value!r} is of the wrong type; allowed: {allowed}"


def test_optional_fields_take_none_for_off():
    assert ModelConfig(bvc_max_distance=None).bvc_max_distance is None
    assert LocalisationConfig(lost_bump_rate=None).lost_bump_rate is None
    assert ReflexConfig(clearance=None).clearance is None
    with pytest.raises(TypeError, match="AgentConfig.model.n_place=None is of the wrong type"):
        ModelConfig(n_place=None)  # type: ignore[arg-type]


def test_the_bvc_and_place_keyword_arguments_come_from_the_model_section():
    model = ModelConfig(bvc_sigma_theta_deg=2.0, n_bvc_distances=20, k=0.25, trace_floor=0.01)
    bvc, place = model.bvc_kwargs(), model.place_kwargs()
    assert bvc["sigma_theta"] == pytest.approx(math.radians(2.0)) and bvc["n_distances"] == 20
    assert bvc["max_distance"] is None and bvc["peak_rate"] == model.bvc_peak_rate
    assert place["k"] == 0.25 and place["trace_floor"] == 0.01 and set(place) <= {f.name for f in dataclasses.fields(model)}


def test_cells_take_their_parameters_from_the_config_only():
    from hippo_agent.cells import BoundaryVectorCells, PlaceCells
    from hippo_agent.faculties.path_integration import PathIntegrator

    with pytest.raises(TypeError):
        BoundaryVectorCells(720, 10.0)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        PlaceCells(10, 20, 8, np.random.default_rng(0))  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        PathIntegrator(10, np.random.default_rng(0))  # type: ignore[call-arg]
    config = AgentConfig()
    BoundaryVectorCells(720, 10.0, **config.model.bvc_kwargs())
    PlaceCells(10, 20, 8, np.random.default_rng(0), **config.model.place_kwargs())
    PathIntegrator(config.path_integration, 10, config.model.k, np.random.default_rng(0))


# ------------------------------------------------------------------ faculties: None = off, and what each needs
def test_a_section_is_none_only_for_a_faculty_and_otherwise_of_its_own_type():
    with pytest.raises(TypeError, match=r"AgentConfig.model=None is of the wrong type; allowed: a ModelConfig$"):
        AgentConfig(model=None)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="AgentConfig.homing=.* is of the wrong type; allowed: a HomingConfig or None"):
        AgentConfig(homing={"radius": 5.0})  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="AgentConfig.map=.* is of the wrong type; allowed: a MapConfig or None"):
        AgentConfig(map=HomingConfig())  # type: ignore[arg-type]
    for name in ("reflexes", "homing", "exploration", "localisation"):
        assert getattr(AgentConfig(**{name: None}), name) is None  # each may be off alone


@pytest.mark.parametrize(
    "off, needing",
    [
        ("path_integration", "map"),
        ("map", "localisation"),
    ],
)
def test_a_faculty_without_what_it_needs_is_an_error_naming_both(off, needing):
    with pytest.raises(ValueError, match=f"AgentConfig.{needing} needs .*{off}"):
        AgentConfig(**{off: None})


@pytest.mark.parametrize("faculty", ["localisation", "exploration", "homing"])
def test_localisation_exploration_and_homing_need_path_integration_and_the_map(faculty):
    on_alone = {name: None for name in FACULTIES if name != faculty}
    with pytest.raises(ValueError, match=f"AgentConfig.{faculty} needs path_integration and map"):
        AgentConfig(**on_alone)
    with pytest.raises(ValueError, match=f"AgentConfig.{faculty} needs map"):
        AgentConfig(**{**on_alone, "path_integration": PathIntegrationConfig()})
    AgentConfig(**{**on_alone, "path_integration": PathIntegrationConfig(), "map": MapConfig()})


def test_path_integration_alone_and_the_paper_model_are_consistent():
    alone = AgentConfig(map=None, localisation=None, exploration=None, homing=None, worlds=None)
    assert alone.path_integration == PathIntegrationConfig() and alone.map is None
    assert everything_off().path_integration is None


def test_paper_config_is_the_paper_model():
    paper = AgentConfig.paper()
    assert all(getattr(paper, name) is None for name in FACULTIES)
    assert paper.reflexes == ReflexConfig(escape_after="exploiting", clearance=None)  # the escape while exploiting only
    assert paper.model == ModelConfig.paper()
    assert not paper.model.learn_pp_in_dry_run and paper.model.dry_run_steps == 5000
    assert (paper.model.tau_r, paper.model.replay_iterations, paper.model.xi, paper.model.xi_here) == (1.0, 20, 1e-3, 1e-6)
    assert AgentConfig.paper().with_values({"model.n_place": 200}).model.n_place == 200
    assert AgentConfig.paper(model=ModelConfig.paper(n_place=200)).model == ModelConfig.paper().replace(n_place=200)
    assert AgentConfig.paper(reflexes=None).reflexes is None
    assert AgentConfig().path_integration is not None
    assert math.isclose(AgentConfig().model.trace_rate, paper.model.trace_rate)
    with pytest.raises(ValueError, match="AgentConfig.homing needs path_integration and map"):
        AgentConfig.paper(homing=HomingConfig())


# ------------------------------------------------------------------ with_values
def test_with_values_changes_fields_by_dotted_name_and_sections_by_name():
    base = AgentConfig()
    changed = base.with_values({"model.n_place": 500, "model.dry_run_steps": 100, "homing.radius": 5.0, "reflexes": None})
    assert changed.model == ModelConfig(n_place=500, dry_run_steps=100)
    assert changed.homing == HomingConfig(radius=5.0) and changed.reflexes is None
    assert changed.map == base.map and changed.path_integration == base.path_integration
    assert base == AgentConfig()  # (a copy: the original is unchanged)
    assert base.with_values({"homing": {"radius": 5.0, "attempts": 2}}).homing == HomingConfig(radius=5.0, attempts=2)
    assert base.with_values({"homing": HomingConfig(arrived=0.2)}).homing == HomingConfig(arrived=0.2)
    assert base.with_values({}) == base


def test_with_values_turns_a_faculty_that_was_off_on_with_its_defaults():
    paper = AgentConfig.paper()
    assert paper.with_values({"reflexes": None, "reflexes.escape_steps": 5}).reflexes == ReflexConfig(escape_steps=5)
    on = everything_off().with_values({"path_integration.gain": 2.0, "map.cell": 0.5})
    assert on.path_integration == PathIntegrationConfig(gain=2.0) and on.map == MapConfig(cell=0.5)
    with pytest.raises(ValueError, match="AgentConfig.homing needs path_integration and map"):
        paper.with_values({"homing.radius": 5.0})  # (checked like any config)


def test_with_values_rejects_unknown_sections_and_fields_naming_what_there_is():
    with pytest.raises(ValueError) as err:
        AgentConfig().with_values({"n_place": 500})  # a flat name of the old layout
    assert "'n_place' names no section of AgentConfig; sections: model, reflexes, path_integration" in str(err.value)
    with pytest.raises(ValueError) as err:
        AgentConfig().with_values({"model.n_cells": 500})
    message = str(err.value)
    assert "AgentConfig.model has no field 'n_cells'" in message and "n_place" in message and "dry_run_steps" in message
    with pytest.raises(ValueError, match=r"unknown field\(s\) \['radiu'\] in AgentConfig.homing; its fields: .*'radius'"):
        AgentConfig().with_values({"homing": {"radiu": 5.0}})


# ------------------------------------------------------------------ to_dict / from_dict
@pytest.mark.parametrize(
    "config",
    [
        AgentConfig(),
        AgentConfig.paper(),
        AgentConfig().with_values({"model.n_place": 123, "model.lambda_": 0.1, "model.bvc_max_distance": 8.0, "homing": None}),
        AgentConfig().with_values({"localisation.lost_bump_rate": None, "reflexes.escape_after": "exploiting"}),
        everything_off(reflexes=None),
    ],
    ids=["default", "paper", "changed", "optional-none", "all-off"],
)
def test_config_round_trips_through_json(config):
    data = config.to_dict()
    assert data["version"] == CONFIG_VERSION == 2
    assert set(data) == {"version", *SECTIONS}
    assert all(data[name] is None or isinstance(data[name], dict) for name in SECTIONS)
    assert AgentConfig.from_dict(json.loads(json.dumps(data, allow_nan=False))) == config


def test_from_dict_keeps_the_defaults_of_what_it_leaves_out():
    assert AgentConfig.from_dict({"version": 2}) == AgentConfig()
    config = AgentConfig.from_dict({"version": 2, "model": {"n_place": 300}, "homing": None})
    assert config == AgentConfig(model=ModelConfig(n_place=300), homing=None)


def test_from_dict_of_the_flat_layout_of_version_1_is_a_clear_error():
    flat = {"n_place": 300, "dry_run_steps": 0, "path_integration": True, "exploration": "directed"}
    for data in (flat, {**flat, "version": 1}):
        with pytest.raises(ValueError) as err:
            AgentConfig.from_dict(data)
        assert "layout version 1" in str(err.value) and "reads version 2" in str(err.value) and "one dict per section" in str(err.value)
    with pytest.raises(ValueError, match="layout version 3"):
        AgentConfig.from_dict({"version": 3})


def test_from_dict_rejects_unknown_sections_fields_and_non_dicts():
    with pytest.raises(ValueError, match=r"unknown AgentConfig section\(s\) \['explore'\]; sections: model, reflexes"):
        AgentConfig.from_dict({"version": 2, "explore": {}})
    with pytest.raises(ValueError, match=r"unknown field\(s\) \['n_cells'\] in AgentConfig.model"):
        AgentConfig.from_dict({"version": 2, "model": {"n_cells": 3}})
    with pytest.raises(TypeError, match="AgentConfig.homing must be a dict of its fields"):
        AgentConfig.from_dict({"version": 2, "homing": 5.0})
    with pytest.raises(TypeError, match="needs a dict"):
        AgentConfig.from_dict([("version", 2)])
    with pytest.raises(ValueError, match="AgentConfig.model.n_place=-3 is invalid"):
        AgentConfig.from_dict({"version": 2, "model": {"n_place": -3}})
