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

Each carrying mode of :attr:`RobustnessConfig.modes` is a board of its own
(the estimators fitted on that mode's training walks): a 2 g accelerometer
range clips a pocketed phone's heel strikes and barely touches a held one.
The ``mode_change`` fault puts a held phone into the pocket and takes a
pocketed one out into the hand.

The faults sit in the middle of the route (:data:`FAULT_T0`–:data:`FAULT_T1`
s into the default 83 s walk of ``han2023_corridor``), which has both the
grid survey of Han2023 and the walk survey of Chen2022, so every shipped
estimator runs on it.
"""

from __future__ import annotations

import dataclasses
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
from indoorsim.estimators.base import Estimator, NotApplicableError, SiteContext
from indoorsim.io.faults import (
    Fault,
    MagneticDisturbance,
    ModeChange,
    apply_faults,
    parse_fault,
    walk_arguments,
)
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate
from indoorsim.walker.schedule import ScheduleLike
from indoorsim.world.site import Site

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
    modes: tuple[str, ...] = ("handheld", "pocketed")
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


def _episode(est: Estimator, rec: Recording, ctx: SiteContext, seed: int) -> _Run:
    try:
        res = run_episode(est, rec, ctx, start_info(rec, seed))
    except EstimatorError as err:
        return _Run(crash=str(err))
    return _Run(t=res.t, estimate=res.estimate, recording=rec)


def _fault_end(fault: Fault) -> float | None:
    """When a fault stops acting, s; None for one that lasts to the walk's end."""
    if isinstance(fault, MagneticDisturbance):  # a Gaussian bump: 3 sigma past its centre
        return float(fault.t0 + 3.0 * fault.sigma)
    t1 = getattr(fault, "t1", None)
    return None if t1 is None else float(t1)


def run_robustness(config: RobustnessConfig, *, progress: Progress | None = None) -> pd.DataFrame:
    """One row per mode × estimator × fault (columns: module docstring), plus the clean ``ae``.

    An estimator not applicable on the scenario (``NotApplicableError`` from
    ``fit``) gets one row per mode with its ``note`` and no numbers.

    Raises:
        EstimatorError: an estimator crashed on a fault-free walk (a defect the
            contract check, not this board, is for).
    """
    site = load_site(config.scenario)
    route = config.route or next(iter(site.scenario.routes))
    ctx = site_context(
        site, device=config.device, survey_device=config.survey_device, window_s=config.window_s
    )
    rows: list[dict[str, object]] = []
    for mode in config.modes:
        faults = [_for_mode(parse_fault(spec), mode) for spec in config.faults]
        walks = _Walks(site, route, mode, config.device, faults)
        train = training_walks(site, route, mode=mode, device=config.device, n=config.n_train)
        for name in config.estimators:
            est = _make(name)
            try:
                _fit(est, ctx, train)
            except NotApplicableError as err:
                rows.append({"mode": mode, "estimator": name, "fault": "", "note": str(err)})
                continue
            rows += _estimator_rows(est, name, mode, faults, walks, ctx, config.seeds, progress)
    return pd.DataFrame(rows)


def _for_mode(fault: Fault, mode: str) -> Fault:
    """The fault for walks carried in ``mode``: a change into that same mode goes to the hand."""
    if isinstance(fault, ModeChange) and fault.mode == mode:
        return dataclasses.replace(fault, mode="handheld")
    return fault


class _Walks:
    """The test walks of one mode, clean and under each fault, built once for every estimator."""

    def __init__(self, site: Site, route: str, mode: str, device: str, faults: list[Fault]):
        self.site, self.route, self.mode, self.device = site, route, mode, device
        self.faults = faults
        self._clean: dict[int, Recording] = {}
        self._faulty: dict[tuple[int, int], Recording] = {}

    def get(self, seed: int, i: int | None) -> Recording:
        """The walk of ``seed``, clean (``i`` None) or under fault ``i``, as evaluate() makes it."""
        if seed not in self._clean:
            self._clean[seed] = self._simulate(self.mode, self.device, seed)
        if i is None:
            return self._clean[seed]
        if (seed, i) not in self._faulty:
            fault = self.faults[i]
            mode, device = walk_arguments([fault], self.mode, self.device)
            changed = (mode.written, device) != (self.mode, self.device)
            base = self._simulate(mode, device, seed) if changed else self._clean[seed]
            self._faulty[seed, i] = apply_faults(base, [fault], seed)
        return self._faulty[seed, i]

    def _simulate(self, mode: ScheduleLike, device: str, seed: int) -> Recording:
        return simulate(self.site, route=self.route, mode=mode, device=device, seed=seed)


def _estimator_rows(
    est: Estimator,
    name: str,
    mode: str,
    faults: list[Fault],
    walks: _Walks,
    ctx: SiteContext,
    seeds: tuple[int, ...],
    progress: Progress | None,
) -> list[dict[str, object]]:
    base = {s: _episode(est, walks.get(s, None), ctx, s) for s in seeds}
    if any(r.crash for r in base.values()):
        msg = next(r.crash for r in base.values() if r.crash)
        raise EstimatorError(name, "act", f"fault-free {mode} walk: {msg}")
    grid = {s: _grid(r) for s, r in base.items()}
    clean_errors = {s: r.errors(grid[s]) for s, r in base.items()}
    ae_clean = float(np.mean([e.mean() for e in clean_errors.values()]))
    rows: list[dict[str, object]] = []
    for i, fault in enumerate(faults):
        if progress:
            progress(f"robustness {mode} {name} {fault.name}")
        runs = {s: _episode(est, walks.get(s, i), ctx, s) for s in seeds}
        crashed = [s for s, r in runs.items() if r.crash]
        row: dict[str, object] = {
            "mode": mode,
            "estimator": name,
            "fault": fault.spec(),
            "fault_label": _label(fault.spec()),
            "crashed_seeds": len(crashed),
            "crash": runs[crashed[0]].crash if crashed else "",
            "ae_clean": ae_clean,
            "ae_fault": math.nan,
            "ratio": math.nan,
            "recovery_s": math.nan,
        }
        if not crashed:
            errors = {s: r.errors(grid[s]) for s, r in runs.items()}
            ae_fault = float(np.mean([e.mean() for e in errors.values()]))
            row["ae_fault"] = ae_fault
            row["ratio"] = ae_fault / max(ae_clean, 1e-9)
            end = _fault_end(fault)
            if end is not None:
                row["recovery_s"] = max(
                    recovery_time(grid[s], errors[s], clean_errors[s], end) for s in runs
                )
        rows.append(row)
    return rows


def _grid(run: _Run) -> NDArray[np.float64]:
    """The walk's scoring times: every GRID_S s from the first window's end to the last's."""
    assert run.t is not None
    return np.arange(run.t[0], run.t[-1] + 1e-9, GRID_S)


# ------------------------------------------------------------------------- writing


# The parameter that tells two board faults of one name apart, for column labels.
_LABELLED_BY = {"nan_burst": "stream", "stuck": "stream", "missing": "streams"}


def _label(spec: str) -> str:
    """A column label: the fault's name, and its stream(s) where several faults share the name."""
    name, _, rest = spec.partition(":")
    key = _LABELLED_BY.get(name)
    params = dict(p.split("=", 1) for p in rest.split(",") if "=" in p)
    if key not in params:
        return name
    return f"{name} {'fused' if params[key] == _FUSED else params[key]}"


def ratio_matrix(table: pd.DataFrame, mode: str) -> pd.DataFrame:
    """Estimators × fault labels → error ratio in one mode (NaN where crashed)."""
    return _matrix(table, mode, "ratio")


def _matrix(table: pd.DataFrame, mode: str, value: str) -> pd.DataFrame:
    cells = table[(table["mode"] == mode) & table["fault"].astype(bool)]
    m = cells.pivot(index="estimator", columns="fault_label", values=value)
    return m.loc[list(dict.fromkeys(cells["estimator"])), list(dict.fromkeys(cells["fault_label"]))]


def _cell(v: float) -> str:
    return "**crash**" if not np.isfinite(v) else f"{v:.2f}"


def _recovery_cell(v: float) -> str:
    return "∞" if v == math.inf else "—" if not np.isfinite(v) else f"{v:.0f}"


def write_robustness(
    out: Path, table: pd.DataFrame, config: RobustnessConfig, *, elapsed_s: float | None = None
) -> None:
    """``robustness.csv``, ``robustness.md`` and the heat map ``robustness.png`` in ``out``."""
    from indoorsim.plots import plot_robustness

    table.to_csv(out / "robustness.csv", index=False)
    cells = table[table["fault"].astype(bool)]
    crashes = cells[cells["crashed_seeds"] > 0]
    modes = list(dict.fromkeys(cells["mode"]))
    lines = [
        "# Robustness: every estimator against every sensor fault",
        "",
        f"Each estimator fitted once per carrying mode on `{config.scenario}` "
        f"({config.device}), then run on the same {len(config.seeds)} test walks clean and "
        "under each fault, one fault at a time (`indoorsim evaluate --fault SPEC` gives the "
        f"same walks). Faults that end act from {FAULT_T0:g} to {FAULT_T1:g} s of the "
        "walk. Errors are scored every 0.5 s, each answer standing until the next. "
        "Generated by `indoorsim leaderboard` (alone: `indoorsim leaderboard "
        "--robustness-only`); the module docstring of `indoorsim.benchmark.robustness` "
        "defines the columns.",
        "",
        f"**Crashes: {len(crashes)}** of {len(cells)} mode × estimator × fault cells"
        + (" (listed below)." if len(crashes) else "."),
        "",
        "![heat map](robustness.png)",
    ]
    # Per mode: the ratio matrix and each estimator's fault-free error, for the tables and plot.
    panels = {
        mode: (
            ratio_matrix(table, mode),
            cells[cells["mode"] == mode].groupby("estimator", sort=False)["ae_clean"].first(),
        )
        for mode in modes
    }
    for mode, (ratios, clean) in panels.items():
        lines += ["", f"## {mode}: error ratio (mean error under the fault / fault-free)", ""]
        head = ["estimator", "clean AE (m)", *ratios.columns]
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for est, values in ratios.iterrows():
            row = [str(est), f"{clean[est]:.2f}", *(_cell(v) for v in values)]
            lines.append("| " + " | ".join(row) + " |")
        recovery = _matrix(table, mode, "recovery_s")
        ending = [c for c in recovery.columns if recovery[c].notna().any()]
        if ending:
            lines += [
                "",
                f"## {mode}: time to recover after the fault ends "
                "(s; worst walk; ∞: not before the walk's end)",
                "",
            ]
            head = ["estimator", *ending]
            lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
            for est, values in recovery[ending].iterrows():
                row = [str(est), *(_recovery_cell(v) for v in values)]
                lines.append("| " + " | ".join(row) + " |")
    lines += ["", "## Faults", ""]
    specs = cells.drop_duplicates(["fault_label", "fault"])
    for label, group in specs.groupby("fault_label", sort=False):
        lines.append(f"- **{label}**: " + "; ".join(f"`{f}`" for f in group["fault"]))
    if len(crashes):
        lines += ["", "## Crashes", ""]
        lines += [
            f"- {r.mode}, {r.estimator} × `{r.fault}` ({r.crashed_seeds} of "
            f"{len(config.seeds)} walks): {r.crash}"
            for r in crashes.itertuples()
        ]
    notes = table[~table["fault"].astype(bool)]
    if len(notes):
        lines += ["", "## Not applicable", ""]
        lines += [f"- {r.mode}, {r.estimator}: {r.note}" for r in notes.itertuples()]
    if elapsed_s is not None:
        lines += ["", f"Regenerated in {elapsed_s:.0f} s."]
    (out / "robustness.md").write_text("\n".join(lines) + "\n")
    fig = plot_robustness(panels)
    fig.savefig(out / "robustness.png", dpi=120, bbox_inches="tight")
