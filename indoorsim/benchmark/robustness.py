"""The robustness board: every estimator against every sensor fault.

:func:`run_robustness` fits each estimator once on a scenario, then runs it on
the same test walks clean and under each fault of :data:`BOARD_FAULTS`
(:mod:`indoorsim.io.faults`), exactly as ``indoorsim evaluate --fault`` would
(the same walks, seeds and fault draws). Per estimator × fault it reports:

* ``crashed``: the walks on which the estimator raised, or answered something
  that is not a finite position (:class:`~indoorsim.benchmark.evaluation.EstimatorError`),
  with the first message. Degrading is fine; crashing is a defect.
* ``ratio``: the mean position error under the fault divided by the clean
  one (means over the walks).
* ``recovery_s``, for faults that end (a gap, an outage, a passing
  disturbance): the time from the fault's end until the error is back to the
  clean run's, within ``max(1 m, 25 %)`` for :data:`RECOVERY_HOLD_S` seconds
  in a row; the worst over walks, ``inf`` if it never is before the walk ends.

Errors are taken on one time grid per walk (every :data:`GRID_S` s, each
answer standing until the next), not at window ends: a fault that removes
samples also moves the window ends, and a mean over other instants would
change an unchanged estimator's score.

The faults sit in the middle of the route (:data:`FAULT_T0`–:data:`FAULT_T1`
s into the default 83 s walk of ``han2023_corridor``), which has both the
grid survey of Han2023 and the walk survey of Chen2022, so every shipped
estimator runs on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from indoorsim.benchmark.evaluation import (
    EstimatorError,
    Progress,
    _fit,
    _make,
    run_episode,
    site_context,
    start_info,
    training_walks,
    true_positions_at,
)
from indoorsim.estimators.base import NotApplicableError
from indoorsim.io.faults import Fault, apply_faults, parse_fault, walk_arguments
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate

__all__ = [
    "BOARD_FAULTS",
    "RobustnessConfig",
    "recovery_time",
    "run_robustness",
    "write_robustness",
]

FAULT_T0 = 30.0
FAULT_T1 = 45.0
"""The window of the faults that start and end, s from the walk's start."""

RECOVERY_HOLD_S = 5.0
"""How long the error must stay within tolerance of the clean one to count as recovered, s."""
GRID_S = 0.5
"""Spacing of the time grid the errors are scored on, s."""
RECOVERY_ABS_M = 1.0
RECOVERY_REL = 0.25

_W = f"t0={FAULT_T0:g},t1={FAULT_T1:g}"
_FUSED = "rotation/game_rotation/gravity"  # Android's fused sensors, absent together
BOARD_FAULTS: tuple[str, ...] = (
    "dropout:streams=accel/gyro/mag,p=0.2",
    f"gap:{_W}",
    f"nan_burst:stream=accel,{_W}",
    f"nan_burst:stream=mag,{_W}",
    f"stuck:stream=gyro,{_W}",
    f"stuck:stream=mag,{_W}",
    f"bias_jump:stream=gyro,t0={FAULT_T0:g},vector=0/0/0.02",
    "bias_drift:stream=gyro,rate=0/0/0.0005",
    "saturation:stream=accel,full_scale=19.6",
    "scale:stream=mag,factor=1.1",
    "jitter:stream=accel,sigma=0.005",
    f"clock_step:stream=mag,t0={FAULT_T0:g},delta=0.5",
    "missing:streams=gyro",
    "missing:streams=mag",
    f"missing:streams={_FUSED}",
    "missing:streams=light",
    "missing:streams=wifi",
    f"wifi_outage:{_W}",
    "scan_throttle:period=30",
    f"lights_off:{_W}",
    f"magnetic_disturbance:t0={(FAULT_T0 + FAULT_T1) / 2:g},amplitude=50,sigma=2.5",
    "case_magnet:offset=30/-20/10",
    f"mode_change:t0={FAULT_T0:g},mode=pocketed",
    "wrong_device:device=honor_50",
)
"""The board's faults: each of :data:`~indoorsim.io.faults.FAULTS` at a level
real phones reach (a 2 g accelerometer range, a 0.02 rad/s gyro bias step, a
10 % magnetometer scale error, a case magnet of tens of µT, Android's
WiFi scan throttling), the sensor-specific ones on the streams estimators lean on."""


