"""Physics: the pymunk body keeps every track inside the walkable area."""

from __future__ import annotations

import numpy as np
import shapely

from indoorsim.scenario import RouteSpec
from indoorsim.walker import physics
from indoorsim.walker.gait import WalkerParams, walk
from indoorsim.walker.route import plan_route
from indoorsim.world.plan import FloorPlan
from tests.walker.conftest import assert_inside


def test_body_stays_in_the_walkable_area(l_plan, l_body):
    assert_inside(l_plan, l_body)


def test_waypoint_route_round_the_corner_stays_inside(l_plan):
    route = plan_route(l_plan, RouteSpec(waypoints=[(1.0, 1.0), (11.0, 1.0), (11.0, 9.0)]))
    body = walk(l_plan, route, WalkerParams(stop_rate_per_min=3.0), np.random.default_rng(3))
    assert_inside(l_plan, body)


def test_pymunk_keeps_the_body_off_a_wall_the_route_hugs(corridor):
    """Waypoints 0.1 m from the wall face, no steering away: the body disc holds the track off."""
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 0.2), (20.0, 0.2)]))
    params = WalkerParams(body_radius_m=0.25, wall_distance_m=0.0)
    body = walk(corridor, route, params, np.random.default_rng(0))
    assert_inside(corridor, body)
    settled = body.t > 1.0  # the disc starts overlapping the wall and is pushed out
    # The wall face is at y = 0.1; lateral sway and pymunk's contact slop take a little.
    assert body.pos[settled, 1].min() > 0.1 + 0.25 - 0.035


def test_random_routes_in_generated_buildings_stay_inside_and_within_the_yaw_limit():
    from indoorsim.scenario import generate

    rng = np.random.default_rng(0)
    params = WalkerParams(stop_rate_per_min=2.0)
    for kind in ("office", "basement"):
        plan = FloorPlan(generate.generate(kind, seed=1))
        free = plan.walkable.buffer(-0.5)
        lo, hi = np.array(plan.bounds[:2]), np.array(plan.bounds[2:])
        ends: list[tuple[float, float]] = []
        while len(ends) < 6:
            p = rng.uniform(lo, hi)
            if free.contains(shapely.Point(p)):
                ends.append((float(p[0]), float(p[1])))
        for a, b in zip(ends[::2], ends[1::2], strict=True):
            route = plan_route(plan, RouteSpec(start=a, goal=b))
            body = walk(plan, route, params, np.random.default_rng(len(ends)))
            assert_inside(plan, body)
            rate = np.degrees(np.abs(np.gradient(body.heading, body.t)))
            assert rate.max() <= params.max_yaw_rate_dps
            assert np.all(np.diff(body.step_phase) >= 0)


def test_generated_office_routes_are_walked_inside_the_walls():
    from indoorsim.scenario import generate

    scenario = generate.generate("office", seed=5)
    plan = FloorPlan(scenario)
    for i, (name, spec) in enumerate(scenario.routes.items()):
        body = walk(plan, plan_route(plan, spec, name), WalkerParams(), np.random.default_rng(i))
        assert_inside(plan, body)


def test_steering_copies_the_plan_only_where_the_physics_would(corridor, monkeypatch):
    # The disc's physics is skipped where the plan keeps clear of every wall
    # and the disc is on it: the walk must come out as with every step simulated.
    route = plan_route(
        corridor, RouteSpec(waypoints=[(1.0, 1.5), (10.0, 1.5), (20.0, 0.2), (30.0, 1.5)])
    )
    params = WalkerParams(wall_distance_m=0.0)  # the route runs into the wall: contacts
    fast = walk(corridor, route, params, np.random.default_rng(4))
    monkeypatch.setattr(physics, "_STEER_MIN_SKIP", 10**9)
    full = walk(corridor, route, params, np.random.default_rng(4))
    np.testing.assert_allclose(fast.pos, full.pos, rtol=0, atol=1e-9)
    assert (full.pos[:, 1] > 0.1 + 0.25 - 0.035).all()  # the wall held the disc off


def test_a_pymunk_space_is_emptied_on_the_way_out():
    """Everything added to a :func:`physics.pymunk_space` is detached from it when the
    block ends, normally or by an exception, so the space's finaliser iterates nothing."""
    import pymunk

    for fail in (False, True):
        try:
            with physics.pymunk_space() as space:
                anchor = pymunk.Body(body_type=pymunk.Body.STATIC)
                disc = pymunk.Body(1.0, 1.0)
                things = [
                    anchor,
                    disc,
                    pymunk.Segment(anchor, (0.0, 0.0), (1.0, 0.0), 0.0),
                    pymunk.Circle(disc, 0.1),
                    pymunk.PivotJoint(anchor, disc, (0.0, 0.0)),
                ]
                space.add(*things)
                space.step(0.01)
                if fail:
                    raise KeyboardInterrupt
        except KeyboardInterrupt:
            pass
        assert not space.shapes and not space.bodies and not space.constraints
        assert all(getattr(x, "space", None) is None for x in things)


# Steers a walk again and again while another thread runs the cyclic garbage
# collector every millisecond: the walls, bodies and joint of each finished walk
# are cyclic garbage (pymunk objects hold handles to themselves), and a collection
# that frees one while its space is locked aborts Chipmunk or segfaults (the code
# before the fix: 6 runs of 6). The pause lets the walk have the GIL: collecting
# without one starved it (a full collection holds the GIL throughout), and a run
# took minutes.
_GC_IN_ANOTHER_THREAD = """
import gc, threading, time
import numpy as np
from indoorsim.walker.physics import steer

xs = np.linspace(0.0, 200.0, 2001)
edges = [np.stack([np.c_[xs[:-1], np.full(2000, y)], np.c_[xs[1:], np.full(2000, y)]], 1)
         for y in (0.0, 1.0)]

class Corridor:  # 1 m wide, of 4000 short walls; the plan presses the disc on one
    walkable_edges = np.concatenate(edges)
    def nearest_boundary(self, points, max_distance):
        return np.zeros_like(points)

def collect():
    while True:
        gc.collect()
        time.sleep(0.001)

threading.Thread(target=collect, daemon=True).start()
ref = np.c_[np.linspace(1.0, 3.0, 300), np.full(300, 0.1)]
for _ in range(10):
    steer(Corridor(), ref, 0.01, 0.25)
print("done")
"""


def test_walks_survive_garbage_collection_in_another_thread():
    """A Dask worker collects garbage in its event loop's thread while a walk runs in
    another: its pymunk spaces must not crash the process (two data-set runs did)."""
    import subprocess
    import sys

    proc = subprocess.run(
        [sys.executable, "-c", _GC_IN_ANOTHER_THREAD], capture_output=True, text=True, timeout=300
    )
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, "done\n", "")
