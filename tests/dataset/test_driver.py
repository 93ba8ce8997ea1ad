"""``indoorsim dataset``: plan, schema, same bytes, resume after a kill, retries, splits."""

from __future__ import annotations

import itertools
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
import torch

from indoorsim.cli import main
from indoorsim.dataset import DatasetConfigError, load_config, make_plan, split_sites
from indoorsim.dataset.card import CARD_JSON
from indoorsim.dataset.config import validate_config
from indoorsim.dataset.driver import RUN_LOG, ShardFailures, build_dataset
from indoorsim.dataset.schema import COLUMNS, arrow_schema
from indoorsim.dataset.shard import (
    _site,
    run_shard,
    sha256_file,
    shard_is_complete,
    simulate_walk,
)
from indoorsim.dataset.torch import WindowDataset, WindowStream, site_split

# Three small sites (the 10 m room and two generated buildings), six 30 s walks,
# one walk per shard, modes changing every few seconds: a few seconds of simulation.
ARGS = ["--sites", "3", "--walks-per-site", "2", "--minutes", "0.5", "--seed", "7"]
CONFIG = {
    "bundled": ["minimal_room"],
    "bundled_share": 0.34,
    "generated_kinds": ["basement", "open_hall"],
    "walks_per_shard": 1,
    "mode_changes_per_minute": 6.0,
    "min_mode_s": 5.0,
    "rows_per_row_group": 8,
}


def _dataset_argv(config_file: Path, workers: int) -> list[str]:
    """``indoorsim dataset`` on the small config, quiet, without ``--out``."""
    return ["dataset", *ARGS, "--config", str(config_file), "--workers", str(workers), "--quiet"]


def _files(root: Path) -> dict[str, bytes]:
    """Every file of a data set but the run log, by relative path."""
    return {
        str(p.relative_to(root)): p.read_bytes()
        for p in sorted(root.rglob("*"))
        if p.is_file() and p.name != RUN_LOG
    }


@pytest.fixture(scope="module")
def config_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("config") / "dataset.yaml"
    path.write_text(json.dumps(CONFIG))
    return path


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory, config_file: Path) -> Path:
    """The data set computed uninterrupted by two workers."""
    out = tmp_path_factory.mktemp("two_workers") / "data"
    assert main([*_dataset_argv(config_file, 2), "--out", str(out)]) == 0
    return out


def test_plan_is_a_pure_function_of_the_config_keyed_by_walk_identity():
    config = load_config(None, {**CONFIG, "sites": 3, "walks_per_site": 4})
    plan = make_plan(config)
    assert plan == make_plan(config)
    regrouped = make_plan(config.model_copy(update={"walks_per_shard": 3}))
    assert regrouped.walks == plan.walks  # regrouping moves walks, never changes them
    assert [len(s.walks) for s in regrouped.shards] == [3, 1] * 3
    more = make_plan(config.model_copy(update={"sites": 4, "walks_per_site": 5}))
    assert all(w in more.walks for w in plan.walks)  # growing keeps the existing walks
    assert len({w.walk_id for w in more.walks}) == len(more.walks)
    for shard in plan.shards:
        assert {w.site for w in shard.walks} == {shard.site.index}
    for walk in plan.walks:
        times = [entry[0] for entry in walk.modes]
        assert times[0] == 0 and all(b - a >= 5.0 - 1e-9 for a, b in itertools.pairwise(times))
        assert all(a[1] != b[1] for a, b in itertools.pairwise(walk.modes))


def test_bad_configuration_is_rejected_naming_the_file_and_key(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "walker:\n  speed_mps: {low: 1.4, high: 1.0}\ndevices: [nokia_3310]\ncolour: 3\n"
    )
    with pytest.raises(DatasetConfigError) as err:
        load_config(bad)
    text = str(err.value)
    assert f"{bad}: walker.speed_mps: low (1.4) must not exceed high (1.0)" in text
    assert f"{bad}: colour: unknown key" in text
    fixed = bad.read_text().replace("{low: 1.4, high: 1.0}", "{low: 1.0, high: 1.4}")
    bad.write_text(fixed.replace("colour: 3\n", ""))
    assert main(["dataset", "--config", str(bad), "--out", str(tmp_path / "out")]) == 2
    printed = capsys.readouterr().err
    assert f"{bad}: devices[0]: unknown device 'nokia_3310'; valid devices are: high_" in printed
    assert not (tmp_path / "out").exists()
    with pytest.raises(DatasetConfigError, match="<inline>: stride_samples"):
        validate_config({"window_samples": 100, "stride_samples": 150}, "<inline>")


