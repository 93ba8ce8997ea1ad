"""Reading and writing: recordings, real phone logs, fingerprint databases, atomic folders.

* :mod:`~indoorsim.io.recording` — :class:`Recording`, one walk's streams and
  metadata, as a folder of Parquet files with a JSON manifest (DESIGN §7);
* :mod:`~indoorsim.io.formats` — the registry of real log formats, by string
  entry point, that :meth:`Recording.load` consults;
* :mod:`~indoorsim.io.reallogs` — one reader module per real format;
* :mod:`~indoorsim.io.fingerprints` — :class:`FingerprintDB`, a survey's tables;
* :mod:`~indoorsim.io.atomic` — folders written under a temporary name, then renamed;
* :mod:`~indoorsim.io.tum` — trajectories as TUM files (``timestamp tx ty tz qx qy qz
  qw``), for evo and other SLAM tools.
"""

from __future__ import annotations

from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.io.recording import MissingStreamError, Recording, RecordingError

__all__ = ["FingerprintDB", "MissingStreamError", "Recording", "RecordingError"]
