"""Metrics by closed forms and hand-computed cases."""

from __future__ import annotations

import ast
import doctest
import inspect
import math

import numpy as np
import pandas as pd
import pytest
from numpy.typing import ArrayLike, NDArray

from indoorsim.benchmark import metrics
from indoorsim.benchmark.metrics import (
    aggregate,
    error_cdf,
    error_stats,
    heading_errors,
    heading_stats,
    jump_backs,
    latency_stats,
    position_errors,
    relative_error,
    step_count_error,
    summarize,
    wall_crossings,
)

# DESIGN.md §10, spelled out here so that a rename fails a test.
ROW_KEYS = [
    "ae",
    "rmse",
    "me",
    "min",
    "sd",
    "cep50",
    "cep75",
    "cep95",
    "n",
    "path_m",
    "final_error",
    "error_per_100m",
    "heading_mae_deg",
    "heading_rmse_deg",
    "step_count_error",
    "step_count_error_pct",
    "wall_crossings",
    "jump_backs",
    "latency_ms_mean",
    "latency_ms_p95",
    "train_time_s",
    *(f"{k}_reftime" for k in ("ae", "rmse", "me", "min", "sd", "cep50", "cep75", "cep95", "n")),
]
REFTIME_KEYS = {k for k in ROW_KEYS if k.endswith("_reftime")}
OPTIONAL_KEYS = {
    "heading_mae_deg",
    "heading_rmse_deg",
    "step_count_error",
    "step_count_error_pct",
    "wall_crossings",
    "latency_ms_mean",
    "latency_ms_p95",
    "train_time_s",
    *REFTIME_KEYS,
}


class WallAtX5:
    """A fake plan: one infinite wall on the line x = 5; records each call's batch size."""

    def __init__(self) -> None:
        self.batch_sizes: list[int] = []

    def crosses_wall(self, p0: ArrayLike, p1: ArrayLike) -> NDArray[np.bool_]:
        a, b = np.asarray(p0), np.asarray(p1)
        self.batch_sizes.append(len(a))
        return (a[:, 0] - 5.0) * (b[:, 0] - 5.0) < 0


# A track crossing x = 5 on its 2nd and 4th moves.
TWICE_THROUGH_WALL = np.array([[1.0, 1.0], [4.0, 1.0], [6.0, 1.0], [7.0, 2.0], [3.0, 2.0]])


# ------------------------------------------------------------------ position


def test_position_error_is_the_3_4_5_hypotenuse():
    est = [[4.0, 6.0], [-1.0, -1.0], [2.0, 2.0]]
    true = [[1.0, 2.0], [2.0, 3.0], [2.0, 2.0]]
    np.testing.assert_allclose(position_errors(est, true), [5.0, 5.0, 0.0])


@pytest.mark.parametrize(
    ("est", "true", "message"),
    [
        ([[0.0, 0.0], [1.0, np.nan], [np.nan, 0.0]], [[0.0, 0.0]] * 3, r"est_xy: .*row 1"),
        ([[0.0, 0.0]] * 3, [[0.0, 0.0], [0.0, 0.0], [np.inf, 0.0]], r"true_xy: .*row 2"),
        ([[0.0, 0.0, 0.0]], [[0.0, 0.0]], r"est_xy: expected points of shape \(N, 2\)"),
        ([[0.0, 0.0]] * 2, [[0.0, 0.0]] * 3, r"differ in length: 2 vs 3"),
    ],
)
def test_position_errors_rejects_bad_input_naming_argument_and_row(est, true, message):
    with pytest.raises(ValueError, match=message):
        position_errors(est, true)


def test_error_stats_by_hand():
    # e = 1, 2, 2, 3, 7: mean 3; Σe² = 67; deviations −2, −1, −1, 0, 4 → Σ = 22.
    # Linear percentiles at h = 4q/100: h = 2 → 2, h = 3 → 3, h = 3.8 → 3 + 0.8·4.
    s = error_stats([2.0, 7.0, 1.0, 3.0, 2.0])
    expected = {
        "ae": 3.0,
        "rmse": math.sqrt(67 / 5),
        "me": 7.0,
        "min": 1.0,
        "sd": math.sqrt(22 / 4),
        "cep50": 2.0,
        "cep75": 3.0,
        "cep95": 6.2,
        "n": 5,
    }
    assert s.keys() == expected.keys()
    for key, value in expected.items():
        assert s[key] == pytest.approx(value, rel=1e-12), key


def test_error_stats_of_one_error_has_no_spread():
    s = error_stats([1.5])
    assert s["sd"] == 0.0
    assert s["ae"] == s["rmse"] == s["me"] == s["min"] == s["cep50"] == s["cep95"] == 1.5


