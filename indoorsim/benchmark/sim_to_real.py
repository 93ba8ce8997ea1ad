"""Sim-to-real: what is tuned on indoorsim alone, measured on real phones.

**Real traces and their twins** (:func:`twin_table`): every estimator that runs
on a real log is scored on each Indoor Location Competition trace and on that
trace's simulated twins — the floor imported from the competition's plan, the
trace's waypoints as the route, the phone and walker fitted to the trace
(:mod:`~indoorsim.benchmark.realism.calibrate`) — the same way, at the
waypoints. The ratio of the real error to the simulated one, per estimator, and
whether the estimators rank alike (Kendall's τ) say how far a leaderboard
ranking carries over to real phones.

A real trace's truth is its surveyor's waypoint marks: the map position of a
waypoint, at the moment it was marked. The marks come before the walker reaches
the waypoint — at a corner, the gyro's turn is centred about 0.8 s after its
mark (:func:`waypoint_lead`) — so a twin is marked the same way
(:func:`as_real_log`): at the waypoint's position, the measured lead before it
passes there. Otherwise the real/sim ratio would also measure the real truth's
timing, which no estimator can follow.

Each estimated track is also scored turned about its start by the rotation that
lays it best on the marks (:func:`~indoorsim.benchmark.metrics.start_aligned_errors`),
which splits an error into a heading held wrong through the trace and the
track's shape; and each walk's long legs are read against its gyro
(:mod:`~indoorsim.benchmark.realism.headings`), which says how straight the
walker went from mark to mark — what a start heading taken from the first two
marks relies on.

**Step counts**: :mod:`~indoorsim.benchmark.step_transfer`.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.ndimage import uniform_filter1d
from scipy.stats import kendalltau

from indoorsim.benchmark.evaluation import (
    REAL_DATA_PARAMS,
    WalkResult,
    evaluate_recording,
    start_info,
)
from indoorsim.benchmark.metrics import start_aligned_errors, track_length
from indoorsim.benchmark.realism.calibrate import calibrate
from indoorsim.benchmark.realism.headings import gyro_yaw_rate, leg_headings, rotation_heading
from indoorsim.benchmark.realism.magnetic import hard_iron_residual, magnetic_statistics
from indoorsim.benchmark.realism.motion import HELD_KEYS, motion_statistics
from indoorsim.benchmark.realism.reference import HELD_FLAT
from indoorsim.benchmark.realism.vigour import vigour_powers
from indoorsim.benchmark.step_transfer import OXFORD, step_count_transfer, write_step_transfer
from indoorsim.estimators.frames import wrap_angle
from indoorsim.estimators.pdr.steps import PeakStepDetector
from indoorsim.io.reallogs.ilc import read_ilc_trace
from indoorsim.io.recording import Recording
from indoorsim.scenario.imports import (
    add_trace_routes,
    import_ilc_floor,
    read_ilc_floor,
)
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate
from indoorsim.walker.path import cumsum0, first_pass
from indoorsim.world.site import Site

__all__ = [
    "SIGNALS",
    "TWIN_ESTIMATORS",
    "TwinResults",
    "TwinSite",
    "as_real_log",
    "passing_times",
    "twin_site",
    "twin_summary",
    "twin_table",
    "walk_signals",
    "waypoint_lead",
    "write_sim_to_real",
    "write_twin_section",
]

Progress = Callable[[str], None]

# ---------------------------------------------------------------------- real traces and twins

ILC_FLOOR = Path("ms-indoor-location-2020", "site1", "F1")
"""The Indoor Location Competition floor, under the real-data folder: plan and traces."""

TWIN_ESTIMATORS = ("start-only", "pdr-basic", "han2023-pdr", "learned-io")
"""The estimators that run on a real log (no floor plan, no surveys)."""
TWIN_SEEDS = (0, 1, 2)
TWIN_MODE = HELD_FLAT
"""The traces' surveyors held the phone flat in front of the body (the mode their
walkers' vigour is fitted through for the real walkers' table, too)."""
TWIN_BASE_DEVICE = "mid_grade"
"""What a trace's calibration cannot show (scale factors, bias drift, light) comes from it."""
TWIN_MARK_SPEED = (0.35, 0.65)
"""How slowly the twins pass each point of their route, as a fraction of the speed around
it (:attr:`~indoorsim.walker.gait.WalkerParams.mark_speed`, drawn per point): the ILC
surveyors tap each waypoint as they pass it, stepping with a third of their swing over
the last fifth of a leg's time (the median low-passed ‖a‖ swing per step, 3.1 m/s²,
against 9.1 between the marks; :func:`walk_signals`). Twins walking through their marks
give 4.6 and 7.6; slowing to 0.5 of their speed, 2.8 and 8.5 (to 0.3: 2.3 and 9.8): the
range is what the real swings bracket (2026-12-08, one seed per trace). A route's
points round walls, which no surveyor marked, are slowed at too."""


def passing_times(truth: pd.DataFrame, waypoints: NDArray[np.float64]) -> NDArray[np.int64]:
    """Index of the truth sample where the walker passes each waypoint, in order: the
    body's closest approach to it, searched from the previous waypoint's on."""
    body = truth[["body_x", "body_y"]].to_numpy(dtype=float)
    out = np.empty(len(waypoints), dtype=np.int64)
    start = 0
    for i, p in enumerate(np.asarray(waypoints, dtype=float)):
        # The first approach within 0.5 m of the closest one, not a later pass by it.
        out[i] = start + first_pass(np.linalg.norm(body[start:] - p, axis=1), 0.5)
        start = int(out[i])
    return out


