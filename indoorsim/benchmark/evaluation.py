"""The evaluation protocol: what an estimator is given, and how it is scored.

For a scenario and a seed (DESIGN §8–§10):

1. **Site context** — the floor plan and the fingerprint databases of every
   survey plan in the scenario, measured with the *survey* phone
   (:func:`site_context`), plus the site's frames.
2. **Training walks** — labelled recordings walked with the walking phone
   (:func:`training_walks`): by default on the scenario's other routes (or
   the same route with other seeds when it has only one); with
   ``train_routes="same"``, walks of the test route itself by other seeds
   (another walker, another day on the same path: the protocol a paper that
   trains on "the" route most likely used).
3. **Test episodes** — one simulated walk per test seed; the estimator is
   reset with the start position and heading (:func:`start_info`) and then
   acts on each observation window in turn (:func:`run_episode`). Truth is
   read only to score an action after it has been taken.

Scoring, two ways (both in every row):

* **time-uniform** (``ae``, ``rmse``, …; the leaderboard's): the answer at
  each window's end against the truth at that instant — what a user of the
  position meets, so an estimate held since the last step counts as late;
* **at the time the estimate refers to** (``ae_reftime``, …; the papers'
  per-step protocol, used by the paper tables): each distinct estimate once,
  against the truth at the time it stands for. An estimator says that time
  with an optional ``estimate_time`` attribute (s, read after each ``act``):
  a step estimator its last step's heel strike or trough, a fingerprint
  estimator the mean time of the samples it matched. Without it, the
  window's end. This is the runner's only new contract: the env's
  observation, action and info are unchanged (an env step still scores the
  answer at the window's end).

The same episode loop runs on real recordings, scored wherever they carry
true positions (:func:`true_positions_at`).

:func:`evaluate` scores one estimator on one scenario and carrying mode over
several seeds (per-walk estimates beside the truth, and metrics);
:func:`evaluate_recording` does the same for a real recording, scored where it
carries true positions. :func:`check_estimator` checks a plug-in against the
protocol.

An estimator that raises, or answers something that is not a finite (x, y),
stops the run with :class:`EstimatorError`, which names the estimator, the
call and, in an episode, the window, its time and the seed; what it raised is
the error's cause.
"""

from __future__ import annotations

import functools
import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from indoorsim._version import __version__
from indoorsim.benchmark import metrics
from indoorsim.envs import env_id
from indoorsim.estimators.base import (
    Estimator,
    NotApplicableError,
    SiteContext,
    StartInfo,
    estimator_class,
)
from indoorsim.io.faults import Fault, apply_faults, parse_fault, walk_arguments
from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.scenario.schema import GridSurveySpec, WalkSurveySpec
from indoorsim.simulate import route_spec, simulate
from indoorsim.survey import grid_survey, walk_survey
from indoorsim.util.provenance import git_revision
from indoorsim.walker.schedule import ModeSchedule, ScheduleLike
from indoorsim.windows import Windower
from indoorsim.world.site import Site

# Seeds of the offline phase and of training walks lie beyond the range test
# seeds are drawn from (a Gymnasium env draws below 2**31), so they never repeat one.
SURVEY_SEED = 2**40
TRAIN_SEED = 2**41


class EstimatorError(ValueError):
    """An estimator that raised, or answered something that is not a position.

    The message names the estimator, the call (``__init__``, ``fit``, ``reset``
    or ``act``) and, in an episode, the window, its time and the walk's seed:
    ``estimator 'mine' raised ZeroDivisionError in act() at window 3 (t = 4.00
    s) of seed 0: division by zero``. What the estimator raised is the
    ``__cause__``, with its traceback. A ``ValueError``, as the check of
    ``act``'s answer raised before it had a type of its own.

    Attributes:
        estimator: the estimator's name.
        call: the method that failed, e.g. ``"act"``.
        window: the episode's window, or None outside an episode.
    """

    def __init__(self, estimator: str, call: str, message: str, window: int | None = None):
        self.estimator = estimator
        self.call = call
        self.window = window
        super().__init__(message)

    @classmethod
    def raised(
        cls,
        estimator: str,
        call: str,
        err: BaseException,
        where: str = "",
        window: int | None = None,
    ) -> EstimatorError:
        """``estimator 'NAME' raised TYPE in CALL()[ where]: MESSAGE``."""
        text = f"estimator {estimator!r} raised {type(err).__name__} in {call}(){where}"
        return cls(estimator, call, f"{text}: {err}" if str(err) else text, window)


