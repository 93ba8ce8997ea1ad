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
  :mod:`indoorsim.world.sky`): each exterior window is cut into small patches
  (:func:`window_patches`), each a point source whose intensity toward a
  receiver is τ·F(θ)·L(û)·dA·cos θ: the luminance L of the CIE sky or the
  ground seen through it along the sight line û, through glazing that passes
  less at oblique incidence θ; the same direct-term kernel as the luminaires
  evaluates it. The sunbeam through the windows has its own kernel
  (:func:`~indoorsim.world.sky.sun_illuminance`), and each window's admitted
  flux feeds the ambient term.
* **The carrier's body** (REALISM §3.1, §3.5; see :class:`BodyShadow`): the
  head and trunk of the person holding the phone, per receiver, are opaque
  solids. A source's direct term is 0 when its sight line passes through
  them, and the ambient term loses the share of the receiver's
  cosine-weighted view they fill, less the light the body itself reflects
  (the solids and their kernels are in :mod:`indoorsim.world.body_shadow`).
* **The receiver's response**: a cosine receiver (an illuminance meter) by
  default; a phone's sensor behind its aperture responds as cosᵏψ, k ≥ 1
  (REALISM §1.6), exactly in the direct term and as for diffuse light,
  2/(k + 1), in the ambient term.

Units: m, cd, lm, lx, cd/m². Frame: the building frame, z up from the floor.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numba
import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from shapely.geometry import Point, Polygon

from indoorsim.world.body_shadow import (
    BODY_REFLECTANCE,
    NO_BODY,
    BodyShadow,
    face_in_view,
)
from indoorsim.world.plan import crosses_properly, near_walls
from indoorsim.world.sky import (
    SkyState,
    WindowApertures,
    glazing_transmission,
    sky_luminance,
    sun_illuminance,
)

if TYPE_CHECKING:
    from indoorsim.scenario.schema import ReflectanceSpec, Scenario
    from indoorsim.world.plan import FloorPlan

__all__ = [
    "LightModel",
    "PointSources",
    "RoomAmbient",
    "diffuse_response",
    "direct_illuminance",
    "window_flux_sources",
    "window_patches",
]

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


