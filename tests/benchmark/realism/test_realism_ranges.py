"""The simulator against real walks: what lies inside its real range stays inside.

The realism board's own comparison (:func:`compare` over the default
:class:`RealismConfig`: four sites, five seeds, every modelled mode; and the
magnetic field and WiFi along handheld walks on five sites), run once for the module.
Each (mode, statistic) whose median lies inside the real range on every site
is pinned here, so a change to the walker, the phone or the building that
pushes one out fails; the others are expected failures, listed by the issues
"Motion realism" and "Environment realism" as work still to do, and report
XPASS when a change brings them in (then move them to ``INSIDE``).
"""

from __future__ import annotations

import math

import pandas as pd
import pytest

from indoorsim.benchmark.realism.motion import HELD_KEYS, HELD_MODE, motion_statistics
from indoorsim.benchmark.realism.reference import (
    LIGHT_MODE,
    LINE_MODE,
    MAGNETIC_MODE,
    MODELLED_MODES,
    RADIO_MODE,
    load_real_magnetic,
    load_real_motion,
    load_real_radio,
)
from indoorsim.benchmark.realism.report import (
    COMPARED,
    COMPARED_LIGHT,
    COMPARED_LINE,
    COMPARED_MAGNETIC,
    COMPARED_RADIO,
    RealismConfig,
    compare,
    compare_environment,
    real_range,
    simulate_environment,
    simulate_motion,
)
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate

INSIDE = {
    "handheld": {
        "step_hz",
        "cadence_ratio",
        "acc_std",
        "acc_p2p",
        "acc_crest",
        "acc_kurtosis",
        "share_step",
        "share_2nd",
        # gyro_rms_2 and _3: under the real range's floor on the generated office, whose
        # walker bounces gently (2.2 m/s² at the step rate), and the middle axis on the
        # Chen2022 office; the real range of the held gyro comes from the 16 vigorous
        # ILC surveyors (3.7 median) alone.
        "share_stride",
        "gyro_rms_1",
        # Inside since the walker weaves off its line (v10: 1.87-2.15°; 1.71-1.85 before).
        "heading_jitter",
        "gyro_drift",
        "surge_step",
        "sway_stride",
        "bob_step",
        "yaw_stride",
        "sway_step",
        "roll_jerk",
        "nod_2nd",
        "bob_phase_2nd",
        # Since the ground's push drives the body's surge (v9: braking as the leading
        # leg takes the load, pushing off before; walker.motion.surge_waveforms), held
        # phones surge 0.20-0.30 m/s² at twice the step rate (real 0.09-0.54); before,
        # one sinusoid left 0.05-0.08.
        "surge_2nd",
        # The real range is wide (-51 to +57°, median +23°: the ILC traces); the
        # simulated hands read -2 to +0.4°, their twins -15° (sim_to_real).
        "surge_phase",
    },
    "calling": {
        "step_hz",
        "cadence_ratio",
        "acc_crest",
        "acc_kurtosis",
        "share_2nd",
        # gyro_rms_1: inside since the Tyrex benchmark's phoning walks join the real
        # range (0.59-0.86 rad/s; the quoted range alone ends at 0.65).
        "gyro_rms_1",
        "gyro_rms_2",
        "gyro_rms_3",
    },
    # Since v11 (a firm elbow and wrist, the elbow a little bent, the swing lagging
    # the legs): the gyro against the Tyrex benchmark's 18 swinging-hand walks, the
    # step-rate peak and the second harmonic. Still outside, all against the one
    # Oxford swinging-arm walker: the step-rate share on the slower walkers' sites
    # (0.60-0.63, real 0.68-0.70), the stride-rate share (0.07-0.12, real 0.12), the
    # peak-to-peak per stride (6.8-11.3, real 6.7-6.8) and ‖a‖ std on the generated
    # office (1.58, real from 1.9).
    "dangling": {
        "step_hz",
        "cadence_ratio",
        "acc_crest",
        "acc_kurtosis",
        "share_2nd",
        "gyro_rms_1",
        "gyro_rms_2",
        "gyro_rms_3",
    },
    "pocketed": {
        "step_hz",
        "cadence_ratio",
        "acc_std",
        "acc_p2p",
        "acc_crest",
        "acc_kurtosis",
        "share_2nd",
        "share_stride",
        "gyro_drift",
    },
}
"""(mode, statistic) inside the real range on every site, per mode."""

