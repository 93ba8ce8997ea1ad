"""Vectorised unit-quaternion helpers, scalar first (w, x, y, z).

scipy's :class:`~scipy.spatial.transform.Rotation` is the reference for
rotations in indoorsim; these few operations exist because its per-rotation
overhead (~0.4 µs for a product) dominates when a ten-minute walk is sampled
at 200 Hz. Each function works on stacks (..., 4) and agrees with scipy to
rounding (tested). The arithmetic per quaternion lives in
:mod:`indoorsim.util.kernels`; this module makes the passes over stacks.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.util.kernels import hamilton, normalised, quat_norm, rotate_vector


def multiply(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Hamilton product a ⊗ b (compose rotations: apply b, then a).

    The two stacks (…, 4) broadcast against each other; a single quaternion
    is applied to every row of the other stack without being repeated in
    memory. One compiled pass of :func:`~indoorsim.util.kernels.hamilton`.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape[-1:] != (4,) or b.shape[-1:] != (4,):
        raise ValueError(f"multiply: expected quaternions (..., 4), got {a.shape} and {b.shape}")
    shape = np.broadcast_shapes(a.shape[:-1], b.shape[:-1])
    out = np.empty((math.prod(shape), 4))
    _multiply_kernel(_rows(a, shape), _rows(b, shape), out)
    return out.reshape(*shape, 4)


def _rows(q: NDArray[np.float64], shape: tuple[int, ...]) -> NDArray[np.float64]:
    """The quaternions q as contiguous rows (K, 4) of the broadcast ``shape``, or one row."""
    if q.size == 4:
        return np.ascontiguousarray(q).reshape(1, 4)
    return np.ascontiguousarray(np.broadcast_to(q, (*shape, 4))).reshape(-1, 4)


@numba.njit(cache=True, error_model="numpy")
def _multiply_kernel(a, b, out):  # pragma: no cover - compiled
    """out[k] = a[k] ⊗ b[k], where a or b may hold a single quaternion for all k."""
    sa, sb = a.shape[0] > 1, b.shape[0] > 1
    for k in range(out.shape[0]):
        i, j = k if sa else 0, k if sb else 0
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = hamilton(
            a[i, 0], a[i, 1], a[i, 2], a[i, 3], b[j, 0], b[j, 1], b[j, 2], b[j, 3]
        )


def conjugate(q: ArrayLike) -> NDArray[np.float64]:
    """The inverse rotation of a unit quaternion."""
    out = np.array(q, dtype=float)
    out[..., 1:] *= -1
    return out


def twist_yaw(q: ArrayLike) -> NDArray[np.float64]:
    """Yaw of world←phone quaternions (..., 4) as their twist about the world's vertical,
    2·atan2(q_z, q_w): a turn by α about the vertical, Rz(α) ⊗ q, adds exactly α
    (its (w, z) pair turns by α/2), whatever the phone's tilt."""
    q = np.asarray(q, dtype=float)
    return 2.0 * np.arctan2(q[..., 3], q[..., 0])


def normalise(q: ArrayLike, *, min_norm: float = 0.0) -> NDArray[np.float64]:
    """Quaternions q (…, 4) divided by their norms; those of norm ≤ ``min_norm``, or NaN, become
    the identity (a logged or held quaternion drifts from unit norm; a missing one is zero).

    One compiled pass of :func:`~indoorsim.util.kernels.normalised`: the same
    bits as ``q / np.linalg.norm(q, axis=-1, keepdims=True)`` where the norm
    is above ``min_norm``.
    """
    q = np.asarray(q, dtype=float)
    if q.shape[-1:] != (4,):
        raise ValueError(f"normalise: expected quaternions (..., 4), got {q.shape}")
    rows = np.ascontiguousarray(q).reshape(-1, 4)
    out = np.empty_like(rows)
    _normalise_kernel(rows, min_norm, out)
    return out.reshape(q.shape)


@numba.njit(cache=True, error_model="numpy")
def _normalise_kernel(q, min_norm, out):  # pragma: no cover - compiled
    """out[k] = q[k] / ‖q[k]‖, or the identity where ‖q[k]‖ is not above ``min_norm``."""
    for k in range(q.shape[0]):
        w, x, y, z = q[k, 0], q[k, 1], q[k, 2], q[k, 3]
        if quat_norm(w, x, y, z) > min_norm:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = normalised(w, x, y, z)
        else:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = 1.0, 0.0, 0.0, 0.0


