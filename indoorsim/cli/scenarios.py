"""``indoorsim scenarios``: the bundled scenarios as a table."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers

__all__ = ["add_scenarios"]


def add_scenarios(subparsers: Subparsers) -> None:
    """Declare ``indoorsim scenarios``."""
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
    from indoorsim.scenario.load import bundled_scenarios, load_scenario
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
