"""WiFi received power: log-distance path loss, multi-wall loss, correlated shadowing.

Mean RSS (dBm) of access point k at a receiver p (REALISM §4.1, DESIGN §4 "Radio"):

    RSS_k(p) = P_tx,k + G_k(θ) − L_sys − FSPL(1 m, f_k) − 10·n·log10(max(d, 1 m)/1 m)
               − Σ_walls L_wall(f_k) + X_k(x, y)

* P_tx the AP's transmit power (EIRP, toward the horizon), L_sys the antenna, cable and body
  losses between it and the phone's report (``radio.system_loss_db``).
* FSPL(1 m, f) = 20·log10(4π·f·1 m/c): 40.1 dB at 2.412 GHz (REALISM §4.1).
* G_k(θ) ≤ 0 the AP's antenna gain toward the phone relative to its horizon
  (:func:`ap_pattern_db`): a vertical dipole's doughnut, θ the angle from the
  vertical, its axial null filled to ``radio.ap_null_depth_db`` below the horizon.
  A phone walking under a ceiling AP reads it far below what the distance alone
  gives (9 dB 0.4 m off its axis, 1.85 m below it); an AP across the room is
  read at its full EIRP.
* d the 3-D distance. The log-distance law is referenced at d0 = 1 m and not
  meant for the near field, so the RSS is held at its 1 m value inside 1 m:
  continuous, never rising without bound as the phone nears the AP.
* Σ L_wall the multi-wall term: each wall the straight 2-D path crosses costs
  its material's loss at f (``plan.crossing_loss_db``; REALISM §4.2); each
  pillar costs ``radio.pillar_loss_db``, since most power diffracts around a
  column narrower than the first Fresnel zone.
* APs of the storeys above and below (``radio.floors_above``/``floors_below``)
  stand where this floor's do, a storey pitch (the ceiling height) up or down,
  with BSSIDs of their own (:func:`storey_bssid`). Through k slabs they lose
  the COST 231 multi-floor term L_f·k^((k+2)/(k+1) − b), b = 0.46
  (``radio.floor_loss_db`` = L_f at 2.4 GHz, scaled with frequency as concrete's
  loss is, :func:`slab_loss_at`: 32 dB for a 5 GHz radio), and the walls their
  path crosses in plan view, counted once as if the floors had the same walls.
  They are what fills a real scan with weak APs: a phone hears its own floor's
  few loud APs and many through the slabs.

The carrier's body is not part of the building: :meth:`RadioModel.body_shadow_db`
gives the loss ``radio.body_loss_db`` for the APs behind the trunk as seen from
the phone (the trunk a vertical cylinder of radius :data:`TORSO_RADIUS_M`), and
the simulator subtracts it from the mean at each scan. Nor is the phone's antenna
isotropic: :meth:`RadioModel.handset_gain_db` gives its gain toward each AP from the
way the handset's side faces (``WifiSpec.antenna_side_ratio_db``), which the
simulator adds likewise.
* X_k a zero-mean Gaussian shadowing field with standard deviation σ
  (``radio.shadowing_sigma_db``) and exponential spatial correlation
  exp(−Δ/λ) (``radio.shadowing_correlation_m``; REALISM §4.3), fixed per AP
  and site so that a survey and a later walk see the same value at the same
  place (see :class:`ShadowingField`).

Small-scale fading (``radio.multipath``, :class:`MultipathField`) is the
multipath interference at the phone's exact position: :meth:`RadioModel.rss`
adds it with ``small_scale=True``, which is what a phone samples; without it
the result is the local mean a survey map or a plot wants.

The temporal variation of a still phone's readings, the detection threshold,
missed beacons and the 1 dB quantisation belong to the phone
(``indoorsim.phone.sensors.scan_rss`` with the device's ``WifiSpec``).
"""

from __future__ import annotations

import functools
import hashlib
import math
import zlib
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike, NDArray

from indoorsim.util.seeding import generator

if TYPE_CHECKING:
    from indoorsim.scenario.schema import Scenario
    from indoorsim.world.plan import FloorPlan

__all__ = [
    "SLAB_REFERENCE_GHZ",
    "MultipathField",
    "RadioModel",
    "ShadowingField",
    "ap_pattern_db",
    "concrete_loss_3gpp_db",
    "floor_loss_db",
    "free_space_loss_1m_db",
    "multipath_rng",
    "shadowing_rng",
    "slab_loss_at",
    "storey_bssid",
]

