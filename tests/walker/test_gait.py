"""Gait: physical invariants of the body track and the true step events."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
import shapely

from indoorsim.scenario import RouteSpec
from indoorsim.walker.gait import (
    PELVIS_HEIGHT_RATIO,
    BodyTrajectory,
    WalkerParams,
    cadence_hz,
    impulse_displacement,
    step_length_m,
    walk,
)
from indoorsim.walker.route import Route, plan_route
from indoorsim.world.plan import FloorPlan

G = 9.81


def _steady(body: BodyTrajectory, skip: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Step times and lengths away from the ends of the walk (gait initiation and stopping)."""
    t = body.steps["t"].to_numpy()
    return np.diff(t)[skip:-skip], body.steps["length"].to_numpy()[1:][skip:-skip]


def _accel(body: BodyTrajectory) -> np.ndarray:
    return np.diff(body.pos, 2, axis=0) * body.rate_hz**2


def _assert_inside(plan: FloorPlan, body: BodyTrajectory) -> None:
    assert plan.is_walkable(body.pos).all()
    assert not plan.crosses_wall(body.pos[:-1], body.pos[1:]).any()


# ---------------------------------------------------------------------- cadence


def test_cadence_matches_the_gait_literature():
    """REALISM §5: ≈ 1.6–1.75 Hz at 1 m/s, ≈ 1.94 Hz at 1.31 m/s, ≈ 2.1 Hz at 1.7 m/s."""
    assert 1.6 <= cadence_hz(1.0) <= 1.75
    assert cadence_hz(1.31) == pytest.approx(1.94, abs=0.05)
    assert cadence_hz(1.7) == pytest.approx(2.1, abs=0.05)
    v = np.linspace(0.3, 2.5, 50)
    assert np.all(np.diff(cadence_hz(v)) > 0)
    # Step length × cadence is the speed, and a taller walker takes longer, slower steps.
    np.testing.assert_allclose(step_length_m(v) * cadence_hz(v), v)
    assert np.all(cadence_hz(v, height_m=1.9) < cadence_hz(v, height_m=1.6))
    assert step_length_m(1.31) == pytest.approx(1.31 / 1.94, rel=0.03)  # 0.67 m usual step


def test_params_are_validated_and_frozen():
    with pytest.raises(ValueError, match="step_time_cv"):
        WalkerParams(step_time_cv=-0.1)
    with pytest.raises(ValueError, match="height_m"):
        WalkerParams(height_m=0.5)
    with pytest.raises(TypeError):
        WalkerParams(1.8)  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        WalkerParams().height_m = 1.9  # type: ignore[misc]


def test_rate_below_200_hz_is_refused(corridor):
    route = Route(name="r", points=np.array([[1.0, 1.5], [5.0, 1.5]]), speed=1.2)
    with pytest.raises(ValueError, match="200"):
        walk(corridor, route, WalkerParams(), np.random.default_rng(0), rate_hz=100.0)


def test_higher_rates_sample_the_same_walk(corridor):
    route = Route(name="r", points=np.array([[1.0, 1.5], [6.0, 1.5]]), speed=1.2)
    body = walk(corridor, route, WalkerParams(), np.random.default_rng(0), rate_hz=400.0)
    np.testing.assert_allclose(np.diff(body.t), 1 / 400)
    assert body.t[0] == 0.0
    assert len(body.t) == len(body.pos) == len(body.heading) == len(body.moving)


# ---------------------------------------------------------------------- walls


def test_body_stays_in_the_walkable_area(l_plan, l_body):
    _assert_inside(l_plan, l_body)


def test_waypoint_route_round_the_corner_stays_inside(l_plan):
    route = plan_route(l_plan, RouteSpec(waypoints=[(1.0, 1.0), (11.0, 1.0), (11.0, 9.0)]))
    body = walk(l_plan, route, WalkerParams(stop_rate_per_min=3.0), np.random.default_rng(3))
    _assert_inside(l_plan, body)


def test_pymunk_keeps_the_body_off_a_wall_the_route_hugs(corridor):
    """Waypoints 0.1 m from the wall face, no steering away: the body disc holds the track off."""
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 0.2), (20.0, 0.2)]))
    params = WalkerParams(body_radius_m=0.25, wall_distance_m=0.0)
    body = walk(corridor, route, params, np.random.default_rng(0))
    _assert_inside(corridor, body)
    settled = body.t > 1.0  # the disc starts overlapping the wall and is pushed out
    # The wall face is at y = 0.1; lateral sway and pymunk's contact slop take a little.
    assert body.pos[settled, 1].min() > 0.1 + 0.25 - 0.035


