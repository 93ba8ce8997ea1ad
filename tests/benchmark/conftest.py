"""Fixtures of the benchmark tests."""

from __future__ import annotations

import shutil
from pathlib import Path

import pandas as pd
import pytest

from indoorsim.benchmark.results_site import write_site

BOARD = Path(__file__).resolve().parents[2] / "leaderboards"


@pytest.fixture(scope="module")
def board(tmp_path_factory) -> Path:
    """A tiny leaderboards folder: a few rows of the committed CSVs in their real columns."""
    out = tmp_path_factory.mktemp("leaderboards")
    corridor = pd.read_csv(BOARD / "han2023_corridor.csv")
    # Rows in the CSV's order (start-only first), so a sort on load shows.
    corridor[corridor["mode"].isin(["handheld", "pocketed"])].groupby("mode").head(4).to_csv(
        out / "han2023_corridor.csv", index=False
    )
    # Any scenario name is a board: found by its columns, not its name.
    room = corridor.head(3).assign(scenario="minimal_room")
    room.loc[room.index[-1], ["ae", "rmse", "cep95"]] = float("nan")  # a not-applicable row
    room.to_csv(out / "minimal_room.csv", index=False)
    for name in ("real_data", "han2023_table1", "chen2022_table2", "realism_motion"):
        pd.read_csv(BOARD / f"{name}.csv").head(4).to_csv(out / f"{name}.csv", index=False)
    for png in ("han2023_corridor_cdf.png", "realism_motion.png"):
        shutil.copy(BOARD / png, out / png)
    shutil.copy(BOARD / "provenance.json", out / "provenance.json")
    write_site(out)
    return out