def as_real_log(rec: Recording, waypoints: NDArray[np.float64], lead_s: float = 0.0) -> Recording:
    """A simulated walk as a real log shows it: no dense truth or steps, only waypoint
    marks — each waypoint's position, marked ``lead_s`` before the walker passes it
    (no earlier than the walk's start, and in order)."""
    truth = rec.truth
    at = passing_times(truth, waypoints)
    t = truth.index.to_numpy(dtype=float)
    marked = np.maximum(t[at] - lead_s, t[0])
    # Marks are taken one after another: each strictly after the one before (a
    # scorer reads one time as one place).
    for i in range(1, len(marked)):
        marked[i] = max(marked[i], np.nextafter(marked[i - 1], np.inf))
    marks = pd.DataFrame(
        np.asarray(waypoints, dtype=float),
        columns=["x", "y"],
        index=pd.Index(marked, name="t"),
    )
    streams = {k: v for k, v in rec.streams.items() if k not in ("truth", "steps")}
    return Recording._from_built(
        {**streams, "waypoints": marks}, {"device": rec.meta.get("device", ""), "source": "twin"}
    )


CORNER_DEG = 45.0
"""A waypoint where the route turns by at least this much is a corner (:func:`waypoint_lead`)."""
LEAD_WINDOW_S = 3.0
"""How far either side of a corner's mark its turn is looked for first, s."""
_LEAD_ITERATIONS = 20


def waypoint_lead(rec: Recording) -> NDArray[np.float64]:
    """How long before the walker's turn each corner waypoint was marked, s.

    At each waypoint where the waypoints' polyline turns by :data:`CORNER_DEG` or
    more, the turn is found in the gyro: the rate of turn about gravity (the
    accelerometer's 1 s mean), smoothed over 0.25 s, where it turns the corner's
    way. Its centroid in time is taken within :data:`LEAD_WINDOW_S` of the mark,
    then again within half that of the centroid until it settles: a window held
    on the mark would pull the centroid toward it, the stride's sway of the
    heading standing in it on both sides of the turn. A corner whose final
    window turns by more than 45° more or less than the polyline (two corners
    in one window) is skipped. Returns the centre's time less the mark's, one
    per corner kept.
    """
    if not {"waypoints", "gyro", "accel"} <= set(rec.streams):
        return np.zeros(0)
    wp = rec.waypoints
    xy = wp[["x", "y"]].to_numpy(dtype=float)
    marks = wp.index.to_numpy(dtype=float)
    if len(xy) < 3 or len(rec.gyro) < 10 or len(rec.accel) < 2:
        return np.zeros(0)
    t, rate = gyro_yaw_rate(rec)
    rate_hz = 1.0 / float(np.median(np.diff(t)))
    rate = uniform_filter1d(rate, max(1, round(0.25 * rate_hz)))
    legs = np.diff(xy, axis=0)
    length = np.hypot(legs[:, 0], legs[:, 1])
    heading = np.arctan2(legs[:, 1], legs[:, 0])
    leads = []
    for i in range(1, len(xy) - 1):
        if min(length[i - 1], length[i]) < 1e-6:
            continue  # a repeated waypoint has no direction
        turn = float(wrap_angle(heading[i] - heading[i - 1]))
        if abs(turn) < np.radians(CORNER_DEG):
            continue
        centre = _turn_centre(t, rate * np.sign(turn), float(marks[i]), LEAD_WINDOW_S)
        for _ in range(_LEAD_ITERATIONS):
            if centre is None:
                break
            moved = _turn_centre(t, rate * np.sign(turn), centre, LEAD_WINDOW_S / 2)
            settled = moved is not None and abs(moved - centre) < 1e-3
            centre = moved
            if settled:
                break
        if centre is None:
            continue
        near = np.abs(t - centre) <= LEAD_WINDOW_S / 2
        turned = float(np.trapezoid(rate[near], t[near]))
        if abs(turned - turn) <= np.radians(CORNER_DEG):
            leads.append(centre - float(marks[i]))
    return np.asarray(leads)


def _turn_centre(
    t: NDArray[np.float64], rate: NDArray[np.float64], around: float, half: float
) -> float | None:
    """Centroid in time of the positive part of ``rate`` within ``half`` of ``around``."""
    near = np.abs(t - around) <= half
    weight = np.clip(rate[near], 0.0, None)
    if near.sum() < 2 or not weight.sum() > 0:
        return None
    return float((t[near] * weight).sum() / weight.sum())


def _path_ratio(result: WalkResult, lead_s: float) -> float:
    """The walked distance read: the estimator's own track (every answer,
    ``WalkResult.track``) from when the walker passes the first scored waypoint to when
    it passes the last — each mark's time plus ``lead_s``, how long before the walker
    reached its waypoint the mark was made — over the scored waypoints' polyline.

    Not the polyline through the estimate at the mark times, which cuts each corner
    the estimate passes after its mark; and not the track from mark to mark, which
    starts a lead's walk short of the first waypoint and ends nearer the last (the
    walker slows to stop), so that the truth itself read 1.05 of the polyline on the
    walks v8 twins. From passing to passing the truth, sampled at the estimators'
    1 s answers, reads 1.00 of it (``test_sim_to_real``).
    """
    e, track = result.estimates, result.track
    true = result.metrics["path_m"]
    if track is None or not len(e) or not true > 0:
        return float("nan")
    t = track["t"].to_numpy(dtype=float)
    t0, t1 = (min(float(x) + lead_s, t[-1]) for x in (e["t"].iloc[0], e["t"].iloc[-1]))
    xy = track[["x", "y"]].to_numpy(dtype=float)
    return track_length(t, xy, t0, t1) / true


LEG_END_SHARE = 0.2
"""The share of each leg's time, at either end, that counts as near its waypoints
(:func:`_leg_parts`, :func:`_approach`)."""


