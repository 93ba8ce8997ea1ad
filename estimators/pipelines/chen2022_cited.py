"""The methods Chen2022 compares against, rebuilt from what their papers publicly describe.

Registered estimators (PAPER_NOTES, Chen2022; the leaderboard marks them "≈"):

* ``edtw-rekf`` — EDTW + REKF (Chen, Song & Yu 2021, *AEU* 135, 153733;
  Chen2022 Table 1): magnetic matching by an enhanced DTW and WiFi matching,
  fused with dead reckoning by a robust extended Kalman filter.
* ``apf`` — APF (Hu, Peng, Tang & Xu 2021, *Sensors* 21(24), 8228; Chen2022
  Table 2): dead reckoning and WiFi fixes fused by an adaptive particle
  filter on the floor plan.
* ``wimag`` — WiMag (Guo, Shao, Zhao, Wang, Li & Luo 2016, IPIN; Chen2022
  Table 2): magnetic, WiFi and PDR fused in a particle filter that selects its
  fusion mode.

Only what those papers make public could be used: their abstracts (EDTW+REKF:
the publisher's abstract of doi:10.1016/j.aeue.2021.153733; APF: the open
abstract of doi:10.3390/s21248228 on MDPI and DOAJ) and, for WiMag, whose
text and abstract we could not find, its title and the sentence Chen2022's
related work gives it. Everything else is a reading of ours, listed below and
marked in each class. All three share Chen2022's front end
(:class:`~indoorsim.estimators.pipelines.chen2022.Chen2022FrontEnd`, its
options and fitted values): the same gait dead reckoning, the same walk
survey, the same query lengths and grid, and the same way of fitting
likelihood and noise scales on the labelled training walks
(:func:`~indoorsim.estimators.pipelines.chen2022.replay_errors`), so that the
comparison is on equal terms; what differs is what each cited paper says
differs.

EDTW + REKF
-----------
Published (abstract): an *enhanced dynamic time warping* (EDTW) improves the
accuracy of magnetic matching; PDR, magnetic matching (MM) and WiFi are fused
by a *robust EKF* (REKF) "that introduces the estimation of the innovation
sequence covariance"; the PDR error model is the state transition, and the
differences PDR − MM and PDR − WiFi are the observations.

Ours:

* **EDTW** (:func:`edtw_many`, :class:`EdtwMatcher`). Chen2022 credits its own
  gain over EDTW to the HV fingerprint's "higher-level" features, so EDTW is
  read as matching the traditional fingerprint, the field magnitude
  |B| = √(B_H² + B_V²) (orientation-free). The enhancement: each sequence is
  mean-removed (an offset between the survey phone and the walking phone
  does not count) and the local distance adds the slope (Keogh–Pazzani
  derivative, per metre) to the value, d(i, j) = √(Δ|B|² + (1 m · Δ∂|B|/∂s)²).
  Windows, directions and WKNN are those of Chen2022's matcher.
* **WiFi fixes**: the paper does not describe its WiFi matching here; the
  front end's MD-DTW profile matcher (same first author) is used.
* **Filter** (:class:`RobustEkf`): state x = [x, y, θ] and PDR as the
  process, which with H = [I₂ 0] and z = a fix is the same filter as the
  published error-state form (state = PDR error, z = PDR − fix). The robust
  part is the innovation-based adaptive estimation (IAE; Mohamed & Schwarz
  1999) that the abstract names: the innovation covariance Ĉ_v is estimated
  from the last M innovations of the same source and, when it exceeds what
  the filter predicts, the fix's R is inflated to match; R is never shrunk
  (a robust filter only down-weights). M = 5 fixes. No floor plan.

APF
---
Published (abstract): dead reckoning is the state transition and the
difference between inertial navigation and the WiFi fingerprint fix the
observation; particles that cross a wall get weight zero; for the others an
*adaptive factor*, from the distance between current and historical
particles, increases the weight of highly trusted particles and reduces that
of less trusted ones; WiFi matching by a *multidimensional Euclidean distance*.

Ours:

* **Adaptive factor** (:class:`AdaptiveParticleFilter`): a particle's
  "historical particle" is its own position L = 5 steps back (ancestors kept
  through resampling); it is trusted when the distance it moved since matches
  the distance dead reckoning walked over the same steps (the chord D),
  α_i = exp(−(‖x_i,k − x_i,k−L‖ − D)² / 2σ_α²), σ_α² = L·(σ_step² + σ_xy²) (the
  along-track spread the process noise gives a chord). It multiplies the
  WiFi likelihood at the steps with a WiFi fix; normalising makes it raise
  the weights of trusted particles and lower the others'.
* **Multidimensional Euclidean distance** (:class:`MdedWifiMatcher`): the
  profile of the last M scans and each run of M consecutive reference
  fingerprints compared as single vectors, √(Σ_scans Σ_APs Δ²), without warping.
* Magnetic matching is not part of the published method and is left out.

WiMag
-----
Published: the title, "multimode fusion localization system based on
magnetic/WiFi/PDR", and Chen2022's summary — it "selects the fusion strategy
to combine the positioning results based on the PF framework".

Ours (all of it a reading):

* **WiFi for the coarse position**: the latest WiFi fix, carried along by
  dead reckoning, is the centre of a region of radius 2 × the WiFi fixes' RMS
  error on the training walks (at least 5 m); before the first scan there is
  no region.
* **Magnetic matching inside the region** (:class:`RegionMagneticMatcher`):
  only survey windows ending in the region are candidates. The matcher is
  plain multi-dimensional DTW on the front end's attitude-free fingerprint
  (``matcher="md-dtw"``; the derivative of HV-DDTW is Chen2022's
  contribution), ``matcher="hv-ddtw"`` being the other reading.
* **Mode selection** per step: a magnetic fix in the region → the magnetic
  likelihood (fine mode; its WiFi fix already chose the region and is not
  counted twice); else a WiFi fix → the WiFi likelihood (coarse mode); else
  dead reckoning alone.
* **Particle filter** without the floor plan (the description names none;
  ``use_plan=True`` adds Chen2022's wall rule).

Likelihood scales R (Gaussian exp(−d²/2R), Chen2022's default reading), the
step-length noise and G_φ are fitted on the training walks exactly as for
``chen2022-cpf``; WiMag fits its magnetic R on region-restricted fixes.
"""

