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

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation

from indoorsim.util import quaternion as quat_ops
from indoorsim.util.kernels import hamilton, normalised, rotvec_from_quat


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
        # Sign-continuous samples, so interpolation takes the short way round
        # (a carried phone's attitude usually is already: then it is just copied).
        flips = np.einsum("ij,ij->i", q[1:], q[:-1]) < 0
        if flips.any():
            q = q * np.where(np.cumsum(np.r_[False, flips]) % 2 == 1, -1.0, 1.0)[:, None]
        self._quat = np.array(q, order="C")
        # One row per axis, so each is interpolated without a strided copy.
        self._rate_mid = np.empty((3, len(self.t) - 1))
        _rates(self.t, self._quat, self._rate_mid)
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
        return self._quaternion_at(self._clip(times))

    def _quaternion_at(self, ts: NDArray[np.float64]) -> NDArray[np.float64]:
        """:meth:`quaternion` at times already checked and clipped (:meth:`_clip`)."""
        ts = np.ascontiguousarray(ts)
        out = np.empty((len(ts), 4))
        _slerp(self.t, self._quat, ts, out)
        return out

    def attitude(self, times: ArrayLike) -> Rotation:
        """World←phone rotations at ``times``."""
        return Rotation.from_quat(self.quaternion(times), scalar_first=True)

    def specific_force(self, times: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) ideal accelerometer reading in the phone frame, m/s²."""
        ts = self._clip(times)
        acc_w = self._acc(ts)
        acc_w[:, 2] += self.gravity_mps2
        # ts is clipped already: straight to the attitude, not through to_phone_frame.
        return quat_ops.rotate(self._quaternion_at(ts), acc_w, inverse=True)

    def angular_rate(self, times: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) ideal gyroscope reading in the phone frame, rad/s."""
        ts = self._clip(times)
        return np.column_stack([np.interp(ts, self._t_mid, rate) for rate in self._rate_mid])

    def to_phone_frame(self, times: ArrayLike, vectors_world: ArrayLike) -> NDArray[np.float64]:
        """Express world-frame vectors (N, 3), one per time, or one (3,), in the phone frame."""
        return quat_ops.rotate(self.quaternion(times), vectors_world, inverse=True)

    def to_world_frame(self, times: ArrayLike, vectors_phone: ArrayLike) -> NDArray[np.float64]:
        """Express phone-frame vectors (N, 3), one per time, or one (3,), in the world frame."""
        return quat_ops.rotate(self.quaternion(times), vectors_phone)


# ----------------------------------------------------------------- compiled kernels
# One pass each over a long trajectory, where the numpy forms make a dozen
# temporaries (rotations of vectors: indoorsim.util.quaternion.rotate). The
# per-quaternion arithmetic comes from indoorsim.util.kernels.


@numba.njit(cache=True, error_model="numpy")
def _rates(t, q, out):  # pragma: no cover - compiled
    """Body rates between consecutive samples: out[:, k] = log(q_k* ⊗ q_{k+1}) / Δt (short way)."""
    for k in range(q.shape[0] - 1):
        j = k + 1
        w, x, y, z = hamilton(
            q[k, 0], -q[k, 1], -q[k, 2], -q[k, 3], q[j, 0], q[j, 1], q[j, 2], q[j, 3]
        )
        x, y, z = rotvec_from_quat(w, x, y, z)
        dt = t[j] - t[k]
        out[0, k] = x / dt
        out[1, k] = y / dt
        out[2, k] = z / dt


# Samples the interval search walks before it bisects.
_WALK_STEPS = 8


@numba.njit(cache=True, inline="always", error_model="numpy")
def _interval(tk, x, i):  # pragma: no cover - compiled
    """The interval k of ``tk`` with tk[k] ≤ x < tk[k + 1], clamped to [0, len(tk) − 2].

    Searched from the hint ``i``: a sensor clock's sorted times move a sample
    or two on from the last one, so a short walk finds it without bisecting
    the whole trajectory; anything else (earlier, farther, NaN) is bisected.
    """
    last = tk.shape[0] - 2
    for _ in range(_WALK_STEPS):
        if not tk[i] <= x:
            break
        if i == last or x < tk[i + 1]:
            return i
        i += 1
    return min(max(np.searchsorted(tk, x, side="right") - 1, 0), last)


@numba.njit(cache=True, error_model="numpy")
def _slerp(tk, qk, t, out):  # pragma: no cover - compiled
    """Spherical-linear interpolation of sign-continuous samples qk at times t (clipped inside).

    Not :func:`indoorsim.util.quaternion.slerp`, although the formula is the
    same: this one takes ``math.acos`` and ``math.sin`` per sample and sums the
    knots' dot product left to right, that one numpy's transcendentals over
    whole arrays and the dot product as numpy's einsum sums it, so the two
    agree to ~1e-15, not bit for bit (tested). Recordings are made with this
    one, so it stays; the interval search from a hint is its own as well.
    """
    i = 0
    for m in range(t.shape[0]):
        i = _interval(tk, t[m], i)
        f = (t[m] - tk[i]) / (tk[i + 1] - tk[i])
        a0, a1, a2, a3 = qk[i, 0], qk[i, 1], qk[i, 2], qk[i, 3]
        b0, b1, b2, b3 = qk[i + 1, 0], qk[i + 1, 1], qk[i + 1, 2], qk[i + 1, 3]
        c = a0 * b0 + a1 * b1 + a2 * b2 + a3 * b3
        if c < 0.0:
            b0, b1, b2, b3, c = -b0, -b1, -b2, -b3, -c
        c = min(c, 1.0)
        theta = math.acos(c)
        sin = math.sin(theta)
        if sin < 1e-9:
            wa, wb = 1.0 - f, f
        else:
            wa, wb = math.sin((1.0 - f) * theta) / sin, math.sin(f * theta) / sin
        out[m, 0], out[m, 1], out[m, 2], out[m, 3] = normalised(
            wa * a0 + wb * b0, wa * a1 + wb * b1, wa * a2 + wb * b2, wa * a3 + wb * b3
        )
