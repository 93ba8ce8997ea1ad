"""CSV exports (folder or ``.zip``) of the "Sensor Logger" app by Kelvin Choi."""

from __future__ import annotations

import csv
import io
import zipfile
import zlib
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from indoorsim.io.reallogs.common import (
    XYZ,
    PathLike,
    build_recording,
    finite_rows,
    median_rates_hz,
    read_csv_columns,
    report_malformed,
    ticks_to_seconds,
    time_frame,
)
from indoorsim.io.recording import Recording, RecordingError

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
# What a damaged zip raises, from opening it to reading a member's last byte
# (RuntimeError: a member flagged encrypted; NotImplementedError, one of them: an
# unknown compression).
_ZIP_ERRORS = (zipfile.BadZipFile, zlib.error, EOFError, RuntimeError)

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
    and counted in ``meta["dropped_rows"]``. Rows that cannot be read (the
    wrong number of fields, a ``time`` or number that does not parse) are
    skipped, counted as ``"<file>.csv: <reason>"`` in ``meta["malformed_rows"]``
    and warned about (:class:`~indoorsim.io.reallogs.common.MalformedRowsWarning`).

    Args:
        path: the export folder or ``.zip``.
        mode: the carry mode, if known (the export does not record it).

    Raises:
        RecordingError: a file lacks a column the mapping needs, or no known
            sensor file is present.
    """
    source = Path(path)
    malformed: Counter[str] = Counter()
    frames: dict[str, pd.DataFrame] = {}
    dropped_files: list[str] = []
    metadata: dict[str, str] = {}
    try:
        with _csv_members(source) as members:
            for stem, opener in sorted(members.items()):
                if stem == "metadata":
                    with (
                        opener() as handle,
                        io.TextIOWrapper(handle, encoding="utf-8-sig", errors="replace") as text,
                    ):
                        try:
                            rows = list(csv.DictReader(text))
                        except csv.Error as err:
                            raise RecordingError(
                                f"{source}: {stem}.csv is not readable as CSV ({err})"
                            ) from err
                    metadata = rows[0] if rows else {}
                elif stem in _SENSOR_LOGGER_FILES:
                    _, mapping = _SENSOR_LOGGER_FILES[stem]
                    numbers: dict[str, type] = {"time": int}
                    numbers |= {
                        c: float for k, c in mapping.items() if k not in _SENSOR_LOGGER_TEXT
                    }
                    with opener() as handle:
                        # Bytes that are not UTF-8 become U+FFFD, and their row a malformed row.
                        text = handle.read().decode("utf-8-sig", errors="replace")
                    frames[stem] = read_csv_columns(
                        text, numbers, header=True, malformed=malformed, file=f"{stem}.csv"
                    )
                else:
                    dropped_files.append(stem)
    except _ZIP_ERRORS as err:
        raise RecordingError(
            f"{source}: not a readable zip archive ({type(err).__name__}: {err})"
        ) from err
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
            raw["accel"] = (lin_ticks, {c: lin[c] + grav[c] for c in XYZ})

    motion_starts = [
        int(raw[s][0][0]) for s in _SENSOR_LOGGER_MOTION if s in raw and len(raw[s][0])
    ]
    all_starts = [int(ticks[0]) for ticks, _ in raw.values() if len(ticks)]
    if not all_starts:
        raise RecordingError(f"{source}: the sensor files have no rows")
    t0 = min(motion_starts or all_starts)
    streams = {
        stream: time_frame(ticks_to_seconds(ticks, t0, 1e9), columns)
        for stream, (ticks, columns) in sorted(raw.items())
    }
    files = {_SENSOR_LOGGER_FILES[stem][0]: f"{stem}.csv" for stem in frames}
    streams = finite_rows(streams, malformed, files)
    meta |= {
        "mode": mode,
        "t0_unix_ns": t0,
        "frames": {
            "phone": "Android sensor frame (x right, y up the screen, z out of it)",
            "rotation": "as exported by Sensor Logger's Orientation.csv; its reference "
            "frame is not documented (not confirmed to be ENU world←phone)",
        },
        "rates_hz": median_rates_hz(streams),
        "dropped_files": dropped_files,
        "dropped_rows": dropped_rows,
        "malformed_rows": report_malformed(source, malformed),
    }
    return build_recording(source, streams, meta)


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


def looks_like_sensor_logger(path: Path) -> bool:
    try:
        if not (path.is_dir() or (path.is_file() and zipfile.is_zipfile(path))):
            return False
        with _csv_members(path) as members:
            for stem in _SENSOR_LOGGER_FILES:
                if stem in members:
                    with members[stem]() as handle:
                        head = handle.readline().decode("utf-8", errors="replace")
                    return head.startswith("time,seconds_elapsed")
    except (OSError, RecordingError, *_ZIP_ERRORS):
        return False
    return False
