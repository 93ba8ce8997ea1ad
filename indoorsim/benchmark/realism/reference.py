"""The real side of the comparison: statistics of real phone logs, measured and committed.

:func:`real_motion_table` reads every real walk of the real-data folder that
has a carrying mode indoorsim models and computes
:func:`~indoorsim.benchmark.realism.motion.motion_statistics` on it, one row
per walk, with the data set and its licence. The result is committed as
``real_motion.csv`` beside this module, so that the comparison runs where the
raw files are absent; :func:`load_real_motion` reads it and
``indoorsim realism --refresh-reference`` writes it again from the raw files.
:func:`real_magnetic_table` does the same for the field along the path of every
real walk with a magnetometer and known positions (``real_magnetic.csv``).

Some statistics need streams no log in the shared real-data folder has (a
gyroscope in a pocket, at the ear or in a swinging hand). Two sources fill them:
the Inria Tyrex attitude benchmark's walks (:data:`TYREX_SOURCE`, read from a copy
of its repository placed in a real-data folder, their rows committed with the
others: a source whose files are absent keeps its committed rows when the table is
refreshed, :func:`merge_refreshed`), and :data:`QUOTED_RANGES`, the real ranges
measured on other real walks by the review that opened the "Motion realism" issue,
marked as quoted, so a reader sees which ranges this repository can reproduce and
which it takes on trust.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from indoorsim.benchmark.realism.line import LINE_KEYS, line_statistics
from indoorsim.benchmark.realism.magnetic import MAGNETIC_KEYS, magnetic_statistics
from indoorsim.benchmark.realism.motion import MOTION_KEYS, motion_profiles, motion_statistics
from indoorsim.benchmark.realism.radio import (
    RADIO_KEYS,
    level_statistics,
    radio_statistics,
    static_statistics,
)
from indoorsim.io.recording import Recording
from indoorsim.walker.real_walkers import VIGOUR_FIELDS

__all__ = [
    "GYRO_KEYS",
    "HELD_FLAT",
    "LIGHT_MODE",
    "LINE_MODE",
    "MAGNETIC_MODE",
    "MAGNETIC_SOURCES",
    "QUOTED_RANGES",
    "RADIO_MODE",
    "REAL_MAGNETIC_CSV",
    "REAL_MOTION_CSV",
    "REAL_PROFILES_CSV",
    "REAL_RADIO_CSV",
    "REAL_SOURCES",
    "TYREX_SOURCE",
    "RealSource",
    "load_real_magnetic",
    "load_real_motion",
    "load_real_profiles",
    "load_real_radio",
    "mean_profiles",
    "merge_refreshed",
    "real_magnetic_table",
    "real_motion_table",
    "real_profiles",
    "real_radio_table",
    "real_walker_rows",
    "real_walker_table",
    "uji_scans",
]

REAL_MOTION_CSV = Path(__file__).with_name("real_motion.csv")
REAL_PROFILES_CSV = Path(__file__).with_name("real_profiles.csv")
REAL_MAGNETIC_CSV = Path(__file__).with_name("real_magnetic.csv")
REAL_RADIO_CSV = Path(__file__).with_name("real_radio.csv")


@dataclass(frozen=True, kw_only=True)
class RealSource:
    """A real data set: where its walks are under the real-data folder, and its terms."""

    name: str
    pattern: str
    """Glob of its walks (files or folders) relative to the real-data folder."""
    licence: str
    phone: str
    statistics: tuple[str, ...] | None = None
    """The statistics its walks are a reference for (the others are left NaN); None: all."""
    min_walking_s: float = 0.0
    """A walk with less walking found in it gives no statistics."""


GYRO_KEYS = ("gyro_rms_1", "gyro_rms_2", "gyro_rms_3")

TYREX_SOURCE = RealSource(
    name="tyrex-attitude",
    pattern="tyrex-attitude/datasets/*/*_*_*Dist_*",
    licence="CeCILL v2.1 (Inria Tyrex; statistics only, no data copied)",
    phone="Nexus 5 ~200 Hz, iPhone 4S / 5 ~100 Hz; accelerometer and gyroscope",
    statistics=GYRO_KEYS,
    min_walking_s=30.0,
)
"""The walks of Michel et al.'s attitude benchmark (PerCom 2017;
github.com/tyrex-team/benchmarks-attitude-smartphones, commit 8ad1100): 3 walkers × 3
phones × 2 runs, texting, phoning, swinging, front and back pocket, about two minutes
each, looping a motion-capture room. They are the only real gyroscope logs here of a
phone at the ear, in a swinging hand and in a pocket, and are a reference for the gyro
RMS only: their walkers step 1.2–1.9 times a second and turn every few metres, so their
‖a‖ levels and spectral shares belong to slow walking round a room (with the phone in
front or at the ear the walking finder, tuned on brisker walks, finds under 30 s of
walking in 24 of the 36; those walks are left out)."""


REAL_SOURCES = (
    RealSource(
        name="ms-indoor-location-2020",
        pattern="ms-indoor-location-2020/site1/F1/path_data_files/*.txt",
        licence="MIT (XYZ10 / Microsoft Research)",
        phone="OPPO PBCM10, held flat, 50 Hz",
    ),
    RealSource(
        name="oxford-stepcounter",
        pattern="oxford-stepcounter/optimisation/*_*_*_*_*",
        licence="CC BY 4.0 (University of Oxford)",
        phone="Google Pixel 405 Hz / Samsung ~210 Hz, accelerometer only",
    ),
    RealSource(
        name="oxford-stepcounter",
        pattern="oxford-stepcounter/validation/user*_*.csv",
        licence="CC BY 4.0 (University of Oxford)",
        phone="Samsung Galaxy S6, 100 Hz, accelerometer only",
    ),
    TYREX_SOURCE,
)

MAGNETIC_SOURCES = (
    RealSource(
        name="mag-slam-1d",
        pattern="mag-slam-1d/*.mat",
        licence="MIT (Kok & Solin 2024)",
        phone="iPad, handheld, magnetometer 10 Hz + ARKit positions",
    ),
    RealSource(
        name="ms-indoor-location-2020",
        pattern="ms-indoor-location-2020/site1/F1/path_data_files/*.txt",
        licence="MIT (XYZ10 / Microsoft Research)",
        phone="OPPO PBCM10, held flat, 50 Hz; positions between surveyed waypoints",
    ),
)
"""Real walks with a magnetometer and known positions along the path."""

MAGNETIC_MODE = "magnetic"
"""The ``mode`` of the magnetic rows: the field is the building's, whatever the carry."""

