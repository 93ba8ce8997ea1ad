"""Property tests of recording folders: a simulated walk saved, then one file damaged.

Damage is a cut, bytes inserted or overwritten, a file deleted, or a manifest whose
JSON is changed (a value of another type, a key deleted, a stream entry that names
another file). ``Recording.load`` then gives a valid recording or a
:class:`RecordingError` naming the folder or the file: never another exception.
"""

from __future__ import annotations

import functools
import json
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import indoorsim
from indoorsim.io.recording import MANIFEST, Recording, RecordingError
from indoorsim.simulate import simulate
from tests.conftest import SWEEP


@functools.cache
def saved_walk() -> dict[str, bytes]:
    """The files of a short simulated walk's recording folder, by name."""
    site = indoorsim.load_site("minimal_room")
    rec = simulate(site, route="main", device="ideal", seed=2, duration_s=2.0)
    with tempfile.TemporaryDirectory() as tmp:
        folder = rec.save(Path(tmp) / "walk")
        return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def _json_values() -> st.SearchStrategy[Any]:
    return st.recursive(
        st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
        lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=6), inner),
        max_leaves=4,
    )


def _paths(tree: Any, path: tuple = ()) -> list[tuple]:
    out = [path]
    if isinstance(tree, dict):
        for key, value in tree.items():
            out += _paths(value, (*path, key))
    elif isinstance(tree, list):
        for i, value in enumerate(tree):
            out += _paths(value, (*path, i))
    return out


def _set(tree: Any, path: tuple, value: Any, *, delete: bool = False) -> Any:
    if not path:
        return value
    head, rest = path[0], path[1:]
    copy = dict(tree) if isinstance(tree, dict) else list(tree)
    if delete and not rest:
        del copy[head]
    else:
        copy[head] = _set(copy[head], rest, value, delete=delete)
    return copy


@st.composite
def damaged_folders(draw: st.DrawFn) -> dict[str, bytes]:
    """The saved walk's files with one of them damaged (or gone)."""
    files = dict(saved_walk())
    name = draw(st.sampled_from(sorted(files)))
    data = files[name]
    kinds = ["cut", "insert", "overwrite", "delete"] + (["json"] * 3 if name == MANIFEST else [])
    kind = draw(st.sampled_from(kinds))
    if kind == "delete":
        del files[name]
    elif kind == "cut":
        files[name] = data[: draw(st.integers(0, len(data) - 1))]
    elif kind in ("insert", "overwrite"):
        at = draw(st.integers(0, len(data)))
        new = draw(st.binary(min_size=1, max_size=16))
        files[name] = data[:at] + new + data[at + (len(new) if kind == "overwrite" else 0) :]
    else:
        manifest = json.loads(data)
        path = draw(st.sampled_from(_paths(manifest)))
        if path and draw(st.booleans()):
            manifest = _set(manifest, path, None, delete=True)
        else:
            manifest = _set(manifest, path, draw(_json_values()))
        files[name] = json.dumps(manifest).encode()
    return files


def _load_damaged(folder: Path, files: dict[str, bytes]) -> None:
    folder.mkdir()
    for name, data in files.items():
        (folder / name).write_bytes(data)
    try:
        rec = Recording.load(folder)
    except RecordingError as err:
        assert str(folder) in str(err), err
        return
    rec.validate()


def _with_manifest(change: Callable[[dict[str, Any]], None]) -> dict[str, bytes]:
    """The saved walk with its manifest changed in place by ``change``."""
    files = dict(saved_walk())
    manifest = json.loads(files[MANIFEST])
    change(manifest)
    return {**files, MANIFEST: json.dumps(manifest).encode()}


# What hypothesis found (TypeError, AttributeError, UnicodeDecodeError), and a path
# that would have led out of the folder.
@given(files=damaged_folders())
@example(files=_with_manifest(lambda m: m["streams"][0].update(file=["accel.parquet"])))
@example(files=_with_manifest(lambda m: m["streams"][0].update(columns=[])))
@example(files=_with_manifest(lambda m: m["streams"][0].update(name={"a": 1})))
@example(files=_with_manifest(lambda m: m["streams"][0].update(file="../walk/accel.parquet")))
@example(files={**saved_walk(), MANIFEST: saved_walk()[MANIFEST].replace(b"{", b"{\x8c", 1)})
def test_a_damaged_recording_folder_loads_or_is_a_recording_error_naming_it(
    tmp_path_factory, files
):
    folder = tmp_path_factory.mktemp("damaged") / "walk"
    try:
        _load_damaged(folder, files)
    finally:
        shutil.rmtree(folder.parent)


@pytest.mark.slow
@settings(SWEEP)
@given(files=damaged_folders())
def test_a_damaged_recording_folder_sweep(tmp_path_factory, files):
    folder = tmp_path_factory.mktemp("damaged") / "walk"
    try:
        _load_damaged(folder, files)
    finally:
        shutil.rmtree(folder.parent)


def test_the_undamaged_walk_loads_as_saved(tmp_path):
    files = saved_walk()
    assert MANIFEST in files and "accel.parquet" in files
    _load_damaged(tmp_path / "walk", files)


def test_a_parquet_file_with_damaged_pandas_metadata_is_a_recording_error(tmp_path):
    # Was: pandas' KeyError 'numpy_type' from the schema metadata it stores in the file.
    import pyarrow.parquet as pq

    files = dict(saved_walk())
    folder = tmp_path / "walk"
    folder.mkdir()
    for name, data in files.items():
        (folder / name).write_bytes(data)
    table = pq.read_table(folder / "accel.parquet")
    pandas_meta = json.loads(table.schema.metadata[b"pandas"])
    del pandas_meta["columns"][0]["numpy_type"]
    table = table.replace_schema_metadata({b"pandas": json.dumps(pandas_meta).encode()})
    pq.write_table(table, folder / "accel.parquet")
    with pytest.raises(RecordingError, match=r"accel\.parquet: stream 'accel' cannot be read"):
        Recording.load(folder)