@dataclass(frozen=True, kw_only=True)
class PointSources:
    """S point sources with axially symmetric intensity I(θ) = intensity_cd · cos^exponent θ.

    Photometrically each source is a point (the far-field model). Its emitting
    face, a rectangle about the position across the axis, matters only where
    something near the receiver hides part of it: the carrier's body casts a
    penumbra, not a hard shadow (:func:`direct_illuminance`).

    Attributes:
        position: (S, 3) source positions, m.
        axis: (S, 3) unit vectors of peak emission (θ = 0).
        intensity_cd: (S,) peak intensity I0, cd.
        exponent: (S,) cosine-power n (1 = Lambertian; 0 = uniform over the front hemisphere).
        face_u: (S, 3) half the emitting face's length, as a vector across the axis, m
            (zero for a point).
        face_v: (S, 3) half its width, as a vector across the axis and ``face_u``, m.
    """

    position: NDArray[np.float64]
    axis: NDArray[np.float64]
    intensity_cd: NDArray[np.float64]
    exponent: NDArray[np.float64]
    face_u: NDArray[np.float64] | None = None
    face_v: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        # Faces default to points: zero half-extents.
        for name in ("face_u", "face_v"):
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.zeros((len(self.position), 3)))
            elif getattr(self, name).shape != (len(self.position), 3):
                raise ValueError(
                    f"PointSources.{name}: expected shape {(len(self.position), 3)}, "
                    f"got {getattr(self, name).shape}"
                )
        # The penumbra's shortcut needs the face's two half-extents at right angles.
        dots = np.abs(np.sum(self.face_u * self.face_v, axis=1))
        if np.any(dots > 1e-9 * (1.0 + np.sum(self.face_u**2 + self.face_v**2, axis=1))):
            raise ValueError("PointSources: face_u and face_v must be perpendicular")

    def __len__(self) -> int:
        return len(self.position)

    @property
    def flux_lm(self) -> NDArray[np.float64]:
        """(S,) total emitted flux Φ = 2π·I0/(n+1), lm (REALISM §3.1)."""
        return 2 * np.pi * self.intensity_cd / (self.exponent + 1)

    @classmethod
    def from_arrays(
        cls,
        position: ArrayLike,
        axis: ArrayLike,
        intensity_cd: ArrayLike,
        exponent: ArrayLike,
        size_m: ArrayLike = (0.0, 0.0),
        along: ArrayLike = (1.0, 0.0, 0.0),
    ) -> PointSources:
        """Sources from array-likes; the axes are normalised.

        Args:
            size_m: (S, 2) or (2,) the emitting face's length and width, m.
            along: (S, 3) or (3,) the direction of the face's length; its part
                across the axis is used (with the axis along it, the face
                takes a direction across the axis).
        """
        pos = np.asarray(position, dtype=float).reshape(-1, 3)
        ax = _unit_rows(np.asarray(axis, dtype=float).reshape(-1, 3))
        n = len(pos)
        size = np.broadcast_to(np.asarray(size_m, dtype=float), (n, 2))
        u = np.broadcast_to(np.asarray(along, dtype=float), (n, 3)).copy()
        u = _tame_rows(u)  # no overflow in the projection below
        u -= np.sum(u * ax, axis=1, keepdims=True) * ax
        length = np.linalg.norm(u, axis=1)
        # An ``along`` parallel to the axis: any direction across it.
        fallback = np.cross(ax, [0.0, 0.0, 1.0])
        fallback[np.linalg.norm(fallback, axis=1) < 1e-9] = [1.0, 0.0, 0.0]
        u = np.where(length[:, None] > 1e-9, u / np.maximum(length, 1e-12)[:, None], fallback)
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        v = np.cross(ax, u)
        return cls(
            position=pos,
            axis=ax,
            intensity_cd=np.broadcast_to(np.asarray(intensity_cd, dtype=float), (n,)).copy(),
            exponent=np.broadcast_to(np.asarray(exponent, dtype=float), (n,)).copy(),
            face_u=u * size[:, :1] / 2,
            face_v=v * size[:, 1:] / 2,
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
            face_u=np.concatenate([g.face_u for g in groups]),
            face_v=np.concatenate([g.face_v for g in groups]),
        )