def _label(estimator: object) -> str:
    return str(getattr(estimator, "name", None) or type(estimator).__name__)


def _make(spec: str, **kwargs: Any) -> Estimator:
    """:func:`indoorsim.estimators.base.make`, a failing constructor as :class:`EstimatorError`.

    Raises:
        UnknownEstimatorError: ``spec`` names no estimator.
        EstimatorError: its constructor raised (the cause).
    """
    cls = estimator_class(spec)
    try:
        return cls(**kwargs)
    except Exception as err:
        raise EstimatorError.raised(spec, "__init__", err) from err


def _fit(estimator: Estimator, context: SiteContext, train: Sequence[Recording]) -> float:
    """:func:`fit_timed`; a failure other than ``NotApplicableError`` as :class:`EstimatorError`."""
    try:
        return fit_timed(estimator, context, train)
    except NotApplicableError:
        raise
    except Exception as err:
        raise EstimatorError.raised(_label(estimator), "fit", err) from err


def window_samples(imu_rate_hz: float, window_s: float) -> int:
    """IMU samples in a window of ``window_s`` seconds."""
    return max(1, round(imu_rate_hz * window_s))


@functools.lru_cache(maxsize=32)
def _surveys(site: Site, survey_device: str, seed: int) -> tuple[tuple[str, FingerprintDB], ...]:
    out = []
    for name, spec in site.scenario.surveys.items():
        if isinstance(spec, GridSurveySpec):
            out.append((name, grid_survey(site, spec, device=survey_device, seed=seed)))
        elif isinstance(spec, WalkSurveySpec):
            out.append((name, walk_survey(site, spec, device=survey_device, seed=seed)))
    return tuple(out)


def site_context(
    site: Site,
    *,
    device: str,
    survey_device: str = "honor_50",
    window_s: float = 1.0,
    survey_seed: int = SURVEY_SEED,
) -> SiteContext:
    """The public knowledge of ``site`` for a walking ``device`` (surveys cached per process)."""
    from indoorsim.phone.devices import get_device

    imu_rate = get_device(device).accel.rate_hz
    sc = site.scenario.site
    return SiteContext(
        name=site.name,
        plan=site.plan,
        # Copies: the surveys are cached, and an estimator may edit its tables.
        fingerprints={name: db.copy() for name, db in _surveys(site, survey_device, survey_seed)},
        bssids=tuple(site.radio.bssids),
        building_north_deg=sc.north_deg,
        magnetic_declination_deg=site.magnetic_declination_deg,
        device=device,
        imu_rate_hz=imu_rate,
        window_samples=window_samples(imu_rate, window_s),
        extra={"survey_device": survey_device, "ceiling_height": sc.ceiling_height},
    )


TRAIN_ROUTES = ("other", "same")
"""Which routes the training walks follow (:func:`training_walks`)."""


def training_walks(
    site: Site,
    test_route: str,
    *,
    mode: ScheduleLike,
    device: str,
    n: int = 2,
    seed: int = TRAIN_SEED,
    routes: str = "other",
) -> list[Recording]:
    """Labelled walks for training, by seeds no test episode uses.

    Args:
        routes: ``"other"``: the scenario's other routes in turn (the test
            route itself when it has no other); ``"same"``: the test route.
    """
    if routes not in TRAIN_ROUTES:
        raise ValueError(f"train routes must be one of {TRAIN_ROUTES}, got {routes!r}")
    others = [r for r in site.scenario.routes if r != test_route]
    if routes == "same" or not others:
        others = [test_route]
    return [
        simulate(site, route=others[k % len(others)], mode=mode, device=device, seed=seed + k)
        for k in range(n)
    ]


