"""Gait: true step events and the body-centre trajectory of a pedestrian walking a route.

:func:`walk` turns a :class:`~indoorsim.walker.route.Route` into a
:class:`BodyTrajectory` (DESIGN §5, numbers from REALISM §5) in five stages,
each in its own module:

1. **Path** (:mod:`indoorsim.walker.path`). Each corner of the route becomes a
   curve with a sin² curvature profile, shortened near walls and where the
   legs are short; sharp or cramped corners are turned on the spot; the path
   bends smoothly away from walls it comes too close to.
2. **Speed profile** (:mod:`indoorsim.walker.pacing`). Along the path the desired
   speed is the cruising speed with a slow random fluctuation, dipped where the
   walker slows at route points (``mark_speed``), capped so that speed × curvature
   stays within the yaw-rate limit, zero at both ends of every walking bout
   (route ends, stops, pivots), with bounded acceleration and deceleration; a
   twin's legs are paced to their real times.
3. **Steps** (here). In each bout the cadence–speed relation
   (:func:`cadence_hz`) gives nominal heel strikes; step times and lengths
   then get their random variation (coefficients of variation, left/right
   asymmetry). The distance walked along the path at each heel strike is the
   sum of the step lengths, so the step events and the trajectory agree
   exactly. A step that came out too quick for a curve's yaw-rate limit takes
   longer instead. The bouts, stops and turns on the spot make up the walk's
   timeline.
4. **Physics** (:mod:`indoorsim.walker.physics`). The body, a pymunk disc, is
   steered through these (time, distance) knots at ``physics_rate_hz``
   against the walkable area's boundary as static segments, so no track
   passes through a wall; the track is upsampled to ``rate_hz`` with a C²
   cubic spline.
5. **Intra-step motion** (:mod:`indoorsim.walker.motion`): speed oscillation,
   bounce, sway, trunk yaw and heel-strike transients, added analytically at
   ``rate_hz`` and faded in and out with every bout, so positions stay C².

Frames: building frame, z up from the floor; heading and yaw in radians from
+x, counter-clockwise, unwrapped. All randomness comes from the ``rng``
argument: the same seed gives identical arrays.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import CubicSpline, PPoly
from scipy.linalg.lapack import dgtsv
from scipy.ndimage import gaussian_filter1d
from scipy.signal import lfilter

from indoorsim.walker.meander import keep_room, lateral_meander
from indoorsim.walker.motion import impulse_displacement, intra_step_motion
from indoorsim.walker.pacing import leg_ends, mark_slowing, paced_legs, speed_profile
from indoorsim.walker.path import SmoothPath, cumsum0, hermite_spline, smootherstep
from indoorsim.walker.physics import steer
from indoorsim.walker.route import Route

if TYPE_CHECKING:
    from indoorsim.world.plan import FloorPlan

__all__ = [
    "PELVIS_HEIGHT_RATIO",
    "BodyTrajectory",
    "WalkerParams",
    "cadence_hz",
    "impulse_displacement",  # defined in walker.motion; kept here for the old import path
    "smootherstep",
    "step_length_m",
    "walk",
]

PELVIS_HEIGHT_RATIO = 0.53
"""Standing height of the body centre (pelvis) as a fraction of body height."""

# Step length / body height = _SL_C0 + _SL_C1·v [D]: least-squares line through
# REALISM §5's anchors (1.0 m/s → 1.6–1.75 Hz, 1.31 m/s → 1.94 Hz, 1.72 m/s →
# 2.11 Hz; Murtagh et al. 2021) read as step lengths v/f for a 1.70 m adult.
# It gives 1.69 Hz at 1.0 m/s, 1.91 Hz at 1.31 m/s and 2.13 Hz at 1.72 m/s, and
# a longer step (lower cadence) for a taller walker at the same speed.
_SL_C0, _SL_C1 = 0.1688, 0.1786
# Below this speed the cadence stops falling: the first step from standing
# and the last one into standing take about as long as slow-walking steps.
_CADENCE_FLOOR_MPS = 0.6
# The speed profile keeps the yaw rate this far below the limit, leaving room
# for the step-to-step speed variation added afterwards.
_YAW_MARGIN = 0.85
# Mean-reversion of the accumulated step-length noise, so the walker's place
# along the path stays within a few cm of the nominal plan (turn slow-downs
# stay aligned with the turns) while each step keeps its own variation.
_LENGTH_REVERSION = 0.25
# Speed-profile grid spacing along the path (m).
_PROFILE_DS_M = 0.01
# Stops keep this far (m) from the route ends, pivots and each other.
_STOP_GAP_M = 3.0
# A walk cut short still steers its body this long past the cut (s).
_SPLINE_TAIL_S = 4.0
# Where within each step a bout checks the yaw rate.
_STEP_FRACTIONS = np.linspace(0.0, 1.0, 17)
# The walker's weave keeps the body this much farther from a wall than the body disc's
# radius (m): people do not brush walls as they walk (meander.keep_room).
_WEAVE_MARGIN_M = 0.05


def step_length_m(speed_mps: ArrayLike, height_m: float = 1.70) -> NDArray[np.float64]:
    """Typical step length (m) at a walking speed for a walker of a given height.

    Args:
        speed_mps: walking speed(s) in m/s.
        height_m: body height in metres.

    Returns:
        Step length(s), ``height·(0.1688 + 0.1786·v)``: 0.59 m at 1.0 m/s and
        0.68 m at 1.31 m/s for a 1.70 m walker (REALISM §5).
    """
    return height_m * (_SL_C0 + _SL_C1 * np.asarray(speed_mps, dtype=float))


def cadence_hz(speed_mps: ArrayLike, height_m: float = 1.70) -> NDArray[np.float64]:
    """Step frequency (steps/s) at a walking speed: speed / step length.

    >>> [round(float(cadence_hz(v)), 2) for v in (1.0, 1.31, 1.72)]
    [1.69, 1.91, 2.13]
    """
    v = np.asarray(speed_mps, dtype=float)
    return v / step_length_m(v, height_m)


@dataclass(kw_only=True, frozen=True)
class WalkerParams:
    """How a pedestrian walks. Defaults give an ordinary adult at usual pace.

    Sources are REALISM.md §5 (gait) unless noted; [E] marks estimates.
    """

    height_m: float = 1.70
    """Body height; scales step length (≈ 0.4·height at usual pace) and the
    pelvis height (0.53·height)."""
    speed_mps: float | None = None
    """Cruising speed; None takes the route's. Usual outdoor pace is 1.31 m/s
    (Murtagh et al. 2021); indoors 1.0–1.3 m/s. A route with ``leg_speeds`` paces
    each leg by them instead (the steps' geometry keeps this speed's)."""
    speed_cv: float = 0.03
    """Slow fluctuation of the cruising speed along the route (CV) [E]."""
    speed_correlation_m: float = 15.0
    """Correlation length of that fluctuation along the route [E]."""
    step_length_cv: float = 0.04
    """Step-to-step variation of step length (CV 3–5 %; at most 0.1)."""
    step_time_cv: float = 0.025
    """Step-to-step variation of step duration (CV 2–3 %; at most 0.1)."""
    asymmetry: float = 0.02
    """Left steps are longer than right ones, and take longer, by this fraction of the
    mean (negative: right longer) [E: healthy gait ≈ 1–3 %]. Step times alternate so
    on real walks: in the Oxford swinging-arm walks consecutive step intervals correlate
    at −0.18 to −0.27. With equal step times the simulated swinging-arm walks lost too
    few steps to a detector that waits 0.5 s between steps (24 % where the real walks
    lose 43–45 %; now 38 %, ``tests/benchmark/realism/test_step_counts.py``)."""
    stand_start_s: float = 3.0
    """Standing still before the first step, as real recordings begin."""
    stand_end_s: float = 3.0
    """Standing still after the last step."""
    start_turn_deg: float = 0.0
    """How far the walker stands turned from the route's first leg before setting off
    (counter-clockwise positive, deg): it turns on the spot toward the leg over the
    last ``start_turn_s`` of ``stand_start_s``. Real surveyors often stand a little
    turned and face their way only as they start; ``indoorsim calibrate`` measures it
    from a recording's gyro."""
    start_turn_s: float = 1.5
    """How long that turn takes, s (at most ``stand_start_s``)."""
    stop_rate_per_min: float = 0.0
    """Mean number of mid-walk stops per minute of walking (Poisson)."""
    stop_duration_s: tuple[float, float] = (2.0, 6.0)
    """Range of a stop's duration (uniform)."""
    mark_speed: tuple[float, float] = (1.0, 1.0)
    """Range of the slowest speed, as a fraction of the speed around it, at which the
    walker passes each inner point of the route, drawn per point (1: no slowing). Real
    surveyors tap each waypoint as they pass it: the ILC traces step at 1.3 steps/s
    with half their usual swing in the second before they pass a mark, at 1.8 around
    it; pedestrians slow likewise at junctions, doors and goals [E]."""
    mark_slowing_m: float = 1.0
    """How far before and after a route point that slowing reaches (m): decelerating
    from usual pace to a third of it at ``max_accel_mps2`` takes about a metre."""
    max_yaw_rate_dps: float = 150.0
    """Largest heading rate while turning (peaks of 90–180 °/s)."""
    turn_steps_per_90deg: float = 2.5
    """Preferred length of a turn: a 90° corner over ≈ 2–3 steps; other turns
    in proportion to the square root of their angle, so the yaw rate, not
    just the turn, grows with the angle."""
    pivot_turn_deg: float = 120.0
    """Corners sharper than this are taken standing, turning on the spot."""
    max_accel_mps2: float = 0.8
    """Largest speed change when starting, stopping and slowing for turns [E:
    usual pace is reached in about two steps]."""
    wall_distance_m: float = 0.4
    """Distance the body centre keeps from walls, pillars and furniture where
    the route allows: half the shoulder width plus the swinging hand [E].
    Turns keep it (or as much as the route's corner does), and the path bends
    smoothly away from anything closer."""
    body_radius_m: float = 0.25
    """Radius of the pymunk disc that stands for the body against the walls:
    the hard limit, where the route leaves no room for ``wall_distance_m``."""
    bounce_fraction: float = 0.7
    """Vertical excursion of the pelvis as a fraction of the compass-gait value
    step²/(8·leg): 4–5 cm peak to peak at usual pace (knee and pelvis
    motion reduce the 6.5–8.8 cm of the rigid-leg model)."""
    double_support: float = 0.2
    """Share of each step in which both feet are on the ground and the load passes
    from the trailing leg to the leading one: each double support is about a tenth
    of the gait cycle at usual pace [S: gait textbooks]. With ``cop_travel_m`` it
    shapes the forward surge (:func:`~indoorsim.walker.motion.surge_waveforms`)."""
    cop_travel_m: float = 0.15
    """How far the centre of pressure rolls along the stance foot in a step, heel to
    forefoot (about 0.6 of a foot's length) [E]."""
    lateral_sway_m: tuple[float, float] = (0.02, 0.03)
    """Range of the lateral sway amplitude toward the stance foot (±2–3 cm)."""
    trunk_yaw_deg: tuple[float, float] = (3.0, 8.0)
    """Range of the trunk's yaw oscillation amplitude at stride frequency (±3–8°)."""
    trunk_roll_deg: tuple[float, float] = (2.0, 4.0)
    """Range of the trunk's sideways lean toward the stance leg at stride frequency
    (the thorax's, ±2–5°; the pelvis lists the other way, its swing side dropping, which
    the pocketed thigh models on its own) [E]."""
    trunk_pitch_deg: tuple[float, float] = (2.0, 4.0)
    """Range of the trunk's forward lean within each step (half its peak to peak in a
    step of the walk's median bounce): most in double support, as heel strike brakes
    the pelvis under it, least
    at the top of the bounce; thorax flexion–extension spans a few degrees in
    walking [E]. A phone held before the chest nods with it: the ILC traces'
    flat-held phones pitch at the step rate with little lag on their vertical
    acceleration (8°; 0.22 rad/s per m/s², median), which a wrist's resonance alone
    does not give."""
    heel_strike_mps2: tuple[float, float] = (1.5, 4.0)
    """Range of the vertical heel-strike transient's peak at cruising speed; on
    top of the bounce this keeps heel-strike peaks at 1.3–2 g in total."""
    loading_width: tuple[float, float] = (0.16, 0.21)
    """Range of the width (σ, in steps) of the vertical acceleration's peak in
    double support, drawn per walk: what ``indoorsim calibrate`` fits through the
    held phone to the 14 ILC surveyors whose vigour is tabled
    (:mod:`indoorsim.walker.real_walkers`: 0.164–0.208). Narrower peaks (0.08–0.14 of
    a step put 1.3–1.8 g at the trunk for a 4–5 cm bounce [E]) give a held phone more
    power at twice the step rate than any real one shows; a wide peak (≥ 0.3) is the
    sinusoidal compass-gait bounce."""
    loading_asymmetry: tuple[float, float] = (0.05, 0.2)
    """Range of the relative difference in bounce between left and right steps,
    drawn per walk (either leg the stronger): gait asymmetry indices of healthy
    walkers reach 5–15 % in vertical ground reaction force [E]."""
    meander_m: tuple[float, float] = (0.07, 0.12)
    """Range of the RMS of the walker's sideways weave off the line it means to walk,
    drawn per walk (:mod:`~indoorsim.walker.meander`). With ``meander_wavelength_m``
    it is what the real ARKit walks' straight stretches show through
    :mod:`indoorsim.benchmark.realism.line` (1.85–2.84 cm and 1.72–2.62° once the stride
    is averaged out over 6 m; the bundled and generated sites' walks: 1.90–2.51 cm and
    1.87–2.37°). Independently, the ILC traces' twins now turn within their straight
    legs as their real surveyors do (the heading's swing within a leg, 2 s means: 5.85°,
    real 5.69°; 3.08° walking on rails)."""
    meander_wavelength_m: float = 5.0
    """Natural wavelength of that weave (m): its heading's departure has an RMS of
    2π·RMS/(wavelength·√5), 2.9° for the middle of ``meander_m``."""
    meander_fade_m: float = 4.0
    """Distance over which the weave fades in after the start and out before the end (m)."""
    physics_rate_hz: float = 25.0
    """Step rate of the pymunk body simulation."""

    def __post_init__(self) -> None:
        for name in _RANGE_FIELDS:
            object.__setattr__(self, name, _as_range(name, getattr(self, name)))
        checks = {
            "height_m": 1.0 <= self.height_m <= 2.3,
            "speed_mps": self.speed_mps is None or 0.1 < self.speed_mps <= 3.0,
            "speed_cv": 0 <= self.speed_cv <= 0.3,
            "speed_correlation_m": self.speed_correlation_m > 0,
            "step_length_cv": 0 <= self.step_length_cv <= 0.1,
            "step_time_cv": 0 <= self.step_time_cv <= 0.1,
            "asymmetry": -0.5 < self.asymmetry < 0.5,
            "stand_start_s": self.stand_start_s >= 0,
            "stand_end_s": self.stand_end_s >= 0,
            "start_turn_deg": -180.0 <= self.start_turn_deg <= 180.0,
            "start_turn_s": self.start_turn_s > 0,
            "stop_rate_per_min": self.stop_rate_per_min >= 0,
            "stop_duration_s": 0 < self.stop_duration_s[0] <= self.stop_duration_s[1],
            "mark_speed": 0.05 <= self.mark_speed[0] <= self.mark_speed[1] <= 1.0,
            "mark_slowing_m": 0.1 <= self.mark_slowing_m <= 10.0,
            "max_yaw_rate_dps": self.max_yaw_rate_dps > 0,
            "turn_steps_per_90deg": self.turn_steps_per_90deg > 0,
            "pivot_turn_deg": 0 < self.pivot_turn_deg < 180,
            "max_accel_mps2": self.max_accel_mps2 > 0,
            "wall_distance_m": self.wall_distance_m >= 0,
            "body_radius_m": 0.05 <= self.body_radius_m <= 0.5,
            "bounce_fraction": self.bounce_fraction >= 0,
            "double_support": 0.0 < self.double_support < 0.5,
            "cop_travel_m": 0.0 <= self.cop_travel_m < 0.3,
            "lateral_sway_m": 0 <= self.lateral_sway_m[0] <= self.lateral_sway_m[1],
            "trunk_yaw_deg": 0 <= self.trunk_yaw_deg[0] <= self.trunk_yaw_deg[1],
            "trunk_roll_deg": 0 <= self.trunk_roll_deg[0] <= self.trunk_roll_deg[1],
            "trunk_pitch_deg": 0 <= self.trunk_pitch_deg[0] <= self.trunk_pitch_deg[1],
            "heel_strike_mps2": 0 <= self.heel_strike_mps2[0] <= self.heel_strike_mps2[1],
            "loading_width": 0.03 <= self.loading_width[0] <= self.loading_width[1] <= 0.5,
            "loading_asymmetry": 0 <= self.loading_asymmetry[0] <= self.loading_asymmetry[1] < 1,
            "meander_m": 0 <= self.meander_m[0] <= self.meander_m[1] <= 0.5,
            "meander_wavelength_m": self.meander_wavelength_m > 0,
            "meander_fade_m": self.meander_fade_m >= 0,
            "physics_rate_hz": 10 <= self.physics_rate_hz <= 200,
        }
        bad = [name for name, ok in checks.items() if not ok]
        if bad:
            values = ", ".join(f"{name}={getattr(self, name)!r}" for name in bad)
            raise ValueError(f"WalkerParams out of range: {values}")