def walk_signals(rec: Recording) -> dict[str, float]:
    """What the phone felt (the swing per step between the first and the last waypoint,
    the rest over the whole walk's walking parts): the step rate, ‖a‖'s
    std while walking (:mod:`~indoorsim.benchmark.realism.motion`), the median swing
    of one step of the low-passed ‖a‖ (peak to valley, the input of Weinberg's step
    length), ‖a‖'s jolts (its RMS at 5–15 Hz,
    :func:`~indoorsim.benchmark.realism.vigour.vigour_powers`), the gyro axes' RMS,
    how the held phone surges, sways, bobs
    and turns within each step (:func:`~indoorsim.benchmark.realism.motion.held_phone_motion`),
    the spread of ‖m‖ along the path, in all and at wavelengths over 10 m
    (:func:`~indoorsim.benchmark.realism.magnetic.magnetic_statistics`), and the
    calibrated magnetometer's residual hard iron where the walk's turns show it
    (:func:`~indoorsim.benchmark.realism.magnetic.hard_iron_residual`), with the
    spread of ‖m‖ once it is taken out (the whole spread where it cannot be told); and
    how straight the legs were walked, read from the gyro against the marks
    (:func:`~indoorsim.benchmark.realism.headings.leg_headings`: the median over the
    long legs of the marks' direction against the gyro's heading, in size, and of the
    heading's swing within a leg); and how fast the short and the long legs were
    walked (:func:`_pace`), and how the walker steps as it approaches each waypoint and
    between them (:func:`_approach`)."""
    field = magnetic_statistics(rec)
    iron = hard_iron_residual(rec)
    iron_free = magnetic_statistics(rec, iron.offset_uT) if iron is not None else field
    stats = motion_statistics(rec)
    t = rec.accel.index.to_numpy(dtype=float)
    first, last = (float(v) for v in rec.waypoints.index[[0, -1]])
    steps = PeakStepDetector().update(t, rec.accel[["x", "y", "z"]].to_numpy(dtype=float))
    swings = [s.a_max - s.a_min for s in steps if first <= s.t <= last]
    vigour = vigour_powers(rec)
    leads = waypoint_lead(rec)
    lead = float(np.median(leads)) if len(leads) else float("nan")
    return (
        {
            "step_hz": stats["step_hz"],
            "acc_std": stats["acc_std"],
            "step_swing": float(np.median(swings)) if swings else float("nan"),
            "acc_jolt_rms": vigour[2] if vigour is not None else float("nan"),
            "gyro_rms_1": stats["gyro_rms_1"],
            "gyro_rms_2": stats["gyro_rms_2"],
            "gyro_rms_3": stats["gyro_rms_3"],
        }
        # Only what the table compares (a phase's real/sim ratio would mean nothing).
        | {key: stats[key] for key in HELD_KEYS if key in SIGNALS}
        | {"mag_std": field["mag_std"], "mag_std_long": field["std_long"]}
        | {
            "hard_iron": iron.horizontal_uT if iron is not None else float("nan"),
            "mag_std_iron_free": iron_free["mag_std"],
            "lead": lead,
        }
        | _straightness(rec)
        | _pace(rec)
        | _approach(rec, steps, lead if len(leads) else 0.0)
    )


def _leg_position(
    passing: NDArray[np.float64], t: NDArray[np.float64]
) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.bool_]]:
    """For each time ``t``: the leg it falls in (between the walker's passing of two
    waypoints, ``passing``), how far into that leg's time it is (0 … 1), and whether it
    falls in a leg at all."""
    took = np.diff(passing)
    leg = np.searchsorted(passing, t, side="right") - 1
    inside = (leg >= 0) & (leg < len(took))
    leg = np.clip(leg, 0, len(took) - 1)
    into = np.divide(t - passing[leg], took[leg], out=np.zeros(len(t)), where=took[leg] > 0)
    return leg, into, inside


def _approach(rec: Recording, steps: Sequence, lead_s: float) -> dict[str, float]:
    """How the walker steps as it approaches each waypoint — over the last
    :data:`LEG_END_SHARE` of each leg's time, the walker passing its waypoints
    ``lead_s`` after their marks — and between the marks (the middle of each leg,
    clear of both ends' shares): the steps ``steps`` holds there per second and their
    median swing of the low-passed ‖a‖ (Weinberg's step-length input). NaN without a
    step there. :func:`walk_signals` passes the peak-valley detector's steps at its
    defaults, whose 0.5 s least interval misses some steps of a brisk walk: the same
    detector on the real trace and its twin, so the two compare, though the rate is not
    the cadence. Read from the accelerometer alone."""
    nan = float("nan")
    out = dict.fromkeys(
        ("approach_step_hz", "approach_swing", "between_step_hz", "between_swing"), nan
    )
    if "waypoints" not in rec.streams or len(rec.waypoints) < 2:
        return out
    passing = rec.waypoints.index.to_numpy(dtype=float) + lead_s
    took = np.diff(passing)
    t = np.array([s.t for s in steps], dtype=float)
    swing = np.array([s.a_max - s.a_min for s in steps])
    _, into, inside = _leg_position(passing, t)
    for key, (lo, hi) in (
        ("approach", (1.0 - LEG_END_SHARE, 1.0)),
        ("between", (LEG_END_SHARE, 1.0 - LEG_END_SHARE)),
    ):
        within = inside & (into >= lo) & (into < hi)
        span = (hi - lo) * float(took[took > 0].sum())
        if span > 0 and within.any():
            out[f"{key}_step_hz"] = float(within.sum() / span)
            out[f"{key}_swing"] = float(np.median(swing[within]))
    return out


_SHORT_LEG_M, _LONG_LEG_M = 4.0, 8.0
"""Legs between waypoints shorter than the first, and at least the second, are paced
apart: the ILC surveyors walk their short legs (turning at both ends) slowly and their
long ones briskly."""


def _pace(rec: Recording) -> dict[str, float]:
    """The walking speed over a walk's short legs together, and over its long ones: their
    length over their time between the marks (NaN without such legs)."""
    xy = rec.waypoints[["x", "y"]].to_numpy(dtype=float)
    dt = np.diff(rec.waypoints.index.to_numpy(dtype=float))
    lengths = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    out = {}
    for key, legs in (
        ("pace_short", lengths < _SHORT_LEG_M),
        ("pace_long", lengths >= _LONG_LEG_M),
    ):
        took = dt[legs].sum()
        out[key] = float(lengths[legs].sum() / took) if took > 0 else float("nan")
    return out


