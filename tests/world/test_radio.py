"""Radio model: log-distance law, multi-wall losses, shadowing statistics and seeding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from indoorsim.scenario import parse_scenario
from indoorsim.world.materials import MATERIALS
from indoorsim.world.plan import FloorPlan
from indoorsim.world.radio import (
    MultipathField,
    RadioModel,
    ap_pattern_db,
    floor_loss_db,
    free_space_loss_1m_db,
    slab_loss_at,
    storey_bssid,
)

ONE_STOREY = {"floors_above": 0, "floors_below": 0}


def _hall(width: float, depth: float, walls: list[dict] | None = None, **keys: object) -> dict:
    """A closed concrete hall [0, width] × [0, depth] with a fixed outline, plus ``walls``;
    a single storey unless ``radio`` says otherwise."""
    keys["radio"] = {**ONE_STOREY, **keys.get("radio", {})}
    corners = [(0, 0), (width, 0), (width, depth), (0, depth)]
    outer = [
        {"from": list(a), "to": list(b), "thickness": 0.2}
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True)
    ]
    return {
        "name": "hall",
        "site": {"latitude": 32.6, "longitude": 117.0, "date": "2025-01-01", "ceiling_height": 3.0},
        "outline": [list(c) for c in corners],
        "walls": outer + (walls or []),
        **keys,
    }


def _ap(x: float, y: float, z: float = 2.5, bssid: str = "02:00:00:00:00:01", **keys) -> dict:
    return {"bssid": bssid, "position": [x, y, z], **keys}


def _model(data: dict) -> RadioModel:
    scenario = parse_scenario(data)
    return RadioModel(scenario, FloorPlan(scenario))


NO_SHADOWING = {"shadowing_sigma_db": 0.0}
ISOTROPIC = {"ap_null_depth_db": 0.0}
"""APs radiating alike in every direction: the distance law alone, whatever the elevation."""


def test_free_space_loss_at_one_metre_matches_realism_table():
    # REALISM §4.1: 40.1 dB @ 2.412 GHz, 46.7 dB @ 5.18 GHz, 47.7 dB @ 5.8 GHz.
    np.testing.assert_allclose(
        free_space_loss_1m_db(np.array([2.412, 5.18, 5.8])), [40.1, 46.7, 47.7], atol=0.05
    )


@pytest.mark.parametrize("exponent", [1.6, 2.0, 3.3])
def test_rss_follows_the_log_distance_law_in_free_space(exponent):
    radio = {"path_loss_exponent": exponent, "system_loss_db": 7.0, **NO_SHADOWING}
    ap = _ap(30, 30, 1.2, tx_power_dbm=20.0, frequency_ghz=5.2)
    model = _model(_hall(60, 60, wifi=[ap], radio=radio))
    d = np.array([0.0, 0.3, 1.0, 2.0, 5.0, 20.0, 25.0])
    rss = model.rss(np.column_stack([30 + d, 30 + 0 * d, 1.2 + 0 * d]))[:, 0]

    at_1m = 20.0 - 7.0 - free_space_loss_1m_db(5.2)
    # Inside the 1 m reference distance the RSS holds its 1 m value.
    np.testing.assert_allclose(rss[:3], at_1m, rtol=0, atol=1e-12)
    assert np.all(np.diff(rss[2:]) < 0)
    np.testing.assert_allclose(rss[3] - rss[5], 10 * exponent, atol=1e-9)  # one decade
    np.testing.assert_allclose(rss[2:], at_1m - 10 * exponent * np.log10(d[2:]), atol=1e-9)


def test_rss_uses_the_three_dimensional_distance():
    model = _model(_hall(20, 20, wifi=[_ap(10, 10, 2.5)], radio=NO_SHADOWING | ISOTROPIC))
    rss = model.rss([[13.0, 14.0, 2.5], [10.0, 10.0, -2.5]])[:, 0]  # both 5 m away
    assert rss[0] == pytest.approx(rss[1], abs=1e-12)


def test_ap_pattern_is_a_half_wave_dipole_with_its_null_filled():
    theta = np.radians([90.0, 60.0, 45.0, 0.0])
    # F(θ) = [cos(π/2·cos θ)/sin θ]²: 1 at the horizon, 0 along the axis.
    f = np.array([1.0, math.cos(math.pi / 4) ** 2 / 0.75, math.cos(math.pi / 2**1.5) ** 2 / 0.5, 0])
    for depth in (0.0, 10.0, 20.0):
        a = 10 ** (-depth / 10)
        np.testing.assert_allclose(
            ap_pattern_db(np.cos(theta), depth), 10 * np.log10((1 - a) * f + a), atol=1e-12
        )
    assert ap_pattern_db(1.0, 10.0) == pytest.approx(-10.0)  # straight down: the filled null
    assert not ap_pattern_db(np.linspace(-1, 1, 101), 0.0).any()  # isotropic
    near_axis = ap_pattern_db(np.cos(np.radians([1e-4, 1e-2, 1.0])), 40.0)
    assert np.all(np.diff(near_axis) > 0) and near_axis[0] == pytest.approx(-40.0, abs=1e-6)


def test_an_ap_overhead_is_read_below_the_distance_law_by_its_pattern():
    # A ceiling AP 1.8 m above the phone's height: straight below it, 0.4 m off and
    # 10 m away along the floor, against the isotropic AP's distance law.
    radio = {**NO_SHADOWING, "ap_null_depth_db": 10.0}
    points = np.array([[10.0, 10.0, 1.2], [10.4, 10.0, 1.2], [20.0, 10.0, 1.2]])
    ap = [_ap(10, 10, 3.0, tx_power_dbm=20.0, frequency_ghz=2.437)]
    dipole = _model(_hall(30, 20, wifi=ap, radio=radio)).rss(points)[:, 0]
    iso = _model(_hall(30, 20, wifi=ap, radio=NO_SHADOWING | ISOTROPIC)).rss(points)[:, 0]
    cos_theta = 1.8 / np.linalg.norm(points - [10.0, 10.0, 3.0], axis=1)
    np.testing.assert_allclose(dipole - iso, ap_pattern_db(cos_theta, 10.0), atol=1e-12)
    assert dipole[0] - iso[0] == pytest.approx(-10.0)
    assert -10.0 < dipole[1] - iso[1] < -8.0 and -0.3 < dipole[2] - iso[2] < 0.0
    # Level with the AP (the horizon) the pattern costs nothing.
    level = [[20.0, 10.0, 3.0]]
    assert _model(_hall(30, 20, wifi=ap, radio=radio)).rss(level)[0, 0] == pytest.approx(
        _model(_hall(30, 20, wifi=ap, radio=NO_SHADOWING | ISOTROPIC)).rss(level)[0, 0], abs=1e-12
    )


@pytest.mark.parametrize("frequency_ghz", [2.4, 5.2])
def test_each_crossed_wall_costs_exactly_its_material_loss(frequency_ghz):
    partitions = [
        {"from": [10, 0], "to": [10, 10], "thickness": 0.12, "material": "drywall"},
        {"from": [20, 0], "to": [20, 10], "thickness": 0.25, "material": "concrete"},
    ]
    keys = {"wifi": [_ap(5, 5, frequency_ghz=frequency_ghz)], "radio": NO_SHADOWING}
    open_hall = _model(_hall(30, 10, **keys))
    walled = _model(_hall(30, 10, walls=partitions, **keys))
    points = [[8.0, 2.0, 1.2], [15.0, 8.0, 1.2], [25.0, 5.0, 1.2], [28.0, 1.0, 0.3]]
    loss = walled.rss(points)[:, 0] - open_hall.rss(points)[:, 0]
    drywall = MATERIALS["drywall"].loss_db(frequency_ghz)
    concrete = MATERIALS["concrete"].loss_db(frequency_ghz)
    np.testing.assert_allclose(
        loss, [0.0, -drywall, -drywall - concrete, -drywall - concrete], atol=1e-9
    )


def test_a_door_on_the_path_costs_nothing():
    partition = [{"from": [10, 0], "to": [10, 10], "thickness": 0.2}]
    keys = {"wifi": [_ap(5, 5)], "radio": NO_SHADOWING}
    with_door = _model(
        _hall(20, 10, walls=partition, doors=[{"position": [10, 5], "width": 1.0}], **keys)
    )
    open_hall = _model(_hall(20, 10, **keys))
    p = [[15.0, 5.0, 1.2]]
    assert with_door.rss(p)[0, 0] == open_hall.rss(p)[0, 0]


def test_rss_is_the_deterministic_part_plus_the_shadowing_field():
    aps = [_ap(5, 5), _ap(25, 8, bssid="02:00:00:00:00:02", frequency_ghz=5.6)]
    plain = _model(_hall(30, 10, wifi=aps, radio=NO_SHADOWING))
    shadowed = _model(_hall(30, 10, wifi=aps, radio={"shadowing_sigma_db": 5.0}))
    p = np.random.default_rng(0).uniform([0, 0, 0], [30, 10, 3], (500, 3))
    np.testing.assert_allclose(shadowed.rss(p), plain.rss(p) + shadowed.shadowing_db(p), atol=1e-9)
    assert shadowed.rss(p).shape == (500, 2) and shadowed.bssids == [a["bssid"] for a in aps]


# ------------------------------------------------------------------- shadowing

SIGMA, LAMBDA = 6.0, 2.0
BSSIDS = [f"02:00:00:00:01:{k:02x}" for k in range(4)]


@pytest.fixture(scope="module")
def field_samples() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shadowing of 4 APs on a 0.5 m grid over an 80 m hall, and the same shifted by λ in x, y."""
    radio = {"shadowing_sigma_db": SIGMA, "shadowing_correlation_m": LAMBDA}
    model = _model(_hall(80, 80, wifi=[_ap(40, 40, bssid=b) for b in BSSIDS], radio=radio, seed=11))
    g = np.arange(1.0, 77.0, 0.5)
    xy = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    return (
        model.shadowing_db(xy),
        model.shadowing_db(xy + np.array([LAMBDA, 0.0])),
        model.shadowing_db(xy + np.array([0.0, LAMBDA])),
    )


