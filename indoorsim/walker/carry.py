"""Carrying the phone: where it is and how it is turned, given the body's motion.

:func:`carry` follows a :class:`~indoorsim.walker.gait.BodyTrajectory` with the
phone in one or more carrying modes (DESIGN §5) — the built-in ``handheld``,
``calling``, ``dangling`` and ``pocketed`` of :mod:`indoorsim.walker.carry_modes`
(re-exported here), or a plugin's. At each change the hand takes the phone from
one mode's place to the next's: a minimum-jerk reach, and a pocket's stroke in or
out where a mode holds it in one (:mod:`indoorsim.walker.handling`).

Modes are components: frozen dataclasses whose fields are their parameters,
registered by name (the protocol and the registry, with its entry-point group
for other packages' modes, are in :mod:`indoorsim.walker.modes`). The
schedule :func:`carry` follows is a :class:`~indoorsim.walker.schedule.ModeSchedule`,
checked when it is made; :func:`carry` adds the checks that need the walk.

Frames (DESIGN §2): building frame x, y, z up; phone frame as Android's
sensor frame (x right, y up along the screen, z out of the screen); the body
frame used inside the modes has x forward, y left, z up. Orientations are
world←phone quaternions, scalar first. A phone lying flat, screen up, top
toward +y, has the identity quaternion.

``light_exposure`` scales the illuminance the light sensor would see with its
normal unobstructed (REALISM §3.5): 1 in the hand (the screen normal's sweep
already modulates the light), 0.05–0.2 at the ear (head shadow), 0.001–0.005
in a pocket (fabric). In the hand, the carrier's head and trunk shadow the
sensor geometrically instead (:mod:`indoorsim.walker.silhouette`): a mode
whose ``casts_body_shadow`` is False (at the ear, in a pocket) has its
exposure stand for the body it touches.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from indoorsim.walker import limbs
from indoorsim.walker.carry_modes import Calling, Dangling, Handheld, Pocketed
from indoorsim.walker.gait import BodyTrajectory, smootherstep
from indoorsim.walker.handling import handover
from indoorsim.walker.modes import (
    ENTRY_POINT_GROUP,
    MODES,
    CarryMode,
    ModePose,
    available_modes,
    get_mode,
    register_mode,
)
from indoorsim.walker.schedule import ModeSchedule, ScheduleError, ScheduleLike
from indoorsim.walker.silhouette import Carrier

__all__ = [
    "ENTRY_POINT_GROUP",
    "MODES",
    "Calling",
    "CarryMode",
    "Dangling",
    "Handheld",
    "ModePose",
    "PhoneTrajectory",
    "Pocketed",
    "Schedule",
    "available_modes",
    "carry",
    "get_mode",
    "register_mode",
]


@dataclass(frozen=True, kw_only=True, eq=False)
class PhoneTrajectory:
    """The phone's true motion, sampled like the body.

    Attributes:
        t: (K,) time in seconds.
        pos: (K, 3) phone position in the building frame, metres.
        quat: (K, 4) world←phone unit quaternion (w, x, y, z), sign-continuous.
        mode: (K,) carrying mode name at each sample (the new mode from the
            middle of a transition on).
        light_exposure: (K,) in [0, 1], the fraction of the unobstructed
            illuminance reaching the light sensor.
        carrier: the person carrying it, whose trunk shadows the phone's radio
            and whose head and trunk shadow its light sensor; None for a phone
            nobody carries.
    """

    t: NDArray[np.float64]
    pos: NDArray[np.float64]
    quat: NDArray[np.float64]
    mode: NDArray[np.str_]
    light_exposure: NDArray[np.float64]
    carrier: Carrier | None = None

    @property
    def torso_xy(self) -> NDArray[np.float64] | None:
        """(K, 2) the carrier's trunk axis in plan (the body centre), m, or None."""
        return None if self.carrier is None else self.carrier.torso_xy


# ---------------------------------------------------------------------- carry

Schedule = ScheduleLike
"""What :func:`carry` takes as its schedule (the name before :mod:`~indoorsim.walker.schedule`)."""


