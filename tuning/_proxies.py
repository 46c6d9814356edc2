"""Differentiable proxies of the discrete couple choice.

The runtime picks, per planning situation, the couple (candidate footprint k,
slice s) of highest couple score: an argmax, piecewise constant in the weights.
The proxy replaces it by a soft selection over the harvested couples of the
situation::

    p_ks = softmax_{valid (k, s)} (score_ks(w, theta) / tau)

and reports expectations under p (step length, curvature energy, clearance,
climb, jerk, ...) as smooth functions of the scoring weights ``w``
(``ScoringWeights.to_array()``) and the gait-timing parameters ``theta``
(``GaitTiming.to_array()``). As tau -> 0, p tends to the one-hot of the runtime's
argmax (uniform over exact ties), so the expectations tend to the metrics of the
couple the exhaustive search picks.

Temperature
-----------
Couple scores are weighted means of goodnesses in [0, 1]. At tau a couple whose score is tau lower
than another weighs e^-1 as much. The legacy stride tune uses tau = 0.05; the terrain and style tunes
(the weights' blocks of :mod:`tuning._fit`) use tau = 0.01: a spider's candidate one cell (7 cm)
farther from the preferred footprint loses 3/13 x 0.07 / 0.3 = 0.054 of score at the default weights
and weighs e^-5.4 (0.5 %) as much, so the expected offset from the preferred footprint stays near the
argmax's (1.4 cm against 0.9 cm on stairs, crates, hills and mixed) while near-ties still share the
probability and give every weight a gradient.

How the timing parameters reach the choice
------------------------------------------
theta shapes the *preferred footprint* P the controller asks for
(``planner._crowd.stage_plan``)::

    P = predicted pelvis + rest foot + forward * v * t_stance / 2,
    predicted pelvis = pelvis + forward * v * t_swing,

with the stride frequency f(v) = max(v / lambda(v), min_frequency),
lambda(v) = stride_coefficient * h * Fr^stride_exponent, the duty factor DF(v),
t_stance = DF / f, and for a new swing t_swing = min(clip((1 - DF) r, 0.05, 0.95) / f, 1)
(r = the leg's authored swing duration over the mean; a re-plan keeps the rest of
the swing in progress, so its t_swing does not depend on theta; the runtime also takes off a new swing's
lateness, the part of a frame since the needle entered its sector, ``planner._crowd.lift_lateness``,
which the harvest's P holds and the proxy keeps fixed: under a frame, 33 ms). So P moves
along the heading by ``v * (g(theta) - g(theta_0))``, g = t_swing + t_stance / 2,
with theta_0 the timing of the harvest: at theta_0 the proxy sees exactly the
runtime's P. In steady walking the realised step (lift-off to touch-down of one
foot) is one stride v / f = lambda, symmetric about the rest foot.

P enters the couple score through the candidates' footprints x_k: the distance
feature d_k = |x_k - P| of every candidate (closeness goodness) and the length
goodness's reference d_ref,k = max(|x_k - source|, cell). The expected step length therefore depends on
theta through the probabilities and the continuous footprints: each candidate's
footprint x_k is its cell's point nearest P (:func:`footprints`, the runtime's
``footprint_point``; moved out of another foot's room as the runtime moved it), so it
follows P inside its cell; the source and every other
raw number are the harvest's, held fixed. This is a local model, valid
while P stays well inside the harvested candidate disc (the runtime would re-centre
the disc on the new P and plan new paths); a fit should re-harvest between
iterations. The other legs' hips (crossings and gaps) are also held at theta_0.

The gait transitions of ``planner._gait`` are not modelled: the runtime's disks
move toward the destination disks while in stance; g uses the destination (steady
state) durations. Only differences of g enter, so this affects the sensitivity, not
the value at theta_0.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from footfall.planner import GRAVITY, SWING_MAX, SWING_MIN, duty_law, stance_lead, stride_law
from footfall.planner.layout import (
    FEAT_DISTANCE,
    FEAT_PROXIMITY,
    FEAT_ROUGHNESS,
    FEAT_SLOPE,
    KIND_REPLAN,
    N_FEATURES,
    N_RAW,
    RAW_CLEARANCE,
    RAW_CLIMB,
    RAW_CURVATURE,
    RAW_JERK,
    RAW_LENGTH,
    T_DUTY_AT_REST,
    T_DUTY_MAX,
    T_DUTY_MIN,
    T_DUTY_SLOPE,
    T_MIN_FREQUENCY,
    T_STRIDE_COEFFICIENT,
    T_STRIDE_EXPONENT,
)
from footfall.tuning._config import enable_x64
from footfall.tuning._scoring import couple_score

LEAST_FREQUENCY_HZ = 1e-3
"""The crowd divides by max(f, 1e-3) (planner._crowd.stage_plan)."""

PROXY_METRICS = ("step_length_m", "forward_offset_m", "offset_m", "touchdown_slope_rad", "touchdown_roughness_m",
                 "detour_ratio", "touchdown_clearance_m", "length_m", "curvature_energy", "clearance_m", "climb_m", "jerk", "couple_score")
"""Keys of :func:`expected_metrics`, each (F,) per situation:

