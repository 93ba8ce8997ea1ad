"""Real phone logs load into Recordings with the right units, frames, clocks and labels."""

from __future__ import annotations

import csv
import doctest
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import indoorsim.io.reallogs.common
from indoorsim.io.reallogs import (
    MalformedRowsWarning,
    carry_mode,
    detect_format,
    read_ilc_trace,
    read_mag_slam_walk,
    read_oxford_validation,
    read_sensor_logger,
)
from indoorsim.io.reallogs.oxford import BOUNCE_STRIDES, MISSED_STRIDES, foot_contacts
from indoorsim.io.recording import Recording, RecordingError
from tests.conftest import REALDATA

ILC = REALDATA / "ms-indoor-location-2020/site1/F1"
OXFORD = REALDATA / "oxford-stepcounter"


def _needs(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"real data not found beside the repository: {path}")
    return path


def _norms(df: pd.DataFrame, columns: list[str]) -> np.ndarray:
    return np.linalg.norm(df[columns].to_numpy(), axis=1)


# ---------------------------------------------------------------------- ILC 2.0 traces


@pytest.fixture(scope="module")
def ilc_traces() -> list[Recording]:
    files = sorted(_needs(ILC / "path_data_files").glob("*.txt"))[:3]
    return [Recording.load(f) for f in files]


def test_ilc_sensor_streams_are_plausible(ilc_traces: list[Recording]):
    for rec in ilc_traces:
        for stream in ("accel", "gyro", "mag", "rotation"):
            assert 45 < rec.meta["rates_hz"][stream] < 55, stream
        assert rec.accel.index[0] == 0.0
        assert 9.3 < _norms(rec.accel, ["x", "y", "z"]).mean() < 10.3
        assert 30 < _norms(rec.mag, ["x", "y", "z"]).mean() < 70
        np.testing.assert_allclose(_norms(rec.rotation, ["qw", "qx", "qy", "qz"]), 1.0, atol=1e-12)
        assert (rec.rotation["qw"] >= 0).all()


def test_ilc_wifi_and_waypoints(ilc_traces: list[Recording]):
    for rec in ilc_traces:
        assert len(rec.wifi) > 100
        assert (rec.wifi["rss"] < 0).all() and (rec.wifi["rss"] > -110).all()
        assert (rec.wifi["age_s"] >= 0).all()
        assert rec.wifi["bssid"].str.fullmatch(r"([0-9a-f]{2}:){5}[0-9a-f]{2}").all()
        assert 3 <= len(rec.waypoints) <= 8
        site = rec.meta["site"]
        assert (rec.waypoints["x"].between(0, site["map_width_m"])).all()
        assert (rec.waypoints["y"].between(0, site["map_height_m"])).all()
        pd.testing.assert_frame_equal(rec.true_positions(), rec.waypoints)
        assert not rec.has_truth


def test_ilc_header_goes_to_meta(ilc_traces: list[Recording]):
    meta = ilc_traces[0].meta
    assert meta["device"] == "OPPO PBCM10"
    assert meta["phone"]["api_level"] == 27
    assert meta["site"]["floor_name"] == "F1"
    assert meta["site"]["map_width_m"] == pytest.approx(239.8, abs=0.1)
    assert meta["sensors"]["mag"]["name"] == "AK09911 Magnetometer"
    assert meta["sensors"]["mag"]["resolution"] == pytest.approx(0.6, abs=0.01)
    assert meta["start_time_unix_ms"] <= meta["t0_unix_ms"] < meta["end_time_unix_ms"]
    assert meta["mode"] == "handheld"
    assert meta["malformed_lines"] == 0
    assert meta["dropped_rows"]["TYPE_BEACON"] > 0


def test_ilc_trace_survives_save_and_load(ilc_traces: list[Recording], tmp_path: Path):
    rec = ilc_traces[0]
    loaded = Recording.load(rec.save(tmp_path / "trace"))
    assert loaded.meta == rec.meta
    for name, df in rec.streams.items():
        pd.testing.assert_frame_equal(df, loaded.streams[name], check_exact=True)


