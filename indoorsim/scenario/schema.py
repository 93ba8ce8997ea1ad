"""The scenario schema: pydantic specs of every key of a scenario file, and its errors.

A scenario describes one building floor and what happens in it: walls, doors,
windows, pillars, furniture, ceiling lights, steel, WiFi access points, named
routes and survey plans. ``../shared/examples/minimal-site.yaml`` is the smallest
complete one; its keys keep their meaning as the schema grows.

Units: metres, degrees, cd, A·m², µT, dBm, m³. Frame: the building frame, x
along the building's +x axis, y along its +y axis (``site.north_deg`` clockwise
from true north), z up from the floor. Values far outside physical sense are
refused: positions beyond ±10 km (:data:`MAX_COORDINATE_M`), dipole moments
beyond 10⁴ A·m² (:data:`MAX_DIPOLE_MOMENT_AM2`).

This module is the bottom layer of the package (DESIGN §1): the world, walker
and phone read these specs, and it imports none of them.
"""

from __future__ import annotations

import datetime
import math
import re
from collections.abc import Iterable, Sequence
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    field_validator,
    model_validator,
)

__all__ = [
    "MAX_COORDINATE_M",
    "MAX_DIPOLE_MOMENT_AM2",
    "DoorSpec",
    "GridSurveySpec",
    "LightSpec",
    "LuminaireSpec",
    "MagneticSpec",
    "MaterialName",
    "ObstacleSpec",
    "PillarSpec",
    "RadioSpec",
    "RebarSpec",
    "RoomSpec",
    "RouteSpec",
    "Scenario",
    "ScenarioError",
    "SiteSpec",
    "WalkSurveySpec",
    "WallSpec",
    "WifiApSpec",
    "WindowSpec",
    "key_path",
]

MaterialName = Literal["concrete", "brick", "drywall", "glass", "wood", "metal", "metal_door"]
"""The wall materials of :data:`indoorsim.world.materials.MATERIALS`."""


class ScenarioError(ValueError):
    """A scenario that cannot be loaded: every problem, each with its key path.

    Attributes:
        source: the file (or other label) the scenario came from.
        problems: ``(key_path, message)`` pairs, e.g. ``("walls[2].thickness",
            "must be > 0")``.
    """

    def __init__(self, source: str, problems: Sequence[tuple[str, str]]):
        self.source = source
        self.problems = list(problems)
        lines = [
            f"{source}: {path}: {msg}" if path else f"{source}: {msg}" for path, msg in problems
        ]
        head = f"invalid scenario ({len(lines)} problem{'s' if len(lines) != 1 else ''}):"
        super().__init__("\n".join([head, *lines]) if len(lines) > 1 else lines[0])


def key_path(loc: Iterable[Any]) -> str:
    """A pydantic error location as the file's dotted key path (``walls[0].to``)."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


# --------------------------------------------------------------------------- schema

MAX_COORDINATE_M = 10_000.0
"""The largest |x|, |y| or |z| of any position in a scenario, m.

The largest buildings on one floor are about a kilometre long; 10 km leaves
room for a site whose origin is far from the building (a campus grid) while
refusing what is surely a typo or a unit mix-up (millimetres for metres,
1e9 for 1e0), which would otherwise surface as a grid of 10⁹ nodes deep in the
radio or magnetic model."""

MAX_DIPOLE_MOMENT_AM2 = 1.0e4
"""The largest |moment| of an explicit magnetic dipole, A·m².

