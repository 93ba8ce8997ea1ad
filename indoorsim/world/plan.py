"""FloorPlan: walls, pillars and furniture of one floor, and the geometric queries on them.

All queries are vectorised over many points or segments at once (a particle
filter asks about thousands of particle moves per step):

* :meth:`FloorPlan.crosses_wall` — does a move pass through anything solid?
* :meth:`FloorPlan.is_walkable` — is a point free floor inside the building?
* :meth:`FloorPlan.light_transmittance` / :meth:`FloorPlan.visible` — line of
  sight between two points (floor-to-ceiling walls and pillars occlude; glass
  passes a fraction of the light).
* :meth:`FloorPlan.crossing_loss_db` — summed radio loss of the elements a
  straight path crosses (the multi-wall model).

Walls stand from floor to ceiling, so occlusion in 3-D reduces to 2-D crossings
of the walls' centre lines. Furniture (desks, cabinets) is lower than the
ceiling and only blocks walking.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numba
import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from shapely.geometry import LineString, Polygon
from shapely.ops import polygonize, unary_union

from indoorsim.world.materials import MATERIALS, Material

if TYPE_CHECKING:
    from indoorsim.scenario.schema import ObstacleSpec, PillarSpec, Scenario, WallSpec


@dataclass(frozen=True, kw_only=True)
class Wall:
    """A wall piece after doors are cut: centre line ``start``→``end``, floor to ceiling."""

    start: tuple[float, float]
    end: tuple[float, float]
    thickness: float
    material: Material
    extend_start: bool = True
    """Whether the solid extends half a thickness past ``start`` (closing corners);
    False at the jamb of a door, so the door keeps its full clear width."""
    extend_end: bool = True

    @property
    def length(self) -> float:
        return math.dist(self.start, self.end)

    def polygon(self) -> Polygon:
        """The wall's solid footprint: a rectangle around the centre line."""
        p0, p1 = np.asarray(self.start), np.asarray(self.end)
        u = (p1 - p0) / self.length
        n = np.array([-u[1], u[0]]) * (self.thickness / 2)
        a = p0 - u * (self.thickness / 2 if self.extend_start else 0.0)
        b = p1 + u * (self.thickness / 2 if self.extend_end else 0.0)
        return Polygon([a + n, b + n, b - n, a - n])


