"""Environment speed: steps per second of the positioning env beside CartPole-v1.

Environment: ``indoorsim/Han2023Corridor-v8`` (the Han2023 L-shaped corridor,
its ``trajectory`` route: a walk of about 75 s, so about 75 one-second windows
of 50 IMU samples per episode), made with :func:`gymnasium.make` like
``CartPole-v1`` (so both carry Gymnasium's default wrappers). The agent is a
null agent: it always answers the start position (CartPole's: always push
left). Each is timed single and as a ``SyncVectorEnv`` of 8, in the same run,
on one thread.

Printed, in environment steps per second (a vector step of 8 envs counts 8):

- excluding resets: only ``step()`` calls on walks simulated beforehand, i.e.
  serving the windows of an already simulated walk and scoring the actions;
- including resets: stepping on and resetting whenever an episode ends, where
  every reset simulates a new walk (the vector env resets its sub-envs itself);

then the ratio of the single env's rate to CartPole's (target ≥ 0.25), and
the mean time of one reset. ``--profile`` adds where the time goes in
``step()`` and in ``reset()`` (cProfile, by internal time).

Run: ``python benchmarks/bench_env.py [--profile]``.
"""

from __future__ import annotations

import argparse
import cProfile
import functools
import pstats
import time
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import SyncVectorEnv
from threadpoolctl import threadpool_limits

import indoorsim.envs

ENV_ID = "indoorsim/Han2023Corridor-v8"
REFERENCE_ID = "CartPole-v1"
N_VECTOR = 8
TARGET_RATIO = 0.25
ROUNDS = 3  # each figure is the best of this many rounds


class StartAgent:
    """The positioning env's null agent: always the start position."""

    def act(self, info: dict[str, Any]) -> Any:
        return info["start_position"]

    def act_vector(self, infos: dict[str, Any], actions: np.ndarray | None, n: int) -> np.ndarray:
        """Actions after a vector reset; after an autoreset, only the reset sub-envs change."""
        if actions is None:
            return infos["start_position"].copy()
        mask = infos["_start_position"]
        actions[mask] = infos["start_position"][mask]
        return actions


class PushLeft:
    """CartPole's null agent: always push left."""

    def act(self, info: dict[str, Any]) -> Any:
        return 0

    def act_vector(self, infos: dict[str, Any], actions: np.ndarray | None, n: int) -> np.ndarray:
        return np.zeros(n, dtype=np.int64) if actions is None else actions


NullAgent = StartAgent | PushLeft


def single_excluding_resets(env: gym.Env, agent: NullAgent, episodes: int) -> float:
    """Steps/s of whole episodes, timing only the ``step()`` calls."""
    steps, elapsed = 0, 0.0
    for seed in range(episodes):
        _, info = env.reset(seed=seed)
        action = agent.act(info)
        terminated = truncated = False
        t0 = time.perf_counter()
        while not (terminated or truncated):
            _, _, terminated, truncated, _ = env.step(action)
            steps += 1
        elapsed += time.perf_counter() - t0
    return steps / elapsed


def single_including_resets(env: gym.Env, agent: NullAgent, steps: int) -> float:
    """Steps/s of stepping on, resetting (a new walk) whenever an episode ends."""
    t0 = time.perf_counter()
    _, info = env.reset(seed=0)
    action = agent.act(info)
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            _, info = env.reset()
            action = agent.act(info)
    return steps / (time.perf_counter() - t0)


def vector_excluding_resets(envs: SyncVectorEnv, agent: NullAgent, rounds: int) -> float:
    """Env-steps/s of a vector env up to its first finished episode, timing only steps.

    Stopping at the first step where any sub-env finishes keeps autoresets out
    of the timed steps: in Gymnasium's default (next-step) mode a sub-env is
    reset on the step *after* it finished.
    """
    n = envs.num_envs
    steps, elapsed = 0, 0.0
    for r in range(rounds):
        _, infos = envs.reset(seed=[r * n + i for i in range(n)])
        actions = agent.act_vector(infos, None, n)
        done = False
        t0 = time.perf_counter()
        while not done:
            _, _, terminated, truncated, _ = envs.step(actions)
            steps += n
            done = bool(terminated.any() or truncated.any())
        elapsed += time.perf_counter() - t0
    return steps / elapsed


