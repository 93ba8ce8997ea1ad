"""Running a data set on Dask: resume, retries, progress, and the card written last.

:func:`build_dataset` is the whole job:

1. resolve the configuration and its plan; store the configuration as
   ``config.json`` in the output folder before any work (or, when the folder
   already holds one, refuse unless it is equal: a resumed run must be the
   same data set), and the SHA-256 of every scenario or device file it names
   as ``inputs.json`` (a resumed run refuses a file whose bytes changed: it
   would mix two buildings or two phones under one name);
2. delete the temporary files a killed run left behind, and skip every shard
   whose sidecar exists and whose file still matches the sidecar's checksum;
3. run the remaining shards as Dask tasks — on a new
   ``LocalCluster(n_workers=W, threads_per_worker=1, processes=True)``, or on
   an existing cluster given by its scheduler address — each retried
   ``config.retries`` times before it counts as failed; a progress bar follows
   :func:`distributed.as_completed`;
4. write ``run_log.json`` (timings, worker count, failures: the one file that
   differs between runs), then, if every shard is done, the dataset card
   (``dataset_card.json`` and ``README.md``), built from the sidecars in shard
   order so that it is byte-identical however the shards were computed.

On an existing cluster the workers write the shards themselves: they need
indoorsim installed and the output folder at the same path (a shared file
system).

Failed shards are reported by name with their exception
(:class:`ShardFailures`); the finished shards stay, and running the same
command again computes only what is missing. An interrupted run (Ctrl-C)
closes its cluster and raises :class:`DatasetInterrupted`, which says how many
shards are complete and kept. A shard that finds the disk full (``ENOSPC``, or a
quota) stops the run the same way, as :class:`DatasetDiskFull`, since every shard
after it would fail alike: the temporary files are deleted, so the finished shards
are all that is left, and the same command resumes once there is space.

Dask's own log lines (a worker's "Compute Failed" with its traceback, for each
retry of a shard that fails on a full disk) are silenced for the run: the
failures are reported by name instead, and recorded in ``run_log.json``. The
worker processes of a local cluster, once started, ignore SIGINT, which Ctrl-C
sends to every process of the terminal's group: the driver handles it and
closes them, where each would print the traceback of its event loop
(:class:`_DriverHandlesInterrupt`).

Workers run single-threaded numerical libraries (OpenMP, MKL, OpenBLAS, torch
and, where installed, whatever ``threadpoolctl`` controls): the environment of
a local cluster's worker processes is set before they start
(``distributed.nanny.pre-spawn-environ``), and a worker plugin sets the limits
again on any cluster.

A local cluster's workers run without Dask's statistical profiler (it samples
the task's stack every 10 ms, for a dashboard this job does not open) and with
slower housekeeping (event-loop tick, system and memory monitors), and
their processes, once their worker has closed cleanly, end
without finalising the interpreter (:class:`_QuickExit`): with numba's LLVM
loaded that takes ~0.3 s, paid at the end of every run.
"""

from __future__ import annotations

import atexit
import contextlib
import datetime
import errno
import json
import logging
import os
import platform
import signal
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import dask
from distributed import Client, LocalCluster, as_completed
from distributed.diagnostics.plugin import WorkerPlugin

from indoorsim.dataset.card import covered_hours, write_card
from indoorsim.dataset.config import DatasetConfig, config_difference, is_yaml_file
from indoorsim.dataset.plan import make_plan
from indoorsim.dataset.shard import (
    PARTIAL,
    RECORDINGS_DIR,
    SHARDS_DIR,
    run_shard,
    sha256_file,
    shard_is_complete,
)
from indoorsim.walker.real_walkers import REAL_WALKERS_CSV

__all__ = [
    "BuildReport",
    "DatasetDiskFull",
    "DatasetFolderError",
    "DatasetInterrupted",
    "ShardFailures",
    "build_dataset",
]

CONFIG_FILE = "config.json"
INPUTS_FILE = "inputs.json"
RUN_LOG = "run_log.json"
_SINGLE_THREAD_ENV = {
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "NUMBA_NUM_THREADS": "1",
}


class DatasetFolderError(ValueError):
    """An output folder that cannot take this data set (foreign content, another config)."""


@dataclass(frozen=True)
class ShardFailure:
    """A shard whose task failed after every retry."""

    name: str
    error: str


