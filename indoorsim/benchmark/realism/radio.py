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
``visit_std``       the same over (visit, AP): the scans of one stay at a point,
                    the phone not moved in between (dB)
``miss_share``      share of a visit's scans that miss an AP the visit hears at
                    a median −80…−55 dBm, well above any detection threshold
==================  ============================================================

A point of the UJI sets is visited twice (on the way out and back); between
visits the phone lands a few centimetres apart and the surveyor faces the
other way, so ``static_std`` holds the multipath fade of the spot and the
body's shadow, and ``visit_std`` only what changes while the phone is still.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from indoorsim.io.recording import Recording

__all__ = [
    "MISS_LEVELS_DBM",
    "RADIO_KEYS",
    "STATIC_KEYS",
    "level_statistics",
    "miss_share",
    "radio_statistics",
    "scan_statistics",
    "static_spread",
    "static_statistics",
]

STATIC_KEYS = ("static_std", "visit_std", "miss_share")
"""The statistics of repeated scans standing still (NaN for a walk)."""
RADIO_KEYS = ("rss_mean", "rss_p90", "aps_per_scan", "scan_interval", *STATIC_KEYS)

MISS_LEVELS_DBM = (-80.0, -55.0)
"""The median levels of the APs whose misses :func:`miss_share` counts."""


def level_statistics(rss: ArrayLike) -> dict[str, float]:
    """Mean and 90th percentile of the levels heard (dBm); NaN for none."""
    levels = np.asarray(rss, dtype=float)
    levels = levels[np.isfinite(levels)]
    if levels.size == 0:
        return {"rss_mean": math.nan, "rss_p90": math.nan}
    return {"rss_mean": float(levels.mean()), "rss_p90": float(np.percentile(levels, 90))}


def scan_statistics(wifi: pd.DataFrame) -> dict[str, float]:
    """:data:`RADIO_KEYS` but :data:`STATIC_KEYS` of a ``wifi`` stream (t index, bssid, rss)."""
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


def miss_share(rss: ArrayLike, visit: ArrayLike) -> float:
    """Share of scans that miss an AP heard in the same visit at a median level
    within :data:`MISS_LEVELS_DBM`.

    Args:
        rss: (S, n_ap) levels of S scans, NaN where the AP was not heard.
        visit: (S,) the stay each scan belongs to (the phone still within one).
    """
    levels = np.asarray(rss, dtype=float)
    where = np.asarray(visit)
    if levels.ndim != 2 or where.shape != (len(levels),):
        raise ValueError(f"rss {levels.shape} must be (S, n_ap) and visit {where.shape} (S,)")
    lo, hi = MISS_LEVELS_DBM
    missed = scans = 0
    for v in np.unique(where):
        block = levels[where == v]
        heard = np.isfinite(block)
        some = heard.any(axis=0)
        median = np.full(block.shape[1], np.nan)
        median[some] = np.nanmedian(block[:, some], axis=0)
        strong = some & (median >= lo) & (median <= hi)
        missed += int((~heard[:, strong]).sum())
        scans += int(strong.sum()) * len(block)
    return missed / scans if scans else math.nan


def static_statistics(rss: ArrayLike, point: ArrayLike, visit: ArrayLike) -> dict[str, float]:
    """:data:`STATIC_KEYS` of repeated scans: (S, n_ap) levels, each scan's point and visit."""
    return {
        "static_std": static_spread(rss, point),
        "visit_std": static_spread(rss, visit),
        "miss_share": miss_share(rss, visit),
    }


def radio_statistics(rec: Recording) -> dict[str, float]:
    """:func:`scan_statistics` of ``rec``'s ``wifi`` stream (all NaN without one)."""
    if "wifi" not in rec.streams:
        return dict.fromkeys(RADIO_KEYS, math.nan)
    return scan_statistics(rec.wifi)