_RANGE_FIELDS = tuple(
    f.name for f in dataclasses.fields(WalkerParams) if isinstance(f.default, tuple)
)
"""The fields of :class:`WalkerParams` that are ranges (low, high) drawn per walk."""


def _as_range(name: str, value: object) -> tuple[float, float]:
    """A range field's value as ``(low, high)``: one number fixes it (a calibrated
    walker, a data set's drawn one), two (a tuple, a YAML or JSON list, an array)
    are the range.

    Raises:
        ValueError: anything else, naming the field.
    """
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return (float(value), float(value))
    if isinstance(value, (tuple, list, np.ndarray)) and len(value) == 2:
        low, high = value
        if all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in (low, high)):
            return (float(low), float(high))
    raise ValueError(
        f"WalkerParams {name}: a range is one number or two (low, high), got {value!r}"
    )


@dataclass(frozen=True, kw_only=True, eq=False)
class BodyTrajectory:
    """The walker's true body motion, sampled uniformly.

    Attributes:
        t: (K,) time in seconds from the start, at ``rate_hz``.
        pos: (K, 3) body centre (pelvis) in the building frame, metres.
        gait_offset: (K, 3) the part of ``pos`` that moves within each step
            (bounce, forward surge, sway, heel-strike jolts), in the building
            frame: ``pos - gait_offset`` follows the path smoothly.
        heading: (K,) walking direction, radians from +x, unwrapped.
        yaw: (K,) trunk yaw: heading plus the stride-frequency trunk rotation.
        roll: (K,) the trunk's sideways lean toward the stance leg, rad (+ left).
        pitch: (K,) the trunk's forward lean within each step, rad (+ forward).
        speed: (K,) horizontal speed of the body centre, m/s.
        step_phase: (K,) steps completed: an integer at each heel strike,
            increasing smoothly in between, constant while standing.
        stride_phase: (K,) position in the gait cycle in [0, 1); 0 at each
            left heel strike, 0.5 at each right one.
        moving: (K,) True while walking (between the start of a bout's first
            step and its last heel strike).
        gait_envelope: (K,) 0 standing, 1 walking; rises over a bout's first
            step and falls over its last, with zero slope and curvature at
            both ends (C²). Intra-step motions are scaled by it, and carrying
            modes can scale theirs too.
        steps: the true heel strikes: columns ``t`` (s), ``foot`` ('L'/'R'),
            ``length`` (m, distance walked along the path since the previous
            heel strike or the bout's start).
        height_m: the walker's body height.
        rate_hz: the sample rate.
    """

    t: NDArray[np.float64]
    pos: NDArray[np.float64]
    gait_offset: NDArray[np.float64]
    heading: NDArray[np.float64]
    yaw: NDArray[np.float64]
    roll: NDArray[np.float64]
    pitch: NDArray[np.float64]
    speed: NDArray[np.float64]
    step_phase: NDArray[np.float64]
    stride_phase: NDArray[np.float64]
    moving: NDArray[np.bool_]
    gait_envelope: NDArray[np.float64]
    steps: pd.DataFrame
    height_m: float
    rate_hz: float

    @property
    def pelvis_height_m(self) -> float:
        """Standing height of the body centre."""
        return PELVIS_HEIGHT_RATIO * self.height_m

    def window(self, start: int, stop: int) -> BodyTrajectory:
        """Samples ``start:stop`` (times kept absolute) and the heel strikes among them."""
        sl = slice(start, stop)
        arrays = {
            f.name: getattr(self, f.name)[sl]
            for f in dataclasses.fields(self)
            if isinstance(getattr(self, f.name), np.ndarray)
        }
        t = arrays["t"]
        steps = self.steps[(self.steps.t >= t[0]) & (self.steps.t <= t[-1])]
        return dataclasses.replace(self, steps=steps.reset_index(drop=True), **arrays)


