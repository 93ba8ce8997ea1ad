"""The carrier's body in the light model: hard shadows of point sources, penumbrae of
extended faces, and the body's share of the ambient view — each against a closed form
or a brute-force count."""

from __future__ import annotations

import math

import numpy as np
import pytest

from indoorsim.phone.devices import LightSensorSpec, cosine_power, get_device
from indoorsim.world.body_shadow import BODY_REFLECTANCE, BodyShadow
from indoorsim.world.light import (
    LightModel,
    PointSources,
    diffuse_response,
    direct_illuminance,
)

from .test_light import _box, _model


def _head_only(head: list[float], radius: float = 0.1, n: int = 1) -> BodyShadow:
    """A head sphere with the trunk sunk far below every receiver."""
    return BodyShadow(
        head=np.tile(head, (n, 1)).astype(float),
        head_radius_m=radius,
        trunk_xy=np.zeros((n, 2)),
        trunk_yaw=np.zeros(n),
        trunk_top=np.full(n, -100.0),
        trunk_half_depth_m=0.1,
        trunk_half_width_m=0.1,
    )


def _trunk_only(xy: list[float], yaw: float, top: float, depth: float, width: float) -> BodyShadow:
    return BodyShadow(
        head=np.array([[0.0, 0.0, -100.0]]),
        head_radius_m=0.1,
        trunk_xy=np.array([xy], dtype=float),
        trunk_yaw=np.array([yaw]),
        trunk_top=np.array([top]),
        trunk_half_depth_m=depth,
        trunk_half_width_m=width,
    )


def test_a_sight_line_through_the_head_is_blocked_and_one_past_it_is_not():
    body = _head_only([0.0, 0.0, 1.5], n=3)
    p = np.tile([0.0, 0.0, 1.0], (3, 1))
    q = np.array([[0.0, 0.0, 3.0], [0.3, 0.0, 3.0], [0.6, 0.0, 3.0]])
    # At the head's height the segment is x/4 off the axis: 0, 0.075 (inside), 0.15.
    assert body.blocks(p, q).tolist() == [True, True, False]
    # A segment that ends before the head reaches nothing.
    assert not _head_only([0.0, 0.0, 1.5]).blocks(p[:1], np.array([[0.0, 0.0, 1.35]]))[0]


def test_the_trunk_is_an_upright_elliptic_cylinder_under_the_shoulders():
    # Facing +y (yaw 90°): depth along y, width along x.
    body = _trunk_only([0.0, 0.0], math.pi / 2, top=1.4, depth=0.1, width=0.2)
    p = np.array([[0.0, 0.5, 1.0]])

    def blocked(q: list[float]) -> bool:
        return bool(body.blocks(p, np.array([q], dtype=float))[0])

    assert blocked([0.0, -0.5, 1.0])  # straight through the chest
    assert blocked([0.15, -0.5, 1.0])  # 0.075 aside at the axis: within the half-width
    assert not blocked([0.6, -0.5, 1.0])  # 0.24–0.36 aside across the trunk: past its side
    # Over the shoulders: the sight line is above the top where it crosses the trunk.
    assert not blocked([0.0, -0.5, 2.2])
    # Rising more gently: z = 1.2 where it meets the chest (y = 0.1), under the top.
    assert blocked([0.0, -0.5, 1.5])


def test_a_point_source_behind_the_head_casts_a_hard_shadow_and_otherwise_keeps_the_law():
    src = PointSources.from_arrays([0.0, 0.0, 3.0], [0.0, 0.0, -1.0], 1000.0, 1.0)
    points = np.array([[0.0, 0.0, 1.2], [1.0, 0.0, 1.2]])
    normals = np.tile([0.0, 0.0, 1.0], (2, 1))
    body = _head_only([0.0, 0.0, 1.6], n=2)
    got = direct_illuminance(src, points, normals, body=body)
    assert got[0] == 0.0
    h, r = 1.8, 1.0
    d = math.hypot(h, r)
    # The second sight line clears the head: E = I0·h²/d⁴ (Lambertian), exactly.
    assert got[1] == pytest.approx(1000.0 * h**2 / d**4, rel=1e-12)


def _visible_share_brute(p: np.ndarray, centre: np.ndarray, half: float, body: BodyShadow) -> float:
    """The share of a square face (side 2·half, horizontal) seen past ``body``, on a fine grid."""
    k = 120
    f = (np.arange(k) + 0.5) / k * 2 - 1
    gx, gy = np.meshgrid(f * half, f * half)
    q = np.column_stack([centre[0] + gx.ravel(), centre[1] + gy.ravel(), np.full(k * k, centre[2])])
    many = BodyShadow(
        head=np.tile(body.head[0], (len(q), 1)),
        head_radius_m=body.head_radius_m,
        trunk_xy=np.tile(body.trunk_xy[0], (len(q), 1)),
        trunk_yaw=np.full(len(q), body.trunk_yaw[0]),
        trunk_top=np.full(len(q), body.trunk_top[0]),
        trunk_half_depth_m=body.trunk_half_depth_m,
        trunk_half_width_m=body.trunk_half_width_m,
    )
    return 1.0 - many.blocks(np.tile(p, (len(q), 1)), q).mean()


