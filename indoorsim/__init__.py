"""indoorsim: a simulation-and-benchmark suite for smartphone indoor positioning.

Quick start::

    import indoorsim
    site = indoorsim.load_site("minimal_room")      # a bundled name or a YAML path
    site.magnetic_field([[1.0, 2.0, 1.2]])          # (1, 3) µT
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from indoorsim.scenario import (
    Scenario,
    ScenarioError,
    dump_scenario,
    load_scenario,
    resolve_scenario,
)

if TYPE_CHECKING:
    from indoorsim.world.site import Site

__version__ = "0.1.0"
__all__ = [
    "Scenario",
    "ScenarioError",
    "Site",
    "__version__",
    "dump_scenario",
    "load_scenario",
    "load_site",
]


def load_site(name_or_path: str | Path | Scenario) -> Site:
    """Load a bundled scenario by name, a scenario YAML file, or a :class:`Scenario` into a Site."""
    from indoorsim.world.site import Site

    if isinstance(name_or_path, Scenario):
        return Site(name_or_path)
    return Site(load_scenario(resolve_scenario(name_or_path)))


def __getattr__(name: str) -> object:
    if name == "Site":
        from indoorsim.world.site import Site

        return Site
    raise AttributeError(f"module 'indoorsim' has no attribute {name!r}")
