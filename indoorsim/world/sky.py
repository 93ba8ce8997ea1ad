"""Daylight outside the building and through its windows: the sun, the sky, the glazing.

* **The sun's position** at the walk's local time on the site's date, from
  pvlib's NREL solar position algorithm, turned into the building frame
  (``site.north_deg``).
* **The sky's luminance** by direction: a CIE standard general sky (ISO
  15469:2004 / CIE S 011): relative luminance L/L_z = f(χ)·φ(Z) / (f(Z_s)·φ(0)),
  with the gradation φ(Z) = 1 + a·exp(b / cos Z) over the zenith angle Z and the
  indicatrix f(χ) = 1 + c·(exp(d·χ) − exp(d·π/2)) + e·cos²χ over the angle χ
  from the sun. Overcast is type 1 (the CIE standard overcast sky, three times
  brighter at the zenith than at the horizon), intermediate type 10, clear
  type 12.
* **How bright** (IES RP-21, "Calculation of daylight availability", 1984):
  the sky's horizontal illuminance E_kh = A + B·sin^C α (klx) over the sun's
  altitude α, and the sun's normal illuminance E_dn = E_xt·exp(−c·m), E_xt the
  extraterrestrial 127.5 klx corrected for the Earth's orbit, m the relative air
  mass, c the extinction of the sky type. The sky's zenith luminance is what
  gives its distribution that E_kh. Below the horizon directions see the
  ground, a Lambertian surface of luminance ρ_g·(E_kh + E_dn·sin α)/π. After
  sunset there is no daylight at all (twilight is left out).
* **The glazing**: the transmittance τ at normal incidence falls at oblique
  incidence as for ``panes`` uncoated panes of glass (Fresnel's equations per
  polarisation, incoherent reflections between the 2·panes faces; absorption
  is in τ).
* **The sunbeam** (:func:`sun_illuminance`): a receiver is in the sun when the
  straight line from it toward the sun leaves the building through glazing
  below the ceiling; walls and pillars (floor to ceiling) block it, windows
  pass it between sill and head.

The windows themselves, as sources of skylight, are cut into patches in
:mod:`indoorsim.world.light`, whose direct-term kernel looks up the sky's
luminance through each patch with :func:`sky_luminance`.

Not modelled: other buildings and the building's own wings outside a window
(every window sees open sky and ground), window reveals, blinds, twilight.
"""

from __future__ import annotations

import dataclasses
import datetime
import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numba
import numpy as np
from numpy.typing import NDArray
from shapely.geometry import LineString, Point, Polygon

from indoorsim.world.body_shadow import NO_BODY, BodyShadow, body_blocks
from indoorsim.world.plan import crosses_properly

if TYPE_CHECKING:
    from indoorsim.scenario.schema import DaylightSpec, Scenario, SiteSpec, WallSpec, WindowSpec
    from indoorsim.world.plan import FloorPlan

__all__ = [
    "CIE_SKY_TYPES",
    "SKY_CONDITIONS",
    "SkyState",
    "WindowApertures",
    "glazing_factor",
    "sky_luminance",
    "sun_illuminance",
]

CIE_SKY_TYPES: dict[int, tuple[float, float, float, float, float]] = {
    1: (4.0, -0.70, 0.0, -1.0, 0.00),  # CIE standard overcast, steep gradation
    2: (4.0, -0.70, 2.0, -1.5, 0.15),
    3: (1.1, -0.80, 0.0, -1.0, 0.00),
    4: (1.1, -0.80, 2.0, -1.5, 0.15),
    5: (0.0, -1.00, 0.0, -1.0, 0.00),  # uniform luminance
    6: (0.0, -1.00, 2.0, -1.5, 0.15),
    7: (0.0, -1.00, 5.0, -2.5, 0.30),
    8: (0.0, -1.00, 10.0, -3.0, 0.45),
    9: (-1.0, -0.55, 2.0, -1.5, 0.15),
    10: (-1.0, -0.55, 5.0, -2.5, 0.30),  # partly cloudy, brighter circumsolar region
    11: (-1.0, -0.55, 10.0, -3.0, 0.45),
    12: (-1.0, -0.32, 10.0, -3.0, 0.45),  # CIE standard clear sky, low turbidity
    13: (-1.0, -0.32, 16.0, -3.0, 0.30),
    14: (-1.0, -0.15, 16.0, -3.0, 0.30),
    15: (-1.0, -0.15, 24.0, -2.8, 0.15),
}
"""The gradation (a, b) and indicatrix (c, d, e) parameters of ISO 15469's 15 skies."""


