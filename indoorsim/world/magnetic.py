"""Magnetic field of a building: the Earth's main field plus steel as point dipoles.

B(p) = B_earth + Σ_j μ0/4π · [3(m_j·r̂)r̂ − m_j]/r³,   r = p − q_j.

* **Earth field** from IGRF (``ppigrf``) for the site's latitude, longitude,
  altitude and date, rotated into the building frame by ``site.north_deg`` — or
  the scenario's explicit ``earth_field_uT``.
* **Steel** becomes point dipoles (seeded from the scenario's ``seed``, so the
  building is the same every time it is loaded). Reinforcing steel is bars,
  magnetised along their axes: a bar of volume V along u takes the induced
  moment V·[χ·(H·u)u + χ_t·(H − (H·u)u)] (H = B_earth/μ0; χ along a long bar,
  whose demagnetising factor is near zero, χ_t ≈ 2 across it) and a remanent
  moment along u (:func:`bar_moments`). A structural element — a column's
  storey, a slab's patch, a beam's bay — is magnetised as one, because its bars
  run through it: a uniformly magnetised patch has no field of its own away
  from its edges, so the field comes from where the magnetisation changes, at
  the patches' edges and the laps, and reaches as far as a line of poles does.
  Independent remanence dipole by dipole would instead make every dipole a
  source, a field as rough as the grid. Per source:

  - pillars: a vertical chain of dipoles through the storey below, this one and
    the one above (columns run through the slabs), vertical bars and ties; a
    steel column erected in two-storey lengths is one element below its splice
    and one above (``PillarSpec.splice_z``);
  - slab and beam rebar: a grid of dipoles at the slab's or beam's height, its
    bars a two-way mesh or a beam's longitudinal bars and stirrups;
  - steel furniture (sheet steel): one dipole at half its height, isotropic,
    with a remanent moment in a random direction;
  - explicit dipoles (elevators, machinery) as given.

Evaluation is vectorised over points and dipoles and chunked to bound memory.
Every pairwise term is written through matrix products (see :func:`dipole_field`),
so the inner work runs in BLAS rather than in Python or in many (N, M, 3)
temporaries.

**Along a path** (:meth:`MagneticModel.field_along`, what the simulated
magnetometer reads) the sum is split by distance into three smooth bands, each
evaluated where its resolution needs it:

    B = B_earth + Σ_j [w₀(r_j) + w₁(r_j) + w₂(r_j)]·B_j,   w₀ + w₁ + w₂ = 1,

with w₀ = 1 − S₁(r), w₁ = S₁(r) − S₂(r), w₂ = S₂(r) and S_k a C⁴ step rising
from 0 at a_k to 1 at b_k (:data:`PATH_BANDS`: 1–3 m and 4–10 m).

* The near band (dipoles within 3 m: a few dozen) is summed exactly at every
  sample. It holds everything that varies on the scale of the phone's own
  motion: a dipole at distance r changes over ~r, and real indoor fields over
  0.5–3 m (REALISM §2.2–2.3).
* The mid and far bands hold only dipoles at least 1 m and 4 m away, weighted
  by steps 2 m and 6 m wide, so they are smooth on that scale (a dipole term's
  k-th spatial derivative is ~(k+2)!/2·|B|/r^k). They are summed exactly at
  knots along the path — at most ``PATH_KNOT_TRAVEL_M`` (0.3 m, 1 m) of travel
  at the local top speed and ``PATH_KNOT_GAP_S`` apart, so the knots follow
  the path's own temporal structure — and interpolated with a cubic spline in
  time. What the knots miss of the path (the gait's centimetre oscillations)
  is added to first order: J(t)·(p(t) − P(t)), with P the spline through the
  knot positions and J the band's gradient, computed at sparser knots.

Against the exact sum the result differs by less than 0.01 µT (at most
0.007 µT, measured over 5-minute walks in every carrying mode in a generated
office and car park; tests/world/test_magnetic.py checks the bound) — far
below a phone magnetometer's 0.2–1 µT noise and 0.15–0.6 µT resolution
(REALISM §1.5, the device profiles) — at a fifth to a tenth of the cost (the
more dipoles, the larger the gain). A noiseless magnetometer (the ``ideal``
profile) reads the exact sum instead (:func:`indoorsim.simulate.sample_sensors`).
"""

from __future__ import annotations

import datetime
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numba
import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline
from scipy.ndimage import maximum_filter1d
from shapely.geometry import Polygon

from indoorsim.util.seeding import generator

if TYPE_CHECKING:
    from indoorsim.scenario.schema import Scenario
    from indoorsim.world.plan import FloorPlan

MU0_OVER_4PI = 1e-7  # T·m/A
_T_TO_UT = 1e6
# Work arrays of (points × dipoles) are kept near this many elements: big
# enough to amortise the Python overhead, small enough to stay in cache.
_CHUNK_PAIRS = 1 << 14

# Keys that keep each steel family's random stream independent of the others.
_STREAM_PILLARS, _STREAM_OBSTACLES, _STREAM_REBAR = 1, 2, 3

