"""Horizontal/vertical magnetic fingerprints and their derivative (Chen2022 Eq. 16–20).

The HV fingerprint (Eq. 16) replaces the field magnitude by two components that
do not depend on how the phone is held: the component along the vertical,

    B_V = B · u                                  (Eq. 17)

with u the unit vector of the gravity sensor, and the horizontal magnitude

    B_H = √(|B|² − B_V²)                         (Eq. 18, erratum)

The text's Eq. 18 subtracts B_V instead of B_V², a typo (PAPER_NOTES, Chen2022
item 3): only the square makes B_H² + B_V² = |B|².

**Sign of B_V.** Eq. 17 is written with pitch θ and roll φ,
B_V = −sin θ·B_x + sin φ cos θ·B_y + cos φ cos θ·B_z: the projection of B on
u = (−sin θ, sin φ cos θ, cos φ cos θ), which is how those two angles are defined
from the accelerometer. The gravity input here is Android's gravity sensor (the
specific force a still phone reads, +9.81 m/s² on z for a phone lying face up),
so u points **up** and B_V is the *upward* component: negative in the northern
hemisphere, where the field dips downward (about −40 µT at mid latitudes). In
the NED body frame of the paper's source the same formula gives the downward
component; matching only needs the survey and the query to share a convention.

The derivative (Eq. 19–20) is Keogh & Pazzani's (2001) estimate, the mean of the
backward difference and the central difference:

    M_k = ((B_k − B_{k−1}) + (B_{k+1} − B_{k−1})/2) / 2,

defined for interior samples; as in Keogh & Pazzani, the first and last values
copy their neighbours.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["derivative", "hv_components"]

# Below this norm, m/s², the gravity vector carries no direction.
_TINY_GRAVITY = 1e-9


def hv_components(
    mag: ArrayLike, gravity: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Horizontal and vertical magnetic components (Chen2022 Eq. 17–18).

    Args:
        mag: (N, 3) magnetic field in the phone frame, µT.
        gravity: (N, 3) gravity sensor in the phone frame (pointing up, as
            Android's), m/s²; only its direction is used. A single (3,) vector
            applies to every sample.

    Returns:
        ``(b_h, b_v)``, each (N,), µT: B_H = √(|B|² − B_V²) ≥ 0 and B_V the
        upward component (see the module docstring for the sign).

    Raises:
        ValueError: on shapes other than (N, 3) / (3,), or a zero gravity vector.

    >>> b_h, b_v = hv_components([[20.0, 0.0, -40.0]], [[0.0, 0.0, 9.81]])
    >>> b_h.tolist(), b_v.tolist()
    ([20.0], [-40.0])
    """
    b = np.asarray(mag, dtype=float)
    g = np.asarray(gravity, dtype=float)
    if b.ndim != 2 or b.shape[1] != 3 or g.shape[-1:] != (3,) or g.ndim > 2:
        raise ValueError(f"need (N, 3) mag and (N, 3) or (3,) gravity, got {b.shape} and {g.shape}")
    norm = np.linalg.norm(g, axis=-1, keepdims=True)
    if np.any(norm < _TINY_GRAVITY):
        raise ValueError("gravity has a zero vector: the vertical is undefined there")
    u = g / norm
    b_v = np.sum(b * u, axis=-1)  # Eq. 17
    # Eq. 18 with the erratum (B_V squared); rounding can leave −1e-15 for a vertical field.
    b_h = np.sqrt(np.maximum(np.sum(b * b, axis=-1) - b_v**2, 0.0))
    return b_h, b_v


def derivative(sequence: ArrayLike) -> NDArray[np.float64]:
    """Keogh & Pazzani derivative of a sequence along its first axis (Chen2022 Eq. 19–20).

    D_k = ((q_k − q_{k−1}) + (q_{k+1} − q_{k−1})/2) / 2 for 0 < k < N − 1;
    D_0 = D_1 and D_{N−1} = D_{N−2}. Each channel of an (N, C) sequence is
    differentiated on its own, so an HV fingerprint (N, 2) gives (M^H, M^V).

    Args:
        sequence: (N,) or (N, C) samples, N ≥ 3.

    Returns:
        The derivative, same shape as ``sequence``.

    Raises:
        ValueError: if the sequence has fewer than 3 samples.

    >>> derivative([0.0, 1.0, 3.0, 6.0, 10.0]).tolist()
    [1.25, 1.25, 2.25, 3.25, 3.25]
    """
    q = np.asarray(sequence, dtype=float)
    if q.ndim not in (1, 2) or q.shape[0] < 3:
        raise ValueError(f"derivative needs an (N,) or (N, C) sequence with N ≥ 3, got {q.shape}")
    d = np.empty_like(q)
    d[1:-1] = ((q[1:-1] - q[:-2]) + (q[2:] - q[:-2]) / 2.0) / 2.0  # Eq. 19–20
    d[0] = d[1]
    d[-1] = d[-2]
    return d
