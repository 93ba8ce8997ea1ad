"""Benchmark: illuminance and RSS at 100 000 points on an office floor, against a shapely reference.

The floor (built below) is 60 m × 18 m: a corridor between two rows of ten
6 m offices, 42 walls (concrete shell, drywall partitions, drywall or glass
corridor fronts) cut by 20 doors into 62 wall pieces, plus 4 pillars in the
corridor; 30 ceiling luminaires (one per office, ten in the corridor) and 10
WiFi APs at 2.4 and 5.2 GHz. Receivers are random walkable points at hand
height with the normal tilted up to 45° from vertical.

The reference is what one writes first: the photometry broadcast over
(points × luminaires) in numpy and occlusion from shapely, one straight line
per (point, source) pair tested with ``STRtree.query(lines, predicate="intersects")``
against the wall pieces (centre lines) and pillars (footprints). Both sides
must agree to 1e-9 (relative) before any figure is printed. The ambient term
is off for the light comparison (it is a per-room constant, timed separately),
and the RSS reference adds the model's own shadowing field, computed outside
its timing.

Run::

    .venv/bin/python benchmarks/bench_light_radio.py            # 100 000 points
    .venv/bin/python benchmarks/bench_light_radio.py --points 20000

Then the carrier's body (the head and trunk of a walker holding each receiver
as a phone in the hand, facing a random way) on the first 20 000 points, with
every luminaire given a 0.6 m panel face: the compiled penumbra kernel against
numpy testing every sight line to every point of the face against the body
(no shortcut), in free space so that only the body is timed; and the body's
share of the ambient view, timed alone.

The model's occlusion queries run through small matrix products, which OpenBLAS
spreads over all cores; on a busy machine set ``OPENBLAS_NUM_THREADS=1`` for
stable figures (the shapely reference is single-threaded either way).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from indoorsim.scenario import Scenario, parse_scenario
from indoorsim.walker.silhouette import silhouette
from indoorsim.world.body_shadow import FACE_STEP_M, BodyShadow
from indoorsim.world.light import LightModel, PointSources, direct_illuminance
from indoorsim.world.plan import FloorPlan
from indoorsim.world.radio import MultipathField, RadioModel, free_space_loss_1m_db

LENGTH, DEPTH, HEIGHT = 60.0, 18.0, 3.0
CORRIDOR = (7.5, 10.5)  # y of the corridor's two fronts
ROOM = 6.0


def office_floor(*, ambient: bool = False) -> Scenario:
    """The benchmark building (see the module docstring)."""
    shell = [(0, 0), (LENGTH, 0), (LENGTH, DEPTH), (0, DEPTH)]
    walls: list[dict[str, Any]] = [
        {"from": list(a), "to": list(b), "thickness": 0.3, "material": "concrete"}
        for a, b in zip(shell, shell[1:] + shell[:1], strict=True)
    ]
    doors, luminaires = [], []
    for k in range(int(LENGTH / ROOM)):
        x0, x1, xc = k * ROOM, (k + 1) * ROOM, (k + 0.5) * ROOM
        for front, (y_in, y_out) in zip(
            CORRIDOR, ((0.0, CORRIDOR[0]), (CORRIDOR[1], DEPTH)), strict=True
        ):
            material = "glass" if k in (3, 4) else "drywall"  # two glass-fronted meeting rooms
            walls.append(
                {"from": [x0, front], "to": [x1, front], "thickness": 0.12, "material": material}
            )
            doors.append({"position": [x0 + 1.0, front], "width": 0.9})
            luminaires.append(
                {
                    "position": [xc, (y_in + y_out) / 2, HEIGHT],
                    "intensity_cd": 1800.0,
                    "exponent": 2.75,
                }
            )
            if k > 0:
                walls.append(
                    {
                        "from": [x0, y_in],
                        "to": [x0, y_out],
                        "thickness": 0.12,
                        "material": "drywall",
                    }
                )
        luminaires.append(
            {"position": [xc, sum(CORRIDOR) / 2, HEIGHT], "intensity_cd": 500.0, "exponent": 1.0}
        )
    wifi = [
        {
            "bssid": f"02:00:00:00:00:{k:02x}",
            "position": [3.0 + 6.0 * k, (2.0, 9.0, 16.0)[k % 3], 2.8],
            "frequency_ghz": (2.4, 5.2)[k % 2],
        }
        for k in range(10)
    ]
    pillars = [
        {"center": [x, sum(CORRIDOR) / 2], "size": [0.4, 0.4]} for x in (12.5, 24.5, 36.5, 48.5)
    ]
    return parse_scenario(
        {
            "name": "bench-office",
            "seed": 1,
            "site": {
                "latitude": 32.6,
                "longitude": 117.0,
                "date": "2025-01-01",
                "ceiling_height": HEIGHT,
            },
            "walls": walls,
            "doors": doors,
            "pillars": pillars,
            "luminaires": luminaires,
            "wifi": wifi,
            "light": {"ambient": ambient},
            # One storey: the reference has no slabs (its APs are this floor's).
            "radio": {"floors_above": 0, "floors_below": 0},
        }
    )


def receivers(
    plan: FloorPlan, n: int, rng: np.random.Generator
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """n walkable points at 0.8–1.6 m, normals tilted up to 45° from vertical."""
    xmin, ymin, xmax, ymax = plan.bounds
    xy = np.zeros((0, 2))
    while len(xy) < n:
        cand = rng.uniform([xmin, ymin], [xmax, ymax], (2 * n, 2))
        xy = np.vstack([xy, cand[plan.is_walkable(cand)]])
    points = np.column_stack([xy[:n], rng.uniform(0.8, 1.6, n)])
    tilt, azimuth = np.arccos(rng.uniform(np.cos(np.pi / 4), 1.0, n)), rng.uniform(0, 2 * np.pi, n)
    normals = np.column_stack(
        [np.sin(tilt) * np.cos(azimuth), np.sin(tilt) * np.sin(azimuth), np.cos(tilt)]
    )
    return points, normals


# ---------------------------------------------------------------- the reference


def _elements(plan: FloorPlan) -> tuple[shapely.STRtree, NDArray[np.float64], list[Any]]:
    """Occluders as shapely geometry: wall pieces (centre lines), then pillars (footprints)."""
    geoms = [shapely.LineString([w.start, w.end]) for w in plan.walls] + [
        p for p, _ in plan.pillars
    ]
    materials = [w.material for w in plan.walls] + [m for _, m in plan.pillars]
    return shapely.STRtree(geoms), np.array([m.light_transmittance for m in materials]), materials


def _pairs(
    tree: shapely.STRtree, a: NDArray[np.float64], b: NDArray[np.float64]
) -> NDArray[np.intp]:
    """(2, K) indices (line, element) of every crossing of the N lines a→b."""
    lines = shapely.linestrings(np.stack([a, np.broadcast_to(b, a.shape)], axis=1))
    return tree.query(lines, predicate="intersects")


def reference_illuminance(
    scenario: Scenario, plan: FloorPlan, points: NDArray[np.float64], normals: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Direct illuminance, lx: (points × luminaires) broadcast, shapely occlusion per luminaire."""
    pos = np.array([lum.position for lum in scenario.luminaires])
    axis = np.array([lum.axis for lum in scenario.luminaires])
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    i0 = np.array([lum.intensity_cd for lum in scenario.luminaires])
    n = np.array([lum.exponent for lum in scenario.luminaires])
    tree, tau, _ = _elements(plan)
    transmittance = np.ones((len(points), len(pos)))
    for j in range(len(pos)):
        line, elem = _pairs(tree, points[:, :2], pos[j, :2])
        np.multiply.at(transmittance[:, j], line, tau[elem])
    out = np.zeros(len(points))
    for s in range(0, len(points), 20_000):  # bounds the (chunk, L, 3) temporaries
        p, nr = points[s : s + 20_000], normals[s : s + 20_000]
        v = pos[None] - p[:, None]
        d = np.linalg.norm(v, axis=-1)
        cos_theta = np.clip(-(v * axis[None]).sum(-1) / d, 0, None)
        cos_psi = np.clip((v * nr[:, None]).sum(-1) / d, 0, None)
        e = np.where(cos_theta > 0, i0 * cos_theta**n, 0.0) * cos_psi / d**2
        out[s : s + 20_000] = (e * transmittance[s : s + 20_000]).sum(1)
    return out


