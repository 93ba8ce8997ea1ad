"""Readers for real phone logs: each turns one log into a :class:`~indoorsim.recording.Recording`.

Formats (each reader's docstring gives its full mapping):

* ``ilc2020`` — Indoor Location Competition 2.0 / Kaggle "indoor-location-
  navigation" path traces (``*.txt``): :func:`read_ilc_trace`.
* ``oxford-stepcounter`` — Oxford step-counter optimisation folders
  (``accelerometer.csv`` + ``stepcounter.csv``): :func:`read_oxford_folder`.
* ``oxford-stepcounter-validation`` — its validation files
  (``<user>_<position>_<unix-ms>.csv``): :func:`read_oxford_validation`.
* ``sensor-logger`` — CSV exports (folder or ``.zip``) of the "Sensor Logger"
  app by Kelvin Choi (tszheichoi): :func:`read_sensor_logger`.

Conventions shared by every reader:

* ``t`` = seconds since the first motion-sensor sample (accelerometer,
  gyroscope, magnetometer or orientation, whichever comes first), computed from
  the log's integer clock so no precision is lost; the log's own value of that
  instant is kept in ``meta`` (``t0_unix_ms``, ``t0_unix_ns`` or ``t0_boot_ns``).
  Rows logged before it (e.g. an ILC trace's first waypoint) get a small
  negative ``t``.
* Values keep the log's units when they already are indoorsim's (m/s², rad/s,
  µT, lux, dBm); frames are the Android sensor frame, as in DESIGN §2.
* A stream is present only when the log has rows for it. Streams are sorted by
  ``t`` (stably). What a reader drops is counted in ``meta["dropped_rows"]``.
* ``meta["mode"]`` is the carry mode in indoorsim's vocabulary when the log
  says it (``handheld``, ``pocketed``, ``dangling``, ``calling``), the log's own
  word for positions indoorsim does not model (e.g. ``Purse``), or None.
* ``meta["rates_hz"]`` is each sensor stream's median sample rate (for ``wifi``,
  the scan rate).

:class:`Recording.load <indoorsim.recording.Recording.load>` picks the reader by
looking at the path (:func:`detect_format`); formats live in the open registry
:data:`FORMATS` (:func:`register_format` adds one).
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
import zipfile
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from indoorsim.recording import Recording, RecordingError

__all__ = [
    "FORMATS",
    "LogFormat",
    "carry_mode",
    "detect_format",
    "read_ilc_trace",
    "read_oxford_folder",
    "read_oxford_validation",
    "read_sensor_logger",
    "register_format",
]

PathLike = str | os.PathLike[str]


@dataclass(frozen=True, kw_only=True)
class LogFormat:
    """A real-log format: how to recognise it and how to read it.

    Attributes:
        name: short identifier, e.g. ``"ilc2020"``.
        description: what the path looks like, for error messages.
        detect: True when a path (file or folder) is in this format; cheap and
            never raises for paths of other formats.
        read: the reader, path → Recording.
    """

    name: str
    description: str
    detect: Callable[[Path], bool]
    read: Callable[[Path], Recording]


FORMATS: list[LogFormat] = []


def register_format(log_format: LogFormat) -> LogFormat:
    """Add a format to :data:`FORMATS` (checked in order by :func:`detect_format`)."""
    if any(f.name == log_format.name for f in FORMATS):
        raise ValueError(f"a log format named {log_format.name!r} is already registered")
    FORMATS.append(log_format)
    return log_format


def detect_format(path: PathLike) -> LogFormat | None:
    """The registered format ``path`` is in, or None."""
    source = Path(path)
    return next((f for f in FORMATS if f.detect(source)), None)


# ---------------------------------------------------------------------- shared helpers

_XYZ = ("x", "y", "z")
_RATE_STREAMS = (
    "accel",
    "gyro",
    "mag",
    "rotation",
    "game_rotation",
    "gravity",
    "linear_accel",
    "light",
    "wifi",
)

# Carry positions named by the logs → indoorsim carry modes (lower-cased keys).
_CARRY_MODES = {
    "inhand": "handheld",
    "hand": "handheld",
    "frontpocket": "pocketed",
    "backpocket": "pocketed",
    "swingingarm": "dangling",
}


def carry_mode(position: str) -> str:
    """indoorsim's carry mode for a logged carrying position, or the position unchanged.

    >>> carry_mode("FrontPocket"), carry_mode("hand"), carry_mode("Purse")
    ('pocketed', 'handheld', 'Purse')
    """
    return _CARRY_MODES.get(position.lower(), position)


def _frame(t: ArrayLike, columns: dict[str, ArrayLike]) -> pd.DataFrame:
    """A stream DataFrame indexed by float64 ``t``, sorted stably by ``t``."""
    df = pd.DataFrame(columns, index=pd.Index(np.asarray(t, dtype=np.float64), name="t"))
    if not df.index.is_monotonic_increasing:
        df = df.sort_index(kind="stable")
    return df


def _seconds(ticks: NDArray[np.int64], t0: int, ticks_per_s: float) -> NDArray[np.float64]:
    # Subtract in integers first: epoch nanoseconds (~1.7e18) do not fit a float64 exactly.
    return (ticks - np.int64(t0)).astype(np.float64) / ticks_per_s


def _rates_hz(streams: dict[str, pd.DataFrame]) -> dict[str, float]:
    rates = {}
    for name in _RATE_STREAMS:
        if name in streams:
            times = np.unique(streams[name].index.to_numpy())
            if len(times) > 1:
                rates[name] = round(float(1.0 / np.median(np.diff(times))), 3)
    return rates


def _quaternion_from_rotation_vector(xyz: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N, 4) unit quaternions (w, x, y, z) from Android rotation-vector (x, y, z) rows.

    Android gives x, y, z = sin(θ/2)·axis; w = cos(θ/2) = sqrt(1 − x² − y² − z²),
    clipped at 0 because rounding can push the norm of xyz a hair above 1.
    """
    w = np.sqrt(np.clip(1.0 - np.sum(xyz**2, axis=1), 0.0, None))
    q = np.column_stack([w, xyz])
    return q / np.linalg.norm(q, axis=1, keepdims=True)


