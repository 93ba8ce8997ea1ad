"""The shared draft every building kind is built on: a tiling of cells and what is placed in it.

A kind's builder (one module per kind in this package) lays out its floor as
axis-aligned :class:`~indoorsim.scenario.generate.cells.Cell` rectangles and
hands them to a :class:`Draft`, which derives the walls from the tiling, cuts
doors and windows, stands pillars and beams on the structural grid, places
lights, access points, steel and furniture, records routes, and finally
assembles and validates the :class:`~indoorsim.scenario.schema.Scenario`
(:meth:`Draft.finish`). The helpers at the end are what the kinds share
besides the draft: one building's wall construction, size checks, office
furniture, radiators and the papers' survey plans. The layout primitives
themselves (cells, wall pieces, intervals, rounding) are in
:mod:`~indoorsim.scenario.generate.cells`.

Sourced figures: the sites are REALISM §2.1's, the luminaire types REALISM
§3.2's, the wall materials REALISM §4.2's, and the BSSIDs locally
administered as REALISM §4 asks; the steel model and its calibration
against REALISM §2.2 and §2.3 are described in :meth:`Draft.magnetic` and
the package docstring.
"""

from __future__ import annotations

import datetime
import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon
from shapely.ops import unary_union

from indoorsim.scenario.generate.cells import (
    NEAR_M,
    PUBLIC_KINDS,
    Cell,
    Door,
    Piece,
    Size,
    WallType,
    boundary_pieces,
    box_distance,
    cell_at,
    closer_than,
    merge_intervals,
    mm,
    snap,
    subtract_intervals,
    wall_class,
)
from indoorsim.scenario.load import parse_scenario
from indoorsim.scenario.schema import Scenario

# Sites the generated buildings stand at (REALISM §2.1 table): the Earth field
# differs in strength and inclination between them.
_SITES = (
    ("Huainan", 32.63, 116.98),
    ("Hefei", 31.82, 117.23),
    ("Shanghai", 31.23, 121.47),
    ("Beijing", 39.90, 116.40),
)


@dataclass(frozen=True, kw_only=True)
class _Fixture:
    """A luminaire type (REALISM §3.2): ranges drawn once per area."""

    intensity_cd: tuple[float, float]
    exponent: tuple[float, float]
    size: tuple[float, float]
    """The emitting face, length × width, m (a tube lies along its line of lights)."""


AP_FLOOR_AREA_M2 = (100.0, 250.0)
"""Floor served by one dual-band AP in an enterprise deployment [E]: a
coverage-designed floor has one per 230–465 m² (2 500–5 000 sq ft, the cells
12–18 m apart that the corridor APs make), a capacity-designed office one per
100–150 m². Each AP is two BSSIDs, so a floor of 900 m² lists 8–18 of its own."""

_FIXTURES = {
    "tube": _Fixture(intensity_cd=(500.0, 600.0), exponent=(1.0, 1.2), size=(1.2, 0.03)),
    "panel": _Fixture(intensity_cd=(1500.0, 1800.0), exponent=(2.4, 2.75), size=(0.6, 0.6)),
    "downlight": _Fixture(intensity_cd=(900.0, 1400.0), exponent=(1.5, 2.0), size=(0.2, 0.2)),
}

Fixture = tuple[float, float, tuple[float, float]]
"""One area's luminaire type as drawn: (intensity_cd, exponent, size)."""


def _induced_direction(latitude: float, north_deg: float) -> np.ndarray:
    """Unit vector of the Earth's field in the building frame, from a centred-dipole
    Earth (tan I = 2 tan φ): good to a few degrees, enough to orient induced steel."""
    inclination = math.atan(2 * math.tan(math.radians(latitude)))
    theta = math.radians(north_deg)
    north = np.array([-math.sin(theta), math.cos(theta), 0.0])
    return math.cos(inclination) * north + math.sin(inclination) * np.array([0.0, 0.0, -1.0])


# --------------------------------------------------------------------------- the draft floor