@dataclass(frozen=True)
class SkyCondition:
    """A weather: its CIE sky type and its IES RP-21 daylight availability.

    Attributes:
        cie_type: key of :data:`CIE_SKY_TYPES`.
        sky_klx: (A, B, C) of the sky's horizontal illuminance A + B·sin^C α, klx.
        extinction: the atmosphere's extinction coefficient c of the sunbeam;
            ``None`` where the sun is hidden.
    """

    cie_type: int
    sky_klx: tuple[float, float, float]
    extinction: float | None


SKY_CONDITIONS: dict[str, SkyCondition] = {
    "overcast": SkyCondition(1, (0.3, 21.0, 1.0), None),
    "intermediate": SkyCondition(10, (0.3, 45.0, 1.0), 0.80),
    "clear": SkyCondition(12, (0.8, 15.5, 0.5), 0.21),
}
"""The weathers of ``DaylightSpec.sky`` (``uniform`` aside), IES RP-21's three."""

EXTRATERRESTRIAL_LUX = 127_500.0
"""The sun's illuminance outside the atmosphere at the mean Earth–sun distance (IES)."""

GLASS_INDEX = 1.52
"""Refractive index of soda-lime window glass."""

# Directions of a Fibonacci sphere for the integrals over the sky and over a
# window's outward hemisphere (about 0.5 % from the exact integrals).
_SPHERE_POINTS = 8192