def reference_multipath(
    field: MultipathField,
    points: NDArray[np.float64],
    ap: NDArray[np.float64],
    obstruction_db: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The band-averaged fade written out over (points × paths × frequencies), dB."""
    k = field.k_factor * 10 ** (-obstruction_db / 10)
    phase = field.wavenumber * np.einsum("nk,mk->nm", points, field.directions) + field.phases
    waves = np.exp(1j * phase)[:, :, None] * field.band[None, :, :]  # (N, M, F)
    direct = np.exp(1j * field.wavenumber * np.linalg.norm(points - ap, axis=1))
    h = np.sqrt(k / (k + 1))[:, None] * direct[:, None] + np.sqrt(1 / (k + 1))[:, None] * waves.sum(
        axis=1
    )
    return 10 * np.log10(np.mean(np.abs(h) ** 2, axis=1))


def reference_rss(
    scenario: Scenario, plan: FloorPlan, points: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Mean RSS without shadowing, dBm: (points × APs) broadcast, shapely wall crossings per AP."""
    radio = scenario.radio
    pos = np.array([ap.position for ap in scenario.wifi])
    f_ghz = np.array([ap.frequency_ghz for ap in scenario.wifi])
    p_tx = np.array([ap.tx_power_dbm for ap in scenario.wifi])
    d = np.maximum(np.linalg.norm(points[:, None] - pos[None], axis=-1), 1.0)
    out = (
        p_tx
        - radio.system_loss_db
        - free_space_loss_1m_db(f_ghz)
        - 10 * radio.path_loss_exponent * np.log10(d)
    )
    tree, _, materials = _elements(plan)
    for k in range(len(pos)):
        loss = np.array([m.loss_db(f_ghz[k]) for m in materials])
        loss[len(plan.walls) :] = radio.pillar_loss_db  # pillars: diffraction, see RadioSpec
        line, elem = _pairs(tree, points[:, :2], pos[k, :2])
        out[:, k] -= np.bincount(line, weights=loss[elem], minlength=len(points))
    return out


def carriers(points: NDArray[np.float64], rng: np.random.Generator) -> BodyShadow:
    """A 1.75 m walker behind each receiver, holding it 0.22 m ahead of the trunk."""
    yaw = rng.uniform(0.0, 2.0 * np.pi, len(points))
    ahead = 0.22 * np.column_stack([np.cos(yaw), np.sin(yaw)])
    pelvis = np.column_stack([points[:, :2] - ahead, np.full(len(points), 0.53 * 1.75)])
    return silhouette(pelvis, yaw, 1.75)


def _np_body_blocks(p: NDArray[np.float64], q: NDArray[np.float64], b: BodyShadow) -> NDArray:
    """(N,) whether each segment p→q (N, 3) passes through the body, in plain numpy."""
    d = q - p
    h = b.head - p
    u = np.clip((h * d).sum(1) / (d * d).sum(1), 0.0, 1.0)
    head = ((h - u[:, None] * d) ** 2).sum(1) < b.head_radius_m**2
    with np.errstate(divide="ignore", invalid="ignore"):
        cut = (b.trunk_top - p[:, 2]) / d[:, 2]
    lo = np.where(d[:, 2] < 0, np.maximum(cut, 0.0), 0.0)
    hi = np.where(d[:, 2] > 0, np.minimum(cut, 1.0), 1.0)
    flat = (d[:, 2] == 0) & (p[:, 2] > b.trunk_top)
    c, s = np.cos(b.trunk_yaw), np.sin(b.trunk_yaw)
    r = p[:, :2] - b.trunk_xy
    ax = (c * r[:, 0] + s * r[:, 1]) / b.trunk_half_depth_m
    ay = (-s * r[:, 0] + c * r[:, 1]) / b.trunk_half_width_m
    bx = (c * d[:, 0] + s * d[:, 1]) / b.trunk_half_depth_m
    by = (-s * d[:, 0] + c * d[:, 1]) / b.trunk_half_width_m
    bb = bx * bx + by * by
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(bb > 0, np.clip(-(ax * bx + ay * by) / bb, lo, hi), lo)
    trunk = ((ax + u * bx) ** 2 + (ay + u * by) ** 2 < 1.0) & (hi >= lo) & ~flat
    return head | trunk


def reference_body_illuminance(
    sources: PointSources, points: NDArray[np.float64], normals: NDArray[np.float64], body
) -> NDArray[np.float64]:
    """Free-space direct illuminance, each source scaled by the share of its face's grid
    points whose sight lines the body leaves clear, every sight line tested."""
    out = np.zeros(len(points))
    for j in range(len(sources)):
        pos, u, v = sources.position[j], sources.face_u[j], sources.face_v[j]
        nu = min(max(int(np.ceil(2 * np.linalg.norm(u) / FACE_STEP_M)), 1), 12)
        nv = min(max(int(np.ceil(2 * np.linalg.norm(v) / FACE_STEP_M)), 1), 12)
        clear = np.zeros(len(points))
        for a in range(nu):
            for b in range(nv):
                q = pos + (2 * (a + 0.5) / nu - 1) * u + (2 * (b + 0.5) / nv - 1) * v
                clear += ~_np_body_blocks(points, np.broadcast_to(q, points.shape), body)
        vec = pos - points
        d2 = np.maximum((vec * vec).sum(1), 0.05**2)
        d = np.sqrt(d2)
        cos_theta = -(vec @ sources.axis[j]) / d
        cos_psi = (vec * normals).sum(1) / d
        e = sources.intensity_cd[j] * np.clip(cos_theta, 0, None) ** sources.exponent[j]
        e = np.where((cos_theta > 0) & (cos_psi > 0), e * cos_psi / d2, 0.0)
        out += e * clear / (nu * nv)
    return out


# ---------------------------------------------------------------- timing


def best_of(fn: Callable[[], Any], repeat: int) -> tuple[Any, float]:
    """The result of ``fn`` and its fastest wall time over ``repeat`` runs, s."""
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return result, min(times)


def _row(label: str, seconds: float, n_points: int, n_pairs: int, pair: str) -> str:
    return (
        f"  {label:<10} {seconds:7.3f} s  {n_points / seconds:9.3g} points/s"
        f"  {n_pairs / seconds:9.3g} point-{pair} pairs/s"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=3, help="runs of the model (best is kept)")
    args = parser.parse_args()

    scenario = office_floor()
    plan = FloorPlan(scenario)
    points, normals = receivers(plan, args.points, np.random.default_rng(0))
    n = len(points)
    print(
        f"office floor: {len(scenario.walls)} walls ({len(plan.walls)} pieces after "
        f"{len(scenario.doors)} doors), {len(scenario.pillars)} pillars, "
        f"{len(scenario.luminaires)} luminaires, {len(scenario.wifi)} APs; {n} points"
    )

    light = LightModel(scenario, plan)
    e, t_light = best_of(lambda: light.illuminance(points, normals), args.repeat)
    e_ref, t_light_ref = best_of(lambda: reference_illuminance(scenario, plan, points, normals), 1)
    np.testing.assert_allclose(e, e_ref, rtol=1e-9, atol=1e-9)
    _, t_free = best_of(lambda: direct_illuminance(light.sources, points, normals), args.repeat)
    ambient = LightModel(office_floor(ambient=True), plan)
    _, t_ambient = best_of(lambda: ambient.illuminance(points, normals), args.repeat)
    pairs = n * len(light.sources)
    print("\nilluminance (direct term with occlusion; agrees with the reference to 1e-9)")
    print(_row("model", t_light, n, pairs, "luminaire"))
    print(_row("reference", t_light_ref, n, pairs, "luminaire"))
    print(f"  ratio      reference time / model time = {t_light_ref / t_light:.1f}")
    print(
        f"  occlusion  {t_light - t_free:.3f} s of the model's {t_light:.3f} s "
        f"({(t_light - t_free) / t_light:.0%}) is in plan.light_transmittance"
    )
    print(f"  ambient    full model with the ambient term: {t_ambient:.3f} s")
    print(f"  values     median {np.median(e):.0f} lx, {np.mean(e == 0):.1%} of points unlit")

    m = min(n, 20_000)
    body = carriers(points[:m], np.random.default_rng(1))
    src = light.sources
    faced = PointSources.from_arrays(
        src.position, src.axis, src.intensity_cd, src.exponent, size_m=(0.6, 0.6)
    )
    pm, nm = points[:m], normals[:m]
    e_body, t_body = best_of(lambda: direct_illuminance(faced, pm, nm, body=body), args.repeat)
    e_body_ref, t_body_ref = best_of(lambda: reference_body_illuminance(faced, pm, nm, body), 1)
    np.testing.assert_allclose(e_body, e_body_ref, rtol=1e-9, atol=1e-9)
    _, t_bare = best_of(lambda: direct_illuminance(faced, pm, nm), args.repeat)
    share, t_view = best_of(lambda: body.view_blocked(pm, nm), args.repeat)
    pairs = m * len(faced)
    print("\ncarrier's body (0.6 m faces, free space; agrees with the reference to 1e-9)")
    print(_row("model", t_body, m, pairs, "luminaire"))
    print(_row("reference", t_body_ref, m, pairs, "luminaire"))
    print(f"  ratio      reference time / model time = {t_body_ref / t_body:.1f}")
    print(f"  body       {t_body - t_bare:.3f} s of the model's {t_body:.3f} s is the penumbra")
    print(
        f"  view       body's share of the ambient view: {t_view:.3f} s, "
        f"{m / t_view:.3g} points/s (mean share {share.mean():.2f})"
    )
    darker = np.mean(e_body < 0.999 * direct_illuminance(faced, pm, nm))
    print(f"  values     {darker:.1%} of points lose direct light to the body")

    radio = RadioModel(scenario, plan)
    rss, t_radio = best_of(lambda: radio.rss(points), args.repeat)
    shadow = radio.shadowing_db(points)
    rss_ref, t_radio_ref = best_of(lambda: reference_rss(scenario, plan, points), 1)
    np.testing.assert_allclose(rss, rss_ref + shadow, rtol=1e-9, atol=1e-9)
    aps = list(zip(radio.positions, radio.frequency_ghz, strict=True))
    _, t_walls = best_of(
        lambda: [
            plan.crossing_loss_db(points, ap[None], f, scenario.radio.pillar_loss_db)
            for ap, f in aps
        ],
        args.repeat,
    )
    pairs = n * len(radio.bssids)
    print("\nRSS (log-distance + multi-wall + shadowing; agrees with the reference to 1e-9)")
    print(_row("model", t_radio, n, pairs, "AP"))
    print(_row("reference", t_radio_ref, n, pairs, "AP"))
    print(f"  ratio      reference time / model time = {t_radio_ref / t_radio:.1f}")
    print(
        f"  walls      {t_walls:.3f} s of the model's {t_radio:.3f} s "
        f"({t_walls / t_radio:.0%}) is in plan.crossing_loss_db"
    )
    print(f"  values     median {np.median(rss):.1f} dBm, range {rss.min():.1f} to {rss.max():.1f}")

    # The multipath fade a phone adds at its exact spot (radio.multipath).
    faded, t_faded = best_of(lambda: radio.rss(points, small_scale=True), args.repeat)
    field, ap = radio.multipath[0], radio.positions[0]
    walls = plan.crossing_loss_db(points, ap[None], float(radio.frequency_ghz[0]))
    one, t_one = best_of(lambda: field.fading_db(points, ap, walls), args.repeat)
    one_ref, t_one_ref = best_of(lambda: reference_multipath(field, points, ap, walls), 1)
    np.testing.assert_allclose(one, one_ref, rtol=1e-9, atol=1e-9)
    terms = n * len(field.phases) * field.band.shape[1]
    fade = faded - rss
    print(
        f"\nmultipath fade ({len(field.phases)} paths × {field.band.shape[1]} frequencies; "
        "agrees with the reference to 1e-9)"
    )
    print(f"  model      {t_one:.4f} s for one AP, {terms / t_one:.3g} path-frequency terms/s")
    print(f"  reference  {t_one_ref:.4f} s, {terms / t_one_ref:.3g} terms/s")
    print(f"  ratio      reference time / model time = {t_one_ref / t_one:.1f}")
    print(
        f"  rss        small_scale=True {t_faded:.3f} s against {t_radio:.3f} s without "
        f"({t_faded / t_radio:.2f}x); fade median {np.median(fade):.2f} dB, std {np.std(fade):.2f}"
    )


if __name__ == "__main__":
    main()