def rotate(q: ArrayLike, v: ArrayLike, *, inverse: bool = False) -> NDArray[np.float64]:
    """Apply the rotation q (…, 4), or its inverse, to vectors v (…, 3): q ⊗ (0, v) ⊗ q*.

    The two stacks broadcast against each other. One compiled pass of
    :func:`~indoorsim.util.kernels.rotate_vector`: a walk rotates 10⁵ vectors
    at a time, where numpy's form would make a dozen temporaries.
    """
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    shape = np.broadcast_shapes(q.shape[:-1], v.shape[:-1])
    qs = np.ascontiguousarray(np.broadcast_to(q, (*shape, 4))).reshape(-1, 4)
    vs = np.ascontiguousarray(np.broadcast_to(v, (*shape, 3))).reshape(-1, 3)
    out = np.empty((len(qs), 3))
    _rotate_kernel(qs, vs, -1.0 if inverse else 1.0, out)
    return out.reshape(*shape, 3)


@numba.njit(cache=True, error_model="numpy")
def _rotate_kernel(q, v, sign, out):  # pragma: no cover - compiled
    """out = q ⊗ (0, v) ⊗ q* with the vector part of q times ``sign`` (−1: the inverse)."""
    for k in range(q.shape[0]):
        out[k, 0], out[k, 1], out[k, 2] = rotate_vector(
            q[k, 0], sign * q[k, 1], sign * q[k, 2], sign * q[k, 3], v[k, 0], v[k, 1], v[k, 2]
        )


def relative_rotvec(q0: ArrayLike, q1: ArrayLike) -> NDArray[np.float64]:
    """Rotation vector of q0* ⊗ q1: the body-frame rotation carrying q0 to q1.

    The numpy form of :func:`~indoorsim.util.kernels.rotvec_from_quat`, which
    the simulator's compiled passes use: the same formula, but numpy's
    ``arctan2`` need not round as ``math.atan2`` does, so the two may differ
    in the last bit.
    """
    rel = multiply(conjugate(q0), q1)
    rel *= np.where(rel[..., :1] < 0, -1.0, 1.0)  # the short way round
    v = rel[..., 1:]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, rel[..., :1])
    # angle / s → 2 as s → 0 (small-angle limit), avoiding 0/0.
    scale = np.where(s > 1e-12, angle / np.where(s > 1e-12, s, 1.0), 2.0)
    return v * scale


def slerp(
    t_knots: ArrayLike,
    q: ArrayLike,
    t: ArrayLike,
    *,
    below: ArrayLike | None = None,
    out: NDArray[np.floating] | None = None,
) -> NDArray[np.floating]:
    """Spherical-linear interpolation of sign-continuous samples q (K, 4) at times t.

    Times outside the knots extrapolate along the first or last interval.

    The ideal IMU (:class:`~indoorsim.phone.kinematics.IdealImu`) has its own
    compiled slerp, which agrees with this one to ~1e-15 but not bit for bit:
    it takes ``math.acos`` and ``math.sin`` per sample where this takes
    numpy's over whole arrays, and sums the knots' dot product left to right
    where this sums it as numpy's einsum does. Each keeps its own so that
    neither's outputs move.

    Args:
        t_knots: (K,) sorted sample times, K ≥ 2.
        q: (K, 4) unit quaternions, scalar first, without sign jumps.
        t: (N,) query times.
        below: optional (N,) index of the latest knot at or before each time
            (``searchsorted(t_knots, t, side="right") - 1``, e.g.
            :func:`~indoorsim.windows.hold_index`), when the caller has it.
        out: optional (N, 4) array to write into; float32 holds the float64
            result rounded.

    Returns:
        (N, 4) unit quaternions (``out`` if given).
    """
    # Any memory layout will do (the truth stream's columns come column-major).
    tk = np.asarray(t_knots, dtype=float)
    qk = np.asarray(q, dtype=float)
    tq = np.asarray(t, dtype=float)
    n = len(tq)
    # The compiled passes index without bounds checks: shapes are checked here.
    if tk.ndim != 1 or len(tk) < 2 or qk.shape != (len(tk), 4) or tq.ndim != 1:
        raise ValueError(
            "slerp: expected (K,) knot times with K ≥ 2, (K, 4) quaternions and (N,) "
            f"times, got {tk.shape}, {qk.shape} and {tq.shape}"
        )
    if below is None:
        below = np.searchsorted(tk, tq, side="right") - 1
    below = np.asarray(below, dtype=np.intp)
    if below.shape != (n,):
        raise ValueError(f"slerp: below must have shape ({n},), got {below.shape}")
    if out is not None and (out.shape != (n, 4) or out.dtype.kind != "f"):
        raise ValueError(
            f"slerp: out must be a float array of shape ({n}, 4), got {out.dtype} {out.shape}"
        )
    i, f, sign = np.empty(n, dtype=np.intp), np.empty(n), np.empty(n)
    angles = np.empty((3, n))  # rows: θ, (1 − f)θ, fθ; then their sines
    _slerp_setup(tk, qk, tq, below, i, f, sign, angles[0])
    # The transcendentals are numpy's own, on whole arrays between the two
    # compiled passes: the same results, bit for bit, as the numpy form.
    theta = np.arccos(angles[0], out=angles[0])
    np.multiply(np.subtract(1.0, f, out=angles[1]), theta, out=angles[1])
    np.multiply(f, theta, out=angles[2])
    sin, sin_a, sin_b = np.sin(angles, out=angles)
    if out is None:
        out = np.empty((n, 4))
    _slerp_blend(qk, i, f, sign, sin, sin_a, sin_b, out)
    return out


