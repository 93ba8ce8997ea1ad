"""Motion statistics of one recording's walking: how the phone shakes and turns.

:func:`motion_statistics` takes a :class:`~indoorsim.io.recording.Recording`
(simulated or a real log) and returns the statistics of the "Motion realism"
issue for the parts where the phone's wearer walks. The same code path runs on
both sides:

1. Every stream used is put on one uniform clock at :data:`MOTION_RATE_HZ`
   (linear interpolation at the stream's own median rate, then a polyphase
   anti-alias resampler), so a 405 Hz research log, a 100 Hz simulated phone
   and a 50 Hz competition trace are measured at the same bandwidth.
2. Walking is found from the accelerometer alone
   (:func:`~indoorsim.benchmark.realism.stats.walking_mask`): truth is never read.
3. The statistics are computed over the walking runs; spectra are the
   run-length-weighted mean of each run's Welch spectrum, so the gaps between
   runs add no false edges.

The keys of the returned dict (NaN where a stream is missing or too short):

==================  ==========================================================
``walking_s``       seconds of walking found
``step_hz``         dominant frequency of ‖a‖ (the step rate)
``cadence_ratio``   ``step_hz`` over the recording's step count per walking second
``acc_std``         standard deviation of ‖a‖ (m/s²)
``acc_p2p``         median peak-to-peak of ‖a‖ per stride (m/s²)
``acc_crest``       median crest factor of ‖a‖ over 10 s windows
``acc_kurtosis``    excess kurtosis of ‖a‖
``share_stride``    share of ‖a‖ power near half the step rate (left/right asymmetry)
``share_step``      share of ‖a‖ power near the step rate
``share_2nd``       share of ‖a‖ power near twice the step rate (heel-strike harmonics)
``gyro_rms_1..3``   per-axis RMS of the angular rate, largest first (rad/s)
``heading_jitter``  std of the fused heading about its 2 s running median (degrees)
``gyro_drift``      drift of the gyro heading ∫ω·ĝ dt against the fused attitude's
                    heading, degrees per stride (signed; :func:`gyro_heading_drift`)
``surge_step``      a phone held top-forward: forward acceleration at the step rate,
``sway_stride``     sideways at the stride rate, vertical at the step rate (m/s²),
``bob_step``        rate of turn at the stride rate (rad/s) and sideways
``yaw_stride``      acceleration at the step rate (m/s²), levelled by its own
``sway_step``       fused attitude (:func:`held_phone_motion`)
``roll_jerk``       a phone held top-forward: correlation of its roll rate with its
                    sideways jerk, while walking (:func:`held_phone_motion`)
``nod_2nd``         a phone held top-forward: its pitch rate per vertical acceleration
                    at twice the step rate (rad/s per m/s²; a resonance rings there)
``bob_phase_2nd``   its vertical acceleration's second harmonic against the step
                    rate's, φ₂ − 2φ₁ (°; the loading peak's and the jolt's timing)
``surge_2nd``       its forward acceleration at twice the step rate (m/s²)
``surge_phase``     its forward acceleration's lead on its vertical acceleration at
                    the step rate (°; the pelvis's own surge leads by a quarter cycle)
==================  ==========================================================
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import ndimage, signal

from indoorsim.benchmark.realism.stats import (
    band_power,
    crest_factor,
    excess_kurtosis,
    peak_frequency,
    peak_to_peak_per_period,
    resample_uniform,
    rms_per_axis,
    walking_mask,
)
from indoorsim.io.recording import Recording
from indoorsim.util import quaternion

__all__ = [
    "HELD_KEYS",
    "MOTION_KEYS",
    "MOTION_RATE_HZ",
    "WalkingSignals",
    "gyro_heading_drift",
    "held_phone_motion",
    "motion_profiles",
    "motion_statistics",
    "uniform_stream",
    "walking_signals",
]

MOTION_RATE_HZ = 50.0
"""The common rate: the lowest of the real logs (Indoor Location Competition traces)."""

MOTION_KEYS = (
    "walking_s",
    "step_hz",
    "cadence_ratio",
    "acc_std",
    "acc_p2p",
    "acc_crest",
    "acc_kurtosis",
    "share_stride",
    "share_step",
    "share_2nd",
    "gyro_rms_1",
    "gyro_rms_2",
    "gyro_rms_3",
    "heading_jitter",
    "gyro_drift",
    "surge_step",
    "sway_stride",
    "bob_step",
    "yaw_stride",
    "sway_step",
    "roll_jerk",
    "nod_2nd",
    "bob_phase_2nd",
    "surge_2nd",
    "surge_phase",
)

_SEGMENT_S = 8.0  # Welch segment: 0.125 Hz bins, several segments per real walk
_CREST_WINDOW_S = 10.0
_JITTER_MEDIAN_S = 2.0
_HALF_WIDTH_HZ = 0.3  # the Hann main lobe and a little cadence drift
_POWER_BAND_HZ = (0.3, 15.0)
_GRAVITY_CUTOFF_HZ = 0.3  # below the stride rate: ĝ is the phone's mean "down" over a stride


def uniform_stream(df: pd.DataFrame, columns: list[str], rate_hz: float) -> NDArray[np.float64]:
    """A stream's columns on a uniform clock at ``rate_hz`` from its first sample.

    The samples are first interpolated onto a uniform grid at their own median
    rate, then resampled by a polyphase filter (which low-passes before it
    decimates), so a faster stream is not aliased.
    """
    t = df.index.to_numpy(dtype=float)
    v = df[columns].to_numpy(dtype=float)
    keep = np.concatenate([[True], np.diff(t) > 0])  # repeated stamps carry no new time
    t, v = t[keep], v[keep]
    native = 1.0 / float(np.median(np.diff(t)))
    _, grid_values = resample_uniform(t, v, native)
    ratio = Fraction(rate_hz / native).limit_denominator(200)
    if ratio == 1:
        return grid_values
    return signal.resample_poly(grid_values, ratio.numerator, ratio.denominator, axis=0)


def _runs(mask: NDArray[np.bool_]) -> list[slice]:
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.view(np.int8), [0]])))
    return [slice(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _mean_spectrum(
    x: NDArray[np.float64], runs: list[slice], rate_hz: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Welch spectra of each run long enough for a segment, weighted by the run's length."""
    nperseg = round(_SEGMENT_S * rate_hz)
    total, weight, freqs = None, 0, None
    for run in runs:
        seg = x[run]
        if len(seg) < nperseg:
            continue
        freqs, p = signal.welch(seg, fs=rate_hz, window="hann", nperseg=nperseg, detrend="constant")
        total = p * len(seg) if total is None else total + p * len(seg)
        weight += len(seg)
    if total is None or freqs is None:
        return None
    return freqs, total / weight


