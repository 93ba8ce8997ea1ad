"""The magnetic field along a walk: its amplitude and spatial spectrum against distance walked.

:func:`magnetic_statistics` takes a :class:`~indoorsim.io.recording.Recording`
with a magnetometer and true positions — dense ``truth`` in a simulated walk,
ARKit positions in the magnetic-SLAM walks, surveyed ``waypoints`` in an Indoor
Location Competition trace — and measures ‖m‖ as a function of the distance
walked, the variable a magnetic matcher sees. The same code path runs on both
sides:

1. The positions are interpolated (linearly in time) to the magnetometer's
   samples, and ‖m‖ is put on a uniform arc-length grid of :data:`GRID_M`
   (:func:`along_path`): standing still adds no distance, so it adds no samples.
2. The series is detrended by a straight line (the slow drift of a sensor's
   offset, or of the Earth's field across a big building, is not the indoor
   anomaly).
3. Bands of wavelength are cut exactly by the discrete Fourier transform
   (:func:`band_std`), so the bands' variances add up to the whole.

The keys of the returned dict (NaN where a stream is missing or the walk is
shorter than :data:`MIN_PATH_M`):

===============  ==============================================================
``path_m``       distance walked (m)
``mag_std``      std of the detrended ‖m‖ (µT)
``share_long``   share of its variance at wavelengths above 10 m
``std_long``     std of the band above 10 m (µT)
``std_mid``      std of the 2–10 m band (µT)
``std_short``    std of the 0.5–2 m band (µT)
``corr_length``  distance at which the autocorrelation first falls to 1/e (m)
===============  ==============================================================
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import signal

from indoorsim.io.recording import Recording

__all__ = [
    "BANDS_M",
    "GRID_M",
    "MAGNETIC_KEYS",
    "MIN_PATH_M",
    "along_path",
    "band_std",
    "correlation_length",
    "magnetic_statistics",
]

GRID_M = 0.1
"""Arc-length spacing of the along-path series (m): a tenth of a step."""

MIN_PATH_M = 40.0
"""Shorter walks hold fewer than four wavelengths of the > 10 m band, most of which the
linear detrend then takes (m)."""

BANDS_M = {"std_long": (10.0, math.inf), "std_mid": (2.0, 10.0), "std_short": (0.5, 2.0)}
"""Wavelength bands (m): building scale, room scale, and the scale of single sources."""

MAGNETIC_KEYS = (
    "path_m",
    "mag_std",
    "share_long",
    "std_long",
    "std_mid",
    "std_short",
    "corr_length",
)


def along_path(
    t: ArrayLike,
    values: ArrayLike,
    t_pos: ArrayLike,
    xy: ArrayLike,
    spacing: float = GRID_M,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``values`` (sampled at times ``t``) on a uniform grid of distance walked.

    The positions ``xy`` (N×2, at times ``t_pos``) are interpolated to ``t``;
    samples outside the positions' time span are dropped. Where the walker
    stands, the distance does not grow and those samples are skipped, so the
    series is the field along the path, not along the clock.

    Returns:
        ``(s, v)``: distance from the start (m) and the values there.
    """
    tv = np.asarray(t, dtype=float)
    vv = np.asarray(values, dtype=float)
    tp = np.asarray(t_pos, dtype=float)
    pos = np.asarray(xy, dtype=float)
    if tv.ndim != 1 or vv.shape != tv.shape:
        raise ValueError(f"t {tv.shape} and values {vv.shape} must be 1-D of one length")
    if tp.ndim != 1 or pos.shape != (len(tp), 2) or len(tp) < 2:
        raise ValueError(f"t_pos {tp.shape} and xy {pos.shape} must be (N,) and (N, 2), N ≥ 2")
    inside = (tv >= tp[0]) & (tv <= tp[-1]) & np.isfinite(vv)
    tv, vv = tv[inside], vv[inside]
    if len(tv) < 2:
        return np.zeros(0), np.zeros(0)
    x = np.interp(tv, tp, pos[:, 0])
    y = np.interp(tv, tp, pos[:, 1])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])
    moving = np.concatenate([[True], np.diff(s) > 0])
    s, vv = s[moving], vv[moving]
    grid = np.arange(0.0, s[-1], spacing)
    return grid, np.interp(grid, s, vv)


def band_std(x: ArrayLike, spacing: float, shortest_m: float, longest_m: float) -> float:
    """Std of the part of ``x`` whose wavelength lies in ``[shortest_m, longest_m)``.

    The band is cut by zeroing the other bins of the real DFT of the demeaned
    series, so by Parseval the bands of a partition add up to the variance.
    """
    arr = np.asarray(x, dtype=float)
    spectrum = np.fft.rfft(arr - arr.mean())
    freq = np.fft.rfftfreq(len(arr), spacing)  # cycles per metre
    keep = (freq > 1.0 / longest_m) & (freq <= 1.0 / shortest_m)
    part = np.fft.irfft(np.where(keep, spectrum, 0.0), n=len(arr))
    return float(np.std(part))


def correlation_length(x: ArrayLike, spacing: float) -> float:
    """Lag (m) at which the demeaned series' autocorrelation first falls below 1/e.

    The biased (divide-by-N) estimate, computed by FFT and read between lags
    by linear interpolation; NaN if it never falls that low.
    """
    arr = np.asarray(x, dtype=float)
    dev = arr - arr.mean()
    n = len(dev)
    if n < 2 or not np.any(dev):
        return math.nan
    size = 1 << (2 * n - 1).bit_length()
    power = np.abs(np.fft.rfft(dev, size)) ** 2
    acf = np.fft.irfft(power, size)[:n]
    acf /= acf[0]
    below = np.flatnonzero(acf < math.exp(-1.0))
    if below.size == 0:
        return math.nan
    k = int(below[0])
    a, b = acf[k - 1], acf[k]
    return float((k - 1 + (a - math.exp(-1.0)) / (a - b)) * spacing)


def field_statistics(s: ArrayLike, v: ArrayLike, spacing: float = GRID_M) -> dict[str, float]:
    """The statistics of the module docstring for a series ``v`` on the grid ``s``."""
    out = dict.fromkeys(MAGNETIC_KEYS, math.nan)
    grid = np.asarray(s, dtype=float)
    values = np.asarray(v, dtype=float)
    out["path_m"] = float(grid[-1] + spacing) if len(grid) else 0.0
    if out["path_m"] < MIN_PATH_M:
        return out
    detrended = signal.detrend(values, type="linear")
    total = float(np.std(detrended))
    out["mag_std"] = total
    for key, (shortest, longest) in BANDS_M.items():
        out[key] = band_std(detrended, spacing, shortest, longest)
    out["share_long"] = out["std_long"] ** 2 / total**2 if total > 0 else math.nan
    out["corr_length"] = correlation_length(detrended, spacing)
    return out


def magnetic_statistics(rec: Recording) -> dict[str, float]:
    """The along-path statistics of ``rec``'s ‖m‖ (see the module docstring for the keys)."""
    if "mag" not in rec.streams or not ({"truth", "waypoints"} & set(rec.streams)):
        return dict.fromkeys(MAGNETIC_KEYS, math.nan)
    mag = rec.mag
    norm = np.linalg.norm(mag[["x", "y", "z"]].to_numpy(dtype=float), axis=1)
    where = rec.true_positions()
    s, v = along_path(
        mag.index.to_numpy(dtype=float),
        norm,
        where.index.to_numpy(dtype=float),
        where[["x", "y"]].to_numpy(dtype=float),
    )
    return field_statistics(s, v)
