"""A small 1-D ResNet for inertial odometry, and its weights-only checkpoints.

The network is RoNIN's ResNet1D (Herath et al., ICRA 2020: a torchvision
ResNet with 1-D convolutions over an IMU window, regressing the mean
horizontal velocity of the window) scaled down for a CPU: a strided stem,
four basic residual blocks of 32–64 channels, global average pooling and a
linear head — about 70 000 parameters instead of RoNIN's ~4.6 million.

Input and output (see :mod:`indoorsim.dataset.torch`):

* input ``(B, 6, W)``: accelerometer x, y, z (m/s², gravity included) then
  gyroscope x, y, z (rad/s), channels first, ``W`` samples at the checkpoint's
  IMU rate, in the checkpoint's *frame*:

  - ``"world"`` — rotated by the phone's own fused rotation vector into
    Android's world frame (x magnetic east, y magnetic north, z up). The
    network's velocity then comes out in world axes with no further
    bookkeeping; errors of the phone's magnetic heading stay in the input, as
    on a real phone.
  - ``"gravity_aligned"`` — rotated by the fused *game* rotation vector
    (RoNIN's heading-agnostic frame): the velocity comes out in that frame's
    arbitrary yaw, and a user turns it to the world by the yaw between the
    rotation vector and the game rotation vector.

* output ``(B, 2)``: mean horizontal velocity of the body centre over the
  window, m/s, in the input frame's horizontal axes.

The input is normalised inside :meth:`InertialResNet.forward` with the
statistics of the training set, stored in the checkpoint's ``model.json``.
The two horizontal axes of each sensor share one scale and have zero mean,
so normalising commutes with a rotation about the vertical: training
augments with random yaw rotations (as RoNIN does), and the network must not
learn a preferred compass direction from the buildings it saw.

Checkpoints are folders of two files (:func:`load_checkpoint`):

* ``weights.pt`` — ``state_dict()`` saved with :func:`torch.save`: a flat
  mapping of names to tensors, nothing else;
* ``model.json`` — what is needed to rebuild the network (architecture
  hyperparameters, frame, window samples, IMU rate, normalisation) plus
  provenance (training configuration, data set card checksum, versions,
  losses) and the SHA-256 of ``weights.pt``.

An *ensemble* is a folder of such checkpoints, each trained by the same
command with its own ``--seed``, and an ``ensemble.json`` naming them
(:data:`ENSEMBLE_JSON`, written by ``indoorsim train --members N``). Its
network averages the members' velocities (a deep ensemble, Lakshminarayanan
et al., NeurIPS 2017): networks that differ only in their seed agree on the
buildings they were trained in and disagree most where their training did not
reach, so the mean is steadier off the training set than any one of them.

Loading reads ``weights.pt`` with ``torch.load(..., weights_only=True)``,
whose restricted unpickler builds only tensors and plain containers, never
arbitrary objects, then refuses anything that is not a flat ``{name:
tensor}`` mapping. The network is rebuilt from ``model.json``: no pickled
code is ever run.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import pickle
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any

import torch
from torch import nn

__all__ = [
    "CHECKPOINT_FORMAT",
    "CHECKPOINT_VERSION",
    "ENSEMBLE_FORMAT",
    "ENSEMBLE_JSON",
    "FRAMES",
    "MEMBER_PREFIX",
    "MODEL_JSON",
    "PACKAGED_CHECKPOINT",
    "WEIGHTS_FILE",
    "Checkpoint",
    "CheckpointError",
    "InertialConfig",
    "InertialEnsemble",
    "InertialResNet",
    "ensemble_meta",
    "is_checkpoint",
    "load_checkpoint",
    "load_weights",
    "packaged_checkpoint",
    "weights_bytes",
]

CHECKPOINT_FORMAT = "indoorsim-inertial-checkpoint"
ENSEMBLE_FORMAT = "indoorsim-inertial-ensemble"
ENSEMBLE_JSON = "ensemble.json"
"""Names an ensemble's member folders (``{"format": ENSEMBLE_FORMAT, "members": [...]}``)."""
MEMBER_PREFIX = "member-"
"""An ensemble's members are its sub-folders ``member-0``, ``member-1``, …"""
CHECKPOINT_VERSION = 1
MODEL_JSON = "model.json"
WEIGHTS_FILE = "weights.pt"
FRAMES = ("world", "gravity_aligned")
"""Input frames a checkpoint may use (both are gravity-aligned, so yaw augmentation is valid)."""
PACKAGED_CHECKPOINT = "learned_io"
"""Name of the checkpoint shipped in ``indoorsim/estimators/nn/checkpoints/``."""


