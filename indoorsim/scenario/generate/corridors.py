"""The ``l_corridor`` and ``u_corridor`` kinds: a school-style wing round a courtyard.

A single-loaded corridor runs along the outside of an L-shaped (two arms:
south and west) or U-shaped (three: south, west and east) wing; rooms lie on
the courtyard side, and a stair closes each free end of an arm. Windows open
in the corridor's outer wall and the courtyard facade. Columns stand on the
corridor's two walls and the courtyard facade.

Figures it follows:

* Structure: corridor 2.1–3.0 m clear, rooms 6.0–8.4 m deep, one bay, half a
  bay or two bays wide; bays of 7.2–8.4 m; ceilings 3.0–3.6 m; a drawn
  footprint of 36–60 m × 24–40 m; columns 0.5–0.6 m with 0.035–0.06 m³ of
  steel; beams 5 dm³ per metre.
* Strong steel, within REALISM §2.3's 10–100 A·m²: door frames 3–10 A·m²,
  the stairs' fire doors 20–40, one electrical cabinet per arm 15–40,
  radiators (10–30) under half the room windows; desks and steel cabinets
  in about half the rooms.
* Light (REALISM §3.2, §3.3): one fixture type along every arm every 3–5 m,
  tubes or panels in a 2.4–3.6 m grid in the rooms.
* Radio: APs every 12–18 m along each arm and on the far walls of the
  largest rooms until the floor has one AP per 100–250 m² (an enterprise
  deployment's density, ``draft.AP_FLOOR_AREA_M2``); path-loss exponent 2.0
  and shadowing σ 4 dB, within REALISM §4.1's corridor and §4.3's ranges.
* Routes: ``corridor`` along the whole corridor, ``room_visit`` along it to
  one room; surveys on the corridor (grid over its floor, walk with
  reference points 5–10 m apart).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from indoorsim.scenario.generate.cells import (
    Cell,
    Size,
    mm,
    path_to,
    snap,
    split_band,
)
from indoorsim.scenario.generate.draft import (
    Draft,
    check_size,
    furnish_offices,
    radiators,
    survey_plans,
    wall_types,
)
from indoorsim.scenario.schema import Scenario


def _courtyard(kind: str, size: Size | None, seed: int, arms: int) -> Scenario:
    """A single-loaded corridor on the outside of an L (2 arms) or U (3 arms):
    south arm along y = 0, west arm along x = 0, east arm along x = size[0]."""
    rng = np.random.default_rng(seed)
    types = wall_types(rng)
    t_ext, t_cor = types["exterior"].thickness, types["corridor"].thickness
    clear = float(rng.choice([2.1, 2.4, 2.7, 3.0]))
    depth = snap(rng.uniform(6.0, 8.4))
    cw = mm(clear + (t_ext + t_cor) / 2)
    wing = cw + depth
    minimum = (2 * wing + 6.0 if arms == 3 else wing + 12.0, wing + 12.0)
    size = check_size(kind, size, (mm(minimum[0]), mm(minimum[1])))
    if size is None:
        length = snap(rng.uniform(max(minimum[0], 36.0), 60.0))
        span = snap(rng.uniform(max(minimum[1], 24.0), 40.0))
    else:
        length, span = size
    h = snap(rng.uniform(3.0, 3.6), 0.1)
    d = Draft(rng, ceiling_height=h, wall_types=types)
    bay_target = rng.uniform(7.2, 8.4)
    nx, ny = max(2, round(length / bay_target)), max(2, round(span / bay_target))
    x_bays = [mm(i * length / nx) for i in range(nx + 1)]
    y_bays = [mm(i * span / ny) for i in range(ny + 1)]
    east = arms == 3

    corridors = [
        Cell(name="corridor", kind="corridor", x0=0.0, y0=0.0, x1=mm(length), y1=cw),
        Cell(name="corridor", kind="corridor", x0=0.0, y0=cw, x1=cw, y1=mm(span)),
    ]
    if east:
        corridors.append(
            Cell(
                name="corridor",
                kind="corridor",
                x0=mm(length - cw),
                y0=cw,
                x1=mm(length),
                y1=mm(span),
            )
        )
    rooms: list[Cell] = []
    stairs: list[Cell] = []

    def band(
        name: str,
        lo: float,
        hi: float,
        lines: Sequence[float],
        place: Callable[[float, float], Cell],
        stair_at_end: bool,
    ) -> None:
        spans = split_band(lo, hi, lines, rng)
        if stair_at_end:
            a, b = spans.pop()
            if b - a > 5.0:
                spans.append((a, mm(b - 3.3)))
                a = mm(b - 3.3)
            stairs.append(place(a, b))
        for i, (a, b) in enumerate(spans):
            c = place(a, b)
            rooms.append(
                Cell(name=f"{name}{i + 1:02d}", kind="room", x0=c.x0, y0=c.y0, x1=c.x1, y1=c.y1)
            )

    x_end = mm(length - cw) if east else mm(length)
    band(
        "room S",
        cw,
        x_end,
        x_bays,
        lambda a, b: Cell(name="stair S", kind="stair", x0=mm(a), y0=cw, x1=mm(b), y1=mm(wing)),
        stair_at_end=not east,
    )
    band(
        "room W",
        mm(wing),
        mm(span),
        y_bays,
        lambda a, b: Cell(name="stair W", kind="stair", x0=cw, y0=mm(a), x1=mm(wing), y1=mm(b)),
        stair_at_end=True,
    )
    if east:
        band(
            "room E",
            mm(wing),
            mm(span),
            y_bays,
            lambda a, b: Cell(
                name="stair E",
                kind="stair",
                x0=mm(length - wing),
                y0=mm(a),
                x1=mm(length - cw),
                y1=mm(b),
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
    radiators(d, windows, {"room"}, 0.5)
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
    d.room_aps(room_doors, ssid)

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
    d.route("room_visit", [*path_to(corridor, approach), (door.x, door.y), door.offset(1.2)])
    furnish_offices(d, rooms)

    d.surveys = survey_plans(
        route="corridor",
        reference_spacing=mm(round(rng.uniform(5, 10) * 2) / 2),
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
        magnetic=d.magnetic(beam_m3_per_m=0.005, bay_m=length / nx),
        radio={"path_loss_exponent": 2.0, "shadowing_sigma_db": 4.0},
    )


def build_l_corridor(size: Size | None, seed: int) -> Scenario:
    """An L-shaped wing: a corridor along its south and west outer walls.

    Args:
        size: the footprint's x and y extent, m (at least the wing's depth
            plus 12 m each way); drawn when None.
        seed: seeds the building's own random generator.

    Returns:
        The validated scenario ``l_corridor-<seed>``.

    Raises:
        ValueError: a size too small.
    """
    return _courtyard("l_corridor", size, seed, arms=2)


def build_u_corridor(size: Size | None, seed: int) -> Scenario:
    """A U-shaped wing: a corridor along its south, west and east outer walls.

    Args:
        size: the footprint's x and y extent, m (at least twice the wing's
            depth plus 6 m, and its depth plus 12 m); drawn when None.
        seed: seeds the building's own random generator.

    Returns:
        The validated scenario ``u_corridor-<seed>``.

    Raises:
        ValueError: a size too small.
    """
    return _courtyard("u_corridor", size, seed, arms=3)
