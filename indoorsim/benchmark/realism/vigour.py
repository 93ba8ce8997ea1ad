"""How hard a walker walks: bounce, loading peak and heel strikes fitted to a recording.

The gait model's vigour (:class:`~indoorsim.walker.gait.WalkerParams`) is the pelvis's
bounce (``bounce_fraction``), the width of its loading peak in double support
(``loading_width``) and the heel-strike jolts (``heel_strike_mps2``). A phone shows
them in ‖a‖ while walking, through whatever carries it, as three figures
(:func:`vigour_powers`, medians over 4 s windows):

* its amplitude at the step rate (the bounce: ∝ ``bounce_fraction``);
* its second harmonic's amplitude over the first's (the loading peak's
  sharpness: a peak of width σ steps has harmonics falling as exp(−(2πkσ)²/2),
  so the ratio is ∝ exp(−6π²σ²));
* its RMS at 5–15 Hz, clear of the second harmonic (from 2·step rate + 0.75 Hz
  where that is higher): the jolts, ∝ ``heel_strike_mps2``, with the higher
  harmonics they put at the step rate's multiples (which the loading peak's
  sharpness feeds a little too); the content between the lines below is the
  steps' irregularity, not their force.

:func:`fit_vigour` walks a straight corridor with the walker the recording shows
(its height, speed and cadence) in the recording's carrying mode, measures the
three with the same function as on the recording, and moves each parameter by
its law until they agree: first a rescale, then along the secant through its
last two passes (each figure also has a floor the carrier adds, which a pure
rescale approaches but never crosses). Each figure depends mostly on one
parameter, so a few passes settle it; :meth:`VigourFit.misses` says where not.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from indoorsim.benchmark.realism.motion import (
    MOTION_RATE_HZ,
    STEP_BAND_HZ,
    StepWindows,
    walking_signals,
)
from indoorsim.benchmark.realism.stats import peak_frequency
from indoorsim.io.recording import Recording
from indoorsim.phone.specs import DeviceProfile
from indoorsim.scenario.load import load_site
from indoorsim.scenario.schema import RouteSpec
from indoorsim.walker.gait import WalkerParams
from indoorsim.walker.schedule import ScheduleLike

__all__ = ["FIGURES", "VigourError", "VigourFit", "fit_vigour", "single_mode", "vigour_powers"]

_CORRIDOR_SITE = "han2023_corridor"
# The x arm of its corridor, straight for 51 m.
_CORRIDOR = [(1.8, 29.8), (53.0, 29.8)]
# Passes of the fit: four settled 13 of the 14 ILC traces it fits once the trunk's jolt
# came with its loading (which feeds the step rate's amplitude); six settle all 14.
_PASSES = 6
_TOLERANCE = 0.1
"""A figure the fitted walk misses by more than this (relative) is not reached."""
_SEEDS = (0, 1)
_BOUNCE_RANGE = (0.2, 2.0)
_HEEL_RANGE = (0.0, 10.0)
_WIDTH_RANGE = (0.03, 0.5)
FIGURES = ("acc_step_amplitude", "acc_harmonic_ratio", "acc_jolt_rms")
"""Names of :func:`vigour_powers`' three figures, as :func:`calibrate` records them."""
_MIN_WINDOWS = 3
"""Fewer windows of walking than this are too few to fit a walker to."""
_TINY = 1e-6
_JOLT_BAND_HZ = (5.0, 15.0)
"""Where the heel strikes' jolts are read (the lower edge raised per window clear of the
second harmonic), below the phones' usual 50 Hz rate's reach."""


@dataclass(frozen=True, kw_only=True)
class VigourFit:
    """:func:`fit_vigour`'s result.

    Attributes:
        bounce_fraction, loading_width, heel_strike_mps2: the fitted walker fields
            (the two ranges as one value each).
        target: the recording's three figures (:func:`vigour_powers`).
        reached: the fitted walker's, on the straight walk.
    """

    bounce_fraction: float
    loading_width: float
    heel_strike_mps2: float
    target: tuple[float, float, float]
    reached: tuple[float, float, float]

    def _relative_misses(self) -> list[float]:
        """Each figure's relative miss, |reached / target − 1|."""
        return [
            abs(got / max(want, _TINY) - 1.0)
            for got, want in zip(self.reached, self.target, strict=True)
        ]

    def _held_at_ends(self) -> list[tuple[str, float, tuple[float, float]]]:
        """The parameters held at an end of their range: (name, value, range)."""
        return [
            (name, value, (low, high))
            for name, value, (low, high) in (
                ("bounce_fraction", self.bounce_fraction, _BOUNCE_RANGE),
                ("loading_width", self.loading_width, _WIDTH_RANGE),
                ("heel_strike_mps2", self.heel_strike_mps2, _HEEL_RANGE),
            )
            if value <= low or value >= high
        ]

    def misses(self, tolerance: float = _TOLERANCE) -> list[str]:
        """What the fit did not reach: each figure the fitted walk misses by more than
        ``tolerance`` (relative), and each parameter held at the end of its range."""
        out = [
            f"{name} {got:.3g} against {want:.3g}"
            for name, got, want, miss in zip(
                FIGURES, self.reached, self.target, self._relative_misses(), strict=True
            )
            if miss > tolerance
        ]
        for name, value, (low, high) in self._held_at_ends():
            out.append(f"{name} held at {value:.3g}, the end of its range {low}–{high}")
        return out

    def closeness(self) -> tuple[bool, bool, float]:
        """How far the fit is from the recording, to order passes by: whether a figure
        misses by more than :meth:`misses`' tolerance, then whether a parameter is held
        at the end of its range, then the largest relative miss of a figure (0: every
        figure reached exactly)."""
        worst = max(self._relative_misses())
        return worst > _TOLERANCE, bool(self._held_at_ends()), worst

    def walker(self, walker: WalkerParams) -> WalkerParams:
        """``walker`` with the fitted vigour."""
        return dataclasses.replace(
            walker,
            bounce_fraction=self.bounce_fraction,
            loading_width=(self.loading_width, self.loading_width),
            heel_strike_mps2=(self.heel_strike_mps2, self.heel_strike_mps2),
        )


