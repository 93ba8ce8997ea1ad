"""End-to-end simulation speed: a 10-minute walk with every sensor at 100 Hz.

Scenario: a generated office floor (930 magnetic dipoles), its round-trip route
repeated to ten minutes of walking, handheld, with the ``mid_grade`` profile set
to 100 Hz for the accelerometer, gyroscope and magnetometer. Timed: route →
gait → carry → every sensor (magnetic field at each magnetometer sample,
illuminance with occlusion, WiFi scans) → error models → fused sensors →
Recording (in memory; writing Parquet is timed separately).

Printed: seconds, × real time, peak memory (tracemalloc: Python and numpy
allocations during the run), and the ratio to a numpy reference that only
derives an ideal IMU from the same true trajectory (second differences of the
positions, relative rotations of the quaternions) — timed in the same run.

Run: ``python benchmarks/bench_simulate.py``.
"""

from __future__ import annotations

import dataclasses
import itertools
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

import indoorsim
from indoorsim.phone.devices import get_device
from indoorsim.scenario import RouteSpec
from indoorsim.simulate import simulate
from indoorsim.world.generate import generate

TARGET_S = 600.0


def ten_minute_route(site: indoorsim.Site) -> RouteSpec:
    base = site.scenario.routes["round_trip"]
    pts = [tuple(p) for p in base.waypoints]
    length = sum(np.hypot(*np.subtract(b, a)) for a, b in itertools.pairwise(pts))
    laps = int(np.ceil(TARGET_S * base.speed / length))
    loop = pts if pts[0] == pts[-1] else pts + pts[-2::-1]
    way = list(loop)
    for _ in range(laps - 1):
        way += loop[1:]
    # Trim the polyline to ten minutes of walking at the route speed.
    out, walked = [way[0]], 0.0
    for a, b in itertools.pairwise(way):
        seg = float(np.hypot(*np.subtract(b, a)))
        if walked + seg >= TARGET_S * base.speed:
            f = (TARGET_S * base.speed - walked) / seg
            out.append(tuple(np.add(a, f * np.subtract(b, a))))
            break
        out.append(b)
        walked += seg
    return RouteSpec(waypoints=out, speed=base.speed)


def numpy_ideal_imu(
    t: np.ndarray, pos: np.ndarray, quat: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Reference: ideal specific force and body rate by plain finite differences."""
    dt = np.diff(t)
    acc = np.gradient(np.gradient(pos, t, axis=0), t, axis=0)
    acc[:, 2] += 9.80665
    w, x, y, z = quat.T
    # Rotate world vectors into the phone frame: v_b = R(q)ᵀ v_w.
    r = np.stack(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    ).transpose(2, 0, 1)
    f_body = np.einsum("kji,kj->ki", r, acc)
    q0, q1 = quat[:-1], quat[1:]
    # Relative rotation q0* ⊗ q1, small-angle: ω ≈ 2·vec(q0* ⊗ q1)/dt.
    rel_v = q0[:, :1] * q1[:, 1:] - q1[:, :1] * q0[:, 1:] - np.cross(q0[:, 1:], q1[:, 1:])
    omega = 2 * rel_v / dt[:, None]
    return f_body, omega


def main() -> None:
    site = indoorsim.load_site(generate("office", seed=0))
    route = ten_minute_route(site)
    base = get_device("mid_grade")
    device = dataclasses.replace(
        base,
        name="mid_grade_100hz",
        accel=dataclasses.replace(base.accel, rate_hz=100.0),
        gyro=dataclasses.replace(base.gyro, rate_hz=100.0),
        mag=dataclasses.replace(base.mag, rate_hz=100.0),
    )
    with threadpool_limits(limits=1):
        simulate(site, route="corridor", device=device, seed=0)  # compile and warm caches
        times = []
        for _ in range(3):
            t0 = time.perf_counter()
            rec = simulate(site, route=route, device=device, seed=1)
            times.append(time.perf_counter() - t0)
        t_sim = min(times)
        # Memory in a separate run: tracemalloc slows every allocation.
        tracemalloc.start()
        simulate(site, route=route, device=device, seed=1)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        truth = rec.truth
        tt = truth.index.to_numpy()
        pos = truth[["x", "y", "z"]].to_numpy()
        quat = truth[["qw", "qx", "qy", "qz"]].to_numpy()
        t0 = time.perf_counter()
        numpy_ideal_imu(tt, pos, quat)
        t_ref = time.perf_counter() - t0
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            rec.save(Path(tmp) / "rec")
            t_save = time.perf_counter() - t0
    dur = rec.duration
    print(
        f"simulate: {dur:.0f} s walk ({dur / 60:.1f} min), {len(site.magnetic.positions)} dipoles, "
        f"{len(site.scenario.luminaires)} luminaires, {len(site.radio.bssids)} APs, one core"
    )
    print("  samples: " + ", ".join(f"{k} {len(v)}" for k, v in rec.streams.items()))
    print(f"  end to end      : {t_sim:6.2f} s  = {dur / t_sim:6.0f}x real time (best of 3)")
    print(f"  peak memory     : {peak / 2**20:6.0f} MiB (tracemalloc, during simulate)")
    print(f"  numpy ideal IMU : {t_ref:6.3f} s  (finite differences only, same trajectory)")
    print(f"  ratio simulate / ideal-IMU reference: {t_sim / t_ref:.1f}")
    print(f"  writing Parquet : {t_save:6.2f} s")


if __name__ == "__main__":
    main()
