"""Chicken particle filter: chicken swarm moves between update and resampling (Chen2022 Eq. 29–31).

After the particle filter's predict and update, the particles are sorted into
a chicken swarm (Meng et al. 2014, "A new bio-inspired algorithm: chicken
swarm optimization"), moved once by the swarm's rules, re-weighted at their
new positions and resampled:

* chicks: the particles whose track crossed a wall (``crossed``: in this
  step's move, or earlier without having been resampled away);
* roosters: the others whose weight exceeds T = 0.75·(max q − min q) + min q
  (Eq. 29), the max and min taken over the non-chicks;
* hens: the rest.

Readings (PAPER_NOTES, Chen2022 item 7). Where the paper prints a formula it
is the default (issue 18); the alternatives are named options. Measured
effects: ``indoorsim.benchmark.evaluation.evaluate("chen2022-cpf", ...)`` on
chen2022_lab and chen2022_office, the mean error over the four carrying modes,
seeds 0–2 (0–9 in brackets), with the Gaussian likelihood of Eq. 27 unless
said otherwise.

* Fitness (Eq. 30b, 31b–c). Printed (default, ``fitness="weight"``): the
  particle weight is the fitness, higher is better, as f = q/max q (the max
  over the non-chicks) so that Eq. 31c's exp(f_mea2 − f_i), which is not
  scale-free, does not depend on how the weights are normalised. A heavy
  rooster then gets σ² < 1, and s1 = exp((f_i − f_mea1)/f_i) → 0 leaves the
  lightest hens to contract toward the hens' mean. ``fitness="cost"``: CSO's
  minimisation sense, f = 1 − q/max q: the heavier of two roosters scatters
  widest (σ² = 1) and s1 ∈ [1, e) pulls the lightest hens hardest toward the
  roosters' mean, overshooting it when s1·rand > 1 — closer to §4's prose
  ("high-quality pedestrian position information is transferred from
  high-quality particles to small-weight ones") than to its equations.
  Effect of the sense alone (both with ``rooster_spread="cso"``): lab
  1.59 → 1.02 m (1.55 → 0.99), office 4.78 → 1.75 m (4.19 → 1.83); with the
  literal likelihood lab 1.96 → 1.26 m, office 5.00 → 2.80 m.
* Roosters' spread (Eq. 30b). Printed (default, ``rooster_spread="printed"``):
  σ² = 1 if f_i ≤ f_k for a random other rooster k, else
  exp((f_mea − f_i)/(f_i + ε)), where f_mea — the paper's q_mea, "the average
  weight" — is the mean of f over all N particles, chicks included with their
  weight 0: Eq. 30b names no flock, unlike Eq. 31's q_mea1 and q_mea2, and a
  filter's average weight is over its particles. With normalised weights
  f_mea = 1/(N·max q): 1 for flat weights, small for a peaked cloud, so the
  heavier rooster of a pair scatters less the more the measurement
  discriminates. A rooster has f > 0.75 (Eq. 29), so σ² ∈ (e⁻¹, e^{1/3}).
  ``rooster_spread="cso"`` (Meng et al. 2014): the rival's f_k in place of
  q_mea, σ² = exp(min(f_k − f_i, 0)/(|f_i| + ε)) ∈ (e⁻¹, 1]. The printed
  form needs the weight sense (validated): with a cost, a heavy rooster's
  f_i → 0 and exp((f_mea − f_i)/f_i) is unbounded. Effect (weight sense,
  cso → printed): lab 1.02 → 0.93 m (0.99 → 0.94), office 1.75 → 1.75 m
  (1.83 → 1.68); with the literal likelihood lab 1.26 → 1.29 m
  (1.25 → 1.19), office 2.80 → 2.90 m (2.36 → 2.36): small beside the
  spread between modes. Together, old (cost, cso) → new defaults: lab
  1.59 → 0.93 m, office 4.78 → 1.75 m; the plain PF does 1.05 and 1.91 m.
  With the literal likelihood, exp(−d) with its 1 m scale, the CPF stays
  behind the PF (lab 1.29 vs 1.06 m, office 2.90 vs 1.90 m; dangling worst).
* Where roosters move (Eq. 30a). X·(1 + N(0, σ²)) on absolute coordinates
  scatters a particle by metres times its coordinates, so it depends on
  where the origin is. It is applied to the rooster's offset from the
  weighted mean m̄: X ← m̄ + (X − m̄)·(1 + N(0, σ²)), per coordinate.
* Hens (Eq. 31). ``hen_targets="means"`` (default, as printed): each hen is
  pulled toward the roosters' mean and the hens' mean, with s1, s2 from the
  mean fitness of those flocks. ``hen_targets="cso"`` (Meng et al. 2014's
  Eq. 23): toward its group's rooster — drawn at random, as groups are
  reformed at every filter step — and a random other rooster or hen. The two
  uniform factors are one scalar per hen and term (Meng's code). s1 and s2
  are bounded: s1 ≤ 1 and s2 ∈ (e⁻¹, e) in the weight sense.
* Chicks (Eq. 24). Each follows a random hen, its mother, by
  FL ~ U(0.5, 0.9) per chick (Meng et al. 2014). A chick stands beyond the
  wall it walked through, so its new place is accepted only if the straight
  line from its mother to it crosses no wall; otherwise it stays a chick with
  weight 0 and resampling removes it.
* Any rooster or hen move that would cross a wall is rejected (the particle
  stays). The swarm moves positions only; headings are untouched.
* Re-weighting: the weights that entered the step times the likelihood at
  the new positions (replacing the update's factor, not compounding it).
* When all non-chick weights are equal there is no pecking order: no
  roosters, and hens stay where they are; chicks still follow hens.

Behaviour to expect: the swarm moves particles toward high likelihood and
then weights them by that same likelihood, so each measurement is used twice
and the CPF is no longer a Bayes filter. On a linear-Gaussian walk (N = 1000,
40 seeds) its RMS error is 1.15× the Kalman filter's (the PF's equals it;
``fitness="cost"``: 1.48×); with accurate steps and 1.5–2 m fixes
(``benchmarks/bench_particle_filter.py``'s walk) 0.43 m against the PF's
0.38 m (``fitness="cost"``: 0.99 m). The cost sense homes in on a fixed
target far faster than the PF; the printed reading does not.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.filters.particle import LikelihoodFn, ParticleFilter

__all__ = ["CHICK", "HEN", "ROOSTER", "ChickenParticleFilter", "classify"]

ROOSTER, HEN, CHICK = 0, 1, 2

# CSO's small constant ε guarding |f_i| = 0 (a hen whose likelihood underflowed).
_EPS = np.finfo(float).eps


def classify(
    w: ArrayLike, crossed: ArrayLike, threshold_fraction: float = 0.75
) -> NDArray[np.int8]:
    """Sort particles into roosters, hens and chicks (Eq. 29).

    Args:
        w: (N,) particle weights.
        crossed: (N,) True where the particle's track crossed a wall.
        threshold_fraction: the 0.75 of Eq. 29.

    Returns:
        (N,) roles: :data:`ROOSTER`, :data:`HEN` or :data:`CHICK`.

    >>> classify([0.1, 0.2, 0.9, 1.0, 0.5], [False, False, False, False, True]).tolist()
    [1, 1, 0, 0, 2]
    """
    w = np.asarray(w, dtype=float)
    crossed = np.asarray(crossed, dtype=bool)
    roles = np.full(len(w), HEN, dtype=np.int8)
    roles[crossed] = CHICK
    q = w[~crossed]
    if q.size:
        # (29) T = (max(q) − min(q))·0.75 + min(q), over the particles that did not cross a wall
        threshold = (q.max() - q.min()) * threshold_fraction + q.min()
        roles[~crossed & (w > threshold)] = ROOSTER
    return roles


@dataclass(kw_only=True)
class ChickenParticleFilter(ParticleFilter):
    """Particle filter whose particles move as a chicken swarm before resampling (Chen2022 CPF).

    A step is :meth:`predict` (Eq. 25, wall rule), :meth:`update` (Eq. 27–28),
    :meth:`swarm` (Eq. 29–31 and 24, re-weighting) and resampling. The
    defaults are the paper's printed readings; the module docstring gives
    each alternative, why it exists and its measured effect. ``roles`` keeps
    the last swarm's classification for diagnosis.

    Attributes:
        threshold_fraction: the 0.75 of Eq. 29.
        fl_range: the range of the chicks' following factor FL.
        hen_targets: ``"means"`` (printed, Eq. 31: roosters' and hens' means)
            or ``"cso"`` (Meng et al. 2014: a random rooster and a random
            other chicken).
        fitness: ``"weight"`` (printed, Eq. 30b–31c: f = q/max q, higher is
            better) or ``"cost"`` (CSO's minimisation sense, f = 1 − q/max q).
        rooster_spread: ``"printed"`` (Eq. 30b: σ² from q_mea, the mean
            fitness of all particles; needs ``fitness="weight"``) or
            ``"cso"`` (Meng et al. 2014: σ² from the rival rooster's f_k).
    """

    threshold_fraction: float = 0.75
    fl_range: tuple[float, float] = (0.5, 0.9)
    hen_targets: Literal["means", "cso"] = "means"
    fitness: Literal["weight", "cost"] = "weight"
    rooster_spread: Literal["printed", "cso"] = "printed"

    roles: NDArray[np.int8] = field(
        default_factory=lambda: np.empty(0, dtype=np.int8), init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if not 0.0 <= self.threshold_fraction <= 1.0:
            raise ValueError(f"threshold_fraction must be in [0, 1], got {self.threshold_fraction}")
        lo, hi = self.fl_range
        if not 0.0 <= lo <= hi <= 1.0:
            raise ValueError(f"fl_range must satisfy 0 ≤ low ≤ high ≤ 1, got {self.fl_range}")
        if self.hen_targets not in ("means", "cso"):
            raise ValueError(f"hen_targets must be 'means' or 'cso', got {self.hen_targets!r}")
        if self.fitness not in ("weight", "cost"):
            raise ValueError(f"fitness must be 'weight' or 'cost', got {self.fitness!r}")
        if self.rooster_spread not in ("printed", "cso"):
            raise ValueError(
                f"rooster_spread must be 'printed' or 'cso', got {self.rooster_spread!r}"
            )
        if self.rooster_spread == "printed" and self.fitness == "cost":
            # A cost is small for a heavy rooster: exp((f_mea − f_i)/f_i) would be unbounded.
            raise ValueError(
                "rooster_spread='printed' (Eq. 30b's q_mea) needs fitness='weight'; "
                "with fitness='cost' use rooster_spread='cso'"
            )

    def swarm(self, likelihood_fn: LikelihoodFn, rng: np.random.Generator) -> None:
        """Classify, move roosters, hens and chicks once, and re-weight at the new positions.

        Call after :meth:`predict` and :meth:`update`, before resampling.

        Args:
            likelihood_fn: (N, 2) positions → (N,) likelihood of this step's
                measurements: the whole product of Eq. 27's factors, the same
                function whose values :meth:`update` received.
            rng: the random generator.
        """
        x0 = self.x
        roles = classify(self.w, self.crossed, self.threshold_fraction)
        roosters = np.flatnonzero(roles == ROOSTER)
        hens = np.flatnonzero(roles == HEN)
        chicks = np.flatnonzero(roles == CHICK)
        # predict() leaves weight on some particle that did not cross a wall, so this max is > 0.
        f = self.w / self.w[~self.crossed].max()
        if self.fitness == "cost":
            f = 1.0 - f  # 0 for the heaviest particle: CSO minimises f

        x_new = x0.copy()
        origin = x0.copy()
        if roosters.size:
            x_new[roosters] = self._move_roosters(f, roosters, rng)
            x_new[hens] = self._move_hens(f, roosters, hens, rng)
        if chicks.size:
            # Hens exist whenever chicks do: the lightest non-chick is always a hen.
            mothers = rng.choice(hens, size=chicks.size)
            fl = rng.uniform(*self.fl_range, size=chicks.size)
            # (24) X_i ← X_i + FL·(X_m − X_i)
            x_new[chicks] = x0[chicks] + fl[:, None] * (x0[mothers] - x0[chicks])
            origin[chicks] = x0[mothers]

        if self.plan is not None:
            blocked = self.plan.crosses_wall(origin, x_new)
            x_new[blocked] = x0[blocked]
            self.crossed = self.crossed & blocked
        self.roles = roles
        self.x = x_new

        self.likelihood = np.asarray(likelihood_fn(x_new), dtype=float)
        prior = np.where(self.crossed, 0.0, self.w_prior)
        w = prior * self.likelihood
        total = w.sum()
        if total == 0:
            # The measurement is incompatible with every particle: ignore it (as in update).
            w, total = prior, prior.sum()
        self.w = w / total

    def _move_roosters(
        self, f: NDArray[np.float64], roosters: NDArray[np.intp], rng: np.random.Generator
    ) -> NDArray[np.float64]:
        n = roosters.size
        # Each rooster competes with a random other rooster k ≠ i (itself when alone: σ² = 1).
        k = roosters[(np.arange(n) + rng.integers(1, n, size=n)) % n] if n > 1 else roosters
        f_i, f_k = f[roosters], f[k]
        if self.rooster_spread == "printed":
            # (30b) σ² = 1 if q_i ≤ q_k, else exp((q_mea − q_i)/(q_i + ε)), q_mea the mean of all N
            sigma2 = np.where(f_i <= f_k, 1.0, np.exp((f.mean() - f_i) / (f_i + _EPS)))
        else:
            # CSO: σ² = 1 if f_i ≤ f_k, else exp((f_k − f_i)/(|f_i| + ε)); the min() covers both
            sigma2 = np.exp(np.minimum(f_k - f_i, 0.0) / (np.abs(f_i) + _EPS))
        centre = self.w @ self.x
        offset = self.x[roosters] - centre
        # (30a) X ← X·(1 + N(0, σ²)), on the offset from the weighted mean (scale-free)
        return centre + offset * (1.0 + np.sqrt(sigma2)[:, None] * rng.standard_normal((n, 2)))

    def _move_hens(
        self,
        f: NDArray[np.float64],
        roosters: NDArray[np.intp],
        hens: NDArray[np.intp],
        rng: np.random.Generator,
    ) -> NDArray[np.float64]:
        n = hens.size
        x_h, f_i = self.x[hens], f[hens]
        if self.hen_targets == "means":
            target1, f1 = self.x[roosters].mean(axis=0), f[roosters].mean()
            target2, f2 = x_h.mean(axis=0), f_i.mean()
        else:
            # r1: the hen's group rooster; r2: any rooster or hen but r1.
            j1 = rng.integers(0, roosters.size, size=n)
            flock = np.concatenate([roosters, hens])
            r1 = roosters[j1]
            r2 = flock[(j1 + rng.integers(1, flock.size, size=n)) % flock.size]
            target1, f1 = self.x[r1], f[r1]
            target2, f2 = self.x[r2], f[r2]
        # (31b) s1 = exp((f_i − f_mea1)/(|f_i| + ε))
        s1 = np.exp((f_i - f1) / (np.abs(f_i) + _EPS))
        # (31c) s2 = exp(f_mea2 − f_i)
        s2 = np.exp(f2 - f_i)
        u = rng.random((n, 2))
        # (31a) X_i ← X_i + s1·rand·(X_mea1 − X_i) + s2·rand·(X_mea2 − X_i)
        return (
            x_h
            + (s1 * u[:, 0])[:, None] * (target1 - x_h)
            + (s2 * u[:, 1])[:, None] * (target2 - x_h)
        )

    def refine(self, likelihood_fn: LikelihoodFn, rng: np.random.Generator) -> None:
        """The chicken swarm between the update and the estimate (:meth:`swarm`)."""
        self.swarm(likelihood_fn, rng)
