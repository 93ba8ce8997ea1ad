"""indoorsim: a simulation-and-benchmark suite for smartphone indoor positioning.

Quick start::

    import indoorsim
    site = indoorsim.load_site("minimal_room")      # a bundled name or a YAML path
    site.magnetic_field([[1.0, 2.0, 1.2]])          # (1, 3) µT

The names below are the package's door: each is imported from its module on
first use, so ``import indoorsim`` stays light (the command line starts fast)
and loads no layer it does not need. Modules that moved in 0.2 keep their old
import paths (:mod:`indoorsim._moved`).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from indoorsim import _moved
from indoorsim._version import __version__
from indoorsim.util import jit_cache

if TYPE_CHECKING:
    from indoorsim.io.fingerprints import FingerprintDB
    from indoorsim.io.recording import Recording
    from indoorsim.scenario.load import dump_scenario, load_scenario, load_site, resolve_scenario
    from indoorsim.scenario.schema import Scenario, ScenarioError
    from indoorsim.world.site import Site

# Before any module with compiled kernels is imported: their cache lives per user.
jit_cache.configure()
_moved.install()

_EXPORTS = {
    "FingerprintDB": "indoorsim.io.fingerprints",
    "Recording": "indoorsim.io.recording",
    "Scenario": "indoorsim.scenario.schema",
    "ScenarioError": "indoorsim.scenario.schema",
    "Site": "indoorsim.world.site",
    "dump_scenario": "indoorsim.scenario.load",
    "load_scenario": "indoorsim.scenario.load",
    "load_site": "indoorsim.scenario.load",
    "resolve_scenario": "indoorsim.scenario.load",
}

__all__ = [
    "FingerprintDB",
    "Recording",
    "Scenario",
    "ScenarioError",
    "Site",
    "__version__",
    "dump_scenario",
    "load_scenario",
    "load_site",
    "resolve_scenario",
]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'indoorsim' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