def test_shadowing_has_the_configured_sigma(field_samples):
    x, _, _ = field_samples
    np.testing.assert_allclose(x.std(axis=0), SIGMA, rtol=0.2)
    assert x.std() == pytest.approx(SIGMA, rel=0.1)
    assert abs(x.mean()) < SIGMA / 4


def test_shadowing_correlation_at_lag_lambda_is_one_over_e(field_samples):
    x, dx, dy = field_samples
    for shifted in (dx, dy):
        rho = np.mean([np.corrcoef(x[:, k], shifted[:, k])[0, 1] for k in range(len(BSSIDS))])
        assert rho == pytest.approx(math.exp(-1), abs=0.08)


def _seeded(seed: int, aps: list[dict]) -> RadioModel:
    return _model(_hall(30, 20, wifi=aps, seed=seed))


POINTS = np.random.default_rng(5).uniform([-1, -1, 0], [31, 21, 3], (400, 3))


def test_same_seed_gives_identical_bytes_and_another_seed_another_field():
    aps = [_ap(5, 5), _ap(20, 15, bssid="02:00:00:00:00:02")]
    a, b, c = _seeded(3, aps).rss(POINTS), _seeded(3, aps).rss(POINTS), _seeded(4, aps).rss(POINTS)
    assert a.tobytes() == b.tobytes()
    assert np.abs(a - c).max() > 1.0


