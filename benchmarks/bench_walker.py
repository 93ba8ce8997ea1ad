"""Walker throughput: a 10-minute walk through :func:`walk` and :func:`carry`.

The walker loops the ring corridor of a 40 m × 20 m floor (four 90° corners
per lap, a door into the inner room, one random stop per minute) at 1.3 m/s
until ten minutes have passed, at the 200 Hz truth rate. Prints the best of a
few runs for ``walk()`` and for ``carry()`` in each carrying mode and in a
schedule that changes mode every two minutes, as seconds and as multiples of
real time (walk duration / compute time).

Run: ``python benchmarks/bench_walker.py``.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from indoorsim.scenario import RouteSpec, parse_scenario
from indoorsim.walker.carry import carry
from indoorsim.walker.gait import WalkerParams, walk
from indoorsim.walker.route import plan_route
from indoorsim.world.plan import FloorPlan

REPEATS = 3
WALK_S = 600.0
SPEED = 1.3


def ring_plan() -> FloorPlan:
    """A 40 m × 20 m floor: a 3 m wide corridor around an inner room with one door."""
    outer = [(0, 0), (40, 0), (40, 20), (0, 20)]
    inner = [(3, 3), (37, 3), (37, 17), (3, 17)]
    walls = [
        {"from": list(ring[i]), "to": list(ring[(i + 1) % 4]), "thickness": 0.2}
        for ring in (outer, inner)
        for i in range(4)
    ]
    scenario = parse_scenario(
        {
            "name": "ring",
            "site": {
                "latitude": 32.63,
                "longitude": 117.0,
                "date": "2025-01-01",
                "ceiling_height": 3.0,
            },
            "walls": walls,
            "doors": [{"position": [20, 3], "width": 0.9}],
        }
    )
    return FloorPlan(scenario)


def best(fn: Callable[[], object]) -> tuple[float, object]:
    times, result = [], None
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return min(times), result


def main() -> None:
    plan = ring_plan()
    lap = [(1.5, 1.5), (38.5, 1.5), (38.5, 18.5), (1.5, 18.5)]
    # Corners and stops cost time: 0.9 of the cruising speed on average.
    waypoints, length = [lap[0]], 0.0
    while length < 0.9 * SPEED * WALK_S:
        nxt = lap[len(waypoints) % 4]
        length += float(np.hypot(nxt[0] - waypoints[-1][0], nxt[1] - waypoints[-1][1]))
        waypoints.append(nxt)
    route = plan_route(plan, RouteSpec(waypoints=waypoints, speed=SPEED), "ring")
    params = WalkerParams(stop_rate_per_min=1.0)

    t_walk, body = best(lambda: walk(plan, route, params, np.random.default_rng(0)))
    duration = float(body.t[-1])
    print(
        f"walk: {duration:.0f} s ({route.length:.0f} m, {len(body.steps)} steps, "
        f"{len(body.t)} samples at {body.rate_hz:.0f} Hz)"
    )
    print(f"{'stage':<12} {'seconds':>8} {'x real time':>12}")
    print(f"{'walk()':<12} {t_walk:8.3f} {duration / t_walk:12.0f}")
    step = duration / 5
    schedules: dict[str, object] = {
        name: name for name in ("handheld", "calling", "dangling", "pocketed")
    }
    schedules["mixed"] = [
        (i * step, name)
        for i, name in enumerate(["handheld", "calling", "dangling", "pocketed", "handheld"])
    ]
    for label, schedule in schedules.items():
        t_carry, _ = best(lambda s=schedule: carry(body, s, np.random.default_rng(1)))
        print(f"{'carry ' + label:<12} {t_carry:8.3f} {duration / t_carry:12.0f}")


if __name__ == "__main__":
    main()
