"""Runs estimators through the evaluation protocol and writes the leaderboards.

:func:`run_leaderboard` regenerates ``leaderboards/`` from
:func:`~indoorsim.benchmark.evaluation.evaluate` runs:
per scenario a Markdown table and a CSV (rows = estimator × mode; mean and
spread over seeds; provenance columns), error-CDF and trajectory plots, a
real-data table, the robustness board (every estimator × sensor fault:
:mod:`~indoorsim.benchmark.robustness`), ``README.md`` assembled from those
tables and the hand-written ``leaderboards/commentary.md``, and the static site
``site/`` (:func:`~indoorsim.benchmark.results_site.write_site`).
"""

from __future__ import annotations

import json
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from indoorsim._version import __version__
from indoorsim.benchmark import metrics
from indoorsim.benchmark.evaluation import (
    REAL_DATA_PARAMS,
    Evaluation,
    Progress,
    WalkResult,
    evaluate,
    evaluate_recording,
)
from indoorsim.benchmark.realism.report import RealismConfig, run_realism
from indoorsim.benchmark.results_site import write_site
from indoorsim.benchmark.robustness import RobustnessConfig, run_robustness, write_robustness
from indoorsim.benchmark.sim_to_real import write_sim_to_real
from indoorsim.benchmark.step_transfer import count_steps, oxford_step_walks
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.util.provenance import REPO, git_revision, realdata_dir
from indoorsim.world.site import Site

__all__ = [
    "BoardConfig",
    "Evaluation",
    "WalkResult",
    "board_links",
    "evaluate",
    "evaluate_recording",
    "markdown_table",
    "run_leaderboard",
    "write_real_data",
    "write_site",
    "write_step_counts",
]

# ----------------------------------------------------------------------- writing


METRIC_COLUMNS = ("ae", "rmse", "me", "min", "sd", "cep50", "cep75", "cep95")
HEADLINE_COLUMNS = ("ae", "rmse", "cep95")
"""The Markdown boards' columns; the CSVs (and the site) carry every metric."""


def markdown_table(rows: pd.DataFrame, columns: Sequence[str] = HEADLINE_COLUMNS) -> str:
    """A Markdown table of ``estimator × mode`` rows with ``mean ± std`` cells (metres).

    Args:
        rows: one row per estimator × mode, as the scenario CSVs hold them.
        columns: the metrics shown; the headline (AE, RMSE, CEP95) unless given,
            e.g. :data:`METRIC_COLUMNS` for every position-error column.
    """
    head = ["estimator", "mode", "seeds", *columns]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for _, r in rows.iterrows():
        cells = [str(r["estimator"]), str(r["mode"]), str(int(r["seeds"]))]
        if r["seeds"] == 0:  # not applicable on this site
            lines.append("| " + " | ".join(cells + ["n/a"] * len(columns)) + " |")
            continue
        for c in columns:
            std = r.get(f"{c}_std", np.nan)
            cells.append(
                f"{r[c]:.2f} ± {std:.2f}" if np.isfinite(std) and r["seeds"] > 1 else f"{r[c]:.2f}"
            )
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def board_links(name: str) -> str:
    """Where a scenario board's every metric and its site page are, from ``leaderboards/``."""
    return (
        f"Every metric, its spread and provenance: [{name}.csv]({name}.csv); "
        f"sortable and filterable: [site/{name}.html](site/{name}.html)."
    )


def write_walks(ev: Evaluation, out: Path) -> None:
    """Per walk: ``estimates.csv`` (t, x, y, true_x, true_y) and ``metrics.csv``."""
    for w in ev.walks:
        folder = out / f"{ev.scenario}_{ev.mode}_{ev.estimator}_seed{w.seed}"
        folder.mkdir(parents=True, exist_ok=True)
        w.estimates.to_csv(folder / "estimates.csv", index=False)
        pd.DataFrame([w.metrics]).to_csv(folder / "metrics.csv", index=False)


def write_scenario(evals: Sequence[Evaluation], out: Path, site: Site) -> pd.DataFrame:
    """CSV, Markdown and plots for one scenario's evaluations; returns its rows."""
    from indoorsim.plots import plot_error_cdfs, plot_tracks

    rows = pd.DataFrame([ev.row() for ev in evals])
    name = site.name
    rows.to_csv(out / f"{name}.csv", index=False)
    (out / f"{name}.md").write_text(
        f"# {name}\n\nPosition error in metres, mean ± SD over seeds.\n\n"
        f"{markdown_table(rows)}\n\n{board_links(name)}\n"
    )
    plot_error_cdfs(evals).savefig(out / f"{name}_cdf.png", dpi=120, bbox_inches="tight")
    plot_tracks(evals, site).savefig(out / f"{name}_tracks.png", dpi=120, bbox_inches="tight")
    return rows


