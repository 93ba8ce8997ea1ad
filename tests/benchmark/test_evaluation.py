"""The evaluation protocol: the contract check, episodes, starts, training walks, plug-ins."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import indoorsim
from indoorsim.benchmark.evaluation import (
    EstimatorContractError,
    check_estimator,
    run_episode,
    start_info,
    training_walks,
)
from indoorsim.benchmark.leaderboard import evaluate, markdown_table
from indoorsim.benchmark.metrics import SUMMARY_KEYS
from indoorsim.estimators.base import SiteContext, StartInfo, UnknownEstimatorError, available, make
from indoorsim.io.recording import Recording
from indoorsim.simulate import UnknownRouteError
from indoorsim.walker.modes import UnknownModeError
from tests.conftest import REALDATA

ILC = REALDATA / "ms-indoor-location-2020/site1/F1/path_data_files"


@pytest.mark.parametrize("name", available())
def test_every_registered_estimator_honours_the_contract(name):
    check_estimator(name)


class _Broken:
    name = "broken"

    def __init__(self, answer=(np.nan, 0.0)):
        self.answer = answer

    def fit(self, site, train):
        pass

    def reset(self, start):
        self.rng = np.random.default_rng()

    def act(self, obs):
        return np.array(self.answer)


class _Restless(_Broken):
    name = "restless"

    def act(self, obs):
        return self.rng.normal(size=2)  # ignores the episode seed


class _Crashing(_Broken):
    name = "crashing"

    def act(self, obs):
        return obs["accel"][10_000]  # an IndexError inside the estimator


class _Trusting(_Broken):
    """Integrates the accelerometer without looking: NaN in, NaN out."""

    name = "trusting"

    def act(self, obs):
        return obs["accel"][obs["valid"].astype(bool), :2].sum(axis=0) * 0.0


def test_contract_check_names_the_broken_rule():
    with pytest.raises(EstimatorContractError, match="expected a finite"):
        check_estimator(_Broken())
    with pytest.raises(EstimatorContractError, match="different estimates"):
        check_estimator(_Restless())
    with pytest.raises(
        EstimatorContractError,
        match=r"crashing: the episode failed: estimator 'crashing' raised IndexError in act\(\) "
        r"at window 0 \(t = \d+\.\d\d s\) of seed 7: index 10000 is out of bounds",
    ):
        check_estimator(_Crashing())
    with pytest.raises(
        EstimatorContractError,
        match=r"trusting: failed on a faulty recording \(NaN on every sensor stream for 2 s, "
        r"then a 2 s gap\): estimator 'trusting' returned array\(\[nan, nan\]\)",
    ):
        check_estimator(_Trusting())
    nameless = _Broken((0.0, 0.0))
    nameless.name = ""
    with pytest.raises(EstimatorContractError, match="no non-empty 'name'"):
        check_estimator(nameless)


def test_unknown_estimator_lists_the_available_ones():
    with pytest.raises(UnknownEstimatorError, match=r"valid estimators are: .*pdr-basic"):
        make("no-such-estimator")
    with pytest.raises(UnknownEstimatorError, match="cannot load estimator"):
        make("no_such_module:Thing")


def test_unknown_routes_and_modes_are_refused_before_the_surveys():
    site = indoorsim.load_site("minimal_room")
    with pytest.raises(UnknownRouteError, match=r"unknown route 'nowhere' in scenario"):
        evaluate("start-only", site, route="nowhere")
    with pytest.raises(UnknownModeError, match=r"unknown carrying mode 'juggling'"):
        evaluate("start-only", site, mode="juggling")
    # Both stay ValueErrors, as the evaluation raised before they had their own types.
    assert issubclass(UnknownRouteError, ValueError) and issubclass(UnknownModeError, ValueError)


def test_training_walks_use_other_routes_and_seeds():
    site = indoorsim.load_site("han2023_corridor")
    walks = training_walks(site, "trajectory", mode="handheld", device="ideal", n=2)
    assert {w.meta["route"]["name"] for w in walks} == {"heading_test"}
    assert len({w.meta["seed"] for w in walks}) == 2 and all(w.has_truth for w in walks)


def test_same_route_training_walks_are_the_test_route_by_seeds_no_test_uses():
    """Han2023's likely layer-2 protocol: the same route, but never a test walk."""
    site = indoorsim.load_site("han2023_corridor")
    walks = training_walks(site, "trajectory", mode="handheld", device="ideal", n=2, routes="same")
    assert {w.meta["route"]["name"] for w in walks} == {"trajectory"}
    seeds = {w.meta["seed"] for w in walks}
    assert len(seeds) == 2 and min(seeds) >= 2**31  # test seeds are drawn below 2**31
    test = indoorsim.simulate.simulate(site, route="trajectory", device="ideal", seed=0)
    for w in walks:
        n = min(len(w.accel), len(test.accel))
        assert not np.array_equal(w.accel.to_numpy()[:n], test.accel.to_numpy()[:n])
    with pytest.raises(ValueError, match="train routes must be one of"):
        training_walks(site, "trajectory", mode="handheld", device="ideal", routes="both")


