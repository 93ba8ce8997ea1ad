"""Meander: how a walker drifts sideways off the line it means to walk.

Nobody walks on rails. Step by step the body's heading strays a little and is
steered back, so a walker on a straight corridor weaves a few centimetres either
side of its line over a few metres, slower than the stride's sway
(Dingwell & Cusumano, PLoS Comput Biol 15:e1007229, 2019: lateral position and
heading fluctuate step to step and are corrected within a few steps). The Kok &
Solin ARKit walks (``shared/realdata/mag-slam-1d``) measure it on real floors:
over their straightest 6 m stretches the handheld device, its stride's sway
averaged out, strays 1.85–2.84 cm (RMS) from the stretch's line and its direction of
travel 1.72–2.62° from the line's (:mod:`indoorsim.benchmark.realism.line`, the
same statistic on both sides in ``leaderboards/realism.md``).

:func:`lateral_meander` draws that sideways offset as a function of the distance
walked, so standing still or turning on the spot adds none: white noise through two
critically damped second-order filters (the walker's heading, corrected toward its
line, integrated into its position; smooth up to the yaw's acceleration), scaled to
the drawn RMS, and faded in and out over the first and the last metres so that a
walk starts and ends on its route's points. :func:`keep_room` eases it off toward a
wall close beside the path, as people keep their distance.
:func:`~indoorsim.walker.gait.walk` adds it along the path's normal and turns the
body's heading by its slope.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import make_interp_spline
from scipy.ndimage import gaussian_filter1d, minimum_filter1d
from scipy.signal import bilinear, lfilter

if TYPE_CHECKING:
    from indoorsim.world.plan import FloorPlan

__all__ = ["Meander", "keep_room", "lateral_meander"]

_DS_M = 0.05
"""Spacing of the offset's samples along the path (m)."""
_SETTLE_WAVELENGTHS = 3.0
"""The filter runs this many wavelengths before the path starts, to be settled there."""
_ROOM_DS_M = 0.5
"""Spacing of the probes for walls beside the path (m)."""
_ROOM_AHEAD = 7
"""Probes (3 m of path) over which the least room is taken."""
_ROOM_STEP_M, _ROOM_PROBES = 0.05, 20
"""Probes for the room beside the path: this far apart (m), this many on each side."""
_ROOM_MIN_M = 0.01
"""The least room the eased offset is given (m): a path squeezed closer to a wall than
the clearance barely weaves toward it."""


