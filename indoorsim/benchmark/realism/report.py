"""Simulated beside real: the realism table of ``leaderboards/realism.md``.

:func:`simulate_motion` walks every carrying mode over bundled and
generated sites and seeds and measures each walk with the same
:func:`~indoorsim.benchmark.realism.motion.motion_statistics` as the real logs;
:func:`compare` puts each (mode, statistic) beside its real range and says,
per site, whether the site's median over seeds lies inside it;
:func:`simulate_magnetic` does the same for the field along handheld walks
(:mod:`~indoorsim.benchmark.realism.magnetic`);
:func:`write_report` writes the Markdown tables, the CSVs and overlay plots.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from indoorsim.benchmark.realism.magnetic import MAGNETIC_KEYS, magnetic_statistics
from indoorsim.benchmark.realism.motion import MOTION_KEYS, motion_statistics
from indoorsim.benchmark.realism.reference import (
    MAGNETIC_MODE,
    MODELLED_MODES,
    QUOTED_RANGES,
    REAL_MAGNETIC_CSV,
    REAL_MOTION_CSV,
    REAL_PROFILES_CSV,
    load_real_magnetic,
    load_real_motion,
    load_real_profiles,
    mean_profiles,
    real_magnetic_table,
    real_motion_table,
    real_profiles,
)
from indoorsim.scenario.generate import generate
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate
from indoorsim.util.provenance import realdata_dir
from indoorsim.world.site import Site

__all__ = [
    "COMPARED",
    "COMPARED_MAGNETIC",
    "RealismConfig",
    "compare",
    "markdown",
    "run_realism",
    "simulate_magnetic",
    "simulate_motion",
    "write_report",
]

COMPARED: dict[str, str] = {
    "step_hz": "step rate (Hz)",
    "cadence_ratio": "‖a‖ spectral peak / cadence",
    "acc_std": "‖a‖ std (m/s²)",
    "acc_p2p": "‖a‖ peak-to-peak per stride (m/s²)",
    "acc_crest": "‖a‖ crest factor",
    "acc_kurtosis": "‖a‖ excess kurtosis",
    "share_step": "‖a‖ power at the step rate",
    "share_2nd": "‖a‖ power at twice the step rate",
    "share_stride": "‖a‖ power at half the step rate",
    "gyro_rms_1": "gyro RMS, largest axis (rad/s)",
    "gyro_rms_2": "gyro RMS, middle axis (rad/s)",
    "gyro_rms_3": "gyro RMS, smallest axis (rad/s)",
    "heading_jitter": "fused heading jitter (°)",
    "gyro_drift": "gyro heading drift ∫ω·ĝ, its size (°/stride)",
}
"""The statistics judged, with their labels (``walking_s`` is shown, not judged)."""

COMPARED_MAGNETIC: dict[str, str] = {
    "share_long": "share of ‖m‖ variance at wavelengths > 10 m",
    "std_long": "std of the > 10 m band (µT)",
    "std_mid": "std of the 2–10 m band (µT)",
    "std_short": "std of the 0.5–2 m band (µT)",
    "corr_length": "1/e correlation length (m)",
    "mag_std": "‖m‖ std (µT)",
}
"""The magnetic statistics judged (``path_m`` is recorded, not judged)."""

BY_SIZE = frozenset({"gyro_drift"})
"""Statistics judged by their size: the pocket's coning turns the gyro heading one way
or the other with the pocket's side, so a site's median over walks of the signed
drift says more about which sides its seeds drew than about how large the drift is."""

Progress = Callable[[str], None]


@dataclass(frozen=True, kw_only=True)
class RealismConfig:
    """Which simulated walks the real ones are compared with."""

    bundled: tuple[str, ...] = ("han2023_corridor", "chen2022_office")
    generated: tuple[tuple[str, int], ...] = (("office", 0), ("basement", 1))
    """Procedural buildings as (kind, seed)."""
    modes: tuple[str, ...] = MODELLED_MODES
    seeds: tuple[int, ...] = (0, 1, 2, 3, 4)
    """Walks per site and mode: five, so that a site's median is not one walker's."""
    device: str = "nexus_5x"
    field_generated: tuple[tuple[str, int], ...] = (
        ("office", 0),
        ("basement", 1),
        ("open_hall", 2),
    )
    """Procedural buildings whose magnetic field is compared: three kinds, as the
    "Environment realism" issue asks, beside the bundled sites."""


def _sites(
    config: RealismConfig, generated: tuple[tuple[str, int], ...] | None = None
) -> list[tuple[str, Site]]:
    sites = [(name, load_site(name)) for name in config.bundled]
    for kind, seed in config.generated if generated is None else generated:
        sites.append((f"generated {kind} (seed {seed})", load_site(generate(kind, seed=seed))))
    return sites


def simulate_motion(
    config: RealismConfig = RealismConfig(), *, progress: Progress | None = None
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Motion statistics of every simulated walk (site × mode × seed, one row each) and
    each mode's mean profiles (:func:`~indoorsim.benchmark.realism.reference.mean_profiles`).

    Each site is walked on its first route (a long walk through it).
    """
    rows = []
    profiles = []
    for label, site in _sites(config):
        route = next(iter(site.scenario.routes))
        for mode in config.modes:
            for seed in config.seeds:
                if progress:
                    progress(f"{label} {mode} seed {seed}")
                rec = simulate(site, route=route, mode=mode, device=config.device, seed=seed)
                rows.append({"site": label, "mode": mode, "seed": seed, **motion_statistics(rec)})
                profiles.append(mean_profiles([(mode, rec)]))
    table = pd.DataFrame(rows, columns=["site", "mode", "seed", *MOTION_KEYS])
    return table, _pooled(profiles)


