"""Scenario files: parse, load and dump YAML, the bundled scenarios by name, and Sites.

Every error names the file, the dotted key path and the problem, and nothing is
half-loaded: :func:`load_scenario` either returns a fully validated
:class:`~indoorsim.scenario.schema.Scenario` (schema *and* geometry checked) or
raises :class:`~indoorsim.scenario.schema.ScenarioError` listing every problem found.

:func:`load_site` is the one way from a scenario name or file to a
:class:`~indoorsim.world.site.Site`: it gives the same Site object for the same
unchanged file, so what is cached per Site (the surveys of
:func:`indoorsim.benchmark.evaluation.site_context`) is computed once per process.
"""

from __future__ import annotations

import threading
import warnings
from collections import OrderedDict
from collections.abc import Iterable
from importlib import resources
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from indoorsim.scenario.checks import geometry_problems, reference_problems
from indoorsim.scenario.schema import SURVEY_KINDS, Scenario, ScenarioError, key_path
from indoorsim.util.errors import UnknownNameError
from indoorsim.world.site import Site

__all__ = [
    "ENTRY_POINT_GROUP",
    "UnknownScenarioError",
    "bundled_scenarios",
    "dump_scenario",
    "load_scenario",
    "load_site",
    "parse_scenario",
    "resolve_scenario",
    "scenario_to_dict",
]


def _pydantic_problems(err: ValidationError) -> list[tuple[str, str]]:
    problems = []
    for e in err.errors(include_url=False):
        msg = e["msg"]
        if msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        loc = list(e["loc"])
        # Pydantic puts the survey's tag (its kind) into the path of a tagged
        # union's errors: surveys.<name>.grid.spacing is the file's surveys.<name>.spacing.
        if len(loc) >= 3 and loc[0] == "surveys" and loc[2] in SURVEY_KINDS:
            del loc[2]
        path = key_path(loc)
        if e["type"] == "extra_forbidden":
            msg = "unknown key"
        problems.append((path, msg))
    return problems


def parse_scenario(
    data: Any, source: str = "<scenario>", *, check_geometry: bool = True
) -> Scenario:
    """Validate a mapping (e.g. parsed YAML) into a :class:`Scenario`.

    Args:
        data: the parsed document.
        source: label used in error messages (usually the file path).
        check_geometry: also check the geometry (lights inside the building and
            not inside walls, doors on walls, windows on walls, routes walkable).

    Raises:
        ScenarioError: listing every problem, each with its key path.
    """
    if not isinstance(data, dict):
        raise ScenarioError(
            source, [("", f"expected a mapping at the top level, got {type(data).__name__}")]
        )
    try:
        scenario = Scenario.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(source, _pydantic_problems(err)) from None
    problems = reference_problems(scenario)
    if check_geometry and not problems:
        problems = geometry_problems(scenario)
    if problems:
        raise ScenarioError(source, problems)
    return scenario


