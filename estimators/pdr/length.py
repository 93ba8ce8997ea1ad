"""Step-length models (Han2023 §2.1.2, Eq. 3–5) and the least-squares calibration of K.

All three models are linear in their walker constant K:

* Weinberg (Eq. 3, ADI AN-602): d = K·(a_max − a_min)^(1/4);
* Kim (Eq. 5): d = K·(mean|a|)^(1/3);
* Scarlet (Eq. 4, garbled in the text; ADI AN-900):
  d = K·(mean|a| − a_min)/(a_max − a_min);

with a = |acc| − g of :mod:`.steps` over one step. K depends on the walker, the
carrying mode and the preprocessing of a (here the detector's low-pass, which
shrinks a_max − a_min), so Han2023 calibrates it per walker on labelled
walks: :func:`calibrate_k`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from indoorsim.estimators.pdr.steps import Step

__all__ = ["MODELS", "WEINBERG_K", "calibrate_k", "kim", "scarlet", "step_lengths", "weinberg"]

WEINBERG_K = 0.48
"""Un-calibrated Weinberg constant for a in m/s²: the midpoint of the two public
code defaults, 0.43 and 0.53 (REALISM §5; typical K is 0.4–0.55). Kim and
Scarlet have no default: their K only means something once calibrated."""


def weinberg(a_max: ArrayLike, a_min: ArrayLike, k: float = WEINBERG_K) -> NDArray[np.float64]:
    """Weinberg step length d = K·(a_max − a_min)^(1/4) (Han2023 Eq. 3), m.

    >>> float(weinberg(2.0, -14.0, k=0.5))
    1.0
    """
    swing = np.asarray(a_max, dtype=float) - np.asarray(a_min, dtype=float)
    return k * np.maximum(swing, 0.0) ** 0.25


def kim(mean_abs_a: ArrayLike, k: float) -> NDArray[np.float64]:
    """Kim step length d = K·(mean|a|)^(1/3) (Han2023 Eq. 5), m.

    >>> float(kim(8.0, k=0.3))
    0.6
    """
    return k * np.cbrt(np.asarray(mean_abs_a, dtype=float))


def scarlet(
    a_max: ArrayLike, a_min: ArrayLike, mean_abs_a: ArrayLike, k: float
) -> NDArray[np.float64]:
    """Scarlet step length d = K·(mean|a| − a_min)/(a_max − a_min) (Han2023 Eq. 4 as read), m.

    The text's Eq. 4 is garbled; this is the reading of PAPER_NOTES, Scarlet's
    ratio of the mean above the minimum to the swing. A step without swing
    (a_max = a_min) has length 0.

    >>> float(scarlet(2.0, -2.0, 1.0, k=1.0))
    0.75
    """
    a_max = np.asarray(a_max, dtype=float)
    a_min = np.asarray(a_min, dtype=float)
    swing = a_max - a_min
    above = np.asarray(mean_abs_a, dtype=float) - a_min
    ratio = np.divide(above, swing, out=np.zeros(np.broadcast(above, swing).shape), where=swing > 0)
    return k * ratio


_Fields = dict[str, NDArray[np.float64]]


def _weinberg_steps(s: _Fields, k: float) -> NDArray[np.float64]:
    return weinberg(s["a_max"], s["a_min"], k)


def _kim_steps(s: _Fields, k: float) -> NDArray[np.float64]:
    return kim(s["mean_abs_a"], k)


def _scarlet_steps(s: _Fields, k: float) -> NDArray[np.float64]:
    return scarlet(s["a_max"], s["a_min"], s["mean_abs_a"], k)


MODELS: dict[str, Callable[[_Fields, float], NDArray[np.float64]]] = {
    "weinberg": _weinberg_steps,
    "kim": _kim_steps,
    "scarlet": _scarlet_steps,
}
"""Step-length models by name, each ``model(fields, k)`` over arrays of step fields."""


def step_lengths(steps: Sequence[Step], k: float, model: str = "weinberg") -> NDArray[np.float64]:
    """Lengths (N,) of detected steps under a model of :data:`MODELS` with constant ``k``, m."""
    if model not in MODELS:
        raise KeyError(f"unknown step-length model {model!r}; models are {sorted(MODELS)}")
    fields = {
        name: np.array([getattr(s, name) for s in steps], dtype=float)
        for name in ("a_max", "a_min", "mean_abs_a")
    }
    return MODELS[model](fields, k)


def calibrate_k(steps: Sequence[Step], true_lengths: ArrayLike, model: str = "weinberg") -> float:
    """Least-squares K for detected steps matched to their true lengths.

    Every model is d = K·f(step), so minimising Σ(K·f_i − L_i)² gives

        K = Σ f_i·L_i / Σ f_i².

    Args:
        steps: detected steps.
        true_lengths: (N,) the true length of each step, m.
        model: a name of :data:`MODELS`.

    Returns:
        The calibrated K.

    Raises:
        ValueError: if the counts differ or every f_i is zero.
    """
    lengths = np.asarray(true_lengths, dtype=float).reshape(-1)
    if len(lengths) != len(steps):
        raise ValueError(f"{len(steps)} steps but {len(lengths)} true lengths")
    f = step_lengths(steps, 1.0, model)
    denom = float(f @ f)
    if denom == 0.0:
        raise ValueError("cannot calibrate K: the steps carry no signal (all model features are 0)")
    return float(f @ lengths) / denom
