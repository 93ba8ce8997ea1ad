"""WKNN by closed forms on a noise-free synthetic grid."""

from __future__ import annotations

import numpy as np
import pytest

from indoorsim.estimators.fingerprint import WKNN

# A 4 × 3 grid, 1 m apart, whose noise-free fingerprint is twice the position.
GRID = np.array([(x, y) for y in range(3) for x in range(4)], dtype=float)
FEATURES = 2.0 * GRID


def test_a_grid_fingerprint_returns_its_point_exactly() -> None:
    knn = WKNN(k=4).fit(FEATURES, GRID)
    np.testing.assert_array_equal(knn.predict(FEATURES), GRID)


def test_elsewhere_the_inverse_distance_weighted_mean() -> None:
    # Fingerprint (0.5, 0): the 3 nearest references are (0, 0) at D = 0.5,
    # (2, 0) at D = 1.5 and (0, 2) at D = √4.25; weights c_i ∝ 1/D_i (Chen2022 Eq. 21).
    c = np.array([1 / 0.5, 1 / 1.5, 1 / np.sqrt(4.25)])
    expected = (c[:, None] * np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])).sum(0) / c.sum()
    knn = WKNN(k=3).fit(FEATURES, GRID)
    np.testing.assert_allclose(knn.predict([0.5, 0.0])[0], expected, rtol=1e-12)


def test_predict_is_vectorised_over_measurements() -> None:
    rng = np.random.default_rng(0)
    queries = rng.uniform(0.0, 6.0, (25, 2))
    knn = WKNN().fit(FEATURES, GRID)
    rows = np.vstack([knn.predict(q) for q in queries])
    np.testing.assert_allclose(knn.predict(queries), rows, rtol=1e-12)


def test_k_beyond_the_table_and_duplicate_exact_matches() -> None:
    features = np.array([[0.0], [0.0], [3.0]])
    positions = np.array([[0.0, 0.0], [2.0, 0.0], [9.0, 9.0]])
    knn = WKNN(k=10).fit(features, positions)
    np.testing.assert_allclose(knn.predict([[0.0]]), [[1.0, 0.0]])  # mean of both exact matches
    # At 1: D = 1, 1, 2 → weights 0.4, 0.4, 0.2.
    np.testing.assert_allclose(knn.predict([[1.0]]), [[0.4 * 2 + 0.2 * 9, 0.2 * 9]])


def test_errors_are_clear() -> None:
    with pytest.raises(ValueError, match="k must be"):
        WKNN(k=0)
    with pytest.raises(RuntimeError, match="not fitted"):
        WKNN().predict([[0.0, 0.0]])
    with pytest.raises(ValueError, match=r"\(M, 2\) positions"):
        WKNN().fit(FEATURES, GRID[:-1])
    with pytest.raises(ValueError, match="finite"):
        WKNN().fit(np.full((2, 2), np.nan), GRID[:2])
    knn = WKNN().fit(FEATURES, GRID)
    with pytest.raises(ValueError, match="3 features"):
        knn.predict([[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="finite"):
        knn.predict([[np.nan, 0.0]])
