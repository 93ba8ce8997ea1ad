"""The walked line's statistics (indoorsim.benchmark.realism.line) on tracks with known answers."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.line import STRIDE_M, line_statistics
from indoorsim.io.recording import Recording
from indoorsim.scenario import load_site
from indoorsim.simulate import simulate
from indoorsim.walker.gait import WalkerParams


def _track(wavelength_m: float, amplitude_m: float, length_m: float = 60.0) -> Recording:
    """A straight walk along x at 1.2 m/s, weaving sideways as a sinusoid, as a dense
    track at 100 Hz (``waypoints``, as the ARKit walks give theirs)."""
    t = np.arange(0.0, length_m / 1.2, 0.01)
    x = 1.2 * t
    y = 5.0 + amplitude_m * np.sin(2 * np.pi * x / wavelength_m)
    track = pd.DataFrame({"x": x, "y": y}, index=pd.Index(t, name="t"))
    return Recording(streams={"waypoints": track}, meta={})


def test_a_weave_of_two_periods_a_stretch_is_measured_through_the_stride_mean():
    """A 3 m wave, 2 cm: two whole periods in each 6 m stretch (no line to take off),
    passed by the 1.4 m moving mean at sinc(1.4/3) = 0.678. The mean leaves 4.6 m, a
    period and a half, over which a sinusoid's RMS is within a few per cent of A/√2."""
    stats = line_statistics(_track(3.0, 0.02))
    gain = math.sin(math.pi * STRIDE_M / 3.0) / (math.pi * STRIDE_M / 3.0)
    assert stats["weave_cm"] == pytest.approx(100 * 0.02 * gain / math.sqrt(2), rel=0.08)
    slope = 0.02 * gain * 2 * math.pi / 3.0 / math.sqrt(2)
    assert stats["weave_deg"] == pytest.approx(math.degrees(slope), rel=0.08)


def test_the_strides_sway_is_averaged_out():
    stats = line_statistics(_track(STRIDE_M, 0.03))  # 3 cm of sway: under a millimetre left
    assert stats["weave_cm"] < 0.1 and stats["weave_deg"] < 0.1


def test_surveyed_waypoints_short_walks_and_missing_positions_are_not_measured():
    sparse = Recording(
        streams={
            "waypoints": pd.DataFrame(
                {"x": [0.0, 30.0, 60.0], "y": [0.0, 0.0, 0.0]},
                index=pd.Index([0.0, 25.0, 50.0], name="t"),
            )
        },
        meta={},
    )
    for rec in (sparse, _track(3.0, 0.02, length_m=12.0), Recording(streams={}, meta={})):
        assert all(math.isnan(v) for v in line_statistics(rec).values())


def test_a_simulated_walker_weaves_and_one_without_its_weave_does_not():
    """On a simulated walk the statistic reads the true track: the drawn weave (7–12 cm
    RMS, 5 m wavelength) shows as 1–4 cm over 6 m stretches, and none without it."""
    site = load_site("han2023_corridor")
    kwargs = dict(route="trajectory", mode="handheld", device="ideal", seed=0)
    weaving = line_statistics(simulate(site, **kwargs))
    straight = line_statistics(simulate(site, walker=WalkerParams(meander_m=0.0), **kwargs))
    assert 1.0 < weaving["weave_cm"] < 4.0 and 0.5 < weaving["weave_deg"] < 4.0
    assert straight["weave_cm"] < 0.3 and straight["weave_deg"] < 0.3
