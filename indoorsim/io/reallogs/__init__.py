"""Readers for real phone logs: each turns one log into a :class:`~indoorsim.io.Recording`.

Formats (each reader's docstring gives its full mapping):

* ``ilc2020`` — Indoor Location Competition 2.0 / Kaggle "indoor-location-
  navigation" path traces (``*.txt``): :func:`read_ilc_trace` (:mod:`.ilc`).
* ``oxford-stepcounter`` — Oxford step-counter optimisation folders
  (``accelerometer.csv`` + ``stepcounter.csv``): :func:`read_oxford_folder` (:mod:`.oxford`).
* ``oxford-stepcounter-validation`` — its validation files
  (``<user>_<position>_<unix-ms>.csv``): :func:`read_oxford_validation`.
* ``sensor-logger`` — CSV exports (folder or ``.zip``) of the "Sensor Logger"
  app by Kelvin Choi (tszheichoi): :func:`read_sensor_logger` (:mod:`.sensor_logger`).
* ``mag-slam-1d`` — the 1-D magnetic-field SLAM walks (``*.mat``, magnetometer
  and ARKit positions): :func:`read_mag_slam_walk` (:mod:`.mag_slam`).
* ``tyrex-attitude`` — walks of the Inria Tyrex attitude-estimation benchmark
  (a folder of whitespace-separated ``accelerometer.txt``, ``gyroscope*.txt``...):
  :func:`read_tyrex_folder` (:mod:`.tyrex`).

Conventions shared by every reader:

* ``t`` = seconds since the first motion-sensor sample (accelerometer,
  gyroscope, magnetometer or orientation, whichever comes first), computed from
  the log's integer clock so no precision is lost; the log's own value of that
  instant is kept in ``meta`` (``t0_unix_ms``, ``t0_unix_ns`` or ``t0_boot_ns``).
  Rows logged before it (e.g. an ILC trace's first waypoint) get a small
  negative ``t``.
* Values keep the log's units when they already are indoorsim's (m/s², rad/s,
  µT, lux, dBm); frames are the Android sensor frame, as in DESIGN §2.
* A stream is present only when the log has rows for it. Streams are sorted by
  ``t`` (stably). What a reader drops is counted in ``meta["dropped_rows"]``.
* Rows a reader cannot read (garbage: the wrong number of fields, a time or
  number that does not parse, a reading that is NaN or infinite) are skipped,
  counted by reason in ``meta["malformed_rows"]``, and reported by a
  :class:`~indoorsim.io.reallogs.common.MalformedRowsWarning` naming the file
  and the counts (the command line prints it as ``indoorsim: warning: ...``).
* A log that cannot be read at all (no row left, a damaged zip or MATLAB file)
  is a :class:`~indoorsim.io.recording.RecordingError` whose message starts
  with the file or folder.
* ``meta["mode"]`` is the carry mode in indoorsim's vocabulary when the log
  says it (``handheld``, ``pocketed``, ``dangling``, ``calling``), the log's own
  word for positions indoorsim does not model (e.g. ``Purse``), or None.
* ``meta["rates_hz"]`` is each sensor stream's median sample rate (for ``wifi``,
  the scan rate).

:class:`Recording.load <indoorsim.io.recording.Recording.load>` picks the reader by
looking at the path (:func:`~indoorsim.io.formats.detect_format`); formats live in the
open registry of :mod:`indoorsim.io.formats`, which names each reader by a string.
"""

from __future__ import annotations

from indoorsim.io.formats import FORMATS, LogFormat, detect_format, register_format
from indoorsim.io.reallogs.common import MalformedRowsWarning, carry_mode
from indoorsim.io.reallogs.ilc import read_ilc_trace
from indoorsim.io.reallogs.mag_slam import read_mag_slam_walk
from indoorsim.io.reallogs.oxford import read_oxford_folder, read_oxford_validation
from indoorsim.io.reallogs.sensor_logger import read_sensor_logger
from indoorsim.io.reallogs.tyrex import read_tyrex_folder

__all__ = [
    "FORMATS",
    "LogFormat",
    "MalformedRowsWarning",
    "carry_mode",
    "detect_format",
    "read_ilc_trace",
    "read_mag_slam_walk",
    "read_oxford_folder",
    "read_oxford_validation",
    "read_sensor_logger",
    "read_tyrex_folder",
    "register_format",
]
