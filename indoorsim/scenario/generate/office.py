"""The ``office`` kind: an office floor along a straight corridor.

A corridor (2.1, 2.4 or 2.7 m clear) runs the floor's length with rooms on both
sides (three floors in four when the size is drawn) or on one side (when a
given width leaves rooms under 4.2 m deep on two); rooms are one structural bay,
half a bay (cellular offices) or two bays merged (open plan, classrooms). One
bay on the north side holds the core: a stair, a 2.2 m lift shaft and, where it
fits, a store room. Columns stand on the corridor and facade walls.

Figures it follows:

* Structure: bays of 6.6–8.4 m on the 300 mm module, 4–8 of them; rooms
  5.4–7.5 m deep; ceilings 2.7–3.3 m; columns 0.5–0.7 m with 0.035–0.06 m³
  of steel; beams 5 dm³ of steel per metre.
* Strong steel, within REALISM §2.3's 10–100 A·m²: door frames 3–10 A·m²,
  the stair's fire door 20–40, lift car 60–100 and counterweight 30–60 with
  guide rails 10–20, lift landing doors 15–30, steel exit doors at both
  corridor ends 20–40, electrical cabinets 15–40, radiators (10–30) under
  60 % of the room windows. Desks and steel cabinets furnish about half the
  rooms. Along the corridor this gives REALISM §2.2-like anomalies (see the
  package docstring).
* Light (REALISM §3.2, §3.3): one fixture type along the corridor every
  3–5 m, tubes or panels in a 2.4–3.6 m grid in the rooms.
* Radio: APs every 12–18 m along the corridor and on the far walls of the
  largest rooms until the floor has one AP per 100–250 m² (an enterprise
  deployment's density, ``draft.AP_FLOOR_AREA_M2``); path-loss exponent 2.0
  and shadowing σ 4 dB, within REALISM §4.1's corridor and §4.3's ranges; the
  floor is one of an office block, so the APs of two storeys above and two
  below are heard through the slabs.
* Routes: ``corridor`` along the centre line, ``round_trip`` out and back on
  either side of it, ``room_visit`` into one room and on; surveys on the
  corridor (grid over its floor, walk with reference points 5–10 m apart).
"""

from __future__ import annotations

import numpy as np

from indoorsim.scenario.generate.cells import (
    Cell,
    Size,
    mm,
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


def build_office(size: Size | None, seed: int) -> Scenario:
    """A straight corridor, rooms on one or both sides, a stair and lift core.

    Args:
        size: the footprint's x and y extent, m (at least 16 × 6.5); drawn when None.
        seed: seeds the building's own random generator.

    Returns:
        The validated scenario ``office-<seed>``.

    Raises:
        ValueError: a size too small, or too narrow for rooms 3.6 m deep.
    """
    rng = np.random.default_rng(seed)
    size = check_size("office", size, (16.0, 6.5))
    types = wall_types(rng)
    t_ext, t_cor = types["exterior"].thickness, types["corridor"].thickness
    corridor_clear = float(rng.choice([2.1, 2.4, 2.7]))
    bay_target = rng.uniform(6.6, 8.4)
    if size is None:
        bay = snap(bay_target)
        length = mm(bay * int(rng.integers(4, 9)))
        double = rng.random() < 0.75
        depth = snap(rng.uniform(5.4, 7.5))
    else:
        length = size[0]
        bay = length / max(2, round(length / bay_target))
    n_bays = round(length / bay)
    # Cell width of the corridor so that its clear width is `corridor_clear`.
    if size is None:
        cw = corridor_clear + (t_cor if double else (t_cor + t_ext) / 2)
        width = mm(cw + depth * (2 if double else 1))
    else:
        width = size[1]
        double = (width - corridor_clear - t_cor) / 2 >= 4.2
        cw = corridor_clear + (t_cor if double else (t_cor + t_ext) / 2)
        depth = (width - cw) / (2 if double else 1)
        if depth < 3.6:
            raise ValueError(f"office: width {width} m leaves rooms only {depth:.1f} m deep")
    h = snap(rng.uniform(2.7, 3.3), 0.1)
    d = Draft(rng, ceiling_height=h, wall_types=types)
    bays = [mm(i * length / n_bays) for i in range(n_bays + 1)]
    y_c0 = mm(depth if double else 0.0)
    y_c1 = mm(y_c0 + cw)
    yc = (y_c0 + y_c1) / 2

    cells = [Cell(name="corridor", kind="corridor", x0=0.0, y0=y_c0, x1=length, y1=y_c1)]
    bands = [(y_c1, width)] + ([(0.0, y_c0)] if double else [])
    rooms: list[Cell] = []
    core_bay = int(rng.integers(1, n_bays - 1)) if n_bays > 2 else 0
    core: dict[str, Cell] = {}
    for side, (b0, b1) in enumerate(bands):
        spans: list[tuple[float, float]] = []
        if side == 0:
            c0, c1 = bays[core_bay], bays[core_bay + 1]
            # Lift shaft (2.2 m) on the stair's far side; what is left of the
            # bay is a store room when it is wide enough for one, else stair.
            stair_w = 3.3 if c1 - c0 - 5.5 >= 2.7 else mm(c1 - c0 - 2.2)
            lift_x = mm(c0 + stair_w)
            core["stair"] = Cell(name="stair", kind="stair", x0=c0, y0=b0, x1=lift_x, y1=b1)
            core["shaft"] = Cell(
                name="lift", kind="shaft", x0=lift_x, y0=b0, x1=mm(lift_x + 2.2), y1=b1
            )
            if c1 - lift_x - 2.2 > 1e-6:
                spans.append((mm(lift_x + 2.2), c1))
            spans += split_band(0.0, c0, bays, rng) if c0 > 0 else []
            spans += split_band(c1, length, bays, rng) if c1 < length else []
        else:
            spans = split_band(0.0, length, bays, rng)
        tag = "N" if side == 0 else "S"
        for i, (a, b) in enumerate(sorted(spans)):
            rooms.append(
                Cell(name=f"room {tag}{i + 1:02d}", kind="room", x0=mm(a), y0=b0, x1=mm(b), y1=b1)
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
            width=mm(rng.choice([0.9, 1.0])),
            count=2 if classroom else 1,
            steel_Am2=(3.0, 10.0),
        )
    d.add_doors(core["stair"], width=1.2, steel_Am2=(20.0, 40.0))
    d.lift(core["shaft"])
    # Landing doors of the lift: steel leaves in the shaft's corridor wall.
    d.steel(core["shaft"].center[0], y_c1 + 0.1, 1.0, (15.0, 30.0))

    windows = d.add_windows({"room", "corridor"})
    radiators(d, windows, {"room"}, 0.6)

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
    d.room_aps(room_doors, ssid)

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
    furnish_offices(d, rooms)

    d.surveys = survey_plans(
        route="corridor",
        reference_spacing=mm(round(rng.uniform(5, 10) * 2) / 2),
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
        magnetic=d.magnetic(beam_m3_per_m=0.005, bay_m=bay),
        radio={
            "path_loss_exponent": 2.0,
            "shadowing_sigma_db": 4.0,
            # An office block with a lift: two storeys each way are heard through the slabs.
            "floors_above": 2,
            "floors_below": 2,
        },
    )