PATH_BANDS: tuple[tuple[float, float], ...] = ((1.0, 3.0), (4.0, 10.0))
"""Transitions (a_k, b_k) in metres between the near, mid and far bands of
:meth:`MagneticModel.field_along`: band k+1 takes over from band k between
a_k and b_k."""
PATH_KNOT_TRAVEL_M: tuple[float, ...] = (0.3, 1.0)
"""Largest phone travel between the knots of the mid and the far band, m."""
PATH_KNOT_GAP_S: tuple[float, ...] = (0.1, 0.5)
"""Largest time between the knots of the mid and the far band, s: the knots
must also follow the gait's own rhythm (steps at ≈ 2 Hz) and, in the mid band,
a pocket's heel-strike jolts (1–2 cm, along and across the thigh, in ≈ 0.1 s):
at 0.125 s a brisk walker's pocket reached 0.016–0.029 µT of error, at 0.1 s
it stays near 0.003 µT."""
# Gradient knots are this many times sparser than value knots.
_GRADIENT_KNOTS = 6.0
# Knots are spaced by the largest speed within this window (s); no knot gap
# may exceed it, so that the bound holds between knots.
_SPEED_WINDOW_S = 2.0
_SPEED_FLOOR = 1e-3  # m/s, keeps the travel bound strictly increasing
# Transitions that make a band's inner weight 1 everywhere, or its outer one 0.
_ALWAYS, _NEVER = (-2.0, -1.0), (1e300, 2e300)
# The top speed of a path is taken from its samples; between samples a spline
# may run a little faster, so the knot spacing keeps this margin.
_SPEED_MARGIN = 1.25
# Side of the cells of the dipole index, relative to the near band's reach.
_CELL_FRACTION = 0.5


@functools.lru_cache(maxsize=64)
def earth_field_enu(
    latitude: float, longitude: float, altitude_km: float, date: datetime.date
) -> tuple[float, float, float]:
    """IGRF main field (east, north, up) in µT at a place and date (via ``ppigrf``)."""
    import ppigrf  # imported lazily: it reads its coefficient file on import

    when = datetime.datetime(date.year, date.month, date.day)
    be, bn, bu = ppigrf.igrf(longitude, latitude, altitude_km, when)
    return (
        float(np.ravel(be)[0]) / 1000,
        float(np.ravel(bn)[0]) / 1000,
        float(np.ravel(bu)[0]) / 1000,
    )


def enu_to_building(vec_enu: ArrayLike, north_deg: float) -> NDArray[np.float64]:
    """Rotate ENU vectors into the building frame whose +y is ``north_deg`` clockwise from north."""
    v = np.asarray(vec_enu, dtype=float)
    a = math.radians(north_deg)
    x_b = np.array([math.cos(a), -math.sin(a), 0.0])
    y_b = np.array([math.sin(a), math.cos(a), 0.0])
    return np.stack([v @ x_b, v @ y_b, v[..., 2]], axis=-1)


