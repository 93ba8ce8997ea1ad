"""Handling: the hand moving the phone from one carrying place to the next.

A change of carrying mode (:func:`~indoorsim.walker.carry.carry`) is the hand
taking the phone from where one mode holds it to where the next one does. The
hand's reach is a minimum-jerk movement (the blend weight is the smootherstep
10τ³ − 15τ⁴ + 6τ⁵ of the reach's time, the profile of point-to-point arm
movements, Flash & Hogan 1985), and the phone turns by slerp along it. A place
that holds the phone in a pocket adds a stroke (:class:`PocketStroke`): the
phone slides in along its long axis and is stopped by the pocket's bottom,
through the cloth and the flesh behind it, within a few hundredths of a second —
the jolt real phones record as they are pocketed (the Oxford step-counter
walks' front and back pockets read ‖a‖ peaks of 10–42 m/s², median 22, in the
seconds around their walks; the simulated walks of ``leaderboards/sim_to_real.md``,
pocketed from the hand and back, 27–35, median 30) — and slides out by the same
stroke run backwards: the pull starts with a jerk as the hand's grip overcomes the
cloth's hold, and slows as the phone clears the mouth.

Timeline of a change over ``transition_s``: the stroke out of the old place
(if it is a pocket), the reach, the stroke into the new place (if it is one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from indoorsim.walker.gait import smootherstep

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation

__all__ = ["STROKE_RISE_S", "PocketStroke", "draw_pocket_stroke", "handover", "stroke_depth"]

STROKE_RISE_S = 0.1
"""How long the hand takes to bring the phone up to its stroke's speed, s [E]."""

_DEPTH_M = (0.10, 0.14)
"""Range of the stroke's length, drawn per pocket: the phone (≈ 0.15 m) enters tip
first from the mouth until its far end is in [E]."""
_SPEED_MPS = (0.3, 0.6)
"""Range of the speed at which the hand pushes it in, drawn per pocket [E]."""
_STOP_S = (0.025, 0.04)
"""Range of how long the pocket's bottom takes to stop it, s, drawn per pocket: the
deceleration is a half-cosine pulse of peak π·v/(2·stop), 12–38 m/s² over this
range and the speed's [E]."""


@dataclass(frozen=True, kw_only=True, eq=False)
class PocketStroke:
    """How the phone slides into the place that holds it, and out of it.

    Attributes:
        axis: (3,) unit vector in the phone's frame: the way it moves going in.
        depth_m: the stroke's length, m.
        speed_mps: the push's speed, m/s.
        stop_s: how long the bottom takes to stop it, s.
    """

    axis: NDArray[np.float64]
    depth_m: float
    speed_mps: float
    stop_s: float

    def __post_init__(self) -> None:
        positive = self.depth_m > 0 and self.speed_mps > 0 and self.stop_s > 0
        if not (positive and self.duration_s >= STROKE_RISE_S + self.stop_s):
            raise ValueError(
                f"a stroke of {self.depth_m} m at {self.speed_mps} m/s stopped in "
                f"{self.stop_s} s: all must be positive and the stroke long enough to "
                "reach its speed and stop"
            )
        if np.shape(self.axis) != (3,):
            raise ValueError(
                f"the stroke's axis must be a 3-vector, got shape {np.shape(self.axis)}"
            )
        norm = float(np.linalg.norm(self.axis))
        if not math.isclose(norm, 1.0, abs_tol=1e-9):
            raise ValueError(f"the stroke's axis must be a unit vector, got length {norm}")

    @property
    def duration_s(self) -> float:
        """Time from the mouth to the bottom: rise, cruise and stop."""
        return self.depth_m / self.speed_mps + 0.5 * (STROKE_RISE_S + self.stop_s)


