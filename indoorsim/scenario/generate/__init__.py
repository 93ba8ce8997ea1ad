"""Procedural buildings: a plausible floor from a kind, a size and a seed.

``generate(kind, size, seed)`` returns a complete, validated
:class:`~indoorsim.scenario.Scenario`: walls with doors and windows, pillars on
a structural grid, furniture, ceiling lights, steel, WiFi access points, named
routes and survey plans. It can be saved with
:func:`~indoorsim.scenario.dump_scenario` and loaded back unchanged.

Kinds (the registry :data:`KINDS`, one module each; ``size`` is the footprint's
x and y extent in metres, drawn from the kind's usual range when omitted):

* ``office`` (:mod:`.office`) — a straight corridor with rooms on one or both
  sides, a stair and lift core, desks and steel cabinets in some rooms.
* ``basement`` (:mod:`.basement`) — an underground car park: a dense pillar
  grid, parked cars, driving aisles, a stair core with lift, a plant room and
  a ramp; dim light.
* ``l_corridor`` / ``u_corridor`` (:mod:`.corridors`) — a school-style
  single-loaded corridor along the outside of an L- or U-shaped wing, rooms on
  the courtyard side, windows on the outer wall, stairs at the arm ends.
* ``open_hall`` (:mod:`.open_hall`) — a mall or atrium: shops round a large
  hall with free-standing columns, kiosks and an escalator, a glass facade
  where no shops stand.

Every kind builds on :mod:`.draft`, the shared floor under construction
(:class:`~.draft.Draft`) and its helpers, and on :mod:`.cells`, the layout
primitives (cells, wall pieces, intervals); what the kinds have in common is
described here.

How a floor is laid out: each builder tiles the footprint with axis-aligned
rectangles (cells) — corridors, rooms, halls, stairs, lift shafts, plant
rooms, ramps. Walls follow from the tiling: one stands wherever two different
spaces meet (none between two circulation cells) and along the footprint's
edge, its thickness and material set by what it separates. Doors are cut where
a room meets circulation, clear of pillars and wall junctions. Pillars stand on
a structural grid (6–9 m bays), embedded in walls or free-standing in open
areas. Routes follow corridor and aisle centre lines, and furniture is placed
afterwards, clear of doors and routes, so every route stays walkable.

Steel (see :meth:`.draft.Draft.magnetic`): columns carry 0.035–0.07 m³ of
reinforcement per storey (a 0.6 m column with 3–5 % steel plus the beam bars
at its head; 0.07–0.11 m³ under a building in a car park, 0.08–0.13 m³ of
rolled section in a steel-framed mall), the floor and ceiling slabs a rebar
mesh (or a mall's steel decking) at z = −0.15 m and ceiling + 0.15 m, the
beams on the column lines 5–8 dm³ per metre (14.5 in a mall, with secondary
beams of 8 dm³ per metre at most 3 m apart), steel
furniture 1.5–12 dm³ per piece, and the strong sources are explicit dipoles of
up to 100 A·m² (REALISM §2.3): lift cars and counterweights, fire doors, steel
door frames, radiators, electrical cabinets, pumps, escalator trusses. Their
moments point mostly along the Earth's field (induced) with a random remanent
part. Reinforcement is bars magnetised along their axes, one element (a
column's storey, a slab's bay or a mesh sheet or decking span, a beam's bay,
a secondary beam) at a time
(:class:`~indoorsim.scenario.schema.MagneticSpec`). The remanent ratio, 2, is
the one amplitude calibrated against REALISM §2.2 (real indoor walks: σ(|B|)
2–9 µT, extremes up to ±25 µT): along the round trip of generated offices
(seeds 0–19, phone at 1.2 m) σ is 2.2–6.7 µT and the extremes −22 to +23 µT.
The spectrum is not calibrated but follows from the elements: the 1/e
correlation length is 1.3–5.5 m (median 2.1; real walks 1.8–4.7) and 0.66 of
the variance (median) lies above 10 m (real 0.64–0.83). With remanence drawn
dipole by dipole and isotropic steel, as before, it was 0.8–1.2 m and 0.25.

Light: luminaires of one type per area, identical within it (REALISM §3.2):
LED tubes (≈ 500–600 cd, exponent ≈ 1), LED panels (1500–1800 cd, exponent
2.4–2.75) or downlights (900–1400 cd, exponent 1.5–2), 3–5 m apart along
corridors and in a 2.4–3.6 m grid in rooms, giving roughly 100–500 lx at desk
and phone height; car parks use tubes only over the aisles, so they stay dim.

WiFi: dual-band access points (one 2.4 GHz and one 5 GHz BSSID each) on the
ceiling every 10–20 m along circulation, and some on room walls, with
locally administered, unique BSSIDs; 17–20 dBm EIRP in either band.

Surveys: every kind declares the two papers' offline phases
(:func:`~.draft.survey_plans`): Han2023's 1.2 m grid, 30 s at 50 Hz per
point, and Chen2022's walk survey along the kind's main route with reference
points 5–10 m apart.

Randomness: every builder draws from its own ``numpy.random.default_rng(seed)``
and nothing else, so the same (kind, size, seed) always gives the same scenario.
"""

from __future__ import annotations

from collections.abc import Callable

from indoorsim.scenario.generate.basement import build_basement
from indoorsim.scenario.generate.cells import (
    Size,
)
from indoorsim.scenario.generate.corridors import build_l_corridor, build_u_corridor
from indoorsim.scenario.generate.office import build_office
from indoorsim.scenario.generate.open_hall import build_open_hall
from indoorsim.scenario.schema import Scenario
from indoorsim.util.errors import UnknownNameError

__all__ = ["KINDS", "Builder", "UnknownKindError", "generate"]

Builder = Callable[[Size | None, int], Scenario]
"""A kind's builder: ``(size or None, seed) -> Scenario``."""


class UnknownKindError(UnknownNameError, KeyError):
    """A building kind :data:`KINDS` does not hold."""

    kind = "building kind"


KINDS: dict[str, Builder] = {
    "office": build_office,
    "basement": build_basement,
    "l_corridor": build_l_corridor,
    "u_corridor": build_u_corridor,
    "open_hall": build_open_hall,
}
"""The building kinds by name. A builder takes ``(size or None, seed)`` and returns
a validated scenario; adding an entry makes a new kind available to :func:`generate`."""


def generate(kind: str, size: tuple[float, float] | None = None, seed: int = 0) -> Scenario:
    """Build a plausible floor of ``kind``.

    Args:
        kind: a key of :data:`KINDS` (``office``, ``basement``, ``l_corridor``,
            ``u_corridor``, ``open_hall``).
        size: the footprint's x and y extent in metres; drawn from the kind's
            usual range when None.
        seed: seeds everything random about the building (a non-negative int).

    Returns:
        A validated scenario named ``"{kind}-{seed}"``; the same arguments always
        give an equal scenario.

    Raises:
        UnknownKindError: for an unknown kind (also a ``KeyError``; it lists the valid ones).
        ValueError: for a size below the kind's minimum, or a negative seed.

    Example:
        >>> s = generate("office", seed=3)
        >>> s.name, "corridor" in s.routes
        ('office-3', True)
    """
    try:
        builder = KINDS[kind]
    except KeyError:
        raise UnknownKindError(kind, sorted(KINDS)) from None
    if seed < 0:
        raise ValueError(f"seed must be non-negative, got {seed}")
    return builder(size, seed)
