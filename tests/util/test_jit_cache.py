"""Where the compiled kernels are cached, and the first-run message."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numba

from indoorsim.util import jit_cache


def _env(**changes: str | None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR",)}
    for key, value in changes.items():
        if value is None:
            env.pop(key, None)
        else:
            env[key] = value
    return env


def test_the_cache_folder_is_per_user_and_can_be_chosen(monkeypatch, tmp_path):
    monkeypatch.delenv("INDOORSIM_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert jit_cache.cache_dir() == tmp_path / "xdg" / "indoorsim" / "numba"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert jit_cache.cache_dir() == Path.home() / ".cache" / "indoorsim" / "numba"
    monkeypatch.setenv("INDOORSIM_CACHE_DIR", str(tmp_path / "mine"))
    assert jit_cache.cache_dir() == tmp_path / "mine" / "numba"


def test_configure_points_numba_there_unless_the_user_chose(monkeypatch, tmp_path):
    monkeypatch.setattr(numba.config, "CACHE_DIR", numba.config.CACHE_DIR)
    monkeypatch.setenv("INDOORSIM_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    jit_cache.configure()
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "numba")
    assert numba.config.CACHE_DIR == str(tmp_path / "numba")  # numba was already loaded
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/elsewhere")
    jit_cache.configure()
    assert os.environ["NUMBA_CACHE_DIR"] == "/elsewhere"


def test_kernels_compiled_by_a_fresh_process_land_in_the_user_cache(tmp_path):
    code = (
        "import numpy as np, indoorsim, numba\n"
        "from indoorsim.util.quaternion import multiply\n"
        "print(numba.config.CACHE_DIR)\n"
        "multiply(np.array([[1.0, 0, 0, 0]]), np.array([[1.0, 0, 0, 0]]))\n"
    )
    env = _env(XDG_CACHE_HOME=str(tmp_path), INDOORSIM_CACHE_DIR=None)
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    folder = tmp_path / "indoorsim" / "numba"
    assert out.stdout.strip() == str(folder)
    assert any(folder.rglob("*.nbi")), "no cache index written"


def test_the_first_compile_is_announced_once_and_counted(tmp_path):
    code = (
        "import sys, numba\n"
        "from indoorsim.util.jit_cache import announce_compiles\n"
        "summary = announce_compiles(sys.stdout)\n"
        "f = numba.njit(lambda x: x + 1)\n"
        "f(1); f(2.0); f(3)\n"  # two signatures compile; the third call reuses the first
        "summary()\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        env=_env(INDOORSIM_CACHE_DIR=str(tmp_path)),
        capture_output=True,
        text=True,
        check=True,
    ).stdout.splitlines()
    folder = tmp_path / "numba"
    assert out[0] == f"indoorsim: compiling kernels, first run only (cached in {folder}) …"
    assert len(out) == 2 and out[1].startswith("indoorsim: compiled 2 kernels in ")


def test_the_command_line_stays_quiet_when_not_at_a_terminal(capsys):
    """Logs and captured output are unchanged: the announcer is only for terminals."""
    from indoorsim.cli import main

    assert main(["scenarios"]) == 0
    assert "compiling kernels" not in capsys.readouterr().err
