"""Sensor error models: from the true signals to what a phone's sensors report.

Each function takes the ideal signal a perfect sensor would see (computed
elsewhere from the phone's true pose and the site's fields), a
:mod:`~indoorsim.phone.devices` spec, and an explicit
:class:`numpy.random.Generator`; none uses global randomness, so the same seed
gives the same bytes. Inside a call every error component draws from its own
child stream (``rng.spawn``), so switching one error off, or changing its size,
leaves the realisations of the others unchanged — two profiles run with one
seed differ only where their specs differ.

* :func:`sample_times` — a continuous sensor's own timestamps: nominal period,
  timestamp jitter, rare gaps of 1–3 dropped samples (REALISM §1.3).
* :class:`InertialErrors`, :func:`apply_inertial` — accelerometer and gyroscope:
  scale factor, misalignment, turn-on bias, Gauss–Markov bias instability,
  rate random walk, white noise, saturation, quantisation.
* :class:`MagnetometerErrors`, :func:`apply_magnetometer` — residual soft and
  hard iron after Android's calibration, white noise, saturation, quantisation.
* :func:`light_events` — an integrating ambient light sensor that reports on change.
* :func:`wifi_scans`, :func:`scan_rss` — scan timing with Android's throttling,
  per-scan fading, detection threshold, 1 dB reports.

Two conventions shared by the continuous sensors:

* **White noise follows the actual sample spacing.** Sample k is treated as the
  mean of the sensor's white noise over its own interval Δt_k = t_k − t_{k−1},
  so its σ is N/√Δt_k (N the noise density). An integrator that weights each
  sample by its Δt_k then sees exactly the angle (or velocity) random walk
  N·√T whatever the jitter and gaps, and the Allan deviation of the white part
  is N/√τ.
* **Slow processes run on the hardware clock.** The bias instability and the
  random walk evolve on a regular grid of ticks at ``rate_hz`` from the first
  sample; each sample takes the value at its nearest tick. Dropped samples and
  pauses therefore let the bias drift as real time passes, and timestamp jitter
  (timestamping noise on Android, not irregular sampling) leaves their
  statistics untouched. ``t`` should be one continuous record at about the
  sensor's rate (as :func:`sample_times` makes): the grid spans it at ``rate_hz``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numba
import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_trapezoid
from scipy.signal import lfilter

from indoorsim.phone.devices import InertialSpec, LightSensorSpec, MagnetometerSpec, WifiSpec

__all__ = [
    "MAX_JITTER_FRAC",
    "THROTTLE_MAX_SCANS",
    "THROTTLE_WINDOW_S",
    "InertialErrors",
    "MagnetometerErrors",
    "apply_inertial",
    "apply_magnetometer",
    "light_events",
    "sample_times",
    "scan_rss",
    "wifi_scans",
]

THROTTLE_WINDOW_S = 120.0
"""Android 9+ foreground throttling window, s (REALISM §4.3)."""
THROTTLE_MAX_SCANS = 4
"""Scans a foreground app may start within one throttling window (REALISM §4.3)."""
MAX_JITTER_FRAC = 0.2
"""Largest timestamp jitter accepted, as a fraction of the period (the CDD asks for < 0.03)."""
MAX_GAP_SAMPLES = 3
"""Longest run of samples one gap drops (REALISM §1.3: gaps of 1–3 samples)."""

# Timestamp offsets are bounded to this fraction of a period, so consecutive
# timestamps can never swap or coincide (at the CDD's 3 % it is a 21σ bound).
_JITTER_BOUND = 0.45
# Relative slack on the event-rate cap, so conversions on a float grid exactly
# 1/max_rate apart are not refused for a last-bit rounding difference.
_RATE_CAP_SLACK = 1e-9


# --------------------------------------------------------------------------- timing


def sample_times(
    duration_s: float,
    rate_hz: float,
    jitter_frac: float,
    rng: np.random.Generator,
    start: float = 0.0,
    *,
    gap_probability: float = 0.0,
) -> NDArray[np.float64]:
    """Timestamps of a continuous sensor over ``[start, start + duration_s)``, s.

    Sample k is due at ``start + k·P`` with P = 1/``rate_hz``. Its timestamp is
    offset by e_k ~ N(0, (jitter_frac·P)²/2), independently per sample (noisy
    timestamping around a steady clock, not a drifting clock), so consecutive
    intervals have σ(Δt) = jitter_frac·P — the quantity the Android CDD bounds.
    Offsets are bounded to ±0.45·P so timestamps stay strictly increasing. The
    first sample is the clock's reference (no offset), so nothing precedes ``start``.

    With ``gap_probability`` p, each sample starts a gap with probability p; a
    gap drops that sample and the next ones, 1–3 in all with equal chance
    (overlapping gaps merge).

    Args:
        duration_s: length of the record, s.
        rate_hz: nominal sample rate, Hz.
        jitter_frac: σ(Δt)/P, in [0, ``MAX_JITTER_FRAC``].
        rng: random source.
        start: time of the first sample, s.
        gap_probability: chance per sample that a gap starts there, in [0, 1).

    Returns:
        (K,) strictly increasing timestamps, K ≈ ``duration_s·rate_hz·(1 − 2p)``.
    """
    if not duration_s >= 0:
        raise ValueError(f"duration_s must be >= 0, got {duration_s}")
    if not rate_hz > 0:
        raise ValueError(f"rate_hz must be > 0, got {rate_hz}")
    if not 0 <= jitter_frac <= MAX_JITTER_FRAC:
        raise ValueError(f"jitter_frac must be in [0, {MAX_JITTER_FRAC}], got {jitter_frac}")
    if not 0 <= gap_probability < 1:
        raise ValueError(f"gap_probability must be in [0, 1), got {gap_probability}")
    jitter_rng, gap_rng = rng.spawn(2)
    period = 1.0 / rate_hz
    # The slack keeps a float product like 1.1·100 = 110.00000000000001 from adding a sample.
    n = max(0, math.ceil(duration_s * rate_hz - 1e-9))
    t = start + period * np.arange(n)
    if jitter_frac > 0 and n > 1:
        offset = jitter_rng.normal(0.0, jitter_frac * period / math.sqrt(2), n - 1)
        t[1:] += np.clip(offset, -_JITTER_BOUND * period, _JITTER_BOUND * period)
    if gap_probability > 0 and n > 0:
        first = np.flatnonzero(gap_rng.random(n) < gap_probability)
        length = gap_rng.integers(1, MAX_GAP_SAMPLES + 1, size=first.size)
        # Index of every dropped sample: each gap's first index plus 0 … length − 1.
        within = np.arange(length.sum()) - np.repeat(np.cumsum(length) - length, length)
        dropped = np.repeat(first, length) + within
        keep = np.ones(n, dtype=bool)
        keep[dropped[dropped < n]] = False
        t = t[keep]
    return t


def _samples(ideal: ArrayLike, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``ideal`` as (K, 3) and ``t`` as (K,) float64 arrays, checked."""
    x = np.asarray(ideal, dtype=np.float64)
    times = np.asarray(t, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"the ideal signal must have shape (K, 3), got {x.shape}")
    if times.shape != (x.shape[0],):
        raise ValueError(f"t must have shape ({x.shape[0]},), got {times.shape}")
    if np.any(np.diff(times) <= 0):
        raise ValueError("t must be strictly increasing")
    return x, times


