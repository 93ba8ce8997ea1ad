"""Simulate one walk: route → gait → carrying mode → phone sensors → :class:`Recording`.

The data flow of DESIGN §3::

    route + walker params ─► gait (body pose, step events) ─► carry mode (phone pose)
    phone pose + Site fields + device profile + rng ─► Recording (streams + truth)

Every sensor samples the world at its own timestamps (the device's clock, with
jitter): the accelerometer and gyroscope read the ideal specific force and
body rate of the phone's true trajectory, the magnetometer the site's field at
the phone rotated into the phone frame (for a magnetometer with noise, the
field along the path of :meth:`~indoorsim.world.magnetic.MagneticModel.field_along`:
within ``PATH_FIELD_ERROR_UT`` of the exact sum), the light sensor the illuminance on
the screen's normal (shadowed by the carrier's head and trunk, the head at the ear or
the pocket), WiFi scans the mean RSS at
the phone. Each then passes through the device's error model, and the fused
sensors are computed from the *noisy* raw streams by the phone's attitude
filter.

Randomness: one :class:`numpy.random.SeedSequence` per run; each sub-model
draws from its own child stream, keyed by name, so the same seed gives the same
bytes and changing one model's draws leaves the others untouched.
"""

from __future__ import annotations

import functools
import importlib.metadata
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
import pyarrow as pa
from numpy.typing import NDArray

from indoorsim.io.recording import Recording
from indoorsim.phone.devices import DeviceProfile, get_device
from indoorsim.phone.fused import fuse
from indoorsim.phone.kinematics import IdealImu, normal_gravity
from indoorsim.phone.sensors import (
    apply_inertial,
    apply_magnetometer,
    light_events,
    sample_times,
    scan_rss,
    wifi_scans,
)
from indoorsim.scenario.schema import RouteSpec
from indoorsim.util.errors import UnknownNameError
from indoorsim.util.seeding import WALK, named_streams
from indoorsim.walker.carry import PhoneTrajectory, carry
from indoorsim.walker.gait import BodyTrajectory, WalkerParams, walk
from indoorsim.walker.route import Route, plan_route
from indoorsim.walker.schedule import ModeSchedule, ScheduleLike
from indoorsim.world.site import Site

# Child streams of a run's SeedSequence, by name. Append new names at the end:
# the position of a name fixes its stream.
_STREAMS = (
    "walker",
    "carry",
    "imu_clock",
    "accel",
    "gyro",
    "mag_clock",
    "mag",
    "light",
    "wifi_times",
    "wifi",
    "gyro_clock",
)

PATH_FIELD_ERROR_UT = 0.01
"""Bound on the error of :meth:`~indoorsim.world.magnetic.MagneticModel.field_along`
against the exact dipole sum along simulated walks (tested)."""
PATH_FIELD_MIN_NOISE_UT = 5 * PATH_FIELD_ERROR_UT
"""Magnetometers with less white noise than this (σ per sample, µT) read the exact
field: for them the path method's error would not be negligible against the noise."""


def run_streams(seed: int) -> dict[str, np.random.Generator]:
    """The named random streams of one run."""
    return named_streams(seed, WALK, _STREAMS)


@dataclass(frozen=True, kw_only=True)
class PhoneSamples:
    """Raw sensor samples of one walk, before they become a Recording."""

    t_accel: NDArray[np.float64]
    accel: NDArray[np.float64]
    t_gyro: NDArray[np.float64]
    gyro: NDArray[np.float64]
    t_mag: NDArray[np.float64]
    mag: NDArray[np.float64]
    t_light: NDArray[np.float64]
    lux: NDArray[np.float64]
    wifi: pd.DataFrame


class UnknownRouteError(UnknownNameError, KeyError, ValueError):
    """A route name the scenario does not have; lists the scenario's routes.

    A ``KeyError`` as :func:`resolve_route` raised before, and a
    ``ValueError`` as the environment and the evaluation raised.
    """

    kind = "route"


def route_spec(site: Site, name: str) -> RouteSpec:
    """The route called ``name`` in ``site``'s scenario: every door checks route names here.

    Raises:
        UnknownRouteError: the scenario has no such route.
    """
    routes = site.scenario.routes
    if not isinstance(name, str) or name not in routes:
        raise UnknownRouteError(name, list(routes), f"in scenario {site.name!r}")
    return routes[name]


