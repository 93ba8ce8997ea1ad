"""The carrier's body in the light model: a head and a trunk that occlude, per receiver.

:class:`BodyShadow` holds the solids, one pose per receiver; its compiled
kernels test a sight line against them (:func:`body_blocks`), give the share of
a source's emitting face seen past them (:func:`face_in_view`, which the
direct-term kernel of :mod:`indoorsim.world.light` calls per source and
receiver) and the share of a receiver's cosine-weighted view they fill (for
the ambient term). The kernels take the body as the one tuple
:attr:`BodyShadow.kernel_args`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "BODY_REFLECTANCE",
    "FACE_STEP_M",
    "NO_BODY",
    "VIEW_DIRECTIONS",
    "BodyShadow",
    "body_blocks",
    "face_in_view",
]

BODY_REFLECTANCE = 0.35
"""Mean diffuse reflectance of a clothed body (skin 0.35–0.5, clothing 0.1–0.6) [E]:
the share of the light falling on the body that it sends back toward the sensor."""


@dataclass(frozen=True, kw_only=True)
class BodyShadow:
    """The carrier's head and trunk as opaque solids, one pose per receiver.

    The head is a sphere; the trunk an upright elliptic cylinder up to the
    shoulders (and on down, for the legs), its short axis along the way the trunk faces.
    Sizes are anthropometric (:mod:`indoorsim.walker.carry` builds them from
    the walker's height); the arms and the hand are not modelled.

    Attributes:
        head: (N, 3) centre of the head, m.
        head_radius_m: the head sphere's radius.
        trunk_xy: (N, 2) the trunk's axis in plan, m.
        trunk_yaw: (N,) the direction the trunk faces, rad from +x.
        trunk_top: (N,) height of the shoulders, m.
        trunk_half_depth_m: semi-axis front to back.
        trunk_half_width_m: semi-axis side to side.
    """

    head: NDArray[np.float64]
    head_radius_m: float
    trunk_xy: NDArray[np.float64]
    trunk_yaw: NDArray[np.float64]
    trunk_top: NDArray[np.float64]
    trunk_half_depth_m: float
    trunk_half_width_m: float

    def __post_init__(self) -> None:
        for name in ("head", "trunk_xy", "trunk_yaw", "trunk_top"):
            value = np.asarray(getattr(self, name), dtype=float)
            if not np.isfinite(value).all():
                raise ValueError(f"BodyShadow.{name}: every value must be finite")
            object.__setattr__(self, name, value)
        n = len(self.head)
        shapes = {
            "head": (self.head.shape, (n, 3)),
            "trunk_xy": (self.trunk_xy.shape, (n, 2)),
            "trunk_yaw": (self.trunk_yaw.shape, (n,)),
            "trunk_top": (self.trunk_top.shape, (n,)),
        }
        for name, (got, want) in shapes.items():
            if got != want:
                raise ValueError(f"BodyShadow.{name}: expected shape {want}, got {got}")
        for name in ("head_radius_m", "trunk_half_depth_m", "trunk_half_width_m"):
            if not getattr(self, name) > 0:
                raise ValueError(f"BodyShadow.{name} must be > 0, got {getattr(self, name)}")

    def __len__(self) -> int:
        return len(self.head)

    @cached_property
    def kernel_args(self) -> tuple:
        """The arrays and sizes the compiled kernels take, as one tuple:
        (head, head radius, trunk_xy, cos yaw, sin yaw, trunk_top, half-depth,
        half-width), contiguous; worked out once per pose set."""
        return (
            np.ascontiguousarray(self.head, dtype=float),
            float(self.head_radius_m),
            np.ascontiguousarray(self.trunk_xy, dtype=float),
            np.ascontiguousarray(np.cos(self.trunk_yaw), dtype=float),
            np.ascontiguousarray(np.sin(self.trunk_yaw), dtype=float),
            np.ascontiguousarray(self.trunk_top, dtype=float),
            float(self.trunk_half_depth_m),
            float(self.trunk_half_width_m),
        )

    def blocks(self, points: ArrayLike, targets: ArrayLike) -> NDArray[np.bool_]:
        """(N,) whether the segment from each receiver ``points[i]`` to ``targets[i]``
        passes through the body (N, 3 each)."""
        p = np.ascontiguousarray(points, dtype=float)
        q = np.ascontiguousarray(targets, dtype=float)
        if p.shape != (len(self), 3) or q.shape != p.shape:
            raise ValueError(
                f"points and targets must be ({len(self)}, 3), got {p.shape}, {q.shape}"
            )
        out = np.zeros(len(p), np.bool_)
        _blocks_each(p, q, self.kernel_args, out)
        return out

    def view_blocked(self, points: ArrayLike, normals: ArrayLike) -> NDArray[np.float64]:
        """(N,) share of each receiver's cosine-weighted view of the room the body fills.

        Estimated with :data:`VIEW_DIRECTIONS` fixed, cosine-weighted directions
        about the normal (a Fibonacci spiral on the unit disc, lifted onto the
        hemisphere), so the share is exact to about 1/``VIEW_DIRECTIONS`` and
        the same for the same pose.
        """
        p = np.ascontiguousarray(points, dtype=float)
        n = np.ascontiguousarray(normals, dtype=float)
        if p.shape != (len(self), 3) or n.shape != p.shape:
            raise ValueError(
                f"points and normals must be ({len(self)}, 3), got {p.shape}, {n.shape}"
            )
        length = np.linalg.norm(n, axis=1, keepdims=True)
        if not (length > 1e-12).all():
            raise ValueError("normals: every normal must be a non-zero vector")
        out = np.zeros(len(p))
        _view_blocked(p, np.ascontiguousarray(n / length), _VIEW_DISC, self.kernel_args, out)
        return out


VIEW_DIRECTIONS = 96
"""Directions per receiver for the body's share of the ambient view."""


def _fibonacci_disc(k: int) -> NDArray[np.float64]:
    """(k, 3) points spread evenly over the unit disc (Vogel's spiral), lifted to
    z = √(1 − r²): cosine-weighted directions on the hemisphere about +z."""
    i = np.arange(k) + 0.5
    r = np.sqrt(i / k)
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - r * r)])


