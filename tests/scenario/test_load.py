"""Scenario files: the shared example loads, round trips, and bad input gets one clear error."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

import indoorsim.scenario.load
from indoorsim.scenario import (
    ScenarioError,
    bundled_scenarios,
    dump_scenario,
    load_scenario,
    parse_scenario,
    resolve_scenario,
)
from indoorsim.scenario.load import UnknownScenarioError, load_site


@pytest.fixture
def base(minimal_site_path: Path) -> dict:
    return yaml.safe_load(minimal_site_path.read_text())


def test_shared_minimal_example_loads_unchanged(minimal_site_path: Path):
    scn = load_scenario(minimal_site_path)
    assert scn.name == "minimal-room"
    assert len(scn.walls) == 5 and scn.walls[4].material == "drywall"
    assert scn.walls[0].start == (0.0, 0.0) and scn.walls[0].to == (10.0, 0.0)
    assert scn.site.earth_field_uT is None and scn.site.north_deg == 0.0
    assert scn.luminaires[0].intensity_cd == 800.0 and scn.luminaires[0].exponent == 1.0
    assert scn.magnetic.dipoles[0].moment == (0.0, 0.0, 25.0)
    assert scn.wifi[1].bssid == "02:00:00:00:00:02"
    assert scn.routes["main"].speed == 1.2 and len(scn.routes["main"].waypoints) == 4


def test_round_trip_through_yaml_file(minimal_site_path: Path, tmp_path: Path):
    scn = load_scenario(minimal_site_path)
    out = tmp_path / "again.yaml"
    dump_scenario(scn, out)
    assert load_scenario(out) == scn
    assert parse_scenario(yaml.safe_load(dump_scenario(scn))) == scn


def test_round_trip_keeps_every_optional_section(tmp_path: Path, base: dict):
    rich = copy.deepcopy(base)
    rich.update(
        seed=7,
        doors=[{"position": [5.0, 1.0], "width": 1.0}],
        windows=[{"from": [2.0, 6.0], "to": [4.0, 6.0]}],
        rooms=[{"name": "west", "polygon": [[0, 0], [5, 0], [5, 6], [0, 6]]}],
        pillars=[{"center": [7.0, 3.0], "size": [0.4, 0.4]}],
        obstacles=[
            {"kind": "cabinet", "center": [8.5, 2.5], "size": [1, 0.5], "steel_volume_m3": 0.01}
        ],
        light={"daylight": {"enabled": True}},
        radio={"shadowing_sigma_db": 6.0},
        surveys={
            "grid": {"kind": "grid", "spacing": 1.2},
            "walk": {"kind": "walk", "route": "main"},
        },
    )
    rich["magnetic"]["rebar"] = [{"z": -0.15}]
    scn = parse_scenario(rich)
    path = tmp_path / "rich.yaml"
    dump_scenario(scn, path)
    assert load_scenario(path) == scn


BAD_CASES = [
    (
        "survey key under its kind",
        lambda d: d.update(surveys={"g": {"kind": "grid", "spacing": -1}}),
        "surveys.g.spacing",  # not surveys.g.grid.spacing: the file has no "grid" level
        "greater than 0",
    ),
    (
        "date before IGRF",
        lambda d: d["site"].update(date="1800-01-01"),
        "site",
        "outside the IGRF-14 model",
    ),
    ("unknown key", lambda d: d["walls"][0].update(colour="red"), "walls[0].colour", "unknown key"),
    ("unknown top key", lambda d: d.update(floors=2), "floors", "unknown key"),
    (
        "wrong type",
        lambda d: d["walls"][0].update(thickness="thick"),
        "walls[0].thickness",
        "number",
    ),
    (
        "NaN",
        lambda d: d["luminaires"][0].update(intensity_cd=float("nan")),
        "luminaires[0].intensity_cd",
        "finite",
    ),
    (
        "infinite",
        lambda d: d["site"].update(ceiling_height=float("inf")),
        "site.ceiling_height",
        "finite",
    ),
    (
        "negative thickness",
        lambda d: d["walls"][1].update(thickness=-0.2),
        "walls[1].thickness",
        "greater than 0",
    ),
    (
        "negative intensity",
        lambda d: d["luminaires"][1].update(intensity_cd=-5),
        "luminaires[1].intensity_cd",
        "greater than or equal to 0",
    ),
    (
        "luminaire outside",
        lambda d: d["luminaires"][1].update(position=[12, 3, 3]),
        "luminaires[1].position",
        "outside the building",
    ),
    (
        "luminaire in wall",
        lambda d: d["luminaires"][1].update(position=[5, 2, 3]),
        "luminaires[1].position",
        "inside a wall",
    ),
    (
        "luminaire above ceiling",
        lambda d: d["luminaires"][0].update(position=[2.5, 3, 3.5]),
        "luminaires[0].position",
        "not within the room",
    ),
    (
        "zero-length wall",
        lambda d: d["walls"][4].update(to=[5.0, 0.0]),
        "walls[4]",
        "zero-length wall",
    ),
    (
        "waypoint outside",
        lambda d: d["routes"]["main"]["waypoints"].append([11, 1]),
        "routes.main.waypoints[4]",
        "not in the walkable area",
    ),
    (
        "waypoint in wall",
        lambda d: d["routes"]["main"]["waypoints"].append([5, 2]),
        "routes.main.waypoints[4]",
        "not in the walkable area",
    ),
    (
        "leg through wall",
        lambda d: d["routes"]["main"]["waypoints"].append([3, 1]),
        "routes.main.waypoints[3]",
        "passes through a wall",
    ),
    (
        "duplicate BSSID",
        lambda d: d["wifi"][1].update(bssid="02:00:00:00:00:01"),
        "wifi[1].bssid",
        "duplicate BSSID",
    ),
    (
        "malformed BSSID",
        lambda d: d["wifi"][1].update(bssid="zz"),
        "wifi[1].bssid",
        "not a MAC address",
    ),
    ("missing key", lambda d: d["site"].pop("date"), "site.date", "required"),
    (
        "unknown material",
        lambda d: d["walls"][0].update(material="cheese"),
        "walls[0].material",
        "concrete",
    ),
    ("3-D wall end", lambda d: d["walls"][0].update(to=[1, 2, 3]), "walls[0].to", "at most 2"),
    (
        "door off any wall",
        lambda d: d.update(doors=[{"position": [3, 3]}]),
        "doors[0].position",
        "not on any wall",
    ),
    (
        "survey of unknown route",
        lambda d: d.update(surveys={"s": {"kind": "walk", "route": "nope"}}),
        "surveys.s.route",
        "unknown route",
    ),
    (
        "survey region off the floor",
        lambda d: d.update(
            surveys={"g": {"kind": "grid", "region": [[20, 20], [21, 20], [21, 21]]}}
        ),
        "surveys.g.region",
        "does not overlap the walkable area",
    ),
    (
        "latitude out of range",
        lambda d: d["site"].update(latitude=95),
        "site.latitude",
        "less than or equal to 90",
    ),
    (
        "wall end a million kilometres away",
        lambda d: d["walls"][3].update(to=[0.0, 1e9]),
        "walls[3].to[1]",
        "1e+09 m is beyond the coordinate limit",
    ),
    (
        "dipole far beyond any building steel",
        lambda d: d["magnetic"]["dipoles"][1].update(moment=[0.0, 0.0, 1e300]),
        "magnetic.dipoles[1].moment",
        "|moment| = 1e+300 A·m² is beyond the limit of 10000 A·m²",
    ),
]


@pytest.mark.parametrize(
    ("label", "mutate", "path", "message"), BAD_CASES, ids=[c[0] for c in BAD_CASES]
)
def test_bad_input_names_file_key_and_problem(base, tmp_path, label, mutate, path, message):
    data = copy.deepcopy(base)
    mutate(data)
    file = tmp_path / "broken.yaml"
    file.write_text(yaml.safe_dump(data))
    with pytest.raises(ScenarioError) as info:
        load_scenario(file)
    err = info.value
    assert [p for p, _ in err.problems] == [path], err.problems
    assert message in err.problems[0][1]
    assert str(file) in str(err) and path in str(err)
    assert err.__context__ is None or err.__suppress_context__  # no traceback from deep inside


def test_several_problems_are_reported_together(base):
    data = copy.deepcopy(base)
    data["walls"][0]["thickness"] = -1
    data["luminaires"][0]["intensity_cd"] = -1
    with pytest.raises(ScenarioError) as info:
        parse_scenario(data, "two.yaml")
    assert {p for p, _ in info.value.problems} == {
        "walls[0].thickness",
        "luminaires[0].intensity_cd",
    }
    assert str(info.value).startswith("invalid scenario (2 problems)")


def test_yaml_syntax_error_reports_its_line(tmp_path: Path):
    file = tmp_path / "syntax.yaml"
    file.write_text("name: x\nsite:\n  latitude: 3\n  longitude: [1, 2\nwalls: []\n")
    with pytest.raises(ScenarioError, match=r"syntax\.yaml: YAML syntax error at line 5"):
        load_scenario(file)


@pytest.mark.parametrize(
    ("content", "where", "looks_like"),
    [
        ("name: café\n".encode("latin-1"), "line 1, column 10 (byte offset 9)", "Latin-1"),
        (b"name: x\n\x00\x01\x02\xff\xfe" * 10, "line 2, column 4 (byte offset 11)", "binary"),
    ],
    ids=["latin-1", "binary"],
)
def test_a_file_that_is_not_utf8_names_the_byte(tmp_path: Path, content, where, looks_like):
    file = tmp_path / "encoded.yaml"
    file.write_bytes(content)
    with pytest.raises(ScenarioError) as info:
        load_scenario(file)
    message = str(info.value)
    assert message.startswith(f"{file}: not UTF-8 text: byte 0x")
    assert where in message and looks_like in message
    assert info.value.__suppress_context__


def test_a_key_given_twice_is_refused_with_both_lines(minimal_site_path: Path, tmp_path: Path):
    text = minimal_site_path.read_text(encoding="utf-8")
    file = tmp_path / "twice.yaml"
    # The last of two values would win silently in PyYAML.
    file.write_text(text + "name: another\n", encoding="utf-8")
    last = len(text.splitlines()) + 1
    first = next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith("name:"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(file)
    assert info.value.problems == [
        ("name", f"duplicate key 'name' at line {last} (first given at line {first}); "
         "give each key once")
    ]  # fmt: skip
    # Nested, in a flow mapping: the key path, and the columns of a shared line.
    file.write_text(text.replace("thickness: 0.12,", "thickness: 0.12, thickness: 0.3,"))
    with pytest.raises(ScenarioError, match=r"walls\[4\]\.thickness: duplicate key 'thickness' "
                       r"at line \d+, column \d+ \(first given at column \d+\)"):  # fmt: skip
        load_scenario(file)


def test_merged_keys_may_be_overridden(minimal_site_path: Path, tmp_path: Path):
    """YAML merge keys (<<) are not duplicates: the mapping's own key overrides them."""
    text = minimal_site_path.read_text(encoding="utf-8")
    file = tmp_path / "merged.yaml"
    file.write_text(
        text.replace("routes:\n  main: {", "routes:\n  main: &main {")
        + "  back: {<<: *main, speed: 1.0}\n",
        encoding="utf-8",
    )
    scn = load_scenario(file)
    assert scn.routes["back"].speed == 1.0
    assert scn.routes["back"].waypoints == scn.routes["main"].waypoints


