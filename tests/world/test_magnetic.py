"""Magnetic field: dipole physics, Maxwell's equations, IGRF, steel expansion."""

from __future__ import annotations

import datetime

import numpy as np
import pytest

from indoorsim.scenario import parse_scenario
from indoorsim.world.magnetic import (
    MagneticModel,
    dipole_field,
    earth_field_enu,
    enu_to_building,
    induced_moment,
)
from indoorsim.world.plan import FloorPlan
from tests.conftest import box_scenario


def _one(points, moment=(0.0, 0.0, 10.0)):
    return dipole_field(np.asarray(points, float), np.zeros((1, 3)), np.array([moment]))


def test_dipole_axis_is_twice_equator_and_falls_as_inverse_cube():
    r = np.array([0.5, 1.0, 2.0, 4.0])
    axial = _one(np.column_stack([0 * r, 0 * r, r]))[:, 2]
    equatorial = _one(np.column_stack([r, 0 * r, 0 * r]))[:, 2]
    np.testing.assert_allclose(axial, -2 * equatorial, rtol=1e-12)
    np.testing.assert_allclose(axial * r**3, axial[0] * r[0] ** 3, rtol=1e-12)
    # Closed form on the axis: μ0/4π · 2m/r³, in µT.
    np.testing.assert_allclose(axial, 1e-7 * 2 * 10.0 / r**3 * 1e6, rtol=1e-12)


def test_dipole_field_matches_textbook_formula_at_random_points():
    rng = np.random.default_rng(1)
    q, m, p = rng.uniform(-5, 5, (7, 3)), rng.normal(0, 30, (7, 3)), rng.uniform(-6, 6, (50, 3))
    r = p[:, None, :] - q[None]
    d = np.linalg.norm(r, axis=-1)
    rhat = r / d[..., None]
    ref = (3 * (rhat * m).sum(-1)[..., None] * rhat - m) / d[..., None] ** 3
    np.testing.assert_allclose(dipole_field(p, q, m), 0.1 * ref.sum(1), rtol=1e-9, atol=1e-12)


def test_field_stays_finite_at_a_dipole():
    b = _one([[0.0, 0.0, 0.0], [0.0, 0.0, 1e-9]])
    assert np.isfinite(b).all()


def _steel_site(seed: int = 3) -> MagneticModel:
    scn = parse_scenario(
        box_scenario(
            seed=seed,
            pillars=[{"center": [3, 3]}, {"center": [7, 3], "steel_volume_m3": 0.03}],
            magnetic={
                "dipoles": [{"position": [5, 1, 0.5], "moment": [20, -10, 5]}],
                "rebar": [{"z": -0.15, "spacing": 1.0}],
            },
        )
    )
    return MagneticModel.from_scenario(scn, FloorPlan(scn))


def test_total_field_is_divergence_and_curl_free_away_from_sources():
    model = _steel_site()
    rng = np.random.default_rng(0)
    pts = np.column_stack(
        [rng.uniform(1, 9, 40), rng.uniform(0.7, 2.2, 40), rng.uniform(0.8, 1.6, 40)]
    )
    h = 1e-4
    jac = np.empty((len(pts), 3, 3))  # jac[:, i, j] = dB_i / dx_j
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        jac[:, :, j] = (model.field(pts + e) - model.field(pts - e)) / (2 * h)
    scale = np.abs(jac).max(axis=(1, 2))
    div = np.trace(jac, axis1=1, axis2=2)
    curl = np.stack(
        [jac[:, 2, 1] - jac[:, 1, 2], jac[:, 0, 2] - jac[:, 2, 0], jac[:, 1, 0] - jac[:, 0, 1]],
        axis=1,
    )
    assert np.all(np.abs(div) < 1e-6 * scale + 1e-9)
    assert np.all(np.abs(curl) < 1e-6 * scale[:, None] + 1e-9)


# IGRF-14 values at h = 0 from REALISM.md §2.1 (nT): north, east, down.
@pytest.mark.parametrize(
    ("lat", "lon", "north", "east", "down"),
    [
        (32.63, 117.00, 32448, -3380, 39001),  # Huainan, 2025.0
        (39.90, 116.40, 27784, -3655, 47193),  # Beijing, 2025.0
        (31.23, 121.47, 33089, -3766, 36149),  # Shanghai, 2025.0
    ],
)
def test_earth_field_agrees_with_published_igrf(lat, lon, north, east, down):
    e, n, u = earth_field_enu(lat, lon, 0.0, datetime.date(2025, 1, 1))
    np.testing.assert_allclose([n * 1000, e * 1000, -u * 1000], [north, east, down], atol=2.0)


