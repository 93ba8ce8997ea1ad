"""Ensembles of ``learned-io`` networks: ``indoorsim train --members N`` and their loading."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import torch

from indoorsim.benchmark.evaluation import check_estimator
from indoorsim.cli import main
from indoorsim.dataset.train import TrainConfig, TrainingFolderError, train, train_ensemble
from indoorsim.estimators.base import make
from indoorsim.estimators.nn.inertial import (
    ENSEMBLE_JSON,
    MODEL_JSON,
    WEIGHTS_FILE,
    CheckpointError,
    InertialEnsemble,
    load_checkpoint,
)

EPOCHS, BATCH = 2, 32

# One site: its val and test splits are empty, and train says so.
pytestmark = pytest.mark.filterwarnings("ignore:--data .* split holds no windows:UserWarning")


@pytest.fixture(scope="module")
def room_data(one_room_data: Path) -> Path:
    return one_room_data


@pytest.fixture(scope="module")
def ensemble(room_data: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two members, seeds 4 and 5, trained by the command line."""
    out = tmp_path_factory.mktemp("ensemble") / "io"
    argv = ["train", "--data", str(room_data), "--out", str(out), "--epochs", str(EPOCHS)]
    argv += ["--batch-size", str(BATCH), "--seed", "4", "--members", "2", "--quiet"]
    assert main(argv) == 0
    return out


def _window(samples: int) -> torch.Tensor:
    imu = torch.randn(8, 6, samples, generator=torch.Generator().manual_seed(2))
    imu[:, 2] += 9.81
    return imu


def test_members_differ_only_in_their_seed(room_data, ensemble, tmp_path):
    assert sorted(p.name for p in ensemble.iterdir()) == [ENSEMBLE_JSON, "member-0", "member-1"]
    meta = json.loads((ensemble / ENSEMBLE_JSON).read_text())
    assert meta["members"] == ["member-0", "member-1"] and meta["seeds"] == [4, 5]
    assert "--members 2" in meta["command"]
    trainings = [
        json.loads((ensemble / m / MODEL_JSON).read_text())["training"] for m in meta["members"]
    ]
    assert [t.pop("seed") for t in trainings] == [4, 5]
    assert trainings[0] == trainings[1]
    # The second member is exactly what a lone run with its seed trains.
    alone = tmp_path / "alone"
    train(room_data, alone, TrainConfig(epochs=EPOCHS, batch_size=BATCH, seed=5), progress=False)
    assert (alone / WEIGHTS_FILE).read_bytes() == (
        ensemble / "member-1" / WEIGHTS_FILE
    ).read_bytes()


def test_the_ensemble_predicts_the_mean_of_its_members(ensemble):
    loaded = load_checkpoint(ensemble)
    assert isinstance(loaded.model, InertialEnsemble)
    assert (loaded.frame, loaded.imu_rate_hz, loaded.window_samples) == ("world", 50.0, 50)
    members = [load_checkpoint(ensemble / f"member-{k}").model for k in range(2)]
    imu = _window(50)
    with torch.inference_mode():
        each = [m(imu) for m in members]
        assert not torch.equal(each[0], each[1])
        torch.testing.assert_close(loaded.model(imu), (each[0] + each[1]) / 2, rtol=0, atol=1e-6)


def test_learned_io_runs_on_an_ensemble(ensemble):
    estimator = make("learned-io", checkpoint=str(ensemble))
    # The estimator's whole contract: finite estimates, deterministic, missing and
    # faulty streams survived.
    check_estimator(estimator)
    assert isinstance(estimator._net.model, InertialEnsemble)


def test_a_member_reached_through_a_link_is_refused(ensemble, tmp_path):
    bad = tmp_path / "bad"
    shutil.copytree(ensemble, bad)
    shutil.rmtree(bad / "member-1")
    (bad / "member-1").symlink_to(ensemble / "member-1")
    with pytest.raises(CheckpointError, match="symbolic link"):
        load_checkpoint(bad)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"members": ["member-0", "member-0"]}, "named twice"),
        ({"format_version": 99}, "format_version"),
    ],
)
def test_a_member_twice_or_a_newer_format_is_refused(ensemble, tmp_path, change, match):
    bad = tmp_path / "bad"
    shutil.copytree(ensemble, bad)
    meta = json.loads((bad / ENSEMBLE_JSON).read_text()) | change
    (bad / ENSEMBLE_JSON).write_text(json.dumps(meta))
    with pytest.raises(CheckpointError, match=match):
        load_checkpoint(bad)


