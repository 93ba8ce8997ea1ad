"""Sensor error models, tested by their invariants and closed forms.

Statistical checks use records long enough that the tolerances sit several
standard errors away from the expected value, whatever the seed.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.phone.devices import (
    DEVICES,
    InertialSpec,
    LightSensorSpec,
    MagnetometerSpec,
    WifiSpec,
    get_device,
)
from indoorsim.phone.sensors import (
    THROTTLE_MAX_SCANS,
    THROTTLE_WINDOW_S,
    InertialErrors,
    MagnetometerErrors,
    apply_inertial,
    apply_magnetometer,
    light_events,
    sample_times,
    scan_rss,
    wifi_scans,
)

IDEAL = get_device("ideal")


def rng(seed: int = 0) -> np.random.Generator:
    return np.random.default_rng(seed)


def overlapping_adev(y: np.ndarray, rate_hz: float, taus_s: np.ndarray) -> np.ndarray:
    """Overlapping Allan deviation of rate samples ``y`` (K,) or (K, 3) at uniform ``rate_hz``.

    σ²(τ) = Σ_k (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2τ²(K + 1 − 2m)), θ the integrated
    signal and m = τ·rate (IEEE Std 952 / 1554).
    """
    theta = np.concatenate([np.zeros((1, *y.shape[1:])), np.cumsum(y, axis=0)]) / rate_hz
    out = []
    for tau in taus_s:
        m = round(tau * rate_hz)
        d = theta[2 * m :] - 2 * theta[m:-m] + theta[: -2 * m]
        out.append(np.sqrt(np.mean(d**2, axis=0) / (2 * (m / rate_hz) ** 2)))
    return np.array(out)


def gauss_markov_adev(tau: np.ndarray, sigma: float, tc: float) -> np.ndarray:
    """Closed-form Allan deviation of a first-order Gauss–Markov process.

    σ²_A(τ) = (2σ²T_c/τ)·[1 − (T_c/2τ)·(3 − 4e^{−τ/T_c} + e^{−2τ/T_c})]
    (Xing & Gebre-Egziabher 2008; q_c T_c² = 2σ²T_c). It rises as a rate random
    walk (2σ²τ/3T_c) for τ ≪ T_c, falls as white noise for τ ≫ T_c, and peaks
    at 0.6174·σ for τ = 1.8926·T_c.
    """
    u = tau / tc
    return sigma * np.sqrt((2 / u) * (1 - (3 - 4 * np.exp(-u) + np.exp(-2 * u)) / (2 * u)))


# --------------------------------------------------------------------------- timing


def test_sample_times_without_jitter_are_the_nominal_grid() -> None:
    t = sample_times(2.0, 50.0, 0.0, rng(), start=3.0)
    np.testing.assert_allclose(t, 3.0 + np.arange(100) / 50.0, rtol=0, atol=1e-12)
    assert sample_times(1.1, 100.0, 0.0, rng()).size == 110  # 1.1·100 is 110.00000000000001


def test_jitter_sets_the_spread_of_the_intervals() -> None:
    rate, jitter = 100.0, 0.02
    t = sample_times(600.0, rate, jitter, rng(), start=1.0)
    dt = np.diff(t)
    assert t[0] == 1.0 and np.all(dt > 0)
    assert np.std(dt) * rate == pytest.approx(jitter, rel=0.03)
    assert np.mean(dt) * rate == pytest.approx(1.0, abs=1e-6)  # a steady clock, not a drifting one


def test_gaps_drop_runs_of_one_to_three_samples() -> None:
    rate, p = 100.0, 0.005
    t = sample_times(1000.0, rate, 0.01, rng(), gap_probability=p)
    steps = np.rint(np.diff(t) * rate).astype(int)
    assert set(np.unique(steps)) <= {1, 2, 3, 4, 5, 6, 7}  # longer only where gaps overlap
    counts = np.array([np.sum(steps == k) for k in (2, 3, 4)])
    assert counts.sum() == pytest.approx(p * 100_000, rel=0.2)
    np.testing.assert_allclose(counts / counts.sum(), 1 / 3, atol=0.08)
    assert t.size == pytest.approx(100_000 * (1 - 2 * p), rel=0.003)
    assert sample_times(1000.0, rate, 0.01, rng(), gap_probability=0.0).size == 100_000


def test_sample_times_rejects_bad_arguments() -> None:
    with pytest.raises(ValueError, match="jitter_frac"):
        sample_times(1.0, 100.0, 0.5, rng())
    with pytest.raises(ValueError, match="gap_probability"):
        sample_times(1.0, 100.0, 0.0, rng(), gap_probability=1.0)
    with pytest.raises(ValueError, match="rate_hz"):
        sample_times(1.0, 0.0, 0.0, rng())


# --------------------------------------------------------------------------- ideal


def test_ideal_profile_leaves_every_signal_bit_identical() -> None:
    r = rng(3)
    t = sample_times(5.0, 100.0, 0.0, r)
    x = r.normal(0, 5, (t.size, 3))
    x[0] = [-0.0, 1e300, -1e-300]  # signed zero and extremes survive untouched
    for out in (
        apply_inertial(x, t, IDEAL.accel, r),
        apply_inertial(x, t, IDEAL.gyro, r),
        apply_magnetometer(x, t, IDEAL.mag, r),
    ):
        assert out.dtype == np.float64 and out.tobytes() == x.tobytes()
        assert out is not x
    lux = np.abs(x[:, 0]) + 3.0
    t_ev, lux_ev = light_events(t, lux, IDEAL.light, r)
    assert t_ev.tobytes() == t.tobytes() and lux_ev.tobytes() == lux.tobytes()
    scans = wifi_scans(60.0, IDEAL.wifi, r)
    np.testing.assert_array_equal(scans, np.arange(0.0, 60.0, IDEAL.wifi.scan_interval_s))
    mean = r.uniform(-120, -20, (scans.size, 4))
    table = scan_rss(scans, mean, ["a", "b", "c", "d"], IDEAL.wifi, r)
    assert len(table) == mean.size
    assert table["rss"].to_numpy().tobytes() == mean.ravel().tobytes()


# --------------------------------------------------------------------------- inertial


def test_still_sensor_reads_its_turn_on_bias() -> None:
    spec = get_device("vivo_s9").gyro
    duration = 60.0
    t = sample_times(duration, spec.rate_hz, 0.015, rng())
    errors = InertialErrors.draw(spec, rng(1))
    y = apply_inertial(np.zeros((t.size, 3)), t, spec, rng(2), errors=errors)
    # What else moves the mean: bias instability, random walk, white noise, one LSB.
    spread = math.sqrt(
        spec.bias_instability**2
        + spec.random_walk**2 * duration / 3
        + spec.noise_density**2 / duration
        + spec.resolution**2 / 12
    )
    np.testing.assert_allclose(y.mean(axis=0), errors.turn_on_bias, atol=5 * spread)


def test_turn_on_bias_varies_between_runs_with_its_sigma() -> None:
    spec = InertialSpec(rate_hz=100.0, turn_on_bias_sigma=0.05, noise_density=1e-3)
    t = np.arange(100) / 100.0
    means = np.array(
        [apply_inertial(np.zeros((100, 3)), t, spec, rng(seed)).mean(axis=0) for seed in range(400)]
    )
    assert np.std(means) == pytest.approx(0.05, rel=0.08)
    assert np.abs(np.mean(means)) < 4 * 0.05 / math.sqrt(means.size)


def test_white_noise_reproduces_the_noise_density() -> None:
    density, rate = 0.01, 100.0
    t = np.arange(60_000) / rate
    y = apply_inertial(
        np.zeros((t.size, 3)), t, InertialSpec(rate_hz=rate, noise_density=density), rng()
    )
    assert np.std(y) == pytest.approx(density * math.sqrt(rate), rel=0.02)
    adev = overlapping_adev(y, rate, np.array([0.1, 1.0, 10.0])).mean(axis=1)
    np.testing.assert_allclose(adev * np.sqrt([0.1, 1.0, 10.0]), density, rtol=0.1)


def test_white_noise_integrates_to_its_random_walk_despite_jitter_and_gaps() -> None:
    """σ_k = N/√Δt_k: the Δt-weighted sum over T seconds has σ = N·√T whatever the spacing."""
    density, rate, duration = 0.01, 100.0, 10.0
    spec = InertialSpec(rate_hz=rate, noise_density=density)
    angles = []
    for seed in range(200):
        r = rng(seed)
        t = sample_times(duration, rate, 0.15, r, gap_probability=0.05)
        y = apply_inertial(np.zeros((t.size, 3)), t, spec, r)
        angles.append(np.sum(y * np.diff(t, prepend=t[0] - 1 / rate)[:, None], axis=0))
    assert np.std(angles) == pytest.approx(density * math.sqrt(duration), rel=0.08)


@pytest.fixture(scope="module")
def two_hours() -> tuple[np.ndarray, np.ndarray]:
    """Times and a zero (still) signal: 2 h at 100 Hz."""
    t = np.arange(720_000) / 100.0
    return t, np.zeros((t.size, 3))


def test_allan_deviation_shows_the_gauss_markov_bias_instability(two_hours) -> None:
    t, still = two_hours
    sigma, tc, density = 0.01, 10.0, 1e-3
    spec = InertialSpec(
        rate_hz=100.0, noise_density=density, bias_instability=sigma, bias_correlation_s=tc
    )
    y = apply_inertial(still, t, spec, rng(11))
    taus = np.array([5.0, 10.0, 1.8926 * tc, 40.0])
    adev = overlapping_adev(y, 100.0, taus).mean(axis=1)
    expected = np.sqrt(gauss_markov_adev(taus, sigma, tc) ** 2 + density**2 / taus)
    np.testing.assert_allclose(adev, expected, rtol=0.15)
    # The white part is 2.3 % of the peak here, so the peak is the Gauss–Markov one.
    assert adev[2] == pytest.approx(0.6174 * sigma, rel=0.1)
    assert np.argmax(adev) == 2
    # Its stationary σ is the configured one.
    assert np.std(y) == pytest.approx(math.sqrt(sigma**2 + density**2 * 100), rel=0.1)


def test_allan_deviation_of_the_rate_random_walk_rises_with_slope_one_half(two_hours) -> None:
    t, still = two_hours
    k = 1e-4
    y = apply_inertial(still, t, InertialSpec(rate_hz=100.0, random_walk=k), rng(12))
    taus = np.array([10.0, 20.0, 50.0, 100.0, 200.0])
    adev = overlapping_adev(y, 100.0, taus).mean(axis=1)
    slope = np.polyfit(np.log(taus), np.log(adev), 1)[0]
    assert slope == pytest.approx(0.5, abs=0.1)
    assert adev[1] == pytest.approx(k * math.sqrt(20.0 / 3), rel=0.15)
    assert np.all(y[0] == 0)  # the walk starts at zero; the turn-on bias holds the offset


def test_scale_factor_and_misalignment_on_a_known_input() -> None:
    scale = np.array([0.01, -0.02, 0.005])
    misalignment = np.array([[0.0, 0.001, -0.002], [0.003, 0.0, 0.0], [0.0, -0.004, 0.0]])
    errors = InertialErrors(turn_on_bias=np.zeros(3), scale_factor=scale, misalignment=misalignment)
    t = np.arange(3) / 100.0
    x = np.array([[9.81, 0.0, 0.0], [0.0, 9.81, 0.0], [0.0, 0.0, 9.81]])
    y = apply_inertial(x, t, InertialSpec(), rng(), errors=errors)
    # Column j of y is the response to a pure input on axis j: 9.81·(I + S + M)[:, j].
    np.testing.assert_allclose(y.T, 9.81 * (np.eye(3) + np.diag(scale) + misalignment), rtol=1e-14)


def test_drawn_axis_errors_have_the_specified_spread() -> None:
    spec = InertialSpec(
        scale_factor_sigma=0.01, misalignment_sigma_rad=0.002, turn_on_bias_sigma=0.3
    )
    draws = [InertialErrors.draw(spec, rng(seed)) for seed in range(2000)]
    scale = np.array([e.scale_factor for e in draws])
    mis = np.array([e.misalignment for e in draws])
    bias = np.array([e.turn_on_bias for e in draws])
    assert np.std(scale) == pytest.approx(0.01, rel=0.05)
    assert np.std(bias) == pytest.approx(0.3, rel=0.05)
    assert np.all(mis[:, [0, 1, 2], [0, 1, 2]] == 0)
    assert np.std(mis[:, ~np.eye(3, dtype=bool)]) == pytest.approx(0.002, rel=0.05)


def test_inertial_errors_reject_a_misalignment_with_a_diagonal() -> None:
    with pytest.raises(ValueError, match="zero diagonal"):
        InertialErrors(turn_on_bias=np.zeros(3), scale_factor=np.zeros(3), misalignment=np.eye(3))


def test_quantisation_and_saturation() -> None:
    lsb, limit = 0.01, 1.0
    spec = InertialSpec(range=limit, resolution=lsb)
    x = np.linspace(-2.0, 2.0, 3001)[:, None] * np.array([1.0, 0.5, -0.3])
    t = np.arange(x.shape[0]) / 100.0
    y = apply_inertial(x, t, spec, rng())
    np.testing.assert_allclose(y / lsb, np.round(y / lsb), atol=1e-9)
    assert np.max(np.abs(y - np.clip(x, -limit, limit))) <= lsb / 2 + 1e-12
    assert y.max() == limit and y.min() == -limit
    np.testing.assert_array_equal(y[np.abs(x) >= limit], np.sign(x[np.abs(x) >= limit]) * limit)


def test_inertial_input_checks() -> None:
    with pytest.raises(ValueError, match="strictly increasing"):
        apply_inertial(np.zeros((3, 3)), [0.0, 0.0, 0.1], InertialSpec(), rng())
    with pytest.raises(ValueError, match=r"\(K, 3\)"):
        apply_inertial(np.zeros((3, 2)), [0.0, 0.1, 0.2], InertialSpec(), rng())
    assert apply_inertial(np.zeros((0, 3)), [], get_device("mid_grade").gyro, rng()).shape == (0, 3)


# --------------------------------------------------------------------------- magnetometer


def test_magnetometer_applies_soft_and_hard_iron() -> None:
    soft = np.array([[0.01, 0.002, 0.0], [0.002, -0.01, 0.003], [0.0, 0.003, 0.02]])
    hard = np.array([1.0, -2.0, 0.5])
    errors = MagnetometerErrors(hard_iron_uT=hard, soft_iron=soft)
    b = np.array([[30.0, -5.0, -40.0], [0.0, 32.0, 39.0]])
    y = apply_magnetometer(b, [0.0, 0.02], MagnetometerSpec(), rng(), errors=errors)
    np.testing.assert_allclose(y, b @ (np.eye(3) + soft).T + hard, rtol=1e-14)
    with pytest.raises(ValueError, match="symmetric"):
        MagnetometerErrors(hard_iron_uT=hard, soft_iron=np.triu(soft))


def test_magnetometer_noise_quantisation_saturation_and_drawn_residuals() -> None:
    spec = get_device("vivo_s9").mag
    t = np.arange(20_000) / spec.rate_hz
    b = np.tile([20.0, 30.0, -40.0], (t.size, 1))
    errors = MagnetometerErrors.draw(spec, rng(5))
    assert np.array_equal(errors.soft_iron, errors.soft_iron.T)
    y = apply_magnetometer(b, t, spec, rng(6), errors=errors)
    np.testing.assert_allclose(y / spec.resolution_uT, np.round(y / spec.resolution_uT), atol=1e-9)
    np.testing.assert_allclose(
        y.mean(axis=0), b[0] @ (np.eye(3) + errors.soft_iron).T + errors.hard_iron_uT, atol=0.02
    )
    assert np.std(y - y.mean(axis=0)) == pytest.approx(
        math.sqrt(spec.noise_sigma_uT**2 + spec.resolution_uT**2 / 12), rel=0.03
    )
    huge = apply_magnetometer(np.full((2, 3), 1e4), [0.0, 0.02], spec, rng())
    np.testing.assert_allclose(huge, spec.range_uT, atol=spec.resolution_uT / 2)


# --------------------------------------------------------------------------- light


def _step_lux(step_at: float = 1.05, before: float = 100.0, after: float = 300.0):
    """A 1 ms illuminance record stepping from ``before`` to ``after`` at ``step_at`` (on the grid).

    The sample at the step carries the mid value, so the trapezoidal integral of
    the record equals that of a sharp step.
    """
    t = np.arange(0.0, 3.0 + 1e-9, 0.001)
    lux = np.where(t < step_at, before, after)
    lux[np.argmin(np.abs(t - step_at))] = (before + after) / 2
    return t, lux


def test_light_sensor_averages_over_its_integration_time() -> None:
    t, lux = _step_lux()
    spec = LightSensorSpec(integration_time_s=0.1)  # every conversion reported, no noise
    t_ev, lux_ev = light_events(t, lux, spec, rng())
    np.testing.assert_allclose(t_ev, 0.1 * np.arange(1, 31), atol=1e-12)
    np.testing.assert_allclose(lux_ev[t_ev < 1.04], 100.0)
    np.testing.assert_allclose(lux_ev[t_ev > 1.16], 300.0)
    # The conversion ending at 1.1 s straddles the step: half of each level.
    assert lux_ev[np.argmin(np.abs(t_ev - 1.1))] == pytest.approx(200.0, abs=1e-9)


def test_light_sensor_reports_on_change_only() -> None:
    t = np.arange(0.0, 3.0, 0.001)
    spec = LightSensorSpec(integration_time_s=0.1, on_change=True, change_threshold_frac=0.02)
    t_ev, _ = light_events(t, np.full(t.size, 250.0), spec, rng())
    assert t_ev.size == 1  # the initial event, then nothing changes
    t, lux = _step_lux()
    t_ev, lux_ev = light_events(t, lux, spec, rng())
    np.testing.assert_allclose(t_ev, [0.1, 1.1, 1.2], atol=1e-12)
    np.testing.assert_allclose(lux_ev, [100.0, 200.0, 300.0], atol=1e-9)
    # 300 differs from 200 by 50 %, below a 60 % threshold; 200 from 100 by 100 %, above it.
    coarse = LightSensorSpec(integration_time_s=0.1, on_change=True, change_threshold_frac=0.6)
    np.testing.assert_allclose(light_events(t, lux, coarse, rng())[1], [100.0, 200.0], atol=1e-9)


def test_light_sensor_event_rate_is_capped() -> None:
    t = np.arange(0.0, 60.0, 0.001)
    lux = 300.0 + 200.0 * np.sin(2 * np.pi * 0.7 * t)  # always changing
    spec = LightSensorSpec(integration_time_s=0.05, max_event_rate_hz=5.0, on_change=True)
    t_ev, _ = light_events(t, lux, spec, rng())
    assert np.min(np.diff(t_ev)) >= 0.2 - 1e-9
    assert t_ev.size == pytest.approx(60 * 5, abs=2)


def test_light_noise_range_and_quantisation() -> None:
    t = np.arange(0.0, 200.0, 0.01)
    noisy = LightSensorSpec(integration_time_s=0.1, relative_noise=0.05)
    _, lux = light_events(t, np.full(t.size, 1000.0), noisy, rng())
    assert np.std(lux) / np.mean(lux) == pytest.approx(0.05, rel=0.1)
    clipped = LightSensorSpec(integration_time_s=0.1, range_lux=65535.0, resolution_lux=1.0)
    _, lux = light_events(t, np.full(t.size, 1e5), clipped, rng())
    assert np.all(lux == 65535.0)
    _, lux = light_events(t, 50.3 + np.sin(t), clipped, rng())
    assert np.all(lux == np.round(lux))


# --------------------------------------------------------------------------- WiFi


def test_wifi_threshold_drops_weak_aps_and_values_are_whole_dbm() -> None:
    spec = get_device("nexus_5x").wifi
    scans = wifi_scans(3600.0, spec, rng())
    mean = np.tile([-60.0, -94.0, -110.0, np.nan], (scans.size, 1))
    table = scan_rss(scans, mean, ["strong", "edge", "weak", "absent"], spec, rng(1))
    assert list(table.columns) == ["t", "bssid", "rss"]
    assert table["t"].dtype == np.float64 and table["rss"].dtype == np.float64
    rss = table["rss"].to_numpy()
    assert np.all(rss >= spec.detection_threshold_dbm)
    assert np.all(rss == np.round(rss))
    heard = table.groupby("bssid")["rss"].size()
    # 17 σ above the threshold: missed only when its beacon is lost.
    missed = 1 - heard["strong"] / scans.size
    assert missed == pytest.approx(spec.miss_probability, abs=4 * math.sqrt(0.04 / scans.size))
    assert 0 < heard["edge"] < scans.size  # at the threshold: sometimes missed
    assert "weak" not in heard.index and "absent" not in heard.index
    # Every row carries its scan's time (a scan that missed every AP has no row).
    assert np.isin(np.unique(table["t"]), scans).all()


def test_wifi_fading_sigma_is_reproduced() -> None:
    spec = WifiSpec(fading_sigma_db=2.0, quantisation_db=1.0)
    scans = np.arange(20_000) * 5.0
    table = scan_rss(scans, np.full((scans.size, 1), -50.3), ["ap"], spec, rng())
    # Rounding to whole dB adds a uniform error of variance 1/12.
    assert table["rss"].std() == pytest.approx(math.sqrt(4 + 1 / 12), rel=0.03)
    assert table["rss"].mean() == pytest.approx(-50.3, abs=0.06)


def test_wifi_throttling_allows_four_scans_per_two_minutes() -> None:
    spec = WifiSpec(scan_interval_s=5.0, scan_duration_s=3.0, throttling=True)
    scans = wifi_scans(3600.0, spec, rng())
    in_window = np.searchsorted(scans, scans + THROTTLE_WINDOW_S, side="right") - np.arange(
        scans.size
    )
    assert in_window.max() == THROTTLE_MAX_SCANS
    # Bursts of 4 requests every 125 s (the window, then the next 5 s tick).
    assert scans.size == pytest.approx(4 * 3600 / 125, abs=4)
    real = wifi_scans(3600.0, get_device("vivo_s9").wifi, rng())
    assert real.size <= 4 * math.ceil(3600 / THROTTLE_WINDOW_S)


def test_wifi_without_throttling_scans_at_the_requested_interval() -> None:
    spec = get_device("nexus_5x").wifi
    scans = wifi_scans(600.0, spec, rng(), start=10.0)
    assert np.all(np.diff(scans) > 0) and scans[0] >= 10.0 and scans[-1] < 610.0
    assert np.mean(np.diff(scans)) == pytest.approx(spec.scan_interval_s, rel=0.02)
    lag = scans - (10.0 + spec.scan_interval_s * np.arange(scans.size))
    assert np.all(np.abs(lag - spec.scan_duration_s) <= spec.scan_duration_spread_s)


def test_wifi_misses_each_ap_independently_with_its_probability() -> None:
    spec = WifiSpec(miss_probability=0.1)
    scans = np.arange(5000) * 3.0
    table = scan_rss(scans, np.full((scans.size, 2), -50.0), ["a", "b"], spec, rng())
    heard = table.pivot_table(index="t", columns="bssid", values="rss", aggfunc="size")
    heard = heard.reindex(scans).notna().to_numpy()
    assert 1 - heard.mean() == pytest.approx(0.1, abs=0.012)
    # Independent per AP: both missed in about 1 % of scans.
    assert np.mean(~heard[:, 0] & ~heard[:, 1]) == pytest.approx(0.01, abs=0.005)
    with pytest.raises(ValueError, match="miss_probability"):
        WifiSpec(miss_probability=1.0)


def test_a_logging_app_scans_back_to_back_and_the_throttle_still_holds() -> None:
    spec = WifiSpec(
        scan_interval_s=1.0, scan_duration_s=3.0, scan_duration_spread_s=1.0, continuous=True
    )
    scans = wifi_scans(600.0, spec, rng(), start=10.0)
    gaps = np.diff(np.concatenate([[10.0], scans]))
    # Each scan's results are the next request: the gaps are the scans' durations.
    assert np.all((gaps >= 2.0) & (gaps <= 4.0)) and scans[-1] < 610.0
    assert np.mean(gaps) == pytest.approx(3.0, abs=0.1)
    assert np.std(gaps) == pytest.approx(2 / math.sqrt(12), rel=0.15)  # uniform ±1 s
    # Fixed durations, so the results keep the accepted requests' spacing.
    fixed = dataclasses.replace(spec, throttling=True, scan_duration_spread_s=0.0)
    throttled = wifi_scans(3600.0, fixed, rng())
    in_window = np.searchsorted(throttled, throttled + THROTTLE_WINDOW_S, side="right")
    assert (in_window - np.arange(throttled.size)).max() == THROTTLE_MAX_SCANS


def test_scan_rss_of_no_scan_is_an_empty_table_with_the_same_columns() -> None:
    table = scan_rss([], np.zeros((0, 2)), ["a", "b"], get_device("vivo_s9").wifi, rng())
    full = scan_rss([1.0], [[-40.0, -50.0]], ["a", "b"], get_device("vivo_s9").wifi, rng())
    assert table.empty and table.dtypes.equals(full.dtypes)
    with pytest.raises(ValueError, match="rss_mean"):
        scan_rss([1.0], [[-40.0]], ["a", "b"], IDEAL.wifi, rng())


# --------------------------------------------------------------------------- determinism


def _run_all(device_name: str, seed: int) -> list[np.ndarray | pd.DataFrame]:
    """Every sensor model of one device, run from one seed."""
    device = DEVICES[device_name]
    r = rng(seed)
    t = sample_times(
        20.0, device.accel.rate_hz, device.timestamp_jitter_frac, r, gap_probability=0.01
    )
    x = np.tile([0.1, 0.2, 9.8], (t.size, 1))
    t_fine = np.arange(0.0, 20.0, 0.01)
    scans = wifi_scans(300.0, device.wifi, r)
    return [
        t,
        apply_inertial(x, t, device.accel, r),
        apply_inertial(x, t, device.gyro, r),
        apply_magnetometer(x, t, device.mag, r),
        *light_events(t_fine, 200 + 50 * np.sin(t_fine), device.light, r),
        scans,
        scan_rss(scans, np.full((scans.size, 2), -80.0), ["a", "b"], device.wifi, r),
    ]


def _same(a: np.ndarray | pd.DataFrame, b: np.ndarray | pd.DataFrame) -> bool:
    if isinstance(a, pd.DataFrame):
        return a.equals(b)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("device_name", [n for n in DEVICES if n != "ideal"])
def test_same_seed_same_bytes_other_seed_different(device_name: str) -> None:
    first, again, other = (_run_all(device_name, s) for s in (7, 7, 8))
    assert all(_same(a, b) for a, b in zip(first, again, strict=True))
    assert not any(_same(a, b) for a, b in zip(first, other, strict=True))


def test_switching_one_error_off_leaves_the_others_unchanged() -> None:
    spec = get_device("mid_grade").gyro
    t = np.arange(1000) / spec.rate_hz
    x = np.zeros((t.size, 3))
    full = apply_inertial(x, t, spec, rng(4))
    no_noise = apply_inertial(x, t, dataclasses.replace(spec, noise_density=0.0), rng(4))
    white_only = InertialSpec(rate_hz=spec.rate_hz, noise_density=spec.noise_density)
    white = apply_inertial(x, t, white_only, rng(4))
    # Same streams: the full output is the noise-free one plus the same white noise, up to one LSB.
    assert np.max(np.abs(full - (no_noise + white))) <= spec.resolution + 1e-12
