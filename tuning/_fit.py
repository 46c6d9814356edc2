"""Fit the scoring weights and the gait timing to the biomechanics targets (optimistix).

Unknowns, positive by construction (log reparametrisation):

* ``log_weights`` (19,): log of ``ScoringWeights.to_array()`` (every weight and scale);
* ``log_timing`` (4,): log of the :data:`FITTED_TIMING` fields of ``GaitTiming``
  (the others stay at the harvest's values).

Residuals (a fixed-length vector; masked situations contribute zeros), each block
divided by the square root of its count so that every target weighs the same
whatever the number of situations:

* stride: new swings of a moving creature, (c lambda_cmd(theta, v) / lambda_target(v) - 1) / tolerance,
  lambda_target = coefficient h Fr^exponent (tuning/data/targets.toml), lambda_cmd(theta, v) = v / f(v)
  the stride the timing commands (``tuning._proxies.stride_frequency``) and c = ``stride_correction``
  (per situation; 1 by default) the realised / commanded stride the exact planner measured under the
  current parameters (output space mapping, :mod:`tuning._tune`). Why the commanded stride and not
  the soft selection's expected step E[|x - source|]: in steady walking every footprint lands at its
  preferred footprint P plus an offset that the weights decide, and a stride is the distance between
  two consecutive touch-downs of one foot, so the offsets cancel and the mean stride is the P spacing
  v / f, set by the timing alone. The per-situation E[step] moves with the weights by the offset
  (which the next step takes back), and with the timing only through how the soft selection leans
  toward a P that moved over fixed candidates -- far more weakly than the runtime, which re-centres
  its candidates on P: fitting it over-stepped the timing by about 4 times (spider: stride exponent
  0.30 -> 0.39 for a 5 % shorter stride). E[step] stays a reported metric (``step_length_m``);
* duty factor: distance of DF(v; theta) + d outside the band [low, high], / (high - low),
  for Fr < froude_max; d = ``duty_correction`` (per situation; 0 by default) the realised stance
  fraction minus the commanded DF that the exact planner measured under the current parameters
  (output space mapping, as for the stride: swings that start late or re-plan, holds);
* duty slope: max(0, -duty_slope - max_slope) (DF falls with speed);
* per creature, on the mean over its situations (a population target: a detour
  around a crate is sometimes the only way, and must not dominate the fit):
  jerk: sqrt(jerk_weight) max(0, log(mean E[J] / maximum)), **jerk_weight = 0 by default**:
  the runtime's jerk metric (``planner._kernels_foot.geometric_jerk``) is dominated by
  finite-difference sampling noise (median about 1.2e5 against the Flash & Hogan target
  of order 1e3), so no weights can meet that target and the block would only pull every
  weight toward the jerk term; :mod:`tuning._tune` instead refuses a candidate whose
  exact median jerk rises above the default weights' (a "do not increase" guard);
  curvature: max(0, mean E[E] / maximum - 1);
  clearance: max(0, 1 - mean E[min(clearance, c)] / c), c = minimum h;
* the weights' blocks (:data:`WEIGHT_BLOCKS`; on with ``weights_blocks=True``, the terrain and style
  tunes of :mod:`tuning._tune`): soft expectations (temperature ``tau``) of what the scoring weights
  decide, each a smooth function of every weight (the stride, duty and jerk blocks above depend on
  the timing alone, and the curvature and clearance hinges are inactive at the defaults, so without
  these blocks the Jacobian with respect to every weight is exactly 0 and Levenberg-Marquardt leaves
  the weights where they are):

  - offset, per new swing of a moving creature: E[|x - P|] / (tolerance lambda_target): the chosen
    footprint's distance to the preferred one in stride tolerances. A stride is the spacing of two
    touch-downs of one foot, lambda_i = lambda + o_i - o_(i-1) along the heading, so the per-stride
    error is the offsets' difference: small offsets, small per-stride errors (always active);
  - touch-down slope, per situation: relu(E[slope] / max_touchdown_slope - 1) (a style's ceiling;
    off without one);
  - detour, per situation: relu(log(E[path length / straight distance] min_distance_ratio)) (a style's
    minimum distance ratio: a swing's detour makes the body walk less of what was asked; off without);
  - touch-down clearance, per situation: relu(1 - E[min(obstacle distance, c)] / c), c = the style's
    minimum clearance (body heights x h): footprints kept away from forbidden boxes (off without one);
  - curvature p95, per situation: relu(log(E[E] / curvature_p95_max)): situations above a style's
    ceiling (the per-situation hinge stands for the 95th percentile of the runs; off without one).

* prior: (y - y_0) / PRIOR_LOG_SCALE, so that parameters no target constrains stay at
  the harvest's values (the problem is otherwise under-determined).

The expectations are the soft selection of :mod:`tuning._proxies` at temperature
``tau`` over harvested, fixed candidate sets: a fit is local, and should be
followed by a new harvest with the fitted parameters (and another fit).

:func:`fit` runs ``n_steps`` Levenberg-Marquardt steps of optimistix's solver
(``init`` / ``step``), the steps as one ``lax.scan`` inside one ``eqx.filter_jit``.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from footfall.planner import GRAVITY
from footfall.planner.layout import TIMING_FIELDS
from footfall.tuning._proxies import Situations, duty_factor, expected_metrics, stride_frequency

FITTED_TIMING = ("stride_coefficient", "stride_exponent", "duty_at_rest", "duty_slope")
_FITTED_INDEX = np.array([TIMING_FIELDS.index(n) for n in FITTED_TIMING])
WEIGHT_BLOCKS = ("offset", "touchdown_slope", "detour", "touchdown_clearance", "curvature_p95")
"""The weights' residual blocks, in the order of :func:`residuals` (module docstring)."""
PRIOR_LOG_SCALE = 1.0
"""A factor e away from the harvest's value costs as much as one target missed by its tolerance."""


