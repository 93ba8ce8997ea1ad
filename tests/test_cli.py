"""The command line: the scenario table, site plots, and clean errors with exit status 2."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from matplotlib.image import imread

import indoorsim.cli
from indoorsim.cli import main
from indoorsim.scenario import bundled_scenarios, load_scenario

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