def _straightness(rec: Recording) -> dict[str, float]:
    """The medians over a walk's long legs of :func:`leg_headings`' two readings (the
    marks' direction against the gyro in size, and the heading's swing), and of the
    marks' direction against the fused rotation vector's heading in size (which
    ``learned-io`` takes its heading from), degrees."""
    nan = float("nan")
    out = {"leg_marks": nan, "leg_swing": nan, "leg_marks_rotation": nan}
    legs = leg_headings(rec)
    if legs is not None:
        out["leg_swing"] = float(np.median(legs.swing_deg))
        out["leg_marks"] = _median_size(legs.marks_deg)
    if "rotation" in rec.streams and len(rec.rotation):
        fused = leg_headings(rec, rotation_heading(rec))
        if fused is not None:
            out["leg_marks_rotation"] = _median_size(fused.marks_deg)
    return out


def _median_size(angles_deg: NDArray[np.float64]) -> float:
    """The median size of a walk's per-leg angles; NaN where they are not read (fewer
    than two legs)."""
    sizes = np.abs(angles_deg)
    return float(np.median(sizes)) if np.isfinite(sizes).all() else float("nan")


SIGNALS = {
    "step_hz": "step rate (Hz)",
    "acc_std": "‖a‖ std while walking (m/s²)",
    "step_swing": "swing of low-passed ‖a‖ per step (m/s²)",
    "acc_jolt_rms": "‖a‖ RMS at 5–15 Hz while walking, the jolts (m/s²)",
    "gyro_rms_1": "gyro RMS, largest axis (rad/s)",
    "gyro_rms_2": "gyro RMS, middle axis (rad/s)",
    "gyro_rms_3": "gyro RMS, smallest axis (rad/s)",
    "surge_step": "forward acceleration at the step rate (m/s²)",
    "sway_stride": "sideways acceleration at the stride rate (m/s²)",
    "bob_step": "vertical acceleration at the step rate (m/s²)",
    "yaw_stride": "rate of turn at the stride rate (rad/s)",
    "sway_step": "sideways acceleration at the step rate (m/s²)",
    "roll_jerk": "roll rate against sideways jerk, correlation",
    "nod_2nd": "pitch rate per vertical acceleration at twice the step rate (rad/s per m/s²)",
    "surge_2nd": "forward acceleration at twice the step rate (m/s²)",
    "mag_std": "‖m‖ std along the path (µT)",
    "mag_std_long": "‖m‖ std at wavelengths over 10 m (µT)",
    "hard_iron": "the magnetometer's residual hard iron, where the turns show it (µT)",
    "mag_std_iron_free": "‖m‖ std along the path without it (µT)",
    "pace_short": "walking speed over legs under 4 m (m/s)",
    "pace_long": "walking speed over legs of 8 m or more (m/s)",
    "lead": "corner waypoints marked before the walker's turn (s)",
    "approach_step_hz": (
        "steps found per second over each leg's last fifth, approaching its waypoint (Hz)"
    ),
    "approach_swing": "swing of low-passed ‖a‖ per step there (m/s²)",
    "between_step_hz": "steps found per second over each leg's middle three fifths (Hz)",
    "between_swing": "swing of low-passed ‖a‖ per step there (m/s²)",
    "leg_marks": "legs of 4 m or more: the marks' direction against the gyro's heading (°)",
    "leg_swing": "legs of 4 m or more: the heading's swing within one, 2 s means (°)",
    "leg_marks_rotation": (
        "legs of 4 m or more: the marks' direction against the rotation vector's heading (°)"
    ),
}
"""The signal statistics the twin table compares (:func:`walk_signals`)."""


LEG_PART_KEYS = ("read_near_m", "paced_near_m", "read_between_m", "paced_between_m")


def _answer_steps(track: pd.DataFrame) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """An estimator's answer times, and how far its own track goes between consecutive
    answers (one fewer)."""
    t = track["t"].to_numpy(dtype=float)
    return t, np.linalg.norm(np.diff(track[["x", "y"]].to_numpy(dtype=float), axis=0), axis=1)


def _leg_parts(result: WalkResult, rec: Recording, lead_s: float) -> dict[str, float]:
    """Where along its legs an estimator's track walks its distance: the length of its
    own track (every answer) near the marks — the first and last :data:`LEG_END_SHARE`
    of each leg's time, the walker passing its waypoints a lead after each mark — and
    between them, each beside the distance the leg's mean speed (its length over its
    time) covers in the same time. Legs after the first only: the first holds the
    start and the estimate's warm-up.

    The leg's mean speed is no truth within the leg: a walker who slows at the marks
    covers less than it near them and more between, and a perfect track reads so. It
    is the one reference a real trace gives there, the same for a trace and its twin.
    """
    track = result.track
    if track is None or len(track) < 2 or "waypoints" not in rec.streams:
        return dict.fromkeys(LEG_PART_KEYS, 0.0)
    passing = rec.waypoints.index.to_numpy(dtype=float) + lead_s
    xy = rec.waypoints[["x", "y"]].to_numpy(dtype=float)
    took = np.diff(passing)
    speed = np.divide(
        np.linalg.norm(np.diff(xy, axis=0), axis=1), took, out=np.zeros(len(took)), where=took > 0
    )
    t, walked = _answer_steps(track)
    centre, dt = 0.5 * (t[1:] + t[:-1]), np.diff(t)
    leg, into, inside = _leg_position(passing, centre)
    inside &= leg >= 1
    near = inside & ((into < LEG_END_SHARE) | (into > 1.0 - LEG_END_SHARE))
    between = inside & ~near
    paced = speed[leg] * dt
    return {
        "read_near_m": float(walked[near].sum()),
        "paced_near_m": float(paced[near].sum()),
        "read_between_m": float(walked[between].sum()),
        "paced_between_m": float(paced[between].sum()),
    }


