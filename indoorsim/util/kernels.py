"""Compiled quaternion and small-matrix kernels: the one home of this arithmetic.

Conventions (DESIGN §2): quaternions are (w, x, y, z), scalar first; a unit
quaternion q stands for the rotation world←body, so R(q) takes body-frame
vectors to the world, v_w = q ⊗ (0, v_b) ⊗ q*.

Every kernel is a numba function compiled into the loop that calls it
(``inline="always"``: no call, and no array made per sample). Most take
components and return a tuple, so a loop over samples keeps its numbers in
registers; where the callers hold a quaternion or a matrix in an array, the
kernel reads or writes that array.

The arithmetic is fixed operation for operation: recordings, fused streams
and estimates are bit for bit functions of it, so reordering a sum or
hoisting a reciprocal here changes outputs (``benchmarks/hashcheck.py``).
Where the package computes the same quantity another way on purpose, the
kernel's docstring says where and how the bits differ.

numba's on-disk cache does not see a change to a kernel from the cached
functions of other modules that inline it: after editing this module, delete
the cache (the folder of :func:`indoorsim.util.jit_cache.cache_dir`, by
default ``~/.cache/indoorsim/numba``) before measuring anything.
"""

from __future__ import annotations

import math

import numba

# Every divisor below is bounded away from zero by the caller, so numpy's error
# model (no per-division zero test) gives the same numbers, faster.
_KERNEL = {"cache": True, "inline": "always", "error_model": "numpy"}


# --------------------------------------------------------------------- products


@numba.njit(**_KERNEL)
def hamilton(w1, x1, y1, z1, w2, x2, y2, z2):  # pragma: no cover - compiled
    """Hamilton product p ⊗ q of p = (w1, x1, y1, z1) and q = (w2, x2, y2, z2).

    As rotations: apply q, then p. Returns (w, x, y, z), each sum taken left
    to right::

        w = w1 w2 − x1 x2 − y1 y2 − z1 z2
        x = w1 x2 + x1 w2 + y1 z2 − z1 y2
        y = w1 y2 − x1 z2 + y1 w2 + z1 x2
        z = w1 z2 + x1 y2 − y1 x2 + z1 w2

    The conjugate product p* ⊗ q is this with (x1, y1, z1) negated: negation
    is exact, so it rounds as the product it is.
    """
    return (
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    )


@numba.njit(**_KERNEL)
def quat_mul_into(a, b, out):  # pragma: no cover - compiled
    """out = a ⊗ b (:func:`hamilton`) for (4,) arrays; ``out`` may be ``a`` or ``b``."""
    out[0], out[1], out[2], out[3] = hamilton(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3])


@numba.njit(**_KERNEL)
def rotate_vector(w, x, y, z, vx, vy, vz):  # pragma: no cover - compiled
    """The vector v rotated by the unit quaternion q = (w, u): q ⊗ (0, v) ⊗ q* = R(q) v.

    Computed as v + w t + u × t with t = 2 u × v, without forming R(q).
    For the inverse rotation R(q)ᵀ v pass −u. Returns (x, y, z).
    """
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


# --------------------------------------------------------------------- norms


@numba.njit(**_KERNEL)
def quat_norm(w, x, y, z):  # pragma: no cover - compiled
    """‖q‖ = √(((w² + x²) + y²) + z²), summed left to right as numpy's ``linalg.norm`` does."""
    return math.sqrt(w * w + x * x + y * y + z * z)


@numba.njit(**_KERNEL)
def normalised(w, x, y, z):  # pragma: no cover - compiled
    """q / ‖q‖ (:func:`quat_norm`), each component divided by the norm. Returns (w, x, y, z)."""
    n = quat_norm(w, x, y, z)
    return w / n, x / n, y / n, z / n


