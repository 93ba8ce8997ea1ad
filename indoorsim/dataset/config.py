"""The data set's configuration: one strict pydantic model, resolved to explicit values.

Everything that decides the bytes of a data set is here; how it is run (the
number of workers, a scheduler address, progress output) is not, so the same
:class:`DatasetConfig` gives the same shards however it is run. A resolved
configuration (every default written out, ``bundled`` expanded to the names it
stands for) is stored in the output folder before any work starts and in the
dataset card at the end; a run that resumes must resolve to an equal one.

A configuration file is YAML (or JSON) with the keys of :class:`DatasetConfig`;
unknown keys are rejected and every error names the file and the key path.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Annotated, Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from indoorsim.scenario.schema import key_path
from indoorsim.util.errors import UnknownNameError

__all__ = ["DatasetConfig", "DatasetConfigError", "Range", "WalkerRanges", "load_config"]

# Generated kinds that make sense for long walks (every kind of scenario/generate/).
DEFAULT_KINDS = ("office", "basement", "l_corridor", "u_corridor", "open_hall")
DEFAULT_MODES = ("handheld", "calling", "dangling", "pocketed")
# Every built-in phone but ``ideal``: a training set should carry sensor errors.
DEFAULT_DEVICES = ("vivo_s9", "nexus_5x", "honor_50", "low_grade", "mid_grade", "high_grade")


class DatasetConfigError(ValueError):
    """A configuration that cannot be used: every problem with its key path.

    Attributes:
        source: the file (or ``--option``) the values came from.
        problems: ``(key_path, message)`` pairs.
    """

    def __init__(self, source: str, problems: list[tuple[str, str]]):
        self.source = source
        self.problems = problems
        lines = [
            f"{source}: {path}: {msg}" if path else f"{source}: {msg}" for path, msg in problems
        ]
        head = f"invalid dataset configuration ({len(lines)} problems):"
        super().__init__("\n".join([head, *lines]) if len(lines) > 1 else lines[0])


class _Strict(BaseModel):
    """Unknown keys rejected, no NaN or infinity, immutable."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)


FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]


class Range(_Strict):
    """A closed interval ``[low, high]`` drawn from uniformly."""

    low: FiniteFloat
    high: FiniteFloat

    @model_validator(mode="after")
    def _ordered(self) -> Range:
        if self.low > self.high:
            raise ValueError(f"low ({self.low}) must not exceed high ({self.high})")
        return self


class WalkerRanges(_Strict):
    """Ranges of the pedestrian parameters (REALISM §5), one draw per walk.

    Every other :class:`~indoorsim.walker.gait.WalkerParams` field keeps its
    default (an ordinary adult's figures, themselves ranges drawn inside the gait),
    but for the vigour, which ``vigour`` takes from real walkers by default.
    """

    height_m: Range = Range(low=1.50, high=1.95)
    """Body height; 1.5–1.95 m covers most adults."""
    speed_mps: Range = Range(low=0.9, high=1.5)
    """Cruising speed: indoor walking 1.0–1.3 m/s, slow to brisk around it. A wider
    range (0.82–1.72 m/s, REALISM §5's slow to fast outdoor pace) was tried for
    ``learned-io``: it read fast walking better (the ILC traces' windows at 1.4–1.8 m/s
    at 0.89 of their speed, against 0.85) but every usual pace worse (its error on
    the bundled sites' held and calling walks rose by 0.3–0.4 m), so the range stays
    where indoor walking is. ``learned-io``'s data set takes 0.9–1.7 m/s: the ILC
    surveyors walk briskly between the marks where they slow, and since their twins
    slow there too (2026-12-08) its ensemble reads the twins better (2.19 m against
    2.22), at the same error on the bundled sites (2026-12-07, when the twins did not
    slow, it read them 0.05 m worse and was not kept)."""
    step_length_cv: Range = Range(low=0.03, high=0.05)
    step_time_cv: Range = Range(low=0.02, high=0.03)
    asymmetry: Range = Range(low=-0.03, high=0.03)
    stop_rate_per_min: Range = Range(low=0.0, high=0.5)
    """Mid-walk stops per minute of walking (Poisson)."""
    mark_speed: Range = Range(low=1.0, high=1.0)
    """Range of the slowest speed, as a fraction of the speed around it, at which a walk
    passes each inner point of its route (a corner of a shortest path, a goal), drawn
    per point inside the walk (:attr:`~indoorsim.walker.gait.WalkerParams.mark_speed`):
    no slowing by default. 0.2–1.0 was tried for ``learned-io`` (2026-12-08): its
    ensemble read the real traces' distance at 0.85 (the shipped one 0.88) and their
    twins', which slow at their marks, alike (0.95), at 0.05 m more error on the
    bundled sites, so it was not kept."""
    vigour: Literal["real", "default"] = "real"
    """``"real"``: each walk takes the vigour (bounce, loading peak, heel strikes) of
    one real walker, drawn from :mod:`indoorsim.walker.real_walkers`' table of
    calibrated real recordings; ``"default"``: every walk the ordinary adult's of
    :class:`~indoorsim.walker.gait.WalkerParams` (one bounce, the other two drawn
    inside the gait). A data set started before this setting existed was made with
    ``"default"``: resuming it needs ``walker: {vigour: default}``."""

    @model_validator(mode="after")
    def _realistic(self) -> WalkerRanges:
        # Bounds of WalkerParams, checked here so a bad range fails before any work.
        limits = {
            "height_m": (1.0, 2.3),
            "speed_mps": (0.2, 3.0),
            "step_length_cv": (0.0, 0.1),
            "step_time_cv": (0.0, 0.1),
            "asymmetry": (-0.49, 0.49),
            "stop_rate_per_min": (0.0, 60.0),
            "mark_speed": (0.05, 1.0),
        }
        for name, (lo, hi) in limits.items():
            r = getattr(self, name)
            if r.low < lo or r.high > hi:
                raise ValueError(f"{name} must lie within [{lo}, {hi}], got [{r.low}, {r.high}]")
        return self


