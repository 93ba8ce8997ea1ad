"""Indoor Location Competition 2.0 floor plans as scenarios, and its traces as routes.

The competition (Microsoft Research / XYZ10; ``shared/realdata/ms-indoor-location-2020``)
gives each floor as ``geojson_map.json`` — one feature whose ``properties.type`` is
``floor`` (the floor outline, a (Multi)Polygon) and one Polygon per shop or unit,
all in longitude/latitude — and ``floor_info.json`` with the floor image's
``map_info.width`` and ``height`` in metres. The traces' waypoints are in that
image's frame: x right, y up, origin at its lower-left corner.

**Frame.** The floor outline's lon/lat bounding box is stretched onto
[0, width] × [0, height] (the mapping of the competition's public notebooks).
It is checked against the real traces: on the MS mall floor (site1/F1) all 85
waypoints of the 16 traces fall inside the floor outline and none inside a
shop; with y flipped, 40 fall in shops and 8 outside. The stretch is
axis-aligned with latitude growing along +y, so the building's +y axis points
to true north (``site.north_deg`` 0); its two scales agree with WGS84's
metres per degree to within a few tenths of a per cent on that floor (the
description of each imported scenario gives them). The site's latitude and
longitude are the outline's centroid.

**Walls** (types as :func:`~indoorsim.scenario.generate.draft.wall_types` of a
mall, ``open_hall``): the floor outline is a 0.3 m concrete exterior wall; each
shop is a room whose edges are walls — glass shopfronts (0.1 m) towards the
public space, partitions (0.1 m drywall or 0.12 m brick, seeded) between two
shops, the exterior wall where a shop meets the outline. Before that, each
shop is clipped to the floor, simplified (Douglas–Peucker, 0.1 m: tiny edges
go and collinear vertices merge), snapped to the millimetre, and cut out of
the shops listed before it where two overlap (the plan's polygons overlap by up
to 0.75 m²); slivers — shops under 1 m² or thinner than 0.3 m — are dropped.
All edges are then noded together, so a stretch shared by two shops is one
wall, and collinear pieces between the same two spaces merge into one wall.

**Doors** (the rule): the *public space* is the floor minus the shops. A shop
gets one doorway, centred on its longest shopfront wall (an edge with the
public space on its far side) among those at least 1.8 m long whose 1 m deep
strip outside lies at least 90 % in the public space (so gaps of a few
decimetres between neighbouring shops do not count as a frontage). Its width
is drawn at 2.4–4.0 m, as ``open_hall`` draws a shop's opening [E: an open
mall shopfront; no width is sourced], and kept 0.3 m clear of the wall's
ends. A shop without such a frontage is left without a door (the summary counts
them). The outline gets no doors: routes stay inside.

**Escalators** (the rule): a unit labelled a non-open area (``feikaifangquyu``)
whose smallest enclosing rectangle is 7–14 m long and 0.9–2.3 m wide, and which
fills at least 0.8 of it, is an escalator, not a shop: its edges stay walls (the
balustrades), it gets no door, light, AP or column, and its steel truss is four
dipoles of 40–80 A·m² on its long axis, at 0.1, 0.37, 0.63 and 0.9 of its
length, each at the height of a truss rising from 0.3 m over the floor at one
end (drawn) to 0.3 m under the ceiling at the other, as ``open_hall`` places its
escalator. On the MS floor 9 of the 46 non-open areas are escalators; within
1 m of them the real traces' ‖m‖ varies 2.7–3.3 µT (high-passed) against
1.2–1.3 µT far from them.

**What the plan does not show**, placed by ``open_hall``'s rules (see
:mod:`~indoorsim.scenario.generate.open_hall` and REALISM §2.3, §3.2, §3.3,
§4): a ceiling of 4.5–6 m [E]; steel columns (0.7–0.9 m, 0.08–0.13 m³ of
rolled steel, spliced at 0.6 m) on a 7.8–9 m grid, kept only inside shops,
0.3 m clear of their walls — in the public space they would stand in the real
walkers' paths, and the plan shows none [E]; primary beams on the grid lines,
secondaries at most 3 m apart (the ``open_hall`` steel frame); the ceiling the
floor above's composite slab on steel decking, but the floor itself a podium
slab over the mall's basement car park, about 40 kg of bars per m² magnetised
bay by bay, as the generated basement's ceiling [E: a ground floor of a large
mall; the plan does not say what lies below]. On the two real traces of 40 m or
more a decked floor left the twins' ‖m‖ a third as varied as the real one
(1.37 against 4.33 µT, the phone's own offset taken out); on the podium 2.11.
A steel door frame
(5–15 A·m²) beside each shop's doorway; downlights or panels on a 4–5 m grid
over the public space and panels on a 2.4–3.6 m grid in the shops (one light
in a shop too small for the grid); dual-band ceiling APs at most 15 m apart
over the public space and, in 40 % of the shops with a door, one on the shop's
far wall. Furniture, kiosks and windows are not placed.

**Routes** (:func:`add_trace_routes`): a trace's waypoints become a waypoint
route of the same name, each leg paced as the surveyor walked it (its length
over the time between its waypoints; the route's cruising speed is the trace's,
:func:`waypoint_speed`). A
waypoint outside the public space (in a shop, a wall or a column) is moved to
the nearest point 0.1 m inside the public space when one is within 1 m, or
else the trace is left out with the reason. A leg whose straight line passes
through a wall or column (the surveyor walked round a shop's corner between
two waypoints) is walked round it by the shortest path with 0.35 m clearance,
at a speed raised to keep the trace's duration; a way round longer than twice
the straight line plus 5 m leaves the trace out. On the MS floor two of the 16
traces need a way round (0.15 and 0.16 m longer), and none is left out.

All randomness draws from ``numpy.random.default_rng(seed)`` in a fixed
order, and every coordinate is rounded to the millimetre: the same plan and
seed give the same YAML bytes.
"""

