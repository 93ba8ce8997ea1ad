"""Sensor faults: composable, seeded transforms of a :class:`~indoorsim.io.recording.Recording`.

A fault stands for something real phones do — drop samples, freeze a stream,
jump a bias, saturate, stamp time irregularly, lose WiFi, walk past a lift —
applied to a recording after it was made. Every fault is a small frozen
dataclass with a ``name`` and its parameters; ``fault.apply(recording, rng)``
returns a NEW recording (the input's frames and meta are never touched) and
appends ``{"name": ..., "params": ...}`` to its ``meta["faults"]``. The same
fault, recording and seed give the same bytes. Faults act on sensor streams
only; ``truth``, ``steps`` and ``waypoints`` are what scoring needs and are
refused as targets.

They live in ``io`` because they are recording → recording transforms with no
dependence on the simulator, usable on real logs as on simulated walks.

A faulty recording may break what :meth:`Recording.validate` asks of a clean
one (NaN values are the point of ``nan_burst``), so it is built without
validation; its ``t`` index stays non-decreasing.

Two faults change the walk rather than its recording, because what they
stand for happens while walking: ``mode_change`` (the phone goes into another
carrying mode that nobody tells the estimator about) and ``wrong_device``
(the walk is recorded by another phone than the one declared, whose profile
the estimator's training walks and windows were made for). They are
:class:`WalkFault`; :func:`walk_arguments` gives the carrying schedule and
device to simulate the faulty walk with, and their ``apply`` only records
them in ``meta["faults"]``.

Spec strings (``indoorsim evaluate --fault``)::

    NAME[:key=value,key=value,...]

Numbers are read as floats; stream names as strings; a list (several streams,
a 3-vector) separates its items with ``/`` or ``;`` because ``,`` separates
parameters: ``bias_jump:stream=accel,t0=5,vector=0.3/0/0``,
``dropout:streams=accel/gyro,p=0.2``. :func:`parse_fault` reads one,
:data:`FAULTS` lists them all.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from indoorsim.io.recording import Recording
from indoorsim.phone.devices import get_device
from indoorsim.util import quaternion
from indoorsim.walker.schedule import ModeSchedule, ScheduleEntry, ScheduleLike

__all__ = [
    "FAULTS",
    "Fault",
    "FaultError",
    "WalkFault",
    "apply_faults",
    "fault_rng",
    "parse_fault",
    "walk_arguments",
]

# Streams a fault may not touch: the truth scoring needs.
_NOT_SENSORS = frozenset({"truth", "steps", "waypoints"})
_XYZ = ["x", "y", "z"]


class FaultError(ValueError):
    """A fault spec or parameter that is not valid; the message names the fault and parameter."""


Streams = dict[str, pd.DataFrame]


@dataclass(frozen=True)
class Fault(ABC):
    """A named, parameterised transform of a recording's sensor streams.

    Subclasses are dataclasses whose fields are the parameters (float, str,
    or tuples of them); ``__post_init__`` validates them with :class:`FaultError`.
    """

    name: ClassVar[str]
    doc: ClassVar[str]

    def params(self) -> dict[str, Any]:
        """The parameters as JSON-able values (tuples as lists)."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            out[f.name] = list(v) if isinstance(v, tuple) else v
        return out

    def spec(self) -> str:
        """The canonical spec string, which :func:`parse_fault` reads back to an equal fault."""
        parts = []
        for k, v in self.params().items():
            if v is None:
                continue
            text = "/".join(_fmt(x) for x in v) if isinstance(v, list) else _fmt(v)
            parts.append(f"{k}={text}")
        return self.name + (":" + ",".join(parts) if parts else "")

    def apply(self, recording: Recording, rng: np.random.Generator) -> Recording:
        """A new recording with this fault applied; ``recording`` is left unchanged."""
        streams = {k: df.copy(deep=True) for k, df in recording.streams.items()}
        for s in self._targets():
            if s not in streams:
                raise FaultError(
                    f"fault {self.name}: the recording has no {s!r} stream "
                    f"(streams present: {', '.join(sorted(streams)) or 'none'})"
                )
        self._transform(streams, rng)
        meta = copy.deepcopy(recording.meta)
        meta["faults"] = [*meta.get("faults", []), {"name": self.name, "params": self.params()}]
        return Recording._from_built(streams, meta)

    def _targets(self) -> tuple[str, ...]:
        v = getattr(self, "streams", None) or (getattr(self, "stream", None),)
        return tuple(s for s in v if s)

    def _fail(self, param: str, why: str) -> FaultError:
        return FaultError(f"fault {self.name}: {param} {why}")

    def _check_sensor(self, param: str, names: Sequence[str]) -> None:
        if not names:
            raise self._fail(param, "names no stream")
        for s in names:
            if s in _NOT_SENSORS:
                raise self._fail(param, f"= {s!r}: not a sensor stream (truth is never faulted)")

    def _check_window(self, t0: float, t1: float) -> None:
        if not (math.isfinite(t0) and math.isfinite(t1)):
            raise self._fail("t0/t1", f"must be finite, got {t0}, {t1}")
        if t1 < t0:
            raise self._fail("t1", f"= {t1} is before t0 = {t0}")

    def _check_vector(self, param: str, v: tuple[float, ...]) -> None:
        if len(v) != 3 or not all(math.isfinite(x) for x in v):
            raise self._fail(param, f"must be 3 finite numbers x/y/z, got {list(v)}")

    @abstractmethod
    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        """Change ``streams`` (already copies) in place."""


