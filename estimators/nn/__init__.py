"""Neural-network components: the BP network and Tent-ASO-BP of Han2023 (§3), and the
1-D ResNet inertial-odometry network of ``learned-io`` with its weights-only checkpoints."""

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
from indoorsim.estimators.nn.inertial import (
    Checkpoint,
    CheckpointError,
    InertialConfig,
    InertialEnsemble,
    InertialResNet,
    load_checkpoint,
    packaged_checkpoint,
)

__all__ = [
    "BPNetwork",
    "Checkpoint",
    "CheckpointError",
    "InertialConfig",
    "InertialEnsemble",
    "InertialResNet",
    "MinMaxScaler",
    "TentAsoBP",
    "batched_forward",
    "flatten",
    "load_checkpoint",
    "n_params",
    "nguyen_widrow",
    "packaged_checkpoint",
    "population_objective",
    "position_error",
    "train_bp",
    "unflatten",
]