@pytest.mark.parametrize(
    ("errors", "message"),
    [([], "errors: empty"), ([1.0, -0.5], "errors: negative value in row 1"), ([[1.0]], "1-D")],
)
def test_error_stats_rejects_bad_errors(errors, message):
    with pytest.raises(ValueError, match=message):
        error_stats(errors)


def test_error_cdf_steps_at_the_data_from_0_to_1():
    errors = [0.5, 2.0, 1.0, 2.0, 3.5]
    x, F = error_cdf(errors)
    np.testing.assert_array_equal(x, [0.5, 1.0, 2.0, 3.5])
    np.testing.assert_allclose(F, [0.2, 0.4, 0.8, 1.0])

    grid = np.linspace(0.0, 4.0, 401)
    xg, Fg = error_cdf(errors, grid)
    np.testing.assert_array_equal(xg, grid)
    assert Fg[0] == 0.0 and Fg[-1] == 1.0
    assert np.all(np.diff(Fg) >= 0)
    # F is flat between data and jumps by multiplicity / N exactly at each datum.
    _, below = error_cdf(errors, x - 1e-9)
    np.testing.assert_allclose(F - below, [0.2, 0.2, 0.4, 0.2])
    assert set(np.round(grid[np.flatnonzero(np.diff(Fg)) + 1], 9)) == set(x)


def test_relative_error_on_an_l_shaped_walk():
    true = [[0.0, 0.0], [30.0, 0.0], [30.0, 20.0]]  # L = 50 m
    r = relative_error([1.0, 0.0, 2.0], true)
    assert r["path_m"] == 50.0
    assert r["final_error"] == 2.0
    assert r["final_error_frac"] == pytest.approx(2.0 / 50.0)
    assert r["mean_error_frac"] == pytest.approx(1.0 / 50.0)
    assert r["error_per_100m"] == pytest.approx(4.0)


def test_relative_error_is_nan_when_the_walker_never_moved():
    r = relative_error([1.0, 2.0], [[3.0, 3.0], [3.0, 3.0]])
    assert r["path_m"] == 0.0 and r["final_error"] == 2.0
    assert math.isnan(r["final_error_frac"]) and math.isnan(r["error_per_100m"])


# ------------------------------------------------------------------ heading and steps


@pytest.mark.parametrize(
    ("est", "true", "wrapped"),
    [
        (179.0, -179.0, -2.0),
        (-179.0, 179.0, 2.0),
        (0.0, 360.0, 0.0),
        (360.0, 0.0, 0.0),
        (10.0, 730.0, 0.0),
        (180.0, 0.0, 180.0),
        (-180.0, 0.0, 180.0),  # the interval is half-open: −180 maps to +180
        (-1e-14, 0.0, 0.0),  # (tiny negative) mod 360 rounds to 360
        (90.0, -45.0, 135.0),
    ],
)
def test_heading_error_wraps_to_half_open_interval(est, true, wrapped):
    assert heading_errors([est], [true])[0] == pytest.approx(wrapped, abs=1e-12)


def test_heading_errors_stay_in_range_for_many_turns():
    rng = np.random.default_rng(0)
    est, true = rng.uniform(-2000, 2000, 1000), rng.uniform(-2000, 2000, 1000)
    d = heading_errors(est, true)
    assert np.all((d > -180.0) & (d <= 180.0))
    np.testing.assert_allclose(np.cos(np.radians(d)), np.cos(np.radians(est - true)), atol=1e-9)


def test_heading_stats_by_hand():
    h = heading_stats(heading_errors([179.0, 0.0, 4.0, -4.0], [-179.0, 358.0, 0.0, 0.0]))
    assert h["heading_mae_deg"] == pytest.approx(3.0)  # |−2|, |2|, |4|, |−4|
    assert h["heading_rmse_deg"] == pytest.approx(math.sqrt(10.0))
    assert h["heading_max_deg"] == pytest.approx(4.0)


def test_heading_input_checks():
    with pytest.raises(ValueError, match=r"true_heading: .*row 1"):
        heading_errors([0.0, 1.0], [0.0, np.nan])
    with pytest.raises(ValueError, match="outside"):
        heading_stats([10.0, 270.0])


