"""Gait: the speed profile, the true step events and the walk they make up."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from indoorsim.scenario import RouteSpec
from indoorsim.walker.gait import (
    PELVIS_HEIGHT_RATIO,
    BodyTrajectory,
    WalkerParams,
    cadence_hz,
    step_length_m,
    walk,
)
from indoorsim.walker.path import first_pass
from indoorsim.walker.route import Route, plan_route


def _steady(body: BodyTrajectory, skip: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Step times and lengths away from the ends of the walk (gait initiation and stopping)."""
    t = body.steps["t"].to_numpy()
    return np.diff(t)[skip:-skip], body.steps["length"].to_numpy()[1:][skip:-skip]


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


def test_asymmetry_lengthens_one_side_and_slows_it_alike(corridor):
    """Left steps 10 % longer than right ones take 10 % longer: the pace holds."""
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (39.0, 1.5)], speed=1.3))
    params = WalkerParams(asymmetry=0.1, speed_cv=0.0)
    body = walk(corridor, route, params, np.random.default_rng(2))
    steps = body.steps.assign(duration=body.steps.t.diff()).iloc[4:-4]
    left, right = steps[steps.foot == "L"], steps[steps.foot == "R"]
    assert left.length.mean() / right.length.mean() == pytest.approx(1.05 / 0.95, rel=0.03)
    assert left.duration.mean() / right.duration.mean() == pytest.approx(1.05 / 0.95, rel=0.03)


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


def _leg_times(corridor, params: WalkerParams, seed: int) -> np.ndarray:
    """How long a walker takes over each leg of a paced straight route, from the walk's
    start (its standing before the first step is the first leg's): 12 m at 0.8 m/s,
    24 m at 1.5 m/s, then 2 m at 1.9 m/s (too short to reach that from a walk that
    ends at rest)."""
    spec = RouteSpec(
        waypoints=[(1.0, 1.5), (13.0, 1.5), (37.0, 1.5), (39.0, 1.5)],
        leg_speeds=[0.8, 1.5, 1.9],
    )
    body = walk(corridor, plan_route(corridor, spec), params, np.random.default_rng(seed))
    passed = [body.t[np.argmax(body.pos[:, 0] >= x)] for x in (13.0, 37.0, 39.0 - 1e-3)]
    return np.diff(np.r_[0.0, passed])


def test_each_leg_takes_its_length_over_its_speed(corridor):
    legs = _leg_times(corridor, WalkerParams(), 5)
    assert legs[:2] == pytest.approx([12.0 / 0.8, 24.0 / 1.5], rel=0.02)
    assert legs[2] > 2.0 / 1.9 * 1.5
    # Stops count to their leg's time: the walker makes it up by walking faster.
    stopping = WalkerParams(stop_rate_per_min=2.0, stop_duration_s=(2.0, 2.0))
    legs = _leg_times(corridor, stopping, 5)
    assert legs[:2] == pytest.approx([12.0 / 0.8, 24.0 / 1.5], rel=0.06)


def test_paced_legs_round_corners_and_back_past_a_point(l_plan):
    # Out along the corridor, round the corner (a turn on the arc), up, back down
    # past the corner's point (a turn on the spot, about 2 s, the fourth leg's) and
    # out again: each leg in its time.
    points = [(1.0, 1.0), (11.0, 1.0), (11.0, 5.0), (11.0, 9.0), (11.0, 5.0), (11.0, 1.0)]
    speeds = [1.0, 0.8, 0.9, 0.6, 0.9]
    spec = RouteSpec(waypoints=points, leg_speeds=speeds)
    params = WalkerParams()
    body = walk(l_plan, plan_route(l_plan, spec), params, np.random.default_rng(3))
    # Passing times: the first approach to each point within 0.5 m of the closest one,
    # after the previous one's (the walker weaves, and passes some points twice).
    at, start = [0.0], 0
    for p in points[1:]:
        start += first_pass(np.linalg.norm(body.pos[start:, :2] - p, axis=1), 0.5)
        at.append(body.t[start])
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    assert np.diff(at) == pytest.approx(lengths / speeds, rel=0.1)