class ShardFailures(RuntimeError):
    """Shards that failed after their retries; the message names each one and its error."""

    def __init__(self, failures: list[ShardFailure], done: int, total: int):
        self.failures = failures
        lines = [f"  {f.name}: {f.error}" for f in failures]
        super().__init__(
            f"{len(failures)} of {total} shards failed after their retries "
            f"({done} are complete and kept; run the same command again to retry):\n"
            + "\n".join(lines)
        )


class DatasetInterrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C after its cluster closed; the message says what is kept."""


class DatasetDiskFull(OSError):
    """A run stopped because a shard found no space to be written (ENOSPC, or a quota).

    Raised once the cluster has closed and half-written files are gone; the message
    (one line, its ``str``) names the shard and the folder, counts the shards kept
    and says how to resume. ``errno`` is the writer's.
    """

    def __init__(self, code: int, message: str):
        super().__init__(code, message)

    def __str__(self) -> str:
        return self.strerror


_DISK_FULL = frozenset({errno.ENOSPC, errno.EDQUOT})


@dataclass
class BuildReport:
    """What a run did.

    Attributes:
        out: the data set's folder.
        shards: shards in the plan.
        skipped: shards that were already complete.
        computed: shards computed in this run.
        windows: windows in the whole data set.
        hours: hours of IMU data in the whole data set.
        wall_s: this run's wall time.
        failures: shards that failed (empty when the card was written).
        timings: per computed shard, its stage timings.
    """

    out: Path
    shards: int
    skipped: int = 0
    computed: int = 0
    windows: int = 0
    hours: float = 0.0
    wall_s: float = 0.0
    failures: list[ShardFailure] = field(default_factory=list)
    timings: dict[str, dict[str, float]] = field(default_factory=dict)


# ---------------------------------------------------------------------- the folder


def _write_json(path: Path, data: Any) -> None:
    tmp = path.with_name(f".{path.name}{PARTIAL}")
    try:
        tmp.write_text(json.dumps(data, indent=2, sort_keys=True, allow_nan=False) + "\n", "utf-8")
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)  # a full disk leaves no half-written file
        raise


def input_files(config: DatasetConfig) -> dict[str, str]:
    """SHA-256 of each file the plan reads: each scenario and device file the
    configuration names, by its path as given, and with real walkers' vigour their
    table (by its name in the package)."""
    named = [*(config.bundled or []), *config.devices]
    files = {name: sha256_file(Path(name)) for name in named if is_yaml_file(name)}
    if config.walker.vigour == "real":
        files[REAL_WALKERS_INPUT] = sha256_file(REAL_WALKERS_CSV)
    return files


REAL_WALKERS_INPUT = "indoorsim/walker/real_walkers.csv"
"""How ``inputs.json`` names the real walkers' table."""


def _check_inputs(out: Path, config: DatasetConfig) -> None:
    """Store the input files' checksums, or check them against the stored ones."""
    wanted = input_files(config)
    path = out / INPUTS_FILE
    if not path.is_file():
        if wanted:  # a data set of built-in names only keeps its folder as it was
            _write_json(path, wanted)
        return
    try:
        stored = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as err:
        raise DatasetFolderError(f"{path}: unreadable ({err}); remove the folder") from None
    changed = [
        f"{name}: sha256 {str(stored.get(name))[:12]}… when the data set was started, "
        f"{digest[:12]}… now"
        for name, digest in wanted.items()
        if stored.get(name) != digest
    ]
    if changed:
        raise DatasetFolderError(
            f"{out}: an input file changed since the data set was started; resuming would "
            "mix its old and new contents (restore it, or use another --out):\n  "
            + "\n  ".join(changed)
        )


