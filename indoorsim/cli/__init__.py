"""The ``indoorsim`` command line.

::

    indoorsim scenarios                                   # the bundled scenarios, as a table
    indoorsim simulate minimal_room --route main --mode handheld,8:calling \
        --device honor_50 --seed 1 --out walks/main-1     # one walk, as a recording folder
    indoorsim survey han2023_basement --kind grid --device honor_50 --seed 0 --out db/
    indoorsim plot site minimal_room my-site.yaml --out plots/
    indoorsim plot site --all --out plots/ --resolution 0.2
    indoorsim plot recording walks/main-1 trace.txt --out plots/
    indoorsim dataset --sites 20 --walks-per-site 8 --minutes 10 --seed 0 \
        --workers 2 --out data/          # labelled Parquet shards on Dask (resumable)
    indoorsim train --data data/ --out checkpoints/io --epochs 15   # the learned-io network

Each subcommand is a pair of functions: ``_add_<command>(subparsers)`` declares
its arguments and sets ``handler`` to ``_run_<command>(args) -> int``. Adding
a subcommand (``simulate``, ``survey``, ...) means adding one such pair and
listing its ``_add_`` function in :data:`_COMMANDS`; plot targets (``plot
recording``, ...) are listed the same way in :data:`_PLOT_TARGETS`.

Exit codes: 0 success, 1 an I/O failure while writing, 2 a usage error (bad
arguments, an unknown scenario, route, mode or device name, an invalid scenario
or data-set configuration file, an output folder that is in the way), 3 work
that finished but failed its goal (``evaluate``: a metric above its
``--fail-above`` threshold; ``dataset``: shards that still failed after their
retries, each named). Errors are printed to stderr as one clear message,
without a traceback.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
import textwrap
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, TypeAlias

from indoorsim._version import __version__
from indoorsim.scenario.load import bundled_scenarios, load_scenario, resolve_scenario
from indoorsim.scenario.schema import GridSurveySpec, Scenario, ScenarioError, WalkSurveySpec

if TYPE_CHECKING:
    from indoorsim.io.fingerprints import FingerprintDB
    from indoorsim.io.recording import Recording
    from indoorsim.phone.devices import DeviceProfile

    _Subparsers: TypeAlias = argparse._SubParsersAction[argparse.ArgumentParser]

__all__ = ["build_parser", "main"]


class CliError(Exception):
    """A usage error: printed as ``indoorsim: <message>``, exit status 2."""


def _positive(convert: Callable[[str], float]) -> Callable[[str], float]:
    """An argparse ``type`` that parses with ``convert`` and accepts only values > 0."""

    def parse(text: str) -> float:
        try:
            value = convert(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not value > 0:
            raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
        return value

    return parse


def _seed(text: str) -> int:
    """An argparse ``type`` for seeds: integers >= 0, as ``numpy.random.SeedSequence`` takes."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text}")
    return value


def _check_out(out: Path, *, overwrite: bool, what: str) -> None:
    """Refuse an ``--out`` folder that is in the way, before the slow work starts.

    The writer makes the final decision (it never replaces anything but an
    earlier ``what``); this only saves running a simulation whose result could
    not be saved.
    """
    if out.exists() and not out.is_dir():
        raise CliError(f"--out {out}: exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise CliError(
            f"--out {out}: already exists; pass --overwrite to replace it "
            f"(only an earlier {what} is ever replaced)"
        )


@contextmanager
def _working(desc: str) -> Iterator[None]:
    """A spinner-style progress bar on stderr, showing the elapsed time, around one long call.

    The survey and simulation functions report no progress of their own, so
    the bar cannot show a fraction done. Shown only when stderr is a terminal.
    """
    from tqdm import tqdm

    done = threading.Event()
    with tqdm(desc=desc, total=None, bar_format="{desc}: {elapsed}", disable=None) as bar:

        def tick() -> None:
            # Without updates tqdm would not redraw; refresh so the time moves.
            while not done.wait(0.5):
                bar.refresh()

        ticker = threading.Thread(target=tick, daemon=True)
        ticker.start()
        try:
            yield
        finally:
            done.set()
            ticker.join()


