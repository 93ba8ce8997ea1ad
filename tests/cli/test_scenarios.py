"""``indoorsim scenarios``: one aligned row per bundled scenario, with its counts."""

from __future__ import annotations

import itertools
import math
import re

import yaml

from indoorsim import load_site
from indoorsim.cli import main
from indoorsim.scenario import bundled_scenarios, load_scenario
from indoorsim.survey import grid_points
from indoorsim.walker.route import plan_route


def _table(text: str) -> dict[str, list[str]]:
    """Rows of the ``scenarios`` table by name; columns are separated by two or more spaces."""
    rows = [re.split(r"\s{2,}", line.strip()) for line in text.splitlines() if line.strip()]
    return {row[0]: row[1:] for row in rows}


def test_scenarios_lists_every_bundled_scenario_with_its_counts(capsys):
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    table = _table(out)
    assert table["name"] == ["size (m)", "walls", "lights", "APs", "dipoles", "description"]
    bundled = bundled_scenarios()
    assert "minimal_room" in bundled
    assert set(table) - {"name"} == set(bundled)
    for name, path in bundled.items():
        scenario = load_scenario(path)
        size, walls, lights, aps = table[name][:4]
        assert re.fullmatch(r"\d+\.\d × \d+\.\d", size)
        assert (int(walls), int(lights), int(aps)) == (
            len(scenario.walls),
            len(scenario.luminaires),
            len(scenario.wifi),
        )
    # Aligned: the counts are right-justified under their headers.
    header, *rows = out.splitlines()
    for column in ("walls", "lights", "APs", "dipoles"):
        end = header.index(column) + len(column)
        assert all(row[end - 1].isdigit() and row[end : end + 1] in ("", " ") for row in rows)


# ------------------------------------------------------------------ one scenario


def _section(text: str, title: str) -> dict[str, list[str]]:
    """The rows of a detail view's routes or surveys table, by name (header row left out)."""
    lines = text.split(f"\n{title}")[1].split("\n\n")[0].splitlines()[2:]
    return {row[0]: row[1:] for row in (re.split(r"\s{2,}", line.strip()) for line in lines)}


def test_scenarios_name_shows_routes_surveys_size_sources_and_description(capsys):
    assert main(["scenarios", "han2023_corridor"]) == 0
    out = capsys.readouterr().out
    site = load_site("han2023_corridor")
    sc = site.scenario
    assert out.startswith(f"han2023_corridor  ({bundled_scenarios()['han2023_corridor']})\n")
    flat = " ".join(out.split())
    assert f"about {' '.join(sc.description.split())}" in flat  # where the numbers come from
    assert "plan 54.2 × 30.2 m (x 0.88 to 55.12, y 0.88 to 31.12), one floor" in flat
    assert "15 walls, 17 doors, 10 windows, 1 room, 31 pillars" in flat
    assert f"lights {len(sc.luminaires)} luminaires;" in flat
    assert f"WiFi {len(sc.wifi)} access points on this floor" in flat
    assert f"{len(site.radio.bssids)} BSSIDs in all" in flat
    dipoles = len(site.magnetic.positions)
    assert f"magnetic {dipoles} dipoles: 21 explicit, 558 in 31 pillars" in flat
    routes = _section(out, "routes")
    assert list(routes) == list(sc.routes) == ["trajectory", "heading_test"]
    for name, spec in sc.routes.items():
        length = sum(math.dist(a, b) for a, b in itertools.pairwise(spec.waypoints))
        assert routes[name][:2] == [f"{length:.1f} m", f"{spec.speed:g} m/s"]
    assert routes["trajectory"][0] == "80.6 m"  # the paper's 80.6 m trajectory
    surveys = _section(out, "surveys")
    assert {n: row[0] for n, row in surveys.items()} == {
        "grid": "grid",
        "walk": "walk",
        "walk_heading_test": "walk",
    }
    n_grid = len(grid_points(site, sc.surveys["grid"]))
    assert surveys["grid"][1].startswith(f"{n_grid} points 1.2 m apart in its region, 30 s at 50")
    assert surveys["walk"][1].startswith("along route trajectory, reference points 8 m apart")


def test_scenarios_path_plans_start_goal_routes_and_says_what_is_missing(tmp_path, capsys):
    data = yaml.safe_load(bundled_scenarios()["minimal_room"].read_text(encoding="utf-8"))
    data["routes"] = {"across": {"start": [1.0, 1.0], "goal": [9.0, 1.0], "speed": 1.0}}
    data["surveys"] = {"coarse": {"kind": "grid", "spacing": 2.0, "duration_s": 5.0}}
    path = tmp_path / "room.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    assert main(["scenarios", str(path)]) == 0
    out = capsys.readouterr().out
    site = load_site(path)
    planned = plan_route(site.plan, site.scenario.routes["across"], name="across").length
    assert planned > 8.0  # around the drywall wall
    across = _section(out, "routes")["across"]
    assert across == [
        f"{planned:.1f} m",
        "1 m/s",
        f"~{planned:.0f} s",
        "start and goal, the shortest walkable path",
    ]
    assert "about" not in out  # no description in this file
    assert _section(out, "surveys")["coarse"][1].endswith("5 s at 50 Hz each, phone flat at 1.2 m")
    data["routes"], data["surveys"] = {}, {}
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    assert main(["scenarios", str(path)]) == 0
    out = capsys.readouterr().out
    assert "the first is the default)\n  none\n" in out and out.endswith("[--name NAME])\n  none\n")


def test_scenarios_unknown_name_is_refused_listing_the_bundled_ones(capsys):
    assert main(["scenarios", "nowhere"]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"indoorsim: unknown scenario 'nowhere'; bundled scenarios are: "
        f"{', '.join(bundled_scenarios())}\n"
    )
