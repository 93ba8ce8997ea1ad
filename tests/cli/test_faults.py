"""``indoorsim evaluate --fault``: faults applied to the test walks and recorded."""

from __future__ import annotations

import pandas as pd

from indoorsim.cli import main

ARGS = ["evaluate", "--estimator", "pdr-basic", "--scenario", "minimal_room", "--seeds", "1"]
ARGS += ["--device", "ideal"]


def test_evaluate_with_a_fault_runs_and_records_it(tmp_path):
    fault = "bias_jump:stream=gyro,t0=2,vector=0/0/0.2"
    assert (
        main([*ARGS, "--fault", fault, "--fault", "gap:t0=4,t1=5", "--out", str(tmp_path / "f")])
        == 0
    )
    assert main([*ARGS, "--out", str(tmp_path / "clean")]) == 0
    faulty = pd.read_csv(tmp_path / "f" / "summary.csv")
    clean = pd.read_csv(tmp_path / "clean" / "summary.csv")
    expected = "bias_jump:stream=gyro,t0=2,vector=0/0/0.2; gap:t0=4,t1=5,streams=accel/gyro/mag"
    assert faulty["faults"].iloc[0] == expected
    assert "faults" not in clean.columns
    assert faulty["ae"].iloc[0] != clean["ae"].iloc[0]  # the fault reached the episode


def test_a_bad_fault_spec_is_one_line_before_any_work(tmp_path, capsys):
    assert (
        main([*ARGS, "--fault", "bias_jump:stream=accel,t0=1", "--out", str(tmp_path / "x")]) == 2
    )
    err = capsys.readouterr().err.strip()
    assert err == (
        "indoorsim: --fault bias_jump:stream=accel,t0=1: fault bias_jump: missing parameter "
        "vector (parameters: stream, t0, vector)"
    )
    assert not (tmp_path / "x").exists()
    assert main([*ARGS, "--fault", "wobble", "--out", str(tmp_path / "y")]) == 2
    assert "unknown fault 'wobble'; known faults: dropout" in capsys.readouterr().err


def test_a_walk_fault_that_changes_nothing_is_one_line(tmp_path, capsys):
    args = [*ARGS, "--fault", "mode_change:t0=5,mode=handheld", "--out", str(tmp_path / "m")]
    assert main(args) == 2
    assert capsys.readouterr().err.strip() == (
        "indoorsim: --fault: fault mode_change: mode = 'handheld' is the mode already carried "
        "at t0 = 5 s: no change"
    )
    assert not (tmp_path / "m").exists()


def test_a_walk_fault_on_a_recording_is_refused(tmp_path, capsys):
    rec = tmp_path / "walk"
    args = ["simulate", "minimal_room", "--mode", "handheld", "--device", "ideal", "--seed", "0"]
    assert main([*args, "--out", str(rec)]) == 0
    capsys.readouterr()
    args = ["evaluate", "--estimator", "pdr-basic", "--recording", str(rec)]
    args += ["--fault", "wrong_device:device=honor_50", "--out", str(tmp_path / "e")]
    assert main(args) == 2
    assert capsys.readouterr().err.strip() == (
        "indoorsim: --fault wrong_device: changes how a walk is simulated, which a "
        "--recording already is; use it with --scenario"
    )
