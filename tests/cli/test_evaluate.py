"""``indoorsim evaluate`` and ``indoorsim leaderboard``: results written, thresholds, plug-ins."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

import indoorsim
from indoorsim.cli import main
from indoorsim.estimators.base import make
from indoorsim.io.recording import Recording


def test_evaluate_cli_writes_walks_and_fails_above_thresholds(tmp_path, capsys):
    args = ["evaluate", "--estimator", "start-only", "--scenario", "minimal_room", "--seeds", "1"]
    args += ["--device", "ideal"]
    assert main([*args, "--out", str(tmp_path / "ok"), "--fail-above", "ae=100"]) == 0
    folder = tmp_path / "ok" / "minimal_room_handheld_start-only_seed0"
    assert list(pd.read_csv(folder / "estimates.csv").columns) == [
        "t",
        "x",
        "y",
        "t_ref",
        "true_x",
        "true_y",
        "true_x_ref",
        "true_y_ref",
    ]
    assert "ae" in pd.read_csv(folder / "metrics.csv").columns
    assert main([*args, "--out", str(tmp_path / "bad"), "--fail-above", "ae=0.01,cep95=100"]) == 3
    assert "ae = " in capsys.readouterr().err
    assert main([*args, "--out", str(tmp_path / "x"), "--fail-above", "speed=1"]) == 2
    assert main([*args[:2], "nope", *args[3:], "--out", str(tmp_path / "y")]) == 2
    assert "unknown estimator 'nope'; valid estimators are:" in capsys.readouterr().err


def _install_plugin(root: Path) -> None:
    (root / "tiny_estimator_plugin.py").write_text(
        "import numpy as np\n"
        "class Centre:\n"
        "    name = 'tiny-centre'\n"
        "    def fit(self, site, train):\n"
        "        xmin, ymin, xmax, ymax = site.plan.bounds\n"
        "        self.centre = np.array([(xmin + xmax) / 2, (ymin + ymax) / 2])\n"
        "    def reset(self, start):\n"
        "        pass\n"
        "    def act(self, obs):\n"
        "        return self.centre.copy()\n"
    )
    dist = root / "tiny_estimator_plugin-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: tiny-estimator-plugin\nVersion: 1.0\n"
    )
    (dist / "entry_points.txt").write_text(
        "[indoorsim.estimators]\ntiny-centre = tiny_estimator_plugin:Centre\n"
    )


def test_an_outside_plugin_runs_through_the_cli(tmp_path):
    plugin = tmp_path / "site-packages"
    plugin.mkdir()
    _install_plugin(plugin)
    cmd = [sys.executable, "-m", "indoorsim", "evaluate", "--estimator", "tiny-centre"]
    cmd += ["--scenario", "minimal_room", "--seeds", "1", "--device", "ideal"]
    cmd += ["--out", str(tmp_path / "out")]
    env = {"PYTHONPATH": str(plugin), "PATH": "/usr/bin:/bin"}
    done = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    summary = pd.read_csv(tmp_path / "out" / "summary.csv")
    assert summary["estimator"].iloc[0] == "tiny-centre" and summary["ae"].iloc[0] > 0
    # The same class by module:Class string, in process.
    sys.path.insert(0, str(plugin))
    try:
        assert make("tiny_estimator_plugin:Centre").name == "tiny-centre"
    finally:
        sys.path.remove(str(plugin))


def test_evaluate_cli_refuses_an_estimator_the_site_cannot_serve(tmp_path, capsys):
    args = ["evaluate", "--estimator", "wknn-mag", "--scenario", "minimal_room", "--seeds", "1"]
    assert main([*args, "--device", "ideal", "--out", str(tmp_path / "o")]) == 2
    assert "not applicable here" in capsys.readouterr().err


def test_evaluate_cli_refuses_zero_seeds(tmp_path, capsys):
    args = ["evaluate", "--estimator", "start-only", "--scenario", "minimal_room", "--seeds", "0"]
    assert main([*args, "--out", str(tmp_path / "o")]) == 2
    assert "--seeds: must be > 0" in capsys.readouterr().err and not (tmp_path / "o").exists()


def test_evaluate_cli_names_a_recording_that_cannot_be_scored(tmp_path, capsys):
    site = indoorsim.load_site("minimal_room")
    rec = indoorsim.simulate.simulate(site, route="main", device="ideal", seed=0, duration_s=5.0)
    streams = {k: v for k, v in rec.streams.items() if k not in ("truth", "steps")}
    bare = Recording(streams=streams, meta=rec.meta).save(tmp_path / "bare")
    args = ["evaluate", "--estimator", "start-only", "--recording", str(bare)]
    assert main([*args, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert f"--recording {bare}: cannot be scored" in err, err
    assert not (tmp_path / "o").exists()  # nothing written for a run that did not happen


def test_leaderboard_cli_takes_a_module_class_estimator(tmp_path, monkeypatch, capsys):
    plugin = tmp_path / "site-packages"
    plugin.mkdir()
    _install_plugin(plugin)
    monkeypatch.syspath_prepend(str(plugin))
    args = ["leaderboard", "--quick", "--scenario", "minimal_room", "--out", str(tmp_path / "lb")]
    assert main([*args, "--estimator", "tiny_estimator_plugin:Centre"]) == 0
    assert "tiny_estimator_plugin:Centre" in capsys.readouterr().out
    assert main([*args, "--estimator", "no_such_module:Thing"]) == 2
    assert "cannot load estimator 'no_such_module:Thing'" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (
            ["evaluate", "--scenario", "minimal_room", "--route", "nowhere"],
            "--route nowhere: unknown route 'nowhere' in scenario 'minimal_room'; "
            "valid routes are: main",
        ),
        (
            ["evaluate", "--scenario", "minimal_room", "--mode", "juggling"],
            "--mode juggling: unknown carrying mode 'juggling'; valid carrying modes are: ",
        ),
        (
            ["evaluate", "--scenario", "minimal_room", "--device", "nokia_3310"],
            "unknown device 'nokia_3310'; valid devices are: ",
        ),
        (
            ["evaluate", "--scenario", "no_such_building"],
            "unknown scenario 'no_such_building'; bundled scenarios are: ",
        ),
        (
            ["leaderboard", "--scenario", "no_such_building"],
            "--scenario no_such_building: unknown scenario 'no_such_building'; "
            "bundled scenarios are: ",
        ),
    ],
)
def test_unknown_names_are_refused_before_any_work(tmp_path, capsys, argv, expected):
    out = tmp_path / "o"
    if argv[0] == "evaluate":
        argv = [*argv, "--estimator", "start-only"]
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"indoorsim: {expected}"), err
    assert not out.exists()