def start_info(recording: Recording, seed: int = 0) -> StartInfo:
    """The start position and heading an episode reveals (truth at the first sample).

    Real recordings without a dense truth start at their first waypoint, heading
    toward the second (DESIGN §8, issue: real data through the same loop).
    """
    t0 = float(recording.accel.index[0])
    if recording.has_truth:
        truth = recording.truth
        return StartInfo(
            position=np.array([truth["x"].iloc[0], truth["y"].iloc[0]]),
            heading=float(truth["heading"].iloc[0]),
            seed=seed,
            t0=t0,
        )
    wp = recording.true_positions()
    xy = wp[["x", "y"]].to_numpy()
    if len(xy) < 2:
        raise ValueError("a recording without truth needs at least two waypoints to start from")
    d = xy[1] - xy[0]
    return StartInfo(position=xy[0].copy(), heading=float(np.arctan2(d[1], d[0])), seed=seed, t0=t0)


def true_positions_at(recording: Recording, t: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N, 2) true phone positions at times t (linear interpolation of the truth stream)."""
    truth = recording.truth
    ts = truth.index.to_numpy(dtype=float)
    return np.column_stack([np.interp(t, ts, truth[c].to_numpy(dtype=float)) for c in ("x", "y")])


def true_headings_at(recording: Recording, t: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N,) true walking direction at times t, rad (interpolated on the unwrapped angle)."""
    truth = recording.truth
    ts = truth.index.to_numpy(dtype=float)
    unwrapped = np.unwrap(truth["heading"].to_numpy(dtype=float))
    return np.angle(np.exp(1j * np.interp(t, ts, unwrapped)))


@dataclass(frozen=True, kw_only=True)
class EpisodeResult:
    """One episode: per window, the time, the estimate and the latency of ``act``.

    ``heading`` (rad, NaN where the estimator exposes none), ``t_ref`` (the
    window's end where it exposes no ``estimate_time``) and ``step_count``
    (None if it exposes none) come from the estimator's optional attributes.
    """

    t: NDArray[np.float64]
    estimate: NDArray[np.float64]
    latency_s: NDArray[np.float64]
    heading: NDArray[np.float64]
    t_ref: NDArray[np.float64]
    """The time each window's estimate refers to, s (≤ the window's end)."""
    step_count: int | None = None
    t_start: float = 0.0
    """Time of the episode's first sensor sample, s."""

    def frame(self) -> pd.DataFrame:
        x, y = self.estimate.T
        return pd.DataFrame(
            {"t": self.t, "x": x, "y": y, "t_ref": self.t_ref, "latency_s": self.latency_s}
        )

    @property
    def new_estimates(self) -> NDArray[np.intp]:
        """Indices of the windows whose estimate refers to a new time (each estimate once)."""
        return new_estimate_rows(self.t_ref)


def new_estimate_rows(t_ref: ArrayLike) -> NDArray[np.intp]:
    """Rows whose reference time differs from the row before (the first row always).

    >>> new_estimate_rows([1.0, 1.0, 2.5, 3.0, 3.0]).tolist()
    [0, 2, 3]
    """
    t = np.asarray(t_ref, dtype=float)
    if not len(t):
        return np.empty(0, dtype=np.intp)
    return np.flatnonzero(np.r_[True, t[1:] != t[:-1]])


