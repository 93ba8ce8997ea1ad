"""Gait: true step events and the body-centre trajectory of a pedestrian walking a route.

:func:`walk` turns a :class:`~indoorsim.walker.route.Route` into a
:class:`BodyTrajectory` (DESIGN §5, numbers from REALISM §5):

1. **Path.** Each corner of the route becomes a curve whose curvature rises and
   falls as sin² along it, so the heading turns with a bell-shaped yaw rate
   (peak twice the mean) and the curve cuts the corner half as much as a
   circular arc of the same length. A 90° corner preferably takes
   ``turn_steps_per_90deg`` steps (others scale with the root of the angle);
   the curve is shortened where the legs are short or where it would come
   closer to walls than ``wall_distance_m`` (or than the polyline itself
   does). Corners sharper than ``pivot_turn_deg``, or so cramped that they
   could only be walked at a crawl, are taken standing: stop, turn on the
   spot, go on (turning on the spot takes no modelled steps). Where the path
   still passes closer than ``wall_distance_m`` to a wall, pillar or desk, it
   is bent smoothly away from it, as people keep their distance.
2. **Speed profile.** Along the path the desired speed is the cruising speed
   with a slow random fluctuation, capped so that speed × curvature stays
   within the yaw-rate limit, zero at both ends of every walking bout (route
   ends, stops, pivots), with bounded acceleration and deceleration.
3. **Steps.** In each bout the cadence–speed relation (:func:`cadence_hz`)
   gives nominal heel strikes; step times and lengths then get their random
   variation (coefficients of variation, left/right asymmetry). The distance
   walked along the path at each heel strike is the sum of the step lengths,
   so the step events and the trajectory agree exactly. A step that came out
   too quick for a curve's yaw-rate limit takes longer instead.
4. **Physics.** The body, a pymunk disc, is steered through these (time,
   distance) knots at ``physics_rate_hz`` against the walkable area's
   boundary as static segments, so no track passes through a wall; the track
   is upsampled to ``rate_hz`` with a C² cubic spline.
5. **Intra-step motion** is added analytically at ``rate_hz``: forward speed
   oscillation and vertical bounce at step frequency (lowest and fastest just
   after heel strike), lateral sway toward the stance foot and trunk yaw at
   stride frequency, and heel-strike transients shaped as Ricker wavelets of
   the acceleration (smooth, zero net velocity change). Amplitudes follow each
   step's length and fade in and out with every bout, so positions stay C².

Frames: building frame, z up from the floor; heading and yaw in radians from
+x, counter-clockwise, unwrapped. All randomness comes from the ``rng``
argument: the same seed gives identical arrays.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numba
import numpy as np
import pandas as pd
import pymunk
import shapely
from numpy.typing import ArrayLike, NDArray
from pymunk._chipmunk_cffi import lib as _CP
from scipy.integrate import cumulative_trapezoid
from scipy.interpolate import CubicSpline, PPoly
from scipy.linalg.lapack import dgtsv
from scipy.ndimage import gaussian_filter1d
from scipy.signal import lfilter

from indoorsim.walker.route import Route

if TYPE_CHECKING:
    from indoorsim.world.plan import FloorPlan

__all__ = [
    "PELVIS_HEIGHT_RATIO",
    "BodyTrajectory",
    "WalkerParams",
    "cadence_hz",
    "impulse_displacement",
    "smootherstep",
    "step_length_m",
    "walk",
]

PELVIS_HEIGHT_RATIO = 0.53
"""Standing height of the body centre (pelvis) as a fraction of body height."""

_G = 9.81  # m/s²

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
# Heel-strike transients peak this long after contact and last about ±3σ; σ =
# 15 ms puts their energy at 10–20 Hz [E].
_HS_DELAY_S, _HS_SIGMA_S = 0.02, 0.015
# The vertical minimum and forward-speed maximum come just after heel strike,
# in double support (as a fraction of a step).
_DOUBLE_SUPPORT_PHASE = 0.1
# Mean-reversion of the accumulated step-length noise, so the walker's place
# along the path stays within a few cm of the nominal plan (turn slow-downs
# stay aligned with the turns) while each step keeps its own variation.
_LENGTH_REVERSION = 0.25
# Profile grid spacing along the path (m) and curve sampling step (m).
_PROFILE_DS_M, _CURVE_DS_M = 0.01, 0.005
# Geometry search for a corner's curve: shrink factor and number of tries.
_TURN_SHRINK, _TURN_TRIES = 0.75, 10
# A corner whose curve could only be walked slower than this (m/s) within the
# yaw-rate limit is turned on the spot.
_PIVOT_BELOW_MPS = 0.3
# Route vertices closer than this (m) to the previous one are dropped: such
# legs (e.g. where a start near a wall joins the planned path) are no walk.
_MIN_LEG_M = 0.05
# Keeping off walls: resampling step (m), smoothing of the push along the path
# (σ, m) and the number of push-and-smooth rounds.
_KEEP_DS_M, _KEEP_SMOOTH_M, _KEEP_ROUNDS = 0.02, 0.3, 8
# The first look for walls near the path reaches this much farther (m), to
# know which points cannot come too close in the rounds that follow.
_KEEP_SCAN_M = 0.1
# Stops keep this far (m) from the route ends, pivots and each other.
_STOP_GAP_M = 3.0
# Speed (m/s) at which the steering joint pulls the body back onto its planned
# track after a wall has pushed it off, and the largest acceleration (m/s²) it
# may give the body: ample for any planned track, and a gentle shove when a
# wall is in the way [E].
_TRACK_MAX_CORRECTION, _MAX_STEER_ACCEL = 0.5, 5.0
# The disc's physics is skipped on stretches of at least _STEER_MIN_SKIP steps
# where the plan stays this much farther than the disc's radius plus a step
# from every wall (m), once the disc is within _STEER_ON_TRACK_M of its plan.
_STEER_CLEAR_M, _STEER_MIN_SKIP, _STEER_ON_TRACK_M = 0.05, 8, 1e-9
# A walk cut short still steers its body this long past the cut (s).
_SPLINE_TAIL_S = 4.0
# Where within each step a bout checks the yaw rate.
_STEP_FRACTIONS = np.linspace(0.0, 1.0, 17)


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


def smootherstep(x: ArrayLike) -> NDArray[np.float64]:
    """0 → 1 over x in [0, 1], 6x⁵ − 15x⁴ + 10x³, flat (zero slope and curvature)
    at both ends: blending with it keeps a C² motion C².

    >>> smootherstep([-1.0, 0.5, 2.0]).tolist()
    [0.0, 0.5, 1.0]
    """
    x = np.clip(x, 0.0, 1.0)
    return x**3 * (x * (6.0 * x - 15.0) + 10.0)


def impulse_displacement(
    t: NDArray[np.float64], t_hs: NDArray[np.float64], peak: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Displacement (m) whose acceleration is a short pulse of ``peak`` m/s² after each heel strike.

    x(t) = −peak·σ²·exp(−u²/2) with u = (t − t_hs − 20 ms)/σ and σ = 15 ms, so
    ẍ = peak·(1 − u²)·exp(−u²/2), a Ricker wavelet: a sharp pulse flanked by
    two shallow opposite lobes, with no net change of velocity and no
    displacement left behind. Smooth at any sample rate of 200 Hz or more.

    Args:
        t: (K,) sorted sample times.
        t_hs: (N,) sorted heel-strike times, more than 0.2 s apart (so only
            the two nearest can reach a sample).
        peak: (N,) acceleration peak of each pulse.
    """
    out = np.zeros(len(t))
    if len(t_hs) == 0:
        return out
    centre = t_hs + _HS_DELAY_S
    # Each sample gets the pulse centred last before it and the one next after
    # it: the exponents of both in one compiled pass, np.exp on each set, and
    # the sum in another pass.
    first = int(np.searchsorted(t, centre[0], "right"))
    last = int(np.searchsorted(t, centre[-1], "right"))
    arg_prev, arg_next = np.empty(len(t) - first), np.empty(last)
    j_prev, j_next = np.empty(len(t) - first, np.intp), np.empty(last, np.intp)
    _pulse_exponents(t, centre, _HS_SIGMA_S, first, arg_prev, j_prev, arg_next, j_next)
    scale = peak * _HS_SIGMA_S**2
    _add_pulses(out, first, scale, j_prev, np.exp(arg_prev), j_next, np.exp(arg_next))
    return out


