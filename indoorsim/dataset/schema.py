"""The shard schema: one row per window, every column declared once, here.

:data:`COLUMNS` is the single source of truth: :func:`arrow_schema` builds the
Parquet schema from it, the shard writer fills it, the torch data set reads it,
and the dataset card's README renders it as a table (:func:`markdown_table`).

Shapes use W for the window's IMU samples (``window_samples``). Arrays of a
fixed shape are nested fixed-size lists (``(W, 3)`` float32 is
``fixed_size_list<fixed_size_list<float, 3>, W>``), so their values sit in one
contiguous buffer per row group and read back as ``(rows, W, 3)`` arrays with a
reshape. Variable-length per-window lists (the WiFi scan, the step events) are
Arrow lists. Sensor arrays are float32; times are float64.

Frames (DESIGN §2): *phone* is Android's sensor frame (x right, y up the
screen, z out of the screen); *building* is the site's frame (x, y on the
floor plan, z up from the floor, metres); the fused rotation vectors' world
frame is Android's (x magnetic east, y magnetic north, z up) for ``rotation``
and an arbitrary gravity-aligned frame for ``game_rotation``. Quaternions are
world←phone, scalar first (w, x, y, z).
"""

from __future__ import annotations

from dataclasses import dataclass

import pyarrow as pa

__all__ = ["COLUMNS", "FORMAT_VERSION", "Column", "arrow_schema", "markdown_table"]

FORMAT_VERSION = 1
"""Version of the shard layout; bumped when a column changes meaning or type."""


@dataclass(frozen=True, kw_only=True)
class Column:
    """One column of the shard table.

    Attributes:
        name: column name.
        dtype: element type: ``float32``, ``float64``, ``int16``, ``int32``, ``bool``, ``string``.
        shape: per-row shape: ``()`` a scalar, ``("W",)`` or ``("W", k)`` a fixed
            array over the window's samples, ``("n",)`` a variable-length list.
        unit: physical unit ("" when none).
        frame: coordinate frame ("" when none).
        group: ``id`` (which walk, window and site), ``sensor`` (what a phone
            measures) or ``label`` (truth).
        doc: meaning, one sentence or two.
    """

    name: str
    dtype: str
    shape: tuple[str | int, ...]
    unit: str
    frame: str
    group: str
    doc: str

    def arrow_type(self, window_samples: int) -> pa.DataType:
        """The Arrow type for windows of ``window_samples`` samples."""
        t = _ARROW[self.dtype]
        for dim in reversed(self.shape):
            if dim == "n":
                t = pa.list_(t)
            else:
                t = pa.list_(t, window_samples if dim == "W" else int(dim))
        return t

    @property
    def shape_text(self) -> str:
        """``scalar`` or the shape as Python writes it: ``(W,)``, ``(W, 3)``."""
        if not self.shape:
            return "scalar"
        return str(tuple(self.shape)).replace("'", "")


_ARROW = {
    "float32": pa.float32(),
    "float64": pa.float64(),
    "int16": pa.int16(),
    "int32": pa.int32(),
    "bool": pa.bool_(),
    "string": pa.string(),
}

_PH, _BLD = "phone", "building"
_W = ("W",)
_W3 = ("W", 3)
_W4 = ("W", 4)

