"""TUM trajectory files: the format by the spec, exact round trips, and evo reading them."""

from __future__ import annotations

import re

import numpy as np
import pytest
from evo.tools import file_interface

from indoorsim.io.tum import heading_quaternions, read_tum, write_tum

RNG = np.random.default_rng(20)
T = np.cumsum(RNG.uniform(0.2, 1.0, 40)) + 1234.5
XY = RNG.normal(0.0, 30.0, (40, 2)) * np.array([1.0, 1e-7])  # tiny and large numbers alike
HEADING = RNG.uniform(-np.pi, np.pi, 40)


def test_lines_follow_the_tum_spec(tmp_path):
    """timestamp tx ty tz qx qy qz qw: eight numbers, single spaces, no header or comment."""
    path = write_tum(tmp_path / "est.tum", T, XY, heading=HEADING)
    lines = path.read_text(encoding="ascii").split("\n")
    assert lines[-1] == "" and len(lines) == len(T) + 1  # one line per pose, each ended
    number = r"-?\d+(\.\d+)?(e[-+]\d+)?"
    for line, t in zip(lines[:-1], T, strict=True):
        assert re.fullmatch(" ".join([number] * 8), line), line
        fields = [float(v) for v in line.split(" ")]
        assert fields[0] == t and fields[3] == 0.0  # time first; z = 0
        qx, qy, qz, qw = fields[4:]
        assert (qx, qy) == (0.0, 0.0) and qx**2 + qy**2 + qz**2 + qw**2 == pytest.approx(1.0)


def test_write_then_read_gives_the_same_floats(tmp_path):
    traj = read_tum(write_tum(tmp_path / "est.tum", T, XY, heading=HEADING))
    assert np.array_equal(traj.t, T)
    assert np.array_equal(traj.position[:, :2], XY) and not traj.position[:, 2].any()
    qx, qy, qz, qw = traj.orientation.T
    yaw = 2 * np.arctan2(qz, qw)  # a turn about +z by the heading
    np.testing.assert_allclose(np.angle(np.exp(1j * (yaw - HEADING))), 0.0, atol=1e-12)
    assert not qx.any() and not qy.any()


def test_unknown_headings_are_the_identity(tmp_path):
    h = HEADING.copy()
    h[::3] = np.nan
    traj = read_tum(write_tum(tmp_path / "a.tum", T, XY, heading=h))
    assert (traj.orientation[::3] == [0.0, 0.0, 0.0, 1.0]).all()
    assert not (traj.orientation[1::3] == [0.0, 0.0, 0.0, 1.0]).all(axis=1).any()
    none = read_tum(write_tum(tmp_path / "b.tum", T, XY))
    assert (none.orientation == [0.0, 0.0, 0.0, 1.0]).all()
    assert heading_quaternions([np.pi / 2]).tolist() == [
        [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)]
    ]


@pytest.mark.parametrize(
    ("t", "xy", "message"),
    [
        ([0.0, 1.0, 1.0], np.zeros((3, 2)), "timestamps must increase strictly"),
        ([0.0, 1.0, 2.0], [[0, 0], [np.nan, 0], [1, 1]], "must be finite"),
        ([0.0, 1.0], np.zeros((3, 2)), "expected (2, 2) positions"),
    ],
)
def test_writing_refuses_what_tum_readers_cannot_use(tmp_path, t, xy, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        write_tum(tmp_path / "x.tum", t, xy)
    assert list(tmp_path.iterdir()) == []  # nothing half-written


def test_reading_skips_comments_and_names_a_bad_line(tmp_path):
    path = tmp_path / "other.tum"
    path.write_text("# timestamp tx ty tz qx qy qz qw\n1 2 3 4 0 0 0 1\n\n2 3 4 5 0 0 0 1\n")
    traj = read_tum(path)
    assert traj.t.tolist() == [1.0, 2.0] and traj.position.tolist() == [[2, 3, 4], [3, 4, 5]]
    path.write_text("1 2 3 4 0 0 0 1\n2 3 4 5 0 0 1\n")
    with pytest.raises(ValueError, match=r"other\.tum, line 2: expected 8 numbers"):
        read_tum(path)


def test_evo_reads_our_files_as_written(tmp_path):
    path = write_tum(tmp_path / "est.tum", T, XY, heading=HEADING)
    traj = file_interface.read_tum_trajectory_file(str(path))
    ours = read_tum(path)
    assert np.array_equal(traj.timestamps, T)
    assert np.array_equal(traj.positions_xyz, ours.position)
    # evo keeps quaternions scalar first (w, x, y, z); the file has them scalar last.
    assert np.array_equal(traj.orientations_quat_wxyz, np.roll(ours.orientation, 1, axis=1))
