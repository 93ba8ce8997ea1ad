"""The static results site: pages from a small leaderboards folder, well formed and offline."""

from __future__ import annotations

import json
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import pandas as pd
import pytest

from indoorsim.cli import main

VOID = {"meta", "link", "img", "input", "br", "hr", "source", "wbr", "col", "area", "base"}


class Page(HTMLParser):
    """Tags checked for nesting; per table its body rows; every src and href."""

    def __init__(self) -> None:
        super().__init__()
        self.open: list[str] = []
        self.tables: dict[str, list[dict[str, str | None]]] = {}
        self.links: list[str] = []
        self.body: dict[str, str | None] = {}
        self._table: str | None = None
        self._in_body = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        self.links += [v for k, v in attrs if k in ("src", "href") and v is not None]
        if tag == "body":
            self.body = a
        if tag == "table":
            self._table = a["id"]
            self.tables[a["id"]] = []
        if tag == "tbody":
            self._in_body = True
        if tag == "tr" and self._in_body:
            self.tables[self._table].append(a)
        if tag not in VOID:
            self.open.append(tag)

    def handle_endtag(self, tag: str) -> None:
        assert self.open and self.open[-1] == tag, f"</{tag}> closes <{self.open[-1:]}>"
        self.open.pop()
        if tag == "tbody":
            self._in_body = False


def parse(path: Path) -> Page:
    page = Page()
    page.feed(path.read_text())
    page.close()
    assert page.open == [], f"{path.name}: unclosed {page.open}"
    return page


def test_a_page_per_board_and_an_index(board):
    pages = {p.stem for p in (board / "site").glob("*.html")}
    expected = {"index", "han2023_corridor", "minimal_room", "han2023", "chen2022"}
    assert pages == expected | {"realism", "real_data"}


@pytest.mark.parametrize(
    ("page", "tables"),
    [
        ("han2023_corridor", {"t-han2023_corridor": "han2023_corridor"}),
        ("minimal_room", {"t-minimal_room": "minimal_room"}),
        ("han2023", {"t-han2023_table1": "han2023_table1"}),
        ("chen2022", {"t-chen2022_table2": "chen2022_table2"}),
        ("realism", {"t-realism_motion": "realism_motion"}),
        ("real_data", {"t-real_data": "real_data"}),
    ],
)
def test_pages_parse_and_hold_every_csv_row_with_its_provenance(board, page, tables):
    parsed = parse(board / "site" / f"{page}.html")
    assert set(parsed.tables) == set(tables)
    revision = json.loads((board / "provenance.json").read_text())["git_revision"]
    for table_id, csv in tables.items():
        frame = pd.read_csv(board / f"{csv}.csv")
        rows = parsed.tables[table_id]
        assert len(rows) == len(frame) > 0
        expected = frame["git_revision"] if "git_revision" in frame else [revision] * len(frame)
        for row, rev in zip(rows, expected, strict=True):
            assert f"git_revision: {rev}" in row["title"]
            assert "package_version: " in row["title"]


def test_the_index_holds_the_best_row_per_scenario_and_mode(board):
    parsed = parse(board / "site" / "index.html")
    # corridor: handheld and pocketed; minimal_room: handheld; real data: handheld.
    assert len(parsed.tables["t-best"]) == 4
    text = (board / "site" / "index.html").read_text()
    for page in ("han2023_corridor", "minimal_room", "han2023", "realism", "real_data"):
        assert f'href="{page}.html"' in text


def test_the_site_is_self_contained(board):
    for path in (board / "site").glob("*.html"):
        text = path.read_text()
        assert not re.search(r"https?://|//[a-z]", text.replace("file://", "")), path.name
        for link in parse(path).links:
            assert not re.match(r"[a-z]+:", link), (path.name, link)
            assert (path.parent / link).resolve().exists(), (path.name, link)
    html = (board / "site" / "han2023_corridor.html").read_text()
    assert 'src="../han2023_corridor_cdf.png"' in html
    assert "<script>" in html and "<style>" in html


def test_leaderboard_site_only_rebuilds_the_site_from_the_csvs(board, tmp_path, capsys):
    shutil.rmtree(board / "site")
    assert main(["leaderboard", "--site-only", "--out", str(board)]) == 0
    assert "wrote 7 pages" in capsys.readouterr().out
    assert (board / "site" / "index.html").is_file()
    assert main(["leaderboard", "--site-only", "--out", str(tmp_path)]) == 2
    assert "no leaderboard CSVs" in capsys.readouterr().err
