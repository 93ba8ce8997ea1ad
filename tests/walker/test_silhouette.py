"""The carrier's silhouette: anthropometric sizes, its pose along the walk, and which
carrying modes let it shade the light sensor."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import indoorsim
from indoorsim.phone.devices import get_device
from indoorsim.simulate import resolve_route, run_streams, sample_sensors
from indoorsim.walker.carry import carry
from indoorsim.walker.gait import PELVIS_HEIGHT_RATIO, WalkerParams, walk
from indoorsim.walker.silhouette import (
    HEAD_CENTRE_RATIO,
    SHOULDER_RATIO,
    Carrier,
    silhouette,
)


def test_sizes_scale_with_height_and_the_head_sits_over_the_shoulders():
    for height in (1.55, 1.75, 1.95):
        pelvis = np.array([[2.0, 3.0, PELVIS_HEIGHT_RATIO * height]])
        body = silhouette(pelvis, np.array([0.0]), height)
        assert body.head[0, 2] == pytest.approx(HEAD_CENTRE_RATIO * height)
        assert body.trunk_top[0] == pytest.approx(SHOULDER_RATIO * height)
        # The head's lowest point clears the shoulders, and it rests above the trunk.
        assert body.head[0, 2] - body.head_radius_m > body.trunk_top[0]
        assert np.hypot(*(body.head[0, :2] - body.trunk_xy[0])) < body.trunk_half_depth_m
        assert 0.08 < body.head_radius_m / height * 1.75 < 0.12
        assert body.trunk_half_width_m > body.trunk_half_depth_m
    with pytest.raises(ValueError, match="height_m"):
        silhouette(np.zeros((1, 3)), np.zeros(1), 0.0)


def test_the_carrier_interpolates_the_pose_and_keeps_each_samples_shading():
    t = np.array([0.0, 1.0, 2.0])
    carrier = Carrier(
        t=t,
        pos=np.array([[0.0, 0.0, 0.9], [1.0, 0.0, 0.9], [2.0, 0.0, 0.9]]),
        trunk_yaw=np.array([0.0, 0.5, 1.0]),
        height_m=1.7,
        shades=np.array([1.0, 1.0, 0.0]),
    )
    weight, body = carrier.shadow_at([0.5, 1.5, 2.0])
    np.testing.assert_allclose(weight, [1.0, 0.5, 0.0])
    np.testing.assert_allclose(body.trunk_xy[:, 0], [0.5, 1.5])
    np.testing.assert_allclose(body.trunk_yaw, [0.25, 0.75])
    with pytest.raises(ValueError, match="shades"):
        Carrier(t=t, pos=carrier.pos, trunk_yaw=t, height_m=1.7, shades=np.ones(2))


@pytest.fixture(scope="module")
def corridor():
    return indoorsim.load_site("han2023_corridor")


def _lux_with_and_without_the_body(site, mode) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(4)
    body = walk(site.plan, resolve_route(site, "trajectory"), WalkerParams(), rng, until_s=25.0)
    phone = carry(body, mode, np.random.default_rng(5))
    device = get_device("ideal")
    shaded = sample_sensors(site, phone, device, run_streams(1)).lux
    bare = sample_sensors(
        site, dataclasses.replace(phone, carrier=None), device, run_streams(1)
    ).lux
    return shaded, bare


def test_the_carriers_body_darkens_a_handheld_phone_and_leaves_a_phone_at_the_ear_alone(
    corridor,
):
    shaded, bare = _lux_with_and_without_the_body(corridor, "handheld")
    # The body only ever takes light away, and walking under a line of lights it
    # takes a lot at times (luminaires behind the head and trunk).
    assert (shaded <= bare + 1e-9).all()
    assert np.median(shaded) < 0.9 * np.median(bare)
    assert (shaded < 0.5 * bare).mean() > 0.05
    # At the ear the mode's exposure stands for the head: no second shadow.
    shaded, bare = _lux_with_and_without_the_body(corridor, "calling")
    np.testing.assert_array_equal(shaded, bare)


def test_the_bodys_shadow_fades_out_as_the_phone_goes_to_the_ear(corridor):
    # From the hand to the ear over 1.5 s: the shadow's weight falls with the blend,
    # so the shaded/bare ratio leaves the hand's value and reaches 1 without a jump.
    shaded, bare = _lux_with_and_without_the_body(corridor, [(0.0, "handheld"), (10.0, "calling")])
    ratio = shaded / np.maximum(bare, 1e-9)
    assert ratio[-1] == pytest.approx(1.0)
    lit = bare > 5.0
    assert np.max(np.abs(np.diff(ratio[lit]))) < 0.35
