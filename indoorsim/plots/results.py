"""Figures of leaderboard results: error CDFs, estimated tracks, named CDFs, training curves.

* :func:`plot_error_cdfs` — the error CDF of each estimator on one scenario,
  one panel per carrying mode, the legend in its own column (the
  leaderboard's ``<scenario>_cdf.png``).
* :func:`plot_tracks` — small multiples: each estimator's track beside the
  truth on the floor plan, first seed, a panel per estimator and mode, each
  holding its track whole (``<scenario>_tracks.png``).
* :func:`plot_named_cdfs` — CDFs of any named error samples, as the papers'
  reproduced experiments draw them.
* :func:`plot_training_curves` — BP training MSE per epoch (Han2023 Fig. 14).
* :func:`plot_realism_profiles` — real and simulated ‖a‖/‖ω‖ spectra and ‖a‖
  histograms overlaid, one row per carrying mode (``realism_motion.png``).
* :func:`plot_robustness` — the heat map of error ratios, estimator × fault,
  crashes marked (``robustness.png``).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
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


_LINESTYLES = ("-", "--", ":", "-.")


def _estimator_styles(names: Iterable[str]) -> dict[str, dict[str, str]]:
    """Colour and line style of each name: past the palette's length, the styles change."""
    palette = ESTIMATOR_COLOURS
    return {
        n: {
            "color": palette[i % len(palette)],
            "linestyle": _LINESTYLES[(i // len(palette)) % len(_LINESTYLES)],
        }
        for i, n in enumerate(dict.fromkeys(names))
    }


def plot_error_cdfs(evaluations: Sequence[Any]) -> Figure:
    """Error CDFs of several evaluations: one panel per carrying mode, one curve per estimator.

    The legend stands in its own column right of the panels; past the palette's
    eight colours, estimators are told apart by their line style as well.

    Args:
        evaluations: :class:`~indoorsim.benchmark.evaluation.Evaluation` objects of one
            scenario; each curve pools the errors of all its seeds.
    """
    from indoorsim.benchmark.metrics import error_cdf, position_errors

    modes = list(dict.fromkeys(ev.mode for ev in evaluations))
    styles = _estimator_styles(ev.estimator for ev in evaluations)
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
            ax.step(x, f, where="post", label=ev.estimator, **styles[ev.estimator])
        ax.set_title(mode)
        ax.set_xlabel("position error (m)")
        ax.set_xlim(left=0)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("fraction of windows")
    handles = {}
    for ax in axes:
        for line in ax.get_lines():
            handles.setdefault(line.get_label(), line)
    if handles:
        fig.legend(
            list(handles.values()),
            list(handles),
            loc="outside right upper",
            fontsize="small",
            title="estimator",
        )
    fig.suptitle(f"{evaluations[0].scenario}: error CDF over all seeds")
    return fig


# Track panels: width of a panel, and the range of its height over its width.
_TRACK_PANEL_IN = 3.4
_TRACK_ASPECT = (0.25, 1.3)


def _track_limits(
    bounds: tuple[float, float, float, float], walk: Any | None
) -> tuple[tuple[float, float], tuple[float, float]]:
    """Axis limits holding the plan, the truth and the track whole, with a margin."""
    xmin, ymin, xmax, ymax = bounds
    if walk is not None and len(walk):
        xs = np.concatenate([walk["x"].to_numpy(float), walk["true_x"].to_numpy(float)])
        ys = np.concatenate([walk["y"].to_numpy(float), walk["true_y"].to_numpy(float)])
        xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
        if len(xs):
            xmin, xmax = min(xmin, xs.min()), max(xmax, xs.max())
        if len(ys):
            ymin, ymax = min(ymin, ys.min()), max(ymax, ys.max())
    margin = max(1.0, 0.04 * max(xmax - xmin, ymax - ymin))
    return (xmin - margin, xmax + margin), (ymin - margin, ymax + margin)


def plot_tracks(evaluations: Sequence[Any], site: Site) -> Figure:
    """Small multiples of the tracks: a panel per estimator (rows) and carrying mode (columns).

    Each panel shows the floor plan, the true path (black) and that estimator's
    track of the first seed; its axes hold the plan and both tracks whole. A
    track that stays at one point (``start-only``) is drawn as a marker. A panel
    whose estimator did not run on the site says so.
    """
    modes = list(dict.fromkeys(ev.mode for ev in evaluations))
    estimators = list(dict.fromkeys(ev.estimator for ev in evaluations))
    colours = _estimator_colours(estimators)
    found = {(ev.estimator, ev.mode): ev for ev in evaluations}
    bounds = site.plan.bounds
    walks: dict[tuple[str, str], Any] = {}
    limits = {}
    for est in estimators:
        for mode in modes:
            ev = found.get((est, mode))
            walk = ev.walks[0].estimates if ev is not None and ev.walks else None
            walks[est, mode] = walk
            limits[est, mode] = _track_limits(bounds, walk)

    def aspect(key: tuple[str, str]) -> float:
        (x0, x1), (y0, y1) = limits[key]
        return float(np.clip((y1 - y0) / (x1 - x0), *_TRACK_ASPECT))

    heights = [max(aspect((est, mode)) for mode in modes) for est in estimators]
    title_in = 0.45
    fig = agg_figure(
        (
            _TRACK_PANEL_IN * len(modes),
            sum(_TRACK_PANEL_IN * h + title_in for h in heights) + 0.6,
        )
    )
    axes = fig.subplots(
        len(estimators),
        len(modes),
        squeeze=False,
        gridspec_kw={"height_ratios": [_TRACK_PANEL_IN * h + title_in for h in heights]},
    )
    for row, est in zip(axes, estimators, strict=True):
        for ax, mode in zip(row, modes, strict=True):
            draw_plan(ax, site.plan, legend=False)
            walk = walks[est, mode]
            (x0, x1), (y0, y1) = limits[est, mode]
            if walk is None:
                ax.text(
                    0.5, 0.5, "not run on this site", transform=ax.transAxes,
                    ha="center", va="center", fontsize=8, color="0.3",
                )  # fmt: skip
            else:
                ax.plot(walk["true_x"], walk["true_y"], color="black", lw=1.6, label="truth")
                x, y = walk["x"].to_numpy(float), walk["y"].to_numpy(float)
                ax.plot(x, y, color=colours[est], lw=1.2, label=est)
                extent = max(np.ptp(x), np.ptp(y)) if len(x) else 0.0
                if extent < 0.01 * max(x1 - x0, y1 - y0):  # one point: a line would not show
                    ax.plot(
                        x[-1:], y[-1:], ls="none", marker="o", ms=7, color=colours[est],
                        markeredgecolor="black", label=f"{est} (one point)",
                    )  # fmt: skip
            ax.set_xlim(x0, x1)
            ax.set_ylim(y0, y1)
            ax.set_aspect("equal", adjustable="box")
            ax.set_title(f"{est} · {mode}", fontsize=9)
            ax.tick_params(labelsize=7)
            ax.set_xlabel("")
            ax.set_ylabel("")
    fig.suptitle(
        f"{site.name}: estimated track (colour) beside the truth (black), first seed; "
        "axes in metres, each panel holding its track whole"
    )
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


def plot_robustness(panels: Mapping[str, tuple[Any, Any]]) -> Figure:
    """Heat maps of error ratios (faulty / fault-free mean error), one panel per carrying mode.

    Args:
        panels: per mode, a DataFrame of estimators × fault labels (the ratio;
            NaN where the estimator crashed) and a Series of each estimator's
            fault-free mean error (m) on the same index.

    The colour is log2 of the ratio on a diverging scale centred at 1 (no
    change) and clipped at 1/2 and 16; each cell also prints the ratio, and
    a crash is a black cell marked "crash".
    """
    from matplotlib.colors import TwoSlopeNorm

    norm = TwoSlopeNorm(vmin=-1.0, vcenter=0.0, vmax=4.0)
    shapes = [ratios.shape for ratios, _ in panels.values()]
    n_fault = max(c for _, c in shapes)
    heights = [r for r, _ in shapes]
    fig = agg_figure((0.55 * n_fault + 2.8, 0.3 * sum(heights) + 1.0 * len(heights) + 1.6))
    axes = fig.subplots(len(panels), 1, squeeze=False, gridspec_kw={"height_ratios": heights})
    image = None
    for ax, (mode, (ratios, clean_ae)) in zip(axes[:, 0], panels.items(), strict=True):
        values = ratios.to_numpy(dtype=float)
        shown = np.log2(np.clip(values, 0.5, 16.0))
        image = ax.imshow(np.ma.masked_invalid(shown), cmap="RdBu_r", norm=norm, aspect="auto")
        ax.set_facecolor("black")  # masked (crashed) cells
        for (i, j), v in np.ndenumerate(values):
            text = "crash" if not np.isfinite(v) else f"{v:.1f}" if v < 9.95 else f"{v:.0f}"
            dark = not np.isfinite(v) or abs(shown[i, j]) > 2.0
            ax.text(
                j,
                i,
                text,
                ha="center",
                va="center",
                fontsize=6,
                color="white" if dark else "black",
            )
        ax.set_xticks(range(values.shape[1]), list(ratios.columns), rotation=60, ha="right")
        ax.tick_params(labelsize=7)
        labels = [
            f"{e} ({a:.1f} m)" for e, a in zip(ratios.index, np.asarray(clean_ae), strict=True)
        ]
        ax.set_yticks(range(values.shape[0]), labels)
        ax.set_title(
            f"{mode}: error under the fault / fault-free (fault-free mean error)",
            fontsize=8,
            loc="left",
        )
    bar = fig.colorbar(image, ax=list(axes[:, 0]), fraction=0.02, pad=0.01)
    ticks = [-1, 0, 1, 2, 3, 4]
    bar.set_ticks(ticks, labels=[f"{2.0**t:g}×" for t in ticks])
    bar.ax.tick_params(labelsize=7)
    return fig


def plot_sim_to_real(errors: Mapping[str, tuple[Any, Any]]) -> Figure:
    """Each real trace's error against its simulated twins', one panel per estimator.

    Args:
        errors: per estimator, two arrays over the same traces: the error on the real
            trace and the mean error of its twins (m).
    """
    fig = agg_figure((3.2 * len(errors), 3.4))
    axes = fig.subplots(1, len(errors), squeeze=False)[0]
    colours = _estimator_colours(errors)
    for ax, (name, (real, sim)) in zip(axes, errors.items(), strict=True):
        real, sim = np.asarray(real, dtype=float), np.asarray(sim, dtype=float)
        top = 1.1 * float(np.nanmax([*real, *sim, 1.0]))
        ax.plot([0, top], [0, top], color="0.6", lw=0.8, label="real = sim")
        ax.scatter(real, sim, s=14, color=colours[name], zorder=3)
        ax.set(xlim=(0, top), ylim=(0, top), title=name, xlabel="real trace error (m)")
        ax.set_aspect("equal")
    axes[0].set_ylabel("simulated twins' error (m)")
    fig.tight_layout()
    return fig
