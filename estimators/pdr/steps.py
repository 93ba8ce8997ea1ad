"""Step detection: peaks and valleys of the low-passed acceleration magnitude (Han2023 §2.1.1).

Han2023 low-passes the accelerometer, forms a = |acc| − g (Eq. 2), marks peaks
and troughs, and rejects "false" ones: two adjacent peaks (or two adjacent
troughs) closer than 0.5 s — the shortest step time of a uniform walk — keep
only the one with the larger |a|. One step is one peak–trough pair. The
paper's step (1), "set the detection threshold", is read here as a minimum
peak-to-valley amplitude.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import butter, group_delay, sos2tf, sosfilt, sosfilt_zi

__all__ = ["STANDARD_GRAVITY", "WALKING_CADENCE_HZ", "PeakStepDetector", "Step", "group_delay_s"]

STANDARD_GRAVITY = 9.80665  # m/s²

WALKING_CADENCE_HZ = 1.85
"""A typical walking step rate (REALISM §5: real cadences 1.69–2.01 Hz): the
frequency at which a step filter's delay is quoted."""


def group_delay_s(sos: ArrayLike, rate_hz: float, at_hz: float = WALKING_CADENCE_HZ) -> float:
    """Group delay of a digital filter (second-order sections) at ``at_hz``, seconds.

    A step found at an extremum of a low-passed signal is reported this late
    after the feature of the raw signal it stands for (the heel strike's
    jolt, the trough of the vertical bounce).

    >>> round(group_delay_s(butter(4, 3.0, fs=50.0, output="sos"), 50.0), 3)
    0.172
    """
    b, a = sos2tf(np.asarray(sos, dtype=float))
    _, delay = group_delay((b, a), w=[at_hz], fs=rate_hz)
    return float(delay[0]) / rate_hz


@dataclass(frozen=True, kw_only=True)
class Step:
    """One detected step: a peak of the low-passed a = |acc| − g and the valley after it.

    Attributes:
        t: time of the peak (the heel strike, delayed by the low-pass filter), s.
        t_valley: time of the valley, s.
        a_max: a at the peak, m/s².
        a_min: a at the valley, m/s².
        mean_abs_a: mean |a| over the step's samples — after the local minimum
            that precedes the peak, up to and including the valley: one gait
            cycle in steady walking — m/s² (Kim's and Scarlet's models).
    """

    t: float
    t_valley: float
    a_max: float
    a_min: float
    mean_abs_a: float


@dataclass(slots=True)
class _Peak:
    t: float
    a: float
    start_cum: float  # Σ|a| and sample count at the local minimum before the peak
    start_n: int
    paired: bool = False


@dataclass(slots=True)
class _Valley:
    t: float
    a: float
    cum: float  # Σ|a| and sample count through the valley
    n: int
    peak: _Peak | None


