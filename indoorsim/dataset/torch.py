"""Torch data sets over the shards, read a row group at a time, never the whole data set.

Two readers share one sample format:

* :class:`WindowDataset` — map-style (``len``, ``ds[i]``): an index of
  (shard, row group) built from the Parquet footers only; a sample reads its
  row group through a memory map and keeps the last few row groups decoded,
  so in-order or row-group-grouped access costs one decode per row group.
  Good for validation and testing; with random shuffling every access may
  decode a row group, so train with…
* :class:`WindowStream` — iterable: row groups in a seeded order (changed by
  :meth:`WindowStream.set_epoch`), windows shuffled within each row group,
  row groups dealt out to ``DataLoader`` workers; memory holds one row group
  per worker.

Both select the shards of one split by site (:func:`site_split`, the same
assignment as the dataset card's suggested split), so no building is in two
splits.

Sample (a dict of tensors; ``W`` samples per window)
----------------------------------------------------

=================  ===========  =============================================
key                shape/type   meaning
=================  ===========  =============================================
``imu``            (6, W) f32   accelerometer x, y, z (m/s²) then gyroscope
                                x, y, z (rad/s), channels first (Conv1d), in
                                the sample's frame (below)
``rotation``       (W, 4) f32   the phone's own fused orientation that
                                defines the frame: world←phone (w, x, y, z)
``vel``            (2,) f32     target: mean horizontal velocity of the body
                                centre over the window, m/s, in the frame's
                                world axes
``vel_samples``    (W, 2) f32   true horizontal phone velocity per sample, same axes
``step_count``     () i64       true heel strikes in the window
``mode``           () i64       carrying mode, index into :attr:`modes`
``mode_changed``   () bool      the mode changes within the window
``window``         () i64       index of the window in its walk
``site``           str          site id (``default_collate`` keeps a list)
``walk_id``        str          walk id
=================  ===========  =============================================

plus any shard column named in ``extra`` as a tensor of its stored shape
(fixed-shape columns only, e.g. ``mag``, ``light``, ``pos``, ``quat``).

Frames (``frame=``):

* ``"phone"`` — ``imu`` raw, in the phone frame; ``rotation`` is the fused
  rotation vector; ``vel`` in that vector's world frame (x magnetic east, y
  magnetic north), i.e. the building-frame truth turned by the site's
  ``magnetic_north``. A model gets raw IMU plus the fused attitude.
* ``"world"`` — ``imu`` rotated by the fused rotation vector into that same
  world frame; ``vel`` as for ``"phone"``. Heading errors of the phone's
  fusion (magnetic disturbances) stay in the inputs, as on a real phone.
* ``"gravity_aligned"`` — RoNIN's heading-agnostic frame: ``imu`` rotated
  by the fused *game* rotation vector (gravity-aligned, yaw arbitrary but
  consistent along the walk); ``vel`` turned into the same frame by the yaw
  between the true attitude and the game rotation vector averaged over the
  window (as RoNIN aligns its ground truth with the device orientation).
"""

from __future__ import annotations

import collections
import json
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import torch
from numpy.typing import NDArray
from torch.utils.data import Dataset, IterableDataset, get_worker_info

from indoorsim.dataset.card import CARD_JSON, SPLIT_FRACTIONS
from indoorsim.dataset.config import DEFAULT_MODES
from indoorsim.dataset.plan import split_sites
from indoorsim.dataset.schema import COLUMNS
from indoorsim.dataset.shard import SHARDS_DIR
from indoorsim.util import quaternion as quat_ops

__all__ = ["FRAMES", "WindowDataset", "WindowStream", "site_split"]

FRAMES = ("phone", "world", "gravity_aligned")
_BASE_COLUMNS = (
    "site",
    "walk_id",
    "window",
    "magnetic_north",
    "accel",
    "gyro",
    "rotation",
    "game_rotation",
    "quat",
    "vel",
    "body_vel",
    "step_count",
    "mode",
    "mode_changed",
)
_BY_NAME = {c.name: c for c in COLUMNS}


