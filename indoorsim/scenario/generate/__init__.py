"""Procedural buildings: a plausible floor from a kind, a size and a seed.

``generate(kind, size, seed)`` returns a complete, validated
:class:`~indoorsim.scenario.Scenario`: walls with doors and windows, pillars on
a structural grid, furniture, ceiling lights, steel, WiFi access points, named
routes and survey plans. It can be saved with
:func:`~indoorsim.scenario.dump_scenario` and loaded back unchanged.

Kinds (the registry :data:`KINDS`; ``size`` is the footprint's x and y extent
in metres, drawn from the kind's usual range when omitted):

* ``office`` — a straight corridor with rooms on one or both sides, a stair
  and lift core, desks and steel cabinets in some rooms.
* ``basement`` — an underground car park: a dense pillar grid, parked cars,
  driving aisles, a stair core with lift, a plant room and a ramp; dim light.
* ``l_corridor`` / ``u_corridor`` — a school-style single-loaded corridor along
  the outside of an L- or U-shaped wing, rooms on the courtyard side, windows
  on the outer wall, stairs at the arm ends.
* ``open_hall`` — a mall or atrium: shops round a large hall with free-standing
  columns, kiosks and an escalator, a glass facade where no shops stand.

How a floor is laid out: each builder tiles the footprint with axis-aligned
rectangles (cells) — corridors, rooms, halls, stairs, lift shafts, plant
rooms, ramps. Walls follow from the tiling: one stands wherever two different
spaces meet (none between two circulation cells) and along the footprint's
edge, its thickness and material set by what it separates. Doors are cut where
a room meets circulation, clear of pillars and wall junctions. Pillars stand on
a structural grid (6–9 m bays), embedded in walls or free-standing in open
areas. Routes follow corridor and aisle centre lines, and furniture is placed
afterwards, clear of doors and routes, so every route stays walkable.

Steel (see :meth:`_Draft.magnetic`): columns carry 0.035–0.07 m³ of
reinforcement per storey (a 0.6 m column with 3–5 % steel plus the beam bars
at its head), the floor and ceiling slabs a rebar mesh at z = −0.15 m and
ceiling + 0.15 m, the beams on the column lines 5–8 dm³ per metre, steel
furniture 1.5–12 dm³ per piece, and the strong sources are explicit dipoles of
up to 100 A·m² (REALISM §2.3): lift cars and counterweights, fire doors, steel
door frames, radiators, electrical cabinets, pumps, escalator trusses. Their
moments point mostly along the Earth's field (induced) with a random remanent
part. Calibrated against REALISM §2.2 (real indoor walks: σ(|B|) 2–9 µT,
extremes up to ±25 µT): along the corridor of generated offices (seeds 0–19,
phone at 1.2 m) σ is 2.2–5 µT, the extremes −10 to +20 µT. The along-path
correlation length, 0.9–1.6 m, is shorter than in §2.2's open-area walks
(1.8–4.7 m): columns and slabs stand 1.2–1.5 m from a corridor's walking line,
and a source's feature is about as wide as its distance.

Light: luminaires of one type per area, identical within it (REALISM §3.2):
LED tubes (≈ 500–600 cd, exponent ≈ 1), LED panels (1500–1800 cd, exponent
2.4–2.75) or downlights (900–1400 cd, exponent 1.5–2), 3–5 m apart along
corridors and in a 2.4–3.6 m grid in rooms, giving roughly 100–500 lx at desk
and phone height; car parks use tubes only over the aisles, so they stay dim.

WiFi: dual-band access points (one 2.4 GHz and one 5 GHz BSSID each) on the
ceiling every 10–20 m along circulation, and some on room walls, with
locally administered, unique BSSIDs.

Randomness: every builder draws from its own ``numpy.random.default_rng(seed)``
and nothing else, so the same (kind, size, seed) always gives the same scenario.
"""

from __future__ import annotations

import datetime
import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon, box
from shapely.ops import unary_union

from indoorsim.scenario.load import parse_scenario
from indoorsim.scenario.schema import Scenario

__all__ = ["KINDS", "Builder", "generate"]

Size = tuple[float, float]
Builder = Callable[[Size | None, int], Scenario]
"""A kind's builder: ``(size or None, seed) -> Scenario``."""

# Circulation spaces: open to each other, no wall between two of them.
_PUBLIC = frozenset({"corridor", "hall", "garage"})
# Spaces enclosed by reinforced-concrete core walls.
_CORE = frozenset({"stair", "shaft", "plant", "ramp"})
# Probe distance off a cell boundary when asking which cell lies on each side.
_EPS = 1e-3

# Sites the generated buildings stand at (REALISM §2.1 table): the Earth field
# differs in strength and inclination between them.
_SITES = (
    ("Huainan", 32.63, 116.98),
    ("Hefei", 31.82, 117.23),
    ("Shanghai", 31.23, 121.47),
    ("Beijing", 39.90, 116.40),
)


def _r(v: float) -> float:
    """Millimetre rounding keeps the YAML readable; floats still round-trip exactly."""
    return round(float(v), 3)


def _snap(v: float, step: float = 0.3) -> float:
    """Snap to the 300 mm building module used for bays, depths and widths."""
    return _r(round(v / step) * step)


# --------------------------------------------------------------------------- layout primitives


@dataclass(frozen=True, kw_only=True)
class _Cell:
    """One axis-aligned rectangle of the tiling; cells sharing ``name`` form one space."""

    name: str
    kind: str
    x0: float
    y0: float
    x1: float
    y1: float

    def contains(self, x: float, y: float) -> bool:
        return self.x0 < x < self.x1 and self.y0 < y < self.y1

    @property
    def width(self) -> float:
        return self.x1 - self.x0

    @property
    def depth(self) -> float:
        return self.y1 - self.y0

    @property
    def center(self) -> tuple[float, float]:
        return ((self.x0 + self.x1) / 2, (self.y0 + self.y1) / 2)

    def polygon(self, inset: float = 0.0) -> Polygon:
        return box(self.x0 + inset, self.y0 + inset, self.x1 - inset, self.y1 - inset)


@dataclass(frozen=True, kw_only=True)
class _Piece:
    """An elementary stretch of cell boundary between two different spaces.

    Horizontal pieces lie on y = ``coord`` from x = ``lo`` to ``hi``; ``neg`` is
    the cell below and ``pos`` the cell above. Vertical pieces lie on
    x = ``coord``; ``neg`` is left and ``pos`` right. ``None`` is outside.
    """

    horizontal: bool
    coord: float
    lo: float
    hi: float
    neg: _Cell | None
    pos: _Cell | None


@dataclass(frozen=True, kw_only=True)
class _WallType:
    thickness: float
    material: str


@dataclass(frozen=True, kw_only=True)
class _Door:
    """A doorway into ``room``; ``normal`` points from circulation into the room."""

    x: float
    y: float
    width: float
    normal: tuple[float, float]
    room: _Cell

    def offset(self, distance: float) -> tuple[float, float]:
        """A point ``distance`` metres into the room (negative: out into circulation)."""
        return (self.x + self.normal[0] * distance, self.y + self.normal[1] * distance)


@dataclass(frozen=True, kw_only=True)
class _Fixture:
    """A luminaire type (REALISM §3.2): ranges drawn once per area."""

    intensity_cd: tuple[float, float]
    exponent: tuple[float, float]


_FIXTURES = {
    "tube": _Fixture(intensity_cd=(500.0, 600.0), exponent=(1.0, 1.2)),
    "panel": _Fixture(intensity_cd=(1500.0, 1800.0), exponent=(2.4, 2.75)),
    "downlight": _Fixture(intensity_cd=(900.0, 1400.0), exponent=(1.5, 2.0)),
}


def _cell_at(cells: Sequence[_Cell], x: float, y: float) -> _Cell | None:
    for c in cells:
        if c.contains(x, y):
            return c
    return None


