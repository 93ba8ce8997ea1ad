"""What the commands share: argument types, checks of names and output folders, a spinner.

Every helper that checks a value raises :class:`CliError`, which
:func:`indoorsim.cli.main` prints as one line with exit status 2. The checks
that need the simulator import it when they run, so that building the parser
(and ``indoorsim --help``) stays fast.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

if TYPE_CHECKING:
    from indoorsim.phone.devices import DeviceProfile
    from indoorsim.walker.schedule import ModeSchedule
    from indoorsim.world.site import Site

    Subparsers: TypeAlias = argparse._SubParsersAction[argparse.ArgumentParser]

__all__ = [
    "CliError",
    "EstimatorNamesFormatter",
    "add_board_folders",
    "check_folder",
    "check_out",
    "device_profile",
    "estimator_options",
    "estimator_spec",
    "mode_schedule",
    "option_hints",
    "positive",
    "route_name",
    "route_or_first",
    "seed_number",
    "table_lines",
    "working",
]


class CliError(Exception):
    """A usage error: printed as ``indoorsim: <message>``, exit status 2."""


# ------------------------------------------------------------- argument types


def add_board_folders(parser: argparse.ArgumentParser, realdata_help: str) -> None:
    """``--out`` (default ``leaderboards/``) and ``--realdata``, as the board commands take them."""
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("leaderboards"),
        metavar="DIR",
        help="default leaderboards/",
    )
    parser.add_argument("--realdata", type=Path, metavar="DIR", help=realdata_help)


def positive(convert: Callable[[str], float]) -> Callable[[str], float]:
    """An argparse ``type`` that parses with ``convert`` and accepts only values > 0."""

    def parse(text: str) -> float:
        try:
            value = convert(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not value > 0:
            raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
        return value

    return parse


def seed_number(text: str) -> int:
    """An argparse ``type`` for seeds: integers >= 0, as ``numpy.random.SeedSequence`` takes."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text}")
    return value


# ------------------------------------------------------------- output folders


def check_folder(out: Path) -> None:
    """Refuse an ``--out`` that exists and is not a folder."""
    if out.exists() and not out.is_dir():
        raise CliError(f"--out {out}: exists and is not a folder")


def check_out(out: Path, *, overwrite: bool, what: str) -> None:
    """Refuse an ``--out`` folder that is in the way, before the slow work starts.

    The writer makes the final decision (it never replaces anything but an
    earlier ``what``); this only saves running a simulation whose result could
    not be saved.
    """
    check_folder(out)
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise CliError(
            f"--out {out}: already exists; pass --overwrite to replace it "
            f"(only an earlier {what} is ever replaced)"
        )


# ------------------------------------------------------------- names


def device_profile(name: str) -> DeviceProfile:
    """The device profile called ``name``, or in the YAML file ``name``; the error lists
    the valid names, or says what is wrong with the file."""
    from indoorsim.phone.devices import DeviceFileError, UnknownDeviceError, get_device

    try:
        return get_device(name)
    except (UnknownDeviceError, DeviceFileError) as err:
        raise CliError(str(err)) from None


def route_name(site: Site, name: str) -> str:
    """``--route``: ``name`` if ``site``'s scenario has such a route."""
    from indoorsim.simulate import UnknownRouteError, route_spec

    try:
        route_spec(site, name)
    except UnknownRouteError as err:
        raise CliError(f"--route {name}: {err}") from None
    return name


def route_or_first(site: Site, name: str | None) -> str:
    """``--route``: ``name`` if given (checked), else the scenario's first route, said on stderr.

    The choice goes to stderr as ``route: NAME (the first of: A, B)`` so that
    stdout keeps only the command's result.
    """
    if name is not None:
        return route_name(site, name)
    routes = list(site.scenario.routes)
    if not routes:
        raise CliError(f"scenario {site.name!r} has no routes to walk (its 'routes:' is empty)")
    which = "the only one" if len(routes) == 1 else f"the first of: {', '.join(routes)}"
    print(f"route: {routes[0]} ({which})", file=sys.stderr)
    return routes[0]


def mode_schedule(text: str, *, one_mode: bool = False) -> ModeSchedule:
    """``--mode`` as a checked schedule: a mode name or, unless ``one_mode``, a schedule.

    The schedule syntax is :meth:`~indoorsim.walker.schedule.ModeSchedule.parse`'s
    (``handheld,30:calling,60:pocketed``).
    """
    from indoorsim.walker.modes import UnknownModeError
    from indoorsim.walker.schedule import ModeSchedule, ScheduleError

    try:
        return ModeSchedule.of(text) if one_mode else ModeSchedule.parse(text)
    except (ScheduleError, UnknownModeError) as err:
        raise CliError(f"--mode {text}: {err}") from None


