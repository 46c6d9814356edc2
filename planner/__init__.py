"""The exact discrete runtime planner (paper §4-§6): local maps, foot paths,
footprint scoring and the best footprint-trajectory couple search.

numpy + numba only: this package never imports JAX, pyvista or pxr.
"""

from footfall._numba_cache import warn_if_foreign_cache as _warn_if_foreign_cache
from footfall.planner._allocator import keep_freed_memory as _keep_freed_memory
from footfall.planner._threads import configure_worker_wait as _configure_worker_wait

# numba's cache folder is the entry points' to set (footfall.configure_numba_cache), not the import's;
# the import only warns when it was set by hand to a folder other sources may have filled.
_warn_if_foreign_cache()
_configure_worker_wait()
# A frame's large arrays from memory the process keeps, not from fresh pages (planner._allocator; opt out with
# FOOTFALL_KEEP_FREED_MEMORY=0).
_keep_freed_memory()

from footfall.planner._batch import BatchResult, FootBatch, make_batch, plan_batch  # noqa: E402
from footfall.planner._crowd import (  # noqa: E402
    ControllerConfig,
    CreatureWalk,
    CrowdModel,
    CrowdState,
    FramePlans,
    StepRecord,
    creature_walk,
    init_crowd,
    planner_config_for,
    step,
    sustained_speed,
)
from footfall.planner._footing import ground_under_feet  # noqa: E402
from footfall.planner._gait import GaitManagerState, advance, init_gaits, set_destination, set_speed  # noqa: E402
from footfall.planner._grid import GridFrame  # noqa: E402
from footfall.planner._harvest import (  # noqa: E402
    FEATURES,
    FootHarvest,
    Harvest,
    harvest_foot,
    harvest_run,
    merge_harvest_chunks,
    pack_harvest,
    task_mapper,
)
from footfall.planner._ik import IKResult, body_rotation, legs_of, rest_pose_angles, solve_legs  # noqa: E402
from footfall.planner._lod import FULL_SEARCH, LOD_MODES, LodConfig  # noqa: E402
from footfall.planner._maps import LocalMaps, WorldRaster  # noqa: E402
from footfall.planner._params import (  # noqa: E402
    DEFAULT_BUDGET,
    EXHAUSTIVE,
    FIRST_VALID,
    PlannerConfig,
    SearchBudget,
)
from footfall.planner._presets import PRESET_SCHEMA_VERSION, Preset, load_preset, preset_dict  # noqa: E402
from footfall.planner._search import COUNTERS, RAW_METRICS, CoupleResult, FootQuery, plan_foot, wavefront_distances  # noqa: E402
from footfall.planner._simulation import (  # noqa: E402
    RECORDING_VERSION,
    Recorder,
    SimulationSummary,
    arrived,
    asked_speed,
    realised_strides,
    simulate,
)
from footfall.planner._threads import single_threaded  # noqa: E402
from footfall.planner._timing import (  # noqa: E402
    GRAVITY,
    SWING_MAX,
    SWING_MIN,
    GaitTiming,
    duty_factor,
    duty_law,
    froude_law,
    hip_height,
    stance_lead,
    stride_frequency,
    stride_law,
    stride_length,
)
from footfall.planner._weights import (  # noqa: E402
    FOOTPRINT_TERMS,
    METRE_SCALE_FIELDS,
    REFERENCE_REST_RADIUS_M,
    SCORE_TERMS,
    TRAJECTORY_TERMS,
    WEIGHT_FIELDS,
    ScoringWeights,
    default_weights,
    falling_goodness,
    rational_goodness,
    rising_goodness,
)
from footfall.planner import layout  # noqa: E402  (the packed arrays' names and indices)

__all__ = [
    "COUNTERS",
    "DEFAULT_BUDGET",
    "EXHAUSTIVE",
    "FEATURES",
    "FIRST_VALID",
    "FOOTPRINT_TERMS",
    "FULL_SEARCH",
    "GRAVITY",
    "LOD_MODES",
    "METRE_SCALE_FIELDS",
    "PRESET_SCHEMA_VERSION",
    "RAW_METRICS",
    "RECORDING_VERSION",
    "REFERENCE_REST_RADIUS_M",
    "SCORE_TERMS",
    "SWING_MAX",
    "SWING_MIN",
    "TRAJECTORY_TERMS",
    "WEIGHT_FIELDS",
    "advance",
    "arrived",
    "asked_speed",
    "BatchResult",
    "body_rotation",
    "ControllerConfig",
    "CoupleResult",
    "CreatureWalk",
    "creature_walk",
    "CrowdModel",
    "CrowdState",
    "default_weights",
    "duty_factor",
    "duty_law",
    "falling_goodness",
    "FootBatch",
    "FootHarvest",
    "FootQuery",
    "FramePlans",
    "froude_law",
    "GaitManagerState",
    "GaitTiming",
    "GridFrame",
    "Harvest",
    "ground_under_feet",
    "harvest_foot",
    "harvest_run",
    "hip_height",
    "IKResult",
    "init_crowd",
    "init_gaits",
    "layout",
    "legs_of",
    "load_preset",
    "LocalMaps",
    "LodConfig",
    "make_batch",
    "plan_batch",
    "plan_foot",
    "planner_config_for",
    "PlannerConfig",
    "Preset",
    "preset_dict",
    "rational_goodness",
    "realised_strides",
    "Recorder",
    "rest_pose_angles",
    "rising_goodness",
    "ScoringWeights",
    "SearchBudget",
    "set_destination",
    "set_speed",
    "simulate",
    "SimulationSummary",
    "single_threaded",
    "solve_legs",
    "step",
    "StepRecord",
    "stride_frequency",
    "stance_lead",
    "stride_law",
    "stride_length",
    "sustained_speed",
    "merge_harvest_chunks",
    "pack_harvest",
    "task_mapper",
    "wavefront_distances",
    "WorldRaster",
]
