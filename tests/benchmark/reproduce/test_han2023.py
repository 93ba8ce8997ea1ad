"""Han2023's experiments: the table builders, on small budgets and hand-made rows."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import indoorsim
from indoorsim.benchmark.evaluation import run_episode, site_context, start_info, true_headings_at
from indoorsim.benchmark.reproduce import han2023 as rep
from indoorsim.benchmark.reproduce.tables import ordering
from indoorsim.estimators.pipelines.han2023 import HEADING_METHODS, Han2023Pdr
from indoorsim.simulate import simulate


@pytest.fixture(scope="module")
def corridor() -> indoorsim.Site:
    return indoorsim.load_site("han2023_corridor")


def test_ordering_compares_ranks_not_values() -> None:
    assert ordering([1.0, 2.0, 3.0], [10.0, 20.0, 30.0])
    assert not ordering([1.0, 3.0, 2.0], [10.0, 20.0, 30.0])


def test_heading_errors_cover_every_column_with_the_same_steps(corridor: indoorsim.Site) -> None:
    errors = rep.heading_errors(corridor, seeds=(0,), device="ideal")
    assert set(errors) == {(m, wt) for m in HEADING_METHODS for wt in (True, False)}
    counts = {len(e) for e in errors.values()}
    assert len(counts) == 1 and counts.pop() > 40  # one detector: the same steps everywhere
    for e in errors.values():
        assert np.all((e >= 0) & (e <= 180))
    table = rep.heading_table_from(errors)
    assert list(table.columns[:3]) == ["method", "wt", "steps"]
    assert len(table) == 8 and table["mean"].notna().all()


def test_mag_frame_start_recovers_an_unknown_map_rotation(corridor: indoorsim.Site) -> None:
    """A site context whose north is 90° off: the 'start' frame still heads the right way."""
    rec = simulate(corridor, route="heading_test", mode="handheld", device="ideal", seed=3)
    ctx = site_context(corridor, device="ideal")
    wrong = dataclasses.replace(ctx, building_north_deg=ctx.building_north_deg + 90.0)
    mean_error = {}
    for frame in ("site", "start"):
        est = Han2023Pdr(heading_method="mag", mag_frame=frame, calibrate=False)
        est.fit(wrong, [])
        run_episode(est, rec, wrong, start_info(rec, 3))
        t, h, _ = np.array(est.step_log).T
        err = np.angle(np.exp(1j * (h - true_headings_at(rec, t))))
        mean_error[frame] = float(np.degrees(np.abs(err)).mean())
    assert mean_error["site"] > 60.0
    assert mean_error["start"] < 15.0


def test_pdr_rejects_unknown_heading_options() -> None:
    with pytest.raises(ValueError, match="heading_method"):
        Han2023Pdr(heading_method="compass")
    with pytest.raises(ValueError, match="mag_frame"):
        Han2023Pdr(mag_frame="north")


def test_static_table_holds_out_the_points_and_records_curves() -> None:
    site = indoorsim.load_site("han2023_basement")
    budget = {"population": 6, "iterations": 5, "epochs": 20}
    table, curves = rep.static_table(site, n_test=20, budget=budget)
    assert list(table["method"]) == ["BP", "ASO-BP", "Tent-ASO-BP", "1-NN lookup (diagnostic)"]
    assert (table["test_points"] == 20).all()
    assert (table["min"] <= table["mean"]).all() and (table["mean"] <= table["max"]).all()
    assert {len(c) for c in curves.values()} == {20}
    assert table["paper_mean"].tolist()[:3] == [2.51, 1.63, 1.31]


def test_trajectory_table_reads_per_estimate_errors_and_keeps_the_paper_to_its_rows(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Tables 3–4: the paper's four rows are trained on the same route; every row's
    statistics are the errors at the time each estimate refers to (``_reftime``),
    averaged over the fit seeds of the row's network (PDR has none)."""
    calls = []

    class _Ev:
        def __init__(self, routes: str, params: dict) -> None:
            # 1 m on the same route, 2 m on others, +0.5 m PDR-only; ±0.1 m by fit seed.
            self.mean = 1.0 if routes == "same" else 2.0
            self.mean += 0.5 if "layer2_inputs" in params else 0.0
            self.mean += 0.1 * (params.get("fit_seed", 1) - 1)

        def row(self) -> dict[str, float]:
            return {
                "min_reftime": 0.1,
                "me_reftime": 3.0,
                "ae_reftime": self.mean,
                "sd_reftime": 0.4,
                "ae": 9.0,
            }

    def fake_evaluate(est, site, *, train_routes, params, **kwargs):
        calls.append((est, train_routes, params))
        return _Ev(train_routes, params or {})

    monkeypatch.setattr(rep, "evaluate", fake_evaluate)
    t = rep.trajectory_table("han2023_basement", seeds=(0,), fit_seeds=(0, 1, 2))
    # Three fits of each of the five network rows, one PDR run.
    assert len(calls) == 3 * (len(rep.TRAJECTORY_RUNS) - 1) + 1
    assert ("han2023-pdr", "same", None) in calls
    paper_rows = t[np.isfinite(t["paper_mean"])]
    assert list(paper_rows["estimator"]) == list(rep.PAPER_TABLES_3_4["han2023_basement"])
    assert (paper_rows["train_routes"] == "same").all()
    np.testing.assert_allclose(paper_rows["mean"], 1.0)  # (0.9 + 1.0 + 1.1) / 3
    by_est = paper_rows.set_index("estimator")
    assert by_est.loc["han2023-fusion", "paper_mean"] == 0.56
    assert by_est.loc["han2023-fusion", "mean_fit_sd"] == pytest.approx(0.1)
    assert by_est.loc["han2023-pdr", "fit_seeds"] == 0
    extra = t[~np.isfinite(t["paper_mean"])].set_index("method")
    assert extra.loc["GM/Light/PDR fusion, layer 2 on other routes", "mean"] == pytest.approx(2.0)
    assert extra.loc["PDR-only layer 2", "mean"] == pytest.approx(1.5)
    assert (t["max"] == 3.0).all() and (t["mean_time_uniform"] == 9.0).all()


@pytest.mark.slow
def test_table_1_bkf_is_the_best_heading_and_beats_the_magnetometer(
    corridor: indoorsim.Site,
) -> None:
    """The parts of Table 1 that reproduce (leaderboards/commentary.md): over the
    leaderboard's five seeds, BKF has the smallest mean step-heading error of the
    four methods, with and without WT."""
    errors = rep.heading_errors(corridor, seeds=(0, 1, 2, 3, 4))
    for wavelet in (True, False):
        means = {m: float(errors[(m, wavelet)].mean()) for m in HEADING_METHODS}
        assert min(means, key=means.__getitem__) == "bkf", (wavelet, means)
        assert means["bkf"] < means["mag"], (wavelet, means)