# ---------------------------------------------------------------------- ILC 2.0 traces

_ILC_XYZ = {
    "TYPE_ACCELEROMETER": "accel",
    "TYPE_GYROSCOPE": "gyro",
    "TYPE_MAGNETIC_FIELD": "mag",
    "TYPE_ROTATION_VECTOR": "rotation",
}
# Field counts (timestamp and type included) of the rows kept.
_ILC_FIELDS = {**dict.fromkeys(_ILC_XYZ, 6), "TYPE_WIFI": 7, "TYPE_WAYPOINT": 4}
_ILC_TYPE = re.compile(r"^TYPE_[A-Z0-9_]+$")
# Android sensor type numbers in the header → names used in meta["sensors"].
_ANDROID_SENSOR_TYPES = {
    1: "accel",
    2: "mag",
    4: "gyro",
    11: "rotation",
    14: "mag_uncalibrated",
    16: "gyro_uncalibrated",
    35: "accel_uncalibrated",
}


def read_ilc_trace(path: PathLike) -> Recording:
    """Read an Indoor Location Competition 2.0 path trace (tab-separated ``*.txt``).

    Mapping (column 1 is Unix time in ms, column 2 the row type):

    * ``TYPE_ACCELEROMETER`` / ``TYPE_GYROSCOPE`` / ``TYPE_MAGNETIC_FIELD``
      x, y, z → ``accel`` (m/s², gravity included) / ``gyro`` (rad/s) / ``mag``
      (µT, the calibrated field), Android phone frame. The accuracy field is
      dropped.
    * ``TYPE_ROTATION_VECTOR`` x, y, z → ``rotation`` (qw, qx, qy, qz) with
      qw = sqrt(max(0, 1 − x² − y² − z²)), renormalised. Android's rotation
      vector is world←phone with the world frame x ≈ east, y = *magnetic* north,
      z up — not the floor-plan frame of the waypoints, whose rotation to it the
      data does not give.
    * ``TYPE_WIFI`` ssid, bssid, RSSI, frequency, last-seen → ``wifi`` with
      ``bssid``, ``rss`` (dBm), ``freq_mhz`` and ``age_s`` = (row time −
      last-seen time)/1000: Android returns cached scan results, so many
      entries are seconds old. ``t`` is the row's time; the SSID is dropped.
    * ``TYPE_WAYPOINT`` x, y → ``waypoints`` (m, floor-plan frame: x right, y
      up, origin at the floor image's lower-left corner) — the trace's only
      ground truth (see :meth:`Recording.true_positions`).
    * Dropped, counted in ``meta["dropped_rows"]``: the uncalibrated sensors,
      iBeacon and the undocumented types (``TYPE_BLUE``, ``TYPE_DIST1``...).

    Clocks: sensor rows carry ``SensorEvent.timestamp`` converted to Unix ms,
    WiFi rows the system time; both are used as logged. ``t`` = (ms − first
    sensor row's ms)/1000.

    Header lines (``#\\tkey:value...``) → ``meta``: ``device`` (brand and
    model), ``phone``, ``app``, ``site`` (ids and names, plus the map's
    ``width_m``/``height_m`` from a ``floor_info.json`` in the trace's folder
    or its parent, as in the upstream layout), ``sensors`` (name, vendor,
    resolution, power, range per sensor), ``start_time_unix_ms`` and
    ``end_time_unix_ms``. ``meta["mode"]`` is ``handheld``: upstream states the
    surveyor held the phone flat in front of the body.

    Lines that cannot be parsed — upstream occasionally loses a newline and
    runs two rows together — are skipped and counted in
    ``meta["malformed_lines"]``.

    Raises:
        RecordingError: the file has no motion-sensor rows.
    """
    source = Path(path)
    columns: dict[str, list[list[float]]] = {name: [] for name in _ILC_XYZ.values()}
    times: dict[str, list[int]] = {name: [] for name in (*_ILC_XYZ.values(), "wifi", "waypoints")}
    wifi: dict[str, list[Any]] = {"bssid": [], "rss": [], "freq_mhz": [], "last_seen": []}
    waypoints: list[list[float]] = []
    header: list[list[str]] = []
    dropped: Counter[str] = Counter()
    malformed = 0
    with source.open(encoding="utf-8") as lines:
        for line in lines:
            line = line.rstrip("\r\n")
            if not line.strip():
                continue
            if line.startswith("#"):
                header.append(line.split("\t")[1:])
                continue
            fields = line.split("\t")
            kind = fields[1] if len(fields) > 1 else ""
            # A row that swallowed the next one shows a second type field.
            if not _ILC_TYPE.match(kind) or any(_ILC_TYPE.match(f) for f in fields[2:]):
                malformed += 1
                continue
            if kind not in _ILC_FIELDS:
                dropped[kind] += 1
                continue
            if len(fields) != _ILC_FIELDS[kind]:
                malformed += 1
                continue
            try:
                ms = int(fields[0])
                if kind in _ILC_XYZ:
                    values = [float(v) for v in fields[2:5]]
                    stream = _ILC_XYZ[kind]
                    columns[stream].append(values)
                elif kind == "TYPE_WIFI":
                    row = (fields[3], float(fields[4]), float(fields[5]), int(fields[6]))
                    stream = "wifi"
                    for key, value in zip(wifi, row, strict=True):
                        wifi[key].append(value)
                else:
                    waypoints.append([float(fields[2]), float(fields[3])])
                    stream = "waypoints"
            except ValueError:
                malformed += 1
                continue
            times[stream].append(ms)

    starts = [min(times[s]) for s in _ILC_XYZ.values() if times[s]]
    if not starts:
        raise RecordingError(
            f"{source}: no accelerometer, gyroscope, magnetometer or rotation rows"
        )
    t0 = min(starts)

    def seconds(stream: str) -> NDArray[np.float64]:
        return _seconds(np.asarray(times[stream], dtype=np.int64), t0, 1e3)

    streams: dict[str, pd.DataFrame] = {}
    for stream in ("accel", "gyro", "mag"):
        if times[stream]:
            xyz = np.asarray(columns[stream], dtype=np.float64)
            streams[stream] = _frame(seconds(stream), dict(zip(_XYZ, xyz.T, strict=True)))
    if times["rotation"]:
        q = _quaternion_from_rotation_vector(np.asarray(columns["rotation"], dtype=np.float64))
        streams["rotation"] = _frame(
            seconds("rotation"), dict(zip(("qw", "qx", "qy", "qz"), q.T, strict=True))
        )
    if times["wifi"]:
        row_ms = np.asarray(times["wifi"], dtype=np.int64)
        age_s = (row_ms - np.asarray(wifi["last_seen"], dtype=np.int64)) / 1e3
        streams["wifi"] = _frame(
            seconds("wifi"),
            {
                "bssid": wifi["bssid"],
                "rss": np.asarray(wifi["rss"], dtype=np.float64),
                "freq_mhz": np.asarray(wifi["freq_mhz"], dtype=np.float64),
                "age_s": age_s,
            },
        )
    if waypoints:
        xy = np.asarray(waypoints, dtype=np.float64)
        streams["waypoints"] = _frame(seconds("waypoints"), {"x": xy[:, 0], "y": xy[:, 1]})

    meta = _ilc_header_meta(header, source)
    meta.update(
        {
            "source": {"format": "ilc2020", "file": source.name},
            "mode": "handheld",
            "t0_unix_ms": t0,
            "frames": {
                "phone": "Android sensor frame (x right, y up the screen, z out of it)",
                "rotation": "world←phone; world = Android rotation-vector frame "
                "(x ≈ east, y = magnetic north, z up), not the floor-plan frame",
                "waypoints": "floor-plan frame of floor_info.json (m; x right, y up, "
                "origin at the floor image's lower-left corner)",
            },
            "rates_hz": _rates_hz(streams),
            "malformed_lines": malformed,
            "dropped_rows": dict(sorted(dropped.items())),
        }
    )
    return Recording(streams=streams, meta=meta)


