"""Weighted k-nearest-neighbour matching of fingerprints (Chen2022 Eq. 21).

The k reference fingerprints nearest to a measurement (Euclidean distance D_i
in feature space) vote for their positions with weights inversely
proportional to distance:

    c_i = (1/D_i) / Σ_j (1/D_j),    p̂ = Σ_i c_i·p_i.

Chen2022's text normalises by C = Σ D_i, a typo (the weights would not sum to
one); the normalisation by Σ 1/D_j is used (PAPER_NOTES, Chen2022 item 5).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

__all__ = ["WKNN"]


@dataclass(kw_only=True)
class WKNN:
    """Weighted k-nearest-neighbour positioning on a fingerprint table.

    A measurement that equals a reference fingerprint exactly (D_i = 0, an
    infinite weight) returns that reference's position; several exact matches
    return their mean.

    Attributes:
        k: neighbours per estimate (fewer if the table has fewer references).
    """

    k: int = 4

    _tree: cKDTree | None = field(default=None, init=False, repr=False, compare=False)
    _positions: NDArray[np.float64] = field(
        default_factory=lambda: np.empty((0, 2)), init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        if self.k < 1:
            raise ValueError(f"k must be ≥ 1, got {self.k}")

    def fit(self, features: ArrayLike, positions: ArrayLike) -> WKNN:
        """Index the reference fingerprints.

        Args:
            features: (M, F) reference fingerprints.
            positions: (M, 2) their positions, m.

        Returns:
            self.
        """
        f = np.asarray(features, dtype=float)
        p = np.asarray(positions, dtype=float)
        if f.ndim != 2 or p.ndim != 2 or len(f) != len(p) or len(f) == 0:
            raise ValueError(
                f"need (M, F) features and (M, 2) positions with M ≥ 1, got {f.shape} and {p.shape}"
            )
        if not (np.isfinite(f).all() and np.isfinite(p).all()):
            raise ValueError("reference fingerprints and positions must be finite")
        self._tree = cKDTree(f)
        self._positions = p
        return self

    def predict(self, features: ArrayLike) -> NDArray[np.float64]:
        """Positions (N, 2) of measurements (N, F), m."""
        if self._tree is None:
            raise RuntimeError("WKNN is not fitted: call fit(features, positions) first")
        f = np.atleast_2d(np.asarray(features, dtype=float))
        if f.shape[1] != self._tree.m:
            raise ValueError(
                f"measurements have {f.shape[1]} features, the references {self._tree.m}"
            )
        if not np.isfinite(f).all():
            raise ValueError("measurements must be finite")
        k = min(self.k, self._tree.n)
        dist, idx = self._tree.query(f, k=k)
        dist = dist.reshape(len(f), k)
        idx = idx.reshape(len(f), k)
        exact = dist == 0.0
        any_exact = exact.any(axis=1, keepdims=True)
        inv = np.divide(1.0, dist, out=np.zeros_like(dist), where=~exact)
        w = np.where(any_exact, exact, inv)
        w /= w.sum(axis=1, keepdims=True)
        return np.einsum("nk,nkd->nd", w, self._positions[idx])
