"""Hash every output a refactor must not change, so "no output changed" is a checked claim.

A refactor (issue "Architecture") or a speed change that claims bit-identity
runs this before and after and compares::

    .venv/bin/python benchmarks/hashcheck.py --save /tmp/before.json
    ... change the code ...
    .venv/bin/python benchmarks/hashcheck.py --against /tmp/before.json

What is hashed, through the public API only (so the script itself survives
the refactors it checks):

* ``recordings``: every bundled scenario walked on each of its routes, in each
  carrying mode and a mode schedule with transitions, on the papers' phones and
  the ``ideal`` profile: every stream's columns (names, dtypes, values) and the
  manifest metadata;
* ``surveys``: every survey declared by a bundled scenario (grid and walk), the
  fingerprint table and its metadata;
* ``generated``: every procedural building kind at two seeds: the scenario
  YAML text and the built site's magnetic field, illuminance and RSS on a grid;
* ``imported``: the MS Indoor Location floor as ``import-plan`` makes it, with the
  real traces' routes (the sim-to-real twins' site: YAML text and field,
  illuminance and RSS on a grid), and the twin of its first trace: the
  calibrated phone and walker, and the recording they walk, as it is and slowing at
  its marks as the sim-to-real table walks it (skipped, with 0 items, where the real
  data is absent);
* ``dataset``: a 4-shard data set (shard bytes and the card's counts and
  checksums; timings and versions excluded);
* ``leaderboard``: the quick leaderboard's metric columns (run-time columns,
  which measure the machine, excluded); ``--full`` runs the whole board (~15 min).

Prints one hash per item and a TOTAL; exits 1 when ``--against`` finds a difference.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

import indoorsim
from indoorsim import Recording
from indoorsim.dataset import DatasetConfig, build_dataset
from indoorsim.scenario import bundled_scenarios
from indoorsim.simulate import simulate
from indoorsim.survey import grid_survey, walk_survey
from indoorsim.util.provenance import realdata_dir

# Generators and the leaderboard moved in the "Architecture" refactor; the
# script reads them from where they are so that it runs on both sides of it.
try:
    from indoorsim.scenario.generate import KINDS, generate
except ImportError:
    from indoorsim.world.generate import KINDS, generate
try:
    from indoorsim.benchmark.leaderboard import BoardConfig, run_leaderboard
except ImportError:
    from indoorsim.leaderboard import BoardConfig, run_leaderboard

MODES = ("handheld", "calling", "dangling", "pocketed")
DEVICES = ("nexus_5x", "honor_50", "vivo_s9", "ideal")
SCHEDULE = [(0.0, "handheld"), (12.0, "pocketed"), (25.0, "dangling"), (38.0, "calling")]
# Columns of a leaderboard that time the machine, not the method.
TIMING_COLUMNS = ("latency_ms", "train_time_s", "git_revision", "package_version")


def _digest(*parts: bytes | str) -> str:
    h = hashlib.sha256()
    for part in parts:
        h.update(part.encode() if isinstance(part, str) else part)
        h.update(b"\0")
    return h.hexdigest()[:16]


def frame_digest(df: pd.DataFrame) -> str:
    """Column names, dtypes, index and values of a frame, exactly."""
    parts: list[bytes | str] = [repr(list(df.columns)), repr(df.index.name)]
    parts.append(np.ascontiguousarray(df.index.to_numpy()).tobytes() if len(df) else b"")
    for name in df.columns:
        col = df[name]
        parts.append(str(col.dtype))
        values = col.to_numpy()
        if values.dtype == object or str(col.dtype) in ("category", "string"):
            parts.append(json.dumps([None if v is None else str(v) for v in values]))
        else:
            parts.append(np.ascontiguousarray(values).tobytes())
    return _digest(*parts)


def _json(value: Any) -> str:
    return json.dumps(value, sort_keys=True, default=str)


def recording_digest(rec: Recording) -> str:
    parts = [_json(rec.meta)]
    for name in sorted(rec.streams):
        parts += [name, frame_digest(rec.streams[name])]
    return _digest(*parts)


def recordings() -> Iterator[tuple[str, str]]:
    k = 0
    for name in bundled_scenarios():
        site = indoorsim.load_site(name)
        for route in sorted(site.scenario.routes):
            duration = 0.0
            for mode in (*MODES, SCHEDULE):
                if not isinstance(mode, str) and duration <= SCHEDULE[-1][0] + 5:
                    continue  # the schedule needs a walk longer than its last change
                device = DEVICES[k % len(DEVICES)]
                k += 1
                label = mode if isinstance(mode, str) else "schedule"
                rec = simulate(site, route=route, mode=mode, device=device, seed=k)
                duration = rec.duration
                yield f"{name}/{route}/{label}/{device}", recording_digest(rec)


def surveys() -> Iterator[tuple[str, str]]:
    for name in bundled_scenarios():
        site = indoorsim.load_site(name)
        for key, spec in sorted(site.scenario.surveys.items()):
            if spec.kind == "grid":
                db = grid_survey(site, spec, device="honor_50", seed=3)
            else:
                db = walk_survey(site, spec, device="honor_50", seed=3)
            parts = [_json(db.meta)]
            for table in sorted(db.tables):
                parts += [table, frame_digest(db.tables[table])]
            yield f"{name}/{key}", _digest(*parts)


def _field_grid(site: indoorsim.Site) -> np.ndarray:
    x0, y0, x1, y1 = site.plan.walkable.bounds
    gx, gy = np.meshgrid(np.linspace(x0, x1, 23), np.linspace(y0, y1, 17))
    pts = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, 1.2)])
    return pts


def generated() -> Iterator[tuple[str, str]]:
    for kind in sorted(KINDS):
        for seed in (0, 7):
            scenario = generate(kind, seed=seed)
            text = indoorsim.dump_scenario(scenario)
            site = indoorsim.load_site(scenario)
            pts = _field_grid(site)
            normals = np.tile([0.0, 0.0, 1.0], (len(pts), 1))
            yield (
                f"{kind}/seed{seed}",
                _digest(
                    text,
                    site.magnetic_field(pts).tobytes(),
                    site.illuminance(pts, normals).tobytes(),
                    site.rss(pts).tobytes(),
                ),
            )


def imported() -> Iterator[tuple[str, str]]:
    # Imported here, not at the top: the sim-to-real twins are not the public API the
    # other groups use, and a moved module must not stop those.
    from indoorsim.benchmark.realism.calibrate import calibrate
    from indoorsim.benchmark.sim_to_real import (
        TWIN_BASE_DEVICE,
        TWIN_MARK_SPEED,
        TWIN_MODE,
        twin_site,
    )

    real = realdata_dir()
    if not (real / "ms-indoor-location-2020" / "site1" / "F1" / "geojson_map.json").is_file():
        return
    twins = twin_site(real)
    site, traces = twins.site, twins.traces
    if not traces:
        return
    pts = _field_grid(site)
    normals = np.tile([0.0, 0.0, 1.0], (len(pts), 1))
    yield (
        "ilc-F1/seed0",
        _digest(
            indoorsim.dump_scenario(site.scenario),
            site.magnetic_field(pts).tobytes(),
            site.illuminance(pts, normals).tobytes(),
            site.rss(pts).tobytes(),
        ),
    )
    name = sorted(traces)[0]
    cal = calibrate(
        Recording.load(traces[name]), name="twin", base=TWIN_BASE_DEVICE, mode=TWIN_MODE
    )
    walk = simulate(site, route=name, mode=TWIN_MODE, device=cal.device, walker=cal.walker, seed=0)
    profile = _json({"walker": str(cal.walker), "device": str(cal.device)})
    yield f"ilc-F1/twin/{name}", _digest(profile, recording_digest(walk))
    # The twin as the sim-to-real table walks it: slowing at its marks (the pacing code
    # that the calibrated walker alone does not reach).
    slowing = dataclasses.replace(cal.walker, mark_speed=TWIN_MARK_SPEED)
    walk = simulate(site, route=name, mode=TWIN_MODE, device=cal.device, walker=slowing, seed=0)
    yield f"ilc-F1/twin-marks/{name}", _digest(recording_digest(walk))


def dataset() -> Iterator[tuple[str, str]]:
    config = DatasetConfig(
        sites=2, walks_per_site=4, walks_per_shard=2, minutes=0.5, seed=5, bundled_share=0.5
    )
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "data"
        build_dataset(config, out, workers=1, progress=False)
        shards = sorted(out.rglob("*.parquet"))
        if len(shards) != 4:
            raise RuntimeError(f"expected 4 shards, got {len(shards)}")
        for path in shards:
            yield f"shard/{path.name}", _digest(path.read_bytes())
        card = json.loads((out / "dataset_card.json").read_text())
        for volatile in ("versions", "timing", "created", "build", "run"):
            card.pop(volatile, None)
        yield "card", _digest(_json(_stable(card)))


def _stable(value: Any) -> Any:
    """The card without the fields that time or date the run."""
    if isinstance(value, dict):
        return {
            k: _stable(v)
            for k, v in value.items()
            if not any(word in k for word in ("time", "seconds", "_at", "version", "duration_s"))
        }
    if isinstance(value, list):
        return [_stable(v) for v in value]
    return value


def leaderboard(full: bool) -> Iterator[tuple[str, str]]:
    config = BoardConfig() if full else BoardConfig.quick()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "board"
        run_leaderboard(config, out)
        for path in sorted(out.glob("*.csv")):
            df = pd.read_csv(path)
            keep = [c for c in df.columns if not any(c.startswith(t) for t in TIMING_COLUMNS)]
            yield f"board/{path.name}", frame_digest(df[keep])


def run(full: bool, only: set[str] | None) -> dict[str, dict[str, str]]:
    groups: dict[str, Callable[[], Iterator[tuple[str, str]]]] = {
        "recordings": recordings,
        "surveys": surveys,
        "generated": generated,
        "imported": imported,
        "dataset": dataset,
        "leaderboard": lambda: leaderboard(full),
    }
    result: dict[str, dict[str, str]] = {}
    for group, items in groups.items():
        if only and group not in only:
            continue
        started = time.perf_counter()
        result[group] = dict(items())
        print(
            f"{group}: {len(result[group])} items, {_digest(_json(result[group]))} "
            f"({time.perf_counter() - started:.0f} s)",
            flush=True,
        )
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--save", type=Path, help="write the hashes to this JSON file")
    parser.add_argument("--against", type=Path, help="compare with hashes saved earlier")
    parser.add_argument("--full", action="store_true", help="hash the whole leaderboard")
    parser.add_argument(
        "--only",
        nargs="+",
        choices=("recordings", "surveys", "generated", "imported", "dataset", "leaderboard"),
        help="hash these groups only",
    )
    args = parser.parse_args(argv)
    result = run(args.full, set(args.only) if args.only else None)
    print(f"TOTAL {_digest(_json(result))}")
    if args.save:
        args.save.write_text(json.dumps(result, indent=1, sort_keys=True) + "\n")
    if args.against:
        before = json.loads(args.against.read_text())
        changed = [
            f"{group}/{item}: {before.get(group, {}).get(item)} -> {digest}"
            for group, items in result.items()
            for item, digest in items.items()
            if before.get(group, {}).get(item) != digest
        ]
        missing = [
            f"{group}/{item}"
            for group, items in before.items()
            if group in result
            for item in items
            if item not in result[group]
        ]
        for line in changed + [f"{m}: missing" for m in missing]:
            print("DIFFERS", line)
        if changed or missing:
            return 1
        print(f"identical to {args.against}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
