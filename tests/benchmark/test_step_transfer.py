"""Step counts: a step detector tuned on simulated walks alone, then run on real ones."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.step_transfer import (
    APP_HOLD_S,
    APP_RETURN_S,
    STEP_DETECTORS,
    StepWalk,
    app_recording,
    count_steps,
    real_step_scores,
    step_route,
    step_walk,
    tune_step_detector,
    write_step_transfer,
)
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate

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


def _row(
    detector,
    source,
    walk,
    mode,
    error,
    walking_error,
    handled=(0.0, 0.0),
    peak=12.0,
    motion=0.5,
    device=100,
):
    """One walk's row of the step-count table, 100 true steps (``device`` by the
    reference device's unchecked count)."""
    return {
        "detector": detector,
        "source": source,
        "walk": walk,
        "mode": mode,
        "true_steps": 100,
        "device_steps": device,
        "error_device_pct": 100.0 * (100 + error - device) / device,
        "detected": 100 + error,
        "error_pct": error,
        "detected_walking": 100 + walking_error,
        "error_walking_pct": walking_error,
        "handled_before_s": handled[0],
        "handled_after_s": handled[1],
        "handled_peak_mps2": peak,
        "handled_motion_mps2": motion,
    }


def test_the_section_gives_each_detector_its_setting_and_real_scores(tmp_path):
    rows = []
    for detector, real_errors in (("peak-valley", (2.0, -4.0, 10.0)), ("trough", (1.0, 1.0, -1.0))):
        for k, (mode, error) in enumerate(
            zip(("handheld", "handheld", "pocketed"), real_errors, strict=True)
        ):
            # While walking, the handling before and after takes 5 points off.
            # The pocketed walk's device counted 110: its check took 10 off.
            rows.append(
                _row(
                    detector,
                    "real",
                    f"w{k}",
                    mode,
                    error,
                    error - 5.0,
                    handled=(1.0 + k, 4.0 + k),
                    peak=20.0,
                    device=110 if mode == "pocketed" else 100,
                )
            )
        # A simulated walk's name is its site and seed, the same in every mode.
        rows.append(_row(detector, "sim", "s", "handheld", 0.0, 0.0, peak=15.0))
        rows.append(_row(detector, "sim", "s", "pocketed", 0.0, 0.0, peak=30.0, motion=0.25))
    errors = pd.DataFrame(rows)
    scores = real_step_scores(errors)
    # Peak-valley: median of |2|, |−4|, |10| is 4; handheld's median |error| 3, pocketed's 10.
    assert scores["peak-valley"] == (4.0, 10.0)
    assert scores["trough"] == (1.0, 1.0)
    # While walking: trough |−4|, |−4|, |−6| -> median 4, handheld 4, pocketed 6.
    assert real_step_scores(errors, "error_walking_pct")["trough"] == (4.0, 6.0)
    best = {"peak-valley": {"min_interval_s": 0.3}, "trough": {"min_step_s": 0.35}}
    text = "\n".join(write_step_transfer(tmp_path, best, errors))
    assert "tuned here: min_interval_s = 0.3" in text and "tuned here: min_step_s = 0.35" in text
    assert "trough: median |error| 1.0 %" in text and "peak-valley: median |error| 4.0 %" in text
    assert "run on 1.0–3.0 s before the first true step and 4.0–6.0 s after" in text
    assert "peak-valley 5–5 a recording; trough 5–5 a recording" in text
    assert "they report peak-valley 0–0; trough 0–0." in text
    # The pocketed walks' handling: one real walk at 20 m/s², one simulated at 30.
    assert "pocketed 20–20 m/s² (median 20, 1 walk), simulated 30–30 m/s²" in text
    assert "pocketed 0.50–0.50 m/s² (median 0.50, 1 walk), simulated 0.25–0.25 m/s²" in text
    assert "trough median |error| 4.0 %, worst mode 6.0 %" in text
    # Against the device's own count: peak-valley 2, -4, 0 %; trough 1, 1, -10 %.
    assert "w2 110 → 100; the other 2 unchanged" in text
    assert (
        "peak-valley median |error| 2.0 %, worst mode 3.0 %; trough median |error| 1.0 %, "
        "worst mode 10.0 % (`error_device_pct`" in text
    )
    assert (tmp_path / "sim_to_real_steps.csv").is_file()