def _device(name: str) -> DeviceProfile:
    from indoorsim.phone.devices import UnknownDeviceError, get_device

    try:
        return get_device(name)
    except UnknownDeviceError as err:
        raise CliError(str(err)) from None


# ------------------------------------------------------------------- scenarios


def _add_scenarios(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "scenarios",
        help="list the bundled scenarios",
        description="List the bundled scenarios (and those added by plug-ins): size, "
        "walls, lights, access points, magnetic dipoles and a description.",
    )
    parser.set_defaults(handler=_run_scenarios)


def _one_line(text: str, width: int = 72) -> str:
    flat = " ".join(text.split())
    return flat if len(flat) <= width else flat[: width - 1].rstrip() + "…"


def _run_scenarios(args: argparse.Namespace) -> int:
    # Only the plan and the magnetic model are built: counting dipoles needs
    # the steel expanded, but not the light or radio fields.
    from indoorsim.world.magnetic import MagneticModel
    from indoorsim.world.plan import FloorPlan

    header = ("name", "size (m)", "walls", "lights", "APs", "dipoles", "description")
    rows = []
    for name, path in bundled_scenarios().items():
        scenario = load_scenario(path)
        plan = FloorPlan(scenario)
        xmin, ymin, xmax, ymax = plan.outline.bounds
        dipoles = len(MagneticModel.from_scenario(scenario, plan).positions)
        rows.append(
            (
                name,
                f"{xmax - xmin:.1f} × {ymax - ymin:.1f}",
                str(len(scenario.walls)),
                str(len(scenario.luminaires)),
                str(len(scenario.wifi)),
                str(dipoles),
                _one_line(scenario.description),
            )
        )
    if not rows:
        print("no bundled scenarios found")
        return 0
    widths = [max(len(r[i]) for r in (header, *rows)) for i in range(len(header))]
    # Names and descriptions read left-aligned; sizes and counts line up on the right.
    left = {0, len(header) - 1}
    for row in (header, *rows):
        cells = [
            cell.ljust(w) if i in left else cell.rjust(w)
            for i, (cell, w) in enumerate(zip(row, widths, strict=True))
        ]
        print("  ".join(cells).rstrip())
    return 0


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


def _add_simulate(subparsers: _Subparsers) -> None:
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
    parser.add_argument("--route", required=True, metavar="NAME", help="a route of the scenario")
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
        "--seed", type=_seed, required=True, metavar="N", help="seed of the run (>= 0)"
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the recording folder to write"
    )
    parser.add_argument(
        "--overwrite", action="store_true", help="replace an earlier recording at --out"
    )
    parser.set_defaults(handler=_run_simulate)


def _mode_schedule(text: str, valid: Sequence[str]) -> str | list[tuple[float, str]]:
    """``--mode`` as :func:`~indoorsim.simulate.simulate` takes it: a name or ``[(t, name), ...]``.

    Raises:
        CliError: bad syntax, start times not increasing from 0, or a mode not in ``valid``.
    """
    entries: list[tuple[float, str]] = []
    for i, item in enumerate(text.split(",")):
        when, colon, name = item.strip().rpartition(":")
        name = name.strip()
        if not name:
            raise CliError(f"--mode {text}: entry {i + 1} ({item!r}) names no carrying mode")
        if name not in valid:
            raise CliError(
                f"--mode {text}: unknown carrying mode {name!r}; "
                f"valid modes are: {', '.join(valid)}"
            )
        if not colon and i > 0:
            raise CliError(f"--mode {text}: {name!r} needs a start time, as in 30:{name}")
        try:
            t_start = float(when) if colon else 0.0
        except ValueError:
            t_start = math.nan
        if not (math.isfinite(t_start) and t_start >= 0):
            raise CliError(f"--mode {text}: {when.strip()!r} is not a start time in seconds >= 0")
        entries.append((t_start, name))
    if entries[0][0] != 0:
        raise CliError(f"--mode {text}: the first mode must start at 0 s, not {entries[0][0]:g} s")
    for (before, _), (after, name) in itertools.pairwise(entries):
        if after <= before:
            raise CliError(
                f"--mode {text}: start times must increase ({name} at {after:g} s "
                f"follows {before:g} s)"
            )
    return entries[0][1] if len(entries) == 1 else entries