from __future__ import annotations

import datetime
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry import LineString, MultiLineString, MultiPolygon, Point, Polygon, shape
from shapely.ops import nearest_points, unary_union

from indoorsim.scenario.generate.cells import WallType, mm, snap
from indoorsim.scenario.generate.draft import Draft, wall_types
from indoorsim.scenario.load import parse_scenario, scenario_to_dict
from indoorsim.scenario.schema import RouteSpec, Scenario
from indoorsim.walker.route import RouteError, plan_route
from indoorsim.world.plan import plan_for

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

_SIMPLIFY_M = 0.1
"""Douglas–Peucker tolerance for the shop polygons, m."""
_GRID_M = 0.001
"""Coordinates snap to the millimetre (as the generator's ``mm``)."""
_SLIVER_WIDTH_M = 0.3
_SLIVER_AREA_M2 = 1.0
_DOOR_WIDTH_M = (2.4, 4.0)
"""A shop's opening, drawn as ``open_hall`` draws it [E]."""
_DOOR_MIN_M = 1.2
_DOOR_JAMB_M = 0.3
_FRONT_DEPTH_M = 1.0
_FRONT_SHARE = 0.9
_LIGHT_INSET_M = 0.4
"""Lights and APs keep this clear of a wall's centre line (half the thickest wall,
its corner extension and a fitting's half size)."""
_NUDGE_M = 1.0
_NUDGE_INSIDE_M = 0.1
_NON_OPEN = "feikaifangquyu"
"""The competition plans' label of a non-open area (非开放区域): escalators, service
cores and voids."""
_ESCALATOR_LENGTH_M = (7.0, 14.0)
_ESCALATOR_WIDTH_M = (0.9, 2.3)
"""A non-open area whose smallest enclosing rectangle is this long and this narrow is an
escalator: 1–1.6 m across its balustrades, 8–14 m of truss for a 4–6 m storey
rising at 30° with its landings [E]."""
_ESCALATOR_FILL = 0.8
"""...and fills at least this share of that rectangle."""

# Owners of the two sides of a boundary stretch.
_OUTSIDE, _PUBLIC = -2, -1


class PlanImportError(ValueError):
    """A floor plan that cannot be imported: the file and what is wrong, in one line."""

    def __init__(self, source: str, problem: str):
        self.source = source
        self.problem = problem
        super().__init__(f"{source}: {problem}" if source else problem)


# --------------------------------------------------------------------------- reading


@dataclass(frozen=True, kw_only=True)
class IlcFloor:
    """One competition floor as read: outline and shops in lon/lat, the map's size in m."""

    outline: Polygon | MultiPolygon
    """The ``floor`` feature (longitude, latitude)."""
    shops: tuple[tuple[str, Polygon], ...]
    """(name, polygon) of every Polygon feature besides the floor, in file order."""
    width_m: float
    height_m: float
    floor_name: str = ""
    date: datetime.date | None = None
    """The newest ``properties.version`` date of the features, when they carry one."""
    source: str = ""


def _read_json(path: Path) -> Any:
    if not path.exists():
        raise PlanImportError(str(path), "no such file")
    if path.is_dir():
        raise PlanImportError(str(path), "is a directory, not a JSON file")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise PlanImportError(str(path), "not a text file (not UTF-8): expected JSON") from None
    except json.JSONDecodeError as err:
        raise PlanImportError(
            str(path), f"not JSON (line {err.lineno}, column {err.colno}: {err.msg})"
        ) from None


def read_ilc_floor(geojson: str | Path, floor_info: str | Path) -> IlcFloor:
    """Read a competition floor: ``geojson_map.json`` and ``floor_info.json``.

    Raises:
        PlanImportError: a missing or unreadable file, or one that is not the
            competition's format (the message names the file and the problem).
    """
    geo_path, info_path = Path(geojson), Path(floor_info)
    return parse_ilc_floor(
        _read_json(geo_path),
        _read_json(info_path),
        geojson_source=str(geo_path),
        floor_info_source=str(info_path),
    )


