"""FingerprintDB: the fingerprint tables a survey produced, and their files.

Kept apart from :mod:`indoorsim.survey` (which runs the simulator) so that
estimators can read fingerprint databases without importing the simulator.
"""

from __future__ import annotations

import copy
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from indoorsim.io.atomic import write_folder

_DB_FILE = "fingerprints.json"
_FORMAT_VERSION = 1


@dataclass(kw_only=True)
class FingerprintDB:
    """Fingerprint tables of one survey.

    Attributes:
        tables: named tables; each has ``x``, ``y`` (building frame, m) and feature columns.
        meta: JSON-able description: scenario, survey kind, device, spacing, frames, seed.
    """

    tables: dict[str, pd.DataFrame]
    meta: dict[str, Any] = field(default_factory=dict)

    def __getitem__(self, name: str) -> pd.DataFrame:
        if name not in self.tables:
            raise KeyError(
                f"fingerprint database has no table {name!r}; tables are {sorted(self.tables)}"
            )
        return self.tables[name]

    def copy(self) -> FingerprintDB:
        """A deep copy: tables and metadata can be changed without touching this one."""
        return FingerprintDB(
            tables={name: df.copy(deep=True) for name, df in self.tables.items()},
            meta=copy.deepcopy(self.meta),
        )

    def save(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
        """Write the tables as Parquet files plus ``fingerprints.json``, atomically."""

        def write(folder: Path) -> None:
            for name, df in self.tables.items():
                df.to_parquet(folder / f"{name}.parquet", index=False)
            doc = {"format_version": _FORMAT_VERSION, "tables": sorted(self.tables), **self.meta}
            (folder / _DB_FILE).write_text(json.dumps(doc, indent=2, allow_nan=False) + "\n")

        return write_folder(
            Path(path),
            write,
            overwrite=overwrite,
            is_ours=_is_db_folder,
            what="fingerprint database",
        )

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> FingerprintDB:
        """Read a folder written by :meth:`save`."""
        folder = Path(path)
        if not _is_db_folder(folder):
            raise FileNotFoundError(
                f"{folder} is not an indoorsim fingerprint database (no {_DB_FILE})"
            )
        doc = json.loads((folder / _DB_FILE).read_text())
        names = doc.pop("tables")
        doc.pop("format_version")
        return cls(tables={n: pd.read_parquet(folder / f"{n}.parquet") for n in names}, meta=doc)


def _is_db_folder(path: Path) -> bool:
    return (path / _DB_FILE).is_file()
