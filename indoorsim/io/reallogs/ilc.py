"""Indoor Location Competition 2.0 / Kaggle "indoor-location-navigation" path traces."""

from __future__ import annotations

import json
import re
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from indoorsim.io.reallogs.common import (
    NOT_A_NUMBER,
    WRONG_FIELD_COUNT,
    XYZ,
    PathLike,
    build_recording,
    finite_rows,
    median_rates_hz,
    quaternion_from_rotation_vector,
    report_malformed,
    ticks_to_seconds,
    time_frame,
)
from indoorsim.io.recording import Recording, RecordingError

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
    ``meta["malformed_lines"]``, by reason in ``meta["malformed_rows"]`` (``without a
    row type``, ``run together with the next row``, ``with the wrong number of
    fields``, ``with a field that is not a number``), and a
    :class:`~indoorsim.io.reallogs.common.MalformedRowsWarning` names the file
    and the counts. Bytes that are not UTF-8 are read as U+FFFD.

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
    malformed: Counter[str] = Counter()
    with source.open(encoding="utf-8", errors="replace") as lines:
        for line in lines:
            line = line.rstrip("\r\n")
            if not line.strip():
                continue
            if line.startswith("#"):
                header.append(line.split("\t")[1:])
                continue
            fields = line.split("\t")
            kind = fields[1] if len(fields) > 1 else ""
            if not _ILC_TYPE.match(kind):
                malformed["without a row type"] += 1
                continue
            # A row that swallowed the next one shows a second type field.
            if any(_ILC_TYPE.match(f) for f in fields[2:]):
                malformed["run together with the next row"] += 1
                continue
            if kind not in _ILC_FIELDS:
                dropped[kind] += 1
                continue
            if len(fields) != _ILC_FIELDS[kind]:
                malformed[WRONG_FIELD_COUNT] += 1
                continue
            try:
                ms = _int64(fields[0])
                if kind in _ILC_XYZ:
                    values = [float(v) for v in fields[2:5]]
                    stream = _ILC_XYZ[kind]
                    columns[stream].append(values)
                elif kind == "TYPE_WIFI":
                    row = (fields[3], float(fields[4]), float(fields[5]), _int64(fields[6]))
                    stream = "wifi"
                    for key, value in zip(wifi, row, strict=True):
                        wifi[key].append(value)
                else:
                    waypoints.append([float(fields[2]), float(fields[3])])
                    stream = "waypoints"
            except ValueError:
                malformed[NOT_A_NUMBER] += 1
                continue
            times[stream].append(ms)

    starts = [min(times[s]) for s in _ILC_XYZ.values() if times[s]]
    if not starts:
        raise RecordingError(
            f"{source}: no accelerometer, gyroscope, magnetometer or rotation rows"
        )
    t0 = min(starts)

    def seconds(stream: str) -> NDArray[np.float64]:
        return ticks_to_seconds(np.asarray(times[stream], dtype=np.int64), t0, 1e3)

    streams: dict[str, pd.DataFrame] = {}
    for stream in ("accel", "gyro", "mag"):
        if times[stream]:
            xyz = np.asarray(columns[stream], dtype=np.float64)
            streams[stream] = time_frame(seconds(stream), dict(zip(XYZ, xyz.T, strict=True)))
    if times["rotation"]:
        q = quaternion_from_rotation_vector(np.asarray(columns["rotation"], dtype=np.float64))
        streams["rotation"] = time_frame(
            seconds("rotation"), dict(zip(("qw", "qx", "qy", "qz"), q.T, strict=True))
        )
    if times["wifi"]:
        row_ms = np.asarray(times["wifi"], dtype=np.int64)
        age_s = (row_ms - np.asarray(wifi["last_seen"], dtype=np.int64)) / 1e3
        streams["wifi"] = time_frame(
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
        streams["waypoints"] = time_frame(seconds("waypoints"), {"x": xy[:, 0], "y": xy[:, 1]})

    streams = finite_rows(streams, malformed)
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
            "rates_hz": median_rates_hz(streams),
            "malformed_lines": sum(malformed.values()),
            "malformed_rows": report_malformed(source, malformed),
            "dropped_rows": dict(sorted(dropped.items())),
        }
    )
    return build_recording(source, streams, meta)


def _int64(field: str) -> int:
    """An integer field (a clock in ms); ValueError unless it fits in int64."""
    value = int(field)
    if not -(2**63) <= value < 2**63:
        raise ValueError(f"{field} does not fit in int64")
    return value


def _ilc_header_meta(header: list[list[str]], source: Path) -> dict[str, Any]:
    """meta entries from the ``#`` header lines (each already split into ``key:value`` items)."""
    values: dict[str, str] = {}
    sensors: dict[str, dict[str, Any]] = {}
    for items in header:
        pairs = dict(item.split(":", 1) for item in items if ":" in item)
        if "type" in pairs and pairs["type"].isascii() and pairs["type"].isdigit():
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


def looks_like_ilc_trace(path: Path) -> bool:
    if not path.is_file() or path.suffix.lower() != ".txt":
        return False
    with path.open(encoding="utf-8", errors="replace") as lines:
        head = [lines.readline() for _ in range(40)]
    return any(
        line.startswith("#\tstartTime:")
        or (len(line.split("\t")) > 1 and _ILC_TYPE.match(line.split("\t")[1]) is not None)
        for line in head
    )