LINE_MODE = "walking line"
"""The ``mode`` of the walked line's rows (the walker's weave, measured where positions
are dense: the magnetic-SLAM walks' ARKit track, a simulated walk's truth)."""

RADIO_MODE = "wifi"
"""The ``mode`` of the WiFi rows."""

LIGHT_MODE = "light"
"""The ``mode`` of the light rows (quoted ranges only: no real light log is local)."""

UJI_FOLDER = "uji-lib-longterm-wifi/db"
UJI_LICENCE = "CC BY 4.0 (Mendoza-Silva et al. 2018)"
_UJI_NOT_HEARD = 100.0

MODELLED_MODES = ("handheld", "calling", "dangling", "pocketed")

_ALL_MODES_QUOTED = {
    # "all" rows of the table: the shape of ‖a‖ and the cadence.
    "acc_crest": (2.5, 12.0),
    "share_2nd": (0.02, 0.11),
    "step_hz": (1.69, 2.01),
    "cadence_ratio": (0.94, 1.01),
}

QUOTED_RANGES: dict[tuple[str, str], tuple[float, float]] = {
    **{(mode, key): r for mode in MODELLED_MODES for key, r in _ALL_MODES_QUOTED.items()},
    ("handheld", "acc_kurtosis"): (-0.8, 15.0),
    ("calling", "acc_kurtosis"): (-0.8, 15.0),
    ("dangling", "acc_kurtosis"): (-0.8, 15.0),
    ("pocketed", "acc_kurtosis"): (0.8, 15.0),
    ("handheld", "acc_std"): (1.7, 4.0),
    ("dangling", "acc_std"): (1.9, 3.2),
    ("pocketed", "acc_std"): (3.7, 6.2),
    ("handheld", "gyro_rms_1"): (0.37, 0.92),
    ("handheld", "gyro_rms_2"): (0.25, 0.72),
    ("handheld", "gyro_rms_3"): (0.17, 0.51),
    ("calling", "gyro_rms_1"): (0.2, 0.65),
    ("calling", "gyro_rms_2"): (0.19, 0.53),
    ("calling", "gyro_rms_3"): (0.16, 0.48),
    ("pocketed", "gyro_rms_1"): (1.35, 1.45),
    ("pocketed", "gyro_rms_2"): (0.96, 1.34),
    ("pocketed", "gyro_rms_3"): (0.78, 0.93),
    ("pocketed", "share_stride"): (0.0, 0.02),
    ("handheld", "heading_jitter"): (1.8, 6.8),
    ("pocketed", "gyro_drift"): (0.0, 2.0),  # 0 to 2 °/stride, either sign with the pocket's side
    # The "Environment realism" issue's magnetic rows (ARKit walks and the MS traces).
    (MAGNETIC_MODE, "share_long"): (0.64, 0.82),
    (MAGNETIC_MODE, "std_long"): (2.0, 8.0),
    (MAGNETIC_MODE, "std_mid"): (1.4, 4.6),
    (MAGNETIC_MODE, "std_short"): (0.2, 1.1),
    (MAGNETIC_MODE, "corr_length"): (1.8, 4.7),
    (MAGNETIC_MODE, "mag_std"): (1.7, 9.5),
    # Its WiFi rows: ILC traces and UJI fingerprints; APs per scan in offices, libraries
    # and museums; the scan interval of a logging app.
    (RADIO_MODE, "rss_mean"): (-87.0, -68.0),
    (RADIO_MODE, "rss_p90"): (-80.0, -53.0),
    (RADIO_MODE, "static_std"): (3.2, 4.4),
    (RADIO_MODE, "aps_per_scan"): (14.0, 28.0),
    (RADIO_MODE, "scan_interval"): (2.0, 4.0),
    # Its light rows: real handheld logs on lit floors (a lit ground floor for the dark
    # share). The median depends on the building: corridors and offices 50–300 lx,
    # basements 9–18 lx (each judged on its kinds of building only).
    (LIGHT_MODE, "lux_median"): (50.0, 300.0),
    (LIGHT_MODE, "lux_median_car_park"): (9.0, 18.0),
    (LIGHT_MODE, "lux_ratio"): (13.0, 95.0),
    (LIGHT_MODE, "dark_share"): (0.29, 0.37),
    (LIGHT_MODE, "dlog_std"): (0.08, 0.14),
}
"""Real ranges quoted from the "Motion realism" and "Environment realism" issues (real
walks measured by the reviews that opened them, some from data sets not in the real-data
folder), by (mode, statistic).
Its peak-to-peak figures are left out: they were taken at each log's own rate over whole
walks, not per stride at the common rate. So are its dangling gyro figures (single values,
≈ 3.5 / 2.0 / 1.8 rad/s, source not named): the 18 swinging-hand walks of the Tyrex
benchmark (:data:`TYREX_SOURCE`) measure 1.16–2.39 / 0.73–1.43 / 0.38–1.15 rad/s, none of
them near those figures.
The comparison takes the union of a quoted range and the range measured here."""


