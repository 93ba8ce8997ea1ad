"""Pedestrian dead reckoning components: step detection, step length, heading.

Streaming components: each keeps its state across observation windows and is
vectorised inside one, so a pipeline feeds it window after window.
"""

from indoorsim.estimators.pdr.filters import (
    HeadingBKF,
    HeadingKF,
    HeadingTrack,
    gyro_heading,
    mag_heading,
)
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
from indoorsim.estimators.pdr.wavelet import StreamingDenoiser, denoise

__all__ = [
    "MODELS",
    "STANDARD_GRAVITY",
    "WEINBERG_K",
    "GyroHeading",
    "HeadingBKF",
    "HeadingKF",
    "HeadingTrack",
    "PeakStepDetector",
    "Step",
    "StreamingDenoiser",
    "calibrate_k",
    "denoise",
    "gyro_heading",
    "kim",
    "mag_heading",
    "scarlet",
    "step_lengths",
    "weinberg",
]
