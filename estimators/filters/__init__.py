"""Particle filters for step-driven positioning on a floor plan (Chen2022 Eq. 25–31).

:class:`ParticleFilter` is the bootstrap filter with the wall rule;
:class:`ChickenParticleFilter` adds the chicken swarm moves between update and
resampling. Both take any plan-like object (:class:`PlanLike`: vectorised
``crosses_wall`` and ``is_walkable``), never the simulator's own classes.
"""

from indoorsim.estimators.filters.chicken import (
    CHICK,
    HEN,
    ROOSTER,
    ChickenParticleFilter,
    classify,
)
from indoorsim.estimators.filters.particle import (
    LikelihoodFn,
    ParticleFilter,
    PlanLike,
    effective_sample_size,
    gaussian_likelihood,
    literal_likelihood,
    systematic_resample,
)

__all__ = [
    "CHICK",
    "HEN",
    "ROOSTER",
    "ChickenParticleFilter",
    "LikelihoodFn",
    "ParticleFilter",
    "PlanLike",
    "classify",
    "effective_sample_size",
    "gaussian_likelihood",
    "literal_likelihood",
    "systematic_resample",
]
