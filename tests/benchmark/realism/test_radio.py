"""WiFi scan statistics, on scans with known answers and on the simulated phone's fading."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import scipy.stats

from indoorsim.benchmark.realism.radio import (
    level_statistics,
    miss_share,
    scan_statistics,
    static_spread,
    static_statistics,
)
from indoorsim.benchmark.realism.report import STATIC_REPEATS, STATIC_VISITS, static_scans
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


def test_simulated_stays_vary_by_the_phones_own_spread_and_visits_by_the_fade():
    # APs heard far above the threshold. Within a stay each scan is μ + σ·ξ rounded to
    # whole dB, so the sample std is about √(σ² + 1/12), less the small-sample bias of
    # 6 scans; between the two visits the spot's multipath fade and the body's side
    # change, so the spread over all 12 scans is larger.
    site = load_site("chen2022_office")
    device = "nexus_5x"
    spec = get_device(device).wifi
    points = np.array([[x, 2.0] for x in np.linspace(2.0, 20.0, 40)])
    levels, point, visit = static_scans(site, points, device, seed=3)
    assert levels.shape[0] == len(points) * STATIC_REPEATS
    assert np.array_equal(np.unique(visit // STATIC_VISITS), np.unique(point))
    strong = np.nanmin(levels, axis=0) > spec.detection_threshold_dbm + 15
    assert strong.sum() >= 3
    stats = static_statistics(levels[:, strong], point, visit)
    # The median over pairs of a 6-sample std: σ·√(median of χ²₅ / 5).
    sigma = math.sqrt(spec.fading_sigma_db**2 + 1 / 12)
    expected = sigma * math.sqrt(scipy.stats.chi2.median(5) / 5)
    assert stats["visit_std"] == pytest.approx(expected, rel=0.1)
    assert stats["static_std"] > stats["visit_std"] + 0.5
    every = static_statistics(levels, point, visit)
    assert every["miss_share"] == pytest.approx(spec.miss_probability, abs=0.01)


def test_miss_share_counts_the_strong_aps_a_stay_missed():
    nan = np.nan
    rss = np.array(
        [
            [-60.0, -90.0, -70.0],
            [nan, -91.0, -71.0],
            [-61.0, nan, -72.0],
            [-62.0, -90.0, nan],
        ]
    )
    # Stay 0 (rows 0–1): APs 0 and 2 are strong, AP 0 missed once: 1 of 4.
    # Stay 1 (rows 2–3): APs 0 and 2 strong (AP 2's median −72), AP 2 missed once: 1 of 4.
    # AP 1 (−90 dBm) is never counted.
    assert miss_share(rss, np.array([0, 0, 1, 1])) == pytest.approx(2 / 8)
    assert math.isnan(miss_share(rss[:, 1:2], np.zeros(4)))


def test_the_visit_facing_back_turns_the_handsets_pattern_round_for_an_ap_beside_the_route():
    # A bare hall, no shadowing or multipath: standing on a line along +x, then facing back,
    # a phone reads an AP 13 m off to its left (+y) through the opposite sides of its own
    # pattern, −ratio/2 on the way out (its +x side to the right) and +ratio/2 on the way
    # back; the trunk, behind the phone, is beside neither.
    from indoorsim.scenario import parse_scenario

    corners = [(0, 0), (60, 0), (60, 20), (0, 20)]
    scenario = parse_scenario(
        {
            "name": "hall",
            "site": {
                "latitude": 40.0,
                "longitude": 0.0,
                "date": "2025-01-01",
                "ceiling_height": 3.0,
            },
            "outline": [list(c) for c in corners],
            "walls": [
                {"from": list(a), "to": list(b), "thickness": 0.2}
                for a, b in zip(corners, corners[1:] + corners[:1], strict=True)
            ],
            "wifi": [{"bssid": "02:00:00:00:00:01", "position": [30.0, 18.0, 1.2]}],
            "radio": {
                "shadowing_sigma_db": 0.0,
                "floors_above": 0,
                "floors_below": 0,
                "multipath": {"enabled": False},
            },
        }
    )
    site = load_site(scenario)
    device = "nexus_5x"
    ratio = get_device(device).wifi.antenna_side_ratio_db
    assert ratio > 0
    points = np.column_stack([np.linspace(29.0, 31.0, 40), np.full(40, 5.0)])
    levels, _, _ = static_scans(site, points, device, seed=1)
    by_visit = np.nanmean(levels[:, 0].reshape(len(points), STATIC_VISITS, -1), axis=2)
    toward = site.radio.positions[0] - np.column_stack([points, np.full(len(points), 1.2)])
    along_y = toward[:, 1] / np.linalg.norm(toward, axis=1)
    # Per point: the 6-scan means differ by the pattern, ± the scans' own spread
    # (σ ≈ 1.7 dB: ≈ 1 dB per difference, 0.16 dB over 40 points).
    expected = -ratio * along_y
    assert np.mean(by_visit[:, 0] - by_visit[:, 1]) == pytest.approx(expected.mean(), abs=0.5)