def _same_space(a: _Cell | None, b: _Cell | None) -> bool:
    if a is None or b is None:
        return a is b
    return a.name == b.name or (a.kind in _PUBLIC and b.kind in _PUBLIC)


def _wall_class(a: _Cell | None, b: _Cell | None) -> str:
    """Which kind of wall separates two different spaces."""
    if a is None or b is None:
        inside = a or b
        assert inside is not None
        # A hall meets the outside through a glass facade (mall entrance).
        return "curtain" if inside.kind == "hall" else "exterior"
    kinds = {a.kind, b.kind}
    if kinds & _CORE:
        return "core"
    if "shop" in kinds and kinds & _PUBLIC:
        return "shopfront"
    if kinds & _PUBLIC:
        return "corridor"
    return "partition"


def _boundary_pieces(cells: Sequence[_Cell]) -> list[_Piece]:
    """Every elementary boundary stretch between two different spaces.

    Scanning the grid of all cell edges keeps this exact: pieces meet at shared
    float coordinates, so contiguous pieces merge into whole walls.
    """
    xs = sorted({v for c in cells for v in (c.x0, c.x1)})
    ys = sorted({v for c in cells for v in (c.y0, c.y1)})
    pieces = []
    for horizontal, lines, stops in ((True, ys, xs), (False, xs, ys)):
        for coord in lines:
            for lo, hi in itertools.pairwise(stops):
                t = (lo + hi) / 2
                if horizontal:
                    neg, pos = _cell_at(cells, t, coord - _EPS), _cell_at(cells, t, coord + _EPS)
                else:
                    neg, pos = _cell_at(cells, coord - _EPS, t), _cell_at(cells, coord + _EPS, t)
                if not _same_space(neg, pos):
                    pieces.append(
                        _Piece(horizontal=horizontal, coord=coord, lo=lo, hi=hi, neg=neg, pos=pos)
                    )
    return pieces


# Box distances this close to a threshold are left to GEOS, whose rounding
# decides the comparison (the closed form agrees with it to ~1e-14 m).
_DISTANCE_TIE_M = 1e-9
# Margin for leaving out boxes that cannot come within a threshold: far above
# any rounding difference.
_NEAR_M = 1e-6

_Bounds = Sequence[float]  # (xmin, ymin, xmax, ymax) of an axis-aligned box


def _box_distance(a: _Bounds, b: _Bounds) -> float:
    """Distance between two axis-aligned boxes, in closed form."""
    dx = max(b[0] - a[2], a[0] - b[2], 0.0)
    dy = max(b[1] - a[3], a[1] - b[3], 0.0)
    return math.hypot(dx, dy)


def _closer_than(bounds: _Bounds, others: Sequence[_Bounds], gap: float) -> bool:
    """``any(box(*bounds).distance(box(*o)) < gap for o in others)``, in closed form
    except where GEOS's rounding could decide it."""
    for o in others:
        dist = _box_distance(bounds, o)
        if abs(dist - gap) <= _DISTANCE_TIE_M:
            dist = shapely.box(*bounds).distance(shapely.box(*o))
        if dist < gap:
            return True
    return False


def _merge_intervals(intervals: Iterable[tuple[float, float]]) -> list[tuple[float, float]]:
    """Join touching intervals (shared end points are exact, see :func:`_boundary_pieces`)."""
    out: list[tuple[float, float]] = []
    for lo, hi in sorted(intervals):
        if out and lo <= out[-1][1] + 1e-9:
            out[-1] = (out[-1][0], max(out[-1][1], hi))
        else:
            out.append((lo, hi))
    return out


def _subtract(
    interval: tuple[float, float], holes: Iterable[tuple[float, float]]
) -> list[tuple[float, float]]:
    """The parts of ``interval`` outside every hole."""
    parts = [interval]
    for h0, h1 in holes:
        nxt = []
        for a, b in parts:
            if h1 <= a or h0 >= b:
                nxt.append((a, b))
                continue
            if h0 > a:
                nxt.append((a, h0))
            if h1 < b:
                nxt.append((h1, b))
        parts = nxt
    return parts


def _split_band(
    lo: float,
    hi: float,
    bay_lines: Sequence[float],
    rng: np.random.Generator,
    min_room: float = 2.7,
) -> list[tuple[float, float]]:
    """Split a band of rooms at structural bay lines: one room per bay, or half a
    bay (cellular offices), or two bays merged (open-plan room, classroom)."""
    lines = [lo, *[b for b in bay_lines if lo + min_room <= b <= hi - min_room], hi]
    rooms: list[tuple[float, float]] = []
    i = 0
    while i < len(lines) - 1:
        a, b = lines[i], lines[i + 1]
        u = rng.random()
        if u < 0.2 and i + 2 < len(lines):
            rooms.append((a, lines[i + 2]))
            i += 2
            continue
        if u < 0.5 and (b - a) / 2 >= min_room:
            mid = _snap((a + b) / 2)
            rooms += [(a, mid), (mid, b)]
        else:
            rooms.append((a, b))
        i += 1
    return rooms


def _path_to(
    polyline: Sequence[tuple[float, float]], target: tuple[float, float]
) -> list[tuple[float, float]]:
    """Walk ``polyline`` up to its leg nearest ``target``, then to ``target``."""
    legs = [
        LineString(polyline[i : i + 2]).distance(Point(target)) for i in range(len(polyline) - 1)
    ]
    return [*polyline[: int(np.argmin(legs)) + 1], target]


def _induced_direction(latitude: float, north_deg: float) -> np.ndarray:
    """Unit vector of the Earth's field in the building frame, from a centred-dipole
    Earth (tan I = 2 tan φ): good to a few degrees, enough to orient induced steel."""
    inclination = math.atan(2 * math.tan(math.radians(latitude)))
    theta = math.radians(north_deg)
    north = np.array([-math.sin(theta), math.cos(theta), 0.0])
    return math.cos(inclination) * north + math.sin(inclination) * np.array([0.0, 0.0, -1.0])


# --------------------------------------------------------------------------- the draft floor


