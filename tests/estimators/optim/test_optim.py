"""The Tent map and Atom Search Optimization (Han2023 §3.2–3.3)."""

from __future__ import annotations

import numpy as np
import pytest

from indoorsim.estimators.optim import ASO, tent_map, tent_population, tent_sequence

# --- Tent map ---------------------------------------------------------------


def test_tent_map_is_eq_30() -> None:
    np.testing.assert_allclose(tent_map([0.0, 0.1, 0.3, 0.5, 0.8, 1.0]), [0, 0.2, 0.6, 1, 0.4, 0])
    # The fixed point 2/3 of x = 2(1 − x).
    assert tent_map(2 / 3) == pytest.approx(2 / 3)
    np.testing.assert_allclose(tent_map([0.3, 0.8], slope=1.99), [0.597, 0.398])


def test_the_literal_map_collapses_to_zero_in_floating_point() -> None:
    seq = tent_sequence(80, 50, np.random.default_rng(0), perturbation=0.0)
    assert (seq[-1] == 0.0).all()


@pytest.mark.parametrize("slope", [2.0, 1.99])
def test_the_tent_sequence_stays_spread_over_the_unit_interval(slope: float) -> None:
    seq = tent_sequence(10_000, 3, np.random.default_rng(1), slope=slope)
    assert ((seq >= 0.0) & (seq < 1.0)).all()
    for column in seq.T:
        counts, _ = np.histogram(column, bins=10, range=(0.0, 1.0))
        share = counts / column.size
        assert ((share > 0.05) & (share < 0.15)).all(), share
        # Never stuck: no iterate repeats the previous one, none is 0.
        assert (np.diff(column) != 0).all()
        assert (column > 0).all()


def test_tent_sequence_is_seeded() -> None:
    a = tent_sequence(500, 2, np.random.default_rng(7))
    b = tent_sequence(500, 2, np.random.default_rng(7))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, tent_sequence(500, 2, np.random.default_rng(8)))