def test_shard_schema_round_trip_matches_the_simulated_walk(tmp_path):
    config = load_config(None, {**CONFIG, "sites": 1, "minutes": 0.4, "stride_samples": 150})
    shard = make_plan(config).shards[0]
    info = run_shard(config.to_json(), shard.to_json(), str(tmp_path))
    path = tmp_path / info["file"]
    assert info["sha256"] == sha256_file(path)
    assert info["bytes"] == path.stat().st_size
    assert not list(path.parent.glob(".*"))  # no temporary file left behind
    table = pq.read_table(path)
    assert table.schema.equals(arrow_schema(config.window_samples))
    assert [c.name for c in COLUMNS] == table.column_names
    assert pq.ParquetFile(path).metadata.row_group(0).num_rows == config.rows_per_row_group

    walk = shard.walks[0]
    rec = simulate_walk(_site(shard.site), walk, config)
    rec.validate()  # a mode schedule's walk, built without it: it must pass all the same
    w, stride = config.window_samples, config.stride
    t_imu = rec.accel.index.to_numpy()
    n_windows = (len(t_imu) - w) // stride + 1
    assert table.num_rows == n_windows == info["walks"][0]["windows"]
    rows = table.to_pylist()
    k = n_windows - 1
    last = rows[k]
    np.testing.assert_array_equal(last["t"], t_imu[k * stride : k * stride + w])
    np.testing.assert_array_equal(
        np.asarray(last["accel"], np.float32),
        rec.accel.to_numpy()[k * stride : k * stride + w].astype(np.float32),
    )
    # Labels: the truth at the IMU times (truth is sampled at 200 Hz).
    truth = rec.truth
    for col, stream_col in ((0, "x"), (1, "y"), (2, "z")):
        expected = np.interp(last["t"], truth.index.to_numpy(), truth[stream_col].to_numpy())
        np.testing.assert_allclose(np.asarray(last["pos"])[:, col], expected, atol=1e-5)
    steps = rec.steps.index.to_numpy()
    for k, row in enumerate(rows):
        t0, t1 = row["t"][0], row["t"][-1]
        # A step belongs to the first IMU sample at or after it.
        after = t_imu[k * stride - 1] if k else -np.inf
        inside = steps[(steps > after) & (steps <= t1)]
        assert row["step_count"] == sum(row["step"]) == len(row["step_t"]) == len(inside)
        np.testing.assert_array_equal(row["step_t"], inside)
        assert len(row["wifi_bssid"]) == len(row["wifi_rss"])
        vel = np.asarray(row["body_vel"])
        disp = np.subtract(row["body_pos"][-1], row["body_pos"][0]) / (t1 - t0)
        np.testing.assert_allclose(vel, disp, atol=1e-5)
    assert {r["mode"] for r in rows} <= set(config.modes)
    sidecar = json.loads(path.with_suffix(".json").read_text())
    assert sidecar == {k: v for k, v in info.items() if k != "timing"}


def test_same_bytes_with_one_and_two_workers(tmp_path, reference, config_file):
    out = tmp_path / "data"
    assert main([*_dataset_argv(config_file, 1), "--out", str(out)]) == 0
    one, two = _files(out), _files(reference)
    assert one.keys() == two.keys()
    assert len([k for k in one if k.endswith(".parquet")]) == 6
    assert [k for k in one if one[k] != two[k]] == []
    card = json.loads((out / CARD_JSON).read_text())
    for shard in card["shards"]:
        assert sha256_file(out / shard["file"]) == shard["sha256"]
    assert card["counts"]["walks"] == 6 and card["counts"]["windows"] > 0


# Loaded by every Python process of the killed run (driver and Dask workers, which
# inherit PYTHONPATH): after the named shard is written, the process group is
# killed, as a power cut would end the run (or sent SIGINT, as Ctrl-C in a
# terminal does), at a known point instead of a time.
_CRASH_HOOK = """
import os

if os.environ.get("INDOORSIM_TEST_CRASH_AFTER"):
    import signal

    import indoorsim.dataset.shard as shard

    _run_shard = shard.run_shard

    def run_shard(config_json, shard_json, out):
        result = _run_shard(config_json, shard_json, out)
        if shard_json["name"] == os.environ["INDOORSIM_TEST_CRASH_AFTER"]:
            sig = getattr(signal, os.environ.get("INDOORSIM_TEST_SIGNAL", "SIGKILL"))
            os.killpg(os.getpgrp(), sig)
        return result

    # Pickled by reference, so the worker runs its own (hooked) copy.
    run_shard.__module__, run_shard.__qualname__ = shard.__name__, "run_shard"
    shard.run_shard = run_shard
"""


