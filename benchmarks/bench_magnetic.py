"""Magnetic field throughput: 100 000 points × 240 dipoles on one core.

Prints point–dipole pairs per second for ``indoorsim.world.magnetic.dipole_field``
and for a straightforward numpy reference (broadcast r = p − q over (N, M, 3)
blocks, textbook formula) timed in the same run, their ratio, and the largest
difference between the two results.

Run: ``python benchmarks/bench_magnetic.py`` (BLAS is limited to one thread).
"""

from __future__ import annotations

import time

import numpy as np
from threadpoolctl import threadpool_limits

from indoorsim.world.magnetic import dipole_field

N_POINTS, N_DIPOLES, REPEATS = 100_000, 240, 3


def reference_field(
    p: np.ndarray, q: np.ndarray, m: np.ndarray, min_distance: float = 0.05
) -> np.ndarray:
    """Textbook B = μ0/4π Σ [3(m·r̂)r̂ − m]/r³ with (block, M, 3) broadcasting, in µT."""
    out = np.empty_like(p)
    block = 2000
    for i in range(0, len(p), block):
        r = p[i : i + block, None, :] - q[None]
        d = np.maximum(np.linalg.norm(r, axis=-1), min_distance)
        rhat = r / d[..., None]
        term = 3 * np.sum(m * rhat, axis=-1)[..., None] * rhat - m
        out[i : i + block] = np.sum(term / d[..., None] ** 3, axis=1) * 0.1
    return out


def best_time(fn, *args) -> tuple[float, np.ndarray]:
    best, result = np.inf, None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        result = fn(*args)
        best = min(best, time.perf_counter() - t0)
    return best, result


def main() -> None:
    rng = np.random.default_rng(0)
    points = np.column_stack(
        [rng.uniform(0, 40, N_POINTS), rng.uniform(0, 20, N_POINTS), np.full(N_POINTS, 1.2)]
    )
    dipoles = np.column_stack(
        [
            rng.uniform(0, 40, N_DIPOLES),
            rng.uniform(0, 20, N_DIPOLES),
            rng.uniform(-3, 6, N_DIPOLES),
        ]
    )
    moments = rng.normal(0, 20, (N_DIPOLES, 3))
    pairs = N_POINTS * N_DIPOLES
    with threadpool_limits(limits=1):
        t_fast, fast = best_time(dipole_field, points, dipoles, moments)
        t_ref, ref = best_time(reference_field, points, dipoles, moments)
    print(f"magnetic field, {N_POINTS} points x {N_DIPOLES} dipoles, one core (best of {REPEATS})")
    print(
        f"  indoorsim dipole_field : {t_fast * 1e3:8.1f} ms  {pairs / t_fast / 1e6:7.1f} M pairs/s"
    )
    print(f"  numpy reference        : {t_ref * 1e3:8.1f} ms  {pairs / t_ref / 1e6:7.1f} M pairs/s")
    print(f"  ratio (reference time / indoorsim time): {t_ref / t_fast:.1f}x")
    print(
        f"  max |difference|: {np.abs(fast - ref).max():.2e} µT"
        f" (field scale {np.abs(ref).max():.0f} µT)"
    )


if __name__ == "__main__":
    main()
