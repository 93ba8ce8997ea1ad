"""``indoorsim evaluate`` and ``indoorsim leaderboard``: results written, thresholds, plug-ins."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from evo.core import metrics as evo_metrics
from evo.core import sync
from evo.tools import file_interface

import indoorsim
from indoorsim.cli import main
from indoorsim.estimators.base import make
from indoorsim.io.recording import Recording
from indoorsim.io.tum import TumTrajectory, read_tum


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
    assert (tmp_path / "lb" / "site" / "minimal_room.html").is_file()  # the site comes along
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


# ------------------------------------------------------------------ --export tum


def _ape(est: TumTrajectory, truth: TumTrajectory) -> np.ndarray:
    assert np.array_equal(est.t, truth.t)
    return np.linalg.norm(est.position - truth.position, axis=1)


def test_export_tum_writes_what_evo_reads_and_scores_as_we_do(tmp_path, capsys):
    args = ["evaluate", "--scenario", "minimal_room", "--seeds", "1", "--device", "ideal"]
    assert main([*args, "--estimator", "pdr-basic", "--export", "tum", "--out", str(tmp_path)]) == 0
    assert capsys.readouterr().err.splitlines()[0] == "route: main (the only one)"
    folder = tmp_path / "minimal_room_handheld_pdr-basic_seed0"
    assert {p.name for p in folder.iterdir()} == {
        "estimates.csv",
        "metrics.csv",
        "estimate.tum",
        "truth.tum",
    }
    frame = pd.read_csv(folder / "estimates.csv")
    metrics = pd.read_csv(folder / "metrics.csv").iloc[0]
    est, truth = read_tum(folder / "estimate.tum"), read_tum(folder / "truth.tum")
    # The estimates at each window's end, the truth at the same times, z = 0.
    np.testing.assert_array_equal(est.t, frame["t"])
    np.testing.assert_array_equal(est.position, frame[["x", "y"]].assign(z=0.0))
    np.testing.assert_array_equal(truth.position, frame[["true_x", "true_y"]].assign(z=0.0))
    errors = _ape(est, truth)
    assert errors.mean() == pytest.approx(metrics["ae"], abs=1e-9)
    assert np.sqrt((errors**2).mean()) == pytest.approx(metrics["rmse"], abs=1e-9)
    # pdr-basic exposes a heading: a turn about +z; the truth turns with the walk (E, S, W).
    assert not (est.orientation == [0, 0, 0, 1]).all(axis=1).all()
    yaw = np.degrees(2 * np.arctan2(truth.orientation[:, 2], truth.orientation[:, 3]))
    walked = np.round(np.angle(np.exp(1j * np.radians(yaw)), deg=True) / 90) % 4
    assert {0, 2, 3} <= set(walked)
    # evo's reader, association and APE (translation part): the same numbers.
    ref = file_interface.read_tum_trajectory_file(str(folder / "truth.tum"))
    traj = file_interface.read_tum_trajectory_file(str(folder / "estimate.tum"))
    ref, traj = sync.associate_trajectories(ref, traj)
    assert ref.num_poses == len(frame)
    ape = evo_metrics.APE(evo_metrics.PoseRelation.translation_part)
    ape.process_data((ref, traj))
    stats = ape.get_all_statistics()
    assert stats["mean"] == pytest.approx(metrics["ae"], abs=1e-9)
    assert stats["rmse"] == pytest.approx(metrics["rmse"], abs=1e-9)
    assert stats["max"] == pytest.approx(metrics["me"], abs=1e-9)
    # And evo's command line, as a user runs it (it keeps its settings under $HOME).
    evo_ape = Path(sys.executable).parent / "evo_ape"
    (tmp_path / "home").mkdir()
    env = {"HOME": str(tmp_path / "home"), "PATH": "/usr/bin:/bin", "MPLBACKEND": "Agg"}
    done = subprocess.run(
        [str(evo_ape), "tum", "truth.tum", "estimate.tum"],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    printed = dict(re.findall(r"^\s*(mean|rmse)\s+(\S+)$", done.stdout, flags=re.M))
    assert float(printed["mean"]) == pytest.approx(metrics["ae"], abs=1e-6)  # 6 decimals
    assert float(printed["rmse"]) == pytest.approx(metrics["rmse"], abs=1e-6)


def test_export_tum_without_heading_or_true_heading_writes_identity(tmp_path, walk_folder):
    args = ["evaluate", "--scenario", "minimal_room", "--seeds", "1", "--device", "ideal"]
    args += ["--estimator", "start-only", "--export", "tum"]
    assert main([*args, "--out", str(tmp_path)]) == 0
    folder = tmp_path / "minimal_room_handheld_start-only_seed0"
    assert (read_tum(folder / "estimate.tum").orientation == [0, 0, 0, 1]).all()
    # A recording: the rows of its estimates.csv; its truth has positions only.
    out = tmp_path / "rec"
    args = ["evaluate", "--recording", str(walk_folder), "--estimator", "pdr-basic"]
    assert main([*args, "--export", "tum", "--out", str(out)]) == 0
    frame = pd.read_csv(out / "estimates.csv")
    est, truth = read_tum(out / "estimate.tum"), read_tum(out / "truth.tum")
    np.testing.assert_array_equal(est.position, frame[["x", "y"]].assign(z=0.0))
    np.testing.assert_array_equal(truth.position, frame[["true_x", "true_y"]].assign(z=0.0))
    assert (truth.orientation == [0, 0, 0, 1]).all()
    errors = _ape(est, truth)
    assert errors.mean() == pytest.approx(pd.read_csv(out / "summary.csv")["ae"].iloc[0], abs=1e-9)