def _real_walks(realdata: Path) -> list[tuple[RealSource, Path, Recording, str]]:
    walks = []
    for source in REAL_SOURCES:
        for path in sorted(realdata.glob(source.pattern)):
            rec = Recording.load(path)
            mode = rec.meta.get("mode")
            # Bags, armbands, neck pouches: no indoorsim mode to compare them with.
            if mode in MODELLED_MODES:
                walks.append((source, path, rec, mode))
    return walks


def _source_statistics(source: RealSource, rec: Recording) -> dict[str, float]:
    """:func:`motion_statistics` of a walk, NaN where its source is no reference."""
    stats = motion_statistics(rec)
    walked = stats["walking_s"] >= source.min_walking_s
    wanted = set(stats if source.statistics is None else source.statistics)
    return {
        key: value if key == "walking_s" or (walked and key in wanted) else np.nan
        for key, value in stats.items()
    }


def real_motion_table(realdata: Path) -> pd.DataFrame:
    """Motion statistics of every real walk in a modelled carrying mode, one row per walk."""
    rows = [
        {
            "dataset": source.name,
            "walk": path.name,
            "mode": mode,
            "phone": source.phone,
            "licence": source.licence,
            **_source_statistics(source, rec),
        }
        for source, path, rec, mode in _real_walks(realdata)
    ]
    return pd.DataFrame(rows, columns=["dataset", "walk", "mode", "phone", "licence", *MOTION_KEYS])


