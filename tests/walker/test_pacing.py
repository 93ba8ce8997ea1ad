"""Pacing along the path: the slowing at route points, in closed form."""

from __future__ import annotations

import numpy as np
import pytest

from indoorsim.walker.pacing import mark_slowing
from indoorsim.walker.path import smootherstep


def test_a_dip_reaches_its_depth_at_the_point_and_fades_out_by_its_half_length():
    s = np.arange(0.0, 21.0)
    f = np.full(len(s), 1.1)  # the slow fluctuation, here constant
    ends = np.array([0.0, 8.0, 20.0])
    knots, factor = mark_slowing(ends, (s, f), np.array([0.4]), half_length_m=1.5)
    at = lambda x: float(np.interp(x, knots, factor))  # noqa: E731
    assert at(8.0) == pytest.approx(1.1 * 0.4)
    # Half way out the smootherstep is at one half: half the dip.
    assert at(8.75) == pytest.approx(1.1 * (1.0 - 0.6 * 0.5))
    assert at(6.5) == pytest.approx(1.1) and at(9.5) == pytest.approx(1.1)
    assert at(3.0) == at(15.0) == pytest.approx(1.1)
    # The dip is symmetric and never below its depth.
    x = np.linspace(6.0, 10.0, 81)
    np.testing.assert_allclose([at(v) for v in x], [at(16.0 - v) for v in x])
    assert factor.min() == pytest.approx(1.1 * 0.4)


def test_overlapping_dips_keep_the_deeper_and_a_factor_of_one_changes_nothing():
    s = np.arange(0.0, 11.0)
    f = np.ones(len(s))
    ends = np.array([0.0, 4.0, 5.0, 10.0])
    knots, factor = mark_slowing(ends, (s, f), np.array([0.5, 0.3]), half_length_m=2.0)
    assert float(np.interp(5.0, knots, factor)) == pytest.approx(0.3)
    # Between the two points the deeper dip's flank is below the shallower's own.
    flank = 1.0 - 0.7 * (1.0 - float(smootherstep(0.25)))
    assert float(np.interp(4.5, knots, factor)) == pytest.approx(flank)
    assert float(np.interp(4.0, knots, factor)) == pytest.approx(0.5)
    knots, factor = mark_slowing(ends, (s, f), np.array([1.0, 1.0]), half_length_m=2.0)
    np.testing.assert_array_equal(factor, np.ones(len(knots)))