def _fmt(v: Any) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _xyz(fault: Fault, name: str, df: pd.DataFrame) -> list[str]:
    if not set(_XYZ) <= set(df.columns):
        raise FaultError(f"fault {fault.name}: stream {name!r} has no x, y, z columns")
    return _XYZ


def _values(name: str, df: pd.DataFrame) -> list[str]:
    """The columns holding a stream's measured values (numeric, not text)."""
    if name == "wifi":
        return ["rss"]
    return [c for c in df.columns if pd.api.types.is_numeric_dtype(df[c])]


def _in(df: pd.DataFrame, t0: float, t1: float) -> np.ndarray:
    t = df.index.to_numpy()
    return (t >= t0) & (t <= t1)


# ---------------------------------------------------------------------------- faults


@dataclass(frozen=True)
class Dropout(Fault):
    name: ClassVar[str] = "dropout"
    doc: ClassVar[str] = "each sample of the streams is lost with probability p (random)"
    streams: tuple[str, ...] = ("accel", "gyro", "mag")
    p: float = 0.1

    def __post_init__(self) -> None:
        self._check_sensor("streams", self.streams)
        if not 0.0 <= self.p <= 1.0:
            raise self._fail("p", f"= {self.p} is not a probability in [0, 1]")

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        for s in self.streams:
            df = streams[s]
            if s == "wifi":  # a scan is lost whole
                u, inv = np.unique(df.index.to_numpy(), return_inverse=True)
                keep = (rng.random(len(u)) >= self.p)[inv]
            else:
                keep = rng.random(len(df)) >= self.p
            streams[s] = df[keep]


@dataclass(frozen=True)
class Gap(Fault):
    name: ClassVar[str] = "gap"
    doc: ClassVar[str] = "every sample of the streams in [t0, t1] is lost (a sensor pause)"
    t0: float
    t1: float
    streams: tuple[str, ...] = ("accel", "gyro", "mag")

    def __post_init__(self) -> None:
        self._check_sensor("streams", self.streams)
        self._check_window(self.t0, self.t1)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        for s in self.streams:
            streams[s] = streams[s][~_in(streams[s], self.t0, self.t1)]


@dataclass(frozen=True)
class NanBurst(Fault):
    name: ClassVar[str] = "nan_burst"
    doc: ClassVar[str] = "the stream's values are NaN over [t0, t1] (a driver reporting garbage)"
    stream: str
    t0: float
    t1: float

    def __post_init__(self) -> None:
        self._check_sensor("stream", (self.stream,))
        self._check_window(self.t0, self.t1)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams[self.stream]
        df.loc[_in(df, self.t0, self.t1), _values(self.stream, df)] = np.nan


