"""EDTW + REKF, APF and WiMag approximations: closed forms of their parts, runs on the sites."""

from __future__ import annotations

import numpy as np
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
from indoorsim.estimators.base import NotApplicableError, SiteContext, make
from indoorsim.estimators.fingerprint import derivative, reference_tracks
from indoorsim.estimators.fingerprint.sequences import WifiSequenceMatcher
from indoorsim.estimators.pdr.gait import GaitStep
from indoorsim.estimators.pipelines.chen2022 import StepFixes
from indoorsim.estimators.pipelines.chen2022_cited import (
    AdaptiveParticleFilter,
    Apf,
    CoarseRegionTracker,
    EdtwMatcher,
    EdtwRekf,
    MdedWifiMatcher,
    RegionMagneticMatcher,
    RobustEkf,
    WiMag,
    edtw_many,
    mded_many,
)
from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.io.recording import Recording
from indoorsim.simulate import simulate
from indoorsim.windows import PRESENT_ORDER
from tests.estimators.pipelines.conftest import SPACING, MetronomeDR, synthetic_track, wifi_map

NAMES = ["edtw-rekf", "apf", "wimag"]


# --- protocol -------------------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_estimator_honours_the_protocol_and_says_it_is_an_approximation(name: str) -> None:
    est = make(name)
    assert est.name == name
    assert type(est).__doc__.startswith("Approximation of ")
    check_estimator(est)


def test_apf_without_wifi_references_is_not_applicable() -> None:
    walk = FingerprintDB(tables={"magnetic": synthetic_track()})
    with pytest.raises(NotApplicableError, match="WiFi"):
        make("apf").fit(SiteContext(name="no wifi", fingerprints={"walk": walk}), [])


# --- EDTW: closed forms ---------------------------------------------------------------------


def test_edtw_ignores_an_offset_and_scales_with_a_gain_as_designed() -> None:
    s = np.linspace(0.0, 12.0, 60)
    r = 45.0 + 3.0 * np.sin(1.1 * s) + np.cos(0.4 * s)
    w = 5.0
    assert edtw_many(r + 7.0, [r], slope_weight=w)[0] == pytest.approx(0.0, abs=1e-9)
    a = 1.5
    q = 3.0 + a * r  # about its mean: a·(r − r̄), slope a·r'
    centred, slope = r - r.mean(), derivative(r)
    on_diagonal = abs(a - 1.0) * np.sum(np.sqrt(centred**2 + w**2 * slope**2))
    assert edtw_many(q, [r], slope_weight=w, window=0)[0] == pytest.approx(on_diagonal, rel=1e-12)
    warped = edtw_many(q, np.array([r]), slope_weight=w)[0]
    assert 0.0 < warped <= on_diagonal + 1e-9


def magnitude_query(hv: np.ndarray, offset_ut: float) -> np.ndarray:
    """An HV query whose magnitude is the reference's plus a constant (B_V kept)."""
    b = np.hypot(hv[:, 0], hv[:, 1]) + offset_ut
    return np.column_stack([np.sqrt(b**2 - hv[:, 1] ** 2), hv[:, 1]])


@pytest.mark.parametrize(("start", "stop"), [(10, 60), (40, 95), (90, 151)])
def test_edtw_matcher_finds_an_offset_segment_at_its_end(start: int, stop: int) -> None:
    tracks = reference_tracks(synthetic_track(), SPACING)
    hv, xy = tracks[0].hv, tracks[0].xy
    m = EdtwMatcher(spacing_m=SPACING).fit(tracks)
    position, distance = m.match(magnitude_query(hv[start:stop], offset_ut=2.5))
    assert distance == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(position, xy[stop - 1])


# --- REKF: closed forms ---------------------------------------------------------------------


