"""How straight a walk's legs are, read from its gyro against its waypoint marks.

A real trace's truth is a surveyor's marks; between two marks nothing says
where the walker went. The gyro does: integrated about gravity it gives the
phone's heading up to one unknown offset (and its slow drift, which no offset
takes out and which both sides of a comparison carry). So, per leg between
consecutive waypoints:

* the **marks' direction against the gyro** — each leg's direction on the map
  less the gyro's heading along it, after the one offset per walk that fits
  them best (a circular mean). A walker who went straight from mark to mark
  and held the phone along the way reads 0; marks placed beside the walked
  line, a walked line that bends, or a phone turned in the hand read more;
* the **heading's swing within the leg** — the peak-to-peak of the gyro's
  heading, averaged over 2 s (a stride's sway averages out), along the leg.

Both are read on the part of each leg clear of its corners: from
:data:`TURN_CLEAR_S` after the leg's first mark (a real mark comes about a second
before its walker turns, and the turn takes a second or two) to its last mark
(the next turn begins about there), on legs of :data:`MIN_LEG_M` or more whose
clear part is at least :data:`MIN_SPAN_S` long, and within the gyro's record.
The swing is of 2 s means whose whole window lies in that part, so no corner
leaks into it. With one offset per walk fitted, a walk of two legs reads plus
and minus half their disagreement. The same functions read real traces and
simulated twins.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import cumulative_trapezoid
from scipy.ndimage import uniform_filter1d

from indoorsim.estimators.frames import wrap_angle, yaw_rate
from indoorsim.io.recording import Recording
from indoorsim.util.quaternion import twist_yaw

__all__ = [
    "MIN_LEG_M",
    "MIN_SPAN_S",
    "TURN_CLEAR_S",
    "LegHeadings",
    "gyro_heading",
    "gyro_yaw_rate",
    "leg_headings",
    "rotation_heading",
]

MIN_LEG_M = 4.0
"""Legs between waypoints at least this long are read, m."""
TURN_CLEAR_S = 3.0
"""A leg is read from this long after its first mark, s: clear of the corner turn that
mark announces (centred about 1 s after it, 1–2 s long)."""
HEADING_MEAN_S = 2.0
"""The heading's swing is of its means over this long, s: about a stride's two steps."""
MIN_SPAN_S = 2 * HEADING_MEAN_S
"""A leg's clear part must be at least this long to be read, s."""


@dataclass(frozen=True)
class LegHeadings:
    """:func:`leg_headings` of one walk, one entry per leg read, in order."""

    leg: NDArray[np.int64]
    """Each leg's index: leg i runs from waypoint i to waypoint i + 1."""
    length_m: NDArray[np.float64]
    """Each leg's length between its marks, m."""
    marks_deg: NDArray[np.float64]
    """The marks' direction less the heading's (the gyro's unless another is given)
    median along the leg's clear part, after the walk's one best offset, degrees; NaN
    for a walk of fewer than two legs read."""
    swing_deg: NDArray[np.float64]
    """Peak-to-peak of the heading's :data:`HEADING_MEAN_S` means within the leg's clear
    part, degrees."""


def gyro_yaw_rate(rec: Recording) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The gyro's rate of turn about gravity (the accelerometer's 1 s mean), at the
    gyro's times: (t, rate), rad/s, counter-clockwise seen from above. A sample the
    gyro or the accelerometer reports as non-finite is bridged by the rate either
    side of it."""
    t = rec.gyro.index.to_numpy(dtype=float)
    rate_hz = 1.0 / float(np.median(np.diff(t)))
    accel = rec.accel
    t_acc = accel.index.to_numpy(dtype=float)
    up = np.column_stack([np.interp(t, t_acc, accel[c].to_numpy(dtype=float)) for c in "xyz"])
    up = uniform_filter1d(up, max(1, round(rate_hz)), axis=0)
    rate = yaw_rate(rec.gyro[["x", "y", "z"]].to_numpy(dtype=float), up)
    finite = np.isfinite(rate)
    if not finite.all() and finite.any():
        rate = np.interp(t, t[finite], rate[finite])
    return t, rate


def gyro_heading(rec: Recording) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The gyro's heading about gravity (:func:`gyro_yaw_rate` integrated, trapezoids), 0
    at the first sample: (t, heading), rad, counter-clockwise, unwrapped."""
    t, rate = gyro_yaw_rate(rec)
    return t, cumulative_trapezoid(rate, t, initial=0.0)


def rotation_heading(rec: Recording) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The fused rotation vector's heading: its twist about the vertical
    (:func:`~indoorsim.util.quaternion.twist_yaw`), unwrapped: (t, heading), rad,
    counter-clockwise. Android fuses it from the gyro, the accelerometer and the
    magnetometer, so indoors it follows the building's magnetic disturbances, which
    the gyro's heading does not feel."""
    rot = rec.rotation
    t = rot.index.to_numpy(dtype=float)
    yaw = twist_yaw(rot[["qw", "qx", "qy", "qz"]].to_numpy(dtype=float))
    return t, np.unwrap(yaw)


def leg_headings(
    rec: Recording, heading: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
) -> LegHeadings | None:
    """Each long leg's marked direction and heading swing against the gyro (module
    docstring), or against ``heading`` — (t, heading) in rad, e.g.
    :func:`rotation_heading` — where given; None where the walk has no waypoints, no
    gyro or accelerometer for the gyro's heading, or no leg long enough to read."""
    if "waypoints" not in rec.streams:
        return None
    wp = rec.waypoints
    xy = wp[["x", "y"]].to_numpy(dtype=float)
    marks = wp.index.to_numpy(dtype=float)
    if len(xy) < 2:
        return None
    if heading is None:
        if not {"gyro", "accel"} <= set(rec.streams) or len(rec.gyro) < 10 or len(rec.accel) < 2:
            return None
        heading = gyro_heading(rec)
    t, heading = heading
    if len(t) < 10:
        return None
    if not np.isfinite(heading).all():
        return None  # no finite sample to bridge from
    window = max(1, round(HEADING_MEAN_S / float(np.median(np.diff(t)))))
    legs, lengths, marked, walked, swings = [], [], [], [], []
    for i in range(len(xy) - 1):
        d = xy[i + 1] - xy[i]
        length = float(np.hypot(d[0], d[1]))
        start, end = marks[i] + TURN_CLEAR_S, marks[i + 1]
        if length < MIN_LEG_M or end - start < MIN_SPAN_S or start < t[0] or end > t[-1]:
            continue
        part = heading[(t >= start) & (t <= end)]
        if len(part) < window + 1:
            continue
        # Means over whole windows inside the part only: none reaches a corner.
        means = np.convolve(part, np.full(window, 1.0 / window), mode="valid")
        legs.append(i)
        lengths.append(length)
        marked.append(np.arctan2(d[1], d[0]))
        walked.append(float(np.median(part)))
        swings.append(float(np.ptp(means)))
    if not legs:
        return None
    apart = wrap_angle(np.asarray(marked) - np.asarray(walked))
    if len(legs) >= 2:
        offset = np.angle(np.mean(np.exp(1j * apart)))
        marks_deg = np.degrees(wrap_angle(apart - offset))
    else:
        marks_deg = np.full(1, np.nan)
    return LegHeadings(
        leg=np.asarray(legs, dtype=np.int64),
        length_m=np.asarray(lengths),
        marks_deg=marks_deg,
        swing_deg=np.degrees(np.asarray(swings)),
    )
