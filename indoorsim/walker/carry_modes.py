"""The built-in carrying modes: the phone's pose in each, given the body's motion.

Numbers from REALISM §6.1; :func:`~indoorsim.walker.carry.carry` follows a
schedule of them (DESIGN §5):

* ``handheld`` — in front of the chest, screen up and pitched toward the eyes
  (``pitch_deg``: 0 is flat, as in Han2023's experiments; ~30° is texting),
  y-axis forward, where the eyes of a head bent over it read it; the arm holds
  the hand in place against the trunk's surge and sway (it bobs with it), the
  whole arm turns about the shoulder under each vertical jolt (the hand surging
  with it), the forearm swings at the elbow, the abducted upper arm twists about
  its axis (moving the hand sideways with every jolt), and the hand nods, turns
  and rocks the phone at the wrist, each joint a damped spring driven by the
  trunk's motion; the hand turns slowly in yaw, with a faint 8–12 Hz tremor.
* ``calling`` — at the ear, screen toward the head, long axis tilted 30–60°
  from vertical, x-axis along ±forward; the head rides on the neck (a damped
  spring) and nods and rocks on it; it shades the light sensor.
* ``dangling`` — in the swinging hand: the arm is a pendulum about the
  shoulder, simulated with pymunk, driven at stride frequency (±15–25°) and
  shaken by the shoulder's own acceleration; the forearm follows through at
  the elbow (damped, lagging the shoulder), turning and arcing with its swing;
  the hand turns at the wrist in two planes, shaken by all the wrist's motion.
* ``pocketed`` — in a front trouser pocket (either side): long axis along the
  thigh, which turns at the hip in three planes over the gait cycle (flexion
  and rotation after the normal-gait hip curves, ab-/adduction with a drawn lag),
  jolted at the same-side heel strike, the flesh under the pocket shearing round
  the thigh, in the dark; the phone rocks on its hold (its own module,
  :mod:`indoorsim.walker.pocketed`, re-exported here).

What a mode draws per use (grip, misalignment, joint stiffness and damping,
pocket side and placement, swing and twist amplitudes) is in its fields'
documentation; a schedule entry's parameters fix any of them. Importing this
module registers the four (:mod:`indoorsim.walker.modes` holds the protocol
and the registry). Frames and ``light_exposure``: :mod:`indoorsim.walker.carry`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
import pymunk
from numpy.typing import NDArray
from pymunk._chipmunk_cffi import lib as _CP
from scipy.interpolate import CubicSpline

from indoorsim.walker import limbs
from indoorsim.walker.anthropometry import (
    ARM_LENGTH,
    EAR_H,
    NECK_H,
    UPPER_ARM,
    arm_about_shoulder,
    bent_eyes,
    body_side,
    hanging_forearm,
    shoulder_joint,
)
from indoorsim.walker.gait import PELVIS_HEIGHT_RATIO, BodyTrajectory
from indoorsim.walker.modes import CarryMode, ModePose, register_mode
from indoorsim.walker.physics import pymunk_space
from indoorsim.walker.pocketed import Pocketed

__all__ = ["Calling", "Dangling", "Handheld", "Pocketed"]

_G = 9.81


# ---------------------------------------------------------------------- modes


@register_mode
@dataclass(kw_only=True, frozen=True)
class Handheld(CarryMode):
    """Held in front of the chest, screen up, looked at (REALISM §6.1 texting row).

    The arm holds the hand where the eyes read it — the eyes of a head bent over the
    phone (:func:`~.anthropometry.bent_eyes`), which for a 1.75 m walker puts the hand
    where an upper arm of anthropometric length reaches (the reading distance and the
    forearm are drawn in metres, so a short walker's implied upper arm is longer and a
    tall one's shorter): it follows the walk, and vertically the
    trunk's bounce and heel strikes, but fore-aft and sideways it passes the trunk's
    surge and sway within each step through a soft damped spring
    (:func:`~.limbs.transmitted`), and it turns with only part of the trunk's yaw and
    sideways lean. The whole arm, its weight ahead of the shoulder, turns about the
    shoulder under the trunk's vertical jolts (upper arm, forearm and hand as rigid
    segments of Winter's proportions, :func:`~.anthropometry.arm_about_shoulder`, on
    the shoulder flexors' damped spring), which moves the hand up and forward together
    and nods the phone with it. Three joints then carry the phone, each held by muscle
    like a damped spring (:func:`~.limbs.oscillator`): the forearm pivots at the elbow, the
    upper arm, held a little out from the side, twists about its own axis, and the
    hand, with the phone, pivots at the wrist. The elbow's acceleration across the
    forearm swings the forearm (stiff, 5.5–7.5 Hz: the phone's acceleration is the
    trunk's passed through it, harmonics and all) and twists the upper arm (4–6 Hz:
    the hand moves across the forearm, mostly sideways, even under vertical jolts,
    as the arm is abducted). The two springs are driven apart, though their
    motions overlap a little (their directions' cosine is 0.1–0.35): an
    approximation of the arm's coupled modes. The hand's acceleration acts on the
    phone's offset from the wrist and nods it (pitch), turns it sideways (yaw,
    stiffer) and rocks it (roll). The nod at the step rate, a real held phone's largest
    rotation, is mostly the trunk's forward lean, which the arm passes on whole while
    its soft hold keeps the hand in place. The grip turns the phone a little about
    the forearm, so the nod shows on more than one phone axis."""

    name: ClassVar[str] = "handheld"
    pitch_deg: float = 30.0
    """Screen tilt toward the eyes: 0 is flat and steady (Han2023's experiments),
    20–45° is texting or browsing."""
    reading_distance_m: tuple[float, float] = (0.30, 0.40)
    """Range of the distance from the eyes at which the phone is held, drawn per use:
    phones are read at 32–36 cm on average (Bababekova et al. 2011, Optom. Vis. Sci.
    88:795: web pages 32.2 cm, text messages 36.2 cm)."""
    gaze_down_deg: tuple[float, float] = (50.0, 65.0)
    """Range of the line of gaze's angle below the horizontal, drawn per use: the head
    flexes 31–39° over a phone (REALISM §6.1) and the eyes look a further 15–25°
    down in their orbits [E]. The phone rests at the reading distance along it."""
    misalignment_deg: float = 5.0
    """SD of the phone's yaw relative to the walking direction, drawn per use
    (≈ 0 ± 10°)."""
    hand: Literal["right", "left"] = "right"
    """Holding hand: the phone sits slightly to that side."""
    tremor_deg: float = 0.05
    """RMS of the hand's 8–12 Hz angular tremor [E]: the ILC traces' held phones turn
    about their x and y axes at 0.04 rad/s between 10 and 12 Hz (median), where
    0.03° gave 0.03."""
    tremor_mm: float = 0.015
    """RMS of the hand's 8–12 Hz positional tremor (≈ 0.06 m/s² RMS) [E]."""
    forearm_m: float = 0.3
    """Elbow to the middle of the grip (≈ 0.17 of body height, Drillis & Contini)."""
    forearm_rise_deg: float = 25.0
    """Elevation of the forearm from the elbow up to the hand [E]."""
    forearm_inward_deg: float = 25.0
    """Turn of the forearm toward the body's midline: the elbow is at the side [E]."""
    elbow_natural_hz: tuple[float, float] = (5.5, 7.5)
    """Range of the held forearm's natural frequency about the elbow, drawn per use [E]."""
    elbow_damping: tuple[float, float] = (0.4, 0.6)
    """Range of the forearm's damping ratio, drawn per use [E]."""
    wrist_offset_m: float = 0.07
    """Distance from the wrist to the centre of mass of hand and phone, along the hand [E]."""
    palm_height_m: float = 0.02
    """Height of that centre of mass above the forearm's axis (the phone lies on the palm) [E]."""
    thumb_offset_m: float = 0.01
    """Its offset beside the forearm's axis toward the body's midline: a phone held
    in one hand lies across the palm toward the fingers that wrap it [E]. Vertical
    jolts roll the phone on it. The ILC traces' held phones roll at 0.08 rad/s at
    1.3–2.5 Hz and their roll rate runs against their sideways jerk (correlation
    −0.36 to +0.05: gravity leaks in as they tilt). At 1 cm their twins roll at 0.08
    and −0.39; at 1.5 cm 0.11 and −0.48. An offset toward the thumb (outward) rolled
    them the other way, +0.3, where the hand's sideways jolts and the roll kept in
    step."""
    wrist_gyration_m: float = 0.05
    """Radius of gyration of hand and phone about their centre of mass [E]."""
    wrist_pitch_hz: tuple[float, float] = (8.0, 10.0)
    """Range of the wrist's natural frequency in flexion (the nod), drawn per use [E].
    The ILC traces' flat-held phones pitch at 0.22, 0.19, 0.16 rad/s per m/s² of their
    vertical acceleration at the step rate and its 2nd and 3rd harmonics, 8°, 20°, 26°
    past a quarter turn (medians of 16): no resonance below 5.5 Hz. A wrist at 3.5–4.5
    Hz rang at the 2nd (0.63, 80° off); at 8–10 Hz, damped 0.5–0.7, the twins read
    0.22, 0.18, 0.19 at 3°, 23°, 56°, the step rate's nod mostly the trunk's lean."""
    wrist_pitch_damping: tuple[float, float] = (0.5, 0.7)
    """Range of the damping ratio of that flexion, drawn per use [E]."""
    wrist_turn_hz: tuple[float, float] = (4.5, 6.0)
    """Range of its natural frequency in radial-ulnar deviation (the sideways turn),
    drawn per use: the wrist is stiffer that way than in flexion, about 1.5–2 times
    [E]; a turn as soft as the nod was (3–4 Hz), under the sideways jolts the
    twisting arm passes on, rang there three times harder than real held phones
    turn."""
    wrist_roll_hz: tuple[float, float] = (4.5, 6.5)
    """Range of its natural frequency in rotation about the forearm, drawn per use [E]."""
    wrist_damping: tuple[float, float] = (0.3, 0.5)
    """Range of the wrist's damping ratio in the turn and the rock, drawn per use [E]."""
    grip_roll_deg: float = 12.0
    """Largest turn of the phone about the forearm's axis in the grip, drawn per use [E]."""
    trunk_coupling: tuple[float, float] = (0.2, 0.4)
    """Range of the fraction of the trunk's yaw oscillation, and of its sideways
    lean, the phone follows, drawn per use (the ILC traces' held phones roll
    0.07 rad/s at 0.5–1.3 Hz, a quarter of the trunk's lean). A phone being read
    is kept before the eyes, and the head is held steady in yaw while the trunk
    turns under it: the 16 ILC traces' flat-held phones turn at 0.17 rad/s
    (median) at the stride rate, a third of what following 0.8 of the trunk gave
    (0.53) [E]."""
    arm_forward_hz: tuple[float, float] = (0.6, 0.9)
    """Range of the natural frequency at which the arm holds the hand in place, fore
    and aft, against the trunk's motion within each step, drawn per use. The hand
    follows the walk, but the upper arm swings on the shoulder under the step
    rate's surge: the ILC traces' hands surge 0.48 m/s² at the step rate (median),
    about a third of the pelvis's, and lag it [E]."""
    arm_lateral_hz: tuple[float, float] = (0.15, 0.25)
    """The same sideways: the hand stays put while the trunk sways and leans under it at
    the stride rate (the 16 ILC traces' hands: 0.34 m/s² at the stride rate, median;
    their twins 0.34) [E]."""
    arm_damping: tuple[float, float] = (0.2, 0.4)
    """Range of the damping ratio of that hold, drawn per use [E]."""
    yaw_wander_deg: float = 2.0
    """RMS of the hand's slow turn about the vertical (over about a second) away
    from its drawn misalignment [E]: walking straight, the ILC traces' phones turn
    2.45° (median) about their 2 s running median heading, integrated from the
    gyro alone, where a hand that only followed the trunk turned 1.7°."""
    pitch_wander_deg: float = 3.0
    """RMS of the hand's slow tilt of the screen while walking, over the yaw wander's
    time scale [E]: the ILC traces' flat-held phones pitch at 0.14 rad/s at 0.3–1.3 Hz
    (median), a hand without it at 0.04. Standing, the hand holds the screen still."""
    yaw_wander_s: float = 0.25
    """Time scale (the smoothing σ) of that turn: it wanders over a second or two,
    slower than the stride [E]."""
    elbow_out_deg: tuple[float, float] = (5.0, 20.0)
    """Range of the upper arm's abduction, drawn per use: the elbow is held a little
    out from the side, so the upper arm hangs from the shoulder down and outward [E]."""
    twist_hz: tuple[float, float] = (4.0, 6.0)
    """Range of the natural frequency at which the shoulder's rotators hold the upper
    arm against twisting about its own axis (humeral rotation), drawn per use:
    forearm, hand and phone (≈ 1.6 kg, ≈ 0.07 kg·m² about that axis) on a rotational
    stiffness of 45–100 N·m/rad [E]. At 2.5–4.5 Hz the twins of the ILC traces moved
    sideways at the step rate twice as much as the real phones (0.55 against 0.25 m/s²)."""
    twist_damping: tuple[float, float] = (0.2, 0.4)
    """Range of that twist's damping ratio, drawn per use [E]."""
    shoulder_hz: tuple[float, float] = (4.0, 6.0)
    """Range of the natural frequency at which the shoulder's flexors hold the whole
    arm, hand and phone against turning about the shoulder's lateral axis, drawn per
    use: ≈ 0.3 kg·m² about the shoulder (a 70 kg walker's) on a flexion stiffness of
    180–410 N·m/rad [E]. The arm's weight lies ahead of the shoulder, so each vertical
    jolt of the trunk turns it: the hand lags down and back as the shoulder is thrown
    up, and its reaction moves it up and forward with the jolt. The 16 ILC traces' held
    phones surge in step with their vertical acceleration (coherence 0.6–0.85; per m/s²
    of it 0.16, 0.20, 0.22 at +24°, −35°, −63° at the step rate and its 2nd and 3rd
    harmonics, medians), which no spring fore and aft gives; their twins 0.17, 0.16,
    0.26 at −15°, −44°, −77° (held stiff at the shoulder: 0.06 at +163° at the 2nd)."""
    shoulder_damping: tuple[float, float] = (0.3, 0.5)
    """Range of that hold's damping ratio, drawn per use [E]."""
    head_flexion_deg: tuple[float, float] = (31.0, 39.0)
    """Range of the neck's flexion over the phone, drawn per use (REALISM §6.1): the
    head bends forward about the base of the neck, taking the eyes forward and down;
    the eyes look the rest of the gaze's way down in their orbits."""

    def rest_place(self, h: float, reach_m: float, gaze: float, flexion: float) -> NDArray:
        """The phone's rest place in the body frame, from the pelvis: where the eyes of a
        head bent by ``flexion`` rad look down at it, ``gaze`` rad below the horizontal,
        ``reach_m`` away, a little toward the holding hand (``h``: body height, m)."""
        forward, up = bent_eyes(flexion)
        height = (NECK_H + up - PELVIS_HEIGHT_RATIO) * h - reach_m * math.sin(gaze)
        return np.array(
            [forward * h + reach_m * math.cos(gaze), 0.02 * body_side(self.hand), height]
        )

    def forearm_axes(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Unit vectors in the body frame along the forearm (elbow → hand) and across it
        (the way its swing about the elbow moves the hand, up and back)."""
        rise, inward = math.radians(self.forearm_rise_deg), math.radians(self.forearm_inward_deg)
        level = np.array([math.cos(inward), -body_side(self.hand) * math.sin(inward), 0.0])
        along = math.cos(rise) * level + [0.0, 0.0, math.sin(rise)]
        across = -math.sin(rise) * level + [0.0, 0.0, math.cos(rise)]
        return along, across

    def pose(self, body: BodyTrajectory, rng: np.random.Generator) -> ModePose:
        h, rate = body.height_m, body.rate_hz
        reach = rng.uniform(*self.reading_distance_m)
        gaze = math.radians(rng.uniform(*self.gaze_down_deg))
        rest = self.rest_place(h, reach, gaze, math.radians(rng.uniform(*self.head_flexion_deg)))
        side = body_side(self.hand)
        along, across = self.forearm_axes()
        coupling = rng.uniform(*self.trunk_coupling)
        yaw = body.heading + coupling * (body.yaw - body.heading)
        frame = limbs.body_frame(yaw)
        # Where the trunk would carry the hand and the elbow (leaning with it, bouncing
        # and swaying within each step, turning with the part of its yaw the hand
        # follows), and where the walk's path would.
        # The arm passes the hand's difference on horizontally as a damped spring,
        # fore-aft and sideways; vertically the hand rides with the elbow, which hangs
        # from the shoulder at the holding side, so it rises and falls with the
        # trunk's sideways lean too.
        trunk = limbs.compose(frame, limbs.lean_sideways(body.roll))
        path = limbs.body_frame(body.heading)

        def bob(point: NDArray[np.float64]) -> NDArray[np.float64]:
            """How high a trunk point rides over its place on the path: bounce plus lean."""
            lean = limbs.apply(trunk, point) - limbs.apply(path, point)
            return body.gait_offset[:, 2] + lean[:, 2]

        on_path = body.pos - body.gait_offset + limbs.apply(path, rest)
        shake = body.pos + limbs.apply(trunk, rest) - on_path
        elbow_rest = rest - self.forearm_m * along
        shake[:, 2] = bob(elbow_rest)
        ahead = (np.cos(body.heading), np.sin(body.heading))
        fwd, left = limbs.to_body(shake[:, :2], ahead).T
        arm_damping = rng.uniform(*self.arm_damping)
        fwd = limbs.transmitted(fwd, rng.uniform(*self.arm_forward_hz), arm_damping, rate)
        left = limbs.transmitted(left, rng.uniform(*self.arm_lateral_hz), arm_damping, rate)
        c, s = ahead
        held = on_path + np.column_stack([fwd * c - left * s, fwd * s + left * c, shake[:, 2]])
        # The elbow, behind the held hand along the forearm.
        elbow = held - limbs.apply(frame, self.forearm_m * along)
        acc = limbs.acceleration(elbow, body.t)
        facing = (np.cos(yaw), np.sin(yaw))
        horiz = limbs.to_body(acc, facing)
        up_across = horiz[:, 0] * across[0] + horiz[:, 1] * across[1] + acc[:, 2] * across[2]
        swing = limbs.oscillator(
            -up_across / self.forearm_m,
            rng.uniform(*self.elbow_natural_hz),
            rng.uniform(*self.elbow_damping),
            rate,
        )
        lever = np.cos(swing)[:, None] * along + np.sin(swing)[:, None] * across
        pos = elbow + limbs.apply(frame, self.forearm_m * lever)
        # The upper arm hangs down and out from the shoulder, so the forearm and hand
        # twist about it (humeral rotation) under the elbow's acceleration across
        # them: the hand moves across the forearm, mostly sideways, and the phone
        # turns about the upper arm. As the arm is abducted, the twist's direction
        # leans out of the horizontal, and every vertical jolt drives it too: real
        # held phones move sideways at about a third of their vertical jolts above
        # 3 Hz, and at the step rate at 0.04–0.1 of the bounce, in step with it.
        out = math.radians(rng.uniform(*self.elbow_out_deg))
        upper_arm = np.array([0.0, side * math.sin(out), -math.cos(out)])
        across_arm = np.cross(upper_arm, self.forearm_m * along)  # hand motion per radian
        elbow_acc = np.column_stack([horiz, acc[:, 2]])
        twist = limbs.oscillator(
            -(elbow_acc @ across_arm) / (across_arm @ across_arm),
            rng.uniform(*self.twist_hz),
            rng.uniform(*self.twist_damping),
            rate,
        )
        pos += limbs.apply(frame, twist[:, None] * across_arm)
        # The whole arm turns about the shoulder under the trunk's vertical jolts: its
        # weight ahead of the shoulder takes the moment of their inertial force. (Its
        # fore-aft hold is the soft spring above; driving this one by the surge too
        # would count that twice. The thorax's own pitch, which the turn rides on, is
        # not in the drive either: its angular acceleration, ≈ 8 rad/s² at the step
        # rate, is of the drive's size, a coupling left out.)
        shoulder = shoulder_joint(h, side)
        lever_arm, inertia = arm_about_shoulder(shoulder, elbow_rest, rest, along, h)
        flex = limbs.oscillator(
            lever_arm * limbs.acceleration(bob(shoulder), body.t) / inertia,
            rng.uniform(*self.shoulder_hz),
            rng.uniform(*self.shoulder_damping),
            rate,
        )
        # + about the body's y tips the hand down and back, along y × (hand − shoulder).
        reach_xz = rest - shoulder
        pos += limbs.apply(frame, flex[:, None] * np.array([reach_xz[2], 0.0, -reach_xz[0]]))
        # The hand's acceleration on its offset from the wrist: angular drive a·d/(d² + ρ²).
        hand_acc = limbs.acceleration(pos, body.t)
        hand_horiz = limbs.to_body(hand_acc, facing)
        d, rho = self.wrist_offset_m, self.wrist_gyration_m
        gain = d / (d**2 + rho**2)
        damping = rng.uniform(*self.wrist_damping)
        hand_across = (
            hand_horiz[:, 0] * across[0] + hand_horiz[:, 1] * across[1] + hand_acc[:, 2] * across[2]
        )
        nod = limbs.oscillator(
            -gain * hand_across,
            rng.uniform(*self.wrist_pitch_hz),
            rng.uniform(*self.wrist_pitch_damping),
            rate,
        )
        grip = math.radians(rng.uniform(-self.grip_roll_deg, self.grip_roll_deg))
        # Sideways, the hand's acceleration turns the phone about the vertical (on the
        # offset along the hand). About the forearm the phone rocks on its centre of
        # mass's offsets from the axis: the vertical acceleration on the offset toward
        # the midline, the sideways one on the height above the palm.
        turn = limbs.oscillator(
            -gain * hand_horiz[:, 1], rng.uniform(*self.wrist_turn_hz), damping, rate
        )
        # The centre of mass toward the midline (phone x: −x for the right hand) and
        # above the palm (phone z). An acceleration a of the hand turns the phone about
        # its long axis (y) by (x·a_up + z·a_left)/(x² + z² + ρ²): the inertial force
        # −m·a acts at the offsets (phone x is the body's right).
        thumb, palm = side * self.thumb_offset_m, self.palm_height_m
        rock = limbs.oscillator(
            (thumb * hand_across + palm * hand_horiz[:, 1]) / (thumb**2 + palm**2 + rho**2),
            rng.uniform(*self.wrist_roll_hz),
            damping,
            rate,
        )
        misalign = math.radians(rng.normal(0.0, self.misalignment_deg))
        n = len(body.t)
        pos += limbs.tremor(n, rate, 1e-3 * self.tremor_mm, rng)
        tremor = limbs.tremor(n, rate, math.radians(self.tremor_deg), rng)
        wander = math.radians(self.yaw_wander_deg) * limbs.slow_noise(
            n, rate, rng, self.yaw_wander_s
        )
        tilt = math.radians(self.pitch_wander_deg) * body.gait_envelope
        tilt *= limbs.slow_noise(n, rate, rng, self.yaw_wander_s)
        rot = limbs.compose(
            frame,
            # The twist first, about the upper arm as the hand's displacement took it.
            limbs.from_rotvec(twist[:, None] * upper_arm),
            limbs.lean_sideways(coupling * body.roll),
            # The thorax's forward lean within each step: the arm passes it on.
            limbs.about("y", body.pitch + flex),
            limbs.body_frame(misalign + wander + turn),
            limbs.about("z", -np.pi / 2),
            limbs.about("x", math.radians(self.pitch_deg) + swing + nod + tilt),
            limbs.about("y", grip + rock),
            limbs.from_rotvec(tremor),
        )
        return ModePose(pos=pos, rot=limbs.rotation(rot), light_exposure=np.ones(n))


@register_mode
@dataclass(kw_only=True, frozen=True)
class Calling(CarryMode):
    """Held at the ear during a call (REALISM §6.1 calling row, §3.5).

    The phone moves with the head. The head rides on the trunk (its bounce,
    sideways lean and yaw) through the neck, stiff in translation (a damped spring of
    ``neck_natural_hz``: the heel strikes' harmonics pass, softened), and it
    nods and rocks on the neck: the trunk's acceleration acts on the head's
    centre of mass, ahead of and above the atlas joint, against the neck's
    muscles (``head_natural_hz``), which steady the head but do not hold it
    still (:func:`~.limbs.oscillator`).
    """

    name: ClassVar[str] = "calling"
    casts_body_shadow: ClassVar[bool] = False  # its exposure is the head's shade
    ear: Literal["right", "left"] = "right"
    """The ear the phone is held to; its screen faces the head."""
    tilt_deg: float | None = None
    """Tilt of the long axis from vertical (top toward the back of the head);
    None draws it uniformly from 30–60° per use."""
    light_exposure_range: tuple[float, float] = (0.05, 0.2)
    """Range of the head-shadow factor, drawn per use (5–20 % of the light)."""
    neck_natural_hz: tuple[float, float] = (6.0, 9.0)
    """Range of the head's natural frequency in translation on the neck, drawn per use [E]."""
    neck_damping: tuple[float, float] = (0.4, 0.6)
    """Range of its damping ratio, drawn per use [E]."""
    head_natural_hz: tuple[float, float] = (2.0, 3.0)
    """Range of the head's natural frequency in nodding and rocking on the neck [E]."""
    head_damping: tuple[float, float] = (0.25, 0.45)
    """Range of their damping ratio, drawn per use [E]."""
    head_offset_m: float = 0.03
    """Offset of the head's centre of mass ahead of (and, for rocking, beside) the
    atlas joint's axis [E]."""
    head_gyration_m: float = 0.08
    """Radius of gyration of the head (with hand and phone) about its centre of mass [E]."""
    trunk_coupling: float = 0.8
    """Fraction of the trunk's yaw oscillation the head follows: it turns with the
    thorax, which turns a little less than the pelvis [E]."""

    def pose(self, body: BodyTrajectory, rng: np.random.Generator) -> ModePose:
        h, rate, side = body.height_m, body.rate_hz, body_side(self.ear)
        yaw = body.heading + self.trunk_coupling * (body.yaw - body.heading)
        frame = limbs.body_frame(yaw)
        # The phone's centre: beside the head, a little ahead of and below the ear.
        offset = np.array([0.05, 0.09 * side, (EAR_H - 0.02 - PELVIS_HEIGHT_RATIO) * h])
        # Where the trunk carries the head: the neck's base leans with the trunk.
        trunk = limbs.compose(frame, limbs.lean_sideways(body.roll))
        carried = body.pos + limbs.apply(trunk, offset)
        acc = limbs.acceleration(carried, body.t)
        natural, damping = rng.uniform(*self.neck_natural_hz), rng.uniform(*self.neck_damping)
        # The head's lag behind the carried point: ü + 2ζωu̇ + ω²u = −a_carried.
        lag = limbs.oscillator(-acc, natural, damping, rate)
        pos = carried + lag
        head_acc = acc + limbs.acceleration(lag, body.t)
        horiz = limbs.to_body(head_acc, yaw)
        d, r = self.head_offset_m, self.head_gyration_m
        gain = d / (d**2 + r**2)
        f_head, z_head = rng.uniform(*self.head_natural_hz), rng.uniform(*self.head_damping)
        nod = limbs.oscillator(-gain * head_acc[:, 2], f_head, z_head, rate)
        rock = limbs.oscillator(gain * horiz[:, 1], f_head, z_head, rate)
        tilt = math.radians(self.tilt_deg if self.tilt_deg is not None else rng.uniform(30.0, 60.0))
        # Top up and back, screen toward the head (−side), x = y × z ≈ ∓forward.
        y = np.array([-math.sin(tilt), 0.0, math.cos(tilt)])
        z = np.array([0.0, -side, 0.0])
        rot = limbs.compose(
            frame,
            limbs.about("x", rock),
            limbs.about("y", nod),
            limbs.from_axes(np.cross(y, z), y, z),
        )
        base = rng.uniform(*self.light_exposure_range)
        light = base * np.exp(0.2 * limbs.slow_noise(len(body.t), rate, rng))
        return ModePose(pos=pos, rot=limbs.rotation(rot), light_exposure=light)


@register_mode
@dataclass(kw_only=True, frozen=True)
class Dangling(CarryMode):
    """In the hand of a swinging arm (REALISM §6.1 swinging row).

    The arm is a rigid pendulum about the shoulder in the walking plane — a rod
    of 3 kg with 0.6 kg of hand and phone at the grip — with muscle tone and
    damping, simulated with pymunk at ``physics_rate_hz`` in the shoulder's
    accelerating frame (gravity minus the shoulder's acceleration). A shoulder
    torque drives it at stride frequency; the torque is the linearised
    pendulum's inverse response to a swing of ``swing_deg``, so the swing is
    close to that amplitude, in antiphase with the same-side leg and a little behind
    it (``swing_lag``), while starting, stopping, bouncing and heel strikes perturb
    it as they would. The forearm hangs from the elbow, a little bent, held by
    muscle like a damped spring
    (:func:`~.limbs.oscillator`): the upper arm's swing whips it on and gravity pulls
    it back under the elbow as the upper arm leans (the linearised double pendulum,
    :func:`~.anthropometry.hanging_forearm`), and it pronates as the arm swings back
    and supinates forward. The hand hangs from the wrist in the same way, in two
    planes: in the swing's it is whipped on by the forearm, and in both it is shaken
    by what the arm passes down from the shoulder (the trunk's bounce, sway and
    heel-strike jolts) and by the arm's sideways arc, and gravity pulls it back under
    the wrist. Those turns about axes through the wrist, a hand's length from the
    phone, turn the phone about its small axes with little linear acceleration.

    Against real swinging phones (``leaderboards/realism.md``): with the elbow and
    wrist firm (damped near critically), the arm's swing ±12–18°, the elbow bent
    10–20° and the swing lagging the legs, the bundled and generated sites' walks put
    0.60–0.70 of ‖a‖'s power at the step rate and 0.07–0.12 at the stride rate (the
    Oxford swinging-arm walks: 0.68–0.70 and 0.12; with the ringing elbow and wrist
    of before, 0.46–0.65 and 0.16–0.19), and turn the phone at 1.2–1.5 / 1.0–1.3 /
    0.7–0.9 rad/s per axis, inside the 18 swinging-hand walks of the Tyrex benchmark
    (1.16–2.39 / 0.73–1.43 / 0.38–1.15). The phone lies diagonally across the palm,
    its top forward and down and its screen outward, the palm turned a little back.
    """

    name: ClassVar[str] = "dangling"
    hand: Literal["right", "left"] = "right"
    """The hand holding the phone."""
    swing_deg: float | None = None
    """Swing amplitude about the shoulder; None draws it from ``swing_range_deg`` per use."""
    swing_range_deg: tuple[float, float] = (12.0, 18.0)
    """Range of the swing amplitude about the shoulder, drawn per use when ``swing_deg``
    is None [E]. A hand that carries a phone swings it gently: the swing's centripetal
    and tangential accelerations raise the mean ‖a‖ by 0.8–1.5 m/s² on the simulated
    walks (by 1.0–1.6 at 15–25°), where the 18 Tyrex walks' mean ‖a‖ is 10.1–11.7
    m/s² (median 11.06) and the Oxford swinging-arm walker's 0.42 m/s² above his own
    phone held in front."""
    swing_lag: tuple[float, float] = (0.04, 0.12)
    """Range of how late the arm's swing comes after the legs', as a fraction of a
    stride, drawn per use: the arm is furthest forward this long after the other
    foot's heel strike [E]. The later the swing, the nearer the hand passes under
    the shoulder (its centripetal pull greatest) to the moment the body's weight is
    taken on the leading leg, and the more the swing adds to the step's jolt in ‖a‖.
    Two real figures pull apart, both from the one walker of the Oxford swinging-arm
    walks. Referred to their foot switches, the swinging hand's step-rate ‖a‖ is 1.10
    times the same walker's phone held in front; the simulated hand's is 0.66–0.70
    times at this lag, 0.41–0.59 with none, 0.77–0.82 at 0.08–0.17. But at 0.08–0.17
    a detector that waits 0.5 s between steps loses 21 % of the simulated walks'
    steps, far from the real 43–45 %; at this lag it loses 38 %."""
    palm_turn_deg: tuple[float, float] = (20.0, 45.0)
    """Range of the hand's turn about the forearm, from the palm facing the thigh
    toward facing back (a relaxed, hanging forearm is a little pronated), drawn
    per use [E]. It tips the screen's normal off the swing's axis, so the swing
    shows on the phone's other axes too."""
    diagonal_deg: tuple[float, float] = (20.0, 50.0)
    """Range of the phone's slant across the palm, its top from pointing forward
    toward pointing down the fingers (curled fingers hold an object diagonally
    across the palm, the oblique palmar grip), drawn per use [E]. With the palm's
    turn the swing's rate spreads over the phone's axes about as real swinging
    phones show it (the Tyrex walks' median 1.72 / 1.04 / 0.68 rad/s)."""
    grip_deg: float = 8.0
    """SD of the grip's misalignment about each axis, drawn per use [E]."""
    damping_ratio: float = 0.25
    """Damping of the arm pendulum (it settles within a few swings after a stop) [E]."""
    tone_nm_per_rad: float = 5.0
    """Shoulder muscle stiffness, raising the arm's natural frequency to ≈ 0.8 Hz [E]."""
    physics_rate_hz: float = 30.0
    """Step rate of the pymunk pendulum (upsampled with a C² spline)."""
    elbow_natural_hz: tuple[float, float] = (1.0, 1.15)
    """Range of the hanging forearm's natural frequency about the elbow, drawn per use:
    its gravity pendulum (0.93 Hz for a 1.75 m walker,
    :func:`~.anthropometry.hanging_forearm`), stiffened a little by muscle tone [E].
    A free arm's elbow flexes and extends 29.7 ± 10.2° peak to peak in normal gait
    (Kang et al., Clin Shoulder Elb 26:126, 2023). A stiffer elbow puts its resonance
    near the step rate: at 1.3 Hz (with the elbow less damped than now) the bundled
    sites' walks put 0.29–0.50 of ‖a‖'s power at the step rate and 0.21–0.29 at the
    stride rate (the Oxford swinging-arm walks: 0.68–0.70 and 0.12), and on some walks
    ‖a‖'s spectral peak leaves the step rate."""
    elbow_damping: tuple[float, float] = (0.65, 0.8)
    """Range of the elbow's damping ratio, drawn per use [E]. The elbow's
    flexors and extensors co-contract to steady the forearm and the phone in the
    hand, so it is damped well below its own ringing, and the step-rate jolts that
    reach it through the shoulder are passed on, not amplified: the elbow flexes
    14–17° peak to peak per stride, less than a free arm's 29.7 ± 10.2° (above); at
    0.4–0.55 (with a swing lagging 1/8 stride) it flexes 19–26° and ‖a‖ keeps
    0.61–0.67 of its power at the step rate where 0.65–0.8 keeps 0.66–0.69 (the Oxford
    swinging-arm walks 0.68–0.70); at 0.25–0.35 it flexes 43–52°."""
    elbow_flexion_deg: tuple[float, float] = (10.0, 20.0)
    """Range of the elbow's mean flexion while the arm swings, drawn per use: walkers
    keep the elbow near full extension (JEB 222:jeb197228, 2019), not locked [E]. The
    hand then hangs a little ahead of the shoulder, so the swing's tangential
    acceleration has an upward share that rises and falls once a stride: 0.07–0.12 of
    ‖a‖'s power at the stride rate on the bundled and generated sites (the Oxford
    swinging-arm walks: 0.12; with the elbow straight about half that)."""
    twist_deg: tuple[float, float] = (5.5, 8.5)
    """Range of the forearm's pronation–supination amplitude with the swing, drawn
    per use: 11–17° peak to peak (14.2 ± 3.2° measured in normal gait, Kang et
    al. 2023)."""
    arc_deg: tuple[float, float] = (5.0, 12.0)
    """Range of the arm's sideways swing, toward the midline forward and out behind
    (the hand's arc crosses in front of the thigh), drawn per use [E]."""

    wrist_natural_hz: tuple[float, float] = (2.5, 3.5)
    """Range of the hand's natural frequency about the wrist (a short, light
    pendulum held by the wrist's muscles), drawn per use for each of its two
    planes: flexion–extension in the swing's plane and the sideways turn in the
    frontal plane (with the palm toward the thigh, flexion–extension again; with
    it turned back, radial–ulnar deviation) [E]."""
    wrist_damping: tuple[float, float] = (0.6, 0.7)
    """Range of the wrist's damping ratio, drawn per use for each plane [E]: a hand
    gripping a phone holds its wrist firm. At 0.2–0.4 the hand rang at its natural
    frequency under each heel strike and spread ‖a‖'s power off the step rate."""

    _HAND_COM: ClassVar[float] = 0.05  # wrist to the centre of hand and phone, of body height
    _ROD_KG: ClassVar[float] = 3.0
    _HAND_KG: ClassVar[float] = 0.6

    def pose(self, body: BodyTrajectory, rng: np.random.Generator) -> ModePose:
        h, side = body.height_m, body_side(self.hand)
        length = ARM_LENGTH * h
        frame = limbs.body_frame(body.yaw)
        shoulder = body.pos + limbs.apply(frame, shoulder_joint(h, side))
        swing = math.radians(
            self.swing_deg if self.swing_deg is not None else rng.uniform(*self.swing_range_deg)
        )
        lag = rng.uniform(*self.swing_lag)
        theta = self._simulate(body, shoulder, length, swing * body.gait_envelope, side, lag)
        # The forearm about the elbow (anthropometry.hanging_forearm): the upper arm's
        # angular acceleration whips it on, and gravity pulls it back under the elbow
        # as the upper arm leans: at the stride rate it takes back about half the whip.
        upper = UPPER_ARM * h
        forearm = length - upper
        gravity, whip = hanging_forearm(h)
        theta_acc = limbs.acceleration(theta, body.t)
        flex = limbs.oscillator(
            -(1.0 + whip) * theta_acc - gravity * theta,
            rng.uniform(*self.elbow_natural_hz),
            rng.uniform(*self.elbow_damping),
            body.rate_hz,
        )
        # Held a little bent, the elbow swings about its flexion and cannot
        # straighten past the straight arm (a smooth floor at zero).
        bent = math.radians(rng.uniform(*self.elbow_flexion_deg))
        if bent > 0.0:
            flex = _no_hyperextension(bent + flex, bent)
        arm = theta + flex

        def _down(angle: NDArray[np.float64]) -> NDArray[np.float64]:
            return np.column_stack([np.sin(angle), np.zeros_like(angle), -np.cos(angle)])

        # The forearm turns and arcs with its own swing, so the three rotations
        # keep in step: −1 back … +1 forward at a full swing.
        swung = arm - bent
        phase = swung / max(float(np.percentile(np.abs(swung), 98)), 1e-9)
        twist = math.radians(rng.uniform(*self.twist_deg)) * phase
        lean = side * math.radians(rng.uniform(*self.arc_deg)) * phase  # toward +y (left)
        arc = limbs.about("x", lean)
        grip_lever = self._HAND_COM * h
        to_wrist = upper * _down(theta) + (forearm - grip_lever) * _down(arm)
        arm_frame = limbs.compose(frame, arc)
        # The hand (with the phone) hangs from the wrist, a short pendulum held by
        # the wrist's muscles in two planes: flexion in the swing's plane and
        # sideways in the frontal one. What moves the wrist drives it: the
        # forearm's own swing and arc, and everything the arm passes down from the
        # shoulder (the trunk's bounce, sway and heel-strike jolts), as the
        # wrist's acceleration across the hand on the lever of the hand's centre
        # of mass, and gravity across it: θ̈_hand = −(arm's angular acceleration)
        # − (a + g)⊥ / lever, with a the wrist's acceleration and g gravity's pull
        # (its share from the hand's own turn is in the wrist's natural frequency).
        wrist = shoulder + limbs.apply(arm_frame, to_wrist)
        wrist_pull = limbs.acceleration(wrist, body.t) + np.array([0.0, 0.0, _G])
        ahead = limbs.apply(
            arm_frame, np.column_stack([np.cos(arm), np.zeros_like(arm), np.sin(arm)])
        )
        beside = limbs.apply(arm_frame, [0.0, 1.0, 0.0])

        def wrist_turn(arm_angle: NDArray[np.float64], across: NDArray[np.float64]):
            # One plane of the wrist: a damped spring under the arm's angular
            # acceleration in that plane and the wrist's acceleration and gravity
            # across the hand.
            drive = (
                -limbs.acceleration(arm_angle, body.t)
                - np.einsum("ij,ij->i", wrist_pull, across) / grip_lever
            )
            natural = rng.uniform(*self.wrist_natural_hz)
            return limbs.oscillator(drive, natural, rng.uniform(*self.wrist_damping), body.rate_hz)

        flexion = wrist_turn(arm, ahead)  # in the swing's plane
        deviation = wrist_turn(lean, beside)  # sideways, in the frontal plane
        hand = arm + flexion
        hand_turn = limbs.compose(limbs.about("y", -hand), limbs.about("x", deviation))
        limb = to_wrist + limbs.apply(hand_turn, [0.0, 0.0, -grip_lever])
        pos = shoulder + limbs.apply(arm_frame, limb)
        # At the bottom of the swing: x down (right hand) or up (left), y
        # forward, z outward.
        base = limbs.from_axes([0.0, 0.0, side], [1.0, 0.0, 0.0], [0.0, side, 0.0])
        # The palm turned back about the forearm (x), the phone slanted across it (z).
        grip = limbs.compose(
            limbs.about("x", side * math.radians(rng.uniform(*self.palm_turn_deg))),
            limbs.about("z", side * math.radians(rng.uniform(*self.diagonal_deg))),
            limbs.from_rotvec(np.radians(rng.normal(0.0, self.grip_deg, 3))),
        )
        rot = limbs.compose(arm_frame, hand_turn, limbs.about("z", side * twist), base, grip)
        return ModePose(pos=pos, rot=limbs.rotation(rot), light_exposure=np.ones(len(body.t)))

    def _simulate(
        self,
        body: BodyTrajectory,
        shoulder: NDArray[np.float64],
        length: float,
        amplitude: NDArray[np.float64],
        side: float,
        lag: float,
    ) -> NDArray[np.float64]:
        """Swing angle (rad, + forward) at the body's samples, ``lag`` strides behind
        the legs' antiphase."""
        m_rod, m_hand = self._ROD_KG, self._HAND_KG
        mass = m_rod + m_hand
        com = (m_rod * length / 2 + m_hand * length) / mass
        inertia = m_rod * length**2 / 3 + m_hand * length**2  # about the shoulder
        stiffness = mass * _G * com + self.tone_nm_per_rad
        damping = 2.0 * self.damping_ratio * math.sqrt(stiffness * inertia)

        # Drive: θ_d = A·cos(2π·(stride phase − lag)) (the right arm is forward
        # just after the left heel strike) through the inverse of I·θ̈ + c·θ̇ + k·θ = τ.
        t = body.t
        stride = body.step_phase / 2.0
        omega = 2.0 * np.pi * limbs.derivative(stride, t)
        cyc = 2.0 * np.pi * (body.stride_phase + (0.0 if side < 0 else 0.5) - lag)
        torque = amplitude * (
            (stiffness - inertia * omega**2) * np.cos(cyc) - damping * omega * np.sin(cyc)
        )
        acc = limbs.acceleration(shoulder, t)
        fwd = np.cos(body.yaw) * acc[:, 0] + np.sin(body.yaw) * acc[:, 1]  # limbs.to_body's forward

        dt = 1.0 / self.physics_rate_hz
        t_phys = t[0] + np.arange(math.ceil((t[-1] - t[0]) / dt) + 1) * dt
        # The shoulder's acceleration, averaged over a physics step so that
        # heel-strike spikes are not aliased.
        win = max(1, round(body.rate_hz * dt))
        smooth = [np.convolve(x, np.ones(win) / win, mode="same") for x in (fwd, acc[:, 2])]
        gx = -np.interp(t_phys, t, smooth[0])
        gy = -_G - np.interp(t_phys, t, smooth[1])
        tau = np.interp(t_phys, t, torque)

        with pymunk_space() as space:
            shoulder = pymunk.Body(body_type=pymunk.Body.STATIC)
            arm = pymunk.Body(mass, inertia - mass * com**2)
            arm.center_of_gravity = (0.0, -com)
            space.add(shoulder, arm)
            space.add(pymunk.PivotJoint(shoulder, arm, (0.0, 0.0), (0.0, 0.0)))
            space.add(pymunk.DampedRotarySpring(shoulder, arm, 0.0, self.tone_nm_per_rad, damping))
            space.gravity = (float(gx[0]), float(gy[0]))
            arm.torque = float(tau[0])
            space.step(dt)  # the first step through pymunk: it checks the bodies once
            # Then Chipmunk directly: pymunk's property and step wrappers cost more
            # than the physics here, and this space has no callbacks (same results).
            # The loop runs some ten thousand times a walk: its names are local.
            c_space, c_arm = space._space, arm._body
            get_angle, set_gravity = _CP.cpBodyGetAngle, _CP.cpSpaceSetGravity
            set_torque, step = _CP.cpBodySetTorque, _CP.cpSpaceStep
            angle = [0.0]
            for ax, ay, tk in zip(gx[1:].tolist(), gy[1:].tolist(), tau[1:].tolist(), strict=True):
                angle.append(get_angle(c_arm))
                set_gravity(c_space, (ax, ay))
                set_torque(c_arm, tk)
                step(c_space, dt)
        return CubicSpline(t_phys, angle)(t)


def _no_hyperextension(flex: NDArray[np.float64], bent: float) -> NDArray[np.float64]:
    """Elbow flexion (rad) kept above zero by a softplus whose scale is a quarter of
    the mean flexion ``bent``: within 2 % of ``flex`` above three quarters of
    ``bent``, bending smoothly onto zero below, so the forearm's angle keeps its
    continuous derivatives."""
    scale = 0.25 * bent
    return scale * np.logaddexp(0.0, flex / scale)


# The pocket's mode lives in its own module; registered here, after the others, as
# it always was (the registry keeps the order of registration).
register_mode(Pocketed)