def _run_simulate(args: argparse.Namespace) -> int:
    _check_out(args.out, overwrite=args.overwrite, what="recording")
    # Imported here: the simulator (numba, pymunk, scipy) is slow to import
    # and not needed by the other subcommands.
    from indoorsim.scenario.load import load_site
    from indoorsim.simulate import simulate
    from indoorsim.walker.carry import available_modes
    from indoorsim.walker.route import RouteError

    site = load_site(args.scenario)
    routes = site.scenario.routes
    if args.route not in routes:
        raise CliError(
            f"--route {args.route}: scenario {site.name!r} has no such route; "
            f"its routes are: {', '.join(routes) or 'none'}"
        )
    mode = _mode_schedule(args.mode, available_modes())
    device = _device(args.device)
    try:
        with _working(f"simulating {site.name}, route {args.route}"):
            rec = simulate(site, route=args.route, mode=mode, device=device, seed=args.seed)
    except RouteError as err:
        raise CliError(f"--route {args.route}: {err}") from None
    except ValueError as err:
        # The carrying model checks a schedule against the walk itself (1.5 s
        # between changes, every start before the walk ends).
        if isinstance(mode, list) and str(err).startswith("schedule["):
            raise CliError(f"--mode {args.mode}: {err}") from None
        raise
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


def _add_survey(subparsers: _Subparsers) -> None:
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
        "--seed", type=_seed, required=True, metavar="N", help="seed of the survey (>= 0)"
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
    _check_out(args.out, overwrite=args.overwrite, what="fingerprint database")
    from indoorsim.scenario.load import load_site
    from indoorsim.survey import grid_survey, walk_survey
    from indoorsim.walker.route import RouteError

    site = load_site(args.scenario)
    name, spec = _survey_plan(site.scenario, args.kind, args.name)
    device = _device(args.device)
    try:
        with _working(f"{args.kind} survey {name!r} of {site.name}"):
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


# ------------------------------------------------------------------- plot


def _add_plot(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "plot",
        help="draw figures of sites and recordings",
        description="Draw figures and write them as PNG files.",
    )
    targets = parser.add_subparsers(dest="target", metavar="TARGET", required=True)
    for add in _PLOT_TARGETS:
        add(targets)


def _add_plot_site(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "site",
        help="site map and field maps (B, light, RSS) of scenarios",
        description="For each scenario write <name>_map.png (walls, lights, magnetic "
        "sources, APs, routes) and heat maps at phone height: <name>_Bx/By/Bz/B.png "
        "(µT), <name>_lux.png (upward-facing receiver) and <name>_rss_<bssid>.png (dBm).",
    )
    parser.add_argument(
        "scenarios", nargs="*", metavar="NAME_OR_PATH", help="bundled scenario names or YAML files"
    )
    parser.add_argument("--all", action="store_true", help="every bundled scenario")
    parser.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder")
    parser.add_argument(
        "--height",
        type=_positive(float),
        default=1.2,
        metavar="H",
        help="receiver height above the floor, m (default: %(default)s)",
    )
    parser.add_argument(
        "--resolution",
        type=_positive(float),
        default=0.1,
        metavar="R",
        help="grid spacing of the field maps, m (default: %(default)s)",
    )
    parser.add_argument(
        "--ap", metavar="BSSID", help="access point whose RSS is mapped (default: the first)"
    )
    parser.add_argument(
        "--dpi",
        type=_positive(int),
        default=150,
        help="resolution of the PNG files (default: %(default)s)",
    )
    parser.set_defaults(handler=_run_plot_site)


