"""Compiled quaternion and small-matrix kernels: closed forms, and agreement with scipy."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from indoorsim.util import kernels

IDENTITY = (1.0, 0.0, 0.0, 0.0)


def _unit(n: int, seed: int) -> np.ndarray:
    return Rotation.random(n, random_state=seed).as_quat(scalar_first=True)


def _scipy(q: np.ndarray) -> Rotation:
    return Rotation.from_quat(q, scalar_first=True)


def _matrix(kernel, q: np.ndarray) -> np.ndarray:
    out = np.empty((3, 3))
    kernel(np.ascontiguousarray(q, dtype=float), out)
    return out


def test_product_with_the_identity_is_exact() -> None:
    for q in _unit(20, 0):
        assert kernels.hamilton(*q, *IDENTITY) == tuple(q)
        assert kernels.hamilton(*IDENTITY, *q) == tuple(q)


def test_product_with_the_conjugate_is_the_squared_norm() -> None:
    rng = np.random.default_rng(1)
    for q in rng.normal(size=(20, 4)):
        w, x, y, z = q
        got = kernels.hamilton(w, x, y, z, w, -x, -y, -z)
        np.testing.assert_allclose(got, [q @ q, 0.0, 0.0, 0.0], atol=1e-14)
    for q in _unit(20, 2):  # q ⊗ q* = 1 for unit q, either way round
        w, x, y, z = q
        np.testing.assert_allclose(kernels.hamilton(w, -x, -y, -z, *q), IDENTITY, atol=1e-15)


def test_product_composes_rotations_as_scipy_and_is_associative() -> None:
    a, b, c = _unit(30, 3), _unit(30, 4), _unit(30, 5)
    for p, q, r in zip(a, b, c, strict=True):
        pq = np.array(kernels.hamilton(*p, *q))
        want, got = _scipy(p) * _scipy(q), _scipy(pq)
        assert (got.inv() * want).magnitude() < 1e-12
        left = kernels.hamilton(*pq, *r)
        right = kernels.hamilton(*p, *kernels.hamilton(*q, *r))
        np.testing.assert_allclose(left, right, atol=1e-15)


def test_quat_mul_into_may_write_over_an_input() -> None:
    a, b = _unit(2, 6)
    want = np.array(kernels.hamilton(*a, *b))
    out = a.copy()
    kernels.quat_mul_into(out, b, out)
    np.testing.assert_array_equal(out, want)
    out = b.copy()
    kernels.quat_mul_into(a, out, out)
    np.testing.assert_array_equal(out, want)


def test_rotating_a_vector_is_the_rotation_matrix_product_and_scipy() -> None:
    rng = np.random.default_rng(7)
    for q, v in zip(_unit(30, 8), rng.normal(size=(30, 3)), strict=True):
        got = np.array(kernels.rotate_vector(*q, *v))
        np.testing.assert_allclose(got, _matrix(kernels.rotation_matrix, q) @ v, atol=1e-12)
        np.testing.assert_allclose(got, _scipy(q).apply(v), atol=1e-12)
        # The inverse rotation: the vector part negated, Rᵀ v.
        back = kernels.rotate_vector(q[0], -q[1], -q[2], -q[3], *got)
        np.testing.assert_allclose(back, v, atol=1e-12)
        # q ⊗ (0, v) ⊗ q*, written out.
        w, x, y, z = q
        sandwich = kernels.hamilton(*kernels.hamilton(*q, 0.0, *v), w, -x, -y, -z)
        np.testing.assert_allclose(sandwich, [0.0, *got], atol=1e-12)


@pytest.mark.parametrize("kernel", [kernels.rotation_matrix, kernels.rotation_matrix_homogeneous])
def test_rotation_matrices_match_scipy_and_are_orthonormal(kernel) -> None:
    for q in _unit(30, 9):
        r = _matrix(kernel, q)
        np.testing.assert_allclose(r, _scipy(q).as_matrix(), atol=1e-12)
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-12)


def test_the_homogeneous_matrix_scales_with_the_squared_norm() -> None:
    for q in _unit(10, 10):
        scaled = _matrix(kernels.rotation_matrix_homogeneous, 1.5 * q)
        np.testing.assert_allclose(scaled, 2.25 * _matrix(kernels.rotation_matrix, q), atol=1e-12)


@pytest.mark.parametrize(
    "rotation",
    [
        Rotation.from_rotvec([0.1, -0.2, 0.3]),  # trace > 0
        Rotation.from_rotvec([3.0, 0.1, 0.0]),  # near π about x: r₀₀ leads
        Rotation.from_rotvec([0.1, 3.0, -0.2]),  # about y: r₁₁ leads
        Rotation.from_rotvec([0.0, 0.2, 3.1]),  # about z: r₂₂ leads
        Rotation.from_rotvec([np.pi, 0.0, 0.0]),  # exactly π: w = 0
    ],
)
def test_quaternion_from_matrix_inverts_the_matrix_on_every_branch(rotation: Rotation) -> None:
    q = rotation.as_quat(scalar_first=True)
    got = np.empty(4)
    kernels.quat_from_matrix(_matrix(kernels.rotation_matrix, q), got)
    sign = 1.0 if got @ q >= 0 else -1.0
    np.testing.assert_allclose(sign * got, q, atol=1e-12)


def test_rotation_vectors_round_trip_and_match_scipy() -> None:
    rng = np.random.default_rng(11)
    vectors = np.vstack(
        [
            rng.normal(size=(20, 3)),
            rng.normal(0.0, 1e-10, (5, 3)),  # the series branch
            np.zeros((1, 3)),
            [[0.0, 0.0, np.pi - 1e-6]],
        ]
    )
    for v in vectors:
        q = np.array(kernels.quat_from_rotvec(*v))
        want = Rotation.from_rotvec(v).as_quat(scalar_first=True)
        np.testing.assert_allclose(q, want, atol=1e-12)
        assert kernels.quat_norm(*q) == pytest.approx(1.0, abs=1e-15)
        back = np.array(kernels.rotvec_from_quat(*q))
        # The short way round: the same rotation, with angle ≤ π.
        np.testing.assert_allclose(back, _scipy(q).as_rotvec(), atol=1e-12)
        np.testing.assert_allclose(kernels.rotvec_from_quat(*-q), back, atol=1e-12)
        if np.linalg.norm(v) <= np.pi:
            np.testing.assert_allclose(back, v, atol=1e-12)


def test_normalisation_gives_unit_quaternions() -> None:
    rng = np.random.default_rng(12)
    for q in rng.normal(size=(20, 4)) * 3.0:
        unit = np.array(kernels.normalised(*q))
        assert kernels.quat_norm(*unit) == pytest.approx(1.0, abs=1e-15)
        np.testing.assert_allclose(unit, q / np.linalg.norm(q), rtol=1e-15)
        # numpy's norm along a row sums it left to right too (frames rely on it).
        assert kernels.quat_norm(*q) == np.linalg.norm(q[None], axis=-1)[0]
        canonical = q.copy()
        kernels.canonicalise(canonical)
        assert canonical[0] >= 0
        np.testing.assert_allclose(canonical, np.sign(q[0]) * unit, atol=1e-15)


def test_skew_is_the_cross_product() -> None:
    rng = np.random.default_rng(13)
    for v, u in rng.normal(size=(10, 2, 3)):
        m = np.empty((3, 3))
        kernels.skew(v, m)
        np.testing.assert_allclose(m @ u, np.cross(v, u), atol=1e-14)
        np.testing.assert_array_equal(m, -m.T)


def test_inverse3_inverts() -> None:
    rng = np.random.default_rng(14)
    for a in rng.normal(size=(10, 3, 3)) + 3.0 * np.eye(3):
        out = np.empty((3, 3))
        kernels.inverse3(a, out)
        np.testing.assert_allclose(out @ a, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(out, np.linalg.inv(a), rtol=1e-10, atol=1e-13)
