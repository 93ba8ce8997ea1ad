"""The offline phase: fingerprint databases measured the way the papers measured them.

Estimators may only use what a real team could have measured (DESIGN §6), so
a survey runs the same sensor models as a walk, with the survey device's
errors, and never reads a field model directly.

* **Grid survey** (Han2023 §2.2.2, §4.2): at every point of a regular grid in
  the walkable area the surveyor holds the phone flat and still for
  ``duration_s`` at ``rate_hz`` (1.2 m, 30 s, 50 Hz in the paper). The
  magnetometer samples are rotated into the geographic frame with the phone's
  own fused attitude (its rotation vector: magnetic east, magnetic north, up)
  and averaged; the light sensor's events are averaged too; WiFi scans heard
  during the stay are averaged per AP, the surveyor's body shadowing the APs
  behind them and, with the head, the light sensor. The device's turn-on errors are drawn
  once per survey (one phone) and its noise per sample.
* **Walk survey** (Chen2022 §3): the surveyor walks the survey's route with
  the phone in hand, tapping a marker at reference points ``reference_spacing``
  apart. The magnetic sequence is labelled with positions interpolated linearly
  in time between marker taps — as a real survey labels it, so speed changes
  between markers become label errors. WiFi fingerprints are taken standing
  still at each reference point for ``wifi_dwell_s``, facing along the route:
  the scans heard are averaged.

The result is a :class:`FingerprintDB`: named pandas tables with position
columns ``x``, ``y`` and feature columns, plus metadata (device, spacing, frame).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.phone.devices import DeviceProfile, get_device
from indoorsim.phone.fused import fuse
from indoorsim.phone.kinematics import normal_gravity
from indoorsim.phone.sensors import (
    InertialErrors,
    MagnetometerErrors,
    apply_inertial,
    apply_magnetometer,
    light_events,
    sample_times,
    scan_rss,
    wifi_scans,
)
from indoorsim.scenario.schema import GridSurveySpec, WalkSurveySpec
from indoorsim.util.seeding import SURVEY, named_streams
from indoorsim.walker.gait import PELVIS_HEIGHT_RATIO, WalkerParams
from indoorsim.walker.silhouette import silhouette
from indoorsim.world.body_shadow import BodyShadow
from indoorsim.world.site import Site

# Child streams of a survey's SeedSequence, by name (append only).
_STREAMS = ("errors", "noise", "wifi_times", "wifi", "walk", "hand")


def survey_streams(seed: int) -> dict[str, np.random.Generator]:
    """The named random streams of one survey."""
    return named_streams(seed, SURVEY, _STREAMS)


def grid_points(site: Site, spec: GridSurveySpec) -> NDArray[np.float64]:
    """(P, 2) grid points at ``spec.spacing`` in the walkable area (within ``spec.region``).

    Raises:
        ValueError: the region leaves no walkable grid point.
    """
    import shapely
    from shapely.geometry import Polygon

    region = site.plan.walkable
    if spec.region is not None:
        region = region.intersection(Polygon(spec.region))
    pts = np.zeros((0, 2))
    if not region.is_empty:
        x0, y0, x1, y1 = region.bounds
        s = spec.spacing
        gx, gy = np.meshgrid(np.arange(x0 + s / 2, x1, s), np.arange(y0 + s / 2, y1, s))
        pts = np.column_stack([gx.ravel(), gy.ravel()])
        pts = pts[shapely.contains_xy(region, pts[:, 0], pts[:, 1])]
    if not len(pts):
        raise ValueError(
            f"{site.name}: the grid survey's region holds no walkable grid point "
            f"at {spec.spacing} m spacing"
        )
    return pts


def grid_survey(
    site: Site,
    spec: GridSurveySpec,
    device: str | DeviceProfile = "honor_50",
    seed: int = 0,
    *,
    heading_deg: float = 90.0,
) -> FingerprintDB:
    """Han2023's grid survey (see the module docstring).

    Args:
        site: the building.
        spec: grid spacing, stay duration, sample rate, phone height, region.
        device: the survey phone.
        seed: the survey's seed.
        heading_deg: direction the phone's top points during the survey,
            degrees from the building's +x axis (the surveyor faces one way).

    Returns:
        A database with one table ``grid``: x, y, mag_x, mag_y, mag_z (µT, the
        phone's geographic frame), mag_norm, lux, and ``rss_<bssid>`` (mean dBm
        of the scans that heard the AP; NaN if none did).
    """
    profile = get_device(device) if isinstance(device, str) else device
    rngs = survey_streams(seed)
    pts = grid_points(site, spec)
    g = normal_gravity(site.scenario.site.latitude)
    # The hand is not a tripod: each stay gets a small fixed tilt and yaw error.
    hand = rngs["hand"]
    tilt = hand.normal(0.0, np.radians(1.0), (len(pts), 2))
    yaw = np.radians(heading_deg - 90.0) + hand.normal(0.0, np.radians(2.0), len(pts))
    att = Rotation.from_euler("zxy", np.column_stack([yaw, tilt]))  # world←phone per point
    # One phone: its turn-on errors are drawn once for the whole survey.
    err_rng = rngs["errors"]
    acc_err = InertialErrors.draw(profile.accel, err_rng)
    gyro_err = InertialErrors.draw(profile.gyro, err_rng)
    mag_err = MagnetometerErrors.draw(profile.mag, err_rng)
    noise = rngs["noise"]
    where = np.column_stack([pts, np.full(len(pts), spec.height)])
    field_w = site.magnetic_field(where)
    facing = np.tile(
        [math.cos(math.radians(heading_deg)), math.sin(math.radians(heading_deg))], (len(pts), 1)
    )
    # The surveyor stands behind the phone: their head and trunk shade its light sensor.
    lux_true = site.illuminance(
        where,
        att.apply([0.0, 0.0, 1.0]),
        _surveyor_body(pts, facing),
        profile.light.response_exponent,
    )
    rss_true = site.rss(where, small_scale=True) - site.radio.body_shadow_db(
        where, _surveyor(pts, facing)
    )
    if profile.wifi.antenna_side_ratio_db > 0:
        # The handset's own pattern, its +x side where the stay's attitude turns it.
        rss_true += site.radio.handset_gain_db(
            where, att.apply([1.0, 0.0, 0.0]), profile.wifi.antenna_side_ratio_db
        )
    rows = []
    for k in range(len(pts)):
        t = sample_times(spec.duration_s, spec.rate_hz, profile.timestamp_jitter_frac, noise)
        n = len(t)
        r_inv = att[k].inv()
        acc = apply_inertial(
            np.tile(r_inv.apply([0.0, 0.0, g]), (n, 1)), t, profile.accel, noise, errors=acc_err
        )
        gyro = apply_inertial(np.zeros((n, 3)), t, profile.gyro, noise, errors=gyro_err)
        mag = apply_magnetometer(
            np.tile(r_inv.apply(field_w[k]), (n, 1)), t, profile.mag, noise, errors=mag_err
        )
        fused = fuse(t, acc, t, gyro, t, mag, gravity_mps2=g)
        est = Rotation.from_quat(fused.rotation, scalar_first=True)
        mag_geo = est.apply(mag).mean(axis=0)  # phone frame → its own geographic frame
        _, lux = light_events(t, np.full(n, lux_true[k]), profile.light, noise)
        _, rss = _static_wifi(site, rss_true[k], spec.duration_s, profile, rngs)
        row = {
            "x": pts[k, 0],
            "y": pts[k, 1],
            "mag_x": mag_geo[0],
            "mag_y": mag_geo[1],
            "mag_z": mag_geo[2],
            "mag_norm": float(np.linalg.norm(mag, axis=1).mean()),
            "lux": float(np.mean(lux)) if len(lux) else np.nan,
        }
        row.update(rss)
        rows.append(row)
    table = pd.DataFrame(rows)
    meta = _meta(site, "grid", profile, seed, spec.model_dump(mode="json"))
    meta["heading_deg"] = heading_deg
    return FingerprintDB(tables={"grid": table}, meta=meta)


SURVEY_HOLD_M = 0.3
"""How far in front of the surveyor's trunk the phone is held for a WiFi stay, m [E]."""


