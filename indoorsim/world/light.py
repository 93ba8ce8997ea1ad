"""Illuminance of a building: ceiling luminaires, inter-reflections and daylight.

E(p, n̂) = Σ_sources E_direct + E_ambient, in lux on a receiver at p (m) with unit
normal n̂, from three parts (DESIGN §4 "Light", REALISM §3):

* **Direct term** (REALISM §3.1). Every source is a point with an axially
  symmetric intensity I(θ) = I0·cosⁿθ (cd) about its axis, zero behind it.
  With d the distance and ŝ the unit vector receiver→source,
  E = I(θ)·max(0, n̂·ŝ)/d² · T, where T = ``plan.light_transmittance`` is 0
  behind an opaque wall or pillar and the product of the glazing transmittances
  crossed otherwise. Walls stand floor to ceiling, so the 2-D crossing test of
  the plan is the 3-D occlusion test.
* **Ambient (inter-reflection) term** (REALISM §3.4; see :class:`RoomAmbient`):
  the split-flux / integrating-sphere approximation per room, fed by the flux
  of every source in the room (luminaires, and daylight patches when enabled),
  uniform within a room, weighted by the receiver's view of the upper and
  lower hemispheres.
* **Daylight** (off by default: the papers walked at night; see
  :func:`window_patches`): each window is a uniform Lambertian area source of
  luminance L = τ·E_v/π, cut into small patches that are point sources
  I(θ) = L·dA·cos θ about the inward window normal, evaluated by the same
  direct-term kernel as the luminaires.

Units: m, cd, lm, lx, cd/m². Frame: the building frame, z up from the floor.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from shapely.geometry import LineString, Point, Polygon

if TYPE_CHECKING:
    from indoorsim.scenario import ReflectanceSpec, Scenario, WallSpec, WindowSpec
    from indoorsim.world.plan import FloorPlan

__all__ = ["LightModel", "PointSources", "RoomAmbient", "direct_illuminance", "window_patches"]

MIN_DISTANCE_M = 0.05
"""Source–receiver distances below this are clamped, keeping E finite. A real
luminaire or window patch is tens of centimetres across, so the point-source
(far-field) model means nothing closer than this anyway."""

DAYLIGHT_PATCH_M = 0.25
"""Largest side of a window patch. The patch sum matches the exact area-source
integral to about 1 % from one patch size away from the glass."""

# A patch sits this far inside the surface of its wall, so that the window's own
# wall (a centre line in the occlusion test) never stands between it and the room.
_PATCH_INSET_M = 0.01
# How far beyond the wall surface we probe to tell the building's inside from outside.
_PROBE_M = 0.05


@dataclass(frozen=True, kw_only=True)
class PointSources:
    """S point sources with axially symmetric intensity I(θ) = intensity_cd · cos^exponent θ.

    Attributes:
        position: (S, 3) source positions, m.
        axis: (S, 3) unit vectors of peak emission (θ = 0).
        intensity_cd: (S,) peak intensity I0, cd.
        exponent: (S,) cosine-power n (1 = Lambertian; 0 = uniform over the front hemisphere).
    """

    position: NDArray[np.float64]
    axis: NDArray[np.float64]
    intensity_cd: NDArray[np.float64]
    exponent: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.position)

    @property
    def flux_lm(self) -> NDArray[np.float64]:
        """(S,) total emitted flux Φ = 2π·I0/(n+1), lm (REALISM §3.1)."""
        return 2 * np.pi * self.intensity_cd / (self.exponent + 1)

    @classmethod
    def from_arrays(
        cls, position: ArrayLike, axis: ArrayLike, intensity_cd: ArrayLike, exponent: ArrayLike
    ) -> PointSources:
        """Sources from array-likes; the axes are normalised."""
        pos = np.asarray(position, dtype=float).reshape(-1, 3)
        ax = np.asarray(axis, dtype=float).reshape(-1, 3)
        ax = ax / np.linalg.norm(ax, axis=1, keepdims=True)
        n = len(pos)
        return cls(
            position=pos,
            axis=ax,
            intensity_cd=np.broadcast_to(np.asarray(intensity_cd, dtype=float), (n,)).copy(),
            exponent=np.broadcast_to(np.asarray(exponent, dtype=float), (n,)).copy(),
        )

    @classmethod
    def empty(cls) -> PointSources:
        """No sources at all."""
        return cls(
            position=np.zeros((0, 3)),
            axis=np.zeros((0, 3)),
            intensity_cd=np.zeros(0),
            exponent=np.zeros(0),
        )

    @classmethod
    def concat(cls, *groups: PointSources) -> PointSources:
        """All sources of ``groups`` as one set, in order."""
        return cls(
            position=np.concatenate([g.position for g in groups]),
            axis=np.concatenate([g.axis for g in groups]),
            intensity_cd=np.concatenate([g.intensity_cd for g in groups]),
            exponent=np.concatenate([g.exponent for g in groups]),
        )


def direct_illuminance(
    sources: PointSources,
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    plan: FloorPlan | None = None,
) -> NDArray[np.float64]:
    """(N,) direct illuminance (lx) of point sources on receivers, with wall occlusion.

    E = Σ_s I0_s·cosⁿθ_s · max(0, n̂·ŝ_s)/d_s² · T_s (REALISM §3.1), θ_s the
    angle between source s's axis and the direction source→receiver.

    Args:
        sources: the emitters.
        points: (N, 3) receiver positions, m.
        normals: (N, 3) receiver unit normals.
        plan: occluding geometry; ``None`` for free space.
    """
    out = np.zeros(len(points))
    for pos, axis, i0, n in zip(
        sources.position, sources.axis, sources.intensity_cd, sources.exponent, strict=True
    ):
        if i0 == 0:
            continue
        v = pos - points  # receiver → source
        d2 = np.maximum(np.einsum("ij,ij->i", v, v), MIN_DISTANCE_M**2)
        d = np.sqrt(d2)
        cos_theta = -(v @ axis) / d
        cos_psi = np.einsum("ij,ij->i", normals, v) / d
        # Only receivers in front of the source and facing it get light; the
        # occlusion query, the costly part, runs on those alone.
        lit = np.flatnonzero((cos_theta > 0) & (cos_psi > 0))
        if lit.size == 0:
            continue
        e = i0 * cos_theta[lit] ** n * cos_psi[lit] / d2[lit]
        if plan is not None:
            e *= plan.light_transmittance(points[lit, :2], pos[None, :2])
        out[lit] += e
    return out


@dataclass(frozen=True, kw_only=True)
class RoomAmbient:
    """Uniform inter-reflected illuminance per room (REALISM §3.4).

    The split-flux / integrating-sphere approximation: the flux Φ emitted in a
    room is reflected around its surfaces A = 2·area + perimeter·h (floor,
    ceiling, walls) of mean reflectance ρ̄, so every surface receives in total
    E_tot = Φ/(A(1−ρ̄)) and the inter-reflected part is
    E_ind = Φ·ρ̄/(A(1−ρ̄)) (REALISM §3.4), which an upward receiver reads.

    A receiver tilted to normal n̂ sees the upper hemisphere (ceiling and walls,
    exitance E_ind) with view factor (1+n_z)/2 and the floor with (1−n_z)/2, as
    in the isotropic tilted-surface model (Liu & Jordan). The floor's exitance is
    its own reflectance times what it receives, ρ_floor·E_tot, so

        E_amb(n̂) = E_ind·(1+n_z)/2 + E_ind·(ρ_floor/ρ̄)·(1−n_z)/2.

    A sensor facing up reads E_ind, one facing down reads the floor's
    exitance; with ρ_floor = 0 this reduces to the plain (1+n_z)/2 scaling.

    Light leaks through open doors: an opening of area A_d in a diffuse field
    passes the flux E_tot·A_d, which the neighbouring room then spreads over
    its own surfaces like a source of its own (one pass: what leaks back is
    second order). A dark room beside a lit corridor so reads a few lux rather
    than none (REALISM §3.4). Sources in no room feed no ambient term, and
    points in no room get 0.

    Attributes:
        rooms: room footprints (``plan.rooms``).
        upper_lux: (R,) E_ind per room, lx.
        lower_lux: (R,) floor exitance ρ_floor·E_tot per room, lx.
    """

    rooms: list[Polygon]
    upper_lux: NDArray[np.float64]
    lower_lux: NDArray[np.float64]

    @classmethod
    def from_sources(
        cls,
        rooms: list[Polygon],
        sources: PointSources,
        ceiling_height: float,
        reflectance: ReflectanceSpec,
        openings: Sequence[tuple[int, int, float]] = (),
    ) -> RoomAmbient:
        """Sum each source's flux into the room that contains it and apply the sphere model.

        Args:
            openings: (room i, room j, area m²) of each open door between two rooms.
        """
        flux = np.zeros(len(rooms))
        x, y = sources.position[:, 0], sources.position[:, 1]
        emitted = sources.flux_lm
        for r, room in enumerate(rooms):
            flux[r] = emitted[shapely.contains_xy(room, x, y)].sum()
        area = np.array([room.area for room in rooms])
        wall_area = np.array([room.length for room in rooms]) * ceiling_height
        surface = 2 * area + wall_area
        rho = reflectance
        rho_mean = (rho.ceiling * area + rho.walls * wall_area + rho.floor * area) / surface
        own_total = flux / (surface * (1 - rho_mean))
        leaked = np.zeros(len(rooms))
        for i, j, door_area in openings:
            leaked[j] += own_total[i] * door_area
            leaked[i] += own_total[j] * door_area
        total = own_total + leaked / (surface * (1 - rho_mean))
        return cls(rooms=rooms, upper_lux=rho_mean * total, lower_lux=rho.floor * total)

    def __call__(
        self, points: NDArray[np.float64], normals: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(N,) ambient illuminance, lx, on receivers at (N, 3) points with (N, 3) unit normals."""
        out = np.zeros(len(points))
        up = (1 + normals[:, 2]) / 2
        for room, e_up, e_down in zip(self.rooms, self.upper_lux, self.lower_lux, strict=True):
            if e_up == 0 and e_down == 0:
                continue
            inside = shapely.contains_xy(room, points[:, 0], points[:, 1])
            out[inside] = e_up * up[inside] + e_down * (1 - up[inside])
        return out