@dataclass(frozen=True)
class Stuck(Fault):
    name: ClassVar[str] = "stuck"
    doc: ClassVar[str] = (
        "the stream repeats its last value at or before t0 over [t0, t1] (a frozen driver)"
    )
    stream: str
    t0: float
    t1: float

    def __post_init__(self) -> None:
        self._check_sensor("stream", (self.stream,))
        if self.stream == "wifi":
            raise self._fail("stream", "= 'wifi': use wifi_outage or scan_throttle")
        self._check_window(self.t0, self.t1)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams[self.stream]
        if not len(df):
            return
        t = df.index.to_numpy()
        k = max(int(np.searchsorted(t, self.t0, side="right")) - 1, 0)
        cols = _values(self.stream, df)
        df.loc[_in(df, self.t0, self.t1), cols] = df[cols].iloc[k].to_numpy()


@dataclass(frozen=True)
class BiasJump(Fault):
    name: ClassVar[str] = "bias_jump"
    doc: ClassVar[str] = "a constant vector is added to the stream from t0 on (a bias step)"
    stream: str
    t0: float
    vector: tuple[float, ...]

    def __post_init__(self) -> None:
        self._check_sensor("stream", (self.stream,))
        self._check_vector("vector", self.vector)
        if not math.isfinite(self.t0):
            raise self._fail("t0", f"must be finite, got {self.t0}")

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams[self.stream]
        cols = _xyz(self, self.stream, df)
        after = df.index.to_numpy() >= self.t0
        df.loc[after, cols] = df.loc[after, cols].to_numpy() + np.asarray(self.vector)


@dataclass(frozen=True)
class BiasDrift(Fault):
    name: ClassVar[str] = "bias_drift"
    doc: ClassVar[str] = "a bias growing linearly from t0, rate per second (thermal drift)"
    stream: str
    rate: tuple[float, ...]
    t0: float = 0.0

    def __post_init__(self) -> None:
        self._check_sensor("stream", (self.stream,))
        self._check_vector("rate", self.rate)
        if not math.isfinite(self.t0):
            raise self._fail("t0", f"must be finite, got {self.t0}")

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams[self.stream]
        cols = _xyz(self, self.stream, df)
        dt = np.clip(df.index.to_numpy() - self.t0, 0.0, None)
        df[cols] = df[cols].to_numpy() + dt[:, None] * np.asarray(self.rate)


@dataclass(frozen=True)
class Saturation(Fault):
    name: ClassVar[str] = "saturation"
    doc: ClassVar[str] = "each component is clipped at ± full_scale (a sensor range too small)"
    stream: str
    full_scale: float

    def __post_init__(self) -> None:
        self._check_sensor("stream", (self.stream,))
        if not (math.isfinite(self.full_scale) and self.full_scale > 0):
            raise self._fail("full_scale", f"must be a positive number, got {self.full_scale}")

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams[self.stream]
        cols = _xyz(self, self.stream, df)
        df[cols] = np.clip(df[cols].to_numpy(), -self.full_scale, self.full_scale)


@dataclass(frozen=True)
class Scale(Fault):
    name: ClassVar[str] = "scale"
    doc: ClassVar[str] = "the stream's values are multiplied by factor (a scale-factor error)"
    stream: str
    factor: float

    def __post_init__(self) -> None:
        self._check_sensor("stream", (self.stream,))
        if self.stream == "wifi":
            raise self._fail("stream", "= 'wifi': RSS in dBm has no scale factor")
        if not math.isfinite(self.factor):
            raise self._fail("factor", f"must be finite, got {self.factor}")

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams[self.stream]
        cols = _values(self.stream, df)
        df[cols] = df[cols].to_numpy() * self.factor


@dataclass(frozen=True)
class Jitter(Fault):
    name: ClassVar[str] = "jitter"
    doc: ClassVar[str] = (
        "Gaussian noise of sigma s on the stream's timestamps, re-sorted so samples keep "
        "their order (irregular stamping)"
    )
    stream: str
    sigma: float

    def __post_init__(self) -> None:
        self._check_sensor("stream", (self.stream,))
        if not (math.isfinite(self.sigma) and self.sigma >= 0):
            raise self._fail("sigma", f"must be a non-negative number, got {self.sigma}")

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams[self.stream]
        # Per distinct time, so the rows of one WiFi scan keep one time.
        u, inv = np.unique(df.index.to_numpy(), return_inverse=True)
        noisy = np.sort(u + rng.normal(0.0, self.sigma, len(u)))
        df.index = pd.Index(noisy[inv].astype(np.float64), name="t")


