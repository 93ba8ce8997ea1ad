"""Pedestrian dead reckoning components: step detection, step length, heading, gait DR.

Streaming components: each keeps its state across observation windows and is
vectorised inside one, so a pipeline feeds it window after window.
"""

from indoorsim.estimators.pdr.attitude import QuaternionAttitude, dcm, euler_angles
from indoorsim.estimators.pdr.filters import (
    HeadingBKF,
    HeadingKF,
    HeadingTrack,
    gyro_heading,
    mag_heading,
)
from indoorsim.estimators.pdr.gait import (
    PENDULUM_LENGTH_M,
    GaitDeadReckoning,
    GaitStep,
    pendulum_step_length,
    vertical_acceleration,
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
from indoorsim.estimators.pdr.zupt import StationaryDetector, VerticalZuptEKF

__all__ = [
    "MODELS",
    "PENDULUM_LENGTH_M",
    "STANDARD_GRAVITY",
    "WEINBERG_K",
    "GaitDeadReckoning",
    "GaitStep",
    "GyroHeading",
    "HeadingBKF",
    "HeadingKF",
    "HeadingTrack",
    "PeakStepDetector",
    "QuaternionAttitude",
    "StationaryDetector",
    "Step",
    "StreamingDenoiser",
    "VerticalZuptEKF",
    "calibrate_k",
    "dcm",
    "denoise",
    "euler_angles",
    "gyro_heading",
    "kim",
    "mag_heading",
    "pendulum_step_length",
    "scarlet",
    "step_lengths",
    "vertical_acceleration",
    "weinberg",
]
