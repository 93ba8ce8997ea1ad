"""Metrics of one estimated walk against exact ground truth, and their spread over seeds.

Each metric is a small function over whole arrays (no Python loop over
steps). :func:`summarize` gathers them into one leaderboard row with the
columns of :data:`SUMMARY_KEYS`, and :func:`aggregate` folds the rows of
several seeds into a mean and a sample standard deviation per column.

Conventions:

* Positions are metres in the plan frame, one row per estimate, shape
  (N, 2). Estimate and truth are sampled at the same instants (normally the
  step events), so row i of one pairs with row i of the other.
* Headings are degrees, in any one frame shared by estimate and truth. The
  simulator's truth heading is radians from +x: convert it with
  :func:`numpy.rad2deg` first.
* Column names are lower case as in DESIGN.md §10, so that leaderboard CSVs
  concatenate with pandas.

Metrics take plain arrays and, for wall crossings, any object with a
vectorised ``crosses_wall(p0, p1)`` method (:class:`PlanLike`; a
``FloorPlan`` is one): this module never imports the simulator.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Mapping, Sequence
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

JUMP_BACK_THRESHOLD_M = 1.0
"""Default backward along-track move (m) that counts as a jump-back: above one
0.6 m step, so a single step's worth of jitter is not counted."""

REFTIME_KEYS: tuple[str, ...] = ("ae", "rmse", "me", "min", "sd", "cep50", "cep75", "cep95", "n")
"""The error statistics also given per estimate at the time it refers to (:func:`summarize`)."""

REFTIME_SUFFIX = "_reftime"

SUMMARY_KEYS: tuple[str, ...] = (
    "ae",
    "rmse",
    "me",
    "min",
    "sd",
    "cep50",
    "cep75",
    "cep95",
    "n",
    "path_m",
    "final_error",
    "error_per_100m",
    "heading_mae_deg",
    "heading_rmse_deg",
    "step_count_error",
    "step_count_error_pct",
    "wall_crossings",
    "jump_backs",
    "latency_ms_mean",
    "latency_ms_p95",
    "train_time_s",
    *(f"{k}{REFTIME_SUFFIX}" for k in REFTIME_KEYS),
)
"""The columns of a :func:`summarize` row, in order (DESIGN.md §10)."""


class PlanLike(Protocol):
    """Anything that tells which straight moves pass through a wall (a ``FloorPlan`` does)."""

    def crosses_wall(self, p0: NDArray[np.float64], p1: NDArray[np.float64]) -> ArrayLike:
        """(M,) True where the move from ``p0[i]`` to ``p1[i]`` passes through a wall."""
        ...


# ------------------------------------------------------------------ validation


def _check_finite(arr: NDArray[np.float64], name: str) -> None:
    bad = ~np.isfinite(arr)
    if bad.any():
        row = int(np.flatnonzero(bad.reshape(len(arr), -1).any(axis=1))[0])
        raise ValueError(f"{name}: non-finite value (NaN or inf) in row {row}: {arr[row].tolist()}")


