"""``indoorsim scenarios``: the bundled scenarios as a table, or one scenario in detail."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from indoorsim.cli.args import table_lines

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers
    from indoorsim.world.site import Site

__all__ = ["add_scenarios"]


def add_scenarios(subparsers: Subparsers) -> None:
    """Declare ``indoorsim scenarios``."""
    parser = subparsers.add_parser(
        "scenarios",
        help="list the bundled scenarios, or show one's routes and surveys",
        description="List the bundled scenarios (and those added by plug-ins): size, "
        "walls, lights, access points, magnetic dipoles and a description. With a NAME, "
        "show that scenario: its routes (length, speed), survey plans, plan size, "
        "light, WiFi and magnetic sources, and its description (where it comes from).",
    )
    parser.add_argument(
        "name",
        nargs="?",
        metavar="NAME",
        help="a bundled scenario name or a scenario YAML file to show in detail",
    )
    parser.set_defaults(handler=_run_scenarios)


def _one_line(text: str, width: int = 72) -> str:
    flat = " ".join(text.split())
    return flat if len(flat) <= width else flat[: width - 1].rstrip() + "…"


def _run_scenarios(args: argparse.Namespace) -> int:
    if args.name is not None:
        return _show_scenario(args.name)
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


# ------------------------------------------------------------------ one scenario

_LABEL = 10  # width of the labels of the detail view


def _field(label: str, text: str) -> str:
    """``label`` then ``text`` wrapped at 88 columns, continuation lines under the text."""
    import textwrap

    return textwrap.fill(
        text,
        width=88,
        initial_indent=label.ljust(_LABEL),
        subsequent_indent=" " * _LABEL,
        break_on_hyphens=False,
    )


def _degrees(value: float, signs: str) -> str:
    """``32.63° N`` from a signed latitude (``signs`` "NS") or longitude ("EW")."""
    return f"{abs(value):g}° {signs[0] if value >= 0 else signs[1]}"


def _count(n: int, what: str, plural: str = "") -> str:
    return f"{n} {what if n == 1 else plural or what + 's'}"


def _show_scenario(name: str) -> int:
    """Print one scenario: what it is, its plan and sources, its routes and survey plans."""
    from collections import Counter

    from indoorsim.scenario.load import load_site, resolve_scenario

    path = resolve_scenario(name)
    site = load_site(path)
    sc, s, radio = site.scenario, site.scenario.site, site.scenario.radio
    lines = [f"{sc.name}  ({path})"]
    if sc.description.strip():
        lines.append(_field("about", " ".join(sc.description.split())))
    earth = (
        f"Earth field {list(s.earth_field_uT)} µT (given)"
        if s.earth_field_uT is not None
        else f"Earth field from IGRF at {_degrees(s.latitude, 'NS')}, "
        f"{_degrees(s.longitude, 'EW')} on {s.date}"
    )
    lines.append(_field("site", f"{earth}; building +y {s.north_deg:g}° clockwise from true north"))
    xmin, ymin, xmax, ymax = site.plan.outline.bounds
    parts = [_count(len(sc.walls), "wall")] + [
        _count(len(items), what)
        for items, what in (
            (sc.doors, "door"),
            (sc.windows, "window"),
            (sc.rooms, "room"),
            (sc.pillars, "pillar"),
            (sc.obstacles, "obstacle"),
        )
        if items
    ]
    lines.append(
        _field(
            "plan",
            f"{xmax - xmin:.1f} × {ymax - ymin:.1f} m (x {xmin:g} to {xmax:g}, y {ymin:g} to "
            f"{ymax:g}), one floor, ceiling {s.ceiling_height:g} m; {', '.join(parts)}",
        )
    )
    daylight = sc.light.daylight
    lines.append(
        _field(
            "lights",
            f"{_count(len(sc.luminaires), 'luminaire')}; ambient inter-reflection "
            f"{'on' if sc.light.ambient else 'off'}; daylight "
            f"{f'on ({daylight.sky} sky)' if daylight.enabled else 'off'}",
        )
    )
    heard = (
        f"; with the same APs on {_count(radio.floors_above, 'storey')} above and "
        f"{radio.floors_below} below, {len(site.radio.bssids)} BSSIDs in all"
        if sc.wifi and (radio.floors_above or radio.floors_below)
        else ""
    )
    lines.append(_field("WiFi", f"{_count(len(sc.wifi), 'access point')} on this floor{heard}"))
    by_source = Counter(str(x) for x in site.magnetic.sources)
    steel = [
        (by_source["dipole"], "explicit"),
        (by_source["pillar"], f"in {_count(len(sc.pillars), 'pillar')}"),
        (by_source["rebar"], f"in {_count(len(sc.magnetic.rebar), 'rebar grid')}"),
        (by_source["obstacle"], "in steel furniture"),
    ]
    listed = ", ".join(f"{n} {what}" for n, what in steel if n)
    lines.append(
        _field("magnetic", f"{_count(len(site.magnetic.positions), 'dipole')}: {listed or 'none'}")
    )
    lines += ["", "routes    (--route NAME of simulate and evaluate; the first is the default)"]
    lines += _routes(site) or ["  none"]
    lines += ["", f"surveys   (indoorsim survey {name} --kind KIND [--name NAME])"]
    lines += _surveys(site) or ["  none"]
    print("\n".join(lines))
    return 0


def _routes(site: Site) -> list[str]:
    """One row per route: name, length, speed, walking time, how it is given."""
    import itertools
    import math

    rows = [("name", "length", "speed", "time", "given as")]
    for name, spec in site.scenario.routes.items():
        if spec.waypoints is not None:
            pts = spec.waypoints
            length = sum(math.dist(a, b) for a, b in itertools.pairwise(pts))
            given = _count(len(pts), "waypoint")
        else:
            # Only start/goal routes need the route planner (and its compiled kernels).
            from indoorsim.walker.route import RouteError, plan_route

            given = "start and goal, the shortest walkable path"
            try:
                length = plan_route(site.plan, spec, name=name).length
            except RouteError as err:
                rows.append((name, "?", f"{spec.speed:g} m/s", "?", f"cannot be planned: {err}"))
                continue
        seconds = length / spec.speed
        rows.append((name, f"{length:.1f} m", f"{spec.speed:g} m/s", f"~{seconds:.0f} s", given))
    return table_lines(rows, right={1, 2, 3}) if len(rows) > 1 else []


def _surveys(site: Site) -> list[str]:
    """One row per survey plan: name, kind and its key parameters."""
    from indoorsim.scenario.schema import GridSurveySpec
    from indoorsim.survey import grid_points

    rows = [("name", "kind", "plan")]
    for name, spec in site.scenario.surveys.items():
        if isinstance(spec, GridSurveySpec):
            try:
                points = f"{len(grid_points(site, spec))} points"
            except ValueError:
                points = "no walkable point"
            where = "in its region" if spec.region is not None else "over the walkable area"
            text = (
                f"{points} {spec.spacing:g} m apart {where}, {spec.duration_s:g} s at "
                f"{spec.rate_hz:g} Hz each, phone flat at {spec.height:g} m"
            )
        else:
            text = (
                f"along route {spec.route}, reference points {spec.reference_spacing:g} m "
                f"apart, {spec.wifi_dwell_s:g} s of WiFi at each, "
                f"{_count(spec.repeats, 'pass', 'passes')}"
            )
        rows.append((name, spec.kind, text))
    return table_lines(rows, right=set()) if len(rows) > 1 else []