@pytest.mark.parametrize("detector", ["peak-valley", "trough"])
def test_a_recording_counts_the_handling_and_the_walking_span_does_not(detector):
    """Ten seconds of the phone handled before the walk and after it (a 1.5 Hz jiggle
    of 3 m/s²): every step reported counts, the handling's among them; while the walk
    walks, only the walk's."""
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
        true_span=(0.0, 60.0 - period, period),
    )
    assert framed.handled_s == pytest.approx((10.0, 10.0 + period), abs=0.02)
    # The jiggle's std, 1.5/√2 m/s², in every whole second outside the walk (to a few
    # per cent: a second holds one and a half of its cycles).
    assert framed.handled_motion_mps2 == pytest.approx(1.5 / np.sqrt(2), rel=0.05)
    assert count_steps(framed, detector, while_walking=True) == pytest.approx(
        walk.true_steps, abs=2
    )
    assert count_steps(framed, detector) > walk.true_steps + 20


def test_a_walks_span_comes_from_its_true_steps():
    """A recording's true steps give the walking span, half an interval before the first
    and one and a half after the last (the detectors report a step after its heel
    strike); without two true steps there is none."""
    t = np.arange(0.0, 20.0, 0.01)
    accel = pd.DataFrame({"x": 0.0, "y": 0.0, "z": G}, index=pd.Index(t, name="t"))
    steps = pd.DataFrame(
        {"foot": None, "length": np.nan}, index=pd.Index([5.0, 5.5, 6.5], name="t")
    )
    rec = Recording._from_built({"accel": accel, "steps": steps}, {})
    walk = step_walk(rec, "real", "w", "pocketed", "pocket")
    # Intervals 0.5 and 1.0: median 0.75.
    assert walk.true_span == (5.0, 6.5, 0.75)
    assert walk.walking == pytest.approx((5.0 - 0.375, 6.5 + 1.125))
    assert walk.handled_s == pytest.approx((5.0, 19.99 - 6.5))
    one = Recording._from_built({"accel": accel, "steps": steps.iloc[:1]}, {})
    alone = step_walk(one, "real", "w", "pocketed", "pocket")
    assert alone.walking is None and alone.handled_s == (0.0, 0.0)
    assert count_steps(alone, while_walking=True) == count_steps(alone) == 0


def test_a_simulated_walk_is_recorded_as_a_phone_app_records_one():
    """Started in the hand, put where the mode carries it, taken back after the last step:
    the schedule's return follows the walk that the simulation then walks."""
    site = load_site("minimal_room")
    route = next(iter(site.scenario.routes))
    assert app_recording(site, route, "handheld", 3) == "handheld"
    schedule = app_recording(site, route, "pocketed", 3)
    rec = simulate(site, route=route, mode=schedule, seed=3)
    last_step = float(rec.steps.index[-1])
    assert schedule == [
        (0.0, "handheld"),
        (APP_HOLD_S, "pocketed"),
        (pytest.approx(last_step + APP_RETURN_S), "handheld"),
    ]
    modes = rec.truth["mode"].to_numpy()
    assert modes[0] == "handheld" and modes[-1] == "handheld" and "pocketed" in set(modes)


def test_a_step_walk_goes_there_and_back_until_it_walks_as_long_as_a_real_one():
    site = load_site("minimal_room")
    name = next(iter(site.scenario.routes))
    spec = step_route(site, name, seconds=60.0)
    route = np.asarray(spec.waypoints)
    once = np.asarray(site.scenario.routes[name].points(), dtype=float)
    length = np.sum(np.linalg.norm(np.diff(route, axis=0), axis=1))
    assert length == pytest.approx(60.0 * spec.speed)
    # Out, back, out …: every second pass ends where the route starts.
    assert np.allclose(route[0], once[0]) and np.allclose(route[len(once) - 1], once[-1])
    assert np.allclose(route[2 * len(once) - 2], once[0])
    # Walked, it takes the route's time and its turns' on top: in this small room a
    # dozen turns about on the spot.
    rec = simulate(site, route=spec, seed=0)
    walking = float(rec.steps.index[-1] - rec.steps.index[0])
    assert 60.0 < walking < 80.0
