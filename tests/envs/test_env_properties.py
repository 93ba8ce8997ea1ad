"""Property tests of the env's actions: anything an agent may hand to ``step``.

An action is accepted exactly when it is two finite real numbers inside the action
space, and then scored as the distance to the true position; anything else (any
shape, dtype, NaN, ±inf, a value far off the site, not an array at all) is a
ValueError saying what was received, and leaves the episode where it was.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import indoorsim.envs  # noqa: F401  (registers the ids)
from tests.conftest import SWEEP

SMALL = "indoorsim/MinimalRoom-v11"

DTYPES = (
    hnp.floating_dtypes(sizes=(16, 32, 64))
    | hnp.integer_dtypes()
    | hnp.unsigned_integer_dtypes()
    | hnp.boolean_dtypes()
    | hnp.complex_number_dtypes()
    | hnp.datetime64_dtypes()
    | hnp.byte_string_dtypes(max_len=3)
    | hnp.unicode_string_dtypes(max_len=3)
)

# Arrays of every shape and dtype (NaN, ±inf and huge values among the floats), pairs
# of floats around and inside the action box (which is [-10.1, 20.1] × [-10.1, 16.1] m),
# and things that are no array at all.
ACTIONS = st.one_of(
    hnp.arrays(DTYPES, hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=3)),
    hnp.arrays(np.float64, 2, elements=st.floats(-40, 40) | st.floats()),
    hnp.arrays(np.float32, 2, elements=st.floats(-40, 40, width=32)),
    hnp.arrays(np.int64, 2, elements=st.integers(-30, 30) | st.integers(-(2**63), 2**63 - 1)),
    st.lists(st.floats(-40, 40) | st.integers(-30, 30), min_size=0, max_size=3),
    st.tuples(st.floats(), st.floats()),
    st.recursive(
        st.none() | st.booleans() | st.floats() | st.text(max_size=3),
        lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=2), inner),
        max_leaves=5,
    ),
)


@pytest.fixture(scope="module")
def env() -> gym.Env:
    """One episode for every example: each accepted action moves it on a window."""
    env = gym.make(SMALL).unwrapped
    env.reset(seed=0)
    return env


def _acceptable(action: object, env: gym.Env) -> bool:
    """Two finite real numbers (no bool, no complex) inside the action space."""
    try:
        a = np.asarray(action)
    except (ValueError, TypeError):
        return False
    if a.shape != (2,) or a.dtype.kind not in "fiu":
        return False
    xy = a.astype(np.float64)
    return bool(np.isfinite(xy).all()) and env.action_space.contains(xy)


def _check_step(env: gym.Env, action: object) -> None:
    k = env._k
    if _acceptable(action, env):
        _, reward, terminated, truncated, info = env.step(action)
        x, y = (float(v) for v in np.asarray(action))
        tx, ty = info["true_position"]
        assert reward == -math.hypot(x - tx, y - ty) == -info["error_m"]
        assert env._k == k + 1 and not truncated
        if terminated:
            env.reset(seed=0)
        return
    with pytest.raises(ValueError) as info:
        env.step(action)
    message = str(info.value)
    assert message.startswith(("invalid action", "non-finite action", "action ")), message
    assert "outside the action space: x in [-10.1, 20.1] m" in message or (
        "expected the (x, y) position estimate in metres" in message
    )
    assert env._k == k  # a refused action scores nothing


@given(action=ACTIONS)
@example(action=np.array([20.1, -10.1]))  # the box's corner is inside
@example(action=np.array([np.nextafter(20.1, 99), 0.0]))  # a hair beyond it is not
@example(action=np.array([1e308, 1e308], dtype=np.float64))
@example(action=np.array([5, 3], dtype=np.uint64))
@example(action=np.array([2.0, 3.0], dtype=np.float16))
@example(action=np.array([[1.0, 2.0]]))
@example(action=[1.0, [2.0, 3.0]])
def test_any_action_is_scored_or_refused_with_a_clear_error(env, action):
    _check_step(env, action)


@pytest.mark.slow
@settings(SWEEP, max_examples=2000)
@given(action=ACTIONS)
def test_any_action_is_scored_or_refused_sweep(env, action):
    _check_step(env, action)
