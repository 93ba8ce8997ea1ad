"""Rotation and joint mechanics the carrying modes share.

Unit quaternion arrays (:data:`Quat`, scalar first) and their few operations
the poses need (:func:`compose`, :func:`about`, :func:`apply`...), the scalar
moves between scipy's order and ours in one compiled pass, and the signal
pieces of the body's joints: finite-difference :func:`derivative` and
:func:`acceleration`, the damped-spring joint :func:`oscillator`, hand
:func:`tremor`, slowly varying noise, and a fast Gaussian smoother.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numba
import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import gaussian_filter1d
from scipy.signal import bilinear, butter, lfilter, oaconvolve, sosfilt, sosfilt_zi
from scipy.spatial.transform import Rotation

from indoorsim.util import quaternion as quat_ops


def put_scalar_first(out: NDArray[np.float64], rot: Rotation) -> None:
    """Write the rotations' quaternions into ``out`` (K, 4), scalar first.

    ``as_quat(scalar_first=True)`` would build an intermediate rolled copy
    (np.roll along an axis of four is slow), and column-by-column copies
    are strided: one compiled pass instead.
    """
    _move_scalar(rot.as_quat(), out, False)


@numba.njit(cache=True, error_model="numpy")
def _move_scalar(q, out, to_last):  # pragma: no cover - compiled
    """out[k] = q[k] with the scalar moved from first to last (``to_last``) or back."""
    for k in range(q.shape[0]):
        a, b, c, d = q[k, 0], q[k, 1], q[k, 2], q[k, 3]
        if to_last:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = b, c, d, a
        else:
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = d, a, b, c


def swap_scalar(q: NDArray[np.float64], to_last: bool) -> NDArray[np.float64]:
    """Quaternion(s) q (4,) or (K, 4) with the scalar moved to the end (``to_last``) or front."""
    q2 = np.ascontiguousarray(np.atleast_2d(q))
    out = np.empty_like(q2)
    _move_scalar(q2, out, to_last)
    return out.reshape(np.shape(q))


# Rotations inside the modes are unit quaternion arrays, (4,) or (K, 4), scalar
# first (scipy's Rotation is built once per pose): at 200 Hz over a long walk
# scipy's conversions on every factor would cost more than the motion itself.
Quat = NDArray[np.float64]


def compose(*rotations: Quat) -> Quat:
    """The product q₁ ⊗ q₂ ⊗ …, each a single quaternion or a stack of one common length.

    The same rotation as chaining scipy's ``*`` (to rounding).
    """
    q = np.atleast_2d(np.asarray(rotations[0], dtype=float))
    for r in rotations[1:]:
        q = quat_ops.multiply(q, r)
    return q


def rotation(q: Quat) -> Rotation:
    """The scipy rotation(s) of quaternion(s) q.

    scipy's ``scalar_first=True`` rolls the array with np.roll, which is slow
    along an axis of four: the scalar is moved in one compiled pass instead.
    """
    return Rotation.from_quat(swap_scalar(q, True))


def about(axis: str, angle: float | NDArray[np.float64]) -> Quat:
    """Rotation(s) by ``angle`` rad about the x, y or z axis (one per angle)."""
    half = 0.5 * np.asarray(angle, dtype=float)
    q = np.zeros((*half.shape, 4))
    q[..., 0] = np.cos(half)
    q[..., 1 + "xyz".index(axis)] = np.sin(half)
    return q


def lean_sideways(roll: float | NDArray[np.float64]) -> Quat:
    """The trunk's sideways lean by ``roll`` rad, + left (``BodyTrajectory.roll``): its top
    tips toward the body's +y. About the forward axis (x) that is a turn by −roll, as a
    positive turn about x takes +z toward −y."""
    return about("x", -np.asarray(roll, dtype=float))


def from_rotvec(v: NDArray[np.float64]) -> Quat:
    """Rotation(s) by rotation vector(s) v."""
    return swap_scalar(Rotation.from_rotvec(v).as_quat(), False)


def body_frame(yaw: NDArray[np.float64]) -> Quat:
    """World←body rotations (body x forward, y left, z up) for yaw angles."""
    return about("z", yaw)


def apply(q: Quat, v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Vectors v (3,) or (K, 3) rotated by q."""
    return quat_ops.rotate(q, v)