SPEED_OF_LIGHT_M_S = 299_792_458.0
REFERENCE_DISTANCE_M = 1.0

GRID_SPACING_M = 0.5
"""Largest node spacing of a shadowing grid (finer when λ/10 is smaller)."""
GRID_MARGIN_M = 1.0
"""The grid extends this far beyond the plan's bounds; beyond it the edge values hold."""

# Tags the shadowing streams so they never coincide with another model's
# streams spawned from the same scenario seed.
_SHADOWING_STREAM = zlib.crc32(b"indoorsim.radio.shadowing")
_MULTIPATH_STREAM = zlib.crc32(b"indoorsim.radio.multipath")
# Circulant embeddings larger than this many cells are refused (~0.5 GB of work arrays).
_MAX_EMBEDDING_CELLS = 1 << 24


def free_space_loss_1m_db(frequency_ghz: float | NDArray[np.float64]) -> NDArray[np.float64]:
    """Free-space path loss at 1 m, 20·log10(4π·f·d0/c), dB."""
    f_hz = np.asarray(frequency_ghz, dtype=float) * 1e9
    return 20 * np.log10(4 * np.pi * f_hz * REFERENCE_DISTANCE_M / SPEED_OF_LIGHT_M_S)


TORSO_RADIUS_M = 0.16
"""The trunk as a cylinder: the area of an adult's chest section (breadth ≈ 0.33 m,
depth ≈ 0.23 m, anthropometric means [E]) as a disc."""
FRESNEL_WIDTH_M = 0.2
"""Width over which the body's shadow sets in: the first Fresnel zone's radius
√(λ·d) at 2.4 GHz, d ≈ 0.3 m from the phone to the trunk."""

COST231_FLOOR_B = 0.46
"""The b of the COST 231 multi-floor term: each further slab costs less than the first."""


def floor_loss_db(slabs: int, per_floor_db: float) -> float:
    """COST 231 loss through ``slabs`` floors: L_f·k^((k+2)/(k+1) − b); 0 for k = 0."""
    if slabs < 0:
        raise ValueError(f"slabs must be >= 0, got {slabs}")
    if slabs == 0:
        return 0.0
    return per_floor_db * slabs ** ((slabs + 2) / (slabs + 1) - COST231_FLOOR_B)


def concrete_loss_3gpp_db(frequency_ghz: float) -> float:
    """3GPP TR 38.901 (Table 7.4.3-1) penetration loss of concrete, 5 + 4f dB (f in GHz)."""
    return 5.0 + 4.0 * frequency_ghz


SLAB_REFERENCE_GHZ = 2.4
"""The frequency ``radio.floor_loss_db`` is given at: REALISM §4.2 tabulates COST 231's
18.3 dB in its 2.4 GHz column (COST 231 itself measured at 1.8 GHz)."""


def slab_loss_at(loss_db: float, frequency_ghz: float) -> float:
    """One slab's loss at ``frequency_ghz`` from ``loss_db`` at :data:`SLAB_REFERENCE_GHZ`.

    A slab's loss in dB is its thickness times a per-metre attenuation; the
    attenuation of concrete grows with frequency as 3GPP's 5 + 4f dB does
    (:func:`concrete_loss_3gpp_db`), so the loss scales by that ratio: ×1.76
    (18.3 → 32.2 dB) at 5.18 GHz, ×1.01 at 2.437 GHz. A slab of no loss stays one.
    """
    return (
        loss_db * concrete_loss_3gpp_db(frequency_ghz) / concrete_loss_3gpp_db(SLAB_REFERENCE_GHZ)
    )


def ap_pattern_db(cos_theta: ArrayLike, null_depth_db: float) -> NDArray[np.float64]:
    """Gain (dB, ≤ 0) of a vertical half-wave dipole at angle θ from its axis, relative
    to the horizon (θ = 90°), its null filled to ``null_depth_db`` below:

        G(θ) = 10·log10((1 − a)·F(θ) + a),   F(θ) = [cos(π/2·cos θ) / sin θ]²,
        a = 10^(−null_depth_db/10)

    F is the half-wave dipole's power pattern (Balanis, *Antenna Theory*, 3rd ed.,
    eq. 4-84), 1 at the horizon and 0 along the axis (its limit, continuous at
    θ → 0); ``null_depth_db`` = 0 is an isotropic antenna (G ≡ 0).
    """
    c = np.abs(np.clip(np.asarray(cos_theta, dtype=float), -1.0, 1.0))
    a = 10 ** (-null_depth_db / 10)
    sin2 = 1.0 - c * c
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(sin2 > 1e-12, np.cos(np.pi / 2 * c) ** 2 / sin2, 0.0)
    return 10 * np.log10((1.0 - a) * f + a)