class FitProblem(eqx.Module):
    """Situations with their creatures' targets, per situation (F,).

    Built by :func:`make_problem`; the second argument of :func:`residuals`, :func:`loss` and
    :func:`fit`. An ``equinox.Module`` (a pytree: ``tau`` and ``fit_timing`` are static).

    Attributes
    ----------
    situations : Situations
        The harvested situations (F of them, C creatures).
    tau : float
        Temperature of the soft selection.
    stride_target_m, stride_tolerance, stride_mask, stride_correction : jax.Array
        (F,) the target stride (m), its relative tolerance, the situations it applies to (new
        swings of a moving creature) and the correction c.
    duty_low, duty_high, duty_mask, duty_correction : jax.Array
        (F,) the duty-factor band, the situations below its Froude limit, and the correction d.
    max_duty_slope : jax.Array
        () the largest allowed d DF / d(v / sqrt(g h)) (the smallest over the creatures).
    jerk_max, curvature_max, clearance_min_m : jax.Array
        (F,) the per-creature bounds: normalised jerk, curvature energy, clearance (m).
    creature_one_hot : jax.Array
        (F, C) which creature each situation belongs to.
    log_weights0, log_timing0 : jax.Array
        (19,) and (4,) the logs of the harvest's weights and fitted timing fields (the prior's
        centre and the fit's start).
    jerk_weight, offset_weight, prior_log_scale : jax.Array
        () weights of the jerk and offset blocks, and the prior's scale.
    slope_max, detour_max, curvature_p95_max, touchdown_clearance_m : jax.Array
        (F,) the style's bounds (inf, or 0 for the clearance: none).
    fit_timing : bool
        False: the timing is held at the harvest's (a tune of the weights alone).

    Examples
    --------
    A spider harvested with a shorter stride law (coefficient 2.0) than its targets' (2.3):

    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import harvest_situations, load_targets, make_problem, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2,
    ...                              timing=GaitTiming(stride_coefficient=2.0))
    >>> situations = situations_from_harvest(harvest)
    >>> problem = make_problem(situations, harvest.creatures, load_targets(creatures=("spider",)), tau=0.01)
    >>> problem.tau, problem.creature_one_hot.shape
    (0.01, (3, 1))
    >>> bool(problem.stride_mask.all())             # three new swings of a moving spider
    True
    >>> target = load_targets(creatures=("spider",))["spider"].stride_length_m(float(situations.speed[0]))
    >>> bool(abs(float(problem.stride_target_m[0]) - target) < 1e-15)
    True
    """

    situations: Situations
    tau: float = eqx.field(static=True)
    stride_target_m: jax.Array
    stride_tolerance: jax.Array
    stride_mask: jax.Array
    stride_correction: jax.Array  # (F,) c: realised / commanded stride measured by the exact planner
    duty_low: jax.Array
    duty_high: jax.Array
    duty_mask: jax.Array
    duty_correction: jax.Array  # (F,) d: realised stance fraction - commanded duty factor
    max_duty_slope: jax.Array  # () the smallest over the creatures
    jerk_max: jax.Array
    curvature_max: jax.Array
    clearance_min_m: jax.Array
    creature_one_hot: jax.Array  # (F, C) situations of each creature
    log_weights0: jax.Array
    log_timing0: jax.Array  # (4,)
    jerk_weight: jax.Array  # () weight of the jerk block (0 by default: module docstring)
    offset_weight: jax.Array  # () weight of the offset block (0: off; module docstring)
    slope_max: jax.Array  # (F,) the style's touch-down slope ceiling (rad; inf: none)
    detour_max: jax.Array  # (F,) 1 / the style's minimum distance ratio (inf: none)
    curvature_p95_max: jax.Array  # (F,) the style's curvature p95 ceiling (inf: none)
    touchdown_clearance_m: jax.Array  # (F,) the style's minimum clearance to forbidden boxes (m; 0: none)
    prior_log_scale: jax.Array = PRIOR_LOG_SCALE  # () the prior's scale (module docstring)
    fit_timing: bool = eqx.field(static=True, default=True)