@numba.njit(cache=True, error_model="numpy")
def _pulse_exponents(
    t, centre, sigma, first, arg_prev, j_prev, arg_next, j_next
):  # pragma: no cover - compiled
    """−u²/2 with u = (t − centre)/σ for the last centre before each sample t[first:]
    and for the next centre from each sample t[:len(arg_next)] on, and which
    centres those are (``t`` and ``centre`` ascending)."""
    k = 0
    for i in range(len(t)):
        while k < len(centre) and centre[k] < t[i]:
            k += 1
        if i >= first:
            u = (t[i] - centre[k - 1]) / sigma
            arg_prev[i - first] = -0.5 * u * u
            j_prev[i - first] = k - 1
        if i < len(arg_next):
            u = (t[i] - centre[k]) / sigma
            arg_next[i] = -0.5 * u * u
            j_next[i] = k


@numba.njit(cache=True, error_model="numpy")
def _add_pulses(out, first, scale, j_prev, e_prev, j_next, e_next):  # pragma: no cover - compiled
    """out[first:] −= the pulses before, then out[:len(e_next)] −= those after."""
    for k in range(len(e_prev)):
        out[first + k] -= scale[j_prev[k]] * e_prev[k]
    for k in range(len(e_next)):
        out[k] -= scale[j_next[k]] * e_next[k]


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
    (Murtagh et al. 2021); indoors 1.0–1.3 m/s."""
    speed_cv: float = 0.03
    """Slow fluctuation of the cruising speed along the route (CV) [E]."""
    speed_correlation_m: float = 15.0
    """Correlation length of that fluctuation along the route [E]."""
    step_length_cv: float = 0.04
    """Step-to-step variation of step length (CV 3–5 %; at most 0.1)."""
    step_time_cv: float = 0.025
    """Step-to-step variation of step duration (CV 2–3 %; at most 0.1)."""
    asymmetry: float = 0.02
    """Left steps are longer than right ones by this fraction of the mean
    (negative: right longer) [E: healthy gait ≈ 1–3 %]."""
    stand_start_s: float = 3.0
    """Standing still before the first step, as real recordings begin."""
    stand_end_s: float = 3.0
    """Standing still after the last step."""
    stop_rate_per_min: float = 0.0
    """Mean number of mid-walk stops per minute of walking (Poisson)."""
    stop_duration_s: tuple[float, float] = (2.0, 6.0)
    """Range of a stop's duration (uniform)."""
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
    speed_oscillation: float = 0.1
    """Intra-step forward speed swing (amplitude) as a fraction of the speed [E]."""
    lateral_sway_m: tuple[float, float] = (0.02, 0.03)
    """Range of the lateral sway amplitude toward the stance foot (±2–3 cm)."""
    trunk_yaw_deg: tuple[float, float] = (3.0, 8.0)
    """Range of the trunk's yaw oscillation amplitude at stride frequency (±3–8°)."""
    heel_strike_mps2: tuple[float, float] = (1.0, 2.5)
    """Range of the vertical heel-strike transient's peak at cruising speed; on
    top of the bounce this keeps heel-strike peaks at 1.3–2 g in total."""
    physics_rate_hz: float = 25.0
    """Step rate of the pymunk body simulation."""

    def __post_init__(self) -> None:
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
            "stop_rate_per_min": self.stop_rate_per_min >= 0,
            "stop_duration_s": 0 < self.stop_duration_s[0] <= self.stop_duration_s[1],
            "max_yaw_rate_dps": self.max_yaw_rate_dps > 0,
            "turn_steps_per_90deg": self.turn_steps_per_90deg > 0,
            "pivot_turn_deg": 0 < self.pivot_turn_deg < 180,
            "max_accel_mps2": self.max_accel_mps2 > 0,
            "wall_distance_m": self.wall_distance_m >= 0,
            "body_radius_m": 0.05 <= self.body_radius_m <= 0.5,
            "bounce_fraction": self.bounce_fraction >= 0,
            "speed_oscillation": 0 <= self.speed_oscillation < 0.5,
            "lateral_sway_m": 0 <= self.lateral_sway_m[0] <= self.lateral_sway_m[1],
            "trunk_yaw_deg": 0 <= self.trunk_yaw_deg[0] <= self.trunk_yaw_deg[1],
            "heel_strike_mps2": 0 <= self.heel_strike_mps2[0] <= self.heel_strike_mps2[1],
            "physics_rate_hz": 10 <= self.physics_rate_hz <= 200,
        }
        bad = [name for name, ok in checks.items() if not ok]
        if bad:
            values = ", ".join(f"{name}={getattr(self, name)!r}" for name in bad)
            raise ValueError(f"WalkerParams out of range: {values}")


