"""Property tests of the real-log readers: random damage to a small log of every format.

Each format's sample is a small excerpt of a real recording from the shared folder
(a synthetic export for Sensor Logger, of which it holds none). Damage is a cut, bytes
inserted or overwritten, a line lost or repeated, or one field replaced by text a
parser may trip on (huge integers, NaN, inf, other scripts' digits). A reader then
either reads the log, with the rows it skipped counted in ``meta["malformed_rows"]``,
or raises :class:`RecordingError` naming the file or folder: never anything else.
"""

from __future__ import annotations

import functools
import io
import re
import shutil
import tempfile
import warnings
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from indoorsim.io.reallogs import (
    MalformedRowsWarning,
    read_ilc_trace,
    read_mag_slam_walk,
    read_oxford_folder,
    read_oxford_validation,
    read_sensor_logger,
)
from indoorsim.io.recording import Recording, RecordingError
from tests.conftest import REALDATA, SWEEP
from tests.io.test_reallogs import _sensor_logger_export

ILC_TRACE = (
    REALDATA / "ms-indoor-location-2020/site1/F1/path_data_files/5dd9e7c5c5b77e0006b17337.txt"
)
OXFORD_FOLDER = REALDATA / "oxford-stepcounter/optimisation/Pixel_Jamie_Hard_InHand_1"
OXFORD_VALIDATION = REALDATA / "oxford-stepcounter/validation/user1_hand_1506421989895.csv"
MAG_SLAM = REALDATA / "mag-slam-1d/eight.mat"

pytestmark = pytest.mark.skipif(not REALDATA.is_dir(), reason=f"no real data at {REALDATA}")


@dataclass(frozen=True)
class Sample:
    """A small log: its files (path in the log → bytes), what to read, and the reader."""

    files: dict[str, bytes]
    target: str
    read: Callable[[Path], Recording]
    text: bool = True  # lines and fields to damage, besides bytes


def _lines(path: Path, keep: Callable[[int, str], bool]) -> bytes:
    with path.open("rb") as fh:
        return b"".join(line for i, line in enumerate(fh) if keep(i, line.decode("utf-8")))


def _ilc_excerpt() -> bytes:
    # The header, a few hundred sensor rows, some WiFi rows, every waypoint, the footer.
    return _lines(
        ILC_TRACE,
        lambda i, line: (
            line.startswith("#") or i < 200 or 720 <= i < 760 or "TYPE_WAYPOINT" in line
        ),
    )


def _sensor_logger_files() -> dict[str, bytes]:
    with tempfile.TemporaryDirectory() as tmp:
        folder = _sensor_logger_export(Path(tmp) / "export")
        return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@functools.cache
def samples() -> dict[str, Sample]:
    """The samples by format, read once (a module global: hypothesis would print a fixture)."""
    logger = _sensor_logger_files()
    return {
        "ilc2020": Sample({"trace.txt": _ilc_excerpt()}, "trace.txt", read_ilc_trace),
        "oxford-stepcounter": Sample(
            {
                "Pixel_Jamie_Hard_InHand_1/accelerometer.csv": _lines(
                    OXFORD_FOLDER / "accelerometer.csv", lambda i, _: i < 300
                ),
                "Pixel_Jamie_Hard_InHand_1/stepcounter.csv": _lines(
                    OXFORD_FOLDER / "stepcounter.csv", lambda i, _: i < 100
                ),
            },
            "Pixel_Jamie_Hard_InHand_1",
            read_oxford_folder,
        ),
        "oxford-stepcounter-validation": Sample(
            {OXFORD_VALIDATION.name: _lines(OXFORD_VALIDATION, lambda i, _: i < 300)},
            OXFORD_VALIDATION.name,
            read_oxford_validation,
        ),
        "sensor-logger": Sample(
            {f"export/{name}": data for name, data in logger.items()}, "export", read_sensor_logger
        ),
        "sensor-logger-zip": Sample(
            {"export.zip": _zipped(logger)}, "export.zip", read_sensor_logger, text=False
        ),
        "mag-slam-1d": Sample(
            {"eight.mat": MAG_SLAM.read_bytes()}, "eight.mat", read_mag_slam_walk, text=False
        ),
    }


def _zipped(files: dict[str, bytes]) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in files.items():
            archive.writestr(name, data)
    return buffer.getvalue()


# Text a parser may trip on where a number belongs.
TOKENS = [
    "",
    " ",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e400",
    "-1e400",
    "99999999999999999999",
    "-99999999999999999999",
    "9223372036854775808",
    "1_000",
    "0x1f",
    "１２３",
    "٣",
    "1e3",
    "-0",
    "x",
    "\x00",
    '"',
    "1,2",
    "\t",
]


