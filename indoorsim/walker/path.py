"""Path: the route's polyline smoothed into the line a pedestrian walks.

:meth:`SmoothPath.build` and :meth:`SmoothPath.keep_off_walls` are the first
stage of :func:`~indoorsim.walker.gait.walk` (DESIGN §5, numbers from REALISM
§5). Route vertices closer than 5 cm to the previous one are dropped first:
such legs are no walk. Each corner of the route then becomes a curve whose
curvature rises and falls as sin² along it, so the heading turns with a
bell-shaped yaw rate (peak twice the mean) and the curve cuts the corner half
as much as a circular arc of the same length. A 90° corner preferably takes
``turn_steps_per_90deg`` steps (others scale with the root of the angle); the
curve is shortened where the legs are short or where it would come closer to
walls than ``wall_distance_m`` (or than the polyline itself does). Corners
sharper than ``pivot_turn_deg``, or so cramped that they could only be walked
at a crawl, are taken standing: stop, turn on the spot, go on (turning on the
spot takes no modelled steps). Where the path still passes closer than
``wall_distance_m`` to a wall, pillar or desk, it is bent smoothly away from
it, as people keep their distance.

The result is a set of knots along the path's length: position, heading
(without the turns on the spot, which the walker makes in time while
standing) and curvature, which the speed profile and the steps of
:mod:`indoorsim.walker.gait` read by distance. Nothing here is random.

Frames: building frame; heading in radians from +x, counter-clockwise,
unwrapped.
"""

from __future__ import annotations

import functools
import math
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numba
import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import PPoly
from scipy.ndimage import gaussian_filter1d

if TYPE_CHECKING:
    from indoorsim.world.plan import FloorPlan

__all__ = ["SmoothPath", "cumsum0", "first_pass", "hermite_spline", "smootherstep"]

# Corner curves are sampled this often along their length (m).
_CURVE_DS_M = 0.005
# Geometry search for a corner's curve: shrink factor and number of tries.
_TURN_SHRINK, _TURN_TRIES = 0.75, 10
# A corner whose curve could only be walked slower than this (m/s) within the
# yaw-rate limit is turned on the spot.
_PIVOT_BELOW_MPS = 0.3
# Route vertices closer than this (m) to the previous one are dropped: such
# legs (e.g. where a start near a wall joins the planned path) are no walk.
_MIN_LEG_M = 0.05
# Keeping off walls: resampling step (m), smoothing of the push along the path
# (σ, m) and the number of push-and-smooth rounds.
_KEEP_DS_M, _KEEP_SMOOTH_M, _KEEP_ROUNDS = 0.02, 0.3, 8
# The first look for walls near the path reaches this much farther (m), to
# know which points cannot come too close in the rounds that follow.
_KEEP_SCAN_M = 0.1