@pytest.mark.parametrize("offset", [0.0, 0.05, 0.1, 0.2, 0.4])
def test_an_extended_face_casts_a_penumbra_matching_the_visible_share(offset):
    # A 0.6 m panel 1.8 m above the sensor, the head 0.4 m above it and a little aside:
    # the head hides a patch of the panel ~4.5 times its own size.
    p = np.array([0.0, 0.0, 1.2])
    centre = np.array([0.0, 0.0, 3.0])
    body = _head_only([offset, 0.0, 1.6])
    panel = PointSources.from_arrays(centre, [0.0, 0.0, -1.0], 1800.0, 2.75, size_m=(0.6, 0.6))
    point = PointSources.from_arrays(centre, [0.0, 0.0, -1.0], 1800.0, 2.75)
    up = np.array([[0.0, 0.0, 1.0]])
    bare = direct_illuminance(point, p[None], up)[0]
    got = direct_illuminance(panel, p[None], up, body=body)[0] / bare
    want = _visible_share_brute(p, centre, 0.3, body)
    # The kernel samples the face on a 6 × 6 grid (cells of 1/36): within a cell or so.
    assert got == pytest.approx(want, abs=0.04)
    assert 0.0 <= got <= 1.0


def test_a_face_shrinks_to_the_point_sources_hard_shadow():
    p = np.array([[0.0, 0.0, 1.2]])
    up = np.array([[0.0, 0.0, 1.0]])
    body = _head_only([0.0, 0.0, 1.6])
    tiny = PointSources.from_arrays([0.0, 0.0, 3.0], [0, 0, -1], 1000.0, 1.0, size_m=(1e-4, 1e-4))
    assert direct_illuminance(tiny, p, up, body=body)[0] == 0.0


def test_the_heads_share_of_the_view_is_the_spheres_view_factor():
    # A sphere of angular radius α whose centre is β from the normal, wholly above the
    # receiver's horizon, fills sin²α·cos β of the cosine-weighted view.
    n = 3
    body = _head_only([0.0, 0.0, 0.0], radius=0.2, n=n)
    beta = np.radians([0.0, 30.0, 50.0])
    dist = 0.6
    # Receivers placed below-beside the head so its centre is β off their upward normal.
    points = np.column_stack([-dist * np.sin(beta), np.zeros(n), -dist * np.cos(beta)])
    normals = np.tile([0.0, 0.0, 1.0], (n, 1))
    got = body.view_blocked(points, normals)
    want = (0.2 / dist) ** 2 * np.cos(beta)
    np.testing.assert_allclose(got, want, atol=0.025)


def test_the_body_takes_its_view_share_from_the_ambient_term_less_what_it_reflects():
    model = _model(
        _box(
            10.0,
            6.0,
            luminaires=[
                {"position": [2.5, 3.0, 3.0], "intensity_cd": 800.0},
                {"position": [7.5, 3.0, 3.0], "intensity_cd": 800.0},
            ],
        )
    )
    assert isinstance(model, LightModel) and model.ambient is not None
    p = np.array([[5.0, 1.0, 1.2]])
    up = np.array([[0.0, 0.0, 1.0]])
    # A head right over the sensor: no luminaire sight line crosses it.
    body = _head_only([5.0, 1.0, 1.6], radius=0.1)
    share = body.view_blocked(p, up)[0]
    assert share > 0.0
    ambient = model.ambient(p, up)[0]
    direct = direct_illuminance(model.sources, p, up, model.plan, body)[0]
    assert direct == pytest.approx(direct_illuminance(model.sources, p, up, model.plan)[0])
    got = model.illuminance(p, up, body)[0]
    assert got == pytest.approx(direct + ambient * (1 - (1 - BODY_REFLECTANCE) * share))


def test_body_shadow_shapes_are_checked():
    with pytest.raises(ValueError, match="trunk_yaw"):
        BodyShadow(
            head=np.zeros((2, 3)),
            head_radius_m=0.1,
            trunk_xy=np.zeros((2, 2)),
            trunk_yaw=np.zeros(3),
            trunk_top=np.zeros(2),
            trunk_half_depth_m=0.1,
            trunk_half_width_m=0.1,
        )
    src = PointSources.from_arrays([0.0, 0.0, 3.0], [0.0, 0.0, -1.0], 1000.0, 1.0)
    with pytest.raises(ValueError, match="body"):
        direct_illuminance(
            src, np.zeros((2, 3)), np.tile([0, 0, 1.0], (2, 1)), body=_head_only([0, 0, 2])
        )