SPEED_BINS_MPS = (0.0, 0.9, 1.3, 1.5, np.inf)
"""The twins' true speed over each of an estimator's answer intervals, binned by
:func:`_speed_reads`: slow (turning, starting, stopping), usual, brisk, fast."""

SPEED_BIN_LABELS = ("under 0.9 m/s", "0.9–1.3 m/s", "1.3–1.5 m/s", "1.5 m/s and over")

SPEED_READ_KEYS = tuple(
    f"{kind}_speed{k}_m" for k in range(len(SPEED_BIN_LABELS)) for kind in ("read", "true")
)


def _speed_reads(result: WalkResult, truth: pd.DataFrame | None) -> dict[str, float]:
    """How far the estimator's own track goes between consecutive answers against how far
    the phone truly went then, summed by the true speed over the interval
    (:data:`SPEED_BINS_MPS`); NaN without a truth (a real trace)."""
    out = dict.fromkeys(SPEED_READ_KEYS, float("nan"))
    track = result.track
    if truth is None or track is None or len(track) < 2:
        return out
    tt = truth.index.to_numpy(dtype=float)
    gone = cumsum0(np.linalg.norm(np.diff(truth[["x", "y"]].to_numpy(dtype=float), axis=0), axis=1))
    t, read = _answer_steps(track)
    true = np.diff(np.interp(t, tt, gone))
    dt = np.diff(t)
    speed = np.divide(true, dt, out=np.zeros(len(dt)), where=dt > 0)
    which = np.digitize(speed, SPEED_BINS_MPS[1:-1])
    for k in range(len(SPEED_BIN_LABELS)):
        out[f"read_speed{k}_m"] = float(read[which == k].sum())
        out[f"true_speed{k}_m"] = float(true[which == k].sum())
    return out


def speed_read_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per estimator, on the twins: the distance its track reads over that truly walked
    in each true-speed bin (:func:`_speed_reads`, summed over traces and seeds), and the
    share of the walked distance in the bin."""
    sim = table[table["data"] == "sim"]
    sums = sim.groupby("estimator", sort=False)[list(SPEED_READ_KEYS)].sum()
    out = pd.DataFrame(index=sums.index)
    total = sum(sums[f"true_speed{k}_m"] for k in range(len(SPEED_BIN_LABELS)))
    for k in range(len(SPEED_BIN_LABELS)):
        true = sums[f"true_speed{k}_m"]
        out[f"read_{k}"] = sums[f"read_speed{k}_m"] / true.where(true > 0)
        out[f"share_{k}"] = true / total.where(total > 0)
    return out


def _scores(
    estimator: str, rec: Recording, lead_s: float, truth: pd.DataFrame | None = None
) -> dict[str, float]:
    result = evaluate_recording(estimator, rec, params=REAL_DATA_PARAMS.get(estimator))
    e = result.estimates
    aligned, turn = start_aligned_errors(
        e[["x", "y"]].to_numpy(dtype=float),
        e[["true_x", "true_y"]].to_numpy(dtype=float),
        start_info(rec).position,
    )
    return (
        {
            "ae": float(result.metrics["ae"]),
            "rmse": float(result.metrics["rmse"]),
            "path_ratio": _path_ratio(result, lead_s),
            "ae_aligned": float(aligned.mean()) if len(aligned) else float("nan"),
            "turn_deg": turn,
        }
        | _leg_parts(result, rec, lead_s)
        | _speed_reads(result, truth)
    )


@dataclass(frozen=True, kw_only=True)
class TwinSite:
    """:func:`twin_site`: the imported floor with a route per real trace."""

    site: Site
    traces: dict[str, Path]
    """The real traces that have a route, by route name."""
    left_out: dict[str, str]
    """The traces without one, and why."""
    marks: dict[str, NDArray[np.float64]]
    """Each route's real waypoints as it walks through them, (K, 2): where a twin is
    marked. A route also holds the points of its ways round walls, which no surveyor
    marked."""


def twin_site(realdata: Path, *, seed: int = 0) -> TwinSite:
    """The imported competition floor with one route per trace."""
    floor_dir = realdata / ILC_FLOOR
    floor = read_ilc_floor(floor_dir / "geojson_map.json", floor_dir / "floor_info.json")
    imported = import_ilc_floor(floor, seed=seed)
    paths = {p.stem: p for p in sorted((floor_dir / "path_data_files").glob("*.txt"))}
    traces = {}
    for name, path in paths.items():
        wp = read_ilc_trace(path).waypoints
        xy = wp[["x", "y"]].to_numpy(dtype=float)
        traces[name] = (xy.tolist(), wp.index.to_numpy(dtype=float).tolist())
    routes = add_trace_routes(imported, traces)
    return TwinSite(
        site=load_site(routes.scenario),
        traces={name: paths[name] for name in routes.kept},
        left_out=routes.left_out,
        marks={name: np.asarray(xy, dtype=float) for name, xy in routes.marks.items()},
    )


@dataclass(frozen=True, kw_only=True)
class TwinResults:
    """:func:`twin_table`'s tables."""

    scores: pd.DataFrame
    """One row per (trace, estimator, data ``real``/``sim``, seed): ae, rmse, path_ratio,
    ae_aligned and turn_deg (:func:`~indoorsim.benchmark.metrics.start_aligned_errors`)."""
    signals: pd.DataFrame
    """One row per (trace, data, seed): :func:`walk_signals`."""
    left_out: dict[str, str]
    """Traces without a twin, and why."""
    lead_s: float = 0.0
    """How long before the walker's turn the twins' waypoints are marked, s: the median of
    :func:`waypoint_lead` over the real traces' corners."""
    corners: int = 0
    """How many real corners that median is over."""


