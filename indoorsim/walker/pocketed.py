"""The ``pocketed`` carrying mode: the phone in a front trouser pocket, riding on the thigh.

Numbers from REALISM §5 (hip angles) and §6.1 (pocket row); the mode is registered
with the other built-in modes by :mod:`indoorsim.walker.carry_modes`, which re-exports
it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numba
import numpy as np
from numpy.typing import NDArray

from indoorsim.util import quaternion as quat_ops
from indoorsim.walker import limbs
from indoorsim.walker.anthropometry import HIP_H, HIP_HALF_WIDTH, body_side
from indoorsim.walker.gait import PELVIS_HEIGHT_RATIO, BodyTrajectory
from indoorsim.walker.handling import draw_pocket_stroke
from indoorsim.walker.hip_curves import HIP_FLEXION, HIP_ROTATION, PELVIC_LIST
from indoorsim.walker.modes import CarryMode, ModePose
from indoorsim.walker.motion import impulse_displacement

__all__ = ["Pocketed"]

_G = 9.81
# Where the phone sits in a front trouser pocket: along the thigh from the hip
# joint, and off the thigh's axis (m) [E].
_POCKET_ALONG_M, _POCKET_FRONT_M = 0.15, 0.07
# A phone as the pocket holds it: a plate of this length and width, its centre
# of mass this far off the thigh's surface (half a phone's thickness) (m).
_PHONE_LENGTH_M, _PHONE_WIDTH_M, _POCKET_LEVER_M = 0.15, 0.072, 0.004


@numba.njit(cache=True, error_model="numpy")
def _pocket_offset(sin_a, cos_a, sin_b, cos_b, jolt, shear, out):  # pragma: no cover - compiled
    """The phone's place from the hip joint in the pelvis frame, the thigh flexed by α
    (sin_a, cos_a) and the pocket β round the thigh from its front toward +y (sin_b,
    cos_b): along·thigh + front·(cos β·forward normal + sin β·lateral), less the
    jolt along the thigh and ``shear`` times it across the thigh's face. One pass
    over the samples.
    """
    for k in range(out.shape[0]):
        s, c, j = sin_a[k], cos_a[k], jolt[k]
        thigh = (s, 0.0, -c)
        normal = (c * cos_b[k], sin_b[k], s * cos_b[k])
        for i in range(3):
            v = _POCKET_ALONG_M * thigh[i] + _POCKET_FRONT_M * normal[i]
            # The jolt drives the phone up along the thigh and shakes the flesh under it.
            out[k, i] = v - j * (thigh[i] + shear * normal[i])


@dataclass(kw_only=True, frozen=True)
class Pocketed(CarryMode):
    """In a front trouser pocket (REALISM §6.1 pocket row, §5 hip angles).

    The phone rides on the thigh, which turns at the hip in all three planes
    over the gait cycle: flexion follows the hip's sagittal angle of normal gait
    (:data:`~.hip_curves.HIP_FLEXION`: slow extension through stance, quick flexion in
    swing, so the pitch rate is not a sinusoid), ab-/adduction follows at stride
    frequency with a drawn lag behind it, and the rotation about the thigh follows
    the hip's transverse-plane curve (:data:`~.hip_curves.HIP_ROTATION`: internal in loading
    response, external toward toe-off) on top of the pelvis's turn, which brings
    that side forward at its heel strike. The hip joint it hangs from rides on the
    pelvis, which lists sideways (:data:`~.hip_curves.PELVIC_LIST`). At the same-side heel
    strike the thigh stops against the ground and the phone jolts along it, and
    the flesh under the pocket shears round the thigh, rolling the pocket with it.

    The pocket lies on the front-outer face of the thigh (``pocket_yaw_deg``
    round it from the front), and the phone in it is a plate held at its deep
    end by the pocket's bottom and against the thigh by the cloth: it rocks on
    that hold, in its own plane, away from the thigh and about its own long axis
    (rolling on the thigh's rounded front), as a damped spring
    (:func:`~.limbs.oscillator`, ``wobble_hz``) under the inertial load of the thigh's
    acceleration and gravity on its centre of mass and of the thigh turning
    under it — heel strikes ring it, the swing's tangential acceleration tips it.
    """

    name: ClassVar[str] = "pocketed"
    casts_body_shadow: ClassVar[bool] = False  # its exposure is the fabric's
    side: Literal["right", "left"] | None = None
    """The pocket's side; None draws it per use."""
    thigh_swing_deg: float | None = None
    """Half the thigh's pitch range over the gait cycle; None draws it from
    18–23° per use (hip range 35–45° peak to peak)."""
    thigh_mean_deg: float = 5.0
    """Mean thigh flexion while walking (20–30° flexion at heel contact,
    10–20° extension late in stance)."""
    thigh_roll_deg: tuple[float, float] = (2.0, 3.5)
    """Range of the thigh's frontal-plane swing amplitude, drawn per use. Real pockets
    swing 6.7–11° peak to peak in the frontal plane, the phone's rocking on its hold
    included: with it the phone's frontal swing is 6–10° (median ≈ 8°) for this range."""
    roll_lag_deg: tuple[float, float] = (30.0, 45.0)
    """Range of its phase lag behind the pitch over the gait cycle, drawn per use:
    the low end of the 30–90° measured in real pockets. Pitch and roll out of phase
    cone, and turn the gyro heading by about π·pitch·roll·sin(lag) per stride (the
    area the tilt encloses): over the whole 30–90° that is 2–6°/stride with this
    swing and roll, while the same real pockets drift 0–2°/stride (typically 1.6);
    30–45° and this roll give 1.7–2 (median over walks)."""
    hip_rotation_deg: tuple[float, float] = (3.0, 5.0)
    """Range of the hip's rotation amplitude about the thigh (:data:`~.hip_curves.HIP_ROTATION`,
    relative to the pelvis), drawn per use: normal gait's hip transverse-plane range
    is 8–15° (Kadaba et al. 1990), the low end here because the pelvis's own turn
    (±3–8°, the trunk's counter-rotation) adds to it nearly in phase; with it and the
    pocket's roll at heel strike the phone turns 20–34° about the thigh per stride
    (median ≈ 24°; the thigh alone 12–23°, median ≈ 20°) against the 17–22° of real
    pockets [E]."""
    rotation_shift: float = 0.05
    """Largest shift of that rotation's curve along the gait cycle, drawn per use
    (fraction of a cycle) [E]."""
    pelvic_list_deg: tuple[float, float] = (3.0, 5.0)
    """Range of the pelvis's frontal-plane tilt amplitude (:data:`~.hip_curves.PELVIC_LIST`:
    ±3–5° in normal gait), drawn per use: it lifts and drops the hip joint that
    carries the thigh by a few millimetres, quickly in each loading response [E]."""
    top_down: bool | None = None
    """Phone inserted top first; None draws it per use."""
    screen_out: bool | None = None
    """Screen facing away from the thigh; None draws it per use."""
    pocket_yaw_deg: float | None = None
    """How far round the thigh, from its front toward the outside, the pocket
    and the phone lie; None draws it from 10–40° per use (a front pocket's
    opening is on the front-outer face) [E]."""
    slant_deg: float | None = None
    """The phone's long axis against the thigh's, in the pocket's plane; None
    draws it from ±(0–20°) per use [E]."""
    wobble_hz: tuple[float, float] = (6.0, 10.0)
    """Range of the natural frequency of the phone rocking on the pocket's hold away
    from the thigh and about its own long axis (cloth tension and the thigh's soft
    tissue), drawn per use [E]."""
    wobble_damping: tuple[float, float] = (0.12, 0.3)
    """Range of that rocking's damping ratio, drawn per use [E]."""
    plane_hz: tuple[float, float] = (5.5, 7.5)
    """Range of the natural frequency of its rocking in its own plane (its yaw in the
    pocket), drawn per use: a front pocket's bag is some 12–14 cm across, nearly
    twice a phone's width, so in that plane only the cloth's friction and the bag's
    tapering seams hold it, more softly than the cloth pressing it to the thigh [E].
    Kept clear of twice the step rate (3.4–4 Hz), which it would pump."""
    plane_damping: tuple[float, float] = (0.1, 0.2)
    """Range of that in-plane rocking's damping ratio, drawn per use: cloth sliding on
    cloth damps less than the thigh's soft tissue under the phone [E]."""
    impact_mps2: tuple[float, float] = (13.5, 28.0)
    """Range of the jolt along the thigh at the same-side heel strike, walking at
    ``impact_speed_mps``. With the thigh's own motion the phone then reads
    per-stride peaks of 3.1–3.2 g at 50 Hz near the usual pace (median over walks;
    2.9 g for slow walkers at 1.1 m/s, 3.7 g for brisk ones at 1.5 m/s), as real
    front pockets do (Oxford step-counter walks, 200–400 Hz: median 3.1 g;
    thigh-worn accelerometers 2–5 g)."""
    impact_speed_mps: float = 1.31
    """Walking speed at which ``impact_mps2`` applies: the heel lands harder the
    faster one walks, so each jolt scales with the speed at its heel strike (as the
    trunk's does, :func:`~.motion.intra_step_motion`, within 0.3–1.3 times), like the
    body's bounce, which grows with the step. 1.31 m/s is the usual pace (REALISM §5,
    Murtagh et al. 2021)."""
    impact_shear: tuple[float, float] = (0.1, 0.4)
    """Range of the jolt across the thigh's front face, as a share of the jolt
    along it: the braking at heel contact and the quadriceps' soft tissue
    shaking under the phone [E] (0.3–0.6 before the flesh's shear round the thigh,
    ``impact_roll``, took its share)."""
    impact_roll: tuple[float, float] = (0.25, 0.45)
    """Range of the jolt's shear of the flesh round the thigh under the pocket, as a
    share of the jolt along it (either way round, drawn per use): the pocket on the
    thigh's rounded front (radius ≈ 7 cm) rolls by that arc over the radius, 2–4° at
    a usual heel strike, as the quadriceps' soft tissue shakes after it. Rotation of
    thigh skin about the bone in gait reaches several degrees (soft-tissue artefact,
    Leardini et al., Gait Posture 21:212, 2005) [E]."""
    impact_width_s: float = 0.028
    """Width σ of that jolt: the thigh's soft tissue and the pocket's cloth spread it.
    The pulse's power peaks at 1/(√2·π·σ) ≈ 8 Hz, where real front pockets put it:
    the Oxford step-counter front-pocket walks, measured at 50 Hz, have 21–44 % of
    ‖a‖'s power above the 8th stride harmonic (≈ 7.5 Hz) and only 2–7 % at twice
    the step rate; a 35 ms pulse (peak 6.4 Hz) put 11–16 % there [D]."""
    light_exposure_range: tuple[float, float] = (0.001, 0.005)
    """Range of the fabric's light transmission, drawn per use."""

    def pose(self, body: BodyTrajectory, rng: np.random.Generator) -> ModePose:
        which = self.side if self.side is not None else ("left", "right")[int(rng.random() < 0.5)]
        h, side = body.height_m, body_side(which)
        # The pelvis counter-rotates against the trunk at stride frequency.
        pelvis = limbs.body_frame(2.0 * body.heading - body.yaw)
        env = body.gait_envelope
        swing = math.radians(
            self.thigh_swing_deg if self.thigh_swing_deg is not None else rng.uniform(18, 23)
        )
        # The leg's own gait cycle: 0 at its heel strike (stride phase 0 is the left one).
        own = np.mod(body.stride_phase - (0.5 if side < 0 else 0.0), 1.0)
        alpha = env * (math.radians(self.thigh_mean_deg) + swing * HIP_FLEXION(own))
        # Ab-/adduction goes through the cycle as quickly as flexion does (fast in
        # swing), a drawn fraction of a cycle behind it. (The draws keep the order
        # they had before the hip's rotation curve and the flesh's roll came in: the
        # new ones come after the old, so a seed keeps its walker's other draws.)
        roll_lag = rng.uniform(*self.roll_lag_deg) / 360.0
        delay = rng.uniform(-self.rotation_shift, self.rotation_shift)
        roll_amp = math.radians(rng.uniform(*self.thigh_roll_deg))
        rotate_amp = math.radians(rng.uniform(*self.hip_rotation_deg))
        roll = env * side * roll_amp * HIP_FLEXION(np.mod(own - roll_lag, 1.0))
        # The hip rotates the thigh internally in loading response and externally
        # toward toe-off (:data:`~.hip_curves.HIP_ROTATION`), on top of the pelvis's own turn,
        # which brings that side forward at its heel strike: internal is toward the
        # midline, −z on the left leg.
        twist = -env * side * rotate_amp * HIP_ROTATION(np.mod(own - delay, 1.0))
        hip = np.array([0.0, HIP_HALF_WIDTH * h * side, (HIP_H - PELVIS_HEIGHT_RATIO) * h])
        same_side = body.steps.foot.to_numpy() == ("R" if side < 0 else "L")
        t_hs = body.steps.t.to_numpy()[same_side]
        pace = np.interp(t_hs, body.t, body.speed) / self.impact_speed_mps
        peaks = rng.uniform(*self.impact_mps2, len(t_hs)) * np.clip(pace, 0.3, 1.3)
        jolt = impulse_displacement(body.t, t_hs, peaks, self.impact_width_s)
        pocket_yaw = math.radians(
            self.pocket_yaw_deg if self.pocket_yaw_deg is not None else rng.uniform(10, 40)
        )
        shear = rng.uniform(*self.impact_shear)
        list_amp = math.radians(rng.uniform(*self.pelvic_list_deg))
        top_down = self.top_down if self.top_down is not None else bool(rng.random() < 0.5)
        screen_out = self.screen_out if self.screen_out is not None else bool(rng.random() < 0.5)
        slant = math.radians(
            self.slant_deg
            if self.slant_deg is not None
            else rng.choice((-1.0, 1.0)) * rng.uniform(0.0, 20.0)
        )
        rocking = (rng.uniform(*self.wobble_hz), rng.uniform(*self.wobble_damping))
        roll_share = rng.uniform(*self.impact_roll) * rng.choice((-1.0, 1.0))
        sliding = (rng.uniform(*self.plane_hz), rng.uniform(*self.plane_damping))

        # The jolt also shears the flesh under the pocket round the thigh (either way):
        # the pocket, on the thigh's rounded front, rolls with it about the thigh.
        twist = twist - jolt * roll_share / _POCKET_FRONT_M
        # Round the thigh toward the outside (+y on the left leg), and with its twist.
        around = side * pocket_yaw + twist
        local = np.empty((len(alpha), 3))
        _pocket_offset(
            np.sin(alpha), np.cos(alpha), np.sin(around), np.cos(around), jolt, shear, local
        )
        # The hip joint rides on the pelvis, which tilts sideways with its list (the
        # loaded side up); the thigh hangs from it in its own frontal-plane angle.
        tilt = env * side * list_amp * PELVIC_LIST(own)
        rigid_pos = (
            body.pos
            + limbs.apply(limbs.compose(pelvis, limbs.about("x", tilt)), hip)
            + limbs.apply(limbs.compose(pelvis, limbs.about("x", roll)), local)
        )
        # Standing, top down, screen out: x right, y down, z forward.
        base = limbs.from_axes([0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0])
        placement = limbs.compose(
            limbs.about("y", -side * pocket_yaw),  # base y is down the thigh
            limbs.about("z", slant),
            limbs.about("y", 0.0 if screen_out else np.pi),
            limbs.about("z", 0.0 if top_down else np.pi),
        )
        rigid = limbs.compose(
            pelvis,
            limbs.about("x", roll),
            limbs.about("y", -alpha),
            limbs.about("z", twist),
            base,
            placement,
        )
        wobble, shift = self._wobble(body, rigid_pos, rigid, top_down, screen_out, rocking, sliding)
        pos = rigid_pos + limbs.apply(rigid, shift)
        rot = limbs.compose(rigid, wobble)
        light = np.full(len(body.t), rng.uniform(*self.light_exposure_range))
        # Pocketed and taken out along its long axis, the top first when it sits top down.
        stroke = draw_pocket_stroke(rng, np.array([0.0, 1.0 if top_down else -1.0, 0.0]))
        return ModePose(pos=pos, rot=limbs.rotation(rot), light_exposure=light, stroke=stroke)

    def _wobble(
        self,
        body: BodyTrajectory,
        pos: NDArray[np.float64],
        rot: limbs.Quat,
        top_down: bool,
        screen_out: bool,
        rocking: tuple[float, float],
        sliding: tuple[float, float],
    ) -> tuple[limbs.Quat, NDArray[np.float64]]:
        """The phone's rocking on the pocket's hold, and its centre's shift with it.

        In the phone's frame the hold is at its deep end, its centre of mass r =
        (0, ∓L/2, ±d) from there. Relative to the rigidly carried phone (specific
        force f at its centre, angular acceleration α), the torque about the hold
        per unit mass is −r × f − (I_c/m)·α: the inertial load on the centre of
        mass, and the phone's own inertia I_c about its centre as the thigh turns
        under it (a hinged body in an accelerating, turning frame; the r × (α × r)
        part of the second term is already in f). Each axis is a damped spring
        of inertia I = I_c + m·(|r|² − r_i²) about the hold: ≈ m·L²/3 away from
        the thigh (x), m·(L²/3 + W²/12) in the phone's plane (z), and m·(W²/12 +
        d²) about its long axis (y) — the thigh's front is rounded, so the phone
        rolls on it, held only by the cloth's tension, not stopped by it [E].
        In its own plane the hold is softer. ``rocking`` and ``sliding`` are the
        (natural frequency, damping ratio) of the two holds (``wobble_hz``,
        ``plane_hz``). Returns the rotation and the centre's displacement (R(θ) − 1)·r, both in
        the phone's frame.
        """
        f = limbs.acceleration(pos, body.t)
        f[:, 2] += _G
        f_phone = quat_ops.rotate(rot, f, inverse=True)
        half = _PHONE_LENGTH_M / 2.0
        r = np.array(
            [0.0, -half if top_down else half, _POCKET_LEVER_M if screen_out else -_POCKET_LEVER_M]
        )
        # The rigid phone's angular velocity and acceleration, in its own frame.
        omega = np.empty_like(f)
        omega[1:] = quat_ops.relative_rotvec(rot[:-1], rot[1:]) * body.rate_hz
        omega[0] = omega[1]
        alpha = limbs.derivative(omega, body.t)
        # Per unit mass: the plate's inertia about its centre, and about the hold.
        length2, width2 = _PHONE_LENGTH_M**2, _PHONE_WIDTH_M**2
        centre = np.array([length2, width2, length2 + width2]) / 12.0
        hold = centre + (r @ r - r**2)
        torque = (-np.cross(r, f_phone) - centre * alpha) / hold
        theta = np.empty_like(torque)
        theta[:, :2] = limbs.oscillator(torque[:, :2], *rocking, body.rate_hz)
        # In its own plane the phone is held more loosely (the pocket is wider than it).
        theta[:, 2] = limbs.oscillator(torque[:, 2], *sliding, body.rate_hz)
        wobble = limbs.from_rotvec(theta)
        shift = limbs.apply(wobble, np.broadcast_to(r, theta.shape)) - r
        return wobble, shift
