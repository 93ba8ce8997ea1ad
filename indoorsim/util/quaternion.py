"""Vectorised unit-quaternion helpers, scalar first (w, x, y, z).

scipy's :class:`~scipy.spatial.transform.Rotation` is the reference for
rotations in indoorsim; these few operations exist because its per-rotation
overhead (~0.4 µs for a product) dominates when a ten-minute walk is sampled
at 200 Hz. Each function works on stacks (..., 4) and agrees with scipy to
rounding (tested).
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray


def multiply(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Hamilton product a ⊗ b (compose rotations: apply b, then a)."""
    w1, x1, y1, z1 = np.moveaxis(np.asarray(a, dtype=float), -1, 0)
    w2, x2, y2, z2 = np.moveaxis(np.asarray(b, dtype=float), -1, 0)
    return np.stack(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ],
        axis=-1,
    )


def conjugate(q: ArrayLike) -> NDArray[np.float64]:
    """The inverse rotation of a unit quaternion."""
    out = np.array(q, dtype=float)
    out[..., 1:] *= -1
    return out


def rotate(q: ArrayLike, v: ArrayLike, *, inverse: bool = False) -> NDArray[np.float64]:
    """Apply the rotation q (…, 4), or its inverse, to vectors v (…, 3): q ⊗ (0, v) ⊗ q*.

    The two stacks broadcast against each other. Computed as v + w·t + u × t
    with t = 2 u × v (u the vector part of q, w its scalar), in one compiled
    pass: a walk rotates 10⁵ vectors at a time, where numpy's form would make
    a dozen temporaries.
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
        w, x, y, z = q[k, 0], sign * q[k, 1], sign * q[k, 2], sign * q[k, 3]
        vx, vy, vz = v[k, 0], v[k, 1], v[k, 2]
        tx = 2.0 * (y * vz - z * vy)
        ty = 2.0 * (z * vx - x * vz)
        tz = 2.0 * (x * vy - y * vx)
        out[k, 0] = vx + w * tx + (y * tz - z * ty)
        out[k, 1] = vy + w * ty + (z * tx - x * tz)
        out[k, 2] = vz + w * tz + (x * ty - y * tx)


def relative_rotvec(q0: ArrayLike, q1: ArrayLike) -> NDArray[np.float64]:
    """Rotation vector of q0* ⊗ q1: the body-frame rotation carrying q0 to q1."""
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
        # Summed left to right, as numpy's norm along a row of four.
        norm = np.sqrt(((r0 * r0 + r1 * r1) + r2 * r2) + r3 * r3)
        out[m, 0], out[m, 1] = r0 / norm, r1 / norm
        out[m, 2], out[m, 3] = r2 / norm, r3 / norm