def make_problem(situations: Situations, creature_names, targets, tau: float, jerk_weight: float = 0.0,
                 stride_correction=None, duty_correction=None, weights_blocks: bool = False,
                 fit_timing: bool = True, offset_weight: float = 1.0,
                 prior_log_scale: float = PRIOR_LOG_SCALE) -> FitProblem:
    """``creature_names``: the harvest's ``creatures`` (``situations.creature`` indexes it);
    ``targets``: :func:`tuning.load_targets` output holding those creatures; ``jerk_weight``:
    weight of the jerk block (0: off, the default; module docstring); ``stride_correction``:
    c per situation (F,), realised / commanded stride (None: 1, the timing model taken at its word);
    ``duty_correction``: d per situation (F,), realised - commanded duty factor (None: 0);
    ``weights_blocks``: the weights' blocks (offset, weighted ``offset_weight``, and the style's bounds
    where the targets state a style; module docstring); ``fit_timing`` False: the timing is held at the harvest's (its
    Jacobian columns are zero and its prior keeps it there): a tune of the weights alone.

    Parameters
    ----------
    situations : Situations
        The harvested situations (:func:`situations_from_harvest`).
    creature_names : sequence of str
        The harvest's ``creatures``.
    targets : dict of str to CreatureTargets
        :func:`load_targets` output holding those creatures.
    tau : float
        Temperature of the soft selection, > 0.
    jerk_weight : float, optional
        Weight of the jerk block, >= 0 (default 0: off).
    stride_correction, duty_correction : array_like of shape (F,), optional
        c (positive) and d (in (-1, 1)) per situation; None: 1 and 0.
    weights_blocks : bool, optional
        Add the weights' blocks (default False).
    fit_timing : bool, optional
        Fit the timing too (default True).
    offset_weight : float, optional
        Weight of the offset block when ``weights_blocks`` (default 1).
    prior_log_scale : float, optional
        Scale of the prior on the log parameters (default :data:`PRIOR_LOG_SCALE`).

    Returns
    -------
    FitProblem
        The situations with their targets, per situation.

    Raises
    ------
    ValueError
        If ``tau`` is not > 0, ``jerk_weight`` is not a number >= 0, a creature has no targets,
        or a correction has the wrong length or values.

    Examples
    --------
    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import harvest_situations, load_targets, make_problem, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2,
    ...                              timing=GaitTiming(stride_coefficient=2.0))
    >>> situations = situations_from_harvest(harvest)
    >>> problem = make_problem(situations, harvest.creatures, load_targets(creatures=("spider",)), tau=0.01)
    >>> problem.situations.n_situations, problem.log_weights0.shape, problem.log_timing0.shape
    (3, (19,), (4,))
    >>> make_problem(situations, harvest.creatures, {}, tau=0.01)
    Traceback (most recent call last):
        ...
    ValueError: targets: no targets for ['spider']
    """
    if not tau > 0.0:
        raise ValueError(f"tau: expected a temperature > 0, got {tau!r}")
    if isinstance(jerk_weight, bool) or not isinstance(jerk_weight, (int, float)) or not jerk_weight >= 0.0:
        raise ValueError(f"jerk_weight: expected a number >= 0, got {jerk_weight!r}")
    index = np.asarray(situations.creature)
    missing = [n for n in creature_names if n not in targets]
    if missing:
        raise ValueError(f"targets: no targets for {missing}")
    per = [targets[creature_names[i]] for i in index]

    def col(fn):
        return jnp.asarray(np.array([fn(t) for t in per], dtype=np.float64))

    v = np.asarray(situations.speed)
    h = np.asarray(situations.leg_height)
    froude = v * v / (GRAVITY * h)
    stride = np.array([t.stride_length_m(s) for t, s in zip(per, v)])
    duty_fr = col(lambda t: t["duty_factor"].values["froude_max"])
    timing0 = np.asarray(situations.timing0)
    weights0 = np.asarray(situations.weights0)
    if stride_correction is None:
        stride_correction = np.ones(v.shape)
    stride_correction = np.asarray(stride_correction, dtype=np.float64)
    if stride_correction.shape != v.shape or not (np.isfinite(stride_correction) & (stride_correction > 0)).all():
        raise ValueError(f"stride_correction: expected {v.shape[0]} positive finite numbers")
    duty_correction = np.zeros(v.shape) if duty_correction is None else np.asarray(duty_correction, dtype=np.float64)
    if duty_correction.shape != v.shape or not (np.isfinite(duty_correction) & (abs(duty_correction) < 1)).all():
        raise ValueError(f"duty_correction: expected {v.shape[0]} finite numbers in (-1, 1)")
    return FitProblem(
        situations=situations, tau=float(tau), stride_target_m=jnp.asarray(stride),
        stride_tolerance=col(lambda t: t["stride_length"].values["relative_tolerance"]),
        stride_mask=jnp.asarray(np.asarray(situations.new_swing) & (v > 0.0)),
        stride_correction=jnp.asarray(stride_correction),
        duty_low=col(lambda t: t["duty_factor"].values["low"]), duty_high=col(lambda t: t["duty_factor"].values["high"]),
        duty_mask=jnp.asarray(froude) < duty_fr, duty_correction=jnp.asarray(duty_correction),
        max_duty_slope=jnp.asarray(min(t["duty_factor_slope"].values["max_slope"] for t in per)),
        jerk_max=col(lambda t: t["swing_jerk"].values["maximum"]),
        curvature_max=col(lambda t: t["curvature_energy"].values["maximum"]),
        clearance_min_m=col(lambda t: t.clearance_min_m),
        creature_one_hot=jnp.asarray(index[:, None] == np.arange(len(creature_names))[None, :], dtype=jnp.float64),
        log_weights0=jnp.log(jnp.asarray(weights0)), log_timing0=jnp.log(jnp.asarray(timing0[_FITTED_INDEX])),
        jerk_weight=jnp.asarray(float(jerk_weight), dtype=jnp.float64),
        offset_weight=jnp.asarray(float(offset_weight) if weights_blocks else 0.0, dtype=jnp.float64),
        slope_max=col(lambda t: _style(t, "max_touchdown_slope_rad", weights_blocks)),
        detour_max=col(lambda t: 1.0 / _style(t, "min_distance_ratio", weights_blocks, 0.0) if _style(
            t, "min_distance_ratio", weights_blocks, 0.0) > 0.0 else np.inf),
        curvature_p95_max=col(lambda t: _style(t, "curvature_p95_max", weights_blocks)),
        touchdown_clearance_m=col(lambda t: _style(t, "min_clearance_body_heights", weights_blocks, 0.0)
                                  * t.leg_length_m),
        prior_log_scale=jnp.asarray(float(prior_log_scale), dtype=jnp.float64), fit_timing=bool(fit_timing))


