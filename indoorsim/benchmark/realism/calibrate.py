"""A digital twin of a phone and a walker: a device profile and walker fitted to a recording.

:func:`calibrate` reads what a recording shows about the phone that made it and
the person who carried it, with the same functions on a real log and on a
simulated one, so a simulated recording with known parameters checks the fit:

* **Rates and timing** (every continuous stream): the output rate is the
  median interval's inverse; the timestamp jitter the spread of the ordinary
  intervals (within ½–1½ of the median) over the median; a dropped run of
  samples is an interval longer than 1½ of it.
* **Noise** (accelerometer, gyroscope, magnetometer), from the parts where the
  phone is still (:func:`still_mask`): the white-noise floor of each axis's
  Welch spectrum over the top of the band (0.6–0.95 of Nyquist), above the
  hand's 8–12 Hz tremor and the body's sway, which a held phone still shows
  when its carrier stands. For white noise of density N sampled at f_s the
  one-sided spectrum is 2N², so N = √(S/2) (:class:`~indoorsim.phone.specs.InertialSpec`);
  the magnetometer's per-sample σ is √(S·f_s/2).
* **Gyroscope bias**: the mean rate per axis while still (the turn-on bias
  plus whatever drift has built up); the profile's ``turn_on_bias_sigma`` is
  its RMS over the axes, the one draw this recording shows.
* **Magnetometer's residual hard iron**: the offset Android's online
  calibration left, fitted from the walk's own magnetometer where the phone
  turns far enough at one tilt
  (:func:`~indoorsim.benchmark.realism.magnetic.hard_iron_residual`); its
  part along the vertical cannot be told while the phone's tilt stays put and
  is 0. The profile takes it as this unit's fixed offset (``mag.hard_iron_uT``).
* **Light and WiFi**: the light sensor's highest event rate, its resolution (the
  smallest step between reported values) and whether it reports on change (no
  two consecutive reports equal); the scan interval (median gap between scans)
  and the weakest RSS heard (the detection threshold).
* **Walker**: the step rate (the dominant frequency of ‖a‖ while walking,
  :mod:`indoorsim.benchmark.realism.motion`), the walking speed from the
  waypoints (their path length over the time walked between the first and the
  last), the step length (speed over step rate), the height that gives that
  step length at that speed in the gait model
  (:func:`~indoorsim.walker.gait.step_length_m`), how long the walker
  stood before the first step (the peak–valley detector's first step less the
  carrying mode's :data:`FIRST_STEP_LAG_S`) and after the last, and how far it turned while
  standing before the first (the gyro's turn about gravity; from
  :data:`START_TURN_MIN_DEG`); and, given the carrying mode,
  its vigour (the pelvis's bounce, its loading peak and the heel-strike jolts),
  fitted so that a straight walk in that mode shows the recording's ‖a‖ at the
  step rate, its second harmonic and what lies off the stride's lines
  (:mod:`indoorsim.benchmark.realism.vigour`).

Whatever a recording cannot show (scale factors, misalignment, bias
instability, soft iron, a hard iron without turns, the light sensor's angular
response, WiFi fading) is taken from a base profile and listed in
:attr:`Calibration.not_measured`. The result is written as YAML
(:func:`write_calibration`) with a ``device:`` and a ``walker:`` section:
``--device FILE`` and ``--walker FILE`` read it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml
from numpy.typing import NDArray
from scipy.signal import welch

from indoorsim.benchmark.realism.headings import gyro_heading
from indoorsim.benchmark.realism.magnetic import HARD_IRON_MIN_ARC_DEG, hard_iron_residual
from indoorsim.benchmark.realism.motion import walking_signals
from indoorsim.benchmark.realism.stats import long_runs, moving_std, peak_frequency
from indoorsim.benchmark.realism.vigour import FIGURES, VigourError, fit_vigour, single_mode
from indoorsim.estimators.pdr.steps import PeakStepDetector
from indoorsim.io.recording import Recording
from indoorsim.phone.devices import get_device
from indoorsim.phone.sensors import MAX_JITTER_FRAC
from indoorsim.phone.specs import DeviceProfile, device_from_dict, device_to_dict
from indoorsim.util.yaml_files import read_yaml_section
from indoorsim.walker.gait import WalkerParams, step_length_m
from indoorsim.walker.schedule import ScheduleLike

__all__ = [
    "Calibration",
    "CalibrationError",
    "calibrate",
    "load_walker",
    "still_mask",
    "stream_timing",
    "white_noise_density",
    "write_calibration",
]

STILL_WINDOW_S = 1.0
STILL_ACCEL_STD = 0.15
"""m/s²: below this moving std of ‖a‖ the phone is still, held or at rest (walking
is above 0.8, :func:`~indoorsim.benchmark.realism.stats.walking_mask`)."""
STILL_GYRO = 0.15
"""rad/s: and its turn rate below this (a held phone's tremor and sway stay under it)."""
MIN_STILL_S = 1.5
"""Still runs shorter than this are not used."""
NOISE_BAND = (0.6, 0.95)
"""Part of the band, as fractions of Nyquist, whose spectrum floor gives the white noise."""


class CalibrationError(ValueError):
    """A recording that cannot be calibrated (no accelerometer, nothing to measure)."""


@dataclass(frozen=True, kw_only=True)
class Calibration:
    """What :func:`calibrate` fitted.

    Attributes:
        device: the fitted device profile.
        walker: the fitted walker.
        measured: every figure measured, by name (the YAML's ``measured:`` section).
        not_measured: profile and walker fields taken from the base, and why.
    """

    device: DeviceProfile
    walker: WalkerParams
    measured: dict[str, float]
    not_measured: dict[str, str]


def stream_timing(t: NDArray[np.float64]) -> tuple[float, float, float]:
    """(rate Hz, timestamp jitter as a fraction of the period, dropped runs per sample)
    of a stream's timestamps ``t`` (s)."""
    dt = np.diff(np.asarray(t, dtype=float))
    dt = dt[dt > 0]
    if len(dt) < 10:
        return math.nan, math.nan, math.nan
    period = float(np.median(dt))
    ordinary = dt[(dt > 0.5 * period) & (dt < 1.5 * period)]
    jitter = float(np.std(ordinary) / period)
    gaps = float(np.count_nonzero(dt >= 1.5 * period) / (len(dt) + 1))
    return 1.0 / period, jitter, gaps


def still_mask(
    accel: NDArray[np.float64], gyro: NDArray[np.float64] | None, rate_hz: float
) -> NDArray[np.bool_]:
    """Samples where the phone is still: ‖a‖'s moving std under :data:`STILL_ACCEL_STD`
    and ‖ω‖ under :data:`STILL_GYRO` over :data:`STILL_WINDOW_S`, in runs of at least
    :data:`MIN_STILL_S` (each run's first and last half window trimmed)."""
    n = max(3, round(STILL_WINDOW_S * rate_hz))
    still = moving_std(np.linalg.norm(accel, axis=1), n) < STILL_ACCEL_STD
    if gyro is not None:
        turn = np.convolve(np.linalg.norm(gyro, axis=1), np.ones(n) / n, mode="same")
        still &= turn < STILL_GYRO
    return long_runs(still, rate_hz, MIN_STILL_S, trim=n // 2)


def white_noise_density(
    samples: list[NDArray[np.float64]], rate_hz: float
) -> tuple[float, NDArray[np.float64]]:
    """N (unit/√Hz, RMS over the axes) of the white noise in still runs ``samples``
    ((n, 3) each), from their Welch spectrum's floor over :data:`NOISE_BAND`; and the
    runs' mean per axis."""
    nyquist = rate_hz / 2
    floors, means, weights = [], [], []
    for run in samples:
        nperseg = min(len(run), round(rate_hz))
        if nperseg < 16:
            continue
        f, p = welch(run - run.mean(axis=0), fs=rate_hz, nperseg=nperseg, axis=0)
        band = (f >= NOISE_BAND[0] * nyquist) & (f <= NOISE_BAND[1] * nyquist)
        floors.append(np.median(p[band], axis=0))
        means.append(run.mean(axis=0))
        weights.append(len(run))
    if not floors:
        return math.nan, np.full(3, math.nan)
    w = np.asarray(weights, dtype=float)
    floor = np.average(np.asarray(floors), axis=0, weights=w)
    mean = np.average(np.asarray(means), axis=0, weights=w)
    return float(np.sqrt(np.mean(floor / 2.0))), mean


def _xyz(df: pd.DataFrame) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    return df.index.to_numpy(dtype=float), df[["x", "y", "z"]].to_numpy(dtype=float)


def _still_runs(
    t: NDArray[np.float64], values: NDArray[np.float64], still_t: NDArray[np.float64], step: float
) -> list[NDArray[np.float64]]:
    """The parts of a stream whose samples fall in still time (``still_t``: the still
    samples' times on a clock of ``step`` s), split where the stillness breaks."""
    if not len(still_t):
        return []
    idx = np.clip(np.searchsorted(still_t, t), 1, len(still_t) - 1)
    near = np.minimum(np.abs(still_t[idx] - t), np.abs(still_t[idx - 1] - t))
    inside = near <= step
    edges = np.flatnonzero(np.diff(np.concatenate([[0], inside.view(np.int8), [0]])))
    return [values[a:b] for a, b in zip(edges[::2], edges[1::2], strict=True) if b - a >= 16]


START_TURN_MIN_DEG = 5.0
"""A standing turn smaller than this is not fitted (deg): a calibrated gyro's leftover
bias turns a standing phone by a degree or two over a few seconds."""


FIRST_STEP_LAG_S: dict[str, float] = {
    "handheld": 0.42,
    "calling": 0.42,
    "dangling": 1.3,
    "pocketed": 0.42,
}
"""How long after the walker sets off the peak–valley detector finds its first step, s,
by carrying mode (medians over simulated walks that stood 3–8 s first, walks v7; on
walks v8, eight walks a mode: 0.41, 0.39, 1.02 s, the pocket 0.27 or 0.96; a
recording whose mode is not known takes the held phone's). The first heel strike
comes 0.8 s after setting off; held at the chest or the ear, the weight shift onto the
first stance leg before it, which leans the trunk, swings ‖a‖ enough to count
(0.40–0.46 s; before v7, with the trunk leaning the other way, it did not, and the
first step was the peak after that heel strike, 1.02–1.06 s). A swinging hand's
first counted step is either the peak after the first heel strike or the next
(on walks v11, six walkers: 1.00–1.01 or 1.58–1.66 s; on walks v10 mostly the first,
on v9 either, as now): the hand, its forearm pulled back under the elbow by gravity,
swings in gently, and the step it swings in on comes out as the shoulder's drive
lags the legs. A pocket's is either of two peaks (0.27–0.28 or 0.95–0.96 s). For both
the table gives a value between the two peaks, so a swinging or pocketed phone's
standing time is known to about a third of a second."""


def _first_step(rec: Recording) -> float | None:
    """Time of the peak–valley step detector's first step, or None if it finds none."""
    t = rec.accel.index.to_numpy(dtype=float)
    steps = PeakStepDetector().update(t, rec.accel[["x", "y", "z"]].to_numpy(dtype=float))
    return float(steps[0].t) if steps else None


def _standing_turn(rec: Recording, first_step: float) -> float | None:
    """How far the walker stood turned from where it set off, deg counter-clockwise: minus
    the gyro's turn about gravity from the recording's start to its first step (so a
    degree or two of the first second's walking sway is in it); None without a gyro
    or a standing start. The twin makes the turn over its whole standing time."""
    if "gyro" not in rec.streams or len(rec.gyro) < 10:
        return None
    t, heading = gyro_heading(rec)
    standing = int(np.searchsorted(t, first_step, side="right"))  # samples at or before it
    if standing < 2:
        return None
    return -math.degrees(float(heading[standing - 1]))


def _walker(
    rec: Recording, mode: str | None, measured: dict[str, float], not_measured: dict[str, str]
) -> dict:
    """Walker fields the recording shows (see the module docstring), carried in ``mode``
    (None: not known)."""
    sig = walking_signals(rec)
    rate = len(sig.norm) / max(rec.accel.index[-1] - rec.accel.index[0], 1e-9)
    fields: dict[str, Any] = {}
    if sig.spectrum is None or not sig.walking.any():
        not_measured["walker"] = "no walking part long enough to measure"
        return fields
    step_hz = peak_frequency(*sig.spectrum)
    measured["step_rate_hz"] = step_hz
    walk_idx = np.flatnonzero(sig.walking)
    t0 = float(rec.accel.index[0])
    # Standing before the first step: from the step detector, less its lag. The
    # walking mask (a moving spread of ‖a‖) reads a real phone handled in a standing
    # surveyor's hand as walking, and a walk's first second as standing.
    first_step = _first_step(rec)
    lag = FIRST_STEP_LAG_S.get(mode or "handheld", FIRST_STEP_LAG_S["handheld"])
    standing = walk_idx[0] / rate if first_step is None else first_step - t0 - lag
    fields["stand_start_s"] = round(float(max(0.0, standing)), 2)
    fields["stand_end_s"] = round(float((len(sig.walking) - 1 - walk_idx[-1]) / rate), 2)
    turn = None if first_step is None else _standing_turn(rec, first_step)
    if turn is not None:
        measured["start_turn_deg"] = turn
        if abs(turn) >= START_TURN_MIN_DEG and fields["stand_start_s"] > 0:
            fields["start_turn_deg"] = round(turn, 1)
            fields["start_turn_s"] = fields["stand_start_s"]
        elif abs(turn) >= START_TURN_MIN_DEG:
            not_measured["start_turn_deg"] = (
                f"turned {turn:.1f}° before the first step without standing: not fitted"
            )
    if "waypoints" not in rec.streams or len(rec.waypoints) < 2:
        not_measured["speed_mps"] = "no waypoints: the walking speed is not shown"
        not_measured["height_m"] = "no waypoints: the step length is not shown"
        return fields
    wp = rec.waypoints
    xy = wp[["x", "y"]].to_numpy(dtype=float)
    path_m = float(np.linalg.norm(np.diff(xy, axis=0), axis=1).sum())
    first, last = (float(v) - t0 for v in wp.index[[0, -1]])
    span = slice(max(0, round(first * rate)), min(len(sig.walking), round(last * rate) + 1))
    walked_s = float(sig.walking[span].sum() / rate)
    if walked_s <= 0 or path_m <= 0:
        not_measured["speed_mps"] = "no walking between the first and the last waypoint"
        return fields
    speed = path_m / walked_s
    step_m = speed / step_hz
    height = step_m / float(step_length_m(speed, 1.0))
    measured |= {"waypoint_path_m": path_m, "speed_mps": speed, "step_length_m": step_m}
    measured["height_m"] = height
    fields["speed_mps"] = round(float(np.clip(speed, 0.2, 3.0)), 3)
    fields["height_m"] = round(float(np.clip(height, 1.0, 2.3)), 3)
    if fields["height_m"] != round(height, 3):
        not_measured["height_m"] = f"the fitted {height:.2f} m is outside 1.0–2.3 m: clipped"
    return fields


def _carrying_mode(
    rec: Recording, mode: ScheduleLike | None
) -> tuple[list[tuple[float, str, dict]] | None, str]:
    """``mode`` (already one entry), else the recording's own where it names one carrying
    mode; with why there is none (empty when there is one)."""
    if mode is not None:
        return mode, ""
    own = rec.meta.get("mode")
    if own is None:
        return None, "carrying mode not known (pass mode): the defaults"
    try:
        return single_mode(own), ""
    except VigourError as err:
        return None, f"the recording's own {err}: the defaults"


def _vigour(
    rec: Recording,
    walker: WalkerParams,
    mode: list[tuple[float, str, dict]] | None,
    why_none: str,
    device: DeviceProfile,
    measured: dict[str, float],
    not_measured: dict[str, str],
) -> WalkerParams:
    """``walker`` with the bounce, loading peak and heel strikes ``rec`` shows in ``mode``
    (:func:`_carrying_mode`'s; None: the defaults, for ``why_none``)."""
    if mode is None:
        not_measured["walker vigour"] = why_none
        return walker
    try:
        fit = fit_vigour(rec, walker, mode, device)
    except VigourError as err:
        not_measured["walker vigour"] = f"{err}: the defaults"
        return walker
    for key, real, sim in zip(FIGURES, fit.target, fit.reached, strict=True):
        measured[key] = real
        measured[f"{key}_fitted_walk"] = sim
    misses = fit.misses()
    if misses:
        not_measured["walker vigour, in part"] = "not reached: " + "; ".join(misses)
    return fit.walker(walker)


def calibrate(
    rec: Recording,
    *,
    name: str = "calibrated",
    base: str | DeviceProfile = "mid_grade",
    mode: ScheduleLike | None = None,
) -> Calibration:
    """Fit a device profile and walker parameters to ``rec`` (see the module docstring).

    Args:
        rec: a real or simulated recording with at least an ``accel`` stream.
        name: the fitted profile's name.
        base: the profile whose figures stand where the recording shows nothing.
        mode: the carrying mode ``rec`` was made in, through which the walker's
            vigour is fitted (:func:`~indoorsim.benchmark.realism.vigour.fit_vigour`);
            None takes the recording's own (``meta["mode"]``, with that mode's
            default parameters) where it names one carrying mode, and otherwise
            leaves the vigour at the defaults (``not_measured`` says why, and where
            the fit fell short).

    Raises:
        CalibrationError: no accelerometer stream, or a ``mode`` that is not one
            carrying mode (a schedule of several cannot be replayed on the reference
            walk).
    """
    if "accel" not in rec.streams or len(rec.accel) < 10:
        raise CalibrationError("the recording has no accelerometer stream to calibrate from")
    if mode is not None:
        try:
            mode = single_mode(mode)
        except VigourError as err:
            raise CalibrationError(str(err)) from None
    base_profile = get_device(base) if isinstance(base, str) else base
    data = device_to_dict(base_profile)
    measured: dict[str, float] = {}
    not_measured: dict[str, str] = {}

    t_acc, acc = _xyz(rec.accel)
    rate_acc, jitter, gaps = stream_timing(t_acc)
    gyro_xyz = _xyz(rec.gyro) if "gyro" in rec.streams and len(rec.gyro) > 10 else None
    # Stillness on the accelerometer's clock, the gyroscope held to it by nearest sample.
    gyro_on_acc = None
    if gyro_xyz is not None:
        idx = np.clip(np.searchsorted(gyro_xyz[0], t_acc), 0, len(gyro_xyz[0]) - 1)
        gyro_on_acc = gyro_xyz[1][idx]
    still = still_mask(acc, gyro_on_acc, rate_acc)
    still_t = t_acc[still]
    measured["still_s"] = float(still.sum() / rate_acc)
    measured["timestamp_jitter_frac"] = jitter
    measured["gap_probability"] = gaps
    if jitter > MAX_JITTER_FRAC:
        # A phone whose clock scatters this much (an Oxford walk's, 0.21 of a period) is
        # simulated at the most the sampler takes; the measured figure stays above.
        not_measured["timestamp jitter"] = (
            f"{jitter:.3g} of the period, more than the simulator takes: held at {MAX_JITTER_FRAC}"
        )
        jitter = MAX_JITTER_FRAC
    data["timestamp_jitter_frac"] = round(jitter, 4)
    data["gap_probability"] = round(gaps, 6)

    streams = {"accel": (t_acc, acc)}
    if gyro_xyz is not None:
        streams["gyro"] = gyro_xyz
    if "mag" in rec.streams and len(rec.mag) > 10:
        streams["mag"] = _xyz(rec.mag)
    for key in ("accel", "gyro", "mag"):
        if key not in streams:
            not_measured[key] = "no such stream in the recording"
            continue
        t, values = streams[key]
        rate, _, _ = stream_timing(t)
        measured[f"{key}.rate_hz"] = rate
        data[key]["rate_hz"] = round(rate, 3)
        density, mean = white_noise_density(_still_runs(t, values, still_t, 1.0 / rate_acc), rate)
        if not math.isfinite(density):
            not_measured[f"{key} noise"] = "no still part of 1.5 s or more"
            continue
        if key == "mag":
            sigma = density * math.sqrt(rate)
            measured["mag.noise_sigma_uT"] = sigma
            data["mag"]["noise_sigma_uT"] = round(sigma, 4)
        else:
            measured[f"{key}.noise_density"] = density
            data[key]["noise_density"] = float(f"{density:.4g}")
        if key == "gyro":
            for axis, b in zip("xyz", mean, strict=True):
                measured[f"gyro.bias_{axis}"] = float(b)
            bias = float(np.sqrt(np.mean(mean**2)))
            data["gyro"]["turn_on_bias_sigma"] = float(f"{bias:.4g}")

    if "light" in rec.streams and len(rec.light) > 2:
        t = rec.light.index.to_numpy(dtype=float)
        lux = rec.light["lux"].to_numpy(dtype=float)
        dt = np.diff(t)
        steps = np.abs(np.diff(lux))
        data["light"]["max_event_rate_hz"] = round(float(1.0 / np.percentile(dt[dt > 0], 5)), 3)
        data["light"]["on_change"] = bool(np.count_nonzero(steps == 0) == 0)
        positive = steps[steps > 0]
        if len(positive):
            data["light"]["resolution_lux"] = float(f"{positive.min():.3g}")
        measured["light.events_per_s"] = float(len(t) / (t[-1] - t[0]))
    else:
        not_measured["light"] = "no light stream"
    if "wifi" in rec.streams and len(rec.wifi):
        scans = np.unique(rec.wifi.index.to_numpy(dtype=float))
        if len(scans) >= 3:
            interval = float(np.median(np.diff(scans)))
            measured["wifi.scan_interval_s"] = interval
            data["wifi"]["scan_interval_s"] = round(interval, 3)
            # A scan cannot outlast the interval: the base's duration shrinks to fit.
            wifi = data["wifi"]
            longest = wifi["scan_duration_s"] + wifi["scan_duration_spread_s"]
            if longest > 0.9 * interval:
                shrink = 0.9 * interval / longest
                wifi["scan_duration_s"] = round(wifi["scan_duration_s"] * shrink, 3)
                wifi["scan_duration_spread_s"] = round(wifi["scan_duration_spread_s"] * shrink, 3)
                not_measured["wifi.scan_duration_s"] = (
                    f"{base_profile.name}'s, shortened to fit the {interval:.2f} s interval"
                )
        weakest = float(rec.wifi["rss"].min())
        measured["wifi.weakest_rss_dbm"] = weakest
        data["wifi"]["detection_threshold_dbm"] = weakest
    else:
        not_measured["wifi"] = "no WiFi stream"
    for figure in (
        "scale_factor_sigma",
        "misalignment_sigma_rad",
        "bias_instability",
        "random_walk",
    ):
        not_measured[f"accel/gyro.{figure}"] = f"not shown by one recording: {base_profile.name}'s"
    iron = hard_iron_residual(rec)
    if iron is None:
        not_measured["mag hard iron"] = (
            f"not shown without turns of {HARD_IRON_MIN_ARC_DEG:.0f}° or more at one "
            f"tilt: {base_profile.name}'s spread"
        )
    else:
        data["mag"]["hard_iron_uT"] = [round(float(v), 2) for v in iron.offset_uT]
        for axis, v in zip("xyz", iron.offset_uT, strict=True):
            measured[f"mag.hard_iron_{axis}_uT"] = float(v)
        not_measured["mag hard iron along the vertical"] = "not shown at one tilt: 0"
    not_measured["mag soft iron"] = f"not shown without tilting: {base_profile.name}'s"
    not_measured["light angular response, wifi fading"] = f"{base_profile.name}'s"

    data["name"] = name
    source = rec.meta.get("source") or rec.meta.get("device") or "a recording"
    data["description"] = f"Fitted by indoorsim calibrate to {source}."
    data["sources"] = [
        "rates, timestamp jitter and gaps, white noise (still parts), gyro bias, light "
        "reporting, WiFi scan interval and threshold: measured [D]",
        f"everything else: the {base_profile.name} profile",
    ]
    device = device_from_dict(data, source="calibration")
    carried, why_none = _carrying_mode(rec, mode)
    name = None if carried is None else carried[0][1]
    walker = WalkerParams(**_walker(rec, name, measured, not_measured))
    walker = _vigour(rec, walker, carried, why_none, device, measured, not_measured)
    return Calibration(
        device=device,
        walker=walker,
        measured={k: float(v) for k, v in measured.items()},
        not_measured=not_measured,
    )


def _plain(value: Any) -> Any:
    """A walker field as YAML writes it (tuples as lists)."""
    return list(value) if isinstance(value, tuple) else value


def write_calibration(cal: Calibration, path: str | Path) -> Path:
    """Write ``cal`` as YAML: ``device:``, ``walker:`` (the fields that differ from the
    defaults), ``measured:`` and ``not_measured:``."""
    defaults = WalkerParams()
    walker = {
        f.name: _plain(getattr(cal.walker, f.name))
        for f in dataclasses.fields(WalkerParams)
        if getattr(cal.walker, f.name) != getattr(defaults, f.name)
    }
    doc = {
        "device": device_to_dict(cal.device),
        "walker": walker,
        "measured": {k: round(v, 6) for k, v in cal.measured.items()},
        "not_measured": dict(cal.not_measured),
    }
    out = Path(path)
    out.write_text(yaml.safe_dump(doc, sort_keys=False, allow_unicode=True), encoding="utf-8")
    return out


def load_walker(path: str | Path) -> WalkerParams:
    """The walker in a YAML file: WalkerParams fields, or under a ``walker:`` key (the
    layout :func:`write_calibration` writes).

    Raises:
        CalibrationError: unreadable file, unknown fields or values out of range.
    """
    source = Path(path)
    data = read_yaml_section(source, "walker", CalibrationError)
    if not isinstance(data, Mapping):
        raise CalibrationError(f"{source}: expected a mapping of walker fields")
    known = {f.name for f in dataclasses.fields(WalkerParams)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise CalibrationError(f"{source}: unknown walker field(s) {unknown}")
    try:
        return WalkerParams(**{k: tuple(v) if isinstance(v, list) else v for k, v in data.items()})
    except (TypeError, ValueError) as err:
        raise CalibrationError(f"{source}: {err}") from None
