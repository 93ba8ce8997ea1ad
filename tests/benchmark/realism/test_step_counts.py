"""A step detector miscounts simulated walks as it miscounts real ones, mode by mode.

Han2023's peak/valley detector counts the real Oxford step-counter walks
(``leaderboards/step_counts_real.csv``, made from ``shared/realdata``) almost
exactly with a 0.3 s minimum interval, and with 0.5 s it loses a share of the
steps that depends on where the phone is: little in the hand, about half when
the arm swings, two thirds in a front pocket, because the stride's own rhythm
in ‖a‖ (the arm's swing, the leg's) hides every other step. A simulated phone
whose signal has the real shape must fool the detector by the same amount.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.reference import load_real_motion
from indoorsim.benchmark.realism.report import RealismConfig, _sites
from indoorsim.estimators.pdr.steps import PeakStepDetector
from indoorsim.io.recording import Recording
from indoorsim.simulate import simulate
from indoorsim.walker.gait import WalkerParams, step_length_m
from tests.conftest import REPO

REAL_COUNTS = REPO / "leaderboards" / "step_counts_real.csv"
REAL_POSITIONS = {
    "handheld": {"InHand", "hand"},
    "dangling": {"SwingingArm"},
    "pocketed": {"FrontPocket", "frontpocket"},
}
"""The Oxford carrying positions each simulated mode models (front pockets only)."""
SEEDS = (0, 1, 2, 3)
"""Walks per site: the arm's swing, its lag, the elbow and the wrist are drawn per walk,
and at 0.5 s one swinging-arm walker loses 0–8 % of its steps where another loses
40–60 %, so the median is taken over several walkers on every site."""
MARGIN_PP = 15.0
"""Allowance beyond the real walks' range, percentage points: two to four real
walks by one or two people per position bound the real spread from below."""


def _walker_at(cadence_hz: float) -> WalkerParams:
    """The default walker at the speed where its cadence is ``cadence_hz``."""
    params = WalkerParams()
    # cadence = v / (h·(c0 + c1·v)), with h·c0 and h·c1 read off step_length_m.
    c0 = float(step_length_m(0.0, params.height_m))
    c1 = float(step_length_m(1.0, params.height_m)) - c0
    return dataclasses.replace(params, speed_mps=cadence_hz * c0 / (1.0 - cadence_hz * c1))


def _real_cadence_hz(walks: pd.DataFrame) -> float:
    """Median of the walks' true steps per second of walking (the committed real tables)."""
    motion = load_real_motion().set_index("walk")["walking_s"]
    return float(np.median(walks["true_steps"] / walks["walk"].map(motion)))


def _error_pct(rec: Recording, min_interval_s: float) -> float:
    acc = rec.accel
    detector = PeakStepDetector(min_interval_s=min_interval_s)
    found = len(detector.update(acc.index.to_numpy(dtype=float), acc[["x", "y", "z"]].to_numpy()))
    true = len(rec.steps)
    return 100.0 * (found - true) / true


@pytest.fixture(scope="module")
def sites():
    return _sites(RealismConfig())


@pytest.mark.parametrize("min_interval_s", [0.3, 0.5])
@pytest.mark.parametrize("mode", sorted(REAL_POSITIONS))
def test_the_detector_miscounts_a_simulated_walk_as_it_does_a_real_one(sites, mode, min_interval_s):
    real = pd.read_csv(REAL_COUNTS)
    real = real[real["position"].isin(REAL_POSITIONS[mode])]
    real = real[real["min_interval_s"] == min_interval_s]
    assert len(real) >= 2
    walker = _walker_at(_real_cadence_hz(real))
    simulated = [
        _error_pct(
            simulate(
                site, route=next(iter(site.scenario.routes)), mode=mode, seed=seed, walker=walker
            ),
            min_interval_s,
        )
        for _, _, site in sites
        for seed in SEEDS
    ]
    real = real["error_pct"]
    low, high = real.min() - MARGIN_PP, real.max() + MARGIN_PP
    assert low <= float(np.median(simulated)) <= high, (
        f"{mode}, {min_interval_s} s: simulated {np.round(simulated, 1)} %, "
        f"real {real.min():.1f} to {real.max():.1f} %"
    )