@dataclass(frozen=True, kw_only=True, eq=False)
class BodyTrajectory:
    """The walker's true body motion, sampled uniformly.

    Attributes:
        t: (K,) time in seconds from the start, at ``rate_hz``.
        pos: (K, 3) body centre (pelvis) in the building frame, metres.
        heading: (K,) walking direction, radians from +x, unwrapped.
        yaw: (K,) trunk yaw: heading plus the stride-frequency trunk rotation.
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
    heading: NDArray[np.float64]
    yaw: NDArray[np.float64]
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
    path = _Path.build(
        route.points, plan, params, float(step_length_m(v_cruise, height)), omega_lim
    ).keep_off_walls(plan, params.wall_distance_m)
    dwells = _dwells(path, params, v_cruise, omega_lim, rng)
    speed_factor = _speed_fluctuation(path.length, params, rng)
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

    # Macro track: the pymunk body steered through the planned knots, then C².
    dt_phys = 1.0 / params.physics_rate_hz
    # A few samples past a cut keep the derived speed central at the cut itself.
    end = duration if until_s is None else min(duration, max(until_s, 0.0) + 0.05)
    # The physics runs a little past the end, so that the spline through its
    # track has the same values up to the end as the whole walk's would (a
    # cubic spline's end condition fades by ~4× per knot).
    phys_end = min(duration, end + _SPLINE_TAIL_S)
    t_phys = np.arange(math.ceil(phys_end / dt_phys) + 1) * dt_phys
    track = _steer(plan, path.position(timeline.distance(t_phys)), dt_phys, params.body_radius_m)
    t = np.arange(math.floor(end * rate_hz + 1e-9) + 1) / rate_hz
    macro = CubicSpline(t_phys, track, axis=0)(t)

    # Intra-step motion on top, in the walking direction's frame.
    phase = timeline.phase(t)
    env = timeline.envelope(t)
    heading = path.heading(timeline.distance(t)) + timeline.pivot_heading(t)
    stride = np.mod((phase - (1.0 if first_left else 0.0)) / 2.0, 1.0)
    steps = timeline.steps()
    lengths = steps["length"].to_numpy()
    leg = PELVIS_HEIGHT_RATIO * height
    durations = timeline.step_durations()
    # Peak-to-peak bounce, capped where fast walking would make its vertical
    # acceleration exceed half of g (the walk-to-run transition lies near g).
    bounce = np.minimum(
        params.bounce_fraction * lengths**2 / (8.0 * leg),
        _G * (durations / (2.0 * np.pi)) ** 2,
    )
    swing = params.speed_oscillation * lengths / (2.0 * np.pi)  # forward swing amplitude
    amp = _per_step_curve(np.column_stack([bounce, swing]), phase)
    cyc = 2.0 * np.pi * (phase - _DOUBLE_SUPPORT_PHASE)
    sway = rng.uniform(*params.lateral_sway_m)
    yaw_amp = math.radians(rng.uniform(*params.trunk_yaw_deg))
    hs_t = steps["t"].to_numpy()
    # Gentler impacts on slow steps (gait initiation, turns), with a little scatter.
    hs_up = (
        rng.uniform(*params.heel_strike_mps2)
        * np.clip(lengths / durations / v_cruise, 0.3, 1.3)
        * rng.uniform(0.85, 1.15, len(hs_t))
    )
    # The heel strike jolts the pelvis up and brakes it at half that.
    jolt = impulse_displacement(t, hs_t, hs_up)
    fwd = env * amp[:, 1] * np.sin(cyc) - 0.5 * jolt
    lat = env * sway * np.sin(2.0 * np.pi * stride)
    up = -0.5 * env * amp[:, 0] * np.cos(cyc) + jolt
    ch, sh = np.cos(heading), np.sin(heading)
    # x and y as contiguous rows: np.gradient along rows is cheaper than down
    # the columns of (K, 3) positions (the same values).
    xy = np.empty((2, len(t)))
    xy[0] = macro[:, 0] + fwd * ch - lat * sh
    xy[1] = macro[:, 1] + fwd * sh + lat * ch
    pos = np.column_stack([xy[0], xy[1], leg + up])
    vel = np.gradient(xy, t, axis=1)
    if end < duration:
        steps = steps[steps["t"] <= t[-1]].reset_index(drop=True)
    return BodyTrajectory(
        t=t,
        pos=pos,
        heading=heading,
        yaw=heading + env * yaw_amp * np.cos(2.0 * np.pi * stride),
        speed=np.hypot(vel[0], vel[1]),
        step_phase=phase,
        stride_phase=stride,
        moving=timeline.moving(t),
        gait_envelope=env,
        steps=steps,
        height_m=height,
        rate_hz=float(rate_hz),
    )


# ---------------------------------------------------------------------- path


_UnitTurn = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], float]


@functools.lru_cache(maxsize=64)
def _turn_grid(n: int) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """What a unit turn at n points takes from its parameter alone: u (4(n − 1) + 1
    points on [0, 1]), u − sin(2πu)/2π, and sin²(πu) at every 4th u."""
    u = np.linspace(0.0, 1.0, 4 * (n - 1) + 1)
    shape = u - np.sin(2.0 * np.pi * u) / (2.0 * np.pi)
    bell = np.sin(np.pi * u[::4]) ** 2
    for a in (u, shape, bell):
        a.flags.writeable = False
    return u, shape, bell


# Unit turns by (φ, n), most recently used last: routes pass many of their
# corners more than once. The lock keeps the bookkeeping whole under threads.
_UNIT_TURNS: dict[tuple[float, int], _UnitTurn] = {}
_UNIT_TURNS_SIZE = 256
_UNIT_TURNS_LOCK = threading.Lock()


def _unit_turns(keys: list[tuple[float, int]]) -> list[_UnitTurn]:
    """Turns by φ rad over unit length, from the origin heading +x, at n points,
    for each (φ, n) in ``keys``.

    Curvature 2φ·sin²(πu) for u in [0, 1], hence heading φ·(u − sin(2πu)/2π).
    Those not cached are computed together: the headings' cosines and sines
    in one call, the trapezoid integrals of the turns side by side in one
    array (each row's cumulative sum is that of the turn alone, so the same
    values as one turn at a time). Read-only arrays.

    Returns:
        For each key: (n, 2) points, (n,) heading, (n,) curvature, and the
        tangent length: the distance from either end to the corner where the
        two legs meet.
    """
    with _UNIT_TURNS_LOCK:
        found = {key: _UNIT_TURNS.pop(key) for key in keys if key in _UNIT_TURNS}
        _UNIT_TURNS.update(found)  # now the most recent
    missing = list(dict.fromkeys(key for key in keys if key not in found))
    if missing:
        grids = [_turn_grid(n) for _, n in missing]
        sizes = np.array([len(u) for u, _, _ in grids])
        theta = np.repeat([phi for phi, _ in missing], sizes) * np.concatenate(
            [shape for _, shape, _ in grids]
        )
        # The turns as rows, padded with u = 1 (no further area) after their ends.
        inside = np.arange(sizes.max()) < sizes[:, None]
        u = np.ones(inside.shape)
        u[inside] = np.concatenate([grid_u for grid_u, _, _ in grids])
        cos_sin = np.zeros((2, *inside.shape))
        cos_sin[:, inside] = np.stack([np.cos(theta), np.sin(theta)])
        xy = cumulative_trapezoid(cos_sin, u[None], initial=0.0)
        starts = np.cumsum(sizes) - sizes
        for k, (phi, n) in enumerate(missing):
            turn_xy = np.ascontiguousarray(xy[:, k, : sizes[k] : 4].T)
            turn_theta = theta[starts[k] : starts[k] + sizes[k] : 4].copy()
            kappa = 2.0 * phi * grids[k][2]
            for a in (turn_xy, turn_theta, kappa):
                a.flags.writeable = False
            # The curve is symmetric about the corner's bisector: its end lies
            # at corner + T·(cos φ, sin φ) with the corner at (T, 0).
            tangent = float(turn_xy[-1, 0] / (1.0 + math.cos(phi)))
            found[(phi, n)] = (turn_xy, turn_theta, kappa, tangent)
        with _UNIT_TURNS_LOCK:
            for key in missing:
                _UNIT_TURNS[key] = found[key]
            while len(_UNIT_TURNS) > _UNIT_TURNS_SIZE:
                del _UNIT_TURNS[next(iter(_UNIT_TURNS))]
    return [found[key] for key in keys]


def _place(
    unit_xy: NDArray[np.float64], length: float, start: NDArray[np.float64], angle: float
) -> NDArray[np.float64]:
    """Scale a unit curve to ``length``, rotate it to ``angle`` and move it to ``start``."""
    c, s = math.cos(angle), math.sin(angle)
    return start + (unit_xy * length) @ np.array([[c, s], [-s, c]])


def _turn_lengths(
    phi: NDArray[np.float64],
    corners: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
    preferred: NDArray[np.float64],
    room: NDArray[np.float64],
    boundary: shapely.Geometry,
    clearance: float,
) -> NDArray[np.float64]:
    """Longest curve length up to ``preferred`` that fits the legs and the walls, for
    each corner (turn ``phi``, vertex, unit directions in and out, all (m, ...)).

    The curve must keep ``clearance`` from the walkable area's boundary, or at
    least as much as the polyline corner it replaces keeps. Each corner's
    search shrinks its curve until it fits (at most _TURN_TRIES times); the
    corners still searching are tested together, one round per try, with the
    arithmetic of one corner at a time (so the same lengths).
    """
    vertex, d_in, d_out = corners
    if len(phi) == 0:
        return np.zeros(0)
    # The turns at 33 points (as _unit_turns computes them), all at once.
    u = np.linspace(0.0, 1.0, 129)
    theta = phi[:, None] * (u - np.sin(2.0 * np.pi * u) / (2.0 * np.pi))
    xy = cumulative_trapezoid(np.stack([np.cos(theta), np.sin(theta)]), u, initial=0.0)
    unit_xy = np.moveaxis(xy[:, :, ::4], 0, -1)
    tangent = unit_xy[:, -1, 0] / (1.0 + np.array([math.cos(p) for p in phi.tolist()]))
    length = np.minimum(preferred, room / tangent)
    rotation = np.array(
        [
            [[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]]
            for a in np.arctan2(d_in[:, 1], d_in[:, 0]).tolist()
        ]
    ).reshape(-1, 2, 2)
    active = np.arange(len(phi))
    for _ in range(_TURN_TRIES):
        k = active
        start = vertex[k] - d_in[k] * tangent[k, None] * length[k, None]
        end = vertex[k] + d_out[k] * tangent[k, None] * length[k, None]
        corner_xy = np.stack([start, vertex[k], end], axis=1)
        # Only the boundary near the corner matters: distances beyond the
        # clearance are never binding.
        lo, hi = corner_xy.min(axis=1) - clearance, corner_xy.max(axis=1) + clearance
        near = np.array(
            [
                shapely.clip_by_rect(boundary, x0, y0, x1, y1)
                for x0, y0, x1, y1 in np.column_stack([lo, hi]).tolist()
            ]
        )
        open_ = ~shapely.is_empty(near)
        k, near, start, corner_xy = k[open_], near[open_], start[open_], corner_xy[open_]
        need = np.minimum(clearance, shapely.distance(near, shapely.linestrings(corner_xy)))
        # The curves, scaled, rotated and moved into place (as _place does).
        curve = start[:, None, :] + (unit_xy[k] * length[k, None, None]) @ rotation[k]
        fits = shapely.distance(near, shapely.linestrings(curve)) >= need - 1e-9
        active = k[~fits]
        length[active] *= _TURN_SHRINK
        if len(active) == 0:
            break
    return length


def _smooth_pushes(
    where: NDArray[np.intp], push: NDArray[np.float64], sigma: float, out: NDArray[np.float64]
) -> None:
    """Add to the (n, 2) ``out`` the pushes placed at rows ``where`` (sorted) and
    smoothed along the path (Gaussian of ``sigma`` samples, nearest-value ends).

    Each stretch of pushed rows is filtered on its own, from 2·radius before its
    first push to 2·radius after its last (elsewhere the result is zero), and
    overlapping stretches add up: :func:`_filter_stretches`, which does
    ``scipy.ndimage.gaussian_filter1d``'s arithmetic in one compiled call
    instead of one scipy call per stretch, and adds each row in place (the
    same sums as adding the smoothed pushes as a whole).
    """
    n = len(out)
    weights = _gaussian_weights(sigma)
    radius = len(weights) - 1
    breaks = np.flatnonzero(np.diff(where) > 2 * radius + 1)
    firsts, lasts = np.r_[0, breaks + 1], np.r_[breaks, len(where) - 1]
    lo = np.maximum(0, where[firsts] - 2 * radius)
    hi = np.minimum(n, where[lasts] + 2 * radius + 1)
    _filter_stretches(where, np.ascontiguousarray(push), firsts, lasts, lo, hi, weights, out)


@numba.njit(cache=True, error_model="numpy")
def _maybe_close(base, offset, watch, slack):  # pragma: no cover - compiled
    """The watched rows (indices into ``watch``) whose offset has used up their slack,
    |x| + |y| ≥ slack, and where those points are now (base + offset): one pass
    instead of gathering every watched row's offset."""
    rows = np.empty(len(watch), dtype=np.intp)
    count = 0
    for i in range(len(watch)):
        r = watch[i]
        if abs(offset[r, 0]) + abs(offset[r, 1]) >= slack[i]:
            rows[count] = i
            count += 1
    pts = np.empty((count, 2))
    for k in range(count):
        r = watch[rows[k]]
        pts[k, 0] = base[r, 0] + offset[r, 0]
        pts[k, 1] = base[r, 1] + offset[r, 1]
    return rows[:count], pts