def test_walker_keeps_its_distance_from_a_wall_the_route_hugs(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 0.35), (20.0, 0.35)]))
    params = WalkerParams()
    body = walk(corridor, route, params, np.random.default_rng(0))
    middle = (body.pos[:, 0] > 5.0) & (body.pos[:, 0] < 16.0)
    gap = body.pos[middle, 1] - 0.1
    assert np.median(gap) == pytest.approx(params.wall_distance_m, abs=0.03)
    # Bending away is gentle: the heading never leaves the corridor's direction by much.
    assert np.degrees(np.abs(body.heading)).max() < 10.0


def test_random_routes_in_generated_buildings_stay_inside_and_within_the_yaw_limit():
    from indoorsim.scenario import generate

    rng = np.random.default_rng(0)
    params = WalkerParams(stop_rate_per_min=2.0)
    for kind in ("office", "basement"):
        plan = FloorPlan(generate.generate(kind, seed=1))
        free = plan.walkable.buffer(-0.5)
        lo, hi = np.array(plan.bounds[:2]), np.array(plan.bounds[2:])
        ends: list[tuple[float, float]] = []
        while len(ends) < 6:
            p = rng.uniform(lo, hi)
            if free.contains(shapely.Point(p)):
                ends.append((float(p[0]), float(p[1])))
        for a, b in zip(ends[::2], ends[1::2], strict=True):
            route = plan_route(plan, RouteSpec(start=a, goal=b))
            body = walk(plan, route, params, np.random.default_rng(len(ends)))
            _assert_inside(plan, body)
            rate = np.degrees(np.abs(np.gradient(body.heading, body.t)))
            assert rate.max() <= params.max_yaw_rate_dps
            assert np.all(np.diff(body.step_phase) >= 0)


def test_generated_office_routes_are_walked_inside_the_walls():
    from indoorsim.scenario import generate

    scenario = generate.generate("office", seed=5)
    plan = FloorPlan(scenario)
    for i, (name, spec) in enumerate(scenario.routes.items()):
        body = walk(plan, plan_route(plan, spec, name), WalkerParams(), np.random.default_rng(i))
        _assert_inside(plan, body)


# ---------------------------------------------------------------------- steps


def test_step_events_match_the_phase(l_body):
    steps, phase = l_body.steps, l_body.step_phase
    assert list(steps.columns) == ["t", "foot", "length"]
    assert len(steps) == round(phase[-1])
    at_strike = np.interp(steps["t"].to_numpy(), l_body.t, phase)
    np.testing.assert_allclose(at_strike, np.arange(1, len(steps) + 1), atol=0.02)
    assert np.all(np.diff(phase) >= 0)
    assert set(steps["foot"]) == {"L", "R"}
    assert np.all(steps["foot"].to_numpy()[1:] != steps["foot"].to_numpy()[:-1])
    # Left heel strikes start a stride, right ones are half way.
    # Sampled just after each heel strike (the phase wraps at left heel strikes).
    after = np.searchsorted(l_body.t, steps["t"].to_numpy())
    stride = l_body.stride_phase[after]
    left = (steps["foot"] == "L").to_numpy()
    dist_to_zero = np.minimum(stride[left], 1 - stride[left])
    assert dist_to_zero.max() < 0.02
    np.testing.assert_allclose(stride[~left], 0.5, atol=0.02)
    assert np.all((l_body.stride_phase >= 0) & (l_body.stride_phase < 1))


def test_step_lengths_add_up_to_the_straight_route(straight_body):
    assert straight_body.steps["length"].sum() == pytest.approx(38.0, abs=1e-9)


def test_step_length_times_cadence_is_the_speed(straight_body):
    times, lengths = _steady(straight_body)
    cadence = 1.0 / times.mean()
    t = straight_body.t
    walking = (t > straight_body.steps["t"].iloc[4]) & (t < straight_body.steps["t"].iloc[-5])
    speed = straight_body.speed[walking].mean()
    assert lengths.mean() * cadence == pytest.approx(speed, rel=0.05)
    assert speed == pytest.approx(1.3, rel=0.05)
    assert cadence == pytest.approx(float(cadence_hz(1.3)), rel=0.05)


