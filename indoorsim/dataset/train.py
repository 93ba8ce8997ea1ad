"""Training the inertial-odometry network on a generated data set (``indoorsim train``).

:func:`train` fits :class:`~indoorsim.estimators.nn.inertial.InertialResNet`
to the windows of an ``indoorsim dataset`` folder, RoNIN-style: the input is
the window's IMU in a gravity-aligned frame (``"world"`` by default: the
phone's own fused rotation vector), the target the mean horizontal velocity
of the body centre over the window, the loss the mean squared error (m²/s²)
of its two components, the optimiser Adam with a cosine-decaying step size.

Data. The shards are read with :class:`~indoorsim.dataset.torch.WindowStream`
(row groups in a seeded order, dealt to ``DataLoader`` workers) through a
seeded shuffle buffer, so a batch mixes walks, sites and phones while memory
holds only the buffer; the train split (whole sites, the dataset card's
suggested split) is trained on, the validation split scored after each epoch
and the test split once at the end, when they exist. Each training window is
turned about the vertical by a random yaw (input and target alike, as RoNIN
does): the buildings' own corridor directions must not become the network's
prior on heading. The input normalisation (per-channel statistics of the
train split, horizontal axes pooled so that it commutes with that rotation)
is computed in a first pass and stored with the checkpoint.

Determinism. Every random choice — the initial weights, the row-group order,
the shuffle buffer, the yaw draws — derives from ``seed`` and the epoch
number, ``torch.use_deterministic_algorithms`` is on and torch runs
``threads`` intra-op threads (1 by default) during the call: on CPU the same
command gives the same weights for the same ``threads`` and ``workers``.

Checkpoints. After every epoch the checkpoint folder is written atomically
(:func:`indoorsim.io.atomic.write_folder`): ``weights.pt`` (``state_dict()``,
tensors only), ``model.json`` (architecture, frame, window, IMU rate,
normalisation, training configuration, the data set card's checksum and
configuration, versions, per-epoch losses) and, until the last epoch,
``training_state.pt`` (Adam's state). A run interrupted between epochs
resumes from the last finished epoch when the same command is run again; the
result is the same as that of an uninterrupted run, because no random state
outlives an epoch. Once finished the folder holds only the two files a user
needs, loaded by :func:`~indoorsim.estimators.nn.inertial.load_checkpoint`.

Ensembles. :func:`train_ensemble` runs :func:`train` once per member, the
members differing only in their seed (``seed``, ``seed + 1``, …), each into its
own sub-folder ``member-K`` (each resumable as above), then names them in
``ensemble.json``, written last: a folder without it is an unfinished ensemble,
which running the same command again completes.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import platform
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch.utils.data import DataLoader, IterableDataset, get_worker_info

from indoorsim._version import __version__
from indoorsim.dataset.shard import write_atomically
from indoorsim.estimators.nn.inertial import (
    CHECKPOINT_FORMAT,
    CHECKPOINT_VERSION,
    ENSEMBLE_JSON,
    FRAMES,
    MEMBER_PREFIX,
    MODEL_JSON,
    WEIGHTS_FILE,
    CheckpointError,
    InertialConfig,
    InertialResNet,
    ensemble_meta,
    is_checkpoint,
    load_checkpoint,
    load_weights,
    weights_bytes,
)
from indoorsim.estimators.nn.threads import torch_settings
from indoorsim.io.atomic import write_folder

__all__ = [
    "TRAINING_STATE",
    "TrainConfig",
    "TrainReport",
    "TrainingFolderError",
    "member_name",
    "train",
    "train_ensemble",
]

TRAINING_STATE = "training_state.pt"
"""Optimiser state kept in an unfinished checkpoint folder, for resuming."""
_CARD = "dataset_card.json"
_EVAL_BATCH = 512


class TrainingFolderError(ValueError):
    """A data folder that cannot be trained on, or an output folder that is in the way."""


@dataclass(frozen=True, kw_only=True)
class TrainConfig:
    """How to train (stored in ``model.json``; a resumed run must have an equal one).

    Attributes:
        epochs: passes over the train split.
        batch_size: windows per optimiser step.
        lr: Adam's initial step size; it decays to 0 on a half cosine over the epochs.
        seed: seeds every random choice.
        frame: input frame, ``"world"`` or ``"gravity_aligned"``.
        workers: ``DataLoader`` worker processes (0: read in the main process).
        threads: torch intra-op threads during training.
        shuffle_buffer: windows held by the shuffle buffer (per worker).
        yaw_augment: turn each training window by a random yaw.
        architecture: the network's hyperparameters.
    """

    epochs: int = 15
    batch_size: int = 128
    lr: float = 3e-3
    seed: int = 0
    frame: str = "world"
    workers: int = 0
    threads: int = 1
    shuffle_buffer: int = 4096
    yaw_augment: bool = True
    architecture: InertialConfig = field(default_factory=InertialConfig)

    def __post_init__(self) -> None:
        if self.frame not in FRAMES:
            raise ValueError(
                f"frame {self.frame!r}: the network regresses velocity in a gravity-aligned "
                f"frame; choose one of {', '.join(FRAMES)}"
            )
        for name in ("epochs", "batch_size", "threads", "shuffle_buffer"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if self.workers < 0 or self.seed < 0:
            raise ValueError("workers and seed must be >= 0")
        if not (math.isfinite(self.lr) and self.lr > 0):
            raise ValueError(f"lr must be a positive number, got {self.lr}")

    def to_json(self) -> dict[str, Any]:
        out = {k: getattr(self, k) for k in self.__dataclass_fields__ if k != "architecture"}
        return out | {"architecture": self.architecture.to_json()}


@dataclass(kw_only=True)
class TrainReport:
    """What a :func:`train` call did.

    Attributes:
        out: the checkpoint folder.
        epochs_run: epochs trained in this call (0 when the folder was already finished).
        resumed_from: epochs that were already done when the call started.
        history: per epoch, ``epoch``, ``train_loss``, ``val_loss`` (None
            without a validation split), ``lr`` and ``seconds``.
        test_loss: the finished network's loss on the test split (None without one).
        windows: windows per split.
        n_params: trainable parameters.
        wall_s: this call's wall time.
    """

    out: Path
    epochs_run: int = 0
    resumed_from: int = 0
    history: list[dict[str, Any]] = field(default_factory=list)
    test_loss: float | None = None
    windows: dict[str, int] = field(default_factory=dict)
    n_params: int = 0
    wall_s: float = 0.0

    @property
    def train_loss(self) -> float:
        """The last epoch's mean training loss (m²/s²)."""
        return float(self.history[-1]["train_loss"])

    @property
    def val_loss(self) -> float | None:
        """The last epoch's validation loss (m²/s²), None without a validation split."""
        return self.history[-1]["val_loss"]


