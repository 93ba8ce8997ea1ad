"""Device profiles: what each simulated phone's sensors get wrong, and how often they report.

A :class:`DeviceProfile` bundles one error specification per sensor (the spec
classes live in :mod:`indoorsim.phone.specs` and are re-exported here). This
module holds the named phones and finds a profile by name, or in a YAML file
(:func:`get_device`: the layout of :func:`device_to_dict`, as ``indoorsim
calibrate`` writes).

Registered profiles (:data:`DEVICES`):

* ``ideal`` — every error exactly zero, no quantisation, no saturation, no
  jitter or gaps: the sensor models return their input unchanged (tests rely on it).
* ``vivo_s9`` — Han2023's phone (survey and walks, 50 Hz).
* ``nexus_5x`` — Chen2022's walking phone (WiFi at 0.2 Hz).
* ``honor_50`` — Chen2022's survey phone.
* ``low_grade``, ``mid_grade``, ``high_grade`` — generic phones from the
  Android CDD floor to a "hifi sensors" flagship.

Each profile's ``sources`` says where every figure comes from, with the tags of
REALISM.md: [S] sourced, [D] derived, [E] estimated. The papers name the phones
but not their sensor chips, so every chip attribution is [E] too.

Other packages add profiles through the ``indoorsim.devices`` entry-point group
(:data:`ENTRY_POINT_GROUP`); each entry point loads to a :class:`DeviceProfile`
whose ``name`` equals the entry point's name::

    [project.entry-points."indoorsim.devices"]
    lab_phone = "my_package.devices:LAB_PHONE"

Units: accelerometer figures in m/s², gyroscope figures in rad/s (the profiles
below are written from datasheet units through the conversion constants of
:mod:`indoorsim.phone.specs`), magnetic field in µT, illuminance in lux, RSS in
dBm, times in s.
"""

from __future__ import annotations

from collections.abc import Mapping
from importlib.metadata import entry_points
from pathlib import Path
from types import MappingProxyType

from indoorsim.phone.specs import (
    DEG,
    DEG_PER_H,
    DEG_PER_H_PER_SQRT_H,
    MG,
    STANDARD_GRAVITY,
    UG,
    DeviceFileError,
    DeviceProfile,
    InertialSpec,
    LightSensorSpec,
    MagnetometerSpec,
    WifiSpec,
    cosine_power,
    device_from_dict,
    device_to_dict,
)
from indoorsim.util.errors import UnknownNameError
from indoorsim.util.yaml_files import read_yaml_section

__all__ = [
    "DEG",
    "DEG_PER_H",
    "DEG_PER_H_PER_SQRT_H",
    "DEVICES",
    "ENTRY_POINT_GROUP",
    "HANDSET_SIDE_RATIO_DB",
    "MG",
    "STANDARD_GRAVITY",
    "UG",
    "DeviceFileError",
    "DeviceProfile",
    "InertialSpec",
    "LightSensorSpec",
    "MagnetometerSpec",
    "UnknownDeviceError",
    "WifiSpec",
    "available_devices",
    "cosine_power",
    "device_from_dict",
    "device_to_dict",
    "get_device",
]

ENTRY_POINT_GROUP = "indoorsim.devices"
"""Entry-point group through which other packages add device profiles."""


# --------------------------------------------------------------------------- profiles

_IDEAL = DeviceProfile(
    name="ideal",
    description=(
        "A perfect phone: every error exactly zero, no quantisation, no saturation, "
        "no timestamp jitter or gaps, every AP heard with its mean RSS. The sensor "
        "models return their input unchanged."
    ),
    sources=("all figures: zero by definition",),
)

HANDSET_SIDE_RATIO_DB = 8.0
"""A handset's receive gain toward its antenna's side over the opposite side, in the
hand, dB [E]: a phone's WiFi antenna sits at one edge (commonly a top corner) and the
board, battery and screen and the gripping hand absorb and shade toward the other, so
measured handset patterns in the horizontal plane vary by about 10 dB from peak to
trough [E]; the ratio of a smooth (first-harmonic) pattern, 8 dB, taken for every
profile (``WifiSpec.antenna_side_ratio_db``). It is what makes a surveyor's two visits
facing opposite ways read the APs beside the route differently (the UJI sets' 3.2–4.4 dB
spread across visits, ``leaderboards/realism.md``), as the trunk does those ahead and
behind."""

