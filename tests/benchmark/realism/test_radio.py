"""WiFi scan statistics, on scans with known answers and on the simulated phone's fading."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.radio import level_statistics, scan_statistics, static_spread
from indoorsim.benchmark.realism.report import STATIC_REPEATS, static_scans
from indoorsim.phone.devices import get_device
from indoorsim.scenario.load import load_site


def test_scan_statistics_of_three_scans():
    # Scans at 0, 2.5 and 5.5 s with 3, 2 and 1 APs.
    t = [0.0, 0.0, 0.0, 2.5, 2.5, 5.5]
    wifi = pd.DataFrame(
        {"bssid": list("abcabc")[:6], "rss": [-50.0, -60, -70, -80, -90, -100]},
        index=pd.Index(t, name="t"),
    )
    stats = scan_statistics(wifi)
    assert stats["rss_mean"] == pytest.approx(-75.0)
    assert stats["rss_p90"] == pytest.approx(-55.0)  # numpy's linear interpolation
    assert stats["aps_per_scan"] == 2.0
    assert stats["scan_interval"] == pytest.approx(2.75)
    assert math.isnan(stats["static_std"])
    assert math.isnan(level_statistics([np.nan])["rss_mean"])


def test_static_spread_counts_only_pairs_heard_in_every_repeat():
    rss = np.array([[-60.0, -80.0, -90.0], [-62.0, -84.0, np.nan], [-64.0, -88.0, -91.0]])
    spread = static_spread(rss, np.zeros(3, dtype=int))
    # AP 0: std of (−60, −62, −64) = 2; AP 1: 4; AP 2 missed once, left out.
    assert spread == pytest.approx(3.0)
    with pytest.raises(ValueError, match="point"):
        static_spread(rss, np.zeros(2))


def test_simulated_static_spread_is_the_phones_fading():
    # APs heard far above the threshold: each repeat is μ + σ·ξ rounded to whole dB,
    # so the sample std is about √(σ² + 1/12), less the small-sample bias of 12 repeats.
    site = load_site("chen2022_office")
    device = "nexus_5x"
    sigma = get_device(device).wifi.fading_sigma_db
    points = np.array([[x, 2.0] for x in np.linspace(2.0, 20.0, 40)])
    levels, point = static_scans(site, points, device, seed=3)
    assert levels.shape[0] == len(points) * STATIC_REPEATS
    strong = np.nanmin(levels, axis=0) > get_device(device).wifi.detection_threshold_dbm + 15
    assert strong.sum() >= 3
    spread = static_spread(levels[:, strong], point)
    assert spread == pytest.approx(math.sqrt(sigma**2 + 1 / 12), rel=0.1)
