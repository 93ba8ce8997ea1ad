"""Floor plans to import: the MS mall floor of the real data, and tiny synthetic ones.

:func:`two_shops` is the closed-form case of the door rule: a 20 m × 10 m floor
whose lower 4 m are a corridor and whose upper 6 m are two shops side by side.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.conftest import REALDATA

MS_FLOOR = REALDATA / "ms-indoor-location-2020" / "site1" / "F1"
needs_ms_floor = pytest.mark.skipif(
    not (MS_FLOOR / "geojson_map.json").is_file(), reason=f"no MS floor plan at {MS_FLOOR}"
)

# Longitude/latitude of the synthetic floor's lower-left corner, and degrees per
# metre: any box does, since the importer stretches it onto floor_info's size.
_LON0, _LAT0, _DEG = 120.0, 30.0, 1e-5


def _lonlat(points: list[tuple[float, float]]) -> list[list[list[float]]]:
    ring = [[_LON0 + x * _DEG, _LAT0 + y * _DEG] for x, y in points]
    return [[*ring, ring[0]]]


def plan_geojson(shops: dict[str, list[tuple[float, float]]], size=(20.0, 10.0)) -> dict:
    """A FeatureCollection: the floor rectangle of ``size`` (m) and one polygon per shop."""
    w, h = size
    features = [
        {
            "type": "Feature",
            "geometry": {
                "type": "MultiPolygon",
                "coordinates": [_lonlat([(0, 0), (w, 0), (w, h), (0, h)])],
            },
            "properties": {"type": "floor", "name": "T1"},
        }
    ]
    for name, corners in shops.items():
        features.append(
            {
                "type": "Feature",
                "geometry": {"type": "Polygon", "coordinates": _lonlat(corners)},
                "properties": {"name": name},
            }
        )
    return {"type": "FeatureCollection", "features": features}


TWO_SHOPS = {
    "A": [(0, 4), (8, 4), (8, 10), (0, 10)],
    "B": [(8, 4), (20, 4), (20, 10), (8, 10)],
}
"""Shop A: 8 m × 6 m, its two longest edges the corridor side (y = 4) and the
exterior (y = 10). Shop B: 12 m × 6 m. The corridor: y < 4."""


def write_plan(folder: Path, shops=TWO_SHOPS, size=(20.0, 10.0)) -> tuple[Path, Path]:
    """``geojson_map.json`` and ``floor_info.json`` of a synthetic floor in ``folder``."""
    geo, info = folder / "geojson_map.json", folder / "floor_info.json"
    geo.write_text(json.dumps(plan_geojson(shops, size)), encoding="utf-8")
    info.write_text(
        json.dumps({"map_info": {"width": size[0], "height": size[1]}}), encoding="utf-8"
    )
    return geo, info
