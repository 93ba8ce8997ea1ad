"""Every docstring example in the package runs (STYLE: examples are doctests).

Modules are imported by their installed names (``indoorsim.envs``, not the
``envs/`` folder), so registries are filled once.
"""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest


def _modules() -> list[str]:
    # envs/ and estimators/ are mapped into the namespace by the installer, so
    # walking indoorsim.__path__ alone would miss them: walk each package.
    names = []
    for package in ("indoorsim", "indoorsim.envs", "indoorsim.estimators"):
        pkg = importlib.import_module(package)
        names.append(package)
        names += [m.name for m in pkgutil.walk_packages(pkg.__path__, prefix=package + ".")]
    return sorted(set(names) - {"indoorsim.__main__"})  # importing __main__ runs the CLI


MODULES = _modules()


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
