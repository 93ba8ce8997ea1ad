"""Helpers shared by the real-log readers: frames, clocks, rates and carry-mode names."""

from __future__ import annotations

import os

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

PathLike = str | os.PathLike[str]

XYZ = ("x", "y", "z")
RATE_STREAMS = (
    "accel",
    "gyro",
    "mag",
    "rotation",
    "game_rotation",
    "gravity",
    "linear_accel",
    "light",
    "wifi",
)

# Carry positions named by the logs → indoorsim carry modes (lower-cased keys).
CARRY_MODES = {
    "inhand": "handheld",
    "hand": "handheld",
    "frontpocket": "pocketed",
    "backpocket": "pocketed",
    "swingingarm": "dangling",
}


def carry_mode(position: str) -> str:
    """indoorsim's carry mode for a logged carrying position, or the position unchanged.

    >>> carry_mode("FrontPocket"), carry_mode("hand"), carry_mode("Purse")
    ('pocketed', 'handheld', 'Purse')
    """
    return CARRY_MODES.get(position.lower(), position)


def time_frame(t: ArrayLike, columns: dict[str, ArrayLike]) -> pd.DataFrame:
    """A stream DataFrame indexed by float64 ``t``, sorted stably by ``t``."""
    df = pd.DataFrame(columns, index=pd.Index(np.asarray(t, dtype=np.float64), name="t"))
    if not df.index.is_monotonic_increasing:
        df = df.sort_index(kind="stable")
    return df


def ticks_to_seconds(ticks: NDArray[np.int64], t0: int, ticks_per_s: float) -> NDArray[np.float64]:
    # Subtract in integers first: epoch nanoseconds (~1.7e18) do not fit a float64 exactly.
    return (ticks - np.int64(t0)).astype(np.float64) / ticks_per_s


def median_rates_hz(streams: dict[str, pd.DataFrame]) -> dict[str, float]:
    rates = {}
    for name in RATE_STREAMS:
        if name in streams:
            times = np.unique(streams[name].index.to_numpy())
            if len(times) > 1:
                rates[name] = round(float(1.0 / np.median(np.diff(times))), 3)
    return rates


def quaternion_from_rotation_vector(xyz: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N, 4) unit quaternions (w, x, y, z) from Android rotation-vector (x, y, z) rows.

    Android gives x, y, z = sin(θ/2)·axis; w = cos(θ/2) = sqrt(1 − x² − y² − z²),
    clipped at 0 because rounding can push the norm of xyz a hair above 1.
    """
    w = np.sqrt(np.clip(1.0 - np.sum(xyz**2, axis=1), 0.0, None))
    q = np.column_stack([w, xyz])
    return q / np.linalg.norm(q, axis=1, keepdims=True)