def test_a_folder_is_not_a_scenario_file(minimal_site_path: Path, tmp_path: Path):
    for load in (load_scenario, resolve_scenario):
        with pytest.raises(ScenarioError) as info:
            load(tmp_path)
        assert str(info.value) == (
            f"{tmp_path}: is a directory, expected a scenario .yaml file (it holds no .yaml files)"
        )
    (tmp_path / "b.yaml").write_text("")
    (tmp_path / "a.yml").write_text("")
    with pytest.raises(ScenarioError, match=r"is a directory, expected a scenario \.yaml file: "
                       "one of a.yml, b.yaml$"):  # fmt: skip
        resolve_scenario(tmp_path)


def test_missing_file_and_non_mapping(tmp_path: Path):
    with pytest.raises(ScenarioError, match="cannot read file"):
        load_scenario(tmp_path / "absent.yaml")
    (tmp_path / "list.yaml").write_text("- 1\n- 2\n")
    with pytest.raises(ScenarioError, match="expected a mapping"):
        load_scenario(tmp_path / "list.yaml")


def test_unknown_scenario_name_lists_the_bundled_ones():
    with pytest.raises(ScenarioError, match="bundled scenarios are") as info:
        resolve_scenario("no_such_building")
    err = info.value
    assert isinstance(err, UnknownScenarioError) and isinstance(err, LookupError)
    assert err.valid == tuple(bundled_scenarios()) and err.source == "no_such_building"
    assert str(err) == (
        f"unknown scenario 'no_such_building'; bundled scenarios are: {', '.join(err.valid)}"
    )