def vigour_powers(rec: Recording) -> tuple[float, float, float] | None:
    """(‖a‖'s amplitude at the step rate, its second harmonic's over it, ‖a‖'s RMS at
    5–15 Hz), in m/s², 1 and m/s², while ``rec``'s carrier walks; None with fewer
    than three windows of walking.

    In Hann-tapered 4 s windows of walking (half overlapping) the step rate is ‖a‖'s
    peak at 1.3–2.8 Hz, and each window's amplitudes at one and two times it are
    read by projection; the jolts' RMS is the window's power in 5–15 Hz, from
    2·step rate + 0.75 Hz where that is higher (clear of the second harmonic's
    main lobe; the content between the lines below is the steps' irregularity,
    not their force). Each figure is the median
    over windows: a real surveyor's taps on the screen at each waypoint jolt a few
    windows, and a mean over the walk (its spectrum's) reads them as vigour.
    """
    rate = MOTION_RATE_HZ
    sig = walking_signals(rec, rate)
    windows = StepWindows(rate)
    freqs = windows.freqs
    # One-sided: every bin but DC (and Nyquist) counts twice in the window's power.
    twice = np.where((freqs > 0) & (freqs < rate / 2), 2.0, 1.0)
    rows = []
    for w in windows.over(sig.norm, sig.runs):
        # Refined between bins: read off the line, the projections would leak.
        power_spectrum = np.abs(windows.spectrum(w)) ** 2
        step_hz = peak_frequency(freqs, power_spectrum, STEP_BAND_HZ)
        first, second = (float(windows.amplitude(w, k * step_hz)) for k in (1.0, 2.0))
        weighted = twice * power_spectrum
        power = float(w @ w) / float(windows.taper @ windows.taper)  # the window's mean power
        # From 5 Hz, or clear of the second harmonic's main lobe (±0.5 Hz in 4 s)
        # where a fast cadence puts it higher.
        low = max(_JOLT_BAND_HZ[0], 2.0 * step_hz + 0.75)
        jolt_band = (freqs >= low) & (freqs <= _JOLT_BAND_HZ[1])
        jolts = power * float(weighted[jolt_band].sum() / max(weighted.sum(), _TINY))
        rows.append([first, second / max(first, _TINY), math.sqrt(jolts)])
    if len(rows) < _MIN_WINDOWS:
        return None
    first, harmonic, jolts = np.median(rows, axis=0)
    return float(first), float(harmonic), float(jolts)


class VigourError(ValueError):
    """The vigour cannot be fitted: a mode that is not one carrying mode, or no
    walking to measure (on the recording or on the reference walk)."""


def single_mode(mode: ScheduleLike) -> list[tuple[float, str, dict]]:
    """``mode`` as a one-entry schedule, which the straight reference walk can replay.

    Raises:
        VigourError: a schedule of several modes (their times are the recording's,
            not the reference walk's), or a name that is not a carrying mode.
    """
    from indoorsim.walker.modes import available_modes

    if isinstance(mode, str):
        entry: tuple = (0.0, mode, {})
    elif isinstance(mode, (list, tuple)) and len(mode) == 1 and isinstance(mode[0], (list, tuple)):
        entry = tuple(mode[0])
    else:
        raise VigourError(
            f"mode {mode!r}: the vigour is fitted through one carrying mode (a name, or a "
            "schedule of one entry)"
        )
    name = entry[1] if len(entry) > 1 else None
    if name not in available_modes():
        raise VigourError(f"mode {name!r}: not a carrying mode ({', '.join(available_modes())})")
    params = dict(entry[2]) if len(entry) > 2 and entry[2] else {}
    return [(0.0, name, params)]