def test_step_count_error_is_signed():
    assert step_count_error(95, 100) == {"step_count_error": -5, "step_count_error_pct": -5.0}
    assert step_count_error(np.int64(103), 100) == {
        "step_count_error": 3,
        "step_count_error_pct": pytest.approx(3.0),
    }
    with pytest.raises(ValueError, match="n_true"):
        step_count_error(5, 0)
    with pytest.raises(ValueError, match="n_est"):
        step_count_error(-1, 5)
    with pytest.raises(TypeError, match="n_est"):
        step_count_error(5.0, 5)


# ------------------------------------------------------------------ track consistency


def test_wall_crossings_counts_each_move_through_the_wall_in_one_call():
    plan = WallAtX5()
    assert wall_crossings(plan, TWICE_THROUGH_WALL) == 2
    assert plan.batch_sizes == [4]
    assert wall_crossings(plan, TWICE_THROUGH_WALL[:1]) == 0


def test_wall_crossings_rejects_a_plan_answering_the_wrong_shape():
    class Scalar:
        def crosses_wall(self, p0: ArrayLike, p1: ArrayLike) -> bool:
            return True

    with pytest.raises(ValueError, match=r"returned shape \(\) for 4 moves"):
        wall_crossings(Scalar(), TWICE_THROUGH_WALL)


# Truth walks +x for four steps, turns to +y for two, then stands still. The
# estimate's along-track advances s_k (its displacement on the true direction):
#   +1, −1.5, −0.5, 0 (a 3 m sideways move), −2, −0.2, and a −9 m move while
#   the walker stands still (no walking direction: never counted).
JB_TRUE = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [4, 0], [4, 1], [4, 2], [4, 2]], dtype=float)
JB_EST = np.cumsum(
    [[0, 0], [1, 0], [-1.5, 0], [-0.5, 0], [0, 3], [0, -2], [5, -0.2], [-9, 0]], axis=0
)


@pytest.mark.parametrize(
    ("threshold_m", "count"),
    [(1.0, 2), (1.5, 1), (0.4, 3), (0.0, 4), (5.0, 0)],  # 1.5: s = −1.5 is not below −1.5
)
def test_jump_backs_on_a_hand_made_track(threshold_m, count):
    assert jump_backs(JB_EST, JB_TRUE, threshold_m=threshold_m) == count


def test_jump_backs_default_threshold_and_checks():
    assert metrics.JUMP_BACK_THRESHOLD_M == 1.0
    assert jump_backs(JB_EST, JB_TRUE) == 2
    assert jump_backs(JB_EST[:1], JB_TRUE[:1]) == 0
    with pytest.raises(ValueError, match="threshold_m"):
        jump_backs(JB_EST, JB_TRUE, threshold_m=-1.0)
    with pytest.raises(ValueError, match=r"est_xy: .*row 3"):
        jump_backs(np.where(np.arange(8)[:, None] == 3, np.nan, JB_EST), JB_TRUE)


def test_latency_stats_in_milliseconds():
    lat = latency_stats([0.001, 0.010, 0.002, 0.003])
    assert lat["latency_ms_mean"] == pytest.approx(4.0)
    assert lat["latency_ms_p95"] == pytest.approx(3.0 + 0.85 * 7.0)  # h = 3·0.95 = 2.85
    assert lat["latency_ms_max"] == pytest.approx(10.0)


# ------------------------------------------------------------------ rows


def _full_row() -> dict[str, float]:
    true = np.array([[0.0, 1.0], [2.0, 1.0], [4.0, 1.0], [7.0, 1.0], [8.0, 2.0]])
    return summarize(
        TWICE_THROUGH_WALL,
        true,
        plan=WallAtX5(),
        est_heading=[179.0, 0.0, 4.0, -4.0],
        true_heading=[-179.0, 358.0, 0.0, 0.0],
        n_steps_est=9,
        n_steps_true=10,
        latencies=[0.001, 0.010, 0.002, 0.003],
        train_time_s=12.5,
        # Three distinct estimates at the times they refer to: errors 0, 1 and 3.
        ref_est_xy=[[0.0, 1.0], [2.0, 2.0], [4.0, 4.0]],
        ref_true_xy=[[0.0, 1.0], [2.0, 1.0], [4.0, 1.0]],
    )


