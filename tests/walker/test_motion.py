"""Motion: the body's accelerations, bounce, sway and trunk yaw within each step."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from indoorsim.scenario import RouteSpec
from indoorsim.walker.gait import BodyTrajectory, WalkerParams, walk
from indoorsim.walker.motion import harmonic_series, impulse_displacement, surge_waveforms
from indoorsim.walker.route import plan_route

G = 9.81


def _accel(body: BodyTrajectory) -> np.ndarray:
    return np.diff(body.pos, 2, axis=0) * body.rate_hz**2


def test_accelerations_are_physical(l_body, straight_body):
    for body in (l_body, straight_body):
        acc = _accel(body)
        assert np.isfinite(acc).all()
        assert np.linalg.norm(acc, axis=1).max() < 3 * G
        specific = acc + np.array([0.0, 0.0, G])
        assert np.linalg.norm(specific, axis=1).max() < 2 * G  # heel-strike peaks < 2 g


def test_vertical_acceleration_swings_5_to_11_per_step(straight_body):
    # REALISM §5: 0.5–1.0 g peak to peak at the trunk [E]; the heel strike's jolt,
    # which peaks with the loading (40 ms after contact), adds up to a tenth to it.
    az = _accel(straight_body)[:, 2]
    t = straight_body.t[1:-1]
    strikes = straight_body.steps["t"].to_numpy()[4:-4]
    swings = [np.ptp(az[(t >= a) & (t < b)]) for a, b in itertools.pairwise(strikes)]
    assert 5.0 <= np.median(swings) <= 11.0


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


def test_the_surge_of_a_rigid_pendulum_on_a_point_foot_is_a_sawtooth():
    """With the load passing between the legs at once and no roll of the foot, the
    lever over the stance foot runs from −1/2 to +1/2 of a step, so gravity's part of
    the forward acceleration is g·D/h·(p − 1/2): a sawtooth, whose harmonics are
    −sin(2πkp)/(πk); the offset's are those divided by −(2πk/T)², i.e. −i/(πk³) in
    units of g·D/h·(T/2π)²."""
    by_gravity, _ = surge_waveforms(0.18, double_support=1e-4, cop_travel_steps=0.0)
    k = np.arange(1, len(by_gravity) + 1)
    # Every harmonic to a few per cent (the 512-point grid's half-sample slip, 0.006·k).
    np.testing.assert_allclose(by_gravity * np.pi * k**3 / -1j, 1.0, rtol=0.06)


def test_a_gradual_transfer_of_the_load_smooths_the_surge():
    """Passed between the legs at once, the load makes the acceleration jump at heel
    strike and its harmonics fall off slowly; passed over a fifth of a step, as in
    walking, they fall off fast: the eighth harmonic of the acceleration (k²·c_k)
    against the first."""

    def eighth_over_first(double_support: float) -> float:
        parts = surge_waveforms(0.18, double_support=double_support, cop_travel_steps=0.2)
        accel = sum(np.abs(c) for c in parts) * np.arange(1, len(parts[0]) + 1) ** 2
        return float(accel[-1] / accel[0])

    assert eighth_over_first(0.2) < 0.1 * eighth_over_first(1e-4)


def test_the_body_brakes_as_the_leading_leg_takes_the_load_and_pushes_off_before(corridor):
    """Without heel-strike jolts, the body centre's forward acceleration is that of the
    ground's force in walking: propulsion peaking about heel strike (the trailing leg's
    push-off, still carrying the load), braking peaking a fifth to a third of a step
    later (the leading leg loaded ahead of the body), each about a quarter of g; the
    speed swings by 0.1–0.4 m/s within a step (the inverted pendulum's 10–15 % of a
    1.3 m/s walk)."""
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (39.0, 1.5)], speed=1.3))
    params = WalkerParams(speed_cv=0.0, asymmetry=0.0, heel_strike_mps2=(0.0, 0.0))
    body = walk(corridor, route, params, np.random.default_rng(11))
    t = body.t[1:-1]
    heading = np.array([np.cos(body.heading[1:-1]), np.sin(body.heading[1:-1])]).T
    forward = np.einsum("ij,ij->i", _accel(body)[:, :2], heading)
    speed = np.gradient(body.pos[:, :2], body.t, axis=0)
    strikes = body.steps["t"].to_numpy()[4:-4]
    step = float(np.median(np.diff(strikes)))

    def mean_between(start: float, end: float) -> float:
        """The mean forward acceleration from ``start`` to ``end`` steps after heel strikes."""
        return float(
            np.concatenate(
                [forward[(t > s + start * step) & (t < s + end * step)] for s in strikes]
            ).mean()
        )

    assert 1.5 < mean_between(-0.1, 0.1) < 3.5
    assert -3.5 < mean_between(0.1, 0.35) < -1.5
    swing = [
        np.ptp(np.linalg.norm(speed[(body.t >= a) & (body.t < b)], axis=1))
        for a, b in itertools.pairwise(strikes)
    ]
    assert 0.1 <= np.median(swing) <= 0.4


def test_a_harmonic_series_is_its_cosines_and_sines():
    phase = np.linspace(0.0, 3.0, 301)
    coeff = np.array([0.5, -0.25j, 0.1 + 0.2j])
    expected = (
        0.5 * np.cos(2 * np.pi * phase)
        + 0.25 * np.sin(4 * np.pi * phase)
        + 0.1 * np.cos(6 * np.pi * phase)
        - 0.2 * np.sin(6 * np.pi * phase)
    )
    np.testing.assert_allclose(harmonic_series(phase, coeff), expected, atol=1e-12)


def test_impulse_leaves_no_velocity_or_displacement():
    t = np.arange(0, 2, 1 / 1000)
    x = impulse_displacement(t, np.array([0.5, 1.2]), np.array([3.0, 2.0]))
    acc = np.gradient(np.gradient(x, t), t)
    assert acc.max() == pytest.approx(3.0, rel=0.01)
    assert abs(x[-1]) < 1e-12 and abs(np.gradient(x, t)[-1]) < 1e-9


def test_impulse_peaks_its_delay_after_each_heel_strike():
    t = np.arange(0, 2, 1 / 1000)
    for delay in (0.02, 0.04):
        x = impulse_displacement(t, np.array([0.5, 1.2]), np.array([3.0, 2.0]), delay_s=delay)
        acc = np.gradient(np.gradient(x, t), t)
        assert t[np.argmax(acc)] == pytest.approx(0.5 + delay, abs=2e-3)


def test_the_trunk_leans_forward_at_the_bounces_bottom_by_its_drawn_amplitude(
    straight_body, corridor
):
    """The trunk's forward lean is in step with the bounce: largest where the body centre
    is lowest (double support), least at the top; in a step of the walk's median bounce
    it swings by twice the drawn amplitude, peak to peak."""
    body = straight_body
    strikes = body.steps["t"].to_numpy()
    core = (body.t > strikes[4]) & (body.t < strikes[-5])
    assert np.corrcoef(body.pitch[core], body.gait_offset[core, 2])[0, 1] < -0.9
    # Standing, the trunk is upright.
    assert np.abs(body.pitch[body.gait_envelope == 0]).max(initial=0.0) < 1e-12
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (39.0, 1.5)], speed=1.3))
    for degrees in (2.0, 3.0):
        params = WalkerParams(speed_cv=0.0, trunk_pitch_deg=degrees, loading_asymmetry=0.0)
        fixed = walk(corridor, route, params, np.random.default_rng(4))
        t, strikes = fixed.t, fixed.steps["t"].to_numpy()[4:-4]
        swings = [np.ptp(fixed.pitch[(t >= a) & (t < b)]) for a, b in itertools.pairwise(strikes)]
        assert np.degrees(np.median(swings)) / 2 == pytest.approx(degrees, rel=0.05)