def _surveyor(points: NDArray[np.float64], facing: NDArray[np.float64]) -> NDArray[np.float64]:
    """The surveyor's trunk in plan: :data:`SURVEY_HOLD_M` behind the phone, facing ``facing``."""
    return points - SURVEY_HOLD_M * facing


def _surveyor_body(points: NDArray[np.float64], facing: NDArray[np.float64]) -> BodyShadow:
    """The surveyor's head and trunk, standing at :func:`_surveyor` facing ``facing``:
    an adult of the default walker's height."""
    height = WalkerParams().height_m
    trunk = _surveyor(points, facing)
    pelvis = np.column_stack([trunk, np.full(len(trunk), PELVIS_HEIGHT_RATIO * height)])
    return silhouette(pelvis, np.arctan2(facing[:, 1], facing[:, 0]), height)


def _static_wifi(
    site: Site,
    rss_mean: NDArray[np.float64],
    duration_s: float,
    device: DeviceProfile,
    rngs: dict[str, np.random.Generator],
) -> tuple[int, dict[str, float]]:
    """Scans of a phone held still for ``duration_s``: their count and the mean RSS per AP.

    Columns ``rss_<bssid>``; NaN for an AP no scan heard.
    """
    scans = wifi_scans(duration_s, device.wifi, rngs["wifi_times"])
    heard = scan_rss(
        scans, np.tile(rss_mean, (len(scans), 1)), site.radio.bssids, device.wifi, rngs["wifi"]
    )
    mean = heard.groupby("bssid")["rss"].mean() if len(heard) else pd.Series(dtype=float)
    return len(scans), {f"rss_{b}": float(mean.get(b, np.nan)) for b in site.radio.bssids}


