"""Sensor faults (:mod:`indoorsim.io.faults`) on a small hand-made recording, closed-form."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from indoorsim.io.faults import (
    FAULTS,
    FaultError,
    WalkFault,
    apply_faults,
    fault_rng,
    parse_fault,
    walk_arguments,
)
from indoorsim.io.recording import Recording

T = np.arange(0.0, 10.0, 0.5)  # 20 samples, 0 … 9.5 s


def _xyz(offset: float) -> pd.DataFrame:
    n = len(T)
    data = {
        "x": offset + np.arange(n, dtype=float),
        "y": offset - np.arange(n, dtype=float),
        "z": np.full(n, offset + 9.0),
    }
    return pd.DataFrame(data, index=pd.Index(T, name="t"))


def _recording() -> Recording:
    wifi_t = np.repeat([0.0, 2.0, 4.0, 6.0, 8.0], 2)
    wifi = pd.DataFrame(
        {"bssid": ["a", "b"] * 5, "rss": np.linspace(-80.0, -40.0, 10)},
        index=pd.Index(wifi_t, name="t"),
    )
    light = pd.DataFrame({"lux": np.full(len(T), 300.0)}, index=pd.Index(T, name="t"))
    truth = _xyz(0.0)[["x", "y"]]
    return Recording(
        streams={
            "accel": _xyz(1.0),
            "gyro": _xyz(0.1),
            "mag": _xyz(20.0),
            "light": light,
            "wifi": wifi,
            "waypoints": truth,
        },
        meta={"device": "ideal"},
    )


def _apply(spec: str, rec: Recording | None = None, seed: int = 0) -> Recording:
    return parse_fault(spec).apply(rec or _recording(), fault_rng(seed, 0))


def _same(a: Recording, b: Recording) -> bool:
    return a.streams.keys() == b.streams.keys() and all(
        a.streams[k].equals(b.streams[k]) and a.streams[k].index.equals(b.streams[k].index)
        for k in a.streams
    )


def test_bias_jump_adds_exactly_the_vector_from_t0_and_nothing_before():
    rec = _recording()
    out = _apply("bias_jump:stream=accel,t0=5,vector=0.5/-1/2", rec)
    diff = out.accel.to_numpy() - rec.accel.to_numpy()
    after = T >= 5
    np.testing.assert_array_equal(diff[~after], 0.0)
    np.testing.assert_allclose(diff[after], np.tile([0.5, -1.0, 2.0], (after.sum(), 1)))
    assert out.meta["faults"] == [
        {"name": "bias_jump", "params": {"stream": "accel", "t0": 5.0, "vector": [0.5, -1, 2]}}
    ]
    assert "faults" not in rec.meta  # the input is unchanged
    assert _same(rec, _recording())


def test_bias_drift_grows_linearly_from_t0():
    rec = _recording()
    out = _apply("bias_drift:stream=gyro,t0=2,rate=0.01/0/0", rec)
    expected = 0.01 * np.clip(T - 2, 0, None)
    np.testing.assert_allclose(out.gyro["x"] - rec.gyro["x"], expected, atol=1e-12)
    np.testing.assert_array_equal(out.gyro["y"], rec.gyro["y"])


def test_stuck_holds_the_exact_value_at_t0():
    rec = _recording()
    out = _apply("stuck:stream=mag,t0=2.2,t1=6", rec)
    window = (T >= 2.2) & (T <= 6)
    held = rec.mag.loc[2.0].to_numpy()  # the last sample at or before t0
    np.testing.assert_array_equal(out.mag.to_numpy()[window], np.tile(held, (window.sum(), 1)))
    np.testing.assert_array_equal(out.mag.to_numpy()[~window], rec.mag.to_numpy()[~window])


def test_nan_burst_and_gap():
    rec = _recording()
    out = _apply("nan_burst:stream=accel,t0=1,t1=2", rec)
    window = (T >= 1) & (T <= 2)
    assert out.accel.to_numpy()[window].size and np.isnan(out.accel.to_numpy()[window]).all()
    assert np.isfinite(out.accel.to_numpy()[~window]).all()
    gap = _apply("gap:streams=accel/gyro,t0=1,t1=2", rec)
    assert len(gap.accel) == len(gap.gyro) == len(T) - window.sum()
    assert not ((gap.accel.index >= 1) & (gap.accel.index <= 2)).any()
    assert gap.mag.equals(rec.mag)


def test_saturation_clips_exactly_and_scale_multiplies():
    rec = _recording()
    out = _apply("saturation:stream=mag,full_scale=25", rec)
    np.testing.assert_array_equal(out.mag.to_numpy(), np.clip(rec.mag.to_numpy(), -25, 25))
    out = _apply("scale:stream=accel,factor=1.1", rec)
    np.testing.assert_allclose(out.accel.to_numpy(), 1.1 * rec.accel.to_numpy())


def test_dropout_keeps_about_1_minus_p_and_is_seed_deterministic():
    big = pd.DataFrame(
        {"x": np.zeros(10_000), "y": 0.0, "z": 9.81},
        index=pd.Index(np.arange(10_000) * 0.01, name="t"),
    )
    rec = Recording(streams={"accel": big})
    out = _apply("dropout:streams=accel,p=0.3", rec, seed=4)
    assert abs(len(out.accel) / 10_000 - 0.7) < 0.03
    assert _same(out, _apply("dropout:streams=accel,p=0.3", rec, seed=4))
    assert not _same(out, _apply("dropout:streams=accel,p=0.3", rec, seed=5))
    scans = _apply("dropout:streams=wifi,p=0.5", seed=1).wifi
    assert (scans.groupby(level="t").size() == 2).all()  # a scan is lost whole


def test_jitter_keeps_times_increasing_and_scans_together():
    rec = _recording()
    out = _apply("jitter:stream=accel,sigma=0.3", rec)
    t = out.accel.index.to_numpy()
    assert (np.diff(t) >= 0).all() and not np.array_equal(t, T)
    np.testing.assert_array_equal(out.accel.to_numpy(), rec.accel.to_numpy())
    wifi = _apply("jitter:stream=wifi,sigma=0.1", rec).wifi
    assert (wifi.groupby(level="t").size() == 2).all()


def test_clock_step_shifts_times_after_t0():
    rec = _recording()
    out = _apply("clock_step:stream=gyro,t0=5,delta=0.25", rec)
    np.testing.assert_allclose(out.gyro.index, np.where(T >= 5, T + 0.25, T))
    back = _apply("clock_step:stream=gyro,t0=5,delta=-1", rec)
    assert back.gyro.index.is_monotonic_increasing and len(back.gyro) == len(T)


def test_missing_removes_the_stream():
    out = _apply("missing:streams=mag/light")
    assert "mag" not in out.streams and "light" not in out.streams and "accel" in out.streams


def test_wifi_outage_and_scan_throttle():
    out = _apply("wifi_outage:t0=1,t1=5")
    assert sorted(set(out.wifi.index)) == [0.0, 6.0, 8.0]
    out = _apply("scan_throttle:period=3")
    assert sorted(set(out.wifi.index)) == [0.0, 4.0, 8.0]
    assert len(out.wifi) == 6


def test_lights_off():
    out = _apply("lights_off:t0=3,t1=4")
    window = (T >= 3) & (T <= 4)
    np.testing.assert_array_equal(out.light["lux"].to_numpy(), np.where(window, 1.0, 300.0))


def test_magnetic_disturbance_and_case_magnet():
    rec = _recording()
    out = _apply("magnetic_disturbance:t0=5,amplitude=40,sigma=1,direction=0/0/2,frame=phone", rec)
    bump = 40 * np.exp(-0.5 * (T - 5) ** 2)
    np.testing.assert_allclose(out.mag["z"] - rec.mag["z"], bump)
    np.testing.assert_array_equal(out.mag["x"], rec.mag["x"])
    random_dir = _apply("magnetic_disturbance:t0=5,amplitude=40,frame=phone", rec).mag - rec.mag
    np.testing.assert_allclose(np.linalg.norm(random_dir.loc[5.0]), 40)
    out = _apply("case_magnet:offset=30/-20/5", rec)
    np.testing.assert_allclose(out.mag.to_numpy() - rec.mag.to_numpy(), [[30, -20, 5]] * len(T))


def test_a_world_frame_disturbance_stays_fixed_in_the_building_while_the_phone_turns():
    # The phone turns about its z axis at 0.5 rad/s: world <- phone is a yaw of 0.5 t.
    yaw = 0.5 * T
    rotation = pd.DataFrame(
        {"qw": np.cos(yaw / 2), "qx": 0.0, "qy": 0.0, "qz": np.sin(yaw / 2)},
        index=pd.Index(T, name="t"),
    )
    rec = Recording(streams={**_recording().streams, "rotation": rotation}, meta={})
    out = _apply("magnetic_disturbance:t0=5,amplitude=40,sigma=1,direction=1/0/0", rec)
    added = (out.mag - rec.mag)[["x", "y", "z"]].to_numpy()
    bump = 40 * np.exp(-0.5 * (T - 5) ** 2)
    # In the phone frame east turns backwards: (cos yaw, -sin yaw, 0).
    np.testing.assert_allclose(
        added, bump[:, None] * np.c_[np.cos(yaw), -np.sin(yaw), 0 * T], atol=1e-12
    )
    with pytest.raises(FaultError, match="the recording has no 'rotation' stream"):
        _apply("magnetic_disturbance:t0=5", _recording())
    with pytest.raises(FaultError, match="frame = 'lift': must be 'world' or 'phone'"):
        parse_fault("magnetic_disturbance:t0=5,frame=lift")


def test_composition_is_in_order_and_recorded():
    specs = ["scale:stream=accel,factor=2", "bias_jump:stream=accel,t0=0,vector=1/1/1"]
    rec = _recording()
    out = apply_faults(rec, [parse_fault(s) for s in specs], seed=0)
    np.testing.assert_allclose(out.accel.to_numpy(), 2 * rec.accel.to_numpy() + 1)
    swapped = apply_faults(rec, [parse_fault(s) for s in reversed(specs)], seed=0)
    np.testing.assert_allclose(swapped.accel.to_numpy(), 2 * (rec.accel.to_numpy() + 1))
    assert [f["name"] for f in out.meta["faults"]] == ["scale", "bias_jump"]


def test_every_fault_round_trips_its_spec_and_leaves_the_input_alone():
    rec = _recording()
    examples = {
        "dropout": "dropout",
        "gap": "gap:t0=1,t1=2",
        "nan_burst": "nan_burst:stream=light,t0=1,t1=2",
        "stuck": "stuck:stream=gyro,t0=1,t1=2",
        "bias_jump": "bias_jump:stream=mag,t0=1,vector=1/2/3",
        "bias_drift": "bias_drift:stream=accel,rate=0.1/0/0",
        "saturation": "saturation:stream=gyro,full_scale=1",
        "scale": "scale:stream=light,factor=0.5",
        "jitter": "jitter:stream=mag,sigma=0.01",
        "clock_step": "clock_step:stream=wifi,t0=3,delta=0.5",
        "missing": "missing:streams=wifi",
        "wifi_outage": "wifi_outage:t0=0,t1=1",
        "scan_throttle": "scan_throttle:period=30",
        "lights_off": "lights_off:t0=0,t1=100,lux=0.5",
        "magnetic_disturbance": "magnetic_disturbance:t0=2,frame=phone",
        "case_magnet": "case_magnet:offset=10/0/0",
        "mode_change": "mode_change:t0=5,mode=pocketed",
        "wrong_device": "wrong_device:device=honor_50",
    }
    assert set(examples) == set(FAULTS)
    for spec in examples.values():
        fault = parse_fault(spec)
        assert parse_fault(fault.spec()) == fault
        a = apply_faults(rec, [fault], seed=3)
        assert _same(a, apply_faults(rec, [fault], seed=3)), spec
        assert a.meta["faults"][0]["name"] == fault.name
    assert _same(rec, _recording())


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("wobble", "unknown fault 'wobble'; known faults: dropout, gap,"),
        ("gap:t0=1", "fault gap: missing parameter t1 (parameters: t0, t1, streams)"),
        ("gap:t0=1,t1=2,when=3", "fault gap: unknown parameter 'when' (parameters:"),
        ("gap:t0=one,t1=2", "fault gap: t0='one' is not a number"),
        ("gap:t0=3,t1=2", "fault gap: t1 = 2.0 is before t0 = 3.0"),
        ("gap:t0", "fault gap: 't0' is not key=value"),
        ("dropout:p=1.5", "fault dropout: p = 1.5 is not a probability in [0, 1]"),
        ("bias_jump:stream=accel,t0=0,vector=1/2", "vector must be 3 finite numbers x/y/z"),
        ("scale:stream=truth,factor=2", "fault scale: stream = 'truth': not a sensor stream"),
        ("saturation:stream=mag,full_scale=-1", "full_scale must be a positive number"),
        ("jitter:stream=mag,sigma=nan", "sigma must be a non-negative number"),
        ("mode_change:t0=5,mode=juggling", "fault mode_change: mode = 'juggling': "),
        ("mode_change:t0=0,mode=pocketed", "t0 must be a positive number of seconds"),
        ("wrong_device:device=nokia", "fault wrong_device: device = 'nokia': unknown device"),
    ],
)
def test_parser_errors_name_the_fault_and_parameter(spec, message):
    with pytest.raises(FaultError) as err:
        parse_fault(spec)
    assert message in str(err.value)


def test_a_fault_on_an_absent_stream_says_which():
    rec = Recording(streams={"accel": _xyz(0.0)})
    with pytest.raises(FaultError, match="fault lights_off: the recording has no 'light'"):
        _apply("lights_off:t0=0,t1=1", rec)


def test_walk_faults_change_the_simulated_walk_and_not_the_recording():
    faults = [
        parse_fault("mode_change:t0=20,mode=pocketed"),
        parse_fault("wrong_device:device=honor_50"),
        parse_fault("scale:stream=accel,factor=2"),
    ]
    assert [isinstance(f, WalkFault) for f in faults] == [True, True, False]
    schedule, device = walk_arguments(faults, [(0, "handheld"), (10, "calling")], "nexus_5x")
    assert device == "honor_50"
    assert [(e.t_start_s, e.mode) for e in schedule.entries] == [
        (0.0, "handheld"),
        (10.0, "calling"),
        (20.0, "pocketed"),
    ]
    # A later entry of the declared schedule is overridden from t0 on.
    schedule, _ = walk_arguments(faults[:1], [(0, "handheld"), (30, "calling")], "ideal")
    assert [(e.t_start_s, e.mode) for e in schedule.entries] == [(0, "handheld"), (20, "pocketed")]
    # Recording-wise they are the identity, recorded in the metadata.
    rec = _recording()
    out = apply_faults(rec, faults[:2], seed=0)
    assert _same(out, rec)
    assert [f["name"] for f in out.meta["faults"]] == ["mode_change", "wrong_device"]


@pytest.mark.parametrize(
    ("spec", "mode", "device", "message"),
    [
        ("mode_change:t0=5,mode=pocketed", "pocketed", "ideal", "already carried at t0 = 5 s"),
        ("wrong_device:device=ideal", "handheld", "ideal", "is the declared device: no fault"),
    ],
)
def test_a_walk_fault_that_changes_nothing_is_refused(spec, mode, device, message):
    with pytest.raises(FaultError, match=message):
        walk_arguments([parse_fault(spec)], mode, device)
