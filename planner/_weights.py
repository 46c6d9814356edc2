"""The scoring weights: one typed, validated, frozen definition.

Every footprint criterion and every trajectory criterion is turned into a
*goodness* in [0, 1] (1 = best), and scores are weighted means of goodnesses:

* footprint score  = sum_k w_k s_k / sum_k w_k over the five footprint terms
  (paper §5.1: "normalised between 0 and 1");
* couple score     = weighted mean over all ten terms (footprint and trajectory),
  so a couple score is also in [0, 1] and comparable between feet.

The numba runtime (:mod:`planner._kernels_score`) and the JAX proxies (tuning/)
read the same fields in the same order through :meth:`ScoringWeights.to_array`;
the index constants below are that order.

Tuning guide
------------
* Raise ``footprint_distance`` to make feet land on the preferred footprint
  (tight, regular gait); lower it to let them wander to flatter, safer ground.
* ``footprint_elevation`` / ``footprint_slope`` trade regularity for flat footholds;
  ``step_critical_m`` and ``slope_critical_rad`` are the heights / angles at which a
  foothold is worth nothing (defaults from Wermelinger et al. 2016).
* ``trajectory_length`` vs ``trajectory_climb`` decides between going *around* an
  obstacle (longer path) and going *over* it (climb); with slices the planner
  tries both and these two weights arbitrate.
* ``trajectory_curvature`` prefers straight, direct swings (curvature energy is
  scale free: an arc turning by theta costs theta^2).
* Reference scales (``*_ref``) set where a goodness reaches 1/2 (rational terms) or
  0 (linear terms); change them with the creature's size.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from numba.extending import register_jitable

from footfall.planner._flat import FlatParameters


def _w(doc: str, default: float, *, unit: str = "-", scale: bool = False):
    return field(default=default, metadata={"doc": doc, "unit": unit, "scale": scale})


@dataclass(frozen=True)
class ScoringWeights(FlatParameters):
    """Weights (dimensionless, >= 0) and reference scales (> 0, units per field).

    Each term's goodness law is in its field's metadata (:meth:`describe` lists them in array
    order); the module docstring is the tuning guide. Every value is stored as a float; a
    non-number, a non-finite value, a negative weight, a reference scale <= 0 or five footprint
    weights that are all 0 raise ValueError naming the field.

    Attributes
    ----------
    footprint_distance, footprint_elevation, footprint_slope : float
        Weights of closeness to the preferred footprint, flatness with the neighbour cells and
        low slope (defaults 3, 1, 1).
    footprint_leg_spacing, footprint_obstacle_proximity : float
        Weights of room to the other legs and distance to forbidden cells (defaults 1, 1).
    trajectory_length, trajectory_curvature, trajectory_clearance : float
        Weights of a direct path, a straight path and a horizontal margin to blocked cells
        (defaults 2, 1, 0.5).
    trajectory_climb, trajectory_jerk : float
        Weights of little rise beyond the step height and smooth 3D motion (defaults 1, 0.5).
    distance_scale_m, step_critical_m, slope_critical_rad : float
        Distance (m), height step (m) and slope (rad) at which a foothold is worth 0
        (defaults 0.30, 0.12, 1.0).
    leg_spacing_ref_m, proximity_ref_m, clearance_ref_m : float
        Gap to the other legs, distance to a forbidden cell and path margin (m) that count as
        enough (defaults 0.05, 0.10, 0.07).
    curvature_energy_ref, climb_ref_m, jerk_ref : float
        Curvature energy (-), extra rise (m) and normalised jerk (-) worth 1/2
        (defaults 1.0, 0.10, 2000).

    Examples
    --------
    >>> from footfall.planner import ScoringWeights
    >>> w = ScoringWeights(footprint_distance=5)
    >>> w.footprint_distance, w.jerk_ref
    (5.0, 2000.0)
    >>> w.to_array().shape                       # 10 weights and 9 reference scales
    (19,)
    >>> ScoringWeights.from_array(w.to_array()) == w
    True
    >>> ScoringWeights(jerk_ref=0.0)
    Traceback (most recent call last):
        ...
    ValueError: ScoringWeights.jerk_ref: a reference scale must be > 0, got 0.0
    """

    # -- footprint terms (paper §5.1) -------------------------------------------------
    footprint_distance: float = _w("closeness to the preferred footprint: s = max(0, 1 - d / distance_scale_m)", 3.0)
    footprint_elevation: float = _w(
        "flatness with the surrounding cells: s = max(0, 1 - max|dh| / step_critical_m) over the 8 neighbours", 1.0
    )
    footprint_slope: float = _w("low slope: s = max(0, 1 - angle / slope_critical_rad)", 1.0)
    footprint_leg_spacing: float = _w(
        "room to the other legs: s = min(1, gap / leg_spacing_ref_m); a crossing is refused outright", 1.0
    )
    footprint_obstacle_proximity: float = _w("distance to forbidden cells: s = min(1, d / proximity_ref_m)", 1.0)
    # -- trajectory terms (paper §5.2, 'trajectory scoring') -----------------------------
    trajectory_length: float = _w("direct path: s = d_ref / max(length, d_ref), length = the ground path's length, d_ref = "
                                   "source->footprint straight distance", 2.0)
    trajectory_curvature: float = _w(
        "straight path: s = 1 / (1 + E / curvature_energy_ref), E = length * integral kappa^2 ds (horizontal)", 1.0
    )
    trajectory_clearance: float = _w("horizontal margin to blocked cells: s = min(1, d_min / clearance_ref_m)", 0.5)
    trajectory_climb: float = _w(
        "little rise beyond the step height: s = 1 / (1 + climb / climb_ref_m)", 1.0
    )
    trajectory_jerk: float = _w("smooth 3D motion: s = 1 / (1 + J / jerk_ref), J = length^3 integral |x'''(s)|^2 ds", 0.5)
    # -- reference scales -----------------------------------------------------------------
    distance_scale_m: float = _w("distance to the preferred footprint at which closeness is worth 0", 0.30, unit="m", scale=True)
    step_critical_m: float = _w("height step to a neighbour cell at which flatness is worth 0", 0.12, unit="m", scale=True)
    slope_critical_rad: float = _w("slope at which a foothold is worth 0", 1.0, unit="rad", scale=True)
    leg_spacing_ref_m: float = _w("gap to the other legs that counts as enough room", 0.05, unit="m", scale=True)
    proximity_ref_m: float = _w("distance to a forbidden cell that counts as safe", 0.10, unit="m", scale=True)
    curvature_energy_ref: float = _w("curvature energy worth 1/2", 1.0, scale=True)
    clearance_ref_m: float = _w("horizontal path margin that counts as safe", 0.07, unit="m", scale=True)
    climb_ref_m: float = _w("extra rise worth 1/2", 0.10, unit="m", scale=True)
    jerk_ref: float = _w("normalised geometric jerk worth 1/2", 2000.0, scale=True)

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise ValueError(f"ScoringWeights.{f.name}: expected a number, got {type(value).__name__}")
            value = float(value)
            object.__setattr__(self, f.name, value)
            if not math.isfinite(value):
                raise ValueError(f"ScoringWeights.{f.name}: must be finite, got {value!r}")
            if f.metadata["scale"] and value <= 0:
                raise ValueError(f"ScoringWeights.{f.name}: a reference scale must be > 0, got {value!r}")
            if not f.metadata["scale"] and value < 0:
                raise ValueError(f"ScoringWeights.{f.name}: a weight must be >= 0, got {value!r}")
        if sum(getattr(self, n) for n in FOOTPRINT_WEIGHT_FIELDS) <= 0:
            raise ValueError("ScoringWeights: at least one footprint weight must be > 0")


WEIGHT_FIELDS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(ScoringWeights))
FOOTPRINT_TERMS: tuple[str, ...] = ("distance", "elevation", "slope", "leg_spacing", "obstacle_proximity")
TRAJECTORY_TERMS: tuple[str, ...] = ("length", "curvature", "clearance", "climb", "jerk")
SCORE_TERMS: tuple[str, ...] = FOOTPRINT_TERMS + TRAJECTORY_TERMS
FOOTPRINT_WEIGHT_FIELDS = tuple("footprint_" + t for t in FOOTPRINT_TERMS)
METRE_SCALE_FIELDS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(ScoringWeights)
                                            if f.metadata["scale"] and f.metadata["unit"] == "m")
REFERENCE_REST_RADIUS_M = 0.35539095170112855
"""m: the rest radius of the creature :class:`ScoringWeights`' metre-valued defaults are sized for (the
built-in spider's, ``scenarios.Creature.rest_radius``)."""