def twin_table(
    realdata: Path,
    estimators: Sequence[str] = TWIN_ESTIMATORS,
    seeds: Sequence[int] = TWIN_SEEDS,
    *,
    progress: Progress | None = None,
) -> TwinResults:
    """Every estimator on each real trace and on its simulated twins, and what the
    phones felt on each.

    A twin walks the trace's route in the imported floor, flat in the hand, with the
    phone and walker :func:`~indoorsim.benchmark.realism.calibrate.calibrate` fits to
    the trace (its rates, timing, WiFi scanning, walking speed, height and vigour); it is then
    scored as the trace is, at the times it passes the trace's waypoints, starting
    from the first heading to the second.
    """
    if progress:
        progress("sim-to-real: importing the floor")
    twins = twin_site(realdata)
    site, left_out = twins.site, twins.left_out
    reals = {name: Recording.load(path) for name, path in twins.traces.items()}
    # How the real surveyors marked their corners: the twins are marked the same way.
    leads = np.concatenate([waypoint_lead(rec) for rec in reals.values()])
    lead = float(np.median(leads)) if len(leads) else 0.0
    rows: list[dict] = []
    signals: list[dict] = []
    for name, real in reals.items():
        cal = calibrate(real, name=f"twin of {name}", base=TWIN_BASE_DEVICE, mode=TWIN_MODE)
        walker = dataclasses.replace(cal.walker, mark_speed=TWIN_MARK_SPEED)
        waypoints = twins.marks[name]
        for est in estimators:
            if progress:
                progress(f"sim-to-real {name} {est} real")
            rows.append({"trace": name, "estimator": est, "data": "real", "seed": -1})
            rows[-1] |= _scores(est, real, lead)
        signals.append({"trace": name, "data": "real", "seed": -1} | walk_signals(real))
        for seed in seeds:
            if progress:
                progress(f"sim-to-real {name} twin seed {seed}")
            walk = simulate(
                site, route=name, mode=TWIN_MODE, device=cal.device, walker=walker, seed=seed
            )
            twin = as_real_log(walk, waypoints, lead_s=lead)
            signals.append({"trace": name, "data": "sim", "seed": seed} | walk_signals(twin))
            for est in estimators:
                rows.append({"trace": name, "estimator": est, "data": "sim", "seed": seed})
                rows[-1] |= _scores(est, twin, lead, walk.truth)
    return TwinResults(
        scores=pd.DataFrame(rows),
        signals=pd.DataFrame(signals),
        left_out=left_out,
        lead_s=lead,
        corners=len(leads),
    )


def twin_summary(table: pd.DataFrame) -> tuple[pd.DataFrame, float]:
    """Per estimator: mean error real and simulated, their ratio, the walked-distance
    ratios, the same errors once each track is turned about its start
    (:func:`~indoorsim.benchmark.metrics.start_aligned_errors`) and the median size of
    that turn; and Kendall's τ between the estimators' rankings on real and simulated
    data."""
    table = table.assign(turn_deg=table["turn_deg"].abs())
    per_trace = table.groupby(["estimator", "data", "trace"], sort=False)[
        ["ae", "rmse", "path_ratio", "ae_aligned", "turn_deg"]
    ].mean()
    by_data = per_trace.groupby(["estimator", "data"], sort=False)
    summary = by_data.mean().unstack("data")
    turns = by_data["turn_deg"].median().unstack("data")
    path_medians = by_data["path_ratio"].median().unstack("data").reindex(summary.index)
    out = pd.DataFrame(
        {
            "estimator": summary.index,
            "ae_real": summary[("ae", "real")].to_numpy(),
            "ae_sim": summary[("ae", "sim")].to_numpy(),
            "path_ratio_real": summary[("path_ratio", "real")].to_numpy(),
            "path_ratio_sim": summary[("path_ratio", "sim")].to_numpy(),
            "path_ratio_real_median": path_medians["real"].to_numpy(),
            "path_ratio_sim_median": path_medians["sim"].to_numpy(),
            "ae_aligned_real": summary[("ae_aligned", "real")].to_numpy(),
            "ae_aligned_sim": summary[("ae_aligned", "sim")].to_numpy(),
            "turn_real": turns["real"].reindex(summary.index).to_numpy(),
            "turn_sim": turns["sim"].reindex(summary.index).to_numpy(),
        }
    )
    out["ratio"] = out["ae_real"] / out["ae_sim"]
    out["aligned_ratio"] = out["ae_aligned_real"] / out["ae_aligned_sim"]
    tau = float(kendalltau(out["ae_real"], out["ae_sim"]).statistic) if len(out) > 1 else np.nan
    return out, tau


def leg_part_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per estimator, real and twins: its track's distance near the marks and between
    them over what the legs' mean speeds cover in the same time (:func:`_leg_parts`,
    summed over the traces and seeds); NaN where that is nothing."""
    sums = table.groupby(["estimator", "data"], sort=False)[list(LEG_PART_KEYS)].sum()
    out = pd.DataFrame(index=sums.index)
    for part in ("near", "between"):
        paced = sums[f"paced_{part}_m"]
        out[part] = sums[f"read_{part}_m"] / paced.where(paced > 0)
    return out.unstack("data")


SHARED_TURN_REFERENCE = "pdr-basic"
"""The estimator whose turn about the start the others' are compared with: it holds the
gyro's heading from the start heading (the first leg's marks), so its turn is how the
walk set off against those marks, plus its gyro's drift."""