def test_a_member_retrained_after_ensemble_json_is_refused(room_data, ensemble, tmp_path):
    out = tmp_path / "io"
    shutil.copytree(ensemble, out)
    other = TrainConfig(epochs=1, batch_size=BATCH, seed=9)
    train(room_data, out / "member-1", other, overwrite=True, progress=False)
    with pytest.raises(CheckpointError, match="member-1 changed since"):
        load_checkpoint(out)


def test_a_refused_rerun_leaves_the_ensemble_as_it_was(room_data, ensemble, tmp_path):
    out = tmp_path / "io"
    shutil.copytree(ensemble, out)
    before = (out / ENSEMBLE_JSON).read_bytes()
    other = TrainConfig(epochs=EPOCHS + 1, batch_size=BATCH, seed=4)
    with pytest.raises(TrainingFolderError, match="another run"):
        train_ensemble(room_data, out, other, members=2, progress=False)
    assert (out / ENSEMBLE_JSON).read_bytes() == before
    assert isinstance(load_checkpoint(out).model, InertialEnsemble)


@pytest.mark.parametrize("member", ["../member-0", "/tmp", "..", "", "a\\b", 3])
def test_a_member_outside_the_ensemble_folder_is_refused(ensemble, tmp_path, member):
    bad = tmp_path / "bad"
    shutil.copytree(ensemble, bad)
    meta = json.loads((bad / ENSEMBLE_JSON).read_text())
    meta["members"] = ["member-0", member]
    (bad / ENSEMBLE_JSON).write_text(json.dumps(meta))
    with pytest.raises(CheckpointError, match="not a folder name"):
        load_checkpoint(bad)


def test_members_of_different_windows_are_refused(ensemble, tmp_path):
    bad = tmp_path / "bad"
    shutil.copytree(ensemble, bad)
    meta = json.loads((bad / "member-1" / MODEL_JSON).read_text())
    meta["window_samples"] = 100
    (bad / "member-1" / MODEL_JSON).write_text(json.dumps(meta))
    with pytest.raises(CheckpointError, match="members differ"):
        load_checkpoint(bad)


@pytest.mark.parametrize("content", ["[1, 2]", '{"format": "x", "members": ["member-0"]}', "{"])
def test_a_malformed_ensemble_json_is_refused(ensemble, tmp_path, content):
    bad = tmp_path / "bad"
    shutil.copytree(ensemble, bad)
    (bad / ENSEMBLE_JSON).write_text(content)
    with pytest.raises(CheckpointError, match=ENSEMBLE_JSON):
        load_checkpoint(bad)


def test_an_interrupted_ensemble_is_no_checkpoint_until_the_command_completes_it(
    room_data, ensemble, tmp_path
):
    out = tmp_path / "io"
    shutil.copytree(ensemble, out)
    shutil.rmtree(out / "member-1")
    (out / ENSEMBLE_JSON).unlink()
    # A killed write leaves a hidden sibling behind: no reason to refuse the folder.
    (out / ".member-1.0a1b2c3d.partial").mkdir()
    with pytest.raises(CheckpointError, match="unfinished ensemble"):
        load_checkpoint(out)
    config = TrainConfig(epochs=EPOCHS, batch_size=BATCH, seed=4)
    reports = train_ensemble(room_data, out, config, members=2, progress=False)
    # The finished member is left as it is; the missing one is trained.
    assert [r.epochs_run for r in reports] == [0, EPOCHS]
    for member in ("member-0", "member-1"):
        weights = (out / member / WEIGHTS_FILE).read_bytes()
        assert weights == (ensemble / member / WEIGHTS_FILE).read_bytes()
    assert json.loads((out / ENSEMBLE_JSON).read_text())["members"] == ["member-0", "member-1"]


def test_a_folder_with_anything_else_is_refused(room_data, tmp_path):
    out = tmp_path / "io"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(TrainingFolderError, match=r"holds notes\.txt: not an ensemble"):
        train_ensemble(room_data, out, TrainConfig(epochs=1), members=2, progress=False)
    assert (out / "notes.txt").read_text() == "mine" and not (out / "member-0").exists()
    with pytest.raises(ValueError, match="at least 2"):
        train_ensemble(room_data, tmp_path / "one", TrainConfig(epochs=1), members=1)


def test_the_packaged_checkpoint_is_the_documented_ensemble():
    """Five members, seeds 0 to 4, each complete and unchanged since ensemble.json."""
    packaged = load_checkpoint()
    assert isinstance(packaged.model, InertialEnsemble) and len(packaged.model.members) == 5
    assert packaged.meta["seeds"] == [0, 1, 2, 3, 4]
    assert "--members 5" in packaged.meta["command"]
    assert (packaged.frame, packaged.imu_rate_hz, packaged.window_samples) == ("world", 50.0, 100)