def test_load_site_gives_one_site_per_unchanged_file(minimal_site_path: Path, tmp_path: Path):
    site = load_site("minimal_room")
    assert load_site("minimal_room") is site
    assert load_site(bundled_scenarios()["minimal_room"]) is site  # the same file by its path
    copy_path = tmp_path / "room.yaml"
    copy_path.write_bytes(minimal_site_path.read_bytes())
    mine = load_site(copy_path)
    assert mine is not site and load_site(str(copy_path)) is mine
    # An edited file (here: another name) is loaded again.
    copy_path.write_text(
        copy_path.read_text().replace("name: minimal-room", "name: edited-room"), encoding="utf-8"
    )
    edited = load_site(copy_path)
    assert edited is not mine and edited.name == "edited-room"
    # A Scenario is not a file: it always gives a new Site.
    assert load_site(site.scenario) is not load_site(site.scenario)


def test_scenarios_are_immutable(minimal_site_path: Path):
    scn = load_scenario(minimal_site_path)
    with pytest.raises(Exception, match="frozen"):
        scn.name = "other"  # type: ignore[misc]


def test_a_date_outside_igrf_is_fine_with_an_explicit_earth_field(base: dict) -> None:
    base["site"].update(date="1800-01-01", earth_field_uT=[0.0, 30.0, -40.0])
    assert parse_scenario(base).site.date.year == 1800


