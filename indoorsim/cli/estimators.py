"""``indoorsim estimators``: every estimator with one line and what it needs, or one in detail.

What an estimator needs comes from its class's optional ``needs`` and ``uses``
attributes (:mod:`indoorsim.estimators.base`), never from its name; a plug-in
that declares neither is listed as "not declared".
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers

__all__ = ["add_estimators"]


def add_estimators(subparsers: Subparsers) -> None:
    """Declare ``indoorsim estimators``."""
    parser = subparsers.add_parser(
        "estimators",
        help="list the estimators and what each needs, or show one's options",
        description="List every registered estimator (built in and from plug-ins) with the "
        "first line of its description, what it needs to run (survey databases, WiFi, "
        "labelled training walks, a checkpoint) and what it also uses when the site has it. "
        "With a NAME, show its description and the options that --estimator "
        "NAME:key=value,... sets.",
    )
    parser.add_argument(
        "name",
        nargs="?",
        metavar="NAME",
        help="a registered estimator or package.module:Class to show in detail",
    )
    parser.set_defaults(handler=_run_estimators)


def _declared(cls: Any, attr: str) -> str:
    value = getattr(cls, attr, None)
    if value is None:
        return "not declared"
    return ", ".join(value) or "nothing"


def _summary(cls: Any) -> str:
    import inspect

    doc = inspect.getdoc(cls) or ""
    return doc.strip().splitlines()[0] if doc.strip() else ""


def _run_estimators(args: argparse.Namespace) -> int:
    if args.name is not None:
        return _show_estimator(args.name)
    from indoorsim.cli.args import table_lines
    from indoorsim.estimators.base import NEEDS, available, estimator_class

    rows = [("name", "needs", "also uses", "what it is")]
    for name in available():
        try:
            cls = estimator_class(name)
        except Exception as err:  # a plug-in whose import fails is listed, not fatal
            rows.append((name, "?", "?", f"cannot be loaded: {err}"))
            continue
        rows.append((name, _declared(cls, "needs"), _declared(cls, "uses"), _summary(cls)))
    print("\n".join(line[2:] for line in table_lines(rows, right=set())))
    print(
        "\nneeds: without it the estimator is not applicable (fit raises NotApplicableError);"
        "\nalso uses: taken when the site has it, defaults otherwise. The terms:"
    )
    width = max(map(len, NEEDS))
    for term, meaning in NEEDS.items():
        print(f"  {term.ljust(width)}  {meaning}")
    print(
        "\nOptions: indoorsim evaluate --estimator NAME:key=value,... "
        "(indoorsim estimators NAME lists them)."
    )
    return 0


def _type_name(hint: Any) -> str:
    """``int``, ``str | None``, ``cpf | pf`` (a Literal's values): an option's type, short."""
    import types
    import typing

    if hint is type(None):
        return "None"
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return " | ".join(str(a) for a in typing.get_args(hint))
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_name(a) for a in typing.get_args(hint))
    return getattr(hint, "__name__", str(hint))


def _show_estimator(spec: str) -> int:
    """Print one estimator: its description, needs, and constructor options with defaults."""
    import dataclasses
    import inspect
    import json

    from indoorsim.cli.args import CliError, option_hints, table_lines
    from indoorsim.estimators.base import UnknownEstimatorError, estimator_class

    try:
        cls = estimator_class(spec)
    except UnknownEstimatorError as err:
        raise CliError(str(err)) from None
    where = f"{getattr(cls, '__module__', '?')}.{getattr(cls, '__qualname__', cls)}"
    lines = [f"{spec}  ({where})", ""]
    lines += (inspect.getdoc(cls) or "(no description)").splitlines()
    lines += ["", f"needs      {_declared(cls, 'needs')}", f"also uses  {_declared(cls, 'uses')}"]
    hints = option_hints(cls)
    rows = [("option", "default", "type")]
    try:
        parameters = inspect.signature(cls).parameters.values()
    except (TypeError, ValueError):
        parameters = []
    for p in parameters:
        if p.kind not in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY):
            continue
        hint = hints.get(p.name)
        if p.default is p.empty:
            default = "(required)"
        elif p.default is dataclasses.MISSING or repr(p.default) == "<factory>":
            default = "(built)"
        else:
            try:
                # As typed after key=: strings bare, the rest as JSON.
                default = p.default if isinstance(p.default, str) else json.dumps(p.default)
            except TypeError:
                default = repr(p.default)
        kind = _type_name(hint) if hint is not None else ""
        if isinstance(hint, type) and hint not in (bool, int, float, str, list, dict, tuple):
            kind += " (an object: not settable here)"
        rows.append((p.name, default, kind))
    lines += ["", f"options  (--estimator {spec}:key=value,...; values read as JSON)"]
    lines += table_lines(rows, right=set()) if len(rows) > 1 else ["  none"]
    print("\n".join(lines))
    return 0
