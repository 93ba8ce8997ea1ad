"""The ``indoorsim`` command line.

::

    indoorsim scenarios                                   # the bundled scenarios, as a table
    indoorsim scenarios minimal_room                      # one: its routes, surveys, sources
    indoorsim import-plan site1/F1/geojson_map.json --traces site1/F1/path_data_files \\
        --seed 0 --out mall.yaml                          # a real floor plan as a scenario
    indoorsim simulate minimal_room --route main --mode handheld,8:calling \\
        --device honor_50 --seed 1 --out walks/main-1     # one walk, as a recording folder
    indoorsim survey han2023_basement --kind grid --device honor_50 --seed 0 --out db/
    indoorsim estimators                                  # each estimator and what it needs
    indoorsim plot site minimal_room my-site.yaml --out plots/
    indoorsim plot site --all --out plots/ --resolution 0.2
    indoorsim plot recording walks/main-1 trace.txt --out plots/
    indoorsim evaluate --estimator pdr-basic --scenario minimal_room --out results/pdr
    indoorsim evaluate --estimator chen2022-cpf:likelihood=gaussian --scenario chen2022_lab \\
        --export tum --out results/cpf                    # options; TUM files for evo
    indoorsim leaderboard --quick --out leaderboards/
    indoorsim realism --out leaderboards/                 # simulated motion beside real phones
    indoorsim calibrate trace.txt --out twin.yaml         # a phone and walker fitted to a log
    indoorsim simulate minimal_room --mode handheld --device twin.yaml --walker twin.yaml \
        --seed 0 --out walks/twin                         # ... and its simulated twin
    indoorsim dataset --sites 20 --walks-per-site 8 --minutes 10 --seed 0 \\
        --workers 2 --out data/          # labelled Parquet shards on Dask (resumable)
    indoorsim train --data data/ --out checkpoints/io --epochs 15   # the learned-io network

One module per command group: :mod:`~indoorsim.cli.scenarios`,
:mod:`~indoorsim.cli.import_plan`,
:mod:`~indoorsim.cli.simulate` (``simulate``, ``survey``),
:mod:`~indoorsim.cli.estimators`,
:mod:`~indoorsim.cli.plot` (``plot site``, ``plot recording``),
:mod:`~indoorsim.cli.evaluate` (``evaluate``, ``leaderboard``),
:mod:`~indoorsim.cli.realism` (``realism``, ``calibrate``) and
:mod:`~indoorsim.cli.dataset` (``dataset``, ``train``); what they share
(argument types, name and folder checks, the progress spinner,
:class:`~indoorsim.cli.args.CliError`) is in :mod:`~indoorsim.cli.args`. Each
command is a pair of functions: ``add_<command>(subparsers)`` declares its
arguments and sets ``handler`` to ``_run_<command>(args) -> int``. Adding a
command means adding one such pair and listing its ``add_`` function in
:data:`_COMMANDS`. A handler imports what it uses when it runs, so that the
command line starts fast.

Exit codes: 0 success, 1 an I/O failure while writing, 2 a usage error (bad
arguments, an unknown scenario, route, mode or device name, an invalid scenario
or data-set configuration file, an output folder that is in the way), 3 work
that finished but failed its goal (``evaluate``: a metric above its
``--fail-above`` threshold; ``dataset``: shards that still failed after their
retries, each named), 130 interrupted (Ctrl-C). Errors are printed to stderr
as one clear message, without a traceback; ``indoorsim --debug COMMAND`` prints
the traceback above it (a plug-in estimator's own, where it raised). Warnings
meant for the user (:class:`~indoorsim.util.errors.IndoorsimWarning`) are
printed as ``indoorsim: warning: <message>``.
"""

from __future__ import annotations

import argparse
import errno
import sys
import traceback
import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, TextIO

from indoorsim._version import __version__
from indoorsim.cli.args import CliError
from indoorsim.cli.dataset import add_dataset, add_train
from indoorsim.cli.estimators import add_estimators
from indoorsim.cli.evaluate import add_evaluate, add_leaderboard
from indoorsim.cli.import_plan import add_import_plan
from indoorsim.cli.plot import add_plot
from indoorsim.cli.realism import add_calibrate, add_realism
from indoorsim.cli.scenarios import add_scenarios
from indoorsim.cli.simulate import add_simulate, add_survey
from indoorsim.scenario.schema import ScenarioError
from indoorsim.util.errors import IndoorsimWarning

if TYPE_CHECKING:
    from indoorsim.cli.args import Subparsers

__all__ = ["build_parser", "main"]

_COMMANDS: tuple[Callable[[Subparsers], None], ...] = (
    add_scenarios,
    add_import_plan,
    add_simulate,
    add_survey,
    add_estimators,
    add_evaluate,
    add_leaderboard,
    add_realism,
    add_calibrate,
    add_dataset,
    add_train,
    add_plot,
)
"""The subcommands, in the order ``indoorsim --help`` lists them."""


def build_parser() -> argparse.ArgumentParser:
    """The ``indoorsim`` argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="indoorsim",
        description="Simulate smartphone indoor positioning in synthetic buildings.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument(
        "--debug",
        action="store_true",
        help="on an error, print its traceback (a plug-in's own among it) above the message",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in _COMMANDS:
        add(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:
        # argparse exits on --help, --version and usage errors; callers of
        # main() get the status back instead.
        return exit_.code if isinstance(exit_.code, int) else 2
    if sys.stderr.isatty():
        # A first run compiles for tens of seconds: say so at a terminal (logs stay as they were).
        from indoorsim.util.jit_cache import announce_compiles

        announce_compiles()
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warnings(warnings.showwarning)
            return args.handler(args)
    except (CliError, ScenarioError, FileExistsError) as err:
        # FileExistsError: an output folder in the way, which only the user can clear.
        _report(err, debug=args.debug)
        return 2
    except OSError as err:
        # A bare OSError's '[Errno 28] ...' said in words; errors with their own message
        # (a data set's disk full, naming the shard and how to resume) stay as they are.
        if err.errno in (errno.ENOSPC, errno.EDQUOT) and type(err).__str__ is OSError.__str__:
            where = f" to write {err.filename}" if err.filename else ""
            message = (
                f"disk full: no space left on the device{where} ({err.strerror}); free some "
                "space and run the same command again"
            )
            _report(err, debug=args.debug, message=message)
            return 1
        _report(err, debug=args.debug)
        return 1
    except KeyboardInterrupt as err:
        # A command that can say what was kept raises a KeyboardInterrupt that says so.
        _report(err if str(err) else KeyboardInterrupt("interrupted"), debug=args.debug)
        return 130


def _report(err: BaseException, *, debug: bool, message: str | None = None) -> None:
    """``indoorsim: <message>`` (default ``str(err)``) on stderr; with ``--debug``, the
    traceback above it."""
    if debug:
        traceback.print_exception(err, file=sys.stderr)
    print(f"indoorsim: {err if message is None else message}", file=sys.stderr)


def _one_line_warnings(show: Callable[..., None]) -> Callable[..., None]:
    """``show`` (a ``warnings.showwarning``), but a warning for the user as one line."""

    def showwarning(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        if issubclass(category, IndoorsimWarning):
            print(f"indoorsim: warning: {message}", file=sys.stderr)
        else:
            show(message, category, filename, lineno, file, line)

    return showwarning
