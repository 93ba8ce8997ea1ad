"""One walk as data: :class:`Recording` (time-indexed streams + metadata) and its Parquet folder.

In memory a recording is a dict of pandas DataFrames, one per stream, each
indexed by ``t`` (float64 seconds from the recording start, non-decreasing),
plus a JSON-able ``meta`` dict (scenario, seed, device, mode, route, rates,
frames...). The same structure holds a simulated walk and a real phone log
(see :mod:`indoorsim.io.reallogs`), so every estimator runs on both.

Streams (columns besides ``t``; DESIGN §2 frames and units):

* ``accel``: ``x, y, z`` specific force in the phone frame, m/s² (gravity included)
* ``gyro``: ``x, y, z`` angular rate in the phone frame, rad/s
* ``mag``: ``x, y, z`` magnetic field in the phone frame, µT
* ``light``: ``lux``
* ``wifi``: ``bssid`` (str), ``rss`` (dBm); one row per AP seen per scan
* ``rotation``: ``qw, qx, qy, qz`` fused world←phone, as the phone estimates it
* ``truth``: ``x, y, z, qw, qx, qy, qz, body_x, body_y, heading, mode``
* ``steps``: ``foot`` ('L'/'R', missing when unknown), ``length`` (m, NaN when unknown)
* ``game_rotation``: ``qw, qx, qy, qz`` fused without the magnetometer
* ``gravity``, ``linear_accel``: ``x, y, z`` m/s² in the phone frame (fused)
* ``waypoints``: ``x, y`` true positions at sparse times (real data)

Other stream names (lower-case identifiers) and extra columns are allowed and
saved as they are; the columns above are required for the named streams.

On disk (the public contract of DESIGN §7): a folder with one ``<stream>.parquet``
per stream, whose first column is ``t`` followed by the stream's columns, and
a ``manifest.json`` holding ``format_version``, ``written_by``, every ``meta``
key, and ``streams`` (file, row count and column dtypes of each). DESIGN §2 says
"int64 nanoseconds in files" while its §7 table says ``t`` (s) and "float64
seconds"; users read these files with pandas against the table, so ``t`` is
written as float64 seconds, exactly as held in memory, and no nanosecond column
is added. Folders are written atomically (a temporary sibling, then a rename).
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from indoorsim._version import __version__
from indoorsim.io.atomic import write_folder
from indoorsim.io.formats import FORMATS, detect_format

__all__ = [
    "FORMAT_VERSION",
    "STREAMS",
    "MissingStreamError",
    "Recording",
    "RecordingError",
    "StreamSpec",
    "UnrecognisedFormatError",
]

FORMAT_VERSION = 1
MANIFEST = "manifest.json"
# Keys save() writes into manifest.json itself; meta may not use them.
_RESERVED_META_KEYS = frozenset({"format_version", "written_by", "streams"})
# Stream names become file names, so keep them to portable identifiers.
_STREAM_NAME = re.compile(r"^[a-z][a-z0-9_]*$")


class RecordingError(ValueError):
    """A recording that is invalid, or a folder that cannot be read as one."""


class UnrecognisedFormatError(RecordingError):
    """A path that is neither a recording folder nor a real-log format indoorsim reads."""


class MissingStreamError(KeyError):
    """A stream the recording does not have; the message lists the streams it has."""

    def __init__(self, name: str, present: list[str]):
        self.name = name
        self.present = present
        have = ", ".join(present) if present else "none"
        super().__init__(f"recording has no {name!r} stream (streams present: {have})")

    def __str__(self) -> str:
        # KeyError.__str__ would repr() the message, quoting it.
        return str(self.args[0])


@dataclass(frozen=True, kw_only=True)
class StreamSpec:
    """What a named stream must hold.

    Attributes:
        columns: required columns besides ``t``, in their canonical order.
        text: those of ``columns`` that hold strings; the others must be numeric.
        may_be_nan: numeric columns where NaN means "unknown"; every other
            numeric required column must be finite.
        doc: one line for users: meaning, frame and units.
    """

    columns: tuple[str, ...]
    text: frozenset[str] = frozenset()
    may_be_nan: frozenset[str] = frozenset()
    doc: str = ""


_XYZ = ("x", "y", "z")
_QUAT = ("qw", "qx", "qy", "qz")

STREAMS: dict[str, StreamSpec] = {
    "accel": StreamSpec(columns=_XYZ, doc="specific force, phone frame, m/s² (gravity included)"),
    "gyro": StreamSpec(columns=_XYZ, doc="angular rate, phone frame, rad/s"),
    "mag": StreamSpec(columns=_XYZ, doc="magnetic field, phone frame, µT"),
    "light": StreamSpec(columns=("lux",), doc="illuminance on the screen face, lux"),
    "wifi": StreamSpec(
        columns=("bssid", "rss"),
        text=frozenset({"bssid"}),
        doc="one row per AP seen per scan: BSSID and RSS in dBm",
    ),
    "rotation": StreamSpec(columns=_QUAT, doc="fused world←phone unit quaternion (phone's own)"),
    "game_rotation": StreamSpec(columns=_QUAT, doc="fused world←phone without magnetometer"),
    "gravity": StreamSpec(columns=_XYZ, doc="fused gravity, phone frame, m/s²"),
    "linear_accel": StreamSpec(columns=_XYZ, doc="fused acceleration minus gravity, m/s²"),
    "truth": StreamSpec(
        columns=(*_XYZ, *_QUAT, "body_x", "body_y", "heading", "mode"),
        text=frozenset({"mode"}),
        doc="true phone position (m), world←phone quaternion, body position, heading "
        "(rad from +x), carry mode",
    ),
    "steps": StreamSpec(
        columns=("foot", "length"),
        text=frozenset({"foot"}),
        may_be_nan=frozenset({"length"}),
        doc="true steps: foot ('L'/'R', missing if unknown) and length (m, NaN if unknown)",
    ),
    "waypoints": StreamSpec(columns=("x", "y"), doc="true positions at sparse times, m"),
}


def _stream_property(name: str) -> property:
    def get(self: Recording) -> pd.DataFrame:
        return self.stream(name)

    get.__doc__ = f"The ``{name}`` stream: {STREAMS[name].doc}. Raises MissingStreamError."
    return property(get)


@dataclass(eq=False, kw_only=True)
class Recording:
    """One walk: time-indexed sensor (and truth) streams plus JSON-able metadata.

    Construction validates every stream (see :meth:`validate`) and the metadata,
    so a Recording that exists is one that can be saved and loaded back
    unchanged (the simulator's own recordings are built valid and not checked
    again, see :meth:`_from_built`). The DataFrames are held, not copied.

    Attributes:
        streams: stream name → DataFrame indexed by float64 ``t`` (seconds from
            the recording start); the module docstring lists the named streams.
        meta: JSON-able metadata (str keys; dicts, lists, str, finite numbers,
            bools, None).

    Example:
        >>> import pandas as pd
        >>> t = pd.Index([0.0, 0.02], name="t")
        >>> acc = pd.DataFrame({"x": [0.0, 0.1], "y": [0.0, 0.0], "z": [9.81, 9.8]}, index=t)
        >>> rec = Recording(streams={"accel": acc}, meta={"device": "ideal"})
        >>> rec.duration, rec.has_truth
        (0.02, False)
        >>> try:
        ...     rec.gyro
        ... except MissingStreamError as err:
        ...     print(err)
        recording has no 'gyro' stream (streams present: accel)
    """

    streams: dict[str, pd.DataFrame]
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.validate()

    @classmethod
    def _from_built(cls, streams: dict[str, pd.DataFrame], meta: dict[str, Any]) -> Recording:
        """A Recording of streams indoorsim has just built itself, without :meth:`validate`.

        Only for the simulator's own output (:mod:`indoorsim.simulate`), whose
        streams are made in the validated layout by construction (float64
        ``t`` index, the named streams' columns) and whose tests check that it
        passes :meth:`validate`; checking every sample of a freshly simulated
        walk again would cost more than building its frames. Data from outside
        (files, real logs, users) goes through the constructor, which validates.
        """
        rec = cls.__new__(cls)
        rec.streams, rec.meta = streams, meta
        return rec

    accel = _stream_property("accel")
    gyro = _stream_property("gyro")
    mag = _stream_property("mag")
    light = _stream_property("light")
    wifi = _stream_property("wifi")
    rotation = _stream_property("rotation")
    game_rotation = _stream_property("game_rotation")
    gravity = _stream_property("gravity")
    linear_accel = _stream_property("linear_accel")
    truth = _stream_property("truth")
    steps = _stream_property("steps")
    waypoints = _stream_property("waypoints")

    def stream(self, name: str) -> pd.DataFrame:
        """The stream called ``name``.

        Raises:
            MissingStreamError: the recording has no such stream.
        """
        try:
            return self.streams[name]
        except KeyError:
            raise MissingStreamError(name, sorted(self.streams)) from None

    @property
    def duration(self) -> float:
        """Seconds between the earliest and the latest sample over all streams (0 if empty)."""
        spans = [(df.index[0], df.index[-1]) for df in self.streams.values() if len(df)]
        if not spans:
            return 0.0
        return float(max(end for _, end in spans) - min(start for start, _ in spans))

    @property
    def has_truth(self) -> bool:
        """Whether a dense ``truth`` stream is present (sparse ``waypoints`` do not count)."""
        return "truth" in self.streams

    def true_positions(self) -> pd.DataFrame:
        """The true horizontal positions known for this walk: ``x, y`` indexed by ``t``.

        The dense ``truth`` stream when present (simulated walks), otherwise the
        sparse ``waypoints`` (real logs such as the Indoor Location Competition
        traces, whose only truth is the surveyor's labelled points).

        Raises:
            MissingStreamError: the recording has neither stream.
        """
        for name in ("truth", "waypoints"):
            if name in self.streams:
                return self.streams[name][["x", "y"]]
        raise MissingStreamError("truth", sorted(self.streams))

    def __repr__(self) -> str:
        rows = ", ".join(f"{name}: {len(df)}" for name, df in self.streams.items())
        return (
            f"Recording(streams={{{rows}}}, duration={self.duration:.3f} s, "
            f"meta keys={sorted(self.meta)})"
        )

    # ------------------------------------------------------------------ validation

    def validate(self) -> None:
        """Check every stream and the metadata; called on construction.

        Every stream: a lower-case identifier for a name, a float64 index named
        ``t`` that is non-decreasing and finite, string column names other than
        ``t``. Named streams: the required columns, numeric where not text, and
        finite numbers (except columns where NaN means unknown). Meta: JSON-able
        so that it survives save/load unchanged.

        Raises:
            RecordingError: naming the stream, column and first offending row.
        """
        if not isinstance(self.streams, Mapping):
            raise RecordingError(f"streams must be a dict of DataFrames, got {type(self.streams)}")
        for name, df in self.streams.items():
            _validate_stream(name, df)
        if not isinstance(self.meta, dict):
            raise RecordingError(f"meta must be a dict, got {type(self.meta).__name__}")
        reserved = _RESERVED_META_KEYS.intersection(self.meta)
        if reserved:
            raise RecordingError(
                f"meta keys {sorted(reserved)} are reserved for manifest.json; rename them"
            )
        _check_jsonable(self.meta, "meta")

    # ------------------------------------------------------------------ Parquet I/O

    def save(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
        """Write the recording as a folder of Parquet files plus ``manifest.json``.

        The folder is written to a temporary sibling and renamed into place, so
        ``path`` is either absent, the previous recording, or complete — never
        half written. Missing parent folders are created.

        Args:
            path: the folder to create.
            overwrite: replace an existing recording folder at ``path``. A path
                holding anything else (a file, a non-empty folder without a
                recording manifest) is never replaced.

        Returns:
            The folder written.

        Raises:
            FileExistsError: ``path`` holds a recording and ``overwrite`` is
                False, or holds something that is not a recording.
        """
        return write_folder(
            Path(path),
            self._write_folder,
            overwrite=overwrite,
            is_ours=_is_recording_folder,
            what="recording",
        )

    def _write_folder(self, folder: Path) -> None:
        entries = []
        for name, df in self.streams.items():
            file = f"{name}.parquet"
            try:
                table = pa.Table.from_pandas(df.reset_index(), preserve_index=False)
            except (pa.ArrowException, ValueError, TypeError) as err:
                raise RecordingError(
                    f"stream {name!r} cannot be written to Parquet: {err}"
                ) from err
            pq.write_table(table, folder / file)
            columns = {"t": str(df.index.dtype)} | {c: str(df[c].dtype) for c in df.columns}
            entries.append({"name": name, "file": file, "rows": len(df), "columns": columns})
        manifest = {
            "format_version": FORMAT_VERSION,
            "written_by": f"indoorsim {__version__}",
            **self.meta,
            "streams": entries,
        }
        text = json.dumps(manifest, indent=2, ensure_ascii=False, allow_nan=False)
        # The manifest goes last: a folder with a manifest has all its streams.
        (folder / MANIFEST).write_text(text + "\n", encoding="utf-8")

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Recording:
        """Read a recording: an indoorsim folder, or a real phone log in a known format.

        An indoorsim folder (``manifest.json`` present) loads exactly as saved.
        Otherwise the path is matched against the formats of
        :mod:`indoorsim.io.formats` (Indoor Location Competition 2.0 traces, Oxford
        step-counter folders and files, Sensor Logger exports).

        Raises:
            FileNotFoundError: ``path`` does not exist.
            UnrecognisedFormatError: ``path`` is in none of the formats; the
                message lists those understood.
            RecordingError: the folder or file is damaged.
        """
        source = Path(path)
        if not source.exists():
            raise FileNotFoundError(f"no such file or folder: {source}")
        if source.is_dir() and (source / MANIFEST).is_file():
            return cls._load_folder(source)
        log_format = detect_format(source)
        if log_format is None:
            understood = [f"indoorsim recording folder ({MANIFEST} beside <stream>.parquet files)"]
            understood += [f"{fmt.name}: {fmt.description}" for fmt in FORMATS]
            raise UnrecognisedFormatError(
                f"{source} is not in a format indoorsim reads. Understood:\n  - "
                + "\n  - ".join(understood)
            )
        return log_format.read(source)

    @classmethod
    def _load_folder(cls, folder: Path) -> Recording:
        try:
            manifest = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as err:
            raise RecordingError(f"{folder / MANIFEST}: not valid JSON ({err})") from err
        version = manifest.get("format_version") if isinstance(manifest, dict) else None
        if not isinstance(version, int) or not isinstance(manifest.get("streams"), list):
            raise RecordingError(
                f"{folder / MANIFEST}: not an indoorsim manifest (needs format_version and streams)"
            )
        if version > FORMAT_VERSION:
            raise RecordingError(
                f"{folder}: format_version {version} was written by a newer indoorsim "
                f"(this one reads up to {FORMAT_VERSION}); upgrade indoorsim"
            )
        streams = {}
        for entry in manifest["streams"]:
            if not isinstance(entry, dict) or not {"name", "file"} <= entry.keys():
                raise RecordingError(f"{folder / MANIFEST}: stream entry {entry!r} lacks name/file")
            name, file_name, columns = entry["name"], entry["file"], entry.get("columns", {})
            # The file is one of the folder's own: a name, not a path that leads elsewhere.
            if not (
                isinstance(name, str)
                and isinstance(file_name, str)
                and file_name == Path(file_name).name
                and file_name not in ("", ".", "..")
                and isinstance(columns, dict)
            ):
                raise RecordingError(
                    f"{folder / MANIFEST}: stream entry {entry!r} needs a name, a file name in "
                    "the folder and a mapping of columns"
                )
            file = folder / file_name
            if not file.is_file():
                raise RecordingError(f"{folder}: stream {name!r} lists missing {file.name}")
            try:
                df = pd.read_parquet(file)
            except Exception as err:
                # Truncated, not Parquet, or pandas' own metadata in it damaged: pyarrow
                # and pandas raise whatever they trip on (OSError, ArrowException,
                # KeyError, TypeError...), each meaning the file cannot be read.
                raise RecordingError(
                    f"{file}: stream {name!r} cannot be read as Parquet: {err}"
                ) from err
            if len(df.columns) == 0 or df.columns[0] != "t":
                first = df.columns[0] if len(df.columns) else None
                raise RecordingError(f"{file}: first column is {first!r}, expected 't'")
            df = df.set_index("t")
            # Parquet has no "object of str" type: pandas ≥ 3 reads such columns
            # back as its string dtype, so restore the dtype the manifest recorded.
            for column, dtype in columns.items():
                if dtype == "object" and column in df.columns and df[column].dtype != object:
                    df[column] = df[column].astype(object)
            streams[name] = df
        meta = {k: v for k, v in manifest.items() if k not in _RESERVED_META_KEYS}
        try:
            return cls(streams=streams, meta=meta)
        except RecordingError as err:
            raise RecordingError(f"{folder}: {err}") from err


# ---------------------------------------------------------------------- helpers


def _validate_stream(name: object, df: object) -> None:
    if not isinstance(name, str) or not _STREAM_NAME.match(name):
        raise RecordingError(
            f"stream name {name!r} must be a lower-case identifier (it becomes a file name)"
        )
    if not isinstance(df, pd.DataFrame):
        raise RecordingError(f"stream {name!r} must be a pandas DataFrame, got {type(df).__name__}")
    index = df.index
    if index.name != "t" or index.dtype != np.float64:
        raise RecordingError(
            f"stream {name!r} must be indexed by float64 't' in seconds (got index "
            f"{index.name!r} of dtype {index.dtype}); e.g. df.set_index('t') with float t"
        )
    bad = [c for c in df.columns if not isinstance(c, str) or c == "t"]
    if bad:
        raise RecordingError(f"stream {name!r}: column names must be strings other than 't': {bad}")
    if len(set(df.columns)) != len(df.columns):  # (a set: no hash table kept on the Index)
        duplicated = sorted(set(df.columns[df.columns.duplicated()]))
        raise RecordingError(f"stream {name!r}: duplicate column names {duplicated}")
    t = index.to_numpy()
    finite = np.isfinite(t)
    if not finite.all():
        row = int(np.argmin(finite))
        raise RecordingError(f"stream {name!r}: t is not finite at row {row} ({float(t[row])})")
    backwards = t[1:] < t[:-1]  # finite t: the same as a negative difference
    if backwards.any():
        row = int(np.argmax(backwards)) + 1
        raise RecordingError(
            f"stream {name!r}: t decreases at row {row} ({float(t[row - 1])} -> {float(t[row])}); "
            "t must be non-decreasing (sort the stream by t)"
        )
    spec = STREAMS.get(name)
    if spec is None:
        return
    # Column names and dtypes as plain Python: looking names up in the frame's
    # column Index would first build its hash table, which costs more here.
    columns = list(df.columns)
    dtypes = dict(zip(columns, df.dtypes, strict=True))
    missing = [c for c in spec.columns if c not in dtypes]
    if missing:
        raise RecordingError(
            f"stream {name!r} is missing column(s) {missing}; it needs {list(spec.columns)}"
        )
    numeric = [c for c in spec.columns if c not in spec.text]
    for column in numeric:
        dtype = dtypes[column]
        if not pd.api.types.is_numeric_dtype(dtype) or pd.api.types.is_bool_dtype(dtype):
            raise RecordingError(f"stream {name!r}: column {column!r} must be numeric, not {dtype}")
    checked = [c for c in numeric if c not in spec.may_be_nan]
    if checked == columns and np.isfinite(df.to_numpy(dtype=np.float64)).all():
        return  # every column checked at once (a view of the frame's one block, usually)
    for column in checked:
        values = df[column].to_numpy(dtype=np.float64)
        finite = np.isfinite(values)
        if not finite.all():
            row = int(np.argmin(finite))
            raise RecordingError(
                f"stream {name!r}: column {column!r} is not finite at row {row} "
                f"(t={float(t[row])}, value {float(values[row])})"
            )


def _check_jsonable(value: object, where: str) -> None:
    """Raise if ``value`` would not come back unchanged from a JSON round trip."""
    if value is None or isinstance(value, bool | str):
        return
    if type(value) is int:  # not bool (handled above) nor numpy integers
        return
    if type(value) is float:
        if not math.isfinite(value):
            raise RecordingError(f"{where} is {value}, which JSON cannot hold")
        return
    if type(value) is list:
        for i, item in enumerate(value):
            _check_jsonable(item, f"{where}[{i}]")
        return
    if type(value) is dict:
        for key, item in value.items():
            if not isinstance(key, str):
                raise RecordingError(f"{where} has key {key!r}; JSON object keys must be str")
            _check_jsonable(item, f"{where}[{key!r}]")
        return
    hint = " (use a list)" if isinstance(value, tuple) else ""
    if isinstance(value, np.generic):
        hint = " (convert with .item())"
    raise RecordingError(
        f"{where} is a {type(value).__name__}, which would not survive JSON unchanged{hint}"
    )


def _is_recording_folder(path: Path) -> bool:
    manifest = path / MANIFEST
    if path.is_symlink() or not manifest.is_file():
        return False
    try:
        content = json.loads(manifest.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return False
    return isinstance(content, dict) and "format_version" in content and "streams" in content