def storey_bssid(bssid: str, storey: int) -> str:
    """The BSSID of the AP standing where ``bssid`` does, ``storey`` floors up (or down).

    A locally administered unicast MAC hashed from the pair, so the same site always
    has the same neighbours and a storey's BSSIDs do not depend on the other APs.
    """
    octets = bytearray(
        hashlib.blake2b(f"{bssid.lower()}@{storey}".encode(), digest_size=6).digest()
    )
    octets[0] = (octets[0] | 0x02) & 0xFE
    return ":".join(f"{o:02x}" for o in octets)


def shadowing_rng(seed: int, bssid: str) -> np.random.Generator:
    """The generator of one AP's shadowing field: a function of the scenario seed and BSSID only.

    Keyed by a hash of the (case-folded) BSSID, not by the AP's index, so that
    adding, removing or reordering APs leaves every other AP's field unchanged.
    """
    return _ap_generator(seed, _SHADOWING_STREAM, bssid)


def multipath_rng(seed: int, bssid: str) -> np.random.Generator:
    """The generator of one AP's multipath field, keyed like :func:`shadowing_rng`."""
    return _ap_generator(seed, _MULTIPATH_STREAM, bssid)


def _ap_generator(seed: int, stream: int, bssid: str) -> np.random.Generator:
    """One AP's generator of one model's ``stream``, keyed by its case-folded BSSID."""
    return generator(seed, (stream, zlib.crc32(bssid.lower().encode("ascii"))))


MULTIPATH_FREQUENCIES = 8
"""Frequencies across the channel at which the band-averaged power is sampled:
spaced 20/7 ≈ 2.9 MHz, below the coherence bandwidth 1/(2π·στ) ≈ 4 MHz at
40 ns, so the average resolves the band's frequency diversity."""


