"""Scoring estimators against the truth: the evaluation protocol, metrics, leaderboards.

* :mod:`~indoorsim.benchmark.evaluation` — the protocol (site context, training
  walks, episodes) and :func:`~indoorsim.benchmark.evaluation.evaluate` /
  :func:`~indoorsim.benchmark.evaluation.evaluate_recording`;
* :mod:`~indoorsim.benchmark.metrics` — per-walk error statistics (DESIGN §10);
* :mod:`~indoorsim.benchmark.leaderboard` — the tables, plots and provenance of ``leaderboards/``;
* :mod:`~indoorsim.benchmark.reproduce` — the papers' own experiments.
"""