def _style(target, key: str, on: bool, none: float = np.inf) -> float:
    """A style's number of a creature's targets (``CreatureTargets.style``), or ``none``."""
    style = getattr(target, "style", None) or {}
    return float(style[key]) if on and key in style else none


def timing_vector(log_timing, timing0):
    """Full GaitTiming vector: the fitted fields from ``log_timing``, the others from ``timing0``."""
    return jnp.asarray(timing0).at[_FITTED_INDEX].set(jnp.exp(log_timing))


def _log(x):
    """log x, floored at 1e-300 (a straight path's curvature is 0 or 1e-27) with finite gradients."""
    return jnp.log(jnp.maximum(x, 1e-300))


def _block(values, mask):
    m = mask.astype(values.dtype)
    return jnp.where(mask, values, 0.0) / jnp.sqrt(jnp.maximum(jnp.sum(m), 1.0))


def residuals(params, problem: FitProblem):
    """The residual vector (module docstring) at ``params = (log_weights, log_timing)``.

    Blocks, in order: stride (F), duty factor (F), duty slope (1), jerk, curvature and clearance
    (C each), the weights' blocks of :data:`WEIGHT_BLOCKS` (F each; zeros when off), and the
    prior (19 + 4). Its length depends on F and C only.

    Parameters
    ----------
    params : tuple of jax.Array
        ``(log_weights (19,), log_timing (4,))``: logs of ``ScoringWeights.to_array()`` and of
        the :data:`FITTED_TIMING` fields.
    problem : FitProblem
        The situations and their targets (:func:`make_problem`).

    Returns
    -------
    jax.Array, shape (7 F + 3 C + 24,)
        The residuals; 0 where a target is met.

    Examples
    --------
    At the harvest's parameters only the stride block is off: each of the three new swings
    commands a stride 2.0 / 2.3 of the target, (2.0 / 2.3 - 1) / 0.15 tolerances, the block
    divided by the square root of its count:

    >>> import jax
    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import harvest_situations, load_targets, make_problem, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2,
    ...                              timing=GaitTiming(stride_coefficient=2.0))
    >>> situations = situations_from_harvest(harvest)
    >>> problem = make_problem(situations, harvest.creatures, load_targets(creatures=("spider",)), tau=0.01)
    >>> from footfall.tuning import residuals
    >>> r = jax.jit(residuals)((problem.log_weights0, problem.log_timing0), problem)
    >>> r.shape
    (48,)
    >>> [round(float(x), 4) for x in r[:3]], round((2.0 / 2.3 - 1) / 0.15 / 3 ** 0.5, 4)
    ([-0.502, -0.502, -0.502], -0.502)
    >>> bool((r[3:] == 0).all())
    True
    """
    log_weights, log_timing = params
    if not problem.fit_timing:
        log_timing = jax.lax.stop_gradient(log_timing)
    s = problem.situations
    w = jnp.exp(log_weights)
    timing = timing_vector(log_timing, s.timing0)
    # The touch-down clearance is capped at the style's minimum where there is one (the path clearance
    # at the clearance target, as before).
    td_on = problem.touchdown_clearance_m > 0.0
    m = expected_metrics(w, timing, s, problem.tau, clearance_cap_m=problem.clearance_min_m,
                         touchdown_cap_m=jnp.where(td_on, problem.touchdown_clearance_m, 1.0))
    td = m["touchdown_clearance_m"]
    moving = s.speed > 0.0
    frequency = stride_frequency(timing, s.speed, s.leg_height)
    commanded = jnp.where(moving, s.speed / jnp.where(moving, frequency, 1.0), 0.0)
    stride = (problem.stride_correction * commanded / problem.stride_target_m - 1.0) / problem.stride_tolerance
    duty = duty_factor(timing, s.speed, s.leg_height) + problem.duty_correction
    width = problem.duty_high - problem.duty_low
    duty_out = (jax.nn.relu(problem.duty_low - duty) + jax.nn.relu(duty - problem.duty_high)) / width
    slope = jax.nn.relu(-timing[TIMING_FIELDS.index("duty_slope")] - problem.max_duty_slope)
    one_hot = problem.creature_one_hot
    count = jnp.maximum(jnp.sum(one_hot, axis=0), 1.0)

    def per_creature(values):  # (F,) -> (C,) mean over each creature's situations
        return (values @ one_hot) / count

    present = jnp.sum(one_hot, axis=0) > 0.0
    # The targets are per creature; every situation of a creature carries the same numbers.
    jerk_max = per_creature(problem.jerk_max)
    curvature_max = per_creature(problem.curvature_max)
    clearance_min = per_creature(problem.clearance_min_m)
    jerk = jax.nn.relu(jnp.log(per_creature(m["jerk"]) / jnp.where(present, jerk_max, 1.0)))
    curvature = jax.nn.relu(per_creature(m["curvature_energy"]) / jnp.where(present, curvature_max, 1.0) - 1.0)
    clearance = jax.nn.relu(1.0 - per_creature(m["clearance_m"]) / jnp.where(present, clearance_min, 1.0))
    scale = jnp.where(problem.stride_mask, problem.stride_tolerance * problem.stride_target_m, 1.0)  # 0 when standing
    offset = jnp.sqrt(problem.offset_weight) * m["offset_m"] / scale
    slope_on = jnp.isfinite(problem.slope_max)
    slope_hinge = jax.nn.relu(m["touchdown_slope_rad"] / jnp.where(slope_on, problem.slope_max, 1.0) - 1.0)
    detour_on = jnp.isfinite(problem.detour_max)
    # Log ratios (as the exact run losses, tuning._events): a few detours around a crate are 10x the
    # straight distance, and a linear hinge squared let them dominate the fit.
    detour = jax.nn.relu(_log(m["detour_ratio"]) - jnp.log(jnp.where(detour_on, problem.detour_max, 1.0)))
    td_hinge = jax.nn.relu(1.0 - td / jnp.where(td_on, problem.touchdown_clearance_m, 1.0))
    curv_on = jnp.isfinite(problem.curvature_p95_max)
    curv = jax.nn.relu(_log(m["curvature_energy"]) - jnp.log(jnp.where(curv_on, problem.curvature_p95_max, 1.0)))
    return jnp.concatenate([
        _block(jnp.where(problem.stride_mask, stride, 0.0), problem.stride_mask),
        _block(duty_out, problem.duty_mask),
        slope[None],
        jnp.sqrt(problem.jerk_weight) * jnp.where(present, jerk, 0.0),
        jnp.where(present, curvature, 0.0),
        jnp.where(present, clearance, 0.0),
        _block(jnp.where(problem.stride_mask, offset, 0.0), problem.stride_mask & (problem.offset_weight > 0.0)),
        _block(slope_hinge, slope_on),
        _block(detour, detour_on),
        _block(td_hinge, td_on),
        _block(curv, curv_on),
        (log_weights - problem.log_weights0) / problem.prior_log_scale,
        (log_timing - problem.log_timing0) / problem.prior_log_scale,
    ])