def _ilc_header_meta(header: list[list[str]], source: Path) -> dict[str, Any]:
    """meta entries from the ``#`` header lines (each already split into ``key:value`` items)."""
    values: dict[str, str] = {}
    sensors: dict[str, dict[str, Any]] = {}
    for items in header:
        pairs = dict(item.split(":", 1) for item in items if ":" in item)
        if "type" in pairs and pairs["type"].isdigit():
            android_type = int(pairs["type"])
            entry: dict[str, Any] = {"android_type": android_type}
            for key, name, convert in (
                ("name", "name", str),
                ("vendor", "vendor", str),
                ("version", "version", int),
                ("resolution", "resolution", float),
                ("power", "power_mA", float),
                ("maximumRange", "max_range", float),
            ):
                if key in pairs:
                    try:
                        entry[name] = convert(pairs[key])
                    except ValueError:
                        entry[name] = pairs[key]
            sensors[_ANDROID_SENSOR_TYPES.get(android_type, f"android_type_{android_type}")] = entry
        else:
            values.update(pairs)

    def take(key: str, convert: Callable[[str], Any] = str) -> Any:
        raw = values.pop(key, None)
        if raw is None:
            return None
        try:
            return convert(raw)
        except ValueError:
            return raw

    phone = {
        "brand": take("Brand"),
        "model": take("Model"),
        "android_version": take("AndroidName"),
        "api_level": take("APILevel", int),
    }
    site = {
        "site_id": take("SiteID"),
        "site_name": take("SiteName"),
        "floor_id": take("FloorId"),
        "floor_name": take("FloorName"),
    }
    for floor_info in (source.parent / "floor_info.json", source.parent.parent / "floor_info.json"):
        if floor_info.is_file():
            map_info = json.loads(floor_info.read_text(encoding="utf-8")).get("map_info", {})
            site["map_width_m"] = map_info.get("width")
            site["map_height_m"] = map_info.get("height")
            break
    meta: dict[str, Any] = {
        "device": " ".join(v for v in (phone["brand"], phone["model"]) if v) or None,
        "phone": phone,
        "app": {"version_name": take("VersionName"), "version_code": take("VersionCode", int)},
        "site": site,
        "sensors": sensors,
        "start_time_unix_ms": take("startTime", int),
        "end_time_unix_ms": take("endTime", int),
    }
    if values:
        meta["header"] = values
    return meta