def _load_all(args: argparse.Namespace) -> list[Scenario]:
    """Every requested scenario, fully validated before anything is drawn or written."""
    if args.all and args.scenarios:
        raise CliError("give scenario names or --all, not both")
    if not args.all and not args.scenarios:
        raise CliError("name at least one scenario (or use --all)")
    if args.all:
        paths = list(bundled_scenarios().values())
    else:
        paths = [resolve_scenario(name) for name in args.scenarios]
    scenarios = [load_scenario(p) for p in paths]
    first_with_name: dict[str, Path] = {}
    for path, scenario in zip(paths, scenarios, strict=True):
        other = first_with_name.setdefault(scenario.name, path)
        if other != path:
            raise CliError(
                f"{other} and {path} are both named {scenario.name!r}; "
                "their plots would overwrite each other"
            )
    return scenarios


def _check_plot_options(args: argparse.Namespace, scenarios: Sequence[Scenario]) -> None:
    """Reject options that do not fit a scenario before the slow work starts."""
    for scenario in scenarios:
        ceiling = scenario.site.ceiling_height
        if args.height >= ceiling:
            raise CliError(
                f"--height {args.height}: must be below the ceiling of {scenario.name!r} "
                f"({ceiling} m)"
            )
        bssids = [ap.bssid.lower() for ap in scenario.wifi]
        if args.ap is not None and args.ap.lower() not in bssids:
            raise CliError(
                f"--ap {args.ap}: not an access point of {scenario.name!r}; "
                f"its BSSIDs are: {', '.join(bssids) or 'none'}"
            )


def _run_plot_site(args: argparse.Namespace) -> int:
    if args.out.exists() and not args.out.is_dir():
        raise CliError(f"--out {args.out}: exists and is not a folder")
    scenarios = _load_all(args)
    _check_plot_options(args, scenarios)
    # Imported here: matplotlib and the field models are slow to import and
    # not needed by the other subcommands.
    from tqdm import tqdm

    from indoorsim.plots import save_site_plots
    from indoorsim.world.site import Site

    bar = tqdm(scenarios, desc="plotting sites", unit="site", disable=len(scenarios) < 2)
    for scenario in bar:
        bar.set_postfix_str(scenario.name)
        paths = save_site_plots(
            Site(scenario),
            args.out,
            height=args.height,
            resolution=args.resolution,
            ap=args.ap,
            dpi=args.dpi,
        )
        for path in paths:
            tqdm.write(str(path), file=sys.stdout)
    return 0


def _add_plot_recording(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "recording",
        help="sensor streams and true track of recordings",
        description="For each recording write <name>_streams.png (accelerometer with the "
        "true steps, gyroscope, magnetometer, light, WiFi over time; panels for missing "
        "streams are left out) and <name>_track.png (the true track coloured by carrying "
        "mode, or a real log's waypoints; on the floor plan when the building is known), "
        "with <name> the recording's folder or file name. Real logs without true positions "
        "get no track.",
    )
    parser.add_argument(
        "recordings",
        nargs="+",
        type=Path,
        metavar="PATH",
        help="recording folders (from indoorsim simulate) or real phone logs, e.g. "
        "Indoor Location Competition traces (*.txt)",
    )
    parser.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder")
    parser.add_argument(
        "--scenario",
        metavar="NAME_OR_PATH",
        help="the building under the tracks (default: the bundled scenario each "
        "recording names, if there is one)",
    )
    parser.add_argument(
        "--dpi",
        type=_positive(int),
        default=150,
        help="resolution of the PNG files (default: %(default)s)",
    )
    parser.set_defaults(handler=_run_plot_recording)


def _run_plot_recording(args: argparse.Namespace) -> int:
    if args.out.exists() and not args.out.is_dir():
        raise CliError(f"--out {args.out}: exists and is not a folder")
    from tqdm import tqdm

    from indoorsim.io.recording import Recording, RecordingError
    from indoorsim.plots import save_recording_plots
    from indoorsim.scenario.load import load_site

    # Everything is read before anything is drawn, so a bad path fails fast.
    recordings: dict[str, tuple[Path, Recording]] = {}
    for path in args.recordings:
        name = path.stem if path.is_file() else path.resolve().name
        try:
            rec = Recording.load(path)
        except (FileNotFoundError, RecordingError) as err:
            raise CliError(str(err)) from None
        if name in recordings:
            raise CliError(
                f"{recordings[name][0]} and {path} are both named {name!r}; "
                "their plots would overwrite each other"
            )
        recordings[name] = (path, rec)
    site = load_site(args.scenario) if args.scenario is not None else None
    bar = tqdm(recordings.items(), desc="plotting recordings", disable=len(recordings) < 2)
    for name, (_, rec) in bar:
        bar.set_postfix_str(name)
        for path in save_recording_plots(rec, args.out, name, site=site, dpi=args.dpi):
            tqdm.write(str(path), file=sys.stdout)
    return 0


