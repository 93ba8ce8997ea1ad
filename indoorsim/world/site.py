"""Site: a scenario's floor plan together with its physical fields.

This is the public face of the world model (DESIGN §4)::

    site = indoorsim.load_site("han2023_corridor")   # a bundled name or a YAML path
    site.magnetic_field(points)          # (N, 3) µT, building frame, Earth + dipoles
    site.illuminance(points, normals)    # (N,) lux on receivers with unit normals
    site.rss(points)                     # (N, n_ap) mean dBm (small_scale=True: + multipath)
    site.plan.crosses_wall(p0, p1)       # (N,) bool for N segments
    site.plan.is_walkable(points)        # (N,) bool
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.scenario.schema import Scenario
from indoorsim.world.body_shadow import BodyShadow
from indoorsim.world.light import LightModel
from indoorsim.world.magnetic import MagneticModel
from indoorsim.world.plan import plan_for
from indoorsim.world.radio import RadioModel


class Site:
    """A loaded building: geometry (``plan``), fields (``magnetic``, ``light``, ``radio``)."""

    def __init__(self, scenario: Scenario):
        self.scenario = scenario
        self.plan = plan_for(scenario)  # the plan that validated it, when just loaded
        self.magnetic = MagneticModel.from_scenario(scenario, self.plan)
        self.light = LightModel(scenario, self.plan)
        self.radio = RadioModel(scenario, self.plan)

    @property
    def name(self) -> str:
        return self.scenario.name

    @property
    def magnetic_declination_deg(self) -> float:
        """Magnetic north, degrees clockwise (east) of true north, from this site's Earth field.

        Read off the field the site actually uses (IGRF, or the scenario's
        explicit ``earth_field_uT``), so a phone's rotation vector — aligned
        with that field — converts to the building frame consistently.
        """
        b = self.magnetic.earth_field_uT
        theta = math.degrees(math.atan2(b[1], b[0]))  # magnetic north, CCW from building +x
        # True north lies at 90° + north_deg (CCW from +x); declination is clockwise from it.
        return (90.0 + self.scenario.site.north_deg - theta + 180.0) % 360.0 - 180.0

    def magnetic_field(self, points: ArrayLike) -> NDArray[np.float64]:
        """(N, 3) magnetic flux density in µT, building frame, at (N, 3) points."""
        return self.magnetic.field(_finite_rows(points, "points"))

    def illuminance(
        self,
        points: ArrayLike,
        normals: ArrayLike,
        body: BodyShadow | None = None,
        response_exponent: float = 1.0,
    ) -> NDArray[np.float64]:
        """(N,) illuminance in lux on receivers at (N, 3) points with (N, 3) unit normals,
        shaded by the carrier's ``body`` at each receiver when given, as a receiver of
        angular response cosᵏψ reads it (k = ``response_exponent``; 1 is a true meter)."""
        p = _finite_rows(points, "points")
        n = _finite_rows(normals, "normals")
        if len(n) != len(p):
            raise ValueError(f"normals: {len(n)} rows for {len(p)} points")
        return self.light.illuminance(p, n, body, response_exponent)

    def rss(self, points: ArrayLike, *, small_scale: bool = False) -> NDArray[np.float64]:
        """(N, n_ap) received power in dBm at (N, 3) points: the local mean, or with
        ``small_scale`` the multipath fade at exactly these points too (what a phone
        there samples; no per-scan variation either way)."""
        return self.radio.rss(_finite_rows(points, "points"), small_scale=small_scale)

    def __repr__(self) -> str:
        return f"Site({self.name!r})"


def _finite_rows(values: ArrayLike, name: str) -> NDArray[np.float64]:
    """``values`` as an (N, 3) float array, or ValueError naming ``name`` and the bad row.

    The field models index grids with the coordinates, so a NaN would otherwise
    fail deep inside them (or silently give NaN).
    """
    a = np.asarray(values, dtype=float)
    if a.ndim == 1 and a.shape == (3,):
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (N, 3), got {np.shape(values)}")
    finite = np.isfinite(a).all(axis=1)
    if not finite.all():
        row = int(np.argmin(finite))
        raise ValueError(f"{name}: row {row} is not finite: {a[row].tolist()}")
    return a