def test_killed_run_resumes_without_losing_or_duplicating_shards(tmp_path, reference, config_file):
    out = tmp_path / "data"
    argv = [*_dataset_argv(config_file, 1), "--out", str(out)]
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(_CRASH_HOOK)
    env = os.environ | {
        "INDOORSIM_TEST_CRASH_AFTER": "shard-00002",
        "PYTHONPATH": os.pathsep.join([str(hook), os.environ.get("PYTHONPATH", "")]),
    }
    # Its own session, so that the kill takes the Dask worker processes too (a crash).
    command = [sys.executable, "-m", "indoorsim", *argv]
    proc = subprocess.run(
        command, start_new_session=True, env=env, stderr=subprocess.DEVNULL, timeout=300
    )
    assert proc.returncode == -signal.SIGKILL
    done_before = {p.name for p in (out / "shards").glob("*.json")}
    assert "shard-00002.json" in done_before and len(done_before) < 6
    assert not (out / CARD_JSON).exists()

    assert main(argv) == 0
    log = json.loads((out / RUN_LOG).read_text())
    assert log["skipped"] >= len(done_before) and log["skipped"] + log["computed"] == 6
    assert _files(out) == _files(reference)
    assert not [p for p in out.rglob(".*")]  # no temporary files left


def test_ctrl_c_is_one_line_and_the_run_resumes(tmp_path, reference, config_file):
    """SIGINT to the whole process group, as Ctrl-C sends it, after a known shard: one
    line on stderr (no traceback of the driver or of a Dask worker), exit 130, the
    finished shards kept, and the same command finishes the same data set."""
    out = tmp_path / "data"
    argv = [*_dataset_argv(config_file, 1), "--out", str(out)]
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(_CRASH_HOOK)
    env = os.environ | {
        "INDOORSIM_TEST_CRASH_AFTER": "shard-00002",
        "INDOORSIM_TEST_SIGNAL": "SIGINT",
        "PYTHONPATH": os.pathsep.join([str(hook), os.environ.get("PYTHONPATH", "")]),
    }
    command = [sys.executable, "-m", "indoorsim", *argv]
    proc = subprocess.run(
        command, start_new_session=True, env=env, capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 130, proc.stderr
    done_before = {p.name for p in (out / "shards").glob("*.json")}
    assert "shard-00002.json" in done_before and len(done_before) < 6
    assert proc.stderr == (
        f"indoorsim: interrupted: {len(done_before)} of 6 shards are complete and kept in "
        f"{out}; run the same command again to resume\n"
    )
    assert not (out / CARD_JSON).exists()

    assert main(argv) == 0
    log = json.loads((out / RUN_LOG).read_text())
    assert log["skipped"] == len(done_before) and log["computed"] == 6 - len(done_before)
    assert _files(out) == _files(reference)
    assert not [p for p in out.rglob(".*")]


# Loaded by every Python process of the run, like _CRASH_HOOK: from the named shard's
# Parquet file on, the disk is full. The writer gets half of its first block down,
# then ENOSPC, as a real full disk fails a write; every later write fails at once
# (a marker file says the disk has filled). The atomic writer must clean up.
_DISK_FULL_HOOK = """
import os

if os.environ.get("INDOORSIM_TEST_DISK_FULL_AT"):
    import contextlib
    import errno
    from pathlib import Path

    import indoorsim.dataset.shard as shard

    _atomic_file = shard._atomic_file
    full = Path(os.environ["INDOORSIM_TEST_DISK_FULL_MARK"])

    class _FillingFile:
        def __init__(self, fh):
            self._fh = fh

        def write(self, data):
            if not full.exists():
                full.touch()
                self._fh.write(bytes(data)[: len(data) // 2])
                self._fh.flush()
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        def __getattr__(self, name):
            return getattr(self._fh, name)

    @contextlib.contextmanager
    def _filling_atomic_file(path):
        with _atomic_file(path) as fh:
            at = path.name == os.environ["INDOORSIM_TEST_DISK_FULL_AT"] + ".parquet"
            yield _FillingFile(fh) if at or full.exists() else fh

    shard._atomic_file = _filling_atomic_file
"""


def test_a_full_disk_is_one_line_leaves_no_partial_file_and_the_run_resumes(
    tmp_path, reference, config_file
):
    """ENOSPC while writing a known shard: one line naming the full disk and the resume
    command, exit 1, no half-written file, the finished shards intact; the same command
    then finishes the same bytes as an uninterrupted run."""
    out = tmp_path / "data"
    argv = [*_dataset_argv(config_file, 1), "--out", str(out)]
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(_DISK_FULL_HOOK)
    mark = tmp_path / "disk-is-full"
    env = os.environ | {
        "INDOORSIM_TEST_DISK_FULL_AT": "shard-00003",
        "INDOORSIM_TEST_DISK_FULL_MARK": str(mark),
        "PYTHONPATH": os.pathsep.join([str(hook), os.environ.get("PYTHONPATH", "")]),
    }
    command = [sys.executable, "-m", "indoorsim", *argv]
    proc = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
    assert mark.exists()  # the hook did fill the disk
    assert proc.returncode == 1, proc.stderr
    done = {p.stem for p in (out / "shards").glob("*.json")}
    assert "shard-00003" not in done and len(done) < 6
    assert proc.stderr == (
        f"indoorsim: disk full: no space left on the device to write shard-00003 in {out} "
        f"(No space left on device); {len(done)} of 6 shards are complete and kept; free "
        "some space and run the same command again to resume\n"
    )
    assert not [p for p in out.rglob(".*")]  # no half-written shard or sidecar
    assert {p.stem for p in (out / "shards").glob("*.parquet")} == done
    for name in done:
        assert shard_is_complete(out, name) is not None  # intact: its checksum holds
    assert not (out / CARD_JSON).exists()

    assert main(argv) == 0
    log = json.loads((out / RUN_LOG).read_text())
    assert log["skipped"] == len(done) and log["computed"] == 6 - len(done)
    assert _files(out) == _files(reference)
    assert len(list((out / "shards").glob("*.parquet"))) == 6
    assert not [p for p in out.rglob(".*")]


def test_a_keyboard_interrupt_in_the_driver_is_one_line(tmp_path, monkeypatch, capsys):
    """The command line's side, without a cluster: exit 130 and the driver's message."""
    from indoorsim.dataset.driver import DatasetInterrupted

    def interrupted(*args, **kwargs):
        raise DatasetInterrupted("interrupted: 2 of 6 shards are complete and kept in x")

    monkeypatch.setattr("indoorsim.dataset.driver.build_dataset", interrupted)
    assert main(["dataset", *ARGS, "--out", str(tmp_path / "x"), "--quiet"]) == 130
    assert capsys.readouterr().err == (
        "indoorsim: interrupted: 2 of 6 shards are complete and kept in x\n"
    )


def test_no_site_is_in_two_splits(reference):
    for n in (1, 2, 3, 7, 40):
        ids = [f"site-{i}" for i in range(n)]
        split = split_sites(ids, seed=n)
        members = [s for part in split.values() for s in part]
        assert sorted(members) == sorted(ids)
        if n >= 3:
            assert all(split.values())
    card = json.loads((reference / CARD_JSON).read_text())
    split = site_split(reference)
    assert split == card["splits"]
    seen: dict[str, str] = {}
    for name in ("train", "val", "test"):
        sites = {s["site"] for s in WindowDataset(reference, name)}
        assert sites == set(split[name]) and sites
        for site in sites:
            assert seen.setdefault(site, name) == name
    assert len(seen) == 3


def test_torch_samples_follow_the_shards_in_every_frame(reference):
    phone = WindowDataset(reference, frame="phone", extra=("accel", "body_vel", "magnetic_north"))
    world = WindowDataset(reference, frame="world")
    aligned = WindowDataset(reference, frame="gravity_aligned")
    assert len(phone) == len(world) == len(aligned) > 0
    for i in (0, len(phone) // 2, len(phone) - 1):
        p, w, g = phone[i], world[i], aligned[i]
        assert p["imu"].shape == (6, 200) and p["imu"].dtype == torch.float32
        torch.testing.assert_close(p["imu"][:3].T, p["accel"])
        # A rotation keeps lengths: of the specific force and of the velocity target.
        for other in (w, g):
            torch.testing.assert_close(other["imu"][:3].norm(dim=0), p["imu"][:3].norm(dim=0))
            torch.testing.assert_close(other["vel"].norm(), p["body_vel"].norm())
        # The fused attitude turns gravity up: the world-frame specific force
        # averages close to +g over a window.
        assert 8.0 < float(w["imu"][2].mean()) < 11.5
        assert 0 <= int(p["mode"]) < len(phone.modes)
    loader = torch.utils.data.DataLoader(WindowStream(reference, seed=1), batch_size=16)
    seen = sum(len(batch["site"]) for batch in loader)
    assert seen == len(phone)


def test_failing_task_is_retried_then_reported_by_name(tmp_path, monkeypatch, capsys):
    from distributed import LocalCluster

    config = load_config(
        None, {**CONFIG, "sites": 2, "walks_per_site": 1, "minutes": 0.2, "retries": 2}
    )
    doomed = make_plan(config).shards[1]
    calls: list[str] = []

    def failing(site, walk, cfg):
        calls.append(walk.walk_id)
        if walk.walk_id == doomed.walks[0].walk_id:
            raise RuntimeError(f"simulated failure in {walk.walk_id}")
        return simulate_walk(site, walk, cfg)

    # Worker threads in this process, so that the patched function is the one they run.
    monkeypatch.setattr("indoorsim.dataset.shard.simulate_walk", failing)
    # One thread: the walks run one at a time, as in indoorsim's own single-threaded workers.
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        with pytest.raises(ShardFailures) as err:
            build_dataset(config, tmp_path / "data", scheduler=cluster.scheduler_address)
        assert calls.count(doomed.walks[0].walk_id) == 1 + config.retries
        assert [f.name for f in err.value.failures] == [doomed.name]
        assert f"{doomed.name}: RuntimeError: simulated failure" in str(err.value)
        assert (tmp_path / "data" / "shards" / "shard-00000.parquet").is_file()
        assert not (tmp_path / "data" / CARD_JSON).exists()
        log = json.loads((tmp_path / "data" / RUN_LOG).read_text())
        assert log["failures"][0]["shard"] == doomed.name

        # The command line: exit status 3 and the shard's name on stderr.
        config_path = tmp_path / "c.json"
        config_path.write_text(json.dumps(config.to_json()))
        argv = [
            "dataset",
            "--config",
            str(config_path),
            "--out",
            str(tmp_path / "data"),
            "--scheduler",
            cluster.scheduler_address,
            "--quiet",
        ]
        assert main(argv) == 3
        assert doomed.name in capsys.readouterr().err


@pytest.mark.parametrize(("closed", "status"), [(True, 0), (False, 3)])
def test_quick_exit_only_after_a_clean_worker_close(closed, status):
    # A local worker process whose worker closed cleanly ends at once, its output
    # flushed; one that did not keeps its own exit status (here 3).
    script = (
        "import sys\n"
        "from indoorsim.dataset.driver import _QuickExit\n"
        "plugin = _QuickExit()\n"
        "plugin.setup(worker=None)\n"
        f"if {closed}:\n"
        "    plugin.teardown(worker=None)\n"
        "sys.stdout.write('unflushed output')\n"
        "sys.exit(3)\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.returncode == status, done.stderr
    assert done.stdout == "unflushed output"


def test_quick_exit_is_registered_on_our_own_cluster_only():
    from distributed import LocalCluster

    from indoorsim.dataset.driver import _client, _DriverHandlesInterrupt, _QuickExit

    def plugins(dask_worker):
        return sorted(dask_worker.plugins)

    def sigint(dask_worker):
        return signal.getsignal(signal.SIGINT)

    with _client(1, None) as client:
        (names,) = client.run(plugins).values()
        assert _QuickExit.name in names and _DriverHandlesInterrupt.name in names
        assert list(client.run(sigint).values()) == [signal.SIG_IGN]
    # In-process workers of someone else's cluster: the hook would end this very process.
    # One thread: the walks run one at a time, as in indoorsim's own single-threaded workers.
    with LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        with _client(None, cluster.scheduler_address) as client:
            (names,) = client.run(plugins).values()
            assert _QuickExit.name not in names and _DriverHandlesInterrupt.name not in names
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # this process's own