@dataclass(frozen=True, kw_only=True)
class RobustnessConfig:
    """What one robustness run covers."""

    estimators: tuple[str, ...]
    faults: tuple[str, ...] = BOARD_FAULTS
    scenario: str = "han2023_corridor"
    route: str | None = None
    mode: str = "handheld"
    seeds: tuple[int, ...] = (0, 1)
    device: str = "nexus_5x"
    survey_device: str = "honor_50"
    window_s: float = 1.0
    n_train: int = 2


@dataclass
class _Run:
    """One estimator on one walk: its answers at the window ends, or the error that stopped it."""

    t: NDArray[np.float64] | None = None
    estimate: NDArray[np.float64] | None = None
    recording: Recording | None = None
    crash: str = ""

    def errors(self, grid: NDArray[np.float64]) -> NDArray[np.float64]:
        """Position error at each grid time: the latest answer given by then against the truth."""
        assert self.t is not None and self.estimate is not None and self.recording is not None
        k = np.clip(np.searchsorted(self.t, grid + 1e-9, side="right") - 1, 0, len(self.t) - 1)
        truth = true_positions_at(self.recording, grid)
        return np.asarray(np.linalg.norm(self.estimate[k] - truth, axis=1))


def recovery_time(
    t: NDArray[np.float64],
    faulty: NDArray[np.float64],
    clean: NDArray[np.float64],
    t_end: float,
    hold_s: float = RECOVERY_HOLD_S,
) -> float:
    """Seconds from a fault's end until ``faulty`` errors are back to ``clean`` ones.

    ``t`` (increasing times), ``faulty`` and ``clean`` are errors at the same
    times. From the first time at or after ``t_end``, the first time that
    starts ``hold_s`` seconds (or the rest of the walk, if shorter) within
    ``max(1 m, 25 %)`` of the clean error gives the answer, counted from that
    first time: 0 if the error is back at once, ``inf`` if it never is.

    >>> t = np.arange(10.0)
    >>> recovery_time(t, np.array([0, 0, 9, 9, 9, 5, 0, 0, 0, 0.0]), np.zeros(10), 2.0, 3.0)
    4.0
    >>> recovery_time(t, np.full(10, 9.0), np.zeros(10), 2.0)
    inf
    """
    ok = faulty <= clean + np.maximum(RECOVERY_ABS_M, RECOVERY_REL * clean)
    first = int(np.searchsorted(t, t_end, side="left"))
    # ok_run[k]: every time in [t[k], t[k] + hold_s) is within tolerance.
    bad_before = np.r_[0, np.cumsum(~ok)]
    stop = np.searchsorted(t, t + hold_s, side="left")
    ok_run = bad_before[stop] == bad_before[np.arange(len(t))]
    hits = np.flatnonzero(ok_run[first:])
    return float(t[first + hits[0]] - t[first]) if len(hits) else math.inf


def _episode(est: object, rec: Recording, ctx: object, seed: int) -> _Run:
    try:
        res = run_episode(est, rec, ctx, start_info(rec, seed))  # type: ignore[arg-type]
    except EstimatorError as err:
        return _Run(crash=str(err))
    return _Run(t=res.t, estimate=res.estimate, recording=rec)


def _fault_end(fault: Fault) -> float | None:
    """When a fault stops acting, s; None for one that lasts to the walk's end."""
    if fault.name == "magnetic_disturbance":  # a Gaussian bump: 3 sigma past its centre
        return float(fault.t0 + 3.0 * fault.sigma)  # type: ignore[attr-defined]
    t1 = getattr(fault, "t1", None)
    return None if t1 is None else float(t1)


