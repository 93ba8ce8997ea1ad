"""Tent-ASO-BP fitting time for both of Han2023's layers, at the paper's settings.

Data (synthetic, seeded). Layer 1: a fingerprint library of 3000 points, the
size of ``han2023_corridor``'s (its ≈196 m² surveyed L-shaped region at
0.25 m spacing gives ≈3100), with positions uniform in the L and four
features (Mx, My, Mz in µT, light in lux) that are smooth random functions of
position (sums of random plane waves). Layer 2: 670 points, five training
walks of the corridor route's 134 steps, with inputs (x_GML, y_GML, x_PDR,
y_PDR) = the position plus a 1.5 m Gaussian error and plus a smooth drift,
and the position as target.

Each layer is fitted by :class:`~indoorsim.estimators.nn.TentAsoBP` with the
paper's settings (population 30, 500 iterations, 1000 BP epochs, lr 0.01,
momentum 0.5). Printed per layer, each the best of three interleaved runs:
the wall time of ``fit`` (target for both layers together ≤ 60 s on this
2-core machine); the time of the search alone, population-batched (the 30
networks in one pass per iteration); and the same search with one network evaluated at a time (a
``BPNetwork`` per atom per iteration, as a per-atom loop would do), timed over
50 iterations and extrapolated linearly to 500 — every iteration costs the
same (same population, same objective, same ASO arithmetic) — with the ratio
of the two. The mean training error after the fit is printed as a sanity
check, not as a result.

Run: ``python benchmarks/bench_tent_aso_bp.py [--threads N]``. Without
``--threads`` torch keeps its default intra-op threads (the library never
changes them); ``--threads 1`` is much faster when other processes keep the
cores busy, because the batched kernels are then split over contended threads.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
import torch
from numpy.typing import NDArray

from indoorsim.estimators.nn import (
    BPNetwork,
    MinMaxScaler,
    TentAsoBP,
    n_params,
    population_objective,
)
from indoorsim.estimators.optim import ASO, Objective

N_LIBRARY, N_WALK_STEPS = 3000, 5 * 134
POPULATION, ITERATIONS, EPOCHS = 30, 500, 1000
LOOP_ITERATIONS, REPEATS = 50, 3


def smooth_field(
    pos: NDArray[np.float64], rng: np.random.Generator, waves: int = 6
) -> NDArray[np.float64]:
    """A smooth random scalar field of position: a sum of plane waves, unit amplitude scale."""
    k = rng.normal(0.0, 0.25, (waves, 2))
    phase = rng.uniform(0.0, 2 * np.pi, waves)
    amp = rng.uniform(0.5, 1.0, waves)
    return np.sin(pos @ k.T + phase) @ amp


def l_corridor(n: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """Points uniform in han2023_corridor's surveyed L: y ∈ [28.6, 31] or x ∈ [52.6, 55]."""
    x_arm, y_arm = 54.0 * 2.4, 2.4 * 27.6
    in_x_arm = rng.random(n) < x_arm / (x_arm + y_arm)
    return np.where(
        in_x_arm[:, None],
        np.column_stack([rng.uniform(1.0, 55.0, n), rng.uniform(28.6, 31.0, n)]),
        np.column_stack([rng.uniform(52.6, 55.0, n), rng.uniform(1.0, 28.6, n)]),
    )


def layer_one_data(rng: np.random.Generator) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    pos = l_corridor(N_LIBRARY, rng)
    offset, gain = np.array([20.0, -5.0, -40.0, 150.0]), np.array([8.0, 8.0, 6.0, 120.0])
    features = offset + gain * np.column_stack([smooth_field(pos, rng) for _ in range(4)])
    return features, pos


def layer_two_data(rng: np.random.Generator) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    pos = l_corridor(N_WALK_STEPS, rng)
    gml = pos + rng.normal(0.0, 1.5, pos.shape)
    drift = np.column_stack([smooth_field(pos, rng), smooth_field(pos, rng)])
    return np.hstack([gml, pos + 2.0 * drift]), pos


