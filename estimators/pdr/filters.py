"""Heading from the magnetometer, the gyroscope and their Kalman fusions (Han2023 §2.1.3).

Han2023 computes two headings and fuses them:

* **Mag** ("Method 2"): the tilt-compensated magnetometer heading,
  :func:`mag_heading` — absolute, but bent by indoor magnetic disturbances;
* **Gyro** ("Method 1"): the yaw rate integrated trapezoidally,
  :func:`gyro_heading` — smooth, but drifting with the gyro's bias;
* **KF** (Eq. 6–9): :class:`HeadingKF`, state x = [φ, ω]ᵀ (heading, rad;
  its rate, rad/s), measurement z = [φ_mag, dφ_mag/dt]ᵀ;
* **BKF** (Eq. 10–15): :class:`HeadingBKF`, the KF whose posterior is shrunk
  by the bias factor γ after every update.

Readings taken where the text is wrong or silent (PAPER_NOTES, Han2023 item 3):

* F = A = [[1, Δt], [0, 1]] (the text's transpose would add Δt·φ to the
  rate instead of Δt·ω to the heading); H = B = I.
* Eq. 8 is P⁻ = F P Fᵀ + Q (the text drops the transpose); Eq. 9 and 15
  update the *prior*, P = (I − K H) P⁻ (the text writes P_{k−1|k−1}).
* Eq. 15's garbled "P^BKF = γ Ŷ" is P^BKF = γ² P, as Eq. 12 implies.
* The text's equations never use the gyroscope, though its state is called
  [φ^gyr, ω^gyr]ᵀ — "the gyroscope heading angle and angular velocity". Read
  here: when gyro rates are given, the state's rate *is* the gyroscope's.
  Before each prediction ω is replaced by the gyro's mean yaw rate over the
  step, ω̄_k = ½(r_{k−1} + r_k), an independent measurement of variance
  ``gyro_rate_var`` (so P_ωω ← σ²_gyro and P_φω ← 0), and then x⁻ = F x. With
  no magnetometer update this is exactly the trapezoidal
  :func:`gyro_heading`; without gyro rates the filter is the text's literal
  constant-rate model.

Angles: the magnetometer heading is unwrapped before filtering — consecutive
measurements differ by less than π — so that the state, its rate and the
innovations never see a 2π jump; the first measurement of a walk is put on
the 2π branch nearest the filter's heading. Filter headings are therefore
continuous (unwrapped); wrap them with
:func:`~indoorsim.estimators.frames.wrap_angle` for display or scoring.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_trapezoid

from indoorsim.estimators.frames import wrap_angle, yaw_rate

__all__ = ["HeadingBKF", "HeadingKF", "HeadingTrack", "gyro_heading", "mag_heading"]

# Below this norm a vector carries no direction (a missing stream is all zeros).
_TINY = 1e-9


def mag_heading(
    mag: ArrayLike,
    gravity_or_accel: ArrayLike,
    magnetic_to_building_rad: float = 0.0,
    axis: ArrayLike = (0.0, 1.0, 0.0),
) -> NDArray[np.float64]:
    """Tilt-compensated magnetometer heading of a phone axis (Han2023 "Method 2").

    With û = g/‖g‖ the phone-frame "up" (the accelerometer at rest, or
    Android's gravity sensor, reads +g upward) and m the field, the horizontal
    east and north directions in the phone frame are

        ê = (m × û)/‖m × û‖,    n̂ = û × ê,

    (the horizontal part of m points to magnetic north; east = north × up).
    The heading of the phone axis v (default +y, the top of the screen) is
    then

        ψ = atan2(v·n̂, v·ê) + magnetic_to_building_rad,

    counter-clockwise from magnetic east (DESIGN §2), moved to the building
    frame by the offset. This is the classical tilt compensation — pitch and
    roll from the accelerometer level the field, whose horizontal yaw is the
    heading — written without Euler angles, so it has no gimbal singularity;
    for v = +y it equals the yaw of Android's Z-X-Y ``getOrientation``.

    Args:
        mag: (N, 3) magnetic field, phone frame, µT.
        gravity_or_accel: (N, 3) gravity (or a still or low-passed
            accelerometer), phone frame; only its direction is used. Linear
            acceleration in a raw walking accelerometer tilts û and so the heading.
        magnetic_to_building_rad: ``SiteContext.magnetic_to_building_rad``;
            0 gives the heading from magnetic east.
        axis: the phone-frame axis whose heading is wanted.

    Returns:
        (N,) headings wrapped to [−π, π); NaN where the field or gravity is
        zero or parallel, or ``axis`` is vertical (no horizontal direction).

    >>> mag_heading([[0.0, 30.0, -40.0]], [[0.0, 0.0, 9.8]])  # flat, top to north
    array([1.57079633])
    """
    m = np.asarray(mag, dtype=float).reshape(-1, 3)
    g = np.asarray(gravity_or_accel, dtype=float).reshape(-1, 3)
    v = np.asarray(axis, dtype=float)
    up = g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), _TINY)
    east = np.cross(m, up)
    north = np.cross(up, east)
    v_east, v_north = east @ v, north @ v
    # ‖ê‖ = ‖m × û‖ and ‖n̂‖ = ‖ê‖ (û ⊥ ê): normalising both would not change atan2.
    e_norm = np.linalg.norm(east, axis=1)
    defined = (e_norm > _TINY) & (np.hypot(v_east, v_north) > _TINY * e_norm)
    psi = wrap_angle(np.arctan2(v_north, v_east) + magnetic_to_building_rad)
    return np.where(defined, psi, np.nan)


def gyro_heading(
    t: ArrayLike, gyro: ArrayLike, gravity: ArrayLike, heading0: float = 0.0
) -> NDArray[np.float64]:
    """Gyroscope heading by trapezoidal integration of the yaw rate (Han2023 "Method 1").

        φ_k = φ₀ + Σ_{j=1..k} ½·(r_{j−1} + r_j)·(t_j − t_{j−1}),    r = ω·ĝ

    with r from :func:`~indoorsim.estimators.frames.yaw_rate`, so that a
    tilted phone integrates its turn about the vertical. The streaming form
    is :class:`~indoorsim.estimators.pdr.heading.GyroHeading`.

    Args:
        t: (N,) sample times, s.
        gyro: (N, 3) angular rate, phone frame, rad/s.
        gravity: (N, 3) gravity (up-pointing), phone frame.
        heading0: the heading at ``t[0]``, rad.

    Returns:
        (N,) unwrapped headings, rad, in the frame of ``heading0``.

    >>> gyro_heading([0.0, 1.0, 2.0], [[0, 0, 0.1], [0, 0, 0.3], [0, 0, 0.3]], [[0, 0, 9.8]] * 3)
    array([0. , 0.2, 0.5])
    """
    r = yaw_rate(np.reshape(gyro, (-1, 3)), np.reshape(gravity, (-1, 3)))
    return heading0 + cumulative_trapezoid(r, np.asarray(t, dtype=float), initial=0.0)


@dataclass(frozen=True, kw_only=True)
class HeadingTrack:
    """Per-step record of a heading filter run (filterpy's saved attributes).

    Step k is the prediction to ``t[k]`` followed by the update with the
    measurement at ``t[k]``. Unmeasured components (NaN in z) have NaN
    innovations and zero gain columns; a step without measurement has
    x = x_prior and P = P_prior.

    Attributes:
        t: (N,) step times, s.
        x: (N, 2) posteriors [φ, ω] (for the BKF, after the shrinkage).
        P: (N, 2, 2) posterior covariances.
        x_prior: (N, 2) priors x⁻.
        P_prior: (N, 2, 2) prior covariances P⁻.
        z: (N, 2) measurements [φ_mag, dφ_mag/dt] as filtered (unwrapped).
        y: (N, 2) innovations z − H x⁻.
        K: (N, 2, 2) Kalman gains.
        gamma: (N,) the BKF's bias factors γ (1 for the plain KF and for
            steps without measurement).
    """

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    P: NDArray[np.float64]
    x_prior: NDArray[np.float64]
    P_prior: NDArray[np.float64]
    z: NDArray[np.float64]
    y: NDArray[np.float64]
    K: NDArray[np.float64]
    gamma: NDArray[np.float64]

    @property
    def heading(self) -> NDArray[np.float64]:
        """(N,) filtered headings φ, rad, unwrapped."""
        return self.x[:, 0]


def _matrix(value: ArrayLike, name: str) -> NDArray[np.float64]:
    m = np.array(value, dtype=float)
    if m.shape != (2, 2) or not np.allclose(m, m.T) or np.any(np.linalg.eigvalsh(m) < 0):
        raise ValueError(f"{name} must be a symmetric positive semi-definite 2×2 matrix, got {m}")
    return m


# ------------------------------------------------------------------ compiled steps
# The recursion cannot be vectorised over time; compiled, a step costs about
# 2 µs instead of some sixty in NumPy. x and P are updated in place. Products
# and copies are written out as loops: numba's BLAS-backed @ and its slice
# assignment take seconds each to compile for 2×2 matrices.


@numba.njit(cache=True)
def _mm(a, b):  # pragma: no cover - compiled
    """a @ b for small matrices."""
    out = np.zeros((a.shape[0], b.shape[1]))
    for i in range(a.shape[0]):
        for j in range(b.shape[1]):
            for r in range(a.shape[1]):
                out[i, j] += a[i, r] * b[r, j]
    return out


@numba.njit(cache=True)
def _mv(a, v):  # pragma: no cover - compiled
    """a @ v for a small matrix and vector."""
    out = np.zeros(a.shape[0])
    for i in range(a.shape[0]):
        for r in range(a.shape[1]):
            out[i] += a[i, r] * v[r]
    return out


@numba.njit(cache=True)
def _inv(s):  # pragma: no cover - compiled
    """The inverse of a 1×1 or 2×2 matrix."""
    if s.shape[0] == 1:
        return 1.0 / s
    det = s[0, 0] * s[1, 1] - s[0, 1] * s[1, 0]
    return np.array([[s[1, 1], -s[0, 1]], [-s[1, 0], s[0, 0]]]) / det


@numba.njit(cache=True)
def _set1(dst, src):  # pragma: no cover - compiled
    """dst[:] = src for vectors."""
    for i in range(dst.shape[0]):
        dst[i] = src[i]


@numba.njit(cache=True)
def _set2(dst, src):  # pragma: no cover - compiled
    """dst[:] = src for matrices."""
    for i in range(dst.shape[0]):
        for j in range(dst.shape[1]):
            dst[i, j] = src[i, j]


@numba.njit(cache=True)
def _predict(x, P, dt, omega, Q, gyro_rate_var):  # pragma: no cover - compiled
    """Eq. 8, after the gyro's rate (if finite) replaces the state's."""
    if np.isfinite(omega):
        x[1] = omega
        P[0, 1] = P[1, 0] = 0.0
        P[1, 1] = gyro_rate_var
    F = np.array([[1.0, dt], [0.0, 1.0]])
    # Eq. 8: x⁻ = F x, P⁻ = F P Fᵀ + Q
    _set1(x, _mv(F, x))
    _set2(P, _mm(_mm(F, P), F.T.copy()) + Q)


@numba.njit(cache=True)
def _update(x, P, z, R, y, K):  # pragma: no cover - compiled
    """Eq. 9 with the finite components of z; fills y and K, returns whether any was measured."""
    y.fill(np.nan)
    K.fill(0.0)
    seen = [i for i in range(2) if np.isfinite(z[i])]
    m = len(seen)
    if m == 0:
        return False
    H = np.zeros((m, 2))
    Rm = np.empty((m, m))
    zm = np.empty(m)
    for i in range(m):
        H[i, seen[i]] = 1.0
        zm[i] = z[seen[i]]
        for j in range(m):
            Rm[i, j] = R[seen[i], seen[j]]
    Ht = H.T.copy()
    # Eq. 9: K = P⁻Hᵀ(H P⁻ Hᵀ + R)⁻¹, x = x⁻ + K(z − H x⁻), P = (I − K H) P⁻
    innovation = zm - _mv(H, x)
    S = _mm(_mm(H, P), Ht) + Rm
    gain = _mm(_mm(P, Ht), _inv(S))
    _set1(x, x + _mv(gain, innovation))
    _set2(P, _mm(np.eye(2) - _mm(gain, H), P))
    for i in range(m):
        y[seen[i]] = innovation[i]
        for r in range(2):
            K[r, seen[i]] = gain[r, i]
    return True


@numba.njit(cache=True)
def _shrink(x, P, origin):  # pragma: no cover - compiled
    """The BKF's bias (Eq. 10, 12, 14, 15) about [origin, 0]; returns γ."""
    x[0] -= origin
    norm2 = x[0] * x[0] + x[1] * x[1]
    # Eq. 14 (γ = 1 for a state exactly at the origin, where it is 0/Tr P)
    gamma = norm2 / (P[0, 0] + P[1, 1] + norm2) if norm2 > 0.0 else 1.0
    # Eq. 10 and 15: X ← γ X, P ← γ² P
    _set1(x, gamma * x)
    _set2(P, gamma * gamma * P)
    x[0] += origin
    return gamma


@numba.njit(cache=True)
def _run(
    dts,
    zs,
    omegas,
    x,
    P,
    Q,
    R,
    gyro_rate_var,
    biased,
    origin,
    xs,
    Ps,
    x_priors,
    P_priors,
    ys,
    Ks,
    gammas,
):  # pragma: no cover - compiled
    """Predict-update (and shrink) over every step, recording each step."""
    for k in range(dts.size):
        _predict(x, P, dts[k], omegas[k], Q, gyro_rate_var)
        _set1(x_priors[k], x)
        _set2(P_priors[k], P)
        if _update(x, P, zs[k], R, ys[k], Ks[k]) and biased:
            gammas[k] = _shrink(x, P, origin)
        _set1(xs[k], x)
        _set2(Ps[k], P)


@dataclass(kw_only=True)
class HeadingKF:
    """Kalman filter of heading and heading rate (Han2023 Eq. 6–9).

    Model, per step k with Δt_k = t_k − t_{k−1}:

        x_k = F x_{k−1} + q,   F = [[1, Δt_k], [0, 1]],   q ~ N(0, Q)    (Eq. 6)
        z_k = H x_k + r,       H = I,                      r ~ N(0, R)    (Eq. 7)

    with x = [φ, ω]ᵀ and z = [φ_mag, dφ_mag/dt]ᵀ. Each step predicts,

        x⁻ = F x,   P⁻ = F P Fᵀ + Q                                       (Eq. 8)

    and, with a measurement, updates:

        y = z − H x⁻,   S = H P⁻ Hᵀ + R,   K = P⁻ Hᵀ S⁻¹                  (Eq. 9)
        x = x⁻ + K y,   P = (I − K H) P⁻

    A component of z that is NaN is not measured (its rows of H and R are
    dropped for that step). Gyro rates, if given, drive the prediction
    (module docstring). Q and R are per step, not per second: the paper's Q
    is a constant matrix, so retune them when the step rate changes. The
    defaults suit steps at 100 Hz: Q = diag(10⁻⁶ rad², 10⁻³ rad²/s²), random
    walks of 0.57°/√s in heading and 0.32 rad/s/√s in rate, and
    R = diag((0.1 rad)², (0.71 rad/s)²), about 6° for an indoor magnetometer
    heading and a noisy difference quotient for its rate.

    The filter keeps its state across calls, so a pipeline feeds it window
    after window, through :meth:`filter` or step by step through
    :meth:`predict` and :meth:`update`; after each step ``x``, ``P``,
    ``x_prior``, ``P_prior``, ``y`` and ``K`` hold that step's values
    (filterpy's names). The steps are compiled with numba: the recursion
    cannot be vectorised over time (a step costs about 2 µs).

    Attributes:
        Q: (2, 2) process noise covariance per step.
        R: (2, 2) measurement noise covariance.
        P0: (2, 2) covariance of the state after :meth:`reset`.
        gyro_rate_var: variance σ²_gyro of the gyro's mean yaw rate over a
            step, (rad/s)², used when gyro rates drive the prediction.
    """

    Q: NDArray[np.float64] = field(default_factory=lambda: np.diag([1e-6, 1e-3]))
    R: NDArray[np.float64] = field(default_factory=lambda: np.diag([1e-2, 0.5]))
    P0: NDArray[np.float64] = field(default_factory=lambda: np.diag([1e-2, 1e-2]))
    gyro_rate_var: float = 1e-4

    # The latest step (filterpy's names), set by reset(), predict() and update().
    x: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    P: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    x_prior: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    P_prior: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    y: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    K: NDArray[np.float64] = field(init=False, repr=False, compare=False)

    # Carried across filter() calls: time of the last step, last gyro rate,
    # last valid magnetometer sample (time, unwrapped heading).
    _t: float | None = field(default=None, init=False, repr=False, compare=False)
    _rate: float | None = field(default=None, init=False, repr=False, compare=False)
    _mag: tuple[float, float] | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        self.Q = _matrix(self.Q, "Q")
        self.R = _matrix(self.R, "R")
        self.P0 = _matrix(self.P0, "P0")
        if self.gyro_rate_var < 0:
            raise ValueError(f"gyro_rate_var must be ≥ 0, got {self.gyro_rate_var}")
        self.reset(0.0)

    def reset(
        self,
        heading: float,
        rate: float = 0.0,
        P: ArrayLike | None = None,
        t0: float | None = None,
    ) -> None:
        """Start a new walk.

        Args:
            heading: initial heading φ₀, rad (the frame every later heading is in).
            rate: initial rate ω₀, rad/s.
            P: initial covariance; ``None`` for ``P0``.
            t0: time of the initial state, s; ``None`` for the first step's
                time (the first step then predicts over Δt = 0).
        """
        self.x = np.array([heading, rate], dtype=float)
        self.P = self.P0.copy() if P is None else _matrix(P, "P")
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()
        self.y = np.full(2, np.nan)
        self.K = np.zeros((2, 2))
        self._t = t0
        self._rate = None
        self._mag = None

    def _bias(self) -> tuple[bool, float]:
        """Whether updates are followed by the BKF's shrinkage, and about which heading."""
        return False, 0.0

    def predict(self, dt: float, omega: float | None = None) -> None:
        """Propagate the state by ``dt`` seconds (Eq. 8).

        Args:
            dt: Δt_k, s.
            omega: the gyro's mean yaw rate over the step, rad/s, which
                replaces the state's rate first; ``None`` (or NaN) for the
                text's constant-rate model.
        """
        w = np.nan if omega is None else float(omega)
        _predict(self.x, self.P, float(dt), w, self.Q, self.gyro_rate_var)
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()

    def update(self, z: ArrayLike) -> float:
        """Correct the prior with z = [φ_mag, dφ_mag/dt] (Eq. 9); NaN components are skipped.

        Returns:
            The bias factor γ applied after the update (1 for the plain KF or
            without a measurement).
        """
        zk = np.ascontiguousarray(z, dtype=float).reshape(2)
        biased, origin = self._bias()
        if _update(self.x, self.P, zk, self.R, self.y, self.K) and biased:
            return float(_shrink(self.x, self.P, origin))
        return 1.0

    def batch_filter(
        self, t: ArrayLike, zs: ArrayLike, omegas: ArrayLike | None = None
    ) -> HeadingTrack:
        """Run predict-update over measurements already unwrapped.

        Args:
            t: (N,) step times, s, increasing and after those of earlier calls.
            zs: (N, 2) measurements [φ, dφ/dt] (NaN: not measured).
            omegas: (N,) the gyro's mean yaw rate over each step, rad/s (NaN:
                the constant-rate model for that step), or ``None`` for the
                constant-rate model throughout.

        Returns:
            The per-step record.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        zs = np.ascontiguousarray(zs, dtype=float).reshape(-1, 2)
        n = len(t)
        w = np.full(n, np.nan) if omegas is None else np.ascontiguousarray(omegas, dtype=float)
        if len(zs) != n or w.shape != (n,):
            raise ValueError(f"{n} times need (N, 2) measurements and (N,) rates")
        xs, Ps = np.empty((n, 2)), np.empty((n, 2, 2))
        x_priors, P_priors = np.empty((n, 2)), np.empty((n, 2, 2))
        ys, Ks, gammas = np.empty((n, 2)), np.empty((n, 2, 2)), np.ones(n)
        dts = np.diff(t, prepend=t[0] if self._t is None else self._t)
        biased, origin = self._bias()
        _run(
            dts, zs, w, self.x, self.P, self.Q, self.R, self.gyro_rate_var, biased, origin,
            xs, Ps, x_priors, P_priors, ys, Ks, gammas,
        )  # fmt: skip
        if n:
            self._t = float(t[-1])
            self.x_prior, self.P_prior = x_priors[-1].copy(), P_priors[-1].copy()
            self.y, self.K = ys[-1].copy(), Ks[-1].copy()
        return HeadingTrack(
            t=t, x=xs, P=Ps, x_prior=x_priors, P_prior=P_priors, z=zs, y=ys, K=Ks, gamma=gammas
        )

    def filter(
        self, t: ArrayLike, heading_mag: ArrayLike, yaw_rates: ArrayLike | None = None
    ) -> HeadingTrack:
        """Filter the next samples of a walk: magnetometer headings and gyro yaw rates.

        The measurements are built here, causally: φ_mag unwrapped (module
        docstring) and dφ_mag/dt the backward difference quotient between
        consecutive valid magnetometer samples (not measured at the first
        one). The gyro's mean rate over step k is ½(r_{k−1} + r_k) (r₀ over
        the first step). Everything carries across calls.

        Args:
            t: (N,) sample times, s, increasing and after those of earlier calls.
            heading_mag: (N,) magnetometer headings in the frame of the state
                (:func:`mag_heading`), wrapped or not; NaN where there is no
                new magnetometer sample (e.g. where ``mag_fresh`` is 0).
            yaw_rates: (N,) gyro yaw rates r = ω·ĝ, rad/s
                (:func:`~indoorsim.estimators.frames.yaw_rate`), or ``None``.

        Returns:
            The per-step record.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        phi = np.asarray(heading_mag, dtype=float).reshape(-1)
        if len(phi) != len(t):
            raise ValueError(f"{len(t)} times but {len(phi)} magnetometer headings")
        zs = np.full((len(t), 2), np.nan)
        ok = np.flatnonzero(np.isfinite(phi))
        if len(ok):
            if self._mag is None:
                # The first measurement of a walk: the 2π branch nearest the state.
                t_last, phi_last = np.nan, float(self.x[0] + wrap_angle(phi[ok[0]] - self.x[0]))
            else:
                t_last, phi_last = self._mag
            unwrapped = np.unwrap(np.r_[phi_last, phi[ok]])
            t_ok = np.r_[t_last, t[ok]]
            zs[ok, 0] = unwrapped[1:]
            zs[ok, 1] = np.diff(unwrapped) / np.diff(t_ok)
            self._mag = (float(t_ok[-1]), float(unwrapped[-1]))
        omegas = None
        if yaw_rates is not None:
            r = np.asarray(yaw_rates, dtype=float).reshape(-1)
            if len(r) != len(t):
                raise ValueError(f"{len(t)} times but {len(r)} yaw rates")
            prev = r[:1] if self._rate is None else np.array([self._rate])
            r_all = np.r_[prev, r]
            omegas = 0.5 * (r_all[:-1] + r_all[1:])
            if len(r):
                self._rate = float(r[-1])
        return self.batch_filter(t, zs, omegas)


