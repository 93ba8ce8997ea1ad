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
* its RMS off the stride's lines, at the step rate's higher multiples and between
  them (the jolts: ∝ ``heel_strike_mps2``).

:func:`fit_vigour` walks a straight corridor with the walker the recording shows
(its height, speed and cadence) in the recording's carrying mode, measures the
three with the same function as on the recording, and rescales each parameter
by its law until they agree. Each figure depends mostly on one parameter, so a
few passes settle it.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy import signal

from indoorsim.benchmark.realism.motion import MOTION_RATE_HZ, walking_signals
from indoorsim.benchmark.realism.stats import peak_frequency
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.scenario.schema import RouteSpec
from indoorsim.walker.gait import WalkerParams
from indoorsim.walker.schedule import ScheduleLike

__all__ = ["VigourFit", "fit_vigour", "vigour_powers"]

_CORRIDOR_SITE = "han2023_corridor"
# The x arm of its corridor, straight for 51 m.
_CORRIDOR = [(1.8, 29.8), (53.0, 29.8)]
_PASSES = 4
_SEEDS = (0, 1)
_BOUNCE_RANGE = (0.2, 2.0)
_HEEL_RANGE = (0.0, 10.0)
_WIDTH_RANGE = (0.03, 0.5)
_WINDOW_S = 4.0
_STEP_BAND_HZ = (1.3, 2.8)
_LINES = (0.5, 1.0, 1.5, 2.0)
"""Multiples of the step rate read by projection: the stride's lines up to the second
harmonic."""


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

    def walker(self, walker: WalkerParams) -> WalkerParams:
        """``walker`` with the fitted vigour."""
        return dataclasses.replace(
            walker,
            bounce_fraction=self.bounce_fraction,
            loading_width=(self.loading_width, self.loading_width),
            heel_strike_mps2=(self.heel_strike_mps2, self.heel_strike_mps2),
        )


def vigour_powers(rec: Recording) -> tuple[float, float, float] | None:
    """(‖a‖'s amplitude at the step rate, its second harmonic's over it, ‖a‖'s RMS
    off the stride's lines), in m/s², 1 and m/s², while ``rec``'s carrier walks;
    None without a whole window of walking.

    In Hann-tapered 4 s windows of walking (half overlapping) the step rate is ‖a‖'s
    peak at 1.3–2.8 Hz; each window's amplitudes at half, one, one and a half and
    two times it are read by projection, and what is left of the window's power is
    off those lines (the higher harmonics and the jolts). Each figure is the median
    over windows: a real surveyor's taps on the screen at each waypoint jolt a few
    windows, and a mean over the walk (its spectrum's) reads them as vigour.
    """
    rate = MOTION_RATE_HZ
    sig = walking_signals(rec, rate)
    n = round(_WINDOW_S * rate)
    t = np.arange(n) / rate
    taper = signal.windows.hann(n, sym=False)
    gain = 2.0 / taper.sum()
    freqs = np.fft.rfftfreq(8 * n, 1.0 / rate)
    rows = []
    for run in sig.runs:
        for start in range(run.start, run.stop - n + 1, n // 2):
            w = sig.norm[start : start + n] - sig.norm[start : start + n].mean()
            w = w * taper
            # Refined between bins: read off the line, the projections would leak.
            power_spectrum = np.abs(np.fft.rfft(w, 8 * n)) ** 2
            step_hz = peak_frequency(freqs, power_spectrum, _STEP_BAND_HZ)
            amps = [gain * abs(np.exp(-2j * np.pi * k * step_hz * t) @ w) for k in _LINES]
            power = float(w @ w) / float(taper @ taper)  # the window's mean power
            rest = power - sum(a * a / 2.0 for a in amps)
            rows.append([amps[1], amps[3] / max(amps[1], 1e-9), math.sqrt(max(rest, 0.0))])
    if not rows:
        return None
    first, harmonic, rest = np.median(rows, axis=0)
    return float(first), float(harmonic), float(rest)


def _walk_powers(walker: WalkerParams, mode: ScheduleLike) -> tuple[float, float, float]:
    """The three figures of straight walks by ``walker`` in ``mode``, averaged over seeds."""
    from indoorsim.simulate import simulate  # the simulator imports the benchmark's neighbours

    site = load_site(_CORRIDOR_SITE)
    route = RouteSpec(waypoints=_CORRIDOR, speed=walker.speed_mps or 1.2)
    powers = []
    for seed in _SEEDS:
        rec = simulate(site, route=route, mode=mode, walker=walker, seed=seed)
        got = vigour_powers(rec)
        if got is None:
            raise RuntimeError("the straight reference walk shows no walking spectrum")
        powers.append(got)
    mean = np.mean(powers, axis=0)
    return float(mean[0]), float(mean[1]), float(mean[2])


def fit_vigour(rec: Recording, walker: WalkerParams, mode: ScheduleLike) -> VigourFit | None:
    """Bounce, loading width and heel strikes that give a straight walk by ``walker``
    (its height, speed and standing times as fitted) in ``mode`` the ‖a‖ figures
    ``rec`` shows while walking (see the module docstring); None when ``rec`` has
    no walking part long enough to measure."""
    target = vigour_powers(rec)
    if target is None:
        return None
    bounce = walker.bounce_fraction
    width = float(np.mean(walker.loading_width))
    heel = float(np.mean(walker.heel_strike_mps2))
    fit = None
    for _ in range(_PASSES):
        fit = VigourFit(
            bounce_fraction=bounce,
            loading_width=width,
            heel_strike_mps2=heel,
            target=target,
            reached=_walk_powers(
                dataclasses.replace(
                    walker,
                    bounce_fraction=bounce,
                    loading_width=(width, width),
                    heel_strike_mps2=(heel, heel),
                ),
                mode,
            ),
        )
        step, harmonic, rest = fit.reached
        bounce = float(np.clip(bounce * target[0] / step, *_BOUNCE_RANGE))
        heel = float(np.clip(heel * target[2] / rest, *_HEEL_RANGE))
        # exp(−6π²σ²) ∝ the harmonic ratio: σ² moves by −ln(ratio's change)/(6π²).
        width_sq = width**2 - math.log(target[1] / harmonic) / (6.0 * math.pi**2)
        width = float(np.clip(math.sqrt(max(width_sq, 0.0)), *_WIDTH_RANGE))
    assert fit is not None
    return fit
