"""The ``basement`` kind: an underground car park.

One to three parking modules side by side, each a driving aisle with a row of
stalls on either side; cross aisles at both ends join the aisles. Columns stand
on every bay line at the stall fronts and backs (none inside the stair, lift
or ramp). Stalls give way to a
stair and lift core by the west cross aisle, a plant room in the north-west
stall row and a ramp in the north-east one, which opens at its foot onto the
east cross aisle.

Figures it follows:

* Structure: stalls 5.1–5.4 m deep, aisles 5.5–6.6 m, cross aisles 6–7 m;
  bays of 7.8–8.4 m (three 2.5 m stalls and a column), 3–6 of them; ceilings
  3.0–3.6 m; 0.35 m concrete outer walls; columns 0.6–0.8 m with
  0.07–0.11 m³ of steel (they carry every storey above); beams 8 dm³ per
  metre; a ground-bearing floor slab with fabric mesh (1.6 dm³ per m², sheets
  4.8 m long, BS 4483) under a podium slab of 5 dm³ per m².
* Strong steel, within REALISM §2.3's 10–100 A·m²: fire doors of the stair and
  plant room 25–45 A·m², the lift (car 60–100, counterweight 30–60, rails
  10–20), three pumps or switchgear in the plant room 50–100; parked cars in a
  bit over half the stalls, 0.03–0.06 m³ of steel each.
* Light: LED tubes (REALISM §3.2) only over the aisles and cross aisles, every
  4–5 m, and in the stair and plant room, with dark concrete surfaces
  (reflectance: ceiling 0.5, walls 0.4, floor 0.2). Every second tube over the
  aisles is switched off, as car parks run outside their busy hours (DIN 67528's
  low-traffic level, REALISM §3.3): along the aisle loop the floor gets
  36–38 lx on average (seeds 1–3) and a phone in the hand reads 8–13 lx at the
  median, against 9–18 lx in real basements; with every tube on it was 72–78 lx
  and 57–86 lx.
* Radio: APs every 16–20 m along each aisle; path-loss exponent 2.2 and
  shadowing σ 5 dB, within REALISM §4.1 and §4.3's ranges; the APs of the
  two storeys above heard through the slabs, none below.
* Routes: ``aisle_loop`` round the aisles (along the first one and back when
  there is only one), ``aisle`` along the first aisle, ``to_stairs`` a
  start/goal walk to the stair door; surveys: a grid over the whole floor and
  a walk on ``aisle_loop`` with reference points 8 m apart.
"""

from __future__ import annotations

import itertools

import numpy as np
from shapely.geometry import box
from shapely.ops import unary_union

from indoorsim.scenario.generate.cells import (
    Cell,
    Size,
    WallType,
    cell_at,
    mm,
    snap,
)
from indoorsim.scenario.generate.draft import (
    Draft,
    check_size,
    survey_plans,
    wall_types,
)
from indoorsim.scenario.schema import Scenario


