"""PDR components by closed forms and invariants: step detection, step length, gyro heading."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import indoorsim
from indoorsim.estimators.frames import heading_from_rotation, to_world, wrap_angle, yaw_rate
from indoorsim.estimators.pdr import (
    STANDARD_GRAVITY,
    GyroHeading,
    PeakStepDetector,
    Step,
    calibrate_k,
    kim,
    scarlet,
    step_lengths,
    weinberg,
)
from indoorsim.simulate import simulate
from indoorsim.walker.gait import WalkerParams

RATE_HZ = 100.0


def sinusoid_walk(
    cadence_hz: float, cycles: int, amplitude: float = 2.0, stand_s: float = 2.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A phone whose |acc| − g is A·sin(2πf(t − t₀)) for ``cycles`` whole cycles between
    two stands: times, (N, 3) accelerations and the true peak times."""
    t = np.arange(0.0, 2 * stand_s + cycles / cadence_hz, 1.0 / RATE_HZ)
    phase = cadence_hz * (t - stand_s)
    a = np.where((phase >= 0) & (phase <= cycles), amplitude * np.sin(2 * np.pi * phase), 0.0)
    acc = np.column_stack([np.zeros_like(t), np.zeros_like(t), STANDARD_GRAVITY + a])
    peaks = stand_s + (np.arange(cycles) + 0.25) / cadence_hz
    return t, acc, peaks


def feed(detector: PeakStepDetector, t: np.ndarray, acc: np.ndarray, sizes: list[int]) -> list:
    """Feed the samples in consecutive pieces of the given sizes (cycled)."""
    steps, i, k = [], 0, 0
    while i < len(t):
        n = sizes[k % len(sizes)]
        steps += detector.update(t[i : i + n], acc[i : i + n])
        i, k = i + n, k + 1
    return steps


def as_array(steps: list[Step]) -> np.ndarray:
    """(N, 5) step fields, for comparisons to rounding."""
    return np.array([[s.t, s.t_valley, s.a_max, s.a_min, s.mean_abs_a] for s in steps])


@pytest.fixture(scope="module")
def corridor() -> indoorsim.Site:
    return indoorsim.load_site("han2023_corridor")


# --- step detection -------------------------------------------------------------------------


def test_sinusoid_counts_every_cycle_once_at_its_peak() -> None:
    t, acc, peaks = sinusoid_walk(1.8, 20)
    steps = PeakStepDetector().update(t, acc)
    assert len(steps) == 20
    t_det = np.array([s.t for s in steps])
    # Every peak is late by the filter's delay: the same one, to within a sample,
    # once the filter has settled into the walk.
    delay = t_det - peaks
    assert np.all((delay > 0.1) & (delay < 0.2))
    assert np.ptp(delay[1:]) <= 1.5 / RATE_HZ
    assert all(s.t < s.t_valley for s in steps)
    # A steady sinusoid: a_max ≈ A, a_min ≈ −A and mean|a| ≈ 2A/π (3 Hz filter gain ≈ 0.99).
    steady = steps[2:-2]
    np.testing.assert_allclose([s.a_max for s in steady], 2.0, rtol=0.02)
    np.testing.assert_allclose([s.a_min for s in steady], -2.0, rtol=0.02)
    np.testing.assert_allclose([s.mean_abs_a for s in steady], 4 / np.pi, rtol=0.03)


def test_streaming_split_gives_the_same_steps() -> None:
    t, acc, _ = sinusoid_walk(1.7, 15)
    whole = as_array(PeakStepDetector().update(t, acc))
    assert len(whole) == 15
    for sizes in ([1], [7, 50, 3], [100], [2, 1]):
        # Chunked filtering and sums differ from one pass only by rounding.
        np.testing.assert_allclose(as_array(feed(PeakStepDetector(), t, acc, sizes)), whole)


def test_reset_forgets_the_previous_walk() -> None:
    t, acc, _ = sinusoid_walk(1.7, 10)
    det = PeakStepDetector()
    first = det.update(t, acc)
    det.reset()
    assert det.update(t, acc) == first


def test_known_rate_equals_estimated_rate() -> None:
    t, acc, _ = sinusoid_walk(1.9, 12)
    np.testing.assert_allclose(
        as_array(PeakStepDetector(rate_hz=RATE_HZ).update(t, acc)),
        as_array(PeakStepDetector().update(t, acc)),
    )


