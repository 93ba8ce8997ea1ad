"""Routes: waypoint legs are checked, planned paths are walkable, short and keep clearance."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
import shapely

from indoorsim.scenario import RouteSpec, parse_scenario
from indoorsim.walker.route import Route, RouteError, plan_route
from indoorsim.world.plan import FloorPlan
from tests.conftest import box_scenario
from tests.walker.conftest import l_scenario


def _legs_walkable(plan: FloorPlan, route: Route) -> bool:
    lines = shapely.linestrings(np.stack([route.points[:-1], route.points[1:]], axis=1))
    return bool(shapely.covers(plan.walkable, lines).all())


def test_waypoints_are_kept_and_measured(l_plan):
    wp = [(1.0, 1.0), (11.0, 1.0), (11.0, 9.0)]
    route = plan_route(l_plan, RouteSpec(waypoints=wp, speed=1.1), "corridor")
    np.testing.assert_array_equal(route.points, wp)
    assert route.length == pytest.approx(18.0)
    assert route.speed == 1.1
    assert route.name == "corridor"


def test_repeated_waypoints_collapse(l_plan):
    route = plan_route(l_plan, RouteSpec(waypoints=[(1, 1), (1, 1), (5, 1), (5, 1)]))
    np.testing.assert_array_equal(route.points, [(1, 1), (5, 1)])


def test_leg_speeds_go_with_their_legs(l_plan):
    spec = RouteSpec(waypoints=[(1, 1), (1, 1), (5, 1), (9, 1)], leg_speeds=[0.5, 0.8, 1.4])
    route = plan_route(l_plan, spec)
    np.testing.assert_array_equal(route.points, [(1, 1), (5, 1), (9, 1)])
    np.testing.assert_array_equal(route.leg_speeds, [0.8, 1.4])  # the repeat's leg dropped
    with pytest.raises(ValueError):
        route.leg_speeds[0] = 2.0
    with pytest.raises(ValueError, match="'leg_speeds' has 1 speeds for 2 legs"):
        RouteSpec(waypoints=[(1, 1), (5, 1), (9, 1)], leg_speeds=[1.0])
    with pytest.raises(ValueError, match="'leg_speeds' needs 'waypoints'"):
        RouteSpec(start=(1, 1), goal=(5, 1), leg_speeds=[1.0])
    with pytest.raises(ValueError, match="leg_speeds must be 1 positive, finite speeds"):
        Route(name="r", points=np.array([(1.0, 1.0), (5.0, 1.0)]), speed=1.0, leg_speeds=[1, 2])


def test_route_is_immutable(l_plan):
    route = plan_route(l_plan, RouteSpec(waypoints=[(1, 1), (5, 1)]))
    with pytest.raises(dataclasses.FrozenInstanceError):
        route.speed = 2.0  # type: ignore[misc]
    with pytest.raises(ValueError):
        route.points[0, 0] = 3.0


def test_leg_through_a_wall_names_route_leg_and_end_points(l_plan):
    # Leg 1 goes from the corridor straight into the room through the wall at y = 2.
    wp = [(1.0, 1.0), (6.0, 1.0), (6.0, 5.0)]
    with pytest.raises(RouteError) as err:
        plan_route(l_plan, RouteSpec(waypoints=wp), "bad")
    msg = str(err.value)
    assert "'bad'" in msg and "leg 1 " in msg and "[6.0, 1.0] → [6.0, 5.0]" in msg
    assert "leg 0 " not in msg


def test_leg_through_the_door_is_fine(l_plan):
    route = plan_route(l_plan, RouteSpec(waypoints=[(4.0, 1.0), (4.0, 5.0)]))
    assert _legs_walkable(l_plan, route)


def test_leg_leaving_the_building_is_rejected(l_plan):
    # Across the empty corner of the L, outside the building.
    with pytest.raises(RouteError, match="leg 0 "):
        plan_route(l_plan, RouteSpec(waypoints=[(9.0, 5.0), (11.0, 5.0)]))


def test_empty_room_shortest_path_is_the_straight_line():
    plan = FloorPlan(parse_scenario(box_scenario()))
    route = plan_route(plan, RouteSpec(start=(1.0, 1.0), goal=(8.0, 5.0)))
    assert len(route.points) == 2
    assert route.length == pytest.approx(math.hypot(7.0, 4.0))


def test_planned_path_goes_through_the_door_and_round_the_corner(l_plan, room_to_corridor_end):
    route = room_to_corridor_end
    assert _legs_walkable(l_plan, route)
    np.testing.assert_array_equal(route.points[[0, -1]], [(2.0, 5.0), (11.0, 9.0)])
    # It leaves the room between the door jambs (x 3.55–4.45 at y = 2).
    pts = route.points
    j = np.flatnonzero((pts[:-1, 1] > 2.0) & (pts[1:, 1] <= 2.0))[0]
    f = (pts[j, 1] - 2.0) / (pts[j, 1] - pts[j + 1, 1])
    assert 3.55 < pts[j, 0] + f * (pts[j + 1, 0] - pts[j, 0]) < 4.45


def test_planned_path_keeps_its_clearance(l_plan, room_to_corridor_end):
    clearance = 0.35
    lines = shapely.linestrings(
        np.stack([room_to_corridor_end.points[:-1], room_to_corridor_end.points[1:]], axis=1)
    )
    gap = shapely.distance(l_plan.solid, lines)
    assert gap.min() >= clearance - 1e-6


def test_shortest_path_bounds(l_plan, room_to_corridor_end):
    """Never shorter than the straight line; never longer than a detour via another point."""
    route = room_to_corridor_end
    a, b = route.points[0], route.points[-1]
    assert route.length >= np.linalg.norm(b - a)
    rng = np.random.default_rng(0)
    free = l_plan.walkable.buffer(-0.5)
    detours = 0
    while detours < 6:
        m = rng.uniform([0, 0], [12, 10])
        if not shapely.contains_xy(free, *m):
            continue
        leg1 = plan_route(l_plan, RouteSpec(start=tuple(a), goal=tuple(m)))
        leg2 = plan_route(l_plan, RouteSpec(start=tuple(m), goal=tuple(b)))
        assert route.length <= leg1.length + leg2.length + 1e-9
        detours += 1


def test_start_near_a_wall_still_joins_the_path(l_plan):
    route = plan_route(l_plan, RouteSpec(start=(0.2, 1.0), goal=(11.0, 9.0)))
    assert _legs_walkable(l_plan, route)
    assert tuple(route.points[0]) == (0.2, 1.0)


def test_door_too_narrow_for_the_clearance_has_no_path():
    plan = FloorPlan(parse_scenario(l_scenario(door_width=0.6)))
    with pytest.raises(RouteError) as err:
        plan_route(plan, RouteSpec(start=(2.0, 5.0), goal=(11.0, 9.0)), "exit")
    msg = str(err.value)
    assert "'exit'" in msg and "[2.0, 5.0]" in msg and "[11.0, 9.0]" in msg
    # A slimmer walker fits through.
    assert plan_route(plan, RouteSpec(start=(2.0, 5.0), goal=(11.0, 9.0)), clearance=0.25)


def test_unwalkable_goal_is_named(l_plan):
    with pytest.raises(RouteError, match=r"goal \[9.0, 5.0\] is not in the walkable area"):
        plan_route(l_plan, RouteSpec(start=(2.0, 5.0), goal=(9.0, 5.0)))


def test_generated_office_routes_are_walkable():
    from indoorsim.scenario import generate

    scenario = generate.generate("office", seed=3)
    plan = FloorPlan(scenario)
    assert scenario.routes
    for name, spec in scenario.routes.items():
        assert _legs_walkable(plan, plan_route(plan, spec, name))
    # Planned across the floor too, between two far corners of the walkable area.
    lo, hi = np.array(plan.bounds[:2]) + 1.0, np.array(plan.bounds[2:]) - 1.0
    ends = list(shapely.points(np.array([lo, hi, [lo[0], hi[1]], [hi[0], lo[1]]])))
    inside = [p for p in ends if plan.walkable.buffer(-0.5).contains(p)]
    for a, b in itertools.combinations(inside, 2):
        route = plan_route(plan, RouteSpec(start=(a.x, a.y), goal=(b.x, b.y)))
        assert _legs_walkable(plan, route)
        assert route.length >= a.distance(b)


def test_visibility_shortcuts_agree_with_shapely():
    # _visible settles most segments with a midpoint test and a compiled
    # proper-crossing test before shapely's exact one: same answers.
    from indoorsim.walker import route as route_module

    plan = FloorPlan(parse_scenario(l_scenario()))
    free = plan.walkable.buffer(-0.35, join_style="mitre", mitre_limit=2.0)
    sight = free.buffer(1e-7, join_style="mitre")
    rng = np.random.default_rng(10)
    nodes = route_module._reflex_vertices(free)
    a = np.concatenate([rng.uniform(-0.5, 12.5, (2000, 2)), nodes[[0] * len(nodes)]])
    b = np.concatenate([rng.uniform(-0.5, 12.5, (2000, 2)), nodes])
    want = shapely.covers(sight, shapely.linestrings(np.stack([a, b], 1)))
    np.testing.assert_array_equal(route_module._visible(sight, a, b), want)
    assert want.any() and not want.all()