def shared_turns(table: pd.DataFrame, reference: str = SHARED_TURN_REFERENCE) -> pd.DataFrame:
    """Per estimator other than ``reference``: the correlation over the traces of its
    signed turn about the start with ``reference``'s, on the real traces (``real``) and
    on their twins (``sim``, each trace's seeds averaged first); NaN with fewer than
    three traces or a turn that never varies.

    Every estimator here takes its start heading from the first leg's marks, so a turn
    the estimators share comes from how the walk set off against them rather than from
    any one estimator; where they share it on the real traces and not on the twins, the
    twins set off along the marks more exactly than the real walkers did."""
    # One row a trace, one column an estimator, per side.
    turns = table.groupby(["data", "trace", "estimator"], sort=False)["turn_deg"].mean()
    by_data = {data: turns.loc[data].unstack("estimator") for data in ("real", "sim")}

    def correlation(wide: pd.DataFrame, name: str) -> float:
        both = wide.reindex(columns=[name, reference]).dropna()
        if len(both) < 3 or both.std().min() == 0:
            return np.nan
        return float(np.corrcoef(both[name], both[reference])[0, 1])

    rows = [
        {"estimator": name} | {data: correlation(wide, name) for data, wide in by_data.items()}
        for name in dict.fromkeys(table["estimator"])
        if name != reference
    ]
    return pd.DataFrame(rows, columns=["estimator", "real", "sim"])


def _plot_twins(table: pd.DataFrame, path: Path) -> None:
    from indoorsim.plots import plot_sim_to_real

    per_trace = table.groupby(["estimator", "data", "trace"], sort=False)["ae"].mean()
    errors = {}
    for name in dict.fromkeys(table["estimator"]):
        real = per_trace.loc[(name, "real")]
        errors[name] = (
            real.to_numpy(),
            per_trace.loc[(name, "sim")].reindex(real.index).to_numpy(),
        )
    plot_sim_to_real(errors).savefig(path, dpi=110)


RATIO_BAND = (0.8, 1.25)
"""The real/sim ratios aimed at (the "Sim-to-real" issue), for errors and for signals."""
_BAND_TEXT = f"{RATIO_BAND[0]:g}–{RATIO_BAND[1]:g}"


def _inside_band(ratio: float) -> bool:
    return bool(RATIO_BAND[0] <= ratio <= RATIO_BAND[1])


def _outside_note(ratio: float) -> str:
    return "" if _inside_band(ratio) else f" (outside {_BAND_TEXT})"


