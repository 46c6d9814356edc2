"""The layout of every packed array the runtime and the tuning share, in one public place.

For each array: the names of its entries, in order, and the index constants derived from those
names. The numba kernels compile the constants in (they import them from here), the harvest and
the search name their columns with the tuples, and the JAX side (``tuning``) reads the same
entries through the same constants. Nothing else defines an index.

* **Footprint features** (``FEATURES``, ``FEAT_*``): the raw numbers a footprint is scored from
  (:func:`planner._kernels_foot.footprint_features`; the harvest's ``cand_features`` columns).
* **Trajectory metrics** (``RAW_METRICS``, ``RAW_*``): the raw numbers of a swing path.
* **Search counters** (``COUNTERS``, ``CNT_*``); the **obstacles' map values** (``FORBIDDEN_*``).
* **Scores** (``SCORES``, ``SCORE_*``), **search modes** (``SEARCH_MODES``, ``MODE_*``) and the
  crowd's **request kinds** (``REQUEST_KINDS``, ``KIND_*``).
* **Scoring weights** (``WEIGHT_FIELDS``, ``W_*``; terms ``SCORE_TERMS``), the **gait timing**
  (``TIMING_FIELDS``, ``T_*``) and the **planner configuration** (``CONFIG_FIELDS``, ``C_*``): the
  order of ``ScoringWeights.to_array()``, ``GaitTiming.to_array()`` and the packed configuration,
  derived from the fields of those frozen dataclasses (their modules hold the dataclasses).

>>> FEATURES[FEAT_SLOPE], RAW_METRICS[RAW_JERK], COUNTERS[CNT_EXPANDED]
('slope_rad', 'jerk', 'cells_expanded')
>>> WEIGHT_FIELDS[W_DISTANCE_SCALE], TIMING_FIELDS[T_STRIDE_EXPONENT]
('distance_scale_m', 'stride_exponent')
"""

from __future__ import annotations

from footfall.planner._params import (
    C_CELL,
    C_MARGIN,
    C_OBST_MARGIN,
    C_POT_GAIN,
    C_POT_RANGE,
    C_RADIUS,
    C_SAMPLES,
    C_SLICE_EPS,
    CONFIG_FIELDS,
)
from footfall.planner._timing import (
    T_DUTY_AT_REST,
    T_DUTY_MAX,
    T_DUTY_MIN,
    T_DUTY_SLOPE,
    T_MIN_FREQUENCY,
    T_STRIDE_COEFFICIENT,
    T_STRIDE_EXPONENT,
    TIMING_FIELDS,
)
from footfall.planner._weights import (
    FOOTPRINT_TERMS,
    N_FOOTPRINT_TERMS,
    N_TERMS,
    SCORE_TERMS,
    TRAJECTORY_TERMS,
    W_CLEARANCE_REF,
    W_CLIMB_REF,
    W_CURVATURE_REF,
    W_DISTANCE_SCALE,
    W_JERK_REF,
    W_LEG_SPACING_REF,
    W_PROXIMITY_REF,
    W_SLOPE_CRITICAL,
    W_STEP_CRITICAL,
    WEIGHT_FIELDS,
)


FEATURES: tuple[str, ...] = ("distance_m", "roughness_m", "slope_rad", "leg_gap_m", "obstacle_distance_m")
"""Raw footprint features: distance to the preferred footprint, roughness and slope under the foot,
gap to the other legs, distance to the nearest blocked cell."""
FEAT_DISTANCE, FEAT_ROUGHNESS, FEAT_SLOPE, FEAT_LEG_GAP, FEAT_PROXIMITY = range(len(FEATURES))
N_FEATURES = len(FEATURES)

RAW_METRICS: tuple[str, ...] = ("length_m", "curvature_energy", "clearance_m", "climb_m", "jerk")
"""Raw trajectory metrics of a swing path."""
RAW_LENGTH, RAW_CURVATURE, RAW_CLEARANCE, RAW_CLIMB, RAW_JERK = range(len(RAW_METRICS))
N_RAW = len(RAW_METRICS)

FORBIDDEN_STATIC, FORBIDDEN_MOVING = 1, 2
"""The values of a local obstacles' map (``LocalMaps.forbidden``; 0 where feet may go): a static
forbidden box, another character's body or the world's edge; a moving forbidden box. A foot beside
a moving box may swing out through its cells, beside a static one never
(:func:`planner._kernels_foot._open_escape`)."""

COUNTERS: tuple[str, ...] = ("couples_evaluated", "couples_2d", "cells_expanded", "wavefronts", "candidates", "slices",
                              "boxed_ways")