class _LateOracle:
    """Answers the exact true position of ``lag_s`` before each window's end, and says so."""

    name = "late-oracle"
    lag_s = 0.5

    def __init__(self, rec: Recording):
        self.truth = rec.truth

    def fit(self, site, train):
        pass

    def reset(self, start):
        self.estimate_time = None

    def act(self, obs):
        self.estimate_time = float(obs["t"][-1]) - self.lag_s
        ts = self.truth.index.to_numpy(dtype=float)
        return np.array(
            [np.interp(self.estimate_time, ts, self.truth[c].to_numpy(float)) for c in "xy"]
        )


def test_an_exact_but_late_estimate_scores_zero_at_the_time_it_refers_to():
    """Closed form: the truth of half a second ago is exact at its own time, and
    late by the distance walked in half a second at the window's end."""
    from indoorsim.benchmark.evaluation import _score, site_context

    site = indoorsim.load_site("han2023_corridor")
    rec = indoorsim.simulate.simulate(site, route="trajectory", device="ideal", seed=0)
    ctx = site_context(site, device="ideal")
    est = _LateOracle(rec)
    res = run_episode(est, rec, ctx, start_info(rec))
    np.testing.assert_allclose(res.t_ref, res.t - 0.5)
    m = _score(res, rec, plan=None, train_time_s=0.0)
    assert m["ae_reftime"] < 1e-9 and m["n_reftime"] == len(res.t)
    walked = np.hypot(*np.diff(rec.truth[["x", "y"]].to_numpy(), axis=0).T).sum()
    speed = walked / (rec.truth.index[-1] - rec.truth.index[0])
    assert m["ae"] == pytest.approx(0.5 * speed, rel=0.25)


def test_an_estimate_time_after_the_window_is_refused_with_the_estimator_named():
    site = indoorsim.load_site("minimal_room")
    rec = indoorsim.simulate.simulate(site, route="main", device="ideal", seed=0)
    est = _LateOracle(rec)
    est.lag_s = -1.0  # claims to know where the walker will be in a second
    ctx = SiteContext(name="m", window_samples=50)
    with pytest.raises(ValueError, match=r"late-oracle.*estimate_time .*window 0"):
        run_episode(est, rec, ctx, start_info(rec))


@pytest.mark.parametrize("name", ["han2023-pdr", "dr-mm"])
def test_a_step_estimate_refers_to_the_true_step_it_stands_for(name):
    """A step estimator's estimate_time is its last step, less the lag measured on the
    training walks: within a few hundredths of a second of the true step events."""
    from indoorsim.benchmark.evaluation import site_context

    site = indoorsim.load_site("chen2022_lab")
    ctx = site_context(site, device="ideal")
    est = make(name)
    est.fit(ctx, training_walks(site, "walk", mode="handheld", device="ideal", n=1))
    rec = indoorsim.simulate.simulate(site, route="walk", device="ideal", seed=0)
    res = run_episode(est, rec, ctx, start_info(rec))
    t_ref = res.t_ref[res.new_estimates][1:]  # the first is the start
    true_t = rec.steps.index.to_numpy(dtype=float)
    nearest = np.abs(t_ref[:, None] - true_t[None, :]).min(axis=1)
    assert len(t_ref) > 20 and np.median(nearest) < 0.05, np.median(nearest)


@pytest.mark.skipif(not ILC.is_dir(), reason="shared real data not found beside the repository")
def test_real_recording_starts_at_its_first_waypoint_heading_to_the_second():
    rec = Recording.load(next(iter(sorted(ILC.glob("*.txt")))))
    start = start_info(rec)
    wp = rec.waypoints[["x", "y"]].to_numpy()
    np.testing.assert_allclose(start.position, wp[0])
    d = wp[1] - wp[0]
    assert start.heading == pytest.approx(np.arctan2(d[1], d[0]))


