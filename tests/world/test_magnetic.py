"""Magnetic field: dipole physics, Maxwell's equations, IGRF, steel expansion."""

from __future__ import annotations

import datetime

import numpy as np
import pytest

from indoorsim.scenario import parse_scenario
from indoorsim.world.magnetic import (
    MagneticModel,
    bar_moments,
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
    # Without remanence a column's moment is its bars' induced one: χ along the vertical
    # bars, χ·(tie share)/2 + χ_t across, summed over its chain (three storeys).
    scn = parse_scenario(
        box_scenario(pillars=[{"center": [3, 3]}], magnetic={"remanent_ratio": 0.0})
    )
    clean = MagneticModel.from_scenario(scn, FloorPlan(scn))
    mag = scn.magnetic
    h = clean.earth_field_uT * 1e-6 / (4e-7 * np.pi)
    ties, chi, chi_t = mag.tie_share, mag.susceptibility, mag.transverse_susceptibility
    per_m3 = np.array(
        [
            (ties / 2 * chi + (1 - ties / 2) * chi_t) * h[0],
            (ties / 2 * chi + (1 - ties / 2) * chi_t) * h[1],
            ((1 - ties) * chi + ties * chi_t) * h[2],
        ]
    )
    np.testing.assert_allclose(clean.moments.sum(axis=0), 3 * 0.015 * per_m3, rtol=1e-12)
    # Isotropic steel (χ_t = χ) takes χ·V·B/μ0 along the field.
    iso = parse_scenario(
        box_scenario(
            pillars=[{"center": [3, 3]}],
            magnetic={"remanent_ratio": 0.0, "transverse_susceptibility": 30.0},
        )
    )
    model = MagneticModel.from_scenario(iso, FloorPlan(iso))
    np.testing.assert_allclose(
        model.moments.sum(axis=0), 3 * induced_moment(0.015, 30.0, model.earth_field_uT)
    )


def test_same_seed_same_moments_other_seed_other_moments():
    a, b, c = _steel_site(3), _steel_site(3), _steel_site(4)
    assert a.moments.tobytes() == b.moments.tobytes()
    assert not np.allclose(a.moments, c.moments)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_anomaly_near_a_column_is_tens_of_microtesla_and_a_few_at_two_metres(seed):
    # REALISM §2.3: 5–30 µT within 0.5 m of a steel column, a few µT at 2 m; with the
    # generator's steel (0.05 m³ per storey, χ 100 along the bars, remanent ratio 2).
    scn = parse_scenario(
        box_scenario(
            seed=seed,
            pillars=[{"center": [5, 3], "steel_volume_m3": 0.05}],
            magnetic={"susceptibility": 100.0, "remanent_ratio": 2.0},
        )
    )
    model = MagneticModel.from_scenario(scn, FloorPlan(scn))
    d = np.array([0.5, 1.0, 2.0])
    pts = np.column_stack([5 + d, np.full(3, 3.0), np.full(3, 1.2)])
    mag = np.linalg.norm(model.anomaly(pts), axis=1)
    assert mag[0] > mag[1] > mag[2]
    assert 5 < mag[0] < 50 and 0.5 < mag[2] < 8


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


# ---------------------------------------------------------------- bars and elements

_B = np.array([20.0, 25.0, -38.0])  # µT
_H = _B * 1e-6 / (4e-7 * np.pi)  # A/m
_X, _Y, _Z = np.eye(3)


def test_a_bar_is_magnetised_along_its_axis_far_more_than_across():
    m = bar_moments(
        np.array([0.01]), np.array([0]), [(_X, 1.0)], _B, 100.0, 2.0, 0.0, np.random.default_rng(0)
    )[0]
    np.testing.assert_allclose(m, 0.01 * np.array([100 * _H[0], 2 * _H[1], 2 * _H[2]]))


def test_an_elements_dipoles_share_one_remanence_along_its_bars():
    rng = np.random.default_rng(5)
    n_elements, per = 4000, 3
    element = np.repeat(np.arange(n_elements), per)
    vol = np.full(len(element), 0.002)
    mesh = [(_X, 0.5), (_Y, 0.5)]
    induced = bar_moments(vol, element, mesh, _B, 100.0, 2.0, 0.0, rng)
    moments = bar_moments(vol, element, mesh, _B, 100.0, 2.0, 1.5, rng)
    remanent = (moments - induced).reshape(n_elements, per, 3)
    np.testing.assert_allclose(remanent, remanent[:, :1, :].repeat(per, axis=1))
    np.testing.assert_allclose(remanent[..., 2], 0.0, atol=1e-15)  # a mesh's bars lie flat
    # RMS of an element's remanent moment: the ratio times χ·V·|H| of the element.
    rms = np.sqrt(np.mean(np.sum(remanent.sum(axis=1) ** 2, axis=1)))
    assert rms == pytest.approx(1.5 * 100.0 * per * 0.002 * np.linalg.norm(_H), rel=0.05)


def _patch(spacing: float, side: float = 8.0, z: float = -0.15) -> tuple[np.ndarray, np.ndarray]:
    """A uniformly magnetised square patch of slab as a grid of dipoles: 10 A·m² per m²."""
    xs = np.arange(-side / 2 + spacing / 2, side / 2, spacing)
    gx, gy = np.meshgrid(xs, xs, indexing="ij")
    pos = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, z)])
    per_area = np.array([8.0, 6.0, 0.0])
    return pos, np.tile(per_area * spacing**2, (len(pos), 1))


def _walk_line() -> np.ndarray:
    x = np.linspace(-12.0, 12.0, 241)
    return np.column_stack([x, np.full_like(x, 1.0), np.full_like(x, 1.2)])