def size_factor(rest_radius_m: float) -> float:
    """The factor on ``ScoringWeights()``'s metre-valued scales in a creature's defaults
    (:func:`default_weights`): its rest radius over :data:`REFERENCE_REST_RADIUS_M`, at most 1.

    >>> size_factor(REFERENCE_REST_RADIUS_M / 2), size_factor(2 * REFERENCE_REST_RADIUS_M)
    (0.5, 1.0)
    """
    if isinstance(rest_radius_m, bool) or not isinstance(rest_radius_m, (int, float, np.floating, np.integer)) \
            or not math.isfinite(rest_radius_m) or rest_radius_m <= 0:
        raise ValueError(f"rest_radius_m: expected a finite number > 0, got {rest_radius_m!r}")
    return min(1.0, float(rest_radius_m) / REFERENCE_REST_RADIUS_M)


def default_weights(rest_radius_m: float, leg_room_m: float = math.inf) -> ScoringWeights:
    """The default scoring weights of a creature of rest radius ``rest_radius_m`` whose stride law leaves
    ``leg_room_m`` between its neighbouring legs (:func:`planner._workspace.leg_room`): the runtime's and
    the tunes' starting point for it.

    The same goodness laws at every size up to the spider's: for a smaller creature each metre-valued
    reference scale (:data:`METRE_SCALE_FIELDS`: distance, height step, leg spacing, proximity,
    clearance, climb) is ``ScoringWeights()``'s times :func:`size_factor`, ``rest_radius_m /
    REFERENCE_REST_RADIUS_M``; the
    weights and the scale-free references (slope, curvature energy, jerk) stay. Why: with the spider's
    7 cm clearance a 12 cm beetle's every swing path scored as near another leg's room, the clearance
    term outvoted the distance to its preferred footprint, and 16 % of its strides landed a 3 cm cell
    off the stride law (0 % sized to it; docs/locomotion.md). A larger creature keeps the spider's
    scales, as its planner keeps the spider's 7 cm cells and 0.25 m search radius
    (``planner_config_for``): grown with it, a crab of 1.6 times the spider's size walked further off
    the stride law among crates and other crabs (per-stride p90 0.257 -> 0.287 on ``mixed``, 30 runs),
    while robot5 (1.2 times) was within the noise.

    The leg-spacing reference (the gap that counts as enough room) is at most ``leg_room_m``: where the
    stride law's own landing spots stand nearer than it to the neighbouring legs, every landing scored
    as crowded and the search moved it back, off the law (random 8-legged creatures with rest feet 4 cm
    apart: rear feet 1.3-2.9 cm short of 5 cm strides, per-stride p90 0.28-0.69). The built-in creatures'
    law leaves more than their reference at the speeds they walk, and keeps it.

    Parameters
    ----------
    rest_radius_m : float
        The creature's rest radius (m, ``scenarios.Creature.rest_radius``), > 0.
    leg_room_m : float, optional
        The room (m, > 0) between neighbouring legs the stride law leaves (no limit by default).

    Returns
    -------
    ScoringWeights

    Raises
    ------
    ValueError
        If ``rest_radius_m`` is not a finite number > 0, or ``leg_room_m`` not a number > 0.

    Examples
    --------
    >>> from footfall.planner import REFERENCE_REST_RADIUS_M, ScoringWeights, default_weights
    >>> default_weights(REFERENCE_REST_RADIUS_M) == ScoringWeights()     # the spider's size: unchanged
    True
    >>> half = default_weights(REFERENCE_REST_RADIUS_M / 2)
    >>> half.clearance_ref_m, half.distance_scale_m, half.slope_critical_rad, half.footprint_distance
    (0.035, 0.15, 1.0, 3.0)
    >>> default_weights(2 * REFERENCE_REST_RADIUS_M) == ScoringWeights()  # larger: the spider's scales
    True
    >>> default_weights(REFERENCE_REST_RADIUS_M, 0.02).leg_spacing_ref_m   # legs 2 cm apart at its walk
    0.02
    >>> default_weights(REFERENCE_REST_RADIUS_M, 0.2) == ScoringWeights()  # more room than the reference
    True
    >>> default_weights(0.0)
    Traceback (most recent call last):
        ...
    ValueError: rest_radius_m: expected a finite number > 0, got 0.0
    """
    k = size_factor(rest_radius_m)
    if isinstance(leg_room_m, bool) or not isinstance(leg_room_m, (int, float, np.floating, np.integer)) \
            or not leg_room_m > 0:
        raise ValueError(f"leg_room_m: expected a number > 0, got {leg_room_m!r}")
    defaults = ScoringWeights()
    scaled = {name: getattr(defaults, name) * k for name in METRE_SCALE_FIELDS} if k != 1.0 else {}
    if leg_room_m < scaled.get("leg_spacing_ref_m", defaults.leg_spacing_ref_m):
        scaled["leg_spacing_ref_m"] = float(leg_room_m)
    return dataclasses.replace(defaults, **scaled) if scaled else defaults