class Draft:
    """A floor under construction: the tiling plus everything placed in it."""

    def __init__(
        self,
        rng: np.random.Generator,
        *,
        ceiling_height: float,
        wall_types: dict[str, WallType],
    ):
        self.rng = rng
        self.h = ceiling_height
        self.wall_types = wall_types
        city, lat, lon = _SITES[int(rng.integers(len(_SITES)))]
        self.city = city
        day = datetime.date(2022, 1, 1) + datetime.timedelta(days=int(rng.integers(0, 3 * 365)))
        self.site = {
            "latitude": lat,
            "longitude": lon,
            "date": day.isoformat(),
            "north_deg": mm(rng.uniform(0.0, 360.0)),
            "ceiling_height": mm(ceiling_height),
        }
        self._induced = _induced_direction(lat, self.site["north_deg"])
        self.cells: list[Cell] = []
        self.pieces: list[Piece] = []
        self.walls: list[dict] = []
        self.doors: list[dict] = []
        self.placed_doors: list[Door] = []
        self.windows: list[dict] = []
        self.pillars: list[tuple[float, float, float]] = []  # (x, y, half size)
        self.pillar_specs: list[dict] = []
        self.obstacles: list[dict] = []
        self.obstacle_shapes: list[Polygon] = []
        self.keep_clear: list[Polygon] = []
        self._keep_clear_cache: tuple[int, shapely.Geometry | None] = (-1, None)
        self.luminaires: list[dict] = []
        self.dipoles: list[dict] = []
        self.wifi: list[dict] = []
        self.routes: dict[str, dict] = {}
        self.beam_lines: list[tuple[bool, float, float, float]] = []
        self.secondary_lines: list[tuple[bool, float, float, float]] = []
        self.surveys: dict[str, dict] = {}
        self._bssids: set[str] = set()

    def set_site(self, *, latitude: float, longitude: float, date: str, north_deg: float) -> None:
        """Stand the building at a given place (a real plan's) instead of the drawn one;
        steel is then magnetised along that place's field."""
        self.site.update(
            {
                "latitude": latitude,
                "longitude": longitude,
                "date": date,
                "north_deg": mm(north_deg),
            }
        )
        self._induced = _induced_direction(latitude, self.site["north_deg"])

    # ------------------------------------------------------------------ walls

    def build_walls(self, cells: Sequence[Cell]) -> None:
        """Fix the tiling and derive the walls from it."""
        self.cells = list(cells)
        self.pieces = boundary_pieces(self.cells)
        runs: dict[tuple[bool, float, str], list[tuple[float, float]]] = {}
        for p in self.pieces:
            runs.setdefault((p.horizontal, p.coord, wall_class(p.neg, p.pos)), []).append(
                (p.lo, p.hi)
            )
        for (horizontal, coord, cls), intervals in sorted(runs.items()):
            wt = self.wall_types[cls]
            for lo, hi in merge_intervals(intervals):
                a = (lo, coord) if horizontal else (coord, lo)
                b = (hi, coord) if horizontal else (coord, hi)
                self.walls.append(
                    {
                        "from": [mm(a[0]), mm(a[1])],
                        "to": [mm(b[0]), mm(b[1])],
                        "thickness": wt.thickness,
                        "material": wt.material,
                    }
                )

    def on_wall(self, x: float, y: float) -> bool:
        """Whether (x, y) lies on a wall's centre line."""
        for p in self.pieces:
            along, across = (x, y) if p.horizontal else (y, x)
            if abs(across - p.coord) < 1e-6 and p.lo - 1e-6 <= along <= p.hi + 1e-6:
                return True
        return False

    def footprint(self) -> Polygon:
        """The outline of the whole tiling."""
        return unary_union([c.polygon() for c in self.cells])

    def region(self, kinds: Iterable[str], inset: float) -> list[list[float]]:
        """Outline of the union of cells of ``kinds``, shrunk by ``inset`` (clear floor)."""
        wanted = set(kinds)
        poly = unary_union([c.polygon() for c in self.cells if c.kind in wanted])
        poly = poly.buffer(-inset, join_style="mitre")
        assert isinstance(poly, Polygon), "circulation must be one connected area"
        return [[mm(x), mm(y)] for x, y in list(poly.exterior.coords)[:-1]]

    # ------------------------------------------------------------------ pillars

    def add_pillars(
        self,
        points: Iterable[tuple[float, float]],
        *,
        size: float,
        steel_m3: float,
        keep: Callable[[float, float], bool],
        splice_z: float | None = None,
    ) -> None:
        """Pillars at structural grid points accepted by ``keep``, duplicates dropped;
        ``splice_z``: steel columns' splice height (:class:`PillarSpec`)."""
        outline = self.footprint()
        for x, y in points:
            x, y = mm(x), mm(y)
            if not outline.covers(Point(x, y)) or not keep(x, y):
                continue
            if any(abs(x - px) < size and abs(y - py) < size for px, py, _ in self.pillars):
                continue
            self.pillars.append((x, y, size / 2))
            self.pillar_specs.append(
                {
                    "center": [x, y],
                    "size": [size, size],
                    "material": "concrete",
                    "steel_volume_m3": mm(steel_m3 * self.rng.uniform(0.85, 1.15)),
                    "splice_z": splice_z,
                }
            )

    def clear_of_pillars(self, x: float, y: float, margin: float) -> bool:
        """Whether (x, y) is more than ``margin`` outside every pillar."""
        return all(
            abs(x - px) > h + margin or abs(y - py) > h + margin for px, py, h in self.pillars
        )

    def clear_of_doors(self, x: float, y: float, margin: float) -> bool:
        """Whether (x, y) is more than ``margin`` beyond every doorway's opening."""
        return all(
            math.dist((x, y), (dr.x, dr.y)) > dr.width / 2 + margin for dr in self.placed_doors
        )

    # ------------------------------------------------------------------ doors and windows

    def frontages(self, room: Cell) -> list[tuple[bool, float, float, float, float]]:
        """Stretches where ``room`` meets circulation: (horizontal, coord, lo, hi, sign),
        ``sign`` the direction (+1/−1 along the wall's normal axis) into the room."""
        found: dict[tuple[bool, float, float], list[tuple[float, float]]] = {}
        for p in self.pieces:
            for here, there, sign in ((p.pos, p.neg, 1.0), (p.neg, p.pos, -1.0)):
                if here is room and there is not None and there.kind in PUBLIC_KINDS:
                    found.setdefault((p.horizontal, p.coord, sign), []).append((p.lo, p.hi))
        out = [
            (horizontal, coord, lo, hi, sign)
            for (horizontal, coord, sign), iv in found.items()
            for lo, hi in merge_intervals(iv)
        ]
        return sorted(out, key=lambda f: (-(f[3] - f[2]), f[0], f[1]))

    def _door_slots(
        self, horizontal: bool, coord: float, lo: float, hi: float, width: float
    ) -> list[tuple[float, float]]:
        """Ranges for a door centre on this stretch: clear of wall junctions and pillars."""
        end = 0.3 + width / 2
        if lo + end > hi - end:
            return []
        holes = [(a - width / 2, b + width / 2) for a, b in self._pillar_holes(horizontal, coord)]
        return [(a, b) for a, b in subtract_intervals((lo + end, hi - end), holes) if b >= a]

    def add_doors(
        self,
        room: Cell,
        *,
        width: float,
        count: int = 1,
        steel_Am2: tuple[float, float] | None = None,
        wide: bool = False,
        facing: tuple[float, float] | None = None,
    ) -> list[Door]:
        """Doorways from circulation into ``room``, near the ends of its longest frontage.

        Args:
            width: clear width; with ``wide``, the widest that fits up to this.
            count: 1, or 2 for a room entered at both ends (classrooms).
            steel_Am2: moment range of the door's steel (frame or fire-door leaf),
                placed as a dipole at handle height; None for no steel.
            facing: only consider frontages whose into-room normal is this.
        """
        for horizontal, coord, lo, hi, sign in self.frontages(room):
            normal = (0.0, sign) if horizontal else (sign, 0.0)
            if facing is not None and normal != facing:
                continue
            if wide:
                free = subtract_intervals(
                    (lo + 0.3, hi - 0.3), self._pillar_holes(horizontal, coord)
                )
                a, b = max(free, key=lambda ab: ab[1] - ab[0], default=(0.0, 0.0))
                width = mm(min(width, b - a - 0.2))
                if width < 1.2:
                    continue
                centres = [(a + b) / 2]
            else:
                slots = self._door_slots(horizontal, coord, lo, hi, width)
                if not slots:
                    continue
                first = slots[0][0] + self.rng.uniform(0.0, min(0.6, slots[0][1] - slots[0][0]))
                last = slots[-1][1] - self.rng.uniform(0.0, min(0.6, slots[-1][1] - slots[-1][0]))
                if count >= 2 and last - first >= width + 1.0:
                    centres = [first, last]
                else:
                    centres = [first if self.rng.random() < 0.5 else last]
            made = []
            for t in centres:
                x, y = (t, coord) if horizontal else (coord, t)
                door = Door(x=mm(x), y=mm(y), width=width, normal=normal, room=room)
                self.doors.append({"position": [door.x, door.y], "width": width})
                self.placed_doors.append(door)
                # Furniture keeps the swing and the first steps inside clear.
                self.keep_clear.append(
                    LineString([door.offset(-0.5), door.offset(1.8)]).buffer(width / 2 + 0.3)
                )
                if steel_Am2 is not None:
                    # The steel of a frame or an open leaf sits beside the
                    # opening, on the hinge side, not in the walking line.
                    side = (width / 2 + 0.1) * (1.0 if self.rng.random() < 0.5 else -1.0)
                    fx, fy = door.offset(0.1)
                    self.steel(fx + side * normal[1], fy - side * normal[0], 1.0, steel_Am2)
                made.append(door)
            return made
        raise RuntimeError(f"no place for a {width} m door into {room.name}")

    def _pillar_holes(self, horizontal: bool, coord: float) -> list[tuple[float, float]]:
        """Stretches of the line at ``coord`` taken by pillars, with 0.15 m to spare."""
        holes = []
        for px, py, half in self.pillars:
            along, across = (px, py) if horizontal else (py, px)
            if abs(across - coord) < half + 0.3:
                holes.append((along - half - 0.15, along + half + 0.15))
        return holes

    def add_windows(self, kinds: Iterable[str], *, sill: float = 0.9) -> list[tuple[float, ...]]:
        """Windows in the exterior walls of cells of ``kinds``, one per span between
        pillars. Returns (x, y, nx, ny) per window centre, the normal pointing inside."""
        wanted = set(kinds)
        head = mm(min(2.4, self.h - 0.3))
        spans: dict[tuple[bool, float, float], list[tuple[float, float]]] = {}
        for p in self.pieces:
            for inside, outside, sign in ((p.pos, p.neg, 1.0), (p.neg, p.pos, -1.0)):
                if outside is None and inside is not None and inside.kind in wanted:
                    spans.setdefault((p.horizontal, p.coord, sign), []).append((p.lo, p.hi))
        centres = []
        for (horizontal, coord, sign), iv in sorted(spans.items()):
            for lo, hi in merge_intervals(iv):
                for a, b in subtract_intervals(
                    (lo + 0.5, hi - 0.5), self._pillar_holes(horizontal, coord)
                ):
                    a, b = a + 0.35, b - 0.35
                    if b - a < 1.0:
                        continue
                    p0 = (a, coord) if horizontal else (coord, a)
                    p1 = (b, coord) if horizontal else (coord, b)
                    self.windows.append(
                        {
                            "from": [mm(p0[0]), mm(p0[1])],
                            "to": [mm(p1[0]), mm(p1[1])],
                            "sill": sill,
                            "head": head,
                        }
                    )
                    mid = (a + b) / 2
                    centres.append(
                        (mid, coord, 0.0, sign) if horizontal else (coord, mid, sign, 0.0)
                    )
        return centres

    # ------------------------------------------------------------------ light, radio, steel

    def fixture(self, name: str) -> Fixture:
        """One luminaire type for an area: (intensity_cd, exponent, size)."""
        f = _FIXTURES[name]
        return (
            mm(round(self.rng.uniform(*f.intensity_cd), -1)),
            mm(round(self.rng.uniform(*f.exponent), 2)),
            f.size,
        )

    def light(
        self,
        x: float,
        y: float,
        fixture: Fixture,
        along: tuple[float, float] = (1.0, 0.0),
        *,
        lit: bool = True,
    ) -> None:
        """A ceiling luminaire of ``fixture`` at (x, y), its length along ``along``,
        switched on unless ``lit`` is False, unless a pillar stands there."""
        if not self.clear_of_pillars(x, y, 0.2):
            return
        self.luminaires.append(
            {
                "position": [mm(x), mm(y), mm(self.h)],
                "intensity_cd": fixture[0],
                "exponent": fixture[1],
                "size": list(fixture[2]),
                "along": [mm(along[0]), mm(along[1]), 0.0],
                "lit": lit,
            }
        )

    def light_line(
        self,
        a: tuple[float, float],
        b: tuple[float, float],
        spacing: float,
        fixture: Fixture,
        *,
        lit_every: int = 1,
    ) -> None:
        """Evenly spaced lights along a→b, half a spacing in from each end, lying along it;
        every ``lit_every``-th one switched on (from the second, when 2), the rest off."""
        length = math.dist(a, b)
        n = max(1, round(length / spacing))
        along = ((b[0] - a[0]) / length, (b[1] - a[1]) / length) if length > 0 else (1.0, 0.0)
        for i in range(n):
            t = (i + 0.5) / n
            lit = (i + 1) % lit_every == 0 or n == 1
            self.light(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), fixture, along, lit=lit)

    def light_grid(self, cell: Cell, spacing: float, fixture: Fixture) -> None:
        """Lights on a grid of about ``spacing`` over ``cell``, half a step in from its edges."""
        nx = max(1, round(cell.width / spacing))
        ny = max(1, round(cell.depth / spacing))
        for i in range(nx):
            for j in range(ny):
                self.light(
                    cell.x0 + (i + 0.5) * cell.width / nx,
                    cell.y0 + (j + 0.5) * cell.depth / ny,
                    fixture,
                )

    def access_point(self, x: float, y: float, z: float, ssid: str) -> None:
        """A dual-band AP: a 2.4 GHz and a 5 GHz radio with sibling BSSIDs."""
        while True:
            octets = [int(v) for v in self.rng.integers(0, 256, size=6)]
            # Locally administered, unicast (REALISM §4; no real vendor's OUI).
            octets[0] = (octets[0] & 0xFC) | 0x02
            octets[5] &= 0xF0
            base = ":".join(f"{v:02x}" for v in octets[:5])
            radios = [f"{base}:{octets[5]:02x}", f"{base}:{octets[5] | 0x08:02x}"]
            if not self._bssids.intersection(radios):
                break
        self._bssids.update(radios)
        pos = [mm(x), mm(y), mm(z)]
        # EIRP 17–20 dBm in both bands: an enterprise AP's radios run below the
        # 5 GHz band's 23 dBm regulatory ceiling (EU 5150–5350 MHz, 200 mW) as the
        # controller's transmit power control sets them for cells 10–20 m apart;
        # 15–20 dBm is what deployed APs radiate [E] ("Environment realism" issue).
        self.wifi.append(
            {
                "bssid": radios[0],
                "position": pos,
                "tx_power_dbm": mm(round(self.rng.uniform(17.0, 20.0))),
                "frequency_ghz": 2.437,
                "ssid": ssid,
            }
        )
        self.wifi.append(
            {
                "bssid": radios[1],
                "position": pos,
                "tx_power_dbm": mm(round(self.rng.uniform(17.0, 20.0))),
                "frequency_ghz": 5.18,
                "ssid": f"{ssid}-5G",
            }
        )

    def aps_along(
        self,
        a: tuple[float, float],
        b: tuple[float, float],
        ssid: str,
        spacing: tuple[float, float] = (12, 18),
    ) -> None:
        """Ceiling APs along a corridor or aisle centre line, 10–20 m apart."""
        n = max(1, math.ceil(math.dist(a, b) / self.rng.uniform(*spacing)))
        for i in range(n):
            t = (i + 0.5) / n
            x, y = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])
            # Off the light line, so lamp and AP do not share a ceiling tile.
            dx, dy = (b[1] - a[1]) / math.dist(a, b), -(b[0] - a[0]) / math.dist(a, b)
            self.access_point(x + 0.4 * dx, y + 0.4 * dy, self.h - 0.05, ssid)

    def room_aps(self, doors: Sequence[Door], ssid: str, min_size_m: float = 7.0) -> None:
        """APs on the far walls of the largest rooms (a side of ``min_size_m`` or more),
        until the floor has one AP per :data:`AP_FLOOR_AREA_M2` (drawn per building),
        the APs already placed counted first."""
        per_ap = self.rng.uniform(*AP_FLOOR_AREA_M2)
        # Each AP is two radios at one place.
        placed = len({tuple(ap["position"]) for ap in self.wifi})
        budget = math.ceil(self.footprint().area / per_ap) - placed
        # One AP per room, on the wall facing its first door (a large room has two).
        first: dict[str, Door] = {}
        for door in doors:
            if max(door.room.width, door.room.depth) >= min_size_m:
                first.setdefault(door.room.name, door)
        # The largest rooms first, a stable sort keeping the doors' order between equals.
        largest = sorted(first.values(), key=lambda d: -d.room.width * d.room.depth)
        for door in largest[: max(0, budget)]:
            self.wall_ap(door, ssid)

    def wall_ap(self, door: Door, ssid: str) -> None:
        """An AP high on the room wall facing the door (the far side of the room)."""
        room = door.room
        depth = room.depth if door.normal[1] else room.width
        x, y = door.offset(depth - 0.25)
        if not self.clear_of_pillars(x, y, 0.2):
            x, y = door.offset(depth / 2)
        self.access_point(x, y, self.h - 0.5, ssid)

    def steel(self, x: float, y: float, z: float, moment_Am2: tuple[float, float]) -> None:
        """A steel source: an induced moment along the Earth's field plus a remanent part."""
        remanent = self.rng.normal(size=3)
        direction = self._induced + 0.5 * remanent / np.linalg.norm(remanent)
        m = self.rng.uniform(*moment_Am2) * direction / np.linalg.norm(direction)
        self.dipoles.append(
            {"position": [mm(x), mm(y), mm(z)], "moment": [mm(round(v, 2)) for v in m]}
        )

    def escalator_truss(self, x: float, y: float, dx: float, dy: float) -> None:
        """An escalator's steel truss, centred at (``x``, ``y``) and running (``dx``,
        ``dy``) from its foot to its head: four dipoles of 40–80 A·m² on its axis, at
        0.1, 0.37, 0.63 and 0.9 of its length, each at the height of a truss rising
        from 0.3 m over the floor to 0.3 m under the ceiling."""
        for t in np.linspace(-0.4, 0.4, 4):
            self.steel(x + t * dx, y + t * dy, 0.3 + (t + 0.5) * (self.h - 0.6), (40.0, 80.0))

    def lift(self, shaft: Cell) -> None:
        """A lift: car and counterweight at random heights, guide rails, and a
        machine-like obstacle filling the shaft so nobody walks inside it."""
        cx, cy = shaft.center
        z_car = self.rng.uniform(0.3, self.h)
        self.steel(cx, cy, z_car, (60.0, 100.0))
        # The counterweight runs on the opposite side of the shaft to the rails.
        self.steel(shaft.x1 - 0.3, cy, self.h - z_car + 0.5, (30.0, 60.0))
        for z in (0.5, 1.5, 2.5):
            self.steel(shaft.x0 + 0.3, cy, z, (10.0, 20.0))
        inset = 0.2
        self.obstacles.append(
            {
                "kind": "machine",
                "center": [mm(cx), mm(cy)],
                "size": [mm(shaft.width - 2 * inset), mm(shaft.depth - 2 * inset)],
                "height": mm(self.h),
                "steel_volume_m3": 0.0,
            }
        )
        self.obstacle_shapes.append(shaft.polygon(inset))

    def add_beams(self, lines: Iterable[tuple[bool, float, float, float]]) -> None:
        """Beams along structural grid lines, each (horizontal, coord, lo, hi), clipped
        to the footprint; overlapping candidates from different wings merge."""
        outline = self.footprint().buffer(1e-6)
        found: dict[tuple[bool, float], list[tuple[float, float]]] = {}
        for horizontal, coord, lo, hi in lines:
            a, b = ((lo, coord), (hi, coord)) if horizontal else ((coord, lo), (coord, hi))
            part = LineString([a, b]).intersection(outline)
            for g in getattr(part, "geoms", [part]):
                if g.is_empty or g.length < 1.0:
                    continue
                xs, ys = g.xy
                ends = sorted(xs) if horizontal else sorted(ys)
                found.setdefault((horizontal, mm(coord)), []).append((ends[0], ends[-1]))
        self.beam_lines = [
            (horizontal, coord, mm(lo), mm(hi))
            for (horizontal, coord), iv in sorted(found.items())
            for lo, hi in merge_intervals(iv)
        ]

    def add_secondary_beams(self, spacing: float, *, horizontal: bool) -> None:
        """Secondary beams between the primary beam lines running the other way:
        lines along x (``horizontal``) or y, ``spacing`` or a bit less apart, so
        each span between primary lines is split evenly (steel floors carry their
        decking on secondaries 2.5–3.5 m apart [SCI P300, Composite slabs and
        beams using steel decking: decking spans of 2.5–3.6 m])."""
        parallel = sorted({c for h, c, _, _ in self.beam_lines if h == horizontal})
        supports = sorted({c for h, c, _, _ in self.beam_lines if h != horizontal})
        lines = []
        for a, b in itertools.pairwise(parallel):
            n = math.ceil((b - a) / spacing - 1e-6)
            lines += [mm(a + k * (b - a) / n) for k in range(1, n)]
        # One beam per span between the primary beams that carry it.
        self.secondary_lines = [
            (horizontal, c, lo, hi) for c in lines for lo, hi in itertools.pairwise(supports)
        ]

    def magnetic(
        self,
        *,
        beam_m3_per_m: float,
        bay_m: float,
        slab_m3_per_m2: float = 0.003,
        slab_element_m: float | None = None,
        secondary_m3_per_m: float = 0.0,
        ceiling_m3_per_m2: float | None = None,
        ceiling_element_m: float | None = None,
    ) -> dict:
        """The ``magnetic`` section: explicit dipoles plus the slabs' and beams' steel.

        Each slab (floor at z = −0.15, the ceiling's at ceiling + 0.15) is a
        two-way rebar mesh — 0.003 m³/m² is φ12 bars at 150 mm both ways, top and
        bottom, in a 150 mm slab — as dipoles 1 m apart, magnetised patch by
        patch: a patch is one structural bay square, over which the same bars
        run (bars are cut to the bay and lapped at the grid lines [E]). At 1 m
        the grid stands for a uniform patch within 4 % at walking height (at
        2 m, 65 %: ``tests/world/test_magnetic.py``). The beams on the grid lines
        are narrow strips of dipoles (one row, 0.5 m apart) at z = −0.3 under
        the floor and in the ceiling slab, their bars along the line, one
        element per bay.

        An effective susceptibility of 100 along a bar (bars are long, so along
        their axis the demagnetising factor is near zero and the steel's own
        susceptibility, in the hundreds, shows through) and about 2 across it.
        The remanence, twice the moment the field induces along the bars (bars
        are rolled, lifted by magnets, bent, cut and welded [E]), is the one
        amplitude calibrated against REALISM §2.2's σ(|B|) of 2–9 µT; at 1 it
        gave 1.3–2.0 µT along the realism board's routes.

        Args:
            beam_m3_per_m: steel per metre of beam (longitudinal bars and stirrups).
            bay_m: the structural bay: the side of a slab's patches and the length
                of a beam's elements.
            slab_m3_per_m2: mesh steel per m² of slab.
            slab_element_m: side of the slab's patches magnetised as one; the bay
                when None (a composite floor's decking sheets span one secondary
                beam spacing).
            secondary_m3_per_m: steel per metre of the secondary beams
                (:meth:`add_secondary_beams`), each spanning one bay.
            ceiling_m3_per_m2: mesh steel per m² of the ceiling's slab when it
                differs from the floor's (a car park's ground slab under a
                podium slab).
            ceiling_element_m: the ceiling slab's patch side when it differs
                from the floor's.
        """
        bay = mm(bay_m)
        rebar = []
        lines = [(line, beam_m3_per_m, bay) for line in self.beam_lines]
        # A secondary beam is one rolled member: one element.
        lines += [
            (line, secondary_m3_per_m, mm(line[3] - line[2])) for line in self.secondary_lines
        ]
        floor_patch = mm(slab_element_m) if slab_element_m else bay
        ceiling_patch = mm(ceiling_element_m) if ceiling_element_m else floor_patch
        ceiling = slab_m3_per_m2 if ceiling_m3_per_m2 is None else ceiling_m3_per_m2
        for slab_z, beam_z, slab_steel, patch in (
            (-0.15, -0.3, slab_m3_per_m2, floor_patch),
            (mm(self.h + 0.15), mm(self.h + 0.15), ceiling, ceiling_patch),
        ):
            rebar.append(
                {
                    "z": slab_z,
                    "spacing": 1.0,
                    "steel_volume_m3_per_m2": slab_steel,
                    "bars": "mesh",
                    "element_m": patch,
                }
            )
            for (horizontal, coord, lo, hi), m3_per_m, element in lines:
                x0, y0, x1, y1 = (
                    (lo, coord - 0.25, hi, coord + 0.25)
                    if horizontal
                    else (coord - 0.25, lo, coord + 0.25, hi)
                )
                corners = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
                rebar.append(
                    {
                        "z": beam_z,
                        "spacing": 0.5,
                        "steel_volume_m3_per_m2": mm(m3_per_m / 0.5),
                        "region": [[mm(x), mm(y)] for x, y in corners],
                        "bars": "x" if horizontal else "y",
                        "element_m": element,
                    }
                )
        return {
            "dipoles": self.dipoles,
            "rebar": rebar,
            "susceptibility": 100.0,
            "remanent_ratio": 2.0,
        }

    # ------------------------------------------------------------------ routes and furniture

    def route(
        self, name: str, waypoints: Sequence[tuple[float, float]], speed: float | None = None
    ) -> None:
        """A named waypoint route (speed drawn at 1.0–1.4 m/s when not given); furniture
        keeps 0.7 m clear of it."""
        pts = [[mm(x), mm(y)] for x, y in waypoints]
        self.routes[name] = {
            "waypoints": pts,
            "speed": mm(speed if speed is not None else round(self.rng.uniform(1.0, 1.4), 2)),
        }
        self.keep_clear.append(LineString(pts).buffer(0.7))

    def furnish(
        self,
        room: Cell,
        *,
        kind: str,
        size: tuple[float, float],
        count: int,
        height: float,
        steel_m3: float,
        against_wall: bool,
    ) -> None:
        """Up to ``count`` pieces of furniture in ``room``, clear of doors, routes,
        pillars and each other (rejection sampling; a piece that never fits is left out)."""
        clear = room.polygon(0.2)
        x0, y0, x1, y1 = clear.bounds
        keep = self._keep_clear_union()
        gap = 0.05 if against_wall else 0.7  # desks keep a seat and an aisle free
        # Bounds of the solids to keep away from (as shapely.box was given them);
        # only those near the room can come that close to a piece inside it.
        placed = [
            b
            for b in shapely.bounds(self.obstacle_shapes).reshape(-1, 4).tolist()
            if box_distance(b, (x0, y0, x1, y1)) < gap + NEAR_M
        ]
        pillars = [
            b
            for b in ((px - h, py - h, px + h, py + h) for px, py, h in self.pillars)
            if box_distance(b, (x0, y0, x1, y1)) < 0.1 + NEAR_M
        ]
        for _ in range(count):
            for _attempt in range(40):
                w, d = size if self.rng.random() < 0.5 else size[::-1]
                if against_wall:
                    side = int(self.rng.integers(4))
                    if side < 2:  # against the bottom or top wall
                        cx = (
                            self.rng.uniform(x0 + w / 2, x1 - w / 2)
                            if x1 - x0 > w
                            else (x0 + x1) / 2
                        )
                        cy = y0 + d / 2 + 0.05 if side == 0 else y1 - d / 2 - 0.05
                    else:  # the left or right wall: long side along it
                        w, d = d, w
                        cy = (
                            self.rng.uniform(y0 + d / 2, y1 - d / 2)
                            if y1 - y0 > d
                            else (y0 + y1) / 2
                        )
                        cx = x0 + w / 2 + 0.05 if side == 2 else x1 - w / 2 - 0.05
                else:
                    if x1 - x0 <= w + 1.2 or y1 - y0 <= d + 1.2:
                        break
                    cx = self.rng.uniform(x0 + w / 2 + 0.6, x1 - w / 2 - 0.6)
                    cy = self.rng.uniform(y0 + d / 2 + 0.6, y1 - d / 2 - 0.6)
                cx, cy = snap(cx, 0.05), snap(cy, 0.05)
                bounds = (cx - w / 2, cy - d / 2, cx + w / 2, cy + d / 2)
                # Everything here is an axis-aligned box except ``keep``: "clear
                # contains shape" is a comparison of bounds, distances are closed
                # form (see closer_than), and only the keep-clear area needs GEOS.
                inside = x0 <= bounds[0] and bounds[2] <= x1 and y0 <= bounds[1] and bounds[3] <= y1
                if (
                    not inside
                    or closer_than(bounds, placed, gap)
                    or closer_than(bounds, pillars, 0.1)
                    or keep.intersects(shapely.box(*bounds))
                ):
                    continue
                shape = shapely.box(*bounds)
                self.obstacles.append(
                    {
                        "kind": kind,
                        "center": [cx, cy],
                        "size": [mm(w), mm(d)],
                        "height": mm(height),
                        "steel_volume_m3": mm(steel_m3 * self.rng.uniform(0.8, 1.2)),
                    }
                )
                self.obstacle_shapes.append(shape)
                placed.append(bounds)
                break

    def _keep_clear_union(self) -> shapely.Geometry:
        """The union of ``keep_clear``, prepared; rebuilt only when it has grown."""
        n = len(self.keep_clear)
        if self._keep_clear_cache[0] != n:
            keep = unary_union(self.keep_clear) if self.keep_clear else Polygon()
            shapely.prepare(keep)
            self._keep_clear_cache = (n, keep)
        return self._keep_clear_cache[1]

    # ------------------------------------------------------------------ output

    def finish(
        self,
        *,
        kind: str,
        seed: int,
        description: str,
        magnetic: dict,
        radio: dict,
        light: dict | None = None,
    ) -> Scenario:
        """Assemble and validate the scenario (schema and geometry, routes included)."""
        rooms: dict[str, list[Polygon]] = {}
        for c in self.cells:
            rooms.setdefault(c.name, []).append(c.polygon())
        room_specs = []
        for name, polys in rooms.items():
            merged = unary_union(polys)
            assert isinstance(merged, Polygon), f"space {name} must be one connected area"
            room_specs.append(
                {
                    "name": name,
                    "polygon": [[mm(x), mm(y)] for x, y in list(merged.exterior.coords)[:-1]],
                }
            )
        data = {
            "name": f"{kind}-{seed}",
            "description": description,
            "seed": seed,
            "site": self.site,
            "walls": self.walls,
            "doors": self.doors,
            "windows": self.windows,
            "rooms": room_specs,
            "pillars": self.pillar_specs,
            "obstacles": self.obstacles,
            "luminaires": self.luminaires,
            "magnetic": magnetic,
            "wifi": self.wifi,
            "radio": radio,
            "routes": self.routes,
            "surveys": self.surveys,
        }
        if light is not None:
            data["light"] = light
        return parse_scenario(data, source=f"generate({kind!r}, seed={seed})")