def test_an_aps_field_does_not_depend_on_the_other_aps():
    mine = _ap(5, 5, bssid="02:00:00:00:00:aa")
    alone = _seeded(3, [mine]).shadowing_db(POINTS)[:, 0]
    others = [_ap(20, 15, bssid="02:00:00:00:00:02"), _ap(1, 19, bssid="02:00:00:00:00:03")]
    crowded = _seeded(3, [others[0], mine, others[1]]).shadowing_db(POINTS)[:, 1]
    assert alone.tobytes() == crowded.tobytes()
    # The field is keyed by the BSSID itself, whatever its letter case.
    upper = _seeded(3, [mine | {"bssid": "02:00:00:00:00:AA"}]).shadowing_db(POINTS)[:, 0]
    assert alone.tobytes() == upper.tobytes()


def test_no_access_points_gives_an_empty_column_set():
    model = _model(_hall(10, 10))
    assert model.rss(POINTS).shape == (len(POINTS), 0)
    assert model.bssids == []


def test_cost231_floor_loss_in_closed_form():
    # L_f·k^((k+2)/(k+1) − 0.46): 18.3 dB through one slab, 18.3·2^(4/3 − 0.46) through two.
    assert floor_loss_db(0, 18.3) == 0.0
    assert floor_loss_db(1, 18.3) == pytest.approx(18.3)
    assert floor_loss_db(2, 18.3) == pytest.approx(18.3 * 2 ** (4 / 3 - 0.46))
    with pytest.raises(ValueError, match="slabs"):
        floor_loss_db(-1, 18.3)