def run_episode(
    estimator: Estimator, recording: Recording, context: SiteContext, start: StartInfo
) -> EpisodeResult:
    """Reset ``estimator`` and feed it every observation window of ``recording`` in order.

    Raises:
        EstimatorError: the estimator raised in ``reset`` or ``act`` (naming the
            window, its time and the seed), or ``act`` answered something other
            than a finite (x, y), or it reported an ``estimate_time`` after the
            window's end.
    """
    windows = Windower(recording, context.window_samples, context.bssids)
    name = _label(estimator)
    try:
        estimator.reset(start)
    except Exception as err:
        raise EstimatorError.raised(name, "reset", err, f" for seed {start.seed}") from err
    n = len(windows)
    t = np.empty(n)
    est = np.empty((n, 2))
    lat = np.empty(n)
    heading = np.full(n, np.nan)
    t_ref = np.empty(n)
    for k in range(n):
        obs = windows.window(k)
        t[k] = windows.end_time(k)
        where = f" at window {k} (t = {t[k]:.2f} s) of seed {start.seed}"
        t0 = time.perf_counter()
        try:
            answer = estimator.act(obs)
        except Exception as err:
            raise EstimatorError.raised(name, "act", err, where, k) from err
        lat[k] = time.perf_counter() - t0
        try:
            action = np.asarray(answer, dtype=float)
        except (TypeError, ValueError):
            action = np.empty(0)  # not numbers: refused below like a wrong shape
        if action.shape != (2,) or not np.isfinite(action).all():
            raise EstimatorError(
                name,
                "act",
                f"estimator {name!r} returned {answer!r} from act(){where}; "
                "expected a finite (x, y) array of shape (2,)",
                k,
            )
        est[k] = action
        h = getattr(estimator, "heading", None)
        if h is not None:
            heading[k] = float(h)
        t_ref[k] = _estimate_time(estimator, t[k], k)
    steps = getattr(estimator, "step_count", None)
    return EpisodeResult(
        t_start=float(windows.t[0]),
        t=t,
        estimate=est,
        latency_s=lat,
        heading=heading,
        t_ref=t_ref,
        step_count=None if steps is None else int(steps),
    )


def _estimate_time(estimator: Estimator, t_end: float, k: int) -> float:
    """The time the estimator's answer refers to: its ``estimate_time``, else the window's end."""
    value = getattr(estimator, "estimate_time", None)
    if value is None:
        return t_end
    t = float(value)
    # A filter's delay subtracted from the first samples' step can fall just before t0; a
    # time after the window's end would claim knowledge of the future.
    if not np.isfinite(t) or t > t_end + 1e-9:
        name = _label(estimator)
        raise EstimatorError(
            name,
            "act",
            f"estimator {name!r} reported estimate_time {value!r} at window {k}, "
            f"which ends at {t_end:.3f} s; expected a finite time no later than that",
            k,
        )
    return t


def fit_timed(estimator: Estimator, context: SiteContext, train: Sequence[Recording]) -> float:
    """Fit and return the training time in seconds."""
    t0 = time.perf_counter()
    estimator.fit(context, train)
    return time.perf_counter() - t0


# ------------------------------------------------------------------ evaluate

Progress = Callable[[str], None]


@dataclass(kw_only=True)
class WalkResult:
    """One scored walk: estimates beside the truth, and its metrics."""

    seed: int
    estimates: pd.DataFrame  # t, x, y, t_ref, true_x, true_y (at t), true_x_ref, true_y_ref
    metrics: dict[str, float]
    heading: NDArray[np.float64] | None = None
    """The estimator's heading at each row of ``estimates``, rad counter-clockwise from
    +x (NaN where it gave none); None when it exposes no ``heading``."""
    true_heading: NDArray[np.float64] | None = None
    """The true walking direction at each row of ``estimates``, rad; None without one
    (a real log's truth is positions only)."""
    track: pd.DataFrame | None = None
    """Every answer the estimator gave: ``t``, ``x``, ``y`` (its own track, whose length
    between two times, :func:`~indoorsim.benchmark.metrics.track_length`, is the
    distance it says was walked). None where not kept (simulated boards)."""


@dataclass(kw_only=True)
class Evaluation:
    """An estimator on one scenario × mode over several seeds."""

    estimator: str
    scenario: str
    mode: str
    config: dict[str, Any]
    walks: list[WalkResult] = field(default_factory=list)
    note: str = ""
    """Why the estimator did not run here (it needs data the site lacks), else empty."""

    def row(self) -> dict[str, Any]:
        """The leaderboard row: aggregate metrics and provenance (NaN metrics when not run)."""
        if self.walks:
            agg = metrics.aggregate([w.metrics for w in self.walks])
        else:
            agg = {"seeds": 0} | {
                k: np.nan for key in metrics.SUMMARY_KEYS for k in (key, f"{key}_std")
            }
        return {
            "scenario": self.scenario,
            "mode": self.mode,
            "estimator": self.estimator,
            **agg,
            "note": self.note,
            **self.config,
        }


