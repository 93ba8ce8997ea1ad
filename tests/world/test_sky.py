"""Daylight: the sun's position, the CIE sky, the glazing and the sunbeam through windows."""

from __future__ import annotations

import datetime
import math

import numpy as np
import pytest

from indoorsim.scenario import ScenarioError, parse_scenario
from indoorsim.scenario.schema import DaylightSpec, SiteSpec
from indoorsim.world.body_shadow import BodyShadow
from indoorsim.world.light import LightModel
from indoorsim.world.plan import FloorPlan
from indoorsim.world.sky import CIE_SKY_TYPES, SkyState, glazing_factor, sun_illuminance

GREENWICH = {"latitude": 51.4779, "longitude": 0.0, "date": "2025-06-21", "ceiling_height": 3.0}


def _sky(sky: str, time: str = "12:00", site: dict | None = None, **keys: object) -> SkyState:
    spec = SiteSpec(**(site or GREENWICH))
    return SkyState.from_spec(
        spec, DaylightSpec(enabled=True, sky=sky, time=time, utc_offset_h=0, **keys)
    )


def test_the_sun_at_greenwich_at_the_june_solstice_noon():
    sky = _sky("clear", "12:02")  # the equation of time: solar noon near 12:02 UTC
    altitude = math.degrees(math.asin(sky.sun[2]))
    assert altitude == pytest.approx(90 - 51.4779 + 23.44, abs=0.1)
    # Due south: with the building's +y to the north, the sun lies toward -y.
    assert sky.sun[1] < 0 and abs(sky.sun[0]) < 0.01


def test_the_building_frame_turns_with_north():
    site = dict(GREENWICH, north_deg=90.0)  # the building's +y points east, +x south
    sky = _sky("clear", "12:02", site)
    assert sky.sun[0] > 0.4 and abs(sky.sun[1]) < 0.01


def test_no_daylight_after_sunset():
    sky = _sky("clear", "23:30")
    assert not sky.daytime and sky.zenith_luminance == 0 and sky.sun_normal_lux == 0


def test_overcast_sky_is_three_times_brighter_at_the_zenith_than_at_the_horizon():
    sky = _sky("overcast")
    zenith, horizon = sky.luminance(np.array([[0, 0, 1.0], [1.0, 0, 1e-12]]))
    a, b = CIE_SKY_TYPES[1][:2]
    assert zenith / horizon == pytest.approx(1 + a * math.exp(b), rel=1e-9)
    assert zenith / horizon == pytest.approx(3.0, rel=0.01)
    # Azimuthally uniform: the sun's direction does not matter.
    around = sky.luminance(np.array([[np.cos(t), np.sin(t), 1.0] for t in (0, 1, 2, 3)]) / 2**0.5)
    np.testing.assert_allclose(around, around[0], rtol=1e-12)


@pytest.mark.parametrize("weather", ["overcast", "intermediate", "clear"])
def test_the_sky_gives_the_ies_horizontal_illuminance(weather):
    sky = _sky(weather, "10:00")
    alpha = math.asin(sky.sun[2])
    a, b, c = {
        "overcast": (0.3, 21.0, 1.0),
        "intermediate": (0.3, 45.0, 1.0),
        "clear": (0.8, 15.5, 0.5),
    }[weather]
    assert sky.horizontal_sky_lux() == pytest.approx(
        1000 * (a + b * math.sin(alpha) ** c), rel=1e-9
    )
    # A fine midpoint quadrature of ∫ L cos Z dΩ agrees with the Fibonacci sum.
    z = (np.arange(360) + 0.5) * (math.pi / 2) / 360
    phi = (np.arange(720) + 0.5) * 2 * math.pi / 720
    gz, gp = np.meshgrid(z, phi, indexing="ij")
    u = np.stack([np.sin(gz) * np.cos(gp), np.sin(gz) * np.sin(gp), np.cos(gz)], -1).reshape(-1, 3)
    weight = (np.cos(gz) * np.sin(gz)).ravel() * (math.pi / 2 / 360) * (2 * math.pi / 720)
    assert np.sum(sky.luminance(u) * weight) == pytest.approx(sky.horizontal_sky_lux(), rel=0.01)