_UJI_WIFI_SOURCE = (
    "wifi.fading_sigma_db and miss_probability from the UJI library sets (a Galaxy S3 "
    "standing still, 6 scans a visit; indoorsim.benchmark.realism.radio, real_radio.csv): "
    "one AP's readings within a visit vary by 1.5–1.8 dB (median sample std, whole dBm), "
    "σ ≈ 1.7 dB once the 1 dB steps are taken out; APs a visit hears at −80…−55 dBm are "
    "missing from 0.2–6.1 % of its scans (4 % taken) [D]. Profiles with other figures keep "
    "them as the spread of phones [E]. wifi.antenna_side_ratio_db: the handset's own "
    "pattern, 8 dB from its antenna's side to the other [E] (HANDSET_SIDE_RATIO_DB)"
)

# The 16-bit full scales phones commonly configure (REALISM §1.4 [E]): ±8 g, ±2000 °/s.
_ACCEL_8G = 8 * STANDARD_GRAVITY
_GYRO_2000DPS = 2000 * DEG

_VIVO_S9 = DeviceProfile(
    name="vivo_s9",
    description=(
        "vivo S9 (2021, MediaTek Dimensity 1100, Android 11 / OriginOS): Han2023's phone for "
        "the 1.2 m grid survey and the walks, logged at 50 Hz. Its sensor chips are not "
        "published; figures are those of the 6-axis IMU and Hall magnetometer classes of "
        "2020-21 phones."
    ),
    accel=InertialSpec(
        rate_hz=50.0,
        noise_density=80 * UG,
        turn_on_bias_sigma=3 * MG,
        bias_instability=40 * UG,
        bias_correlation_s=100.0,
        random_walk=1.5e-5,
        scale_factor_sigma=0.005,
        misalignment_sigma_rad=0.5 * DEG,
        range=_ACCEL_8G,
        resolution=_ACCEL_8G / 32768,
    ),
    gyro=InertialSpec(
        rate_hz=50.0,
        noise_density=0.004 * DEG,
        turn_on_bias_sigma=0.1 * DEG,
        bias_instability=10 * DEG_PER_H,
        bias_correlation_s=100.0,
        random_walk=10 * DEG_PER_H_PER_SQRT_H,
        scale_factor_sigma=0.005,
        misalignment_sigma_rad=0.5 * DEG,
        range=_GYRO_2000DPS,
        resolution=_GYRO_2000DPS / 32768,
    ),
    mag=MagnetometerSpec(
        rate_hz=50.0,
        noise_sigma_uT=0.4,
        hard_iron_sigma_uT=1.5,
        soft_iron_diag_sigma=0.01,
        soft_iron_offdiag_sigma=0.005,
        resolution_uT=0.15,
        range_uT=4912.0,
    ),
    light=LightSensorSpec(
        half_sensitivity_deg=47.5,  # behind cover glass: mid ±35–60° [E] (REALISM §1.6)
        max_event_rate_hz=10.0,
        integration_time_s=0.1,
        range_lux=65535.0,
        resolution_lux=1.0,
        relative_noise=0.05,
        on_change=True,
        change_threshold_frac=0.02,
    ),
    wifi=WifiSpec(
        scan_interval_s=5.0,
        scan_duration_s=3.0,
        scan_duration_spread_s=1.0,
        throttling=True,
        detection_threshold_dbm=-95.0,
        fading_sigma_db=1.7,
        antenna_side_ratio_db=HANDSET_SIDE_RATIO_DB,
        miss_probability=0.04,
        quantisation_db=1.0,
    ),
    timestamp_jitter_frac=0.015,
    gap_probability=5e-4,
    sources=(
        _UJI_WIFI_SOURCE,
        "accel.rate_hz, gyro.rate_hz, mag.rate_hz = 50 Hz: Han2023 §4.2 'The data collection "
        "frequency was set to 50 Hz' (survey), §4.5 the walks use 'the same data acquisition "
        "equipment, software, relevant parameter settings' [S]",
        "IMU chip: unpublished; LSM6DSO / ICM-42605 class assumed [E]",
        "accel.noise_density 80 µg/√Hz: LSM6DSO 70 [E], ICM-42605 70 [S] (REALISM §1.1), "
        "rounded up for an in-phone part [E]",
        "accel.turn_on_bias_sigma 3 mg: OS/factory-calibrated 2–5 mg (REALISM §1.4) [E]",
        "accel.bias_instability 40 µg, T_c 100 s; accel.random_walk 1.5e-5 m/s²/√s [E]",
        "accel/gyro.scale_factor_sigma 0.5 %, misalignment 0.5°: REALISM §1.4 [E]",
        "accel.range ±8 g, gyro.range ±2000 °/s, 16-bit LSB: REALISM §1.4 [E]",
        "gyro.noise_density 0.004 °/s/√Hz: LSM6DSO / ICM-42605 3.8 mdps/√Hz (REALISM §1.1) [S/E]",
        "gyro.turn_on_bias_sigma 0.1 °/s: residual of Android's gyro drift compensation, "
        "below the CDD SR ceiling 0.57 °/s (REALISM §1.2) [E]",
        "gyro.bias_instability 10 °/h, T_c 100 s: 11-phone study 5–20 °/h (REALISM §1.4) [S/E]",
        "gyro.random_walk 10 °/h/√h [E]",
        "mag chip: AK09918 class assumed [E]; resolution 0.15 µT, range ±4912 µT: AK09918 "
        "datasheet (REALISM §1.5) [S]",
        "mag.noise_sigma_uT 0.4: 0.2–0.5 µT to simulate (REALISM §1.5) [D]",
        "mag.hard_iron_sigma_uT 1.5, soft iron 1 % / 0.5 %: residual after Android's online "
        "calibration (raw: 10–100 µT, few %) [E]",
        "light: behind-OLED ALS assumed (relative_noise 5 % from display leakage) [E]; "
        "100 ms integration, ≤ 10 Hz events (REALISM §1.6) [E]; range 65535 lx, 1 lx steps, "
        "2 % change threshold [E]",
        "wifi.throttling on: Android 11 default, 4 scans / 2 min (REALISM §4.3) [S]; "
        "Han2023 does not use WiFi",
        "wifi.scan_interval_s 5 (the app's request rate), scan_duration 3 ± 1 s: full "
        "dual-band scan 2–4 s (REALISM §4.3) [E]",
        "wifi.detection_threshold_dbm −95: REALISM §4.3 (−90…−95 dBm) [E]; "
        "quantisation 1 dB: ScanResult.level is an integer [S]",
        "timestamp_jitter_frac 1.5 %, gap_probability 5e-4: REALISM §1.3 (1–3 %, rare gaps) [E]",
    ),
)