"""The search's counters of one foot (``boxed_ways``: 1 when its couple is a boxed-in foot's way out,
:data:`planner._kernels_foot.BOXED_CELL_COST`)."""
CNT_COUPLES_3D, CNT_COUPLES_2D, CNT_EXPANDED, CNT_WAVEFRONTS, CNT_CANDIDATES, CNT_SLICES, CNT_BOXED = range(len(COUNTERS))
N_COUNTERS = len(COUNTERS)

SCORES: tuple[str, ...] = ("couple", "footprint", "trajectory")
"""The three scores of a planned couple."""
SCORE_COUPLE, SCORE_FOOTPRINT, SCORE_TRAJECTORY = range(len(SCORES))

SEARCH_MODES: tuple[str, ...] = ("search", "per_target", "brute_force")
"""How the couple search runs: the paper's search, one wavefront per target, every couple."""
MODE_SEARCH, MODE_PER_TARGET, MODE_BRUTE_FORCE = range(len(SEARCH_MODES))

LEG_ROW: tuple[str, ...] = ("hip_x", "hip_z", "foot_x", "foot_z", "ends_in_foot")
"""A row of the legs a foot's landing keeps clear of (``FootBatch.legs``): a segment of another leg's
ground projection, (x, z) to (x, z), and 1.0 when its end is a foot (a leg hip -> foot, or another
character's foot as a zero-length leg), 0.0 for a segment of a leg as drawn (hip, knees, foot), which
only its line keeps feet off (:func:`planner._kernels_foot.footprint_features`)."""
LEG_HIP_X, LEG_HIP_Z, LEG_FOOT_X, LEG_FOOT_Z, LEG_FOOT = range(len(LEG_ROW))
N_LEG_COLUMNS = len(LEG_ROW)

REQUEST_KINDS: tuple[str, ...] = ("none", "new_swing", "forced_step", "replan")
"""What the crowd asks of a foot in a frame (``planner._crowd.stage_requests``; the harvest's ``kind``)."""
KIND_NONE, KIND_NEW_SWING, KIND_FORCED_STEP, KIND_REPLAN = range(len(REQUEST_KINDS))

assert WEIGHT_FIELDS[:N_TERMS] == tuple("footprint_" + t for t in FOOTPRINT_TERMS) + tuple(
    "trajectory_" + t for t in TRAJECTORY_TERMS)
assert len(SCORE_TERMS) == N_TERMS and N_FOOTPRINT_TERMS == len(FOOTPRINT_TERMS)

__all__ = [
    "C_CELL", "C_MARGIN", "C_OBST_MARGIN", "C_POT_GAIN", "C_POT_RANGE", "C_RADIUS", "C_SAMPLES", "C_SLICE_EPS",
    "CNT_BOXED", "CNT_CANDIDATES", "CNT_COUPLES_2D", "CNT_COUPLES_3D", "CNT_EXPANDED", "CNT_SLICES", "CNT_WAVEFRONTS",
    "CONFIG_FIELDS", "COUNTERS",
    "FEAT_DISTANCE", "FEAT_LEG_GAP", "FEAT_PROXIMITY", "FEAT_ROUGHNESS", "FEAT_SLOPE", "FEATURES",
    "FOOTPRINT_TERMS", "KIND_FORCED_STEP", "KIND_NEW_SWING", "KIND_NONE", "KIND_REPLAN", "MODE_BRUTE_FORCE", "MODE_PER_TARGET", "MODE_SEARCH",
    "LEG_FOOT", "LEG_FOOT_X", "LEG_FOOT_Z", "LEG_HIP_X", "LEG_HIP_Z", "LEG_ROW", "N_LEG_COLUMNS",
    "N_COUNTERS", "N_FEATURES", "N_FOOTPRINT_TERMS", "N_RAW", "N_TERMS",
    "RAW_CLEARANCE", "RAW_CLIMB", "RAW_CURVATURE", "RAW_JERK", "RAW_LENGTH", "RAW_METRICS",
    "REQUEST_KINDS", "SCORE_COUPLE", "SCORE_FOOTPRINT", "SCORE_TERMS", "SCORE_TRAJECTORY", "SCORES", "SEARCH_MODES",
    "T_DUTY_AT_REST", "T_DUTY_MAX", "T_DUTY_MIN", "T_DUTY_SLOPE", "T_MIN_FREQUENCY", "T_STRIDE_COEFFICIENT",
    "T_STRIDE_EXPONENT", "TIMING_FIELDS", "TRAJECTORY_TERMS",
    "W_CLEARANCE_REF", "W_CLIMB_REF", "W_CURVATURE_REF", "W_DISTANCE_SCALE", "W_JERK_REF", "W_LEG_SPACING_REF",
    "W_PROXIMITY_REF", "W_SLOPE_CRITICAL", "W_STEP_CRITICAL", "WEIGHT_FIELDS",
]