@dataclass(frozen=True)
class ClockStep(Fault):
    name: ClassVar[str] = "clock_step"
    doc: ClassVar[str] = (
        "timestamps at or after t0 shift by delta s (a clock correction); samples are "
        "re-sorted by time when delta < 0"
    )
    stream: str
    t0: float
    delta: float

    def __post_init__(self) -> None:
        self._check_sensor("stream", (self.stream,))
        if not (math.isfinite(self.t0) and math.isfinite(self.delta)):
            raise self._fail("t0/delta", f"must be finite, got {self.t0}, {self.delta}")

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams[self.stream]
        t = df.index.to_numpy()
        df.index = pd.Index(np.where(t >= self.t0, t + self.delta, t), name="t")
        streams[self.stream] = df.sort_index(kind="stable")


@dataclass(frozen=True)
class Missing(Fault):
    name: ClassVar[str] = "missing"
    doc: ClassVar[str] = "the streams are absent from the start (a phone without the sensor)"
    streams: tuple[str, ...]

    def __post_init__(self) -> None:
        self._check_sensor("streams", self.streams)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        for s in self.streams:
            del streams[s]


@dataclass(frozen=True)
class WifiOutage(Fault):
    name: ClassVar[str] = "wifi_outage"
    doc: ClassVar[str] = "no WiFi scans in [t0, t1] (radio off, an access point outage)"
    t0: float
    t1: float

    def __post_init__(self) -> None:
        self._check_window(self.t0, self.t1)

    def _targets(self) -> tuple[str, ...]:
        return ("wifi",)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        streams["wifi"] = streams["wifi"][~_in(streams["wifi"], self.t0, self.t1)]


@dataclass(frozen=True)
class ScanThrottle(Fault):
    name: ClassVar[str] = "scan_throttle"
    doc: ClassVar[str] = (
        "at most one WiFi scan every period s is kept (Android's scan throttling: 4 per 2 min)"
    )
    period: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.period) and self.period > 0):
            raise self._fail("period", f"must be a positive number, got {self.period}")

    def _targets(self) -> tuple[str, ...]:
        return ("wifi",)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams["wifi"]
        kept: list[float] = []
        for t in np.unique(df.index.to_numpy()):
            if not kept or t - kept[-1] >= self.period:
                kept.append(float(t))
        streams["wifi"] = df[np.isin(df.index.to_numpy(), kept)]


@dataclass(frozen=True)
class LightsOff(Fault):
    name: ClassVar[str] = "lights_off"
    doc: ClassVar[str] = "the light sensor reads a dark level (lux) over [t0, t1] (lights off)"
    t0: float
    t1: float
    lux: float = 1.0

    def __post_init__(self) -> None:
        self._check_window(self.t0, self.t1)
        if not (math.isfinite(self.lux) and self.lux >= 0):
            raise self._fail("lux", f"must be a non-negative number, got {self.lux}")

    def _targets(self) -> tuple[str, ...]:
        return ("light",)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams["light"]
        df.loc[_in(df, self.t0, self.t1), "lux"] = self.lux


