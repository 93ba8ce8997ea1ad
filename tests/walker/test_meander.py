"""The walker's weave off its line (indoorsim.walker.meander)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from indoorsim.scenario import RouteSpec
from indoorsim.walker.gait import WalkerParams, walk
from indoorsim.walker.meander import keep_room, lateral_meander
from indoorsim.walker.route import plan_route
from tests.walker.conftest import assert_inside


def test_the_weave_has_the_drawn_size_and_its_slope_the_closed_form_one():
    """(d/ds + ω)⁴ z = white noise: z's RMS is the drawn one, its slope's RMS is ω/√5 of
    it, and it fades to rest at both ends."""
    rms, wavelength = 0.08, 5.0
    m = lateral_meander(5000.0, rms, wavelength, 4.0, np.random.default_rng(0))
    offset, slope = m.at(m.s)
    inner = (m.s > 10.0) & (m.s < m.s[-1] - 10.0)
    assert offset[inner].std() == pytest.approx(rms, rel=0.05)
    omega = 2 * math.pi / wavelength
    assert slope[inner].std() == pytest.approx(rms * omega / math.sqrt(5), rel=0.05)
    # Level and on the line at both ends, and held beyond them.
    ends = np.array([0.0, m.s[-1]])
    np.testing.assert_allclose(m.at(ends)[0], 0.0, atol=1e-12)
    np.testing.assert_allclose(m.at(ends)[1], 0.0, atol=1e-9)
    np.testing.assert_allclose(m.at(np.array([-1.0, m.s[-1] + 1.0]))[0], 0.0, atol=1e-12)
    # The same draws for the same length and seed; none without a length's worth.
    again = lateral_meander(5000.0, rms, wavelength, 4.0, np.random.default_rng(0))
    np.testing.assert_array_equal(again.offset, m.offset)


def test_the_weave_keeps_its_distance_from_a_wall_beside_the_path(corridor):
    """A path 0.4 m from a wall: toward it the weave stops short of the clearance; away
    from it, and in the open, it is nearly the drawn one."""
    s = np.linspace(0.0, 30.0, 601)
    heading = np.zeros_like(s)
    drawn = lateral_meander(30.0, 0.15, 5.0, 2.0, np.random.default_rng(1))
    # The corridor's wall face is at y = 0.1: the path runs 0.4 m from it, along +x.
    near = keep_room(
        drawn, np.column_stack([5.0 + s, np.full_like(s, 0.5)]), heading, corridor, 0.3
    )
    toward = drawn.offset < 0.0  # − is to the right of +x: toward the wall
    assert (0.5 + near.offset[toward] - 0.1 > 0.3 - 0.02).all()
    assert drawn.offset[toward].min() < -0.12  # the drawn weave would have come closer
    # Probed to a metre, the room eases an offset within 15 cm by no more than 1.2 %.
    away = (drawn.offset > 0.0) & (drawn.offset < 0.15)
    np.testing.assert_allclose(near.offset[away], drawn.offset[away], rtol=0.012)
    # In the middle of the 3 m corridor, 1.4 m from either wall, the weave is as drawn.
    middle = keep_room(
        drawn, np.column_stack([5.0 + s, np.full_like(s, 1.5)]), heading, corridor, 0.3
    )
    within = np.abs(drawn.offset) < 0.15
    np.testing.assert_allclose(middle.offset[within], drawn.offset[within], rtol=0.012)


def test_a_walker_weaves_off_its_line_and_back_onto_its_ends(corridor):
    route = plan_route(corridor, RouteSpec(waypoints=[(1.0, 1.5), (39.0, 1.5)], speed=1.3))
    body = walk(corridor, route, WalkerParams(), np.random.default_rng(2))
    line = body.pos[:, 1] - body.gait_offset[:, 1] - 1.5
    moving = body.moving & (body.pos[:, 0] > 8.0) & (body.pos[:, 0] < 32.0)
    # Centimetres either side of the line (the drawn RMS 6–11 cm), not metres.
    assert 0.02 < line[moving].std() < 0.15
    # It starts and ends on the route's points.
    assert abs(line[0]) < 1e-6 and abs(line[-1]) < 1e-6
    # The body faces its way along the weave: the heading's departure from the corridor
    # is the line's slope.
    along = body.pos[moving, 0] - body.gait_offset[moving, 0]
    slope = np.gradient(line[moving], along)
    np.testing.assert_allclose(np.tan(body.heading[moving]), slope, atol=2e-3)
    assert_inside(corridor, body)
    # Without it the walker keeps to the line.
    plain = walk(corridor, route, WalkerParams(meander_m=(0.0, 0.0)), np.random.default_rng(2))
    np.testing.assert_allclose(plain.pos[:, 1] - plain.gait_offset[:, 1], 1.5, atol=1e-9)