def _points(xy: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = np.asarray(xy, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"{name}: expected points of shape (N, 2), got {arr.shape}")
    _check_finite(arr, name)
    return arr


def _paired_points(
    est_xy: ArrayLike, true_xy: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    est, true = _points(est_xy, "est_xy"), _points(true_xy, "true_xy")
    if len(est) != len(true):
        raise ValueError(f"est_xy and true_xy differ in length: {len(est)} vs {len(true)}")
    return est, true


def _values(x: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {arr.shape}")
    _check_finite(arr, name)
    return arr


def _nonempty_nonnegative(x: ArrayLike, name: str) -> NDArray[np.float64]:
    arr = _values(x, name)
    if len(arr) == 0:
        raise ValueError(f"{name}: empty")
    if (arr < 0).any():
        row = int(np.flatnonzero(arr < 0)[0])
        raise ValueError(f"{name}: negative value in row {row}: {arr[row]}")
    return arr


def _count(n: int, name: str) -> int:
    try:
        value = operator.index(n)
    except TypeError:
        raise TypeError(f"{name}: expected an integer count, got {n!r}") from None
    if value < 0:
        raise ValueError(f"{name}: a count cannot be negative, got {value}")
    return value


def _given_together(a: object, b: object, name_a: str, name_b: str) -> None:
    if (a is None) != (b is None):
        raise ValueError(f"{name_a} and {name_b} must be given together")


# ------------------------------------------------------------------ position


def position_errors(est_xy: ArrayLike, true_xy: ArrayLike) -> NDArray[np.float64]:
    """Euclidean position error of each estimate, e_i = ‖p̂_i − p_i‖₂.

    Args:
        est_xy: (N, 2) estimated positions, m.
        true_xy: (N, 2) true positions at the same instants, m.

    Returns:
        (N,) errors e_i, m.

    Raises:
        ValueError: if either array is not (N, 2), their lengths differ, or a
            row holds NaN or inf (the message names the argument and the first
            bad row).

    Example:
        >>> position_errors([[3.0, 4.0], [1.0, 1.0]], [[0.0, 0.0], [1.0, 1.0]])
        array([5., 0.])
    """
    est, true = _paired_points(est_xy, true_xy)
    d = est - true
    return np.hypot(d[:, 0], d[:, 1])


def start_aligned_errors(
    est_xy: ArrayLike, true_xy: ArrayLike, start: ArrayLike
) -> tuple[NDArray[np.float64], float]:
    """Position errors once the estimated track is turned about its start, and the turn.

    The turn θ that best lays the track on the truth about the start p_0, where
    the estimator was told it stood (least squares, a pure rotation: the start is
    given, so no shift and no scale), is θ = atan2(Σ a_i × b_i, Σ a_i · b_i) with
    a_i = p̂_i − p_0 and b_i = p_i − p_0. What is left is the error of the track's
    shape; θ is the correction of its heading — an estimator that starts δ off
    (counter-clockwise) and is otherwise right reads θ = −δ and no error after it.
    A heading that turns away along the walk is corrected by a share of that turn,
    weighted by distance from the start. A track that never leaves the start has no
    direction (θ = 0).

    Args:
        est_xy: (N, 2) estimated positions, m.
        true_xy: (N, 2) true positions at the same instants, m.
        start: (2,) the start position, m.

    Returns:
        (N,) errors of the turned track, m, and θ, degrees counter-clockwise.

    Example:
        >>> errors, turn = start_aligned_errors([[0, 1], [0, 2]], [[1, 0], [2, 0]], [0, 0])
        >>> errors.round(12).tolist(), turn
        ([0.0, 0.0], -90.0)
    """
    est, true = _paired_points(est_xy, true_xy)
    p0 = np.asarray(start, dtype=float)
    if p0.shape != (2,):
        raise ValueError(f"start: expected one point (x, y), got shape {p0.shape}")
    _check_finite(p0[None], "start")
    a = est - p0
    b = true - p0
    theta = math.atan2(float(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])), float(np.sum(a * b)))
    c, s = math.cos(theta), math.sin(theta)
    turned = np.column_stack([c * a[:, 0] - s * a[:, 1], s * a[:, 0] + c * a[:, 1]])
    d = turned - b
    return np.hypot(d[:, 0], d[:, 1]), math.degrees(theta)


def error_stats(errors: ArrayLike) -> dict[str, float]:
    """Summary statistics of N position errors e_1 … e_N.

    * ``ae`` = (1/N) Σ e_i, the papers' mean (average) error;
    * ``rmse`` = √((1/N) Σ e_i²);
    * ``me`` = max e_i and ``min`` = min e_i;
    * ``sd`` = √(Σ (e_i − ae)² / (N − 1)), the *sample* SD as the papers'
      tables report it; 0 when N = 1 (a single error has no spread);
    * ``cep50``, ``cep75``, ``cep95``: the 50th/75th/95th percentiles of e,
      i.e. the radius around the truth holding that share of the estimates.
      Linear interpolation between order statistics (numpy's default,
      Hyndman–Fan type 7): with e sorted and 0-based, h = (N − 1)·q/100 and
      P_q = e_⌊h⌋ + (h − ⌊h⌋)(e_⌊h⌋+1 − e_⌊h⌋);
    * ``n`` = N.

    Args:
        errors: (N,) non-negative errors, m, N ≥ 1.

    Returns:
        The statistics above, in metres (``n`` a count).

    Raises:
        ValueError: if ``errors`` is empty, not 1-D, non-finite or negative.

    Example:
        >>> s = error_stats([1.0, 2.0, 2.0, 3.0, 7.0])
        >>> [round(s[k], 3) for k in ("ae", "rmse", "sd", "cep50", "cep75", "cep95")]
        [3.0, 3.661, 2.345, 2.0, 3.0, 6.2]
    """
    e = _nonempty_nonnegative(errors, "errors")
    cep50, cep75, cep95 = np.percentile(e, [50.0, 75.0, 95.0], method="linear")
    return {
        "ae": float(e.mean()),
        "rmse": float(np.sqrt(np.mean(e**2))),
        "me": float(e.max()),
        "min": float(e.min()),
        "sd": float(e.std(ddof=1)) if len(e) > 1 else 0.0,
        "cep50": float(cep50),
        "cep75": float(cep75),
        "cep95": float(cep95),
        "n": len(e),
    }


def error_cdf(
    errors: ArrayLike, grid: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Empirical CDF of the errors, F(x) = #{i : e_i ≤ x} / N.

    Without ``grid``, x holds the distinct error values in increasing order
    and F the CDF at each, so F jumps by (multiplicity)/N at every datum and
    ends at 1; F(x) = 0 below x[0]. Draw it as a right-continuous staircase,
    ``ax.step(x, F, where="post")``. With ``grid``, F is evaluated at the
    given abscissae (e.g. ``np.linspace(0, 5, 101)`` to put several
    estimators on one axis).

    Args:
        errors: (N,) non-negative errors, m, N ≥ 1.
        grid: optional (M,) abscissae, m, in any order.

    Returns:
        ``(x, F)``: the abscissae (m) and the CDF there, both 1-D and of equal length.

    Example:
        >>> x, F = error_cdf([2.0, 1.0, 2.0, 4.0])
        >>> x.tolist(), F.tolist()
        ([1.0, 2.0, 4.0], [0.25, 0.75, 1.0])
    """
    e = np.sort(_nonempty_nonnegative(errors, "errors"))
    if grid is None:
        x, counts = np.unique(e, return_counts=True)
        return x, np.cumsum(counts) / len(e)
    x = _values(grid, "grid")
    return x, np.searchsorted(e, x, side="right") / len(e)


def _path_length(xy: NDArray[np.float64]) -> float:
    d = np.diff(xy, axis=0)
    return float(np.hypot(d[:, 0], d[:, 1]).sum())


def track_length(t: ArrayLike, xy: ArrayLike, t0: float, t1: float) -> float:
    """Length of a track between two times: the polyline through its positions ``xy`` at
    times ``t`` (strictly increasing) from ``t0`` to ``t1``, each end linearly
    interpolated (and held at the track's first or last position outside its times).

    The distance a positioning system says was walked. A polyline through a few
    of its positions instead (at a real trace's waypoint marks, say) cuts every
    corner the track turns between them, and by more the later the track passes
    the corner than the mark says. Every answer counts: sampled finer, a track
    that wobbles reads longer.

    Example:
        >>> track_length([0.0, 1.0, 2.0], [[0.0, 0.0], [3.0, 0.0], [3.0, 4.0]], 0.5, 2.0)
        5.5
    """
    tt = _values(t, "t")
    pos = _points(xy, "xy")
    if len(tt) != len(pos):
        raise ValueError(f"t and xy differ in length: {len(tt)} vs {len(pos)}")
    if not len(tt):
        raise ValueError("t: empty")
    if (np.diff(tt) <= 0).any():
        k = int(np.argmax(np.diff(tt) <= 0))
        raise ValueError(f"t must increase: t[{k + 1}] = {tt[k + 1]} after t[{k}] = {tt[k]}")
    if not (math.isfinite(t0) and math.isfinite(t1)):
        raise ValueError(f"t0 = {t0} and t1 = {t1} must be finite")
    if not t0 <= t1:
        raise ValueError(f"t0 = {t0} is after t1 = {t1}")
    inside = (tt > t0) & (tt < t1)
    ends = [[np.interp(x, tt, pos[:, k]) for k in range(2)] for x in (t0, t1)]
    return _path_length(np.vstack([ends[0], pos[inside], ends[1]]))


def relative_error(errors: ArrayLike, true_xy: ArrayLike) -> dict[str, float]:
    """Errors relative to the distance walked.

    With L = Σ_{k=1}^{N−1} ‖p_k − p_{k−1}‖ the length of the true track
    through the sampled positions:

    * ``path_m`` = L;
    * ``final_error`` = e_N, the error of the last estimate, m;
    * ``final_error_frac`` = e_N / L;
    * ``mean_error_frac`` = ae / L with ae = (1/N) Σ e_i;
    * ``error_per_100m`` = 100 m · e_N / L: the end-point drift per 100 m
      walked, the usual figure for dead reckoning (for the mean error per
      100 m, take 100 · ``mean_error_frac``).

    The fractions are NaN when L = 0 (the walker never moved).

    Args:
        errors: (N,) non-negative errors, m, in walking order, N ≥ 1.
        true_xy: (N, 2) true positions at the same instants, m.

    Returns:
        The quantities above.

    Example:
        >>> r = relative_error([0.0, 1.0, 2.0], [[0.0, 0.0], [30.0, 0.0], [30.0, 20.0]])
        >>> r["path_m"], r["final_error_frac"], r["error_per_100m"]
        (50.0, 0.04, 4.0)
    """
    e = _nonempty_nonnegative(errors, "errors")
    true = _points(true_xy, "true_xy")
    if len(e) != len(true):
        raise ValueError(f"errors and true_xy differ in length: {len(e)} vs {len(true)}")
    path = _path_length(true)
    final, mean = float(e[-1]), float(e.mean())
    final_frac = final / path if path > 0 else math.nan
    return {
        "path_m": path,
        "final_error": final,
        "final_error_frac": final_frac,
        "mean_error_frac": mean / path if path > 0 else math.nan,
        "error_per_100m": 100.0 * final_frac,
    }


# ------------------------------------------------------------------ heading and steps


def heading_errors(est_heading: ArrayLike, true_heading: ArrayLike) -> NDArray[np.float64]:
    """Signed heading error of each estimate, wrapped to (−180°, 180°].

    Δ_i = d_i − 360·[d_i > 180] with d_i = (ψ̂_i − ψ_i) mod 360 ∈ [0, 360),
    so an estimate 2° counter-clockwise of the truth gives +2 however many
    turns either angle carries (Han2023 Table 1 averages |Δ_i|; its Eq. 32's
    "mod 360" alone is not a valid mean, see PAPER_NOTES.md).

    Args:
        est_heading: (N,) estimated headings, degrees.
        true_heading: (N,) true headings at the same instants, degrees.

    Returns:
        (N,) wrapped errors Δ_i, degrees.

    Example:
        >>> heading_errors([179.0, 0.0, 10.0], [-179.0, 360.0, 730.0]).tolist()
        [-2.0, 0.0, 0.0]
    """
    est = _values(est_heading, "est_heading")
    true = _values(true_heading, "true_heading")
    if len(est) != len(true):
        raise ValueError(
            f"est_heading and true_heading differ in length: {len(est)} vs {len(true)}"
        )
    d = np.mod(est - true, 360.0)
    # mod of a tiny negative number rounds to 360.0, which the branch maps to 0.
    return np.where(d > 180.0, d - 360.0, d)


def heading_stats(errors: ArrayLike) -> dict[str, float]:
    """Summary of wrapped heading errors Δ_1 … Δ_N (from :func:`heading_errors`).

    * ``heading_mae_deg`` = (1/N) Σ |Δ_i| (Han2023 Table 1's per-step error);
    * ``heading_rmse_deg`` = √((1/N) Σ Δ_i²);
    * ``heading_max_deg`` = max |Δ_i|.

    Args:
        errors: (N,) wrapped errors in (−180, 180], degrees, N ≥ 1.

    Returns:
        The statistics above, degrees.

    Raises:
        ValueError: if ``errors`` is empty, non-finite or outside [−180, 180]
            (unwrapped input).
    """
    d = _values(errors, "errors")
    if len(d) == 0:
        raise ValueError("errors: empty")
    outside = np.abs(d) > 180.0
    if outside.any():
        row = int(np.flatnonzero(outside)[0])
        raise ValueError(
            f"errors: {d[row]} in row {row} is outside [-180, 180]; wrap with heading_errors"
        )
    a = np.abs(d)
    return {
        "heading_mae_deg": float(a.mean()),
        "heading_rmse_deg": float(np.sqrt(np.mean(d**2))),
        "heading_max_deg": float(a.max()),
    }


def step_count_error(n_est: int, n_true: int) -> dict[str, float]:
    """Step-detection error: ΔN = N̂ − N and 100·ΔN/N.

    Signed, so that missed steps (ΔN < 0, e.g. a fast walker under a 0.5 s
    minimum step interval) are told apart from false detections (ΔN > 0);
    its spread over seeds shows in :func:`aggregate`.

    Args:
        n_est: detected steps N̂ ≥ 0.
        n_true: true steps N > 0.

    Returns:
        ``step_count_error`` (steps) and ``step_count_error_pct`` (% of N).

    Example:
        >>> step_count_error(95, 100)
        {'step_count_error': -5, 'step_count_error_pct': -5.0}
    """
    est, true = _count(n_est, "n_est"), _count(n_true, "n_true")
    if true == 0:
        raise ValueError("n_true: the true walk must have at least one step")
    diff = est - true
    return {"step_count_error": diff, "step_count_error_pct": 100.0 * diff / true}


# ------------------------------------------------------------------ track consistency


def wall_crossings(plan_like: PlanLike, est_xy: ArrayLike) -> int:
    """Number of moves between consecutive estimates that pass through a wall.

    The papers' "trajectory through the wall": the estimated track is the
    polyline p̂_0 → p̂_1 → … → p̂_{N−1}, and the count is
    #{k : plan_like.crosses_wall(p̂_{k−1}, p̂_k)}, all N − 1 moves asked in
    one vectorised call. A move through two walls counts once; what counts as
    crossing (e.g. starting inside a wall) is the plan's definition.

    Args:
        plan_like: any object with ``crosses_wall(p0, p1)`` taking two (M, 2)
            arrays and returning (M,) booleans.
        est_xy: (N, 2) estimated positions in walking order, m.

    Returns:
        The number of crossing moves, 0 for fewer than two estimates.

    Raises:
        ValueError: if ``crosses_wall`` does not return one value per move.
    """
    est = _points(est_xy, "est_xy")
    if len(est) < 2:
        return 0
    hits = np.asarray(plan_like.crosses_wall(est[:-1], est[1:]), dtype=bool)
    if hits.shape != (len(est) - 1,):
        raise ValueError(
            f"plan_like.crosses_wall returned shape {hits.shape} for {len(est) - 1} moves"
        )
    return int(np.count_nonzero(hits))


def jump_backs(
    est_xy: ArrayLike, true_xy: ArrayLike, threshold_m: float = JUMP_BACK_THRESHOLD_M
) -> int:
    """Number of estimates that jump backwards along the walking direction.

    For each interval k = 1 … N−1 the true walking direction is the unit
    vector of the true displacement, u_k = (p_k − p_{k−1}) / ‖p_k − p_{k−1}‖,
    and the estimate's along-track advance is the projection of its own
    displacement, s_k = (p̂_k − p̂_{k−1}) · u_k. Interval k is a jump-back
    when s_k < −threshold_m. Intervals in which the walker did not move
    (p_k = p_{k−1}) have no walking direction and never count.

    Args:
        est_xy: (N, 2) estimated positions in walking order, m.
        true_xy: (N, 2) true positions at the same instants, m.
        threshold_m: backward advance (m, ≥ 0) that must be exceeded.

    Returns:
        The number of jump-backs, 0 for fewer than two estimates.

    Example:
        >>> true = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]
        >>> est = [[0.0, 0.0], [2.0, 0.0], [0.5, 0.0], [3.0, 0.0]]
        >>> jump_backs(est, true, threshold_m=1.0)
        1
    """
    est, true = _paired_points(est_xy, true_xy)
    if not (math.isfinite(threshold_m) and threshold_m >= 0):
        raise ValueError(f"threshold_m: expected a finite value >= 0, got {threshold_m}")
    d_true, d_est = np.diff(true, axis=0), np.diff(est, axis=0)
    length = np.hypot(d_true[:, 0], d_true[:, 1])
    moving = length > 0
    s = np.einsum("ij,ij->i", d_est[moving], d_true[moving]) / length[moving]
    return int(np.count_nonzero(s < -threshold_m))


# ------------------------------------------------------------------ cost


def latency_stats(seconds_per_step: ArrayLike) -> dict[str, float]:
    """Run time per step of an estimator, in milliseconds.

    With t_i the wall-clock seconds spent on step i: ``latency_ms_mean`` =
    1000·(1/N) Σ t_i; ``latency_ms_p95`` = 1000·P_95(t) (linear
    interpolation, as in :func:`error_stats`); ``latency_ms_max`` =
    1000·max t_i.

    Args:
        seconds_per_step: (N,) non-negative durations, s, N ≥ 1.

    Returns:
        The statistics above, ms.
    """
    ms = 1000.0 * _nonempty_nonnegative(seconds_per_step, "seconds_per_step")
    return {
        "latency_ms_mean": float(ms.mean()),
        "latency_ms_p95": float(np.percentile(ms, 95.0, method="linear")),
        "latency_ms_max": float(ms.max()),
    }


# ------------------------------------------------------------------ rows


def summarize(
    est_xy: ArrayLike,
    true_xy: ArrayLike,
    *,
    plan: PlanLike | None = None,
    est_heading: ArrayLike | None = None,
    true_heading: ArrayLike | None = None,
    n_steps_est: int | None = None,
    n_steps_true: int | None = None,
    latencies: ArrayLike | None = None,
    train_time_s: float | None = None,
    ref_est_xy: ArrayLike | None = None,
    ref_true_xy: ArrayLike | None = None,
) -> dict[str, float]:
    """One leaderboard row: every metric of one walk, keyed by :data:`SUMMARY_KEYS`.

    Position metrics come from :func:`error_stats` and :func:`relative_error`
    (``path_m``, ``final_error``, ``error_per_100m``) and ``jump_backs`` from
    :func:`jump_backs` with :data:`JUMP_BACK_THRESHOLD_M`; these need only
    the two tracks. The others need their optional inputs and are NaN when
    those are omitted, so that every row has the same columns in the same
    order:

    * ``heading_mae_deg``, ``heading_rmse_deg`` ← ``est_heading`` and
      ``true_heading`` (degrees, :func:`heading_stats`);
    * ``step_count_error``, ``step_count_error_pct`` ← ``n_steps_est`` and
      ``n_steps_true`` (:func:`step_count_error`);
    * ``wall_crossings`` ← ``plan`` (:func:`wall_crossings`);
    * ``latency_ms_mean``, ``latency_ms_p95`` ← ``latencies``, seconds per
      step (:func:`latency_stats`);
    * ``train_time_s`` ← ``train_time_s``, seconds;
    * ``ae_reftime`` … ``n_reftime`` (:data:`REFTIME_KEYS`) ← ``ref_est_xy``
      and ``ref_true_xy``: :func:`error_stats` of each distinct estimate
      against the truth at the time it refers to (a step estimator's last
      step), the papers' per-step errors. ``est_xy``/``true_xy`` are the
      time-uniform ones: the answer at every window's end against the truth
      then, as a user of the position would meet it.

    Every value is a float (counts are whole numbers), so a column keeps one
    dtype whether or not its input was given.

    Args:
        est_xy: (N, 2) estimated positions, m.
        true_xy: (N, 2) true positions at the same instants, m.
        plan: object with a vectorised ``crosses_wall(p0, p1)``.
        est_heading: (M,) estimated headings, degrees.
        true_heading: (M,) true headings at the same instants, degrees.
        n_steps_est: number of detected steps.
        n_steps_true: number of true steps.
        latencies: (K,) estimator run time per step, s.
        train_time_s: estimator training (or calibration) time, s.
        ref_est_xy: (M, 2) each distinct estimate once, m.
        ref_true_xy: (M, 2) the true positions at the times those refer to, m.

    Returns:
        The row, keys exactly :data:`SUMMARY_KEYS`.

    Raises:
        ValueError: on invalid input (see the metric functions), or when only
            one input of a pair (headings, step counts) is given.
    """
    errors = position_errors(est_xy, true_xy)
    row: dict[str, float] = dict.fromkeys(SUMMARY_KEYS, math.nan)
    row.update(error_stats(errors))
    rel = relative_error(errors, true_xy)
    for key in ("path_m", "final_error", "error_per_100m"):
        row[key] = rel[key]
    row["jump_backs"] = jump_backs(est_xy, true_xy)
    _given_together(est_heading, true_heading, "est_heading", "true_heading")
    _given_together(n_steps_est, n_steps_true, "n_steps_est", "n_steps_true")
    _given_together(ref_est_xy, ref_true_xy, "ref_est_xy", "ref_true_xy")
    if ref_est_xy is not None and ref_true_xy is not None:
        stats = error_stats(position_errors(ref_est_xy, ref_true_xy))
        row.update({f"{k}{REFTIME_SUFFIX}": stats[k] for k in REFTIME_KEYS})
    if est_heading is not None and true_heading is not None:
        heading = heading_stats(heading_errors(est_heading, true_heading))
        row["heading_mae_deg"] = heading["heading_mae_deg"]
        row["heading_rmse_deg"] = heading["heading_rmse_deg"]
    if n_steps_est is not None and n_steps_true is not None:
        row.update(step_count_error(n_steps_est, n_steps_true))
    if plan is not None:
        row["wall_crossings"] = wall_crossings(plan, est_xy)
    if latencies is not None:
        latency = latency_stats(latencies)
        row["latency_ms_mean"] = latency["latency_ms_mean"]
        row["latency_ms_p95"] = latency["latency_ms_p95"]
    if train_time_s is not None:
        if not (math.isfinite(train_time_s) and train_time_s >= 0):
            raise ValueError(f"train_time_s: expected a finite value >= 0, got {train_time_s}")
        row["train_time_s"] = train_time_s
    return {key: float(value) for key, value in row.items()}


def aggregate(rows: Sequence[Mapping[str, float]]) -> dict[str, float]:
    """Fold the rows of S seeds into mean and spread per metric.

    For each key m of the rows: ``m`` = m̄ = (1/S) Σ_s m_s and ``m_std`` =
    √(Σ_s (m_s − m̄)² / (S − 1)), the sample SD over seeds (0 when S = 1);
    plus ``seeds`` = S, first. A NaN in any seed makes that metric's mean and
    SD NaN (a metric that some seeds lack is not comparable).

    Args:
        rows: S ≥ 1 rows with the same keys, e.g. from :func:`summarize`.

    Returns:
        ``seeds``, then ``m`` and ``m_std`` for each key in the first row's order.

    Raises:
        ValueError: if ``rows`` is empty or the rows' keys differ.

    Example:
        >>> aggregate([{"ae": 1.0}, {"ae": 3.0}])
        {'seeds': 2, 'ae': 2.0, 'ae_std': 1.4142135623730951}
    """
    if not rows:
        raise ValueError("rows: need at least one row")
    keys = list(rows[0])
    for i, r in enumerate(rows[1:], start=1):
        if set(r) != set(keys):
            missing, extra = sorted(set(keys) - set(r)), sorted(set(r) - set(keys))
            raise ValueError(
                f"rows[{i}] keys differ from rows[0]: missing {missing}, extra {extra}"
            )
    values = np.array([[float(r[k]) for k in keys] for r in rows])
    mean = values.mean(axis=0)
    if len(rows) > 1:
        std = values.std(axis=0, ddof=1)
    else:
        std = np.where(np.isnan(mean), math.nan, 0.0)
    out: dict[str, float] = {"seeds": len(rows)}
    for key, m, s in zip(keys, mean, std, strict=True):
        out[key] = float(m)
        out[f"{key}_std"] = float(s)
    return out