def write_provenance(out: Path, config: dict[str, Any]) -> None:
    doc = {
        "package_version": __version__,
        "git_revision": git_revision(),
        **config,
    }
    (out / "provenance.json").write_text(json.dumps(doc, indent=2) + "\n")


# --------------------------------------------------------------------- the board

BASELINES = ("start-only", "pdr-basic", "wknn-mag")
HAN2023 = ("han2023-pdr", "han2023-gm", "han2023-gml", "han2023-fusion")
CHEN2022 = ("dr-wifi", "dr-mm", "pf", "chen2022-cpf", "edtw-rekf", "apf", "wimag")
LEARNED = ("learned-io",)
HAN2023_TABLE2 = ("bp", "aso-bp", "tent-aso-bp")
"""Han2023's layer-1 training variants (Table 2): robustness board only, not scenario boards."""
PIPELINES = HAN2023 + CHEN2022 + LEARNED
MODES = ("handheld", "calling", "dangling", "pocketed")
SCENARIOS = ("han2023_basement", "han2023_corridor", "chen2022_lab", "chen2022_office")
# The real recordings, under the real-data folder (util.provenance.realdata_dir).
ILC_TRACES = Path("ms-indoor-location-2020", "site1", "F1", "path_data_files")
OXFORD = Path("oxford-stepcounter")


@dataclass(frozen=True, kw_only=True)
class BoardConfig:
    """What one leaderboard run covers."""

    scenarios: tuple[str, ...] = SCENARIOS
    estimators: tuple[str, ...] = BASELINES + PIPELINES
    modes: tuple[str, ...] = MODES
    seeds: tuple[int, ...] = (0, 1, 2)
    device: str = "nexus_5x"
    survey_device: str = "honor_50"
    window_s: float = 1.0
    real_data: bool = True
    paper_experiments: bool = True
    realism: bool = True
    """Also write ``realism.md``: simulated motion, field, WiFi and light beside real ones."""
    robustness: bool = True
    """Also write ``robustness.md``: every estimator under every sensor fault."""
    robustness_estimators: tuple[str, ...] | None = BASELINES + PIPELINES + HAN2023_TABLE2
    """The robustness board's estimators (every shipped one); None: :attr:`estimators`."""
    sim_to_real: bool = True
    """Also write ``sim_to_real.md``: what is tuned on simulation alone, on real phones."""

    @classmethod
    def quick(cls, scenarios: Sequence[str] | None = None) -> BoardConfig:
        """One seed, two modes: a fast smoke run (the README's main job)."""
        return cls(
            scenarios=tuple(scenarios or ("han2023_corridor",)),
            estimators=BASELINES,
            modes=("handheld", "pocketed"),
            seeds=(0,),
            real_data=False,
            paper_experiments=False,
            realism=False,
            robustness=False,
            sim_to_real=False,
        )


def run_leaderboard(
    config: BoardConfig,
    out: Path,
    *,
    progress: Progress | None = None,
    realdata: str | Path | None = None,
    timings: dict[str, float] | None = None,
) -> dict[str, pd.DataFrame]:
    """Evaluate every estimator × scenario × mode of ``config`` and write ``out``.

    Args:
        config: what the board covers.
        out: the output folder (created).
        progress: called with a line of text before each walk.
        realdata: the real-data folder (default: :func:`~indoorsim.util.provenance.realdata_dir`);
            the real-data tables are written for the recordings it holds.
        timings: if given, filled with the seconds some parts took (``sim_to_real``).

    Returns the rows per scenario (and ``"real_data"`` when run).
    """
    real = realdata_dir(realdata)
    revision = git_revision()
    if revision.endswith("-dirty") and out.resolve() == (REPO / "leaderboards").resolve():
        # The committed tables must come from committed code: provenance names the revision.
        warnings.warn(
            f"regenerating {out} from a working tree with uncommitted changes ({revision}); "
            "commit first, or run from a clean checkout, before committing these tables",
            stacklevel=2,
        )
    out.mkdir(parents=True, exist_ok=True)
    tables: dict[str, pd.DataFrame] = {}
    for scenario in config.scenarios:
        site = load_site(scenario)
        evals = [
            evaluate(
                est,
                site,
                mode=mode,
                seeds=config.seeds,
                device=config.device,
                survey_device=config.survey_device,
                window_s=config.window_s,
                progress=progress,
            )
            for mode in config.modes
            for est in config.estimators
        ]
        tables[site.name] = write_scenario(evals, out, site)
    if config.paper_experiments:
        from indoorsim.benchmark.reproduce import chen2022, han2023

        han2023.write_report(
            out, trajectory_seeds=config.seeds, device=config.device, progress=progress
        )
        chen2022.write_report(out, tables, device=config.device, progress=progress)
    if config.real_data and (real / ILC_TRACES).is_dir():
        tables["real_data"] = write_real_data(out, real / ILC_TRACES, progress=progress)
    if config.real_data and (real / OXFORD).is_dir():
        write_step_counts(out, real / OXFORD, progress=progress)
    if config.realism:
        run_realism(
            out,
            config=RealismConfig(device=config.device),
            realdata=None if realdata is None else real,
            progress=progress,
        )
    if config.robustness:
        write_robustness_board(config, out, progress=progress)
    if config.sim_to_real and real.is_dir():
        elapsed = write_sim_to_real(out, real, progress=progress)
        if timings is not None:
            timings["sim_to_real"] = elapsed
    write_provenance(out, {"config": _jsonable_config(config)})
    write_readme(out, tables)
    write_site(out)
    return tables