def test_a_slab_loses_more_at_5_ghz_as_concrete_does():
    # 3GPP's concrete, 5 + 4f dB: 14.6 dB at 2.4 GHz, 25.8 dB at 5.2 GHz; a slab scales so.
    assert slab_loss_at(18.3, 2.4) == pytest.approx(18.3)
    assert slab_loss_at(18.3, 5.2) == pytest.approx(18.3 * 25.8 / 14.6)
    assert slab_loss_at(14.6, 3.8) == pytest.approx(5.0 + 4.0 * 3.8)
    assert slab_loss_at(0.0, 5.18) == 0.0  # a slab that passes everything still does


def test_a_5_ghz_radio_of_the_storey_above_is_heard_through_a_thicker_slab():
    radio = {**NO_SHADOWING, **ISOTROPIC, "floors_above": 1, "floors_below": 0}
    radio["floor_loss_db"] = 15.0
    aps = [
        _ap(10, 5, 2.5, tx_power_dbm=20.0, frequency_ghz=f, bssid=b)
        for f, b in ((2.4, "02:00:00:00:00:10"), (5.2, "02:00:00:00:00:18"))
    ]
    model = _model(_hall(30, 10, wifi=aps, radio=radio))
    rss = model.rss(np.array([[10.0, 5.0, 2.5]]))[0]
    # Columns: the two own radios, then the storey above's, 3 m straight up.
    fspl = [free_space_loss_1m_db(2.4), free_space_loss_1m_db(5.2)]
    up = 20.0 - 10.0 - np.array(fspl) - 20 * np.log10(3.0) - [15.0, 15.0 * 25.8 / 14.6]
    np.testing.assert_allclose(rss[2:], up, atol=1e-9)


def test_the_storeys_above_and_below_repeat_the_floors_aps_through_the_slab():
    radio = {
        **NO_SHADOWING,
        **ISOTROPIC,
        "floors_above": 1,
        "floors_below": 2,
        "floor_loss_db": 15.0,
    }
    ap = _ap(10, 5, 2.5, tx_power_dbm=20.0, frequency_ghz=2.437)
    model = _model(_hall(30, 10, wifi=[ap], radio=radio))
    own = ap["bssid"]
    assert model.bssids == [own, *(storey_bssid(own, k) for k in (1, -1, -2))]
    assert list(model.storey) == [0, 1, -1, -2]
    np.testing.assert_allclose(model.positions[:, 2], [2.5, 5.5, -0.5, -3.5])
    # Straight below the AP of the storey above: 3 m farther, one slab between.
    p = np.array([[10.0, 5.0, 2.5]])
    rss = model.rss(p)[0]
    d = np.array([1.0, 3.0, 3.0, 6.0])
    slab = slab_loss_at(15.0, 2.437)
    slabs = np.array([0.0, slab, slab, floor_loss_db(2, slab)])
    expected = 20.0 - 10.0 - free_space_loss_1m_db(2.437) - 20 * np.log10(d) - slabs
    np.testing.assert_allclose(rss, expected, atol=1e-9)


def test_storey_bssids_are_fixed_locally_administered_and_distinct():
    b = storey_bssid("02:93:0C:5E:52:10", 1)
    assert b == storey_bssid("02:93:0c:5e:52:10", 1) != storey_bssid("02:93:0c:5e:52:10", -1)
    first = int(b.split(":")[0], 16)
    assert first & 0x02 and not first & 0x01  # locally administered, unicast
    assert len(b) == 17 and b == b.lower()


def _behind_model(body_loss_db: float = 6.0) -> RadioModel:
    # Three APs at 1.2 m: ahead of (+x), behind (−x) and beside (+y) a phone at (10, 10).
    aps = [
        _ap(20, 10, 1.2, bssid="02:00:00:00:00:01"),
        _ap(0.5, 10, 1.2, bssid="02:00:00:00:00:02"),
        _ap(10, 19.5, 1.2, bssid="02:00:00:00:00:03"),
    ]
    radio = {**NO_SHADOWING, "body_loss_db": body_loss_db}
    return _model(_hall(20.5, 20, wifi=aps, radio=radio))


