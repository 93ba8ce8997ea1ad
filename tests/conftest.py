"""Shared fixtures: paths to the shared folder and small scenarios built in Python."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
MINIMAL_SITE = SHARED / "examples" / "minimal-site.yaml"


@pytest.fixture
def minimal_site_path() -> Path:
    if not MINIMAL_SITE.is_file():
        pytest.skip(f"shared folder not found beside the repository: {MINIMAL_SITE}")
    return MINIMAL_SITE


def box_scenario(**overrides: object) -> dict:
    """A 10 m × 6 m concrete room as a plain dict; keys in ``overrides`` replace the defaults."""
    data: dict = {
        "name": "box",
        "site": {
            "latitude": 32.63,
            "longitude": 117.0,
            "date": "2025-01-01",
            "ceiling_height": 3.0,
        },
        "walls": [
            {"from": [0, 0], "to": [10, 0], "thickness": 0.2},
            {"from": [10, 0], "to": [10, 6], "thickness": 0.2},
            {"from": [10, 6], "to": [0, 6], "thickness": 0.2},
            {"from": [0, 6], "to": [0, 0], "thickness": 0.2},
        ],
    }
    data.update(overrides)
    return data
