"""Han2023: PDR with BKF(-WT) heading, Tent-ASO-BP GM/Light fingerprinting, and their fusion.

Registered estimators (PAPER_NOTES, Han2023):

* ``han2023-pdr`` — peak–valley steps (0.5 s rule), Weinberg lengths with K
  calibrated on the labelled training walks, heading from the biased Kalman
  filter fusing the gyro's yaw rate and the tilt-compensated magnetometer
  heading (optionally wavelet-denoised: ``wavelet=True``, the paper's BKF-WT).
* ``han2023-gm`` / ``han2023-gml`` — layer 1: a Tent-ASO-BP network from the
  window's mean magnetic field in the geographic frame (and, for GML, its
  mean illuminance) to (x, y), trained on the fingerprint library
  interpolated from the grid survey.
* ``han2023-fusion`` — layer 2: a second Tent-ASO-BP network from
  (x_GML, y_GML, x_PDR, y_PDR) to (x, y), trained on the training walks.
* ``bp``, ``aso-bp``, ``tent-aso-bp`` — layer 1 (GM/Light) with plain BP,
  ASO-BP and Tent-ASO-BP: the static-test variants of Table 2.

Readings taken where the paper is silent:

* The BKF shrinks toward ``bkf_origin``: ``"zero"`` is the literal filter
  (shrinkage toward heading 0 of the building frame), ``"start"`` shrinks
  toward the episode's start heading.
* Wavelet denoising (``wavelet=True``) is causal
  (:class:`~indoorsim.estimators.pdr.StreamingDenoiser`, db4, soft universal
  threshold) on the gyro's three axes (every sample) and on the
  magnetometer's three axes (its fresh samples only).
* The magnetometer heading is the heading of the phone's +y axis (the phone
  held flat in front, as in the paper); in other carrying modes it measures
  the phone's heading, not the walking direction.
* Layer 1's light input, when the light stream is missing, is the library's
  mean illuminance (the network still answers from the magnetic field).
* Layer 2 does not feed back into either layer: PDR and GM/Light run
  independently from the start, as in the paper's description.
* Training budgets default to the paper's (population 30, 500 ASO
  iterations, 1000 BP epochs, MATLAB ``traingdm`` with lr 0.01 and momentum
  0.5): the batched ASO makes that about 5 s for the corridor's layer 1 and
  0.2 s for layer 2 on one thread (``benchmarks/bench_han2023.py``).
  Smaller budgets are constructor arguments (the tests use them).

Missing streams: without a gyroscope the heading filter runs its
constant-rate model on the magnetometer alone; without a magnetometer it
integrates the gyro; without the fused gravity the window's mean specific
force stands in for "up". Layer 1 without a magnetometer or rotation vector,
or in a window without a fresh magnetometer sample, holds its previous answer
(the start position at first).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.base import (
    NotApplicableError,
    Observation,
    SiteContext,
    StartInfo,
    not_reset_error,
    present_streams,
    register,
)
from indoorsim.estimators.fingerprint.library import SURVEY_COLUMNS, FingerprintLibrary
from indoorsim.estimators.frames import geomagnetic_mean, wrap_angle, yaw_rate
from indoorsim.estimators.nn.bp import BPUpdate, TentAsoBP
from indoorsim.estimators.pdr import (
    WEINBERG_K,
    HeadingBKF,
    HeadingKF,
    PeakStepDetector,
    Step,
    StreamingDenoiser,
    calibrate_k,
    mag_heading,
    weinberg,
)
from indoorsim.estimators.samples import SampleGuard
from indoorsim.io.recording import Recording
from indoorsim.windows import Windower

__all__ = [
    "AsoBP",
    "Han2023Fusion",
    "Han2023GM",
    "Han2023GML",
    "Han2023Pdr",
    "PlainBP",
    "TentAsoBPStatic",
    "match_steps",
    "median_step_lag_s",
    "step_lag_s",
]

# Layer 2's inputs: the paper's, and PDR alone (what the network learns from the route).
LAYER2_INPUTS = ("gml+pdr", "pdr")

# Table 1's heading methods, in the paper's column order.
HEADING_METHODS = ("bkf", "kf", "mag", "gyro")

# How far back the heading history reaches for steps confirmed late, s.
_HISTORY_S = 5.0


def step_lag_s(t_detected: ArrayLike, true_t: ArrayLike) -> float:
    """How long after a true step its detection is timed: the median, over the
    detected steps, of the time since the latest true step (NaN with none before).

    A detector times a step at a feature of a filtered signal (the peak of the
    low-passed ‖a‖, the trough of the vertical bounce), a roughly constant
    lag after the step's event (the heel strike) that labelled walks measure.

    >>> round(step_lag_s([1.2, 1.8, 2.4], [1.0, 1.6, 2.2]), 3)
    0.2
    """
    t_det = np.asarray(t_detected, dtype=float)
    t_true = np.asarray(true_t, dtype=float)
    before = np.searchsorted(t_true, t_det, side="right") - 1
    ok = before >= 0
    if not ok.any():
        return float("nan")
    return float(np.median(t_det[ok] - t_true[before[ok]]))


def median_step_lag_s(lags: Sequence[float]) -> float:
    """The median of per-walk :func:`step_lag_s` values that are known (NaN if none is).

    >>> median_step_lag_s([0.2, float("nan"), 0.24])
    0.22
    """
    known = [lag for lag in lags if np.isfinite(lag)]
    return float(np.median(known)) if known else float("nan")


def match_steps(
    steps: Sequence[Step], true_t: NDArray[np.float64], true_len: NDArray[np.float64]
) -> tuple[list[Step], NDArray[np.float64]]:
    """Detected steps paired one-to-one with the nearest true step in time.

    The detector reports a step at its low-passed peak, a roughly constant
    lag after the true step's time: the lag is estimated first, as the
    median time from the latest true step to each detected peak. A detected
    step then pairs with the true step nearest its peak time minus the lag if
    that is within half the median true step interval and no nearer detected
    step claimed it; true steps with an unknown (NaN) length are skipped.

    Returns:
        The matched detected steps and their true lengths, m.
    """
    if not len(steps) or len(true_t) < 2:
        return [], np.empty(0)
    tol = 0.5 * float(np.median(np.diff(true_t)))
    t_det = np.array([s.t for s in steps])
    lag = step_lag_s(t_det, true_t)
    if np.isfinite(lag):
        t_det = t_det - lag
    idx = np.clip(np.searchsorted(true_t, t_det), 1, len(true_t) - 1)
    left, right = true_t[idx - 1], true_t[idx]
    nearest = np.where(np.abs(t_det - left) <= np.abs(t_det - right), idx - 1, idx)
    gap = np.abs(t_det - true_t[nearest])
    best: dict[int, int] = {}
    for k in np.argsort(gap, kind="stable"):
        j = int(nearest[k])
        if gap[k] <= tol and j not in best and np.isfinite(true_len[j]):
            best[j] = int(k)
    order = sorted(best.items(), key=lambda item: item[1])
    return [steps[k] for _, k in order], np.array([true_len[j] for j, _ in order])


# --------------------------------------------------------------------------- PDR


@register("han2023-pdr")
@dataclass(kw_only=True)
class Han2023Pdr:
    """Han2023's PDR: calibrated Weinberg steps along the BKF(-WT) heading (module docstring).

    Position += L·(cos φ, sin φ) per detected step from the known start
    (Eq. 1), φ the filter's heading at the step's peak.

    Attributes:
        min_interval_s: the detector's shortest time between extrema (paper: 0.5 s).
        weinberg_k: Weinberg's K when no training walk calibrates it.
        calibrate: calibrate K in ``fit`` on the training walks' true steps.
        wavelet: wavelet-denoise gyro and magnetometer first (BKF-WT).
        wavelet_name: the denoiser's wavelet.
        denoise_window: the denoiser's buffer, samples.
        bkf_origin: ``"zero"`` (literal) or ``"start"`` (module docstring).
        heading_method: ``"bkf"`` (the paper's), ``"kf"``, ``"mag"`` (the
            tilt-compensated magnetometer heading alone, held between fresh
            samples) or ``"gyro"`` (trapezoidal integration of the yaw rate
            alone): the four columns of Table 1.
        mag_frame: ``"site"`` turns magnetometer headings into the building
            frame with the site's north and declination; ``"start"`` instead
            takes the offset from the episode's first fresh magnetometer
            window and the known start heading — for real logs whose map
            is not tied to north.
        k_fitted: after ``fit``, the K in use.
        step_lag_fitted: after ``fit``, how late the detector times a step
            after its heel strike on the training walks, s (NaN without
            labelled steps: the filter's group delay stands in).
        step_log: this episode's detected steps as (peak time s, heading rad
            unwrapped, length m), for per-step scoring (Table 1).
    """

    name: ClassVar[str] = "han2023-pdr"
    needs: ClassVar[tuple[str, ...]] = ()
    uses: ClassVar[tuple[str, ...]] = ("training walks",)

    min_interval_s: float = 0.5
    weinberg_k: float = WEINBERG_K
    calibrate: bool = True
    wavelet: bool = False
    wavelet_name: str = "db4"
    denoise_window: int = 64
    bkf_origin: str = "start"
    heading_method: str = "bkf"
    mag_frame: str = "site"

    k_fitted: float = field(default=WEINBERG_K, init=False, compare=False)
    step_lag_fitted: float = field(default=float("nan"), init=False, compare=False)
    _mag_to_building: float = field(default=0.0, init=False, repr=False, compare=False)
    _site_mag_offset: float = field(default=0.0, init=False, repr=False, compare=False)
    _align_pending: bool = field(default=False, init=False, repr=False, compare=False)
    _detector: PeakStepDetector = field(init=False, repr=False, compare=False)
    step_log: list[tuple[float, float, float]] = field(
        default_factory=list, init=False, repr=False, compare=False
    )
    _filter: HeadingKF = field(init=False, repr=False, compare=False)
    _gyro_dn: StreamingDenoiser = field(init=False, repr=False, compare=False)
    _mag_dn: StreamingDenoiser = field(init=False, repr=False, compare=False)
    _position: NDArray[np.float64] | None = field(
        default=None, init=False, repr=False, compare=False
    )
    _steps: int = field(default=0, init=False, repr=False, compare=False)
    _estimate_time: float = field(default=0.0, init=False, repr=False, compare=False)
    _hist_t: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    _hist_h: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    _heading: float = field(default=0.0, init=False, repr=False, compare=False)
    _guard: SampleGuard = field(default_factory=SampleGuard, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.bkf_origin not in ("zero", "start"):
            raise ValueError(f"bkf_origin must be 'zero' or 'start', got {self.bkf_origin!r}")
        if self.mag_frame not in ("site", "start"):
            raise ValueError(f"mag_frame must be 'site' or 'start', got {self.mag_frame!r}")
        if self.heading_method not in HEADING_METHODS:
            raise ValueError(
                f"heading_method must be one of {HEADING_METHODS}, got {self.heading_method!r}"
            )
        self.k_fitted = self.weinberg_k
        self._detector = PeakStepDetector(min_interval_s=self.min_interval_s)
        self._filter = HeadingBKF() if self.heading_method == "bkf" else HeadingKF()
        self._gyro_dn = StreamingDenoiser(window=self.denoise_window, wavelet=self.wavelet_name)
        self._mag_dn = StreamingDenoiser(window=self.denoise_window, wavelet=self.wavelet_name)

    @property
    def heading(self) -> float:
        """Current walking-direction estimate, rad counter-clockwise from +x, wrapped."""
        return float(wrap_angle(self._heading))

    @property
    def step_count(self) -> int:
        """Steps detected since the episode's start."""
        return self._steps

    @property
    def estimate_time(self) -> float:
        """The time the position refers to: the last step's heel strike (its peak
        time less the lag measured in ``fit``, else the filter's group delay; the
        start before a step), s."""
        return self._estimate_time

    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """Calibrate K on the training walks' true steps (default K without any), and
        measure there how late the detector times a step (:attr:`estimate_time`)."""
        self._site_mag_offset = site.magnetic_to_building_rad
        self.k_fitted = self.weinberg_k
        matched: list[Step] = []
        lengths: list[NDArray[np.float64]] = []
        lags: list[float] = []
        for rec in train:
            true = rec.streams.get("steps")
            accel = rec.streams.get("accel")
            if true is None or accel is None or not len(true) or not len(accel):
                continue
            det = PeakStepDetector(min_interval_s=self.min_interval_s)
            steps = det.update(accel.index.to_numpy(dtype=float), accel[["x", "y", "z"]].to_numpy())
            true_t = true.index.to_numpy(dtype=float)
            s, lens = match_steps(steps, true_t, true["length"].to_numpy(dtype=float))
            matched += s
            lengths.append(lens)
            lags.append(step_lag_s([st.t for st in steps], true_t))
        self.step_lag_fitted = median_step_lag_s(lags)
        if matched and self.calibrate:
            try:
                self.k_fitted = calibrate_k(matched, np.concatenate(lengths))
            except ValueError:
                self.k_fitted = self.weinberg_k

    def reset(self, start: StartInfo) -> None:
        self._position = np.array(start.position, dtype=float)
        self._steps = 0
        self._estimate_time = float(start.t0)
        self.step_log = []
        self._heading = float(start.heading)
        self._mag_to_building = self._site_mag_offset
        self._align_pending = self.mag_frame == "start"
        self._detector.reset()
        self._filter.origin = float(start.heading) if self.bkf_origin == "start" else 0.0
        self._filter.reset(float(start.heading))
        self._gyro_dn.reset()
        self._mag_dn.reset()
        self._hist_t, self._hist_h = np.empty(0), np.empty(0)
        self._guard.reset()

    def _headings(self, obs: Observation, valid: NDArray[np.bool_]) -> None:
        """Run the heading method over the window's samples and extend the history."""
        present = present_streams(obs)
        t = obs["t"][valid]
        acc = obs["accel"][valid]
        up = (
            obs["gravity"][valid] if present["gravity"] else np.broadcast_to(acc.mean(0), acc.shape)
        )
        rates = None
        if present["gyro"] and self.heading_method != "mag":
            gyro = obs["gyro"][valid]
            if self.wavelet:
                gyro = self._gyro_dn.update(gyro)
            rates = yaw_rate(gyro, up)
        phi = np.full(len(t), np.nan)
        if present["mag"] and self.heading_method != "gyro":
            fresh = obs["mag_fresh"][valid].astype(bool)
            if fresh.any():
                mag = obs["mag"][valid][fresh]
                if self.wavelet:
                    mag = self._mag_dn.update(mag)
                if self._align_pending:
                    raw = mag_heading(mag, up[fresh])
                    mean = np.angle(np.exp(1j * raw).mean())
                    self._mag_to_building = float(wrap_angle(self._heading - mean))
                    self._align_pending = False
                phi[fresh] = mag_heading(mag, up[fresh], self._mag_to_building)
        if self.heading_method == "mag":
            h = self._held_mag_heading(phi)
        else:
            h = self._filter.filter(t, phi, rates).heading
        self._heading = float(h[-1])
        t_all = np.r_[self._hist_t, t]
        h_all = np.r_[self._hist_h, h]
        keep = t_all >= t[-1] - _HISTORY_S
        self._hist_t, self._hist_h = t_all[keep], h_all[keep]

    def _held_mag_heading(self, phi: NDArray[np.float64]) -> NDArray[np.float64]:
        """The magnetometer heading alone ("Mag"): unwrapped, held between fresh samples."""
        h = np.empty(len(phi))
        last = self._heading
        for i, p in enumerate(phi):
            if np.isfinite(p):
                last += float(wrap_angle(p - last))
            h[i] = last
        return h

    def act(self, obs: Observation) -> NDArray[np.float64]:
        if self._position is None:
            raise not_reset_error(self.name)
        obs = self._guard(obs)
        valid = obs["valid"].astype(bool)
        if not valid.any():
            return self._position.copy()
        self._headings(obs, valid)
        steps = self._detector.update(obs["t"][valid], obs["accel"][valid])
        if steps:
            self._steps += len(steps)
            t_steps = [s.t for s in steps]
            phi = np.interp(t_steps, self._hist_t, self._hist_h)
            length = weinberg([s.a_max for s in steps], [s.a_min for s in steps], self.k_fitted)
            self.step_log += zip(t_steps, phi.tolist(), length.tolist(), strict=True)
            self._position += np.array([length @ np.cos(phi), length @ np.sin(phi)])
            lag = self.step_lag_fitted
            if not np.isfinite(lag):
                lag = self._detector.delay_s
            self._estimate_time = t_steps[-1] - lag
        return self._position.copy()