# --------------------------------------------------------------------------- shared by the kinds


def wall_types(
    rng: np.random.Generator, *, exterior: WallType | None = None
) -> dict[str, WallType]:
    """One building's wall construction (materials as in REALISM §4.2)."""
    brick_partitions = rng.random() < 0.5
    return {
        "exterior": exterior
        or (
            WallType(thickness=0.24, material="brick")
            if rng.random() < 0.5
            else WallType(thickness=0.3, material="concrete")
        ),
        "curtain": WallType(thickness=0.1, material="glass"),
        "core": WallType(thickness=0.25, material="concrete"),
        "corridor": WallType(thickness=0.2, material="brick" if brick_partitions else "concrete"),
        "partition": (
            WallType(thickness=0.12, material="brick")
            if brick_partitions
            else WallType(thickness=0.1, material="drywall")
        ),
        "shopfront": WallType(thickness=0.1, material="glass"),
    }


def check_size(kind: str, size: Size | None, minimum: Size) -> Size | None:
    """``size`` as floats, or None when not given.

    Raises:
        ValueError: a size not finite or below the kind's ``minimum``.
    """
    if size is None:
        return None
    sx, sy = (float(v) for v in size)
    if not (math.isfinite(sx) and math.isfinite(sy)) or sx < minimum[0] or sy < minimum[1]:
        raise ValueError(
            f"{kind}: size {tuple(size)} is too small; "
            f"the minimum is {minimum[0]} m × {minimum[1]} m"
        )
    return (sx, sy)