_NEXUS_5X = DeviceProfile(
    name="nexus_5x",
    description=(
        "LG Nexus 5X (2015, Snapdragon 808, Android 6.0–8.1): Chen2022's walking phone, "
        "WiFi at 0.2 Hz. Commonly listed with a Bosch BMI160 IMU and a Bosch BMM150 "
        "magnetometer; the figures follow those parts."
    ),
    accel=InertialSpec(
        rate_hz=50.0,
        noise_density=180 * UG,
        turn_on_bias_sigma=5 * MG,
        bias_instability=60 * UG,
        bias_correlation_s=100.0,
        random_walk=2e-5,
        scale_factor_sigma=0.005,
        misalignment_sigma_rad=0.5 * DEG,
        range=_ACCEL_8G,
        resolution=_ACCEL_8G / 32768,
    ),
    gyro=InertialSpec(
        rate_hz=50.0,
        noise_density=0.007 * DEG,
        turn_on_bias_sigma=0.3 * DEG,
        bias_instability=20 * DEG_PER_H,
        bias_correlation_s=100.0,
        random_walk=20 * DEG_PER_H_PER_SQRT_H,
        scale_factor_sigma=0.01,
        misalignment_sigma_rad=0.5 * DEG,
        range=_GYRO_2000DPS,
        resolution=_GYRO_2000DPS / 32768,
    ),
    mag=MagnetometerSpec(
        rate_hz=50.0,
        noise_sigma_uT=0.5,
        hard_iron_sigma_uT=2.0,
        soft_iron_diag_sigma=0.01,
        soft_iron_offdiag_sigma=0.005,
        resolution_uT=0.3,
        range_uT=1300.0,
    ),
    light=LightSensorSpec(
        half_sensitivity_deg=47.5,  # behind cover glass: mid ±35–60° [E] (REALISM §1.6)
        max_event_rate_hz=5.0,
        integration_time_s=0.1,
        range_lux=43000.0,
        resolution_lux=1.0,
        relative_noise=0.03,
        on_change=True,
        change_threshold_frac=0.02,
    ),
    wifi=WifiSpec(
        scan_interval_s=5.0,
        scan_duration_s=3.0,
        scan_duration_spread_s=1.0,
        throttling=False,
        detection_threshold_dbm=-95.0,
        fading_sigma_db=1.7,
        antenna_side_ratio_db=HANDSET_SIDE_RATIO_DB,
        miss_probability=0.04,
        quantisation_db=1.0,
    ),
    timestamp_jitter_frac=0.02,
    gap_probability=1e-3,
    sources=(
        _UJI_WIFI_SOURCE,
        "wifi.scan_interval_s 5 (0.2 Hz): Chen2022 'WiFi fingerprint' (offline phase): "
        "'low WiFi RSS update rates, such as 0.2 Hz for Nexus 5X' [S]",
        "wifi.throttling off: Android ≤ 8.1 has no foreground scan throttling (REALISM §4.3) [S]",
        "wifi.scan_duration 3 ± 1 s: full dual-band scan 2–4 s (REALISM §4.3) [E]",
        "wifi.detection_threshold_dbm −95: REALISM §4.3 [E]; "
        "quantisation 1 dB: ScanResult.level is an integer [S]",
        "accel/gyro/mag rate 50 Hz: Chen2022 states no IMU rate; SENSOR_DELAY_GAME assumed [E]",
        "IMU chip: Bosch BMI160 (as commonly listed for this phone) [E]",
        "accel.noise_density 180 µg/√Hz: BMI160 (REALISM §1.1: 180 [E], 150 [S])",
        "accel.turn_on_bias_sigma 5 mg: BMI160 raw ±40 mg, factory-calibrated 2–5 mg "
        "(REALISM §1.1, §1.4) [E]",
        "accel.bias_instability 60 µg, T_c 100 s; accel.random_walk 2e-5 m/s²/√s [E]",
        "accel.scale_factor_sigma 0.5 %, misalignment 0.5°: REALISM §1.4 [E]",
        "accel.range ±8 g, gyro.range ±2000 °/s, 16-bit LSB: BMI160 ranges (REALISM §1.1) [S], "
        "setting [E]",
        "gyro.noise_density 0.007 °/s/√Hz: BMI160 (REALISM §1.1) [S/E]",
        "gyro.turn_on_bias_sigma 0.3 °/s: BMI160 ZRO ±3 °/s raw [S], after Android drift "
        "compensation (CDD SR ceiling 0.57 °/s) [E]",
        "gyro.bias_instability 20 °/h, T_c 100 s: top of the 5–20 °/h phone range for a "
        "2015 part (REALISM §1.4) [E]; gyro.random_walk 20 °/h/√h [E]",
        "gyro.scale_factor_sigma 1 %: BMI160 sensitivity error ±1 % typ = 1σ (REALISM §1.1) [E]",
        "mag chip: Bosch BMM150 [E]; resolution 0.3 µT, range ±1300 µT (x, y): BMM150 "
        "datasheet BST-BMM150-DS001-01 [S]",
        "mag.noise_sigma_uT 0.5: CDD SHOULD ≤ 0.5 µT (REALISM §1.2) [S], BMM150 regular "
        "preset ≈ 0.6 µT [E]",
        "mag.hard_iron_sigma_uT 2, soft iron 1 % / 0.5 %: residual after Android's online "
        "calibration [E]",
        "light: Rohm RPR-0521RS class assumed [E]; 100 ms integration, ≤ 5 Hz events "
        "(REALISM §1.6 2–10 Hz) [E]; range 43000 lx, 1 lx steps, 3 % noise, 2 % change "
        "threshold [E]",
        "timestamp_jitter_frac 2 %, gap_probability 1e-3: REALISM §1.3 (1–3 %, rare gaps) [E]",
    ),
)

