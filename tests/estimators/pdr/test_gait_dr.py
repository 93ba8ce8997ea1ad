"""Chen2022 gait-based DR: step-length closed forms, the bounce's excursion, streaming, walks."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import indoorsim
from indoorsim.estimators.pdr.gait import (
    GaitDeadReckoning,
    GaitStep,
    pendulum_step_length,
    vertical_acceleration,
)
from indoorsim.io.recording import Recording
from indoorsim.simulate import simulate

G = 9.81
RATE_HZ = 100.0


@pytest.fixture(scope="module")
def corridor() -> indoorsim.Site:
    return indoorsim.load_site("han2023_corridor")


@pytest.fixture(scope="module")
def lab() -> indoorsim.Site:
    return indoorsim.load_site("chen2022_lab")


def streams(rec: Recording) -> tuple[np.ndarray, ...]:
    """t, accel, gyro and fused gravity of a recording at the accelerometer's times."""
    index = rec.accel.index
    gyro = rec.gyro.reindex(index, method="ffill").fillna(0.0).to_numpy()
    gravity = rec.gravity.reindex(index, method="ffill").fillna(0.0).to_numpy()
    return index.to_numpy(), rec.accel.to_numpy(), gyro, gravity


def feed(dr: GaitDeadReckoning, arrays: tuple, sizes: list[int]) -> list[GaitStep]:
    """Feed (t, accel, gyro, gravity) in consecutive pieces of the given sizes (cycled)."""
    t, accel, gyro, gravity = arrays
    steps, i, k = [], 0, 0
    while i < len(t):
        n = sizes[k % len(sizes)]
        sl = slice(i, i + n)
        steps += dr.update(
            t[sl],
            accel[sl],
            None if gyro is None else gyro[sl],
            None if gravity is None else gravity[sl],
        )
        i, k = i + n, k + 1
    return steps


def as_array(steps: list[GaitStep]) -> np.ndarray:
    return np.array([dataclasses.astuple(s) for s in steps])