def draw_pocket_stroke(rng: np.random.Generator, axis: NDArray[np.float64]) -> PocketStroke:
    """A pocket's stroke along ``axis`` (phone frame), its depth, speed and stop drawn."""
    return PocketStroke(
        axis=np.asarray(axis, dtype=float),
        depth_m=float(rng.uniform(*_DEPTH_M)),
        speed_mps=float(rng.uniform(*_SPEED_MPS)),
        stop_s=float(rng.uniform(*_STOP_S)),
    )


def stroke_depth(tau: NDArray[np.float64], stroke: PocketStroke) -> NDArray[np.float64]:
    """How far the phone has gone in, m, ``tau`` s after it starts in at the mouth.

    The speed rises by smootherstep over :data:`STROKE_RISE_S`, holds, and falls to
    zero over ``stop_s`` as a half cosine; the depth is its integral in closed form:
    0 before the stroke, ``depth_m`` from its end on, C² throughout (the acceleration
    is zero at every joint of the phases).
    """
    tau = np.asarray(tau, dtype=float)
    v, rise, stop = stroke.speed_mps, STROKE_RISE_S, stroke.stop_s
    cruise = stroke.duration_s - rise - stop
    x = np.clip(tau / rise, 0.0, 1.0)
    # ∫ smootherstep = τ⁶ − 3τ⁵ + 2.5τ⁴ (in units of the rise time).
    rising = v * rise * x**4 * (x * (x - 3.0) + 2.5)
    holding = v * np.clip(tau - rise, 0.0, cruise)
    u = np.clip((tau - rise - cruise) / stop, 0.0, 1.0)
    stopping = 0.5 * v * stop * (u + np.sin(np.pi * u) / np.pi)
    # The sum can fall a rounding step short of the depth at the end: the end is exact.
    return np.where(tau >= stroke.duration_s, stroke.depth_m, rising + holding + stopping)


def handover(
    tau: NDArray[np.float64],
    span_s: float,
    old: tuple[NDArray[np.float64], Rotation, PocketStroke | None],
    new: tuple[NDArray[np.float64], Rotation, PocketStroke | None],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Where the hand has the phone ``tau`` s into a change of place that takes ``span_s``,
    how far its reach has gone (0 → 1, the weight the orientation's slerp takes), and
    how far it has left the old place's light for the new one's (0 → 1): out of a
    pocket as it comes out, into one as it goes in, over the span otherwise.

    ``old`` and ``new`` are each place's (positions, rotations, stroke) at the same
    samples: where each mode would hold the phone, and its pocket's stroke (None for
    a hand, an ear). The phone leaves the old place by its stroke run backwards, the
    hand reaches from the old place's mouth to the new one's, and the phone goes in
    by the new stroke. Without strokes the reach takes the whole span.

    Raises:
        ValueError: if the strokes leave the reach no time.
    """
    (old_pos, old_rot, old_stroke), (new_pos, new_rot, new_stroke) = old, new
    out_s = old_stroke.duration_s if old_stroke is not None else 0.0
    in_s = new_stroke.duration_s if new_stroke is not None else 0.0
    reach_s = span_s - out_s - in_s
    if reach_s <= 0:
        raise ValueError(
            f"a change of carrying place over {span_s} s leaves no time to reach: the "
            f"pockets' strokes take {out_s + in_s:.3f} s"
        )
    w = smootherstep((tau - out_s) / reach_s)
    light = smootherstep(tau / span_s)
    if old_stroke is not None:
        # Out of the pocket: the stroke run backwards, from the bottom to the mouth.
        out = old_stroke.depth_m - stroke_depth(out_s - tau, old_stroke)
        old_pos = old_pos + out[:, None] * old_rot.apply(-old_stroke.axis)
        light = out / old_stroke.depth_m
    if new_stroke is not None:
        # Held over the mouth until the reach is done, then pushed in.
        left = new_stroke.depth_m - stroke_depth(tau - out_s - reach_s, new_stroke)
        new_pos = new_pos + left[:, None] * new_rot.apply(-new_stroke.axis)
        light = 1.0 - left / new_stroke.depth_m if old_stroke is None else w
    return (1 - w)[:, None] * old_pos + w[:, None] * new_pos, w, light
