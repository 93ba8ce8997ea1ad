"""``indoorsim simulate`` and ``indoorsim survey``: folders written, summaries, clean refusals."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from indoorsim import load_site
from indoorsim.cli import main
from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.io.recording import Recording
from indoorsim.phone.devices import available_devices
from indoorsim.scenario import bundled_scenarios, load_scenario
from indoorsim.survey import grid_points
from tests.cli.conftest import WALK

# ------------------------------------------------------------------- simulate


def _simulate(out: Path, *extra: str, mode: str = "handheld") -> int:
    return main(["simulate", *WALK, "--mode", mode, "--out", str(out), *extra])


def test_simulate_writes_a_recording_whose_manifest_names_its_origin(tmp_path, capsys):
    out = tmp_path / "walk"
    assert _simulate(out) == 0
    rec = Recording.load(out)
    scenario = load_scenario(bundled_scenarios()["minimal_room"])
    assert rec.meta["scenario"] == scenario.name
    assert (rec.meta["device"], rec.meta["mode"], rec.meta["seed"]) == ("honor_50", "handheld", 3)
    assert rec.meta["route"]["name"] == "main"
    assert {"accel", "gyro", "mag", "light", "wifi", "truth", "steps"} <= set(rec.streams)
    summary = " ".join(capsys.readouterr().out.split())
    assert f"Wrote {out}" in summary
    assert f"{rec.duration:.1f} s walk" in summary
    assert f"in {len(rec.steps)} steps" in summary
    assert f"accel {len(rec.accel)}," in summary
    assert f"wifi {len(rec.wifi)} readings in {rec.wifi.index.nunique()} scans" in summary


def test_simulate_twice_with_overwrite_writes_the_same_bytes(tmp_path):
    out = tmp_path / "walk"
    assert _simulate(out, "--overwrite") == 0
    first = {p.name: p.read_bytes() for p in out.iterdir()}
    assert _simulate(out, "--overwrite") == 0
    assert {p.name: p.read_bytes() for p in out.iterdir()} == first
    assert any(name.endswith(".parquet") for name in first)


def test_mode_schedule_switches_modes_at_the_given_times(walk_folder):
    rec = Recording.load(walk_folder)
    assert rec.meta["mode"] == [[0.0, "handheld"], [6.0, "calling"], [12.0, "pocketed"]]
    mode = rec.truth["mode"]
    assert list(dict.fromkeys(mode)) == ["handheld", "calling", "pocketed"]
    # A change takes 1.5 s; the truth names the new mode from its middle on.
    for name, start in (("calling", 6.0), ("pocketed", 12.0)):
        assert start <= mode.index[mode == name][0] <= start + 1.5


def _all_named(names, text: str) -> bool:
    return all(name in text for name in names)


# ``extra`` options come after WALK's, and argparse keeps the last of a repeated option.
@pytest.mark.parametrize(
    ("mode", "extra", "expected"),
    [
        ("walking", [], ["'walking'", "calling, dangling, handheld, pocketed"]),
        ("handheld", ["--device", "nokia_3310"], ["'nokia_3310'", "honor_50", "ideal"]),
        (
            "handheld",
            ["--route", "nowhere"],
            ["--route nowhere: unknown route", "routes are: main"],
        ),
        ("handheld,calling", [], ["'calling' needs a start time"]),
        ("5:handheld", [], ["first mode must start at 0 s"]),
        ("handheld,9:calling,8:pocketed", [], ["must increase", "pocketed at 8 s"]),
        ("handheld,soon:calling", [], ["'soon' is not a start time"]),
        ("handheld,6:calling,7:pocketed", [], ["1.5 s transition"]),
        ("handheld,60:calling", [], ["60.0 s, after the walk ends"]),
    ],
)
def test_simulate_refuses_bad_arguments_naming_the_value(tmp_path, capsys, mode, extra, expected):
    out = tmp_path / "walk"
    assert _simulate(out, *extra, mode=mode) == 2
    err = capsys.readouterr().err
    assert err.startswith("indoorsim: ") and "Traceback" not in err
    assert _all_named(expected, err), err
    assert not out.exists()


def test_unknown_device_lists_every_device(tmp_path, capsys):
    assert _simulate(tmp_path / "walk", "--device", "nokia_3310") == 2
    assert _all_named(available_devices(), capsys.readouterr().err)


def test_simulate_never_replaces_what_is_not_a_recording(tmp_path, capsys):
    taken = tmp_path / "notes"
    taken.mkdir()
    (taken / "todo.txt").write_text("keep me", encoding="utf-8")
    assert _simulate(taken) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert _simulate(taken, "--overwrite") == 2
    assert "is not an indoorsim recording" in capsys.readouterr().err
    assert [p.name for p in taken.iterdir()] == ["todo.txt"]
    assert _simulate(taken / "todo.txt") == 2
    assert "not a folder" in capsys.readouterr().err


def test_an_earlier_recording_is_replaced_only_with_overwrite(tmp_path, capsys):
    out = tmp_path / "walk"
    assert _simulate(out) == 0
    assert _simulate(out, mode="dangling") == 2
    err = capsys.readouterr().err
    assert str(out) in err and "pass --overwrite" in err
    assert Recording.load(out).meta["mode"] == "handheld"
    assert _simulate(out, "--overwrite", mode="dangling") == 0
    assert Recording.load(out).meta["mode"] == "dangling"


def _minimal_room_with_routes(folder: Path, routes: dict) -> Path:
    """The minimal room with ``routes`` in place of its own."""
    data = yaml.safe_load(bundled_scenarios()["minimal_room"].read_text(encoding="utf-8"))
    data["routes"] = routes
    path = folder / "routes.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def test_simulate_without_route_walks_the_first_and_says_which(tmp_path, capsys):
    argv = ["simulate", "minimal_room", "--mode", "handheld", "--device", "ideal", "--seed", "0"]
    assert main([*argv, "--out", str(tmp_path / "only")]) == 0
    captured = capsys.readouterr()
    assert captured.err.splitlines()[0] == "route: main (the only one)"
    assert "route: " not in captured.out  # stdout keeps the summary alone
    assert Recording.load(tmp_path / "only").meta["route"]["name"] == "main"
    two = {"short": {"waypoints": [[1, 5], [4, 5]]}, "main": {"waypoints": [[1, 5], [9, 5]]}}
    scenario = _minimal_room_with_routes(tmp_path, two)
    argv[1] = str(scenario)
    assert main([*argv, "--out", str(tmp_path / "first")]) == 0
    assert "route: short (the first of: short, main)" in capsys.readouterr().err
    assert Recording.load(tmp_path / "first").meta["route"]["name"] == "short"


def test_simulate_without_route_refuses_a_scenario_without_routes(tmp_path, capsys):
    scenario = _minimal_room_with_routes(tmp_path, {})
    argv = ["simulate", str(scenario), "--mode", "handheld", "--device", "ideal", "--seed", "0"]
    assert main([*argv, "--out", str(tmp_path / "walk")]) == 2
    err = capsys.readouterr().err
    assert err == (
        "indoorsim: scenario 'minimal_room' has no routes to walk (its 'routes:' is empty)\n"
    )
    assert not (tmp_path / "walk").exists()


# ------------------------------------------------------------------- survey


def _survey(scenario: str | Path, out: Path, *extra: str) -> int:
    argv = ["survey", str(scenario), "--device", "honor_50", "--seed", "1", "--out", str(out)]
    return main([*argv, *extra])


def test_grid_survey_writes_the_scenarios_plan_as_a_database(tmp_path, capsys):
    out = tmp_path / "db"
    assert _survey("han2023_basement", out, "--kind", "grid") == 0
    db = FingerprintDB.load(out)
    assert (db.meta["kind"], db.meta["device"], db.meta["seed"]) == ("grid", "honor_50", 1)
    site = load_site("han2023_basement")
    points = grid_points(site, site.scenario.surveys["grid"])
    np.testing.assert_allclose(db["grid"][["x", "y"]].to_numpy(), points)
    summary = " ".join(capsys.readouterr().out.split())
    assert f"{len(points)} points 1.2 m apart" in summary
    assert f"rss_<bssid> × {len(site.radio.bssids)}" in summary  # the storeys around included


def test_walk_survey_writes_reference_points_and_sequences(tmp_path, capsys):
    out = tmp_path / "db"
    assert _survey("chen2022_lab", out, "--kind", "walk", "--name", "walk") == 0
    db = FingerprintDB.load(out)
    assert set(db.tables) == {"magnetic", "markers", "wifi"}
    assert db.meta["kind"] == "walk"
    summary = " ".join(capsys.readouterr().out.split())
    assert f"{len(db['wifi'])} reference points" in summary
    assert f"table magnetic: {len(db['magnetic'])} rows" in summary


@pytest.fixture
def two_grid_plans(tmp_path) -> Path:
    """The minimal room with two small grid survey plans."""
    data = yaml.safe_load(bundled_scenarios()["minimal_room"].read_text(encoding="utf-8"))
    data["surveys"] = {
        "coarse": {"kind": "grid", "spacing": 2.0, "duration_s": 2.0},
        "fine": {"kind": "grid", "spacing": 1.0, "duration_s": 2.0},
    }
    path = tmp_path / "two-plans.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def test_survey_name_picks_one_of_several_plans(two_grid_plans, tmp_path, capsys):
    out = tmp_path / "db"
    assert _survey(two_grid_plans, out, "--kind", "grid") == 2
    assert "choose one with --name: coarse, fine" in capsys.readouterr().err
    assert not out.exists()
    assert _survey(two_grid_plans, out, "--kind", "grid", "--name", "coarse") == 0
    assert FingerprintDB.load(out).meta["spec"]["spacing"] == 2.0


@pytest.mark.parametrize(
    ("scenario", "extra", "expected"),
    [
        ("minimal_room", ["--kind", "grid"], "no grid survey plan; its survey plans are: none"),
        ("minimal_room", ["--kind", "walk"], "no walk survey plan; its survey plans are: none"),
        ("chen2022_lab", ["--kind", "walk", "--name", "loop"], "--name loop"),
        ("han2023_basement", ["--kind", "grid", "--device", "nokia_3310"], "'nokia_3310'"),
    ],
)
def test_survey_refuses_plans_and_devices_that_do_not_exist(
    tmp_path, capsys, scenario, extra, expected
):
    out = tmp_path / "db"
    assert _survey(scenario, out, *extra) == 2
    assert expected in capsys.readouterr().err
    assert not out.exists()
