"""The shard task: simulate a shard's walks, cut them into windows, write one Parquet file.

:func:`run_shard` is what a Dask worker runs. It depends only on its arguments
(the resolved configuration and the shard's entry of the plan), so any worker,
in any order, on any retry, writes the same bytes.

One walk (:func:`simulate_walk`):

1. **Route.** From the walk's route seed, a random start in the walkable area
   (at least 0.6 m from anything solid), then random goals (each the farthest
   of three random points) joined by the route planner's shortest paths
   (visibility graph, 0.35 m body clearance), until the route is longer than
   the walker could cover in the walk's duration at the fastest its
   cruising-speed fluctuation allows. At a goal the walker turns (on the spot
   where the next leg doubles back) and goes on.
2. **Simulation.** :func:`indoorsim.simulate.simulate` with the walk's device
   (accelerometer and gyroscope rate set to ``imu_rate_hz``), walker
   parameters, carrying-mode schedule and seed, cut to the configured
   duration before the phone is carried (``duration_s``).
3. **Windows** (:func:`window_table`). :class:`~indoorsim.windows.Windower`
   aligns every stream to the IMU clock (sample-and-hold with freshness
   masks, WiFi as the latest scan); windows of ``window_samples`` samples
   start every ``stride_samples``; only full windows are written. Labels come
   from the truth stream (200 Hz) interpolated linearly to the IMU times
   (attitude by slerp, heading unwrapped first), velocity by central differences of
   the truth positions.

The shard file is written atomically: the table is serialised straight into
a file under a hidden temporary name, hashed (sha256) as it is written, synced
and renamed into place;
then a small JSON sidecar (``shard-NNNNN.json``: checksum, counts, walks) is
written the same way. A shard is complete when its sidecar exists and its
checksum matches the file.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import json
import math
import os
import secrets
import time
import weakref
from collections.abc import Iterator
from pathlib import Path
from typing import Any, BinaryIO

import numba
import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import shapely
from numpy.typing import NDArray

from indoorsim.dataset.config import DatasetConfig
from indoorsim.dataset.plan import ShardSpec, SiteSpec, WalkSpec
from indoorsim.dataset.schema import COLUMNS, FORMAT_VERSION, arrow_schema
from indoorsim.io.recording import Recording
from indoorsim.phone.devices import DeviceProfile, get_device
from indoorsim.scenario.schema import RouteSpec
from indoorsim.util import quaternion as quat_ops
from indoorsim.walker.route import Route, RouteError, plan_route
from indoorsim.windows import Windower, columns_array, hold_index
from indoorsim.world.site import Site

__all__ = [
    "SHARDS_DIR",
    "dataset_device",
    "random_route",
    "run_shard",
    "shard_is_complete",
    "simulate_walk",
    "window_table",
]

SHARDS_DIR = "shards"
RECORDINGS_DIR = "recordings"
PARTIAL = ".partial"
# Route drawing: distance kept from walls for random start and goal points,
# clearance of the planned legs, the shortest leg worth walking, and tries.
_POINT_CLEARANCE_M, _ROUTE_CLEARANCE_M, _MIN_LEG_M, _TRIES = 0.6, 0.35, 4.0, 200
_GOAL_CANDIDATES = 3
_START_TRIES = 10  # failed first legs before another start is drawn
# The cruising speed fluctuates up to 3 CV above the walker's speed (gait.py);
# with the default CV of 3 % a route this much longer than speed × duration
# always lasts the whole duration.
_ROUTE_MARGIN = 1.1


# ------------------------------------------------------------------------- sites


@functools.lru_cache(maxsize=4)
def _site(spec: SiteSpec) -> Site:
    """The site of a plan entry; kept for the next shard of the same site on this worker."""
    from indoorsim.scenario.generate import generate
    from indoorsim.scenario.load import load_site

    if spec.source in ("bundled", "file"):
        return load_site(spec.id)
    assert spec.generator_seed is not None  # make_plan sets it for generated sites
    return load_site(generate(spec.kind, seed=spec.generator_seed))


def dataset_device(name: str, imu_rate_hz: float) -> DeviceProfile:
    """The device profile ``name`` with its accelerometer and gyroscope at ``imu_rate_hz``.

    The error figures are densities and per-run draws, so they keep their
    meaning at another rate; the magnetometer, light and WiFi keep the
    profile's own rates.
    """
    profile = get_device(name)
    return dataclasses.replace(
        profile,
        accel=dataclasses.replace(profile.accel, rate_hz=imu_rate_hz),
        gyro=dataclasses.replace(profile.gyro, rate_hz=imu_rate_hz),
    )


# ------------------------------------------------------------------------ routes

_FREE_AREAS: weakref.WeakKeyDictionary[Site, shapely.Geometry] = weakref.WeakKeyDictionary()


def _free_area(site: Site) -> shapely.Geometry:
    """Where random route points may lie: the walkable area kept clear of walls."""
    if site not in _FREE_AREAS:
        area = site.plan.walkable.buffer(-_POINT_CLEARANCE_M)
        if area.is_empty:  # a very cramped plan: settle for the route clearance
            area = site.plan.walkable.buffer(-_ROUTE_CLEARANCE_M)
        if area.is_empty:
            raise RouteError(f"site {site.name!r}: no walkable point clear of the walls")
        shapely.prepare(area)
        _FREE_AREAS[site] = area
    return _FREE_AREAS[site]


class _RandomPoints:
    """Random points of ``area``: each the first inside ``area`` of a block of
    uniform draws over its bounds (blocks without one are skipped).

    The blocks are drawn many at a time and tested column by column, all open
    blocks in one call: the same points, in the same order, as drawing and
    testing one block per point, at a fraction of the calls. (The generator
    is this object's alone, so drawing ahead changes nothing.)
    """

    _BLOCK, _BLOCKS, _COLUMNS = 64, 32, 8  # points per block, blocks per draw, tested per pass

    def __init__(self, area: shapely.Geometry, rng: np.random.Generator):
        xmin, ymin, xmax, ymax = area.bounds
        self._area, self._rng = area, rng
        self._lo, self._hi = (xmin, ymin), (xmax, ymax)
        self._ready: list[NDArray[np.float64]] = []  # next point last

    def __call__(self) -> NDArray[np.float64]:
        while not self._ready:
            self._draw()
        return self._ready.pop()

    def _draw(self) -> None:
        xy = self._rng.uniform(self._lo, self._hi, size=(self._BLOCKS, self._BLOCK, 2))
        first = np.full(self._BLOCKS, -1)
        open_ = np.arange(self._BLOCKS)  # blocks whose first inside point is not found yet
        for col in range(0, self._BLOCK, self._COLUMNS):
            cand = xy[open_, col : col + self._COLUMNS]
            inside = shapely.contains_xy(self._area, cand[..., 0], cand[..., 1])
            hit = inside.any(axis=1)
            first[open_[hit]] = col + np.argmax(inside[hit], axis=1)
            open_ = open_[~hit]
            if not len(open_):
                break
        self._ready = [xy[k, first[k]] for k in reversed(range(self._BLOCKS)) if first[k] >= 0]


def random_route(site: Site, length_m: float, speed_mps: float, seed: int) -> Route:
    """A route of ``length_m`` metres through ``site``: random goals joined by shortest paths.

    Args:
        site: the building.
        length_m: the route's length; the last leg is cut there.
        speed_mps: the route's walking speed.
        seed: seeds the start and every goal.

    Raises:
        RouteError: the site offers no walkable legs (every try failed).
    """
    random_point = _RandomPoints(_free_area(site), np.random.default_rng(seed))
    here = random_point()
    points = [here]
    total, failures = 0.0, 0
    while total < length_m:
        # The farthest of a few random goals: walks cross the building as people
        # do, and fewer, longer legs cost fewer path searches.
        goals = np.array([random_point() for _ in range(_GOAL_CANDIDATES)])
        goal = goals[int(np.argmax(np.hypot(*(goals - here).T)))]
        if float(np.hypot(*(goal - here))) < _MIN_LEG_M and failures < _TRIES // 2:
            failures += 1  # a short hop is no walk; small sites may offer nothing longer
            continue
        try:
            leg = plan_route(
                site.plan,
                RouteSpec(start=tuple(here), goal=tuple(goal), speed=speed_mps),
                clearance=_ROUTE_CLEARANCE_M,
            )
        except RouteError:
            failures += 1
            if failures > _TRIES:
                raise RouteError(
                    f"site {site.name!r}: no route of {length_m:.0f} m found after "
                    f"{_TRIES} failed legs"
                ) from None
            if len(points) == 1 and failures % _START_TRIES == 0:
                # No leg leaves this start: it may be in a pocket the clearance
                # cuts off from the rest (a cramped room). Start elsewhere.
                here = random_point()
                points = [here]
            continue
        points.extend(leg.points[1:])
        total += leg.length
        here = goal
    return Route(name="random", points=_cut(np.asarray(points), length_m), speed=speed_mps)


def _cut(points: NDArray[np.float64], length_m: float) -> NDArray[np.float64]:
    """The polyline's first ``length_m`` metres."""
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    ends = np.cumsum(seg)
    k = int(np.searchsorted(ends, length_m))
    if k >= len(seg):
        return points
    start = ends[k] - seg[k]
    tip = points[k] + (points[k + 1] - points[k]) * ((length_m - start) / seg[k])
    return np.vstack([points[: k + 1], tip]) if length_m > start + 1e-6 else points[: k + 1]


# ------------------------------------------------------------------------ a walk


def simulate_walk(site: Site, walk: WalkSpec, config: DatasetConfig) -> Recording:
    """Simulate one planned walk (route, device, walker, modes, seed), cut to ``config.minutes``."""
    from indoorsim.simulate import simulate
    from indoorsim.walker.gait import WalkerParams

    duration = config.minutes * 60.0
    speed = walk.walker["speed_mps"]
    route = random_route(site, _ROUTE_MARGIN * speed * duration, speed, walk.route_seed)
    return simulate(
        site,
        route=route,
        mode=walk.schedule,
        device=dataset_device(walk.device, config.imu_rate_hz),
        seed=walk.seed,
        walker=WalkerParams(**walk.walker),
        duration_s=duration,
    )


def _interpolate(t_src: NDArray[np.float64], t: NDArray[np.float64], below: NDArray[np.intp]):
    """Linear interpolation from ``t_src`` to ``t`` (inside its span), as a function of
    values and optionally the output dtype (float32: the float64 result rounded).

    ``below`` is :func:`~indoorsim.windows.hold_index` of ``t`` in ``t_src``.
    """
    j, f = _fractions(t_src, t, below)

    def at(values: NDArray[np.float64], dtype: type = np.float64) -> NDArray:
        out = np.empty((len(t), *values.shape[1:]), dtype=dtype)
        width = math.prod(values.shape[1:])  # not -1: t may be empty
        _lerp(values.reshape(len(values), width), j, f, out.reshape(len(t), width))
        return out

    return at


@numba.njit(cache=True, error_model="numpy")
def _fractions(t_src, t, below):  # pragma: no cover - compiled
    """The interval ``j = clip(below, 0, len(t_src) − 2)`` of each time and its fraction
    ``f = clip((t − t_src[j]) / (t_src[j + 1] − t_src[j]), 0, 1)``, as numpy clips
    (NaN kept, −0.0 kept)."""
    last = t_src.shape[0] - 2
    j = np.empty(t.shape[0], np.intp)
    f = np.empty(t.shape[0])
    for i in range(t.shape[0]):
        k = min(max(below[i], 0), last)
        x = (t[i] - t_src[k]) / (t_src[k + 1] - t_src[k])
        j[i], f[i] = k, 0.0 if x < 0.0 else (1.0 if x > 1.0 else x)
    return j, f


@numba.njit(cache=True, error_model="numpy")
def _lerp(v, j, f, out):  # pragma: no cover - compiled
    """``out = v[j] + f * (v[j + 1] - v[j])`` row by row (the same operations), in one pass."""
    for i in range(j.shape[0]):
        for k in range(v.shape[1]):
            a = v[j[i], k]
            out[i, k] = a + f[i] * (v[j[i] + 1, k] - a)


def _fixed(values: NDArray, shape: tuple[int, ...]) -> pa.Array:
    """(rows, *shape) values as nested fixed-size lists."""
    arr: pa.Array = pa.array(np.ascontiguousarray(values).reshape(-1))
    for size in reversed(shape):
        arr = pa.FixedSizeListArray.from_arrays(arr, size)
    return arr


def _lists(values: pa.Array, counts: NDArray[np.intp]) -> pa.Array:
    offsets = np.zeros(len(counts) + 1, dtype=np.int32)
    np.cumsum(counts, out=offsets[1:])
    return pa.ListArray.from_arrays(pa.array(offsets), values)


def window_table(
    rec: Recording, site: Site, site_spec: SiteSpec, walk: WalkSpec, config: DatasetConfig
) -> pa.Table:
    """The windows of one walk as a table with the shard schema (see the module docstring)."""
    w_len, stride = config.window_samples, config.stride
    win = Windower(rec, w_len, site.radio.bssids)
    t = win.t
    n = len(t)
    starts = np.arange(0, n - w_len + 1, stride)
    nw = len(starts)
    last = starts + w_len - 1
    a = win.aligned
    if stride == w_len:  # back to back: the windows are the first nw·W samples, reshaped

        def cut(x: NDArray) -> NDArray:
            return x[: nw * w_len].reshape(nw, w_len, *x.shape[1:])

    else:
        idx = starts[:, None] + np.arange(w_len)

        def cut(x: NDArray) -> NDArray:
            return x[idx]

    truth = rec.truth
    tt = truth.index.to_numpy()
    below = hold_index(tt, t)
    at = _interpolate(tt, t, below)
    pos_truth = columns_array(truth, ["x", "y", "z"])
    # Labels stored only as float32 are written so straight away (the same
    # rounding of the same float64 values as a cast afterwards).
    pos = at(pos_truth, np.float32)
    vel = at(np.gradient(pos_truth, tt, axis=0), np.float32)
    quat = quat_ops.slerp(
        tt,
        columns_array(truth, ["qw", "qx", "qy", "qz"]),
        t,
        below=below,
        out=np.empty((n, 4), dtype=np.float32),
    )
    body = at(columns_array(truth, ["body_x", "body_y"]))
    heading = at(np.unwrap(truth["heading"].to_numpy(dtype=np.float64)))
    # Wrapped to (−π, π] as π − ((π − heading) mod 2π), in place (the array is ours).
    np.subtract(np.pi, heading, out=heading)
    np.mod(heading, 2.0 * np.pi, out=heading)
    np.subtract(np.pi, heading, out=heading)
    held = np.clip(below, 0, len(tt) - 1)
    # The per-sample modes come in long runs: the runs are named (codes in
    # sorted-name order), not 10⁵ strings one by one.
    labels = pa.array(truth["mode"])
    if isinstance(labels, pa.ChunkedArray):
        labels = labels.combine_chunks()
    runs = pc.run_end_encode(labels)
    mode_names, run_code = np.unique(
        np.asarray(runs.values.to_pylist(), dtype=str), return_inverse=True
    )
    mode_code = np.repeat(run_code, np.diff(runs.run_ends.to_numpy(), prepend=0))
    mode_at = mode_code[held]

    steps = rec.steps
    step_t = steps.index.to_numpy(dtype=float)
    step_sample = np.searchsorted(t, step_t, side="left")
    inside = step_sample < n
    step_t, step_sample = step_t[inside], step_sample[inside]
    step_len = steps["length"].to_numpy(dtype=np.float32)[inside]
    step_flag = np.zeros(n, dtype=bool)
    step_flag[step_sample] = True
    lo = np.searchsorted(step_sample, starts, side="left")
    hi = np.searchsorted(step_sample, starts + w_len, side="left")
    counts = hi - lo
    offsets = np.r_[0, np.cumsum(counts)]
    picked = np.repeat(lo - offsets[:-1], counts) + np.arange(offsets[-1])

    wifi = win.wifi_windows(starts, last)
    heard = wifi["wifi_heard"].astype(bool)
    rows, cols = np.nonzero(heard)
    bssids = np.asarray(site.radio.bssids, dtype=object)

    field = site.magnetic.earth_field_uT
    north = math.atan2(field[1], field[0])
    body_dt = t[last] - t[starts]
    body_vel = (body[last] - body[starts]) / body_dt[:, None]
    mode_win = cut(mode_at)

    def f32(x: NDArray) -> NDArray[np.float32]:
        return np.asarray(x, dtype=np.float32)

    def repeat(text: str) -> pa.Array:
        return pa.array([text] * nw, type=pa.string())

    columns: dict[str, pa.Array] = {
        "site": repeat(site_spec.id),
        "site_kind": repeat(site_spec.kind),
        "walk_id": repeat(walk.walk_id),
        "device": repeat(walk.device),
        "window": pa.array(np.arange(nw, dtype=np.int32)),
        "t_start": pa.array(t[starts]),
        "magnetic_north": pa.array(np.full(nw, north, dtype=np.float32)),
        "t": _fixed(cut(t), (w_len,)),
        "accel": _fixed(f32(cut(a["accel"])), (w_len, 3)),
        "gyro": _fixed(f32(cut(a["gyro"])), (w_len, 3)),
        "mag": _fixed(f32(cut(a["mag"])), (w_len, 3)),
        "mag_fresh": _fixed(cut(a["mag_fresh"]).astype(bool), (w_len,)),
        "light": _fixed(f32(cut(a["light"])), (w_len,)),
        "light_fresh": _fixed(cut(a["light_fresh"]).astype(bool), (w_len,)),
        "rotation": _fixed(f32(cut(a["rotation"])), (w_len, 4)),
        "game_rotation": _fixed(f32(cut(a["game_rotation"])), (w_len, 4)),
        "gravity": _fixed(f32(cut(a["gravity"])), (w_len, 3)),
        "wifi_bssid": _lists(pa.array(bssids[cols], type=pa.string()), heard.sum(axis=1)),
        "wifi_rss": _lists(pa.array(f32(wifi["wifi_rss"][rows, cols])), heard.sum(axis=1)),
        "wifi_fresh": pa.array(wifi["wifi_fresh"][:, 0].astype(bool)),
        "wifi_age": pa.array(f32(wifi["wifi_age"][:, 0])),
        "pos": _fixed(f32(cut(pos)), (w_len, 3)),
        "vel": _fixed(f32(cut(vel)), (w_len, 3)),
        "quat": _fixed(f32(cut(quat)), (w_len, 4)),
        "body_pos": _fixed(f32(cut(body)), (w_len, 2)),
        "body_vel": _fixed(f32(body_vel), (2,)),
        "heading": _fixed(f32(cut(heading)), (w_len,)),
        "step": _fixed(cut(step_flag), (w_len,)),
        "step_count": pa.array(counts.astype(np.int16)),
        "step_t": _lists(pa.array(step_t[picked]), counts),
        "step_length": _lists(pa.array(step_len[picked]), counts),
        "mode": pa.array(mode_names[mode_at[last]].astype(object), type=pa.string()),
        "mode_changed": pa.array((mode_win != mode_win[:, :1]).any(axis=1)),
    }
    return pa.Table.from_arrays([columns[c.name] for c in COLUMNS], schema=arrow_schema(w_len))


# ------------------------------------------------------------------------ writing


def _scalar_columns() -> list[str]:
    return [c.name for c in COLUMNS if not c.shape]


def _float_leaves() -> list[str]:
    """Parquet paths of the float columns' values (each list level adds ``.list.element``)."""
    return [c.name + ".list.element" * len(c.shape) for c in COLUMNS if c.dtype.startswith("float")]


class _HashingSink:
    """A write-only binary file that passes what it is given on to ``fh`` and hashes it."""

    closed = False

    def __init__(self, fh: BinaryIO):
        self._fh = fh
        self.sha256 = hashlib.sha256()
        self.size = 0

    def write(self, data: bytes | memoryview) -> int:
        self.sha256.update(data)
        self.size += len(data)
        return self._fh.write(data)

    def writable(self) -> bool:
        return True

    def flush(self) -> None:
        pass  # ``fh`` is flushed and synced by its owner

    def close(self) -> None:
        self.closed = True  # ``fh`` stays open for its owner to sync


def write_parquet(path: Path, table: pa.Table, config: DatasetConfig) -> tuple[str, int]:
    """Write ``table`` as the shard file at ``path``, atomically; return its sha256 and size.

    A fixed layout, so equal tables give equal bytes. The writer's output goes
    straight to the temporary file (see :func:`write_atomically`) and into the
    hash as it is produced, in blocks of a MiB: the file is never held whole
    in memory (a growing buffer would be copied each time it doubles).
    """
    with _atomic_file(path) as fh:
        sink = _HashingSink(fh)
        with pa.output_stream(sink, buffer_size=1 << 20) as stream:
            pq.write_table(
                table,
                stream,
                row_group_size=config.rows_per_row_group,
                compression=config.compression,
                # Dictionaries only where values repeat (ids, modes, BSSIDs); statistics
                # only on the scalar columns, which readers filter on.
                use_dictionary=[c.name for c in COLUMNS if c.dtype == "string"],
                write_statistics=_scalar_columns(),
                # Floats stored byte plane by byte plane: the planes of slowly varying
                # signs and exponents compress well, so zstd shards are ~20 % smaller
                # and written faster (the decoded values are the same).
                use_byte_stream_split=_float_leaves(),
            )
    return sink.sha256.hexdigest(), sink.size


@contextlib.contextmanager
def _atomic_file(path: Path) -> Iterator[BinaryIO]:
    """A file open for writing under a hidden temporary name, synced and renamed to
    ``path`` when the block ends; removed instead if it raises."""
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}{PARTIAL}")
    try:
        with open(tmp, "wb") as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_atomically(path: Path, data: bytes | memoryview) -> None:
    """Write ``data`` to ``path``: a hidden temporary sibling, synced, then renamed."""
    with _atomic_file(path) as fh:
        fh.write(data)