def walk(
    plan: FloorPlan,
    route: Route,
    params: WalkerParams,
    rng: np.random.Generator,
    rate_hz: float = 200.0,
    until_s: float | None = None,
) -> BodyTrajectory:
    """Simulate a pedestrian walking ``route`` in ``plan``.

    Args:
        plan: the floor plan (its walkable area bounds the body).
        route: the polyline to follow and, unless ``params.speed_mps`` is set,
            the cruising speed.
        params: how the pedestrian walks.
        rng: the only source of randomness.
        rate_hz: output sample rate, at least 200 Hz (the IMU truth rate).
        until_s: compute the trajectory only up to this time (a long route
            walked for a fixed time). The walk is planned in full and draws
            the same random numbers, so the samples up to ``until_s`` are
            those of the whole walk (to rounding); the trajectory and its heel
            strikes end a few samples after it. None computes the whole walk.

    Returns:
        The body trajectory and the true heel strikes.

    Raises:
        ValueError: for a rate below 200 Hz.
    """
    if not rate_hz >= 200.0:
        raise ValueError(f"rate_hz must be >= 200 Hz to resolve heel strikes, got {rate_hz}")
    v_cruise = params.speed_mps if params.speed_mps is not None else route.speed
    height = params.height_m
    omega_lim = _YAW_MARGIN * math.radians(params.max_yaw_rate_dps)
    # The line walked (path.py), with its turns on the spot and random stops.
    path = SmoothPath.build(
        route.points,
        plan,
        step_m=float(step_length_m(v_cruise, height)),
        omega_lim=omega_lim,
        turn_steps_per_90deg=params.turn_steps_per_90deg,
        pivot_turn_deg=params.pivot_turn_deg,
        clearance_m=params.wall_distance_m,
    ).keep_off_walls(plan, params.wall_distance_m)
    dwells = _dwells(path, params, v_cruise, omega_lim, rng)
    speed_factor = _speed_fluctuation(path.length, params, rng)
    slows = params.mark_speed != (1.0, 1.0) and len(route.points) > 2
    if slows or route.leg_speeds is not None:
        # Where each route point falls on the path: where the walker slows, where a
        # paced leg ends.
        ends = leg_ends(path, route.points)
    if slows:
        # Slowing at the route's inner points (a surveyor's marks), before the legs are
        # paced: a paced leg keeps its time, walked faster between its ends.
        slowest = rng.uniform(*params.mark_speed, len(route.points) - 2)
        speed_factor = mark_slowing(ends, speed_factor, slowest, params.mark_slowing_m)
    if route.leg_speeds is not None:
        half_step = 0.5 * float(step_length_m(v_cruise, height))
        speed_factor = paced_legs(
            path, route, ends, dwells, v_cruise, omega_lim, half_step, speed_factor, params
        )
    first_left = bool(rng.random() < 0.5)

    # Walking bouts between the dwells, each from rest to rest.
    edges = [0.0, *(d.s for d in dwells), path.length]
    bouts: list[_Bout] = []
    t_now, n_steps = params.stand_start_s, 0
    for b in range(len(edges) - 1):
        bout = _Bout.plan(
            path,
            (edges[b], edges[b + 1]),
            (t_now, n_steps, first_left),
            v_cruise,
            omega_lim,
            speed_factor,
            params,
            rng,
        )
        bouts.append(bout)
        n_steps += len(bout.lengths)
        t_now = bout.t_end + (dwells[b].duration if b < len(dwells) else 0.0)
    timeline = _Timeline(bouts, dwells)
    duration = t_now + params.stand_end_s

    # Samples: the physics' and the output's. A few samples past a cut keep the derived
    # speed central at the cut itself; the physics runs a little past the end, so that
    # the spline through its track has the same values up to the end as the whole
    # walk's would (a cubic spline's end condition fades by ~4× per knot).
    dt_phys = 1.0 / params.physics_rate_hz
    end = duration if until_s is None else min(duration, max(until_s, 0.0) + 0.05)
    phys_end = min(duration, end + _SPLINE_TAIL_S)
    t_phys = np.arange(math.ceil(phys_end / dt_phys) + 1) * dt_phys
    t = np.arange(math.floor(end * rate_hz + 1e-9) + 1) / rate_hz

    # Intra-step motion, in the walking direction's frame (motion.py).
    phase = timeline.phase(t)
    env = timeline.envelope(t)
    stride = np.mod((phase - (1.0 if first_left else 0.0)) / 2.0, 1.0)
    steps = timeline.steps()
    leg = PELVIS_HEIGHT_RATIO * height
    within = intra_step_motion(
        t,
        phase=phase,
        stride=stride,
        envelope=env,
        strike_t=steps["t"].to_numpy(),
        step_lengths=steps["length"].to_numpy(),
        step_durations=timeline.step_durations(),
        leg_m=leg,
        cruise_mps=v_cruise,
        bounce_fraction=params.bounce_fraction,
        double_support=params.double_support,
        cop_travel_m=params.cop_travel_m,
        lateral_sway_m=params.lateral_sway_m,
        trunk_yaw_deg=params.trunk_yaw_deg,
        trunk_roll_deg=params.trunk_roll_deg,
        trunk_pitch_deg=params.trunk_pitch_deg,
        heel_strike_mps2=params.heel_strike_mps2,
        loading_width=params.loading_width,
        loading_asymmetry=params.loading_asymmetry,
        rng=rng,
    )
    # The walker's own weave off the line it means to walk (meander.py), drawn last so
    # that the walk's other draws are those of a walker without it.
    meander = lateral_meander(
        path.length,
        rng.uniform(*params.meander_m),
        params.meander_wavelength_m,
        params.meander_fade_m,
        rng,
    )
    meander = keep_room(
        meander,
        path.position(meander.s),
        path.heading(meander.s),
        plan,
        params.body_radius_m + _WEAVE_MARGIN_M,
    )

    # Macro track: the pymunk body steered through the planned knots, moved aside by
    # the weave (physics.py), then C².
    s_phys = timeline.distance(t_phys)
    aside, weave = meander.at(s_phys)
    normal = path.heading(s_phys) + 0.5 * math.pi
    aim = path.position(s_phys) + aside[:, None] * np.column_stack([np.cos(normal), np.sin(normal)])
    track = steer(plan, aim, dt_phys, params.body_radius_m)
    # The track and the turn the weave's slope gives the body, C² through the physics'
    # samples (the weave varies over metres, the physics' samples are centimetres apart).
    macro_turn = CubicSpline(t_phys, np.column_stack([track, np.arctan(weave)]), axis=0)(t)
    macro = macro_turn[:, :2]
    # The body faces its way along the path, turned by the weave.
    heading = path.heading(timeline.distance(t)) + macro_turn[:, 2] + timeline.pivot_heading(t)
    turn_s = min(params.start_turn_s, params.stand_start_s)
    if params.start_turn_deg and turn_s > 0:
        # Standing turned, then turning on the spot to face the first leg.
        done = smootherstep((t - (params.stand_start_s - turn_s)) / turn_s)
        heading = heading + math.radians(params.start_turn_deg) * (1.0 - done)
    fwd, lat = within.forward, within.lateral
    ch, sh = np.cos(heading), np.sin(heading)
    # x and y as contiguous rows: np.gradient along rows is cheaper than down
    # the columns of (K, 3) positions (the same values).
    xy = np.empty((2, len(t)))
    xy[0] = macro[:, 0] + fwd * ch - lat * sh
    xy[1] = macro[:, 1] + fwd * sh + lat * ch
    pos = np.column_stack([xy[0], xy[1], leg + within.up])
    gait_offset = np.column_stack([fwd * ch - lat * sh, fwd * sh + lat * ch, within.up])
    vel = np.gradient(xy, t, axis=1)
    if end < duration:
        steps = steps[steps["t"] <= t[-1]].reset_index(drop=True)
    return BodyTrajectory(
        t=t,
        pos=pos,
        gait_offset=gait_offset,
        heading=heading,
        yaw=heading + within.trunk_yaw,
        roll=within.trunk_roll,
        pitch=within.trunk_pitch,
        speed=np.hypot(vel[0], vel[1]),
        step_phase=phase,
        stride_phase=stride,
        moving=timeline.moving(t),
        gait_envelope=env,
        steps=steps,
        height_m=height,
        rate_hz=float(rate_hz),
    )