# ---------------------------------------------------------------------- speed profile


def test_turns_obey_the_yaw_rate_limit(l_plan, l_body):
    rate = np.degrees(np.abs(np.gradient(l_body.heading, l_body.t)))
    assert rate.max() <= WalkerParams().max_yaw_rate_dps
    assert rate.max() >= 90.0  # the corner is turned briskly, as people do
    slow = WalkerParams(max_yaw_rate_dps=60.0)
    route = plan_route(l_plan, RouteSpec(waypoints=[(1.0, 1.0), (11.0, 1.0), (11.0, 9.0)]))
    body = walk(l_plan, route, slow, np.random.default_rng(1))
    assert np.degrees(np.abs(np.gradient(body.heading, body.t))).max() <= 60.0


# ---------------------------------------------------------------------- the walk


def test_same_seed_same_walk_other_seed_other_walk(l_plan, room_to_corridor_end):
    runs = [
        walk(l_plan, room_to_corridor_end, WalkerParams(), np.random.default_rng(s))
        for s in (9, 9, 10)
    ]
    fields = ("t", "pos", "gait_offset", "heading", "yaw", "roll", "pitch", "speed")
    for field in (*fields, "step_phase", "stride_phase", "moving"):
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
    fields = ("t", "pos", "gait_offset", "heading", "yaw", "roll", "pitch", "speed")
    for name in (*fields, "step_phase", "gait_envelope"):
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=0, atol=1e-12)
    assert b.steps.equals(a.steps)


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


def test_walker_slows_at_each_route_point_and_cruises_between(corridor):
    # Points every 8 m on a straight corridor: the walker passes each inner one at about
    # the drawn fraction of its speed and is back at cruise midway between them.
    points = [(1.0 + 8.0 * k, 1.5) for k in range(5)]
    route = plan_route(corridor, RouteSpec(waypoints=points, speed=1.3))
    calm = {"speed_cv": 0.0, "meander_m": 0.0}
    params = WalkerParams(mark_speed=0.3, **calm)
    body = walk(corridor, route, params, np.random.default_rng(5))
    x = body.pos[:, 0]
    # The speed averaged over a stride (the within-step surge averages out there).
    stride = round(1.1 * body.rate_hz)
    mean_speed = np.convolve(body.speed, np.ones(stride) / stride, mode="same")
    for k in (1, 2, 3):
        at = np.argmin(np.abs(x - points[k][0]))
        mid = np.argmin(np.abs(x - points[k][0] - 4.0))
        assert mean_speed[at] == pytest.approx(0.3 * 1.3, abs=0.15)
        assert mean_speed[mid] == pytest.approx(1.3, rel=0.06)
    # The steps keep coming through the slowing: shorter, not stopped.
    assert body.moving[(x > 8.5) & (x < 9.5)].all()
    plain = walk(corridor, route, WalkerParams(**calm), np.random.default_rng(5))
    assert body.t[-1] > plain.t[-1] + 3 * 1.0


def test_paced_legs_keep_their_times_when_the_walker_slows_at_points(l_plan):
    # A twin slowing at its marks walks faster between them, each leg in its time.
    points = [(1.0, 1.0), (11.0, 1.0), (11.0, 5.0), (11.0, 9.0)]
    speeds = [1.0, 0.9, 0.8]
    spec = RouteSpec(waypoints=points, leg_speeds=speeds)
    params = WalkerParams(mark_speed=(0.25, 0.4))
    body = walk(l_plan, plan_route(l_plan, spec), params, np.random.default_rng(3))
    at, start, passing = [0.0], 0, []
    for p in points[1:]:
        start += first_pass(np.linalg.norm(body.pos[start:, :2] - p, axis=1), 0.5)
        at.append(body.t[start])
        passing.append(start)
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    assert np.diff(at) == pytest.approx(lengths / speeds, rel=0.1)
    # ... and passes each inner mark well below its legs' speeds (over half a second).
    half = int(0.25 * body.rate_hz)
    for k in (1, 2):
        i = passing[k - 1]
        assert body.speed[i - half : i + half].mean() < 0.7 * min(speeds[k - 1], speeds[k])
