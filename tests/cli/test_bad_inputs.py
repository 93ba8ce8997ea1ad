"""Bad input, as a new user hands it to the command line: one clear line, exit status 2.

The rows of issue 19's table of bad inputs that did not get a clear error, each
fed to the command that meets it. Every refusal is one line ``indoorsim: ...``
on stderr naming what and where, with no traceback.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from indoorsim.cli import main
from tests.conftest import BUNDLED_MINIMAL


def _one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    """The single ``indoorsim: ...`` line on stderr, without its prefix."""
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("indoorsim: "), err
    return lines[0].removeprefix("indoorsim: ")


def _simulate(scenario: Path, out: Path) -> int:
    args = ["simulate", str(scenario), "--mode", "handheld", "--device", "ideal", "--seed", "1"]
    return main([*args, "--out", str(out)])


# ------------------------------------------------------------------ scenario files

_TEXT = BUNDLED_MINIMAL.read_text(encoding="utf-8")


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (
            _TEXT.replace("# The smallest", "# The café's smallest").encode("latin-1"),
            "not UTF-8 text: byte 0xe9 at line 1, column 10 (byte offset 9): invalid "
            "continuation byte; scenario files are UTF-8 YAML, this looks like text in "
            "Latin-1 or another 8-bit encoding",
        ),
        (
            bytes(range(256)),
            "not UTF-8 text: byte 0x80 at line 2, column 118 (byte offset 128): invalid "
            "start byte; scenario files are UTF-8 YAML, this looks like a binary file",
        ),
        (
            _TEXT.replace("to: [10.0, 0.0]", "to: [1e9, 0.0]").encode(),
            "walls[0].to[0]: 1e+09 m is beyond the coordinate limit: positions are metres in "
            "the building frame, within ±10000 m of its origin",
        ),
        (
            (_TEXT + "name: another_room\n").encode(),
            f"name: duplicate key 'name' at line {len(_TEXT.splitlines()) + 1} (first given at "
            "line 4); give each key once",
        ),
        (
            _TEXT.replace("moment: [0.0, 0.0, 25.0]", "moment: [0.0, 0.0, 1e300]").encode(),
            "magnetic.dipoles[0].moment: |moment| = 1e+300 A·m² is beyond the limit of 10000 "
            "A·m² (the moment of ≈ 65 t of steel in the Earth's field, more than any object in "
            "a building; it would clip a phone's ±4912 µT magnetometer within 0.74 m)",
        ),
    ],
    ids=["latin-1", "binary", "wall-end-at-1e9-m", "duplicate-key", "dipole-1e300"],
)
def test_a_broken_scenario_file_is_named_with_its_key_and_problem(
    tmp_path, capsys, content, message
):
    scenario = tmp_path / "site.yaml"
    scenario.write_bytes(content)
    assert _simulate(scenario, tmp_path / "walk") == 2
    assert _one_line_error(capsys) == f"{scenario}: {message}"
    assert not (tmp_path / "walk").exists()


def test_a_folder_given_as_the_scenario_lists_its_yaml_files(tmp_path, capsys):
    (tmp_path / "sites").mkdir()
    (tmp_path / "sites" / "office.yaml").write_text(_TEXT)
    assert _simulate(tmp_path / "sites", tmp_path / "walk") == 2
    assert _one_line_error(capsys) == (
        f"{tmp_path / 'sites'}: is a directory, expected a scenario .yaml file: one of office.yaml"
    )


# ------------------------------------------------------------------ evaluate

_EVALUATE = ["evaluate", "--estimator", "start-only", "--scenario", "minimal_room"]
_EVALUATE += ["--seeds", "1", "--device", "ideal"]


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_a_threshold_that_is_not_finite_is_refused_at_parsing(tmp_path, capsys, value):
    out = tmp_path / "results"
    assert main([*_EVALUATE, "--out", str(out), "--fail-above", f"rmse=1,ae={value}"]) == 2
    err = capsys.readouterr().err
    assert err.endswith(
        f"indoorsim evaluate: error: argument --fail-above: 'ae={value}': "
        "threshold must be a finite number\n"
    )
    assert not out.exists()


def test_evaluate_into_earlier_results_is_refused_unless_overwrite(tmp_path, capsys):
    out = tmp_path / "results"
    seed1 = out / "minimal_room_handheld_start-only_seed1"
    assert main([*_EVALUATE, "--seeds", "2", "--out", str(out)]) == 0
    assert seed1.is_dir()
    capsys.readouterr()
    assert main([*_EVALUATE, "--out", str(out)]) == 2
    assert _one_line_error(capsys) == (
        f"--out {out}: already exists; pass --overwrite to replace it (only an earlier "
        "evaluation is ever replaced)"
    )
    assert seed1.is_dir()  # untouched
    # --overwrite replaces the folder whole: no per-seed folder of the earlier run is left.
    assert main([*_EVALUATE, "--out", str(out), "--overwrite"]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "minimal_room_handheld_start-only_seed0",
        "summary.csv",
    ]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left


def test_evaluate_does_not_replace_a_folder_of_something_else(tmp_path, capsys):
    out = tmp_path / "notes"
    out.mkdir()
    (out / "todo.txt").write_text("keep me")
    assert main([*_EVALUATE, "--out", str(out), "--overwrite"]) == 2
    assert _one_line_error(capsys) == (
        f"--out {out}: not an earlier evaluation (no summary.csv); refusing to replace it"
    )
    assert (out / "todo.txt").read_text() == "keep me"


# ------------------------------------------------------------------ plug-in estimators

_PLUGIN = """
import numpy as np


