"""DTW throughput: one query against 1000 references, length 100, two channels, one core.

Times ``indoorsim.estimators.fingerprint.dtw.dtw_many`` and the compiled C library
dtaidistance on the same data in the same run (best of ``REPEATS`` after a
warm-up call) and prints times, DP cells per second and ratios. The two do not
compute the same number:

* ``dtw_many`` — Chen2022 Alg. 1: the **sum** of Euclidean local distances
  ‖q_i − r_j‖ along the best path.
* dtaidistance ``dtw_ndim`` — the **root of the summed squared** local distances,
  √(min over paths of Σ‖q_i − r_j‖²). Same DP, same 100 × 100 cells per pair;
  each cell skips the square root the paper's definition needs.
* dtaidistance ``dtw`` (1-D), once per channel — two independent one-channel
  DTWs (each channel warped on its own), root of summed squares: twice the
  cells, one channel each.

Both dtaidistance entry points are timed: ``distance_matrix_fast`` with a
one-row block (one C call for all pairs, ``parallel=False``) and a Python loop
of ``distance_fast`` calls. Each definition is checked against a plain-Python
brute force of itself on a few references.

dtaidistance is a benchmark-only dependency (not in pyproject's dependencies):
``pip install dtaidistance``. Run: ``python benchmarks/bench_dtw.py``.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable

import numpy as np

from indoorsim.estimators.fingerprint.dtw import dtw_many

try:
    import dtaidistance
    from dtaidistance import dtw as dtai_dtw
    from dtaidistance import dtw_ndim as dtai_ndim
except ImportError as exc:  # not a project dependency
    raise SystemExit("bench_dtw needs dtaidistance: pip install dtaidistance") from exc

N_REFS, LENGTH, CHANNELS, REPEATS, N_CHECKED = 1000, 100, 2, 7, 3
OURS = "indoorsim dtw_many (sum of ‖·‖)"
NDIM_BLOCK = "dtaidistance dtw_ndim matrix block (√Σ‖·‖²)"
NDIM_LOOP = "dtaidistance dtw_ndim distance_fast loop (√Σ‖·‖²)"


def best_time(fn: Callable[[], np.ndarray]) -> tuple[float, np.ndarray]:
    """Best wall time of ``REPEATS`` calls, s, and the last result."""
    best, result = math.inf, np.empty(0)
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def brute_dtw(query: np.ndarray, reference: np.ndarray, squared: bool) -> float:
    """Textbook recursion; local cost ‖·‖ (paper) or ‖·‖² then a final root (dtaidistance)."""
    n, m = len(query), len(reference)
    local = ((query[:, None, :] - reference[None, :, :]) ** 2).sum(axis=-1)
    local = local if squared else np.sqrt(local)

    @functools.cache
    def cost(i: int, j: int) -> float:
        d = float(local[i, j])
        if i == 0 and j == 0:
            return d
        if i == 0:
            return d + cost(0, j - 1)
        if j == 0:
            return d + cost(i - 1, 0)
        return d + min(cost(i - 1, j), cost(i - 1, j - 1), cost(i, j - 1))

    for i in range(n):  # fill row by row to keep the recursion shallow
        for j in range(m):
            cost(i, j)
    total = cost(n - 1, m - 1)
    return math.sqrt(total) if squared else total


def main() -> None:
    rng = np.random.default_rng(0)
    # Random walks, like magnetic HV sequences (µT).
    refs = rng.normal(0.0, 1.0, (N_REFS, LENGTH, CHANNELS)).cumsum(axis=1)
    query = rng.normal(0.0, 1.0, (LENGTH, CHANNELS)).cumsum(axis=0)
    series = np.ascontiguousarray(np.concatenate([query[None], refs]))
    block = ((0, 1), (1, N_REFS + 1))
    per_channel = [np.ascontiguousarray(series[:, :, c]) for c in range(CHANNELS)]
    cells = N_REFS * LENGTH * LENGTH

    t0 = time.perf_counter()
    dtw_many(query, refs)
    first_call = time.perf_counter() - t0

    runs = {  # name: (DP cells per run, call)
        OURS: (cells, lambda: dtw_many(query, refs)),
        NDIM_BLOCK: (
            cells,
            lambda: dtai_ndim.distance_matrix_fast(
                series, block=block, parallel=False, compact=True
            ),
        ),
        NDIM_LOOP: (cells, lambda: np.array([dtai_ndim.distance_fast(query, r) for r in refs])),
        "dtaidistance 1-D dtw matrix block, per channel": (
            CHANNELS * cells,
            lambda: np.array(
                [
                    dtai_dtw.distance_matrix_fast(s, block=block, parallel=False, compact=True)
                    for s in per_channel
                ]
            ),
        ),
    }
    timings = {name: best_time(fn) for name, (_, fn) in runs.items()}

    print(
        f"DTW, 1 query x {N_REFS} references, length {LENGTH}, {CHANNELS} channels, one core"
        f" (best of {REPEATS}); dtaidistance {dtaidistance.__version__}"
    )
    print(f"  indoorsim first call (numba compile or cache load): {first_call:.2f} s")
    t_ours = timings[OURS][0]
    for name, (t, _) in timings.items():
        print(
            f"  {name:<50s} {t * 1e3:7.2f} ms  {runs[name][0] / t / 1e6:6.0f} M cells/s"
            f"  time / indoorsim {t / t_ours:5.2f}"
        )

    ours, theirs, looped = (timings[name][1] for name in (OURS, NDIM_BLOCK, NDIM_LOOP))
    checked = rng.choice(N_REFS, N_CHECKED, replace=False)
    err_ours = max(abs(ours[r] - brute_dtw(query, refs[r], squared=False)) for r in checked)
    err_theirs = max(abs(theirs[r] - brute_dtw(query, refs[r], squared=True)) for r in checked)
    print(f"  brute force on {N_CHECKED} references: max |difference|")
    print(f"    indoorsim vs Σ‖·‖          {err_ours:.1e}  (distances ~{np.median(ours):.0f})")
    print(f"    dtaidistance vs √Σ‖·‖²     {err_theirs:.1e}  (distances ~{np.median(theirs):.0f})")
    print(f"    dtaidistance block vs loop {np.abs(theirs - looped).max():.1e}")
    top = 10
    overlap = len(set(np.argsort(ours)[:top]) & set(np.argsort(theirs)[:top]))
    print(
        f"  nearest reference: indoorsim #{np.argmin(ours)}, dtaidistance #{np.argmin(theirs)};"
        f" {overlap} of the {top} nearest in common"
    )


if __name__ == "__main__":
    main()
