"""The command line: scenarios, simulate, survey, plots, and clean errors with exit status 2."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from matplotlib.image import imread

import indoorsim.cli
import indoorsim.plots
from indoorsim import load_site
from indoorsim.cli import main
from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.io.recording import Recording
from indoorsim.phone.devices import available_devices
from indoorsim.scenario import bundled_scenarios, load_scenario
from indoorsim.survey import grid_points
from tests.conftest import REALDATA

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# Coarse grids and small images keep each plotted site well under a second.
FAST = ["--resolution", "0.5", "--dpi", "50"]
MINIMAL_PLOTS = [
    f"minimal-room_{key}.png"
    for key in ("map", "Bx", "By", "Bz", "B", "lux", "rss_02-00-00-00-00-01")
]


def _table(text: str) -> dict[str, list[str]]:
    """Rows of the ``scenarios`` table by name; columns are separated by two or more spaces."""
    rows = [re.split(r"\s{2,}", line.strip()) for line in text.splitlines() if line.strip()]
    return {row[0]: row[1:] for row in rows}


def _renamed_copy(source: Path, folder: Path, name: str) -> Path:
    data = yaml.safe_load(source.read_text(encoding="utf-8"))
    data["name"] = name
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


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


def test_python_dash_m_runs_the_command_line():
    result = subprocess.run(
        [sys.executable, "-m", "indoorsim", "scenarios"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "minimal_room" in result.stdout


def test_plot_site_writes_valid_pngs_and_prints_their_paths(minimal_site_path, tmp_path, capsys):
    out = tmp_path / "plots"
    assert main(["plot", "site", str(minimal_site_path), "--out", str(out), *FAST]) == 0
    printed = capsys.readouterr().out.split()
    assert [Path(p).name for p in printed] == MINIMAL_PLOTS
    for path in map(Path, printed):
        assert path.parent == out
        assert path.read_bytes()[:8] == PNG_SIGNATURE
        height, width = imread(path).shape[:2]
        assert 150 <= height <= 2000 and 200 <= width <= 3000, (path.name, height, width)


def test_plot_site_all_plots_every_bundled_scenario(
    minimal_site_path, tmp_path, monkeypatch, capsys
):
    other = _renamed_copy(minimal_site_path, tmp_path, "other-room")
    monkeypatch.setattr(
        indoorsim.cli, "bundled_scenarios", lambda: {"a": minimal_site_path, "b": other}
    )
    assert main(["plot", "site", "--all", "--out", str(tmp_path / "all"), *FAST]) == 0
    names = {Path(p).name for p in capsys.readouterr().out.split()}
    assert names == set(MINIMAL_PLOTS) | {n.replace("minimal", "other") for n in MINIMAL_PLOTS}


def test_broken_scenario_file_names_the_file_and_key(minimal_site_path, tmp_path, capsys):
    data = yaml.safe_load(minimal_site_path.read_text(encoding="utf-8"))
    data["walls"][1]["thickness"] = -0.2
    broken = tmp_path / "broken.yaml"
    broken.write_text(yaml.safe_dump(data), encoding="utf-8")
    out = tmp_path / "plots"
    assert main(["plot", "site", str(broken), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(broken) in err and "walls[1].thickness" in err
    assert "Traceback" not in err
    assert not out.exists()


def test_unknown_scenario_name_lists_the_valid_names(tmp_path, capsys):
    assert main(["plot", "site", "no_such_building", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "no_such_building" in err
    assert all(name in err for name in bundled_scenarios())


def test_out_that_is_a_file_is_refused(minimal_site_path, tmp_path, capsys):
    existing = tmp_path / "taken.png"
    existing.write_bytes(b"")
    assert main(["plot", "site", str(minimal_site_path), "--out", str(existing)]) == 2
    assert "not a folder" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--ap", "aa:bb:cc:dd:ee:ff"], "02:00:00:00:00:01, 02:00:00:00:00:02"),
        (["--height", "3.5"], "ceiling"),
        (["--all"], "not both"),
    ],
)
def test_options_that_do_not_fit_are_refused_before_plotting(
    minimal_site_path, tmp_path, capsys, extra, message
):
    out = tmp_path / "plots"
    assert main(["plot", "site", str(minimal_site_path), "--out", str(out), *extra]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_two_scenarios_with_one_name_would_overwrite_each_other(
    minimal_site_path, tmp_path, capsys
):
    twin = _renamed_copy(minimal_site_path, tmp_path, "minimal-room")
    args = ["plot", "site", str(minimal_site_path), str(twin), "--out", str(tmp_path / "p")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert str(minimal_site_path) in err and str(twin) in err
    assert "both named 'minimal-room'" in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        ([], "required: COMMAND"),
        (["plot"], "required: TARGET"),
        (["plot", "site", "--out", "x"], "name at least one scenario"),
        (["plot", "site", "x", "--out", "x", "--height", "-1"], "must be > 0"),
        (["plot", "site", "x", "--out", "x", "--resolution", "fine"], "expected a number"),
        (["plot", "site", "x", "--out", "x", "--dpi", "0"], "must be > 0"),
    ],
)
def test_usage_errors_exit_2_with_a_message(argv, message, capsys):
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_help_exits_0(capsys):
    assert main(["plot", "site", "--help"]) == 0
    assert "--resolution" in capsys.readouterr().out


# ------------------------------------------------------------------- simulate

ILC_TRACES = REALDATA / "ms-indoor-location-2020" / "site1" / "F1" / "path_data_files"
WALK = ["minimal_room", "--route", "main", "--device", "honor_50", "--seed", "3"]
SCHEDULE = "handheld,6:calling,12:pocketed"


def _simulate(out: Path, *extra: str, mode: str = "handheld") -> int:
    return main(["simulate", *WALK, "--mode", mode, "--out", str(out), *extra])


@pytest.fixture(scope="module")
def walk_folder(tmp_path_factory) -> Path:
    """A recording written by ``indoorsim simulate`` with a three-mode schedule."""
    out = tmp_path_factory.mktemp("walks") / "main-3"
    assert _simulate(out, mode=SCHEDULE) == 0
    return out


@pytest.fixture
def ilc_trace() -> Path:
    traces = sorted(ILC_TRACES.glob("*.txt"))
    if not traces:
        pytest.skip(f"real data not found beside the repository: {ILC_TRACES}")
    return traces[0]


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
        ("handheld", ["--route", "nowhere"], ["--route nowhere", "its routes are: main"]),
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
    assert f"rss_<bssid> × {len(site.scenario.wifi)}" in summary


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


# ------------------------------------------------------------------- plot recording


def _assert_png(path: Path) -> None:
    assert path.read_bytes()[:8] == PNG_SIGNATURE
    height, width = imread(path).shape[:2]
    assert 200 <= height <= 3000 and 300 <= width <= 3000, (path.name, height, width)


def _plot_recordings(paths: list[Path], out: Path, *extra: str) -> int:
    return main(["plot", "recording", *map(str, paths), "--out", str(out), "--dpi", "40", *extra])


def test_plot_recording_draws_a_simulated_walk(walk_folder, tmp_path, capsys):
    out = tmp_path / "plots"
    assert _plot_recordings([walk_folder], out) == 0
    printed = [Path(p) for p in capsys.readouterr().out.split()]
    assert printed == [out / "main-3_streams.png", out / "main-3_track.png"]
    for path in printed:
        _assert_png(path)


def test_plot_recording_draws_a_real_trace(ilc_trace, tmp_path, capsys):
    out = tmp_path / "plots"
    assert _plot_recordings([ilc_trace], out) == 0
    printed = [Path(p) for p in capsys.readouterr().out.split()]
    assert printed == [out / f"{ilc_trace.stem}_streams.png", out / f"{ilc_trace.stem}_track.png"]
    for path in printed:
        _assert_png(path)


def test_plot_recording_draws_the_track_on_the_scenario_given(
    walk_folder, minimal_site_path, tmp_path, monkeypatch
):
    drawn_on = []

    def save(rec, out_dir, name, *, site, dpi):
        drawn_on.append(site.name)
        return []

    monkeypatch.setattr(indoorsim.plots, "save_recording_plots", save)
    other = _renamed_copy(minimal_site_path, tmp_path, "other-room")
    assert _plot_recordings([walk_folder], tmp_path / "p", "--scenario", str(other)) == 0
    assert drawn_on == ["other-room"]


def test_two_recordings_with_one_name_would_overwrite_each_other(walk_folder, tmp_path, capsys):
    twin = tmp_path / "elsewhere" / walk_folder.name
    shutil.copytree(walk_folder, twin)
    assert _plot_recordings([walk_folder, twin], tmp_path / "p") == 2
    assert "both named 'main-3'" in capsys.readouterr().err
    assert not (tmp_path / "p").exists()


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (lambda tmp: tmp / "missing", "no such file or folder"),
        (lambda tmp: tmp, "not in a format indoorsim reads"),
    ],
)
def test_plot_recording_refuses_what_is_not_a_recording(tmp_path, capsys, make, expected):
    assert main(["plot", "recording", str(make(tmp_path)), "--out", str(tmp_path / "p")]) == 2
    assert expected in capsys.readouterr().err
    assert not (tmp_path / "p").exists()
