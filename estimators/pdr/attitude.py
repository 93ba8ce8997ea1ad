"""Quaternion attitude and heading of the gait-based DR (Chen2022 Eq. 8–12).

:class:`QuaternionAttitude` propagates a world←phone quaternion by the gyro
increments (Eq. 8), with the gyro bias learned while the phone is still (our
reduction of the paper's attitude-bias states) and a slow tilt alignment to
gravity, and follows the heading through the direction cosine matrix
(Eq. 9, :func:`dcm`) and its Euler angles (Eq. 10–12, :func:`euler_angles`).
:class:`~indoorsim.estimators.pdr.gait.GaitDeadReckoning` takes each step's
heading from it.

Readings taken where the text is wrong or silent (PAPER_NOTES, Chen2022 item 1–2):

* **Eq. 8** has sign ambiguities in ΔΘ and calls I a 3 × 3 identity (it is
  4 × 4). Implemented as the standard kinematics it stands for, q ← q ⊗
  exp(½Δθ) with the body-frame increment Δθ = (ω̄ − b_g)·Δt (ω̄ the mean of
  two consecutive gyro samples, b_g the gyro bias learned while still); its
  matrix form is the paper's [I cos(Δθ/2) + ΔΘ sin(Δθ/2)/Δθ] q.
* **Eq. 10–12** use arctan; here atan2, so every quadrant is kept.
* **Heading in every carrying mode.** Eq. 12's yaw is the heading of the
  phone's x axis. The walking heading is the start heading plus the change
  of that yaw since the start; a phone whose x axis stands near vertical (a
  phone at the ear in landscape, say) would make it ill-defined, so the axis
  whose heading is followed is the phone axis most nearly horizontal,
  switched (with the heading kept continuous) when it comes within 30° of
  the vertical. Being a function of the attitude and not an integral of a
  yaw rate, this heading does not creep when the phone's tilt circulates (a
  pocket's thigh swing), which ∫ω·ĝ dt does
  (:class:`~indoorsim.estimators.pdr.heading.GyroHeading`).

Frames: phone frame as Android's sensor frame; the attitude quaternion is
world←phone, scalar first (w, x, y, z) as :mod:`indoorsim.util.quaternion`, with a
local world frame whose z is up and whose yaw origin is arbitrary — only
changes of yaw are used. The quaternion arithmetic comes from
:mod:`indoorsim.util.kernels`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.pdr._checks import non_negative, positive
from indoorsim.util.kernels import (
    hamilton,
    normalised,
    quat_from_rotvec,
    rotation_matrix_homogeneous,
)

__all__ = ["QuaternionAttitude", "dcm", "euler_angles"]

# The heading follows another phone axis once its axis comes within this of
# the vertical (horizontal projection below sin 30° = 0.5).
_MIN_HORIZONTAL = 0.5
# Still gyro samples held back for the bias guard; beyond this many (a guard
# longer than 4096 samples) the oldest is used early.
_BIAS_FIFO = 4096
# What the compiled loop carries from one call to the next besides the
# quaternion, the bias and the FIFO of still samples: one record of these fields.
_STATE = np.dtype(
    [
        ("t_prev", np.float64),  # time of the previous sample, s; NaN before the first
        ("w_prev", np.float64, (3,)),  # its angular rate, rad/s
        ("axis", np.int64),  # the phone axis whose heading is followed
        ("yaw_prev", np.float64),  # that axis's yaw at the previous sample, rad
        ("rel_yaw", np.float64),  # the accumulated change of yaw, rad
        ("n_bias", np.int64),  # still samples the bias has taken in
        ("fifo_head", np.int64),  # ring-buffer index of the oldest waiting still sample
        ("fifo_len", np.int64),  # still samples waiting
    ]
)


# ------------------------------------------------------------------ closed forms


def dcm(q: ArrayLike) -> NDArray[np.float64]:
    """Direction cosine matrices C_b^n (world←phone) of unit quaternions (Chen2022 Eq. 9).

    The paper's q = [q1 q2 q3 q4] has the scalar last; here (w, x, y, z)
    scalar first, so its q4 is w and q1..q3 are x, y, z. Eq. 9 is the
    homogeneous form, :func:`~indoorsim.util.kernels.rotation_matrix_homogeneous`.

    Args:
        q: (..., 4) unit quaternions, scalar first.

    Returns:
        (..., 3, 3) rotation matrices; column j is phone axis j in the world.

    >>> dcm([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]).round(6)[:2, :2].tolist()
    [[0.0, -1.0], [1.0, 0.0]]
    """
    q = np.asarray(q, dtype=float)
    if q.shape[-1:] != (4,):
        raise ValueError(f"dcm: expected quaternions (..., 4), got {q.shape}")
    rows = np.ascontiguousarray(q).reshape(-1, 4)
    out = np.empty((len(rows), 3, 3))
    _dcm_rows(rows, out)
    return out.reshape(*q.shape[:-1], 3, 3)


@numba.njit(cache=True)
def _dcm_rows(q, out):  # pragma: no cover - compiled
    """out[k] = Eq. 9 of q[k]."""
    for k in range(q.shape[0]):
        rotation_matrix_homogeneous(q[k], out[k])


def euler_angles(
    C: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Pitch ϑ, roll φ and yaw ψ of direction cosine matrices (Chen2022 Eq. 10–12), rad.

    The z-y-x Euler angles of C = R_z(ψ) R_y(ϑ) R_x(φ), with atan2 for the
    paper's arctan. Yaw is the heading of the phone's x axis, undefined when
    that axis is vertical (|ϑ| = 90°).

    Args:
        C: (..., 3, 3) world←phone rotation matrices.

    Returns:
        (pitch, roll, yaw), each (...).
    """
    C = np.asarray(C, dtype=float)
    # Eq. 10: ϑ = arctan(−C31 / √(C32² + C33²))
    pitch = np.arctan2(-C[..., 2, 0], np.hypot(C[..., 2, 1], C[..., 2, 2]))
    # Eq. 11: φ = arctan(C32 / C33)
    roll = np.arctan2(C[..., 2, 1], C[..., 2, 2])
    # Eq. 12: ψ = arctan(C21 / C11)
    yaw = np.arctan2(C[..., 1, 0], C[..., 0, 0])
    return pitch, roll, yaw