def loss(params, problem: FitProblem):
    """1/2 |residuals|^2.

    Parameters
    ----------
    params : tuple of jax.Array
        ``(log_weights (19,), log_timing (4,))`` (:func:`residuals`).
    problem : FitProblem
        The situations and their targets (:func:`make_problem`).

    Returns
    -------
    jax.Array, shape ()
        The loss, >= 0; 0 when every target is met at the harvest's parameters.

    Examples
    --------
    The three stride residuals of :func:`residuals`, -0.8696 / sqrt(3) each, give
    1/2 x 0.8696^2:

    >>> import jax
    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import harvest_situations, load_targets, make_problem, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2,
    ...                              timing=GaitTiming(stride_coefficient=2.0))
    >>> situations = situations_from_harvest(harvest)
    >>> problem = make_problem(situations, harvest.creatures, load_targets(creatures=("spider",)), tau=0.01)
    >>> from footfall.tuning import loss
    >>> params = (problem.log_weights0, problem.log_timing0)
    >>> round(float(jax.jit(loss)(params, problem)), 4), round(0.5 * ((2.0 / 2.3 - 1) / 0.15) ** 2, 4)
    (0.3781, 0.3781)
    """
    r = residuals(params, problem)
    return 0.5 * jnp.sum(r * r)