_HONOR_50 = DeviceProfile(
    name="honor_50",
    description=(
        "Honor 50 (2021, Snapdragon 778G, Magic UI 4.2 / Android 11): Chen2022's survey phone "
        "for the WiFi and magnetic fingerprints. Its sensor chips are not published; "
        "figures are those of the 6-axis IMU and Hall magnetometer classes of 2020-21 phones."
    ),
    accel=InertialSpec(
        rate_hz=50.0,
        noise_density=90 * UG,
        turn_on_bias_sigma=3 * MG,
        bias_instability=40 * UG,
        bias_correlation_s=100.0,
        random_walk=1.5e-5,
        scale_factor_sigma=0.005,
        misalignment_sigma_rad=0.5 * DEG,
        range=_ACCEL_8G,
        resolution=_ACCEL_8G / 32768,
    ),
    gyro=InertialSpec(
        rate_hz=50.0,
        noise_density=0.005 * DEG,
        turn_on_bias_sigma=0.15 * DEG,
        bias_instability=10 * DEG_PER_H,
        bias_correlation_s=100.0,
        random_walk=10 * DEG_PER_H_PER_SQRT_H,
        scale_factor_sigma=0.005,
        misalignment_sigma_rad=0.5 * DEG,
        range=_GYRO_2000DPS,
        resolution=_GYRO_2000DPS / 32768,
    ),
    mag=MagnetometerSpec(
        rate_hz=50.0,
        noise_sigma_uT=0.4,
        hard_iron_sigma_uT=1.5,
        soft_iron_diag_sigma=0.01,
        soft_iron_offdiag_sigma=0.005,
        resolution_uT=0.15,
        range_uT=4912.0,
    ),
    light=LightSensorSpec(
        half_sensitivity_deg=47.5,  # behind cover glass: mid ±35–60° [E] (REALISM §1.6)
        max_event_rate_hz=10.0,
        integration_time_s=0.1,
        range_lux=65535.0,
        resolution_lux=1.0,
        relative_noise=0.05,
        on_change=True,
        change_threshold_frac=0.02,
    ),
    wifi=WifiSpec(
        scan_interval_s=5.0,
        scan_duration_s=3.0,
        scan_duration_spread_s=1.0,
        throttling=False,
        detection_threshold_dbm=-95.0,
        fading_sigma_db=1.7,
        antenna_side_ratio_db=HANDSET_SIDE_RATIO_DB,
        miss_probability=0.04,
        quantisation_db=1.0,
    ),
    timestamp_jitter_frac=0.015,
    gap_probability=5e-4,
    sources=(
        _UJI_WIFI_SOURCE,
        "rates 50 Hz: Chen2022 states none for the survey; SENSOR_DELAY_GAME assumed [E]",
        "wifi.throttling off: Android 11 throttles by default (4 scans / 2 min, REALISM §4.3 [S]), "
        "far too few for a walk survey; the team is assumed to have switched the 'Wi-Fi scan "
        "throttling' developer option off (Android 10+) [E]",
        "wifi.scan_interval_s 5: Chen2022's 0.2 Hz figure for Android phones [S]; "
        "scan_duration 3 ± 1 s (REALISM §4.3) [E]",
        "wifi.detection_threshold_dbm −95: REALISM §4.3 [E]; "
        "quantisation 1 dB: ScanResult.level is an integer [S]",
        "IMU chip: unpublished; LSM6DSO / ICM-42605 class assumed [E]",
        "accel.noise_density 90 µg/√Hz: 70 µg/√Hz parts (REALISM §1.1) in a phone [E]",
        "accel.turn_on_bias_sigma 3 mg (REALISM §1.4) [E]; bias_instability 40 µg, "
        "T_c 100 s, random_walk 1.5e-5 m/s²/√s [E]",
        "gyro.noise_density 0.005 °/s/√Hz: 3.8 mdps/√Hz parts (REALISM §1.1) in a phone [E]",
        "gyro.turn_on_bias_sigma 0.15 °/s after Android drift compensation [E]; "
        "bias_instability 10 °/h (REALISM §1.4) [S/E]; random_walk 10 °/h/√h [E]",
        "scale_factor_sigma 0.5 %, misalignment 0.5°, ±8 g / ±2000 °/s 16-bit: REALISM §1.4 [E]",
        "mag chip: AK09918 class assumed [E]; 0.15 µT LSB, ±4912 µT (REALISM §1.5) [S]; "
        "noise 0.4 µT (REALISM §1.5) [D]; residual hard iron 1.5 µT, soft iron 1 % / 0.5 % [E]",
        "light: behind-OLED ALS assumed [E]; 100 ms, ≤ 10 Hz, 65535 lx, 1 lx, 5 % noise, "
        "2 % threshold [E]",
        "timestamp_jitter_frac 1.5 %, gap_probability 5e-4: REALISM §1.3 [E]",
    ),
)

