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

**The phone's own offset.** A calibrated magnetometer (Android's
``TYPE_MAGNETIC_FIELD``) keeps a residual hard-iron offset h, fixed in the
phone, that its online calibration has not removed. It turns with the phone,
so ‖m‖ = ‖B + h‖ changes at every turn by up to 2·|h| — building-scale
"structure" that belongs to the phone, not the building.
:func:`hard_iron_residual` measures h from a walk's own magnetometer, and
``magnetic_statistics(rec, hard_iron_uT=h)`` measures the field without it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import signal

from indoorsim.io.recording import Recording

__all__ = [
    "BANDS_M",
    "GRID_M",
    "HARD_IRON_MAX_PLANE_TILT_DEG",
    "HARD_IRON_MAX_SPREAD",
    "HARD_IRON_MIN_ARC_DEG",
    "HARD_IRON_MIN_FLATNESS",
    "MAGNETIC_KEYS",
    "MIN_PATH_M",
    "HardIronFit",
    "along_path",
    "band_std",
    "correlation_length",
    "hard_iron_residual",
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


def magnetic_statistics(rec: Recording, hard_iron_uT: ArrayLike | None = None) -> dict[str, float]:
    """The along-path statistics of ``rec``'s ‖m‖ (see the module docstring for the keys),
    less the phone-frame offset ``hard_iron_uT`` (µT) when one is given."""
    if "mag" not in rec.streams or not ({"truth", "waypoints"} & set(rec.streams)):
        return dict.fromkeys(MAGNETIC_KEYS, math.nan)
    mag = rec.mag
    values = mag[["x", "y", "z"]].to_numpy(dtype=float)
    if hard_iron_uT is not None:
        values = values - np.asarray(hard_iron_uT, dtype=float)
    norm = np.linalg.norm(values, axis=1)
    where = rec.true_positions()
    s, v = along_path(
        mag.index.to_numpy(dtype=float),
        norm,
        where.index.to_numpy(dtype=float),
        where[["x", "y"]].to_numpy(dtype=float),
    )
    return field_statistics(s, v)


HARD_IRON_MIN_ARC_DEG = 150.0
"""How far round its circle the field must turn (deg) for the circle's centre to be
fitted: a walk with fewer turns shows an offset's effect but does not pin it down."""

HARD_IRON_MAX_SPREAD = 0.1
"""Largest RMS distance of the samples from the fitted circle, as a share of its radius,
for the circle to describe them: beyond it the building's own field varies along the walk
as much as the offset turns, or the phone's tilt does not stay put (a pocket)."""

HARD_IRON_MIN_FLATNESS = 2.0
"""The samples' spread within their plane (its narrower direction) over their spread out
of it, at least: below it they lie nearly on a line and the plane is not told."""

HARD_IRON_MAX_PLANE_TILT_DEG = 20.0
"""Largest angle between the circle's plane and the horizontal the accelerometer's mean
(gravity) shows: a plane at a steeper angle is not the phone turning about the vertical."""

_HARD_IRON_MIN_SAMPLES = 100


@dataclass(frozen=True)
class HardIronFit:
    """A walk's residual hard-iron offset, fitted by :func:`hard_iron_residual`.

    Attributes:
        offset_uT: (3,) the offset in the phone frame, µT. Its part along the
            phone-frame vertical cannot be told from the building's vertical
            field while the tilt stays put, and is taken as 0.
        horizontal_uT: the offset's size square to the vertical, µT: the part that
            turns with the phone.
        radius_uT: the circle's radius: the horizontal field the phone saw, µT.
        arc_deg: how far round the circle the samples go, deg.
        spread_uT: RMS distance of the samples from the circle in its plane, µT.
    """

    offset_uT: NDArray[np.float64]
    horizontal_uT: float
    radius_uT: float
    arc_deg: float
    spread_uT: float


def hard_iron_residual(rec: Recording) -> HardIronFit | None:
    """The phone's residual hard-iron offset, from a walk's magnetometer alone.

    A phone that keeps its tilt while it turns about the vertical reads
    m = Rᵀ·B + h: its samples run round a circle, in the plane square to the
    phone-frame vertical û, of radius |B_h|, centred on h + B_v·û. The plane
    is the samples' least-spread direction (SVD), the circle in it is fitted
    by algebraic least squares (Kåsa) — both exact for points on a circle —
    and the offset is the centre less its part along û: h's part square to the
    vertical. No attitude is used, so a fused tilt's bias (1–2° while walking,
    which would pass 35 µT·sin 2° ≈ 1.2 µT of the vertical field off as an
    offset) does not enter.

    Returns None where it cannot be told: no ``mag`` stream, fewer than 100
    samples, samples not spread over a plane (:data:`HARD_IRON_MIN_FLATNESS`), a
    plane steeper than :data:`HARD_IRON_MAX_PLANE_TILT_DEG` against the
    accelerometer's mean where there is one, an arc under
    :data:`HARD_IRON_MIN_ARC_DEG`, or a spread over :data:`HARD_IRON_MAX_SPREAD`
    of the radius.
    """
    if "mag" not in rec.streams or len(rec.mag) < _HARD_IRON_MIN_SAMPLES:
        return None
    m = rec.mag[["x", "y", "z"]].to_numpy(dtype=float)
    m = m[np.isfinite(m).all(axis=1)]
    if len(m) < _HARD_IRON_MIN_SAMPLES:
        return None
    mean = m.mean(axis=0)
    _, spreads, axes = np.linalg.svd(m - mean, full_matrices=False)
    e1, e2, up = axes
    # The samples must span a plane (a short arc is nearly a line, whose plane is
    # anyone's), and that plane must be the horizontal one the phone turned in.
    if spreads[1] < HARD_IRON_MIN_FLATNESS * spreads[2]:
        return None
    if "accel" in rec.streams and len(rec.accel):
        accel = rec.accel[["x", "y", "z"]].to_numpy(dtype=float)
        accel = accel[np.isfinite(accel).all(axis=1)]
        gravity = accel.mean(axis=0) if len(accel) else np.zeros(3)
        norm = float(np.linalg.norm(gravity))
        if not norm > 0:
            return None  # the plane cannot be checked against the vertical
        if abs(float(gravity @ up)) / norm < math.cos(math.radians(HARD_IRON_MAX_PLANE_TILT_DEG)):
            return None
    u, v = (m - mean) @ e1, (m - mean) @ e2
    design = np.column_stack([u, v, np.ones_like(u)])
    (a, b, c), *_ = np.linalg.lstsq(design, u * u + v * v, rcond=None)
    a, b = a / 2.0, b / 2.0
    radius = math.sqrt(max(c + a * a + b * b, 0.0))
    spread = float(np.sqrt(np.mean((np.hypot(u - a, v - b) - radius) ** 2)))
    angles = np.sort(np.arctan2(v - b, u - a))
    gaps = np.diff(np.concatenate([angles, [angles[0] + 2 * math.pi]]))
    arc = math.degrees(2 * math.pi - float(gaps.max()))
    if arc < HARD_IRON_MIN_ARC_DEG or not spread <= HARD_IRON_MAX_SPREAD * radius:
        return None
    centre = mean + a * e1 + b * e2
    offset = centre - (centre @ up) * up
    return HardIronFit(
        offset_uT=offset,
        horizontal_uT=float(np.linalg.norm(offset)),
        radius_uT=radius,
        arc_deg=arc,
        spread_uT=spread,
    )
