"""Labelled data sets at scale: many sites, walks, carrying modes and phones, as Parquet shards.

``indoorsim dataset`` (DESIGN §11) simulates walks through bundled and
procedurally generated buildings and writes fixed-length windows of the
phone's streams with their truth labels, on Dask, deterministically whatever
the number of workers, resumably, and with a dataset card. The modules, one
role each:

* :mod:`~indoorsim.dataset.config` — :class:`DatasetConfig`, the strict configuration;
* :mod:`~indoorsim.dataset.plan` — :func:`make_plan`: sites, walks and shards
  as a pure function of the configuration; :func:`split_sites`;
* :mod:`~indoorsim.dataset.schema` — :data:`COLUMNS`, every column of a shard
  (name, type, shape, unit, frame, meaning);
* :mod:`~indoorsim.dataset.shard` — the task: simulate a shard's walks, cut
  windows, write the file atomically;
* :mod:`~indoorsim.dataset.driver` — :func:`build_dataset`: Dask, resume,
  retries, progress;
* :mod:`~indoorsim.dataset.card` — ``dataset_card.json`` and ``README.md``;
* :mod:`~indoorsim.dataset.torch` — torch data sets over the shards.

Example:
    >>> from indoorsim.dataset import DatasetConfig, make_plan
    >>> plan = make_plan(DatasetConfig(sites=3, walks_per_site=2, bundled_share=0).resolved())
    >>> [s.kind for s in plan.sites], len(plan.walks), [s.name for s in plan.shards]
    (['office', 'basement', 'l_corridor'], 6, ['shard-00000', 'shard-00001', 'shard-00002'])
"""

from __future__ import annotations

from typing import Any

from indoorsim.dataset.config import DatasetConfig, DatasetConfigError, load_config
from indoorsim.dataset.plan import Plan, ShardSpec, SiteSpec, WalkSpec, make_plan, split_sites
from indoorsim.dataset.schema import COLUMNS, Column

__all__ = [
    "COLUMNS",
    "BuildReport",
    "Column",
    "DatasetConfig",
    "DatasetConfigError",
    "DatasetFolderError",
    "Plan",
    "ShardFailures",
    "ShardSpec",
    "SiteSpec",
    "WalkSpec",
    "build_dataset",
    "load_config",
    "make_plan",
    "split_sites",
]

_DRIVER = ("BuildReport", "DatasetFolderError", "ShardFailures", "build_dataset")


def __getattr__(name: str) -> Any:
    # The driver imports Dask, which is slow to import and not needed to read a plan.
    if name in _DRIVER:
        from indoorsim.dataset import driver

        return getattr(driver, name)
    raise AttributeError(f"module 'indoorsim.dataset' has no attribute {name!r}")
