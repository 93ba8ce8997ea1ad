"""The Oxford step-counter data set: optimisation folders and validation files."""

from __future__ import annotations

import math
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from indoorsim.io.reallogs.common import (
    NOT_FINITE,
    XYZ,
    PathLike,
    build_recording,
    carry_mode,
    finite_rows,
    median_rates_hz,
    read_csv_columns,
    report_malformed,
    ticks_to_seconds,
    time_frame,
)
from indoorsim.io.recording import Recording, RecordingError


def _step_rows(t: NDArray[np.float64], extra: dict[str, ArrayLike] | None = None) -> pd.DataFrame:
    """A ``steps`` stream for steps whose foot and length the log does not know."""
    n = len(t)
    columns: dict[str, ArrayLike] = {
        "foot": np.full(n, None, dtype=object),
        "length": np.full(n, np.nan),
    }
    return time_frame(t, columns | (extra or {}))


BOUNCE_STRIDES = 0.5
"""A channel of the reference device that rises again within this share of a stride
(the median interval between its own rises) of its last step is the switch bouncing,
not a step: one foot cannot strike twice within half a stride (0.50–0.59 s at the
1.7–2 steps/s of these walks)."""
MISSED_STRIDES = 1.5
"""Two steps of one channel with none of the other between, at most this many strides
apart, hold a contact the other channel missed: the feet alternate while walking, so
the other foot struck in between. Further apart (a halt, a turn on the spot) nothing
is added."""


@dataclass(frozen=True)
class FootContacts:
    """The reference device's steps with its two faults undone (:func:`foot_contacts`)."""

    t: NDArray[np.float64]
    """Each step's time, s, in order."""
    channel: NDArray[np.int64]
    """The channel (foot) of each step, 1 or 2."""
    inferred: NDArray[np.bool_]
    """True for a contact the device missed, placed midway between its neighbours."""
    bounces: int
    """Rises dropped as the switch bouncing."""


