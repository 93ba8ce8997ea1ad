"""Physics: the body as a pymunk disc, steered along its plan against the walls.

:func:`steer` is the fourth stage of :func:`~indoorsim.walker.gait.walk`
(DESIGN §5): the body, a pymunk disc of ``body_radius_m``, is steered through
the planned positions at ``physics_rate_hz`` against the walkable area's
boundary as static segments, so no track passes through a wall, whatever the
route or the planned path do near it. The walk then upsamples the track to
``rate_hz`` with a C² cubic spline.

Frames: building frame, metres. Nothing here is random.
"""

from __future__ import annotations

import contextlib
import math
import threading
from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np
import pymunk
from numpy.typing import NDArray
from pymunk._chipmunk_cffi import lib as _CP

if TYPE_CHECKING:
    from indoorsim.world.plan import FloorPlan

__all__ = ["PYMUNK_LOCK", "pymunk_space", "steer"]

PYMUNK_LOCK = threading.RLock()
"""Held while any pymunk space of the package lives (:func:`pymunk_space`).
Pymunk objects are not synchronised and its C calls release the GIL; two walks
simulated in threads of one process (a multi-threaded Dask worker) crashed in
Chipmunk's space teardown. The physics is a few per cent of a walk, so
serialising it costs little."""


@contextlib.contextmanager
def pymunk_space() -> Iterator[pymunk.Space]:
    """A pymunk space for one computation, under :data:`PYMUNK_LOCK`, emptied on the way out.

    Pymunk's shapes, bodies and constraints each hold a handle to themselves, so
    they die in the cyclic garbage collector, not when their last name goes. A
    space that dies first removes them in its finaliser while iterating them in
    Chipmunk, the space locked and the GIL released between callbacks; a
    collection in another thread (a Dask worker's event loop) that frees one of
    them there removes it from the locked space, and Chipmunk aborts ("cannot be
    done safely during a call to cpSpaceStep()") or the process segfaults: two
    data-set runs died so while their cluster closed. Emptied here, while
    everything in it is still reachable, the space has nothing left to iterate
    and its garbage no space to touch. Use only bodies added to the space (not
    ``space.static_body``, which pymunk keeps outside ``space.bodies``).
    """
    with PYMUNK_LOCK:
        space = pymunk.Space()
        try:
            yield space
        finally:
            space.remove(*space.constraints, *space.shapes, *space.bodies)


# Speed (m/s) at which the steering joint pulls the body back onto its planned
# track after a wall has pushed it off, and the largest acceleration (m/s²) it
# may give the body: ample for any planned track, and a gentle shove when a
# wall is in the way [E].
_TRACK_MAX_CORRECTION, _MAX_STEER_ACCEL = 0.5, 5.0
# The disc's physics is skipped on stretches of at least _STEER_MIN_SKIP steps
# where the plan stays this much farther than the disc's radius plus a step
# from every wall (m), once the disc is within _STEER_ON_TRACK_M of its plan.
_STEER_CLEAR_M, _STEER_MIN_SKIP, _STEER_ON_TRACK_M = 0.05, 8, 1e-9


def steer(
    plan: FloorPlan, ref: NDArray[np.float64], dt: float, radius: float
) -> NDArray[np.float64]:
    """Drive a pymunk disc through the reference positions ``ref`` (one per ``dt``).

    A kinematic control body carries the plan; a pivot joint of bounded force
    drags the disc after it, and the walkable area's boundary, as static
    segments, stops it. The control body runs one step ahead, because pymunk
    moves bodies with the velocity solved in the previous step: without a wall
    in the way the disc lands exactly on every reference point. Once a wall has
    held it back, the joint pulls it back onto the plan at a bounded speed.

    Args:
        plan: the floor plan; its walkable area's boundary stops the disc.
        ref: (K, 2) planned body positions, one every ``dt`` seconds.
        dt: the physics time step (s).
        radius: the disc's radius (m).

    Returns:
        (K, 2) positions of the disc, starting at ``ref[0]``.
    """
    with pymunk_space() as space:
        return _steer_in(space, plan, ref, dt, radius)