def test_a_clear_sky_is_brightest_around_the_sun_and_has_a_sunbeam():
    sky = _sky("clear", "10:00")
    tilted = sky.sun + np.array([0.0, 0.0, 0.05])
    near = sky.luminance((tilted / np.linalg.norm(tilted))[None, :])
    away = sky.luminance(np.array([[-sky.sun[0], -sky.sun[1], sky.sun[2]]]))
    assert near[0] > 3 * away[0]
    alpha = math.asin(sky.sun[2])
    assert 50_000 < sky.sun_normal_lux < 127_500 * 1.034 * math.exp(-0.21)
    assert sky.ground_luminance == pytest.approx(
        0.2 * (sky.horizontal_sky_lux() + sky.sun_normal_lux * math.sin(alpha)) / math.pi,
        rel=1e-9,
    )
    assert _sky("overcast", "10:00").sun_normal_lux == 0


def test_glazing_falls_from_normal_to_grazing_incidence():
    mu = np.linspace(0, 1, 101)
    one, two = glazing_factor(mu, 1), glazing_factor(mu, 2)
    assert one[-1] == pytest.approx(1.0, abs=1e-12) and one[0] == 0 and two[0] == 0
    assert np.all(np.diff(one) >= 0) and np.all(np.diff(two) >= 0)
    assert np.all(two[1:-1] < one[1:-1])  # more faces reflect more at oblique incidence
    # Single pane, lossless: 1 − R with R = 2r/(1 + r) per polarisation; at
    # Brewster's angle the p-polarised half passes whole.
    n = 1.52
    c = math.cos(math.atan(n))
    ct = math.sqrt(1 - (1 - c * c) / n**2)
    rs = ((c - n * ct) / (c + n * ct)) ** 2
    r0 = ((n - 1) / (n + 1)) ** 2
    expected = 0.5 * ((1 - rs) / (1 + rs) + 1.0) / ((1 - r0) / (1 + r0))
    assert glazing_factor(np.array([c]), 1)[0] == pytest.approx(expected, rel=1e-12)


# ------------------------------------------------------------------- the sunbeam

SOUTH_WINDOW = {"from": [2.0, 0.0], "to": [8.0, 0.0], "sill": 0.9, "head": 2.1}


def _room(time: str = "12:02", walls: list[dict] | None = None, windows=(SOUTH_WINDOW,)) -> dict:
    corners = [(0, 0), (10, 0), (10, 6), (0, 6)]
    outer = [
        {"from": list(a), "to": list(b), "thickness": 0.2}
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True)
    ]
    return {
        "name": "sunny room",
        "site": dict(GREENWICH, date="2025-03-20"),  # the sun ~38° up at noon
        "walls": outer + (walls or []),
        "windows": list(windows),
        "light": {
            "ambient": False,
            "daylight": {"enabled": True, "sky": "clear", "time": time, "utc_offset_h": 0},
        },
    }


def _light(data: dict) -> LightModel:
    scenario = parse_scenario(data)
    return LightModel(scenario, FloorPlan(scenario))


def _through_window(model: LightModel, point) -> bool:
    """Where the ray toward the sun meets the window's wall (y = 0), and whether
    that lies in the pane, by plain geometry."""
    s = model.sky.sun
    t = -point[1] / s[1]
    x, z = point[0] + t * s[0], point[2] + t * s[2]
    return 2.0 <= x <= 8.0 and 0.9 <= z <= 2.1


