"""``indoorsim realism`` and ``calibrate``: reports and twins written, bad arguments refused."""

from __future__ import annotations

import pandas as pd
import pytest
import yaml

from indoorsim.cli import main
from indoorsim.io.recording import Recording
from tests.conftest import REALDATA


def test_realism_writes_the_report_and_its_tables(tmp_path, capsys):
    out = tmp_path / "board"
    assert main(["realism", "--out", str(out), "--seeds", "1", "--mode", "handheld"]) == 0
    assert "statistics inside their real range" in capsys.readouterr().out
    text = (out / "realism.md").read_text()
    assert "### handheld" in text and "real range" in text
    table = pd.read_csv(out / "realism_motion.csv")
    assert set(table["mode"]) == {"handheld"}
    assert (out / "realism_motion.png").stat().st_size > 0


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--seeds", "0"], "--seeds must be at least 1"),
        (["--realdata", "/no/such/folder"], "--realdata /no/such/folder: no such folder"),
        (["--mode", "juggling"], "unknown carrying mode 'juggling'"),
    ],
)
def test_realism_refuses_bad_arguments(tmp_path, capsys, argv, expected):
    assert main(["realism", "--out", str(tmp_path / "board"), *argv]) == 2
    assert expected in capsys.readouterr().err


_ILC = REALDATA / "ms-indoor-location-2020" / "site1" / "F1" / "path_data_files"


@pytest.mark.skipif(not _ILC.is_dir(), reason="the real ILC traces are not here")
def test_calibrate_a_real_trace_and_simulate_its_twin(tmp_path, capsys):
    trace = sorted(_ILC.glob("*.txt"))[0]
    twin = tmp_path / "twin.yaml"
    assert main(["calibrate", str(trace), "--out", str(twin)]) == 0
    printed = capsys.readouterr().out
    assert f"wrote {twin}" in printed and "speed_mps" in printed
    # The ILC reader says the phone was held: the vigour is fitted through that.
    assert "walker vigour: bounce_fraction" in printed and "the fitted walk" in printed
    assert "not measured: accel noise" in printed  # the surveyor never stood still
    fitted = yaml.safe_load(twin.read_text())
    assert fitted["device"]["accel"]["rate_hz"] == pytest.approx(50.0, abs=0.5)
    assert 1.5 < fitted["walker"]["height_m"] < 2.0
    out = tmp_path / "walk"
    argv = ["simulate", "minimal_room", "--mode", "handheld", "--seed", "0"]
    assert main([*argv, "--device", str(twin), "--walker", str(twin), "--out", str(out)]) == 0
    assert Recording.load(out).meta["device"] == "twin"


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["/no/such/log", "--out", "{tmp}/a.yaml"], "/no/such/log"),
        (["{walk}", "--out", "{tmp}/a.txt"], "must end in .yaml or .yml"),
        (["{walk}", "--out", "{tmp}/a.yaml", "--base", "brick"], "unknown device 'brick'"),
        (["{walk}", "--out", "{tmp}/a.yaml", "--mode", "juggling"], "--mode: mode 'juggling'"),
    ],
)
def test_calibrate_refuses_bad_arguments(tmp_path, capsys, walk_folder, argv, expected):
    args = [a.format(tmp=tmp_path, walk=walk_folder) for a in argv]
    assert main(["calibrate", *args]) == 2
    assert expected in capsys.readouterr().err


def test_simulate_names_a_broken_device_or_walker_file(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("walker: {height_m: 9}\ndevice: {name: x, gyro: {rate_hz: 0}}\n")
    argv = ["simulate", "minimal_room", "--mode", "handheld", "--seed", "0"]
    out = str(tmp_path / "w")
    assert main([*argv, "--device", str(bad), "--out", out]) == 2
    assert "rate_hz must be > 0" in capsys.readouterr().err
    assert main([*argv, "--device", "ideal", "--walker", str(bad), "--out", out]) == 2
    assert "height_m=9" in capsys.readouterr().err


def test_leaderboard_sim_to_real_only_writes_its_page_and_names_a_missing_folder(tmp_path, capsys):
    real = tmp_path / "real"
    real.mkdir()
    out = tmp_path / "board"
    assert (
        main(["leaderboard", "--sim-to-real-only", "--realdata", str(real), "--out", str(out)]) == 0
    )
    assert "sim_to_real.md in" in capsys.readouterr().out
    assert "No Oxford step-counter walks" in (out / "sim_to_real.md").read_text()
    assert "sim_to_real.md" in (out / "README.md").read_text()
    missing = ["--realdata", str(tmp_path / "none"), "--out", str(out)]
    assert main(["leaderboard", "--sim-to-real-only", *missing]) == 2
    assert "no real-data folder" in capsys.readouterr().err
