"""``calibrate`` of one real trace on one core, beside reading it.

The "Sim-to-real" issue's target: fitting a device profile and a walker to one
trace takes under 10 s on one core. This times, best of ``--repeats`` after one
warm-up, in one process with the BLAS and OpenMP pools held to one thread:

* ``calibrate``: :func:`~indoorsim.benchmark.realism.calibrate.calibrate` of the
  largest MS Indoor Location trace file, its carrying mode removed from its
  metadata (rates, noise, hard iron, light and WiFi reporting, the walker's
  cadence, speed and height);
* ``+ vigour``: the same through the flat-held phone the sim-to-real twins use,
  which adds the vigour's straight reference walks
  (:func:`~indoorsim.benchmark.realism.vigour.fit_vigour`);

and, as the reference, reading that trace (``Recording.load``), printing each
time and its ratio to the reference.

Run: ``python benchmarks/bench_calibrate.py [--repeats N] [--realdata DIR]``.
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections.abc import Callable
from pathlib import Path

from threadpoolctl import threadpool_limits

from indoorsim.benchmark.realism.calibrate import calibrate
from indoorsim.benchmark.sim_to_real import TWIN_BASE_DEVICE, TWIN_MODE
from indoorsim.io.recording import Recording
from indoorsim.util.provenance import realdata_dir

TARGET_S = 10.0


def best(fn: Callable[[], object], repeats: int) -> float:
    """Best wall time of ``repeats`` calls after one warm-up."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--realdata", type=Path, default=None)
    args = parser.parse_args()
    folder = realdata_dir(args.realdata) / "ms-indoor-location-2020" / "site1" / "F1"
    trace = max((folder / "path_data_files").glob("*.txt"), key=lambda p: p.stat().st_size)
    with warnings.catch_warnings(), threadpool_limits(limits=1):
        warnings.simplefilter("ignore")
        rec = Recording.load(trace)
        # The ILC reader names the mode (handheld): without it the vigour is not fitted.
        bare = Recording._from_built(
            rec.streams, {k: v for k, v in rec.meta.items() if k != "mode"}
        )
        walked = float(rec.accel.index[-1] - rec.accel.index[0])
        reference = best(lambda: Recording.load(trace), args.repeats)
        plain = best(lambda: calibrate(bare, base=TWIN_BASE_DEVICE), args.repeats)
        vigour = best(lambda: calibrate(rec, base=TWIN_BASE_DEVICE, mode=TWIN_MODE), args.repeats)
    print(f"trace {trace.name}: {walked:.0f} s of recording")
    print(f"reference (read the trace): {reference:.3f} s")
    for label, seconds in (("calibrate", plain), ("calibrate + vigour", vigour)):
        verdict = "meets" if seconds < TARGET_S else "misses"
        print(
            f"{label}: {seconds:.3f} s, {seconds / reference:.1f}x the reference; "
            f"{verdict} the {TARGET_S:.0f} s target"
        )


if __name__ == "__main__":
    main()