def one_at_a_time_objective(
    x: torch.Tensor, y: torch.Tensor, scale: torch.Tensor, hidden: int
) -> Objective:
    """Eq. 31 like :func:`population_objective`, but one network per atom."""

    def objective(atoms: NDArray[np.float64]) -> NDArray[np.float64]:
        out = np.empty(len(atoms))
        with torch.no_grad():
            for i, theta in enumerate(atoms):
                pred = BPNetwork(theta, n_in=x.shape[1], hidden=hidden, n_out=y.shape[1])(x)
                out[i] = torch.linalg.vector_norm((pred - y) * scale, dim=-1).sum().item()
        return out

    return objective


def best_times(*fns: Callable[[], object]) -> list[float]:
    """Best of REPEATS wall times of each function, the runs interleaved.

    Interleaving spreads the load of other processes on a shared machine
    evenly over the contenders instead of on whichever runs during a spike.
    """
    best = [np.inf] * len(fns)
    for _ in range(REPEATS):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            best[i] = min(best[i], time.perf_counter() - t0)
    return best


def bench_layer(name: str, x: NDArray[np.float64], y: NDArray[np.float64], seed: int) -> float:
    """Print one layer's figures; return the wall time of the fit, s."""
    model = TentAsoBP(population=POPULATION, iterations=ITERATIONS, epochs=EPOCHS)
    xs, ys = MinMaxScaler().fit(x), MinMaxScaler().fit(y)
    xt, yt = torch.from_numpy(xs.transform(x)), torch.from_numpy(ys.transform(y))
    scale = torch.from_numpy(ys.scale)
    d = n_params(x.shape[1], model.hidden, y.shape[1])
    lower, upper = np.full(d, -model.bound), np.full(d, model.bound)

    def search(objective: Objective, iterations: int) -> Callable[[], object]:
        aso = ASO(population=POPULATION, iterations=iterations, tent_init=True)
        return lambda: aso.minimize(objective, lower, upper, np.random.default_rng(seed))

    t_fit, t_batched, t_loop = best_times(
        lambda: model.fit(x, y, np.random.default_rng(seed)),
        search(population_objective(xt, yt, scale, hidden=model.hidden), ITERATIONS),
        search(one_at_a_time_objective(xt, yt, scale, model.hidden), LOOP_ITERATIONS),
    )
    t_loop_full = t_loop * ITERATIONS / LOOP_ITERATIONS
    error = np.linalg.norm(model.predict(x) - y, axis=1).mean()

    print(f"{name}: {len(x)} points, {x.shape[1]} → {y.shape[1]}, D = {d}")
    print(f"  fit (search + {EPOCHS} BP epochs)      {t_fit:7.2f} s")
    print(
        f"  search, {POPULATION} networks per pass        {t_batched:7.2f} s  "
        f"({ITERATIONS} iterations)"
    )
    print(
        f"  search, one network at a time       {t_loop_full:7.2f} s  "
        f"(extrapolated from {LOOP_ITERATIONS} iterations: {t_loop:.2f} s)"
    )
    print(f"  one-at-a-time / batched search      {t_loop_full / t_batched:7.1f}×")
    baseline = np.linalg.norm(y - y.mean(axis=0), axis=1).mean()
    print(f"  mean training error after the fit   {error:7.2f} m  (the mean: {baseline:.2f} m)")
    return t_fit


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--threads", type=int, default=0, help="torch intra-op threads (0: default)"
    )
    args = parser.parse_args()
    if args.threads > 0:
        torch.set_num_threads(args.threads)
    print(
        f"torch {torch.__version__}, {torch.get_num_threads()} intra-op threads; "
        f"population {POPULATION}, {ITERATIONS} iterations, {EPOCHS} BP epochs"
    )
    rng = np.random.default_rng(2023)
    t1 = bench_layer("layer 1 (Mx, My, Mz, L) → (x, y)", *layer_one_data(rng), seed=1)
    t2 = bench_layer("layer 2 (x_GML, y_GML, x_PDR, y_PDR) → (x, y)", *layer_two_data(rng), seed=2)
    print(f"both layers: {t1 + t2:.2f} s (target ≤ 60 s)")


if __name__ == "__main__":
    main()
