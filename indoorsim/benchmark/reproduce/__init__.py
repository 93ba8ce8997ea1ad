"""The papers' own experiments, reproduced on the bundled sites beside the papers' numbers.

One module per paper (``han2023``, ``chen2022``); the leaderboard command
writes their tables into ``leaderboards/``.
"""