# ------------------------------------------------------------------ the compiled loop
# Per sample, nothing is allocated: the quaternion arithmetic is on components.


@numba.njit(cache=True)
def _attitude_run(
    t,
    gyro,
    up,
    still,
    q,
    bias,
    state,
    fifo_t,
    fifo_w,
    tilt_gain_rate,
    bias_rate,
    guard_s,
    out_q,
    out_yaw,
):  # pragma: no cover - compiled
    """Propagate the attitude through the samples; fill quaternions and relative yaws.

    q (4,) and the gyro bias (3,) are updated in place, as is ``state`` (a
    one-record array of :data:`_STATE`) and the ring buffer of still samples
    waiting for ``guard_s`` of stillness after them: their times ``fifo_t``
    and rows [ω (3), Δt] ``fifo_w``, ``fifo_len`` of them from ``fifo_head``.
    Per sample k, once the first has set the clock:

    1. Eq. 8, q ← q ⊗ exp(½Δθ), Δθ = (½(ω_{k−1} + ω_k) − b)Δt; then, if
       ``tilt_gain_rate`` > 0, the tilt alignment (:class:`QuaternionAttitude`);
       then q ← q/‖q‖.
    2. The bias FIFO, if ``bias_rate`` > 0: a moving sample empties it (the
       still samples just before motion may be its start); a still one is
       queued, and queued samples followed by ``guard_s`` of stillness (or
       pushed out of a full queue) update the bias (:func:`_bias_step`).
    3. Eq. 12 for the followed axis j, ψ = atan2(C[1, j], C[0, j]) with C
       the DCM (Eq. 9): the relative yaw grows by the change of ψ, wrapped;
       when the axis comes within 30° of the vertical (or at the first
       sample) the most horizontal axis is followed from then on.
    """
    s = state[0]
    cap = fifo_t.size
    C = np.empty((3, 3))
    for k in range(t.size):
        started = np.isfinite(s.t_prev)
        dt = t[k] - s.t_prev if started else 0.0
        if started:
            # Eq. 8: q ← q ⊗ exp(½Δθ), Δθ = ω̄Δt with the bias-corrected mean rate
            d0, d1, d2, d3 = quat_from_rotvec(
                (0.5 * (s.w_prev[0] + gyro[k, 0]) - bias[0]) * dt,
                (0.5 * (s.w_prev[1] + gyro[k, 1]) - bias[1]) * dt,
                (0.5 * (s.w_prev[2] + gyro[k, 2]) - bias[2]) * dt,
            )
            q[0], q[1], q[2], q[3] = hamilton(q[0], q[1], q[2], q[3], d0, d1, d2, d3)
            if tilt_gain_rate > 0.0:
                # Measured up in the world; turning it toward +z about the
                # horizontal axis u × ẑ corrects roll and pitch, not yaw.
                rotation_matrix_homogeneous(q, C)
                u0, u1, u2 = 0.0, 0.0, 0.0
                for j in range(3):
                    u0 += C[0, j] * up[k, j]
                    u1 += C[1, j] * up[k, j]
                    u2 += C[2, j] * up[k, j]
                norm = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
                if norm > 0.0:
                    ex, ey = u1 / norm, -u0 / norm
                    angle = math.atan2(math.sqrt(ex * ex + ey * ey), u2 / norm)
                    gain = min(1.0, tilt_gain_rate * dt)
                    sin_e = math.sqrt(ex * ex + ey * ey)
                    if sin_e > 0.0:
                        scale = gain * angle / sin_e
                        r0, r1, r2, r3 = quat_from_rotvec(ex * scale, ey * scale, 0.0)
                        q[0], q[1], q[2], q[3] = hamilton(r0, r1, r2, r3, q[0], q[1], q[2], q[3])
            q[0], q[1], q[2], q[3] = normalised(q[0], q[1], q[2], q[3])
        if bias_rate > 0.0:
            if not still[k]:
                s.fifo_len = 0  # the still samples just before motion may be its start
            else:
                if s.fifo_len == cap:  # full: use the oldest now
                    _use_oldest(bias, s, fifo_w, bias_rate)
                j = (s.fifo_head + s.fifo_len) % cap
                fifo_t[j] = t[k]
                for i in range(3):
                    fifo_w[j, i] = gyro[k, i]
                fifo_w[j, 3] = dt
                s.fifo_len += 1
            while s.fifo_len > 0 and fifo_t[s.fifo_head] <= t[k] - guard_s:
                _use_oldest(bias, s, fifo_w, bias_rate)
        rotation_matrix_homogeneous(q, C)
        axis = s.axis
        if not started or math.hypot(C[0, axis], C[1, axis]) < _MIN_HORIZONTAL:
            if started:
                # Last increment on the old axis, then follow the most horizontal one.
                yaw = math.atan2(C[1, axis], C[0, axis])
                s.rel_yaw += (yaw - s.yaw_prev + math.pi) % (2.0 * math.pi) - math.pi
            best, best_h = 0, -1.0
            for j in range(3):
                h = math.hypot(C[0, j], C[1, j])
                if h > best_h:
                    best, best_h = j, h
            s.axis = best
            s.yaw_prev = math.atan2(C[1, best], C[0, best])
        else:
            # Eq. 12 for the followed axis: ψ = atan2(C[1, j], C[0, j])
            yaw = math.atan2(C[1, axis], C[0, axis])
            s.rel_yaw += (yaw - s.yaw_prev + math.pi) % (2.0 * math.pi) - math.pi
            s.yaw_prev = yaw
        s.t_prev = t[k]
        for i in range(3):
            s.w_prev[i] = gyro[k, i]
        for i in range(4):
            out_q[k, i] = q[i]
        out_yaw[k] = s.rel_yaw


