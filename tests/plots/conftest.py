"""Shared fixtures of the plot tests: a small site with every element the figures draw."""

from __future__ import annotations

import pytest

from indoorsim.scenario import parse_scenario
from indoorsim.world.site import Site
from tests.conftest import box_scenario


@pytest.fixture(scope="module")
def site() -> Site:
    """A small office with every kind of element the plots draw."""
    walls = box_scenario()["walls"] + [
        {"from": [6, 0], "to": [6, 6], "thickness": 0.12, "material": "drywall"},
        {"from": [6, 3], "to": [10, 3], "thickness": 0.05, "material": "glass"},
    ]
    scenario = box_scenario(
        name="test-office",
        walls=walls,
        doors=[{"position": [6, 1.5]}, {"position": [8, 3]}],
        rooms=[{"name": "hall", "polygon": [[0, 0], [6, 0], [6, 6], [0, 6]]}],
        pillars=[{"center": [3, 3]}],
        obstacles=[
            {"kind": "desk", "center": [1.5, 5], "size": [1.4, 0.7]},
            {
                "kind": "cabinet",
                "center": [9, 5.5],
                "size": [1.0, 0.5],
                "height": 1.8,
                "steel_volume_m3": 0.01,
            },
        ],
        luminaires=[
            {"position": [2, 2, 3], "intensity_cd": 800},
            {"position": [8, 1.5, 3], "intensity_cd": 800},
        ],
        magnetic={
            "dipoles": [{"position": [4.5, 1, -0.3], "moment": [0, 0, 25]}],
            "rebar": [{"z": -0.15}],
        },
        wifi=[
            {"bssid": "02:00:00:00:00:01", "position": [1, 1, 2.5]},
            {"bssid": "02:00:00:00:00:2A", "position": [9, 1, 2.5]},
        ],
        routes={
            "tour": {"waypoints": [[1, 1.5], [5, 1.5], [8, 1.5]]},
            "errand": {"start": [1, 4], "goal": [8, 4.5]},
        },
    )
    return Site(parse_scenario(scenario))
