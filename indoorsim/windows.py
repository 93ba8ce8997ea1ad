"""Observation windows: a recording's sensor streams cut into fixed-size pieces.

This is the one place where streams become what an estimator sees, shared by
the Gymnasium environment, the real-data runner and the data-set writer. It
reads only sensor streams — never ``truth``, ``steps`` or ``waypoints``.

A window is ``samples`` consecutive accelerometer samples (the IMU clock sets
the pace: a fixed length at the IMU rate). Every other stream is aligned to
those timestamps by sample-and-hold (the latest sample at or before each IMU
time; zeros, or the identity rotation, before a stream's first sample) with a
``*_fresh`` mask marking where a new sample arrived, so the slower sensors'
timing is not lost. WiFi is a vector over the site's BSSIDs:
the latest scan at or before the window's end, which APs it heard, whether it
arrived during this window, and its age. A stream the recording lacks (real
logs without light, say) is zeros with its fresh mask all zero, and
``present`` says which streams exist. The last window of a recording may be
short: ``valid`` marks its real samples and the padding repeats the last one.

Observation keys and shapes (W = samples, A = number of APs):

=================  =========  ==============================================
key                shape      meaning
=================  =========  ==============================================
``t``              (W,)       IMU sample times, s from the recording start
``valid``          (W,)       1 for real samples, 0 for padding
``accel``          (W, 3)     specific force, phone frame, m/s²
``gyro``           (W, 3)     angular rate, phone frame, rad/s
``mag``            (W, 3)     magnetic field, phone frame, µT
``mag_fresh``      (W,)       1 where a new magnetometer sample arrived
``rotation``       (W, 4)     fused rotation vector (w, x, y, z), world←phone
``game_rotation``  (W, 4)     fused game rotation vector
``gravity``        (W, 3)     fused gravity, phone frame, m/s²
``light``          (W,)       illuminance, lux
``light_fresh``    (W,)       1 where a light event arrived
``wifi_rss``       (A,)       latest scan's RSS per AP, dBm (``NO_SIGNAL_DBM`` if unheard)
``wifi_heard``     (A,)       1 where the latest scan heard the AP
``wifi_fresh``     (1,)       1 if a scan arrived during this window
``wifi_age``       (1,)       seconds since the latest scan (``MAX_AGE_S`` if none yet)
``present``        (7,)       1 per stream present: gyro, mag, rotation, light, wifi,
                             gravity, game_rotation
=================  =========  ==============================================
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import gymnasium as gym
import numba
import numpy as np
import pandas as pd
from numpy.typing import NDArray

from indoorsim.io.recording import Recording

NO_SIGNAL_DBM = -110.0
MAX_AGE_S = 3600.0
# Appended, never reordered: estimators index the flags by these names.
PRESENT_ORDER = ("gyro", "mag", "rotation", "light", "wifi", "gravity", "game_rotation")

Observation = dict[str, NDArray]


def observation_space(samples: int, n_aps: int) -> gym.spaces.Dict:
    """The Gymnasium space of one observation window."""
    big = np.float64(1e9)

    def box(shape: tuple[int, ...], low: float = -big, high: float = big) -> gym.spaces.Box:
        return gym.spaces.Box(low=low, high=high, shape=shape, dtype=np.float64)

    w = samples
    return gym.spaces.Dict(
        {
            "t": box((w,), 0.0),
            "valid": gym.spaces.MultiBinary(w),
            "accel": box((w, 3)),
            "gyro": box((w, 3)),
            "mag": box((w, 3)),
            "mag_fresh": gym.spaces.MultiBinary(w),
            "rotation": box((w, 4), -1.0, 1.0),
            "game_rotation": box((w, 4), -1.0, 1.0),
            "gravity": box((w, 3)),
            "light": box((w,), 0.0),
            "light_fresh": gym.spaces.MultiBinary(w),
            "wifi_rss": box((n_aps,), -200.0, 50.0),
            "wifi_heard": gym.spaces.MultiBinary(n_aps),
            "wifi_fresh": gym.spaces.MultiBinary(1),
            "wifi_age": box((1,), 0.0, MAX_AGE_S),
            "present": gym.spaces.MultiBinary(len(PRESENT_ORDER)),
        }
    )


def columns_array(df: pd.DataFrame, names: list[str]) -> NDArray[np.float64]:
    """``df[names].to_numpy(dtype=float)``, without pandas' column-list selection.

    Adjacent columns are sliced by position: a view of the frame's block when
    they share one (a stream's own x, y, z; the truth stream's floats), where
    the selection would copy; other columns are stacked.
    """
    at = [df.columns.get_loc(name) for name in names]
    if all(isinstance(k, int) for k in at) and at == list(range(at[0], at[0] + len(at))):
        return df.iloc[:, at[0] : at[0] + len(at)].to_numpy(dtype=float)
    return np.stack([df[name].to_numpy(dtype=float) for name in names]).T


def hold_index(t_src: NDArray[np.float64], t_dst: NDArray[np.float64]) -> NDArray[np.intp]:
    """Index of the latest source sample at or before each destination time (−1: none yet).

    ``t_src`` must be sorted (a stream's ``t``). For sorted ``t_dst`` as well
    (another stream's ``t``) one merge pass replaces a binary search per time.
    """
    t_src = np.ascontiguousarray(t_src, dtype=np.float64)
    t_dst = np.ascontiguousarray(t_dst, dtype=np.float64)
    if len(t_dst) > 1 and (t_dst[1:] < t_dst[:-1]).any():
        return np.searchsorted(t_src, t_dst, side="right") - 1
    return _merge_hold(t_src, t_dst)


@numba.njit(cache=True, error_model="numpy")
def _held_rows(src, idx, unknown):  # pragma: no cover - compiled
    """``src[idx]`` row by row, ``unknown`` where ``idx`` is −1 (no sample yet)."""
    out = np.empty((idx.shape[0], src.shape[1]))
    for i in range(idx.shape[0]):
        j = idx[i]
        if j >= 0:
            for k in range(src.shape[1]):
                out[i, k] = src[j, k]
        else:
            for k in range(src.shape[1]):
                out[i, k] = unknown[k]
    return out


@numba.njit(cache=True, error_model="numpy")
def _merge_hold(t_src, t_dst):  # pragma: no cover - compiled
    """:func:`hold_index` of sorted times: ``searchsorted(t_src, t_dst, "right") - 1``."""
    out = np.empty(t_dst.shape[0], np.intp)
    j = 0
    for i in range(t_dst.shape[0]):
        while j < t_src.shape[0] and t_src[j] <= t_dst[i]:
            j += 1
        out[i] = j - 1
    return out


class Windower:
    """Cuts a recording into observation windows (see the module docstring).

    Args:
        recording: the walk (simulated or real); needs an ``accel`` stream.
        samples: IMU samples per window.
        bssids: the APs, in the order of the WiFi vectors.

    Attributes:
        t: (n,) the IMU sample times.
        aligned: every per-sample key of the observation table but ``t`` and
            ``valid``, as one (n, ...) array over all IMU samples, before it is
            cut into windows (the data-set writer cuts overlapping windows from it).
            Read-only: the streams on the IMU clock (accel, and as a rule gyro
            and the fused streams) are views of the recording's columns, not
            copies. (Observations from :meth:`window` are fresh arrays.)
    """

    def __init__(self, recording: Recording, samples: int, bssids: Sequence[str]):
        if samples < 1:
            raise ValueError(f"samples per window must be ≥ 1, got {samples}")
        self.samples = samples
        self.bssids = tuple(bssids)
        streams = recording.streams
        if "accel" not in streams or len(streams["accel"]) == 0:
            raise ValueError("an observation window needs an 'accel' stream with samples")
        accel = streams["accel"]
        self.t = accel.index.to_numpy(dtype=float)
        n = len(self.t)
        self.present = np.array(
            [int(name in streams and len(streams[name]) > 0) for name in PRESENT_ORDER], np.int8
        )
        aligned: dict[str, NDArray] = {"accel": columns_array(accel, ["x", "y", "z"])}
        # The gyroscope and the fused streams run on the IMU clock itself, as a
        # rule: on strictly increasing times each sample holds its own, so their
        # aligned values are their columns, with no search and no gather.
        distinct = bool((self.t[1:] > self.t[:-1]).all())
        for name, cols, width in (
            ("gyro", ["x", "y", "z"], 3),
            ("mag", ["x", "y", "z"], 3),
            ("rotation", ["qw", "qx", "qy", "qz"], 4),
            ("game_rotation", ["qw", "qx", "qy", "qz"], 4),
            ("gravity", ["x", "y", "z"], 3),
            ("light", ["lux"], 1),
        ):
            # Before a stream's first sample nothing is known yet: zeros, or the
            # identity rotation rather than an invalid zero quaternion (never the
            # later first sample, which would look into the future).
            unknown = np.zeros(width)
            if name in ("rotation", "game_rotation"):
                unknown[0] = 1.0
            df = streams.get(name)
            timed = name in ("mag", "light")  # the slow sensors: their timing matters
            if df is not None and len(df):
                t_src = df.index.to_numpy(dtype=float)
                if distinct and len(t_src) == n and np.array_equal(t_src, self.t):
                    idx = np.arange(n)  # each IMU sample holds its own
                    values = columns_array(df, cols)
                else:
                    idx = hold_index(t_src, self.t)
                    values = _held_rows(columns_array(df, cols), idx, unknown)
                if timed:
                    fresh = (idx > np.r_[-1, idx[:-1]]).astype(np.int8)
            else:
                values = np.tile(unknown, (n, 1))
                fresh = np.zeros(n, dtype=np.int8)
            aligned[name] = values[:, 0] if width == 1 else values
            if timed:
                aligned[f"{name}_fresh"] = fresh
        for values in aligned.values():
            values.flags.writeable = False  # some are views of the recording's columns
        self.aligned = aligned
        self._scan_t, self._scan_rss, self._scan_heard = self._scans(streams.get("wifi"))
        self._n_windows = -(-n // samples)
        self._cut: dict[str, NDArray] | None = None

    @property
    def _blocks(self) -> dict[str, NDArray]:
        """Every window, cut once on first use, so that window(k) only copies: an
        environment step or an estimator's loop costs a few microseconds. (The
        data-set writer cuts its own windows from ``aligned`` and never needs these.)"""
        if self._cut is None:
            n, samples = len(self.t), self.samples
            slot = np.arange(self._n_windows * samples)
            at = np.minimum(slot, n - 1)  # the last window's padding repeats its last sample
            shape = (self._n_windows, samples)
            blocks: dict[str, NDArray] = {
                "t": self.t[at].reshape(shape),
                "valid": (slot < n).astype(np.int8).reshape(shape),
            }
            for name, values in self.aligned.items():
                blocks[name] = values[at].reshape(shape + values.shape[1:])
            first = np.arange(self._n_windows) * samples
            last = np.minimum(first + samples, n) - 1
            blocks.update(self.wifi_windows(first, last))
            self._cut = blocks
        return self._cut

    def wifi_windows(self, first: NDArray[np.intp], last: NDArray[np.intp]) -> dict[str, NDArray]:
        """The WiFi entries of windows spanning IMU samples ``first[k]..last[k]``.

        Each window gets the latest scan at or before its last sample; the scan
        is fresh when it arrived after the sample before the window's first
        (any time, for a window starting at sample 0). Windows may overlap.

        Returns:
            ``wifi_rss`` and ``wifi_heard`` of shape (N, A), ``wifi_fresh`` and
            ``wifi_age`` of shape (N, 1), for N windows and A APs.
        """
        scan_t, rss, heard = self._scan_t, self._scan_rss, self._scan_heard
        n_windows = len(first)
        t_end = self.t[last]
        t_prev = np.where(first > 0, self.t[np.maximum(first - 1, 0)], -np.inf)
        s = np.searchsorted(scan_t, t_end, side="right") - 1
        got = s >= 0
        out = {
            "wifi_rss": np.full((n_windows, len(self.bssids)), NO_SIGNAL_DBM),
            "wifi_heard": np.zeros((n_windows, len(self.bssids)), np.int8),
            "wifi_fresh": np.zeros((n_windows, 1), np.int8),
            "wifi_age": np.full((n_windows, 1), MAX_AGE_S),
        }
        out["wifi_rss"][got] = rss[s[got]]
        out["wifi_heard"][got] = heard[s[got]]
        out["wifi_fresh"][got, 0] = scan_t[s[got]] > t_prev[got]
        out["wifi_age"][got, 0] = np.minimum(t_end[got] - scan_t[s[got]], MAX_AGE_S)
        return out

    def _scans(
        self, wifi: object
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int8]]:
        """Scan times (S,), RSS (S, A) and heard flags (S, A)."""
        a = len(self.bssids)
        if wifi is None or not len(wifi):  # type: ignore[arg-type]
            return np.zeros(0), np.zeros((0, a)), np.zeros((0, a), np.int8)
        col = {b: k for k, b in enumerate(self.bssids)}
        ts = wifi.index.to_numpy(dtype=float)  # type: ignore[attr-defined]
        scan_t, scan_of_row = np.unique(ts, return_inverse=True)
        rss = np.full((len(scan_t), a), NO_SIGNAL_DBM)
        heard = np.zeros((len(scan_t), a), np.int8)
        # Each row's AP column, −1 for an AP outside the site's list (get_indexer's
        # −1 picks the appended −1): one lookup of the whole column, not one per row.
        found = pd.Index(list(col)).get_indexer(wifi["bssid"])  # type: ignore[index]
        ap = np.append(np.fromiter(col.values(), np.intp, len(col)), -1)[found]
        keep = ap >= 0  # APs outside the site's list are ignored
        rss[scan_of_row[keep], ap[keep]] = wifi["rss"].to_numpy(dtype=float)[keep]  # type: ignore[index]
        heard[scan_of_row[keep], ap[keep]] = 1
        return scan_t, rss, heard

    def __len__(self) -> int:
        return self._n_windows

    def end_time(self, k: int) -> float:
        """Time of window k's last real sample, s."""
        return float(self.t[min((k + 1) * self.samples, len(self.t)) - 1])

    def window(self, k: int) -> Observation:
        """Observation k (0-based): fresh arrays, which the caller may keep or modify."""
        if not 0 <= k < self._n_windows:
            raise IndexError(f"window {k} out of range: the recording has {len(self)} windows")
        obs = {name: block[k].copy() for name, block in self._blocks.items()}
        obs["present"] = self.present.copy()
        return obs

    def __iter__(self) -> Iterator[Observation]:
        for k in range(len(self)):
            yield self.window(k)
