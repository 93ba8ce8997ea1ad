"""End-to-end simulation speed: a 10-minute walk with every sensor at 100 Hz, per carrying mode.

Scenario: a generated office floor (its dipoles, luminaires and APs are
printed), its round-trip route repeated to ten minutes of walking, with the
``mid_grade`` profile set to 100 Hz for the accelerometer, gyroscope and
magnetometer. Timed: route → gait → carry → every sensor (magnetic field at
each magnetometer sample, illuminance with occlusion, WiFi scans) → error
models → fused sensors → Recording (in memory; writing Parquet is timed
separately).

Printed per carrying mode: seconds and × real time (best of 3), by wall clock
and by this process's CPU time (which other jobs on the machine do not
inflate), and the load average.

Then, on the same ten minutes of samples and in the same process, each field
evaluation against its exact, straightforward reference:

* magnetometer: ``MagneticModel.field_along`` (near steel summed exactly at
  every sample, the smooth rest at knots) against the exact dipole sum at
  every sample (``site.magnetic_field``, BLAS): time ratio and largest error;
* light: the compiled direct-illuminance kernel against the per-source numpy
  sum with ``plan.light_transmittance``: time ratio and largest difference;
* a numpy reference that only derives an ideal IMU from the same true
  trajectory (second differences of the positions, relative rotations of the
  quaternions): the ratio of the whole simulation to it.

Run: ``python benchmarks/bench_simulate.py``.
"""

from __future__ import annotations

import dataclasses
import itertools
import os
import tempfile
import time
import tracemalloc
from collections.abc import Callable
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

import indoorsim
from indoorsim.phone.devices import get_device
from indoorsim.phone.kinematics import IdealImu
from indoorsim.scenario import RouteSpec
from indoorsim.scenario.generate import generate
from indoorsim.simulate import PATH_FIELD_ERROR_UT, simulate
from indoorsim.walker.carry import carry
from indoorsim.walker.gait import WalkerParams, walk
from indoorsim.walker.route import plan_route
from indoorsim.world.light import MIN_DISTANCE_M, direct_illuminance

TARGET_S = 600.0
MODES = ("handheld", "calling", "dangling", "pocketed")


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


def numpy_direct_illuminance(
    site: indoorsim.Site, points: np.ndarray, normals: np.ndarray
) -> np.ndarray:
    """Reference: the direct-light sum source by source in numpy, with the plan's occlusion."""
    src = site.light.sources
    out = np.zeros(len(points))
    for pos, axis, i0, n in zip(
        src.position, src.axis, src.intensity_cd, src.exponent, strict=True
    ):
        v = pos - points
        d2 = np.maximum(np.einsum("ij,ij->i", v, v), MIN_DISTANCE_M**2)
        d = np.sqrt(d2)
        cos_theta, cos_psi = -(v @ axis) / d, np.einsum("ij,ij->i", normals, v) / d
        lit = np.flatnonzero((cos_theta > 0) & (cos_psi > 0))
        e = i0 * cos_theta[lit] ** n * cos_psi[lit] / d2[lit]
        out[lit] += e * site.plan.light_transmittance(points[lit, :2], pos[None, :2])
    return out