def load_scenario(path: str | Path) -> Scenario:
    """Load and fully validate a scenario YAML file.

    Raises:
        ScenarioError: for a missing file or a folder, a file that is not UTF-8
            (with the byte's line, column and offset), a YAML syntax error (with its
            line), a key given twice in one mapping (with both lines), or any
            schema or geometry problem.
    """
    path = Path(path)
    source = str(path)
    if path.is_dir():
        raise ScenarioError(source, [("", _directory_problem(path))])
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise ScenarioError(source, [("", f"cannot read file: {err.strerror or err}")]) from None
    except UnicodeDecodeError as err:
        raise ScenarioError(source, [("", _encoding_problem(err))]) from None
    try:
        data, duplicates = _load_yaml(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        problem = getattr(err, "problem", None) or str(err)
        raise ScenarioError(source, [("", f"YAML syntax error at {where}{problem}")]) from None
    if duplicates:
        raise ScenarioError(source, duplicates)
    return parse_scenario(data, source)


def _directory_problem(path: Path) -> str:
    """What to say when a scenario path is a folder: the YAML files in it, if any."""
    names = sorted(p.name for p in path.iterdir() if p.suffix in (".yaml", ".yml"))
    if not names:
        return "is a directory, expected a scenario .yaml file (it holds no .yaml files)"
    shown = ", ".join(names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5 else "")
    return f"is a directory, expected a scenario .yaml file: one of {shown}"


def _encoding_problem(err: UnicodeDecodeError) -> str:
    """Where a file stops being UTF-8: the byte, its line and column, and its offset."""
    raw = bytes(err.object)
    line = raw.count(b"\n", 0, err.start) + 1
    column = err.start - (raw.rfind(b"\n", 0, err.start) + 1) + 1
    head = raw[:8192]
    # Text in any 8-bit encoding has few control characters; a binary file many.
    control = sum(1 for b in head if b < 0x20 and b not in b"\t\n\r")
    binary = b"\0" in head or control > 0.05 * len(head)
    kind = "a binary file" if binary else "text in Latin-1 or another 8-bit encoding"
    return (
        f"not UTF-8 text: byte 0x{raw[err.start]:02x} at line {line}, column {column} (byte "
        f"offset {err.start}): {err.reason}; scenario files are UTF-8 YAML, this looks "
        f"like {kind}"
    )


# libyaml's parser when PyYAML was built with it: the same safe constructors, at
# a fraction of the pure-Python parser's time.
_FastSafeLoader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_MERGE_TAG = "tag:yaml.org,2002:merge"


def _load_yaml(text: str) -> tuple[Any, list[tuple[str, str]]]:
    """``yaml.safe_load(text)``, parsed by libyaml when available, and its duplicate keys.

    A document libyaml rejects is parsed again by the pure-Python parser, so
    syntax errors are reported exactly as ``yaml.safe_load`` reports them. A
    document with a key given twice in one mapping (which YAML forbids, and
    PyYAML would resolve silently by keeping the last) is not constructed: the
    duplicates come back as ``(key path, message)`` instead.
    """
    try:
        return _compose_and_construct(text, _FastSafeLoader)
    except yaml.YAMLError:
        if _FastSafeLoader is yaml.SafeLoader:
            raise
        return _compose_and_construct(text, yaml.SafeLoader)


def _compose_and_construct(text: str, loader_class: Any) -> tuple[Any, list[tuple[str, str]]]:
    loader = loader_class(text)
    try:
        node = loader.get_single_node()
        if node is None:  # an empty document
            return None, []
        duplicates = _duplicate_keys(node)
        return (None if duplicates else loader.construct_document(node)), duplicates
    finally:
        loader.dispose()


def _duplicate_keys(root: yaml.Node) -> list[tuple[str, str]]:
    """Keys given twice in one mapping, as ``(key path, message)`` with both lines."""
    problems: list[tuple[int, str, str]] = []  # (line, key path, message)
    visited: set[int] = set()  # an anchored node is checked once, wherever it is used
    pending: list[tuple[yaml.Node, list[Any]]] = [(root, [])]
    while pending:
        node, loc = pending.pop()
        if id(node) in visited:
            continue
        visited.add(id(node))
        if isinstance(node, yaml.SequenceNode):
            pending.extend((item, [*loc, i]) for i, item in enumerate(node.value))
        elif isinstance(node, yaml.MappingNode):
            first: dict[tuple[str, str], yaml.Mark] = {}
            for key_node, value_node in node.value:
                if key_node.tag == _MERGE_TAG or not isinstance(key_node, yaml.ScalarNode):
                    # Merged keys (<<) may be overridden: only the mapping's own keys count.
                    pending.append((value_node, loc))
                    continue
                key, mark = (key_node.tag, key_node.value), key_node.start_mark
                if key in first:
                    before = first[key]
                    # The column too where both are on one line (a flow mapping).
                    here, there = (
                        (f"line {mark.line + 1}", f"line {before.line + 1}")
                        if mark.line != before.line
                        else (
                            f"line {mark.line + 1}, column {mark.column + 1}",
                            f"column {before.column + 1}",
                        )
                    )
                    problems.append(
                        (
                            mark.line,
                            key_path([*loc, key_node.value]),
                            f"duplicate key {key_node.value!r} at {here} (first given at "
                            f"{there}); give each key once",
                        )
                    )
                else:
                    first[key] = mark
                pending.append((value_node, [*loc, key_node.value]))
    return [(path, message) for _, path, message in sorted(problems)]


class _FlowListDumper(yaml.SafeDumper):
    """Writes short lists of numbers inline (``[1.0, 2.0]``), as people write them."""


def _represent_list(dumper: yaml.SafeDumper, data: list[Any]) -> yaml.Node:
    flow = all(isinstance(v, int | float | str | bool) for v in data) or all(
        isinstance(v, list) and all(isinstance(x, int | float) for x in v) for v in data
    )
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


_FlowListDumper.add_representer(list, _represent_list)


def scenario_to_dict(scenario: Scenario) -> dict[str, Any]:
    """The scenario as plain YAML-able data, keys as in files.

    Defaults are written out too, so a saved scenario keeps its meaning even if
    a later version changes a default.
    """
    return scenario.model_dump(mode="json", by_alias=True)


def dump_scenario(scenario: Scenario, path: str | Path | None = None) -> str:
    """Write ``scenario`` as YAML (to ``path`` when given) and return the text.

    ``load_scenario(path) == scenario`` holds for every valid scenario.
    """
    text = yaml.dump(
        scenario_to_dict(scenario), Dumper=_FlowListDumper, sort_keys=False, allow_unicode=True
    )
    if path is not None:
        Path(path).write_text(text, encoding="utf-8")
    return text


# --------------------------------------------------------------------------- registry

ENTRY_POINT_GROUP = "indoorsim.scenarios"
"""Entry-point group through which other packages add scenarios: each entry
point loads to a path (or a folder of ``*.yaml`` files)."""


def bundled_scenarios() -> dict[str, Path]:
    """Scenario names → YAML paths: the bundled ones, then any from entry points."""
    names: dict[str, Path] = {}
    folder = resources.files("indoorsim.scenarios")
    for item in sorted(folder.iterdir(), key=lambda t: t.name):
        if item.name.endswith(".yaml"):
            names[item.name[: -len(".yaml")]] = Path(str(item))
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        # A broken plugin must not take the bundled scenarios (and every
        # environment id) down with it: it is reported and left out.
        try:
            target = Path(str(ep.load()))
        except Exception as err:
            warnings.warn(
                f"scenario plug-in {ep.name!r} ({ep.value}) failed to load and is ignored: {err!r}",
                stacklevel=2,
            )
            continue
        found = (
            {p.stem: p for p in sorted(target.glob("*.yaml"))}
            if target.is_dir()
            else {ep.name: target}
        )
        for name, path in found.items():
            if name in names:  # a bundled name keeps its meaning everywhere; first plug-in wins
                warnings.warn(
                    f"scenario plug-in {ep.name!r}: {name!r} is already taken by "
                    f"{names[name]}; {path} is ignored",
                    stacklevel=2,
                )
                continue
            names[name] = path
    return names


class UnknownScenarioError(UnknownNameError, ScenarioError):
    """A scenario name that is neither bundled (or from a plug-in) nor a file.

    Also a :class:`~indoorsim.scenario.schema.ScenarioError`, as it was before
    it had its own type: ``source`` is the name, with one problem.
    """

    kind = "scenario"
    valid_label = "bundled scenarios"

    def __init__(self, name: str, valid: Iterable[str], where: str = "", kind: str = ""):
        super().__init__(name, valid, where, kind)
        self.source = name
        self.problems = [("", self.message)]


def resolve_scenario(name_or_path: str | Path) -> Path:
    """The YAML path for a bundled scenario name, or ``name_or_path`` if it is a file.

    Raises:
        UnknownScenarioError: neither a known name nor an existing file; lists the names.
        ScenarioError: a ``.yaml``/``.yml`` path that is not a file, or a folder
            (the message lists the YAML files in it).
    """
    known = bundled_scenarios()
    if str(name_or_path) in known:
        return known[str(name_or_path)]
    path = Path(name_or_path)
    if path.is_dir():
        raise ScenarioError(str(path), [("", _directory_problem(path))])
    if path.suffix in (".yaml", ".yml") or path.exists():
        if not path.is_file():
            raise ScenarioError(str(path), [("", "no such file")])
        return path
    raise UnknownScenarioError(str(name_or_path), known)


_SITE_CACHE_SIZE = 32
_sites: OrderedDict[tuple[str, int, int], Site] = OrderedDict()
"""Sites by (resolved path, mtime in ns, size) of their file, least recently used first."""
_sites_lock = threading.Lock()  # threaded Dask workers load sites concurrently


def load_site(name_or_path: str | Path | Scenario) -> Site:
    """The Site of a bundled scenario name, a scenario YAML file, or a :class:`Scenario`.

    A name or a path gives the same Site object as long as its file is
    unchanged (same resolved path, modification time and size); an edited file
    is loaded again. A :class:`Scenario` always gives a new Site.

    Raises:
        UnknownScenarioError: neither a known name nor an existing file.
        ScenarioError: a file that cannot be read or is not a valid scenario.
    """
    if isinstance(name_or_path, Scenario):
        return Site(name_or_path)
    path = resolve_scenario(name_or_path)
    stat = path.stat()
    key = (str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    with _sites_lock:
        site = _sites.get(key)
        if site is None:
            # Loaded from the path as given, so that errors name the file as the caller did.
            site = _sites[key] = Site(load_scenario(path))
            if len(_sites) > _SITE_CACHE_SIZE:
                _sites.popitem(last=False)
        else:
            _sites.move_to_end(key)
    return site