@numba.njit(cache=True)
def _use_oldest(bias, s, fifo_w, bias_rate):  # pragma: no cover - compiled
    """Take the oldest waiting still sample out of the FIFO into the bias (:func:`_bias_step`)."""
    _bias_step(bias, s, fifo_w[s.fifo_head], bias_rate)
    s.fifo_head = (s.fifo_head + 1) % fifo_w.shape[0]
    s.fifo_len -= 1


@numba.njit(cache=True)
def _bias_step(bias, s, sample, bias_rate):  # pragma: no cover - compiled
    """Zero angular-rate update: a still phone's gyro reads its bias.

    A fading-memory mean: the plain mean of the first samples, then an
    exponential one with weight Δt/τ (``sample`` = [ω (3), Δt]).
    """
    s.n_bias += 1
    gain = max(1.0 / s.n_bias, bias_rate * sample[3])
    for i in range(3):
        bias[i] += (sample[i] - bias[i]) * gain


def _level_quaternion(up: NDArray[np.float64]) -> NDArray[np.float64]:
    """Attitude with roll and pitch from the phone-frame up vector, yaw 0 (Eq. 10–11 inverted).

    With C = R_y(ϑ) R_x(φ), the third row of C is ûᵀ, so ϑ = atan2(−u_x, √(u_y² + u_z²)),
    φ = atan2(u_y, u_z), and q = q_y(ϑ) ⊗ q_x(φ).
    """
    u = up / np.linalg.norm(up)
    pitch = math.atan2(-u[0], math.hypot(u[1], u[2]))
    roll = math.atan2(u[1], u[2])
    q_pitch = (math.cos(pitch / 2), 0.0, math.sin(pitch / 2), 0.0)
    q_roll = (math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0)
    return np.array(hamilton(*q_pitch, *q_roll))