SMALL_TRACE = """\
#\tstartTime:1000000
#\tSiteID:s1\tSiteName:Mall\tFloorId:f1\tFloorName:F2
#\tBrand:ACME\tModel:P1\tAndroidName:14\tAPILevel:34
#\ttype:1\tname:Acc\tversion:1\tvendor:V\tresolution:0.01\tpower:0.1\tmaximumRange:80
1000010\tTYPE_WAYPOINT\t1.5\t2.5
1000100\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3
1000100\tTYPE_ROTATION_VECTOR\t0.0\t0.0\t0.70710678\t3
1000100\tTYPE_BEACON\tuuid\t1\t2\t-60\t-70\t1.0\tmac\t1000100
1000120\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.9\t31000140\tTYPE_GYROSCOPE\t0.0\t0.0\t0.1\t3
1000140\tTYPE_ACCELEROMETER\t0.1\t0.2\tnot-a-number\t3
1000160\tTYPE_ACCELEROMETER\t0.0\t0.3\t9.7\t3
1000200\tTYPE_WIFI\tnet\t02:00:00:00:00:01\t-61\t2412\t998200
1000200\tTYPE_WIFI\tnet\t02:00:00:00:00:02\t-75\t5180\t1000150
1000900\tTYPE_WAYPOINT\t3.5\t2.5
#\tendTime:1001000
"""


def test_ilc_mapping_on_a_small_trace(tmp_path: Path):
    path = tmp_path / "trace.txt"
    path.write_text(SMALL_TRACE, encoding="utf-8")
    assert detect_format(path).name == "ilc2020"
    with pytest.warns(
        MalformedRowsWarning,
        match=r"trace\.txt: skipped 2 malformed rows \(1 run together with the next row, "
        r"1 with a field that is not a number\)$",
    ):
        rec = read_ilc_trace(path)
    # t = 0 at the first sensor row (ms 1000100); the waypoint before it is negative.
    np.testing.assert_array_equal(rec.accel.index, [0.0, 0.06])
    np.testing.assert_array_equal(rec.accel["z"], [9.8, 9.7])
    np.testing.assert_array_equal(rec.waypoints.index, [-0.09, 0.8])
    # Rotation vector 90° about z: w = sqrt(1 - z²) = cos 45°.
    np.testing.assert_allclose(rec.rotation.iloc[0], [np.sqrt(0.5), 0, 0, np.sqrt(0.5)], atol=1e-8)
    np.testing.assert_array_equal(rec.wifi.index, [0.1, 0.1])
    np.testing.assert_array_equal(rec.wifi["rss"], [-61.0, -75.0])
    np.testing.assert_allclose(rec.wifi["age_s"], [2.0, 0.05])
    # The run-on line (two rows, one newline lost) and the unparsable value are skipped.
    assert rec.meta["malformed_lines"] == 2
    assert rec.meta["malformed_rows"] == {
        "run together with the next row": 1,
        "with a field that is not a number": 1,
    }
    assert "gyro" not in rec.streams
    assert rec.meta["dropped_rows"] == {"TYPE_BEACON": 1}
    assert rec.meta["device"] == "ACME P1" and rec.meta["site"]["floor_name"] == "F2"
    assert rec.meta["sensors"]["accel"]["max_range"] == 80.0
    assert "map_width_m" not in rec.meta["site"]


# ---------------------------------------------------------------------- Oxford step counter


def _upstream_steps() -> dict[str, int]:
    with (_needs(OXFORD) / "optimisation/stats_upstream.csv").open() as rows:
        return {
            row[0]: int(row[6])
            for row in csv.reader(rows, skipinitialspace=True)
            if not row[0].startswith("#")
        }


