"""How straight a walk's legs are, read from its gyro against its waypoint marks.

A real trace's truth is a surveyor's marks; between two marks nothing says
where the walker went. The gyro does: integrated about gravity it gives the
phone's heading up to one unknown offset and its slow drift. So, per leg
between consecutive waypoints:

* the **marks' direction against the gyro** — each leg's direction on the map
  less the gyro's heading along it, after the one offset per walk that fits
  them best (a circular mean). A walker who went straight from mark to mark
  and held the phone along the way reads 0; marks placed beside the walked
  line, a walked line that bends, or a phone turned in the hand read more;
* the **heading's swing within the leg** — the peak-to-peak of the gyro's
  heading, averaged over 2 s (a stride's sway averages out), along the leg.

Both are read on the middle of each leg (:data:`LEG_SPAN` of its time), clear
of the corner turns at either end, and only on legs of :data:`MIN_LEG_M` or
more, whose direction two marks a metre off still give to about 10°. The same
functions read real traces and simulated twins.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import uniform_filter1d

from indoorsim.estimators.frames import wrap_angle, yaw_rate
from indoorsim.io.recording import Recording

__all__ = ["LEG_SPAN", "MIN_LEG_M", "LegHeadings", "gyro_yaw_rate", "leg_headings"]

MIN_LEG_M = 4.0
"""Legs between waypoints at least this long are read, m."""
LEG_SPAN = (0.3, 0.8)
"""The part of each leg's time whose heading is read: past the turn at its start (a
mark comes about a second before its walker turns) and before the next."""
HEADING_MEAN_S = 2.0
"""The heading's swing is of its means over this long, s: about a stride's two steps."""


@dataclass(frozen=True)
class LegHeadings:
    """:func:`leg_headings` of one walk, one entry per leg read, in order."""

    leg: NDArray[np.int64]
    """Each leg's index: leg i runs from waypoint i to waypoint i + 1."""
    length_m: NDArray[np.float64]
    """Each leg's length between its marks, m."""
    marks_deg: NDArray[np.float64]
    """The marks' direction less the gyro's heading along the leg, after the walk's one
    best offset, degrees; NaN for a walk of fewer than two legs read."""
    swing_deg: NDArray[np.float64]
    """Peak-to-peak of the heading's :data:`HEADING_MEAN_S` means along the leg, degrees."""


def gyro_yaw_rate(rec: Recording) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The gyro's rate of turn about gravity (the accelerometer's 1 s mean), at the
    gyro's times: (t, rate), rad/s, counter-clockwise seen from above."""
    t = rec.gyro.index.to_numpy(dtype=float)
    rate_hz = 1.0 / float(np.median(np.diff(t)))
    accel = rec.accel
    t_acc = accel.index.to_numpy(dtype=float)
    up = np.column_stack([np.interp(t, t_acc, accel[c].to_numpy(dtype=float)) for c in "xyz"])
    up = uniform_filter1d(up, max(1, round(rate_hz)), axis=0)
    return t, yaw_rate(rec.gyro[["x", "y", "z"]].to_numpy(dtype=float), up)


def leg_headings(rec: Recording) -> LegHeadings | None:
    """Each long leg's marked direction and heading swing against the gyro (module
    docstring); None where the walk has no waypoints, gyro or accelerometer, or no
    leg long enough to read."""
    if not {"waypoints", "gyro", "accel"} <= set(rec.streams):
        return None
    wp = rec.waypoints
    xy = wp[["x", "y"]].to_numpy(dtype=float)
    marks = wp.index.to_numpy(dtype=float)
    if len(xy) < 2 or len(rec.gyro) < 10 or len(rec.accel) < 2:
        return None
    t, rate = gyro_yaw_rate(rec)
    heading = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t))])
    rate_hz = 1.0 / float(np.median(np.diff(t)))
    smooth = uniform_filter1d(heading, max(1, round(HEADING_MEAN_S * rate_hz)))
    legs, lengths, marked, walked, swings = [], [], [], [], []
    for i in range(len(xy) - 1):
        d = xy[i + 1] - xy[i]
        length = float(np.hypot(d[0], d[1]))
        start, end = marks[i], marks[i + 1]
        span = (t >= start + LEG_SPAN[0] * (end - start)) & (
            t <= start + LEG_SPAN[1] * (end - start)
        )
        if length < MIN_LEG_M or span.sum() < 10:
            continue
        legs.append(i)
        lengths.append(length)
        marked.append(np.arctan2(d[1], d[0]))
        walked.append(float(np.median(heading[span])))
        swings.append(float(np.ptp(smooth[span])))
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
