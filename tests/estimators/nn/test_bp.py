"""The BP network and Tent-ASO-BP (Han2023 §3.1, §3.4)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from indoorsim.estimators.nn import (
    BPNetwork,
    MinMaxScaler,
    TentAsoBP,
    batched_forward,
    bp,
    flatten,
    n_params,
    nguyen_widrow,
    position_error,
    train_bp,
    unflatten,
)
from indoorsim.estimators.nn.bp import BPUpdate


def test_the_4_4_2_network_has_the_papers_30_parameters() -> None:
    assert n_params(4, 4, 2) == 30
    assert n_params(3, 5, 1) == 5 * 3 + 5 + 5 + 1


def test_flatten_inverts_unflatten() -> None:
    theta = torch.arange(2 * 30, dtype=torch.float64).reshape(2, 30)
    w1, b1, w2, b2 = unflatten(theta, 4, 4, 2)
    assert (w1.shape, b1.shape, w2.shape, b2.shape) == ((2, 4, 4), (2, 4), (2, 2, 4), (2, 2))
    assert w1[1, 0, 1] == 31 and b1[0, 0] == 16 and b2[0, 1] == 29
    torch.testing.assert_close(flatten(w1, b1, w2, b2), theta, rtol=0, atol=0)
    with pytest.raises(ValueError, match="30 parameters"):
        unflatten(theta[:, :29], 4, 4, 2)


def test_the_network_is_tanh_then_linear() -> None:
    rng = np.random.default_rng(0)
    w1, b1, w2, b2 = rng.normal(size=(4, 4)), rng.normal(size=4), rng.normal(size=(2, 4)), [1, 2]
    theta = np.concatenate([w1.ravel(), b1, w2.ravel(), b2])
    x = rng.normal(size=(7, 4))
    with torch.no_grad():
        out = BPNetwork(theta)(torch.from_numpy(x)).numpy()
    np.testing.assert_allclose(out, np.tanh(x @ w1.T + b1) @ w2.T + b2, rtol=1e-12)


def test_batched_forward_equals_a_loop_over_single_networks_exactly() -> None:
    gen = torch.Generator().manual_seed(1)
    theta = 2 * torch.rand(30, 30, generator=gen, dtype=torch.float64) - 1
    x = torch.rand(500, 4, generator=gen, dtype=torch.float64)
    with torch.no_grad():
        batched = batched_forward(theta, x)
        looped = torch.stack([BPNetwork(t)(x) for t in theta])
    assert batched.shape == (30, 500, 2)
    assert torch.equal(batched, looped)


def test_position_error_is_eq_31_in_output_units() -> None:
    rng = np.random.default_rng(2)
    x = rng.uniform(0, 50, (40, 4))
    y = np.column_stack([rng.uniform(0, 54, 40), rng.uniform(0, 30, 40)])
    xs, ys = MinMaxScaler().fit(x), MinMaxScaler().fit(y)
    theta = torch.from_numpy(rng.normal(size=(3, 30)))
    xn = torch.from_numpy(xs.transform(x))
    got = position_error(theta, xn, torch.from_numpy(ys.transform(y)), torch.from_numpy(ys.scale))
    for t, g in zip(theta, got, strict=True):
        with torch.no_grad():
            pred = ys.inverse_transform(BPNetwork(t)(xn).numpy())
        assert g.item() == pytest.approx(np.linalg.norm(pred - y, axis=1).sum(), rel=1e-12)


def test_min_max_scaler_maps_onto_minus_one_one_and_back() -> None:
    x = np.array([[0.0, 10.0, 5.0], [4.0, 30.0, 5.0], [1.0, 20.0, 5.0]])
    s = MinMaxScaler().fit(x)
    z = s.transform(x)
    np.testing.assert_allclose(z[:, :2].min(axis=0), -1)
    np.testing.assert_allclose(z[:, :2].max(axis=0), 1)
    np.testing.assert_array_equal(z[:, 2], 0)  # a constant column sits in the middle
    np.testing.assert_allclose(s.inverse_transform(z), x)
    np.testing.assert_allclose(s.scale, [2, 10, 1])
    with pytest.raises(RuntimeError, match="not fitted"):
        MinMaxScaler().transform(x)


def test_nguyen_widrow_rows_have_the_prescribed_norm() -> None:
    theta = nguyen_widrow(4, 4, 2, torch.Generator().manual_seed(0))
    w1, b1, w2, b2 = unflatten(theta, 4, 4, 2)
    beta = 0.7 * 4 ** (1 / 4)
    norms = torch.linalg.vector_norm(w1, dim=1)
    torch.testing.assert_close(norms, torch.full((4,), beta, dtype=torch.float64))
    assert (b1.abs() <= beta).all() and (w2.abs() <= 0.5).all() and (b2.abs() <= 0.5).all()


def test_bp_lowers_the_mse_and_fits_a_linear_map() -> None:
    rng = np.random.default_rng(3)
    x = rng.uniform(-1, 1, (200, 4))
    y = x @ rng.uniform(-0.3, 0.3, (2, 4)).T + [0.1, -0.2]
    net = BPNetwork(nguyen_widrow(4, 4, 2, torch.Generator().manual_seed(0)))
    slow = train_bp(net, x, y)  # Han2023's 1000 epochs, lr 0.01, momentum 0.5
    assert slow.shape == (1000,) and (np.diff(slow) < 0).all()
    # the heavy ball's lr 0.5 used here before, as traingdm: the same steady step 0.5/(1 − 0.9)
    train_bp(net, x, y, epochs=2000, lr=5.0, momentum=0.9)
    with torch.no_grad():
        residual = net(torch.from_numpy(x)).numpy() - y
    assert np.sqrt(np.mean(residual**2)) < 0.02 * y.std()


def saturated_net(target: float) -> tuple[BPNetwork, np.ndarray, np.ndarray]:
    """A 1-1-1 network whose MSE is a quadratic with a closed-form gradient.

    tanh(50 + 0.3x) is 1.0 in float64 for |x| ≤ 1, so 1 − tanh² is 0: the hidden
    layer sits at 1 and gets no gradient, the output is w2 + b2 at every point, and
    E = (w2 + b2 − target)², ∂E/∂w2 = ∂E/∂b2 = 2(w2 + b2 − target).
    """
    theta = np.array([0.3, 50.0, 0.25, 0.25])  # w1, b1, w2, b2
    x = np.linspace(-1.0, 1.0, 5)[:, None]
    return BPNetwork(theta, n_in=1, hidden=1, n_out=1), x, np.full((5, 1), target)


@pytest.mark.parametrize(
    ("update", "w2_by_epoch", "mse"),
    [
        # e = w2 + b2 + 0.5, g = 2e for w2 and b2 alike; η = 0.1, μ = 0.5.
        # traingdm, v ← μv − η(1 − μ)g from v = −ηg (the toolbox starts dX at lr·g):
        #   e = 1:    v = −0.1·2                    = −0.2
        #   e = 0.6:  v = 0.5·(−0.2) − 0.05·1.2     = −0.16
        #   e = 0.28: v = 0.5·(−0.16) − 0.05·0.56   = −0.108
        ("traingdm", [0.05, -0.11, -0.218], [1.0, 0.36, 0.0784]),
        # heavy ball, v ← μv + g from v = 0, step −ηv:
        #   e = 1:    v = 2                 step −0.2
        #   e = 0.6:  v = 0.5·2 + 1.2 = 2.2 step −0.22
        #   e = 0.16: v = 1.1 + 0.32 = 1.42 step −0.142
        ("heavy_ball", [0.05, -0.17, -0.312], [1.0, 0.36, 0.0256]),
    ],
)
def test_three_epochs_equal_the_update_by_hand(
    update: BPUpdate, w2_by_epoch: list[float], mse: list[float]
) -> None:
    for epochs, w2 in enumerate(w2_by_epoch, start=1):
        net, x, y = saturated_net(-0.5)
        history = train_bp(net, x, y, epochs=epochs, lr=0.1, momentum=0.5, update=update)
        np.testing.assert_allclose(history, mse[:epochs], rtol=1e-12)
        expected = [0.3, 50.0, w2, w2]  # the saturated layer does not move
        np.testing.assert_allclose(net.theta.detach().numpy(), expected, rtol=1e-12, atol=1e-15)


def test_steps_on_a_constant_gradient_follow_both_closed_forms() -> None:
    # A target so far away that w2 + b2 − target rounds to 1e20 while w2 + b2 moves by
    # hundreds: ∂E/∂w2 = ∂E/∂b2 = g = 2e20 exactly, every epoch.
    lr, mu, g, epochs = 1e-20, 0.5, 2e20, 30
    steps = {}
    updates: tuple[BPUpdate, ...] = ("traingdm", "heavy_ball")
    for update in updates:
        w2 = [0.25]
        for k in range(1, epochs + 1):
            net, x, y = saturated_net(-1e20)
            train_bp(net, x, y, epochs=k, lr=lr, momentum=mu, update=update)
            w2.append(net.theta[2].item())
        steps[update] = -np.diff(w2)
    k = np.arange(1, epochs + 1)
    np.testing.assert_allclose(steps["traingdm"], lr * g, rtol=1e-9)
    np.testing.assert_allclose(steps["heavy_ball"], lr * g * (1 - mu**k) / (1 - mu), rtol=1e-9)
    ratio = steps["heavy_ball"][-1] / steps["traingdm"][-1]
    assert ratio == pytest.approx(1 / (1 - mu), rel=1e-8)


def test_an_unknown_update_is_refused() -> None:
    with pytest.raises(ValueError, match="valid: traingdm, heavy_ball"):
        TentAsoBP(bp_update="adam")  # type: ignore[arg-type]
    net, x, y = saturated_net(0.0)
    with pytest.raises(ValueError, match="unknown BP update 'sgd'"):
        train_bp(net, x, y, update="sgd")  # type: ignore[arg-type]


def teacher_library(n: int = 250) -> tuple[np.ndarray, np.ndarray]:
    """(Mx, My, Mz, L)-like features and positions given by a smooth 4-4-2 map of them."""
    rng = np.random.default_rng(10)
    u = rng.uniform(-1, 1, (n, 4))
    features = np.array([40.0, -20.0, 30.0, 200.0]) + u * [10.0, 5.0, 8.0, 100.0]
    z = np.tanh(u @ rng.normal(0, 0.8, (4, 4)).T + rng.normal(0, 0.3, 4)) @ rng.normal(size=(4, 2))
    positions = [5.0, 3.0] + (z - z.min(axis=0)) / np.ptp(z, axis=0) * [50.0, 24.0]
    return features, positions


# A fast schedule, not the paper's. Before traingdm became the default this was the heavy
# ball's lr 0.3 at momentum 0.9 for 2000 epochs; traingdm's equal steady step (lr 3) starts
# with a step ten times as long (its first is η∇E), which left Tent-ASO-BP at 16 % of the spread.
FAST = {"iterations": 60, "epochs": 4000, "lr": 2.0, "momentum": 0.5}


@pytest.mark.parametrize(
    "flags", [{}, {"use_tent": False}, {"use_aso": False}], ids=["Tent-ASO-BP", "ASO-BP", "BP"]
)
def test_tent_aso_bp_learns_a_smooth_map(flags: dict) -> None:
    features, positions = teacher_library()
    model = TentAsoBP(**FAST, **flags).fit(features, positions, np.random.default_rng(0))
    error = np.linalg.norm(model.predict(features) - positions, axis=1).mean()
    spread = np.linalg.norm(positions - positions.mean(axis=0), axis=1).mean()
    assert error < 0.1 * spread
    if flags.get("use_aso", True):
        assert model.convergence.shape == (60,) and (np.diff(model.convergence) <= 0).all()
    assert model.training_mse.shape == (4000,)


def test_the_search_scores_all_30_atoms_in_one_pass(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[tuple[int, ...]] = []
    original = bp.position_error

    def counting(theta: torch.Tensor, *args, **kwargs) -> torch.Tensor:
        calls.append(tuple(theta.shape))
        return original(theta, *args, **kwargs)

    monkeypatch.setattr(bp, "position_error", counting)
    features, positions = teacher_library(100)
    TentAsoBP(iterations=20, epochs=1).fit(features, positions, np.random.default_rng(0))
    assert calls == [(30, 30)] * 20


def test_same_seed_same_predictions_and_no_global_rng_use() -> None:
    features, positions = teacher_library(100)
    # The legacy global numpy state is read only to check that nothing draws from it.
    torch_state, numpy_state = torch.get_rng_state(), np.random.get_state()  # noqa: NPY002
    a = TentAsoBP(iterations=20, epochs=200).fit(features, positions, np.random.default_rng(4))
    b = TentAsoBP(iterations=20, epochs=200).fit(features, positions, np.random.default_rng(4))
    c = TentAsoBP(use_aso=False, epochs=200).fit(features, positions, np.random.default_rng(4))
    np.testing.assert_array_equal(a.predict(features), b.predict(features))
    assert not np.array_equal(a.predict(features), c.predict(features))
    assert torch.equal(torch.get_rng_state(), torch_state)
    after = np.random.get_state()  # noqa: NPY002
    assert all(np.array_equal(s, t) for s, t in zip(after, numpy_state, strict=True))


def test_a_fit_is_single_threaded_whatever_the_callers_setting_and_restores_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    features, positions = teacher_library(100)
    seen: list[int] = []
    inner_fit = TentAsoBP._fit

    def spying_fit(self: TentAsoBP, *args: object) -> TentAsoBP:
        seen.append(torch.get_num_threads())  # what the search and BP run with
        return inner_fit(self, *args)

    monkeypatch.setattr(TentAsoBP, "_fit", spying_fit)
    before = torch.get_num_threads()
    fits = []
    try:
        for threads in (1, 2):
            torch.set_num_threads(threads)
            model = TentAsoBP(iterations=5, epochs=50)
            fits.append(model.fit(features, positions, np.random.default_rng(4)).predict(features))
            assert torch.get_num_threads() == threads
    finally:
        torch.set_num_threads(before)
    assert seen == [1, 1]
    np.testing.assert_array_equal(fits[0], fits[1])


@pytest.mark.parametrize("update", ["traingdm", "heavy_ball"])
def test_without_aso_it_is_plain_bp_from_nguyen_widrow(update: BPUpdate) -> None:
    features, positions = teacher_library(100)
    model = TentAsoBP(use_aso=False, epochs=300, bp_update=update)
    model.fit(features, positions, np.random.default_rng(5))
    assert model.convergence.size == 0

    seed = int(np.random.default_rng(5).integers(2**63))
    xs, ys = MinMaxScaler().fit(features), MinMaxScaler().fit(positions)
    net = BPNetwork(nguyen_widrow(4, 4, 2, torch.Generator().manual_seed(seed)))
    mse = train_bp(net, xs.transform(features), ys.transform(positions), epochs=300, update=update)
    np.testing.assert_array_equal(model.training_mse, mse)
    with torch.no_grad():
        expected = ys.inverse_transform(net(torch.from_numpy(xs.transform(features))).numpy())
    np.testing.assert_array_equal(model.predict(features), expected)


def test_predict_before_fit_raises() -> None:
    with pytest.raises(RuntimeError, match="not fitted"):
        TentAsoBP().predict(np.zeros((1, 4)))
