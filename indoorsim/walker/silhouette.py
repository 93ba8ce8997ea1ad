"""The carrier's body as the light sensor sees it: a head and a trunk that cast shadows.

A phone in the hand sees the ceiling past the person holding it: their head
sits close to the screen's normal (they are looking at it) and their trunk
fills the view behind the phone (REALISM §3.5: "the body shadows luminaires
behind the user"). :func:`silhouette` poses those two solids from where the
body is and which way its trunk faces, as a
:class:`~indoorsim.world.light.BodyShadow` the light model occludes with.

Sizes are fractions of body height (Drillis & Contini segment ratios and
adult anthropometric tables, as commonly tabulated) [E]: head breadth 0.15 m,
length 0.195 m and height 0.23 m give a sphere of equal volume r ≈ 0.1 m; chest
breadth ≈ 0.32 m and depth ≈ 0.23 m for a 1.75 m adult. While texting the
head is bent forward over the phone by a few centimetres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.walker.gait import PELVIS_HEIGHT_RATIO
from indoorsim.world.body_shadow import BodyShadow

__all__ = [
    "HEAD_CENTRE_RATIO",
    "HEAD_FORWARD_RATIO",
    "HEAD_RADIUS_RATIO",
    "SHOULDER_RATIO",
    "TRUNK_HALF_DEPTH_RATIO",
    "TRUNK_HALF_WIDTH_RATIO",
    "Carrier",
    "silhouette",
]

HEAD_CENTRE_RATIO = 0.90
"""Height of the head's centre (ear level) over body height."""
HEAD_FORWARD_RATIO = 0.02
"""How far the head's centre sits ahead of the trunk's axis, over body height
(bent forward over a phone in the hand) [E]."""
HEAD_RADIUS_RATIO = 0.057
"""Radius of the head sphere over body height (0.1 m at 1.75 m)."""
SHOULDER_RATIO = 0.818
"""Height of the shoulders, the trunk's top, over body height."""
TRUNK_HALF_DEPTH_RATIO = 0.066
"""Half the chest's depth over body height (0.115 m at 1.75 m)."""
TRUNK_HALF_WIDTH_RATIO = 0.09
"""Half the chest's breadth over body height (0.16 m at 1.75 m)."""


def silhouette(body_pos: ArrayLike, trunk_yaw: ArrayLike, height_m: float) -> BodyShadow:
    """The head and trunk of a person ``height_m`` tall, one pose per sample.

    Args:
        body_pos: (N, 3) the body centre (pelvis), m; its height carries the
            gait's bounce to the head and shoulders.
        trunk_yaw: (N,) the direction the trunk faces, rad from +x.
        height_m: the person's height.
    """
    pos = np.asarray(body_pos, dtype=float)
    yaw = np.asarray(trunk_yaw, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 3 or yaw.shape != (len(pos),):
        raise ValueError(
            f"body_pos (N, 3) and trunk_yaw (N,) expected, got {pos.shape}, {yaw.shape}"
        )
    if not height_m > 0:
        raise ValueError(f"height_m must be > 0, got {height_m}")
    # Heights from the pelvis's, so the head and shoulders bounce with the gait.
    base_z = pos[:, 2] - PELVIS_HEIGHT_RATIO * height_m
    forward = HEAD_FORWARD_RATIO * height_m
    head = np.column_stack(
        [
            pos[:, 0] + forward * np.cos(yaw),
            pos[:, 1] + forward * np.sin(yaw),
            base_z + HEAD_CENTRE_RATIO * height_m,
        ]
    )
    return BodyShadow(
        head=head,
        head_radius_m=HEAD_RADIUS_RATIO * height_m,
        trunk_xy=np.ascontiguousarray(pos[:, :2]),
        trunk_yaw=yaw.copy(),
        trunk_top=base_z + SHOULDER_RATIO * height_m,
        trunk_half_depth_m=TRUNK_HALF_DEPTH_RATIO * height_m,
        trunk_half_width_m=TRUNK_HALF_WIDTH_RATIO * height_m,
    )


@dataclass(frozen=True, kw_only=True)
class Carrier:
    """The person carrying a phone, sampled with the phone's trajectory.

    Attributes:
        t: (K,) sample times, s.
        pos: (K, 3) body centre (pelvis), m.
        trunk_yaw: (K,) the direction the trunk faces, rad, unwrapped.
        height_m: body height.
        shades: (K,) in [0, 1], how much the body's shadow on the light sensor
            counts: 0 where the carrying mode's ``light_exposure`` already
            stands for the body the phone touches (at the ear, in a pocket), 1
            where it does not, in between while one mode blends into another.
    """

    t: NDArray[np.float64]
    pos: NDArray[np.float64]
    trunk_yaw: NDArray[np.float64]
    height_m: float
    shades: NDArray[np.float64]

    def __post_init__(self) -> None:
        k = len(self.t)
        for name, want in (("pos", (k, 3)), ("trunk_yaw", (k,)), ("shades", (k,))):
            got = np.shape(getattr(self, name))
            if got != want:
                raise ValueError(f"Carrier.{name}: expected shape {want}, got {got}")
        if not self.height_m > 0:
            raise ValueError(f"Carrier.height_m must be > 0, got {self.height_m}")

    @property
    def torso_xy(self) -> NDArray[np.float64]:
        """(K, 2) the trunk's axis in plan, m."""
        return self.pos[:, :2]

    def shadow_at(self, t: ArrayLike) -> tuple[NDArray[np.float64], BodyShadow]:
        """At times ``t`` (M,): how much the body's shadow counts (M,), and the
        body's pose at the samples where it counts at all (weight > 0).

        Positions, yaw and weight are interpolated linearly.
        """
        tt = np.asarray(t, dtype=float)
        weight = np.interp(tt, self.t, self.shades)
        at = tt[weight > 0]
        pos = np.column_stack([np.interp(at, self.t, self.pos[:, i]) for i in range(3)])
        return weight, silhouette(pos, np.interp(at, self.t, self.trunk_yaw), self.height_m)