@dataclass(frozen=True, kw_only=True)
class MultipathField:
    """One AP's small-scale fading: a sum-of-sinusoids channel (Clarke's model
    with delays), fixed in space so that the same spot reads the same fade.

    The complex gain at point p and frequency offset Δf_i in the channel is

        h_i(p) = √(K/(K+1))·exp(j·k0·|p − p_ap|)
               + √(1/(K+1))·(1/√M)·Σ_m exp(j(k0·u_m·p + φ_m − 2π·Δf_i·τ_m))

    with M plane waves from directions u_m uniform on the sphere (isotropic
    scattering: the field's correlation is sinc(k0·Δ), first zero at λ/2),
    phases φ_m uniform and excess delays τ_m exponential with mean στ (an
    exponential power-delay profile of rms spread στ). The reading is the
    band-averaged power mean_i |h_i|², mean 1 over places, in dB. K is the
    direct wave's share: the AP's own K-factor divided by the loss of what the
    direct path crosses.

    Attributes:
        wavenumber: k0 = 2π·f/c, rad/m.
        directions: (M, 3) unit arrival directions.
        phases: (M,) phases φ_m, rad.
        band: (M, F) exp(−j·2π·Δf_i·τ_m)/√M.
        k_factor: the AP's K-factor of an unobstructed link (linear).
    """

    wavenumber: float
    directions: NDArray[np.float64]
    phases: NDArray[np.float64]
    band: NDArray[np.complex128]
    k_factor: float

    @classmethod
    def sample(
        cls,
        rng: np.random.Generator,
        frequency_ghz: float,
        *,
        paths: int,
        delay_spread_ns: float,
        rician_k_db: float,
        rician_k_sigma_db: float,
        bandwidth_mhz: float,
    ) -> MultipathField:
        """One AP's field, drawn from ``rng`` (:func:`multipath_rng`)."""
        z = rng.standard_normal((paths, 3))
        directions = z / np.linalg.norm(z, axis=1, keepdims=True)
        phases = rng.uniform(0.0, 2 * np.pi, paths)
        delays = rng.exponential(delay_spread_ns * 1e-9, paths)
        k_db = rician_k_db + rician_k_sigma_db * rng.standard_normal()
        offsets = bandwidth_mhz * 1e6 * (np.linspace(0.0, 1.0, MULTIPATH_FREQUENCIES) - 0.5)
        band = np.exp(-2j * np.pi * np.outer(delays, offsets)) / math.sqrt(paths)
        return cls(
            wavenumber=2 * np.pi * frequency_ghz * 1e9 / SPEED_OF_LIGHT_M_S,
            directions=directions,
            phases=phases,
            band=band,
            k_factor=10 ** (k_db / 10),
        )

    def fading_db(
        self,
        points: NDArray[np.float64],
        ap: NDArray[np.float64],
        obstruction_db: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """(N,) fade in dB at (N, 3) points, the direct path weakened by ``obstruction_db`` (N,)."""
        k = self.k_factor * 10 ** (-np.asarray(obstruction_db, dtype=float) / 10)
        scattered = np.exp(1j * (self.wavenumber * (points @ self.directions.T) + self.phases))
        direct = np.exp(1j * self.wavenumber * np.linalg.norm(points - ap, axis=1))
        h = np.sqrt(k / (k + 1))[:, None] * direct[:, None] + np.sqrt(1 / (k + 1))[:, None] * (
            scattered @ self.band
        )
        power = np.mean(h.real**2 + h.imag**2, axis=1)
        return 10 * np.log10(np.maximum(power, 1e-12))


@dataclass(frozen=True, kw_only=True)
class ShadowingField:
    """A stationary Gaussian field on a regular grid, interpolated bilinearly.

    Covariance σ²·exp(−Δ/λ) between nodes; sampled exactly on the grid by
    circulant embedding (Dietrich & Newsam 1997): the covariance of a periodic
    grid at least twice as large (plus a few λ, so that the wrap-around is
    negligible) is diagonalised by the 2-D FFT, and the FFT of white noise
    scaled by the square roots of its eigenvalues has that covariance. Between
    nodes the field is interpolated bilinearly; at the default spacing
    (≤ λ/10) that lowers its standard deviation by at most 4 % (at cell
    centres, 0 at nodes). Outside the grid the nearest edge value holds.

    Attributes:
        origin: (x, y) of node [0, 0], m.
        spacing_m: node spacing, m.
        values: (nx, ny) field at the nodes, indexed [ix, iy], dB.
    """

    origin: tuple[float, float]
    spacing_m: float
    values: NDArray[np.float64]

    @classmethod
    def sample(
        cls,
        rng: np.random.Generator,
        bounds: tuple[float, float, float, float],
        sigma_db: float,
        correlation_m: float,
        *,
        spacing_m: float | None = None,
        margin_m: float = GRID_MARGIN_M,
    ) -> ShadowingField:
        """One realisation covering ``bounds`` (xmin, ymin, xmax, ymax) plus ``margin_m``.

        Args:
            rng: the AP's generator (:func:`shadowing_rng`).
            bounds: the area to cover, m.
            sigma_db: standard deviation σ, dB.
            correlation_m: correlation length λ: ρ(λ) = 1/e.
            spacing_m: node spacing; min(0.5 m, λ/10) by default.
            margin_m: extra cover around ``bounds``.

        Raises:
            ValueError: if the grid would need an unreasonably large embedding
                (a correlation length far below the building's size).
        """
        h = spacing_m if spacing_m is not None else min(GRID_SPACING_M, correlation_m / 10)
        x0, y0 = bounds[0] - margin_m, bounds[1] - margin_m
        nx = math.ceil((bounds[2] + margin_m - x0) / h) + 1
        ny = math.ceil((bounds[3] + margin_m - y0) / h) + 1
        amplitude = _embedding_amplitude(nx, ny, h, correlation_m)
        mx, my = amplitude.shape
        noise = rng.standard_normal((2, mx, my))
        z = np.empty((mx, my), dtype=complex)
        z.real = noise[0]
        z.imag = noise[1]
        z *= amplitude
        # Re and Im of this FFT are two independent fields with the embedded
        # covariance (Dietrich & Newsam); one is enough. The 2-D FFT is done
        # as fft2 does it, along axis 0 and then along axis 1, but the second
        # pass only over the nx rows that are kept (the same arithmetic).
        z = scipy.fft.fft(z, axis=0, overwrite_x=True)
        field = scipy.fft.fft(z[:nx], axis=1, overwrite_x=True)
        values = sigma_db * np.ascontiguousarray(field.real[:, :ny])
        return cls(origin=(x0, y0), spacing_m=h, values=values)

    def __call__(self, xy: NDArray[np.float64]) -> NDArray[np.float64]:
        """(N,) field at (N, 2) points, bilinear between nodes."""
        nx, ny = self.values.shape
        fx = np.clip((xy[:, 0] - self.origin[0]) / self.spacing_m, 0, nx - 1)
        fy = np.clip((xy[:, 1] - self.origin[1]) / self.spacing_m, 0, ny - 1)
        ix = np.minimum(fx.astype(np.intp), nx - 2)
        iy = np.minimum(fy.astype(np.intp), ny - 2)
        tx, ty = fx - ix, fy - iy
        v = self.values
        return (1 - tx) * ((1 - ty) * v[ix, iy] + ty * v[ix, iy + 1]) + tx * (
            (1 - ty) * v[ix + 1, iy] + ty * v[ix + 1, iy + 1]
        )


@functools.lru_cache(maxsize=8)
def _embedding_amplitude(nx: int, ny: int, h: float, correlation_m: float) -> NDArray[np.float64]:
    """√(λ/(mx·my)) of :func:`_embedding_eigenvalues`: the same for every AP of a
    site, so it is computed once (read-only)."""
    eigenvalues = _embedding_eigenvalues(nx, ny, h, correlation_m)
    out = np.sqrt(eigenvalues / (eigenvalues.shape[0] * eigenvalues.shape[1]))
    out.flags.writeable = False
    return out


def _embedding_eigenvalues(nx: int, ny: int, h: float, correlation_m: float) -> NDArray[np.float64]:
    """Eigenvalues of a periodic grid holding the exp(−Δ/λ) covariance of nx × ny nodes.

    The periodic grid is at least twice the field plus 8λ in each direction,
    where exp(−8) ≈ 3e-4 makes the wrap-around negligible; the small negative
    eigenvalues that remain are clipped (their total weight is checked).
    """
    pad = math.ceil(8 * correlation_m / h)
    mx = scipy.fft.next_fast_len(2 * (nx - 1) + pad)
    my = scipy.fft.next_fast_len(2 * (ny - 1) + pad)
    if mx * my > _MAX_EMBEDDING_CELLS:
        raise ValueError(
            f"shadowing grid of {nx} × {ny} nodes at {h:.3g} m needs a {mx} × {my} embedding; "
            "use a larger shadowing_correlation_m"
        )
    kx, ky = np.arange(mx), np.arange(my)
    dx = np.minimum(kx, mx - kx) * h
    dy = np.minimum(ky, my - ky) * h
    cov = np.exp(-np.hypot(dx[:, None], dy[None, :]) / correlation_m)
    eigenvalues = scipy.fft.fft2(cov).real
    negative = -eigenvalues[eigenvalues < 0].sum()
    if negative > 1e-3 * eigenvalues.sum():
        raise ValueError(f"circulant embedding is not positive enough ({negative:.3g})")
    return np.maximum(eigenvalues, 0.0)


class RadioModel:
    """Mean WiFi RSS of every access point of a scenario (see the module docstring).

    Attributes:
        bssids: the APs' BSSIDs (the columns of :meth:`rss`): the scenario's in its
            order, then each neighbouring storey's in the same order (above, then below).
        storey: (n_ap,) the storey of each AP relative to this one (0 for the scenario's).
        positions: (n_ap, 3) AP positions, m.
        tx_power_dbm: (n_ap,) transmit powers (EIRP), dBm.
        frequency_ghz: (n_ap,) carrier frequencies, GHz.
        path_loss_exponent: n of the log-distance law.
        system_loss_db: losses between EIRP and the phone's report, dB.
        ap_null_depth_db: depth of the APs' axial null below the horizon, dB
            (:func:`ap_pattern_db`; 0: isotropic APs).
        shadowing: one field per AP, or ``None`` when σ = 0.
        multipath: one small-scale field per AP, or ``None`` when disabled.
        slab_loss_db: (n_ap,) the COST 231 multi-floor loss of each AP, dB.
        body_loss_db: loss behind the carrier's body, dB (:meth:`body_shadow_db`).
        plan: the walls and pillars that attenuate.
    """

    def __init__(self, scenario: Scenario, plan: FloorPlan):
        radio = scenario.radio
        self.plan = plan
        own = [ap.bssid for ap in scenario.wifi]
        position = np.array([ap.position for ap in scenario.wifi], dtype=float).reshape(-1, 3)
        power = np.array([ap.tx_power_dbm for ap in scenario.wifi], dtype=float)
        frequency = np.array([ap.frequency_ghz for ap in scenario.wifi], dtype=float)
        storeys = [0, *range(1, radio.floors_above + 1), *range(-1, -radio.floors_below - 1, -1)]
        pitch = scenario.site.ceiling_height
        self.bssids: list[str] = [b if k == 0 else storey_bssid(b, k) for k in storeys for b in own]
        if len(set(map(str.lower, self.bssids))) != len(self.bssids):
            raise ValueError("a neighbouring storey's BSSID repeats one of the site's")
        self.storey = np.repeat(storeys, len(own)).astype(int)
        self.positions = np.concatenate(
            [position + np.array([0.0, 0.0, k * pitch]) for k in storeys]
        ).reshape(-1, 3)
        self.tx_power_dbm = np.tile(power, len(storeys))
        self.frequency_ghz = np.tile(frequency, len(storeys))
        self.slab_loss_db = np.array(
            [
                floor_loss_db(abs(int(k)), slab_loss_at(radio.floor_loss_db, f))
                for k, f in zip(self.storey, self.frequency_ghz, strict=True)
            ]
        )
        self.path_loss_exponent = radio.path_loss_exponent
        self.system_loss_db = radio.system_loss_db
        self.body_loss_db = radio.body_loss_db
        self.ap_null_depth_db = radio.ap_null_depth_db
        self.pillar_loss_db = radio.pillar_loss_db
        self.multipath: list[MultipathField] | None = None
        if radio.multipath.enabled:
            spec = radio.multipath
            self.multipath = [
                MultipathField.sample(
                    multipath_rng(scenario.seed, bssid),
                    float(f_ghz),
                    paths=spec.paths,
                    delay_spread_ns=spec.delay_spread_ns,
                    rician_k_db=spec.rician_k_db,
                    rician_k_sigma_db=spec.rician_k_sigma_db,
                    bandwidth_mhz=spec.bandwidth_mhz,
                )
                for bssid, f_ghz in zip(self.bssids, self.frequency_ghz, strict=True)
            ]
        self.shadowing: list[ShadowingField] | None = None
        if radio.shadowing_sigma_db > 0:
            self.shadowing = [
                ShadowingField.sample(
                    shadowing_rng(scenario.seed, bssid),
                    plan.bounds,
                    radio.shadowing_sigma_db,
                    radio.shadowing_correlation_m,
                )
                for bssid in self.bssids
            ]

    def rss(self, points: ArrayLike, *, small_scale: bool = False) -> NDArray[np.float64]:
        """(N, n_ap) received power in dBm at (N, 3) points: the local mean, or with
        ``small_scale`` the multipath fade at exactly these points added (what a phone
        there reads before its own temporal variation)."""
        p = _as_points3(points)
        ref_db = (
            self.tx_power_dbm
            - self.system_loss_db
            - free_space_loss_1m_db(self.frequency_ghz)
            - self.slab_loss_db
        )
        out = np.empty((len(p), len(self.bssids)))
        for k, (ap, f_ghz) in enumerate(zip(self.positions, self.frequency_ghz, strict=True)):
            span = np.linalg.norm(p - ap, axis=1)
            d = np.maximum(span, REFERENCE_DISTANCE_M)
            walls = self.plan.crossing_loss_db(
                p[:, :2], ap[None, :2], float(f_ghz), pillar_loss_db=self.pillar_loss_db
            )
            out[:, k] = ref_db[k] - 10 * self.path_loss_exponent * np.log10(
                d / REFERENCE_DISTANCE_M
            )
            out[:, k] -= walls
            if self.ap_null_depth_db > 0:
                # The AP's doughnut: cos θ = |Δz|/distance (horizontal at the AP itself).
                cos_theta = np.abs(p[:, 2] - ap[2]) / np.maximum(span, 1e-9)
                out[:, k] += ap_pattern_db(cos_theta, self.ap_null_depth_db)
            if small_scale and self.multipath is not None:
                obstruction = walls + self.slab_loss_db[k]
                out[:, k] += self.multipath[k].fading_db(p, ap, obstruction)
        if self.shadowing is not None:
            out += self.shadowing_db(p)
        return out

    def body_shadow_db(self, points: ArrayLike, torso_xy: ArrayLike) -> NDArray[np.float64]:
        """(N, n_ap) loss (dB, ≥ 0) from the carrier's trunk at ``torso_xy`` (N, 2) on the
        way from each AP to the phone at ``points`` (N, 3).

        In plan view, the ray from the phone toward an AP is shadowed when it passes
        the trunk's axis closer than :data:`TORSO_RADIUS_M` on the trunk's side of
        the phone. The shadow sets in smoothly over :data:`FRESNEL_WIDTH_M`, across
        the ray and along it, so a phone against the body (a pocket) loses the APs
        on the body's side, a held phone those behind its carrier, and the loss is
        continuous as the walker turns.
        """
        p = _as_points3(points)
        torso = np.asarray(torso_xy, dtype=float)
        if torso.shape != (len(p), 2):
            raise ValueError(f"torso_xy: expected shape ({len(p)}, 2), got {torso.shape}")
        to_torso = torso - p[:, :2]  # (N, 2)
        to_ap = self.positions[None, :, :2] - p[:, None, :2]  # (N, n_ap, 2)
        unit = to_ap / np.maximum(np.linalg.norm(to_ap, axis=2, keepdims=True), 1e-9)
        along = np.einsum("nak,nk->na", unit, to_torso)
        miss = np.abs(unit[..., 0] * to_torso[:, None, 1] - unit[..., 1] * to_torso[:, None, 0])
        across = _smoothstep((TORSO_RADIUS_M - miss) / FRESNEL_WIDTH_M + 0.5)
        ahead = _smoothstep(along / FRESNEL_WIDTH_M + 0.5)
        return self.body_loss_db * across * ahead

    def handset_gain_db(
        self, points: ArrayLike, side_axis: ArrayLike, side_ratio_db: float
    ) -> NDArray[np.float64]:
        """(N, n_ap) the phone's own receive gain toward each AP, dB, zero-mean:
        (ratio/2)·(û·ŝ), û the unit direction from the phone at ``points`` (N, 3) to
        the AP and ŝ ``side_axis`` (N, 3), the world direction of the handset's side
        that hears best (``WifiSpec.antenna_side_ratio_db`` is the ratio): the first
        harmonic of the handset's pattern, +ratio/2 toward that side, −ratio/2 away
        from it, 0 ahead, behind, straight up and down.
        """
        p = _as_points3(points)
        axis = np.asarray(side_axis, dtype=float)
        if axis.shape != (len(p), 3):
            raise ValueError(f"side_axis: expected shape ({len(p)}, 3), got {axis.shape}")
        axis = axis / np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-12)
        to_ap = self.positions[None, :, :] - p[:, None, :]  # (N, n_ap, 3)
        unit = to_ap / np.maximum(np.linalg.norm(to_ap, axis=2, keepdims=True), 1e-9)
        return 0.5 * side_ratio_db * np.einsum("nak,nk->na", unit, axis)

    def shadowing_db(self, points: ArrayLike) -> NDArray[np.float64]:
        """(N, n_ap) shadowing term X_k at (N, 2) or (N, 3) points, dB (zeros when σ = 0)."""
        p = np.asarray(points, dtype=float)
        if p.ndim != 2 or p.shape[1] not in (2, 3):
            raise ValueError(f"points: expected shape (N, 2) or (N, 3), got {p.shape}")
        out = np.zeros((len(p), len(self.bssids)))
        if self.shadowing is not None:
            xy = np.ascontiguousarray(p[:, :2])
            for k, field in enumerate(self.shadowing):
                out[:, k] = field(xy)
        return out


def _smoothstep(x: NDArray[np.float64]) -> NDArray[np.float64]:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _as_points3(points: ArrayLike) -> NDArray[np.float64]:
    p = np.asarray(points, dtype=float)
    if p.shape == (3,):
        p = p[None, :]
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points: expected shape (N, 3), got {p.shape}")
    return p
