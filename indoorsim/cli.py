"""The ``indoorsim`` command line.

::

    indoorsim scenarios                                   # the bundled scenarios, as a table
    indoorsim plot site minimal_room my-site.yaml --out plots/
    indoorsim plot site --all --out plots/ --resolution 0.2

Each subcommand is a pair of functions: ``_add_<command>(subparsers)`` declares
its arguments and sets ``handler`` to ``_run_<command>(args) -> int``. Adding
a subcommand (``simulate``, ``survey``, ...) means adding one such pair and
listing its ``_add_`` function in :data:`_COMMANDS`; plot targets (``plot
recording``, ...) are listed the same way in :data:`_PLOT_TARGETS`.

Exit codes: 0 success, 1 an I/O failure while writing, 2 a usage error (bad
arguments, an unknown scenario name, an invalid scenario file). Errors are
printed to stderr as one clear message, without a traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, TypeAlias

from indoorsim import __version__
from indoorsim.scenario import (
    Scenario,
    ScenarioError,
    bundled_scenarios,
    load_scenario,
    resolve_scenario,
)

if TYPE_CHECKING:
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


# ------------------------------------------------------------------- plot


def _add_plot(subparsers: _Subparsers) -> None:
    parser = subparsers.add_parser(
        "plot",
        help="draw figures of sites",
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


_PLOT_TARGETS: tuple[Callable[[_Subparsers], None], ...] = (_add_plot_site,)
"""What ``indoorsim plot`` can draw; each entry adds one ``plot <target>`` subcommand."""

_COMMANDS: tuple[Callable[[_Subparsers], None], ...] = (_add_scenarios, _add_plot)
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
    except (CliError, ScenarioError) as err:
        print(f"indoorsim: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        print(f"indoorsim: {err}", file=sys.stderr)
        return 1