@dataclass(frozen=True, kw_only=True)
class InertialConfig:
    """Architecture hyperparameters of :class:`InertialResNet` (stored in ``model.json``).

    Attributes:
        in_channels: input channels (accelerometer and gyroscope, 3 each).
        out_dim: outputs (horizontal velocity, 2).
        stem_channels: channels of the stem convolution.
        stem_kernel: kernel of the stem convolution (stride 2: the gait's
            1–3 Hz content survives halving a 50–200 Hz input).
        channels: output channels of each residual block.
        strides: stride of each residual block's first convolution.
        kernel_size: kernel of the residual blocks' convolutions (odd).
    """

    in_channels: int = 6
    out_dim: int = 2
    stem_channels: int = 32
    stem_kernel: int = 7
    channels: tuple[int, ...] = (32, 48, 64, 64)
    strides: tuple[int, ...] = (1, 2, 2, 2)
    kernel_size: int = 3

    def __post_init__(self) -> None:
        if len(self.channels) != len(self.strides) or not self.channels:
            raise ValueError(
                f"channels {self.channels} and strides {self.strides} must have the same, "
                "non-zero length"
            )
        if self.kernel_size % 2 == 0 or self.stem_kernel % 2 == 0:
            raise ValueError("kernel sizes must be odd (same padding)")
        sizes = (self.in_channels, self.out_dim, self.stem_channels, *self.channels, *self.strides)
        if min(sizes) < 1:
            raise ValueError(f"sizes must be positive: {self}")

    def to_json(self) -> dict[str, Any]:
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> InertialConfig:
        known = set(cls.__dataclass_fields__)
        unknown = set(data) - known
        if unknown:
            raise ValueError(f"unknown architecture keys {sorted(unknown)}")
        return cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in data.items()})


class BasicBlock1D(nn.Module):
    """conv–BN–ReLU–conv–BN plus the (projected) input, then ReLU (He et al., RoNIN)."""

    def __init__(self, c_in: int, c_out: int, kernel_size: int, stride: int):
        super().__init__()
        pad = kernel_size // 2
        self.conv1 = nn.Conv1d(c_in, c_out, kernel_size, stride, pad, bias=False)
        self.bn1 = nn.BatchNorm1d(c_out)
        self.conv2 = nn.Conv1d(c_out, c_out, kernel_size, 1, pad, bias=False)
        self.bn2 = nn.BatchNorm1d(c_out)
        self.shortcut = (
            nn.Sequential(nn.Conv1d(c_in, c_out, 1, stride, bias=False), nn.BatchNorm1d(c_out))
            if stride != 1 or c_in != c_out
            else nn.Identity()
        )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = torch.relu(self.bn1(self.conv1(x)))
        y = self.bn2(self.conv2(y))
        return torch.relu(y + self.shortcut(x))