@pytest.mark.parametrize(
    ("folder", "device_steps", "steps", "mode", "rate_hz"),
    [  # device_steps: the table in realdata/oxford-stepcounter/README.md
        ("Pixel_Jamie_Hard_InHand_1", 292, 292, "handheld", 405),
        ("Pixel_Jamie_Hard_SwingingArm_1", 284, 264, "dangling", 405),
        ("Samsung_Dario_Hard_FrontPocket_1", 306, 315, "pocketed", 205),
        ("Samsung_Carmelo_Hard_Purse_1", 288, 288, "Purse", 205),
    ],
)
def test_oxford_folder_steps_are_the_devices_checked(
    folder: str, device_steps: int, steps: int, mode: str, rate_hz: float
):
    rec = Recording.load(_needs(OXFORD / "optimisation" / folder))
    assert rec.meta["device_steps"] == device_steps == _upstream_steps()[folder]
    assert sum(rec.meta["channel_steps"]) == device_steps
    # The check: bounces dropped, missed contacts added (foot_contacts).
    assert len(rec.steps) == steps == rec.meta["ground_truth_steps"]
    bounces, missed = rec.meta["switch_bounces"], rec.meta["missed_contacts"]
    assert steps == device_steps - bounces + missed
    assert (bounces, missed) == {
        "Pixel_Jamie_Hard_SwingingArm_1": (20, 0),
        "Samsung_Dario_Hard_FrontPocket_1": (6, 15),
    }.get(folder, (0, 0))
    assert missed == rec.steps["inferred"].sum()
    assert set(rec.steps["channel"]) == {1, 2}
    assert rec.steps["foot"].isna().all() and rec.steps["length"].isna().all()
    assert rec.meta["mode"] == mode
    assert rec.meta["rates_hz"]["accel"] == pytest.approx(rate_hz, rel=0.03)
    assert 9.5 < _norms(rec.accel, ["x", "y", "z"]).mean() < 11.5
    assert rec.steps.index[0] > 0 and rec.steps.index[-1] <= rec.accel.index[-1] + 0.1


def _alternating(n: int, step_s: float = 0.55) -> tuple[np.ndarray, np.ndarray]:
    """n steps of a clean two-switch device: feet alternate every ``step_s``."""
    return np.arange(n) * step_s, np.where(np.arange(n) % 2 == 0, 1, 2)


def test_foot_contacts_leaves_a_clean_device_alone():
    t, channel = _alternating(40)
    contacts = foot_contacts(t[::-1], channel[::-1])  # any order in, time order out
    np.testing.assert_array_equal(contacts.t, t)
    np.testing.assert_array_equal(contacts.channel, channel)
    assert not contacts.inferred.any() and contacts.bounces == 0


def test_foot_contacts_drops_bounces_and_adds_missed_contacts():
    t, channel = _alternating(40)  # a stride of 1.1 s
    stride = 1.1
    # Channel 1 bounces 0.3 s after three of its steps (within half a stride) ...
    bounce_t = t[[4, 10, 20]] + 0.3
    # ... and channel 2 misses its steps 7 and 25 (channel 1 steps twice in a row).
    keep = np.ones(len(t), dtype=bool)
    keep[[7, 25]] = False
    contacts = foot_contacts(
        np.concatenate([t[keep], bounce_t]), np.concatenate([channel[keep], [1, 1, 1]])
    )
    assert contacts.bounces == 3
    # Every true step back, the missed ones midway between their neighbours.
    np.testing.assert_allclose(contacts.t, t)
    np.testing.assert_array_equal(contacts.channel, channel)
    np.testing.assert_array_equal(np.flatnonzero(contacts.inferred), [7, 25])
    assert 0.3 < BOUNCE_STRIDES * stride and MISSED_STRIDES * stride > 2 * 0.55


def test_foot_contacts_adds_nothing_across_a_halt():
    # The walker stops on channel 1's foot and starts again with it 3 s later.
    t, channel = _alternating(21)
    later_t, later_channel = _alternating(20)
    contacts = foot_contacts(
        np.concatenate([t, t[-1] + 3.0 + later_t]), np.concatenate([channel, later_channel])
    )
    assert len(contacts.t) == 41 and not contacts.inferred.any()


def test_foot_contacts_rejects_mismatched_inputs():
    with pytest.raises(ValueError, match="3 step times but 2 channels"):
        foot_contacts([0.0, 0.5, 1.0], [1, 2])
    with pytest.raises(ValueError, match="must be finite; 1 are not"):
        foot_contacts([0.0, np.nan, 1.0], [1, 2, 1])
    with pytest.raises(ValueError, match=r"channels must be 1 or 2, got \[1, 3\]"):
        foot_contacts([0.0, 0.5, 1.0], [1, 3, 1])


