"""Importing Indoor Location Competition floor plans: the door rule in closed form,
the MS mall floor's frame against its real waypoints, round trips, seeds, routes."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Polygon

from indoorsim.scenario.imports import (
    PlanImportError,
    add_trace_routes,
    import_ilc_floor,
    parse_ilc_floor,
    read_ilc_floor,
    waypoint_speed,
)
from indoorsim.scenario.load import dump_scenario, load_scenario, load_site
from indoorsim.walker.gait import WalkerParams
from tests.scenario.imports.conftest import (
    MS_FLOOR,
    TWO_SHOPS,
    needs_ms_floor,
    plan_geojson,
)

INFO = {"map_info": {"width": 20.0, "height": 10.0}}


@pytest.fixture(scope="module")
def two_shops():
    return import_ilc_floor(parse_ilc_floor(plan_geojson(TWO_SHOPS), INFO), seed=3)


# ------------------------------------------------------------------ the door rule, closed form


def test_each_shop_gets_one_door_centred_on_its_corridor_side(two_shops):
    s = two_shops.scenario
    assert [r.name for r in s.rooms] == ["A", "B"]
    assert two_shops.doorless == ()
    doors = sorted(s.doors, key=lambda d: d.position)
    # A's longest edges tie at 8 m (y = 4 on the corridor, y = 10 on the outline):
    # the door goes to the one facing the corridor, at its midpoint; B's at (14, 4).
    assert [d.position for d in doors] == [(4.0, 4.0), (14.0, 4.0)]
    for d in doors:
        assert 2.4 <= d.width <= 4.0


def test_a_long_narrow_non_open_area_is_an_escalator_with_a_rising_steel_truss():
    """No door, no light, four dipoles on its long axis at the heights of a truss rising
    from 0.3 m over the floor to 0.3 m under the ceiling; a square non-open area of
    the same label stays a unit with a door."""
    plan = {
        "A": [(0, 4), (8, 4), (8, 10), (0, 10)],
        "feikaifangquyu": [(10, 6), (19, 6), (19, 7.5), (10, 7.5)],  # 9 m × 1.5 m
    }
    bare = import_ilc_floor(parse_ilc_floor(plan_geojson({"A": plan["A"]}), INFO), seed=3)
    imported = import_ilc_floor(parse_ilc_floor(plan_geojson(plan), INFO), seed=3)
    s = imported.scenario
    assert imported.escalators == 1 and imported.doorless == ()
    assert [d.position[0] < 8 for d in s.doors] == [True]
    escalator = shapely.box(10, 6, 19, 7.5)
    assert not any(escalator.contains(shapely.Point(lum.position[:2])) for lum in s.luminaires)
    known = {tuple(d.position) for d in bare.scenario.magnetic.dipoles}
    truss = [d for d in s.magnetic.dipoles if escalator.contains(shapely.Point(d.position[:2]))]
    assert len(truss) == 4 and not known & {tuple(d.position) for d in truss}
    assert {round(d.position[1], 3) for d in truss} == {6.75}
    heights = [d.position[2] for d in sorted(truss, key=lambda d: d.position[0])]
    h = s.site.ceiling_height
    along = np.array([0.1, 11 / 30, 19 / 30, 0.9])  # linspace(-0.4, 0.4, 4) + 0.5
    assert sorted(heights) == pytest.approx(0.3 + along * (h - 0.6), abs=1e-3)
    assert heights == sorted(heights) or heights == sorted(heights, reverse=True)
    for d in truss:
        assert 40.0 <= float(np.linalg.norm(d.moment)) <= 80.0 + 1e-6
    square = {"A": plan["A"], "feikaifangquyu": [(12, 4), (16, 4), (16, 8), (12, 8)]}
    kept = import_ilc_floor(parse_ilc_floor(plan_geojson(square), INFO), seed=3)
    assert kept.escalators == 0 and len(kept.scenario.doors) == 2


def test_walls_follow_the_outline_and_the_shops_once_each(two_shops):
    walls = two_shops.scenario.walls
    kinds = sorted((w.material, w.thickness) for w in walls)
    # Outline: 3 pieces beside the corridor, 2 round each shop; A|corridor and
    # B|corridor glass shopfronts; one partition between A and B (not two).
    assert kinds.count(("concrete", 0.3)) == 7
    assert kinds.count(("glass", 0.1)) == 2
    partitions = [w for w in walls if w.material in ("drywall", "brick")]
    assert len(partitions) == 1 and {partitions[0].start, partitions[0].to} == {(8, 4), (8, 10)}
    assert len(walls) == 10
    assert two_shops.scenario.site.north_deg == 0.0


def test_shop_polygons_are_cleaned(two_shops):
    # A tiny zigzag and collinear vertices are simplified away; a 0.2 m sliver is dropped.
    shops = {
        "A": [(0, 4), (4, 4), (4.03, 4.02), (4.06, 4), (8, 4), (8, 10), (0, 10)],
        "B": [(8, 4), (14, 4), (20, 4), (20, 10), (8, 10)],
        "sliver": [(0, 0), (6, 0), (6, 0.2), (0, 0.2)],
    }
    imported = import_ilc_floor(parse_ilc_floor(plan_geojson(shops), INFO), seed=3)
    assert imported.slivers == ("sliver",)
    assert dump_scenario(imported.scenario) == dump_scenario(two_shops.scenario)


def test_routes_nudge_a_waypoint_out_of_a_shop_or_leave_the_trace_out(two_shops):
    traces = {
        "clean": ([(1.0, 2.0), (18.0, 2.0)], 1.1),
        "nudged": ([(1.0, 4.5), (18.0, 2.0)], 1.1),  # 0.5 m into shop A, behind its wall
        "deep": ([(1.0, 8.0), (18.0, 2.0)], 1.1),  # 4 m into shop A
        "too_fast": ([(1.0, 2.0), (18.0, 2.0)], 5.0),
    }
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = add_trace_routes(two_shops, traces)
    routes = result.scenario.routes
    assert routes["clean"].waypoints == [(1.0, 2.0), (18.0, 2.0)]
    assert routes["clean"].speed == 1.1
    # The shopfront's face is 0.05 m below y = 4; the waypoint goes 0.1 m further.
    assert routes["nudged"].waypoints[0] == pytest.approx((1.0, 3.85), abs=1e-3)
    assert result.kept["nudged"] == ["waypoint 0 moved 0.65 m out of shop 'A'"]
    assert result.marks["nudged"][0] == pytest.approx([1.0, 3.85], abs=1e-3)  # where walked
    assert "in shop 'A'" in result.left_out["deep"] and "more than 1 m" in result.left_out["deep"]
    assert "outside (0.1, 3]" in result.left_out["too_fast"]
    assert set(routes) == {"clean", "nudged"}


def test_a_leg_through_a_shop_is_walked_round_it_or_left_out():
    # A kiosk (3 m × 1.5 m) stands in the corridor: its doorway is on a 3 m side,
    # and a straight leg along the corridor cuts through its short sides.
    shops = {**TWO_SHOPS, "kiosk": [(10, 1.5), (13, 1.5), (13, 3), (10, 3)]}
    imported = import_ilc_floor(parse_ilc_floor(plan_geojson(shops), INFO), seed=3)
    assert {d.position[1] for d in imported.scenario.doors} - {4.0} <= {1.5, 3.0}
    trace = {"through": ([(9.0, 2.2), (14.0, 2.2)], 1.2)}
    where = (
        "leg 0 (9.00, 2.20) → (14.00, 2.20) passes through a wall or column (the straight "
        "line cuts through shop 'kiosk' for 3.00 m)"
    )
    result = add_trace_routes(imported, trace, detour=False)
    assert result.kept == {} and result.left_out == {"through": where}
    result = add_trace_routes(imported, trace)
    route = result.scenario.routes["through"]
    pts = np.asarray(route.waypoints)
    length = np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()
    assert len(pts) > 2
    assert tuple(pts[0]) == (9.0, 2.2) and tuple(pts[-1]) == (14.0, 2.2)
    # Round the kiosk's 1.5 m side with 0.35 m to spare, at the trace's duration.
    assert 5.0 < length < 8.0
    assert route.speed == pytest.approx(1.2 * length / 5.0, abs=1e-3)
    assert result.kept["through"][0].startswith(where + ": walked round it, ")
    # Paced per leg, the way round keeps the leg's time: each of its legs faster.
    paced = add_trace_routes(imported, {"through": ([(9.0, 2.2), (14.0, 2.2)], [3.0, 7.0])})
    way = paced.scenario.routes["through"]
    assert way.waypoints == route.waypoints
    assert way.leg_speeds == pytest.approx([length / 4.0] * (len(pts) - 1), abs=1e-3)
    kiosk = Polygon(shops["kiosk"])
    assert not LineString(pts).intersects(kiosk)
    # The trace's own marks are the two a surveyor made, not the way round's corners.
    assert result.marks == {"through": [[9.0, 2.2], [14.0, 2.2]]}


def test_waypoint_speed_is_path_length_over_time():
    assert waypoint_speed([(0, 0), (3, 0), (3, 4)], [10.0, 12.0, 17.0]) == 1.0
    assert math.isnan(waypoint_speed([(0, 0), (1, 0)], [5.0, 5.0]))


def test_a_trace_with_times_is_paced_leg_by_leg(two_shops):
    traces = {
        # The stay at a repeated waypoint goes to the leg after it: 7 m in 10 s, then
        # 10 m in 4 + 3 s; the route's speed is the trace's, 17 m in 17 s.
        "paced": ([(1.0, 2.0), (8.0, 2.0), (8.0, 2.0), (18.0, 2.0)], [0.0, 10.0, 14.0, 17.0]),
        "miscounted": ([(1.0, 2.0), (18.0, 2.0)], [0.0, 5.0, 9.0]),
        "at_once": ([(1.0, 2.0), (8.0, 2.0), (8.0, 2.0), (18.0, 2.0)], [0.0, 10.0, 12.0, 10.0]),
        # A leg crawled: 1 m in 12 s (0.083 m/s).
        "crawled": ([(1.0, 2.0), (17.0, 2.0), (18.0, 2.0)], [0.0, 12.0, 24.0]),
        # 0.1004 m/s rounds to 0.1, which the schema's (0.1, 3] leaves out.
        "rounded": ([(1.0, 2.0), (11.04, 2.0), (18.0, 2.0)], [0.0, 100.0, 105.0]),
        # Nudged out of shop A (0.65 m): the leg keeps its time, not its speed.
        "nudged": ([(1.0, 4.5), (18.0, 2.0)], [0.0, 17.0]),
    }
    result = add_trace_routes(two_shops, traces)
    route = result.scenario.routes["paced"]
    assert route.waypoints == [(1.0, 2.0), (8.0, 2.0), (18.0, 2.0)]
    assert route.leg_speeds == pytest.approx([0.7, 10.0 / 7.0], abs=1e-3)
    assert route.speed == 1.0
    assert result.left_out["miscounted"] == "3 waypoint times for 2 waypoints"
    # The repeat's first time (10 s) and the next waypoint's (10 s): no time between.
    assert result.left_out["at_once"] == "waypoints 1 and 3 are marked 0.000 s apart"
    assert result.left_out["crawled"] == (
        "the leg from waypoint 1 to 2 is walked at 0.083 m/s, outside (0.1, 3] m/s"
    )
    assert "the leg from waypoint 0 to 1 is walked at 0.100 m/s" in result.left_out["rounded"]
    nudged = result.scenario.routes["nudged"]
    length = np.linalg.norm(np.subtract(*nudged.waypoints))
    assert nudged.leg_speeds == pytest.approx([length / 17.0], abs=1e-3)


def test_a_trace_left_out_for_a_leg_is_not_also_a_route():
    shops = {**TWO_SHOPS, "kiosk": [(10, 1.5), (13, 1.5), (13, 3), (10, 3)]}
    imported = import_ilc_floor(parse_ilc_floor(plan_geojson(shops), INFO), seed=3)
    # The straight 5 m through the kiosk in 2 s is 2.5 m/s; round it, above 3 m/s.
    trace = {"fast": ([(2.0, 2.2), (9.0, 2.2), (14.0, 2.2)], [0.0, 12.0, 14.0])}
    result = add_trace_routes(imported, trace)
    assert "is walked at" in result.left_out["fast"] and "above" not in result.left_out["fast"]
    assert "fast" not in result.scenario.routes and "fast" not in result.kept


@pytest.mark.parametrize(
    ("geojson", "info", "message"),
    [
        ([], INFO, "geojson: not GeoJSON: expected a FeatureCollection"),
        ({"type": "FeatureCollection", "features": []}, INFO, "geojson: no floor feature"),
        (plan_geojson(TWO_SHOPS), {"width": 20}, "floor_info: no map_info with a width"),
        (plan_geojson(TWO_SHOPS), {"map_info": {"width": 0, "height": 5}}, "floor_info: map size"),
    ],
)
def test_bad_plans_say_which_file_and_what(geojson, info, message):
    with pytest.raises(PlanImportError, match=message):
        parse_ilc_floor(geojson, info)


# ------------------------------------------------------------------ the MS mall floor


@pytest.fixture(scope="module")
def ms():
    floor = read_ilc_floor(MS_FLOOR / "geojson_map.json", MS_FLOOR / "floor_info.json")
    return import_ilc_floor(floor, seed=0)


@pytest.fixture(scope="module")
def ms_traces():
    from indoorsim.io.reallogs.ilc import read_ilc_trace

    traces = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # upstream's run-together rows are skipped
        for path in sorted((MS_FLOOR / "path_data_files").glob("*.txt")):
            wp = read_ilc_trace(path).waypoints
            xy = wp[["x", "y"]].to_numpy()
            traces[path.stem] = (xy.tolist(), wp.index.to_numpy(dtype=float).tolist())
    return traces


@needs_ms_floor
def test_ms_waypoints_fall_in_the_corridors(ms, ms_traces):
    s = ms.scenario
    xy = np.concatenate([np.asarray(wp) for wp, _ in ms_traces.values()])
    shops = shapely.union_all([Polygon(r.polygon) for r in s.rooms])
    assert len(xy) == 85
    assert shapely.contains_xy(Polygon(s.outline), xy[:, 0], xy[:, 1]).all()
    assert not shapely.contains_xy(shops, xy[:, 0], xy[:, 1]).any()
    # The check can fail: with the y axis flipped, many waypoints land in shops.
    assert shapely.contains_xy(shops, xy[:, 0], 176.44 - xy[:, 1]).mean() > 0.3


@needs_ms_floor
def test_ms_floor_is_a_mall(ms):
    s, n = ms.scenario, ms.counts()
    assert n["rooms"] == 172 and ms.slivers == ()
    assert n["doors"] + len(ms.doorless) + ms.escalators == 172 and n["doors"] > 120
    assert ms.escalators == 9  # of the 46 non-open areas
    assert n["lights"] > 1000 and n["aps"] > 50 and n["pillars"] > 50
    assert s.site.latitude == pytest.approx(30.29, abs=0.01)
    assert s.site.longitude == pytest.approx(120.08, abs=0.01)
    assert s.site.north_deg == 0.0
    # Every door is cut into a glass shopfront.
    glass = [LineString([w.start, w.to]) for w in s.walls if w.material == "glass"]
    tree = shapely.STRtree(glass)
    for d in s.doors:
        assert len(tree.query(shapely.Point(d.position), predicate="dwithin", distance=0.01))


@needs_ms_floor
def test_ms_floor_round_trips_and_is_seeded(ms, tmp_path):
    path = tmp_path / "ms.yaml"
    text = dump_scenario(ms.scenario, path)
    assert load_scenario(path) == ms.scenario
    floor = read_ilc_floor(MS_FLOOR / "geojson_map.json", MS_FLOOR / "floor_info.json")
    assert dump_scenario(import_ilc_floor(floor, seed=0).scenario) == text
    assert dump_scenario(import_ilc_floor(floor, seed=1).scenario) != text


@needs_ms_floor
def test_ms_traces_become_routes_that_simulate(ms, ms_traces, tmp_path):
    from indoorsim.simulate import simulate

    result = add_trace_routes(ms, ms_traces)
    assert set(result.kept) | set(result.left_out) == set(ms_traces)
    assert len(result.kept) >= 14
    for name, reason in result.left_out.items():
        assert "passes through a wall" in reason, (name, reason)

    def length(xy):
        return np.linalg.norm(np.diff(np.asarray(xy), axis=0), axis=1).sum()

    for name, notes in result.kept.items():
        route, (waypoints, times) = result.scenario.routes[name], ms_traces[name]
        # The same duration: the trace's speed over the path walked, and each leg its time.
        duration = times[-1] - times[0]
        assert length(route.waypoints) / route.speed == pytest.approx(duration, rel=1e-3)
        legs = np.linalg.norm(np.diff(np.asarray(route.waypoints), axis=0), axis=1)
        assert (legs / np.asarray(route.leg_speeds)).sum() == pytest.approx(duration, rel=1e-3)
        if not notes:
            assert np.allclose(route.waypoints, waypoints, atol=1e-3)
            assert route.leg_speeds == pytest.approx(legs / np.diff(times), abs=1e-3)
    path = tmp_path / "ms.yaml"
    dump_scenario(result.scenario, path)
    assert load_scenario(path) == result.scenario
    site = load_site(path)
    # A route with a leg walked round a wall, when there is one (the whole path is
    # planned before the walk is cut at 4 s).
    name = min(result.kept, key=lambda n: (not result.kept[n], n))
    rec = simulate(site, route=name, mode="handheld", device="nexus_5x", seed=0, duration_s=4.0)
    start = np.asarray(result.scenario.routes[name].waypoints[0])
    truth = rec.truth[["x", "y"]].to_numpy()
    assert rec.duration > 3.0 and np.linalg.norm(truth[0] - start) < 1.0
    # A whole trace walked leg by leg in the surveyor's times. Not its first leg: the
    # surveyor marked it already walking (2.1 m in 2.0 s), the walker starts at rest.
    from indoorsim.benchmark.sim_to_real import passing_times

    name = "5dd9e7c6c5b77e0006b17339"  # seven legs of 2-11 m, no sharp turn
    route = result.scenario.routes[name]
    # Without the walker's weave, which moves its closest approach to a mark by a few
    # per cent of a short leg's time.
    straight = WalkerParams(meander_m=0.0)
    rec = simulate(site, route=name, mode="handheld", device="nexus_5x", seed=0, walker=straight)
    at = rec.truth.index.to_numpy()[passing_times(rec.truth, np.asarray(route.waypoints))]
    at[0] = 0.0
    error = (np.diff(at) / np.diff(ms_traces[name][1]) - 1.0)[1:]
    assert np.abs(error).max() < 0.05, error


def test_an_l_shaped_non_open_area_is_not_an_escalator():
    """Its enclosing rectangle fits an escalator's (10 m × 1.5 m) but it fills only 0.57
    of it: it stays a unit with a door."""
    plan = {
        "A": [(0, 4), (8, 4), (8, 10), (0, 10)],
        "feikaifangquyu": [(10, 6), (20, 6), (20, 7.5), (19, 7.5), (19, 6.7), (10, 6.7)],
    }
    imported = import_ilc_floor(parse_ilc_floor(plan_geojson(plan), INFO), seed=3)
    assert imported.escalators == 0
