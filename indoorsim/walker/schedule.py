"""Carrying-mode schedules: which mode the phone is carried in from when, checked once.

A schedule is written in one of three ways:

* a mode name, for the whole walk: ``"handheld"``;
* entries ``(t_start_s, mode)`` or ``(t_start_s, mode, params)``, ``params``
  being the mode's fields: ``[(0.0, "handheld", {"pitch_deg": 0.0}), (30.0, "calling")]``;
* on the command line, ``handheld,30:calling,60:pocketed`` (:meth:`ModeSchedule.parse`).

:meth:`ModeSchedule.of` and :meth:`ModeSchedule.parse` turn each into a
:class:`ModeSchedule` and check everything the schedule alone decides: the
mode names (against the registry of :mod:`indoorsim.walker.modes`), the start
times (finite, increasing, the first at 0 s) and the parameter names. Every
problem is a :class:`ScheduleError` (or, for a mode name, an
:class:`~indoorsim.walker.modes.UnknownModeError`) naming its entry:
``schedule[2]: ...``. What only the walk decides, a change after the walk's
end or two changes closer than the transition between them, is checked by
:func:`~indoorsim.walker.carry.carry` when it follows the schedule.

Example:
    >>> ModeSchedule.parse("handheld,30:calling").entries[1]
    ScheduleEntry(t_start_s=30.0, mode='calling', params={})
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from numbers import Real
from typing import Any, NamedTuple, TypeAlias

from indoorsim.walker.modes import UnknownModeError, mode_fields

__all__ = ["ModeSchedule", "ScheduleEntry", "ScheduleError", "ScheduleLike"]


class ScheduleError(ValueError):
    """A carrying schedule that cannot be followed; the message names the entry."""


class ScheduleEntry(NamedTuple):
    """One entry of a schedule: from ``t_start_s`` on, the phone is carried as ``mode``.

    Attributes:
        t_start_s: when the mode starts, seconds from the start of the walk.
        mode: the carrying mode's registered name.
        params: the mode's fields that differ from its defaults (a copy).
    """

    t_start_s: float
    mode: str
    params: dict[str, Any]


@dataclass(frozen=True)
class ModeSchedule:
    """A checked carrying-mode schedule (see the module docstring).

    Construct it with :meth:`of` or :meth:`parse`; constructing it directly
    from entries checks them the same way.

    Attributes:
        entries: the schedule's entries, the first at 0 s, start times increasing.
        written: the schedule as its caller wrote it: the mode name, or the
            entries as given (their start times unconverted, each with its
            ``params`` only if it had them). A recording's metadata stores
            this form, so it says what was asked for.

    Raises:
        ScheduleError: a malformed entry, a start time that is not a finite
            number, a first mode that does not start at 0 s, start times that do
            not increase, or a parameter the mode does not have.
        UnknownModeError: a mode name that is not registered.
    """

    entries: tuple[ScheduleEntry, ...]
    written: str | tuple[tuple[Any, ...], ...] | None = field(
        default=None, compare=False, repr=False
    )

    def __post_init__(self) -> None:
        given = tuple(self.entries)
        if not given:
            raise ScheduleError("empty carrying schedule")
        entries = tuple(_entry(i, raw) for i, raw in enumerate(given))
        named = isinstance(self.written, str)
        for i, entry in enumerate(entries):
            _check(i, entry, entries[i - 1] if i else None, named=named)
        object.__setattr__(self, "entries", entries)
        if self.written is None:
            object.__setattr__(self, "written", tuple(_as_given(raw) for raw in given))

    @classmethod
    def of(cls, value: ScheduleLike) -> ModeSchedule:
        """A schedule from a mode name, a sequence of entries, or a schedule (returned as it is).

        Raises:
            ScheduleError: ``value`` is none of these, or a bad schedule (see the class).
            UnknownModeError: a mode name that is not registered.
        """
        if isinstance(value, ModeSchedule):
            return value
        if isinstance(value, str):
            return cls((ScheduleEntry(0.0, value, {}),), written=value)
        if isinstance(value, Sequence):
            return cls(tuple(value))
        raise ScheduleError(
            "expected a carrying-mode name or a schedule [(t_start, mode[, params]), ...], "
            f"got {value!r}"
        )

    @classmethod
    def parse(cls, text: str) -> ModeSchedule:
        """A schedule from the command line's syntax: ``handheld,30:calling,60:pocketed``.

        Comma-separated entries ``START:MODE``, ``START`` in seconds from the
        start of the walk; the first entry starts at 0 and may omit its time.
        A single mode is written (see :attr:`written`) as its name.

        Raises:
            ScheduleError: bad syntax, or a bad schedule (see the class).
            UnknownModeError: a mode name that is not registered.
        """
        entries: list[tuple[float, str]] = []
        for i, item in enumerate(text.split(",")):
            when, colon, name = item.strip().rpartition(":")
            name = name.strip()
            if not name:
                raise ScheduleError(f"schedule[{i}]: {item!r} names no carrying mode")
            if not colon and i > 0:
                raise ScheduleError(f"schedule[{i}]: {name!r} needs a start time, as in 30:{name}")
            try:
                t_start = float(when) if colon else 0.0
            except ValueError:
                t_start = math.nan
            if not (math.isfinite(t_start) and t_start >= 0):
                raise ScheduleError(
                    f"schedule[{i}]: {when.strip()!r} is not a start time in seconds >= 0"
                )
            entries.append((t_start, name))
        return cls(tuple(entries), written=entries[0][1] if len(entries) == 1 else tuple(entries))


ScheduleLike: TypeAlias = (
    str | Sequence[tuple[float, str] | tuple[float, str, Mapping[str, Any]]] | ModeSchedule
)
"""What :meth:`ModeSchedule.of` takes: a mode name, entries, or a schedule."""


def _entry(i: int, raw: object) -> ScheduleEntry:
    """``raw`` as an entry, its start time a float: its shape and types checked, not its values."""
    if not isinstance(raw, tuple | list) or len(raw) not in (2, 3):
        raise ScheduleError(
            f"schedule[{i}]: expected (t_start, mode) or (t_start, mode, params), got {raw!r}"
        )
    t_start, name = raw[0], raw[1]
    if isinstance(t_start, bool) or not isinstance(t_start, Real):
        raise ScheduleError(
            f"schedule[{i}]: the start time must be a number of seconds, got {t_start!r}"
        )
    if not isinstance(name, str):
        raise ScheduleError(f"schedule[{i}]: the mode must be a carrying-mode name, got {name!r}")
    params = raw[2] if len(raw) == 3 else {}
    if not isinstance(params, Mapping):
        raise ScheduleError(
            f"schedule[{i}]: the parameters of mode {name!r} must be a mapping, got {params!r}"
        )
    return ScheduleEntry(float(t_start), name, dict(params))


def _as_given(raw: Sequence[Any]) -> tuple[Any, ...]:
    """A checked entry as its caller wrote it, with a copy of its ``params`` if it had them."""
    return (raw[0], raw[1], dict(raw[2])) if len(raw) == 3 else (raw[0], raw[1])


def _check(i: int, entry: ScheduleEntry, before: ScheduleEntry | None, *, named: bool) -> None:
    """Check entry ``i`` against the one ``before`` it and the mode registry.

    ``named``: the schedule was written as a mode name, so a message need not
    point at an entry.
    """
    t_start, name, params = entry
    if not math.isfinite(t_start):
        raise ScheduleError(f"schedule[{i}]: the start time must be finite, got {t_start}")
    if before is None and t_start != 0:
        raise ScheduleError(f"schedule[0]: the first mode must start at 0 s, not {t_start:g} s")
    if before is not None and t_start <= before.t_start_s:
        raise ScheduleError(
            f"schedule[{i}]: start times must increase ({name} at {t_start:g} s "
            f"follows {before.t_start_s:g} s)"
        )
    try:
        fields = mode_fields(name)
    except UnknownModeError as err:
        if named:
            raise
        raise UnknownModeError(name, err.valid, f"in schedule[{i}]") from None
    unknown = sorted(set(params) - fields)
    if unknown:
        raise ScheduleError(
            f"schedule[{i}]: unknown parameter(s) {unknown} for mode {name!r}; "
            f"its parameters are {sorted(fields)}"
        )
