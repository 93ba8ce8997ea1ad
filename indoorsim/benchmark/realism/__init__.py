"""Realism: the same statistics on simulated and real phone recordings, side by side.

* :mod:`~indoorsim.benchmark.realism.stats` — signal statistics as pure
  functions of arrays (crest factor, kurtosis, harmonic shares, per-axis RMS,
  walking detection), tested on signals with closed-form answers.
"""
