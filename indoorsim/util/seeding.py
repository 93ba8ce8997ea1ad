"""Seeded random streams: one seed, one independent generator per sub-model.

DESIGN §3: everything random draws from ``numpy.random.Generator``s derived
from one seed per run. :func:`generator` is the one place a generator is
derived from a seed and a spawn key; :func:`named_streams` gives a run's
sub-models theirs. A named stream's spawn key is (phase, position of its
name), so appending a name never changes the others, and the phases (a walk,
a survey, …) never share a stream even under the same seed.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

WALK, SURVEY = 0, 1  # phases


def generator(seed: int, spawn_key: Sequence[int] = ()) -> np.random.Generator:
    """The generator of ``SeedSequence(seed, spawn_key=spawn_key)``.

    The same (seed, spawn key), the same stream, on any machine; two keys, two
    independent streams.

    >>> float(generator(7, (0, 3)).random()) == float(generator(7, (0, 3)).random())
    True
    """
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=tuple(spawn_key)))


def named_streams(seed: int, phase: int, names: Sequence[str]) -> dict[str, np.random.Generator]:
    """One generator per name, ``generator(seed, (phase, i))`` for the i-th name."""
    return {name: generator(seed, (phase, i)) for i, name in enumerate(names)}