# ---------------------------------------------------------------------- data


def _keep_imu_vel(sample: dict[str, Any]) -> dict[str, Any]:
    # Module level (not a lambda) so that DataLoader workers can pickle it.
    return {"imu": sample["imu"], "vel": sample["vel"]}


class _ShuffleBuffer(IterableDataset):
    """Seeded shuffle buffer over a :class:`WindowStream` (windows of many row groups mix).

    Each worker reads its own row groups (the stream deals them out) and
    shuffles them through its own buffer, seeded by (seed, epoch, worker).
    """

    def __init__(self, stream: Any, size: int, seed: int):
        self.stream = stream
        self.size = size
        self.seed = seed
        self.epoch = 0

    def set_epoch(self, epoch: int) -> None:
        self.epoch = epoch
        self.stream.set_epoch(epoch)

    def __len__(self) -> int:
        return len(self.stream)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        info = get_worker_info()
        rng = np.random.default_rng([self.seed, self.epoch, 0 if info is None else info.id])
        buffer: list[dict[str, Any]] = []
        for sample in self.stream:
            if len(buffer) < self.size:
                buffer.append(sample)
                continue
            k = int(rng.integers(self.size))
            yield buffer[k]
            buffer[k] = sample
        for k in rng.permutation(len(buffer)):
            yield buffer[int(k)]