@dataclass(frozen=True)
class MagneticDisturbance(Fault):
    name: ClassVar[str] = "magnetic_disturbance"
    doc: ClassVar[str] = (
        "a transient field bump of amplitude µT, Gaussian in time (centre t0, width sigma s), "
        "along direction (random when not given) in frame 'world' (east, north, up: a lift "
        "or a passing trolley, fixed in the building while the phone turns; the phone's "
        "own rotation vector takes it into the phone frame) or 'phone'"
    )
    t0: float
    amplitude: float = 50.0
    sigma: float = 1.0
    direction: tuple[float, ...] | None = None
    frame: str = "world"

    def __post_init__(self) -> None:
        if not math.isfinite(self.t0):
            raise self._fail("t0", f"must be finite, got {self.t0}")
        if not math.isfinite(self.amplitude):
            raise self._fail("amplitude", f"must be finite, got {self.amplitude}")
        if not (math.isfinite(self.sigma) and self.sigma > 0):
            raise self._fail("sigma", f"must be a positive number, got {self.sigma}")
        if self.direction is not None:
            self._check_vector("direction", self.direction)
            if not any(self.direction):
                raise self._fail("direction", "must not be the zero vector")
        if self.frame not in ("world", "phone"):
            raise self._fail("frame", f"= {self.frame!r}: must be 'world' or 'phone'")

    def _targets(self) -> tuple[str, ...]:
        return ("mag", "rotation") if self.frame == "world" else ("mag",)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        d = np.asarray(self.direction) if self.direction is not None else rng.normal(size=3)
        d = d / np.linalg.norm(d)
        df = streams["mag"]
        t = df.index.to_numpy()
        bump = self.amplitude * np.exp(-0.5 * ((t - self.t0) / self.sigma) ** 2)
        if self.frame == "world":
            # The rotation vector is world ← phone: its inverse takes the building's
            # vector into the phone frame, held from the latest fused sample.
            rot = streams["rotation"]
            k = np.searchsorted(rot.index.to_numpy(), t, side="right") - 1
            q = rot[["qw", "qx", "qy", "qz"]].to_numpy(dtype=float)[np.clip(k, 0, len(rot) - 1)]
            d = quaternion.rotate(q, np.broadcast_to(d, (len(t), 3)), inverse=True)
        df[_XYZ] = df[_XYZ].to_numpy() + bump[:, None] * d


@dataclass(frozen=True)
class CaseMagnet(Fault):
    name: ClassVar[str] = "case_magnet"
    doc: ClassVar[str] = (
        "a constant hard-iron offset (µT, phone frame) on the magnetometer: a magnet in the "
        "phone's case"
    )
    offset: tuple[float, ...]

    def __post_init__(self) -> None:
        self._check_vector("offset", self.offset)

    def _targets(self) -> tuple[str, ...]:
        return ("mag",)

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        df = streams["mag"]
        df[_XYZ] = df[_XYZ].to_numpy() + np.asarray(self.offset)


class WalkFault(Fault):
    """A fault in how the walk is made: the simulator walks with other arguments.

    Its recording transform is the identity (``apply`` only records the
    fault); :meth:`walk` changes the carrying schedule or the device that
    :func:`walk_arguments` passes on to the simulator.
    """

    def _targets(self) -> tuple[str, ...]:
        return ()

    def _transform(self, streams: Streams, rng: np.random.Generator) -> None:
        return None

    @abstractmethod
    def walk(self, schedule: ModeSchedule, device: str) -> tuple[ModeSchedule, str]:
        """The schedule and device the faulty walk is simulated with."""


@dataclass(frozen=True)
class ModeChange(WalkFault):
    name: ClassVar[str] = "mode_change"
    doc: ClassVar[str] = (
        "from t0 on the phone is carried in another mode, and the estimator is not told "
        "(put into a pocket mid-walk)"
    )
    t0: float
    mode: str

    def __post_init__(self) -> None:
        if not (math.isfinite(self.t0) and self.t0 > 0):
            raise self._fail("t0", f"must be a positive number of seconds, got {self.t0}")
        try:
            ModeSchedule.of(self.mode)
        except (ValueError, LookupError) as err:
            raise self._fail("mode", f"= {self.mode!r}: {err}") from None

    def walk(self, schedule: ModeSchedule, device: str) -> tuple[ModeSchedule, str]:
        kept = [e for e in schedule.entries if e.t_start_s < self.t0]
        if kept[-1].mode == self.mode:
            raise self._fail(
                "mode",
                f"= {self.mode!r} is the mode already carried at t0 = {self.t0:g} s: no change",
            )
        return ModeSchedule((*kept, ScheduleEntry(self.t0, self.mode, {}))), device