def test_standing_still_and_small_swings_are_not_steps() -> None:
    t, acc, _ = sinusoid_walk(1.8, 10, amplitude=0.2)  # 0.4 m/s² swing < 0.5 threshold
    assert PeakStepDetector().update(t, acc) == []
    assert len(PeakStepDetector(min_amplitude_mps2=0.3).update(t, acc)) == 10


def test_min_interval_drops_the_smaller_of_close_peaks() -> None:
    # 2.5 steps/s: adjacent peaks 0.4 s apart are "false" under Han2023's 0.5 s.
    t, acc, _ = sinusoid_walk(2.5, 20)
    assert len(PeakStepDetector(min_interval_s=0.3).update(t, acc)) == 20
    assert len(PeakStepDetector(min_interval_s=0.5).update(t, acc)) < 20


def test_simulated_handheld_walk_count_within_5_percent(corridor: indoorsim.Site) -> None:
    # On real handheld and swinging walks the detector is off by +0.5 % and -5 %
    # (leaderboards/step_counts_real.md). A 60-step walk's gentle first and last
    # steps, and the slow ones of its sharp turns, may go uncounted: over three
    # walkers 6.5 %, 1.5 % and 1.5 % (seed 1 misses two of a turn's steps).
    errors = []
    for seed in (1, 2, 3):
        rec = simulate(corridor, route="heading_test", mode="handheld", device="ideal", seed=seed)
        t, acc = rec.accel.index.to_numpy(), rec.accel.to_numpy()
        steps = feed(PeakStepDetector(), t, acc, [100])
        errors.append(abs(len(steps) - len(rec.steps)) / len(rec.steps))
    assert np.median(errors) <= 0.05 and max(errors) <= 0.08


def test_fast_cadence_needs_a_shorter_min_interval(corridor: indoorsim.Site) -> None:
    walker = WalkerParams(height_m=1.4, speed_mps=1.575)
    rec = simulate(corridor, route="heading_test", device="ideal", seed=1, walker=walker)
    cadence = 1.0 / np.median(np.diff(rec.steps.index.to_numpy()))
    assert 2.3 < cadence < 2.7  # the premise: a 2.5 Hz walk
    t, acc = rec.accel.index.to_numpy(), rec.accel.to_numpy()
    n_true = len(rec.steps)
    assert len(PeakStepDetector(min_interval_s=0.5).update(t, acc)) < 0.8 * n_true
    assert abs(len(PeakStepDetector(min_interval_s=0.3).update(t, acc)) - n_true) <= 0.03 * n_true


def test_detector_validates_its_parameters() -> None:
    with pytest.raises(ValueError, match="rate_hz"):
        PeakStepDetector(rate_hz=5.0)
    with pytest.raises(ValueError, match="cutoff_hz"):
        PeakStepDetector(cutoff_hz=0.0)
    with pytest.raises(ValueError, match="3 times but 2"):
        PeakStepDetector().update(np.arange(3.0), np.zeros((2, 3)))


# --- step length ----------------------------------------------------------------------------


def test_length_models_closed_forms() -> None:
    assert weinberg(2.0, -14.0, k=0.5) == pytest.approx(0.5 * 16**0.25)
    assert kim(8.0, k=0.3) == pytest.approx(0.3 * 2.0)
    assert scarlet(2.0, -2.0, 1.0, k=0.8) == pytest.approx(0.8 * 3.0 / 4.0)
    np.testing.assert_allclose(weinberg([1.0, 3.0], [-1.0, -13.0], k=1.0), [2**0.25, 2.0])
    assert weinberg(1.0, 2.0) == 0.0  # no swing, no length
    assert scarlet(1.0, 1.0, 1.0, k=1.0) == 0.0


def random_steps(n: int, seed: int = 0) -> list[Step]:
    rng = np.random.default_rng(seed)
    a_max = rng.uniform(1.0, 3.0, n)
    a_min = -rng.uniform(1.0, 3.0, n)
    return [
        Step(t=float(k), t_valley=k + 0.3, a_max=hi, a_min=lo, mean_abs_a=rng.uniform(0.5, 2.0))
        for k, (hi, lo) in enumerate(zip(a_max, a_min, strict=True))
    ]