class Base:
    name = "flaky"

    def fit(self, site, train):
        pass

    def reset(self, start):
        self.k = 0

    def act(self, obs):
        self.k += 1
        return np.zeros(2)


class InInit(Base):
    def __init__(self):
        raise RuntimeError("no licence file")


class InFit(Base):
    def fit(self, site, train):
        raise KeyError("wifi")


class InReset(Base):
    def reset(self, start):
        raise AttributeError("no start heading")


class InAct(Base):
    def act(self, obs):
        if super().act(obs) is not None and self.k == 4:
            return 1 / 0
        return np.zeros(2)


class NaN(Base):
    def act(self, obs):
        return np.array([np.nan, 1.0])


class Shape(Base):
    def act(self, obs):
        return np.zeros(3)
"""


@pytest.fixture
def plugin(tmp_path, monkeypatch) -> str:
    """The module of misbehaving plug-in estimators, importable as ``flaky_plugin``."""
    (tmp_path / "flaky_plugin.py").write_text(_PLUGIN)
    monkeypatch.syspath_prepend(str(tmp_path))
    return "flaky_plugin"


_NOT_A_POSITION = "expected a finite (x, y) array of shape (2,)"


@pytest.mark.parametrize(
    ("cls", "message"),
    [
        (
            "InInit",
            "--estimator flaky_plugin:InInit: raised RuntimeError in __init__(): no licence file",
        ),
        ("InFit", "estimator 'flaky' raised KeyError in fit(): 'wifi'"),
        (
            "InReset",
            "estimator 'flaky' raised AttributeError in reset() for seed 0: no start heading",
        ),
        (
            "InAct",
            "estimator 'flaky' raised ZeroDivisionError in act() at window 3 (t = 3.99 s) of "
            "seed 0: division by zero",
        ),
        (
            "NaN",
            "estimator 'flaky' returned array([nan,  1.]) from act() at window 0 (t = 0.99 s) "
            f"of seed 0; {_NOT_A_POSITION}",
        ),
        (
            "Shape",
            "estimator 'flaky' returned array([0., 0., 0.]) from act() at window 0 (t = 0.99 s) "
            f"of seed 0; {_NOT_A_POSITION}",
        ),
    ],
)
def test_a_failing_plugin_estimator_is_one_line_naming_the_call(
    tmp_path, capsys, plugin, cls, message
):
    argv = ["evaluate", "--estimator", f"{plugin}:{cls}", "--scenario", "minimal_room"]
    argv += ["--route", "main", "--seeds", "1", "--device", "ideal", "--out", str(tmp_path / "r")]
    assert main(argv) == 2
    assert _one_line_error(capsys) == message
    assert not (tmp_path / "r").exists()


def test_debug_shows_the_plugin_s_own_traceback(tmp_path, capsys, plugin):
    argv = ["--debug", "evaluate", "--estimator", f"{plugin}:InAct", "--scenario", "minimal_room"]
    argv += ["--route", "main", "--seeds", "1", "--device", "ideal", "--out", str(tmp_path / "r")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("Traceback (most recent call last):")
    assert 'flaky_plugin.py", line ' in err and "return 1 / 0" in err
    assert err.splitlines()[-1].startswith("indoorsim: estimator 'flaky' raised ZeroDivisionError")


# ------------------------------------------------------------------ real logs


def test_garbage_rows_in_a_real_trace_are_counted_on_one_warning_line(tmp_path, capsys):
    lines = ["#\tstartTime:1000000", "1000000\tTYPE_WAYPOINT\t1.5\t2.5"]
    lines += [f"{1000000 + 20 * k}\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3" for k in range(200)]
    lines += ["1002000\tTYPE_WAYPOINT\t2.5\t2.5", "1004000\tTYPE_WAYPOINT\t3.5\t2.5"]
    lines[50:50] = ["garbage", "1001000\tTYPE_ACCELEROMETER\t0.1\tx\t9.8\t3", "1001000\t\t\t"]
    trace = tmp_path / "trace.txt"
    trace.write_text("\n".join(lines) + "\n")
    argv = ["evaluate", "--estimator", "start-only", "--recording", str(trace)]
    assert main([*argv, "--out", str(tmp_path / "r")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"indoorsim: warning: {trace}: skipped 3 malformed rows (1 with a field that is not a "
        "number, 2 without a row type)"
    ]


def test_a_full_disk_is_one_line_saying_so(tmp_path, monkeypatch, capsys):
    import errno

    import pandas as pd

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "e" / "summary.csv"))

    monkeypatch.setattr(pd.DataFrame, "to_csv", full)
    args = ["evaluate", "--estimator", "start-only", "--scenario", "minimal_room", "--seeds", "1"]
    assert main([*args, "--device", "ideal", "--out", str(tmp_path / "e")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == (
        f"indoorsim: disk full: no space left on the device to write {tmp_path}/e/summary.csv "
        "(No space left on device); free some space and run the same command again"
    )
    assert "Traceback" not in "\n".join(err)
    assert not (tmp_path / "e").exists()  # nothing half-written
