"""Ideal inertial signals from a phone's true trajectory.

Given the phone's position p(t) and attitude q(t) (world←phone) sampled densely
(≥ 200 Hz), an error-free phone would measure, at any time t:

* specific force f = R(t)ᵀ (p̈(t) + g·ẑ) — the accelerometer reads +g upward
  when still (DESIGN §2: a phone flat screen-up at rest reads (0, 0, +9.81));
* body angular rate ω with q̇ = ½ q ⊗ (0, ω) — what the gyroscope reads.

p̈ comes from a C² cubic spline through the positions. ω comes from the
relative rotation between consecutive attitude samples, ω_{k+½} =
log(q_kᶜ ⊗ q_{k+1})/Δt (exact for a constant rate over the interval, second-order
accurate otherwise), interpolated linearly to the query times. The attitude at
query times is the spherical-linear interpolation of the samples.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation

from indoorsim import quaternion as quat_ops


def normal_gravity(latitude_deg: float) -> float:
    """WGS-84 normal gravity on the ellipsoid (Somigliana's formula), m/s²."""
    s2 = math.sin(math.radians(latitude_deg)) ** 2
    return 9.7803253359 * (1 + 0.00193185265241 * s2) / math.sqrt(1 - 0.00669437999013 * s2)


class IdealImu:
    """Error-free accelerometer and gyroscope signals along a dense true trajectory.

    Args:
        t: (K,) strictly increasing sample times, s.
        position: (K, 3) phone position in the world frame, m.
        quat: (K, 4) attitude world←phone, scalar first.
        gravity_mps2: magnitude of gravity at the site.
    """

    def __init__(
        self, t: ArrayLike, position: ArrayLike, quat: ArrayLike, gravity_mps2: float = 9.80665
    ):
        self.t = np.asarray(t, dtype=float)
        if np.any(np.diff(self.t) <= 0):
            raise ValueError("IdealImu: trajectory times must be strictly increasing")
        self.gravity_mps2 = gravity_mps2
        self._pos = CubicSpline(self.t, np.asarray(position, dtype=float), axis=0)
        self._acc = self._pos.derivative(2)
        q = np.asarray(quat, dtype=float)
        # Sign-continuous samples, so interpolation takes the short way round.
        flips = np.r_[False, np.einsum("ij,ij->i", q[1:], q[:-1]) < 0]
        self._quat = q * np.where(np.cumsum(flips) % 2 == 1, -1.0, 1.0)[:, None]
        dt = np.diff(self.t)
        self._rate_mid = quat_ops.relative_rotvec(self._quat[:-1], self._quat[1:]) / dt[:, None]
        self._t_mid = 0.5 * (self.t[:-1] + self.t[1:])

    def _clip(self, times: ArrayLike) -> NDArray[np.float64]:
        ts = np.asarray(times, dtype=float)
        if ts.size and (ts.min() < self.t[0] - 1e-9 or ts.max() > self.t[-1] + 1e-9):
            raise ValueError(
                f"query times [{ts.min():.3f}, {ts.max():.3f}] s leave the trajectory "
                f"[{self.t[0]:.3f}, {self.t[-1]:.3f}] s"
            )
        return np.clip(ts, self.t[0], self.t[-1])

    def position(self, times: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) phone position, m."""
        return self._pos(self._clip(times))

    def quaternion(self, times: ArrayLike) -> NDArray[np.float64]:
        """(N, 4) world←phone unit quaternions (w, x, y, z) at ``times``."""
        return quat_ops.slerp(self.t, self._quat, self._clip(times))

    def attitude(self, times: ArrayLike) -> Rotation:
        """World←phone rotations at ``times``."""
        return Rotation.from_quat(self.quaternion(times), scalar_first=True)

    def specific_force(self, times: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) ideal accelerometer reading in the phone frame, m/s²."""
        ts = self._clip(times)
        acc_w = self._acc(ts)
        acc_w[:, 2] += self.gravity_mps2
        return quat_ops.rotate(quat_ops.conjugate(self.quaternion(ts)), acc_w)

    def angular_rate(self, times: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) ideal gyroscope reading in the phone frame, rad/s."""
        ts = self._clip(times)
        return np.column_stack([np.interp(ts, self._t_mid, self._rate_mid[:, i]) for i in range(3)])

    def to_phone_frame(self, times: ArrayLike, vectors_world: ArrayLike) -> NDArray[np.float64]:
        """Express world-frame vectors (N, 3), one per time, in the phone frame."""
        return quat_ops.rotate(quat_ops.conjugate(self.quaternion(times)), vectors_world)

    def to_world_frame(self, times: ArrayLike, vectors_phone: ArrayLike) -> NDArray[np.float64]:
        """Express phone-frame vectors (N, 3), one per time, in the world frame."""
        return quat_ops.rotate(self.quaternion(times), vectors_phone)
