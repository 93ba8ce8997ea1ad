"""Neural-network components: the BP network and Tent-ASO-BP of Han2023 (§3)."""

from indoorsim.estimators.nn.bp import (
    BPNetwork,
    MinMaxScaler,
    TentAsoBP,
    batched_forward,
    flatten,
    n_params,
    nguyen_widrow,
    population_objective,
    position_error,
    train_bp,
    unflatten,
)

__all__ = [
    "BPNetwork",
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