class _EntryPoint:
    """Stands in for an importlib.metadata entry point of the scenario group."""

    def __init__(self, name: str, target: object):
        self.name, self.value, self._target = name, f"plugin:{name}", target

    def load(self) -> object:
        if isinstance(self._target, Exception):
            raise self._target
        return self._target


def test_scenario_plugins_cannot_break_or_replace_the_bundled_ones(
    minimal_site_path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = tmp_path / "plugin"
    folder.mkdir()
    (folder / "minimal_room.yaml").write_text(minimal_site_path.read_text(), encoding="utf-8")
    (folder / "extra_room.yaml").write_text(minimal_site_path.read_text(), encoding="utf-8")
    plugins = [
        _EntryPoint("broken", ImportError("no module named plugin")),
        _EntryPoint("f", folder),
    ]
    monkeypatch.setattr(indoorsim.scenario.load, "entry_points", lambda group: plugins)
    with pytest.warns(UserWarning) as caught:
        names = bundled_scenarios()
    messages = [str(w.message) for w in caught]
    assert any("'broken' (plugin:broken) failed to load" in m for m in messages), messages
    assert any("'minimal_room' is already taken" in m for m in messages), messages
    assert names["extra_room"] == folder / "extra_room.yaml"
    assert names["minimal_room"].parent.name == "scenarios"  # the bundled file, not the plugin's
