"""The positioning environments: Gymnasium's contract, determinism, scoring, and the runner.

The contract tests run over every id registered to
:class:`~indoorsim.envs.positioning.IndoorPositioningEnv`; the error handling
tests need only one (the smallest scenario).
"""

from __future__ import annotations

import doctest
import functools
import math
import pickle
import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env, data_equivalence
from gymnasium.vector import AsyncVectorEnv, SyncVectorEnv

import indoorsim
import indoorsim.envs
import indoorsim.envs.positioning
from indoorsim.benchmark.evaluation import run_episode, start_info, true_positions_at
from indoorsim.envs.positioning import IndoorPositioningEnv
from indoorsim.estimators.base import SiteContext, StartInfo
from indoorsim.io.faults import FaultError, apply_faults
from indoorsim.scenario import bundled_scenarios
from indoorsim.simulate import simulate
from indoorsim.windows import Observation, Windower

ENV_IDS = sorted(
    env_id
    for env_id, spec in gym.registry.items()
    if spec.entry_point == indoorsim.envs.ENTRY_POINT
)
SMALL = "indoorsim/MinimalRoom-v11"
# Gymnasium recommends a [-1, 1] action box; ours is a position in metres, by design.
_ACTION_BOX_ADVICE = "we recommend using a symmetric and normalized space"


def _start(info: dict) -> StartInfo:
    return StartInfo(
        position=info["start_position"],
        heading=info["start_heading"],
        seed=info["walk_seed"],
        t0=info["t"],
    )


def _walk(env: gym.Env, seed: int):
    """An independent simulation of the walk that ``env.reset(seed=seed)`` serves."""
    env = env.unwrapped
    site = indoorsim.load_site(env.scenario)
    return simulate(site, route=env.route, mode=env.mode, device=env.device, seed=seed)


def _rollout(env: gym.Env, seed: int) -> dict[str, list]:
    """Observations, rewards and infos of one whole episode of the null agent (the start)."""
    obs, info = env.reset(seed=seed)
    out = {"obs": [obs], "reward": [], "info": [info], "terminated": []}
    start = info["start_position"]
    terminated = False
    while not terminated:
        obs, reward, terminated, truncated, info = env.step(start)
        assert truncated is False
        for key, value in zip(out, (obs, reward, info, terminated), strict=True):
            out[key].append(value)
    return out


class _Recorder:
    """A fake estimator: keeps what it is shown and walks to and fro on a line from the start
    (2 m at most, so that it stays in the action space)."""

    name = "recorder"

    def __init__(self) -> None:
        self.start: StartInfo | None = None
        self.seen: list[Observation] = []

    def fit(self, site: SiteContext, train: object) -> None:
        """Nothing to learn."""

    def reset(self, start: StartInfo) -> None:
        self.start, self.seen = start, []

    def act(self, obs: Observation) -> np.ndarray:
        self.seen.append(obs)
        assert self.start is not None
        return self.start.position + 0.25 * (len(self.seen) % 8)


# ---------------------------------------------------------------- registration


def test_every_bundled_scenario_is_registered_in_camel_case():
    assert ENV_IDS == sorted(indoorsim.envs.ENV_IDS)
    assert {gym.spec(i).kwargs["scenario"] for i in ENV_IDS} == set(bundled_scenarios())
    assert indoorsim.envs.env_id("han2023_corridor") == "indoorsim/Han2023Corridor-v11"
    assert indoorsim.envs.env_id("minimal_room") == "indoorsim/MinimalRoom-v11"
    for env_id in ENV_IDS:
        spec = gym.spec(env_id)
        assert spec.namespace == "indoorsim" and spec.version == indoorsim.envs.VERSION == 11
        assert spec.entry_point == "indoorsim.envs.positioning:IndoorPositioningEnv"
        assert spec.max_episode_steps is None
        assert spec.id == indoorsim.envs.env_id(spec.kwargs["scenario"])


