"""Real walkers' vigour: what a data set draws so that its walkers differ as real ones do.

A walker's vigour — the pelvis's bounce (``bounce_fraction``), the width of the
loading peak in double support (``loading_width``) and the heel-strike jolts
(``heel_strike_mps2``) — sets how hard a phone is shaken at a given speed. Real
walkers differ in it by more than a factor of two at the same speed, and the
three go together: a walker who bounces more has a broader loading peak. A
model trained on walkers of one vigour reads a vigorous walker's bounce as
speed (a learned-io network overestimated the distance of the twins of the
four most vigorous real surveyors by 10–35 %; ``leaderboards/commentary.md``).

``real_walkers.csv`` beside this module holds the vigour ``indoorsim
calibrate`` fits to real recordings with known speed, one row per walk whose
fit converged inside its ranges; ``indoorsim realism --refresh-reference``
writes it from the raw logs
(:func:`indoorsim.benchmark.realism.reference.real_walker_table`). A data
set draws one row per walk, all three together (:func:`draw_real_vigour`).
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["REAL_WALKERS_CSV", "VIGOUR_FIELDS", "draw_real_vigour", "load_real_walkers"]

REAL_WALKERS_CSV = Path(__file__).with_name("real_walkers.csv")

VIGOUR_FIELDS = ("bounce_fraction", "loading_width", "heel_strike_mps2")
"""The :class:`~indoorsim.walker.gait.WalkerParams` fields a real walker's row sets."""


@cache
def _table(path: Path) -> pd.DataFrame:
    table = pd.read_csv(path)
    missing = [c for c in ("dataset", "walk", "licence", *VIGOUR_FIELDS) if c not in table]
    if missing:
        raise ValueError(f"{path}: the real walkers' table lacks the columns {missing}")
    values = table[list(VIGOUR_FIELDS)].to_numpy(dtype=float)
    if not len(table) or not np.isfinite(values).all():
        raise ValueError(f"{path}: the real walkers' table is empty or has a missing value")
    return table


def load_real_walkers(path: Path = REAL_WALKERS_CSV) -> pd.DataFrame:
    """The committed table: dataset, walk, licence, the walker's height and speed as
    fitted, and its vigour (:data:`VIGOUR_FIELDS`), one row per real walk.

    Raises:
        ValueError: the table lacks a column or a value.
    """
    return _table(Path(path)).copy()


def draw_real_vigour(rng: np.random.Generator, path: Path = REAL_WALKERS_CSV) -> dict[str, float]:
    """One real walker's vigour, the row drawn uniformly: ``{field: value}`` for
    :data:`VIGOUR_FIELDS` (each a single number, which fixes that range of
    :class:`~indoorsim.walker.gait.WalkerParams`)."""
    table = _table(Path(path))
    row = table.iloc[int(rng.integers(len(table)))]
    return {name: float(row[name]) for name in VIGOUR_FIELDS}
