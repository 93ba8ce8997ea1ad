"""Figures of a site: the floor plan, where its sources are, and its fields at phone height.

* :func:`draw_plan` draws a :class:`~indoorsim.world.plan.FloorPlan` onto an
  existing axes: walls filled and coloured by material, pillars, furniture,
  the walkable floor; doors show as gaps in the walls.
* :func:`plot_site_map` adds the sources: luminaires, magnetic dipoles (marker
  size from the moment, colour from the kind of steel), WiFi access points and
  the scenario's named routes.
* :func:`plot_site_fields` samples the site's fields on a regular grid at phone
  height (:func:`sample_site_fields`) and draws one heat map per quantity:
  Bx, By, Bz and |B| in µT (the maps of Han2023 Figs. 10–11), illuminance on an
  upward-facing receiver in lux, and the mean RSS of one access point in dBm.
* :func:`save_site_plots` writes all of them as PNG files.

Figures of one walk (a :class:`~indoorsim.io.recording.Recording`, simulated or a
real phone log):

* :func:`plot_recording_streams` stacks the sensor streams over time
  (accelerometer with the true steps, gyroscope, magnetometer, light, WiFi).
* :func:`plot_recording_track` draws the true track on the floor plan,
  coloured by carrying mode.
* :func:`save_recording_plots` writes both as PNG files.

Every figure is a free-standing :class:`matplotlib.figure.Figure` on an Agg
canvas: nothing is registered with ``pyplot``, so plotting many sites in one
process (or in a worker) leaves no figures behind and never needs a display.
"""

from __future__ import annotations

import itertools
import math
import re
import textwrap
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib import colormaps
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import CenteredNorm, Colormap, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import FancyArrowPatch, Patch, PathPatch
from matplotlib.path import Path as MplPath
from matplotlib.transforms import offset_copy
from numpy.typing import NDArray
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry
from shapely.geometry.polygon import orient
from shapely.ops import unary_union

from indoorsim.scenario.load import bundled_scenarios, load_scenario
from indoorsim.scenario.schema import ScenarioError
from indoorsim.walker.route import RouteError, plan_route

if TYPE_CHECKING:
    import pandas as pd

    from indoorsim.io.recording import Recording
    from indoorsim.world.materials import Material
    from indoorsim.world.plan import FloorPlan
    from indoorsim.world.site import Site

__all__ = [
    "FieldGrid",
    "draw_plan",
    "plot_recording_streams",
    "plot_recording_track",
    "plot_site_fields",
    "plot_site_map",
    "sample_site_fields",
    "save_figures",
    "save_recording_plots",
    "save_site_plots",
]

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

_ROUTE_COLOURS = ("#2ca02c", "#17becf", "#e377c2", "#bcbd22", "#8c564b", "#1f9e89")
_FALLBACK_COLOUR = "#999999"
_FLOOR_COLOUR = "#f4efe4"
_DESK_COLOUR = "#e6d8b9"
_FURNITURE_COLOUR = "#9e8b6e"
_LIGHT_COLOUR = "#ffd21f"
_AP_COLOUR = "#1f4e9c"
# Marker areas (pt²) of the strongest magnetic source and of the weakest one
# still drawn large enough to see; rebar gets a fixed small dot.
_DIPOLE_MAX_AREA = 320.0
_DIPOLE_MIN_AREA = 14.0
_REBAR_AREA = 4.0
_DPI = 150
# Field maps saturate beyond this percentile of |B − B_earth| (see _robust_halfrange).
_SATURATION_PERCENTILE = 97.5
# Routes sharing a corridor are drawn this many points apart, so none hides another.
_ROUTE_SPREAD_PT = 3.0
_LABEL_BOX = {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8}
# Recording plots: the phone's x, y, z in the red, green, blue of 3-D tools.
_AXIS_COLOURS = {"x": "#d62728", "y": "#2ca02c", "z": "#1f77b4"}
_EXTRA_MODE_COLOURS = ("#8c564b", "#e377c2", "#17becf", "#bcbd22")
_LIGHT_TRACE_COLOUR = "#b8860b"
_WAYPOINT_COLOUR = "#1f77b4"
_STRONGEST_APS = 5
# Light gets a log axis when its positive readings span this many decades.
_LIGHT_LOG_DECADES = 2.0
_PANEL_HEIGHT_IN = 1.7
_TITLE_PT = 11.0
_TRACK_LEGEND_IN = 2.3


