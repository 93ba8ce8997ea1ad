"""The Tent chaotic map (Han2023 §3.3, Eq. 30) and Tent-initialised populations.

Eq. 30 is x ← 2x for x < ½ and x ← 2(1 − x) otherwise. In floating point its
orbits die: every double in (0, 1) is a dyadic rational m/2^k, each step turns
m/2^k into m'/2^(k−1), so after at most ~53 steps the orbit reaches ½ → 1 → 0
and stays at the fixed point 0 for good (PAPER_NOTES, Han2023 item 8).

Two common fixes, both available here:

* **random kick** (default, ``slope=2``): the map is Eq. 30 exactly, and an
  iterate that lands on 0, ¼, ½ or ¾ — the points whose exact orbit reaches 0
  within two steps, which by the argument above every orbit must pass
  through — is moved to x + ``perturbation``·U(0, 1), the improved Tent map
  of Shan et al. (2005, *Control and Decision* 20(2)). Their rule also kicks
  an orbit that repeats an earlier value; with slope 2 a float orbit cannot
  cycle without passing through these points, so that check is not needed.
  The invariant density stays uniform.
* **reduced slope** (``slope=1.99``): x ← 1.99·x / 1.99·(1 − x). Multiplying by
  1.99 is not a bit shift, so orbits never collapse; the sequence is a
  deterministic function of its start and lives in [0.00995, 0.995].

``perturbation=0`` with ``slope=2`` gives the literal Eq. 30, which collapses
(kept so that the failure can be shown).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["tent_map", "tent_population", "tent_sequence"]

_COLLAPSE_POINTS = np.array([0.0, 0.25, 0.5, 0.75])
"""Iterates that reach the fixed point 0 of the exact map within two steps."""


def tent_map(x: ArrayLike, slope: float = 2.0) -> NDArray[np.float64]:
    """One step of the tent map (Han2023 Eq. 30 for ``slope=2``).

    >>> tent_map([0.2, 0.7]).tolist()
    [0.4, 0.6000000000000001]
    """
    x = np.asarray(x, dtype=float)
    # Eq. 30
    return np.where(x < 0.5, slope * x, slope * (1.0 - x))


def tent_sequence(
    n: int,
    dim: int,
    rng: np.random.Generator,
    *,
    slope: float = 2.0,
    perturbation: float = 0.1,
) -> NDArray[np.float64]:
    """Tent-map orbits: ``dim`` independent chaotic sequences of length ``n``.

    Each column starts from its own x₀ ~ U(0, 1) (Han2023: "a constant within
    (0, 1) is randomly chosen as the initial value") and row k holds the k-th
    iterate, x₀ included. See the module docstring for the floating-point fix.

    Args:
        n: iterates per sequence (rows).
        dim: independent sequences (columns).
        rng: the seeded generator for the starts and the kicks.
        slope: 2 for Eq. 30; 1.99 for the reduced-slope fix.
        perturbation: size of the kick U(0, ``perturbation``) given to an
            iterate on 0, ¼, ½ or ¾; 0 disables the kick.

    Returns:
        (n, dim) values in [0, 1).

    >>> seq = tent_sequence(1000, 3, np.random.default_rng(0))
    >>> seq.shape, bool(seq[-100:].min() > 0)
    ((1000, 3), True)
    """
    if n < 0 or dim < 0:
        raise ValueError(f"n and dim must be ≥ 0, got {n} and {dim}")
    if not 0.0 < slope <= 2.0:
        raise ValueError(f"slope must be in (0, 2], got {slope}")
    if not 0.0 <= perturbation < 0.25:
        raise ValueError(
            f"perturbation must be in [0, 0.25) to stay inside (0, 1), got {perturbation}"
        )
    out = np.empty((n, dim))
    x = rng.random(dim)
    for k in range(n):
        if perturbation > 0.0:
            stuck = np.isin(x, _COLLAPSE_POINTS)
            if stuck.any():
                x = np.where(stuck, x + perturbation * rng.random(dim), x)
        out[k] = x
        x = tent_map(x, slope)
    return out


def tent_population(
    size: int,
    lower: ArrayLike,
    upper: ArrayLike,
    rng: np.random.Generator,
    *,
    slope: float = 2.0,
    perturbation: float = 0.1,
) -> NDArray[np.float64]:
    """A population whose coordinates follow tent-map orbits (Han2023 §3.4, step 2).

    Member i, coordinate d is lower_d + s_id·(upper_d − lower_d), with s the
    :func:`tent_sequence` of ``size`` iterates in D columns: successive
    members are successive iterates of one orbit per coordinate.

    Args:
        size: population size (rows).
        lower: (D,) lower bounds (a scalar means D = 1).
        upper: (D,) upper bounds.
        rng: the seeded generator.
        slope: see :func:`tent_sequence`.
        perturbation: see :func:`tent_sequence`.

    Returns:
        (size, D) positions inside [lower, upper).

    >>> pop = tent_population(30, [-1.0, 0.0], [1.0, 10.0], np.random.default_rng(1))
    >>> pop.shape, bool((pop[:, 1] >= 0).all() and (pop[:, 1] < 10).all())
    ((30, 2), True)
    """
    lo, hi = np.broadcast_arrays(
        np.atleast_1d(np.asarray(lower, dtype=float)), np.atleast_1d(np.asarray(upper, dtype=float))
    )
    if lo.ndim != 1 or not (hi > lo).all():
        raise ValueError(f"need 1-D bounds with upper > lower, got {lo} and {hi}")
    s = tent_sequence(size, lo.size, rng, slope=slope, perturbation=perturbation)
    return lo + s * (hi - lo)
