"""``indoorsim simulate`` and ``indoorsim survey``: one walk or one survey plan, to a folder.

Both run the simulator on one scenario and write what it measured, a
recording folder or a fingerprint database, then print a one-paragraph summary.
"""

from __future__ import annotations

import argparse
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from indoorsim.cli.args import (
    CliError,
    check_out,
    device_profile,
    mode_schedule,
    route_or_first,
    seed_number,
    working,
)

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers
    from indoorsim.io.fingerprints import FingerprintDB
    from indoorsim.io.recording import Recording
    from indoorsim.scenario.schema import GridSurveySpec, Scenario, WalkSurveySpec

__all__ = ["add_simulate", "add_survey"]

# ------------------------------------------------------------------- simulate

_SCHEDULE_HELP = """\
carrying mode:
  --mode takes one carrying mode for the whole walk (handheld, calling, dangling,
  pocketed, or one a plug-in adds), or a schedule of modes: comma-separated
  entries START:MODE, START in seconds from the start of the walk. The first
  entry starts at 0 and may omit its time. Example:

      --mode handheld,30:calling,60:pocketed

  holds the phone in the hand from 0 s, at the ear from 30 s and in a pocket
  from 60 s. Each change takes 1.5 s, so starts must be at least that far apart
  and before the walk ends.
"""


def add_simulate(subparsers: Subparsers) -> None:
    """Declare ``indoorsim simulate``."""
    parser = subparsers.add_parser(
        "simulate",
        help="simulate one walk and write it as a recording folder",
        # Raw, so that the schedule example keeps its layout; hence the line breaks.
        description="Walk one of a scenario's routes with a phone carried as --mode and\n"
        "write the sensor streams and the truth as a recording folder (Parquet\n"
        "files and manifest.json), then print a summary.",
        epilog=_SCHEDULE_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "scenario", metavar="SCENARIO", help="a bundled scenario name or a scenario YAML file"
    )
    parser.add_argument(
        "--route",
        metavar="NAME",
        help="a route of the scenario (default: its first; `indoorsim scenarios SCENARIO` "
        "lists them)",
    )
    parser.add_argument(
        "--mode",
        required=True,
        metavar="MODE",
        help="a carrying mode, or a schedule such as handheld,30:calling,60:pocketed (see below)",
    )
    parser.add_argument(
        "--device",
        required=True,
        metavar="DEVICE",
        help="the phone's device profile, e.g. ideal (no sensor errors) or honor_50",
    )
    parser.add_argument(
        "--seed", type=seed_number, required=True, metavar="N", help="seed of the run (>= 0)"
    )
    parser.add_argument(
        "--walker",
        type=Path,
        metavar="FILE",
        help="the walker's parameters: a YAML file, such as `indoorsim calibrate` writes "
        "(default: an average adult)",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the recording folder to write"
    )
    parser.add_argument(
        "--overwrite", action="store_true", help="replace an earlier recording at --out"
    )
    parser.set_defaults(handler=_run_simulate)


def _run_simulate(args: argparse.Namespace) -> int:
    check_out(args.out, overwrite=args.overwrite, what="recording")
    # Imported here: the simulator (numba, pymunk, scipy) is slow to import
    # and not needed by the other subcommands.
    from indoorsim.scenario.load import load_site
    from indoorsim.simulate import simulate
    from indoorsim.walker.route import RouteError
    from indoorsim.walker.schedule import ScheduleError

    site = load_site(args.scenario)
    mode = mode_schedule(args.mode)
    device = device_profile(args.device)
    walker = None
    if args.walker is not None:
        from indoorsim.benchmark.realism.calibrate import CalibrationError, load_walker

        try:
            walker = load_walker(args.walker)
        except CalibrationError as err:
            raise CliError(f"--walker {err}") from None
    route = route_or_first(site, args.route)  # last: it says which route when defaulting
    try:
        with working(f"simulating {site.name}, route {route}"):
            rec = simulate(
                site, route=route, mode=mode, device=device, seed=args.seed, walker=walker
            )
    except RouteError as err:
        raise CliError(f"--route {route}: {err}") from None
    except ScheduleError as err:
        # The carrying model checks a schedule against the walk itself (1.5 s
        # between changes, every start before the walk ends).
        raise CliError(f"--mode {args.mode}: {err}") from None
    path = rec.save(args.out, overwrite=args.overwrite)
    print(_recording_summary(rec, path, args.mode))
    return 0


def _recording_summary(rec: Recording, path: Path, mode: str) -> str:
    """One paragraph: what was walked, how far and long, and how many samples each stream has."""
    import numpy as np

    meta = rec.meta
    body = rec.truth[["body_x", "body_y"]].to_numpy()
    walked = float(np.linalg.norm(np.diff(body, axis=0), axis=1).sum())
    counts = [
        f"{name} {len(df)} readings in {df.index.nunique()} scans"
        if name == "wifi"
        else f"{name} {len(df)}"
        for name, df in rec.streams.items()
    ]
    text = (
        f"Wrote {path}: {meta['scenario']}, route {meta['route']['name']}, mode {mode}, "
        f"device {meta['device']}, seed {meta['seed']}. A {rec.duration:.1f} s walk of "
        f"{walked:.1f} m in {len(rec.steps)} steps. Samples per stream: {', '.join(counts)}."
    )
    return textwrap.fill(text, width=88, break_on_hyphens=False)