@dataclass(frozen=True, kw_only=True)
class SkyState:
    """The daylight outside at one moment: the sky, the ground and the sun.

    Attributes:
        cie: (a, b, c, d, e) of the sky's luminance distribution.
        zenith_luminance: L_z, cd/m².
        sun: (3,) unit vector toward the sun in the building frame.
        sun_normal_lux: the sunbeam's illuminance on a plane facing it, lx (0
            when the sun is hidden or down).
        ground_luminance: the ground's luminance, cd/m².
        transmittance: the glazing's visible transmittance at normal incidence.
        panes: panes of glass (the oblique-incidence fall-off).
        daytime: whether the sun is above the horizon (no daylight otherwise).
    """

    cie: tuple[float, float, float, float, float]
    zenith_luminance: float
    sun: NDArray[np.float64]
    sun_normal_lux: float
    ground_luminance: float
    transmittance: float
    panes: int
    daytime: bool

    @classmethod
    def from_spec(cls, site: SiteSpec, daylight: DaylightSpec) -> SkyState:
        """The daylight of ``daylight`` at ``site`` on its date."""
        if daylight.sky == "uniform":
            luminance = daylight.exterior_vertical_lux / math.pi
            return cls(
                cie=CIE_SKY_TYPES[5],
                zenith_luminance=luminance,
                sun=np.array([0.0, 0.0, 1.0]),
                sun_normal_lux=0.0,
                ground_luminance=luminance,
                transmittance=daylight.transmittance,
                panes=daylight.panes,
                daytime=True,
            )
        altitude, azimuth, air_mass = sun_position(site, daylight)
        condition = SKY_CONDITIONS[daylight.sky]
        # The azimuth is clockwise from true north; the building's +y is
        # north_deg clockwise from north and its +x a right angle further.
        bearing = math.radians(azimuth - site.north_deg)
        alt = math.radians(altitude)
        sun = np.array(
            [math.cos(alt) * math.sin(bearing), math.cos(alt) * math.cos(bearing), math.sin(alt)]
        )
        # The sky's shape with a unit zenith luminance, from which the rest is scaled.
        relative = cls(
            cie=CIE_SKY_TYPES[condition.cie_type],
            zenith_luminance=1.0,
            sun=sun,
            sun_normal_lux=0.0,
            ground_luminance=0.0,
            transmittance=daylight.transmittance,
            panes=daylight.panes,
            daytime=True,
        )
        if altitude <= 0.0:
            return dataclasses.replace(relative, zenith_luminance=0.0, daytime=False)
        a, b, c = condition.sky_klx
        sky_lux = 1000.0 * (a + b * math.sin(alt) ** c)
        day = site.date.timetuple().tm_yday
        extraterrestrial = EXTRATERRESTRIAL_LUX * (
            1 + 0.034 * math.cos(2 * math.pi * (day - 2) / 365)
        )
        sun_lux = 0.0
        if condition.extinction is not None:
            sun_lux = extraterrestrial * math.exp(-condition.extinction * air_mass)
        return dataclasses.replace(
            relative,
            zenith_luminance=sky_lux / relative.horizontal_sky_lux(),
            sun_normal_lux=sun_lux,
            ground_luminance=daylight.ground_reflectance * (sky_lux + sun_lux * sun[2]) / math.pi,
        )

    @cached_property
    def kernel_args(self) -> NDArray[np.float64]:
        """The state as the flat array :func:`sky_luminance` reads."""
        a, b, c, d, e = self.cie
        cos_zs = min(max(float(self.sun[2]), -1.0), 1.0)
        zs = math.acos(cos_zs)
        # f(Z_s)·φ(0): the relative distribution is 1 at the zenith.
        norm = _indicatrix(zs, c, d, e) * (1.0 + a * math.exp(b))
        return np.array(
            [
                a,
                b,
                c,
                d,
                e,
                self.zenith_luminance,
                *self.sun,
                norm,
                self.ground_luminance,
                float(self.panes),
            ]
        )

    def luminance(self, directions: NDArray[np.float64]) -> NDArray[np.float64]:
        """(N,) luminance, cd/m², seen looking along (N, 3) unit ``directions``
        (the sky above the horizon, the ground below)."""
        u = np.asarray(directions, dtype=float).reshape(-1, 3)
        out = np.empty(len(u))
        _luminances(np.ascontiguousarray(u), self.kernel_args, out)
        return out

    def horizontal_sky_lux(self) -> float:
        """The sky's illuminance on an unobstructed horizontal plane, lx: ∫ L cos Z dΩ."""
        u = _fibonacci_sphere(_SPHERE_POINTS)
        up = u[u[:, 2] > 0]
        return float(np.sum(self.luminance(up) * up[:, 2]) * 4 * math.pi / _SPHERE_POINTS)

    def pane_lux(self, outward: NDArray[np.float64]) -> float:
        """Illuminance, lx, behind a pane whose outward unit normal is ``outward``: what
        reaches its inner face from the sky, the ground and the sun, through the glazing."""
        n = np.asarray(outward, dtype=float)
        u = _fibonacci_sphere(_SPHERE_POINTS)
        cos_t = u @ n
        front = cos_t > 0
        seen = self.luminance(u[front]) * glazing_factor(cos_t[front], self.panes) * cos_t[front]
        sky = float(np.sum(seen) * 4 * math.pi / _SPHERE_POINTS)
        cos_sun = float(self.sun @ n)
        sun = 0.0
        if self.sun_normal_lux > 0.0 and cos_sun > 0.0:
            sun = self.sun_normal_lux * float(glazing_factor(np.array([cos_sun]), self.panes)[0])
            sun *= cos_sun
        return self.transmittance * (sky + sun)


def sun_position(site: SiteSpec, daylight: DaylightSpec) -> tuple[float, float, float]:
    """The sun's apparent altitude and azimuth (degrees; azimuth clockwise from true
    north) and the relative air mass (Kasten & Young), at ``daylight.time`` local
    clock time on ``site.date`` (pvlib's NREL SPA)."""
    import pandas as pd
    import pvlib

    offset = daylight.utc_offset_h
    if offset is None:
        offset = round(site.longitude / 15.0)
    zone = datetime.timezone(datetime.timedelta(hours=offset))
    when = pd.DatetimeIndex([datetime.datetime.combine(site.date, daylight.time, tzinfo=zone)])
    position = pvlib.solarposition.get_solarposition(
        when, site.latitude, site.longitude, altitude=1000.0 * site.altitude_km
    )
    altitude = float(position["apparent_elevation"].iloc[0])
    azimuth = float(position["azimuth"].iloc[0])
    air_mass = math.inf
    if altitude > 0.0:
        air_mass = float(
            pvlib.atmosphere.get_relative_airmass(90.0 - altitude, model="kastenyoung1989")
        )
    return altitude, azimuth, air_mass


def _indicatrix(chi: float, c: float, d: float, e: float) -> float:
    return 1.0 + c * (math.exp(d * chi) - math.exp(d * math.pi / 2)) + e * math.cos(chi) ** 2