def test_building_rotation_maps_east_onto_plus_y_when_rotated_90_degrees():
    enu = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(enu_to_building(enu, 0.0), enu)
    np.testing.assert_allclose(enu_to_building(enu, 90.0), [-2.0, 1.0, 3.0], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(enu_to_building(enu, 37.0)), np.linalg.norm(enu))


def test_explicit_earth_field_overrides_igrf():
    scn = parse_scenario(
        box_scenario(site={**box_scenario()["site"], "earth_field_uT": [1, 2, -40]})
    )
    model = MagneticModel.from_scenario(scn, FloorPlan(scn))
    np.testing.assert_allclose(model.field([[5, 3, 1.2]]), [[1, 2, -40]])


def test_induced_moment_follows_earth_field_and_chi_v_over_mu0():
    b = np.array([0.0, 30.0, -40.0])  # 50 µT
    m = induced_moment(0.01, 30.0, b)
    np.testing.assert_allclose(m / np.linalg.norm(m), b / 50.0)
    np.testing.assert_allclose(np.linalg.norm(m), 30 * 0.01 * 50e-6 / (4e-7 * np.pi))


def test_steel_expansion_counts_and_remanence():
    model = _steel_site()
    n_pillar = (model.sources == "pillar").sum()
    assert n_pillar == 2 * 3 * 6  # two pillars, three storeys of 3 m at 0.5 m spacing
    assert (model.sources == "dipole").sum() == 1
    assert (model.sources == "rebar").sum() == 60  # 10 × 6 cells of 1 m
    # Without remanence every steel moment is parallel to the Earth's field.
    scn = parse_scenario(
        box_scenario(pillars=[{"center": [3, 3]}], magnetic={"remanent_ratio": 0.0})
    )
    clean = MagneticModel.from_scenario(scn, FloorPlan(scn))
    unit = clean.moments / np.linalg.norm(clean.moments, axis=1, keepdims=True)
    np.testing.assert_allclose(
        unit, np.tile(clean.earth_field_uT / np.linalg.norm(clean.earth_field_uT), (len(unit), 1))
    )
    # A pillar's total induced moment is χ·V·B/μ0 spread over its chain (three storeys).
    total = clean.moments.sum(axis=0)
    np.testing.assert_allclose(
        total, 3 * induced_moment(0.015, 30.0, clean.earth_field_uT), rtol=1e-12
    )


def test_same_seed_same_moments_other_seed_other_moments():
    a, b, c = _steel_site(3), _steel_site(3), _steel_site(4)
    assert a.moments.tobytes() == b.moments.tobytes()
    assert not np.allclose(a.moments, c.moments)


def test_anomaly_near_pillar_is_tens_of_microtesla_and_decays():
    model = _steel_site()
    d = np.array([0.45, 1.0, 2.0])
    pts = np.column_stack([3 + d, np.full(3, 3.0), np.full(3, 1.2)])
    mag = np.linalg.norm(model.anomaly(pts), axis=1)
    assert mag[0] > mag[1] > mag[2]
    assert 3 < mag[0] < 200


# ---------------------------------------------------------------- along a path
# MagneticModel.field_along approximates the smooth far part of the sum; its
# error must stay far below a phone magnetometer's noise (0.2–1 µT, REALISM §1.5).


def _bands():
    from indoorsim.world import magnetic as mg

    return [
        (mg._ALWAYS, mg.PATH_BANDS[0]),
        (mg.PATH_BANDS[0], mg.PATH_BANDS[1]),
        (mg.PATH_BANDS[1], mg._NEVER),
    ]


@pytest.fixture(scope="module")
def office():
    import indoorsim
    from indoorsim.scenario.generate import generate

    return indoorsim.load_site(generate("office", seed=5))


def test_path_bands_add_up_to_the_exact_sum(office):
    model = office.magnetic
    b = office.plan.bounds
    rng = np.random.default_rng(2)
    pts = np.column_stack(
        [rng.uniform(b[0], b[2], 300), rng.uniform(b[1], b[3], 300), rng.uniform(0.2, 2.0, 300)]
    )
    total = sum(model._band(pts, inner, outer) for inner, outer in _bands())
    np.testing.assert_allclose(total, model.anomaly(pts), rtol=1e-9, atol=1e-9)


