"""Stationary detection and the vertical ZUPT Kalman filter (Chen2022 Eq. 1–3).

Two components of the gait-based dead reckoning
(:class:`~indoorsim.estimators.pdr.gait.GaitDeadReckoning`):
:class:`StationaryDetector` finds the samples at which the phone is still,
and :class:`VerticalZuptEKF` integrates the vertical acceleration to a height
with zero-velocity updates at them.

Chen2022's 9-state error filter (vertical position and velocity, three
attitude angles and four biases) is only cited (its F, Q, H, R are "in Chen
et al. 2018b"). This is a documented *reduction*: a 3-state Kalman filter on
the vertical channel (position, velocity, accelerometer bias); the attitude
part, the gyro biases re-estimated whenever the phone is still (a zero
angular-rate update), is in
:class:`~indoorsim.estimators.pdr.attitude.QuaternionAttitude`.

Reading taken where the text is silent (PAPER_NOTES, Chen2022 item 1–2):
**Eq. 2**, the EKF's state equation δX_k = F_{k−1} δX_{k−1} + ω_{k−1}, is
lost in the extraction; Eq. 3 is the measurement equation. Both are used
with the matrices of :class:`VerticalZuptEKF`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.pdr._checks import non_negative, positive

__all__ = ["StationaryDetector", "VerticalZuptEKF"]


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
        positive("window_s", self.window_s)
        positive("accel_std_mps2", self.accel_std_mps2)
        positive("gyro_rms_rad_s", self.gyro_rms_rad_s)

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
      k₁ = 2√2·π·f_c: 0.989 at 100 Hz, 0.978 at 50 Hz for f_c = 0.25 Hz (a
      scale that :meth:`~indoorsim.estimators.pdr.gait.GaitDeadReckoning.calibrate`
      absorbs). It would fight a real climb (stairs, ramps); Chen2022's sites
      are level.

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
        positive("accel_psd", self.accel_psd)
        non_negative("bias_psd", self.bias_psd)
        positive("zupt_sigma_mps", self.zupt_sigma_mps)
        if self.level_bandwidth_hz is not None:
            positive("level_bandwidth_hz", self.level_bandwidth_hz)
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