def carry(
    body: BodyTrajectory,
    schedule: ScheduleLike,
    rng: np.random.Generator,
    transition_s: float = 1.5,
) -> PhoneTrajectory:
    """The phone's trajectory while the walker carries it as ``schedule`` says.

    Args:
        body: the walker's body trajectory (from :func:`~indoorsim.walker.gait.walk`).
        schedule: a :class:`~indoorsim.walker.schedule.ModeSchedule`, or
            what :meth:`~indoorsim.walker.schedule.ModeSchedule.of` takes: a
            mode name for the whole walk, or a list of ``(t_start, mode_name)``
            or ``(t_start, mode_name, params)`` entries, the first at t = 0.
            Each later one must start at least ``transition_s`` after the one
            before and before the walk ends. ``params`` are the mode's
            fields, e.g. ``(0.0, "handheld", {"pitch_deg": 0.0})``.
        rng: the only source of randomness.
        transition_s: how long a change of mode takes (1–3 s, REALISM §6.1): the
            hand's minimum-jerk reach from one place to the next (positions blend
            C², orientations by slerp), and a pocket's stroke in or out
            (:mod:`~indoorsim.walker.handling`).

    Returns:
        The phone trajectory on the body's time base.

    Raises:
        ScheduleError: for a schedule that is malformed or does not fit the
            walk, or a ``transition_s`` too short for a pocket's stroke and the
            hand's reach (a ``ValueError``).
        UnknownModeError: for an unknown mode name (a ``KeyError``).
    """
    if not 0 < transition_s <= 10:
        raise ValueError(f"transition_s must be in (0, 10] s, got {transition_s}")
    entries = _parse_schedule(schedule, body, transition_s)
    t = body.t
    n = len(t)
    rngs = rng.spawn(len(entries))
    starts = [int(np.searchsorted(t, e[0], "left")) for e in entries]
    poses: list[tuple[int, ModePose]] = []
    for j, (mode, child) in enumerate(zip((e[1] for e in entries), rngs, strict=True)):
        i0 = starts[j]
        i1 = (
            n
            if j + 1 == len(entries)
            else int(np.searchsorted(t, entries[j + 1][0] + transition_s, "right"))
        )
        i1 = min(max(i1, i0 + 2), n)
        poses.append((i0, mode.pose(body.window(i0, i1), child)))

    pos = np.empty((n, 3))
    quat = np.empty((n, 4))
    light = np.empty(n)
    shade = np.empty(n)  # how much the body's own shadow counts (blended like the exposure)
    flags = [float(e[1].casts_body_shadow) for e in entries]
    # Each sample's mode as an index into the schedule: a string array of a
    # whole walk costs more to fill sample by sample than its poses do.
    which = np.empty(n, dtype=np.intp)
    for j, (i0, pose) in enumerate(poses):
        sl = slice(i0, i0 + len(pose.pos))
        pos[sl], light[sl] = pose.pos, pose.light_exposure
        shade[sl] = flags[j]
        limbs.put_scalar_first(quat[sl], pose.rot)
        which[sl] = j
        if j == 0:
            continue
        # The hand takes the phone from the previous mode's place, which was
        # evaluated past this start, to this one's (:func:`~.handling.handover`).
        prev_i0, prev = poses[j - 1]
        k = min(len(pose.pos), prev_i0 + len(prev.pos) - i0)
        a = slice(i0 - prev_i0, i0 - prev_i0 + k)
        tau = t[i0 : i0 + k] - t[i0]
        try:
            pos[i0 : i0 + k], reach, lit = handover(
                tau,
                transition_s,
                (prev.pos[a], prev.rot[a], prev.stroke),
                (pose.pos[:k], pose.rot[:k], pose.stroke),
            )
        except ValueError as exc:
            raise ScheduleError(f"schedule[{j}]: {exc}; give the change more time") from exc
        light[i0 : i0 + k] = (1 - lit) * prev.light_exposure[a] + lit * pose.light_exposure[:k]
        # The body's shade and the label pass over the whole change (the label from its middle).
        w = smootherstep(tau / transition_s)
        shade[i0 : i0 + k] = (1 - w) * flags[j - 1] + w * flags[j]
        limbs.put_scalar_first(quat[i0 : i0 + k], _slerp(prev.rot[a], pose.rot[:k], reach))
        which[i0 : i0 + k] = np.where(w < 0.5, j - 1, j)
    # Sized by the longest name in use, as a string array built from the names would be.
    used = np.flatnonzero(np.bincount(which, minlength=len(entries)))
    used_names = [entries[j][1].name for j in used]
    names = np.empty(len(entries), dtype=np.array(used_names).dtype)
    names[used] = used_names
    # ``which`` is a few long runs: filling each costs less than indexing per sample.
    cuts = [0, *(np.flatnonzero(which[1:] != which[:-1]) + 1).tolist(), n]
    mode = np.empty(n, dtype=names.dtype)
    for a, b in itertools.pairwise(cuts):
        mode[a:b] = names[which[a]]
    return PhoneTrajectory(
        t=t,
        pos=pos,
        quat=_sign_continuous(quat),
        mode=mode,
        light_exposure=np.clip(light, 0.0, 1.0),
        carrier=Carrier(
            t=t,
            pos=body.pos,
            trunk_yaw=body.yaw,
            height_m=body.height_m,
            shades=shade,
        ),
    )