# -------------------------------------------------------------------- evaluate


def _thresholds(text: str) -> dict[str, float]:
    """``ae=1.5,cep95=3`` → ``{"ae": 1.5, "cep95": 3.0}`` (metric names as in the CSVs)."""
    from indoorsim.benchmark.metrics import SUMMARY_KEYS

    out: dict[str, float] = {}
    for item in text.split(","):
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or name not in SUMMARY_KEYS:
            raise argparse.ArgumentTypeError(
                f"{item!r}: expected METRIC=VALUE with METRIC one of {', '.join(SUMMARY_KEYS)}"
            )
        try:
            out[name] = float(value)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{item!r}: {value!r} is not a number") from None
    return out


def _add_evaluate(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "evaluate",
        help="score one estimator on a scenario (or a real recording)",
        description="Run an estimator through the evaluation protocol: site context and "
        "training walks, then one test walk per seed. Writes per walk estimates.csv "
        "(t, x, y, true_x, true_y) and metrics.csv, and a summary.csv. With --fail-above "
        "the exit status is 3 when any named metric (mean over seeds) is worse than its "
        "threshold: the CI use case.",
    )
    parser.add_argument(
        "--estimator", required=True, metavar="NAME", help="a registered name or module:Class"
    )
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--scenario", metavar="NAME_OR_PATH", help="a scenario to simulate")
    source.add_argument(
        "--recording",
        type=Path,
        metavar="PATH",
        help="a recording (indoorsim folder or a real log) scored at its true positions",
    )
    parser.add_argument("--mode", default="handheld", help="carrying mode (default handheld)")
    parser.add_argument("--route", default=None, help="test route (default: the first)")
    parser.add_argument(
        "--seeds", type=_positive(int), default=3, metavar="N", help="test seeds 0..N-1"
    )
    parser.add_argument("--device", default="nexus_5x", help="walking phone (default nexus_5x)")
    parser.add_argument(
        "--survey-device", default="honor_50", help="survey phone (default honor_50)"
    )
    parser.add_argument(
        "--window", type=_positive(float), default=1.0, metavar="S", help="window length, s"
    )
    parser.add_argument("--out", type=Path, required=True, metavar="DIR")
    parser.add_argument(
        "--fail-above",
        type=_thresholds,
        default={},
        metavar="M=V,...",
        help="exit 3 if any of these metrics exceeds its value, e.g. ae=1.5,cep95=3",
    )
    parser.set_defaults(handler=_run_evaluate)


