"""``indoorsim scenarios``: one aligned row per bundled scenario, with its counts."""

from __future__ import annotations

import re

from indoorsim.cli import main
from indoorsim.scenario import bundled_scenarios, load_scenario


def _table(text: str) -> dict[str, list[str]]:
    """Rows of the ``scenarios`` table by name; columns are separated by two or more spaces."""
    rows = [re.split(r"\s{2,}", line.strip()) for line in text.splitlines() if line.strip()]
    return {row[0]: row[1:] for row in rows}


def test_scenarios_lists_every_bundled_scenario_with_its_counts(capsys):
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    table = _table(out)
    assert table["name"] == ["size (m)", "walls", "lights", "APs", "dipoles", "description"]
    bundled = bundled_scenarios()
    assert "minimal_room" in bundled
    assert set(table) - {"name"} == set(bundled)
    for name, path in bundled.items():
        scenario = load_scenario(path)
        size, walls, lights, aps = table[name][:4]
        assert re.fullmatch(r"\d+\.\d × \d+\.\d", size)
        assert (int(walls), int(lights), int(aps)) == (
            len(scenario.walls),
            len(scenario.luminaires),
            len(scenario.wifi),
        )
    # Aligned: the counts are right-justified under their headers.
    header, *rows = out.splitlines()
    for column in ("walls", "lights", "APs", "dipoles"):
        end = header.index(column) + len(column)
        assert all(row[end - 1].isdigit() and row[end : end + 1] in ("", " ") for row in rows)
