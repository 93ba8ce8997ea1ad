"""1-D magnetic-field SLAM walks (Kok & Solin 2024): a magnetometer with ARKit poses.

The data set (``shared/realdata/mag-slam-1d``, MIT) holds four handheld iPad
walks through a library, a mall, a square and a figure-of-eight, each a MATLAB
file of the magnetometer at 10 Hz and the visual-inertial (ARKit) positions —
the only real recordings here whose magnetic field is known along a densely
positioned path.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from indoorsim.io.reallogs.common import (
    XYZ,
    PathLike,
    build_recording,
    finite_rows,
    median_rates_hz,
    report_malformed,
    time_frame,
)
from indoorsim.io.recording import Recording, RecordingError

_REQUIRED = ("t", "tm", "m", "dPos")


def read_mag_slam_walk(path: PathLike) -> Recording:
    """Read one walk (``eight.mat``, ``library.mat``...) of the 1-D magnetic SLAM data.

    Mapping (variable names from the files, meaning from upstream ``prepareData.m``):

    * ``tm`` (s), ``m`` (N×3, µT) → ``mag``, the calibrated field in the
      device's sensor frame. Upstream turns it by ``rotz(-pi/2)`` into the
      ARKit body frame; the frame is kept as logged (‖m‖ does not depend on it).
    * ``t`` (s) and ``dPos`` ((N−1)×3 increments, m) → ``waypoints``: the
      ARKit position ``[0; cumsum(dPos)]``, horizontal x and y, at every ``t``
      (dense, but visual-inertial odometry, which drifts slowly — not a survey).
    * ``quat``, ``dPosSmooth``, ``LL`` and ``initPos`` are dropped (the
      quaternion's axis order is not documented; the rest is unused upstream).
      Upstream also skips the first 150 samples of ``library``; this reader keeps
      every sample.

    ``t`` = seconds since the first of ``t`` and ``tm``; ``meta["mode"]`` is
    ``handheld`` (upstream: "a handheld iPad moving in indoor scenes").
    """
    from scipy.io import loadmat

    source = Path(path)
    try:
        data = loadmat(source)
    except Exception as err:
        # scipy's parser meets damaged bytes with whatever it trips on (MatReadError,
        # OSError, TypeError, IndexError, zlib.error...): each means the file is not readable.
        raise RecordingError(
            f"{source}: not a readable MATLAB file ({type(err).__name__}: {err})"
        ) from err
    missing = [name for name in _REQUIRED if name not in data]
    if missing:
        raise RecordingError(
            f"{source}: a magnetic-SLAM walk needs variables {list(_REQUIRED)}; missing {missing}"
        )
    t, tm, m, steps = (_numbers(data, name, source) for name in ("t", "tm", "m", "dPos"))
    t, tm = t.ravel(), tm.ravel()
    if not (len(t) and len(tm)):
        raise RecordingError(f"{source}: t and tm must not be empty")
    if m.shape != (len(tm), 3) or steps.shape != (len(t) - 1, 3):
        raise RecordingError(
            f"{source}: expected m of shape ({len(tm)}, 3) and dPos of shape ({len(t) - 1}, 3), "
            f"got {m.shape} and {steps.shape}"
        )
    for name, values in (("t", t), ("tm", tm)):
        if not np.isfinite(values).all():
            raise RecordingError(f"{source}: {name} holds NaN or infinite times")
    t0 = float(min(t[0], tm[0]))
    # Garbage values overflow to inf: readings are then dropped below, times refused.
    with np.errstate(over="ignore", invalid="ignore"):
        position = np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])
        streams = {
            "mag": time_frame(tm - t0, dict(zip(XYZ, m.T, strict=True))),
            "waypoints": time_frame(t - t0, {"x": position[:, 0], "y": position[:, 1]}),
        }
    malformed: Counter[str] = Counter()
    streams = finite_rows(streams, malformed)
    meta: dict[str, Any] = {
        "source": {"format": "mag-slam-1d", "file": source.name},
        "device": "iPad (ARKit)",
        "mode": "handheld",
        "t0_log_s": t0,
        "frames": {"phone": "the iPad's magnetometer frame, as logged"},
        "rates_hz": median_rates_hz(streams),
        "dropped_rows": {},
        "malformed_rows": report_malformed(source, malformed),
    }
    return build_recording(source, streams, meta)


def _numbers(data: dict[str, Any], name: str, source: Path) -> NDArray[np.float64]:
    """The MATLAB variable ``name`` as a float array, or a RecordingError saying it is not one."""
    value = np.asarray(data[name])
    if value.dtype.kind not in "iuf":  # a struct, a cell, text, complex numbers
        raise RecordingError(
            f"{source}: variable {name!r} is not an array of real numbers ({value.dtype})"
        )
    return value.astype(np.float64)


def looks_like_mag_slam_walk(path: Path) -> bool:
    if not path.is_file() or path.suffix.lower() != ".mat":
        return False
    from scipy.io import whosmat

    try:
        names = {name for name, _, _ in whosmat(path)}
    except (OSError, ValueError, NotImplementedError):
        return False
    return set(_REQUIRED) <= names