def _score(
    result: EpisodeResult, rec: Recording, *, plan: Any, train_time_s: float
) -> dict[str, float]:
    """Metrics of one simulated walk; heading and step count when the estimator exposes them."""
    truth_xy = true_positions_at(rec, result.t)
    extra: dict[str, Any] = {}
    has_heading = np.isfinite(result.heading)
    if has_heading.any():
        extra["est_heading"] = np.degrees(result.heading[has_heading])
        extra["true_heading"] = np.degrees(true_headings_at(rec, result.t[has_heading]))
    if result.step_count is not None:
        in_episode = (rec.steps.index >= result.t_start) & (rec.steps.index <= result.t[-1])
        extra["n_steps_est"] = result.step_count
        extra["n_steps_true"] = int(in_episode.sum())
    rows = result.new_estimates
    extra["ref_est_xy"] = result.estimate[rows]
    extra["ref_true_xy"] = true_positions_at(rec, result.t_ref[rows])
    return metrics.summarize(
        result.estimate,
        truth_xy,
        plan=plan,
        latencies=result.latency_s,
        train_time_s=train_time_s,
        **extra,
    )


def evaluate(
    estimator: str,
    scenario: str | Site,
    *,
    mode: str = "handheld",
    seeds: Sequence[int] = (0, 1, 2),
    route: str | None = None,
    device: str = "nexus_5x",
    survey_device: str = "honor_50",
    window_s: float = 1.0,
    n_train: int = 2,
    train_routes: str = "other",
    params: dict[str, Any] | None = None,
    faults: Sequence[Fault] = (),
    progress: Progress | None = None,
) -> Evaluation:
    """Score ``estimator`` (a registered name or ``module:Class``) over ``seeds``.

    ``params`` go to the estimator's constructor; ``train_routes`` says which
    routes the training walks follow (:func:`training_walks`). ``faults``
    (:mod:`indoorsim.io.faults`) are applied in order to each test walk before
    its episode, fault ``i`` on the walk of seed ``s`` drawing from
    ``fault_rng(s, i)``; a walk fault (``mode_change``, ``wrong_device``)
    changes the schedule or phone the test walks are simulated with, while the
    estimator's context and training walks keep the declared ones. Training
    walks and surveys stay clean. They are
    recorded in the config's ``faults`` column (their specs joined by ``;``),
    which is present only when there are faults.

    Raises:
        UnknownRouteError: ``route`` is not one of the scenario's routes.
        UnknownModeError: ``mode`` is not a carrying mode (both are ``ValueError``).
        EstimatorError: the estimator raised (other than ``NotApplicableError``
            from ``fit``, which becomes the evaluation's ``note``) or answered
            something that is not a position.
    """
    site = scenario if isinstance(scenario, Site) else load_site(scenario)
    route = route or next(iter(site.scenario.routes))
    route_spec(site, route)
    schedule = ModeSchedule.of(mode)
    walk_mode, walk_device = walk_arguments(faults, schedule, device)  # its errors first
    ctx = site_context(site, device=device, survey_device=survey_device, window_s=window_s)
    est = _make(estimator, **(params or {}))
    train = training_walks(
        site, route, mode=schedule, device=device, n=n_train, routes=train_routes
    )
    config = {
        "env_id": env_id(site.name),
        "route": route,
        "device": device,
        "survey_device": survey_device,
        "window_s": window_s,
        "n_train": n_train,
        "train_routes": train_routes,
        "params": json.dumps(params or {}, sort_keys=True),
        "package_version": __version__,
        "git_revision": git_revision(),
    }
    if faults:
        config["faults"] = "; ".join(f.spec() for f in faults)
    ev = Evaluation(estimator=estimator, scenario=site.name, mode=mode, config=config)
    try:
        train_s = _fit(est, ctx, train)
    except NotApplicableError as err:
        ev.note = str(err)
        return ev
    for seed in seeds:
        if progress:
            progress(f"{site.name} {mode} {estimator} seed {seed}")
        rec = simulate(site, route=route, mode=walk_mode, device=walk_device, seed=seed)
        rec = apply_faults(rec, faults, seed)
        res = run_episode(est, rec, ctx, start_info(rec, seed))
        truth_xy = true_positions_at(rec, res.t)
        ref_xy = true_positions_at(rec, res.t_ref)
        frame = res.frame().drop(columns="latency_s")
        frame["true_x"], frame["true_y"] = truth_xy[:, 0], truth_xy[:, 1]
        frame["true_x_ref"], frame["true_y_ref"] = ref_xy[:, 0], ref_xy[:, 1]
        score = _score(res, rec, plan=site.plan, train_time_s=train_s)
        walk = WalkResult(
            seed=seed,
            estimates=frame,
            metrics=score,
            heading=res.heading if np.isfinite(res.heading).any() else None,
            true_heading=true_headings_at(rec, res.t),
        )
        ev.walks.append(walk)
    return ev


