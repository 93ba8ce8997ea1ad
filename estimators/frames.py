"""Frame helpers shared by the estimators: vectors to the world, headings, yaw rates.

Frames (DESIGN §2): the phone frame is Android's sensor frame (x right, y up
the screen, z out of the screen); fused rotations are unit quaternions
world←phone, scalar first. The rotation vector's world frame is Android's —
x magnetic east, y magnetic north, z up — and building-frame headings are
counter-clockwise from the building's +x axis, so a heading measured in the
rotation-vector frame becomes a building heading by adding
:attr:`~indoorsim.estimators.base.SiteContext.magnetic_to_building_rad`.
"""

from __future__ import annotations

from collections.abc import Mapping

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.util import quaternion
from indoorsim.util.kernels import hamilton, normalised, quat_from_rotvec
from indoorsim.windows import PRESENT_ORDER

__all__ = [
    "gyro_attitude",
    "heading_from_rotation",
    "to_world",
    "wrap_angle",
    "yaw_rate",
]

# Below this norm a vector carries no direction (a missing stream is all zeros).
_TINY = 1e-9


def wrap_angle(angle: ArrayLike) -> NDArray[np.float64]:
    """Angles wrapped to [−π, π).

    >>> wrap_angle([0.0, 3 * np.pi / 2]).round(4).tolist()
    [0.0, -1.5708]
    """
    return (np.asarray(angle, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi


def to_world(rotation: ArrayLike, vectors: ArrayLike) -> NDArray[np.float64]:
    """Phone-frame vectors (N, 3) rotated to the world by quaternions (N, 4), v_w = q ⊗ v ⊗ q*.

    The quaternions are normalised first (held or logged values drift from unit
    norm); an all-zero quaternion counts as the identity.
    """
    return quaternion.rotate(quaternion.normalise(rotation, min_norm=_TINY), vectors)


def heading_from_rotation(
    rotation: ArrayLike,
    magnetic_to_building_rad: float,
    axis: ArrayLike = (0.0, 1.0, 0.0),
) -> NDArray[np.float64]:
    """Building-frame heading of a phone axis from the fused rotation vector.

    The axis v (default +y, the top of the screen: the walking direction of a
    phone held in front) is rotated to the rotation-vector frame, projected on
    the horizontal plane and measured from magnetic east:

        ψ = atan2(v_north, v_east) + magnetic_to_building_rad, wrapped to [−π, π).

    Args:
        rotation: (N, 4) world←phone quaternions of the rotation vector.
        magnetic_to_building_rad: ``SiteContext.magnetic_to_building_rad``.
        axis: the phone-frame axis whose heading is wanted. It must not point
            straight up or down (its horizontal projection gives the heading).

    Returns:
        (N,) headings, rad counter-clockwise from the building's +x axis.
    """
    q = np.asarray(rotation, dtype=float)
    v = to_world(q, np.broadcast_to(np.asarray(axis, dtype=float), (*q.shape[:-1], 3)))
    return wrap_angle(np.arctan2(v[..., 1], v[..., 0]) + magnetic_to_building_rad)


def yaw_rate(gyro: ArrayLike, gravity: ArrayLike) -> NDArray[np.float64]:
    """Angular rate about the vertical, r = ω · ĝ with ĝ = g / ‖g‖.

    ``gravity`` is what Android's gravity sensor reports — the accelerometer's
    reading at rest — so in the phone frame it points *up*: r > 0 is a
    counter-clockwise turn seen from above, the sense in which building
    headings grow. Projecting on ĝ makes r independent of how the phone is
    tilted, which integrating the gyro's z axis alone is not.

    Args:
        gyro: (N, 3) angular rate, phone frame, rad/s.
        gravity: (N, 3) gravity (or any up-pointing vector), phone frame.

    Returns:
        (N,) yaw rates, rad/s; 0 where ``gravity`` is zero (no direction known).
    """
    w = np.asarray(gyro, dtype=float)
    g = np.asarray(gravity, dtype=float)
    norm = np.linalg.norm(g, axis=-1)
    dot = np.einsum("...i,...i->...", w, g)
    return np.where(norm > _TINY, dot / np.where(norm > _TINY, norm, 1.0), 0.0)


def gyro_attitude(
    q0: ArrayLike, t0: float, w0: ArrayLike, t: ArrayLike, gyro: ArrayLike
) -> NDArray[np.float64]:
    """World←phone attitudes at ``t`` (N,) carried from ``q0`` (at ``t0``, rate ``w0``) by
    the gyro alone: q ← q ⊗ exp(½·ω̄·Δt), ω̄ the mean of consecutive rates, phone frame.

    Whole-attitude propagation has none of ∫ω·ĝ's creep when the tilt circulates
    (:func:`yaw_rate`); only the gyro's own errors accumulate.
    """
    w = np.ascontiguousarray(gyro, dtype=float).reshape(-1, 3)
    times = np.ascontiguousarray(t, dtype=float).reshape(-1)
    out = np.empty((len(times), 4))
    _propagate(np.asarray(q0, dtype=float), float(t0), np.asarray(w0, dtype=float), times, w, out)
    return out


@numba.njit(cache=True)
def _propagate(q0, t0, w0, t, w, out):  # pragma: no cover - compiled
    qw, qx, qy, qz = q0[0], q0[1], q0[2], q0[3]
    t_prev, ax, ay, az = t0, w0[0], w0[1], w0[2]
    for k in range(len(t)):
        dt = t[k] - t_prev
        bx, by, bz = w[k, 0], w[k, 1], w[k, 2]
        dw, dx, dy, dz = quat_from_rotvec(
            0.5 * (ax + bx) * dt, 0.5 * (ay + by) * dt, 0.5 * (az + bz) * dt
        )
        pw, px, py, pz = hamilton(qw, qx, qy, qz, dw, dx, dy, dz)
        qw, qx, qy, qz = normalised(pw, px, py, pz)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = qw, qx, qy, qz
        t_prev, ax, ay, az = t[k], bx, by, bz


def geomagnetic_mean(obs: Mapping[str, NDArray]) -> NDArray[np.float64] | None:
    """Mean magnetic vector of a window in the phone's geographic frame, µT.

    Each *new* magnetometer sample is rotated to the world by the fused rotation
    vector (magnetic east, north, up — the frame of a grid survey's mag_x/y/z)
    and averaged once: sample-and-hold repeats would weight slow samples more.
    None when the window has no such sample or the recording lacks the streams.
    """
    flags = dict(zip(PRESENT_ORDER, obs["present"], strict=True))
    if not (flags["mag"] and flags["rotation"]):
        return None
    fresh = obs["valid"].astype(bool) & obs["mag_fresh"].astype(bool)
    if not fresh.any():
        return None
    return to_world(obs["rotation"][fresh], obs["mag"][fresh]).mean(axis=0)
