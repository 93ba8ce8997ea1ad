"""Gymnasium environments for indoor positioning (DESIGN §9).

Importing this package registers one environment per bundled scenario (and
per scenario that a plugin adds through the ``indoorsim.scenarios`` entry
points) as ``indoorsim/<Scenario>-v11``, the scenario's name in CamelCase:
``han2023_corridor`` is ``indoorsim/Han2023Corridor-v11`` and ``minimal_room``
is ``indoorsim/MinimalRoom-v11``. Each id is
:class:`~indoorsim.envs.positioning.IndoorPositioningEnv` with that scenario;
the environment module itself is imported only when an environment is made.

Gymnasium's ``module:id`` syntax imports this package on the way, so no
explicit import is needed::

    import gymnasium as gym
    env = gym.make("indoorsim.envs:indoorsim/Han2023Corridor-v11", mode="pocketed")

Other options (``route``, ``mode``, ``device``, ``survey_device``,
``window_s``, ``render_mode``, ``faults``) are keyword arguments of :func:`gymnasium.make`.

Example:
    >>> import gymnasium as gym
    >>> from indoorsim.envs import ENV_IDS, env_id
    >>> env_id("han2023_corridor")
    'indoorsim/Han2023Corridor-v11'
    >>> "indoorsim/MinimalRoom-v11" in ENV_IDS and "indoorsim/MinimalRoom-v11" in gym.registry
    True
"""

from __future__ import annotations

import re

import gymnasium

from indoorsim.scenario.load import bundled_scenarios

__all__ = ["ENTRY_POINT", "ENV_IDS", "VERSION", "env_id"]

ENTRY_POINT = "indoorsim.envs.positioning:IndoorPositioningEnv"
VERSION = 11
"""The environments' version; a change that can move a leaderboard number bumps it."""


def env_id(scenario: str) -> str:
    """The registered id of a scenario: ``han2023_corridor`` → ``indoorsim/Han2023Corridor-v11``."""
    camel = "".join(part[:1].upper() + part[1:] for part in re.split(r"[_\-\s]+", scenario))
    return f"indoorsim/{camel}-v{VERSION}"


def _register_all() -> tuple[str, ...]:
    ids = []
    for name in bundled_scenarios():
        ids.append(env_id(name))
        gymnasium.register(
            id=ids[-1],
            entry_point=ENTRY_POINT,
            kwargs={"scenario": name},
            max_episode_steps=None,
        )
    return tuple(ids)


ENV_IDS: tuple[str, ...] = _register_all()
"""Every id registered on import, in the order of :func:`indoorsim.scenario.bundled_scenarios`."""
