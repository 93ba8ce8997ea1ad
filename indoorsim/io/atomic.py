"""Atomic writes of output folders: complete or absent, never half written.

A folder is written under a hidden temporary sibling name and renamed into
place (a rename within one file system is atomic). Replacing an existing folder
first renames the old one aside, so a failure leaves the old folder or the new
one, never a mixture. Recordings, fingerprint databases and data-set shards all
go through :func:`write_folder`.
"""

from __future__ import annotations

import secrets
import shutil
from collections.abc import Callable
from pathlib import Path


def write_folder(
    target: Path,
    write: Callable[[Path], None],
    *,
    overwrite: bool,
    is_ours: Callable[[Path], bool],
    what: str,
) -> Path:
    """Create the folder ``target`` by calling ``write(tmp_folder)``, atomically.

    Args:
        target: the folder to create.
        write: fills the (empty, existing) temporary folder it is given.
        overwrite: replace an existing folder for which ``is_ours`` holds.
        is_ours: recognises a folder this writer may replace.
        what: the kind of folder, for error messages ("recording", ...).

    Raises:
        FileExistsError: ``target`` holds one of ours and ``overwrite`` is False,
            or holds anything else (a file, a non-empty foreign folder).
    """
    if target.exists() or target.is_symlink():
        if is_ours(target):
            if not overwrite:
                raise FileExistsError(
                    f"{target} already holds a {what}; pass overwrite=True to replace it"
                )
        elif not (target.is_dir() and not target.is_symlink() and not any(target.iterdir())):
            raise FileExistsError(
                f"{target} exists and is not an indoorsim {what}; refusing to overwrite it"
            )
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = sibling(target, "partial")
    tmp.mkdir()  # not tempfile.mkdtemp: its 0700 mode would outlive the rename
    try:
        write(tmp)
        replace_folder(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return target


def sibling(target: Path, purpose: str) -> Path:
    """An unused hidden name beside ``target`` (same file system, so renames are atomic)."""
    while True:
        candidate = target.with_name(f".{target.name}.{secrets.token_hex(4)}.{purpose}")
        if not candidate.exists():
            return candidate


def replace_folder(new: Path, target: Path) -> None:
    """Move the finished folder ``new`` to ``target``, replacing what is there."""
    if not target.exists():
        new.rename(target)
        return
    aside = sibling(target, "old")
    target.rename(aside)
    try:
        new.rename(target)
    except BaseException:
        aside.rename(target)
        raise
    shutil.rmtree(aside, ignore_errors=True)
