"""The ambient light a walking phone reports: its spread, its dark time and how fast it changes.

:func:`light_statistics` takes a recording's ``light`` stream — a simulated
phone's or a real log's — and measures it over the walk. Android's light
sensor reports on change, so each reported value holds until the next one:
spreads and shares are weighted by that holding time, not counted per event.

Keys (NaN without a light stream of at least two events):

================  =============================================================
``lux_median``    time-weighted median (lx)
``lux_ratio``     time-weighted 95th over 5th percentile (the 5th held at ≥ 1 lx)
``dark_share``    share of the time below :data:`DARK_LUX`
``dlog_std``      std of Δlog10(lux + 1) between consecutive reports
================  =============================================================
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.io.recording import Recording

__all__ = ["DARK_LUX", "LIGHT_KEYS", "light_statistics", "lux_statistics", "weighted_quantile"]

DARK_LUX = 50.0
"""Below this a walker is in a dim stretch: between luminaires, an unlit corridor."""

LIGHT_KEYS = ("lux_median", "lux_ratio", "dark_share", "dlog_std")


def weighted_quantile(values: ArrayLike, weights: ArrayLike, q: float) -> float:
    """The ``q`` quantile of ``values`` each held for ``weights``: the smallest value
    below which at least a share ``q`` of the total weight lies."""
    v = np.asarray(values, dtype=float)
    w = np.asarray(weights, dtype=float)
    if v.shape != w.shape or v.ndim != 1 or len(v) == 0:
        raise ValueError(f"values {v.shape} and weights {w.shape} must be 1-D of one length")
    order = np.argsort(v, kind="stable")
    cumulative = np.cumsum(w[order])
    k = int(np.searchsorted(cumulative, q * cumulative[-1], side="left"))
    return float(v[order][min(k, len(v) - 1)])


def _holding_times(t: NDArray[np.float64]) -> NDArray[np.float64]:
    """How long each report holds: until the next; the last for the median interval."""
    gaps = np.diff(t)
    return np.append(gaps, np.median(gaps))


def lux_statistics(t: ArrayLike, lux: ArrayLike) -> dict[str, float]:
    """:data:`LIGHT_KEYS` of reports ``lux`` at times ``t`` (see the module docstring)."""
    out = dict.fromkeys(LIGHT_KEYS, math.nan)
    tt = np.asarray(t, dtype=float)
    values = np.asarray(lux, dtype=float)
    if tt.shape != values.shape or tt.ndim != 1:
        raise ValueError(f"t {tt.shape} and lux {values.shape} must be 1-D of one length")
    keep = np.isfinite(values)
    tt, values = tt[keep], values[keep]
    if len(tt) < 2:
        return out
    held = _holding_times(tt)
    out["lux_median"] = weighted_quantile(values, held, 0.5)
    low = max(weighted_quantile(values, held, 0.05), 1.0)
    out["lux_ratio"] = weighted_quantile(values, held, 0.95) / low
    out["dark_share"] = float(held[values < DARK_LUX].sum() / held.sum())
    out["dlog_std"] = float(np.std(np.diff(np.log10(np.maximum(values, 0.0) + 1.0))))
    return out


def light_statistics(rec: Recording) -> dict[str, float]:
    """:func:`lux_statistics` of ``rec``'s ``light`` stream (all NaN without one)."""
    if "light" not in rec.streams:
        return dict.fromkeys(LIGHT_KEYS, math.nan)
    light = rec.light
    return lux_statistics(light.index.to_numpy(dtype=float), light["lux"].to_numpy(dtype=float))
