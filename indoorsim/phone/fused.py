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

import numba
import numpy as np
from numpy.typing import NDArray

_NOMINAL_GRAVITY = 9.81  # what the AOSP filter assumes, m/s²


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
    rot, game, bias, grav = _run(
        tg,
        g,
        ta,
        a,
        tm,
        m,
        np.asarray(accel[np.argmin(t_accel)], float),
        np.asarray(mag[np.argmin(t_mag)], float),
        p.gyro_var,
        p.gyro_bias_var,
        p.acc_stdev,
        p.mag_stdev,
        p.min_field_uT**2,
        p.max_field_uT**2,
        gravity_mps2,
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
# Quaternions are (w, x, y, z), world←body. R(q) maps body vectors to world.
# error_model="numpy" drops the per-division zero checks, which cost a fifth of
# the run: every divisor here is bounded away from zero, and the results are the same.


@numba.njit(cache=True, inline="always", error_model="numpy")
def _rotmat(q, r):  # pragma: no cover - compiled
    w, x, y, z = q[0], q[1], q[2], q[3]
    r[0, 0] = 1 - 2 * (y * y + z * z)
    r[0, 1] = 2 * (x * y - w * z)
    r[0, 2] = 2 * (x * z + w * y)
    r[1, 0] = 2 * (x * y + w * z)
    r[1, 1] = 1 - 2 * (x * x + z * z)
    r[1, 2] = 2 * (y * z - w * x)
    r[2, 0] = 2 * (x * z - w * y)
    r[2, 1] = 2 * (y * z + w * x)
    r[2, 2] = 1 - 2 * (x * x + y * y)


@numba.njit(cache=True, inline="always", error_model="numpy")
def _quat_mul_into(a, b, out):  # pragma: no cover - compiled
    w = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3]
    x = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2]
    y = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1]
    z = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]
    out[0], out[1], out[2], out[3] = w, x, y, z


@numba.njit(cache=True, inline="always", error_model="numpy")
def _normalise(q):  # pragma: no cover - compiled
    n = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    s = 1.0 / n if q[0] >= 0 else -1.0 / n  # keep w ≥ 0: a continuous output
    for i in range(4):
        q[i] *= s


@numba.njit(cache=True, inline="always", error_model="numpy")
def _skew(v, m):  # pragma: no cover - compiled
    m[0, 0], m[0, 1], m[0, 2] = 0.0, -v[2], v[1]
    m[1, 0], m[1, 1], m[1, 2] = v[2], 0.0, -v[0]
    m[2, 0], m[2, 1], m[2, 2] = -v[1], v[0], 0.0


@numba.njit(cache=True, error_model="numpy")
def _triad(acc, mag, q):  # pragma: no cover - compiled
    """Attitude world←body from body-frame 'up' (accel) and the magnetic field."""
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
    tr = r[0, 0] + r[1, 1] + r[2, 2]
    if tr > 0:
        s = np.sqrt(tr + 1.0) * 2
        q[0] = 0.25 * s
        q[1] = (r[2, 1] - r[1, 2]) / s
        q[2] = (r[0, 2] - r[2, 0]) / s
        q[3] = (r[1, 0] - r[0, 1]) / s
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = np.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2]) * 2
        q[0] = (r[2, 1] - r[1, 2]) / s
        q[1] = 0.25 * s
        q[2] = (r[0, 1] + r[1, 0]) / s
        q[3] = (r[0, 2] + r[2, 0]) / s
    elif r[1, 1] > r[2, 2]:
        s = np.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2]) * 2
        q[0] = (r[0, 2] - r[2, 0]) / s
        q[1] = (r[0, 1] + r[1, 0]) / s
        q[2] = 0.25 * s
        q[3] = (r[1, 2] + r[2, 1]) / s
    else:
        s = np.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1]) * 2
        q[0] = (r[1, 0] - r[0, 1]) / s
        q[1] = (r[0, 2] + r[2, 0]) / s
        q[2] = (r[1, 2] + r[2, 1]) / s
        q[3] = 0.25 * s
    _normalise(q)


