"""Parameter checks shared by the gait dead reckoning's components (zupt, attitude, gait)."""

from __future__ import annotations

import numpy as np


def positive(name: str, value: float) -> None:
    """Raise ValueError unless ``value`` is a finite number > 0."""
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")


def non_negative(name: str, value: float) -> None:
    """Raise ValueError unless ``value`` is a finite number ≥ 0."""
    if not (np.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a finite number ≥ 0, got {value!r}")
