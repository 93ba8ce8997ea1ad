"""``indoorsim import-plan``: a real floor plan to a scenario file, and its bad inputs."""

from __future__ import annotations

import json

import pytest

from indoorsim.cli import main
from indoorsim.scenario.load import load_scenario
from tests.scenario.imports.conftest import MS_FLOOR, needs_ms_floor, write_plan


def _one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("indoorsim: "), err
    return lines[0].removeprefix("indoorsim: ")


def test_a_synthetic_plan_becomes_a_scenario(tmp_path, capsys):
    geo, info = write_plan(tmp_path)
    out = tmp_path / "plan.yaml"
    assert main(["import-plan", str(geo), "--floor-info", str(info), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "walls 10 (" in text and "rooms 2 (0 sliver shops dropped), doors 2 (" in text
    assert f"wrote {out}" in text and " s in all)" in text
    scenario = load_scenario(out)
    assert scenario.name == "ilc-t1-0" and len(scenario.doors) == 2
    # floor_info.json beside the GeoJSON is the default; an existing --out needs --overwrite.
    assert main(["import-plan", str(geo), "--out", str(out)]) == 2
    assert _one_line_error(capsys) == f"--out {out}: already exists; pass --overwrite to replace it"
    assert main(["import-plan", str(geo), "--seed", "4", "--out", str(out), "--overwrite"]) == 0
    # A folder not there yet is made, as the documented learned-io recipe needs.
    nested = tmp_path / "plans" / "ms" / "plan.yaml"
    assert main(["import-plan", str(geo), "--out", str(nested)]) == 0
    assert load_scenario(nested).name == scenario.name


@pytest.mark.parametrize(
    ("content", "problem"),
    [
        (None, "no such file"),
        (
            '{"type": "FeatureCollection", "features": [',
            "not JSON (line 1, column 44: Expecting value)",
        ),
        ("[1, 2]", "not GeoJSON: expected a FeatureCollection"),
        ('{"type": "FeatureCollection", "features": []}', "no floor feature (one whose"),
    ],
)
def test_bad_geojson_is_one_line_naming_the_file(tmp_path, capsys, content, problem):
    _, info = write_plan(tmp_path)
    geo = tmp_path / "plan.json"
    if content is not None:
        geo.write_text(content, encoding="utf-8")
    args = ["import-plan", str(geo), "--floor-info", str(info), "--out", str(tmp_path / "o.yaml")]
    assert main(args) == 2
    assert _one_line_error(capsys).startswith(f"{geo}: {problem}")
    assert not (tmp_path / "o.yaml").exists()


def test_bad_floor_info_and_traces_are_one_line(tmp_path, capsys):
    geo, info = write_plan(tmp_path)
    out = str(tmp_path / "o.yaml")
    info.write_text(json.dumps({"width": 3}), encoding="utf-8")
    assert main(["import-plan", str(geo), "--out", out]) == 2
    assert _one_line_error(capsys) == (
        f"{info}: no map_info with a width and height (m): not a floor_info.json"
    )
    geo, info = write_plan(tmp_path)
    missing = tmp_path / "traces"
    assert main(["import-plan", str(geo), "--traces", str(missing), "--out", out]) == 2
    assert _one_line_error(capsys) == f"--traces {missing}: no such folder"
    missing.mkdir()
    assert main(["import-plan", str(geo), "--traces", str(missing), "--out", out]) == 2
    assert "no Indoor Location Competition traces" in _one_line_error(capsys)


@needs_ms_floor
def test_the_ms_floor_with_its_traces(tmp_path, capsys):
    out = tmp_path / "ms.yaml"
    args = ["import-plan", str(MS_FLOOR / "geojson_map.json"), "--out", str(out)]
    assert main([*args, "--traces", str(MS_FLOOR / "path_data_files")]) == 0
    text = capsys.readouterr().out
    assert "(floor F1, 239.8 m × 176.4 m), seed 0, in " in text
    kept = int(text.split("routes from 16 traces: ")[1].split(" kept")[0])
    left_out = [line for line in text.splitlines() if line.startswith("    left out ")]
    assert kept + len(left_out) == 16 and kept >= 12
    assert all("passes through a wall" in line for line in left_out)
    assert len(load_scenario(out).routes) == kept
