"""The bundled scenarios: each loads and round-trips, and the papers' stated
dimensions, light counts, route lengths and survey plans hold (sources in
scenarios/README.md)."""

from __future__ import annotations

import datetime
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from shapely.geometry import LineString, Point
from shapely.ops import unary_union

import indoorsim
from indoorsim.scenario import (
    Scenario,
    bundled_scenarios,
    dump_scenario,
    load_scenario,
    parse_scenario,
    resolve_scenario,
)
from indoorsim.world.plan import FloorPlan
from tests.conftest import REPO, SHARED

SCENARIOS = REPO / "scenarios"
BUNDLED = sorted(SCENARIOS.glob("*.yaml"))
SHARED_MINIMAL = SHARED / "examples/minimal-site.yaml"
EXPECTED = {
    "minimal_room",
    "han2023_basement",
    "han2023_corridor",
    "chen2022_lab",
    "chen2022_office",
}


def load(name: str) -> Scenario:
    return load_scenario(SCENARIOS / f"{name}.yaml")


def route_length(s: Scenario, name: str) -> float:
    wp = np.array(s.routes[name].waypoints)
    return float(np.linalg.norm(np.diff(wp, axis=0), axis=1).sum())


def bearings(s: Scenario, name: str) -> list[float]:
    """Compass bearing of each leg (degrees clockwise from true north): the
    building's +y axis points ``north_deg`` clockwise from north."""
    wp = np.array(s.routes[name].waypoints)
    d = np.diff(wp, axis=0)
    return [(s.site.north_deg + math.degrees(math.atan2(dx, dy))) % 360 for dx, dy in d]


def walkable_run(plan: FloorPlan, a: tuple[float, float], b: tuple[float, float], through) -> float:
    """Length of the walkable stretch of the line a→b that contains ``through``."""
    part = plan.walkable.intersection(LineString([a, b]))
    pieces = getattr(part, "geoms", [part])
    return next(p.length for p in pieces if p.distance(Point(through)) < 1e-9)


def test_all_expected_scenarios_are_bundled() -> None:
    assert {p.stem for p in BUNDLED} == EXPECTED


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.stem)
def test_loads_and_round_trips(path: Path, tmp_path: Path) -> None:
    s = load_scenario(path)
    assert parse_scenario(yaml.safe_load(dump_scenario(s))) == s
    dump_scenario(s, tmp_path / path.name)
    assert load_scenario(tmp_path / path.name) == s


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_loadable_by_name(name: str) -> None:
    assert resolve_scenario(name) == bundled_scenarios()[name]
    assert load_scenario(resolve_scenario(name)) == load(name)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_every_site_has_steel_and_wifi(name: str) -> None:
    s = load(name)
    assert s.magnetic.dipoles
    assert len(s.wifi) >= 2
    assert s.luminaires


@pytest.mark.parametrize("name", sorted(EXPECTED - {"minimal_room"}))
def test_paper_sites_say_what_is_reconstructed(name: str) -> None:
    s = load(name)
    assert "reconstructed" in s.description
    assert s.magnetic.rebar and s.pillars


def test_shared_minimal_example_loads_and_is_bundled_under_its_registry_name() -> None:
    if not SHARED_MINIMAL.is_file():
        pytest.skip(f"shared folder not found beside the repository: {SHARED_MINIMAL}")
    shared = load_scenario(SHARED_MINIMAL)
    assert shared.name == "minimal-room"
    # The bundled copy differs only in its name, which matches its file (and
    # registry) name so that a recording's manifest names a loadable scenario.
    assert load("minimal_room") == shared.model_copy(update={"name": "minimal_room"})
    bundled = (SCENARIOS / "minimal_room.yaml").read_text()
    assert bundled == SHARED_MINIMAL.read_text().replace("name: minimal-room", "name: minimal_room")


# ----------------------------------------------------------------- Han2023 (paper §4)


def test_han2023_sites_are_in_huainan_in_2023() -> None:
    for name in ("han2023_basement", "han2023_corridor"):
        site = load(name).site
        assert site.latitude == pytest.approx(32.63, abs=0.05)
        assert site.longitude == pytest.approx(117.0, abs=0.05)
        # Experiments before submission (1 August 2023).
        assert datetime.date(2023, 1, 1) <= site.date <= datetime.date(2023, 8, 1)


def test_han2023_basement_dimensions_lights_route() -> None:
    s = load("han2023_basement")
    plan = FloorPlan(s)
    assert s.site.north_deg == 0.0  # X east, Y north
    # 12 m along x and 26.4 m along y, SW corner labelled (1, 1).
    assert walkable_run(plan, (-5, 11.0), (20, 11.0), (7.0, 11.0)) == pytest.approx(12.0)
    assert walkable_run(plan, (4.0, -5), (4.0, 40), (4.0, 10.0)) == pytest.approx(26.4)
    assert plan.is_walkable([[1.01, 4.0]]).all() and not plan.is_walkable([[0.99, 4.0]]).any()
    # Four identical lights along y.
    lums = s.luminaires
    assert len(lums) == 4
    assert len({(lum.intensity_cd, lum.exponent) for lum in lums}) == 1
    assert (
        len({lum.position[0] for lum in lums}) == 1 and len({lum.position[1] for lum in lums}) == 4
    )
    assert route_length(s, "A_to_D") == pytest.approx(43.2, abs=1e-9)
    assert len(s.routes["A_to_D"].waypoints) == 4  # A, B, C, D


