"""Sensor error specifications: what one phone's sensors get wrong, as declarations.

:class:`DeviceProfile` bundles one specification per sensor —
:class:`InertialSpec` for the accelerometer and the gyroscope,
:class:`MagnetometerSpec`, :class:`LightSensorSpec`, :class:`WifiSpec` — plus the
timing faults shared by the continuous sensors (timestamp jitter, dropped
samples). :mod:`indoorsim.phone.sensors` realises them with a seeded generator;
:mod:`indoorsim.phone.devices` holds the named phones. Every spec's defaults
describe a perfect sensor, so ``InertialSpec()`` is already a working
(error-free) component.

:func:`device_to_dict` and :func:`device_from_dict` turn a profile into plain
data and back: the layout of a device YAML file.

Units: accelerometer figures in m/s², gyroscope figures in rad/s (written from
datasheet units through the conversion constants of this module), magnetic
field in µT, illuminance in lux, RSS in dBm, times in s.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "DEG",
    "DEG_PER_H",
    "DEG_PER_H_PER_SQRT_H",
    "MG",
    "STANDARD_GRAVITY",
    "UG",
    "DeviceFileError",
    "DeviceProfile",
    "InertialSpec",
    "LightSensorSpec",
    "MagnetometerSpec",
    "WifiSpec",
    "cosine_power",
    "device_from_dict",
    "device_to_dict",
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
        hard_iron_uT: this unit's residual hard-iron offset h (x, y, z), phone
            frame, µT, where it is known — a twin calibrated on a real
            recording (``indoorsim calibrate``); None draws h per run from
            ``hard_iron_sigma_uT``.
    """

    rate_hz: float = 100.0
    noise_sigma_uT: float = 0.0
    hard_iron_sigma_uT: float = 0.0
    soft_iron_diag_sigma: float = 0.0
    soft_iron_offdiag_sigma: float = 0.0
    resolution_uT: float = 0.0
    range_uT: float = math.inf
    hard_iron_uT: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        if self.hard_iron_uT is not None:
            try:
                offset = tuple(float(v) for v in self.hard_iron_uT)
            except TypeError:
                offset = ()
            if len(offset) != 3 or not all(math.isfinite(v) for v in offset):
                raise ValueError(
                    f"MagnetometerSpec.hard_iron_uT must be three finite numbers (x, y, z), "
                    f"got {self.hard_iron_uT!r}"
                )
            object.__setattr__(self, "hard_iron_uT", offset)
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


class DeviceFileError(ValueError):
    """A device-profile YAML file that cannot be read, or whose figures are invalid."""


_FLAGS = frozenset({"on_change", "throttling", "continuous"})
"""The boolean fields of the sensor specs."""
_VECTORS = frozenset({"hard_iron_uT"})
"""The fields that hold a vector, or None (every other field is a number)."""


def _figure(key: str, value: Any) -> Any:
    """A device file's value as its field takes it: a flag, a vector (or None), a number."""
    if key in _FLAGS:
        return bool(value)
    if key in _VECTORS:
        if value is None:
            return None
        if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
            raise ValueError(f"{key} must be a list of three numbers, got {value!r}")
        return tuple(float(v) for v in value)
    return float(value)


_SPECS = {
    "accel": InertialSpec,
    "gyro": InertialSpec,
    "mag": MagnetometerSpec,
    "light": LightSensorSpec,
    "wifi": WifiSpec,
}


def device_to_dict(profile: DeviceProfile) -> dict[str, Any]:
    """``profile`` as plain data (the layout of a device YAML file)."""
    data = dataclasses.asdict(profile)
    data["sources"] = list(profile.sources)
    if profile.mag.hard_iron_uT is not None:
        data["mag"]["hard_iron_uT"] = list(profile.mag.hard_iron_uT)
    return data


def device_from_dict(data: Mapping[str, Any], *, source: str = "device") -> DeviceProfile:
    """The profile :func:`device_to_dict` wrote. Sections and fields left out keep their
    defaults (a perfect sensor).

    Raises:
        DeviceFileError: an unknown section or field, or a figure out of its range,
            named with ``source``.
    """
    if not isinstance(data, Mapping):
        raise DeviceFileError(f"{source}: expected a mapping of profile fields")
    known = {f.name for f in dataclasses.fields(DeviceProfile)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise DeviceFileError(f"{source}: unknown field(s) {unknown}; known: {sorted(known)}")
    kwargs = dict(data)
    try:
        for name, cls in _SPECS.items():
            section = kwargs.get(name, {})
            if not isinstance(section, Mapping):
                raise DeviceFileError(
                    f"{source}: {name} must be a mapping of {cls.__name__} fields"
                )
            fields = {f.name for f in dataclasses.fields(cls)}
            bad = sorted(set(section) - fields)
            if bad:
                raise DeviceFileError(f"{source}: {name}: unknown field(s) {bad}")
            kwargs[name] = cls(**{k: _figure(k, v) for k, v in section.items()})
        kwargs["sources"] = tuple(str(line) for line in kwargs.get("sources", ()))
        return DeviceProfile(**kwargs)
    except (TypeError, ValueError) as err:
        if isinstance(err, DeviceFileError):
            raise
        raise DeviceFileError(f"{source}: {err}") from None