@numba.njit(**_KERNEL)
def canonicalise(q):  # pragma: no cover - compiled
    """q ← ±q / ‖q‖ in place, the sign making w ≥ 0 (the same rotation, and a continuous output).

    Scaled by the one reciprocal ±1/‖q‖, which does not round as
    :func:`normalised`'s four divisions do: the two are not interchangeable
    bit for bit (the fused-sensor filter uses this one).
    """
    n = quat_norm(q[0], q[1], q[2], q[3])
    s = 1.0 / n if q[0] >= 0 else -1.0 / n
    for i in range(4):
        q[i] *= s


# --------------------------------------------------------------------- rotation vectors


@numba.njit(**_KERNEL)
def quat_from_rotvec(vx, vy, vz):  # pragma: no cover - compiled
    """exp(½v): the unit quaternion (cos ½θ, sin ½θ · v/θ) of the rotation vector v, θ = ‖v‖.

    sin(½θ)/θ is taken as its series ½ − θ²/48 below θ = 1e-8 (avoiding 0/0).
    Returns (w, x, y, z). (The fused-sensor filter's gyro increment forms the
    same quaternion from the rate and the interval, rounding differently;
    scipy's ``Rotation.from_rotvec``, which the carry modes use, takes a longer
    series below θ = 1e-3, so the two differ in the last bits there.)
    """
    angle = math.sqrt(vx * vx + vy * vy + vz * vz)
    s = math.sin(0.5 * angle) / angle if angle > 1e-8 else 0.5 - angle * angle / 48.0
    return math.cos(0.5 * angle), s * vx, s * vy, s * vz


@numba.njit(**_KERNEL)
def rotvec_from_quat(w, x, y, z):  # pragma: no cover - compiled
    """log(q)·2: the rotation vector of the unit quaternion q, the short way round (angle ≤ π).

    With q taken as −q where w < 0, v = u · 2 atan2(‖u‖, w)/‖u‖ (u the vector
    part), whose factor tends to 2 as ‖u‖ → 0 (used below 1e-12, avoiding
    0/0). Returns (x, y, z). (:func:`indoorsim.util.quaternion.relative_rotvec`
    is the numpy form, whose ``arctan2`` need not round as ``math.atan2``.)
    """
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    scale = 2.0 * math.atan2(s, w) / s if s > 1e-12 else 2.0
    return x * scale, y * scale, z * scale


# --------------------------------------------------------------------- rotation matrices


@numba.njit(**_KERNEL)
def rotation_matrix(q, r):  # pragma: no cover - compiled
    """r = R(q), the 3 × 3 rotation matrix of the unit quaternion q (world←body).

    The unit-norm form R = I + 2w[u×] + 2[u×]²::

        [1 − 2(y² + z²)   2(xy − wz)       2(xz + wy)    ]
        [2(xy + wz)       1 − 2(x² + z²)   2(yz − wx)    ]
        [2(xz − wy)       2(yz + wx)       1 − 2(x² + y²)]

    Equal to :func:`rotation_matrix_homogeneous` for a unit q, but not in its
    last bits: the fused-sensor filter uses this form, the estimators' gait
    attitude the other.
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    r[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    r[0, 1] = 2.0 * (x * y - w * z)
    r[0, 2] = 2.0 * (x * z + w * y)
    r[1, 0] = 2.0 * (x * y + w * z)
    r[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    r[1, 2] = 2.0 * (y * z - w * x)
    r[2, 0] = 2.0 * (x * z - w * y)
    r[2, 1] = 2.0 * (y * z + w * x)
    r[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@numba.njit(**_KERNEL)
def rotation_matrix_homogeneous(q, c):  # pragma: no cover - compiled
    """c = ‖q‖² R(q), the homogeneous form of the rotation matrix (Chen2022 Eq. 9)::

        [w² + x² − y² − z²   2(xy − zw)          2(xz + yw)        ]
        [2(xy + zw)          w² − x² + y² − z²   2(yz − xw)        ]
        [2(xz − yw)          2(yz + xw)          w² − x² − y² + z² ]

    the direction cosine matrix C_b^n of a unit q: column j is body axis j in
    the world. See :func:`rotation_matrix` for the unit-norm form.
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    c[0, 0] = w * w + x * x - y * y - z * z
    c[0, 1] = 2.0 * (x * y - z * w)
    c[0, 2] = 2.0 * (x * z + y * w)
    c[1, 0] = 2.0 * (x * y + z * w)
    c[1, 1] = w * w - x * x + y * y - z * z
    c[1, 2] = 2.0 * (y * z - x * w)
    c[2, 0] = 2.0 * (x * z - y * w)
    c[2, 1] = 2.0 * (y * z + x * w)
    c[2, 2] = w * w - x * x - y * y + z * z


