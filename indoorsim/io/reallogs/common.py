"""Helpers shared by the real-log readers: frames, clocks, rates, carry-mode names and the
rows they skip."""

from __future__ import annotations

import csv
import io
import os
import warnings
from collections import Counter
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from indoorsim.io.recording import STREAMS, Recording, RecordingError
from indoorsim.util.errors import IndoorsimWarning

PathLike = str | os.PathLike[str]

NOT_A_NUMBER = "with a field that is not a number"
WRONG_FIELD_COUNT = "with the wrong number of fields"
"""Why :func:`read_csv_columns` skips a row (the keys of ``meta["malformed_rows"]``)."""
NOT_FINITE = "with a reading that is NaN or infinite"
"""Why :func:`finite_rows` skips a row."""

_INT64_MIN, _INT64_MAX = -(2**63), 2**63 - 1


class MalformedRowsWarning(IndoorsimWarning):
    """A real log had rows that could not be read; they were skipped and counted.

    The message names the file and how many rows were skipped for which
    reason; ``meta["malformed_rows"]`` of the recording holds the same counts.
    """


def report_malformed(source: PathLike, malformed: Mapping[str, int]) -> dict[str, int]:
    """Warn (:class:`MalformedRowsWarning`) naming ``source`` and the rows skipped per reason.

    Returns the counts for ``meta["malformed_rows"]``, sorted by reason ({} when none).
    """
    counts = {reason: int(n) for reason, n in sorted(malformed.items()) if n}
    if counts:
        total = sum(counts.values())
        reasons = ", ".join(f"{n} {reason}" for reason, n in counts.items())
        warnings.warn(
            f"{source}: skipped {total} malformed row{'s' if total != 1 else ''} ({reasons})",
            MalformedRowsWarning,
            stacklevel=3,
        )
    return counts


def read_csv_columns(
    text: str,
    columns: Mapping[str, type],
    *,
    header: bool,
    malformed: Counter[str],
    file: str = "",
) -> pd.DataFrame:
    """A CSV file's rows with ``columns`` as int64 (``int``) or float64 (``float``).

    Without ``header``, ``columns`` names every column in order; with it, the
    file's first line names them and ``columns`` types those it lists (the
    others are kept as read). A row that does not have the file's number of
    fields (or that the csv module cannot split), or whose integer or number
    field does not parse (an empty or ``nan`` number is NaN, as pandas reads it;
    an integer must fit in int64), is skipped and counted in ``malformed`` under
    :data:`WRONG_FIELD_COUNT` or :data:`NOT_A_NUMBER`, prefixed with ``file`` when
    given. A clean file is read by pandas alone.
    """
    dtypes = {name: np.int64 if kind is int else np.float64 for name, kind in columns.items()}
    names = None if header else list(columns)
    try:
        with warnings.catch_warnings():
            # Rows all one field too long: pandas would warn and drop the last field;
            # inf in an integer column: it would warn and store garbage.
            warnings.simplefilter("error", pd.errors.ParserWarning)
            warnings.simplefilter("error", RuntimeWarning)
            return pd.read_csv(
                io.StringIO(text),
                header=0 if header else None,
                names=names,
                dtype=dtypes,
                index_col=False,
            )
    except (
        ValueError,
        OverflowError,  # an integer beyond int64
        RuntimeWarning,
        pd.errors.ParserError,
        pd.errors.ParserWarning,
    ):
        pass  # a malformed row somewhere: read row by row below
    rows = []
    unreadable = 0
    # Line by line: a stray carriage return or quote (a csv.Error) spoils its own row only.
    for line in io.StringIO(text, newline=""):
        try:
            row = next(csv.reader([line]), [])
        except csv.Error:
            unreadable += 1
            continue
        if any(f.strip() for f in row):
            rows.append(row)
    if header:
        if not rows:
            return pd.DataFrame(columns=list(columns))
        names, rows = rows[0], rows[1:]
    else:
        names = list(columns)
    kept = [row for row in rows if len(row) == len(names)]
    prefix = f"{file}: " if file else ""
    malformed[prefix + WRONG_FIELD_COUNT] += len(rows) - len(kept) + unreadable
    raw = pd.DataFrame(kept, columns=names, dtype=object)
    bad = pd.Series(False, index=raw.index)
    parsed: dict[str, pd.Series] = {}
    for name, kind in columns.items():
        if name not in raw:
            continue  # the reader says which column a file lacks
        field = raw[name].astype(str).str.strip()
        if kind is int:
            digits = field.str.fullmatch(r"[+-]?[0-9]+").astype(bool)
            ok = pd.Series(
                [
                    d and _INT64_MIN <= int(v) <= _INT64_MAX
                    for d, v in zip(digits, field, strict=True)
                ],
                index=field.index,
                dtype=bool,
            )
            parsed[name] = field.where(ok, "0").astype(np.int64)
        else:
            number = pd.to_numeric(field, errors="coerce")
            ok = number.notna() | field.str.lower().isin(["", "nan"])
            parsed[name] = number.astype(np.float64)
        bad |= ~ok
    malformed[prefix + NOT_A_NUMBER] += int(bad.sum())
    out = raw.assign(**parsed)[~bad]
    return out.reset_index(drop=True)


