"""Device profiles: registry, plugins, validation, and their figures against the Android CDD."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from indoorsim.phone.devices import (
    DEG,
    DEVICES,
    STANDARD_GRAVITY,
    DeviceProfile,
    InertialSpec,
    LightSensorSpec,
    MagnetometerSpec,
    UnknownDeviceError,
    WifiSpec,
    available_devices,
    get_device,
)

REAL_PROFILES = [name for name in DEVICES if name != "ideal"]
SPEC_NAMES = ("accel", "gyro", "mag", "light", "wifi")


def test_registry_keys_are_the_profiles_names() -> None:
    assert {
        "ideal",
        "vivo_s9",
        "nexus_5x",
        "honor_50",
        "low_grade",
        "mid_grade",
        "high_grade",
    } <= set(DEVICES)
    for name, profile in DEVICES.items():
        assert profile.name == name
        assert get_device(name) is profile


def test_registry_and_profiles_are_read_only() -> None:
    with pytest.raises(TypeError):
        DEVICES["mine"] = DeviceProfile(name="mine")  # type: ignore[index]
    with pytest.raises(dataclasses.FrozenInstanceError):
        DEVICES["vivo_s9"].gyro.noise_density = 0.0  # type: ignore[misc]


def test_unknown_device_lists_the_valid_names() -> None:
    with pytest.raises(UnknownDeviceError) as info:
        get_device("nokia_3310")
    message = str(info.value)
    assert "nokia_3310" in message
    for name in DEVICES:
        assert name in message


def test_ideal_profile_has_no_error_at_all() -> None:
    ideal = get_device("ideal")
    assert ideal.timestamp_jitter_frac == 0 and ideal.gap_probability == 0
    for spec in (ideal.accel, ideal.gyro):
        assert spec.noise_density == spec.turn_on_bias_sigma == spec.bias_instability == 0
        assert spec.random_walk == spec.scale_factor_sigma == spec.misalignment_sigma_rad == 0
        assert spec.range == math.inf and spec.resolution == 0
    mag = ideal.mag
    assert mag.noise_sigma_uT == mag.hard_iron_sigma_uT == mag.resolution_uT == 0
    assert mag.soft_iron_diag_sigma == mag.soft_iron_offdiag_sigma == 0 and mag.range_uT == math.inf
    light = ideal.light
    assert light.relative_noise == light.resolution_lux == light.integration_time_s == 0
    assert light.range_lux == light.max_event_rate_hz == math.inf and not light.on_change
    wifi = ideal.wifi
    assert wifi.fading_sigma_db == wifi.quantisation_db == wifi.scan_duration_s == 0
    assert wifi.detection_threshold_dbm == -math.inf and not wifi.throttling


def test_default_specs_are_the_ideal_sensors() -> None:
    ideal = get_device("ideal")
    assert (ideal.accel, ideal.mag, ideal.light, ideal.wifi) == (
        InertialSpec(),
        MagnetometerSpec(),
        LightSensorSpec(),
        WifiSpec(),
    )


@pytest.mark.parametrize("name", REAL_PROFILES)
def test_profiles_meet_the_android_cdd(name: str) -> None:
    """Every phone profile satisfies the CDD §7.3 MUSTs quoted in REALISM §1.2."""
    d = get_device(name)
    assert d.accel.rate_hz >= 50 and d.gyro.rate_hz >= 50 and d.mag.rate_hz >= 10
    assert d.accel.range >= 4 * STANDARD_GRAVITY
    assert d.gyro.range >= 1000 * DEG
    # Per-axis accelerometer std at its rate ≤ 0.05 m/s²; gyro density ≤ 3.2e-4 rad/s/√Hz.
    assert d.accel.noise_density * math.sqrt(d.accel.rate_hz) <= 0.05
    assert d.gyro.noise_density <= 3.2e-4
    # 12 bits or better over the range.
    assert d.accel.resolution <= 2 * d.accel.range / 2**12
    assert d.gyro.resolution <= 2 * d.gyro.range / 2**12
    assert d.mag.noise_sigma_uT <= 1.5 and d.mag.resolution_uT <= 0.6 and d.mag.range_uT >= 900
    # Calibrated gyro: stationary error SHOULD be < 0.01 rad/s; a typical (1σ) unit meets it.
    assert d.gyro.turn_on_bias_sigma <= 0.01
    assert d.timestamp_jitter_frac <= 0.03
    assert d.wifi.quantisation_db == 1.0


def test_papers_phones_follow_the_papers() -> None:
    vivo, nexus = get_device("vivo_s9"), get_device("nexus_5x")
    # Han2023 §4.2: geomagnetic and light data at 50 Hz.
    assert vivo.accel.rate_hz == vivo.gyro.rate_hz == vivo.mag.rate_hz == 50
    # Chen2022: WiFi at 0.2 Hz on the Nexus 5X (Android ≤ 8.1: no throttling).
    assert nexus.wifi.scan_interval_s == 5.0 and not nexus.wifi.throttling
    # Android 11 throttles by default.
    assert vivo.wifi.throttling


@pytest.mark.parametrize("name", REAL_PROFILES)
def test_every_profile_cites_a_source_for_each_sensor(name: str) -> None:
    d = get_device(name)
    assert d.description
    text = " ".join(d.sources).lower()
    for spec in SPEC_NAMES:
        assert spec in text, f"{name}: no source line mentions {spec}"
    assert all(any(tag in line for tag in ("[S", "[D", "[E")) for line in d.sources)


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda: InertialSpec(noise_density=-1.0), "noise_density"),
        (lambda: InertialSpec(bias_instability=math.nan), "bias_instability"),
        (lambda: InertialSpec(rate_hz=0.0), "rate_hz"),
        (lambda: InertialSpec(bias_correlation_s=0.0), "bias_correlation_s"),
        (lambda: MagnetometerSpec(range_uT=-5.0), "range_uT"),
        (lambda: LightSensorSpec(max_event_rate_hz=0.0), "max_event_rate_hz"),
        (lambda: WifiSpec(fading_sigma_db=-1.0), "fading_sigma_db"),
        (lambda: WifiSpec(antenna_side_ratio_db=-1.0), "antenna_side_ratio_db"),
        (lambda: WifiSpec(scan_interval_s=2.0, scan_duration_s=3.0), "scan_interval_s"),
        (lambda: WifiSpec(scan_duration_s=1.0, scan_duration_spread_s=2.0), "spread"),
        (lambda: DeviceProfile(name="x", gap_probability=1.0), "gap_probability"),
        (lambda: DeviceProfile(name="x", timestamp_jitter_frac=-0.1), "timestamp_jitter_frac"),
    ],
)
def test_invalid_figures_are_rejected_by_name(make, field: str) -> None:
    with pytest.raises(ValueError, match=field):
        make()


def test_a_spec_in_the_wrong_slot_is_rejected() -> None:
    with pytest.raises(TypeError, match="accel"):
        DeviceProfile(name="x", accel=MagnetometerSpec())  # type: ignore[arg-type]


# --------------------------------------------------------------------------- plugins


def _install_plugin(
    root: Path, monkeypatch: pytest.MonkeyPatch, module: str, entry_points: dict[str, str]
) -> None:
    """Put a tiny distribution on sys.path whose ``indoorsim.devices`` entry points are given.

    The module defines GOOD (a profile named after ``module``), ALIEN (not a
    profile), MISNAMED (a profile with another name) and IMPOSTOR (named ``ideal``).
    """
    (root / f"{module}.py").write_text(
        "from indoorsim.phone.devices import DeviceProfile, InertialSpec\n"
        f"GOOD = DeviceProfile(name={module!r}, accel=InertialSpec(rate_hz=400.0))\n"
        "ALIEN = {'name': 'alien'}\n"
        "MISNAMED = DeviceProfile(name='someone_else')\n"
        "IMPOSTOR = DeviceProfile(name='ideal', gap_probability=0.5)\n"
    )
    dist = root / f"{module}-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {module}\nVersion: 1.0\n")
    lines = "".join(f"{name} = {module}:{target}\n" for name, target in entry_points.items())
    (dist / "entry_points.txt").write_text(f"[indoorsim.devices]\n{lines}")
    monkeypatch.syspath_prepend(str(root))


def test_a_plugin_from_outside_adds_a_device(tmp_path: Path, monkeypatch) -> None:
    _install_plugin(
        tmp_path, monkeypatch, "lab_phone_plugin", {"lab_phone_plugin": "GOOD", "ideal": "IMPOSTOR"}
    )
    profile = get_device("lab_phone_plugin")
    assert isinstance(profile, DeviceProfile) and profile.accel.rate_hz == 400.0
    assert "lab_phone_plugin" in available_devices()
    # A plugin cannot redefine a built-in profile.
    assert get_device("ideal") is DEVICES["ideal"]
    assert available_devices()["ideal"] is DEVICES["ideal"]


def test_a_plugin_that_is_not_a_profile_is_rejected(tmp_path: Path, monkeypatch) -> None:
    _install_plugin(tmp_path, monkeypatch, "alien_plugin", {"alien": "ALIEN"})
    with pytest.raises(TypeError, match="alien"):
        get_device("alien")
    # Built-in profiles do not depend on the plugins loading.
    assert get_device("vivo_s9") is DEVICES["vivo_s9"]


def test_a_plugin_whose_name_differs_is_rejected(tmp_path: Path, monkeypatch) -> None:
    _install_plugin(tmp_path, monkeypatch, "misnamed_plugin", {"misnamed": "MISNAMED"})
    with pytest.raises(ValueError, match="someone_else"):
        get_device("misnamed")