def _heading_jitter_deg(rotation: NDArray[np.float64], walking: NDArray[np.bool_]) -> float:
    """Std (°) of the phone's forward-axis heading about its running median, while walking."""
    q = rotation / np.linalg.norm(rotation, axis=1, keepdims=True)
    forward = quaternion.rotate(q, np.array([0.0, 1.0, 0.0]))
    heading = np.unwrap(np.arctan2(forward[:, 1], forward[:, 0]))
    size = max(3, round(_JITTER_MEDIAN_S * MOTION_RATE_HZ) | 1)
    residual = heading - ndimage.median_filter(heading, size=size, mode="nearest")
    return float(np.degrees(np.std(residual[walking]))) if walking.sum() > size else math.nan


def gyro_heading_drift(
    gyro: NDArray[np.float64],
    accel: NDArray[np.float64],
    rotation: NDArray[np.float64],
    runs: list[slice],
    rate_hz: float,
) -> float:
    """Heading change of ∫ω·ĝ dt minus the fused heading's change, radians, summed over runs.

    This is the error of the usual PDR gyro heading, which integrates the rate
    about the phone's low-passed gravity direction ĝ: a phone that pitches and
    rolls out of phase (a thigh's coning in a pocket) turns about ĝ without
    the walker turning, by the area its tilt encloses per cycle. The full
    attitude's heading is the yaw of the phone axis that stays most horizontal,
    which is periodic over a stride, so only the walker's own turns remain in
    it. Arrays share one uniform clock at ``rate_hz``; quaternions are world←phone.
    """
    b, a = signal.butter(2, _GRAVITY_CUTOFF_HZ, fs=rate_hz)
    down = signal.filtfilt(b, a, accel, axis=0)
    down /= np.linalg.norm(down, axis=1, keepdims=True)
    q = rotation / np.linalg.norm(rotation, axis=1, keepdims=True)
    axes = np.eye(3)
    world_z = np.stack([quaternion.rotate(q, axis)[:, 2] for axis in axes])
    flat = axes[int(np.argmin(np.mean(np.abs(world_z), axis=1)))]
    forward = quaternion.rotate(q, flat)
    yaw = np.unwrap(np.arctan2(forward[:, 1], forward[:, 0]))
    rate = np.einsum("ij,ij->i", gyro, down)
    total = 0.0
    for run in runs:
        turned_gyro = float(np.sum(rate[run]) / rate_hz)
        total += turned_gyro - float(yaw[run.stop - 1] - yaw[run.start])
    return total


