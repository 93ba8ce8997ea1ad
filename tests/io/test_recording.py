"""Recording: validation on construction, exact Parquet round trip, atomic and careful writes."""

from __future__ import annotations

import doctest
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from indoorsim.io import recording
from indoorsim.io.recording import (
    FORMAT_VERSION,
    MissingStreamError,
    Recording,
    RecordingError,
    UnrecognisedFormatError,
)


def _stream(t: np.ndarray, **columns: object) -> pd.DataFrame:
    return pd.DataFrame(columns, index=pd.Index(np.asarray(t, dtype=np.float64), name="t"))


def make_recording(seed: int = 0) -> Recording:
    """Every named stream plus an extra one, with str, object, category, int and bool columns."""
    rng = np.random.default_rng(seed)
    n = 50
    # Irregular times that are not short decimals, so exactness is really tested.
    t = np.cumsum(rng.uniform(0.015, 0.025, n))
    xyz = {c: rng.normal(size=n) for c in "xyz"}
    quat = rng.normal(size=(n, 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    q = dict(zip(("qw", "qx", "qy", "qz"), quat.T, strict=True))
    scan_t = np.repeat([0.5, 2.5], 3)
    streams = {
        "accel": _stream(t, x=xyz["x"], y=xyz["y"], z=xyz["z"] + 9.81),
        "gyro": _stream(t, **xyz),
        "mag": _stream(t + 1e-3, **{k: 40 * v for k, v in xyz.items()}),
        "light": _stream(t[::5], lux=rng.uniform(0, 500, 10), saturated=np.zeros(10, dtype=bool)),
        "wifi": _stream(
            scan_t,
            bssid=["02:00:00:00:00:01", "02:00:00:00:00:02", "02:00:00:00:00:03"] * 2,
            rss=[-40.0, -71.0, -90.0, -42.0, -70.0, -91.0],
            freq_mhz=np.array([2412, 5180, 2437] * 2, dtype=np.int64),
        ),
        "rotation": _stream(t, **q),
        "game_rotation": _stream(t, **q),
        "gravity": _stream(t, x=np.zeros(n), y=np.zeros(n), z=np.full(n, 9.81)),
        "linear_accel": _stream(t, **xyz),
        "truth": _stream(
            t,
            x=xyz["x"],
            y=xyz["y"],
            z=np.full(n, 1.2),
            **q,
            body_x=xyz["x"],
            body_y=xyz["y"],
            heading=rng.uniform(-np.pi, np.pi, n),
            mode=pd.Categorical(["handheld"] * 25 + ["pocketed"] * 25),
        ),
        # Object (not pandas' str) dtype with a missing foot: Parquet cannot say "object".
        "steps": _stream(
            t[::10], foot=["L", "R", "L", "R", None], length=[0.7, 0.71, np.nan, 0.69, 0.7]
        ).astype({"foot": object}),
        "waypoints": _stream([0.0, 1.0], x=[1.0, 2.0], y=[3.0, 4.0]),
        "barometer": _stream(t[:3], hpa=[1013.2, 1013.1, 1013.3]),
    }
    meta = {
        "scenario": "han2023_corridor",
        "seed": seed,
        "device": "ideal",
        "mode": "handheld",
        "route": [[0.0, 0.0], [10.0, 2.5]],
        "rates_hz": {"accel": 50.0, "wifi": 0.5},
        "frame": "ENU",
        "site": "杭州西溪银泰城",
        "notes": None,
        "noisy": False,
    }
    return Recording(streams=streams, meta=meta)


def assert_same_recording(a: Recording, b: Recording) -> None:
    assert list(a.streams) == list(b.streams)
    for name, df in a.streams.items():
        other = b.streams[name]
        pd.testing.assert_frame_equal(df, other, check_exact=True)
        assert dict(df.dtypes) == dict(other.dtypes), name
        assert df.index.dtype == other.index.dtype == np.float64
        # Bit-for-bit, not merely close.
        assert np.array_equal(
            df.index.to_numpy().view(np.int64), other.index.to_numpy().view(np.int64)
        )
    assert a.meta == b.meta


# ---------------------------------------------------------------------- round trip and layout


def test_round_trip_is_exact_for_every_stream_dtype_and_meta(tmp_path: Path):
    rec = make_recording()
    folder = rec.save(tmp_path / "walk")
    assert_same_recording(rec, Recording.load(folder))


def test_files_follow_the_public_layout(tmp_path: Path):
    rec = make_recording()
    folder = rec.save(tmp_path / "walk")
    accel = pd.read_parquet(folder / "accel.parquet")
    assert list(accel.columns) == ["t", "x", "y", "z"]
    assert accel["t"].dtype == np.float64
    np.testing.assert_array_equal(accel["t"].to_numpy(), rec.accel.index.to_numpy())
    assert list(pd.read_parquet(folder / "wifi.parquet").columns[:3]) == ["t", "bssid", "rss"]
    manifest = json.loads((folder / "manifest.json").read_text(encoding="utf-8"))
    assert manifest["format_version"] == FORMAT_VERSION
    assert manifest["written_by"].startswith("indoorsim ")
    assert manifest["scenario"] == "han2023_corridor" and manifest["seed"] == 0
    rows = {s["name"]: s["rows"] for s in manifest["streams"]}
    assert rows == {name: len(df) for name, df in rec.streams.items()}
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        ["manifest.json", *(f"{name}.parquet" for name in rec.streams)]
    )


def test_empty_recording_round_trips(tmp_path: Path):
    rec = Recording(streams={})
    loaded = Recording.load(rec.save(tmp_path / "empty"))
    assert loaded.streams == {} and loaded.meta == {} and loaded.duration == 0.0


# ---------------------------------------------------------------------- careful writes


def _unserialisable() -> Recording:
    rec = make_recording()
    bad = rec.gyro.copy()
    # Parquet has no column type for a mix of ints and strings.
    bad["label"] = pd.Series([1, "a"] * 25, dtype=object).to_numpy()
    return Recording(streams={**rec.streams, "gyro": bad}, meta=rec.meta)


def test_failed_write_leaves_nothing_behind(tmp_path: Path):
    with pytest.raises(RecordingError, match="'gyro'"):
        _unserialisable().save(tmp_path / "walk")
    assert list(tmp_path.iterdir()) == []


def test_failed_overwrite_keeps_the_previous_recording(tmp_path: Path):
    first = make_recording(seed=1)
    folder = first.save(tmp_path / "walk")
    with pytest.raises(RecordingError):
        _unserialisable().save(folder, overwrite=True)
    assert [p.name for p in tmp_path.iterdir()] == ["walk"]
    assert_same_recording(first, Recording.load(folder))


def test_existing_recording_needs_overwrite(tmp_path: Path):
    folder = make_recording(seed=1).save(tmp_path / "walk")
    second = make_recording(seed=2)
    with pytest.raises(FileExistsError, match="overwrite=True"):
        second.save(folder)
    second.save(folder, overwrite=True)
    assert_same_recording(second, Recording.load(folder))
    assert [p.name for p in tmp_path.iterdir()] == ["walk"]


@pytest.mark.parametrize("overwrite", [False, True])
def test_refuses_to_replace_something_that_is_not_a_recording(tmp_path: Path, overwrite: bool):
    folder = tmp_path / "thesis"
    folder.mkdir()
    (folder / "chapter1.tex").write_text("precious")
    with pytest.raises(FileExistsError, match="not an indoorsim recording"):
        make_recording().save(folder, overwrite=overwrite)
    assert (folder / "chapter1.tex").read_text() == "precious"
    file = tmp_path / "notes.txt"
    file.write_text("also precious")
    with pytest.raises(FileExistsError, match="not an indoorsim recording"):
        make_recording().save(file, overwrite=overwrite)
    assert file.read_text() == "also precious"


def test_writes_into_an_empty_folder_and_creates_parents(tmp_path: Path):
    (tmp_path / "empty").mkdir()
    make_recording().save(tmp_path / "empty")
    make_recording().save(tmp_path / "a" / "b" / "walk")
    assert (tmp_path / "empty" / "manifest.json").is_file()
    assert (tmp_path / "a" / "b" / "walk" / "manifest.json").is_file()


# ---------------------------------------------------------------------- validation


def _accel(**columns: object) -> pd.DataFrame:
    base = {"x": [0.0, 0.1, 0.2], "y": [0.0, 0.0, 0.0], "z": [9.8, 9.8, 9.8]}
    return _stream(np.array([0.0, 0.02, 0.04]), **(base | columns))


def test_missing_column_is_named():
    with pytest.raises(RecordingError, match=r"stream 'accel' is missing column\(s\) \['z'\]"):
        Recording(streams={"accel": _accel().drop(columns="z")})


def test_decreasing_time_names_stream_and_row():
    df = _accel()
    df.index = pd.Index([0.0, 0.04, 0.02], name="t")
    with pytest.raises(RecordingError, match=r"stream 'accel': t decreases at row 2"):
        Recording(streams={"accel": df})


def test_nan_names_stream_column_and_row():
    with pytest.raises(
        RecordingError, match=r"stream 'accel': column 'y' is not finite at row 1 \(t=0.02"
    ):
        Recording(streams={"accel": _accel(y=[0.0, np.nan, 0.0])})


def test_equal_times_are_allowed_and_unknown_step_length_may_be_nan():
    wifi = _stream([1.0, 1.0], bssid=["a", "b"], rss=[-50.0, -60.0])
    steps = _stream([0.5], foot=["L"], length=[np.nan])
    Recording(streams={"wifi": wifi, "steps": steps})


@pytest.mark.parametrize(
    ("streams", "message"),
    [
        ({"accel": _accel().reset_index()}, "indexed by float64 't'"),
        ({"accel": _accel().set_axis(pd.Index([0, 1, 2], name="t"))}, "indexed by float64 't'"),
        ({"Accel": _accel()}, "lower-case identifier"),
        ({"accel": _accel(x=["a", "b", "c"])}, "column 'x' must be numeric"),
        ({"accel": _accel().assign(t=1.0)}, "other than 't'"),
    ],
)
def test_malformed_streams_are_rejected(streams: dict, message: str):
    with pytest.raises(RecordingError, match=message):
        Recording(streams=streams)


@pytest.mark.parametrize(
    ("meta", "message"),
    [
        ({"route": (1.0, 2.0)}, r"meta\['route'\] is a tuple.*use a list"),
        ({"seed": np.int64(3)}, r"meta\['seed'\] is a int64.*\.item\(\)"),
        ({"rates": {"accel": float("nan")}}, r"meta\['rates'\]\['accel'\] is nan"),
        ({"streams": []}, "reserved"),
    ],
)
def test_meta_must_survive_json(meta: dict, message: str):
    with pytest.raises(RecordingError, match=message):
        Recording(streams={}, meta=meta)


# ---------------------------------------------------------------------- access


def test_missing_stream_error_names_the_stream_and_those_present():
    rec = Recording(streams={"accel": _accel()})
    with pytest.raises(MissingStreamError) as info:
        _ = rec.truth
    assert isinstance(info.value, KeyError)
    assert str(info.value) == "recording has no 'truth' stream (streams present: accel)"
    with pytest.raises(MissingStreamError, match="'truth'"):
        rec.true_positions()


def test_properties():
    rec = make_recording()
    assert rec.accel is rec.streams["accel"]
    assert rec.has_truth
    # From the waypoints at 0 s to the last WiFi scan at 2.5 s, the widest span of any stream.
    assert rec.duration == 2.5
    pd.testing.assert_frame_equal(rec.true_positions(), rec.truth[["x", "y"]])
    real = Recording(streams={"waypoints": rec.waypoints})
    assert not real.has_truth
    pd.testing.assert_frame_equal(real.true_positions(), rec.waypoints)


# ---------------------------------------------------------------------- loading


def test_unknown_path_lists_the_formats_understood(tmp_path: Path):
    (tmp_path / "holiday.jpg").write_bytes(b"\xff\xd8")
    with pytest.raises(UnrecognisedFormatError) as info:
        Recording.load(tmp_path / "holiday.jpg")
    message = str(info.value)
    for name in ("manifest.json", "ilc2020", "oxford-stepcounter", "sensor-logger"):
        assert name in message
    with pytest.raises(FileNotFoundError):
        Recording.load(tmp_path / "absent")


def test_newer_format_version_is_refused(tmp_path: Path):
    folder = make_recording().save(tmp_path / "walk")
    manifest = json.loads((folder / "manifest.json").read_text(encoding="utf-8"))
    manifest["format_version"] = FORMAT_VERSION + 1
    (folder / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")
    with pytest.raises(RecordingError, match="newer indoorsim"):
        Recording.load(folder)


def test_a_damaged_stream_file_is_named(tmp_path: Path):
    folder = make_recording().save(tmp_path / "rec")
    victim = folder / "accel.parquet"
    victim.write_bytes(victim.read_bytes()[:40])  # cut short, as by a full disk
    with pytest.raises(RecordingError, match=r"accel\.parquet: stream 'accel' cannot be read"):
        Recording.load(folder)


def test_docstring_examples_run():
    result = doctest.testmod(recording)
    assert result.attempted > 0 and result.failed == 0
