"""Han2023's geomagnetic and light fingerprint library (§2.2.2, §4.2).

The grid survey measures the magnetic field (in the survey phone's
geographic frame: magnetic east, north, up) and the illuminance at points
1.2 m apart. Han2023 densifies it by radial-basis-function interpolation,
the magnetic components and the light **at different resolutions**, and
combines them into one library of fingerprints (Mx, My, Mz, L) at positions
(x, y) (PAPER_NOTES, Han2023 item 5). The paper gives neither the
resolutions nor the kernel; the readings taken here:

* **Kernel**: SciPy's :class:`~scipy.interpolate.RBFInterpolator` with the
  thin-plate spline φ(r) = r² ln r and a degree-1 polynomial — its default,
  scale-free (no shape parameter ε to tune), the smoothest interpolant of
  scattered 2-D data in the bending-energy sense, and exact on linear fields.
* **Smoothing**: 0 by default, so the library passes through every surveyed
  value: each is a 30-s average whose noise is small beside the field's
  variation from point to point. A positive ``smoothing`` trades that for
  robustness to noisy surveys.
* **Resolutions**: magnetic 0.3 m and light 0.6 m by default. Both grids are
  anchored at the survey's lowest x and y, so with a survey spacing that is
  a multiple of the resolution (1.2 m) every surveyed point is a grid node.
* **Combination**: the magnetic grid is the library's grid. The light
  interpolant is evaluated on its own, coarser, rectangular grid, and the
  library's light value at each magnetic grid point is the bilinear
  interpolation of that grid — so the light column has the light
  resolution's detail, sampled at the magnetic points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import RBFInterpolator, RegularGridInterpolator

__all__ = ["FEATURES", "HOLDOUT_POINTS", "SURVEY_COLUMNS", "FingerprintLibrary"]

FEATURES = ("Mx", "My", "Mz", "L")
"""Library feature columns: magnetic east, north, up (µT) and illuminance (lux)."""

SURVEY_COLUMNS = {"Mx": "mag_x", "My": "mag_y", "Mz": "mag_z", "L": "lux"}
"""The grid-survey column (:func:`indoorsim.survey.grid_survey`) behind each feature."""

HOLDOUT_POINTS = 80
"""Library points held out for Han2023's static positioning test (Table 2)."""

# Grid nodes within this fraction of a cell of the bounds still count as inside.
_EPS = 1e-9


def _axis(lo: float, hi: float, anchor: float, step: float, *, cover: bool) -> NDArray[np.float64]:
    """Nodes anchor + k·step inside [lo, hi] or, with ``cover``, just covering it."""
    k0 = (lo - anchor) / step
    k1 = (hi - anchor) / step
    if cover:
        first, last = math.floor(k0 + _EPS), math.ceil(k1 - _EPS)
    else:
        first, last = math.ceil(k0 - _EPS), math.floor(k1 + _EPS)
    return anchor + step * np.arange(first, last + 1)


