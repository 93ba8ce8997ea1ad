"""``indoorsim realism``: the report is written, bad arguments are refused by name."""

from __future__ import annotations

import pandas as pd
import pytest

from indoorsim.cli import main


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