def _white_noise(
    t: NDArray[np.float64], density: float, rate_hz: float, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """White noise of density ``density``: (K, 3) standard normals ξ and (K,) σ_k = density/√Δt_k.

    The noise is σ_k·ξ_k (formed where it is added: :func:`_add_terms`). The
    first sample's interval is taken as the nominal period 1/``rate_hz``.
    """
    spacing = np.diff(t, prepend=t[0] - 1.0 / rate_hz)
    return rng.standard_normal((t.size, 3)), density / np.sqrt(spacing)


# An error term that is off (see _add_terms).
_NO_ROWS = np.zeros((0, 3))
_NO_VALUES = np.zeros(0)
_NO_TICKS = np.zeros(0, np.int64)


@numba.njit(cache=True, error_model="numpy")
def _add_terms(y, offset, table, tick, xi, sigma):  # pragma: no cover - compiled
    """y_k += offset, then += table[tick_k], then += σ_k·ξ_k, in one pass over y.

    A term given as an empty array is off and not added at all (adding 0 would
    turn a −0 into +0). Each element takes the same additions, in the same
    order, as the ``y += …`` statements would, without their (K, 3) temporaries.
    """
    has_offset, has_table, has_noise = offset.shape[0] > 0, tick.shape[0] > 0, xi.shape[0] > 0
    for k in range(y.shape[0]):
        for j in range(3):
            v = y[k, j]
            if has_offset:
                v += offset[j]
            if has_table:
                v += table[tick[k], j]
            if has_noise:
                v += xi[k, j] * sigma[k]
            y[k, j] = v


def _digitise(y: NDArray[np.float64], limit: float, step: float) -> NDArray[np.float64]:
    """Q(sat(y)): clip to ±``limit`` (if finite), then round to multiples of ``step`` (if > 0).

    Works in place on ``y`` (the caller's own array) and returns it.
    """
    if math.isfinite(limit):
        np.clip(y, -limit, limit, out=y)
    if step > 0:
        # step·round(y/step), in place.
        np.divide(y, step, out=y)
        np.round(y, out=y)
        np.multiply(step, y, out=y)
    return y


# --------------------------------------------------------------------------- inertial


@dataclass(frozen=True, kw_only=True, eq=False)
class InertialErrors:
    """The errors an accelerometer or gyroscope keeps for a whole run.

    Drawn once per device and run (:meth:`draw`), or given explicitly to
    reproduce a known unit. U is the sensor's unit (m/s² or rad/s).

    Attributes:
        turn_on_bias: (3,) b_on, U.
        scale_factor: (3,) diagonal of S, fractional errors (0.01 = +1 %).
        misalignment: (3, 3) M with a zero diagonal, rad: M[i, j] is how much of
            true axis j leaks into sensed axis i (misalignment and non-orthogonality).
    """

    turn_on_bias: NDArray[np.float64]
    scale_factor: NDArray[np.float64]
    misalignment: NDArray[np.float64]

    def __post_init__(self) -> None:
        for name, shape in (
            ("turn_on_bias", (3,)),
            ("scale_factor", (3,)),
            ("misalignment", (3, 3)),
        ):
            value = np.array(getattr(self, name), dtype=np.float64)
            if value.shape != shape:
                raise ValueError(
                    f"InertialErrors.{name} must have shape {shape}, got {value.shape}"
                )
            value.flags.writeable = False
            object.__setattr__(self, name, value)
        if np.any(np.diag(self.misalignment)):
            raise ValueError(
                "InertialErrors.misalignment must have a zero diagonal "
                "(axis gain errors belong in scale_factor)"
            )

    @classmethod
    def draw(cls, spec: InertialSpec, rng: np.random.Generator) -> InertialErrors:
        """Draw one unit's errors: every entry Gaussian with the spec's 1σ."""
        z = rng.standard_normal(12)
        misalignment = np.zeros((3, 3))
        misalignment[~np.eye(3, dtype=bool)] = spec.misalignment_sigma_rad * z[6:]
        return cls(
            turn_on_bias=spec.turn_on_bias_sigma * z[:3],
            scale_factor=spec.scale_factor_sigma * z[3:6],
            misalignment=misalignment,
        )

    @property
    def distortion(self) -> NDArray[np.float64]:
        """S + M, the (3, 3) departure of the sensor's axes from the identity."""
        return np.diag(self.scale_factor) + self.misalignment


def apply_inertial(
    ideal: ArrayLike,
    t: ArrayLike,
    spec: InertialSpec,
    rng: np.random.Generator,
    *,
    errors: InertialErrors | None = None,
) -> NDArray[np.float64]:
    """What an accelerometer or gyroscope reports for the ideal signal ``ideal``.

    The error model, per sample k (x_k the ideal 3-vector in the phone frame):

        y_k = Q(sat((I + S + M)·x_k + b_on + b_GM(t_k) + b_RW(t_k) + w_k))

    * S = diag(s), M: scale-factor and misalignment matrices, b_on: turn-on
      bias — all fixed for the run (:class:`InertialErrors`).
    * b_GM: first-order Gauss–Markov bias, stationary σ = ``bias_instability``,
      correlation time T_c = ``bias_correlation_s``. On the hardware clock
      (period P): b[n] = φ·b[n−1] + σ·√(1 − φ²)·ξ[n], φ = exp(−P/T_c), started
      from its stationary distribution; generated with ``scipy.signal.lfilter``.
    * b_RW: rate random walk, b[n] = b[n−1] + K·√P·ξ[n], b = 0 at the first
      sample (the turn-on bias holds the initial value), K = ``random_walk``.
    * w_k: white noise, σ_k = N/√Δt_k with N = ``noise_density`` and Δt_k the
      actual spacing before sample k (σ = N·√rate at the nominal spacing).
    * sat: clip to ±``range``; Q: round to multiples of ``resolution``.

    ξ are independent standard normals. Error terms that are exactly zero are
    skipped, so the ``ideal`` profile returns ``ideal`` bit for bit.

    Args:
        ideal: (K, 3) true specific force (m/s²) or angular rate (rad/s), phone frame.
        t: (K,) strictly increasing sample times, s (from :func:`sample_times`).
        spec: the sensor's error specification.
        rng: random source.
        errors: this unit's fixed errors; drawn from ``spec`` when None.

    Returns:
        (K, 3) reported values, in the unit of ``ideal``.
    """
    x, times = _samples(ideal, t)
    errors_rng, gm_rng, rw_rng, white_rng = rng.spawn(4)
    if errors is None:
        errors = InertialErrors.draw(spec, errors_rng)
    y = x.copy()
    if x.shape[0] == 0:
        return y
    distortion = errors.distortion
    if distortion.any():
        y += x @ distortion.T
    table, tick = _NO_ROWS, _NO_TICKS
    if spec.bias_instability > 0 or spec.random_walk > 0:
        table, tick = _slow_bias(times, spec, gm_rng, rw_rng)
    xi, sigma = _NO_ROWS, _NO_VALUES
    if spec.noise_density > 0:
        xi, sigma = _white_noise(times, spec.noise_density, spec.rate_hz, white_rng)
    # y += b_on; y += b_GM + b_RW; y += w, in one pass.
    offset = errors.turn_on_bias if errors.turn_on_bias.any() else _NO_VALUES
    _add_terms(y, offset, table, tick, xi, sigma)
    return _digitise(y, spec.range, spec.resolution)


def _slow_bias(
    t: NDArray[np.float64],
    spec: InertialSpec,
    gm_rng: np.random.Generator,
    rw_rng: np.random.Generator,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """b_GM + b_RW on the hardware clock, (ticks, 3), and each sample's nearest tick, (K,).

    Sample k's slow bias is ``table[tick[k]]``.
    """
    period = 1.0 / spec.rate_hz
    tick = np.rint((t - t[0]) * spec.rate_hz).astype(np.int64)
    n = int(tick[-1]) + 1
    bias = np.zeros((n, 3))
    if spec.bias_instability > 0:
        sigma, tau = spec.bias_instability, spec.bias_correlation_s
        phi = math.exp(-period / tau)
        # σ·√(1 − φ²) keeps the variance at σ²; expm1 keeps it accurate when P ≪ T_c.
        drive = sigma * math.sqrt(-math.expm1(-2.0 * period / tau))
        initial = sigma * gm_rng.standard_normal(3)
        xi = gm_rng.standard_normal((n, 3))
        bias += lfilter([drive], [1.0, -phi], xi, axis=0, zi=phi * initial[None, :])[0]
    if spec.random_walk > 0:
        steps = rw_rng.standard_normal((n, 3))
        steps *= spec.random_walk * math.sqrt(period)
        steps[0] = 0.0
        bias += np.cumsum(steps, axis=0, out=steps)
    return bias, tick


# --------------------------------------------------------------------------- magnetometer


@dataclass(frozen=True, kw_only=True, eq=False)
class MagnetometerErrors:
    """The calibration residuals a magnetometer keeps for a whole run.

    Attributes:
        hard_iron_uT: (3,) residual hard-iron offset h, µT.
        soft_iron: (3, 3) symmetric residual soft-iron perturbation A; the
            sensor sees (I + A)·B.
    """

    hard_iron_uT: NDArray[np.float64]
    soft_iron: NDArray[np.float64]

    def __post_init__(self) -> None:
        for name, shape in (("hard_iron_uT", (3,)), ("soft_iron", (3, 3))):
            value = np.array(getattr(self, name), dtype=np.float64)
            if value.shape != shape:
                raise ValueError(
                    f"MagnetometerErrors.{name} must have shape {shape}, got {value.shape}"
                )
            value.flags.writeable = False
            object.__setattr__(self, name, value)
        # A soft-iron map is a symmetric ellipsoid distortion; a rotation is not soft iron.
        if not np.array_equal(self.soft_iron, self.soft_iron.T):
            raise ValueError("MagnetometerErrors.soft_iron must be symmetric")

    @classmethod
    def draw(cls, spec: MagnetometerSpec, rng: np.random.Generator) -> MagnetometerErrors:
        """Draw one unit's residuals: every entry Gaussian with the spec's 1σ, except a
        hard-iron offset the spec fixes (the same draws are made either way)."""
        z = rng.standard_normal(9)
        soft = np.diag(spec.soft_iron_diag_sigma * z[:3])
        upper = np.triu_indices(3, 1)
        soft[upper] = spec.soft_iron_offdiag_sigma * z[3:6]
        soft[upper[::-1]] = soft[upper]
        hard = spec.hard_iron_sigma_uT * z[6:]
        if spec.hard_iron_uT is not None:
            hard = np.array(spec.hard_iron_uT, dtype=float)
        return cls(hard_iron_uT=hard, soft_iron=soft)


def apply_magnetometer(
    ideal_uT: ArrayLike,
    t: ArrayLike,
    spec: MagnetometerSpec,
    rng: np.random.Generator,
    *,
    errors: MagnetometerErrors | None = None,
) -> NDArray[np.float64]:
    """What the calibrated magnetometer (``TYPE_MAGNETIC_FIELD``) reports.

    The error model, per sample k (B_k the true field in the phone frame):

        y_k = Q(sat((I + A)·B_k + h + w_k))

    * A: symmetric residual soft iron, h: residual hard iron — fixed for the
      run (:class:`MagnetometerErrors`), what Android's online calibration leaves.
    * w_k: white noise; ``noise_sigma_uT`` is σ at the nominal rate, scaled
      as σ·√(P/Δt_k) with the actual spacing Δt_k (the shared white-noise
      convention of this module).
    * sat: clip to ±``range_uT``; Q: round to multiples of ``resolution_uT``.

    Args:
        ideal_uT: (K, 3) true magnetic field in the phone frame, µT.
        t: (K,) strictly increasing sample times, s.
        spec: the magnetometer's error specification.
        rng: random source.
        errors: this unit's residuals; drawn from ``spec`` when None.

    Returns:
        (K, 3) reported field, µT.
    """
    x, times = _samples(ideal_uT, t)
    errors_rng, white_rng = rng.spawn(2)
    if errors is None:
        errors = MagnetometerErrors.draw(spec, errors_rng)
    y = x.copy()
    if x.shape[0] == 0:
        return y
    if errors.soft_iron.any():
        y += x @ errors.soft_iron.T
    xi, sigma = _NO_ROWS, _NO_VALUES
    if spec.noise_sigma_uT > 0:
        density = spec.noise_sigma_uT / math.sqrt(spec.rate_hz)
        xi, sigma = _white_noise(times, density, spec.rate_hz, white_rng)
    # y += h; y += w, in one pass.
    offset = errors.hard_iron_uT if errors.hard_iron_uT.any() else _NO_VALUES
    _add_terms(y, offset, _NO_ROWS, _NO_TICKS, xi, sigma)
    return _digitise(y, spec.range_uT, spec.resolution_uT)


# --------------------------------------------------------------------------- light


def light_events(
    t_fine: ArrayLike,
    lux_fine: ArrayLike,
    spec: LightSensorSpec,
    rng: np.random.Generator,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The events an ambient light sensor (Android ``TYPE_LIGHT``) delivers.

    1. Conversions: the sensor converts back to back, one every
       T = ``integration_time_s`` from ``t_fine[0]``; each reads the mean
       illuminance over the preceding T (trapezoidal integral of the fine
       signal). With T = 0 it reads ``lux_fine`` at every fine sample.
    2. Each reading gets multiplicative Gaussian noise of relative σ
       ``relative_noise``, is clipped to [0, ``range_lux``] and rounded to
       multiples of ``resolution_lux``.
    3. Reporting: with ``on_change``, a conversion is reported only when it
       differs from the last reported value by at least
       ``change_threshold_frac`` of it (and differs at all); the first
       conversion is always reported, as Android delivers an initial event.
       Events closer than 1/``max_event_rate_hz`` to the last event are dropped,
       not delayed. Both rules depend on the last event, so this step loops
       over the conversions (a few per second).

    The ``ideal`` spec reports every fine sample with its exact value.

    Args:
        t_fine: (K,) strictly increasing times of the true illuminance, s,
            sampled finer than the integration time.
        lux_fine: (K,) true illuminance on the sensor, lux.
        spec: the light sensor's specification.
        rng: random source.

    Returns:
        (event times (E,), s; reported illuminance (E,), lux).
    """
    t = np.asarray(t_fine, dtype=np.float64)
    lux = np.asarray(lux_fine, dtype=np.float64)
    if t.ndim != 1 or lux.shape != t.shape:
        raise ValueError(
            f"t_fine and lux_fine must be 1-D of equal length, got {t.shape}, {lux.shape}"
        )
    if t.size == 0:
        return t.copy(), lux.copy()
    if np.any(np.diff(t) <= 0):
        raise ValueError("t_fine must be strictly increasing")
    window = spec.integration_time_s
    if window > 0:
        n = math.floor((t[-1] - t[0]) / window + 1e-9)
        t_conv = t[0] + window * np.arange(1, n + 1)
        integral = cumulative_trapezoid(lux, t, initial=0.0)
        reading = (
            np.interp(t_conv, t, integral) - np.interp(t_conv - window, t, integral)
        ) / window
    else:
        t_conv, reading = t.copy(), lux.copy()
    if spec.relative_noise > 0:
        reading = reading * (1.0 + spec.relative_noise * rng.standard_normal(reading.size))
    reading = np.clip(reading, 0.0, spec.range_lux)
    if spec.resolution_lux > 0:
        reading = spec.resolution_lux * np.round(reading / spec.resolution_lux)
    keep = _reported(t_conv, reading, spec)
    return t_conv[keep], reading[keep]


def _reported(
    t: NDArray[np.float64], value: NDArray[np.float64], spec: LightSensorSpec
) -> NDArray[np.bool_]:
    """Mask of the conversions the driver reports (on-change rule and rate cap)."""
    keep = np.zeros(t.size, dtype=bool)
    if not spec.on_change and math.isinf(spec.max_event_rate_hz):
        keep[:] = True
        return keep
    min_interval = (1.0 - _RATE_CAP_SLACK) / spec.max_event_rate_hz
    _report(t, value, min_interval, spec.on_change, spec.change_threshold_frac, keep)
    return keep


@numba.njit(cache=True, error_model="numpy")
def _report(t, value, min_interval, on_change, threshold, keep):  # pragma: no cover - compiled
    """Set ``keep`` where a conversion is reported: each decision depends on the last report."""
    last_t, last_value = -math.inf, math.nan  # last_t = −inf: nothing reported yet
    for i in range(t.shape[0]):
        if t[i] - last_t < min_interval:
            continue
        if on_change and last_t > -math.inf:
            change = abs(value[i] - last_value)
            if change == 0 or change < threshold * abs(last_value):
                continue
        keep[i] = True
        last_t, last_value = t[i], value[i]


# --------------------------------------------------------------------------- WiFi


def wifi_scans(
    duration_s: float, spec: WifiSpec, rng: np.random.Generator, start: float = 0.0
) -> NDArray[np.float64]:
    """Times at which scan results arrive during ``[start, start + duration_s)``, s.

    The app requests a scan every ``scan_interval_s`` from ``start`` or, with
    ``continuous``, at ``start`` and then whenever a scan's results arrive
    (retrying a refused request ``scan_interval_s`` later). With
    ``throttling`` a request is refused when the app already started
    ``THROTTLE_MAX_SCANS`` (4) scans in the last ``THROTTLE_WINDOW_S`` (120 s) —
    Android 9+'s rule for a foreground app, a sliding window over accepted
    requests (REALISM §4.3) — so a 5 s request interval yields bursts of 4 scans
    every ≈ 2 minutes. Each accepted scan's results arrive ``scan_duration_s`` ±
    ``scan_duration_spread_s`` (uniform) after its request. Scans other apps or
    the system start are not modelled.

    Args:
        duration_s: length of the record, s.
        spec: WiFi scanning specification.
        rng: random source (scan durations).
        start: time of the first request, s.

    Returns:
        (S,) strictly increasing result times within the record, s.
    """
    if not duration_s >= 0:
        raise ValueError(f"duration_s must be >= 0, got {duration_s}")
    if spec.continuous:
        return _continuous_scans(duration_s, spec, rng, start)
    n = max(0, math.ceil(duration_s / spec.scan_interval_s - 1e-9))
    requests = start + spec.scan_interval_s * np.arange(n)
    if spec.throttling:
        requests = _throttle(requests)
    spread = spec.scan_duration_spread_s * rng.uniform(-1.0, 1.0, requests.size)
    done = requests + (spec.scan_duration_s + spread)
    return done[done < start + duration_s]


def _continuous_scans(
    duration_s: float, spec: WifiSpec, rng: np.random.Generator, start: float
) -> NDArray[np.float64]:
    """Result times of an app that requests each scan as the last one's results arrive."""
    end = start + duration_s
    accepted: list[float] = []
    done: list[float] = []
    request = start
    while request < end:
        throttled = (
            spec.throttling
            and len(accepted) >= THROTTLE_MAX_SCANS
            and request - accepted[-THROTTLE_MAX_SCANS] <= THROTTLE_WINDOW_S
        )
        if throttled:
            request += spec.scan_interval_s
            continue
        accepted.append(request)
        spread = spec.scan_duration_spread_s * rng.uniform(-1.0, 1.0)
        # A scan takes some time even where the profile gives none, so time moves on.
        request += max(spec.scan_duration_s + spread, 1e-3)
        done.append(request)
    out = np.array(done, dtype=np.float64)
    return out[out < end]


def _throttle(requests: NDArray[np.float64]) -> NDArray[np.float64]:
    """The requests Android's foreground throttle accepts (each depends on the earlier ones)."""
    accepted: list[float] = []
    for r in requests.tolist():
        if (
            len(accepted) < THROTTLE_MAX_SCANS
            or r - accepted[-THROTTLE_MAX_SCANS] > THROTTLE_WINDOW_S
        ):
            accepted.append(r)
    return np.array(accepted, dtype=np.float64)


def scan_rss(
    scan_times: ArrayLike,
    rss_mean: ArrayLike,
    bssids: Sequence[str],
    spec: WifiSpec,
    rng: np.random.Generator,
) -> pd.DataFrame:
    """The scan results a phone reports, one row per AP heard per scan.

    For scan s and AP a: r = Q(μ[s, a] + σ·ξ[s, a]), reported when r ≥ the
    detection threshold and the AP's beacon was not missed.

    * μ: received power at the phone's position during the scan (path loss,
      walls, the site's fixed shadowing and, from ``Site.rss(small_scale=True)``,
      the multipath fade of that exact spot), dBm. NaN or −inf: not heard.
    * σ·ξ: the reading's variation from scan to scan, Gaussian in dB,
      σ = ``fading_sigma_db``, independent between scans and APs: what a still
      phone sees as people move and the RSSI estimate wanders.
    * a miss: with ``miss_probability``, independently per scan and AP, the AP
      is left out of the scan (a lost beacon or probe response).
    * Q: rounding to multiples of ``quantisation_db`` (1 dB: whole dBm, as
      ``ScanResult.level``). The threshold applies to the reported value, so
      every reported RSS is ≥ ``detection_threshold_dbm``.

    Args:
        scan_times: (S,) times the scans' results arrive, s (:func:`wifi_scans`).
        rss_mean: (S, n_ap) mean RSS of each AP at each scan, dBm.
        bssids: (n_ap,) the APs' BSSIDs, in the column order of ``rss_mean``.
        spec: WiFi scanning specification.
        rng: random source.

    Returns:
        DataFrame with columns ``t`` (float64, s), ``bssid`` (str) and ``rss``
        (float64, dBm; whole numbers when quantised at 1 dB — float so that every
        profile, ``ideal`` included, shares one schema), ordered by scan, then
        by the order of ``bssids``.
    """
    t = np.asarray(scan_times, dtype=np.float64)
    rss = np.array(rss_mean, dtype=np.float64)
    ids = np.asarray(list(bssids), dtype=object)
    if t.ndim != 1 or rss.shape != (t.size, ids.size):
        raise ValueError(
            f"rss_mean must have shape (len(scan_times), len(bssids)) = ({t.size}, {ids.size}), "
            f"got {rss.shape}"
        )
    if spec.fading_sigma_db > 0:
        rss += spec.fading_sigma_db * rng.standard_normal(rss.shape)
    if spec.quantisation_db > 0:
        rss = spec.quantisation_db * np.round(rss / spec.quantisation_db)
    heard = np.isfinite(rss) & (rss >= spec.detection_threshold_dbm)
    if spec.miss_probability > 0:
        heard &= rng.random(rss.shape) >= spec.miss_probability
    scan_index, ap_index = np.nonzero(heard)
    return pd.DataFrame(
        {
            "t": t[scan_index],
            "bssid": pd.Series(ids[ap_index], dtype="str"),
            "rss": rss[heard],
        }
    )