@pytest.mark.parametrize("rises", [[], [0.0], [0.0, 0.55, 1.1, 1.65]])
def test_foot_contacts_leaves_a_device_it_cannot_check_alone(rises):
    """One switch alone (or none): no stride to measure, no other foot to alternate
    with, so nothing is dropped or added."""
    contacts = foot_contacts(rises, [1] * len(rises))
    np.testing.assert_array_equal(contacts.t, rises)
    assert not contacts.inferred.any() and contacts.bounces == 0


@pytest.mark.parametrize(
    "name", ["user1_hand_1506421989895.csv", "user2_backpocket_1506422483834.csv"]
)
def test_oxford_validation_steps_follow_the_ground_truth_column(name: str):
    path = _needs(OXFORD / "validation" / name)
    rec = Recording.load(path)
    ground_truth = np.loadtxt(path, delimiter=",", usecols=5)
    assert len(rec.steps) == ground_truth[-1] == rec.meta["ground_truth_steps"]
    assert rec.meta["device_steps"] == rec.meta["ground_truth_steps"]
    assert 326 <= len(rec.steps) <= 361
    assert 99 < rec.meta["rates_hz"]["accel"] < 102
    assert rec.meta["device"] == "Samsung Galaxy S6"
    assert rec.accel.index[0] == 0.0
    assert 9.5 < _norms(rec.accel, ["x", "y", "z"]).mean() < 12.5


def test_oxford_validation_meta():
    hand = Recording.load(_needs(OXFORD / "validation/user1_hand_1506421989895.csv"))
    assert hand.meta["mode"] == "handheld" and hand.meta["user"] == "user1"
    assert hand.meta["start_time_unix_ms"] == 1506421989895
    assert hand.meta["hardware_steps"] is None  # all zero: not recorded for user1
    assert hand.meta["dropped_rows"] == {"zero_accel_placeholder": 1}
    pocket = read_oxford_validation(OXFORD / "validation/user2_backpocket_1506422483834.csv")
    assert pocket.meta["mode"] == "pocketed" and pocket.meta["hardware_steps"] == 345


def test_oxford_validation_steps_on_a_small_file(tmp_path: Path):
    path = tmp_path / "user9_armband_1500000000000.csv"
    # ns, ax, ay, az, app steps, ground-truth steps, hardware steps; GT jumps by 2 at row 3.
    path.write_text(
        "5000000000,0,0,0,0,0,0\n"
        "5010000000,0.1,0.2,9.8,0,0,0\n"
        "5020000000,0.1,0.2,9.8,1,1,0\n"
        "5030000000,0.1,0.2,9.8,1,3,0\n"
        "5040000000,0.1,0.2,9.8,2,3,0\n"
    )
    rec = Recording.load(path)
    np.testing.assert_allclose(rec.steps.index, [0.01, 0.02, 0.02])
    np.testing.assert_allclose(rec.accel.index, [0.0, 0.01, 0.02, 0.03])
    assert rec.meta["mode"] == "armband" and rec.meta["app_algorithm_steps"] == 2
    path.write_text("1,0.1,0.2,9.8,0,2,0\n2,0.1,0.2,9.8,0,1,0\n")
    with pytest.raises(RecordingError, match="decreases at row 1"):
        Recording.load(path)


def test_garbage_rows_are_skipped_counted_and_warned_about(tmp_path: Path):
    """Garbage in a real log: the readable rows are read as in a clean file, the others
    skipped, counted by reason in meta and named in one warning."""
    clean = "".join(
        f"{5_000_000_000 + k * 10_000_000},0.1,0.2,9.8,0,{k // 2},0\n" for k in range(6)
    )
    rows = clean.splitlines(keepends=True)
    path = tmp_path / "user9_armband_1500000000000.csv"
    path.write_text(clean)
    expected = Recording.load(path)
    garbage = ["0.1,garbage\n", "5012000000,0.1,0.2,x9.8,0,0,0\n", "\n", "1,2,3,4,5,6,7,8\n"]
    path.write_bytes("".join([*rows[:2], *garbage, *rows[2:]]).encode() + b"\xff\xfe,1,2,3,4,5,6\n")
    with pytest.warns(MalformedRowsWarning) as warned:
        rec = Recording.load(path)
    assert [str(w.message) for w in warned] == [
        f"{path}: skipped 4 malformed rows (2 with a field that is not a number, "
        "2 with the wrong number of fields)"
    ]
    assert rec.meta["malformed_rows"] == {
        "with a field that is not a number": 2,
        "with the wrong number of fields": 2,
    }
    for name, df in expected.streams.items():
        pd.testing.assert_frame_equal(df, rec.streams[name])
    assert expected.meta["malformed_rows"] == {}


