"""Quaternion helpers agree with scipy's Rotation."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from indoorsim import quaternion as quat


def _random(n: int, seed: int) -> Rotation:
    return Rotation.random(n, random_state=seed)


def test_multiply_conjugate_and_rotate_match_scipy():
    a, b = _random(50, 0), _random(50, 1)
    qa, qb = a.as_quat(scalar_first=True), b.as_quat(scalar_first=True)
    got = Rotation.from_quat(quat.multiply(qa, qb), scalar_first=True)
    assert np.allclose((got.inv() * (a * b)).magnitude(), 0, atol=1e-12)
    v = np.random.default_rng(2).normal(size=(50, 3))
    np.testing.assert_allclose(quat.rotate(qa, v), a.apply(v), atol=1e-12)
    np.testing.assert_allclose(quat.rotate(quat.conjugate(qa), v), a.inv().apply(v), atol=1e-12)


def test_relative_rotvec_matches_scipy_including_tiny_angles():
    a = _random(40, 3)
    small = Rotation.from_rotvec(np.random.default_rng(4).normal(0, 1e-9, (40, 3)))
    for b in (_random(40, 5), a * small):
        want = (a.inv() * b).as_rotvec()
        got = quat.relative_rotvec(a.as_quat(scalar_first=True), b.as_quat(scalar_first=True))
        np.testing.assert_allclose(got, want, atol=1e-12)


def test_slerp_matches_scipy():
    t = np.linspace(0, 10, 21)
    rots = _random(21, 6)
    q = rots.as_quat(scalar_first=True)
    tq = np.random.default_rng(7).uniform(0, 10, 300)
    got = Rotation.from_quat(quat.slerp(t, q, tq), scalar_first=True)
    want = Slerp(t, rots)(tq)
    assert np.abs((got.inv() * want).magnitude()).max() < 1e-9


def test_slerp_takes_the_interval_index_and_a_float32_output():
    t = np.linspace(0, 10, 21)
    q = _random(21, 8).as_quat(scalar_first=True)
    q[5] = q[4]  # equal neighbours: the linear weights
    q[1:] *= np.where(np.einsum("ij,ij->i", q[:-1], q[1:]) < 0, -1.0, 1.0)[:, None]
    tq = np.sort(np.random.default_rng(9).uniform(-1, 11, 300))  # extrapolated at the ends
    want = quat.slerp(t, q, tq)
    below = np.searchsorted(t, tq, side="right") - 1
    np.testing.assert_array_equal(quat.slerp(t, q, tq, below=below), want)
    out = np.empty((300, 4), dtype=np.float32)
    assert quat.slerp(t, np.asfortranarray(q), tq, below=below, out=out) is out
    np.testing.assert_array_equal(out, want.astype(np.float32))
    np.testing.assert_allclose(np.linalg.norm(want, axis=1), 1.0, atol=1e-15)


def test_rotate_broadcasts_and_inverts():
    rng = np.random.default_rng(5)
    rot = Rotation.random(6, random_state=11)
    q = rot.as_quat(scalar_first=True)
    v = rng.normal(size=(6, 3))
    np.testing.assert_allclose(quat.rotate(q, v, inverse=True), rot.inv().apply(v), atol=1e-12)
    # One rotation for many vectors, many rotations for one vector, stacks of stacks.
    np.testing.assert_allclose(quat.rotate(q[0], v), rot[0].apply(v), atol=1e-12)
    np.testing.assert_allclose(quat.rotate(q, v[0]), rot.apply(v[0]), atol=1e-12)
    assert quat.rotate(q[0], v[0]).shape == (3,)
    stacked = quat.rotate(q.reshape(2, 3, 4), v.reshape(2, 3, 3))
    np.testing.assert_array_equal(stacked.reshape(6, 3), quat.rotate(q, v))
