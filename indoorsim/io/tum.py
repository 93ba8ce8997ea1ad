"""TUM trajectory files: one pose per line, ``timestamp tx ty tz qx qy qz qw``.

The plain-text trajectory format of the TUM RGB-D benchmark (Sturm et al.
2012), which evo (``evo_ape tum truth.tum estimate.tum``) and most SLAM tools
read: eight space-separated numbers per line — the time in seconds, the
position in metres, the orientation as a unit quaternion with the scalar
last. Readers skip lines that start with ``#``; :func:`write_tum` writes none
(no header), so a file holds poses only.

indoorsim writes 2-D trajectories in the building frame: x and y, z = 0, and
the orientation a turn about +z by the heading h (rad counter-clockwise from
+x), ``qx = qy = 0, qz = sin(h/2), qw = cos(h/2)``, where the heading is
known, else the identity ``(0, 0, 0, 1)``. Numbers are written in Python's
shortest round-trip form, so reading a file back gives the same floats.

>>> import tempfile, pathlib
>>> path = pathlib.Path(tempfile.mkdtemp()) / "walk.tum"
>>> _ = write_tum(path, [0.5, 1.5], [[1.0, 2.0], [1.5, 2.0]], heading=[0.0, float("nan")])
>>> print(path.read_text(), end="")
0.5 1.0 2.0 0.0 0.0 0.0 0.0 1.0
1.5 1.5 2.0 0.0 0.0 0.0 0.0 1.0
>>> read_tum(path).position[:, :2].tolist()
[[1.0, 2.0], [1.5, 2.0]]
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["TumTrajectory", "heading_quaternions", "read_tum", "write_tum"]


@dataclass(frozen=True)
class TumTrajectory:
    """Poses read from a TUM file.

    Attributes:
        t: (N,) timestamps, s.
        position: (N, 3) positions tx, ty, tz, m.
        orientation: (N, 4) unit quaternions qx, qy, qz, qw (scalar last, as in the file).
    """

    t: NDArray[np.float64]
    position: NDArray[np.float64]
    orientation: NDArray[np.float64]


def heading_quaternions(heading: ArrayLike) -> NDArray[np.float64]:
    """(N, 4) quaternions qx, qy, qz, qw turning +x to each heading about +z; identity for NaN.

    >>> heading_quaternions([np.pi, float("nan")]).round(12).tolist()
    [[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    """
    h = np.asarray(heading, dtype=float).reshape(-1)
    known = np.isfinite(h)
    half = np.where(known, h, 0.0) / 2.0
    q = np.zeros((len(h), 4))
    q[:, 2] = np.sin(half)
    q[:, 3] = np.cos(half)
    return q


def write_tum(
    path: str | os.PathLike[str],
    t: ArrayLike,
    xy: ArrayLike,
    heading: ArrayLike | None = None,
) -> Path:
    """Write a 2-D trajectory as a TUM file (z = 0); returns the path.

    Args:
        path: the file to write (replaced if it exists; written under a
            temporary name first, so a reader never sees half a file).
        t: (N,) strictly increasing timestamps, s.
        xy: (N, 2) positions in the building frame, m (or (N, 3) with z).
        heading: (N,) headings, rad counter-clockwise from +x, NaN where
            unknown; None: identity orientations throughout.

    Raises:
        ValueError: for mismatched lengths, non-finite times or positions, or
            timestamps that do not increase (TUM readers associate poses by time).
    """
    path = Path(path)
    t = np.asarray(t, dtype=float).reshape(-1)
    pos = np.asarray(xy, dtype=float)
    if pos.ndim != 2 or pos.shape[1] not in (2, 3) or len(pos) != len(t):
        raise ValueError(f"{path}: expected ({len(t)}, 2) positions, got {pos.shape}")
    if pos.shape[1] == 2:
        pos = np.column_stack([pos, np.zeros(len(pos))])
    if not (np.isfinite(t).all() and np.isfinite(pos).all()):
        raise ValueError(f"{path}: times and positions must be finite")
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"{path}: timestamps must increase strictly")
    h = np.full(len(t), np.nan) if heading is None else np.asarray(heading, dtype=float)
    if h.shape != t.shape:
        raise ValueError(f"{path}: expected {len(t)} headings, got shape {h.shape}")
    rows = np.column_stack([t, pos, heading_quaternions(h)])
    # repr: the shortest text that reads back as the same float; "-0.0" kept as "0.0".
    text = "".join(" ".join(repr(float(v) + 0.0) for v in row) + "\n" for row in rows)
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    tmp.write_text(text, encoding="ascii")
    os.replace(tmp, path)
    return path


def read_tum(path: str | os.PathLike[str]) -> TumTrajectory:
    """Read a TUM file: eight numbers per line; ``#`` comment lines and blank lines skipped.

    Raises:
        ValueError: a line without eight numbers (the message names the file and line).
    """
    path = Path(path)
    rows = []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if not line.strip() or line.startswith("#"):
            continue
        fields = line.split()
        try:
            if len(fields) != 8:
                raise ValueError(f"{len(fields)} fields")
            rows.append([float(v) for v in fields])
        except ValueError as err:
            raise ValueError(
                f"{path}, line {number}: expected 8 numbers (timestamp tx ty tz qx qy qz qw): {err}"
            ) from None
    data = np.array(rows, dtype=float).reshape(-1, 8)
    return TumTrajectory(t=data[:, 0], position=data[:, 1:4], orientation=data[:, 4:8])