@dataclass(kw_only=True)
class FingerprintLibrary:
    """Fingerprint library interpolated from a grid survey (module docstring).

    After :meth:`fit`, :attr:`table` holds one row per library point with
    columns ``x``, ``y`` (building frame, m) and :data:`FEATURES`.

    Attributes:
        mag_resolution: spacing of the magnetic (and library) grid, m.
        light_resolution: spacing of the light grid, m.
        kernel: an :class:`~scipy.interpolate.RBFInterpolator` kernel.
        smoothing: RBF smoothing; 0 interpolates the survey exactly.
        epsilon: RBF shape parameter, for the kernels that need one
            (``gaussian``, ``multiquadric``, …); ``None`` otherwise.
        neighbors: survey points per RBF evaluation (local RBF for large
            surveys); ``None`` uses all of them.
    """

    mag_resolution: float = 0.3
    light_resolution: float = 0.6
    kernel: str = "thin_plate_spline"
    smoothing: float = 0.0
    epsilon: float | None = None
    neighbors: int | None = None

    table: pd.DataFrame = field(init=False, repr=False, compare=False)
    light_grid_x: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    light_grid_y: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    light_grid: NDArray[np.float64] = field(init=False, repr=False, compare=False)

    _mag: RBFInterpolator | None = field(default=None, init=False, repr=False, compare=False)
    _light: RegularGridInterpolator | None = field(
        default=None, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        if not (self.mag_resolution > 0 and self.light_resolution > 0):
            raise ValueError(
                "resolutions must be positive, got "
                f"{self.mag_resolution} (magnetic) and {self.light_resolution} (light)"
            )

    def _rbf(self, points: NDArray[np.float64], values: NDArray[np.float64]) -> RBFInterpolator:
        return RBFInterpolator(
            points,
            values,
            kernel=self.kernel,
            smoothing=self.smoothing,
            epsilon=self.epsilon,
            neighbors=self.neighbors,
        )

    def fit(self, survey: pd.DataFrame, plan_like: Any) -> FingerprintLibrary:
        """Interpolate a grid survey onto the library points.

        Args:
            survey: the grid-survey table: ``x``, ``y`` and the columns of
                :data:`SURVEY_COLUMNS`. Rows with a NaN magnetic or light
                value are left out of that quantity's interpolant.
            plan_like: where the library lives. Either a floor plan (anything
                with ``bounds`` = (xmin, ymin, xmax, ymax) and
                ``is_walkable(points)``): the library points are the
                walkable nodes of the magnetic grid inside the bounds; or an
                (M, 2) array: the library points themselves (the caller's
                walkable grid, whose spacing is then the magnetic resolution).

        Returns:
            self.
        """
        missing = {"x", "y", *SURVEY_COLUMNS.values()} - set(survey.columns)
        if missing:
            raise ValueError(f"the survey table lacks columns {sorted(missing)}")
        xy = survey[["x", "y"]].to_numpy(dtype=float)
        mag = survey[[SURVEY_COLUMNS[f] for f in FEATURES[:3]]].to_numpy(dtype=float)
        lux = survey[SURVEY_COLUMNS["L"]].to_numpy(dtype=float)
        anchor = xy.min(axis=0)
        points = self._library_points(plan_like, anchor)
        mag_ok = np.isfinite(mag).all(axis=1)
        lux_ok = np.isfinite(lux)
        self._mag = self._rbf(xy[mag_ok], mag[mag_ok])
        # The light grid covers the library and the survey, so both can be looked up.
        extent = np.vstack([points, xy])
        lo, hi = extent.min(axis=0), extent.max(axis=0)
        gx = _axis(lo[0], hi[0], anchor[0], self.light_resolution, cover=True)
        gy = _axis(lo[1], hi[1], anchor[1], self.light_resolution, cover=True)
        nodes = np.column_stack([a.ravel() for a in np.meshgrid(gx, gy, indexing="ij")])
        light = self._rbf(xy[lux_ok], lux[lux_ok])(nodes).reshape(len(gx), len(gy))
        self.light_grid_x, self.light_grid_y, self.light_grid = gx, gy, light
        self._light = RegularGridInterpolator(
            (gx, gy), light, method="linear", bounds_error=False, fill_value=None
        )
        features = self.features_at(points)
        self.table = pd.DataFrame(
            {"x": points[:, 0], "y": points[:, 1], **dict(zip(FEATURES, features.T, strict=True))}
        )
        return self

    def _library_points(self, plan_like: Any, anchor: NDArray[np.float64]) -> NDArray[np.float64]:
        """(M, 2) library points: the given array, or the plan's walkable magnetic-grid nodes."""
        if hasattr(plan_like, "is_walkable") and hasattr(plan_like, "bounds"):
            x0, y0, x1, y1 = plan_like.bounds
            gx = _axis(x0, x1, anchor[0], self.mag_resolution, cover=False)
            gy = _axis(y0, y1, anchor[1], self.mag_resolution, cover=False)
            grid = np.column_stack([a.ravel() for a in np.meshgrid(gx, gy, indexing="xy")])
            points = grid[np.asarray(plan_like.is_walkable(grid), dtype=bool)]
        else:
            points = np.asarray(plan_like, dtype=float)
            if points.ndim != 2 or points.shape[1] != 2:
                raise ValueError(
                    "plan_like must be a plan (bounds, is_walkable) or an (M, 2) array of "
                    f"points, got an array of shape {points.shape}"
                )
        if not len(points):
            raise ValueError("no library points: the plan has no walkable grid node")
        return points

    def features_at(self, points: ArrayLike) -> NDArray[np.float64]:
        """(M, 4) fingerprints (Mx, My, Mz, L) at any points (M, 2), as the library computes them.

        Mx, My, Mz come from the magnetic RBF at the points; L is the bilinear
        interpolation of the light grid (extrapolated linearly beyond it).
        """
        if self._mag is None or self._light is None:
            raise RuntimeError("FingerprintLibrary is not fitted: call fit(survey, plan_like)")
        p = np.atleast_2d(np.asarray(points, dtype=float))
        return np.column_stack([self._mag(p), self._light(p)])

    def holdout(self, n: int, rng: np.random.Generator) -> tuple[pd.DataFrame, pd.DataFrame]:
        """Split ``n`` random library points off for testing (Han2023 Table 2: 80 points).

        Args:
            n: points to hold out (:data:`HOLDOUT_POINTS` in the paper).
            rng: the run's random generator.

        Returns:
            (train, test): the other library rows and the ``n`` held-out rows,
            each in library order with a fresh index.
        """
        if not hasattr(self, "table"):
            raise RuntimeError("FingerprintLibrary is not fitted: call fit(survey, plan_like)")
        if not 0 <= n <= len(self.table):
            raise ValueError(f"cannot hold out {n} of {len(self.table)} library points")
        test = np.zeros(len(self.table), dtype=bool)
        test[rng.choice(len(self.table), size=n, replace=False)] = True
        return (
            self.table[~test].reset_index(drop=True),
            self.table[test].reset_index(drop=True),
        )