TRAJECTORY_WEIGHT_FIELDS = tuple("trajectory_" + t for t in TRAJECTORY_TERMS)

# Index constants into ScoringWeights.to_array(), used by the numba kernels and the JAX proxies.
N_FOOTPRINT_TERMS = len(FOOTPRINT_TERMS)
N_TERMS = len(SCORE_TERMS)
W_DISTANCE_SCALE = WEIGHT_FIELDS.index("distance_scale_m")
W_STEP_CRITICAL = WEIGHT_FIELDS.index("step_critical_m")
W_SLOPE_CRITICAL = WEIGHT_FIELDS.index("slope_critical_rad")
W_LEG_SPACING_REF = WEIGHT_FIELDS.index("leg_spacing_ref_m")
W_PROXIMITY_REF = WEIGHT_FIELDS.index("proximity_ref_m")
W_CURVATURE_REF = WEIGHT_FIELDS.index("curvature_energy_ref")
W_CLEARANCE_REF = WEIGHT_FIELDS.index("clearance_ref_m")
W_CLIMB_REF = WEIGHT_FIELDS.index("climb_ref_m")
W_JERK_REF = WEIGHT_FIELDS.index("jerk_ref")
assert WEIGHT_FIELDS[:N_TERMS] == FOOTPRINT_WEIGHT_FIELDS + TRAJECTORY_WEIGHT_FIELDS