# ------------------------------------------------------------------- geometry


def _geometry_path(geom: BaseGeometry) -> MplPath:
    """A matplotlib path for a (multi)polygon, holes included.

    Exteriors are oriented counter-clockwise and holes clockwise so that the
    non-zero fill rule leaves the holes empty.
    """
    vertices: list[NDArray[np.float64]] = []
    codes: list[NDArray[np.uint8]] = []
    for poly in getattr(geom, "geoms", [geom]):
        if not isinstance(poly, Polygon) or poly.is_empty:
            continue
        poly = orient(poly, sign=1.0)
        for ring in (poly.exterior, *poly.interiors):
            xy = np.asarray(ring.coords, dtype=float)
            ring_codes = np.full(len(xy), MplPath.LINETO, dtype=np.uint8)
            ring_codes[0], ring_codes[-1] = MplPath.MOVETO, MplPath.CLOSEPOLY
            vertices.append(xy)
            codes.append(ring_codes)
    if not vertices:
        return MplPath(np.zeros((0, 2)))
    return MplPath(np.concatenate(vertices), np.concatenate(codes))


def _add_shape(ax: Axes, geom: BaseGeometry, **patch_kw: object) -> PathPatch:
    patch = PathPatch(_geometry_path(geom), **patch_kw)
    ax.add_patch(patch)
    return patch


def _by_material(items: Iterable[tuple[Polygon, Material]]) -> dict[str, list[Polygon]]:
    groups: dict[str, list[Polygon]] = {}
    for poly, material in items:
        groups.setdefault(material.name, []).append(poly)
    return groups