# --------------------------------------------------------------------------- layer 1


def grid_survey_table(site: SiteContext, survey: str | None, who: str) -> pd.DataFrame:
    grids = {name: db for name, db in sorted(site.fingerprints.items()) if "grid" in db.tables}
    if survey is not None:
        grids = {survey: grids[survey]} if survey in grids else {}
    if not grids:
        wanted = f"a grid survey named {survey!r}" if survey else "a grid survey"
        raise NotApplicableError(
            f"{who} needs {wanted} (a fingerprint database with a 'grid' table of "
            f"{', '.join(SURVEY_COLUMNS.values())}); site {site.name!r} has "
            f"{sorted(site.fingerprints) or 'no fingerprint databases'}"
        )
    table = next(iter(grids.values()))["grid"]
    missing = [c for c in ["x", "y", *SURVEY_COLUMNS.values()] if c not in table.columns]
    if missing:
        raise NotApplicableError(f"{who}: the grid survey lacks columns {missing}")
    return table


@register("han2023-gml")
@dataclass(kw_only=True)
class Han2023GML:
    """Layer 1, GM/Light: Tent-ASO-BP from (Mx, My, Mz, L) to (x, y) (module docstring).

    ``fit`` interpolates the grid survey into a
    :class:`~indoorsim.estimators.fingerprint.library.FingerprintLibrary` and
    trains the network on every library point. ``act`` feeds it the window's
    mean field (fresh magnetometer samples rotated to the geographic frame by
    the rotation vector) and mean illuminance.

    Attributes:
        population: ASO atoms (paper 30).
        iterations: ASO iterations (paper 500).
        epochs: BP epochs (paper 1000).
        hidden: hidden neurons (paper 4).
        use_tent: Tent-map initial population.
        use_aso: ASO search of the initial weights.
        bp_update: BP's momentum update (:class:`~indoorsim.estimators.nn.bp.TentAsoBP`).
        mag_resolution: library magnetic grid, m.
        light_resolution: library light grid, m.
        survey: the grid survey's database name; None for the first with a grid.
        fit_seed: the seed of the training's randomness.
        library: after ``fit``, the fingerprint library.
        network: after ``fit``, the trained network.
    """

    name: ClassVar[str] = "han2023-gml"
    needs: ClassVar[tuple[str, ...]] = ("grid survey",)
    uses: ClassVar[tuple[str, ...]] = ("floor plan",)
    features: ClassVar[tuple[str, ...]] = ("Mx", "My", "Mz", "L")

    population: int = 30
    iterations: int = 500
    epochs: int = 1000
    hidden: int = 4
    use_tent: bool = True
    use_aso: bool = True
    bp_update: BPUpdate = "traingdm"
    mag_resolution: float = 0.3
    light_resolution: float = 0.6
    survey: str | None = None
    fit_seed: int = 0

    library: FingerprintLibrary | None = field(default=None, init=False, repr=False, compare=False)
    network: TentAsoBP | None = field(default=None, init=False, repr=False, compare=False)
    _mean_light: float = field(default=0.0, init=False, repr=False, compare=False)
    _guard: SampleGuard = field(default_factory=SampleGuard, init=False, repr=False, compare=False)
    _position: NDArray[np.float64] | None = field(
        default=None, init=False, repr=False, compare=False
    )
    _estimate_time: float = field(default=0.0, init=False, repr=False, compare=False)

    @property
    def estimate_time(self) -> float:
        """The time the position refers to: the mean time of the fresh magnetometer
        samples it was computed from (the start before any), s."""
        return self._estimate_time

    def _new_network(self) -> TentAsoBP:
        return TentAsoBP(
            population=self.population,
            iterations=self.iterations,
            epochs=self.epochs,
            hidden=self.hidden,
            use_tent=self.use_tent,
            use_aso=self.use_aso,
            bp_update=self.bp_update,
        )

    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """Build the library from the grid survey and train the network on it.

        Raises:
            NotApplicableError: if the site has no grid survey.
        """
        table = grid_survey_table(site, self.survey, self.name)
        plan_like = site.plan if site.plan is not None else table[["x", "y"]].to_numpy(float)
        self.library = FingerprintLibrary(
            mag_resolution=self.mag_resolution, light_resolution=self.light_resolution
        ).fit(table, plan_like)
        self.fit_table(self.library.table)

    def fit_table(self, table: pd.DataFrame) -> None:
        """Train the network on a library table (columns x, y and the features)."""
        self._mean_light = float(table["L"].mean()) if "L" in table else 0.0
        x = table[list(self.features)].to_numpy(dtype=float)
        y = table[["x", "y"]].to_numpy(dtype=float)
        self.network = self._new_network().fit(x, y, np.random.default_rng(self.fit_seed))

    def predict(self, features: NDArray[np.float64]) -> NDArray[np.float64]:
        """Positions (N, 2) of features (N, len(features))."""
        if self.network is None:
            raise RuntimeError(f"{self.name}: call fit(site, train) first")
        return self.network.predict(np.atleast_2d(features))

    def reset(self, start: StartInfo) -> None:
        self._position = np.array(start.position, dtype=float)
        self._estimate_time = float(start.t0)
        self._guard.reset()

    def window_features(self, obs: Observation) -> NDArray[np.float64] | None:
        """The window's feature vector, or None without a fresh, rotatable magnetometer sample."""
        field_geo = geomagnetic_mean(obs)
        if field_geo is None:
            return None
        if "L" not in self.features:
            return field_geo
        valid = obs["valid"].astype(bool)
        if present_streams(obs)["light"]:
            lit = valid & obs["light_fresh"].astype(bool)
            lux = float(obs["light"][lit].mean()) if lit.any() else float(obs["light"][valid][-1])
        else:
            lux = self._mean_light
        return np.r_[field_geo, lux]

    def act(self, obs: Observation) -> NDArray[np.float64]:
        if self.network is None:
            raise RuntimeError(f"{self.name}: call fit(site, train) first (it needs a grid survey)")
        if self._position is None:
            raise not_reset_error(self.name)
        obs = self._guard(obs)
        f = self.window_features(obs)
        if f is not None:
            self._position = self.predict(f[None, :])[0]
            fresh = obs["valid"].astype(bool) & obs["mag_fresh"].astype(bool)
            self._estimate_time = float(obs["t"][fresh].mean())
        return self._position.copy()