_LOW_GRADE = DeviceProfile(
    name="low_grade",
    description=(
        "A budget phone near the Android CDD floor: 50 Hz IMU, noisy and loosely calibrated "
        "sensors, coarse 0.6 µT magnetometer, 3 % timestamp jitter, throttled WiFi."
    ),
    accel=InertialSpec(
        rate_hz=50.0,
        noise_density=300 * UG,
        turn_on_bias_sigma=10 * MG,
        bias_instability=100 * UG,
        bias_correlation_s=60.0,
        random_walk=5e-5,
        scale_factor_sigma=0.01,
        misalignment_sigma_rad=1.0 * DEG,
        range=4 * STANDARD_GRAVITY,
        resolution=8 * STANDARD_GRAVITY / 32768,
    ),
    gyro=InertialSpec(
        rate_hz=50.0,
        noise_density=0.015 * DEG,
        turn_on_bias_sigma=0.5 * DEG,
        bias_instability=30 * DEG_PER_H,
        bias_correlation_s=60.0,
        random_walk=40 * DEG_PER_H_PER_SQRT_H,
        scale_factor_sigma=0.01,
        misalignment_sigma_rad=1.0 * DEG,
        range=1000 * DEG,
        resolution=2000 * DEG / 32768,
    ),
    mag=MagnetometerSpec(
        rate_hz=50.0,
        noise_sigma_uT=1.0,
        hard_iron_sigma_uT=5.0,
        soft_iron_diag_sigma=0.02,
        soft_iron_offdiag_sigma=0.01,
        resolution_uT=0.6,
        range_uT=900.0,
    ),
    light=LightSensorSpec(
        half_sensitivity_deg=47.5,  # behind cover glass: mid ±35–60° [E] (REALISM §1.6)
        max_event_rate_hz=2.0,
        integration_time_s=0.2,
        range_lux=10000.0,
        resolution_lux=1.0,
        relative_noise=0.05,
        on_change=True,
        change_threshold_frac=0.05,
    ),
    wifi=WifiSpec(
        scan_interval_s=5.0,
        scan_duration_s=4.0,
        scan_duration_spread_s=1.0,
        throttling=True,
        detection_threshold_dbm=-90.0,
        fading_sigma_db=3.0,
        antenna_side_ratio_db=HANDSET_SIDE_RATIO_DB,
        miss_probability=0.04,
        quantisation_db=1.0,
    ),
    timestamp_jitter_frac=0.03,
    gap_probability=2e-3,
    sources=(
        _UJI_WIFI_SOURCE,
        "rates: CDD MUST ≥ 50 Hz accel/gyro, ≥ 10 Hz mag (REALISM §1.2) [S], 50 Hz chosen",
        "accel range ±4 g: CDD minimum [S]; gyro range ±1000 °/s: CDD minimum [S]; 16-bit "
        "over ±8 g / ±2000 °/s (chip setting, REALISM §1.4) [E]",
        "accel.noise_density 300 µg/√Hz: above the 120–250 suggested draw, within CDD's "
        "0.05 m/s² per-axis std (REALISM §1.2, §1.4) [D/E]",
        "gyro.noise_density 0.015 °/s/√Hz: under the CDD ceiling 0.018 (REALISM §1.2) [D/E]",
        "turn-on bias 10 mg / 0.5 °/s: REALISM §1.4 (20 mg raw; CDD SR 0.57 °/s) [E]",
        "bias instability 100 µg / 30 °/h, T_c 60 s; random walk 5e-5 m/s²/√s / 40 °/h/√h [E]",
        "scale factor 1 % (TDK ±1 %), misalignment 1° (REALISM §1.1, §1.4) [E]",
        "mag: noise 1.0 µT (CDD MUST ≤ 1.5), resolution 0.6 µT (CDD ≤ 0.6; AK09911), "
        "range ±900 µT (CDD) (REALISM §1.2, §1.5) [S]; residual hard iron 5 µT, soft iron "
        "2 % / 1 % [E]",
        "light: 200 ms integration, ≤ 2 Hz, 10 klx range, 5 % noise and threshold [E]",
        "wifi: throttled (Android 9+ default) [S]; 4 ± 1 s scans, −90 dBm threshold, 3 dB "
        "fading (REALISM §4.3) [E]",
        "timestamp_jitter_frac 3 %: CDD ceiling (REALISM §1.2) [S]; gap_probability 2e-3 [E]",
    ),
)