REAL_DATA_PARAMS: dict[str, dict[str, Any]] = {
    "han2023-pdr": {"mag_frame": "start"},
    "learned-io": {"frame_offset": "start", "magnetic_tau_s": 30.0},
}
"""Constructor parameters on real logs: their map is not tied to north, so the
estimators that use magnetic north take its offset from the start heading.

``learned-io`` also holds its heading on the gyro (``magnetic_tau_s``): on the
simulated twins of the real traces, whose phones carry the residual hard iron
``indoorsim calibrate`` finds in them, that took its error from 1.71 to 1.40 m
(``leaderboards/sim_to_real.md``). The choice is made on the twins, which are
simulation; on the bundled sites' phones, with their smaller offsets, it helps
in some and costs in others, so it is not the default."""


def evaluate_recording(
    estimator: str,
    recording: Recording,
    *,
    window_s: float = 1.0,
    params: dict[str, Any] | None = None,
) -> WalkResult:
    """Run ``estimator`` on a real recording and score it at the recording's true positions.

    The site context of a real log has no floor plan or surveys: the estimator
    gets the start (first waypoint, heading toward the second) and the
    recording's own WiFi APs. Estimates are linearly interpolated to the
    waypoint times for scoring. ``params`` go to the estimator's constructor.
    """
    rate = 1.0 / float(np.median(np.diff(recording.accel.index.to_numpy(dtype=float))))
    bssids = tuple(sorted(set(recording.wifi["bssid"]))) if "wifi" in recording.streams else ()
    site = recording.meta.get("site")
    ctx = SiteContext(
        name=str(site.get("site_name", "real")) if isinstance(site, dict) else "real",
        bssids=bssids,
        device=str(recording.meta.get("device", "")),
        imu_rate_hz=rate,
        window_samples=max(1, round(rate * window_s)),
    )
    est = _make(estimator, **(params or {}))
    _fit(est, ctx, [])  # NotApplicableError propagates: a real log has no surveys or plan
    res = run_episode(est, recording, ctx, start_info(recording))
    truth = recording.true_positions()
    t_true = truth.index.to_numpy(dtype=float)
    keep = (t_true >= res.t[0]) & (t_true <= res.t[-1])
    t_true = t_true[keep]
    est_at = np.column_stack([np.interp(t_true, res.t, res.estimate[:, i]) for i in range(2)])
    true_xy = truth[["x", "y"]].to_numpy(dtype=float)[keep]
    frame = pd.DataFrame(
        {
            "t": t_true,
            "x": est_at[:, 0],
            "y": est_at[:, 1],
            "true_x": true_xy[:, 0],
            "true_y": true_xy[:, 1],
        }
    )
    heading = None
    known = np.isfinite(res.heading)
    if known.any():
        # Interpolated on the unwrapped angle, as the positions are, where the estimator gave one.
        heading = np.interp(t_true, res.t[known], np.unwrap(res.heading[known]))
    return WalkResult(
        seed=0,
        estimates=frame,
        metrics=metrics.summarize(est_at, true_xy, latencies=res.latency_s),
        heading=heading,
        track=pd.DataFrame({"t": res.t, "x": res.estimate[:, 0], "y": res.estimate[:, 1]}),
    )


