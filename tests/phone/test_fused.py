"""Fused sensors: the attitude filter tracks ideal streams and errs as a phone does."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from indoorsim.phone.fused import fuse

G = 9.80665
B_EARTH = np.array([0.0, 30.0, -40.0])  # magnetic-ENU frame: no east component


def _streams(rots: Rotation, field_w: np.ndarray = B_EARTH, accel_w: np.ndarray | None = None):
    acc_w = np.array([0.0, 0.0, G]) if accel_w is None else accel_w + np.array([0.0, 0.0, G])
    return rots.inv().apply(acc_w), rots.inv().apply(field_w)


def _angle_deg(a: Rotation, b: Rotation) -> np.ndarray:
    return np.degrees((a.inv() * b).magnitude())


def _tilt_deg(q: np.ndarray, rots: Rotation) -> np.ndarray:
    up_est = Rotation.from_quat(q, scalar_first=True).inv().apply([0, 0, 1])
    up_true = rots.inv().apply([0, 0, 1])
    return np.degrees(np.arccos(np.clip((up_est * up_true).sum(1), -1, 1)))


def test_still_phone_gets_its_attitude_from_gravity_and_north():
    t = np.arange(0, 5, 0.01)
    truth = Rotation.from_euler("zyx", [123, 20, -35], degrees=True)
    rots = Rotation.concatenate([truth] * len(t))
    acc, mag = _streams(rots)
    f = fuse(t, acc, t, np.zeros((len(t), 3)), t, mag)
    assert _angle_deg(Rotation.from_quat(f.rotation, scalar_first=True), rots).max() < 1e-4
    np.testing.assert_allclose(np.linalg.norm(f.rotation, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(f.gravity, acc, atol=1e-5)
    np.testing.assert_allclose(f.linear_accel, 0.0, atol=1e-5)


def test_rotating_phone_with_ideal_sensors_is_tracked():
    t = np.arange(0, 60, 0.01)
    w_body = np.array([0.3, -0.5, 1.2])
    rots = Rotation.from_euler("zyx", [30, 10, -5], degrees=True) * Rotation.from_rotvec(
        np.outer(t, w_body)
    )
    acc, mag = _streams(rots)
    f = fuse(t, acc, t, np.tile(w_body, (len(t), 1)), t, mag)
    assert _angle_deg(Rotation.from_quat(f.rotation, scalar_first=True), rots).max() < 0.05
    assert _tilt_deg(f.game_rotation, rots).max() < 0.05


def test_magnetic_disturbance_pulls_the_rotation_vector_but_not_the_game_rotation():
    t = np.arange(0, 30, 0.01)
    rots = Rotation.from_rotvec(np.outer(t, [0, 0, 0.2]))  # turning slowly, flat
    acc, _ = _streams(rots)
    # A steel source adds a 15 µT eastward field between 10 s and 20 s.
    field = np.tile(B_EARTH, (len(t), 1))
    field[(t > 10) & (t < 20), 0] += 15.0
    mag = rots.inv().apply(field)
    f = fuse(t, acc, t, np.tile([0, 0, 0.2], (len(t), 1)), t, mag)
    err9 = _angle_deg(Rotation.from_quat(f.rotation, scalar_first=True), rots)
    game = Rotation.from_quat(f.game_rotation, scalar_first=True)
    assert err9[(t > 15) & (t < 20)].max() > 5.0  # heading pulled toward the disturbed field
    assert err9[t < 10].max() < 0.05
    assert _angle_deg(game, rots).max() < 0.05  # gyro + gravity only: undisturbed


def test_fields_outside_the_valid_range_are_ignored():
    t = np.arange(0, 10, 0.01)
    rots = Rotation.from_rotvec(np.outer(t, [0, 0, 0.3]))
    acc, mag = _streams(rots)
    strong = mag.copy()
    strong[200:] *= 4.0  # 200 µT: rejected, so the gyro carries the heading
    f = fuse(t, acc, t, np.tile([0, 0, 0.3], (len(t), 1)), t, strong)
    assert _angle_deg(Rotation.from_quat(f.rotation, scalar_first=True), rots).max() < 0.05


def test_accelerations_are_down_weighted_and_separated_as_linear_acceleration():
    t = np.arange(0, 20, 0.01)
    rots = Rotation.from_euler("x", np.full((len(t), 1), 10.0), degrees=True)
    lin_w = np.column_stack(
        [2.0 * np.sin(2 * np.pi * 1.8 * t), np.zeros(len(t)), 3.0 * np.sin(2 * np.pi * 1.8 * t)]
    )
    acc, mag = _streams(rots, accel_w=lin_w)
    f = fuse(t, acc, t, np.zeros((len(t), 3)), t, mag)
    assert _tilt_deg(f.game_rotation, rots).max() < 1.0
    lin_b = rots.inv().apply(lin_w)
    assert np.abs(f.linear_accel - lin_b)[200:].max() < 0.2


def test_outputs_follow_each_streams_own_timestamps():
    t_acc, t_gyro, t_mag = (
        np.arange(0, 3, 0.01),
        np.arange(0.003, 3, 0.005),
        np.arange(0.001, 3, 0.02),
    )
    rot_at = lambda tt: Rotation.from_rotvec(np.outer(tt, [0.1, 0.2, 0.3]))  # noqa: E731
    acc, _ = _streams(rot_at(t_acc))
    _, mag = _streams(rot_at(t_mag))
    f = fuse(t_acc, acc, t_gyro, np.tile([0.1, 0.2, 0.3], (len(t_gyro), 1)), t_mag, mag)
    assert f.rotation.shape == (len(t_gyro), 4) and f.gravity.shape == (len(t_acc), 3)
    assert (
        _angle_deg(Rotation.from_quat(f.rotation, scalar_first=True), rot_at(t_gyro))[10:].max()
        < 0.1
    )


def test_streams_out_of_time_order_give_the_same_samples_in_their_own_order():
    t = np.arange(0, 3, 0.01)
    rots = Rotation.from_rotvec(np.outer(t, [0.1, 0.2, 0.3]))
    acc, mag = _streams(rots)
    gyro = np.tile([0.1, 0.2, 0.3], (len(t), 1))
    t_mag = t + 0.004  # interleaved with, and ties between, the other streams
    ref = fuse(t, acc, t, gyro, t_mag, mag)
    rng = np.random.default_rng(0)
    pa, pg, pm = (rng.permutation(len(t)) for _ in range(3))
    f = fuse(t[pa], acc[pa], t[pg], gyro[pg], t_mag[pm], mag[pm])
    np.testing.assert_array_equal(f.rotation, ref.rotation[pg])
    np.testing.assert_array_equal(f.game_rotation, ref.game_rotation[pg])
    np.testing.assert_array_equal(f.gyro_bias, ref.gyro_bias[pg])
    np.testing.assert_array_equal(f.gravity, ref.gravity[pa])
    np.testing.assert_array_equal(f.linear_accel, ref.linear_accel[pa])


def test_missing_stream_is_a_clear_error():
    t = np.arange(0, 1, 0.01)
    with pytest.raises(ValueError, match="the mag stream is empty"):
        fuse(
            t,
            np.tile([0, 0, G], (len(t), 1)),
            t,
            np.zeros((len(t), 3)),
            np.zeros(0),
            np.zeros((0, 3)),
        )