# --------------------------------------------------------------------------- the goodness laws, once
# Each goodness is one of three laws of a raw number and its weight's scale, written here once: the
# numba kernels compile them (planner._kernels_foot.footprint_goodness, trajectory_goodness), the JAX
# scoring traces them (tuning._scoring). Each caller adds only its backend's floor or ceiling (and JAX
# its care for +inf).


@register_jitable
def falling_goodness(value, critical):
    """1 - value / critical: distance, roughness and slope (floored at 0 by the caller).

    Parameters
    ----------
    value : float or ndarray
        The raw number: distance to the preferred footprint (m), largest height step to a
        neighbour cell (m) or slope (rad).
    critical : float or ndarray
        The value at which the goodness reaches 0 (``distance_scale_m``, ``step_critical_m``
        or ``slope_critical_rad``), > 0.

    Returns
    -------
    float or ndarray
        ``1 - value / critical``: 1 at ``value = 0``, 0 at ``critical``, negative beyond it.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import falling_goodness
    >>> falling_goodness(np.array([0.0, 0.15, 0.3]), 0.3).tolist()
    [1.0, 0.5, 0.0]
    >>> falling_goodness(0.45, 0.3)   # beyond the critical value: the caller floors it at 0
    -0.5
    """
    return 1.0 - value / critical


@register_jitable
def rising_goodness(value, reference):
    """value / reference: leg spacing, obstacle proximity, clearance (capped at 1 by the caller), and
    directness (the straight distance over the path length, at least the distance).

    Parameters
    ----------
    value : float or ndarray
        The raw number: gap to the other legs, distance to a forbidden cell or horizontal path
        margin (m); for directness, the straight source-to-footprint distance (m).
    reference : float or ndarray
        The value worth 1 (``leg_spacing_ref_m``, ``proximity_ref_m``, ``clearance_ref_m``);
        for directness, the path length, at least the straight distance. > 0.

    Returns
    -------
    float or ndarray
        ``value / reference``: 0 at ``value = 0``, 1 at the reference, above 1 beyond it.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import rising_goodness
    >>> rising_goodness(np.array([0.05, 0.2]), 0.1).tolist()   # the caller caps 2.0 at 1
    [0.5, 2.0]
    >>> rising_goodness(0.3, 0.6)   # directness: a 0.3 m step along a 0.6 m path
    0.5
    """
    return value / reference


@register_jitable
def rational_goodness(value, reference):
    """1 / (1 + value / reference): curvature, climb and jerk (1/2 at the reference).

    Parameters
    ----------
    value : float or ndarray
        The raw number, >= 0: curvature energy (-), climb beyond the step height (m) or
        normalised jerk (-).
    reference : float or ndarray
        The value worth 1/2 (``curvature_energy_ref``, ``climb_ref_m`` or ``jerk_ref``), > 0.

    Returns
    -------
    float or ndarray
        ``1 / (1 + value / reference)``, in (0, 1] for ``value >= 0``: 1 at 0, 1/2 at the
        reference, falling towards 0 without reaching it.

    Examples
    --------
    >>> from footfall.planner import rational_goodness
    >>> rational_goodness(0.0, 0.1), rational_goodness(0.1, 0.1)
    (1.0, 0.5)
    >>> round(rational_goodness(0.3, 0.1), 6)   # three times the reference: 1 / 4
    0.25
    """
    return 1.0 / (1.0 + value / reference)