@dataclass(frozen=True)
class WrongDevice(WalkFault):
    name: ClassVar[str] = "wrong_device"
    doc: ClassVar[str] = (
        "the walk is recorded by device, not the phone declared to the estimator "
        "(its training walks, windows and noise model are the declared phone's)"
    )
    device: str

    def __post_init__(self) -> None:
        try:
            get_device(self.device)
        except LookupError as err:
            raise self._fail("device", f"= {self.device!r}: {err}") from None

    def walk(self, schedule: ModeSchedule, device: str) -> tuple[ModeSchedule, str]:
        if device == self.device:
            raise self._fail("device", f"= {self.device!r} is the declared device: no fault")
        return schedule, self.device


FAULTS: dict[str, type[Fault]] = {
    cls.name: cls
    for cls in (
        Dropout,
        Gap,
        NanBurst,
        Stuck,
        BiasJump,
        BiasDrift,
        Saturation,
        Scale,
        Jitter,
        ClockStep,
        Missing,
        WifiOutage,
        ScanThrottle,
        LightsOff,
        MagneticDisturbance,
        CaseMagnet,
        ModeChange,
        WrongDevice,
    )
}
"""Every fault by name."""


# ---------------------------------------------------------------------------- specs


def _convert(fault: str, key: str, kind: str, text: str) -> Any:
    def num(item: str) -> float:
        try:
            return float(item)
        except ValueError:
            raise FaultError(f"fault {fault}: {key}={text!r} is not a number") from None

    items = [x.strip() for x in text.replace(";", "/").split("/")]
    if kind.startswith("tuple[float"):
        return tuple(num(x) for x in items)
    if kind.startswith("tuple[str"):
        return tuple(x for x in items if x)
    if kind == "float":
        return num(text)
    return text.strip()


def parse_fault(spec: str) -> Fault:
    """The fault a ``NAME[:key=value,...]`` string describes (module docstring: the syntax).

    Raises:
        FaultError: an unknown fault (listing the known ones), an unknown or
            missing parameter (listing the fault's parameters), or a bad value.
    """
    name, _, rest = spec.strip().partition(":")
    name = name.strip()
    if name not in FAULTS:
        raise FaultError(f"unknown fault {name!r}; known faults: {', '.join(FAULTS)}")
    cls = FAULTS[name]
    fields = {f.name: f for f in dataclasses.fields(cls)}
    known = ", ".join(fields)
    kwargs: dict[str, Any] = {}
    for part in filter(None, (p.strip() for p in rest.split(","))):
        key, eq, value = part.partition("=")
        key = key.strip()
        if not eq:
            raise FaultError(f"fault {name}: {part!r} is not key=value (parameters: {known})")
        if key not in fields:
            raise FaultError(f"fault {name}: unknown parameter {key!r} (parameters: {known})")
        kwargs[key] = _convert(name, key, str(fields[key].type), value)
    missing = [
        k
        for k, f in fields.items()
        if k not in kwargs
        and f.default is dataclasses.MISSING
        and f.default_factory is dataclasses.MISSING
    ]
    if missing:
        raise FaultError(
            f"fault {name}: missing parameter {', '.join(missing)} (parameters: {known})"
        )
    return cls(**kwargs)


def fault_rng(seed: int, index: int) -> np.random.Generator:
    """The generator of the ``index``-th fault (from 0) applied to the walk of ``seed``."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(index)]))


def walk_arguments(
    faults: Sequence[Fault], mode: ScheduleLike, device: str
) -> tuple[ModeSchedule, str]:
    """The carrying schedule and device to simulate a walk with under ``faults``.

    The declared ``mode`` and ``device`` unless a :class:`WalkFault` changes
    them (in order); the estimator is still told the declared ones.
    """
    schedule = ModeSchedule.of(mode)
    for fault in faults:
        if isinstance(fault, WalkFault):
            schedule, device = fault.walk(schedule, device)
    return schedule, device


def apply_faults(recording: Recording, faults: Sequence[Fault], seed: int) -> Recording:
    """``recording`` with ``faults`` in order; fault ``i`` draws from ``fault_rng(seed, i)``."""
    for i, fault in enumerate(faults):
        recording = fault.apply(recording, fault_rng(seed, i))
    return recording