def merge_refreshed(fresh: pd.DataFrame, committed: pd.DataFrame) -> pd.DataFrame:
    """``fresh`` (measured from a real-data folder) with the ``committed`` rows of every
    data set ``fresh`` has no walk of: a source whose files are not in that folder (the
    Tyrex walks, kept outside the shared folder for their licence) keeps its rows."""
    kept = committed[~committed["dataset"].isin(set(fresh["dataset"]))]
    frames = [frame for frame in (fresh, kept) if len(frame)]
    return pd.concat(frames, ignore_index=True) if frames else fresh


HELD_FLAT: list[tuple[float, str, dict[str, float]]] = [(0.0, "handheld", {"pitch_deg": 0.0})]
"""How the ILC surveyors carried their phones: flat in the hand (their traces' own
attitude shows it), the mode their walkers' vigour is fitted through."""


def real_walker_rows(source: RealSource, paths: list[Path]) -> list[dict]:
    """One row per real walk whose walker ``indoorsim calibrate`` fits in full: its
    speed from the waypoints and its vigour converged inside its ranges (a walk too
    short to measure, or one whose fit ends at a range's end, is left out: it says
    more of the walk than of the walker)."""
    from indoorsim.benchmark.realism.calibrate import calibrate  # calibrate simulates walks

    rows = []
    for path in paths:
        cal = calibrate(Recording.load(path), name=path.name, mode=HELD_FLAT)
        w = cal.walker
        failed = {"walker vigour", "walker vigour, in part"} & set(cal.not_measured)
        if w.speed_mps is None or failed:
            continue
        rows.append(
            {
                "dataset": source.name,
                "walk": path.name,
                "licence": source.licence,
                "height_m": w.height_m,
                "speed_mps": w.speed_mps,
                # A fitted walker's ranges (loading width, heel strikes) are single values.
                **{name: float(np.mean(getattr(w, name))) for name in VIGOUR_FIELDS},
            }
        )
    return rows


def real_walker_table(realdata: Path) -> pd.DataFrame:
    """The vigour of the real walkers whose speed is known — the ILC surveyors, their
    phones held flat — for :mod:`indoorsim.walker.real_walkers`. (The Oxford walks
    have no positions: without a speed their bounce is not told from their step
    length.)"""
    ilc = next(source for source in REAL_SOURCES if source.name == "ms-indoor-location-2020")
    rows = real_walker_rows(ilc, sorted(realdata.glob(ilc.pattern)))
    columns = ["dataset", "walk", "licence", "height_m", "speed_mps", *VIGOUR_FIELDS]
    return pd.DataFrame(rows, columns=columns)


def real_magnetic_table(realdata: Path) -> pd.DataFrame:
    """Along-path field statistics of every real walk with a magnetometer and positions,
    one row per walk (walks shorter than
    :data:`~indoorsim.benchmark.realism.magnetic.MIN_PATH_M` get NaN statistics), and
    the walked line's (:mod:`~indoorsim.benchmark.realism.line`: NaN where the
    positions are surveyed waypoints, not a track)."""
    rows = []
    for source in MAGNETIC_SOURCES:
        for path in sorted(realdata.glob(source.pattern)):
            rec = Recording.load(path)
            rows.append(
                {
                    "dataset": source.name,
                    "walk": path.name,
                    "mode": MAGNETIC_MODE,
                    "phone": source.phone,
                    "licence": source.licence,
                }
                | magnetic_statistics(rec)
                | line_statistics(rec)
            )
    columns = ["dataset", "walk", "mode", "phone", "licence", *MAGNETIC_KEYS, *LINE_KEYS]
    return pd.DataFrame(rows, columns=columns)


def uji_scans(folder: Path) -> pd.DataFrame:
    """One UJI fingerprint set (``<folder>/<set>rss.csv`` and ``crd.csv``) as a table:
    ``x``, ``y``, ``floor``, ``point`` (an id per reference point), ``visit`` (an id per
    run of consecutive scans at one point: one stay) and one column per AP (dBm, NaN
    where not heard — the files' 100)."""
    name = folder.name
    rss = np.loadtxt(folder.parent / f"{name}rss.csv", delimiter=",")
    crd = np.loadtxt(folder.parent / f"{name}crd.csv", delimiter=",")
    if rss.ndim != 2 or crd.shape != (len(rss), 3):
        raise ValueError(f"{folder}: rss {rss.shape} and crd {crd.shape} do not line up")
    table = pd.DataFrame(np.where(rss == _UJI_NOT_HEARD, np.nan, rss))
    table.columns = [f"ap{j:03d}" for j in range(rss.shape[1])]
    where = pd.DataFrame(crd, columns=["x", "y", "floor"])
    where["point"] = where.groupby(["x", "y", "floor"], sort=False).ngroup()
    where["visit"] = (where["point"] != where["point"].shift()).cumsum() - 1
    return pd.concat([where, table], axis=1)