def build_basement(size: Size | None, seed: int) -> Scenario:
    """An underground car park: stall rows either side of driving aisles, cross
    aisles at both ends, a pillar grid at the stall fronts, a stair and lift
    core, a plant room and a ramp.

    Args:
        size: the footprint's x and y extent, m (at least 28 × 15); drawn when None.
        seed: seeds the building's own random generator.

    Returns:
        The validated scenario ``basement-<seed>``.

    Raises:
        ValueError: a size too small, or too narrow for stalls and an aisle.
    """
    rng = np.random.default_rng(seed)
    size = check_size("basement", size, (28.0, 15.0))
    types = wall_types(rng, exterior=WallType(thickness=0.35, material="concrete"))
    stall = snap(rng.uniform(5.1, 5.4), 0.1)
    cross = snap(rng.uniform(6.0, 7.0))
    bay_target = rng.uniform(7.8, 8.4)  # three 2.5 m stalls and a column
    if size is None:
        n_modules = int(rng.integers(1, 4))
        aisle = snap(rng.uniform(5.5, 6.6))
        width = mm(n_modules * (2 * stall + aisle))
        length = mm(2 * cross + int(rng.integers(3, 7)) * snap(bay_target))
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
    h = snap(rng.uniform(3.0, 3.6), 0.1)
    d = Draft(rng, ceiling_height=h, wall_types=types)

    x_lines = [0.0, *[mm(cross + i * bay) for i in range(n_bays + 1)], mm(length)]
    y_lines = sorted(
        {
            mm(v)
            for k in range(n_modules)
            for v in (k * module, k * module + stall, (k + 1) * module - stall, (k + 1) * module)
        }
    )
    aisles = [mm(k * module + module / 2) for k in range(n_modules)]

    # Rooms replace stalls: stair and lift by the west cross aisle on the south
    # wall, plant room in the north-west stall row, ramp in the north-east one.
    x_a, x_b = x_lines[1], x_lines[2]
    stair = Cell(name="stair", kind="stair", x0=x_a, y0=0.0, x1=mm(x_a + 3.3), y1=mm(stall))
    shaft = Cell(
        name="lift", kind="shaft", x0=mm(x_a + 3.3), y0=0.0, x1=mm(x_a + 5.5), y1=mm(stall - 2.5)
    )
    plant = Cell(
        name="plant room", kind="plant", x0=x_a, y0=mm(width - stall), x1=x_b, y1=mm(width)
    )
    ramp = Cell(
        name="ramp", kind="ramp", x0=x_lines[-3], y0=mm(width - stall), x1=x_lines[-2], y1=mm(width)
    )
    specials = [stair, shaft, plant, ramp]
    # The garage floor: the rest of the rectangle, as elementary cells.
    xs = sorted({0.0, mm(length), *(v for c in specials for v in (c.x0, c.x1))})
    ys = sorted({0.0, mm(width), *(v for c in specials for v in (c.y0, c.y1))})
    garage = []
    for xa, xb in itertools.pairwise(xs):
        for ya, yb in itertools.pairwise(ys):
            if cell_at(specials, (xa + xb) / 2, (ya + yb) / 2) is None:
                garage.append(Cell(name="garage", kind="garage", x0=xa, y0=ya, x1=xb, y1=yb))
    d.build_walls(garage + specials)

    pillar = float(rng.choice([0.6, 0.7, 0.8]))
    inside_room = (stair, shaft, ramp)
    d.add_pillars(
        ((x, y) for x in x_lines for y in y_lines),
        size=pillar,
        # Basement columns carry every storey above: 3–4 % of steel with the laps
        # of the bars from below, 0.07–0.11 m³ over a 3.0–3.6 m storey [E].
        steel_m3=rng.uniform(0.07, 0.11),
        keep=lambda x, y: d.on_wall(x, y) or cell_at(inside_room, x, y) is None,
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
    # Every second one is switched off: the car park's low-traffic level.
    for y in aisles:
        d.light_line((cross / 2, y), (length - cross / 2, y), spacing, tubes, lit_every=2)
    for x in (cross / 2, length - cross / 2):
        d.light_line((x, 0.0), (x, width), spacing, tubes, lit_every=2)
    d.light_grid(stair, 4.0, tubes)
    d.light_grid(plant, 3.5, tubes)

    for y in aisles:
        d.aps_along((cross, y), (length - cross, y), "parking", spacing=(16, 20))

    xw, xe = mm(cross / 2), mm(length - cross / 2)
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
        "goal": [mm(v) for v in stair_door.offset(1.0)],
        "speed": 1.2,
    }

    # Parked cars: three stalls per bay, a bit over half of them taken.
    stall_w = (bay - pillar) / 3
    car = min(4.6, mm(stall - 0.5))
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
                            "center": [mm(cx), mm(cy)],
                            "size": [1.8, car],
                            "height": 1.5,
                            "steel_volume_m3": mm(rng.uniform(0.03, 0.06)),
                        }
                    )
                    d.obstacle_shapes.append(shape)

    d.surveys = survey_plans(route="aisle_loop", reference_spacing=8.0)
    return d.finish(
        kind="basement",
        seed=seed,
        description=(
            f"Generated underground car park, {length:.1f} m × {width:.1f} m in {d.city}: "
            f"{n_modules} driving aisle(s) with stall rows, a {bay:.2f} m column grid, "
            f"stair and lift core, plant room, ramp; dim tube lighting over the aisles."
        ),
        # The floor is a ground-bearing slab with a mesh top and bottom (A393:
        # 2 × 6.2 kg/m²); the ceiling the building's podium slab, 300 mm under
        # heavier loads (fire-engine access, landscaping: EN 1991-1-1 cat. G),
        # about 40 kg/m² of bars [E].
        magnetic=d.magnetic(
            beam_m3_per_m=0.008,
            bay_m=bay,
            slab_m3_per_m2=0.0016,
            slab_element_m=4.8,
            ceiling_m3_per_m2=0.005,
            ceiling_element_m=bay,
        ),
        radio={
            "path_loss_exponent": 2.2,
            "shadowing_sigma_db": 5.0,
            # Under the ground: nothing below, two storeys of the building above.
            "floors_above": 2,
            "floors_below": 0,
        },
        light={"reflectance": {"ceiling": 0.5, "walls": 0.4, "floor": 0.2}},
    )