def _stream(data: Path, split: str, frame: str, *, shuffle: bool, seed: int) -> Any:
    from indoorsim.dataset.torch import WindowStream

    return WindowStream(
        data, split, frame=frame, shuffle=shuffle, seed=seed, transform=_keep_imu_vel
    )


def _read_card(data: Path) -> tuple[dict[str, Any], str]:
    path = data / _CARD
    if not path.is_file():
        raise TrainingFolderError(
            f"--data {data}: no {_CARD}: not a finished indoorsim data set (run the same "
            "`indoorsim dataset` command again to finish it)"
        )
    raw = path.read_bytes()
    card = json.loads(raw)
    if card.get("format") != "indoorsim-dataset":
        raise TrainingFolderError(f"{path}: not an indoorsim dataset card")
    return card, hashlib.sha256(raw).hexdigest()


def _warn(message: str) -> None:
    warnings.warn(message, stacklevel=3)


def _empty_split(card: dict[str, Any], split: str) -> str:
    """Why ``split`` holds no windows, as far as the card tells."""
    sites = card.get("splits", {}).get(split)
    if sites:
        return f"the {split} split's sites ({', '.join(sites)}) hold no windows"
    return (
        f"the {split} split holds no windows: it has no site (splits are whole sites, and "
        "every split gets one only from 3 sites on)"
    )


def _input_stats(loader: DataLoader) -> tuple[list[float], list[float]]:
    """Per-channel mean and scale of the train split's IMU.

    In both frames x and y are horizontal: each sensor's two horizontal axes
    get mean 0 and one shared scale (their pooled RMS), so that normalising
    commutes with a turn about the vertical (the yaw augmentation).
    """
    total = torch.zeros(6, dtype=torch.float64)
    squares = torch.zeros(6, dtype=torch.float64)
    count = 0
    for batch in loader:
        x = batch["imu"].to(torch.float64)
        total += x.sum(dim=(0, 2))
        squares += (x * x).sum(dim=(0, 2))
        count += x.shape[0] * x.shape[2]
    if count == 0:
        raise TrainingFolderError("the train split holds no windows")
    mean = total / count
    second = squares / count
    out_mean, out_std = mean.clone(), (second - mean * mean).clamp_min(0).sqrt()
    for horizontal in ((0, 1), (3, 4)):
        idx = list(horizontal)
        out_mean[idx] = 0.0
        out_std[idx] = second[idx].mean().sqrt()
    # A channel that never varies (a phone without a gyroscope) keeps scale 1.
    out_std = torch.where(out_std > 1e-6, out_std, torch.ones_like(out_std))
    return [float(v) for v in out_mean], [float(v) for v in out_std]


def _turn_yaw(
    imu: torch.Tensor, vel: torch.Tensor, generator: torch.Generator
) -> tuple[torch.Tensor, torch.Tensor]:
    """Turn each window (input and target) about the vertical by a uniform random angle."""
    angle = torch.rand(imu.shape[0], generator=generator, dtype=imu.dtype) * (2 * math.pi)
    c, s = torch.cos(angle)[:, None], torch.sin(angle)[:, None]
    out = imu.clone()
    for ix, iy in ((0, 1), (3, 4)):
        x, y = imu[:, ix], imu[:, iy]
        out[:, ix], out[:, iy] = c * x - s * y, s * x + c * y
    vx, vy = vel[:, 0:1], vel[:, 1:2]
    return out, torch.cat([c * vx - s * vy, s * vx + c * vy], dim=1)