def real_radio_table(realdata: Path) -> pd.DataFrame:
    """WiFi statistics of the real logs, one row per walk or fingerprint set.

    * ILC traces (walking, a mall floor): levels and scan interval. Their APs per
      scan are left out: a mall's 150–480 results per scan, cached ones included,
      say nothing of the offices, corridors and halls simulated here.
    * UJI library sets (standing, 12 repeats per point in two visits): levels, APs
      per scan, the spread over repeats and within a visit, the share of scans that
      miss a strong AP.
    """
    rows = []
    ilc = next(source for source in MAGNETIC_SOURCES if source.name == "ms-indoor-location-2020")
    for path in sorted(realdata.glob(ilc.pattern)):
        stats = radio_statistics(Recording.load(path))
        stats["aps_per_scan"] = np.nan
        rows.append({"dataset": ilc.name, "walk": path.name, "licence": ilc.licence} | stats)
    for rss_file in sorted(realdata.glob(f"{UJI_FOLDER}/*/*rss.csv")):
        name = rss_file.name.removesuffix("rss.csv")
        scans = uji_scans(rss_file.parent / name)
        aps = scans.filter(like="ap").to_numpy()
        stats = dict.fromkeys(RADIO_KEYS, np.nan) | level_statistics(aps.ravel())
        stats["aps_per_scan"] = float(np.median(np.isfinite(aps).sum(axis=1)))
        stats |= static_statistics(aps, scans["point"].to_numpy(), scans["visit"].to_numpy())
        walk = f"{rss_file.parent.name}/{name}"
        rows.append(
            {"dataset": "uji-lib-longterm-wifi", "walk": walk, "licence": UJI_LICENCE} | stats
        )
    columns = ["dataset", "walk", "mode", "licence", *RADIO_KEYS]
    return pd.DataFrame(rows).assign(mode=RADIO_MODE).reindex(columns=columns)


def load_real_radio(path: Path = REAL_RADIO_CSV) -> pd.DataFrame:
    """The committed table of :func:`real_radio_table`."""
    return pd.read_csv(path)


def load_real_magnetic(path: Path = REAL_MAGNETIC_CSV) -> pd.DataFrame:
    """The committed table of :func:`real_magnetic_table`."""
    return pd.read_csv(path)


def mean_profiles(labelled: list[tuple[str, Recording]]) -> pd.DataFrame:
    """Each mode's mean of :func:`motion_profiles` over its recordings: mode, curve, x, y."""
    sums: dict[tuple[str, str], list] = {}
    for mode, rec in labelled:
        for curve, (x, y) in motion_profiles(rec).items():
            entry = sums.setdefault((mode, curve), [x, np.zeros_like(y), 0])
            entry[1] = entry[1] + y
            entry[2] += 1
    frames = [
        pd.DataFrame({"mode": mode, "curve": curve, "x": x, "y": total / n, "walks": n})
        for (mode, curve), (x, total, n) in sums.items()
    ]
    columns = ["mode", "curve", "x", "y", "walks"]
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=columns)


def real_profiles(realdata: Path) -> pd.DataFrame:
    """The mean spectra and ‖a‖ histogram of the real walks of each modelled mode (of the
    sources that are a reference for every statistic)."""
    return mean_profiles(
        [(mode, rec) for source, _, rec, mode in _real_walks(realdata) if source.statistics is None]
    )


def load_real_motion(path: Path = REAL_MOTION_CSV) -> pd.DataFrame:
    """The committed table of :func:`real_motion_table` (or another one written like it)."""
    return pd.read_csv(path)


def load_real_profiles(path: Path = REAL_PROFILES_CSV) -> pd.DataFrame:
    """The committed table of :func:`real_profiles`."""
    return pd.read_csv(path)
