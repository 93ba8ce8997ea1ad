"""The walked line: how far a handheld device weaves off its straight stretches.

:func:`line_statistics` takes a :class:`~indoorsim.io.recording.Recording` with dense
positions — ``truth`` in a simulated walk, the ARKit positions (``waypoints`` at
10 Hz) of the magnetic-SLAM walks — and measures, over the walk's straightest
stretches, how the device strays sideways from each stretch's line once its stride's
sway is averaged out. The same code path runs on both sides:

1. The positions are put on a 10 Hz clock (the ARKit walks' rate).
2. Stretches of :data:`STRETCH_M` of path whose chord is at least
   :data:`MIN_CHORD` of their length are taken one after another (a gentle curve's
   sagitta stays under a quarter of a metre; corners and detours are left out).
3. In each, the positions are fitted by a line; the sideways offset from it, on a
   5 cm grid along it, is averaged over :data:`STRIDE_M` (a stride: its sway at the
   stride rate averages out), and its RMS and its slope's (the direction of travel
   against the line's) are taken.

Keys (medians over the stretches; NaN without :data:`MIN_STRETCHES` of them, or
without positions at :data:`MIN_RATE_HZ` or more: surveyed waypoints are not a
walked line):

==================  ===========================================================
``weave_cm``        sideways RMS off the stretch's line, stride averaged out (cm)
``weave_deg``       RMS of the direction of travel against the line's (°)
==================  ===========================================================
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from indoorsim.io.recording import Recording

__all__ = ["LINE_KEYS", "MIN_CHORD", "STRETCH_M", "STRIDE_M", "line_statistics", "weave"]

LINE_KEYS = ("weave_cm", "weave_deg")
STRETCH_M = 6.0
"""Length of path of each straight stretch (m)."""
MIN_CHORD = 0.995
"""A stretch counts as straight when its chord is at least this share of its length."""
STRIDE_M = 1.4
"""Averaging length along the line (m): a stride at usual pace."""
MIN_STRETCHES = 3
MIN_RATE_HZ = 5.0
_RATE_HZ = 10.0
_GRID_M = 0.05


def weave(xy: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per straight stretch of the positions ``xy`` ((K, 2), evenly in time): the
    sideways RMS off its line with the stride averaged out (m) and its slope's RMS
    (rad), as two arrays over the stretches."""
    seg = np.hypot(*np.diff(xy, axis=0).T)
    s = np.r_[0.0, np.cumsum(seg)]
    rms, slope_rms = [], []
    i = 0
    while True:
        j = int(np.searchsorted(s, s[i] + STRETCH_M))
        if j >= len(s):
            break
        w = xy[i : j + 1]
        if np.hypot(*(w[-1] - w[0])) < MIN_CHORD * STRETCH_M:
            i += 3  # slide on and look again
            continue
        c = w - w.mean(axis=0)
        _, _, vt = np.linalg.svd(c, full_matrices=False)
        along, across = c @ vt[0], c @ vt[1]
        order = np.argsort(along)
        grid = np.arange(along.min(), along.max(), _GRID_M)
        lateral = np.interp(grid, along[order], across[order])
        k = round(STRIDE_M / _GRID_M)
        if len(lateral) > k + 2:
            smooth = np.convolve(lateral, np.ones(k) / k, mode="valid")
            rms.append(float(smooth.std()))
            slope_rms.append(float(np.arctan(np.gradient(smooth, _GRID_M)).std()))
        i = j
    return np.array(rms), np.array(slope_rms)


def line_statistics(rec: Recording) -> dict[str, float]:
    """The walked line's statistics of ``rec`` (the module docstring's keys)."""
    out = dict.fromkeys(LINE_KEYS, math.nan)
    if "truth" in rec.streams:
        frame = rec.truth
    elif "waypoints" in rec.streams:
        frame = rec.waypoints
    else:
        return out
    t = frame.index.to_numpy(dtype=float)
    if len(t) < 2 or np.median(np.diff(t)) > 1.0 / MIN_RATE_HZ:
        return out
    clock = np.arange(t[0], t[-1], 1.0 / _RATE_HZ)
    xy = np.column_stack([np.interp(clock, t, frame[c].to_numpy(dtype=float)) for c in "xy"])
    rms, slope = weave(xy)
    if len(rms) >= MIN_STRETCHES:
        out["weave_cm"] = 100.0 * float(np.median(rms))
        out["weave_deg"] = math.degrees(float(np.median(slope)))
    return out