* ``step_length_m``: horizontal distance source -> target;
* ``forward_offset_m``: (target - P) along the heading (how far the weights pull the
  foot ahead of, > 0, or behind the preferred footprint);
* ``offset_m``: |target - P|, the distance feature (how far the chosen footprint lands from the
  preferred one: a stride is the spacing of two touch-downs, so the offsets are what the weights
  add to the per-stride error, :mod:`tuning._fit`);
* ``touchdown_slope_rad``, ``touchdown_roughness_m``: the slope and the roughness (largest height
  step to a neighbour cell) under the chosen footprint (``planner.FEATURES``);
* ``detour_ratio``: the swing path's ground length / the straight distance source -> footprint
  (``d_ref``): 1 for a direct swing, more for a detour around or over an obstacle;
* ``touchdown_clearance_m``: the footprint's distance to forbidden cells (``obstacle_distance_m``,
  the creature-dilated forbidden region of the local map), capped at ``clearance_cap_m`` as the
  path clearance is (+inf when no forbidden cell is in the map);
* ``length_m``, ``curvature_energy``, ``clearance_m``, ``climb_m``, ``jerk``: the raw
  trajectory metrics (``planner.RAW_METRICS``); the clearance is capped at
  ``clearance_cap_m`` (a number or (F,); +inf when nothing is blocked around a path);
