"""Particle filter for pedestrian positioning with wall constraints (Chen2022 Eq. 25–28).

Each particle is a position and a walking direction; the arrays hold all N
particles at once (``x`` (N, 2), ``heading`` (N,), ``w`` (N,)) and every
operation is vectorised over them. One filter step is

1. :meth:`ParticleFilter.predict` — move every particle by the detected step
   (Eq. 25) and give zero weight to those whose move passes through a wall
   (one ``plan.crosses_wall`` call for all particles);
2. :meth:`ParticleFilter.update` — multiply the weights by the measurement
   likelihood (Eq. 27–28: the caller forms the product of the WiFi and
   magnetic factors, e.g. with :func:`gaussian_likelihood`);
3. :meth:`ParticleFilter.estimate` — the weighted mean position;
4. :meth:`ParticleFilter.resample_if_needed` — systematic resampling when the
   effective sample size falls below a fraction of N.

Frames: Chen2022 measures the heading φ from north, clockwise, and moves by
x ← x + SL·sin φ, y ← y + SL·cos φ (Eq. 25). indoorsim's building frame
measures headings θ counter-clockwise from +x (DESIGN §2). The filter accepts
and stores building-frame headings; :meth:`ParticleFilter.predict` converts to
the paper's φ = π/2 − θ (so Δφ = −Δθ), applies Eq. 25 as printed, and converts
back. A building heading of 0 therefore moves a particle along +x.

Readings taken where the paper is silent or loose (PAPER_NOTES, Chen2022 item 6):

* Eq. 27 is exp(−‖z − x‖) with no square and no R: :func:`literal_likelihood`,
  the pipeline's default; the Gaussian exp(−d²/2R) is
  :func:`gaussian_likelihood`. Eq. 27's prefactor 1/(√‖R‖·√2π) is the same for
  every particle and cancels when the weights are normalised, so it is left out.
* Step-length noise (``sigma_step``) is added to the paper's G_φ, G_x, G_y.
* Degenerate weights are handled explicitly, never by dividing by zero:
  if every particle that carries weight crosses a wall, the move is undone
  (positions return to where they were, headings keep the turn, weights are
  unchanged: the pedestrian cannot have walked through the wall, so the step
  is taken as blocked); if a measurement gives zero likelihood to every remaining
  particle (e.g. a fingerprint fix tens of metres away underflows
  exp(−d²/2R)), the measurement is ignored and the weights are kept.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.frames import wrap_angle

__all__ = [
    "LikelihoodFn",
    "ParticleFilter",
    "PlanLike",
    "effective_sample_size",
    "gaussian_likelihood",
    "literal_likelihood",
    "systematic_resample",
]

LikelihoodFn = Callable[[NDArray[np.float64]], NDArray[np.float64]]
"""Measurement likelihood at particle positions: (N, 2) positions → (N,) non-negative values."""


class PlanLike(Protocol):
    """What the filters need from a floor plan (``SiteContext.plan`` provides it)."""

    def crosses_wall(self, p0: ArrayLike, p1: ArrayLike) -> NDArray[np.bool_]:
        """(N,) True where the straight move p0[i] → p1[i] passes through something solid."""
        ...

    def is_walkable(self, points: ArrayLike) -> NDArray[np.bool_]:
        """(N,) True where a point is free floor inside the building."""
        ...


def gaussian_likelihood(d: ArrayLike, R: float) -> NDArray[np.float64]:
    """Gaussian likelihood of a position fix at distances d, exp(−d²/2R) (Eq. 27, an option).

    With d = ‖z − x‖ this is the density of an isotropic 2-D Gaussian fix
    z ~ N(x, R·I) up to a constant factor.

    Args:
        d: (N,) distances between the fix and each particle, m.
        R: the fix's variance per axis, m².

    Returns:
        (N,) likelihoods in (0, 1].

    >>> gaussian_likelihood([0.0, 2.0], R=2.0).round(4).tolist()
    [1.0, 0.3679]
    """
    d = np.asarray(d, dtype=float)
    return np.exp(-(d**2) / (2.0 * R))


def literal_likelihood(d: ArrayLike) -> NDArray[np.float64]:
    """Eq. 27 as printed, exp(−d): no square, no R (the default; see the module docstring).

    Args:
        d: (N,) distances between the fix and each particle, m.

    Returns:
        (N,) likelihoods in (0, 1].
    """
    return np.exp(-np.asarray(d, dtype=float))


def effective_sample_size(w: ArrayLike) -> float:
    """N_eff = 1 / Σ w_i² of normalised weights (N for uniform weights, 1 for a single particle)."""
    w = np.asarray(w, dtype=float)
    return float(1.0 / np.dot(w, w))


def systematic_resample(w: ArrayLike, rng: np.random.Generator) -> NDArray[np.intp]:
    """Ancestor indices drawn by systematic resampling.

    One uniform offset u ~ U[0, 1) places N evenly spaced pointers
    (u + i)/N, i = 0…N−1, on the cumulative weights; particle j is copied once
    for each pointer falling in its slice of the cumulative sum. Zero-weight
    particles have empty slices and are never chosen.

    Args:
        w: (N,) normalised weights.
        rng: the random generator.

    Returns:
        (N,) indices into the particles, non-decreasing.
    """
    w = np.asarray(w, dtype=float)
    n = len(w)
    pointers = (rng.random() + np.arange(n)) / n
    cumulative = np.cumsum(w)
    cumulative[-1] = 1.0  # round-off must not leave the last pointers beyond the end
    return np.searchsorted(cumulative, pointers, side="right")


@dataclass(kw_only=True)
class ParticleFilter:
    """Bootstrap particle filter on (x, y, heading) driven by detected steps (Chen2022 Eq. 25–28).

    State (all vectorised over the N particles):

    * ``x`` (N, 2) positions, m; ``heading`` (N,) building-frame headings, rad
      counter-clockwise from +x; ``w`` (N,) normalised weights.
    * ``crossed`` (N,) True where the particle's track has passed through a
      wall: in the last predicted move, or earlier without the particle having
      been resampled away since (its weight is 0 either way).

    Kept for diagnosis (filterpy style): ``x_prior`` and ``w_prior``, the
    positions and weights entering the last :meth:`predict`; ``likelihood``,
    the last measurement likelihood; ``ancestors``, the indices chosen by the
    last resampling. They describe the particles as indexed before that
    resampling.

    Attributes:
        n_particles: N.
        sigma_heading: std of the heading noise G_φ added per step, rad.
        sigma_step: std of the step-length noise added per step, m.
        sigma_xy: std of the position noises G_x, G_y added per step, m.
        ess_threshold: resample when the effective sample size falls below
            ``ess_threshold·N`` (1.0 resamples after nearly every update, 0
            never).
        plan: a floor plan offering ``crosses_wall`` and ``is_walkable``
            (:class:`PlanLike`); ``None`` for no wall constraint.

    Example:
        >>> pf = ParticleFilter(n_particles=500, sigma_heading=0.0, sigma_step=0.0, sigma_xy=0.0)
        >>> rng = np.random.default_rng(0)
        >>> pf.initialise([0.0, 0.0], heading=0.0, spread=0.0, rng=rng)
        >>> pf.predict(step_length=0.7, delta_heading=0.0, rng=rng)
        >>> pf.estimate().round(6).tolist()
        [0.7, 0.0]
    """

    n_particles: int = 1000
    sigma_heading: float = 0.05
    sigma_step: float = 0.05
    sigma_xy: float = 0.1
    ess_threshold: float = 0.5
    plan: PlanLike | None = None

    x: NDArray[np.float64] = field(
        default_factory=lambda: np.empty((0, 2)), init=False, repr=False, compare=False
    )
    heading: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    w: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    crossed: NDArray[np.bool_] = field(
        default_factory=lambda: np.empty(0, dtype=bool), init=False, repr=False, compare=False
    )
    x_prior: NDArray[np.float64] = field(
        default_factory=lambda: np.empty((0, 2)), init=False, repr=False, compare=False
    )
    w_prior: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    likelihood: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    ancestors: NDArray[np.intp] = field(
        default_factory=lambda: np.empty(0, dtype=np.intp), init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        if self.n_particles < 1:
            raise ValueError(f"n_particles must be ≥ 1, got {self.n_particles}")
        for name in ("sigma_heading", "sigma_step", "sigma_xy"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be ≥ 0, got {getattr(self, name)}")
        if not 0.0 <= self.ess_threshold <= 1.0:
            raise ValueError(f"ess_threshold must be in [0, 1], got {self.ess_threshold}")

    # ------------------------------------------------------------------ filter

    def initialise(
        self,
        position: ArrayLike,
        heading: float,
        spread: float,
        rng: np.random.Generator,
        *,
        heading_spread: float = 0.0,
    ) -> None:
        """Draw the particles around a known start, with equal weights.

        Positions are N(position, spread²·I), headings N(heading,
        heading_spread²). With a plan, particles drawn off the walkable floor
        or behind a wall as seen from ``position`` (in the next room) are
        replaced by copies of randomly chosen good ones; if none is good (a
        start inside a wall), the draw is kept as it is.

        Args:
            position: (2,) start position, m.
            heading: start heading, building frame, rad counter-clockwise from +x.
            spread: std of the position scatter, m.
            rng: the random generator.
            heading_spread: std of the heading scatter, rad.
        """
        n = self.n_particles
        x = np.asarray(position, dtype=float)[None, :] + spread * rng.standard_normal((n, 2))
        if self.plan is not None:
            start = np.broadcast_to(np.asarray(position, dtype=float), x.shape)
            ok = self.plan.is_walkable(x) & ~self.plan.crosses_wall(start, x)
            if ok.any() and not ok.all():
                x[~ok] = x[rng.choice(np.flatnonzero(ok), size=int((~ok).sum()))]
        self.x = x
        self.heading = wrap_angle(heading + heading_spread * rng.standard_normal(n))
        self.w = np.full(n, 1.0 / n)
        self.crossed = np.zeros(n, dtype=bool)
        self.x_prior = x.copy()
        self.w_prior = self.w.copy()
        self.likelihood = np.ones(n)
        self.ancestors = np.arange(n)

    def predict(self, step_length: float, delta_heading: float, rng: np.random.Generator) -> None:
        """Move every particle by one detected step (Eq. 25) and apply the wall rule.

        Args:
            step_length: SL, the detected step's length, m.
            delta_heading: the heading change since the last step, building
                frame (counter-clockwise positive), rad.
            rng: the random generator.
        """
        n = self.n_particles
        self.x_prior = self.x
        self.w_prior = self.w
        crossed_before = self.crossed
        # Building heading θ (from +x, counter-clockwise) → paper heading φ (from north, clockwise).
        phi = np.pi / 2 - self.heading
        # (25a) φ(k) = φ(k−1) + Δφ + G_φ, with Δφ = −Δθ
        phi = phi - delta_heading + self.sigma_heading * rng.standard_normal(n)
        sl = step_length + self.sigma_step * rng.standard_normal(n)
        g = self.sigma_xy * rng.standard_normal((n, 2))
        x = np.empty_like(self.x_prior)
        # (25b) x(k) = x(k−1) + SL·sin φ(k) + G_x
        x[:, 0] = self.x_prior[:, 0] + sl * np.sin(phi) + g[:, 0]
        # (25c) y(k) = y(k−1) + SL·cos φ(k) + G_y
        x[:, 1] = self.x_prior[:, 1] + sl * np.cos(phi) + g[:, 1]
        self.heading = wrap_angle(np.pi / 2 - phi)
        self.x = x

        if self.plan is None:
            return
        self.crossed = crossed_before | self.plan.crosses_wall(self.x_prior, self.x)
        # A move through a wall is impossible: weight 0 (Yu et al. 2017, as Chen2022 cites).
        w = np.where(self.crossed, 0.0, self.w_prior)
        total = w.sum()
        if total > 0:
            self.w = w / total
        else:
            # Every weighted particle walked into a wall: the step was blocked.
            self.x = self.x_prior
            self.crossed = crossed_before

    def update(self, likelihood: ArrayLike) -> None:
        """Multiply the weights by a measurement likelihood and normalise (Eq. 28: q = q_WiFi·q_MM).

        Args:
            likelihood: (N,) non-negative likelihood of the measurement at each
                particle, e.g. ``gaussian_likelihood(d_wifi, R) *
                gaussian_likelihood(d_mm, R)``.
        """
        self.likelihood = np.asarray(likelihood, dtype=float)
        w = self.w * self.likelihood
        total = w.sum()
        if total == 0:
            # The measurement is incompatible with every particle: ignore it.
            return
        self.w = w / total

    def estimate(self) -> NDArray[np.float64]:
        """(2,) the weighted mean position Σ w_i·x_i, m."""
        return self.w @ self.x

    @property
    def neff(self) -> float:
        """The effective sample size 1/Σ w_i² of the current weights."""
        return effective_sample_size(self.w)

    def resample(self, rng: np.random.Generator) -> None:
        """Systematic resampling: copy particles in proportion to their weights, then w = 1/N."""
        idx = systematic_resample(self.w, rng)
        self.ancestors = idx
        self.x = self.x[idx]
        self.heading = self.heading[idx]
        self.crossed = self.crossed[idx]
        self.w = np.full(self.n_particles, 1.0 / self.n_particles)

    def resample_if_needed(self, rng: np.random.Generator) -> bool:
        """Resample when N_eff < ``ess_threshold``·N.

        Returns:
            True if the particles were resampled.
        """
        if self.neff < self.ess_threshold * self.n_particles:
            self.resample(rng)
            return True
        return False

    def step(
        self,
        step_length: float,
        delta_heading: float,
        likelihood_fn: LikelihoodFn,
        rng: np.random.Generator,
    ) -> NDArray[np.float64]:
        """One whole filter step: predict, update, estimate, resample if needed.

        Args:
            step_length: SL, m.
            delta_heading: building-frame heading change since the last step, rad.
            likelihood_fn: (N, 2) positions → (N,) likelihood of this step's
                measurements (the product of Eq. 27's factors).
            rng: the random generator.

        Returns:
            (2,) the weighted mean position after the update and :meth:`refine`
            (before resampling, which only adds noise to it).
        """
        self.predict(step_length, delta_heading, rng)
        self.update(likelihood_fn(self.x))
        self.refine(likelihood_fn, rng)
        position = self.estimate()
        self.resample_if_needed(rng)
        return position

    def refine(self, likelihood_fn: LikelihoodFn, rng: np.random.Generator) -> None:
        """Move or re-weight the particles between update and estimate; nothing for the PF.

        The chicken particle filter's swarm goes here.
        """