@functools.lru_cache(maxsize=8)
def _gaussian_weights(sigma: float) -> NDArray[np.float64]:
    """Weights of ``gaussian_filter1d(x, sigma)`` (default truncation) from the centre
    outwards, read off its response to a unit impulse (exact: all other terms are 0)."""
    radius = int(4.0 * sigma + 0.5)
    impulse = np.zeros(2 * radius + 1)
    impulse[radius] = 1.0
    weights = gaussian_filter1d(impulse, sigma)[radius:]
    weights.flags.writeable = False
    return weights


@numba.njit(cache=True, error_model="numpy")
def _filter_stretches(where, push, firsts, lasts, lo, hi, w, out):  # pragma: no cover - compiled
    """out[lo[c]:hi[c]] += stretch c (pushes where[firsts[c]:lasts[c] + 1]) filtered.

    Row i of a stretch x (extended by its end values) becomes
    x[i]·w[0] + Σ (x[i − j] + x[i + j])·w[j], j from the radius down to 1:
    gaussian_filter1d's sum, in its order, so the result is the same to the
    bit. Rows farther than the radius from every push are 0 and add nothing
    (``out`` starts at +0.0 and so never holds −0.0), so they are skipped. The
    rows one stretch reaches lie more than a radius from the next stretch's
    pushes, so each row gets at most one sum: adding in place gives what adding
    all the smoothed pushes at once would. The loop over rows is innermost,
    where the compiler vectorises it.
    """
    r = len(w) - 1
    for c in range(len(firsts)):
        first, last, a, b = firsts[c], lasts[c], lo[c], hi[c]
        size = b - a
        # The rows within reach of a push (relative to a).
        k0, k1 = max(where[first] - r, a) - a, min(where[last] + r + 1, b) - a
        m = k1 - k0
        for col in range(2):
            x = np.zeros(size + 2 * r)  # the stretch, padded by r at both ends
            for i in range(first, last + 1):
                x[where[i] - a + r] = push[i, col]
            x[:r] = x[r]
            x[size + r :] = x[size + r - 1]
            start = k0 + r  # x index of row k0
            acc = np.empty(m)
            for k in range(m):
                acc[k] = x[start + k] * w[0]
            for j in range(r, 0, -1):
                left, right, wj = x[start - j : start - j + m], x[start + j : start + j + m], w[j]
                for k in range(m):
                    acc[k] += (left[k] + right[k]) * wj
            dest = out[a + k0 : a + k1, col]
            for k in range(m):
                dest[k] += acc[k]