def direct_illuminance(
    sources: PointSources,
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    plan: FloorPlan | None = None,
    body: BodyShadow | None = None,
    response_exponent: float = 1.0,
    sky: SkyState | None = None,
    sky_from: int | None = None,
) -> NDArray[np.float64]:
    """(N,) direct illuminance (lx) of point sources on receivers, with wall occlusion.

    E = Σ_s I0_s·cosⁿθ_s · max(0, n̂·ŝ_s)/d_s² · T_s (REALISM §3.1), θ_s the
    angle between source s's axis and the direction source→receiver.

    Args:
        sources: the emitters.
        points: (N, 3) receiver positions, m.
        normals: (N, 3) receiver unit normals.
        plan: occluding geometry; ``None`` for free space.
        body: the carrier's body at each receiver, which also occludes; ``None``
            for none. Its shadow is soft: the direct term is scaled by the share
            of points spread over the source's face
            (:data:`~indoorsim.world.body_shadow.FACE_STEP_M` apart,
            at most 12 a side) whose sight lines the body leaves clear.
        response_exponent: the receiver's angular response cosᵏψ (k = 1: a true
            cosine receiver, an illuminance meter; a phone's sensor behind its
            aperture is narrower,
            :func:`~indoorsim.phone.devices.cosine_power`). Calibrated at
            normal incidence, so a source straight ahead reads the same.
        sky: the daylight outside, with ``sky_from``: sources from that index
            on are window patches (:func:`window_patches`), whose intensity is
            scaled per sight line by the luminance of the sky or ground beyond
            the patch and the glazing's fall-off at its incidence.
    """
    if not response_exponent >= 1.0:
        raise ValueError(f"response_exponent must be ≥ 1, got {response_exponent}")
    out = np.zeros(len(points))
    if body is not None and len(body) != len(points):
        raise ValueError(f"body: {len(body)} poses for {len(points)} receivers")
    if plan is not None:
        sa, sb, elem, transmittance = plan.light_occluders
    else:
        sa, sb, elem, transmittance = (
            np.zeros((0, 2)),
            np.zeros((0, 2)),
            np.zeros(0, np.intp),
            np.zeros(0),
        )
    sa, sb = np.ascontiguousarray(sa, dtype=float), np.ascontiguousarray(sb, dtype=float)
    position = np.ascontiguousarray(sources.position, dtype=float)
    start, items = _occluders_by_direction(position, sa, sb)
    _direct(
        np.ascontiguousarray(points, dtype=float),
        np.ascontiguousarray(normals, dtype=float),
        position,
        np.ascontiguousarray(sources.axis, dtype=float),
        np.ascontiguousarray(sources.intensity_cd, dtype=float),
        np.ascontiguousarray(sources.exponent, dtype=float),
        np.ascontiguousarray(sources.face_u, dtype=float),
        np.ascontiguousarray(sources.face_v, dtype=float),
        sa,
        sb,
        np.ascontiguousarray(elem, dtype=np.intp),
        np.ascontiguousarray(transmittance, dtype=float),
        start,
        items,
        float(response_exponent),
        body is not None,
        body.kernel_args if body is not None else NO_BODY,
        len(sources) if sky is None or sky_from is None else int(sky_from),
        sky.kernel_args if sky is not None else _NO_SKY,
        out,
    )
    return out


_NO_SKY = np.zeros(12)


def diffuse_response(k: float) -> float:
    """What a cosᵏ receiver calibrated at normal incidence reads in a uniform diffuse
    field, as a share of the true illuminance: ∫cosᵏψ dΩ / ∫cosψ dΩ = 2/(k + 1)."""
    return 2.0 / (k + 1.0)


# Directions around a source are binned this finely for the occlusion test.
_DIRECTION_BINS = 128


