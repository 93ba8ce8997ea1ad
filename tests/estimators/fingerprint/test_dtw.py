"""DTW, DDTW, HV-DDTW and MD-DTW against a plain-Python brute force (Chen2022 Alg. 1).

The brute force is the recursion of Alg. 1 written cell by cell; it is itself
checked against an exhaustive search over all warping paths on tiny sequences.
"""

from __future__ import annotations

import doctest
import functools
import math
from collections.abc import Callable

import numpy as np
import pytest

from indoorsim.estimators.fingerprint import dtw as dtw_module
from indoorsim.estimators.fingerprint import hv as hv_module
from indoorsim.estimators.fingerprint.dtw import (
    ddtw_many,
    dtw_distance,
    dtw_many,
    hv_ddtw_many,
    match_subsequence,
    md_dtw_many,
    weighted_knn,
)
from indoorsim.estimators.fingerprint.hv import derivative, hv_components

TOL = 1e-9

# ----------------------------------------------------------------- brute force


def local_distance(a: list[float], b: list[float]) -> float:
    """Alg. 1 line 3: Euclidean distance between two samples."""
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b, strict=True)))


def brute_dtw(
    query: np.ndarray, reference: np.ndarray, window: int | None = None, subsequence: bool = False
) -> float:
    """D(n−1, m−1) by the recursion of Alg. 1 (open begin/end if ``subsequence``)."""
    q = [list(np.atleast_1d(s)) for s in query]
    r = [list(np.atleast_1d(s)) for s in reference]
    n, m = len(q), len(r)

    def admissible(i: int, j: int) -> bool:
        return window is None or -window - max(0, n - m) <= j - i <= window + max(0, m - n)

    @functools.cache
    def cost(i: int, j: int) -> float:
        if not admissible(i, j):
            return math.inf
        d = local_distance(q[i], r[j])
        if i == 0 and (j == 0 or subsequence):
            return d
        if i == 0:
            return d + cost(0, j - 1)
        if j == 0:
            return d + cost(i - 1, 0)
        return d + min(cost(i - 1, j), cost(i - 1, j - 1), cost(i, j - 1))

    if subsequence:
        return min(cost(n - 1, j) for j in range(m))
    return cost(n - 1, m - 1)


def exhaustive_dtw(query: np.ndarray, reference: np.ndarray) -> float:
    """Minimum over every warping path from (0, 0) to (n−1, m−1) of Σ d(i, j)."""
    n, m = len(query), len(reference)
    best = math.inf

    def walk(i: int, j: int, total: float) -> None:
        nonlocal best
        total += local_distance(list(query[i]), list(reference[j]))
        if (i, j) == (n - 1, m - 1):
            best = min(best, total)
            return
        for di, dj in ((1, 0), (0, 1), (1, 1)):
            if i + di < n and j + dj < m:
                walk(i + di, j + dj, total)

    walk(0, 0, 0.0)
    return best


def brute_derivative(x: np.ndarray) -> np.ndarray:
    """Keogh & Pazzani, sample by sample (Eq. 19–20)."""
    out = np.empty_like(x, dtype=float)
    for k in range(1, len(x) - 1):
        out[k] = ((x[k] - x[k - 1]) + (x[k + 1] - x[k - 1]) / 2) / 2
    out[0], out[-1] = out[1], out[-2]
    return out


def random_case(
    rng: np.random.Generator, channels: int, n_refs: int, max_len: int = 30
) -> tuple[np.ndarray, list[np.ndarray]]:
    """A random-walk query and references of assorted lengths (≥ 3)."""
    n = int(rng.integers(3, max_len))
    query = rng.normal(size=(n, channels)).cumsum(axis=0)
    lengths = [n, *rng.integers(3, max_len + 10, n_refs - 1)]
    return query, [rng.normal(size=(int(m), channels)).cumsum(axis=0) for m in lengths]


def batched_and_single(
    fn: Callable[..., np.ndarray], query: np.ndarray, refs: list[np.ndarray], **options: float
) -> tuple[np.ndarray, np.ndarray]:
    """``fn`` on all references at once (SIMD batches) and one at a time (one-reference kernel)."""
    return fn(query, refs, **options), np.array([fn(query, [r], **options)[0] for r in refs])


def assert_matches(got: tuple[np.ndarray, np.ndarray], expected: list[float]) -> None:
    for distances in got:
        np.testing.assert_allclose(distances, expected, rtol=0, atol=TOL)


# ------------------------------------------------------------ the brute force