# ------------------------------------------------------------------ contract


class EstimatorContractError(AssertionError):
    """An estimator that breaks the protocol, with what it did wrong."""


@functools.lru_cache(maxsize=1)
def _check_site() -> Site:
    """The minimal room with a short grid survey and a walk survey: every input kind, quickly."""
    base = load_site("minimal_room").scenario
    surveys = {
        "grid": GridSurveySpec(kind="grid", spacing=1.2, duration_s=3.0),
        "walk": WalkSurveySpec(kind="walk", route="main", reference_spacing=3.0, wifi_dwell_s=5.0),
    }
    return Site(base.model_copy(update={"surveys": surveys}))


# A faulty driver's worst: every sensor stream NaN for 2 s, then 2 s of nothing.
_CONTRACT_FAULTS = (
    *(
        f"nan_burst:stream={stream},t0=4,t1=6"
        for stream in ("accel", "gyro", "mag", "light", "wifi", "rotation", "game_rotation")
    ),
    "nan_burst:stream=gravity,t0=4,t1=6",
    "gap:t0=9,t1=11,streams=accel/gyro/mag/light/rotation/game_rotation/gravity",
)


def check_estimator(estimator: Estimator | str) -> None:
    """Check that ``estimator`` honours the protocol on a small simulated site.

    The checks: a ``name`` string; ``fit`` accepts the site context and
    labelled walks; after ``reset`` every ``act`` returns a finite (2,) array;
    the same episode twice gives the same estimates (deterministic given the
    episode seed); it copes with a window whose slow sensors are absent
    (``present`` flags zero) — a real log without light or WiFi — and with a
    faulty recording: NaN in every sensor stream for 2 s (a driver reporting
    garbage), then a 2 s gap in all of them.

    Raises:
        EstimatorContractError: naming the broken rule.
    """
    est = _make(estimator) if isinstance(estimator, str) else estimator
    label = getattr(est, "name", None)
    if not isinstance(label, str) or not label:
        raise EstimatorContractError(f"{est!r} has no non-empty 'name' string")
    site = _check_site()
    route = "main"
    ctx = site_context(site, device="mid_grade", survey_device="honor_50", window_s=0.5)
    try:
        est.fit(ctx, training_walks(site, route, mode="handheld", device="mid_grade", n=1))
    except Exception as err:
        raise EstimatorContractError(f"{label}: fit failed: {err!r}") from err
    rec = simulate(site, route=route, mode="handheld", device="mid_grade", seed=7)
    runs = []
    for _ in range(2):
        try:
            runs.append(run_episode(est, rec, ctx, start_info(rec, seed=7)).estimate)
        except EstimatorError as err:  # names the call, the window and what went wrong
            raise EstimatorContractError(f"{label}: the episode failed: {err}") from err
    if not np.array_equal(runs[0], runs[1]):
        raise EstimatorContractError(f"{label}: the same episode twice gave different estimates")
    bare = Recording(
        streams={k: v for k, v in rec.streams.items() if k in ("accel", "gyro", "mag")},
        meta=rec.meta,
    )
    try:
        run_episode(est, bare, ctx, start_info(rec, seed=7))
    except Exception as err:
        raise EstimatorContractError(
            f"{label}: failed on a recording with only accel, gyro and mag: {err!r}"
        ) from err
    faulty = apply_faults(rec, [parse_fault(spec) for spec in _CONTRACT_FAULTS], seed=7)
    try:
        run_episode(est, faulty, ctx, start_info(rec, seed=7))
    except Exception as err:
        raise EstimatorContractError(
            f"{label}: failed on a faulty recording (NaN on every sensor stream for 2 s, "
            f"then a 2 s gap): {err}"
        ) from err