@register("han2023-gm")
@dataclass(kw_only=True)
class Han2023GM(Han2023GML):
    """Layer 1, magnetic only (Single GM): Tent-ASO-BP from (Mx, My, Mz) to (x, y)."""

    name: ClassVar[str] = "han2023-gm"
    features: ClassVar[tuple[str, ...]] = ("Mx", "My", "Mz")


@register("bp")
@dataclass(kw_only=True)
class PlainBP(Han2023GML):
    """GM/Light layer 1 trained by plain BP from a Nguyen–Widrow start (Table 2, "BP")."""

    name: ClassVar[str] = "bp"
    use_tent: bool = False
    use_aso: bool = False


@register("aso-bp")
@dataclass(kw_only=True)
class AsoBP(Han2023GML):
    """GM/Light layer 1 with ASO-searched initial weights, random population (Table 2)."""

    name: ClassVar[str] = "aso-bp"
    use_tent: bool = False
    use_aso: bool = True


@register("tent-aso-bp")
@dataclass(kw_only=True)
class TentAsoBPStatic(Han2023GML):
    """GM/Light layer 1 with Tent-initialised ASO (Table 2, "Tent-ASO-BP")."""

    name: ClassVar[str] = "tent-aso-bp"
    use_tent: bool = True
    use_aso: bool = True