* ``couple_score``: the expected couple score.
"""


class Situations(eqx.Module):
    """Harvested planning situations as float64 JAX arrays (F situations, K candidates, S slices);
    only situations with at least one couple are kept (the softmax needs one).

    Build it with :func:`situations_from_harvest`. An ``equinox.Module``: a pytree of arrays that
    ``jax.jit`` and ``jax.grad`` take as an argument.

    Attributes
    ----------
    cand_mask, cand_xz, cand_centre, cand_features : jax.Array
        Per candidate (F, K, ...): valid, footprint (x, z) (m), its cell's centre (m), raw
        features (``planner.FEATURES``).
    couple_mask, couple_raw : jax.Array
        Per couple (F, K, S, ...): valid, raw trajectory metrics (``planner.RAW_METRICS``).
    d_ref : jax.Array
        (F, K) the length goodness's reference (m) of each candidate at the harvest's timing.
    source, preferred, forward : jax.Array
        Where the foot was, (x, y, z) (F, 3); the preferred footprint (x, z) at the harvest's
        timing (F, 2); the unit heading (x, z) (F, 2).
    speed, leg_height, relative_swing, cell_size : jax.Array
        (F,) the creature's speed (m/s), its hip height h (m), the leg's authored swing duration
        over the mean, and the local map's cell size (m).
    new_swing : jax.Array
        (F,) bool: a new swing (True) or a re-plan of a swing in progress.
    creature : jax.Array
        (F,) int: index in the harvest's ``creatures``.
    timing0, weights0 : jax.Array
        ``GaitTiming.to_array()`` (7,) and ``ScoringWeights.to_array()`` (19,) of the harvest.
    n_situations : int
        F.

    Examples
    --------
    >>> from footfall.tuning import harvest_situations, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2)
    >>> situations = situations_from_harvest(harvest)
    >>> situations.n_situations                     # the first frame's three requests
    3
    >>> situations.cand_xz.shape, situations.couple_raw.shape
    ((3, 20, 2), (3, 20, 1, 5))
    >>> situations.timing0.shape, situations.weights0.shape
    ((7,), (19,))
    """

    cand_mask: jax.Array  # (F, K) bool
    cand_xz: jax.Array  # (F, K, 2)
    cand_centre: jax.Array  # (F, K, 2) centres of the candidate cells
    cand_features: jax.Array  # (F, K, 5)
    couple_mask: jax.Array  # (F, K, S) bool
    couple_raw: jax.Array  # (F, K, S, 5)
    d_ref: jax.Array  # (F, K) the length goodness's reference of each candidate at the harvest's timing
    source: jax.Array  # (F, 3)
    preferred: jax.Array  # (F, 2) at the harvest's timing
    forward: jax.Array  # (F, 2)
    speed: jax.Array  # (F,)
    leg_height: jax.Array  # (F,)
    relative_swing: jax.Array  # (F,)
    new_swing: jax.Array  # (F,) bool
    cell_size: jax.Array  # (F,)
    creature: jax.Array  # (F,) int
    timing0: jax.Array  # (7,) GaitTiming.to_array() of the harvest
    weights0: jax.Array  # (19,) ScoringWeights.to_array() of the harvest

    @property
    def n_situations(self) -> int:
        return int(self.speed.shape[0])


def situations_from_harvest(harvest) -> Situations:
    """Convert a :class:`planner.Harvest` (enables float64 in JAX).

    Situations without a valid couple are dropped; the candidates' footprints keep their
    horizontal coordinates (x, z), and a situation is a new swing unless it re-plans a swing in
    progress.

    Parameters
    ----------
    harvest : footfall.planner.Harvest
        E.g. :func:`harvest_situations` output.

    Returns
    -------
    Situations
        The kept situations as float64 (and bool, int) JAX arrays.

    Raises
    ------
    ValueError
        If the harvest's features or raw metrics do not have the runtime's widths.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.tuning import harvest_situations, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2)
    >>> situations = situations_from_harvest(harvest)
    >>> situations.n_situations == int(harvest.has_couple.sum())
    True
    >>> situations.cand_features.dtype, situations.cand_features.shape
    (dtype('float64'), (3, 20, 5))
    >>> bool(np.array_equal(situations.speed, harvest.speed[harvest.has_couple]))
    True
    """
    enable_x64()
    keep = np.asarray(harvest.has_couple)

    def f64(a):
        return jnp.asarray(np.asarray(a)[keep], dtype=jnp.float64)

    if harvest.cand_features.shape[-1] != N_FEATURES or harvest.couple_raw.shape[-1] != N_RAW:
        raise ValueError("harvest: features or raw metrics of the wrong width")
    return Situations(
        cand_mask=jnp.asarray(harvest.cand_mask[keep]), cand_xz=f64(harvest.cand_xyz[..., [0, 2]]),
        cand_centre=f64(harvest.cand_centre_xz),
        cand_features=f64(harvest.cand_features), couple_mask=jnp.asarray(harvest.couple_mask[keep]),
        couple_raw=f64(harvest.couple_raw), d_ref=f64(harvest.d_ref), source=f64(harvest.source), preferred=f64(harvest.preferred),
        forward=f64(harvest.forward), speed=f64(harvest.speed), leg_height=f64(harvest.leg_height),
        relative_swing=f64(harvest.relative_swing), new_swing=jnp.asarray(harvest.kind[keep] != KIND_REPLAN),
        cell_size=f64(harvest.cell_size), creature=jnp.asarray(harvest.creature[keep]),
        timing0=jnp.asarray(harvest.timing, dtype=jnp.float64),
        weights0=jnp.asarray(harvest.weights, dtype=jnp.float64))


def stride_length(timing, speed, leg_height):
    """lambda(v) = stride_coefficient * h * Fr^stride_exponent, 0 at v = 0 (planner._timing).

    Fr = v^2 / (g h) is the Froude number. The JAX twin of :func:`footfall.planner.stride_length`,
    differentiable in ``timing`` (also at v = 0, where the gradient is 0).

    Parameters
    ----------
    timing : jax.Array, shape (7,)
        ``GaitTiming.to_array()``.
    speed : array_like
        Speed v (m/s), >= 0.
    leg_height : array_like
        Hip height h (m), > 0; broadcasts against ``speed``.

    Returns
    -------
    jax.Array
        The stride length lambda (m), shaped as ``speed`` and ``leg_height`` broadcast.

    Examples
    --------
    At Fr = 1 the stride is ``stride_coefficient * h`` (2.3 x 0.12 m); the numbers are the
    runtime's:

    >>> import numpy as np
    >>> import jax.numpy as jnp
    >>> from footfall import planner
    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import enable_x64, stride_length
    >>> enable_x64()
    >>> timing = jnp.asarray(GaitTiming().to_array())
    >>> v = np.array([0.0, 0.5, (9.81 * 0.12) ** 0.5])
    >>> [round(float(x), 4) for x in stride_length(timing, v, 0.12)]
    [0.0, 0.1734, 0.276]
    >>> bool(np.abs(stride_length(timing, v, 0.12) - planner.stride_length(GaitTiming(), v, 0.12)).max() < 1e-12)
    True
    """
    moving = speed > 0.0
    v = jnp.where(moving, speed, 1.0)  # a safe value where v = 0: Fr^b has no derivative in b at Fr = 0
    length = stride_law(timing[T_STRIDE_COEFFICIENT], timing[T_STRIDE_EXPONENT], v, leg_height)
    return jnp.where(moving, length, 0.0)


def stride_frequency(timing, speed, leg_height):
    """f(v) = max(v / lambda(v), min_frequency_hz) where lambda > 0, else 0 (planner._timing).

    The JAX twin of :func:`footfall.planner.stride_frequency`.

    Parameters
    ----------
    timing : jax.Array, shape (7,)
        ``GaitTiming.to_array()``.
    speed : array_like
        Speed v (m/s), >= 0.
    leg_height : array_like
        Hip height h (m), > 0; broadcasts against ``speed``.

    Returns
    -------
    jax.Array
        The stride frequency f (Hz): 0 at v = 0, at least ``min_frequency_hz`` (default 0.5 Hz)
        when moving.

    Examples
    --------
    >>> import numpy as np
    >>> import jax.numpy as jnp
    >>> from footfall import planner
    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import enable_x64, stride_frequency
    >>> enable_x64()
    >>> timing = jnp.asarray(GaitTiming().to_array())
    >>> v = np.array([0.0, 0.001, 0.5])             # standing, creeping (the floor), walking
    >>> [round(float(x), 4) for x in stride_frequency(timing, v, 0.12)]
    [0.0, 0.5, 2.8836]
    >>> bool(np.abs(stride_frequency(timing, v, 0.12) - planner.stride_frequency(GaitTiming(), v, 0.12)).max()
    ...      < 1e-12)
    True
    """
    moving = stride_length(timing, speed, leg_height) > 0.0
    v = jnp.where(moving, speed, 1.0)
    natural = v / stride_length(timing, v, leg_height)
    return jnp.where(moving, jnp.maximum(natural, timing[T_MIN_FREQUENCY]), 0.0)


def duty_factor(timing, speed, leg_height):
    """DF(v) = clip(duty_at_rest - duty_slope * v / sqrt(g h), duty_min, duty_max) (planner._timing).

    The duty factor (stance fraction of a stride cycle); the JAX twin of
    :func:`footfall.planner.duty_factor`.

    Parameters
    ----------
    timing : jax.Array, shape (7,)
        ``GaitTiming.to_array()``.
    speed : array_like
        Speed v (m/s), >= 0.
    leg_height : array_like
        Hip height h (m), > 0; broadcasts against ``speed``.

    Returns
    -------
    jax.Array
        The duty factor DF, in [duty_min, duty_max].

    Examples
    --------
    The defaults: 0.72 at rest, 0.72 - 0.22 = 0.5 at v = sqrt(g h), and no lower than
    ``duty_min`` = 0.5 beyond:

    >>> import numpy as np
    >>> import jax.numpy as jnp
    >>> from footfall import planner
    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import duty_factor, enable_x64
    >>> enable_x64()
    >>> timing = jnp.asarray(GaitTiming().to_array())
    >>> v = np.array([0.0, 1.0, 2.0]) * (9.81 * 0.12) ** 0.5
    >>> [round(float(x), 4) for x in duty_factor(timing, v, 0.12)]
    [0.72, 0.5, 0.5]
    >>> bool(np.abs(duty_factor(timing, v, 0.12) - planner.duty_factor(GaitTiming(), v, 0.12)).max() < 1e-12)
    True
    """
    raw = duty_law(timing[T_DUTY_AT_REST], timing[T_DUTY_SLOPE], speed, jnp.sqrt(GRAVITY * leg_height))
    return jnp.clip(raw, timing[T_DUTY_MIN], timing[T_DUTY_MAX])


def preferred_lead_time(timing, speed, leg_height, relative_swing, new_swing):
    """g = t_swing + t_stance / 2 (s, steady state; module docstring): P leads by v * g.
    A re-plan's t_swing does not depend on the timing and is left out (only differences matter).

    t_stance = DF / f and, for a new swing, t_swing = min(clip((1 - DF) r, 0.05, 0.95) / f, 1),
    with f floored at :data:`LEAST_FREQUENCY_HZ`.

    Parameters
    ----------
    timing : jax.Array, shape (7,)
        ``GaitTiming.to_array()``.
    speed, leg_height : array_like
        Speed v (m/s) and hip height h (m).
    relative_swing : array_like
        r: the leg's authored swing duration over the gait's mean.
    new_swing : array_like of bool
        A new swing (True) or a re-plan (False: no t_swing term).

    Returns
    -------
    jax.Array
        The lead time g (s), shaped as the inputs broadcast.

    Examples
    --------
    At 0.5 m/s with h = 0.12 m, the runtime's f and DF give the same lead time by hand:

    >>> import jax.numpy as jnp
    >>> from footfall import planner
    >>> from footfall.planner import GaitTiming
    >>> from footfall.tuning import enable_x64, preferred_lead_time
    >>> enable_x64()
    >>> timing = jnp.asarray(GaitTiming().to_array())
    >>> f = planner.stride_frequency(GaitTiming(), 0.5, 0.12)
    >>> df = planner.duty_factor(GaitTiming(), 0.5, 0.12)
    >>> by_hand = min(min(max(1.0 - df, 0.05), 0.95) / f, 1.0) + 0.5 * df / f
    >>> g = preferred_lead_time(timing, 0.5, 0.12, 1.0, True)
    >>> round(float(g), 4), bool(abs(float(g) - by_hand) < 1e-12)
    (0.2395, True)
    >>> round(float(preferred_lead_time(timing, 0.5, 0.12, 1.0, False)), 4)   # a re-plan: DF / (2 f)
    0.1073
    """
    frequency = jnp.maximum(stride_frequency(timing, speed, leg_height), LEAST_FREQUENCY_HZ)
    duty = duty_factor(timing, speed, leg_height)
    swing = jnp.clip((1.0 - duty) * relative_swing, SWING_MIN, SWING_MAX)
    t_swing = jnp.where(new_swing, jnp.minimum(swing / frequency, 1.0), 0.0)
    # 0.5 * (DF / f) is (0.5 * DF) / f bit for bit: halving is exact.
    return t_swing + stance_lead(duty / frequency)


def preferred_footprint(timing, situations: Situations):
    """(F, 2) the preferred footprint at timing ``theta``; = the harvest's at theta_0.

    P moves along each situation's heading by v (g(theta) - g(theta_0)), g the
    :func:`preferred_lead_time`. For a body still turning, the runtime also turns P with the turn a
    longer or shorter swing makes (``planner._crowd.touchdown_turn``); the proxy keeps the heading of
    the lift-off, exact at theta_0 and for straight walking.

    Parameters
    ----------
    timing : jax.Array, shape (7,)
        ``GaitTiming.to_array()`` theta.
    situations : Situations
        The harvested situations (their ``timing0`` is theta_0).

    Returns
    -------
    jax.Array, shape (F, 2)
        The preferred footprints (x, z) (m).

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.tuning import harvest_situations, preferred_footprint, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2)
    >>> s = situations_from_harvest(harvest)
    >>> bool(np.array_equal(preferred_footprint(s.timing0, s), harvest.preferred[harvest.has_couple]))
    True

    A longer stride law (stride_coefficient 2.3 -> 2.6) means a lower stride frequency, longer
    stance and swing times, so P moves ahead along the heading:

    >>> moved = preferred_footprint(s.timing0.at[0].set(2.6), s)
    >>> ahead = ((moved - s.preferred) * s.forward).sum(axis=1)
    >>> bool((ahead > 0).all())
    True
    """
    s = situations
    args = (s.speed, s.leg_height, s.relative_swing, s.new_swing)
    shift = s.speed * (preferred_lead_time(timing, *args) - preferred_lead_time(s.timing0, *args))
    return s.preferred + s.forward * shift[:, None]


def _norm(dx, dz):
    # sqrt of a floored square: equal to hypot away from 0, and differentiable at 0.
    return jnp.sqrt(jnp.maximum(dx * dx + dz * dz, 1e-300))


def footprints(situations: Situations, pref):
    """(F, K, 2) the candidates' continuous footprints for preferred footprints ``pref`` (F, 2): each
    cell's point nearest P (planner._kernels_foot.footprint_point); = the harvest's at theta_0.

    A footprint the runtime moved out of another foot's room (planner._kernels_foot.out_of_other_feet:
    the harvest's point is not its cell's point nearest P) keeps that move and follows P with it, the
    other legs being held at theta_0."""
    s = situations
    half = 0.5 * s.cell_size[:, None, None]
    nearest = jnp.clip(pref[:, None, :], s.cand_centre - half, s.cand_centre + half)
    nearest0 = jnp.clip(s.preferred[:, None, :], s.cand_centre - half, s.cand_centre + half)
    moved = jnp.any(s.cand_xz != nearest0, axis=-1, keepdims=True)
    return jnp.where(moved, s.cand_xz + (nearest - nearest0), nearest)


def moved_paths(situations: Situations, x):
    """(d_ref (F, K), raw (F, K, S, 5)) for the candidates' footprints ``x`` (F, K, 2): the length
    goodness's reference, each candidate's straight distance from the source to its own footprint
    (planner._kernels_search.directness_references), and the raw metrics with each path's length
    moved by as much as that distance (a footprint moving inside its cell lengthens or shortens the
    path's last stretch; its detour is held). Both are the harvest's at theta_0."""
    s = situations
    d_ref = jnp.maximum(_norm(x[..., 0] - s.source[:, None, 0], x[..., 1] - s.source[:, None, 2]),
                        s.cell_size[:, None])
    raw = s.couple_raw.at[..., RAW_LENGTH].add((d_ref - s.d_ref)[..., None])
    return d_ref, raw


def couple_scores(weights, timing, situations: Situations):
    """(F, K, S) couple scores at weights ``w`` and timing ``theta`` (invalid couples: -inf).

    Each candidate's footprint follows the :func:`preferred_footprint` inside its cell (the
    distance feature and the path lengths move with it); every other raw number is the
    harvest's. At the harvest's timing these are the runtime's scores.

    Parameters
    ----------
    weights : jax.Array, shape (19,)
        ``ScoringWeights.to_array()`` w.
    timing : jax.Array, shape (7,)
        ``GaitTiming.to_array()`` theta.
    situations : Situations
        The harvested situations.

    Returns
    -------
    jax.Array, shape (F, K, S)
        :func:`couple_score` of every couple; -inf where ``situations.couple_mask`` is False.

    Examples
    --------
    At the harvest's parameters the scores are the runtime's (numba) ones:

    >>> import numpy as np
    >>> from footfall.tuning import couple_scores, harvest_situations, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2)
    >>> s = situations_from_harvest(harvest)
    >>> scores = np.asarray(couple_scores(s.weights0, s.timing0, s))
    >>> scores.shape
    (3, 20, 1)
    >>> valid = harvest.couple_mask[harvest.has_couple]
    >>> bool(np.abs(scores[valid] - harvest.couple_scores[harvest.has_couple][..., 0][valid]).max() < 1e-12)
    True
    >>> bool(np.isneginf(scores[~valid]).all())
    True
    """
    s = situations
    pref = preferred_footprint(timing, s)
    x = footprints(s, pref)
    d = _norm(x[..., 0] - pref[:, None, 0], x[..., 1] - pref[:, None, 1])
    features = s.cand_features.at[..., FEAT_DISTANCE].set(d)
    d_ref, raw = moved_paths(s, x)
    score = couple_score(features[:, :, None, :], raw, d_ref[:, :, None], weights)
    return jnp.where(s.couple_mask, score, -jnp.inf)


def soft_selection(scores, mask, tau):
    """(F, K, S) probabilities softmax(score / tau) over the valid couples of each situation.

    The largest valid score is subtracted first (outside the gradient) so that the exponentials
    never overflow; invalid couples get probability 0.

    Parameters
    ----------
    scores : jax.Array, shape (F, K, S)
        Couple scores (:func:`couple_scores`; invalid entries may be -inf).
    mask : jax.Array, shape (F, K, S)
        Valid couples; every situation needs at least one.
    tau : float
        Temperature, > 0: a couple scoring tau less than another weighs e^-1 as much.

    Returns
    -------
    jax.Array, shape (F, K, S)
        Probabilities summing to 1 over each situation's couples.

    Examples
    --------
    >>> import math
    >>> import jax.numpy as jnp
    >>> from footfall.tuning import enable_x64, soft_selection
    >>> enable_x64()
    >>> p = soft_selection(jnp.array([[[0.5], [0.4]]]), jnp.ones((1, 2, 1), dtype=bool), 0.1)
    >>> round(float(p[0, 1, 0] / p[0, 0, 0]), 4), round(math.exp(-1), 4)   # 0.1 lower: e^-1 as likely
    (0.3679, 0.3679)
    >>> p = soft_selection(jnp.array([[[0.5, 0.5], [0.4, 0.9]]]), jnp.array([[[True, True], [True, False]]]), 0.1)
    >>> [round(float(x), 4) for x in p.ravel()]     # the masked 0.9 gets nothing
    [0.4223, 0.4223, 0.1554, 0.0]
    """
    flat = scores.reshape(scores.shape[0], -1)
    valid = mask.reshape(flat.shape)
    top = jax.lax.stop_gradient(jnp.max(jnp.where(valid, flat, -jnp.inf), axis=1, keepdims=True))
    e = jnp.where(valid, jnp.exp((jnp.where(valid, flat, top) - top) / tau), 0.0)
    return (e / jnp.sum(e, axis=1, keepdims=True)).reshape(scores.shape)


def expected_metrics(weights, timing, situations: Situations, tau, clearance_cap_m=jnp.inf, touchdown_cap_m=None):
    """Expectations under the soft selection at temperature ``tau`` (> 0): a dict of (F,)
    arrays keyed by :data:`PROXY_METRICS`. ``touchdown_cap_m``: the cap of ``touchdown_clearance_m``
    (a number or (F,); None: ``clearance_cap_m``).

    Smooth in the weights and the timing: the differentiable stand-in for the metrics of the
    couple the runtime picks (:func:`hard_metrics`), which it tends to as tau -> 0 away from
    ties.

    Parameters
    ----------
    weights : jax.Array, shape (19,)
        ``ScoringWeights.to_array()`` w.
    timing : jax.Array, shape (7,)
        ``GaitTiming.to_array()`` theta.
    situations : Situations
        The harvested situations.
    tau : float
        Temperature of :func:`soft_selection`, > 0 (module docstring: 0.01 to 0.05).
    clearance_cap_m : float or jax.Array, optional
        Cap (m) of the path clearance, a number or (F,); default +inf (no cap).
    touchdown_cap_m : float or jax.Array, optional
        Cap (m) of ``touchdown_clearance_m``; None: ``clearance_cap_m``.

    Returns
    -------
    dict of str to jax.Array
        One (F,) array per key of :data:`PROXY_METRICS`.

    Examples
    --------
    >>> import jax
    >>> import jax.numpy as jnp
    >>> from footfall.tuning import expected_metrics, harvest_situations, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2)
    >>> s = situations_from_harvest(harvest)
    >>> metrics = expected_metrics(s.weights0, s.timing0, s, 0.01)
    >>> len(metrics), metrics["step_length_m"].shape
    (13, (3,))

    The expected couple score is at most the best couple's; as tau -> 0 the expectation becomes
    the metric of the best couple (:func:`hard_metrics`):

    >>> from footfall.tuning import hard_metrics
    >>> hard = hard_metrics(s.weights0, s.timing0, s)
    >>> bool((metrics["couple_score"] <= hard["couple_score"]).all())
    True
    >>> cold = expected_metrics(s.weights0, s.timing0, s, 1e-6)
    >>> bool(jnp.allclose(cold["step_length_m"], hard["step_length_m"], rtol=1e-9))
    True

    The gradient of the expected offset from the preferred footprint reaches the weights (finite,
    not all zero), which the argmax's does not:

    >>> offset = jax.jit(jax.grad(lambda w: expected_metrics(w, s.timing0, s, 0.01)["offset_m"].sum()))
    >>> grad = offset(s.weights0)
    >>> grad.shape, bool(jnp.isfinite(grad).all()), bool((grad != 0).any())
    ((19,), True, True)
    """
    scores = couple_scores(weights, timing, situations)
    p = soft_selection(scores, situations.couple_mask, tau)
    return _metrics_under(p, scores, timing, situations, clearance_cap_m, touchdown_cap_m)


def hard_metrics(weights, timing, situations: Situations, clearance_cap_m=jnp.inf):
    """The same metrics at the argmax couple of each situation (first maximum in the search's
    order, as the exhaustive search picks): the tau -> 0 limit away from ties.

    The choice is piecewise constant in the weights (a gradient does not go through it): for
    reporting and checking, not for fitting.

    Parameters
    ----------
    weights : jax.Array, shape (19,)
        ``ScoringWeights.to_array()`` w.
    timing : jax.Array, shape (7,)
        ``GaitTiming.to_array()`` theta.
    situations : Situations
        The harvested situations.
    clearance_cap_m : float or jax.Array, optional
        Cap (m) of the path clearance (and of the touch-down clearance), a number or (F,);
        default +inf.

    Returns
    -------
    dict of str to jax.Array
        One (F,) array per key of :data:`PROXY_METRICS`, at the best couple.

    Examples
    --------
    At the harvest's parameters the best couple's score is the one the runtime's exhaustive
    search found:

    >>> import numpy as np
    >>> from footfall.tuning import hard_metrics, harvest_situations, situations_from_harvest
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2)
    >>> s = situations_from_harvest(harvest)
    >>> hard = hard_metrics(s.weights0, s.timing0, s)
    >>> runtime = harvest.chosen_scores[harvest.has_couple, 0]
    >>> bool(np.abs(np.asarray(hard["couple_score"]) - runtime).max() < 1e-12)
    True
    >>> [round(float(x), 4) for x in hard["step_length_m"]]
    [0.0893, 0.0892, 0.179]
    """
    s = situations
    scores = couple_scores(weights, timing, s)
    flat = scores.reshape(scores.shape[0], -1)
    best = jnp.argmax(flat, axis=1)
    one_hot = jax.nn.one_hot(best, flat.shape[1], dtype=flat.dtype).reshape(scores.shape)
    return _metrics_under(one_hot, scores, timing, s, clearance_cap_m)


def _metrics_under(p, scores, timing, s, clearance_cap_m, touchdown_cap_m=None):
    """The PROXY_METRICS under the selection p (F, K, S): the expectations of :func:`_couple_metrics`."""
    # invalid couples have p = 0 and are zeroed (no inf * 0)
    return {key: jnp.sum(p * jnp.where(s.couple_mask, values, 0.0), axis=(1, 2))
            for key, values in _couple_metrics(scores, timing, s, clearance_cap_m, touchdown_cap_m).items()}


def _couple_metrics(scores, timing, s, clearance_cap_m, touchdown_cap_m=None):
    """The PROXY_METRICS of every couple, (F, K, S) each (invalid couples: any value)."""
    pref = preferred_footprint(timing, s)
    x = footprints(s, pref)
    step = _norm(x[..., 0] - s.source[:, None, 0], x[..., 1] - s.source[:, None, 2])
    ahead = ((x[..., 0] - pref[:, None, 0]) * s.forward[:, None, 0]
             + (x[..., 1] - pref[:, None, 1]) * s.forward[:, None, 1])
    offset = _norm(x[..., 0] - pref[:, None, 0], x[..., 1] - pref[:, None, 1])
    d_ref, raw = moved_paths(s, x)
    clearance = raw[..., RAW_CLEARANCE]
    finite = jnp.isfinite(clearance)
    cap = jnp.asarray(clearance_cap_m, dtype=clearance.dtype)
    cap = cap.reshape(cap.shape + (1,) * (clearance.ndim - cap.ndim))  # a number or (F,) per situation
    capped = jnp.where(finite, jnp.minimum(jnp.where(finite, clearance, 0.0), cap), cap)
    prox = s.cand_features[..., FEAT_PROXIMITY]
    prox_finite = jnp.isfinite(prox)
    cap_k = cap[..., 0]  # (1, 1) or (F, 1): per candidate
    if touchdown_cap_m is not None:
        cap_k = jnp.asarray(touchdown_cap_m, dtype=clearance.dtype)
        cap_k = cap_k.reshape(cap_k.shape + (1,) * (2 - cap_k.ndim))
    prox_capped = jnp.where(prox_finite, jnp.minimum(jnp.where(prox_finite, prox, 0.0), cap_k), cap_k)
    shape = raw.shape[:-1]

    def per_candidate(values):  # (F, K) -> (F, K, S)
        return jnp.broadcast_to(values[..., None], shape)

    return {
        "step_length_m": per_candidate(step),
        "forward_offset_m": per_candidate(ahead),
        "offset_m": per_candidate(offset),
        "touchdown_slope_rad": per_candidate(s.cand_features[..., FEAT_SLOPE]),
        "touchdown_roughness_m": per_candidate(s.cand_features[..., FEAT_ROUGHNESS]),
        "detour_ratio": raw[..., RAW_LENGTH] / d_ref[..., None],
        "touchdown_clearance_m": per_candidate(jnp.broadcast_to(prox_capped, step.shape)),
        "length_m": raw[..., RAW_LENGTH],
        "curvature_energy": raw[..., RAW_CURVATURE],
        "clearance_m": capped,
        "climb_m": raw[..., RAW_CLIMB],
        "jerk": raw[..., RAW_JERK],
        "couple_score": scores,
    }


# The outer boundary's compiled forms, for callers outside a jit (the tune's Spearman check, the
# metric-change validation): one program per shape and static argument, where an eager call compiles
# a program for each primitive it meets (about a hundred per call on a cold compilation cache).
compiled_couple_scores = eqx.filter_jit(couple_scores)
compiled_expected_metrics = eqx.filter_jit(expected_metrics)