@dataclass(frozen=True)
class SmoothPath:
    """The smoothed route as knots along its length, linearly interpolated
    (the heading cubically, with the curvature as its slope, so that the
    heading rate is continuous).

    ``theta`` leaves out the turns taken on the spot (``pivots``: distance
    along the path, heading change); those are added in time while the walker
    stands at the corner.
    """

    s: NDArray[np.float64]
    """(n,) distance along the path at each knot (m), increasing."""
    xy: NDArray[np.float64]
    """(n, 2) knot positions in the building frame (m)."""
    theta: NDArray[np.float64]
    """(n,) heading at each knot (rad from +x, unwrapped), without the pivots."""
    kappa: NDArray[np.float64]
    """(n,) curvature at each knot (rad/m): the heading's slope."""
    pivots: tuple[tuple[float, float], ...]
    """Turns on the spot: (distance along the path, heading change in rad)."""

    @property
    def length(self) -> float:
        """Length of the path (m)."""
        return float(self.s[-1])

    def position(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        """(len(s), 2) positions at the distances ``s`` along the path."""
        return np.column_stack(
            [np.interp(s, self.s, self.xy[:, 0]), np.interp(s, self.s, self.xy[:, 1])]
        )

    def heading(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        """Heading (without the pivots) at the distances ``s``, C¹ through the knots."""
        return hermite_spline(self.s, self.theta, self.kappa)(s)

    def max_curvature(self, s: NDArray[np.float64], half_width: float) -> NDArray[np.float64]:
        """Largest |curvature| within ``half_width`` of each distance in ``s`` (exact;
        ``s`` ascending).

        Curvature is linear between knots, so the maximum over a window is at a
        knot inside it or at one of its ends. The knots inside are covered by a
        sliding-window maximum, so even a curve far shorter than the window is
        never missed.
        """
        a, b = s - half_width, s + half_width
        edges = np.maximum(
            np.abs(np.interp(a, self.s, self.kappa)), np.abs(np.interp(b, self.s, self.kappa))
        )
        out = np.empty(len(s))
        first = int(np.searchsorted(self.s, a[0])) if len(s) else 0
        _window_max(self.s, self.kappa, first, a, b, edges, out)
        return out

    def keep_off_walls(self, plan: FloorPlan, distance: float) -> SmoothPath:
        """This path, bent smoothly away from the walkable area's boundary where
        it comes closer than ``distance``.

        Each round pushes every point that is too close straight away from its
        nearest boundary point by its shortfall, and smooths the pushes along
        the path with a Gaussian (σ = 0.3 m) so the track stays smooth; pushes
        from opposite walls cancel, so a narrow passage is walked in its
        middle. Smoothing spreads a short push thin, so a sharp corner is
        cleared only partly: the pymunk body is the hard limit. Headings turn by
        the angle the push adds to the path's direction. Returns the path
        unchanged when nothing is too close.
        """
        if distance <= 0 or len(plan.walkable_edges) == 0:
            return self
        # Which metres of the path come near anything? One cheap query on points
        # every 0.2 m (with half that as margin for the chords between them).
        metres = math.ceil(self.length)
        coarse = self.position(np.minimum(np.linspace(0.0, metres, 5 * metres + 1), self.length))
        close = ~np.isnan(plan.nearest_boundary(coarse, distance + 0.11)[:, 0])
        hit = np.unique(np.minimum(np.flatnonzero(close) // 5, metres - 1)).astype(float)
        if len(hit) == 0:
            return self
        n = max(2, math.ceil(self.length / _KEEP_DS_M) + 1)
        s = np.linspace(0.0, self.length, n)
        # Pivot corners become knots (in place of their nearest grid point, so
        # the spacing stays even).
        for p, _ in self.pivots:
            s[np.clip(round(p / self.length * (n - 1)), 1, n - 2)] = p
        base = self.position(s)
        offset = np.zeros_like(base)
        # Points that may need a push: the hit metres and the smoothing's reach.
        reach = 4.0 * _KEEP_SMOOTH_M
        cover = np.zeros(len(s) + 1, dtype=int)
        np.add.at(cover, np.searchsorted(s, hit - reach), 1)
        np.add.at(cover, np.searchsorted(s, hit + 1.0 + reach), -1)
        watch = np.flatnonzero(np.cumsum(cover)[:-1] > 0)
        sigma = _KEEP_SMOOTH_M / _KEEP_DS_M
        # One scan a little beyond ``distance`` gives each watched point its
        # slack: how much nearer the boundary it would have to come to be too
        # close. A point moves by its offset (at most |x| + |y| of it), so only
        # points whose offset has used up their slack can be too close; only
        # those are queried (the rest would surely find nothing: the margin
        # covers rounding), which gives the same pushes as querying them all.
        base_w = base[watch]
        scan_m = distance + _KEEP_SCAN_M
        seen = plan.nearest_boundary(base_w, scan_m)
        gap0 = np.where(np.isnan(seen[:, 0]), scan_m, np.linalg.norm(base_w - seen, axis=1))
        slack = gap0 - distance - 1e-6
        for _ in range(_KEEP_ROUNDS):
            maybe, pts = _maybe_close(base, offset, watch, slack)
            # Each point is pushed from its nearest boundary point only.
            nearest = plan.nearest_boundary(pts, distance)
            near = np.flatnonzero(~np.isnan(nearest[:, 0]))
            if len(near) == 0:
                break
            away = pts[near] - nearest[near]
            gap = np.linalg.norm(away, axis=1)
            scale = (distance - gap) / np.maximum(gap, 1e-12)
            _smooth_pushes(watch[maybe[near]], away * scale[:, None], sigma, offset)
        if not offset.any():
            return self
        moved = base + offset
        d_old, d_new = np.diff(base, axis=0), np.diff(moved, axis=0)
        s_new = cumsum0(np.linalg.norm(d_new, axis=1))
        # How far the push turns each chord, averaged onto the knots (chords,
        # not central differences, so that a pivot's corner adds no spike).
        turn = np.arctan2(
            d_old[:, 0] * d_new[:, 1] - d_old[:, 1] * d_new[:, 0],
            np.einsum("ij,ij->i", d_old, d_new),
        )
        theta = self.heading(s) + np.r_[turn[0], 0.5 * (turn[:-1] + turn[1:]), turn[-1]]
        return SmoothPath(
            s=s_new,
            xy=moved,
            theta=theta,
            kappa=np.gradient(theta, s_new),
            pivots=tuple((float(np.interp(p, s, s_new)), dth) for p, dth in self.pivots),
        )

    @classmethod
    def build(
        cls,
        pts: NDArray[np.float64],
        plan: FloorPlan,
        *,
        step_m: float,
        omega_lim: float,
        turn_steps_per_90deg: float,
        pivot_turn_deg: float,
        clearance_m: float,
    ) -> SmoothPath:
        """Smooth the polyline ``pts``.

        Args:
            pts: the route's vertices.
            plan: the floor plan, for the clearance of the turns.
            step_m: the cruising step length.
            omega_lim: the yaw rate (rad/s) the turns are planned for.
            turn_steps_per_90deg: preferred length of a 90° turn in cruising
                steps; other turns scale with the square root of their angle.
            pivot_turn_deg: corners sharper than this are turned on the spot.
            clearance_m: distance the curves keep from the walkable area's
                boundary (or as much as the polyline corner keeps).
        """
        pts = _drop_short_legs(pts)
        d = np.diff(pts, axis=0)
        legs = np.linalg.norm(d, axis=1)
        unit = d / legs[:, None]
        ang = np.arctan2(d[:, 1], d[:, 0])
        turns = np.angle(np.exp(1j * np.diff(ang)))  # wrapped to (−π, π]
        boundary = plan.walkable.boundary
        pivot_rad = math.radians(pivot_turn_deg)
        # Knot rows (s, x, y, heading without pivots, curvature), in blocks.
        blocks = [np.array([[0.0, *pts[0], ang[0], 0.0]])]
        pivots: list[tuple[float, float]] = []
        theta = float(ang[0])

        def line_to(p: NDArray[np.float64]) -> None:
            s0, x0, y0 = blocks[-1][-1, :3]
            ds = math.hypot(p[0] - x0, p[1] - y0)
            if ds > 1e-12:
                blocks.append(np.array([[s0 + ds, p[0], p[1], theta, 0.0]]))

        # The corners turned while walking, and their curves' lengths (found
        # for all corners at once).
        turned = np.flatnonzero((np.abs(turns) >= 1e-9) & (np.abs(turns) <= pivot_rad))
        room = np.minimum(
            np.where(turned == 0, legs[turned], 0.5 * legs[turned]),
            np.where(turned + 2 == len(legs), legs[turned + 1], 0.5 * legs[turned + 1]),
        )
        fitted = np.full(len(turns), np.nan)
        fitted[turned] = _turn_lengths(
            turns[turned],
            (pts[turned + 1], unit[turned], unit[turned + 1]),
            turn_steps_per_90deg * np.sqrt(np.abs(turns[turned]) / (math.pi / 2)) * step_m,
            room,
            boundary,
            clearance_m,
        )

        # Where the curve would have to be so tight that it could only be
        # walked at a crawl, people stop and turn on the spot instead. The
        # other corners' curves (their unit turns computed together).
        curves = {}
        for j in turned.tolist():
            phi, length = turns[j], fitted[j]
            if omega_lim * length / (2.0 * abs(phi)) >= _PIVOT_BELOW_MPS:
                curves[j] = (float(phi), max(9, math.ceil(length / _CURVE_DS_M) + 1))
        unit_turns = dict(zip(curves, _unit_turns(list(curves.values())), strict=True))

        for j, phi in enumerate(turns):
            vertex = pts[j + 1]
            if abs(phi) < 1e-9:  # collinear: nothing to turn
                continue
            if j not in curves:  # sharper than a pivot turn, or too cramped to walk
                line_to(vertex)
                pivots.append((float(blocks[-1][-1, 0]), float(phi)))
                continue
            length = fitted[j]
            n = curves[j][1]
            unit_xy, unit_th, unit_ka, tangent = unit_turns[j]
            start = vertex - unit[j] * tangent * length
            line_to(start)
            xy = _place(unit_xy, length, start, float(ang[j]))
            blocks.append(
                np.column_stack(
                    [
                        blocks[-1][-1, 0] + np.linspace(0.0, length, n)[1:],
                        xy[1:],
                        theta + unit_th[1:],
                        unit_ka[1:] / length,
                    ]
                )
            )
            theta += float(phi)
        line_to(pts[-1])
        arr = np.concatenate(blocks)
        return cls(
            s=arr[:, 0], xy=arr[:, 1:3], theta=arr[:, 3], kappa=arr[:, 4], pivots=tuple(pivots)
        )


# ---------------------------------------------------------------------- corners


def _drop_short_legs(pts: NDArray[np.float64]) -> NDArray[np.float64]:
    """The polyline without vertices within _MIN_LEG_M of the one kept before them.

    The end points stay; a vertex just before the end gives way to it.
    """
    # Usually every leg is long enough (with a margin for rounding): then
    # nothing is dropped, and the loop below need not run.
    if len(pts) >= 2 and np.all(np.hypot(*np.diff(pts, axis=0).T) > _MIN_LEG_M * (1.0 + 1e-9)):
        return pts.copy()
    keep = [0]
    for i in range(1, len(pts) - 1):
        if np.linalg.norm(pts[i] - pts[keep[-1]]) >= _MIN_LEG_M:
            keep.append(i)
    if len(keep) > 1 and np.linalg.norm(pts[-1] - pts[keep[-1]]) < _MIN_LEG_M:
        keep.pop()
    return pts[[*keep, len(pts) - 1]]


_UnitTurn = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], float]


@functools.lru_cache(maxsize=64)
def _turn_grid(n: int) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """What a unit turn at n points takes from its parameter alone: u (4(n − 1) + 1
    points on [0, 1]), u − sin(2πu)/2π, and sin²(πu) at every 4th u."""
    u = np.linspace(0.0, 1.0, 4 * (n - 1) + 1)
    shape = u - np.sin(2.0 * np.pi * u) / (2.0 * np.pi)
    bell = np.sin(np.pi * u[::4]) ** 2
    for a in (u, shape, bell):
        a.flags.writeable = False
    return u, shape, bell


# Unit turns by (φ, n), most recently used last: routes pass many of their
# corners more than once. The lock keeps the bookkeeping whole under threads.
_UNIT_TURNS: dict[tuple[float, int], _UnitTurn] = {}
_UNIT_TURNS_SIZE = 256
_UNIT_TURNS_LOCK = threading.Lock()


def _unit_turns(keys: list[tuple[float, int]]) -> list[_UnitTurn]:
    """Turns by φ rad over unit length, from the origin heading +x, at n points,
    for each (φ, n) in ``keys``.

    Curvature 2φ·sin²(πu) for u in [0, 1], hence heading φ·(u − sin(2πu)/2π).
    Those not cached are computed together: the headings' cosines and sines
    in one call, the trapezoid integrals of the turns side by side in one
    array (each row's cumulative sum is that of the turn alone, so the same
    values as one turn at a time). Read-only arrays.

    Returns:
        For each key: (n, 2) points, (n,) heading, (n,) curvature, and the
        tangent length: the distance from either end to the corner where the
        two legs meet.
    """
    with _UNIT_TURNS_LOCK:
        found = {key: _UNIT_TURNS.pop(key) for key in keys if key in _UNIT_TURNS}
        _UNIT_TURNS.update(found)  # now the most recent
    missing = list(dict.fromkeys(key for key in keys if key not in found))
    if missing:
        grids = [_turn_grid(n) for _, n in missing]
        sizes = np.array([len(u) for u, _, _ in grids])
        theta = np.repeat([phi for phi, _ in missing], sizes) * np.concatenate(
            [shape for _, shape, _ in grids]
        )
        # The turns as rows, padded with u = 1 (no further area) after their ends.
        inside = np.arange(sizes.max()) < sizes[:, None]
        u = np.ones(inside.shape)
        u[inside] = np.concatenate([grid_u for grid_u, _, _ in grids])
        cos_sin = np.zeros((2, *inside.shape))
        cos_sin[:, inside] = np.stack([np.cos(theta), np.sin(theta)])
        xy = cumulative_trapezoid(cos_sin, u[None], initial=0.0)
        starts = np.cumsum(sizes) - sizes
        for k, (phi, n) in enumerate(missing):
            turn_xy = np.ascontiguousarray(xy[:, k, : sizes[k] : 4].T)
            turn_theta = theta[starts[k] : starts[k] + sizes[k] : 4].copy()
            kappa = 2.0 * phi * grids[k][2]
            for a in (turn_xy, turn_theta, kappa):
                a.flags.writeable = False
            # The curve is symmetric about the corner's bisector: its end lies
            # at corner + T·(cos φ, sin φ) with the corner at (T, 0).
            tangent = float(turn_xy[-1, 0] / (1.0 + math.cos(phi)))
            found[(phi, n)] = (turn_xy, turn_theta, kappa, tangent)
        with _UNIT_TURNS_LOCK:
            for key in missing:
                _UNIT_TURNS[key] = found[key]
            while len(_UNIT_TURNS) > _UNIT_TURNS_SIZE:
                del _UNIT_TURNS[next(iter(_UNIT_TURNS))]
    return [found[key] for key in keys]


def _place(
    unit_xy: NDArray[np.float64], length: float, start: NDArray[np.float64], angle: float
) -> NDArray[np.float64]:
    """Scale a unit curve to ``length``, rotate it to ``angle`` and move it to ``start``."""
    c, s = math.cos(angle), math.sin(angle)
    return start + (unit_xy * length) @ np.array([[c, s], [-s, c]])


def _turn_lengths(
    phi: NDArray[np.float64],
    corners: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
    preferred: NDArray[np.float64],
    room: NDArray[np.float64],
    boundary: shapely.Geometry,
    clearance: float,
) -> NDArray[np.float64]:
    """Longest curve length up to ``preferred`` that fits the legs and the walls, for
    each corner (turn ``phi``, vertex, unit directions in and out, all (m, ...)).

    The curve must keep ``clearance`` from the walkable area's boundary, or at
    least as much as the polyline corner it replaces keeps. Each corner's
    search shrinks its curve until it fits (at most _TURN_TRIES times); the
    corners still searching are tested together, one round per try, with the
    arithmetic of one corner at a time (so the same lengths).
    """
    vertex, d_in, d_out = corners
    if len(phi) == 0:
        return np.zeros(0)
    # The turns at 33 points (as _unit_turns computes them), all at once.
    u = np.linspace(0.0, 1.0, 129)
    theta = phi[:, None] * (u - np.sin(2.0 * np.pi * u) / (2.0 * np.pi))
    xy = cumulative_trapezoid(np.stack([np.cos(theta), np.sin(theta)]), u, initial=0.0)
    unit_xy = np.moveaxis(xy[:, :, ::4], 0, -1)
    tangent = unit_xy[:, -1, 0] / (1.0 + np.array([math.cos(p) for p in phi.tolist()]))
    length = np.minimum(preferred, room / tangent)
    rotation = np.array(
        [
            [[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]]
            for a in np.arctan2(d_in[:, 1], d_in[:, 0]).tolist()
        ]
    ).reshape(-1, 2, 2)
    active = np.arange(len(phi))
    for _ in range(_TURN_TRIES):
        k = active
        start = vertex[k] - d_in[k] * tangent[k, None] * length[k, None]
        end = vertex[k] + d_out[k] * tangent[k, None] * length[k, None]
        corner_xy = np.stack([start, vertex[k], end], axis=1)
        # Only the boundary near the corner matters: distances beyond the
        # clearance are never binding.
        lo, hi = corner_xy.min(axis=1) - clearance, corner_xy.max(axis=1) + clearance
        near = np.array(
            [
                shapely.clip_by_rect(boundary, x0, y0, x1, y1)
                for x0, y0, x1, y1 in np.column_stack([lo, hi]).tolist()
            ]
        )
        open_ = ~shapely.is_empty(near)
        k, near, start, corner_xy = k[open_], near[open_], start[open_], corner_xy[open_]
        need = np.minimum(clearance, shapely.distance(near, shapely.linestrings(corner_xy)))
        # The curves, scaled, rotated and moved into place (as _place does).
        curve = start[:, None, :] + (unit_xy[k] * length[k, None, None]) @ rotation[k]
        fits = shapely.distance(near, shapely.linestrings(curve)) >= need - 1e-9
        active = k[~fits]
        length[active] *= _TURN_SHRINK
        if len(active) == 0:
            break
    return length


# ---------------------------------------------------------------------- keeping off walls


def _smooth_pushes(
    where: NDArray[np.intp], push: NDArray[np.float64], sigma: float, out: NDArray[np.float64]
) -> None:
    """Add to the (n, 2) ``out`` the pushes placed at rows ``where`` (sorted) and
    smoothed along the path (Gaussian of ``sigma`` samples, nearest-value ends).

    Each stretch of pushed rows is filtered on its own, from 2·radius before its
    first push to 2·radius after its last (elsewhere the result is zero), and
    overlapping stretches add up: :func:`_filter_stretches`, which does
    ``scipy.ndimage.gaussian_filter1d``'s arithmetic in one compiled call
    instead of one scipy call per stretch, and adds each row in place (the
    same sums as adding the smoothed pushes as a whole).
    """
    n = len(out)
    weights = _gaussian_weights(sigma)
    radius = len(weights) - 1
    breaks = np.flatnonzero(np.diff(where) > 2 * radius + 1)
    firsts, lasts = np.r_[0, breaks + 1], np.r_[breaks, len(where) - 1]
    lo = np.maximum(0, where[firsts] - 2 * radius)
    hi = np.minimum(n, where[lasts] + 2 * radius + 1)
    _filter_stretches(where, np.ascontiguousarray(push), firsts, lasts, lo, hi, weights, out)


@numba.njit(cache=True, error_model="numpy")
def _maybe_close(base, offset, watch, slack):  # pragma: no cover - compiled
    """The watched rows (indices into ``watch``) whose offset has used up their slack,
    |x| + |y| ≥ slack, and where those points are now (base + offset): one pass
    instead of gathering every watched row's offset."""
    rows = np.empty(len(watch), dtype=np.intp)
    count = 0
    for i in range(len(watch)):
        r = watch[i]
        if abs(offset[r, 0]) + abs(offset[r, 1]) >= slack[i]:
            rows[count] = i
            count += 1
    pts = np.empty((count, 2))
    for k in range(count):
        r = watch[rows[k]]
        pts[k, 0] = base[r, 0] + offset[r, 0]
        pts[k, 1] = base[r, 1] + offset[r, 1]
    return rows[:count], pts


@functools.lru_cache(maxsize=8)
def _gaussian_weights(sigma: float) -> NDArray[np.float64]:
    """Weights of ``gaussian_filter1d(x, sigma)`` (default truncation) from the centre
    outwards, read off its response to a unit impulse (exact: all other terms are 0)."""
    radius = int(4.0 * sigma + 0.5)
    impulse = np.zeros(2 * radius + 1)
    impulse[radius] = 1.0
    weights = gaussian_filter1d(impulse, sigma)[radius:]
    weights.flags.writeable = False
    return weights


@numba.njit(cache=True, error_model="numpy")
def _filter_stretches(where, push, firsts, lasts, lo, hi, w, out):  # pragma: no cover - compiled
    """out[lo[c]:hi[c]] += stretch c (pushes where[firsts[c]:lasts[c] + 1]) filtered.

    Row i of a stretch x (extended by its end values) becomes
    x[i]·w[0] + Σ (x[i − j] + x[i + j])·w[j], j from the radius down to 1:
    gaussian_filter1d's sum, in its order, so the result is the same to the
    bit. Rows farther than the radius from every push are 0 and add nothing
    (``out`` starts at +0.0 and so never holds −0.0), so they are skipped. The
    rows one stretch reaches lie more than a radius from the next stretch's
    pushes, so each row gets at most one sum: adding in place gives what adding
    all the smoothed pushes at once would. The loop over rows is innermost,
    where the compiler vectorises it.
    """
    r = len(w) - 1
    for c in range(len(firsts)):
        first, last, a, b = firsts[c], lasts[c], lo[c], hi[c]
        size = b - a
        # The rows within reach of a push (relative to a).
        k0, k1 = max(where[first] - r, a) - a, min(where[last] + r + 1, b) - a
        m = k1 - k0
        for col in range(2):
            x = np.zeros(size + 2 * r)  # the stretch, padded by r at both ends
            for i in range(first, last + 1):
                x[where[i] - a + r] = push[i, col]
            x[:r] = x[r]
            x[size + r :] = x[size + r - 1]
            start = k0 + r  # x index of row k0
            acc = np.empty(m)
            for k in range(m):
                acc[k] = x[start + k] * w[0]
            for j in range(r, 0, -1):
                left, right, wj = x[start - j : start - j + m], x[start + j : start + j + m], w[j]
                for k in range(m):
                    acc[k] += (left[k] + right[k]) * wj
            dest = out[a + k0 : a + k1, col]
            for k in range(m):
                dest[k] += acc[k]


# ---------------------------------------------------------------------- curvature


@numba.njit(cache=True, error_model="numpy")
def _window_max(knots, value, first, a, b, floor, out):  # pragma: no cover - compiled
    """out[i] = max(floor[i], |value| at the knots in [a[i], b[i]]), for ascending a
    and b; ``first`` is the first knot at or after a[0].

    A monotone deque of knot indices (|value| decreasing from its head) holds
    the candidates of the current window; each knot enters and leaves it once.
    """
    queue = np.empty(len(knots) - first, dtype=np.intp)
    head, tail, nxt = 0, 0, first
    for i in range(len(a)):
        while nxt < len(knots) and knots[nxt] <= b[i]:
            while tail > head and abs(value[queue[tail - 1]]) <= abs(value[nxt]):
                tail -= 1
            queue[tail] = nxt
            tail += 1
            nxt += 1
        while tail > head and knots[queue[head]] < a[i]:
            head += 1
        out[i] = floor[i]
        if tail > head and abs(value[queue[head]]) > out[i]:
            out[i] = abs(value[queue[head]])


# ---------------------------------------------------------------------- shared helpers


def hermite_spline(
    x: NDArray[np.float64], y: NDArray[np.float64], dydx: NDArray[np.float64]
) -> PPoly:
    """``CubicHermiteSpline(x, y, dydx)`` for 1-D data: the same coefficients, without
    its input checks (but for increasing ``x``) and array-API dispatch."""
    dx = np.diff(x)
    if not np.all(dx > 0):
        raise ValueError("`x` must be strictly increasing sequence.")
    slope = np.diff(y) / dx
    t = (dydx[:-1] + dydx[1:] - 2 * slope) / dx
    c = np.stack((t / dx, (slope - dydx[:-1]) / dx - t, dydx[:-1], y[:-1]))
    return PPoly.construct_fast(c, np.ascontiguousarray(x, dtype=float))


def cumsum0(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.r_[0.0, np.cumsum(x)]``, without np.r_'s parsing (it costs more than the sum)."""
    out = np.empty(len(x) + 1)
    out[0] = 0.0
    np.cumsum(x, out=out[1:])
    return out


def first_pass(gap: NDArray[np.float64], slack: float) -> int:
    """Index of the first pass by a point along a track, given the track's distance
    ``gap`` to it at each sample: the closest sample of the first run of samples within
    ``slack`` of the closest of all — not a later pass that comes a little closer."""
    near = np.flatnonzero(gap <= gap.min() + slack)
    breaks = np.flatnonzero(np.diff(near) > 1)
    end = near[breaks[0]] + 1 if len(breaks) else near[-1] + 1
    return int(near[0] + np.argmin(gap[near[0] : end]))


def smootherstep(x: ArrayLike) -> NDArray[np.float64]:
    """0 → 1 over x in [0, 1], 6x⁵ − 15x⁴ + 10x³, flat (zero slope and curvature)
    at both ends: blending with it keeps a C² motion C².

    >>> smootherstep([-1.0, 0.5, 2.0]).tolist()
    [0.0, 0.5, 1.0]
    """
    x = np.clip(x, 0.0, 1.0)
    return x**3 * (x * (6.0 * x - 15.0) + 10.0)
