"""The realism comparison: real ranges, the committed real table, inside/outside per site."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from indoorsim.benchmark.realism.light import LIGHT_KEYS
from indoorsim.benchmark.realism.magnetic import MAGNETIC_KEYS
from indoorsim.benchmark.realism.motion import MOTION_KEYS, motion_statistics
from indoorsim.benchmark.realism.radio import RADIO_KEYS
from indoorsim.benchmark.realism.reference import (
    GYRO_KEYS,
    QUOTED_RANGES,
    RADIO_MODE,
    TYREX_SOURCE,
    load_real_magnetic,
    load_real_motion,
    load_real_profiles,
    load_real_radio,
    merge_refreshed,
    real_magnetic_table,
    real_motion_table,
    real_profiles,
    real_radio_table,
    real_walker_table,
)
from indoorsim.benchmark.realism.report import (
    COMPARED,
    COMPARED_LIGHT,
    COMPARED_MAGNETIC,
    COMPARED_RADIO,
    RealismConfig,
    compare,
    markdown,
    real_range,
    simulate_environment,
    simulate_motion,
    write_report,
)
from indoorsim.io.recording import Recording
from indoorsim.scenario.load import load_site
from indoorsim.simulate import simulate
from indoorsim.walker.real_walkers import VIGOUR_FIELDS, load_real_walkers
from tests.conftest import REALDATA


def _real(mode: str, key: str, values: list[float]) -> pd.DataFrame:
    return pd.DataFrame({"mode": mode, key: values})


def test_a_real_range_is_the_measured_one_joined_with_the_quoted_one():
    quoted = QUOTED_RANGES[("pocketed", "acc_std")]
    low, high, source = real_range(_real("pocketed", "acc_std", [4.0, 7.5]), "pocketed", "acc_std")
    assert (low, high) == (quoted[0], 7.5) and source == "2 real logs + quoted"
    low, high, source = real_range(_real("handheld", "acc_p2p", [6.0, 9.0]), "handheld", "acc_p2p")
    assert (low, high, source) == (6.0, 9.0, "2 real logs")
    low, _, source = real_range(_real("handheld", "acc_p2p", []), "calling", "acc_p2p")
    assert math.isnan(low) and source == "no real data"


def test_a_statistic_of_some_kinds_of_building_leaves_the_others_unjudged():
    # APs per scan hold for offices (and libraries, museums): a car park is shown only.
    real = pd.DataFrame({"mode": RADIO_MODE, "aps_per_scan": [14.0, 28.0]})
    sim = pd.DataFrame(
        {"site": ["o", "g"], "kind": ["office", "basement"], "mode": RADIO_MODE, "seed": 0}
    )
    for key in COMPARED_RADIO:
        sim[key] = np.nan
    sim["aps_per_scan"] = [18.0, 9.0]
    table = compare(real, sim, COMPARED_RADIO)
    row = table[table["statistic"] == "aps_per_scan"].iloc[0]
    assert row["sites"] == 1 and row["sites_inside"] == 1 and row["not_judged"] == "g"
    text = markdown(table, ["o", "g"], COMPARED_RADIO)
    assert "18 ✓" in text and "9 (not judged)" in text
    # Without kinds every site is judged.
    row = compare(real, sim.drop(columns="kind"), COMPARED_RADIO).iloc[2]
    assert row["statistic"] == "aps_per_scan" and row["sites"] == 2 and row["sites_inside"] == 1


def test_compare_counts_the_sites_whose_median_lies_inside():
    real = pd.DataFrame({"mode": "handheld", "acc_p2p": [6.0, 9.0]})
    sim = pd.DataFrame(
        {
            "site": ["a", "a", "a", "b", "b", "b"],
            "mode": "handheld",
            "seed": [0, 1, 2] * 2,
            **{k: np.nan for k in MOTION_KEYS},
        }
    )
    sim["acc_p2p"] = [1.0, 7.0, 8.0, 5.0, 5.5, 10.0]  # medians: a 7.0 inside, b 5.5 outside
    table = compare(real, sim)
    row = table[table["statistic"] == "acc_p2p"].iloc[0]
    assert row["a"] == 7.0 and row["b"] == 5.5 and row["sites_inside"] == 1
    text = markdown(table, ["a", "b"])
    assert "7 ✓" in text and "**5.5** ✗" in text


def test_a_kind_of_several_buildings_is_judged_by_its_median_building():
    # Three buildings of one kind, walked 4, 2 and 2 times: their medians are 1, 7 and
    # 8, so the kind reads 7 (inside 6–9), with 1–8 beside it. The median of all eight
    # walks (4) would weigh the much-walked building, not the kind's buildings.
    real = pd.DataFrame({"mode": "handheld", "acc_p2p": [6.0, 9.0]})
    sim = pd.DataFrame(
        {
            "site": ["k"] * 8 + ["one"] * 2,
            "building": [0, 0, 0, 0, 1, 1, 2, 2, -1, -1],
            "mode": "handheld",
            "seed": [0, 1, 2, 3, 0, 1, 0, 1, 0, 1],
            **{k: np.nan for k in MOTION_KEYS},
        }
    )
    sim["acc_p2p"] = [1.0, 1.0, 1.0, 1.0, 7.0, 7.0, 8.0, 8.0, 5.0, 5.0]
    table = compare(real, sim)
    row = table[table["statistic"] == "acc_p2p"].iloc[0]
    assert (row["k"], row["k low"], row["k high"]) == (7.0, 1.0, 8.0)
    assert row["sites_inside"] == 1 and row["sites"] == 2
    text = markdown(table, ["k", "one"])
    assert "| 7 ✓ (1–8) | **5** ✗ |" in text  # one building: no spread


@pytest.mark.skipif(not REALDATA.is_dir(), reason=f"no real data at {REALDATA}")
def test_the_committed_real_table_is_what_the_real_logs_give():
    """The shared folder's walks measure as committed; the Tyrex walks (not in it) keep
    their committed rows, a reference for the gyro RMS only."""
    committed = load_real_motion()
    fresh = merge_refreshed(real_motion_table(REALDATA), committed)
    assert list(fresh["walk"]) == list(committed["walk"])
    for key in MOTION_KEYS:
        np.testing.assert_allclose(fresh[key], committed[key], rtol=1e-5, err_msg=key)
    tyrex = committed[committed["dataset"] == TYREX_SOURCE.name]
    assert sorted(set(tyrex["mode"])) == ["calling", "dangling", "handheld", "pocketed"]
    others = [k for k in MOTION_KEYS if k not in (*GYRO_KEYS, "walking_s")]
    assert tyrex[others].isna().all().all()
    walked = tyrex["walking_s"] >= TYREX_SOURCE.min_walking_s
    assert tyrex.loc[walked, list(GYRO_KEYS)].notna().all().all()
    assert tyrex.loc[~walked, list(GYRO_KEYS)].isna().all().all()


def _as_tyrex_walk(rec: Recording, folder: Path, seconds: float) -> None:
    """The first ``seconds`` of a simulated recording written as a Tyrex Android walk."""
    folder.mkdir(parents=True)
    for name, file in (("accel", "accelerometer.txt"), ("gyro", "gyroscope-calibrated.txt")):
        df = rec.streams[name]
        df = df[df.index < df.index[0] + seconds]
        np.savetxt(folder / file, np.column_stack([df.index, df[["x", "y", "z"]]]), fmt="%.9g")
    (folder / "timeAlignment.txt").write_text("0\n")
    (folder / "record.properties").write_text("[Device]\nModel = Nexus 5\n")


def test_a_source_is_a_reference_only_for_its_statistics(tmp_path: Path):
    """A Tyrex walk gives its gyro RMS (the same as the recording's own) and nothing
    else; one with less walking than the source asks for gives nothing."""
    site = load_site("han2023_corridor")
    rec = simulate(site, route="trajectory", mode="dangling", device="nexus_5x", seed=0)
    root = tmp_path / "tyrex-attitude" / "datasets" / "android"
    _as_tyrex_walk(rec, root / "Sim_Nexus5_NoDist_Swinging", 1e9)
    _as_tyrex_walk(rec, root / "Sim_Nexus5_NoDist_Phoning", 20.0)
    table = real_motion_table(tmp_path).set_index("walk")
    assert list(table["dataset"]) == ["tyrex-attitude"] * 2
    whole = table.loc["Sim_Nexus5_NoDist_Swinging"]
    own = motion_statistics(Recording.load(root / "Sim_Nexus5_NoDist_Swinging"))
    assert whole["walking_s"] >= TYREX_SOURCE.min_walking_s
    gyro = whole[list(GYRO_KEYS)].astype(float)
    np.testing.assert_allclose(gyro, [own[k] for k in GYRO_KEYS])
    assert whole[["acc_std", "share_step", "step_hz"]].isna().all()
    short = table.loc["Sim_Nexus5_NoDist_Phoning"]
    assert short["walking_s"] < TYREX_SOURCE.min_walking_s
    assert short[[k for k in MOTION_KEYS if k != "walking_s"]].isna().all()


def test_a_refreshed_table_keeps_the_sources_whose_files_are_absent():
    committed = pd.DataFrame({"dataset": ["a", "b", "b"], "walk": ["1", "2", "3"], "x": [1, 2, 3]})
    fresh = pd.DataFrame({"dataset": ["a", "c"], "walk": ["1", "4"], "x": [10, 40]})
    merged = merge_refreshed(fresh, committed)
    assert list(merged["walk"]) == ["1", "4", "2", "3"]
    assert list(merged["x"]) == [10, 40, 2, 3]


@pytest.mark.skipif(not REALDATA.is_dir(), reason=f"no real data at {REALDATA}")
def test_the_committed_real_walkers_are_what_calibrating_the_real_logs_gives():
    fresh, committed = real_walker_table(REALDATA), load_real_walkers()
    assert list(fresh["walk"]) == list(committed["walk"])
    for key in ("height_m", "speed_mps", *VIGOUR_FIELDS):
        np.testing.assert_allclose(fresh[key], committed[key], rtol=1e-5, err_msg=key)


def test_every_modelled_mode_is_simulated_and_every_statistic_measured():
    config = RealismConfig(bundled=("minimal_room",), generated=(), seeds=(0,))
    sim, curves = simulate_motion(config)
    assert sorted(sim["mode"]) == sorted(config.modes)
    assert set(COMPARED) <= set(sim.columns)
    assert set(curves["curve"]) == {"accel_psd", "gyro_psd", "accel_hist", "accel_stride"}


@pytest.mark.skipif(not REALDATA.is_dir(), reason=f"no real data at {REALDATA}")
def test_the_committed_real_profiles_are_what_the_real_logs_give():
    fresh, committed = real_profiles(REALDATA), load_real_profiles()
    assert list(fresh["curve"]) == list(committed["curve"])
    np.testing.assert_allclose(fresh["y"], committed["y"], rtol=1e-5, atol=1e-12)


@pytest.mark.skipif(not REALDATA.is_dir(), reason=f"no real data at {REALDATA}")
@pytest.mark.parametrize(
    ("fresh", "committed", "keys"),
    [
        (real_magnetic_table, load_real_magnetic, MAGNETIC_KEYS),
        (real_radio_table, load_real_radio, RADIO_KEYS),
    ],
    ids=["magnetic", "radio"],
)
def test_the_committed_environment_tables_are_what_the_real_logs_give(fresh, committed, keys):
    measured, stored = fresh(REALDATA), committed()
    assert list(measured["walk"]) == list(stored["walk"])
    for key in keys:
        np.testing.assert_allclose(measured[key], stored[key], rtol=1e-5, err_msg=key)


def test_the_environment_is_measured_on_each_sites_longest_route_and_reported(tmp_path):
    config = RealismConfig(
        bundled=("han2023_corridor",), generated=(), field_generated=(), seeds=(0, 1)
    )
    env = simulate_environment(config)
    assert list(env["seed"]) == [0, 1] and set(env["route"]) == {"trajectory"}
    assert env[[*COMPARED_MAGNETIC, *COMPARED_RADIO, *LIGHT_KEYS]].notna().all().all()
    motion = pd.DataFrame({"site": ["s"], "mode": ["handheld"], "seed": [0]})
    motion = motion.assign(**{k: 1.0 for k in MOTION_KEYS})
    tables = write_report(
        tmp_path,
        load_real_motion(),
        motion,
        real_field=load_real_magnetic(),
        real_radio=load_real_radio(),
        sim_env=env,
    )
    judged = (("magnetic", COMPARED_MAGNETIC), ("wifi", COMPARED_RADIO), ("light", COMPARED_LIGHT))
    for mode, compared in judged:
        rows = tables[tables["mode"] == mode]
        assert list(rows["statistic"]) == list(compared)
        # The corridor is an office's: the car parks' median does not judge it.
        car_park_only = rows["statistic"] == "lux_median_car_park"
        assert (rows.loc[~car_park_only, "sites"] == 1).all()
        assert (rows.loc[car_park_only, "sites"] == 0).all()
    text = (tmp_path / "realism.md").read_text()
    assert "## Magnetic field" in text and "## WiFi" in text and "## Light" in text
    assert "han2023_corridor: trajectory" in text


def test_a_generated_kind_is_walked_in_several_of_its_buildings():
    config = RealismConfig(
        bundled=(),
        generated=(),
        field_generated=(("office", 3),),
        field_buildings=2,
        field_building_walks=1,
        seeds=(0, 1),
    )
    env = simulate_environment(config)
    # Two buildings (the generator's seeds 3 and 4), one walk each, under one label.
    assert list(env["building"]) == [3, 4] and list(env["seed"]) == [0, 0]
    assert set(env["site"]) == {"generated office (2 buildings)"}
    assert env["mag_std"].nunique() == 2  # two buildings, two fields
