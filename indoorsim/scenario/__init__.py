"""Scenarios: the schema of a scenario file, its checks, loading and dumping, and generators.

* :mod:`~indoorsim.scenario.schema` — the pydantic specs (the bottom layer: the
  world, walker and phone read them);
* :mod:`~indoorsim.scenario.checks` — problems between keys and in the geometry;
* :mod:`~indoorsim.scenario.load` — YAML in and out, bundled scenarios by name;
* :mod:`~indoorsim.scenario.generate` — procedural buildings, one module per kind;
* :mod:`~indoorsim.scenario.imports` — real floor plans (the Indoor Location
  Competition's GeoJSON) and real traces' waypoints as scenarios and routes.

Every error names the file, the dotted key path and the problem, and nothing is
half-loaded: :func:`load_scenario` either returns a fully validated
:class:`Scenario` (schema *and* geometry checked) or raises :class:`ScenarioError`
listing every problem found.

The loader's names are imported on first use: the world layer imports the
schema, and the loader checks geometry with the world's floor plan, so an
eager import here would close a circle.
"""

from __future__ import annotations

import importlib
from typing import Any

from indoorsim.scenario.schema import (
    SURVEY_KINDS,
    DaylightSpec,
    DipoleSpec,
    DoorSpec,
    GridSurveySpec,
    LightSpec,
    LuminaireSpec,
    MagneticSpec,
    MaterialName,
    ObstacleSpec,
    PillarSpec,
    RadioSpec,
    RebarSpec,
    ReflectanceSpec,
    RoomSpec,
    RouteSpec,
    Scenario,
    ScenarioError,
    SiteSpec,
    SurveySpec,
    WalkSurveySpec,
    WallSpec,
    WifiApSpec,
    WindowSpec,
    key_path,
)

__all__ = [
    "ENTRY_POINT_GROUP",
    "SURVEY_KINDS",
    "DaylightSpec",
    "DipoleSpec",
    "DoorSpec",
    "GridSurveySpec",
    "LightSpec",
    "LuminaireSpec",
    "MagneticSpec",
    "MaterialName",
    "ObstacleSpec",
    "PillarSpec",
    "RadioSpec",
    "RebarSpec",
    "ReflectanceSpec",
    "RoomSpec",
    "RouteSpec",
    "Scenario",
    "ScenarioError",
    "SiteSpec",
    "SurveySpec",
    "WalkSurveySpec",
    "WallSpec",
    "WifiApSpec",
    "WindowSpec",
    "bundled_scenarios",
    "dump_scenario",
    "key_path",
    "load_scenario",
    "parse_scenario",
    "resolve_scenario",
    "scenario_to_dict",
]

_LOADER = frozenset(
    {
        "ENTRY_POINT_GROUP",
        "bundled_scenarios",
        "dump_scenario",
        "load_scenario",
        "load_site",
        "parse_scenario",
        "resolve_scenario",
        "scenario_to_dict",
    }
)


def __getattr__(name: str) -> Any:
    if name in _LOADER:
        return getattr(importlib.import_module("indoorsim.scenario.load"), name)
    raise AttributeError(f"module 'indoorsim.scenario' has no attribute {name!r}")