_VIEW_DISC = _fibonacci_disc(VIEW_DIRECTIONS)

# How far a view ray is followed: past any part of the body.
_VIEW_REACH_M = 4.0


@numba.njit(cache=True, inline="always", error_model="numpy")
def body_blocks(px, py, pz, qx, qy, qz, i, body, grow):  # pragma: no cover - compiled
    """True when the segment p→q passes through receiver i's head sphere or trunk
    (an upright elliptic cylinder under ``top[i]``), each grown to hold every
    point within ``grow`` m of it: the sphere's radius and the top by ``grow``,
    the ellipse scaled by 1 + grow/(its smaller semi-axis) (adding ``grow`` to
    both semi-axes would not hold the offset ellipse unless it were a circle)."""
    head, head_r, trunk, cos_yaw, sin_yaw, top, half_depth, half_width = body
    if grow > 0.0:
        head_r = head_r + grow
        scale = 1.0 + grow / min(half_depth, half_width)
        half_depth, half_width = scale * half_depth, scale * half_width
    dx, dy, dz = qx - px, qy - py, qz - pz
    length2 = dx * dx + dy * dy + dz * dz
    if length2 == 0.0:
        return False
    # Head: the segment's closest approach to the centre.
    hx, hy, hz = head[i, 0] - px, head[i, 1] - py, head[i, 2] - pz
    u = min(max((hx * dx + hy * dy + hz * dz) / length2, 0.0), 1.0)
    ex, ey, ez = hx - u * dx, hy - u * dy, hz - u * dz
    if ex * ex + ey * ey + ez * ez < head_r * head_r:
        return True
    # Trunk: the part of the segment below the shoulders, in the trunk's frame
    # scaled to a unit circle; the least |a + u·b|² over that part.
    lo, hi = 0.0, 1.0
    roof = top[i] + grow
    if dz > 0.0:
        hi = min(hi, (roof - pz) / dz)
    elif dz < 0.0:
        lo = max(lo, (roof - pz) / dz)
    elif pz > roof:
        return False
    if hi < lo:
        return False
    c, s = cos_yaw[i], sin_yaw[i]
    rx, ry = px - trunk[i, 0], py - trunk[i, 1]
    ax = (c * rx + s * ry) / half_depth
    ay = (-s * rx + c * ry) / half_width
    bx = (c * dx + s * dy) / half_depth
    by = (-s * dx + c * dy) / half_width
    bb = bx * bx + by * by
    u = lo
    if bb > 0.0:
        u = min(max(-(ax * bx + ay * by) / bb, lo), hi)
    fx, fy = ax + u * bx, ay + u * by
    return fx * fx + fy * fy < 1.0


@numba.njit(cache=True, error_model="numpy")
def _blocks_each(p, q, body, out):  # pragma: no cover - compiled
    for i in range(p.shape[0]):
        out[i] = body_blocks(p[i, 0], p[i, 1], p[i, 2], q[i, 0], q[i, 1], q[i, 2], i, body, 0.0)