def write_twin_section(out: Path, results: TwinResults) -> list[str]:
    """``sim_to_real_twins.csv``, ``sim_to_real_signals.csv`` and ``sim_to_real.png``;
    returns the Markdown section."""
    table, left_out = results.scores, results.left_out
    table.to_csv(out / "sim_to_real_twins.csv", index=False)
    results.signals.to_csv(out / "sim_to_real_signals.csv", index=False)
    summary, tau = twin_summary(table)
    _plot_twins(table, out / "sim_to_real.png")
    traces = table["trace"].nunique()
    seeds = table.loc[table["data"] == "sim", "seed"].nunique()
    lines = [
        "## Real traces and their simulated twins",
        "",
        f"The {traces} Indoor Location Competition traces (MIT; site 1, floor F1) and, for "
        f"each, {seeds} simulated twins: the floor imported by `indoorsim import-plan`, "
        "the trace's waypoints as the route, each leg walked in the trace's time between "
        "its waypoints, the phone held flat, and the phone and walker "
        "`indoorsim calibrate` fits to the trace (the walker's height, speed and "
        "cadence, how far it stood turned before its first step, and its vigour through "
        "the flat-held phone: bounce, loading peak and heel strikes), slowing to "
        f"{TWIN_MARK_SPEED[0]:g}–{TWIN_MARK_SPEED[1]:g} of its speed as it passes each "
        "waypoint, as the real surveyors do when they tap one. Both scored the "
        "same way, at the "
        "waypoints, from the first waypoint heading to the second. A real waypoint is "
        "marked before its surveyor reaches it: at the corners the gyro's turn comes "
        f"{results.lead_s:.2f} s after the mark (median over {results.corners} corners), "
        "so each twin's waypoints are marked at their positions that long before the "
        "simulated walker passes them. Mean absolute error (m) "
        "over traces (twins: their seeds' mean per trace first); the walked-distance ratio "
        "is the length of the estimator's own track, through every answer it gave (one a "
        "second), from when the walker passes the first scored waypoint to when it passes "
        "the last (each mark's time plus that lead), over the scored waypoints' polyline "
        "(mean over traces, the median in brackets). Until 2026-12-07 it was the polyline "
        "through the estimate at the mark times, which cuts every corner the estimate "
        "passes after its mark (`leaderboards/commentary.md`).",
        "",
        "| estimator | error real (m) | error sim (m) | real / sim | distance ratio real "
        "| distance ratio sim |",
        "|---|---|---|---|---|---|",
    ]
    for _, r in summary.iterrows():
        lines.append(
            f"| {r['estimator']} | {r['ae_real']:.2f} | {r['ae_sim']:.2f} | "
            f"{r['ratio']:.2f}{_outside_note(r['ratio'])} | {r['path_ratio_real']:.2f} "
            f"({r['path_ratio_real_median']:.2f}) | {r['path_ratio_sim']:.2f} "
            f"({r['path_ratio_sim_median']:.2f}) |"
        )
    lines += [
        "",
        f"Kendall's τ between the estimators' rankings on real and simulated data: {tau:.2f} "
        "(1: the same order).",
        "",
        "Where along the legs the distance is read: each estimator's track near the "
        f"marks (the first and last {LEG_END_SHARE:.0%} of each leg's time, the walker "
        "passing its waypoints that lead after the marks) and between them, over the "
        "distance the leg's mean speed (its length over its time) covers in the same "
        "time; the legs after the first, summed over the traces (`_leg_parts`). The leg's "
        "mean speed is no truth within a leg: a walker who slows at the marks reads "
        "under 1 near them and over 1 between even when tracked perfectly, so read the "
        "real column against the twins', not against 1.",
        "",
        "| estimator | near the marks real | near the marks sim | between real | between sim |",
        "|---|---|---|---|---|",
    ]
    parts = leg_part_summary(table)
    for est in summary["estimator"]:
        r = parts.loc[est]
        lines.append(
            f"| {est} | {r[('near', 'real')]:.2f} | {r[('near', 'sim')]:.2f} | "
            f"{r[('between', 'real')]:.2f} | {r[('between', 'sim')]:.2f} |"
        )
    reads = speed_read_summary(table)
    lines += [
        "",
        "How each estimator reads the twins' speed: the length of its own track between "
        "consecutive answers over the distance the phone truly went then, by the true "
        "speed over the interval (summed over the traces and seeds; `_speed_reads`), and "
        "the share of the walked distance at that speed in brackets. A real trace has no "
        "truth between its marks.",
        "",
        "| estimator | " + " | ".join(SPEED_BIN_LABELS) + " |",
        "|---|" + "---|" * len(SPEED_BIN_LABELS),
    ]
    for est in summary["estimator"]:
        if est not in reads.index:
            continue
        r = reads.loc[est]
        cells = [
            f"{r[f'read_{k}']:.2f} ({r[f'share_{k}']:.2f})" for k in range(len(SPEED_BIN_LABELS))
        ]
        lines.append(f"| {est} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "The same errors once each estimated track is turned about the start by the one "
        "rotation that lays it best on the marks (least squares; "
        "`indoorsim.benchmark.metrics.start_aligned_errors`): the turn corrects a "
        "heading held wrong from the start, and a share of one that turned away along "
        "the trace (its size, median over traces); what is left is the error of the "
        "track's shape.",
        "",
        "| estimator | turn real (°) | turn sim (°) | error after it real (m) "
        "| error after it sim (m) | real / sim |",
        "|---|---|---|---|---|---|",
    ]
    for _, r in summary.iterrows():
        lines.append(
            f"| {r['estimator']} | {r['turn_real']:.1f} | {r['turn_sim']:.1f} | "
            f"{r['ae_aligned_real']:.2f} | {r['ae_aligned_sim']:.2f} | "
            f"{r['aligned_ratio']:.2f}{_outside_note(r['aligned_ratio'])} |"
        )
    shared = shared_turns(table).dropna(how="all", subset=["real", "sim"])
    if len(shared):
        lines += [
            "",
            "How far each turn is shared with `pdr-basic`'s, which holds the gyro's heading "
            "from the start heading the first leg's marks give (the correlation of the signed "
            "turns over the traces, real / twins; `shared_turns`): "
            + "; ".join(
                f"{r['estimator']} {r['real']:.2f} / {r['sim']:.2f}" for _, r in shared.iterrows()
            )
            + ". A turn shared on the real traces and not on the twins is how the real walkers "
            "set off against the first leg's marks, which the twins, walking from mark to "
            "mark, do not show.",
        ]
    lines += [
        "",
        "![real against simulated error per trace](sim_to_real.png)",
        "",
        "What the phones felt between the first and the last waypoint (median over the "
        "traces measured on both sides, how many in the second column; twins: their "
        "seeds' mean per trace first):",
        "",
        "| signal | traces | real | sim | real / sim |",
        "|---|---|---|---|---|",
    ]
    per_trace = results.signals.groupby(["data", "trace"])[list(SIGNALS)].mean()
    apart = []
    real_iron = per_trace.loc["real", "hard_iron"].notna()
    sim_iron = per_trace.loc["sim", "hard_iron"].reindex(real_iron.index).notna()
    for key, label in SIGNALS.items():
        # Over the traces measured on both sides (a field's spread needs 40 m, a hard
        # iron enough turning), so that both medians are of the same walks; the field
        # without the hard iron only where it was taken out on both or on neither.
        real_values = per_trace.loc["real", key]
        sim_values = per_trace.loc["sim", key].reindex(real_values.index)
        both = real_values.notna() & sim_values.notna()
        if key == "mag_std_iron_free":
            both &= real_iron == sim_iron
        if not both.any():
            lines.append(f"| {label} | 0 | n/a | n/a | n/a |")
            continue
        real = float(real_values[both].median())
        sim = float(sim_values[both].median())
        lines.append(f"| {label} | {int(both.sum())} | {real:.3g} | {sim:.3g} | {real / sim:.2f} |")
        if not _inside_band(real / sim):
            apart.append(f"{label.split(' (')[0]} ({real / sim:.2f})")
    lines.append("")
    if apart:
        # The measured departures of the twins from their real traces: where an
        # estimator's real/sim error ratio leaves 0.8–1.25, look here first.
        lines += [
            f"Where the twins depart from their real traces by more than {_BAND_TEXT} (real / "
            "sim): " + "; ".join(apart) + ".",
            "",
        ]
    if left_out:
        lines += ["Traces without a twin:", ""]
        lines += [f"- {name}: {why}" for name, why in sorted(left_out.items())]
        lines.append("")
    return lines


def write_sim_to_real(out: Path, realdata: Path, *, progress: Progress | None = None) -> float:
    """``sim_to_real.md`` (and its CSVs) from the real recordings under ``realdata``;
    returns how long it took, s."""
    start = time.perf_counter()
    lines = [
        "# Sim-to-real: tuned on indoorsim, measured on real phones",
        "",
        "Estimators on real recordings beside their simulated twins, and what is tuned "
        "on simulated data alone run unchanged on real recordings (`shared/realdata`). "
        "Regenerated by `indoorsim leaderboard` (alone: `indoorsim leaderboard "
        "--sim-to-real-only`).",
        "",
    ]
    if (realdata / ILC_FLOOR).is_dir():
        lines += write_twin_section(out, twin_table(realdata, progress=progress))
    else:
        lines += [f"No competition floor under {realdata}: no table of twins.", ""]
    if (realdata / OXFORD).is_dir():
        best, errors = step_count_transfer(realdata / OXFORD, progress=progress)
        lines += write_step_transfer(out, best, errors)
    else:
        lines += [f"No Oxford step-counter walks under {realdata}: no step-count table.", ""]
    (out / "sim_to_real.md").write_text("\n".join(lines))
    return time.perf_counter() - start
