"""Scenario checks beyond the schema: references between keys and the floor plan's geometry.

Every problem comes back as ``(key path, message)`` so that the loader can
report them all at once, each under the key it concerns (``doors[2].position``).
The geometric checks build the floor plan, so they sit above the world layer.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry import Polygon
from shapely.ops import unary_union

from indoorsim.scenario.schema import Scenario, WalkSurveySpec
from indoorsim.world.plan import door_on_wall, near_walls, plan_for, wall_polygons

__all__ = ["geometry_problems", "reference_problems"]


def reference_problems(scenario: Scenario) -> list[tuple[str, str]]:
    """Problems between keys: duplicate BSSIDs, surveys naming unknown routes."""
    problems: list[tuple[str, str]] = []
    seen: dict[str, int] = {}
    for i, ap in enumerate(scenario.wifi):
        key = ap.bssid.lower()
        if key in seen:
            problems.append(
                (f"wifi[{i}].bssid", f"duplicate BSSID {ap.bssid} (also wifi[{seen[key]}])")
            )
        seen.setdefault(key, i)
    for name, survey in scenario.surveys.items():
        if isinstance(survey, WalkSurveySpec) and survey.route not in scenario.routes:
            problems.append(
                (
                    f"surveys.{name}.route",
                    f"unknown route {survey.route!r}; routes are {sorted(scenario.routes)}",
                )
            )
    return problems


def _points(xy: Sequence[Sequence[float]]) -> NDArray[np.object_]:
    """Shapely points of (N, 2) coordinates (N may be 0)."""
    return shapely.points(np.array(xy, dtype=float).reshape(-1, 2))


def geometry_problems(scenario: Scenario) -> list[tuple[str, str]]:
    """Geometric sanity checks of a schema-valid scenario, as (key path, message)."""
    problems: list[tuple[str, str]] = []
    if scenario.outline is not None and not Polygon(scenario.outline).is_valid:
        problems.append(("outline", "polygon is self-intersecting or degenerate"))
        return problems
    walls = scenario.walls
    near = near_walls([door.position for door in scenario.doors], walls)
    for i, door in enumerate(scenario.doors):
        if not any(
            door_on_wall(door.position, walls[j].start, walls[j].to, walls[j].thickness) is not None
            for j in np.flatnonzero(near[i]).tolist()
        ):
            problems.append((f"doors[{i}].position", f"{list(door.position)} is not on any wall"))
    near = near_walls([win.start for win in scenario.windows], walls) & near_walls(
        [win.to for win in scenario.windows], walls
    )
    for i, win in enumerate(scenario.windows):
        on = [
            j
            for j in np.flatnonzero(near[i]).tolist()
            if door_on_wall(win.start, walls[j].start, walls[j].to, walls[j].thickness) is not None
            and door_on_wall(win.to, walls[j].start, walls[j].to, walls[j].thickness) is not None
        ]
        if not on:
            problems.append((f"windows[{i}]", "both ends must lie on the same wall"))
        if win.head > scenario.site.ceiling_height:
            problems.append((f"windows[{i}].head", "window head is above the ceiling"))
    for i, door in enumerate(scenario.doors):
        if door.height > scenario.site.ceiling_height:
            problems.append((f"doors[{i}].height", "door is taller than the ceiling"))
    plan = plan_for(scenario)
    if plan.outline.is_empty or plan.outline.area <= 0:
        problems.append(("walls", "the walls enclose no area: close them or give an 'outline'"))
        return problems
    h = scenario.site.ceiling_height
    outline = plan.outline
    shapely.prepare(outline)
    # Walls and pillars, of which only those within a hair of a luminaire can
    # hold it: the union is built only if there are any.
    wall_parts = np.array(wall_polygons(plan.walls) + [p for p, _ in plan.pillars], dtype=object)
    lum_points = _points([lum.position[:2] for lum in scenario.luminaires])
    in_outline = shapely.covers(outline, lum_points)
    near = shapely.STRtree(wall_parts).query(lum_points, predicate="dwithin", distance=1e-6)
    close = set(near[0].tolist())
    wall_solid = unary_union(list(wall_parts)) if close else Polygon()
    for i, lum in enumerate(scenario.luminaires):
        x, y, z = lum.position
        if not in_outline[i]:
            problems.append((f"luminaires[{i}].position", f"{[x, y, z]} is outside the building"))
        elif i in close and wall_solid.contains(lum_points[i]):
            problems.append(
                (f"luminaires[{i}].position", f"{[x, y, z]} is inside a wall or pillar")
            )
        if not 0 < z <= h + 1e-9:
            problems.append(
                (f"luminaires[{i}].position", f"height {z} m is not within the room (0, {h}]")
            )
    inside = shapely.covers(outline, _points([p.center for p in scenario.pillars]))
    for i, p in enumerate(scenario.pillars):
        if not inside[i]:
            problems.append((f"pillars[{i}].center", f"{list(p.center)} is outside the building"))
    inside = shapely.covers(outline, _points([o.center for o in scenario.obstacles]))
    for i, o in enumerate(scenario.obstacles):
        if not inside[i]:
            problems.append((f"obstacles[{i}].center", f"{list(o.center)} is outside the building"))
    for name, survey in scenario.surveys.items():
        region = getattr(survey, "region", None)
        if region is None:
            continue
        poly = Polygon(region)
        if not poly.is_valid:
            problems.append(
                (f"surveys.{name}.region", "polygon is self-intersecting or degenerate")
            )
        elif poly.intersection(plan.walkable).area <= 0:
            problems.append((f"surveys.{name}.region", "does not overlap the walkable area"))
    for name, route in scenario.routes.items():
        pts = np.array(route.points(), dtype=float)
        ok = plan.is_walkable(pts)
        key = "waypoints" if route.waypoints is not None else None
        for j in np.flatnonzero(~ok):
            where = f"routes.{name}.{key}[{j}]" if key else f"routes.{name}.{('start', 'goal')[j]}"
            problems.append((where, f"{pts[j].tolist()} is not in the walkable area"))
        if key and ok.all():
            blocked = plan.crosses_wall(pts[:-1], pts[1:])
            for j in np.flatnonzero(blocked):
                problems.append(
                    (
                        f"routes.{name}.waypoints[{j}]",
                        f"the leg {pts[j].tolist()} → {pts[j + 1].tolist()} passes through a wall",
                    )
                )
    return problems
