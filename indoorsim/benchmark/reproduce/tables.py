"""Side-by-side cells and method orderings shared by the papers' reproduction tables."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["cell", "ordering", "paper_cells", "rank_line"]


def ordering(ours: Sequence[float], paper: Sequence[float]) -> bool:
    """Whether two score lists rank their methods in the same order (ties broken alike)."""
    return list(np.argsort(ours, kind="stable")) == list(np.argsort(paper, kind="stable"))


def cell(ours: float, paper: float, digits: int = 2) -> str:
    """The cell "ours (paper)" to ``digits`` decimals; n/a where we have no number."""
    ours_s = "n/a" if not np.isfinite(ours) else f"{ours:.{digits}f}"
    return f"{ours_s} ({paper:.{digits}f})"


def paper_cells(row: Mapping[str, Any], keys: Iterable[str], digits: int = 2) -> str:
    """The cells of ``keys`` in a table row, each ``row[k]`` beside ``row["paper_" + k]``.

    >>> paper_cells({"ae": 1.0, "paper_ae": 1.5, "me": 2.0, "paper_me": 3.0}, ["ae", "me"])
    '1.00 (1.50) | 2.00 (3.00)'
    """
    return " | ".join(cell(row[k], row[f"paper_{k}"], digits) for k in keys)


def rank_line(names: Sequence[str], ours: Sequence[float], paper: Sequence[float]) -> str:
    """Methods ranked by mean error, ours and the paper's (those we could not run left out)."""
    keep = [i for i, v in enumerate(ours) if np.isfinite(v)]
    names = [names[i] for i in keep]
    ours, paper = [ours[i] for i in keep], [paper[i] for i in keep]

    def order(v: Sequence[float]) -> str:
        return " < ".join(names[i] for i in np.argsort(v, kind="stable"))

    same = "same order" if ordering(ours, paper) else "**different order**"
    return f"Mean error, best first — ours: {order(ours)}; paper: {order(paper)} ({same})."