# ---------------------------------------------------------------------- timing


@dataclass(frozen=True)
class _Dwell:
    """Standing at distance ``s`` for ``duration`` s, turning by ``dtheta`` meanwhile."""

    s: float
    duration: float
    dtheta: float = 0.0


def _dwells(
    path: SmoothPath,
    params: WalkerParams,
    v_cruise: float,
    omega_lim: float,
    rng: np.random.Generator,
) -> list[_Dwell]:
    """On-the-spot turns at sharp corners plus random stops, in order along the path."""
    # A smootherstep turn peaks at 1.875× its mean rate.
    out = [
        _Dwell(s=s, duration=max(1.875 * abs(dth) / omega_lim, 0.5), dtheta=dth)
        for s, dth in path.pivots
    ]
    expected = params.stop_rate_per_min * path.length / v_cruise / 60.0
    n = rng.poisson(expected)
    lo, hi = _STOP_GAP_M, path.length - _STOP_GAP_M
    where = np.sort(rng.uniform(lo, max(lo, hi), n))
    durations = rng.uniform(*params.stop_duration_s, n)
    taken = [0.0, path.length, *(d.s for d in out)]
    for s, dur in zip(where, durations, strict=True):
        if hi > lo and min(abs(s - x) for x in taken) >= _STOP_GAP_M:
            out.append(_Dwell(s=float(s), duration=float(dur)))
            taken.append(float(s))
    return sorted(out, key=lambda d: d.s)