_MID_GRADE = DeviceProfile(
    name="mid_grade",
    description=(
        "A typical mid-range phone: the suggested per-device draws of REALISM §1.4 at 100 Hz."
    ),
    accel=InertialSpec(
        rate_hz=100.0,
        noise_density=150 * UG,
        turn_on_bias_sigma=4 * MG,
        bias_instability=50 * UG,
        bias_correlation_s=100.0,
        random_walk=2e-5,
        scale_factor_sigma=0.005,
        misalignment_sigma_rad=0.5 * DEG,
        range=_ACCEL_8G,
        resolution=_ACCEL_8G / 32768,
    ),
    gyro=InertialSpec(
        rate_hz=100.0,
        noise_density=0.007 * DEG,
        turn_on_bias_sigma=0.2 * DEG,
        bias_instability=10 * DEG_PER_H,
        bias_correlation_s=100.0,
        random_walk=15 * DEG_PER_H_PER_SQRT_H,
        scale_factor_sigma=0.005,
        misalignment_sigma_rad=0.5 * DEG,
        range=_GYRO_2000DPS,
        resolution=_GYRO_2000DPS / 32768,
    ),
    mag=MagnetometerSpec(
        rate_hz=50.0,
        noise_sigma_uT=0.4,
        hard_iron_sigma_uT=2.0,
        soft_iron_diag_sigma=0.01,
        soft_iron_offdiag_sigma=0.005,
        resolution_uT=0.15,
        range_uT=4912.0,
    ),
    light=LightSensorSpec(
        half_sensitivity_deg=47.5,  # behind cover glass: mid ±35–60° [E] (REALISM §1.6)
        max_event_rate_hz=5.0,
        integration_time_s=0.1,
        range_lux=30000.0,
        resolution_lux=1.0,
        relative_noise=0.03,
        on_change=True,
        change_threshold_frac=0.02,
    ),
    wifi=WifiSpec(
        scan_interval_s=5.0,
        scan_duration_s=3.0,
        scan_duration_spread_s=0.5,
        throttling=True,
        detection_threshold_dbm=-93.0,
        fading_sigma_db=1.7,
        antenna_side_ratio_db=HANDSET_SIDE_RATIO_DB,
        miss_probability=0.04,
        quantisation_db=1.0,
    ),
    timestamp_jitter_frac=0.02,
    gap_probability=5e-4,
    sources=(
        _UJI_WIFI_SOURCE,
        "accel: noise 150 µg/√Hz, turn-on 4 mg (calibrated), scale 0.5 %, misalignment 0.5° "
        "(REALISM §1.4 suggested draws) [E]; bias instability 50 µg, T_c 100 s, random "
        "walk 2e-5 m/s²/√s [E]",
        "gyro: noise 0.007 °/s/√Hz (BMI160/BMI270 class, REALISM §1.1) [S]; turn-on 0.2 °/s "
        "calibrated, bias instability 10 °/h (REALISM §1.4) [E]; random walk 15 °/h/√h [E]",
        "ranges ±8 g / ±2000 °/s, 16-bit (REALISM §1.4) [E]; rate 100 Hz [E]",
        "mag: AK09918 class 0.15 µT / ±4912 µT [S], noise 0.4 µT [D], residual hard iron "
        "2 µT, soft iron 1 % / 0.5 % [E]; 50 Hz (CDD SHOULD) [S]",
        "light: 100 ms, ≤ 5 Hz (REALISM §1.6) [E]; 30 klx, 1 lx, 3 %, 2 % threshold [E]",
        "wifi: throttled (Android 9+) [S]; 3 ± 0.5 s scans, −93 dBm, 2 dB fading "
        "(REALISM §4.3) [E]; 1 dB steps [S]",
        "timestamp_jitter_frac 2 %, gap_probability 5e-4 (REALISM §1.3) [E]",
    ),
)