def test_han2023_corridor_dimensions_lights_route() -> None:
    s = load("han2023_corridor")
    plan = FloorPlan(s)
    assert s.site.north_deg == 180.0  # X west, Y south
    # 2.4 m wide; 54 m along x, 30 m along y (clear floor).
    assert walkable_run(plan, (24.0, 20), (24.0, 40), (24.0, 29.8)) == pytest.approx(2.4)
    assert walkable_run(plan, (40, 9.0), (60, 9.0), (53.8, 9.0)) == pytest.approx(2.4)
    assert walkable_run(plan, (-5, 29.8), (60, 29.8), (30.0, 29.8)) == pytest.approx(54.0)
    assert walkable_run(plan, (53.8, -5), (53.8, 40), (53.8, 15.0)) == pytest.approx(30.0)
    # 14 identical lights along x and 7 along y.
    lums = s.luminaires
    assert len({(lum.intensity_cd, lum.exponent) for lum in lums}) == 1
    along_x = [lum for lum in lums if lum.position[1] == 29.8]
    along_y = [lum for lum in lums if lum.position[0] == 53.8 and lum.position[1] != 29.8]
    assert (len(along_x), len(along_y), len(lums)) == (14, 7, 21)
    assert route_length(s, "trajectory") == pytest.approx(80.6, abs=1e-9)


@pytest.mark.parametrize("name", ["han2023_basement", "han2023_corridor"])
def test_han2023_heading_test_goes_west_north_east(name: str) -> None:
    # Paper §4.3: west to a corner, 90° turn north, 90° turn east.
    assert bearings(load(name), "heading_test") == pytest.approx([270.0, 0.0, 90.0], abs=1e-9)


@pytest.mark.parametrize("name", ["han2023_basement", "han2023_corridor"])
def test_han2023_grid_survey(name: str) -> None:
    # Paper §4.2: 1.2 m × 1.2 m grid, 30 s per point at 50 Hz.
    grid = load(name).surveys["grid"]
    assert (grid.kind, grid.spacing, grid.duration_s, grid.rate_hz) == ("grid", 1.2, 30.0, 50.0)


# ----------------------------------------------------------------- Chen2022


@pytest.mark.parametrize("name", ["chen2022_lab", "chen2022_office"])
def test_chen2022_sites_in_shanghai_before_submission(name: str) -> None:
    site = load(name).site
    assert site.latitude == pytest.approx(31.2, abs=0.3)
    assert site.longitude == pytest.approx(121.5, abs=0.3)
    assert site.date < datetime.date(2022, 2, 11)  # received 11 February 2022


@pytest.mark.parametrize("name", ["chen2022_lab", "chen2022_office"])
def test_chen2022_walk_survey(name: str) -> None:
    s = load(name)
    walk = s.surveys["walk"]
    assert walk.kind == "walk" and walk.route in s.routes
    assert 5.0 <= walk.reference_spacing <= 10.0  # reference points 5–10 m apart
    assert route_length(s, walk.route) >= 4 * walk.reference_spacing


def test_chen2022_lab_has_desks_windows_pillars_walls() -> None:
    s = load("chen2022_lab")
    plan = FloorPlan(s)
    assert any(o.kind == "desk" for o in s.obstacles)
    assert s.windows and s.walls
    walls = unary_union([w.polygon() for w in plan.walls])
    assert any(not column.intersects(walls) for column, _ in plan.pillars), "a free-standing pillar"


def test_chen2022_office_has_classrooms_doors_windows_square_columns() -> None:
    s = load("chen2022_office")
    plan = FloorPlan(s)
    assert any(r.name.startswith("classroom") for r in s.rooms)
    assert s.doors and s.windows
    corridor = next(r for r in s.rooms if r.name == "corridor")
    edges = {min(y for _, y in corridor.polygon), max(y for _, y in corridor.polygon)}
    on_edges = [i for i, p in enumerate(s.pillars) if p.center[1] in edges]
    assert len(on_edges) >= 10
    assert all(s.pillars[i].size[0] == s.pillars[i].size[1] for i in on_edges)
    # They stand out of the corridor's walls, into the corridor.
    walls = unary_union([w.polygon() for w in plan.walls])
    assert all(not walls.contains(plan.pillars[i][0]) for i in on_edges)


def test_bundled_sites_load_as_sites() -> None:
    site = indoorsim.load_site("han2023_corridor")
    assert site.magnetic_field([[30.0, 29.8, 1.2]]).shape == (1, 3)