def test_rekf_prediction_is_the_pdr_step_with_its_jacobians() -> None:
    sl, dth, sig_sl, sig_th, sig_xy = 0.7, 0.2, 0.05, 0.02, 0.1
    ekf = RobustEkf(sigma_step=sig_sl, sigma_heading=sig_th, sigma_xy=sig_xy)
    ekf.initialise([1.0, 2.0], heading=0.3, position_std=0.5, heading_std=0.1)
    x0, P0 = ekf.x.copy(), ekf.P.copy()

    def f(state: np.ndarray, noise: np.ndarray) -> np.ndarray:
        th = state[2] + dth + noise[1]
        length = sl + noise[0]
        return np.array([state[0] + length * np.cos(th), state[1] + length * np.sin(th), th])

    def jacobian(fn, at: np.ndarray, h: float = 1e-6) -> np.ndarray:
        cols = [(fn(at + h * e) - fn(at - h * e)) / (2 * h) for e in np.eye(len(at))]
        return np.column_stack(cols)

    F = jacobian(lambda s: f(s, np.zeros(2)), x0)
    G = jacobian(lambda n: f(x0, n), np.zeros(2))
    Q = G @ np.diag([sig_sl**2, sig_th**2]) @ G.T + np.diag([sig_xy**2, sig_xy**2, 0.0])
    ekf.predict(sl, dth)
    np.testing.assert_allclose(ekf.x, f(x0, np.zeros(2)), atol=1e-12)
    np.testing.assert_allclose(ekf.P, F @ P0 @ F.T + Q, atol=1e-9)


def primed_ekf(window: int = 5) -> RobustEkf:
    ekf = RobustEkf(sigma_step=0.05, sigma_heading=0.03, sigma_xy=0.1, innovation_window=window)
    ekf.initialise([4.0, -1.0], heading=1.0, position_std=0.8, heading_std=0.2)
    ekf.predict(0.65, -0.1)
    return ekf


H = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def kalman(x: np.ndarray, P: np.ndarray, z: np.ndarray, R: np.ndarray):
    """The textbook linear update."""
    S = H @ P @ H.T + R
    K = P @ H.T @ np.linalg.inv(S)
    return x + K @ (z - H @ x), (np.eye(3) - K @ H) @ P


def test_rekf_is_the_kalman_filter_for_a_small_innovation() -> None:
    ekf = primed_ekf()
    x, P = ekf.x.copy(), ekf.P.copy()
    z = H @ x + np.array([0.3, -0.2])  # |v|² = 0.13 < tr(H P⁻ Hᵀ): λ = 1
    weight = ekf.update(z, r=2.0)
    x_kf, P_kf = kalman(x, P, z, 2.0 * np.eye(2))
    assert weight == 1.0
    np.testing.assert_allclose(ekf.x, x_kf, atol=1e-12)
    np.testing.assert_allclose(ekf.P, P_kf, atol=1e-12)


def test_rekf_down_weights_an_outlier_by_its_innovation_covariance() -> None:
    r = 2.0
    ekf = primed_ekf(window=3)
    x, P = ekf.x.copy(), ekf.P.copy()
    v = np.array([12.0, -9.0])
    hph = H @ P @ H.T
    # Ĉ_v = v vᵀ (one innovation so far); λ = (tr Ĉ_v − tr H P⁻ Hᵀ) / tr R
    lam = (v @ v - np.trace(hph)) / (2.0 * r)
    weight = ekf.update(H @ x + v, r=r)
    assert weight == pytest.approx(1.0 / lam)
    x_kf, P_kf = kalman(x, P, H @ x + v, lam * r * np.eye(2))
    np.testing.assert_allclose(ekf.x, x_kf, atol=1e-12)
    np.testing.assert_allclose(ekf.P, P_kf, atol=1e-12)
    # The next fix of the same source still sees the outlier in its window of M = 3.
    ekf.predict(0.6, 0.0)
    x, P = ekf.x.copy(), ekf.P.copy()
    u = np.array([0.1, 0.1])
    c_v = (np.outer(v, v) + np.outer(u, u)) / 2.0
    lam = (np.trace(c_v) - np.trace(H @ P @ H.T)) / (2.0 * r)
    assert ekf.update(H @ x + u, r=r) == pytest.approx(1.0 / lam)
    # Another source keeps its own window: a small innovation there is not down-weighted.
    ekf.predict(0.6, 0.0)
    assert ekf.update(ekf.x[:2] + np.array([0.05, 0.0]), r=r, source="wifi") == 1.0


# --- APF: closed forms ----------------------------------------------------------------------


