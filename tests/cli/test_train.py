"""``indoorsim train`` on empty splits, and its checkpoint passed to ``evaluate`` as an option."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

from indoorsim.cli import main
from indoorsim.dataset.card import CARD_JSON


@pytest.fixture(scope="module")
def one_site(one_room_data: Path) -> Path:
    return one_room_data


def _train(data: Path, out: Path) -> list[str]:
    return ["train", "--data", str(data), "--out", str(out), "--epochs", "1", "--quiet"]


def test_train_warns_about_empty_validation_and_test_splits(one_site, tmp_path, capsys):
    splits = json.loads((one_site / CARD_JSON).read_text())["splits"]
    assert splits == {"train": ["minimal_room"], "val": [], "test": []}
    out = tmp_path / "io"
    assert main([*_train(one_site, out), "--batch-size", "32"]) == 0
    captured = capsys.readouterr()
    losses = {"val": "no validation loss after each epoch", "test": "no test loss"}
    assert captured.err.splitlines() == [
        f"indoorsim: warning: --data {one_site}: the {split} split holds no windows: it has "
        "no site (splits are whole sites, and every split gets one only from 3 sites on); "
        f"{loss}"
        for split, loss in losses.items()
    ]  # even with --quiet
    assert "(0 val, 0 test)" in " ".join(captured.out.split())
    assert (out / "model.json").is_file() and (out / "weights.pt").is_file()
    # The checkpoint, given to learned-io on the command line, is the one that runs.
    args = ["evaluate", "--scenario", "minimal_room", "--seeds", "1", "--device", "ideal"]
    spec = f"learned-io:checkpoint={out}"
    assert main([*args, "--estimator", spec, "--out", str(tmp_path / "eval")]) == 0
    summary = pd.read_csv(tmp_path / "eval" / "summary.csv")
    assert json.loads(summary["params"].iloc[0]) == {"checkpoint": str(out)}
    assert summary["ae"].iloc[0] > 0


def test_train_refuses_an_empty_train_split(one_site, tmp_path, capsys):
    # The data set with its one (train) site's shard emptied: a train split without windows.
    data = tmp_path / "data"
    shutil.copytree(one_site, data)
    (shard,) = sorted((data / "shards").glob("shard-*.parquet"))
    pq.write_table(pq.read_table(shard).slice(0, 0), shard)
    out = tmp_path / "io"
    assert main(_train(data, out)) == 2
    assert capsys.readouterr().err == (
        f"indoorsim: --data {data}: the train split holds no windows: nothing to train on\n"
    )
    assert not out.exists()