def parse_ilc_floor(
    geojson: Any,
    floor_info: Any,
    *,
    geojson_source: str = "geojson",
    floor_info_source: str = "floor_info",
) -> IlcFloor:
    """An :class:`IlcFloor` from the parsed GeoJSON and ``floor_info.json``.

    Raises:
        PlanImportError: not a GeoJSON FeatureCollection, no ``floor`` feature,
            a geometry that is not a valid polygon, or no positive map size.
    """
    if not isinstance(geojson, dict) or geojson.get("type") != "FeatureCollection":
        raise PlanImportError(
            geojson_source, "not GeoJSON: expected a FeatureCollection (a 'type' and 'features')"
        )
    features = geojson.get("features")
    if not isinstance(features, list):
        raise PlanImportError(geojson_source, "not GeoJSON: 'features' is not a list")
    outline = None
    floor_name = ""
    shops: list[tuple[str, Polygon]] = []
    dates: list[datetime.date] = []
    for i, feature in enumerate(features):
        if not isinstance(feature, dict) or not isinstance(feature.get("geometry"), dict):
            raise PlanImportError(geojson_source, f"features[{i}] is not a GeoJSON Feature")
        props = feature.get("properties") or {}
        try:
            geom = shape(feature["geometry"])
        except Exception as err:  # shapely raises several types for bad geometry
            raise PlanImportError(
                geojson_source, f"features[{i}]: not a GeoJSON geometry ({err})"
            ) from None
        version = str(props.get("version", ""))[:10]
        try:
            dates.append(datetime.date.fromisoformat(version))
        except ValueError:
            pass
        if props.get("type") == "floor":
            if outline is not None:
                raise PlanImportError(geojson_source, "more than one feature of type 'floor'")
            if not isinstance(geom, Polygon | MultiPolygon) or geom.is_empty:
                raise PlanImportError(
                    geojson_source,
                    f"features[{i}]: the floor is a {geom.geom_type}, not a (Multi)Polygon",
                )
            outline = geom
            floor_name = str(props.get("name", ""))
        elif isinstance(geom, Polygon) and not geom.is_empty:
            shops.append((str(props.get("name") or props.get("display") or f"unit {i}"), geom))
    if outline is None:
        raise PlanImportError(
            geojson_source, "no floor feature (one whose properties.type is 'floor': the outline)"
        )
    info = floor_info.get("map_info") if isinstance(floor_info, dict) else None
    try:
        width, height = float(info["width"]), float(info["height"])  # type: ignore[index]
    except (TypeError, KeyError, ValueError):
        raise PlanImportError(
            floor_info_source, "no map_info with a width and height (m): not a floor_info.json"
        ) from None
    if not (0 < width < 1e4 and 0 < height < 1e4):
        raise PlanImportError(
            floor_info_source, f"map size {width:g} m × {height:g} m is not a floor's"
        )
    return IlcFloor(
        outline=outline,
        shops=tuple(shops),
        width_m=width,
        height_m=height,
        floor_name=floor_name,
        date=max(dates) if dates else None,
        source=geojson_source,
    )


# --------------------------------------------------------------------------- importing


@dataclass(frozen=True, kw_only=True)
class ImportedPlan:
    """An imported floor: the scenario and what was built, for a report."""

    scenario: Scenario
    shops: int
    """Units kept as rooms (shops and escalators)."""
    slivers: tuple[str, ...]
    """Names of the shops dropped as slivers."""
    doorless: tuple[str, ...]
    """Names of the shops without a frontage for a door."""
    escalators: int = 0
    """Units taken for escalators (no door, a steel truss)."""
    public: Polygon | MultiPolygon = field(repr=False)
    """The public space (floor minus shops) in the scenario frame."""

    def counts(self) -> dict[str, int]:
        """Walls, rooms, doors, lights, APs (radios), pillars, dipoles and rebar groups."""
        s = self.scenario
        return {
            "walls": len(s.walls),
            "rooms": len(s.rooms),
            "doors": len(s.doors),
            "lights": len(s.luminaires),
            "aps": len(s.wifi) // 2,
            "radios": len(s.wifi),
            "pillars": len(s.pillars),
            "dipoles": len(s.magnetic.dipoles),
            "rebar": len(s.magnetic.rebar),
        }


class _PlanDraft(Draft):
    """A :class:`Draft` whose footprint is a real floor, not a tiling of cells."""

    def __init__(self, rng: np.random.Generator, *, floor: Polygon | MultiPolygon, **kw: Any):
        super().__init__(rng, **kw)
        self._floor = floor

    def footprint(self) -> Polygon:
        return self._floor  # type: ignore[return-value]


def _frame(floor: IlcFloor) -> tuple[float, float, float, float]:
    lon0, lat0, lon1, lat1 = floor.outline.bounds
    if not (lon1 > lon0 and lat1 > lat0):
        raise PlanImportError(floor.source, "the floor outline has no extent")
    return lon0, lat0, lon1, lat1


def _to_metres(geoms: Any, floor: IlcFloor) -> Any:
    lon0, lat0, lon1, lat1 = _frame(floor)
    sx, sy = floor.width_m / (lon1 - lon0), floor.height_m / (lat1 - lat0)
    return shapely.transform(
        geoms, lambda c: np.column_stack([(c[:, 0] - lon0) * sx, (c[:, 1] - lat0) * sy])
    )


def _polygons(geom: Any) -> list[Polygon]:
    return [g for g in shapely.get_parts(geom) if isinstance(g, Polygon) and not g.is_empty]


def _largest(geom: Any) -> Polygon:
    parts = _polygons(geom)
    return max(parts, key=lambda g: g.area) if parts else Polygon()


def _outline(parts: list[Polygon], source: str) -> Polygon:
    """One polygon round the floor's parts: a floor of several buildings (the MS floor:
    two, 14.7 m apart across a street) is closed over the gaps between them; the
    walls still follow each part, so the gap is outdoor floor between exterior walls."""
    union = unary_union(parts)
    if isinstance(union, Polygon):
        return Polygon(union.exterior)
    gap = max(min(p.distance(q) for q in parts if q is not p) for p in parts)
    radius = gap / 2 + 0.5
    closed = union.buffer(radius, join_style="mitre").buffer(-radius, join_style="mitre")
    bridges = [
        piece
        for piece in _polygons(closed.difference(union))
        if sum(piece.distance(p) < 1e-3 for p in parts) >= 2
    ]
    joined = unary_union([union, *bridges])
    if not isinstance(joined, Polygon):
        raise PlanImportError(source, "the floor's parts cannot be joined into one outline")
    return Polygon(joined.exterior)


