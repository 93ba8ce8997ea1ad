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
    # Without the weave, whose turns would blur the corner's.
    params = WalkerParams(speed_cv=0.0, meander_m=(0.0, 0.0))
    body = walk(l_plan, route, params, np.random.default_rng(5))
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
    # Walking, the body turns only with its weave (a few °/s); the reversal is on the spot.
    turning = np.abs(np.gradient(body.heading, body.t)) > math.radians(20.0)
    assert turning.any() and not (turning & body.moving).any()
    assert np.degrees(np.abs(np.gradient(body.heading, body.t))).max() <= 150.0
    assert_inside(corridor, body)


def test_a_walker_standing_turned_faces_its_way_before_the_first_step(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (20.0, 1.5)]))
    params = WalkerParams(stand_start_s=3.0, start_turn_deg=30.0, start_turn_s=1.5)
    body = walk(corridor, route, params, np.random.default_rng(4))
    plain = walk(corridor, route, WalkerParams(stand_start_s=3.0), np.random.default_rng(4))
    standing = body.t < 3.0
    # Turned 30° left until 1.5 s before setting off, then on the spot to face +x.
    np.testing.assert_allclose(np.degrees(body.heading[body.t <= 1.5]), 30.0, atol=1e-9)
    assert np.degrees(body.heading[np.searchsorted(body.t, 2.25)]) == pytest.approx(15.0, abs=0.1)
    np.testing.assert_allclose(body.heading[~standing], plain.heading[~standing], atol=1e-12)
    # Turning on the spot: the body does not move, and the walk is the same walk.
    np.testing.assert_allclose(body.pos, plain.pos, atol=1e-12)
    with pytest.raises(ValueError, match="start_turn_s"):
        WalkerParams(start_turn_s=0.0)