def _speed_fluctuation(
    length: float, params: WalkerParams, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Knots (distance, factor) of the slowly varying cruising-speed factor around 1."""
    s = np.arange(math.ceil(length) + 2, dtype=float)
    noise = gaussian_filter1d(rng.standard_normal(len(s)), params.speed_correlation_m)
    sd = noise.std()
    factor = 1.0 + params.speed_cv * (noise / sd if sd > 0 else noise)
    lim = 3.0 * params.speed_cv
    return s, np.clip(factor, 1.0 - lim, 1.0 + lim)


@dataclass(frozen=True)
class _Bout:
    """One walk from rest to rest: heel-strike knots and their smooth interpolants."""

    t0: float
    n0: int
    t_knots: NDArray[np.float64]  # bout start, then each heel strike (absolute s)
    s_knots: NDArray[np.float64]  # distance along the path at those times
    lengths: NDArray[np.float64]
    left: NDArray[np.bool_]
    distance: PPoly
    phase: PPoly

    @property
    def t_end(self) -> float:
        return float(self.t_knots[-1])

    @classmethod
    def plan(
        cls,
        path: SmoothPath,
        span: tuple[float, float],
        start: tuple[float, int, bool],
        v_cruise: float,
        omega_lim: float,
        speed_factor: tuple[NDArray[np.float64], NDArray[np.float64]],
        params: WalkerParams,
        rng: np.random.Generator,
    ) -> _Bout:
        """Steps for walking from ``span[0]`` to ``span[1]`` along the path.

        Args:
            path: the smoothed route.
            span: start and end distance of the bout along the path.
            start: the bout's start time, the steps taken before it, and
                whether the walk's first step is with the left foot.
            v_cruise: cruising speed.
            omega_lim: the yaw-rate limit the speed profile keeps to (rad/s).
            speed_factor: knots of the slow speed fluctuation.
            params: the walker.
            rng: randomness for the step variation.
        """
        s_a, s_b = span
        t0, n0, first_left = start
        n = max(2, math.ceil((s_b - s_a) / _PROFILE_DS_M))
        grid = np.linspace(s_a, s_b, n + 1)

        # Desired speed: cruise × fluctuation, capped by the yaw-rate limit on
        # curves, zero at both ends, reached with bounded acceleration. The cap
        # holds for a whole step around each point, since the speed can only
        # follow the plan step by step. The acceleration passes are closed forms
        # of the usual forward/backward sweeps: v²(s) ≤ v²(s') + 2a|s − s'|.
        height = params.height_m
        kappa = path.max_curvature(grid, 0.5 * float(step_length_m(v_cruise, height)))
        v_lim = v_cruise * np.interp(grid, *speed_factor)
        v_lim = np.minimum(v_lim, omega_lim / np.maximum(kappa, 1e-9))
        v, dtau = np.empty(len(grid)), np.empty(len(grid) - 1)
        speed_profile(grid, v_lim, s_a, 2.0 * params.max_accel_mps2, v, dtau)
        # Time along the profile (exact for constant acceleration between knots).
        tau = cumsum0(dtau)

        # Nominal heel strikes: integer crossings of the cadence phase, with the
        # phase stretched so that the last step ends exactly at the bout's end.
        floor = min(_CADENCE_FLOOR_MPS, v_cruise)
        phase = cumulative_trapezoid(cadence_hz(np.maximum(v, floor), height), tau, initial=0.0)
        count = max(1, round(phase[-1]))
        t_nom = np.interp(np.arange(1, count + 1), phase * (count / phase[-1]), tau)
        t_nom[-1] = tau[-1]
        length_nom = np.diff(np.interp(np.concatenate(([0.0], t_nom)), tau, grid))
        time_nom = np.diff(t_nom, prepend=0.0)

        # Random variation. Step times vary independently. Step lengths vary
        # too, with the accumulated deviation pulled back to the plan at rate
        # _LENGTH_REVERSION (its variance inflation 2/(2−β) is divided out).
        k = n0 + np.arange(count)
        left = (k % 2 == 0) == first_left
        sym = np.where(left, 1.0 + 0.5 * params.asymmetry, 1.0 - 0.5 * params.asymmetry)
        cv_t, cv_l = params.step_time_cv, params.step_length_cv
        # The longer steps take longer too: the walker keeps its pace through a stride.
        jitter = 1.0 + np.clip(rng.normal(0.0, cv_t, count), -3 * cv_t, 3 * cv_t)
        times = time_nom * sym * jitter
        beta = _LENGTH_REVERSION
        err = length_nom * np.clip(rng.normal(0.0, cv_l, count), -3 * cv_l, 3 * cv_l)
        drift = lfilter([1.0], [1.0, beta - 1.0], err * math.sqrt(1.0 - beta / 2.0))
        lengths = np.maximum(length_nom * sym + np.diff(drift, prepend=0.0), 0.2 * length_nom)
        # The last step lands exactly on the bout's end.
        total, last_min = s_b - s_a, 0.5 * length_nom[-1]
        head = lengths[:-1].sum()
        if total - head < last_min:
            lengths[:-1] *= (total - last_min) / head
        lengths[-1] = total - lengths[:-1].sum()

        s_knots = s_a + cumsum0(lengths)
        s_knots[-1] = s_b
        # A step that came out fast enough to break the yaw-rate limit on a
        # curve takes longer instead (as a walker slows into a turn). Checked
        # against the step-wide curvature bound, with a little room left.
        omega_max = 0.97 * math.radians(params.max_yaw_rate_dps)
        for _ in range(5):
            t_knots = t0 + cumsum0(times)
            distance = _knot_spline(t_knots, s_knots, natural=False)
            tt = t_knots[:-1, None] + times[:, None] * _STEP_FRACTIONS
            rate = np.interp(distance(tt), grid, kappa) * np.abs(distance(tt, 1))
            excess = rate.max(axis=1) / omega_max
            if np.all(excess <= 1.0):
                break
            times = _bounded_ratio(times * np.clip(excess * 1.02, 1.0, 1.5), 2.0)
        return cls(
            t0=t0,
            n0=n0,
            t_knots=t_knots,
            s_knots=s_knots,
            lengths=lengths,
            left=left,
            distance=distance,
            phase=_knot_spline(t_knots, n0 + np.arange(count + 1.0), natural=True),
        )


def _knot_spline(x: NDArray[np.float64], y: NDArray[np.float64], natural: bool) -> PPoly:
    """``CubicSpline(x, y, bc_type=...)`` through a bout's knots: zero slope at both
    ends, or with ``natural`` zero curvature.

    The same tridiagonal system for the knot slopes as scipy's CubicSpline,
    solved by the same LAPACK routine (scipy's ``dgtsv`` binding), and the same
    Hermite coefficients, so the same piecewise polynomial (a test pins it to
    CubicSpline); but without the input validation and array-API dispatch
    that cost most of the time of a spline through a few dozen knots (a walk
    builds hundreds of them). ``x`` must increase strictly.
    """
    n = len(x)
    dx = np.diff(x)
    slope = np.diff(y) / dx
    # Banded matrix (upper, main, lower diagonal) and right-hand side.
    ab = np.zeros((3, n))
    rhs = np.empty(n)
    ab[1, 1:-1] = 2 * (dx[:-1] + dx[1:])
    ab[0, 2:] = dx[:-1]
    ab[-1, :-2] = dx[1:]
    rhs[1:-1] = 3 * (dx[1:] * slope[:-1] + dx[:-1] * slope[1:])
    if natural:  # second derivative 0 at both ends (scipy's rows with a value of 0)
        ab[1, 0], ab[0, 1] = 2 * dx[0], dx[0]
        rhs[0] = 3 * (y[1] - y[0])
        ab[1, -1], ab[-1, -2] = 2 * dx[-1], dx[-1]
        rhs[-1] = 3 * (y[-1] - y[-2])
    else:  # first derivative 0 at both ends
        ab[1, 0], ab[0, 1], rhs[0] = 1.0, 0.0, 0.0
        ab[1, -1], ab[-1, -2], rhs[-1] = 1.0, 0.0, 0.0
    *_, dydx, info = dgtsv(ab[2, :-1], ab[1], ab[0, 1:], rhs[:, None], 1, 1, 1, 1)
    if info != 0:
        raise np.linalg.LinAlgError("singular matrix")
    return hermite_spline(x, y, dydx[:, 0])


def _bounded_ratio(x: NDArray[np.float64], ratio: float) -> NDArray[np.float64]:
    """``x`` raised as little as possible so that neighbours differ at most ``ratio``-fold.

    Closed form of the forward and backward sweeps x_i ≥ x_j / ratio^|i − j|.
    Keeps the interpolating splines through the step knots monotone.
    """
    k = np.arange(len(x)) * math.log(ratio)
    a = np.log(x)
    a = np.maximum(a, np.maximum.accumulate(a + k) - k)
    a = np.maximum(a, np.maximum.accumulate((a - k)[::-1])[::-1] + k)
    return np.exp(a)


class _Timeline:
    """The walk in time: standing, bouts and dwells, queried at sorted times."""

    def __init__(self, bouts: list[_Bout], dwells: list[_Dwell]):
        self.bouts = bouts
        self.dwells = dwells

    def _spans(self, t: NDArray[np.float64]) -> list[tuple[_Bout, int, int, int]]:
        """Each bout, the samples it covers (``i0:i1``) and where the next one
        begins (the samples ``i1:i2`` wait for it, holding the bout's end)."""
        t0 = np.array([b.t0 for b in self.bouts])
        t_end = np.array([b.t_end for b in self.bouts])
        i0 = np.searchsorted(t, t0, "left").tolist()
        i1 = np.searchsorted(t, t_end, "right").tolist()
        i2 = [*i0[1:], len(t)]
        return list(zip(self.bouts, i0, i1, i2, strict=True))

    def distance(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        out = np.zeros(len(t))
        for b, i0, i1, i2 in self._spans(t):
            out[i0:i1] = b.distance(t[i0:i1])
            out[i1:i2] = b.s_knots[-1]
        return out

    def phase(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        out = np.zeros(len(t))
        for b, i0, i1, i2 in self._spans(t):
            out[i0:i1] = b.phase(t[i0:i1])
            out[i1:i2] = b.n0 + len(b.lengths)
        return out

    def envelope(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """1 while walking, fading in over a bout's first step and out over its last (C²)."""
        out = np.zeros(len(t))
        for b, i0, i1, _ in self._spans(t):
            tt = t[i0:i1]
            first, last = b.t_knots[1] - b.t_knots[0], b.t_knots[-1] - b.t_knots[-2]
            out[i0:i1] = smootherstep((tt - b.t0) / first) * smootherstep((b.t_end - tt) / last)
        return out

    def moving(self, t: NDArray[np.float64]) -> NDArray[np.bool_]:
        out = np.zeros(len(t), dtype=bool)
        for _, i0, i1, _ in self._spans(t):
            out[i0:i1] = True
        return out

    def pivot_heading(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Heading change from the turns on the spot (each during the dwell after its bout)."""
        out = np.zeros(len(t))
        for b, d in zip(self.bouts, self.dwells, strict=False):
            if d.dtheta:
                # 0 before the turn, dtheta after it: only the turn itself needs the step.
                i0 = int(np.searchsorted(t, b.t_end, "right"))
                i1 = int(np.searchsorted(t, b.t_end + d.duration, "left"))
                out[i0:i1] += d.dtheta * smootherstep((t[i0:i1] - b.t_end) / d.duration)
                out[i1:] += d.dtheta
        return out

    def steps(self) -> pd.DataFrame:
        return pd.DataFrame(
            {
                "t": np.concatenate([b.t_knots[1:] for b in self.bouts]),
                "foot": np.where(np.concatenate([b.left for b in self.bouts]), "L", "R"),
                "length": np.concatenate([b.lengths for b in self.bouts]),
            }
        )

    def step_durations(self) -> NDArray[np.float64]:
        return np.concatenate([np.diff(b.t_knots) for b in self.bouts])
