"""Quaternion helpers agree with scipy's Rotation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from indoorsim.util import quaternion as quat


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


def _slerp_numpy(tk, qk, tq):
    """The plain numpy slerp the compiled one replaced (its reference, bit for bit)."""
    i = np.clip(np.searchsorted(tk, tq, side="right") - 1, 0, len(tk) - 2)
    f = ((tq - tk[i]) / (tk[i + 1] - tk[i]))[:, None]
    a, b = qk[i], qk[i + 1]
    b = b * np.where(np.einsum("ij,ij->i", a, b) < 0, -1.0, 1.0)[:, None]
    cos = np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0)[:, None]
    theta = np.arccos(cos)
    sin = np.sin(theta)
    small = sin < 1e-9
    wa = np.where(small, 1.0 - f, np.sin((1.0 - f) * theta) / np.where(small, 1.0, sin))
    wb = np.where(small, f, np.sin(f * theta) / np.where(small, 1.0, sin))
    out = wa * a + wb * b
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def test_slerp_equals_the_numpy_form_bit_for_bit():
    # Random, nearly equal (the linear branch), sign-flipped and repeated knots,
    # times outside the knots and on them. (Bit-identity rests on numpy summing
    # a row of four as einsum and norm do here; a different numpy may differ
    # in the last bit.)
    rng = np.random.default_rng(12)
    for k in (2, 3, 50):
        t = np.cumsum(rng.uniform(0.01, 1.0, k))
        q = _random(k, k).as_quat(scalar_first=True)
        q[1::3] = q[0::3][: len(q[1::3])] + rng.normal(0, 1e-12, q[1::3].shape)
        q[2::5] *= -1.0
        tq = np.concatenate([rng.uniform(t[0] - 1, t[-1] + 1, 500), t])
        np.testing.assert_array_equal(quat.slerp(t, q, tq), _slerp_numpy(t, q, tq))


def test_slerp_refuses_arrays_of_the_wrong_shape():
    t, q, tq = np.arange(3.0), _random(3, 1).as_quat(scalar_first=True), np.linspace(0, 2, 7)
    for kwargs in ({"out": np.empty((6, 4))}, {"out": np.empty((7, 4), int)}, {"below": [0]}):
        with pytest.raises(ValueError, match="slerp: "):
            quat.slerp(t, q, tq, **kwargs)
    with pytest.raises(ValueError, match="K ≥ 2"):
        quat.slerp(t[:1], q[:1], tq)
    with pytest.raises(ValueError, match="quaternions"):
        quat.slerp(t, q[:, :3], tq)


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


def _multiply_numpy(a, b):
    """The numpy product the compiled one replaced (its reference, bit for bit)."""
    w1, x1, y1, z1 = np.moveaxis(np.asarray(a, dtype=float), -1, 0)
    w2, x2, y2, z2 = np.moveaxis(np.asarray(b, dtype=float), -1, 0)
    return np.stack(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ],
        axis=-1,
    )


def test_multiply_broadcasts_and_equals_the_numpy_form_bit_for_bit():
    a = _random(12, 12).as_quat(scalar_first=True)
    b = _random(12, 13).as_quat(scalar_first=True)
    for x, y in [
        (a, b),
        (a[0], b),  # one rotation applied to many
        (a, b[0]),
        (a[0], b[0]),
        (a.reshape(3, 1, 4, 4)[:, :, 0], b.reshape(1, 3, 4, 4)[:, :, 1]),  # stacks of stacks
        (np.asfortranarray(a), b[::-1]),  # any memory layout
        (a[:0], b[0]),
    ]:
        got = quat.multiply(x, y)
        np.testing.assert_array_equal(got, _multiply_numpy(x, y))
    with pytest.raises(ValueError, match="quaternions"):
        quat.multiply(a[:, :3], b)


def test_normalise_divides_by_the_norm_and_makes_zero_the_identity():
    rng = np.random.default_rng(14)
    q = rng.normal(size=(20, 4)) * rng.uniform(0.1, 3.0, (20, 1))
    q[3], q[7], q[9] = 0.0, np.nan, 1e-12
    norm = np.linalg.norm(q, axis=-1, keepdims=True)
    want = np.where(norm > 1e-9, q / np.where(norm > 1e-9, norm, 1.0), [1.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(quat.normalise(q, min_norm=1e-9), want)
    np.testing.assert_array_equal(quat.normalise(np.asfortranarray(q), min_norm=1e-9), want)
    assert quat.normalise(q[0]).shape == (4,)
    np.testing.assert_array_equal(quat.normalise(q[3]), [1.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(np.linalg.norm(quat.normalise(q), axis=1), 1.0, atol=1e-15)