def _run_evaluate(args: argparse.Namespace) -> int:
    import pandas as pd

    from indoorsim.benchmark import evaluation, leaderboard
    from indoorsim.estimators.base import UnknownEstimatorError, make
    from indoorsim.io.recording import MissingStreamError, Recording, RecordingError

    if args.out.exists() and not args.out.is_dir():
        raise CliError(f"--out {args.out}: exists and is not a folder")
    try:
        make(args.estimator)
    except UnknownEstimatorError as err:
        raise CliError(f"--estimator: {err}") from None
    # --out is created only once there are results to write in it.
    if args.recording is not None:
        try:
            rec = Recording.load(args.recording)
        except (RecordingError, OSError) as err:
            raise CliError(f"--recording {args.recording}: {err}") from None
        from indoorsim.estimators.base import NotApplicableError

        try:
            with _working(f"evaluating {args.estimator}"):
                walk = evaluation.evaluate_recording(args.estimator, rec, window_s=args.window)
        except NotApplicableError as err:
            raise CliError(f"--estimator {args.estimator}: not applicable here: {err}") from None
        except (MissingStreamError, ValueError) as err:
            # A log without the truth or waypoints that scoring needs.
            raise CliError(f"--recording {args.recording}: cannot be scored: {err}") from None
        args.out.mkdir(parents=True, exist_ok=True)
        walk.estimates.to_csv(args.out / "estimates.csv", index=False)
        summary = pd.DataFrame([{"estimator": args.estimator, **walk.metrics}])
    else:
        scenario = load_scenario(resolve_scenario(args.scenario))
        from indoorsim.world.site import Site

        site = Site(scenario)
        if args.route is not None and args.route not in scenario.routes:
            raise CliError(f"--route {args.route}: routes are {', '.join(scenario.routes)}")
        from indoorsim.walker.carry import available_modes

        if args.mode not in available_modes():
            raise CliError(f"--mode {args.mode}: modes are {', '.join(available_modes())}")
        _device(args.device)
        _device(args.survey_device)
        from tqdm import tqdm

        with tqdm(total=args.seeds, desc=args.estimator, disable=None, file=sys.stderr) as bar:
            ev = evaluation.evaluate(
                args.estimator,
                site,
                mode=args.mode,
                seeds=tuple(range(args.seeds)),
                route=args.route,
                device=args.device,
                survey_device=args.survey_device,
                window_s=args.window,
                progress=lambda _msg: bar.update(1),  # called as each seed's walk starts
            )
        if ev.note:
            raise CliError(f"--estimator {args.estimator}: not applicable here: {ev.note}")
        args.out.mkdir(parents=True, exist_ok=True)
        leaderboard.write_walks(ev, args.out)
        summary = pd.DataFrame([ev.row()])
    summary.to_csv(args.out / "summary.csv", index=False)
    shown = [c for c in ("ae", "rmse", "me", "cep50", "cep95") if c in summary]
    print(summary[["estimator", *shown]].to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    worse = {
        k: float(summary[k].iloc[0])
        for k, limit in args.fail_above.items()
        if not float(summary[k].iloc[0]) <= limit  # NaN counts as worse
    }
    if worse:
        for k, v in worse.items():
            print(f"indoorsim: {k} = {v:.3f} exceeds {args.fail_above[k]:g}", file=sys.stderr)
        return 3
    return 0


# ----------------------------------------------------------------- leaderboard


def _add_leaderboard(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "leaderboard",
        help="regenerate the leaderboards (tables, CSVs, plots)",
        description="Evaluate the estimators on the bundled paper scenarios in every carrying "
        "mode over several seeds, and write per scenario a Markdown table, a CSV with "
        "provenance, CDF and track plots, plus the real-data table and README.md.",
    )
    parser.add_argument(
        "--scenario", action="append", metavar="NAME", help="only these scenarios (repeatable)"
    )
    parser.add_argument(
        "--estimator", action="append", metavar="NAME", help="only these estimators (repeatable)"
    )
    parser.add_argument("--quick", action="store_true", help="one seed, two modes, no real data")
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("leaderboards"),
        metavar="DIR",
        help="default leaderboards/",
    )
    parser.add_argument(
        "--realdata",
        type=Path,
        metavar="DIR",
        help="the folder of real recordings for the real-data tables (default: "
        "$INDOORSIM_REALDATA, else ../shared/realdata beside the repository)",
    )
    parser.set_defaults(handler=_run_leaderboard)