def _steer_in(
    space: pymunk.Space, plan: FloorPlan, ref: NDArray[np.float64], dt: float, radius: float
) -> NDArray[np.float64]:
    """:func:`steer` in the given (empty) space."""
    space.collision_slop = 1e-3  # pymunk's default (0.1) is in metres here: far too loose
    building = pymunk.Body(body_type=pymunk.Body.STATIC)
    walls = []
    for a, b in plan.walkable_edges.tolist():
        seg = pymunk.Segment(building, a, b, 0.0)
        seg.friction = 0.0
        walls.append(seg)
    space.add(building, *walls)  # in one call: pymunk's add costs more per call than per shape
    mass = 70.0
    body = pymunk.Body(mass, math.inf)  # the disc never spins: heading is planned
    disc = pymunk.Circle(body, radius)
    disc.friction = 0.0
    control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    joint = pymunk.PivotJoint(control, body, (0.0, 0.0), (0.0, 0.0))
    joint.max_force = mass * _MAX_STEER_ACCEL
    joint.max_bias = _TRACK_MAX_CORRECTION
    space.add(body, disc, control, joint)

    vel = np.zeros_like(ref)
    vel[:-1] = np.diff(ref, axis=0) / dt
    lead = ref - vel * dt
    body.position = tuple(ref[0])
    body.velocity = tuple(vel[0])
    out = np.empty_like(ref)
    out[0] = ref[0]
    if len(ref) > 1:
        control.position = tuple(lead[1])
        control.velocity = tuple(vel[1])
        space.step(dt)  # the first step through pymunk: it checks the bodies once
        out[1] = tuple(body.position)
    # Then Chipmunk directly: pymunk's property and step wrappers cost more than
    # the physics over thousands of steps, and this space has no callbacks,
    # additions or removals for them to handle (the results are identical).
    # Flat lists of floats, not lists of pairs: thousands of small containers
    # would keep the garbage collector busy.
    c_space, c_control, c_body = space._space, control._body, body._body
    lx, ly = lead[:, 0].tolist(), lead[:, 1].tolist()
    vx, vy = vel[:, 0].tolist(), vel[:, 1].tolist()
    rx, ry = ref[:, 0].tolist(), ref[:, 1].tolist()
    # Where the plan keeps the disc clear of every wall (with room for a step's
    # travel), a disc that is on its track stays on it: no contact can arise,
    # so those stretches are copied rather than stepped.
    step = float(np.max(np.linalg.norm(vel, axis=1))) * dt if len(ref) > 1 else 0.0
    clear = np.isnan(plan.nearest_boundary(ref, radius + step + _STEER_CLEAR_M)[:, 0])
    # The first sample at or after each one that is not clear.
    blocked = np.where(clear, len(ref), np.arange(len(ref)))
    run_end = np.minimum.accumulate(blocked[::-1])[::-1].tolist()
    k, n = 2, len(ref)
    while k < n:
        end = run_end[k]
        if end - k >= _STEER_MIN_SKIP:
            p = _CP.cpBodyGetPosition(c_body)
            if abs(p.x - rx[k - 1]) + abs(p.y - ry[k - 1]) < _STEER_ON_TRACK_M:
                out[k:end] = ref[k:end]
                _CP.cpBodySetPosition(c_body, (rx[end - 1], ry[end - 1]))
                _CP.cpBodySetVelocity(c_body, (vx[end - 1], vy[end - 1]))
                k = end
                continue
        _CP.cpBodySetPosition(c_control, (lx[k], ly[k]))
        _CP.cpBodySetVelocity(c_control, (vx[k], vy[k]))
        _CP.cpSpaceStep(c_space, dt)
        p = _CP.cpBodyGetPosition(c_body)
        out[k, 0], out[k, 1] = p.x, p.y
        k += 1
    return out
