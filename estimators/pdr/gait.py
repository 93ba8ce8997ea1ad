"""Gait-based dead reckoning (Chen2022 "The gait-based DR", Eq. 1–12).

Chen2022 builds its DR from four parts, each a component here:

* **Stationary detection and an EKF on the vertical channel** (Eq. 1–3, ZUPT):
  :class:`StationaryDetector` and :class:`VerticalZuptEKF`. The paper's
  9-state error filter (vertical position and velocity, three attitude angles
  and four biases) is only cited (its F, Q, H, R are "in Chen et al. 2018b").
  This module implements a documented *reduction*: a 3-state Kalman filter on
  the vertical channel (position, velocity, accelerometer bias) and, for the
  attitude, the gyro biases re-estimated whenever the phone is still (a zero
  angular-rate update) in :class:`QuaternionAttitude`.
* **Step length** by the inverted pendulum: vertical acceleration on gravity
  (Eq. 4, :func:`vertical_acceleration`), the vertical excursion S_VD between
  two adjacent troughs by double integration (Eq. 5, through the EKF), and
  D = 2√(L² − (L − S_VD)²) (Eq. 6, :func:`pendulum_step_length`).
* **Step counting**: one step between two adjacent troughs of the vertical
  acceleration (Eq. 7; garbled in the text, reading below).
* **Heading** from the quaternion attitude: update by gyro increments (Eq. 8),
  direction cosine matrix (Eq. 9, :func:`dcm`), Euler angles (Eq. 10–12,
  :func:`euler_angles`).

:class:`GaitDeadReckoning` runs them together on streamed samples and returns
:class:`GaitStep` records.

Readings taken where the text is wrong or silent (PAPER_NOTES, Chen2022 item 1–2):

* **Eq. 4 sign.** The paper's g(t) is gravity pointing down, so
  a_z = −(a − g)·g/|g| is the upward specific force less g. Android's gravity
  sensor reads gravity as the accelerometer does at rest, pointing *up*, so
  with that g the same quantity is a_v = (a − g)·ĝ = a·ĝ − |g|, up positive.
* **Eq. 5.** The double integral of a_z from one trough to the next is the
  height change over a step — zero on a level floor, since the phone returns
  to the same height every step. What the pendulum of Eq. 6 needs is the
  height of the arc: S_VD is read as the vertical excursion (maximum minus
  minimum) of the doubly integrated a_v between the two troughs. The
  integration is the EKF's, whose level pseudo-measurement keeps drift out
  of it. (Removing the chord between the step's two end heights as well
  made it worse in simulated walks: a pocketed phone's height repeats every
  stride, not every step, and the step's ends lie on the steep parts of
  the bounce, where one sample of timing moves them by millimetres.)
* **Eq. 6.** L is "the distance between the smartphone and the ground while
  the walker is static". For a phone held at chest height that is ≈ 1.2 m
  (0.70 of a 1.70 m body); it agrees with the pendulum read backwards from
  gait data — a CoM excursion of 4–5 cm at 0.67 m steps gives
  L = D²/(8·S_VD) ≈ 1.1–1.4 m (REALISM §5) — which is why the paper's phone
  height fits better than the leg length (≈ 0.9 m) of the compass-gait
  model, which Zijlstra & Hof (2003) correct by an empirical factor of
  ≈ 1.25 on D (REALISM §5). Where the phone
  does not follow the trunk (a dangling hand, a thigh pocket) L is only a
  scale: :meth:`GaitDeadReckoning.calibrate` fits a length scale on training
  walks.
* **Eq. 7** survives only as its symbols (t^trough, t_1, t_2, a^thd). Read:
  a trough is a local minimum t^trough of the low-passed vertical
  acceleration with a_v(t^trough) < −a^thd, not while the phone is still;
  of two troughs closer than the shortest step time the deeper is kept; two
  adjacent kept troughs t_1 < t_2 make one step if t_2 − t_1 is at most the
  longest step time and the phone was not still in between. The first
  trough of a walking bout (after stillness, or after a gap longer than the
  longest step time) has no t_1: it too ends a step — the one that brought
  the walker to it — taken from where the phone left stillness, at most
  the longest step time before. Otherwise every bout would lose a step
  (the first and last steps of a bout, a third of a full step long, have
  almost no bounce and are missed anyway: 2–4 % of a simulated walk).
* **Eq. 2**, the EKF's state equation δX_k = F_{k−1} δX_{k−1} + ω_{k−1}, is
  lost in the extraction; Eq. 3 is the measurement equation. Both are used
  with the matrices of :class:`VerticalZuptEKF`.
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
changes of yaw are used.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import butter, sosfilt, sosfilt_zi

__all__ = [
    "PENDULUM_LENGTH_M",
    "GaitDeadReckoning",
    "GaitStep",
    "QuaternionAttitude",
    "StationaryDetector",
    "VerticalZuptEKF",
    "dcm",
    "euler_angles",
    "pendulum_step_length",
    "vertical_acceleration",
]

PENDULUM_LENGTH_M = 1.2
"""Default pendulum length L of Eq. 6: a phone held at chest height by a 1.70 m
adult (0.70 × 1.70 m), the paper's "phone height when static"; also the L that a
4–5 cm CoM excursion at 0.67 m steps implies (module docstring)."""

# Below this norm (m/s²) a gravity row carries no direction: a fused stream
# that has not started yet, or a missing one, is all zeros.
_MIN_GRAVITY = 1.0
# Samples used to estimate the sampling rate when none is given: a fixed
# count, so that the estimate does not depend on how the samples are chunked.
_RATE_SAMPLES = 16
# The heading follows another phone axis once its axis comes within this of
# the vertical (horizontal projection below sin 30° = 0.5).
_MIN_HORIZONTAL = 0.5
# Still gyro samples held back for the bias guard; beyond this many (a guard
# longer than 4096 samples) the oldest is used early.
_BIAS_FIFO = 4096


def _positive(name: str, value: float) -> None:
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")


def _non_negative(name: str, value: float) -> None:
    if not (np.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a finite number ≥ 0, got {value!r}")


# ------------------------------------------------------------------ closed forms


def vertical_acceleration(accel: ArrayLike, gravity: ArrayLike) -> NDArray[np.float64]:
    """Vertical acceleration a_v = (a − g)·ĝ = a·ĝ − |g| (Chen2022 Eq. 4, sign as read), m/s².

    Args:
        accel: (N, 3) specific force, phone frame, m/s².
        gravity: (N, 3) gravity as Android reports it (pointing up: the
            accelerometer's reading at rest), or a low-passed accelerometer.

    Returns:
        (N,) upward acceleration; 0 for a phone at rest reading exactly ``gravity``.

    >>> vertical_acceleration([[0.0, 3.0, 10.0]], [[0.0, 0.0, 9.8]]).round(6).tolist()
    [0.2]
    """
    a = np.asarray(accel, dtype=float).reshape(-1, 3)
    g = np.asarray(gravity, dtype=float).reshape(-1, 3)
    norm = np.linalg.norm(g, axis=1)
    # Eq. 4: a_v = (a − g)·g/|g|
    return np.einsum("ij,ij->i", a - g, g) / norm


def pendulum_step_length(s_vd: ArrayLike, pendulum_length: float) -> NDArray[np.float64]:
    """Inverted-pendulum step length D = 2√(L² − (L − S_VD)²) (Chen2022 Eq. 6), m.

    S_VD is clipped to [0, L]: a negative excursion is no step, and beyond L the
    pendulum would pass the horizontal (D = 2L at most).

    Args:
        s_vd: vertical excursion of the step, m.
        pendulum_length: L, m.

    >>> round(float(pendulum_step_length(0.05, 1.25)), 12)
    0.7
    """
    _positive("pendulum_length", pendulum_length)
    s = np.clip(np.asarray(s_vd, dtype=float), 0.0, pendulum_length)
    L = pendulum_length
    # Eq. 6: D = 2√(L² − (L − S_VD)²)
    return 2.0 * np.sqrt(L * L - (L - s) ** 2)


def dcm(q: ArrayLike) -> NDArray[np.float64]:
    """Direction cosine matrices C_b^n (world←phone) of unit quaternions (Chen2022 Eq. 9).

    The paper's q = [q1 q2 q3 q4] has the scalar last; here (w, x, y, z)
    scalar first, so its q4 is w and q1..q3 are x, y, z.

    Args:
        q: (..., 4) unit quaternions, scalar first.

    Returns:
        (..., 3, 3) rotation matrices; column j is phone axis j in the world.

    >>> dcm([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]).round(6)[:2, :2].tolist()
    [[0.0, -1.0], [1.0, 0.0]]
    """
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=float), -1, 0)
    # Eq. 9, with q1, q2, q3, q4 = x, y, z, w
    rows = [
        [w * w + x * x - y * y - z * z, 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), w * w - x * x + y * y - z * z, 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), w * w - x * x - y * y + z * z],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


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


# ------------------------------------------------------------------ stationary detection


@numba.njit(cache=True)
def _window_stats(
    t, acc_norm, gyro_norm, first, window_s, t_start, acc_std, gyro_rms
):  # pragma: no cover - compiled
    """Std of |a| and RMS of |ω| over the samples in (t_k − window_s, t_k], for k ≥ first.

    Windows not yet covering ``window_s`` of data since ``t_start`` get inf.
    """
    j0 = 0
    for k in range(first, t.size):
        while t[k] - t[j0] >= window_s:
            j0 += 1
        n = k - j0 + 1
        if n < 3 or t[k] - t_start < window_s * (1.0 - 1e-9) - 1e-12:
            acc_std[k - first] = np.inf
            gyro_rms[k - first] = np.inf
            continue
        mean = 0.0
        for j in range(j0, k + 1):
            mean += acc_norm[j]
        mean /= n
        var = 0.0
        energy = 0.0
        for j in range(j0, k + 1):
            d = acc_norm[j] - mean
            var += d * d
            energy += gyro_norm[j] * gyro_norm[j]
        acc_std[k - first] = math.sqrt(var / n)
        gyro_rms[k - first] = math.sqrt(energy / n)


@dataclass(kw_only=True)
class StationaryDetector:
    """Streaming still-phone detector: quiet accelerometer magnitude and gyro over a window.

    Sample k is stationary when, over the trailing window (t_k − ``window_s``, t_k],

        std(|a|) < ``accel_std_mps2``   and   RMS(|ω|) < ``gyro_rms_rad_s``,

    the acceleration-moving-variance and angular-rate-energy detectors of
    Skog et al., "Zero-velocity detection — an algorithm evaluation", IEEE
    TBME 57(11), 2010, combined by "and". Without a gyro only the first
    test is made. The window trails, so a walk is "moving" from its first
    jolt and "still" again only a full window after its last: the ZUPT never
    lands on a moving phone. Samples before the first full window are not
    stationary.

    Defaults, for a phone in the hand or a pocket rather than on a foot: the
    window is about one step (0.5 s), so a walking window always holds a
    step's swing; the thresholds sit between a hand holding still — tremor of
    ≈ 0.06 m/s² RMS and 0.03° at 8–12 Hz (≈ 0.03 rad/s), Android CDD noise
    floors far below — and walking, whose |a| swings 2–4 m/s² peak to peak
    (std ≳ 0.7 m/s²) and whose trunk yaw oscillation alone turns a handheld
    phone at ≳ 0.1 rad/s (REALISM §5–6).

    Attributes:
        window_s: length of the trailing window, s.
        accel_std_mps2: threshold on the standard deviation of |a|, m/s².
        gyro_rms_rad_s: threshold on the RMS of |ω|, rad/s.
    """

    window_s: float = 0.5
    accel_std_mps2: float = 0.2
    gyro_rms_rad_s: float = 0.1

    # Samples within the window of the last one (t, |a|, |ω|), and the first time.
    _tail: NDArray[np.float64] = field(
        default_factory=lambda: np.empty((0, 3)), init=False, repr=False, compare=False
    )
    _t_start: float | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        _positive("window_s", self.window_s)
        _positive("accel_std_mps2", self.accel_std_mps2)
        _positive("gyro_rms_rad_s", self.gyro_rms_rad_s)

    def reset(self) -> None:
        """Forget the window: the next sample starts a new recording."""
        self._tail = np.empty((0, 3))
        self._t_start = None

    def update(self, t: ArrayLike, accel: ArrayLike, gyro: ArrayLike | None) -> NDArray[np.bool_]:
        """Classify the next samples.

        Args:
            t: (N,) sample times, s, increasing and after those of earlier calls.
            accel: (N, 3) specific force, m/s².
            gyro: (N, 3) angular rate, rad/s, or None (accelerometer test only).

        Returns:
            (N,) True where the phone is still.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        acc_norm = np.linalg.norm(np.asarray(accel, dtype=float).reshape(-1, 3), axis=1)
        gyro_norm = (
            np.zeros_like(t)
            if gyro is None
            else np.linalg.norm(np.asarray(gyro, dtype=float).reshape(-1, 3), axis=1)
        )
        if not len(t):
            return np.zeros(0, dtype=bool)
        if self._t_start is None:
            self._t_start = float(t[0])
        buf = np.concatenate([self._tail, np.column_stack([t, acc_norm, gyro_norm])])
        first = len(self._tail)
        acc_std = np.empty(len(t))
        gyro_rms = np.empty(len(t))
        _window_stats(
            buf[:, 0], buf[:, 1], buf[:, 2], first, self.window_s, self._t_start, acc_std, gyro_rms
        )
        self._tail = buf[buf[:, 0] > t[-1] - self.window_s]
        return (acc_std < self.accel_std_mps2) & (gyro_rms < self.gyro_rms_rad_s)


# ------------------------------------------------------------------ vertical EKF
# The recursions cannot be vectorised over time; compiled, a sample costs well
# under a microsecond. Matrix products are written out as loops: numba's
# BLAS-backed @ takes seconds to compile for 3 × 3 matrices.


@numba.njit(cache=True)
def _scalar_update(x, P, h, z, r):  # pragma: no cover - compiled
    """Kalman update with one scalar measurement z = h·x + v, v ~ N(0, r), Joseph form."""
    n = x.size
    ph = np.zeros(n)
    for i in range(n):
        for j in range(n):
            ph[i] += P[i, j] * h[j]
    s = r
    innovation = z
    for i in range(n):
        s += h[i] * ph[i]
        innovation -= h[i] * x[i]
    # Eq. 3 update: K = P⁻hᵀ/S, x = x⁻ + K(z − h x⁻), P = (I − K h) P⁻ (I − K h)ᵀ + K r Kᵀ
    K = ph / s
    for i in range(n):
        x[i] += K[i] * innovation
    A = np.eye(n)
    for i in range(n):
        for j in range(n):
            A[i, j] -= K[i] * h[j]
    AP = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            for m in range(n):
                AP[i, j] += A[i, m] * P[m, j]
    for i in range(n):
        for j in range(n):
            acc = K[i] * r * K[j]
            for m in range(n):
                acc += AP[i, m] * A[j, m]
            P[i, j] = acc
    for i in range(n):
        for j in range(i + 1, n):
            P[i, j] = P[j, i] = 0.5 * (P[i, j] + P[j, i])


@numba.njit(cache=True)
def _ekf_run(t, a, still, last, x, P, q_a, q_b, r_zupt, r_level, out):  # pragma: no cover
    """Predict with each sample's vertical acceleration, then the ZUPT and level updates.

    ``last`` = [t, a] of the previous sample (NaN time before the first) is
    updated in place, as are x and P; out[k] receives the posterior state.
    """
    h_pos = np.array([1.0, 0.0, 0.0])
    h_vel = np.array([0.0, 1.0, 0.0])
    for k in range(t.size):
        dt = t[k] - last[0] if np.isfinite(last[0]) else 0.0
        if dt > 0.0:
            acc = 0.5 * (last[1] + a[k]) - x[2]
            dt2 = dt * dt
            # Eq. 2 (prediction): x⁻ = F x + B ā with the bias-corrected mean acceleration
            x[0] += x[1] * dt + 0.5 * acc * dt2
            x[1] += acc * dt
            F = np.array([[1.0, dt, -0.5 * dt2], [0.0, 1.0, -dt], [0.0, 0.0, 1.0]])
            FP = np.zeros((3, 3))
            for i in range(3):
                for j in range(3):
                    for m in range(3):
                        FP[i, j] += F[i, m] * P[m, j]
            # P⁻ = F P Fᵀ + Q
            for i in range(3):
                for j in range(3):
                    acc_ij = 0.0
                    for m in range(3):
                        acc_ij += FP[i, m] * F[j, m]
                    P[i, j] = acc_ij
            P[0, 0] += q_a * dt2 * dt / 3.0
            P[0, 1] += q_a * dt2 / 2.0
            P[1, 0] += q_a * dt2 / 2.0
            P[1, 1] += q_a * dt
            P[2, 2] += q_b * dt
        if still[k]:
            _scalar_update(x, P, h_vel, 0.0, r_zupt)
        if dt > 0.0 and r_level > 0.0:
            _scalar_update(x, P, h_pos, 0.0, r_level / dt)
        last[0] = t[k]
        last[1] = a[k]
        for i in range(3):
            out[k, i] = x[i]


@dataclass(kw_only=True)
class VerticalZuptEKF:
    """Kalman filter of the vertical channel with zero-velocity and level pseudo-measurements.

    Our documented reduction of Chen2022's 9-state EKF (Eq. 1–3), whose
    matrices the paper only cites: the vertical states only, with the
    accelerometer's vertical bias in place of the paper's "bias of the
    vertical velocity". Linear, so the EKF is a plain Kalman filter.

    State x = [p, v, b]ᵀ: vertical position about the walk's level (m),
    vertical velocity (m/s), bias of the vertical acceleration (m/s²). Per
    sample k, with Δt = t_k − t_{k−1} and the mean measured acceleration
    ā = ½(a_{k−1} + a_k):

        x_k = F x_{k−1} + B ā + w,   F = [[1, Δt, −½Δt²], [0, 1, −Δt], [0, 0, 1]],
                                      B = [½Δt², Δt, 0]ᵀ,                  (Eq. 2)
        Q = q_a·[[Δt³/3, Δt²/2, 0], [Δt²/2, Δt, 0], [0, 0, 0]] + diag(0, 0, q_b·Δt),

    the white-acceleration model (q_a: PSD of what the measured a_v gets
    wrong — noise, tilt leakage of horizontal acceleration) with a
    random-walk bias (q_b); the bias's coupling into Q's p and v terms is
    dropped, as usual for a slow bias. Measurements (Eq. 3), scalar:

    * **ZUPT** while the phone is still: z = 0 = v + ν, H = [0, 1, 0],
      R = ``zupt_sigma_mps``². Through v the bias becomes observable, so a
      still phone's bias is estimated and its position held.
    * **Level** at every sample: z = 0 = p + ν, H = [1, 0, 0], R = r_h/Δt,
      a pseudo-measurement that the phone's height on a level floor stays at
      its mean. Chosen over "zero velocity at troughs" because the detected
      trough of the low-passed a_v lags the top of the bounce by ≈ 0.15 s —
      a quarter of a step, where the vertical speed is near its largest —
      and over a per-step zero-mean-velocity constraint
      because that needs the step detection (with its latency) inside the
      filter; the level anchor needs neither. With r_h = q_a/(2π·f_c)⁴ the
      filter leaves the position a second-order high-pass of the integrated
      acceleration with corner f_c = ``level_bandwidth_hz``: drift slower
      than f_c is bounded, the bounce at 1.5–2.5 steps/s passes. Its gain
      there is 1 − k₁Δt/2 rather than the continuous filter's 1, where
      k₁ = 2√2·π·f_c: 0.989 at 100 Hz, 0.978 at 50 Hz for f_c = 0.25 Hz
      (a scale that :meth:`GaitDeadReckoning.calibrate` absorbs). It
      would fight a real climb (stairs, ramps); Chen2022's sites are level.

    Q and R are in continuous-time units (per second), so the filter hardly
    depends on the sampling rate (but for that gain).

    Attributes:
        accel_psd: q_a, (m/s²)²/Hz: 0.1 m/s²/√Hz, mostly what a tilt error
            of a degree or two leaks from walking's horizontal accelerations
            (MEMS noise, ≤ 0.002 m/s²/√Hz, is far below).
        bias_psd: q_b, (m/s²)²/s: the bias wanders 0.01 m/s² in 100 s.
        zupt_sigma_mps: standard deviation of the zero-velocity measurement,
            m/s: a hand holding still moves at millimetres per second.
        level_bandwidth_hz: f_c of the level pseudo-measurement, a tenth of
            the slowest walking cadence; None turns it off.
        P0: (3, 3) covariance after :meth:`reset`: 1 cm, 1 cm/s and 0.1 m/s²
            (an uncalibrated MEMS bias and the fused gravity's nominal |g|).
    """

    accel_psd: float = 1e-2
    bias_psd: float = 1e-6
    zupt_sigma_mps: float = 0.01
    level_bandwidth_hz: float | None = 0.25
    P0: NDArray[np.float64] = field(default_factory=lambda: np.diag([1e-4, 1e-4, 1e-2]))

    x: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    P: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    # The previous sample's time and acceleration (time NaN before the first).
    _last: NDArray[np.float64] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        _positive("accel_psd", self.accel_psd)
        _non_negative("bias_psd", self.bias_psd)
        _positive("zupt_sigma_mps", self.zupt_sigma_mps)
        if self.level_bandwidth_hz is not None:
            _positive("level_bandwidth_hz", self.level_bandwidth_hz)
        P0 = np.array(self.P0, dtype=float)
        if P0.shape != (3, 3) or not np.allclose(P0, P0.T) or np.any(np.linalg.eigvalsh(P0) < 0):
            raise ValueError(f"P0 must be a symmetric positive semi-definite 3×3 matrix, got {P0}")
        self.P0 = P0
        self.reset()

    @property
    def level_psd(self) -> float:
        """r_h of the level pseudo-measurement, m²·s (0 when it is off)."""
        if self.level_bandwidth_hz is None:
            return 0.0
        return self.accel_psd / (2.0 * np.pi * self.level_bandwidth_hz) ** 4

    def reset(self) -> None:
        """Start again at x = 0 with covariance ``P0``."""
        self.x = np.zeros(3)
        self.P = self.P0.copy()
        self._last = np.array([np.nan, 0.0])

    def filter(self, t: ArrayLike, a: ArrayLike, stationary: ArrayLike) -> NDArray[np.float64]:
        """Run the filter over the next samples.

        Args:
            t: (N,) sample times, s, increasing and after those of earlier calls.
            a: (N,) vertical acceleration a_v (Eq. 4), m/s².
            stationary: (N,) True where the phone is still (ZUPT).

        Returns:
            (N, 3) posterior states [p, v, b] at ``t``; ``x`` and ``P`` hold the last.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        a = np.asarray(a, dtype=float).reshape(-1)
        still = np.asarray(stationary, dtype=bool).reshape(-1)
        if not (len(t) == len(a) == len(still)):
            raise ValueError(f"{len(t)} times, {len(a)} accelerations, {len(still)} flags")
        out = np.empty((len(t), 3))
        _ekf_run(
            t,
            a,
            still,
            self._last,
            self.x,
            self.P,
            self.accel_psd,
            self.bias_psd,
            self.zupt_sigma_mps**2,
            self.level_psd,
            out,
        )
        return out


# ------------------------------------------------------------------ attitude


@numba.njit(cache=True)
def _quat_mul(a, b):  # pragma: no cover - compiled
    """Hamilton product a ⊗ b, scalar first."""
    return np.array(
        [
            a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
        ]
    )


@numba.njit(cache=True)
def _set_quat(dst, src):  # pragma: no cover - compiled
    """dst[:] = src, written out (numba's slice assignment is slow to compile)."""
    for i in range(4):
        dst[i] = src[i]


@numba.njit(cache=True)
def _rotvec_quat(v):  # pragma: no cover - compiled
    """exp(½v): the unit quaternion of the rotation vector v."""
    angle = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    # sin(θ/2)/θ → ½ as θ → 0 (its series), avoiding 0/0.
    s = math.sin(0.5 * angle) / angle if angle > 1e-8 else 0.5 - angle * angle / 48.0
    return np.array([math.cos(0.5 * angle), s * v[0], s * v[1], s * v[2]])


@numba.njit(cache=True)
def _dcm(q, C):  # pragma: no cover - compiled
    """Eq. 9 into C (scalar-first q)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    C[0, 0] = w * w + x * x - y * y - z * z
    C[0, 1] = 2.0 * (x * y - z * w)
    C[0, 2] = 2.0 * (x * z + y * w)
    C[1, 0] = 2.0 * (x * y + z * w)
    C[1, 1] = w * w - x * x + y * y - z * z
    C[1, 2] = 2.0 * (y * z - x * w)
    C[2, 0] = 2.0 * (x * z - y * w)
    C[2, 1] = 2.0 * (y * z + x * w)
    C[2, 2] = w * w - x * x - y * y + z * z


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

    ``state`` = [t_prev, ω_prev (3), axis, yaw_prev, relative yaw, bias sample
    count, FIFO head, FIFO length] carries across calls (t_prev NaN before the
    first sample), as do q, bias and the FIFO of still samples (t; ω, Δt)
    waiting for ``guard_s`` of stillness after them.
    """
    cap = fifo_t.size
    C = np.empty((3, 3))
    for k in range(t.size):
        dt = t[k] - state[0] if np.isfinite(state[0]) else 0.0
        if np.isfinite(state[0]):
            # Eq. 8: q ← q ⊗ exp(½Δθ), Δθ = ω̄Δt with the bias-corrected mean rate
            dtheta = np.empty(3)
            for i in range(3):
                dtheta[i] = (0.5 * (state[1 + i] + gyro[k, i]) - bias[i]) * dt
            _set_quat(q, _quat_mul(q, _rotvec_quat(dtheta)))
            if tilt_gain_rate > 0.0:
                # Measured up in the world; turning it toward +z about the
                # horizontal axis u × ẑ corrects roll and pitch, not yaw.
                _dcm(q, C)
                u = np.zeros(3)
                for i in range(3):
                    for j in range(3):
                        u[i] += C[i, j] * up[k, j]
                norm = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
                if norm > 0.0:
                    ex, ey = u[1] / norm, -u[0] / norm
                    angle = math.atan2(math.sqrt(ex * ex + ey * ey), u[2] / norm)
                    gain = min(1.0, tilt_gain_rate * dt)
                    sin_e = math.sqrt(ex * ex + ey * ey)
                    if sin_e > 0.0:
                        scale = gain * angle / sin_e
                        tilt = _rotvec_quat(np.array([ex * scale, ey * scale, 0.0]))
                        _set_quat(q, _quat_mul(tilt, q))
            n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
            for i in range(4):
                q[i] /= n
        if bias_rate > 0.0:
            if not still[k]:
                state[10] = 0.0  # the still samples just before motion may be its start
            else:
                if state[10] == cap:  # full: use the oldest now
                    _bias_step(bias, state, fifo_w[int(state[9])], bias_rate)
                    state[9] = (state[9] + 1) % cap
                    state[10] -= 1
                j = int((state[9] + state[10]) % cap)
                fifo_t[j] = t[k]
                for i in range(3):
                    fifo_w[j, i] = gyro[k, i]
                fifo_w[j, 3] = dt
                state[10] += 1
            while state[10] > 0 and fifo_t[int(state[9])] <= t[k] - guard_s:
                _bias_step(bias, state, fifo_w[int(state[9])], bias_rate)
                state[9] = (state[9] + 1) % cap
                state[10] -= 1
        _dcm(q, C)
        axis = int(state[5])
        if not np.isfinite(state[0]) or math.hypot(C[0, axis], C[1, axis]) < _MIN_HORIZONTAL:
            if np.isfinite(state[0]):
                # Last increment on the old axis, then follow the most horizontal one.
                yaw = math.atan2(C[1, axis], C[0, axis])
                state[7] += (yaw - state[6] + math.pi) % (2.0 * math.pi) - math.pi
            best, best_h = 0, -1.0
            for j in range(3):
                h = math.hypot(C[0, j], C[1, j])
                if h > best_h:
                    best, best_h = j, h
            state[5] = best
            state[6] = math.atan2(C[1, best], C[0, best])
        else:
            # Eq. 12 for the followed axis: ψ = atan2(C[1, j], C[0, j])
            yaw = math.atan2(C[1, axis], C[0, axis])
            state[7] += (yaw - state[6] + math.pi) % (2.0 * math.pi) - math.pi
            state[6] = yaw
        state[0] = t[k]
        for i in range(3):
            state[1 + i] = gyro[k, i]
        for i in range(4):
            out_q[k, i] = q[i]
        out_yaw[k] = state[7]


@numba.njit(cache=True)
def _bias_step(bias, state, sample, bias_rate):  # pragma: no cover - compiled
    """Zero angular-rate update: a still phone's gyro reads its bias.

    A fading-memory mean: the plain mean of the first samples, then an
    exponential one with weight Δt/τ (``sample`` = [ω (3), Δt]).
    """
    state[8] += 1.0
    gain = max(1.0 / state[8], bias_rate * sample[3])
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
    q_pitch = np.array([math.cos(pitch / 2), 0.0, math.sin(pitch / 2), 0.0])
    q_roll = np.array([math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0])
    return _quat_mul(q_pitch, q_roll)


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
    _state: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    _fifo_t: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    _fifo_w: NDArray[np.float64] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.tilt_time_constant_s is not None:
            _positive("tilt_time_constant_s", self.tilt_time_constant_s)
        if self.gyro_bias_time_constant_s is not None:
            _positive("gyro_bias_time_constant_s", self.gyro_bias_time_constant_s)
        _non_negative("gyro_bias_guard_s", self.gyro_bias_guard_s)
        self.reset()

    def reset(self) -> None:
        """Forget the attitude: the next sample levels it again from gravity."""
        self.q = np.array([1.0, 0.0, 0.0, 0.0])
        self.bias = np.zeros(3)
        self._state = np.array([np.nan, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        self._fifo_t = np.zeros(_BIAS_FIFO)
        self._fifo_w = np.zeros((_BIAS_FIFO, 4))

    @property
    def started(self) -> bool:
        """Whether a sample has set the attitude since the last reset."""
        return bool(np.isfinite(self._state[0]))

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


# ------------------------------------------------------------------ the facade


@dataclass(frozen=True)
class GaitStep:
    """One step of the gait-based DR.

    Attributes:
        t: time of the trough that ends the step, s.
        length: step length D (Eq. 6) times the length scale, m.
        heading: walking direction at the step, rad counter-clockwise from the building +x.
        delta_heading: heading change since the previous step (or since reset
            for the first), rad.
        vertical_displacement: S_VD (Eq. 5), m.
    """

    t: float
    length: float
    heading: float
    delta_heading: float
    vertical_displacement: float


@dataclass(slots=True)
class _Trough:
    t: float
    a: float


@dataclass(kw_only=True)
class GaitDeadReckoning:
    """Streaming gait-based DR (Chen2022 Eq. 1–12): steps with length and heading.

    Per sample (module docstring for the readings of the paper):

    1. ĝ: the fused gravity stream where given and ``use_gravity_stream``
       (rows of norm below 1 m/s² — a stream not yet started — fall back),
       else the accelerometer low-passed at ``gravity_cutoff_hz`` (2nd-order
       Butterworth);
    2. a_v = a·ĝ − |g| (Eq. 4);
    3. stillness (:class:`StationaryDetector`);
    4. the vertical EKF (:class:`VerticalZuptEKF`) integrates a_v to a height;
    5. the attitude (:class:`QuaternionAttitude`, Eq. 8–12) gives the change
       of yaw, if there is a gyro;
    6. a_v low-passed at ``step_cutoff_hz`` (4th-order Butterworth) is
       searched for troughs, and adjacent troughs make steps (Eq. 7);
    7. each step's S_VD is the excursion of the EKF height between its two
       troughs (Eq. 5), its length 2√(L² − (L − S_VD)²)·``length_scale``
       (Eq. 6), its heading the start heading plus the mean relative yaw
       over the step (which halves the heading error of the yaw at the
       step's end in simulated walks: the phone's own oscillation averages
       out; in a turn it lags by half a step).

    A step is reported once its ending trough is final: ``min_step_s`` after
    it (no deeper trough can replace it), plus the step filter's group delay
    (≈ 0.1 s at 3 Hz). The result does not depend on how the samples are
    split across :meth:`update` calls (to rounding). Without a gyro the
    heading stays at the start heading.

    Sampling is taken as uniform at ``rate_hz`` for the two low-pass
    filters; the EKF and the attitude use the actual sample intervals.

    Attributes:
        pendulum_length: L of Eq. 6, m (default: :data:`PENDULUM_LENGTH_M`).
        length_scale: factor on Eq. 6's D; :meth:`calibrate` fits it.
        use_gravity_stream: take ĝ from the fused gravity stream when given.
            It is the better vertical (Eq. 4 as physics); in a swinging hand
            the low-passed accelerometer counts steps better all the same:
            its ĝ is the arm's mean direction, so a_v keeps the swing's
            centripetal acceleration, which peaks once per step (simulated
            Nexus 5X walks: count errors 0 to +19 % with the stream, −2 to
            +4 % without).
        gravity_cutoff_hz: low-pass cut-off of the accelerometer's gravity
            estimate: a tenth of a walking cadence, so the step's
            accelerations hardly tilt it.
        step_cutoff_hz: low-pass cut-off of a_v for trough search: passes
            cadences up to 2.5 steps/s and removes heel-strike transients
            (as :class:`~indoorsim.estimators.pdr.steps.PeakStepDetector`).
        trough_threshold_mps2: a^thd of Eq. 7: a trough lies below −a^thd.
            Walking troughs of the low-passed a_v reach −1.5 to −3 m/s² in
            hand, at the ear and in a pocket, but only −0.4 to −1.3 m/s² in
            a swinging hand, whose swing lowers the hand as the trunk rises
            and so cancels much of the bounce; a still phone's stay within a
            few hundredths.
        min_step_s: shortest step time; of two troughs closer than this the
            deeper is kept (2.5 steps/s is 0.4 s).
        max_step_s: longest step time; troughs further apart do not make a
            step (gait initiation is ≈ 0.7 s at most).
        rate_hz: sampling rate; None estimates it from the median interval
            of the first 16 samples (steps appear once those arrived).
        stationary: the still-phone detector.
        ekf: the vertical Kalman filter.
        attitude: the gyro attitude.
    """

    pendulum_length: float = PENDULUM_LENGTH_M
    length_scale: float = 1.0
    use_gravity_stream: bool = True
    gravity_cutoff_hz: float = 0.3
    step_cutoff_hz: float = 3.0
    trough_threshold_mps2: float = 0.3
    min_step_s: float = 0.3
    max_step_s: float = 1.0
    rate_hz: float | None = None
    stationary: StationaryDetector = field(default_factory=StationaryDetector)
    ekf: VerticalZuptEKF = field(default_factory=VerticalZuptEKF)
    attitude: QuaternionAttitude = field(default_factory=QuaternionAttitude)

    _start_heading: float = field(default=0.0, init=False, repr=False, compare=False)
    _last_step_heading: float = field(default=0.0, init=False, repr=False, compare=False)
    _count: int = field(default=0, init=False, repr=False, compare=False)
    _rel_yaw: float = field(default=0.0, init=False, repr=False, compare=False)
    _waiting: list[tuple[NDArray[np.float64], ...]] = field(
        default_factory=list, init=False, repr=False, compare=False
    )
    _rate: float | None = field(default=None, init=False, repr=False, compare=False)
    _sos_g: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    _sos_s: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    _zi_g: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    _zi_s: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    # Recent samples (t, filtered a_v, EKF height, relative yaw, still): the
    # last two are the edge for extrema, the rest the span a step can need.
    _hist: NDArray[np.float64] = field(
        default_factory=lambda: np.empty((0, 5)), init=False, repr=False, compare=False
    )
    _last: _Trough | None = field(default=None, init=False, repr=False, compare=False)
    _pending: _Trough | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        _positive("pendulum_length", self.pendulum_length)
        _positive("length_scale", self.length_scale)
        _positive("gravity_cutoff_hz", self.gravity_cutoff_hz)
        _positive("step_cutoff_hz", self.step_cutoff_hz)
        _non_negative("trough_threshold_mps2", self.trough_threshold_mps2)
        _positive("min_step_s", self.min_step_s)
        _positive("max_step_s", self.max_step_s)
        if self.max_step_s <= self.min_step_s:
            raise ValueError(
                f"max_step_s ({self.max_step_s}) must exceed min_step_s ({self.min_step_s})"
            )
        if self.gravity_cutoff_hz >= self.step_cutoff_hz:
            raise ValueError(
                f"gravity_cutoff_hz ({self.gravity_cutoff_hz}) must be below "
                f"step_cutoff_hz ({self.step_cutoff_hz})"
            )
        if self.rate_hz is not None:
            _positive("rate_hz", self.rate_hz)
            self._check_rate(self.rate_hz)
        self.reset(0.0)

    def _check_rate(self, rate: float) -> None:
        if rate <= 2 * self.step_cutoff_hz:
            raise ValueError(
                f"rate_hz {rate:.3g} Hz must exceed twice step_cutoff_hz ({self.step_cutoff_hz})"
            )

    # -------------------------------------------------------------- public interface

    def reset(self, heading: float) -> None:
        """Start a new walk at ``heading``, rad counter-clockwise from the building +x."""
        if not np.isfinite(heading):
            raise ValueError(f"heading must be finite, got {heading!r}")
        self._start_heading = self._last_step_heading = float(heading)
        self._count = 0
        self._rel_yaw = 0.0
        self._waiting = []
        self._rate = self.rate_hz
        self._sos_g = self._sos_s = self._zi_g = self._zi_s = None
        self._hist = np.empty((0, 5))
        self._last = self._pending = None
        self.stationary.reset()
        self.ekf.reset()
        self.attitude.reset()

    @property
    def heading(self) -> float:
        """The latest heading estimate, rad counter-clockwise from building +x (unwrapped)."""
        return self._start_heading + self._rel_yaw

    @property
    def step_count(self) -> int:
        """Steps reported since the last reset."""
        return self._count

    def update(
        self,
        t: ArrayLike,
        accel: ArrayLike,
        gyro: ArrayLike | None,
        gravity: ArrayLike | None = None,
    ) -> list[GaitStep]:
        """Feed consecutive samples; return the steps completed in this chunk.

        Args:
            t: (N,) sample times, s, increasing and after those of earlier calls.
            accel: (N, 3) specific force, phone frame, m/s².
            gyro: (N, 3) angular rate, phone frame, rad/s, at the same times;
                None if the phone has none.
            gravity: (N, 3) fused gravity, phone frame, m/s², or None.

        Returns:
            The steps whose ending troughs became final with these samples, in time order.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        accel = np.asarray(accel, dtype=float).reshape(-1, 3)
        n = len(t)
        if len(accel) != n:
            raise ValueError(f"{n} times but {len(accel)} accelerometer samples")
        # NaN rows mark a missing stream for the samples of this chunk.
        gyro_a = np.full((n, 3), np.nan) if gyro is None else np.asarray(gyro, dtype=float)
        grav_a = np.full((n, 3), np.nan) if gravity is None else np.asarray(gravity, dtype=float)
        for name, arr in (("gyro", gyro_a), ("gravity", grav_a)):
            if arr.shape != (n, 3):
                raise ValueError(f"{name} must have shape ({n}, 3), got {arr.shape}")
        if self._rate is None:
            self._waiting.append((t, accel, gyro_a, grav_a))
            t, accel, gyro_a, grav_a = (
                np.concatenate([w[i] for w in self._waiting]) for i in range(4)
            )
            if len(t) < _RATE_SAMPLES:
                return []
            self._waiting = []
            rate = 1.0 / float(np.median(np.diff(t[:_RATE_SAMPLES])))
            self._check_rate(rate)
            self._rate = rate
        if not len(t):
            return []
        return self._process(t, accel, gyro_a, grav_a)

    def calibrate(self, steps: Sequence[GaitStep], true_lengths: ArrayLike) -> float:
        """Fit and set ``length_scale`` to steps matched to their true lengths; return it.

        Eq. 6 makes every length c·f(S_VD), f the pendulum at
        ``pendulum_length`` (computed from the steps' stored S_VD, so the
        scale they were made with does not matter). The fit is the scale
        that makes the total distance exact,

            c = Σ L_i / Σ f_i,

        rather than least squares (Σ f_i·L_i / Σ f_i²,
        :func:`~indoorsim.estimators.pdr.length.calibrate_k`), which shrinks
        c when f scatters about the truth — regression dilution: in a
        pocket, where the steps of the pocket's leg bounce the phone about
        twice as much as the others, least squares comes out 4–5 % short
        on distance.

        Args:
            steps: steps of training walks.
            true_lengths: (N,) the true length of each step, m.

        Raises:
            ValueError: if the counts differ or every f_i is zero.
        """
        lengths = np.asarray(true_lengths, dtype=float).reshape(-1)
        if len(lengths) != len(steps):
            raise ValueError(f"{len(steps)} steps but {len(lengths)} true lengths")
        f = pendulum_step_length(
            np.array([s.vertical_displacement for s in steps], dtype=float), self.pendulum_length
        )
        denom = float(f.sum())
        if denom == 0.0:
            raise ValueError("cannot calibrate length_scale: every step has S_VD = 0")
        scale = float(lengths.sum()) / denom
        _positive("length_scale", scale)
        self.length_scale = scale
        return scale

    # -------------------------------------------------------------- internals

    def _process(
        self,
        t: NDArray[np.float64],
        accel: NDArray[np.float64],
        gyro: NDArray[np.float64],
        gravity: NDArray[np.float64],
    ) -> list[GaitStep]:
        if self._sos_g is None:
            self._sos_g = butter(2, self.gravity_cutoff_hz, fs=self._rate, output="sos")
            self._sos_s = butter(4, self.step_cutoff_hz, fs=self._rate, output="sos")
            # At rest on the first sample: no start transient.
            self._zi_g = sosfilt_zi(self._sos_g)[:, :, None] * accel[0]
        g_lp, self._zi_g = sosfilt(self._sos_g, accel, axis=0, zi=self._zi_g)
        up = g_lp
        if self.use_gravity_stream:
            fused = np.linalg.norm(np.nan_to_num(gravity), axis=1) > _MIN_GRAVITY
            up = np.where(fused[:, None], gravity, g_lp)
        # Eq. 4: a_v = a·ĝ − |g|
        a_v = vertical_acceleration(accel, up)
        has_gyro = np.isfinite(gyro).all(axis=1)
        # Samples without a gyro reading pass the detector's gyro test.
        still = self.stationary.update(t, accel, np.where(has_gyro[:, None], gyro, 0.0))
        height = self.ekf.filter(t, a_v, still)[:, 0]
        rel_yaw = np.full(len(t), self._rel_yaw)
        if has_gyro.any():
            _, yaw = self.attitude.update(
                t[has_gyro], gyro[has_gyro], up[has_gyro], still[has_gyro]
            )
            # Samples without a gyro reading hold the latest heading.
            latest = np.cumsum(has_gyro) - 1
            rel_yaw = np.where(latest >= 0, yaw[np.maximum(latest, 0)], self._rel_yaw)
        self._rel_yaw = float(rel_yaw[-1])
        if self._zi_s is None:
            self._zi_s = sosfilt_zi(self._sos_s) * a_v[0]
        y, self._zi_s = sosfilt(self._sos_s, a_v, zi=self._zi_s)

        buf = np.concatenate(
            [self._hist, np.column_stack([t, y, height, rel_yaw, still.astype(float)])]
        )
        n_old = len(self._hist)
        tb, yb = buf[:, 0], buf[:, 1]
        # Interior samples only: a trough needs both neighbours. Old samples
        # beyond the edge of two were already searched.
        lo = max(n_old - 1, 1)
        idx = np.arange(lo, len(buf) - 1)
        is_trough = (yb[idx] < yb[idx - 1]) & (yb[idx] <= yb[idx + 1])
        is_trough &= (yb[idx] < -self.trough_threshold_mps2) & (buf[idx, 4] == 0.0)
        steps: list[GaitStep] = []
        for i in idx[is_trough]:
            self._confirm(tb[i], buf, steps)
            self._on_trough(_Trough(t=float(tb[i]), a=float(yb[i])))
        if len(buf) >= 2:
            self._confirm(tb[-2], buf, steps)  # every sample up to here is decided
        keep = tb >= tb[-1] - (self.max_step_s + self.min_step_s + 0.5)
        keep[-2:] = True
        self._hist = buf[keep]
        return steps

    def _on_trough(self, trough: _Trough) -> None:
        pending = self._pending
        if pending is not None and trough.a >= pending.a:
            return  # closer than min_step_s (else _confirm took it) and shallower
        self._pending = trough

    def _confirm(self, t_now: float, buf: NDArray[np.float64], out: list[GaitStep]) -> None:
        """Make the pending trough final once no deeper one can replace it; emit its step."""
        p = self._pending
        if p is None or t_now - p.t < self.min_step_s:
            return
        self._pending = None
        last, self._last = self._last, p
        # Eq. 7: the step runs from the previous trough, or, opening a bout,
        # from at most max_step_s before; in either case from the end of any
        # stillness in between.
        chained = last is not None and p.t - last.t <= self.max_step_s
        t_start = last.t if chained else p.t - self.max_step_s
        i0, i1 = np.searchsorted(buf[:, 0], [t_start, p.t], side="left")
        span = buf[i0 : i1 + 1]
        still = np.flatnonzero(span[:, 4])
        if len(still):
            span = span[still[-1] :]
        if len(span) < 3:
            return
        # Eq. 5: S_VD, the excursion of the doubly integrated a_v
        s_vd = float(np.ptp(span[:, 2]))
        # Eq. 6: D = 2√(L² − (L − S_VD)²), scaled
        length = self.length_scale * float(pendulum_step_length(s_vd, self.pendulum_length))
        # The step's mean yaw: the phone's own oscillation (trunk yaw, arm
        # swing, thigh) averages out of it, and the walking direction stays.
        heading = self._start_heading + float(np.mean(span[:, 3]))
        out.append(
            GaitStep(
                t=p.t,
                length=length,
                heading=heading,
                delta_heading=heading - self._last_step_heading,
                vertical_displacement=s_vd,
            )
        )
        self._last_step_heading = heading
        self._count += 1