def test_the_body_shadows_the_aps_behind_a_held_phone_only():
    model = _behind_model(6.0)
    phone = np.array([[10.0, 10.0, 1.2]])
    torso = np.array([[9.7, 10.0]])  # the carrier 0.3 m behind, facing +x
    np.testing.assert_allclose(model.body_shadow_db(phone, torso)[0], [0.0, 6.0, 0.0], atol=1e-12)
    # Turned round, the carrier shadows the AP that was ahead.
    turned = model.body_shadow_db(phone, np.array([[10.3, 10.0]]))[0]
    np.testing.assert_allclose(turned, [6.0, 0.0, 0.0], atol=1e-12)
    assert not _behind_model(0.0).body_shadow_db(phone, torso).any()


def test_the_body_shadow_sets_in_continuously_as_the_carrier_turns():
    model = _behind_model(6.0)
    phone = np.tile([10.0, 10.0, 1.2], (721, 1))
    angle = np.radians(np.linspace(0.0, 360.0, 721))
    torso = phone[:, :2] - 0.3 * np.column_stack([np.cos(angle), np.sin(angle)])
    loss = model.body_shadow_db(phone, torso)[:, 1]  # the AP at −x
    assert loss.min() == 0.0 and loss.max() == pytest.approx(6.0)
    assert np.abs(np.diff(loss)).max() < 0.3  # 0.5° steps: no jump


def test_a_phone_against_the_body_loses_the_aps_on_the_bodys_side():
    model = _behind_model(8.0)
    phone = np.array([[10.0, 10.0, 0.8]])
    torso = np.array([[10.0, 10.1]])  # a front pocket, the pelvis centre 0.1 m toward +y
    loss = model.body_shadow_db(phone, torso)[0]
    np.testing.assert_allclose(loss[2], 8.0)  # the AP beyond the body, at +y
    assert loss[0] < 8.0 and loss[1] < 8.0  # those to the sides lose less (half-shadowed)
    with pytest.raises(ValueError, match="torso_xy"):
        model.body_shadow_db(phone, np.zeros((2, 2)))


# ------------------------------------------------------------------- multipath


def _field(paths: int = 128, delay_ns: float = 1e-6, k_db: float = -200.0, seed: int = 0):
    return MultipathField.sample(
        np.random.default_rng(seed),
        2.4,
        paths=paths,
        delay_spread_ns=delay_ns,
        rician_k_db=k_db,
        rician_k_sigma_db=0.0,
        bandwidth_mhz=20.0,
    )


AP = np.array([0.0, 0.0, 2.5])


def _places(n: int = 40_000, seed: int = 1) -> np.ndarray:
    return np.random.default_rng(seed).uniform([-40, -40, 0], [40, 40, 3], (n, 3))


def test_narrowband_scattering_alone_is_rayleigh_fading():
    # Power exponential with mean 1: in dB, mean −10·γ/ln 10 = −2.51 dB and std
    # 10/ln 10 · π/√6 = 5.57 dB.
    fade = _field().fading_db(_places(), AP, np.zeros(40_000))
    assert np.mean(10 ** (fade / 10)) == pytest.approx(1.0, abs=0.03)
    assert np.mean(fade) == pytest.approx(-10 * np.euler_gamma / math.log(10), abs=0.15)
    assert np.std(fade) == pytest.approx(10 / math.log(10) * math.pi / math.sqrt(6), rel=0.04)


def test_the_band_average_has_the_variance_of_its_frequency_correlation():
    # For a Gaussian field the covariance of |h(f_i)|² and |h(f_j)|² is |ρ_ij|², ρ the
    # correlation between frequencies: Σ_m band[m, i]·conj(band[m, j]) for these paths.
    field = _field(delay_ns=40.0)
    power = 10 ** (field.fading_db(_places(), AP, np.zeros(40_000)) / 10)
    rho = field.band.T @ field.band.conj()
    assert np.var(power) == pytest.approx(np.mean(np.abs(rho) ** 2), rel=0.06)
    assert np.std(10 * np.log10(power)) < 4.0  # shallower than narrowband Rayleigh's 5.6 dB


def test_fading_decorrelates_within_half_a_wavelength():
    # Isotropic scattering in 3-D: field correlation sinc(k·d), zero at d = λ/2.
    field = _field()
    p = _places(20_000)
    wavelength = 2 * math.pi / field.wavenumber
    power = [
        10 ** (field.fading_db(p + np.array([d, 0.0, 0.0]), AP, np.zeros(len(p))) / 10)
        for d in (0.0, wavelength / 20, wavelength / 2)
    ]
    near = np.corrcoef(power[0], power[1])[0, 1]
    half = np.corrcoef(power[0], power[2])[0, 1]
    assert near > 0.9
    assert abs(half) < 0.05
    assert near == pytest.approx(np.sinc(1 / 10) ** 2, abs=0.03)  # np.sinc(x) = sin(πx)/(πx)


