"""WiFi scans as a phone reports them: levels heard, APs per scan, scan rate, temporal spread.

The same functions run on a simulated recording's ``wifi`` stream, on a real
trace's (Indoor Location Competition logs) and on static fingerprint tables
(the UJI library's repeated scans). A scan is the set of rows that share one
timestamp — how both indoorsim and the real logs write a scan's results.

Keys (NaN where not measured):

==================  ============================================================
``rss_mean``        mean RSS of every AP heard in every scan (dBm)
``rss_p90``         90th percentile of those levels (dBm)
``aps_per_scan``    median number of APs a scan reports
``scan_interval``   median time between scans of a walk (s)
``static_std``      median over (point, AP) of the std of RSS across repeated
                    scans standing at the point, over the pairs heard in every
                    repeat (dB)
==================  ============================================================
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from indoorsim.io.recording import Recording

__all__ = ["RADIO_KEYS", "level_statistics", "radio_statistics", "scan_statistics", "static_spread"]

RADIO_KEYS = ("rss_mean", "rss_p90", "aps_per_scan", "scan_interval", "static_std")


def level_statistics(rss: ArrayLike) -> dict[str, float]:
    """Mean and 90th percentile of the levels heard (dBm); NaN for none."""
    levels = np.asarray(rss, dtype=float)
    levels = levels[np.isfinite(levels)]
    if levels.size == 0:
        return {"rss_mean": math.nan, "rss_p90": math.nan}
    return {"rss_mean": float(levels.mean()), "rss_p90": float(np.percentile(levels, 90))}


def scan_statistics(wifi: pd.DataFrame) -> dict[str, float]:
    """:data:`RADIO_KEYS` but ``static_std`` of a ``wifi`` stream (rows: t index, bssid, rss)."""
    out = dict.fromkeys(RADIO_KEYS, math.nan)
    if len(wifi) == 0:
        return out
    out |= level_statistics(wifi["rss"].to_numpy(dtype=float))
    t = wifi.index.to_numpy(dtype=float)
    per_scan = pd.Series(t).value_counts()
    out["aps_per_scan"] = float(per_scan.median())
    scans = np.unique(t)
    if len(scans) >= 2:
        out["scan_interval"] = float(np.median(np.diff(scans)))
    return out


def static_spread(rss: ArrayLike, point: ArrayLike) -> float:
    """Median sample std (dB, ddof 1) across repeats of one AP at one point.

    Args:
        rss: (S, n_ap) levels of S scans, NaN where the AP was not heard.
        point: (S,) the reference point each scan was taken at.

    Only (point, AP) pairs heard in every scan at that point count, so a
    level near the detection threshold, cut off in some repeats, does not
    shrink the spread.
    """
    levels = np.asarray(rss, dtype=float)
    where = np.asarray(point)
    if levels.ndim != 2 or where.shape != (len(levels),):
        raise ValueError(f"rss {levels.shape} must be (S, n_ap) and point {where.shape} (S,)")
    spreads = []
    for p in np.unique(where):
        block = levels[where == p]
        if len(block) < 2:
            continue
        heard = np.isfinite(block).all(axis=0)
        spreads.append(block[:, heard].std(axis=0, ddof=1))
    pooled = np.concatenate(spreads) if spreads else np.zeros(0)
    return float(np.median(pooled)) if pooled.size else math.nan


def radio_statistics(rec: Recording) -> dict[str, float]:
    """:func:`scan_statistics` of ``rec``'s ``wifi`` stream (all NaN without one)."""
    if "wifi" not in rec.streams:
        return dict.fromkeys(RADIO_KEYS, math.nan)
    return scan_statistics(rec.wifi)
