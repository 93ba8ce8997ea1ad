"""SampleGuard: a sample that is not a number is a sample the phone did not deliver."""

from __future__ import annotations

import numpy as np

from indoorsim.estimators.samples import SampleGuard
from indoorsim.windows import NO_SIGNAL_DBM, observation_space


def _window(t0: float = 0.0, w: int = 5, aps: int = 3) -> dict[str, np.ndarray]:
    obs = {k: np.zeros(v.shape) for k, v in observation_space(w, aps).spaces.items()}
    obs["t"] = t0 + 0.02 * np.arange(w)
    obs["valid"][:] = 1
    obs["accel"][:] = (0.0, 0.0, 9.81)
    obs["gyro"][:] = (0.0, 0.0, 0.1)
    obs["mag"][:] = np.arange(w)[:, None] + np.array([20.0, 0.0, -40.0])
    obs["mag_fresh"][:] = 1
    obs["rotation"][:] = obs["game_rotation"][:] = (0.0, 0.0, 0.0, 1.0)
    obs["gravity"][:] = (0.0, 0.0, 9.81)
    obs["light"][:] = 300.0
    obs["wifi_rss"][:] = (-60.0, -70.0, -80.0)
    obs["wifi_heard"][:] = 1
    return obs


def test_a_clean_window_is_returned_as_it_is():
    obs = _window()
    assert SampleGuard()(obs) is obs


def test_an_imu_row_with_nan_is_a_lost_sample_and_the_input_is_untouched():
    obs = _window()
    obs["gyro"][1, 2] = np.nan
    obs["accel"][3] = np.inf
    out = SampleGuard()(obs)
    assert out["valid"].tolist() == [1, 0, 1, 0, 1]
    assert np.isfinite(out["accel"]).all() and np.isfinite(out["gyro"]).all()
    # The good rows are exactly the phone's; the caller's window keeps its NaN.
    np.testing.assert_array_equal(out["accel"][[0, 2, 4]], obs["accel"][[0, 2, 4]])
    assert np.isnan(obs["gyro"][1, 2]) and obs["valid"].all()


def test_held_streams_hold_their_last_finite_sample_across_windows():
    guard = SampleGuard()
    first = _window()
    guard(first)
    second = _window(t0=0.1)
    second["mag"][:2] = np.nan
    second["light"][0] = np.nan
    second["rotation"][1:] = np.nan
    out = guard(second)
    # The first two mag samples hold the previous window's last one, and are not fresh.
    np.testing.assert_array_equal(out["mag"][:2], np.repeat(first["mag"][-1:], 2, axis=0))
    assert out["mag_fresh"].tolist() == [0, 0, 1, 1, 1]
    np.testing.assert_array_equal(out["mag"][2:], second["mag"][2:])
    assert out["light"][0] == 300.0 and out["light_fresh"][0] == 0
    np.testing.assert_array_equal(out["rotation"][1:], np.repeat(second["rotation"][:1], 4, 0))


def test_before_any_good_sample_the_rotation_is_the_identity_and_gravity_zero():
    obs = _window()
    obs["rotation"][:] = np.nan
    obs["gravity"][:] = np.nan
    out = SampleGuard()(obs)
    np.testing.assert_array_equal(out["rotation"], np.tile([1.0, 0.0, 0.0, 0.0], (5, 1)))
    np.testing.assert_array_equal(out["gravity"], np.zeros((5, 3)))


def test_reset_forgets_the_held_samples():
    guard = SampleGuard()
    guard(_window())
    guard.reset()
    obs = _window()
    obs["mag"][:] = np.nan
    np.testing.assert_array_equal(guard(obs)["mag"], np.zeros((5, 3)))


def test_a_nan_rss_is_an_ap_not_heard():
    obs = _window()
    obs["wifi_rss"][1] = np.nan
    out = SampleGuard()(obs)
    assert out["wifi_rss"].tolist() == [-60.0, NO_SIGNAL_DBM, -80.0]
    assert out["wifi_heard"].tolist() == [1, 0, 1]


def test_a_window_without_some_keys_is_guarded_on_those_it_has():
    obs = {k: v for k, v in _window().items() if k not in ("light", "wifi_rss", "gravity")}
    obs["mag"][0] = np.nan
    out = SampleGuard()(obs)
    assert out.keys() == obs.keys() and out["mag_fresh"][0] == 0