def _mse(model: InertialResNet, loader: DataLoader) -> float | None:
    """Mean squared velocity error over a split, eval mode (None for an empty split)."""
    model.eval()
    sse, n = 0.0, 0
    with torch.inference_mode():
        for batch in loader:
            err = model(batch["imu"]) - batch["vel"]
            sse += float((err.double() ** 2).sum())
            n += err.numel()
    return sse / n if n else None


# ---------------------------------------------------------------- checkpoint


def _versions() -> dict[str, str]:
    import pyarrow

    return {
        "indoorsim": __version__,
        "torch": torch.__version__,
        "numpy": np.__version__,
        "pyarrow": pyarrow.__version__,
        "python": platform.python_version(),
    }


_DATASET_FLAGS = {
    "sites": "--sites",
    "walks_per_site": "--walks-per-site",
    "minutes": "--minutes",
    "seed": "--seed",
}


def _commands(data: Path, ds_config: dict[str, Any], command: str | None) -> dict[str, Any]:
    """The commands that rebuild the data set and this checkpoint, for ``model.json``.

    The data set's command is recovered from its resolved configuration: the
    keys the command line has options for become options, every other key
    that differs from the defaults goes into the ``--config`` file, listed
    under ``dataset_config_file``.
    """
    from indoorsim.dataset import DatasetConfig

    defaults = DatasetConfig().resolved().to_json()

    def arg(value: Any) -> str:
        return f"{value:g}" if isinstance(value, float) else str(value)

    flags = " ".join(f"{flag} {arg(ds_config[key])}" for key, flag in _DATASET_FLAGS.items())
    keys = {k: v for k, v in ds_config.items() if k not in _DATASET_FLAGS and v != defaults.get(k)}
    config = "--config DATASET_CONFIG.yaml " if keys else ""
    return {
        "dataset": f"indoorsim dataset {config}{flags} --out {data}",
        "dataset_config_file": keys,
        "train": command,
    }


def _write_checkpoint(
    out: Path, model: InertialResNet, meta: dict[str, Any], optimizer_state: dict | None
) -> None:
    weights = weights_bytes(model)
    meta = meta | {"weights_sha256": hashlib.sha256(weights).hexdigest()}

    def write(tmp: Path) -> None:
        (tmp / WEIGHTS_FILE).write_bytes(weights)
        (tmp / MODEL_JSON).write_text(
            json.dumps(meta, indent=2, allow_nan=False) + "\n", encoding="utf-8"
        )
        if optimizer_state is not None:
            torch.save({"optimizer": optimizer_state}, tmp / TRAINING_STATE)

    write_folder(out, write, overwrite=True, is_ours=is_checkpoint, what="checkpoint")


def _load_resume(
    out: Path, identity: dict[str, Any], overwrite: bool
) -> tuple[dict[str, Any], dict[str, torch.Tensor], dict | None] | None:
    """The earlier run in ``out`` to continue (meta, weights, optimiser state), or None.

    Raises:
        TrainingFolderError: ``out`` holds a checkpoint of another training
            configuration or data set and ``overwrite`` is False, or something
            that is not a checkpoint.
    """
    if not out.exists():
        return None
    if not out.is_dir():
        raise TrainingFolderError(f"--out {out}: exists and is not a folder")
    if not is_checkpoint(out):
        if any(out.iterdir()):
            raise TrainingFolderError(
                f"--out {out}: a non-empty folder that is not a checkpoint; refusing to "
                "write into it"
            )
        return None
    meta = json.loads((out / MODEL_JSON).read_text(encoding="utf-8"))
    stored = {k: meta.get(k) for k in identity}
    if stored != identity:
        if overwrite:
            return None
        diff = [k for k in identity if stored[k] != identity[k]]
        raise TrainingFolderError(
            f"--out {out}: holds a checkpoint of another run (differs in {', '.join(diff)}); "
            "pass --overwrite to replace it, or choose another --out"
        )
    if overwrite:
        return None
    try:
        weights = load_weights((out / WEIGHTS_FILE).read_bytes(), str(out / WEIGHTS_FILE))
    except (OSError, CheckpointError) as err:
        raise TrainingFolderError(f"--out {out}: cannot resume: {err}") from None
    state_path = out / TRAINING_STATE
    state = None
    if state_path.is_file():
        state = torch.load(state_path, map_location="cpu", weights_only=True)["optimizer"]
    elif not meta.get("complete"):
        raise TrainingFolderError(f"--out {out}: unfinished checkpoint without {TRAINING_STATE}")
    return meta, weights, state