def _walk_powers(
    walker: WalkerParams, mode: list, device: str | DeviceProfile
) -> tuple[float, float, float]:
    """The three figures of straight walks by ``walker`` in ``mode``, averaged over seeds."""
    from indoorsim.simulate import simulate  # the simulator imports the benchmark's neighbours

    site = load_site(_CORRIDOR_SITE)
    route = RouteSpec(waypoints=_CORRIDOR, speed=walker.speed_mps or 1.2)
    # Standing is not measured: the reference walks start and end with a step.
    moving = dataclasses.replace(walker, stand_start_s=0.5, stand_end_s=0.5)
    powers = []
    for seed in _SEEDS:
        rec = simulate(site, route=route, mode=mode, walker=moving, device=device, seed=seed)
        got = vigour_powers(rec)
        if got is None:
            raise VigourError(
                f"a straight walk at {route.speed:.2f} m/s in this mode shows no walking to measure"
            )
        powers.append(got)
    mean = np.mean(powers, axis=0)
    return float(mean[0]), float(mean[1]), float(mean[2])


def _secant(
    history: list[tuple[float, float]],
    target: float,
    proportional: float,
    law: tuple[Callable[[float], float], Callable[[float], float]],
) -> float:
    """The next value of a parameter from its ``history`` of (value, figure) pairs.

    ``law`` is (to, back): the transform of the parameter in which the figure is
    taken as affine (its power law plus a floor the carrier adds, which a pure
    rescale cannot cross), and its inverse. The step goes through the last two
    points when they are distinct and the slope is positive, else it is the
    ``proportional`` rescale.
    """
    if len(history) >= 2:
        (p0, y0), (p1, y1) = history[-2], history[-1]
        x0, x1 = law[0](p0), law[0](p1)
        if abs(x1 - x0) > 1e-12 and (y1 - y0) / (x1 - x0) > 0:
            slope = (y1 - y0) / (x1 - x0)
            return law[1](x1 + (target - y1) / slope)
    return proportional


def fit_vigour(
    rec: Recording,
    walker: WalkerParams,
    mode: ScheduleLike,
    device: str | DeviceProfile = "ideal",
) -> VigourFit:
    """Bounce, loading width and heel strikes that give a straight walk by ``walker``
    (its height and speed as fitted; its cadence follows from them in the gait model)
    in ``mode``, recorded by ``device``, the ‖a‖ figures ``rec`` shows while walking
    (see the module docstring).

    Raises:
        VigourError: ``mode`` is not one carrying mode, or there is too little
            walking to measure in ``rec`` or on the reference walk.
    """
    schedule = single_mode(mode)
    target = vigour_powers(rec)
    if target is None:
        raise VigourError(f"fewer than {_MIN_WINDOWS} windows of walking to measure")
    bounce = walker.bounce_fraction
    width = float(np.mean(walker.loading_width))
    heel = float(np.mean(walker.heel_strike_mps2))
    histories: tuple[list, list, list] = ([], [], [])
    best = None
    for _ in range(_PASSES):
        trial = dataclasses.replace(
            walker,
            bounce_fraction=bounce,
            loading_width=(width, width),
            heel_strike_mps2=(heel, heel),
        )
        reached = _walk_powers(trial, schedule, device)
        fit = VigourFit(
            bounce_fraction=bounce,
            loading_width=width,
            heel_strike_mps2=heel,
            target=target,
            reached=reached,
        )
        # The secant steps can overshoot once the figures are reached (the jolts feed
        # the step rate's amplitude too): the closest pass is the fit.
        if best is None or fit.closeness() < best.closeness():
            best = fit
        step, harmonic, jolts = (max(v, _TINY) for v in reached)
        pairs = zip(histories, (bounce, width, heel), (step, harmonic, jolts), strict=True)
        for history, value, figure in pairs:
            history.append((value, figure))
        # Amplitude ∝ bounce; log of the harmonic ratio falls with σ²; RMS² grows with heel².
        bounce = _secant(
            histories[0], target[0], bounce * target[0] / step, (lambda v: v, lambda x: x)
        )
        width = _secant(
            [(w, math.log(y)) for w, y in histories[1]],
            math.log(target[1]),
            math.sqrt(max(width**2 - math.log(target[1] / harmonic) / (6 * math.pi**2), 0.0)),
            (lambda v: -(v**2), lambda x: math.sqrt(max(-x, 0.0))),
        )
        heel = _secant(
            [(h, y * y) for h, y in histories[2]],
            target[2] ** 2,
            heel * target[2] / jolts,
            (lambda v: v * v, lambda x: math.sqrt(max(x, 0.0))),
        )
        bounce = float(np.clip(bounce, *_BOUNCE_RANGE))
        width = float(np.clip(width, *_WIDTH_RANGE))
        heel = float(np.clip(heel, *_HEEL_RANGE))
    assert best is not None
    return best
