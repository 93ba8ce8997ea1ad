"""Chen2022's experiments: the paper-table builder on hand-made leaderboard rows, and
(slow) the figures that reproduce."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.reproduce import chen2022 as rep


def test_paper_table_puts_our_per_estimate_rows_beside_the_papers_and_averages_the_modes() -> None:
    """The paper's errors are per step: the table reads the leaderboard's errors at
    the time each estimate refers to (``_reftime``), not its time-uniform ones."""
    stats = {"rmse": 1.0, "me": 2.0, "cep75": 1.5, "cep95": 2.0}
    rows = pd.DataFrame(
        [
            {"mode": m, "estimator": e, "ae": 99.0, **{f"{k}_reftime": v for k, v in stats.items()}}
            | {"ae_reftime": ae}
            for m, ae in zip(rep.MODES, (1.0, 2.0, 3.0, 4.0), strict=True)
            for e in ("chen2022-cpf", "dr-mm")
        ]
    )
    t = rep.paper_table(rows, rep.PAPER_TABLE_1).set_index(["mode", "estimator"])
    assert t.loc[("handheld", "chen2022-cpf"), "ae"] == 3.0
    assert t.loc[("handheld", "chen2022-cpf"), "paper_ae"] == 0.61
    assert t.loc[("general", "dr-mm"), "ae"] == 2.5  # the mean of the four modes
    assert np.isnan(t.loc[("calling", "edtw-rekf"), "ae"])  # not run: n/a, never invented
    assert t.loc[("calling", "edtw-rekf"), "method"].endswith("≈")  # marked approximation


def test_every_paper_row_has_the_five_statistics() -> None:
    for table in (rep.PAPER_TABLE_1, rep.PAPER_TABLE_2):
        assert set(table) == {*rep.MODES, "general"}
        for methods in table.values():
            assert all(len(v) == len(rep.STATS) for v in methods.values())


@pytest.mark.slow
def test_figures_8_and_23_reproduce() -> None:
    """The figures that reproduce (leaderboards/commentary.md), on the leaderboard's
    seeds: Fig. 8, HV-DDTW matching well ahead of MD-DTW in every mode; Fig. 23,
    the same error whichever phone surveyed (DDTW removes its offset)."""
    curves = rep.figure_errors(seeds=(0, 1, 2))
    for mode, fig8 in curves["fig8"].items():
        assert fig8["HV-DDTW"].mean() < 0.8 * fig8["MD-DTW"].mean(), mode
    for mode, fig23 in curves["fig23"].items():
        honor, nexus = (float(e.mean()) for e in fig23.values())
        assert abs(honor - nexus) < 0.15, (mode, honor, nexus)