def dipole_field(
    points: NDArray[np.float64],
    positions: NDArray[np.float64],
    moments: NDArray[np.float64],
    min_distance: float = 0.05,
) -> NDArray[np.float64]:
    """Summed field (µT) of M dipoles at N points: (N, 3).

    With r_ij = p_i − q_j and w_ij = 3(m_j·r_ij)/r_ij⁵, the sum
    Σ_j [w_ij r_ij − m_j/r_ij³] equals p_i·Σ_j w_ij − (w @ q)_i − ((1/r³) @ m)_i,
    and m·r and r² are affine in p — so every (N, M) quantity comes from a
    matrix product plus a few element-wise passes.

    Args:
        points: (N, 3) metres.
        positions: (M, 3) dipole positions, metres.
        moments: (M, 3) dipole moments, A·m².
        min_distance: distances below this are clamped (a point dipole's field
            diverges at its centre; real steel has finite size).
    """
    p = np.asarray(points, dtype=float)
    q = np.asarray(positions, dtype=float)
    m = np.asarray(moments, dtype=float)
    out = np.zeros_like(p)
    if len(q) == 0 or len(p) == 0:
        return out
    # Centre the coordinates: keeps |p|² and |q|² small, so r² = |p|² + |q|² − 2p·q
    # loses no precision to cancellation.
    origin = q.mean(axis=0)
    p = p - origin
    q = q - origin
    q2 = np.einsum("ij,ij->i", q, q)
    qm = np.einsum("ij,ij->i", q, m)
    r2_min = min_distance * min_distance
    step = max(1, _CHUNK_PAIRS // len(q))
    for i in range(0, len(p), step):
        pc = p[i : i + step]
        r2 = pc @ (-2.0 * q.T)
        r2 += np.einsum("ij,ij->i", pc, pc)[:, None]
        r2 += q2
        np.maximum(r2, r2_min, out=r2)
        mr = pc @ m.T
        mr -= qm
        inv_r3 = np.sqrt(r2)
        inv_r3 *= r2
        np.reciprocal(inv_r3, out=inv_r3)
        w = mr
        w *= inv_r3
        w /= r2
        w *= 3.0
        out[i : i + step] = pc * w.sum(axis=1)[:, None] - w @ q - inv_r3 @ m
    out *= MU0_OVER_4PI * _T_TO_UT
    return out


# Consecutive points evaluated together: one candidate list of dipoles is
# gathered per chunk, and the inner loop runs over the chunk's points.
_CHUNK = 32
# ... and no wider than this fraction of the band's reach.
_CHUNK_REACH = 0.3
# Lanes of the compiled loops over a chunk's points (4 doubles in AVX2).
_LANES = 4
# Margin (m) by which every point must be past a step's end for the step to
# count as constant: far above the rounding of the distances.
_FLAT_MARGIN = 1e-6


@numba.njit(cache=True, inline="always", error_model="numpy")
def _step(x):  # pragma: no cover - compiled
    """The C⁴ smootherstep 126x⁵ − 420x⁶ + 540x⁷ − 315x⁸ + 70x⁹ of x ∈ [0, 1]."""
    return x * x * x * x * x * (126.0 + x * (-420.0 + x * (540.0 + x * (-315.0 + 70.0 * x))))


@numba.njit(cache=True, inline="always", error_model="numpy")
def _band_weight(r, a_in, k_in, a_out, k_out, inner, outer):  # pragma: no cover - compiled
    """A band's weight at distance r and its two ramp coordinates (xi, xo).

    The weight is smootherstep up from a_in minus smootherstep up from a_out
    (:func:`_step` of each ramp coordinate x ∈ [0, 1]); the coordinates give
    the weight's derivative.

    ``inner`` / ``outer`` False (constants at the call site, so the dead
    terms compile away) say that the inner step is known to be 1 / the outer
    one 0 at r. The result is then exactly the full form's: the step at
    x = 1 evaluates to exactly 1.0 (every partial sum is an integer), at
    x = 0 to exactly 0.0, and subtracting 0.0 changes no value.
    """
    xi, w = 1.0, 1.0
    if inner:
        xi = min(max((r - a_in) * k_in, 0.0), 1.0)
        w = _step(xi)
    xo = 0.0
    if outer:
        xo = min(max((r - a_out) * k_out, 0.0), 1.0)
        w = w - _step(xo)
    return w, xi, xo


@numba.njit(cache=True, inline="always", error_model="numpy")
def _band_slope(xi, xo, k_in, k_out, inner, outer):  # pragma: no cover - compiled
    """(dw/dr)·r_c/630 from :func:`_band_weight`'s coordinates (dead terms left out as there)."""
    ui, uo = xi * (1.0 - xi), xo * (1.0 - xo)
    d = ui * ui * ui * ui * k_in if inner else 0.0
    if outer:
        d = d - uo * uo * uo * uo * k_out
    return d


@numba.njit(cache=True, inline="always", error_model="numpy")
def _pair_terms(p, i, qx, qy, qz, mx, my, mz, ramp, inner, outer):  # pragma: no cover - compiled
    """What the field and its gradient share for point i of a chunk and one dipole:
    r = p_i − q, the band weight and its ramp coordinates, the clamped distance
    r_c, 1/r_c², 1/r_c³, m·r and s = 3(m·r)/r_c²."""
    a_in, k_in, a_out, k_out, r_min = ramp
    rx, ry, rz = p[0, i] - qx, p[1, i] - qy, p[2, i] - qz
    r = math.sqrt(rx * rx + ry * ry + rz * rz)
    w, xi, xo = _band_weight(r, a_in, k_in, a_out, k_out, inner, outer)
    rc = max(r, r_min)
    inv_r2 = 1.0 / (rc * rc)
    inv_r3 = inv_r2 / rc
    mr = mx * rx + my * ry + mz * rz
    s = 3.0 * mr * inv_r2
    return rx, ry, rz, w, xi, xo, rc, inv_r2, inv_r3, mr, s


@numba.njit(cache=True, inline="always", error_model="numpy")
def _add_pairs(
    acc, p, m_pts, pos, mom, j, ramp, value, grad, inner, outer
):  # pragma: no cover - compiled
    """Add dipole j's weighted field (``value``) and gradient (``grad``) at
    the chunk's points ``p[:, :m_pts]`` to ``acc`` (see :func:`_band_field`);
    ``ramp`` = (a_in, k_in, a_out, k_out, r_min)."""
    k_in, k_out = ramp[1], ramp[3]
    qx, qy, qz = pos[j, 0], pos[j, 1], pos[j, 2]
    mx, my, mz = mom[j, 0], mom[j, 1], mom[j, 2]
    if value:
        for i in range(m_pts):
            rx, ry, rz, w, _, _, rc, inv_r2, inv_r3, mr, s = _pair_terms(
                p, i, qx, qy, qz, mx, my, mz, ramp, inner, outer
            )
            acc[0, i] += w * (s * rx - mx) * inv_r3
            acc[1, i] += w * (s * ry - my) * inv_r3
            acc[2, i] += w * (s * rz - mz) * inv_r3
    if grad:
        # The gradient in a loop of its own, so that neither loop branches.
        for i in range(m_pts):
            rx, ry, rz, w, xi, xo, rc, inv_r2, inv_r3, mr, s = _pair_terms(
                p, i, qx, qy, qz, mx, my, mz, ramp, inner, outer
            )
            # ∂(w·B_i)/∂r_k = w·(3[m_k r_i + m_i r_k + (m·r)δ_ik]/r⁵ − 15(m·r) r_i r_k/r⁷)
            # + w'(r)·B_i·r_k/r = r_i·u_k + z_i·r_k + D·δ_ik with u = 3w·m/r⁵,
            # z = u + w'·B/r − 15w(m·r)·r/r⁷ and D = 3w(m·r)/r⁵.
            dw = 630.0 * _band_slope(xi, xo, k_in, k_out, inner, outer) / rc
            a5 = 3.0 * w * inv_r3 * inv_r2
            c7 = 5.0 * a5 * mr * inv_r2
            dg = a5 * mr
            ux, uy, uz = a5 * mx, a5 * my, a5 * mz
            zx = ux + dw * (s * rx - mx) * inv_r3 - c7 * rx
            zy = uy + dw * (s * ry - my) * inv_r3 - c7 * ry
            zz = uz + dw * (s * rz - mz) * inv_r3 - c7 * rz
            acc[3, i] += rx * ux + zx * rx + dg
            acc[4, i] += rx * uy + zx * ry
            acc[5, i] += rx * uz + zx * rz
            acc[6, i] += ry * ux + zy * rx
            acc[7, i] += ry * uy + zy * ry + dg
            acc[8, i] += ry * uz + zy * rz
            acc[9, i] += rz * ux + zz * rx
            acc[10, i] += rz * uy + zz * ry
            acc[11, i] += rz * uz + zz * rz + dg


@numba.njit(cache=True, error_model="numpy")
def _band_field(
    points, pos, mom, order, cell_start, grid, band, r_min, out, jac
):  # pragma: no cover - compiled
    """Add Σ_j w(r_j)·[3(m_j·r)r/r⁵ − m_j/r³] (A/m; μ0/4π times it is B) to ``out`` at each point.

    ``band`` = (a_in, b_in, a_out, b_out): w = S((r − a_in)/(b_in − a_in)) −
    S((r − a_out)/(b_out − a_out)), S the C⁴ step x⁵(126 − 420x + 540x² −
    315x³ + 70x⁴) clamped to [0, 1]; a_in < b_in < 0 makes the first term 1,
    a huge a_out the second 0 (then every dipole is a candidate). As in
    :func:`dipole_field`, r is clamped to ``r_min`` in the field, not in
    the weight.

    Points are taken ``_CHUNK`` at a time: the dipoles that can reach any of
    them (cell index ``order``, ``cell_start``, ``grid`` = (x0, y0, cell,
    ncx, ncy), then a distance test against the chunk's bounding sphere) are
    gathered once, and the innermost loop runs over the chunk's points
    without branches, so it vectorises (``error_model="numpy"`` drops the
    division checks that would stop it); each point still sums its dipoles in
    candidate order and nothing is contracted or reassociated, so the result
    does not depend on the vector width.

    The field is added to ``out`` only when it has a row per point; when
    ``jac`` has one, the gradient ∂(w·B_i)/∂p_k is added to ``jac[:, i, k]``
    (meant for bands that start beyond the clamp).
    """
    x0, y0, cell = grid[0], grid[1], grid[2]
    ncx, ncy = int(grid[3]), int(grid[4])
    a_in, b_in, a_out, b_out = band[0], band[1], band[2], band[3]
    k_in, k_out = 1.0 / (b_in - a_in), 1.0 / (b_out - a_out)
    ramp = (a_in, k_in, a_out, k_out, r_min)
    bounded = b_out < 1e100
    value = out.shape[0] == points.shape[0]
    grad = jac.shape[0] == points.shape[0]
    n = points.shape[0]
    # A chunk also ends where its points spread wider than a fraction of the
    # band's reach, so that its candidates stay close to each point's own.
    max_rad = _CHUNK_REACH * b_out if bounded else np.inf
    cand = np.empty(order.shape[0], np.intp)
    ramps = np.empty(order.shape[0], np.int8)
    p = np.empty((3, _CHUNK))
    acc = np.empty((12, _CHUNK))
    lo = np.empty(3)
    hi = np.empty(3)
    c0 = 0
    while c0 < n:
        for d in range(3):
            lo[d] = points[c0, d]
            hi[d] = points[c0, d]
        m_pts = 0
        rad = 0.0
        while m_pts < _CHUNK and c0 + m_pts < n:
            i = c0 + m_pts
            r2 = 0.0
            for d in range(3):
                r2 += (max(hi[d], points[i, d]) - min(lo[d], points[i, d])) ** 2
            if m_pts > 0 and 0.5 * math.sqrt(r2) > max_rad:
                break
            for d in range(3):
                lo[d] = min(lo[d], points[i, d])
                hi[d] = max(hi[d], points[i, d])
                p[d, m_pts] = points[i, d]
            rad = 0.5 * math.sqrt(r2)
            m_pts += 1
        cx, cy, cz = 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])
        # Candidates: within b_out of some point, and not closer than a_in to all.
        ix0, ix1, iy0, iy1 = 0, ncx - 1, 0, ncy - 1
        far2 = (b_out + rad) ** 2
        if bounded:
            ix0 = max(math.floor((cx - b_out - rad - x0) / cell), 0)
            ix1 = min(math.floor((cx + b_out + rad - x0) / cell), ncx - 1)
            iy0 = max(math.floor((cy - b_out - rad - y0) / cell), 0)
            iy1 = min(math.floor((cy + b_out + rad - y0) / cell), ncy - 1)
        near = a_in - rad
        near2 = near * near if near > 0.0 else -1.0
        # A step that is constant at all the chunk's points (the inner one 1
        # beyond b_in, the outer one 0 within a_out; the margin covers the
        # rounding of these tests) is left out of a dipole's loops. (A huge
        # a_out squares to inf: the outer step is 0 for every dipole.)
        flat_in = b_in + rad + _FLAT_MARGIN
        flat_in2 = flat_in * flat_in if flat_in > 0.0 else -1.0
        flat_out = a_out - rad - _FLAT_MARGIN
        flat_out2 = flat_out * flat_out if flat_out > 0.0 else -1.0
        nc = 0
        for iy in range(iy0, iy1 + 1):
            if ix0 > ix1:
                break
            for k in range(cell_start[iy * ncx + ix0], cell_start[iy * ncx + ix1 + 1]):
                j = order[k]
                dx, dy, dz = pos[j, 0] - cx, pos[j, 1] - cy, pos[j, 2] - cz
                d2 = dx * dx + dy * dy + dz * dz
                if (bounded and d2 >= far2) or d2 <= near2:
                    continue
                cand[nc] = j
                ramps[nc] = (d2 < flat_in2) + 2 * (d2 > flat_out2)
                nc += 1
        # The loops run over whole vectors of lanes: the padding lanes repeat
        # the last point and are dropped, so no point is left to the slower
        # scalar remainder of a vectorised loop.
        m_vec = -(-m_pts // _LANES) * _LANES
        for i in range(m_pts, m_vec):
            for d in range(3):
                p[d, i] = p[d, m_pts - 1]
        acc[:, :m_vec] = 0.0
        for c in range(nc):
            j = cand[c]
            # One copy of the loops for each pair of steps that ramp over the
            # chunk (bit 0 the inner, bit 1 the outer), each compiled without
            # the terms of a constant step.
            if ramps[c] == 3:
                _add_pairs(acc, p, m_vec, pos, mom, j, ramp, value, grad, True, True)
            elif ramps[c] == 2:
                _add_pairs(acc, p, m_vec, pos, mom, j, ramp, value, grad, False, True)
            elif ramps[c] == 1:
                _add_pairs(acc, p, m_vec, pos, mom, j, ramp, value, grad, True, False)
            else:
                _add_pairs(acc, p, m_vec, pos, mom, j, ramp, value, grad, False, False)
        for i in range(m_pts):
            if value:
                for d in range(3):
                    out[c0 + i, d] += acc[d, i]
            if grad:
                for a in range(3):
                    for b in range(3):
                        jac[c0 + i, a, b] += acc[3 + 3 * a + b, i]
        c0 += m_pts


@dataclass(frozen=True, eq=False)
class _DipoleIndex:
    """Dipoles binned by (x, y) into square cells, each row of cells contiguous.

    Attributes:
        order: dipole indices sorted by cell (row-major: y, then x).
        cell_start: (ncx·ncy + 1,) start of each cell's run in ``order``.
        grid: (x0, y0, cell side, ncx, ncy).
    """

    order: NDArray[np.intp]
    cell_start: NDArray[np.intp]
    grid: NDArray[np.float64]

    @classmethod
    def build(cls, positions: NDArray[np.float64], cell: float) -> _DipoleIndex:
        if len(positions) == 0:
            return cls(np.zeros(0, np.intp), np.zeros(2, np.intp), np.array([0, 0, cell, 1, 1.0]))
        lo = positions[:, :2].min(axis=0)
        n = np.floor((positions[:, :2].max(axis=0) - lo) / cell).astype(np.intp) + 1
        ix = np.minimum(np.floor((positions[:, :2] - lo) / cell).astype(np.intp), n - 1)
        key = ix[:, 1] * n[0] + ix[:, 0]
        order = np.argsort(key, kind="stable").astype(np.intp)
        cell_start = np.searchsorted(key[order], np.arange(n[0] * n[1] + 1)).astype(np.intp)
        return cls(order, cell_start, np.array([lo[0], lo[1], cell, n[0], n[1]], dtype=float))


def induced_moment(
    volume_m3: float | NDArray[np.float64], susceptibility: float, b_earth_uT: NDArray[np.float64]
) -> NDArray[np.float64]:
    """m = χ·V·B/μ0 (A·m²) for steel of volume V magnetised by the field B (µT)."""
    b_tesla = np.asarray(b_earth_uT, dtype=float) / _T_TO_UT
    v = np.asarray(volume_m3, dtype=float)
    return susceptibility * v[..., None] * b_tesla / (4 * math.pi * MU0_OVER_4PI)


@dataclass(kw_only=True)
class MagneticModel:
    """Earth field plus a set of point dipoles, all in the building frame.

    Attributes:
        earth_field_uT: (3,) uniform main field.
        positions: (M, 3) dipole positions, m.
        moments: (M, 3) dipole moments, A·m².
        sources: (M,) label of each dipole's origin (``"dipole"``, ``"pillar"``,
            ``"rebar"``, ``"obstacle"``), for plots and diagnostics.
        min_distance: clamp distance near a dipole, m.
    """

    earth_field_uT: NDArray[np.float64]
    positions: NDArray[np.float64]
    moments: NDArray[np.float64]
    sources: NDArray[np.str_]
    min_distance: float = 0.05

    @classmethod
    def from_scenario(cls, scenario: Scenario, plan: FloorPlan) -> MagneticModel:
        """Expand a scenario's steel into dipoles (see the module docstring)."""
        site, mag = scenario.site, scenario.magnetic
        if site.earth_field_uT is not None:
            b_earth = np.array(site.earth_field_uT, dtype=float)
        else:
            enu = earth_field_enu(site.latitude, site.longitude, site.altitude_km, site.date)
            b_earth = enu_to_building(enu, site.north_deg)

        def rng(stream: int) -> np.random.Generator:
            return generator(scenario.seed, (stream,))

        def sheet_steel(
            pos: NDArray[np.float64], vol: NDArray[np.float64], stream: int
        ) -> NDArray[np.float64]:
            # Sheet-steel furniture: isotropic, remanence in a random direction.
            ind = induced_moment(vol, mag.susceptibility, b_earth)
            size = np.linalg.norm(ind, axis=1, keepdims=True)
            rem = (
                rng(stream).standard_normal(pos.shape) * size * (mag.remanent_ratio / math.sqrt(3))
            )
            return ind + rem

        def bars(
            vol: NDArray[np.float64],
            element: NDArray[np.intp],
            families: list[tuple[NDArray[np.float64], float]],
            stream: int,
        ) -> NDArray[np.float64]:
            return bar_moments(
                vol,
                element,
                families,
                b_earth,
                mag.susceptibility,
                mag.transverse_susceptibility,
                mag.remanent_ratio,
                rng(stream),
            )

        groups: list[tuple[NDArray[np.float64], NDArray[np.float64], str]] = []
        if mag.dipoles:
            groups.append(
                (
                    np.array([d.position for d in mag.dipoles], float),
                    np.array([d.moment for d in mag.dipoles], float),
                    "dipole",
                )
            )
        h = site.ceiling_height
        ties = mag.tie_share
        if scenario.pillars:
            n = max(1, round(h / mag.pillar_dipole_spacing))
            z = (np.arange(3 * n) + 0.5) * (h / n) - h  # storey below, this, above
            pos = np.array([(*p.center, zz) for p in scenario.pillars for zz in z])
            vol = np.repeat([p.steel_volume_m3 / n for p in scenario.pillars], len(z))
            # One element per pillar and storey: the bars are lapped at each slab;
            # a spliced steel column is one length below its splice, one above.
            storey = np.arange(len(z)) // n
            element = np.concatenate(
                [
                    3 * i + (storey if p.splice_z is None else (z >= p.splice_z))
                    for i, p in enumerate(scenario.pillars)
                ]
            )
            column = [(_Z, 1.0 - ties), (_X, ties / 2), (_Y, ties / 2)]
            groups.append((pos, bars(vol, element, column, _STREAM_PILLARS), "pillar"))
        steel_obst = [o for o in scenario.obstacles if o.steel_volume_m3 > 0]
        if steel_obst:
            pos = np.array([(*o.center, o.height / 2) for o in steel_obst])
            vol = np.array([o.steel_volume_m3 for o in steel_obst])
            groups.append((pos, sheet_steel(pos, vol, _STREAM_OBSTACLES), "obstacle"))
        for k, rebar in enumerate(scenario.magnetic.rebar):
            region = Polygon(rebar.region) if rebar.region is not None else plan.outline
            pos = _grid_in(region, rebar.spacing, rebar.z)
            if len(pos):
                vol = np.full(len(pos), rebar.steel_volume_m3_per_m2 * rebar.spacing**2)
                element = _elements(pos, region.bounds, rebar.bars, rebar.element_m)
                families = _BAR_FAMILIES[rebar.bars](ties)
                moments = bars(vol, element, families, _STREAM_REBAR * 1000 + k)
                groups.append((pos, moments, "rebar"))

        if groups:
            positions = np.concatenate([g[0] for g in groups])
            moments = np.concatenate([g[1] for g in groups])
            sources = np.concatenate([np.full(len(g[0]), g[2]) for g in groups])
        else:
            positions, moments, sources = np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=str)
        return cls(
            earth_field_uT=b_earth,
            positions=positions,
            moments=moments,
            sources=sources,
            min_distance=mag.min_distance,
        )

    def field(self, points: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) total field in µT at (N, 3) points (a single (3,) point gives (1, 3))."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points: expected shape (N, 3), got {np.shape(points)}")
        return self.earth_field_uT + self.anomaly(p)

    def anomaly(self, points: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) field of the dipoles alone, µT."""
        return dipole_field(
            np.atleast_2d(np.asarray(points, dtype=float)),
            self.positions,
            self.moments,
            self.min_distance,
        )

    def field_along(
        self,
        t: NDArray[np.float64],
        position: Callable[[NDArray[np.float64]], NDArray[np.float64]],
        path_t: NDArray[np.float64],
        path_pos: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """(N, 3) total field in µT along a moving point's path, at sorted times ``t``.

        The near band of dipoles is summed exactly at every time, the smooth
        mid and far bands at knots and interpolated (see the module
        docstring); the result is within 0.01 µT of :meth:`field` at the
        same points for walking paths (speeds up to a few m/s).

        Args:
            t: (N,) increasing times within the path's span, s.
            position: the path: maps times within [t[0], t[-1]] to (K, 3) positions, m.
            path_t: (P,) times of the path's dense samples (≥ 100 Hz), s.
            path_pos: (P, 3) the path at ``path_t``; its local speed sets the knots.
        """
        t = np.asarray(t, dtype=float)
        points = np.ascontiguousarray(position(t), dtype=float)
        out = np.zeros_like(points)
        if len(t) == 0 or len(self.positions) == 0:
            return out + self.earth_field_uT
        out += self._band(points, _ALWAYS, PATH_BANDS[0])
        travel = _travel_bound(np.asarray(path_t, float), np.asarray(path_pos, float))
        bands = [*PATH_BANDS, _NEVER]
        for k, spacing in enumerate(PATH_KNOT_TRAVEL_M):
            inner, outer = bands[k], bands[k + 1]
            t_knot = _knot_times(t[0], t[-1], *travel, spacing, PATH_KNOT_GAP_S[k])
            if len(t_knot) >= len(t) // 2 or len(t_knot) < 4:
                out += self._band(points, inner, outer)
                continue
            p_knot = np.ascontiguousarray(position(t_knot), dtype=float)
            # One spline through the knots for the band's field and for the
            # knots' positions P (used below): its columns are independent,
            # and the knot intervals are found once.
            smooth = CubicSpline(
                t_knot, np.hstack([self._band(p_knot, inner, outer), p_knot]), axis=0
            )(t)
            out += smooth[:, :3]
            # The knots follow the path on their own scale; what they miss (gait
            # oscillations of a few cm) is added to first order with the
            # gradient, which varies slowly enough to be known at fewer knots.
            t_grad = _knot_times(
                t[0],
                t[-1],
                *travel,
                _GRADIENT_KNOTS * spacing,
                _GRADIENT_KNOTS * PATH_KNOT_GAP_S[k],
            )
            if len(t_grad) < 4:
                t_grad = t_knot
            jac = self._band_gradient(
                np.ascontiguousarray(position(t_grad), dtype=float), inner, outer
            )
            grad = CubicSpline(t_grad, jac.reshape(-1, 9), axis=0)(t).reshape(-1, 3, 3)
            out += np.einsum("nij,nj->ni", grad, points - smooth[:, 3:])
        return self.earth_field_uT + out

    def _band(
        self, points: NDArray[np.float64], inner: tuple[float, float], outer: tuple[float, float]
    ) -> NDArray[np.float64]:
        """(N, 3) field in µT at points of the dipoles weighted S_inner − S_outer
        (see :func:`_band_field`)."""
        part = np.zeros_like(points)
        self._band_kernel(points, inner, outer, part, np.zeros((0, 3, 3)))
        part *= MU0_OVER_4PI * _T_TO_UT
        return part

    def _band_gradient(
        self, points: NDArray[np.float64], inner: tuple[float, float], outer: tuple[float, float]
    ) -> NDArray[np.float64]:
        """(N, 3, 3) gradient in µT/m of :meth:`_band`, [n, i, k] = ∂B_i/∂p_k at point n."""
        jac = np.zeros((len(points), 3, 3))
        self._band_kernel(points, inner, outer, np.zeros((0, 3)), jac)
        jac *= MU0_OVER_4PI * _T_TO_UT
        return jac

    def _band_kernel(
        self,
        points: NDArray[np.float64],
        inner: tuple[float, float],
        outer: tuple[float, float],
        out: NDArray[np.float64],
        jac: NDArray[np.float64],
    ) -> None:
        index = self._path_index
        _band_field(
            points,
            self.positions,
            self.moments,
            index.order,
            index.cell_start,
            index.grid,
            np.array([*inner, *outer], dtype=float),
            self.min_distance,
            out,
            jac,
        )

    @functools.cached_property
    def _path_index(self) -> _DipoleIndex:
        """The cell index of the dipoles, built once per model (the site's steel is fixed)."""
        return _DipoleIndex.build(
            np.ascontiguousarray(self.positions, dtype=float), _CELL_FRACTION * PATH_BANDS[0][1]
        )


_X, _Y, _Z = np.eye(3)

_BAR_FAMILIES: dict[str, Callable[[float], list[tuple[NDArray[np.float64], float]]]] = {
    # (bar direction, share of the steel), given the share in ties and stirrups.
    "mesh": lambda ties: [(_X, 0.5), (_Y, 0.5)],
    "x": lambda ties: [(_X, 1.0 - ties), (_Y, ties / 2), (_Z, ties / 2)],
    "y": lambda ties: [(_Y, 1.0 - ties), (_X, ties / 2), (_Z, ties / 2)],
}


def bar_moments(
    volume: NDArray[np.float64],
    element: NDArray[np.intp],
    families: list[tuple[NDArray[np.float64], float]],
    b_earth_uT: NDArray[np.float64],
    susceptibility: float,
    transverse_susceptibility: float,
    remanent_ratio: float,
    rng: np.random.Generator,
) -> NDArray[np.float64]:
    """(M, 3) moments (A·m²) of dipoles standing for bars (see :class:`MagneticSpec`).

    Args:
        volume: (M,) steel each dipole stands for, m³.
        element: (M,) which element each dipole belongs to; an element's dipoles
            share its remanent magnetisation (one draw per element and bar direction,
            in order of first appearance).
        families: (unit direction, share of the steel) of each bar direction.
        b_earth_uT: the Earth's field.
        susceptibility: χ along a bar.
        transverse_susceptibility: χ_t across it.
        remanent_ratio: the elements' RMS remanent moment over χ·V·|H|.
        rng: the remanence's random source.
    """
    h = np.asarray(b_earth_uT, dtype=float) / _T_TO_UT / (4 * math.pi * MU0_OVER_4PI)  # A/m
    per_unit = np.zeros(3)  # induced moment per m³ of steel
    for u, share in families:
        along = float(h @ u) * u
        per_unit += share * (susceptibility * along + transverse_susceptibility * (h - along))
    _, first, which = np.unique(element, return_index=True, return_inverse=True)
    order = np.argsort(first)  # elements in order of first appearance: stable draws
    draws = np.empty((len(first), len(families)))
    draws[order] = rng.standard_normal((len(first), len(families)))
    norm = math.sqrt(sum(share**2 for _, share in families)) or 1.0
    scale = remanent_ratio * susceptibility * float(np.linalg.norm(h)) / norm
    directions = np.array([share * u for u, share in families])  # (F, 3)
    remanent_per_unit = scale * draws @ directions  # (E, 3) per m³ of the element's steel
    vol = np.asarray(volume, dtype=float)[:, None]
    return vol * (per_unit + remanent_per_unit[which])


def _elements(
    pos: NDArray[np.float64],
    bounds: tuple[float, float, float, float],
    bars: str,
    element_m: float | None,
) -> NDArray[np.intp]:
    """Element of each grid point: square patches (a mesh) or segments along a beam's
    bars, ``element_m`` long from the region's lower-left corner; one per point if None."""
    if element_m is None:
        return np.arange(len(pos))
    ix = np.floor((pos[:, 0] - bounds[0]) / element_m).astype(np.intp)
    iy = np.floor((pos[:, 1] - bounds[1]) / element_m).astype(np.intp)
    if bars == "x":
        return ix
    if bars == "y":
        return iy
    return ix * (iy.max() + 1) + iy


def _grid_in(region: Polygon, spacing: float, z: float) -> NDArray[np.float64]:
    """Grid points (x, y, z) at ``spacing`` inside ``region``, aligned to its bounds."""
    if region.is_empty:
        return np.zeros((0, 3))
    x0, y0, x1, y1 = region.bounds
    xs = np.arange(x0 + spacing / 2, x1, spacing)
    ys = np.arange(y0 + spacing / 2, y1, spacing)
    gx, gy = np.meshgrid(xs, ys, indexing="xy")
    gx, gy = gx.ravel(), gy.ravel()
    inside = shapely.contains_xy(region, gx, gy)
    return np.column_stack([gx[inside], gy[inside], np.full(inside.sum(), z)])


def _travel_bound(
    path_t: NDArray[np.float64], path_pos: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(times, cumulative bound of the distance travelled since path_t[0]) along a path.

    The bound integrates the largest sample speed within ±``_SPEED_WINDOW_S``
    (times ``_SPEED_MARGIN``): between two knots no more than that apart it
    bounds the travel from above.
    """
    if len(path_t) < 2:
        return np.array([0.0, 1.0]), np.array([0.0, 1.0])
    dt = np.diff(path_t)
    speed = np.empty(len(dt))
    _speeds(np.ascontiguousarray(path_pos), dt, speed)
    width = 2 * max(1, round(_SPEED_WINDOW_S / float(np.median(dt)))) + 1
    bound = _SPEED_MARGIN * maximum_filter1d(speed, width, mode="nearest") + _SPEED_FLOOR
    return path_t, np.r_[0.0, np.cumsum(bound * dt)]


@numba.njit(cache=True, error_model="numpy")
def _speeds(pos, dt, out):  # pragma: no cover - compiled
    """out[k] = |pos[k+1] − pos[k]| / dt[k]: one pass, not numpy's four over a long path."""
    for k in range(out.shape[0]):
        dx = pos[k + 1, 0] - pos[k, 0]
        dy = pos[k + 1, 1] - pos[k, 1]
        dz = pos[k + 1, 2] - pos[k, 2]
        out[k] = math.sqrt(dx * dx + dy * dy + dz * dz) / dt[k]


def _knot_times(
    t0: float,
    t1: float,
    path_t: NDArray[np.float64],
    travel: NDArray[np.float64],
    spacing_m: float,
    gap_s: float,
) -> NDArray[np.float64]:
    """Knot times from t0 to t1 (both included), ``spacing_m`` of bounded travel apart
    and at most ``gap_s`` (≤ ``_SPEED_WINDOW_S``) apart."""
    c0, c1 = np.interp([t0, t1], path_t, travel)
    n = max(1, math.ceil((c1 - c0) / spacing_m))
    knots = np.interp(np.linspace(c0, c1, n + 1), travel, path_t)
    knots[0], knots[-1] = t0, t1
    gap = np.diff(knots)
    parts = np.ceil(gap / min(gap_s, _SPEED_WINDOW_S)).astype(np.intp)
    if np.any(parts > 1):
        # Split each long gap into equal parts.
        first = np.repeat(np.cumsum(parts) - parts, parts)
        frac = (np.arange(parts.sum()) - first) / np.repeat(parts, parts)
        knots = np.r_[np.repeat(knots[:-1], parts) + frac * np.repeat(gap, parts), knots[-1]]
    return knots