def _run_leaderboard(args: argparse.Namespace) -> int:
    import dataclasses

    from tqdm import tqdm

    from indoorsim.benchmark import leaderboard
    from indoorsim.estimators.base import UnknownEstimatorError, make

    if args.out.exists() and not args.out.is_dir():
        raise CliError(f"--out {args.out}: exists and is not a folder")
    known = bundled_scenarios()
    for name in args.scenario or ():
        if name not in known:
            raise CliError(f"--scenario {name}: bundled scenarios are {', '.join(known)}")
    for name in args.estimator or ():
        try:  # a registered name or a module:Class plug-in, as for evaluate
            make(name)
        except UnknownEstimatorError as err:
            raise CliError(f"--estimator: {err}") from None
    config = (
        leaderboard.BoardConfig.quick(args.scenario)
        if args.quick
        else leaderboard.BoardConfig(
            **({"scenarios": tuple(args.scenario)} if args.scenario else {})
        )
    )
    if args.estimator:
        config = dataclasses.replace(config, estimators=tuple(args.estimator))
    with tqdm(desc="leaderboard", disable=None, file=sys.stderr) as bar:
        tables = leaderboard.run_leaderboard(
            config,
            args.out,
            progress=lambda msg: (bar.set_postfix_str(msg), bar.update(1)),
            realdata=args.realdata,
        )
    for name, table in tables.items():
        print(f"\n## {name}\n\n{leaderboard.markdown_table(table)}")
    print(f"\nwrote {args.out}/")
    return 0


# ------------------------------------------------------------------- dataset


def _add_dataset(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "dataset",
        help="generate a labelled data set of windows as Parquet shards (Dask)",
        description="Simulate many walks (bundled and generated sites, random routes, walkers, "
        "carrying modes with transitions, devices) and write fixed-length windows of the "
        "phone's streams with their truth labels as Parquet shards, plus a dataset card "
        "(dataset_card.json and README.md, with the schema). Runs on a local Dask cluster "
        "(--workers processes) or an existing one (--scheduler). The output is the same "
        "whatever the number of workers; an interrupted run resumes when the same command "
        "is run again. Options given here override the --config file's keys.",
    )
    parser.add_argument("--sites", type=_positive(int), metavar="N", help="number of sites")
    parser.add_argument(
        "--walks-per-site", type=_positive(int), metavar="K", help="walks in each site"
    )
    parser.add_argument(
        "--minutes", type=_positive(float), metavar="M", help="length of each walk, minutes"
    )
    parser.add_argument("--seed", type=_seed, metavar="S", help="seed of the data set (>= 0)")
    parser.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help="YAML/JSON file with any key of the data-set configuration (see "
        "indoorsim.dataset.config.DatasetConfig)",
    )
    parser.add_argument(
        "--recordings",
        action="store_true",
        default=None,
        help="also save every walk's whole recording folder under recordings/",
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=_positive(int),
        metavar="W",
        help="worker processes of the local cluster (default: the number of cores)",
    )
    where.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="use an existing Dask cluster, e.g. tcp://10.0.0.5:8786 (its workers need "
        "indoorsim and --out at the same path)",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the data set's folder"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(handler=_run_dataset)


def _run_dataset(args: argparse.Namespace) -> int:
    from indoorsim.dataset import DatasetConfigError, load_config
    from indoorsim.dataset.driver import DatasetFolderError, ShardFailures, build_dataset

    overrides = {
        key: value
        for key, value in (
            ("sites", args.sites),
            ("walks_per_site", args.walks_per_site),
            ("minutes", args.minutes),
            ("seed", args.seed),
            ("recordings", args.recordings),
        )
        if value is not None
    }
    try:
        config = load_config(args.config, overrides)
    except DatasetConfigError as err:
        raise CliError(str(err)) from None
    try:
        report = build_dataset(
            config,
            args.out,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=False if args.quiet else None,
        )
    except DatasetFolderError as err:
        raise CliError(str(err)) from None
    except ShardFailures as err:
        print(f"indoorsim: {err}", file=sys.stderr)
        return 3
    text = (
        f"Wrote {args.out}: {report.shards} shards ({report.computed} computed now, "
        f"{report.skipped} already complete), {report.windows} windows, "
        f"{report.hours:.2f} hours of labelled data, in {report.wall_s:.1f} s. "
        f"Card: {args.out / 'dataset_card.json'} and {args.out / 'README.md'}."
    )
    print(textwrap.fill(text, width=88, break_on_hyphens=False))
    return 0


# --------------------------------------------------------------------- train


