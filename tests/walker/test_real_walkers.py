"""Real walkers' vigour: the committed table, and drawing one walker's from it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from indoorsim.walker.gait import WalkerParams
from indoorsim.walker.real_walkers import (
    VIGOUR_FIELDS,
    draw_real_vigour,
    load_real_walkers,
)


def test_every_real_walker_is_a_valid_walker_of_its_own_vigour():
    table = load_real_walkers()
    assert len(table) >= 10
    assert table["licence"].str.len().min() > 0
    for _, row in table.iterrows():
        walker = WalkerParams(**{name: float(row[name]) for name in VIGOUR_FIELDS})
        assert walker.bounce_fraction == row["bounce_fraction"]
        assert walker.loading_width == (row["loading_width"],) * 2
        assert walker.heel_strike_mps2 == (row["heel_strike_mps2"],) * 2
    # Real walkers differ: the bounce spans more than a factor of two.
    assert table["bounce_fraction"].max() > 2.0 * table["bounce_fraction"].min()


def test_a_draw_is_one_whole_row_the_same_for_the_same_seed_and_every_row_comes_up():
    table = load_real_walkers()
    rows = {tuple(r) for r in table[list(VIGOUR_FIELDS)].itertuples(index=False)}
    rng = np.random.default_rng(3)
    drawn = [tuple(draw_real_vigour(rng).values()) for _ in range(40 * len(table))]
    assert set(drawn) == rows  # whole rows, never a mix of two walkers
    again = np.random.default_rng(3)
    assert tuple(draw_real_vigour(again).values()) == drawn[0]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda t: t.drop(columns=["loading_width"]), "lacks the columns"),
        (lambda t: t.assign(heel_strike_mps2=np.nan), "missing value"),
        (lambda t: t.iloc[:0], "empty"),
    ],
    ids=["column", "value", "empty"],
)
def test_a_broken_table_says_what_and_where(tmp_path, change, message):
    path = tmp_path / "walkers.csv"
    change(load_real_walkers()).to_csv(path, index=False)
    with pytest.raises(ValueError, match=message) as err:
        draw_real_vigour(np.random.default_rng(0), path)
    assert str(path) in str(err.value)


def test_a_range_given_as_one_number_fixes_it_and_a_list_is_the_range():
    walker = WalkerParams(loading_width=0.15, heel_strike_mps2=[2.0, 3.0])
    assert walker.loading_width == (0.15, 0.15)
    assert walker.heel_strike_mps2 == (2.0, 3.0)
    with pytest.raises(ValueError, match="loading_width"):
        WalkerParams(loading_width=0.9)


def test_the_table_is_handed_out_as_a_copy_and_read_again_when_the_file_changes(tmp_path):
    first = load_real_walkers()
    first.loc[0, "bounce_fraction"] = -1.0
    assert load_real_walkers().loc[0, "bounce_fraction"] > 0
    path = tmp_path / "walkers.csv"
    load_real_walkers().to_csv(path, index=False)
    assert len(load_real_walkers(path)) == len(first)
    load_real_walkers().iloc[:2].to_csv(path, index=False)
    assert len(load_real_walkers(path)) == 2
    assert isinstance(first, pd.DataFrame)


@pytest.mark.parametrize(
    ("column", "value", "message"),
    [
        ("loading_width", 0.9, "line 3 .*loading_width"),
        ("bounce_fraction", "brisk", "line 3 .*could not convert"),
        ("licence", " ", "line 3 .*no licence"),
    ],
    ids=["no walker's", "not a number", "no licence"],
)
def test_a_bad_row_is_named_by_its_line(tmp_path, column, value, message):
    table = load_real_walkers().astype({column: object})
    table.loc[1, column] = value
    path = tmp_path / "walkers.csv"
    table.to_csv(path, index=False)
    with pytest.raises(ValueError, match=message) as err:
        load_real_walkers(path)
    assert str(path) in str(err.value)


@pytest.mark.parametrize("value", [[0.1], [0.1, 0.12, 0.9], True, "0.1", (0.1, None)], ids=repr)
def test_a_range_that_is_neither_one_number_nor_two_names_its_field(value):
    with pytest.raises(ValueError, match="WalkerParams loading_width: a range is one number"):
        WalkerParams(loading_width=value)


def test_numpy_numbers_and_arrays_are_ranges_too():
    walker = WalkerParams(loading_width=np.float32(0.15), heel_strike_mps2=np.array([2.0, 3.0]))
    assert walker.loading_width == pytest.approx((0.15, 0.15))
    assert walker.heel_strike_mps2 == (2.0, 3.0) and isinstance(walker.heel_strike_mps2, tuple)