def _fibonacci_sphere(n: int) -> NDArray[np.float64]:
    """``n`` nearly evenly spread unit vectors (each stands for 4π/n sr)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - z * z)
    phi = math.pi * (3.0 - math.sqrt(5.0)) * k
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


@numba.njit(cache=True, inline="always", error_model="numpy")
def sky_luminance(ux, uy, uz, sky):  # pragma: no cover - compiled
    """Luminance, cd/m², looking along the unit vector (ux, uy, uz) out of the
    building: the CIE sky above the horizon, the ground below (``sky`` is
    :attr:`SkyState.kernel_args`)."""
    if uz <= 0.0:
        return sky[10]
    a, b, c, d, e = sky[0], sky[1], sky[2], sky[3], sky[4]
    gradation = 1.0 + a * math.exp(b / max(uz, 1e-9))
    cos_chi = min(max(ux * sky[6] + uy * sky[7] + uz * sky[8], -1.0), 1.0)
    chi = math.acos(cos_chi)
    indicatrix = 1.0 + c * (math.exp(d * chi) - math.exp(d * math.pi / 2)) + e * cos_chi * cos_chi
    return sky[5] * indicatrix * gradation / sky[9]


@numba.njit(cache=True, error_model="numpy")
def _luminances(u, sky, out):  # pragma: no cover - compiled
    for i in range(u.shape[0]):
        out[i] = sky_luminance(u[i, 0], u[i, 1], u[i, 2], sky)


@numba.njit(cache=True, inline="always", error_model="numpy")
def glazing_transmission(cos_t, panes):  # pragma: no cover - compiled
    """The glazing's transmittance at incidence cos θ = ``cos_t`` relative to normal
    incidence: ``panes`` lossless panes of index :data:`GLASS_INDEX`, unpolarised
    light, incoherent reflections between the faces, T = (1 − r)/(1 + (2N − 1)·r)
    per polarisation with r Fresnel's reflectance of one face."""
    c = min(max(cos_t, 0.0), 1.0)
    if c == 0.0:
        return 0.0
    n = GLASS_INDEX
    ct = math.sqrt(max(1.0 - (1.0 - c * c) / (n * n), 0.0))
    rs = ((c - n * ct) / (c + n * ct)) ** 2
    rp = ((ct - n * c) / (ct + n * c)) ** 2
    k = 2.0 * panes - 1.0
    t = 0.5 * ((1.0 - rs) / (1.0 + k * rs) + (1.0 - rp) / (1.0 + k * rp))
    r0 = ((n - 1.0) / (n + 1.0)) ** 2
    return t / ((1.0 - r0) / (1.0 + k * r0))


@numba.njit(cache=True, error_model="numpy")
def _glazing_each(cos_t, panes, out):  # pragma: no cover - compiled
    for i in range(cos_t.shape[0]):
        out[i] = glazing_transmission(cos_t[i], panes)


def glazing_factor(cos_t: NDArray[np.float64], panes: int) -> NDArray[np.float64]:
    """(N,) :func:`glazing_transmission` at incidence cosines ``cos_t``."""
    c = np.ascontiguousarray(np.asarray(cos_t, dtype=float).ravel())
    out = np.empty(len(c))
    _glazing_each(c, float(panes), out)
    return out


# ------------------------------------------------------------------ windows


@dataclass(frozen=True, kw_only=True)
class WindowApertures:
    """The exterior windows of a floor: where daylight comes in.

    Attributes:
        start, end: (W, 2) ends of each window on its wall, m.
        sill, head: (W,) heights of its bottom and top, m.
        inward: (W, 2) unit normal of its wall pointing into the building.
        half_thickness: (W,) half its wall's thickness, m.
    """

    start: NDArray[np.float64]
    end: NDArray[np.float64]
    sill: NDArray[np.float64]
    head: NDArray[np.float64]
    inward: NDArray[np.float64]
    half_thickness: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.start)

    @classmethod
    def of(cls, scenario: Scenario, outline: Polygon) -> WindowApertures:
        """The windows of ``scenario`` with the building on exactly one side (inside
        ``outline``); internal glazing and windows out on their own are left out."""
        rows = []
        for window in scenario.windows:
            wall = _host_wall(window, scenario.walls)
            p0, p1 = np.asarray(window.start, float), np.asarray(window.to, float)
            u = (p1 - p0) / float(np.linalg.norm(p1 - p0))
            inward = _inward_normal(outline, (p0 + p1) / 2, u, wall.thickness)
            if inward is not None:
                rows.append((p0, p1, window.sill, window.head, inward, wall.thickness / 2))
        if not rows:
            z2, z = np.zeros((0, 2)), np.zeros(0)
            return cls(start=z2, end=z2, sill=z, head=z, inward=z2, half_thickness=z)
        p0, p1, sill, head, inward, half = zip(*rows, strict=True)
        return cls(
            start=np.array(p0),
            end=np.array(p1),
            sill=np.array(sill, float),
            head=np.array(head, float),
            inward=np.array(inward),
            half_thickness=np.array(half, float),
        )


