"""Observation windows: shapes, sample-and-hold alignment, WiFi vectors, padding, no truth."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from indoorsim.io.recording import Recording
from indoorsim.windows import MAX_AGE_S, NO_SIGNAL_DBM, Windower, observation_space


def _frame(t, **cols):
    return pd.DataFrame(cols, index=pd.Index(np.asarray(t, float), name="t"))


@pytest.fixture
def rec() -> Recording:
    t = np.arange(0.0, 2.5, 0.1)  # 25 IMU samples at 10 Hz
    n = len(t)
    tm = np.arange(0.05, 2.5, 0.25)  # slower magnetometer
    wifi = _frame(
        [0.7, 0.7, 1.9],
        bssid=["aa:00:00:00:00:01", "aa:00:00:00:00:09", "aa:00:00:00:00:02"],
        rss=[-60.0, -70.0, -75.0],
    )
    return Recording(
        streams={
            "accel": _frame(t, x=np.arange(n, dtype=float), y=np.zeros(n), z=np.full(n, 9.8)),
            "gyro": _frame(t, x=np.zeros(n), y=np.zeros(n), z=np.full(n, 0.1)),
            "mag": _frame(
                tm, x=np.arange(len(tm), dtype=float), y=np.ones(len(tm)), z=np.zeros(len(tm))
            ),
            "wifi": wifi,
            "truth": _frame(
                t,
                x=t,
                y=t,
                z=t,
                qw=np.ones(n),
                qx=0 * t,
                qy=0 * t,
                qz=0 * t,
                body_x=t,
                body_y=t,
                heading=0 * t,
                mode=["handheld"] * n,
            ),
        }
    )


BSSIDS = ("aa:00:00:00:00:01", "aa:00:00:00:00:02")


def test_windows_have_the_declared_space(rec):
    w = Windower(rec, 10, BSSIDS)
    space = observation_space(10, len(BSSIDS))
    assert len(w) == 3
    for obs in w:
        assert set(obs) == set(space.spaces)
        for key, sub in space.spaces.items():
            assert obs[key].shape == sub.shape, key


def test_sample_and_hold_and_fresh_masks(rec):
    obs = Windower(rec, 10, BSSIDS).window(0)
    np.testing.assert_allclose(obs["t"], np.arange(0, 1.0, 0.1))
    np.testing.assert_allclose(obs["accel"][:, 0], np.arange(10))
    # Magnetometer samples at 0.05, 0.30, 0.55, 0.80 s, held until the next one;
    # before the first (t = 0) nothing is known yet: zeros.
    np.testing.assert_allclose(obs["mag"][:, 0], [0, 0, 0, 1, 1, 1, 2, 2, 3, 3])
    np.testing.assert_allclose(obs["mag"][0], [0, 0, 0])
    np.testing.assert_array_equal(obs["mag_fresh"], [0, 1, 0, 1, 0, 0, 1, 0, 1, 0])
    # Streams the recording lacks are zeros, never fresh, and marked absent.
    assert not obs["light_fresh"].any() and (obs["rotation"][:, 0] == 1).all()
    np.testing.assert_array_equal(obs["present"], [1, 1, 0, 0, 1, 0, 0])


def test_wifi_vector_is_the_latest_scan_over_the_site_aps(rec):
    w = Windower(rec, 5, BSSIDS)  # windows end at 0.4, 0.9, 1.4, 1.9, 2.4 s
    first, second, fourth, fifth = w.window(0), w.window(1), w.window(3), w.window(4)
    np.testing.assert_allclose(first["wifi_rss"], [NO_SIGNAL_DBM, NO_SIGNAL_DBM])
    assert first["wifi_age"][0] == MAX_AGE_S and first["wifi_fresh"][0] == 0
    np.testing.assert_allclose(
        second["wifi_rss"], [-60.0, NO_SIGNAL_DBM]
    )  # the unknown AP is ignored
    np.testing.assert_array_equal(second["wifi_heard"], [1, 0])
    assert second["wifi_fresh"][0] == 1 and second["wifi_age"][0] == pytest.approx(0.2)
    np.testing.assert_allclose(fourth["wifi_rss"], [NO_SIGNAL_DBM, -75.0])
    assert fourth["wifi_fresh"][0] == 1
    assert fifth["wifi_fresh"][0] == 0 and fifth["wifi_age"][0] == pytest.approx(0.5)


def test_last_window_is_padded_and_marked(rec):
    w = Windower(rec, 10, BSSIDS)
    last = w.window(2)
    np.testing.assert_array_equal(last["valid"], [1] * 5 + [0] * 5)
    np.testing.assert_allclose(last["t"][5:], last["t"][4])
    assert w.end_time(2) == pytest.approx(2.4)
    with pytest.raises(IndexError, match="out of range"):
        w.window(3)


def test_windows_never_carry_truth(rec):
    obs = Windower(rec, 10, BSSIDS).window(1)
    assert not {"truth", "x", "y", "heading", "steps"} & set(obs)


def test_a_recording_needs_accelerometer_samples(rec):
    with pytest.raises(ValueError, match="needs an 'accel' stream"):
        Windower(Recording(streams={"gyro": rec.gyro}), 10, BSSIDS)