def test_mded_is_the_euclidean_distance_of_the_whole_profile() -> None:
    points, rss = wifi_map()
    floored = np.where(np.isnan(rss), -110.0, rss)
    runs = np.stack([floored[j : j + 2] for j in range(len(points) - 1)])
    query = rss[3:5] + np.array([2.0, -1.0, 0.5, 0.0])
    expected = np.sqrt(((np.where(np.isnan(query), -110.0, query) - runs) ** 2).sum(axis=(1, 2)))
    np.testing.assert_allclose(mded_many(query, runs), expected)
    np.testing.assert_allclose(mded_many(query, list(runs)), expected)
    m = MdedWifiMatcher(scans=2).fit([(points, rss)])
    for j in range(1, len(points)):
        position, distance = m.match(rss[j - 1 : j + 1])
        assert distance == 0.0
        np.testing.assert_array_equal(position, points[j])


def test_the_adaptive_factor_follows_its_formula_through_resampling() -> None:
    rng = np.random.default_rng(3)
    sig_sl = 0.1
    pf = AdaptiveParticleFilter(
        n_particles=6, sigma_heading=0.0, sigma_step=sig_sl, sigma_xy=0.0, history_steps=2
    )
    pf.initialise([0.0, 0.0], heading=0.0, spread=0.0, rng=rng)
    np.testing.assert_array_equal(pf.adaptive_factor(), np.ones(6))
    pf.predict(1.0, 0.0, rng)
    at_step1 = pf.x.copy()
    pf.predict(1.0, 0.0, rng)  # along +x: each particle moved 2 m plus its step noise
    moved = np.linalg.norm(pf.x, axis=1)
    alpha = np.exp(-((moved - 2.0) ** 2) / (2.0 * 2 * sig_sl**2))
    np.testing.assert_allclose(pf.adaptive_factor(), alpha)
    q = np.linspace(0.5, 1.0, 6)
    pf.update_adaptive(q)
    np.testing.assert_allclose(pf.w, q * alpha / np.sum(q * alpha))
    # After resampling each particle's historical particle is its ancestor's.
    pf.resample(rng)
    pf.predict(1.0, np.pi / 2, rng)  # a left turn: the chord of the last two moves is √2 m
    moved = np.linalg.norm(pf.x - at_step1[pf.ancestors], axis=1)
    alpha = np.exp(-((moved - np.sqrt(2.0)) ** 2) / (2.0 * 2 * sig_sl**2))
    np.testing.assert_allclose(pf.adaptive_factor(), alpha)


# --- WiMag: closed forms --------------------------------------------------------------------


def test_region_matcher_only_returns_positions_in_its_region() -> None:
    tracks = reference_tracks(synthetic_track(), SPACING)
    hv, xy = tracks[0].hv, tracks[0].xy
    m = RegionMagneticMatcher(matcher="md-dtw").fit(tracks)
    query = hv[40:95]
    m.region = (xy[94], 3.0)
    position, distance = m.match(query)
    assert distance == 0.0
    np.testing.assert_array_equal(position, xy[94])
    centre = xy[140]  # elsewhere on the path: the best windows there are wrong, but inside
    m.region = (centre, 2.0)
    position, distance = m.match(query)
    assert distance > 0.0 and np.linalg.norm(position - centre) <= 2.0
    m.region = (np.array([100.0, 100.0]), 1.0)
    position, distance = m.match(query)
    assert np.isnan(position).all() and distance == np.inf


def wifi_window(t: np.ndarray, rss: np.ndarray | None) -> dict[str, np.ndarray]:
    """A 1-s window of a still phone; with ``rss`` a scan that arrived at its end."""
    w, n_aps = len(t), 4
    present = {
        "gyro": 0,
        "mag": 0,
        "rotation": 0,
        "light": 0,
        "wifi": 1,
        "gravity": 1,
        "game_rotation": 0,
    }
    up = np.tile([0.0, 0.0, 9.81], (w, 1))
    heard = np.zeros(n_aps) if rss is None else np.isfinite(rss)
    return {
        "t": t,
        "valid": np.ones(w, np.int8),
        "accel": up.copy(),
        "gyro": np.zeros((w, 3)),
        "mag": np.zeros((w, 3)),
        "mag_fresh": np.zeros(w, np.int8),
        "gravity": up,
        "wifi_rss": np.full(n_aps, -110.0) if rss is None else np.nan_to_num(rss, nan=-110.0),
        "wifi_heard": heard.astype(np.int8),
        "wifi_fresh": np.array([rss is not None], np.int8),
        "wifi_age": np.zeros(1),
        "present": np.array([present[k] for k in PRESENT_ORDER], np.int8),
    }