def site_split(
    root: str | Path,
    fractions: tuple[float, float, float] = SPLIT_FRACTIONS,
    seed: int | None = None,
) -> dict[str, list[str]]:
    """The data set's sites by split (train/val/test), whole sites only.

    Args:
        root: the data set's folder.
        fractions: train/val/test shares of the sites.
        seed: seeds the assignment; None takes the data set's seed, which with
            the default fractions reproduces the card's suggested split.
    """
    shards = _shard_sites(Path(root))
    if seed is None:
        seed = _card(Path(root)).get("config", {}).get("seed", 0)
    return split_sites(sorted(set(shards.values())), fractions, seed=seed)


def _card(root: Path) -> dict[str, Any]:
    path = root / CARD_JSON
    return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}


def _shard_sites(root: Path) -> dict[Path, str]:
    """Every shard file of the data set and its site (a shard holds one site)."""
    folder = root / SHARDS_DIR
    files = sorted(folder.glob("shard-*.parquet"))
    if not files:
        raise FileNotFoundError(f"{root}: no shards (expected {SHARDS_DIR}/shard-*.parquet)")
    out = {}
    for f in files:
        sidecar = f.with_suffix(".json")
        if sidecar.is_file():
            out[f] = json.loads(sidecar.read_text(encoding="utf-8"))["site"]
            continue
        sites = pq.read_table(f, columns=["site"]).column("site").unique().to_pylist()
        if len(sites) != 1:
            raise ValueError(f"{f}: a shard must hold one site, found {sites}")
        out[f] = sites[0]
    return out


@dataclass(frozen=True)
class _Group:
    """One row group of one shard."""

    path: Path
    index: int
    rows: int


def _groups(
    root: str | Path,
    split: str | None,
    sites: Sequence[str] | None,
    fractions: tuple[float, float, float],
    seed: int | None,
) -> list[_Group]:
    shard_sites = _shard_sites(Path(root))
    if split is not None:
        if split not in ("train", "val", "test"):
            raise ValueError(f"split must be 'train', 'val', 'test' or None, got {split!r}")
        if sites is not None:
            raise ValueError("give a split or a list of sites, not both")
        sites = site_split(root, fractions, seed)[split]
    wanted = None if sites is None else set(sites)
    out = []
    for path, site in shard_sites.items():
        if wanted is not None and site not in wanted:
            continue
        meta = pq.ParquetFile(path).metadata
        out += [_Group(path, i, meta.row_group(i).num_rows) for i in range(meta.num_row_groups)]
    return out


def _column(table: pa.Table, name: str) -> NDArray:
    """A column as a numpy array of its per-row shape (rows, ...)."""
    col = table.column(name).combine_chunks()
    spec = _BY_NAME[name]
    if spec.dtype == "string":
        return np.asarray(col.to_pylist(), dtype=object)
    if "n" in spec.shape:
        raise ValueError(f"column {name!r} has variable length; it cannot be a tensor")
    values = col
    for _ in spec.shape:
        values = values.flatten()
    arr = values.to_numpy(zero_copy_only=False)
    shape = [len(table)] + [int(d) if d != "W" else -1 for d in spec.shape]
    return arr.reshape(shape) if spec.shape else arr


