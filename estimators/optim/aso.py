"""Atom Search Optimization (Zhao, Wang & Zhang 2019; Han2023 §3.2, Eq. 22–29).

Atoms are candidate solutions. Each feels a Lennard-Jones-like interaction
force from the K(t) best atoms (repulsive when close, attractive further out)
and a constraint force pulling it to the best atom found so far; light atoms
(poor fitness) accelerate most. The whole population moves at once and the
objective is called once per iteration with the whole population, so an
objective that evaluates a batch in one pass (the population-batched
Tent-ASO-BP of :mod:`indoorsim.estimators.nn.bp`) pays no per-atom cost.

Reference: Zhao, Wang & Zhang, *Knowledge-Based Systems* 163 (2019) 283–304.
This follows the authors' MATLAB code (``ASO.m``, ``Acceleration.m``,
``LJPotential.m``, MATLAB File Exchange 67011, mirrored on GitHub) where the
paper's text and the code differ, and says so:

* **Force** (Han2023 Eq. 22, whose "h³" is a typo for h¹³). Zhao's text
  prints −η(t)[2h¹³ − h⁷] with h = r/σ ≥ h_min > 1, which never changes
  sign, so atoms could not switch from repulsion to attraction. The code uses
  the Lennard-Jones derivative, F_ij = −c(t)·[12h⁻¹³ − 6h⁻⁷], which is zero at
  h = 2^(1/6) ≈ 1.12, between h_min and h_max: repulsive below, attractive
  above. That is what is implemented, with c(t) = (1 − (t−1)/T)³ here and
  α·e^(−20t/T) applied with the constraint force below, so that
  η(t) = α(1 − (t−1)/T)³e^(−20t/T) as in the text.
* **h clamping** (Eq. 23, ``LJPotential.m``): h = r_ij/σ clamped to [h_min, h_max] with
  h_min = g₀ + 0.1·sin(πt/2T), g₀ = 1.1, and h_max = u = 1.24.
* **Length scale** σ(t) (``Acceleration.m``): the distance from atom i to the mean
  position of the K(t) best atoms.
* **K(t)** = ⌊N − (N − 2)√(t/T)⌋ + 1 best atoms (the code's rounding), at most N.
* **Constraint force** (Eq. 25; Han2023's Eq. 22 and 25 swap the names α and β):
  λ(t)(x_best − x_i) with λ(t) = β·e^(−20t/T).
* **Masses** (Eq. 26–27): M_i = exp(−(f_i − f_best)/(f_worst − f_best)),
  m_i = M_i/ΣM_j. Han2023's Eq. 26 labels best and worst the other way round,
  which would make the best atoms the lightest; the code's form
  exp(−(f_i − f_worst)/(f_worst − f_best)) differs from Zhao's by a constant
  factor that Eq. 27 cancels. If all fitnesses are equal the masses are equal.
* **Motion** (Eq. 28–29): a_i = (F_i + G_i)/m_i, v ← rand⊙v + a, x ← x + v,
  with per-coordinate uniform random numbers; a coordinate that leaves the
  bounds is redrawn uniformly inside them. Initial velocities are drawn
  uniformly in the bounds, as in the code.
* **Elitism**: after an iteration without improvement, a random atom is
  replaced by the best atom. The code leaves that atom's old fitness in the
  mass computation; here it takes the best fitness with the position.

Defaults α = 50, β = 0.2 (PAPER_NOTES, Han2023 item 7; mealpy's example uses
the same values).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.optim.tent import tent_population

__all__ = ["ASO", "AsoResult", "Objective"]

Objective = Callable[[NDArray[np.float64]], NDArray[np.float64]]
"""A population objective: (P, D) positions → (P,) fitness values to minimise."""

_G0 = 1.1
"""g₀ of h_min(t) = g₀ + 0.1·sin(πt/2T) (``LJPotential.m``)."""
_H_MAX = 1.24
"""u = h_max (``LJPotential.m``)."""
_EPS = float(np.finfo(float).eps)


@dataclass(frozen=True, kw_only=True)
class AsoResult:
    """The outcome of one ASO run.

    Attributes:
        x: (D,) best position found.
        fitness: its objective value.
        convergence: (iterations,) best fitness so far after each iteration
            (the initial population counts as iteration 1), for Han2023 Fig. 14.
        evaluations: objective values computed (population × iterations).
    """

    x: NDArray[np.float64]
    fitness: float
    convergence: NDArray[np.float64]
    evaluations: int


@dataclass(kw_only=True)
class ASO:
    """Atom Search Optimization, vectorised over the population (see the module docstring).

    Attributes:
        population: atoms N (Han2023: 30).
        iterations: iterations T, the initial population included (Han2023: 500).
        alpha: depth weight α of the interaction force.
        beta: multiplier weight β of the constraint force.
        tent_init: draw the initial positions from tent-map orbits
            (:func:`~indoorsim.estimators.optim.tent.tent_population`, Han2023
            §3.3) instead of uniformly.

    >>> aso = ASO(population=20, iterations=100)
    >>> res = aso.minimize(lambda x: (x**2).sum(axis=1), [-5.0] * 3, [5.0] * 3,
    ...                    np.random.default_rng(0))
    >>> res.evaluations, bool(res.fitness < 1e-2)
    (2000, True)
    """

    population: int = 30
    iterations: int = 500
    alpha: float = 50.0
    beta: float = 0.2
    tent_init: bool = False

    def __post_init__(self) -> None:
        if self.population < 2:
            raise ValueError(f"population must be ≥ 2, got {self.population}")
        if self.iterations < 1:
            raise ValueError(f"iterations must be ≥ 1, got {self.iterations}")

    def minimize(
        self,
        objective: Objective,
        lower: ArrayLike,
        upper: ArrayLike,
        rng: np.random.Generator,
    ) -> AsoResult:
        """Minimise ``objective`` inside the box [lower, upper].

        Args:
            objective: called once per iteration with all (N, D) positions,
                returns (N,) finite fitness values.
            lower: (D,) lower bounds.
            upper: (D,) upper bounds.
            rng: the seeded generator for every random number of the run.

        Returns:
            The best position, its fitness and the convergence curve.
        """
        lo, hi = np.broadcast_arrays(
            np.atleast_1d(np.asarray(lower, dtype=float)),
            np.atleast_1d(np.asarray(upper, dtype=float)),
        )
        if lo.ndim != 1 or not (hi > lo).all():
            raise ValueError(f"need 1-D bounds with upper > lower, got {lo} and {hi}")
        n, big_t = self.population, self.iterations
        shape = (n, lo.size)

        if self.tent_init:
            x = tent_population(n, lo, hi, rng)
        else:
            x = rng.uniform(lo, hi, shape)
        v = rng.uniform(lo, hi, shape)
        fit = _evaluate(objective, x)
        i_best = int(np.argmin(fit))
        x_best, f_best = x[i_best].copy(), float(fit[i_best])
        curve = np.empty(big_t)
        curve[0] = f_best

        for t in range(2, big_t + 1):
            a = self._acceleration(x, fit, x_best, t - 1, rng)
            # Eq. 29
            v = rng.random(shape) * v + a
            x = x + v
            outside = (x < lo) | (x > hi)
            x = np.where(outside, rng.uniform(lo, hi, shape), x)
            fit = _evaluate(objective, x)
            i = int(np.argmin(fit))
            if fit[i] < f_best:
                x_best, f_best = x[i].copy(), float(fit[i])
            else:
                r = int(rng.integers(n))
                x[r], fit[r] = x_best, f_best
            curve[t - 1] = f_best
        return AsoResult(x=x_best, fitness=f_best, convergence=curve, evaluations=n * big_t)

    def _acceleration(
        self,
        x: NDArray[np.float64],
        fit: NDArray[np.float64],
        x_best: NDArray[np.float64],
        t: int,
        rng: np.random.Generator,
    ) -> NDArray[np.float64]:
        """Accelerations (N, D) of all atoms at iteration t (Eq. 22–28)."""
        n, big_t = self.population, self.iterations
        m = _masses(fit)
        k = min(n, math.floor(n - (n - 2) * math.sqrt(t / big_t)) + 1)
        kbest = np.argsort(fit, kind="stable")[:k]

        # σ(t), the distance to the mean of the K best atoms (Acceleration.m)
        sigma = np.linalg.norm(x - x[kbest].mean(axis=0), axis=1)
        diff = x[None, kbest, :] - x[:, None, :]  # (N, K, D): x_j − x_i
        r = np.linalg.norm(diff, axis=2)
        ratio = np.divide(r, sigma[:, None], out=np.full_like(r, np.inf), where=sigma[:, None] > 0)
        # Eq. 23
        h = np.clip(ratio, _G0 + 0.1 * math.sin(math.pi * t / (2 * big_t)), _H_MAX)
        # Eq. 22, the Lennard-Jones derivative of the authors' code (module docstring)
        c = (1.0 - (t - 1) / big_t) ** 3
        potential = -c * (12.0 * h**-13 - 6.0 * h**-7)
        unit = diff / (r[..., None] + _EPS)
        # Eq. 24
        f = np.sum(rng.random(diff.shape) * potential[..., None] * unit, axis=1)
        # Eq. 25, and the e^(−20t/T) shared with η(t)
        decay = math.exp(-20.0 * t / big_t)
        force = decay * (self.alpha * f + self.beta * (x_best - x))
        # Eq. 28
        return force / m[:, None]


def _masses(fit: NDArray[np.float64]) -> NDArray[np.float64]:
    """Normalised masses (Eq. 26–27): the best atom is heaviest."""
    spread = fit.max() - fit.min()
    if spread == 0.0:
        return np.full(fit.shape, 1.0 / fit.size)
    # Eq. 26
    big_m = np.exp(-(fit - fit.min()) / spread)
    # Eq. 27
    return big_m / big_m.sum()


def _evaluate(objective: Objective, x: NDArray[np.float64]) -> NDArray[np.float64]:
    fit = np.asarray(objective(x), dtype=float)
    if fit.shape != (len(x),):
        raise ValueError(f"the objective must return ({len(x)},) values, got shape {fit.shape}")
    if not np.isfinite(fit).all():
        raise ValueError("the objective returned non-finite values")
    return fit