def _meta(
    site: Site, kind: str, device: DeviceProfile, seed: int, spec: dict[str, Any]
) -> dict[str, Any]:
    return {
        "scenario": site.name,
        "kind": kind,
        "device": device.name,
        "seed": int(seed),
        "spec": spec,
        "frame": {
            "position": "building frame, metres",
            "magnetic": "the survey phone's geographic frame: magnetic east, north, up (µT)",
        },
    }


def walk_survey(
    site: Site,
    spec: WalkSurveySpec,
    device: str | DeviceProfile = "honor_50",
    seed: int = 0,
    *,
    with_truth: bool = False,
) -> FingerprintDB | tuple[FingerprintDB, pd.DataFrame]:
    """Chen2022's walk survey (see the module docstring).

    Args:
        site: the building.
        spec: the route, reference-point spacing, WiFi dwell and repeats.
        device: the survey phone.
        seed: the survey's seed.
        with_truth: also return the phone's true positions at the magnetic
            samples (for diagnosing label errors). They are never part of the
            database: a real survey team does not have them.

    Returns:
        A database with tables ``magnetic`` (pass, t, x, y labelled from the
        markers, mag_x, mag_y, mag_z in the phone frame, b_h, b_v, b_norm from
        the fused gravity — Eq. 17–18), ``markers`` (t, x, y of each reference
        point) and ``wifi`` (ref, x, y and ``rss_<bssid>`` means); with
        ``with_truth``, also a table (pass, t, true_x, true_y) row-aligned with
        ``magnetic``.
    """
    from indoorsim.simulate import resolve_route, simulate

    profile = get_device(device) if isinstance(device, str) else device
    rngs = survey_streams(seed)
    route = resolve_route(site, spec.route)
    markers = _reference_points(route.points, spec.reference_spacing)
    tables_mag, tables_marks, tables_truth = [], [], []
    for rep in range(spec.repeats):
        rec = simulate(
            site,
            route=route,
            mode="handheld",
            device=profile,
            seed=int(rngs["walk"].integers(2**31)),
        )
        truth = rec.truth
        body = truth[["body_x", "body_y"]].to_numpy()
        t_mark = _marker_taps(truth.index.to_numpy(), body, np.asarray(route.points), markers)
        mag = rec.mag
        tm = mag.index.to_numpy()
        inside = (tm >= t_mark[0]) & (tm <= t_mark[-1])
        x = np.interp(tm[inside], t_mark, markers[:, 0])
        y = np.interp(tm[inside], t_mark, markers[:, 1])
        grav = rec.gravity
        gv = np.column_stack([np.interp(tm[inside], grav.index, grav[c]) for c in "xyz"])
        up = gv / np.linalg.norm(gv, axis=1, keepdims=True)
        m = mag.to_numpy()[inside]
        b_norm = np.linalg.norm(m, axis=1)
        # Eq. 17: the component along "up" (negative in the northern hemisphere).
        b_v = np.einsum("ij,ij->i", m, up)
        b_h = np.sqrt(np.maximum(b_norm**2 - b_v**2, 0.0))  # Eq. 18 with the erratum
        true_xy = truth[["x", "y"]].to_numpy()
        tables_mag.append(
            pd.DataFrame(
                {
                    "pass": rep,
                    "t": tm[inside],
                    "x": x,
                    "y": y,
                    "mag_x": m[:, 0],
                    "mag_y": m[:, 1],
                    "mag_z": m[:, 2],
                    "b_h": b_h,
                    "b_v": b_v,
                    "b_norm": b_norm,
                }
            )
        )
        tables_truth.append(
            pd.DataFrame(
                {
                    "pass": rep,
                    "t": tm[inside],
                    "true_x": np.interp(tm[inside], truth.index, true_xy[:, 0]),
                    "true_y": np.interp(tm[inside], truth.index, true_xy[:, 1]),
                }
            )
        )
        tables_marks.append(
            pd.DataFrame(
                {
                    "pass": rep,
                    "ref": np.arange(len(markers)),
                    "t": t_mark,
                    "x": markers[:, 0],
                    "y": markers[:, 1],
                }
            )
        )
    # WiFi: standing still at each reference point for the dwell time.
    height = 1.2
    where = np.column_stack([markers, np.full(len(markers), height)])
    # The surveyor faces along the route: toward the next reference point.
    ahead = np.diff(markers, axis=0)
    ahead = np.vstack([ahead, ahead[-1:]]) if len(ahead) else np.array([[1.0, 0.0]])
    facing = ahead / np.maximum(np.linalg.norm(ahead, axis=1, keepdims=True), 1e-9)
    rss_true = site.rss(where, small_scale=True) - site.radio.body_shadow_db(
        where, _surveyor(markers, facing)
    )
    if profile.wifi.antenna_side_ratio_db > 0:
        # Held flat, its top ahead: the handset's +x side to the surveyor's right.
        side = np.column_stack([facing[:, 1], -facing[:, 0], np.zeros(len(facing))])
        rss_true += site.radio.handset_gain_db(where, side, profile.wifi.antenna_side_ratio_db)
    rows = []
    for k, point in enumerate(markers):
        n_scans, rss = _static_wifi(site, rss_true[k], spec.wifi_dwell_s, profile, rngs)
        row = {"ref": k, "x": point[0], "y": point[1], "scans": n_scans, **rss}
        rows.append(row)
    meta = _meta(site, "walk", profile, seed, spec.model_dump(mode="json"))
    meta["frame"]["magnetic"] = "phone frame (mag_*); b_h, b_v from the phone's fused gravity (µT)"
    db = FingerprintDB(
        tables={
            "magnetic": pd.concat(tables_mag, ignore_index=True),
            "markers": pd.concat(tables_marks, ignore_index=True),
            "wifi": pd.DataFrame(rows),
        },
        meta=meta,
    )
    return (db, pd.concat(tables_truth, ignore_index=True)) if with_truth else db


