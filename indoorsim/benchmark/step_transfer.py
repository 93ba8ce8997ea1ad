"""Step counts: a step detector tuned on simulated walks alone, run on real ones.

Every step detector of the package, each with the settings a user would tune:

* Han2023's streaming peak–valley detector
  (:class:`~indoorsim.estimators.pdr.steps.PeakStepDetector`, §2.1.1; the step
  detector of ``pdr-basic``, ``han2023-pdr`` and ``han2023-fusion``): its low-pass
  cut-off, the shortest interval between two steps and the smallest swing of one;
* Chen2022's trough detector (:class:`~indoorsim.estimators.pdr.gait.GaitDeadReckoning`,
  Eq. 7; the steps of ``dr-wifi``, ``dr-mm``, ``pf``, ``chen2022-cpf`` and the other
  gait-DR pipelines): its low-pass cut-off, the depth a trough must reach and the
  shortest step, on the accelerometer alone (its gravity the accelerometer
  low-passed), as the Oxford walks log it.

The settings are chosen on simulated walks only (:func:`simulated_step_walks`:
every modelled carrying mode, several sites and walkers), for each detector the
setting whose worst mode has the smallest median count error
(:func:`tune_step_detector`); that one setting then counts the steps of every
real Oxford step-counter walk, against the reference device's steps (its faults
undone by :func:`~indoorsim.io.reallogs.oxford.foot_contacts`). A step
counter does not know how the phone is carried, so one setting serves every mode.
Every step a detector reports in the recording counts, as a step counter's would.

The real recordings are a phone app's: they run on for seconds before the first
true step and after the last, while the phone goes from the hand that started the
app to where it is carried and back. The simulated walks are recorded the same way
(:func:`app_recording`): they start and end in the hand, and the change of place
is the hand's reach with a pocket's stroke (:mod:`~indoorsim.walker.handling`). A
second count, beside, takes only the steps reported while the walk walks
(:attr:`StepWalk.walking`, from the reference device's steps): it separates the
detectors' counting of a walk from their rejection of handling.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from indoorsim.benchmark.realism.reference import MODELLED_MODES
from indoorsim.estimators.pdr.gait import GaitDeadReckoning
from indoorsim.estimators.pdr.steps import PeakStepDetector
from indoorsim.io.recording import Recording
from indoorsim.scenario import RouteSpec
from indoorsim.scenario.generate import generate
from indoorsim.scenario.load import load_site
from indoorsim.simulate import resolve_route, run_streams, simulate
from indoorsim.walker.gait import WalkerParams, walk
from indoorsim.walker.schedule import ScheduleLike
from indoorsim.world.site import Site

__all__ = [
    "OXFORD",
    "STEP_DETECTORS",
    "STEP_GRID",
    "TROUGH_GRID",
    "StepDetector",
    "StepWalk",
    "app_recording",
    "count_steps",
    "oxford_step_walks",
    "real_step_scores",
    "simulated_step_walks",
    "step_count_transfer",
    "step_route",
    "step_walk",
    "tune_step_detector",
    "write_step_transfer",
]

Progress = Callable[[str], None]

OXFORD = Path("oxford-stepcounter")
"""The Oxford step-counter walks, under the real-data folder."""

STEP_GRID: dict[str, tuple[float, ...]] = {
    "cutoff_hz": (2.0, 2.5, 3.0, 4.0),
    "min_interval_s": (0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5),
    "min_amplitude_mps2": (0.3, 0.5, 0.8, 1.2, 1.6),
}
"""The peak–valley detector's settings tried on the simulated walks (every combination)."""

TROUGH_GRID: dict[str, tuple[float, ...]] = {
    "step_cutoff_hz": (2.5, 3.0, 4.0),
    "trough_threshold_mps2": (0.1, 0.2, 0.3, 0.5, 0.8),
    "min_step_s": (0.25, 0.3, 0.35, 0.4, 0.45),
}
"""The trough detector's settings tried on the simulated walks (every combination)."""

