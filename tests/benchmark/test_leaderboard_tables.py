"""The Markdown boards: a compact headline table that links the CSV and the site page."""

from __future__ import annotations

import pandas as pd

from indoorsim.benchmark.leaderboard import (
    HEADLINE_COLUMNS,
    METRIC_COLUMNS,
    board_links,
    markdown_table,
    write_readme,
)
from tests.benchmark.conftest import BOARD


def _rows() -> pd.DataFrame:
    corridor = pd.read_csv(BOARD / "han2023_corridor.csv")
    return corridor[corridor["mode"] == "handheld"].head(3).reset_index(drop=True)


def _header(table: str) -> list[str]:
    return [c.strip() for c in table.splitlines()[0].strip("|").split("|")]


def test_the_board_shows_the_headline_with_its_spread_over_seeds():
    rows = _rows()
    table = markdown_table(rows)
    assert HEADLINE_COLUMNS == ("ae", "rmse", "cep95")
    assert _header(table) == ["estimator", "mode", "seeds", "ae", "rmse", "cep95"]
    r = rows.iloc[0]
    cells = [f"{r[c]:.2f} ± {r[f'{c}_std']:.2f}" for c in HEADLINE_COLUMNS]
    assert f"| {r['estimator']} | handheld | {int(r['seeds'])} | {' | '.join(cells)} |" in table
    assert len(table.splitlines()) == 2 + len(rows)


def test_a_caller_can_still_ask_for_every_metric():
    table = markdown_table(_rows(), columns=METRIC_COLUMNS)
    assert _header(table)[3:] == list(METRIC_COLUMNS)


def test_a_row_not_run_reads_n_a_and_one_seed_has_no_spread():
    rows = _rows().head(2).copy()
    rows.loc[0, "seeds"] = 0
    rows.loc[1, "seeds"] = 1
    first, second = markdown_table(rows).splitlines()[2:]
    assert first.endswith("| n/a | n/a | n/a |")
    assert "±" not in second


def test_readme_links_each_board_s_csv_and_site_page(tmp_path):
    rows = _rows()
    write_readme(tmp_path, {"han2023_corridor": rows, "real_data": rows})
    readme = (tmp_path / "README.md").read_text()
    assert board_links("han2023_corridor") in readme
    assert "[han2023_corridor.csv](han2023_corridor.csv)" in readme
    assert "[site/han2023_corridor.html](site/han2023_corridor.html)" in readme
    assert "[real_data.csv](real_data.csv)" in readme
    assert "![tracks](han2023_corridor_tracks.png)" in readme
    assert "| cep50 |" not in readme  # the headline only