_HIGH_GRADE = DeviceProfile(
    name="high_grade",
    description=(
        "A flagship with CDD 'hifi sensors' class parts (LSM6DSV / ICM-42605): 200 Hz, low "
        "noise, tight calibration, 1 % jitter, WiFi throttling switched off."
    ),
    accel=InertialSpec(
        rate_hz=200.0,
        noise_density=60 * UG,
        turn_on_bias_sigma=2 * MG,
        bias_instability=20 * UG,
        bias_correlation_s=200.0,
        random_walk=1e-5,
        scale_factor_sigma=0.003,
        misalignment_sigma_rad=0.2 * DEG,
        range=_ACCEL_8G,
        resolution=_ACCEL_8G / 32768,
    ),
    gyro=InertialSpec(
        rate_hz=200.0,
        noise_density=0.0028 * DEG,
        turn_on_bias_sigma=0.05 * DEG,
        bias_instability=3 * DEG_PER_H,
        bias_correlation_s=200.0,
        random_walk=5 * DEG_PER_H_PER_SQRT_H,
        scale_factor_sigma=0.003,
        misalignment_sigma_rad=0.2 * DEG,
        range=_GYRO_2000DPS,
        resolution=_GYRO_2000DPS / 32768,
    ),
    mag=MagnetometerSpec(
        rate_hz=100.0,
        noise_sigma_uT=0.2,
        hard_iron_sigma_uT=1.0,
        soft_iron_diag_sigma=0.005,
        soft_iron_offdiag_sigma=0.0025,
        resolution_uT=0.15,
        range_uT=4912.0,
    ),
    light=LightSensorSpec(
        half_sensitivity_deg=47.5,  # behind cover glass: mid ±35–60° [E] (REALISM §1.6)
        max_event_rate_hz=10.0,
        integration_time_s=0.05,
        range_lux=65535.0,
        resolution_lux=0.1,
        relative_noise=0.01,
        on_change=True,
        change_threshold_frac=0.01,
    ),
    wifi=WifiSpec(
        scan_interval_s=3.0,
        scan_duration_s=2.0,
        scan_duration_spread_s=0.5,
        throttling=False,
        detection_threshold_dbm=-95.0,
        fading_sigma_db=1.5,
        antenna_side_ratio_db=HANDSET_SIDE_RATIO_DB,
        miss_probability=0.04,
        quantisation_db=1.0,
    ),
    timestamp_jitter_frac=0.01,
    gap_probability=1e-4,
    sources=(
        _UJI_WIFI_SOURCE,
        "accel.noise_density 60 µg/√Hz, gyro 2.8 mdps/√Hz: LSM6DSV (REALISM §1.1) [S]",
        "rate 200 Hz: CDD SHOULD (REALISM §1.2) [S]; hifi timestamps within 2.5 ms [S]",
        "turn-on 2 mg / 0.05 °/s, bias instability 20 µg / 3 °/h (T_c 200 s), random walk "
        "1e-5 m/s²/√s / 5 °/h/√h, scale 0.3 %, misalignment 0.2° [E]",
        "ranges ±8 g / ±2000 °/s, 16-bit (REALISM §1.4) [E]",
        "mag: 100 Hz (AK09918 current spec at 100 Hz), 0.15 µT / ±4912 µT (REALISM §1.5) [S]; "
        "noise 0.2 µT (REALISM §1.5 0.2–0.5) [D]; residual hard iron 1 µT, soft iron "
        "0.5 % / 0.25 % [E]",
        "light: 50 ms integration, ≤ 10 Hz, 0.1 lx steps, 1 % noise and threshold [E]",
        "wifi: throttling switched off (Android 10+ developer option) and a 2 ± 0.5 s scan "
        "every 3 s, i.e. ≈ 0.33 Hz (REALISM §4.3 0.25–0.5 Hz) [E]; −95 dBm, 1.5 dB fading [E]",
        "timestamp_jitter_frac 1 %, gap_probability 1e-4 (REALISM §1.3) [E]",
    ),
)