def test_tent_population_maps_orbits_into_the_bounds() -> None:
    lower, upper = np.array([-3.0, 0.0, 10.0]), np.array([3.0, 1.0, 20.0])
    pop = tent_population(30, lower, upper, np.random.default_rng(2))
    assert pop.shape == (30, 3)
    assert ((pop >= lower) & (pop < upper)).all()
    seq = tent_sequence(30, 3, np.random.default_rng(2))
    np.testing.assert_array_equal(pop, lower + seq * (upper - lower))
    # Successive members are successive iterates of one orbit per coordinate
    # (a 53-bit start needs ~50 steps to reach a kicked point).
    np.testing.assert_array_equal(seq[1:], tent_map(seq[:-1]))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"slope": 2.5}, "slope"), ({"slope": 0.0}, "slope"), ({"perturbation": 0.3}, "perturbation")],
)
def test_tent_sequence_rejects_bad_parameters(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        tent_sequence(10, 1, np.random.default_rng(0), **kwargs)


# --- ASO --------------------------------------------------------------------


def sphere(x: np.ndarray) -> np.ndarray:
    return np.sum(x**2, axis=1)


def rastrigin(x: np.ndarray) -> np.ndarray:
    return 10.0 * x.shape[1] + np.sum(x**2 - 10.0 * np.cos(2 * np.pi * x), axis=1)


PROBLEMS = {"sphere": (sphere, 100.0), "rastrigin": (rastrigin, 5.12)}
DIM, POP, ITERATIONS, SEEDS = 10, 30, 100, range(5)


def random_search(f, bound: float, evaluations: int, rng: np.random.Generator) -> float:
    return float(f(rng.uniform(-bound, bound, (evaluations, DIM))).min())


@pytest.mark.parametrize("tent_init", [False, True], ids=["ASO", "Tent-ASO"])
@pytest.mark.parametrize("problem", sorted(PROBLEMS))
def test_aso_beats_random_search_at_equal_evaluations(problem: str, tent_init: bool) -> None:
    f, bound = PROBLEMS[problem]
    aso = ASO(population=POP, iterations=ITERATIONS, tent_init=tent_init)
    lower, upper = np.full(DIM, -bound), np.full(DIM, bound)
    found = [aso.minimize(f, lower, upper, np.random.default_rng(s)).fitness for s in SEEDS]
    baseline = [random_search(f, bound, POP * ITERATIONS, np.random.default_rng(s)) for s in SEEDS]
    assert np.median(found) < 0.5 * np.median(baseline), (found, baseline)


def matlab_acceleration(pop, fit, x_best, t, big_t, alpha, beta, rng) -> np.ndarray:
    """A line-by-line transcription of the authors' Acceleration.m and LJPotential.m."""
    n, dim = pop.shape
    m = np.exp(-(fit - fit.max()) / (fit.max() - fit.min()))
    m = m / m.sum()
    g = np.exp(-20 * t / big_t)
    kbest = int(np.floor(n - (n - 2) * (t / big_t) ** 0.5)) + 1
    index_m = np.argsort(-m, kind="stable")
    a = np.zeros((n, dim))
    for i in range(n):
        e = np.zeros(dim)
        mk = pop[index_m[:kbest]].sum(axis=0) / kbest
        distance = np.linalg.norm(pop[i] - mk)
        for k in range(kbest):
            j = index_m[k]
            r = np.linalg.norm(pop[i] - pop[j])
            c = (1 - (t - 1) / big_t) ** 3
            rsmin, rsmax = 1.1 + 0.1 * np.sin(t / big_t * np.pi / 2), 1.24
            if r / distance < rsmin:
                rs = rsmin
            else:
                rs = rsmax if r / distance > rsmax else r / distance
            potential = c * (12 * (-rs) ** (-13) - 6 * (-rs) ** (-7))
            unit = (pop[j] - pop[i]) / (np.linalg.norm(pop[i] - pop[j]) + np.finfo(float).eps)
            e = e + rng.random(dim) * potential * unit
        e = alpha * e + beta * (x_best - pop[i])
        a[i] = e / m[i]
    return a * g


@pytest.mark.parametrize("t", [1, 7, 30])
def test_the_vectorised_acceleration_is_the_authors_code(t: int) -> None:
    rng = np.random.default_rng(6)
    pop = rng.uniform(-5, 5, (9, 4))
    fit = rastrigin(pop)
    x_best = pop[np.argmin(fit)]
    aso = ASO(population=9, iterations=30)
    # Both draw the per-pair random vectors in the same (atom, neighbour) order.
    got = aso._acceleration(pop, fit, x_best, t, np.random.default_rng(7))
    want = matlab_acceleration(pop, fit, x_best, t, 30, 50.0, 0.2, np.random.default_rng(7))
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


class Recorder:
    """A population objective that records every call."""

    def __init__(self, f) -> None:
        self.f, self.calls, self.values = f, [], []

    def __call__(self, x: np.ndarray) -> np.ndarray:
        self.calls.append(x.copy())
        self.values.append(self.f(x))
        return self.values[-1]


def test_aso_calls_the_objective_once_per_iteration_with_the_population() -> None:
    rec = Recorder(sphere)
    lower, upper = np.full(4, -2.0), np.full(4, 3.0)
    res = ASO(population=12, iterations=40).minimize(rec, lower, upper, np.random.default_rng(3))
    assert len(rec.calls) == 40 and res.evaluations == 12 * 40
    assert all(c.shape == (12, 4) for c in rec.calls)
    # Every evaluated atom lies in the box (out-of-range coordinates are redrawn).
    evaluated = np.concatenate(rec.calls)
    assert ((evaluated >= lower) & (evaluated <= upper)).all()
    # The curve is the running minimum of everything evaluated, and x attains it.
    running = np.minimum.accumulate([v.min() for v in rec.values])
    np.testing.assert_array_equal(res.convergence, running)
    assert res.fitness == res.convergence[-1] == sphere(res.x[None])[0]


def test_aso_is_seeded() -> None:
    aso = ASO(population=10, iterations=30, tent_init=True)
    a = aso.minimize(rastrigin, [-5.12] * 3, [5.12] * 3, np.random.default_rng(4))
    b = aso.minimize(rastrigin, [-5.12] * 3, [5.12] * 3, np.random.default_rng(4))
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.convergence, b.convergence)


def test_aso_survives_a_flat_objective() -> None:
    # Equal fitnesses: equal masses, and no division by a zero spread.
    res = ASO(population=8, iterations=20).minimize(
        lambda x: np.zeros(len(x)), [-1.0, -1.0], [1.0, 1.0], np.random.default_rng(5)
    )
    assert res.fitness == 0.0 and np.isfinite(res.x).all()


def test_aso_rejects_a_malformed_objective() -> None:
    with pytest.raises(ValueError, match="shape"):
        ASO(population=5, iterations=3).minimize(
            lambda x: sphere(x)[:-1], [-1.0], [1.0], np.random.default_rng(0)
        )
    with pytest.raises(ValueError, match="non-finite"):
        ASO(population=5, iterations=3).minimize(
            lambda x: np.full(len(x), np.nan), [-1.0], [1.0], np.random.default_rng(0)
        )
