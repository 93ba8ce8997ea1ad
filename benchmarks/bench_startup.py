"""Start-up time of the command line, whole processes, beside ``python -c pass``.

Issue 20 ("Fast start") gives two targets for a warm machine (the compiled
kernels already cached): ``indoorsim scenarios`` ≤ 1.5 s and ``indoorsim
simulate`` of the han2023_corridor walk ≤ 3 s, each the whole process. This
runs each command as a new process (the ``indoorsim`` console script of the
interpreter running this file) ``--repeats`` times after one warm-up run, and
prints the best and the median wall time and their ratio to the reference,
``python -c pass``, timed the same way in the same run.

``--first-run`` also times the README's main job (``indoorsim leaderboard
--quick --scenario han2023_corridor``) on an empty kernel cache (a new
``INDOORSIM_CACHE_DIR``), then once more on the cache it filled: issue 20's
"fast first run", ≤ 60 s and ≤ 15 s after the install.

Run: ``python benchmarks/bench_startup.py [--repeats N] [--first-run]``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TARGETS_S = {"indoorsim scenarios": 1.5, "indoorsim simulate han2023_corridor": 3.0}
FIRST_RUN_TARGETS_S = {"first run (empty cache)": 60.0, "second run": 15.0}


def timed(cmd: list[str], repeats: int) -> list[float]:
    """Wall times of ``repeats`` runs of ``cmd`` after one untimed warm-up run."""
    subprocess.run(cmd, check=True, capture_output=True)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times.append(time.perf_counter() - t0)
    return times


def first_run(cli: str, scratch: Path) -> None:
    """The README's main job on an empty kernel cache, then again on the filled one."""
    env = {**os.environ, "INDOORSIM_CACHE_DIR": str(scratch / "cache")}
    env.pop("NUMBA_CACHE_DIR", None)  # set by any indoorsim import in this process's parent
    cmd = [cli, "leaderboard", "--quick", "--scenario", "han2023_corridor"]
    print("README main job (indoorsim leaderboard --quick --scenario han2023_corridor)")
    for k, (label, target) in enumerate(FIRST_RUN_TARGETS_S.items()):
        t0 = time.perf_counter()
        subprocess.run(
            [*cmd, "--out", str(scratch / f"board{k}")], env=env, check=True, capture_output=True
        )
        seconds = time.perf_counter() - t0
        verdict = "met" if seconds <= target else "NOT met"
        print(f"{label:>36}: {seconds:6.1f} s  target ≤ {target:g} s: {verdict}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--first-run", action="store_true", help="also time the main job cold")
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
        if args.first_run:
            first_run(cli, out)
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