def vector_including_resets(envs: SyncVectorEnv, agent: NullAgent, vector_steps: int) -> float:
    """Env-steps/s of a vector env stepping on, its sub-envs resetting themselves."""
    n = envs.num_envs
    t0 = time.perf_counter()
    _, infos = envs.reset(seed=0)
    actions = agent.act_vector(infos, None, n)
    for _ in range(vector_steps):
        _, _, _, _, infos = envs.step(actions)
        if "_start_position" in infos:
            actions = agent.act_vector(infos, actions, n)
    return vector_steps * n / (time.perf_counter() - t0)


def _best(measure: Callable[[], float]) -> float:
    return max(measure() for _ in range(ROUNDS))


def measure(env_id: str, agent: NullAgent, scale: int) -> dict[str, float]:
    """The four rates of one environment; ``scale`` sizes the runs to its cost."""
    env = gym.make(env_id)
    envs = SyncVectorEnv([functools.partial(gym.make, env_id)] * N_VECTOR)
    try:
        return {
            "single, excl. resets": _best(
                lambda: single_excluding_resets(env, agent, episodes=20 * scale)
            ),
            "single, incl. resets": _best(
                lambda: single_including_resets(env, agent, steps=800 * scale)
            ),
            f"sync x{N_VECTOR}, excl. resets": _best(
                lambda: vector_excluding_resets(envs, agent, rounds=3 * scale)
            ),
            f"sync x{N_VECTOR}, incl. resets": _best(
                lambda: vector_including_resets(envs, agent, vector_steps=200 * scale)
            ),
        }
    finally:
        env.close()
        envs.close()


def mean_reset_s(env_id: str, n: int = 10) -> float:
    env = gym.make(env_id)
    env.reset(seed=0)
    t0 = time.perf_counter()
    for seed in range(1, n + 1):
        env.reset(seed=seed)
    return (time.perf_counter() - t0) / n


def profile(env_id: str) -> None:
    """Print where the time goes in step() (whole episodes) and in reset()."""
    env = gym.make(env_id)
    steps = cProfile.Profile()
    for seed in range(20):
        _, info = env.reset(seed=seed)
        action = info["start_position"]
        terminated = False
        steps.enable()  # the resets between episodes stay out
        while not terminated:
            terminated = env.step(action)[2]
        steps.disable()
    resets = cProfile.Profile()
    resets.runcall(lambda: [env.reset(seed=seed) for seed in range(10)])
    for title, prof in (("step(), 20 whole episodes", steps), ("reset(), 10 new walks", resets)):
        print(f"\n--- {title}: by internal time ---")
        pstats.Stats(prof).sort_stats("tottime").print_stats(12)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", action="store_true", help="also profile step() and reset()")
    args = parser.parse_args()
    assert ENV_ID in indoorsim.envs.ENV_IDS
    with threadpool_limits(limits=1):
        gym.make(ENV_ID).reset(seed=0)  # load the site and compile the kernels
        ours = measure(ENV_ID, StartAgent(), scale=1)
        # CartPole's episodes under a constant push last ~10 steps: more of them.
        ref = measure(REFERENCE_ID, PushLeft(), scale=200)
        reset_s = mean_reset_s(ENV_ID)
    width = max(len(k) for k in ours)
    print(f"{'env steps per second':<{width}}  {ENV_ID:>30}  {REFERENCE_ID:>14}  ratio")
    for key in ours:
        ratio = ours[key] / ref[key]
        print(f"{key:<{width}}  {ours[key]:>30,.0f}  {ref[key]:>14,.0f}  {ratio:5.3f}")
    ratio = ours["single, excl. resets"] / ref["single, excl. resets"]
    verdict = "meets" if ratio >= TARGET_RATIO else "misses"
    print(
        f"\nsingle env / CartPole (excl. resets): {ratio:.3f}; {verdict} the target "
        f"of ≥ {TARGET_RATIO}"
    )
    print(f"one reset (a new walk simulated and windowed): {reset_s * 1e3:.1f} ms")
    if args.profile:
        with threadpool_limits(limits=1):
            profile(ENV_ID)


if __name__ == "__main__":
    main()
