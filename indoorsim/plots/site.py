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
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib import colormaps
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.colors import CenteredNorm, Colormap, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import FancyArrowPatch, PathPatch
from matplotlib.path import Path as MplPath
from matplotlib.transforms import offset_copy
from numpy.typing import NDArray
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry
from shapely.geometry.polygon import orient
from shapely.ops import unary_union

from indoorsim.plots.style import (
    AP_COLOUR,
    DESK_COLOUR,
    DIPOLE_MAX_AREA,
    DIPOLE_MIN_AREA,
    DPI,
    FALLBACK_COLOUR,
    FLOOR_COLOUR,
    FURNITURE_COLOUR,
    LABEL_BOX,
    LIGHT_COLOUR,
    MATERIAL_COLOURS,
    REBAR_AREA,
    ROUTE_COLOURS,
    ROUTE_SPREAD_PT,
    SOURCE_COLOURS,
    new_figure,
    save_figures,
)
from indoorsim.walker.route import RouteError, plan_route

if TYPE_CHECKING:
    from indoorsim.world.materials import Material
    from indoorsim.world.plan import FloorPlan
    from indoorsim.world.site import Site

# Field maps saturate beyond this percentile of |B − B_earth| (see _robust_halfrange).
_SATURATION_PERCENTILE = 97.5


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
                facecolor=FLOOR_COLOUR,
                edgecolor="none",
                zorder=0.5,
                label="walkable floor",
            )
        )
    kinds = list(obstacle_kinds) if obstacle_kinds is not None else ["other"] * len(plan.obstacles)
    desks = [p for p, k in zip(plan.obstacles, kinds, strict=True) if k == "desk"]
    others = [p for p, k in zip(plan.obstacles, kinds, strict=True) if k != "desk"]
    for polys, colour, label in (
        (desks, DESK_COLOUR, "desk"),
        (others, FURNITURE_COLOUR, "furniture"),
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
                    facecolor=MATERIAL_COLOURS.get(name, FALLBACK_COLOUR),
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
    area = DIPOLE_MAX_AREA * (moment_Am2 / m_max) ** (2 / 3)
    return np.maximum(area, DIPOLE_MIN_AREA)


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
    for lit, label in ((True, "luminaire"), (False, "luminaire, off")):
        xy = np.array([lum.position[:2] for lum in scenario.luminaires if lum.lit is lit]).reshape(
            -1, 2
        )
        if not len(xy):
            continue
        handles.append(
            ax.scatter(
                xy[:, 0],
                xy[:, 1],
                s=100,
                marker="*",
                facecolor=LIGHT_COLOUR if lit else "none",
                edgecolor="#8a6d00",
                linewidth=0.7,
                zorder=4,
                label=label,
            )
        )
    groups = _dipole_groups(site)
    strong = [m for kind, (_, m) in groups.items() if kind != "rebar"]
    m_max = max((float(m.max()) for m in strong if len(m)), default=0.0)
    for kind, (spots, moment) in groups.items():
        colour = SOURCE_COLOURS.get(kind, FALLBACK_COLOUR)
        if kind == "rebar" or m_max <= 0:
            # Slab rebar is a dense, weak, uniform grid: a faint texture, not a marker each.
            ax.scatter(
                spots[:, 0],
                spots[:, 1],
                s=REBAR_AREA,
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
                color=AP_COLOUR,
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
                color=AP_COLOUR,
                zorder=6,
                bbox=LABEL_BOX,
            )
    return handles


def _draw_routes(ax: Axes, site: Site) -> list[Artist]:
    handles: list[Artist] = []
    routes = site.scenario.routes
    starts_seen: dict[tuple[float, float], int] = {}
    for i, (name, spec) in enumerate(routes.items()):
        colour = ROUTE_COLOURS[i % len(ROUTE_COLOURS)]
        label = f"route {name}"
        # Scenarios often run several routes along one corridor: shift each
        # diagonally by a few points (a fixed screen distance at any scale).
        shift = (i - (len(routes) - 1) / 2) * ROUTE_SPREAD_PT
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
            bbox=LABEL_BOX,
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
    fig, ax = new_figure(site.plan.bounds, side_in=2.3)
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
    fig, ax = new_figure(site.plan.bounds, side_in=0.0 if wide else 1.3)
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
            bbox=LABEL_BOX,
        )
    return figures


# ------------------------------------------------------------------- files


def save_site_plots(
    site: Site,
    out_dir: str | Path,
    *,
    height: float = 1.2,
    resolution: float = 0.1,
    ap: str | None = None,
    dpi: int = DPI,
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
