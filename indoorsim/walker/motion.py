"""Motion: what the body does within each step, on top of its macro track.

:func:`intra_step_motion` is the last stage of
:func:`~indoorsim.walker.gait.walk` (DESIGN §5, numbers from REALISM §5),
added analytically at ``rate_hz``: vertical bounce at step frequency (lowest
just after heel strike), the forward surge the ground's force gives it
(:func:`surge_waveforms`: braking as the leading leg takes the load, propulsion
as the trailing leg pushes off), lateral
sway and lean toward the stance foot and trunk yaw at stride frequency, and heel-strike
transients shaped as Ricker wavelets of the acceleration (smooth, zero net
velocity change; :func:`impulse_displacement`, which the carrying modes use
for the phone's own jolts too). Amplitudes follow each step's length and fade
in and out with every bout, so positions stay C².

Frames: offsets in the walking direction's frame (forward, left, up), metres;
trunk yaw in radians. All randomness comes from the ``rng`` argument.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

__all__ = [
    "IntraStepMotion",
    "bounce_waveform",
    "harmonic_series",
    "impulse_displacement",
    "intra_step_motion",
    "surge_waveforms",
]

_G = 9.81  # m/s²
# Heel-strike transients last about ±3σ (when they peak: below). At
# the trunk σ = 30 ms puts their energy at 4–10 Hz: the heel pad, the knee and
# the spine's soft tissue have spread the impact [E]. Hand-held phones demand
# it: below the forearm's 6 Hz resonance the jolt reaches the hand, and the
# real ILC hand-held walks' ‖a‖ (std 1.7–5.8 m/s², per-stride peak-to-peak
# 6.8–17, crest 2.5–5.7, excess kurtosis up to 7.7) are reached; at 15 ms
# (10–20 Hz) the forearm filtered the jolt out and the hand read a sinusoid.
_HS_SIGMA_S = 0.03
# At the trunk the jolt peaks with the loading, about 40 ms after contact: the leg's
# joints and soft tissue carry it up as weight acceptance loads them. The ILC traces'
# flat-held phones say so: their vertical acceleration's second and third harmonics
# sit −8° and −5° from the step rate's (median over 16; φ₂ − 2φ₁ and φ₃ − 3φ₁), where
# a jolt 20 ms after contact put their twins at +4° and +34°, 40 ms at −2° and −2°,
# 50 ms at −5° and −17°. Nearer the heel, at a thigh's pocket, it comes sooner.
_TRUNK_JOLT_DELAY_S = 0.04
_HS_DELAY_S = 0.02
# The vertical minimum and forward-speed maximum come just after heel strike,
# in double support (as a fraction of a step).
_DOUBLE_SUPPORT_PHASE = 0.1
# Harmonics of the step rate kept in the vertical bounce's waveform: the
# fifth of a 0.08-step-wide loading peak carries 0.2 % of its power.
_BOUNCE_HARMONICS = 5


def bounce_waveform(phase: NDArray[np.float64], width: float) -> NDArray[np.float64]:
    """Vertical offset of the body centre within a step, peak to peak 1, mean 0.

    The body centre's vertical acceleration peaks once per step, in double
    support just after heel strike, when both legs carry the body and the
    ground reaction force is highest (weight acceptance, 1.3–2 g at the trunk,
    REALISM §5), and sags through single support. Modelled as a periodic
    Gaussian pulse of acceleration of ``width`` (σ, in steps) centred
    ``_DOUBLE_SUPPORT_PHASE`` after each heel strike: its k-th harmonic has
    relative amplitude exp(−(2πk·width)²/2), so the offset, the acceleration
    integrated twice, is the sum of those harmonics divided by k². A wide pulse
    is the sinusoidal bounce of the compass gait; a narrow one makes the
    impulsive, harmonic-rich ‖a‖ of real walking.
    """
    k, accel = _loading_peak(width)
    grid = np.linspace(0.0, 1.0, 513)[:-1]
    scale = _offset_scale(accel, k, 2.0 * np.pi * np.outer(grid, k))
    weight = accel / k**2
    return -scale * harmonic_series(phase - _DOUBLE_SUPPORT_PHASE, weight)


def _loading_peak(width: float) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """The step rate's harmonics k of the loading peak and their relative amplitudes in
    the acceleration, exp(−(2πk·width)²/2) (:func:`bounce_waveform`)."""
    k = np.arange(1, _BOUNCE_HARMONICS + 1)
    return k, np.exp(-0.5 * (2.0 * np.pi * k * width) ** 2)


def _offset_scale(
    accel: NDArray[np.float64], k: NDArray[np.int64], angles: NDArray[np.float64]
) -> float:
    """1 / the peak to peak of the offset whose acceleration harmonics are ``accel``,
    over a step sampled at ``angles`` ((N, H): each sample's k·x): the scale that makes
    the bounce's offset 1 peak to peak."""
    return 1.0 / float(np.ptp(-(accel / k**2 * np.cos(angles)).sum(axis=1)))


_SURGE_HARMONICS = 8
"""Harmonics of the step rate kept in the forward surge: above the eighth lie 0.01–0.02 %
of its acceleration's power (loading peaks 0.03–0.21 of a step wide), an RMS error of
about 1.4 %."""


def surge_waveforms(
    width: float, double_support: float, cop_travel_steps: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Fourier coefficients of the body centre's forward offset within a step, as the
    ground's force drives it: (gravity's part, the loading peak's part), each (H,)
    complex for the step rate's harmonics 1 … H.

    The stance leg pushes along itself, so the ground's horizontal force is its
    vertical force times the lever of the body centre over the centre of pressure,
    over the centre's height (the inverted pendulum with a foot): a_fwd = (g + a_up)·λ/h.
    Over a step of length D the lever runs from −D/2 at heel strike (the leading foot
    ahead: braking) to +D/2 at the next (the body centre past the foot: propulsion),
    less the centre of pressure's roll from heel to forefoot (``cop_travel_steps``);
    in double support (the first ``double_support`` of the step) the load passes from
    the trailing leg, pushing off from its toes, to the leading one (a smoothstep of
    weight). The vertical force peaks as the load passes (:func:`bounce_waveform`'s
    loading peak of ``width``), so the braking after heel strike and the push-off
    before it are sharp and rich in harmonics, where the body's speed swing used to
    be one sinusoid. The mean of the product is removed, by assumption: the lever
    averages −0.03 of a step (mostly the foot's roll), which would take about
    0.2 m/s² off a steady walk's speed; the push-off's work that makes up for it, and
    the forces the model leaves out, are not modelled, so the surge is the product's
    swing about its mean.

    With λ = D·ℓ(p) and a_up = bounce·(2π/T)²·u(p) (u the loading peak of unit
    bounce), the forward offset is (D/h)·[g·(T/2π)²·G(p) + bounce·L(p)]: G and L are
    the harmonic series returned here (of ℓ and of u·ℓ, each harmonic k divided by
    −k²), so cadence, step length and bounce scale a step's surge through the two
    amplitudes alone.

    Args:
        width: the loading peak's width σ, in steps (:func:`bounce_waveform`).
        double_support: the share of the step over which the load passes between
            the legs.
        cop_travel_steps: the centre of pressure's roll along the foot over a step,
            in steps.

    Returns:
        (G, L): (H,) complex coefficients each, H = :data:`_SURGE_HARMONICS`, for
        :func:`harmonic_series`.
    """
    grid = np.arange(512) / 512.0
    x = 2.0 * np.pi * (grid - _DOUBLE_SUPPORT_PHASE)
    # u: the loading peak's acceleration for a bounce of peak to peak 1 (in units of
    # (2π/T)²·bounce), the second derivative of bounce_waveform's offset.
    k, weight = _loading_peak(width)
    angles = np.outer(x, k)
    loading = _offset_scale(weight, k, angles) * (weight * np.cos(angles)).sum(axis=1)
    share = np.clip(grid / double_support, 0.0, 1.0)
    share = share * share * (3.0 - 2.0 * share)  # of the load on the leading leg
    lever = share * (grid - 0.5 - cop_travel_steps * grid) + (1.0 - share) * (
        grid + 0.5 - cop_travel_steps
    )
    h = np.arange(1, _SURGE_HARMONICS + 1)
    out = []
    for accel in (lever, loading * lever):
        coeff = np.fft.rfft(accel)[1 : _SURGE_HARMONICS + 1] * (2.0 / len(grid))
        out.append(-coeff / h**2)
    return out[0], out[1]


def harmonic_series(phase: NDArray[np.float64], coeff: ArrayLike) -> NDArray[np.float64]:
    """Σ_k Re(c_k·e^{2πik·phase}) for k = 1 … H: step-periodic waveforms.

    ``coeff`` is (H,) for one waveform, or (M, H) for M waveforms at the same phases
    (which share the work: the result is then (M, K)).

    cos 2πp + 0.5·sin 4πp (a coefficient −i is a sine):

    >>> harmonic_series(np.array([0.0, 0.125]), np.array([1.0, -0.5j])).round(6).tolist()
    [1.0, 1.207107]
    """
    c = np.asarray(coeff, dtype=complex)
    if c.ndim not in (1, 2):
        raise ValueError(f"coeff must be (H,) or (M, H), got shape {c.shape}")
    rows = np.atleast_2d(c)
    phase = np.ascontiguousarray(phase, dtype=float)
    out = np.zeros((rows.shape[0], len(phase)))
    _harmonic_kernel(phase, np.ascontiguousarray(rows.real), np.ascontiguousarray(rows.imag), out)
    return out[0] if c.ndim == 1 else out


@numba.njit(cache=True, error_model="numpy")
def _harmonic_kernel(phase, re, im, out):  # pragma: no cover - compiled
    """out[m, i] = Σ_k re[m, k]·cos((k+1)x_i) − im[m, k]·sin((k+1)x_i), x = 2π·phase: cos
    and sin of the higher harmonics by the angle-addition recurrence, one pair of
    transcendental calls per sample."""
    two_pi = 2.0 * np.pi
    for i in range(phase.shape[0]):
        c1 = np.cos(two_pi * phase[i])
        s1 = np.sin(two_pi * phase[i])
        ck, sk = c1, s1
        for k in range(re.shape[1]):
            if k:
                ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1
            for m in range(re.shape[0]):
                out[m, i] += re[m, k] * ck - im[m, k] * sk


class IntraStepMotion(NamedTuple):
    """The body centre's motion within each step, in the walking direction's frame."""

    forward: NDArray[np.float64]
    """(K,) offset along the walking direction (m)."""
    lateral: NDArray[np.float64]
    """(K,) offset to the left of it (m)."""
    up: NDArray[np.float64]
    """(K,) offset from the standing pelvis height (m)."""
    trunk_yaw: NDArray[np.float64]
    """(K,) trunk rotation on top of the heading (rad)."""
    trunk_roll: NDArray[np.float64]
    """(K,) trunk lean toward the stance leg (rad, + to the left)."""
    trunk_pitch: NDArray[np.float64]
    """(K,) trunk lean forward (rad, + forward): most in double support, least at
    the top of the bounce."""


def intra_step_motion(
    t: NDArray[np.float64],
    *,
    phase: NDArray[np.float64],
    stride: NDArray[np.float64],
    envelope: NDArray[np.float64],
    strike_t: NDArray[np.float64],
    step_lengths: NDArray[np.float64],
    step_durations: NDArray[np.float64],
    leg_m: float,
    cruise_mps: float,
    bounce_fraction: float,
    double_support: float,
    cop_travel_m: float,
    lateral_sway_m: tuple[float, float],
    trunk_yaw_deg: tuple[float, float],
    trunk_roll_deg: tuple[float, float],
    trunk_pitch_deg: tuple[float, float],
    heel_strike_mps2: tuple[float, float],
    loading_width: tuple[float, float],
    loading_asymmetry: tuple[float, float],
    rng: np.random.Generator,
) -> IntraStepMotion:
    """Bounce, forward surge, sway, trunk yaw and heel-strike jolts at the times ``t``.

    Args:
        t: (K,) sample times (s).
        phase: (K,) steps completed at each sample (the step phase).
        stride: (K,) position in the gait cycle in [0, 1), 0 at left heel strikes.
        envelope: (K,) 0 standing, 1 walking, C² in between: scales every motion.
        strike_t: (N,) heel-strike times (s).
        step_lengths: (N,) length of each step (m).
        step_durations: (N,) duration of each step (s).
        leg_m: standing height of the pelvis (m).
        cruise_mps: cruising speed; slower steps strike more gently.
        bounce_fraction: vertical excursion as a fraction of the compass-gait
            value step²/(8·leg).
        double_support: the share of a step in which both feet carry the body and
            the load passes from the trailing leg to the leading one.
        cop_travel_m: how far the centre of pressure rolls along the stance foot
            over a step, heel to forefoot (m).
        lateral_sway_m: range of the sway amplitude (drawn once per walk).
        trunk_yaw_deg: range of the trunk yaw amplitude (drawn once per walk).
        trunk_roll_deg: range of the trunk's sideways lean amplitude (drawn once per walk).
        trunk_pitch_deg: range of the trunk's forward lean within each step, half its
            peak to peak in a step of the walk's median bounce (drawn once per walk,
            after every other draw).
        heel_strike_mps2: range of the heel-strike peak at cruising speed.
        loading_width: range of the width of the vertical acceleration's
            weight-acceptance peak, in steps (drawn once per walk;
            :func:`bounce_waveform`).
        loading_asymmetry: range of the relative difference between the bounce
            of left and right steps (drawn once per walk, either leg the stronger).
        rng: draws the walk's sway, trunk yaw, roll and pitch, loading width and
            asymmetry, and the heel-strike amplitudes.

    Returns:
        The offsets from the macro track and the trunk's yaw, roll and pitch.
    """
    # Peak-to-peak bounce, capped where fast walking would make its vertical
    # acceleration exceed half of g (the walk-to-run transition lies near g).
    bounce = np.minimum(
        bounce_fraction * step_lengths**2 / (8.0 * leg_m),
        _G * (step_durations / (2.0 * np.pi)) ** 2,
    )
    # One leg loads the body harder than the other: alternate steps bounce more.
    lopsided = rng.uniform(*loading_asymmetry) * rng.choice([-1.0, 1.0])
    bounce = bounce * (1.0 + 0.5 * lopsided * (-1.0) ** np.arange(len(bounce)))
    # The forward surge's two parts per step (surge_waveforms): gravity's through the
    # lever, and the loading peak's.
    gravity_surge = step_lengths / leg_m * _G * (step_durations / (2.0 * np.pi)) ** 2
    loading_surge = step_lengths / leg_m * bounce
    amp = _per_step_curve(np.column_stack([bounce, gravity_surge, loading_surge]), phase)
    sway = rng.uniform(*lateral_sway_m)
    yaw_amp = math.radians(rng.uniform(*trunk_yaw_deg))
    roll_amp = math.radians(rng.uniform(*trunk_roll_deg))
    # Gentler impacts on slow steps (gait initiation, turns), with a little scatter.
    hs_up = (
        rng.uniform(*heel_strike_mps2)
        * np.clip(step_lengths / step_durations / cruise_mps, 0.3, 1.3)
        * rng.uniform(0.85, 1.15, len(strike_t))
    )
    width = rng.uniform(*loading_width)
    # The foot's roll as a share of the walk's median step: one waveform for the walk,
    # so a short step (starting, turning) rolls as far, in steps, as a cruising one,
    # where in metres it would roll further.
    typical_step = float(np.median(step_lengths)) if len(step_lengths) else 1.0
    surge = harmonic_series(
        phase, np.stack(surge_waveforms(width, double_support, cop_travel_m / typical_step))
    )
    # The heel strike jolts the pelvis up and brakes it at half that.
    jolt = impulse_displacement(t, strike_t, hs_up, delay_s=_TRUNK_JOLT_DELAY_S)
    # The trunk leans forward as heel strike brakes the pelvis beneath it (double
    # support, the bounce's bottom) and straightens over the stance leg (its top):
    # in step with the bounce, and in its shape; as large as the drawn amplitude in a
    # step of the walk's median bounce (over every planned step, so that a walk cut
    # short leans as the whole walk does up to the cut).
    pitch_amp = math.radians(rng.uniform(*trunk_pitch_deg))
    wave = bounce_waveform(phase, width)
    typical = float(np.median(bounce)) if len(bounce) else 0.0
    relative = amp[:, 0] / max(typical, 1e-12)
    return IntraStepMotion(
        forward=envelope * (amp[:, 1] * surge[0] + amp[:, 2] * surge[1]) - 0.5 * jolt,
        lateral=envelope * sway * np.sin(2.0 * np.pi * stride),
        up=envelope * amp[:, 0] * wave + jolt,
        trunk_yaw=envelope * yaw_amp * np.cos(2.0 * np.pi * stride),
        # Over the stance leg, in phase with the sway toward it.
        trunk_roll=envelope * roll_amp * np.sin(2.0 * np.pi * stride),
        trunk_pitch=-2.0 * envelope * pitch_amp * relative * wave,
    )


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


def impulse_displacement(
    t: NDArray[np.float64],
    t_hs: NDArray[np.float64],
    peak: NDArray[np.float64],
    sigma_s: float = _HS_SIGMA_S,
    delay_s: float = _HS_DELAY_S,
) -> NDArray[np.float64]:
    """Displacement (m) whose acceleration is a short pulse of ``peak`` m/s² after each heel strike.

    x(t) = −peak·σ²·exp(−u²/2) with u = (t − t_hs − d)/σ (σ = ``sigma_s``, d = ``delay_s``), so
    ẍ = peak·(1 − u²)·exp(−u²/2), a Ricker wavelet: a sharp pulse flanked by
    two shallow opposite lobes, with no net change of velocity and no
    displacement left behind. Smooth at any sample rate of 200 Hz or more.

    Args:
        t: (K,) sorted sample times.
        t_hs: (N,) sorted heel-strike times, more than 0.2 s apart (so only
            the two nearest can reach a sample).
        peak: (N,) acceleration peak of each pulse.
        sigma_s: the pulse's width σ (the soft tissue between an impact and
            what it jolts spreads it: the trunk ≈ 30 ms, a pocket on the thigh 35 ms).
        delay_s: how long after each heel strike the pulse peaks (the trunk's
            40 ms, a thigh's 20 ms).
    """
    out = np.zeros(len(t))
    if len(t_hs) == 0:
        return out
    centre = t_hs + delay_s
    # Each sample gets the pulse centred last before it and the one next after
    # it: the exponents of both in one compiled pass, np.exp on each set, and
    # the sum in another pass.
    first = int(np.searchsorted(t, centre[0], "right"))
    last = int(np.searchsorted(t, centre[-1], "right"))
    arg_prev, arg_next = np.empty(len(t) - first), np.empty(last)
    j_prev, j_next = np.empty(len(t) - first, np.intp), np.empty(last, np.intp)
    _pulse_exponents(t, centre, sigma_s, first, arg_prev, j_prev, arg_next, j_next)
    scale = peak * sigma_s**2
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
    """x −= peak·σ²·exp(−u²/2) of the pulse before each sample (out[first:]), then of
    the one after it (out[:len(e_next)]); ``scale`` is peak·σ², ``e_*`` the exponentials."""
    for k in range(len(e_prev)):
        out[first + k] -= scale[j_prev[k]] * e_prev[k]
    for k in range(len(e_next)):
        out[k] -= scale[j_next[k]] * e_next[k]
