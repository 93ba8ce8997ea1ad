"""The BP network and Tent-ASO-BP of Han2023 (§3.1, §3.4; Eq. 20, 21, 31).

A back-propagation network n_in–h–n_out (4–4–2 in both of Han2023's layers:
"search dimensionality of 30" = 4·4 + 4 + 2·4 + 2, Eq. 20 with a ≈ 1.5). The
hidden layer is tanh, which is MATLAB ``newff``'s default ``tansig``
(2/(1 + e^(−2n)) − 1 ≡ tanh n), and the output layer is linear (``purelin``).

A network is described by one flat parameter vector θ = [W1, b1, W2, b2]
(W1 (h, n_in) row-major, b1 (h,), W2 (n_out, h) row-major, b2 (n_out,)): the
position of one atom in the search. :func:`batched_forward` evaluates P such
networks on the same inputs in one pass (two batched matrix products), which
is what lets ASO score all 30 atoms per iteration with one call.

Tent-ASO-BP (:class:`TentAsoBP`): inputs and outputs are min–max normalised to
[−1, 1] (MATLAB ``mapminmax``); Tent-initialised ASO searches θ in the box
[−``bound``, ``bound``]^D with Eq. 31, the summed Euclidean position error on
the training points, as fitness; BP then trains from the best atom. Choices
where the paper is silent (PAPER_NOTES, Han2023 items 6–9):

* **Fitness units**: Eq. 31 is "positioning accuracy", so the error is
  measured in the original output units (metres), not in normalised units
  that would weight x and y by the inverse of their extents.
* **Search box**: ±3 for every weight and threshold (the range of MATLAB
  GA-BP codes; Han2023 only says a range is set), a field.
* **BP**: full-batch gradient descent with momentum on the mean squared
  error over all training points and outputs in normalised units. That is
  MATLAB's ``mse`` performance, the quantity of Han2023 Fig. 14; Eq. 21's ½Σ
  per sample differs only by a constant factor of the learning rate.
* **Momentum update** (``bp_update``): the text's "learning rate of 0.01"
  and "momentum factor of 0.5" are ``net.trainParam.lr`` and ``mc`` of
  MATLAB's ``traingdm`` (``newff``'s default trainer, ``trainlm``, ignores
  both), so the default is ``traingdm``'s update, dX = mc·dX + lr·(1 − mc)·g
  with g = −∇E and X ← X + dX, i.e. v ← μv − η(1 − μ)∇E, θ ← θ + v. The
  toolbox starts dX at lr·g, so its first step, and every step on a constant
  gradient, is η∇E. ``"heavy_ball"``, this module's update before issue 18,
  is ``torch.optim.SGD``'s: v ← μv + ∇E, θ ← θ − ηv, steady step
  η∇E/(1 − μ), twice the paper's at μ = 0.5. Apart from the first step,
  ``traingdm`` at η is the heavy ball at η(1 − μ). Both are written out:
  importing ``torch.optim`` pulls in ``torch._dynamo``, about a second.
  Measured (heavy ball → traingdm; Table 2 over 5 held-out draws, the fusion,
  both layers, over 8 fit seeds): ASO-BP and Tent-ASO-BP move by ≤ 0.03 m on average
  (about 7 m basement, 10 m corridor; paper 1.63 / 1.31 m); plain BP, whose
  start is not searched, ends 1000 epochs at a higher training MSE and
  +0.05 m (basement) / +0.69 m (corridor); no network reaches Fig. 14's
  MSE < 0.1 either way. ``han2023-gml`` moves ≤ 0.14 m, ``han2023-fusion``
  −0.37 ± 0.68 m (basement) and +0.48 ± 1.86 m (corridor), within its
  spread over fit seeds: the learning rate does not explain the distance
  to the paper's tables.
* **Plain BP** (``use_aso=False``) starts from a Nguyen–Widrow initialisation
  (MATLAB ``newff``'s default ``initnw``, Nguyen & Widrow 1990): hidden rows
  of norm 0.7·h^(1/n_in), hidden thresholds U(−β, β), output weights and
  thresholds U(−0.5, 0.5).

Numbers are float64 throughout. Random numbers come from the numpy Generator
given to ``fit`` (ASO and the tent map) and from a local ``torch.Generator``
seeded from it (the Nguyen–Widrow start); torch's global RNG is never used.

A fit runs on one intra-op thread with torch's deterministic algorithms
(:func:`~indoorsim.estimators.nn.threads.torch_settings`, restored afterwards),
so its result cannot depend on the machine's core count. It is also the
faster choice: the batched passes (30 × N × 4 values) are large enough for
torch to split over its threads, which costs far more than it saves when
other processes keep the cores busy (on the 2-core development machine under
load, 100 ASO iterations on 400 points took 0.9–1.9 s with 2 threads and
0.07 s with 1). A fit at the paper's settings, either update, takes about 5 s
on one core on ``han2023_corridor``'s 7262 library points (layer 1) and 0.2 s
on its 87 layer-2 windows; ``benchmarks/bench_han2023.py`` times the search.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np
import torch
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.nn.threads import torch_settings
from indoorsim.estimators.optim.aso import ASO, Objective

__all__ = [
    "BP_UPDATES",
    "BPNetwork",
    "BPUpdate",
    "MinMaxScaler",
    "TentAsoBP",
    "batched_forward",
    "flatten",
    "n_params",
    "nguyen_widrow",
    "population_objective",
    "position_error",
    "train_bp",
    "unflatten",
]

DTYPE = torch.float64

BPUpdate = Literal["traingdm", "heavy_ball"]
BP_UPDATES: tuple[str, ...] = get_args(BPUpdate)


def n_params(n_in: int, hidden: int, n_out: int) -> int:
    """Weights and thresholds of an n_in–hidden–n_out network.

    >>> n_params(4, 4, 2)
    30
    """
    return hidden * n_in + hidden + n_out * hidden + n_out


def unflatten(
    theta: torch.Tensor, n_in: int, hidden: int, n_out: int
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    """Split parameter vectors (..., D) into (W1, b1, W2, b2) views.

    Args:
        theta: (..., D) parameter vectors [W1, b1, W2, b2], D = :func:`n_params`.
        n_in: inputs.
        hidden: hidden neurons.
        n_out: outputs.

    Returns:
        W1 (..., hidden, n_in), b1 (..., hidden), W2 (..., n_out, hidden), b2 (..., n_out).
    """
    d = n_params(n_in, hidden, n_out)
    if theta.shape[-1] != d:
        raise ValueError(
            f"a {n_in}-{hidden}-{n_out} network has {d} parameters, got {theta.shape[-1]}"
        )
    w1, b1, w2, b2 = torch.split(theta, [hidden * n_in, hidden, n_out * hidden, n_out], dim=-1)
    lead = theta.shape[:-1]
    return w1.reshape(*lead, hidden, n_in), b1, w2.reshape(*lead, n_out, hidden), b2


def flatten(w1: torch.Tensor, b1: torch.Tensor, w2: torch.Tensor, b2: torch.Tensor) -> torch.Tensor:
    """Join (W1, b1, W2, b2) into parameter vectors (..., D); the inverse of :func:`unflatten`."""
    return torch.cat([w1.flatten(-2), b1, w2.flatten(-2), b2], dim=-1)


def batched_forward(
    theta: torch.Tensor, x: torch.Tensor, *, hidden: int = 4, n_out: int = 2
) -> torch.Tensor:
    """Outputs of P networks on the same inputs, in one pass.

    Args:
        theta: (P, D) parameter vectors.
        x: (N, n_in) inputs.
        hidden: hidden neurons of every network.
        n_out: outputs of every network.

    Returns:
        (P, N, n_out) outputs.
    """
    w1, b1, w2, b2 = unflatten(theta, x.shape[-1], hidden, n_out)
    # tansig hidden layer, purelin output layer
    h = torch.tanh(torch.matmul(x, w1.transpose(1, 2)) + b1[:, None, :])
    return torch.matmul(h, w2.transpose(1, 2)) + b2[:, None, :]


def position_error(
    theta: torch.Tensor,
    x: torch.Tensor,
    y: torch.Tensor,
    scale: torch.Tensor,
    *,
    hidden: int = 4,
) -> torch.Tensor:
    """Eq. 31, the summed Euclidean error of each of P networks, in output units.

    Args:
        theta: (P, D) parameter vectors.
        x: (N, n_in) normalised inputs.
        y: (N, n_out) normalised targets.
        scale: (n_out,) output units per normalised unit (:attr:`MinMaxScaler.scale`):
            the normalisation is affine, so the error in output units is the
            normalised error times it.
        hidden: hidden neurons.

    Returns:
        (P,) fitness values.
    """
    pred = batched_forward(theta, x, hidden=hidden, n_out=y.shape[-1])
    # Eq. 31
    return torch.linalg.vector_norm((pred - y) * scale, dim=-1).sum(dim=-1)


def nguyen_widrow(n_in: int, hidden: int, n_out: int, generator: torch.Generator) -> torch.Tensor:
    """A Nguyen–Widrow starting point for inputs in [−1, 1] (module docstring).

    Args:
        n_in: inputs.
        hidden: hidden neurons.
        n_out: outputs.
        generator: the local torch generator to draw from.

    Returns:
        (D,) parameter vector.
    """
    beta = 0.7 * hidden ** (1.0 / n_in)

    def uniform(*shape: int) -> torch.Tensor:
        return torch.rand(*shape, generator=generator, dtype=DTYPE) - 0.5

    w1 = uniform(hidden, n_in)
    w1 = beta * w1 / torch.linalg.vector_norm(w1, dim=1, keepdim=True)
    b1 = 2.0 * beta * uniform(hidden)
    return flatten(w1, b1, uniform(n_out, hidden), uniform(n_out))


class BPNetwork(torch.nn.Module):
    """One n_in–hidden–n_out network with tanh hidden and linear output layers.

    Its only parameter is the flat vector ``theta``, so an ASO atom loads
    directly and BP trains the same 30 numbers the search found.

    Args:
        theta: (D,) weights and thresholds [W1, b1, W2, b2] (copied).
        n_in: inputs.
        hidden: hidden neurons.
        n_out: outputs.

    >>> net = BPNetwork(torch.zeros(n_params(4, 4, 2)))
    >>> net(torch.ones(3, 4, dtype=torch.float64)).shape
    torch.Size([3, 2])
    """

    def __init__(self, theta: ArrayLike, *, n_in: int = 4, hidden: int = 4, n_out: int = 2):
        super().__init__()
        t = torch.as_tensor(theta, dtype=DTYPE)
        if t.shape != (n_params(n_in, hidden, n_out),):
            raise ValueError(
                f"a {n_in}-{hidden}-{n_out} network needs ({n_params(n_in, hidden, n_out)},) "
                f"parameters, got {tuple(t.shape)}"
            )
        self.n_in, self.hidden, self.n_out = n_in, hidden, n_out
        self.theta = torch.nn.Parameter(t.detach().clone())

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """Outputs (N, n_out) of inputs (N, n_in)."""
        w1, b1, w2, b2 = unflatten(self.theta, self.n_in, self.hidden, self.n_out)
        return torch.tanh(x @ w1.T + b1) @ w2.T + b2


def train_bp(
    net: BPNetwork,
    x: ArrayLike,
    y: ArrayLike,
    *,
    epochs: int = 1000,
    lr: float = 0.01,
    momentum: float = 0.5,
    update: BPUpdate = "traingdm",
) -> NDArray[np.float64]:
    """Full-batch gradient descent with momentum on the MSE, in place (module docstring).

    Deterministic: no sampling, the whole training set every epoch.

    Args:
        net: the network to train.
        x: (N, n_in) normalised inputs.
        y: (N, n_out) normalised targets.
        epochs: gradient steps.
        lr: learning rate η.
        momentum: momentum μ.
        update: ``"traingdm"`` (MATLAB's, steady step η∇E) or ``"heavy_ball"``
            (torch SGD's, steady step η∇E/(1 − μ)).

    Returns:
        (epochs,) the MSE before each step (Han2023 Fig. 14).

    Raises:
        ValueError: for an unknown ``update``.
    """
    _check_bp_update(update)
    xt = torch.as_tensor(x, dtype=DTYPE)
    yt = torch.as_tensor(y, dtype=DTYPE)
    velocity = torch.zeros_like(net.theta)
    history = np.empty(epochs)
    for epoch in range(epochs):
        # Eq. 21, averaged over points and outputs (MATLAB mse)
        loss = torch.mean((net(xt) - yt) ** 2)
        (grad,) = torch.autograd.grad(loss, net.theta)
        with torch.no_grad():
            if update == "traingdm":
                if epoch == 0:
                    velocity = -lr * grad  # traingdm starts dX at lr·g
                velocity.mul_(momentum).sub_((1.0 - momentum) * lr * grad)
                net.theta.add_(velocity)
            else:
                velocity.mul_(momentum).add_(grad)
                net.theta.sub_(lr * velocity)
        history[epoch] = loss.item()
    return history


def _check_bp_update(update: str) -> None:
    """Raise ValueError unless ``update`` is one of :data:`BP_UPDATES`."""
    if update not in BP_UPDATES:
        raise ValueError(f"unknown BP update {update!r}; valid: {', '.join(BP_UPDATES)}")


@dataclass(kw_only=True)
class MinMaxScaler:
    """Per-column affine map of [min, max] onto [low, high] (MATLAB ``mapminmax``).

    A constant column maps to the middle of [low, high] and back to its value.

    Attributes:
        low: lower end of the normalised range.
        high: upper end of the normalised range.

    >>> s = MinMaxScaler().fit(np.array([[0.0, 10.0], [4.0, 30.0]]))
    >>> s.transform(np.array([[2.0, 30.0]])).tolist()
    [[0.0, 1.0]]
    """

    low: float = -1.0
    high: float = 1.0

    data_min: NDArray[np.float64] = field(default_factory=lambda: np.empty(0), init=False)
    data_max: NDArray[np.float64] = field(default_factory=lambda: np.empty(0), init=False)

    def fit(self, x: ArrayLike) -> MinMaxScaler:
        """Record the column ranges of (N, F) data; returns self."""
        a = np.asarray(x, dtype=float)
        if a.ndim != 2 or len(a) == 0 or not np.isfinite(a).all():
            raise ValueError(f"need finite (N, F) data with N ≥ 1, got shape {a.shape}")
        if not self.high > self.low:
            raise ValueError(f"need high > low, got [{self.low}, {self.high}]")
        self.data_min, self.data_max = a.min(axis=0), a.max(axis=0)
        return self

    @property
    def scale(self) -> NDArray[np.float64]:
        """(F,) data units per normalised unit (1 for a constant column)."""
        span = self.data_max - self.data_min
        return np.where(span > 0, span, self.high - self.low) / (self.high - self.low)

    def transform(self, x: ArrayLike) -> NDArray[np.float64]:
        """Normalise (N, F) data."""
        return (self._check(x) - self._mid_in) / self.scale + self._mid_out

    def inverse_transform(self, z: ArrayLike) -> NDArray[np.float64]:
        """Map normalised (N, F) values back to data units."""
        return (self._check(z) - self._mid_out) * self.scale + self._mid_in

    @property
    def _mid_in(self) -> NDArray[np.float64]:
        return (self.data_min + self.data_max) / 2

    @property
    def _mid_out(self) -> float:
        return (self.low + self.high) / 2

    def _check(self, x: ArrayLike) -> NDArray[np.float64]:
        if self.data_min.size == 0:
            raise RuntimeError("MinMaxScaler is not fitted: call fit(x) first")
        a = np.asarray(x, dtype=float)
        if a.ndim != 2 or a.shape[1] != self.data_min.size:
            raise ValueError(f"need (N, {self.data_min.size}) data, got shape {a.shape}")
        return a


@dataclass(kw_only=True)
class TentAsoBP:
    """Tent-ASO-BP regression (Han2023 §3.4); BP and ASO-BP by its flags.

    ``use_aso=False`` is plain BP from a Nguyen–Widrow start; ``use_aso=True,
    use_tent=False`` is ASO-BP; the defaults are Tent-ASO-BP with Han2023's
    settings. See the module docstring for the choices where the paper is silent.

    Attributes:
        population: ASO atoms.
        iterations: ASO iterations.
        epochs: BP epochs after the search.
        lr: BP learning rate.
        momentum: BP momentum.
        bp_update: BP's momentum update, ``"traingdm"`` (the paper's MATLAB
            trainer) or ``"heavy_ball"`` (torch SGD's; module docstring).
        hidden: hidden neurons.
        use_tent: Tent-map initial population (only with ``use_aso``).
        use_aso: search the initial weights with ASO.
        bound: the search box is [−bound, bound] for every weight and threshold.
        alpha: ASO depth weight.
        beta: ASO multiplier weight.
        convergence: after ``fit``, ASO's best Eq. 31 fitness per iteration
            (output units summed over the training points; empty for plain BP).
        training_mse: after ``fit``, the normalised MSE before each BP epoch.
    """

    population: int = 30
    iterations: int = 500
    epochs: int = 1000
    lr: float = 0.01
    momentum: float = 0.5
    bp_update: BPUpdate = "traingdm"
    hidden: int = 4
    use_tent: bool = True
    use_aso: bool = True
    bound: float = 3.0
    alpha: float = 50.0
    beta: float = 0.2

    convergence: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    training_mse: NDArray[np.float64] = field(
        default_factory=lambda: np.empty(0), init=False, repr=False, compare=False
    )
    _net: BPNetwork | None = field(default=None, init=False, repr=False, compare=False)
    _x_scaler: MinMaxScaler = field(default_factory=MinMaxScaler, init=False, repr=False)
    _y_scaler: MinMaxScaler = field(default_factory=MinMaxScaler, init=False, repr=False)

    def __post_init__(self) -> None:
        _check_bp_update(self.bp_update)

    def fit(self, x: ArrayLike, y: ArrayLike, rng: np.random.Generator) -> TentAsoBP:
        """Search the initial weights (unless ``use_aso=False``), then train by BP.

        Args:
            x: (N, n_in) inputs, e.g. (Mx, My, Mz, L) or (x_GML, y_GML, x_PDR, y_PDR).
            y: (N, n_out) target positions, m.
            rng: the seeded generator for all the randomness of the fit.

        Returns:
            self.
        """
        xa, ya = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if xa.ndim != 2 or ya.ndim != 2 or len(xa) != len(ya):
            raise ValueError(
                f"need (N, n_in) inputs and (N, n_out) targets, got {xa.shape}, {ya.shape}"
            )
        with torch_settings(threads=1):
            return self._fit(xa, ya, rng)

    def _fit(
        self, xa: NDArray[np.float64], ya: NDArray[np.float64], rng: np.random.Generator
    ) -> TentAsoBP:
        n_in, n_out = xa.shape[1], ya.shape[1]
        xt = torch.from_numpy(self._x_scaler.fit(xa).transform(xa))
        yt = torch.from_numpy(self._y_scaler.fit(ya).transform(ya))

        if self.use_aso:
            d = n_params(n_in, self.hidden, n_out)
            aso = ASO(
                population=self.population,
                iterations=self.iterations,
                alpha=self.alpha,
                beta=self.beta,
                tent_init=self.use_tent,
            )
            objective = population_objective(
                xt, yt, torch.from_numpy(self._y_scaler.scale), hidden=self.hidden
            )
            result = aso.minimize(objective, np.full(d, -self.bound), np.full(d, self.bound), rng)
            theta0 = torch.from_numpy(result.x)
            self.convergence = result.convergence
        else:
            gen = torch.Generator().manual_seed(int(rng.integers(2**63)))
            theta0 = nguyen_widrow(n_in, self.hidden, n_out, gen)
            self.convergence = np.empty(0)

        net = BPNetwork(theta0, n_in=n_in, hidden=self.hidden, n_out=n_out)
        self.training_mse = train_bp(
            net,
            xt,
            yt,
            epochs=self.epochs,
            lr=self.lr,
            momentum=self.momentum,
            update=self.bp_update,
        )
        self._net = net
        return self

    def predict(self, x: ArrayLike) -> NDArray[np.float64]:
        """Positions (N, n_out) of inputs (N, n_in), in the targets' units."""
        if self._net is None:
            raise RuntimeError("TentAsoBP is not fitted: call fit(x, y, rng) first")
        xt = torch.from_numpy(self._x_scaler.transform(x))
        with torch.no_grad():
            z = self._net(xt).numpy()
        return self._y_scaler.inverse_transform(z)

    @property
    def network(self) -> BPNetwork:
        """The trained network (on normalised inputs and outputs)."""
        if self._net is None:
            raise RuntimeError("TentAsoBP is not fitted: call fit(x, y, rng) first")
        return self._net


def population_objective(
    x: torch.Tensor, y: torch.Tensor, scale: torch.Tensor, *, hidden: int = 4
) -> Objective:
    """The ASO objective: atoms (P, D) → Eq. 31 fitness (P,), all networks in one pass.

    Args:
        x: (N, n_in) normalised inputs.
        y: (N, n_out) normalised targets.
        scale: (n_out,) output units per normalised unit.
        hidden: hidden neurons.
    """

    def objective(atoms: NDArray[np.float64]) -> NDArray[np.float64]:
        with torch.no_grad():
            return position_error(torch.from_numpy(atoms), x, y, scale, hidden=hidden).numpy()

    return objective
