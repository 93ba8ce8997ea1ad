"""Pacing along the walked path: the speed profile under a cap, where the route's points
fall on the path, each leg paced to its time, and the walker slowing at route points.

:func:`~indoorsim.walker.gait.walk` plans every walking bout's speed with
:func:`speed_profile`; a route with ``leg_speeds`` (a real trace's twin) has its legs'
speed caps found by :func:`paced_legs`; :func:`mark_slowing` dips the cruising-speed
factor at the route's inner points, where a surveyor taps a waypoint as they pass it or
a pedestrian slows at a junction or a door.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Protocol

import numba
import numpy as np
from numpy.typing import NDArray

from indoorsim.walker.path import SmoothPath, cumsum0, first_pass, smootherstep
from indoorsim.walker.route import Route

if TYPE_CHECKING:
    from indoorsim.walker.gait import WalkerParams

__all__ = ["leg_ends", "mark_slowing", "paced_legs", "speed_profile"]

# Pacing a route's legs (paced_legs): the grid of its speed profile (m), the
# fixed-point passes (each leaves a leg within a few per cent of its time), and
# the range of a leg's speed cap (m/s): brisk walking tops out near 2 m/s.
_PACE_DS_M = 0.05
_PACE_PASSES = 12
_PACE_CAP_MPS = (0.15, 2.0)
# Where a route point falls on the walked path (leg_ends): sampled this finely (m),
# the first pass within this of the closest (m; a corner's arc misses its waypoint by
# a few centimetres to decimetres).
_PASS_DS_M = 0.02
_PASS_SLACK_M = 0.5
# A dip of the speed factor at a route point (mark_slowing) gets this many knots on
# either side.
_MARK_KNOTS = 20


class _Dwell(Protocol):
    """Standing at distance ``s`` along the path for ``duration`` s."""

    s: float
    duration: float


def leg_ends(path: SmoothPath, points: NDArray[np.float64]) -> NDArray[np.float64]:
    """(L,) distance along the walked path of each route point: 0, where the path first
    comes closest to each inner point, searched in order from the previous one within a
    leg and a half (:func:`~.path.first_pass`, so that a route coming back past a point
    is not taken for its first pass), the length. An end within :data:`_PASS_SLACK_M`
    of a turn on the spot is put at it: the turn starts the leg after it."""
    ends = np.empty(len(points))
    ends[0], ends[-1] = 0.0, path.length
    legs = np.linalg.norm(np.diff(points, axis=0), axis=1)
    pivots = np.array([s for s, _ in path.pivots])
    for i in range(1, len(points) - 1):
        lo = ends[i - 1]
        hi = min(path.length, lo + 1.5 * legs[i - 1] + 2.0)
        along = np.linspace(lo, hi, max(2, math.ceil((hi - lo) / _PASS_DS_M) + 1))
        gap = np.linalg.norm(path.position(along) - points[i], axis=1)
        ends[i] = along[first_pass(gap, _PASS_SLACK_M)]
        if len(pivots):
            k = int(np.argmin(np.abs(pivots - ends[i])))
            if abs(pivots[k] - ends[i]) <= _PASS_SLACK_M and pivots[k] >= lo:
                ends[i] = pivots[k]
    return ends


def paced_legs(
    path: SmoothPath,
    route: Route,
    ends: NDArray[np.float64],
    dwells: Sequence[_Dwell],
    v_cruise: float,
    omega_lim: float,
    curve_window_m: float,
    speed_factor: tuple[NDArray[np.float64], NDArray[np.float64]],
    params: WalkerParams,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The cruising-speed factor with each leg's own speed cap, set so that every leg
    of the route takes its length over its ``leg_speeds`` entry; ``ends`` is where each
    route point falls on the path (:func:`leg_ends`).

    A leg's mean speed is below its cap: the walker starts, stops and slows for
    turns within it. So the caps are found by fixed-point iteration on the walk's
    speed profile (the bouts' own, :func:`speed_profile`, over the whole path,
    at rest at every dwell, whose time counts to its leg, and the standing
    before the first step to the first leg: a route's time starts at its first
    waypoint, as a surveyor's first mark does): each pass scales a leg's cap by
    the time it took over the time it should. Caps stay within
    :data:`_PACE_CAP_MPS`; a leg too short to reach its speed, or holding more
    standing than its time, takes longer. Deterministic: no random draw.
    """
    assert route.leg_speeds is not None
    target = np.linalg.norm(np.diff(route.points, axis=0), axis=1) / route.leg_speeds
    n = max(2, math.ceil(path.length / _PACE_DS_M))
    grid = np.linspace(0.0, path.length, n + 1)
    leg = np.clip(np.searchsorted(ends, grid, side="right") - 1, 0, len(target) - 1)
    fluctuation = np.interp(grid, *speed_factor)
    curve_cap = omega_lim / np.maximum(path.max_curvature(grid, curve_window_m), 1e-9)
    at = [d.s for d in dwells]
    rest = np.searchsorted(grid, at).clip(0, n)
    standing = np.bincount(
        np.clip(np.searchsorted(ends, at, side="right") - 1, 0, len(target) - 1),
        weights=[d.duration for d in dwells],
        minlength=len(target),
    )
    standing[0] += params.stand_start_s
    cap = np.clip(np.asarray(route.leg_speeds, dtype=float), *_PACE_CAP_MPS)
    v, dtau = np.empty(len(grid)), np.empty(len(grid) - 1)
    for _ in range(_PACE_PASSES):
        v_lim = np.minimum(cap[leg] * fluctuation, curve_cap)
        v_lim[rest] = 0.0
        speed_profile(grid, v_lim, 0.0, 2.0 * params.max_accel_mps2, v, dtau)
        took = np.diff(np.interp(ends, grid, cumsum0(dtau))) + standing
        cap = np.clip(cap * took / target, *_PACE_CAP_MPS)
    return grid, cap[leg] * fluctuation / v_cruise


