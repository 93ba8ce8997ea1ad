"""FloorPlan geometry: vectorised queries agree with shapely, doors, occlusion, wall losses."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from indoorsim.scenario import parse_scenario
from indoorsim.world.materials import MATERIALS
from indoorsim.world.plan import FloorPlan, segment_hits
from tests.conftest import box_scenario


def _plan(**overrides) -> FloorPlan:
    return FloorPlan(parse_scenario(box_scenario(**overrides)))


def _two_rooms(material: str = "drywall", **extra) -> FloorPlan:
    walls = [
        *box_scenario()["walls"],
        {"from": [5, 0], "to": [5, 6], "thickness": 0.12, "material": material},
    ]
    return _plan(walls=walls, **extra)


def test_segment_hits_matches_shapely_on_random_segments():
    rng = np.random.default_rng(0)
    p0, p1 = rng.uniform(0, 10, (300, 2)), rng.uniform(0, 10, (300, 2))
    a, b = rng.uniform(0, 10, (40, 2)), rng.uniform(0, 10, (40, 2))
    hits = segment_hits(p0, p1, a, b)
    ref = shapely.intersects(
        shapely.linestrings(np.stack([p0, p1], 1))[:, None],
        shapely.linestrings(np.stack([a, b], 1))[None],
    )
    np.testing.assert_array_equal(hits, ref)


def test_crosses_wall_agrees_with_shapely_on_random_moves():
    plan = _two_rooms(
        pillars=[{"center": [2.5, 3.0]}],
        obstacles=[{"kind": "desk", "center": [7.5, 3], "size": [1.6, 0.8]}],
    )
    rng = np.random.default_rng(1)
    p0, p1 = rng.uniform(-0.5, 10.5, (2000, 2)), rng.uniform(-0.5, 10.5, (2000, 2))
    lines = shapely.linestrings(np.stack([p0, p1], 1))
    # Passing through the solid = the segment meets its interior (touching a boundary is allowed).
    ref = shapely.intersects(lines, plan.solid) & ~shapely.touches(lines, plan.solid)
    np.testing.assert_array_equal(plan.crosses_wall(p0, p1), ref)


def test_is_walkable_excludes_walls_pillars_furniture_and_outside():
    plan = _plan(
        pillars=[{"center": [3, 3], "size": [0.6, 0.6]}],
        obstacles=[{"center": [7, 3], "size": [1, 1]}],
    )
    pts = [[1, 1], [3, 3], [7, 3], [0.05, 3], [11, 3], [3.4, 3], [7.6, 3]]
    np.testing.assert_array_equal(
        plan.is_walkable(pts), [True, False, False, False, False, True, True]
    )


def test_door_cuts_a_gap_of_its_clear_width():
    walls = [*box_scenario()["walls"], {"from": [5, 0], "to": [5, 6], "thickness": 0.2}]
    plan = _plan(walls=walls, doors=[{"position": [5, 3], "width": 1.0}])
    assert len(plan.walls) == 6  # the partition is split in two
    # Points just inside the clear width are free; points just beyond are wall.
    np.testing.assert_array_equal(
        plan.is_walkable([[5, 3.49], [5, 2.51], [5, 3.52], [5, 2.48]]), [True, True, False, False]
    )
    assert not plan.crosses_wall([[4, 3]], [[6, 3]])[0]
    assert plan.crosses_wall([[4, 1]], [[6, 1]])[0]


def test_outer_corners_are_closed():
    plan = _plan()
    # Wall ends extend half a thickness, so the outer corner square is solid.
    assert shapely.contains_xy(plan.solid, -0.09, -0.09)
    assert plan.crosses_wall([[0.35, -0.3]], [[-0.3, 0.32]])[0]


def test_visibility_and_glass_transmittance():
    concrete, glass = _two_rooms("concrete"), _two_rooms("glass")
    p, q = [[2, 3]], [[8, 3]]
    assert not concrete.visible(p, q)[0] and concrete.light_transmittance(p, q)[0] == 0
    assert glass.visible(p, q)[0]
    assert glass.light_transmittance(p, q)[0] == pytest.approx(
        MATERIALS["glass"].light_transmittance
    )
    assert concrete.light_transmittance([[1, 1]], [[4, 5]])[0] == 1.0


def test_crossing_loss_sums_material_losses_and_counts_a_pillar_once():
    plan = _two_rooms("brick", pillars=[{"center": [2.5, 3.0], "size": [0.6, 0.6]}])
    brick, concrete = MATERIALS["brick"].loss_db(2.4), MATERIALS["concrete"].loss_db(2.4)
    loss = plan.crossing_loss_db(
        [[1, 1], [1, 3], [1, 3], [12, 3]], [[4, 1], [8, 3], [4, 3.6], [8, 3]], 2.4
    )
    # Through nothing; through the pillar centre (both diagonals) and the brick wall;
    # past a pillar corner; from outside through the outer concrete wall.
    np.testing.assert_allclose(loss, [0.0, concrete + brick, concrete, concrete])
    crossings = plan.element_crossings([[1, 3]], [[8, 3]])
    assert crossings.shape == (1, len(plan.walls) + 1) and crossings.sum() == 2


def test_loss_grows_with_frequency():
    for m in MATERIALS.values():
        assert m.loss_db(5.2) >= m.loss_db(2.4) > 0


def test_single_point_broadcasts_and_bad_shapes_are_named():
    plan = _two_rooms()
    out = plan.crosses_wall([1, 3], [[4, 3], [8, 3]])
    np.testing.assert_array_equal(out, [False, True])
    with pytest.raises(ValueError, match="p0 and p1 must have the same number"):
        plan.crosses_wall([[1, 1], [2, 2]], [[3, 3], [4, 4], [5, 5]])
    with pytest.raises(ValueError, match=r"points: expected points of shape"):
        plan.is_walkable(np.zeros((3, 4)))


def test_nearest_boundary_is_the_same_when_the_grid_must_use_larger_cells(monkeypatch):
    # A plan whose grid would pass its budget (long diagonal walls fill many
    # small cells) takes larger cells; any cell size finds the same points.
    pts = np.random.default_rng(6).uniform(-0.5, 10.5, (2000, 2))
    fine = _two_rooms().nearest_boundary(pts, 0.8)
    monkeypatch.setattr("indoorsim.world.plan._EDGE_GRID_BUDGET", 2000)
    plan = _two_rooms()
    coarse = plan.nearest_boundary(pts, 0.8)
    (grid,) = [g for _, _, g in plan._edge_grids.values()]
    assert grid[2] > 1.0 / 4  # the cells grew (0.8 m is served by the 1 m grid)
    np.testing.assert_array_equal(coarse, fine)


def test_rooms_are_the_closed_faces_of_the_wall_graph():
    plan = _two_rooms()
    assert len(plan.rooms) == 2
    assert sorted(round(r.area, 6) for r in plan.rooms) == [30.0, 30.0]


def test_nearest_boundary_point_agrees_with_shapely():
    plan = _two_rooms(
        pillars=[{"center": [2.5, 3.0]}],
        obstacles=[{"kind": "desk", "center": [7.5, 3], "size": [1.6, 0.8]}],
    )
    rng = np.random.default_rng(5)
    pts = rng.uniform(-0.5, 10.5, (3000, 2))
    near = plan.nearest_boundary(pts, 0.4)
    boundary = plan.walkable.boundary
    dist = shapely.distance(shapely.points(pts), boundary)
    found = ~np.isnan(near[:, 0])
    # Points within the distance (and only those) get a boundary point, the nearest one.
    np.testing.assert_array_equal(found, dist <= 0.4)
    np.testing.assert_allclose(np.hypot(*(near[found] - pts[found]).T), dist[found], atol=1e-12)
    on_boundary = shapely.distance(shapely.points(near[found]), boundary)
    np.testing.assert_allclose(on_boundary, 0.0, atol=1e-9)
