"""The estimator protocol and the public knowledge an estimator may use.

An estimator is any object with::

    name: str
    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None  # optional training
    def reset(self, start: StartInfo) -> None                              # a new episode
    def act(self, obs: Observation) -> np.ndarray                          # (x, y) now, metres

An estimator may also expose ``heading`` (its current walking-direction
estimate, rad counter-clockwise from the building's +x), ``step_count``
(steps detected so far) and ``estimate_time`` (the time, s, its current
answer refers to — a step estimator's last step, a fingerprint match's
samples — no later than the window's end; None for "now"): the runner then
scores heading error per window, step-count error, and each estimate also
against the truth at the time it refers to (the ``_reftime`` metrics, the
papers' per-step protocol, beside the time-uniform ones at the window's end:
:mod:`~indoorsim.benchmark.evaluation`).

It sees only what a real team would have: the :class:`SiteContext` (floor
plan, fingerprint databases measured with the survey phone, the site's
frames), labelled training walks on other routes and seeds, the start of each
test episode, and the sensor windows of :mod:`indoorsim.windows`. It never
imports the simulator's truth side (``indoorsim.world``, ``indoorsim.walker``,
``indoorsim.phone``); a test enforces this.

Estimators register by name (:func:`register`), through the entry-point group
``indoorsim.estimators``, or as a ``"package.module:Class"`` string, so a
user's package plugs in without editing indoorsim (:func:`make`).

An estimator class may also declare what it runs on, for ``indoorsim
estimators`` to list (both optional; the terms are the keys of :data:`NEEDS`)::

    needs: ClassVar[tuple[str, ...]] = ("walk survey", "WiFi")  # without them fit raises
                                                               # NotApplicableError
    uses: ClassVar[tuple[str, ...]] = ("training walks",)     # taken when the site has
                                                               # them, defaults otherwise

Both describe the class's default options (an option may switch a source off).
A class without them is listed as "not declared".
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from importlib.metadata import entry_points
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from indoorsim.io.fingerprints import FingerprintDB
from indoorsim.io.recording import Recording
from indoorsim.util.errors import UnknownNameError
from indoorsim.windows import PRESENT_ORDER, Observation

__all__ = [
    "ENTRY_POINT_GROUP",
    "NEEDS",
    "Estimator",
    "NotApplicableError",
    "Observation",
    "SiteContext",
    "StartInfo",
    "UnknownEstimatorError",
    "available",
    "estimator_class",
    "make",
    "not_reset_error",
    "present_streams",
    "register",
]

ENTRY_POINT_GROUP = "indoorsim.estimators"

NEEDS: dict[str, str] = {
    "grid survey": "a fingerprint database with a 'grid' table: Han2023's offline phase "
    "(indoorsim survey --kind grid)",
    "walk survey": "a fingerprint database with 'magnetic' and 'wifi' tables: Chen2022's "
    "offline phase (indoorsim survey --kind walk)",
    "WiFi": "WiFi scans in the walk and reference fingerprints of the site's APs in the survey",
    "training walks": "labelled walks of the site with truth and true steps (evaluate "
    "simulates them: --train-routes)",
    "floor plan": "the site's walls and walkable area (none for a real log)",
    "checkpoint": "a trained network folder (indoorsim train --out); the packaged one "
    "unless the checkpoint option names another",
}
"""The terms of an estimator class's optional ``needs`` and ``uses`` (module docstring)."""


@dataclass(frozen=True, kw_only=True)
class SiteContext:
    """Public knowledge of a site.

    Attributes:
        name: the scenario (or real site) name.
        plan: the floor plan, or ``None`` for real data without one. Offers
            ``crosses_wall(p0, p1)``, ``is_walkable(points)``, ``bounds`` and
            the ``walkable`` polygon.
        fingerprints: survey databases by survey name (``"grid"``, ``"walk"``).
        bssids: the APs, in the order of the observations' WiFi vectors.
        building_north_deg: the building's +y axis, degrees clockwise from true north.
        magnetic_declination_deg: magnetic north, degrees clockwise (east) of true north.
        device: the walking phone's model name.
        imu_rate_hz: the walking phone's nominal IMU rate.
        window_samples: IMU samples per observation window.
        extra: anything else a site provides (documented where it is filled in).
    """

    name: str
    plan: Any = None
    fingerprints: dict[str, FingerprintDB] = field(default_factory=dict)
    bssids: tuple[str, ...] = ()
    building_north_deg: float = 0.0
    magnetic_declination_deg: float = 0.0
    device: str = ""
    imu_rate_hz: float = 50.0
    window_samples: int = 50
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def magnetic_to_building_rad(self) -> float:
        """Add to a heading measured from magnetic east (Android's rotation-vector
        frame, counter-clockwise) to get it from the building's +x axis."""
        return math.radians(self.building_north_deg - self.magnetic_declination_deg)


