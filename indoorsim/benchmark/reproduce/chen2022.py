"""Chen2022's own experiments (§"Experiments"), run on the bundled sites beside the paper's numbers.

* Table 1 — the laboratory, four carrying modes: DR+WiFi, DR+MM, EDTW+REKF,
  HV-DDTW+CPF (``dr-wifi``, ``dr-mm``, ``edtw-rekf``, ``chen2022-cpf``).
* Table 2 — the office corridor: APF, WiMag, HV-DDTW+CPF (``apf``,
  ``wimag``, ``chen2022-cpf``).
  Both are read from the leaderboard's rows of ``chen2022_lab`` and
  ``chen2022_office`` (:func:`paper_table`), with a "general" row = the mean
  over the four modes, as the paper's.
* Fig. 8 — ``chen2022-cpf`` with the magnetic matcher MD-DTW against HV-DDTW.
* Fig. 10 — the plain particle filter (``pf``) against the chicken PF.
* Fig. 23 — the survey phone is the walking phone (N-N) or not (H-N: survey
  Honor 50, walk Nexus 5X).

The figures' mode is not stated in the text; here each is run handheld and
pocketed in the laboratory, errors pooled over the seeds.

Every error here is the papers' per-step one: each estimate once, against
the truth at the time it refers to (the ``_reftime`` metrics of
:mod:`~indoorsim.benchmark.evaluation`), not the leaderboard's time-uniform
error at every window's end, which also counts how late a step estimate is. EDTW+REKF, APF and
WiMag are built from what their cited papers publicly describe: approximations,
marked so in every table.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from indoorsim.benchmark.evaluation import evaluate, new_estimate_rows
from indoorsim.benchmark.metrics import REFTIME_SUFFIX
from indoorsim.benchmark.reproduce.tables import paper_cells, rank_line

__all__ = ["APPROXIMATIONS", "PAPER_TABLE_1", "PAPER_TABLE_2", "paper_table", "write_report"]

MODES = ("calling", "dangling", "handheld", "pocketed")
STATS = ("ae", "rmse", "me", "cep75", "cep95")

# Table 1 (laboratory): AE, RMSE, ME, CEP 75 %, CEP 95 % (m) per mode and method.
PAPER_TABLE_1: dict[str, dict[str, tuple[float, ...]]] = {
    "calling": {
        "dr-wifi": (1.5, 1.69, 2.58, 2.08, 2.56),
        "dr-mm": (0.93, 1.06, 1.77, 1.28, 1.76),
        "edtw-rekf": (0.92, 1.08, 2.15, 1.29, 2.12),
        "chen2022-cpf": (0.74, 0.86, 1.57, 0.98, 1.52),
    },
    "dangling": {
        "dr-wifi": (1.01, 1.1, 1.77, 1.34, 1.72),
        "dr-mm": (0.84, 0.99, 1.71, 1.38, 1.72),
        "edtw-rekf": (0.67, 0.79, 1.44, 0.99, 1.42),
        "chen2022-cpf": (0.54, 0.67, 1.35, 0.79, 1.32),
    },
    "handheld": {
        "dr-wifi": (0.9, 1.06, 1.9, 1.28, 1.86),
        "dr-mm": (0.93, 1.12, 2.37, 1.17, 2.32),
        "edtw-rekf": (0.89, 1.05, 2.57, 1.09, 2.52),
        "chen2022-cpf": (0.61, 0.74, 1.82, 0.79, 1.82),
    },
    "pocketed": {
        "dr-wifi": (2.14, 2.36, 3.49, 2.98, 3.42),
        "dr-mm": (1.66, 1.85, 3.15, 2.29, 3.12),
        "edtw-rekf": (1.85, 2.03, 3.35, 2.58, 3.32),
        "chen2022-cpf": (1.64, 1.79, 2.47, 2.26, 2.47),
    },
    "general": {
        "dr-wifi": (1.39, 1.55, 2.43, 1.92, 2.39),
        "dr-mm": (1.09, 1.26, 2.25, 1.53, 2.23),
        "edtw-rekf": (1.08, 1.24, 2.38, 1.49, 2.35),
        "chen2022-cpf": (0.88, 1.02, 1.8, 1.21, 1.78),
    },
}

# Table 2 (office corridor), same columns.
PAPER_TABLE_2: dict[str, dict[str, tuple[float, ...]]] = {
    "calling": {
        "apf": (3.74, 5.18, 12.71, 5.13, 11.17),
        "wimag": (1.46, 1.61, 2.97, 1.86, 2.93),
        "chen2022-cpf": (1.15, 1.37, 2.91, 1.63, 2.87),
    },
    "dangling": {
        "apf": (5.16, 6.34, 13.58, 8.93, 10.77),
        "wimag": (1.47, 1.63, 3.07, 1.86, 3.03),
        "chen2022-cpf": (1.14, 1.32, 2.69, 1.48, 2.57),
    },
    "handheld": {
        "apf": (1.37, 1.79, 5.62, 2.13, 3.17),
        "wimag": (1.33, 1.51, 3.72, 1.61, 2.97),
        "chen2022-cpf": (1.04, 1.27, 3.25, 1.53, 2.77),
    },
    "pocketed": {
        "apf": (4.35, 5.49, 12.09, 5.43, 11.87),
        "wimag": (1.34, 1.46, 3.07, 1.61, 2.37),
        "chen2022-cpf": (1.06, 1.24, 2.62, 1.36, 2.37),
    },
    "general": {
        "apf": (3.66, 4.41, 11.0, 5.41, 9.25),
        "wimag": (1.4, 1.51, 3.21, 1.74, 2.83),
        "chen2022-cpf": (1.1, 1.26, 2.88, 1.5, 2.65),
    },
}

LABELS = {
    "dr-wifi": "DR+WiFi",
    "dr-mm": "DR+MM",
    "edtw-rekf": "EDTW+REKF ≈",
    "chen2022-cpf": "HV-DDTW+CPF",
    "apf": "APF ≈",
    "wimag": "WiMag ≈",
    "pf": "HV-DDTW+PF",
}
# Built from their cited papers' public descriptions, not from their code.
APPROXIMATIONS = ("edtw-rekf", "apf", "wimag")


def paper_table(rows: pd.DataFrame, paper: dict[str, dict[str, tuple[float, ...]]]) -> pd.DataFrame:
    """Our rows of the paper's methods and modes beside the paper's values, plus "general".

    Args:
        rows: a scenario's leaderboard rows (``estimator``, ``mode`` and the
            lower-case metric columns).
        paper: :data:`PAPER_TABLE_1` or :data:`PAPER_TABLE_2`.

    Returns:
        One row per (mode, estimator) with our ``ae`` … ``cep95`` — the
        leaderboard's ``ae_reftime`` … ``cep95_reftime``, errors at the time
        each estimate refers to, as the paper's per-step errors are (NaN
        where the leaderboard has no such row) — and ``paper_*``; "general"
        is the mean of our four modes, as the paper's general rows are of theirs.
    """
    indexed = rows.set_index(["mode", "estimator"]) if len(rows) else None
    out = []
    for mode, methods in paper.items():
        for est, values in methods.items():
            if mode == "general":
                per_mode = [r for r in out if r["estimator"] == est and r["mode"] in MODES]
                ours = {k: float(np.mean([r[k] for r in per_mode])) for k in STATS}
            elif indexed is not None and (mode, est) in indexed.index:
                ours = {k: float(indexed.loc[(mode, est), k + REFTIME_SUFFIX]) for k in STATS}
            else:
                ours = dict.fromkeys(STATS, np.nan)
            out.append(
                {
                    "mode": mode,
                    "estimator": est,
                    "method": LABELS[est],
                    **ours,
                    **{f"paper_{k}": v for k, v in zip(STATS, values, strict=True)},
                }
            )
    return pd.DataFrame(out)


def _markdown(table: pd.DataFrame, title: str) -> list[str]:
    lines = [
        title,
        "",
        "| mode | method | estimator | AE | RMSE | ME | CEP 75 % | CEP 95 % |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for _, r in table.iterrows():
        lines.append(
            f"| {r['mode']} | {r['method']} | `{r['estimator']}` | " + paper_cells(r, STATS) + " |"
        )
    lines.append("")
    for mode in table["mode"].unique():
        sub = table[table["mode"] == mode]
        lines.append(
            f"- {mode}: " + rank_line(list(sub["method"]), list(sub["ae"]), list(sub["paper_ae"]))
        )
    return [*lines, ""]


def _errors(ev: Any) -> NDArray[np.float64]:
    """Each estimate's error at the time it refers to, pooled over an evaluation's walks."""
    from indoorsim.benchmark.metrics import position_errors

    if not ev.walks:
        return np.empty(0)
    errors = []
    for w in ev.walks:
        new = w.estimates.iloc[new_estimate_rows(w.estimates["t_ref"])]
        errors.append(position_errors(new[["x", "y"]], new[["true_x_ref", "true_y_ref"]]))
    return np.concatenate(errors)


def figure_errors(
    *,
    scenario: str = "chen2022_lab",
    modes: Sequence[str] = ("handheld", "pocketed"),
    seeds: Sequence[int] = (0, 1, 2),
    device: str = "nexus_5x",
    progress: Callable[[str], None] | None = None,
) -> dict[str, dict[str, dict[str, NDArray[np.float64]]]]:
    """Pooled per-estimate errors for Fig. 8, 10 and 23: figure → mode → curve label → errors."""

    runs: dict[str, list[tuple[str, str, dict[str, Any], str]]] = {
        # curve label, estimator, constructor parameters, survey phone
        "fig8": [
            ("MD-DTW", "chen2022-cpf", {"matcher": "md-dtw"}, "honor_50"),
            ("HV-DDTW", "chen2022-cpf", {}, "honor_50"),
        ],
        "fig10": [("PF", "pf", {}, "honor_50"), ("CPF", "chen2022-cpf", {}, "honor_50")],
        "fig23": [
            ("H-N (survey Honor 50)", "chen2022-cpf", {}, "honor_50"),
            ("N-N (survey Nexus 5X)", "chen2022-cpf", {}, "nexus_5x"),
        ],
    }
    out: dict[str, dict[str, dict[str, NDArray[np.float64]]]] = {}
    # The paper's method with its defaults is a curve of all three figures: run it once.
    done: dict[tuple[str, str, str, str], NDArray[np.float64]] = {}
    for fig, curves in runs.items():
        for mode in modes:
            for label, est, params, survey in curves:
                key = (est, json.dumps(params, sort_keys=True), survey, mode)
                if key not in done:
                    if progress:
                        progress(f"chen2022 {fig} {mode} {label}")
                    ev = evaluate(
                        est,
                        scenario,
                        mode=mode,
                        seeds=seeds,
                        device=device,
                        survey_device=survey,
                        params=params,
                    )
                    done[key] = _errors(ev)
                out.setdefault(fig, {}).setdefault(mode, {})[label] = done[key]
    return out


FIGURE_TITLES = {
    "fig8": "Chen2022 Fig. 8: MD-DTW vs HV-DDTW magnetic matching (laboratory)",
    "fig10": "Chen2022 Fig. 10: PF vs chicken PF (laboratory)",
    "fig23": "Chen2022 Fig. 23: survey phone vs walking phone (laboratory)",
}


def write_report(
    out: Path,
    scenario_rows: dict[str, pd.DataFrame],
    *,
    seeds: Sequence[int] = (0, 1, 2),
    device: str = "nexus_5x",
    progress: Callable[[str], None] | None = None,
) -> str:
    """Tables 1–2 from the leaderboard rows, Fig. 8/10/23 by new runs; writes ``chen2022.md``.

    Returns:
        The Markdown (also written to ``out/chen2022.md``).
    """
    from indoorsim.plots import plot_named_cdfs

    lines = [
        "## Chen2022: the paper's tables beside ours",
        "",
        "Each cell: **ours (paper)**; ≈ marks a method built from its cited paper's "
        "public description (an approximation). Errors as the paper's, per step: each "
        "estimate against the truth at the time it refers to (the leaderboard's "
        "`_reftime` columns; its main tables score the answer at every window's end). "
        "Generated by `indoorsim leaderboard` "
        "(`indoorsim/reproduce/chen2022.py`); the discussion is in the commentary below.",
        "",
    ]
    for name, paper, title in (
        ("chen2022_lab", PAPER_TABLE_1, "### Table 1: laboratory (`chen2022_lab`), m"),
        ("chen2022_office", PAPER_TABLE_2, "### Table 2: office corridor (`chen2022_office`), m"),
    ):
        rows = scenario_rows.get(name)
        if rows is None:
            continue
        table = paper_table(rows, paper)
        table.to_csv(out / f"chen2022_{'table1' if paper is PAPER_TABLE_1 else 'table2'}.csv")
        lines += _markdown(table, title)
    errors = figure_errors(seeds=seeds, device=device, progress=progress)
    summary = []
    for fig, panels in errors.items():
        path = f"chen2022_{fig}_cdf.png"
        plot_named_cdfs(panels, xlabel="position error (m)", title=FIGURE_TITLES[fig]).savefig(
            out / path, dpi=120, bbox_inches="tight"
        )
        lines += [f"### {FIGURE_TITLES[fig]}", "", f"![{fig}]({path})", ""]
        lines += [
            "| mode | curve | estimates | mean | CEP 50 % | CEP 95 % | max |",
            "|---|---|---|---|---|---|---|",
        ]
        for mode, curves in panels.items():
            for label, e in curves.items():
                stats = (
                    (e.mean(), *np.percentile(e, [50, 95]), e.max()) if len(e) else (np.nan,) * 4
                )
                summary.append(
                    {"figure": fig, "mode": mode, "curve": label, "estimates": len(e)}
                    | dict(zip(("mean", "cep50", "cep95", "max"), stats, strict=True))
                )
                lines.append(
                    f"| {mode} | {label} | {len(e)} | "
                    + " | ".join(f"{v:.2f}" for v in stats)
                    + " |"
                )
        lines.append("")
    pd.DataFrame(summary).to_csv(out / "chen2022_figures.csv", index=False)
    text = "\n".join(lines)
    (out / "chen2022.md").write_text(text)
    return text