@dataclass(frozen=True, kw_only=True)
class WalkingSignals:
    """One recording's streams on the common clock, and where its wearer walks.

    The other streams start within a sample or two of the accelerometer (one
    clock on real phones, a jittered one each in simulation), so they are
    aligned by index and cut to the shortest.
    """

    accel: NDArray[np.float64]
    """(N, 3) specific force, phone frame."""
    norm: NDArray[np.float64]
    """(N,) ‖a‖."""
    walking: NDArray[np.bool_]
    runs: list[slice]
    gyro: NDArray[np.float64] | None
    rotation: NDArray[np.float64] | None
    """(N, 4) world←phone, sign-continuous."""
    spectrum: tuple[NDArray[np.float64], NDArray[np.float64]] | None
    """Run-weighted Welch spectrum of ‖a‖ over the walking runs (None: none long enough)."""


def walking_signals(rec: Recording, rate_hz: float = MOTION_RATE_HZ) -> WalkingSignals:
    """Put ``rec``'s motion streams on the common clock and find its walking."""
    acc = uniform_stream(rec.accel, ["x", "y", "z"], rate_hz)
    gyro = uniform_stream(rec.gyro, ["x", "y", "z"], rate_hz) if "gyro" in rec.streams else None
    rotation = None
    if "rotation" in rec.streams:
        # q and -q are one rotation: make the samples sign-continuous before filtering them.
        q = rec.rotation[["qw", "qx", "qy", "qz"]].to_numpy(dtype=float, copy=True)
        flips = np.concatenate([[False], np.einsum("ij,ij->i", q[1:], q[:-1]) < 0])
        q *= np.where(np.cumsum(flips) % 2 == 1, -1.0, 1.0)[:, None]
        continuous = pd.DataFrame(q, index=rec.rotation.index, columns=["qw", "qx", "qy", "qz"])
        rotation = uniform_stream(continuous, ["qw", "qx", "qy", "qz"], rate_hz)
    n = min(len(x) for x in (acc, gyro, rotation) if x is not None)
    acc = acc[:n]
    norm = np.linalg.norm(acc, axis=1)
    walking = walking_mask(norm, rate_hz)
    runs = _runs(walking)
    return WalkingSignals(
        accel=acc,
        norm=norm,
        walking=walking,
        runs=runs,
        gyro=None if gyro is None else gyro[:n],
        rotation=None if rotation is None else rotation[:n],
        spectrum=_mean_spectrum(norm, runs, rate_hz),
    )


def motion_statistics(rec: Recording) -> dict[str, float]:
    """The walking statistics of ``rec`` (see the module docstring for the keys)."""
    out = dict.fromkeys(MOTION_KEYS, math.nan)
    rate = MOTION_RATE_HZ
    sig = walking_signals(rec, rate)
    norm, walking, runs = sig.norm, sig.walking, sig.runs
    out["walking_s"] = float(walking.sum() / rate)
    out.update(held_phone_motion(rec, sig))
    if sig.spectrum is None:
        return out
    f, p = sig.spectrum
    step_hz = peak_frequency(f, p)
    out["step_hz"] = step_hz
    whole = band_power(f, p, *_POWER_BAND_HZ)
    for key, multiple in (("share_stride", 0.5), ("share_step", 1.0), ("share_2nd", 2.0)):
        centre = multiple * step_hz
        out[key] = band_power(f, p, centre - _HALF_WIDTH_HZ, centre + _HALF_WIDTH_HZ) / whole

    walked = norm[walking]
    out["acc_std"] = float(np.std(walked))
    out["acc_kurtosis"] = excess_kurtosis(walked)
    stride_s = 2.0 / step_hz
    out["acc_p2p"] = float(
        np.median(
            [peak_to_peak_per_period(norm[r], rate, stride_s) for r in runs if _long(r, stride_s)]
        )
    )
    window = round(_CREST_WINDOW_S * rate)
    crests = [
        crest_factor(norm[s : s + window])
        for r in runs
        for s in range(r.start, r.stop - window + 1, window)
    ]
    out["acc_crest"] = float(np.median(crests)) if crests else math.nan

    if "steps" in rec.streams and len(rec.steps):
        t0 = float(rec.accel.index[0])
        steps_t = (rec.steps.index.to_numpy(dtype=float) - t0) * rate
        in_walk = walking[np.clip(steps_t.astype(int), 0, len(walking) - 1)]
        if in_walk.any():
            out["cadence_ratio"] = step_hz / (in_walk.sum() / out["walking_s"])
    if sig.gyro is not None:
        rms = rms_per_axis(sig.gyro[walking])
        out["gyro_rms_1"], out["gyro_rms_2"], out["gyro_rms_3"] = (float(v) for v in rms)
    if sig.rotation is not None:
        out["heading_jitter"] = _heading_jitter_deg(sig.rotation, walking)
        if sig.gyro is not None:
            drift = gyro_heading_drift(sig.gyro, sig.accel, sig.rotation, runs, rate)
            strides = walking.sum() / rate * step_hz / 2
            out["gyro_drift"] = math.degrees(drift) / strides
    return out


