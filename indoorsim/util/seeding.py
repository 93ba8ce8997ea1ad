"""Named random streams: one seed, one independent generator per sub-model.

DESIGN §3: everything random draws from ``numpy.random.Generator``s spawned
from one ``SeedSequence`` per run. A stream's spawn key is (phase, position of
its name), so appending a name never changes the others, and the phases (a
walk, a survey, …) never share a stream even under the same seed.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

WALK, SURVEY = 0, 1  # phases


def named_streams(seed: int, phase: int, names: Sequence[str]) -> dict[str, np.random.Generator]:
    """One generator per name, from ``SeedSequence(seed, spawn_key=(phase, i))``."""
    return {
        name: np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(phase, i)))
        for i, name in enumerate(names)
    }
