"""Magnetic field of a building: the Earth's main field plus steel as point dipoles.

B(p) = B_earth + Σ_j μ0/4π · [3(m_j·r̂)r̂ − m_j]/r³,   r = p − q_j.

* **Earth field** from IGRF (``ppigrf``) for the site's latitude, longitude,
  altitude and date, rotated into the building frame by ``site.north_deg`` — or
  the scenario's explicit ``earth_field_uT``.
* **Steel** becomes point dipoles. Each steel element of volume V carries an
  induced moment along the Earth's field, m = χ·V·B_earth/μ0 (χ an effective,
  shape-limited susceptibility), plus a remanent moment in a random direction
  whose RMS size is ``remanent_ratio`` times the induced one (seeded from the
  scenario's ``seed``, so the building is the same every time it is loaded):

  - pillars: a vertical chain of dipoles through the storey below, this one and
    the one above (columns run through the slabs, which makes them line-like
    sources decaying as ~1/r² at walking height);
  - slab rebar: a grid of dipoles at the slab's height;
  - steel furniture: one dipole at half its height;
  - explicit dipoles (elevators, machinery) as given.

Evaluation is vectorised over points and dipoles and chunked to bound memory.
Every pairwise term is written through matrix products (see :func:`dipole_field`),
so the inner work runs in BLAS rather than in Python or in many (N, M, 3)
temporaries.
"""

from __future__ import annotations

import datetime
import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from shapely.geometry import Polygon

if TYPE_CHECKING:
    from indoorsim.scenario import Scenario
    from indoorsim.world.plan import FloorPlan

MU0_OVER_4PI = 1e-7  # T·m/A
_T_TO_UT = 1e6
# Work arrays of (points × dipoles) are kept near this many elements: big
# enough to amortise the Python overhead, small enough to stay in cache.
_CHUNK_PAIRS = 1 << 14

# Keys that keep each steel family's random stream independent of the others.
_STREAM_PILLARS, _STREAM_OBSTACLES, _STREAM_REBAR = 1, 2, 3


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
            return np.random.default_rng(np.random.SeedSequence(scenario.seed, spawn_key=(stream,)))

        def steel(
            pos: NDArray[np.float64], vol: NDArray[np.float64], stream: int
        ) -> NDArray[np.float64]:
            ind = induced_moment(vol, mag.susceptibility, b_earth)
            size = np.linalg.norm(ind, axis=1, keepdims=True)
            rem = (
                rng(stream).standard_normal(pos.shape) * size * (mag.remanent_ratio / math.sqrt(3))
            )
            return ind + rem

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
        if scenario.pillars:
            n = max(1, round(h / mag.pillar_dipole_spacing))
            z = (np.arange(3 * n) + 0.5) * (h / n) - h  # storey below, this, above
            pos = np.array([(*p.center, zz) for p in scenario.pillars for zz in z])
            vol = np.repeat([p.steel_volume_m3 / n for p in scenario.pillars], len(z))
            groups.append((pos, steel(pos, vol, _STREAM_PILLARS), "pillar"))
        steel_obst = [o for o in scenario.obstacles if o.steel_volume_m3 > 0]
        if steel_obst:
            pos = np.array([(*o.center, o.height / 2) for o in steel_obst])
            vol = np.array([o.steel_volume_m3 for o in steel_obst])
            groups.append((pos, steel(pos, vol, _STREAM_OBSTACLES), "obstacle"))
        for k, rebar in enumerate(scenario.magnetic.rebar):
            region = Polygon(rebar.region) if rebar.region is not None else plan.outline
            pos = _grid_in(region, rebar.spacing, rebar.z)
            if len(pos):
                vol = np.full(len(pos), rebar.steel_volume_m3_per_m2 * rebar.spacing**2)
                groups.append((pos, steel(pos, vol, _STREAM_REBAR * 1000 + k), "rebar"))

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