# How far beyond the wall surface we probe to tell the building's inside from outside.
_PROBE_M = 0.05


def _host_wall(window: WindowSpec, walls: list[WallSpec]) -> WallSpec:
    """The wall whose solid holds both ends of ``window`` (the scenario checks one exists)."""
    for wall in walls:
        line = LineString([wall.start, wall.to])
        if all(
            line.distance(Point(end)) <= wall.thickness / 2 + 1e-6
            for end in (window.start, window.to)
        ):
            return wall
    raise ValueError(f"window {window.start}→{window.to} does not lie on any wall")


def _inward_normal(
    outline: Polygon, mid: NDArray[np.float64], u: NDArray[np.float64], thickness: float
) -> NDArray[np.float64] | None:
    """The unit normal of a wall with direction ``u`` pointing into the building, if unique."""
    normal = np.array([-u[1], u[0]])
    probe = thickness / 2 + _PROBE_M
    inside = [outline.contains(Point(*(mid + s * probe * normal))) for s in (1.0, -1.0)]
    if inside == [True, False]:
        return normal
    if inside == [False, True]:
        return -normal
    return None


# ------------------------------------------------------------------ the sunbeam


def sun_illuminance(
    sky: SkyState,
    points: NDArray[np.float64],
    normals: NDArray[np.float64],
    plan: FloorPlan,
    windows: WindowApertures,
    ceiling_height: float,
    body: BodyShadow | None = None,
    response_exponent: float = 1.0,
) -> NDArray[np.float64]:
    """(N,) illuminance, lx, of the sunbeam on receivers (unit ``normals``).

    E = E_dn·Π τ_k·max(0, n̂·ŝ)ᵏ where the ray from the receiver toward the
    sun ŝ leaves the building, before it climbs to the ceiling, through one of
    ``windows`` between its sill and head (τ·:func:`glazing_transmission`),
    crossing nothing but glass walls on the way (their material's
    transmittance). Any other wall or pillar in the way, the ceiling, or the
    carrier's ``body`` shades it (the sun's half-degree disc casts a sharp
    shadow).
    """
    out = np.zeros(len(points))
    if sky.sun_normal_lux <= 0.0 or not sky.daytime:
        return out
    sa, sb, elem, transmittance = plan.light_occluders
    _sunbeam(
        np.ascontiguousarray(points, dtype=float),
        np.ascontiguousarray(normals, dtype=float),
        np.ascontiguousarray(sky.sun, dtype=float),
        float(sky.sun_normal_lux),
        float(sky.transmittance),
        float(sky.panes),
        np.ascontiguousarray(sa, dtype=float),
        np.ascontiguousarray(sb, dtype=float),
        np.ascontiguousarray(elem, dtype=np.intp),
        np.ascontiguousarray(transmittance, dtype=float),
        np.ascontiguousarray(windows.start, dtype=float).reshape(-1, 2),
        np.ascontiguousarray(windows.end, dtype=float).reshape(-1, 2),
        np.ascontiguousarray(windows.sill, dtype=float),
        np.ascontiguousarray(windows.head, dtype=float),
        np.ascontiguousarray(windows.inward, dtype=float).reshape(-1, 2),
        np.ascontiguousarray(windows.half_thickness, dtype=float),
        float(ceiling_height),
        float(response_exponent),
        body is not None,
        body.kernel_args if body is not None else NO_BODY,
        out,
    )
    return out


# The body test's far end along the sunbeam, m: beyond the carrier's reach.
_SUN_PROBE_M = 10.0