def test_a_sensor_logger_file_with_garbage_keeps_its_good_rows(tmp_path: Path):
    folder = _sensor_logger_export(tmp_path / "export")
    expected = read_sensor_logger(folder)
    gyro = folder / "Gyroscope.csv"
    head, *rows = gyro.read_text().splitlines(keepends=True)
    gyro.write_text("".join([head, rows[0], "not,a,row,at,all\n", "oops\n", *rows[1:]]))
    with pytest.warns(
        MalformedRowsWarning,
        match=r"export: skipped 2 malformed rows \(1 gyroscope\.csv: with a field that is not "
        r"a number, 1 gyroscope\.csv: with the wrong number of fields\)",
    ):
        rec = read_sensor_logger(folder)
    assert rec.meta["malformed_rows"] == {
        "gyroscope.csv: with a field that is not a number": 1,
        "gyroscope.csv: with the wrong number of fields": 1,
    }
    pd.testing.assert_frame_equal(rec.gyro, expected.gyro)


def test_carry_modes():
    assert [carry_mode(p) for p in ("InHand", "hand", "BackPocket", "backpocket")] == [
        "handheld",
        "handheld",
        "pocketed",
        "pocketed",
    ]
    assert carry_mode("SwingingArm") == "dangling"
    assert carry_mode("NeckPouch") == "NeckPouch"


# ---------------------------------------------------------------------- Sensor Logger

T0 = 1_700_000_000_000_000_000  # ns since the epoch


def _rows(header: str, rows: list[tuple]) -> str:
    return header + "\n" + "".join(",".join(str(v) for v in row) + "\n" for row in rows)


def _sensor_logger_export(folder: Path, *, platform: str = "android") -> Path:
    """A small export in the app's documented layout (axis files ordered z, y, x)."""
    folder.mkdir()
    ms = 1_000_000
    times = [T0 + 10 * ms * i for i in range(4)]
    files = {
        "Gyroscope.csv": _rows(
            "time,seconds_elapsed,z,y,x",
            [(t, 0.1 + i / 100, 0.3, 0.2, 0.1) for i, t in enumerate(times)],
        ),
        "Gravity.csv": _rows(
            "time,seconds_elapsed,z,y,x",
            [(t, 0.1 + i / 100, 9.8, 0.5, 0.0) for i, t in enumerate(times)],
        ),
        "Accelerometer.csv": _rows(
            "time,seconds_elapsed,z,y,x",
            [(t, 0.1 + i / 100, 0.3, 0.2, 0.1) for i, t in enumerate(times)],
        ),
        "Magnetometer.csv": _rows(
            "time,seconds_elapsed,z,y,x",
            [
                (times[0], 0.1, -40.0, 20.0, 5.0),
                (times[2], 0.12, -41.0, 21.0, 6.0),
                # A stale repeat of an earlier sample: its time goes backwards.
                (times[1], 0.11, -40.0, 20.0, 5.0),
                (times[3], 0.13, -42.0, 22.0, 7.0),
            ],
        ),
        "Orientation.csv": _rows(
            "time,seconds_elapsed,qz,qy,qx,qw,roll,pitch,yaw",
            [(t, 0.1, 0.0, 0.0, 0.6, 0.8, 0.0, 1.287, 0.0) for t in times],
        ),
        "Location.csv": _rows("time,seconds_elapsed,latitude,longitude", [(times[0], 0.1, 51, 0)]),
        "Metadata.csv": _rows(
            "version,device name,recording epoch time,recording time,recording timezone,"
            "platform,appVersion,device id,sensors,sampleRateMs,standardisation,platform version",
            [
                (
                    3,
                    "Pixel 8",
                    T0 // 1_000_000,
                    "2023-11-14_22-13-20",
                    "Europe/London",
                    platform,
                    "1.64",
                    "secret-id",
                    "Accelerometer|Gyroscope",
                    "10|10",
                    "false",
                    36,
                )
            ],
        ),
    }
    if platform == "android":
        files["TotalAcceleration.csv"] = _rows(
            "time,seconds_elapsed,z,y,x",
            [(t - 5 * ms, 0.095 + i / 100, 9.81, 0.7, 0.1) for i, t in enumerate(times)],
        )
        files["Light.csv"] = _rows("time,seconds_elapsed,lux", [(times[1], 0.11, 120.5)])
        files["WiFi.csv"] = _rows(
            "time,seconds_elapsed,ssid,bssid,frequency,level,capabilities",
            [
                (times[2], 0.12, "lab", "02:00:00:00:00:0a", 2437, -48, "[WPA2]"),
                (times[2], 0.12, "lab", "02:00:00:00:00:0b", 5180, -77, "[WPA2]"),
            ],
        )
    for name, text in files.items():
        (folder / name).write_text(text)
    return folder