STEP_SITES: tuple[str | tuple[str, int], ...] = (
    "han2023_corridor",
    "chen2022_office",
    ("office", 0),
)
"""Sites of the simulated walks: two bundled, one generated (kind, seed)."""

STEP_SEEDS = (0, 1, 2)
STEP_DEVICE = "mid_grade"
"""A generic phone at 100 Hz, as the Oxford walks' phones log."""
STEP_WALK_S = 170.0
"""How long each simulated walk walks at its route's speed, s: as long as the Oxford
recordings walk (their 257–361 true steps at 1.7–1.9 steps/s, 140–200 s), so that the
phone's handling before and after weighs in a simulated walk's count as in a real
one's."""


@dataclass(frozen=True, kw_only=True)
class StepWalk:
    """One walk's accelerometer, its true step count and when it walked."""

    source: str
    """``sim`` or ``real``."""
    name: str
    mode: str
    position: str
    t: NDArray[np.float64]
    accel: NDArray[np.float64]
    true_steps: int
    device_steps: int | None = None
    """The reference device's own count where the true steps are its steps checked
    (the Oxford walks: :func:`~indoorsim.io.reallogs.oxford.foot_contacts`); None
    where they are the steps themselves."""
    true_span: tuple[float, float, float] | None = None
    """(first true step, last true step, median true step interval), s; None without
    two true steps."""

    @property
    def walking(self) -> tuple[float, float] | None:
        """While the walk walks, s: from :data:`WALKING_MARGINS` true step intervals before
        its first true step to after its last (None without a ``true_span``)."""
        if self.true_span is None:
            return None
        first, last, interval = self.true_span
        before, after = WALKING_MARGINS
        return first - before * interval, last + after * interval

    @functools.cached_property
    def _handled_norms(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """‖a‖ before :attr:`walking` and after it; None without a walking span."""
        span = self.walking
        if span is None:
            return None
        norm = np.linalg.norm(self.accel, axis=1)
        return norm[self.t < span[0]], norm[self.t > span[1]]

    @property
    def handled_peak_mps2(self) -> float:
        """The largest ‖a‖ outside :attr:`walking` (the phone handled, the walker
        standing), m/s²; NaN without a walking span or without samples outside it."""
        stretches = self._handled_norms
        if stretches is None or not any(len(x) for x in stretches):
            return math.nan
        return float(max(x.max() for x in stretches if len(x)))

    @property
    def handled_motion_mps2(self) -> float:
        """How much the phone moves outside :attr:`walking`: the median, over 1 s windows
        (half overlapping, within the stretch before the walk and the one after), of
        ‖a‖'s standard deviation, m/s²; NaN without a walking span or a whole window
        outside it."""
        stretches = self._handled_norms
        if stretches is None or len(self.t) < 2:
            return math.nan
        n = max(2, round(1.0 / float(np.median(np.diff(self.t)))))
        stds = [
            float(np.std(x[i : i + n])) for x in stretches for i in range(0, len(x) - n + 1, n // 2)
        ]
        return float(np.median(stds)) if stds else math.nan

    @property
    def handled_s(self) -> tuple[float, float]:
        """How long the recording runs before the first true step and after the last, s."""
        if self.true_span is None:
            return 0.0, 0.0
        return self.true_span[0] - float(self.t[0]), float(self.t[-1]) - self.true_span[1]


WALKING_MARGINS = (0.5, 1.5)
"""The walking span's margins before the first true step and after the last, in true
step intervals. A detector reports a step some way after the true step it belongs
to (the real walks in modelled modes, 10th–50th–90th percentile of that delay: the
peak–valley detector 0.12–0.25–0.41 of an interval, the trough detector
0.30–0.63–0.77; simulated walks 0.10–0.42–0.46 and 0.40–0.81–0.86), so the span ends
well after the last true step and need not start much before the first."""


def step_walk(rec: Recording, source: str, name: str, mode: str, position: str) -> StepWalk:
    """A recording's accelerometer, its true steps (``rec.steps``) and their span."""
    steps = rec.steps.index.to_numpy(dtype=float)
    span = (steps[0], steps[-1], float(np.median(np.diff(steps)))) if len(steps) > 1 else None
    return StepWalk(
        source=source,
        name=name,
        mode=mode,
        position=position,
        t=rec.accel.index.to_numpy(dtype=float),
        accel=rec.accel[["x", "y", "z"]].to_numpy(dtype=float),
        true_steps=len(steps),
        device_steps=rec.meta.get("device_steps"),
        true_span=span,
    )


APP_HOLD_S = 1.5
"""How long the phone stays in the hand that started the app before it is put where it
is carried (the schedule's shortest stretch: one change's time), s."""
APP_RETURN_S = 0.5
"""How long after the walk's last heel strike the hand takes the phone back, s: the
walker has come to a halt."""


def step_route(site: Site, route: str, seconds: float = STEP_WALK_S) -> RouteSpec:
    """``route`` of ``site`` walked there and back, and on, for ``seconds`` at its speed:
    its waypoints cut where that distance is reached. (Turning round at each end and the
    turns on the way take the walker a little longer.)"""
    planned = resolve_route(site, route)
    forward = [(float(x), float(y)) for x, y in planned.points]
    passes = (forward[::-1][1:], forward[1:])  # back to the start, out to the end again
    goal = seconds * planned.speed
    way = list(forward)
    for k in range(math.ceil(goal / planned.length) - 1):
        way += passes[k % 2]
    # Cut the last leg where the walked distance reaches the goal.
    legs = np.linalg.norm(np.diff(way, axis=0), axis=1)
    walked = np.concatenate([[0.0], np.cumsum(legs)])
    j = min(int(np.searchsorted(walked, goal)), len(way) - 1)  # first point at or past it
    a, b = np.asarray(way[j - 1]), np.asarray(way[j])
    end = a + (goal - walked[j - 1]) / legs[j - 1] * (b - a)
    return RouteSpec(waypoints=[*way[:j], (float(end[0]), float(end[1]))], speed=planned.speed)


def app_recording(site: Site, route: str | RouteSpec, mode: str, seed: int) -> ScheduleLike:
    """The carrying-mode schedule of ``route``'s walk with ``seed`` recorded as a phone
    app records one: started in the hand (held as :data:`MODELLED_MODES`' handheld
    holds it), put where ``mode`` carries it, and taken back into the hand once the
    walk ends, before the recording stops. A handheld walk stays in the hand.

    The walk's own steps time the return: :func:`~indoorsim.simulate.simulate` walks
    the body from the same seed before it carries the phone, so the body is the one
    walked here.
    """
    if mode == "handheld":
        return mode
    body = walk(site.plan, resolve_route(site, route), WalkerParams(), run_streams(seed)["walker"])
    last_step = float(body.steps["t"].iloc[-1])
    return [(0.0, "handheld"), (APP_HOLD_S, mode), (last_step + APP_RETURN_S, "handheld")]


def simulated_step_walks(
    sites: Sequence[str | tuple[str, int]] = STEP_SITES,
    seeds: Sequence[int] = STEP_SEEDS,
    modes: Sequence[str] = MODELLED_MODES,
    device: str = STEP_DEVICE,
    *,
    progress: Progress | None = None,
) -> list[StepWalk]:
    """Simulated walks (site × mode × seed) on each site's first route, walked there and
    back for :data:`STEP_WALK_S` (:func:`step_route`), each recorded as a phone app
    records one (:func:`app_recording`)."""
    walks = []
    for spec in sites:
        site = load_site(generate(spec[0], seed=spec[1]) if isinstance(spec, tuple) else spec)
        label = f"generated {spec[0]} (seed {spec[1]})" if isinstance(spec, tuple) else spec
        route = step_route(site, next(iter(site.scenario.routes)))
        for mode, seed in itertools.product(modes, seeds):
            if progress:
                progress(f"step walks {label} {mode} {seed}")
            schedule = app_recording(site, route, mode, seed)
            rec = simulate(site, route=route, mode=schedule, device=device, seed=seed)
            walks.append(step_walk(rec, "sim", f"{label} seed {seed}", mode, mode))
    return walks


def oxford_step_walks(oxford_dir: Path, *, progress: Progress | None = None) -> list[StepWalk]:
    """The Oxford step-counter walks (optimisation and validation sets)."""
    paths = sorted(p for p in (oxford_dir / "optimisation").iterdir() if p.is_dir())
    paths += sorted((oxford_dir / "validation").glob("*.csv"))
    walks = []
    for path in paths:
        if progress:
            progress(f"step counts {path.name}")
        rec = Recording.load(path)
        mode = str(rec.meta.get("mode", ""))
        walks.append(step_walk(rec, "real", path.name, mode, str(rec.meta.get("position", mode))))
    return walks


def _peak_times(walk: StepWalk, **settings: float) -> NDArray[np.float64]:
    return np.array([s.t for s in PeakStepDetector(**settings).update(walk.t, walk.accel)])


def _trough_times(walk: StepWalk, **settings: float) -> NDArray[np.float64]:
    # No gyro and no fused gravity: the Oxford walks log the accelerometer alone.
    dr = GaitDeadReckoning(use_gravity_stream=False, **settings)
    return np.array([s.t for s in dr.update(walk.t, walk.accel, None)])


@dataclass(frozen=True, kw_only=True)
class StepDetector:
    """A step detector the table tunes and runs: what it is, its grid, how it counts."""

    label: str
    used_by: str
    grid: dict[str, tuple[float, ...]]
    times: Callable[..., NDArray[np.float64]]
    """``times(walk, **settings)``: the time of each step it reports in a walk fed whole
    (the low-passed peak's or the trough's, some way after the heel strike), s."""


STEP_DETECTORS: dict[str, StepDetector] = {
    "peak-valley": StepDetector(
        label="Han2023's peak–valley detector",
        used_by="pdr-basic, han2023-pdr, han2023-fusion",
        grid=STEP_GRID,
        times=_peak_times,
    ),
    "trough": StepDetector(
        label="Chen2022's trough detector",
        used_by="dr-wifi, dr-mm, pf, chen2022-cpf, edtw-rekf, apf, wimag",
        grid=TROUGH_GRID,
        times=_trough_times,
    ),
}
"""Every step detector of the package, by the name the table gives it."""


def count_steps(
    walk: StepWalk, detector: str = "peak-valley", *, while_walking: bool = False, **settings: float
) -> int:
    """Steps ``detector`` (a :data:`STEP_DETECTORS` name) with ``settings`` finds in
    ``walk`` fed whole: all it reports, or with ``while_walking`` those it reports
    within ``walk.walking``."""
    times = _step_times(walk, detector, settings)
    return _counted(times, walk.walking if while_walking else None)


def _step_times(walk: StepWalk, detector: str, settings: dict[str, float]) -> NDArray[np.float64]:
    if detector not in STEP_DETECTORS:
        raise ValueError(f"no step detector {detector!r}; there are {', '.join(STEP_DETECTORS)}")
    return STEP_DETECTORS[detector].times(walk, **settings)


def _counted(times: NDArray[np.float64], span: tuple[float, float] | None) -> int:
    if span is None:
        return len(times)
    return int(np.count_nonzero((times >= span[0]) & (times <= span[1])))


def _errors(
    walks: Sequence[StepWalk], settings: dict[str, float], detector: str = "peak-valley"
) -> pd.DataFrame:
    """One row per walk: the steps counted over the whole recording (``detected``,
    ``error_pct``) and while it walks (``detected_walking``, ``error_walking_pct``), and
    how long the recording runs before and after the walk (``handled_before_s``,
    ``handled_after_s``), its largest ‖a‖ there (``handled_peak_mps2``) and how much the
    phone moves there (``handled_motion_mps2``); and the reference device's own count
    (``device_steps``) and the error against it (``error_device_pct``). Errors are NaN
    for a walk without true steps."""
    rows = []
    for w in walks:
        times = _step_times(w, detector, settings)
        n, n_walking = _counted(times, None), _counted(times, w.walking)
        true = w.true_steps if w.true_steps > 0 else math.nan
        device = w.true_steps if w.device_steps is None else w.device_steps
        before, after = w.handled_s
        rows.append(
            {
                "detector": detector,
                "source": w.source,
                "walk": w.name,
                "mode": w.mode,
                "position": w.position,
                "true_steps": w.true_steps,
                "device_steps": device,
                "detected": n,
                "error_pct": 100.0 * (n - w.true_steps) / true,
                "detected_walking": n_walking,
                "error_walking_pct": 100.0 * (n_walking - w.true_steps) / true,
                "error_device_pct": 100.0 * (n - device) / device if device > 0 else math.nan,
                "handled_before_s": before,
                "handled_after_s": after,
                "handled_peak_mps2": w.handled_peak_mps2,
                "handled_motion_mps2": w.handled_motion_mps2,
            }
        )
    return pd.DataFrame(rows)


def tune_step_detector(
    walks: Sequence[StepWalk],
    grid: dict[str, tuple[float, ...]] | None = None,
    detector: str = "peak-valley",
) -> tuple[dict[str, float], pd.DataFrame]:
    """The setting of ``grid`` (default: ``detector``'s own) whose worst mode has the
    smallest median absolute count error on ``walks``, judged with its neighbours, and
    every setting's scores.

    Simulated walks are counted almost exactly by many settings, and a setting on
    the edge of that good region is the first to fail on walks a little unlike them.
    So each setting's score (``worst_mode_pct``) is averaged with those of its
    neighbours, one grid step along each axis, a neighbour beyond the grid counting
    as the grid's worst (``smoothed_pct``); the best smoothed score wins, then the
    best own score, then the smallest median over all walks.
    """
    grid = STEP_DETECTORS[detector].grid if grid is None else grid
    shape = tuple(len(v) for v in grid.values())
    worst = np.empty(shape)
    overall = np.empty(shape)
    for index in np.ndindex(shape):
        settings = {key: grid[key][i] for key, i in zip(grid, index, strict=True)}
        errors = _errors(walks, settings, detector)
        by_mode = errors.groupby("mode")["error_pct"].apply(lambda e: float(np.median(e.abs())))
        worst[index] = float(by_mode.max())
        overall[index] = float(np.median(errors["error_pct"].abs()))
    rows = []
    for index in np.ndindex(shape):
        near = [worst[index]]
        for axis in range(len(shape)):
            for step in (-1, 1):
                j = list(index)
                j[axis] += step
                # Beyond the grid nothing is known: count it as the grid's worst.
                near.append(worst[tuple(j)] if 0 <= j[axis] < shape[axis] else worst.max())
        rows.append(
            {key: grid[key][i] for key, i in zip(grid, index, strict=True)}
            | {
                "smoothed_pct": float(np.mean(near)),
                "worst_mode_pct": float(worst[index]),
                "median_abs_pct": float(overall[index]),
            }
        )
    scores = pd.DataFrame(rows).sort_values(
        ["smoothed_pct", "worst_mode_pct", "median_abs_pct"], kind="stable", ignore_index=True
    )
    best = {key: float(scores.loc[0, key]) for key in grid}
    return best, scores


def step_count_transfer(
    oxford_dir: Path, *, progress: Progress | None = None
) -> tuple[dict[str, dict[str, float]], pd.DataFrame]:
    """Each detector of :data:`STEP_DETECTORS` tuned on simulated walks (its setting, by
    name), and its errors on them and on every real Oxford walk (one row per detector
    and walk: ``source`` ``sim`` or ``real``)."""
    sim = simulated_step_walks(progress=progress)
    real = oxford_step_walks(oxford_dir)
    best, tables = {}, []
    for name in STEP_DETECTORS:
        if progress:
            progress(f"step counts: tuning the {name} detector")
        best[name], _ = tune_step_detector(sim, detector=name)
        tables += [_errors(sim, best[name], name), _errors(real, best[name], name)]
    return best, pd.concat(tables, ignore_index=True)


def _summary(errors: pd.DataFrame) -> pd.DataFrame:
    return (
        errors.groupby(["detector", "source", "mode"], sort=False)["error_pct"]
        .agg(
            walks="count",
            median="median",
            median_abs=lambda e: float(np.median(np.abs(e))),
            low="min",
            high="max",
        )
        .reset_index()
    )


def real_step_scores(
    errors: pd.DataFrame, column: str = "error_pct"
) -> dict[str, tuple[float, float]]:
    """Per detector, on the real walks in the modelled carrying modes: the median
    absolute count error and the worst mode's median absolute error, % (``column``:
    ``error_pct`` over the whole recording, ``error_walking_pct`` while it walks,
    ``error_device_pct`` against the reference device's unchecked count)."""
    out = {}
    for name, rows in errors.groupby("detector", sort=False):
        real = rows[(rows["source"] == "real") & rows["mode"].isin(MODELLED_MODES)]
        if not len(real):
            out[str(name)] = (float("nan"), float("nan"))
            continue
        by_mode = real.groupby("mode")[column].apply(lambda e: float(np.median(e.abs())))
        out[str(name)] = (float(np.median(real[column].abs())), float(by_mode.max()))
    return out


def _pocketed_range(walks: pd.DataFrame, column: str, label: str, digits: int = 0) -> str:
    """The pocketed walks' ``column``: 'lo–hi m/s² (median m, n walks)'."""
    values = walks.loc[walks["mode"] == "pocketed", column].dropna()
    if not len(values):
        return f"({label}: none)"
    return (
        f"{values.min():.{digits}f}–{values.max():.{digits}f} m/s² (median "
        f"{values.median():.{digits}f}, {len(values)} walk{'' if len(values) == 1 else 's'})"
    )


def write_step_transfer(
    out: Path, best: dict[str, dict[str, float]], errors: pd.DataFrame
) -> list[str]:
    """``sim_to_real_steps.csv``; returns the Markdown section for ``sim_to_real.md``."""
    errors.to_csv(out / "sim_to_real_steps.csv", index=False)
    summary = _summary(errors)
    real = errors[errors["source"] == "real"]
    handled = real.drop_duplicates("walk")  # one row a walk: its recording, not the detector
    outside = (real["detected"] - real["detected_walking"]).groupby(real["detector"], sort=False)
    sim = errors[errors["source"] == "sim"]
    sim_outside = (sim["detected"] - sim["detected_walking"]).groupby(sim["detector"], sort=False)
    sim_walks = sim.drop_duplicates(["walk", "mode"])  # a simulated walk is named for its site
    lines = [
        "## Step counts: detectors tuned on simulated walks, on real ones",
        "",
        "Every step detector of the package, each with the one setting that counts the "
        "simulated walks best, run unchanged on every real Oxford step-counter walk "
        "(CC BY 4.0) against the reference device's steps (checked, below). The setting "
        "is chosen on "
        f"simulated walks alone: {len(STEP_SITES)} sites × {len(MODELLED_MODES)} modes × "
        f"{len(STEP_SEEDS)} walkers, device {STEP_DEVICE}; the smallest median count error "
        "in the worst carrying mode, averaged with the neighbouring settings on the grid. "
        "Each simulated walk is recorded as a phone app records one: started and stopped "
        "in the hand, with the phone taken to where the mode carries it and back "
        "(the hand's reach and a pocket's stroke in and out). "
        "The accelerometer alone, as the Oxford walks log it; every step the detector "
        "reports in the recording counts. Error in % of the true steps.",
        "",
    ]
    for name, detector in STEP_DETECTORS.items():
        setting = ", ".join(f"{k} = {v:g}" for k, v in best[name].items())
        lines.append(
            f"- **{name}**: {detector.label}, the step detector of {detector.used_by} "
            f"(which run it at their own settings); tuned here: {setting}."
        )
    lines += [
        "",
        "| detector | data | mode | walks | median error % | median \\|error\\| % "
        "| min % | max % |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for _, r in summary.iterrows():
        lines.append(
            f"| {r['detector']} | {r['source']} | {r['mode']} | {int(r['walks'])} | "
            f"{r['median']:+.1f} | {r['median_abs']:.1f} | {r['low']:+.1f} | {r['high']:+.1f} |"
        )
    lines.append("")
    walking = real_step_scores(errors, "error_walking_pct")
    for name, (overall, worst) in real_step_scores(errors).items():
        lines.append(
            f"Real walks in modelled modes, {name}: median |error| {overall:.1f} % "
            f"(aim ≤ 3 %), worst mode's median |error| {worst:.1f} % (aim ≤ 8 %)."
        )
        lines.append("")
    checked = handled[handled["device_steps"] != handled["true_steps"]]
    if len(checked):
        lines += [
            "The true steps are the reference device's, checked "
            "(`indoorsim.io.reallogs.oxford.foot_contacts`): its two switches, one a foot, "
            "bounce — a channel rising again within half a stride of its last step, which "
            "no foot does — and miss contacts — one channel stepping twice with none of "
            "the other between, which alternating feet do not. Bounces are dropped and "
            "missed contacts added midway; "
            + ", ".join(
                f"{r['walk']} {int(r['device_steps'])} → {int(r['true_steps'])}"
                for _, r in checked.iterrows()
            )
            + f"; the other {len(handled) - len(checked)} unchanged (the data set's notes had "
            "found the peak of these walks' ‖a‖ spectrum 5–7 % below the device's step rate "
            "when swinging and 4 % above it in the pocket: `shared/realdata/oxford-stepcounter`"
            "). Against the device's unchecked count the same detectors read: "
            + "; ".join(
                f"{name} median |error| {o:.1f} %, worst mode {w:.1f} %"
                for name, (o, w) in real_step_scores(errors, "error_device_pct").items()
            )
            + " (`error_device_pct` in the CSV).",
            "",
        ]
    if len(real):
        before, after = WALKING_MARGINS
        lines += [
            "The real recordings run on "
            f"{handled['handled_before_s'].min():.1f}–{handled['handled_before_s'].max():.1f} s "
            "before the first true step and "
            f"{handled['handled_after_s'].min():.1f}–{handled['handled_after_s'].max():.1f} s "
            "after the last (the phone put into the pocket or bag and taken out, the "
            "walker standing), and the detectors report steps there: "
            + "; ".join(f"{name} {int(n.min())}–{int(n.max())} a recording" for name, n in outside)
            + ". In the simulated walks, where the hand takes the phone over 1.5 s before "
            "the first step and after the last and the walker otherwise stands still, they "
            "report "
            + "; ".join(f"{name} {int(n.min())}–{int(n.max())}" for name, n in sim_outside)
            + ". The handling jolts the phone: the largest ‖a‖ outside the walk, pocketed "
            + _pocketed_range(handled, "handled_peak_mps2", "real")
            + ", simulated "
            + _pocketed_range(sim_walks, "handled_peak_mps2", "sim")
            + "; and the phone moves there — the median over 1 s windows of ‖a‖'s std, "
            "pocketed "
            + _pocketed_range(handled, "handled_motion_mps2", "real", 2)
            + ", simulated "
            + _pocketed_range(sim_walks, "handled_motion_mps2", "sim", 2)
            + " (a still pocket: sensor noise, ≈ 0.015). Counted only while the walk walks (from "
            f"{before:g} of a true step interval before the first true step to {after:g} "
            "after the last, a span the reference device's steps give and a step counter "
            "does not know), the same detectors read: "
            + "; ".join(
                f"{name} median |error| {o:.1f} %, worst mode {w:.1f} %"
                for name, (o, w) in walking.items()
            )
            + " (`detected_walking` in the CSV).",
            "",
        ]
    return lines