@pytest.mark.parametrize("shape", [(1, 1), (1, 4), (4, 1), (3, 3), (4, 5), (5, 4)])
def test_the_brute_force_is_the_best_warping_path(shape: tuple[int, int]) -> None:
    rng = np.random.default_rng(sum(shape))
    q, r = rng.normal(size=(shape[0], 2)), rng.normal(size=(shape[1], 2))
    assert brute_dtw(q, r) == pytest.approx(exhaustive_dtw(q, r), abs=TOL)


# ------------------------------------------------- every variant vs brute force


@pytest.mark.parametrize("channels", [1, 2, 3, 6])
def test_dtw_equals_brute_force(channels: int) -> None:
    rng = np.random.default_rng(channels)
    query, refs = random_case(rng, channels, 10)
    expected = [brute_dtw(query, r) for r in refs]
    assert_matches(batched_and_single(dtw_many, query, refs), expected)


@pytest.mark.parametrize("window", [0, 1, 3, 8])
def test_windowed_dtw_equals_brute_force(window: int) -> None:
    rng = np.random.default_rng(window)
    query, refs = random_case(rng, 2, 10)
    expected = [brute_dtw(query, r, window=window) for r in refs]
    assert_matches(batched_and_single(dtw_many, query, refs, window=window), expected)


@pytest.mark.parametrize("channels", [1, 2, 4])
def test_subsequence_dtw_equals_brute_force(channels: int) -> None:
    rng = np.random.default_rng(10 + channels)
    query, refs = random_case(rng, channels, 10)
    expected = [brute_dtw(query, r, subsequence=True) for r in refs]
    assert_matches(batched_and_single(dtw_many, query, refs, subsequence=True), expected)
    # The reported segment is where that distance is reached: full DTW on it gives it back.
    match = match_subsequence(query, refs)
    np.testing.assert_allclose(match.distance, expected, rtol=0, atol=TOL)
    on_segment = [
        brute_dtw(query, r[a:b]) for r, a, b in zip(refs, match.start, match.stop, strict=True)
    ]
    np.testing.assert_allclose(on_segment, expected, rtol=0, atol=TOL)


@pytest.mark.parametrize("channels", [1, 3])
def test_ddtw_equals_brute_force_on_derivatives(channels: int) -> None:
    rng = np.random.default_rng(20 + channels)
    query, refs = random_case(rng, channels, 10)
    expected = [brute_dtw(brute_derivative(query), brute_derivative(r)) for r in refs]
    assert_matches(batched_and_single(ddtw_many, query, refs), expected)
    expected_window = [
        brute_dtw(brute_derivative(query), brute_derivative(r), window=2) for r in refs
    ]
    assert_matches(batched_and_single(ddtw_many, query, refs, window=2), expected_window)


def test_hv_ddtw_equals_brute_force_of_algorithm_1() -> None:
    rng = np.random.default_rng(30)
    query, refs = random_case(rng, 2, 10)

    def algorithm_1(q_hv: np.ndarray, r_hv: np.ndarray) -> float:
        m_q, m_r = brute_derivative(q_hv), brute_derivative(r_hv)  # Eq. 19–20
        n, m = len(m_q), len(m_r)
        # Line 3: d(i, j) = √((M^H(i) − M^H_db(j))² + (M^V(i) − M^V_db(j))²).
        d = [
            [math.hypot(m_q[i, 0] - m_r[j, 0], m_q[i, 1] - m_r[j, 1]) for j in range(m)]
            for i in range(n)
        ]
        big_d = [[0.0] * m for _ in range(n)]
        big_d[0][0] = d[0][0]  # line 6
        for i in range(1, n):
            big_d[i][0] = d[i][0] + big_d[i - 1][0]  # line 7
        for j in range(1, m):
            big_d[0][j] = d[0][j] + big_d[0][j - 1]
        for i in range(1, n):
            for j in range(1, m):  # line 8
                big_d[i][j] = d[i][j] + min(big_d[i - 1][j], big_d[i - 1][j - 1], big_d[i][j - 1])
        return big_d[n - 1][m - 1]

    expected = [algorithm_1(query, r) for r in refs]
    assert_matches(batched_and_single(hv_ddtw_many, query, refs), expected)


def test_md_dtw_equals_brute_force_with_the_floor() -> None:
    rng = np.random.default_rng(40)
    query, refs = random_case(rng, 5, 10)
    query, refs = -70 + 10 * query, [-70 + 10 * r for r in refs]
    query[rng.random(query.shape) < 0.2] = np.nan  # unheard APs
    for r in refs:
        r[rng.random(r.shape) < 0.2] = np.nan
    floor = -95.0

    def filled(x: np.ndarray) -> np.ndarray:
        return np.array([[floor if np.isnan(v) or v < floor else v for v in s] for s in x])

    expected = [brute_dtw(filled(query), filled(r)) for r in refs]
    assert_matches(batched_and_single(md_dtw_many, query, refs, floor_dbm=floor), expected)