COLUMNS: tuple[Column, ...] = (
    # ---------------------------------------------------------------- identity
    Column(name="site", dtype="string", shape=(), unit="", frame="", group="id",
           doc="Site id: a bundled scenario's name or `{kind}-{seed}` of a generated one."),
    Column(name="site_kind", dtype="string", shape=(), unit="", frame="", group="id",
           doc="`bundled`, or the generated building's kind (office, basement, ...)."),
    Column(name="walk_id", dtype="string", shape=(), unit="", frame="", group="id",
           doc="Walk id `s{site}-w{walk}`, unique in the data set (see the card's `walks`)."),
    Column(name="device", dtype="string", shape=(), unit="", frame="", group="id",
           doc="Device profile of the phone (its accelerometer and gyroscope set to "
               "the configured IMU rate)."),
    Column(name="window", dtype="int32", shape=(), unit="", frame="", group="id",
           doc="Index of the window within its walk, from 0."),
    Column(name="t_start", dtype="float64", shape=(), unit="s", frame="", group="id",
           doc="Time of the window's first IMU sample, from the walk's start."),
    Column(name="magnetic_north", dtype="float32", shape=(), unit="rad", frame=_BLD, group="id",
           doc="Direction of magnetic north in the building frame, from +x counter-clockwise: "
               "rotating building-frame vectors by π/2 − this about z gives the world frame of "
               "`rotation` (x magnetic east, y magnetic north)."),
    # ------------------------------------------------------------------ sensors
    Column(name="t", dtype="float64", shape=_W, unit="s", frame="", group="sensor",
           doc="IMU sample times (the phone's clock, with its jitter), from the walk's start."),
    Column(name="accel", dtype="float32", shape=_W3, unit="m/s²", frame=_PH, group="sensor",
           doc="Accelerometer: specific force, gravity included."),
    Column(name="gyro", dtype="float32", shape=_W3, unit="rad/s", frame=_PH, group="sensor",
           doc="Gyroscope: angular rate (on the accelerometer's clock)."),
    Column(name="mag", dtype="float32", shape=_W3, unit="µT", frame=_PH, group="sensor",
           doc="Calibrated magnetometer, sample-and-hold onto the IMU clock "
               "(zeros before its first sample)."),
    Column(name="mag_fresh", dtype="bool", shape=_W, unit="", frame="", group="sensor",
           doc="True where a new magnetometer sample arrived."),
    Column(name="light", dtype="float32", shape=_W, unit="lux", frame="", group="sensor",
           doc="Ambient light on the screen face, sample-and-hold (light events are "
               "on-change)."),
    Column(name="light_fresh", dtype="bool", shape=_W, unit="", frame="", group="sensor",
           doc="True where a new light event arrived."),
    Column(name="rotation", dtype="float32", shape=_W4, unit="", frame="Android world←phone",
           group="sensor",
           doc="Fused rotation vector (accel + gyro + mag) as the phone computes it; "
               "world x magnetic east, y magnetic north, z up."),
    Column(name="game_rotation", dtype="float32", shape=_W4, unit="",
           frame="gravity-aligned world←phone", group="sensor",
           doc="Fused game rotation vector (no magnetometer): gravity-aligned, yaw "
               "arbitrary but consistent within the walk."),
    Column(name="gravity", dtype="float32", shape=_W3, unit="m/s²", frame=_PH, group="sensor",
           doc="Fused gravity vector."),
    Column(name="wifi_bssid", dtype="string", shape=("n",), unit="", frame="", group="sensor",
           doc="APs heard by the latest WiFi scan at or before the window's last sample "
               "(empty before the first scan)."),
    Column(name="wifi_rss", dtype="float32", shape=("n",), unit="dBm", frame="", group="sensor",
           doc="Their RSS, in the order of `wifi_bssid`."),
    Column(name="wifi_fresh", dtype="bool", shape=(), unit="", frame="", group="sensor",
           doc="True if that scan arrived during this window."),
    Column(name="wifi_age", dtype="float32", shape=(), unit="s", frame="", group="sensor",
           doc="Age of that scan at the window's last sample (3600 if no scan yet)."),
    # ------------------------------------------------------------------- labels
    Column(name="pos", dtype="float32", shape=_W3, unit="m", frame=_BLD, group="label",
           doc="True phone position at each IMU sample."),
    Column(name="vel", dtype="float32", shape=_W3, unit="m/s", frame=_BLD, group="label",
           doc="True phone velocity at each IMU sample."),
    Column(name="quat", dtype="float32", shape=_W4, unit="", frame="building←phone",
           group="label", doc="True phone attitude at each IMU sample."),
    Column(name="body_pos", dtype="float32", shape=("W", 2), unit="m", frame=_BLD, group="label",
           doc="True body-centre (pelvis) position on the floor at each IMU sample."),
    Column(name="body_vel", dtype="float32", shape=(2,), unit="m/s", frame=_BLD, group="label",
           doc="Mean body-centre velocity over the window: its displacement from the "
               "first to the last sample over their time difference (the usual "
               "inertial-odometry target)."),
    Column(name="heading", dtype="float32", shape=_W, unit="rad", frame=_BLD, group="label",
           doc="True walking direction at each IMU sample, from +x counter-clockwise, "
               "in (−π, π]."),
    Column(name="step", dtype="bool", shape=_W, unit="", frame="", group="label",
           doc="True at the first IMU sample at or after each true heel strike."),
    Column(name="step_count", dtype="int16", shape=(), unit="", frame="", group="label",
           doc="Number of heel strikes marked in `step`."),
    Column(name="step_t", dtype="float64", shape=("n",), unit="s", frame="", group="label",
           doc="Their exact times, from the walk's start."),
    Column(name="step_length", dtype="float32", shape=("n",), unit="m", frame="", group="label",
           doc="Their lengths (distance along the path since the previous heel strike)."),
    Column(name="mode", dtype="string", shape=(), unit="", frame="", group="label",
           doc="Carrying mode at the window's last sample (handheld, calling, dangling, "
               "pocketed)."),
    Column(name="mode_changed", dtype="bool", shape=(), unit="", frame="", group="label",
           doc="True if the carrying mode changes within the window (a transition)."),
)  # fmt: skip
"""Every column of a shard, in file order."""


def arrow_schema(window_samples: int) -> pa.Schema:
    """The Parquet/Arrow schema of a shard with ``window_samples`` samples per window."""
    return pa.schema(
        [pa.field(c.name, c.arrow_type(window_samples), nullable=False) for c in COLUMNS]
    )


def markdown_table(window_samples: int) -> str:
    """The schema as a Markdown table (for the dataset card's README)."""
    rows = ["| column | type | shape | unit | frame | meaning |", "|---|---|---|---|---|---|"]
    for c in COLUMNS:
        shape = c.shape_text.replace("W", str(window_samples))
        rows.append(
            f"| `{c.name}` | {c.dtype} | {shape} | {c.unit or '–'} | {c.frame or '–'} | {c.doc} |"
        )
    return "\n".join(rows)
