"""Normal gait's hip and pelvis angles over a gait cycle, as periodic splines.

The pocketed phone's thigh turns at the hip in three planes
(:class:`~indoorsim.walker.pocketed.Pocketed`): flexion, rotation about the
thigh, and the pelvis's sideways list. Each curve is a function of the gait
cycle's phase in [0, 1) from that side's heel strike, scaled to ±1; a mode
scales it by its drawn amplitude.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

__all__ = ["HIP_FLEXION", "HIP_ROTATION", "PELVIC_LIST"]


def _unit_periodic(p: np.ndarray, deg: np.ndarray) -> CubicSpline:
    """The periodic cubic spline through knots ``deg`` at phases ``p``, shifted and scaled
    so that the curve (sampled on 1001 points) spans exactly −1 to +1."""
    grid = np.linspace(0.0, 1.0, 1001)
    raw = CubicSpline(p, deg, bc_type="periodic")(grid)
    mid, half = 0.5 * (raw.max() + raw.min()), 0.5 * np.ptp(raw)
    return CubicSpline(p, (deg - mid) / half, bc_type="periodic")


def _hip_flexion() -> CubicSpline:
    """The hip's sagittal angle over a gait cycle from heel strike, scaled to ±1.

    Knots read off the normal-gait hip flexion curve (Winter, *Biomechanics and
    Motor Control of Human Movement*, 2009: ≈ 25° flexed at heel strike,
    ≈ 10° extended at 55 % of the cycle, ≈ 30° flexed late in swing) [E],
    joined by a periodic cubic spline.
    """
    p = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.55, 0.62, 0.7, 0.8, 0.88, 0.95, 1.0])
    deg = np.array([25.0, 23.0, 15.0, 7.0, 0.0, -8.0, -10.0, -4.0, 8.0, 22.0, 28.0, 27.0, 25.0])
    return _unit_periodic(p, deg)


HIP_FLEXION = _hip_flexion()


def _pelvic_list() -> CubicSpline:
    """The pelvis's frontal-plane tilt over a gait cycle from one side's heel strike,
    that side up positive, scaled to ±1.

    Knots read off normal gait's pelvic obliquity (Perry & Burnfield, *Gait
    Analysis*, 2010; Winter 2009): in that side's loading response the other,
    unloaded side drops fast — the hip on the loaded side rises relative to it,
    most at 12–15 % of the cycle — and it levels slowly through single support;
    the next half cycle mirrors it [E]. The fast drop puts the stride's third
    harmonic into the hip's vertical motion.
    """
    p = np.array([0.0, 0.05, 0.13, 0.2, 0.3, 0.4, 0.5])
    up = np.array([0.0, 0.6, 1.0, 0.9, 0.5, 0.2, 0.0])
    p, up = np.r_[p, p[1:] + 0.5], np.r_[up, -up[1:]]
    return CubicSpline(p, up, bc_type="periodic")


PELVIC_LIST = _pelvic_list()


def _hip_rotation() -> CubicSpline:
    """The thigh's rotation about its long axis relative to the pelvis over a gait cycle
    from that side's heel strike, internal rotation positive, scaled to ±1.

    Knots read off normal gait's hip transverse-plane rotation (Perry & Burnfield,
    *Gait Analysis*, 2010; Kadaba et al., J Orthop Res 8:383, 1990: a range of
    8–15°): the limb rotates internally through loading response, most at
    10–15 % of the cycle, externally through single support to its most at
    toe-off (≈ 60 %), and internally again through swing [E]. Stance's slow
    external turn and swing's quick return put the stride's second and third
    harmonics into its rate.
    """
    p = np.array([0.0, 0.06, 0.13, 0.25, 0.4, 0.52, 0.62, 0.7, 0.8, 0.9, 1.0])
    deg = np.array([0.3, 0.8, 1.0, 0.6, -0.1, -0.7, -1.0, -0.6, 0.1, 0.2, 0.3])
    return _unit_periodic(p, deg)


HIP_ROTATION = _hip_rotation()