def best_of(n: int, run: Callable[[], object]) -> tuple[float, float, object]:
    """Best wall and CPU seconds of n runs, and the last result."""
    wall, cpu, out = np.inf, np.inf, None
    for _ in range(n):
        w0, c0 = time.perf_counter(), time.process_time()
        out = run()
        wall = min(wall, time.perf_counter() - w0)
        cpu = min(cpu, time.process_time() - c0)
    return wall, cpu, out


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
    load = os.getloadavg()
    print(
        f"simulate: 10-minute walks, {len(site.magnetic.positions)} dipoles, "
        f"{len(site.scenario.luminaires)} luminaires, {len(site.radio.bssids)} APs, one core; "
        f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} ({os.cpu_count()} cores)"
    )
    with threadpool_limits(limits=1):
        simulate(site, route="corridor", device=device, seed=0)  # compile and warm caches
        rec = None
        for mode in MODES:
            wall, cpu, rec = best_of(
                3, lambda m=mode: simulate(site, route=route, mode=m, device=device, seed=1)
            )
            dur = rec.duration
            print(
                f"  {mode:9s}: {wall:5.2f} s wall = {dur / wall:5.0f}x real time, "
                f"{cpu:5.2f} s CPU = {dur / cpu:5.0f}x real time (best of 3)"
            )
        # Memory in a separate run: tracemalloc slows every allocation.
        tracemalloc.start()
        simulate(site, route=route, device=device, seed=1)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        print(f"  peak memory: {peak / 2**20:.0f} MiB (tracemalloc, during one simulate)")

        # The fields along one ten-minute dangling walk (the fastest-moving phone).
        planned = plan_route(site.plan, route)
        rng = np.random.default_rng(3)
        body = walk(site.plan, planned, WalkerParams(), rng)
        phone = carry(body, "dangling", rng)
        imu = IdealImu(phone.t, phone.pos, phone.quat)
        t_mag = np.arange(phone.t[0], phone.t[-1], 0.01)
        w_fast, c_fast, fast = best_of(
            3, lambda: site.magnetic.field_along(t_mag, imu.position, phone.t, phone.pos)
        )
        w_exact, c_exact, exact = best_of(3, lambda: site.magnetic_field(imu.position(t_mag)))
        err = float(np.linalg.norm(fast - exact, axis=1).max())
        print(
            f"  magnetometer, {len(t_mag)} samples: path field {w_fast:.3f} s "
            f"({c_fast:.3f} s CPU), exact sum {w_exact:.3f} s ({c_exact:.3f} s CPU): "
            f"ratio exact / path {c_exact / c_fast:.1f} (CPU); largest error {err:.4f} µT "
            f"(bound {PATH_FIELD_ERROR_UT} µT)"
        )
        t_light = np.arange(phone.t[0], phone.t[-1], 0.02)
        points = imu.position(t_light)
        normals = imu.to_world_frame(t_light, np.tile([0.0, 0.0, 1.0], (len(t_light), 1)))
        w_k, c_k, kernel = best_of(
            3, lambda: direct_illuminance(site.light.sources, points, normals, site.plan)
        )
        w_r, c_r, ref = best_of(1, lambda: numpy_direct_illuminance(site, points, normals))
        rel = float(np.max(np.abs(kernel - ref) / np.maximum(ref, 1e-9)))
        print(
            f"  light, {len(t_light)} samples: kernel {w_k:.3f} s ({c_k:.3f} s CPU), "
            f"per-source numpy {w_r:.3f} s ({c_r:.3f} s CPU): ratio {c_r / c_k:.1f} (CPU); "
            f"largest relative difference {rel:.1e}"
        )

        truth = rec.truth
        tt = truth.index.to_numpy()
        pos = truth[["x", "y", "z"]].to_numpy()
        quat = truth[["qw", "qx", "qy", "qz"]].to_numpy()
        w_imu, c_imu, _ = best_of(3, lambda: numpy_ideal_imu(tt, pos, quat))
        _, c_sim, _ = best_of(
            1, lambda: simulate(site, route=route, mode="handheld", device=device, seed=1)
        )
        print(
            f"  numpy ideal IMU: {w_imu:.3f} s (finite differences only, same trajectory); "
            f"ratio simulate / ideal-IMU reference {c_sim / c_imu:.1f} (CPU)"
        )
        with tempfile.TemporaryDirectory() as tmp:
            w_save, _, _ = best_of(1, lambda: rec.save(Path(tmp) / "rec", overwrite=True))
        print(f"  writing Parquet: {w_save:.2f} s")


if __name__ == "__main__":
    main()
