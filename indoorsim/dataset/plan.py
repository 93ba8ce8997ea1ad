"""The plan of a data set: which sites, which walks, which shard holds which walks.

:func:`make_plan` is a pure function of a resolved
:class:`~indoorsim.dataset.config.DatasetConfig` and the packaged real walkers'
table it draws vigour from (whose checksum the driver keeps in ``inputs.json``):
the same configuration gives the same plan on any machine, before any simulation
runs. Every random choice draws from a generator keyed by the configuration's
seed and the *identity* of what it decides — ``(seed, site index)`` for a site,
``(seed, site index, walk index)`` for a walk — never by shard, worker or
execution order. Changing ``walks_per_shard`` regroups the same walks; adding
sites or walks leaves the existing ones as they were.

Sites: the first ``round(sites · bundled_share)`` come from the scenarios of
``bundled`` — bundled names or scenario files such as an imported real floor —
(a seeded permutation of them, so each is used at most once),
the others are procedural buildings whose kinds take turns through
``generated_kinds``, each from its own generator seed.

Walks: per walk a device, walker parameters drawn from the configured ranges
and (by default) one real walker's vigour,
a carrying-mode schedule (a random first mode, then changes at Poisson times
of rate ``mode_changes_per_minute``, each stretch at least ``min_mode_s``
long), a seed for the route and a seed for the simulation. The route itself
is drawn in the worker (it needs the floor plan) from the route seed.

Shards: the walks of one site, ``walks_per_shard`` at a time, numbered
site by site.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from indoorsim.dataset.config import DatasetConfig, Range, is_yaml_file
from indoorsim.util.seeding import generator
from indoorsim.walker.real_walkers import draw_real_vigour
from indoorsim.walker.schedule import ModeSchedule

__all__ = ["Plan", "ShardSpec", "SiteSpec", "WalkSpec", "make_plan", "split_sites"]

# Seeding phase of the data-set plan, beside indoorsim.util.seeding's WALK = 0 and
# SURVEY = 1, so that no plan stream coincides with a walk's or a survey's.
PLAN_PHASE = 2
_SITES, _WALKS, _BUNDLED_ORDER, _MODE_PARAMS, _VIGOUR = 0, 1, 2, 3, 4
_MAX_SEED = 2**63 - 1


def _rng(seed: int, *key: int) -> np.random.Generator:
    return generator(seed, (PLAN_PHASE, *key))


@dataclass(frozen=True, kw_only=True)
class SiteSpec:
    """One building of the data set.

    Attributes:
        index: position in the plan (0-based).
        id: the site's name: the bundled scenario's name, the scenario file's path
            as the configuration gives it, or ``{kind}-{seed}`` for a generated one
            (the generated scenario's own name).
        source: ``"bundled"``, ``"file"`` or ``"generated"``.
        kind: the generated kind, or ``"bundled"`` or ``"file"``.
        generator_seed: the seed passed to ``generate`` (None when bundled).
    """

    index: int
    id: str
    source: str
    kind: str
    generator_seed: int | None = None


@dataclass(frozen=True, kw_only=True)
class WalkSpec:
    """One walk: everything that is drawn for it before the simulation.

    Attributes:
        walk_id: ``s{site:04d}-w{walk:03d}``, unique in the data set.
        site: the site's index.
        index: the walk's index within its site.
        device: device-profile name (its IMU rate is set to the configured rate).
        walker: :class:`~indoorsim.walker.gait.WalkerParams` fields drawn for this walker.
        modes: the carrying-mode schedule, ``[[t_start_s, mode(, params)], ...]``,
            params being the stretch's configured mode parameters.
        route_seed: seeds the random route through the site.
        seed: the simulation's seed (:func:`indoorsim.simulate.simulate`).
    """

    walk_id: str
    site: int
    index: int
    device: str
    walker: dict[str, float | list[float]]
    modes: list[list[Any]]
    route_seed: int
    seed: int

    @property
    def schedule(self) -> ModeSchedule:
        """:attr:`modes` as the checked schedule the walk's simulation follows."""
        entries = [
            (float(e[0]), str(e[1]), dict(e[2])) if len(e) > 2 else (float(e[0]), str(e[1]))
            for e in self.modes
        ]
        return ModeSchedule.of(entries)


@dataclass(frozen=True, kw_only=True)
class ShardSpec:
    """One output file: a fixed set of walks of one site.

    Attributes:
        index: shard number.
        name: ``shard-{index:05d}`` (wider when there are more shards).
        site: the site all its walks are in.
        walks: the walks, in order.
    """

    index: int
    name: str
    site: SiteSpec
    walks: tuple[WalkSpec, ...]

    def to_json(self) -> dict[str, Any]:
        """A JSON-able dict (how a shard task travels to a worker)."""
        return {
            "index": self.index,
            "name": self.name,
            "site": asdict(self.site),
            "walks": [asdict(w) for w in self.walks],
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> ShardSpec:
        """Inverse of :meth:`to_json`."""
        return cls(
            index=data["index"],
            name=data["name"],
            site=SiteSpec(**data["site"]),
            walks=tuple(WalkSpec(**w) for w in data["walks"]),
        )


@dataclass(frozen=True, kw_only=True)
class Plan:
    """Sites, walks and shards of a data set (see the module docstring)."""

    sites: tuple[SiteSpec, ...]
    walks: tuple[WalkSpec, ...]
    shards: tuple[ShardSpec, ...]


def make_plan(config: DatasetConfig) -> Plan:
    """The plan of a resolved configuration (see the module docstring)."""
    sites = _sites(config)
    walks = tuple(
        _walk(config, site.index, j) for site in sites for j in range(config.walks_per_site)
    )
    shards: list[ShardSpec] = []
    n_shards = len(sites) * -(-config.walks_per_site // config.walks_per_shard)
    width = max(5, len(str(n_shards - 1)))
    for site in sites:
        own = [w for w in walks if w.site == site.index]
        for k in range(0, len(own), config.walks_per_shard):
            index = len(shards)
            shards.append(
                ShardSpec(
                    index=index,
                    name=f"shard-{index:0{width}d}",
                    site=site,
                    walks=tuple(own[k : k + config.walks_per_shard]),
                )
            )
    return Plan(sites=sites, walks=walks, shards=tuple(shards))


def _sites(config: DatasetConfig) -> tuple[SiteSpec, ...]:
    bundled = list(config.bundled or [])
    n_bundled = config.bundled_sites
    order = _rng(config.seed, _BUNDLED_ORDER).permutation(len(bundled))
    out = []
    for i in range(n_bundled):
        name = bundled[order[i]]
        source = "file" if is_yaml_file(name) else "bundled"
        out.append(SiteSpec(index=i, id=name, source=source, kind=source))
    used = {s.id for s in out}
    kinds = config.generated_kinds
    for i in range(n_bundled, config.sites):
        kind = kinds[(i - n_bundled) % len(kinds)]
        rng = _rng(config.seed, _SITES, i)
        while True:  # a repeated (kind, seed) would be the same building twice
            gen_seed = int(rng.integers(0, 2**31))
            site_id = f"{kind}-{gen_seed}"
            if site_id not in used:
                break
        used.add(site_id)
        out.append(
            SiteSpec(index=i, id=site_id, source="generated", kind=kind, generator_seed=gen_seed)
        )
    return tuple(out)


def _uniform(rng: np.random.Generator, r: Any) -> float:
    return round(float(rng.uniform(r.low, r.high)), 6)


def _walk(config: DatasetConfig, site: int, j: int) -> WalkSpec:
    # A fixed sequence of draws per walk: the lists of devices or modes can
    # change without moving any other draw.
    rng = _rng(config.seed, _WALKS, site, j)
    device = config.devices[int(rng.integers(len(config.devices)))]
    ranges = config.walker
    walker = {
        name: _uniform(rng, getattr(ranges, name))
        for name in (
            "height_m",
            "speed_mps",
            "step_length_cv",
            "step_time_cv",
            "asymmetry",
            "stop_rate_per_min",
        )
    }
    if (ranges.mark_speed.low, ranges.mark_speed.high) != (1.0, 1.0):
        # A range the walk draws from at each of its route points: no draw here.
        walker["mark_speed"] = [ranges.mark_speed.low, ranges.mark_speed.high]
    if ranges.vigour == "real":
        # Its own stream: choosing the vigour moves no other draw of the walk.
        walker |= draw_real_vigour(_rng(config.seed, _VIGOUR, site, j))
    # The schedule draws as many numbers as it has changes: its own stream.
    modes = _mode_schedule(config, np.random.default_rng(int(rng.integers(_MAX_SEED))))
    route_seed = int(rng.integers(_MAX_SEED))
    seed = int(rng.integers(_MAX_SEED))
    # Each stretch's mode parameters from a stream of their own: configuring
    # them moves no other draw of the walk.
    params_rng = _rng(config.seed, _MODE_PARAMS, site, j)
    for entry in modes:
        drawn = _mode_params(config, entry[1], params_rng)
        if drawn:
            entry.append(drawn)
    return WalkSpec(
        walk_id=f"s{site:04d}-w{j:03d}",
        site=site,
        index=j,
        device=device,
        walker=walker,
        modes=modes,
        route_seed=route_seed,
        seed=seed,
    )


def _mode_params(config: DatasetConfig, mode: str, rng: np.random.Generator) -> dict[str, Any]:
    """The configured parameters of one stretch in ``mode``: ranges drawn, values as given."""
    return {
        name: _uniform(rng, value) if isinstance(value, Range) else value
        for name, value in config.mode_params.get(mode, {}).items()
    }


def _mode_schedule(config: DatasetConfig, rng: np.random.Generator) -> list[list[Any]]:
    """``[[0, first_mode], [t1, mode1], ...]``: Poisson changes, none in the last stretch."""
    names = config.modes
    mode = names[int(rng.integers(len(names)))]
    schedule: list[list[Any]] = [[0.0, mode]]
    if config.mode_changes_per_minute == 0 or len(names) < 2:
        return schedule
    mean_gap = 60.0 / config.mode_changes_per_minute
    end = config.minutes * 60.0 - config.min_mode_s
    t = 0.0
    while True:
        # Millisecond times read well in the card; the gap is kept whole.
        t = round(t + max(config.min_mode_s, round(float(rng.exponential(mean_gap)), 3)), 3)
        if t > end:
            return schedule
        others = [m for m in names if m != mode]
        mode = others[int(rng.integers(len(others)))]
        schedule.append([t, mode])


def split_sites(
    site_ids: list[str],
    fractions: tuple[float, float, float] = (0.8, 0.1, 0.1),
    seed: int = 0,
) -> dict[str, list[str]]:
    """Assign whole sites to train/val/test, so no building is seen in two splits.

    A seeded permutation of the sorted ids is cut by ``fractions``. With three
    or more sites every split with a positive fraction gets at least one site.

    Args:
        site_ids: the sites (any order; duplicates are ignored).
        fractions: shares of train, val and test; non-negative, summing to 1.
        seed: seeds the permutation.

    Returns:
        ``{"train": [...], "val": [...], "test": [...]}``, each sorted.

    Raises:
        ValueError: for fractions that are negative or do not sum to 1.

    Example:
        >>> s = split_sites([f"site{i}" for i in range(10)], seed=1)
        >>> [len(s[k]) for k in ("train", "val", "test")]
        [8, 1, 1]
    """
    if len(fractions) != 3 or min(fractions) < 0 or abs(sum(fractions) - 1.0) > 1e-9:
        raise ValueError(f"fractions must be three shares >= 0 summing to 1, got {fractions}")
    ids = sorted(set(site_ids))
    n = len(ids)
    counts = [round(f * n) for f in fractions[1:]]
    if n >= 3:
        counts = [max(c, 1) if f > 0 else c for c, f in zip(counts, fractions[1:], strict=True)]
    n_val, n_test = counts
    n_val = min(n_val, n)
    n_test = min(n_test, n - n_val)
    order = [ids[k] for k in np.random.default_rng(seed).permutation(n)]
    test, val, train = order[:n_test], order[n_test : n_test + n_val], order[n_test + n_val :]
    return {"train": sorted(train), "val": sorted(val), "test": sorted(test)}