def _add_train(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "train",
        help="train the learned-io inertial-odometry network on a data set",
        description="Train the small 1-D ResNet of the learned-io estimator (RoNIN-style "
        "velocity regression) on the train split of an `indoorsim dataset` folder, scoring "
        "the val split after each epoch. Writes the checkpoint folder --out (weights.pt, "
        "tensors only, and model.json) atomically after every epoch; running the same "
        "command again resumes an interrupted run. Seeded and deterministic on CPU for a "
        "given --threads and --workers.",
    )
    parser.add_argument(
        "--data", type=Path, required=True, metavar="DIR", help="a finished data set folder"
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the checkpoint folder to write"
    )
    parser.add_argument("--epochs", type=_positive(int), default=15, metavar="N")
    parser.add_argument("--batch-size", type=_positive(int), default=128, metavar="B")
    parser.add_argument(
        "--lr", type=_positive(float), default=3e-3, metavar="LR", help="Adam's initial step"
    )
    parser.add_argument("--seed", type=_seed, default=0, metavar="S", help="seed (>= 0)")
    parser.add_argument(
        "--workers", type=_seed, default=0, metavar="W", help="DataLoader workers (default 0)"
    )
    parser.add_argument(
        "--threads", type=_positive(int), default=1, metavar="T", help="torch threads (default 1)"
    )
    # The frames of indoorsim.estimators.nn.inertial.FRAMES, spelled out so that
    # building the parser does not import torch.
    parser.add_argument(
        "--frame",
        choices=("world", "gravity_aligned"),
        default="world",
        help="input frame (default world)",
    )
    parser.add_argument(
        "--overwrite", action="store_true", help="replace a checkpoint of another run at --out"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar or epoch lines")
    parser.set_defaults(handler=_run_train)


def _run_train(args: argparse.Namespace) -> int:
    from indoorsim.dataset.train import TrainConfig, TrainingFolderError, describe, train

    try:
        config = TrainConfig(
            epochs=args.epochs,
            batch_size=args.batch_size,
            lr=args.lr,
            seed=args.seed,
            frame=args.frame,
            workers=args.workers,
            threads=args.threads,
        )
    except ValueError as err:
        raise CliError(str(err)) from None
    if not args.data.is_dir():
        raise CliError(f"--data {args.data}: not a folder")
    command = " ".join(
        [
            "indoorsim train",
            f"--data {args.data} --out {args.out}",
            f"--epochs {args.epochs} --batch-size {args.batch_size} --lr {args.lr:g}",
            f"--seed {args.seed} --workers {args.workers} --threads {args.threads}",
            f"--frame {args.frame}",
        ]
    )
    try:
        report = train(
            args.data,
            args.out,
            config,
            overwrite=args.overwrite,
            progress=False if args.quiet else None,
            log=None if args.quiet else lambda line: print(line, file=sys.stderr),
            command=command,
        )
    except TrainingFolderError as err:
        raise CliError(str(err)) from None
    print(textwrap.fill(describe(report), width=88, break_on_hyphens=False))
    return 0


_PLOT_TARGETS: tuple[Callable[[_Subparsers], None], ...] = (_add_plot_site, _add_plot_recording)
"""What ``indoorsim plot`` can draw; each entry adds one ``plot <target>`` subcommand."""

_COMMANDS: tuple[Callable[[_Subparsers], None], ...] = (
    _add_scenarios,
    _add_simulate,
    _add_survey,
    _add_evaluate,
    _add_leaderboard,
    _add_dataset,
    _add_train,
    _add_plot,
)
"""The subcommands, in the order ``indoorsim --help`` lists them."""


# ------------------------------------------------------------------- entry point


def build_parser() -> argparse.ArgumentParser:
    """The ``indoorsim`` argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="indoorsim",
        description="Simulate smartphone indoor positioning in synthetic buildings.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in _COMMANDS:
        add(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:
        # argparse exits on --help, --version and usage errors; callers of
        # main() get the status back instead.
        return exit_.code if isinstance(exit_.code, int) else 2
    try:
        return args.handler(args)
    except (CliError, ScenarioError, FileExistsError) as err:
        # FileExistsError: an output folder in the way, which only the user can clear.
        print(f"indoorsim: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        print(f"indoorsim: {err}", file=sys.stderr)
        return 1