def segment_hits(
    p0: NDArray[np.float64], p1: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """Proper intersections between N segments p0→p1 and M segments a→b: (N, M) bool.

    Touching at an end point or running collinearly does not count. Each
    orientation test is affine in the points, so all four are matrix products
    over the (N, M) grid instead of Python loops.
    """
    d = b - a  # (M, 2)
    w = np.stack([-d[:, 1], d[:, 0]])  # cross(d, p - a) = p @ w - k
    k = a[:, 1] * d[:, 0] - a[:, 0] * d[:, 1]
    o1 = p0 @ w - k
    o2 = p1 @ w - k
    e = p1 - p0  # (N, 2)
    ew = np.stack([e[:, 0], -e[:, 1]], axis=1)  # cross(e, q - p0) = ew @ [q_y, q_x] - c
    c = (e[:, 0] * p0[:, 1] - e[:, 1] * p0[:, 0])[:, None]
    o3 = ew @ np.stack([a[:, 1], a[:, 0]]) - c
    o4 = ew @ np.stack([b[:, 1], b[:, 0]]) - c
    return (o1 * o2 < 0) & (o3 * o4 < 0)


_ANY, _SUM, _PRODUCT = 0, 1, 2
PRODUCT = _PRODUCT


@numba.njit(cache=True, inline="always", error_model="numpy")
def crosses_properly(x0, y0, x1, y1, ax, ay, bx, by):  # pragma: no cover - compiled
    """Whether (x0, y0)→(x1, y1) properly crosses a→b: the orientation tests of
    :func:`segment_hits`, after a bounding-box rejection."""
    if max(ax, bx) < min(x0, x1) or min(ax, bx) > max(x0, x1):
        return False
    if max(ay, by) < min(y0, y1) or min(ay, by) > max(y0, y1):
        return False
    dx, dy = bx - ax, by - ay
    o1 = dx * (y0 - ay) - dy * (x0 - ax)
    o2 = dx * (y1 - ay) - dy * (x1 - ax)
    if o1 * o2 >= 0:
        return False
    ex, ey = x1 - x0, y1 - y0
    o3 = ex * (ay - y0) - ey * (ax - x0)
    o4 = ex * (by - y0) - ey * (bx - x0)
    return o3 * o4 < 0


@numba.njit(cache=True, inline="always", error_model="numpy")
def fold_segment(x0, y0, x1, y1, sa, sb, seg_elem, value, mode):  # pragma: no cover - compiled
    """Fold a value over the distinct elements the segment (x0, y0)→(x1, y1) properly crosses.

    ``mode`` _ANY: 1.0 if anything is crossed; _SUM: Σ value[element];
    _PRODUCT: Π value[element] (stops at 0). Segments of one element are
    contiguous in ``sa``/``sb``, so an element crossed twice (a pillar's two
    diagonals) counts once. The same orientation tests as :func:`segment_hits`,
    with a bounding-box rejection first.
    """
    acc = 1.0 if mode == _PRODUCT else 0.0
    counted = -1
    for j in range(sa.shape[0]):
        if not crosses_properly(x0, y0, x1, y1, sa[j, 0], sa[j, 1], sb[j, 0], sb[j, 1]):
            continue
        e = seg_elem[j]
        if e == counted:
            continue
        counted = e
        if mode == _ANY:
            return 1.0
        if mode == _SUM:
            acc += value[e]
        else:
            acc *= value[e]
            if acc == 0.0:
                return 0.0
    return acc


@numba.njit(cache=True, error_model="numpy")
def _fold_crossings(p0, p1, sa, sb, seg_elem, value, mode, out):  # pragma: no cover - compiled
    """:func:`fold_segment` for each segment p0[i]→p1[i]."""
    for i in range(p0.shape[0]):
        out[i] = fold_segment(p0[i, 0], p0[i, 1], p1[i, 0], p1[i, 1], sa, sb, seg_elem, value, mode)


@numba.njit(cache=True, error_model="numpy")
def _nearest_on_edges(
    p, a, b, cell_start, cell_edges, grid, max_d, out
):  # pragma: no cover - compiled
    """Nearest point on the edges a→b within ``max_d`` of each point p (NaN where none).

    ``cell_edges[cell_start[c]:cell_start[c + 1]]`` lists the edges that come
    within ``max_d`` of grid cell c (``grid`` = (x0, y0, cell, nx, ny)), so one
    cell holds every candidate of a point inside it. Ties keep the first edge.
    """
    x0, y0, cell = grid[0], grid[1], grid[2]
    nx, ny = int(grid[3]), int(grid[4])
    lim = max_d * max_d
    for i in range(p.shape[0]):
        out[i, 0] = np.nan
        out[i, 1] = np.nan
        ix = math.floor((p[i, 0] - x0) / cell)
        iy = math.floor((p[i, 1] - y0) / cell)
        if ix < 0 or iy < 0 or ix >= nx or iy >= ny:
            continue
        c = iy * nx + ix
        best = np.inf
        for k in range(cell_start[c], cell_start[c + 1]):
            e = cell_edges[k]
            dx, dy = b[e, 0] - a[e, 0], b[e, 1] - a[e, 1]
            u = ((p[i, 0] - a[e, 0]) * dx + (p[i, 1] - a[e, 1]) * dy) / (dx * dx + dy * dy)
            u = min(max(u, 0.0), 1.0)
            qx, qy = a[e, 0] + u * dx, a[e, 1] + u * dy
            d2 = (p[i, 0] - qx) ** 2 + (p[i, 1] - qy) ** 2
            if d2 <= lim and d2 < best:
                best = d2
                out[i, 0] = qx
                out[i, 1] = qy


# Most entries (edge listings) or cells a nearest-edge grid may hold before its
# cells grow (FloorPlan._edge_grid): a few tens of MB.
_EDGE_GRID_BUDGET = 2_000_000


def _as_points(x: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = np.asarray(x, dtype=float)
    if arr.ndim == 1 and arr.shape[0] in (2, 3):
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] not in (2, 3):
        raise ValueError(f"{name}: expected points of shape (N, 2) or (N, 3), got {arr.shape}")
    return arr[:, :2]


class FloorPlan:
    """The static geometry of one floor, built from a :class:`~indoorsim.scenario.Scenario`.

    Attributes:
        outline: the building footprint (wall centre lines, or the scenario's outline).
        walls: wall pieces after cutting the doors.
        pillars: pillar footprints with their materials.
        obstacles: furniture footprints (block walking only).
        solid: union of everything that blocks walking.
        walkable: ``outline`` minus ``solid``.
        rooms: closed faces of the wall graph (doors closed), used for the
            ambient-light term; the outline itself when walls close no face.
    """

    def __init__(self, scenario: Scenario):
        self.walls: list[Wall] = _cut_doors(scenario)
        # The faces of the wall graph give both the outline (when the scenario
        # has none) and the rooms.
        faces = _wall_faces(scenario)
        self.outline: Polygon = _outline(scenario, faces)
        pillar_shapes = _rectangles(scenario.pillars)
        self.pillars: list[tuple[Polygon, Material]] = [
            (poly, MATERIALS[p.material])
            for poly, p in zip(pillar_shapes, scenario.pillars, strict=True)
        ]
        self.obstacles: list[Polygon] = _rectangles(scenario.obstacles)
        self.solid = unary_union(wall_polygons(self.walls) + pillar_shapes + self.obstacles)
        self.walkable = self.outline.difference(self.solid)
        shapely.prepare(self.walkable)
        shapely.prepare(self.solid)
        self.rooms: list[Polygon] = faces or [self.outline]

        # Occluding elements as centre-line segments: one per wall, the two
        # diagonals of each pillar (any line through a convex cell meets one).
        seg_a, seg_b, seg_elem, materials = [], [], [], []
        for w in self.walls:
            seg_a.append(w.start)
            seg_b.append(w.end)
            seg_elem.append(len(materials))
            materials.append(w.material)
        for poly, mat in self.pillars:
            c = list(poly.exterior.coords)[:4]
            for i, j in ((0, 2), (1, 3)):
                seg_a.append(c[i])
                seg_b.append(c[j])
                seg_elem.append(len(materials))
            materials.append(mat)
        self._seg_a = np.array(seg_a, dtype=float).reshape(-1, 2)
        self._seg_b = np.array(seg_b, dtype=float).reshape(-1, 2)
        self._seg_elem = np.array(seg_elem, dtype=np.intp)
        self.element_materials: list[Material] = materials
        self._elem_transmittance = np.array([m.light_transmittance for m in materials])

        edges_a, edges_b = [], []
        for poly in getattr(self.solid, "geoms", [self.solid]):
            if poly.is_empty:
                continue
            for ring in [poly.exterior, *poly.interiors]:
                xy = np.asarray(ring.coords)
                edges_a.append(xy[:-1])
                edges_b.append(xy[1:])
        self._edge_a = np.concatenate(edges_a) if edges_a else np.zeros((0, 2))
        self._edge_b = np.concatenate(edges_b) if edges_b else np.zeros((0, 2))
        self._edge_ids = np.arange(len(self._edge_a), dtype=np.intp)
        self._edge_ones = np.ones(len(self._edge_a))

    # ------------------------------------------------------------------ queries

    @functools.cached_property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) of the building including wall thickness."""
        # The bounds of the union of the outline and the solids (the union's
        # extreme vertices are theirs), without computing the union.
        boxes = shapely.bounds([self.outline, self.solid])
        lo, hi = np.nanmin(boxes[:, :2], axis=0), np.nanmax(boxes[:, 2:], axis=0)
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))

    def is_walkable(self, points: ArrayLike) -> NDArray[np.bool_]:
        """(N,) True where a point is free floor inside the building."""
        p = _as_points(points, "points")
        return shapely.contains_xy(self.walkable, p[:, 0], p[:, 1])

    @functools.cached_property
    def walkable_edges(self) -> NDArray[np.float64]:
        """(M, 2, 2) end points of the edges of the walkable area's boundary (read-only)."""
        rings = [
            np.asarray(ring.coords)
            for poly in getattr(self.walkable, "geoms", [self.walkable])
            if not poly.is_empty
            for ring in [poly.exterior, *poly.interiors]
        ]
        if not rings:
            ab = np.zeros((0, 2, 2))
        else:
            ab = np.concatenate([np.stack([xy[:-1], xy[1:]], axis=1) for xy in rings])
            ab = np.ascontiguousarray(ab[np.linalg.norm(ab[:, 1] - ab[:, 0], axis=1) > 1e-12])
        ab.flags.writeable = False
        return ab

    def nearest_boundary(self, points: ArrayLike, max_distance: float) -> NDArray[np.float64]:
        """(N, 2) nearest point of the walkable area's boundary to each point, NaN where
        the boundary is farther than ``max_distance``."""
        p = np.ascontiguousarray(_as_points(points, "points"))
        out = np.empty((len(p), 2))
        ab = self.walkable_edges
        if len(ab) == 0:
            out[:] = np.nan
            return out
        # One grid serves every distance up to its own (rounded up to 0.25 m).
        start, edges, grid = self._edge_grid(math.ceil(float(max_distance) / 0.25) * 0.25)
        a, b = np.ascontiguousarray(ab[:, 0]), np.ascontiguousarray(ab[:, 1])
        _nearest_on_edges(p, a, b, start, edges, grid, float(max_distance), out)
        return out

    def _edge_grid(
        self, max_distance: float
    ) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.float64]]:
        """Cells listing the edges within ``max_distance`` of each, in ascending
        order; built once per distance.

        Cells of side ``max_distance``/4 (at least 0.125 m) keep each point's
        candidates few. Each edge is listed in every cell of its bounding box
        grown by ``max_distance``, so long diagonal walls fill many small
        cells: where the grid would pass :data:`_EDGE_GRID_BUDGET` entries or
        cells, the cells double (up to ``max_distance``, at least 0.25 m).
        Any cell size finds the same nearest edges.
        """
        cache = self.__dict__.setdefault("_edge_grids", {})
        if max_distance not in cache:
            ab = self.walkable_edges
            ends = ab.reshape(-1, 2)
            lo = ends.min(axis=0) - max_distance
            for cell in (max_distance / 4.0, max_distance / 2.0, max_distance):
                cell = max(cell, 0.25 if cell == max_distance else 0.125)
                n = np.floor((ends.max(axis=0) + max_distance - lo) / cell).astype(int) + 1
                # Every cell whose square the edge's box, grown by max_distance, overlaps.
                box_lo = np.floor((ab.min(axis=1) - max_distance - lo) / cell).astype(int)
                box_hi = np.floor((ab.max(axis=1) + max_distance - lo) / cell).astype(int)
                width = box_hi - box_lo + 1
                count = width[:, 0] * width[:, 1]
                if max(count.sum(), n[0] * n[1]) <= _EDGE_GRID_BUDGET:
                    break
            # The cells of each edge's block, all edges at once.
            owners = np.repeat(np.arange(len(ab)), count)
            k = np.arange(len(owners)) - np.repeat(np.cumsum(count) - count, count)
            gx = box_lo[owners, 0] + k % width[owners, 0]
            gy = box_lo[owners, 1] + k // width[owners, 0]
            cell_of = gy * n[0] + gx
            # Stable: each cell's edges stay in ascending order (the kernel's
            # ties keep the first).
            order = np.argsort(cell_of, kind="stable")
            start = np.searchsorted(cell_of[order], np.arange(n[0] * n[1] + 1))
            grid = np.array([lo[0], lo[1], cell, n[0], n[1]], dtype=float)
            cache[max_distance] = (start, owners[order].astype(np.intp), grid)
        return cache[max_distance]

    def crosses_wall(self, p0: ArrayLike, p1: ArrayLike) -> NDArray[np.bool_]:
        """(N,) True where the straight move p0→p1 passes through a wall, pillar or obstacle.

        A move that starts or ends inside a solid counts; one that only touches
        a solid's boundary does not.
        """
        a, b = self._pair(p0, p1)
        inside = shapely.contains_xy(self.solid, a[:, 0], a[:, 1])
        inside |= shapely.contains_xy(self.solid, b[:, 0], b[:, 1])
        hit = self._fold(a, b, self._edge_a, self._edge_b, self._edge_ones, _ANY, self._edge_ids)
        return inside | (hit > 0)

    def visible(self, p: ArrayLike, q: ArrayLike) -> NDArray[np.bool_]:
        """(N,) True where no opaque wall or pillar stands between p and q (glass lets light by)."""
        return self.light_transmittance(p, q) > 0

    def light_transmittance(self, p: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
        """(N,) fraction of direct light passing from p to q: 0 behind an opaque
        element, the product of the glazing transmittances crossed otherwise."""
        a, b = self._pair(p, q)
        return self._fold(a, b, self._seg_a, self._seg_b, self._elem_transmittance, _PRODUCT)

    @property
    def light_occluders(
        self,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp], NDArray[np.float64]]:
        """What :meth:`light_transmittance` folds over, for compiled callers: segment
        starts and ends (S, 2), each segment's element (S,), and each element's
        transmittance; pass them to :func:`fold_segment` with mode ``PRODUCT``."""
        return self._seg_a, self._seg_b, self._seg_elem, self._elem_transmittance

    def crossing_loss_db(
        self,
        p0: ArrayLike,
        p1: ArrayLike,
        frequency_ghz: float,
        pillar_loss_db: float | None = None,
    ) -> NDArray[np.float64]:
        """(N,) summed radio attenuation (dB) of the elements the path p0→p1 crosses.

        Walls cost their material's loss. Pillars cost ``pillar_loss_db`` when
        given (a column narrower than the first Fresnel zone is mostly
        diffracted around, not through), their material's loss otherwise.
        """
        a, b = self._pair(p0, p1)
        loss = np.array([m.loss_db(frequency_ghz) for m in self.element_materials])
        if pillar_loss_db is not None:
            loss[len(self.walls) :] = pillar_loss_db
        return self._fold(a, b, self._seg_a, self._seg_b, loss, _SUM)

    def element_crossings(self, p0: ArrayLike, p1: ArrayLike) -> NDArray[np.bool_]:
        """(N, n_elements) True where path p0→p1 crosses element j (walls, then pillars)."""
        a, b = self._pair(p0, p1)
        if len(self._seg_a) == 0:
            return np.zeros((len(a), 0), dtype=bool)
        hits = segment_hits(a, b, self._seg_a, self._seg_b)
        starts = np.flatnonzero(np.r_[True, np.diff(self._seg_elem) != 0])
        return np.logical_or.reduceat(hits, starts, axis=1)

    # ------------------------------------------------------------------ helpers

    @staticmethod
    def _pair(p0: ArrayLike, p1: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        a, b = _as_points(p0, "p0"), _as_points(p1, "p1")
        if len(a) == 1 and len(b) > 1:
            a = np.broadcast_to(a, b.shape)
        elif len(b) == 1 and len(a) > 1:
            b = np.broadcast_to(b, a.shape)
        if a.shape != b.shape:
            raise ValueError(f"p0 and p1 must have the same number of points: {len(a)} vs {len(b)}")
        return np.ascontiguousarray(a), np.ascontiguousarray(b)

    def _fold(
        self,
        p0: NDArray[np.float64],
        p1: NDArray[np.float64],
        sa: NDArray[np.float64],
        sb: NDArray[np.float64],
        value: NDArray[np.float64],
        mode: int,
        seg_elem: NDArray[np.intp] | None = None,
    ) -> NDArray[np.float64]:
        out = np.empty(len(p0))
        elem = self._seg_elem if seg_elem is None else seg_elem
        _fold_crossings(p0, p1, sa, sb, elem, np.ascontiguousarray(value, dtype=float), mode, out)
        return out


# ---------------------------------------------------------------------- building


# The plan plan_for built last, with its scenario.
_last_plan: tuple[Scenario, FloorPlan] | None = None


def plan_for(scenario: Scenario) -> FloorPlan:
    """``FloorPlan(scenario)``, built once for consecutive requests with the same scenario.

    Loading a scenario checks its geometry on a plan (:func:`geometry_problems`)
    and a :class:`~indoorsim.world.site.Site` is usually built from it right
    after; both get this one plan (a plan is not changed after construction).
    """
    global _last_plan
    last = _last_plan
    if last is not None and last[0] is scenario:
        return last[1]
    plan = FloorPlan(scenario)
    _last_plan = (scenario, plan)
    return plan


def _wall_faces(scenario: Scenario) -> list[Polygon]:
    """Closed faces of the graph of wall centre lines (doors closed)."""
    return list(polygonize(unary_union([LineString([w.start, w.to]) for w in scenario.walls])))


def _outline(scenario: Scenario, faces: list[Polygon] | None = None) -> Polygon:
    if scenario.outline is not None:
        return Polygon(scenario.outline)
    if faces is None:
        faces = _wall_faces(scenario)
    if not faces:
        return Polygon()
    merged = unary_union(faces)
    if merged.geom_type == "MultiPolygon":
        merged = max(merged.geoms, key=lambda g: g.area)
    return Polygon(merged.exterior)


def wall_polygons(walls: Sequence[Wall]) -> list[Polygon]:
    """``[w.polygon() for w in walls]``, the arithmetic vectorised over the walls."""
    if not walls:
        return []
    p0 = np.array([w.start for w in walls], dtype=float)
    p1 = np.array([w.end for w in walls], dtype=float)
    half = np.array([w.thickness / 2 for w in walls])
    u = (p1 - p0) / np.array([w.length for w in walls])[:, None]
    n = np.column_stack([-u[:, 1], u[:, 0]]) * half[:, None]
    a = p0 - u * np.where([w.extend_start for w in walls], half, 0.0)[:, None]
    b = p1 + u * np.where([w.extend_end for w in walls], half, 0.0)[:, None]
    return list(shapely.polygons(np.stack([a + n, b + n, b - n, a - n], axis=1)))


def _rectangles(specs: Sequence[PillarSpec | ObstacleSpec]) -> list[Polygon]:
    """The footprints of pillars or obstacles: rectangles of ``size`` about ``center``,
    rotated by ``rotation_deg`` (made in one shapely call)."""
    if not specs:
        return []
    corners = []
    for spec in specs:
        (cx, cy), w, d = spec.center, spec.size[0] / 2, spec.size[1] / 2
        c, s = math.cos(math.radians(spec.rotation_deg)), math.sin(math.radians(spec.rotation_deg))
        local = ((-w, -d), (w, -d), (w, d), (-w, d))
        corners.append([(cx + c * x - s * y, cy + s * x + c * y) for x, y in local])
    return list(shapely.polygons(np.array(corners, dtype=float)))


def near_walls(points: ArrayLike, walls: Sequence[WallSpec]) -> NDArray[np.bool_]:
    """(N, n_walls) whether each point lies in each wall's bounding box grown by half
    its thickness plus 1 mm: necessary for a point to be on the wall (within half
    its thickness of the centre line, as :func:`door_on_wall` tests), so only
    these pairs need that test."""
    p = np.asarray(points, dtype=float).reshape(-1, 1, 2)
    a = np.array([w.start for w in walls], dtype=float)
    b = np.array([w.to for w in walls], dtype=float)
    grow = (np.array([w.thickness for w in walls]) / 2 + 1e-3)[:, None]
    return ((p >= np.minimum(a, b) - grow) & (p <= np.maximum(a, b) + grow)).all(axis=2)


def _cut_doors(scenario: Scenario) -> list[Wall]:
    """Split the walls at each door, leaving a gap of the door's clear width."""
    # Per wall: list of (t0, t1) gaps in metres along the centre line.
    gaps: list[list[tuple[float, float]]] = [[] for _ in scenario.walls]
    near = near_walls([door.position for door in scenario.doors], scenario.walls)
    for door, candidates in zip(scenario.doors, near, strict=True):
        for i in np.flatnonzero(candidates).tolist():
            spec = scenario.walls[i]
            t = door_on_wall(door.position, spec.start, spec.to, spec.thickness)
            if t is not None:
                gaps[i].append((t - door.width / 2, t + door.width / 2))
    walls: list[Wall] = []
    for spec, wall_gaps in zip(scenario.walls, gaps, strict=True):
        p0, p1 = np.asarray(spec.start, float), np.asarray(spec.to, float)
        length = float(np.linalg.norm(p1 - p0))
        u = (p1 - p0) / length
        pieces: list[tuple[float, float, bool, bool]] = [(0.0, length, True, True)]
        for g0, g1 in sorted(wall_gaps):
            nxt = []
            for s0, s1, e0, e1 in pieces:
                if g1 <= s0 or g0 >= s1:
                    nxt.append((s0, s1, e0, e1))
                    continue
                if g0 > s0:
                    nxt.append((s0, g0, e0, False))
                if g1 < s1:
                    nxt.append((g1, s1, False, e1))
            pieces = nxt
        mat = MATERIALS[spec.material]
        for s0, s1, e0, e1 in pieces:
            if s1 - s0 < 1e-6:
                continue
            walls.append(
                Wall(
                    start=tuple(p0 + u * s0),
                    end=tuple(p0 + u * s1),
                    thickness=spec.thickness,
                    material=mat,
                    extend_start=e0,
                    extend_end=e1,
                )
            )
    return walls


def door_on_wall(
    position: Sequence[float], a: Sequence[float], b: Sequence[float], thickness: float
) -> float | None:
    """Distance along wall a→b of the door's projection, or None if the door is not on it."""
    p, a_, b_ = (np.asarray(v, float) for v in (position, a, b))
    d = b_ - a_
    length = float(np.linalg.norm(d))
    t = float(np.dot(p - a_, d) / length)
    if t < 0 or t > length:
        return None
    off = abs(d[0] * (p[1] - a_[1]) - d[1] * (p[0] - a_[0])) / length
    return t if off <= thickness / 2 + 1e-6 else None
