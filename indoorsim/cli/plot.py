"""``indoorsim plot <target>``: figures of sites and recordings, written as PNG files.

Each target is a pair of functions, ``_add_plot_<target>(subparsers)`` and
``_run_plot_<target>(args)``, listed in :data:`_PLOT_TARGETS`. Everything a
target draws is read and checked before the first figure is written.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from indoorsim.cli.args import CliError, check_folder, positive

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers
    from indoorsim.io.recording import Recording
    from indoorsim.world.site import Site

__all__ = ["add_plot"]


def add_plot(subparsers: Subparsers) -> None:
    """Declare ``indoorsim plot`` and its targets."""
    parser = subparsers.add_parser(
        "plot",
        help="draw figures of sites and recordings",
        description="Draw figures and write them as PNG files.",
    )
    targets = parser.add_subparsers(dest="target", metavar="TARGET", required=True)
    for add in _PLOT_TARGETS:
        add(targets)


# ------------------------------------------------------------------- site


def _add_plot_site(subparsers: Subparsers) -> None:
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
        type=positive(float),
        default=1.2,
        metavar="H",
        help="receiver height above the floor, m (default: %(default)s)",
    )
    parser.add_argument(
        "--resolution",
        type=positive(float),
        default=0.1,
        metavar="R",
        help="grid spacing of the field maps, m (default: %(default)s)",
    )
    parser.add_argument(
        "--ap", metavar="BSSID", help="access point whose RSS is mapped (default: the first)"
    )
    parser.add_argument(
        "--dpi",
        type=positive(int),
        default=150,
        help="resolution of the PNG files (default: %(default)s)",
    )
    parser.set_defaults(handler=_run_plot_site)


def _load_all(args: argparse.Namespace) -> list[Site]:
    """Every requested scenario's site, fully validated before anything is drawn or written."""
    from indoorsim.scenario.load import bundled_scenarios, load_site, resolve_scenario

    if args.all and args.scenarios:
        raise CliError("give scenario names or --all, not both")
    if not args.all and not args.scenarios:
        raise CliError("name at least one scenario (or use --all)")
    if args.all:
        paths = list(bundled_scenarios().values())
    else:
        paths = [resolve_scenario(name) for name in args.scenarios]
    sites = [load_site(p) for p in paths]
    first_with_name: dict[str, Path] = {}
    for path, site in zip(paths, sites, strict=True):
        other = first_with_name.setdefault(site.name, path)
        if other != path:
            raise CliError(
                f"{other} and {path} are both named {site.name!r}; "
                "their plots would overwrite each other"
            )
    return sites


def _check_plot_options(args: argparse.Namespace, sites: list[Site]) -> None:
    """Reject options that do not fit a scenario before the slow work starts."""
    for site in sites:
        scenario = site.scenario
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
    check_folder(args.out)
    sites = _load_all(args)
    _check_plot_options(args, sites)
    # Imported here: matplotlib is slow to import and not needed by the other subcommands.
    from tqdm import tqdm

    from indoorsim.plots import save_site_plots

    bar = tqdm(sites, desc="plotting sites", unit="site", disable=len(sites) < 2)
    for site in bar:
        bar.set_postfix_str(site.name)
        paths = save_site_plots(
            site,
            args.out,
            height=args.height,
            resolution=args.resolution,
            ap=args.ap,
            dpi=args.dpi,
        )
        for path in paths:
            tqdm.write(str(path), file=sys.stdout)
    return 0


# ------------------------------------------------------------------- recording


def _add_plot_recording(subparsers: Subparsers) -> None:
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
        type=positive(int),
        default=150,
        help="resolution of the PNG files (default: %(default)s)",
    )
    parser.set_defaults(handler=_run_plot_recording)


def _run_plot_recording(args: argparse.Namespace) -> int:
    check_folder(args.out)
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


_PLOT_TARGETS: tuple[Callable[[Subparsers], None], ...] = (_add_plot_site, _add_plot_recording)
"""What ``indoorsim plot`` can draw; each entry adds one ``plot <target>`` subcommand."""
