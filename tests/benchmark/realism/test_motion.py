"""Motion statistics of whole recordings: closed forms on synthetic logs, agreement with truth."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.motion import (
    HELD_KEYS,
    MOTION_KEYS,
    held_phone_motion,
    motion_profiles,
    motion_statistics,
    uniform_stream,
)
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate


def _frame(t: np.ndarray, values: np.ndarray, columns: list[str]) -> pd.DataFrame:
    return pd.DataFrame(values, index=pd.Index(t, name="t"), columns=columns)


def _sine_walk(step_hz: float = 1.8, seconds: float = 60.0, rate: float = 200.0) -> Recording:
    """A phone that bounces sinusoidally at the step rate while yawing at a steady rate."""
    t = np.arange(0, seconds, 1 / rate)
    accel = np.column_stack(
        [np.zeros_like(t), np.zeros_like(t), 9.81 + 2 * np.sin(2 * np.pi * step_hz * t)]
    )
    gyro = np.tile([0.0, 0.0, 0.1], (len(t), 1))
    half = 0.05 * t  # yaw 0.1 rad/s about z
    rotation = np.column_stack([np.cos(half), np.zeros_like(t), np.zeros_like(t), np.sin(half)])
    steps_t = np.arange(0.25, seconds, 1 / step_hz)
    steps = pd.DataFrame(
        {"foot": np.arange(len(steps_t)) % 2, "length": 0.7}, index=pd.Index(steps_t, name="t")
    )
    return Recording(
        streams={
            "accel": _frame(t, accel, ["x", "y", "z"]),
            "gyro": _frame(t, gyro, ["x", "y", "z"]),
            "rotation": _frame(t, rotation, ["qw", "qx", "qy", "qz"]),
            "steps": steps,
        },
        meta={},
    )


def test_a_sinusoidal_walk_gives_the_closed_form_statistics():
    s = motion_statistics(_sine_walk(1.8))
    assert set(s) == set(MOTION_KEYS)
    assert s["step_hz"] == pytest.approx(1.8, abs=0.01)
    assert s["cadence_ratio"] == pytest.approx(1.0, abs=0.01)
    assert s["acc_std"] == pytest.approx(2 / math.sqrt(2), rel=0.01)
    assert s["acc_p2p"] == pytest.approx(4.0, rel=0.01)
    assert s["acc_crest"] == pytest.approx(math.sqrt(2), rel=0.01)
    assert s["acc_kurtosis"] == pytest.approx(-1.5, abs=0.01)
    assert s["share_step"] > 0.99 and s["share_2nd"] < 0.01 and s["share_stride"] < 0.01
    assert s["gyro_rms_1"] == pytest.approx(0.0, abs=1e-9)
    assert s["heading_jitter"] == pytest.approx(0.0, abs=1e-3)


def test_a_held_phones_surge_sway_bob_and_turn_are_read_in_its_own_walking_frame():
    """A flat phone turning steadily about the vertical, whose top-forward, sideways and
    vertical accelerations and yaw rate are sines of known amplitude: they come back
    whatever the compass direction of its top."""
    rec = _sine_walk(1.75)
    t = rec.accel.index.to_numpy()
    step, stride = 2 * np.pi * 1.75 * t, np.pi * 1.75 * t
    rec.accel["y"] = 0.5 * np.sin(step + 0.7)
    rec.accel["x"] = 0.3 * np.sin(stride) + 0.25 * np.cos(step)
    rec.gyro["z"] = 0.1 + 0.2 * np.cos(stride)
    held = held_phone_motion(rec)
    assert set(held) == set(HELD_KEYS)
    expected = {
        "surge_step": 0.5,
        "sway_stride": 0.3,
        "bob_step": 2.0,
        "yaw_stride": 0.2,
        "sway_step": 0.25,
    }
    for key, value in expected.items():
        assert held[key] == pytest.approx(value, rel=0.02), key
    # Off the analysis grid, and with a sway at the step rate too, the stride rate's
    # reading is not biased by the step rate's sidelobes.
    rec = _sine_walk(1.9)
    t = rec.accel.index.to_numpy()
    rec.accel["x"] = 0.3 * np.sin(np.pi * 1.9 * t) + 0.5 * np.sin(2 * np.pi * 1.9 * t)
    assert held_phone_motion(rec)["sway_stride"] == pytest.approx(0.3, rel=0.01)


def test_a_held_phones_roll_against_its_sideways_jerk_in_closed_form():
    """A phone rolling at ω_y = cos(Ωt) lets gravity into its x axis, a_x = −g·∫ω_y:
    the jerk is −g·ω_y, a correlation of −1. A sideways shake at another frequency
    whose jerk is as large as gravity's share halves the covariance's weight: −1/√2."""
    g, f = 9.81, 1.75
    rec = _sine_walk(f)
    t = rec.accel.index.to_numpy()
    omega = 2 * np.pi * f
    rec.gyro["y"] = np.cos(omega * t)
    rec.accel["x"] = -g * np.sin(omega * t) / omega
    assert held_phone_motion(rec)["roll_jerk"] == pytest.approx(-1.0, abs=1e-3)
    shake = 2 * np.pi * 3.1
    rec.accel["x"] += g / shake * np.sin(shake * t)
    assert held_phone_motion(rec)["roll_jerk"] == pytest.approx(-1 / math.sqrt(2), abs=0.02)
    # Rolled by the sideways acceleration, as a pendulum would be: positive.
    rec.accel["x"] = g * np.sin(omega * t) / omega
    assert held_phone_motion(rec)["roll_jerk"] == pytest.approx(1.0, abs=1e-3)


def test_the_stride_profile_of_a_lopsided_walk_is_its_waveform():
    # One foot's steps jolt harder: ‖a‖ = g + 2·cos(2π·2f·t) + 3·cos(2π·f·t) at the
    # stride rate f, largest at t = 0 of each stride.
    stride_hz, rate = 0.9, 200.0
    t = np.arange(0, 60.0, 1 / rate)
    phase = 2 * np.pi * stride_hz * t
    z = 9.81 + 2 * np.cos(2 * phase) + 3 * np.cos(phase)
    zeros = np.zeros_like(t)
    rec = Recording(
        streams={"accel": _frame(t, np.column_stack([zeros, zeros, z]), ["x", "y", "z"])},
        meta={},
    )
    x, y = motion_profiles(rec)["accel_stride"]
    assert x[0] == -0.5 and x[-1] == 1.5
    expected = 9.81 + 2 * np.cos(4 * np.pi * x) + 3 * np.cos(2 * np.pi * x)
    np.testing.assert_allclose(y, expected, atol=0.05)


def test_a_still_phone_has_no_walking_and_no_statistics():
    t = np.arange(0, 30, 0.01)
    rec = Recording(
        streams={"accel": _frame(t, np.tile([0.0, 0.0, 9.81], (len(t), 1)), ["x", "y", "z"])},
        meta={},
    )
    s = motion_statistics(rec)
    assert s["walking_s"] == 0 and math.isnan(s["step_hz"])


def test_resampling_to_the_common_rate_keeps_a_slow_signal_and_removes_a_fast_one():
    t = np.arange(0, 20, 1 / 400)
    slow, fast = np.sin(2 * np.pi * 2 * t), np.sin(2 * np.pi * 60 * t)  # 60 Hz > 25 Hz Nyquist
    out = uniform_stream(_frame(t, np.column_stack([slow, fast]), ["a", "b"]), ["a", "b"], 50.0)
    grid = np.arange(len(out)) / 50.0
    inner = slice(50, -50)  # away from the filter's edges
    np.testing.assert_allclose(out[inner, 0], np.sin(2 * np.pi * 2 * grid[inner]), atol=0.01)
    assert np.abs(out[inner, 1]).max() < 0.01  # not aliased to 10 Hz


@pytest.mark.parametrize("mode", ["handheld", "pocketed"])
def test_the_step_rate_found_in_a_simulated_walk_is_its_true_cadence(mode):
    rec = simulate(load_site("han2023_corridor"), route="trajectory", mode=mode, seed=2)
    s = motion_statistics(rec)
    assert s["walking_s"] > 30
    assert s["cadence_ratio"] == pytest.approx(1.0, abs=0.05)


def _coning(pitch_amp: float, roll_amp: float, stride_hz: float = 0.9) -> Recording:
    """Pitch A·sin u and roll -B·cos u (a quarter cycle behind), no yaw, u = 2π·f_stride·t,
    with the exact body rates and a bounce at the step rate so that walking is found."""
    from scipy.spatial.transform import Rotation

    rate, seconds = 200.0, 60.0
    t = np.arange(0, seconds, 1 / rate)
    u = 2 * np.pi * stride_hz * t
    pitch, roll = pitch_amp * np.sin(u), -roll_amp * np.cos(u)
    pitch_rate = pitch_amp * 2 * np.pi * stride_hz * np.cos(u)
    roll_rate = roll_amp * 2 * np.pi * stride_hz * np.sin(u)
    rot = Rotation.from_euler("ZYX", np.column_stack([np.zeros_like(t), pitch, roll]))
    gyro = np.column_stack([roll_rate, pitch_rate * np.cos(roll), -pitch_rate * np.sin(roll)])
    lift = np.column_stack([0 * t, 0 * t, 9.81 + 2.0 * np.sin(2 * u)])
    return Recording(
        streams={
            "accel": _frame(t, rot.inv().apply(lift), ["x", "y", "z"]),
            "gyro": _frame(t, gyro, ["x", "y", "z"]),
            "rotation": _frame(t, np.roll(rot.as_quat(), 1, axis=1), ["qw", "qx", "qy", "qz"]),
        },
        meta={},
    )


def test_a_coning_phone_drifts_by_the_closed_form_per_stride():
    # About the mean "down" the phone turns by ∫ -θ' sin φ dt = 2π·A·J1(B) per stride.
    from scipy.special import j1

    s = motion_statistics(_coning(0.3, 0.15))
    assert s["step_hz"] == pytest.approx(1.8, abs=0.01)
    expected = math.degrees(2 * np.pi * 0.3 * j1(0.15))
    assert s["gyro_drift"] == pytest.approx(expected, rel=0.03)
    # The mirror image (the other pocket: roll leads instead of lagging) drifts the other way.
    assert motion_statistics(_coning(0.3, -0.15))["gyro_drift"] == pytest.approx(
        -expected, rel=0.03
    )


def test_a_held_phones_nod_and_bob_shape_at_twice_the_step_rate_in_closed_form():
    """Vertical acceleration 2·cos(ωt) + 0.6·cos(2ωt + 0.5) and a pitch rate of
    0.4·cos(ωt) + 0.3·cos(2ωt + 1.2): 0.5 rad/s per m/s² at the second harmonic, which
    sits 0.5 rad (28.6°) from the fundamental's; a pulse symmetric about its peak
    (all harmonics cosines) reads 0°."""
    f = 1.75
    rec = _sine_walk(f)
    t = rec.accel.index.to_numpy()
    w = 2 * np.pi * f
    rec.accel["z"] = 9.81 + 2 * np.cos(w * t) + 0.6 * np.cos(2 * w * t + 0.5)
    rec.gyro["x"] = 0.4 * np.cos(w * t) + 0.3 * np.cos(2 * w * t + 1.2)
    held = held_phone_motion(rec)
    assert held["nod_2nd"] == pytest.approx(0.5, rel=0.02)
    assert held["bob_phase_2nd"] == pytest.approx(math.degrees(0.5), abs=1.0)
    rec.accel["z"] = 9.81 + 2 * np.cos(w * t) + 0.6 * np.cos(2 * w * t)
    assert held_phone_motion(rec)["bob_phase_2nd"] == pytest.approx(0.0, abs=1.0)


def test_a_held_phones_surge_at_twice_the_step_rate_is_its_amplitude():
    """Forward acceleration 0.3·cos(ωt + 0.4) + 0.45·cos(2ωt − 0.7) on the phone's y axis
    (held flat, top forward) reads 0.3 at the step rate and 0.45 at twice it; against the
    vertical 2·sin(ωt) it leads by 0.4 rad and a quarter cycle."""
    f = 1.75
    rec = _sine_walk(f)
    t = rec.accel.index.to_numpy()
    w = 2 * np.pi * f
    rec.accel["y"] = 0.3 * np.cos(w * t + 0.4) + 0.45 * np.cos(2 * w * t - 0.7)
    held = held_phone_motion(rec)
    assert held["surge_step"] == pytest.approx(0.3, rel=0.03)
    assert held["surge_2nd"] == pytest.approx(0.45, rel=0.03)
    assert held["surge_phase"] == pytest.approx(math.degrees(0.4) + 90.0, abs=1.0)
