"""Gyroscope heading: the yaw rate about gravity integrated from a known start (Han2023 §2.1.3).

Han2023's "Method 1": integrate the gyroscope's angular rate to a heading,
trapezoidally. The rate that turns the walker is the one about the vertical,
r = ω·ĝ (:func:`~indoorsim.estimators.frames.yaw_rate`), so a tilted or
pitching phone (handheld toward the eyes, at the ear) still integrates the
turn and not a mixture of axes. Stable over short spans, it drifts with the
gyro's bias; the magnetometer and the Kalman fusions correct that.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.frames import yaw_rate

__all__ = ["GyroHeading"]


@dataclass(kw_only=True)
class GyroHeading:
    """Streaming gyro heading in the building frame, rad counter-clockwise from +x.

    From the start heading φ₀ at the first sample, for each later sample k

        φ_k = φ_{k−1} + ½·(r_{k−1} + r_k)·(t_k − t_{k−1}),   r = ω·ĝ,

    carrying the last sample across :meth:`update` calls. The heading is
    unwrapped (continuous), as the heading filters built on it need.

    Limit: ∫ω·ĝ dt is the phone's change of yaw only while its tilt does not
    circulate. A phone whose "up" traces a loop in its own frame every stride
    (in a trouser pocket, thigh pitch together with pelvis yaw) gains the
    loop's solid angle per stride — a geometric phase the integral cannot
    tell from a turn — so its heading drifts even with a perfect gyro.

    Attributes:
        history_s: how far back :meth:`at` can look up headings, s. A step
            detector reports steps up to about a second late; the default
            covers that with room to spare.
    """

    history_s: float = 5.0

    _t: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    _h: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    _last: tuple[float, float, float] | None = field(
        default=None, init=False, repr=False, compare=False
    )
    _start: float | None = field(default=None, init=False, repr=False, compare=False)

    def reset(self, heading: float) -> None:
        """Start a new walk whose first sample has heading ``heading`` (rad from +x)."""
        self._t = np.empty(0)
        self._h = np.empty(0)
        self._last = None
        self._start = float(heading)

    @property
    def heading(self) -> float:
        """The latest heading, rad (the start heading before any sample)."""
        if self._start is None:
            raise RuntimeError("GyroHeading has no start heading: call reset(heading) first")
        return self._last[2] if self._last is not None else self._start

    def update(self, t: ArrayLike, gyro: ArrayLike, gravity: ArrayLike) -> NDArray[np.float64]:
        """Integrate the next samples.

        Args:
            t: (N,) sample times, s, increasing and after those of earlier calls.
            gyro: (N, 3) angular rate, phone frame, rad/s.
            gravity: (N, 3) gravity (up-pointing), phone frame; only its direction is used.

        Returns:
            (N,) headings at ``t``, rad.
        """
        if self._start is None:
            raise RuntimeError("GyroHeading has no start heading: call reset(heading) first")
        t = np.asarray(t, dtype=float).reshape(-1)
        if not len(t):
            return np.empty(0)
        r = yaw_rate(np.reshape(gyro, (-1, 3)), np.reshape(gravity, (-1, 3)))
        if self._last is None:
            t_prev, r_prev, h_prev = t[0], r[0], self._start
        else:
            t_prev, r_prev, h_prev = self._last
        # Trapezoids between consecutive samples, the first from the carried one.
        r_all = np.r_[r_prev, r]
        increments = 0.5 * (r_all[:-1] + r_all[1:]) * np.diff(np.r_[t_prev, t])
        h = h_prev + np.cumsum(increments)
        self._last = (float(t[-1]), float(r[-1]), float(h[-1]))
        t_all, h_all = np.r_[self._t, t], np.r_[self._h, h]
        keep = t_all >= t[-1] - self.history_s
        self._t, self._h = t_all[keep], h_all[keep]
        return h

    def at(self, t: ArrayLike) -> NDArray[np.float64]:
        """Headings at times ``t`` within the retained history (linear interpolation,
        held constant beyond its ends), rad."""
        if not len(self._t):
            return np.full(np.shape(t), self.heading)
        return np.interp(t, self._t, self._h)
