"""Figures of leaderboard results: error CDFs, estimated tracks, named CDFs, training curves.

* :func:`plot_error_cdfs` — the error CDF of each estimator on one scenario,
  one panel per carrying mode (the leaderboard's ``<scenario>_cdf.png``).
* :func:`plot_tracks` — each estimator's track beside the truth on the floor
  plan, first seed, one panel per mode (``<scenario>_tracks.png``).
* :func:`plot_named_cdfs` — CDFs of any named error samples, as the papers'
  reproduced experiments draw them.
* :func:`plot_training_curves` — BP training MSE per epoch (Han2023 Fig. 14).
* :func:`plot_realism_profiles` — real and simulated ‖a‖/‖ω‖ spectra and ‖a‖
  histograms overlaid, one row per carrying mode (``realism_motion.png``).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from indoorsim.plots.site import draw_plan
from indoorsim.plots.style import ESTIMATOR_COLOURS, agg_figure

if TYPE_CHECKING:
    from indoorsim.world.site import Site


def _estimator_colours(names: Iterable[str]) -> dict[str, str]:
    """A colour for each name, in order of first appearance."""
    palette = ESTIMATOR_COLOURS
    return {n: palette[i % len(palette)] for i, n in enumerate(dict.fromkeys(names))}


def _panel_row(n: int) -> tuple[Figure, NDArray[np.object_]]:
    """A figure of ``n`` panels side by side, 4.2 inches each, sharing the y axis."""
    fig = agg_figure((4.2 * n, 3.6))
    return fig, fig.subplots(1, n, squeeze=False, sharey=True)[0]


def plot_error_cdfs(evaluations: Sequence[Any]) -> Figure:
    """Error CDFs of several evaluations: one panel per carrying mode, one curve per estimator.

    Args:
        evaluations: :class:`~indoorsim.benchmark.evaluation.Evaluation` objects of one
            scenario; each curve pools the errors of all its seeds.
    """
    from indoorsim.benchmark.metrics import error_cdf, position_errors

    modes = list(dict.fromkeys(ev.mode for ev in evaluations))
    colours = _estimator_colours(ev.estimator for ev in evaluations)
    fig, axes = _panel_row(len(modes))
    for ax, mode in zip(axes, modes, strict=True):
        for ev in (e for e in evaluations if e.mode == mode and e.walks):
            err = np.concatenate(
                [
                    position_errors(w.estimates[["x", "y"]], w.estimates[["true_x", "true_y"]])
                    for w in ev.walks
                ]
            )
            x, f = error_cdf(err)
            ax.step(x, f, where="post", color=colours[ev.estimator], label=ev.estimator)
        ax.set_title(mode)
        ax.set_xlabel("position error (m)")
        ax.set_xlim(left=0)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("fraction of windows")
    axes[0].legend(loc="lower right", fontsize="small")
    fig.suptitle(f"{evaluations[0].scenario}: error CDF over all seeds")
    return fig


def plot_tracks(evaluations: Sequence[Any], site: Site) -> Figure:
    """Estimated tracks beside the truth on the floor plan, first seed, one panel per mode."""
    modes = list(dict.fromkeys(ev.mode for ev in evaluations))
    colours = _estimator_colours(ev.estimator for ev in evaluations)
    xmin, ymin, xmax, ymax = site.plan.bounds
    aspect = (ymax - ymin) / max(xmax - xmin, 1e-3)
    width = 5.5
    fig = agg_figure((width * len(modes), max(3.0, width * aspect) + 1.0))
    axes = fig.subplots(1, len(modes), squeeze=False)[0]
    for ax, mode in zip(axes, modes, strict=True):
        draw_plan(ax, site.plan, legend=False)
        truth_drawn = False
        for ev in (e for e in evaluations if e.mode == mode):
            if not ev.walks:
                continue
            walk = ev.walks[0].estimates
            if not truth_drawn:
                ax.plot(walk["true_x"], walk["true_y"], color="black", lw=2.0, label="truth")
                truth_drawn = True
            ax.plot(walk["x"], walk["y"], color=colours[ev.estimator], lw=1.2, label=ev.estimator)
        ax.set_title(f"{mode} (first seed)")
        ax.set_xlim(xmin - 5, xmax + 5)
        ax.set_ylim(ymin - 5, ymax + 5)
    axes[0].legend(loc="best", fontsize="small")
    fig.suptitle(f"{site.name}: estimated tracks")
    return fig


def plot_named_cdfs(
    panels: dict[str, dict[str, NDArray[np.float64]]], *, xlabel: str, title: str
) -> Figure:
    """Empirical CDFs of named error samples, one panel per key of ``panels``.

    Args:
        panels: panel title → (curve label → 1-D error samples).
        xlabel: the errors' quantity and unit.
        title: the figure's title.
    """
    from indoorsim.benchmark.metrics import error_cdf

    fig, axes = _panel_row(len(panels))
    for ax, (panel, curves) in zip(axes, panels.items(), strict=True):
        colours = _estimator_colours(curves)
        for label, errors in curves.items():
            if len(errors):
                x, f = error_cdf(np.asarray(errors, dtype=float))
                ax.step(x, f, where="post", color=colours[label], label=label)
        ax.set_title(panel)
        ax.set_xlabel(xlabel)
        ax.set_xlim(left=0)
        ax.grid(alpha=0.3)
        ax.legend(loc="lower right", fontsize="small")
    axes[0].set_ylabel("fraction")
    fig.suptitle(title)
    return fig


def plot_training_curves(
    panels: dict[str, dict[str, NDArray[np.float64]]], *, threshold: float | None = None
) -> Figure:
    """Training MSE per epoch (log scale), one panel per key, one curve per network (Fig. 14).

    Args:
        panels: panel title → (network label → (epochs,) MSE).
        threshold: a horizontal reference line (Han2023 counts epochs to MSE < 0.1).
    """
    fig, axes = _panel_row(len(panels))
    for ax, (panel, curves) in zip(axes, panels.items(), strict=True):
        colours = _estimator_colours(curves)
        for label, mse in curves.items():
            ax.semilogy(np.arange(1, len(mse) + 1), mse, color=colours[label], label=label)
        if threshold is not None:
            ax.axhline(threshold, color="0.5", lw=0.8, ls="--")
        ax.set_title(panel)
        ax.set_xlabel("BP epoch")
        ax.grid(alpha=0.3, which="both")
        ax.legend(loc="upper right", fontsize="small")
    axes[0].set_ylabel("training MSE (normalised)")
    fig.suptitle("Convergence of BP, ASO-BP and Tent-ASO-BP (Han2023 Fig. 14)")
    return fig


_REALISM_CURVES = (
    ("accel_psd", "‖a‖ spectrum", "frequency (Hz)", "power ((m/s²)²/Hz)"),
    ("gyro_psd", "‖ω‖ spectrum", "frequency (Hz)", "power ((rad/s)²/Hz)"),
    ("accel_hist", "‖a‖ while walking", "‖a‖ (m/s²)", "density"),
    ("accel_stride", "‖a‖ over a stride", "strides from the stride's largest peak", "‖a‖ (m/s²)"),
)


def plot_realism_profiles(real: Any, sim: Any) -> Figure:
    """Real against simulated motion profiles: a row per carrying mode, a column per curve.

    Args:
        real, sim: tables with columns ``mode``, ``curve``, ``x``, ``y``, ``walks``
            (:func:`indoorsim.benchmark.realism.reference.mean_profiles`).
    """
    modes = list(dict.fromkeys([*sim["mode"], *real["mode"]]))
    fig = agg_figure((4.2 * len(_REALISM_CURVES), 2.6 * len(modes)))
    fig.set_layout_engine("constrained")
    axes = fig.subplots(len(modes), len(_REALISM_CURVES), squeeze=False)
    for row, mode in zip(axes, modes, strict=True):
        for ax, (curve, title, xlabel, ylabel) in zip(row, _REALISM_CURVES, strict=True):
            for table, label, colour in ((real, "real", "#d62728"), (sim, "simulated", "#1f77b4")):
                part = table[(table["mode"] == mode) & (table["curve"] == curve)]
                if part.empty:
                    continue
                walks = int(part["walks"].iloc[0])
                ax.plot(part["x"], part["y"], color=colour, lw=1.2, label=f"{label} ({walks})")
            if curve.endswith("_psd"):
                ax.set_yscale("log")
                ax.set_xlim(0, 20)
            ax.set_title(f"{mode}: {title}", fontsize=9)
            ax.set_xlabel(xlabel, fontsize=8)
            ax.set_ylabel(ylabel, fontsize=8)
            ax.tick_params(labelsize=7)
            if ax.lines:
                ax.legend(fontsize=7)
    return fig