def _looks_like_ilc_trace(path: Path) -> bool:
    if not path.is_file() or path.suffix.lower() != ".txt":
        return False
    with path.open(encoding="utf-8", errors="replace") as lines:
        head = [lines.readline() for _ in range(40)]
    return any(
        line.startswith("#\tstartTime:")
        or (len(line.split("\t")) > 1 and _ILC_TYPE.match(line.split("\t")[1]) is not None)
        for line in head
    )


register_format(
    LogFormat(
        name="ilc2020",
        description="Indoor Location Competition 2.0 path trace (*.txt, tab-separated, "
        "'#\\tstartTime:' header, TYPE_* rows)",
        detect=_looks_like_ilc_trace,
        read=read_ilc_trace,
    )
)


# ---------------------------------------------------------------------- Oxford step counter


def _step_rows(t: NDArray[np.float64], extra: dict[str, ArrayLike] | None = None) -> pd.DataFrame:
    """A ``steps`` stream for steps whose foot and length the log does not know."""
    n = len(t)
    columns: dict[str, ArrayLike] = {
        "foot": np.full(n, None, dtype=object),
        "length": np.full(n, np.nan),
    }
    return _frame(t, columns | (extra or {}))


def read_oxford_folder(path: PathLike) -> Recording:
    """Read an Oxford step-counter optimisation folder ``<Phone>_<User>_<Surface>_<Position>_<n>``.

    Mapping:

    * ``accelerometer.csv`` (no header: ``SensorEvent.timestamp`` ns, accuracy
      flag, x, y, z m/s² with gravity) → ``accel``; the accuracy flag (always 3)
      is dropped.
    * ``stepcounter.csv`` (no header: timestamp ns on the same clock, then the
      binary states of the two channels of the ground-truth device) → ``steps``,
      one row per 0→1 transition on either channel, as upstream's ``stats.js``
      counts them (a channel that starts at 1 is not a step). ``foot`` is
      missing and ``length`` NaN: that the channels are the two feet is a
      reading, not documented upstream; the channel (1 or 2) is kept in column
      ``channel``.
    * ``metadata.txt`` (some folders) → ``meta["sensors"]["accel"]["name"]``.
    * The folder name → ``meta`` ``device`` (phone), ``user``, ``surface``,
      ``position`` and ``trial``; ``mode`` from the position (``InHand`` →
      handheld, ``FrontPocket``/``BackPocket`` → pocketed, ``SwingingArm`` →
      dangling, others as given).

    ``t`` = (ns − first accelerometer ns)/1e9 (a clock since boot;
    ``meta["t0_boot_ns"]``). ``meta["ground_truth_steps"]`` is the step count and
    ``meta["channel_steps"]`` the count per channel.
    """
    folder = Path(path)
    accel = pd.read_csv(
        folder / "accelerometer.csv",
        header=None,
        names=["ns", "accuracy", "x", "y", "z"],
        dtype={
            "ns": np.int64,
            "accuracy": np.int64,
            "x": np.float64,
            "y": np.float64,
            "z": np.float64,
        },
    )
    if accel.empty:
        raise RecordingError(f"{folder / 'accelerometer.csv'}: no rows")
    ticks = accel["ns"].to_numpy()
    t0 = int(ticks.min())
    streams = {
        "accel": _frame(_seconds(ticks, t0, 1e9), {c: accel[c].to_numpy() for c in _XYZ}),
    }
    counter = pd.read_csv(
        folder / "stepcounter.csv",
        header=None,
        names=["ns", "channel_1", "channel_2"],
        dtype=np.int64,
    )
    step_t, step_channel, per_channel = [], [], []
    state_t = _seconds(counter["ns"].to_numpy(), t0, 1e9)
    for channel in (1, 2):
        state = counter[f"channel_{channel}"].to_numpy()
        rises = np.flatnonzero((state[1:] == 1) & (state[:-1] == 0)) + 1
        step_t.append(state_t[rises])
        step_channel.append(np.full(len(rises), channel, dtype=np.int64))
        per_channel.append(len(rises))
    streams["steps"] = _step_rows(np.concatenate(step_t), {"channel": np.concatenate(step_channel)})

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
        for line in sensor_file.read_text(encoding="utf-8").splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "accelerometer" and value.strip():
                meta["sensors"] = {"accel": {"name": value.strip()}}
    meta |= {
        "t0_boot_ns": t0,
        "frames": {"phone": "Android sensor frame (x right, y up the screen, z out of it)"},
        "rates_hz": _rates_hz(streams),
        "ground_truth_steps": len(streams["steps"]),
        "channel_steps": per_channel,
        "dropped_rows": {},
    }
    return Recording(streams=streams, meta=meta)