def write_robustness_board(
    config: BoardConfig, out: Path, *, progress: Progress | None = None
) -> pd.DataFrame:
    """``robustness.md``, ``.csv`` and ``.png`` for the board's estimators, device and window."""
    robust = RobustnessConfig(
        estimators=config.robustness_estimators or config.estimators,
        device=config.device,
        survey_device=config.survey_device,
        window_s=config.window_s,
    )
    t0 = time.perf_counter()
    table = run_robustness(robust, progress=progress)
    write_robustness(out, table, robust, elapsed_s=time.perf_counter() - t0)
    return table


def tables_on_disk(out: Path, config: BoardConfig) -> dict[str, pd.DataFrame]:
    """The scenario and real-data tables an earlier run wrote into ``out``, as run_leaderboard
    returns them (to reassemble ``README.md`` after regenerating one part)."""
    names = [*config.scenarios, "real_data"]
    return {n: pd.read_csv(out / f"{n}.csv") for n in names if (out / f"{n}.csv").is_file()}


def _jsonable_config(config: BoardConfig) -> dict[str, Any]:
    return {k: list(v) if isinstance(v, tuple) else v for k, v in config.__dict__.items()}


def write_real_data(
    out: Path,
    traces_dir: Path,
    *,
    estimators: Sequence[str] = ("pdr-basic", "han2023-pdr", "learned-io"),
    progress: Progress | None = None,
) -> pd.DataFrame:
    """Real Indoor Location Competition traces scored at their waypoints, a row per estimator.

    Parameters of :data:`REAL_DATA_PARAMS` apply and are shown in the table.
    """
    traces = sorted(traces_dir.glob("*.txt"))
    rows = []
    for est in estimators:
        walks = []
        for path in traces:
            if progress:
                progress(f"real data {est} {path.name}")
            rec = Recording.load(path)
            walks.append(evaluate_recording(est, rec, params=REAL_DATA_PARAMS.get(est)).metrics)
        agg = metrics.aggregate(walks)
        params = REAL_DATA_PARAMS.get(est, {})
        label = est + "".join(f" ({k}={v})" for k, v in params.items())
        rows.append(
            {
                "scenario": "ilc2020_site1_F1",
                "mode": "handheld",
                "estimator": label,
                **agg,
                "device": "OPPO PBCM10",
                "source": "shared/realdata/ms-indoor-location-2020 (MIT licence)",
                "package_version": __version__,
                "git_revision": git_revision(),
            }
        )
    table = pd.DataFrame(rows)
    table.to_csv(out / "real_data.csv", index=False)
    (out / "real_data.md").write_text(
        "# Real data: Indoor Location Competition 2.0, site 1 floor F1\n\n"
        f"{len(traces)} traces, OPPO PBCM10 held flat; errors at the surveyor's "
        "waypoints (m), mean ± SD over traces.\n\n"
        + markdown_table(table)
        + "\n\n"
        + board_links("real_data")
        + "\n"
    )
    return table


def step_count_table(
    oxford_dir: Path,
    min_intervals_s: Sequence[float] = (0.5, 0.3),
    *,
    progress: Progress | None = None,
) -> pd.DataFrame:
    """The step detector of Han2023 (§2.1.1) on the real Oxford step-counter walks.

    One row per walk and minimum peak interval: detected steps against the
    reference device's steps (checked: :func:`~indoorsim.io.reallogs.oxford.foot_contacts`),
    for each carrying position. The whole walk is fed
    to the streaming detector in one piece.
    """
    rows = []
    for walk in oxford_step_walks(oxford_dir, progress=progress):
        for interval in min_intervals_s:
            n = count_steps(walk, min_interval_s=interval)
            rows.append(
                {
                    "walk": walk.name,
                    "position": walk.position,
                    "mode": walk.mode,
                    "min_interval_s": interval,
                    "true_steps": walk.true_steps,
                    "detected": n,
                    "error_pct": 100.0 * (n - walk.true_steps) / walk.true_steps,
                }
            )
    return pd.DataFrame(rows)