def prepare_folder(out: Path, config: DatasetConfig) -> None:
    """Create ``out`` with ``config.json`` (and ``inputs.json``), or check that it holds
    this configuration and these input files.

    Raises:
        DatasetFolderError: ``out`` is a file, a non-empty folder that is no
            data set, a data set of another configuration (the message
            lists the keys that differ), or one whose scenario or device files
            changed since it was started (the message names them).
    """
    wanted = config.to_json()
    stored_path = out / CONFIG_FILE
    if out.exists() and not out.is_dir():
        raise DatasetFolderError(f"--out {out}: exists and is not a folder")
    if stored_path.is_file():
        try:
            stored = json.loads(stored_path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as err:
            raise DatasetFolderError(
                f"{stored_path}: unreadable ({err}); remove the folder"
            ) from None
        if isinstance(stored, dict) and isinstance(stored.get("walker"), dict):
            # A data set started before walkers took real vigour was made without it.
            stored["walker"].setdefault("vigour", "default")
            # ... and before walkers could slow at their route's points (none did).
            stored["walker"].setdefault("mark_speed", {"low": 1.0, "high": 1.0})
        diff = (
            config_difference(stored, wanted) if isinstance(stored, dict) else ["<not a mapping>"]
        )
        if diff:
            raise DatasetFolderError(
                f"{out} holds a data set of another configuration; resuming needs the same "
                "arguments (or use another --out). Differences:\n  " + "\n  ".join(diff)
            )
        _check_inputs(out, config)
        return
    if out.is_dir() and any(out.iterdir()):
        raise DatasetFolderError(
            f"--out {out}: a non-empty folder without {CONFIG_FILE}; "
            "refusing to write a data set into it"
        )
    out.mkdir(parents=True, exist_ok=True)
    _write_json(stored_path, wanted)
    _check_inputs(out, config)


def _clean_partials(out: Path) -> None:
    """Delete what a killed run left half written (temporary files and folders)."""
    import shutil

    for folder in (out, out / SHARDS_DIR, out / RECORDINGS_DIR):
        if not folder.is_dir():
            continue
        for item in folder.iterdir():
            if item.name.startswith(".") and item.name.endswith((PARTIAL, ".old")):
                if item.is_dir() and not item.is_symlink():
                    shutil.rmtree(item, ignore_errors=True)
                else:
                    item.unlink(missing_ok=True)


# ---------------------------------------------------------------------- Dask


class _SingleThreaded(WorkerPlugin):
    """Worker plugin: one thread for every numerical library in the worker's process.

    Pre-spawn environment variables cover the worker processes of a local
    cluster; this covers an existing cluster's workers too.
    """

    idempotent = True
    name = "indoorsim-single-threaded"

    def setup(self, worker: Any) -> None:
        os.environ.update(_SINGLE_THREAD_ENV)
        with contextlib.suppress(ImportError):
            from threadpoolctl import threadpool_limits

            threadpool_limits(limits=1)
        if "torch" in sys.modules:
            sys.modules["torch"].set_num_threads(1)


class _QuickExit(WorkerPlugin):
    """Worker plugin for the worker processes of our own local cluster: a process
    whose worker has closed cleanly exits at once with status 0, skipping the interpreter's
    finalisation (~0.3 s of module and LLVM teardown while the run waits for
    its cluster to close).

    The hook runs at the process's exit, after the worker's close has finished
    (plugins torn down, comms and services closed) and multiprocessing's own
    exit handling has run. Registered after every library's exit handler, it
    runs first (atexit is last in, first out) and skips them and the rest of
    the finalisation: weakref finalizers, ``logging.shutdown`` (so a buffered
    log handler would lose its last records: the workers log only to stderr,
    flushed here), and the exit status of an error raised after the close
    (the process exits 0; the close is done by then). A worker that never
    closed cleanly (killed, crashed) exits the ordinary way. Not used on an
    existing cluster, whose processes are not ours.
    """

    idempotent = True
    name = "indoorsim-quick-exit"

    def __init__(self) -> None:
        self._closed = False

    def setup(self, worker: Any) -> None:
        atexit.register(self._exit)

    def teardown(self, worker: Any) -> None:
        self._closed = True

    def _exit(self) -> None:
        if self._closed:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(0)


class _DriverHandlesInterrupt(WorkerPlugin):
    """Worker plugin for the worker processes of our own local cluster: ignore SIGINT.

    Ctrl-C sends SIGINT to every process of the terminal's process group, the
    Dask workers among them; the driver stops the run and closes the cluster
    (the shard a worker is writing is atomic: it is written whole or not at
    all), where each worker would print the traceback of its interrupted event
    loop. The driver's own process (in-process workers) is left alone. Not used
    on an existing cluster, whose processes are not ours. A worker interrupted
    before this setup has run (in the first seconds of a run, while it imports)
    still prints its traceback: only SIG_IGN survives the exec that starts it,
    and ignoring SIGINT in the driver meanwhile would lose the Ctrl-C.
    """

    idempotent = True
    name = "indoorsim-driver-handles-interrupt"

    def __init__(self) -> None:
        self._driver = os.getpid()

    def setup(self, worker: Any) -> None:
        if os.getpid() != self._driver:
            signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextlib.contextmanager
def _quiet_dask_logs(quiet: bool) -> Iterator[None]:
    """Raise the level of the ``distributed`` logger's stream handlers past ERROR, then restore."""
    handlers = [
        h for h in logging.getLogger("distributed").handlers if isinstance(h, logging.StreamHandler)
    ]
    before = [h.level for h in handlers]
    try:
        if quiet:
            for handler in handlers:
                handler.setLevel(logging.CRITICAL + 1)
        yield
    finally:
        for handler, level in zip(handlers, before, strict=True):
            handler.setLevel(level)


@contextlib.contextmanager
def _client(workers: int | None, scheduler: str | None, quiet: bool = True) -> Iterator[Client]:
    if scheduler is not None:
        with Client(scheduler, set_as_default=False) as client:
            client.register_plugin(_SingleThreaded(), name=_SingleThreaded.name)
            yield client
        return
    n = workers or os.cpu_count() or 1
    local = {
        "distributed.nanny.pre-spawn-environ": _SINGLE_THREAD_ENV,
        # The statistical profiler samples the task's stack every 10 ms (GIL
        # switches, ~3 % of a shard's time) for a dashboard nobody watches here.
        "distributed.worker.profile.enabled": False,
        # Housekeeping at a pace for tasks of seconds, not Dask's defaults for
        # interactive clusters (event-loop tick 20 ms, system monitor 0.5 s,
        # memory monitor 0.1 s): idle, a worker used ~2 % of a core on it and
        # the scheduler's process ~3 %, which with two workers on two cores
        # came out of the shards' time.
        "distributed.admin.tick.interval": "1s",
        "distributed.admin.system-monitor.interval": "5s",
        # (The nanny's check that stops a worker past 95 % of its memory limit
        # runs at this pace too; half a second still catches a runaway walk.)
        "distributed.worker.memory.monitor-interval": "500ms",
    }
    with dask.config.set(local):
        with (
            LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                # Without a dashboard the scheduler still serves health routes over
                # HTTP, by default on port 8787: on a free port instead, so that a
                # second run on the machine does not print "Port 8787 is already in use".
                scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                # In the workers' processes too: the driver reports failures itself.
                silence_logs=logging.CRITICAL + 1 if quiet else logging.ERROR,
            ) as cluster,
            Client(cluster, set_as_default=False) as client,
        ):
            client.register_plugin(_SingleThreaded(), name=_SingleThreaded.name)
            client.register_plugin(_QuickExit(), name=_QuickExit.name)
            client.register_plugin(_DriverHandlesInterrupt(), name=_DriverHandlesInterrupt.name)
            yield client


