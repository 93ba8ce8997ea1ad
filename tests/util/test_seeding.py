"""Seeded streams: one generator per (seed, spawn key), named streams built on it."""

from __future__ import annotations

import numpy as np

from indoorsim.util.seeding import SURVEY, WALK, generator, named_streams


def test_generator_is_the_seed_sequences_stream() -> None:
    for seed, key in [(0, ()), (7, (3,)), (2**40, (1, 2, 3))]:
        want = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key)).random(5)
        np.testing.assert_array_equal(generator(seed, key).random(5), want)
        np.testing.assert_array_equal(generator(seed, list(key)).random(5), want)
    np.testing.assert_array_equal(generator(5).random(3), np.random.default_rng(5).random(3))


def test_different_keys_or_seeds_give_different_streams() -> None:
    draws = {
        (seed, key): generator(seed, key).random()
        for seed in (0, 1)
        for key in [(), (0,), (1,), (0, 0), (0, 1), (1, 0)]
    }
    assert len(set(draws.values())) == len(draws)


def test_named_streams_keep_their_streams_when_names_are_appended() -> None:
    names = ("walker", "carry", "accel")
    first = {k: g.random(4) for k, g in named_streams(3, WALK, names).items()}
    longer = {k: g.random(4) for k, g in named_streams(3, WALK, (*names, "new")).items()}
    for i, name in enumerate(names):
        np.testing.assert_array_equal(longer[name], first[name])
        np.testing.assert_array_equal(first[name], generator(3, (WALK, i)).random(4))
    survey = named_streams(3, SURVEY, names)
    assert not np.array_equal(survey["walker"].random(4), first["walker"])