def _looks_like_oxford_folder(path: Path) -> bool:
    return (path / "accelerometer.csv").is_file() and (path / "stepcounter.csv").is_file()


register_format(
    LogFormat(
        name="oxford-stepcounter",
        description="Oxford step-counter optimisation folder (accelerometer.csv + stepcounter.csv)",
        detect=_looks_like_oxford_folder,
        read=read_oxford_folder,
    )
)

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
       ``length`` NaN; the total is ``meta["ground_truth_steps"]``;
    7. the phone's hardware step counter, cumulative → dropped; its final count
       is ``meta["hardware_steps"]``, None when the column is all zero (not
       recorded).

    Leading rows whose three axes are exactly 0 are dropped (counted in
    ``meta["dropped_rows"]``): a still phone cannot read zero specific force,
    so such a first row is a placeholder written before the first sensor event.
    The file name gives ``meta`` ``user``, ``position``, ``mode`` (``hand`` →
    handheld, ``frontpocket``/``backpocket`` → pocketed, others as given) and
    ``start_time_unix_ms``; the phone is a Samsung Galaxy S6 (upstream README).

    Raises:
        RecordingError: the ground-truth count decreases, or the file is empty.
    """
    source = Path(path)
    data = np.loadtxt(source, delimiter=",", ndmin=2)
    if data.shape[1] != 7 or len(data) == 0:
        raise RecordingError(f"{source}: expected 7 comma-separated columns, got {data.shape}")
    placeholder = np.all(data[:, 1:4] == 0.0, axis=1)
    leading = int(np.argmin(placeholder)) if not placeholder.all() else len(data)
    data = data[leading:]
    if len(data) == 0:
        raise RecordingError(f"{source}: every accelerometer row is zero")
    # Timestamps (~1e12 ns since boot) are exact in float64, well below 2**53.
    ticks = data[:, 0].astype(np.int64)
    t0 = int(ticks.min())
    t = _seconds(ticks, t0, 1e9)
    truth_count = data[:, 5].astype(np.int64)
    increments = np.diff(truth_count, prepend=truth_count[0])
    if (increments < 0).any():
        row = int(np.argmax(increments < 0)) + leading
        raise RecordingError(f"{source}: ground-truth step count decreases at row {row}")
    streams = {
        "accel": _frame(t, {"x": data[:, 1], "y": data[:, 2], "z": data[:, 3]}),
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
        "rates_hz": _rates_hz(streams),
        "ground_truth_steps": int(increments.sum()),
        "app_algorithm_steps": int(data[-1, 4] - data[0, 4]),
        "hardware_steps": int(hardware[-1] - hardware[0]) if hardware.any() else None,
        "dropped_rows": {"zero_accel_placeholder": leading} if leading else {},
    }
    return Recording(streams=streams, meta=meta)


def _looks_like_oxford_validation(path: Path) -> bool:
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


register_format(
    LogFormat(
        name="oxford-stepcounter-validation",
        description="Oxford step-counter validation file (*.csv, no header, 7 numeric columns)",
        detect=_looks_like_oxford_validation,
        read=read_oxford_validation,
    )
)


# ---------------------------------------------------------------------- Sensor Logger

# Sensor Logger file (lower-cased stem) → (stream, {stream column: file column}).
_SENSOR_LOGGER_FILES: dict[str, tuple[str, dict[str, str]]] = {
    "totalacceleration": ("accel", {"x": "x", "y": "y", "z": "z"}),
    "accelerometer": ("linear_accel", {"x": "x", "y": "y", "z": "z"}),
    "gravity": ("gravity", {"x": "x", "y": "y", "z": "z"}),
    "gyroscope": ("gyro", {"x": "x", "y": "y", "z": "z"}),
    "magnetometer": ("mag", {"x": "x", "y": "y", "z": "z"}),
    "orientation": ("rotation", {"qw": "qw", "qx": "qx", "qy": "qy", "qz": "qz"}),
    "light": ("light", {"lux": "lux"}),
    "wifi": ("wifi", {"bssid": "bssid", "rss": "level", "freq_mhz": "frequency"}),
}
_SENSOR_LOGGER_MOTION = ("accel", "linear_accel", "gravity", "gyro", "mag", "rotation")
_SENSOR_LOGGER_TEXT = frozenset({"bssid"})
# Metadata.csv columns kept (→ meta key); "device id" is left out on purpose.
_SENSOR_LOGGER_META = {
    "device name": "device",
    "platform": "platform",
    "platform version": "platform_version",
    "appVersion": "app_version",
    "version": "export_version",
    "recording time": "recording_time",
    "recording timezone": "recording_timezone",
    "recording epoch time": "recording_epoch_time",
    "sensors": "sensors_logged",
    "sampleRateMs": "sample_interval_ms",
    "standardisation": "standardisation",
}


def read_sensor_logger(path: PathLike, *, mode: str | None = None) -> Recording:
    """Read a "Sensor Logger" app (tszheichoi) CSV export: its folder or its ``.zip``.

    Column layouts and units are those of the app's documentation
    (github.com/tszheichoi/awesome-sensor-logger, ``UNITS.md``,
    ``COORDINATES.md``, ``CROSSPLATFORM.md``): every file has ``time`` (Unix
    ns) and ``seconds_elapsed``; columns are read by name (the axis files are
    ordered ``z, y, x``).

    * ``TotalAcceleration.csv`` (Android: acceleration *with* gravity) → ``accel``.
    * ``Accelerometer.csv`` → ``linear_accel``: the app documents it as
      acceleration *without* gravity on both platforms. When there is no
      ``TotalAcceleration.csv`` (always so on iOS) and ``Gravity.csv`` has the
      same timestamps, ``accel`` = Accelerometer + Gravity, as the app's
      documentation suggests.
    * ``Gravity.csv`` → ``gravity``; ``Gyroscope.csv`` → ``gyro`` (rad/s);
      ``Magnetometer.csv`` → ``mag`` (µT, calibrated); ``Light.csv`` ``lux`` →
      ``light`` (Android only); ``WiFi.csv`` ``bssid``, ``level`` (dBm),
      ``frequency`` → ``wifi`` ``bssid``, ``rss``, ``freq_mhz`` (Android only).
    * ``Orientation.csv`` ``qw, qx, qy, qz`` → ``rotation`` unchanged;
      ``roll, pitch, yaw`` are dropped. The documentation describes the angles
      (reference "x-north-z-vertical"; magnetic north on Android, true north on
      iOS) but not which frames the quaternion maps between, so whether it is
      world←phone in indoorsim's ENU sense is **not confirmed**;
      ``meta["frames"]["rotation"]`` says so.
    * Other files (Location, Barometer, Uncalibrated variants, Annotation...)
      are dropped and listed in ``meta["dropped_files"]``.

    Frames: Android's (DESIGN §2). iOS reports acceleration and gravity with
    the opposite sign on all three axes unless the app's "Standardise Units &
    Frames" setting was on, so for an iOS export whose metadata does not say
    ``standardisation`` true, ``linear_accel`` and ``gravity`` are negated. The
    gyroscope is documented as the same on both; the magnetometer's sign on iOS
    is not documented and is left as exported.

    ``Metadata.csv`` → ``meta`` (``device``, ``platform``, ``app_version``,
    ``standardisation``...; strings as exported, but ``standardisation`` a
    bool). Its full column list is not in the app's documentation (the README
    names version, device name, recording time and platform; the others are as
    seen in published exports), so each is read only if present; the
    ``device id`` column is not kept. Rows whose ``time`` goes backwards
    (stale cached values, which the app's README says to remove) are dropped
    and counted in ``meta["dropped_rows"]``.

    Args:
        path: the export folder or ``.zip``.
        mode: the carry mode, if known (the export does not record it).

    Raises:
        RecordingError: a file lacks a column the mapping needs, or no known
            sensor file is present.
    """
    source = Path(path)
    with _csv_members(source) as members:
        frames: dict[str, pd.DataFrame] = {}
        dropped_files = []
        metadata: dict[str, str] = {}
        for stem, opener in sorted(members.items()):
            if stem == "metadata":
                with opener() as handle:
                    rows = list(csv.DictReader(io.TextIOWrapper(handle, encoding="utf-8-sig")))
                metadata = rows[0] if rows else {}
            elif stem in _SENSOR_LOGGER_FILES:
                with opener() as handle:
                    frames[stem] = pd.read_csv(handle)
            else:
                dropped_files.append(stem)
    if not frames:
        raise RecordingError(
            f"{source}: no Sensor Logger sensor file "
            f"({', '.join(sorted(_SENSOR_LOGGER_FILES))}; names case-insensitive)"
        )

    raw: dict[str, tuple[NDArray[np.int64], dict[str, NDArray[Any]]]] = {}
    dropped_rows: dict[str, int] = {}
    for stem, df in frames.items():
        stream, mapping = _SENSOR_LOGGER_FILES[stem]
        missing = [c for c in ("time", *mapping.values()) if c not in df.columns]
        if missing:
            raise RecordingError(f"{source}: {stem}.csv lacks column(s) {missing}")
        ticks = df["time"].to_numpy(dtype=np.int64)
        # Keep rows at or after the latest time seen so far: later rows that go
        # back in time are stale repeats.
        keep = ticks >= np.maximum.accumulate(ticks)
        if not keep.all():
            dropped_rows[f"{stem}_time_backwards"] = int((~keep).sum())
        columns = {
            column: df[file_column].to_numpy()[keep]
            if column in _SENSOR_LOGGER_TEXT
            else df[file_column].to_numpy(dtype=np.float64)[keep]
            for column, file_column in mapping.items()
        }
        raw[stream] = (ticks[keep], columns)

    meta: dict[str, Any] = {"source": {"format": "sensor-logger", "name": source.name}}
    for column, key in _SENSOR_LOGGER_META.items():
        if metadata.get(column) not in (None, ""):
            meta[key] = metadata[column]
    if "standardisation" in meta:
        meta["standardisation"] = meta["standardisation"].strip().lower() == "true"
    platform = meta.get("platform", "").strip().lower()
    if platform == "ios" and not meta.get("standardisation", False):
        for stream in ("linear_accel", "gravity"):
            if stream in raw:
                raw[stream] = (raw[stream][0], {c: -v for c, v in raw[stream][1].items()})
    if "accel" not in raw and "linear_accel" in raw and "gravity" in raw:
        (lin_ticks, lin), (grav_ticks, grav) = raw["linear_accel"], raw["gravity"]
        if np.array_equal(lin_ticks, grav_ticks):
            raw["accel"] = (lin_ticks, {c: lin[c] + grav[c] for c in _XYZ})

    motion_starts = [
        int(raw[s][0][0]) for s in _SENSOR_LOGGER_MOTION if s in raw and len(raw[s][0])
    ]
    all_starts = [int(ticks[0]) for ticks, _ in raw.values() if len(ticks)]
    if not all_starts:
        raise RecordingError(f"{source}: the sensor files have no rows")
    t0 = min(motion_starts or all_starts)
    streams = {
        stream: _frame(_seconds(ticks, t0, 1e9), columns)
        for stream, (ticks, columns) in sorted(raw.items())
    }
    meta |= {
        "mode": mode,
        "t0_unix_ns": t0,
        "frames": {
            "phone": "Android sensor frame (x right, y up the screen, z out of it)",
            "rotation": "as exported by Sensor Logger's Orientation.csv; its reference "
            "frame is not documented (not confirmed to be ENU world←phone)",
        },
        "rates_hz": _rates_hz(streams),
        "dropped_files": dropped_files,
        "dropped_rows": dropped_rows,
    }
    return Recording(streams=streams, meta=meta)


@contextmanager
def _csv_members(source: Path) -> Iterator[dict[str, Callable[[], IO[bytes]]]]:
    """The CSV files of an export folder or zip: lower-cased stem → opener (binary)."""
    if source.is_dir():
        members: dict[str, Callable[[], IO[bytes]]] = {}
        for file in sorted(source.iterdir()):
            if file.is_file() and file.suffix.lower() == ".csv":
                _add_member(members, file.name, _opener(file), source)
        yield members
        return
    with zipfile.ZipFile(source) as archive:
        members = {}
        for info in archive.infolist():
            name = Path(info.filename)
            # macOS zips carry resource forks as __MACOSX/._Name.csv.
            if info.is_dir() or name.suffix.lower() != ".csv" or "__MACOSX" in name.parts:
                continue
            _add_member(members, name.name, _zip_opener(archive, info), source)
        yield members


def _add_member(
    members: dict[str, Callable[[], IO[bytes]]],
    name: str,
    opener: Callable[[], IO[bytes]],
    source: Path,
) -> None:
    stem = Path(name).stem.lower()
    if stem in members:
        raise RecordingError(f"{source}: more than one {stem}.csv (names are case-insensitive)")
    members[stem] = opener


def _opener(path: Path) -> Callable[[], IO[bytes]]:
    return lambda: path.open("rb")


def _zip_opener(archive: zipfile.ZipFile, info: zipfile.ZipInfo) -> Callable[[], IO[bytes]]:
    return lambda: archive.open(info)


def _looks_like_sensor_logger(path: Path) -> bool:
    try:
        if not (path.is_dir() or (path.is_file() and zipfile.is_zipfile(path))):
            return False
        with _csv_members(path) as members:
            for stem in _SENSOR_LOGGER_FILES:
                if stem in members:
                    with members[stem]() as handle:
                        head = handle.readline().decode("utf-8", errors="replace")
                    return head.startswith("time,seconds_elapsed")
    except (OSError, zipfile.BadZipFile, RecordingError):
        return False
    return False


register_format(
    LogFormat(
        name="sensor-logger",
        description="Sensor Logger app CSV export (folder or .zip with Accelerometer.csv, "
        "Gyroscope.csv... headed 'time,seconds_elapsed,...')",
        detect=_looks_like_sensor_logger,
        read=read_sensor_logger,
    )
)
