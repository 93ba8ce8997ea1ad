"""The ``open_hall`` kind: a mall floor or atrium.

Shops line three or four sides of a large hall (the middle shop of the north
side is the stair core); a glass facade closes the hall where no shops stand.
A walkway ring runs 2 m in front of the shop fronts, with a cross aisle
between two column lines; columns stand free in the hall clear of the aisles,
and in the shop fronts and partitions on the same grid. Kiosks stand inside
the ring and an escalator, a long steel truss, clear of the aisles.

Figures it follows:

* Structure: a drawn footprint of 36–60 m × 28–44 m; shops 6.0–8.4 m deep,
  partitioned on the column lines; a column grid of 7.8–9.0 m; a 4.5–6.0 m
  high hall; 0.3 m concrete outer walls. A steel frame for a mall's 4–5 kN/m²
  (EN 1991-1-1 categories C/D, against an office's 2.5–3): rolled columns of
  0.08–0.13 m³ per storey cased to 0.7–0.9 m, erected in two-storey lengths
  spliced 0.6 m above the floor (SCI P358), primary beams of 14.5 dm³ per
  metre on the column lines, secondary beams of 8 dm³ per metre at most 3 m
  apart, and composite slabs on steel decking (1.7 dm³ per m² with the mesh;
  SCI P300).
* Strong steel, within REALISM §2.3's 10–100 A·m²: shop door frames
  5–15 A·m², the stair's fire door 25–45, the escalator truss as four
  dipoles of 40–80 rising along its length; shelves in every shop, counters
  as kiosks.
* Light (REALISM §3.2, §3.3 entrance halls): downlights or panels in a
  4–5 m grid over the hall, panels in a 2.4–3.6 m grid in the shops.
* Radio: ceiling APs on a grid at most 15 m apart over the hall and on the
  back wall of some shops; path-loss exponent 2.2 and shadowing σ 5 dB,
  within REALISM §4.1 and §4.3's ranges.
* Routes: ``loop`` round the walkway ring, ``cross`` along the cross aisle,
  ``shop_visit`` round the ring into one shop; surveys: a grid over the hall
  and a walk on ``loop`` with reference points 8 m apart.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from shapely.geometry import LineString, Point, box
from shapely.ops import unary_union

from indoorsim.scenario.generate.cells import (
    Cell,
    Size,
    WallType,
    mm,
    path_to,
    snap,
    split_band,
)
from indoorsim.scenario.generate.draft import (
    Draft,
    check_size,
    survey_plans,
    wall_types,
)
from indoorsim.scenario.schema import Scenario


def build_open_hall(size: Size | None, seed: int) -> Scenario:
    """A mall floor: shops on three or four sides of a hall with free-standing
    columns, kiosks and an escalator; a glass facade where no shops stand.

    Args:
        size: the footprint's x and y extent, m (at least 30 × 24); drawn when None.
        seed: seeds the building's own random generator.

    Returns:
        The validated scenario ``open_hall-<seed>``.

    Raises:
        ValueError: a size too small.
    """
    rng = np.random.default_rng(seed)
    size = check_size("open_hall", size, (30.0, 24.0))
    if size is None:
        length, width = snap(rng.uniform(36.0, 60.0)), snap(rng.uniform(28.0, 44.0))
    else:
        length, width = size
    types = wall_types(rng, exterior=WallType(thickness=0.3, material="concrete"))
    h = snap(rng.uniform(4.5, 6.0), 0.1)
    d = Draft(rng, ceiling_height=h, wall_types=types)
    shop_depth = snap(rng.uniform(6.0, 8.4))
    south_shops = rng.random() < 0.5
    ds = shop_depth if south_shops else 0.0
    hall = Cell(
        name="hall",
        kind="hall",
        x0=shop_depth,
        y0=ds,
        x1=mm(length - shop_depth),
        y1=mm(width - shop_depth),
    )
    # The column grid spans the hall: its edge lines stand in the shop fronts,
    # its inner lines free in the hall; shop partitions follow the same lines.
    bay_target = rng.uniform(7.8, 9.0)
    nx, ny = max(1, round(hall.width / bay_target)), max(1, round(hall.depth / bay_target))
    x_bays = [mm(hall.x0 + i * hall.width / nx) for i in range(nx + 1)]
    y_bays = [mm(hall.y0 + j * hall.depth / ny) for j in range(ny + 1)]

    def add_band(
        tag: str,
        lo: float,
        hi: float,
        lines: Sequence[float],
        rect: Callable[[float, float], tuple[float, float, float, float]],
        front: tuple[float, float],
    ) -> list[Cell]:
        """Shops from ``lo`` to ``hi`` along a band; ``rect`` maps a span to the
        shop's (x0, y0, x1, y1) and ``front`` is the band's stretch facing the hall.
        The corner shops of the side bands reach past the hall's corners."""
        first, last = front
        inner = [v for v in lines if first + 3.0 <= v <= last - 3.0]
        spans: list[tuple[float, float]] = []
        for a, b in split_band(lo, hi, inner, rng, min_room=3.6):
            # A split corner shop with no hall frontage joins its neighbour.
            if spans and min(spans[-1][1], last) - max(spans[-1][0], first) < 3.0:
                a = spans.pop()[0]
            spans.append((a, b))
        if len(spans) > 1 and min(spans[-1][1], last) - max(spans[-1][0], first) < 3.0:
            spans[-2:] = [(spans[-2][0], spans[-1][1])]
        out = []
        for i, (a, b) in enumerate(spans):
            x0, y0, x1, y1 = (mm(v) for v in rect(a, b))
            out.append(Cell(name=f"shop {tag}{i + 1:02d}", kind="shop", x0=x0, y0=y0, x1=x1, y1=y1))
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
    stair = Cell(name="stair", kind="stair", x0=s.x0, y0=s.y0, x1=s.x1, y1=s.y1)
    shops = west + east + north + south
    d.build_walls([hall, stair, *shops])
    for shop in shops:
        if not d.frontages(shop):
            raise RuntimeError(f"open_hall: {shop.name} does not front the hall")

    # Aisles: a walkway ring 2 m in front of the shop fronts, and a cross aisle
    # midway between two column lines.
    ring = hall.polygon(2.0)
    x0, y0, x1, y1 = ring.bounds
    cross_y = mm(hall.y0 + ((ny - 1) // 2 + 0.5) * hall.depth / ny)
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
            for x in sorted({0.0, *x_bays, mm(length)})
            for y in sorted({0.0, *y_bays, mm(width)})
        ),
        size=pillar,
        # Rolled steel columns (UC 305×305×118 to 356×368×177: 0.08–0.13 m³ over a
        # 4.5–6 m storey), encased in concrete for fire protection.
        steel_m3=rng.uniform(0.08, 0.13),
        keep=keep,
        # Erected in two-storey lengths, spliced 0.6 m above the floor, clear of
        # the beam connections and at a fitter's working height [SCI P358].
        splice_z=0.6,
    )
    d.add_beams(
        [(False, x, 0.0, width) for x in sorted({0.0, *x_bays, mm(length)})]
        + [(True, y, 0.0, length) for y in sorted({0.0, *y_bays, mm(width)})]
    )
    d.add_secondary_beams(3.0, horizontal=False)
    shop_doors = []
    for shop in shops:
        shop_doors += d.add_doors(
            shop, width=mm(rng.uniform(2.4, 4.0)), wide=True, steel_Am2=(5.0, 15.0)
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
    d.route("shop_visit", [*path_to(ring_path, approach), (door.x, door.y), door.offset(1.5)])

    # An escalator pair: a long steel truss, placed clear of the aisles.
    esc_len = mm(1.7 * h)
    keep_clear = unary_union(d.keep_clear)
    for _ in range(60):
        cx = snap(rng.uniform(hall.x0 + esc_len / 2 + 2.5, hall.x1 - esc_len / 2 - 2.5), 0.1)
        cy = snap(rng.uniform(hall.y0 + 3.5, hall.y1 - 3.5), 0.1)
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
                "height": mm(h),
                "steel_volume_m3": 0.0,
            }
        )
        d.obstacle_shapes.append(shape)
        d.escalator_truss(cx, cy, esc_len, 0.0)
        break
    # Kiosks inside the walkway ring.
    inside_ring = Cell(name="hall", kind="hall", x0=x0, y0=y0, x1=x1, y1=y1)
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

    d.surveys = survey_plans(route="loop", reference_spacing=8.0, region=d.region({"hall"}, 0.2))
    sides = "four" if south_shops else "three"
    return d.finish(
        kind="open_hall",
        seed=seed,
        description=(
            f"Generated mall floor, {length:.1f} m × {width:.1f} m in {d.city}: shops "
            f"{shop_depth:.1f} m deep on {sides} sides of a {h:.1f} m high hall with "
            f"free-standing columns, kiosks and an escalator."
        ),
        # A steel frame with composite floors (SCI P300): primary beams UB 610×229
        # (≈ 113 kg/m) on the column lines, secondaries UB 406×178×60–67 at ≤ 3 m
        # for a mall's 4–5 kN/m² (EN 1991-1-1 categories C/D), and 0.9–1 mm
        # decking (≈ 10.5 kg/m²) plus an A193 anti-crack mesh (≈ 3 kg/m²) as the
        # slab's steel, one decking span magnetised as one.
        magnetic=d.magnetic(
            beam_m3_per_m=0.0145,
            bay_m=hall.width / nx,
            slab_m3_per_m2=0.0017,
            slab_element_m=3.0,
            secondary_m3_per_m=0.008,
        ),
        radio={"path_loss_exponent": 2.2, "shadowing_sigma_db": 5.0},
    )