def run_robustness(config: RobustnessConfig, *, progress: Progress | None = None) -> pd.DataFrame:
    """One row per estimator × fault (columns: module docstring), plus the clean ``ae``.

    An estimator not applicable on the scenario (``NotApplicableError`` from
    ``fit``) gets one row with its ``note`` and no numbers.
    """
    site = load_site(config.scenario)
    route = config.route or next(iter(site.scenario.routes))
    ctx = site_context(
        site, device=config.device, survey_device=config.survey_device, window_s=config.window_s
    )
    train = training_walks(site, route, mode=config.mode, device=config.device, n=config.n_train)
    faults = [parse_fault(spec) for spec in config.faults]

    clean: dict[int, Recording] = {}
    faulty: dict[tuple[int, int], Recording] = {}

    def walk(seed: int, i: int | None) -> Recording:
        # Built once and shared by every estimator: the same walks, as evaluate() makes them.
        if seed not in clean:
            clean[seed] = simulate(
                site, route=route, mode=config.mode, device=config.device, seed=seed
            )
        if i is None:
            return clean[seed]
        if (seed, i) not in faulty:
            mode, device = walk_arguments([faults[i]], config.mode, config.device)
            base = (
                clean[seed]
                if (mode.written, device) == (config.mode, config.device)
                else simulate(site, route=route, mode=mode, device=device, seed=seed)
            )
            faulty[seed, i] = apply_faults(base, [faults[i]], seed)
        return faulty[seed, i]

    rows = []
    for name in config.estimators:
        est = _make(name)
        try:
            _fit(est, ctx, train)
        except NotApplicableError as err:
            rows.append({"estimator": name, "fault": "", "note": str(err)})
            continue
        base = {s: _episode(est, walk(s, None), ctx, s) for s in config.seeds}
        if any(r.crash for r in base.values()):
            msg = next(r.crash for r in base.values() if r.crash)
            raise EstimatorError(name, "act", f"fault-free walk: {msg}")
        grid = {s: _grid(r) for s, r in base.items()}
        clean_errors = {s: r.errors(grid[s]) for s, r in base.items()}
        ae_clean = float(np.mean([e.mean() for e in clean_errors.values()]))
        for i, fault in enumerate(faults):
            if progress:
                progress(f"robustness {name} {fault.name}")
            runs = {s: _episode(est, walk(s, i), ctx, s) for s in config.seeds}
            crashed = [s for s, r in runs.items() if r.crash]
            row = {
                "estimator": name,
                "fault": fault.spec(),
                "fault_name": fault.name,
                "crashed_seeds": len(crashed),
                "crash": runs[crashed[0]].crash if crashed else "",
                "ae_clean": ae_clean,
                "ae_fault": math.nan,
                "ratio": math.nan,
                "recovery_s": math.nan,
            }
            if not crashed:
                errors = {s: r.errors(grid[s]) for s, r in runs.items()}
                row["ae_fault"] = float(np.mean([e.mean() for e in errors.values()]))
                row["ratio"] = row["ae_fault"] / max(ae_clean, 1e-9)
                end = _fault_end(fault)
                if end is not None:
                    row["recovery_s"] = max(
                        recovery_time(grid[s], errors[s], clean_errors[s], end) for s in runs
                    )
            rows.append(row)
    return pd.DataFrame(rows)


def _grid(run: _Run) -> NDArray[np.float64]:
    """The walk's scoring times: every GRID_S s from the first window's end to the last's."""
    assert run.t is not None
    return np.arange(run.t[0], run.t[-1] + 1e-9, GRID_S)


# ------------------------------------------------------------------------- writing


# The parameter that tells two board faults of one name apart, for column labels.
_LABELLED_BY = {
    "nan_burst": "stream",
    "stuck": "stream",
    "missing": "streams",
    "mode_change": "mode",
    "wrong_device": "device",
}


def _short(spec: str) -> str:
    """A column label: the fault's name, and its stream, mode or device where several share it."""
    name, _, rest = spec.partition(":")
    key = _LABELLED_BY.get(name)
    params = dict(p.split("=", 1) for p in rest.split(",") if "=" in p)
    if key not in params:
        return name
    return f"{name} {'fused' if params[key] == _FUSED else params[key]}"


