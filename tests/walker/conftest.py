"""Walker fixtures: an L-shaped corridor with a room behind a door, and a straight corridor.

Also :func:`assert_inside`, the check that a body track keeps to the walkable area.
"""

from __future__ import annotations

import numpy as np
import pytest

from indoorsim.scenario import RouteSpec, parse_scenario
from indoorsim.walker.gait import BodyTrajectory, WalkerParams, walk
from indoorsim.walker.route import Route, plan_route
from indoorsim.world.plan import FloorPlan
from tests.conftest import box_scenario

# Corridor y 0–2 along x 0–12, turning north along x 10–12 up to y 10; a room
# x 0–8, y 2–7 opens onto the corridor through a 0.9 m door at (4, 2).
L_WALLS = [
    ((0, 0), (12, 0)),
    ((12, 0), (12, 10)),
    ((12, 10), (10, 10)),
    ((10, 10), (10, 2)),
    ((10, 2), (8, 2)),
    ((8, 2), (8, 7)),
    ((8, 7), (0, 7)),
    ((0, 7), (0, 0)),
    ((0, 2), (8, 2)),
]
DOOR = {"position": [4, 2], "width": 0.9}


def l_scenario(door_width: float = 0.9, **routes: dict) -> dict:
    """The L-corridor scenario as a dict, with ``routes`` added."""
    return box_scenario(
        name="l-corridor",
        walls=[{"from": list(a), "to": list(b), "thickness": 0.2} for a, b in L_WALLS],
        doors=[{**DOOR, "width": door_width}],
        routes=routes,
    )


def straight_plan(length: float = 40.0) -> FloorPlan:
    """A 3 m wide corridor ``length`` m long along +x."""
    corners = [(0, 0), (length, 0), (length, 3), (0, 3)]
    walls = [
        {"from": list(corners[i]), "to": list(corners[(i + 1) % 4]), "thickness": 0.2}
        for i in range(4)
    ]
    return FloorPlan(parse_scenario(box_scenario(name="straight", walls=walls)))


@pytest.fixture(scope="session")
def l_plan() -> FloorPlan:
    return FloorPlan(parse_scenario(l_scenario()))


@pytest.fixture(scope="session")
def room_to_corridor_end(l_plan: FloorPlan) -> Route:
    """From inside the room, out through the door, round the corner, up the corridor."""
    return plan_route(l_plan, RouteSpec(start=(2.0, 5.0), goal=(11.0, 9.0), speed=1.3), "exit")


@pytest.fixture(scope="session")
def l_body(l_plan: FloorPlan, room_to_corridor_end: Route) -> BodyTrajectory:
    return walk(l_plan, room_to_corridor_end, WalkerParams(), np.random.default_rng(7))


@pytest.fixture(scope="session")
def corridor() -> FloorPlan:
    return straight_plan()


@pytest.fixture(scope="session")
def straight_body(corridor: FloorPlan) -> BodyTrajectory:
    """38 m of straight walking at 1.3 m/s, without slow speed drift, asymmetry or
    weave (meander)."""
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (39.0, 1.5)], speed=1.3))
    params = WalkerParams(speed_cv=0.0, asymmetry=0.0, meander_m=(0.0, 0.0))
    return walk(corridor, route, params, np.random.default_rng(11))


def assert_inside(plan: FloorPlan, body: BodyTrajectory) -> None:
    """Every sample of the body is walkable and no step between samples crosses a wall."""
    assert plan.is_walkable(body.pos).all()
    assert not plan.crosses_wall(body.pos[:-1], body.pos[1:]).any()
