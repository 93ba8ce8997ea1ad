"""Where things are and which code made them: the repository, the real-data folder, the revision.

Paths outside the package come from an argument or an environment variable;
the repository's sibling ``shared/realdata`` (this project's development
layout) is only the last default.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

__all__ = ["OUTPUTS", "REALDATA_ENV", "REPO", "git_revision", "realdata_dir"]

REPO = Path(__file__).resolve().parents[2]
"""The source tree this package runs from (for an installed wheel: site-packages)."""

REALDATA_ENV = "INDOORSIM_REALDATA"
"""Environment variable naming the folder of real recordings (``../shared/realdata``'s layout)."""


def realdata_dir(path: str | os.PathLike[str] | None = None) -> Path:
    """The real-data folder: ``path``, else ``$INDOORSIM_REALDATA``, else ``../shared/realdata``.

    The folder need not exist: callers skip what it lacks (a wheel installed
    without the shared folder has no real data).
    """
    if path is not None:
        return Path(path)
    env = os.environ.get(REALDATA_ENV)
    if env:
        return Path(env)
    return REPO.parent / "shared" / "realdata"


OUTPUTS = ("leaderboards",)
"""Folders of generated results: a run that rewrites them is not made "dirty" by it."""


def git_revision() -> str:
    """The repository's commit, with ``-dirty`` for local changes to its code, or ``unknown``.

    Changes under :data:`OUTPUTS` do not count: the leaderboard command rewrites
    ``leaderboards/`` while it runs, and asks for the revision after it began.
    """

    def git(*args: str) -> str:
        return subprocess.run(
            ["git", "-C", str(REPO), *args], capture_output=True, text=True, check=True, timeout=10
        ).stdout.strip()

    try:
        rev = git("rev-parse", "--short=12", "HEAD")
        excluded = [f":(exclude){folder}" for folder in OUTPUTS]
        changed = git("status", "--porcelain", "--untracked-files=no", "--", ".", *excluded)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    if not rev:
        return "unknown"
    return f"{rev}-dirty" if changed else rev
