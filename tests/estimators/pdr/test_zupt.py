"""Still-phone detection and the vertical ZUPT Kalman filter (Chen2022 Eq. 1–3)."""

from __future__ import annotations

import numpy as np
import pytest

from indoorsim.estimators.pdr.zupt import StationaryDetector, VerticalZuptEKF

G = 9.81
RATE_HZ = 100.0


def test_stationary_detector_separates_still_walking_and_turning() -> None:
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 4.0, 1.0 / RATE_HZ)
    tremor = rng.normal(0.0, 0.05, (len(t), 3))
    still_acc = np.array([0.0, 0.0, G]) + tremor
    still_gyro = rng.normal(0.0, 0.02, (len(t), 3))
    flags = StationaryDetector().update(t, still_acc, still_gyro)
    assert not flags[t < 0.49].any() and flags[t >= 0.5].all()  # a full window first
    walking = still_acc + np.outer(np.sin(2 * np.pi * 1.8 * t), [0.0, 0.0, 1.5])
    assert not StationaryDetector().update(t, walking, still_gyro).any()
    turning = still_gyro + np.array([0.0, 0.0, 0.5])
    assert not StationaryDetector().update(t, still_acc, turning).any()
    assert StationaryDetector().update(t, still_acc, None)[t >= 0.5].all()  # no gyro to see it


def test_stationary_detector_streams() -> None:
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 6.0, 1.0 / RATE_HZ)
    acc = np.array([0.0, 0.0, G]) + np.outer(np.sin(2 * np.pi * 0.5 * t) > 0, [0, 0, 1.0]) * (
        rng.normal(0.0, 1.0, (len(t), 3))
    )
    whole = StationaryDetector().update(t, acc, None)
    assert whole.any() and not whole.all()
    det = StationaryDetector()
    parts = [det.update(t[i : i + 37], acc[i : i + 37], None) for i in range(0, len(t), 37)]
    np.testing.assert_array_equal(np.concatenate(parts), whole)


def test_ekf_step_equals_the_hand_written_equations() -> None:
    ekf = VerticalZuptEKF(P0=np.diag([1e-3, 2e-3, 3e-2]))
    ekf.x[:] = [0.01, -0.02, 0.05]
    x0, P0 = ekf.x.copy(), ekf.P.copy()
    t, a = np.array([0.0, 0.02]), np.array([0.3, -0.1])
    states = ekf.filter(t, a, [False, True])
    # Prediction over Δt with the mean acceleration, then ZUPT, then level.
    dt = 0.02
    F = np.array([[1, dt, -(dt**2) / 2], [0, 1, -dt], [0, 0, 1]])
    B = np.array([dt**2 / 2, dt, 0])
    qa, qb = ekf.accel_psd, ekf.bias_psd
    Q = qa * np.array([[dt**3 / 3, dt**2 / 2, 0], [dt**2 / 2, dt, 0], [0, 0, 0]])
    Q[2, 2] = qb * dt
    x = F @ x0 + B * a.mean()
    P = F @ P0 @ F.T + Q
    for H, R in (([0.0, 1.0, 0.0], ekf.zupt_sigma_mps**2), ([1.0, 0.0, 0.0], ekf.level_psd / dt)):
        H = np.array([H])
        K = P @ H.T / (H @ P @ H.T + R)
        x = x + (K * (0.0 - H @ x)).ravel()
        P = (np.eye(3) - K @ H) @ P
    np.testing.assert_allclose(states[0], x0)  # the first sample only sets the clock
    np.testing.assert_allclose(states[1], x, rtol=1e-10)
    np.testing.assert_allclose(ekf.P, P, rtol=1e-8, atol=1e-15)


def test_zupt_holds_a_still_phone_with_a_biased_accelerometer() -> None:
    rng = np.random.default_rng(6)
    t = np.arange(0.0, 30.0, 1.0 / RATE_HZ)
    a = 0.1 + rng.normal(0.0, 0.01, len(t))  # 0.1 m/s² bias read along the vertical
    ekf = VerticalZuptEKF(level_bandwidth_hz=None)
    states = ekf.filter(t, a, np.ones(len(t), dtype=bool))
    assert np.abs(states[-100:, 1]).max() < 1e-3  # zero velocity
    assert np.abs(states[:, 0]).max() < 0.01  # bounded displacement
    assert ekf.x[2] == pytest.approx(0.1, abs=0.005)  # the bias, learned
    free = VerticalZuptEKF(level_bandwidth_hz=None).filter(t, a, np.zeros(len(t), dtype=bool))
    assert free[-1, 0] > 40.0  # ½·b·t² = 45 m without the ZUPT


# --- parameters ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("factory", "name"),
    [
        (lambda: StationaryDetector(window_s=0.0), "window_s"),
        (lambda: StationaryDetector(accel_std_mps2=-1.0), "accel_std_mps2"),
        (lambda: VerticalZuptEKF(zupt_sigma_mps=0.0), "zupt_sigma_mps"),
        (lambda: VerticalZuptEKF(level_bandwidth_hz=-0.1), "level_bandwidth_hz"),
        (lambda: VerticalZuptEKF(P0=np.eye(2)), "P0"),
    ],
)
def test_rejects_bad_parameters(factory, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        factory()