DEVICES: Mapping[str, DeviceProfile] = MappingProxyType(
    {
        p.name: p
        for p in (_IDEAL, _VIVO_S9, _NEXUS_5X, _HONOR_50, _LOW_GRADE, _MID_GRADE, _HIGH_GRADE)
    }
)
"""The built-in profiles by name (read-only). Plugins add more: see :func:`available_devices`."""


class UnknownDeviceError(UnknownNameError):
    """A device name that is neither built in nor provided by an entry point."""

    kind = "device"


def available_devices() -> dict[str, DeviceProfile]:
    """Every device profile by name: the built-in ones, then those of entry points.

    A plugin cannot replace a built-in profile: an entry point with a built-in
    name is ignored, so ``ideal`` and the papers' phones mean the same thing
    wherever indoorsim runs.

    Raises:
        TypeError: an entry point does not load to a :class:`DeviceProfile`.
        ValueError: an entry point's profile has a ``name`` other than the entry point's.
    """
    found = dict(DEVICES)
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name in found:
            continue
        profile = ep.load()
        if not isinstance(profile, DeviceProfile):
            raise TypeError(
                f"entry point {ep.name!r} ({ep.value}) in group {ENTRY_POINT_GROUP!r} loads to "
                f"a {type(profile).__name__}, not a DeviceProfile"
            )
        if profile.name != ep.name:
            raise ValueError(
                f"entry point {ep.name!r} ({ep.value}) loads to a profile named "
                f"{profile.name!r}; the names must match"
            )
        found[ep.name] = profile
    return found


def _load_device_file(path: Path) -> DeviceProfile:
    """The profile in a YAML file: the profile's fields, or under a ``device:`` key (the
    layout ``indoorsim calibrate`` writes, beside ``walker:``)."""
    return device_from_dict(read_yaml_section(path, "device", DeviceFileError), source=str(path))


def get_device(name: str) -> DeviceProfile:
    """The device profile called ``name``, or the one in the YAML file ``name`` (a path
    ending in ``.yaml`` or ``.yml``, as ``indoorsim calibrate`` writes).

    Raises:
        UnknownDeviceError: no such profile; the message lists the valid names.
        DeviceFileError: the file cannot be read or holds an invalid profile.
    """
    if name in DEVICES:
        # Built-ins never need the entry points, so a broken plugin cannot break them.
        return DEVICES[name]
    if name.endswith((".yaml", ".yml")):
        return _load_device_file(Path(name))
    known = available_devices()
    if name not in known:
        raise UnknownDeviceError(name, sorted(known))
    return known[name]
