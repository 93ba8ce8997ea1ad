"""``indoorsim import-plan``: a real floor plan, and the real traces walked on it, as a scenario.

Reads an Indoor Location Competition 2.0 floor (``geojson_map.json`` and its
``floor_info.json``), builds the scenario with
:func:`~indoorsim.scenario.imports.import_ilc_floor`, adds one route per trace
in ``--traces`` (their waypoints, each leg in the surveyor's time,
:func:`~indoorsim.scenario.imports.add_trace_routes`), writes the YAML and
prints what was built, which traces were left out and why, and the time taken.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import TYPE_CHECKING

from indoorsim.cli.args import CliError, seed_number

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers

__all__ = ["add_import_plan"]


def add_import_plan(subparsers: Subparsers) -> None:
    """Declare ``indoorsim import-plan``."""
    parser = subparsers.add_parser(
        "import-plan",
        help="turn a real floor plan (Indoor Location Competition GeoJSON) into a scenario",
        description="Turn an Indoor Location Competition 2.0 floor plan (geojson_map.json, "
        "in the waypoint frame of its floor_info.json) into a scenario: walls from the floor "
        "outline and the shop polygons, a doorway on each shop's longest corridor frontage, "
        "and lights, WiFi access points and a steel frame placed by the generator's mall "
        "rules (seeded). With --traces, each trace's waypoints become a route, each leg walked "
        "in the trace's time; traces whose path cannot be walked in the scenario are listed with "
        "the reason.",
    )
    parser.add_argument("geojson", type=Path, metavar="GEOJSON", help="geojson_map.json")
    parser.add_argument(
        "--floor-info",
        type=Path,
        default=None,
        metavar="JSON",
        help="floor_info.json (default: the one beside GEOJSON)",
    )
    parser.add_argument(
        "--traces",
        type=Path,
        default=None,
        metavar="DIR",
        help="a folder of the competition's path traces (*.txt) whose waypoints become routes",
    )
    parser.add_argument(
        "--seed", type=seed_number, default=0, metavar="N", help="seeds what the plan does not show"
    )
    parser.add_argument("--name", default=None, help="scenario name (default ilc-<floor>-<seed>)")
    parser.add_argument(
        "--out", type=Path, required=True, metavar="YAML", help="the scenario file to write"
    )
    parser.add_argument("--overwrite", action="store_true", help="replace --out if it exists")
    parser.set_defaults(handler=_run_import_plan)


def _read_traces(
    folder: Path,
) -> tuple[dict[str, tuple[list[list[float]], list[float]]], dict[str, str]]:
    """Waypoints and their times of each trace in ``folder``, and the traces that have none."""
    from indoorsim.io.reallogs.ilc import looks_like_ilc_trace, read_ilc_trace
    from indoorsim.io.recording import RecordingError

    if not folder.is_dir():
        raise CliError(f"--traces {folder}: no such folder")
    files = sorted(p for p in folder.iterdir() if looks_like_ilc_trace(p))
    if not files:
        raise CliError(f"--traces {folder}: no Indoor Location Competition traces (*.txt) in it")
    traces: dict[str, tuple[list[list[float]], list[float]]] = {}
    unreadable: dict[str, str] = {}
    for path in files:
        try:
            waypoints = read_ilc_trace(path).streams.get("waypoints")
        except RecordingError as err:
            unreadable[path.stem] = f"not readable: {err}"
            continue
        if waypoints is None or len(waypoints) < 2:
            unreadable[path.stem] = "fewer than two TYPE_WAYPOINT rows"
            continue
        xy = waypoints[["x", "y"]].to_numpy()
        traces[path.stem] = (xy.tolist(), waypoints.index.to_numpy(dtype=float).tolist())
    return traces, unreadable


def _run_import_plan(args: argparse.Namespace) -> int:
    from indoorsim.scenario.imports import (
        PlanImportError,
        add_trace_routes,
        import_ilc_floor,
        read_ilc_floor,
    )
    from indoorsim.scenario.load import dump_scenario

    out: Path = args.out
    if out.is_dir():
        raise CliError(f"--out {out}: is a folder; give the scenario file to write")
    if out.exists() and not args.overwrite:
        raise CliError(f"--out {out}: already exists; pass --overwrite to replace it")
    # The scenario's folder is made, as the data set's and the leaderboard's --out are.
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise CliError(f"--out {out}: cannot make its folder ({err.strerror})") from None
    floor_info = args.floor_info or args.geojson.parent / "floor_info.json"
    start = time.perf_counter()
    try:
        floor = read_ilc_floor(args.geojson, floor_info)
        imported = import_ilc_floor(floor, seed=args.seed, name=args.name)
    except PlanImportError as err:
        raise CliError(str(err)) from None
    built = time.perf_counter() - start
    scenario = imported.scenario
    n = imported.counts()
    materials: dict[str, int] = {}
    for wall in scenario.walls:
        materials[wall.material] = materials.get(wall.material, 0) + 1
    print(
        f"imported {args.geojson} (floor {floor.floor_name or '?'}, {floor.width_m:.1f} m × "
        f"{floor.height_m:.1f} m), seed {args.seed}, in {built:.2f} s"
    )
    print(
        f"  walls {n['walls']} ({', '.join(f'{v} {k}' for k, v in sorted(materials.items()))}), "
        f"rooms {n['rooms']} ({len(imported.slivers)} sliver shops dropped), doors {n['doors']} "
        f"({len(imported.doorless)} shops without a corridor frontage for one, "
        f"{imported.escalators} escalators without)"
    )
    print(
        f"  lights {n['lights']}, APs {n['aps']} ({n['radios']} radios), columns "
        f"{n['pillars']}, steel dipoles {n['dipoles']}, rebar groups {n['rebar']}"
    )
    if args.traces is not None:
        traces, unreadable = _read_traces(args.traces)
        routes = add_trace_routes(imported, traces)
        scenario = routes.scenario
        left_out = {**unreadable, **routes.left_out}
        changed = {k: v for k, v in routes.kept.items() if v}
        print(
            f"  routes from {len(traces) + len(unreadable)} traces: {len(routes.kept)} kept "
            f"({len(changed)} with a waypoint moved into the corridor or a leg walked round a "
            f"wall), {len(left_out)} left out"
        )
        for name, notes in sorted(changed.items()):
            print(f"    kept {name}: {'; '.join(notes)}")
        for name, reason in sorted(left_out.items()):
            print(f"    left out {name}: {reason}")
        if routes.kept:
            # The traces' phone: an OPPO PBCM10 (BMI160, AK09911, Android 8.1), held flat.
            print(
                f"  a trace's twin: indoorsim simulate {out} --route {min(routes.kept)} "
                "--mode handheld --device nexus_5x (the nearest built-in profile to the "
                "traces' OPPO PBCM10)"
            )
    dump_scenario(scenario, out)
    print(f"wrote {out} ({time.perf_counter() - start:.2f} s in all)")
    return 0