def sha256_file(path: Path) -> str:
    """Hex sha256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def shard_is_complete(out: Path, name: str) -> dict[str, Any] | None:
    """The sidecar of a finished shard whose file matches its checksum, else None."""
    folder = out / SHARDS_DIR
    sidecar, data = folder / f"{name}.json", folder / f"{name}.parquet"
    if not (sidecar.is_file() and data.is_file()):
        return None
    try:
        info = json.loads(sidecar.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    if not isinstance(info, dict) or info.get("sha256") != sha256_file(data):
        return None
    return info


def run_shard(config_json: dict[str, Any], shard_json: dict[str, Any], out: str) -> dict[str, Any]:
    """Simulate, window and write one shard; return its sidecar plus timings.

    Args:
        config_json: the resolved configuration (``DatasetConfig.to_json()``).
        shard_json: the shard's plan entry (``ShardSpec.to_json()``).
        out: the data set's folder.

    Returns:
        The sidecar written beside the shard (name, file, sha256, bytes, rows,
        site, walks) with an extra ``timing`` entry (wall seconds per stage,
        their total, and the process's CPU seconds), which is not written.
    """
    config = DatasetConfig.model_validate(config_json)
    shard = ShardSpec.from_json(shard_json)
    root = Path(out)
    clock = {"site_s": 0.0, "simulate_s": 0.0, "windows_s": 0.0, "write_s": 0.0}
    cpu0, t0 = time.process_time(), time.perf_counter()
    site = _site(shard.site)
    clock["site_s"] = time.perf_counter() - t0
    tables, walks = [], []
    for walk in shard.walks:
        t1 = time.perf_counter()
        rec = simulate_walk(site, walk, config)
        t2 = time.perf_counter()
        if config.recordings:
            rec.save(root / RECORDINGS_DIR / walk.walk_id, overwrite=True)
        table = window_table(rec, site, shard.site, walk, config)
        t3 = time.perf_counter()
        clock["simulate_s"] += t2 - t1
        clock["windows_s"] += t3 - t2
        tables.append(table)
        walks.append(
            {
                "walk_id": walk.walk_id,
                "windows": table.num_rows,
                "duration_s": round(float(rec.accel.index[-1]), 6),
                "walked_m": round(_walked(rec), 3),
                "steps": len(rec.steps),
            }
        )
    t4 = time.perf_counter()
    folder = root / SHARDS_DIR
    folder.mkdir(parents=True, exist_ok=True)
    sha256, size = write_parquet(folder / f"{shard.name}.parquet", pa.concat_tables(tables), config)
    sidecar = {
        "format_version": FORMAT_VERSION,
        "name": shard.name,
        "file": f"{SHARDS_DIR}/{shard.name}.parquet",
        "sha256": sha256,
        "bytes": size,
        "rows": sum(w["windows"] for w in walks),
        "site": shard.site.id,
        "walks": walks,
    }
    text = json.dumps(sidecar, indent=2, sort_keys=True, allow_nan=False) + "\n"
    write_atomically(folder / f"{shard.name}.json", text.encode("utf-8"))
    clock["write_s"] = time.perf_counter() - t4
    clock["total_s"] = time.perf_counter() - t0
    clock["cpu_s"] = time.process_time() - cpu0  # apart from total_s when cores are shared
    return {**sidecar, "timing": {k: round(v, 4) for k, v in clock.items()}}


def _walked(rec: Recording) -> float:
    """Distance the body centre travelled, m."""
    body = columns_array(rec.truth, ["body_x", "body_y"])
    return float(np.linalg.norm(np.diff(body, axis=0), axis=1).sum())
