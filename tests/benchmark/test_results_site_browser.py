"""The results site in headless Chromium: the script runs without a console message, tables fill.

Needs the ``chromium`` binary (Debian package ``chromium``; ``.ci/run`` installs it).
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

CHROMIUM = shutil.which("chromium")
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="no chromium binary on PATH (apt-get install chromium)"
)


def dump_dom(page: Path, profile: Path) -> str:
    """The page's DOM after its script ran; fails on any console message."""
    run = subprocess.run(
        [
            str(CHROMIUM),
            "--headless",
            "--disable-gpu",
            "--no-sandbox",
            f"--user-data-dir={profile}",
            "--enable-logging=stderr",
            "--v=0",
            "--dump-dom",
            page.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    console = [line for line in run.stderr.splitlines() if ":CONSOLE" in line]
    assert console == [], console
    return run.stdout


def tables(dom: str) -> dict[str, dict[str, str]]:
    """Each table's attributes, by id."""
    return {
        m["id"]: dict(re.findall(r'([\w-]+)="([^"]*)"', m["attrs"]))
        for m in re.finditer(r'<table class="board" id="(?P<id>[^"]+)"(?P<attrs>[^>]*)>', dom)
    }


def test_index_and_a_scenario_page_run_their_script_and_fill_their_tables(board, tmp_path):
    index = dump_dom(board / "site" / "index.html", tmp_path / "profile")
    assert '<body data-ready="1">' in index
    assert tables(index)["t-best"]["data-visible"] == "4"

    dom = dump_dom(board / "site" / "han2023_corridor.html", tmp_path / "profile")
    assert '<body data-ready="1">' in dom
    table = tables(dom)["t-han2023_corridor"]
    assert table["data-visible"] == "8"
    assert table["data-sorted"] == "ae:asc"  # sorted on load by the script
    body = dom.split('id="t-han2023_corridor"', 1)[1].split("</tbody>", 1)[0]
    ae = [float(v) for v in re.findall(r'<td data-col="ae" data-value="([^"]+)"', body)]
    assert len(ae) == 8 and ae == sorted(ae)
    assert "start-only" not in body.split("</tr>", 1)[0]  # first in the CSV, worst AE
    # The metric selector starts on the headline: other metric columns hidden.
    assert re.search(r'<th data-col="me" data-kind="metric" class="hidden">', dom)
    assert re.search(r'<th data-col="ae" data-kind="metric" class="asc">', dom)


def test_a_table_with_a_not_applicable_row_sorts_it_last(board, tmp_path):
    dom = dump_dom(board / "site" / "minimal_room.html", tmp_path / "profile")
    assert tables(dom)["t-minimal_room"]["data-visible"] == "3"
    body = dom.split('id="t-minimal_room"', 1)[1].split("</tbody>", 1)[0]
    last = body.rsplit("<tr", 1)[1]
    assert 'class="na"' in last