def simulate_magnetic(
    config: RealismConfig = RealismConfig(), *, progress: Progress | None = None
) -> pd.DataFrame:
    """Along-path field statistics of handheld walks (site × seed, one row each).

    Each site is walked on its longest route (the real magnetic walks are
    46–346 m long, and the > 10 m band needs distance), held in the hand like
    the real walks' phones and tablets.
    """
    rows = []
    for label, site in _sites(config, config.field_generated):
        lengths = {}
        for route in site.scenario.routes:
            rec = simulate(site, route=route, mode="handheld", device=config.device, seed=0)
            lengths[route] = magnetic_statistics(rec)["path_m"]
        route = max(lengths, key=lengths.__getitem__)
        for seed in config.seeds:
            if progress:
                progress(f"{label} magnetic seed {seed}")
            rec = simulate(site, route=route, mode="handheld", device=config.device, seed=seed)
            rows.append(
                {"site": label, "mode": MAGNETIC_MODE, "seed": seed, "route": route}
                | magnetic_statistics(rec)
            )
    return pd.DataFrame(rows, columns=["site", "mode", "seed", "route", *MAGNETIC_KEYS])


def _pooled(profiles: list[pd.DataFrame]) -> pd.DataFrame:
    """Per-walk profiles averaged per mode and curve (each walk weighs the same)."""
    if not profiles:
        return pd.DataFrame(columns=["mode", "curve", "x", "y", "walks"])
    every = pd.concat(profiles, ignore_index=True)
    pooled = every.groupby(["mode", "curve", "x"], sort=False).agg(
        y=("y", "mean"), walks=("y", "size")
    )
    return pooled.reset_index()


def real_range(real: pd.DataFrame, mode: str, key: str) -> tuple[float, float, str]:
    """The real range of a statistic in a mode: measured here, quoted, or their union."""
    values = real.loc[real["mode"] == mode, key].dropna() if key in real else pd.Series([])
    if key in BY_SIZE:
        values = values.abs()
    quoted = QUOTED_RANGES.get((mode, key))
    lows, highs, sources = [], [], []
    if len(values):
        lows.append(float(values.min()))
        highs.append(float(values.max()))
        sources.append(f"{len(values)} real walks")
    if quoted is not None:
        lows.append(quoted[0])
        highs.append(quoted[1])
        sources.append("quoted")
    if not lows:
        return math.nan, math.nan, "no real data"
    return min(lows), max(highs), " + ".join(sources)