class DatasetConfig(_Strict):
    """What a data set contains. Defaults give a small but complete mixed data set.

    The CLI options ``--sites``, ``--walks-per-site``, ``--minutes``, ``--seed``
    and ``--recordings`` set the keys of the same names (``walks_per_site``).
    """

    sites: Annotated[int, Field(ge=1, le=100_000)] = 8
    """Number of sites (buildings)."""
    walks_per_site: Annotated[int, Field(ge=1, le=10_000)] = 4
    """Walks simulated in each site, each on its own route, walker, modes and phone."""
    minutes: Annotated[float, Field(gt=0, le=240, allow_inf_nan=False)] = 5.0
    """Length of each walk in minutes; windows past it are not written."""
    seed: Annotated[int, Field(ge=0)] = 0
    """Seeds every random choice of the plan and every walk."""
    bundled: list[str] | None = None
    """Scenarios the sites may be drawn from: bundled scenario names, or scenario
    YAML files such as ``indoorsim import-plan`` writes for a real building (paths
    relative to the working directory); None: every bundled scenario."""
    bundled_share: Annotated[float, Field(ge=0, le=1)] = 0.25
    """Fraction of the sites taken from ``bundled`` (rounded; at most one site per
    scenario); the others are generated."""
    generated_kinds: list[str] = list(DEFAULT_KINDS)
    """Kinds of procedurally generated buildings, used in turn."""
    modes: Annotated[list[str], Field(min_length=1)] = list(DEFAULT_MODES)
    """Carrying modes a walk switches between."""
    mode_changes_per_minute: Annotated[float, Field(ge=0, le=6)] = 0.5
    """Mean rate of carrying-mode changes (Poisson; 0: one mode per walk)."""
    min_mode_s: Annotated[float, Field(ge=5, le=3600)] = 15.0
    """Shortest stretch in one carrying mode, s (a change itself takes 1.5 s)."""
    devices: Annotated[list[str], Field(min_length=1)] = list(DEFAULT_DEVICES)
    """Device profiles, one drawn per walk: names, or YAML files such as ``indoorsim
    calibrate`` writes (paths relative to the working directory)."""
    imu_rate_hz: Annotated[float, Field(ge=20, le=1000)] = 100.0
    """Accelerometer and gyroscope rate; every device's profile is set to it
    (magnetometer, light and WiFi keep the profile's own rates)."""
    window_samples: Annotated[int, Field(ge=8, le=100_000)] = 200
    """IMU samples per window (200 = 2 s at 100 Hz)."""
    stride_samples: Annotated[int, Field(ge=1, le=100_000)] | None = None
    """IMU samples between consecutive window starts; None: ``window_samples``."""
    walker: WalkerRanges = WalkerRanges()
    mode_params: dict[str, dict[str, Range | bool | FiniteFloat | str]] = {
        "handheld": {"pitch_deg": Range(low=0.0, high=45.0)}
    }
    """Carrying-mode parameters per mode, for every stretch of that mode: a value
    fixes the parameter, a range is drawn from per stretch. The rest keep the
    mode's own defaults, which draw per use (grip, joints, pocket side...). The
    default draws the held phone's screen tilt from flat (as in Han2023) to
    texting (REALISM §6.1)."""
    walks_per_shard: Annotated[int, Field(ge=1, le=10_000)] = 4
    """Walks per shard; a shard never mixes sites, so a site's last shard may hold fewer."""
    rows_per_row_group: Annotated[int, Field(ge=1, le=1_000_000)] = 256
    """Windows per Parquet row group (the unit the torch data set reads)."""
    compression: Annotated[str, Field(pattern="^(zstd|snappy|lz4|gzip|none)$")] = "zstd"
    recordings: bool = False
    """Also save every walk's whole Recording folder under ``recordings/``."""
    retries: Annotated[int, Field(ge=0, le=20)] = 2
    """How often a failed shard task is retried before it is reported."""

    @model_validator(mode="after")
    def _consistent(self) -> DatasetConfig:
        stride = self.stride_samples
        if stride is not None and stride > self.window_samples:
            raise ValueError(
                f"stride_samples ({stride}) must not exceed window_samples "
                f"({self.window_samples}): samples between windows would be lost"
            )
        window_s = self.window_samples / self.imu_rate_hz
        if window_s > self.minutes * 60:
            raise ValueError(
                f"a window ({window_s:g} s) is longer than a walk ({self.minutes:g} min)"
            )
        for key in ("bundled", "generated_kinds", "modes", "devices"):
            values = getattr(self, key) or []
            if len(set(values)) != len(values):
                raise ValueError(f"{key} lists a name twice: {values}")
        return self

    @property
    def stride(self) -> int:
        """IMU samples between window starts."""
        return self.stride_samples or self.window_samples

    @property
    def window_s(self) -> float:
        """Nominal window length in seconds."""
        return self.window_samples / self.imu_rate_hz

    def resolved(self) -> DatasetConfig:
        """This configuration with every name checked and ``bundled``/``stride`` made explicit.

        Raises:
            DatasetConfigError: an unknown scenario, kind, mode or device name,
                with the key and the valid names.
        """
        from indoorsim.phone.devices import (
            DeviceFileError,
            UnknownDeviceError,
            available_devices,
            get_device,
        )
        from indoorsim.scenario.generate import KINDS, UnknownKindError
        from indoorsim.scenario.load import (
            ScenarioError,
            UnknownScenarioError,
            bundled_scenarios,
            load_scenario,
        )
        from indoorsim.walker.modes import UnknownModeError, available_modes, mode_fields

        problems: list[tuple[str, str]] = []
        known_scenarios = list(bundled_scenarios())
        bundled = known_scenarios if self.bundled is None else list(self.bundled)
        checks: tuple[tuple[str, list[str], list[str], Callable[..., UnknownNameError]], ...] = (
            ("bundled", bundled, known_scenarios, UnknownScenarioError),
            ("generated_kinds", self.generated_kinds, sorted(KINDS), UnknownKindError),
            ("modes", self.modes, available_modes(), UnknownModeError),
            ("devices", self.devices, sorted(available_devices()), UnknownDeviceError),
        )
        for key, names, valid, unknown in checks:
            for i, name in enumerate(names):
                if key == "devices" and is_yaml_file(name):
                    # A profile file, as `indoorsim calibrate` writes: it must load.
                    try:
                        get_device(name)
                    except DeviceFileError as err:
                        problems.append((f"{key}[{i}]", str(err)))
                elif key == "bundled" and is_yaml_file(name):
                    # A scenario file, as `indoorsim import-plan` writes: it must load.
                    try:
                        load_scenario(name)
                    except ScenarioError as err:
                        problems.append((f"{key}[{i}]", str(err)))
                elif name not in valid:
                    problems.append((f"{key}[{i}]", str(unknown(name, valid))))
        modes = available_modes()
        for mode, params in self.mode_params.items():
            if mode not in modes:
                problems.append((f"mode_params.{mode}", str(UnknownModeError(mode, modes))))
                continue
            fields = mode_fields(mode)
            for name in params:
                if name not in fields:
                    problems.append(
                        (
                            f"mode_params.{mode}.{name}",
                            f"not a parameter of {mode!r}; its parameters are {sorted(fields)}",
                        )
                    )
        n_bundled = round(self.sites * self.bundled_share) if bundled else 0
        if self.sites - min(n_bundled, len(bundled)) > 0 and not self.generated_kinds:
            problems.append(
                ("generated_kinds", f"{self.sites} sites need generated ones, but no kind is given")
            )
        if problems:
            raise DatasetConfigError("configuration", problems)
        return self.model_copy(update={"bundled": bundled, "stride_samples": self.stride})

    def to_json(self) -> dict[str, Any]:
        """A JSON-able dict (the form stored in ``config.json`` and the card)."""
        return self.model_dump(mode="json")

    @property
    def bundled_sites(self) -> int:
        """How many sites come from the bundled scenarios (needs :meth:`resolved`)."""
        names = self.bundled or []
        return min(round(self.sites * self.bundled_share), len(names))