class InertialResNet(nn.Module):
    """The 1-D ResNet velocity regressor (see the module docstring).

    Args:
        config: architecture hyperparameters.
        input_mean: (6,) per-channel mean subtracted from the input.
        input_std: (6,) per-channel scale the input is divided by.

    The normalisation is held in non-persistent buffers: it lives in
    ``model.json`` (readable, and the one copy), not in ``state_dict()``.
    """

    def __init__(
        self,
        config: InertialConfig | None = None,
        input_mean: Sequence[float] | None = None,
        input_std: Sequence[float] | None = None,
    ):
        super().__init__()
        self.config = config = config or InertialConfig()
        c = config.in_channels
        mean = torch.zeros(c) if input_mean is None else torch.as_tensor(input_mean)
        std = torch.ones(c) if input_std is None else torch.as_tensor(input_std)
        if mean.shape != (c,) or std.shape != (c,) or not bool((std > 0).all()):
            raise ValueError(f"input_mean and input_std must be ({c},), std > 0")
        self.register_buffer("input_mean", mean.float().view(1, c, 1), persistent=False)
        self.register_buffer("input_std", std.float().view(1, c, 1), persistent=False)
        k = config.stem_kernel
        self.stem = nn.Sequential(
            nn.Conv1d(c, config.stem_channels, k, stride=2, padding=k // 2, bias=False),
            nn.BatchNorm1d(config.stem_channels),
            nn.ReLU(),
        )
        blocks = []
        c_in = config.stem_channels
        for c_out, stride in zip(config.channels, config.strides, strict=True):
            blocks.append(BasicBlock1D(c_in, c_out, config.kernel_size, stride))
            c_in = c_out
        self.blocks = nn.Sequential(*blocks)
        self.head = nn.Linear(c_in, config.out_dim)
        self._initialise()

    def _initialise(self) -> None:
        # RoNIN's (torchvision's) initialisation; the last BN of each residual
        # branch starts at zero so every block starts as the identity.
        for m in self.modules():
            if isinstance(m, nn.Conv1d):
                nn.init.kaiming_normal_(m.weight, mode="fan_out", nonlinearity="relu")
            elif isinstance(m, nn.BatchNorm1d):
                nn.init.ones_(m.weight)
                nn.init.zeros_(m.bias)
        for block in self.blocks:
            nn.init.zeros_(block.bn2.weight)
        nn.init.normal_(self.head.weight, 0.0, 0.01)
        nn.init.zeros_(self.head.bias)

    def forward(self, imu: torch.Tensor) -> torch.Tensor:
        """(B, 6, W) raw IMU in the model's frame → (B, 2) velocity, m/s."""
        x = (imu - self.input_mean) / self.input_std
        x = self.blocks(self.stem(x))
        return self.head(x.mean(dim=-1))

    def n_params(self) -> int:
        """Number of trainable parameters."""
        return sum(p.numel() for p in self.parameters() if p.requires_grad)


class InertialEnsemble(nn.Module):
    """The mean of several :class:`InertialResNet` outputs (see the module docstring)."""

    def __init__(self, members: Sequence[nn.Module]):
        super().__init__()
        if not members:
            raise ValueError("an ensemble needs at least one member")
        self.members = nn.ModuleList(members)

    def forward(self, imu: torch.Tensor) -> torch.Tensor:
        return torch.stack([member(imu) for member in self.members]).mean(dim=0)


class CheckpointError(ValueError):
    """A checkpoint folder that cannot be loaded: missing, malformed, or unsafe."""


@dataclass(frozen=True)
class Checkpoint:
    """A loaded checkpoint: the network in eval mode and its ``model.json`` (an
    ensemble's: its members averaged, and its ``ensemble.json`` with what
    :func:`ensemble_meta` reads from the members).

    Attributes:
        model: the rebuilt network, weights loaded, in eval mode.
        meta: the content of ``model.json``.
        source: where it was loaded from.
    """

    model: InertialResNet | InertialEnsemble
    meta: dict[str, Any] = field(repr=False)
    source: str = ""

    @property
    def frame(self) -> str:
        """Input frame: ``"world"`` or ``"gravity_aligned"``."""
        return str(self.meta["frame"])

    @property
    def imu_rate_hz(self) -> float:
        """IMU rate the network was trained at."""
        return float(self.meta["imu_rate_hz"])

    @property
    def window_samples(self) -> int:
        """Samples per input window."""
        return int(self.meta["window_samples"])


def weights_bytes(model: nn.Module) -> bytes:
    """``model.state_dict()`` serialised with :func:`torch.save` (tensors only)."""
    buf = io.BytesIO()
    torch.save({k: v.detach().clone() for k, v in model.state_dict().items()}, buf)
    return buf.getvalue()


def load_weights(data: bytes, source: str = WEIGHTS_FILE) -> dict[str, torch.Tensor]:
    """A state dict from ``weights.pt`` bytes, refusing anything but ``{name: tensor}``.

    ``weights_only=True`` makes torch's unpickler refuse every global outside
    its small allow-list (no classes, no functions, no code); it still builds
    plain containers and numbers, so the result's shape is checked too.

    Raises:
        CheckpointError: the file is not a torch file, needs an object that
            is not allowed, or holds anything but a flat mapping of tensors.
    """
    try:
        state = torch.load(io.BytesIO(data), map_location="cpu", weights_only=True)
    except pickle.UnpicklingError as err:
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise CheckpointError(
            f"{source}: refused: it needs objects other than tensors to load ({first}). "
            "A checkpoint's weights must be a state_dict of tensors only."
        ) from None
    except (RuntimeError, EOFError, ValueError, OSError) as err:
        raise CheckpointError(f"{source}: not a readable torch weights file: {err}") from None
    if not isinstance(state, Mapping):
        raise CheckpointError(
            f"{source}: refused: holds a {type(state).__name__}, not a mapping of tensors"
        )
    bad = [
        f"{k!r} ({type(v).__name__})"
        for k, v in state.items()
        if not isinstance(k, str) or type(v) is not torch.Tensor
    ]
    if bad:
        raise CheckpointError(
            f"{source}: refused: entries that are not tensors: {', '.join(bad[:5])}"
            + (" …" if len(bad) > 5 else "")
        )
    return dict(state)


def _read(folder: Traversable, name: str) -> bytes:
    item = folder / name
    if not item.is_file():
        raise CheckpointError(f"{folder}: no {name}: not an inertial-odometry checkpoint folder")
    return item.read_bytes()


def is_checkpoint(folder: Path) -> bool:
    """True if ``folder`` holds a ``model.json`` of this format (an earlier checkpoint)."""
    try:
        meta = json.loads((folder / MODEL_JSON).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(meta, dict) and meta.get("format") == CHECKPOINT_FORMAT


def ensemble_meta(members: Sequence[str], checkpoints: Sequence[Checkpoint]) -> dict[str, Any]:
    """What ``ensemble.json`` holds of member folders ``members``, loaded as
    ``checkpoints``: their frame, rate and window (which they share), each one's
    final losses, and each one's weights checksum (so that a member retrained after
    the file was written is noticed)."""
    first = checkpoints[0].meta
    pairs = list(zip(members, checkpoints, strict=True))
    return {
        "format": ENSEMBLE_FORMAT,
        "format_version": CHECKPOINT_VERSION,
        "members": list(members),
        "frame": first["frame"],
        "imu_rate_hz": first["imu_rate_hz"],
        "window_samples": first["window_samples"],
        "member_final_losses": {name: ck.meta.get("final") for name, ck in pairs},
        "member_weights_sha256": {name: ck.meta.get("weights_sha256") for name, ck in pairs},
    }


def _model_from_meta(meta: Mapping[str, Any], source: str) -> InertialResNet:
    try:
        if meta.get("format") != CHECKPOINT_FORMAT:
            raise ValueError(f"format is {meta.get('format')!r}, expected {CHECKPOINT_FORMAT!r}")
        if int(meta.get("format_version", -1)) > CHECKPOINT_VERSION:
            raise ValueError(
                f"format_version {meta['format_version']} is newer than this indoorsim reads "
                f"({CHECKPOINT_VERSION})"
            )
        if meta["frame"] not in FRAMES:
            raise ValueError(f"frame {meta['frame']!r} is not one of {FRAMES}")
        rate, samples = float(meta["imu_rate_hz"]), int(meta["window_samples"])
        if not (math.isfinite(rate) and rate > 0 and samples > 0):
            raise ValueError(f"imu_rate_hz {rate} and window_samples {samples} must be > 0")
        config = InertialConfig.from_json(meta["architecture"])
        return InertialResNet(config, meta["input_mean"], meta["input_std"])
    except (KeyError, TypeError, ValueError) as err:
        raise CheckpointError(f"{source}/{MODEL_JSON}: invalid: {err}") from None


def load_checkpoint(folder: str | Path | Traversable | None = None) -> Checkpoint:
    """Rebuild the network of a checkpoint folder from ``model.json`` and load its weights;
    of an ensemble folder (``ensemble.json``), every member's, averaged.

    Args:
        folder: the checkpoint or ensemble folder; None loads the packaged one
            (:func:`packaged_checkpoint`).

    Raises:
        CheckpointError: a missing file, a ``model.json`` that does not
            describe a network this code builds, a ``weights.pt`` that is not
            a flat mapping of tensors or does not match ``model.json`` (its
            checksum, or the network's parameter names and shapes); for an
            ensemble also an ``ensemble.json`` that is malformed, names a member
            outside its folder (or twice), or whose members were retrained since
            it was written or differ in frame, IMU rate or window; and a folder
            of members without ``ensemble.json`` (an unfinished ensemble).
    """
    root: Traversable = packaged_checkpoint() if folder is None else _traversable(folder)
    if (root / ENSEMBLE_JSON).is_file():
        return _load_ensemble(root)
    if not (root / MODEL_JSON).is_file() and (root / f"{MEMBER_PREFIX}0").is_dir():
        raise CheckpointError(
            f"{root}: an unfinished ensemble (member folders but no {ENSEMBLE_JSON}): run "
            "the train command that made it again to finish it"
        )
    return _load_single(root)


def _load_ensemble(root: Traversable) -> Checkpoint:
    """An ensemble folder's members, loaded each as :func:`load_checkpoint` does, as one
    :class:`Checkpoint` whose network averages them."""
    source = str(root)
    if isinstance(root, Path) and (root / ENSEMBLE_JSON).is_symlink():
        raise CheckpointError(f"{source}/{ENSEMBLE_JSON}: a symbolic link; refused")
    try:
        meta = json.loads(_read(root, ENSEMBLE_JSON).decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise CheckpointError(f"{source}/{ENSEMBLE_JSON}: not valid JSON: {err}") from None
    members = meta.get("members") if isinstance(meta, dict) else None
    if (
        not isinstance(meta, dict)
        or meta.get("format") != ENSEMBLE_FORMAT
        or not isinstance(members, list)
        or not members
    ):
        raise CheckpointError(
            f"{source}/{ENSEMBLE_JSON}: expected {{'format': {ENSEMBLE_FORMAT!r}, "
            "'members': [folder names], ...}"
        )
    version = meta.get("format_version", 1)
    if not isinstance(version, int) or version > CHECKPOINT_VERSION:
        raise CheckpointError(
            f"{source}/{ENSEMBLE_JSON}: format_version {version!r} is not one this indoorsim "
            f"reads (up to {CHECKPOINT_VERSION})"
        )
    for name in members:
        _check_member(root, name)
    if len(set(members)) != len(members):
        raise CheckpointError(f"{source}/{ENSEMBLE_JSON}: a member is named twice")
    loaded = [_load_single(root / name) for name in members]
    recorded = meta.get("member_weights_sha256") or {}
    changed = [
        name
        for name, ck in zip(members, loaded, strict=True)
        if name in recorded and recorded[name] != ck.meta.get("weights_sha256")
    ]
    if changed:
        raise CheckpointError(
            f"{source}: {', '.join(changed)} changed since {ENSEMBLE_JSON} was written (a "
            "train command left unfinished?): run it again to finish the ensemble"
        )
    shared = {(ck.frame, ck.imu_rate_hz, ck.window_samples) for ck in loaded}
    if len(shared) != 1:
        raise CheckpointError(
            f"{source}: members differ in frame, IMU rate or window: {sorted(shared)}"
        )
    model = InertialEnsemble([ck.model for ck in loaded]).eval()
    return Checkpoint(model=model, meta=meta | ensemble_meta(members, loaded), source=source)


def _check_member(root: Traversable, name: object) -> None:
    """Refuse a member that is not a plain sub-folder of ``root`` (never one reached
    through a link, which could point anywhere)."""
    plain = isinstance(name, str) and name not in {"", ".", ".."}
    if not plain or "/" in name or "\\" in name:
        raise CheckpointError(f"{root}/{ENSEMBLE_JSON}: member {name!r} is not a folder name")
    if isinstance(root, Path) and (root / name).is_symlink():
        raise CheckpointError(f"{root}/{name}: a symbolic link; an ensemble's members are its own")


def _load_single(root: Traversable) -> Checkpoint:
    source = str(root)
    try:
        meta = json.loads(_read(root, MODEL_JSON).decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise CheckpointError(f"{source}/{MODEL_JSON}: not valid JSON: {err}") from None
    if not isinstance(meta, dict):
        raise CheckpointError(f"{source}/{MODEL_JSON}: expected a JSON object")
    model = _model_from_meta(meta, source)
    data = _read(root, WEIGHTS_FILE)
    state = load_weights(data, f"{source}/{WEIGHTS_FILE}")
    expected = meta.get("weights_sha256")
    if expected is not None and hashlib.sha256(data).hexdigest() != expected:
        raise CheckpointError(
            f"{source}/{WEIGHTS_FILE}: its SHA-256 does not match model.json's weights_sha256: "
            "the weights were changed or belong to another checkpoint"
        )
    try:
        model.load_state_dict(state, strict=True)
    except RuntimeError as err:
        raise CheckpointError(
            f"{source}: weights do not fit the network model.json describes: {err}"
        ) from None
    return Checkpoint(model=model.eval(), meta=meta, source=source)


def _traversable(folder: str | Path | Traversable) -> Traversable:
    return Path(folder) if isinstance(folder, str) else folder


def packaged_checkpoint() -> Traversable:
    """The checkpoint folder shipped with indoorsim (works in installed packages too)."""
    return resources.files("indoorsim.estimators.nn") / "checkpoints" / PACKAGED_CHECKPOINT