def _parse_schedule(
    schedule: ScheduleLike, body: BodyTrajectory, transition_s: float
) -> list[tuple[float, CarryMode]]:
    """The schedule's modes, built, at their starts on ``body``'s clock.

    Raises:
        ScheduleError: a change after the walk ends or within ``transition_s``
            of the one before, besides what :class:`ModeSchedule` checks.
    """
    out: list[tuple[float, CarryMode]] = []
    for i, (t_start, name, params) in enumerate(ModeSchedule.of(schedule).entries):
        if i > 0 and t_start < out[-1][0] + transition_s:
            raise ScheduleError(
                f"schedule[{i}]: starts at {t_start} s, less than the {transition_s} s "
                f"transition after the previous mode at {out[-1][0]} s"
            )
        if i > 0 and t_start >= body.t[-1]:
            raise ScheduleError(f"schedule[{i}]: starts at {t_start} s, after the walk ends")
        out.append((max(t_start, float(body.t[0])), get_mode(name)(**params)))
    return out


def _slerp(a: Rotation, b: Rotation, w: NDArray[np.float64]) -> Rotation:
    """Per-sample slerp from ``a`` to ``b`` by ``w``, continuous in time.

    The relative rotation's log is unwrapped: when it passes through 180°
    the equivalent rotation vector on the other side is kept, so the blend
    does not jump from one way round to the other.
    """
    rel = (a.inv() * b).as_rotvec()
    # The other way round lies 2π from rel[k], so it can be nearer the previous
    # sample only across a step longer than π: test there (with a margin for
    # rounding), and on after every sample that was replaced.
    step = np.linalg.norm(np.diff(rel, axis=0), axis=1)
    done = 1
    for k in (np.flatnonzero(step > np.pi - 1e-6) + 1).tolist():
        if k < done:
            continue
        while k < len(rel) and _unwrap(rel, k):
            k += 1
        done = k + 1
    return a * Rotation.from_rotvec(rel * w[:, None])


def _unwrap(rel: NDArray[np.float64], k: int) -> bool:
    """Replace rel[k] by the other way round if that is nearer rel[k − 1]; whether it was."""
    angle = np.linalg.norm(rel[k])
    if angle > 1e-12:
        alt = rel[k] * (1.0 - 2.0 * np.pi / angle)
        if np.linalg.norm(alt - rel[k - 1]) < np.linalg.norm(rel[k] - rel[k - 1]):
            rel[k] = alt
            return True
    return False


def _sign_continuous(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Flip quaternion signs so consecutive samples stay on the same hemisphere (w ≥ 0 first).

    Works in place on ``q`` and returns it.
    """
    _sign_continuous_kernel(q)
    return q


@numba.njit(cache=True, error_model="numpy")
def _sign_continuous_kernel(q):  # pragma: no cover - compiled
    """Negate q[k] wherever an odd number of sign jumps (q[0] with w < 0, then each
    sample whose dot product with the one before, as given, is negative) lies up to k."""
    flip = False
    pw, px, py, pz = 1.0, 0.0, 0.0, 0.0  # q[0] is compared with the identity: its w ≥ 0
    for k in range(q.shape[0]):
        w, x, y, z = q[k, 0], q[k, 1], q[k, 2], q[k, 3]
        if (w * pw + x * px + y * py + z * pz < 0) if k > 0 else (w < 0):
            flip = not flip
        pw, px, py, pz = w, x, y, z
        if flip:
            q[k, 0], q[k, 1], q[k, 2], q[k, 3] = -w, -x, -y, -z
