"""Carrying modes by name: the :class:`CarryMode` protocol and its registry.

A carrying mode turns the body's motion into the phone's pose
(:mod:`indoorsim.walker.carry_modes` holds the built-in ones: ``handheld``,
``calling``, ``dangling``, ``pocketed``). Modes are components: frozen
dataclasses whose fields are their parameters, registered by name in
:data:`MODES` with :func:`register_mode`. Other packages add modes through the
``indoorsim.modes`` entry-point group (each entry point loads a
:class:`CarryMode` subclass); :func:`get_mode` finds either kind and raises
:class:`UnknownModeError`, listing the valid names, when it cannot.

The protocol sits apart from the built-in modes so that a schedule of modes
(:mod:`indoorsim.walker.schedule`) can be checked against the registry
without a circle through :func:`~indoorsim.walker.carry.carry`, which follows
such a schedule.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from importlib.metadata import entry_points
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from indoorsim.util.errors import UnknownNameError
from indoorsim.walker.gait import BodyTrajectory
from indoorsim.walker.handling import PocketStroke

__all__ = [
    "ENTRY_POINT_GROUP",
    "MODES",
    "CarryMode",
    "ModePose",
    "UnknownModeError",
    "available_modes",
    "get_mode",
    "mode_fields",
    "register_mode",
]

ENTRY_POINT_GROUP = "indoorsim.modes"
"""Entry-point group through which other packages add carrying modes."""

_BUILT_IN = "indoorsim.walker.carry_modes"
"""The module whose import registers the built-in modes."""


@dataclass(frozen=True, kw_only=True, eq=False)
class ModePose:
    """One mode's phone pose over a stretch of samples.

    Attributes:
        pos: (K, 3) position, building frame.
        rot: K world←phone rotations.
        light_exposure: (K,) in [0, 1].
        stroke: how the phone slides into the place that holds it, for a mode that
            holds it in a pocket (:mod:`~indoorsim.walker.handling`); None for a hand
            or an ear, which the phone is simply brought to.
    """

    pos: NDArray[np.float64]
    rot: Rotation
    light_exposure: NDArray[np.float64]
    stroke: PocketStroke | None = None


class CarryMode(ABC):
    """A way of carrying the phone. Subclasses are ``@dataclass(kw_only=True, frozen=True)``
    components whose fields are the mode's parameters, with working defaults.
    """

    name: ClassVar[str]
    casts_body_shadow: ClassVar[bool] = True
    """Whether the carrier's head and trunk shadow the light sensor geometrically
    (:mod:`indoorsim.walker.silhouette`). False where the phone touches the body
    and the mode's ``light_exposure`` stands for it instead (at the ear, in a pocket)."""

    def __post_init__(self) -> None:
        """Reject parameters no body has: a frequency or damping ratio that is not
        positive, a range drawn from whose ends are out of order or not finite."""
        bad = []
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            ends = value if isinstance(value, tuple) else (value,)
            if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in ends):
                continue
            ok = all(math.isfinite(v) for v in ends) and (len(ends) != 2 or ends[0] <= ends[1])
            if f.name.endswith("_hz") or "damping" in f.name:
                ok = ok and min(ends) > 0
            if not ok:
                bad.append(f"{f.name}={value!r}")
        if bad:
            raise ValueError(f"{type(self).__name__} parameters out of range: {', '.join(bad)}")

    @abstractmethod
    def pose(self, body: BodyTrajectory, rng: np.random.Generator) -> ModePose:
        """The phone's pose while the body moves as ``body`` (any stretch of a walk).

        Args:
            body: the body trajectory, possibly a window of a longer one.
            rng: randomness for this use of the mode (placement, amplitudes).
        """


class UnknownModeError(UnknownNameError, KeyError, ValueError):
    """A carrying-mode name that is neither built in, registered, nor an entry point.

    A ``KeyError`` as :func:`get_mode` raised before, and a ``ValueError`` as
    the environment and the evaluation raised for a bad ``mode`` argument.
    """

    kind = "carrying mode"


MODES: dict[str, type[CarryMode]] = {}
"""Built-in and registered carrying modes by name."""


def register_mode(cls: type[CarryMode]) -> type[CarryMode]:
    """Class decorator: add a :class:`CarryMode` subclass to :data:`MODES` under ``cls.name``."""
    if not (isinstance(cls, type) and issubclass(cls, CarryMode)):
        raise TypeError(f"{cls!r} is not a CarryMode subclass")
    if MODES.get(cls.name, cls) is not cls:
        raise ValueError(f"a different carrying mode is already registered as {cls.name!r}")
    MODES[cls.name] = cls
    return cls


def _load_plugins() -> None:
    # The built-in modes first, so that an entry point cannot take one of their names.
    # Their module is imported by name: it imports this registry to register them.
    importlib.import_module(_BUILT_IN)
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name not in MODES:
            cls = ep.load()
            if not (isinstance(cls, type) and issubclass(cls, CarryMode)):
                raise TypeError(
                    f"entry point {ep.name!r} in {ENTRY_POINT_GROUP!r} loads {cls!r}, "
                    "not a CarryMode subclass"
                )
            MODES[ep.name] = cls


def available_modes() -> list[str]:
    """Names of every carrying mode: built in, registered, or from entry points."""
    _load_plugins()
    return sorted(MODES)


def get_mode(name: str) -> type[CarryMode]:
    """The carrying-mode class registered as ``name``.

    Raises:
        UnknownModeError: for an unknown name (a ``KeyError``); it lists the valid ones.
    """
    if name not in MODES:
        _load_plugins()
    if name not in MODES:
        raise UnknownModeError(name, sorted(MODES))
    return MODES[name]


def mode_fields(name: str) -> set[str]:
    """The parameters of the carrying mode called ``name`` (its dataclass fields).

    Raises:
        UnknownModeError: for an unknown name.
    """
    cls = get_mode(name)
    return {f.name for f in dataclasses.fields(cls)} if dataclasses.is_dataclass(cls) else set()
