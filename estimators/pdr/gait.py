"""Gait-based dead reckoning (Chen2022 "The gait-based DR", Eq. 1–12).

Chen2022 builds its DR from four parts:

* **Stationary detection and an EKF on the vertical channel** (Eq. 1–3, ZUPT):
  :class:`~indoorsim.estimators.pdr.zupt.StationaryDetector` and
  :class:`~indoorsim.estimators.pdr.zupt.VerticalZuptEKF` (module
  :mod:`~indoorsim.estimators.pdr.zupt`, with the reduction of the paper's
  9-state filter that it implements).
* **Step length** by the inverted pendulum: vertical acceleration on gravity
  (Eq. 4, :func:`vertical_acceleration`), the vertical excursion S_VD between
  two adjacent troughs by double integration (Eq. 5, through the EKF), and
  D = 2√(L² − (L − S_VD)²) (Eq. 6, :func:`pendulum_step_length`).
* **Step counting**: one step between two adjacent troughs of the vertical
  acceleration (Eq. 7; garbled in the text, reading below).
* **Heading** from the quaternion attitude: update by gyro increments (Eq. 8),
  direction cosine matrix (Eq. 9), Euler angles (Eq. 10–12):
  :class:`~indoorsim.estimators.pdr.attitude.QuaternionAttitude` (module
  :mod:`~indoorsim.estimators.pdr.attitude`, with its readings of the paper).

:class:`GaitDeadReckoning` runs them together on streamed samples and returns
:class:`GaitStep` records.

Readings taken where the text is wrong or silent (PAPER_NOTES, Chen2022 item 1–2):

* **Eq. 4 sign.** The paper's g(t) is gravity pointing down, so
  a_z = −(a − g)·g/|g| is the upward specific force less g. Android's gravity
  sensor reads gravity as the accelerometer does at rest, pointing *up*, so
  with that g the same quantity is a_v = (a − g)·ĝ = a·ĝ − |g|, up positive.
* **Eq. 5.** The double integral of a_z from one trough to the next is the
  height change over a step — zero on a level floor, since the phone returns
  to the same height every step. What the pendulum of Eq. 6 needs is the
  height of the arc: S_VD is read as the vertical excursion (maximum minus
  minimum) of the doubly integrated a_v between the two troughs. The
  integration is the EKF's, whose level pseudo-measurement keeps drift out
  of it. (Removing the chord between the step's two end heights as well
  made it worse in simulated walks: a pocketed phone's height repeats every
  stride, not every step, and the step's ends lie on the steep parts of
  the bounce, where one sample of timing moves them by millimetres.)
* **Eq. 6.** L is "the distance between the smartphone and the ground while
  the walker is static". For a phone held at chest height that is ≈ 1.2 m
  (0.70 of a 1.70 m body); it agrees with the pendulum read backwards from
  gait data — a CoM excursion of 4–5 cm at 0.67 m steps gives
  L = D²/(8·S_VD) ≈ 1.1–1.4 m (REALISM §5) — which is why the paper's phone
  height fits better than the leg length (≈ 0.9 m) of the compass-gait
  model, which Zijlstra & Hof (2003) correct by an empirical factor of
  ≈ 1.25 on D (REALISM §5). Where the phone
  does not follow the trunk (a dangling hand, a thigh pocket) L is only a
  scale: :meth:`GaitDeadReckoning.calibrate` fits a length scale on training
  walks.
* **Eq. 7** survives only as its symbols (t^trough, t_1, t_2, a^thd). Read:
  a trough is a local minimum t^trough of the low-passed vertical
  acceleration with a_v(t^trough) < −a^thd, not while the phone is still;
  of two troughs closer than the shortest step time the deeper is kept; two
  adjacent kept troughs t_1 < t_2 make one step if t_2 − t_1 is at most the
  longest step time and the phone was not still in between. The first
  trough of a walking bout (after stillness, or after a gap longer than the
  longest step time) has no t_1: it too ends a step — the one that brought
  the walker to it — taken from where the phone left stillness, at most
  the longest step time before. Otherwise every bout would lose a step
  (the first and last steps of a bout, a third of a full step long, have
  almost no bounce and are missed anyway: 2–4 % of a simulated walk).

Frames: phone frame as Android's sensor frame (DESIGN §2); headings are
building-frame, counter-clockwise from +x.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import butter, sosfilt, sosfilt_zi

from indoorsim.estimators.pdr._checks import non_negative, positive

# dcm and euler_angles are re-exported for the path they had before the split.
from indoorsim.estimators.pdr.attitude import QuaternionAttitude, dcm, euler_angles
from indoorsim.estimators.pdr.steps import group_delay_s
from indoorsim.estimators.pdr.zupt import StationaryDetector, VerticalZuptEKF

__all__ = [
    "PENDULUM_LENGTH_M",
    "GaitDeadReckoning",
    "GaitStep",
    "QuaternionAttitude",
    "StationaryDetector",
    "VerticalZuptEKF",
    "dcm",
    "euler_angles",
    "pendulum_step_length",
    "vertical_acceleration",
]

PENDULUM_LENGTH_M = 1.2
"""Default pendulum length L of Eq. 6: a phone held at chest height by a 1.70 m
adult (0.70 × 1.70 m), the paper's "phone height when static"; also the L that a
4–5 cm CoM excursion at 0.67 m steps implies (module docstring)."""

# Below this norm (m/s²) a gravity row carries no direction: a fused stream
# that has not started yet, or a missing one, is all zeros.
_MIN_GRAVITY = 1.0
# Samples used to estimate the sampling rate when none is given: a fixed
# count, so that the estimate does not depend on how the samples are chunked.
_RATE_SAMPLES = 16

# ------------------------------------------------------------------ closed forms


def vertical_acceleration(accel: ArrayLike, gravity: ArrayLike) -> NDArray[np.float64]:
    """Vertical acceleration a_v = (a − g)·ĝ = a·ĝ − |g| (Chen2022 Eq. 4, sign as read), m/s².

    Args:
        accel: (N, 3) specific force, phone frame, m/s².
        gravity: (N, 3) gravity as Android reports it (pointing up: the
            accelerometer's reading at rest), or a low-passed accelerometer.

    Returns:
        (N,) upward acceleration; 0 for a phone at rest reading exactly ``gravity``.

    >>> vertical_acceleration([[0.0, 3.0, 10.0]], [[0.0, 0.0, 9.8]]).round(6).tolist()
    [0.2]
    """
    a = np.asarray(accel, dtype=float).reshape(-1, 3)
    g = np.asarray(gravity, dtype=float).reshape(-1, 3)
    norm = np.linalg.norm(g, axis=1)
    # Eq. 4: a_v = (a − g)·g/|g|
    return np.einsum("ij,ij->i", a - g, g) / norm


def pendulum_step_length(s_vd: ArrayLike, pendulum_length: float) -> NDArray[np.float64]:
    """Inverted-pendulum step length D = 2√(L² − (L − S_VD)²) (Chen2022 Eq. 6), m.

    S_VD is clipped to [0, L]: a negative excursion is no step, and beyond L the
    pendulum would pass the horizontal (D = 2L at most).

    Args:
        s_vd: vertical excursion of the step, m.
        pendulum_length: L, m.

    >>> round(float(pendulum_step_length(0.05, 1.25)), 12)
    0.7
    """
    positive("pendulum_length", pendulum_length)
    s = np.clip(np.asarray(s_vd, dtype=float), 0.0, pendulum_length)
    L = pendulum_length
    # Eq. 6: D = 2√(L² − (L − S_VD)²)
    return 2.0 * np.sqrt(L * L - (L - s) ** 2)


# ------------------------------------------------------------------ the facade


@dataclass(frozen=True)
class GaitStep:
    """One step of the gait-based DR.

    Attributes:
        t: time of the trough that ends the step, s.
        length: step length D (Eq. 6) times the length scale, m.
        heading: walking direction at the step, rad counter-clockwise from the building +x.
        delta_heading: heading change since the previous step (or since reset
            for the first), rad.
        vertical_displacement: S_VD (Eq. 5), m.
    """

    t: float
    length: float
    heading: float
    delta_heading: float
    vertical_displacement: float


@dataclass(slots=True)
class _Trough:
    t: float
    a: float


@dataclass(kw_only=True)
class GaitDeadReckoning:
    """Streaming gait-based DR (Chen2022 Eq. 1–12): steps with length and heading.

    Per sample (module docstring for the readings of the paper):

    1. ĝ: the fused gravity stream where given and ``use_gravity_stream``
       (rows of norm below 1 m/s² — a stream not yet started — fall back),
       else the accelerometer low-passed at ``gravity_cutoff_hz`` (2nd-order
       Butterworth);
    2. a_v = a·ĝ − |g| (Eq. 4);
    3. stillness (:class:`StationaryDetector`);
    4. the vertical EKF (:class:`VerticalZuptEKF`) integrates a_v to a height;
    5. the attitude (:class:`QuaternionAttitude`, Eq. 8–12) gives the change
       of yaw, if there is a gyro;
    6. a_v low-passed at ``step_cutoff_hz`` (4th-order Butterworth) is
       searched for troughs, and adjacent troughs make steps (Eq. 7);
    7. each step's S_VD is the excursion of the EKF height between its two
       troughs (Eq. 5), its length 2√(L² − (L − S_VD)²)·``length_scale``
       (Eq. 6), its heading the start heading plus the mean relative yaw
       over the step (which halves the heading error of the yaw at the
       step's end in simulated walks: the phone's own oscillation averages
       out; in a turn it lags by half a step).

    A step is reported once its ending trough is final: ``min_step_s`` after
    it (no deeper trough can replace it), plus the step filter's group delay
    (≈ 0.1 s at 3 Hz). The result does not depend on how the samples are
    split across :meth:`update` calls (to rounding). Without a gyro the
    heading stays at the start heading.

    Sampling is taken as uniform at ``rate_hz`` for the two low-pass
    filters; the EKF and the attitude use the actual sample intervals.

    Attributes:
        pendulum_length: L of Eq. 6, m (default: :data:`PENDULUM_LENGTH_M`).
        length_scale: factor on Eq. 6's D; :meth:`calibrate` fits it.
        use_gravity_stream: take ĝ from the fused gravity stream when given.
            It is the better vertical (Eq. 4 as physics); in a swinging hand
            the low-passed accelerometer counts steps better all the same:
            its ĝ is the arm's mean direction, so a_v keeps the swing's
            centripetal acceleration, which peaks once per step (simulated
            Nexus 5X walks: count errors 0 to +19 % with the stream, −2 to
            +4 % without).
        gravity_cutoff_hz: low-pass cut-off of the accelerometer's gravity
            estimate: a tenth of a walking cadence, so the step's
            accelerations hardly tilt it.
        step_cutoff_hz: low-pass cut-off of a_v for trough search: passes
            cadences up to 2.5 steps/s and removes heel-strike transients
            (as :class:`~indoorsim.estimators.pdr.steps.PeakStepDetector`).
        trough_threshold_mps2: a^thd of Eq. 7: a trough lies below −a^thd.
            Walking troughs of the low-passed a_v reach −1.5 to −3 m/s² in
            hand, at the ear and in a pocket, but only −0.4 to −1.3 m/s² in
            a swinging hand, whose swing lowers the hand as the trunk rises
            and so cancels much of the bounce; a still phone's stay within a
            few hundredths.
        min_step_s: shortest step time; of two troughs closer than this the
            deeper is kept (2.5 steps/s is 0.4 s).
        max_step_s: longest step time; troughs further apart do not make a
            step (gait initiation is ≈ 0.7 s at most).
        rate_hz: sampling rate; None estimates it from the median interval
            of the first 16 samples (steps appear once those arrived).
        stationary: the still-phone detector.
        ekf: the vertical Kalman filter.
        attitude: the gyro attitude.
    """

    pendulum_length: float = PENDULUM_LENGTH_M
    length_scale: float = 1.0
    use_gravity_stream: bool = True
    gravity_cutoff_hz: float = 0.3
    step_cutoff_hz: float = 3.0
    trough_threshold_mps2: float = 0.3
    min_step_s: float = 0.3
    max_step_s: float = 1.0
    rate_hz: float | None = None
    stationary: StationaryDetector = field(default_factory=StationaryDetector)
    ekf: VerticalZuptEKF = field(default_factory=VerticalZuptEKF)
    attitude: QuaternionAttitude = field(default_factory=QuaternionAttitude)

    _start_heading: float = field(default=0.0, init=False, repr=False, compare=False)
    _last_step_heading: float = field(default=0.0, init=False, repr=False, compare=False)
    _count: int = field(default=0, init=False, repr=False, compare=False)
    _rel_yaw: float = field(default=0.0, init=False, repr=False, compare=False)
    _waiting: list[tuple[NDArray[np.float64], ...]] = field(
        default_factory=list, init=False, repr=False, compare=False
    )
    _rate: float | None = field(default=None, init=False, repr=False, compare=False)
    _sos_g: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    _sos_s: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    _zi_g: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    _zi_s: NDArray[np.float64] | None = field(default=None, init=False, repr=False, compare=False)
    # Recent samples (t, filtered a_v, EKF height, relative yaw, still): the
    # last two are the edge for extrema, the rest the span a step can need.
    _hist: NDArray[np.float64] = field(
        default_factory=lambda: np.empty((0, 5)), init=False, repr=False, compare=False
    )
    _last: _Trough | None = field(default=None, init=False, repr=False, compare=False)
    _pending: _Trough | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        positive("pendulum_length", self.pendulum_length)
        positive("length_scale", self.length_scale)
        positive("gravity_cutoff_hz", self.gravity_cutoff_hz)
        positive("step_cutoff_hz", self.step_cutoff_hz)
        non_negative("trough_threshold_mps2", self.trough_threshold_mps2)
        positive("min_step_s", self.min_step_s)
        positive("max_step_s", self.max_step_s)
        if self.max_step_s <= self.min_step_s:
            raise ValueError(
                f"max_step_s ({self.max_step_s}) must exceed min_step_s ({self.min_step_s})"
            )
        if self.gravity_cutoff_hz >= self.step_cutoff_hz:
            raise ValueError(
                f"gravity_cutoff_hz ({self.gravity_cutoff_hz}) must be below "
                f"step_cutoff_hz ({self.step_cutoff_hz})"
            )
        if self.rate_hz is not None:
            positive("rate_hz", self.rate_hz)
            self._check_rate(self.rate_hz)
        self.reset(0.0)

    def _check_rate(self, rate: float) -> None:
        if rate <= 2 * self.step_cutoff_hz:
            raise ValueError(
                f"rate_hz {rate:.3g} Hz must exceed twice step_cutoff_hz ({self.step_cutoff_hz})"
            )

    # -------------------------------------------------------------- public interface

    def reset(self, heading: float) -> None:
        """Start a new walk at ``heading``, rad counter-clockwise from the building +x."""
        if not np.isfinite(heading):
            raise ValueError(f"heading must be finite, got {heading!r}")
        self._start_heading = self._last_step_heading = float(heading)
        self._count = 0
        self._rel_yaw = 0.0
        self._waiting = []
        self._rate = self.rate_hz
        self._sos_g = self._sos_s = self._zi_g = self._zi_s = None
        self._hist = np.empty((0, 5))
        self._last = self._pending = None
        self.stationary.reset()
        self.ekf.reset()
        self.attitude.reset()

    @property
    def heading(self) -> float:
        """The latest heading estimate, rad counter-clockwise from building +x (unwrapped)."""
        return self._start_heading + self._rel_yaw

    @property
    def step_count(self) -> int:
        """Steps reported since the last reset."""
        return self._count

    @property
    def step_delay_s(self) -> float:
        """The step filter's group delay at a walking cadence, s (NaN before the
        rate is known): a step's ``t`` minus this is its trough in the raw a_v."""
        if self._sos_s is None or self._rate is None:
            return float("nan")
        return group_delay_s(self._sos_s, self._rate)

    def update(
        self,
        t: ArrayLike,
        accel: ArrayLike,
        gyro: ArrayLike | None,
        gravity: ArrayLike | None = None,
    ) -> list[GaitStep]:
        """Feed consecutive samples; return the steps completed in this chunk.

        Args:
            t: (N,) sample times, s, increasing and after those of earlier calls.
            accel: (N, 3) specific force, phone frame, m/s².
            gyro: (N, 3) angular rate, phone frame, rad/s, at the same times;
                None if the phone has none.
            gravity: (N, 3) fused gravity, phone frame, m/s², or None.

        Returns:
            The steps whose ending troughs became final with these samples, in time order.
        """
        t = np.asarray(t, dtype=float).reshape(-1)
        accel = np.asarray(accel, dtype=float).reshape(-1, 3)
        n = len(t)
        if len(accel) != n:
            raise ValueError(f"{n} times but {len(accel)} accelerometer samples")
        # NaN rows mark a missing stream for the samples of this chunk.
        gyro_a = np.full((n, 3), np.nan) if gyro is None else np.asarray(gyro, dtype=float)
        grav_a = np.full((n, 3), np.nan) if gravity is None else np.asarray(gravity, dtype=float)
        for name, arr in (("gyro", gyro_a), ("gravity", grav_a)):
            if arr.shape != (n, 3):
                raise ValueError(f"{name} must have shape ({n}, 3), got {arr.shape}")
        if self._rate is None:
            self._waiting.append((t, accel, gyro_a, grav_a))
            t, accel, gyro_a, grav_a = (
                np.concatenate([w[i] for w in self._waiting]) for i in range(4)
            )
            if len(t) < _RATE_SAMPLES:
                return []
            self._waiting = []
            rate = 1.0 / float(np.median(np.diff(t[:_RATE_SAMPLES])))
            self._check_rate(rate)
            self._rate = rate
        if not len(t):
            return []
        return self._process(t, accel, gyro_a, grav_a)

    def calibrate(self, steps: Sequence[GaitStep], true_lengths: ArrayLike) -> float:
        """Fit and set ``length_scale`` to steps matched to their true lengths; return it.

        Eq. 6 makes every length c·f(S_VD), f the pendulum at
        ``pendulum_length`` (computed from the steps' stored S_VD, so the
        scale they were made with does not matter). The fit is the scale
        that makes the total distance exact,

            c = Σ L_i / Σ f_i,

        rather than least squares (Σ f_i·L_i / Σ f_i²,
        :func:`~indoorsim.estimators.pdr.length.calibrate_k`), which shrinks
        c when f scatters about the truth — regression dilution: in a
        pocket, where the steps of the pocket's leg bounce the phone about
        twice as much as the others, least squares comes out 4–5 % short
        on distance.

        Args:
            steps: steps of training walks.
            true_lengths: (N,) the true length of each step, m.

        Raises:
            ValueError: if the counts differ or every f_i is zero.
        """
        lengths = np.asarray(true_lengths, dtype=float).reshape(-1)
        if len(lengths) != len(steps):
            raise ValueError(f"{len(steps)} steps but {len(lengths)} true lengths")
        f = pendulum_step_length(
            np.array([s.vertical_displacement for s in steps], dtype=float), self.pendulum_length
        )
        denom = float(f.sum())
        if denom == 0.0:
            raise ValueError("cannot calibrate length_scale: every step has S_VD = 0")
        scale = float(lengths.sum()) / denom
        positive("length_scale", scale)
        self.length_scale = scale
        return scale

    # -------------------------------------------------------------- internals

    def _process(
        self,
        t: NDArray[np.float64],
        accel: NDArray[np.float64],
        gyro: NDArray[np.float64],
        gravity: NDArray[np.float64],
    ) -> list[GaitStep]:
        if self._sos_g is None:
            self._sos_g = butter(2, self.gravity_cutoff_hz, fs=self._rate, output="sos")
            self._sos_s = butter(4, self.step_cutoff_hz, fs=self._rate, output="sos")
            # At rest on the first sample: no start transient.
            self._zi_g = sosfilt_zi(self._sos_g)[:, :, None] * accel[0]
        g_lp, self._zi_g = sosfilt(self._sos_g, accel, axis=0, zi=self._zi_g)
        up = g_lp
        if self.use_gravity_stream:
            fused = np.linalg.norm(np.nan_to_num(gravity), axis=1) > _MIN_GRAVITY
            up = np.where(fused[:, None], gravity, g_lp)
        # Eq. 4: a_v = a·ĝ − |g|
        a_v = vertical_acceleration(accel, up)
        has_gyro = np.isfinite(gyro).all(axis=1)
        # Samples without a gyro reading pass the detector's gyro test.
        still = self.stationary.update(t, accel, np.where(has_gyro[:, None], gyro, 0.0))
        height = self.ekf.filter(t, a_v, still)[:, 0]
        rel_yaw = np.full(len(t), self._rel_yaw)
        if has_gyro.any():
            _, yaw = self.attitude.update(
                t[has_gyro], gyro[has_gyro], up[has_gyro], still[has_gyro]
            )
            # Samples without a gyro reading hold the latest heading.
            latest = np.cumsum(has_gyro) - 1
            rel_yaw = np.where(latest >= 0, yaw[np.maximum(latest, 0)], self._rel_yaw)
        self._rel_yaw = float(rel_yaw[-1])
        if self._zi_s is None:
            self._zi_s = sosfilt_zi(self._sos_s) * a_v[0]
        y, self._zi_s = sosfilt(self._sos_s, a_v, zi=self._zi_s)

        buf = np.concatenate(
            [self._hist, np.column_stack([t, y, height, rel_yaw, still.astype(float)])]
        )
        n_old = len(self._hist)
        tb, yb = buf[:, 0], buf[:, 1]
        # Interior samples only: a trough needs both neighbours. Old samples
        # beyond the edge of two were already searched.
        lo = max(n_old - 1, 1)
        idx = np.arange(lo, len(buf) - 1)
        is_trough = (yb[idx] < yb[idx - 1]) & (yb[idx] <= yb[idx + 1])
        is_trough &= (yb[idx] < -self.trough_threshold_mps2) & (buf[idx, 4] == 0.0)
        steps: list[GaitStep] = []
        for i in idx[is_trough]:
            self._confirm(tb[i], buf, steps)
            self._on_trough(_Trough(t=float(tb[i]), a=float(yb[i])))
        if len(buf) >= 2:
            self._confirm(tb[-2], buf, steps)  # every sample up to here is decided
        keep = tb >= tb[-1] - (self.max_step_s + self.min_step_s + 0.5)
        keep[-2:] = True
        self._hist = buf[keep]
        return steps

    def _on_trough(self, trough: _Trough) -> None:
        pending = self._pending
        if pending is not None and trough.a >= pending.a:
            return  # closer than min_step_s (else _confirm took it) and shallower
        self._pending = trough

    def _confirm(self, t_now: float, buf: NDArray[np.float64], out: list[GaitStep]) -> None:
        """Make the pending trough final once no deeper one can replace it; emit its step."""
        p = self._pending
        if p is None or t_now - p.t < self.min_step_s:
            return
        self._pending = None
        last, self._last = self._last, p
        # Eq. 7: the step runs from the previous trough, or, opening a bout,
        # from at most max_step_s before; in either case from the end of any
        # stillness in between.
        chained = last is not None and p.t - last.t <= self.max_step_s
        t_start = last.t if chained else p.t - self.max_step_s
        i0, i1 = np.searchsorted(buf[:, 0], [t_start, p.t], side="left")
        span = buf[i0 : i1 + 1]
        still = np.flatnonzero(span[:, 4])
        if len(still):
            span = span[still[-1] :]
        if len(span) < 3:
            return
        # Eq. 5: S_VD, the excursion of the doubly integrated a_v
        s_vd = float(np.ptp(span[:, 2]))
        # Eq. 6: D = 2√(L² − (L − S_VD)²), scaled
        length = self.length_scale * float(pendulum_step_length(s_vd, self.pendulum_length))
        # The step's mean yaw: the phone's own oscillation (trunk yaw, arm
        # swing, thigh) averages out of it, and the walking direction stays.
        heading = self._start_heading + float(np.mean(span[:, 3]))
        out.append(
            GaitStep(
                t=p.t,
                length=length,
                heading=heading,
                delta_heading=heading - self._last_step_heading,
                vertical_displacement=s_vd,
            )
        )
        self._last_step_heading = heading
        self._count += 1
