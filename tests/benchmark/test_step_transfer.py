"""Step counts: a step detector tuned on simulated walks alone, then run on real ones."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.step_transfer import (
    STEP_DETECTORS,
    StepWalk,
    count_steps,
    real_step_scores,
    tune_step_detector,
    write_step_transfer,
)

G = 9.80665


def _walk(cadence_hz: float, swing: float, seconds: float = 60.0, rate: float = 100.0):
    """A phone whose ‖a‖ swings by ``swing`` once per step at ``cadence_hz``."""
    t = np.arange(0.0, seconds, 1.0 / rate)
    up = G + 0.5 * swing * np.sin(2 * np.pi * cadence_hz * t)
    accel = np.column_stack([np.zeros_like(t), np.zeros_like(t), up])
    steps = int(cadence_hz * seconds)
    return StepWalk(
        source="sim",
        name=f"{cadence_hz}",
        mode="handheld",
        position="hand",
        t=t,
        accel=accel,
        true_steps=steps,
    )


def test_a_clean_sinusoidal_walk_is_counted_to_a_step():
    walk = _walk(1.8, 3.0)
    assert count_steps(walk, min_interval_s=0.3) == pytest.approx(walk.true_steps, abs=1)


def test_a_too_long_minimum_interval_drops_steps_of_a_fast_walker():
    fast = _walk(2.5, 3.0)
    assert count_steps(fast, min_interval_s=0.5) < 0.9 * fast.true_steps


def test_tuning_picks_a_setting_inside_the_good_region_not_on_its_edge():
    walks = [_walk(1.7, 3.0), _walk(2.3, 3.0)]
    grid = {
        "cutoff_hz": (3.0,),
        "min_interval_s": (0.15, 0.25, 0.35, 0.45, 0.55),
        "min_amplitude_mps2": (0.5,),
    }
    best, scores = tune_step_detector(walks, grid)
    # 0.45 s and more drop the 2.3 Hz walker's steps (0.43 s apart).
    bad = scores.set_index("min_interval_s")["worst_mode_pct"]
    assert bad[0.55] > 10 and bad[0.25] < 2 and bad[0.35] < 2
    # 0.15 and 0.25 s are as good on their own, but 0.25 has good neighbours on both sides.
    assert best["min_interval_s"] == 0.25
    assert list(scores.columns[:3]) == list(grid)


def test_the_trough_detector_counts_a_clean_walk_and_drops_a_fast_walkers_steps():
    walk = _walk(1.8, 3.0)
    assert count_steps(walk, "trough") == pytest.approx(walk.true_steps, abs=1)
    fast = _walk(2.5, 3.0)
    assert count_steps(fast, "trough", min_step_s=0.5, max_step_s=1.0) < 0.9 * fast.true_steps
    with pytest.raises(ValueError, match="no step detector 'pedometer'; there are peak-valley"):
        count_steps(walk, "pedometer")


def test_every_detector_is_tuned_on_its_own_grid():
    walks = [_walk(1.7, 3.0), _walk(2.3, 3.0)]
    grid = {"step_cutoff_hz": (3.0,), "trough_threshold_mps2": (0.3,), "min_step_s": (0.3, 0.5)}
    best, scores = tune_step_detector(walks, grid, detector="trough")
    # 0.5 s drops the 2.3 Hz walker's steps (0.43 s apart); 0.3 s keeps them.
    assert best == {"step_cutoff_hz": 3.0, "trough_threshold_mps2": 0.3, "min_step_s": 0.3}
    assert scores.set_index("min_step_s")["worst_mode_pct"][0.5] > 10
    assert set(STEP_DETECTORS["trough"].grid) == set(grid)
    assert set(STEP_DETECTORS["peak-valley"].grid) == {
        "cutoff_hz",
        "min_interval_s",
        "min_amplitude_mps2",
    }


def test_the_section_gives_each_detector_its_setting_and_real_scores(tmp_path):
    rows = []
    for detector, real_errors in (("peak-valley", (2.0, -4.0, 10.0)), ("trough", (1.0, 1.0, -1.0))):
        for mode, error in zip(("handheld", "handheld", "pocketed"), real_errors, strict=True):
            # Over the whole recording, the handling before and after adds 5 points.
            rows.append(
                {
                    "detector": detector,
                    "source": "real",
                    "mode": mode,
                    "error_pct": error,
                    "error_whole_pct": error + 5.0,
                }
            )
        rows.append(
            {
                "detector": detector,
                "source": "sim",
                "mode": "handheld",
                "error_pct": 0.0,
                "error_whole_pct": 0.0,
            }
        )
    errors = pd.DataFrame(rows)
    scores = real_step_scores(errors)
    # Peak-valley: median of |2|, |−4|, |10| is 4; handheld's median |error| 3, pocketed's 10.
    assert scores["peak-valley"] == (4.0, 10.0)
    assert scores["trough"] == (1.0, 1.0)
    # Whole recordings: trough |6|, |6|, |4| -> median 6, handheld 6, pocketed 4.
    assert real_step_scores(errors, "error_whole_pct")["trough"] == (6.0, 6.0)
    best = {"peak-valley": {"min_interval_s": 0.3}, "trough": {"min_step_s": 0.35}}
    text = "\n".join(write_step_transfer(tmp_path, best, errors))
    assert "setting min_interval_s = 0.3" in text and "setting min_step_s = 0.35" in text
    assert "trough: median |error| 1.0 %" in text and "peak-valley: median |error| 4.0 %" in text
    assert "the whole recordings 6.0 % and 6.0 %" in text
    assert (tmp_path / "sim_to_real_steps.csv").is_file()


@pytest.mark.parametrize("detector", ["peak-valley", "trough"])
def test_only_the_steps_reported_while_the_walk_walks_are_counted(detector):
    """Ten seconds of the phone handled before the walk and after it (a 1.5 Hz jiggle
    of 3 m/s²): the whole recording counts them, the walk's span does not."""
    walk = _walk(1.8, 3.0)
    t = np.arange(-10.0, 70.0, 0.01)
    up = np.full_like(t, G)
    inside = (t >= 0.0) & (t < 60.0)
    up[inside] = walk.accel[:, 2]
    handled = ~inside
    up[handled] += 1.5 * np.sin(2 * np.pi * 1.5 * t[handled])
    accel = np.column_stack([np.zeros_like(t), np.zeros_like(t), up])
    period = 1.0 / 1.8
    framed = StepWalk(
        source="real",
        name="handled",
        mode="pocketed",
        position="pocket",
        t=t,
        accel=accel,
        true_steps=walk.true_steps,
        walking=(-period, 60.0 + period),
    )
    assert count_steps(framed, detector) == pytest.approx(walk.true_steps, abs=2)
    assert count_steps(framed, detector, whole=True) > walk.true_steps + 20
