"""The layout primitives a floor is drafted from: cells, the walls between them, intervals.

A kind's builder tiles its floor with axis-aligned :class:`Cell` rectangles;
:func:`boundary_pieces` finds every stretch of cell edge between two different
spaces and :func:`wall_class` says what kind of wall stands there, which
:class:`~indoorsim.scenario.generate.draft.Draft` merges into walls and cuts
doors into. Besides these: millimetre rounding and the 300 mm module
(:func:`mm`, :func:`snap`), interval arithmetic along a wall line
(:func:`merge_intervals`, :func:`subtract_intervals`), closed-form box
distances for keep-clear checks (:func:`closer_than`), splitting a band of
rooms at bay lines (:func:`split_band`) and routing to a target
(:func:`path_to`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon, box

Size = tuple[float, float]
"""A footprint's x and y extent, m."""

# Circulation spaces: open to each other, no wall between two of them.
PUBLIC_KINDS = frozenset({"corridor", "hall", "garage"})
# Spaces enclosed by reinforced-concrete core walls.
_CORE = frozenset({"stair", "shaft", "plant", "ramp"})
# Probe distance off a cell boundary when asking which cell lies on each side.
_EPS = 1e-3


def mm(v: float) -> float:
    """Round to the millimetre: keeps the YAML readable; floats still round-trip exactly."""
    return round(float(v), 3)


def snap(v: float, step: float = 0.3) -> float:
    """Snap to the 300 mm building module used for bays, depths and widths."""
    return mm(round(v / step) * step)


# --------------------------------------------------------------------------- layout primitives


@dataclass(frozen=True, kw_only=True)
class Cell:
    """One axis-aligned rectangle of the tiling; cells sharing ``name`` form one space."""

    name: str
    kind: str
    x0: float
    y0: float
    x1: float
    y1: float

    def contains(self, x: float, y: float) -> bool:
        """Whether (x, y) lies strictly inside the rectangle."""
        return self.x0 < x < self.x1 and self.y0 < y < self.y1

    @property
    def width(self) -> float:
        """Extent along x, m."""
        return self.x1 - self.x0

    @property
    def depth(self) -> float:
        """Extent along y, m."""
        return self.y1 - self.y0

    @property
    def center(self) -> tuple[float, float]:
        """The rectangle's centre (x, y)."""
        return ((self.x0 + self.x1) / 2, (self.y0 + self.y1) / 2)

    def polygon(self, inset: float = 0.0) -> Polygon:
        """The rectangle shrunk by ``inset`` on every side (grown when negative)."""
        return box(self.x0 + inset, self.y0 + inset, self.x1 - inset, self.y1 - inset)


@dataclass(frozen=True, kw_only=True)
class Piece:
    """An elementary stretch of cell boundary between two different spaces.

    Horizontal pieces lie on y = ``coord`` from x = ``lo`` to ``hi``; ``neg`` is
    the cell below and ``pos`` the cell above. Vertical pieces lie on
    x = ``coord``; ``neg`` is left and ``pos`` right. ``None`` is outside.
    """

    horizontal: bool
    coord: float
    lo: float
    hi: float
    neg: Cell | None
    pos: Cell | None


@dataclass(frozen=True, kw_only=True)
class WallType:
    """How one class of wall is built: thickness (m) and material."""

    thickness: float
    material: str


@dataclass(frozen=True, kw_only=True)
class Door:
    """A doorway into ``room``; ``normal`` points from circulation into the room."""

    x: float
    y: float
    width: float
    normal: tuple[float, float]
    room: Cell

    def offset(self, distance: float) -> tuple[float, float]:
        """A point ``distance`` metres into the room (negative: out into circulation)."""
        return (self.x + self.normal[0] * distance, self.y + self.normal[1] * distance)


def cell_at(cells: Sequence[Cell], x: float, y: float) -> Cell | None:
    """The cell whose interior holds (x, y); None on a boundary or outside."""
    for c in cells:
        if c.contains(x, y):
            return c
    return None


def _same_space(a: Cell | None, b: Cell | None) -> bool:
    if a is None or b is None:
        return a is b
    return a.name == b.name or (a.kind in PUBLIC_KINDS and b.kind in PUBLIC_KINDS)


def wall_class(a: Cell | None, b: Cell | None) -> str:
    """Which kind of wall separates two different spaces."""
    if a is None or b is None:
        inside = a or b
        assert inside is not None
        # A hall meets the outside through a glass facade (mall entrance).
        return "curtain" if inside.kind == "hall" else "exterior"
    kinds = {a.kind, b.kind}
    if kinds & _CORE:
        return "core"
    if "shop" in kinds and kinds & PUBLIC_KINDS:
        return "shopfront"
    if kinds & PUBLIC_KINDS:
        return "corridor"
    return "partition"


def boundary_pieces(cells: Sequence[Cell]) -> list[Piece]:
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
                    neg, pos = cell_at(cells, t, coord - _EPS), cell_at(cells, t, coord + _EPS)
                else:
                    neg, pos = cell_at(cells, coord - _EPS, t), cell_at(cells, coord + _EPS, t)
                if not _same_space(neg, pos):
                    pieces.append(
                        Piece(horizontal=horizontal, coord=coord, lo=lo, hi=hi, neg=neg, pos=pos)
                    )
    return pieces


# Box distances this close to a threshold are left to GEOS, whose rounding
# decides the comparison (the closed form agrees with it to ~1e-14 m).
_DISTANCE_TIE_M = 1e-9
# Margin for leaving out boxes that cannot come within a threshold: far above
# any rounding difference.
NEAR_M = 1e-6

Bounds = Sequence[float]  # (xmin, ymin, xmax, ymax) of an axis-aligned box


def box_distance(a: Bounds, b: Bounds) -> float:
    """Distance between two axis-aligned boxes, in closed form."""
    dx = max(b[0] - a[2], a[0] - b[2], 0.0)
    dy = max(b[1] - a[3], a[1] - b[3], 0.0)
    return math.hypot(dx, dy)


def closer_than(bounds: Bounds, others: Sequence[Bounds], gap: float) -> bool:
    """``any(box(*bounds).distance(box(*o)) < gap for o in others)``, in closed form
    except where GEOS's rounding could decide it."""
    for o in others:
        dist = box_distance(bounds, o)
        if abs(dist - gap) <= _DISTANCE_TIE_M:
            dist = shapely.box(*bounds).distance(shapely.box(*o))
        if dist < gap:
            return True
    return False


def merge_intervals(intervals: Iterable[tuple[float, float]]) -> list[tuple[float, float]]:
    """Join touching intervals (shared end points are exact, see :func:`boundary_pieces`)."""
    out: list[tuple[float, float]] = []
    for lo, hi in sorted(intervals):
        if out and lo <= out[-1][1] + 1e-9:
            out[-1] = (out[-1][0], max(out[-1][1], hi))
        else:
            out.append((lo, hi))
    return out


def subtract_intervals(
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


def split_band(
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
            mid = snap((a + b) / 2)
            rooms += [(a, mid), (mid, b)]
        else:
            rooms.append((a, b))
        i += 1
    return rooms


def path_to(
    polyline: Sequence[tuple[float, float]], target: tuple[float, float]
) -> list[tuple[float, float]]:
    """Walk ``polyline`` up to its leg nearest ``target``, then to ``target``."""
    legs = [
        LineString(polyline[i : i + 2]).distance(Point(target)) for i in range(len(polyline) - 1)
    ]
    return [*polyline[: int(np.argmin(legs)) + 1], target]