@numba.njit(cache=True, error_model="numpy")
def _slerp_setup(tk, qk, t, below, i, f, sign, cos):  # pragma: no cover - compiled
    """Per time: the interval i, its fraction f, the sign taking q[i + 1] the short way
    from q[i], and the cosine of the angle between them (clipped to [−1, 1])."""
    last = tk.shape[0] - 2
    for m in range(t.shape[0]):
        k = min(max(below[m], 0), last)
        i[m] = k
        f[m] = (t[m] - tk[k]) / (tk[k + 1] - tk[k])
        s = -1.0 if _dot(qk, k, 1.0) < 0.0 else 1.0
        sign[m] = s
        c = _dot(qk, k, s)
        cos[m] = -1.0 if c < -1.0 else (1.0 if c > 1.0 else c)


@numba.njit(cache=True, inline="always", error_model="numpy")
def _dot(qk, k, s):  # pragma: no cover - compiled
    """q[k] · (s q[k + 1]), summed as numpy's einsum sums four products: (0 + 2) + (1 + 3)."""
    p0 = qk[k, 0] * (qk[k + 1, 0] * s)
    p1 = qk[k, 1] * (qk[k + 1, 1] * s)
    p2 = qk[k, 2] * (qk[k + 1, 2] * s)
    p3 = qk[k, 3] * (qk[k + 1, 3] * s)
    return (p0 + p2) + (p1 + p3)


@numba.njit(cache=True, error_model="numpy")
def _slerp_blend(qk, i, f, sign, sin, sin_a, sin_b, out):  # pragma: no cover - compiled
    """out = (wa q[i] + wb s q[i + 1]) / its norm, with wa = sin((1 − f)θ) / sin θ and
    wb = sin(fθ) / sin θ, or the linear weights where sin θ < 1e-9 (nearly equal)."""
    for m in range(i.shape[0]):
        k, s = i[m], sign[m]
        if sin[m] < 1e-9:
            wa, wb = 1.0 - f[m], f[m]
        else:
            wa, wb = sin_a[m] / sin[m], sin_b[m] / sin[m]
        r0 = wa * qk[k, 0] + wb * (qk[k + 1, 0] * s)
        r1 = wa * qk[k, 1] + wb * (qk[k + 1, 1] * s)
        r2 = wa * qk[k, 2] + wb * (qk[k + 1, 2] * s)
        r3 = wa * qk[k, 3] + wb * (qk[k + 1, 3] * s)
        # normalised sums left to right, as numpy's norm along a row of four.
        out[m, 0], out[m, 1], out[m, 2], out[m, 3] = normalised(r0, r1, r2, r3)
