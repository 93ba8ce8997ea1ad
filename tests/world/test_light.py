"""Light model: photometric laws, occlusion, the integrating-sphere ambient term, daylight."""

from __future__ import annotations

import math

import numpy as np
import pytest

from indoorsim.scenario import parse_scenario
from indoorsim.world.light import LightModel, PointSources, direct_illuminance
from indoorsim.world.materials import MATERIALS
from indoorsim.world.plan import FloorPlan
from indoorsim.world.sky import glazing_factor


def _box(
    width: float, depth: float, height: float = 3.0, walls: list[dict] | None = None, **keys: object
) -> dict:
    """A closed concrete room [0, width] × [0, depth], plus ``walls``; other keys as given."""
    corners = [(0, 0), (width, 0), (width, depth), (0, depth)]
    outer = [
        {"from": list(a), "to": list(b), "thickness": 0.2}
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True)
    ]
    return {
        "name": "box",
        "site": {
            "latitude": 32.6,
            "longitude": 117.0,
            "date": "2025-01-01",
            "ceiling_height": height,
        },
        "walls": outer + (walls or []),
        **keys,
    }


def _model(data: dict) -> LightModel:
    scenario = parse_scenario(data)
    return LightModel(scenario, FloorPlan(scenario))


def _lamp(position, intensity_cd=1000.0, exponent=1.0, axis=(0.0, 0.0, -1.0)) -> dict:
    return {
        "position": list(position),
        "intensity_cd": intensity_cd,
        "exponent": exponent,
        "axis": list(axis),
    }


NO_AMBIENT = {"ambient": False}


def test_inverse_square_law_on_the_axis():
    model = _model(_box(20, 20, 10, luminaires=[_lamp((10, 10, 9))], light=NO_AMBIENT))
    d = np.array([0.5, 1.0, 2.0, 4.0, 8.0])
    e = model.illuminance(np.column_stack([10 + 0 * d, 10 + 0 * d, 9 - d]), [0, 0, 1])
    np.testing.assert_allclose(e * d**2, 1000.0, rtol=1e-12)
    np.testing.assert_allclose(e[1:] / e[:-1], 0.25, rtol=1e-12)


def test_cosine_law_on_the_receiver_normal():
    model = _model(_box(20, 20, 10, luminaires=[_lamp((10, 10, 9))], light=NO_AMBIENT))
    alpha = np.radians([0, 20, 45, 70, 89, 90, 120, 180])
    normals = np.column_stack([0 * alpha, np.sin(alpha), np.cos(alpha)])
    e = model.illuminance(np.tile([10, 10, 7], (len(alpha), 1)), normals)
    expected = e[0] * np.maximum(np.cos(alpha), 0)
    np.testing.assert_allclose(e, expected, rtol=1e-12, atol=1e-12)
    assert np.all(e[alpha > np.pi / 2] == 0)


@pytest.mark.parametrize("exponent", [0.0, 1.0, 2.75, 10.0])
def test_emission_follows_cos_power_about_a_tilted_axis(exponent):
    axis = np.array([0.4, -0.2, -1.0]) / np.linalg.norm([0.4, -0.2, -1.0])
    lamp = np.array([10.0, 10.0, 5.0])
    model = _model(
        _box(20, 20, 10, luminaires=[_lamp(lamp, 500.0, exponent, axis)], light=NO_AMBIENT)
    )
    side = np.cross(axis, [0, 0, 1])
    side /= np.linalg.norm(side)
    theta = np.radians([0, 15, 40, 65, 85, 95, 130, 180])
    r = 2.0
    directions = np.outer(np.cos(theta), axis) + np.outer(np.sin(theta), side)
    # Each receiver faces the lamp, so cos ψ = 1 and E·r² is the emitted intensity.
    e = model.illuminance(lamp + r * directions, -directions)
    front = np.cos(theta) > 0
    np.testing.assert_allclose(e[front] * r**2, 500.0 * np.cos(theta[front]) ** exponent, rtol=1e-9)
    assert np.all(e[~front] == 0)


def _two_rooms(material: str, doors: list | None = None) -> dict:
    partition = {"from": [10, 0], "to": [10, 10], "thickness": 0.15, "material": material}
    return _box(
        20,
        10,
        walls=[partition],
        doors=doors or [],
        luminaires=[_lamp((5, 5, 3))],
        light=NO_AMBIENT,
    )


