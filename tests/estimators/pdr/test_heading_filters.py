"""Heading components of Han2023's BKF-WT by closed forms: wavelet denoising, mag and gyro
headings, and the KF/BKF against hand-written equations."""

from __future__ import annotations

import numpy as np
import pytest
import pywt
from scipy.spatial.transform import Rotation

import indoorsim
from indoorsim.estimators.base import SiteContext
from indoorsim.estimators.frames import heading_from_rotation, wrap_angle
from indoorsim.estimators.pdr.filters import (
    HeadingBKF,
    HeadingKF,
    gyro_heading,
    mag_heading,
)
from indoorsim.estimators.pdr.wavelet import (
    StreamingDenoiser,
    default_level,
    denoise,
    universal_threshold,
)
from indoorsim.simulate import simulate

# ---------------------------------------------------------------- wavelet


def noisy_sine(n: int, sigma: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A 0.5 Hz sine at 100 Hz and the same with white noise of RMS ``sigma``."""
    t = np.arange(n) / 100.0
    clean = np.sin(2 * np.pi * 0.5 * t)
    return clean, clean + np.random.default_rng(seed).normal(0.0, sigma, n)


def rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


@pytest.mark.parametrize("n", [1000, 1001])
def test_denoise_halves_the_error_of_a_noisy_sine_and_keeps_its_length(n: int) -> None:
    clean, noisy = noisy_sine(n, 0.1)
    out = denoise(noisy)
    assert out.shape == noisy.shape
    assert rms(out - clean) < rms(noisy - clean) / 2


@pytest.mark.parametrize("mode", ["soft", "hard", "garrote"])
def test_a_constant_signal_comes_back_unchanged_not_nan(mode: str) -> None:
    # Constant input: every detail coefficient is 0, so the universal threshold
    # is 0 too, where pywt's soft rule computes 0/0 (PyWavelets issue #866).
    for value in (0.0, 2.5):
        x = np.full((100, 2), value)
        np.testing.assert_allclose(denoise(x, mode=mode), x, atol=1e-12)
    stream = StreamingDenoiser(window=32, mode=mode)
    np.testing.assert_allclose(stream.update(np.zeros(50)), 0.0, atol=1e-12)


def test_denoise_treats_channels_independently() -> None:
    _, a = noisy_sine(800, 0.1, seed=1)
    _, b = noisy_sine(800, 0.5, seed=2)
    both = denoise(np.column_stack([a, 3.0 * b]))
    np.testing.assert_allclose(both, np.column_stack([denoise(a), denoise(3.0 * b)]), atol=1e-12)


def test_a_zero_threshold_reconstructs_the_signal() -> None:
    _, noisy = noisy_sine(513, 0.3)
    np.testing.assert_allclose(denoise(noisy, threshold=0.0), noisy, atol=1e-10)


def test_universal_threshold_is_mad_sigma_times_sqrt_2_ln_n() -> None:
    d = np.array([-2.0, 1.0, 0.5, -0.2, 9.0])  # median |d| = 1
    assert float(universal_threshold(d, 400)) == pytest.approx(
        np.sqrt(2 * np.log(400)) / 0.6744897501960817, rel=1e-12
    )


def test_streaming_output_is_the_batch_denoiser_on_its_buffer() -> None:
    # The streaming output *is* denoise() of the buffer ending at that sample:
    # equal up to rounding, whatever the split of the updates.
    _, noisy = noisy_sine(700, 0.1)
    w = 256
    stream = StreamingDenoiser(window=w)
    out = np.concatenate([stream.update(noisy[i : i + 97]) for i in range(0, 700, 97)])
    for k in (w - 1, 400, 699):
        assert out[k] == pytest.approx(denoise(noisy[k - w + 1 : k + 1])[-1], abs=1e-12)
    np.testing.assert_allclose(stream.denoised_window(), denoise(noisy[-w:]), atol=1e-12)
    lagged = StreamingDenoiser(window=w, lag=5).update(noisy)
    assert lagged[-1] == pytest.approx(denoise(noisy[-w:])[-6], abs=1e-12)


def test_streaming_last_sample_agrees_with_the_batch_over_the_whole_signal() -> None:
    # With N − W a multiple of 2^level the decimation grids align, and the
    # coefficients that reach the last sample never reach the buffer's start
    # (support 7·(2³ − 1) + 1 = 50 ≪ W), so the two transforms share those
    # coefficients. Only λ differs (σ from different d₁, √(2 ln W) vs
    # √(2 ln N)); soft thresholding moves each coefficient by at most |Δλ|,
    # so |Δy| ≤ |Δλ|·Σ|∂y_last/∂d_i|, the sum over the detail coefficients of
    # the buffer's transform (the reconstruction is linear).
    n, w = 2048, 256
    _, noisy = noisy_sine(n, 0.1)
    level = default_level(w)
    assert (n - w) % 2**level == 0
    streamed = StreamingDenoiser(window=w).update(noisy)[-1]
    batch = denoise(noisy)[-1]
    d1_w = pywt.wavedec(noisy[-w:], "db4", level=level, mode="symmetric")[-1]
    d1_n = pywt.wavedec(noisy, "db4", level=level, mode="symmetric")[-1]
    d_lambda = abs(float(universal_threshold(d1_w, w)) - float(universal_threshold(d1_n, n)))
    coeffs = pywt.wavedec(np.zeros(w), "db4", level=level, mode="symmetric")
    gain = 0.0
    for j in range(1, len(coeffs)):
        for i in range(len(coeffs[j])):
            unit = [np.zeros_like(c) for c in coeffs]
            unit[j][i] = 1.0
            gain += abs(pywt.waverec(unit, "db4", mode="symmetric")[w - 1])
    assert abs(streamed - batch) <= d_lambda * gain + 1e-12


def test_streaming_denoiser_checks_its_arguments() -> None:
    with pytest.raises(ValueError, match="lag"):
        StreamingDenoiser(window=8, lag=8)
    with pytest.raises(ValueError, match="wavelet"):
        StreamingDenoiser(wavelet="nope")
    with pytest.raises(RuntimeError, match="no samples"):
        StreamingDenoiser().denoised_window()


# ---------------------------------------------------------------- mag and gyro headings

# An ENU field pointing to magnetic north and down (northern hemisphere), µT.
FIELD_ENU = np.array([0.0, 30.0, -40.0])


def random_attitudes(n: int, seed: int) -> Rotation:
    """World←phone attitudes at any yaw, tilted up to 70° (the top never near vertical)."""
    rng = np.random.default_rng(seed)
    yaw = rng.uniform(-np.pi, np.pi, n)
    pitch = rng.uniform(-np.radians(70), np.radians(70), n)
    roll = rng.uniform(-np.radians(70), np.radians(70), n)
    return Rotation.from_euler("ZXY", np.column_stack([yaw, pitch, roll]))


def test_mag_heading_recovers_the_heading_of_a_tilted_phone() -> None:
    att = random_attitudes(500, seed=3)
    top = att.apply([0.0, 1.0, 0.0])
    truth = np.arctan2(top[:, 1], top[:, 0])  # the top's heading from east
    mag = att.inv().apply(FIELD_ENU)
    gravity = att.inv().apply([0.0, 0.0, 9.81])  # the accelerometer at rest reads "up"
    np.testing.assert_allclose(wrap_angle(mag_heading(mag, gravity) - truth), 0.0, atol=1e-9)
    # In the building frame: plus the offset, wrapped.
    offset = 2.5
    np.testing.assert_allclose(
        wrap_angle(mag_heading(mag, gravity, offset) - (truth + offset)), 0.0, atol=1e-9
    )
    assert np.all(np.abs(mag_heading(mag, gravity, offset)) <= np.pi)


def test_mag_heading_is_undefined_without_direction() -> None:
    up = [[0.0, 0.0, 9.81]]
    assert np.isnan(mag_heading([[0.0, 0.0, 0.0]], up)).all()  # a missing stream
    assert np.isnan(mag_heading([[0.0, 0.0, -40.0]], up)).all()  # a vertical field
    assert np.isnan(mag_heading([[0.0, 30.0, -40.0]], [[0.0, 9.81, 0.0]])).all()  # top up


def test_gyro_heading_integrates_the_yaw_rate_of_a_tilted_phone() -> None:
    # r(t) = a + b·t about the vertical: the trapezoid rule is exact, φ = φ₀ + a·t + b·t²/2.
    t = np.sort(np.random.default_rng(4).uniform(0.0, 5.0, 300))
    a, b, phi0 = 0.3, -0.1, 1.0
    up = Rotation.from_euler("XY", [0.4, -0.3]).inv().apply([0.0, 0.0, 1.0])
    gyro = (a + b * t)[:, None] * up
    expected = phi0 + a * (t - t[0]) + b * (t**2 - t[0] ** 2) / 2
    np.testing.assert_allclose(gyro_heading(t, gyro, 9.81 * np.tile(up, (300, 1)), phi0), expected)


# ---------------------------------------------------------------- KF and BKF by hand

Q = np.array([[2e-4, 1e-5], [1e-5, 3e-3]])
R = np.array([[4e-2, 2e-3], [2e-3, 0.3]])
P0 = np.diag([0.05, 0.02])
GYRO_VAR = 2e-3


def hand_filter(t, zs, omegas, x, P, t0, biased=False, origin=0.0):
    """Han2023 Eq. 8, 9, 14, 15 (with the PAPER_NOTES errata) written out."""
    xs, Ps = [], []
    for k in range(len(t)):
        dt = t[k] - (t0 if k == 0 else t[k - 1])
        if omegas is not None:  # the gyro's rate replaces the state's
            x = np.array([x[0], omegas[k]])
            P = np.array([[P[0, 0], 0.0], [0.0, GYRO_VAR]])
        F = np.array([[1.0, dt], [0.0, 1.0]])
        x, P = F @ x, F @ P @ F.T + Q
        seen = np.isfinite(zs[k])
        if seen.any():
            H = np.eye(2)[seen]
            K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R[np.ix_(seen, seen)])
            x, P = x + K @ (zs[k][seen] - H @ x), (np.eye(2) - K @ H) @ P
            if biased:
                xo = x - [origin, 0.0]
                gamma = xo @ xo / (np.trace(P) + xo @ xo)
                x, P = [origin, 0.0] + gamma * xo, gamma**2 * P
        xs.append(x)
        Ps.append(P)
    return np.array(xs), np.array(Ps)


def linear_gaussian_case(seed: int = 5, n: int = 200):
    """Times, measurements (some missing) and gyro rates from the model itself."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.005, 0.03, n))
    x = np.array([1.2, 0.4])
    truth = []
    for dt in np.diff(t, prepend=t[0] - 0.01):
        x = np.array([[1.0, dt], [0.0, 1.0]]) @ x + rng.multivariate_normal([0, 0], Q)
        truth.append(x)
    zs = np.array(truth) + rng.multivariate_normal([0, 0], R, n)
    zs[rng.random(n) < 0.1] = np.nan  # no measurement
    zs[rng.random(n) < 0.1, 1] = np.nan  # heading only
    omegas = np.array(truth)[:, 1] + rng.normal(0.0, np.sqrt(GYRO_VAR), n)
    return t, zs, omegas


@pytest.mark.parametrize("cls", [HeadingKF, HeadingBKF])
@pytest.mark.parametrize("gyro", [False, True])
def test_kf_and_bkf_equal_the_hand_written_equations(cls: type[HeadingKF], gyro: bool) -> None:
    t, zs, omegas = linear_gaussian_case()
    w = omegas if gyro else None
    f = cls(Q=Q, R=R, P0=P0, gyro_rate_var=GYRO_VAR)
    f.reset(1.0, 0.3, t0=t[0] - 0.01)
    track = f.batch_filter(t, zs, w)
    xs, Ps = hand_filter(t, zs, w, np.array([1.0, 0.3]), P0, t[0] - 0.01, biased=cls is HeadingBKF)
    np.testing.assert_allclose(track.x, xs, rtol=0, atol=1e-12)
    np.testing.assert_allclose(track.P, Ps, rtol=0, atol=1e-12)
    # Priors, innovations, gains and γ are kept: x = γ·(x⁻ + K y) on every step.
    y = np.where(np.isfinite(track.y), track.y, 0.0)
    post = track.x_prior + np.einsum("nij,nj->ni", track.K, y)
    np.testing.assert_allclose(track.gamma[:, None] * post, track.x, atol=1e-12)
    assert (track.gamma == 1.0).all() == (cls is HeadingKF)
    # Stepping by hand and the batch agree.
    g = cls(Q=Q, R=R, P0=P0, gyro_rate_var=GYRO_VAR)
    g.reset(1.0, 0.3, t0=t[0] - 0.01)
    for k, dt in enumerate(np.diff(t, prepend=t[0] - 0.01)):
        g.predict(dt, None if w is None else w[k])
        g.update(zs[k])
    np.testing.assert_allclose(g.x, track.x[-1], atol=1e-12)
    np.testing.assert_allclose(g.P, track.P[-1], atol=1e-12)


def test_bkf_gamma_on_a_hand_case() -> None:
    # P⁻ = I (Q = 0, Δt = 0), R = I → K = I/2; x⁻ = [2, 0], z = [4, 8] → x = [3, 4],
    # P = I/2, so γ = 25/(1 + 25) (Eq. 14), x ← γx, P ← γ²P.
    bkf = HeadingBKF(Q=np.zeros((2, 2)), R=np.eye(2))
    bkf.reset(2.0, 0.0, P=np.eye(2), t0=0.0)
    bkf.predict(0.0)
    assert bkf.update([4.0, 8.0]) == pytest.approx(25 / 26, rel=1e-14)
    np.testing.assert_allclose(bkf.x, [3 * 25 / 26, 4 * 25 / 26], rtol=1e-14)
    np.testing.assert_allclose(bkf.P, (25 / 26) ** 2 * np.eye(2) / 2, rtol=1e-14)
    # About origin 1: x − [1, 0] = [2, 4], γ = 20/21.
    shifted = HeadingBKF(Q=np.zeros((2, 2)), R=np.eye(2), origin=1.0)
    shifted.reset(2.0, 0.0, P=np.eye(2), t0=0.0)
    shifted.predict(0.0)
    assert shifted.update([4.0, 8.0]) == pytest.approx(20 / 21, rel=1e-14)
    np.testing.assert_allclose(shifted.x, [1 + 2 * 20 / 21, 4 * 20 / 21], rtol=1e-14)


def test_kf_is_frame_invariant_and_the_bkf_is_not_unless_its_origin_moves() -> None:
    t, zs, omegas = linear_gaussian_case(seed=6)
    c = 2.0
    shifted = zs + np.array([c, 0.0])

    def run(f: HeadingKF, z: np.ndarray, phi0: float) -> np.ndarray:
        f.reset(phi0, t0=t[0])
        return f.batch_filter(t, z, omegas).heading

    np.testing.assert_allclose(run(HeadingKF(), shifted, 1.0 + c), run(HeadingKF(), zs, 1.0) + c)
    literal = run(HeadingBKF(), shifted, 1.0 + c) - run(HeadingBKF(), zs, 1.0)
    assert np.abs(literal - c).max() > 1e-3
    np.testing.assert_allclose(
        run(HeadingBKF(origin=c), shifted, 1.0 + c), run(HeadingBKF(), zs, 1.0) + c, atol=1e-12
    )


def test_without_magnetometer_the_gyro_driven_kf_is_the_trapezoidal_gyro_heading() -> None:
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.uniform(0.005, 0.02, 300))
    rates = np.cumsum(rng.normal(0.0, 0.05, 300))
    up = np.tile([0.0, 0.0, 9.81], (300, 1))
    kf = HeadingKF()
    kf.reset(0.7)
    track = kf.filter(t, np.full(300, np.nan), rates)
    expected = gyro_heading(t, rates[:, None] * [0.0, 0.0, 1.0], up, 0.7)
    np.testing.assert_allclose(track.heading, expected, atol=1e-12)


