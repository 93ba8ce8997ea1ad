"""Han2023 pipeline: protocol, K calibration, PDR on a basement walk, layer 1, the fusion."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import indoorsim
from indoorsim.benchmark.evaluation import (
    check_estimator,
    run_episode,
    site_context,
    start_info,
    training_walks,
    true_positions_at,
)
from indoorsim.estimators.base import Estimator, NotApplicableError, SiteContext
from indoorsim.estimators.pdr import PeakStepDetector, weinberg
from indoorsim.estimators.pipelines.han2023 import (
    AsoBP,
    Han2023Fusion,
    Han2023GM,
    Han2023GML,
    Han2023Pdr,
    PlainBP,
    TentAsoBPStatic,
    match_steps,
)
from indoorsim.scenario import GridSurveySpec
from indoorsim.simulate import simulate
from indoorsim.world.site import Site

TINY = {"population": 6, "iterations": 5, "epochs": 20}


def tiny(name: str) -> Estimator:
    if name == "han2023-pdr":
        return Han2023Pdr()
    if name == "han2023-fusion":
        return Han2023Fusion(gml=Han2023GML(**TINY), **TINY)
    cls = {
        "han2023-gm": Han2023GM,
        "han2023-gml": Han2023GML,
        "bp": PlainBP,
        "aso-bp": AsoBP,
        "tent-aso-bp": TentAsoBPStatic,
    }[name]
    return cls(**TINY)


NAMES = [
    "han2023-pdr",
    "han2023-gm",
    "han2023-gml",
    "han2023-fusion",
    "bp",
    "aso-bp",
    "tent-aso-bp",
]


@pytest.fixture(scope="module")
def basement() -> indoorsim.Site:
    return indoorsim.load_site("han2023_basement")


@pytest.fixture(scope="module")
def basement_context(basement: indoorsim.Site) -> SiteContext:
    return site_context(basement, device="ideal")


@pytest.fixture(scope="module")
def basement_train(basement: indoorsim.Site) -> list[indoorsim.Recording]:
    return training_walks(basement, "A_to_D", mode="handheld", device="ideal", n=2)


# --- protocol -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_estimator_honours_the_protocol(name: str) -> None:
    est = tiny(name)
    assert est.name == name
    assert isinstance(est, Estimator)
    check_estimator(est)


def test_variants_set_the_table_2_flags() -> None:
    assert (PlainBP().use_tent, PlainBP().use_aso) == (False, False)
    assert (AsoBP().use_tent, AsoBP().use_aso) == (False, True)
    assert (TentAsoBPStatic().use_tent, TentAsoBPStatic().use_aso) == (True, True)
    assert (Han2023GML().population, Han2023GML().iterations, Han2023GML().epochs) == (
        30,
        500,
        1000,
    )


def test_layer_1_needs_a_grid_survey() -> None:
    with pytest.raises(NotApplicableError, match="grid survey"):
        Han2023GML(**TINY).fit(SiteContext(name="bare"), [])
    with pytest.raises(NotApplicableError):
        Han2023Fusion(gml=Han2023GML(**TINY), **TINY).fit(SiteContext(name="bare"), [])


def test_bkf_origin_is_validated() -> None:
    with pytest.raises(ValueError, match="bkf_origin"):
        Han2023Pdr(bkf_origin="north")


# --- PDR ------------------------------------------------------------------------------------


def test_calibrated_k_within_10_percent_of_the_true_ratio(
    basement_context: SiteContext, basement_train: list[indoorsim.Recording]
) -> None:
    pdr = Han2023Pdr()
    pdr.fit(basement_context, basement_train)
    true_len, features = 0.0, 0.0
    for rec in basement_train:
        steps = PeakStepDetector().update(rec.accel.index.to_numpy(), rec.accel.to_numpy())
        matched, lengths = match_steps(
            steps, rec.steps.index.to_numpy(float), rec.steps["length"].to_numpy(float)
        )
        assert len(matched) >= 0.9 * len(rec.steps)
        true_len += lengths.sum()
        features += weinberg([s.a_max for s in matched], [s.a_min for s in matched], 1.0).sum()
    assert pdr.k_fitted == pytest.approx(true_len / features, rel=0.10)
    # Without training walks: the default K.
    pdr.fit(basement_context, [])
    assert pdr.k_fitted == pdr.weinberg_k


@pytest.mark.parametrize("wavelet", [False, True])
def test_pdr_ends_near_the_truth_on_a_basement_walk(
    basement: indoorsim.Site,
    basement_context: SiteContext,
    basement_train: list[indoorsim.Recording],
    wavelet: bool,
) -> None:
    # Held straight ahead: a grip's drawn misalignment (5° SD) turns the whole 43 m track
    # by itself (3.7 m at its end), which a PDR taking the phone's heading cannot know.
    straight = [(0.0, "handheld", {"misalignment_deg": 0.0})]
    rec = simulate(basement, route="A_to_D", mode=straight, device="ideal", seed=1)
    pdr = Han2023Pdr(wavelet=wavelet)
    pdr.fit(basement_context, basement_train)
    result = run_episode(pdr, rec, basement_context, start_info(rec))
    truth = true_positions_at(rec, result.t)
    assert np.linalg.norm(result.estimate[-1] - truth[-1]) < 3.0
    assert abs(result.step_count - len(rec.steps)) <= 0.05 * len(rec.steps)
    assert np.isfinite(result.heading).all()


# --- layer 1 --------------------------------------------------------------------------------


def synthetic_library() -> pd.DataFrame:
    """A noise-free library whose features vary smoothly and one-to-one with position."""
    x, y = np.meshgrid(np.arange(0.0, 6.01, 0.3), np.arange(0.0, 9.01, 0.3))
    x, y = x.ravel(), y.ravel()
    return pd.DataFrame(
        {
            "x": x,
            "y": y,
            "Mx": 20.0 + 1.5 * x + 0.2 * y,
            "My": -10.0 + 0.3 * x + 1.2 * y,
            "Mz": -40.0 + 0.5 * np.sin(0.3 * x) + 0.1 * y,
            "L": 150.0 + 8.0 * y,
        }
    )


@pytest.mark.parametrize("cls", [Han2023GML, Han2023GM])
def test_layer_1_reproduces_its_training_points(cls: type[Han2023GML]) -> None:
    table = synthetic_library()
    net = cls(population=30, iterations=300, epochs=1000)
    net.fit_table(table)
    assert net.network is not None
    pred = net.predict(table[list(cls.features)].to_numpy())
    err = np.linalg.norm(pred - table[["x", "y"]].to_numpy(), axis=1)
    assert err.mean() < 0.5, err.mean()


# --- fusion ---------------------------------------------------------------------------------


def test_fusion_runs_end_to_end_on_a_small_room() -> None:
    base = indoorsim.load_site("minimal_room").scenario
    site = Site(
        base.model_copy(
            update={"surveys": {"grid": GridSurveySpec(kind="grid", spacing=1.2, duration_s=2.0)}}
        )
    )
    ctx = site_context(site, device="mid_grade", window_s=0.5)
    route = next(iter(site.scenario.routes))
    train = training_walks(site, route, mode="handheld", device="mid_grade", n=2)
    fusion = Han2023Fusion(gml=Han2023GML(**TINY), **TINY)
    fusion.fit(ctx, train)
    assert fusion.network is not None and fusion.pdr.k_fitted != fusion.pdr.weinberg_k
    rec = simulate(site, route=route, mode="handheld", device="mid_grade", seed=3)
    result = run_episode(fusion, rec, ctx, start_info(rec, seed=3))
    assert result.estimate.shape == (len(result.t), 2)
    assert np.isfinite(result.estimate).all()
    # The tiny networks are not expected to locate well; the PDR layer under
    # them must still count the walk's steps.
    walked = (rec.steps.index >= result.t_start) & (rec.steps.index <= result.t[-1])
    assert result.step_count is not None
    assert abs(result.step_count - int(walked.sum())) <= 2


def test_a_pdr_only_layer_2_takes_the_two_pdr_coordinates() -> None:
    """The diagnostic row of Tables 3–4: layer 2 fed (x_PDR, y_PDR) alone, and no
    layer 1 (so no grid survey) needed."""
    site = indoorsim.load_site("minimal_room")
    ctx = site_context(site, device="mid_grade", window_s=0.5)
    route = next(iter(site.scenario.routes))
    train = training_walks(site, route, mode="handheld", device="mid_grade", n=1, routes="same")
    fusion = Han2023Fusion(layer2_inputs="pdr", **TINY)
    inputs, targets = fusion.layer_two_data(ctx, train)
    assert inputs.shape[1] == 2 and targets.shape == (len(inputs), 2)
    fusion.fit(ctx, train)  # the minimal room has no grid survey: layer 1 is not fitted
    assert fusion.gml.network is None and fusion.network is not None
    with pytest.raises(ValueError, match="layer2_inputs must be one of"):
        Han2023Fusion(layer2_inputs="light")