def test_a_slab_patch_on_a_one_metre_grid_matches_magpylibs_uniform_plate():
    # An independent closed form (magpylib's uniformly magnetised cuboid) for the patch
    # the model stands for with a 1 m dipole grid, seen at walking height.
    magpy = pytest.importorskip("magpylib")
    thickness = 0.01
    polarization = 4e-7 * np.pi * np.array([8.0, 6.0, 0.0]) / thickness  # J = μ0·M, T
    plate = magpy.magnet.Cuboid(
        dimension=(8.0, 8.0, thickness), polarization=polarization, position=(0, 0, -0.15)
    )
    line = _walk_line()
    exact = plate.getB(line) * 1e6  # µT
    rms = np.sqrt(np.mean(np.sum(exact**2, axis=1)))
    for spacing, bound in ((1.0, 0.05), (0.5, 0.01)):
        err = dipole_field(line, *_patch(spacing)) - exact
        assert np.sqrt(np.mean(np.sum(err**2, axis=1))) < bound * rms, spacing
    # At 2 m the grid's own ripple is as large as the patch's field: why slabs use 1 m.
    coarse = dipole_field(line, *_patch(2.0)) - exact
    assert np.sqrt(np.mean(np.sum(coarse**2, axis=1))) > 0.3 * rms


def test_a_mesh_patch_is_the_brute_force_sum_of_its_bars():
    # 8 m × 8 m of φ12 bars 0.15 m apart both ways, each a chain of dipoles 5 cm apart
    # magnetised along the bar, against the model's 1 m grid of the same patch.
    chi, chi_t, ratio = 100.0, 2.0, 1.0
    rng = np.random.default_rng(2)
    g = rng.standard_normal(2)  # the patch's remanence, one draw per bar direction
    area = np.pi * 0.006**2
    offsets = np.arange(-4.0 + 0.075, 4.0, 0.15)
    along = np.arange(-4.0 + 0.025, 4.0, 0.05)
    pos, mom = [], []
    for u, k in ((_X, 0), (_Y, 1)):
        vol = area * 0.05
        induced = vol * (chi * _H[k] * u + chi_t * (_H - _H[k] * u))
        # Each direction's share of the element's remanence, per m³ of its own bars.
        remanent = vol * ratio * chi * np.linalg.norm(_H) * g[k] / np.sqrt(0.5**2 + 0.5**2) * u
        for c in offsets:
            pts = np.column_stack([along, np.full_like(along, c)])
            pts = pts if k == 0 else pts[:, ::-1]
            pos.append(np.column_stack([pts, np.full(len(pts), -0.15)]))
            mom.append(np.tile(induced + remanent, (len(pts), 1)))
    bars_pos, bars_mom = np.concatenate(pos), np.concatenate(mom)
    line = _walk_line()
    exact = dipole_field(line, bars_pos, bars_mom)
    # The model: one element, both bar directions holding half the steel.
    grid = _patch(1.0)[0]
    volume = bars_mom.shape[0] * area * 0.05 / len(grid)
    draws = iter(g)

    class _Fixed:
        def standard_normal(self, shape):
            return np.array([[next(draws) for _ in range(shape[1])]])

    model = bar_moments(
        np.full(len(grid), volume),
        np.zeros(len(grid), dtype=int),
        [(_X, 0.5), (_Y, 0.5)],
        _B,
        chi,
        chi_t,
        ratio,
        _Fixed(),
    )
    err = dipole_field(line, grid, model) - exact
    rms = np.sqrt(np.mean(np.sum(exact**2, axis=1)))
    assert np.sqrt(np.mean(np.sum(err**2, axis=1))) < 0.05 * rms


def test_slab_patches_and_pillar_storeys_are_elements():
    scn = parse_scenario(
        box_scenario(
            pillars=[{"center": [3, 3]}],
            magnetic={
                "remanent_ratio": 1.0,
                "rebar": [{"z": -0.15, "spacing": 1.0, "bars": "mesh", "element_m": 5.0}],
            },
        )
    )
    model = MagneticModel.from_scenario(scn, FloorPlan(scn))
    rebar = model.moments[model.sources == "rebar"]
    where = model.positions[model.sources == "rebar"]
    patch = (where[:, 0] // 5).astype(int) * 10 + (where[:, 1] // 5).astype(int)
    for p in np.unique(patch):
        np.testing.assert_allclose(
            rebar[patch == p], rebar[patch == p][:1].repeat((patch == p).sum(), 0)
        )
    assert len(np.unique(rebar.round(12), axis=0)) == len(np.unique(patch))
    pillar = model.moments[model.sources == "pillar"].reshape(3, -1, 3)  # three storeys
    assert np.ptp(pillar, axis=1).max() < 1e-12  # one moment per storey
    assert np.ptp(pillar[:, 0], axis=0).max() > 0  # and storeys differ


def test_a_spliced_steel_column_is_one_length_below_its_splice_and_one_above():
    scn = parse_scenario(
        box_scenario(
            pillars=[{"center": [3, 3], "splice_z": 0.6}, {"center": [7, 3]}],
            magnetic={"remanent_ratio": 1.0},
        )
    )
    model = MagneticModel.from_scenario(scn, FloorPlan(scn))
    pos = model.positions[model.sources == "pillar"]
    mom = model.moments[model.sources == "pillar"]
    spliced = pos[:, 0] == 3
    for part in (pos[:, 2] < 0.6, pos[:, 2] >= 0.6):
        assert np.ptp(mom[spliced & part], axis=0).max() < 1e-12  # one length, one moment
    assert np.ptp(mom[spliced], axis=0).max() > 0  # the two lengths differ
    # The concrete column beside it keeps one element per storey.
    assert len(np.unique(mom[~spliced].round(12), axis=0)) == 3