def finite_rows(
    streams: Mapping[str, pd.DataFrame],
    malformed: Counter[str],
    files: Mapping[str, str] | None = None,
) -> dict[str, pd.DataFrame]:
    """``streams`` without the rows whose readings are NaN or infinite, counted in ``malformed``.

    Only the columns a :class:`~indoorsim.io.recording.Recording` needs finite are
    looked at (not those where NaN means unknown). A skipped row is counted under
    :data:`NOT_FINITE`, prefixed with its file's name from ``files`` (stream → file)
    when given.
    """
    out = {}
    for name, df in streams.items():
        spec = STREAMS.get(name)
        checked = [
            c
            for c in (spec.columns if spec else ())
            if c in df.columns and c not in spec.text and c not in spec.may_be_nan
        ]
        if checked:
            good = np.isfinite(df[checked].to_numpy(dtype=np.float64)).all(axis=1)
            if not good.all():
                prefix = f"{files[name]}: " if files and name in files else ""
                malformed[prefix + NOT_FINITE] += int((~good).sum())
                df = df[good]
        out[name] = df
    return out


def build_recording(
    source: PathLike, streams: dict[str, pd.DataFrame], meta: dict[str, Any]
) -> Recording:
    """``Recording(streams, meta)``, with ``source`` named in any :class:`RecordingError`."""
    try:
        return Recording(streams=streams, meta=meta)
    except RecordingError as err:
        raise RecordingError(f"{source}: {err}") from err


XYZ = ("x", "y", "z")
RATE_STREAMS = (
    "accel",
    "gyro",
    "mag",
    "rotation",
    "game_rotation",
    "gravity",
    "linear_accel",
    "light",
    "wifi",
)

# Carry positions named by the logs → indoorsim carry modes (lower-cased keys).
CARRY_MODES = {
    "inhand": "handheld",
    "hand": "handheld",
    "frontpocket": "pocketed",
    "backpocket": "pocketed",
    "swingingarm": "dangling",
    "swinging": "dangling",
    "texting": "handheld",
    "phoning": "calling",
}


def carry_mode(position: str) -> str:
    """indoorsim's carry mode for a logged carrying position, or the position unchanged.

    >>> carry_mode("FrontPocket"), carry_mode("hand"), carry_mode("Purse")
    ('pocketed', 'handheld', 'Purse')
    """
    return CARRY_MODES.get(position.lower(), position)


def time_frame(t: ArrayLike, columns: dict[str, ArrayLike]) -> pd.DataFrame:
    """A stream DataFrame indexed by float64 ``t``, sorted stably by ``t``."""
    df = pd.DataFrame(columns, index=pd.Index(np.asarray(t, dtype=np.float64), name="t"))
    if not df.index.is_monotonic_increasing:
        df = df.sort_index(kind="stable")
    return df


def ticks_to_seconds(ticks: NDArray[np.int64], t0: int, ticks_per_s: float) -> NDArray[np.float64]:
    # Subtract in integers first: epoch nanoseconds (~1.7e18) do not fit a float64 exactly.
    return (ticks - np.int64(t0)).astype(np.float64) / ticks_per_s


def median_rates_hz(streams: dict[str, pd.DataFrame]) -> dict[str, float]:
    rates = {}
    for name in RATE_STREAMS:
        if name in streams:
            times = np.unique(streams[name].index.to_numpy())
            if len(times) > 1:
                rates[name] = round(float(1.0 / np.median(np.diff(times))), 3)
    return rates


def quaternion_from_rotation_vector(xyz: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N, 4) unit quaternions (w, x, y, z) from Android rotation-vector (x, y, z) rows.

    Android gives x, y, z = sin(θ/2)·axis; w = cos(θ/2) = sqrt(1 − x² − y² − z²),
    clipped at 0 because rounding can push the norm of xyz a hair above 1. Rows
    that are not finite (or too large to square) come back NaN.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        squared = np.sum(xyz**2, axis=1)
        w = np.sqrt(np.clip(1.0 - squared, 0.0, None))
        q = np.column_stack([w, xyz])
        q /= np.linalg.norm(q, axis=1, keepdims=True)
    # A garbage row too large to square is NaN, as a NaN row is: neither is a rotation.
    q[~np.isfinite(squared)] = np.nan
    return q
