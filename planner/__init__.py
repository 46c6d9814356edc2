"""The exact discrete runtime planner (paper §4-§6): local maps, foot paths,
footprint scoring and the best footprint-trajectory couple search.

numpy + numba only: this package never imports JAX, pyvista or pxr.
"""

from planner._cache import configure_numba_cache as _configure_numba_cache

_configure_numba_cache()

from planner._batch import BatchResult, FootBatch, make_batch, plan_batch  # noqa: E402
from planner._grid import GridFrame  # noqa: E402
from planner._maps import LocalMaps, WorldRaster  # noqa: E402
from planner._params import (  # noqa: E402
    DEFAULT_BUDGET,
    EXHAUSTIVE,
    FIRST_VALID,
    PlannerConfig,
    SearchBudget,
)
from planner._search import COUNTERS, RAW_METRICS, CoupleResult, FootQuery, plan_foot, wavefront_distances  # noqa: E402
from planner._weights import (  # noqa: E402
    FOOTPRINT_TERMS,
    SCORE_TERMS,
    TRAJECTORY_TERMS,
    WEIGHT_FIELDS,
    ScoringWeights,
)

__all__ = [
    "BatchResult",
    "FootBatch",
    "make_batch",
    "plan_batch",
    "COUNTERS",
    "DEFAULT_BUDGET",
    "EXHAUSTIVE",
    "FIRST_VALID",
    "FOOTPRINT_TERMS",
    "RAW_METRICS",
    "SCORE_TERMS",
    "TRAJECTORY_TERMS",
    "WEIGHT_FIELDS",
    "CoupleResult",
    "FootQuery",
    "GridFrame",
    "LocalMaps",
    "PlannerConfig",
    "ScoringWeights",
    "SearchBudget",
    "WorldRaster",
    "plan_foot",
    "wavefront_distances",
]
