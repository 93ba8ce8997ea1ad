"""Android-style fused (virtual) sensors computed from the simulated raw streams.

A phone does not measure its orientation: Android's sensor service estimates it
by fusing the gyroscope, accelerometer and magnetometer. indoorsim does the same
thing to the *simulated* raw streams, so the fused outputs carry exactly the
errors a phone's would — gyro noise and bias, accelerations mistaken for
gravity, indoor magnetic disturbances pulling the heading — never truth plus
noise.

The filter follows the design of AOSP's ``SensorFusion`` (frameworks/native,
``services/sensorservice/Fusion.cpp``): an indirect (multiplicative) extended
Kalman filter on the attitude quaternion and the gyro bias, after Trawny &
Roumeliotis, *Indirect Kalman Filter for 3D Attitude Estimation* (2005):

* state: q (world←phone) and gyro bias b; error state δθ (body-frame small
  rotation, q_true = q ⊗ δq(δθ)) and δb; covariance P as 2 × 2 blocks of 3 × 3;
* predict on each gyro sample with ω = ω_meas − b over the sample interval,
  with the closed-form transition Φ and the process noise of a gyro with white
  noise variance ``gyro_var`` ((rad/s)²/Hz) and bias random walk
  ``gyro_bias_var`` ((rad/s)²/s);
* update on each accelerometer sample with the measured direction of "up"
  (σ grows as exp(√| |a| − g |) when the phone accelerates, so walking
  accelerations are down-weighted; skipped near free fall);
* update on each magnetometer sample with magnetic north made orthogonal to the
  estimated up (samples with |B| outside 10–100 µT or B parallel to up are
  rejected, as on a phone);
* initial attitude from the first accelerometer and magnetometer samples
  (TRIAD), initial P = 0, as the AOSP filter does.

Two filters run side by side:

* ``rotation`` (Android ``TYPE_ROTATION_VECTOR``): 9-axis. Its world frame is
  Android's: x magnetic east, y magnetic north, z up;
* ``game_rotation`` (``TYPE_GAME_ROTATION_VECTOR``): no magnetometer (a
  pseudo-measurement holds yaw's covariance bounded, the bias is not
  estimated); its yaw origin is arbitrary and drifts with the gyro.

``gravity`` and ``linear_accel`` are reported at the accelerometer's samples
from the game-rotation attitude, unaffected by magnetic disturbances (as in
recent Android releases).

The event loop is sequential by nature (each sample updates the state), so it
is compiled with numba; each step works on preallocated scratch arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from indoorsim.util.kernels import (
    canonicalise,
    inverse3,
    quat_from_matrix,
    quat_mul_into,
    rotation_matrix,
    skew,
)

_NOMINAL_GRAVITY = 9.81  # what the AOSP filter assumes, m/s²
# The world's up and magnetic north (Android's rotation-vector frame: x east, y north, z up).
_UP_WORLD = np.array([0.0, 0.0, 1.0])
_NORTH_WORLD = np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True, kw_only=True)
class FusionParams:
    """Tuning of the attitude filter (defaults: the AOSP ``DEFAULT_*`` values).

    Attributes:
        gyro_var: gyro white-noise variance per Hz, (rad/s)²/Hz.
        gyro_bias_var: gyro bias random-walk variance, (rad/s)²/s.
        acc_stdev: accelerometer noise, m/s².
        mag_stdev: magnetometer noise, µT.
        min_field_uT: magnetometer samples weaker than this are rejected.
        max_field_uT: magnetometer samples stronger than this are rejected.
    """

    gyro_var: float = 1e-7
    gyro_bias_var: float = 1e-12
    acc_stdev: float = 0.015
    mag_stdev: float = 0.1
    min_field_uT: float = 10.0
    max_field_uT: float = 100.0


@dataclass(frozen=True, kw_only=True)
class FusedStreams:
    """Outputs of :func:`fuse`, each aligned with the raw samples it was computed on.

    Attributes:
        t_rotation: (G,) gyro timestamps, s.
        rotation: (G, 4) 9-axis attitude world←phone (w, x, y, z), magnetic-ENU world.
        game_rotation: (G, 4) gyro+accel attitude, arbitrary yaw origin.
        gyro_bias: (G, 3) the 9-axis filter's gyro bias estimate, rad/s.
        t_gravity: (A,) accelerometer timestamps, s.
        gravity: (A, 3) gravity in the phone frame, m/s².
        linear_accel: (A, 3) accelerometer minus gravity, m/s².
    """

    t_rotation: NDArray[np.float64]
    rotation: NDArray[np.float64]
    game_rotation: NDArray[np.float64]
    gyro_bias: NDArray[np.float64]
    t_gravity: NDArray[np.float64]
    gravity: NDArray[np.float64]
    linear_accel: NDArray[np.float64]


def fuse(
    t_accel: NDArray[np.float64],
    accel: NDArray[np.float64],
    t_gyro: NDArray[np.float64],
    gyro: NDArray[np.float64],
    t_mag: NDArray[np.float64],
    mag: NDArray[np.float64],
    params: FusionParams | None = None,
    gravity_mps2: float = 9.80665,
) -> FusedStreams:
    """Run the 9-axis and the game-rotation filters over raw phone streams.

    Args:
        t_accel, accel: (A,) s and (A, 3) m/s², specific force in the phone frame.
        t_gyro, gyro: (G,) s and (G, 3) rad/s.
        t_mag, mag: (M,) s and (M, 3) µT.
        params: filter tuning; the AOSP defaults when omitted.
        gravity_mps2: the gravity magnitude used for the gravity output.

    Returns:
        The fused streams. The filters start from the attitude given by the
        first accelerometer and magnetometer samples (a phone's fusion
        initialises within its first few samples the same way).
    """
    p = params or FusionParams()
    for name, arr in (("accel", accel), ("gyro", gyro), ("mag", mag)):
        if len(arr) == 0:
            raise ValueError(f"fuse: the {name} stream is empty; fused sensors need all three")
    # The compiled loop merges the three streams itself, in time order, so each
    # stream must be in time order: the simulator's are; others are stably
    # sorted here and their outputs mapped back below.
    streams = [
        _in_time_order(t_gyro, gyro),
        _in_time_order(t_accel, accel),
        _in_time_order(t_mag, mag),
    ]
    (tg, g, g_order), (ta, a, a_order), (tm, m, _) = streams
    tuning = _Tuning(
        gyro_var=float(p.gyro_var),
        bias_var=float(p.gyro_bias_var),
        acc_std=float(p.acc_stdev),
        mag_std=float(p.mag_stdev),
        min_b2=float(p.min_field_uT**2),
        max_b2=float(p.max_field_uT**2),
        gravity_mps2=float(gravity_mps2),
    )
    rot, game, bias, grav = _run(
        tg,
        g,
        ta,
        a,
        tm,
        m,
        np.asarray(accel[np.argmin(t_accel)], float),
        np.asarray(mag[np.argmin(t_mag)], float),
        tuning,
    )
    if g_order is not None:
        rot, game, bias = (_unsort(x, g_order) for x in (rot, game, bias))
    if a_order is not None:
        grav = _unsort(grav, a_order)
    return FusedStreams(
        t_rotation=np.asarray(t_gyro, float),
        rotation=rot,
        game_rotation=game,
        gyro_bias=bias,
        t_gravity=np.asarray(t_accel, float),
        gravity=grav,
        linear_accel=np.asarray(accel, float) - grav,
    )


def _in_time_order(
    t: NDArray, x: NDArray
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp] | None]:
    """``t`` and ``x`` as contiguous float arrays in time order, and the order that
    sorted them (None when they already were: the usual case, and no copy)."""
    t = np.ascontiguousarray(t, dtype=np.float64)
    x = np.ascontiguousarray(x, dtype=np.float64)
    if np.all(t[1:] >= t[:-1]):  # False with any NaN: those are sorted (last) below
        return t, x, None
    order = np.argsort(t, kind="stable")
    return t[order], np.ascontiguousarray(x[order]), order


def _unsort(y: NDArray[np.float64], order: NDArray[np.intp]) -> NDArray[np.float64]:
    """Rows of ``y``, computed in the order ``order``, put back in the input order."""
    out = np.empty_like(y)
    out[order] = y
    return out


# ----------------------------------------------------------------- compiled core
# Quaternions are (w, x, y, z), world←body; R(q) maps body vectors to the world
# (indoorsim.util.kernels). error_model="numpy" drops the per-division zero
# checks, which cost a fifth of the run: every divisor here is bounded away from
# zero, and the results are the same.


class _Tuning(NamedTuple):
    """:class:`FusionParams` as the compiled loop takes them.

    Attributes:
        gyro_var: gyro white-noise variance per Hz, (rad/s)²/Hz.
        bias_var: gyro bias random-walk variance, (rad/s)²/s.
        acc_std: accelerometer noise σ_a, m/s².
        mag_std: magnetometer noise σ_m, µT.
        min_b2: squared weakest accepted field, µT².
        max_b2: squared strongest accepted field, µT².
        gravity_mps2: the gravity magnitude of the gravity output, m/s².
    """

    gyro_var: float
    bias_var: float
    acc_std: float
    mag_std: float
    min_b2: float
    max_b2: float
    gravity_mps2: float


class _Filter(NamedTuple):
    """The state of one attitude filter. Separate arrays, not rows of one: a
    view per event costs more than the arithmetic.

    Attributes:
        q: (4,) attitude world←phone.
        b: (3,) gyro bias b, rad/s.
        P: (6, 6) covariance of the error state [δθ, δb] (δθ a body-frame
            small rotation, q_true = q ⊗ δq(δθ)), as 2 × 2 blocks of 3 × 3.
    """

    q: NDArray[np.float64]
    b: NDArray[np.float64]
    P: NDArray[np.float64]


class _Scratch(NamedTuple):
    """Scratch arrays of :func:`_predict` and :func:`_update`, allocated once per run.

    Attributes:
        w: (3,) bias-corrected body rate ω = ω_meas − b.
        dq: (4,) the increment δq(ω Δt) of a prediction, the correction
            (1, ½δθ) of an update.
        wx: (3, 3) [ω×].
        wx2: (3, 3) [ω×]².
        phi: (3, 6) the upper block row [Φ00 Φ01] of the transition Φ (the
            lower one is [0 I]).
        phi_p: (3, 6) the upper block row of Φ P.
        h: (3,) the predicted measurement h = R(q)ᵀ r.
        H: (3, 3) [h×], the attitude block of the Jacobian [[h×] 0].
        S: (3, 3) the innovation covariance.
        S_inv: (3, 3) its inverse.
        K: (6, 3) the Kalman gain.
        HP: (3, 6) H P.
        e: (3,) the innovation z − h.
    """

    w: NDArray[np.float64]
    dq: NDArray[np.float64]
    wx: NDArray[np.float64]
    wx2: NDArray[np.float64]
    phi: NDArray[np.float64]
    phi_p: NDArray[np.float64]
    h: NDArray[np.float64]
    H: NDArray[np.float64]
    S: NDArray[np.float64]
    S_inv: NDArray[np.float64]
    K: NDArray[np.float64]
    HP: NDArray[np.float64]
    e: NDArray[np.float64]


@numba.njit(cache=True, error_model="numpy")
def _scratch():  # pragma: no cover - compiled
    """A fresh :class:`_Scratch`."""
    return _Scratch(
        np.empty(3),
        np.empty(4),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((3, 6)),
        np.empty((3, 6)),
        np.empty(3),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((6, 3)),
        np.empty((3, 6)),
        np.empty(3),
    )


@numba.njit(cache=True, error_model="numpy")
def _triad(acc, mag, q):  # pragma: no cover - compiled
    """q = the attitude world←body from body-frame 'up' (accel) and the magnetic field (TRIAD).

    up = a/|a|, east = (m × up)/|m × up|, north = up × east are the rows of
    R(q); q is R's quaternion (:func:`~indoorsim.util.kernels.quat_from_matrix`),
    normalised with w ≥ 0.
    """
    up = acc / np.sqrt(np.sum(acc * acc))
    east = np.cross(mag, up)
    n = np.sqrt(np.sum(east * east))
    if n < 1e-9:  # field parallel to gravity: any east will do
        east = np.cross(
            np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0]), up
        )
        n = np.sqrt(np.sum(east * east))
    east = east / n
    north = np.cross(up, east)
    # The rows of R (world←body) are the world axes seen in the body frame.
    r = np.empty((3, 3))
    for i in range(3):
        r[0, i], r[1, i], r[2, i] = east[i], north[i], up[i]
    quat_from_matrix(r, q)
    canonicalise(q)


@numba.njit(cache=True, inline="always", error_model="numpy")
def _predict(f, w_meas, dt, tuning, ws):  # pragma: no cover - compiled
    """Propagate the filter ``f`` over dt with the bias-corrected body rate ω = ω_meas − b.

    Trawny & Roumeliotis (2005), eq. 187–202, with θ = |ω| Δt:

        q ← q ⊗ δq,  δq = (cos ½θ, sin(½θ) ω/|ω|), then normalised (w ≥ 0)
        Φ = [[Φ00, Φ01], [0, I]],
        Φ00 = I − [ω×] sin θ/|ω| + [ω×]² (1 − cos θ)/|ω|²,
        Φ01 = [ω×] (1 − cos θ)/|ω|² − I Δt − [ω×]² (θ − sin θ)/|ω|³,
        P ← Φ P Φᵀ + Q_d,
        Q_d = [[(σ_g² Δt + σ_b² Δt³/3) I, −½σ_b² Δt² I], [−½σ_b² Δt² I, σ_b² Δt I]],

    σ_g² = ``tuning.gyro_var`` (white gyro noise), σ_b² = ``tuning.bias_var``
    (bias random walk). |ω| is held at 1e-9 at least. (δq is formed from ω and
    the half angle, which ``sin θ`` and ``cos θ`` reuse, not from the rotation
    vector ωΔt as :func:`~indoorsim.util.kernels.quat_from_rotvec` forms it:
    the two do not round alike.)
    """
    q, b, P = f.q, f.b, f.P
    we, dq, wx, wx2, phi, tmp = ws.w, ws.dq, ws.wx, ws.wx2, ws.phi, ws.phi_p
    for i in range(3):
        we[i] = w_meas[i] - b[i]
    nw = np.sqrt(we[0] * we[0] + we[1] * we[1] + we[2] * we[2])
    if nw < 1e-9:
        nw = 1e-9
    th = nw * dt
    sh, ch = np.sin(0.5 * th), np.cos(0.5 * th)
    s = sh / nw
    dq[0], dq[1], dq[2], dq[3] = ch, we[0] * s, we[1] * s, we[2] * s
    quat_mul_into(q, dq, q)  # q ← q ⊗ δq(ω dt)
    canonicalise(q)
    skew(we, wx)
    # wx2 = wx @ wx. The products with wx's zero diagonal are left out: each is
    # ±0 added to a sum that starts at +0, which never changes the sum's bits
    # (for finite rates), so this is exactly the full product, at 12 of 27 products.
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for r in range(3):
                if r != i and r != j:
                    acc += wx[i, r] * wx[r, j]
            wx2[i, j] = acc
    k_sin, k_cos = 2.0 * sh * ch, 1.0 - 2.0 * sh * sh  # sin θ, cos θ from the half angle
    c1, c2 = k_sin / nw, (1 - k_cos) / (nw * nw)
    c3 = (th - k_sin) / (nw * nw * nw)
    # Φ00 in phi[:, :3], Φ01 in phi[:, 3:].
    for i in range(3):
        for j in range(3):
            eye = 1.0 if i == j else 0.0
            phi[i, j] = eye - wx[i, j] * c1 + wx2[i, j] * c2
            phi[i, 3 + j] = wx[i, j] * c2 - eye * dt - wx2[i, j] * c3
    # P ← Φ P Φᵀ by blocks, skipping the zero and identity blocks of Φ:
    # A = Φ00 P00 + Φ01 P10, B = Φ00 P01 + Φ01 P11 (= the new P01),
    # P00 ← A Φ00ᵀ + B Φ01ᵀ; P11 is unchanged.
    for i in range(3):
        for j in range(3):
            a_ij = 0.0
            b_ij = 0.0
            for r in range(3):
                a_ij += phi[i, r] * P[r, j] + phi[i, 3 + r] * P[3 + r, j]
                b_ij += phi[i, r] * P[r, 3 + j] + phi[i, 3 + r] * P[3 + r, 3 + j]
            tmp[i, j] = a_ij
            tmp[i, 3 + j] = b_ij
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for r in range(3):
                acc += tmp[i, r] * phi[j, r] + tmp[i, 3 + r] * phi[j, 3 + r]
            P[i, j] = acc
        for j in range(3):
            P[i, 3 + j] = tmp[i, 3 + j]
            P[3 + j, i] = tmp[i, 3 + j]
    bias_var = tuning.bias_var
    q00 = tuning.gyro_var * dt + bias_var * dt**3 / 3.0
    q01 = -0.5 * bias_var * dt * dt
    q11 = bias_var * dt
    for i in range(3):
        P[i, i] += q00
        P[i, 3 + i] += q01
        P[3 + i, i] += q01
        P[3 + i, 3 + i] += q11


@numba.njit(cache=True, inline="always", error_model="numpy")
def _update(f, rmat, z, ref_world, sigma, estimate_bias, ws):  # pragma: no cover - compiled
    """EKF update of ``f``: the unit world direction ``ref_world`` measured as ``z`` in the body.

    With h(q) = R(q)ᵀ r and h(q ⊗ δq) ≈ h + [h×] δθ, H = [[h×], 0] and R = σ² I:

        S = H P Hᵀ + σ² I,   K = P Hᵀ S⁻¹,   e = z − h,
        P ← (I − K H) P,     δθ = K_θ e,   q ← q ⊗ (1, ½δθ), normalised (w ≥ 0),
        b ← b + K_b e  (only if ``estimate_bias``).

    ``rmat`` is R(q), from the caller, which needs it too.
    """
    q, b, P = f.q, f.b, f.P
    h, H, S, Si, K, HP, dq, e = ws.h, ws.H, ws.S, ws.S_inv, ws.K, ws.HP, ws.dq, ws.e
    for i in range(3):
        h[i] = rmat[0, i] * ref_world[0] + rmat[1, i] * ref_world[1] + rmat[2, i] * ref_world[2]
    skew(h, H)
    # HP = H P[:3, :] (3 × 6); S = H P00 Hᵀ + σ² I. As in _predict, the products
    # with H's zero diagonal are left out: exactly the same sums.
    for i in range(3):
        for j in range(6):
            acc = 0.0
            for r in range(3):
                if r != i:
                    acc += H[i, r] * P[r, j]
            HP[i, j] = acc
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for r in range(3):
                if r != j:
                    acc += HP[i, r] * H[j, r]
            S[i, j] = acc + (sigma * sigma if i == j else 0.0)
    inverse3(S, Si)
    # K = P Hᵀ S⁻¹ = (H P)ᵀ S⁻¹ since P is symmetric: (6 × 3).
    for i in range(6):
        for j in range(3):
            acc = 0.0
            for r in range(3):
                acc += HP[r, i] * Si[r, j]
            K[i, j] = acc
    for i in range(3):
        e[i] = z[i] - h[i]
    # P ← (I − K H) P = P − K (H P) = P − (HP)ᵀ S⁻¹ (HP), symmetric: the upper
    # triangle is computed and mirrored, which also keeps P symmetric exactly.
    for i in range(6):
        for j in range(i, 6):
            acc = K[i, 0] * HP[0, j] + K[i, 1] * HP[1, j] + K[i, 2] * HP[2, j]
            P[i, j] -= acc
            P[j, i] = P[i, j]
    dq[0] = 1.0
    for i in range(3):
        dq[1 + i] = 0.5 * (K[i, 0] * e[0] + K[i, 1] * e[1] + K[i, 2] * e[2])
    quat_mul_into(q, dq, q)
    canonicalise(q)
    if estimate_bias:
        for i in range(3):
            b[i] += K[3 + i, 0] * e[0] + K[3 + i, 1] * e[1] + K[3 + i, 2] * e[2]


@numba.njit(cache=True, inline="always", error_model="numpy")
def _before(t_early, t_late):  # pragma: no cover - compiled
    """Whether a sample at ``t_early`` of an earlier stream in the tie order comes
    before one at ``t_late`` of a later stream: time order, NaN times last.

    When timestamps tie, gyro goes before accel before mag: the state is propagated
    to a time before the measurements taken at that time update it.
    """
    return t_early <= t_late or np.isnan(t_late)


@numba.njit(cache=True, error_model="numpy")
def _run(t_gyro, gyro, t_acc, acc, t_mag, mag, first_acc, first_mag, tuning):  # pragma: no cover
    """Both filters over the three time-ordered streams, merged into one sequence of events.

    The 9-axis filter (rotation vector) and the game-rotation filter start
    from the TRIAD attitude of ``first_acc`` and ``first_mag`` (:func:`_triad`)
    with b = 0 and P = 0, as the AOSP filter does. Then per event, in time
    order (ties: gyro, accel, mag; :func:`_before`):

    * **gyro** ω at t: both filters predict over Δt since the previous gyro
      sample (:func:`_predict`; the first one, or a repeated time, only sets
      the clock). Outputs at t: both attitudes and the 9-axis bias.
    * **accelerometer** a: unless |a| ≤ 0.1 g (free fall: no direction), both
      filters update with the measured up (:func:`_update`), z = a/|a|
      against r = ẑ, with σ = σ_a·exp(√| |a| − g |)/|a| so that accelerations
      weigh less; the game filter then with a zero-innovation north
      pseudo-measurement, z = R(q)ᵀ ŷ, σ = σ_m, which holds its yaw covariance
      as AOSP does without a magnetometer. Output at t: gravity
      g·R(q_game)ᵀ ẑ.
    * **magnetometer** m: if B_min² ≤ |m|² ≤ B_max² and |m × u|² ≥ 1e-6, u =
      R(q)ᵀ ẑ the estimated up, the 9-axis filter updates with magnetic north
      made orthogonal to up, z = n/|n| with n = u × (m × u), against r = ŷ,
      σ = σ_m/|n|. The game filter never sees the magnetometer.

    The events are written out here rather than in helpers: a helper taking
    the filters' and scratch arrays adds reference counting to every event
    (5 % of the run inlined, 20 % called).

    Args:
        t_gyro, gyro: (G,) s and (G, 3) rad/s.
        t_acc, acc: (A,) s and (A, 3) m/s².
        t_mag, mag: (M,) s and (M, 3) µT.
        first_acc, first_mag: (3,) the samples that initialise the attitude.
        tuning: the filter constants.

    Returns:
        rotation (G, 4), game rotation (G, 4) and gyro bias (G, 3) at the gyro
        samples; gravity (A, 3) at the accelerometer samples.
    """
    n_gyro, n_acc, n_mag = len(t_gyro), len(t_acc), len(t_mag)
    rot = np.empty((n_gyro, 4))
    game_rot = np.empty((n_gyro, 4))
    bias = np.empty((n_gyro, 3))
    grav = np.empty((n_acc, 3))
    q0 = np.zeros(4)
    _triad(first_acc, first_mag, q0)
    nine = _Filter(q0, np.zeros(3), np.zeros((6, 6)))
    game = _Filter(q0.copy(), np.zeros(3), np.zeros((6, 6)))
    ws = _scratch()
    q_nine, q_game, b_nine = nine.q, game.q, nine.b
    rmat = np.empty((3, 3))
    v = np.empty(3)
    zp = np.empty(3)
    last_gyro_t = np.nan
    gi, ai, mi = 0, 0, 0
    while gi < n_gyro or ai < n_acc or mi < n_mag:
        # The next sample of the three time-ordered streams.
        if (
            gi < n_gyro
            and (ai == n_acc or _before(t_gyro[gi], t_acc[ai]))
            and (mi == n_mag or _before(t_gyro[gi], t_mag[mi]))
        ):
            for j in range(3):
                v[j] = gyro[gi, j]
            t = t_gyro[gi]
            if not np.isnan(last_gyro_t) and t > last_gyro_t:
                dt = t - last_gyro_t
                _predict(nine, v, dt, tuning, ws)
                _predict(game, v, dt, tuning, ws)
            last_gyro_t = t
            for j in range(4):
                rot[gi, j] = q_nine[j]
                game_rot[gi, j] = q_game[j]
            for j in range(3):
                bias[gi, j] = b_nine[j]
            gi += 1
        elif ai < n_acc and (mi == n_mag or _before(t_acc[ai], t_mag[mi])):
            for j in range(3):
                v[j] = acc[ai, j]
            na = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
            if na > 0.1 * _NOMINAL_GRAVITY:  # no gravity direction in free fall
                sigma = tuning.acc_std * np.exp(np.sqrt(abs(na - _NOMINAL_GRAVITY))) / na
                for j in range(3):
                    zp[j] = v[j] / na
                rotation_matrix(q_nine, rmat)
                _update(nine, rmat, zp, _UP_WORLD, sigma, True, ws)
                rotation_matrix(q_game, rmat)
                _update(game, rmat, zp, _UP_WORLD, sigma, False, ws)
                # Game rotation: hold yaw's covariance with a zero-innovation
                # north pseudo-measurement.
                rotation_matrix(q_game, rmat)
                for j in range(3):
                    zp[j] = rmat[1, j]
                _update(game, rmat, zp, _NORTH_WORLD, tuning.mag_std, False, ws)
            # Gravity from the game rotation, free of magnetic disturbances.
            rotation_matrix(q_game, rmat)
            for j in range(3):
                grav[ai, j] = rmat[2, j] * tuning.gravity_mps2
            ai += 1
        else:  # magnetometer
            for j in range(3):
                v[j] = mag[mi, j]
            b2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
            if tuning.min_b2 <= b2 <= tuning.max_b2:  # reject disturbed or degenerate fields
                rotation_matrix(q_nine, rmat)
                ux, uy, uz = rmat[2, 0], rmat[2, 1], rmat[2, 2]  # world up in the body frame
                # east = m × up, north = up × east (no temporaries in the event loop)
                ex = v[1] * uz - v[2] * uy
                ey = v[2] * ux - v[0] * uz
                ez = v[0] * uy - v[1] * ux
                if ex * ex + ey * ey + ez * ez >= 1e-6:
                    zp[0] = uy * ez - uz * ey
                    zp[1] = uz * ex - ux * ez
                    zp[2] = ux * ey - uy * ex
                    nn = np.sqrt(zp[0] * zp[0] + zp[1] * zp[1] + zp[2] * zp[2])
                    for j in range(3):
                        zp[j] /= nn
                    _update(nine, rmat, zp, _NORTH_WORLD, tuning.mag_std / nn, True, ws)
            mi += 1
    return rot, game_rot, bias, grav
