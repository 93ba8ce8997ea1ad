"""The robustness board (indoorsim.benchmark.robustness): a small site, closed forms."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.robustness import (
    BOARD_FAULTS,
    RobustnessConfig,
    recovery_time,
    run_robustness,
    write_robustness,
)
from indoorsim.io.faults import FAULTS, parse_fault


class Trusting:
    """Uses the accelerometer without looking: a NaN sample makes its answer NaN."""

    name = "trusting"

    def fit(self, site, train):
        pass

    def reset(self, start):
        self.start = np.asarray(start.position, dtype=float)

    def act(self, obs):
        return self.start + 0.0 * obs["accel"][obs["valid"].astype(bool), :2].sum(axis=0)


T = np.arange(20.0) + 1.0  # window ends, s


@pytest.mark.parametrize(
    ("faulty", "expected"),
    [
        (np.zeros(20), 0.0),  # never worse: back at once
        (np.r_[np.zeros(10), np.full(3, 5.0), np.zeros(7)], 3.0),  # 3 windows late
        (np.r_[np.zeros(10), np.full(10, 5.0)], math.inf),  # never back
        # Within 1 m of the clean error counts as back; one good window among bad ones does not.
        (np.r_[np.zeros(10), 5.0, 0.9, 5.0, 5.0, np.full(6, 0.5)], 4.0),
    ],
)
def test_recovery_time_counts_whole_windows_from_the_fault_end(faulty, expected):
    assert recovery_time(T, faulty, np.zeros(20), t_end=10.5, hold_s=5.0) == expected


def test_recovery_tolerance_is_a_quarter_of_a_large_clean_error():
    clean = np.full(20, 8.0)
    assert recovery_time(T, clean * 1.24, clean, 0.0) == 0.0
    assert recovery_time(T, clean * 1.26, clean, 0.0) == math.inf


def test_the_board_covers_every_fault_kind():
    assert {parse_fault(spec).name for spec in BOARD_FAULTS} == set(FAULTS)


@pytest.fixture(scope="module")
def small_board():
    config = RobustnessConfig(
        estimators=("start-only", "pdr-basic", "tests.benchmark.test_robustness:Trusting"),
        faults=("nan_burst:stream=accel,t0=5,t1=8", "gap:t0=5,t1=8", "missing:streams=light"),
        scenario="minimal_room",
        modes=("handheld",),
        seeds=(0,),
    )
    return config, run_robustness(config)


def test_crashes_ratios_and_recovery_on_a_small_board(small_board):
    _, table = small_board
    assert (table["mode"] == "handheld").all()
    cell = table.assign(name=table["fault"].str.partition(":")[0]).set_index(["estimator", "name"])
    # The start is the start whatever the sensors say: exactly the fault-free error.
    assert (cell.loc["start-only", "ratio"] == 1.0).all()
    assert cell.loc[("start-only", "gap"), "recovery_s"] == 0.0
    # pdr-basic never reads the light sensor; a gap loses the distance walked in it.
    assert cell.loc[("pdr-basic", "missing"), "ratio"] == 1.0
    assert math.isnan(cell.loc[("pdr-basic", "missing"), "recovery_s"])  # it never ends
    assert cell.loc[("pdr-basic", "gap"), "ratio"] > 1.0
    # The estimator that trusts every sample crashes on NaN and only there.
    trusting = "tests.benchmark.test_robustness:Trusting"
    assert cell.loc[(trusting, "nan_burst"), "crashed_seeds"] == 1
    assert "returned array([nan, nan]) from act()" in cell.loc[(trusting, "nan_burst"), "crash"]
    assert math.isnan(cell.loc[(trusting, "nan_burst"), "ratio"])
    assert (cell.loc[trusting, "crashed_seeds"].drop("nan_burst") == 0).all()
    assert int(table["crashed_seeds"].sum()) == 1


def test_the_written_board_lists_every_cell_and_the_crash(small_board, tmp_path):
    config, table = small_board
    write_robustness(tmp_path, table, config, elapsed_s=1.0)
    text = (tmp_path / "robustness.md").read_text()
    assert "**Crashes: 1** of 9 mode × estimator × fault cells" in text
    assert "| tests.benchmark.test_robustness:Trusting |" in text and "**crash**" in text
    assert "nan_burst accel" in text and "missing light" in text and "## handheld:" in text
    assert (tmp_path / "robustness.png").stat().st_size > 10_000
    again = pd.read_csv(tmp_path / "robustness.csv")
    assert len(again) == len(table) == 9


def test_a_change_into_the_walked_mode_goes_to_the_hand_instead():
    from indoorsim.benchmark.robustness import _for_mode

    into_pocket = parse_fault("mode_change:t0=30,mode=pocketed")
    assert _for_mode(into_pocket, "handheld") is into_pocket
    assert _for_mode(into_pocket, "pocketed").spec() == "mode_change:t0=30,mode=handheld"
