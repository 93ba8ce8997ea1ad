"""How straight the legs were walked: the gyro's heading against the waypoint marks."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.headings import HEADING_MEAN_S, leg_headings
from indoorsim.io.recording import Recording

RATE_HZ = 100.0


def _walk(marks_xy, marks_t, turns, wander=(0.0, 0.1), seconds=60.0):
    """A level phone turning the route's corners: each turn a 2 s raised-cosine pulse
    of the rate of turn centred 1 s after its mark, plus a slow sinusoidal wander of
    the heading (amplitude rad, frequency Hz)."""
    t = np.arange(0.0, seconds, 1.0 / RATE_HZ)
    rate = np.zeros_like(t)
    for at, angle in turns:
        pulse = np.abs(t - (at + 1.0)) < 1.0
        rate[pulse] += angle / 2.0 * (1 + np.cos(np.pi * (t[pulse] - at - 1.0)))
    amplitude, freq = wander
    rate += amplitude * 2 * np.pi * freq * np.cos(2 * np.pi * freq * t)
    index = pd.Index(t, name="t")
    zero = np.zeros_like(t)
    streams = {
        "gyro": pd.DataFrame({"x": zero, "y": zero, "z": rate}, index=index),
        "accel": pd.DataFrame({"x": zero, "y": zero, "z": zero + 9.81}, index=index),
        "waypoints": pd.DataFrame(
            np.asarray(marks_xy, dtype=float),
            columns=["x", "y"],
            index=pd.Index(np.asarray(marks_t, dtype=float), name="t"),
        ),
    }
    return Recording._from_built(streams, {})


# An L: 20 m east, a left turn, 20 m north, at 1 m/s. The gyro's heading starts at 0
# whatever the map says: the one offset per walk absorbs that.
MARKS = [[0.0, 0.0], [20.0, 0.0], [20.0, 20.0]]
TIMES = [0.0, 20.0, 40.0]
TURNS = [(20.0, math.pi / 2)]


def test_legs_walked_straight_from_mark_to_mark_read_no_departure():
    legs = leg_headings(_walk(MARKS, TIMES, TURNS))
    assert legs is not None
    np.testing.assert_array_equal(legs.leg, [0, 1])
    np.testing.assert_allclose(legs.length_m, [20.0, 20.0])
    np.testing.assert_allclose(legs.marks_deg, 0.0, atol=0.05)
    np.testing.assert_allclose(legs.swing_deg, 0.0, atol=0.05)


def test_a_mark_beside_the_walked_line_shows_as_half_its_angle_on_either_leg():
    # The corner marked 2 m north of where it was walked: the first leg's marks point
    # atan(2/20) left of the walk, the second's (still due north) not at all. The
    # walk's one offset takes half of it, so the legs read half each, in opposite senses.
    marks = [[0.0, 0.0], [20.0, 2.0], [20.0, 20.0]]
    legs = leg_headings(_walk(marks, TIMES, TURNS))
    first = math.degrees(math.atan2(2.0, 20.0))
    second = math.degrees(math.atan2(18.0, 0.0)) - 90.0  # 0: the second leg is due north
    offset = (first + second) / 2
    np.testing.assert_allclose(legs.marks_deg, [first - offset, second - offset], atol=0.05)


def test_the_swing_is_the_peak_to_peak_of_the_headings_2_s_means():
    # A 0.1 Hz wander of 5° amplitude: its 2 s means keep sinc(0.1 Hz · 2 s) of it, and
    # each leg's read span (10 s) holds one whole period.
    amplitude, freq = math.radians(5.0), 0.1
    legs = leg_headings(_walk(MARKS, TIMES, TURNS, wander=(amplitude, freq)))
    kept = np.sinc(freq * HEADING_MEAN_S)
    np.testing.assert_allclose(legs.swing_deg, 2 * 5.0 * kept, rtol=0.02)


def test_short_legs_are_not_read_and_one_leg_has_no_offset_to_fit():
    short = leg_headings(_walk([[0.0, 0.0], [3.0, 0.0], [3.0, 3.0]], [0.0, 3.0, 6.0], []))
    assert short is None
    one = leg_headings(_walk([[0.0, 0.0], [20.0, 0.0]], [0.0, 20.0], []))
    assert one is not None and len(one.leg) == 1 and np.isnan(one.marks_deg).all()
    assert one.swing_deg[0] == pytest.approx(0.0, abs=0.05)


def test_a_walk_without_marks_or_gyro_is_not_read():
    rec = _walk(MARKS, TIMES, TURNS)
    streams = {k: v for k, v in rec.streams.items() if k != "gyro"}
    assert leg_headings(Recording._from_built(streams, {})) is None