class _Reader:
    """Decodes row groups into per-window samples in one frame."""

    def __init__(
        self,
        frame: str,
        extra: Sequence[str],
        modes: Sequence[str],
        transform: Callable[[dict[str, Any]], dict[str, Any]] | None,
    ):
        if frame not in FRAMES:
            raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
        for name in extra:
            spec = _BY_NAME.get(name)
            if spec is None:
                raise ValueError(f"extra: no shard column {name!r}; columns: {', '.join(_BY_NAME)}")
            if spec.dtype == "string" or "n" in spec.shape:
                raise ValueError(f"extra: column {name!r} is not a fixed-shape numeric array")
        self.frame = frame
        self.extra = tuple(extra)
        self.modes = tuple(modes)
        self.transform = transform
        self.columns = tuple(dict.fromkeys((*_BASE_COLUMNS, *self.extra)))

    def decode(self, group: _Group) -> dict[str, NDArray]:
        """One row group as arrays, with the frame applied to the whole group at once."""
        pf = pq.ParquetFile(group.path, memory_map=True)
        table = pf.read_row_group(group.index, columns=list(self.columns))
        c = {name: _column(table, name) for name in self.columns}
        accel, gyro = c["accel"].astype(np.float64), c["gyro"].astype(np.float64)
        # Building → Android world (x magnetic east, y magnetic north): turn by π/2 − north.
        to_world = np.pi / 2 - c["magnetic_north"].astype(np.float64)
        vel = _turn(c["body_vel"].astype(np.float64), to_world)
        vel_samples = _turn(c["vel"][..., :2].astype(np.float64), to_world[:, None])
        if self.frame == "gravity_aligned":
            q = c["game_rotation"].astype(np.float64)
            # Yaw from the game frame to the building frame, averaged over the window.
            rel = quat_ops.multiply(c["quat"].astype(np.float64), quat_ops.conjugate(q))
            offset = np.angle(np.exp(1j * quat_ops.twist_yaw(rel)).mean(axis=1))
            vel = _turn(c["body_vel"].astype(np.float64), -offset)
            vel_samples = _turn(c["vel"][..., :2].astype(np.float64), -offset[:, None])
        else:
            q = c["rotation"].astype(np.float64)
        if self.frame != "phone":
            accel, gyro = quat_ops.rotate(q, accel), quat_ops.rotate(q, gyro)
        mode_index = {m: i for i, m in enumerate(self.modes)}
        out = {
            "imu": np.concatenate([accel, gyro], axis=-1).transpose(0, 2, 1).astype(np.float32),
            "rotation": q.astype(np.float32),
            "vel": vel.astype(np.float32),
            "vel_samples": vel_samples.astype(np.float32),
            "step_count": c["step_count"].astype(np.int64),
            "mode": np.array([mode_index.get(m, -1) for m in c["mode"]], dtype=np.int64),
            "mode_changed": c["mode_changed"],
            "window": c["window"].astype(np.int64),
            "site": c["site"],
            "walk_id": c["walk_id"],
        }
        for name in self.extra:
            out[name] = c[name]
        return out

    def sample(self, arrays: dict[str, NDArray], row: int) -> dict[str, Any]:
        s: dict[str, Any] = {
            k: (v[row] if v.dtype == object else torch.from_numpy(np.array(v[row])))
            for k, v in arrays.items()
        }
        return self.transform(s) if self.transform is not None else s


def _turn(v: NDArray[np.float64], angle: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotate horizontal vectors (..., 2) counter-clockwise by ``angle`` (broadcast)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], axis=-1)


class _WindowSource:
    """What both data sets share: their split's row groups and the reader that decodes them."""

    reader: _Reader
    groups: list[_Group]

    def _open(
        self,
        root: str | Path,
        split: str | None,
        sites: Sequence[str] | None,
        fractions: tuple[float, float, float],
        split_seed: int | None,
        reader: _Reader,
    ) -> None:
        self.reader = reader
        self.groups = _groups(root, split, sites, fractions, split_seed)

    @property
    def modes(self) -> tuple[str, ...]:
        """The carrying-mode names; ``sample["mode"]`` indexes this tuple."""
        return self.reader.modes


