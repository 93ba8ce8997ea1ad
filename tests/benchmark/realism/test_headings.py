"""How straight the legs were walked: the gyro's heading against the waypoint marks."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.headings import (
    HEADING_MEAN_S,
    gyro_heading,
    leg_headings,
    rotation_heading,
)
from indoorsim.io.recording import Recording
from indoorsim.util import quaternion

RATE_HZ = 100.0


def _walk(marks_xy, marks_t, turns, wander=(0.0, 0.1), seconds=60.0, bump=None):
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
    if bump is not None:  # (start, seconds, angle): a brief glance aside and back
        at, length, angle = bump
        out = (t >= at) & (t < at + 0.5)
        back = (t >= at + length - 0.5) & (t < at + length)
        rate[out] += angle / 0.5
        rate[back] -= angle / 0.5
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


def test_a_map_turned_half_round_is_one_offset_whatever_side_of_180_it_falls():
    # The map turned 178° against the gyro, and the corner marked 2 m off as above: the
    # two legs' disagreements straddle ±180°, whose plain mean would be near 0.
    turn = math.radians(178.0)
    rot = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    marks = np.array([[0.0, 0.0], [20.0, 2.0], [20.0, 20.0]]) @ rot.T
    legs = leg_headings(_walk(marks, TIMES, TURNS))
    half = math.degrees(math.atan2(2.0, 20.0)) / 2
    np.testing.assert_allclose(legs.marks_deg, [half, -half], atol=0.05)


def test_a_glance_aside_swings_the_heading_but_does_not_move_the_legs_direction():
    # 20° aside for 1.5 s in the middle of the first leg: the median heading stays on
    # the leg (a mean would move 1.7°); the swing sees the glance through its 2 s means:
    # 20°·1 s of turning aside (0.5 s out, 0.5 s held, 0.5 s back) over 2 s is 10°.
    legs = leg_headings(_walk(MARKS, TIMES, TURNS, bump=(10.0, 1.5, math.radians(20.0))))
    np.testing.assert_allclose(legs.marks_deg, 0.0, atol=0.05)
    assert legs.swing_deg[0] == pytest.approx(10.0, rel=0.02)
    assert legs.swing_deg[1] == pytest.approx(0.0, abs=0.05)


def test_a_short_legs_corners_do_not_leak_into_its_swing():
    # A square of 8 m legs at 1 m/s: each leg's clear part (5 s) lies between its
    # corners' turns, so straight legs swing not at all; 5 m legs are too short to read.
    square = [[0.0, 0.0], [8.0, 0.0], [8.0, 8.0], [0.0, 8.0], [0.0, 0.0]]
    times = [0.0, 8.0, 16.0, 24.0, 32.0]
    turns = [(8.0, math.pi / 2), (16.0, math.pi / 2), (24.0, math.pi / 2)]
    legs = leg_headings(_walk(square, times, turns, seconds=40.0))
    np.testing.assert_array_equal(legs.leg, [0, 1, 2, 3])
    np.testing.assert_allclose(legs.swing_deg, 0.0, atol=0.05)
    np.testing.assert_allclose(legs.marks_deg, 0.0, atol=0.05)
    small = [[x * 5 / 8, y * 5 / 8] for x, y in square]
    fives = [(5.0 * k, math.pi / 2) for k in (1, 2, 3)]
    assert leg_headings(_walk(small, [0.0, 5.0, 10.0, 15.0, 20.0], fives, seconds=25.0)) is None


def test_a_leg_past_the_gyros_record_is_not_read_and_a_gyro_dropout_is_bridged():
    # The last mark 40 s after the gyro stops: that leg is left out.
    rec = _walk(MARKS, [0.0, 20.0, 100.0], TURNS)
    legs = leg_headings(rec)
    assert list(legs.leg) == [0] and np.isnan(legs.marks_deg).all()
    # A NaN in the gyro during a straight stretch: bridged, nothing changes.
    rec = _walk(MARKS, TIMES, TURNS)
    rec.gyro.iloc[1500, 2] = np.nan
    legs = leg_headings(rec)
    np.testing.assert_allclose(legs.marks_deg, 0.0, atol=0.05)
    np.testing.assert_allclose(legs.swing_deg, 0.0, atol=0.05)


def test_the_rotation_vectors_heading_shows_a_disturbance_the_gyro_does_not_feel():
    """A fused heading that the building's field turns 6° one way on the first leg and
    the other way on the second reads ∓6° against the marks (the marks less the
    heading) where the gyro's reads 0, whatever the phone's tilt and the map's north."""
    rec = _walk(MARKS, TIMES, TURNS)
    t, gyro = gyro_heading(rec)
    disturbance = np.radians(np.where(t < 20.0, 6.0, -6.0))
    yaw = gyro + disturbance + 2.0  # the rotation vector's world is magnetic north's
    tilt = np.array([math.cos(0.3), math.sin(0.3), 0.0, 0.0])  # pitched 34°
    q = quaternion.multiply(
        np.column_stack([np.cos(yaw / 2), np.zeros_like(t), np.zeros_like(t), np.sin(yaw / 2)]),
        tilt,
    )
    rotation = pd.DataFrame(q, columns=["qw", "qx", "qy", "qz"], index=rec.gyro.index)
    rec = Recording._from_built(rec.streams | {"rotation": rotation}, {})
    t_rot, fused = rotation_heading(rec)
    np.testing.assert_allclose(fused - fused[0], yaw - yaw[0], atol=1e-9)
    np.testing.assert_allclose(leg_headings(rec).marks_deg, 0.0, atol=0.05)
    np.testing.assert_allclose(leg_headings(rec, (t_rot, fused)).marks_deg, [-6.0, 6.0], atol=0.05)