def test_step_variation_reproduces_the_parameters(straight_body):
    times, lengths = _steady(straight_body)
    assert times.std() / times.mean() == pytest.approx(0.025, rel=0.3)
    assert lengths.std() / lengths.mean() == pytest.approx(0.04, rel=0.3)


def test_asymmetry_lengthens_one_side(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (39.0, 1.5)], speed=1.3))
    params = WalkerParams(asymmetry=0.1, speed_cv=0.0)
    body = walk(corridor, route, params, np.random.default_rng(2))
    steps = body.steps.iloc[4:-4]
    left = steps[steps.foot == "L"].length.mean()
    right = steps[steps.foot == "R"].length.mean()
    assert left / right == pytest.approx(1.05 / 0.95, rel=0.03)


def test_standing_still_at_both_ends(l_body):
    params = WalkerParams()
    t, steps = l_body.t, l_body.steps["t"].to_numpy()
    assert steps[0] > params.stand_start_s
    assert steps[-1] == pytest.approx(t[-1] - params.stand_end_s, abs=1 / l_body.rate_hz)
    still = (t < params.stand_start_s - 0.1) | (t > t[-1] - params.stand_end_s + 0.2)
    assert not l_body.moving[still].any()
    assert l_body.speed[still].max() < 0.01
    np.testing.assert_allclose(
        l_body.pos[t < params.stand_start_s - 0.1, 2], PELVIS_HEIGHT_RATIO * 1.70, atol=1e-6
    )


def test_stops_stand_still_without_steps(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (39.0, 1.5)]))
    params = WalkerParams(stop_rate_per_min=6.0, stop_duration_s=(3.0, 3.0))
    body = walk(corridor, route, params, np.random.default_rng(4))
    inner = (body.t > params.stand_start_s) & (body.t < body.t[-1] - params.stand_end_s)
    still = inner & ~body.moving
    assert still.sum() / body.rate_hz >= 2 * 3.0 - 0.1  # at least two stops happened
    steps = body.steps["t"].to_numpy()
    idx = np.clip(np.searchsorted(body.t, steps), 0, len(body.t) - 1)
    # Heel strikes end bouts; none falls strictly inside a stop.
    assert not (still[idx] & still[np.maximum(idx - 1, 0)]).any()
    # Away from the bout ends the body is at rest during stops.
    core = still & (np.convolve(still, np.ones(41), "same") >= 41)
    assert body.speed[core].max() < 0.01


# ---------------------------------------------------------------------- motion


def test_accelerations_are_physical(l_body, straight_body):
    for body in (l_body, straight_body):
        acc = _accel(body)
        assert np.isfinite(acc).all()
        assert np.linalg.norm(acc, axis=1).max() < 3 * G
        specific = acc + np.array([0.0, 0.0, G])
        assert np.linalg.norm(specific, axis=1).max() < 2 * G  # heel-strike peaks < 2 g


def test_vertical_acceleration_swings_5_to_10_per_step(straight_body):
    az = _accel(straight_body)[:, 2]
    t = straight_body.t[1:-1]
    strikes = straight_body.steps["t"].to_numpy()[4:-4]
    swings = [np.ptp(az[(t >= a) & (t < b)]) for a, b in itertools.pairwise(strikes)]
    assert 5.0 <= np.median(swings) <= 10.0


def test_bounce_sway_and_trunk_yaw_amplitudes(straight_body):
    body, params = straight_body, WalkerParams()
    strikes = body.steps["t"].to_numpy()
    core = (body.t > strikes[4]) & (body.t < strikes[-5])
    z = body.pos[core, 2]
    assert 0.035 <= np.ptp(z) <= 0.07  # 4–5 cm bounce plus heel-strike dips
    lateral = body.pos[core, 1] - 1.5
    assert params.lateral_sway_m[0] * 0.9 <= np.abs(lateral).max() <= params.lateral_sway_m[1] * 1.2
    trunk = np.degrees(np.abs(body.yaw[core] - body.heading[core]).max())
    assert params.trunk_yaw_deg[0] * 0.9 <= trunk <= params.trunk_yaw_deg[1] * 1.01


