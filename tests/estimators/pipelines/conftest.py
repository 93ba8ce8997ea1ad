"""Fixtures and stand-ins shared by the Chen2022 tests (its pipeline and its cited methods)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import pytest

import indoorsim
from indoorsim.benchmark.evaluation import site_context, training_walks
from indoorsim.estimators.base import SiteContext
from indoorsim.estimators.pdr.gait import GaitStep
from indoorsim.io.recording import Recording

# Grid of the synthetic magnetic tracks, m.
SPACING = 0.2


@pytest.fixture(scope="module")
def lab() -> indoorsim.Site:
    return indoorsim.load_site("chen2022_lab")


@pytest.fixture(scope="module")
def lab_context(lab: indoorsim.Site) -> SiteContext:
    return site_context(lab, device="ideal")


@pytest.fixture(scope="module")
def lab_train(lab: indoorsim.Site) -> list[Recording]:
    return training_walks(lab, "survey_loop", mode="handheld", device="ideal", n=2)


def synthetic_track(length_m: float = 30.0) -> pd.DataFrame:
    """A walk-survey magnetic table on the grid: an L-shaped path, a non-repeating HV field."""
    s = SPACING * np.arange(round(length_m / SPACING) + 1)
    corner = 14.0  # on the grid, so that label distances stay exact multiples of the spacing
    x = np.where(s <= corner, s, corner)
    y = np.where(s <= corner, 0.0, s - corner)
    b_h = 30.0 + 3.0 * np.sin(1.3 * s) + 2.0 * np.sin(0.37 * s + 1.0)
    b_v = -35.0 + 2.0 * np.cos(0.9 * s) + 1.5 * np.sin(0.021 * s**2)
    return pd.DataFrame({"pass": 0, "t": s / 1.2, "x": x, "y": y, "b_h": b_h, "b_v": b_v})


def wifi_map() -> tuple[np.ndarray, np.ndarray]:
    """Reference points every 5 m along a corridor; noise-free log-distance RSS of four APs."""
    points = np.column_stack([np.arange(0.0, 50.1, 5.0), np.full(11, 1.5)])
    aps = np.array([[3.0, 0.0], [18.0, 3.0], [33.0, 0.0], [48.0, 3.0]])
    d = np.linalg.norm(points[:, None, :] - aps[None, :, :], axis=2)
    rss = -40.0 - 25.0 * np.log10(np.maximum(d, 1.0))
    rss[rss < -70.0] = np.nan  # beyond the phone's detection threshold: unheard
    return points, rss


@dataclass
class MetronomeDR:
    """Stand-in dead reckoning: a step of ``length`` every ``period`` s along +x.

    A step due at a window's last sample (to rounding) falls in that window.
    """

    length: float = 0.6
    period: float = 0.5
    step_count: int = 0
    heading: float = 0.0
    step_delay_s: float = 0.0  # steps are timed exactly: no filter
    _next: float = 0.0

    def reset(self, heading: float) -> None:
        self.heading, self.step_count, self._next = heading, 0, self.period

    def update(self, t, accel, gyro, gravity=None) -> list[GaitStep]:
        steps = []
        while self._next <= t[-1] + 1e-9:
            steps.append(GaitStep(self._next, self.length, self.heading, 0.0, 0.05))
            self._next += self.period
            self.step_count += 1
        return steps
