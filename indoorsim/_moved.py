"""Old import paths of modules that moved in the "Architecture" reorganisation (0.2).

``import indoorsim.recording`` (and every other path below) still works: it
gives the module at its new place, the same object, with a
:class:`DeprecationWarning` naming the new path. The aliases are resolved by a
meta-path finder installed on ``import indoorsim``, so no stub file sits in the
package tree.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings
from collections.abc import Sequence
from types import ModuleType

MOVED: dict[str, str] = {
    "indoorsim.atomic": "indoorsim.io.atomic",
    "indoorsim.evaluation": "indoorsim.benchmark.evaluation",
    "indoorsim.fingerprints": "indoorsim.io.fingerprints",
    "indoorsim.leaderboard": "indoorsim.benchmark.leaderboard",
    "indoorsim.metrics": "indoorsim.benchmark.metrics",
    "indoorsim.quaternion": "indoorsim.util.quaternion",
    "indoorsim.reallogs": "indoorsim.io.reallogs",
    "indoorsim.recording": "indoorsim.io.recording",
    "indoorsim.reproduce": "indoorsim.benchmark.reproduce",
    "indoorsim.reproduce.chen2022": "indoorsim.benchmark.reproduce.chen2022",
    "indoorsim.reproduce.han2023": "indoorsim.benchmark.reproduce.han2023",
    "indoorsim.reproduce.tables": "indoorsim.benchmark.reproduce.tables",
    "indoorsim.seeding": "indoorsim.util.seeding",
    "indoorsim.training": "indoorsim.dataset.train",
    "indoorsim.world.generate": "indoorsim.scenario.generate",
}
"""Old module path → new module path."""


class _AliasLoader(importlib.abc.Loader):
    def __init__(self, target: str):
        self.target = target
        self._spec: importlib.machinery.ModuleSpec | None = None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        warnings.warn(
            f"{spec.name} moved to {self.target}; import it from there "
            "(the old path will be removed in a later release)",
            DeprecationWarning,
            stacklevel=2,
        )
        module = importlib.import_module(self.target)
        self._spec = module.__spec__
        return module

    def exec_module(self, module: ModuleType) -> None:
        # The module is the new one, already executed: only the old name is bound.
        # The import system has just given it the alias's spec; it keeps its own.
        module.__spec__ = self._spec


class _MovedFinder(importlib.abc.MetaPathFinder):
    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        new = MOVED.get(fullname)
        if new is None:
            return None
        return importlib.util.spec_from_loader(fullname, _AliasLoader(new))


def install() -> None:
    """Put the finder on ``sys.meta_path`` once.

    It goes first: a moved package's submodules (``indoorsim.reproduce.tables``)
    would otherwise be found by the path finder in the new package's folder and
    loaded a second time under the old name.
    """
    if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _MovedFinder())
