"""Signal statistics that compare simulated phone streams with real ones.

Every function here is a pure function of arrays (times in s, values in SI
units), used unchanged on a simulated recording and on a real phone log, so a
difference in a statistic is a difference in the signals and never in how it
was measured. Each is checked on signals with a closed-form answer
(``tests/benchmark/realism/test_stats.py``): a pure sine's crest factor is √2
and its excess kurtosis −1.5; a signal with all its power at one frequency
puts a share of 1 there.

Conventions:

* ``x`` a 1-D series sampled uniformly at ``rate_hz``; callers resample
  irregular logs first (:func:`resample_uniform`).
* Spectra are Welch estimates (Hann windows of ``segment_s`` seconds, half
  overlap, mean removed), so shares of power are shares of the variance.
* "Step frequency" is the dominant frequency of the accelerometer magnitude
  in the walking band (:data:`STEP_BAND_HZ`); a stride is two steps.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import signal, stats

__all__ = [
    "STEP_BAND_HZ",
    "band_power",
    "band_share",
    "crest_factor",
    "dominant_frequency",
    "excess_kurtosis",
    "harmonic_shares",
    "long_runs",
    "moving_std",
    "peak_frequency",
    "peak_to_peak_per_period",
    "resample_uniform",
    "rms_per_axis",
    "spectrum",
    "walking_mask",
]

STEP_BAND_HZ = (1.2, 2.8)
"""Where a walker's step frequency lies (REALISM §5: 1.6–2.1 Hz at 1.0–1.7 m/s, with margin)."""


def _series(x: ArrayLike, name: str = "x") -> NDArray[np.float64]:
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 1 or arr.size < 2:
        raise ValueError(
            f"{name} must be a 1-D series of at least 2 samples, got shape {arr.shape}"
        )
    if not np.isfinite(arr).all():
        raise ValueError(f"{name} has {int((~np.isfinite(arr)).sum())} non-finite samples")
    return arr


def crest_factor(x: ArrayLike) -> float:
    """Largest deviation from the mean over the standard deviation (a sine: √2).

    Impulsive signals (heel strikes) have a high crest factor, a sinusoid a low one.
    """
    arr = _series(x)
    dev = arr - arr.mean()
    sd = float(np.sqrt(np.mean(dev**2)))
    return float(np.max(np.abs(dev)) / sd) if sd > 0 else math.nan


def excess_kurtosis(x: ArrayLike) -> float:
    """Fisher's excess kurtosis, biased estimator (a sine: −1.5; Gaussian noise: 0)."""
    arr = _series(x)
    if np.ptp(arr) == 0:
        return math.nan
    return float(stats.kurtosis(arr, fisher=True, bias=True))


def rms_per_axis(v: ArrayLike) -> NDArray[np.float64]:
    """Root mean square of each column about its mean, largest first: (3,) for gyro rates."""
    arr = np.asarray(v, dtype=float)
    if arr.ndim != 2 or len(arr) < 2:
        raise ValueError(f"expected an (N, k) array with N ≥ 2, got shape {arr.shape}")
    dev = arr - arr.mean(axis=0)
    return np.sort(np.sqrt(np.mean(dev**2, axis=0)))[::-1]