RECEIVERS = np.array([[15.0, 5.0, 1.0], [12.0, 3.0, 0.5], [4.0, 6.0, 1.0]])  # last: lamp's room


@pytest.mark.parametrize("material", sorted(MATERIALS))
def test_partition_passes_its_material_transmittance(material):
    e_free = _model(_box(20, 10, luminaires=[_lamp((5, 5, 3))], light=NO_AMBIENT)).illuminance(
        RECEIVERS, [0, 0, 1]
    )
    e = _model(_two_rooms(material)).illuminance(RECEIVERS, [0, 0, 1])
    tau = MATERIALS[material].light_transmittance
    np.testing.assert_allclose(e[:2], tau * e_free[:2], rtol=1e-12)
    assert e[2] == e_free[2] > 0


def test_concrete_blocks_direct_light_but_a_door_on_the_path_lets_it_through():
    free = _model(_box(20, 10, luminaires=[_lamp((5, 5, 3))], light=NO_AMBIENT))
    closed = _model(_two_rooms("concrete"))
    door = _model(_two_rooms("concrete", doors=[{"position": [10, 5], "width": 1.0}]))
    p = [[15.0, 5.0, 1.0]]
    assert closed.illuminance(p, [0, 0, 1])[0] == 0
    assert door.illuminance(p, [0, 0, 1])[0] == free.illuminance(p, [0, 0, 1])[0] > 0


def test_pillar_casts_a_shadow():
    data = _box(20, 10, luminaires=[_lamp((5, 5, 3))], light=NO_AMBIENT)
    data["pillars"] = [{"center": [8, 5], "size": [0.6, 0.6]}]
    e = _model(data).illuminance([[11.0, 5.0, 1.0], [11.0, 8.0, 1.0]], [0, 0, 1])
    assert e[0] == 0 < e[1]


def test_illuminance_is_non_negative_and_finite_everywhere():
    rng = np.random.default_rng(0)
    lamps = [
        _lamp((x, y, 3.0), 800.0, n, rng.normal(size=3))
        for x, y, n in zip(
            rng.uniform(1, 19, 12), rng.uniform(1, 9, 12), rng.uniform(0, 5, 12), strict=True
        )
    ]
    data = _two_rooms("glass") | {
        "luminaires": lamps,
        "windows": [{"from": [2, 0], "to": [6, 0]}],
        "light": {"ambient": True, "daylight": {"enabled": True}},
    }
    model = _model(data)
    points = np.vstack(
        [rng.uniform([-2, -2, -1], [22, 12, 4], (2000, 3)), [lamp["position"] for lamp in lamps]]
    )
    e = model.illuminance(points, rng.normal(size=points.shape))
    assert np.all(np.isfinite(e)) and np.all(e >= 0)
    assert np.count_nonzero(e) > len(e) // 2