def mark_slowing(
    ends: NDArray[np.float64],
    speed_factor: tuple[NDArray[np.float64], NDArray[np.float64]],
    slowest: NDArray[np.float64],
    half_length_m: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The cruising-speed factor's knots dipped at each inner route point.

    At the point ``ends[i]`` (distance along the path) the factor is multiplied by
    ``slowest[i - 1]``, and back to 1 at ``half_length_m`` either side along a
    smootherstep, so the speed stays C¹ and the walker's bounded acceleration does the
    rest; where two dips overlap the deeper one holds. Each dip gets
    :data:`_MARK_KNOTS` knots either side.

    Args:
        ends: (L,) distance along the path of every route point (:func:`leg_ends`).
        speed_factor: the factor's knots (distance, factor).
        slowest: (L − 2,) the factor at each inner point, in (0, 1].
        half_length_m: how far either side of a point the slowing reaches.
    """
    s, f = speed_factor
    inner = ends[1:-1]
    offsets = np.linspace(-half_length_m, half_length_m, 2 * _MARK_KNOTS + 1)
    local = (inner[:, None] + offsets).ravel()
    knots = np.union1d(s, np.clip(local, s[0], s[-1]))
    dip = np.ones(len(knots))
    for at, low in zip(inner, slowest, strict=True):
        near = 1.0 - smootherstep(np.abs(knots - at) / half_length_m)
        dip = np.minimum(dip, 1.0 - (1.0 - low) * near)
    return knots, np.interp(knots, s, f) * dip


@numba.njit(cache=True, error_model="numpy")
def speed_profile(grid, v_lim, s_a, two_a, v, dtau):  # pragma: no cover - compiled
    """The bout's speed ``v`` on ``grid`` under the cap ``v_lim``, 0 at both ends, and
    the time ``dtau`` from each grid point to the next.

    The acceleration passes are closed forms of the usual forward/backward
    sweeps, v²(s) ≤ v²(s') + 2a|s − s'|, with x = 2a·(s − s_a):
    w = min(w, x + running min of (w − x)), then the same backwards with
    w + x; v = √max(w, 0), and dtau = 2·Δs / max(v + v_next, 1e-12) (exact
    for constant acceleration between grid points). One pass each, with the
    same operations as the array expressions they replace.
    """
    n = len(grid)
    x = np.empty(n)  # 2a·(s − s_a)
    w = np.empty(n)  # v²: the cap squared, then after each sweep
    for i in range(n):
        x[i] = two_a * (grid[i] - s_a)
        w[i] = 0.0 if i == 0 or i == n - 1 else v_lim[i] * v_lim[i]
    low = np.inf
    for i in range(n):
        low = min(low, w[i] - x[i])
        w[i] = min(w[i], x[i] + low)
    low = np.inf
    for i in range(n - 1, -1, -1):
        low = min(low, w[i] + x[i])
        w[i] = min(w[i], low - x[i])
    for i in range(n):
        v[i] = math.sqrt(max(w[i], 0.0))
    for i in range(n - 1):
        dtau[i] = 2.0 * (grid[i + 1] - grid[i]) / max(v[i + 1] + v[i], 1e-12)