def _occluders_by_direction(
    position: NDArray[np.float64], sa: NDArray[np.float64], sb: NDArray[np.float64]
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Per source and direction bin, the occluding segments that span that direction.

    A segment can cross the sight line from a source to a receiver only if
    it spans the receiver's direction as seen from the source (in the plan),
    so the occlusion test needs only the segments of that direction's bin:
    ``items[start[r]:start[r + 1]]`` with r = s·``_DIRECTION_BINS`` + k, in
    increasing order (an element's segments stay contiguous). Memoised on the
    arrays' contents (a site's sources and walls are fixed).
    """
    key = (position[:, :2].tobytes(), sa.tobytes(), sb.tobytes())
    hit = _DIRECTION_CACHE.get(key)
    if hit is None:
        counts = np.zeros((len(position), _DIRECTION_BINS), np.intp)
        _bin_directions(position, sa, sb, counts, np.zeros(0, np.intp), np.zeros(0, np.intp))
        start = np.zeros(counts.size + 1, np.intp)
        np.cumsum(counts.ravel(), out=start[1:])
        items = np.empty(start[-1], np.intp)
        _bin_directions(position, sa, sb, counts, start, items)
        hit = (start, items)
        if len(_DIRECTION_CACHE) >= 8:
            _DIRECTION_CACHE.pop(next(iter(_DIRECTION_CACHE)))
        _DIRECTION_CACHE[key] = hit
    return hit


_DIRECTION_CACHE: dict[tuple[bytes, bytes, bytes], tuple[NDArray[np.intp], NDArray[np.intp]]] = {}


@numba.njit(cache=True, inline="always", error_model="numpy")
def _pseudo_angle(dx, dy):  # pragma: no cover - compiled
    """A stand-in for the direction angle of (dx, dy), in [0, 4), increasing
    counter-clockwise from +x like the angle (but cheaper than atan2)."""
    if dx == 0.0 and dy == 0.0:
        return 0.0
    if dy >= 0.0:
        return dy / (dx + dy) if dx >= 0.0 else 1.0 - dx / (dy - dx)
    return 2.0 - dy / (-dx - dy) if dx < 0.0 else 3.0 + dx / (dx - dy)


@numba.njit(cache=True, inline="always", error_model="numpy")
def _direction_bin(dx, dy):  # pragma: no cover - compiled
    """The direction bin of (dx, dy): ``_DIRECTION_BINS`` equal pseudo-angle intervals."""
    k = int(_pseudo_angle(dx, dy) * (_DIRECTION_BINS / 4.0))
    return min(max(k, 0), _DIRECTION_BINS - 1)


@numba.njit(cache=True, error_model="numpy")
def _bin_directions(position, sa, sb, counts, start, items):  # pragma: no cover - compiled
    """Count (``items`` empty) or list each segment in the direction bins it spans, per source.

    The arc a segment spans from a source is the one shorter than π between
    its ends' directions; a segment through the source spans every bin. One
    bin of margin on each side absorbs rounding.
    """
    fill = items.shape[0] > 0
    nb = _DIRECTION_BINS
    for s in range(position.shape[0]):
        sx, sy = position[s, 0], position[s, 1]
        for j in range(sa.shape[0]):
            ax, ay, bx, by = sa[j, 0] - sx, sa[j, 1] - sy, sb[j, 0] - sx, sb[j, 1] - sy
            cross = ax * by - ay * bx
            if cross == 0.0 and ax * bx + ay * by <= 0.0:
                k0, n = 0, nb  # the source lies on the segment
            else:
                if cross < 0.0:
                    ax, ay, bx, by = bx, by, ax, ay  # counter-clockwise from a to b, less than π
                ka = _direction_bin(ax, ay) - 1
                kb = _direction_bin(bx, by) + 1
                if kb < ka:
                    kb += nb
                k0, n = ka, min(kb - ka + 1, nb)
            for k in range(k0, k0 + n):
                b = k % nb
                if fill:
                    row = s * nb + b
                    items[start[row] + counts[s, b] - 1] = j
                    counts[s, b] -= 1
                else:
                    counts[s, b] += 1


# Receivers are taken this many at a time: a source whose light an opaque
# element blocks from the whole group is skipped for all of them at once.
_CHUNK = 32


@numba.njit(cache=True, error_model="numpy")
def _direct(
    p,
    n,
    pos,
    axis,
    i0,
    expo,
    face_u,
    face_v,
    sa,
    sb,
    elem,
    transmittance,
    start,
    items,
    response,
    has_body,
    body,
    sky_from,
    sky,
    out,
):  # pragma: no cover - compiled
    """The sum of :func:`direct_illuminance`, each receiver's sources in order.

    Receivers come in chunks of consecutive points (a path's samples lie close
    together). A source is skipped for a whole chunk when a single opaque
    element shadows the chunk's bounding disc (:func:`_shadows_disc`), which
    is exact: every receiver in the disc is occluded. Otherwise the occlusion
    test (the costly part) runs per receiver in front of the source and
    facing it, against the segments that span its direction, unless none of
    those segments comes near the chunk's sight lines (:func:`_off_box`:
    then nothing is crossed, T = 1, exactly what the test would find). With
    ``has_body``, a source's term is scaled by the share of its face the
    receiver's body (the tuple :attr:`BodyShadow.kernel_args`) leaves in view
    (:func:`~indoorsim.world.body_shadow.face_in_view`). The receiver's
    response is cos^``response`` ψ. Sources from ``sky_from`` on are window
    patches: their term takes the luminance beyond them along the sight line
    (:func:`~indoorsim.world.sky.sky_luminance` of ``sky``) and the glazing's
    fall-off at the incidence θ on the pane.
    """
    d2_min = MIN_DISTANCE_M * MIN_DISTANCE_M
    nb = _DIRECTION_BINS
    m = p.shape[0]
    for c0 in range(0, m, _CHUNK):
        c1 = min(c0 + _CHUNK, m)
        lo_x, hi_x, lo_y, hi_y = p[c0, 0], p[c0, 0], p[c0, 1], p[c0, 1]
        for i in range(c0, c1):
            lo_x, hi_x = min(lo_x, p[i, 0]), max(hi_x, p[i, 0])
            lo_y, hi_y = min(lo_y, p[i, 1]), max(hi_y, p[i, 1])
        cx, cy = 0.5 * (lo_x + hi_x), 0.5 * (lo_y + hi_y)
        rho = 0.5 * math.sqrt((hi_x - lo_x) ** 2 + (hi_y - lo_y) ** 2) + 1e-9
        for s in range(pos.shape[0]):
            if i0[s] == 0:
                continue
            sx, sy, sz = pos[s, 0], pos[s, 1], pos[s, 2]
            if sa.shape[0]:
                row = s * nb + _direction_bin(cx - sx, cy - sy)
                if _shadows_disc(
                    sx,
                    sy,
                    cx,
                    cy,
                    rho,
                    sa,
                    sb,
                    elem,
                    transmittance,
                    items[start[row] : start[row + 1]],
                ):
                    continue
            ax, ay, az = axis[s, 0], axis[s, 1], axis[s, 2]
            # The plan box of the source and the chunk: a segment whose box lies
            # off it fails the box rejection of every sight line of the chunk, so
            # a direction bin holding only such segments is clear (T = 1).
            bx0, bx1 = min(lo_x, sx), max(hi_x, sx)
            by0, by1 = min(lo_y, sy), max(hi_y, sy)
            last_row, clear = -1, True
            for i in range(c0, c1):
                vx, vy, vz = sx - p[i, 0], sy - p[i, 1], sz - p[i, 2]  # receiver → source
                # The cosines' signs are their numerators' (d > 0): a receiver
                # behind the source or facing away is passed over before the
                # square root and the divisions.
                along = -(vx * ax + vy * ay + vz * az)
                facing = n[i, 0] * vx + n[i, 1] * vy + n[i, 2] * vz
                if along <= 0.0 or facing <= 0.0:
                    continue
                d2 = max(vx * vx + vy * vy + vz * vz, d2_min)
                d = math.sqrt(d2)
                cos_theta = along / d
                cos_psi = facing / d
                if cos_theta <= 0.0 or cos_psi <= 0.0:
                    continue  # (an underflow to 0)
                seen = 1.0
                if has_body:
                    seen = face_in_view(p[i, 0], p[i, 1], p[i, 2], s, pos, face_u, face_v, i, body)
                    if seen == 0.0:
                        continue
                t = 1.0
                if sa.shape[0]:
                    row = s * nb + _direction_bin(-vx, -vy)
                    near = items[start[row] : start[row + 1]]
                    if row != last_row:  # receivers of a chunk mostly share one or two bins
                        last_row = row
                        clear = _off_box(bx0, bx1, by0, by1, sa, sb, near)
                    if not clear:
                        t = _transmittance(
                            p[i, 0], p[i, 1], sx, sy, sa, sb, elem, transmittance, near
                        )
                        if t == 0.0:
                            continue  # it would add e·0 = 0: skip the power
                if response != 1.0:
                    cos_psi = cos_psi**response
                e = i0[s] * (cos_theta if expo[s] == 1.0 else cos_theta ** expo[s]) * cos_psi / d2
                if s >= sky_from:
                    e *= sky_luminance(vx / d, vy / d, vz / d, sky)
                    e *= glazing_transmission(cos_theta, sky[11])
                out[i] += e * t * seen


@numba.njit(cache=True, inline="always", error_model="numpy")
def _shadows_disc(sx, sy, cx, cy, rho, sa, sb, elem, value, idx):  # pragma: no cover - compiled
    """True when one opaque segment among ``idx`` blocks the sight line from the
    source (sx, sy) to every point of the disc (cx, cy, rho).

    A segment a→b properly crosses the sight line to p when p lies strictly
    inside the wedge of rays s→a, s→b and strictly beyond the line through a
    and b; for a whole disc, that holds when its centre is at least rho inside
    each of those three half-planes.
    """
    for j in idx:
        if value[elem[j]] != 0.0:
            continue
        ax, ay, bx, by = sa[j, 0] - sx, sa[j, 1] - sy, sb[j, 0] - sx, sb[j, 1] - sy
        qx, qy = cx - sx, cy - sy
        turn = ax * by - ay * bx
        if turn == 0.0:
            continue
        if turn < 0.0:
            ax, ay, bx, by = bx, by, ax, ay  # counter-clockwise from a to b
        la = math.sqrt(ax * ax + ay * ay)
        lb = math.sqrt(bx * bx + by * by)
        if ax * qy - ay * qx < rho * la:  # left of s→a by at least rho
            continue
        if qx * by - qy * bx < rho * lb:  # right of s→b by at least rho
            continue
        # Beyond the line a→b, on the side away from the source (s at the origin).
        ex, ey = bx - ax, by - ay
        le = math.sqrt(ex * ex + ey * ey)
        side_s = ex * (0.0 - ay) - ey * (0.0 - ax)
        side_q = ex * (qy - ay) - ey * (qx - ax)
        if side_s > 0.0:
            side_s, side_q = -side_s, -side_q
        if side_q >= rho * le and side_s < 0.0:
            return True
    return False


@numba.njit(cache=True, inline="always", error_model="numpy")
def _off_box(x0, x1, y0, y1, sa, sb, idx):  # pragma: no cover - compiled
    """True when every segment among ``idx`` has its box strictly off the box
    [x0, x1] × [y0, y1]: the first test of ``crosses_properly`` then rejects it
    for any sight line inside that box."""
    for j in idx:
        if max(sa[j, 0], sb[j, 0]) < x0 or min(sa[j, 0], sb[j, 0]) > x1:
            continue
        if max(sa[j, 1], sb[j, 1]) < y0 or min(sa[j, 1], sb[j, 1]) > y1:
            continue
        return False
    return True


@numba.njit(cache=True, inline="always", error_model="numpy")
def _transmittance(x0, y0, x1, y1, sa, sb, elem, value, idx):  # pragma: no cover - compiled
    """Π value[element] over the distinct elements among segments ``idx`` that
    (x0, y0)→(x1, y1) properly crosses (:func:`~indoorsim.world.plan.fold_segment`)."""
    acc = 1.0
    counted = -1
    for j in idx:
        if not crosses_properly(x0, y0, x1, y1, sa[j, 0], sa[j, 1], sb[j, 0], sb[j, 1]):
            continue
        e = elem[j]
        if e == counted:
            continue
        counted = e
        acc *= value[e]
        if acc == 0.0:
            return 0.0
    return acc


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
            # Only the points in the room's bounding box need the exact test.
            x0, y0, x1, y1 = room.bounds
            box = np.flatnonzero(
                (points[:, 0] >= x0)
                & (points[:, 0] <= x1)
                & (points[:, 1] >= y0)
                & (points[:, 1] <= y1)
            )
            inside = box[shapely.contains_xy(room, points[box, 0], points[box, 1])]
            out[inside] = e_up * up[inside] + e_down * (1 - up[inside])
        return out


def window_patches(
    windows: WindowApertures, transmittance: float, patch_m: float = DAYLIGHT_PATCH_M
) -> PointSources:
    """Daylight sources: every exterior window cut into patches of unit luminance.

    A patch of area dA seen from a receiver has the luminance L(û) of the sky
    or ground beyond it along the sight line û, through glazing of transmittance
    τ·F(θ) (:mod:`indoorsim.world.sky`), so its intensity toward the receiver is
    τ·F(θ)·L(û)·dA·cos θ about the inward normal. The patches carry
    I0 = τ·dA; the direct-term kernel multiplies in F(θ)·L(û) per sight line.
    Patches are at most ``patch_m`` on a side and sit just inside the wall
    surface, so their own wall does not occlude them; other walls occlude as
    for luminaires.

    Args:
        windows: the exterior windows (:class:`~indoorsim.world.sky.WindowApertures`).
        transmittance: τ, the glazing's at normal incidence.
        patch_m: largest patch side, m.
    """
    groups = [PointSources.empty()]
    for k in range(len(windows)):
        p0, p1, inward = windows.start[k], windows.end[k], windows.inward[k]
        width = float(np.linalg.norm(p1 - p0))
        u = (p1 - p0) / width
        height = float(windows.head[k] - windows.sill[k])
        nu, nv = math.ceil(width / patch_m), math.ceil(height / patch_m)
        su = (np.arange(nu) + 0.5) * width / nu
        sv = windows.sill[k] + (np.arange(nv) + 0.5) * height / nv
        inset = windows.half_thickness[k] + _PATCH_INSET_M
        xy = p0 + np.outer(su, u) + inset * inward
        position = np.column_stack([np.repeat(xy, nv, axis=0), np.tile(sv, nu)])
        groups.append(
            PointSources.from_arrays(
                position,
                np.broadcast_to([inward[0], inward[1], 0.0], position.shape),
                transmittance * (width / nu) * (height / nv),
                1.0,
                size_m=(width / nu, height / nv),
                along=(u[0], u[1], 0.0),
            )
        )
    return PointSources.concat(*groups)


def window_flux_sources(windows: WindowApertures, sky: SkyState) -> PointSources:
    """One Lambertian stand-in per window carrying the flux its pane admits,
    A·E_pane (:meth:`SkyState.pane_lux`), for the ambient term's flux balance."""
    if len(windows) == 0:
        return PointSources.empty()
    flux = np.array(
        [
            float(np.linalg.norm(windows.end[k] - windows.start[k]))
            * float(windows.head[k] - windows.sill[k])
            * sky.pane_lux(np.array([-windows.inward[k, 0], -windows.inward[k, 1], 0.0]))
            for k in range(len(windows))
        ]
    )
    inset = windows.half_thickness + _PATCH_INSET_M
    xy = (windows.start + windows.end) / 2 + inset[:, None] * windows.inward
    position = np.column_stack([xy, (windows.sill + windows.head) / 2])
    axis = np.column_stack([windows.inward, np.zeros(len(windows))])
    return PointSources.from_arrays(position, axis, flux / math.pi, 1.0)


