"""Surveys: fingerprints equal the fields for an ideal phone, and carry a real phone's errors."""

from __future__ import annotations

import numpy as np
import pytest

import indoorsim
from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.phone.devices import get_device
from indoorsim.scenario import GridSurveySpec, WalkSurveySpec
from indoorsim.survey import SURVEY_HOLD_M, grid_points, grid_survey, walk_survey
from indoorsim.walker.gait import PELVIS_HEIGHT_RATIO, WalkerParams
from indoorsim.walker.silhouette import silhouette


@pytest.fixture(scope="module")
def basement():
    return indoorsim.load_site("han2023_basement")


@pytest.fixture(scope="module")
def lab():
    return indoorsim.load_site("chen2022_lab")


SMALL_GRID = GridSurveySpec(kind="grid", spacing=2.4, duration_s=5.0, rate_hz=50.0)


def test_grid_points_are_walkable_and_on_the_spacing(basement):
    pts = grid_points(basement, SMALL_GRID)
    assert len(pts) > 10 and basement.plan.is_walkable(pts).all()
    steps = np.diff(np.unique(pts[:, 0]))
    np.testing.assert_allclose(steps[steps < 3], 2.4)


def _surveyed_lux(site, xyz: np.ndarray, k: float) -> np.ndarray:
    """What a phone of angular response cosᵏ held flat at ``xyz`` reads, its surveyor
    facing +y (heading 90°) SURVEY_HOLD_M behind it."""
    trunk = xyz[:, :2] - [0.0, SURVEY_HOLD_M]
    height = WalkerParams().height_m
    pelvis = np.column_stack([trunk, np.full(len(trunk), PELVIS_HEIGHT_RATIO * height)])
    body = silhouette(pelvis, np.full(len(trunk), np.pi / 2), height)
    return site.illuminance(xyz, np.tile([0.0, 0.0, 1.0], (len(xyz), 1)), body, k)


def test_ideal_grid_survey_measures_the_field_in_the_phones_geographic_frame(basement):
    db = grid_survey(basement, SMALL_GRID, device="ideal", seed=0)
    grid = db["grid"]
    xyz = np.column_stack([grid[["x", "y"]].to_numpy(), np.full(len(grid), 1.2)])
    field = basement.magnetic_field(xyz)
    # The phone's own frame points its y axis at the local magnetic north, so the
    # field reads (0, B_h, B_up) there: an ideal phone recovers it exactly.
    np.testing.assert_allclose(grid["mag_x"], 0.0, atol=1e-6)
    np.testing.assert_allclose(grid["mag_y"], np.hypot(field[:, 0], field[:, 1]), atol=1e-6)
    np.testing.assert_allclose(grid["mag_z"], field[:, 2], atol=1e-6)
    # The surveyor faces +y (heading 90°), holding the phone SURVEY_HOLD_M in front:
    # their head and trunk shade the light sensor, their body the APs behind them.
    trunk = xyz[:, :2] - [0.0, SURVEY_HOLD_M]
    lux = _surveyed_lux(basement, xyz, 1.0)
    np.testing.assert_allclose(grid["lux"], lux, rtol=0.06)  # the hand tilts ~1°
    up = np.tile([0.0, 0.0, 1.0], (len(xyz), 1))
    assert (lux < 0.9 * basement.illuminance(xyz, up)).any()  # a luminaire behind the head
    # The ideal phone reads the local mean plus the multipath fade of its spot.
    rss = basement.rss(xyz, small_scale=True) - basement.radio.body_shadow_db(xyz, trunk)
    assert basement.radio.body_shadow_db(xyz, trunk).max() > 0
    for k, b in enumerate(basement.radio.bssids):
        np.testing.assert_allclose(grid[f"rss_{b}"], rss[:, k], atol=1e-9)


def test_noisy_grid_survey_is_close_but_not_equal(basement):
    ideal = grid_survey(basement, SMALL_GRID, device="ideal", seed=0)["grid"]
    real = grid_survey(basement, SMALL_GRID, device="vivo_s9", seed=0)["grid"]
    diff = (real["mag_norm"] - ideal["mag_norm"]).abs()
    assert 0 < diff.median() < 3.0
    # The real sensor's noise, against what its narrower angular response reads.
    xyz = np.column_stack([real[["x", "y"]].to_numpy(), np.full(len(real), 1.2)])
    k = get_device("vivo_s9").light.response_exponent
    lux_ratio = real["lux"] / _surveyed_lux(basement, xyz, k)
    assert not np.allclose(lux_ratio, 1.0) and np.all(np.abs(lux_ratio - 1) < 0.25)
    assert (real["lux"] < ideal["lux"]).mean() > 0.9  # it reads diffuse light low


def test_survey_is_deterministic_and_round_trips(basement, tmp_path):
    a = grid_survey(basement, SMALL_GRID, device="honor_50", seed=4)
    b = grid_survey(basement, SMALL_GRID, device="honor_50", seed=4)
    c = grid_survey(basement, SMALL_GRID, device="honor_50", seed=5)
    assert a["grid"].equals(b["grid"]) and not a["grid"].equals(c["grid"])
    path = a.save(tmp_path / "db")
    back = FingerprintDB.load(path)
    assert back["grid"].equals(a["grid"]) and back.meta == a.meta
    with pytest.raises(FileExistsError):
        a.save(path)
    with pytest.raises(KeyError, match="tables are"):
        back["wifi"]


def test_walk_survey_labels_from_markers_and_wifi_at_reference_points(lab):
    spec = next(s for s in lab.scenario.surveys.values() if isinstance(s, WalkSurveySpec))
    db, truth = walk_survey(lab, spec, device="ideal", seed=1, with_truth=True)
    mag, marks, wifi = db["magnetic"], db["markers"], db["wifi"]
    assert np.all(np.diff(marks["t"]) >= 0) and np.all(np.diff(mag["t"]) > 0)
    # Labels interpolated between marker taps stay near the phone's true position.
    assert not {"true_x", "true_y"} & set(mag.columns)  # a real team has no truth
    err = np.hypot(mag["x"] - truth["true_x"], mag["y"] - truth["true_y"])
    assert np.median(err) < 0.5 and err.max() < 2.0
    np.testing.assert_allclose(mag["b_h"] ** 2 + mag["b_v"] ** 2, mag["b_norm"] ** 2, rtol=1e-9)
    assert (mag["b_v"] < 0).all()  # the field dips downward in the northern hemisphere
    assert len(wifi) == len(marks) and (wifi["scans"] > 0).all()
    xyz = np.column_stack([wifi[["x", "y"]].to_numpy(), np.full(len(wifi), 1.2)])
    # At each reference point the surveyor faces the next one (the last: as before it).
    ahead = np.diff(xyz[:, :2], axis=0)
    ahead = np.vstack([ahead, ahead[-1:]])
    trunk = xyz[:, :2] - SURVEY_HOLD_M * ahead / np.linalg.norm(ahead, axis=1, keepdims=True)
    rss = lab.rss(xyz, small_scale=True) - lab.radio.body_shadow_db(xyz, trunk)
    for k, b in enumerate(lab.radio.bssids):
        np.testing.assert_allclose(wifi[f"rss_{b}"], rss[:, k], atol=1e-9)