def spectrum(
    x: ArrayLike, rate_hz: float, *, segment_s: float = 8.0
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Welch power spectral density (frequencies in Hz, power per Hz) of the demeaned series."""
    arr = _series(x)
    nperseg = min(len(arr), max(8, round(segment_s * rate_hz)))
    f, p = signal.welch(
        arr, fs=rate_hz, window="hann", nperseg=nperseg, detrend="constant", scaling="density"
    )
    return f, p


def band_power(f: NDArray[np.float64], p: NDArray[np.float64], lo: float, hi: float) -> float:
    """Power of the bins whose centre lies in ``[lo, hi]`` (a sum of bins, not a trapezoid,
    so adjacent bands add up and a window's main lobe is counted whole)."""
    keep = (f >= lo) & (f <= hi)
    return float(p[keep].sum() * (f[1] - f[0])) if len(f) > 1 else 0.0


def band_share(
    f: NDArray[np.float64],
    p: NDArray[np.float64],
    center_hz: float,
    half_width_hz: float,
    total: tuple[float, float] | None = None,
) -> float:
    """Share of the power within ``center ± half_width`` of the power in ``total`` (all if None)."""
    lo, hi = total if total is not None else (float(f[0]), float(f[-1]))
    whole = band_power(f, p, lo, hi)
    if whole <= 0:
        return math.nan
    part = band_power(f, p, max(lo, center_hz - half_width_hz), min(hi, center_hz + half_width_hz))
    return part / whole


def peak_frequency(
    f: NDArray[np.float64], p: NDArray[np.float64], band: tuple[float, float] = STEP_BAND_HZ
) -> float:
    """Frequency of a spectrum's highest bin within ``band`` (Hz), refined between bins
    by the parabola through the log powers of the peak bin and its neighbours."""
    keep = np.flatnonzero((f >= band[0]) & (f <= band[1]))
    if keep.size == 0:
        return math.nan
    k = int(keep[np.argmax(p[keep])])
    if 0 < k < len(p) - 1 and min(p[k - 1 : k + 2]) > 0:
        a, b, c = np.log(p[k - 1 : k + 2])
        denom = a - 2 * b + c
        if denom != 0:
            return float(f[k] + 0.5 * (a - c) / denom * (f[1] - f[0]))
    return float(f[k])


def dominant_frequency(
    x: ArrayLike, rate_hz: float, band: tuple[float, float] = STEP_BAND_HZ
) -> float:
    """Frequency of the highest spectral peak of ``x`` within ``band`` (Hz)."""
    return peak_frequency(*spectrum(x, rate_hz), band)


def harmonic_shares(
    x: ArrayLike,
    rate_hz: float,
    f0_hz: float,
    *,
    multiples: Sequence[float] = (0.5, 1.0, 2.0),
    half_width_hz: float = 0.3,
    total: tuple[float, float] = (0.3, 15.0),
) -> dict[float, float]:
    """Share of the power in ``total`` that lies near each multiple of ``f0_hz``.

    With ``f0`` the step frequency, multiple 0.5 is the stride frequency (a
    left/right asymmetry), 1 the steps themselves, 2 their second harmonic
    (impulsive heel strikes put power there; a sinusoidal bounce does not).
    ``half_width_hz`` covers the main lobe of the 8 s Hann window (±0.25 Hz)
    and a cadence that drifts a little along the walk.
    """
    f, p = spectrum(x, rate_hz)
    return {m: band_share(f, p, m * f0_hz, half_width_hz, total) for m in multiples}


def peak_to_peak_per_period(x: ArrayLike, rate_hz: float, period_s: float) -> float:
    """Median over consecutive whole periods of the peak-to-peak range within each."""
    arr = _series(x)
    n = max(2, round(period_s * rate_hz))
    k = len(arr) // n
    if k == 0:
        return math.nan
    blocks = arr[: k * n].reshape(k, n)
    return float(np.median(np.ptp(blocks, axis=1)))


def resample_uniform(
    t: ArrayLike, v: ArrayLike, rate_hz: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Linear interpolation of samples ``v`` (N or N×k) at times ``t`` onto a uniform grid."""
    tt = np.asarray(t, dtype=float)
    vv = np.asarray(v, dtype=float)
    if tt.ndim != 1 or len(tt) != len(vv) or len(tt) < 2:
        raise ValueError(f"t {tt.shape} and v {vv.shape} must have the same length ≥ 2")
    if np.any(np.diff(tt) < 0):
        raise ValueError("t must be non-decreasing")
    grid = np.arange(tt[0], tt[-1], 1.0 / rate_hz)
    if vv.ndim == 1:
        return grid, np.interp(grid, tt, vv)
    return grid, np.column_stack([np.interp(grid, tt, vv[:, j]) for j in range(vv.shape[1])])


def walking_mask(
    accel_norm: ArrayLike,
    rate_hz: float,
    *,
    window_s: float = 2.0,
    min_std: float = 0.8,
    min_run_s: float = 6.0,
) -> NDArray[np.bool_]:
    """Samples that belong to walking: the moving std of ‖a‖ above ``min_std`` m/s².

    Standing (a phone at rest or held still reads ‖a‖ ≈ g with a few hundredths
    of m/s² of noise and tremor) is below it; every carrying mode's walking is
    well above. Runs shorter than ``min_run_s`` (a shuffle, a turn on the spot,
    picking the phone up) are dropped, and the first and last half window of
    each run, which straddle its edge, are trimmed.
    """
    arr = _series(accel_norm, "accel_norm")
    n = max(3, round(window_s * rate_hz))
    return long_runs(moving_std(arr, n) > min_std, rate_hz, min_run_s, trim=n // 2)


def moving_std(x: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    """Standard deviation of ``x`` over a centred window of ``n`` samples (``same`` length)."""
    kernel = np.ones(n) / n
    mean = np.convolve(x, kernel, mode="same")
    var = np.convolve(x**2, kernel, mode="same") - mean**2
    return np.sqrt(np.maximum(var, 0.0))


def long_runs(
    mask: NDArray[np.bool_], rate_hz: float, min_run_s: float, *, trim: int
) -> NDArray[np.bool_]:
    """The runs of ``mask`` that last at least ``min_run_s``, each with ``trim`` samples
    cut from both ends (the half window that straddles its edge)."""
    out = np.zeros_like(mask)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.view(np.int8), [0]])))
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        if (b - a) / rate_hz >= min_run_s:
            out[a + trim : b - trim] = True
    return out