class LightModel:
    """Illuminance on receivers in a building: direct light, inter-reflections, daylight.

    See the module docstring for the model. Daylight patches and luminaires
    share one list of point sources and one direct-term kernel; the sunbeam
    has its own (:func:`~indoorsim.world.sky.sun_illuminance`).

    Attributes:
        sources: luminaires first (``n_luminaires`` of them), then daylight
            patches (none unless ``scenario.light.daylight.enabled`` in daytime).
        n_luminaires: how many of ``sources`` are luminaires.
        sky: the daylight outside, or ``None`` when daylight is off.
        windows: the exterior windows daylight comes through.
        ambient: the per-room inter-reflection term, or ``None`` when
            ``scenario.light.ambient`` is off.
        plan: the occluding geometry.
    """

    def __init__(self, scenario: Scenario, plan: FloorPlan):
        self.plan = plan
        self.ceiling_height = scenario.site.ceiling_height
        lums = [lum for lum in scenario.luminaires if lum.lit]
        luminaires = PointSources.from_arrays(
            np.array([lum.position for lum in lums], dtype=float).reshape(-1, 3),
            np.array([lum.axis for lum in lums], dtype=float).reshape(-1, 3),
            np.array([lum.intensity_cd for lum in lums], dtype=float),
            np.array([lum.exponent for lum in lums], dtype=float),
            np.array([lum.size for lum in lums], dtype=float).reshape(-1, 2),
            np.array([lum.along for lum in lums], dtype=float).reshape(-1, 3),
        )
        self.n_luminaires = len(luminaires)
        self.sources = luminaires
        self.sky: SkyState | None = None
        self.windows = WindowApertures.of(scenario, plan.outline)
        flux_sources = luminaires
        daylight = scenario.light.daylight
        if daylight.enabled:
            self.sky = SkyState.from_spec(scenario.site, daylight)
            if self.sky.daytime and len(self.windows):
                patches = window_patches(self.windows, daylight.transmittance)
                self.sources = PointSources.concat(luminaires, patches)
                flux_sources = PointSources.concat(
                    luminaires, window_flux_sources(self.windows, self.sky)
                )
        self.ambient: RoomAmbient | None = None
        if scenario.light.ambient:
            self.ambient = RoomAmbient.from_sources(
                plan.rooms,
                flux_sources,
                scenario.site.ceiling_height,
                scenario.light.reflectance,
                door_openings(scenario, plan.rooms),
            )

    def illuminance(
        self,
        points: ArrayLike,
        normals: ArrayLike,
        body: BodyShadow | None = None,
        response_exponent: float = 1.0,
    ) -> NDArray[np.float64]:
        """(N,) illuminance in lux on receivers at (N, 3) points with (N, 3) unit normals.

        Args:
            points: (N, 3) receiver positions, m.
            normals: (N, 3) receiver normals (normalised here), or one (3,)
                normal for all receivers.
            body: the carrier's body at each receiver. It stops the direct
                light whose sight line it crosses, and takes its share f of the
                receiver's view of the room (:meth:`BodyShadow.view_blocked`)
                from the ambient term, giving back what it reflects:
                E_amb·(1 − (1 − ρ_body)·f), ρ_body = :data:`BODY_REFLECTANCE`.
            response_exponent: the receiver's angular response cosᵏψ (1: an
                illuminance meter). The direct term takes it exactly; the
                ambient term, taken as diffuse, the share :func:`diffuse_response`.
                (The body's share f stays cosine-weighted: for k ≈ 1.8 a cosᵏ
                weighting would change the ambient term by about 3 %.)

        Raises:
            ValueError: for arrays of the wrong shape or a zero-length normal.
        """
        p, n = _receivers(points, normals)
        out = direct_illuminance(
            self.sources, p, n, self.plan, body, response_exponent, self.sky, self.n_luminaires
        )
        if self.sky is not None and self.sky.sun_normal_lux > 0.0:
            out += sun_illuminance(
                self.sky,
                p,
                n,
                self.plan,
                self.windows,
                self.ceiling_height,
                body,
                response_exponent,
            )
        if self.ambient is not None:
            ambient = self.ambient(p, n)
            if body is not None:
                ambient *= 1.0 - (1.0 - BODY_REFLECTANCE) * body.view_blocked(p, n)
            if response_exponent != 1.0:
                ambient *= diffuse_response(response_exponent)
            out += ambient
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
    # Only the walls whose (grown) bounding box holds a door can have it on them.
    near = near_walls([door.position for door in scenario.doors], scenario.walls)
    for door, candidates in zip(scenario.doors, near, strict=True):
        p = np.asarray(door.position, dtype=float)
        for j in np.flatnonzero(candidates).tolist():
            wall = scenario.walls[j]
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


_HUGE = 1e150  # a component whose square would overflow


def _tame_rows(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rows with a component beyond ±1e150 divided by their largest one (the same
    direction, squares that do not overflow); every other row exactly as given."""
    big = np.max(np.abs(v), axis=1, keepdims=True)
    return np.where(big > _HUGE, v / np.where(big > _HUGE, big, 1.0), v)


def _unit_rows(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Each row of ``v`` scaled to length 1; rows of components near 1e300 too (their
    squares would overflow), so a direction given as (1e300, 0, 0) is +x."""
    v = _tame_rows(v)
    return v / np.linalg.norm(v, axis=1, keepdims=True)