@dataclass(frozen=True)
class Meander:
    """A sideways offset (m, + to the left of the path) along the path's length."""

    s: NDArray[np.float64]
    """(n,) distance along the path (m), from 0 to its length, evenly spaced."""
    offset: NDArray[np.float64]
    """(n,) the offset at each distance (m)."""

    def at(self, s: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The offset (m) and its slope (m per m) at the distances ``s``, through a
        quintic spline (C⁴, so the slope's own curvature, which the body's turn
        differentiates twice more, has no kinks between the samples); held beyond the
        ends."""
        # Level at both ends, where the fades have brought it to rest.
        ends = [(1, 0.0), (2, 0.0)]
        curve = make_interp_spline(self.s, self.offset, k=5, bc_type=(ends, ends))
        inside = np.clip(s, self.s[0], self.s[-1])
        return curve(inside), curve(inside, 1)


def lateral_meander(
    length_m: float,
    rms_m: float,
    wavelength_m: float,
    fade_m: float,
    rng: np.random.Generator,
) -> Meander:
    """Draw a walker's sideways offset from its path over ``length_m``.

    Args:
        length_m: the path's length (m).
        rms_m: the offset's RMS away from the fades (m).
        wavelength_m: the filter's natural wavelength 2π/ω (m). The offset's slope
            (the heading's departure, rad) has an RMS of ``rms_m``·ω/√5.
        fade_m: length over which the offset fades in after the start and out before
            the end (m).
        rng: draws the white noise (a number of draws fixed by ``length_m``).

    Returns:
        The offset along the path, zero at both ends.
    """
    omega = 2.0 * math.pi / wavelength_m
    settle = math.ceil(_SETTLE_WAVELENGTHS * wavelength_m / _DS_M)
    n = max(2, math.ceil(length_m / _DS_M) + 1)
    noise = rng.standard_normal(settle + n)
    # (d/ds + ω)⁴ z = w(s): two critically damped second-order stages, so that z is
    # smooth to its third derivative (the body's yaw acceleration, which turns the
    # phone, is continuous). w is white with unit-variance samples _DS_M apart
    # (spectral density _DS_M): the steady variance of z is 5·_DS_M / (32ω⁷).
    b, a = bilinear([1.0], [1.0, 2.0 * omega, omega**2], fs=1.0 / _DS_M)
    z = lfilter(b, a, lfilter(b, a, noise))[settle:]
    z *= rms_m / math.sqrt(5.0 * _DS_M / (32.0 * omega**7))
    s = np.linspace(0.0, length_m, n)
    edge = np.clip(np.minimum(s, length_m - s) / max(fade_m, 1e-9), 0.0, 1.0)
    # Faded by the smootherstep, so the offset stays C² through the fades. Written out:
    # gait.smootherstep's own form rounds its last bits differently, and gait imports
    # this module.
    return Meander(s=s, offset=z * edge**3 * (10.0 - 15.0 * edge + 6.0 * edge**2))


def keep_room(
    meander: Meander,
    position: NDArray[np.float64],
    heading: NDArray[np.float64],
    plan: FloorPlan,
    clearance_m: float,
) -> Meander:
    """``meander`` eased off toward walls close beside the path: on each side, the room
    r is how far the body's centre can move off the path along its normal and stay
    ``clearance_m`` from every wall (probed every 5 cm up to a metre), and an
    offset o toward that side becomes o / √(1 + (o/r)²): nearly as drawn while well
    within r, never beyond it. The walker weaves freely in the open and keeps its
    distance beside a wall or in a doorway.

    Args:
        meander: the drawn offset.
        position: (len(meander.s), 2) the path's points at ``meander.s``.
        heading: (len(meander.s),) the path's heading there (rad).
        plan: the floor plan (its walkable area's boundary).
        clearance_m: how near a wall the body's centre may weave (m).
    """
    every = max(1, round(_ROOM_DS_M / _DS_M))
    probe = np.r_[np.arange(0, len(meander.s) - 1, every), len(meander.s) - 1]
    normal = np.column_stack([-np.sin(heading[probe]), np.cos(heading[probe])])
    steps = np.arange(_ROOM_PROBES + 1) * _ROOM_STEP_M
    reach = clearance_m + _ROOM_STEP_M
    rooms = []
    for side in (1.0, -1.0):
        points = position[probe, None, :] + side * steps[None, :, None] * normal[:, None, :]
        flat = points.reshape(-1, 2)
        gap = np.linalg.norm(plan.nearest_boundary(flat, reach) - flat, axis=1)
        gap = np.where(np.isnan(gap), reach, gap)
        gap = np.where(plan.is_walkable(flat), gap, 0.0).reshape(len(probe), len(steps))
        # The room reaches where the probes' gap to the nearest wall first falls below the
        # clearance, between two probes by linear interpolation (a continuous room).
        margin = np.c_[gap - clearance_m, np.full(len(probe), -1.0)]
        k = np.argmax(margin < 0.0, axis=1)
        before = margin[np.arange(len(probe)), np.maximum(k - 1, 0)]
        after = margin[np.arange(len(probe)), k]
        crossing = before / np.where(k == 0, 1.0, before - after)
        room = np.where(
            k == 0,
            0.0,
            np.minimum(steps[np.maximum(k - 1, 0)] + crossing * _ROOM_STEP_M, steps[-1]),
        )
        # The least room within a metre and a half either way, smoothed (σ = half a
        # metre): the walker comes back toward its line before a doorway or a wall
        # begins, over a few steps, not at it.
        room = minimum_filter1d(np.maximum(room, _ROOM_MIN_M), _ROOM_AHEAD, mode="nearest")
        fine = np.interp(meander.s, meander.s[probe], room)
        rooms.append(gaussian_filter1d(fine, _ROOM_DS_M / _DS_M, mode="nearest"))
    left, right = rooms
    o = meander.offset
    room = np.where(o >= 0.0, left, right)
    # A soft limit, o / √(1 + (o/r)²): the offset nearly as drawn while well within the
    # room, never beyond it, and bending toward it over a few steps, not at once.
    return Meander(s=meander.s, offset=o / np.sqrt(1.0 + (o / room) ** 2))