def window_patches(
    scenario: Scenario, plan: FloorPlan, patch_m: float = DAYLIGHT_PATCH_M
) -> PointSources:
    """Daylight sources: every exterior window cut into Lambertian patches.

    A window is a uniform Lambertian emitter of luminance L = τ·E_v/π (τ the
    glazing transmittance, E_v the exterior vertical illuminance on the pane;
    uniform surroundings that put E_v on a plane have luminance E_v/π). A patch of area
    dA radiates I(θ) = L·dA·cos θ about the inward normal, whose flux is
    π·L·dA, so the patches of a window carry its full flux τ·E_v·A into the room.
    Patches are at most ``patch_m`` on a side and sit just inside the wall
    surface, so their own wall does not occlude them; other walls occlude as
    for luminaires.

    "Inward" is the side of the wall that lies inside ``plan.outline``. A
    window with the building on both sides (internal glazing) or on neither
    has no daylight behind it and yields no patches.

    Args:
        scenario: windows, walls and ``light.daylight``.
        plan: the floor plan (for the outline).
        patch_m: largest patch side, m.
    """
    daylight = scenario.light.daylight
    luminance = daylight.transmittance * daylight.exterior_vertical_lux / math.pi
    groups = [PointSources.empty()]
    for window in scenario.windows:
        wall = _host_wall(window, scenario.walls)
        p0, p1 = np.asarray(window.start, float), np.asarray(window.to, float)
        width = float(np.linalg.norm(p1 - p0))
        u = (p1 - p0) / width
        inward = _inward_normal(plan.outline, (p0 + p1) / 2, u, wall.thickness)
        if inward is None:
            continue
        height = window.head - window.sill
        nu, nv = math.ceil(width / patch_m), math.ceil(height / patch_m)
        su = (np.arange(nu) + 0.5) * width / nu
        sv = window.sill + (np.arange(nv) + 0.5) * height / nv
        inset = wall.thickness / 2 + _PATCH_INSET_M
        xy = p0 + np.outer(su, u) + inset * inward
        position = np.column_stack([np.repeat(xy, nv, axis=0), np.tile(sv, nu)])
        groups.append(
            PointSources.from_arrays(
                position,
                np.broadcast_to([inward[0], inward[1], 0.0], position.shape),
                luminance * (width / nu) * (height / nv),
                1.0,
            )
        )
    return PointSources.concat(*groups)


