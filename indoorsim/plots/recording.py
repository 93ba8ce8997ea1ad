"""Figures of one walk: a :class:`~indoorsim.io.recording.Recording`, simulated or a real phone log.

* :func:`plot_recording_streams` stacks the sensor streams over time
  (accelerometer with the true steps, gyroscope, magnetometer, light, WiFi).
* :func:`plot_recording_track` draws the true track on the floor plan,
  coloured by carrying mode.
* :func:`save_recording_plots` writes both as PNG files.
"""

from __future__ import annotations

import itertools
import math
import textwrap
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from numpy.typing import NDArray

from indoorsim.plots.site import draw_plan
from indoorsim.plots.style import (
    AXIS_COLOURS,
    DPI,
    EXTRA_MODE_COLOURS,
    LABEL_BOX,
    LIGHT_TRACE_COLOUR,
    MODE_COLOURS,
    PANEL_HEIGHT_IN,
    TITLE_PT,
    TRACK_LEGEND_IN,
    WAYPOINT_COLOUR,
    agg_figure,
    new_figure,
    save_figures,
)
from indoorsim.scenario.load import bundled_scenarios, load_site
from indoorsim.scenario.schema import ScenarioError

if TYPE_CHECKING:
    import pandas as pd

    from indoorsim.io.recording import Recording
    from indoorsim.world.site import Site

_STRONGEST_APS = 5
# Light gets a log axis when its positive readings span this many decades.
_LIGHT_LOG_DECADES = 2.0


def _mode_colours(modes: Iterable[str]) -> dict[str, str]:
    """A colour for each mode: the built-in ones fixed, others in order of appearance."""
    extra = itertools.cycle(EXTRA_MODE_COLOURS)
    colours: dict[str, str] = {}
    for mode in modes:
        if mode not in colours:
            colours[mode] = MODE_COLOURS.get(mode) or next(extra)
    return colours


def _mode_runs(rec: Recording) -> list[tuple[str, int, int]]:
    """``(mode, first, stop)`` row ranges of the truth stream, one per stretch in one mode.

    Empty for recordings without a ``truth`` stream (real logs).
    """
    if not rec.has_truth or not len(rec.truth):
        return []
    modes = rec.truth["mode"].to_numpy()
    change = np.flatnonzero(modes[1:] != modes[:-1]) + 1
    edges = [0, *change.tolist(), len(modes)]
    return [(str(modes[a]), a, b) for a, b in itertools.pairwise(edges)]


def _mode_text(mode: object) -> str:
    """The manifest's ``mode`` (a name, or ``[[t, name(, params)], ...]``) in a few words."""
    if isinstance(mode, list) and all(isinstance(m, list) and len(m) >= 2 for m in mode):
        # No-break spaces keep "calling (15 s)" together when the title wraps.
        return " → ".join(
            str(name) if i == 0 else f"{name}\u00a0({t:g}\u00a0s)"
            for i, (t, name, *_) in enumerate(mode)
        )
    return str(mode)


def _recording_title(rec: Recording, what: str, *extra: str, width_in: float) -> str:
    """Where the walk comes from; device, seed, duration and ``extra``; the carrying mode.

    Lines are wrapped to fit ``width_in`` inches at the title's font size.
    """
    meta = rec.meta
    source = meta.get("source")
    route = meta.get("route")
    if "scenario" in meta:
        head = str(meta["scenario"])
        if isinstance(route, dict) and "name" in route:
            head += f", route {route['name']}"
    elif isinstance(source, dict) and "file" in source:
        head = f"{source['file']} ({source.get('format', 'real log')})"
        site = meta.get("site")
        if isinstance(site, dict) and site.get("floor_name"):
            head += f", floor {site['floor_name']}"
    else:
        head = "recording"
    details = [f"device {meta['device']}"] if meta.get("device") is not None else []
    if meta.get("seed") is not None:
        details.append(f"seed {meta['seed']}")
    details += [f"{rec.duration:.1f} s", *extra]
    lines = [f"{head} — {what}", " · ".join(details)]
    if meta.get("mode") is not None:
        lines.append(f"mode {_mode_text(meta['mode'])}")
    # About 0.6 em per character in the default sans-serif font.
    chars = max(int(width_in * 72 / (0.6 * TITLE_PT)), 30)
    return "\n".join(textwrap.fill(line, chars, break_on_hyphens=False) for line in lines)


