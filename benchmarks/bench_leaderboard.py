"""Leaderboard wall time: the three baselines on one scenario × four modes × three seeds.

Prints the wall time of ``leaderboard.evaluate`` for start-only, pdr-basic and
wknn-mag on ``han2023_corridor`` in every carrying mode over three seeds, and
the ratio to a reference timed in the same run: simulating the same test and
training walks alone (the floor any evaluation pays).

Run: ``python benchmarks/bench_leaderboard.py``.
"""

from __future__ import annotations

import time

from threadpoolctl import threadpool_limits

import indoorsim
from indoorsim.benchmark.evaluation import TRAIN_SEED, evaluate, site_context
from indoorsim.benchmark.leaderboard import BASELINES, MODES
from indoorsim.simulate import simulate

SCENARIO, SEEDS, N_TRAIN = "han2023_corridor", (0, 1, 2), 2


def main() -> None:
    site = indoorsim.load_site(SCENARIO)
    with threadpool_limits(limits=1):
        site_context(site, device="nexus_5x")  # surveys: measured once, outside both timings
        t0 = time.perf_counter()
        for _est in BASELINES:
            for mode in MODES:
                for k in range(N_TRAIN):
                    simulate(
                        site,
                        route="heading_test",
                        mode=mode,
                        device="nexus_5x",
                        seed=TRAIN_SEED + k,
                    )
                for seed in SEEDS:
                    simulate(site, route="trajectory", mode=mode, device="nexus_5x", seed=seed)
        t_ref = time.perf_counter() - t0
        t0 = time.perf_counter()
        for est in BASELINES:
            for mode in MODES:
                evaluate(est, site, mode=mode, seeds=SEEDS, n_train=N_TRAIN)
        t_board = time.perf_counter() - t0
    runs = len(BASELINES) * len(MODES)
    print(f"leaderboard: {len(BASELINES)} baselines x {len(MODES)} modes x {len(SEEDS)} seeds")
    print(f"  scenario {SCENARIO}, one core")
    print(f"  evaluate (fit, episodes, metrics): {t_board:6.1f} s")
    print(f"  per estimator x mode             : {t_board / runs:6.2f} s")
    print(f"  reference, simulating the walks  : {t_ref:6.1f} s")
    print(f"  ratio evaluate / simulation alone: {t_board / t_ref:.2f}")


if __name__ == "__main__":
    main()