@numba.njit(**_KERNEL)
def quat_from_matrix(r, q):  # pragma: no cover - compiled
    """q = the quaternion of the rotation matrix r, by Shepperd's method (up to sign).

    From the largest of the trace and the diagonal entries, for accuracy at
    every angle: with tr = r₀₀ + r₁₁ + r₂₂ > 0, s = 2√(tr + 1) and
    q = (s/4, (r₂₁ − r₁₂)/s, (r₀₂ − r₂₀)/s, (r₁₀ − r₀₁)/s); otherwise the
    like formula led by the largest diagonal entry. q is unit only as far as r
    is a rotation: the caller normalises.
    """
    tr = r[0, 0] + r[1, 1] + r[2, 2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q[0] = 0.25 * s
        q[1] = (r[2, 1] - r[1, 2]) / s
        q[2] = (r[0, 2] - r[2, 0]) / s
        q[3] = (r[1, 0] - r[0, 1]) / s
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2]) * 2
        q[0] = (r[2, 1] - r[1, 2]) / s
        q[1] = 0.25 * s
        q[2] = (r[0, 1] + r[1, 0]) / s
        q[3] = (r[0, 2] + r[2, 0]) / s
    elif r[1, 1] > r[2, 2]:
        s = math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2]) * 2
        q[0] = (r[0, 2] - r[2, 0]) / s
        q[1] = (r[0, 1] + r[1, 0]) / s
        q[2] = 0.25 * s
        q[3] = (r[1, 2] + r[2, 1]) / s
    else:
        s = math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1]) * 2
        q[0] = (r[1, 0] - r[0, 1]) / s
        q[1] = (r[0, 2] + r[2, 0]) / s
        q[2] = (r[1, 2] + r[2, 1]) / s
        q[3] = 0.25 * s


# --------------------------------------------------------------------- 3 × 3 matrices


@numba.njit(**_KERNEL)
def skew(v, m):  # pragma: no cover - compiled
    """m = [v×], the cross-product matrix: [v×] u = v × u."""
    m[0, 0], m[0, 1], m[0, 2] = 0.0, -v[2], v[1]
    m[1, 0], m[1, 1], m[1, 2] = v[2], 0.0, -v[0]
    m[2, 0], m[2, 1], m[2, 2] = -v[1], v[0], 0.0


@numba.njit(**_KERNEL)
def inverse3(a, out):  # pragma: no cover - compiled
    """out = a⁻¹ for a 3 × 3 matrix, as the adjugate over the determinant.

    det a by cofactors along the first row; each entry of the adjugate times
    1/det. No pivoting: for the well-conditioned matrices of a filter's
    innovation covariance, not a general solver.
    """
    det = (
        a[0, 0] * (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1])
        - a[0, 1] * (a[1, 0] * a[2, 2] - a[1, 2] * a[2, 0])
        + a[0, 2] * (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0])
    )
    inv_det = 1.0 / det
    out[0, 0] = (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]) * inv_det
    out[0, 1] = (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) * inv_det
    out[0, 2] = (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1]) * inv_det
    out[1, 0] = (a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]) * inv_det
    out[1, 1] = (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) * inv_det
    out[1, 2] = (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2]) * inv_det
    out[2, 0] = (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]) * inv_det
    out[2, 1] = (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) * inv_det
    out[2, 2] = (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]) * inv_det