# ------------------------------------------------------------- estimator options

# A comma starts a new option only where ``key=`` follows, so values may hold
# commas (a JSON list, a path).
_NEXT_OPTION = re.compile(r",(?=\s*[A-Za-z_][A-Za-z0-9_]*\s*=)")
_OPTION_KEY = re.compile(r"\s*[A-Za-z_][A-Za-z0-9_]*\s*=")


def estimator_spec(text: str) -> tuple[str, dict[str, Any]]:
    """``--estimator NAME[:key=value,...]`` → ``(NAME, {key: value})``.

    NAME is a registered name or a ``package.module:Class``; the options start
    after the first ``:`` that is followed by ``key=``. Each value is read as
    JSON where it parses (numbers, ``true``/``false``, ``null``, ``"quoted
    strings"``, lists) and kept as the plain string otherwise. Only the
    syntax is checked here; :func:`estimator_options` checks the names and
    values against the estimator.

    >>> estimator_spec("chen2022-cpf:likelihood=gaussian,n_particles=500")
    ('chen2022-cpf', {'likelihood': 'gaussian', 'n_particles': 500})
    >>> estimator_spec("my_pkg.mod:Class:k=3")
    ('my_pkg.mod:Class', {'k': 3})
    >>> estimator_spec("my_pkg.mod:Class")
    ('my_pkg.mod:Class', {})
    """
    cut = next(
        (m.start() for m in re.finditer(":", text) if _OPTION_KEY.match(text, m.start() + 1)),
        None,
    )
    if cut is None:
        if "=" in text:
            raise CliError(
                f"--estimator {text}: expected NAME:key=value,... (options after a colon)"
            )
        return text, {}
    name, options = text[:cut], text[cut + 1 :]
    params: dict[str, Any] = {}
    for item in _NEXT_OPTION.split(options):
        key, _, raw = item.partition("=")
        key, raw = key.strip(), raw.strip()
        if key in params:
            raise CliError(f"--estimator {name}: option {key} given twice")
        try:
            params[key] = json.loads(raw)
        except ValueError:
            params[key] = raw
    return name, params


def estimator_options(text: str) -> tuple[str, dict[str, Any]]:
    """``--estimator NAME[:key=value,...]``, checked: the name, and options the estimator takes.

    The estimator is built once with the options. Refused, each as a
    :class:`CliError` naming the estimator and the option: a name that is
    neither registered nor a loadable ``module:Class``; an option its
    constructor does not take; a value of the wrong kind for an option typed
    ``bool``, ``int``, ``float``, ``str``, ``None``, a ``Literal`` or a class
    (nothing else can be built on the command line); whatever the constructor
    itself refuses (its ``TypeError`` or ``ValueError``); and a constructor that
    raises anything else, or raises without options (``raised TYPE in __init__()``).
    """
    import inspect

    from indoorsim.estimators.base import UnknownEstimatorError, estimator_class

    name, params = estimator_spec(text)
    try:
        cls = estimator_class(name)
    except UnknownEstimatorError as err:
        raise CliError(f"--estimator: {err}") from None
    label = f"--estimator {name}"
    try:
        signature = inspect.signature(cls)
    except (TypeError, ValueError):  # a factory whose signature cannot be read
        signature = None
    if signature is not None and not any(
        p.kind is p.VAR_KEYWORD for p in signature.parameters.values()
    ):
        options = [
            n
            for n, p in signature.parameters.items()
            if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
        ]
        for key in params:
            if key not in options:
                raise CliError(
                    f"{label}: unknown option {key!r}; its options are: "
                    f"{', '.join(options) or 'none'}"
                )
    hints = option_hints(cls)
    for key, value in params.items():
        expected = _mismatch(value, hints.get(key))
        if expected:
            raise CliError(f"{label}: option {key}={_shown(value)}: expected {expected}")
    try:
        cls(**params)
    except (TypeError, ValueError) as err:
        if params:
            raise CliError(f"{label}: {_culprits(cls, params)}{err}") from None
        raise CliError(f"{label}: {_raised(err)}") from err
    except Exception as err:  # a plug-in's own failure: kept in the chain for --debug
        raise CliError(f"{label}: {_raised(err)}") from err
    return name, params