def test_filter_unwraps_the_magnetometer_and_carries_state_across_calls() -> None:
    # A noise-free turn through ±π at 0.8 rad/s: gyro and magnetometer agree, so
    # the filtered heading is the unwrapped truth, continuous across the cut.
    t = np.arange(0.0, 6.0, 0.01)
    truth = np.pi - 1.5 + 0.8 * t  # passes π at t = 1.875 s
    mag = wrap_angle(truth)
    rates = np.full_like(t, 0.8)
    kf = HeadingKF()
    kf.reset(truth[0] - 2 * np.pi, rate=0.8)  # the mag's branch is chosen from here
    track = kf.filter(t, mag, rates)
    np.testing.assert_allclose(track.heading, truth - 2 * np.pi, atol=1e-9)
    np.testing.assert_allclose(track.z[1:, 1], 0.8, atol=1e-9)
    # Window after window, the state, unwrapping and rates carry over exactly.
    whole, parts = HeadingBKF(origin=1.0), HeadingBKF(origin=1.0)
    whole.reset(0.0)
    parts.reset(0.0)
    expected = whole.filter(t, mag, rates)
    pieces = [parts.filter(t[i : i + 50], mag[i : i + 50], rates[i : i + 50]) for i in (0, 50)]
    pieces.append(parts.filter(t[100:], mag[100:], rates[100:]))
    np.testing.assert_allclose(np.concatenate([p.x for p in pieces]), expected.x, atol=1e-12)
    np.testing.assert_allclose(np.concatenate([p.P for p in pieces]), expected.P, atol=1e-12)