def test_module_colon_id_makes_the_env_without_an_import():
    code = (
        "import gymnasium as gym, sys\n"
        "env = gym.make('indoorsim.envs:indoorsim/MinimalRoom-v11')\n"
        "print(type(env.unwrapped).__name__, 'indoorsim.envs' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["IndoorPositioningEnv", "True"]


def test_docstring_examples_run():
    for module in (indoorsim.envs, indoorsim.envs.positioning):
        result = doctest.testmod(module)
        assert result.attempted > 0 and result.failed == 0, module.__name__


# ---------------------------------------------------------------- the contract


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_check_env_passes_with_only_the_action_box_advice(env_id):
    env = gym.make(env_id)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    others = [str(w.message) for w in caught if _ACTION_BOX_ADVICE not in str(w.message)]
    assert others == []


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_episode_other_seed_other_walk(env_id):
    env = gym.make(env_id)
    first, again, other = (_rollout(env, seed) for seed in (7, 7, 8))
    for key in first:
        assert data_equivalence(first[key], again[key], exact=True), key
    assert first["terminated"][-1] and not any(first["terminated"][:-1])
    assert not np.array_equal(first["obs"][0]["accel"], other["obs"][0]["accel"])
    assert first["reward"] != other["reward"][: len(first["reward"])]
    assert (first["info"][0]["walk_seed"], other["info"][0]["walk_seed"]) == (7, 8)
    # Every window is in the space, and the final observation repeats the last window.
    assert all(obs in env.observation_space for obs in first["obs"])
    assert data_equivalence(first["obs"][-1], first["obs"][-2], exact=True)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_unseeded_resets_follow_the_env_seed(env_id):
    env = gym.make(env_id)
    env.reset(seed=3)
    seeds = [env.reset()[1]["walk_seed"] for _ in range(2)]
    env.reset(seed=3)
    assert [env.reset()[1]["walk_seed"] for _ in range(2)] == seeds
    assert len(set(seeds)) == 2


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_null_agent_loses_the_distance_from_the_start(env_id):
    env = gym.make(env_id)
    episode = _rollout(env, seed=11)
    rec = _walk(env, seed=11)
    truth = rec.truth
    start = np.array([truth["x"].iloc[0], truth["y"].iloc[0]])
    np.testing.assert_array_equal(episode["info"][0]["start_position"], start)
    # Each window is scored at its last IMU sample, against the truth stream there.
    t = np.array([info["t"] for info in episode["info"][1:]])
    w = env.observation_space["accel"].shape[0]
    t_imu = rec.accel.index.to_numpy()
    np.testing.assert_array_equal(t, t_imu[np.r_[w - 1 : len(t_imu) : w, len(t_imu) - 1]][: len(t)])
    ts = truth.index.to_numpy()
    true_xy = np.column_stack([np.interp(t, ts, truth[c].to_numpy()) for c in ("x", "y")])
    np.testing.assert_allclose(
        episode["reward"], -np.linalg.norm(true_xy - start, axis=1), rtol=0, atol=1e-12
    )
    for info, reward, xy in zip(episode["info"][1:], episode["reward"], true_xy, strict=True):
        np.testing.assert_allclose(info["true_position"], xy, rtol=0, atol=1e-12)
        assert info["error_m"] == -reward and isinstance(reward, float)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_reset_reveals_the_start_and_no_other_truth(env_id):
    env = gym.make(env_id)
    obs, info = env.reset(seed=1)
    assert set(info) == {"start_position", "start_heading", "walk_seed", "t"}
    assert info["start_position"].shape == (2,) and math.isfinite(info["start_heading"])
    assert set(obs) == set(env.observation_space.spaces)
    assert not {"truth", "x", "y", "heading", "steps", "true_position"} & set(obs)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_pickled_mid_episode_env_continues_identically(env_id):
    env = gym.make(env_id)
    _, info = env.reset(seed=5)
    action = info["start_position"] + 1.0
    for _ in range(3):
        env.step(action)
    clone = pickle.loads(pickle.dumps(env))
    terminated = False
    while not terminated:
        a, b = env.step(action), clone.step(action)
        assert data_equivalence(a, b, exact=True)
        terminated = a[2]
    # The env's random state travels too: the next unseeded walks are the same.
    assert data_equivalence(env.reset(), clone.reset(), exact=True)


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("vector", [SyncVectorEnv, AsyncVectorEnv])
def test_vector_envs_step_like_single_envs(env_id, vector):
    envs = vector([functools.partial(gym.make, env_id)] * 2)
    try:
        obs, infos = envs.reset(seed=[21, 22])
        w = envs.single_observation_space["accel"].shape[0]
        assert obs["accel"].shape == (2, w, 3)
        start = infos["start_position"]
        assert start.shape == (2, 2)
        rewards = [envs.step(start)[1] for _ in range(3)]
    finally:
        envs.close()
    single = gym.make(env_id)
    for i, seed in enumerate((21, 22)):
        expected = _rollout(single, seed)["reward"][:3]
        assert [r[i] for r in rewards] == expected


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_render_draws_an_rgb_image_of_the_episode(env_id):
    env = gym.make(env_id, render_mode="rgb_array")
    _, info = env.reset(seed=2)
    before = env.render()
    for _ in range(5):
        env.step(info["start_position"] + 2.0)
    after = env.render()
    assert after.ndim == 3 and after.shape[2] == 3 and after.dtype == np.uint8
    assert after.shape == before.shape and not np.array_equal(before, after)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_episode_equals_the_runners_episode(env_id):
    env = gym.make(env_id)
    context = env.unwrapped.site_context
    other = gym.make(env_id).unwrapped.site_context
    # Surveyed once per process, but each env has its own copy of the tables.
    assert context is not other and context.fingerprints.keys() == other.fingerprints.keys()
    for name, db in context.fingerprints.items():
        twin = other.fingerprints[name]
        assert db is not twin and db.tables.keys() == twin.tables.keys()
        for table, df in db.tables.items():
            assert df is not twin.tables[table] and df.equals(twin.tables[table])
    assert context.window_samples == env.observation_space["accel"].shape[0]

    agent = _Recorder()
    obs, info = env.reset(seed=4)
    agent.reset(_start(info))
    ts, truth, rewards, terminated = [], [], [], False
    while not terminated:
        obs, reward, terminated, _, step_info = env.step(agent.act(obs))
        ts.append(step_info["t"])
        truth.append(step_info["true_position"])
        rewards.append(reward)

    rec = _walk(env, seed=4)
    runner = _Recorder()
    result = run_episode(runner, rec, context, start_info(rec, seed=4))
    assert data_equivalence(runner.seen, agent.seen, exact=True)
    assert data_equivalence(vars(runner.start), vars(agent.start), exact=True)
    np.testing.assert_array_equal(result.t, ts)
    np.testing.assert_array_equal(true_positions_at(rec, result.t), np.array(truth))
    np.testing.assert_allclose(
        rewards, -np.linalg.norm(result.estimate - np.array(truth), axis=1), rtol=0, atol=1e-12
    )


# ---------------------------------------------------------------- faults


def test_faults_change_the_walk_as_evaluate_does():
    site = indoorsim.load_site("minimal_room")
    specs = ["wrong_device:device=honor_50", "nan_burst:stream=accel,t0=2,t1=3", "dropout:p=0.3"]
    env = gym.make(SMALL, faults=specs).unwrapped
    assert env.faults[0].spec() == "wrong_device:device=honor_50"
    obs, _ = env.reset(seed=3)
    clean = simulate(site, route="main", mode="handheld", device="honor_50", seed=3)
    faulty = apply_faults(clean, env.faults, seed=3)
    seen = [obs["accel"]]
    terminated = False
    while not terminated:
        obs, _, terminated, _, _ = env.step(env.action_space.low + 10.0)
        seen.append(obs["accel"])
    # The env's windows are the faulty recording's, cut with the declared phone's window.
    windows = Windower(faulty, env.site_context.window_samples, env.bssids)
    assert len(seen) == len(windows) + 1
    for k, accel in enumerate(seen[:-1]):
        np.testing.assert_array_equal(accel, windows.window(k)["accel"])
    assert any(np.isnan(a).any() for a in seen)
    assert env.site_context.device == "nexus_5x"


def test_a_bad_fault_fails_at_construction():
    with pytest.raises(FaultError, match="fault mode_change: mode = 'handheld' is the mode"):
        IndoorPositioningEnv("minimal_room", faults=["mode_change:t0=5,mode=handheld"])
    with pytest.raises(FaultError, match="unknown fault 'wobble'"):
        IndoorPositioningEnv("minimal_room", faults="wobble")


# ---------------------------------------------------------------- options and errors


def test_reset_options_override_route_and_mode_for_one_episode():
    env = gym.make("indoorsim/Han2023Corridor-v11")
    site = indoorsim.load_site("han2023_corridor")
    default, other = list(site.scenario.routes)[:2]
    assert env.unwrapped.route == default
    _, info = env.reset(seed=1, options={"route": other, "mode": "pocketed"})
    rec = simulate(site, route=other, mode="pocketed", device="nexus_5x", seed=1)
    np.testing.assert_array_equal(info["start_position"], start_info(rec).position)
    _, info = env.reset(seed=1)
    rec = simulate(site, route=default, mode="handheld", device="nexus_5x", seed=1)
    np.testing.assert_array_equal(info["start_position"], start_info(rec).position)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"speed": 2.0}, r"unknown reset option.*'speed'.*valid options: \['route', 'mode'\]"),
        (
            {"route": "nowhere"},
            r"unknown route 'nowhere' in scenario 'minimal_room'; valid routes are: main$",
        ),
        (
            {"mode": "juggling"},
            r"unknown carrying mode 'juggling'; valid carrying modes are: .*handheld",
        ),
        ({"mode": [(0.0, "handheld"), (5.0, "juggling")]}, r"'juggling' in schedule\[1\]"),
        ({"mode": 3}, r"expected a carrying-mode name or a schedule .*got 3"),
    ],
)
def test_bad_reset_options_say_what_is_valid(options, message):
    env = gym.make(SMALL)
    with pytest.raises(ValueError, match=message):
        env.reset(options=options)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"route": "nowhere"}, ValueError, r"valid routes are: main"),
        ({"mode": "juggling"}, ValueError, r"valid carrying modes are"),
        ({"device": "nokia_3310"}, LookupError, r"valid devices are"),
        ({"survey_device": "nokia_3310"}, LookupError, r"valid devices are"),
        ({"window_s": 0.0}, ValueError, r"window_s must be a number of seconds in \(0, 60\]"),
        ({"window_s": 1e6}, ValueError, r"window_s must be .* got 1000000\.0"),
        ({"window_s": True}, ValueError, r"window_s must be .* got True"),
        ({"mode": [("x", "handheld")]}, ValueError, r"schedule\[0\]: .* must be a number"),
        ({"mode": [(0, "handheld"), (-1, "pocketed")]}, ValueError, r"schedule\[1\]: .*increase"),
        ({"mode": [(0, "handheld"), (0, "pocketed")]}, ValueError, r"schedule\[1\]: .*increase"),
        ({"mode": [(0, "handheld", {"pich_deg": 1})]}, ValueError, r"schedule\[0\]: .*pich_deg"),
        ({"render_mode": "human"}, ValueError, r"render_mode must be None or one of"),
    ],
)
def test_bad_arguments_fail_at_construction(kwargs, error, message):
    with pytest.raises(error, match=message):
        IndoorPositioningEnv("minimal_room", **kwargs)


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (np.array([np.nan, 1.0]), r"non-finite action ndarray \[nan  1\.\]"),
        (np.array([1.0, np.inf]), r"non-finite action ndarray \[ 1\. inf\]"),
        (np.zeros(3), r"shape \(3,\).*expected the \(x, y\) position .*shape \(2,\)"),
        (np.zeros((1, 2)), r"shape \(1, 2\)"),
        (1.5, r"float 1\.5 \(shape \(\), dtype float64\)"),
        (np.array(["1", "2"]), r"dtype <U1"),
        (np.array([True, False]), r"dtype bool"),
        (np.array([1 + 1j, 2.0]), r"dtype complex128"),
        ([1.0, [2.0, 3.0]], r"invalid action \[1\.0, \[2\.0, 3\.0\]\]"),
    ],
)
def test_bad_actions_are_rejected_saying_what_was_received(action, message):
    env = gym.make(SMALL).unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match=message):
        env.step(action)