@numba.njit(cache=True, error_model="numpy")
def _sunbeam(
    p,
    n,
    sun,
    sun_lux,
    tau,
    panes,
    sa,
    sb,
    elem,
    transmittance,
    wa,
    wb,
    sill,
    head,
    inward,
    half,
    ceiling,
    response,
    has_body,
    body,
    out,
):  # pragma: no cover - compiled
    """The loop of :func:`sun_illuminance`, one receiver at a time.

    Along the ray's plan, up to where it climbs to the ceiling, the nearest
    crossing of an exterior window (between sill and head) is where it leaves
    the building; it is lit when no opaque crossing comes first, through the
    glass walls it crosses before that. Beyond the window the sky is open.
    """
    horizontal = math.sqrt(sun[0] * sun[0] + sun[1] * sun[1])
    if horizontal < 1e-9:
        return  # the sun straight overhead: the ceiling shades every receiver
    hx, hy = sun[0] / horizontal, sun[1] / horizontal
    rise = sun[2] / horizontal  # height gained per metre along the plan
    for i in range(p.shape[0]):
        facing = n[i, 0] * sun[0] + n[i, 1] * sun[1] + n[i, 2] * sun[2]
        if facing <= 0.0 or p[i, 2] >= ceiling:
            continue
        reach = (ceiling - p[i, 2]) / rise  # plan distance to the ceiling's height
        x0, y0 = p[i, 0], p[i, 1]
        x1, y1 = x0 + reach * hx, y0 + reach * hy
        exit_f, exit_w, block_f = 2.0, -1, 2.0  # fractions of the way to ``reach``
        for j in range(sa.shape[0]):
            if transmittance[elem[j]] > 0.0:
                continue
            if not crosses_properly(x0, y0, x1, y1, sa[j, 0], sa[j, 1], sb[j, 0], sb[j, 1]):
                continue
            # Where the ray meets the segment, and how high it is there.
            dx, dy = sb[j, 0] - sa[j, 0], sb[j, 1] - sa[j, 1]
            o0 = dx * (y0 - sa[j, 1]) - dy * (x0 - sa[j, 0])
            o1 = dx * (y1 - sa[j, 1]) - dy * (x1 - sa[j, 0])
            f = o0 / (o0 - o1)
            cx, cy = x0 + f * (x1 - x0), y0 + f * (y1 - y0)
            z = p[i, 2] + f * reach * rise
            through = -1
            for w in range(wa.shape[0]):
                if not sill[w] <= z <= head[w]:
                    continue
                ux, uy = wb[w, 0] - wa[w, 0], wb[w, 1] - wa[w, 1]
                length = math.sqrt(ux * ux + uy * uy)
                along = ((cx - wa[w, 0]) * ux + (cy - wa[w, 1]) * uy) / length
                across = abs((cx - wa[w, 0]) * uy - (cy - wa[w, 1]) * ux) / length
                if 0.0 <= along <= length and across <= half[w] + 1e-6:
                    through = w
                    break
            if through >= 0:
                if f < exit_f:
                    exit_f, exit_w = f, through
            elif f < block_f:
                block_f = f
        if exit_w < 0 or block_f < exit_f:
            continue
        cos_pane = abs(inward[exit_w, 0] * sun[0] + inward[exit_w, 1] * sun[1])
        t = tau * glazing_transmission(cos_pane, panes)
        for j in range(sa.shape[0]):  # glass walls on the way to the window
            if transmittance[elem[j]] == 0.0:
                continue
            if not crosses_properly(x0, y0, x1, y1, sa[j, 0], sa[j, 1], sb[j, 0], sb[j, 1]):
                continue
            dx, dy = sb[j, 0] - sa[j, 0], sb[j, 1] - sa[j, 1]
            o0 = dx * (y0 - sa[j, 1]) - dy * (x0 - sa[j, 0])
            o1 = dx * (y1 - sa[j, 1]) - dy * (x1 - sa[j, 0])
            if o0 / (o0 - o1) < exit_f:
                t *= transmittance[elem[j]]
        if t == 0.0:
            continue
        if has_body and body_blocks(
            x0,
            y0,
            p[i, 2],
            x0 + _SUN_PROBE_M * sun[0],
            y0 + _SUN_PROBE_M * sun[1],
            p[i, 2] + _SUN_PROBE_M * sun[2],
            i,
            body,
            0.0,
        ):
            continue
        cos_psi = facing
        if response != 1.0:
            cos_psi = cos_psi**response
        out[i] = sun_lux * t * cos_psi