def test_filter_arguments_are_checked() -> None:
    with pytest.raises(ValueError, match="positive semi-definite"):
        HeadingKF(Q=np.array([[1.0, 2.0], [2.0, 1.0]]))
    with pytest.raises(ValueError, match="magnetometer headings"):
        HeadingKF().filter([0.0, 0.1], [0.0])


# ---------------------------------------------------------------- a simulated walk


@pytest.fixture(scope="module")
def corridor_walk():
    site = indoorsim.load_site("han2023_corridor")
    rec = simulate(site, route="heading_test", device="ideal", seed=0)
    frame = rec.meta["frame"]
    ctx = SiteContext(
        name=site.name,
        building_north_deg=frame["building_north_deg"],
        magnetic_declination_deg=frame["magnetic_declination_deg"],
    )
    return site, rec, ctx


def test_mag_heading_on_an_ideal_walk_errs_by_the_field_deflection(corridor_walk) -> None:
    # Ideal sensors: with the true attitude's gravity, the mag heading's error
    # is exactly minus the local field's horizontal deflection from the Earth's
    # field — it points the phone to the local "north". With the phone's own
    # fused gravity it stays within a few degrees where the field is undisturbed.
    site, rec, ctx = corridor_walk
    t = rec.mag.index.to_numpy()
    truth = rec.truth
    q = np.column_stack([np.interp(t, truth.index, truth[c]) for c in ("qw", "qx", "qy", "qz")])
    pos = np.column_stack([np.interp(t, truth.index, truth[c]) for c in "xyz"])
    heading = heading_from_rotation(q, 0.0)  # truth quaternions are building←phone
    b = site.magnetic_field(pos)
    b_earth = site.magnetic.earth_field_uT
    deflection = wrap_angle(np.arctan2(b[:, 1], b[:, 0]) - np.arctan2(b_earth[1], b_earth[0]))
    up = Rotation.from_quat(q, scalar_first=True).inv().apply([0.0, 0.0, 9.81])
    psi = mag_heading(rec.mag.to_numpy(), up, ctx.magnetic_to_building_rad)
    np.testing.assert_allclose(wrap_angle(psi - heading + deflection), 0.0, atol=1e-9)
    g = rec.gravity
    fused_up = np.column_stack([np.interp(t, g.index, g[c]) for c in "xyz"])
    err = np.abs(
        wrap_angle(
            mag_heading(rec.mag.to_numpy(), fused_up, ctx.magnetic_to_building_rad) - heading
        )
    )
    calm = np.abs(deflection) < np.radians(1.0)
    assert calm.sum() > 500
    assert np.degrees(np.median(err[calm])) < 2.0
    assert np.degrees(np.percentile(err[calm], 90)) < 5.0
