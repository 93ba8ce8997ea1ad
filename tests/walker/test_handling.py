"""Handling: the hand's reach between carrying places and a pocket's stroke, in closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from indoorsim.walker.carry import carry
from indoorsim.walker.gait import smootherstep
from indoorsim.walker.handling import (
    STROKE_RISE_S,
    PocketStroke,
    draw_pocket_stroke,
    handover,
    stroke_depth,
)
from indoorsim.walker.schedule import ScheduleError

STROKE = PocketStroke(axis=np.array([0.0, 1.0, 0.0]), depth_m=0.12, speed_mps=0.4, stop_s=0.03)


def test_a_stroke_goes_the_pockets_depth_at_its_speed_and_stops_as_a_half_cosine():
    dt = 1e-4
    tau = np.arange(-0.1, STROKE.duration_s + 0.1, dt)
    depth = stroke_depth(tau, STROKE)
    assert np.all(depth[tau <= 0] == 0.0) and np.all(depth[tau >= STROKE.duration_s] == 0.12)
    speed = np.gradient(depth, dt)
    assert np.all(speed >= -1e-9)
    cruise = (tau > STROKE_RISE_S + 0.01) & (tau < STROKE.duration_s - STROKE.stop_s - 0.01)
    assert np.allclose(speed[cruise], 0.4, atol=1e-6)
    # The bottom stops it at π·v/(2·stop): 20.9 m/s² for 0.4 m/s in 30 ms.
    decel = -np.gradient(speed, dt)
    assert decel.max() == pytest.approx(math.pi * 0.4 / (2 * 0.03), rel=1e-3)
    # C²: the acceleration starts and ends each phase at zero (no step in it).
    assert np.abs(np.diff(decel)).max() < 0.05 * decel.max()


@pytest.mark.parametrize(
    ("depth", "speed", "stop", "axis", "match"),
    [
        (0.0, 0.4, 0.03, (0, 1, 0), "positive"),
        (0.12, -0.4, 0.03, (0, 1, 0), "positive"),
        (0.01, 0.6, 0.03, (0, 1, 0), "long enough"),
        (0.12, 0.4, 0.03, (0, 2, 0), "unit vector"),
        (0.12, 0.4, 0.03, (0, 1), "3-vector"),
    ],
)
def test_an_impossible_stroke_is_refused(depth, speed, stop, axis, match):
    with pytest.raises(ValueError, match=match):
        PocketStroke(axis=np.array(axis, float), depth_m=depth, speed_mps=speed, stop_s=stop)


def _places(n: int) -> tuple[np.ndarray, Rotation, np.ndarray, Rotation]:
    """A hand at (0, 0, 1.2) and a pocket at (0.1, −0.2, 0.8) whose phone is upright."""
    hand = np.tile([0.0, 0.0, 1.2], (n, 1))
    pocket = np.tile([0.1, -0.2, 0.8], (n, 1))
    upright = Rotation.from_rotvec(np.tile([np.pi / 2, 0.0, 0.0], (n, 1)))  # phone +y up
    return hand, Rotation.identity(n), pocket, upright


def test_without_a_pocket_the_change_is_one_minimum_jerk_reach():
    tau = np.linspace(0.0, 1.5, 301)
    hand, flat, other, turned = _places(len(tau))
    pos, reach, light = handover(tau, 1.5, (hand, flat, None), (other, turned, None))
    w = smootherstep(tau / 1.5)
    assert np.array_equal(reach, w) and np.array_equal(light, w)
    assert np.array_equal(pos, (1 - w)[:, None] * hand + w[:, None] * other)


def test_into_a_pocket_the_hand_reaches_its_mouth_and_pushes_the_phone_in():
    tau = np.linspace(0.0, 1.5, 3001)
    hand, flat, pocket, upright = _places(len(tau))
    # Upright in the pocket (its top, +y, up): it goes in bottom first, along −y.
    stroke = PocketStroke(axis=np.array([0.0, -1.0, 0.0]), depth_m=0.12, speed_mps=0.4, stop_s=0.03)
    pos, reach, light = handover(tau, 1.5, (hand, flat, None), (pocket, upright, stroke))
    reach_s = 1.5 - stroke.duration_s
    assert np.allclose(pos[0], hand[0]) and np.allclose(pos[-1], pocket[0])
    # At the end of the reach the phone is over the mouth, 0.12 m up the thigh.
    mouth = np.searchsorted(tau, reach_s)
    assert reach[mouth] == pytest.approx(1.0, abs=1e-6)
    assert pos[mouth] == pytest.approx(pocket[0] + [0.0, 0.0, 0.12], abs=1e-4)
    # Then it goes straight down into the pocket and stops; it is dark once in.
    assert np.allclose(pos[mouth:, :2], pocket[0, :2])
    assert np.all(np.diff(pos[mouth:, 2]) <= 1e-12)
    assert np.all(light[: mouth + 1] == 0.0) and light[-1] == 1.0
    assert np.allclose(light[mouth:], (0.8 + 0.12 - pos[mouth:, 2]) / 0.12)


def test_out_of_a_pocket_is_the_stroke_run_backwards_then_the_reach():
    tau = np.linspace(0.0, 1.5, 3001)
    hand, flat, pocket, upright = _places(len(tau))
    into, _, dark = handover(tau, 1.5, (hand, flat, None), (pocket, upright, STROKE))
    out, _, lit = handover(1.5 - tau, 1.5, (pocket, upright, STROKE), (hand, flat, None))
    # The same path, walked the other way in time, and the light the other way round.
    assert np.allclose(out, into, atol=1e-12)
    assert np.allclose(lit, 1.0 - dark, atol=1e-12)


def test_strokes_that_leave_no_time_to_reach_are_refused():
    tau = np.linspace(0.0, 0.3, 11)  # the stroke alone takes 0.365 s
    hand, flat, pocket, upright = _places(len(tau))
    with pytest.raises(ValueError, match="no time to reach"):
        handover(tau, 0.3, (hand, flat, None), (pocket, upright, STROKE))


def test_pocketing_a_phone_jolts_it_as_real_pocketed_phones_are(straight_body):
    """From the hand into the pocket: the largest acceleration while the phone changes
    place is the pocket's bottom stopping it, π·v/(2·stop) over the drawn speeds and
    stops (12–38 m/s²) on top of the hand's and the walk's."""
    peaks = []
    for seed in range(8):
        phone = carry(
            straight_body, [(0.0, "handheld"), (2.0, "pocketed")], np.random.default_rng(seed)
        )
        dt = 1.0 / straight_body.rate_hz
        acc = np.gradient(np.gradient(phone.pos, dt, axis=0), dt, axis=0)
        changing = (phone.t > 2.0) & (phone.t < 3.5)
        peaks.append(np.linalg.norm(acc[changing], axis=1).max())
    assert 10.0 < min(peaks) and max(peaks) < 45.0


def test_the_phone_goes_down_into_the_pocket(straight_body):
    """Standing (the first step is at 3.8 s), the phone put into the pocket from 1.5 s
    goes down the thigh in the stroke's last tenth of a second (every stroke takes
    more than 0.23 s): the pocket's mouth is above its bottom."""
    schedule = [(0.0, "handheld"), (1.5, "pocketed")]
    for seed in range(6):
        phone = carry(straight_body, schedule, np.random.default_rng(seed))
        last = (phone.t > 2.9) & (phone.t < 3.0)
        assert np.all(np.diff(phone.pos[last, 2]) < 0.0)


def test_a_change_too_quick_for_the_pockets_stroke_is_refused(straight_body):
    with pytest.raises(ScheduleError, match=r"schedule\[1\]: .*no time to reach"):
        carry(
            straight_body,
            [(0.0, "handheld"), (1.0, "pocketed")],
            np.random.default_rng(0),
            transition_s=0.2,
        )


def test_a_drawn_stroke_lies_in_its_ranges():
    strokes = [
        draw_pocket_stroke(np.random.default_rng(s), np.array([0.0, 1.0, 0.0])) for s in range(50)
    ]
    jolts = [math.pi * s.speed_mps / (2 * s.stop_s) for s in strokes]
    assert 11.7 < min(jolts) and max(jolts) < 37.8
    assert all(0.10 <= s.depth_m <= 0.14 for s in strokes)