@st.composite
def damage(draw: st.DrawFn, data: bytes, text: bool) -> bytes:
    """``data`` damaged once."""
    kinds = ["cut", "insert", "overwrite"] + (["field", "line"] if text else [])
    kind = draw(st.sampled_from(kinds))
    if kind == "cut":
        return data[: draw(st.integers(0, len(data)))]
    if kind in ("insert", "overwrite"):
        at = draw(st.integers(0, len(data)))
        new = draw(st.binary(min_size=1, max_size=16))
        return data[:at] + new + data[at + (len(new) if kind == "overwrite" else 0) :]
    lines = data.split(b"\n")
    i = draw(st.integers(0, len(lines) - 1))
    if kind == "line":
        j = draw(st.integers(0, len(lines) - 1))
        how = draw(st.sampled_from(["drop", "repeat", "swap"]))
        if how == "drop":
            del lines[i]
        elif how == "repeat":
            lines.insert(j, lines[i])
        else:
            lines[i], lines[j] = lines[j], lines[i]
        return b"\n".join(lines)
    # One field of one line replaced by a token (fields split at tabs and commas).
    parts = re.split(rb"([\t,])", lines[i])
    fields = list(range(0, len(parts), 2))
    f = draw(st.sampled_from(fields))
    token = draw(st.sampled_from(TOKENS) | st.text(max_size=4))
    parts[f] = token.encode("utf-8")
    lines[i] = b"".join(parts)
    return b"\n".join(lines)


def _read_damaged(sample: Sample, folder: Path, file: str, content: bytes) -> None:
    """Write ``sample`` into ``folder`` with ``file`` replaced by ``content``, and read it."""
    for name, data in sample.files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content if name == file else data)
    target = folder / sample.target
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MalformedRowsWarning)
        try:
            rec = sample.read(target)
        except RecordingError as err:
            # Names what could not be read: the file, or the log (a folder, a zip).
            assert str(target) in str(err) or str(folder / file) in str(err), err
            return
    malformed = rec.meta["malformed_rows"]
    assert isinstance(malformed, dict)
    assert all(isinstance(n, int) and n > 0 for n in malformed.values()), malformed
    rec.validate()
    skipped = [w for w in caught if issubclass(w.category, MalformedRowsWarning)]
    if malformed:  # one warning naming the log and the total
        assert len(skipped) == 1, skipped
        message = str(skipped[0].message)
        assert str(target) in message and f"skipped {sum(malformed.values())} malformed" in message
    else:
        assert skipped == []


FORMATS = [
    "ilc2020",
    "oxford-stepcounter",
    "oxford-stepcounter-validation",
    "sensor-logger",
    "sensor-logger-zip",
    "mag-slam-1d",
]


def _check(tmp: Path, data: st.DataObject, name: str) -> None:
    sample = samples()[name]
    file = data.draw(st.sampled_from(sorted(sample.files)), label="file")
    content = data.draw(damage(sample.files[file], sample.text), label="content")
    _read_damaged(sample, tmp, file, content)


@pytest.mark.parametrize("name", FORMATS)
def test_each_undamaged_sample_reads_cleanly(tmp_path, name):
    sample = samples()[name]
    for file, data in sample.files.items():
        (tmp_path / file).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / file).write_bytes(data)
    rec = sample.read(tmp_path / sample.target)
    assert rec.meta["malformed_rows"] == {}
    assert len(rec.streams) >= 2


@pytest.mark.parametrize("name", FORMATS)
@given(data=st.data())
def test_a_damaged_log_reads_or_is_a_recording_error_naming_it(tmp_path_factory, name, data):
    folder = tmp_path_factory.mktemp(name)
    try:
        _check(folder, data, name)
    finally:
        shutil.rmtree(folder)


@pytest.mark.slow
@pytest.mark.parametrize("name", FORMATS)
@settings(SWEEP)
@given(data=st.data())
def test_a_damaged_log_reads_or_is_a_recording_error_sweep(tmp_path_factory, name, data):
    folder = tmp_path_factory.mktemp(name)
    try:
        _check(folder, data, name)
    finally:
        shutil.rmtree(folder)


# ------------------------------------------------------- what hypothesis found, kept


def _write(folder: Path, files: dict[str, bytes]) -> None:
    for name, data in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)


def _replace_field(data: bytes, line: int, field: int, token: bytes, sep: bytes) -> bytes:
    lines = data.split(b"\n")
    parts = lines[line].split(sep)
    parts[field] = token
    lines[line] = sep.join(parts)
    return b"\n".join(lines)