def test_turns_obey_the_yaw_rate_limit(l_plan, l_body):
    rate = np.degrees(np.abs(np.gradient(l_body.heading, l_body.t)))
    assert rate.max() <= WalkerParams().max_yaw_rate_dps
    assert rate.max() >= 90.0  # the corner is turned briskly, as people do
    slow = WalkerParams(max_yaw_rate_dps=60.0)
    route = plan_route(l_plan, RouteSpec(waypoints=[(1.0, 1.0), (11.0, 1.0), (11.0, 9.0)]))
    body = walk(l_plan, route, slow, np.random.default_rng(1))
    assert np.degrees(np.abs(np.gradient(body.heading, body.t))).max() <= 60.0


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
    _assert_inside(corridor, body)


def test_impulse_leaves_no_velocity_or_displacement():
    t = np.arange(0, 2, 1 / 1000)
    x = impulse_displacement(t, np.array([0.5, 1.2]), np.array([3.0, 2.0]))
    acc = np.gradient(np.gradient(x, t), t)
    assert acc.max() == pytest.approx(3.0, rel=0.01)
    assert abs(x[-1]) < 1e-12 and abs(np.gradient(x, t)[-1]) < 1e-9


def test_same_seed_same_walk_other_seed_other_walk(l_plan, room_to_corridor_end):
    runs = [
        walk(l_plan, room_to_corridor_end, WalkerParams(), np.random.default_rng(s))
        for s in (9, 9, 10)
    ]
    for field in ("t", "pos", "heading", "yaw", "speed", "step_phase", "stride_phase", "moving"):
        np.testing.assert_array_equal(getattr(runs[0], field), getattr(runs[1], field))
    assert runs[0].steps.equals(runs[1].steps)
    assert not np.array_equal(runs[0].steps["length"], runs[2].steps["length"])


def test_a_walk_cut_short_is_the_whole_walk_up_to_the_cut(l_plan, room_to_corridor_end):
    params = WalkerParams(stop_rate_per_min=2.0)
    whole = walk(l_plan, room_to_corridor_end, params, np.random.default_rng(3))
    cut = walk(l_plan, room_to_corridor_end, params, np.random.default_rng(3), until_s=9.0)
    assert cut.t[-1] < whole.t[-1] - 2.0
    k = int(np.searchsorted(whole.t, 9.0, side="right"))
    a, b = whole.window(0, k), cut.window(0, k)
    for name in ("t", "pos", "heading", "yaw", "speed", "step_phase", "gait_envelope"):
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=0, atol=1e-12)
    assert b.steps.equals(a.steps)


def test_steering_copies_the_plan_only_where_the_physics_would(corridor, monkeypatch):
    # The disc's physics is skipped where the plan keeps clear of every wall
    # and the disc is on it: the walk must come out as with every step simulated.
    from indoorsim.walker import gait

    route = plan_route(
        corridor, RouteSpec(waypoints=[(1.0, 1.5), (10.0, 1.5), (20.0, 0.2), (30.0, 1.5)])
    )
    params = WalkerParams(wall_distance_m=0.0)  # the route runs into the wall: contacts
    fast = walk(corridor, route, params, np.random.default_rng(4))
    monkeypatch.setattr(gait, "_STEER_MIN_SKIP", 10**9)
    full = walk(corridor, route, params, np.random.default_rng(4))
    np.testing.assert_allclose(fast.pos, full.pos, rtol=0, atol=1e-9)
    assert (full.pos[:, 1] > 0.1 + 0.25 - 0.035).all()  # the wall held the disc off


@pytest.mark.parametrize("natural", [False, True])
def test_bout_splines_are_scipys_cubic_splines_to_the_bit(natural: bool) -> None:
    from scipy.interpolate import CubicSpline

    from indoorsim.walker.gait import _knot_spline

    rng = np.random.default_rng(3)
    bc = "natural" if natural else ((1, 0.0), (1, 0.0))
    for n in (2, 3, 4, 7, 40):
        x = np.cumsum(rng.uniform(0.2, 1.5, n))
        y = np.cumsum(rng.uniform(0.0, 2.0, n))
        ours, scipys = _knot_spline(x, y, natural=natural), CubicSpline(x, y, bc_type=bc)
        np.testing.assert_array_equal(ours.c, scipys.c)
        np.testing.assert_array_equal(ours.x, scipys.x)