def build_dataset(
    config: DatasetConfig,
    out: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: bool | None = None,
    dask_logs: bool = False,
) -> BuildReport:
    """Generate (or resume) the data set of ``config`` in ``out``.

    Args:
        config: the configuration (resolved here if it is not yet).
        out: the output folder: new, empty, or an earlier run of the same configuration.
        workers: local worker processes (default: the number of cores). Ignored
            with ``scheduler``.
        scheduler: address of an existing Dask scheduler (``tcp://host:8786``).
        progress: show a progress bar (None: only when stderr is a terminal).
        dask_logs: let Dask's own log lines (ERROR and above) through to stderr.

    Returns:
        What was done; the card is written when every shard is complete.

    Raises:
        DatasetFolderError: ``out`` cannot take this data set.
        ShardFailures: some shards failed after their retries (the others are kept).
        DatasetInterrupted: Ctrl-C (a ``KeyboardInterrupt``), once the cluster
            has closed; the finished shards are kept.
        DatasetDiskFull: a shard could not be written for want of space (an
            ``OSError``), once the cluster has closed; the finished shards are
            kept and no half-written file is left.
    """
    from tqdm import tqdm

    started = time.perf_counter()
    started_at = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
    config = config.resolved()
    root = Path(out)
    plan = make_plan(config)
    prepare_folder(root, config)
    _clean_partials(root)
    report = BuildReport(out=root, shards=len(plan.shards))
    sidecars: dict[str, dict[str, Any]] = {}
    todo = []
    for shard in plan.shards:
        info = shard_is_complete(root, shard.name)
        if info is None:
            todo.append(shard)
        else:
            sidecars[shard.name] = info
    report.skipped = len(sidecars)

    disk_full: tuple[str, OSError] | None = None
    if todo:
        config_json = config.to_json()
        try:
            with (
                _quiet_dask_logs(not dask_logs),
                _client(workers, scheduler, quiet=not dask_logs) as client,
                tqdm(
                    total=len(plan.shards),
                    initial=len(sidecars),
                    unit="shard",
                    desc="dataset",
                    disable=None if progress is None else not progress,
                    file=sys.stderr,
                ) as bar,
            ):
                run_id = f"{os.getpid()}-{time.time_ns()}"
                futures = {
                    client.submit(
                        run_shard,
                        config_json,
                        shard.to_json(),
                        str(root),
                        key=f"{shard.name}-{run_id}",
                        retries=config.retries,
                        pure=False,
                    ): shard.name
                    for shard in todo
                }
                for future in as_completed(futures, loop=client.loop):
                    name = futures[future]
                    if future.status == "error":
                        err = future.exception()
                        if isinstance(err, OSError) and err.errno in _DISK_FULL:
                            # Every shard after it would fail the same way: stop here.
                            disk_full = (name, err)
                            break
                        report.failures.append(ShardFailure(name, f"{type(err).__name__}: {err}"))
                    else:
                        result = future.result()
                        report.timings[name] = result.pop("timing")
                        sidecars[name] = result
                        report.computed += 1
                        bar.set_postfix_str(name)
                    bar.update(1)
                    future.release()
        except KeyboardInterrupt:
            # Here the cluster has closed (the with statement's exits), and a shard
            # may have finished meanwhile: its sidecar, written last, says so.
            done = sum((root / SHARDS_DIR / f"{s.name}.json").is_file() for s in plan.shards)
            raise DatasetInterrupted(
                f"interrupted: {done} of {len(plan.shards)} shards are complete and kept in "
                f"{root}; run the same command again to resume"
            ) from None
    if disk_full is not None:
        # The cluster has closed; a worker stopped mid-write may have left a temporary file.
        _clean_partials(root)
        name, err = disk_full
        done = sum(shard_is_complete(root, s.name) is not None for s in plan.shards)
        raise DatasetDiskFull(
            err.errno,
            f"disk full: no space left on the device to write {name} in {root} "
            f"({err.strerror or err}); {done} of {len(plan.shards)} shards are complete and "
            "kept; free some space and run the same command again to resume",
        )
    report.failures.sort(key=lambda f: f.name)
    report.windows = sum(int(s["rows"]) for s in sidecars.values())
    report.hours = covered_hours(
        [w["windows"] for info in sidecars.values() for w in info["walks"]], config
    )
    report.wall_s = time.perf_counter() - started
    _write_run_log(root, report, started_at, workers, scheduler)
    if report.failures:
        raise ShardFailures(report.failures, len(sidecars), len(plan.shards))
    write_card(root, config, plan, [sidecars[s.name] for s in plan.shards], versions())
    return report


def versions() -> dict[str, str]:
    """Versions of indoorsim and the libraries whose behaviour shapes the data."""
    out = {"python": platform.python_version()}
    for package in (
        "indoorsim",
        "numpy",
        "scipy",
        "pandas",
        "pyarrow",
        "shapely",
        "pymunk",
        "numba",
    ):
        try:
            out[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            out[package] = "not installed"
    return out


def _write_run_log(
    root: Path, report: BuildReport, started_at: str, workers: int | None, scheduler: str | None
) -> None:
    log = {
        "started_utc": started_at,
        "wall_s": round(report.wall_s, 3),
        "workers": None if scheduler else (workers or os.cpu_count() or 1),
        "scheduler": scheduler or "local",
        "shards": report.shards,
        "skipped": report.skipped,
        "computed": report.computed,
        "failures": [{"shard": f.name, "error": f.error} for f in report.failures],
        "timings": report.timings,
        "note": "run information only: not part of the data set and not byte-identical "
        "between runs",
    }
    _write_json(root / RUN_LOG, log)
