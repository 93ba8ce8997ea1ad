"""Real walkers' vigour: what a data set draws so that its walkers differ as real ones do.

A walker's vigour — the pelvis's bounce (``bounce_fraction``), the width of the
loading peak in double support (``loading_width``) and the heel-strike jolts
(``heel_strike_mps2``) — sets how hard a phone is shaken at a given speed. Real
walkers differ in it by more than a factor of two at the same speed, and a
walker's three go together (they are fitted together, so a walk takes all three
of one walker, never a mix). A
model trained on walkers of one vigour reads a vigorous walker's bounce as
speed (a learned-io network overestimated the distance of the twins of the
four most vigorous real surveyors by 10–35 %: ``leaderboards/commentary.md``, and
``indoorsim/estimators/pipelines/learned_io.py``'s docstring).

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


def _table(path: Path) -> pd.DataFrame:
    # Read again when the file changes (a refreshed reference in the same process).
    stat = path.stat()
    return _read_table(path, stat.st_mtime_ns, stat.st_size)


@cache
def _read_table(path: Path, _mtime_ns: int, _size: int) -> pd.DataFrame:
    from indoorsim.walker.gait import WalkerParams  # gait is the heavier module

    table = pd.read_csv(path)
    missing = [c for c in ("dataset", "walk", "licence", *VIGOUR_FIELDS) if c not in table]
    if missing:
        raise ValueError(f"{path}: the real walkers' table lacks the columns {missing}")
    if not len(table):
        raise ValueError(f"{path}: the real walkers' table is empty")
    for i, row in table.iterrows():
        # Line i + 2 of the file: the header is line 1.
        try:
            values = [float(row[name]) for name in VIGOUR_FIELDS]
            if not np.isfinite(values).all():
                raise ValueError("a missing value")
            WalkerParams(**dict(zip(VIGOUR_FIELDS, values, strict=True)))
        except (TypeError, ValueError) as err:
            raise ValueError(f"{path}, line {i + 2} ({row['walk']}): {err}") from None
        if not str(row["licence"]).strip() or pd.isna(row["licence"]):
            raise ValueError(f"{path}, line {i + 2} ({row['walk']}): no licence")
    return table


def load_real_walkers(path: Path = REAL_WALKERS_CSV) -> pd.DataFrame:
    """The committed table: dataset, walk, licence, the walker's height and speed as
    fitted, and its vigour (:data:`VIGOUR_FIELDS`), one row per real walk.

    Raises:
        ValueError: the table lacks a column, a row a value or a licence, or a row's
            vigour is no walker's (its line named).
    """
    return _table(Path(path)).copy()


def draw_real_vigour(rng: np.random.Generator, path: Path = REAL_WALKERS_CSV) -> dict[str, float]:
    """One real walker's vigour, the row drawn uniformly: ``{field: value}`` for
    :data:`VIGOUR_FIELDS` (each a single number, which fixes that range of
    :class:`~indoorsim.walker.gait.WalkerParams`)."""
    table = _table(Path(path))
    row = table.iloc[int(rng.integers(len(table)))]
    return {name: float(row[name]) for name in VIGOUR_FIELDS}