def test_start_only_error_is_the_distance_from_the_start():
    site = indoorsim.load_site("minimal_room")
    ev = evaluate("start-only", site, seeds=(0,), device="ideal", n_train=1)
    walk = ev.walks[0].estimates
    assert list(walk.columns) == [
        "t", "x", "y", "t_ref", "true_x", "true_y", "true_x_ref", "true_y_ref"
    ]  # fmt: skip
    assert (walk["t_ref"] == walk["t"]).all()  # no estimate_time: the window's end
    start = walk[["x", "y"]].to_numpy()
    assert np.allclose(start, start[0])
    err = np.hypot(walk["true_x"] - walk["x"], walk["true_y"] - walk["y"])
    assert ev.walks[0].metrics["ae"] == pytest.approx(err.mean())
    row = ev.row()
    assert {"scenario", "mode", "estimator", "seeds", "env_id", "git_revision"} <= set(row)
    assert set(SUMMARY_KEYS) <= set(row) and row["env_id"] == "indoorsim/MinimalRoom-v11"
    assert "| start-only | handheld | 1 |" in markdown_table(pd.DataFrame([row]))


def test_episode_rejects_a_nan_estimate():
    site = indoorsim.load_site("minimal_room")
    rec = indoorsim.simulate.simulate(site, route="main", device="ideal", seed=0)
    ctx = SiteContext(name="m", window_samples=50)
    with pytest.raises(ValueError, match=r"broken.*window 0"):
        run_episode(_Broken(), rec, ctx, StartInfo(position=np.zeros(2), heading=0.0))


@pytest.mark.parametrize(
    ("north_deg", "field"),
    [(0.0, None), (30.0, None), (0.0, [0.0, 30.0, -40.0]), (-40.0, [30.0, 0.0, -40.0])],
)
def test_rotation_vector_heading_converts_to_the_building_frame(north_deg, field):
    from scipy.spatial.transform import Rotation

    from indoorsim.benchmark.evaluation import site_context
    from indoorsim.estimators.frames import heading_from_rotation
    from indoorsim.simulate import simulate
    from indoorsim.world.site import Site

    base = indoorsim.load_site("minimal_room").scenario
    site_spec = base.site.model_copy(update={"north_deg": north_deg, "earth_field_uT": field})
    magnetic = base.magnetic.model_copy(update={"dipoles": []})  # an undisturbed field
    site = Site(base.model_copy(update={"site": site_spec, "magnetic": magnetic, "surveys": {}}))
    ctx = site_context(site, device="ideal")
    rec = simulate(site, route="main", device="ideal", seed=0)
    rot = rec.rotation
    est = heading_from_rotation(rot.to_numpy(), ctx.magnetic_to_building_rad)
    truth = rec.truth
    q = truth[["qw", "qx", "qy", "qz"]].to_numpy()
    top = Rotation.from_quat(q, scalar_first=True).apply([0.0, 1.0, 0.0])
    true = np.interp(rot.index, truth.index, np.unwrap(np.arctan2(top[:, 1], top[:, 0])))
    err = np.degrees(np.angle(np.exp(1j * (est - true))))
    assert np.median(np.abs(err)) < 2.0


def test_true_step_count_starts_at_the_first_sample_whatever_the_window():
    site = indoorsim.load_site("minimal_room")
    counts = {
        w: evaluate("pdr-basic", site, seeds=(0,), device="ideal", n_train=1, window_s=w)
        .walks[0]
        .metrics["step_count_error"]
        for w in (1.0, 5.0)
    }
    assert counts[1.0] == counts[5.0]


@pytest.mark.skipif(not (REALDATA / "oxford-stepcounter").is_dir(), reason="no real data")
def test_real_step_count_table_uses_the_reference_counts(tmp_path):
    from indoorsim.benchmark.leaderboard import write_step_counts

    table = write_step_counts(tmp_path, REALDATA / "oxford-stepcounter")
    inhand = table[
        (table["walk"] == "Pixel_Jamie_Hard_InHand_1") & (table["min_interval_s"] == 0.3)
    ]
    assert inhand["true_steps"].item() == 292
    assert abs(inhand["error_pct"].item()) < 5  # a phone held in the hand: a clean count
    assert "| hand | 0.5 |" in (tmp_path / "step_counts_real.md").read_text()
