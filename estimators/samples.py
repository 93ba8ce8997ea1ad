"""Sensor samples that are not numbers, read as the samples a phone did not deliver.

A faulty driver can report NaN or ±inf (the ``nan_burst`` fault of
:mod:`indoorsim.io.faults`); one such value in a filter's state would poison
every later estimate. :class:`SampleGuard` turns a window into one whose every
value is finite, by the meaning each stream's layout already has
(:mod:`indoorsim.windows`):

* an IMU row (``accel``, ``gyro``) with a value that is not finite is a lost
  sample: its ``valid`` flag is cleared, so estimators skip it exactly as they
  skip a sample dropped by the phone; its values are replaced by finite ones
  only so that arithmetic on the whole array stays quiet;
* ``mag`` and ``light`` are sample-and-hold with a freshness mask: a bad
  sample is not fresh, and the value held is the stream's last finite one
  (from this window or an earlier one);
* the fused ``rotation``, ``game_rotation`` and ``gravity`` hold their last
  finite sample (the identity rotation, zero gravity, before any);
* a WiFi RSS that is not finite is an AP not heard.

A window with nothing to replace is returned as it is (no copy).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from indoorsim.windows import NO_SIGNAL_DBM, Observation

__all__ = ["SampleGuard"]

_IMU = ("accel", "gyro")
_HELD_FRESH = (("mag", "mag_fresh"), ("light", "light_fresh"))
_HELD = ("rotation", "game_rotation", "gravity")
_BEFORE_ANY = {"rotation": (1.0, 0.0, 0.0, 0.0), "game_rotation": (1.0, 0.0, 0.0, 0.0)}


def _bad_rows(values: NDArray[np.float64]) -> NDArray[np.bool_]:
    finite = np.isfinite(values)
    return ~(finite.all(axis=1) if values.ndim == 2 else finite)


class SampleGuard:
    """Makes every value of a window finite, remembering each held stream's last good sample.

    Call :meth:`reset` at each episode's start, then the guard on each window
    in order (module docstring: what is replaced by what).

    Example:
        >>> from indoorsim.windows import observation_space
        >>> obs = {k: np.zeros(v.shape) for k, v in observation_space(4, 2).spaces.items()}
        >>> obs["valid"][:] = 1
        >>> obs["accel"][1] = np.nan
        >>> clean = SampleGuard()(obs)
        >>> clean["valid"].tolist(), bool(np.isfinite(clean["accel"]).all())
        ([1.0, 0.0, 1.0, 1.0], True)
    """

    def __init__(self) -> None:
        self._last: dict[str, NDArray[np.float64]] = {}

    def reset(self) -> None:
        """Forget the held samples (a new walk)."""
        self._last = {}

    def __call__(self, obs: Observation) -> Observation:
        """``obs`` with every value finite (the same object when nothing had to change)."""
        out: Observation | None = None

        def copy() -> Observation:
            nonlocal out
            if out is None:
                out = dict(obs)
            return out

        # A key a hand-made window leaves out is simply not looked at.
        imu = [key for key in _IMU if key in obs]
        lost = np.zeros(len(obs["valid"]), dtype=bool)
        for key in imu:
            lost |= _bad_rows(obs[key])
        if lost.any():
            o = copy()
            o["valid"] = np.where(lost, 0, obs["valid"]).astype(obs["valid"].dtype)
            for key in imu:
                o[key] = np.where(np.isfinite(obs[key]), obs[key], 0.0)
        for key, fresh in _HELD_FRESH:
            if key not in obs:
                continue
            bad = _bad_rows(obs[key])
            if bad.any():
                o = copy()
                o[key] = self._hold(key, obs[key], bad)
                o[fresh] = np.where(bad, 0, obs[fresh]).astype(obs[fresh].dtype)
            self._remember(key, obs[key], bad)
        for key in _HELD:
            if key not in obs:
                continue
            bad = _bad_rows(obs[key])
            if bad.any():
                copy()[key] = self._hold(key, obs[key], bad)
            self._remember(key, obs[key], bad)
        rss = obs.get("wifi_rss")
        if rss is not None and not np.isfinite(rss).all():
            o = copy()
            heard = np.isfinite(rss)
            o["wifi_rss"] = np.where(heard, rss, NO_SIGNAL_DBM)
            o["wifi_heard"] = np.where(heard, obs["wifi_heard"], 0).astype(obs["wifi_heard"].dtype)
        return obs if out is None else out

    def _hold(
        self, key: str, values: NDArray[np.float64], bad: NDArray[np.bool_]
    ) -> NDArray[np.float64]:
        """``values`` with each bad row replaced by the last good one before it."""
        good = np.flatnonzero(~bad)
        # Index of the last good row at or before each row (-1: none in this window).
        at = np.maximum.accumulate(np.where(~bad, np.arange(len(bad)), -1))
        before = self._last.get(key)
        if before is None:
            before = np.asarray(_BEFORE_ANY.get(key, np.zeros(values.shape[1:])), dtype=float)
        held = np.where(
            (at >= 0)[(...,) + (None,) * (values.ndim - 1)],
            values[np.maximum(at, 0)] if len(good) else before,
            before,
        )
        return np.asarray(held, dtype=float)

    def _remember(self, key: str, values: NDArray[np.float64], bad: NDArray[np.bool_]) -> None:
        good = np.flatnonzero(~bad)
        if len(good):
            self._last[key] = np.array(values[good[-1]], dtype=float)