def test_free_space_kernel_equals_hand_written_sum():
    rng = np.random.default_rng(1)
    src = PointSources.from_arrays(
        rng.uniform(0, 5, (4, 3)),
        rng.normal(size=(4, 3)),
        rng.uniform(100, 900, 4),
        [0.0, 1.0, 2.0, 3.5],
    )
    p = rng.uniform(0, 5, (300, 3))
    n = rng.normal(size=(300, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = src.position[None] - p[:, None]  # (N, S, 3) receiver → source
    d = np.linalg.norm(v, axis=-1)
    cos_theta = -(v * src.axis).sum(-1) / d
    cos_psi = (v * n[:, None]).sum(-1) / d
    ref = np.where(
        (cos_theta > 0) & (cos_psi > 0),
        src.intensity_cd * np.abs(cos_theta) ** src.exponent * cos_psi / d**2,
        0.0,
    )
    np.testing.assert_allclose(direct_illuminance(src, p, n), ref.sum(1), rtol=1e-12)


# ------------------------------------------------------------------- ambient


def _ambient(model_on: LightModel, model_off: LightModel, points, normal) -> np.ndarray:
    return model_on.illuminance(points, normal) - model_off.illuminance(points, normal)


def test_ambient_matches_the_integrating_sphere_formula_in_a_box():
    rho = {"ceiling": 0.85, "walls": 0.6, "floor": 0.25}
    lamps = [_lamp((2.5, 3.0, 3.0), 800.0, 1.0), _lamp((7.5, 3.0, 3.0), 1500.0, 2.75)]
    on = _model(_box(10, 6, 3.0, luminaires=lamps, light={"reflectance": rho}))
    off = _model(_box(10, 6, 3.0, luminaires=lamps, light=NO_AMBIENT))

    flux = 2 * math.pi * (800.0 / 2 + 1500.0 / 3.75)
    area, walls = 60.0, 32.0 * 3.0
    surface = 2 * area + walls
    rho_mean = (rho["ceiling"] * area + rho["walls"] * walls + rho["floor"] * area) / surface
    e_up = flux * rho_mean / (surface * (1 - rho_mean))
    e_down = flux * rho["floor"] / (surface * (1 - rho_mean))

    p = [[1.0, 1.0, 1.2], [5.0, 3.0, 0.1], [9.0, 5.5, 2.0]]
    np.testing.assert_allclose(_ambient(on, off, p, [0, 0, 1]), e_up, rtol=1e-12)
    np.testing.assert_allclose(_ambient(on, off, p, [0, 0, -1]), e_down, rtol=1e-12)
    np.testing.assert_allclose(_ambient(on, off, p, [1, 0, 0]), (e_up + e_down) / 2, rtol=1e-12)
    tilt = np.radians(30)
    np.testing.assert_allclose(
        _ambient(on, off, p, [0, math.sin(tilt), math.cos(tilt)]),
        e_up * (1 + math.cos(tilt)) / 2 + e_down * (1 - math.cos(tilt)) / 2,
        rtol=1e-12,
    )
    assert _ambient(on, off, [[-3.0, 3.0, 1.0], [12.0, 3.0, 1.0]], [0, 0, 1]).tolist() == [0, 0]


def test_ambient_reproduces_the_realism_corridor_example():
    # REALISM §3.4: corridor 2 × 20 × 2.8 m, 5 × 2000 lm, ρ̄ = 0.48 gives E_ind ≈ 45 lx.
    i0 = 2000.0 * 2 / (2 * math.pi)  # Lambertian: Φ = π·I0
    lamps = [_lamp((2.0 + 4.0 * k, 1.0, 2.8), i0) for k in range(5)]
    rho = {"ceiling": 0.48, "walls": 0.48, "floor": 0.48}
    on = _model(_box(20, 2, 2.8, luminaires=lamps, light={"reflectance": rho}))
    off = _model(_box(20, 2, 2.8, luminaires=lamps, light=NO_AMBIENT))
    e = _ambient(on, off, [[10.0, 1.0, 1.2]], [0, 0, 1])[0]
    assert e == pytest.approx(45.4, abs=0.1)


def test_ambient_stays_in_the_lit_room():
    partition = {"from": [10, 0], "to": [10, 10], "thickness": 0.15}
    data = _box(20, 10, walls=[partition], luminaires=[_lamp((5, 5, 3))])
    on, off = _model(data), _model(data | {"light": NO_AMBIENT})
    amb = _ambient(on, off, [[3.0, 3.0, 1.0], [15.0, 5.0, 1.0]], [0, 0, 1])
    assert amb[0] > 0 and amb[1] == 0
    assert on.illuminance([[15.0, 5.0, 1.0]], [0, 0, 1])[0] == 0


def test_ambient_leaks_through_an_open_door_by_the_aperture_flux():
    partition = {"from": [10, 0], "to": [10, 10], "thickness": 0.15}
    door = {"position": [10, 2], "width": 1.0, "height": 2.0}
    rho = {"ceiling": 0.5, "walls": 0.5, "floor": 0.5}
    lit = _box(20, 10, walls=[partition], doors=[door], luminaires=[_lamp((5, 5, 3), 2000.0)])
    lit["light"] = {"reflectance": rho}
    on, off = _model(lit), _model(lit | {"light": NO_AMBIENT})
    # Room surfaces: 2·100 + 40·3 = 320 m² each; ρ̄ = 0.5; lamp flux Φ = π·I0.
    e_tot_lit = math.pi * 2000.0 / (320 * 0.5)
    leaked_total = e_tot_lit * 2.0 / (320 * 0.5)  # door area 2 m²
    dark = _ambient(on, off, [[15.0, 8.0, 1.0]], [0, 0, 1])[0]
    assert dark == pytest.approx(0.5 * leaked_total, rel=1e-9)
    assert 0 < dark < _ambient(on, off, [[3.0, 8.0, 1.0]], [0, 0, 1])[0]


# ------------------------------------------------------------------- daylight

WINDOW = {"from": [3.5, 0.0], "to": [6.5, 0.0], "sill": 0.9, "head": 2.1}


def test_an_unlit_luminaire_gives_no_light_direct_or_reflected():
    lamps = [_lamp((3, 3, 2.9)), _lamp((7, 5, 2.9), intensity_cd=800.0)]
    off = {**lamps[1], "lit": False}
    with_off = _model(_box(10, 8, luminaires=[lamps[0], off]))
    without = _model(_box(10, 8, luminaires=[lamps[0]]))
    grid = np.array([(x, y, 1.2) for x in (1.0, 5.0, 7.0) for y in (2.0, 5.0)])
    np.testing.assert_array_equal(
        with_off.illuminance(grid, [0, 0, 1]), without.illuminance(grid, [0, 0, 1])
    )
    both = _model(_box(10, 8, luminaires=lamps)).illuminance(grid, [0, 0, 1])
    assert (both > without.illuminance(grid, [0, 0, 1])).all()


def test_daylight_is_off_by_default():
    model = _model(_box(10, 6, windows=[WINDOW]))
    assert len(model.sources) == model.n_luminaires == 0
    assert np.all(model.illuminance([[5.0, 1.0, 1.5], [5.0, 3.0, 1.0]], [0, -1, 0]) == 0)


def _uniform_daylight(exterior_lux: float, transmittance: float) -> dict:
    return {
        "enabled": True,
        "sky": "uniform",
        "exterior_vertical_lux": exterior_lux,
        "transmittance": transmittance,
    }


@pytest.mark.parametrize("distance", [0.5, 1.0, 3.0])
def test_daylight_near_a_window_matches_the_area_source_integral(distance):
    """A uniform sky and ground of luminance E_v/π behind the pane: the patch sum
    against a fine quadrature of τ·F(θ)·L·cos θ·cos ψ / r² over the window."""
    daylight = _uniform_daylight(8000.0, 0.6)
    model = _model(_box(10, 6, windows=[WINDOW], light={"ambient": False, "daylight": daylight}))
    plane = 0.1 + 0.01  # patches sit just inside the wall surface (half of 0.2 m + inset)
    receiver = np.array([5.0, plane + distance, 1.5])
    e = model.illuminance([receiver], [0, -1, 0])[0]
    # The pane: x 3.5..6.5, z 0.9..2.1 in the plane y = ``plane``; the receiver faces it.
    k = 600
    x = 3.5 + (np.arange(k) + 0.5) * 3.0 / k
    z = 0.9 + (np.arange(k // 2) + 0.5) * 1.2 / (k // 2)
    gx, gz = np.meshgrid(x, z)
    d = np.stack([gx - receiver[0], np.full_like(gx, plane - receiver[1]), gz - receiver[2]], -1)
    r = np.linalg.norm(d, axis=-1)
    cos = distance / r  # the same angle at the pane and at the receiver
    factor = glazing_factor(cos.ravel(), 2).reshape(cos.shape)
    patch_area = (3.0 / k) * (1.2 / (k // 2))
    exact = np.sum(0.6 * factor * 8000.0 / math.pi * cos * cos / r**2) * patch_area
    assert e == pytest.approx(exact, rel=0.01)


def test_daylight_needs_sight_of_the_window():
    partition = {"from": [8, 0], "to": [8, 6], "thickness": 0.15}
    daylight = {"enabled": True}
    model = _model(
        _box(
            10,
            6,
            walls=[partition],
            windows=[WINDOW],
            light={"ambient": False, "daylight": daylight},
        )
    )
    e = model.illuminance(
        [[5.0, 1.0, 1.5], [5.0, 1.0, 1.5], [9.0, 1.0, 1.5], [5.0, -1.0, 1.5]],
        [[0, -1, 0], [0, 1, 0], [-1, 0, 0], [0, 1, 0]],
    )
    assert e[0] > 100 and e[1] == 0 and e[2] == 0 and e[3] == 0


def test_daylight_flux_feeds_the_ambient_term():
    daylight = _uniform_daylight(10000.0, 0.7)
    on = _model(_box(10, 6, windows=[WINDOW], light={"daylight": daylight}))
    off = _model(_box(10, 6, windows=[WINDOW], light={"ambient": False, "daylight": daylight}))
    # Everything the pane admits, τ·E_v·A·⟨F⟩, with ⟨F⟩ = 2∫F(μ)·μ dμ the glazing's
    # fall-off averaged over a diffuse field.
    mu = (np.arange(20000) + 0.5) / 20000
    mean_factor = 2 * np.mean(glazing_factor(mu, 2) * mu)
    flux = 0.7 * 10000.0 * 3.0 * 1.2 * mean_factor
    area, walls = 60.0, 32.0 * 3.0
    surface = 2 * area + walls
    rho_mean = (0.8 * area + 0.5 * walls + 0.3 * area) / surface
    expected = flux * rho_mean / (surface * (1 - rho_mean))
    assert _ambient(on, off, [[8.0, 5.0, 1.0]], [0, 0, 1])[0] == pytest.approx(expected, rel=2e-3)


def test_window_in_an_internal_wall_admits_no_daylight():
    partition = {"from": [5, 0], "to": [5, 6], "thickness": 0.15}
    inner = {"from": [5.0, 2.0], "to": [5.0, 4.0]}
    model = _model(
        _box(10, 6, walls=[partition], windows=[inner], light={"daylight": {"enabled": True}})
    )
    assert len(model.sources) == 0


def test_receiver_arrays_are_checked():
    model = _model(_box(10, 6, luminaires=[_lamp((5, 3, 3))]))
    one = model.illuminance([5.0, 3.0, 1.0], [0.0, 0.0, 2.0])  # normals are normalised
    assert one.shape == (1,) and one[0] == model.illuminance([[5.0, 3.0, 1.0]], [0, 0, 1])[0]
    with pytest.raises(ValueError, match="normals"):
        model.illuminance([[5.0, 3.0, 1.0]], [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="points"):
        model.illuminance([[5.0, 3.0]], [0.0, 0.0, 1.0])


# ---------------------------------------------------------------- the compiled kernel


def _reference_direct(sources, points, normals, plan):
    """E = Σ_s I0·cosⁿθ·cos ψ/d²·T source by source in numpy, T from plan.light_transmittance."""
    out = np.zeros(len(points))
    for pos, axis, i0, n in zip(
        sources.position, sources.axis, sources.intensity_cd, sources.exponent, strict=True
    ):
        v = pos - points
        d2 = np.maximum(np.einsum("ij,ij->i", v, v), 0.05**2)
        d = np.sqrt(d2)
        cos_theta, cos_psi = -(v @ axis) / d, np.einsum("ij,ij->i", normals, v) / d
        lit = np.flatnonzero((cos_theta > 0) & (cos_psi > 0))
        e = i0 * cos_theta[lit] ** n * cos_psi[lit] / d2[lit]
        out[lit] += e * plan.light_transmittance(points[lit, :2], pos[None, :2])
    return out


@pytest.mark.parametrize("layout", ["path", "scattered"])
def test_kernel_with_its_shortcuts_equals_the_per_source_sum(layout):
    # The kernel skips a source for a whole chunk of receivers when one opaque
    # element shadows them all, and tests only the elements spanning each
    # receiver's direction: both exact, so the sums agree to rounding.
    import indoorsim
    from indoorsim.scenario.generate import generate

    site = indoorsim.load_site(generate("office", seed=2))
    rng = np.random.default_rng(4)
    x0, y0, x1, y1 = site.plan.bounds
    if layout == "path":  # a random walk: consecutive receivers close together
        start = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
        xy = np.clip(start + np.cumsum(rng.normal(0, 0.05, (6000, 2)), axis=0), (x0, y0), (x1, y1))
    else:
        xy = rng.uniform((x0, y0), (x1, y1), (3000, 2))
    points = np.column_stack([xy, rng.uniform(0.3, 1.8, len(xy))])
    normals = rng.normal(size=points.shape)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    sources = site.light.sources
    got = direct_illuminance(sources, points, normals, site.plan)
    want = _reference_direct(sources, points, normals, site.plan)
    assert (want > 0).mean() > 0.5 and (want == 0).any()
    np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-12)