def test_a_face_lies_across_the_axis_along_its_length():
    src = PointSources.from_arrays(
        [[0.0, 0.0, 3.0]], [[0.0, 0.0, -1.0]], 500.0, 1.0, size_m=(1.2, 0.03), along=(0.0, 1.0, 0.0)
    )
    np.testing.assert_allclose(src.face_u[0], [0.0, 0.6, 0.0], atol=1e-12)
    np.testing.assert_allclose(np.abs(src.face_v[0]), [0.015, 0.0, 0.0], atol=1e-12)
    # An ``along`` parallel to the axis still gives a face across it.
    odd = PointSources.from_arrays([0, 0, 3.0], [0, 0, -1.0], 1.0, 1.0, (0.6, 0.6), (0, 0, 1.0))
    assert abs(odd.face_u[0] @ [0.0, 0.0, 1.0]) < 1e-12
    assert np.linalg.norm(odd.face_u[0]) == pytest.approx(0.3)


@pytest.mark.parametrize("k", [1.0, 1.78, 3.0])
def test_a_narrow_receiver_reads_a_point_source_by_cos_k_and_diffuse_light_by_2_over_k_plus_1(k):
    # A uniform point source 2 m away at 40° incidence: E = I0·cosᵏψ/d².
    psi = math.radians(40.0)
    src = PointSources.from_arrays(
        [2 * math.sin(psi), 0.0, 2 * math.cos(psi)], [-math.sin(psi), 0, -math.cos(psi)], 500.0, 0.0
    )
    up = np.array([[0.0, 0.0, 1.0]])
    got = direct_illuminance(src, np.zeros((1, 3)), up, response_exponent=k)[0]
    assert got == pytest.approx(500.0 * math.cos(psi) ** k / 4.0, rel=1e-12)
    # Straight ahead it reads the same as a cosine meter (calibrated at normal incidence).
    ahead = PointSources.from_arrays([0.0, 0.0, 2.0], [0.0, 0.0, -1.0], 500.0, 0.0)
    assert direct_illuminance(ahead, np.zeros((1, 3)), up, response_exponent=k)[0] == 125.0
    # A uniform diffuse field: ∫cosᵏ dΩ / ∫cos dΩ, here by quadrature over the hemisphere.
    theta = np.linspace(0.0, math.pi / 2, 20001)
    ratio = np.trapezoid(np.cos(theta) ** k * np.sin(theta), theta) / 0.5
    assert diffuse_response(k) == pytest.approx(ratio, rel=1e-6)


def test_the_ambient_term_reads_as_diffuse_light_through_a_narrow_receiver():
    model = _model(
        _box(10.0, 6.0, luminaires=[{"position": [2.5, 3.0, 3.0], "intensity_cd": 800.0}])
    )
    p, up = np.array([[7.0, 3.0, 1.2]]), np.array([[0.0, 0.0, 1.0]])
    k = cosine_power(47.5)
    direct = direct_illuminance(model.sources, p, up, model.plan, response_exponent=k)[0]
    want = direct + model.ambient(p, up)[0] * 2 / (k + 1)
    assert model.illuminance(p, up, response_exponent=k)[0] == pytest.approx(want)


def test_the_half_sensitivity_angle_gives_the_cosine_power():
    assert cosine_power(60.0) == 1.0  # exactly: the cosine path, bit for bit
    for half in (35.0, 47.5, 55.0):
        assert math.cos(math.radians(half)) ** cosine_power(half) == pytest.approx(0.5)
    assert LightSensorSpec().response_exponent == pytest.approx(1.0)
    assert get_device("nexus_5x").light.response_exponent > 1.0
    with pytest.raises(ValueError, match="half_sensitivity_deg"):
        LightSensorSpec(half_sensitivity_deg=75.0)
    with pytest.raises(ValueError, match="response_exponent"):
        up = np.array([[0.0, 0.0, 1.0]])
        direct_illuminance(PointSources.empty(), np.zeros((1, 3)), up, response_exponent=0.5)


def test_bad_bodies_and_faces_are_clear_errors():
    with pytest.raises(ValueError, match=r"head.*finite"):
        _head_only([0.0, float("nan"), 1.6])
    u = np.array([[0.3, 0.0, 0.0]])
    with pytest.raises(ValueError, match="perpendicular"):
        PointSources(
            position=np.zeros((1, 3)),
            axis=np.array([[0.0, 0.0, -1.0]]),
            intensity_cd=np.ones(1),
            exponent=np.ones(1),
            face_u=u,
            face_v=u,
        )
    with pytest.raises(ValueError, match="face_u"):
        PointSources(
            position=np.zeros((2, 3)),
            axis=np.tile([0.0, 0.0, -1.0], (2, 1)),
            intensity_cd=np.ones(2),
            exponent=np.ones(2),
            face_u=u,
        )
    # The view share takes any non-zero normal, normalised.
    body = _head_only([0.0, 0.0, 0.0], radius=0.2)
    p = np.array([[0.0, 0.0, -0.6]])
    assert body.view_blocked(p, [[0.0, 0.0, 2.0]])[0] == body.view_blocked(p, [[0, 0, 1.0]])[0]
