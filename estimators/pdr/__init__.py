"""Pedestrian dead reckoning components: step detection, step length, heading.

Streaming components: each keeps its state across observation windows and is
vectorised inside one, so a pipeline feeds it window after window.
"""

from indoorsim.estimators.pdr.heading import GyroHeading
from indoorsim.estimators.pdr.length import (
    MODELS,
    WEINBERG_K,
    calibrate_k,
    kim,
    scarlet,
    step_lengths,
    weinberg,
)
from indoorsim.estimators.pdr.steps import STANDARD_GRAVITY, PeakStepDetector, Step

__all__ = [
    "MODELS",
    "STANDARD_GRAVITY",
    "WEINBERG_K",
    "GyroHeading",
    "PeakStepDetector",
    "Step",
    "calibrate_k",
    "kim",
    "scarlet",
    "step_lengths",
    "weinberg",
]