@numba.njit(cache=True, error_model="numpy")
def _window_max(knots, value, first, a, b, floor, out):  # pragma: no cover - compiled
    """out[i] = max(floor[i], |value| at the knots in [a[i], b[i]]), for ascending a
    and b; ``first`` is the first knot at or after a[0].

    A monotone deque of knot indices (|value| decreasing from its head) holds
    the candidates of the current window; each knot enters and leaves it once.
    """
    queue = np.empty(len(knots) - first, dtype=np.intp)
    head, tail, nxt = 0, 0, first
    for i in range(len(a)):
        while nxt < len(knots) and knots[nxt] <= b[i]:
            while tail > head and abs(value[queue[tail - 1]]) <= abs(value[nxt]):
                tail -= 1
            queue[tail] = nxt
            tail += 1
            nxt += 1
        while tail > head and knots[queue[head]] < a[i]:
            head += 1
        out[i] = floor[i]
        if tail > head and abs(value[queue[head]]) > out[i]:
            out[i] = abs(value[queue[head]])


def _drop_short_legs(pts: NDArray[np.float64]) -> NDArray[np.float64]:
    """The polyline without vertices within _MIN_LEG_M of the one kept before them.

    The end points stay; a vertex just before the end gives way to it.
    """
    # Usually every leg is long enough (with a margin for rounding): then
    # nothing is dropped, and the loop below need not run.
    if len(pts) >= 2 and np.all(np.hypot(*np.diff(pts, axis=0).T) > _MIN_LEG_M * (1.0 + 1e-9)):
        return pts.copy()
    keep = [0]
    for i in range(1, len(pts) - 1):
        if np.linalg.norm(pts[i] - pts[keep[-1]]) >= _MIN_LEG_M:
            keep.append(i)
    if len(keep) > 1 and np.linalg.norm(pts[-1] - pts[keep[-1]]) < _MIN_LEG_M:
        keep.pop()
    return pts[[*keep, len(pts) - 1]]


