"""``indoorsim plot site`` and ``plot recording``: valid PNGs, checked before anything is drawn."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml
from matplotlib.image import imread

import indoorsim.plots
import indoorsim.scenario.load
from indoorsim.cli import main
from indoorsim.scenario import bundled_scenarios
from tests.cli.conftest import renamed_copy
from tests.conftest import REALDATA

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# Coarse grids and small images keep each plotted site well under a second.
FAST = ["--resolution", "0.5", "--dpi", "50"]
MINIMAL_PLOTS = [
    f"minimal-room_{key}.png"
    for key in ("map", "Bx", "By", "Bz", "B", "lux", "rss_02-00-00-00-00-01")
]
ILC_TRACES = REALDATA / "ms-indoor-location-2020" / "site1" / "F1" / "path_data_files"

# ------------------------------------------------------------------- plot site


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
    other = renamed_copy(minimal_site_path, tmp_path, "other-room")
    monkeypatch.setattr(
        indoorsim.scenario.load,
        "bundled_scenarios",
        lambda: {"a": minimal_site_path, "b": other},
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
    twin = renamed_copy(minimal_site_path, tmp_path, "minimal-room")
    args = ["plot", "site", str(minimal_site_path), str(twin), "--out", str(tmp_path / "p")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert str(minimal_site_path) in err and str(twin) in err
    assert "both named 'minimal-room'" in err


# ------------------------------------------------------------------- plot recording


@pytest.fixture
def ilc_trace() -> Path:
    traces = sorted(ILC_TRACES.glob("*.txt"))
    if not traces:
        pytest.skip(f"real data not found beside the repository: {ILC_TRACES}")
    return traces[0]


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
    other = renamed_copy(minimal_site_path, tmp_path, "other-room")
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