def ratio_matrix(table: pd.DataFrame) -> pd.DataFrame:
    """Estimators × fault labels → error ratio (NaN where crashed)."""
    ok = table[table["fault"].astype(bool)]
    m = ok.pivot(index="estimator", columns="fault", values="ratio")
    return m.loc[list(dict.fromkeys(ok["estimator"])), list(dict.fromkeys(ok["fault"]))]


def write_robustness(
    out: Path, table: pd.DataFrame, config: RobustnessConfig, *, elapsed_s: float | None = None
) -> None:
    """``robustness.csv``, ``robustness.md`` and the heat map ``robustness.png`` in ``out``."""
    from indoorsim.plots import plot_robustness

    table.to_csv(out / "robustness.csv", index=False)
    rows = table[table["fault"].astype(bool)]
    faults = list(dict.fromkeys(rows["fault"]))
    labels = {f: _short(f) for f in faults}
    crashes = rows[rows["crashed_seeds"] > 0]
    lines = [
        "# Robustness: every estimator against every sensor fault",
        "",
        f"Each estimator fitted once on `{config.scenario}` ({config.mode}, "
        f"{config.device}), then run on the same {len(config.seeds)} test walks clean and "
        "under each fault, one fault at a time (`indoorsim evaluate --fault SPEC` gives the "
        f"same walks). Faults that end act from {FAULT_T0:g} to {FAULT_T1:g} s. Generated by "
        "`indoorsim leaderboard`; the module docstring of `indoorsim.benchmark.robustness` "
        "defines the columns.",
        "",
        f"**Crashes: {len(crashes)}** of {len(rows)} estimator × fault cells"
        + (" (listed below)." if len(crashes) else "."),
        "",
        "## Error ratio (mean error under the fault / fault-free)",
        "",
        "![heat map](robustness.png)",
        "",
    ]
    matrix = ratio_matrix(table)
    head = ["estimator", "clean AE (m)", *[labels[f] for f in faults]]
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    clean = rows.groupby("estimator", sort=False)["ae_clean"].first()
    for est in matrix.index:
        cells = [est, f"{clean[est]:.2f}"]
        for f in faults:
            v = matrix.loc[est, f]
            cells.append("**crash**" if not np.isfinite(v) else f"{v:.2f}")
        lines.append("| " + " | ".join(cells) + " |")
    ending = [f for f in faults if _fault_end(parse_fault(f)) is not None]
    if ending:
        lines += [
            "",
            "## Time to recover after the fault ends (s; worst walk; ∞: not before the walk's end)",
            "",
        ]
        head = ["estimator", *[labels[f] for f in ending]]
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        rec = rows.pivot(index="estimator", columns="fault", values="recovery_s")
        for est in matrix.index:
            cells = [est]
            for f in ending:
                v = rec.loc[est, f]
                cells.append("∞" if v == math.inf else "—" if not np.isfinite(v) else f"{v:.0f}")
            lines.append("| " + " | ".join(cells) + " |")
    lines += ["", "## Faults", ""]
    lines += [f"- **{labels[f]}**: `{f}`" for f in faults]
    if len(crashes):
        lines += ["", "## Crashes", ""]
        lines += [
            f"- {r.estimator} × `{r.fault}` ({r.crashed_seeds} of {len(config.seeds)} walks): "
            f"{r.crash}"
            for r in crashes.itertuples()
        ]
    notes = table[~table["fault"].astype(bool)]
    if len(notes):
        lines += ["", "## Not applicable", ""]
        lines += [f"- {r.estimator}: {r.note}" for r in notes.itertuples()]
    if elapsed_s is not None:
        lines += ["", f"Regenerated in {elapsed_s:.0f} s."]
    (out / "robustness.md").write_text("\n".join(lines) + "\n")
    fig = plot_robustness(matrix.rename(columns=labels), clean.loc[matrix.index])
    fig.savefig(out / "robustness.png", dpi=120, bbox_inches="tight")
