"""Real floor plans as scenarios: one module per plan format.

* :mod:`~indoorsim.scenario.imports.ilc` — the GeoJSON floor plans of the
  Indoor Location Competition 2.0 (Microsoft Research / XYZ10) with their
  ``floor_info.json``, and the competition traces' waypoints as routes.

An importer builds the walls, rooms and doors from the plan and places what
the plan does not show (lights, access points, steel) by the procedural
generator's rules (:mod:`indoorsim.scenario.generate`), seeded: the same plan
and seed always give the same scenario, byte for byte once dumped. It reads
plain data (parsed JSON, waypoint lists); reading real traces is the
``io`` layer's job, and the command line (``indoorsim import-plan``) joins them.
"""

from __future__ import annotations

from indoorsim.scenario.imports.ilc import (
    IlcFloor,
    ImportedPlan,
    PlanImportError,
    RouteImport,
    add_trace_routes,
    import_ilc_floor,
    parse_ilc_floor,
    read_ilc_floor,
    waypoint_speed,
)

__all__ = [
    "IlcFloor",
    "ImportedPlan",
    "PlanImportError",
    "RouteImport",
    "add_trace_routes",
    "import_ilc_floor",
    "parse_ilc_floor",
    "read_ilc_floor",
    "waypoint_speed",
]
