"""Realism: the same statistics on simulated and real phone recordings, side by side.

* :mod:`~indoorsim.benchmark.realism.stats` — signal statistics as pure
  functions of arrays (crest factor, kurtosis, harmonic shares, per-axis RMS,
  walking detection), tested on signals with closed-form answers.
* :mod:`~indoorsim.benchmark.realism.motion` — a recording's walking statistics.
* :mod:`~indoorsim.benchmark.realism.magnetic` — ‖m‖ against the distance walked:
  its amplitude, wavelength bands and correlation length.
* :mod:`~indoorsim.benchmark.realism.radio` — WiFi scans: levels, APs per scan, temporal spread.
* :mod:`~indoorsim.benchmark.realism.light` — the light sensor's spread, dark time and changes.
* :mod:`~indoorsim.benchmark.realism.reference` — the real side, measured and committed.
* :mod:`~indoorsim.benchmark.realism.report` — simulated beside real: ``realism.md``.
"""
