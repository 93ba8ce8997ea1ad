"""Ideal IMU: closed-form motions give their closed-form specific force and rate."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from indoorsim.phone.kinematics import IdealImu, normal_gravity


def test_still_phone_reads_gravity_and_zero_rate():
    t = np.arange(0, 5, 0.005)
    q = Rotation.from_euler("zyx", [40, 15, -20], degrees=True)
    imu = IdealImu(
        t, np.tile([1.0, 2.0, 1.2], (len(t), 1)), np.tile(q.as_quat(scalar_first=True), (len(t), 1))
    )
    ts = np.linspace(0.1, 4.9, 97)
    np.testing.assert_allclose(
        imu.specific_force(ts), q.inv().apply(np.tile([0, 0, 9.80665], (97, 1))), atol=1e-12
    )
    np.testing.assert_allclose(imu.angular_rate(ts), 0.0, atol=1e-12)
    flat = IdealImu(t, np.zeros((len(t), 3)), np.tile([1.0, 0, 0, 0], (len(t), 1)))
    np.testing.assert_allclose(
        flat.specific_force(ts), np.tile([0, 0, 9.80665], (97, 1)), atol=1e-12
    )


def test_circular_motion_gives_centripetal_force_and_constant_yaw_rate():
    # Phone flat, moving on a circle of radius r at rate w and yawing with it.
    r, w = 2.0, 0.8
    t = np.arange(0, 20, 0.005)
    pos = np.column_stack([r * np.cos(w * t), r * np.sin(w * t), np.full(len(t), 1.2)])
    quat = Rotation.from_rotvec(np.outer(w * t + np.pi, [0, 0, 1])).as_quat(scalar_first=True)
    imu = IdealImu(t, pos, quat)
    ts = np.linspace(1, 19, 200)
    # The horizontal specific force is the centripetal r·w², whatever the phone's yaw.
    f = imu.specific_force(ts)
    np.testing.assert_allclose(np.linalg.norm(f[:, :2], axis=1), r * w**2, rtol=1e-5)
    np.testing.assert_allclose(f[:, 2], 9.80665, atol=1e-6)
    np.testing.assert_allclose(imu.angular_rate(ts), np.tile([0, 0, w], (200, 1)), atol=1e-9)


def test_integrating_the_rate_recovers_the_attitude():
    t = np.arange(0, 60, 0.005)
    rotvec = np.column_stack([0.3 * np.sin(1.9 * t), 0.2 * np.cos(0.9 * t), 0.4 * t])
    rots = Rotation.from_rotvec(rotvec)
    imu = IdealImu(t, np.zeros((len(t), 3)), rots.as_quat(scalar_first=True))
    ts = np.arange(0, 59.99, 0.01)
    rate = imu.angular_rate(ts)
    q = rots[0]
    for k in range(len(ts) - 1):  # midpoint rule on the 100 Hz gyro
        q = q * Rotation.from_rotvec(0.5 * (rate[k] + rate[k + 1]) * (ts[k + 1] - ts[k]))
    assert np.degrees((q.inv() * imu.attitude([ts[-1]])[0]).magnitude()) < 0.1


def test_queries_outside_the_trajectory_are_refused():
    t = np.arange(0, 1, 0.01)
    imu = IdealImu(t, np.zeros((len(t), 3)), np.tile([1.0, 0, 0, 0], (len(t), 1)))
    with pytest.raises(ValueError, match="leave the trajectory"):
        imu.specific_force([2.0])


def test_normal_gravity_at_equator_and_pole():
    assert normal_gravity(0.0) == pytest.approx(9.7803253359)
    assert normal_gravity(90.0) == pytest.approx(9.8321849378, abs=1e-8)


def test_compiled_attitude_kernels_match_the_quaternion_helpers():
    from indoorsim.util import quaternion as quat_ops

    rng = np.random.default_rng(6)
    t = np.cumsum(rng.uniform(0.004, 0.006, 3000))
    q = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.05, (3000, 3)), axis=0)).as_quat(
        scalar_first=True
    )
    q[::7] *= -1  # sign flips, which the trajectory makes continuous
    imu = IdealImu(t, rng.normal(size=(3000, 3)), q)
    ts = np.sort(rng.uniform(t[0], t[-1], 5000))
    ref_q = quat_ops.slerp(t, imu._quat, ts)
    np.testing.assert_allclose(imu.quaternion(ts), ref_q, atol=1e-15)
    v = rng.normal(size=(5000, 3))
    np.testing.assert_allclose(imu.to_world_frame(ts, v), quat_ops.rotate(ref_q, v), atol=1e-14)
    np.testing.assert_allclose(
        imu.to_phone_frame(ts, v), quat_ops.rotate(quat_ops.conjugate(ref_q), v), atol=1e-14
    )
    rate = quat_ops.relative_rotvec(imu._quat[:-1], imu._quat[1:]) / np.diff(t)[:, None]
    np.testing.assert_allclose(imu.angular_rate(imu._t_mid), rate, atol=1e-12)