HELD_KEYS = MOTION_KEYS[-10:]
"""Keys of :func:`held_phone_motion` (the last of :data:`MOTION_KEYS`)."""
HELD_MODE = "handheld"
"""The carrying mode whose phone is held top-forward: the only one they are judged in."""

STEP_BAND_HZ = (1.3, 2.8)
"""Where a window's step rate is looked for (its spectrum's peak), Hz."""


class StepWindows:
    """Hann-tapered windows of a walk's walking parts, 4 s long and half overlapping,
    and the projection that reads an amplitude at one frequency off each.

    A Hann taper: a reading at the stride rate must not pick up the step rate's
    (stronger) sidelobes, 0.9 Hz away in a 4 s window. ``freqs`` are the bins of
    the window's spectrum zero-padded eightfold (:meth:`spectrum`), where the step
    rate's peak is found.
    """

    def __init__(self, rate_hz: float = MOTION_RATE_HZ, seconds: float = 4.0) -> None:
        self.n = round(seconds * rate_hz)
        self.t = np.arange(self.n) / rate_hz
        self.taper = signal.windows.hann(self.n, sym=False)
        self.gain = 2.0 / self.taper.sum()
        self.freqs = np.fft.rfftfreq(8 * self.n, 1.0 / rate_hz)

    def over(self, x: NDArray[np.float64], runs: list[slice]) -> Iterator[NDArray[np.float64]]:
        """Each window of ``x`` (samples along axis 0) within ``runs``, less its mean,
        tapered."""
        n = self.n
        taper = self.taper.reshape(-1, *[1] * (x.ndim - 1))
        for run in runs:
            for start in range(run.start, run.stop - n + 1, n // 2):
                w = x[start : start + n] - x[start : start + n].mean(axis=0)
                w *= taper
                yield w

    def spectrum(self, w: NDArray[np.float64]) -> NDArray[np.complex128]:
        """A tapered window's spectrum, zero-padded eightfold, at :attr:`freqs`."""
        return np.fft.rfft(w, 8 * self.n, axis=0)

    def coefficient(self, w: NDArray[np.float64], hz: float) -> NDArray[np.complex128]:
        """Each column of a tapered window at ``hz`` as a complex amplitude (its modulus
        the amplitude, its angle the phase at the window's start), by projection."""
        return self.gain * (np.exp(-2j * np.pi * hz * self.t) @ w)

    def amplitude(self, w: NDArray[np.float64], hz: float) -> NDArray[np.float64]:
        """The amplitude of each column of a tapered window at ``hz``, by projection."""
        return np.abs(self.coefficient(w, hz))


def held_phone_motion(rec: Recording, sig: WalkingSignals | None = None) -> dict[str, float]:
    """How a phone held with its top forward moves within each step, while walking.

    The accelerometer and gyroscope are levelled by the phone's own fused
    attitude; "forward" is the phone's y axis levelled, "sideways" the horizontal
    across it. In 4 s windows of walking (half overlapping) the step rate is the
    vertical acceleration's peak at 1.3–2.8 Hz, and each of the first five keys is the
    median over windows of an amplitude (m/s², or rad/s for the yaw rate), read by
    projection of the Hann-tapered window on that frequency:

    ``surge_step``   forward acceleration at the step rate
    ``sway_stride``  sideways acceleration at the stride rate (half the step rate)
    ``bob_step``     vertical acceleration at the step rate
    ``yaw_stride``   rate of turn about the vertical at the stride rate
    ``sway_step``    sideways acceleration at the step rate
    ``roll_jerk``    correlation of the roll rate (about the phone's long axis, y)
                     with the sideways jerk (d a_x/dt), both in the phone's frame,
                     over the walking parts

    ``nod_2nd``       pitch rate (about the sideways axis) per vertical acceleration
                     at twice the step rate: |Σ P·A*| / Σ |A|² over the windows'
                     projections P and A there (rad/s per m/s²)
    ``bob_phase_2nd`` the vertical acceleration's second harmonic against its
                     fundamental, the angle of Σ A₂·A₁*² / (|A₂|·|A₁|²) (°, in
                     −180…180): 0 for a pulse symmetric about its peak
    ``surge_2nd``     forward acceleration at twice the step rate, the median
                     amplitude over windows as the first five (m/s²)

    ``roll_jerk`` tells what rolls the phone. Tilting it lets gravity into its x
    axis against the turn (a roll at ω_y changes a_x by −g·ω_y): left to that, the
    two are negatively correlated, as in the ILC traces' held phones. A phone
    rolled as a pendulum by the hand's sideways acceleration correlates
    positively.

    NaN without a rotation vector or gyroscope, or without a whole window. ``sig``:
    ``rec``'s :func:`walking_signals`, when already at hand.
    """
    out = dict.fromkeys(HELD_KEYS, math.nan)
    rate = MOTION_RATE_HZ
    sig = walking_signals(rec, rate) if sig is None else sig
    if sig.rotation is None or sig.gyro is None:
        return out
    q = sig.rotation / np.linalg.norm(sig.rotation, axis=1, keepdims=True)
    acc, gyro = quaternion.rotate(q, sig.accel), quaternion.rotate(q, sig.gyro)
    ahead = quaternion.rotate(q, np.array([0.0, 1.0, 0.0]))[:, :2]
    ahead /= np.linalg.norm(ahead, axis=1, keepdims=True)
    levelled = np.column_stack(
        [
            np.einsum("ij,ij->i", acc[:, :2], ahead),
            acc[:, 0] * ahead[:, 1] - acc[:, 1] * ahead[:, 0],
            acc[:, 2],
            gyro[:, 2],
            gyro[:, 0] * ahead[:, 1] - gyro[:, 1] * ahead[:, 0],
        ]
    )
    windows = StepWindows(rate)
    band = (windows.freqs > STEP_BAND_HZ[0]) & (windows.freqs < STEP_BAND_HZ[1])
    rows, second = [], []
    for w in windows.over(levelled, sig.runs):
        step_hz = windows.freqs[band][np.argmax(np.abs(windows.spectrum(w[:, 2]))[band])]
        at_step = windows.coefficient(w, step_hz)
        at_stride = windows.amplitude(w, step_hz / 2.0)
        at_2nd = windows.coefficient(w, 2.0 * step_hz)
        rows.append([abs(at_step[0]), at_stride[1], abs(at_step[2]), at_stride[3], abs(at_step[1])])
        second.append((at_step[2], at_2nd[2], at_2nd[4], abs(at_2nd[0]), at_step[0]))
    if rows:
        out.update(zip(HELD_KEYS[:5], np.median(rows, axis=0).tolist(), strict=True))
        out["roll_jerk"] = roll_jerk_correlation(sig.accel, sig.gyro, sig.runs, rate)
        bob, bob_2nd, nod_2nd, surge_2nd, surge = (np.array(c) for c in zip(*second, strict=True))
        out["surge_2nd"] = float(np.median(surge_2nd))
        power = float(np.sum(np.abs(bob_2nd) ** 2))
        if power > 0:
            out["nod_2nd"] = float(abs(np.sum(nod_2nd * np.conj(bob_2nd))) / power)
        out["bob_phase_2nd"] = _mean_phase_deg(bob_2nd * np.conj(bob) ** 2)
        out["surge_phase"] = _mean_phase_deg(surge * np.conj(bob))
    return out


def _mean_phase_deg(z: NDArray[np.complex128]) -> float:
    """The mean direction of the windows' complex products ``z``, each of unit weight
    (its angle alone counts, not its size), in degrees; NaN if every one is zero."""
    sizes = np.abs(z)
    if not (sizes > 0).any():
        return math.nan
    return math.degrees(np.angle(np.sum(z[sizes > 0] / sizes[sizes > 0])))


def roll_jerk_correlation(
    accel: NDArray[np.float64], gyro: NDArray[np.float64], runs: list[slice], rate_hz: float
) -> float:
    """Pearson correlation of the roll rate (``gyro[:, 1]``) with the sideways jerk
    (the time derivative of ``accel[:, 0]``) over the samples of ``runs``, each run
    differentiated on its own; NaN with fewer than three samples or no variation."""
    parts = [
        (gyro[run, 1], np.gradient(accel[run, 0]) * rate_hz)
        for run in runs
        if run.stop - run.start >= 3
    ]
    if not parts:
        return math.nan
    roll = np.concatenate([p[0] for p in parts])
    jerk = np.concatenate([p[1] for p in parts])
    if roll.std() == 0 or jerk.std() == 0:
        return math.nan
    return float(np.corrcoef(roll, jerk)[0, 1])


PROFILE_HIST_EDGES = np.linspace(0.0, 40.0, 81)
"""Bins of the ‖a‖ histogram (m/s²)."""

PROFILE_STRIDE_X = np.linspace(-0.5, 1.5, 81)
"""Where the stride profile is read: strides from each stride's largest ‖a‖ peak."""


def _peak_offset(x: NDArray[np.float64], k: int) -> float:
    """Where the parabola through samples k − 1, k, k + 1 peaks, relative to k."""
    if 0 < k < len(x) - 1:
        denom = x[k - 1] - 2.0 * x[k] + x[k + 1]
        if denom < 0:
            return float(0.5 * (x[k - 1] - x[k + 1]) / denom)
    return 0.0


def stride_profile(
    norm: NDArray[np.float64], runs: list[slice], step_hz: float, rate_hz: float = MOTION_RATE_HZ
) -> NDArray[np.float64] | None:
    """Median ‖a‖ over a walk's strides, each aligned on its largest peak, at
    :data:`PROFILE_STRIDE_X` (m/s²); None without two whole strides.

    A carrying mode's signature within the gait cycle: a pocket's jolt at its own
    heel strike and what the thigh does after it, a swinging arm's two passes,
    a held phone's two steps. Within each run, each stride's largest sample
    (refined between samples by a parabola) is found in the stride that starts
    half a stride after the last one, so the peaks stay on one foot.
    """
    period = 2.0 * rate_hz / step_hz  # samples per stride
    segments = []
    for run in runs:
        x = norm[run]
        grid = np.arange(len(x))
        start = 0.5 * period
        while start + 2.5 * period < len(x):
            lo = round(start)
            k = lo + int(np.argmax(x[lo : lo + round(period)]))
            peak = k + _peak_offset(x, k)
            segments.append(np.interp(peak + PROFILE_STRIDE_X * period, grid, x))
            start = peak + 0.5 * period
    return np.median(segments, axis=0) if len(segments) >= 2 else None


def motion_profiles(rec: Recording) -> dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Curves to overlay real and simulated walks: (x, y) by name.

    ``accel_psd`` and ``gyro_psd``: run-weighted Welch spectra of ‖a‖ and ‖ω‖
    over the walking runs (Hz, power per Hz); ``accel_hist``: density of ‖a‖
    over the walking samples (bin centres in m/s²); ``accel_stride``: ‖a‖ over
    a stride (:func:`stride_profile`). Missing streams are left out.
    """
    sig = walking_signals(rec)
    out: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}
    if sig.spectrum is None:
        return out
    out["accel_psd"] = sig.spectrum
    if sig.gyro is not None:
        gyro_psd = _mean_spectrum(np.linalg.norm(sig.gyro, axis=1), sig.runs, MOTION_RATE_HZ)
        if gyro_psd is not None:
            out["gyro_psd"] = gyro_psd
    density, _ = np.histogram(sig.norm[sig.walking], bins=PROFILE_HIST_EDGES, density=True)
    out["accel_hist"] = (0.5 * (PROFILE_HIST_EDGES[1:] + PROFILE_HIST_EDGES[:-1]), density)
    step_hz = peak_frequency(*sig.spectrum)
    if math.isfinite(step_hz):
        profile = stride_profile(sig.norm, sig.runs, step_hz)
        if profile is not None:
            out["accel_stride"] = (PROFILE_STRIDE_X, profile)
    return out


def _long(run: slice, period_s: float) -> bool:
    return (run.stop - run.start) / MOTION_RATE_HZ >= 2 * period_s
