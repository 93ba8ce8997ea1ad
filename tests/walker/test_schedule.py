"""Carrying-mode schedules: three ways of writing one, each checked once, one message style."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from indoorsim.walker.carry import carry
from indoorsim.walker.modes import UnknownModeError, available_modes
from indoorsim.walker.schedule import ModeSchedule, ScheduleEntry, ScheduleError


def test_a_mode_name_is_one_entry_from_0_s_written_as_the_name():
    schedule = ModeSchedule.of("calling")
    assert schedule.entries == (ScheduleEntry(0.0, "calling", {}),)
    assert schedule.written == "calling"
    assert ModeSchedule.of(schedule) is schedule


def test_entries_keep_the_form_they_were_written_in():
    given = [(0, "handheld", {"pitch_deg": 0.0}), [np.float64(8.5), "pocketed"]]
    schedule = ModeSchedule.of(given)
    assert schedule.entries == (
        ScheduleEntry(0.0, "handheld", {"pitch_deg": 0.0}),
        ScheduleEntry(8.5, "pocketed", {}),
    )
    assert all(type(e.t_start_s) is float for e in schedule.entries)
    assert schedule.written == ((0, "handheld", {"pitch_deg": 0.0}), (np.float64(8.5), "pocketed"))
    given[0][2]["pitch_deg"] = 45.0  # the schedule holds copies
    assert schedule.entries[0].params == {"pitch_deg": 0.0}
    # Equal schedules compare equal, however they were written.
    assert ModeSchedule.of([(0.0, "calling")]) == ModeSchedule.of("calling")
    assert pickle.loads(pickle.dumps(schedule)) == schedule


def test_the_command_line_syntax():
    schedule = ModeSchedule.parse("handheld, 30:calling,60.5:pocketed")
    assert [(e.t_start_s, e.mode) for e in schedule.entries] == [
        (0.0, "handheld"),
        (30.0, "calling"),
        (60.5, "pocketed"),
    ]
    assert schedule.written == ((0.0, "handheld"), (30.0, "calling"), (60.5, "pocketed"))
    assert ModeSchedule.parse("0:dangling").written == "dangling"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("handheld,,8:calling", r"schedule\[1\]: '' names no carrying mode"),
        ("handheld,calling", r"schedule\[1\]: 'calling' needs a start time, as in 30:calling"),
        ("handheld,soon:calling", r"schedule\[1\]: 'soon' is not a start time in seconds >= 0"),
        ("handheld,-3:calling", r"schedule\[1\]: '-3' is not a start time"),
        ("handheld,inf:calling", r"schedule\[1\]: 'inf' is not a start time"),
        ("5:handheld", r"schedule\[0\]: the first mode must start at 0 s, not 5 s"),
        ("handheld,9:calling,8:pocketed", r"schedule\[2\]: .*increase \(pocketed at 8 s follows 9"),
    ],
)
def test_bad_command_line_schedules_name_the_entry(text, message):
    with pytest.raises(ScheduleError, match=message):
        ModeSchedule.parse(text)


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ([], "empty carrying schedule"),
        (
            3,
            r"expected a carrying-mode name or a schedule \[\(t_start, mode\[, params\]\), .*got 3",
        ),
        ([("handheld",)], r"schedule\[0\]: expected \(t_start, mode\) or"),
        (
            [("0", "handheld")],
            r"schedule\[0\]: the start time must be a number of seconds, got '0'",
        ),
        ([(True, "handheld")], r"schedule\[0\]: the start time must be a number"),
        ([(0.0, "handheld"), (np.nan, "calling")], r"schedule\[1\]: .* finite, got nan"),
        ([(0.0, "handheld"), (0.0, "calling")], r"schedule\[1\]: start times must increase"),
        ([(2.0, "handheld")], r"schedule\[0\]: the first mode must start at 0 s, not 2 s"),
        ([(0.0, 7)], r"schedule\[0\]: the mode must be a carrying-mode name, got 7"),
        ([(0.0, "handheld", 5)], r"schedule\[0\]: the parameters of mode 'handheld' must be a"),
        (
            [(0.0, "handheld", {"pich_deg": 1})],
            r"schedule\[0\]: unknown parameter\(s\) \['pich_deg",
        ),
    ],
)
def test_bad_schedules_name_the_entry(value, message):
    with pytest.raises(ScheduleError, match=message):
        ModeSchedule.of(value)


def test_an_unknown_mode_names_its_entry_and_lists_the_valid_modes():
    valid = ", ".join(available_modes())
    with pytest.raises(UnknownModeError) as info:
        ModeSchedule.of([(0.0, "handheld"), (5.0, "juggling")])
    assert str(info.value) == (
        f"unknown carrying mode 'juggling' in schedule[1]; valid carrying modes are: {valid}"
    )
    with pytest.raises(UnknownModeError) as info:
        ModeSchedule.parse("juggling")
    assert str(info.value) == f"unknown carrying mode 'juggling'; valid carrying modes are: {valid}"


def test_carry_follows_a_schedule_as_it_follows_the_entries_it_holds(straight_body):
    given = [(0, "handheld"), (8, "pocketed", {"top_down": True}), (14.0, "calling")]
    a = carry(straight_body, given, np.random.default_rng(4))
    b = carry(straight_body, ModeSchedule.of(given), np.random.default_rng(4))
    for field in ("pos", "quat", "light_exposure", "mode"):
        assert getattr(a, field).tobytes() == getattr(b, field).tobytes(), field