@pytest.mark.parametrize("action", [[1e9, 3.0], [5.0, -10.3], np.array([-1e300, 1e300])])
def test_an_action_outside_the_action_space_is_rejected_with_its_bounds(action):
    env = gym.make(SMALL).unwrapped
    env.reset(seed=0)
    (xlo, ylo), (xhi, yhi) = env.action_space.low, env.action_space.high
    assert (xlo, ylo, xhi, yhi) == (-10.1, -10.1, 20.1, 16.1)  # the 10 m × 6 m room ± 10 m
    with pytest.raises(ValueError) as info:
        env.step(action)
    assert str(info.value) == (
        f"action {indoorsim.envs.positioning._describe(action)} is outside the action space: "
        "x in [-10.1, 20.1] m, y in [-10.1, 16.1] m (the floor plan's bounds ± 10 m)"
    )
    _, reward, *_ = env.step([20.1, -10.1])  # the box's corner is still inside
    assert np.isfinite(reward)


def test_integer_and_list_actions_are_positions():
    env = gym.make(SMALL).unwrapped
    env.reset(seed=0)
    a = env.step([1, 2])
    env.reset(seed=0)
    b = env.step(np.array([1.0, 2.0], dtype=np.float32))
    assert a[1] == b[1]


def test_step_outside_an_episode_is_an_error():
    env = gym.make(SMALL).unwrapped
    with pytest.raises(RuntimeError, match=r"call reset\(\) before step\(\)"):
        env.step(np.zeros(2))
    _rollout(env, seed=0)
    with pytest.raises(RuntimeError, match="the episode has terminated"):
        env.step(np.zeros(2))


def test_render_without_a_render_mode_warns_and_returns_none():
    env = gym.make(SMALL).unwrapped
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="without a render mode"):
        assert env.render() is None
