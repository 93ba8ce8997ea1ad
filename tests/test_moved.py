"""Modules that moved in the "Architecture" reorganisation keep their old import paths."""

from __future__ import annotations

import importlib
import pickle
import subprocess
import sys

import pytest

from indoorsim._moved import MOVED


@pytest.mark.parametrize(("old", "new"), sorted(MOVED.items()))
def test_an_old_path_gives_the_new_module_with_a_deprecation_warning(old, new):
    # In a fresh interpreter: here the old name may already be bound by another test.
    code = (
        "import importlib, warnings\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    warnings.simplefilter('always')\n"
        f"    old = importlib.import_module({old!r})\n"
        f"new = importlib.import_module({new!r})\n"
        "assert old is new, (old, new)\n"
        "assert old.__spec__.name == new.__name__\n"
        f"assert any({new!r} in str(w.message) and w.category is DeprecationWarning "
        "for w in caught), [str(w.message) for w in caught]\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_the_root_door_names_resolve_on_first_use():
    import indoorsim

    for name in indoorsim.__all__:
        assert getattr(indoorsim, name) is not None
    assert indoorsim.Recording is importlib.import_module("indoorsim.io.recording").Recording
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        _ = indoorsim.nothing


def test_objects_reached_by_an_old_path_pickle_under_their_new_one():
    with pytest.warns(DeprecationWarning, match="indoorsim.io.fingerprints"):
        old = importlib.import_module("indoorsim.fingerprints")
    db = old.FingerprintDB(tables={}, meta={"a": 1})
    assert b"indoorsim.io.fingerprints" in pickle.dumps(db)
