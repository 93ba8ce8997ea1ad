"""The along-path field statistics, on series and walks with closed-form answers."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.magnetic import (
    GRID_M,
    MIN_PATH_M,
    along_path,
    band_std,
    correlation_length,
    field_statistics,
    hard_iron_residual,
    magnetic_statistics,
)
from indoorsim.io.recording import Recording
from indoorsim.util import quaternion


def _cosines(length_m: float, parts: dict[float, float]) -> tuple[np.ndarray, np.ndarray]:
    # Even about the walk's middle, so a straight line fitted to them is flat.
    s = np.arange(0.0, length_m, GRID_M)
    mid = 0.5 * s[-1]
    return s, sum(
        amp * np.cos(2 * np.pi * (s - mid) / wavelength) for wavelength, amp in parts.items()
    )


def test_each_band_holds_the_cosines_whose_wavelength_lies_in_it():
    # Whole periods of 20 m, 5 m and 1 m on a 200 m walk: a cosine of amplitude A has std A/√2.
    s, v = _cosines(200.0, {20.0: 3.0, 5.0: 2.0, 1.0: 0.5})
    stats = field_statistics(s, v)
    assert stats["std_long"] == pytest.approx(3.0 / math.sqrt(2), rel=1e-9)
    assert stats["std_mid"] == pytest.approx(2.0 / math.sqrt(2), rel=1e-9)
    assert stats["std_short"] == pytest.approx(0.5 / math.sqrt(2), rel=1e-9)
    assert stats["share_long"] == pytest.approx(9.0 / (9.0 + 4.0 + 0.25), rel=1e-9)
    # Parseval: the bands of a partition add up to the whole variance.
    total = sum(band_std(v, GRID_M, lo, hi) ** 2 for lo, hi in [(0.2, 0.5), (0.5, 2), (2, 10)])
    assert total + band_std(v, GRID_M, 10.0, math.inf) ** 2 == pytest.approx(np.var(v))


def test_a_linear_trend_is_not_an_anomaly():
    s, v = _cosines(100.0, {10.0 / 3: 2.0})
    stats = field_statistics(s, v + 45.0 + 0.05 * s)
    assert stats["mag_std"] == pytest.approx(2.0 / math.sqrt(2), rel=1e-9)
    assert stats["std_long"] == pytest.approx(0.0, abs=1e-9)


def test_correlation_length_of_a_cosine_and_of_an_exponential_process():
    # A cosine's autocorrelation is cos(2πd/λ): it falls to 1/e at d = λ·acos(1/e)/(2π).
    _, v = _cosines(2000.0, {8.0: 1.0})
    expected = 8.0 * math.acos(math.exp(-1.0)) / (2 * math.pi)
    assert correlation_length(v, GRID_M) == pytest.approx(expected, rel=0.01)
    # A first-order Gauss–Markov series with correlation exp(−d/L) falls to 1/e at L.
    rng = np.random.default_rng(0)
    length, n = 3.0, 200_000
    phi = math.exp(-GRID_M / length)
    noise = rng.standard_normal(n) * math.sqrt(1 - phi**2)
    x = np.empty(n)
    x[0] = rng.standard_normal()
    for i in range(1, n):
        x[i] = phi * x[i - 1] + noise[i]
    assert correlation_length(x, GRID_M) == pytest.approx(length, rel=0.05)


def test_standing_still_adds_no_distance():
    # 10 s walking 1 m/s along x, 10 s standing, 20 s on: the field seen is f(x) either way.
    t = np.arange(0.0, 40.0, 0.02)
    x = np.interp(t, [0, 10, 20, 40], [0, 10, 10, 30])
    field = 50.0 + np.sin(x)
    s, v = along_path(t, field, t, np.column_stack([x, np.zeros_like(x)]))
    assert s[-1] == pytest.approx(30.0 - GRID_M, abs=1e-9)
    np.testing.assert_allclose(v, 50.0 + np.sin(s), atol=1e-3)


def test_a_walk_below_the_shortest_path_is_not_measured():
    s, v = _cosines(MIN_PATH_M - 1.0, {5.0: 1.0})
    stats = field_statistics(s, v)
    assert stats["path_m"] == pytest.approx(MIN_PATH_M - 1.0, abs=GRID_M)
    assert math.isnan(stats["share_long"]) and math.isnan(stats["corr_length"])


def test_magnetic_statistics_reads_a_recording_with_waypoints():
    # A 60 m straight walk at 1.2 m/s past a field whose ‖m‖ varies as 4·cos(2πx/20) µT,
    # logged in an arbitrary phone frame: only ‖m‖ counts.
    t = np.arange(0.0, 50.0, 0.02)
    x = 1.2 * t
    norm = 48.0 + 4.0 * np.cos(2 * np.pi * x / 20.0)
    mag = pd.DataFrame(
        {"x": 0.6 * norm, "y": 0.0 * norm, "z": -0.8 * norm}, index=pd.Index(t, name="t")
    )
    waypoints = pd.DataFrame(
        {"x": [0.0, 60.0], "y": [5.0, 5.0]}, index=pd.Index([0.0, 50.0], name="t")
    )
    rec = Recording(streams={"mag": mag, "waypoints": waypoints}, meta={})
    stats = magnetic_statistics(rec)
    assert stats["path_m"] == pytest.approx(60.0, abs=GRID_M)
    assert stats["std_long"] == pytest.approx(4.0 / math.sqrt(2), rel=0.01)
    assert stats["share_long"] == pytest.approx(1.0, abs=0.01)
    no_mag = Recording(streams={"waypoints": waypoints}, meta={})
    assert all(math.isnan(v) for v in magnetic_statistics(no_mag).values())


_EARTH_ENU = np.array([-3.8, 33.4, -35.3])  # µT, Hangzhou's field in Android's world frame
_OFFSET = np.array([8.0, -5.0, 3.0])


def _turning_phone(turn_deg: float, pitch_deg: float, offset=_OFFSET) -> Recording:
    """A phone at a fixed tilt, turned steadily through ``turn_deg`` in a uniform field,
    its magnetometer reading R(q)ᵀ·B + offset."""
    t = np.arange(0.0, 60.0, 0.02)
    yaw = np.radians(turn_deg) * t / t[-1]
    half = np.radians(pitch_deg) / 2
    tilt = np.array([math.cos(half), math.sin(half), 0.0, 0.0])
    turn = np.column_stack([np.cos(yaw / 2), 0 * yaw, 0 * yaw, np.sin(yaw / 2)])
    q = quaternion.multiply(turn, tilt)
    m = quaternion.rotate(q, np.tile(_EARTH_ENU, (len(t), 1)), inverse=True) + offset
    index = pd.Index(t, name="t")
    streams = {
        "mag": pd.DataFrame(m, columns=["x", "y", "z"], index=index),
        "rotation": pd.DataFrame(q, columns=["w", "x", "y", "z"], index=index),
    }
    return Recording._from_built(streams, {})


def test_a_flat_phone_turning_gives_back_its_offset_and_a_steady_field():
    fit = hard_iron_residual(_turning_phone(400.0, 0.0))
    # Held level, the offset's z cannot be told from the vertical field: taken as 0.
    np.testing.assert_allclose(fit.offset_uT, [8.0, -5.0, 0.0], atol=1e-9)
    assert fit.horizontal_uT == pytest.approx(math.hypot(8.0, -5.0))
    assert fit.radius_uT == pytest.approx(math.hypot(-3.8, 33.4))
    assert fit.arc_deg > 359.0 and fit.spread_uT < 1e-9
    # Without its horizontal offset, ‖m‖ no longer swings with the heading.
    flat = _turning_phone(400.0, 0.0, offset=np.array([8.0, -5.0, 0.0]))
    values = flat.mag.to_numpy() - hard_iron_residual(flat).offset_uT
    assert np.ptp(np.linalg.norm(values, axis=1)) < 1e-9
    assert np.ptp(np.linalg.norm(flat.mag.to_numpy(), axis=1)) > 10.0


def test_a_tilted_phone_gives_back_the_offset_it_shows_at_its_tilt():
    """At 30° of pitch what turns with the phone is the offset's part square to the
    phone-frame vertical û: h − (h·û)·û."""
    fit = hard_iron_residual(_turning_phone(200.0, 30.0))
    tilt = np.array([math.cos(math.radians(15.0)), math.sin(math.radians(15.0)), 0.0, 0.0])
    up = quaternion.rotate(tilt, [0.0, 0.0, 1.0], inverse=True)
    expected = _OFFSET - (_OFFSET @ up) * up
    np.testing.assert_allclose(fit.offset_uT, expected, atol=1e-9)


def test_an_offset_is_not_fitted_from_too_little_turning_or_a_tumbling_phone():
    assert hard_iron_residual(_turning_phone(120.0, 0.0)) is None
    assert hard_iron_residual(Recording._from_built({}, {})) is None
    # A phone tumbling about its own axes (a pocket's thigh swing, exaggerated) does not
    # trace one circle: its samples fill a sphere, and no offset is claimed.
    rng = np.random.default_rng(0)
    q = quaternion.normalise(rng.normal(size=(3000, 4)))
    m = quaternion.rotate(q, np.tile(_EARTH_ENU, (3000, 1)), inverse=True) + _OFFSET
    index = pd.Index(np.arange(3000) * 0.02, name="t")
    tumbling = Recording._from_built(
        {"mag": pd.DataFrame(m, columns=["x", "y", "z"], index=index)}, {}
    )
    assert hard_iron_residual(tumbling) is None
