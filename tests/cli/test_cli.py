"""The command line's door: ``python -m indoorsim``, usage errors, help, and a fast start."""

from __future__ import annotations

import subprocess
import sys

import pytest

from indoorsim.cli import main


def test_python_dash_m_runs_the_command_line():
    result = subprocess.run(
        [sys.executable, "-m", "indoorsim", "scenarios"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "minimal_room" in result.stdout


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        ([], "required: COMMAND"),
        (["plot"], "required: TARGET"),
        (["plot", "site", "--out", "x"], "name at least one scenario"),
        (["plot", "site", "x", "--out", "x", "--height", "-1"], "must be > 0"),
        (["plot", "site", "x", "--out", "x", "--resolution", "fine"], "expected a number"),
        (["plot", "site", "x", "--out", "x", "--dpi", "0"], "must be > 0"),
    ],
)
def test_usage_errors_exit_2_with_a_message(argv, message, capsys):
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_help_exits_0(capsys):
    assert main(["plot", "site", "--help"]) == 0
    assert "--resolution" in capsys.readouterr().out


def test_every_command_is_listed_in_order(capsys):
    assert main(["--help"]) == 0
    listed = capsys.readouterr().out
    commands = ["scenarios", "simulate", "survey", "evaluate", "leaderboard", "dataset", "train"]
    positions = [listed.index(f"\n    {name}") for name in [*commands, "plot"]]
    assert positions == sorted(positions)


def test_building_the_parser_imports_no_command_s_dependencies():
    """The command line starts fast: each command imports what it uses when it runs."""
    code = (
        "import sys\n"
        "from indoorsim.cli import build_parser\n"
        "build_parser()\n"
        "heavy = ('numba', 'scipy', 'pandas', 'matplotlib', 'torch', 'dask', 'indoorsim.world')\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    assert done.stdout.split() == ["[]"]
