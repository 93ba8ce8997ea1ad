"""Path: corner curves, turns on the spot and keeping off walls, seen in the walked track."""

from __future__ import annotations

import math

import numpy as np
import pytest

from indoorsim.scenario import RouteSpec
from indoorsim.walker.gait import WalkerParams, walk
from indoorsim.walker.route import plan_route
from tests.walker.conftest import assert_inside


def test_walker_keeps_its_distance_from_a_wall_the_route_hugs(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 0.35), (20.0, 0.35)]))
    params = WalkerParams()
    body = walk(corridor, route, params, np.random.default_rng(0))
    middle = (body.pos[:, 0] > 5.0) & (body.pos[:, 0] < 16.0)
    gap = body.pos[middle, 1] - 0.1
    assert np.median(gap) == pytest.approx(params.wall_distance_m, abs=0.03)
    # Bending away is gentle: the heading never leaves the corridor's direction by much.
    assert np.degrees(np.abs(body.heading)).max() < 10.0


def test_a_right_angle_takes_a_few_steps_and_slows_the_walker(l_plan):
    route = plan_route(l_plan, RouteSpec(waypoints=[(1.0, 1.0), (11.0, 1.0), (11.0, 9.0)]))
    body = walk(l_plan, route, WalkerParams(speed_cv=0.0), np.random.default_rng(5))
    turned = body.heading - body.heading[0]
    t10, t90 = np.interp([0.1, 0.9], turned / (math.pi / 2), body.t)
    steps_in_turn = np.diff(np.interp([t10, t90], body.t, body.step_phase))[0]
    assert 1.0 <= steps_in_turn <= 3.0
    cruise = body.speed[(body.t > 6) & (body.t < 8)].mean()
    turning = body.speed[(body.t > t10) & (body.t < t90)].mean()
    assert turning < cruise


def test_sharp_reversal_turns_on_the_spot(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(2.0, 1.5), (10.0, 1.5), (3.0, 1.5)]))
    body = walk(corridor, route, WalkerParams(), np.random.default_rng(0))
    assert body.heading[-1] - body.heading[0] == pytest.approx(math.pi, abs=1e-9)
    turning = np.abs(np.gradient(body.heading, body.t)) > 1e-3
    assert not (turning & body.moving).any()
    assert np.degrees(np.abs(np.gradient(body.heading, body.t))).max() <= 150.0
    assert_inside(corridor, body)
