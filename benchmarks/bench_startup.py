"""Start-up time of the command line, whole processes, beside ``python -c pass``.

Issue 20 ("Fast start") gives two targets for a warm machine (the compiled
kernels already cached): ``indoorsim scenarios`` ≤ 1.5 s and ``indoorsim
simulate`` of the han2023_corridor walk ≤ 3 s, each the whole process. This
runs each command as a new process (the ``indoorsim`` console script of the
interpreter running this file) ``--repeats`` times after one warm-up run, and
prints the best and the median wall time and their ratio to the reference,
``python -c pass``, timed the same way in the same run.

Run: ``python benchmarks/bench_startup.py [--repeats N]``.
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TARGETS_S = {"indoorsim scenarios": 1.5, "indoorsim simulate han2023_corridor": 3.0}


def timed(cmd: list[str], repeats: int) -> list[float]:
    """Wall times of ``repeats`` runs of ``cmd`` after one untimed warm-up run."""
    subprocess.run(cmd, check=True, capture_output=True)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    cli = str(Path(sys.executable).with_name("indoorsim"))
    out = Path(tempfile.mkdtemp(prefix="bench_startup_"))
    try:
        commands = {
            "python -c pass": [sys.executable, "-c", "pass"],
            "indoorsim scenarios": [cli, "scenarios"],
            "indoorsim simulate han2023_corridor": [
                *(cli, "simulate", "han2023_corridor", "--mode", "handheld"),
                *("--device", "nexus_5x", "--seed", "1", "--out", str(out / "walk")),
                "--overwrite",
            ],
        }
        results = {name: timed(cmd, args.repeats) for name, cmd in commands.items()}
    finally:
        shutil.rmtree(out, ignore_errors=True)
    reference = min(results["python -c pass"])
    print(f"whole-process wall time, best and median of {args.repeats} warm runs")
    for name, times in results.items():
        best, median = min(times), statistics.median(times)
        target = TARGETS_S.get(name)
        verdict = (
            ""
            if target is None
            else f"  target ≤ {target:g} s: {'met' if best <= target else 'NOT met'}"
        )
        print(
            f"{name:>36}: best {best:6.2f} s  median {median:6.2f} s  "
            f"×{best / reference:5.0f} python -c pass{verdict}"
        )


if __name__ == "__main__":
    main()