def _owners(
    points: NDArray[np.float64], shops: shapely.STRtree, floor: Polygon | MultiPolygon
) -> NDArray[np.intp]:
    """Which space holds each point: a shop's index, _PUBLIC or _OUTSIDE."""
    own = np.where(shapely.contains_xy(floor, points[:, 0], points[:, 1]), _PUBLIC, _OUTSIDE)
    pi, si = shops.query(shapely.points(points), predicate="within")
    own[pi] = si
    return own.astype(np.intp)


def _segments(lines: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(N, 2) start and end points of every straight piece of ``lines``."""
    xy, idx = shapely.get_coordinates(shapely.get_parts(lines), return_index=True)
    same = idx[1:] == idx[:-1]
    return xy[:-1][same], xy[1:][same]


def _side_probes(
    a: NDArray[np.float64], b: NDArray[np.float64], offset: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Points ``offset`` to the left and right of each segment's midpoint, and the
    left unit normals."""
    d = b - a
    n = np.column_stack([-d[:, 1], d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
    mid = (a + b) / 2
    return mid + offset * n, mid - offset * n, n


def import_ilc_floor(floor: IlcFloor, *, seed: int = 0, name: str | None = None) -> ImportedPlan:
    """The scenario of a competition floor (see the module docstring for every rule).

    Args:
        floor: the floor as read by :func:`read_ilc_floor`.
        seed: seeds everything the plan does not show (the same seed, the same scenario).
        name: the scenario's name; default ``ilc-<floor name>-<seed>``.

    Raises:
        PlanImportError: a floor whose outline or shops give no building.
    """
    if seed < 0:
        raise ValueError(f"seed must be non-negative, got {seed}")
    rng = np.random.default_rng(seed)
    src = floor.source

    # -- geometry in metres
    parts = _polygons(shapely.make_valid(_to_metres(floor.outline, floor)))
    parts = [Polygon(p.exterior) for p in _polygons(shapely.set_precision(parts, _GRID_M))]
    if not parts:
        raise PlanImportError(src, "the floor outline encloses no area")
    floor_m = unary_union(parts)
    names = [n for n, _ in floor.shops]
    raw = _to_metres(np.array([g for _, g in floor.shops], dtype=object), floor)
    raw = shapely.intersection(shapely.make_valid(raw), floor_m)
    raw = shapely.set_precision(shapely.simplify(raw, _SIMPLIFY_M), _GRID_M)
    tree = shapely.STRtree(raw)
    shops: list[Polygon] = []
    kept_names: list[str] = []
    slivers: list[str] = []
    for i, geom in enumerate(raw):
        poly = _largest(geom)
        earlier = [shops[j] for j in tree.query(poly) if j < i and not shops[j].is_empty]
        if earlier and not poly.is_empty:
            poly = _largest(shapely.set_precision(poly.difference(unary_union(earlier)), _GRID_M))
        if (
            poly.is_empty
            or poly.area < _SLIVER_AREA_M2
            or poly.buffer(-_SLIVER_WIDTH_M / 2).is_empty
        ):
            slivers.append(names[i])
            shops.append(Polygon())
            continue
        shops.append(shapely.normalize(Polygon(poly.exterior)))
        kept_names.append(names[i])
    rooms = [s for s in shops if not s.is_empty]
    if not rooms:
        raise PlanImportError(src, "no shop polygon inside the floor outline")
    shop_tree = shapely.STRtree(rooms)
    public = floor_m.difference(unary_union(rooms))
    shapely.prepare(public)
    outline = _outline(parts, src)

    # -- site, building, draft
    lon0, lat0, lon1, lat1 = _frame(floor)
    centre = floor.outline.centroid
    lat, lon = float(centre.y), float(centre.x)
    # WGS84 metres per degree at the site, against the stretch's scales.
    phi = math.radians(lat)
    m_per_deg_lat = 111132.92 - 559.82 * math.cos(2 * phi) + 1.175 * math.cos(4 * phi)
    m_per_deg_lon = 111412.84 * math.cos(phi) - 93.5 * math.cos(3 * phi)
    scale_x = floor.width_m / ((lon1 - lon0) * m_per_deg_lon)
    scale_y = floor.height_m / ((lat1 - lat0) * m_per_deg_lat)
    types = wall_types(rng, exterior=WallType(thickness=0.3, material="concrete"))
    h = snap(rng.uniform(4.5, 6.0), 0.1)
    d = _PlanDraft(rng, floor=floor_m, ceiling_height=h, wall_types=types)
    d.set_site(
        latitude=round(lat, 5),
        longitude=round(lon, 5),
        date=(floor.date or datetime.date(2020, 1, 1)).isoformat(),
        north_deg=0.0,
    )

    # -- walls: every edge noded once, each side's owner probed
    linework = unary_union(shapely.boundary(np.array([*rooms, *parts], dtype=object)))
    a, b = _segments(linework)
    keep = np.linalg.norm(b - a, axis=1) > 1e-9
    a, b = a[keep], b[keep]
    left, right, _ = _side_probes(a, b, 0.01)
    own_l, own_r = _owners(left, shop_tree, floor_m), _owners(right, shop_tree, floor_m)
    lo, hi = np.minimum(own_l, own_r), np.maximum(own_l, own_r)
    groups: dict[tuple[int, int], list[int]] = {}
    for k in np.flatnonzero(lo != hi).tolist():
        groups.setdefault((int(lo[k]), int(hi[k])), []).append(k)
    # Per group: collinear pieces merged, then one wall per straight stretch.
    wall_a, wall_b, wall_key = [], [], []
    for key in sorted(groups):
        idx = groups[key]
        merged = shapely.line_merge(MultiLineString([[a[k], b[k]] for k in idx]))
        merged = shapely.simplify(merged, 0.005)
        sa, sb = _segments(merged)
        wall_a.append(sa)
        wall_b.append(sb)
        wall_key += [key] * len(sa)
    wa, wb = np.concatenate(wall_a), np.concatenate(wall_b)
    for (k0, _), p, q in zip(wall_key, wa.tolist(), wb.tolist(), strict=True):
        if math.dist(p, q) < 0.01:
            continue
        cls = "exterior" if k0 == _OUTSIDE else "shopfront" if k0 == _PUBLIC else "partition"
        wt = types[cls]
        d.walls.append(
            {
                "from": [mm(p[0]), mm(p[1])],
                "to": [mm(q[0]), mm(q[1])],
                "thickness": wt.thickness,
                "material": wt.material,
            }
        )

    # -- columns inside the shops, on a structural grid
    bay = rng.uniform(7.8, 9.0)
    pillar = float(rng.choice([0.7, 0.8, 0.9]))
    xmin, ymin, xmax, ymax = floor_m.bounds
    gx = np.arange(xmin + bay / 2, xmax, bay)
    gy = np.arange(ymin + bay / 2, ymax, bay)
    # Escalators are voids through the storey, not shops: no column stands in one.
    escalator = [_is_escalator(name, poly) for name, poly in zip(kept_names, rooms, strict=True)]
    inner_shops = unary_union(
        [
            s.buffer(-(pillar / 2 + 0.3), join_style="mitre")
            for s, esc in zip(rooms, escalator, strict=True)
            if not esc
        ]
    )
    shapely.prepare(inner_shops)
    grid = np.array([(x, y) for y in gy for x in gx])
    at = grid[shapely.contains_xy(inner_shops, grid[:, 0], grid[:, 1])]
    d.add_pillars(
        at.tolist(),
        size=pillar,
        steel_m3=rng.uniform(0.08, 0.13),
        keep=lambda x, y: True,
        splice_z=0.6,
    )
    d.add_beams(
        [(False, float(x), ymin, ymax) for x in np.arange(xmin, xmax + 1e-9, bay)]
        + [(True, float(y), xmin, xmax) for y in np.arange(ymin, ymax + 1e-9, bay)]
    )
    d.add_secondary_beams(3.0, horizontal=False)

    # -- doors: the longest shopfront with public space outside
    front = [i for i, key in enumerate(wall_key) if key[0] == _PUBLIC]
    fa, fb = wa[front], wb[front]
    length = np.linalg.norm(fb - fa, axis=1)
    probe_l, _, normal = _side_probes(fa, fb, 0.05)
    shop_of = np.array([wall_key[i][1] for i in front], dtype=np.intp)
    left_is_shop = _owners(probe_l, shop_tree, floor_m) == shop_of
    out_n = np.where(left_is_shop[:, None], -normal, normal)
    strips = shapely.polygons(
        np.stack([fa, fb, fb + _FRONT_DEPTH_M * out_n, fa + _FRONT_DEPTH_M * out_n], axis=1)
    )
    share = shapely.area(shapely.intersection(strips, public)) / np.maximum(
        shapely.area(strips), 1e-12
    )
    ok = (length >= _DOOR_MIN_M + 2 * _DOOR_JAMB_M) & (share >= _FRONT_SHARE)
    doors_at: list[tuple[float, float, float, NDArray[np.float64]] | None] = []
    doorless = []
    for s, shop_name in enumerate(kept_names):
        drawn = rng.uniform(*_DOOR_WIDTH_M)
        if escalator[s]:
            doors_at.append(None)
            continue
        cand = np.flatnonzero(ok & (shop_of == s))
        if len(cand) == 0:
            doorless.append(shop_name)
            doors_at.append(None)
            continue
        k = cand[np.argmax(length[cand])]
        width = mm(min(drawn, length[k] - 2 * _DOOR_JAMB_M))
        mid = (fa[k] + fb[k]) / 2
        d.doors.append({"position": [mm(mid[0]), mm(mid[1])], "width": width})
        # The steel frame beside the opening, on the hinge side (as Draft.add_doors).
        u = (fb[k] - fa[k]) / length[k]
        side = (width / 2 + 0.1) * (1.0 if rng.random() < 0.5 else -1.0)
        fx, fy = mid - 0.1 * out_n[k] + side * u
        d.steel(float(fx), float(fy), 1.0, (5.0, 15.0))
        doors_at.append((float(mid[0]), float(mid[1]), width, -out_n[k]))

    # -- escalators: a steel truss rising along each
    for poly in (r for r, esc in zip(rooms, escalator, strict=True) if esc):
        _escalator_truss(d, poly, rng)

    # -- lights: the open_hall's fixtures and spacings
    hall_light = d.fixture("downlight" if rng.random() < 0.5 else "panel")
    shop_light = d.fixture("panel")
    public_in = public.buffer(-_LIGHT_INSET_M, join_style="mitre")
    shops_in = [
        Polygon() if esc else s.buffer(-_LIGHT_INSET_M, join_style="mitre")
        for s, esc in zip(rooms, escalator, strict=True)
    ]
    for area, spacing, fixture in (
        (public_in, rng.uniform(4.0, 5.0), hall_light),
        (unary_union(shops_in), rng.uniform(2.4, 3.6), shop_light),
    ):
        ox, oy = rng.uniform(0.0, spacing, size=2)
        xs = np.arange(xmin + ox, xmax, spacing)
        ys = np.arange(ymin + oy, ymax, spacing)
        pts = np.array([(x, y) for y in ys for x in xs])
        for x, y in pts[shapely.contains_xy(area, pts[:, 0], pts[:, 1])].tolist():
            d.light(x, y, fixture)
    lit = shapely.points(np.array([lum["position"][:2] for lum in d.luminaires]))
    hit = set(shapely.STRtree(lit).query(np.array(rooms, dtype=object), predicate="contains")[0])
    for i, inner in enumerate(shops_in):
        if i not in hit and not inner.is_empty:
            p = inner.point_on_surface()
            d.light(p.x, p.y, shop_light)

    # -- APs: ceiling grid over the public space, some on shops' far walls
    ap_in = public.buffer(-1.0, join_style="mitre")
    cx, cy = (
        v.ravel() for v in np.meshgrid(np.arange(xmin, xmax, 15.0), np.arange(ymin, ymax, 15.0))
    )
    cells = shapely.box(cx, cy, cx + 15.0, cy + 15.0)
    pieces = shapely.intersection(cells, ap_in)
    big = shapely.area(pieces) >= 20.0
    for p in shapely.point_on_surface(pieces[big]):
        d.access_point(p.x, p.y, h - 0.05, "mall")
    for i, door in enumerate(doors_at):
        if door is None or rng.random() >= 0.4:
            continue
        inner = shops_in[i]
        if inner.is_empty:
            continue
        ring = np.asarray(inner.exterior.coords)[:-1]
        far = ring[np.argmax(np.hypot(ring[:, 0] - door[0], ring[:, 1] - door[1]))]
        d.access_point(float(far[0]), float(far[1]), h - 0.5, "shop")

    # -- steel frame and assembly: a podium floor over the car park, a decked ceiling
    magnetic = d.magnetic(
        beam_m3_per_m=0.0145,
        bay_m=bay,
        slab_m3_per_m2=0.005,
        slab_element_m=bay,
        secondary_m3_per_m=0.008,
        ceiling_m3_per_m2=0.0017,
        ceiling_element_m=3.0,
    )
    slabs = [r for r in magnetic["rebar"] if "region" not in r]
    magnetic["rebar"] = [
        {**slab, "region": [[mm(x), mm(y)] for x, y in list(part.exterior.coords)[:-1]]}
        for slab in slabs
        for part in parts
    ] + [r for r in magnetic["rebar"] if "region" in r]
    seen: dict[str, int] = {}
    room_specs = []
    for shop_name, poly in zip(kept_names, rooms, strict=True):
        seen[shop_name] = seen.get(shop_name, 0) + 1
        label = shop_name if seen[shop_name] == 1 else f"{shop_name} ({seen[shop_name]})"
        room_specs.append(
            {"name": label, "polygon": [[mm(x), mm(y)] for x, y in list(poly.exterior.coords)[:-1]]}
        )
    floor_label = floor.floor_name or "floor"
    data = {
        "name": name or f"ilc-{floor_label}-{seed}".lower(),
        "description": (
            f"Imported from the Indoor Location Competition 2.0 floor plan {Path(src).name} "
            f"(floor {floor_label}, {floor.width_m:.1f} m × {floor.height_m:.1f} m): walls, "
            f"shops and doors from the plan; the outline's lon/lat box stretched onto the "
            f"map (x scale {scale_x:.4f}, y scale {scale_y:.4f} of WGS84's metres per "
            f"degree); lights, APs and the steel frame placed by open_hall's rules, seed "
            f"{seed}. Traces were recorded on an OPPO PBCM10 (BMI160, AK09911, Android 8.1) "
            f"held flat; the nearest built-in device profile is nexus_5x (BMI160, Android 8) [E]."
        ),
        "seed": seed,
        "site": d.site,
        "outline": [[mm(x), mm(y)] for x, y in list(outline.exterior.coords)[:-1]],
        "walls": d.walls,
        "doors": d.doors,
        "rooms": room_specs,
        "pillars": d.pillar_specs,
        "luminaires": d.luminaires,
        "magnetic": magnetic,
        "wifi": d.wifi,
        "radio": {"path_loss_exponent": 2.2, "shadowing_sigma_db": 5.0},
    }
    scenario = parse_scenario(data, source=f"import_ilc_floor({src!r}, seed={seed})")
    return ImportedPlan(
        scenario=scenario,
        shops=len(rooms),
        slivers=tuple(slivers),
        doorless=tuple(doorless),
        escalators=sum(escalator),
        public=public,
    )


def _is_escalator(name: str, poly: Polygon) -> bool:
    """Whether a plan unit is an escalator (the module docstring's rule)."""
    if name != _NON_OPEN or poly.area <= 0:
        return False
    length, width = _rectangle_sides(poly)
    return (
        _ESCALATOR_LENGTH_M[0] <= length <= _ESCALATOR_LENGTH_M[1]
        and _ESCALATOR_WIDTH_M[0] <= width <= _ESCALATOR_WIDTH_M[1]
        # A strip, not an L or a ring that happens to fit the box (the MS floor's
        # escalators fill 0.96–1 of theirs).
        and poly.area >= _ESCALATOR_FILL * length * width
    )


def _rectangle_sides(poly: Polygon) -> tuple[float, float]:
    """The long and short sides of ``poly``'s smallest enclosing rectangle, m."""
    corners = np.asarray(poly.minimum_rotated_rectangle.exterior.coords)
    sides = np.linalg.norm(np.diff(corners[:3], axis=0), axis=1)
    return float(sides.max()), float(sides.min())


def _escalator_truss(d: Draft, poly: Polygon, rng: np.random.Generator) -> None:
    """The escalator's truss (:meth:`Draft.escalator_truss`) on its long axis, rising
    from one end (drawn) to the other."""
    corners = np.asarray(poly.minimum_rotated_rectangle.exterior.coords)[:4]
    edges = np.diff(np.vstack([corners, corners[:1]]), axis=0)
    long_edge = edges[int(np.argmax(np.linalg.norm(edges, axis=1)))]
    # The two long sides point opposite ways and tie to rounding: fix the sign first,
    # so the drawn end, not the geometry library's rounding, decides where it rises.
    if long_edge[0] < -1e-9 or (abs(long_edge[0]) <= 1e-9 and long_edge[1] < 0):
        long_edge = -long_edge
    x, y = corners.mean(axis=0)
    dx, dy = long_edge if rng.random() < 0.5 else -long_edge
    d.escalator_truss(float(x), float(y), float(dx), float(dy))


# --------------------------------------------------------------------------- routes


def waypoint_speed(waypoints: Sequence[Sequence[float]], times_s: Sequence[float]) -> float:
    """Walking speed of a trace: its waypoint path length over the time from the
    first waypoint to the last, m/s (NaN when that time is not positive).

    >>> waypoint_speed([(0, 0), (3, 0), (3, 4)], [0.0, 2.0, 7.0])
    1.0
    """
    xy = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    t = np.asarray(times_s, dtype=float)
    if len(xy) < 2 or len(t) != len(xy) or not t[-1] > t[0]:
        return math.nan
    return float(np.linalg.norm(np.diff(xy, axis=0), axis=1).sum() / (t[-1] - t[0]))


@dataclass(frozen=True, kw_only=True)
class RouteImport:
    """Routes added from traces: the scenario with them, and what happened to each trace."""

    scenario: Scenario
    kept: dict[str, list[str]]
    """Trace name → notes (waypoints moved, and by how much); empty when unchanged."""
    left_out: dict[str, str]
    """Trace name → why it is not a route."""
    marks: dict[str, list[list[float]]] = field(default_factory=dict)
    """Trace name → its own waypoints as the route walks through them (moved into the
    public space, repeats dropped): the route's waypoints less the points of its ways
    round walls, so a simulated walk can be marked where the real one was."""


def _through(leg: LineString, room_polys: list[tuple[str, Polygon]]) -> str:
    """What a blocked leg's straight line meets: the shops it cuts, or the one it grazes."""
    cut = [(n, leg.intersection(poly).length) for n, poly in room_polys if leg.intersects(poly)]
    if cut:
        return "cuts through " + ", ".join(f"shop {n!r} for {length:.2f} m" for n, length in cut)
    if not room_polys:
        return "meets a wall or column"
    n, poly = min(room_polys, key=lambda rp: leg.distance(rp[1]))
    return f"comes within {leg.distance(poly):.2f} m of shop {n!r}: into its wall"


def add_trace_routes(
    imported: ImportedPlan,
    traces: Mapping[str, tuple[Sequence[Sequence[float]], float | Sequence[float]]],
    *,
    nudge_m: float = _NUDGE_M,
    detour: bool = True,
) -> RouteImport:
    """Add one waypoint route per trace: ``name → (waypoints, speed m/s)``, or
    ``name → (waypoints, times s)`` with each waypoint's time, which paces every leg
    as the surveyor walked it (its ``leg_speeds``: the leg's length over the time
    between its waypoints) at the trace's speed overall (:func:`waypoint_speed`).

    A waypoint outside the public space (in a shop, a wall or a column) moves to
    the nearest point 0.1 m inside the public space when that is within
    ``nudge_m``; otherwise the trace is left out. A leg whose straight line
    passes through a wall or column (the surveyor walked round a shop's corner
    between two waypoints) is, with ``detour``, walked round it by the shortest
    path keeping 0.35 m from everything solid (:func:`~indoorsim.walker.route.plan_route`),
    and the speed is raised so that the walk keeps the trace's duration — and,
    paced, the leg its time (the real path was the longer one); a way round
    longer than twice the straight line plus 5 m leaves the trace out, as does
    any blocked leg without ``detour``, a speed outside the schema's (0.1, 3] m/s
    (the trace's, or a paced leg's as walked), or two waypoints marked at once
    or out of order. Repeated waypoints (under 1 cm apart) are walked once; the
    time a surveyor spent at one counts to the leg after it.
    """
    base = imported.scenario
    plan = plan_for(base)
    free = imported.public.difference(plan.solid)
    inside = free.buffer(-_NUDGE_INSIDE_M)
    shapely.prepare(free)
    room_polys = [(r.name, Polygon(r.polygon)) for r in base.rooms]
    routes: dict[str, dict[str, Any]] = {}
    kept: dict[str, list[str]] = {}
    left_out: dict[str, str] = {}
    marks: dict[str, list[list[float]]] = {}
    for trace, (waypoints, pace) in traces.items():
        xy = np.asarray(waypoints, dtype=float).reshape(-1, 2)
        times = None if np.ndim(pace) == 0 else np.asarray(pace, dtype=float)
        if times is not None and times.shape != (len(xy),):
            left_out[trace] = f"{times.size} waypoint times for {len(xy)} waypoints"
            continue
        number = np.arange(len(xy))  # each waypoint's place in the trace, for messages
        if len(xy):
            step = np.r_[True, np.linalg.norm(np.diff(xy, axis=0), axis=1) >= 0.01]
            # A repeat keeps its first time: the leg after it takes the stay too.
            xy, number = xy[step], number[step]
            if times is not None:
                times = times[step]
        if len(xy) < 2:
            left_out[trace] = "fewer than two distinct waypoints"
            continue
        took = None if times is None else np.diff(times)
        if took is not None and not np.all(took > 0):
            j = int(np.flatnonzero(~(took > 0))[0])
            left_out[trace] = (
                f"waypoints {number[j]} and {number[j + 1]} are marked {took[j]:.3f} s apart"
            )
            continue
        speed = float(pace) if times is None else waypoint_speed(xy, times)
        if not (math.isfinite(speed) and 0.1 < speed <= 3.0):
            left_out[trace] = f"walking speed {speed:.2f} m/s is outside (0.1, 3] m/s"
            continue
        notes: list[str] = []
        reason = ""
        ok = shapely.contains_xy(free, xy[:, 0], xy[:, 1])
        for j in np.flatnonzero(~ok).tolist():
            p = Point(xy[j])
            where = next((n for n, poly in room_polys if poly.contains(p)), None)
            what = f"in shop {where!r}" if where else "in a wall or column, or outside the floor"
            target = nearest_points(inside, p)[0]
            dist = p.distance(target)
            if dist > nudge_m:
                reason = (
                    f"waypoint {j} ({xy[j, 0]:.2f}, {xy[j, 1]:.2f}) lies {what}, "
                    f"{dist:.2f} m from the public space (more than {nudge_m:g} m)"
                )
                break
            notes.append(f"waypoint {j} moved {dist:.2f} m out of {what[3:]}")
            xy[j] = (target.x, target.y)
        if reason:
            left_out[trace] = reason
            continue
        xy = np.round(xy, 3)
        straight = float(np.linalg.norm(np.diff(xy, axis=0), axis=1).sum())
        # Blocked: through a wall's centre line, or out of the walkable area (a
        # wall's thickness, a column), as the walker's planner tests a leg.
        legs = shapely.linestrings(np.stack([xy[:-1], xy[1:]], axis=1))
        blocked = plan.crosses_wall(xy[:-1], xy[1:]) | ~shapely.covers(plan.walkable, legs)
        path = [xy[:1]]
        # Paced, each leg as walked (straight, or its way round a wall) in its time.
        paced: list[NDArray[np.float64]] = []
        for j in range(len(xy) - 1):
            if not blocked[j]:
                path.append(xy[j + 1 : j + 2])
                if took is not None:
                    paced.append(np.array([shapely.length(legs[j]) / took[j]]))
                continue
            leg = LineString(xy[j : j + 2])
            where = (
                f"leg {j} ({xy[j, 0]:.2f}, {xy[j, 1]:.2f}) → ({xy[j + 1, 0]:.2f}, "
                f"{xy[j + 1, 1]:.2f}) passes through a wall or column (the straight line "
                f"{_through(leg, room_polys)})"
            )
            if not detour:
                reason = where
                break
            try:
                way = plan_route(
                    plan, RouteSpec(start=tuple(xy[j]), goal=tuple(xy[j + 1])), clearance=0.35
                )
            except RouteError as err:
                reason = f"{where}, and there is no way round it ({err})"
                break
            if way.length > 2 * leg.length + 5.0:
                reason = (
                    f"{where}, and the way round is {way.length:.1f} m against "
                    f"{leg.length:.1f} m straight"
                )
                break
            notes.append(f"{where}: walked round it, {way.length - leg.length:.2f} m longer")
            path.append(np.round(way.points[1:], 3))
            if took is not None:
                paced.append(np.full(len(way.points) - 1, way.length / took[j]))
        if reason:
            left_out[trace] = reason
            continue
        pts = np.concatenate(path)
        length = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
        if length > straight + 1e-6:
            # The trace's duration kept: its speed over the longer path.
            walked = speed * length / straight
            notes.append(f"speed {speed:.3f} → {walked:.3f} m/s to keep the trace's duration")
            speed = walked
            if speed > 3.0:
                left_out[trace] = f"walking speed {speed:.2f} m/s round the walls is above 3 m/s"
                continue
        route: dict[str, Any] = {"waypoints": pts.tolist(), "speed": mm(speed)}
        if took is not None:
            # Rounded as written, then checked against the schema's range.
            walked_legs = [mm(float(v)) for v in np.concatenate(paced)]
            counts = [len(p) for p in paced]
            bad = [k for k, v in enumerate(walked_legs) if not 0.1 < v <= 3.0]
            if bad:
                j = int(np.searchsorted(np.cumsum(counts), bad[0], side="right"))
                left_out[trace] = (
                    f"the leg from waypoint {number[j]} to {number[j + 1]} is walked at "
                    f"{walked_legs[bad[0]]:.3f} m/s, outside (0.1, 3] m/s"
                )
                continue
            route["leg_speeds"] = walked_legs
        routes[trace] = route
        kept[trace] = notes
        marks[trace] = xy.tolist()
    data = scenario_to_dict(base)
    data["routes"] = {**data["routes"], **routes}
    scenario = parse_scenario(data, source=f"{base.name} with trace routes")
    return RouteImport(scenario=scenario, kept=kept, left_out=left_out, marks=marks)