def test_the_sunbeam_falls_where_the_geometry_says():
    model = _light(_room())
    s = model.sky.sun
    assert s[1] < 0  # the window faces the sun
    xs, ys = np.meshgrid(np.linspace(0.5, 9.5, 19), np.linspace(0.3, 5.7, 19))
    points = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, 1.0)])
    normal = s  # a receiver facing the sun: cos ψ = 1
    e = sun_illuminance(
        model.sky, points, np.broadcast_to(normal, points.shape), model.plan, model.windows, 3.0
    )
    lit = np.array([_through_window(model, p) for p in points])
    assert lit.any() and not lit.all()
    np.testing.assert_array_equal(e > 0, lit)
    cos_pane = abs(s[1])
    expected = model.sky.sun_normal_lux * 0.7 * glazing_factor(np.array([cos_pane]), 2)[0]
    np.testing.assert_allclose(e[lit], expected, rtol=1e-12)
    # Facing away from the sun: no beam; a horizontal receiver: cos ψ = sin α.
    assert np.all(
        sun_illuminance(
            model.sky, points, np.broadcast_to(-s, points.shape), model.plan, model.windows, 3.0
        )
        == 0
    )
    flat = sun_illuminance(
        model.sky,
        points,
        np.broadcast_to([0, 0, 1.0], points.shape),
        model.plan,
        model.windows,
        3.0,
    )
    np.testing.assert_allclose(flat[lit], expected * s[2] / 1.0, rtol=1e-12)


def test_walls_pillars_and_the_carrier_shade_the_sunbeam():
    partition = {"from": [0.0, 1.0], "to": [5.0, 1.0], "thickness": 0.1}
    model = _light(_room(walls=[partition]))
    s = model.sky.sun
    behind = np.array([3.0, 1.3, 1.0])  # the partition lies between it and the window
    open_side = np.array([7.0, 1.3, 1.0])
    assert _through_window(model, behind) and _through_window(model, open_side)
    e = model.illuminance([behind, open_side], s)
    assert e[0] < 1000 < e[1]  # skylight still reaches the shaded point
    # The carrier standing sunward of the phone shades it.
    ahead = open_side + 0.3 * s / np.linalg.norm(s[:2])
    ahead[2] = 0.0
    body = BodyShadow(
        head=np.array([[ahead[0], ahead[1], 1.6]]),
        head_radius_m=0.1,
        trunk_xy=np.array([[ahead[0], ahead[1]]]),
        trunk_yaw=np.zeros(1),
        trunk_top=np.array([1.45]),
        trunk_half_depth_m=0.12,
        trunk_half_width_m=0.2,
    )
    shaded = sun_illuminance(
        model.sky, open_side[None], s[None], model.plan, model.windows, 3.0, body
    )
    assert shaded[0] == 0


def test_a_room_without_windows_gets_no_daylight():
    model = _light(_room(windows=()))
    assert len(model.sources) == 0
    points = np.array([[5.0, 3.0, 1.2], [0.5, 0.5, 2.9]])
    assert np.all(model.illuminance(points, [0, 0, 1.0]) == 0)


def test_skylight_falls_with_the_sun_and_vanishes_at_night():
    noon = _light(_room("12:02")).illuminance([[5.0, 1.0, 1.2]], [0, 0, 1.0])[0]
    evening = _light(_room("17:30")).illuminance([[5.0, 1.0, 1.2]], [0, 0, 1.0])[0]
    night = _light(_room("22:00"))
    assert noon > evening > 0
    assert len(night.sources) == 0 and night.illuminance([[5.0, 1.0, 1.2]], [0, 0, 1.0])[0] == 0


def test_daylight_settings_are_checked():
    with pytest.raises(ScenarioError, match="quote the time"):
        parse_scenario(_room() | {"light": {"daylight": {"enabled": True, "time": 870}}})
    with pytest.raises(ScenarioError, match="uniform"):
        parse_scenario(_room() | {"light": {"daylight": {"exterior_vertical_lux": 5000.0}}})
    with pytest.raises(ScenarioError, match="needs exterior_vertical_lux"):
        parse_scenario(_room() | {"light": {"daylight": {"sky": "uniform"}}})
    assert DaylightSpec(time="09:15").time == datetime.time(9, 15)