def compare(
    real: pd.DataFrame, sim: pd.DataFrame, compared: Mapping[str, str] = COMPARED
) -> pd.DataFrame:
    """Per (mode, statistic): the real range, each site's median over seeds, inside or not
    (``sites_inside`` of ``sites``)."""
    judged = sim[["mode", "site", *compared]].copy()
    for key in BY_SIZE & set(compared):
        judged[key] = judged[key].abs()
    medians = judged.groupby(["mode", "site"], sort=False)[list(compared)].median()
    sites = list(dict.fromkeys(sim["site"]))
    rows = []
    for mode in dict.fromkeys(sim["mode"]):
        for key in compared:
            low, high, source = real_range(real, mode, key)
            row = {"mode": mode, "statistic": key, "real_low": low, "real_high": high}
            row["real_source"] = source
            inside = 0
            for site in sites:
                value = float(medians.loc[(mode, site), key])
                row[site] = value
                inside += bool(low <= value <= high)
            row["sites_inside"] = inside if np.isfinite(low) else np.nan
            row["sites"] = len(sites)
            rows.append(row)
    return pd.DataFrame(rows)


def _cell(value: float, low: float, high: float) -> str:
    if not np.isfinite(value):
        return "–"
    text = f"{value:.3g}"
    if not np.isfinite(low):
        return text
    return f"{text} ✓" if low <= value <= high else f"**{text}** ✗"