def test_a_strong_direct_wave_flattens_the_fade_and_a_wall_in_its_way_brings_it_back():
    field = _field(k_db=40.0)
    p = _places(5000)
    clear = field.fading_db(p, AP, np.zeros(len(p)))
    # P ≈ 1 + 2·Re(s)/√K for a unit scattered field s: std 10/ln 10 · √(2/K) dB.
    assert np.std(clear) == pytest.approx(10 / math.log(10) * math.sqrt(2e-4), rel=0.1)
    behind_walls = field.fading_db(p, AP, np.full(len(p), 60.0))
    assert np.std(behind_walls) == pytest.approx(5.57, rel=0.06)


def test_rss_small_scale_adds_each_aps_own_fade_to_the_local_mean():
    aps = [_ap(5, 5), _ap(25, 8, bssid="02:00:00:00:00:02", frequency_ghz=5.6)]
    partition = [{"from": [15, 0], "to": [15, 10], "thickness": 0.2}]
    model = _model(_hall(30, 10, walls=partition, wifi=aps, radio=NO_SHADOWING))
    p = np.random.default_rng(0).uniform([0, 0, 0], [30, 10, 3], (300, 3))
    fade = model.rss(p, small_scale=True) - model.rss(p)
    for k, field in enumerate(model.multipath):
        walls = model.plan.crossing_loss_db(
            p[:, :2],
            model.positions[None, k, :2],
            aps[k].get("frequency_ghz", 2.4),
            pillar_loss_db=model.pillar_loss_db,
        )
        np.testing.assert_allclose(fade[:, k], field.fading_db(p, model.positions[k], walls))
    # The same spot reads the same fade; another seed gives another field.
    np.testing.assert_array_equal(model.rss(p, small_scale=True), model.rss(p, small_scale=True))
    other = _model(_hall(30, 10, walls=partition, wifi=aps, radio=NO_SHADOWING, seed=5))
    assert not np.allclose(other.rss(p, small_scale=True), model.rss(p, small_scale=True))
    off = _model(_hall(30, 10, wifi=aps, radio={**NO_SHADOWING, "multipath": {"enabled": False}}))
    np.testing.assert_array_equal(off.rss(p, small_scale=True), off.rss(p))


def test_the_handset_pattern_is_its_first_harmonic_toward_its_side():
    # APs ahead (+x), behind (−x) and beside (+y) the phone at (10, 10, 1.2), at its height.
    model = _behind_model()
    phone = np.array([[10.0, 10.0, 1.2]] * 3)
    sides = np.array([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 1.0, 0.0]])  # not unit: normalised
    gain = model.handset_gain_db(phone, sides, 8.0)
    np.testing.assert_allclose(gain[0], [0.0, 0.0, 4.0], atol=1e-12)  # +ratio/2 toward its side
    np.testing.assert_allclose(gain[1], [0.0, 0.0, -4.0], atol=1e-12)  # turned round: −ratio/2
    c = math.cos(math.radians(45.0))
    np.testing.assert_allclose(gain[2], [4.0 * c, -4.0 * c, 4.0 * c], atol=1e-12)
    # Turning the phone round swaps the sign for every AP: the mean of the two is 0.
    np.testing.assert_allclose(
        model.handset_gain_db(phone, sides, 8.0) + model.handset_gain_db(phone, -sides, 8.0), 0.0
    )
    assert not model.handset_gain_db(phone, sides, 0.0).any()
    with pytest.raises(ValueError, match="side_axis"):
        model.handset_gain_db(phone, np.zeros((2, 3)), 8.0)


def test_the_handset_pattern_is_zero_toward_an_ap_straight_above():
    model = _model(_hall(20, 20, wifi=[_ap(10, 10, 3.0)], radio=NO_SHADOWING))
    gain = model.handset_gain_db([[10.0, 10.0, 1.2]], [[1.0, 0.0, 0.0]], 8.0)
    np.testing.assert_allclose(gain, 0.0, atol=1e-12)
