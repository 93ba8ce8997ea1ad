"""Where numba keeps indoorsim's compiled kernels, and saying so while it compiles them.

The kernels are compiled on first use and cached on disk (``cache=True``).
numba's default cache sits beside each source file, in the source tree (or
in site-packages); :func:`configure` moves it to one folder per user instead,
so a source tree stays clean and a read-only install still caches:

* ``$INDOORSIM_CACHE_DIR/numba`` if that variable is set,
* else ``$XDG_CACHE_HOME/indoorsim/numba``, ``%LOCALAPPDATA%\\indoorsim\\numba``
  on Windows, or ``~/.cache/indoorsim/numba``.

A ``NUMBA_CACHE_DIR`` the user set wins. numba keys each cached function by
its source file's path and time stamp, so two checkouts never share or
spoil each other's entries.

A first run compiles for tens of seconds with nothing else to show;
:func:`announce_compiles` (the command line installs it) prints one line
when the first kernel of a process starts compiling, and how many were
compiled, in how long, when the process ends. Only real compiles are
counted: numba raises no event for a kernel loaded from the cache.
"""

from __future__ import annotations

import atexit
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

__all__ = ["announce_compiles", "cache_dir", "configure"]


def cache_dir() -> Path:
    """The folder of indoorsim's compiled kernels (module docstring)."""
    root = os.environ.get("INDOORSIM_CACHE_DIR")
    if root:
        return Path(root) / "numba"
    if sys.platform == "win32" and os.environ.get("LOCALAPPDATA"):
        base = Path(os.environ["LOCALAPPDATA"])
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "indoorsim" / "numba"


def configure() -> None:
    """Point numba's cache at :func:`cache_dir` unless the user chose one.

    Call before any module with cached kernels is imported (``import
    indoorsim`` does): numba picks each function's cache folder when it is
    decorated. Cheap: it imports numba only if numba is already loaded.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    folder = str(cache_dir())
    os.environ["NUMBA_CACHE_DIR"] = folder  # read by numba on import, and by child processes
    numba = sys.modules.get("numba")
    if numba is not None:
        numba.config.CACHE_DIR = folder


_installed = False


def announce_compiles(stream: TextIO | None = None) -> Callable[[], None]:
    """Tell the user when kernels compile in this process (module docstring).

    Prints, at the first compile, "compiling kernels, first run only (cached
    in …)"; the returned function prints the count and the time spent, and
    is registered to run at exit when the first call's ``stream`` is None
    (stderr at the time of printing). The listener is installed once per
    process; later calls return a summary of the same counts.
    """
    global _installed
    from numba.core import event

    def write(text: str) -> None:
        print(text, file=stream if stream is not None else sys.stderr, flush=True)

    state = _STATE

    def summary() -> None:
        if state["count"]:
            write(
                f"indoorsim: compiled {state['count']} kernels in {state['seconds']:.0f} s; "
                "the next runs load them from the cache"
            )

    if not _installed:
        _installed = True

        class _Announcer(event.Listener):
            def on_start(self, ev: event.Event) -> None:
                if state["depth"] == 0:
                    if state["count"] == 0:
                        write(
                            "indoorsim: compiling kernels, first run only "
                            f"(cached in {cache_dir()}) …"
                        )
                    state["started"] = time.perf_counter()
                state["depth"] += 1

            def on_end(self, ev: event.Event) -> None:
                state["depth"] -= 1
                state["count"] += 1
                if state["depth"] == 0:
                    state["seconds"] += time.perf_counter() - state["started"]

        event.register("numba:compile", _Announcer())
        if stream is None:
            atexit.register(summary)

    return summary


# Counts of this process's compiles: kernels (nested ones included), the nesting
# depth now, when the outermost compile began, and the seconds spent.
_STATE: dict[str, float] = {"count": 0, "depth": 0, "started": 0.0, "seconds": 0.0}