def write_step_counts(
    out: Path, oxford_dir: Path, *, progress: Progress | None = None
) -> pd.DataFrame:
    """``step_counts_real.csv`` and ``.md``: count error per carrying position."""
    table = step_count_table(oxford_dir, progress=progress)
    table.to_csv(out / "step_counts_real.csv", index=False)
    summary = (
        table.groupby(["position", "min_interval_s"])["error_pct"]
        .agg(["count", "mean", "min", "max"])
        .reset_index()
    )
    lines = [
        "# Real data: step counts on the Oxford step-counter walks",
        "",
        "Han2023's peak/valley detector (low-pass, minimum interval between extrema) "
        "on the accelerometer of each walk (CC BY 4.0, `shared/realdata/oxford-stepcounter`), "
        "against the reference device's steps, its switches' bounces dropped and missed "
        "contacts added (`indoorsim.io.reallogs.oxford.foot_contacts`; `sim_to_real.md` "
        "gives the device's own counts). Error in % of the true steps, per carrying "
        "position and minimum interval.",
        "",
        "| position | min interval (s) | walks | mean error % | min % | max % |",
        "|---|---|---|---|---|---|",
    ]
    for _, r in summary.iterrows():
        lines.append(
            f"| {r['position']} | {r['min_interval_s']:.1f} | {int(r['count'])} | "
            f"{r['mean']:+.1f} | {r['min']:+.1f} | {r['max']:+.1f} |"
        )
    (out / "step_counts_real.md").write_text("\n".join(lines) + "\n")
    return table


def write_readme(out: Path, tables: dict[str, pd.DataFrame]) -> None:
    """``README.md``: the tables, then the hand-written ``commentary.md`` verbatim."""
    parts = [
        "# Leaderboards",
        "",
        "Generated by `indoorsim leaderboard` (do not edit by hand; edit "
        "`commentary.md`, which is appended below). Position errors in metres, "
        "mean ± SD over seeds: the headline AE, RMSE and CEP95. Per-scenario CSVs carry "
        "every metric, its spread and the provenance (env id, devices, window, package "
        "version, git revision); [site/index.html](site/index.html) shows them sortable "
        "and filterable.",
        "",
    ]
    for name, table in tables.items():
        title = "Real data (ILC 2020 traces)" if name == "real_data" else name
        parts += [f"## {title}", "", markdown_table(table), "", board_links(name), ""]
        if name != "real_data":
            parts += [f"![CDF]({name}_cdf.png)", "", f"![tracks]({name}_tracks.png)", ""]
    for paper in ("han2023", "chen2022"):
        report = out / f"{paper}.md"
        if report.is_file():
            parts += [report.read_text().rstrip(), ""]
    if (out / "robustness.csv").is_file():
        cells = pd.read_csv(out / "robustness.csv")
        crashes = int((cells["crashed_seeds"].fillna(0) > 0).sum())
        parts += [
            "## Robustness",
            "",
            "Every estimator under every sensor fault (dropouts, NaN bursts, stuck streams, "
            "bias steps, saturation, missing sensors, WiFi outages, magnetic disturbances, "
            f"an undeclared mode change, the wrong phone): {crashes} crashes; error ratios and "
            "recovery times in [robustness.md](robustness.md).",
            "",
            "![robustness](robustness.png)",
            "",
        ]
    realism = out / "realism.md"
    if realism.is_file():
        parts += [
            "## Realism",
            "",
            "Simulated phone motion, magnetic field, WiFi and light beside real recordings, "
            "statistic by statistic: [realism.md](realism.md) (`indoorsim realism`).",
            "",
            "![realism](realism_motion.png)",
            "",
        ]
    transfer = out / "sim_to_real.md"
    if transfer.is_file():
        parts += [
            "## Sim-to-real",
            "",
            "Each estimator's error on the real ILC traces beside their simulated twins "
            "(the real/sim ratio and whether the ranking holds), and a step detector tuned "
            "on simulated walks alone counting the real Oxford walks: "
            "[sim_to_real.md](sim_to_real.md).",
            "",
        ]
    steps = out / "step_counts_real.md"
    if steps.is_file():
        parts += ["## " + steps.read_text().split("\n", 1)[0].lstrip("# "), ""]
        parts += [steps.read_text().split("\n", 2)[2].rstrip(), ""]
    commentary = out / "commentary.md"
    if commentary.is_file():
        parts += [commentary.read_text().rstrip(), ""]
    (out / "README.md").write_text("\n".join(parts))
