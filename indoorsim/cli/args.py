"""What the commands share: argument types, checks of names and output folders, a spinner.

Every helper that checks a value raises :class:`CliError`, which
:func:`indoorsim.cli.main` prints as one line with exit status 2. The checks
that need the simulator import it when they run, so that building the parser
(and ``indoorsim --help``) stays fast.
"""

from __future__ import annotations

import argparse
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, TypeAlias

if TYPE_CHECKING:
    from indoorsim.phone.devices import DeviceProfile
    from indoorsim.walker.schedule import ModeSchedule
    from indoorsim.world.site import Site

    Subparsers: TypeAlias = argparse._SubParsersAction[argparse.ArgumentParser]

__all__ = [
    "CliError",
    "add_board_folders",
    "check_folder",
    "check_out",
    "device_profile",
    "mode_schedule",
    "positive",
    "route_name",
    "route_or_first",
    "seed_number",
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
    """The device profile called ``name``; the error lists the valid names."""
    from indoorsim.phone.devices import UnknownDeviceError, get_device

    try:
        return get_device(name)
    except UnknownDeviceError as err:
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