def markdown(
    table: pd.DataFrame, sites: Sequence[str], labels: Mapping[str, str] = COMPARED
) -> str:
    """The comparison as Markdown: one table per mode, a ✓ where a site's median is inside."""
    lines = []
    for mode, part in table.groupby("mode", sort=False):
        head = ["statistic", "real range", "source", *sites]
        lines += [f"### {mode}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for _, r in part.iterrows():
            low, high = r["real_low"], r["real_high"]
            rng = f"{low:.3g} – {high:.3g}" if np.isfinite(low) else "–"
            cells = [labels[r["statistic"]], rng, r["real_source"]]
            cells += [_cell(float(r[s]), low, high) for s in sites]
            lines.append("| " + " | ".join(cells) + " |")
        judged = part["sites_inside"].dropna()
        lines += [
            "",
            f"{int((judged == len(sites)).sum())} of {len(judged)} statistics inside their "
            f"real range on every site.",
            "",
        ]
    return "\n".join(lines)


def write_report(
    out: Path,
    real: pd.DataFrame,
    sim: pd.DataFrame,
    real_curves: pd.DataFrame | None = None,
    sim_curves: pd.DataFrame | None = None,
    *,
    real_field: pd.DataFrame | None = None,
    sim_field: pd.DataFrame | None = None,
) -> pd.DataFrame:
    """``realism.md``, ``realism_motion.csv`` (the comparison), ``realism_sim_walks.csv``,
    with profiles given ``realism_motion.png`` (real and simulated curves overlaid), and
    with the field tables given ``realism_magnetic.csv`` and ``realism_sim_field.csv``.

    Returns:
        The comparison tables, motion then magnetic, one row per (mode, statistic).
    """
    out.mkdir(parents=True, exist_ok=True)
    if real_curves is not None and sim_curves is not None:
        from indoorsim.plots.results import plot_realism_profiles

        fig = plot_realism_profiles(real_curves, sim_curves)
        fig.savefig(out / "realism_motion.png", dpi=110, bbox_inches="tight")
    table = compare(real, sim)
    sites = list(dict.fromkeys(sim["site"]))
    table.to_csv(out / "realism_motion.csv", index=False)
    sim.to_csv(out / "realism_sim_walks.csv", index=False)
    n_real = real.groupby("mode").size().to_dict()
    n_seeds = int(sim.groupby(["mode", "site"]).size().median())
    lines = [
        "# Realism: simulated phones and buildings beside real ones",
        "",
        "## Motion",
        "",
        "The same statistics (`indoorsim.benchmark.realism.motion`) on real logs and on "
        "simulated walks, over the walking parts found from the accelerometer alone, at a "
        "common 50 Hz. Real range: min–max over the real walks of that carrying mode "
        "(" + ", ".join(f"{m}: {n}" for m, n in sorted(n_real.items())) + " walks from "
        "`shared/realdata`: ILC 2020 traces, MIT; Oxford step counter, CC BY 4.0), joined "
        "with the ranges quoted by the Motion realism issue where it gives one. Simulated: "
        f"each site's median over {n_seeds} seeds (the gyro heading drift by its size, "
        "real and simulated: its sign goes with the pocket's side); ✓ inside the real "
        "range, ✗ outside. "
        "`realism_motion.png` overlays the real and simulated ‖a‖ and ‖ω‖ spectra, "
        "‖a‖ histograms and ‖a‖ over a stride of each mode.",
        "",
        markdown(table, sites),
    ]
    tables = [table]
    if real_field is not None and sim_field is not None:
        field = compare(real_field, sim_field, COMPARED_MAGNETIC)
        field_sites = list(dict.fromkeys(sim_field["site"]))
        field.to_csv(out / "realism_magnetic.csv", index=False)
        sim_field.to_csv(out / "realism_sim_field.csv", index=False)
        measured = real_field.dropna(subset=["mag_std"])
        counts = measured.groupby("dataset").size().to_dict()
        routes = sim_field.groupby("site", sort=False)["route"].first()
        lines += [
            "## Magnetic field",
            "",
            "The same statistics (`indoorsim.benchmark.realism.magnetic`) of ‖m‖ against the "
            "distance walked, on a 0.1 m grid, detrended by a straight line; wavelength bands "
            "cut exactly by the DFT. Real range: min–max over the real walks of at least 40 m ("
            + ", ".join(f"{n} from {d}" for d, n in sorted(counts.items()))
            + "; mag-slam-1d: handheld iPad with ARKit positions, MIT; ILC traces: positions "
            "between the surveyed waypoints), joined with the ranges quoted by the "
            "Environment realism issue. Simulated: each site's median over "
            f"{int(sim_field.groupby('site').size().median())} handheld walks of its longest "
            "route (" + ", ".join(f"{site}: {route}" for site, route in routes.items()) + ").",
            "",
            markdown(field, field_sites, COMPARED_MAGNETIC),
        ]
        tables.append(field)
    (out / "realism.md").write_text("\n".join(lines) + "\n")
    return pd.concat(tables, ignore_index=True)


def run_realism(
    out: Path,
    *,
    config: RealismConfig = RealismConfig(),
    realdata: Path | None = None,
    refresh_reference: bool = False,
    progress: Progress | None = None,
) -> pd.DataFrame:
    """Measure simulated walks, compare them with the real tables, write ``out/realism.md``.

    Args:
        out: the output folder (``leaderboards/`` for the committed report).
        config: the simulated sites, modes, seeds and phone.
        realdata: the real-data folder; when given (or when ``refresh_reference``),
            the real statistics are measured from its logs instead of read from the
            committed tables.
        refresh_reference: also write the measured real tables over the committed ones.
        progress: called with a line of text before each simulated walk.

    Returns:
        The comparison tables (one row per mode and statistic; the magnetic rows have
        mode ``"magnetic"``).
    """
    if realdata is not None or refresh_reference:
        folder = realdata_dir(realdata)
        real, real_curves = real_motion_table(folder), real_profiles(folder)
        real_field = real_magnetic_table(folder)
        if refresh_reference:
            real.to_csv(REAL_MOTION_CSV, index=False, float_format="%.6g")
            real_curves.to_csv(REAL_PROFILES_CSV, index=False, float_format="%.6g")
            real_field.to_csv(REAL_MAGNETIC_CSV, index=False, float_format="%.6g")
    else:
        real, real_curves = load_real_motion(), load_real_profiles()
        real_field = load_real_magnetic()
    sim, sim_curves = simulate_motion(config, progress=progress)
    sim_field = simulate_magnetic(config, progress=progress)
    return write_report(
        out, real, sim, real_curves, sim_curves, real_field=real_field, sim_field=sim_field
    )
