"""Baseline estimators: the floor every method should beat.

* ``start-only`` — stays at the start position: the error of not moving.
* ``pdr-basic`` — un-calibrated pedestrian dead reckoning: peak–valley steps,
  Weinberg lengths with the default K, gyro heading from the known start.
* ``wknn-mag`` — single-window magnetic fingerprinting: the window's mean
  field in the geographic frame matched by WKNN against the grid survey.

Each works in every carrying mode and with missing streams (``obs["present"]``):
what a baseline cannot compute without a stream it holds (see each class).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from indoorsim.estimators.base import (
    NotApplicableError,
    Observation,
    SiteContext,
    StartInfo,
    not_reset_error,
    present_streams,
    register,
)
from indoorsim.estimators.fingerprint import WKNN
from indoorsim.estimators.frames import geomagnetic_mean
from indoorsim.estimators.pdr import WEINBERG_K, GyroHeading, PeakStepDetector, weinberg
from indoorsim.estimators.samples import SampleGuard
from indoorsim.io.recording import Recording

__all__ = ["PdrBasic", "StartOnly", "WknnMag"]

_MAG_COLUMNS = ["mag_x", "mag_y", "mag_z"]


@register("start-only")
@dataclass(kw_only=True)
class StartOnly:
    """Always answers the start position."""

    name: ClassVar[str] = "start-only"
    needs: ClassVar[tuple[str, ...]] = ()
    uses: ClassVar[tuple[str, ...]] = ()

    _position: NDArray[np.float64] | None = field(
        default=None, init=False, repr=False, compare=False
    )

    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """Nothing to learn."""

    def reset(self, start: StartInfo) -> None:
        self._position = np.array(start.position, dtype=float)

    def act(self, obs: Observation) -> NDArray[np.float64]:
        if self._position is None:
            raise not_reset_error(self.name)
        return self._position.copy()


@register("pdr-basic")
@dataclass(kw_only=True)
class PdrBasic:
    """Un-calibrated PDR: position += L·(cos φ, sin φ) at each detected step (Han2023 Eq. 1).

    L is Weinberg's length with ``weinberg_k`` (not fitted: this is the
    baseline that calibration must beat); φ is the gyro heading at the step's
    peak, integrated from the start heading. The answer at a window's end
    includes the steps confirmed so far, so it trails the walker by the
    detector's latency (about ``min_interval_s`` plus a step).

    Missing streams: without a gyroscope the heading stays at the start
    heading; without the fused gravity the window's mean specific force
    stands in for "up" (walking accelerations average out over a gait cycle).

    Besides the position it exposes ``heading`` (the latest gyro heading),
    ``step_count`` (steps detected this episode) and ``estimate_time`` (the
    last step's heel strike: the peak time less the detector's filter delay)
    for the runner's metrics.

    Attributes:
        weinberg_k: Weinberg's K for a in m/s².
        detector: the step detector (its parameters; its state is reset per episode).
        gyro_heading: the gyro heading integrator.
    """

    name: ClassVar[str] = "pdr-basic"
    needs: ClassVar[tuple[str, ...]] = ()
    uses: ClassVar[tuple[str, ...]] = ()

    weinberg_k: float = WEINBERG_K
    detector: PeakStepDetector = field(default_factory=PeakStepDetector)
    gyro_heading: GyroHeading = field(default_factory=GyroHeading)

    _position: NDArray[np.float64] | None = field(
        default=None, init=False, repr=False, compare=False
    )
    _steps: int = field(default=0, init=False, repr=False, compare=False)
    _estimate_time: float = field(default=0.0, init=False, repr=False, compare=False)
    _guard: SampleGuard = field(default_factory=SampleGuard, init=False, repr=False, compare=False)

    @property
    def heading(self) -> float:
        """Current walking-direction estimate, rad counter-clockwise from +x."""
        return self.gyro_heading.heading

    @property
    def estimate_time(self) -> float:
        """The time the position refers to: the last step's heel strike (else the start), s."""
        return self._estimate_time

    @property
    def step_count(self) -> int:
        """Steps detected since the episode's start."""
        return self._steps

    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """Nothing to learn: the baseline is deliberately un-calibrated."""

    def reset(self, start: StartInfo) -> None:
        self._position = np.array(start.position, dtype=float)
        self._steps = 0
        self._estimate_time = float(start.t0)
        self.detector.reset()
        self.gyro_heading.reset(start.heading)
        self._guard.reset()

    def act(self, obs: Observation) -> NDArray[np.float64]:
        if self._position is None:
            raise not_reset_error(self.name)
        obs = self._guard(obs)
        valid = obs["valid"].astype(bool)
        t = obs["t"][valid]
        acc = obs["accel"][valid]
        if not len(t):
            return self._position.copy()
        present = present_streams(obs)
        up = (
            obs["gravity"][valid] if present["gravity"] else np.broadcast_to(acc.mean(0), acc.shape)
        )
        # A missing gyroscope arrives as zeros: the heading then holds.
        self.gyro_heading.update(t, obs["gyro"][valid], up)
        steps = self.detector.update(t, acc)
        if steps:
            self._steps += len(steps)
            phi = self.gyro_heading.at([s.t for s in steps])
            length = weinberg([s.a_max for s in steps], [s.a_min for s in steps], self.weinberg_k)
            self._position += np.array([length @ np.cos(phi), length @ np.sin(phi)])
            self._estimate_time = steps[-1].t - self.detector.delay_s
        return self._position.copy()


