"""Han2023's dual-resolution fingerprint library by closed forms on synthetic surveys."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import indoorsim
from indoorsim.benchmark.evaluation import site_context
from indoorsim.estimators.fingerprint.library import FEATURES, FingerprintLibrary

SPACING = 1.2  # the paper's survey grid, m


class LPlan:
    """An L-shaped floor: x ∈ [0, 12], y ∈ [0, 3.6], plus x ∈ [0, 3.6], y ∈ [3.6, 9.6]."""

    bounds = (-0.2, -0.2, 12.2, 9.8)  # with the walls

    @staticmethod
    def is_walkable(points: np.ndarray) -> np.ndarray:
        x, y = np.asarray(points, dtype=float).T
        inside = lambda lo, hi, v: (v > lo) & (v < hi)  # noqa: E731
        return (inside(0, 12, x) & inside(0, 3.6, y)) | (inside(0, 3.6, x) & inside(0, 9.6, y))


def survey(fields) -> pd.DataFrame:
    """A grid survey of the L plan at 1.2 m whose features are ``fields(x, y)`` → 4 arrays."""
    xs = np.arange(0.6, 12.0, SPACING)
    ys = np.arange(0.6, 9.6, SPACING)
    gx, gy = (a.ravel() for a in np.meshgrid(xs, ys))
    keep = LPlan.is_walkable(np.column_stack([gx, gy]))
    x, y = gx[keep], gy[keep]
    mx, my, mz, lux = fields(x, y)
    return pd.DataFrame({"x": x, "y": y, "mag_x": mx, "mag_y": my, "mag_z": mz, "lux": lux})


def bumpy(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, ...]:
    """Smooth but strongly non-linear fields (anomalies of a few µT, light peaks every 5 m)."""
    return (
        3.0 + 5.0 * np.sin(x) * np.cos(0.7 * y),
        -30.0 + 4.0 * np.cos(1.3 * x + 0.2 * y),
        -40.0 + 6.0 * np.exp(-((x - 5.0) ** 2 + (y - 2.0) ** 2) / 4.0),
        200.0 + 150.0 * np.cos(2 * np.pi * x / 5.0) + 20.0 * np.sin(y),
    )


def linear(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, ...]:
    return 1.0 + 2.0 * x - y, -30.0 + 0.5 * y, -40.0 - x + 3.0 * y, 100.0 + 10.0 * x + 4.0 * y


SURVEY_COLS = ["mag_x", "mag_y", "mag_z", "lux"]


def test_reproduces_the_surveyed_points_at_zero_smoothing() -> None:
    table = survey(bumpy)
    lib = FingerprintLibrary().fit(table, LPlan())
    xy = table[["x", "y"]].to_numpy()
    expected = table[SURVEY_COLS].to_numpy()
    np.testing.assert_allclose(lib.features_at(xy), expected, rtol=1e-9, atol=1e-9)
    # The grids are anchored at the survey: every surveyed point is a library row.
    rounded = {"x": 9, "y": 9}
    merged = table.round(rounded).merge(lib.table.round(rounded), on=["x", "y"])
    assert len(merged) == len(table)
    np.testing.assert_allclose(merged[list(FEATURES)], merged[SURVEY_COLS], rtol=1e-9, atol=1e-9)


def test_smoothing_stops_reproducing_the_survey() -> None:
    table = survey(bumpy)
    lib = FingerprintLibrary(smoothing=10.0).fit(table, LPlan())
    xy = table[["x", "y"]].to_numpy()
    assert np.abs(lib.features_at(xy) - table[SURVEY_COLS].to_numpy()).max() > 0.1


def test_a_linear_field_is_interpolated_exactly() -> None:
    lib = FingerprintLibrary().fit(survey(linear), LPlan())
    expected = np.column_stack(linear(lib.table["x"].to_numpy(), lib.table["y"].to_numpy()))
    np.testing.assert_allclose(lib.table[list(FEATURES)], expected, rtol=1e-9, atol=1e-8)
    # Anywhere, too (the light grid extrapolates linearly beyond its edge).
    pts = np.random.default_rng(0).uniform([0.2, 0.2], [3.4, 9.4], (50, 2))
    np.testing.assert_allclose(lib.features_at(pts), np.column_stack(linear(*pts.T)), atol=1e-8)


@pytest.mark.parametrize(("mag_res", "light_res"), [(0.3, 0.6), (0.4, 0.8), (0.3, 1.2)])
def test_the_two_resolutions_are_honoured(mag_res: float, light_res: float) -> None:
    table = survey(bumpy)
    lib = FingerprintLibrary(mag_resolution=mag_res, light_resolution=light_res).fit(table, LPlan())
    pts = lib.table[["x", "y"]].to_numpy()
    # The library is the walkable magnetic grid, anchored at the survey's corner.
    assert LPlan.is_walkable(pts).all()
    for axis, start in ((0, table["x"].min()), (1, table["y"].min())):
        k = (pts[:, axis] - start) / mag_res
        np.testing.assert_allclose(k, np.round(k), atol=1e-9)
        np.testing.assert_allclose(np.diff(np.unique(pts[:, axis].round(9))), mag_res, atol=1e-9)
    np.testing.assert_allclose(np.diff(lib.light_grid_x), light_res, atol=1e-9)
    np.testing.assert_allclose(np.diff(lib.light_grid_y), light_res, atol=1e-9)
    # Denser than the survey: every walkable node within the survey's hull.
    assert len(lib.table) > (SPACING / mag_res) ** 2 * len(table) * 0.8
    # The magnetic columns are the RBF at each library point; the light column
    # is bilinear between light-grid nodes: exactly the mean of the two nodes
    # a point lies halfway between.
    mid_x = lib.light_grid_x[:-1] + light_res / 2
    on_row = np.isclose(pts[:, 1], lib.light_grid_y[1]) & np.isin(
        pts[:, 0].round(9), mid_x.round(9)
    )
    assert on_row.any()
    i = np.searchsorted(lib.light_grid_x, pts[on_row, 0]) - 1
    node_mean = (lib.light_grid[i, 1] + lib.light_grid[i + 1, 1]) / 2
    np.testing.assert_allclose(lib.table.loc[on_row, "L"], node_mean, rtol=1e-12)


def test_a_coarse_light_grid_blurs_the_light_but_not_the_field() -> None:
    table = survey(bumpy)
    fine = FingerprintLibrary(mag_resolution=0.3, light_resolution=0.3).fit(table, LPlan())
    coarse = FingerprintLibrary(mag_resolution=0.3, light_resolution=1.2).fit(table, LPlan())
    pd.testing.assert_frame_equal(fine.table[["x", "y"]], coarse.table[["x", "y"]])
    mag = ["Mx", "My", "Mz"]
    np.testing.assert_allclose(fine.table[mag], coarse.table[mag], rtol=1e-12)
    assert np.abs(fine.table["L"] - coarse.table["L"]).max() > 1.0


def test_points_given_as_an_array_are_the_library() -> None:
    table = survey(bumpy)
    pts = np.array([[1.0, 1.0], [2.5, 3.0], [3.0, 8.0]])
    lib = FingerprintLibrary().fit(table, pts)
    np.testing.assert_array_equal(lib.table[["x", "y"]], pts)
    np.testing.assert_allclose(lib.table[list(FEATURES)], lib.features_at(pts))


def test_nan_light_rows_are_left_out_of_the_light_only() -> None:
    table = survey(linear)
    table.loc[3, "lux"] = np.nan
    lib = FingerprintLibrary().fit(table, LPlan())
    assert np.isfinite(lib.table[list(FEATURES)].to_numpy()).all()
    np.testing.assert_allclose(
        lib.features_at(table.loc[[3], ["x", "y"]].to_numpy())[0],
        np.array(linear(table.loc[3, "x"], table.loc[3, "y"])),
        atol=1e-8,
    )


def test_holdout_splits_random_library_points() -> None:
    lib = FingerprintLibrary().fit(survey(bumpy), LPlan())
    train, test = lib.holdout(80, np.random.default_rng(1))
    assert len(test) == 80 and len(train) == len(lib.table) - 80
    both = pd.concat([train, test]).sort_values(["x", "y"]).reset_index(drop=True)
    pd.testing.assert_frame_equal(both, lib.table.sort_values(["x", "y"]).reset_index(drop=True))
    again, _ = lib.holdout(80, np.random.default_rng(1))
    pd.testing.assert_frame_equal(train, again)
    other, _ = lib.holdout(80, np.random.default_rng(2))
    assert not train.equals(other)


def test_errors_are_clear() -> None:
    with pytest.raises(ValueError, match="resolutions must be positive"):
        FingerprintLibrary(mag_resolution=0.0)
    with pytest.raises(RuntimeError, match="not fitted"):
        FingerprintLibrary().features_at([[0.0, 0.0]])
    with pytest.raises(ValueError, match="lacks columns"):
        FingerprintLibrary().fit(pd.DataFrame({"x": [0.0], "y": [0.0]}), LPlan())
    with pytest.raises(ValueError, match=r"\(M, 2\)"):
        FingerprintLibrary().fit(survey(linear), np.zeros(3))
    lib = FingerprintLibrary().fit(survey(linear), LPlan())
    with pytest.raises(ValueError, match="cannot hold out"):
        lib.holdout(len(lib.table) + 1, np.random.default_rng(0))


def test_on_a_surveyed_scenario() -> None:
    # The real pieces: a scenario's floor plan and its simulated grid survey.
    ctx = site_context(indoorsim.load_site("han2023_corridor"), device="ideal")
    table = ctx.fingerprints["grid"]["grid"]
    lib = FingerprintLibrary().fit(table, ctx.plan)
    assert ctx.plan.is_walkable(lib.table[["x", "y"]].to_numpy()).all()
    assert len(lib.table) > 10 * len(table)
    np.testing.assert_allclose(
        lib.features_at(table[["x", "y"]].to_numpy()),
        table[SURVEY_COLS].to_numpy(),
        rtol=1e-7,
        atol=1e-7,
    )
