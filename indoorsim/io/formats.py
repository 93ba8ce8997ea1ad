"""The registry of real phone-log formats that :meth:`Recording.load` understands.

Each :class:`LogFormat` names its detector and reader as ``"module:function"``
strings, resolved on first use, so the registry imports no reader and the
readers (which build :class:`~indoorsim.io.recording.Recording` objects) can
import the recording module without a circle. Other packages add formats
through the ``indoorsim.log_formats`` entry-point group (each entry point loads
to a :class:`LogFormat`) or with :func:`register_format`.
"""

from __future__ import annotations

import importlib
import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from importlib.metadata import entry_points
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from indoorsim.io.recording import Recording

__all__ = ["ENTRY_POINT_GROUP", "FORMATS", "LogFormat", "detect_format", "register_format"]

ENTRY_POINT_GROUP = "indoorsim.log_formats"

PathLike = str | os.PathLike[str]


def _resolve(target: str | Callable[..., Any]) -> Callable[..., Any]:
    if callable(target):
        return target
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True, kw_only=True)
class LogFormat:
    """A real-log format: how to recognise it and how to read it.

    Attributes:
        name: short identifier, e.g. ``"ilc2020"``.
        description: what the path looks like, for error messages.
        detector: ``"module:function"`` (or the function): path → True when the
            path (file or folder) is in this format; cheap, and never raises for
            paths of other formats.
        reader: ``"module:function"`` (or the function): path → Recording.
    """

    name: str
    description: str
    detector: str | Callable[[Path], bool]
    reader: str | Callable[[Path], Recording]

    def detect(self, path: Path) -> bool:
        """Whether ``path`` is in this format."""
        return bool(_resolve(self.detector)(path))

    def read(self, path: Path) -> Recording:
        """Read ``path`` (in this format) into a Recording."""
        return _resolve(self.reader)(path)


_READERS = "indoorsim.io.reallogs"

FORMATS: list[LogFormat] = [
    LogFormat(
        name="ilc2020",
        description="Indoor Location Competition 2.0 path trace (*.txt, tab-separated, "
        "'#\\tstartTime:' header, TYPE_* rows)",
        detector=f"{_READERS}.ilc:looks_like_ilc_trace",
        reader=f"{_READERS}.ilc:read_ilc_trace",
    ),
    LogFormat(
        name="oxford-stepcounter",
        description="Oxford step-counter optimisation folder (accelerometer.csv + stepcounter.csv)",
        detector=f"{_READERS}.oxford:looks_like_oxford_folder",
        reader=f"{_READERS}.oxford:read_oxford_folder",
    ),
    LogFormat(
        name="oxford-stepcounter-validation",
        description="Oxford step-counter validation file (*.csv, no header, 7 numeric columns)",
        detector=f"{_READERS}.oxford:looks_like_oxford_validation",
        reader=f"{_READERS}.oxford:read_oxford_validation",
    ),
    LogFormat(
        name="sensor-logger",
        description="Sensor Logger app CSV export (folder or .zip with Accelerometer.csv, "
        "Gyroscope.csv... headed 'time,seconds_elapsed,...')",
        detector=f"{_READERS}.sensor_logger:looks_like_sensor_logger",
        reader=f"{_READERS}.sensor_logger:read_sensor_logger",
    ),
    LogFormat(
        name="mag-slam-1d",
        description="1-D magnetic-field SLAM walk (*.mat with t, tm, m, dPos: magnetometer "
        "and ARKit positions)",
        detector=f"{_READERS}.mag_slam:looks_like_mag_slam_walk",
        reader=f"{_READERS}.mag_slam:read_mag_slam_walk",
    ),
    LogFormat(
        name="tyrex-attitude",
        description="Inria Tyrex attitude benchmark walk (folder with accelerometer.txt, "
        "gyroscope[-calibrated].txt, timeAlignment.txt; whitespace-separated)",
        detector=f"{_READERS}.tyrex:looks_like_tyrex_folder",
        reader=f"{_READERS}.tyrex:read_tyrex_folder",
    ),
]
"""The formats, checked in this order by :func:`detect_format`."""


def register_format(log_format: LogFormat) -> LogFormat:
    """Add a format to :data:`FORMATS` (checked after the ones before it)."""
    if any(f.name == log_format.name for f in FORMATS):
        raise ValueError(f"a log format named {log_format.name!r} is already registered")
    FORMATS.append(log_format)
    return log_format


def _load_plugins() -> None:
    known = {f.name for f in FORMATS}
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name in known:
            continue
        # A broken plug-in must not stop indoorsim reading its own formats.
        try:
            log_format = ep.load()
        except Exception as err:
            warnings.warn(
                f"log-format plug-in {ep.name!r} ({ep.value}) failed to load and is ignored: "
                f"{err!r}",
                stacklevel=3,
            )
            continue
        if not isinstance(log_format, LogFormat):
            warnings.warn(
                f"log-format plug-in {ep.name!r} ({ep.value}) loads to a "
                f"{type(log_format).__name__}, not a LogFormat; ignored",
                stacklevel=3,
            )
            continue
        FORMATS.append(log_format)
        known.add(log_format.name)


def detect_format(path: PathLike) -> LogFormat | None:
    """The first registered format ``path`` is in (built-in formats first), or None."""
    _load_plugins()
    source = Path(path)
    return next((f for f in FORMATS if f.detect(source)), None)