def resolve_route(site: Site, route: str | RouteSpec | Route) -> Route:
    """A walkable :class:`Route` from a route name of the scenario, a spec, or a route.

    Raises:
        UnknownRouteError: a name the scenario does not have.
        RouteError: a route that cannot be walked.
    """
    if isinstance(route, Route):
        return route
    if isinstance(route, str):
        return plan_route(site.plan, route_spec(site, route), name=route)
    return plan_route(site.plan, route, name="custom")


def simulate(
    site: Site,
    *,
    route: str | RouteSpec | Route,
    mode: ScheduleLike = "handheld",
    device: str | DeviceProfile = "ideal",
    seed: int = 0,
    walker: WalkerParams | None = None,
    truth_rate_hz: float = 200.0,
    light_sample_hz: float = 50.0,
    duration_s: float | None = None,
) -> Recording:
    """Walk ``route`` through ``site`` carrying a ``device`` in ``mode`` and record it.

    Args:
        site: the building.
        route: a route name of the scenario, a :class:`RouteSpec` or a planned :class:`Route`.
        mode: a carrying-mode name, a schedule ``[(t_start, mode_name[, params]), ...]``,
            or a :class:`~indoorsim.walker.schedule.ModeSchedule`.
        device: a device-profile name or profile.
        seed: the run's seed (walker, carrying mode and every sensor draw from it).
        walker: pedestrian parameters (defaults: an average adult).
        truth_rate_hz: rate of the truth stream (≥ 200 Hz).
        light_sample_hz: rate at which illuminance is evaluated for the light
            sensor's integration.
        duration_s: keep only the walk's first ``duration_s`` seconds: the body
            trajectory is cut there before the phone is carried and the sensors
            sample it (a long route walked for a fixed time, as the data-set
            writer does). None keeps the whole walk. A mode schedule must
            start every mode before the cut.

    Returns:
        The recording: raw, fused and truth streams plus metadata.
    """
    if truth_rate_hz < 200:
        raise ValueError(f"truth_rate_hz must be ≥ 200 Hz, got {truth_rate_hz}")
    if not light_sample_hz > 0:
        raise ValueError(f"light_sample_hz must be > 0, got {light_sample_hz}")
    if duration_s is not None and not duration_s > 0:
        raise ValueError(f"duration_s must be > 0 s, got {duration_s}")
    profile = get_device(device) if isinstance(device, str) else device
    rngs = run_streams(seed)
    planned = resolve_route(site, route)
    schedule = ModeSchedule.of(mode)
    params = walker or WalkerParams()
    body = walk(
        site.plan, planned, params, rngs["walker"], rate_hz=truth_rate_hz, until_s=duration_s
    )
    if duration_s is not None:
        body = body.window(0, int(np.searchsorted(body.t, duration_s, side="right")))
    phone = carry(body, schedule, rngs["carry"])
    samples = sample_sensors(site, phone, profile, rngs, light_sample_hz=light_sample_hz)
    rec = _recording(site, planned, body, phone, samples, profile, seed, schedule, params)
    if duration_s is not None:
        rec.meta["duration_s"] = float(duration_s)
    return rec