def test_the_coarse_region_follows_the_last_wifi_fix_by_dead_reckoning() -> None:
    points, rss = wifi_map()
    tracker = CoarseRegionTracker(
        dr=MetronomeDR(),  # type: ignore[arg-type]
        wifi=WifiSequenceMatcher(scans=1).fit([(points, rss)]),
        region_radius_m=6.0,
    )
    tracker.reset(0.0, 0.0)
    regions = []
    for k in range(5):
        t = k + np.arange(1, 51) / 50.0
        tracker.process(wifi_window(t, rss[4] if k == 2 else None))
        regions.append(tracker.region)
    assert regions[:2] == [None, None]
    # The scan at t = 3 s is fixed at its step (t = 3 s), exactly on reference point 4 …
    centre, radius = regions[2]
    np.testing.assert_allclose(centre, points[4], atol=1e-12)
    assert radius == 6.0
    # … and then moves with each 0.6 m step along +x: two steps per window.
    np.testing.assert_allclose(regions[4][0], points[4] + [2.4, 0.0], atol=1e-12)


def test_wimag_selects_magnetic_then_wifi_then_dead_reckoning() -> None:
    est = WiMag()
    step = GaitStep(1.0, 0.6, 0.0, 0.0, 0.05)
    mag, wifi = np.array([1.0, 2.0]), np.array([3.0, 4.0])
    assert est.select(StepFixes(step, mag, wifi))[:2] == ("magnetic", mag)
    assert est.select(StepFixes(step, None, wifi))[:2] == ("wifi", wifi)
    assert est.select(StepFixes(step, None, None)) == ("dr", None, 0.0)
    # The region: 2 RMS WiFi errors, √(2R) each, never under min_region_m.
    assert est._radius(8.0) == pytest.approx(8.0)
    assert est._radius(0.5) == est.min_region_m


# --- the pipelines on the bundled Chen sites ------------------------------------------------


@pytest.fixture(scope="module")
def office() -> indoorsim.Site:
    return indoorsim.load_site("chen2022_office")


@pytest.mark.parametrize("mode", ["handheld", "calling", "dangling", "pocketed"])
def test_every_carrying_mode_runs_on_the_office(mode: str, office: indoorsim.Site) -> None:
    ctx = site_context(office, device="nexus_5x")
    route = "corridor"
    train = training_walks(office, route, mode=mode, device="nexus_5x", n=1)
    rec = simulate(office, route=route, mode=mode, device="nexus_5x", seed=5)
    for name in NAMES:
        est = make(name)
        est.fit(ctx, train)
        result = run_episode(est, rec, ctx, start_info(rec, seed=5))
        assert np.isfinite(result.estimate).all() and result.step_count
        assert np.isfinite(result.heading).all()
        if isinstance(est, Apf):  # on the floor plan: no surviving particle in a wall
            pf = est.particle_filter
            assert pf is not None and office.plan.is_walkable(pf.x[pf.w > 0]).all()
        if isinstance(est, WiMag):
            assert sum(est.modes.values()) == result.step_count
        if isinstance(est, EdtwRekf):
            assert est.ekf is not None and np.all(np.linalg.eigvalsh(est.ekf.P) > 0)


def test_each_follows_an_ideal_handheld_walk(
    lab: indoorsim.Site, lab_context: SiteContext, lab_train: list[Recording]
) -> None:
    rec = simulate(lab, route="survey_loop", mode="handheld", device="ideal", seed=1)
    errors = {}
    for name in [*NAMES, "start-only"]:
        est = make(name)
        est.fit(lab_context, lab_train)
        result = run_episode(est, rec, lab_context, start_info(rec, seed=1))
        errors[name] = np.linalg.norm(result.estimate - true_positions_at(rec, result.t), axis=1)
    for name in NAMES:
        assert errors[name].mean() < 0.5 * errors["start-only"].mean(), name