class _Draft:
    """A floor under construction: the tiling plus everything placed in it."""

    def __init__(
        self,
        rng: np.random.Generator,
        *,
        ceiling_height: float,
        wall_types: dict[str, _WallType],
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
            "north_deg": _r(rng.uniform(0.0, 360.0)),
            "ceiling_height": _r(ceiling_height),
        }
        self._induced = _induced_direction(lat, self.site["north_deg"])
        self.cells: list[_Cell] = []
        self.pieces: list[_Piece] = []
        self.walls: list[dict] = []
        self.doors: list[dict] = []
        self.placed_doors: list[_Door] = []
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
        self.surveys: dict[str, dict] = {}
        self._bssids: set[str] = set()

    # ------------------------------------------------------------------ walls

    def build_walls(self, cells: Sequence[_Cell]) -> None:
        """Fix the tiling and derive the walls from it."""
        self.cells = list(cells)
        self.pieces = _boundary_pieces(self.cells)
        runs: dict[tuple[bool, float, str], list[tuple[float, float]]] = {}
        for p in self.pieces:
            runs.setdefault((p.horizontal, p.coord, _wall_class(p.neg, p.pos)), []).append(
                (p.lo, p.hi)
            )
        for (horizontal, coord, cls), intervals in sorted(runs.items()):
            wt = self.wall_types[cls]
            for lo, hi in _merge_intervals(intervals):
                a = (lo, coord) if horizontal else (coord, lo)
                b = (hi, coord) if horizontal else (coord, hi)
                self.walls.append(
                    {
                        "from": [_r(a[0]), _r(a[1])],
                        "to": [_r(b[0]), _r(b[1])],
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
        return unary_union([c.polygon() for c in self.cells])

    def region(self, kinds: Iterable[str], inset: float) -> list[list[float]]:
        """Outline of the union of cells of ``kinds``, shrunk by ``inset`` (clear floor)."""
        wanted = set(kinds)
        poly = unary_union([c.polygon() for c in self.cells if c.kind in wanted])
        poly = poly.buffer(-inset, join_style="mitre")
        assert isinstance(poly, Polygon), "circulation must be one connected area"
        return [[_r(x), _r(y)] for x, y in list(poly.exterior.coords)[:-1]]

    # ------------------------------------------------------------------ pillars

    def add_pillars(
        self,
        points: Iterable[tuple[float, float]],
        *,
        size: float,
        steel_m3: float,
        keep: Callable[[float, float], bool],
    ) -> None:
        """Pillars at structural grid points accepted by ``keep``, duplicates dropped."""
        outline = self.footprint()
        for x, y in points:
            x, y = _r(x), _r(y)
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
                    "steel_volume_m3": _r(steel_m3 * self.rng.uniform(0.85, 1.15)),
                }
            )

    def clear_of_pillars(self, x: float, y: float, margin: float) -> bool:
        return all(
            abs(x - px) > h + margin or abs(y - py) > h + margin for px, py, h in self.pillars
        )

    def clear_of_doors(self, x: float, y: float, margin: float) -> bool:
        return all(
            math.dist((x, y), (dr.x, dr.y)) > dr.width / 2 + margin for dr in self.placed_doors
        )

    # ------------------------------------------------------------------ doors and windows

    def frontages(self, room: _Cell) -> list[tuple[bool, float, float, float, float]]:
        """Stretches where ``room`` meets circulation: (horizontal, coord, lo, hi, sign),
        ``sign`` the direction (+1/−1 along the wall's normal axis) into the room."""
        found: dict[tuple[bool, float, float], list[tuple[float, float]]] = {}
        for p in self.pieces:
            for here, there, sign in ((p.pos, p.neg, 1.0), (p.neg, p.pos, -1.0)):
                if here is room and there is not None and there.kind in _PUBLIC:
                    found.setdefault((p.horizontal, p.coord, sign), []).append((p.lo, p.hi))
        out = [
            (horizontal, coord, lo, hi, sign)
            for (horizontal, coord, sign), iv in found.items()
            for lo, hi in _merge_intervals(iv)
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
        return [(a, b) for a, b in _subtract((lo + end, hi - end), holes) if b >= a]

    def add_doors(
        self,
        room: _Cell,
        *,
        width: float,
        count: int = 1,
        steel_Am2: tuple[float, float] | None = None,
        wide: bool = False,
        facing: tuple[float, float] | None = None,
    ) -> list[_Door]:
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
                free = _subtract((lo + 0.3, hi - 0.3), self._pillar_holes(horizontal, coord))
                a, b = max(free, key=lambda ab: ab[1] - ab[0], default=(0.0, 0.0))
                width = _r(min(width, b - a - 0.2))
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
                door = _Door(x=_r(x), y=_r(y), width=width, normal=normal, room=room)
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
        head = _r(min(2.4, self.h - 0.3))
        spans: dict[tuple[bool, float, float], list[tuple[float, float]]] = {}
        for p in self.pieces:
            for inside, outside, sign in ((p.pos, p.neg, 1.0), (p.neg, p.pos, -1.0)):
                if outside is None and inside is not None and inside.kind in wanted:
                    spans.setdefault((p.horizontal, p.coord, sign), []).append((p.lo, p.hi))
        centres = []
        for (horizontal, coord, sign), iv in sorted(spans.items()):
            for lo, hi in _merge_intervals(iv):
                for a, b in _subtract((lo + 0.5, hi - 0.5), self._pillar_holes(horizontal, coord)):
                    a, b = a + 0.35, b - 0.35
                    if b - a < 1.0:
                        continue
                    p0 = (a, coord) if horizontal else (coord, a)
                    p1 = (b, coord) if horizontal else (coord, b)
                    self.windows.append(
                        {
                            "from": [_r(p0[0]), _r(p0[1])],
                            "to": [_r(p1[0]), _r(p1[1])],
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

    def fixture(self, name: str) -> tuple[float, float]:
        """One luminaire type for an area: (intensity_cd, exponent)."""
        f = _FIXTURES[name]
        return (
            _r(round(self.rng.uniform(*f.intensity_cd), -1)),
            _r(round(self.rng.uniform(*f.exponent), 2)),
        )

    def light(self, x: float, y: float, fixture: tuple[float, float]) -> None:
        if not self.clear_of_pillars(x, y, 0.2):
            return
        self.luminaires.append(
            {
                "position": [_r(x), _r(y), _r(self.h)],
                "intensity_cd": fixture[0],
                "exponent": fixture[1],
            }
        )

    def light_line(
        self,
        a: tuple[float, float],
        b: tuple[float, float],
        spacing: float,
        fixture: tuple[float, float],
    ) -> None:
        """Evenly spaced lights along a→b, half a spacing in from each end."""
        n = max(1, round(math.dist(a, b) / spacing))
        for i in range(n):
            t = (i + 0.5) / n
            self.light(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), fixture)

    def light_grid(self, cell: _Cell, spacing: float, fixture: tuple[float, float]) -> None:
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
        pos = [_r(x), _r(y), _r(z)]
        self.wifi.append(
            {
                "bssid": radios[0],
                "position": pos,
                "tx_power_dbm": _r(round(self.rng.uniform(17.0, 20.0))),
                "frequency_ghz": 2.437,
                "ssid": ssid,
            }
        )
        self.wifi.append(
            {
                "bssid": radios[1],
                "position": pos,
                "tx_power_dbm": _r(round(self.rng.uniform(20.0, 23.0))),
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

    def wall_ap(self, door: _Door, ssid: str) -> None:
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
            {"position": [_r(x), _r(y), _r(z)], "moment": [_r(round(v, 2)) for v in m]}
        )

    def lift(self, shaft: _Cell) -> None:
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
                "center": [_r(cx), _r(cy)],
                "size": [_r(shaft.width - 2 * inset), _r(shaft.depth - 2 * inset)],
                "height": _r(self.h),
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
                found.setdefault((horizontal, _r(coord)), []).append((ends[0], ends[-1]))
        self.beam_lines = [
            (horizontal, coord, _r(lo), _r(hi))
            for (horizontal, coord), iv in sorted(found.items())
            for lo, hi in _merge_intervals(iv)
        ]

    def magnetic(self, *, beam_m3_per_m: float, slab_m3_per_m2: float = 0.003) -> dict:
        """The ``magnetic`` section: explicit dipoles plus the slabs' steel.

        Each slab (floor at z = −0.15, the ceiling's at ceiling + 0.15) is a
        rebar mesh — 0.003 m³/m² is φ12 bars at 150 mm both ways, top and bottom,
        in a 150 mm slab — as dipoles 2 m apart: a regular mesh's induced field
        cancels at walking height whatever the spacing, and 2 m is the size of
        the patches over which the bars' remanence stays coherent. The beams on
        the grid lines are narrow strips of dipoles (one row, 0.5 m apart) at
        z = −0.3 under the floor and in the ceiling slab.

        Steel is calibrated as a whole against REALISM §2.2 (σ of |B| a few µT
        along a corridor): an effective susceptibility of 100 (column and beam
        bars are long, so along their axis the demagnetising factor is near
        zero and the steel's own susceptibility, in the hundreds, shows through)
        and remanence as large as the induced moment (bars are bent, cut and
        welded).

        Args:
            beam_m3_per_m: steel per metre of beam (longitudinal bars and stirrups).
            slab_m3_per_m2: mesh steel per m² of slab.
        """
        rebar = []
        for slab_z, beam_z in ((-0.15, -0.3), (_r(self.h + 0.15), _r(self.h + 0.15))):
            rebar.append({"z": slab_z, "spacing": 2.0, "steel_volume_m3_per_m2": slab_m3_per_m2})
            for horizontal, coord, lo, hi in self.beam_lines:
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
                        "steel_volume_m3_per_m2": _r(beam_m3_per_m / 0.5),
                        "region": [[_r(x), _r(y)] for x, y in corners],
                    }
                )
        return {
            "dipoles": self.dipoles,
            "rebar": rebar,
            "susceptibility": 100.0,
            "remanent_ratio": 1.0,
        }

    # ------------------------------------------------------------------ routes and furniture

    def route(
        self, name: str, waypoints: Sequence[tuple[float, float]], speed: float | None = None
    ) -> None:
        pts = [[_r(x), _r(y)] for x, y in waypoints]
        self.routes[name] = {
            "waypoints": pts,
            "speed": _r(speed if speed is not None else round(self.rng.uniform(1.0, 1.4), 2)),
        }
        self.keep_clear.append(LineString(pts).buffer(0.7))

    def furnish(
        self,
        room: _Cell,
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
            if _box_distance(b, (x0, y0, x1, y1)) < gap + _NEAR_M
        ]
        pillars = [
            b
            for b in ((px - h, py - h, px + h, py + h) for px, py, h in self.pillars)
            if _box_distance(b, (x0, y0, x1, y1)) < 0.1 + _NEAR_M
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
                cx, cy = _snap(cx, 0.05), _snap(cy, 0.05)
                bounds = (cx - w / 2, cy - d / 2, cx + w / 2, cy + d / 2)
                # Everything here is an axis-aligned box except ``keep``: "clear
                # contains shape" is a comparison of bounds, distances are closed
                # form (see _closer_than), and only the keep-clear area needs GEOS.
                inside = x0 <= bounds[0] and bounds[2] <= x1 and y0 <= bounds[1] and bounds[3] <= y1
                if (
                    not inside
                    or _closer_than(bounds, placed, gap)
                    or _closer_than(bounds, pillars, 0.1)
                    or keep.intersects(shapely.box(*bounds))
                ):
                    continue
                shape = shapely.box(*bounds)
                self.obstacles.append(
                    {
                        "kind": kind,
                        "center": [cx, cy],
                        "size": [_r(w), _r(d)],
                        "height": _r(height),
                        "steel_volume_m3": _r(steel_m3 * self.rng.uniform(0.8, 1.2)),
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
                    "polygon": [[_r(x), _r(y)] for x, y in list(merged.exterior.coords)[:-1]],
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


def _wall_types(
    rng: np.random.Generator, *, exterior: _WallType | None = None
) -> dict[str, _WallType]:
    """One building's wall construction (materials as in REALISM §4.2)."""
    brick_partitions = rng.random() < 0.5
    return {
        "exterior": exterior
        or (
            _WallType(thickness=0.24, material="brick")
            if rng.random() < 0.5
            else _WallType(thickness=0.3, material="concrete")
        ),
        "curtain": _WallType(thickness=0.1, material="glass"),
        "core": _WallType(thickness=0.25, material="concrete"),
        "corridor": _WallType(thickness=0.2, material="brick" if brick_partitions else "concrete"),
        "partition": (
            _WallType(thickness=0.12, material="brick")
            if brick_partitions
            else _WallType(thickness=0.1, material="drywall")
        ),
        "shopfront": _WallType(thickness=0.1, material="glass"),
    }


def _check_size(kind: str, size: Size | None, minimum: Size) -> Size | None:
    if size is None:
        return None
    sx, sy = (float(v) for v in size)
    if not (math.isfinite(sx) and math.isfinite(sy)) or sx < minimum[0] or sy < minimum[1]:
        raise ValueError(
            f"{kind}: size {tuple(size)} is too small; "
            f"the minimum is {minimum[0]} m × {minimum[1]} m"
        )
    return (sx, sy)


def _furnish_offices(d: _Draft, rooms: Sequence[_Cell]) -> None:
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


def _radiators(d: _Draft, windows: Sequence[tuple[float, ...]], kinds: set[str], p: float) -> None:
    """Steel panel radiators under a share ``p`` of the windows of ``kinds`` rooms."""
    for x, y, nx, ny in windows:
        cell = _cell_at(d.cells, x + 0.3 * nx, y + 0.3 * ny)
        if cell is not None and cell.kind in kinds and d.rng.random() < p:
            d.steel(x + 0.25 * nx, y + 0.25 * ny, 0.45, (10.0, 30.0))


# --------------------------------------------------------------------------- kinds


def _office(size: Size | None, seed: int) -> Scenario:
    """A straight corridor, rooms on one or both sides, a stair and lift core."""
    rng = np.random.default_rng(seed)
    size = _check_size("office", size, (16.0, 6.5))
    types = _wall_types(rng)
    t_ext, t_cor = types["exterior"].thickness, types["corridor"].thickness
    corridor_clear = float(rng.choice([2.1, 2.4, 2.7]))
    bay_target = rng.uniform(6.6, 8.4)
    if size is None:
        bay = _snap(bay_target)
        length = _r(bay * int(rng.integers(4, 9)))
        double = rng.random() < 0.75
        depth = _snap(rng.uniform(5.4, 7.5))
    else:
        length = size[0]
        bay = length / max(2, round(length / bay_target))
    n_bays = round(length / bay)
    # Cell width of the corridor so that its clear width is `corridor_clear`.
    if size is None:
        cw = corridor_clear + (t_cor if double else (t_cor + t_ext) / 2)
        width = _r(cw + depth * (2 if double else 1))
    else:
        width = size[1]
        double = (width - corridor_clear - t_cor) / 2 >= 4.2
        cw = corridor_clear + (t_cor if double else (t_cor + t_ext) / 2)
        depth = (width - cw) / (2 if double else 1)
        if depth < 3.6:
            raise ValueError(f"office: width {width} m leaves rooms only {depth:.1f} m deep")
    h = _snap(rng.uniform(2.7, 3.3), 0.1)
    d = _Draft(rng, ceiling_height=h, wall_types=types)
    bays = [_r(i * length / n_bays) for i in range(n_bays + 1)]
    y_c0 = _r(depth if double else 0.0)
    y_c1 = _r(y_c0 + cw)
    yc = (y_c0 + y_c1) / 2

    cells = [_Cell(name="corridor", kind="corridor", x0=0.0, y0=y_c0, x1=length, y1=y_c1)]
    bands = [(y_c1, width)] + ([(0.0, y_c0)] if double else [])
    rooms: list[_Cell] = []
    core_bay = int(rng.integers(1, n_bays - 1)) if n_bays > 2 else 0
    core: dict[str, _Cell] = {}
    for side, (b0, b1) in enumerate(bands):
        spans: list[tuple[float, float]] = []
        if side == 0:
            c0, c1 = bays[core_bay], bays[core_bay + 1]
            # Lift shaft (2.2 m) on the stair's far side; what is left of the
            # bay is a store room when it is wide enough for one, else stair.
            stair_w = 3.3 if c1 - c0 - 5.5 >= 2.7 else _r(c1 - c0 - 2.2)
            lift_x = _r(c0 + stair_w)
            core["stair"] = _Cell(name="stair", kind="stair", x0=c0, y0=b0, x1=lift_x, y1=b1)
            core["shaft"] = _Cell(
                name="lift", kind="shaft", x0=lift_x, y0=b0, x1=_r(lift_x + 2.2), y1=b1
            )
            if c1 - lift_x - 2.2 > 1e-6:
                spans.append((_r(lift_x + 2.2), c1))
            spans += _split_band(0.0, c0, bays, rng) if c0 > 0 else []
            spans += _split_band(c1, length, bays, rng) if c1 < length else []
        else:
            spans = _split_band(0.0, length, bays, rng)
        tag = "N" if side == 0 else "S"
        for i, (a, b) in enumerate(sorted(spans)):
            rooms.append(
                _Cell(name=f"room {tag}{i + 1:02d}", kind="room", x0=_r(a), y0=b0, x1=_r(b), y1=b1)
            )
    cells += rooms + list(core.values())
    d.build_walls(cells)

    pillar = float(rng.choice([0.5, 0.6, 0.7]))
    grid_y = sorted({0.0, y_c0, y_c1, width})
    d.add_pillars(
        ((x, y) for x in bays for y in grid_y),
        size=pillar,
        steel_m3=rng.uniform(0.035, 0.06),
        keep=d.on_wall,
    )
    d.add_beams([(False, x, 0.0, width) for x in bays] + [(True, y, 0.0, length) for y in grid_y])

    room_doors = []
    for room in rooms:
        classroom = room.width >= 7.0
        room_doors += d.add_doors(
            room,
            width=_r(rng.choice([0.9, 1.0])),
            count=2 if classroom else 1,
            steel_Am2=(3.0, 10.0),
        )
    d.add_doors(core["stair"], width=1.2, steel_Am2=(20.0, 40.0))
    d.lift(core["shaft"])
    # Landing doors of the lift: steel leaves in the shaft's corridor wall.
    d.steel(core["shaft"].center[0], y_c1 + 0.1, 1.0, (15.0, 30.0))

    windows = d.add_windows({"room", "corridor"})
    _radiators(d, windows, {"room"}, 0.6)

    # Steel exit doors closing both corridor ends, and electrical cabinets
    # recessed in the corridor walls.
    for x_end, inward in ((0.0, 1.0), (length, -1.0)):
        d.steel(x_end + inward * (t_ext / 2 + 0.05), yc, 1.0, (20.0, 40.0))
    for _ in range(max(1, n_bays // 3)):
        x = rng.uniform(1.0, length - 1.0)
        if d.clear_of_pillars(x, y_c0, 0.5) and d.clear_of_doors(x, y_c0, 0.5):
            d.steel(x, y_c0, 1.3, (15.0, 40.0))

    corridor_light = d.fixture(str(rng.choice(["tube", "panel", "downlight"])))
    room_light = d.fixture(str(rng.choice(["tube", "panel"])))
    spacing = rng.uniform(3.0, 5.0)
    d.light_line((0.0, yc), (length, yc), spacing, corridor_light)
    for room in rooms:
        d.light_grid(room, rng.uniform(2.4, 3.6), room_light)
    d.light_grid(core["stair"], 4.0, corridor_light)

    ssid = str(rng.choice(["staff", "office", "corp"]))
    d.aps_along((0.0, yc), (length, yc), ssid)
    for door in room_doors:
        if door.room.width >= 7.0 and rng.random() < 0.5:
            d.wall_ap(door, ssid)

    start, end = (0.9, yc), (length - 0.9, yc)
    d.route("corridor", [start, end])
    d.route(
        "round_trip",
        [(0.9, yc - 0.35), (length - 0.9, yc - 0.35), (length - 0.9, yc + 0.35), (0.9, yc + 0.35)],
    )
    door = room_doors[int(rng.integers(len(room_doors)))]
    d.route(
        "room_visit",
        [
            start,
            (door.x, yc),
            (door.x, door.y),
            door.offset(1.2),
            (door.x, door.y),
            (door.x, yc),
            end,
        ],
    )
    _furnish_offices(d, rooms)

    d.surveys = _survey_plans(
        route="corridor",
        reference_spacing=_r(round(rng.uniform(5, 10) * 2) / 2),
        region=d.region({"corridor"}, max(t_cor, t_ext) / 2),
    )
    layout = "rooms on both sides" if double else "rooms on one side"
    return d.finish(
        kind="office",
        seed=seed,
        description=(
            f"Generated office floor, {length:.1f} m × {width:.1f} m in {d.city}: "
            f"a {corridor_clear} m corridor with {layout}, {n_bays} structural bays "
            f"of {length / n_bays:.2f} m, a stair and lift core."
        ),
        magnetic=d.magnetic(beam_m3_per_m=0.005),
        radio={"path_loss_exponent": 2.0, "shadowing_sigma_db": 4.0},
    )


def _basement(size: Size | None, seed: int) -> Scenario:
    """An underground car park: stall rows either side of driving aisles, cross
    aisles at both ends, a pillar grid at the stall fronts, a stair and lift
    core, a plant room and a ramp."""
    rng = np.random.default_rng(seed)
    size = _check_size("basement", size, (28.0, 15.0))
    types = _wall_types(rng, exterior=_WallType(thickness=0.35, material="concrete"))
    stall = _snap(rng.uniform(5.1, 5.4), 0.1)
    cross = _snap(rng.uniform(6.0, 7.0))
    bay_target = rng.uniform(7.8, 8.4)  # three 2.5 m stalls and a column
    if size is None:
        n_modules = int(rng.integers(1, 4))
        aisle = _snap(rng.uniform(5.5, 6.6))
        width = _r(n_modules * (2 * stall + aisle))
        length = _r(2 * cross + int(rng.integers(3, 7)) * _snap(bay_target))
    else:
        length, width = size
        n_modules = max(1, round(width / (2 * stall + 6.0)))
        aisle = width / n_modules - 2 * stall
        if aisle < 4.5:
            stall = (width / n_modules - 4.5) / 2
            aisle = 4.5
        if stall < 4.0:
            raise ValueError(f"basement: width {width} m does not fit stalls and an aisle")
    n_bays = max(2, round((length - 2 * cross) / bay_target))
    bay = (length - 2 * cross) / n_bays
    module = width / n_modules
    h = _snap(rng.uniform(3.0, 3.6), 0.1)
    d = _Draft(rng, ceiling_height=h, wall_types=types)

    x_lines = [0.0, *[_r(cross + i * bay) for i in range(n_bays + 1)], _r(length)]
    y_lines = sorted(
        {
            _r(v)
            for k in range(n_modules)
            for v in (k * module, k * module + stall, (k + 1) * module - stall, (k + 1) * module)
        }
    )
    aisles = [_r(k * module + module / 2) for k in range(n_modules)]

    # Rooms replace stalls: stair and lift by the west cross aisle on the south
    # wall, plant room in the north-west stall row, ramp in the north-east one.
    x_a, x_b = x_lines[1], x_lines[2]
    stair = _Cell(name="stair", kind="stair", x0=x_a, y0=0.0, x1=_r(x_a + 3.3), y1=_r(stall))
    shaft = _Cell(
        name="lift", kind="shaft", x0=_r(x_a + 3.3), y0=0.0, x1=_r(x_a + 5.5), y1=_r(stall - 2.5)
    )
    plant = _Cell(
        name="plant room", kind="plant", x0=x_a, y0=_r(width - stall), x1=x_b, y1=_r(width)
    )
    ramp = _Cell(
        name="ramp", kind="ramp", x0=x_lines[-3], y0=_r(width - stall), x1=x_lines[-2], y1=_r(width)
    )
    specials = [stair, shaft, plant, ramp]
    # The garage floor: the rest of the rectangle, as elementary cells.
    xs = sorted({0.0, _r(length), *(v for c in specials for v in (c.x0, c.x1))})
    ys = sorted({0.0, _r(width), *(v for c in specials for v in (c.y0, c.y1))})
    garage = []
    for xa, xb in itertools.pairwise(xs):
        for ya, yb in itertools.pairwise(ys):
            if _cell_at(specials, (xa + xb) / 2, (ya + yb) / 2) is None:
                garage.append(_Cell(name="garage", kind="garage", x0=xa, y0=ya, x1=xb, y1=yb))
    d.build_walls(garage + specials)

    pillar = float(rng.choice([0.6, 0.7, 0.8]))
    inside_room = (stair, shaft, ramp)
    d.add_pillars(
        ((x, y) for x in x_lines for y in y_lines),
        size=pillar,
        steel_m3=rng.uniform(0.045, 0.07),
        keep=lambda x, y: d.on_wall(x, y) or _cell_at(inside_room, x, y) is None,
    )
    d.add_beams(
        [(False, x, 0.0, width) for x in x_lines] + [(True, y, 0.0, length) for y in y_lines]
    )
    d.add_doors(stair, width=1.2, steel_Am2=(25.0, 45.0))
    d.add_doors(plant, width=1.5, steel_Am2=(25.0, 45.0))
    # The ramp opens at its foot onto the east cross aisle.
    d.add_doors(ramp, width=stall, wide=True, facing=(-1.0, 0.0))
    d.lift(shaft)
    # Pumps, a transformer and switchgear in the plant room.
    for _ in range(3):
        px, py = (
            rng.uniform(plant.x0 + 1.5, plant.x1 - 1.5),
            rng.uniform(plant.y0 + 1.5, plant.y1 - 1.5),
        )
        d.steel(px, py, 0.8, (50.0, 100.0))

    tubes = d.fixture("tube")
    spacing = rng.uniform(4.0, 5.0)
    for y in aisles:
        d.light_line((cross / 2, y), (length - cross / 2, y), spacing, tubes)
    for x in (cross / 2, length - cross / 2):
        d.light_line((x, 0.0), (x, width), spacing, tubes)
    d.light_grid(stair, 4.0, tubes)
    d.light_grid(plant, 3.5, tubes)

    for y in aisles:
        d.aps_along((cross, y), (length - cross, y), "parking", spacing=(16, 20))

    xw, xe = _r(cross / 2), _r(length - cross / 2)
    if n_modules >= 2:
        loop = [
            (xw, aisles[0]),
            (xe, aisles[0]),
            (xe, aisles[-1]),
            (xw, aisles[-1]),
            (xw, aisles[0]),
        ]
    else:
        loop = [(xw, 1.5), (xw, aisles[0]), (xe, aisles[0]), (xe, 1.5)]
    d.route("aisle_loop", loop)
    d.route("aisle", [(xw, aisles[0]), (xe, aisles[0])])
    stair_door = next(dr for dr in d.placed_doors if dr.room is stair)
    d.routes["to_stairs"] = {
        "start": [xe, aisles[0]],
        "goal": [_r(v) for v in stair_door.offset(1.0)],
        "speed": 1.2,
    }

    # Parked cars: three stalls per bay, a bit over half of them taken.
    stall_w = (bay - pillar) / 3
    car = min(4.6, _r(stall - 0.5))
    keep_clear = unary_union(d.keep_clear)
    for k in range(n_modules):
        for y0, y1 in (
            (k * module, k * module + stall),
            ((k + 1) * module - stall, (k + 1) * module),
        ):
            for i in range(n_bays):
                for j in range(3):
                    cx = x_lines[1] + i * bay + pillar / 2 + (j + 0.5) * stall_w
                    cy = (y0 + y1) / 2
                    shape = box(cx - 0.9, cy - car / 2, cx + 0.9, cy + car / 2)
                    if (
                        rng.random() > 0.55
                        or any(shape.intersects(c.polygon(-0.3)) for c in specials)
                        or shape.intersects(keep_clear)
                    ):
                        continue
                    d.obstacles.append(
                        {
                            "kind": "other",
                            "center": [_r(cx), _r(cy)],
                            "size": [1.8, car],
                            "height": 1.5,
                            "steel_volume_m3": _r(rng.uniform(0.03, 0.06)),
                        }
                    )
                    d.obstacle_shapes.append(shape)

    d.surveys = _survey_plans(route="aisle_loop", reference_spacing=8.0)
    return d.finish(
        kind="basement",
        seed=seed,
        description=(
            f"Generated underground car park, {length:.1f} m × {width:.1f} m in {d.city}: "
            f"{n_modules} driving aisle(s) with stall rows, a {bay:.2f} m column grid, "
            f"stair and lift core, plant room, ramp; dim tube lighting over the aisles."
        ),
        magnetic=d.magnetic(beam_m3_per_m=0.008),
        radio={"path_loss_exponent": 2.2, "shadowing_sigma_db": 5.0},
        light={"reflectance": {"ceiling": 0.5, "walls": 0.4, "floor": 0.2}},
    )


def _courtyard(kind: str, size: Size | None, seed: int, arms: int) -> Scenario:
    """A single-loaded corridor on the outside of an L (2 arms) or U (3 arms):
    south arm along y = 0, west arm along x = 0, east arm along x = size[0]."""
    rng = np.random.default_rng(seed)
    types = _wall_types(rng)
    t_ext, t_cor = types["exterior"].thickness, types["corridor"].thickness
    clear = float(rng.choice([2.1, 2.4, 2.7, 3.0]))
    depth = _snap(rng.uniform(6.0, 8.4))
    cw = _r(clear + (t_ext + t_cor) / 2)
    wing = cw + depth
    minimum = (2 * wing + 6.0 if arms == 3 else wing + 12.0, wing + 12.0)
    size = _check_size(kind, size, (_r(minimum[0]), _r(minimum[1])))
    if size is None:
        length = _snap(rng.uniform(max(minimum[0], 36.0), 60.0))
        span = _snap(rng.uniform(max(minimum[1], 24.0), 40.0))
    else:
        length, span = size
    h = _snap(rng.uniform(3.0, 3.6), 0.1)
    d = _Draft(rng, ceiling_height=h, wall_types=types)
    bay_target = rng.uniform(7.2, 8.4)
    nx, ny = max(2, round(length / bay_target)), max(2, round(span / bay_target))
    x_bays = [_r(i * length / nx) for i in range(nx + 1)]
    y_bays = [_r(i * span / ny) for i in range(ny + 1)]
    east = arms == 3

    corridors = [
        _Cell(name="corridor", kind="corridor", x0=0.0, y0=0.0, x1=_r(length), y1=cw),
        _Cell(name="corridor", kind="corridor", x0=0.0, y0=cw, x1=cw, y1=_r(span)),
    ]
    if east:
        corridors.append(
            _Cell(
                name="corridor",
                kind="corridor",
                x0=_r(length - cw),
                y0=cw,
                x1=_r(length),
                y1=_r(span),
            )
        )
    rooms: list[_Cell] = []
    stairs: list[_Cell] = []

    def band(
        name: str,
        lo: float,
        hi: float,
        lines: Sequence[float],
        place: Callable[[float, float], _Cell],
        stair_at_end: bool,
    ) -> None:
        spans = _split_band(lo, hi, lines, rng)
        if stair_at_end:
            a, b = spans.pop()
            if b - a > 5.0:
                spans.append((a, _r(b - 3.3)))
                a = _r(b - 3.3)
            stairs.append(place(a, b))
        for i, (a, b) in enumerate(spans):
            c = place(a, b)
            rooms.append(
                _Cell(name=f"{name}{i + 1:02d}", kind="room", x0=c.x0, y0=c.y0, x1=c.x1, y1=c.y1)
            )

    x_end = _r(length - cw) if east else _r(length)
    band(
        "room S",
        cw,
        x_end,
        x_bays,
        lambda a, b: _Cell(name="stair S", kind="stair", x0=_r(a), y0=cw, x1=_r(b), y1=_r(wing)),
        stair_at_end=not east,
    )
    band(
        "room W",
        _r(wing),
        _r(span),
        y_bays,
        lambda a, b: _Cell(name="stair W", kind="stair", x0=cw, y0=_r(a), x1=_r(wing), y1=_r(b)),
        stair_at_end=True,
    )
    if east:
        band(
            "room E",
            _r(wing),
            _r(span),
            y_bays,
            lambda a, b: _Cell(
                name="stair E",
                kind="stair",
                x0=_r(length - wing),
                y0=_r(a),
                x1=_r(length - cw),
                y1=_r(b),
            ),
            stair_at_end=True,
        )
    d.build_walls(corridors + rooms + stairs)

    pillar = float(rng.choice([0.5, 0.6]))
    grid = [(x, y) for x in x_bays for y in (0.0, cw, wing)]
    grid += [(x, y) for x in (0.0, cw, wing) for y in y_bays]
    if east:
        grid += [(x, y) for x in (length, length - cw, length - wing) for y in y_bays]
    d.add_pillars(grid, size=pillar, steel_m3=rng.uniform(0.035, 0.06), keep=d.on_wall)
    beams = [(False, x, 0.0, wing) for x in x_bays] + [
        (True, y, 0.0, length) for y in (0, cw, wing)
    ]
    beams += [(True, y, 0.0, wing) for y in y_bays] + [(False, x, 0.0, span) for x in (0, cw, wing)]
    if east:
        beams += [(True, y, length - wing, length) for y in y_bays]
        beams += [(False, x, 0.0, span) for x in (length, length - cw, length - wing)]
    d.add_beams(beams)

    room_doors = []
    for room in rooms:
        room_doors += d.add_doors(
            room,
            width=1.0,
            count=2 if max(room.width, room.depth) >= 7.0 else 1,
            steel_Am2=(3.0, 10.0),
        )
    for s in stairs:
        d.add_doors(s, width=1.2, steel_Am2=(20.0, 40.0))
    windows = d.add_windows({"room", "corridor"})
    _radiators(d, windows, {"room"}, 0.5)
    # Electrical cabinets in the corridor's inner wall, one per arm.
    for a0, a1, fixed, horizontal in (
        (cw + 1.0, x_end - 1.0, cw, True),
        (wing + 1.0, span - 1.0, cw, False),
    ):
        t = rng.uniform(a0, a1)
        x, y = (t, fixed) if horizontal else (fixed, t)
        if d.clear_of_pillars(x, y, 0.4) and d.clear_of_doors(x, y, 0.5):
            d.steel(x, y, 1.3, (15.0, 40.0))

    yc = cw / 2
    xw, xe = cw / 2, length - cw / 2
    corridor_light = d.fixture(str(rng.choice(["tube", "panel", "downlight"])))
    room_light = d.fixture(str(rng.choice(["tube", "panel"])))
    spacing = rng.uniform(3.0, 5.0)
    d.light_line((0.0, yc), (length, yc), spacing, corridor_light)
    d.light_line((xw, cw), (xw, span), spacing, corridor_light)
    if east:
        d.light_line((xe, cw), (xe, span), spacing, corridor_light)
    for room in rooms:
        d.light_grid(room, rng.uniform(2.4, 3.6), room_light)
    for s in stairs:
        d.light_grid(s, 4.0, corridor_light)

    ssid = str(rng.choice(["campus", "school", "staff"]))
    d.aps_along((0.0, yc), (length, yc), ssid)
    d.aps_along((xw, cw), (xw, span), ssid)
    if east:
        d.aps_along((xe, cw), (xe, span), ssid)
    for door in room_doors:
        if max(door.room.width, door.room.depth) >= 7.0 and rng.random() < 0.4:
            d.wall_ap(door, ssid)

    north_w = (xw, span - 0.9)
    if east:
        corridor = [north_w, (xw, yc), (xe, yc), (xe, span - 0.9)]
    else:
        corridor = [(length - 0.9, yc), (xw, yc), north_w]
    d.route("corridor", corridor)
    # Visit a room: follow the corridor route to the arm of the chosen door,
    # then step to the corridor centre line opposite the door and go in.
    door = room_doors[int(rng.integers(len(room_doors)))]
    if door.normal[1]:
        approach = (door.x, yc)
    else:
        approach = (xw if door.x < length / 2 else xe, door.y)
    d.route("room_visit", [*_path_to(corridor, approach), (door.x, door.y), door.offset(1.2)])
    _furnish_offices(d, rooms)

    d.surveys = _survey_plans(
        route="corridor",
        reference_spacing=_r(round(rng.uniform(5, 10) * 2) / 2),
        region=d.region({"corridor"}, max(t_cor, t_ext) / 2),
    )
    shape = "U" if east else "L"
    return d.finish(
        kind=kind,
        seed=seed,
        description=(
            f"Generated {shape}-shaped teaching wing, {length:.1f} m × {span:.1f} m "
            f"in {d.city}: a {clear} m single-loaded corridor on the outer side, rooms "
            f"{depth:.1f} m deep on the courtyard side, stairs at the arm ends."
        ),
        magnetic=d.magnetic(beam_m3_per_m=0.005),
        radio={"path_loss_exponent": 2.0, "shadowing_sigma_db": 4.0},
    )


def _l_corridor(size: Size | None, seed: int) -> Scenario:
    return _courtyard("l_corridor", size, seed, arms=2)


def _u_corridor(size: Size | None, seed: int) -> Scenario:
    return _courtyard("u_corridor", size, seed, arms=3)


def _open_hall(size: Size | None, seed: int) -> Scenario:
    """A mall floor: shops on three or four sides of a hall with free-standing
    columns, kiosks and an escalator; a glass facade where no shops stand."""
    rng = np.random.default_rng(seed)
    size = _check_size("open_hall", size, (30.0, 24.0))
    if size is None:
        length, width = _snap(rng.uniform(36.0, 60.0)), _snap(rng.uniform(28.0, 44.0))
    else:
        length, width = size
    types = _wall_types(rng, exterior=_WallType(thickness=0.3, material="concrete"))
    h = _snap(rng.uniform(4.5, 6.0), 0.1)
    d = _Draft(rng, ceiling_height=h, wall_types=types)
    shop_depth = _snap(rng.uniform(6.0, 8.4))
    south_shops = rng.random() < 0.5
    ds = shop_depth if south_shops else 0.0
    hall = _Cell(
        name="hall",
        kind="hall",
        x0=shop_depth,
        y0=ds,
        x1=_r(length - shop_depth),
        y1=_r(width - shop_depth),
    )
    # The column grid spans the hall: its edge lines stand in the shop fronts,
    # its inner lines free in the hall; shop partitions follow the same lines.
    bay_target = rng.uniform(7.8, 9.0)
    nx, ny = max(1, round(hall.width / bay_target)), max(1, round(hall.depth / bay_target))
    x_bays = [_r(hall.x0 + i * hall.width / nx) for i in range(nx + 1)]
    y_bays = [_r(hall.y0 + j * hall.depth / ny) for j in range(ny + 1)]

    def add_band(
        tag: str,
        lo: float,
        hi: float,
        lines: Sequence[float],
        rect: Callable[[float, float], tuple[float, float, float, float]],
        front: tuple[float, float],
    ) -> list[_Cell]:
        """Shops from ``lo`` to ``hi`` along a band; ``rect`` maps a span to the
        shop's (x0, y0, x1, y1) and ``front`` is the band's stretch facing the hall.
        The corner shops of the side bands reach past the hall's corners."""
        first, last = front
        inner = [v for v in lines if first + 3.0 <= v <= last - 3.0]
        spans: list[tuple[float, float]] = []
        for a, b in _split_band(lo, hi, inner, rng, min_room=3.6):
            # A split corner shop with no hall frontage joins its neighbour.
            if spans and min(spans[-1][1], last) - max(spans[-1][0], first) < 3.0:
                a = spans.pop()[0]
            spans.append((a, b))
        if len(spans) > 1 and min(spans[-1][1], last) - max(spans[-1][0], first) < 3.0:
            spans[-2:] = [(spans[-2][0], spans[-1][1])]
        out = []
        for i, (a, b) in enumerate(spans):
            x0, y0, x1, y1 = (_r(v) for v in rect(a, b))
            out.append(
                _Cell(name=f"shop {tag}{i + 1:02d}", kind="shop", x0=x0, y0=y0, x1=x1, y1=y1)
            )
        return out

    side_front = (ds, width - shop_depth)
    end_front = (shop_depth, length - shop_depth)
    west = add_band("W", 0.0, width, y_bays, lambda a, b: (0.0, a, shop_depth, b), side_front)
    east = add_band(
        "E", 0.0, width, y_bays, lambda a, b: (length - shop_depth, a, length, b), side_front
    )
    north = add_band(
        "N", *end_front, x_bays, lambda a, b: (a, width - shop_depth, b, width), end_front
    )
    south = (
        add_band("S", *end_front, x_bays, lambda a, b: (a, 0.0, b, ds), end_front)
        if south_shops
        else []
    )
    # The middle north shop becomes the stair core.
    k = len(north) // 2
    s = north.pop(k)
    stair = _Cell(name="stair", kind="stair", x0=s.x0, y0=s.y0, x1=s.x1, y1=s.y1)
    shops = west + east + north + south
    d.build_walls([hall, stair, *shops])
    for shop in shops:
        if not d.frontages(shop):
            raise RuntimeError(f"open_hall: {shop.name} does not front the hall")

    # Aisles: a walkway ring 2 m in front of the shop fronts, and a cross aisle
    # midway between two column lines.
    ring = hall.polygon(2.0)
    x0, y0, x1, y1 = ring.bounds
    cross_y = _r(hall.y0 + ((ny - 1) // 2 + 0.5) * hall.depth / ny)
    aisles = [ring.exterior, LineString([(x0, cross_y), (x1, cross_y)])]
    pillar = float(rng.choice([0.7, 0.8, 0.9]))
    free = hall.polygon(1.0)

    def keep(x: float, y: float) -> bool:
        if d.on_wall(x, y):
            return True
        pt = Point(x, y)
        return free.contains(pt) and all(a.distance(pt) > 1.5 for a in aisles)

    d.add_pillars(
        (
            (x, y)
            for x in sorted({0.0, *x_bays, _r(length)})
            for y in sorted({0.0, *y_bays, _r(width)})
        ),
        size=pillar,
        steel_m3=rng.uniform(0.045, 0.07),
        keep=keep,
    )
    d.add_beams(
        [(False, x, 0.0, width) for x in sorted({0.0, *x_bays, _r(length)})]
        + [(True, y, 0.0, length) for y in sorted({0.0, *y_bays, _r(width)})]
    )
    shop_doors = []
    for shop in shops:
        shop_doors += d.add_doors(
            shop, width=_r(rng.uniform(2.4, 4.0)), wide=True, steel_Am2=(5.0, 15.0)
        )
    d.add_doors(stair, width=1.5, steel_Am2=(25.0, 45.0))
    d.add_windows({"hall"}, sill=0.0)

    d.route("loop", [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)])
    d.route("cross", [(x0, cross_y), (x1, cross_y)])
    # Visit a shop: round the ring to the point in front of its door, then in.
    door = shop_doors[int(rng.integers(len(shop_doors)))]
    dx, dy = door.normal
    approach = (door.x, y1 if dy > 0 else y0) if dy else (x1 if dx > 0 else x0, door.y)
    ring_path = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
    d.route("shop_visit", [*_path_to(ring_path, approach), (door.x, door.y), door.offset(1.5)])

    # An escalator pair: a long steel truss, placed clear of the aisles.
    esc_len = _r(1.7 * h)
    keep_clear = unary_union(d.keep_clear)
    for _ in range(60):
        cx = _snap(rng.uniform(hall.x0 + esc_len / 2 + 2.5, hall.x1 - esc_len / 2 - 2.5), 0.1)
        cy = _snap(rng.uniform(hall.y0 + 3.5, hall.y1 - 3.5), 0.1)
        shape = box(cx - esc_len / 2, cy - 1.8, cx + esc_len / 2, cy + 1.8)
        if shape.intersects(keep_clear) or any(
            shape.distance(box(px - hh, py - hh, px + hh, py + hh)) < 0.3
            for px, py, hh in d.pillars
        ):
            continue
        d.obstacles.append(
            {
                "kind": "machine",
                "center": [cx, cy],
                "size": [esc_len, 3.6],
                "height": _r(h),
                "steel_volume_m3": 0.0,
            }
        )
        d.obstacle_shapes.append(shape)
        for t in np.linspace(-0.4, 0.4, 4):
            d.steel(cx + t * esc_len, cy, 0.3 + (t + 0.5) * (h - 0.6), (40.0, 80.0))
        break
    # Kiosks inside the walkway ring.
    inside_ring = _Cell(name="hall", kind="hall", x0=x0, y0=y0, x1=x1, y1=y1)
    for _ in range(int(rng.integers(2, 6))):
        d.furnish(
            inside_ring,
            kind="counter",
            size=(2.4, 1.2),
            count=1,
            height=1.1,
            steel_m3=0.004,
            against_wall=False,
        )
    for shop in shops:
        d.furnish(
            shop,
            kind="shelf",
            size=(1.8, 0.5),
            count=int(rng.integers(1, 4)),
            height=2.0,
            steel_m3=0.012,
            against_wall=True,
        )

    hall_light = d.fixture("downlight" if rng.random() < 0.5 else "panel")
    shop_light = d.fixture("panel")
    d.light_grid(hall, rng.uniform(4.0, 5.0), hall_light)
    for shop in shops:
        d.light_grid(shop, rng.uniform(2.4, 3.6), shop_light)
    d.light_grid(stair, 4.0, hall_light)
    # Ceiling APs on a grid at most 15 m apart, nudged off the light grid and,
    # where a column stands there, beside it.
    nxa, nya = math.ceil(hall.width / 15), math.ceil(hall.depth / 15)
    for i in range(nxa):
        for j in range(nya):
            x = hall.x0 + (i + 0.5) * hall.width / nxa + 0.5
            y = hall.y0 + (j + 0.5) * hall.depth / nya + 0.5
            if not d.clear_of_pillars(x, y, 0.3):
                x += 1.5
            d.access_point(x, y, h - 0.05, "mall")
    for door in shop_doors:
        if rng.random() < 0.4:
            d.wall_ap(door, "shop")

    d.surveys = _survey_plans(route="loop", reference_spacing=8.0, region=d.region({"hall"}, 0.2))
    sides = "four" if south_shops else "three"
    return d.finish(
        kind="open_hall",
        seed=seed,
        description=(
            f"Generated mall floor, {length:.1f} m × {width:.1f} m in {d.city}: shops "
            f"{shop_depth:.1f} m deep on {sides} sides of a {h:.1f} m high hall with "
            f"free-standing columns, kiosks and an escalator."
        ),
        magnetic=d.magnetic(beam_m3_per_m=0.006),
        radio={"path_loss_exponent": 2.2, "shadowing_sigma_db": 5.0},
    )


KINDS: dict[str, Builder] = {
    "office": _office,
    "basement": _basement,
    "l_corridor": _l_corridor,
    "u_corridor": _u_corridor,
    "open_hall": _open_hall,
}
"""The building kinds by name. A builder takes ``(size or None, seed)`` and returns
a validated scenario; adding an entry makes a new kind available to :func:`generate`."""


def generate(kind: str, size: tuple[float, float] | None = None, seed: int = 0) -> Scenario:
    """Build a plausible floor of ``kind``.

    Args:
        kind: a key of :data:`KINDS` (``office``, ``basement``, ``l_corridor``,
            ``u_corridor``, ``open_hall``).
        size: the footprint's x and y extent in metres; drawn from the kind's
            usual range when None.
        seed: seeds everything random about the building (a non-negative int).

    Returns:
        A validated scenario named ``"{kind}-{seed}"``; the same arguments always
        give an equal scenario.

    Raises:
        KeyError: for an unknown kind (the message lists the valid ones).
        ValueError: for a size below the kind's minimum, or a negative seed.

    Example:
        >>> s = generate("office", seed=3)
        >>> s.name, "corridor" in s.routes
        ('office-3', True)
    """
    try:
        builder = KINDS[kind]
    except KeyError:
        raise KeyError(
            f"unknown building kind {kind!r}; valid kinds: {', '.join(sorted(KINDS))}"
        ) from None
    if seed < 0:
        raise ValueError(f"seed must be non-negative, got {seed}")
    return builder(size, seed)


def _survey_plans(
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