def _reference_points(points: NDArray[np.float64], spacing: float) -> NDArray[np.float64]:
    """Points every ``spacing`` metres along a polyline, plus its end and every corner."""
    pts = np.asarray(points, dtype=float)
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s_corner = np.r_[0.0, np.cumsum(seg)]
    s = np.union1d(np.arange(0.0, s_corner[-1], spacing), s_corner)
    return np.column_stack([np.interp(s, s_corner, pts[:, i]) for i in range(2)])


def _marker_taps(
    t: NDArray[np.float64],
    body: NDArray[np.float64],
    route: NDArray[np.float64],
    markers: NDArray[np.float64],
) -> NDArray[np.float64]:
    """When the surveyor taps each marker: as the body reaches it along the walk.

    Progress is the distance walked so far, scaled to the route's length (the
    walker cuts corners a little); the first marker is tapped on setting off.
    Routes that return to their start (loops) are handled, unlike a nearest-point rule.
    """
    walked = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(body, axis=0), axis=1))]
    route_s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(route, axis=0), axis=1))]
    marker_s = _arc_length_of(markers, route, route_s)
    target = marker_s / route_s[-1] * walked[-1]
    target[0] = min(0.05, walked[-1])  # setting off
    idx = np.minimum(np.searchsorted(walked, target), len(t) - 1)
    return t[idx]


def _arc_length_of(
    points: NDArray[np.float64], route: NDArray[np.float64], route_s: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Arc length along ``route`` of reference points generated on it, in order."""
    out = np.empty(len(points))
    seg = 0
    for k, p in enumerate(points):
        # Reference points come in route order: search forward from the last one.
        while seg < len(route) - 2 and not _on_segment(p, route[seg], route[seg + 1]):
            seg += 1
        out[k] = route_s[seg] + np.linalg.norm(p - route[seg])
    return out


def _on_segment(p: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> bool:
    d = b - a
    t = float(np.dot(p - a, d) / max(np.dot(d, d), 1e-12))
    return -1e-9 <= t <= 1 + 1e-9 and float(np.linalg.norm(a + t * d - p)) < 1e-6
