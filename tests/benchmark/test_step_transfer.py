"""Step counts: a step detector tuned on simulated walks alone, then run on real ones."""

from __future__ import annotations

import numpy as np
import pytest

from indoorsim.benchmark.step_transfer import StepWalk, count_steps, tune_step_detector

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