# --------------------------------------------------------------------------- layer 2


def _truth_start(rec: Recording, seed: int) -> StartInfo | None:
    truth = rec.streams.get("truth")
    if truth is None or not len(truth):
        return None
    return StartInfo(
        position=np.array([truth["x"].iloc[0], truth["y"].iloc[0]], dtype=float),
        heading=float(truth["heading"].iloc[0]),
        seed=seed,
        t0=float(rec.accel.index[0]),
    )


@register("han2023-fusion")
@dataclass(kw_only=True)
class Han2023Fusion:
    """Layer 2: Tent-ASO-BP from (x_GML, y_GML, x_PDR, y_PDR) to (x, y) (module docstring).

    ``fit`` fits both layers' components, replays every labelled training
    walk window by window through them (started from the walk's true start)
    and trains the network on their answers against the true position at
    each window's end.

    Which walks train layer 2 is the evaluation protocol's choice (the paper
    does not say; PAPER_NOTES, Han2023 item 9): walks of other routes, or of
    the test route by other seeds (``evaluate(..., train_routes="same")``).
    On the same route the network can learn the route itself — where along
    it a PDR answer lies and how PDR drifts there — rather than how to weigh
    two position sources; ``layer2_inputs="pdr"`` trains it on the PDR
    answer alone, which shows how much of its accuracy is that.

    Attributes:
        pdr: the PDR (its parameters).
        gml: layer 1 (its parameters).
        layer2_inputs: ``"gml+pdr"`` (the paper's 4-D input) or ``"pdr"``
            ((x_PDR, y_PDR) only: a diagnostic of what layer 2 learns).
        population: layer-2 ASO atoms.
        iterations: layer-2 ASO iterations.
        epochs: layer-2 BP epochs.
        bp_update: layer 2's BP momentum update (layer 1's is ``gml.bp_update``).
        fit_seed: the seed of layer 2's training.
        network: after ``fit``, layer 2.
    """

    name: ClassVar[str] = "han2023-fusion"
    needs: ClassVar[tuple[str, ...]] = ("grid survey", "training walks")
    uses: ClassVar[tuple[str, ...]] = ("floor plan",)

    pdr: Han2023Pdr = field(default_factory=Han2023Pdr)
    gml: Han2023GML = field(default_factory=Han2023GML)
    layer2_inputs: str = "gml+pdr"
    population: int = 30
    iterations: int = 500
    epochs: int = 1000
    hidden: int = 4
    bp_update: BPUpdate = "traingdm"
    fit_seed: int = 0

    network: TentAsoBP | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.layer2_inputs not in LAYER2_INPUTS:
            raise ValueError(
                f"layer2_inputs must be one of {LAYER2_INPUTS}, got {self.layer2_inputs!r}"
            )

    @property
    def heading(self) -> float:
        """The PDR's heading, rad counter-clockwise from +x."""
        return self.pdr.heading

    @property
    def step_count(self) -> int:
        """The PDR's steps this episode."""
        return self.pdr.step_count

    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """Fit the PDR and layer 1, then layer 2 on the training walks.

        Raises:
            NotApplicableError: without a grid survey, or without a training
                walk with a truth stream.
        """
        if self.layer2_inputs != "pdr":
            self.gml.fit(site, train)
        self.pdr.fit(site, train)
        inputs, targets = self.layer_two_data(site, train)
        self.network = TentAsoBP(
            population=self.population,
            iterations=self.iterations,
            epochs=self.epochs,
            hidden=self.hidden,
            bp_update=self.bp_update,
        ).fit(inputs, targets, np.random.default_rng(self.fit_seed))

    def layer_two_data(
        self, site: SiteContext, train: Sequence[Recording]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Layer 2's training set: the fitted PDR and layer 1 replayed on the training walks.

        Returns:
            (N, 4) inputs (x_GML, y_GML, x_PDR, y_PDR) at each window's end
            ((N, 2) (x_PDR, y_PDR) with ``layer2_inputs="pdr"``) and (N, 2)
            true positions there.

        Raises:
            NotApplicableError: without a training walk with a truth stream.
        """
        inputs, targets = [], []
        for k, rec in enumerate(train):
            start = _truth_start(rec, seed=k)
            if start is None or "accel" not in rec.streams or not len(rec.accel):
                continue
            windows = Windower(rec, site.window_samples, site.bssids)
            self.reset(start)
            ends = np.array([windows.end_time(i) for i in range(len(windows))])
            for obs in windows:
                inputs.append(self._inputs(obs))
            ts = rec.truth.index.to_numpy(dtype=float)
            targets.append(
                np.column_stack([np.interp(ends, ts, rec.truth[c].to_numpy(float)) for c in "xy"])
            )
        if not inputs:
            raise NotApplicableError(
                f"{self.name} needs labelled training walks (with a truth stream) for layer 2"
            )
        return np.array(inputs), np.vstack(targets)

    def reset(self, start: StartInfo) -> None:
        self.pdr.reset(start)
        self.gml.reset(start)

    def act(self, obs: Observation) -> NDArray[np.float64]:
        if self.network is None:
            raise RuntimeError(f"{self.name}: call fit(site, train) first")
        return self.network.predict(self._inputs(obs)[None, :])[0]

    def _inputs(self, obs: Observation) -> NDArray[np.float64]:
        """Layer 2's input for the window: both layers' answers, or PDR's alone."""
        pdr = self.pdr.act(obs)
        if self.layer2_inputs == "pdr":
            return pdr
        return np.r_[self.gml.act(obs), pdr]
