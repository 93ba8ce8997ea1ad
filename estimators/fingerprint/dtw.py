"""Dynamic time warping of fingerprint sequences (Chen2022 Alg. 1, MD-DTW, Eq. 21).

A query sequence q (n samples, C channels) is compared with each reference
sequence r (m_r samples, same C) by the classic DTW recursion of Alg. 1,

    d(i, j) = ‖q_i − r_j‖₂                              (Alg. 1, line 3)
    D(i, j) = d(i, j) + min(D(i−1, j), D(i−1, j−1), D(i, j−1))   (lines 6–8)

with D(0, 0) = d(0, 0), and distance D(n−1, m−1): the **sum** of Euclidean
local distances along the best warping path (PAPER_NOTES, Chen2022 item 4).
Some libraries (dtaidistance's ``dtw_ndim``) instead return the root of the
summed *squared* local distances; that is a different number.

Variants:

* :func:`dtw_many` — plain DTW of the samples (HV fingerprints directly).
* :func:`ddtw_many` — DTW of Keogh & Pazzani derivatives (Eq. 19–20).
* :func:`hv_ddtw_many` — Alg. 1: DDTW of two-channel HV fingerprints, local
  distance √(ΔM_H² + ΔM_V²).
* :func:`md_dtw_many` — MD-DTW of WiFi RSS sequences (local distance Euclidean
  over the access points, unheard APs at a floor value).
* :func:`match_subsequence` — where in a long reference a short query fits.
* :func:`weighted_knn` — the position from the k nearest references (Eq. 21).

Options shared by the ``*_many`` functions:

* ``window`` — a Sakoe–Chiba band of half-width w samples: cell (i, j) is
  admissible iff −w − max(0, n − m) ≤ j − i ≤ w + max(0, m − n). The band is
  widened by the length difference so that the end cell is always reachable
  (dtaidistance's band with its ``window`` = w + 1). ``window=0`` with equal
  lengths allows only the diagonal: Σ_i ‖q_i − r_i‖.
* ``subsequence`` — open-begin/open-end DTW: the whole query is matched to the
  best-fitting *segment* of each reference, D(0, j) = d(0, j) for every j and
  distance min_j D(n−1, j). Online matching needs this: the last few metres
  walked are a short query somewhere inside a longer survey sequence. Not
  combinable with ``window`` (a band needs the alignment's start).

All references are processed in one call to compiled code, single-threaded.
The recursion is sequential along i and j but references are independent, so
full DTW sorts the references by length and takes them in batches of up to 64
that share each DP cell update as the innermost loop: the cell update runs as
SIMD over references (memory O(m_max · C · 64)). Fewer than 8 references, and
the subsequence variant (whose start bookkeeping does not vectorise), run a
scalar one-reference kernel with O(m) memory. ``benchmarks/bench_dtw.py``
compares the speed with the C library dtaidistance.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.fingerprint.hv import derivative

__all__ = [
    "DEFAULT_FLOOR_DBM",
    "SubsequenceMatch",
    "ddtw_many",
    "dtw_distance",
    "dtw_many",
    "hv_ddtw_many",
    "match_subsequence",
    "md_dtw_many",
    "weighted_knn",
]

References = ArrayLike | Sequence[ArrayLike]

# References per SIMD batch: 32 and 64 were the fastest of 8–256 on benchmarks/bench_dtw.py.
_LANES = 64
# Lanes are padded to a multiple of this (8 doubles: one AVX-512 register) so that
# no lane falls to the compiler's scalar remainder loop; a batch of fewer
# references runs the one-reference kernel, which is as fast there.
_SIMD = 8

# RSS given to an access point a scan did not hear, dBm: indoorsim.windows.NO_SIGNAL_DBM.
DEFAULT_FLOOR_DBM = -110.0


@dataclass(frozen=True)
class SubsequenceMatch:
    """Best-fitting segment of each reference for a query (open-begin/open-end DTW).

    Attributes:
        distance: (R,) DTW distance between the query and ``reference[start:stop]``.
        start: (R,) first reference sample aligned with the query's first sample.
        stop: (R,) one past the reference sample aligned with the query's last.
    """

    distance: NDArray[np.float64]
    start: NDArray[np.int64]
    stop: NDArray[np.int64]


class _Packed(NamedTuple):
    """References back to back: reference r is ``flat[starts[r]:starts[r] + lengths[r]]``."""

    flat: NDArray[np.float64]
    starts: NDArray[np.int64]
    lengths: NDArray[np.int64]


# ----------------------------------------------------------------- public API


def dtw_distance(
    query: ArrayLike,
    reference: ArrayLike,
    *,
    window: int | None = None,
    subsequence: bool = False,
) -> float:
    """DTW distance between two sequences (Alg. 1).

    Args:
        query: (n,) or (n, C) samples.
        reference: (m,) or (m, C) samples.
        window: Sakoe–Chiba half-width in samples (module docstring); None: none.
        subsequence: match the query to the best segment of the reference.

    Returns:
        The sum of Euclidean local distances along the best warping path.

    >>> dtw_distance([0.0, 1.0, 2.0], [0.0, 0.0, 1.0, 1.0, 2.0])
    0.0
    >>> dtw_distance([[0.0, 0.0], [0.0, 0.0]], [[3.0, 4.0], [6.0, 8.0]])
    15.0
    """
    return float(dtw_many(query, [reference], window=window, subsequence=subsequence)[0])


def dtw_many(
    query: ArrayLike,
    references: References,
    *,
    window: int | None = None,
    subsequence: bool = False,
) -> NDArray[np.float64]:
    """DTW distances (Alg. 1) from one query to many references.

    Args:
        query: (n,) or (n, C) samples.
        references: an (R, m, C) array, an (R, m) array of one-channel
            references, or a sequence of (m_r, C) / (m_r,) arrays of any lengths.
        window: Sakoe–Chiba half-width in samples (module docstring); None: none.
        subsequence: open-begin/open-end matching (module docstring).

    Returns:
        (R,) distances: sums of Euclidean local distances along the best paths.

    Raises:
        ValueError: on empty sequences, channel-count mismatches, non-finite
            samples, a negative window, or a window with ``subsequence``.
    """
    q = _as_sequence(query, "query")
    _check_options(window, subsequence)
    return _distances(q, _pack(references, q.shape[1]), window, subsequence)


def ddtw_many(
    query: ArrayLike,
    references: References,
    *,
    window: int | None = None,
    subsequence: bool = False,
) -> NDArray[np.float64]:
    """Derivative DTW: :func:`dtw_many` on Keogh & Pazzani derivatives (Eq. 19–20).

    Each sequence (query and every reference) is differentiated on its own, so
    a constant offset between query and reference does not count.

    Args:
        query: (n,) or (n, C) samples, n ≥ 3.
        references: as :func:`dtw_many`, each with ≥ 3 samples.
        window: Sakoe–Chiba half-width in samples; None: none.
        subsequence: open-begin/open-end matching.

    Returns:
        (R,) distances between the derivative sequences.
    """
    q = derivative(_as_sequence(query, "query"))
    _check_options(window, subsequence)
    return _distances(q, _derivative_packed(_pack(references, q.shape[1])), window, subsequence)


def hv_ddtw_many(
    query_hv: ArrayLike,
    references_hv: References,
    *,
    window: int | None = None,
    subsequence: bool = False,
) -> NDArray[np.float64]:
    """HV-DDTW (Alg. 1): DDTW of HV fingerprints with local distance √(ΔM_H² + ΔM_V²).

    The inputs are the HV fingerprints (B_H, B_V) of Eq. 17–18 (see
    :func:`~indoorsim.estimators.fingerprint.hv.hv_components`); their
    derivatives (M_H, M_V) of Eq. 19–20 are taken here.

    Args:
        query_hv: (n, 2) measured fingerprint (B_H, B_V), n ≥ 3.
        references_hv: (R, m, 2) array or sequence of (m_r, 2) reference
            fingerprints, each with ≥ 3 samples.
        window: Sakoe–Chiba half-width in samples; None: none.
        subsequence: open-begin/open-end matching.

    Returns:
        (R,) fingerprint distances D of Alg. 1.
    """
    q = _as_sequence(query_hv, "query_hv")
    if q.shape[1] != 2:
        raise ValueError(f"an HV fingerprint has 2 channels (B_H, B_V), got {q.shape[1]}")
    return ddtw_many(q, references_hv, window=window, subsequence=subsequence)


def md_dtw_many(
    query_rss: ArrayLike,
    references_rss: References,
    *,
    floor_dbm: float = DEFAULT_FLOOR_DBM,
    window: int | None = None,
    subsequence: bool = False,
) -> NDArray[np.float64]:
    """MD-DTW of WiFi RSS sequences (Chen2022 §"WiFi matching", after Li et al. 2016).

    Each sample is a scan: one RSS per access point, the APs in the same order
    in query and references. The local distance is the Euclidean distance over
    the APs. An AP a scan did not hear (NaN) counts as ``floor_dbm``, and
    readings below the floor are raised to it, so "not heard" and "barely
    heard" are the same. The default −110 dBm is what the observation windows
    report for an unheard AP (``indoorsim.windows.NO_SIGNAL_DBM``).

    Args:
        query_rss: (n, A) RSS, dBm, NaN where unheard.
        references_rss: (R, m, A) array or sequence of (m_r, A) RSS sequences.
        floor_dbm: RSS of an unheard AP, dBm.
        window: Sakoe–Chiba half-width in scans; None: none.
        subsequence: open-begin/open-end matching.

    Returns:
        (R,) distances, dB.
    """
    q = _as_sequence(query_rss, "query_rss")
    _check_options(window, subsequence)
    refs = _pack(references_rss, q.shape[1])
    refs = refs._replace(flat=_floor_rss(refs.flat, floor_dbm))
    return _distances(_floor_rss(q, floor_dbm), refs, window, subsequence)


def match_subsequence(query: ArrayLike, references: References) -> SubsequenceMatch:
    """Open-begin/open-end DTW: the best segment of each reference for the query.

    Distances as :func:`dtw_many` with ``subsequence=True``, plus where the
    segment lies. Ties between predecessors go to the diagonal, then to
    D(i−1, j), then to D(i, j−1); between end points to the first. For the
    derivative variants pass :func:`~indoorsim.estimators.fingerprint.hv.derivative`
    of the query and of the references: the derivative keeps sample indices.

    Args:
        query: (n,) or (n, C) samples.
        references: as :func:`dtw_many`.

    Returns:
        Distances and segment bounds, each (R,).

    >>> match = match_subsequence([5.0, 6.0], [[0.0, 5.0, 6.0, 0.0]])
    >>> match.distance.tolist(), match.start.tolist(), match.stop.tolist()
    ([0.0], [1], [3])
    """
    q = _as_sequence(query, "query")
    refs = _pack(references, q.shape[1])
    _check_finite(q, refs)
    return _match(q, refs)


def weighted_knn(distances: ArrayLike, positions: ArrayLike, *, k: int = 4) -> NDArray[np.float64]:
    """Position from the k references nearest in sequence distance (Chen2022 Eq. 21).

    p̂ = Σ_i c_i·p_i over the k smallest distances D_i, with c_i = (1/D_i) / Σ_j 1/D_j.
    The text normalises by C = Σ D_i, a typo (PAPER_NOTES, Chen2022 item 5);
    the rule is that of :class:`~indoorsim.estimators.fingerprint.knn.WKNN`,
    here on precomputed DTW distances. References at distance 0 take all the
    weight, equally among themselves.

    Args:
        distances: (R,) distances of one query, or (Q, R) of Q queries.
        positions: (R, 2) reference positions, m.
        k: neighbours per estimate (fewer if there are fewer references).

    Returns:
        (2,) position, or (Q, 2) for (Q, R) distances, m.

    Raises:
        ValueError: on shape mismatches, k < 1, or distances that are not
            finite and non-negative.

    >>> weighted_knn([1.0, 3.0, 9.0], [[0.0, 0.0], [4.0, 0.0], [9.0, 9.0]], k=2).tolist()
    [1.0, 0.0]
    """
    d = np.asarray(distances, dtype=float)
    p = np.asarray(positions, dtype=float)
    single = d.ndim == 1
    d = np.atleast_2d(d)
    if k < 1:
        raise ValueError(f"k must be ≥ 1, got {k}")
    if d.ndim != 2 or p.ndim != 2 or p.shape[0] != d.shape[1] or p.shape[0] == 0:
        raise ValueError(
            f"need (R,) or (Q, R) distances and (R, 2) positions, got {d.shape}, {p.shape}"
        )
    if not np.isfinite(d).all() or (d < 0).any():
        raise ValueError("distances must be finite and non-negative")
    k = min(k, d.shape[1])
    idx = np.argpartition(d, k - 1, axis=1)[:, :k]
    nearest = np.take_along_axis(d, idx, axis=1)
    exact = nearest == 0.0
    inv = np.divide(1.0, nearest, out=np.zeros_like(nearest), where=~exact)
    c = np.where(exact.any(axis=1, keepdims=True), exact, inv)  # Eq. 21: c_i = 1/D_i
    c /= c.sum(axis=1, keepdims=True)
    estimate = np.einsum("qk,qkd->qd", c, p[idx])
    return estimate[0] if single else estimate


# ------------------------------------------------------------- input handling


def _as_sequence(x: ArrayLike, name: str) -> NDArray[np.float64]:
    """(n, C) float64 view of an (n,) or (n, C) sequence."""
    a = np.asarray(x, dtype=float)
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2 or a.shape[0] == 0 or a.shape[1] == 0:
        raise ValueError(f"{name} must be a non-empty (n,) or (n, C) array, got {np.shape(x)}")
    return a


def _pack(references: References, channels: int) -> _Packed:
    """References as one (T, C) block with per-reference offsets and lengths."""
    if isinstance(references, np.ndarray):
        a = np.asarray(references, dtype=float)
        if a.ndim == 2:
            a = a[:, :, None]
        if a.ndim != 3 or a.shape[1] == 0:
            raise ValueError(
                f"references array must be (R, m, C) or (R, m), got {references.shape}"
            )
        n_refs, m, c = a.shape
        flat = a.reshape(n_refs * m, c)
        starts = np.arange(n_refs, dtype=np.int64) * m
        lengths = np.full(n_refs, m, dtype=np.int64)
    else:
        seqs = [_as_sequence(r, f"references[{k}]") for k, r in enumerate(references)]
        flat = np.concatenate(seqs) if seqs else np.empty((0, channels))
        lengths = np.array([len(s) for s in seqs], dtype=np.int64)
        starts = np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64)
    if flat.shape[1] != channels:
        raise ValueError(
            f"references have {flat.shape[1]} channel(s), the query {channels}"
            " (pass a single reference as [reference])"
        )
    return _Packed(np.ascontiguousarray(flat), starts, lengths)


def _derivative_packed(refs: _Packed) -> _Packed:
    """Eq. 19–20 on every reference at once; each reference keeps its own end points."""
    if len(refs.lengths) == 0:
        return refs
    if refs.lengths.min() < 3:
        raise ValueError("derivative DTW needs references of at least 3 samples")
    d = derivative(refs.flat)  # interior values straddling two references are overwritten below
    last = refs.starts + refs.lengths - 1
    d[refs.starts] = d[refs.starts + 1]
    d[last] = d[last - 1]
    return refs._replace(flat=d)


def _floor_rss(rss: NDArray[np.float64], floor_dbm: float) -> NDArray[np.float64]:
    """Unheard (NaN) and weaker-than-floor readings set to the floor, dBm."""
    return np.maximum(np.where(np.isnan(rss), floor_dbm, rss), floor_dbm)


def _check_options(window: int | None, subsequence: bool) -> None:
    if window is not None and window < 0:
        raise ValueError(f"window must be ≥ 0 samples, got {window}")
    if window is not None and subsequence:
        raise ValueError("a Sakoe–Chiba window cannot be combined with subsequence matching")


def _check_finite(query: NDArray[np.float64], refs: _Packed) -> None:
    if not (np.isfinite(query).all() and np.isfinite(refs.flat).all()):
        raise ValueError("query and references must be finite")


def _distances(
    query: NDArray[np.float64], refs: _Packed, window: int | None, subsequence: bool
) -> NDArray[np.float64]:
    """Run the compiled kernel matching the options."""
    _check_finite(query, refs)
    if subsequence:
        return _match(query, refs).distance
    n_refs = len(refs.lengths)
    out = np.empty(n_refs)
    if n_refs == 0:
        return out
    n = len(query)
    if window is None:  # bounds every cell meets: j − i ∈ [−(n − 1), m − 1]
        lo = np.full(n_refs, n, dtype=np.int64)
        hi = refs.lengths.copy()
    else:
        lo = window + np.maximum(0, n - refs.lengths)
        hi = window + np.maximum(0, refs.lengths - n)
    _dtw_kernel(
        np.ascontiguousarray(query),
        refs.flat,
        refs.starts,
        refs.lengths,
        np.argsort(refs.lengths, kind="stable"),  # similar lengths share a batch
        lo,
        hi,
        out,
    )
    return out


def _match(query: NDArray[np.float64], refs: _Packed) -> SubsequenceMatch:
    """Run the open-begin/open-end kernel."""
    n_refs = len(refs.lengths)
    distance = np.empty(n_refs)
    start = np.empty(n_refs, dtype=np.int64)
    stop = np.empty(n_refs, dtype=np.int64)
    if n_refs:
        _subsequence_kernel(
            np.ascontiguousarray(query), refs.flat, refs.starts, refs.lengths, distance, start, stop
        )
    return SubsequenceMatch(distance=distance, start=start, stop=stop)


# ------------------------------------------------------------- compiled kernels
# Batched layout: up to _LANES references are gathered into ref[j, c, b] and the
# DP is kept as one row per lane, row[j + 1, b] = D(i, j) (row[0, b] = D(i, −1) = ∞),
# overwritten in place as i advances; diag[b] holds D(i−1, j−1). Every innermost
# loop runs over the lanes b, which the compiler turns into SIMD. The
# one-reference kernels keep D(i, j−1) and D(i−1, j−1) in registers instead.


@numba.njit(cache=True, inline="always")
def _distance_squared(query, i, reference, j):  # pragma: no cover - compiled
    """‖q_i − r_j‖² (Alg. 1, line 3, before the root)."""
    s = 0.0
    for c in range(query.shape[1]):
        e = query[i, c] - reference[j, c]
        s += e * e
    return s


@numba.njit(cache=True, inline="always")
def _lanes_distance_squared(query, i, ref, j, n_lanes, acc):  # pragma: no cover - compiled
    """acc[b] = ‖q_i − r_j‖² for every lane b (Alg. 1, line 3, before the root)."""
    for b in range(n_lanes):
        acc[b] = 0.0
    for c in range(query.shape[1]):
        qc = query[i, c]
        for b in range(n_lanes):
            e = qc - ref[j, c, b]
            acc[b] += e * e


@numba.njit(cache=True)
def _dtw_pair(query, reference, lo, hi):  # pragma: no cover - compiled
    """Alg. 1 for one reference within the band −lo ≤ j − i ≤ hi: D(n−1, m−1)."""
    n = query.shape[0]
    m = reference.shape[0]
    row = np.full(m + 1, np.inf)  # row[j + 1] = D(i, j), row[0] = D(i, −1) = ∞
    for i in range(n):
        j_lo = max(0, i - lo)
        j_hi = min(m - 1, i + hi)
        # D(−1, −1) = 0 starts the path (line 6). Left of the band, row[j_lo] still
        # holds D(i−1, j_lo−1): the diagonal predecessor, so it changes no minimum.
        diag = (0.0 if i == 0 else np.inf) if j_lo == 0 else row[j_lo]
        left = row[j_lo]
        for j in range(j_lo, j_hi + 1):
            up = row[j + 1]
            best = min(up, diag, left)  # line 8: D(i−1, j), D(i−1, j−1), D(i, j−1)
            diag = up
            left = math.sqrt(_distance_squared(query, i, reference, j)) + best
            row[j + 1] = left
    return row[m]


@numba.njit(cache=True)
def _gather(flat, starts, lengths, order, first, n_real, ref):  # pragma: no cover - compiled
    """Copy references order[first:first + n_real] into ref[j, c, b]; the longest length."""
    m = 0
    for b in range(n_real):
        r = order[first + b]
        s = starts[r]
        m = max(m, lengths[r])
        for j in range(lengths[r]):
            for c in range(flat.shape[1]):
                ref[j, c, b] = flat[s + j, c]
    return m


@numba.njit(cache=True)
def _dtw_kernel(query, flat, starts, lengths, order, lo, hi, out):  # pragma: no cover - compiled
    """Alg. 1 with a per-reference band −lo[r] ≤ j − i ≤ hi[r]; out[r] = D(n−1, m_r−1)."""
    n, channels = query.shape
    n_refs = order.shape[0]
    width = min(_LANES, -(-n_refs // _SIMD) * _SIMD)
    m_max = lengths.max()
    ref = np.zeros((m_max, channels, width))
    row = np.empty((m_max + 1, width))
    acc = np.empty(width)
    diag = np.empty(width)
    lane_lo = np.zeros(width, dtype=np.int64)  # padding lanes compute results never read
    lane_hi = np.zeros(width, dtype=np.int64)
    for first in range(0, n_refs, _LANES):
        n_real = min(_LANES, n_refs - first)
        if n_real < _SIMD:
            for b in range(n_real):
                r = order[first + b]
                out[r] = _dtw_pair(query, flat[starts[r] : starts[r] + lengths[r]], lo[r], hi[r])
            continue
        n_lanes = -(-n_real // _SIMD) * _SIMD
        m = _gather(flat, starts, lengths, order, first, n_real, ref)
        band_lo = 0
        band_hi = 0
        for b in range(n_real):
            r = order[first + b]
            lane_lo[b] = lo[r]
            lane_hi[b] = hi[r]
            band_lo = max(band_lo, lo[r])
            band_hi = max(band_hi, hi[r])
        row[: m + 1, :n_lanes] = np.inf
        for i in range(n):
            # Only the batch's band is visited; as in _dtw_pair, the stale cell left
            # of it equals the diagonal predecessor.
            j_lo = max(0, i - band_lo)
            j_hi = min(m - 1, i + band_hi)
            for b in range(n_lanes):
                diag[b] = (0.0 if i == 0 else np.inf) if j_lo == 0 else row[j_lo, b]
            for j in range(j_lo, j_hi + 1):
                _lanes_distance_squared(query, i, ref, j, n_lanes, acc)
                k = j - i
                for b in range(n_lanes):
                    up = row[j + 1, b]
                    best = min(up, diag[b], row[j, b])  # line 8
                    diag[b] = up
                    inside = -lane_lo[b] <= k <= lane_hi[b]
                    row[j + 1, b] = (math.sqrt(acc[b]) if inside else np.inf) + best
        for b in range(n_real):
            r = order[first + b]
            out[r] = row[lengths[r], b]


@numba.njit(cache=True)
def _subsequence_pair(query, reference):  # pragma: no cover - compiled
    """Open-begin/open-end Alg. 1 for one reference: (distance, start, stop)."""
    n = query.shape[0]
    m = reference.shape[0]
    row = np.empty(m)  # row[j] = D(i, j)
    origin = np.empty(m, dtype=np.int64)  # first reference sample of that path
    for j in range(m):  # open begin: D(0, j) = d(0, j), the path starts at j
        row[j] = math.sqrt(_distance_squared(query, 0, reference, j))
        origin[j] = j
    for i in range(1, n):
        diag, diag_origin = np.inf, 0
        left, left_origin = np.inf, 0
        for j in range(m):
            up, up_origin = row[j], origin[j]
            best, best_origin = diag, diag_origin
            if up < best:
                best, best_origin = up, up_origin
            if left < best:
                best, best_origin = left, left_origin
            diag, diag_origin = up, up_origin
            left = math.sqrt(_distance_squared(query, i, reference, j)) + best
            left_origin = best_origin
            row[j], origin[j] = left, left_origin
    end = np.argmin(row)  # open end: the first best last sample
    return row[end], origin[end], end + 1


@numba.njit(cache=True)
def _subsequence_kernel(
    query, flat, starts, lengths, distance, start, stop
):  # pragma: no cover - compiled
    """:func:`_subsequence_pair` over every reference (SIMD over references gains nothing here)."""
    for r in range(lengths.shape[0]):
        distance[r], start[r], stop[r] = _subsequence_pair(
            query, flat[starts[r] : starts[r] + lengths[r]]
        )
