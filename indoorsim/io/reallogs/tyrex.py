"""The Inria Tyrex attitude-estimation benchmark: one folder per recorded walk.

Michel, Genevès, Fourati and Layaïda, "On attitude estimation with smartphones"
(PerCom 2017; github.com/tyrex-team/benchmarks-attitude-smartphones, CeCILL v2.1):
three walkers, a Nexus 5 and two iPhones, each carried texting, phoning, swinging
in the hand and in a front and back pocket while walking loops of a motion-capture
room, about two minutes a walk. The folders hold whitespace-separated text files,
one row per sample, time in seconds first.
"""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from indoorsim.io.reallogs.common import (
    NOT_A_NUMBER,
    WRONG_FIELD_COUNT,
    XYZ,
    PathLike,
    build_recording,
    carry_mode,
    finite_rows,
    median_rates_hz,
    quaternion_from_rotation_vector,
    report_malformed,
    time_frame,
)
from indoorsim.io.recording import Recording, RecordingError

STANDARD_GRAVITY = 9.80665
"""m/s² per g: iOS logs acceleration in g."""

_GYRO_FILES = ("gyroscope-calibrated.txt", "gyroscope.txt")


def _rows(path: Path, width: int, malformed: Counter[str]) -> NDArray[np.float64]:
    """The first ``width`` numbers of each row of a whitespace-separated text file.

    A row with fewer fields, a field that is not a number or a time (the first) that is
    not finite is skipped and counted.
    """
    good, short, garbage = [], 0, 0
    for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
        fields = line.split()
        if not fields:
            continue
        if len(fields) < width:
            short += 1
            continue
        try:
            row = [float(f) for f in fields[:width]]
        except ValueError:
            garbage += 1
            continue
        if math.isfinite(row[0]):
            good.append(row)
        else:
            garbage += 1
    malformed[f"{path.name}: {WRONG_FIELD_COUNT}"] += short
    malformed[f"{path.name}: {NOT_A_NUMBER}"] += garbage
    return np.array(good, dtype=np.float64).reshape(-1, width)


def looks_like_tyrex_folder(path: Path) -> bool:
    """A folder with ``accelerometer.txt``, a gyroscope file and ``timeAlignment.txt``."""
    return (
        path.is_dir()
        and (path / "accelerometer.txt").is_file()
        and (path / "timeAlignment.txt").is_file()
        and any((path / name).is_file() for name in _GYRO_FILES)
    )


def read_tyrex_folder(path: PathLike) -> Recording:
    """Read a walk of the Tyrex benchmark, ``<User>_<Phone>_<Dist|NoDist>_<Context>``.

    Mapping:

    * ``accelerometer.txt`` (t s, x, y, z) → ``accel``: m/s² with gravity on
      Android (``record.properties`` present); in g on iOS, where a phone lying
      still reads −1 g on the axis pointing up, so it is multiplied by −9.80665
      to read as Android's +9.81 (the axes are the same: x right, y up the
      screen, z out of it).
    * ``gyroscope-calibrated.txt`` (Android; bias removed by the OS) or
      ``gyroscope.txt`` (iOS: t, x, y, z rad/s) → ``gyro``.
    * ``rotation-vector.txt`` (Android: t, x, y, z, cos(θ/2), accuracy) →
      ``rotation`` (qw, qx, qy, qz).
    * The folder name → ``meta`` ``user``, ``device``, ``magnetic_disturbance``
      (``Dist``) and ``position`` (the context); ``mode`` from it (``Texting``
      → handheld, ``Phoning`` → calling, ``Swinging`` → dangling,
      ``FrontPocket``/``BackPocket`` → pocketed, others as given: ``AR``,
      ``RunningHand``, ``RunningPocket``). A folder named otherwise (the
      benchmark's superseded ``…_old`` walk) has ``mode`` None.

    ``t`` = seconds since the first accelerometer or gyroscope sample (the log's
    own clock value of it is ``meta["t0_log_s"]``). The motion-capture ground
    truth (``datasets/qualisys/*.mat``) and the magnetometer are not read.
    Rows that cannot be read are skipped and counted in ``meta["malformed_rows"]``.
    """
    folder = Path(path)
    malformed: Counter[str] = Counter()
    android = (folder / "record.properties").is_file()
    accel = _rows(folder / "accelerometer.txt", 4, malformed)
    gyro_file = next((folder / n for n in _GYRO_FILES if (folder / n).is_file()), None)
    if gyro_file is None:
        raise RecordingError(f"{folder}: no gyroscope file ({' or '.join(_GYRO_FILES)})")
    gyro = _rows(gyro_file, 4, malformed)
    if not len(accel) or not len(gyro):
        empty = "accelerometer.txt" if not len(accel) else gyro_file.name
        raise RecordingError(f"{folder / empty}: no rows")
    t0 = float(min(accel[:, 0].min(), gyro[:, 0].min()))
    scale = 1.0 if android else -STANDARD_GRAVITY
    streams: dict[str, pd.DataFrame] = {
        name: time_frame(rows[:, 0] - t0, dict(zip(XYZ, (k * rows[:, 1:]).T, strict=True)))
        for name, rows, k in (("accel", accel, scale), ("gyro", gyro, 1.0))
    }
    files = {"accel": "accelerometer.txt", "gyro": gyro_file.name}
    rotation_file = folder / "rotation-vector.txt"
    if android and rotation_file.is_file():
        rv = _rows(rotation_file, 4, malformed)
        if len(rv):
            q = quaternion_from_rotation_vector(rv[:, 1:4])
            streams["rotation"] = time_frame(
                rv[:, 0] - t0, dict(zip(("qw", "qx", "qy", "qz"), q.T, strict=True))
            )
            files["rotation"] = rotation_file.name
    streams = finite_rows(streams, malformed, files)

    meta: dict[str, Any] = {"source": {"format": "tyrex-attitude", "folder": folder.name}}
    parts = folder.name.split("_")
    # Exactly four parts: a walk recorded again keeps the old one as <name>_old.
    if len(parts) == 4 and parts[2] in ("Dist", "NoDist"):
        user, phone, disturbance, position = parts
        meta |= {
            "device": phone,
            "user": user,
            "magnetic_disturbance": disturbance == "Dist",
            "position": position,
            "mode": carry_mode(position),
        }
    else:
        meta |= {"device": None, "mode": None}
    meta |= {
        "t0_log_s": t0,
        "frames": {"phone": "Android sensor frame (x right, y up the screen, z out of it)"},
        "rates_hz": median_rates_hz(streams),
        "dropped_rows": {},
        "malformed_rows": report_malformed(folder, malformed),
    }
    return build_recording(folder, streams, meta)