def test_summarize_full_row_has_exactly_the_design_keys_and_values():
    row = _full_row()
    assert list(row) == ROW_KEYS == list(metrics.SUMMARY_KEYS)
    assert all(type(v) is float and math.isfinite(v) for v in row.values())
    # errors: 1, 2, 2, 1, 5; true path 2 + 2 + 3 + √2 m.
    assert row["ae"] == pytest.approx(11 / 5) and row["me"] == 5.0 and row["min"] == 1.0
    assert row["n"] == 5.0 and row["final_error"] == 5.0
    assert row["path_m"] == pytest.approx(7 + math.sqrt(2))
    assert row["error_per_100m"] == pytest.approx(500 / (7 + math.sqrt(2)))
    # Estimate's along-track advances: 3, 2, 1, −4/√2 → one jump-back.
    assert row["jump_backs"] == 1.0
    assert row["wall_crossings"] == 2.0
    assert row["heading_mae_deg"] == pytest.approx(3.0)
    assert row["heading_rmse_deg"] == pytest.approx(math.sqrt(10.0))
    assert row["step_count_error"] == -1.0 and row["step_count_error_pct"] == pytest.approx(-10.0)
    assert row["latency_ms_mean"] == pytest.approx(4.0)
    assert row["latency_ms_p95"] == pytest.approx(8.95)
    assert row["train_time_s"] == 12.5
    assert row["ae_reftime"] == pytest.approx(4 / 3) and row["me_reftime"] == 3.0
    assert row["min_reftime"] == 0.0 and row["n_reftime"] == 3.0


def test_summarize_minimal_row_has_the_same_keys_with_nan_for_omitted_inputs():
    row = summarize([[3.0, 4.0], [1.0, 0.0]], [[0.0, 0.0], [1.0, 0.0]])
    assert list(row) == ROW_KEYS
    assert all(type(v) is float for v in row.values())
    assert {k for k, v in row.items() if math.isnan(v)} == OPTIONAL_KEYS
    assert row["ae"] == 2.5 and row["sd"] == pytest.approx(math.sqrt(12.5))
    # Leaderboard CSVs built from full and minimal rows concatenate column by column.
    table = pd.concat([pd.DataFrame([_full_row()]), pd.DataFrame([row])], ignore_index=True)
    assert list(table.columns) == ROW_KEYS and table.dtypes.eq(float).all()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"est_heading": [0.0, 0.0]}, "est_heading and true_heading must be given together"),
        ({"n_steps_true": 3}, "n_steps_est and n_steps_true must be given together"),
        ({"train_time_s": math.nan}, "train_time_s"),
        ({"ref_est_xy": [[0.0, 0.0]]}, "ref_est_xy and ref_true_xy must be given together"),
    ],
)
def test_summarize_rejects_half_given_pairs(kwargs, message):
    with pytest.raises(ValueError, match=message):
        summarize([[0.0, 0.0], [1.0, 0.0]], [[0.0, 0.0], [1.0, 0.0]], **kwargs)


def test_summarize_nan_estimate_names_the_argument_and_row():
    with pytest.raises(ValueError, match=r"est_xy: non-finite value \(NaN or inf\) in row 1"):
        summarize([[0.0, 0.0], [np.nan, 0.0]], [[0.0, 0.0], [1.0, 0.0]])


def test_aggregate_mean_and_sample_std_by_hand():
    rows = [
        {"ae": 1.0, "n": 10.0, "heading_mae_deg": math.nan},
        {"ae": 2.0, "n": 10.0, "heading_mae_deg": math.nan},
        {"n": 10.0, "ae": 6.0, "heading_mae_deg": math.nan},
    ]
    agg = aggregate(rows)
    assert list(agg) == [
        "seeds",
        "ae",
        "ae_std",
        "n",
        "n_std",
        "heading_mae_deg",
        "heading_mae_deg_std",
    ]
    assert agg["seeds"] == 3
    assert agg["ae"] == pytest.approx(3.0)
    assert agg["ae_std"] == pytest.approx(math.sqrt((4 + 1 + 9) / 2))
    assert agg["n"] == 10.0 and agg["n_std"] == 0.0
    assert math.isnan(agg["heading_mae_deg"]) and math.isnan(agg["heading_mae_deg_std"])


def test_aggregate_of_one_seed_has_zero_spread():
    agg = aggregate([_full_row()])
    assert agg["seeds"] == 1
    assert all(agg[f"{k}_std"] == 0.0 for k in ROW_KEYS)
    assert all(agg[k] == v for k, v in _full_row().items())


def test_aggregate_rejects_empty_or_mismatched_rows():
    with pytest.raises(ValueError, match="at least one row"):
        aggregate([])
    with pytest.raises(
        ValueError, match=r"rows\[1\] keys differ.*missing \['rmse'\], extra \['me'\]"
    ):
        aggregate([{"ae": 1.0, "rmse": 1.0}, {"ae": 1.0, "me": 1.0}])


# ------------------------------------------------------------------ module


def test_metrics_never_import_the_simulator():
    tree = ast.parse(inspect.getsource(metrics))
    imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    forbidden = ("indoorsim.world", "indoorsim.walker", "indoorsim.phone")
    assert not {m for m in imported if m.startswith(forbidden)}