def _fn(params, problem):
    return residuals(params, problem), None


@eqx.filter_jit
def _run(params, problem: FitProblem, solver, n_steps: int):
    f_struct, aux_struct = jax.eval_shape(lambda: _fn(params, problem))
    options: dict = {}
    tags = frozenset()
    state = solver.init(_fn, params, problem, options, f_struct, aux_struct, tags)
    # The solver state holds non-array leaves (e.g. the Jacobian operator's jaxpr): only its
    # arrays go through the scan carry; the rest is the same at every step.
    dynamic, static = eqx.partition(state, eqx.is_array)

    def one_step(carry, _):
        y, dyn = carry
        y, st, _ = solver.step(_fn, y, problem, options, eqx.combine(dyn, static), tags)
        return (y, eqx.filter(st, eqx.is_array)), loss(y, problem)

    (params, _), history = jax.lax.scan(one_step, (params, dynamic), None, length=n_steps)
    return params, history


def fit(problem: FitProblem, n_steps: int = 20, solver=None):
    """Levenberg-Marquardt from the harvest's parameters. Returns (weights (19,), timing (7,),
    loss history (n_steps,)) as numpy arrays; the loss before the fit is ``loss(initial, problem)``.

    The steps run as one compiled ``lax.scan`` (a new ``n_steps`` compiles afresh). Entry ``k`` of
    the history is the loss at the parameters after ``k + 1`` steps. The first step evaluates the
    starting point and proposes a move, so ``history[0]`` is the initial loss and a fit needs
    ``n_steps >= 2`` to move the parameters.

    Parameters
    ----------
    problem : FitProblem
        The situations and their targets (:func:`make_problem`).
    n_steps : int, optional
        Number of solver steps, >= 1 (default 20).
    solver : optimistix solver, optional
        Default ``optimistix.LevenbergMarquardt(rtol=1e-8, atol=1e-8)``.

    Returns
    -------
    weights : numpy.ndarray, shape (19,)
        Fitted ``ScoringWeights.to_array()``.
    timing : numpy.ndarray, shape (7,)
        Fitted ``GaitTiming.to_array()`` (the fields outside :data:`FITTED_TIMING` are the
        harvest's).
    history : numpy.ndarray, shape (n_steps,)
        The loss after each step.

    Raises
    ------
    ValueError
        If ``n_steps`` is not an integer >= 1.

    Examples
    --------
    A spider harvested with a too short stride law (coefficient 2.0, target 2.3). One step only
    evaluates the start: ``history[0]`` is the loss there, and the parameters have not moved. (Two
    steps bring the loss from 0.3781 to 0.0026 and lengthen the commanded stride: the fit's tests,
    ``tests/test_tuning_fit.py``; each ``n_steps`` compiles its own program, about 7 s for two.)

    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import harvest_situations, load_targets, make_problem, situations_from_harvest
    >>> from footfall.tuning import fit, loss
    >>> from footfall.tuning._fit import initial_params
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2,
    ...                              timing=GaitTiming(stride_coefficient=2.0))
    >>> situations = situations_from_harvest(harvest)
    >>> problem = make_problem(situations, harvest.creatures, load_targets(creatures=("spider",)), tau=0.01)
    >>> weights, timing, history = fit(problem, n_steps=1)
    >>> weights.shape, timing.shape, history.shape
    ((19,), (7,), (1,))
    >>> round(float(history[0]), 4), bool(abs(history[0] - loss(initial_params(problem), problem)) < 1e-12)
    (0.3781, True)
    >>> GaitTiming.from_array(timing).stride_coefficient
    2.0
    """
    if isinstance(n_steps, bool) or not isinstance(n_steps, int) or n_steps < 1:
        raise ValueError(f"n_steps: expected an integer >= 1, got {n_steps!r}")
    solver = solver or optx.LevenbergMarquardt(rtol=1e-8, atol=1e-8)
    params, history = _run(initial_params(problem), problem, solver, n_steps)
    log_weights, log_timing = params
    return (np.exp(np.asarray(log_weights)), np.asarray(timing_vector(log_timing, problem.situations.timing0)),
            np.asarray(history))


def initial_params(problem: FitProblem):
    return (problem.log_weights0, problem.log_timing0)


# One compiled program per problem shape: evaluated eagerly, each of the loss's primitives compiles a
# program of its own (with the Spearman check's, a tiny tune's 266 programs -> 57 on a cold compilation
# cache, 2026-11-26).
_compiled_loss = eqx.filter_jit(loss)


def initial_loss(problem: FitProblem) -> float:
    """:func:`loss` at the harvest's parameters (``initial_params``), as one compiled program."""
    return float(_compiled_loss(initial_params(problem), problem))
