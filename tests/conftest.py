"""Shared fixtures: paths to the shared folder and small scenarios built in Python.

Folders outside the repository come from the environment, with this
project's development layout (``../shared`` beside the repository) as default:
``$INDOORSIM_SHARED`` for the shared examples, ``$INDOORSIM_REALDATA`` for the
real recordings (as :func:`indoorsim.util.provenance.realdata_dir` reads it).
Tests that need them skip, saying which folder is missing, when they are absent.

Property tests (hypothesis) run under the ``suite`` profile: a bounded number
of examples, drawn the same way on every run, so the default suite is
deterministic and its time bounded. ``@settings(SWEEP)`` on a ``slow`` test runs
the same property over many more random examples; ``--hypothesis-profile slow``
(or ``$INDOORSIM_HYPOTHESIS_PROFILE=slow``) does so for every property test.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from indoorsim.util.provenance import realdata_dir

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("INDOORSIM_SHARED") or REPO.parent / "shared")
REALDATA = realdata_dir()
MINIMAL_SITE = SHARED / "examples" / "minimal-site.yaml"
BUNDLED_MINIMAL = REPO / "scenarios" / "minimal_room.yaml"

# No deadline: a first example may compile numba kernels or load a site (seconds).
# No example database: derandomised runs would only replay what they draw anyway.
settings.register_profile(
    "suite",
    max_examples=30,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "slow",
    max_examples=500,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
if settings.get_current_profile_name() == "default":  # no --hypothesis-profile given
    settings.load_profile(os.environ.get("INDOORSIM_HYPOTHESIS_PROFILE", "suite"))
SWEEP = settings.get_profile("slow")
"""For the ``slow`` sweeps: the property over 500 fresh random examples a run."""


@pytest.fixture(scope="session")
def one_room_data(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A data set of one 30 s walk in the bundled 10 m room: ~60 windows of 1 s at
    50 Hz, all in the train split (its val and test splits are empty). Seconds to
    build; enough to train the learned-io network an epoch or two."""
    from indoorsim.dataset import DatasetConfig, build_dataset

    config = DatasetConfig(
        sites=1,
        walks_per_site=1,
        minutes=0.5,
        seed=3,
        bundled=["minimal_room"],
        bundled_share=1.0,
        imu_rate_hz=50.0,
        window_samples=50,
        stride_samples=25,
        rows_per_row_group=64,
    )
    out = tmp_path_factory.mktemp("one_room") / "data"
    build_dataset(config, out, workers=1, progress=False)
    return out


@pytest.fixture
def minimal_site_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shared minimal example; without the shared folder, the bundled copy under its name.

    The bundled ``minimal_room.yaml`` is the shared file but for its ``name:``
    (tests/world/test_bundled_scenarios.py checks that), so the scenario tests
    run, not skip, on a machine that has only the repository.
    """
    if MINIMAL_SITE.is_file():
        return MINIMAL_SITE
    copy = tmp_path_factory.mktemp("shared") / MINIMAL_SITE.name
    text = BUNDLED_MINIMAL.read_text(encoding="utf-8")
    copy.write_text(text.replace("name: minimal_room", "name: minimal-room", 1), encoding="utf-8")
    return copy


def box_scenario(**overrides: object) -> dict:
    """A 10 m × 6 m concrete room as a plain dict; keys in ``overrides`` replace the defaults."""
    data: dict = {
        "name": "box",
        "site": {
            "latitude": 32.63,
            "longitude": 117.0,
            "date": "2025-01-01",
            "ceiling_height": 3.0,
        },
        "walls": [
            {"from": [0, 0], "to": [10, 0], "thickness": 0.2},
            {"from": [10, 0], "to": [10, 6], "thickness": 0.2},
            {"from": [10, 6], "to": [0, 6], "thickness": 0.2},
            {"from": [0, 6], "to": [0, 0], "thickness": 0.2},
        ],
    }
    data.update(overrides)
    return data