@numba.njit(cache=True, inline="always", error_model="numpy")
def _predict(q, b, P, w_meas, dt, gyro_var, bias_var, ws):  # pragma: no cover - compiled
    """Propagate q and P over dt with the bias-corrected body rate.

    Transition Φ = [[Φ00, Φ01], [0, I]] in closed form (Trawny & Roumeliotis
    2005, eq. 187–202); process noise of white gyro noise plus a bias random walk.
    """
    we, dq, qn, wx, wx2, phi, tmp = ws[0], ws[1], ws[2], ws[3], ws[4], ws[5], ws[6]
    for i in range(3):
        we[i] = w_meas[i] - b[i]
    nw = np.sqrt(we[0] * we[0] + we[1] * we[1] + we[2] * we[2])
    if nw < 1e-9:
        nw = 1e-9
    th = nw * dt
    sh, ch = np.sin(0.5 * th), np.cos(0.5 * th)
    s = sh / nw
    dq[0], dq[1], dq[2], dq[3] = ch, we[0] * s, we[1] * s, we[2] * s
    _quat_mul_into(q, dq, qn)  # q ← q ⊗ δq(ω dt)
    for i in range(4):
        q[i] = qn[i]
    _normalise(q)
    _skew(we, wx)
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
    # Φ00 in phi[:3, :3], Φ01 in phi[:3, 3:]; the lower blocks are 0 and I.
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
    q00 = gyro_var * dt + bias_var * dt**3 / 3.0
    q01 = -0.5 * bias_var * dt * dt
    q11 = bias_var * dt
    for i in range(3):
        P[i, i] += q00
        P[i, 3 + i] += q01
        P[3 + i, i] += q01
        P[3 + i, 3 + i] += q11


@numba.njit(cache=True, inline="always", error_model="numpy")
def _update(q, b, P, rmat, z, ref_world, sigma, estimate_bias, ws):  # pragma: no cover - compiled
    """EKF update with a unit reference direction ``ref_world`` measured as ``z`` (body frame).

    h(q) = R(q)ᵀ r and h(q ⊗ δq) ≈ h + [h×] δθ, so H = [[h×], 0]. ``rmat`` is
    R(q), from the caller, which needs it too.
    """
    h, H, S, Si, K, HP, dq, qn, e = (
        ws[7],
        ws[8],
        ws[9],
        ws[10],
        ws[11],
        ws[12],
        ws[1],
        ws[2],
        ws[13],
    )
    for i in range(3):
        h[i] = rmat[0, i] * ref_world[0] + rmat[1, i] * ref_world[1] + rmat[2, i] * ref_world[2]
    _skew(h, H)
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
    det = (
        S[0, 0] * (S[1, 1] * S[2, 2] - S[1, 2] * S[2, 1])
        - S[0, 1] * (S[1, 0] * S[2, 2] - S[1, 2] * S[2, 0])
        + S[0, 2] * (S[1, 0] * S[2, 1] - S[1, 1] * S[2, 0])
    )
    inv_det = 1.0 / det
    Si[0, 0] = (S[1, 1] * S[2, 2] - S[1, 2] * S[2, 1]) * inv_det
    Si[0, 1] = (S[0, 2] * S[2, 1] - S[0, 1] * S[2, 2]) * inv_det
    Si[0, 2] = (S[0, 1] * S[1, 2] - S[0, 2] * S[1, 1]) * inv_det
    Si[1, 0] = (S[1, 2] * S[2, 0] - S[1, 0] * S[2, 2]) * inv_det
    Si[1, 1] = (S[0, 0] * S[2, 2] - S[0, 2] * S[2, 0]) * inv_det
    Si[1, 2] = (S[0, 2] * S[1, 0] - S[0, 0] * S[1, 2]) * inv_det
    Si[2, 0] = (S[1, 0] * S[2, 1] - S[1, 1] * S[2, 0]) * inv_det
    Si[2, 1] = (S[0, 1] * S[2, 0] - S[0, 0] * S[2, 1]) * inv_det
    Si[2, 2] = (S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]) * inv_det
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
    _quat_mul_into(q, dq, qn)
    for i in range(4):
        q[i] = qn[i]
    _normalise(q)
    if estimate_bias:
        for i in range(3):
            b[i] += K[3 + i, 0] * e[0] + K[3 + i, 1] * e[1] + K[3 + i, 2] * e[2]