# ---------------------------------------------------------------------- train


def train(
    data: str | Path,
    out: str | Path,
    config: TrainConfig | None = None,
    *,
    overwrite: bool = False,
    progress: bool | None = None,
    log: Callable[[str], None] | None = None,
    command: str | None = None,
    warn: Callable[[str], None] | None = None,
) -> TrainReport:
    """Train the inertial-odometry network on ``data`` and write the checkpoint folder ``out``.

    Args:
        data: a finished ``indoorsim dataset`` folder.
        out: the checkpoint folder: new, empty, an unfinished run of the same
            configuration (resumed), or a finished one (left as it is).
        config: how to train (defaults: :class:`TrainConfig`).
        overwrite: replace a checkpoint of another configuration (or start a
            finished one afresh).
        progress: show a progress bar (None: only when stderr is a terminal).
        log: receives one line per epoch (and a note when resuming).
        command: the command line that ran this, stored in ``model.json``.
        warn: receives a line, before training starts, for an empty
            validation or test split (training goes on without that loss);
            None: :func:`warnings.warn`.

    Returns:
        What was done, with the per-epoch losses.

    Raises:
        TrainingFolderError: ``data`` is not a finished data set, its train
            split is empty, or ``out`` is in the way.
    """
    from tqdm import tqdm

    config = config or TrainConfig()
    data, out = Path(data), Path(out)
    say = log or (lambda _line: None)
    started = time.perf_counter()
    card, card_sha = _read_card(data)
    ds_config = card["config"]
    identity = _jsonable(
        {"training": config.to_json(), "data": {"card_sha256": card_sha, "config": ds_config}}
    )
    resume = _load_resume(out, identity, overwrite)
    report = TrainReport(out=out)

    with torch_settings(config.threads):
        streams = {
            split: _stream(data, split, config.frame, shuffle=split == "train", seed=config.seed)
            for split in ("train", "val", "test")
        }
        report.windows = {split: len(s) for split, s in streams.items()}
        if report.windows["train"] == 0:
            raise TrainingFolderError(
                f"--data {data}: the train split holds no windows: nothing to train on"
            )
        for split, loss in (
            ("val", "no validation loss after each epoch"),
            ("test", "no test loss"),
        ):
            if not report.windows[split]:
                (warn or _warn)(f"--data {data}: {_empty_split(card, split)}; {loss}")

        def loader(dataset: Any, batch: int) -> DataLoader:
            return DataLoader(dataset, batch_size=batch, num_workers=config.workers)

        eval_loaders = {
            split: loader(streams[split], _EVAL_BATCH)
            for split in ("val", "test")
            if report.windows[split]
        }
        if resume is not None:
            meta, weights, optimizer_state = resume
            mean, std = meta["input_mean"], meta["input_std"]
        else:
            stats_stream = _stream(data, "train", config.frame, shuffle=False, seed=config.seed)
            mean, std = _input_stats(loader(stats_stream, _EVAL_BATCH))
            meta = {
                "format": CHECKPOINT_FORMAT,
                "format_version": CHECKPOINT_VERSION,
                "architecture": config.architecture.to_json(),
                "frame": config.frame,
                "imu_rate_hz": float(ds_config["imu_rate_hz"]),
                "window_samples": int(ds_config["window_samples"]),
                "input": "accelerometer x, y, z (m/s², gravity included) then gyroscope "
                "x, y, z (rad/s), channels first, in the frame's axes",
                "output": "mean horizontal velocity of the body centre over the window, m/s, "
                "in the frame's horizontal axes",
                "input_mean": mean,
                "input_std": std,
                **identity,
                "windows": report.windows,
                "versions": _versions(),
                "commands": _commands(data, ds_config, command),
                "history": [],
                "epochs_done": 0,
                "complete": False,
            }
            weights, optimizer_state = None, None

        with torch.random.fork_rng(devices=[]):  # the caller's global RNG is left alone
            torch.manual_seed(config.seed)
            model = InertialResNet(config.architecture, mean, std)
        optimizer = torch.optim.Adam(model.parameters(), lr=config.lr)
        if weights is not None:
            model.load_state_dict(weights, strict=True)
        if optimizer_state is not None:
            optimizer.load_state_dict(optimizer_state)
        report.n_params = model.n_params()
        meta["n_params"] = report.n_params
        start = int(meta["epochs_done"])
        report.resumed_from = start
        report.history = list(meta["history"])
        if 0 < start < config.epochs:
            say(f"resuming {out} after epoch {start} of {config.epochs}")

        train_data = _ShuffleBuffer(streams["train"], config.shuffle_buffer, config.seed)
        train_loader = loader(train_data, config.batch_size)
        for epoch in range(start, config.epochs):
            t0 = time.perf_counter()
            lr = config.lr * 0.5 * (1.0 + math.cos(math.pi * epoch / config.epochs))
            for group in optimizer.param_groups:
                group["lr"] = lr
            train_data.set_epoch(epoch)
            augment = torch.Generator().manual_seed(config.seed * 1_000_003 + epoch)
            model.train()
            sse, n = 0.0, 0
            with tqdm(
                total=report.windows["train"],
                desc=f"epoch {epoch + 1}/{config.epochs}",
                unit="win",
                disable=None if progress is None else not progress,
                leave=False,
            ) as bar:
                for batch in train_loader:
                    imu, vel = batch["imu"], batch["vel"]
                    if config.yaw_augment:
                        imu, vel = _turn_yaw(imu, vel, augment)
                    loss = torch.nn.functional.mse_loss(model(imu), vel)
                    optimizer.zero_grad(set_to_none=True)
                    loss.backward()
                    optimizer.step()
                    sse += loss.item() * vel.numel()
                    n += vel.numel()
                    bar.update(len(vel))
                    bar.set_postfix_str(f"loss {sse / n:.4f}")
            val = _mse(model, eval_loaders["val"]) if "val" in eval_loaders else None
            entry = {
                "epoch": epoch + 1,
                "train_loss": sse / n,
                "val_loss": val,
                "lr": lr,
                "seconds": round(time.perf_counter() - t0, 2),
            }
            report.history.append(entry)
            report.epochs_run += 1
            last = epoch + 1 == config.epochs
            if last and "test" in eval_loaders:
                report.test_loss = _mse(model, eval_loaders["test"])
            meta |= {
                "history": report.history,
                "epochs_done": epoch + 1,
                "complete": last,
                "train_s": round(sum(h["seconds"] for h in report.history), 1),
                "final": {
                    "train_loss": entry["train_loss"],
                    "val_loss": val,
                    "test_loss": report.test_loss,
                },
            }
            _write_checkpoint(out, model, meta, None if last else optimizer.state_dict())
            val_text = "" if val is None else f", val {val:.4f}"
            say(
                f"epoch {epoch + 1}/{config.epochs}: train {entry['train_loss']:.4f}"
                f"{val_text} m²/s² ({entry['seconds']:.1f} s)"
            )
        if not report.epochs_run and meta.get("final"):
            report.test_loss = meta["final"].get("test_loss")
    report.wall_s = time.perf_counter() - started
    return report