@dataclass(frozen=True)
class _Path:
    """The smoothed route as knots along its length, linearly interpolated
    (the heading cubically, with the curvature as its slope, so that the
    heading rate is continuous).

    ``theta`` leaves out the turns taken on the spot (``pivots``: distance
    along the path, heading change); those are added in time while the walker
    stands at the corner.
    """

    s: NDArray[np.float64]
    xy: NDArray[np.float64]
    theta: NDArray[np.float64]
    kappa: NDArray[np.float64]
    pivots: tuple[tuple[float, float], ...]

    @property
    def length(self) -> float:
        return float(self.s[-1])

    def position(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.column_stack(
            [np.interp(s, self.s, self.xy[:, 0]), np.interp(s, self.s, self.xy[:, 1])]
        )

    def heading(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        return _hermite(self.s, self.theta, self.kappa)(s)

    def max_curvature(self, s: NDArray[np.float64], half_width: float) -> NDArray[np.float64]:
        """Largest |curvature| within ``half_width`` of each distance in ``s`` (exact;
        ``s`` ascending).

        Curvature is linear between knots, so the maximum over a window is at a
        knot inside it or at one of its ends. The knots inside are covered by a
        sliding-window maximum, so even a curve far shorter than the window is
        never missed.
        """
        a, b = s - half_width, s + half_width
        edges = np.maximum(
            np.abs(np.interp(a, self.s, self.kappa)), np.abs(np.interp(b, self.s, self.kappa))
        )
        out = np.empty(len(s))
        first = int(np.searchsorted(self.s, a[0])) if len(s) else 0
        _window_max(self.s, self.kappa, first, a, b, edges, out)
        return out

    def keep_off_walls(self, plan: FloorPlan, distance: float) -> _Path:
        """This path, bent smoothly away from the walkable area's boundary where
        it comes closer than ``distance``.

        Each round pushes every point that is too close straight away from its
        nearest boundary point by its shortfall, and smooths the pushes along
        the path with a Gaussian (σ = 0.3 m) so the track stays smooth; pushes
        from opposite walls cancel, so a narrow passage is walked in its
        middle. Smoothing spreads a short push thin, so a sharp corner is
        cleared only partly: the pymunk body is the hard limit. Headings turn by
        the angle the push adds to the path's direction. Returns the path
        unchanged when nothing is too close.
        """
        if distance <= 0 or len(plan.walkable_edges) == 0:
            return self
        # Which metres of the path come near anything? One cheap query on points
        # every 0.2 m (with half that as margin for the chords between them).
        metres = math.ceil(self.length)
        coarse = self.position(np.minimum(np.linspace(0.0, metres, 5 * metres + 1), self.length))
        close = ~np.isnan(plan.nearest_boundary(coarse, distance + 0.11)[:, 0])
        hit = np.unique(np.minimum(np.flatnonzero(close) // 5, metres - 1)).astype(float)
        if len(hit) == 0:
            return self
        n = max(2, math.ceil(self.length / _KEEP_DS_M) + 1)
        s = np.linspace(0.0, self.length, n)
        # Pivot corners become knots (in place of their nearest grid point, so
        # the spacing stays even).
        for p, _ in self.pivots:
            s[np.clip(round(p / self.length * (n - 1)), 1, n - 2)] = p
        base = self.position(s)
        offset = np.zeros_like(base)
        # Points that may need a push: the hit metres and the smoothing's reach.
        reach = 4.0 * _KEEP_SMOOTH_M
        cover = np.zeros(len(s) + 1, dtype=int)
        np.add.at(cover, np.searchsorted(s, hit - reach), 1)
        np.add.at(cover, np.searchsorted(s, hit + 1.0 + reach), -1)
        watch = np.flatnonzero(np.cumsum(cover)[:-1] > 0)
        sigma = _KEEP_SMOOTH_M / _KEEP_DS_M
        # One scan a little beyond ``distance`` gives each watched point its
        # slack: how much nearer the boundary it would have to come to be too
        # close. A point moves by its offset (at most |x| + |y| of it), so only
        # points whose offset has used up their slack can be too close; only
        # those are queried (the rest would surely find nothing: the margin
        # covers rounding), which gives the same pushes as querying them all.
        base_w = base[watch]
        scan_m = distance + _KEEP_SCAN_M
        seen = plan.nearest_boundary(base_w, scan_m)
        gap0 = np.where(np.isnan(seen[:, 0]), scan_m, np.linalg.norm(base_w - seen, axis=1))
        slack = gap0 - distance - 1e-6
        for _ in range(_KEEP_ROUNDS):
            maybe, pts = _maybe_close(base, offset, watch, slack)
            # Each point is pushed from its nearest boundary point only.
            nearest = plan.nearest_boundary(pts, distance)
            near = np.flatnonzero(~np.isnan(nearest[:, 0]))
            if len(near) == 0:
                break
            away = pts[near] - nearest[near]
            gap = np.linalg.norm(away, axis=1)
            scale = (distance - gap) / np.maximum(gap, 1e-12)
            _smooth_pushes(watch[maybe[near]], away * scale[:, None], sigma, offset)
        if not offset.any():
            return self
        moved = base + offset
        d_old, d_new = np.diff(base, axis=0), np.diff(moved, axis=0)
        s_new = _cumsum0(np.linalg.norm(d_new, axis=1))
        # How far the push turns each chord, averaged onto the knots (chords,
        # not central differences, so that a pivot's corner adds no spike).
        turn = np.arctan2(
            d_old[:, 0] * d_new[:, 1] - d_old[:, 1] * d_new[:, 0],
            np.einsum("ij,ij->i", d_old, d_new),
        )
        theta = self.heading(s) + np.r_[turn[0], 0.5 * (turn[:-1] + turn[1:]), turn[-1]]
        return _Path(
            s=s_new,
            xy=moved,
            theta=theta,
            kappa=np.gradient(theta, s_new),
            pivots=tuple((float(np.interp(p, s, s_new)), dth) for p, dth in self.pivots),
        )

    @classmethod
    def build(
        cls,
        pts: NDArray[np.float64],
        plan: FloorPlan,
        params: WalkerParams,
        step_m: float,
        omega_lim: float,
    ) -> _Path:
        """Smooth the polyline ``pts``.

        Args:
            pts: the route's vertices.
            plan: the floor plan, for the clearance of the turns.
            params: the walker.
            step_m: the cruising step length.
            omega_lim: the yaw rate (rad/s) the turns are planned for.
        """
        pts = _drop_short_legs(pts)
        d = np.diff(pts, axis=0)
        legs = np.linalg.norm(d, axis=1)
        unit = d / legs[:, None]
        ang = np.arctan2(d[:, 1], d[:, 0])
        turns = np.angle(np.exp(1j * np.diff(ang)))  # wrapped to (−π, π]
        boundary = plan.walkable.boundary
        pivot_rad = math.radians(params.pivot_turn_deg)
        # Knot rows (s, x, y, heading without pivots, curvature), in blocks.
        blocks = [np.array([[0.0, *pts[0], ang[0], 0.0]])]
        pivots: list[tuple[float, float]] = []
        theta = float(ang[0])

        def line_to(p: NDArray[np.float64]) -> None:
            s0, x0, y0 = blocks[-1][-1, :3]
            ds = math.hypot(p[0] - x0, p[1] - y0)
            if ds > 1e-12:
                blocks.append(np.array([[s0 + ds, p[0], p[1], theta, 0.0]]))

        # The corners turned while walking, and their curves' lengths (found
        # for all corners at once).
        turned = np.flatnonzero((np.abs(turns) >= 1e-9) & (np.abs(turns) <= pivot_rad))
        room = np.minimum(
            np.where(turned == 0, legs[turned], 0.5 * legs[turned]),
            np.where(turned + 2 == len(legs), legs[turned + 1], 0.5 * legs[turned + 1]),
        )
        fitted = np.full(len(turns), np.nan)
        fitted[turned] = _turn_lengths(
            turns[turned],
            (pts[turned + 1], unit[turned], unit[turned + 1]),
            params.turn_steps_per_90deg * np.sqrt(np.abs(turns[turned]) / (math.pi / 2)) * step_m,
            room,
            boundary,
            params.wall_distance_m,
        )

        # Where the curve would have to be so tight that it could only be
        # walked at a crawl, people stop and turn on the spot instead. The
        # other corners' curves (their unit turns computed together).
        curves = {}
        for j in turned.tolist():
            phi, length = turns[j], fitted[j]
            if omega_lim * length / (2.0 * abs(phi)) >= _PIVOT_BELOW_MPS:
                curves[j] = (float(phi), max(9, math.ceil(length / _CURVE_DS_M) + 1))
        unit_turns = dict(zip(curves, _unit_turns(list(curves.values())), strict=True))

        for j, phi in enumerate(turns):
            vertex = pts[j + 1]
            if abs(phi) < 1e-9:  # collinear: nothing to turn
                continue
            if j not in curves:  # sharper than a pivot turn, or too cramped to walk
                line_to(vertex)
                pivots.append((float(blocks[-1][-1, 0]), float(phi)))
                continue
            length = fitted[j]
            n = curves[j][1]
            unit_xy, unit_th, unit_ka, tangent = unit_turns[j]
            start = vertex - unit[j] * tangent * length
            line_to(start)
            xy = _place(unit_xy, length, start, float(ang[j]))
            blocks.append(
                np.column_stack(
                    [
                        blocks[-1][-1, 0] + np.linspace(0.0, length, n)[1:],
                        xy[1:],
                        theta + unit_th[1:],
                        unit_ka[1:] / length,
                    ]
                )
            )
            theta += float(phi)
        line_to(pts[-1])
        arr = np.concatenate(blocks)
        return cls(
            s=arr[:, 0], xy=arr[:, 1:3], theta=arr[:, 3], kappa=arr[:, 4], pivots=tuple(pivots)
        )


# ---------------------------------------------------------------------- timing


@dataclass(frozen=True)
class _Dwell:
    """Standing at distance ``s`` for ``duration`` s, turning by ``dtheta`` meanwhile."""

    s: float
    duration: float
    dtheta: float = 0.0


def _dwells(
    path: _Path,
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
        path: _Path,
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
        _speed_profile(grid, v_lim, s_a, 2.0 * params.max_accel_mps2, v, dtau)
        # Time along the profile (exact for constant acceleration between knots).
        tau = _cumsum0(dtau)

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
        times = time_nom * (1.0 + np.clip(rng.normal(0.0, cv_t, count), -3 * cv_t, 3 * cv_t))
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

        s_knots = s_a + _cumsum0(lengths)
        s_knots[-1] = s_b
        # A step that came out fast enough to break the yaw-rate limit on a
        # curve takes longer instead (as a walker slows into a turn). Checked
        # against the step-wide curvature bound, with a little room left.
        omega_max = 0.97 * math.radians(params.max_yaw_rate_dps)
        for _ in range(5):
            t_knots = t0 + _cumsum0(times)
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


@numba.njit(cache=True, error_model="numpy")
def _speed_profile(grid, v_lim, s_a, two_a, v, dtau):  # pragma: no cover - compiled
    """The bout's speed ``v`` on ``grid`` under the cap ``v_lim``, 0 at both ends, and
    the time ``dtau`` from each grid point to the next.

    The acceleration passes are closed forms of the usual forward/backward
    sweeps, v²(s) ≤ v²(s') + 2a|s − s'|, with x = 2a·(s − s_a):
    w = min(w, x + running min of (w − x)), then the same backwards with
    w + x; v = √max(w, 0), and dtau = 2·Δs / max(v + v_next, 1e-12) (exact
    for constant acceleration between grid points). One pass each, with the
    same operations as the array expressions they replace.
    """
    n = len(grid)
    x = np.empty(n)
    w = np.empty(n)
    for i in range(n):
        x[i] = two_a * (grid[i] - s_a)
        w[i] = 0.0 if i == 0 or i == n - 1 else v_lim[i] * v_lim[i]
    low = np.inf
    for i in range(n):
        low = min(low, w[i] - x[i])
        w[i] = min(w[i], x[i] + low)
    low = np.inf
    for i in range(n - 1, -1, -1):
        low = min(low, w[i] + x[i])
        w[i] = min(w[i], low - x[i])
    for i in range(n):
        v[i] = math.sqrt(max(w[i], 0.0))
    for i in range(n - 1):
        dtau[i] = 2.0 * (grid[i + 1] - grid[i]) / max(v[i + 1] + v[i], 1e-12)


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
    return _hermite(x, y, dydx[:, 0])


def _hermite(x: NDArray[np.float64], y: NDArray[np.float64], dydx: NDArray[np.float64]) -> PPoly:
    """``CubicHermiteSpline(x, y, dydx)`` for 1-D data: the same coefficients, without
    its input checks (but for increasing ``x``) and array-API dispatch."""
    dx = np.diff(x)
    if not np.all(dx > 0):
        raise ValueError("`x` must be strictly increasing sequence.")
    slope = np.diff(y) / dx
    t = (dydx[:-1] + dydx[1:] - 2 * slope) / dx
    c = np.stack((t / dx, (slope - dydx[:-1]) / dx - t, dydx[:-1], y[:-1]))
    return PPoly.construct_fast(c, np.ascontiguousarray(x, dtype=float))


def _cumsum0(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.r_[0.0, np.cumsum(x)]``, without np.r_'s parsing (it costs more than the sum)."""
    out = np.empty(len(x) + 1)
    out[0] = 0.0
    np.cumsum(x, out=out[1:])
    return out


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


# ---------------------------------------------------------------------- motion


def _steer(
    plan: FloorPlan, ref: NDArray[np.float64], dt: float, radius: float
) -> NDArray[np.float64]:
    """Drive a pymunk disc through the reference positions ``ref`` (one per ``dt``).

    A kinematic control body carries the plan; a pivot joint of bounded force
    drags the disc after it, and the walkable area's boundary, as static
    segments, stops it. The control body runs one step ahead, because pymunk
    moves bodies with the velocity solved in the previous step: without a wall
    in the way the disc lands exactly on every reference point. Once a wall has
    held it back, the joint pulls it back onto the plan at a bounded speed.
    """
    space = pymunk.Space()
    space.collision_slop = 1e-3  # pymunk's default (0.1) is in metres here: far too loose
    walls = []
    for a, b in plan.walkable_edges.tolist():
        seg = pymunk.Segment(space.static_body, a, b, 0.0)
        seg.friction = 0.0
        walls.append(seg)
    space.add(*walls)  # in one call: pymunk's add costs more per call than per shape
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


def _polygons(geom: shapely.Geometry) -> list[shapely.Polygon]:
    if geom.is_empty:
        return []
    return list(getattr(geom, "geoms", [geom]))


def _per_step_curve(values: NDArray[np.float64], phase: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per-step quantities as C² functions of the step phase.

    Knots at mid-step, plus the first and last values held at phase 0 and at
    the last heel strike, so the phase (which never leaves that range) needs
    no clipping, which would put kinks into the motion.
    """
    n = len(values)
    knots = np.r_[0.0, np.arange(n) + 0.5, n]
    held = np.concatenate([values[:1], values, values[-1:]])
    return CubicSpline(knots, held, axis=0, bc_type="natural")(phase)