@dataclass(kw_only=True)
class QuaternionAttitude:
    """Streaming gyro attitude and relative heading (Chen2022 Eq. 8–12).

    At the first sample, roll and pitch come from gravity (Eq. 10–11
    inverted), yaw is 0 in a local world frame. Each later sample
    propagates the quaternion by the gyro increment (Eq. 8, standard
    kinematics), then optionally:

    * **tilt alignment** (complementary): the attitude is turned by a
      fraction Δt/``tilt_time_constant_s`` of the angle between its "up" and
      the measured one, about a horizontal world axis — so roll and pitch do
      not drift with the gyro bias, while yaw is left to the gyro. The slow
      constant passes the fast swing of a dangling or pocketed phone to the
      gyro and only pulls the mean tilt.
    * **gyro bias** (zero angular-rate update; our reduction of the paper's
      attitude-bias states ε_roll, ε_pitch, ε_yaw): while the phone is still,
      the bias is the fading-memory mean of the gyro over the last
      ``gyro_bias_time_constant_s``, and it is subtracted from every rate.
      Walks start standing, so a phone's turn-on bias (0.3°/s for the
      Nexus 5X profile: 20° over a minute) is gone by the first step. A
      still sample counts only once ``gyro_bias_guard_s`` of stillness
      has followed it: gait initiation turns the trunk gently for half a
      second or more before the detector sees motion, and that turn must not
      become bias.

    The relative yaw is the accumulated change of Eq. 12's yaw of the
    followed phone axis (module docstring): exactly the rotation about the
    vertical for a phone turning at any fixed tilt.

    Attributes:
        tilt_time_constant_s: time constant of the tilt alignment, s; None turns it off.
        gyro_bias_time_constant_s: memory of the still-phone gyro-bias mean,
            s; None turns bias estimation off.
        gyro_bias_guard_s: stillness needed after a sample before it counts
            toward the bias, s.
    """

    tilt_time_constant_s: float | None = 10.0
    gyro_bias_time_constant_s: float | None = 10.0
    gyro_bias_guard_s: float = 1.0

    q: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    bias: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    _state: NDArray[np.void] = field(init=False, repr=False, compare=False)  # (1,) of _STATE
    _fifo_t: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    _fifo_w: NDArray[np.float64] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.tilt_time_constant_s is not None:
            positive("tilt_time_constant_s", self.tilt_time_constant_s)
        if self.gyro_bias_time_constant_s is not None:
            positive("gyro_bias_time_constant_s", self.gyro_bias_time_constant_s)
        non_negative("gyro_bias_guard_s", self.gyro_bias_guard_s)
        self.reset()

    def reset(self) -> None:
        """Forget the attitude: the next sample levels it again from gravity."""
        self.q = np.array([1.0, 0.0, 0.0, 0.0])
        self.bias = np.zeros(3)
        self._state = np.zeros(1, dtype=_STATE)
        self._state["t_prev"] = np.nan
        self._fifo_t = np.zeros(_BIAS_FIFO)
        self._fifo_w = np.zeros((_BIAS_FIFO, 4))

    @property
    def started(self) -> bool:
        """Whether a sample has set the attitude since the last reset."""
        return bool(np.isfinite(self._state["t_prev"][0]))

    def update(
        self,
        t: ArrayLike,
        gyro: ArrayLike,
        up: ArrayLike,
        stationary: ArrayLike | None = None,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Propagate through the next samples.

        Args:
            t: (N,) sample times, s, increasing and after those of earlier calls.
            gyro: (N, 3) angular rate, phone frame, rad/s.
            up: (N, 3) gravity, up-pointing, phone frame (only its direction is
                used): the first levels the attitude, all align the tilt.
            stationary: (N,) True where the phone is still (gyro-bias
                estimation); None for never.

        Returns:
            (N, 4) world←phone quaternions and (N,) relative yaws, rad.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        gyro = np.asarray(gyro, dtype=float).reshape(-1, 3)
        up = np.asarray(up, dtype=float).reshape(-1, 3)
        still = (
            np.zeros(len(t), dtype=bool)
            if stationary is None
            else np.asarray(stationary, dtype=bool).reshape(-1)
        )
        if not (len(t) == len(gyro) == len(up) == len(still)):
            raise ValueError(f"{len(t)} times, {len(gyro)} gyro, {len(up)} up, {len(still)} flags")
        out_q = np.empty((len(t), 4))
        out_yaw = np.empty(len(t))
        if not len(t):
            return out_q, out_yaw
        if not self.started:
            if not np.linalg.norm(up[0]) > 0:
                raise ValueError("the first up vector is zero: no gravity to level the attitude")
            self.q = _level_quaternion(up[0])
        tilt_rate = 0.0 if self.tilt_time_constant_s is None else 1.0 / self.tilt_time_constant_s
        tau = self.gyro_bias_time_constant_s
        bias_rate = 0.0 if tau is None else 1.0 / tau
        _attitude_run(
            t,
            gyro,
            up,
            still,
            self.q,
            self.bias,
            self._state,
            self._fifo_t,
            self._fifo_w,
            tilt_rate,
            bias_rate,
            self.gyro_bias_guard_s,
            out_q,
            out_yaw,
        )
        return out_q, out_yaw