def _draw_vector(ax: Axes, df: pd.DataFrame, *, norm: str | None) -> None:
    t = df.index.to_numpy()
    for axis in "xyz":
        ax.plot(t, df[axis].to_numpy(), color=AXIS_COLOURS[axis], linewidth=0.6, label=axis)
    if norm is not None:
        magnitude = np.linalg.norm(df[["x", "y", "z"]].to_numpy(dtype=float), axis=1)
        ax.plot(t, magnitude, color="black", linewidth=0.9, label=norm)


def _draw_light(ax: Axes, light: pd.DataFrame, t_end: float) -> None:
    # The light sensor reports on change: each reading holds until the next
    # one, and the last until the recording ends.
    t = np.append(light.index.to_numpy(), t_end)
    lux = light["lux"].to_numpy(dtype=float)
    ax.plot(
        t,
        np.append(lux, lux[-1]),
        drawstyle="steps-post",
        color=LIGHT_TRACE_COLOUR,
        linewidth=0.9,
        label="lux",
    )
    positive = lux[lux > 0]
    if positive.size and positive.max() >= positive.min() * 10**_LIGHT_LOG_DECADES:
        # A pocket reads ~1 lux, a lit corridor hundreds: on a linear axis the
        # dark stretches would be a flat line. Symlog keeps zero readings visible.
        ax.set_yscale("symlog", linthresh=10 ** math.floor(math.log10(positive.min())))
    ax.set_ylim(bottom=0.0)


def _scans(wifi: pd.DataFrame) -> pd.DataFrame:
    """RSS by scan (rows, the scan's ``t``) and BSSID (columns); NaN where a scan missed an AP."""
    return wifi.reset_index().pivot_table(index="t", columns="bssid", values="rss", aggfunc="max")


def _draw_wifi_rss(ax: Axes, wifi: pd.DataFrame, _t_end: float) -> None:
    scans = _scans(wifi)
    # Rank APs by mean RSS over every scan, a scan that missed one counting as
    # the weakest RSS heard: strong and reliably heard APs come first.
    score = scans.fillna(float(wifi["rss"].min())).mean()
    strongest = score.sort_values(ascending=False, kind="stable").index[:_STRONGEST_APS]
    t = scans.index.to_numpy()
    for bssid in strongest:
        ax.plot(t, scans[bssid].to_numpy(), marker="o", markersize=3, linewidth=0.9, label=bssid)


def _draw_wifi_count(ax: Axes, wifi: pd.DataFrame, _t_end: float) -> None:
    heard = _scans(wifi).notna().sum(axis=1)
    t = heard.index.to_numpy()
    width = 0.25 * float(np.median(np.diff(t))) if len(t) > 1 else 0.5
    ax.bar(t, heard.to_numpy(), width=width, color="#999999", label="APs heard")
    ax.set_ylim(bottom=0)


@dataclass(frozen=True)
class _Panel:
    """One panel of :func:`plot_recording_streams`.

    Attributes:
        stream: the stream it draws; the panel is left out without it.
        label: the y-axis label.
        draw: draws the stream into the axes, given the recording's last time (s).
        height: relative to the other panels.
    """

    stream: str
    label: str
    draw: Callable[[Axes, pd.DataFrame, float], None]
    height: float = 1.0