def test_batches_beyond_the_simd_width_keep_each_reference_in_place() -> None:
    # 150 references of shuffled lengths span three batches of 64 lanes.
    rng = np.random.default_rng(50)
    query = rng.normal(size=(12, 2)).cumsum(axis=0)
    refs = [rng.normal(size=(int(m), 2)).cumsum(axis=0) for m in rng.integers(3, 40, 150)]
    expected = [brute_dtw(query, r) for r in refs]
    np.testing.assert_allclose(dtw_many(query, refs), expected, rtol=0, atol=TOL)
    np.testing.assert_allclose(
        dtw_many(query, refs, window=4), [brute_dtw(query, r, window=4) for r in refs], atol=TOL
    )
    single = [dtw_distance(query, r) for r in refs[:10]]
    np.testing.assert_allclose(single, expected[:10], rtol=0, atol=TOL)


# ------------------------------------------------------------------ hand cases

X = np.array([0.0, 1.0, 4.0, 9.0, 16.0, 25.0])
# Two warps of X of the same length; aligning them needs |j − i| up to 2.
WARP_A = X[[0, 0, 0, 1, 2, 3, 4, 5]]
WARP_B = X[[0, 1, 2, 3, 4, 5, 5, 5]]


def test_identical_sequences_are_at_zero_under_every_variant() -> None:
    rng = np.random.default_rng(60)
    seq = rng.normal(size=(25, 2)).cumsum(axis=0)
    for fn in (dtw_many, ddtw_many, hv_ddtw_many, md_dtw_many):
        assert fn(seq, [seq])[0] == 0.0
    assert dtw_many(seq, [seq], window=0)[0] == 0.0


def test_a_time_warped_copy_is_at_zero_under_dtw_only() -> None:
    euclidean = np.abs(WARP_A - WARP_B).sum()
    assert euclidean > 0
    assert dtw_distance(WARP_A, WARP_B) == 0.0
    assert dtw_distance(WARP_A, X) == 0.0  # different lengths too


def test_a_constant_offset_is_at_zero_under_ddtw_only() -> None:
    rng = np.random.default_rng(61)
    seq = rng.normal(size=(30, 2)).cumsum(axis=0)
    shifted = seq + np.array([7.0, -3.0])
    assert dtw_many(seq, [shifted])[0] > 1.0
    assert ddtw_many(seq, [shifted])[0] == pytest.approx(0.0, abs=1e-12)
    assert hv_ddtw_many(seq, [shifted])[0] == pytest.approx(0.0, abs=1e-12)


def test_the_local_distance_is_euclidean_and_summed() -> None:
    # Paper's DTW: 5 + 10 = 15; the root of summed squares would be √125.
    assert dtw_distance([[0.0, 0.0], [0.0, 0.0]], [[3.0, 4.0], [6.0, 8.0]]) == 15.0
    assert dtw_distance([0.0], [1.0, 2.0]) == 3.0  # one query sample meets both


def test_derivative_by_hand() -> None:
    # Interior: ((q_k − q_{k−1}) + (q_{k+1} − q_{k−1})/2)/2; ends copy their neighbours.
    np.testing.assert_allclose(
        derivative([0.0, 1.0, 3.0, 6.0, 10.0]), [1.25, 1.25, 2.25, 3.25, 3.25], rtol=0, atol=0
    )
    two = derivative(np.column_stack([np.arange(6.0) * 2.0, np.full(6, 5.0)]))
    np.testing.assert_array_equal(two, np.column_stack([np.full(6, 2.0), np.zeros(6)]))
    rng = np.random.default_rng(62)
    x = rng.normal(size=(9, 3))
    np.testing.assert_allclose(derivative(x), brute_derivative(x), rtol=0, atol=1e-15)


# ---------------------------------------------------------------- the window


def test_window_zero_is_the_euclidean_sum_along_the_diagonal() -> None:
    assert dtw_distance(WARP_A, WARP_B, window=0) == pytest.approx(np.abs(WARP_A - WARP_B).sum())


def test_the_window_limits_the_warp() -> None:
    assert dtw_distance(WARP_A, WARP_B, window=2) == 0.0
    assert dtw_distance(WARP_A, WARP_B, window=1) > 0.0
    assert dtw_distance(WARP_A, WARP_B, window=1) == pytest.approx(
        brute_dtw(WARP_A, WARP_B, window=1), abs=TOL
    )


