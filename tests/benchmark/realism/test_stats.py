"""Realism statistics on signals with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from indoorsim.benchmark.realism.stats import (
    band_share,
    crest_factor,
    dominant_frequency,
    excess_kurtosis,
    harmonic_shares,
    peak_to_peak_per_period,
    resample_uniform,
    rms_per_axis,
    spectrum,
    walking_mask,
)

RATE = 100.0


def _sine(f_hz: float = 1.8, seconds: float = 60.0, amplitude: float = 2.0) -> np.ndarray:
    t = np.arange(0, seconds, 1 / RATE)
    return 9.81 + amplitude * np.sin(2 * np.pi * f_hz * t)


def test_a_pure_sine_has_crest_factor_root_two_and_excess_kurtosis_minus_one_and_a_half():
    x = _sine()
    assert crest_factor(x) == pytest.approx(math.sqrt(2), rel=1e-4)
    assert excess_kurtosis(x) == pytest.approx(-1.5, abs=1e-3)


def test_gaussian_noise_has_excess_kurtosis_zero_and_impulses_a_high_crest_factor():
    rng = np.random.default_rng(0)
    assert excess_kurtosis(rng.normal(size=200_000)) == pytest.approx(0.0, abs=0.05)
    spikes = np.zeros(1000)
    spikes[::100] = 1.0  # one sample in a hundred: crest factor ≈ 0.99 / sqrt(0.0099)
    assert crest_factor(spikes) == pytest.approx(0.99 / math.sqrt(0.0099), rel=1e-9)


def test_a_sine_puts_all_its_power_at_its_frequency():
    x = _sine(1.8)
    shares = harmonic_shares(x, RATE, 1.8)
    assert shares[1.0] > 0.99
    assert shares[0.5] < 1e-3 and shares[2.0] < 1e-3


def test_harmonic_shares_follow_the_amplitudes_squared():
    t = np.arange(0, 80, 1 / RATE)
    x = (
        np.sin(2 * np.pi * 1.8 * t)
        + 0.5 * np.sin(2 * np.pi * 3.6 * t)
        + 0.25 * np.sin(np.pi * 1.8 * t)
    )
    shares = harmonic_shares(x, RATE, 1.8)
    total = 1 + 0.25 + 0.0625
    assert shares[1.0] == pytest.approx(1 / total, abs=0.01)
    assert shares[2.0] == pytest.approx(0.25 / total, abs=0.01)
    assert shares[0.5] == pytest.approx(0.0625 / total, abs=0.01)


def test_dominant_frequency_finds_the_step_rate_between_bins():
    assert dominant_frequency(_sine(1.87), RATE) == pytest.approx(1.87, abs=0.01)


def test_welch_power_integrates_to_the_variance():
    x = _sine(1.8, amplitude=2.0)
    f, p = spectrum(x, RATE)
    assert np.trapezoid(p, f) == pytest.approx(np.var(x), rel=0.02)
    assert band_share(f, p, 1.8, 0.3) > 0.99


def test_rms_per_axis_is_about_the_mean_and_sorted_largest_first():
    t = np.arange(0, 10, 1 / RATE)
    wave = [np.sin(2 * np.pi * f * t) for f in (0.7, 0.9, 1.1)]  # whole cycles in 10 s
    v = np.column_stack([0.1 * wave[0], 5.0 + 0.3 * wave[1], 0.2 * wave[2]])
    np.testing.assert_allclose(rms_per_axis(v), [0.3, 0.2, 0.1] / np.sqrt(2), rtol=1e-9)


def test_peak_to_peak_per_period_of_a_sine_is_twice_its_amplitude():
    assert peak_to_peak_per_period(_sine(1.0, amplitude=3.0), RATE, 1.0) == pytest.approx(
        6.0, rel=1e-3
    )


def test_walking_mask_finds_the_walk_between_two_still_stretches():
    rng = np.random.default_rng(1)
    still = 9.81 + 0.02 * rng.normal(size=int(10 * RATE))
    walk = _sine(1.8, seconds=20.0)
    mask = walking_mask(np.concatenate([still, walk, still]), RATE)
    t = np.arange(mask.size) / RATE
    assert not mask[t < 10].any() and not mask[t >= 30].any()
    assert mask[(t > 11.5) & (t < 28.5)].all()


def test_walking_mask_drops_a_short_shuffle():
    still = np.full(int(10 * RATE), 9.81)
    shuffle = _sine(1.8, seconds=3.0)
    assert not walking_mask(np.concatenate([still, shuffle, still]), RATE).any()


def test_resampling_keeps_a_linear_signal_exactly():
    t = np.sort(np.random.default_rng(2).uniform(0, 10, 500))
    grid, v = resample_uniform(t, 3 * t + 1, 50.0)
    np.testing.assert_allclose(v, 3 * grid + 1, atol=1e-12)
    assert np.allclose(np.diff(grid), 0.02)


@pytest.mark.parametrize("bad", [[1.0], [[1.0, 2.0]], [1.0, float("nan"), 2.0]])
def test_statistics_name_a_bad_series(bad):
    with pytest.raises(ValueError, match="x "):
        crest_factor(bad)