def test_ilc_rows_with_inf_or_a_clock_beyond_int64_are_counted(tmp_path):
    # Were: a RecordingError naming no file (inf RSSI), an OverflowError (the clock),
    # a ValueError (a sensor type of superscript digits, which str.isdigit accepts).
    data = _ilc_excerpt()
    lines = data.split(b"\n")
    wifi = next(i for i, line in enumerate(lines) if b"TYPE_WIFI" in line)
    accel = next(i for i, line in enumerate(lines) if b"\tTYPE_ACCELEROMETER\t" in line)
    data = _replace_field(data, wifi, 4, b"-inf", b"\t")
    data = _replace_field(data, accel, 0, b"99999999999999999999", b"\t")
    data = data.replace(b"type:1\t", "type:²\t".encode(), 1)
    _write(tmp_path, {"trace.txt": data})
    with pytest.warns(MalformedRowsWarning, match="skipped 2 malformed rows"):
        rec = read_ilc_trace(tmp_path / "trace.txt")
    assert rec.meta["malformed_rows"] == {
        "with a field that is not a number": 1,
        "with a reading that is NaN or infinite": 1,
    }
    assert "android_type_2" not in rec.meta["sensors"]


def test_oxford_rows_with_nan_or_a_clock_beyond_int64_are_counted(tmp_path):
    # Were: an OverflowError, and a RecordingError naming no file.
    sample = samples()["oxford-stepcounter"]
    name = "Pixel_Jamie_Hard_InHand_1/accelerometer.csv"
    data = _replace_field(sample.files[name], 5, 0, b"99999999999999999999", b",")
    data = _replace_field(data, 9, 4, b"nan", b",")
    _write(tmp_path, {**sample.files, name: data})
    with pytest.warns(MalformedRowsWarning, match="skipped 2 malformed rows"):
        rec = read_oxford_folder(tmp_path / sample.target)
    assert rec.meta["malformed_rows"] == {
        "accelerometer.csv: with a field that is not a number": 1,
        "accelerometer.csv: with a reading that is NaN or infinite": 1,
    }
    assert len(rec.accel) == 298


def test_oxford_validation_rows_with_a_nan_step_count_are_counted(tmp_path):
    # Was: a RuntimeWarning casting NaN to an integer count (an error in this suite).
    sample = samples()["oxford-stepcounter-validation"]
    data = _replace_field(sample.files[sample.target], 7, 5, b"nan", b",")
    data = _replace_field(data, 8, 6, b"1e300", b",")
    _write(tmp_path, {sample.target: data})
    with pytest.warns(MalformedRowsWarning, match="skipped 2 malformed rows"):
        rec = read_oxford_validation(tmp_path / sample.target)
    assert rec.meta["malformed_rows"] == {
        "with a reading that is NaN or infinite": 1,
        "with a step count beyond 2**53": 1,
    }


def test_sensor_logger_survives_bad_bytes_in_its_metadata_and_a_stray_carriage_return(
    tmp_path,
):
    # Were: a UnicodeDecodeError (Metadata.csv) and a csv.Error (a lone CR in a row).
    files = dict(samples()["sensor-logger"].files)
    files["export/Metadata.csv"] = files["export/Metadata.csv"].replace(b"Pixel", b"Pi\xffel")
    lines = files["export/Gyroscope.csv"].split(b"\n")
    lines[2] = lines[2].replace(b",", b",\r1", 1)
    files["export/Gyroscope.csv"] = b"\n".join(lines)
    _write(tmp_path, files)
    with pytest.warns(MalformedRowsWarning):
        rec = read_sensor_logger(tmp_path / "export")
    assert rec.meta["device"] == "Pi\ufffdel 8"
    assert sum(rec.meta["malformed_rows"].values()) >= 1
    assert all(k.startswith("gyroscope.csv: ") for k in rec.meta["malformed_rows"])


def _flip(data: bytes, at: int) -> bytes:
    return data[:at] + bytes([data[at] ^ 0xFF]) + data[at + 1 :]


@pytest.mark.parametrize(
    ("name", "damaged"),
    [
        ("sensor-logger-zip", lambda data: data[:100]),
        ("sensor-logger-zip", lambda data: data[:-30]),
        ("sensor-logger-zip", lambda data: _flip(data, 60)),
        ("mag-slam-1d", lambda data: data[:997]),
        ("mag-slam-1d", lambda data: _flip(data, 200)),
    ],
    ids=["zip-cut-100", "zip-cut-end", "zip-flip-60", "mat-cut-997", "mat-flip-200"],
)
def test_a_damaged_binary_log_is_a_recording_error_naming_it(tmp_path, name, damaged):
    # Were: BadZipFile, zlib.error or EOFError from the zip, scipy's zlib.error (or
    # TypeError, IndexError) from the .mat file, none naming the file. (A cut .mat
    # file was refused already: it stays refused.)
    sample = samples()[name]
    ((file, data),) = sample.files.items()
    _write(tmp_path, {file: damaged(data)})
    with pytest.raises(RecordingError, match=re.escape(f"{tmp_path / file}: not a readable")):
        sample.read(tmp_path / file)
