"""The indoor-positioning environment: a simulated walk served window by window (DESIGN §9).

The environment joins the simulator and the estimators: each episode simulates
one walk through a scenario's building (:func:`indoorsim.simulate.simulate`),
cuts its sensor streams into observation windows
(:class:`indoorsim.windows.Windower`) and scores the agent's position
estimate at the end of every window against the exact truth, exactly as
:func:`indoorsim.benchmark.evaluation.run_episode` does for the benchmark runner.
"""

from __future__ import annotations

import functools
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.text import Text
from numpy.typing import NDArray

from indoorsim.benchmark.evaluation import (
    site_context,
    start_info,
    true_positions_at,
    window_samples,
)
from indoorsim.estimators.base import SiteContext
from indoorsim.io.faults import Fault, apply_faults, parse_fault, walk_arguments
from indoorsim.phone.devices import get_device
from indoorsim.plots import draw_plan
from indoorsim.scenario.load import load_site
from indoorsim.simulate import route_spec, simulate
from indoorsim.walker.schedule import ModeSchedule, ScheduleLike
from indoorsim.windows import Observation, Windower, observation_space

__all__ = ["ACTION_MARGIN_M", "MAX_WINDOW_S", "IndoorPositioningEnv"]

ACTION_MARGIN_M = 10.0
"""How far beyond the floor plan's bounds the action space reaches, m."""

MAX_WINDOW_S = 60.0
"""The longest window one step may play, s: the observation arrays, and the
space's bounds allocated at construction, grow with it."""

_RESET_OPTIONS = ("route", "mode")
_WALK_SEED_BOUND = 2**31  # walk seeds drawn by the env lie in [0, 2**31)
_RENDER_LONG_IN = 5.6
_RENDER_MIN_WIDTH_IN = 3.0
_RENDER_MIN_HEIGHT_IN = 1.2
_RENDER_DPI = 100
_TRUTH_COLOUR = "black"
_ESTIMATE_COLOUR = "#d62728"


def _describe(action: object) -> str:
    """A short description of a rejected action, for error messages."""
    try:
        a = np.asarray(action)
    except (ValueError, TypeError):
        return repr(action)
    values = np.array2string(a, threshold=6, edgeitems=2) if a.dtype != object else repr(action)
    return f"{type(action).__name__} {values} (shape {a.shape}, dtype {a.dtype})"


@dataclass
class _RenderFrame:
    """The figure that ``render()`` redraws: the plan once, the tracks per call."""

    fig: Figure
    truth: Line2D
    estimate: Line2D
    start: Line2D
    title: Text


@dataclass(frozen=True)
class _Episode:
    """One simulated walk, prepared at reset so that ``step()`` only looks things up."""

    windows: Windower
    route: str
    walk_seed: int
    start_position: NDArray[np.float64]
    t_end: list[float]  # end time of each window, s
    truth_end: list[list[float]]  # true (x, y) at each window's end, m
    track_t: NDArray[np.float64]  # the truth stream, for render()
    track_xy: NDArray[np.float64]
    estimates: NDArray[np.float64]  # (n_windows, 2), filled in as the agent acts