_PANELS: tuple[_Panel, ...] = (
    _Panel("accel", "accel (m/s²)", lambda ax, df, _: _draw_vector(ax, df, norm="|a|")),
    _Panel("gyro", "gyro (rad/s)", lambda ax, df, _: _draw_vector(ax, df, norm=None)),
    _Panel("mag", "mag (µT)", lambda ax, df, _: _draw_vector(ax, df, norm="|B|")),
    _Panel("light", "light (lux)", _draw_light),
    _Panel("wifi", "WiFi RSS (dBm)", _draw_wifi_rss),
    _Panel("wifi", "APs per scan", _draw_wifi_count, height=0.55),
)
"""The panels of :func:`plot_recording_streams`, top to bottom."""


def _has_rows(rec: Recording, name: str) -> bool:
    return name in rec.streams and len(rec.streams[name]) > 0


def plot_recording_streams(rec: Recording) -> Figure:
    """The sensor streams of one walk, stacked over a shared time axis.

    Panels, each only when the recording has that stream: accelerometer
    (x, y, z and |a|, with the true steps as thin vertical lines when a
    ``steps`` stream exists), gyroscope (x, y, z), magnetometer (x, y, z and
    |B|), light (lux as reported, held until the next report; symlog axis when
    the readings span two decades or more), WiFi RSS of the five strongest APs
    at each scan (mean RSS over all scans, a miss counting as the weakest RSS
    heard) and the number of APs each scan heard. When the phone changes
    carrying mode during the walk, each mode's stretch is shaded in its
    colour (:data:`MODE_COLOURS`).

    Args:
        rec: a simulated walk or a real phone log.

    Returns:
        A free-standing figure (not registered with ``pyplot``).

    Raises:
        ValueError: the recording has none of the plotted streams.
    """
    panels = [p for p in _PANELS if _has_rows(rec, p.stream)]
    if not panels:
        wanted = ", ".join(dict.fromkeys(p.stream for p in _PANELS))
        have = ", ".join(rec.streams) or "none"
        raise ValueError(f"nothing to plot: the recording has none of {wanted} (it has: {have})")
    heights = [p.height for p in panels]
    fig = agg_figure((12.0, 1.1 + PANEL_HEIGHT_IN * sum(heights)))
    axes = fig.subplots(
        len(panels), 1, sharex=True, squeeze=False, gridspec_kw={"height_ratios": heights}
    )[:, 0]
    spans = [(df.index[0], df.index[-1]) for df in rec.streams.values() if len(df)]
    t_start, t_end = min(a for a, _ in spans), max(b for _, b in spans)
    runs = _mode_runs(rec)
    colours = _mode_colours(mode for mode, _, _ in runs)
    t_truth = rec.truth.index.to_numpy() if runs else np.zeros(0)
    for ax, panel in zip(axes, panels, strict=True):
        panel.draw(ax, rec.streams[panel.stream], t_end)
        if panel.stream == "accel" and _has_rows(rec, "steps"):
            ax.vlines(
                rec.steps.index.to_numpy(),
                0.0,
                1.0,
                transform=ax.get_xaxis_transform(),
                color="#555555",
                linewidth=0.4,
                alpha=0.7,
                zorder=0.5,
                label=f"true steps ({len(rec.steps)})",
            )
        if len(runs) > 1:
            for mode, first, stop in runs:
                end = t_truth[stop] if stop < len(t_truth) else t_truth[-1]
                ax.axvspan(t_truth[first], end, color=colours[mode], alpha=0.08, linewidth=0)
        ax.set_ylabel(panel.label, fontsize=9)
        ax.tick_params(labelsize=8)
        ax.grid(alpha=0.3, linewidth=0.5)
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=7, frameon=False)
    axes[0].set_xlim(t_start, t_end)
    axes[-1].set_xlabel("t (s)")
    if len(runs) > 1:
        fig.legend(
            handles=[Patch(color=c, alpha=0.3, label=m) for m, c in colours.items()],
            title="carrying mode (shaded)",
            loc="outside lower center",
            ncols=len(colours),
            fontsize=8,
            title_fontsize=8,
            frameon=False,
        )
    fig.suptitle(
        _recording_title(rec, "sensor streams", width_in=fig.get_figwidth()), fontsize=TITLE_PT
    )
    return fig