def test_docstring_examples_run():
    result = doctest.testmod(metrics)
    assert result.attempted > 0 and result.failed == 0


def test_a_track_on_a_wrong_heading_is_turned_back_about_the_start():
    # The true walk: an L from (2, 1); the estimate walks its exact shape 17° turned
    # counter-clockwise about the start, so turning it back 17° leaves no error.
    true = np.array([[2.0, 1.0], [6.0, 1.0], [10.0, 1.0], [10.0, 5.0], [10.0, 9.0]])
    th = math.radians(17.0)
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    est = (true - true[0]) @ rot.T + true[0]
    errors, turn = metrics.start_aligned_errors(est[1:], true[1:], true[0])
    assert turn == pytest.approx(-17.0)
    np.testing.assert_allclose(errors, 0.0, atol=1e-12)
    # A track too short by a fifth keeps its shape error, and the turn is the same.
    short = (est - true[0]) * 0.8 + true[0]
    errors, turn = metrics.start_aligned_errors(short[1:], true[1:], true[0])
    assert turn == pytest.approx(-17.0)
    np.testing.assert_allclose(errors, 0.2 * np.linalg.norm(true[1:] - true[0], axis=1))
    # Turning the whole scene changes nothing.
    errors_turned, turn_turned = metrics.start_aligned_errors(
        short[1:] @ rot.T, true[1:] @ rot.T, true[0] @ rot.T
    )
    np.testing.assert_allclose(errors_turned, errors, atol=1e-12)
    assert turn_turned == pytest.approx(turn)


def test_a_track_that_never_leaves_the_start_is_not_turned():
    errors, turn = metrics.start_aligned_errors(np.ones((2, 2)), [[1.0, 1.0], [4.0, 5.0]], [1, 1])
    assert turn == 0.0
    np.testing.assert_allclose(errors, [0.0, 5.0])


def test_the_start_must_be_one_finite_point():
    with pytest.raises(ValueError, match="start"):
        metrics.start_aligned_errors([[1.0, 1.0]], [[1.0, 1.0]], [np.nan, 0.0])
    with pytest.raises(ValueError):
        metrics.start_aligned_errors([[1.0, 1.0]], [[1.0, 1.0]], [0.0, 0.0, 0.0])


def test_track_length_clips_the_track_to_its_times():
    t = [0.0, 1.0, 2.0, 3.0]
    xy = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
    assert metrics.track_length(t, xy, 0.0, 3.0) == pytest.approx(6.0)
    # Ends between answers are interpolated: half of the first leg and half of the last.
    assert metrics.track_length(t, xy, 0.5, 2.5) == pytest.approx(4.0)
    # Within one leg: the straight piece between the two interpolated points.
    assert metrics.track_length(t, xy, 1.25, 1.75) == pytest.approx(1.0)
    assert metrics.track_length(t, xy, 2.0, 2.0) == 0.0
    # Longer than the chord through its positions at a few times: it turns between them.
    chord = math.dist(xy[0], xy[3])
    assert metrics.track_length(t, xy, 0.0, 3.0) > chord
    # Outside the track's times its ends are held, not extrapolated.
    assert metrics.track_length(t, xy, -5.0, 9.0) == pytest.approx(6.0)
    # One answer: no distance.
    assert metrics.track_length([1.0], [[4.0, 4.0]], 0.0, 2.0) == 0.0


@pytest.mark.parametrize(
    ("t", "xy", "t0", "t1", "message"),
    [
        ([0.0, 1.0], [[0.0, 0.0]], 0.0, 1.0, "differ in length"),
        ([0.0, 1.0], [[0.0, 0.0], [1.0, math.nan]], 0.0, 1.0, "xy"),
        ([0.0, 1.0], [[0.0, 0.0], [1.0, 0.0]], 1.0, 0.0, "after"),
        ([0.0, 1.0], [[0.0, 0.0], [1.0, 0.0]], math.nan, 1.0, "finite"),
        ([0.0, 2.0, 1.0], [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], 0.0, 2.0, r"t\[2\] = 1.0 after"),
        ([0.0, 0.0], [[0.0, 0.0], [1.0, 0.0]], 0.0, 1.0, "must increase"),
        ([], np.zeros((0, 2)), 0.0, 1.0, "empty"),
    ],
)
def test_track_length_rejects_bad_input(t, xy, t0, t1, message):
    with pytest.raises(ValueError, match=message):
        metrics.track_length(t, xy, t0, t1)
