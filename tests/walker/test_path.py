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


def _walked_line(body, x_from: float, x_to: float) -> tuple[np.ndarray, np.ndarray]:
    """The body's track along a corridor on +x, its gait sway averaged out over 1.2 m
    (about a stride): (x, y) every 5 cm."""
    x = np.arange(x_from, x_to, 0.05)
    forward = np.maximum.accumulate(body.pos[:, 0])
    y = np.interp(x, forward, body.pos[:, 1])
    k = round(1.2 / 0.05)
    return x[k // 2 : -k // 2 + 1], np.convolve(y, np.ones(k) / k, mode="valid")


def test_a_weaving_walker_leaves_the_line_by_its_set_angle_and_keeps_off_the_walls(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (39.0, 1.5)], speed=1.3))
    straight = walk(corridor, route, WalkerParams(speed_cv=0.0), np.random.default_rng(3))
    weaving = walk(
        corridor, route, WalkerParams(speed_cv=0.0, meander_deg=4.0), np.random.default_rng(3)
    )
    x, y0 = _walked_line(straight, 6.0, 34.0)
    _, y = _walked_line(weaving, 6.0, 34.0)
    # Straight: the line walked is the route's, to the sway's leftovers.
    assert np.abs(y0 - 1.5).max() < 0.01
    # Weaving: its direction departs from the corridor's by about the RMS set (one walk
    # of 28 m over a 1.5 m length scale is a small sample), decimetres either side.
    slope = np.degrees(np.arctan(np.gradient(y, x)))
    assert 2.5 < np.sqrt(np.mean(slope**2)) < 5.5
    assert 0.03 < np.std(y) < 0.3
    # It starts and ends where the route does, and still keeps its distance from walls.
    np.testing.assert_allclose(weaving.pos[0], straight.pos[0], atol=1e-9)
    assert np.abs(weaving.pos[-1] - straight.pos[-1]).max() < 0.01
    assert_inside(corridor, weaving)
    assert weaving.pos[:, 1].min() > 0.1 + 0.3 and weaving.pos[:, 1].max() < 2.9 - 0.3


def test_without_a_weave_the_walk_draws_the_same_numbers(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (20.0, 1.5)]))
    a = walk(corridor, route, WalkerParams(), np.random.default_rng(8))
    b = walk(corridor, route, WalkerParams(meander_deg=0.0), np.random.default_rng(8))
    np.testing.assert_array_equal(a.pos, b.pos)
    with pytest.raises(ValueError, match="meander_deg"):
        WalkerParams(meander_deg=-1.0)


def test_a_weave_is_zero_at_a_turn_on_the_spot(corridor):
    # Out and back: the reversal is taken standing, where the weave fades to nothing,
    # so the walker turns where the straight walker does.
    route = plan_route(corridor, RouteSpec(waypoints=[(2.0, 1.5), (20.0, 1.5), (3.0, 1.5)]))
    params = WalkerParams(meander_deg=4.0)
    body = walk(corridor, route, params, np.random.default_rng(2))
    far = int(np.argmax(body.pos[:, 0]))
    assert body.pos[far, 0] == pytest.approx(20.0, abs=0.05)
    assert body.pos[far, 1] == pytest.approx(1.5, abs=0.05)
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