def member_name(k: int) -> str:
    """The sub-folder of an ensemble's ``k``-th member."""
    return f"{MEMBER_PREFIX}{k}"


def train_ensemble(
    data: str | Path,
    out: str | Path,
    config: TrainConfig | None = None,
    *,
    members: int,
    overwrite: bool = False,
    progress: bool | None = None,
    log: Callable[[str], None] | None = None,
    command: str | None = None,
    warn: Callable[[str], None] | None = None,
) -> list[TrainReport]:
    """Train ``members`` networks that differ only in their seed (``config.seed`` and the
    next ``members − 1``) into ``out/member-K`` and name them in ``out/ensemble.json``.

    Arguments as :func:`train`'s; each member resumes, or is left as it is, as
    :func:`train` does, and ``overwrite`` starts every member afresh. ``ensemble.json``
    is written once every member is finished; it records each member's weights
    checksum, so an ensemble whose members were retrained since is refused by
    :func:`~indoorsim.estimators.nn.inertial.load_checkpoint` until this is run again.

    Returns:
        Each member's report, in order.

    Raises:
        ValueError: fewer than two members.
        TrainingFolderError: as :func:`train`, or ``out`` holds anything but an
            ensemble's members and ``ensemble.json`` (or more members than asked).
    """
    if members < 2:
        raise ValueError(f"an ensemble needs at least 2 members, got {members}")
    config = config or TrainConfig()
    out = Path(out)
    names = [member_name(k) for k in range(members)]
    if out.exists():
        if not out.is_dir():
            raise TrainingFolderError(f"--out {out}: exists and is not a folder")
        # Hidden names are the atomic writers' own (a member or ensemble.json being
        # replaced when a run was killed): theirs to clean, not ours to refuse.
        stray = sorted(
            p.name
            for p in out.iterdir()
            if p.name not in {*names, ENSEMBLE_JSON} and not p.name.startswith(".")
        )
        if stray or (out / ENSEMBLE_JSON).is_dir():
            what = ", ".join(stray[:5]) if stray else f"a folder named {ENSEMBLE_JSON}"
            raise TrainingFolderError(
                f"--out {out}: holds {what}: not an ensemble of {members} members "
                "(--overwrite replaces members, nothing else); choose another --out"
            )
    out.mkdir(parents=True, exist_ok=True)
    say = log or (lambda _line: None)
    reports = []
    for k, name in enumerate(names):
        say(f"member {k + 1} of {members} (seed {config.seed + k}): {out / name}")
        member = dataclasses.replace(config, seed=config.seed + k)
        reports.append(
            train(
                data,
                out / name,
                member,
                overwrite=overwrite,
                progress=progress,
                log=log,
                command=command,
                warn=warn,
            )
        )
    meta = ensemble_meta(names, [load_checkpoint(out / name) for name in names])
    meta["seeds"] = [config.seed + k for k in range(members)]
    meta["command"] = command
    text = json.dumps(meta, indent=2, allow_nan=False) + "\n"
    write_atomically(out / ENSEMBLE_JSON, text.encode("utf-8"))
    return reports


def _jsonable(value: Any) -> Any:
    """``value`` through a JSON round trip (tuples become lists, as in ``model.json``)."""
    return json.loads(json.dumps(value))


def describe(report: TrainReport) -> str:
    """One paragraph on a finished :func:`train` call, for the command line."""
    epochs = len(report.history)
    if not report.epochs_run:
        head = f"{report.out}: already trained ({epochs} epochs); nothing to do."
    else:
        resumed = f", resumed after epoch {report.resumed_from}," if report.resumed_from else ""
        head = (
            f"{report.out}: trained {report.n_params} parameters for {epochs} epochs{resumed} "
            f"on {report.windows['train']} windows ({report.windows['val']} val, "
            f"{report.windows['test']} test) in {report.wall_s:.1f} s."
        )
    losses = [f"train {report.train_loss:.4f}"]
    if report.val_loss is not None:
        losses.append(f"val {report.val_loss:.4f}")
    if report.test_loss is not None:
        losses.append(f"test {report.test_loss:.4f}")
    return f"{head} Final losses (m²/s²): {', '.join(losses)}."