def sample_sensors(
    site: Site,
    phone: PhoneTrajectory,
    device: DeviceProfile,
    rngs: dict[str, np.random.Generator],
    *,
    light_sample_hz: float = 50.0,
) -> PhoneSamples:
    """Every sensor of ``device`` along the phone's true trajectory (see the module docstring)."""
    g = normal_gravity(site.scenario.site.latitude)
    imu = IdealImu(phone.t, phone.pos, phone.quat, gravity_mps2=g)
    t0, duration = float(phone.t[0]), float(phone.t[-1] - phone.t[0])
    jitter, gaps = device.timestamp_jitter_frac, device.gap_probability

    def clock(rate_hz: float, stream: str) -> NDArray[np.float64]:
        t = sample_times(duration, rate_hz, jitter, rngs[stream], start=t0, gap_probability=gaps)
        return t[t <= phone.t[-1]]

    t_accel = clock(device.accel.rate_hz, "imu_clock")
    # Accelerometer and gyroscope share one IMU clock when they run at one rate.
    same_clock = device.gyro.rate_hz == device.accel.rate_hz
    t_gyro = t_accel if same_clock else clock(device.gyro.rate_hz, "gyro_clock")
    accel = apply_inertial(imu.specific_force(t_accel), t_accel, device.accel, rngs["accel"])
    gyro = apply_inertial(imu.angular_rate(t_gyro), t_gyro, device.gyro, rngs["gyro"])

    t_mag = clock(device.mag.rate_hz, "mag_clock")
    if device.mag.noise_sigma_uT >= PATH_FIELD_MIN_NOISE_UT:
        # Near steel exactly at every sample, the smooth rest at knots: within
        # PATH_FIELD_ERROR_UT of the exact sum, far below this sensor's noise.
        field_w = site.magnetic.field_along(t_mag, imu.position, phone.t, phone.pos)
    else:
        # A (nearly) noiseless magnetometer, such as the ideal profile's, would
        # show even that: the exact sum at every sample.
        field_w = site.magnetic_field(imu.position(t_mag))
    mag = apply_magnetometer(imu.to_phone_frame(t_mag, field_w), t_mag, device.mag, rngs["mag"])

    t_fine = np.arange(t0, phone.t[-1], 1.0 / light_sample_hz)
    # The screen's outward normal, phone +z, in the world frame.
    normals = imu.to_world_frame(t_fine, [0.0, 0.0, 1.0])
    exposure = np.interp(t_fine, phone.t, phone.light_exposure)
    where = imu.position(t_fine)
    k = device.light.response_exponent
    if phone.carrier is None:
        lux_fine = site.illuminance(where, normals, response_exponent=k)
    else:
        # The carrier's head and trunk shadow the sensor where the mode models them.
        # While one mode blends into another the shaded and bare readings blend too.
        weight, body = phone.carrier.shadow_at(t_fine)
        some, full = weight > 0, weight >= 1
        lux_fine = np.zeros(len(t_fine))
        lux_fine[some] = weight[some] * site.illuminance(where[some], normals[some], body, k)
        bare = ~full
        lux_fine[bare] += (1 - weight[bare]) * site.illuminance(
            where[bare], normals[bare], response_exponent=k
        )
    lux_fine *= exposure
    t_light, lux = light_events(t_fine, lux_fine, device.light, rngs["light"])

    t_scan = wifi_scans(duration, device.wifi, rngs["wifi_times"], start=t0)
    t_scan = t_scan[t_scan <= phone.t[-1]]
    # A scan sweeps the channels over its duration: take the phone where it was mid-scan.
    t_mid = np.clip(t_scan - device.wifi.scan_duration_s / 2, t0, phone.t[-1])
    # What the phone receives where it is: the local mean and that spot's multipath fade.
    rss_mean = (
        site.rss(imu.position(t_mid), small_scale=True)
        if len(t_scan)
        else np.zeros((0, len(site.radio.bssids)))
    )
    if phone.torso_xy is not None and len(t_scan):
        # The carrier's trunk shadows the APs behind it (REALISM §4.3).
        torso = np.column_stack([np.interp(t_mid, phone.t, phone.torso_xy[:, i]) for i in (0, 1)])
        rss_mean = rss_mean - site.radio.body_shadow_db(imu.position(t_mid), torso)
    if device.wifi.antenna_side_ratio_db > 0 and len(t_scan):
        # The handset's own pattern, turned with the phone: its +x side in the world.
        rss_mean = rss_mean + site.radio.handset_gain_db(
            imu.position(t_mid),
            imu.to_world_frame(t_mid, [1.0, 0.0, 0.0]),
            device.wifi.antenna_side_ratio_db,
        )
    wifi = scan_rss(t_scan, rss_mean, site.radio.bssids, device.wifi, rngs["wifi"])
    return PhoneSamples(
        t_accel=t_accel,
        accel=accel,
        t_gyro=t_gyro,
        gyro=gyro,
        t_mag=t_mag,
        mag=mag,
        t_light=t_light,
        lux=lux,
        wifi=wifi,
    )


def _frame(t: NDArray[np.float64], values: NDArray[np.float64], columns: list[str]) -> pd.DataFrame:
    """A stream: the columns of the (rows, columns) float array ``values``, indexed by ``t``.

    The frame wraps ``values`` and ``t`` as they are, without a copy: they are
    this walk's own arrays, fresh from the sensor models and the attitude
    filter, and nothing else keeps them. (pandas holds ``values`` as one
    block, its transpose: for a row-major ``values`` a column is a strided
    view, and the row-major array of the columns, which the windower reads,
    is ``values`` itself.)
    """
    return pd.DataFrame(
        values.reshape(len(values), -1),
        index=pd.Index(np.asarray(t, dtype=float), name="t", copy=False),
        columns=columns,
        copy=False,
    )


_XYZ, _QUAT = ["x", "y", "z"], ["qw", "qx", "qy", "qz"]
_TRUTH = [*_XYZ, *_QUAT, "body_x", "body_y", "heading"]


# How this pandas holds a column of text: its pyarrow-backed "str" (pandas ≥ 3) or object.
_TEXT_DTYPE = pd.Series(["text"]).dtype