@register("wknn-mag")
@dataclass(kw_only=True)
class WknnMag:
    """Magnetic WKNN per window against the grid survey's (mag_x, mag_y, mag_z).

    The window's fresh magnetometer samples are rotated to the world by the
    phone's fused rotation vector — Android's frame: magnetic east, north, up,
    the frame of the grid survey's columns — averaged, and matched by
    :class:`~indoorsim.estimators.fingerprint.WKNN`. No motion model: each
    window stands alone.

    Missing streams: without a magnetometer or a rotation vector, or in a
    window with no fresh magnetometer sample, the previous answer holds
    (the start position at first).

    Attributes:
        k: neighbours of the WKNN.
        survey: name of the fingerprint database to use; None takes the
            site's database with a ``grid`` table (the only one, or the first
            in name order).
    """

    name: ClassVar[str] = "wknn-mag"
    needs: ClassVar[tuple[str, ...]] = ("grid survey",)
    uses: ClassVar[tuple[str, ...]] = ()

    k: int = 4
    survey: str | None = None

    _knn: WKNN | None = field(default=None, init=False, repr=False, compare=False)
    _position: NDArray[np.float64] | None = field(
        default=None, init=False, repr=False, compare=False
    )
    _guard: SampleGuard = field(default_factory=SampleGuard, init=False, repr=False, compare=False)

    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None:
        """Index the grid survey's magnetic fingerprints.

        Raises:
            ValueError: if the site has no grid survey (or not the one named).
        """
        table = self._grid_table(site)
        self._knn = WKNN(k=self.k).fit(table[_MAG_COLUMNS].to_numpy(), table[["x", "y"]].to_numpy())

    def _grid_table(self, site: SiteContext) -> pd.DataFrame:
        grids = {name: db for name, db in sorted(site.fingerprints.items()) if "grid" in db.tables}
        if self.survey is not None:
            grids = {self.survey: grids[self.survey]} if self.survey in grids else {}
        if not grids:
            wanted = f"a grid survey named {self.survey!r}" if self.survey else "a grid survey"
            raise NotApplicableError(
                f"{self.name} needs {wanted} (a fingerprint database with a 'grid' table of "
                f"{', '.join(_MAG_COLUMNS)}); site {site.name!r} has "
                f"{sorted(site.fingerprints) or 'no fingerprint databases'}"
            )
        table = next(iter(grids.values()))["grid"]
        missing = [c for c in ["x", "y", *_MAG_COLUMNS] if c not in table.columns]
        if missing:
            raise ValueError(f"{self.name}: the grid survey lacks columns {missing}")
        return table

    def reset(self, start: StartInfo) -> None:
        self._position = np.array(start.position, dtype=float)
        self._guard.reset()

    def act(self, obs: Observation) -> NDArray[np.float64]:
        if self._knn is None:
            raise RuntimeError(
                f"{self.name}: call fit(site, train) first (it needs the grid survey)"
            )
        if self._position is None:
            raise not_reset_error(self.name)
        field_geo = geomagnetic_mean(self._guard(obs))
        if field_geo is None:
            return self._position.copy()
        self._position = self._knn.predict(field_geo[None, :])[0]
        return self._position.copy()