def test_the_window_widens_by_the_length_difference() -> None:
    # X is 6 samples, WARP_A 8: a 0-wide band still reaches the end cell.
    assert np.isfinite(dtw_distance(X, WARP_A, window=0))
    assert dtw_distance(X, WARP_A, window=0) == pytest.approx(brute_dtw(X, WARP_A, window=0))


# --------------------------------------------------------- subsequence matching


def test_subsequence_finds_a_planted_segment() -> None:
    rng = np.random.default_rng(70)
    refs = [rng.normal(size=(300, 2)).cumsum(axis=0) for _ in range(5)]
    planted = refs[3][120:160]
    match = match_subsequence(planted, refs)
    assert int(np.argmin(match.distance)) == 3
    assert match.distance[3] == 0.0
    assert (match.start[3], match.stop[3]) == (120, 160)
    assert (match.distance[[0, 1, 2, 4]] > 1.0).all()
    # A slower walk over the same segment: samples repeated, same place found.
    slow = planted[np.repeat(np.arange(40), rng.integers(1, 4, 40))]
    match = match_subsequence(slow, refs)
    assert match.distance[3] == 0.0
    assert (match.start[3], match.stop[3]) == (120, 160)
    # A faster walk skips every other sample. The skipped ones cost (each is
    # visited by a step along the reference), so the best segment may trim a few
    # samples at its ends, where squeezing query samples together costs less.
    fast = planted[::2]
    match = match_subsequence(fast, refs)
    assert int(np.argmin(match.distance)) == 3
    assert abs(match.start[3] - 120) <= 8 and abs(match.stop[3] - 159) <= 8
    assert match.distance[3] == pytest.approx(brute_dtw(fast, refs[3], subsequence=True), abs=TOL)
    segment = refs[3][match.start[3] : match.stop[3]]
    assert dtw_distance(fast, segment) == pytest.approx(match.distance[3], abs=TOL)
    # Whereas full DTW must also account for the rest of the reference.
    assert dtw_many(planted, refs)[3] > 1.0


def test_subsequence_of_derivatives_finds_an_offset_segment() -> None:
    rng = np.random.default_rng(71)
    survey = rng.normal(size=(200, 2)).cumsum(axis=0)
    online = survey[50:90] + np.array([12.0, -4.0])  # another phone's constant bias
    match = match_subsequence(derivative(online), [derivative(survey)])
    # The derivatives agree on survey samples 51–88; the query's end values copy
    # their neighbours' (D_0 = D_1), so they too fall on samples 51 and 88.
    assert match.distance[0] == pytest.approx(0.0, abs=1e-9)
    assert (match.start[0], match.stop[0]) == (51, 89)
    assert match_subsequence(online, [survey]).distance[0] > 1.0  # raw samples see the bias


# ----------------------------------------------------------- HV fingerprints


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def test_hv_of_a_phone_lying_flat() -> None:
    b_h, b_v = hv_components([[20.0, 0.0, -40.0], [0.0, 30.0, 10.0]], [0.0, 0.0, 9.81])
    np.testing.assert_allclose(b_h, [20.0, 30.0])
    np.testing.assert_allclose(b_v, [-40.0, 10.0])  # up is positive: gravity sensor points up


def test_hv_is_eq_17_and_18_and_independent_of_attitude() -> None:
    rng = np.random.default_rng(80)
    field_world = rng.normal(0.0, 25.0, (50, 3))
    rotations = [random_rotation(rng) for _ in range(50)]  # world ← phone, per sample
    mag = np.array([r.T @ b for r, b in zip(rotations, field_world, strict=True)])
    gravity = np.array([r.T @ [0.0, 0.0, 9.81] for r in rotations])
    b_h, b_v = hv_components(mag, gravity)
    np.testing.assert_allclose(b_v, field_world[:, 2], atol=1e-12)
    np.testing.assert_allclose(b_h, np.hypot(field_world[:, 0], field_world[:, 1]), atol=1e-12)
    # Eq. 17 literally, pitch θ and roll φ from the gravity direction u.
    u = gravity / np.linalg.norm(gravity, axis=1, keepdims=True)
    theta, phi = np.arcsin(-u[:, 0]), np.arctan2(u[:, 1], u[:, 2])
    eq17 = (
        -np.sin(theta) * mag[:, 0]
        + np.sin(phi) * np.cos(theta) * mag[:, 1]
        + np.cos(phi) * np.cos(theta) * mag[:, 2]
    )
    np.testing.assert_allclose(b_v, eq17, atol=1e-12)
    np.testing.assert_allclose(b_h**2 + b_v**2, (mag**2).sum(axis=1), rtol=1e-12)  # erratum