@numba.njit(cache=True, error_model="numpy")
def _view_blocked(p, n, disc, body, out):  # pragma: no cover - compiled
    """Per receiver, the share of the cosine-weighted directions ``disc`` (lifted
    about the normal) whose rays the body stops within ``_VIEW_REACH_M``.

    The ray tests of :func:`body_blocks`, with what depends on the receiver
    alone (its offset from the head, its place in the trunk's scaled frame)
    worked out once per receiver rather than once per ray.
    """
    head, head_r, trunk, cos_yaw, sin_yaw, top, half_depth, half_width = body
    k = disc.shape[0]
    reach = _VIEW_REACH_M
    r2 = head_r * head_r
    for i in range(p.shape[0]):
        nx, ny, nz = n[i, 0], n[i, 1], n[i, 2]
        # An orthonormal frame (t1, t2, n) about the normal.
        if abs(nz) < 0.9:
            t1x, t1y, t1z = -ny, nx, 0.0
        else:
            t1x, t1y, t1z = 0.0, -nz, ny
        norm = math.sqrt(t1x * t1x + t1y * t1y + t1z * t1z)
        t1x, t1y, t1z = t1x / norm, t1y / norm, t1z / norm
        t2x, t2y, t2z = ny * t1z - nz * t1y, nz * t1x - nx * t1z, nx * t1y - ny * t1x
        hx, hy, hz = head[i, 0] - p[i, 0], head[i, 1] - p[i, 1], head[i, 2] - p[i, 2]
        hh = hx * hx + hy * hy + hz * hz
        c, s = cos_yaw[i], sin_yaw[i]
        rx, ry = p[i, 0] - trunk[i, 0], p[i, 1] - trunk[i, 1]
        ax = (c * rx + s * ry) / half_depth
        ay = (-s * rx + c * ry) / half_width
        aa = ax * ax + ay * ay
        roof = top[i] - p[i, 2]  # the shoulders' height above the receiver
        hit = 0
        for j in range(k):
            a, b, w = disc[j, 0], disc[j, 1], disc[j, 2]
            wx = a * t1x + b * t2x + w * nx
            wy = a * t1y + b * t2y + w * ny
            wz = a * t1z + b * t2z + w * nz
            # Head: the ray's closest approach, within its reach.
            u = min(max(hx * wx + hy * wy + hz * wz, 0.0), reach)
            if hh - 2.0 * u * (hx * wx + hy * wy + hz * wz) + u * u < r2:
                hit += 1
                continue
            # Trunk: the part of the ray below the shoulders, in the scaled frame.
            lo, hi = 0.0, reach
            if wz > 0.0:
                hi = min(hi, roof / wz)
            elif wz < 0.0:
                lo = max(lo, roof / wz)
            elif roof < 0.0:
                continue
            if hi < lo:
                continue
            bx = (c * wx + s * wy) / half_depth
            by = (-s * wx + c * wy) / half_width
            bb = bx * bx + by * by
            ab = ax * bx + ay * by
            u = lo
            if bb > 0.0:
                u = min(max(-ab / bb, lo), hi)
            if aa + 2.0 * u * ab + u * u * bb < 1.0:
                hit += 1
        out[i] = hit / k


FACE_STEP_M = 0.1
"""Spacing of the points over a source's face for its body penumbra, m. The head,
a few tenths of a metre from the sensor, shades a patch of the ceiling several
times its own size, so this resolves the penumbra well."""
_FACE_POINTS_MAX = 12  # per side of the face


@numba.njit(cache=True, inline="always", error_model="numpy")
def face_in_view(px, py, pz, s, pos, face_u, face_v, i, body):  # pragma: no cover - compiled
    """The share of source s's face that receiver i sees past its body, in [0, 1].

    When even the body grown by the face's half-diagonal leaves the sight line
    to the centre clear, every sight line to the face is clear (each stays
    within that distance of it, ``face_u`` ⟂ ``face_v``): 1 at once. Otherwise
    the face is sampled on an even grid of cells :data:`FACE_STEP_M` on a side
    or less, up to ``_FACE_POINTS_MAX`` per side (wider cells on faces over
    1.2 m). A count a rounding error past a whole number is not rounded up.
    """
    ux, uy, uz = face_u[s, 0], face_u[s, 1], face_u[s, 2]
    vx, vy, vz = face_v[s, 0], face_v[s, 1], face_v[s, 2]
    lu = math.sqrt(ux * ux + uy * uy + uz * uz)
    lv = math.sqrt(vx * vx + vy * vy + vz * vz)
    sx, sy, sz = pos[s, 0], pos[s, 1], pos[s, 2]
    reach = math.sqrt(lu * lu + lv * lv)
    if not body_blocks(px, py, pz, sx, sy, sz, i, body, reach):
        return 1.0
    if reach == 0.0:
        return 0.0
    nu = min(max(math.ceil(2.0 * lu / FACE_STEP_M - 1e-9), 1), _FACE_POINTS_MAX)
    nv = min(max(math.ceil(2.0 * lv / FACE_STEP_M - 1e-9), 1), _FACE_POINTS_MAX)
    clear = 0
    for a in range(nu):
        fa = 2.0 * (a + 0.5) / nu - 1.0
        for b in range(nv):
            fb = 2.0 * (b + 0.5) / nv - 1.0
            qx = sx + fa * ux + fb * vx
            qy = sy + fa * uy + fb * vy
            qz = sz + fa * uz + fb * vz
            if not body_blocks(px, py, pz, qx, qy, qz, i, body, 0.0):
                clear += 1
    return clear / (nu * nv)


NO_BODY = (
    np.zeros((1, 3)),
    1.0,
    np.zeros((1, 2)),
    np.ones(1),
    np.zeros(1),
    np.zeros(1),
    1.0,
    1.0,
)
"""The kernels' body tuple when there is no body (never read: a flag says so)."""
