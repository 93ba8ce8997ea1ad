"""Routes through the walkable area: given waypoints, or a shortest path from start to goal.

A :class:`Route` is a polyline the walker's body centre follows (DESIGN §5).
:func:`plan_route` turns a scenario's :class:`~indoorsim.scenario.RouteSpec`
into one:

* **waypoints** are taken as given; every leg must lie in the walkable area
  (inside the building, clear of walls, pillars and furniture);
* **start → goal** is joined by the shortest path that keeps a body clearance
  from everything solid: the walkable area is eroded by the clearance and the
  path is found on the visibility graph of the eroded polygon's reflex
  vertices (a shortest path in a polygonal domain bends only there), with
  :func:`scipy.sparse.csgraph.dijkstra`.

The erosion uses mitred joins, so a wall corner becomes a single vertex at
``clearance·√2`` from the corner rather than a many-vertex arc: the graph stays
small and the path keeps a little extra room where the walker turns. A start
or goal closer than the clearance to a wall joins the path at the nearest
point that has it. The visibility graph (the roadmap) of a floor plan is built
once per clearance and kept while the plan lives, so planning many routes in
one building costs a few milliseconds each.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numba
import numpy as np
import shapely
from numpy.typing import NDArray
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra
from shapely.geometry import MultiPolygon, Point, Polygon
from shapely.geometry.polygon import orient
from shapely.ops import nearest_points

if TYPE_CHECKING:
    from indoorsim.scenario.schema import RouteSpec
    from indoorsim.world.plan import FloorPlan

__all__ = ["Route", "RouteError", "plan_route"]

# Consecutive points closer than this are one point (metres).
_SAME_POINT_M = 1e-9
# Visibility is tested against the free region grown by this much, so that a
# segment running exactly along a boundary edge is not lost to rounding.
_VISIBILITY_TOL_M = 1e-7
# Bounds the (pairs of graph nodes) tested per vectorised shapely call.
_PAIR_CHUNK = 1 << 16


class RouteError(ValueError):
    """A route that cannot be walked: an unwalkable leg, or no path from start to goal."""


@dataclass(frozen=True, kw_only=True, eq=False)
class Route:
    """A walkable polyline with the desired walking speed (compared by identity).

    Attributes:
        name: the route's name (for messages and recordings).
        points: (L, 2) polyline vertices in the building frame, metres; no two
            consecutive points coincide. Read-only.
        speed: desired walking speed in m/s.
        leg_speeds: (L − 1,) mean speed over each leg, m/s, or None: every leg at
            ``speed`` (:attr:`~indoorsim.scenario.schema.RouteSpec.leg_speeds`).
            Read-only.
        length: total polyline length in metres (derived from ``points``).
    """

    name: str
    points: NDArray[np.float64]
    speed: float
    leg_speeds: NDArray[np.float64] | None = None
    length: float = field(init=False)

    def __post_init__(self) -> None:
        pts = np.array(self.points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2:
            raise ValueError(f"route {self.name!r}: points must be (L >= 2, 2), got {pts.shape}")
        legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        if np.any(legs <= _SAME_POINT_M):
            raise ValueError(f"route {self.name!r}: consecutive points must differ")
        if not self.speed > 0:
            raise ValueError(f"route {self.name!r}: speed must be > 0, got {self.speed}")
        if self.leg_speeds is not None:
            legs_v = np.array(self.leg_speeds, dtype=float)
            if legs_v.shape != (len(pts) - 1,) or not np.all((legs_v > 0) & np.isfinite(legs_v)):
                raise ValueError(
                    f"route {self.name!r}: leg_speeds must be {len(pts) - 1} positive, finite "
                    f"speeds (one per leg), got {legs_v.tolist()}"
                )
            legs_v.flags.writeable = False
            object.__setattr__(self, "leg_speeds", legs_v)
        pts.flags.writeable = False
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "length", float(legs.sum()))


def plan_route(plan: FloorPlan, spec: RouteSpec, name: str = "", clearance: float = 0.35) -> Route:
    """Turn a route specification into a walkable :class:`Route`.

    Args:
        plan: the floor plan to walk in.
        spec: waypoints, or a start and a goal, and the desired speed.
        name: the route's name, used in error messages.
        clearance: for start/goal routes, the distance in metres the planned
            path keeps from walls, pillars, furniture and the building outline
            (roughly the half-width of a walking person plus a margin). Given
            waypoints are used as they are.

    Returns:
        The route; for start/goal, the shortest path with that clearance (the
        first and last legs may come closer where start or goal themselves do).

    Raises:
        RouteError: a waypoint leg leaves the walkable area (the message names
            the leg's index and end points), start or goal is not walkable, or
            no path with the clearance joins them.
    """
    label = f"route {name!r}" if name else "route"
    if spec.waypoints is not None:
        given = np.asarray(spec.waypoints, dtype=float)
        kept = _distinct(given)
        pts = given[kept]
        # A repeated waypoint's leg has no length: its speed goes with it.
        leg_speeds = None if spec.leg_speeds is None else np.asarray(spec.leg_speeds)[kept[1:]]
        if len(pts) < 2:
            raise RouteError(f"{label}: all waypoints are the same point {pts[0].tolist()}")
        bad = ~_segments_covered(plan.walkable, pts[:-1], pts[1:])
        if bad.any():
            legs = "; ".join(
                f"leg {j} {pts[j].tolist()} → {pts[j + 1].tolist()}" for j in np.flatnonzero(bad)
            )
            raise RouteError(
                f"{label}: not walkable (leaves the walkable area or passes through "
                f"a wall, pillar or obstacle): {legs}"
            )
        return Route(name=name, points=pts, speed=spec.speed, leg_speeds=leg_speeds)
    assert spec.start is not None and spec.goal is not None  # RouteSpec guarantees the pair
    start, goal = np.asarray(spec.start, float), np.asarray(spec.goal, float)
    pts = _shortest_path(plan, start, goal, clearance, label)
    return Route(name=name, points=pts, speed=spec.speed)


# ---------------------------------------------------------------------- helpers


def _distinct(pts: NDArray[np.float64]) -> NDArray[np.bool_]:
    """(L,) False where a point repeats its predecessor."""
    return np.r_[True, np.linalg.norm(np.diff(pts, axis=0), axis=1) > _SAME_POINT_M]


def _dedupe(pts: NDArray[np.float64]) -> NDArray[np.float64]:
    """Drop points that repeat their predecessor."""
    return pts[_distinct(pts)]


def _segments_covered(
    region: Polygon | MultiPolygon, a: NDArray[np.float64], b: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """(N,) True where the segment a→b lies entirely in ``region`` (boundary included)."""
    out = np.empty(len(a), dtype=bool)
    for i in range(0, len(a), _PAIR_CHUNK):
        lines = shapely.linestrings(np.stack([a[i : i + _PAIR_CHUNK], b[i : i + _PAIR_CHUNK]], 1))
        out[i : i + _PAIR_CHUNK] = shapely.covers(region, lines)
    return out


def _polygons(geom: shapely.Geometry) -> list[Polygon]:
    if geom.is_empty:
        return []
    if isinstance(geom, Polygon):
        return [geom]
    return [g for g in getattr(geom, "geoms", []) if isinstance(g, Polygon) and not g.is_empty]


def _reflex_vertices(region: shapely.Geometry) -> NDArray[np.float64]:
    """(M, 2) vertices where the free region's boundary turns into the free space.

    With exteriors counter-clockwise and holes clockwise, the free space lies to
    the left of every ring, so a reflex vertex is a right turn.
    """
    out = []
    for poly in _polygons(region):
        poly = orient(poly, sign=1.0)
        for ring in [poly.exterior, *poly.interiors]:
            xy = np.asarray(ring.coords)[:-1]
            prev, nxt = np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0)
            d0, d1 = xy - prev, nxt - xy
            cross = d0[:, 0] * d1[:, 1] - d0[:, 1] * d1[:, 0]
            out.append(xy[cross < 0])
    return np.concatenate(out) if out else np.zeros((0, 2))


def _attach(
    walkable: shapely.Geometry, free: shapely.Geometry, p: NDArray[np.float64]
) -> NDArray[np.float64] | None:
    """The point where ``p`` joins the eroded region: itself, its nearest free point, or None."""
    if shapely.covers(free, Point(p)):
        return p
    q = np.asarray(nearest_points(free, Point(p))[0].coords[0])
    if _segments_covered(walkable, p[None], q[None])[0]:
        return q
    return None


@dataclass(frozen=True)
class _Roadmap:
    """The visibility graph of a floor plan's walkable area eroded by one clearance.

    Attributes:
        free: the eroded walkable area.
        sight: ``free`` grown by a hair and prepared, for visibility tests.
        sight_edges: (E, 2, 2) edges of ``sight``'s rings.
        nodes: (n, 2) reflex vertices of ``free``.
        edges: (m, 2) index pairs (i < j, sorted) of mutually visible nodes.
        weights: (m,) their distances.
        adjacency: the edges as the rows of a sparse matrix (row pointers,
            columns, weights: each node's higher neighbours, ascending), then
            the same of its transpose (the lower neighbours), for
            :func:`_node_rows`.
    """

    free: shapely.Geometry
    sight: shapely.Geometry
    sight_edges: NDArray[np.float64]
    nodes: NDArray[np.float64]
    edges: NDArray[np.intp]
    weights: NDArray[np.float64]
    adjacency: tuple[NDArray[np.int32], NDArray[np.int32], NDArray[np.float64], ...]
    # Recent route ends: where each joins ``free`` and which nodes it sees from
    # there. A route of many legs starts each leg where the last one ended.
    _ends: dict[bytes, tuple[NDArray[np.float64] | None, NDArray[np.bool_] | None]] = field(
        default_factory=dict, repr=False, compare=False
    )

    def sightlines(
        self, plan: FloorPlan, p: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64] | None, NDArray[np.bool_] | None]:
        """Where ``p`` joins the eroded area (None if it cannot) and which nodes are
        visible from there."""
        key = np.asarray(p, dtype=float).tobytes()
        if key not in self._ends:
            q = _attach(plan.walkable, self.free, p)
            seen = None
            if q is not None:
                from_q = np.broadcast_to(q, self.nodes.shape)
                seen = _visible(self.sight, from_q, self.nodes, self.sight_edges)
            if len(self._ends) >= 4:
                del self._ends[next(iter(self._ends))]
            self._ends[key] = (q, seen)
        return self._ends[key]

    @classmethod
    def build(cls, plan: FloorPlan, clearance: float) -> _Roadmap:
        free = plan.walkable.buffer(-clearance, join_style="mitre", mitre_limit=2.0)
        sight = free.buffer(_VISIBILITY_TOL_M, join_style="mitre")
        shapely.prepare(sight)
        sight_edges = _ring_edges(sight)
        nodes = _reflex_vertices(free)
        i, j = np.triu_indices(len(nodes), k=1)
        seen = _visible(sight, nodes[i], nodes[j], sight_edges)
        i, j = i[seen], j[seen]
        weights = np.linalg.norm(nodes[i] - nodes[j], axis=1)
        upper_ptr, lower_ptr = np.zeros((2, len(nodes) + 1), np.int32)
        np.cumsum(np.bincount(i, minlength=len(nodes)), out=upper_ptr[1:])
        np.cumsum(np.bincount(j, minlength=len(nodes)), out=lower_ptr[1:])
        # The pairs are sorted by i, so a stable sort by j keeps each node's
        # lower neighbours ascending.
        by_j = np.argsort(j, kind="stable")
        adjacency = (
            upper_ptr, j.astype(np.int32), weights,
            lower_ptr, i[by_j].astype(np.int32), weights[by_j],
        )  # fmt: skip
        return cls(
            free=free,
            sight=sight,
            sight_edges=sight_edges,
            nodes=nodes,
            edges=np.column_stack([i, j]),
            weights=weights,
            adjacency=adjacency,
        )


# One roadmap per plan and clearance: many routes are planned in each building.
_ROADMAPS: weakref.WeakKeyDictionary[FloorPlan, dict[float, _Roadmap]] = weakref.WeakKeyDictionary()


def _roadmap(plan: FloorPlan, clearance: float) -> _Roadmap:
    per_plan = _ROADMAPS.setdefault(plan, {})
    if clearance not in per_plan:
        per_plan[clearance] = _Roadmap.build(plan, clearance)
    return per_plan[clearance]


def _visible(
    sight: shapely.Geometry,
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    edges: NDArray[np.float64] | None = None,
) -> NDArray[np.bool_]:
    """(N,) True where segment a→b stays in ``sight``.

    Two cheap tests settle most pairs before the exact one: a segment whose
    midpoint is outside, or that properly crosses an edge of the boundary
    (``sight``'s ring edges, computed unless given), leaves the region.
    """
    mid = 0.5 * (a + b)
    out = shapely.contains_xy(sight, mid[:, 0], mid[:, 1])
    if edges is None:
        edges = _ring_edges(sight)
    if len(edges):
        crossed = np.empty(int(out.sum()))
        _crosses_any(
            np.ascontiguousarray(a[out]),
            np.ascontiguousarray(b[out]),
            np.ascontiguousarray(edges[:, 0]),
            np.ascontiguousarray(edges[:, 1]),
            crossed,
        )
        out[out] = crossed == 0.0
    out[out] = _segments_covered(sight, a[out], b[out])
    return out


def _ring_edges(region: shapely.Geometry) -> NDArray[np.float64]:
    """(E, 2, 2) edges of every ring of ``region``."""
    rings = [
        np.asarray(ring.coords)
        for poly in _polygons(region)
        for ring in [poly.exterior, *poly.interiors]
    ]
    if not rings:
        return np.zeros((0, 2, 2))
    return np.concatenate([np.stack([xy[:-1], xy[1:]], axis=1) for xy in rings])


@numba.njit(cache=True, error_model="numpy")
def _crosses_any(p0, p1, ea, eb, out):  # pragma: no cover - compiled
    """out[i] = 1.0 where segment p0[i]→p1[i] properly crosses one of the edges ea→eb."""
    for i in range(p0.shape[0]):
        x0, y0, x1, y1 = p0[i, 0], p0[i, 1], p1[i, 0], p1[i, 1]
        lo_x, hi_x = min(x0, x1), max(x0, x1)
        lo_y, hi_y = min(y0, y1), max(y0, y1)
        ex, ey = x1 - x0, y1 - y0
        out[i] = 0.0
        for j in range(ea.shape[0]):
            ax, ay, bx, by = ea[j, 0], ea[j, 1], eb[j, 0], eb[j, 1]
            if max(ax, bx) < lo_x or min(ax, bx) > hi_x or max(ay, by) < lo_y or min(ay, by) > hi_y:
                continue
            dx, dy = bx - ax, by - ay
            if (dx * (y0 - ay) - dy * (x0 - ax)) * (dx * (y1 - ay) - dy * (x1 - ax)) >= 0:
                continue
            if (ex * (ay - y0) - ey * (ax - x0)) * (ex * (by - y0) - ey * (bx - x0)) >= 0:
                continue
            out[i] = 1.0
            break


@numba.njit(cache=True)
def _node_rows(
    up_ptr, up_col, up_w, lo_ptr, lo_col, lo_w, w_a, w_b, w_ab, indptr, indices, data
):  # pragma: no cover - compiled
    """The both-ways CSR rows of a route's graph: start 0, goal 1, roadmap nodes 2...

    Each row is the node's row of the one-way matrix (edges to higher
    indices, ascending) followed by its row of the transpose (edges from
    lower indices, ascending). The start's edges: to the goal if ``w_ab`` ≥ 0,
    to roadmap node r (graph node r + 2) if ``w_a[r]`` ≥ 0, of that length;
    the goal's likewise from ``w_b``; the roadmap's from ``up_*`` (one-way
    rows, i < j) and ``lo_*`` (their transpose).
    """
    m = len(up_ptr) - 1
    k = 0
    indptr[0] = 0
    if w_ab >= 0.0:
        indices[k], data[k] = 1, w_ab
        k += 1
    for r in range(m):
        if w_a[r] >= 0.0:
            indices[k], data[k] = r + 2, w_a[r]
            k += 1
    indptr[1] = k
    for r in range(m):
        if w_b[r] >= 0.0:
            indices[k], data[k] = r + 2, w_b[r]
            k += 1
    if w_ab >= 0.0:
        indices[k], data[k] = 0, w_ab
        k += 1
    indptr[2] = k
    for r in range(m):
        for e in range(up_ptr[r], up_ptr[r + 1]):
            indices[k], data[k] = up_col[e] + 2, up_w[e]
            k += 1
        if w_a[r] >= 0.0:
            indices[k], data[k] = 0, w_a[r]
            k += 1
        if w_b[r] >= 0.0:
            indices[k], data[k] = 1, w_b[r]
            k += 1
        for e in range(lo_ptr[r], lo_ptr[r + 1]):
            indices[k], data[k] = lo_col[e] + 2, lo_w[e]
            k += 1
        indptr[r + 3] = k


def _shortest_path(
    plan: FloorPlan,
    start: NDArray[np.float64],
    goal: NDArray[np.float64],
    clearance: float,
    label: str,
) -> NDArray[np.float64]:
    ends = np.stack([start, goal])
    for which, p, ok in zip(("start", "goal"), ends, plan.is_walkable(ends), strict=True):
        if not ok:
            raise RouteError(f"{label}: {which} {p.tolist()} is not in the walkable area")
    if np.linalg.norm(goal - start) <= _SAME_POINT_M:
        raise RouteError(f"{label}: start and goal are the same point {start.tolist()}")
    no_path = RouteError(
        f"{label}: no walkable path from start {start.tolist()} to goal {goal.tolist()} "
        f"keeping {clearance:g} m from walls and obstacles"
    )
    road = _roadmap(plan, clearance)
    if road.free.is_empty:
        raise no_path
    (a, seen_a), (b, seen_b) = road.sightlines(plan, start), road.sightlines(plan, goal)
    if a is None or b is None:
        raise no_path
    # Nodes 0 and 1 are where start and goal join the eroded area, then the
    # roadmap's. Each edge is stored in both directions and searched as a
    # directed graph: scipy's undirected search would build the transpose per
    # call and scan each node's row of the matrix, then of its transpose. The
    # rows here are those two concatenated (:func:`_node_rows`), so the search
    # relaxes the same edges in the same order and finds the same path, ties
    # included.
    n = len(road.nodes) + 2
    pts = np.concatenate([np.stack([a, b]), road.nodes])
    direct = _visible(road.sight, a[None], b[None], road.sight_edges)[0]
    from_a = np.flatnonzero(seen_a) + 2
    from_b = np.flatnonzero(seen_b) + 2
    # The start's and goal's edges as a graph of start→goal, start→nodes,
    # goal→nodes would have them (the same distances).
    targets = np.concatenate([[1], from_a, from_b] if direct else [from_a, from_b])
    src = np.zeros(len(targets), np.intp)
    src[len(targets) - len(from_b) :] = 1
    w = np.linalg.norm(pts[src] - pts[targets], axis=1)
    w_a, w_b = np.full(n - 2, -1.0), np.full(n - 2, -1.0)  # -1: not seen
    w_a[seen_a] = w[int(direct) : int(direct) + len(from_a)]
    w_b[seen_b] = w[len(targets) - len(from_b) :]
    size = 2 * (len(targets) + len(road.weights))  # every edge twice
    indptr, indices, data = np.empty(n + 1, np.int32), np.empty(size, np.int32), np.empty(size)
    w_ab = w[0] if direct else -1.0
    _node_rows(*road.adjacency, w_a, w_b, w_ab, indptr, indices, data)
    graph = csr_matrix((data, indices, indptr), shape=(n, n))
    dist, pred = dijkstra(graph, directed=True, indices=0, return_predecessors=True)
    if not math.isfinite(dist[1]):
        raise no_path
    chain = [1]
    while chain[-1] != 0:
        chain.append(int(pred[chain[-1]]))
    return _dedupe(np.concatenate([start[None], pts[chain[::-1]], goal[None]]))
