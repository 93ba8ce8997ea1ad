"""Sensor-model throughput for one hour of a walk, and the Gauss–Markov generator against a loop.

Prints samples per second for each sensor model of the ``high_grade`` profile
(the fastest rates) over one hour, then times the first-order Gauss–Markov
recursion b[n] = φ·b[n−1] + g·ξ[n] as ``scipy.signal.lfilter`` runs it (what
:func:`indoorsim.phone.sensors.apply_inertial` uses) and as the textbook
per-sample Python loop, on the same ξ: their speed ratio and largest difference.

Run: ``python benchmarks/bench_sensors.py``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np
from scipy.signal import lfilter

from indoorsim.phone.devices import get_device
from indoorsim.phone.sensors import (
    apply_inertial,
    apply_magnetometer,
    light_events,
    sample_times,
    scan_rss,
    wifi_scans,
)

DURATION_S, REPEATS = 3600.0, 3


def best_time(fn: Callable[[], object]) -> tuple[float, object]:
    best, result = math.inf, None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def gauss_markov_loop(xi: np.ndarray, phi: float, gain: float, b0: np.ndarray) -> np.ndarray:
    """Reference: the recursion one sample at a time."""
    out = np.empty_like(xi)
    b = b0
    for n in range(xi.shape[0]):
        b = phi * b + gain * xi[n]
        out[n] = b
    return out


def main() -> None:
    device = get_device("high_grade")
    rng = np.random.default_rng(0)
    print(f"{device.name}, {DURATION_S:.0f} s of data per model")

    t = sample_times(
        DURATION_S,
        device.gyro.rate_hz,
        device.timestamp_jitter_frac,
        rng,
        gap_probability=device.gap_probability,
    )
    rate = np.tile([0.1, -0.2, 0.05], (t.size, 1))
    seconds, _ = best_time(lambda: apply_inertial(rate, t, device.gyro, rng))
    print(f"apply_inertial     {t.size:>9} samples  {t.size / seconds:>12.3g} samples/s")

    t_mag = sample_times(DURATION_S, device.mag.rate_hz, device.timestamp_jitter_frac, rng)
    field = np.tile([20.0, 30.0, -40.0], (t_mag.size, 1))
    seconds, _ = best_time(lambda: apply_magnetometer(field, t_mag, device.mag, rng))
    print(f"apply_magnetometer {t_mag.size:>9} samples  {t_mag.size / seconds:>12.3g} samples/s")

    t_fine = np.arange(0.0, DURATION_S, 0.005)
    lux = 250.0 + 150.0 * np.sin(2 * np.pi * 0.9 * t_fine)
    seconds, _ = best_time(lambda: light_events(t_fine, lux, device.light, rng))
    print(f"light_events       {t_fine.size:>9} samples  {t_fine.size / seconds:>12.3g} samples/s")

    scans = wifi_scans(DURATION_S, device.wifi, rng)
    mean = rng.uniform(-100.0, -40.0, (scans.size, 200))
    bssids = [f"02:00:00:00:{i // 256:02x}:{i % 256:02x}" for i in range(200)]
    seconds, _ = best_time(lambda: scan_rss(scans, mean, bssids, device.wifi, rng))
    print(f"scan_rss           {mean.size:>9} AP-scans {mean.size / seconds:>12.3g} AP-scans/s")

    n = t.size
    phi = math.exp(-1.0 / (device.gyro.rate_hz * device.gyro.bias_correlation_s))
    gain = math.sqrt(1.0 - phi**2)
    xi = rng.standard_normal((n, 3))
    b0 = rng.standard_normal(3)
    fast, ours = best_time(lambda: lfilter([gain], [1.0, -phi], xi, axis=0, zi=phi * b0[None])[0])
    slow, reference = best_time(lambda: gauss_markov_loop(xi, phi, gain, b0))
    print(
        f"Gauss-Markov, {n} steps x 3 axes: lfilter {fast * 1e3:.1f} ms, loop {slow * 1e3:.0f} ms, "
        f"ratio {slow / fast:.0f}x, max |difference| {np.max(np.abs(ours - reference)):.1e}"
    )


if __name__ == "__main__":
    main()