class IndoorPositioningEnv(gym.Env[Observation, NDArray[np.float64]]):
    """Estimate a walking pedestrian's position from the phone's sensor streams.

    ## Description

    Each episode is one walk, simulated afresh: a pedestrian follows one of the
    scenario's routes through the building, carrying a phone (``device``) in
    a carrying mode or a schedule of modes. The phone's accelerometer,
    gyroscope, magnetometer, light sensor, WiFi scans and fused rotation
    sensors arrive one fixed-length window at a time, and after each window
    the agent says where the phone is. The building's public knowledge — the
    floor plan and the fingerprint databases that the scenario's surveys
    measured with a second phone (``survey_device``) — is
    ``env.unwrapped.site_context``, a
    :class:`~indoorsim.estimators.base.SiteContext` to ``fit`` estimators on.
    It is built on first use (the surveys take a few seconds) and shared by
    every environment of the process with the same site and phones.

    An episode is the same as :func:`indoorsim.benchmark.evaluation.run_episode` with
    the same scenario, route, mode, device and seed: the same windows, scored
    at the same times against the same truth.

    ## Observation Space

    A ``Dict`` of one window of ``W`` IMU samples (``W`` = ``window_s`` times
    the device's IMU rate, 50 for the Nexus 5X and one second) over the
    site's ``A`` WiFi access points: :func:`indoorsim.windows.observation_space`
    ``(W, A)``. The table of keys, shapes and units is in
    :mod:`indoorsim.windows`: the IMU streams sample by sample, the slower
    sensors held with freshness masks, the latest WiFi scan as a vector over
    the site's APs (in ``site_context.bssids`` order). The last window of a
    walk may be short: ``valid`` marks its real samples. Observations never
    contain truth.

    ## Action Space

    ``Box(low=(xmin - 10, ymin - 10), high=(xmax + 10, ymax + 10), shape=(2,),
    dtype=float64)``: the estimated (x, y) of the phone at the *end* of the
    current window (``info["t"]`` of the coming step), in metres in the
    building frame, where ``(xmin, ymin, xmax, ymax)`` are the floor plan's
    bounds. An action that is not two finite real numbers, or lies outside
    the box (more than 10 m beyond the floor plan: no estimate of a position
    in the building), raises :class:`ValueError` saying what it was and the
    box's bounds.

    ## Rewards

    Minus the position error in metres: ``-‖action - truth(t_end)‖``, where
    ``truth(t_end)`` is the phone's true (x, y) at the window's last sample
    (interpolated from the 200 Hz truth stream). The return is minus the sum
    of the errors; divide by the episode length for the mean error (AE).

    ## Starting State

    ``reset`` simulates a new walk. Its seed is ``seed`` when given, else
    drawn from the environment's ``np_random`` (so ``reset(seed=s)`` followed
    by unseeded resets is a reproducible sequence of walks). It returns the
    first window and an info dict with what an experimenter tells the
    estimator at the start, as in the papers, and nothing more:

    - ``start_position``: (2,) true (x, y) at the first sample, m;
    - ``start_heading``: the initial walking direction, rad counter-clockwise
      from the building's +x;
    - ``walk_seed``: the walk's seed (for estimators that sample);
    - ``t``: the time of the first sample, s.

    ``options`` may override, for this episode only, ``"route"`` (a route
    name of the scenario) and ``"mode"`` (a carrying-mode name or schedule).

    After each step, ``info`` reveals the truth of the window just scored:
    ``true_position`` ((2,) m), ``error_m`` and ``t`` (the window's end, s).

    ## Episode End

    The episode terminates when the window at the route's end has been
    scored; the final observation repeats that last window. Episodes are
    never truncated (the walk's length sets the number of steps, about one
    per ``window_s`` seconds walked).

    ## Arguments

    - ``scenario``: a bundled scenario name (``indoorsim scenarios`` lists
      them) or the path of a scenario YAML file.
    - ``route``: a route name of the scenario; default its first route.
    - ``mode``: a carrying mode (``"handheld"``, ``"calling"``,
      ``"dangling"``, ``"pocketed"`` or a plugin's) or a schedule
      ``[(t_start, mode[, params]), ...]`` (or a
      :class:`~indoorsim.walker.schedule.ModeSchedule`); default ``"handheld"``.
    - ``device``: the walking phone's profile; default ``"nexus_5x"``.
    - ``survey_device``: the phone of the offline surveys; default ``"honor_50"``.
    - ``window_s``: window length, s, at most ``MAX_WINDOW_S`` (60 s); default 1.0.
    - ``render_mode``: ``None`` or ``"rgb_array"`` (the floor plan with the
      true track and the estimates so far).
    - ``faults``: sensor faults (:mod:`indoorsim.io.faults`: spec strings such
      as ``"gap:t0=20,t1=30"`` or fault objects) applied in order to every
      walk, as ``indoorsim evaluate --fault`` does: fault ``i`` of the walk of
      seed ``s`` draws from ``fault_rng(s, i)``. A ``mode_change`` or
      ``wrong_device`` fault walks with another carrying mode or phone than
      ``mode`` and ``device`` say; ``site_context`` stays the declared one's.
      Observations may then hold NaN (``nan_burst``) or lack streams
      (``missing``), as a faulty phone's would. Default: none.

    The registered ids ``indoorsim/<Scenario>-v11`` fix ``scenario``; pass
    the others to :func:`gymnasium.make`.

    ## Version History

    - v0: initial version.
    - v1: ``present`` has a seventh flag, for the game rotation vector. Later
      (no reward changed): an action outside the action space raises
      ``ValueError``, where it was scored as it was; the ``faults`` argument
      (default none: the same walks as before).
    - v2: the simulated walks changed (the held phone at the reader's eyes' distance
      and gaze, the pocket's hip rotation and rocking, the handset's and the APs'
      antenna patterns, car parks with half their aisle lights off): a seed gives
      other observations and errors. Spaces, rewards and arguments are unchanged.
    - v3: the held phone's walks changed (the arm holds the hand in place against the
      trunk's surge and sway, it follows a third of the trunk's yaw and wanders
      slowly in yaw, it bobs with the elbow at the holding side): a seed gives
      other observations and errors. Spaces, rewards and arguments are unchanged.
    - v4: the held phone's walks changed again (the abducted upper arm twists about its
      axis under every jolt, moving the hand sideways; the phone rocks less about its
      long axis, follows part of the trunk's lean, and its wrist is damped harder and
      stiffer sideways): a seed gives other observations and errors. Spaces, rewards
      and arguments are unchanged.
    - v5: the WiFi scans changed (a 5 GHz radio of the storey above or below loses
      32 dB through the slab where a 2.4 GHz one loses 18.5, as concrete's loss
      grows with frequency): a seed gives other scans and WiFi errors. Spaces,
      rewards and arguments are unchanged.
    - v6: the walks changed (the trunk leans forward within each step and its heel
      strike's jolt peaks with the loading; the held phone nods with the trunk, its
      wrist is stiffer in flexion and it tilts slowly while walking; the held phone's
      roll on its thumb-side offset, which came without a bump): a seed gives other
      observations and errors. Spaces, rewards and arguments are unchanged.
    - v7: the walks changed (the trunk leans sideways toward the stance leg, as its
      roll always said, where the held and calling phones leaned it toward the swing
      leg; the held hand is held sideways more softly): a seed gives other
      observations and errors. Spaces, rewards and arguments are unchanged.
    - v8: the walks changed (the held arm turns about the shoulder under each vertical
      jolt, so the hand surges with it; the reading pose's eyes are those of a head
      bent over the phone, so the hand rests lower and further ahead; walkers' default
      loading peak is the one the ILC surveyors fit): a seed gives other observations
      and errors. Spaces, rewards and arguments are unchanged.
    - v9: the walks changed (the body's forward surge is the ground's push through the
      stance leg — braking as the leading leg takes the load, pushing off before it —
      where it was one sinusoid; ``WalkerParams.speed_oscillation`` gave way to
      ``double_support`` and ``cop_travel_m``): a seed gives other observations and
      errors. Spaces, rewards and arguments are unchanged.
    - v10: the walks changed (the walker weaves a few centimetres off the line it
      means to walk, ``WalkerParams.meander_m``; the swinging arm's forearm and hand
      are pulled back under the elbow and wrist by gravity, the elbow 1.0–1.15 Hz
      where 1.3–1.8 Hz rang near the step rate): a seed gives other observations and
      errors. Spaces, rewards and arguments are unchanged.
    - v11: the walks changed (a walker's longer steps take longer too,
      ``WalkerParams.asymmetry``; the swinging arm swings ±12–18° a little behind the
      legs, its elbow bent 10–20° and, with the wrist, firm): a seed gives other
      observations and errors. Spaces, rewards and arguments are unchanged.

    Example:
        >>> import gymnasium as gym
        >>> import indoorsim.envs
        >>> env = gym.make("indoorsim/MinimalRoom-v11")
        >>> obs, info = env.reset(seed=1)
        >>> obs["accel"].shape
        (50, 3)
        >>> obs, reward, terminated, truncated, info = env.step(info["start_position"])
        >>> bool(reward == -info["error_m"])
        True
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"], "render_fps": 1.0}

    def __init__(
        self,
        scenario: str | os.PathLike[str],
        route: str | None = None,
        mode: ScheduleLike = "handheld",
        device: str = "nexus_5x",
        survey_device: str = "honor_50",
        window_s: float = 1.0,
        render_mode: str | None = None,
        faults: Sequence[str | Fault] = (),
    ):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        if (
            isinstance(window_s, bool)
            or not isinstance(window_s, int | float)
            or not 0 < window_s <= MAX_WINDOW_S
        ):
            raise ValueError(
                f"window_s must be a number of seconds in (0, {MAX_WINDOW_S:g}], got {window_s!r}"
            )
        self.scenario = scenario
        # One Site per scenario file and process (load_site caches it): the
        # surveys of site_context() are cached per Site, so envs on the same
        # building survey it once.
        self._site = load_site(scenario)
        routes = list(self._site.scenario.routes)
        if not routes:
            raise ValueError(f"scenario {self._site.name!r} has no routes to walk")
        self.route = self._check_route(routes[0] if route is None else route)
        self.mode = mode
        self._schedule = ModeSchedule.of(mode)
        imu_rate_hz = get_device(device).accel.rate_hz
        get_device(survey_device)  # fail now, not at the first survey
        if isinstance(faults, str | Fault):
            faults = (faults,)
        self.faults = tuple(parse_fault(f) if isinstance(f, str) else f for f in faults)
        walk_arguments(self.faults, self._schedule, device)  # a walk fault's error now
        self.device = device
        self.survey_device = survey_device
        self.window_s = float(window_s)
        self.render_mode = render_mode
        # One step plays window_s seconds of the walk.
        self.metadata = {**self.metadata, "render_fps": 1.0 / self.window_s}
        # The same window length and AP order as site_context() gives, computed
        # without the surveys so that constructing an env stays cheap.
        self.window_samples = window_samples(imu_rate_hz, self.window_s)
        self.bssids = tuple(self._site.radio.bssids)
        self.observation_space = observation_space(self.window_samples, len(self.bssids))
        xmin, ymin, xmax, ymax = self._site.plan.bounds
        self.action_space = gym.spaces.Box(
            low=np.array([xmin - ACTION_MARGIN_M, ymin - ACTION_MARGIN_M]),
            high=np.array([xmax + ACTION_MARGIN_M, ymax + ACTION_MARGIN_M]),
            dtype=np.float64,
        )
        self._episode: _Episode | None = None
        self._k = 0  # the window the agent is looking at
        self._frame: _RenderFrame | None = None

    # ------------------------------------------------------------------ API

    @functools.cached_property
    def site_context(self) -> SiteContext:
        """The site's public knowledge for ``fit``.

        The surveys run once per process and site (then cached); each env gets
        its own copy of the tables, so an estimator that edits them in ``fit``
        does not change what another env's estimator sees.
        """
        return site_context(
            self._site,
            device=self.device,
            survey_device=self.survey_device,
            window_s=self.window_s,
        )

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Observation, dict[str, Any]]:
        """Simulate a new walk and return its first window (see ``## Starting State``)."""
        super().reset(seed=seed)
        route, mode = self._episode_options(options or {})
        walk_seed = int(self.np_random.integers(_WALK_SEED_BOUND)) if seed is None else int(seed)
        walk_mode, walk_device = walk_arguments(self.faults, mode, self.device)
        rec = simulate(self._site, route=route, mode=walk_mode, device=walk_device, seed=walk_seed)
        rec = apply_faults(rec, self.faults, walk_seed)
        start = start_info(rec, walk_seed)
        windows = Windower(rec, self.window_samples, self.bssids)
        t_end = np.array([windows.end_time(k) for k in range(len(windows))])
        truth = rec.truth
        self._episode = _Episode(
            windows=windows,
            route=route,
            walk_seed=walk_seed,
            start_position=start.position,
            # Plain floats: step() reads one entry per call, faster than from arrays.
            t_end=t_end.tolist(),
            truth_end=true_positions_at(rec, t_end).tolist(),
            track_t=truth.index.to_numpy(dtype=float),
            track_xy=truth[["x", "y"]].to_numpy(dtype=float),
            estimates=np.full((len(windows), 2), np.nan),
        )
        self._k = 0
        info = {
            "start_position": start.position.copy(),
            "start_heading": start.heading,
            "walk_seed": walk_seed,
            "t": start.t0,
        }
        return windows.window(0), info

    def step(
        self, action: NDArray[np.float64]
    ) -> tuple[Observation, float, bool, bool, dict[str, Any]]:
        """Score ``action`` as the position at the current window's end; serve the next window."""
        episode = self._episode
        if episode is None:
            raise RuntimeError("call reset() before step()")
        k = self._k
        n = len(episode.t_end)
        if k >= n:
            raise RuntimeError("the episode has terminated; call reset() to start a new one")
        x, y = self._check_action(action)
        tx, ty = episode.truth_end[k]
        error = math.hypot(x - tx, y - ty)
        episode.estimates[k] = (x, y)
        self._k = k + 1
        terminated = self._k == n
        obs = episode.windows.window(k if terminated else k + 1)
        info = {"true_position": np.array((tx, ty)), "error_m": error, "t": episode.t_end[k]}
        return obs, -error, terminated, False, info

    def render(self) -> NDArray[np.uint8] | None:
        """An (H, W, 3) uint8 image: the plan, the true track and the estimates so far."""
        if self.render_mode is None:
            gym.logger.warn(
                "render() was called without a render mode; "
                'create the environment with render_mode="rgb_array"'
            )
            return None
        if self._frame is None:
            self._frame = self._new_frame()
        frame = self._frame
        episode = self._episode
        if episode is None:
            for line in (frame.truth, frame.estimate, frame.start):
                line.set_data([], [])
            frame.title.set_text(f"{self._site.name}: no episode yet")
        else:
            scored = self._k
            t_now = episode.t_end[scored - 1] if scored else episode.track_t[0]
            upto = int(np.searchsorted(episode.track_t, t_now, side="right"))
            frame.truth.set_data(episode.track_xy[:upto, 0], episode.track_xy[:upto, 1])
            frame.estimate.set_data(episode.estimates[:scored, 0], episode.estimates[:scored, 1])
            frame.start.set_data([episode.start_position[0]], [episode.start_position[1]])
            text = (
                f"{self._site.name} · {episode.route} · seed {episode.walk_seed}"
                f" · t = {t_now:.1f} s"
            )
            if scored:
                est, true = episode.estimates[scored - 1], episode.truth_end[scored - 1]
                text += f" · error {math.hypot(est[0] - true[0], est[1] - true[1]):.2f} m"
            frame.title.set_text(text)
        canvas = frame.fig.canvas
        canvas.draw()
        return np.asarray(canvas.buffer_rgba())[:, :, :3].copy()

    def close(self) -> None:
        """Release the render figure."""
        self._frame = None
        super().close()

    # ------------------------------------------------------------- pickling

    def __getstate__(self) -> dict[str, Any]:
        # The Site is left out and looked up again from the scenario on
        # unpickling: envs of one process then share it (and its surveys), and
        # the pickle stays small. The render figure is rebuilt when next needed.
        state = self.__dict__.copy()
        del state["_site"]
        state["_frame"] = None
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._site = load_site(self.scenario)

    # ------------------------------------------------------------- helpers

    def _check_route(self, route: str) -> str:
        route_spec(self._site, route)
        return route

    def _episode_options(self, options: dict[str, Any]) -> tuple[str, ModeSchedule]:
        unknown = sorted(set(options) - set(_RESET_OPTIONS))
        if unknown:
            raise ValueError(
                f"unknown reset option(s) {unknown}; valid options: {list(_RESET_OPTIONS)}"
            )
        route = self._check_route(options["route"]) if "route" in options else self.route
        mode = ModeSchedule.of(options["mode"]) if "mode" in options else self._schedule
        return route, mode

    def _check_action(self, action: object) -> tuple[float, float]:
        """The action as two floats, or ValueError saying what was wrong."""
        expected = "expected the (x, y) position estimate in metres: 2 finite real numbers"
        try:
            a = np.asarray(action)
        except (ValueError, TypeError):
            raise ValueError(f"invalid action {_describe(action)}; {expected}") from None
        if a.shape != (2,) or a.dtype.kind not in "fiu":
            raise ValueError(f"invalid action {_describe(action)}; {expected}, shape (2,)")
        x, y = float(a[0]), float(a[1])
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError(f"non-finite action {_describe(action)}; {expected}")
        (xlo, ylo), (xhi, yhi) = self.action_space.low, self.action_space.high
        if not (xlo <= x <= xhi and ylo <= y <= yhi):
            raise ValueError(
                f"action {_describe(action)} is outside the action space: x in "
                f"[{xlo:g}, {xhi:g}] m, y in [{ylo:g}, {yhi:g}] m (the floor plan's bounds "
                f"± {ACTION_MARGIN_M:g} m)"
            )
        return x, y

    def _new_frame(self) -> _RenderFrame:
        xmin, ymin, xmax, ymax = self._site.plan.bounds
        # The plan's long side gets _RENDER_LONG_IN inches, and the axes stay wide
        # enough for the legend above them. Margins are in inches, for the labels.
        w, h = max(xmax - xmin, 1e-3), max(ymax - ymin, 1e-3)
        scale = _RENDER_LONG_IN / max(w, h)
        axes_w, axes_h = max(w * scale, _RENDER_MIN_WIDTH_IN), max(h * scale, _RENDER_MIN_HEIGHT_IN)
        left, right, bottom, top = 0.7, 0.15, 0.5, 0.6
        fig = Figure(figsize=(axes_w + left + right, axes_h + bottom + top), dpi=_RENDER_DPI)
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        fig.subplots_adjust(
            left=left / fig.get_figwidth(),
            right=1 - right / fig.get_figwidth(),
            bottom=bottom / fig.get_figheight(),
            top=1 - top / fig.get_figheight(),
        )
        draw_plan(
            ax,
            self._site.plan,
            obstacle_kinds=[o.kind for o in self._site.scenario.obstacles],
            legend=False,
        )
        (truth,) = ax.plot([], [], color=_TRUTH_COLOUR, linewidth=1.5, zorder=4, label="truth")
        (estimate,) = ax.plot(
            [],
            [],
            color=_ESTIMATE_COLOUR,
            linewidth=1.0,
            marker="o",
            markersize=2.5,
            zorder=5,
            label="estimate",
        )
        (start,) = ax.plot(
            [],
            [],
            linestyle="none",
            marker="o",
            markersize=8,
            markerfacecolor="white",
            markeredgecolor="black",
            zorder=6,
            label="start",
        )
        ax.legend(
            handles=[truth, estimate, start],
            loc="lower right",
            bbox_to_anchor=(1.0, 1.0),
            ncols=3,
            fontsize=7,
            frameon=False,
        )
        # The title's own line, above the legend's: a long scenario name cannot collide with it.
        title = fig.text(0.02, 0.98, "", fontsize=8, verticalalignment="top")
        return _RenderFrame(fig=fig, truth=truth, estimate=estimate, start=start, title=title)