@dataclass(kw_only=True)
class PeakStepDetector:
    """Streaming peak–valley step detector (Han2023 §2.1.1).

    Each :meth:`update` takes the next accelerometer samples and returns the
    steps confirmed so far; state (filter memory, pending extrema) carries
    across calls, so feeding a walk in any split gives the same steps.

    Algorithm, per sample k:

    1. a_k = ‖acc_k‖ − g (Eq. 2), low-passed by a causal Butterworth filter
       whose state starts at rest on the first sample (no start transient).
    2. Local maxima are peak candidates, local minima valley candidates.
    3. A peak closer than ``min_interval_s`` to the last kept peak replaces it
       if higher, else is dropped; valleys likewise (a deeper valley wins).
       Comparing by value, not |a|, is the same for the usual positive peaks
       and negative valleys and ignores a bump inside a trough.
    4. A kept valley pairs with the latest unpaired kept peak before it;
       the pair is a step if a_max − a_min ≥ ``min_amplitude_mps2``.

    Latency: a valley is final once ``min_interval_s`` of later signal holds
    no deeper valley, so a step is reported at least ``min_interval_s`` after
    its valley (plus one sample to recognise the valley, plus the filter's
    group delay: ≈ 0.14 s for the default 4th-order 3 Hz filter).

    Sampling is taken as uniform at ``rate_hz``; occasional timestamp jitter or
    gaps only perturb the filter slightly.

    Attributes:
        cutoff_hz: low-pass cut-off. Han2023 does not give one; 3 Hz passes
            cadences up to 2.5 steps/s (gain ≥ 0.9) and removes the heel-strike
            transients above.
        order: Butterworth filter order.
        min_interval_s: shortest time between two kept peaks (or two kept
            valleys): Han2023's 0.5 s. Walkers above 2 steps/s need less, and
            near 2 steps/s the step-to-step variation of the peaks' timing
            already drops some steps.
        min_amplitude_mps2: smallest peak-to-valley swing of a step. Walking
            swings 2–4 m/s² after the filter in every carrying mode, the
            steps that start and stop a walk about 1 m/s²; a phone at rest
            a few hundredths.
        gravity_mps2: g of Eq. 2. It shifts a by a constant, so it affects
            only ``mean_abs_a``.
        rate_hz: accelerometer rate; None estimates it from the median sample
            interval of the first samples (real phones miss their nominal rate).
    """

    cutoff_hz: float = 3.0
    order: int = 4
    min_interval_s: float = 0.5
    min_amplitude_mps2: float = 0.5
    gravity_mps2: float = STANDARD_GRAVITY
    rate_hz: float | None = None

    _sos: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    _rate_in_use: float = field(default=0.0, init=False, repr=False, compare=False)
    _zi: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    _waiting: list[tuple[NDArray[np.float64], NDArray[np.float64]]] = field(
        default_factory=list, init=False, repr=False, compare=False
    )
    # The last two filtered samples (time, a, Σ|a|, count): a local extremum
    # at a window's last sample is only known with the next window's first.
    _tail: NDArray[np.float64] = field(
        default_factory=lambda: np.empty((0, 4)), init=False, repr=False, compare=False
    )
    _cum: float = field(default=0.0, init=False, repr=False, compare=False)
    _n: int = field(default=0, init=False, repr=False, compare=False)
    _last_min: tuple[float, int] | None = field(default=None, init=False, repr=False, compare=False)
    _peak: _Peak | None = field(default=None, init=False, repr=False, compare=False)
    _valley: _Valley | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.cutoff_hz <= 0 or self.order < 1:
            raise ValueError(
                f"need cutoff_hz > 0 and order ≥ 1, got {self.cutoff_hz}, {self.order}"
            )
        if self.min_interval_s < 0 or self.min_amplitude_mps2 < 0:
            raise ValueError("min_interval_s and min_amplitude_mps2 must be ≥ 0")
        if self.rate_hz is not None and self.rate_hz <= 2 * self.cutoff_hz:
            raise ValueError(f"rate_hz {self.rate_hz} must exceed twice cutoff_hz {self.cutoff_hz}")

    @property
    def delay_s(self) -> float:
        """The low-pass filter's group delay at a walking cadence, s (NaN before the
        first samples fix the rate): a step's ``t`` minus this is the heel strike."""
        if self._sos is None:
            return float("nan")
        return group_delay_s(self._sos, self._rate_in_use)

    def reset(self) -> None:
        """Forget everything: the next sample starts a new walk."""
        self._sos = self._zi = None
        self._waiting = []
        self._tail = np.empty((0, 4))
        self._cum, self._n = 0.0, 0
        self._last_min = self._peak = self._valley = None

    def update(self, t: ArrayLike, acc: ArrayLike) -> list[Step]:
        """Feed the next samples; return the steps confirmed by them, in time order.

        Args:
            t: (N,) sample times, s, increasing and after those of earlier calls.
            acc: (N, 3) specific force, phone frame, m/s².

        Returns:
            The steps whose valleys became final with these samples.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        acc = np.asarray(acc, dtype=float).reshape(-1, 3)
        if len(t) != len(acc):
            raise ValueError(f"{len(t)} times but {len(acc)} accelerometer samples")
        if self._sos is None:
            t, acc = self._start(t, acc)
            if self._sos is None:
                return []
        if not len(t):
            return []
        a = np.linalg.norm(acc, axis=1) - self.gravity_mps2
        if self._zi is None:
            self._zi = sosfilt_zi(self._sos) * a[0]  # at rest on the first sample
        y, self._zi = sosfilt(self._sos, a, zi=self._zi)
        cum = self._cum + np.cumsum(np.abs(y))
        n = self._n + np.arange(1, len(y) + 1)
        self._cum, self._n = float(cum[-1]), int(n[-1])

        buf = np.concatenate([self._tail, np.column_stack([t, y, cum, n])])
        self._tail = buf[-2:]
        tb, yb = buf[:, 0], buf[:, 1]
        # Interior samples only: an extremum needs both neighbours.
        rise = yb[1:-1] - yb[:-2]
        fall = yb[1:-1] - yb[2:]
        is_peak = (rise > 0) & (fall >= 0)
        is_valley = (rise < 0) & (fall <= 0)
        steps: list[Step] = []
        for i in np.flatnonzero(is_peak | is_valley) + 1:
            self._confirm(tb[i], steps)
            if is_peak[i - 1]:
                self._on_peak(tb[i], yb[i], buf[i, 2], int(buf[i, 3]))
            else:
                self._on_valley(tb[i], yb[i], buf[i, 2], int(buf[i, 3]))
        if len(buf) >= 2:
            self._confirm(tb[-2], steps)  # every sample up to here is decided
        return steps

    def _start(
        self, t: NDArray[np.float64], acc: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Design the filter once the rate is known (estimating it needs two samples)."""
        self._waiting.append((t, acc))
        t_all = np.concatenate([w[0] for w in self._waiting])
        acc_all = np.concatenate([w[1] for w in self._waiting])
        rate = self.rate_hz
        if rate is None:
            if len(t_all) < 2:
                return t_all, acc_all
            rate = 1.0 / float(np.median(np.diff(t_all)))
            if rate <= 2 * self.cutoff_hz:
                raise ValueError(
                    f"accelerometer rate {rate:.3g} Hz is too low "
                    f"for a {self.cutoff_hz} Hz low-pass"
                )
        self._sos = butter(self.order, self.cutoff_hz, fs=rate, output="sos")
        self._rate_in_use = rate
        self._waiting = []
        return t_all, acc_all

    def _confirm(self, t_now: float, out: list[Step]) -> None:
        """Emit the pending valley's step once no deeper valley can replace it."""
        v = self._valley
        if v is None or t_now - v.t < self.min_interval_s:
            return
        self._valley = None
        p = v.peak
        if p is not None and p.a - v.a >= self.min_amplitude_mps2:
            mean_abs = (v.cum - p.start_cum) / (v.n - p.start_n)
            out.append(
                Step(
                    t=float(p.t),
                    t_valley=float(v.t),
                    a_max=float(p.a),
                    a_min=float(v.a),
                    mean_abs_a=float(mean_abs),
                )
            )

    def _on_peak(self, t: float, a: float, cum: float, n: int) -> None:
        # The step's span starts after the local minimum before its peak; with
        # none yet (the walk's first samples), at the peak itself.
        start = self._last_min if self._last_min is not None else (cum - abs(a), n - 1)
        kept = self._peak
        if kept is not None and t - kept.t < self.min_interval_s:
            if a <= kept.a:
                return
            if self._valley is not None and self._valley.peak is kept:
                self._valley.peak = None  # its peak was false: no step for that valley
        self._peak = _Peak(t=t, a=a, start_cum=start[0], start_n=start[1])

    def _on_valley(self, t: float, a: float, cum: float, n: int) -> None:
        self._last_min = (cum, n)
        pending = self._valley
        if pending is not None:  # closer than min_interval_s, else _confirm emitted it
            if a >= pending.a:
                return
            # The deeper valley wins; it keeps the pending one's peak unless a
            # newer unpaired peak lies between them.
            peak = self._free_peak() or pending.peak
        else:
            peak = self._free_peak()
        self._valley = _Valley(t=t, a=a, cum=cum, n=n, peak=peak)

    def _free_peak(self) -> _Peak | None:
        """The latest kept peak if no valley has claimed it (it is then claimed)."""
        p = self._peak
        if p is None or p.paired:
            return None
        p.paired = True
        return p
