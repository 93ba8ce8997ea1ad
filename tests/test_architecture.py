"""The package's architecture (DESIGN §1): layers import downward only, and no import circles.

Every ``import`` statement of the package is read from the source, at any
depth (a function-level import cannot hide a circle or a layer violation);
only imports under ``if TYPE_CHECKING:`` are left out of the circle check, as
they never run. Each module belongs to the layer of the longest prefix in
:data:`LAYERS`; it may import its own layer and those below, never above.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.conftest import REPO

# Installed package → source folder (pyproject's package-dir).
ROOTS = {"indoorsim": "indoorsim", "indoorsim.envs": "envs", "indoorsim.estimators": "estimators"}

# Module prefix → layer, bottom (0) to top (DESIGN §1).
LAYERS: dict[str, int] = {
    "indoorsim._version": 0,
    "indoorsim.util": 0,
    "indoorsim.scenario": 0,  # the package door and its schema
    "indoorsim.scenario.schema": 0,
    "indoorsim.world": 1,
    "indoorsim.scenario.checks": 2,  # geometry checks build the world's floor plan
    "indoorsim.scenario.load": 2,
    "indoorsim.scenario.generate": 2,
    "indoorsim.scenario.imports": 2,  # importers build on the generator's draft and the plan
    "indoorsim.walker": 2,
    "indoorsim.phone": 2,
    "indoorsim.simulate": 3,
    "indoorsim.survey": 3,
    "indoorsim.io": 3,
    "indoorsim.windows": 3,
    "indoorsim.estimators": 4,
    "indoorsim.benchmark": 5,
    "indoorsim.dataset": 5,
    "indoorsim.envs": 5,
    "indoorsim.plots": 5,
    "indoorsim.cli": 6,
    "indoorsim._moved": 7,  # old paths, resolved only by name
    "indoorsim": 7,  # the root door re-exports by name, on first use
    "indoorsim.__main__": 7,
}

# What the estimators may never see: the simulator's truth side (DESIGN §1, §8).
TRUTH_SIDE = ("indoorsim.world", "indoorsim.walker", "indoorsim.phone", "indoorsim.simulate")


@dataclass(frozen=True)
class Import:
    source: str
    target: str
    line: int
    type_checking: bool


def _module_files() -> dict[str, Path]:
    mods = {}
    for package, folder in ROOTS.items():
        for path in sorted((REPO / folder).rglob("*.py")):
            parts = list(path.relative_to(REPO / folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            mods[".".join([package, *parts])] = path
    return mods


MODULES = _module_files()


def _resolve(name: str) -> str | None:
    """The deepest module of the package that ``name`` names (a module or a name in one)."""
    while name:
        if name in MODULES:
            return name
        name = name.rpartition(".")[0]
    return None


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _imports(name: str, path: Path) -> Iterator[Import]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]

    def visit(node: ast.AST, type_checking: bool) -> Iterator[Import]:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _is_type_checking(child.test):
                for stmt in child.body:
                    yield from visit_stmt(stmt, True)
                for stmt in child.orelse:
                    yield from visit_stmt(stmt, type_checking)
            else:
                yield from visit_stmt(child, type_checking)

    def visit_stmt(node: ast.AST, type_checking: bool) -> Iterator[Import]:
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package
                for _ in range(node.level - 1):
                    anchor = anchor.rpartition(".")[0]
                base = f"{anchor}.{base}" if base else anchor
            # ``from pkg import sub`` imports the submodule when there is one.
            targets = [f"{base}.{a.name}" for a in node.names]
        for target in targets:
            resolved = _resolve(target)
            if resolved is not None and resolved != name:
                yield Import(name, resolved, node.lineno, type_checking)
        yield from visit(node, type_checking)

    yield from visit(tree, False)


IMPORTS = [imp for name, path in MODULES.items() for imp in _imports(name, path)]


def layer(module: str) -> int:
    prefix = max((p for p in LAYERS if module == p or module.startswith(p + ".")), key=len)
    return LAYERS[prefix]


def test_every_module_has_a_layer():
    for module in MODULES:
        assert any(module == p or module.startswith(p + ".") for p in LAYERS), module


def test_no_module_imports_a_layer_above_its_own():
    upward = [
        f"{i.source} (layer {layer(i.source)}) imports {i.target} (layer {layer(i.target)}) "
        f"at line {i.line}"
        for i in IMPORTS
        if layer(i.target) > layer(i.source)
    ]
    assert not upward, "\n".join(upward)


def test_estimators_never_import_the_simulators_truth_side():
    seen = [
        f"{i.source} imports {i.target} at line {i.line}"
        for i in IMPORTS
        if i.source.startswith("indoorsim.estimators")
        and any(i.target == t or i.target.startswith(t + ".") for t in TRUTH_SIDE)
    ]
    assert not seen, "\n".join(seen)


@pytest.mark.parametrize("domain", ["indoorsim.world", "indoorsim.walker", "indoorsim.phone"])
def test_the_simulation_never_imports_benchmark_envs_or_estimators(domain):
    above = ("indoorsim.benchmark", "indoorsim.envs", "indoorsim.estimators", "indoorsim.dataset")
    seen = [
        f"{i.source} imports {i.target} at line {i.line}"
        for i in IMPORTS
        if i.source.startswith(domain) and any(i.target.startswith(a) for a in above)
    ]
    assert not seen, "\n".join(seen)


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges.get(child, ())))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return found


def test_no_import_circles():
    edges: dict[str, set[str]] = {name: set() for name in MODULES}
    for i in IMPORTS:
        if not i.type_checking:
            edges[i.source].add(i.target)
    assert _cycles(edges) == []


def test_the_circle_check_finds_a_circle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
