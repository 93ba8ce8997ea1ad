"""Where things are and which code made them: the repository, the real-data folder, the revision.

Paths outside the package come from an argument or an environment variable;
the repository's sibling ``shared/realdata`` (this project's development
layout) is only the last default.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

__all__ = ["REALDATA_ENV", "REPO", "git_revision", "realdata_dir"]

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


def git_revision() -> str:
    """The repository's commit (with ``-dirty`` for local changes), or ``unknown``."""
    try:
        rev = subprocess.run(
            ["git", "-C", str(REPO), "describe", "--always", "--dirty", "--abbrev=12"],
            capture_output=True,
            text=True,
            check=True,
            timeout=10,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return rev or "unknown"