def test_sensor_logger_android_folder(tmp_path: Path):
    rec = Recording.load(_sensor_logger_export(tmp_path / "export"))
    assert rec.meta["source"]["format"] == "sensor-logger"
    # t = 0 at the first motion sample: TotalAcceleration, 5 ms before the others.
    np.testing.assert_allclose(rec.accel.index, [0.0, 0.01, 0.02, 0.03])
    np.testing.assert_allclose(rec.gyro.index, [0.005, 0.015, 0.025, 0.035])
    # Columns are taken by name, not position: files list z, y, x.
    np.testing.assert_array_equal(rec.accel.iloc[0], [0.1, 0.7, 9.81])
    np.testing.assert_array_equal(rec.gyro.iloc[0], [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(rec.linear_accel.iloc[0], [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(rec.gravity.iloc[0], [0.0, 0.5, 9.8])
    np.testing.assert_array_equal(rec.rotation.iloc[0], [0.8, 0.6, 0.0, 0.0])
    np.testing.assert_array_equal(rec.mag["z"], [-40.0, -41.0, -42.0])
    assert rec.meta["dropped_rows"] == {"magnetometer_time_backwards": 1}
    assert rec.light["lux"].tolist() == [120.5]
    assert rec.wifi["bssid"].tolist() == ["02:00:00:00:00:0a", "02:00:00:00:00:0b"]
    np.testing.assert_array_equal(rec.wifi["rss"], [-48.0, -77.0])
    assert rec.meta["device"] == "Pixel 8" and rec.meta["platform"] == "android"
    assert rec.meta["standardisation"] is False
    assert rec.meta["t0_unix_ns"] == T0 - 5_000_000
    assert rec.meta["dropped_files"] == ["location"]
    assert "secret-id" not in str(rec.meta)
    assert "not confirmed" in rec.meta["frames"]["rotation"]


def test_sensor_logger_zip_reads_like_the_folder(tmp_path: Path):
    folder = _sensor_logger_export(tmp_path / "export")
    archive = tmp_path / "export.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        for file in folder.iterdir():
            zf.write(file, arcname=f"2023-11-14_22-13-20/{file.name}")
    from_zip, from_folder = Recording.load(archive), read_sensor_logger(folder)
    assert list(from_zip.streams) == list(from_folder.streams)
    for name, df in from_folder.streams.items():
        pd.testing.assert_frame_equal(df, from_zip.streams[name])


def test_sensor_logger_ios_builds_accel_from_user_acceleration_and_gravity(tmp_path: Path):
    rec = read_sensor_logger(
        _sensor_logger_export(tmp_path / "ios", platform="ios"), mode="calling"
    )
    # iOS without standardisation reports acceleration and gravity with the opposite sign.
    np.testing.assert_array_equal(rec.gravity.iloc[0], [-0.0, -0.5, -9.8])
    np.testing.assert_array_equal(rec.linear_accel.iloc[0], [-0.1, -0.2, -0.3])
    np.testing.assert_allclose(rec.accel.iloc[0], [-0.1, -0.7, -10.1])
    assert rec.accel.index[0] == 0.0 and rec.meta["mode"] == "calling"
    assert "light" not in rec.streams and "wifi" not in rec.streams


def test_sensor_logger_missing_column_is_named(tmp_path: Path):
    folder = _sensor_logger_export(tmp_path / "export")
    (folder / "Gyroscope.csv").write_text("time,seconds_elapsed,z,y\n1,0.1,0.3,0.2\n")
    with pytest.raises(RecordingError, match=r"gyroscope.csv lacks column\(s\) \['x'\]"):
        Recording.load(folder)


def test_docstring_examples_run():
    result = doctest.testmod(indoorsim.io.reallogs.common)
    assert result.attempted > 0 and result.failed == 0


# --- 1-D magnetic-field SLAM walks (MATLAB files) ---


def _write_mag_slam(path: Path, n: int = 50, **drop: bool) -> Path:
    from scipy.io import savemat

    t = np.arange(n) * 0.1
    step = np.tile([0.1, 0.0, 0.0], (n - 1, 1))  # 1 m/s along x
    data = {"t": t[:, None], "tm": (t + 0.002)[:, None], "m": np.tile([20.0, 0.0, 40.0], (n, 1))}
    data |= {"dPos": step, "quat": np.tile([1.0, 0, 0, 0], (n, 1))}
    for name in drop:
        data.pop(name)
    savemat(path, data)
    return path


def test_mag_slam_mapping_on_a_small_walk(tmp_path: Path):
    rec = Recording.load(_write_mag_slam(tmp_path / "walk.mat"))
    assert rec.meta["source"]["format"] == "mag-slam-1d" and rec.meta["mode"] == "handheld"
    assert set(rec.streams) == {"mag", "waypoints"}
    np.testing.assert_allclose(rec.waypoints["x"].iloc[[0, -1]], [0.0, 4.9])
    np.testing.assert_allclose(rec.mag.index[:2], [0.002, 0.102])
    assert rec.meta["rates_hz"]["mag"] == pytest.approx(10.0)


def test_mag_slam_missing_variable_is_named(tmp_path: Path):
    path = _write_mag_slam(tmp_path / "walk.mat", dPos=True)
    with pytest.raises(RecordingError, match=r"missing \['dPos'\]"):
        read_mag_slam_walk(path)


@pytest.mark.skipif(not REALDATA.is_dir(), reason=f"no real data at {REALDATA}")
def test_mag_slam_walks_match_their_readme():
    # Path lengths and ‖m‖ mean from shared/realdata/mag-slam-1d/README.md.
    expected = {"eight": (46.4, 45.8), "library": (170.7, 45.7), "mall": (345.8, 46.6)}
    for name, (length, mean) in expected.items():
        rec = Recording.load(REALDATA / "mag-slam-1d" / f"{name}.mat")
        xy = rec.waypoints[["x", "y"]].to_numpy()
        assert np.hypot(*np.diff(xy, axis=0).T).sum() == pytest.approx(length, abs=0.1)
        assert np.linalg.norm(rec.mag.to_numpy(), axis=1).mean() == pytest.approx(mean, abs=0.05)


# ---------------------------------------------------------------------- Tyrex benchmark


def _tyrex_walk(folder: Path, *, android: bool, n: int = 50) -> Path:
    """A small walk in the Tyrex benchmark's layout: a phone lying face up, turning
    about its z axis at 0.5 rad/s, sampled at 100 Hz from t = 7.5 s on the log's clock."""
    folder.mkdir(parents=True)
    t = 7.5 + 0.01 * np.arange(n)
    up = 9.80665 if android else -1.0  # Android m/s², iOS g (a phone lying still: −1 g)
    accel = np.column_stack([t, np.zeros(n), np.zeros(n), np.full(n, up)])
    gyro = np.column_stack([t + 0.002, np.zeros(n), np.zeros(n), np.full(n, 0.5)])
    np.savetxt(folder / "accelerometer.txt", accel, fmt="%.6f")
    np.savetxt(folder / ("gyroscope-calibrated.txt" if android else "gyroscope.txt"), gyro)
    (folder / "timeAlignment.txt").write_text("   6.6000000e-01\n")
    if android:
        (folder / "record.properties").write_text("[Device]\nModel = Nexus 5\n")
        # Rotation vector x, y, z, cos(θ/2), accuracy: a turn of 0.5·t about z.
        half = 0.25 * (t - t[0])
        rv = np.column_stack([t, 0 * t, 0 * t, np.sin(half), np.cos(half), 0 * t + 0.17])
        np.savetxt(folder / "rotation-vector.txt", rv)
    return folder


@pytest.mark.parametrize("android", [True, False])
def test_tyrex_walk_reads_in_android_units_and_frame(tmp_path: Path, android: bool):
    """Both platforms read as Android does: gravity +9.81 m/s² on the axis pointing up,
    rad/s, t from the first sample; the context names the carrying mode."""
    folder = _tyrex_walk(tmp_path / "Jakob_iPhone5_NoDist_Swinging", android=android)
    rec = Recording.load(folder)
    assert rec.meta["source"]["format"] == "tyrex-attitude"
    assert rec.meta["mode"] == "dangling" and rec.meta["user"] == "Jakob"
    assert rec.meta["magnetic_disturbance"] is False
    np.testing.assert_allclose(rec.accel[["x", "y", "z"]].mean().to_numpy(), [0, 0, 9.80665])
    np.testing.assert_allclose(rec.gyro["z"].to_numpy(), 0.5)
    assert rec.accel.index[0] == 0.0 and rec.gyro.index[0] == pytest.approx(0.002)
    assert rec.meta["t0_log_s"] == pytest.approx(7.5)
    assert rec.meta["rates_hz"]["accel"] == pytest.approx(100.0)
    assert ("rotation" in rec.streams) is android
    if android:
        # The rotation vector's quaternion turns about z as the gyro says.
        q = rec.rotation[["qw", "qz"]].to_numpy()
        angle = 2.0 * np.arctan2(q[:, 1], q[:, 0])
        np.testing.assert_allclose(angle, 0.5 * rec.rotation.index.to_numpy(), atol=1e-9)


def test_tyrex_contexts_and_superseded_walks(tmp_path: Path):
    modes = {}
    for name in (
        "Thibaud_Nexus5_Dist_Texting",
        "Thibaud_Nexus5_Dist_Phoning",
        "Thibaud_Nexus5_Dist_FrontPocket",
        "Thibaud_Nexus5_Dist_AR",
        "Jakob_Nexus5_Dist_Swinging_old",
    ):
        modes[name] = Recording.load(_tyrex_walk(tmp_path / name, android=True)).meta["mode"]
    assert list(modes.values()) == ["handheld", "calling", "pocketed", "AR", None]


def test_tyrex_garbage_rows_and_a_missing_gyroscope(tmp_path: Path):
    folder = _tyrex_walk(tmp_path / "Guillaume_Nexus5_Dist_Texting", android=True)
    expected = Recording.load(folder)
    accel = folder / "accelerometer.txt"
    lines = accel.read_text().splitlines(keepends=True)
    garbage = ["7.53 0.1 oops 9.8\n", "7.54 0.1\n", "nan 0.1 0.2 9.8\n"]
    accel.write_text("".join([*lines[:3], *garbage, *lines[3:]]))
    with pytest.warns(MalformedRowsWarning, match="skipped 3 malformed rows"):
        rec = Recording.load(folder)
    assert rec.meta["malformed_rows"] == {
        "accelerometer.txt: with a field that is not a number": 2,
        "accelerometer.txt: with the wrong number of fields": 1,
    }
    pd.testing.assert_frame_equal(rec.accel, expected.accel)
    (folder / "gyroscope-calibrated.txt").unlink()
    (folder / "gyroscope.txt").write_text("")
    with pytest.raises(RecordingError, match=r"gyroscope\.txt: no rows"):
        Recording.load(folder)