class WindowDataset(_WindowSource, Dataset):
    """Map-style torch data set of windows (see the module docstring for the sample format).

    Args:
        root: the data set's folder (``indoorsim dataset --out``).
        split: ``"train"``, ``"val"``, ``"test"`` or None for every site.
        sites: explicit site ids instead of a split.
        frame: ``"phone"``, ``"world"`` or ``"gravity_aligned"``.
        extra: further fixed-shape columns to include (``"mag"``, ``"pos"``, …).
        fractions: train/val/test shares of the sites.
        split_seed: seeds the split (None: the data set's seed, as in the card).
        cache_row_groups: decoded row groups kept in memory.
        transform: applied to each sample dict.
        modes: carrying-mode names; ``sample["mode"]`` indexes this list.
    """

    def __init__(
        self,
        root: str | Path,
        split: str | None = None,
        *,
        sites: Sequence[str] | None = None,
        frame: str = "phone",
        extra: Sequence[str] = (),
        fractions: tuple[float, float, float] = SPLIT_FRACTIONS,
        split_seed: int | None = None,
        cache_row_groups: int = 2,
        transform: Callable[[dict[str, Any]], dict[str, Any]] | None = None,
        modes: Sequence[str] = DEFAULT_MODES,
    ):
        self._open(
            root, split, sites, fractions, split_seed, _Reader(frame, extra, modes, transform)
        )
        self.starts = np.cumsum([0] + [g.rows for g in self.groups])
        self.cache_size = max(1, cache_row_groups)
        self._cache: collections.OrderedDict[int, dict[str, NDArray]] = collections.OrderedDict()

    def __len__(self) -> int:
        return int(self.starts[-1])

    def __getitem__(self, index: int) -> dict[str, Any]:
        n = len(self)
        if not -n <= index < n:
            raise IndexError(f"index {index} out of range for {n} windows")
        index %= n
        g = int(np.searchsorted(self.starts, index, side="right")) - 1
        if g not in self._cache:
            if len(self._cache) >= self.cache_size:
                self._cache.popitem(last=False)
            self._cache[g] = self.reader.decode(self.groups[g])
        else:
            self._cache.move_to_end(g)
        return self.reader.sample(self._cache[g], index - int(self.starts[g]))


class WindowStream(_WindowSource, IterableDataset):
    """Iterable torch data set streaming row groups (see the module docstring).

    Args:
        root, split, sites, frame, extra, fractions, split_seed, transform, modes:
            as for :class:`WindowDataset`.
        shuffle: shuffle the row groups and the windows within each.
        seed: seeds the shuffling (with the epoch).
    """

    def __init__(
        self,
        root: str | Path,
        split: str | None = None,
        *,
        sites: Sequence[str] | None = None,
        frame: str = "phone",
        extra: Sequence[str] = (),
        fractions: tuple[float, float, float] = SPLIT_FRACTIONS,
        split_seed: int | None = None,
        shuffle: bool = True,
        seed: int = 0,
        transform: Callable[[dict[str, Any]], dict[str, Any]] | None = None,
        modes: Sequence[str] = DEFAULT_MODES,
    ):
        self._open(
            root, split, sites, fractions, split_seed, _Reader(frame, extra, modes, transform)
        )
        self.shuffle = shuffle
        self.seed = seed
        self.epoch = 0

    def set_epoch(self, epoch: int) -> None:
        """Change the shuffling order (call before each epoch)."""
        self.epoch = epoch

    def __len__(self) -> int:
        return sum(g.rows for g in self.groups)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        rng = np.random.default_rng([self.seed, self.epoch])
        order = rng.permutation(len(self.groups)) if self.shuffle else np.arange(len(self.groups))
        info = get_worker_info()
        if info is not None:  # each DataLoader worker takes every num_workers-th row group
            order = order[info.id :: info.num_workers]
        for g in order:
            arrays = self.reader.decode(self.groups[int(g)])
            rows = self.groups[int(g)].rows
            for row in rng.permutation(rows) if self.shuffle else range(rows):
                yield self.reader.sample(arrays, int(row))
