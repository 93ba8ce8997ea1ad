"""The revision a result records: a regenerated leaderboard is not "dirty" code."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from indoorsim.util import provenance

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def _git(repo: Path, *args: str) -> str:
    return subprocess.run(
        ["git", "-C", str(repo), *args], capture_output=True, text=True, check=True
    ).stdout.strip()


def test_changed_outputs_leave_the_revision_clean_and_changed_code_does_not(tmp_path, monkeypatch):
    repo = tmp_path / "repo"
    (repo / "leaderboards").mkdir(parents=True)
    (repo / "code.py").write_text("x = 1\n")
    (repo / "leaderboards" / "board.md").write_text("| a |\n")
    _git(repo, "init", "-q")
    _git(repo, "add", ".")
    _git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "init")
    monkeypatch.setattr(provenance, "REPO", repo)
    head = _git(repo, "rev-parse", "--short=12", "HEAD")
    assert provenance.git_revision() == head
    (repo / "leaderboards" / "board.md").write_text("| b |\n")  # a run rewrote its board
    assert provenance.git_revision() == head
    (repo / "code.py").write_text("x = 2\n")
    assert provenance.git_revision() == f"{head}-dirty"
    monkeypatch.setattr(provenance, "REPO", tmp_path / "not-a-repo")
    assert provenance.git_revision() == "unknown"