@numba.njit(cache=True, error_model="numpy")
def _workspace():  # pragma: no cover - compiled
    return (
        np.empty(3),
        np.empty(4),
        np.empty(4),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((6, 6)),
        np.empty((6, 6)),
        np.empty(3),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((6, 3)),
        np.empty((3, 6)),
        np.empty(3),
    )


@numba.njit(cache=True, inline="always", error_model="numpy")
def _before(t_early, t_late):  # pragma: no cover - compiled
    """Whether a sample at ``t_early`` of an earlier stream in the tie order comes
    before one at ``t_late`` of a later stream: time order, NaN times last.

    When timestamps tie, gyro goes before accel before mag: the state is propagated
    to a time before the measurements taken at that time update it.
    """
    return t_early <= t_late or np.isnan(t_late)


@numba.njit(cache=True, error_model="numpy")
def _run(
    t_gyro,
    gyro,
    t_acc,
    acc,
    t_mag,
    mag,
    first_acc,
    first_mag,
    gyro_var,
    bias_var,
    acc_std,
    mag_std,
    min_b2,
    max_b2,
    g_out,
):  # pragma: no cover - compiled
    n_gyro, n_acc, n_mag = len(t_gyro), len(t_acc), len(t_mag)
    rot = np.empty((n_gyro, 4))
    game = np.empty((n_gyro, 4))
    bias = np.empty((n_gyro, 3))
    grav = np.empty((n_acc, 3))
    # Filter 0 (q0, b0, P0): 9-axis; filter 1 (q1, b1, P1): game rotation (no
    # magnetometer). Both start from the TRIAD attitude of the first
    # accelerometer and magnetometer samples. Separate arrays, not rows of one:
    # a view per event costs more than the arithmetic.
    q0 = np.zeros(4)
    _triad(first_acc, first_mag, q0)
    q1 = q0.copy()
    b0 = np.zeros(3)
    b1 = np.zeros(3)
    P0 = np.zeros((6, 6))
    P1 = np.zeros((6, 6))
    ws = _workspace()
    rmat = np.empty((3, 3))
    v = np.empty(3)
    zp = np.empty(3)
    up_w = np.array([0.0, 0.0, 1.0])
    north_w = np.array([0.0, 1.0, 0.0])
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
                _predict(q0, b0, P0, v, dt, gyro_var, bias_var, ws)
                _predict(q1, b1, P1, v, dt, gyro_var, bias_var, ws)
            last_gyro_t = t
            for j in range(4):
                rot[gi, j] = q0[j]
                game[gi, j] = q1[j]
            for j in range(3):
                bias[gi, j] = b0[j]
            gi += 1
        elif ai < n_acc and (mi == n_mag or _before(t_acc[ai], t_mag[mi])):
            for j in range(3):
                v[j] = acc[ai, j]
            na = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
            if na > 0.1 * _NOMINAL_GRAVITY:  # no gravity direction in free fall
                sigma = acc_std * np.exp(np.sqrt(abs(na - _NOMINAL_GRAVITY))) / na
                for j in range(3):
                    zp[j] = v[j] / na
                _rotmat(q0, rmat)
                _update(q0, b0, P0, rmat, zp, up_w, sigma, True, ws)
                _rotmat(q1, rmat)
                _update(q1, b1, P1, rmat, zp, up_w, sigma, False, ws)
                # Game rotation: hold yaw's covariance with a zero-innovation
                # north pseudo-measurement, as AOSP does without a magnetometer.
                _rotmat(q1, rmat)
                for j in range(3):
                    zp[j] = rmat[1, j]
                _update(q1, b1, P1, rmat, zp, north_w, mag_std, False, ws)
            _rotmat(q1, rmat)
            for j in range(3):
                grav[ai, j] = rmat[2, j] * g_out
            ai += 1
        else:  # magnetometer
            for j in range(3):
                v[j] = mag[mi, j]
            mi += 1
            b2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
            if min_b2 <= b2 <= max_b2:  # reject disturbed or degenerate fields
                _rotmat(q0, rmat)
                ux, uy, uz = rmat[2, 0], rmat[2, 1], rmat[2, 2]  # world up in the body frame
                # east = v × up, north = up × east (no temporaries in the event loop)
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
                    _update(q0, b0, P0, rmat, zp, north_w, mag_std / nn, True, ws)
    return rot, game, bias, grav