def is_yaml_file(name: str) -> bool:
    """Whether a ``bundled`` or ``devices`` entry names a YAML file rather than a built-in."""
    return name.endswith((".yaml", ".yml"))


def validate_config(data: Mapping[str, Any], source: str) -> DatasetConfig:
    """A :class:`DatasetConfig` from parsed keys, errors labelled with ``source``.

    Raises:
        DatasetConfigError: every problem, each with its dotted key path.
    """
    if not isinstance(data, Mapping):
        raise DatasetConfigError(
            source, [("", f"expected a mapping of keys, got {type(data).__name__}")]
        )
    try:
        config = DatasetConfig.model_validate(dict(data))
    except ValidationError as err:
        problems = []
        for e in err.errors(include_url=False):
            msg = e["msg"].removeprefix("Value error, ")
            problems.append(
                (key_path(e["loc"]), "unknown key" if e["type"] == "extra_forbidden" else msg)
            )
        raise DatasetConfigError(source, problems) from None
    try:
        return config.resolved()
    except DatasetConfigError as err:
        raise DatasetConfigError(source, err.problems) from None


def load_config(
    path: str | Path | None, overrides: Mapping[str, Any] | None = None
) -> DatasetConfig:
    """Read a YAML/JSON configuration file, apply ``overrides`` and resolve it.

    Args:
        path: the file, or None for the defaults.
        overrides: keys that replace the file's (the CLI options that were given).

    Raises:
        DatasetConfigError: the file is unreadable, not a mapping, or invalid;
            the message names the file and the key.
    """
    data: dict[str, Any] = {}
    source = "command line"
    if path is not None:
        source = str(path)
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as err:
            raise DatasetConfigError(
                source, [("", f"cannot read: {err.strerror or err}")]
            ) from None
        try:
            loaded = yaml.safe_load(text)
        except yaml.YAMLError as err:
            raise DatasetConfigError(source, [("", f"not valid YAML/JSON: {err}")]) from None
        if loaded is None:
            loaded = {}
        if not isinstance(loaded, dict):
            raise DatasetConfigError(
                source, [("", f"expected a mapping of keys, got {type(loaded).__name__}")]
            )
        data = loaded
    data = {**data, **(overrides or {})}
    return validate_config(data, source)


def config_difference(
    stored: Mapping[str, Any], wanted: Mapping[str, Any], prefix: str = ""
) -> list[str]:
    """Dotted keys whose values differ between two JSON configurations."""
    out = []
    for key in sorted(set(stored) | set(wanted)):
        a, b = stored.get(key, "<absent>"), wanted.get(key, "<absent>")
        path = f"{prefix}.{key}" if prefix else key
        if isinstance(a, dict) and isinstance(b, dict):
            out += config_difference(a, b, path)
        elif a != b:
            out.append(f"{path}: stored {json.dumps(a)}, now {json.dumps(b)}")
    return out