def bouncing_phone(
    amplitude_m: float, cadence_hz: float, cycles: int, tilt: Rotation, stand_s: float = 3.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A tilted, non-rotating phone between two stands whose height is s(τ)·A·(1 − cos 2πfτ):
    ``cycles`` whole cycles, the first and last faded in and out by a smootherstep s, so
    that height, velocity and acceleration are continuous. Returns t, accel, gravity."""
    t = np.arange(0.0, 2 * stand_s + cycles / cadence_hz, 1.0 / RATE_HZ)
    duration, ramp = cycles / cadence_hz, 1.0 / cadence_hz
    tau = np.clip(t - stand_s, 0.0, duration)
    # The envelope rises over the first cycle and falls over the last: s(u) = 6u⁵ − 15u⁴ + 10u³.
    u = np.clip(np.minimum(tau, duration - tau) / ramp, 0.0, 1.0)
    sign = np.where(tau < duration / 2, 1.0, -1.0)
    env = 6 * u**5 - 15 * u**4 + 10 * u**3
    env_d = sign * (30 * u**4 - 60 * u**3 + 30 * u**2) / ramp
    env_dd = (120 * u**3 - 180 * u**2 + 60 * u) / ramp**2
    omega = 2 * np.pi * cadence_hz
    wave = 1 - np.cos(omega * tau)
    wave_d, wave_dd = omega * np.sin(omega * tau), omega**2 * np.cos(omega * tau)
    a_up = amplitude_m * (env_dd * wave + 2 * env_d * wave_d + env * wave_dd)
    a_up[(t < stand_s) | (t > stand_s + duration)] = 0.0
    world = np.column_stack([np.zeros_like(t), np.zeros_like(t), G + a_up])
    phone = tilt.inv()
    gravity = np.tile(phone.apply([0.0, 0.0, G]), (len(t), 1))
    return t, phone.apply(world), gravity


# --- closed forms -----------------------------------------------------------------------------


def test_pendulum_step_length_closed_form() -> None:
    # D = 2√(L² − (L − S)²) = 2√(2LS − S²): L = 1.25, S = 0.05 gives 2√0.1225 = 0.7.
    assert pendulum_step_length(0.05, 1.25) == pytest.approx(0.7, abs=1e-12)
    s = np.array([0.0, 0.02, 0.04, 0.3])
    np.testing.assert_allclose(pendulum_step_length(s, 0.9), 2 * np.sqrt(2 * 0.9 * s - s**2))
    # Outside [0, L] the excursion is clipped: no step, or the pendulum's widest.
    np.testing.assert_allclose(pendulum_step_length([-0.01, 2.0], 1.2), [0.0, 2.4])


def test_vertical_acceleration_is_independent_of_the_phone_tilt() -> None:
    rng = np.random.default_rng(0)
    world = np.column_stack([rng.normal(0, 2, 50), rng.normal(0, 2, 50), G + rng.normal(0, 2, 50)])
    for tilt in Rotation.random(4, random_state=1):
        phone = tilt.inv()
        up = np.tile(phone.apply([0.0, 0.0, G]), (50, 1))
        np.testing.assert_allclose(vertical_acceleration(phone.apply(world), up), world[:, 2] - G)


# --- the vertical excursion through the EKF ------------------------------------------------------


def test_sinusoidal_bounce_gives_its_peak_to_trough_excursion() -> None:
    amplitude, cadence, cycles = 0.02, 1.8, 20
    tilt = Rotation.from_euler("xy", [35.0, -10.0], degrees=True)
    t, acc, gravity = bouncing_phone(amplitude, cadence, cycles, tilt)
    for use_stream in (True, False):
        dr = GaitDeadReckoning(use_gravity_stream=use_stream, pendulum_length=1.2)
        steps = dr.update(t, acc, None, gravity)
        # One trough per cycle, each ending a step (the first opens the bout);
        # the faded first and last cycles may fall short of the threshold.
        assert cycles - 2 <= len(steps) == dr.step_count <= cycles
        # Once the level pseudo-measurement has settled on the walk's mean
        # height (A above the stand's), and before the fade-out, the excursion
        # is the peak-to-trough 2A.
        settled = [s for s in steps if 3.0 + 5.0 < s.t < 3.0 + (cycles - 1) / cadence]
        s_vd = np.array([s.vertical_displacement for s in settled])
        assert len(s_vd) >= 10
        np.testing.assert_allclose(s_vd, 2 * amplitude, rtol=0.03)
        np.testing.assert_allclose(
            [s.length for s in settled], pendulum_step_length(s_vd, 1.2), rtol=1e-12
        )
        np.testing.assert_allclose(np.diff([s.t for s in settled]), 1 / cadence, atol=1.5 / RATE_HZ)


# --- the streaming facade -----------------------------------------------------------------------


def test_chunk_split_invariance(corridor: indoorsim.Site) -> None:
    rec = simulate(corridor, route="heading_test", mode="pocketed", device="nexus_5x", seed=5)
    arrays = streams(rec)
    start = float(rec.truth["heading"].iloc[0])
    dr = GaitDeadReckoning()
    dr.reset(start)
    whole = as_array(feed(dr, arrays, [len(arrays[0])]))
    assert len(whole) > 40
    for sizes in ([1], [7, 50, 3], [100], [16, 1]):
        dr.reset(start)
        np.testing.assert_allclose(as_array(feed(dr, arrays, sizes)), whole, rtol=0, atol=1e-12)
    assert dr.step_count == len(whole)


def test_without_a_gyro_the_heading_stays_at_the_start() -> None:
    t, acc, gravity = bouncing_phone(0.02, 1.8, 10, Rotation.identity())
    dr = GaitDeadReckoning()
    dr.reset(1.234)
    steps = dr.update(t, acc, None, gravity)
    assert len(steps) >= 8
    assert all(s.heading == 1.234 and s.delta_heading == 0.0 for s in steps)
    assert dr.heading == 1.234


def test_facade_heading_follows_a_turn() -> None:
    # The bouncing phone turns at 0.2 rad/s about the vertical from the 5th second.
    t, acc, gravity = bouncing_phone(0.02, 1.8, 20, Rotation.identity())
    rate = np.where(t >= 5.0, 0.2, 0.0)
    gyro = np.column_stack([np.zeros_like(t), np.zeros_like(t), rate])
    dr = GaitDeadReckoning()
    dr.reset(-0.5)
    steps = dr.update(t, acc, gyro, gravity)
    turned = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t))])
    assert dr.heading == pytest.approx(-0.5 + turned[-1], abs=1e-9)
    np.testing.assert_allclose(
        np.cumsum([s.delta_heading for s in steps]), np.array([s.heading for s in steps]) + 0.5
    )
    # Each step's heading is the mean over its span: between its ends' headings.
    for before, s in itertools.pairwise(steps):
        assert -0.5 + np.interp(before.t, t, turned) - 1e-9 <= s.heading
        assert s.heading <= -0.5 + np.interp(s.t, t, turned) + 1e-9


def test_reset_forgets_the_walk() -> None:
    t, acc, gravity = bouncing_phone(0.02, 1.8, 8, Rotation.identity())
    dr = GaitDeadReckoning()
    first = as_array(dr.update(t, acc, None, gravity))
    dr.reset(0.0)
    np.testing.assert_array_equal(as_array(dr.update(t, acc, None, gravity)), first)
    assert dr.step_count == len(first)


def test_calibrate_recovers_the_length_scale() -> None:
    s_vd = np.linspace(0.01, 0.05, 12)
    steps = [
        GaitStep(t=float(i), length=0.0, heading=0.0, delta_heading=0.0, vertical_displacement=s)
        for i, s in enumerate(s_vd)
    ]
    dr = GaitDeadReckoning(pendulum_length=1.1, length_scale=0.5)
    truth = 1.37 * pendulum_step_length(s_vd, 1.1)
    assert dr.calibrate(steps, truth) == pytest.approx(1.37, rel=1e-12)
    assert dr.length_scale == pytest.approx(1.37, rel=1e-12)
    with pytest.raises(ValueError, match="12 steps but 2"):
        dr.calibrate(steps, [0.6, 0.6])
    with pytest.raises(ValueError, match="S_VD = 0"):
        dr.calibrate([dataclasses.replace(steps[0], vertical_displacement=0.0)], [0.6])


# --- simulated walks ---------------------------------------------------------------------------


@pytest.mark.parametrize(("site_name", "route"), [("corridor", "trajectory"), ("lab", "walk")])
@pytest.mark.parametrize("seed", [1, 2])
def test_handheld_step_counts_within_5_percent(
    site_name: str, route: str, seed: int, request: pytest.FixtureRequest
) -> None:
    site = request.getfixturevalue(site_name)
    rec = simulate(site, route=route, mode="handheld", device="ideal", seed=seed)
    dr = GaitDeadReckoning()
    dr.reset(float(rec.truth["heading"].iloc[0]))
    steps = feed(dr, streams(rec), [100])
    assert abs(len(steps) - len(rec.steps)) <= 0.05 * len(rec.steps)


def test_calibrated_handheld_lengths_match_on_another_walk(corridor: indoorsim.Site) -> None:
    def walk(seed: int) -> tuple[list[GaitStep], np.ndarray]:
        rec = simulate(corridor, route="trajectory", mode="handheld", device="ideal", seed=seed)
        steps = feed(GaitDeadReckoning(), streams(rec), [250])
        true_t = rec.steps.index.to_numpy()
        nearest = np.abs(np.subtract.outer([s.t for s in steps], true_t)).argmin(axis=1)
        return steps, rec.steps["length"].to_numpy()[nearest]

    train, test = walk(3), walk(4)
    dr = GaitDeadReckoning()
    scale = dr.calibrate(*train)
    # The hand rides the trunk's bounce (and its heel-strike jolts) close to one to one,
    # so the inverted pendulum of L = 1.2 m needs little scaling either way.
    assert 0.8 < scale < 1.25
    s_vd = [s.vertical_displacement for s in test[0]]
    lengths = scale * pendulum_step_length(s_vd, dr.pendulum_length)
    assert lengths.sum() == pytest.approx(test[1].sum(), rel=0.03)


@pytest.mark.parametrize("mode", ["handheld", "calling", "dangling", "pocketed"])
def test_nexus_walks_in_every_mode_stay_in_a_loose_band(
    corridor: indoorsim.Site, mode: str
) -> None:
    rec = simulate(corridor, route="heading_test", mode=mode, device="nexus_5x", seed=1)
    dr = GaitDeadReckoning()
    dr.reset(float(rec.truth["heading"].iloc[0]))
    steps = feed(dr, streams(rec), [50])
    n_true = len(rec.steps)
    assert 0.7 * n_true <= len(steps) <= 1.3 * n_true
    lengths = np.array([s.length for s in steps])
    assert np.all(np.isfinite(lengths)) and 0.2 < lengths.mean() < 1.2
    assert np.isfinite(dr.heading)


# --- parameters ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("factory", "name"),
    [
        (lambda: GaitDeadReckoning(pendulum_length=0.0), "pendulum_length"),
        (lambda: GaitDeadReckoning(length_scale=-1.0), "length_scale"),
        (lambda: GaitDeadReckoning(trough_threshold_mps2=-0.1), "trough_threshold_mps2"),
        (lambda: GaitDeadReckoning(min_step_s=0.6, max_step_s=0.5), "max_step_s"),
        (lambda: GaitDeadReckoning(gravity_cutoff_hz=np.nan), "gravity_cutoff_hz"),
        (lambda: GaitDeadReckoning(gravity_cutoff_hz=4.0), "gravity_cutoff_hz"),
        (lambda: GaitDeadReckoning(rate_hz=5.0), "rate_hz"),
        (lambda: pendulum_step_length(0.05, -1.0), "pendulum_length"),
    ],
)
def test_rejects_bad_parameters(factory, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        factory()


def test_rejects_bad_input() -> None:
    dr = GaitDeadReckoning()
    with pytest.raises(ValueError, match="heading"):
        dr.reset(np.nan)
    with pytest.raises(ValueError, match="3 times but 2"):
        dr.update(np.arange(3.0), np.zeros((2, 3)), None)
    with pytest.raises(ValueError, match="gyro"):
        dr.update(np.arange(3.0), np.zeros((3, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="rate_hz"):  # 4 Hz sampling for a 3 Hz low-pass
        dr.update(np.arange(20) * 0.25, np.tile([0.0, 0.0, G], (20, 1)), None)


def test_the_components_still_import_from_the_gait_module() -> None:
    from indoorsim.estimators.pdr import attitude, gait, zupt

    assert gait.QuaternionAttitude is attitude.QuaternionAttitude
    assert (gait.dcm, gait.euler_angles) == (attitude.dcm, attitude.euler_angles)
    assert gait.StationaryDetector is zupt.StationaryDetector
    assert gait.VerticalZuptEKF is zupt.VerticalZuptEKF
