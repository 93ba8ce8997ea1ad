"""Chen2022 pipeline: sequence matching by closed forms, the filters on a bundled site."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

import indoorsim
from indoorsim.benchmark.evaluation import (
    check_estimator,
    run_episode,
    start_info,
    training_walks,
    true_positions_at,
)
from indoorsim.estimators.base import NotApplicableError, SiteContext, StartInfo, make
from indoorsim.estimators.filters import ChickenParticleFilter, ParticleFilter
from indoorsim.estimators.fingerprint import (
    MagneticSequenceMatcher,
    WifiSequenceMatcher,
    reference_tracks,
    resample_by_distance,
)
from indoorsim.estimators.pipelines.chen2022 import (
    DEFAULT_R_MAGNETIC_M2,
    DEFAULT_R_WIFI_M2,
    Chen2022Cpf,
    FixTracker,
)
from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.io.recording import Recording
from indoorsim.simulate import simulate
from indoorsim.windows import PRESENT_ORDER
from tests.estimators.pipelines.conftest import SPACING, MetronomeDR, synthetic_track, wifi_map

NAMES = ["chen2022-cpf", "pf", "dr-wifi", "dr-mm"]


# --- protocol -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_estimator_honours_the_protocol(name: str) -> None:
    est = make(name)
    assert est.name == name
    check_estimator(est)


def test_registered_variants_fuse_what_the_paper_compares() -> None:
    cpf, pf, wifi, mm = (make(n) for n in NAMES)
    assert (cpf.fusion, cpf.use_wifi, cpf.use_magnetic) == ("cpf", True, True)
    assert (pf.fusion, pf.use_wifi, pf.use_magnetic) == ("pf", True, True)
    assert (wifi.fusion, wifi.use_wifi, wifi.use_magnetic) == ("pf", True, False)
    assert (mm.fusion, mm.use_wifi, mm.use_magnetic) == ("pf", False, True)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"fusion": "ekf"},
        {"matcher": "dtw"},
        {"likelihood": "laplace"},
        {"use_wifi": False, "use_magnetic": False},
        {"query_steps": 0},
    ],
)
def test_invalid_options_are_rejected(kwargs: dict) -> None:
    with pytest.raises(ValueError):
        Chen2022Cpf(**kwargs)


# The pipeline's estimators and the cited methods it is compared with share the front end.
@pytest.mark.parametrize("name", [*NAMES, "edtw-rekf", "apf", "wimag"])
def test_a_site_without_a_walk_survey_is_not_applicable(name: str) -> None:
    with pytest.raises(NotApplicableError, match="walk survey"):
        make(name).fit(SiteContext(name="bare"), [])
    grid = FingerprintDB(tables={"grid": pd.DataFrame({"x": [0.0], "y": [0.0]})})
    with pytest.raises(NotApplicableError, match="walk survey"):
        make(name).fit(SiteContext(name="grid only", fingerprints={"grid": grid}), [])


# --- matching: closed forms -----------------------------------------------------------------


def test_resampling_by_distance_averages_the_samples_of_each_cell() -> None:
    s = np.array([0.0, 0.05, 0.5, 0.5, 0.5, 1.0])
    grid, v = resample_by_distance(s, 2.0 * s, 0.5)
    np.testing.assert_allclose(grid, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(v, [0.05, 1.0, 2.0])  # cell 0 averages 0 and 0.1
    # A linear profile sampled symmetrically about each grid point comes back exactly
    # (the two end cells hold half a cell's samples).
    dense = 0.008 * np.arange(1251)
    grid, v = resample_by_distance(dense, 3.0 * dense - 1.0, 0.2)
    np.testing.assert_allclose(grid, 0.2 * np.arange(51), atol=1e-12)
    np.testing.assert_allclose(v[1:-1], 3.0 * grid[1:-1] - 1.0, atol=1e-9)
    # A cell no sample falls in is interpolated from its neighbours.
    grid, v = resample_by_distance([0.0, 1.0], [0.0, 4.0], 0.25)
    np.testing.assert_allclose(v, [0.0, 1.0, 2.0, 3.0, 4.0])


def test_reference_tracks_follow_the_labelled_path() -> None:
    table = synthetic_track()
    (track,) = reference_tracks(table, SPACING)
    np.testing.assert_allclose(track.s, SPACING * np.arange(len(table)), atol=1e-9)
    np.testing.assert_allclose(track.xy, table[["x", "y"]].to_numpy(), atol=1e-9)
    np.testing.assert_allclose(track.hv, table[["b_h", "b_v"]].to_numpy(), atol=1e-9)
    back = track.reversed()
    np.testing.assert_allclose(back.xy, track.xy[::-1])
    np.testing.assert_allclose(back.s, track.s)


@pytest.mark.parametrize("matcher", ["hv-ddtw", "md-dtw"])
@pytest.mark.parametrize(("start", "stop"), [(10, 60), (40, 95), (90, 151)])
def test_an_exact_subsegment_matches_its_end_position(matcher: str, start: int, stop: int) -> None:
    tracks = reference_tracks(synthetic_track(), SPACING)
    hv, xy = tracks[0].hv, tracks[0].xy
    m = MagneticSequenceMatcher(matcher=matcher).fit(tracks)
    position, distance = m.match(hv[start:stop])
    assert distance == 0.0
    np.testing.assert_array_equal(position, xy[stop - 1])
    # Walked the other way, the segment ends where the survey's began.
    position, _ = m.match(hv[start:stop][::-1])
    np.testing.assert_array_equal(position, xy[start])


def test_hv_ddtw_ignores_a_constant_offset_and_md_dtw_does_not() -> None:
    tracks = reference_tracks(synthetic_track(), SPACING)
    query = tracks[0].hv[30:90] + np.array([4.0, -3.0])  # another phone's offset, say
    hv_ddtw = MagneticSequenceMatcher(matcher="hv-ddtw").fit(tracks)
    position, distance = hv_ddtw.match(query)
    assert distance == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(position, tracks[0].xy[89])
    _, distance = MagneticSequenceMatcher(matcher="md-dtw").fit(tracks).match(query)
    assert distance > 1.0


@pytest.mark.parametrize("scans", [1, 2, 3])
def test_wifi_wknn_returns_the_exact_point_on_a_noise_free_map(scans: int) -> None:
    points, rss = wifi_map()
    m = WifiSequenceMatcher(scans=scans).fit([(points, rss)])
    for j in range(scans - 1, len(points)):
        position, distance = m.match(rss[j - scans + 1 : j + 1])
        assert distance == 0.0
        np.testing.assert_array_equal(position, points[j])
    # Walking back along the corridor: the profile reversed ends at its first point.
    position, _ = m.match(rss[2 : 2 + scans][::-1])
    np.testing.assert_array_equal(position, points[2])


# --- the front end --------------------------------------------------------------------------


def observation(t: np.ndarray, mag: np.ndarray, gravity: np.ndarray) -> dict[str, np.ndarray]:
    w = len(t)
    present = {
        "gyro": 0,
        "mag": 1,
        "rotation": 0,
        "light": 0,
        "wifi": 0,
        "gravity": 1,
        "game_rotation": 0,
    }
    return {
        "t": t,
        "valid": np.ones(w, np.int8),
        "accel": gravity.copy(),
        "gyro": np.zeros((w, 3)),
        "mag": mag,
        "mag_fresh": np.ones(w, np.int8),
        "gravity": gravity,
        "wifi_rss": np.zeros(0),
        "wifi_heard": np.zeros(0, np.int8),
        "wifi_fresh": np.zeros(1, np.int8),
        "wifi_age": np.zeros(1),
        "present": np.array([present[k] for k in PRESENT_ORDER], np.int8),
    }


def test_fixes_do_not_depend_on_how_the_phone_is_held() -> None:
    """HV fingerprints are orientation-invariant: tumbling the phone changes no fix (Eq. 17–18)."""
    table = synthetic_track()
    tracks = reference_tracks(table, SPACING)
    speed, rate = 1.2, 50.0
    t = np.arange(1, int(20.0 * rate) + 1) / rate
    s = speed * t
    b_h = np.interp(s, tracks[0].s, tracks[0].hv[:, 0])
    b_v = np.interp(s, tracks[0].s, tracks[0].hv[:, 1])
    # The field in the world (east, north, up): horizontal part turning as the track bends.
    world = np.column_stack([b_h * np.cos(0.3 * s), b_h * np.sin(0.3 * s), b_v])
    up = np.array([0.0, 0.0, 9.81])
    fixes = []
    for attitude in (
        Rotation.identity(len(t)),
        Rotation.from_euler("xyz", np.column_stack([0.9 * np.sin(3 * t), 0.4 * t, 2.0 * t])),
    ):
        mag = attitude.inv().apply(world)  # phone frame
        gravity = attitude.inv().apply(np.tile(up, (len(t), 1)))
        tracker = FixTracker(
            dr=MetronomeDR(length=speed * 0.5),  # type: ignore[arg-type]
            magnetic=MagneticSequenceMatcher().fit(tracks),
            query_steps=16,
            spacing_m=SPACING,
        )
        tracker.reset(0.0, 0.0)
        out = []
        for k in range(0, len(t), 50):
            sl = slice(k, k + 50)
            out += tracker.process(observation(t[sl], mag[sl], gravity[sl]))
        fixes.append(np.array([f.magnetic for f in out if f.magnetic is not None]))
    assert len(fixes[0]) > 10
    np.testing.assert_allclose(fixes[1], fixes[0], atol=1e-6)
    # The fixes follow the survey's labels: the walker is where its distance puts it.
    t_fix = np.array([f.step.t for f in out if f.magnetic is not None])
    truth = table[["x", "y"]].to_numpy()[np.rint(speed * t_fix / SPACING).astype(int)]
    assert np.median(np.linalg.norm(fixes[0] - truth, axis=1)) < 0.5


# --- the pipeline on a bundled Chen site ----------------------------------------------------


def test_fit_calibrates_the_length_scale_and_the_likelihoods(
    lab_context: SiteContext, lab_train: list[Recording]
) -> None:
    est = Chen2022Cpf()
    est.fit(lab_context, [])
    assert est.dr.length_scale == 1.0
    assert (est.r_magnetic_m2, est.r_wifi_m2) == (DEFAULT_R_MAGNETIC_M2, DEFAULT_R_WIFI_M2)
    est.fit(lab_context, lab_train)
    assert 0.5 < est.dr.length_scale < 2.0 and est.dr.length_scale != 1.0
    assert est.r_magnetic_m2 >= 0.25 and est.r_wifi_m2 >= 0.25
    assert est.r_wifi_m2 != DEFAULT_R_WIFI_M2 and est.r_magnetic_m2 != DEFAULT_R_MAGNETIC_M2
    # A later fit without training walks starts again from the configured values.
    est.fit(lab_context, [])
    assert est.dr.length_scale == 1.0 and est.r_wifi_m2 == DEFAULT_R_WIFI_M2


def test_the_pipeline_follows_an_ideal_handheld_walk(
    lab: indoorsim.Site, lab_context: SiteContext, lab_train: list[Recording]
) -> None:
    rec = simulate(lab, route="survey_loop", mode="handheld", device="ideal", seed=1)
    errors = {}
    for name in ("chen2022-cpf", "start-only"):
        est = make(name)
        est.fit(lab_context, lab_train)
        result = run_episode(est, rec, lab_context, start_info(rec, seed=1))
        err = np.linalg.norm(result.estimate - true_positions_at(rec, result.t), axis=1)
        errors[name] = err
    cpf = errors["chen2022-cpf"]
    # Measured: AE 1.3 m against start-only's 8.0 m, last error under 2 m.
    assert cpf.mean() < 0.3 * errors["start-only"].mean()
    assert cpf[-1] < 4.0


@pytest.mark.parametrize("mode", ["handheld", "calling", "dangling", "pocketed"])
def test_no_surviving_particle_stands_in_a_wall(
    mode: str, lab: indoorsim.Site, lab_context: SiteContext
) -> None:
    rec = simulate(lab, route="walk", mode=mode, device="nexus_5x", seed=4)
    train = training_walks(lab, "walk", mode=mode, device="nexus_5x", n=1)
    est = make("chen2022-cpf")
    est.fit(lab_context, train)
    result = run_episode(est, rec, lab_context, start_info(rec, seed=4))
    assert np.isfinite(result.estimate).all() and result.step_count > 0
    pf = est.particle_filter
    assert isinstance(pf, ChickenParticleFilter) and pf.x.shape == (est.n_particles, 2)
    alive = pf.w > 0
    assert alive.sum() > 0
    assert lab.plan.is_walkable(pf.x[alive]).all()


def test_options_for_fig8_and_the_literal_likelihood_run(
    lab: indoorsim.Site, lab_context: SiteContext, lab_train: list[Recording]
) -> None:
    rec = simulate(lab, route="survey_loop", mode="handheld", device="ideal", seed=2)
    for kwargs in ({"matcher": "md-dtw"}, {"likelihood": "literal"}, {"fusion": "pf"}):
        est = Chen2022Cpf(n_particles=200, **kwargs)
        est.fit(lab_context, lab_train)
        result = run_episode(est, rec, lab_context, start_info(rec, seed=2))
        assert np.isfinite(result.estimate).all()
        assert isinstance(est.particle_filter, ParticleFilter)


def test_it_runs_on_the_accelerometer_alone(
    lab: indoorsim.Site, lab_context: SiteContext, lab_train: list[Recording]
) -> None:
    rec = simulate(lab, route="survey_loop", mode="handheld", device="ideal", seed=3)
    bare = Recording(streams={"accel": rec.accel}, meta=rec.meta)
    est = make("chen2022-cpf")
    est.fit(lab_context, lab_train)
    result = run_episode(est, bare, lab_context, start_info(rec, seed=3))
    assert np.isfinite(result.estimate).all()
    assert result.step_count is not None and result.step_count > 0


def test_the_cpf_passes_the_printed_swarm_readings_to_its_filter(
    lab_context: SiteContext,
) -> None:
    """Defaults as Chen2022 prints them (weight fitness, Eq. 30b's q_mea, exp(−d));
    the other readings reach the filter when asked for."""
    start = StartInfo(position=np.array([1.3, 10.9]), heading=0.0, seed=1)
    for kwargs, expected in (
        ({}, ("weight", "printed")),
        ({"fitness": "cost", "rooster_spread": "cso"}, ("cost", "cso")),
    ):
        est = Chen2022Cpf(n_particles=50, **kwargs)
        est.fit(lab_context, [])
        est.reset(start)
        pf = est.particle_filter
        assert isinstance(pf, ChickenParticleFilter)
        assert (pf.fitness, pf.rooster_spread) == expected
    assert Chen2022Cpf().likelihood == "literal"
    with pytest.raises(ValueError, match="rooster_spread"):
        Chen2022Cpf(fitness="cost", rooster_spread="printed")


@pytest.mark.parametrize("only", [None, "wifi", "magnetic"])
def test_the_default_likelihood_is_eq_27_as_printed(only: str | None) -> None:
    """Eq. 27–28 by hand: q = Π 1/(√‖R‖·√2π)·exp(−‖z − x‖) over the fixes present.
    The prefactor is the same for every particle, so the weights it gives are those
    of exp(−d_WiFi − d_MM) once normalised."""
    from indoorsim.estimators.pdr import GaitStep
    from indoorsim.estimators.pipelines.chen2022 import StepFixes

    est = Chen2022Cpf()
    est.r_wifi_m2, est.r_magnetic_m2 = 7.0, 3.0  # only the prefactor would see them
    z_wifi, z_mag = np.array([2.0, 1.0]), np.array([-1.0, 3.0])
    fixes = StepFixes(
        GaitStep(1.0, 0.6, 0.0, 0.0, 0.05),
        magnetic=None if only == "wifi" else z_mag,
        wifi=None if only == "magnetic" else z_wifi,
    )
    particles = np.array([[0.0, 0.0], [2.0, 1.0], [-1.0, 3.0], [5.0, -4.0]])
    q = est._likelihood(fixes)(particles)
    by_hand = np.ones(len(particles))
    for z, r, kind in ((z_wifi, 7.0, "wifi"), (z_mag, 3.0, "magnetic")):
        if only in (None, kind):
            d = np.hypot(*(particles - z).T)
            by_hand *= np.exp(-d) / (np.sqrt(r) * np.sqrt(2 * np.pi))
    np.testing.assert_allclose(q / q.sum(), by_hand / by_hand.sum(), rtol=1e-12)
    # d = 0 to its own fix and √13 m to the other: exp(−√13) of the unnormalised value
    if only is None:
        assert q[1] == pytest.approx(np.exp(-np.sqrt(13.0)))