def foot_contacts(t: ArrayLike, channel: ArrayLike) -> FootContacts:
    """The steps of the two-channel reference device, bounces dropped and misses added.

    The device has two switches, read as the two feet (README of the data set), and
    both fail in the recordings: in the swinging-arm walks a channel rises again
    0.27–0.45 s after its last rise, mid-stride (a bounce: 284 rises where the
    spectrum's cadence says ≈ 264 steps, one channel 151 and the other 133), and in
    one pocket walk a channel rises 144 times against the other's 162, with twelve of
    its strides two or three strides long (missed contacts: 15 added). That pocket
    walk's other channel also rises six times 0.29–0.39 s after its own last rise,
    recurring through the walk (15, 65, 75, 120, 150 s), which are dropped as bounces;
    whether some are a foot re-planted in a turn, which a step count might count, the
    recording cannot tell (6 of its 315 steps). A rise within
    :data:`BOUNCE_STRIDES` of a stride of the same channel's last kept step is
    dropped; between two kept steps of one channel with none of the other's between,
    at most :data:`MISSED_STRIDES` strides apart, the other foot's step is added
    midway. A device that alternates cleanly is returned unchanged, and so is one
    whose channels cannot be checked against each other (either has fewer than two
    rises: a stride cannot be measured, or the other foot's steps are not there to
    alternate with).

    Args:
        t: (N,) times of the rises, s.
        channel: (N,) the channel of each rise, 1 or 2.

    Raises:
        ValueError: a time that is not finite, a channel other than 1 or 2, or
            lengths that differ.

    >>> c = foot_contacts([0.0, 0.5, 0.8, 1.0, 1.5, 2.0, 3.0, 3.5], [1, 2, 2, 1, 2, 1, 1, 2])
    >>> c.t.tolist(), c.channel.tolist(), c.bounces  # channel 2 bounced at 0.8
    ([0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5], [1, 2, 1, 2, 1, 2, 1, 2], 1)
    >>> c.inferred.nonzero()[0].tolist()  # channel 2 missed its step between 2 and 3
    [5]
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    channel = np.asarray(channel, dtype=np.int64).reshape(-1)
    if len(t) != len(channel):
        raise ValueError(f"{len(t)} step times but {len(channel)} channels")
    if not np.isfinite(t).all():
        raise ValueError(f"step times must be finite; {int((~np.isfinite(t)).sum())} are not")
    if not np.isin(channel, (1, 2)).all():
        raise ValueError(f"channels must be 1 or 2, got {sorted(set(channel.tolist()))}")
    per_channel = [np.sort(t[channel == c]) for c in (1, 2)]
    if min(len(x) for x in per_channel) < 2:
        order = np.argsort(t, kind="stable")
        return FootContacts(t[order], channel[order], np.zeros(len(t), dtype=bool), 0)
    stride = float(np.median(np.concatenate([np.diff(x) for x in per_channel])))
    kept: list[tuple[float, int]] = []
    bounces = 0
    for c, times in zip((1, 2), per_channel, strict=True):
        last = -math.inf
        for s in times:
            if s - last < BOUNCE_STRIDES * stride:
                bounces += 1
                continue
            kept.append((float(s), c))
            last = s
    kept.sort()
    out_t, out_c, out_inferred = [], [], []
    for k, (s, c) in enumerate(kept):
        if k and kept[k - 1][1] == c and s - kept[k - 1][0] <= MISSED_STRIDES * stride:
            out_t.append(0.5 * (kept[k - 1][0] + s))
            out_c.append(3 - c)
            out_inferred.append(True)
        out_t.append(s)
        out_c.append(c)
        out_inferred.append(False)
    return FootContacts(
        np.array(out_t), np.array(out_c, dtype=np.int64), np.array(out_inferred), bounces
    )


def read_oxford_folder(path: PathLike) -> Recording:
    """Read an Oxford step-counter optimisation folder ``<Phone>_<User>_<Surface>_<Position>_<n>``.

    Mapping:

    * ``accelerometer.csv`` (no header: ``SensorEvent.timestamp`` ns, accuracy
      flag, x, y, z m/s² with gravity) → ``accel``; the accuracy flag (always 3)
      is dropped.
    * ``stepcounter.csv`` (no header: timestamp ns on the same clock, then the
      binary states of the two channels of the ground-truth device) → ``steps``:
      the 0→1 transitions on either channel, which upstream's ``stats.js``
      counts as the steps (a channel that starts at 1 is not a step), with the
      device's faults undone by :func:`foot_contacts` — a channel's bounce
      dropped, a contact it missed between two of its steps added (column
      ``inferred`` True). ``foot`` is missing and ``length`` NaN: that the
      channels are the two feet is a reading, not documented upstream; the
      channel (1 or 2) is kept in column ``channel``.
    * ``metadata.txt`` (some folders) → ``meta["sensors"]["accel"]["name"]``.
    * The folder name → ``meta`` ``device`` (phone), ``user``, ``surface``,
      ``position`` and ``trial``; ``mode`` from the position (``InHand`` →
      handheld, ``FrontPocket``/``BackPocket`` → pocketed, ``SwingingArm`` →
      dangling, others as given).

    ``t`` = (ns − first accelerometer ns)/1e9 (a clock since boot;
    ``meta["t0_boot_ns"]``). ``meta["ground_truth_steps"]`` is the step count,
    ``meta["device_steps"]`` the device's own (upstream's: every transition),
    ``meta["channel_steps"]`` the device's count per channel, and
    ``meta["switch_bounces"]`` and ``meta["missed_contacts"]`` what the check
    dropped and added. Rows that cannot be read
    are skipped and counted as ``"<file>.csv: <reason>"`` in
    ``meta["malformed_rows"]``, with a warning (see :mod:`indoorsim.io.reallogs`).
    """
    folder = Path(path)
    malformed: Counter[str] = Counter()
    accel = read_csv_columns(
        _text(folder / "accelerometer.csv"),
        {"ns": int, "accuracy": int, "x": float, "y": float, "z": float},
        header=False,
        malformed=malformed,
        file="accelerometer.csv",
    )
    if accel.empty:
        raise RecordingError(f"{folder / 'accelerometer.csv'}: no rows")
    ticks = accel["ns"].to_numpy()
    t0 = int(ticks.min())
    streams = {
        "accel": time_frame(
            ticks_to_seconds(ticks, t0, 1e9), {c: accel[c].to_numpy() for c in XYZ}
        ),
    }
    counter = read_csv_columns(
        _text(folder / "stepcounter.csv"),
        {"ns": int, "channel_1": int, "channel_2": int},
        header=False,
        malformed=malformed,
        file="stepcounter.csv",
    )
    step_t, step_channel, per_channel = [], [], []
    state_t = ticks_to_seconds(counter["ns"].to_numpy(), t0, 1e9)
    for channel in (1, 2):
        state = counter[f"channel_{channel}"].to_numpy()
        rises = np.flatnonzero((state[1:] == 1) & (state[:-1] == 0)) + 1
        step_t.append(state_t[rises])
        step_channel.append(np.full(len(rises), channel, dtype=np.int64))
        per_channel.append(len(rises))
    contacts = foot_contacts(np.concatenate(step_t), np.concatenate(step_channel))
    streams["steps"] = _step_rows(
        contacts.t, {"channel": contacts.channel, "inferred": contacts.inferred}
    )
    streams = finite_rows(streams, malformed, {"accel": "accelerometer.csv"})

    meta: dict[str, Any] = {"source": {"format": "oxford-stepcounter", "folder": folder.name}}
    parts = folder.name.split("_")
    if len(parts) == 5:
        phone, user, surface, position, trial = parts
        meta |= {
            "device": phone,
            "user": user,
            "surface": surface,
            "position": position,
            "trial": int(trial) if trial.isdigit() else trial,
            "mode": carry_mode(position),
        }
    else:
        meta |= {"device": None, "mode": None}
    sensor_file = folder / "metadata.txt"
    if sensor_file.is_file():
        for line in _text(sensor_file).splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "accelerometer" and value.strip():
                meta["sensors"] = {"accel": {"name": value.strip()}}
    meta |= {
        "t0_boot_ns": t0,
        "frames": {"phone": "Android sensor frame (x right, y up the screen, z out of it)"},
        "rates_hz": median_rates_hz(streams),
        "ground_truth_steps": len(streams["steps"]),
        "device_steps": sum(per_channel),
        "channel_steps": per_channel,
        "switch_bounces": contacts.bounces,
        "missed_contacts": int(contacts.inferred.sum()),
        "dropped_rows": {},
        "malformed_rows": report_malformed(folder, malformed),
    }
    return build_recording(folder, streams, meta)


def _text(path: Path) -> str:
    # Bytes that are not UTF-8 become U+FFFD, and their row a malformed row.
    return path.read_text(encoding="utf-8", errors="replace")


def looks_like_oxford_folder(path: Path) -> bool:
    return (path / "accelerometer.csv").is_file() and (path / "stepcounter.csv").is_file()


_COUNT_OUT_OF_RANGE = "with a step count beyond 2**53"
_MAX_STEPS_PER_ROW = 1000

_VALIDATION_NAME = re.compile(r"^(?P<user>[^_]+)_(?P<position>[^_]+)_(?P<start_ms>\d+)$")


def read_oxford_validation(path: PathLike) -> Recording:
    """Read an Oxford step-counter validation file ``<user>_<position>_<unix-ms-start>.csv``.

    Seven columns, no header (upstream ``validation/README.md``):

    1. ``SensorEvent.timestamp``, ns since boot → ``t`` = (ns − first ns)/1e9;
    2–4. acc x, y, z (m/s², gravity included) → ``accel``;
    5. the app's own step algorithm, cumulative → dropped; its final count is
       ``meta["app_algorithm_steps"]``;
    6. the ground-truth device, cumulative → ``steps``: one row at each row
       where it increases (k rows if it jumps by k); ``foot`` missing,
       ``length`` NaN; the total is ``meta["ground_truth_steps"]`` (and
       ``meta["device_steps"]``: with no channels the device's faults cannot be
       checked, :func:`foot_contacts`);
    7. the phone's hardware step counter, cumulative → dropped; its final count
       is ``meta["hardware_steps"]``, None when the column is all zero (not
       recorded).

    Leading rows whose three axes are exactly 0 are dropped (counted in
    ``meta["dropped_rows"]``): a still phone cannot read zero specific force,
    so such a first row is a placeholder written before the first sensor event.
    The file name gives ``meta`` ``user``, ``position``, ``mode`` (``hand`` →
    handheld, ``frontpocket``/``backpocket`` → pocketed, others as given) and
    ``start_time_unix_ms``; the phone is a Samsung Galaxy S6 (upstream README).
    Rows that cannot be read are skipped and counted by reason in
    ``meta["malformed_rows"]``, with a warning (see :mod:`indoorsim.io.reallogs`).

    Raises:
        RecordingError: the ground-truth count decreases or jumps by more than 1000 steps at
            one row, or the file has no readable row.
    """
    source = Path(path)
    malformed: Counter[str] = Counter()
    columns = ("ns", "x", "y", "z", "app_steps", "truth_steps", "hardware_steps")
    table = read_csv_columns(
        _text(source),
        {name: int if name == "ns" else float for name in columns},
        header=False,
        malformed=malformed,
    )
    data = table[list(columns)].to_numpy(dtype=np.float64)
    ns = table["ns"].to_numpy(dtype=np.int64)
    good = np.isfinite(data).all(axis=1)
    malformed[NOT_FINITE] += int((~good).sum())
    # Step counts are whole numbers, cast to int64 below: exact only within 2**53.
    counts = np.abs(np.where(good[:, None], data[:, 4:], 0.0)) <= 2.0**53
    malformed[_COUNT_OUT_OF_RANGE] += int((good & ~counts.all(axis=1)).sum())
    keep = good & counts.all(axis=1)
    data, ns = data[keep], ns[keep]
    if len(data) == 0:
        raise RecordingError(f"{source}: no rows of 7 comma-separated numbers")
    placeholder = np.all(data[:, 1:4] == 0.0, axis=1)
    leading = int(np.argmin(placeholder)) if not placeholder.all() else len(data)
    data = data[leading:]
    if len(data) == 0:
        raise RecordingError(f"{source}: every accelerometer row is zero")
    ticks = ns[leading:]
    t0 = int(ticks.min())
    t = ticks_to_seconds(ticks, t0, 1e9)
    truth_count = data[:, 5].astype(np.int64)
    increments = np.diff(truth_count, prepend=truth_count[0])
    if (increments < 0).any():
        row = int(np.argmax(increments < 0)) + leading
        raise RecordingError(f"{source}: ground-truth step count decreases at row {row}")
    if (increments > _MAX_STEPS_PER_ROW).any():
        row = int(np.argmax(increments > _MAX_STEPS_PER_ROW)) + leading
        raise RecordingError(
            f"{source}: ground-truth step count jumps by {int(increments.max())} at row {row} "
            f"(more than {_MAX_STEPS_PER_ROW} steps between two samples is no walk)"
        )
    streams = {
        "accel": time_frame(t, {"x": data[:, 1], "y": data[:, 2], "z": data[:, 3]}),
        "steps": _step_rows(np.repeat(t, increments)),
    }
    hardware = data[:, 6].astype(np.int64)
    meta: dict[str, Any] = {
        "source": {"format": "oxford-stepcounter-validation", "file": source.name},
        "device": "Samsung Galaxy S6",
        "mode": None,
    }
    match = _VALIDATION_NAME.match(source.stem)
    if match:
        meta |= {
            "user": match["user"],
            "position": match["position"],
            "mode": carry_mode(match["position"]),
            "start_time_unix_ms": int(match["start_ms"]),
        }
    meta |= {
        "t0_boot_ns": t0,
        "frames": {"phone": "Android sensor frame (x right, y up the screen, z out of it)"},
        "rates_hz": median_rates_hz(streams),
        "ground_truth_steps": int(increments.sum()),
        "device_steps": int(increments.sum()),
        "app_algorithm_steps": int(data[-1, 4] - data[0, 4]),
        "hardware_steps": int(hardware[-1] - hardware[0]) if hardware.any() else None,
        "dropped_rows": {"zero_accel_placeholder": leading} if leading else {},
        "malformed_rows": report_malformed(source, malformed),
    }
    return build_recording(source, streams, meta)


def looks_like_oxford_validation(path: Path) -> bool:
    if not path.is_file() or path.suffix.lower() != ".csv":
        return False
    with path.open(encoding="utf-8", errors="replace") as lines:
        fields = lines.readline().strip().split(",")
    if len(fields) != 7:
        return False
    try:
        [float(f) for f in fields]
    except ValueError:
        return False
    return True
