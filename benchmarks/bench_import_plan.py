"""``import-plan`` of the MS mall floor on one core, beside generating an ``open_hall``.

The "Sim-to-real" issue's target: importing the Indoor Location Competition's
MS floor (site1/F1: 172 shops, 240 m × 176 m) takes under 10 s on one core.
This times, best of ``--repeats`` after one warm-up, in one process with the
BLAS and OpenMP pools held to one thread:

* ``read + import``: :func:`~indoorsim.scenario.imports.read_ilc_floor` and
  :func:`~indoorsim.scenario.imports.import_ilc_floor` (validation included);
* ``+ trace routes``: :func:`~indoorsim.scenario.imports.add_trace_routes` of
  the 16 traces' waypoints (read once beforehand: reading traces is the io
  layer's work, timed apart);
* ``dump YAML``: :func:`~indoorsim.scenario.load.dump_scenario`;

and, as the reference, ``generate("open_hall", seed=0)``, the bundled-size
procedural mall (about a tenth of the floor area), printing each time and its
ratio to the reference.

Run: ``python benchmarks/bench_import_plan.py [--repeats N] [--realdata DIR]``.
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections.abc import Callable
from pathlib import Path

from threadpoolctl import threadpool_limits

from indoorsim.io.reallogs.ilc import read_ilc_trace
from indoorsim.scenario.generate import generate
from indoorsim.scenario.imports import (
    add_trace_routes,
    import_ilc_floor,
    read_ilc_floor,
    waypoint_speed,
)
from indoorsim.scenario.load import dump_scenario
from indoorsim.util.provenance import realdata_dir

TARGET_S = 10.0


def best(fn: Callable[[], object], repeats: int) -> tuple[float, object]:
    """Best wall time of ``repeats`` calls after one warm-up, and the last result."""
    result = fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return min(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--realdata", type=Path, default=None)
    args = parser.parse_args()
    floor_dir = realdata_dir(args.realdata) / "ms-indoor-location-2020" / "site1" / "F1"
    geojson, info = floor_dir / "geojson_map.json", floor_dir / "floor_info.json"

    t0 = time.perf_counter()
    traces = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for path in sorted((floor_dir / "path_data_files").glob("*.txt")):
            wp = read_ilc_trace(path).waypoints
            xy = wp[["x", "y"]].to_numpy()
            traces[path.stem] = (xy.tolist(), waypoint_speed(xy, wp.index.to_numpy()))
    read_traces = time.perf_counter() - t0

    with threadpool_limits(limits=1):
        reference, _ = best(lambda: generate("open_hall", seed=0), args.repeats)
        imported_s, imported = best(
            lambda: import_ilc_floor(read_ilc_floor(geojson, info), seed=0), args.repeats
        )
        routes_s, routes = best(lambda: add_trace_routes(imported, traces), args.repeats)
        dump_s, text = best(lambda: dump_scenario(routes.scenario), args.repeats)

    n = imported.counts()
    print(
        f"MS floor site1/F1: {n['walls']} walls, {n['rooms']} rooms, {n['doors']} doors, "
        f"{n['lights']} lights, {n['aps']} APs, {n['pillars']} columns; "
        f"{len(routes.kept)} of {len(traces)} traces kept as routes; YAML {len(text) / 1e6:.1f} MB"
    )
    print(f"{'step (one core, best of ' + str(args.repeats) + ')':>40}  {'time':>8}  ratio")
    rows = {
        'generate("open_hall", seed=0) [reference]': reference,
        "read + import (validated)": imported_s,
        "+ trace routes (16 traces, validated)": routes_s,
        "dump YAML": dump_s,
        "import-plan in all (read, import, routes, dump)": imported_s + routes_s + dump_s,
    }
    for label, seconds in rows.items():
        print(f"{label:>48}: {seconds:6.2f} s  {seconds / reference:5.2f}×")
    print(f"{'reading the 16 traces (io, once)':>48}: {read_traces:6.2f} s")
    total = imported_s + routes_s + dump_s
    verdict = "met" if total <= TARGET_S else "NOT met"
    print(f"target: import-plan of the MS floor ≤ {TARGET_S:g} s on one core: {verdict}")


if __name__ == "__main__":
    main()