def furnish_offices(d: Draft, rooms: Sequence[Cell]) -> None:
    """Desks with steel frames and steel filing cabinets in about half the rooms."""
    for room in rooms:
        if d.rng.random() < 0.5:
            continue
        area = room.width * room.depth
        d.furnish(
            room,
            kind="desk",
            size=(1.4, 0.7),
            count=max(1, int(area / 8)),
            height=0.75,
            steel_m3=0.0015,
            against_wall=False,
        )
        d.furnish(
            room,
            kind="cabinet",
            size=(0.9, 0.45),
            count=int(d.rng.integers(1, 4)),
            height=1.9,
            steel_m3=0.008,
            against_wall=True,
        )


def radiators(d: Draft, windows: Sequence[tuple[float, ...]], kinds: set[str], p: float) -> None:
    """Steel panel radiators under a share ``p`` of the windows of ``kinds`` rooms."""
    for x, y, nx, ny in windows:
        cell = cell_at(d.cells, x + 0.3 * nx, y + 0.3 * ny)
        if cell is not None and cell.kind in kinds and d.rng.random() < p:
            d.steel(x + 0.25 * nx, y + 0.25 * ny, 0.45, (10.0, 30.0))


def survey_plans(
    *, route: str, reference_spacing: float, region: list[list[float]] | None = None
) -> dict[str, dict[str, object]]:
    """The two papers' offline phases: Han2023's 1.2 m, 30 s at 50 Hz grid (over
    ``region``, the whole floor when None) and Chen2022's walk survey along ``route``."""
    grid: dict[str, object] = {
        "kind": "grid",
        "spacing": 1.2,
        "duration_s": 30.0,
        "rate_hz": 50.0,
        "height": 1.2,
    }
    if region is not None:
        grid["region"] = region
    walk = {
        "kind": "walk",
        "route": route,
        "reference_spacing": reference_spacing,
        "wifi_dwell_s": 10.0,
        "repeats": 1,
    }
    return {"grid": grid, "walk": walk}