def _host_wall(window: WindowSpec, walls: list[WallSpec]) -> WallSpec:
    """The wall whose solid holds both ends of ``window`` (the scenario checks one exists)."""
    for wall in walls:
        line = LineString([wall.start, wall.to])
        if all(
            line.distance(Point(end)) <= wall.thickness / 2 + 1e-6
            for end in (window.start, window.to)
        ):
            return wall
    raise ValueError(f"window {window.start}→{window.to} does not lie on any wall")


def _inward_normal(
    outline: Polygon, mid: NDArray[np.float64], u: NDArray[np.float64], thickness: float
) -> NDArray[np.float64] | None:
    """The unit normal of a wall with direction ``u`` pointing into the building, if unique."""
    normal = np.array([-u[1], u[0]])
    probe = thickness / 2 + _PROBE_M
    inside = [outline.contains(Point(*(mid + s * probe * normal))) for s in (1.0, -1.0)]
    if inside == [True, False]:
        return normal
    if inside == [False, True]:
        return -normal
    return None


class LightModel:
    """Illuminance on receivers in a building: direct light, inter-reflections, daylight.

    See the module docstring for the model. Daylight patches and luminaires
    share one list of point sources and one direct-term kernel.

    Attributes:
        sources: luminaires first (``n_luminaires`` of them), then daylight
            patches (none unless ``scenario.light.daylight.enabled``).
        n_luminaires: how many of ``sources`` are luminaires.
        ambient: the per-room inter-reflection term, or ``None`` when
            ``scenario.light.ambient`` is off.
        plan: the occluding geometry.
    """

    def __init__(self, scenario: Scenario, plan: FloorPlan):
        self.plan = plan
        lums = scenario.luminaires
        luminaires = PointSources.from_arrays(
            np.array([lum.position for lum in lums], dtype=float).reshape(-1, 3),
            np.array([lum.axis for lum in lums], dtype=float).reshape(-1, 3),
            np.array([lum.intensity_cd for lum in lums], dtype=float),
            np.array([lum.exponent for lum in lums], dtype=float),
        )
        self.n_luminaires = len(luminaires)
        if scenario.light.daylight.enabled:
            self.sources = PointSources.concat(luminaires, window_patches(scenario, plan))
        else:
            self.sources = luminaires
        self.ambient: RoomAmbient | None = None
        if scenario.light.ambient:
            self.ambient = RoomAmbient.from_sources(
                plan.rooms,
                self.sources,
                scenario.site.ceiling_height,
                scenario.light.reflectance,
                door_openings(scenario, plan.rooms),
            )

    def illuminance(self, points: ArrayLike, normals: ArrayLike) -> NDArray[np.float64]:
        """(N,) illuminance in lux on receivers at (N, 3) points with (N, 3) unit normals.

        Args:
            points: (N, 3) receiver positions, m.
            normals: (N, 3) receiver normals (normalised here), or one (3,)
                normal for all receivers.

        Raises:
            ValueError: for arrays of the wrong shape or a zero-length normal.
        """
        p, n = _receivers(points, normals)
        out = direct_illuminance(self.sources, p, n, self.plan)
        if self.ambient is not None:
            out += self.ambient(p, n)
        return out