def _labels(values: NDArray[np.str_]) -> pd.api.extensions.ExtensionArray | NDArray[np.object_]:
    """Per-sample names (a few names in long runs) as the text column pandas would make.

    Built from the runs: converting 10⁵ samples one by one to Python strings
    would cost more than the rest of the truth stream.
    """
    n = len(values)
    start = np.flatnonzero(np.r_[True, values[1:] != values[:-1]]) if n else np.zeros(0, int)
    names, run = np.unique(values[start], return_inverse=True)
    codes = np.repeat(run.astype(np.int32), np.diff(np.r_[start, n]))
    if getattr(_TEXT_DTYPE, "storage", None) == "pyarrow":
        dictionary = pa.DictionaryArray.from_arrays(codes, pa.array(names, type=pa.string()))
        return pd.array(dictionary, dtype=_TEXT_DTYPE)
    return names.astype(object)[codes]


@functools.cache
def _version() -> str:
    return importlib.metadata.version("indoorsim")


def _recording(
    site: Site,
    route: Route,
    body: BodyTrajectory,
    phone: PhoneTrajectory,
    s: PhoneSamples,
    device: DeviceProfile,
    seed: int,
    schedule: ModeSchedule,
    walker: WalkerParams,
) -> Recording:
    g = normal_gravity(site.scenario.site.latitude)
    fused = fuse(s.t_accel, s.accel, s.t_gyro, s.gyro, s.t_mag, s.mag, gravity_mps2=g)
    heading = np.angle(np.exp(1j * body.heading))  # wrapped to (−π, π]
    # The truth's float columns copied once into the column-major block pandas
    # would consolidate them into: the labels are computed from it column by
    # column (np.gradient along the rows of the position columns, say).
    truth_columns = np.stack([*phone.pos.T, *phone.quat.T, *body.pos[:, :2].T, heading])
    truth = _frame(phone.t, truth_columns.T, _TRUTH)
    truth["mode"] = _labels(np.asarray(phone.mode))
    steps = body.steps.set_index("t") if "t" in body.steps.columns else body.steps
    steps.index = steps.index.astype(float).rename("t")
    wifi = s.wifi.set_index("t") if "t" in s.wifi.columns else s.wifi
    wifi.index = wifi.index.astype(float).rename("t")
    streams = {
        "accel": _frame(s.t_accel, s.accel, _XYZ),
        "gyro": _frame(s.t_gyro, s.gyro, _XYZ),
        "mag": _frame(s.t_mag, s.mag, _XYZ),
        "light": _frame(s.t_light, s.lux, ["lux"]),
        "wifi": wifi,
        "rotation": _frame(fused.t_rotation, fused.rotation, _QUAT),
        "game_rotation": _frame(fused.t_rotation, fused.game_rotation, _QUAT),
        "gravity": _frame(fused.t_gravity, fused.gravity, _XYZ),
        "linear_accel": _frame(fused.t_gravity, fused.linear_accel, _XYZ),
        "truth": truth,
        "steps": steps,
    }
    sc = site.scenario.site
    meta = {
        "scenario": site.name,
        "seed": int(seed),
        "device": device.name,
        "mode": _schedule_meta(schedule),
        "route": {
            "name": route.name,
            "points": np.asarray(route.points).tolist(),
            "speed": route.speed,
        },
        "walker": {k: _jsonable(v) for k, v in asdict(walker).items()},
        "rates_hz": {
            "accel": device.accel.rate_hz,
            "gyro": device.gyro.rate_hz,
            "mag": device.mag.rate_hz,
            "truth": float(1.0 / np.median(np.diff(phone.t))),
        },
        "frame": {
            "world": "building frame: x along the building's +x, y along its +y, z up, metres",
            "phone": "Android sensor frame: x right, y up the screen, z out of the screen",
            "quaternion": "world<-phone, scalar first (w, x, y, z)",
            "rotation_world": "Android rotation vector: x magnetic east, y magnetic north, z up",
            "building_north_deg": sc.north_deg,
            "magnetic_declination_deg": site.magnetic_declination_deg,
        },
        "gravity_mps2": g,
        "package": "indoorsim",
        "version": _version(),
    }
    return Recording._from_built(streams, meta)


def _schedule_meta(schedule: ModeSchedule) -> object:
    """The schedule as its caller wrote it (a mode name, or its entries), as JSON data."""
    written = schedule.written
    return written if isinstance(written, str) else [list(map(_jsonable, m)) for m in written]


def _jsonable(v: object) -> object:
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, tuple):
        return [_jsonable(x) for x in v]
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    return v