def test_hv_ddtw_ignores_how_the_phone_is_held() -> None:
    # One walk's field recorded by a phone at two attitudes: raw 3-axis DTW sees a
    # difference, HV-DDTW none.
    rng = np.random.default_rng(81)
    field_world = rng.normal(0.0, 3.0, (60, 3)).cumsum(axis=0) + np.array([15.0, 20.0, -40.0])
    hv = []
    raw = []
    for rot in (random_rotation(rng), random_rotation(rng)):
        mag = field_world @ rot  # rows rotated to the phone: rotᵀ b
        hv.append(np.column_stack(hv_components(mag, rot.T @ [0.0, 0.0, 9.81])))
        raw.append(mag)
    assert dtw_distance(raw[0], raw[1]) > 100.0
    assert hv_ddtw_many(hv[0], [hv[1]])[0] == pytest.approx(0.0, abs=1e-9)


# ------------------------------------------------------------------ WKNN (Eq. 21)


def test_weighted_knn_is_eq_21_with_the_erratum() -> None:
    positions = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 8.0], [9.0, 9.0]])
    d = np.array([1.0, 2.0, 4.0, 50.0])
    c = 1.0 / d[:3]
    expected = (c[:, None] * positions[:3]).sum(axis=0) / c.sum()
    np.testing.assert_allclose(weighted_knn(d, positions, k=3), expected, rtol=1e-12)
    both = weighted_knn(np.vstack([d, d[::-1]]), positions, k=3)
    np.testing.assert_allclose(both[0], expected, rtol=1e-12)
    # An exact match takes all the weight; k beyond the table uses every reference.
    np.testing.assert_array_equal(weighted_knn([3.0, 0.0, 1.0, 2.0], positions), [4.0, 0.0])
    np.testing.assert_allclose(
        weighted_knn(d, positions, k=10),
        ((1.0 / d)[:, None] * positions).sum(axis=0) / (1.0 / d).sum(),
    )


# -------------------------------------------------------------- input forms


def test_reference_arrays_and_lists_agree() -> None:
    rng = np.random.default_rng(90)
    query = rng.normal(size=(10, 2))
    refs = rng.normal(size=(5, 12, 2))
    np.testing.assert_array_equal(dtw_many(query, refs), dtw_many(query, list(refs)))
    one_channel = rng.normal(size=(5, 12))
    np.testing.assert_array_equal(
        dtw_many(query[:, 0], one_channel), dtw_many(query[:, :1], list(one_channel[..., None]))
    )
    assert dtw_many(query, []).shape == (0,)
    assert match_subsequence(query, np.empty((0, 4, 2))).start.shape == (0,)


def test_errors_are_clear() -> None:
    q = np.zeros((5, 2))
    with pytest.raises(ValueError, match="1 channel"):
        dtw_many(q, [np.zeros(5)])
    with pytest.raises(ValueError, match="single reference"):
        dtw_many(q, np.zeros((5, 2)))  # one reference passed without a list
    with pytest.raises(ValueError, match="non-empty"):
        dtw_many(q, [np.zeros((0, 2))])
    with pytest.raises(ValueError, match="finite"):
        dtw_many(q, [np.full((3, 2), np.nan)])
    with pytest.raises(ValueError, match="window must be"):
        dtw_many(q, [q], window=-1)
    with pytest.raises(ValueError, match="cannot be combined"):
        dtw_many(q, [q], window=2, subsequence=True)
    with pytest.raises(ValueError, match="at least 3"):
        ddtw_many(q, [q[:2]])
    with pytest.raises(ValueError, match="N ≥ 3"):
        derivative([1.0, 2.0])
    with pytest.raises(ValueError, match="2 channels"):
        hv_ddtw_many(np.zeros((5, 3)), [np.zeros((5, 3))])
    with pytest.raises(ValueError, match="zero vector"):
        hv_components(np.ones((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"\(N, 3\) mag"):
        hv_components(np.ones((2, 2)), np.ones((2, 3)))
    with pytest.raises(ValueError, match="k must be"):
        weighted_knn([1.0], [[0.0, 0.0]], k=0)
    with pytest.raises(ValueError, match="finite and non-negative"):
        weighted_knn([np.inf, 1.0], [[0.0, 0.0], [1.0, 1.0]])
    with pytest.raises(ValueError, match=r"\(R, 2\) positions"):
        weighted_knn([1.0, 2.0], [[0.0, 0.0]])


@pytest.mark.parametrize("module", [dtw_module, hv_module])
def test_docstring_examples_run(module: object) -> None:
    result = doctest.testmod(module)
    assert result.attempted > 0
    assert result.failed == 0
