"""Light statistics on report sequences with closed-form answers."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.light import (
    light_statistics,
    lux_statistics,
    weighted_quantile,
)
from indoorsim.io.recording import Recording


def test_weighted_quantile_counts_how_long_each_value_holds():
    assert weighted_quantile([10.0, 20.0, 30.0], [1.0, 1.0, 1.0], 0.5) == 20.0
    assert weighted_quantile([10.0, 20.0, 30.0], [8.0, 1.0, 1.0], 0.5) == 10.0
    assert weighted_quantile([30.0, 10.0], [1.0, 3.0], 0.9) == 30.0
    with pytest.raises(ValueError, match="weights"):
        weighted_quantile([1.0], [1.0, 2.0], 0.5)


def test_a_walk_of_seven_lit_and_three_dark_seconds():
    # On-change reports each second: 100 lx for 7 s, then 20 lx for 3 s (held to t = 10 s).
    t = np.arange(10.0)
    lux = np.array([100.0] * 7 + [20.0] * 3)
    stats = lux_statistics(t, lux)
    assert stats["dark_share"] == pytest.approx(0.3)
    assert stats["lux_median"] == 100.0
    assert stats["lux_ratio"] == pytest.approx(100.0 / 20.0)
    # One step of log10(101/21) among nine differences, the rest zero.
    step = math.log10(101.0 / 21.0)
    assert stats["dlog_std"] == pytest.approx(np.std([0.0] * 8 + [-step]))


def test_darkness_is_held_at_one_lux_in_the_ratio():
    stats = lux_statistics(np.arange(4.0), np.array([0.0, 0.0, 0.0, 300.0]))
    assert stats["lux_ratio"] == pytest.approx(300.0)  # p95 300 over p5 0, held at 1 lx
    assert stats["dark_share"] == pytest.approx(0.75)


def test_light_statistics_reads_a_recordings_light_stream():
    t = pd.Index(np.arange(0.0, 5.0, 0.5), name="t")
    rec = Recording(streams={"light": pd.DataFrame({"lux": np.full(10, 80.0)}, index=t)}, meta={})
    stats = light_statistics(rec)
    assert stats["lux_median"] == 80.0 and stats["dark_share"] == 0.0 and stats["dlog_std"] == 0.0
    assert all(math.isnan(v) for v in light_statistics(Recording(streams={}, meta={})).values())