def from_axes(x: Sequence[float], y: Sequence[float], z: Sequence[float]) -> Quat:
    """The rotation whose columns are the phone's x, y, z axes in the body frame."""
    return Rotation.from_matrix(np.column_stack([x, y, z])).as_quat(scalar_first=True)


@functools.cache
def butter_sos(band: float | tuple[float, float], rate_hz: float) -> tuple[NDArray, NDArray]:
    """Second-order Butterworth sections (low-pass, or band-pass for a pair) and their
    steady-state initial conditions per unit input; designed once per band and rate."""
    btype = "lowpass" if isinstance(band, float | int) else "bandpass"
    sos = butter(2, band, btype=btype, fs=rate_hz, output="sos")
    zi = sosfilt_zi(sos)
    return sos, zi


def lowpass(x: NDArray[np.float64], cutoff_hz: float, rate_hz: float) -> NDArray[np.float64]:
    """Second-order Butterworth low-pass along axis 0, starting in its steady state."""
    sos, zi = butter_sos(cutoff_hz, rate_hz)
    x = np.asarray(x, dtype=float)
    init = zi[..., None] * x[0] if x.ndim > 1 else zi * x[0]
    return sosfilt(sos, x, axis=0, zi=init)[0]


def derivative(x: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """First derivative of samples ``x`` (K,) or (K, ...) at times ``t`` (K,) along axis 0:
    ``np.gradient(x, t, axis=0)`` to the bit (second-order central differences on the
    uneven grid, one-sided at the ends), in one compiled pass instead of numpy's dozen
    temporaries (a tenth of the time on a 10-minute walk)."""
    x = np.asarray(x, dtype=float)
    t = np.ascontiguousarray(t, dtype=float)
    if len(x) < 2 or t.shape != (len(x),):
        return np.gradient(x, t, axis=0)  # numpy's own errors
    flat = np.ascontiguousarray(x.reshape(len(x), -1))
    out = np.empty_like(flat)
    dt = np.diff(t)
    # numpy takes evenly spaced times as one step, with its simpler formula.
    _gradient(flat, t, bool((dt == dt[0]).all()), out)
    return out.reshape(x.shape)


@numba.njit(cache=True, error_model="numpy")
def _gradient(f, t, even, out):  # pragma: no cover - compiled
    """out = np.gradient(f, t, axis=0) for (K, M) f, with numpy's coefficients and its
    order of operations (so the same bits); ``even``: the times are evenly spaced."""
    n = f.shape[0]
    for j in range(f.shape[1]):
        out[0, j] = (f[1, j] - f[0, j]) / (t[1] - t[0])
        out[n - 1, j] = (f[n - 1, j] - f[n - 2, j]) / (t[n - 1] - t[n - 2])
    if even:
        step2 = 2.0 * (t[1] - t[0])
        for i in range(1, n - 1):
            for j in range(f.shape[1]):
                out[i, j] = (f[i + 1, j] - f[i - 1, j]) / step2
        return
    for i in range(1, n - 1):
        dx1 = t[i] - t[i - 1]
        dx2 = t[i + 1] - t[i]
        a = -(dx2) / (dx1 * (dx1 + dx2))
        b = (dx2 - dx1) / (dx1 * dx2)
        c = dx1 / (dx2 * (dx1 + dx2))
        for j in range(f.shape[1]):
            out[i, j] = a * f[i - 1, j] + b * f[i, j] + c * f[i + 1, j]


def acceleration(pos: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """Second derivative of sampled positions along axis 0 (:func:`derivative` twice)."""
    return derivative(derivative(pos, t), t)


def oscillator(
    drive: NDArray[np.float64], natural_hz: float, damping: float, rate_hz: float
) -> NDArray[np.float64]:
    """θ of θ̈ + 2ζω·θ̇ + ω²·θ = drive, from rest (ω = 2π·natural_hz, ζ = damping).

    A limb segment held by muscle about a joint: below its natural frequency
    it follows the static balance drive/ω², near it the response rings, above
    it the segment's inertia holds it still. Discretised by the bilinear
    transform (at the body's 200 Hz and more, frequency warping is negligible).
    """
    return _spring(drive, natural_hz, damping, rate_hz, base_driven=False)


def transmitted(
    motion: NDArray[np.float64], natural_hz: float, damping: float, rate_hz: float
) -> NDArray[np.float64]:
    """What a mass on a damped spring does when its base moves by ``motion``, from rest.

    x of ẍ + 2ζω·(ẋ − u̇) + ω²·(x − u) = 0 for the base motion u: the
    transmissibility (1 + 2jζr)/(1 − r² + 2jζr) at r = f/f_n. Slow motion is
    followed exactly (a steady walk's drift needs no spring force), motion
    near the natural frequency is amplified, and well above it the mass's
    inertia holds it still while the base moves under it. Bilinear transform,
    as :func:`oscillator`.
    """
    return _spring(motion, natural_hz, damping, rate_hz, base_driven=True)


def _spring(
    x: NDArray[np.float64], natural_hz: float, damping: float, rate_hz: float, *, base_driven: bool
) -> NDArray[np.float64]:
    """The damped spring's response to ``x`` from rest, by the bilinear transform: driven
    by a force (1 over the characteristic polynomial) or through its base (the spring
    and damper's own terms over it)."""
    omega = 2.0 * np.pi * natural_hz
    den = [1.0, 2.0 * damping * omega, omega**2]
    b, a = bilinear(den[1:] if base_driven else [1.0], den, fs=rate_hz)
    return lfilter(b, a, x, axis=0)


def to_body(
    vec: NDArray[np.float64],
    heading: NDArray[np.float64] | tuple[NDArray[np.float64], NDArray[np.float64]],
) -> NDArray[np.float64]:
    """Horizontal vectors in the walking frame: (forward, left). ``heading`` is the
    angles, or their (cos, sin) where a caller turns several vectors by the same ones."""
    c, s = heading if isinstance(heading, tuple) else (np.cos(heading), np.sin(heading))
    return np.column_stack([c * vec[:, 0] + s * vec[:, 1], -s * vec[:, 0] + c * vec[:, 1]])


def tremor(n: int, rate_hz: float, rms: float, rng: np.random.Generator) -> NDArray[np.float64]:
    """Physiological tremor on three axes: noise band-limited to 8–12 Hz with RMS ``rms``."""
    sos, _ = butter_sos((8.0, 12.0), rate_hz)
    x = sosfilt(sos, rng.standard_normal((n, 3)), axis=0)
    sd = x.std()
    if sd > 0:
        x *= rms / sd
    return x


def slow_noise(
    n: int, rate_hz: float, rng: np.random.Generator, sigma_s: float = 0.5
) -> NDArray[np.float64]:
    """Unit-RMS noise varying over about four ``sigma_s`` (white noise smoothed by a
    Gaussian of σ = ``sigma_s`` seconds: its amplitude response halves at
    0.19/``sigma_s`` Hz, its power response at 0.076/``sigma_s`` Hz)."""
    x = gaussian_smooth(rng.standard_normal(n), sigma_s * rate_hz)
    sd = x.std()
    return x / sd if sd > 0 else x


def gaussian_smooth(x: NDArray[np.float64], sigma: float) -> NDArray[np.float64]:
    """``scipy.ndimage.gaussian_filter1d(x, sigma)`` (same kernel, mirrored ends), by FFT.

    With σ of a hundred samples the direct filter costs ~800 products per
    sample; overlap-add convolution gives the same result to rounding.
    """
    radius = int(4.0 * sigma + 0.5)
    u = np.arange(-radius, radius + 1)
    kernel = np.exp(-0.5 * (u / sigma) ** 2)
    kernel /= kernel.sum()
    # ndimage's "reflect" mirrors about the edge, repeating the end sample.
    padded = np.pad(x, radius, mode="symmetric") if len(x) > radius else None
    if padded is None:
        return gaussian_filter1d(x, sigma)
    return oaconvolve(padded, kernel, mode="valid")