INSIDE_ENVIRONMENT: dict[str, set[str]] = {
    # std_mid: 1.09 and 1.26 µT on the generated basements and halls (their median
    # building; real 1.38 to 4.6). share_long: the generated offices' median building
    # has 0.60 of its variance beyond 10 m (0.48 to 0.69 over five; real 0.64 to
    # 0.83), 0.645 before the APs' density rule redrew them: borderline either way.
    MAGNETIC_MODE: {"std_long", "std_short", "corr_length", "mag_std"},
    RADIO_MODE: {
        "rss_mean",
        "rss_p90",
        "aps_per_scan",
        "scan_interval",
        "static_std",
        "visit_std",
        "miss_share",
    },
    LIGHT_MODE: {"lux_median", "lux_median_car_park"},
    LINE_MODE: {"weave_cm", "weave_deg"},
}
"""Magnetic, WiFi and light statistics inside their real range on every site, each
generated kind by its median building (the issue "Environment realism": the generated
basements and halls' fields are too weak at 2–10 m, the generated offices' too
weak beyond 10 m for their 2–10 m structure; the simulated light's 95/5 range
is too narrow, and its dark share and changes off, in lit corridors)."""

_REAL = load_real_motion()
_JUDGED = [
    (mode, key)
    for mode in MODELLED_MODES
    for key in COMPARED
    if math.isfinite(real_range(_REAL, mode, key)[0])
    and (key not in HELD_KEYS or mode == HELD_MODE)
]


_OUTSIDE = pytest.mark.xfail(reason="outside its real range on some site today", strict=False)


def _case(mode: str, key: str):
    marks = () if key in INSIDE.get(mode, set()) else _OUTSIDE
    return pytest.param(mode, key, id=f"{mode}-{key}", marks=marks)


_ENVIRONMENT = (
    [(MAGNETIC_MODE, key) for key in COMPARED_MAGNETIC]
    + [(RADIO_MODE, key) for key in COMPARED_RADIO]
    + [(LIGHT_MODE, key) for key in COMPARED_LIGHT]
    + [(LINE_MODE, key) for key in COMPARED_LINE]
)


def _environment_case(mode: str, key: str):
    marks = () if key in INSIDE_ENVIRONMENT[mode] else _OUTSIDE
    return pytest.param(mode, key, id=f"{mode}-{key}", marks=marks)


@pytest.fixture(scope="module")
def comparison() -> pd.DataFrame:
    sim, _ = simulate_motion(RealismConfig())
    return compare(_REAL, sim).set_index(["mode", "statistic"])


@pytest.fixture(scope="module")
def environment_comparison() -> pd.DataFrame:
    sim = simulate_environment(RealismConfig())
    tables = compare_environment(load_real_magnetic(), load_real_radio(), sim)
    return pd.concat(tables).set_index(["mode", "statistic"])


def _assert_inside(table: pd.DataFrame, mode: str, key: str) -> None:
    row = table.loc[(mode, key)]
    outside = {
        site: round(float(row[site]), 3)
        for site in table.columns[
            table.columns.get_loc("real_source") + 1 : table.columns.get_loc("sites_inside")
        ]
        if not row["real_low"] <= row[site] <= row["real_high"]
    }
    assert row["sites_inside"] == row["sites"], (
        f"{mode} {key}: real {row['real_low']:.3g}–{row['real_high']:.3g}, outside on {outside}"
    )


def test_every_pinned_statistic_has_a_real_range():
    pinned = {(mode, key) for mode, keys in INSIDE.items() for key in keys}
    assert pinned <= set(_JUDGED)
    assert INSIDE_ENVIRONMENT[MAGNETIC_MODE] <= set(COMPARED_MAGNETIC)
    assert INSIDE_ENVIRONMENT[RADIO_MODE] <= set(COMPARED_RADIO)
    assert INSIDE_ENVIRONMENT[LIGHT_MODE] <= set(COMPARED_LIGHT)
    assert INSIDE_ENVIRONMENT[LINE_MODE] <= set(COMPARED_LINE)


@pytest.mark.parametrize(("mode", "key"), [_case(m, k) for m, k in _JUDGED])
def test_the_simulated_median_lies_inside_the_real_range_on_every_site(comparison, mode, key):
    _assert_inside(comparison, mode, key)


@pytest.mark.parametrize(("mode", "key"), [_environment_case(m, k) for m, k in _ENVIRONMENT])
def test_the_simulated_building_lies_inside_the_real_range_on_every_site(
    environment_comparison, mode, key
):
    _assert_inside(environment_comparison, mode, key)


@pytest.mark.parametrize("seed", [0, 1])
def test_the_pocket_drift_turns_with_the_pockets_side(seed: int):
    # The thigh's roll and twist mirror with the side, so the coning that turns the
    # gyro heading does too: real pockets drift either way, by their side.
    site = load_site("han2023_corridor")
    drift = {
        side: motion_statistics(
            simulate(
                site,
                route="trajectory",
                mode=[(0.0, "pocketed", {"side": side})],
                device=RealismConfig().device,
                seed=seed,
            )
        )["gyro_drift"]
        for side in ("left", "right")
    }
    assert drift["left"] < -0.3 and drift["right"] > 0.3
