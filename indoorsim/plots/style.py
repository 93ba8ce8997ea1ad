"""The look every figure shares: colours, marker and figure sizes, free-standing figures, PNG files.

Colours are keyed by what they show (wall material, kind of magnetic source,
carrying mode) so that a material or a mode looks the same in every figure.
Every figure is a :class:`matplotlib.figure.Figure` on its own Agg canvas
(:func:`agg_figure`): nothing is registered with ``pyplot``, so plotting many
sites in one process (or in a worker) leaves no figures behind and never
needs a display.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path

from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

MATERIAL_COLOURS: dict[str, str] = {
    "concrete": "#5b5b5b",
    "brick": "#a0522d",
    "drywall": "#c9ad7f",
    "glass": "#6cc3e8",
    "wood": "#8b5a2b",
    "metal": "#2f3f52",
    "metal_door": "#47617d",
}
"""Fill colour of each wall material; materials added later fall back to grey."""

SOURCE_COLOURS: dict[str, str] = {
    "pillar": "#d62728",
    "rebar": "#7f7f7f",
    "obstacle": "#ff7f0e",
    "dipole": "#9467bd",
}
"""Marker colour of each kind of magnetic source (``MagneticModel.sources``)."""

MODE_COLOURS: dict[str, str] = {
    "handheld": "#1f77b4",
    "calling": "#d62728",
    "dangling": "#ff7f0e",
    "pocketed": "#9467bd",
}
"""Colour of each built-in carrying mode in recording plots; other modes take further colours."""

# Further carrying modes, in order of appearance.
EXTRA_MODE_COLOURS = ("#8c564b", "#e377c2", "#17becf", "#bcbd22")
# Estimators on a leaderboard plot, in order of appearance.
ESTIMATOR_COLOURS = (
    "#1f77b4",
    "#d62728",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#8c564b",
    "#e377c2",
    "#17becf",
)
ROUTE_COLOURS = ("#2ca02c", "#17becf", "#e377c2", "#bcbd22", "#8c564b", "#1f9e89")
FALLBACK_COLOUR = "#999999"
FLOOR_COLOUR = "#f4efe4"
DESK_COLOUR = "#e6d8b9"
FURNITURE_COLOUR = "#9e8b6e"
LIGHT_COLOUR = "#ffd21f"
AP_COLOUR = "#1f4e9c"
# Recording plots: the phone's x, y, z in the red, green, blue of 3-D tools.
AXIS_COLOURS = {"x": "#d62728", "y": "#2ca02c", "z": "#1f77b4"}
LIGHT_TRACE_COLOUR = "#b8860b"
WAYPOINT_COLOUR = "#1f77b4"

# Marker areas (pt²) of the strongest magnetic source and of the weakest one
# still drawn large enough to see; rebar gets a fixed small dot.
DIPOLE_MAX_AREA = 320.0
DIPOLE_MIN_AREA = 14.0
REBAR_AREA = 4.0
# Routes sharing a corridor are drawn this many points apart, so none hides another.
ROUTE_SPREAD_PT = 3.0
LABEL_BOX = {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8}
DPI = 150
PANEL_HEIGHT_IN = 1.7
TITLE_PT = 11.0
TRACK_LEGEND_IN = 2.3


def agg_figure(figsize: tuple[float, float]) -> Figure:
    """A constrained-layout figure of ``figsize`` inches on its own Agg canvas."""
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def new_figure(bounds: tuple[float, float, float, float], *, side_in: float) -> tuple[Figure, Axes]:
    """A figure whose axes fit the plan's aspect, plus ``side_in`` inches for legend or bar.

    The plan's long side gets 9 inches, growing to 13 for long, narrow plans so
    that a corridor keeps a legible width.

    Args:
        bounds: the plan's (xmin, ymin, xmax, ymax), m.
        side_in: width beside the axes for a legend or colour bar, inches.

    Returns:
        The figure and its one axes.
    """
    xmin, ymin, xmax, ymax = bounds
    w, h = max(xmax - xmin, 1e-3), max(ymax - ymin, 1e-3)
    elongation = max(w, h) / min(w, h)
    long_in = min(13.0, 9.0 * math.sqrt(max(elongation / 2.0, 1.0)))
    if w >= h:
        axes_w, axes_h = long_in, max(long_in / elongation, 2.5)
    else:
        axes_w, axes_h = max(long_in / elongation, 3.5), long_in
    fig = agg_figure((axes_w + side_in + 1.0, axes_h + 1.2))
    return fig, fig.add_subplot()


def _safe(text: str) -> str:
    """``text`` made safe as part of a file name on any OS (BSSID colons become dashes)."""
    return re.sub(r"[^A-Za-z0-9._-]+", "-", text.replace(":", "-")).strip("-") or "site"


def save_figures(figures: Mapping[str, Figure], out_dir: Path, prefix: str, dpi: int) -> list[Path]:
    """Write each figure as ``<prefix>_<key>.png`` in ``out_dir``; return the paths."""
    paths = []
    for key, fig in figures.items():
        path = out_dir / f"{_safe(prefix)}_{_safe(key)}.png"
        # "tight" keeps multi-line titles and tick labels inside the image whatever
        # the plan's aspect ratio.
        fig.savefig(path, dpi=dpi, bbox_inches="tight", pad_inches=0.1)
        paths.append(path)
    return paths