def _scenario_site(name: object) -> Site | None:
    """The bundled scenario a recording's manifest names, as a Site; None if there is none.

    Bundled scenarios are named as their files, so the manifest's name is the key.
    """
    bundled = bundled_scenarios()
    if not isinstance(name, str) or name not in bundled:
        return None
    try:
        return load_site(name)
    except ScenarioError:
        return None


def _visits(
    xy: NDArray[np.float64], t: NDArray[np.float64], within: float
) -> list[tuple[NDArray[np.float64], list[float]]]:
    """Points of a path with the times they were visited; points closer than ``within`` merge."""
    spots: list[tuple[NDArray[np.float64], list[float]]] = []
    for point, when in zip(xy, t, strict=True):
        for spot, times in spots:
            if np.linalg.norm(point - spot) <= within:
                times.append(float(when))
                break
        else:
            spots.append((point, [float(when)]))
    return spots


def _path_length(xy: NDArray[np.float64]) -> float:
    return float(np.linalg.norm(np.diff(xy, axis=0), axis=1).sum())


def plot_recording_track(rec: Recording, site: Site | None = None) -> Figure:
    """The true track of one walk, on the floor plan when the building is known.

    Simulated walks draw the phone's true position (``truth`` x, y) coloured
    by carrying mode, a diamond where the mode changes, dots at the true steps
    and the planned route dashed; real logs draw their surveyed ``waypoints``
    joined by straight lines (their only truth). A circle marks the start, a
    square the end.

    Args:
        rec: a simulated walk or a real phone log.
        site: the building to draw underneath. When omitted, the bundled
            scenario named by ``rec.meta["scenario"]`` if there is one that
            loads; otherwise the track is drawn on plain axes.

    Returns:
        A free-standing figure (not registered with ``pyplot``).

    Raises:
        MissingStreamError: the recording has neither ``truth`` nor ``waypoints``.
        ValueError: that stream has no rows.
    """
    positions = rec.true_positions()
    if positions.empty:
        raise ValueError("nothing to plot: the recording's true positions are empty")
    if site is None:
        site = _scenario_site(rec.meta.get("scenario"))
    xy = positions[["x", "y"]].to_numpy(dtype=float)
    t = positions.index.to_numpy()
    route = rec.meta.get("route")
    planned = (
        np.asarray(route["points"], dtype=float)
        if isinstance(route, dict) and route.get("points")
        else None
    )
    if site is not None:
        fig, ax = new_figure(site.plan.bounds, side_in=TRACK_LEGEND_IN)
        handles = draw_plan(
            ax, site.plan, obstacle_kinds=[o.kind for o in site.scenario.obstacles], legend=False
        )
    else:
        shown = xy if planned is None else np.vstack([xy, planned])
        (xmin, ymin), (xmax, ymax) = shown.min(axis=0), shown.max(axis=0)
        fig, ax = new_figure((xmin, ymin, xmax, ymax), side_in=TRACK_LEGEND_IN)
        # No plan to keep in shape: the view, not the axes box, absorbs the aspect.
        ax.set_aspect("equal", adjustable="datalim")
        ax.margins(0.08)
        ax.grid(alpha=0.3, linewidth=0.5)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        handles = []
    if planned is not None:
        (line,) = ax.plot(
            planned[:, 0],
            planned[:, 1],
            linestyle="--",
            color="#777777",
            linewidth=1.0,
            zorder=3,
            label="planned route",
        )
        handles.append(line)
    runs = _mode_runs(rec)
    if runs:
        colours = _mode_colours(mode for mode, _, _ in runs)
        drawn: set[str] = set()
        for mode, first, stop in runs:
            # Each stretch runs on to the next one's first point, so the track has no gaps.
            (line,) = ax.plot(
                xy[first : stop + 1, 0],
                xy[first : stop + 1, 1],
                color=colours[mode],
                linewidth=1.8,
                solid_capstyle="round",
                zorder=4,
                label=mode,
            )
            if mode not in drawn:
                handles.append(line)
                drawn.add(mode)
            if first > 0:
                ax.plot(
                    *xy[first],
                    marker="D",
                    markersize=7,
                    markerfacecolor=colours[mode],
                    markeredgecolor="black",
                    zorder=5,
                )
                ax.annotate(
                    f"{mode} at {t[first]:.1f} s",
                    tuple(xy[first]),
                    xytext=(7, -12),
                    textcoords="offset points",
                    fontsize=8,
                    color=colours[mode],
                    fontweight="bold",
                    zorder=6,
                    bbox=LABEL_BOX,
                )
        if _has_rows(rec, "steps"):
            t_steps = rec.steps.index.to_numpy()
            at = np.column_stack([np.interp(t_steps, t, xy[:, i]) for i in range(2)])
            handles.append(
                ax.scatter(
                    at[:, 0],
                    at[:, 1],
                    s=6,
                    color="black",
                    linewidth=0,
                    zorder=4.5,
                    label=f"true steps ({len(t_steps)})",
                )
            )
        # No-break spaces keep the length in one piece when the title wraps.
        length = f"{_path_length(xy):.1f}\u00a0m\u00a0walked"
    else:
        (line,) = ax.plot(
            xy[:, 0],
            xy[:, 1],
            marker="o",
            markersize=4,
            color=WAYPOINT_COLOUR,
            linewidth=1.5,
            zorder=4,
            label=f"waypoints ({len(xy)}), straight between",
        )
        handles.append(line)
        # A surveyed path often doubles back: the times give the order, and a
        # spot visited twice gets one label with both times.
        for point, times in _visits(xy, t, within=0.02 * float(np.ptp(xy, axis=0).max())):
            ax.annotate(
                ", ".join(f"{when:.1f}" for when in times) + " s",
                tuple(point),
                xytext=(5, 5),
                textcoords="offset points",
                fontsize=7,
                color=WAYPOINT_COLOUR,
                zorder=6,
                bbox=LABEL_BOX,
            )
        length = f"{_path_length(xy):.1f}\u00a0m\u00a0between\u00a0waypoints"
    for k, marker, face, what in ((0, "o", "white", "start"), (-1, "s", "black", "end")):
        (end,) = ax.plot(
            *xy[k],
            linestyle="none",
            marker=marker,
            markersize=9 if marker == "o" else 7,
            markerfacecolor=face,
            markeredgecolor="black",
            markeredgewidth=1.5,
            zorder=6,
            label=f"{what} ({t[k]:.1f} s)",
        )
        handles.append(end)
    # Over the axes only (the width new_figure gave them): the legend takes the right.
    width_in = fig.get_figwidth() - TRACK_LEGEND_IN - 1.0
    ax.set_title(_recording_title(rec, "true track", length, width_in=width_in), fontsize=TITLE_PT)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
    return fig


def save_recording_plots(
    rec: Recording,
    out_dir: str | Path,
    name: str,
    *,
    site: Site | None = None,
    dpi: int = DPI,
) -> list[Path]:
    """Write a walk's figures as PNG files.

    Files: ``<name>_streams.png`` (:func:`plot_recording_streams`) when the
    recording has a sensor stream, and ``<name>_track.png``
    (:func:`plot_recording_track`) when it has true positions (``truth`` or
    ``waypoints``).

    Args:
        rec: a simulated walk or a real phone log.
        out_dir: folder to write into; created if missing.
        name: file name prefix, e.g. the recording's folder name.
        site: the building under the track; see :func:`plot_recording_track`.
        dpi: resolution of the PNG files.

    Returns:
        The written paths, streams first.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {}
    if any(_has_rows(rec, panel.stream) for panel in _PANELS):
        figures["streams"] = plot_recording_streams(rec)
    if _has_rows(rec, "truth") or _has_rows(rec, "waypoints"):
        figures["track"] = plot_recording_track(rec, site)
    return save_figures(figures, out, name, dpi)
