"""Device profiles: what each simulated phone's sensors get wrong, and how often they report.

A :class:`DeviceProfile` bundles one error specification per sensor —
:class:`InertialSpec` for the accelerometer and the gyroscope,
:class:`MagnetometerSpec`, :class:`LightSensorSpec`, :class:`WifiSpec` — plus the
timing faults shared by the continuous sensors (timestamp jitter, dropped
samples). The specs are declarations only; :mod:`indoorsim.phone.sensors`
realises them with a seeded generator. Every spec's defaults describe a perfect
sensor, so ``InertialSpec()`` is already a working (error-free) component.

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
below are written from datasheet units through the conversion constants of this
module), magnetic field in µT, illuminance in lux, RSS in dBm, times in s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from types import MappingProxyType

from indoorsim.util.errors import UnknownNameError

__all__ = [
    "DEVICES",
    "ENTRY_POINT_GROUP",
    "HANDSET_SIDE_RATIO_DB",
    "DeviceProfile",
    "InertialSpec",
    "LightSensorSpec",
    "MagnetometerSpec",
    "UnknownDeviceError",
    "WifiSpec",
    "available_devices",
    "cosine_power",
    "get_device",
]

STANDARD_GRAVITY = 9.80665
"""m/s² per g."""
MG = STANDARD_GRAVITY * 1e-3
"""m/s² per milli-g."""
UG = STANDARD_GRAVITY * 1e-6
"""m/s² per micro-g (noise densities are quoted in µg/√Hz)."""
DEG = math.pi / 180
"""rad per degree (°/s → rad/s, °/s/√Hz → rad/s/√Hz)."""
DEG_PER_H = DEG / 3600
"""rad/s per °/h (bias instability is quoted in °/h)."""
DEG_PER_H_PER_SQRT_H = DEG_PER_H / 60
"""rad/s/√s per °/h/√h (rate random walk): 1 °/h/√h = (π/180/3600 rad/s) / √(3600 s)."""

ENTRY_POINT_GROUP = "indoorsim.devices"
"""Entry-point group through which other packages add device profiles."""


def _check(
    spec: object, *, nonnegative: tuple[str, ...] = (), positive: tuple[str, ...] = ()
) -> None:
    """Raise ValueError naming the first field of ``spec`` outside its allowed range.

    NaN fails both tests, so a missing figure cannot slip through as NaN.
    """
    for name in nonnegative:
        value = getattr(spec, name)
        if not value >= 0:
            raise ValueError(f"{type(spec).__name__}.{name} must be >= 0, got {value}")
    for name in positive:
        value = getattr(spec, name)
        if not value > 0:
            raise ValueError(f"{type(spec).__name__}.{name} must be > 0, got {value}")


@dataclass(frozen=True, kw_only=True)
class InertialSpec:
    """Error model of a 3-axis accelerometer or gyroscope.

    U below is the sensor's unit: m/s² for an accelerometer, rad/s for a
    gyroscope. The model (realised by :func:`indoorsim.phone.sensors.apply_inertial`) is

        y = Q(sat((I + S + M)·x + b_on + b_GM(t) + b_RW(t) + w))

    Attributes:
        rate_hz: nominal output data rate, Hz.
        noise_density: white-noise density N, U/√Hz; the Allan deviation of
            the white part is N/√τ, so it reads N at τ = 1 s.
        turn_on_bias_sigma: 1σ per axis of b_on, the bias drawn once per run, U.
        bias_instability: stationary 1σ of b_GM, a first-order Gauss–Markov
            bias, U. Its Allan deviation peaks at ≈ 0.62·σ near τ ≈ 1.9·T_c.
        bias_correlation_s: T_c, correlation time of b_GM, s.
        random_walk: rate random walk coefficient K of b_RW, U/√s (= U/s/√Hz,
            e.g. rad/s/√s): the bias drifts by K·√Δt over Δt, and its Allan
            deviation is K·√(τ/3).
        scale_factor_sigma: 1σ of each diagonal entry of S, fraction (0.01 = 1 %).
        misalignment_sigma_rad: 1σ of each off-diagonal entry of M (axis
            misalignment and non-orthogonality), rad.
        range: saturation limit ±range per axis, U (``inf``: never saturates).
        resolution: quantisation step (one LSB), U (0: not quantised).
    """

    rate_hz: float = 100.0
    noise_density: float = 0.0
    turn_on_bias_sigma: float = 0.0
    bias_instability: float = 0.0
    bias_correlation_s: float = 100.0
    random_walk: float = 0.0
    scale_factor_sigma: float = 0.0
    misalignment_sigma_rad: float = 0.0
    range: float = math.inf
    resolution: float = 0.0

    def __post_init__(self) -> None:
        _check(
            self,
            nonnegative=(
                "noise_density",
                "turn_on_bias_sigma",
                "bias_instability",
                "random_walk",
                "scale_factor_sigma",
                "misalignment_sigma_rad",
                "resolution",
            ),
            positive=("rate_hz", "bias_correlation_s", "range"),
        )


@dataclass(frozen=True, kw_only=True)
class MagnetometerSpec:
    """Error model of the calibrated magnetometer (Android ``TYPE_MAGNETIC_FIELD``).

    Android removes the hard-iron offset online and compensates soft iron, so
    the figures here are what is left after that calibration (the raw offsets
    of tens of µT belong to ``TYPE_MAGNETIC_FIELD_UNCALIBRATED``). The model
    (:func:`indoorsim.phone.sensors.apply_magnetometer`) is

        y = Q(sat((I + A)·B + h + w)),   A symmetric

    Attributes:
        rate_hz: nominal output data rate, Hz.
        noise_sigma_uT: per-axis white-noise 1σ of one sample at ``rate_hz``, µT.
        hard_iron_sigma_uT: 1σ per axis of the residual hard-iron offset h, µT.
        soft_iron_diag_sigma: 1σ of A's diagonal entries (axis gain error), fraction.
        soft_iron_offdiag_sigma: 1σ of A's off-diagonal entries (cross-coupling), fraction.
        resolution_uT: quantisation step, µT (0: not quantised).
        range_uT: saturation limit ±range per axis, µT (``inf``: never saturates).
    """

    rate_hz: float = 100.0
    noise_sigma_uT: float = 0.0
    hard_iron_sigma_uT: float = 0.0
    soft_iron_diag_sigma: float = 0.0
    soft_iron_offdiag_sigma: float = 0.0
    resolution_uT: float = 0.0
    range_uT: float = math.inf

    def __post_init__(self) -> None:
        _check(
            self,
            nonnegative=(
                "noise_sigma_uT",
                "hard_iron_sigma_uT",
                "soft_iron_diag_sigma",
                "soft_iron_offdiag_sigma",
                "resolution_uT",
            ),
            positive=("rate_hz", "range_uT"),
        )


def cosine_power(half_sensitivity_deg: float) -> float:
    """The k of an angular response cosᵏψ that falls to half at ``half_sensitivity_deg``
    (REALISM §1.6: a bare photodiode is a cosine, k = 1 at 60°; behind a phone's
    cover glass and aperture ±35–60°): k = ln ½ / ln cos ψ½."""
    if not 0.0 < half_sensitivity_deg <= 60.0:
        raise ValueError(f"half_sensitivity_deg must be in (0, 60], got {half_sensitivity_deg}")
    if half_sensitivity_deg == 60.0:
        return 1.0  # exactly: cos 60° = ½ only to a rounding error
    return math.log(0.5) / math.log(math.cos(math.radians(half_sensitivity_deg)))


@dataclass(frozen=True, kw_only=True)
class LightSensorSpec:
    """Ambient light sensor (Android ``TYPE_LIGHT``, an on-change sensor).

    The sensor converts back to back, each conversion averaging the
    illuminance over the last ``integration_time_s``; the driver reports a
    conversion only when it differs from the last reported value, and no faster
    than ``max_event_rate_hz`` (:func:`indoorsim.phone.sensors.light_events`).

    Attributes:
        max_event_rate_hz: highest event rate the driver delivers, Hz (``inf``: no cap).
        integration_time_s: averaging window of one conversion, s. 0 reads the
            illuminance instantly at every input sample.
        range_lux: saturation limit, lux (``inf``: never saturates).
        resolution_lux: quantisation step, lux (0: not quantised).
        relative_noise: 1σ of the multiplicative noise, fraction of the reading.
        on_change: report only changed readings (Android's behaviour); False
            reports every conversion.
        change_threshold_frac: with ``on_change``, a reading counts as changed
            when it differs from the last reported one and by at least this
            fraction of it.
        half_sensitivity_deg: incidence angle at which the sensor's response
            falls to half: 60° is a cosine receiver (a bare photodiode); behind a
            phone's cover glass and aperture ±35–60° (REALISM §1.6). The
            response is cosᵏψ with k from :func:`cosine_power`,
            calibrated at normal incidence.
    """

    max_event_rate_hz: float = math.inf
    integration_time_s: float = 0.0
    range_lux: float = math.inf
    resolution_lux: float = 0.0
    relative_noise: float = 0.0
    on_change: bool = False
    change_threshold_frac: float = 0.0
    half_sensitivity_deg: float = 60.0

    def __post_init__(self) -> None:
        _check(
            self,
            nonnegative=(
                "integration_time_s",
                "resolution_lux",
                "relative_noise",
                "change_threshold_frac",
            ),
            positive=("max_event_rate_hz", "range_lux"),
        )
        if not 0.0 < self.half_sensitivity_deg <= 60.0:
            raise ValueError(
                f"half_sensitivity_deg must be in (0, 60] (60 is a cosine receiver), "
                f"got {self.half_sensitivity_deg}"
            )

    @property
    def response_exponent(self) -> float:
        """k of the angular response cosᵏψ (1 for a cosine receiver)."""
        return cosine_power(self.half_sensitivity_deg)


@dataclass(frozen=True, kw_only=True)
class WifiSpec:
    """WiFi scanning of an app in the foreground.

    The app asks for a scan every ``scan_interval_s``, or, ``continuous``, as
    soon as the previous scan's results arrive (what logging apps do); with
    ``throttling`` (Android 9+ default) a foreground app gets at most 4 scans
    per 2 minutes and further requests are refused. A scan's results arrive
    ``scan_duration_s`` (± ``scan_duration_spread_s``, uniform) after its
    request. Each reported RSS is the received power at the phone (the site's
    mean and multipath fade, ``Site.rss(small_scale=True)``) plus the reading's
    own variation, Gaussian in dB, quantised; an AP's beacon is missed with
    ``miss_probability``, and readings below the detection threshold are dropped
    (:func:`indoorsim.phone.sensors.wifi_scans`, :func:`~indoorsim.phone.sensors.scan_rss`).

    Attributes:
        scan_interval_s: time between the app's scan requests, s (``continuous``:
            the wait before retrying a refused request).
        scan_duration_s: mean time from request to results (a full dual-band scan), s.
        scan_duration_spread_s: half-width of the uniform spread of the duration, s.
        throttling: Android 9+ foreground scan throttling (4 scans per 120 s) is on.
        continuous: the app requests the next scan when the last one's results arrive.
        detection_threshold_dbm: weakest RSS reported, dBm (``-inf``: every AP heard).
        fading_sigma_db: 1σ of a still phone's readings of one AP from scan to scan,
            dB: people moving, the RSSI estimate's own error (the multipath fade of
            the place itself is the site's, not this).
        miss_probability: chance that a scan misses an AP it would hear (its beacon
            or probe response lost), independently per scan and AP.
        quantisation_db: RSS reporting step, dB (Android reports whole dBm: 1; 0: exact).
        antenna_side_ratio_db: the handset's receive gain toward its +x side (the right
            edge, the screen toward the user) over its gain toward −x, dB; 0: an
            isotropic phone. The gain in dB is (ratio/2)·cos of the angle between
            phone +x and the direction to the AP (:meth:`indoorsim.world.radio.
            RadioModel.handset_gain_db`): the WiFi antenna sits at one edge of the
            handset, and the chassis (board, battery, screen) and the hand holding it
            shade the other side, so a phone turned round reads an AP on its side
            several dB apart, where the carrier's trunk changes nothing.
    """

    scan_interval_s: float = 5.0
    scan_duration_s: float = 0.0
    scan_duration_spread_s: float = 0.0
    throttling: bool = False
    continuous: bool = False
    detection_threshold_dbm: float = -math.inf
    fading_sigma_db: float = 0.0
    miss_probability: float = 0.0
    quantisation_db: float = 0.0
    antenna_side_ratio_db: float = 0.0

    def __post_init__(self) -> None:
        _check(
            self,
            nonnegative=(
                "scan_duration_s",
                "scan_duration_spread_s",
                "fading_sigma_db",
                "quantisation_db",
                "antenna_side_ratio_db",
            ),
            positive=("scan_interval_s",),
        )
        if not 0.0 <= self.miss_probability < 1.0:
            raise ValueError(
                f"WifiSpec.miss_probability must be in [0, 1), got {self.miss_probability}"
            )
        if self.scan_duration_spread_s > self.scan_duration_s:
            raise ValueError("WifiSpec.scan_duration_spread_s must not exceed scan_duration_s")
        # A scan must end before the app's next request, so results stay in order.
        if (
            not self.continuous
            and self.scan_duration_s + self.scan_duration_spread_s > self.scan_interval_s
        ):
            raise ValueError(
                "WifiSpec: scan_duration_s + scan_duration_spread_s must not exceed "
                f"scan_interval_s ({self.scan_duration_s} + {self.scan_duration_spread_s} "
                f"> {self.scan_interval_s})"
            )
        if math.isnan(self.detection_threshold_dbm):
            raise ValueError("WifiSpec.detection_threshold_dbm must not be NaN")


@dataclass(frozen=True, kw_only=True)
class DeviceProfile:
    """One phone model: an error specification per sensor and its timing faults.

    Attributes:
        name: registry key.
        description: what the phone is and how the figures were chosen.
        accel: accelerometer, m/s².
        gyro: gyroscope, rad/s.
        mag: calibrated magnetometer, µT.
        light: ambient light sensor, lux.
        wifi: WiFi scanning, dBm.
        timestamp_jitter_frac: σ of the interval between consecutive timestamps
            of the continuous sensors, as a fraction of their period (Android
            CDD: SHOULD be < 0.03).
        gap_probability: chance per sample that a run of 1–3 samples is dropped.
        sources: one line per figure (or group of figures) naming where it
            comes from, tagged [S] sourced, [D] derived or [E] estimated.
    """

    name: str
    description: str = ""
    accel: InertialSpec = field(default_factory=InertialSpec)
    gyro: InertialSpec = field(default_factory=InertialSpec)
    mag: MagnetometerSpec = field(default_factory=MagnetometerSpec)
    light: LightSensorSpec = field(default_factory=LightSensorSpec)
    wifi: WifiSpec = field(default_factory=WifiSpec)
    timestamp_jitter_frac: float = 0.0
    gap_probability: float = 0.0
    sources: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        _check(self, nonnegative=("timestamp_jitter_frac", "gap_probability"))
        if self.gap_probability >= 1:
            raise ValueError(
                f"DeviceProfile.gap_probability must be < 1, got {self.gap_probability}"
            )
        expected = {
            "accel": InertialSpec,
            "gyro": InertialSpec,
            "mag": MagnetometerSpec,
            "light": LightSensorSpec,
            "wifi": WifiSpec,
        }
        for name, cls in expected.items():
            spec = getattr(self, name)
            if not isinstance(spec, cls):
                raise TypeError(
                    f"DeviceProfile.{name} must be a {cls.__name__}, got {type(spec).__name__}"
                )


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


def get_device(name: str) -> DeviceProfile:
    """The device profile called ``name``.

    Raises:
        UnknownDeviceError: no such profile; the message lists the valid names.
    """
    if name in DEVICES:
        # Built-ins never need the entry points, so a broken plugin cannot break them.
        return DEVICES[name]
    known = available_devices()
    if name not in known:
        raise UnknownDeviceError(name, sorted(known))
    return known[name]