from __future__ import annotations

import copy
import dataclasses
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.base import (
    Observation,
    SiteContext,
    StartInfo,
    not_reset_error,
    register,
)
from indoorsim.estimators.filters import ParticleFilter, gaussian_likelihood
from indoorsim.estimators.fingerprint.dtw import (
    DEFAULT_FLOOR_DBM,
    dtw_many,
    weighted_knn,
)
from indoorsim.estimators.fingerprint.hv import derivative
from indoorsim.estimators.fingerprint.sequences import (
    MagneticSequenceMatcher,
    WifiSequenceMatcher,
)
from indoorsim.estimators.frames import wrap_angle
from indoorsim.estimators.pipelines.chen2022 import (
    DEFAULT_R_WIFI_M2,
    Chen2022FrontEnd,
    FixTracker,
    StepFixes,
    fix_variance_m2,
    replay_errors,
)
from indoorsim.io.recording import Recording

__all__ = [
    "AdaptiveParticleFilter",
    "Apf",
    "CoarseRegionTracker",
    "EdtwMatcher",
    "EdtwRekf",
    "MdedWifiMatcher",
    "RegionMagneticMatcher",
    "RobustEkf",
    "WiMag",
    "edtw_many",
    "mded_many",
]

# Internal state of a dataclass: not a constructor argument, not shown, not compared.
_STATE: dict[str, bool] = {"init": False, "repr": False, "compare": False}

Region = tuple[NDArray[np.float64], float]
"""A disk: its centre (2,), m, and radius, m."""


# ------------------------------------------------------------------------------ EDTW


def _edtw_features(seqs: NDArray[np.float64], slope_weight: float) -> NDArray[np.float64]:
    """(R, n) magnitude sequences → (R, n, 2) channels [|B| − mean, w·∂|B|] (module docstring)."""
    # EDTW (our reading of Chen et al. 2021): the mean-removed value and the slope
    centred = seqs - seqs.mean(axis=1, keepdims=True)
    # Keogh–Pazzani derivative (Chen2022 Eq. 19–20) of each sequence along its samples.
    slope = derivative(seqs.T).T
    return np.stack([centred, slope_weight * slope], axis=2)


def edtw_many(
    query: ArrayLike,
    references: ArrayLike | Sequence[ArrayLike],
    *,
    slope_weight: float = 1.0,
    window: int | None = None,
) -> NDArray[np.float64]:
    """Enhanced DTW distances of one magnitude sequence to many (our reading of Chen et al. 2021).

    Each sequence is mean-removed and paired with its Keogh–Pazzani derivative
    (each differentiated on its own); the classic DTW recursion (Chen2022
    Alg. 1, summed local distances) then runs with the local distance

        d(i, j) = √((q̃_i − r̃_j)² + w²·(q'_i − r'_j)²),

    q̃ the mean-removed values, q' the derivative per sample, w =
    ``slope_weight``. A constant offset between query and reference does not
    count; a copy scaled about its mean by a has, on the diagonal, the
    distance |a − 1|·Σ_i √(r̃_i² + w²·r'_i²).

    Args:
        query: (n,) magnitudes, n ≥ 3.
        references: (R, m) array or sequence of (m_r,) arrays, each ≥ 3 samples.
        slope_weight: w, the weight of the derivative channel (samples per
            unit of the slope's length scale: 1/spacing for a 1 m scale).
        window: Sakoe–Chiba half-width in samples; None: none.

    Returns:
        (R,) distances.

    >>> float(edtw_many([1.0, 2.0, 4.0, 3.0], [[11.0, 12.0, 14.0, 13.0]])[0])
    0.0
    """
    q = np.asarray(query, dtype=float)
    if q.ndim != 1 or len(q) < 3:
        raise ValueError(f"the query must be (n,) with n ≥ 3, got {q.shape}")
    if slope_weight < 0:
        raise ValueError(f"slope_weight must be ≥ 0, got {slope_weight}")
    qf = _edtw_features(q[None, :], slope_weight)[0]
    if isinstance(references, np.ndarray) and references.ndim == 2:
        if references.shape[1] < 3:
            raise ValueError("EDTW needs references of at least 3 samples")
        refs: NDArray[np.float64] | list[NDArray[np.float64]] = _edtw_features(
            np.asarray(references, dtype=float), slope_weight
        )
    else:
        seqs = [np.asarray(r, dtype=float) for r in references]
        if any(s.ndim != 1 or len(s) < 3 for s in seqs):
            raise ValueError("EDTW needs (m,) references of at least 3 samples")
        refs = [_edtw_features(s[None, :], slope_weight)[0] for s in seqs]
    return dtw_many(qf, refs, window=window)