@dataclass(frozen=True, kw_only=True)
class StartInfo:
    """What an episode reveals at its start, as in the papers' experiments.

    Attributes:
        position: (2,) start position in the building frame, m.
        heading: initial walking direction, rad counter-clockwise from the building's +x.
        seed: the episode's seed, for estimators that sample (particle filters).
        t0: time of the first observation sample, s.
    """

    position: NDArray[np.float64]
    heading: float
    seed: int = 0
    t0: float = 0.0


@runtime_checkable
class Estimator(Protocol):
    """The protocol every estimator satisfies (see the module docstring)."""

    name: str

    def fit(self, site: SiteContext, train: Sequence[Recording]) -> None: ...

    def reset(self, start: StartInfo) -> None: ...

    def act(self, obs: Observation) -> NDArray[np.float64]: ...


class NotApplicableError(ValueError):
    """Raised by ``fit`` when a site lacks what the estimator needs (e.g. a grid survey).

    The leaderboard records such an estimator as not applicable on that site,
    with the message, instead of failing the run.
    """


def present_streams(obs: Observation) -> dict[str, bool]:
    """Which optional streams the window's recording has (``obs["present"]`` by name)."""
    return {name: bool(flag) for name, flag in zip(PRESENT_ORDER, obs["present"], strict=True)}


def not_reset_error(name: str) -> RuntimeError:
    """The error an estimator raises when ``act`` comes before ``reset``."""
    return RuntimeError(f"{name}: call reset(start) before act(obs)")


class UnknownEstimatorError(UnknownNameError):
    """An estimator name that is neither registered, an entry point, nor ``module:Class``.

    A ``module:Class`` whose import fails is one too; its message then gives
    the import's error (``reason``) instead of the registered names.
    """

    kind = "estimator"

    def __init__(self, name: str, valid: Sequence[str] = (), where: str = "", reason: str = ""):
        self.reason = reason
        super().__init__(name, valid, where)

    @property
    def message(self) -> str:
        if self.reason:
            return f"cannot load estimator {self.name!r}: {self.reason}"
        return super().message

    def __reduce__(self) -> tuple[type, tuple[str, tuple[str, ...], str, str]]:
        return type(self), (self.name, self.valid, self.where, self.reason)


_REGISTRY: dict[str, Callable[..., Estimator]] = {}


def register(name: str) -> Callable[[type], type]:
    """Class decorator: make the estimator constructible as ``make(name)``."""

    def deco(cls: type) -> type:
        if name in _REGISTRY and _REGISTRY[name] is not cls:
            raise ValueError(f"estimator name {name!r} is already registered to {_REGISTRY[name]}")
        _REGISTRY[name] = cls
        return cls

    return deco


def available() -> list[str]:
    """Names of the registered and entry-point estimators."""
    _load_builtins()
    names = set(_REGISTRY) | {ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)}
    return sorted(names)


def estimator_class(spec: str) -> Callable[..., Estimator]:
    """What :func:`make` calls for ``spec``: the registered class, the entry point's
    target, or the ``module:Class`` — to read its options, docstring or ``needs``.

    Raises:
        UnknownEstimatorError: listing the names that exist.
    """
    _load_builtins()
    if spec in _REGISTRY:
        return _REGISTRY[spec]
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name == spec:
            return ep.load()
    if ":" in spec:
        module, _, attr = spec.partition(":")
        try:
            return getattr(importlib.import_module(module), attr)
        except (ImportError, AttributeError) as err:
            raise UnknownEstimatorError(spec, reason=str(err)) from None
    raise UnknownEstimatorError(spec, [*available(), "or any 'package.module:Class'"])


def make(spec: str, **kwargs: Any) -> Estimator:
    """Build an estimator from a registered name, an entry-point name, or ``module:Class``.

    Raises:
        UnknownEstimatorError: listing the names that exist.
    """
    return estimator_class(spec)(**kwargs)


def _load_builtins() -> None:
    # Importing the pipelines registers them; done lazily to keep `import` light.
    importlib.import_module("indoorsim.estimators.baselines")
    importlib.import_module("indoorsim.estimators.pipelines.han2023")
    importlib.import_module("indoorsim.estimators.pipelines.chen2022")
    importlib.import_module("indoorsim.estimators.pipelines.chen2022_cited")
    importlib.import_module("indoorsim.estimators.pipelines.learned_io")
