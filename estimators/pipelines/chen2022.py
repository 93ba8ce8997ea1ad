"""Chen2022: gait dead reckoning, HV-DDTW magnetic and MD-DTW WiFi matching, chicken PF fusion.

Registered estimators (PAPER_NOTES, Chen2022):

* ``chen2022-cpf`` — HV-DDTW + CPF, the paper's method: gait-based dead
  reckoning drives a chicken particle filter whose weights are the product of
  a magnetic-matching and a WiFi-matching likelihood (Eq. 25–31).
* ``pf`` — the same observations fused by the plain particle filter (Fig. 10).
* ``dr-wifi`` — DR + WiFi matching (Table 1's "DR + WiFi").
* ``dr-mm`` — DR + HV-DDTW magnetic matching (Table 1's "DR + MM").

One filter step per detected step k:

1. Dead reckoning (:class:`~indoorsim.estimators.pdr.gait.GaitDeadReckoning`)
   reports the step's length SL and heading change Δθ.
2. Magnetic fix: the walking phone's magnetometer samples since the step
   ``query_steps`` steps back become HV fingerprints (Eq. 17–18) with the
   phone's own gravity vector, are put on a metre grid by the distance dead
   reckoning walked, and are matched by HV-DDTW (Alg. 1) against every window
   of the walk survey's tracks; the WKNN (Eq. 21) of the best windows' ends is
   the fix z₂ (Eq. 26b), the position at step k
   (:class:`~indoorsim.estimators.fingerprint.sequences.MagneticSequenceMatcher`).
3. WiFi fix: each new scan joins a profile of the last ``wifi_scans`` scans,
   matched by MD-DTW against runs of the survey's reference fingerprints
   (:class:`~indoorsim.estimators.fingerprint.sequences.WifiSequenceMatcher`);
   the fix z₁ (Eq. 26a) is used once, at the first step after the scan.
4. The filter: predict (Eq. 25, wall rule), weights × q_WiFi·q_MM (Eq. 27–28),
   for the CPF the chicken swarm (Eq. 29–31), estimate, resample
   (:mod:`indoorsim.estimators.filters`). Eq. 25 measures the heading φ from
   north, clockwise; the filters keep building-frame headings (from +x,
   counter-clockwise) and convert at their boundary (φ = π/2 − θ, Δφ = −Δθ),
   so Δθ from dead reckoning goes in unchanged.

Between steps the answer is the last filter estimate. Particles are arrays
(``particle_filter.x``, ``.w``, ``.heading``), inspectable after an episode.

Readings taken where the paper is silent:

* **DR + WiFi and DR + MM.** The paper names these baselines but not their
  fusion. They run the same particle filter (the plain PF: the chicken swarm
  is the paper's contribution, not the baselines') with only the WiFi or only
  the magnetic likelihood.
* **Sequences on a metre grid.** Survey tracks and queries are resampled
  every ``spacing_m`` metres (references by their labelled path, queries by
  the distance dead reckoning walked); the paper does not say on which axis
  it samples. The query is the last ``query_steps`` steps; the paper gives
  no length. The default, 16 steps (≈ 10 m), was chosen on the training
  routes of the office scenario (not its test route; the lab's training
  route mostly leaves the survey's): handheld, the median error of the
  magnetic fixes fell from 4.9 m at 8 steps to 2.3 m at 12 and 0.6 m at 16,
  and stayed at 0.6 m at 24, while a longer query waits longer for its first
  fix and straddles more turns.
* **Where a fix comes from.** A magnetic "reference location" is the end of
  a window of the query's length along a survey track, in either walking
  direction (B_H and B_V do not depend on it); Eq. 21's WKNN runs over those
  windows' DTW distances with c_i = 1/D_i normalised by Σ c_i (erratum). WiFi
  reference sequences are runs of consecutive reference points along the
  survey path (Li et al. 2016a's profile matching), either direction.
* **Likelihood (Eq. 27).** As printed by default (``likelihood="literal"``):
  q = exp(−‖z − x‖)/(√‖R‖·√(2π)) per source, d = ‖z − x‖ in metres with no
  square and no R in the exponent (PAPER_NOTES, Chen2022 item 6). Its
  prefactor is the same for every particle and cancels when the weights are
  normalised, so R plays no part; the exponential tails are heavy enough
  that one fix tens of metres off does not wipe out the particles near the
  truth. ``likelihood="gaussian"`` is the textbook reading exp(−d²/2R). Its
  R — the "noise of the observation equation", whose value the paper does
  not give — is estimated in ``fit`` per source as the maximum-likelihood
  isotropic variance of that source's fixes on the labelled training walks,
  R = mean(d²)/2, d the distance from the fix to the true position at the
  fix's step, floored at (0.5 m)²; without training walks the defaults below
  hold. Mismatches on those walks make R large (11–70 m² on the bundled
  sites), so the Gaussian filters lean on dead reckoning.
* **Filter noise.** G_φ and the step-length noise are estimated in ``fit``
  too. G_φ is the random-walk rate of dead reckoning's heading error on the
  training walks: the RMS change of that error over 10 steps, divided by √10
  (a single step's Δθ carries the trunk's left/right sway, which alternates
  and does not accumulate, so the per-step change would overstate it
  several-fold). The step-length noise is the RMS of calibrated step lengths
  against the matched true steps. G_x, G_y is ``sigma_xy``.
* **Fixes are used once.** A WiFi fix updates the filter at one step only
  (shifted by the dead-reckoned displacement since its scan), and a step
  without any fix is a pure prediction: no update and, for the CPF, no swarm
  (the swarm acts on measurement weights; with none it would only contract
  the cloud).
* **DR length scale** is calibrated in ``fit`` on the training walks' true
  steps (detected steps paired with true ones by time,
  :func:`~indoorsim.estimators.pipelines.han2023.match_steps`).

Missing streams: without the fused gravity, the phone's "up" for the HV
fingerprint is the low-passed accelerometer (time constant
``gravity_tau_s``), and dead reckoning gets no gravity stream (it low-passes
the accelerometer itself); without a gyroscope dead reckoning keeps its
heading; without a magnetometer or WiFi (or a site whose survey lacks them)
that likelihood is left out; without both the filter is dead reckoning on the
floor plan.

Behaviour to expect: in the simulated sites the fixes are heavy-tailed — a
magnetic query straddling a turn the survey did not make, or recorded at
another height than the survey's (a pocket, a swinging hand: the field of
the floor's rebar differs by about as much as it varies along the route),
matches a wrong stretch tens of metres away — so the fitted R are large and
the Gaussian filters lean on dead reckoning and the walls. The printed
likelihood exp(−d) has a fixed 1 m scale instead, so every fix pulls the
particles within a few metres of it hard. The chicken swarm moves particles
toward the heaviest ones whatever the likelihood's scale (its moves are
scale-free, :mod:`~indoorsim.estimators.filters.chicken`), so the CPF
follows such fixes further than the PF does: measured over the four modes,
seeds 0–2, the CPF does 1.29 m in the lab and 2.90 m in the office with
exp(−d), 0.93 and 1.75 m with the Gaussian; the PF 1.06 / 1.90 m with either.

Paper experiments: Fig. 8 is ``matcher="md-dtw"`` against the default; Fig. 10
is ``pf`` against ``chen2022-cpf``; Fig. 23 (survey phone ≠ walking phone) is a
site context built with another ``survey_device``: the survey database comes
from the context and the walking phone is whatever recorded the walk.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal, TypeVar

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.signal import lfilter

from indoorsim.estimators.base import (
    NotApplicableError,
    Observation,
    SiteContext,
    StartInfo,
    not_reset_error,
    present_streams,
    register,
)
from indoorsim.estimators.filters import (
    ChickenParticleFilter,
    ParticleFilter,
    PlanLike,
    gaussian_likelihood,
    literal_likelihood,
)
from indoorsim.estimators.fingerprint.hv import hv_components
from indoorsim.estimators.fingerprint.sequences import (
    MagneticSequenceMatcher,
    WifiSequenceMatcher,
    distance_along,
    reference_tracks,
    resample_by_distance,
)
from indoorsim.estimators.frames import wrap_angle
from indoorsim.estimators.pdr.gait import GaitDeadReckoning, GaitStep
from indoorsim.estimators.pipelines.han2023 import match_steps, median_step_lag_s, step_lag_s
from indoorsim.estimators.samples import SampleGuard
from indoorsim.io.recording import Recording
from indoorsim.util.seeding import generator
from indoorsim.windows import Windower

__all__ = [
    "Chen2022Cpf",
    "Chen2022FrontEnd",
    "Chen2022Pf",
    "DrMm",
    "DrWifi",
    "FixErrors",
    "FixTracker",
    "StepFixes",
    "calibrate_length_scale",
    "fit_survey_matchers",
    "fix_variance_m2",
    "labelled_walks",
    "noise_std",
    "replay_dr",
    "replay_errors",
    "walk_surveys",
    "wifi_references",
]

# Likelihood variances and filter noises used when no training walk can estimate them.
DEFAULT_R_MAGNETIC_M2 = 3.0**2
DEFAULT_R_WIFI_M2 = 4.0**2
DEFAULT_SIGMA_STEP_M = 0.05
DEFAULT_SIGMA_HEADING_RAD = 0.05
# Floors of the estimates: a few lucky training fixes must not make a source absolute.
_MIN_R_M2 = 0.5**2
_MIN_SIGMA_STEP_M = 0.02
_MIN_SIGMA_HEADING_RAD = 0.01
# Fewer training fixes (or steps) than this keep the defaults.
_MIN_SAMPLES = 5
# Below this norm, m/s², a gravity vector has no direction (a stream not yet started).
_TINY_GRAVITY = 1e-6
# Steps over which the heading's random walk is measured (even: whole strides).
_HEADING_LAG_STEPS = 10
# Shortest step kept on the distance axis, m: the grid needs a strictly increasing distance.
_MIN_STEP_M = 1e-3


# Dataclass options of internal state: not constructor arguments, not shown, not compared.
_STATE: dict[str, bool] = {"init": False, "repr": False, "compare": False}


_PF = TypeVar("_PF", bound=ParticleFilter)


def _empty(width: int = 0) -> NDArray[np.float64]:
    return np.empty((0, width)) if width else np.empty(0)


@dataclass(frozen=True)
class StepFixes:
    """One detected step with the fixes that arrived for it.

    Attributes:
        step: the dead-reckoning step.
        magnetic: (2,) magnetic fix z₂ (Eq. 26b) at the step, m; None without one.
        wifi: (2,) WiFi fix z₁ (Eq. 26a) carried to the step, m; None without one.
    """

    step: GaitStep
    magnetic: NDArray[np.float64] | None
    wifi: NDArray[np.float64] | None


@dataclass(kw_only=True)
class FixTracker:
    """Streaming front end: dead-reckoning steps and the fixes for each (module docstring).

    Feed it every observation window in order (:meth:`process`); it keeps the
    magnetometer samples of the last ``query_steps`` steps as HV fingerprints,
    the last scans, and the distance and displacement dead reckoning walked.

    Attributes:
        dr: the dead reckoning (reset by :meth:`reset`).
        magnetic: the magnetic matcher, or None for no magnetic fixes.
        wifi: the WiFi matcher, or None for no WiFi fixes.
        query_steps: steps per magnetic query.
        spacing_m: the metre grid of the magnetic sequences.
        gravity_alpha: per-sample gain of the accelerometer low-pass that
            stands in for a missing gravity stream, 1 − exp(−Δt/τ).
        step_lag_s: how late dead reckoning times a step after the true step
            (measured on labelled walks, :func:`calibrate_length_scale`); NaN:
            the step filter's group delay stands in (:attr:`estimate_time`).
    """

    dr: GaitDeadReckoning
    magnetic: MagneticSequenceMatcher | None = None
    wifi: WifiSequenceMatcher | None = None
    query_steps: int = 16
    spacing_m: float = 0.2
    gravity_alpha: float = 0.02
    step_lag_s: float = float("nan")

    # Per step since the start (the start first): time, distance walked and
    # dead-reckoned displacement, m; kept as far back as a query reaches.
    _t_steps: NDArray[np.float64] = field(default_factory=lambda: _empty(), **_STATE)
    _s_steps: NDArray[np.float64] = field(default_factory=lambda: _empty(), **_STATE)
    _xy_steps: NDArray[np.float64] = field(default_factory=lambda: _empty(2), **_STATE)
    # Fresh magnetometer samples as HV fingerprints (B_H, B_V), µT, and their times.
    _mag_t: NDArray[np.float64] = field(default_factory=lambda: _empty(), **_STATE)
    _mag_hv: NDArray[np.float64] = field(default_factory=lambda: _empty(2), **_STATE)
    _scans: list[NDArray[np.float64]] = field(default_factory=list, **_STATE)
    _pending: tuple[float, NDArray[np.float64]] | None = field(default=None, **_STATE)
    _g_lp: NDArray[np.float64] | None = field(default=None, **_STATE)
    _estimate_time: float = field(default=0.0, **_STATE)
    _guard: SampleGuard = field(default_factory=SampleGuard, **_STATE)

    @property
    def estimate_time(self) -> float:
        """The time the latest step's position refers to: the true step its trough
        stands for (the step's time less ``step_lag_s``, else less the step
        filter's group delay), s; the start before a step."""
        return self._estimate_time

    def reset(self, t0: float, heading: float) -> None:
        """Start an episode at time t0 (s) walking along ``heading`` (rad from +x)."""
        self.dr.reset(heading)
        self._estimate_time = float(t0)
        # The start is the distance axis' anchor: 0 m walked, no displacement.
        self._t_steps = np.array([t0])
        self._s_steps = np.zeros(1)
        self._xy_steps = np.zeros((1, 2))
        self._mag_t, self._mag_hv = np.empty(0), np.empty((0, 2))
        self._scans, self._pending, self._g_lp = [], None, None
        self._guard.reset()

    def process(self, obs: Observation) -> list[StepFixes]:
        """Take the next window; return its detected steps, each with its fixes."""
        obs = self._guard(obs)
        valid = obs["valid"].astype(bool)
        if not valid.any():
            return []
        present = present_streams(obs)
        t = obs["t"][valid]
        acc = obs["accel"][valid]
        gravity = obs["gravity"][valid] if present["gravity"] else None
        up = gravity if gravity is not None else self._low_pass(acc)
        if self.magnetic is not None and present["mag"]:
            self._add_magnetic(t, obs["mag"][valid], obs["mag_fresh"][valid].astype(bool), up)
        if self.wifi is not None and present["wifi"] and obs["wifi_fresh"][0]:
            self._add_scan(t[-1] - float(obs["wifi_age"][0]), obs)
        out = []
        gyro = obs["gyro"][valid] if present["gyro"] else None
        for step in self.dr.update(t, acc, gyro, gravity=gravity):
            self._add_step(step)
            lag = self.step_lag_s if np.isfinite(self.step_lag_s) else self.dr.step_delay_s
            self._estimate_time = float(step.t) - lag
            out.append(StepFixes(step, self._magnetic_fix(), self._wifi_fix(step.t)))
        self._forget()
        return out

    def _low_pass(self, acc: NDArray[np.float64]) -> NDArray[np.float64]:
        """First-order low-pass of the accelerometer: "up" when the gravity stream is missing."""
        a = self.gravity_alpha
        if self._g_lp is None:
            self._g_lp = acc[0].copy()
        y, _ = lfilter([a], [1.0, a - 1.0], acc, axis=0, zi=((1.0 - a) * self._g_lp)[None, :])
        self._g_lp = y[-1].copy()
        return y

    def _add_magnetic(
        self,
        t: NDArray[np.float64],
        mag: NDArray[np.float64],
        fresh: NDArray[np.bool_],
        up: NDArray[np.float64],
    ) -> None:
        keep = fresh & (np.linalg.norm(up, axis=1) > _TINY_GRAVITY)
        if keep.any():
            b_h, b_v = hv_components(mag[keep], up[keep])  # Eq. 17–18
            self._mag_t = np.r_[self._mag_t, t[keep]]
            self._mag_hv = np.vstack([self._mag_hv, np.column_stack([b_h, b_v])])

    def _add_scan(self, t_scan: float, obs: Observation) -> None:
        heard = obs["wifi_heard"].astype(bool)
        if not heard.any() or self.wifi is None:
            return
        self._scans = [*self._scans, np.where(heard, obs["wifi_rss"], np.nan)][-self.wifi.scans :]
        position, _ = self.wifi.match(np.array(self._scans))
        # A newer scan replaces a fix no step has used yet: each fix is used once.
        self._pending = (t_scan, position)

    def _add_step(self, step: GaitStep) -> None:
        length = max(float(step.length), _MIN_STEP_M)
        t = max(float(step.t), self._t_steps[-1] + 1e-6)
        move = length * np.array([np.cos(step.heading), np.sin(step.heading)])
        self._t_steps = np.r_[self._t_steps, t]
        self._s_steps = np.r_[self._s_steps, self._s_steps[-1] + length]
        self._xy_steps = np.vstack([self._xy_steps, self._xy_steps[-1] + move])

    def _magnetic_fix(self) -> NDArray[np.float64] | None:
        n = self.query_steps
        if self.magnetic is None or len(self._t_steps) < n + 1:
            return None
        sel = (self._mag_t >= self._t_steps[-n - 1]) & (self._mag_t <= self._t_steps[-1])
        if sel.sum() < 3:
            return None
        s = distance_along(self._mag_t[sel], self._t_steps, self._s_steps)
        _, query = resample_by_distance(s, self._mag_hv[sel], self.spacing_m)
        if len(query) < 3:
            return None
        position, _ = self.magnetic.match(query)
        return position

    def _wifi_fix(self, t_step: float) -> NDArray[np.float64] | None:
        if self._pending is None or self._pending[0] > t_step:
            return None
        t_scan, position = self._pending
        self._pending = None
        # Carry the fix from the scan's time to this step along the dead-reckoned track.
        at_scan = np.array([np.interp(t_scan, self._t_steps, self._xy_steps[:, i]) for i in (0, 1)])
        return position + self._xy_steps[-1] - at_scan

    def _forget(self) -> None:
        """Drop steps and samples no later query can reach."""
        keep = self.query_steps + 2
        if len(self._t_steps) > keep:
            self._t_steps = self._t_steps[-keep:]
            self._s_steps = self._s_steps[-keep:]
            self._xy_steps = self._xy_steps[-keep:]
        recent = self._mag_t >= self._t_steps[0]
        if not recent.all():
            self._mag_t, self._mag_hv = self._mag_t[recent], self._mag_hv[recent]


def walk_surveys(site: SiteContext, survey: str | None, who: str) -> list[dict[str, pd.DataFrame]]:
    """Every walk survey's tables (``magnetic``, ``wifi``), in name order, or NotApplicableError.

    A site may survey several paths (one walk survey each); their tracks and
    reference runs are pooled, never joined end to end.

    Args:
        site: the site context.
        survey: the walk survey's database name; None: every database with a
            ``magnetic`` table.
        who: the estimator's name, for the error message.

    Raises:
        NotApplicableError: if the site has no such walk survey.
    """
    walks = {n: db for n, db in sorted(site.fingerprints.items()) if "magnetic" in db.tables}
    if survey is not None:
        walks = {survey: walks[survey]} if survey in walks else {}
    if not walks:
        wanted = f"a walk survey named {survey!r}" if survey else "a walk survey"
        raise NotApplicableError(
            f"{who} needs {wanted} (a fingerprint database with a 'magnetic' table of "
            "labelled HV sequences and a 'wifi' table of reference fingerprints, as "
            f"indoorsim.survey.walk_survey makes); site {site.name!r} has "
            f"{sorted(site.fingerprints) or 'no fingerprint databases'}"
        )
    return [db.tables for db in walks.values()]


def wifi_references(
    tables: dict[str, pd.DataFrame], bssids: Sequence[str]
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Reference points in survey order and their RSS in the site's AP order (None: unusable)."""
    table = tables.get("wifi")
    if table is None or not len(table) or not bssids:
        return None
    table = table.sort_values("ref", kind="stable") if "ref" in table else table
    rss = np.column_stack(
        [
            table[f"rss_{b}"].to_numpy(dtype=float)
            if f"rss_{b}" in table
            else np.full(len(table), np.nan)
            for b in bssids
        ]
    )
    if np.isnan(rss).all():
        return None
    return table[["x", "y"]].to_numpy(dtype=float), rss


def fit_survey_matchers(
    site: SiteContext,
    surveys: Sequence[dict[str, pd.DataFrame]],
    *,
    magnetic: MagneticSequenceMatcher | None,
    wifi: WifiSequenceMatcher | None,
    spacing_m: float,
    who: str,
) -> tuple[MagneticSequenceMatcher | None, WifiSequenceMatcher | None]:
    """Fit sequence matchers on the walk surveys' magnetic tracks and WiFi reference paths.

    Args:
        site: the site context (its APs order the WiFi references).
        surveys: the walk surveys' tables (:func:`walk_surveys`).
        magnetic: an unfitted magnetic matcher, or None for no magnetic fixes.
        wifi: an unfitted WiFi matcher, or None for no WiFi fixes.
        spacing_m: the metre grid of the magnetic tracks.
        who: the estimator's name, for error messages.

    Returns:
        ``(magnetic, wifi)``, each fitted, or None where it was not wanted or
        the surveys cannot feed it.

    Raises:
        NotApplicableError: when neither wanted matcher can be fitted, or a
            magnetic table lacks its columns.
    """
    mag_out = wifi_out = None
    if magnetic is not None:
        try:
            tracks = [
                track
                for tables in surveys
                for track in reference_tracks(tables["magnetic"], spacing_m)
            ]
        except ValueError as err:
            raise NotApplicableError(f"{who}: {err}") from None
        if tracks:
            mag_out = magnetic.fit(tracks)
    if wifi is not None:
        paths = [r for t in surveys if (r := wifi_references(t, site.bssids)) is not None]
        if paths:
            wifi_out = wifi.fit(paths)
    if mag_out is None and wifi_out is None:
        wanted = " and ".join(
            w for w, m in (("magnetic tracks", magnetic), ("WiFi", wifi)) if m is not None
        )
        raise NotApplicableError(
            f"{who}: the walk survey of site {site.name!r} has no usable {wanted}"
        )
    return mag_out, wifi_out


def labelled_walks(train: Sequence[Recording]) -> list[Recording]:
    """The training walks that carry an accelerometer, truth and true steps."""
    return [r for r in train if {"accel", "truth", "steps"} <= set(r.streams) and len(r.accel)]


def replay_dr(dr: GaitDeadReckoning, rec: Recording) -> list[GaitStep]:
    """Dead reckoning (a copy of ``dr``) over a whole labelled walk in one chunk."""
    dr = copy.deepcopy(dr)
    dr.reset(float(rec.truth["heading"].iloc[0]))
    acc = rec.accel
    t = acc.index.to_numpy(dtype=float)
    return dr.update(
        t,
        acc[["x", "y", "z"]].to_numpy(dtype=float),
        _at(rec, "gyro", t),
        _at(rec, "gravity", t),
    )


def calibrate_length_scale(dr: GaitDeadReckoning, train: Sequence[Recording]) -> float:
    """Fit ``dr``'s length scale on its detected steps paired with the true steps.

    Steps are paired by time (:func:`~indoorsim.estimators.pipelines.han2023.match_steps`);
    with fewer than a handful of pairs the scale is left as it is.

    Args:
        dr: the dead reckoning to calibrate (in place).
        train: labelled walks (:func:`labelled_walks`).

    Returns:
        How late dead reckoning times a step after the true one, the median over
        the walks of :func:`~indoorsim.estimators.pipelines.han2023.step_lag_s`,
        s (NaN without a walk to tell).
    """
    matched: list[GaitStep] = []
    lengths: list[NDArray[np.float64]] = []
    lags: list[float] = []
    for rec in train:
        steps = replay_dr(dr, rec)
        true_t = rec.steps.index.to_numpy(dtype=float)
        s, lens = match_steps(steps, true_t, rec.steps["length"].to_numpy(float))
        matched += s
        lengths.append(lens)
        lags.append(step_lag_s([st.t for st in steps], true_t))
    if len(matched) >= _MIN_SAMPLES:
        dr.calibrate(matched, np.concatenate(lengths))
    return median_step_lag_s(lags)


@dataclass(frozen=True)
class FixErrors:
    """What the front end got wrong on labelled walks, pooled over the walks.

    Attributes:
        magnetic_m: distances from each magnetic fix to the true position at its step, m.
        wifi_m: the same for the WiFi fixes, m.
        step_length_m: detected minus true length of each matched step, m.
        heading_walk_rad: changes of dead reckoning's heading error over
            ``_HEADING_LAG_STEPS`` steps, divided by √lag (a per-step random-walk rate).
    """

    magnetic_m: NDArray[np.float64]
    wifi_m: NDArray[np.float64]
    step_length_m: NDArray[np.float64]
    heading_walk_rad: NDArray[np.float64]


def replay_errors(
    tracker: FixTracker,
    dr: GaitDeadReckoning,
    site: SiteContext,
    train: Sequence[Recording],
) -> FixErrors:
    """Run (a copy of) the front end over labelled walks and collect its errors.

    Args:
        tracker: the front end; a deep copy is replayed, with a copy of ``dr``.
        dr: the (calibrated) dead reckoning.
        site: the site context (window length, APs).
        train: labelled walks (:func:`labelled_walks`).
    """
    err_mm: list[float] = []
    err_wifi: list[float] = []
    err_len: list[float] = []
    err_turn: list[float] = []
    tracker = copy.deepcopy(tracker)
    for rec in train:
        windows = Windower(rec, site.window_samples, site.bssids)
        tracker.dr = copy.deepcopy(dr)
        tracker.reset(float(windows.t[0]), float(rec.truth["heading"].iloc[0]))
        fixes = [f for obs in windows for f in tracker.process(obs)]
        if not fixes:
            continue
        t = np.array([f.step.t for f in fixes])
        true_xy = _truth_xy(rec, t)
        for f, p in zip(fixes, true_xy, strict=True):
            if f.magnetic is not None:
                err_mm.append(float(np.linalg.norm(f.magnetic - p)))
            if f.wifi is not None:
                err_wifi.append(float(np.linalg.norm(f.wifi - p)))
        ts = rec.truth.index.to_numpy(dtype=float)
        true_h = np.interp(t, ts, np.unwrap(rec.truth["heading"].to_numpy(dtype=float)))
        # Heading error at each step; its change over an even number of steps
        # cancels the left/right sway that a single step's change is full of.
        e = np.unwrap(wrap_angle(np.array([f.step.heading for f in fixes]) - true_h))
        lag = _HEADING_LAG_STEPS
        err_turn += list((e[lag:] - e[:-lag]) / np.sqrt(lag))
        steps = [f.step for f in fixes]
        s, lens = match_steps(
            steps, rec.steps.index.to_numpy(dtype=float), rec.steps["length"].to_numpy(float)
        )
        err_len += [st.length - L for st, L in zip(s, lens, strict=True)]
    return FixErrors(
        magnetic_m=np.array(err_mm),
        wifi_m=np.array(err_wifi),
        step_length_m=np.array(err_len),
        heading_walk_rad=np.array(err_turn),
    )


def fix_variance_m2(distances_m: NDArray[np.float64], default: float) -> float:
    """R of a source's fixes: the ML per-axis variance of an isotropic 2-D Gaussian.

    R = mean(d²)/2 over the fixes' distances to the truth, floored at (0.5 m)²;
    ``default`` with fewer than a handful of fixes.
    """
    if len(distances_m) < _MIN_SAMPLES:
        return default
    # R = mean(d²)/2: the ML variance per axis of an isotropic 2-D Gaussian fix.
    return max(float(np.mean(np.square(distances_m))) / 2.0, _MIN_R_M2)


def noise_std(errors: NDArray[np.float64], default: float, floor: float) -> float:
    """RMS of the errors, floored; ``default`` with fewer than a handful of them."""
    if len(errors) < _MIN_SAMPLES:
        return default
    return max(_rms(errors), floor)


def _truth_xy(rec: Recording, t: NDArray[np.float64]) -> NDArray[np.float64]:
    truth = rec.truth
    ts = truth.index.to_numpy(dtype=float)
    return np.column_stack([np.interp(t, ts, truth[c].to_numpy(dtype=float)) for c in ("x", "y")])


def _at(rec: Recording, stream: str, t: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """A 3-axis stream interpolated to times t, or None if the recording lacks it."""
    df = rec.streams.get(stream)
    if df is None or not len(df):
        return None
    ts = df.index.to_numpy(dtype=float)
    return np.column_stack([np.interp(t, ts, df[c].to_numpy(dtype=float)) for c in "xyz"])


def _rms(x: Sequence[float] | NDArray[np.float64]) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


@dataclass(kw_only=True)
class Chen2022FrontEnd:
    """What Chen2022's estimators and the methods it compares against share: the front end.

    ``fit`` loads the walk survey into the sequence matchers, builds the
    :class:`FixTracker` over them and calibrates, on the labelled training
    walks, the dead reckoning's length scale, the fixes' R and the filter
    noises (module docstring); ``reset`` helpers start the tracker and a
    particle filter at the known start. Subclasses say which matchers they
    use (:meth:`_matchers`) and run their filter in ``reset`` and ``act``.

    Attributes:
        query_steps: steps per magnetic query.
        spacing_m: metre grid of the magnetic sequences.
        magnetic_k: neighbours of the magnetic WKNN (Eq. 21).
        wifi_scans: scans per WiFi profile.
        wifi_k: neighbours of the WiFi WKNN.
        sigma_xy: std of the position noises G_x, G_y per step, m.
        start_spread_m: std of the start position around the known start, m.
        start_heading_spread_rad: std of the start heading around the known one, rad.
        calibrate: estimate the DR length scale, R and the filter noises in
            ``fit`` from the training walks (else the defaults).
        gravity_tau_s: time constant of the accelerometer low-pass used when
            the gravity stream is missing, s.
        survey: the walk survey's database name; None: every database with
            a ``magnetic`` table (a site may survey several paths).
        dr: the dead reckoning (its parameters; its length scale is fitted).
        r_magnetic_m2: after ``fit``, R of the magnetic fixes, m².
        r_wifi_m2: after ``fit``, R of the WiFi fixes, m².
        sigma_step_m: after ``fit``, the step-length noise, m.
        sigma_heading_rad: after ``fit``, G_φ, the heading random walk per step, rad.
    """

    name: ClassVar[str] = ""

    query_steps: int = 16
    spacing_m: float = 0.2
    magnetic_k: int = 4
    wifi_scans: int = 2
    wifi_k: int = 3
    sigma_xy: float = 0.1
    start_spread_m: float = 0.3
    start_heading_spread_rad: float = 0.1
    calibrate: bool = True
    gravity_tau_s: float = 1.0
    survey: str | None = None
    dr: GaitDeadReckoning = field(default_factory=GaitDeadReckoning, compare=False)

    r_magnetic_m2: float = field(default=DEFAULT_R_MAGNETIC_M2, init=False)
    r_wifi_m2: float = field(default=DEFAULT_R_WIFI_M2, init=False)
    sigma_step_m: float = field(default=DEFAULT_SIGMA_STEP_M, init=False)
    sigma_heading_rad: float = field(default=DEFAULT_SIGMA_HEADING_RAD, init=False)
    _plan: PlanLike | None = field(default=None, **_STATE)
    _tracker: FixTracker | None = field(default=None, **_STATE)
    # The episode's generator, for the filters that sample.
    _rng: np.random.Generator | None = field(default=None, **_STATE)
    _position: NDArray[np.float64] | None = field(default=None, **_STATE)
    _length_scale: float = field(default=1.0, **_STATE)

    def __post_init__(self) -> None:
        # The configured scale, restored by every fit before it calibrates (or not).
        self._length_scale = float(self.dr.length_scale)
        if self.query_steps < 1 or self.spacing_m <= 0:
            raise ValueError("need query_steps ≥ 1 and spacing_m > 0")
        self._matchers()  # validates the matcher options early

    @property
    def step_count(self) -> int:
        """Steps dead reckoning detected this episode."""
        return int(self.dr.step_count)

    @property
    def estimate_time(self) -> float | None:
        """The time the position refers to: the last step's (:class:`FixTracker`), s."""
        return None if self._tracker is None else self._tracker.estimate_time

    # ---------------------------------------------------------------------- fit

    def _matchers(self) -> tuple[MagneticSequenceMatcher | None, WifiSequenceMatcher | None]:
        """Unfitted magnetic and WiFi matchers of the method (None: not used)."""
        raise NotImplementedError

    def _new_tracker(
        self,
        magnetic: MagneticSequenceMatcher | None,
        wifi: WifiSequenceMatcher | None,
        gravity_alpha: float,
    ) -> FixTracker:
        """The front end over the fitted matchers (a subclass may return a FixTracker subclass)."""
        return FixTracker(**self._tracker_options(magnetic, wifi, gravity_alpha))

    def _tracker_options(
        self,
        magnetic: MagneticSequenceMatcher | None,
        wifi: WifiSequenceMatcher | None,
        gravity_alpha: float,
    ) -> dict[str, Any]:
        """The :class:`FixTracker` arguments: dead reckoning, matchers and query options."""
        return {
            "dr": self.dr,
            "magnetic": magnetic,
            "wifi": wifi,
            "query_steps": self.query_steps,
            "spacing_m": self.spacing_m,
            "gravity_alpha": gravity_alpha,
        }

    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """Load the walk survey; calibrate DR, fix variances and noises on the training walks.

        Raises:
            NotApplicableError: without a walk survey, or when it lacks what
                the method's fixes need (magnetic tracks, WiFi references).
        """
        surveys = walk_surveys(site, self.survey, self.name)
        magnetic, wifi = self._matchers()
        magnetic, wifi = fit_survey_matchers(
            site, surveys, magnetic=magnetic, wifi=wifi, spacing_m=self.spacing_m, who=self.name
        )
        self._plan = site.plan
        alpha = 1.0 - float(np.exp(-1.0 / (site.imu_rate_hz * self.gravity_tau_s)))
        self._tracker = self._new_tracker(magnetic, wifi, alpha)
        self.dr.length_scale = self._length_scale
        self.r_magnetic_m2, self.r_wifi_m2 = DEFAULT_R_MAGNETIC_M2, DEFAULT_R_WIFI_M2
        self.sigma_step_m, self.sigma_heading_rad = DEFAULT_SIGMA_STEP_M, DEFAULT_SIGMA_HEADING_RAD
        labelled = labelled_walks(train)
        if self.calibrate and labelled:
            self._tracker.step_lag_s = calibrate_length_scale(self.dr, labelled)
            self._calibrate_noise(site, labelled)

    def _calibrate_noise(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """R per source, G_φ and the step-length noise from replays of the training walks."""
        assert self._tracker is not None
        e = replay_errors(self._tracker, self.dr, site, train)
        self._set_noise(e.step_length_m, e.heading_walk_rad)
        self.r_magnetic_m2 = fix_variance_m2(e.magnetic_m, self.r_magnetic_m2)
        self.r_wifi_m2 = fix_variance_m2(e.wifi_m, self.r_wifi_m2)

    def _set_noise(self, step_err: NDArray[np.float64], heading_walk: NDArray[np.float64]) -> None:
        """The step-length noise and G_φ from replayed errors (:func:`noise_std`)."""
        self.sigma_step_m = noise_std(step_err, self.sigma_step_m, _MIN_SIGMA_STEP_M)
        self.sigma_heading_rad = noise_std(
            heading_walk, self.sigma_heading_rad, _MIN_SIGMA_HEADING_RAD
        )

    # ------------------------------------------------------------------ episode

    def _start(self, start: StartInfo) -> FixTracker:
        """Reset the front end at the start; returns the tracker (RuntimeError before ``fit``)."""
        if self._tracker is None:
            raise RuntimeError(f"{self.name}: call fit(site, train) first (it needs a walk survey)")
        self._tracker.reset(float(start.t0), float(start.heading))
        self._position = np.array(start.position, dtype=float)
        return self._tracker

    def _start_particles(
        self,
        cls: type[_PF],
        start: StartInfo,
        *,
        n_particles: int,
        ess_threshold: float,
        plan: PlanLike | None,
        **options: object,
    ) -> _PF:
        """A ``cls`` particle filter with the fitted noises, its particles drawn around the start.

        Args:
            cls: the particle filter class.
            start: the episode's start; its seed seeds a new generator (``_rng``).
            n_particles: particles of the filter.
            ess_threshold: resample when N_eff < ess_threshold·N.
            plan: the floor plan of the wall rule, or None for none.
            **options: further arguments of ``cls``.
        """
        pf = cls(
            n_particles=n_particles,
            sigma_heading=self.sigma_heading_rad,
            sigma_step=self.sigma_step_m,
            sigma_xy=self.sigma_xy,
            ess_threshold=ess_threshold,
            plan=plan,
            **options,
        )
        # One generator per episode, from the episode's seed: same episode, same estimates.
        self._rng = generator(start.seed)
        pf.initialise(
            start.position,
            heading=start.heading,
            spread=self.start_spread_m,
            rng=self._rng,
            heading_spread=self.start_heading_spread_rad,
        )
        return pf

    @property
    def heading(self) -> float:
        """The particles' weighted circular mean heading, rad counter-clockwise from +x;
        dead reckoning's before the filter has particles (or for a filter without them)."""
        pf: ParticleFilter | None = getattr(self, "particle_filter", None)
        if pf is None or not len(pf.w):
            return float(self.dr.heading)
        return float(np.arctan2(pf.w @ np.sin(pf.heading), pf.w @ np.cos(pf.heading)))


@register("chen2022-cpf")
@dataclass(kw_only=True)
class Chen2022Cpf(Chen2022FrontEnd):
    """HV-DDTW + CPF: DR, magnetic and WiFi fixes fused by a chicken particle filter.

    See the module docstring for the pipeline and the readings taken, and
    :class:`Chen2022FrontEnd` for the front end's options and fitted values.

    Attributes:
        fusion: ``"cpf"`` (chicken particle filter) or ``"pf"`` (plain).
        use_magnetic: fuse magnetic fixes (q_MM).
        use_wifi: fuse WiFi fixes (q_WiFi).
        matcher: ``"hv-ddtw"`` (Alg. 1) or ``"md-dtw"`` (raw HV values; Fig. 8).
        likelihood: ``"literal"`` exp(−d) as Eq. 27 prints it, or ``"gaussian"`` exp(−d²/2R).
        fitness: the swarm's fitness, ``"weight"`` (as printed) or ``"cost"``
            (:class:`~indoorsim.estimators.filters.ChickenParticleFilter`; CPF only).
        rooster_spread: the roosters' σ² (Eq. 30b), ``"printed"`` or ``"cso"`` (CPF only).
        n_particles: particles of the filter.
        ess_threshold: resample when N_eff < ess_threshold·N.
        particle_filter: during and after an episode, the filter and its particles.
    """

    name: ClassVar[str] = "chen2022-cpf"
    needs: ClassVar[tuple[str, ...]] = ("walk survey",)
    uses: ClassVar[tuple[str, ...]] = ("WiFi", "training walks", "floor plan")

    fusion: Literal["cpf", "pf"] = "cpf"
    use_magnetic: bool = True
    use_wifi: bool = True
    matcher: Literal["hv-ddtw", "md-dtw"] = "hv-ddtw"
    likelihood: Literal["gaussian", "literal"] = "literal"
    fitness: Literal["weight", "cost"] = "weight"
    rooster_spread: Literal["printed", "cso"] = "printed"
    n_particles: int = 1000
    ess_threshold: float = 0.5
    particle_filter: ParticleFilter | None = field(
        default=None, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        if self.fusion not in ("cpf", "pf"):
            raise ValueError(f"fusion must be 'cpf' or 'pf', got {self.fusion!r}")
        if self.likelihood not in ("gaussian", "literal"):
            raise ValueError(f"likelihood must be 'gaussian' or 'literal', got {self.likelihood!r}")
        if not (self.use_magnetic or self.use_wifi):
            raise ValueError("use_magnetic and use_wifi cannot both be False")
        ChickenParticleFilter(**self._swarm_options())  # validates the swarm options early
        super().__post_init__()

    def _swarm_options(self) -> dict[str, Any]:
        return {"fitness": self.fitness, "rooster_spread": self.rooster_spread}

    def _matchers(self) -> tuple[MagneticSequenceMatcher | None, WifiSequenceMatcher | None]:
        # Both are built (and so validated) even when a likelihood is switched off.
        magnetic = MagneticSequenceMatcher(matcher=self.matcher, k=self.magnetic_k)
        wifi = WifiSequenceMatcher(scans=self.wifi_scans, k=self.wifi_k)
        return (magnetic if self.use_magnetic else None, wifi if self.use_wifi else None)

    def reset(self, start: StartInfo) -> None:
        self._start(start)
        cpf = self.fusion == "cpf"
        self.particle_filter = self._start_particles(
            ChickenParticleFilter if cpf else ParticleFilter,
            start,
            n_particles=self.n_particles,
            ess_threshold=self.ess_threshold,
            plan=self._plan,
            **(self._swarm_options() if cpf else {}),
        )

    def act(self, obs: Observation) -> NDArray[np.float64]:
        if self._position is None or self._tracker is None or self.particle_filter is None:
            raise not_reset_error(self.name)
        assert self._rng is not None
        pf = self.particle_filter
        for f in self._tracker.process(obs):
            pf.predict(f.step.length, f.step.delta_heading, self._rng)
            fn = self._likelihood(f)
            if fn is not None:
                pf.update(fn(pf.x))
                pf.refine(fn, self._rng)  # the CPF's swarm; nothing for the PF
            self._position = pf.estimate()
            pf.resample_if_needed(self._rng)
        return self._position.copy()

    def _likelihood(
        self, f: StepFixes
    ) -> Callable[[NDArray[np.float64]], NDArray[np.float64]] | None:
        """q = q_WiFi·q_MM at particle positions (Eq. 27–28), or None without any fix."""
        fixes = [(z, r) for z, r in ((f.wifi, self.r_wifi_m2), (f.magnetic, self.r_magnetic_m2))]
        fixes = [(z, r) for z, r in fixes if z is not None]
        if not fixes:
            return None

        def q(x: NDArray[np.float64]) -> NDArray[np.float64]:
            out = np.ones(len(x))
            for z, r in fixes:
                d = np.linalg.norm(x - z, axis=1)
                # (27) q ∝ exp(−d) (as printed, default) or exp(−d²/2R); (28) product
                out *= (
                    gaussian_likelihood(d, r)
                    if self.likelihood == "gaussian"
                    else (literal_likelihood(d))
                )
            return out

        return q


@register("pf")
@dataclass(kw_only=True)
class Chen2022Pf(Chen2022Cpf):
    """The same observations fused by the plain particle filter (Fig. 10's PF)."""

    name: ClassVar[str] = "pf"
    fusion: Literal["cpf", "pf"] = "pf"


@register("dr-wifi")
@dataclass(kw_only=True)
class DrWifi(Chen2022Pf):
    """DR + WiFi matching (Table 1): the plain PF with the WiFi likelihood only."""

    name: ClassVar[str] = "dr-wifi"
    needs: ClassVar[tuple[str, ...]] = ("walk survey", "WiFi")
    uses: ClassVar[tuple[str, ...]] = ("training walks", "floor plan")
    use_magnetic: bool = False


@register("dr-mm")
@dataclass(kw_only=True)
class DrMm(Chen2022Pf):
    """DR + HV-DDTW magnetic matching (Table 1): the plain PF with the magnetic likelihood only."""

    name: ClassVar[str] = "dr-mm"
    needs: ClassVar[tuple[str, ...]] = ("walk survey",)
    uses: ClassVar[tuple[str, ...]] = ("training walks", "floor plan")
    use_wifi: bool = False