# ------------------------------------------------------------------- survey


def add_survey(subparsers: Subparsers) -> None:
    """Declare ``indoorsim survey``."""
    parser = subparsers.add_parser(
        "survey",
        help="run a scenario's survey plan and write the fingerprint database",
        description="Run the offline phase as the papers did: a grid survey (phone held "
        "still and flat at each grid point, Han2023) or a walk survey (walking a route past "
        "reference points, Chen2022), following the scenario's survey plan of that kind. "
        "Writes the FingerprintDB folder and prints a summary.",
    )
    parser.add_argument(
        "scenario", metavar="SCENARIO", help="a bundled scenario name or a scenario YAML file"
    )
    parser.add_argument(
        "--kind", required=True, choices=("grid", "walk"), help="which kind of survey"
    )
    parser.add_argument(
        "--name",
        metavar="SURVEY",
        help="the survey plan to run, when the scenario has several of --kind",
    )
    parser.add_argument(
        "--device",
        required=True,
        metavar="DEVICE",
        help="the survey phone's device profile, e.g. ideal or honor_50",
    )
    parser.add_argument(
        "--seed", type=seed_number, required=True, metavar="N", help="seed of the survey (>= 0)"
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the database folder to write"
    )
    parser.add_argument(
        "--overwrite", action="store_true", help="replace an earlier database at --out"
    )
    parser.set_defaults(handler=_run_survey)


def _survey_plan(
    scenario: Scenario, kind: str, name: str | None
) -> tuple[str, GridSurveySpec | WalkSurveySpec]:
    """The name and spec of the scenario's survey plan of ``kind`` (called ``name``, if given)."""
    plans = {n: spec for n, spec in scenario.surveys.items() if spec.kind == kind}
    listing = ", ".join(f"{n} ({spec.kind})" for n, spec in scenario.surveys.items()) or "none"
    if name is not None:
        if name not in plans:
            raise CliError(
                f"--name {name}: scenario {scenario.name!r} has no {kind} survey plan of that "
                f"name; its survey plans are: {listing}"
            )
        return name, plans[name]
    if not plans:
        raise CliError(
            f"--kind {kind}: scenario {scenario.name!r} has no {kind} survey plan; "
            f"its survey plans are: {listing}"
        )
    if len(plans) > 1:
        raise CliError(
            f"scenario {scenario.name!r} has {len(plans)} {kind} survey plans; "
            f"choose one with --name: {', '.join(plans)}"
        )
    return next(iter(plans.items()))


def _run_survey(args: argparse.Namespace) -> int:
    check_out(args.out, overwrite=args.overwrite, what="fingerprint database")
    from indoorsim.scenario.load import load_site
    from indoorsim.scenario.schema import GridSurveySpec
    from indoorsim.survey import grid_survey, walk_survey
    from indoorsim.walker.route import RouteError

    site = load_site(args.scenario)
    name, spec = _survey_plan(site.scenario, args.kind, args.name)
    device = device_profile(args.device)
    try:
        with working(f"{args.kind} survey {name!r} of {site.name}"):
            if isinstance(spec, GridSurveySpec):
                db = grid_survey(site, spec, device=device, seed=args.seed)
            else:
                db = walk_survey(site, spec, device=device, seed=args.seed)
    except RouteError as err:
        raise CliError(f"survey {name!r}: {err}") from None
    path = db.save(args.out, overwrite=args.overwrite)
    print(_survey_summary(db, path, name))
    return 0


def _columns(names: Sequence[str]) -> str:
    """Column names, with the one-per-AP ``rss_<bssid>`` columns counted rather than listed."""
    rss = [c for c in names if c.startswith("rss_")]
    shown = [c for c in names if not c.startswith("rss_")]
    if rss:
        shown.append(f"rss_<bssid> × {len(rss)}")
    return ", ".join(shown)


def _survey_summary(db: FingerprintDB, path: Path, name: str) -> str:
    """One paragraph: which survey, how many points, and each table's rows and columns."""
    meta, spec = db.meta, db.meta["spec"]
    if meta["kind"] == "grid":
        points = (
            f"{len(db['grid'])} points {spec['spacing']:g} m apart, "
            f"{spec['duration_s']:g} s at {spec['rate_hz']:g} Hz each"
        )
    else:
        passes = spec["repeats"]
        points = (
            f"{len(db['wifi'])} reference points {spec['reference_spacing']:g} m apart along "
            f"route {spec['route']}, {passes} pass{'es' if passes != 1 else ''}"
        )
    tables = "; ".join(
        f"table {table}: {len(df)} rows, columns {_columns(list(df.columns))}"
        for table, df in db.tables.items()
    )
    text = (
        f"Wrote {path}: {meta['kind']} survey {name!r} of {meta['scenario']}, device "
        f"{meta['device']}, seed {meta['seed']}: {points}. {tables}."
    )
    return textwrap.fill(text, width=88, break_on_hyphens=False)
