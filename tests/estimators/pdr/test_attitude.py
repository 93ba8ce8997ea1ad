"""Chen2022 quaternion attitude: Eq. 9–12 closed forms, heading at any tilt, gyro bias."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from indoorsim.estimators.pdr.attitude import QuaternionAttitude, dcm, euler_angles

G = 9.81
RATE_HZ = 100.0


def test_dcm_and_euler_angles_match_scipy() -> None:
    rot = Rotation.random(20, random_state=2)
    q = rot.as_quat(scalar_first=True)
    np.testing.assert_allclose(dcm(q), rot.as_matrix(), atol=1e-12)
    pitch, roll, yaw = euler_angles(dcm(q))
    np.testing.assert_allclose(np.column_stack([yaw, pitch, roll]), rot.as_euler("ZYX"), atol=1e-9)


def test_quaternion_heading_of_a_constant_yaw_rate_is_rate_times_time_at_any_tilt() -> None:
    rate = 0.37  # rad/s about the vertical, for 20 s: more than a full turn
    t = np.arange(0.0, 20.0, 1.0 / RATE_HZ)
    at_ear = Rotation.from_euler("xz", [80.0, 30.0], degrees=True)  # long axis near vertical
    for tilt in [Rotation.identity(), at_ear, *Rotation.random(4, random_state=3)]:
        phone = tilt.inv()
        gyro = np.tile(phone.apply([0.0, 0.0, rate]), (len(t), 1))
        up = np.tile(phone.apply([0.0, 0.0, G]), (len(t), 1))
        q, yaw = QuaternionAttitude().update(t, gyro, up)
        np.testing.assert_allclose(yaw, rate * t, rtol=0, atol=1e-9)
        # The attitude itself is the tilt turned about the vertical.
        expected = Rotation.from_rotvec(np.outer(rate * t, [0, 0, 1])) * tilt
        q0 = Rotation.from_quat(q[0], scalar_first=True)
        got = Rotation.from_quat(q, scalar_first=True) * q0.inv() * tilt
        np.testing.assert_allclose(got.as_matrix(), expected.as_matrix(), atol=1e-9)


def test_heading_follows_another_axis_when_its_axis_turns_vertical() -> None:
    dt = 1.0 / RATE_HZ
    # Flat phone (x followed), then rolled 80° about its y axis (x nearly vertical),
    # then turned about the vertical at 0.5 rad/s.
    n1, n2 = 140, 200
    gyro = np.vstack([np.tile([0.0, 1.0, 0.0], (n1, 1)), np.zeros((1, 3))])
    tilt = Rotation.from_rotvec([0.0, 1.0 * dt * (n1 - 0.5), 0.0])
    gyro = np.vstack([gyro, np.tile(tilt.inv().apply([0.0, 0.0, 0.5]), (n2, 1))])
    t = np.arange(len(gyro)) * dt
    up = np.tile([0.0, 0.0, G], (len(t), 1))
    _, yaw = QuaternionAttitude(tilt_time_constant_s=None).update(t, gyro, up)
    np.testing.assert_allclose(yaw[: n1 + 1], 0.0, atol=1e-12)  # rolling is no turn
    np.testing.assert_allclose(np.diff(yaw[n1 + 2 :]), 0.5 * dt, atol=1e-12)


def test_gyro_bias_is_learned_while_still_and_removed() -> None:
    bias = np.array([0.01, -0.02, 0.03])
    t = np.arange(0.0, 15.0, 1.0 / RATE_HZ)
    moving = t >= 5.0
    gyro = bias + np.where(moving[:, None], [0.0, 0.0, 0.3], 0.0)
    up = np.tile([0.0, 0.0, G], (len(t), 1))
    learned = QuaternionAttitude()
    _, yaw = learned.update(t, gyro, up, stationary=~moving)
    np.testing.assert_allclose(learned.bias, bias, atol=1e-12)
    turn = yaw[-1] - yaw[np.argmax(moving) - 1]
    assert turn == pytest.approx(0.3 * 10.0, abs=2e-3)
    _, raw = QuaternionAttitude(gyro_bias_time_constant_s=None).update(t, gyro, up, ~moving)
    assert raw[-1] - raw[np.argmax(moving) - 1] > 0.3 * 10.0 + 0.25  # the bias turns it


def test_streaming_in_pieces_equals_one_call() -> None:
    rng = np.random.default_rng(8)
    t = np.arange(0.0, 12.0, 1.0 / RATE_HZ)
    gyro = np.where((t > 4.0)[:, None], rng.normal(0.0, 0.4, (len(t), 3)), 0.002)
    up = np.tile([0.5, 1.0, G], (len(t), 1)) + rng.normal(0.0, 0.1, (len(t), 3))
    still = t < 4.0
    whole = QuaternionAttitude(gyro_bias_guard_s=0.5)
    q, yaw = whole.update(t, gyro, up, still)
    parts = QuaternionAttitude(gyro_bias_guard_s=0.5)
    pieces = [
        parts.update(t[sl], gyro[sl], up[sl], still[sl])
        for sl in (slice(i, i + 37) for i in range(0, len(t), 37))
    ]
    np.testing.assert_array_equal(np.concatenate([p[0] for p in pieces]), q)
    np.testing.assert_array_equal(np.concatenate([p[1] for p in pieces]), yaw)
    np.testing.assert_array_equal(parts.bias, whole.bias)


def test_a_full_bias_queue_uses_its_oldest_samples_early() -> None:
    # A guard longer than the queue (4096 samples at 100 Hz is 41 s): the bias
    # is learned all the same, from the samples pushed out of the full queue.
    bias = np.array([0.01, -0.02, 0.03])
    t = np.arange(0.0, 60.0, 1.0 / RATE_HZ)
    up = np.tile([0.0, 0.0, G], (len(t), 1))
    att = QuaternionAttitude(gyro_bias_guard_s=100.0)
    att.update(t, np.tile(bias, (len(t), 1)), up, np.ones(len(t), dtype=bool))
    np.testing.assert_allclose(att.bias, bias, atol=1e-12)
    fresh = QuaternionAttitude(gyro_bias_guard_s=100.0)
    fresh.update(t[:4000], np.tile(bias, (4000, 1)), up[:4000], np.ones(4000, dtype=bool))
    np.testing.assert_array_equal(fresh.bias, 0.0)  # all still waiting for the guard


# --- parameters ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("factory", "name"),
    [
        (lambda: QuaternionAttitude(tilt_time_constant_s=0.0), "tilt_time_constant_s"),
        (lambda: QuaternionAttitude(gyro_bias_guard_s=-1.0), "gyro_bias_guard_s"),
    ],
)
def test_rejects_bad_parameters(factory, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        factory()