def draw_plan(
    ax: Axes,
    plan: FloorPlan,
    *,
    obstacle_kinds: Sequence[str] | None = None,
    floor: bool = True,
    legend: bool = True,
) -> list[Artist]:
    """Draw a floor plan: walkable floor, furniture, walls by material, pillars.

    Walls are the pieces left after cutting the doors, so a door is the gap
    between two pieces (the floor colour shows through it).

    Args:
        ax: the axes to draw into; its aspect is set equal and its axes
            labelled in metres.
        plan: the floor plan.
        obstacle_kinds: the ``kind`` of each of ``plan.obstacles`` (from the
            scenario); desks are drawn lighter than other furniture. All
            obstacles are drawn as furniture when omitted.
        floor: fill the walkable area faintly (turn off when a heat map is
            underneath).
        legend: add a legend of the materials and elements to ``ax``.

    Returns:
        The labelled artists, for a legend placed elsewhere.
    """
    handles: list[Artist] = []
    if floor and not plan.walkable.is_empty:
        handles.append(
            _add_shape(
                ax,
                plan.walkable,
                facecolor=_FLOOR_COLOUR,
                edgecolor="none",
                zorder=0.5,
                label="walkable floor",
            )
        )
    kinds = list(obstacle_kinds) if obstacle_kinds is not None else ["other"] * len(plan.obstacles)
    desks = [p for p, k in zip(plan.obstacles, kinds, strict=True) if k == "desk"]
    others = [p for p, k in zip(plan.obstacles, kinds, strict=True) if k != "desk"]
    for polys, colour, label in (
        (desks, _DESK_COLOUR, "desk"),
        (others, _FURNITURE_COLOUR, "furniture"),
    ):
        if polys:
            handles.append(
                _add_shape(
                    ax,
                    unary_union(polys),
                    facecolor=colour,
                    edgecolor="#6b5a3e",
                    linewidth=0.5,
                    zorder=1.0,
                    label=label,
                )
            )
    walls = _by_material((w.polygon(), w.material) for w in plan.walls)
    pillars = _by_material(plan.pillars)
    for kind, groups, style in (
        # One union per material: overlapping rectangles at wall corners would
        # otherwise show their seams. Pillars are hatched like columns on a drawing.
        ("wall", walls, {"linewidth": 0.4, "zorder": 2.0}),
        ("pillar", pillars, {"linewidth": 0.9, "hatch": "xx", "zorder": 2.1}),
    ):
        for name, polys in groups.items():
            handles.append(
                _add_shape(
                    ax,
                    unary_union(polys),
                    facecolor=MATERIAL_COLOURS.get(name, _FALLBACK_COLOUR),
                    edgecolor="black",
                    label=f"{kind}: {name.replace('_', ' ')}",
                    **style,
                )
            )
    xmin, ymin, xmax, ymax = plan.bounds
    pad = 0.03 * max(xmax - xmin, ymax - ymin, 1.0)
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(ymin - pad, ymax + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if legend:
        ax.legend(handles=handles, loc="best", fontsize=8)
    return handles


def _new_figure(
    bounds: tuple[float, float, float, float], *, side_in: float
) -> tuple[Figure, Axes]:
    """A figure whose axes fit the plan's aspect, plus ``side_in`` inches for legend or bar.

    The plan's long side gets 9 inches, growing to 13 for long, narrow plans so
    that a corridor keeps a legible width.
    """
    xmin, ymin, xmax, ymax = bounds
    w, h = max(xmax - xmin, 1e-3), max(ymax - ymin, 1e-3)
    elongation = max(w, h) / min(w, h)
    long_in = min(13.0, 9.0 * math.sqrt(max(elongation / 2.0, 1.0)))
    if w >= h:
        axes_w, axes_h = long_in, max(long_in / elongation, 2.5)
    else:
        axes_w, axes_h = max(long_in / elongation, 3.5), long_in
    fig = Figure(figsize=(axes_w + side_in + 1.0, axes_h + 1.2), layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


# ------------------------------------------------------------------- site map


def _dipole_groups(site: Site) -> dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Per source kind: distinct (x, y) spots and the summed |moment| (A·m²) at each.

    A pillar's chain of dipoles (and a floor and ceiling rebar node) share one
    spot on the plan, so they become one marker.
    """
    mag = site.magnetic
    groups = {}
    strength = np.linalg.norm(mag.moments, axis=1)
    for kind in dict.fromkeys(mag.sources.tolist()):
        sel = mag.sources == kind
        spots, inverse = np.unique(np.round(mag.positions[sel, :2], 3), axis=0, return_inverse=True)
        groups[kind] = (spots, np.bincount(inverse.ravel(), weights=strength[sel]))
    return groups


def _moment_area(moment_Am2: NDArray[np.float64], m_max: float) -> NDArray[np.float64]:
    # A dipole's field falls to a given level at a distance ∝ ∛m, so the marker
    # radius follows ∛m and its area (what scatter takes) m^(2/3).
    area = _DIPOLE_MAX_AREA * (moment_Am2 / m_max) ** (2 / 3)
    return np.maximum(area, _DIPOLE_MIN_AREA)


def _reference_moments(m_max: float) -> list[float]:
    """Two or three round moments (1, 10, 100... A·m²) spanning the legend's size scale."""
    top = 10.0 ** math.floor(math.log10(m_max))
    return [m for m in (top / 100, top / 10, top) if m >= m_max / 1000]


def _marker_handle(label: str, colour: str, *, markersize: float = 9.0, **kw: object) -> Line2D:
    """A legend entry showing one round marker (nothing is drawn on the axes)."""
    kw.setdefault("markeredgecolor", "black")
    return Line2D(
        [],
        [],
        linestyle="none",
        marker="o",
        markersize=markersize,
        markerfacecolor=colour,
        markeredgewidth=0.5,
        label=label,
        **kw,
    )


def _draw_sources(ax: Axes, site: Site) -> list[Artist]:
    handles: list[Artist] = []
    scenario = site.scenario
    if scenario.luminaires:
        xy = np.array([lum.position[:2] for lum in scenario.luminaires])
        handles.append(
            ax.scatter(
                xy[:, 0],
                xy[:, 1],
                s=100,
                marker="*",
                facecolor=_LIGHT_COLOUR,
                edgecolor="#8a6d00",
                linewidth=0.7,
                zorder=4,
                label="luminaire",
            )
        )
    groups = _dipole_groups(site)
    strong = [m for kind, (_, m) in groups.items() if kind != "rebar"]
    m_max = max((float(m.max()) for m in strong if len(m)), default=0.0)
    for kind, (spots, moment) in groups.items():
        colour = SOURCE_COLOURS.get(kind, _FALLBACK_COLOUR)
        if kind == "rebar" or m_max <= 0:
            # Slab rebar is a dense, weak, uniform grid: a faint texture, not a marker each.
            ax.scatter(
                spots[:, 0],
                spots[:, 1],
                s=_REBAR_AREA,
                color=colour,
                alpha=0.35,
                linewidth=0,
                zorder=3,
            )
            handles.append(_marker_handle(f"magnetic: {kind}", colour, markersize=3, alpha=0.5))
            continue
        ax.scatter(
            spots[:, 0],
            spots[:, 1],
            s=_moment_area(moment, m_max),
            color=colour,
            alpha=0.75,
            edgecolor="black",
            linewidth=0.5,
            zorder=3.5,
        )
        # A fixed-size legend marker: the scatter's own would take its first spot's size.
        handles.append(_marker_handle(f"magnetic: {kind}", colour, alpha=0.75))
    if m_max > 0:
        for ref in _reference_moments(m_max):
            size = math.sqrt(float(_moment_area(np.array([ref]), m_max)[0]))
            handles.append(
                _marker_handle(
                    f"|m| = {ref:g} A·m²", "none", markersize=size, markeredgecolor="#444444"
                )
            )
    if scenario.wifi:
        xy = np.array([ap.position[:2] for ap in scenario.wifi])
        handles.append(
            ax.scatter(
                xy[:, 0],
                xy[:, 1],
                s=70,
                marker="D",
                color=_AP_COLOUR,
                edgecolor="white",
                linewidth=0.8,
                zorder=5,
                label="WiFi AP (last octets)",
            )
        )
        for ap in scenario.wifi:
            ax.annotate(
                ap.bssid[-5:].lower(),
                ap.position[:2],
                xytext=(5, 5),
                textcoords="offset points",
                fontsize=7,
                color=_AP_COLOUR,
                zorder=6,
                bbox=_LABEL_BOX,
            )
    return handles


def _draw_routes(ax: Axes, site: Site) -> list[Artist]:
    handles: list[Artist] = []
    routes = site.scenario.routes
    starts_seen: dict[tuple[float, float], int] = {}
    for i, (name, spec) in enumerate(routes.items()):
        colour = _ROUTE_COLOURS[i % len(_ROUTE_COLOURS)]
        label = f"route {name}"
        # Scenarios often run several routes along one corridor: shift each
        # diagonally by a few points (a fixed screen distance at any scale).
        shift = (i - (len(routes) - 1) / 2) * _ROUTE_SPREAD_PT
        transform = offset_copy(ax.transData, fig=ax.figure, x=shift, y=shift, units="points")
        try:
            # The path the walker will take: start/goal routes are planned
            # around walls, waypoint routes are checked leg by leg.
            xy = plan_route(site.plan, spec, name).points
            linestyle = "-"
        except RouteError:
            # Still show what the scenario asks for: the map is where one
            # looks to see why a route cannot be walked.
            xy = np.asarray(spec.points(), dtype=float)
            linestyle, label = ":", f"{label} (not walkable)"
        (line,) = ax.plot(
            xy[:, 0],
            xy[:, 1],
            color=colour,
            linestyle=linestyle,
            linewidth=1.8,
            alpha=0.9,
            zorder=4.5,
            solid_capstyle="round",
            label=label,
            transform=transform,
        )
        ax.plot(*xy[0], marker="o", markersize=6, color=colour, zorder=4.6, transform=transform)
        ax.plot(*xy[-1], marker="s", markersize=5, color=colour, zorder=4.6, transform=transform)
        seg = np.diff(xy, axis=0)
        length = np.linalg.norm(seg, axis=1)
        # An arrowhead at the middle of every leg long enough to hold one.
        for a, d, n in zip(xy[:-1], seg, length, strict=True):
            if n < 0.8 and n < length.max():
                continue
            mid, u = a + d / 2, d / n
            ax.add_patch(
                FancyArrowPatch(
                    tuple(mid - 0.2 * u),
                    tuple(mid + 0.2 * u),
                    arrowstyle="-|>",
                    mutation_scale=16,
                    color=colour,
                    linewidth=0,
                    zorder=4.7,
                    transform=transform,
                )
            )
        # Names of routes that start at the same spot stack upwards.
        start = (round(float(xy[0, 0]), 1), round(float(xy[0, 1]), 1))
        stacked = starts_seen.get(start, 0)
        starts_seen[start] = stacked + 1
        ax.annotate(
            name,
            tuple(xy[0]),
            xytext=(6, 6 + 11 * stacked),
            textcoords="offset points",
            fontsize=8,
            color=colour,
            fontweight="bold",
            zorder=6,
            bbox=_LABEL_BOX,
        )
        handles.append(line)
    return handles


def plot_site_map(site: Site) -> Figure:
    """The floor plan with every source and route of a site.

    Luminaires are stars; magnetic sources are circles coloured by kind (pillar,
    obstacle, explicit dipole; slab rebar as a faint dot grid) whose area grows
    as |m|^(2/3) — the radius is proportional to the distance at which the
    dipole's field falls to a fixed level — with the moments of a pillar's
    vertical chain summed into one marker; WiFi APs are diamonds labelled by the
    last two octets of their BSSID; routes are the paths the walker will take
    (start/goal routes planned around the walls), with arrows, a circle at the
    start, a square at the end and the name at the start — dotted along the
    scenario's points when the route cannot be walked.

    Args:
        site: the loaded site.

    Returns:
        A free-standing figure (not registered with ``pyplot``).
    """
    fig, ax = _new_figure(site.plan.bounds, side_in=2.3)
    handles = draw_plan(
        ax, site.plan, obstacle_kinds=[o.kind for o in site.scenario.obstacles], legend=False
    )
    for room in site.scenario.rooms:
        at = Polygon(room.polygon).representative_point()
        ax.annotate(
            room.name,
            (at.x, at.y),
            ha="center",
            va="center",
            fontsize=7,
            color="#555555",
            style="italic",
            zorder=1.5,
        )
    handles += _draw_sources(ax, site)
    handles += _draw_routes(ax, site)
    scenario = site.scenario
    counts = (
        f"{len(scenario.walls)} walls · {len(scenario.luminaires)} luminaires · "
        f"{len(site.magnetic.positions)} dipoles · {len(scenario.wifi)} APs"
    )
    ax.set_title(f"{site.name} — site map\n{counts}", fontsize=11)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
    return fig


# ------------------------------------------------------------------- field maps


@dataclass(frozen=True, kw_only=True)
class FieldGrid:
    """A site's fields sampled on a regular grid at one height.

    Values are NaN outside the walkable area (walls, pillars, furniture and
    outside the building).

    Attributes:
        x: (nx,) cell-centre x coordinates, m.
        y: (ny,) cell-centre y coordinates, m.
        height: sampling height above the floor, m.
        resolution: cell size, m.
        walkable: (ny, nx) True where the cell centre is walkable.
        magnetic_uT: (ny, nx, 3) flux density (Bx, By, Bz), µT.
        illuminance_lux: (ny, nx) illuminance on an upward-facing receiver, lux.
        rss_dbm: (ny, nx, n_ap) mean RSS of each AP (order of ``site.radio.bssids``), dBm.
    """

    x: NDArray[np.float64]
    y: NDArray[np.float64]
    height: float
    resolution: float
    walkable: NDArray[np.bool_]
    magnetic_uT: NDArray[np.float64]
    illuminance_lux: NDArray[np.float64]
    rss_dbm: NDArray[np.float64]

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(left, right, bottom, top) of the cell edges, for ``imshow``."""
        half = self.resolution / 2
        return (
            float(self.x[0] - half),
            float(self.x[-1] + half),
            float(self.y[0] - half),
            float(self.y[-1] + half),
        )


def sample_site_fields(site: Site, height: float = 1.2, resolution: float = 0.1) -> FieldGrid:
    """Evaluate every field of ``site`` on a grid over ``site.plan.bounds``.

    Each field is computed by one vectorised call over all walkable cell
    centres at once.

    Args:
        site: the loaded site.
        height: receiver height above the floor, m (a phone held in front of
            the body is at about 1.2 m).
        resolution: grid spacing, m.

    Raises:
        ValueError: ``resolution`` not positive or wider than the building, or
            ``height`` not inside the room.
    """
    if not resolution > 0:
        raise ValueError(f"resolution must be > 0 m, got {resolution}")
    ceiling = site.scenario.site.ceiling_height
    if not 0 < height < ceiling:
        raise ValueError(
            f"height must be between the floor and the ceiling (0, {ceiling}) m, got {height}"
        )
    xmin, ymin, xmax, ymax = site.plan.bounds
    x = np.arange(xmin + resolution / 2, xmax, resolution)
    y = np.arange(ymin + resolution / 2, ymax, resolution)
    if not (len(x) and len(y)):
        raise ValueError(f"resolution {resolution} m is coarser than the building itself")
    gx, gy = np.meshgrid(x, y)
    walkable = site.plan.is_walkable(np.column_stack([gx.ravel(), gy.ravel()])).reshape(gx.shape)
    points = np.column_stack([gx[walkable], gy[walkable], np.full(walkable.sum(), height)])
    up = np.tile([0.0, 0.0, 1.0], (len(points), 1))
    n_ap = len(site.radio.bssids)

    def on_grid(values: NDArray[np.float64], *trailing: int) -> NDArray[np.float64]:
        out = np.full((*gx.shape, *trailing), np.nan)
        out[walkable] = values.reshape(len(points), *trailing)
        return out

    return FieldGrid(
        x=x,
        y=y,
        height=height,
        resolution=resolution,
        walkable=walkable,
        magnetic_uT=on_grid(site.magnetic_field(points), 3),
        illuminance_lux=on_grid(site.illuminance(points, up)),
        rss_dbm=on_grid(site.rss(points), n_ap),
    )


def _field_figure(
    site: Site,
    grid: FieldGrid,
    values: NDArray[np.float64],
    *,
    title: str,
    label: str,
    cmap: str | Colormap,
    norm: Normalize,
    extend: str,
) -> tuple[Figure, Axes]:
    xmin, ymin, xmax, ymax = site.plan.bounds
    wide = (xmax - xmin) > 2.5 * (ymax - ymin)
    # A long, low plan gets its colour bar underneath, where there is room.
    fig, ax = _new_figure(site.plan.bounds, side_in=0.0 if wide else 1.3)
    if wide:
        fig.set_figheight(fig.get_figheight() + 0.8)
    image = ax.imshow(
        np.ma.masked_invalid(values),
        origin="lower",
        extent=grid.extent,
        cmap=cmap,
        norm=norm,
        interpolation="nearest",
        zorder=0.2,
    )
    draw_plan(
        ax,
        site.plan,
        obstacle_kinds=[o.kind for o in site.scenario.obstacles],
        floor=False,
        legend=False,
    )
    bar = fig.colorbar(
        image,
        ax=ax,
        label=label,
        extend=extend,
        orientation="horizontal" if wide else "vertical",
        shrink=0.9,
        aspect=40 if wide else 25,
    )
    bar.ax.tick_params(labelsize=8)
    ax.set_title(f"{site.name} — {title}", fontsize=11)
    return fig, ax


def _robust_halfrange(deviation: NDArray[np.float64]) -> float:
    # The field grows as 1/r³ toward a dipole: scaled to its extremes, the cells
    # next to steel would wash out the few-µT texture that fingerprinting uses
    # (in a generated office the median deviation is ~2 µT, the 99th
    # percentile ~40 µT). The cells beyond the percentile saturate instead.
    finite = np.abs(deviation[np.isfinite(deviation)])
    top = float(np.percentile(finite, _SATURATION_PERCENTILE)) if finite.size else 0.0
    return max(top, 0.1)


def _extend(values: NDArray[np.float64], vmin: float, vmax: float) -> str:
    v = values[np.isfinite(values)]
    low, high = bool((v < vmin).any()), bool((v > vmax).any())
    return {(False, False): "neither", (True, False): "min", (False, True): "max"}.get(
        (low, high), "both"
    )


def _resolve_ap(site: Site, ap: str | None) -> int | None:
    bssids = [b.lower() for b in site.radio.bssids]
    if ap is None:
        return 0 if bssids else None
    if ap.lower() not in bssids:
        raise ValueError(
            f"{site.name}: no access point {ap!r}; its BSSIDs are {', '.join(bssids) or 'none'}"
        )
    return bssids.index(ap.lower())


def plot_site_fields(
    site: Site,
    height: float = 1.2,
    resolution: float = 0.1,
    *,
    ap: str | None = None,
    detection_threshold_dbm: float = -95.0,
) -> dict[str, Figure]:
    """Heat maps of a site's fields at phone height, with the walls drawn over them.

    * ``"Bx"``, ``"By"``, ``"Bz"``, ``"B"`` (|B|): flux density in µT on a
      diverging scale centred on the Earth's field, so steel shows as red
      (stronger) and blue (weaker) patches; the scale spans the 97.5th
      percentile of the deviation, and the colour bar's arrows mark the
      saturated cells beyond it (next to steel).
    * ``"lux"``: illuminance on an upward-facing receiver (normal (0, 0, 1)).
    * ``"rss_<bssid>"``: mean RSS of one AP (no per-scan fading); cells below
      ``detection_threshold_dbm`` (where a phone would not hear the AP) are
      grey. Absent when the site has no APs.

    Args:
        site: the loaded site.
        height: receiver height above the floor, m.
        resolution: grid spacing, m.
        ap: BSSID of the AP whose RSS is mapped (case-insensitive); the first
            one when omitted.
        detection_threshold_dbm: weakest RSS a phone reports; the default is
            a typical phone's (REALISM §4.3), as in the bundled device profiles.

    Returns:
        Figures keyed by quantity, in the order above.

    Raises:
        ValueError: an unknown ``ap``, or invalid ``height`` or ``resolution``.
    """
    ap_index = _resolve_ap(site, ap)
    grid = sample_site_fields(site, height, resolution)
    at = f"z = {grid.height:g} m"
    earth = np.asarray(site.magnetic.earth_field_uT, dtype=float)
    figures: dict[str, Figure] = {}
    components = [grid.magnetic_uT[..., i] for i in range(3)]
    components.append(np.linalg.norm(grid.magnetic_uT, axis=-1))
    centres = [*earth, float(np.linalg.norm(earth))]
    for key, values, centre in zip(("Bx", "By", "Bz", "B"), components, centres, strict=True):
        half = _robust_halfrange(values - centre)
        name = "|B|" if key == "B" else key
        figures[key], _ = _field_figure(
            site,
            grid,
            values,
            title=f"{name} at {at}\n(white = Earth field, {centre:.1f} µT)",
            label=f"{name} (µT)",
            cmap="RdBu_r",
            norm=CenteredNorm(centre, half),
            extend=_extend(values, centre - half, centre + half),
        )

    lux = grid.illuminance_lux
    top = max(float(np.nanmax(lux)) if np.isfinite(lux).any() else 0.0, 1.0)
    figures["lux"], ax = _field_figure(
        site,
        grid,
        lux,
        title=f"illuminance at {at}, receiver facing up (+ luminaire)",
        label="illuminance (lux)",
        cmap="inferno",
        norm=Normalize(0.0, top),
        extend="neither",
    )
    if site.scenario.luminaires:
        xy = np.array([lum.position[:2] for lum in site.scenario.luminaires])
        ax.scatter(
            xy[:, 0],
            xy[:, 1],
            s=40,
            marker="+",
            color="#30a0ff",
            linewidth=1.0,
            zorder=3,
        )

    if ap_index is not None:
        bssid = site.radio.bssids[ap_index]
        rss = grid.rss_dbm[..., ap_index]
        finite = rss[np.isfinite(rss)]
        floor_dbm = detection_threshold_dbm
        high = float(finite.max()) if finite.size else floor_dbm + 1.0
        low = max(floor_dbm, float(finite.min())) if finite.size else floor_dbm
        cmap = colormaps["viridis"].with_extremes(under="#c8c8c8")
        figures[f"rss_{bssid}"], ax = _field_figure(
            site,
            grid,
            rss,
            title=f"mean RSS of AP {bssid} (◆) at {at}",
            label="RSS (dBm)",
            cmap=cmap,
            norm=Normalize(low, max(high, low + 1.0)),
            extend="min" if (finite < floor_dbm).any() else "neither",
        )
        spec = next(w for w in site.scenario.wifi if w.bssid.lower() == bssid.lower())
        ax.scatter(
            *spec.position[:2],
            s=90,
            marker="D",
            color="#e8112d",
            edgecolor="white",
            linewidth=1.0,
            zorder=5,
        )
        ax.annotate(
            bssid[-5:].lower(),
            spec.position[:2],
            xytext=(6, 6),
            textcoords="offset points",
            fontsize=8,
            color="#e8112d",
            zorder=6,
            bbox=_LABEL_BOX,
        )
    return figures


# ------------------------------------------------------------------- recordings


def _mode_colours(modes: Iterable[str]) -> dict[str, str]:
    """A colour for each mode: the built-in ones fixed, others in order of appearance."""
    extra = itertools.cycle(_EXTRA_MODE_COLOURS)
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
    chars = max(int(width_in * 72 / (0.6 * _TITLE_PT)), 30)
    return "\n".join(textwrap.fill(line, chars, break_on_hyphens=False) for line in lines)


def _draw_vector(ax: Axes, df: pd.DataFrame, *, norm: str | None) -> None:
    t = df.index.to_numpy()
    for axis in "xyz":
        ax.plot(t, df[axis].to_numpy(), color=_AXIS_COLOURS[axis], linewidth=0.6, label=axis)
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
        color=_LIGHT_TRACE_COLOUR,
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
    fig = Figure(figsize=(12.0, 1.1 + _PANEL_HEIGHT_IN * sum(heights)), layout="constrained")
    FigureCanvasAgg(fig)
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
        _recording_title(rec, "sensor streams", width_in=fig.get_figwidth()), fontsize=_TITLE_PT
    )
    return fig


def _scenario_site(name: object) -> Site | None:
    """The bundled scenario a recording's manifest names, as a Site; None if there is none.

    Bundled scenarios are named as their files, so the manifest's name is the key.
    """
    from indoorsim.world.site import Site

    bundled = bundled_scenarios()
    if not isinstance(name, str) or name not in bundled:
        return None
    try:
        return Site(load_scenario(bundled[name]))
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
        fig, ax = _new_figure(site.plan.bounds, side_in=_TRACK_LEGEND_IN)
        handles = draw_plan(
            ax, site.plan, obstacle_kinds=[o.kind for o in site.scenario.obstacles], legend=False
        )
    else:
        shown = xy if planned is None else np.vstack([xy, planned])
        (xmin, ymin), (xmax, ymax) = shown.min(axis=0), shown.max(axis=0)
        fig, ax = _new_figure((xmin, ymin, xmax, ymax), side_in=_TRACK_LEGEND_IN)
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
                    bbox=_LABEL_BOX,
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
            color=_WAYPOINT_COLOUR,
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
                color=_WAYPOINT_COLOUR,
                zorder=6,
                bbox=_LABEL_BOX,
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
    # Over the axes only (the width _new_figure gave them): the legend takes the right.
    width_in = fig.get_figwidth() - _TRACK_LEGEND_IN - 1.0
    ax.set_title(_recording_title(rec, "true track", length, width_in=width_in), fontsize=_TITLE_PT)
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)
    return fig


# ------------------------------------------------------------------- files


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


def save_site_plots(
    site: Site,
    out_dir: str | Path,
    *,
    height: float = 1.2,
    resolution: float = 0.1,
    ap: str | None = None,
    dpi: int = _DPI,
) -> list[Path]:
    """Write a site's map and field maps as PNG files.

    Files: ``<name>_map.png``, ``<name>_Bx.png``, ``<name>_By.png``,
    ``<name>_Bz.png``, ``<name>_B.png`` (|B|), ``<name>_lux.png`` and
    ``<name>_rss_<bssid>.png`` (colons as dashes), with ``<name>`` the
    scenario's name.

    Args:
        site: the loaded site.
        out_dir: folder to write into; created if missing.
        height: receiver height of the field maps, m.
        resolution: grid spacing of the field maps, m.
        ap: BSSID of the AP whose RSS is mapped; the first one when omitted.
        dpi: resolution of the PNG files.

    Returns:
        The written paths, map first.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {"map": plot_site_map(site)}
    figures.update(plot_site_fields(site, height, resolution, ap=ap))
    return save_figures(figures, out, site.name, dpi)


def save_recording_plots(
    rec: Recording,
    out_dir: str | Path,
    name: str,
    *,
    site: Site | None = None,
    dpi: int = _DPI,
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


# ----------------------------------------------------------------- leaderboards


def _estimator_colours(names: Iterable[str]) -> dict[str, str]:
    cycle = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"]
    return {n: cycle[i % len(cycle)] for i, n in enumerate(dict.fromkeys(names))}


def plot_error_cdfs(evaluations: Sequence[Any]) -> Figure:
    """Error CDFs of several evaluations: one panel per carrying mode, one curve per estimator.

    Args:
        evaluations: :class:`indoorsim.benchmark.leaderboard.Evaluation` objects of one
            scenario; each curve pools the errors of all its seeds.
    """
    from indoorsim.benchmark.metrics import error_cdf, position_errors

    modes = list(dict.fromkeys(ev.mode for ev in evaluations))
    colours = _estimator_colours(ev.estimator for ev in evaluations)
    fig = Figure(figsize=(4.2 * len(modes), 3.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(modes), squeeze=False, sharey=True)[0]
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
    fig = Figure(figsize=(width * len(modes), max(3.0, width * aspect) + 1.0), layout="constrained")
    FigureCanvasAgg(fig)
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

    fig = Figure(figsize=(4.2 * len(panels), 3.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(panels), squeeze=False, sharey=True)[0]
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
    fig = Figure(figsize=(4.2 * len(panels), 3.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(panels), squeeze=False, sharey=True)[0]
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