def test_band_gradient_is_the_derivative_of_the_band(office):
    model = office.magnetic
    rng = np.random.default_rng(3)
    b = office.plan.bounds
    pts = np.column_stack(
        [rng.uniform(b[0], b[2], 50), rng.uniform(b[1], b[3], 50), rng.uniform(0.5, 1.5, 50)]
    )
    for inner, outer in _bands()[1:]:
        jac = model._band_gradient(pts, inner, outer)
        h = 1e-5
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            fd = (model._band(pts + e, inner, outer) - model._band(pts - e, inner, outer)) / (2 * h)
            np.testing.assert_allclose(jac[:, :, k], fd, atol=1e-7 * np.abs(jac).max())


@pytest.mark.parametrize("mode", ["handheld", "calling", "dangling", "pocketed"])
def test_path_field_is_within_its_bound_of_the_exact_sum_in_every_mode(office, mode):
    from indoorsim.phone.kinematics import IdealImu
    from indoorsim.simulate import PATH_FIELD_ERROR_UT, run_streams
    from indoorsim.walker.carry import carry
    from indoorsim.walker.gait import WalkerParams, walk
    from indoorsim.walker.route import plan_route

    # A brisk, tall walker (fast hands and feet) around the office's corridor loop.
    route = plan_route(office.plan, office.scenario.routes["round_trip"])
    rngs = run_streams(7)
    body = walk(office.plan, route, WalkerParams(speed_mps=1.5, height_m=1.9), rngs["walker"])
    body = body.window(0, int(np.searchsorted(body.t, 75.0)))
    phone = carry(body, mode, rngs["carry"])
    imu = IdealImu(phone.t, phone.pos, phone.quat)
    t = np.arange(phone.t[0], phone.t[-1], 0.01)  # a 100 Hz magnetometer
    fast = office.magnetic.field_along(t, imu.position, phone.t, phone.pos)
    exact = office.magnetic.field(imu.position(t))
    assert t[-1] > 60.0  # a minute of walking, turns included
    assert np.linalg.norm(fast - exact, axis=1).max() < PATH_FIELD_ERROR_UT


def test_path_field_of_a_fast_swing_past_a_strong_source():
    # A 100 A·m² source (a lift car) 0.4 m from a hand swinging ±0.3 m at 1 Hz
    # while the walker passes at 1.5 m/s: the field changes by tens of µT.
    model = MagneticModel(
        earth_field_uT=np.array([0.0, 30.0, -40.0]),
        positions=np.array([[5.0, 0.4, 1.0], *[[x, 3.0, -0.15] for x in range(12)]]),
        moments=np.array([[60.0, -40.0, 60.0], *[[3.0, 1.0, 4.0]] * 12]),
        sources=np.array(["dipole"] + ["rebar"] * 12),
    )
    t_path = np.arange(0.0, 8.0, 0.005)
    pos = np.column_stack(
        [
            1.5 * t_path + 0.3 * np.sin(2 * np.pi * t_path),
            np.zeros_like(t_path),
            1.0 + 0.05 * np.cos(4 * np.pi * t_path),
        ]
    )

    def position(t):
        return np.column_stack([np.interp(t, t_path, pos[:, k]) for k in range(3)])

    t = np.arange(0.0, t_path[-1], 0.01)
    fast = model.field_along(t, position, t_path, pos)
    exact = model.field(position(t))
    assert np.linalg.norm(exact - model.earth_field_uT, axis=1).max() > 20.0
    assert np.linalg.norm(fast - exact, axis=1).max() < 0.01


def test_path_field_of_a_point_at_rest_is_the_exact_field(office):
    t_path = np.arange(0.0, 30.0, 0.005)
    pos = np.tile([12.0, 5.0, 1.1], (len(t_path), 1))

    def position(t):
        return np.tile([12.0, 5.0, 1.1], (len(t), 1))

    t = np.arange(0.0, 29.0, 0.02)
    fast = office.magnetic.field_along(t, position, t_path, pos)
    np.testing.assert_allclose(fast, office.magnetic.field(position(t)), atol=1e-9)
