"""The body's proportions the carrying modes hang the phone from.

Heights and lengths are fractions of body height (Drillis & Contini's anthropometric
ratios, as commonly tabulated) [E]; the arm's segments' masses are fractions of body
mass, their centres of mass and radii of gyration fractions of the segment's length
(Winter, *Biomechanics and Motor Control of Human Movement*, table 4.1).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from indoorsim.walker.gait import PELVIS_HEIGHT_RATIO

__all__ = [
    "ARM_LENGTH",
    "EAR_H",
    "EYE_FROM_NECK",
    "EYE_H",
    "HIP_H",
    "HIP_HALF_WIDTH",
    "NECK_H",
    "SHOULDER_H",
    "SHOULDER_HALF_WIDTH",
    "UPPER_ARM",
    "arm_about_shoulder",
    "bent_eyes",
    "hanging_forearm",
    "shoulder_joint",
]

SHOULDER_H, EAR_H, EYE_H, HIP_H = 0.818, 0.90, 0.936, 0.50
NECK_H = 0.83
"""Height of the base of the neck (C7), about which the head bends over a phone, taken
on the trunk's axis [E]."""
EYE_FROM_NECK = (0.05, EYE_H - NECK_H)
"""The eyes from the base of the neck, upright: ahead of the trunk's axis and above [E]."""
ARM_LENGTH = 0.386
"""Shoulder to the middle of the grip."""
UPPER_ARM = 0.186
"""Shoulder to elbow."""
SHOULDER_HALF_WIDTH = 0.115
HIP_HALF_WIDTH = 0.055

UPPER_ARM_MASS, UPPER_ARM_COM, UPPER_ARM_GYRATION = 0.028, 0.436, 0.322
FOREARM_MASS, FOREARM_COM, FOREARM_GYRATION, FOREARM = 0.016, 0.430, 0.303, 0.146
HAND_MASS, HAND_GYRATION, HAND = 0.006, 0.297, 0.108
PHONE_MASS_FRACTION = 0.0026
"""A phone of ≈ 0.18 kg on a 70 kg body."""


def body_side(which: str) -> float:
    """+1 for the left side of the body (its +y), −1 for the right."""
    return 1.0 if which == "left" else -1.0


def shoulder_joint(height_m: float, side: float) -> NDArray[np.float64]:
    """The shoulder joint on ``side`` (+1 left, −1 right) in the body frame, from the
    pelvis, m."""
    return np.array(
        [0.0, side * SHOULDER_HALF_WIDTH * height_m, (SHOULDER_H - PELVIS_HEIGHT_RATIO) * height_m]
    )


def bent_eyes(flexion: float) -> tuple[float, float]:
    """The eyes' place ahead of the trunk's axis and above the base of the neck, as
    fractions of body height, with the head bent forward by ``flexion`` rad about it."""
    c, s = math.cos(flexion), math.sin(flexion)
    return (
        EYE_FROM_NECK[0] * c + EYE_FROM_NECK[1] * s,
        EYE_FROM_NECK[1] * c - EYE_FROM_NECK[0] * s,
    )


def arm_about_shoulder(
    shoulder: NDArray[np.float64],
    elbow: NDArray[np.float64],
    hand: NDArray[np.float64],
    along: NDArray[np.float64],
    height_m: float,
) -> tuple[float, float]:
    """The held arm's first moment and moment of inertia about the shoulder's lateral
    axis, per kilogram of body mass (their ratio is what matters): the upper arm from
    ``shoulder`` to ``elbow``, the forearm from ``elbow`` along ``along`` and the hand
    with the phone at ``hand`` as rigid segments, in the body's sagittal plane.

    Returns (Σ m·x, Σ m·(x² + z² + ρ²)): x ahead of the shoulder, z above it."""
    upper_len = float(np.linalg.norm(elbow - shoulder))
    fore_len = FOREARM * height_m
    segments = (
        (
            UPPER_ARM_MASS,
            shoulder + UPPER_ARM_COM * (elbow - shoulder),
            UPPER_ARM_GYRATION * upper_len,
        ),
        (FOREARM_MASS, elbow + FOREARM_COM * fore_len * along, FOREARM_GYRATION * fore_len),
        (HAND_MASS + PHONE_MASS_FRACTION, hand, HAND_GYRATION * HAND * height_m),
    )
    first = sum(m * (c - shoulder)[0] for m, c, _ in segments)
    second = sum(
        m * ((c - shoulder)[0] ** 2 + (c - shoulder)[2] ** 2 + rho**2) for m, c, rho in segments
    )
    return float(first), float(second)


def hanging_forearm(height_m: float) -> tuple[float, float]:
    """The forearm with the hand and the phone at the grip, hanging from the elbow:
    its moments about the elbow per kilogram of body mass, S = Σ m·d and
    J = Σ m·(d² + ρ²) (d from the elbow along the forearm, ρ each part's radius of
    gyration), as the two numbers the linearised swinging arm needs:

    - ω_g² = g·S/J (1/s²), the forearm's own gravity pendulum (0.93 Hz at 1.75 m:
      S/J scales as 1/height, 3.5 /m there);
    - S·u/J, by which the upper arm's angular acceleration θ̈ whips the forearm on
      through the elbow's tangential acceleration u·θ̈ (u the upper arm's length).

    With φ the elbow's flexion forward of the upper arm's line and θ the upper arm's
    angle from the vertical, J·(θ̈ + φ̈) + S·u·θ̈ = −g·S·(θ + φ) − (the elbow's muscle
    and damping): φ̈ + 2ζω_n·φ̇ + ω_n²·φ = −(1 + S·u/J)·θ̈ − ω_g²·θ, where ω_n² is
    ω_g² plus the muscles' tone over J."""
    fore_len = FOREARM * height_m
    grip = (ARM_LENGTH - UPPER_ARM) * height_m
    parts = (
        (FOREARM_MASS, FOREARM_COM * fore_len, FOREARM_GYRATION * fore_len),
        (HAND_MASS + PHONE_MASS_FRACTION, grip, HAND_GYRATION * HAND * height_m),
    )
    first = sum(m * d for m, d, _ in parts)
    second = sum(m * (d**2 + rho**2) for m, d, rho in parts)
    return 9.81 * first / second, first * UPPER_ARM * height_m / second
