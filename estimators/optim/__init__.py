"""Population optimisers: Atom Search Optimization and the Tent chaotic map.

Each optimiser calls its objective once per iteration with the whole
population, (P, D) → (P,), so a batched objective costs one call per iteration.
"""

from indoorsim.estimators.optim.aso import ASO, AsoResult, Objective
from indoorsim.estimators.optim.tent import tent_map, tent_population, tent_sequence

__all__ = ["ASO", "AsoResult", "Objective", "tent_map", "tent_population", "tent_sequence"]