@dataclass(kw_only=True)
class HeadingBKF(HeadingKF):
    """Han2023's biased Kalman filter (Eq. 10–15): a KF whose posterior is shrunk after each update.

    After the KF update (:class:`HeadingKF`), with x the state relative to
    the origin, x_o = x − [φ_origin, 0]ᵀ,

        γ = ‖x_o‖² / (Tr P + ‖x_o‖²)                                      (Eq. 14)
        x ← [φ_origin, 0]ᵀ + γ x_o                                        (Eq. 10)
        P ← γ² P                                                          (Eq. 12, 15)

    and the shrunk pair is the posterior the next step starts from (Eq. 15).
    γ minimises the mean squared error γ² Tr P + (γ − 1)²‖x‖² of γ x̂
    (Eq. 13) — but only if ‖x‖² were the true state's norm; the filter
    plugs in its own estimate.

    Implemented literally, on the unwrapped heading. Note what that means:
    the shrinkage pulls the heading toward φ = 0, and how hard depends on
    where 0 is. A heading near 0 (walking along the frame's +x axis) with
    ‖x‖² comparable to Tr P collapses toward 0, and P with it (γ² ≪ 1), so
    the next updates barely move it; a heading near ±π, or a walk that has
    turned a full circle, is barely touched (γ ≈ 1 − Tr P/‖x‖²). Gyro rates
    (:class:`HeadingKF`) limit the damage: the shrunk rate is replaced at
    the next step. The result is not invariant to the choice of frame, and
    the norm adds rad² to (rad/s)², as the text does. ``origin`` moves the
    point of shrinkage: 0 (default) is the literal filter; the start heading,
    say, shrinks toward it instead. At exactly x_o = 0 the formula's
    γ = 0/Tr P = 0 would zero P; γ = 1 is used there.

    Attributes:
        origin: φ_origin, rad, in the frame of the state.
    """

    origin: float = 0.0

    def _bias(self) -> tuple[bool, float]:
        return True, self.origin
