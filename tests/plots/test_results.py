"""Result figures: error CDFs and tracks of evaluations, named CDFs, training curves."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.evaluation import Evaluation, WalkResult
from indoorsim.plots.results import (
    plot_error_cdfs,
    plot_named_cdfs,
    plot_realism_profiles,
    plot_tracks,
    plot_training_curves,
)
from indoorsim.plots.style import ESTIMATOR_COLOURS
from indoorsim.world.site import Site


def _walk(seed: int, errors: list[float]) -> WalkResult:
    """A walk along y = 2 whose estimates sit ``errors`` metres north of the truth."""
    t = np.arange(len(errors), dtype=float)
    true_x, true_y = 1.0 + t, np.full(len(t), 2.0)
    estimates = pd.DataFrame(
        {"t": t, "x": true_x, "y": true_y + errors, "true_x": true_x, "true_y": true_y}
    )
    return WalkResult(seed=seed, estimates=estimates, metrics={})


def _evaluation(estimator: str, mode: str, *walks: WalkResult) -> Evaluation:
    return Evaluation(
        estimator=estimator, scenario="test-office", mode=mode, config={}, walks=list(walks)
    )


@pytest.fixture
def evaluations() -> list[Evaluation]:
    return [
        _evaluation("good", "handheld", _walk(0, [0.5, 0.25]), _walk(1, [1.0, 0.5])),
        _evaluation("bad", "handheld", _walk(0, [2.0, 3.0])),
        _evaluation("good", "pocketed", _walk(0, [1.5, 1.5, 0.5])),
        _evaluation("bad", "pocketed"),  # not run on this site: no walks
    ]


def test_error_cdfs_have_a_panel_per_mode_and_pool_every_seed(evaluations):
    before = plt.get_fignums()
    fig = plot_error_cdfs(evaluations)
    assert plt.get_fignums() == before
    assert [ax.get_title() for ax in fig.axes] == ["handheld", "pocketed"]
    curves = {
        (ax.get_title(), line.get_label()): line for ax in fig.axes for line in ax.get_lines()
    }
    assert set(curves) == {("handheld", "good"), ("handheld", "bad"), ("pocketed", "good")}
    # F(x) = #{e ≤ x} / N over the errors of both seeds.
    good = curves["handheld", "good"]
    np.testing.assert_allclose(good.get_xdata(), [0.25, 0.5, 1.0])
    np.testing.assert_allclose(good.get_ydata(), [0.25, 0.75, 1.0])
    np.testing.assert_allclose(curves["pocketed", "good"].get_ydata(), [1 / 3, 1.0])
    assert good.get_color() != curves["handheld", "bad"].get_color()
    assert "test-office" in fig.texts[0].get_text()


def test_error_cdfs_legend_stands_outside_the_panels_once_per_estimator(evaluations):
    fig = plot_error_cdfs(evaluations)
    assert all(ax.get_legend() is None for ax in fig.axes)
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == ["good", "bad"]
    fig.canvas.draw()
    box = legend.get_window_extent()
    assert all(box.x0 >= ax.get_window_extent().x1 for ax in fig.axes)


def test_error_cdfs_tell_estimators_apart_past_the_palette():
    names = [f"e{i}" for i in range(len(ESTIMATOR_COLOURS) + 2)]
    fig = plot_error_cdfs([_evaluation(n, "handheld", _walk(0, [1.0, 2.0])) for n in names])
    (ax,) = fig.axes
    styles = {(line.get_color(), line.get_linestyle()) for line in ax.get_lines()}
    assert len(styles) == len(names)


def _tracks(fig) -> dict[str, object]:
    return {ax.get_title(): ax for ax in fig.axes}


def test_tracks_are_a_panel_per_estimator_and_mode(site: Site, evaluations):
    fig = plot_tracks(evaluations, site)
    assert list(_tracks(fig)) == [
        "good · handheld",
        "good · pocketed",
        "bad · handheld",
        "bad · pocketed",
    ]
    panels = _tracks(fig)
    handheld = panels["good · handheld"]
    lines = {line.get_label(): line for line in handheld.get_lines()}
    assert list(lines) == ["truth", "good"]
    first = evaluations[0].walks[0].estimates
    np.testing.assert_array_equal(lines["good"].get_ydata(), first["y"])
    np.testing.assert_array_equal(lines["truth"].get_xdata(), first["true_x"])
    assert handheld.patches  # the floor plan underneath
    # "bad" has no walks in pocketed: the plan and a note, no track.
    empty = panels["bad · pocketed"]
    assert empty.patches and not empty.get_lines()
    assert "not run" in empty.texts[0].get_text()


def _inside(ax, x, y) -> bool:
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    x, y = np.asarray(x, float), np.asarray(y, float)
    return bool(((x0 <= x) & (x <= x1) & (y0 <= y) & (y <= y1)).all())


def test_every_track_lies_whole_inside_its_panel(site: Site):
    """A track far outside the plan widens its own panel; the plan stays in view too."""
    t = np.arange(4, dtype=float)
    lost = pd.DataFrame(
        {
            "t": t,
            "x": [1.0, 30.0, 60.0, 90.0],
            "y": [2.0, -20.0, -40.0, -55.0],
            "true_x": 1.0 + t,
            "true_y": np.full(4, 2.0),
        }
    )
    evaluations = [
        _evaluation("lost", "handheld", WalkResult(seed=0, estimates=lost, metrics={})),
        _evaluation("good", "handheld", _walk(0, [0.5, 0.25])),
    ]
    fig = plot_tracks(evaluations, site)
    fig.canvas.draw()  # limits as drawn, after the aspect is applied
    xmin, ymin, xmax, ymax = site.plan.bounds
    for ax in fig.axes:
        lines = ax.get_lines()
        assert lines
        for line in lines:
            assert _inside(ax, line.get_xdata(), line.get_ydata()), ax.get_title()
        assert _inside(ax, [xmin, xmax], [ymin, ymax])
    lost_ax, good_ax = fig.axes
    assert np.ptp(lost_ax.get_xlim()) > np.ptp(good_ax.get_xlim())  # each panel its own limits


def test_a_track_at_one_point_is_drawn_as_a_marker(site: Site):
    t = np.arange(5, dtype=float)
    still = pd.DataFrame({"t": t, "x": 1.0, "y": 2.0, "true_x": 1.0 + t, "true_y": np.full(5, 2.0)})
    fig = plot_tracks(
        [_evaluation("start-only", "handheld", WalkResult(seed=0, estimates=still, metrics={}))],
        site,
    )
    (ax,) = fig.axes
    markers = [line for line in ax.get_lines() if line.get_marker() not in (None, "None", "")]
    assert len(markers) == 1
    np.testing.assert_array_equal(markers[0].get_xydata(), [[1.0, 2.0]])
    assert markers[0].get_markersize() >= 5
    assert _inside(ax, [1.0], [2.0])
    # A moving track has no marker.
    fig = plot_tracks([_evaluation("good", "handheld", _walk(0, [0.5, 0.25]))], site)
    assert all(line.get_marker() in (None, "None", "") for line in fig.axes[0].get_lines())


def test_named_cdfs_skip_empty_samples():
    fig = plot_named_cdfs(
        {"left": {"a": np.array([2.0, 1.0]), "none": np.array([])}, "right": {"b": [0.5]}},
        xlabel="error (m)",
        title="two panels",
    )
    left, right = fig.axes
    assert (left.get_title(), right.get_title()) == ("left", "right")
    ((line,),) = [left.get_lines()]
    assert line.get_label() == "a"
    np.testing.assert_allclose(line.get_ydata(), [0.5, 1.0])
    assert [line.get_label() for line in right.get_lines()] == ["b"]
    assert left.get_xlabel() == "error (m)"
    assert fig.texts[0].get_text() == "two panels"


@pytest.mark.parametrize("threshold", [None, 0.1])
def test_training_curves_plot_mse_per_epoch_on_a_log_axis(threshold):
    mse = np.array([1.0, 0.3, 0.05])
    fig = plot_training_curves({"run": {"bp": mse}}, threshold=threshold)
    (ax,) = fig.axes
    assert ax.get_yscale() == "log"
    curve = next(line for line in ax.get_lines() if line.get_label() == "bp")
    np.testing.assert_array_equal(curve.get_xdata(), [1, 2, 3])
    np.testing.assert_array_equal(curve.get_ydata(), mse)
    references = [line for line in ax.get_lines() if line is not curve]
    assert [tuple(line.get_ydata()) for line in references] == (
        [] if threshold is None else [(threshold, threshold)]
    )


def test_realism_profiles_put_real_beside_simulated_per_mode_and_curve():
    x = np.linspace(0, 25, 11)

    def table(modes: list[str], curves: list[str], walks: int) -> pd.DataFrame:
        return pd.DataFrame(
            [
                {"mode": m, "curve": c, "x": xi, "y": 1.0 + xi, "walks": walks}
                for m in modes
                for c in curves
                for xi in x
            ]
        )

    real = table(["handheld"], ["accel_psd", "accel_hist"], 3)
    curves = ["accel_psd", "gyro_psd", "accel_hist", "accel_stride"]
    sim = table(["handheld", "pocketed"], curves, 2)
    fig = plot_realism_profiles(real, sim)
    assert len(fig.axes) == 8  # two modes × four curves
    handheld_psd = fig.axes[0]
    assert handheld_psd.get_yscale() == "log"
    assert [line.get_label() for line in handheld_psd.get_lines()] == ["real (3)", "simulated (2)"]
    assert fig.axes[3].get_yscale() == "linear"  # the stride profile
    pocket_gyro = fig.axes[5]
    assert [line.get_label() for line in pocket_gyro.get_lines()] == ["simulated (2)"]