def _raised(err: Exception) -> str:
    text = f"raised {type(err).__name__} in __init__()"
    return f"{text}: {err}" if str(err) else text


def option_hints(cls: Any) -> dict[str, Any]:
    """The constructor's parameter annotations, resolved; {} where they cannot be."""
    import typing

    try:
        return typing.get_type_hints(cls.__init__)
    except Exception:  # forward references a plug-in cannot resolve: nothing to check by type
        return {}


def _fits(value: Any, hint: Any) -> bool | None:
    """Whether a value from the command line fits ``hint``; None where that cannot be told."""
    import types
    import typing

    if hint is None or hint is Any:
        return None
    if hint is type(None):
        return value is None
    if hint is bool:
        return isinstance(value, bool)
    if hint is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if hint is float:
        return isinstance(value, int | float) and not isinstance(value, bool)
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return any(value == a and type(value) is type(a) for a in typing.get_args(hint))
    if origin in (typing.Union, types.UnionType):
        verdicts = [_fits(value, arg) for arg in typing.get_args(hint)]
        if any(v is True for v in verdicts):
            return True
        return False if all(v is False for v in verdicts) else None
    if origin in (tuple, list, dict) or hint in (tuple, list, dict):
        return None  # JSON gives lists for tuples: left to the constructor
    if isinstance(hint, type):
        return isinstance(value, hint)
    return None


def _describe(hint: Any) -> str:
    import types
    import typing

    names = {type(None): "null", bool: "true or false", int: "a whole number", float: "a number"}
    if hint in names:
        return names[hint]
    if hint is str:
        return "a string"
    origin = typing.get_origin(hint)
    if origin is typing.Literal:
        return "one of " + ", ".join(
            a if isinstance(a, str) else json.dumps(a) for a in typing.get_args(hint)
        )
    if origin in (typing.Union, types.UnionType):
        return " or ".join(_describe(a) for a in typing.get_args(hint))
    return f"a {getattr(hint, '__name__', hint)} (not settable from the command line)"


def _mismatch(value: Any, hint: Any) -> str:
    """What ``hint`` expects if ``value`` does not fit it, else ``""``."""
    if _fits(value, hint) is not False:
        return ""
    expected = _describe(hint)
    if not isinstance(value, str) and _fits("", hint):
        expected += " (a string that reads as JSON goes in double quotes)"
    return expected


def _shown(value: Any) -> str:
    return value if isinstance(value, str) else json.dumps(value)


def _culprits(cls: Any, params: dict[str, Any]) -> str:
    """``option k=v: `` for the one option the constructor refuses on its own, else the lot."""
    if not params:
        return ""
    for key, value in params.items():
        try:
            cls(**{key: value})
        except (TypeError, ValueError):
            return f"option {key}={_shown(value)}: "
    together = ", ".join(f"{k}={_shown(v)}" for k, v in params.items())
    return f"options {together} together: "


# ------------------------------------------------------------- output


class EstimatorNamesFormatter(argparse.HelpFormatter):
    """Help text with ``{estimators}`` replaced by the registered estimator names.

    The names are looked up only when a help text is formatted (``--help``),
    since finding them imports every estimator.
    """

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = super()._get_help_string(action)
        if text and "{estimators}" in text:
            from indoorsim.estimators.base import available

            text = text.replace("{estimators}", ", ".join(available()))
        return text


def table_lines(rows: list[tuple[str, ...]], right: set[int]) -> list[str]:
    """Rows (the first a header) as aligned columns, indented by two spaces, columns
    two spaces apart; the columns whose index is in ``right`` right-justified."""
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return [
        "  "
        + "  ".join(
            cell.rjust(w) if i in right else cell.ljust(w)
            for i, (cell, w) in enumerate(zip(row, widths, strict=True))
        ).rstrip()
        for row in rows
    ]


# ------------------------------------------------------------- progress


@contextmanager
def working(desc: str) -> Iterator[None]:
    """A spinner-style progress bar on stderr, showing the elapsed time, around one long call.

    The survey and simulation functions report no progress of their own, so
    the bar cannot show a fraction done. Shown only when stderr is a terminal.
    """
    from tqdm import tqdm

    done = threading.Event()
    with tqdm(desc=desc, total=None, bar_format="{desc}: {elapsed}", disable=None) as bar:

        def tick() -> None:
            # Without updates tqdm would not redraw; refresh so the time moves.
            while not done.wait(0.5):
                bar.refresh()

        ticker = threading.Thread(target=tick, daemon=True)
        ticker.start()
        try:
            yield
        finally:
            done.set()
            ticker.join()