def _receivers(
    points: ArrayLike, normals: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    p = np.asarray(points, dtype=float)
    if p.ndim == 1 and p.shape == (3,):
        p = p[None, :]
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points: expected shape (N, 3), got {p.shape}")
    n = np.asarray(normals, dtype=float)
    if n.shape == (3,):
        n = np.broadcast_to(n, p.shape)
    if n.shape != p.shape:
        raise ValueError(f"normals: expected shape {p.shape} or (3,), got {n.shape}")
    length = np.linalg.norm(n, axis=1)
    if np.any(length < 1e-12):
        raise ValueError("normals: every normal must be a non-zero vector")
    return np.ascontiguousarray(p), n / length[:, None]


def door_openings(scenario: Scenario, rooms: list[Polygon]) -> list[tuple[int, int, float]]:
    """(room i, room j, area m²) for every door that joins two different rooms.

    The rooms on either side are found by probing just beyond the wall's faces
    at the door, along the wall's normal.
    """
    out = []
    for door in scenario.doors:
        p = np.asarray(door.position, dtype=float)
        for wall in scenario.walls:
            a, b = np.asarray(wall.start, float), np.asarray(wall.to, float)
            d = b - a
            length = float(np.hypot(*d))
            t = float(np.dot(p - a, d)) / length
            off = abs(d[0] * (p[1] - a[1]) - d[1] * (p[0] - a[0])) / length
            if not (0 <= t <= length and off <= wall.thickness / 2 + 1e-6):
                continue
            normal = np.array([-d[1], d[0]]) / length
            probes = p + np.outer([1.0, -1.0], normal) * (wall.thickness / 2 + 0.05)
            sides = [
                next((r for r, room in enumerate(rooms) if room.covers(Point(*q))), None)
                for q in probes
            ]
            if sides[0] is not None and sides[1] is not None and sides[0] != sides[1]:
                out.append((sides[0], sides[1], door.width * door.height))
            break
    return out