Steel magnetised by the Earth's field (|H| ≈ 40 A/m) along its bars, at the
schema's default susceptibility 30, carries ≈ 1200 A·m² per m³: a reinforced
column's storey (0.015 m³) ≈ 18 A·m². 10⁴ A·m² is the moment of ≈ 8 m³
(≈ 65 t) of steel magnetised as one, more than any one object in a building.
Its on-axis field, μ0/4π · 2m/r³, is 2000 µT at 1 m and saturates a ±4912 µT
phone magnetometer within 0.74 m: larger moments would only clip the
magnetometer everywhere near them."""


def _within_site(value: float) -> float:
    if abs(value) > MAX_COORDINATE_M:
        raise ValueError(
            f"{value:g} m is beyond the coordinate limit: positions are metres in the "
            f"building frame, within ±{MAX_COORDINATE_M:g} m of its origin"
        )
    return value


FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]
PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegFloat = Annotated[float, Field(ge=0, allow_inf_nan=False)]


def _size_within_site(value: float) -> float:
    if value > MAX_COORDINATE_M:
        raise ValueError(
            f"{value:g} m is beyond the size limit: lengths are metres, at most "
            f"{MAX_COORDINATE_M:g} m"
        )
    return value


Length = Annotated[float, Field(gt=0, allow_inf_nan=False), AfterValidator(_size_within_site)]
"""A size of something built (a thickness, a width, a height), m: > 0 and at most
:data:`MAX_COORDINATE_M` (a wall 1e300 m thick would overflow the floor plan's geometry)."""
NonNegLength = Annotated[float, Field(ge=0, allow_inf_nan=False), AfterValidator(_size_within_site)]
Coordinate = Annotated[float, Field(allow_inf_nan=False), AfterValidator(_within_site)]
"""A position's x, y or z, m: finite and within ±:data:`MAX_COORDINATE_M`."""
Vec2 = tuple[Coordinate, Coordinate]
"""A point (x, y) in the building frame, m."""
Point3 = tuple[Coordinate, Coordinate, Coordinate]
"""A point (x, y, z) in the building frame, m."""
Vec3 = tuple[FiniteFloat, FiniteFloat, FiniteFloat]
"""A vector that is not a position (a field, a moment, a direction)."""


class _Spec(BaseModel):
    """Base: unknown keys rejected, no NaN/inf, immutable, strict about types."""

    model_config = ConfigDict(
        extra="forbid", allow_inf_nan=False, frozen=True, populate_by_name=True
    )


IGRF_FIRST_DATE = datetime.date(1900, 1, 1)
IGRF_END_DATE = datetime.date(2030, 1, 1)  # exclusive


class SiteSpec(_Spec):
    """Where the building stands and how it is oriented."""

    latitude: Annotated[float, Field(ge=-90, le=90)]
    longitude: Annotated[float, Field(ge=-180, le=180)]
    date: datetime.date
    north_deg: FiniteFloat = 0.0
    """Direction of the building's +y axis, degrees clockwise from true north."""
    ceiling_height: Length
    altitude_km: Annotated[float, Field(ge=-1, le=10)] = 0.0
    earth_field_uT: Vec3 | None = None
    """Earth field in the building frame, overriding IGRF when given."""

    @model_validator(mode="after")
    def _igrf_covers_the_date(self) -> SiteSpec:
        # IGRF-14 is defined from 1900.0 to 2030.0; outside it ppigrf extrapolates
        # (with a warning on stdout) a field that is not the Earth's.
        if self.earth_field_uT is None and not IGRF_FIRST_DATE <= self.date < IGRF_END_DATE:
            raise ValueError(
                f"date {self.date} is outside the IGRF-14 model ({IGRF_FIRST_DATE} to "
                f"{IGRF_END_DATE - datetime.timedelta(days=1)}): give 'earth_field_uT' for it"
            )
        return self


class WallSpec(_Spec):
    """A straight wall segment from floor to ceiling."""

    start: Vec2 = Field(alias="from")
    to: Vec2
    thickness: Length
    material: MaterialName = "concrete"

    @model_validator(mode="after")
    def _non_degenerate(self) -> WallSpec:
        if math.dist(self.start, self.to) < 1e-6:
            raise ValueError("zero-length wall: 'from' and 'to' are the same point")
        return self


class DoorSpec(_Spec):
    """An open doorway: a gap of ``width`` cut into the wall passing through ``position``."""

    position: Vec2
    width: Length = 0.9
    height: Length = 2.1


class WindowSpec(_Spec):
    """Glazing in a wall between ``from`` and ``to``; lets daylight in when enabled."""

    start: Vec2 = Field(alias="from")
    to: Vec2
    sill: NonNegLength = 0.9
    head: Length = 2.1

    @model_validator(mode="after")
    def _valid(self) -> WindowSpec:
        if math.dist(self.start, self.to) < 1e-6:
            raise ValueError("zero-length window: 'from' and 'to' are the same point")
        if self.head <= self.sill:
            raise ValueError(f"window head {self.head} must be above its sill {self.sill}")
        return self


class RoomSpec(_Spec):
    """A named area (office, corridor, hall): used for labels and plots."""

    name: str
    polygon: Annotated[list[Vec2], Field(min_length=3)]


class PillarSpec(_Spec):
    """A floor-to-ceiling column (rectangular), blocking walking, light and radio.

    Its reinforcing steel (``steel_volume_m3``) becomes a vertical chain of
    magnetic dipoles (see :class:`MagneticSpec`).
    """

    center: Vec2
    size: tuple[Length, Length] = (0.6, 0.6)
    rotation_deg: FiniteFloat = 0.0
    material: MaterialName = "concrete"
    steel_volume_m3: NonNegFloat = 0.015
    """Reinforcing steel per storey; the column continues through the storeys
    above and below, which carry the same amount."""
    splice_z: Annotated[float, Field(gt=0, allow_inf_nan=False)] | None = None
    """A steel column erected in two-storey lengths: the height above this floor of
    the splice between them (0.5–0.6 m is usual), where one length's magnetisation
    ends and the next one's begins. None: a concrete column, its bars lapped at
    every slab (one element per storey)."""


class ObstacleSpec(_Spec):
    """Furniture or equipment below ceiling height: blocks walking only.

    Steel furniture (cabinets, shelves) carries ``steel_volume_m3`` of steel,
    which becomes one magnetic dipole at half its height.
    """

    kind: Literal["desk", "cabinet", "shelf", "counter", "machine", "other"] = "other"
    center: Vec2
    size: tuple[Length, Length]
    rotation_deg: FiniteFloat = 0.0
    height: Length = 0.75
    steel_volume_m3: NonNegFloat = 0.0


class LuminaireSpec(_Spec):
    """A ceiling light with intensity I(θ) = intensity_cd · cosᵉˣᵖᵒⁿᵉⁿᵗ θ about its axis."""

    position: Point3
    intensity_cd: NonNegFloat
    exponent: NonNegFloat = 1.0
    axis: Vec3 = (0.0, 0.0, -1.0)
    size: tuple[NonNegLength, NonNegLength] = (0.0, 0.0)
    """The emitting face, length × width (m) across the axis: a panel 0.6 × 0.6, a
    tube 1.2 × 0.03, a downlight 0.2 × 0.2. Only the carrier's penumbra uses it;
    the photometry is the point source's."""
    along: Vec3 = (1.0, 0.0, 0.0)
    """Direction of the face's length (a tube's axis)."""
    lit: bool = True
    """Whether it is switched on. An unlit luminaire (switched off, failed, or in a
    zone switched down) gives no light, direct or reflected; it stays in the plan."""

    @field_validator("axis", "along")
    @classmethod
    def _unit_axis(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        if math.hypot(*v) < 1e-9:
            raise ValueError("must be a non-zero vector")
        return v


class DaylightSpec(_Spec):
    """Daylight through windows (off by default: the papers walked at night).

    The sky outside is a CIE standard general sky (ISO 15469) whose brightness
    follows the sun's altitude at ``time`` on ``site.date`` (IES daylight
    availability), plus the sun itself under ``clear`` and ``intermediate``
    skies; ``uniform`` is a sky and ground of one luminance E_v/π, the
    textbook's uniform surroundings (for closed-form checks). See
    :mod:`indoorsim.world.sky`.
    """

    enabled: bool = False
    sky: Literal["overcast", "intermediate", "clear", "uniform"] = "overcast"
    time: datetime.time = datetime.time(12, 0)
    """Local clock time of the walk on ``site.date``."""
    utc_offset_h: Annotated[float, Field(ge=-12, le=14)] | None = None
    """The local clock's offset from UTC, h; ``None``: the site's longitude / 15, rounded."""
    exterior_vertical_lux: NonNegFloat | None = None
    """The ``uniform`` sky's illuminance on a vertical pane, lx (given for it alone:
    the other skies derive theirs from the sun's altitude)."""
    transmittance: Annotated[float, Field(ge=0, le=1)] = 0.7
    """Visible transmittance of the glazing at normal incidence."""
    panes: Annotated[int, Field(ge=1, le=4)] = 2
    """Panes of uncoated glass: how the transmittance falls at oblique incidence (Fresnel)."""
    ground_reflectance: Annotated[float, Field(ge=0, lt=1)] = 0.2

    @field_validator("time", mode="before")
    @classmethod
    def _quoted_time(cls, value: Any) -> Any:
        # YAML 1.1 reads an unquoted 14:30 as the base-60 number 870, which
        # pydantic would take for seconds after midnight (00:14:30).
        if isinstance(value, int | float) and not isinstance(value, bool):
            raise ValueError(
                f"got the number {value}: quote the time ('14:30'), since YAML reads an "
                "unquoted 14:30 as 870"
            )
        return value

    @model_validator(mode="after")
    def _uniform_sky_only(self) -> DaylightSpec:
        if self.sky == "uniform" and self.exterior_vertical_lux is None:
            raise ValueError("the 'uniform' sky needs exterior_vertical_lux (lx on the pane)")
        if self.sky != "uniform" and self.exterior_vertical_lux is not None:
            raise ValueError(
                f"exterior_vertical_lux applies to sky 'uniform' only; the "
                f"{self.sky!r} sky takes its brightness from the sun's altitude"
            )
        return self


class ReflectanceSpec(_Spec):
    ceiling: Annotated[float, Field(ge=0, lt=1)] = 0.8
    walls: Annotated[float, Field(ge=0, lt=1)] = 0.5
    floor: Annotated[float, Field(ge=0, lt=1)] = 0.3


class LightSpec(_Spec):
    """Light model options: inter-reflection (ambient) term and daylight."""

    ambient: bool = True
    reflectance: ReflectanceSpec = ReflectanceSpec()
    daylight: DaylightSpec = DaylightSpec()


class DipoleSpec(_Spec):
    """A magnetic point dipole with a fixed moment in the building frame."""

    position: Point3
    moment: Vec3
    """A·m², |moment| at most :data:`MAX_DIPOLE_MOMENT_AM2` (10⁴ A·m², ≈ 65 t of steel)."""

    @field_validator("moment")
    @classmethod
    def _building_sized(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        size = math.hypot(*v)
        if size > MAX_DIPOLE_MOMENT_AM2:
            raise ValueError(
                f"|moment| = {size:.3g} A·m² is beyond the limit of "
                f"{MAX_DIPOLE_MOMENT_AM2:g} A·m² (the moment of ≈ 65 t of steel in the "
                "Earth's field, more than any object in a building; it would clip a phone's "
                "±4912 µT magnetometer within 0.74 m)"
            )
        return v


class RebarSpec(_Spec):
    """Reinforcing steel in a slab or a beam, as a grid of dipoles.

    ``bars`` says which way the bars run: ``mesh`` (a slab: two layers, along x
    and along y, half the steel each) or ``x`` / ``y`` (a beam: its longitudinal
    bars that way, ``MagneticSpec.tie_share`` of the steel in stirrups across
    it). Bars are long, so the Earth's field magnetises them along their axes
    (``MagneticSpec.susceptibility``) far more than across
    (``transverse_susceptibility``), and their remanence lies along them.
    """

    z: Coordinate
    spacing: PositiveFloat = 1.0
    steel_volume_m3_per_m2: NonNegFloat = 0.002
    region: Annotated[list[Vec2], Field(min_length=3)] | None = None
    """Polygon covered by the steel; the building outline when omitted."""
    bars: Literal["mesh", "x", "y"] = "mesh"
    element_m: PositiveFloat | None = None
    """Side of the square patches (a mesh) or length of the segments (a beam) over
    which one set of bars runs, magnetised as one: a structural bay, the length a
    bar spans between laps [E]. Patches start at the region's lower-left corner.
    None: every dipole is its own element."""


class MagneticSpec(_Spec):
    """Magnetic sources: explicit dipoles, plus the steel of pillars, slabs and beams.

    Reinforcing steel is bars. A bar of volume V along u in the Earth's field
    H = B_earth/μ0 takes the induced moment V·[χ·(H·u)u + χ_t·(H − (H·u)u)] —
    χ = ``susceptibility`` along it, χ_t = ``transverse_susceptibility`` across —
    and a remanent moment along u. An element (a column's storey, a slab's
    patch, a beam's bay: see :class:`RebarSpec`) is magnetised as one: each of
    its bar directions f, holding the share w_f of its steel, carries g_f·c_f·u_f
    with g_f a standard normal (seeded) and c_f = ``remanent_ratio``·χ·V·|H|·
    w_f/√(Σ w_f²), so the element's RMS remanent moment is ``remanent_ratio``
    times the moment the field would induce along its bars. Steel furniture is
    sheet steel: isotropic χ, a remanent moment in a random direction.
    """

    dipoles: list[DipoleSpec] = []
    rebar: list[RebarSpec] = []
    susceptibility: NonNegFloat = 30.0
    """Effective volume susceptibility of steel along a bar (or of sheet steel)."""
    transverse_susceptibility: NonNegFloat = 2.0
    """Across a long bar: its demagnetising factor ½ caps it near 2 [D: χ/(1 + χ/2)]."""
    tie_share: Annotated[float, Field(ge=0, le=1)] = 0.25
    """Share of a column's or beam's steel in the ties and stirrups that run across
    it (half each way) [E]."""
    remanent_ratio: NonNegFloat = 0.5
    pillar_dipole_spacing: PositiveFloat = 0.5
    min_distance: PositiveFloat = 0.05
    """Distances to a dipole below this are clamped, keeping the field finite."""


class WifiApSpec(_Spec):
    """A WiFi access point."""

    bssid: str
    position: Point3
    tx_power_dbm: Annotated[float, Field(ge=-10, le=36, allow_inf_nan=False)] = 18.0
    frequency_ghz: Annotated[float, Field(ge=2.3, le=7.2, allow_inf_nan=False)] = 2.4
    ssid: str = ""

    @field_validator("bssid")
    @classmethod
    def _mac(cls, v: str) -> str:
        if not re.fullmatch(r"[0-9a-fA-F]{2}(:[0-9a-fA-F]{2}){5}", v):
            raise ValueError(f"{v!r} is not a MAC address like 02:00:00:00:00:01")
        return v


class MultipathSpec(_Spec):
    """Small-scale fading: the multipath field a phone samples at its exact position.

    Each AP's field is a sum of ``paths`` plane waves from isotropic directions
    with excess delays of an exponential power-delay profile (rms
    ``delay_spread_ns``), plus the direct wave; a scan reads the power averaged
    over the channel's ``bandwidth_mhz`` (what an RSSI over a 20 MHz channel
    measures). The direct wave carries K times the scattered power: K drawn per
    AP, log-normal about ``rician_k_db``, divided by the loss of the walls and
    slabs the direct path crosses (a wall weakens the direct wave, not the
    scattered field). It decorrelates within half a wavelength (6 cm at 2.4 GHz):
    a still phone reads one fade scan after scan, a walking phone a new fade
    each scan, a phone put back on the same marker another.
    """

    enabled: bool = True
    paths: Annotated[int, Field(ge=4, le=256)] = 24
    delay_spread_ns: PositiveFloat = 40.0
    """rms delay spread: 3GPP TR 38.901 InH-office 20 ns LOS, 48 ns NLOS at 2.4 GHz [S/D]."""
    rician_k_db: Annotated[float, Field(ge=-100, le=100)] = 7.0
    """Mean K-factor of an unobstructed link, dB: 3GPP TR 38.901 InH LOS, μ_K = 7 dB [S].
    Within ±100 dB (10^(K/10) of a K beyond that would overflow, and mean nothing)."""
    rician_k_sigma_db: Annotated[float, Field(ge=0, le=30)] = 4.0
    """Spread of K between APs, dB: 3GPP TR 38.901 InH LOS, σ_K = 4 dB [S]; at most 30 dB."""
    bandwidth_mhz: Annotated[float, Field(gt=0, le=160)] = 20.0
    """Channel over which the RSSI is measured (a 20 MHz WiFi channel)."""


class RadioSpec(_Spec):
    """Propagation model: log-distance path loss + multi-wall loss + shadowing + multipath."""

    path_loss_exponent: Annotated[float, Field(ge=1.0, le=6.0)] = 2.0
    system_loss_db: NonNegFloat = 10.0
    """Antenna, cable and body losses between AP EIRP and the phone's report."""
    pillar_loss_db: NonNegFloat = 3.0
    """Loss past a pillar: a 0.4–0.8 m column is narrower than the first Fresnel
    zone at 2.4–5 GHz (≈ 0.5 m at 5 m range), so most power diffracts around
    it; a few dB [E] rather than a concrete wall's 12–26 dB."""
    shadowing_sigma_db: NonNegFloat = 4.0
    shadowing_correlation_m: Annotated[float, Field(ge=1, le=100, allow_inf_nan=False)] = 8.0
    """Decorrelation distance of the shadowing field, m: 6–10 m indoors (REALISM §4.3).
    Within [1, 100] m: the field is sampled at a tenth of it and embedded in a grid
    8 of it wider, which below 1 m or above 100 m outgrows the memory of a machine."""
    floors_above: Annotated[int, Field(ge=0, le=3)] = 1
    floors_below: Annotated[int, Field(ge=0, le=3)] = 1
    """Storeys above and below whose APs the phone hears through the slabs. Each is
    laid out like this one — the same AP positions, a storey pitch (the ceiling
    height) up or down, with BSSIDs of their own — as the floors of an office block
    or a library repeat one plan [E]."""
    floor_loss_db: NonNegFloat = 18.3
    """COST 231 multi-floor loss L_f of one reinforced-concrete slab at 2.4 GHz
    (REALISM §4.2); a radio at f loses L_f·(5 + 4f)/(5 + 4·2.4), as concrete's loss
    grows with frequency (3GPP TR 38.901; 32.2 dB at 5.18 GHz); through k slabs,
    L_f·k^((k+2)/(k+1) − b) with b = 0.46. 0: the slabs pass everything."""
    body_loss_db: NonNegFloat = 6.0
    """Loss when the carrier's body stands between the phone and an AP: 3–10 dB
    (REALISM §4.3 [E]); the middle taken."""
    ap_null_depth_db: Annotated[float, Field(ge=0, le=40, allow_inf_nan=False)] = 10.0
    """How far below its horizontal gain an AP radiates straight up or down, dB; 0 for
    an isotropic AP. An AP's omni antennas are vertical dipoles radiating a doughnut,
    strongest toward the horizon and weakest along their axis, whether the AP hangs
    from the ceiling or sits high on a wall (Aerohive, "Installation guidelines":
    "better coverage horizontally than vertically"); the axial null of a lone
    half-wave dipole is filled in a real AP by its several elements, its housing and
    the ceiling's reflections, to about 10 dB below the horizon [E]. See
    :func:`indoorsim.world.radio.ap_pattern_db`."""
    multipath: MultipathSpec = MultipathSpec()


class RouteSpec(_Spec):
    """A walk: explicit waypoints, or a start and goal joined by a shortest path."""

    waypoints: Annotated[list[Vec2], Field(min_length=2)] | None = None
    start: Vec2 | None = None
    goal: Vec2 | None = None
    speed: Annotated[float, Field(gt=0.1, le=3.0, allow_inf_nan=False)] = 1.2
    leg_speeds: list[Annotated[float, Field(gt=0.1, le=3.0, allow_inf_nan=False)]] | None = None
    """With waypoints: the mean speed over each leg between consecutive waypoints,
    m/s, one per leg — the walker paces each leg to take its length over that
    speed, within its acceleration and turning limits and a top walking speed of
    2 m/s (a real surveyor's trace, fast on long straight legs and slow on short
    ones). The first leg's time includes the walker's standing before its first
    step; a stop or a turn on the spot counts to the leg it is on (a turn at a
    waypoint, to the leg after it). None walks every leg at the cruising speed.
    The walker's step geometry still follows ``speed``."""

    @model_validator(mode="after")
    def _one_form(self) -> RouteSpec:
        has_wp = self.waypoints is not None
        has_sg = self.start is not None or self.goal is not None
        if has_wp == has_sg:
            raise ValueError("give either 'waypoints' or both 'start' and 'goal'")
        if has_sg and (self.start is None or self.goal is None):
            raise ValueError("'start' and 'goal' must be given together")
        if self.leg_speeds is not None:
            if self.waypoints is None:
                raise ValueError("'leg_speeds' needs 'waypoints' (one speed per leg)")
            if len(self.leg_speeds) != len(self.waypoints) - 1:
                raise ValueError(
                    f"'leg_speeds' has {len(self.leg_speeds)} speeds for "
                    f"{len(self.waypoints) - 1} legs (one per pair of consecutive waypoints)"
                )
        return self

    def points(self) -> list[tuple[float, float]]:
        """The points that must be walkable (waypoints, or start and goal)."""
        return list(self.waypoints) if self.waypoints is not None else [self.start, self.goal]


class GridSurveySpec(_Spec):
    """Han2023's offline phase: a phone held flat, still, on a regular grid."""

    kind: Literal["grid"]
    spacing: PositiveFloat = 1.2
    duration_s: PositiveFloat = 30.0
    rate_hz: PositiveFloat = 50.0
    height: PositiveFloat = 1.2
    region: Annotated[list[Vec2], Field(min_length=3)] | None = None


class WalkSurveySpec(_Spec):
    """Chen2022's offline phase: walking a route past marked reference points."""

    kind: Literal["walk"]
    route: str
    reference_spacing: PositiveFloat = 5.0
    wifi_dwell_s: PositiveFloat = 10.0
    repeats: Annotated[int, Field(ge=1)] = 1


SurveySpec = Annotated[GridSurveySpec | WalkSurveySpec, Field(discriminator="kind")]
SURVEY_KINDS = ("grid", "walk")


class Scenario(_Spec):
    """A complete, validated scenario (see the module docstring)."""

    name: Annotated[str, Field(min_length=1)]
    description: str = ""
    seed: Annotated[int, Field(ge=0)] = 0
    """Seeds the site's fixed randomness (remanent moments, shadowing fields)."""
    site: SiteSpec
    outline: Annotated[list[Vec2], Field(min_length=3)] | None = None
    """Building footprint; derived from the walls when omitted."""
    walls: Annotated[list[WallSpec], Field(min_length=1)]
    doors: list[DoorSpec] = []
    windows: list[WindowSpec] = []
    rooms: list[RoomSpec] = []
    pillars: list[PillarSpec] = []
    obstacles: list[ObstacleSpec] = []
    luminaires: list[LuminaireSpec] = []
    light: LightSpec = LightSpec()
    magnetic: MagneticSpec = MagneticSpec()
    wifi: list[WifiApSpec] = []
    radio: RadioSpec = RadioSpec()
    routes: dict[str, RouteSpec] = {}
    surveys: dict[str, SurveySpec] = {}