@dataclass(kw_only=True)
class EdtwMatcher(MagneticSequenceMatcher):
    """Magnetic sequence matching by enhanced DTW of the field magnitude (:func:`edtw_many`).

    The same survey windows, walking directions and WKNN (Chen2022 Eq. 21) as
    :class:`~indoorsim.estimators.fingerprint.sequences.MagneticSequenceMatcher`;
    queries and windows arrive as HV fingerprints and are compared as their
    magnitude |B| = √(B_H² + B_V²) (Eq. 18 makes that exact).

    Attributes:
        slope_length_m: the length scale that weighs the slope against the
            value: the derivative channel is the slope per metre times this.
        spacing_m: the grid spacing of tracks and queries, m.
    """

    matcher: Literal["edtw"] = "edtw"  # type: ignore[assignment]
    slope_length_m: float = 1.0
    spacing_m: float = 0.2

    def __post_init__(self) -> None:
        if self.k < 1:
            raise ValueError(f"k must be ≥ 1, got {self.k}")
        if self.slope_length_m < 0 or self.spacing_m <= 0:
            raise ValueError("need slope_length_m ≥ 0 and spacing_m > 0")

    def distances(self, query_hv: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """EDTW distances of the query to every window, and the windows' end positions."""
        q = self._query(query_hv)
        refs, ends = self.windows(len(q))
        magnitude: NDArray[np.float64] | list[NDArray[np.float64]]
        if isinstance(refs, np.ndarray):
            magnitude = np.hypot(refs[..., 0], refs[..., 1])
        else:
            magnitude = [np.hypot(r[:, 0], r[:, 1]) for r in refs]
        # Slope per sample → per metre (÷ spacing), times the length scale.
        w = self.slope_length_m / self.spacing_m
        d = edtw_many(np.hypot(q[:, 0], q[:, 1]), magnitude, slope_weight=w, window=self.band)
        return d, ends


# ------------------------------------------------------------------------------ REKF


@dataclass(kw_only=True)
class RobustEkf:
    """Step-driven EKF on [x, y, θ] with innovation-based robust fixes (our reading of the REKF).

    Predict, per detected step of length SL and heading change Δθ (PDR as the
    state transition; θ from the building's +x, counter-clockwise)::

        θ⁻ = θ + Δθ,   x⁻ = x + SL·cos θ⁻,   y⁻ = y + SL·sin θ⁻
        F = ∂f/∂x = [[1, 0, −SL·sin θ⁻], [0, 1, SL·cos θ⁻], [0, 0, 1]]
        G = ∂f/∂w = [[cos θ⁻, −SL·sin θ⁻], [sin θ⁻, SL·cos θ⁻], [0, 1]],  w = [δSL, δθ]
        Q = G·diag(σ_step², σ_heading²)·Gᵀ + diag(σ_xy², σ_xy², 0)
        P⁻ = F P Fᵀ + Q

    Update with a position fix z (2,) of variance r per axis::

        H = [I₂ 0],  R = r·I₂,  v = z − H x⁻,  S = H P⁻ Hᵀ + R
        Ĉ_v = (1/M)·Σ_{last M innovations of this source} v vᵀ     (IAE)
        λ = max(1, (tr Ĉ_v − tr H P⁻ Hᵀ) / tr R),   R̃ = λ·R
        K = P⁻ Hᵀ (H P⁻ Hᵀ + R̃)⁻¹,  x = x⁻ + K v,
        P = (I − K H) P⁻ (I − K H)ᵀ + K R̃ Kᵀ                      (Joseph form)

    When the recent innovations are no larger than the filter predicts
    (λ = 1, the equivalent weight 1/λ = 1) this is the plain EKF; a fix
    whose innovations outgrow S is down-weighted by 1/λ. Chen et al. 2021's
    abstract names the innovation-covariance estimate; M, the trace
    comparison and "inflate only" are our choices (module docstring).

    Kept for diagnosis (filterpy style): ``x_prior`` and ``P_prior`` of the
    last prediction; ``y`` (innovation), ``S`` (with R̃), ``K`` and ``weight``
    (1/λ) of the last update.

    Attributes:
        sigma_step: std of the step-length noise δSL, m.
        sigma_heading: std of the heading noise δθ per step, rad.
        sigma_xy: std of the position noise per step and axis, m.
        innovation_window: M, innovations per source in Ĉ_v.

    Example:
        >>> ekf = RobustEkf(sigma_step=0.0, sigma_heading=0.0, sigma_xy=0.0)
        >>> ekf.initialise([0.0, 0.0], heading=0.0, position_std=1.0, heading_std=0.0)
        >>> ekf.predict(step_length=0.7, delta_heading=0.0)
        >>> ekf.x.round(6).tolist()
        [0.7, 0.0, 0.0]
    """

    sigma_step: float = 0.05
    sigma_heading: float = 0.05
    sigma_xy: float = 0.1
    innovation_window: int = 5

    x: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3), **_STATE)
    P: NDArray[np.float64] = field(default_factory=lambda: np.eye(3), **_STATE)
    x_prior: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3), **_STATE)
    P_prior: NDArray[np.float64] = field(default_factory=lambda: np.eye(3), **_STATE)
    y: NDArray[np.float64] = field(default_factory=lambda: np.zeros(2), **_STATE)
    S: NDArray[np.float64] = field(default_factory=lambda: np.eye(2), **_STATE)
    K: NDArray[np.float64] = field(default_factory=lambda: np.zeros((3, 2)), **_STATE)
    weight: float = field(default=1.0, **_STATE)
    _innovations: dict[str, deque[NDArray[np.float64]]] = field(default_factory=dict, **_STATE)

    H: ClassVar[NDArray[np.float64]] = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])

    def __post_init__(self) -> None:
        for name in ("sigma_step", "sigma_heading", "sigma_xy"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be ≥ 0, got {getattr(self, name)}")
        if self.innovation_window < 1:
            raise ValueError(f"innovation_window must be ≥ 1, got {self.innovation_window}")

    def initialise(
        self, position: ArrayLike, heading: float, *, position_std: float, heading_std: float
    ) -> None:
        """Start at a known position and heading with diagonal uncertainty."""
        self.x = np.array([*np.asarray(position, dtype=float), heading])
        self.P = np.diag([position_std**2, position_std**2, heading_std**2])
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()
        self._innovations = {}
        self.weight = 1.0

    def predict(self, step_length: float, delta_heading: float) -> None:
        """Propagate by one detected step (see the class docstring)."""
        theta = self.x[2] + delta_heading
        c, s = np.cos(theta), np.sin(theta)
        sl = step_length
        # f(x): the PDR step as state transition (Chen et al. 2021), Chen2022 Eq. 25 in our frame
        x = np.array([self.x[0] + sl * c, self.x[1] + sl * s, theta])
        # F = ∂f/∂x and G = ∂f/∂w, w = [δSL, δθ]: the EKF's linearisation of f
        F = np.array([[1.0, 0.0, -sl * s], [0.0, 1.0, sl * c], [0.0, 0.0, 1.0]])
        G = np.array([[c, -sl * s], [s, sl * c], [0.0, 1.0]])
        Q = G @ np.diag([self.sigma_step**2, self.sigma_heading**2]) @ G.T + np.diag(
            [self.sigma_xy**2, self.sigma_xy**2, 0.0]
        )
        # P⁻ = F P Fᵀ + Q
        self.P = F @ self.P @ F.T + Q
        self.x = x
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()

    def update(self, z: ArrayLike, r: float, source: str = "fix") -> float:
        """Fuse a position fix z (2,) of variance r (m², per axis); returns the weight 1/λ."""
        H = self.H
        R = r * np.eye(2)
        v = np.asarray(z, dtype=float) - H @ self.x
        window = self._innovations.setdefault(source, deque(maxlen=self.innovation_window))
        window.append(v)
        # IAE: Ĉ_v = (1/M) Σ v vᵀ over the window (Mohamed & Schwarz 1999)
        c_v = sum(np.outer(u, u) for u in window) / len(window)
        hph = H @ self.P @ H.T
        # λ = max(1, (tr Ĉ_v − tr H P⁻ Hᵀ) / tr R) (ours): R inflated to the observed innovations
        lam = max(1.0, (np.trace(c_v) - np.trace(hph)) / np.trace(R))
        R_eq = lam * R
        S = hph + R_eq
        # K = P⁻ Hᵀ S⁻¹, x = x⁻ + K v: the Kalman update with R̃
        K = self.P @ H.T @ np.linalg.inv(S)
        self.x = self.x + K @ v
        i_kh = np.eye(3) - K @ H
        # Joseph form: P = (I − K H) P⁻ (I − K H)ᵀ + K R̃ Kᵀ
        self.P = i_kh @ self.P @ i_kh.T + K @ R_eq @ K.T
        self.y, self.S, self.K, self.weight = v, S, K, 1.0 / lam
        return self.weight


# ------------------------------------------------------------------------------- APF


def mded_many(
    query_rss: ArrayLike,
    references_rss: ArrayLike | Sequence[ArrayLike],
    *,
    floor_dbm: float = DEFAULT_FLOOR_DBM,
) -> NDArray[np.float64]:
    """Multidimensional Euclidean distance of a scan profile to reference runs (our reading).

    The query's m scans and each reference run's last m points are compared
    as one vector over scans × APs, √(Σ_scans Σ_APs (q − r)²), without
    warping; unheard APs (NaN) and readings below the floor count as
    ``floor_dbm``.

    Args:
        query_rss: (m, A) RSS, dBm, oldest scan first.
        references_rss: (R, M, A) array or sequence of (M_r, A) runs, M_r ≥ 1.
        floor_dbm: RSS of an unheard AP, dBm.

    Returns:
        (R,) distances, dB.

    >>> mded_many([[-50.0, -60.0]], [[[-53.0, -64.0]]]).tolist()
    [5.0]
    """
    q = np.asarray(query_rss, dtype=float)
    if q.ndim != 2 or not q.size:
        raise ValueError(f"the query must be a non-empty (m, A) array, got {q.shape}")
    q = np.maximum(np.where(np.isnan(q), floor_dbm, q), floor_dbm)

    def one(r: NDArray[np.float64]) -> float:
        n = min(len(r), len(q))
        d = q[-n:] - r[-n:]
        # MDED (our reading of Hu et al. 2021): √(Σ_scans Σ_APs (q − r)²)
        return float(np.sqrt(np.sum(d * d)))

    if isinstance(references_rss, np.ndarray) and references_rss.ndim == 3:
        r = np.asarray(references_rss, dtype=float)
        r = np.maximum(np.where(np.isnan(r), floor_dbm, r), floor_dbm)
        n = min(r.shape[1], len(q))
        d = q[None, -n:, :] - r[:, -n:, :]
        # MDED (our reading of Hu et al. 2021): √(Σ_scans Σ_APs (q − r)²)
        return np.sqrt(np.einsum("rma,rma->r", d, d))
    return np.array(
        [
            one(np.maximum(np.where(np.isnan(a), floor_dbm, a), floor_dbm))
            for a in (np.asarray(x, dtype=float) for x in references_rss)
        ]
    )


@dataclass(kw_only=True)
class MdedWifiMatcher(WifiSequenceMatcher):
    """WiFi profile matching by the multidimensional Euclidean distance (:func:`mded_many`).

    The reference runs (consecutive survey reference points, both directions)
    and the WKNN (Chen2022 Eq. 21) are those of
    :class:`~indoorsim.estimators.fingerprint.sequences.WifiSequenceMatcher`;
    only the distance differs.
    """

    def match(self, query_rss: ArrayLike) -> tuple[NDArray[np.float64], float]:
        """The fix from a scan profile (oldest first): ``(position (2,), smallest distance)``."""
        if not self.fitted:
            raise RuntimeError("call fit(paths) first")
        d = mded_many(query_rss, self._runs, floor_dbm=self.floor_dbm)
        return weighted_knn(d, self._ends, k=self.k), float(d.min())


@dataclass(kw_only=True)
class AdaptiveParticleFilter(ParticleFilter):
    """Particle filter with Hu et al. (2021)'s adaptive factor, in our reading.

    Besides :class:`~indoorsim.estimators.filters.ParticleFilter` (Eq. 25 and
    the wall rule: a particle that crosses a wall gets weight 0), it keeps
    each particle's positions over the last L steps (reindexed by the
    ancestors at every resampling) and the nominal dead-reckoning moves. The
    adaptive factor of particle i after step k (module docstring):

        D = ‖Σ_{j=k−L+1..k} SL_j·(cos θ_j, sin θ_j)‖      (the DR chord, θ_j nominal)
        α_i = exp(−(‖x_i,k − x_i,k−L‖ − D)² / (2σ_α²)),   σ_α² = L·(σ_step² + σ_xy²)

    with L the steps available (at most ``history_steps``); :meth:`update_adaptive`
    multiplies it into a measurement update. ``adaptive`` keeps the last factor.

    Attributes:
        history_steps: L, steps between a particle and its historical particle.
        sigma_adaptive_m: σ_α, m; None: from the process noise as above.
    """

    history_steps: int = 5
    sigma_adaptive_m: float | None = None

    adaptive: NDArray[np.float64] = field(default_factory=lambda: np.empty(0), **_STATE)
    _history: deque[NDArray[np.float64]] = field(default_factory=deque, **_STATE)
    _moves: deque[NDArray[np.float64]] = field(default_factory=deque, **_STATE)
    _nominal_heading: float = field(default=0.0, **_STATE)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.history_steps < 1:
            raise ValueError(f"history_steps must be ≥ 1, got {self.history_steps}")
        if self.sigma_adaptive_m is not None and self.sigma_adaptive_m <= 0:
            raise ValueError(f"sigma_adaptive_m must be > 0, got {self.sigma_adaptive_m}")

    def initialise(
        self,
        position: ArrayLike,
        heading: float,
        spread: float,
        rng: np.random.Generator,
        *,
        heading_spread: float = 0.0,
    ) -> None:
        super().initialise(position, heading, spread, rng, heading_spread=heading_spread)
        self._history = deque([self.x.copy()], maxlen=self.history_steps + 1)
        self._moves = deque(maxlen=self.history_steps)
        self._nominal_heading = float(heading)
        self.adaptive = np.ones(self.n_particles)

    def predict(self, step_length: float, delta_heading: float, rng: np.random.Generator) -> None:
        super().predict(step_length, delta_heading, rng)
        self._nominal_heading += delta_heading
        h = self._nominal_heading
        self._moves.append(step_length * np.array([np.cos(h), np.sin(h)]))
        self._history.append(self.x.copy())

    def resample(self, rng: np.random.Generator) -> None:
        super().resample(rng)
        # Each survivor inherits its ancestor's past.
        self._history = deque(
            (h[self.ancestors] for h in self._history), maxlen=self._history.maxlen
        )

    def adaptive_factor(self) -> NDArray[np.float64]:
        """(N,) α_i for the current particles (class docstring); ones before the first step."""
        steps = len(self._moves)
        if steps == 0:
            return np.ones(self.n_particles)
        moved = np.linalg.norm(self.x - self._history[-steps - 1], axis=1)
        chord = float(np.linalg.norm(np.sum(self._moves, axis=0)))
        if self.sigma_adaptive_m is not None:
            var = self.sigma_adaptive_m**2
        else:
            # σ_α² = L·(σ_step² + σ_xy²): the along-track spread of an L-step chord
            var = steps * (self.sigma_step**2 + self.sigma_xy**2)
        if var == 0.0:
            return np.ones(self.n_particles)
        # α_i = exp(−(‖x_i,k − x_i,k−L‖ − D)² / 2σ_α²): our reading of Hu et al. 2021's factor
        return np.exp(-((moved - chord) ** 2) / (2.0 * var))

    def update_adaptive(self, likelihood: ArrayLike) -> None:
        """Measurement update with the weights × likelihood × adaptive factor, normalised."""
        self.adaptive = self.adaptive_factor()
        self.update(np.asarray(likelihood, dtype=float) * self.adaptive)


# ----------------------------------------------------------------------------- WiMag


@dataclass(kw_only=True)
class RegionMagneticMatcher(MagneticSequenceMatcher):
    """Magnetic sequence matching restricted to the windows that end in a region (WiMag ≈).

    With ``region`` None every window competes, as in the parent class; with
    a region (centre, radius) only windows whose end lies within the radius
    of the centre. Without any such window :meth:`match` returns a NaN
    position and an infinite distance.

    Attributes:
        region: the current region, set by the caller before matching.
    """

    region: Region | None = field(default=None, init=False, repr=False, compare=False)

    def distances(self, query_hv: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Distances to the windows in the region (HV-DDTW or MD-DTW) and their end positions."""
        q = self._query(query_hv)
        refs, ends = self.windows(len(q))
        if self.region is not None:
            centre, radius = self.region
            inside = np.flatnonzero(np.linalg.norm(ends - centre, axis=1) <= radius)
            if not len(inside):
                return np.empty(0), np.empty((0, 2))
            refs = refs[inside] if isinstance(refs, np.ndarray) else [refs[i] for i in inside]
            ends = ends[inside]
        return self._dtw(q, refs), ends

    def match(self, query_hv: ArrayLike) -> tuple[NDArray[np.float64], float]:
        """WKNN of the k nearest windows in the region; (NaN, NaN), inf without one."""
        d, ends = self.distances(query_hv)
        if not len(d):
            return np.full(2, np.nan), float("inf")
        return weighted_knn(d, ends, k=self.k), float(d.min())


@dataclass(kw_only=True)
class CoarseRegionTracker(FixTracker):
    """Chen2022's front end with WiMag's coarse-to-fine magnetic matching (module docstring).

    Before each window the magnetic matcher is given the region around the
    latest WiFi fix, carried along by the dead-reckoned steps since; steps of
    one window share the region of its start (≤ two steps of staleness,
    small beside the radius). A step whose query found no window in the
    region has no magnetic fix.

    Attributes:
        magnetic: a :class:`RegionMagneticMatcher` (or None).
        region_radius_m: radius of the region, m.
    """

    magnetic: RegionMagneticMatcher | None = None  # type: ignore[assignment]
    region_radius_m: float = 10.0

    _centre: NDArray[np.float64] | None = field(default=None, **_STATE)

    def reset(self, t0: float, heading: float) -> None:
        super().reset(t0, heading)
        self._centre = None

    @property
    def region(self) -> Region | None:
        """The current region (centre, radius), or None before the first WiFi fix."""
        return None if self._centre is None else (self._centre.copy(), self.region_radius_m)

    def process(self, obs: Observation) -> list[StepFixes]:
        if self.magnetic is not None:
            self.magnetic.region = self.region
        out = []
        for f in super().process(obs):
            if f.magnetic is not None and not np.isfinite(f.magnetic).all():
                f = dataclasses.replace(f, magnetic=None)
            if self._centre is not None:
                h = f.step.heading
                self._centre = self._centre + f.step.length * np.array([np.cos(h), np.sin(h)])
            if f.wifi is not None:
                self._centre = f.wifi.copy()
            out.append(f)
        return out


# ------------------------------------------------------------------------- estimators


@register("edtw-rekf")
@dataclass(kw_only=True)
class EdtwRekf(Chen2022FrontEnd):
    """Approximation of EDTW + REKF (Chen et al. 2021): EDTW and WiFi fixes in a robust EKF.

    Magnetic fixes from :class:`EdtwMatcher`, WiFi fixes from the front end's
    MD-DTW profile matcher, fused per step by :class:`RobustEkf` (fix
    variances and process noises fitted on the training walks). No floor
    plan. See the module docstring for what is published and what is ours.

    Attributes:
        slope_length_m: EDTW's weight of the slope against the value, m.
        innovation_window: M of the innovation covariance estimate.
        ekf: during and after an episode, the filter.
    """

    name: ClassVar[str] = "edtw-rekf"
    needs: ClassVar[tuple[str, ...]] = ("walk survey",)
    uses: ClassVar[tuple[str, ...]] = ("WiFi", "training walks")

    slope_length_m: float = 1.0
    innovation_window: int = 5
    ekf: RobustEkf | None = field(default=None, init=False, repr=False, compare=False)

    def _matchers(self) -> tuple[MagneticSequenceMatcher | None, WifiSequenceMatcher | None]:
        return (
            EdtwMatcher(
                k=self.magnetic_k, slope_length_m=self.slope_length_m, spacing_m=self.spacing_m
            ),
            WifiSequenceMatcher(scans=self.wifi_scans, k=self.wifi_k),
        )

    @property
    def heading(self) -> float:
        """The filter's heading θ, rad counter-clockwise from +x."""
        if self.ekf is None:
            return float(self.dr.heading)
        return float(wrap_angle(self.ekf.x[2]))

    def reset(self, start: StartInfo) -> None:
        self._start(start)
        self.ekf = RobustEkf(
            sigma_step=self.sigma_step_m,
            sigma_heading=self.sigma_heading_rad,
            sigma_xy=self.sigma_xy,
            innovation_window=self.innovation_window,
        )
        self.ekf.initialise(
            start.position,
            start.heading,
            position_std=self.start_spread_m,
            heading_std=self.start_heading_spread_rad,
        )

    def act(self, obs: Observation) -> NDArray[np.float64]:
        if self._position is None or self._tracker is None or self.ekf is None:
            raise not_reset_error(self.name)
        for f in self._tracker.process(obs):
            self.ekf.predict(f.step.length, f.step.delta_heading)
            # Sequential updates (independent fixes): magnetic, then WiFi.
            if f.magnetic is not None:
                self.ekf.update(f.magnetic, self.r_magnetic_m2, "magnetic")
            if f.wifi is not None:
                self.ekf.update(f.wifi, self.r_wifi_m2, "wifi")
            self._position = self.ekf.x[:2].copy()
        return self._position.copy()


@register("apf")
@dataclass(kw_only=True)
class Apf(Chen2022FrontEnd):
    """Approximation of APF (Hu et al. 2021): DR and WiFi fixes in an adaptive particle filter.

    WiFi fixes from :class:`MdedWifiMatcher`; the filter is
    :class:`AdaptiveParticleFilter` on the floor plan (wall-crossing
    particles get weight 0), its adaptive factor multiplied into each WiFi
    update. No magnetic matching (the published method has none). See the
    module docstring for what is published and what is ours.

    Attributes:
        n_particles: particles of the filter.
        ess_threshold: resample when N_eff < ess_threshold·N.
        history_steps: L of the adaptive factor.
        particle_filter: during and after an episode, the filter.
    """

    name: ClassVar[str] = "apf"
    needs: ClassVar[tuple[str, ...]] = ("walk survey", "WiFi")
    uses: ClassVar[tuple[str, ...]] = ("training walks", "floor plan")

    n_particles: int = 1000
    ess_threshold: float = 0.5
    history_steps: int = 5
    particle_filter: AdaptiveParticleFilter | None = field(
        default=None, init=False, repr=False, compare=False
    )

    def _matchers(self) -> tuple[MagneticSequenceMatcher | None, WifiSequenceMatcher | None]:
        return None, MdedWifiMatcher(scans=self.wifi_scans, k=self.wifi_k)

    def reset(self, start: StartInfo) -> None:
        self._start(start)
        self.particle_filter = self._start_particles(
            AdaptiveParticleFilter,
            start,
            n_particles=self.n_particles,
            ess_threshold=self.ess_threshold,
            plan=self._plan,
            history_steps=self.history_steps,
        )

    def act(self, obs: Observation) -> NDArray[np.float64]:
        pf = self.particle_filter
        if self._position is None or self._tracker is None or pf is None or self._rng is None:
            raise not_reset_error(self.name)
        for f in self._tracker.process(obs):
            pf.predict(f.step.length, f.step.delta_heading, self._rng)
            if f.wifi is not None:
                d = np.linalg.norm(pf.x - f.wifi, axis=1)
                pf.update_adaptive(gaussian_likelihood(d, self.r_wifi_m2))
            self._position = pf.estimate()
            pf.resample_if_needed(self._rng)
        return self._position.copy()


@register("wimag")
@dataclass(kw_only=True)
class WiMag(Chen2022FrontEnd):
    """Approximation of WiMag (Guo et al. 2016): WiFi region, magnetic fix in it, mode-switching PF.

    The front end is :class:`CoarseRegionTracker` (WiFi fix → region →
    :class:`RegionMagneticMatcher`); each step the particle filter takes the
    magnetic likelihood if there is a magnetic fix in the region, else the
    WiFi likelihood if there is a WiFi fix, else only the prediction
    (``modes`` counts the choices). See the module docstring for what is
    published (very little) and what is ours.

    Attributes:
        matcher: magnetic sequence distance, ``"md-dtw"`` or ``"hv-ddtw"``.
        region_sigmas: region radius in RMS WiFi-fix errors.
        min_region_m: smallest region radius, m.
        use_plan: apply the floor plan's wall rule in the particle filter.
        n_particles: particles of the filter.
        ess_threshold: resample when N_eff < ess_threshold·N.
        region_radius_m: after ``fit``, the region radius, m.
        modes: during and after an episode, steps per fusion mode.
        particle_filter: during and after an episode, the filter.
    """

    name: ClassVar[str] = "wimag"
    needs: ClassVar[tuple[str, ...]] = ("walk survey",)
    uses: ClassVar[tuple[str, ...]] = ("WiFi", "training walks")

    matcher: Literal["md-dtw", "hv-ddtw"] = "md-dtw"
    region_sigmas: float = 2.0
    min_region_m: float = 5.0
    use_plan: bool = False
    n_particles: int = 1000
    ess_threshold: float = 0.5
    region_radius_m: float = field(default=0.0, init=False)
    modes: dict[str, int] = field(default_factory=dict, init=False, repr=False, compare=False)
    particle_filter: ParticleFilter | None = field(
        default=None, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.region_sigmas <= 0 or self.min_region_m <= 0:
            raise ValueError("need region_sigmas > 0 and min_region_m > 0")
        self.region_radius_m = self._radius(DEFAULT_R_WIFI_M2)

    def _matchers(self) -> tuple[MagneticSequenceMatcher | None, WifiSequenceMatcher | None]:
        return (
            RegionMagneticMatcher(matcher=self.matcher, k=self.magnetic_k),
            WifiSequenceMatcher(scans=self.wifi_scans, k=self.wifi_k),
        )

    def _radius(self, r_wifi_m2: float) -> float:
        # RMS distance error of an isotropic 2-D fix of per-axis variance R: √(2R).
        return max(self.region_sigmas * float(np.sqrt(2.0 * r_wifi_m2)), self.min_region_m)

    def _new_tracker(
        self,
        magnetic: MagneticSequenceMatcher | None,
        wifi: WifiSequenceMatcher | None,
        gravity_alpha: float,
    ) -> FixTracker:
        assert magnetic is None or isinstance(magnetic, RegionMagneticMatcher)
        self.region_radius_m = self._radius(DEFAULT_R_WIFI_M2)
        return CoarseRegionTracker(
            **self._tracker_options(magnetic, wifi, gravity_alpha),
            region_radius_m=self.region_radius_m,
        )

    def _calibrate_noise(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """WiFi R and noises first (they set the region), then R of the region-restricted fixes."""
        tracker = self._tracker
        assert isinstance(tracker, CoarseRegionTracker)
        wifi_only = copy.copy(tracker)
        wifi_only.magnetic = None
        e = replay_errors(wifi_only, self.dr, site, train)
        self._set_noise(e.step_length_m, e.heading_walk_rad)
        self.r_wifi_m2 = fix_variance_m2(e.wifi_m, self.r_wifi_m2)
        self.region_radius_m = tracker.region_radius_m = self._radius(self.r_wifi_m2)
        if tracker.magnetic is not None:
            e = replay_errors(tracker, self.dr, site, train)
            self.r_magnetic_m2 = fix_variance_m2(e.magnetic_m, self.r_magnetic_m2)

    def reset(self, start: StartInfo) -> None:
        self._start(start)
        self.particle_filter = self._start_particles(
            ParticleFilter,
            start,
            n_particles=self.n_particles,
            ess_threshold=self.ess_threshold,
            plan=self._plan if self.use_plan else None,
        )
        self.modes = {"magnetic": 0, "wifi": 0, "dr": 0}

    def select(self, f: StepFixes) -> tuple[str, NDArray[np.float64] | None, float]:
        """The step's fusion mode, its fix and the fix's R (class docstring)."""
        if f.magnetic is not None:
            return "magnetic", f.magnetic, self.r_magnetic_m2
        if f.wifi is not None:
            return "wifi", f.wifi, self.r_wifi_m2
        return "dr", None, 0.0

    def act(self, obs: Observation) -> NDArray[np.float64]:
        pf = self.particle_filter
        if self._position is None or self._tracker is None or pf is None or self._rng is None:
            raise not_reset_error(self.name)
        for f in self._tracker.process(obs):
            pf.predict(f.step.length, f.step.delta_heading, self._rng)
            mode, z, r = self.select(f)
            self.modes[mode] += 1
            if z is not None:
                pf.update(gaussian_likelihood(np.linalg.norm(pf.x - z, axis=1), r))
            self._position = pf.estimate()
            pf.resample_if_needed(self._rng)
        return self._position.copy()