def test_step_lengths_apply_the_models() -> None:
    steps = random_steps(5)
    a_max = np.array([s.a_max for s in steps])
    a_min = np.array([s.a_min for s in steps])
    mean = np.array([s.mean_abs_a for s in steps])
    np.testing.assert_allclose(step_lengths(steps, 0.5), weinberg(a_max, a_min, 0.5))
    np.testing.assert_allclose(step_lengths(steps, 0.6, "kim"), kim(mean, 0.6))
    np.testing.assert_allclose(
        step_lengths(steps, 0.7, "scarlet"), scarlet(a_max, a_min, mean, 0.7)
    )
    with pytest.raises(KeyError, match="weinberg"):
        step_lengths(steps, 0.5, "unknown")


@pytest.mark.parametrize("model", ["weinberg", "kim", "scarlet"])
def test_calibrate_k_recovers_k_from_noise_free_lengths(model: str) -> None:
    steps = random_steps(30)
    truth = step_lengths(steps, 0.4321, model)
    assert calibrate_k(steps, truth, model) == pytest.approx(0.4321, rel=1e-12)


def test_calibrate_k_rejects_mismatched_input() -> None:
    with pytest.raises(ValueError, match="3 steps but 2"):
        calibrate_k(random_steps(3), [0.6, 0.6])


# --- heading --------------------------------------------------------------------------------


def test_gyro_heading_integrates_constant_and_linear_rates_exactly() -> None:
    rng = np.random.default_rng(1)
    t = np.cumsum(rng.uniform(0.005, 0.02, 400))  # irregular sampling
    up = np.tile([0.0, 0.0, 9.81], (len(t), 1))
    for rate in (0.3 + 0 * t, 0.2 + 0.05 * (t - t[0])):
        gyro = np.column_stack([np.zeros_like(t), np.zeros_like(t), rate])
        est = GyroHeading()
        est.reset(1.0)
        h = np.concatenate(
            [est.update(t[:137], gyro[:137], up[:137]), est.update(t[137:], gyro[137:], up[137:])]
        )
        dt = t - t[0]
        expected = 1.0 + rate[0] * dt + 0.5 * (rate[-1] - rate[0]) / dt[-1] * dt**2
        np.testing.assert_allclose(h, expected, atol=1e-12)
        assert est.heading == pytest.approx(expected[-1])
        assert est.at(t[-50]) == pytest.approx(expected[-50])


def test_tilting_the_phone_keeps_the_yaw_rate_about_gravity() -> None:
    rng = np.random.default_rng(2)
    omega_world = rng.normal(size=(50, 3))
    up_world = np.array([0.0, 0.0, 9.81])
    flat = yaw_rate(omega_world, np.tile(up_world, (50, 1)))
    np.testing.assert_allclose(flat, omega_world[:, 2])
    for tilt in Rotation.random(5, random_state=3):
        phone = tilt.inv()  # the same motion seen by a tilted phone
        rates = yaw_rate(phone.apply(omega_world), np.tile(phone.apply(up_world), (50, 1)))
        np.testing.assert_allclose(rates, flat, atol=1e-12)
        # The phone's own z axis is not the vertical: integrating it would be wrong.
        assert not np.allclose(phone.apply(omega_world)[:, 2], flat)


def test_yaw_rate_without_gravity_is_zero() -> None:
    assert yaw_rate([[0.0, 0.0, 1.0]], [[0.0, 0.0, 0.0]]).tolist() == [0.0]


def test_gyro_heading_needs_a_start() -> None:
    with pytest.raises(RuntimeError, match="reset"):
        GyroHeading().update([0.0], [[0.0, 0.0, 0.0]], [[0.0, 0.0, 9.8]])


# --- frames ---------------------------------------------------------------------------------


def test_heading_from_rotation_of_a_flat_phone() -> None:
    # Identity: the phone's top (+y) points to magnetic north, 90° from magnetic east.
    yaw = np.array([0.0, 0.5, -2.0])
    q = Rotation.from_euler("z", yaw[:, None]).as_quat(scalar_first=True)
    offset = 0.3
    np.testing.assert_allclose(
        heading_from_rotation(q, offset), wrap_angle(np.pi / 2 + yaw + offset), atol=1e-12
    )


def test_to_world_normalises_and_treats_zero_as_identity() -> None:
    q = Rotation.from_euler("z", 90, degrees=True).as_quat(scalar_first=True)
    np.testing.assert_allclose(to_world([2 * q], [[1.0, 0.0, 0.0]]), [[0.0, 1.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(to_world([[0.0, 0, 0, 0]], [[1.0, 2.0, 3.0]]), [[1.0, 2.0, 3.0]])
