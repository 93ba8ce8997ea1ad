"""CLI fixtures: a recording written by ``indoorsim simulate``, scenarios under other names."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from indoorsim.cli import main

WALK = ["minimal_room", "--route", "main", "--device", "honor_50", "--seed", "3"]
SCHEDULE = "handheld,6:calling,12:pocketed"


def renamed_copy(source: Path, folder: Path, name: str) -> Path:
    """A copy of the scenario file ``source`` in ``folder``, named ``name``."""
    data = yaml.safe_load(source.read_text(encoding="utf-8"))
    data["name"] = name
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def walk_folder(tmp_path_factory) -> Path:
    """A recording written by ``indoorsim simulate`` with a three-mode schedule."""
    out = tmp_path_factory.mktemp("walks") / "main-3"
    assert main(["simulate", *WALK, "--mode", SCHEDULE, "--out", str(out)]) == 0
    return out
