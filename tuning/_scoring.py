"""Exact scoring in JAX: the runtime's goodnesses and scores from raw numbers.

Term by term the formulas of :func:`planner._kernels_foot.footprint_goodness`,
:func:`planner._kernels_foot.trajectory_goodness` and
:func:`planner._kernels_foot.weighted_mean`: each goodness calls the same law as the kernel
(:func:`planner._weights.falling_goodness`, ``rising_goodness``, ``rational_goodness``, one
source for both), reading the weights vector ``w = ScoringWeights.to_array()`` through the
same index constants. Raw inputs are the harvest's (:mod:`planner._harvest`):

* footprint features (..., 5) in ``planner.FEATURES`` order;
* trajectory metrics (..., 5) in ``planner.RAW_METRICS`` order, and ``d_ref`` (m): the straight
  ground distance from the source to the couple's own footprint (the length goodness is directness).

Every function broadcasts over leading axes, is pure, and differentiates with
respect to ``w`` and the raw numbers. Call it with float64 inputs (``jax_enable_x64``,
see :func:`tuning.enable_x64`) to reproduce the runtime's float64 numbers.

Infinite raw numbers are legitimate (no other leg, no blocked cell in the region:
the gap, the obstacle distance or the clearance is +inf, and its goodness is 1);
they are handled with a double ``where`` so that gradients stay finite.
"""

from __future__ import annotations

import jax.numpy as jnp

from footfall.planner import falling_goodness, rational_goodness, rising_goodness
from footfall.planner.layout import (
    FEAT_DISTANCE,
    FEAT_LEG_GAP,
    FEAT_PROXIMITY,
    FEAT_ROUGHNESS,
    FEAT_SLOPE,
    N_FOOTPRINT_TERMS,
    N_TERMS,
    RAW_CLEARANCE,
    RAW_CLIMB,
    RAW_CURVATURE,
    RAW_JERK,
    RAW_LENGTH,
    W_CLEARANCE_REF,
    W_CLIMB_REF,
    W_CURVATURE_REF,
    W_DISTANCE_SCALE,
    W_JERK_REF,
    W_LEG_SPACING_REF,
    W_PROXIMITY_REF,
    W_SLOPE_CRITICAL,
    W_STEP_CRITICAL,
)


def _saturating(value, reference):
    """min(1, value / reference), = 1 for value = +inf, with finite gradients there."""
    finite = jnp.isfinite(value)
    safe = jnp.where(finite, value, 0.0)
    return jnp.where(finite, jnp.minimum(1.0, rising_goodness(safe, reference)), 1.0)


def footprint_goodness(features, w):
    """(..., 5) footprint goodnesses in [0, 1] (FOOTPRINT_TERMS order) of raw features (..., 5).

    Closeness, flatness and low slope fall linearly to 0 at their critical values (floored at 0);
    room to the other legs and distance to forbidden cells rise linearly to 1 at their reference
    scales (capped at 1; +inf gives 1).

    Parameters
    ----------
    features : array_like, shape (..., 5)
        Raw footprint features in ``planner.FEATURES`` order: distance to the preferred footprint
        (m), roughness (m), slope (rad), gap to the other legs (m), distance to the nearest
        forbidden cell (m). The last two may be +inf.
    w : jax.Array, shape (19,)
        ``ScoringWeights.to_array()``: only the reference scales are read here.

    Returns
    -------
    jax.Array, shape (..., 5)
        The goodnesses of ``planner.FOOTPRINT_TERMS``, each in [0, 1].

    Examples
    --------
    Each feature at half its critical value or reference scale (defaults 0.30 m, 0.12 m, 1 rad,
    0.05 m), and no forbidden cell in the map:

    >>> import jax.numpy as jnp
    >>> from footfall.planner import ScoringWeights
    >>> from footfall.tuning import enable_x64, footprint_goodness
    >>> enable_x64()
    >>> w = jnp.asarray(ScoringWeights().to_array())
    >>> features = jnp.array([0.15, 0.06, 0.5, 0.025, jnp.inf])
    >>> [round(float(g), 4) for g in footprint_goodness(features, w)]
    [0.5, 0.5, 0.5, 0.5, 1.0]
    >>> float(footprint_goodness(jnp.array([0.45, 0.0, 0.0, 1.0, 1.0]), w)[0])   # beyond 0.30 m: floored
    0.0
    >>> footprint_goodness(jnp.zeros((4, 3, 5)), w).shape                      # leading axes broadcast
    (4, 3, 5)
    """
    f = jnp.asarray(features)
    return jnp.stack([
        jnp.maximum(0.0, falling_goodness(f[..., FEAT_DISTANCE], w[W_DISTANCE_SCALE])),
        jnp.maximum(0.0, falling_goodness(f[..., FEAT_ROUGHNESS], w[W_STEP_CRITICAL])),
        jnp.maximum(0.0, falling_goodness(f[..., FEAT_SLOPE], w[W_SLOPE_CRITICAL])),
        _saturating(f[..., FEAT_LEG_GAP], w[W_LEG_SPACING_REF]),
        _saturating(f[..., FEAT_PROXIMITY], w[W_PROXIMITY_REF]),
    ], axis=-1)


def trajectory_goodness(raw, d_ref, w):
    """(..., 5) trajectory goodnesses in [0, 1] (TRAJECTORY_TERMS order) of raw metrics (..., 5);
    ``d_ref`` broadcasts against the leading axes.

    Directness is ``d_ref / max(length, d_ref)``; curvature, climb and jerk are
    ``1 / (1 + value / reference)`` (1/2 at the reference); the clearance rises linearly to 1 at
    its reference (capped at 1; +inf gives 1).

    Parameters
    ----------
    raw : array_like, shape (..., 5)
        Raw trajectory metrics in ``planner.RAW_METRICS`` order: path length (m), curvature
        energy (-), horizontal clearance to blocked cells (m, may be +inf), climb (m), normalised
        jerk (-).
    d_ref : array_like
        Straight ground distance (m) from the source to the couple's own footprint; broadcasts
        against ``raw[..., 0]``.
    w : jax.Array, shape (19,)
        ``ScoringWeights.to_array()``: only the reference scales are read here.

    Returns
    -------
    jax.Array, shape (..., 5)
        The goodnesses of ``planner.TRAJECTORY_TERMS``, each in [0, 1].

    Examples
    --------
    A path 0.4 m long for a 0.3 m step, curvature, climb and jerk at their references (defaults
    1.0, 0.10 m, 2000: goodness 1/2) and a clearance of half its reference (0.035 of 0.07 m):

    >>> import jax.numpy as jnp
    >>> from footfall.planner import ScoringWeights
    >>> from footfall.tuning import enable_x64, trajectory_goodness
    >>> enable_x64()
    >>> w = jnp.asarray(ScoringWeights().to_array())
    >>> raw = jnp.array([0.4, 1.0, 0.035, 0.1, 2000.0])
    >>> [round(float(g), 4) for g in trajectory_goodness(raw, 0.3, w)]
    [0.75, 0.5, 0.5, 0.5, 0.5]
    >>> straight = jnp.array([0.3, 0.0, jnp.inf, 0.0, 0.0])     # direct, flat, nothing blocked
    >>> [round(float(g), 4) for g in trajectory_goodness(straight, 0.3, w)]
    [1.0, 1.0, 1.0, 1.0, 1.0]
    """
    r = jnp.asarray(raw)
    d_ref = jnp.asarray(d_ref)
    return jnp.stack([
        rising_goodness(d_ref, jnp.maximum(r[..., RAW_LENGTH], d_ref)),
        rational_goodness(r[..., RAW_CURVATURE], w[W_CURVATURE_REF]),
        _saturating(r[..., RAW_CLEARANCE], w[W_CLEARANCE_REF]),
        rational_goodness(r[..., RAW_CLIMB], w[W_CLIMB_REF]),
        rational_goodness(r[..., RAW_JERK], w[W_JERK_REF]),
    ], axis=-1)


def weighted_mean(terms, w, lo: int, hi: int):
    """sum_k w_k terms_k / sum_k w_k over k in [lo, hi) of the last axis of ``terms`` (indexed
    from ``lo``), summed in index order as the runtime does; 0 if the weights sum to 0.

    Parameters
    ----------
    terms : jax.Array, shape (..., hi - lo)
        Goodnesses; ``terms[..., k - lo]`` goes with the weight ``w[k]``.
    w : jax.Array
        Weights vector (``ScoringWeights.to_array()`` or any vector of at least ``hi`` numbers).
    lo, hi : int
        The weights used are ``w[lo:hi]``.

    Returns
    -------
    jax.Array, shape (...,)
        The weighted mean, or 0 where ``w[lo:hi]`` sums to 0.

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> from footfall.tuning import enable_x64, weighted_mean
    >>> enable_x64()
    >>> w = jnp.array([2.0, 1.0, 1.0])
    >>> float(weighted_mean(jnp.array([1.0, 0.0, 0.5]), w, 0, 3))   # (2 + 0 + 0.5) / 4
    0.625
    >>> float(weighted_mean(jnp.array([1.0, 0.0]), w, 1, 3))        # terms paired with w[1], w[2]
    0.5
    >>> float(weighted_mean(jnp.array([1.0, 1.0]), jnp.zeros(2), 0, 2))
    0.0
    """
    num = 0.0
    den = 0.0
    for k in range(lo, hi):
        num = num + w[k] * terms[..., k - lo]
        den = den + w[k]
    safe = jnp.where(den > 0.0, den, 1.0)
    return jnp.where(den > 0.0, num / safe, 0.0)


def footprint_score(features, w):
    """(...,) footprint score: weighted mean of the five footprint goodnesses.

    Parameters
    ----------
    features : array_like, shape (..., 5)
        Raw footprint features (:func:`footprint_goodness`).
    w : jax.Array, shape (19,)
        ``ScoringWeights.to_array()``: the five footprint weights and the reference scales.

    Returns
    -------
    jax.Array, shape (...,)
        The footprint score, in [0, 1].

    Examples
    --------
    Goodnesses 1/2, 1/2, 1/2, 1/2 and 1 (:func:`footprint_goodness`) under the default weights
    3, 1, 1, 1, 1 give (3 x 0.5 + 0.5 + 0.5 + 0.5 + 1) / 7 = 4/7:

    >>> import jax.numpy as jnp
    >>> from footfall.planner import ScoringWeights
    >>> from footfall.tuning import enable_x64, footprint_score
    >>> enable_x64()
    >>> w = jnp.asarray(ScoringWeights().to_array())
    >>> round(float(footprint_score(jnp.array([0.15, 0.06, 0.5, 0.025, jnp.inf]), w)), 4)
    0.5714
    >>> float(footprint_score(jnp.array([0.0, 0.0, 0.0, jnp.inf, jnp.inf]), w))   # a perfect foothold
    1.0
    """
    return weighted_mean(footprint_goodness(features, w), w, 0, N_FOOTPRINT_TERMS)


def trajectory_score(raw, d_ref, w):
    """(...,) trajectory score: weighted mean of the five trajectory goodnesses.

    Parameters
    ----------
    raw : array_like, shape (..., 5)
        Raw trajectory metrics (:func:`trajectory_goodness`).
    d_ref : array_like
        Straight ground distance (m) from the source to the footprint; broadcasts against
        ``raw[..., 0]``.
    w : jax.Array, shape (19,)
        ``ScoringWeights.to_array()``: the five trajectory weights and the reference scales.

    Returns
    -------
    jax.Array, shape (...,)
        The trajectory score, in [0, 1].

    Examples
    --------
    Goodnesses 0.75, 1/2, 1/2, 1/2, 1/2 (:func:`trajectory_goodness`) under the default weights
    2, 1, 0.5, 1, 0.5 give (1.5 + 0.5 + 0.25 + 0.5 + 0.25) / 5 = 0.6:

    >>> import jax.numpy as jnp
    >>> from footfall.planner import ScoringWeights
    >>> from footfall.tuning import enable_x64, trajectory_score
    >>> enable_x64()
    >>> w = jnp.asarray(ScoringWeights().to_array())
    >>> round(float(trajectory_score(jnp.array([0.4, 1.0, 0.035, 0.1, 2000.0]), 0.3, w)), 4)
    0.6
    """
    return weighted_mean(trajectory_goodness(raw, d_ref, w), w, N_FOOTPRINT_TERMS, N_TERMS)


def couple_terms(features, raw, d_ref, w):
    """(..., 10) all goodnesses (SCORE_TERMS order); ``features`` broadcasts against ``raw``.

    Parameters
    ----------
    features : array_like, shape (..., 5)
        Raw footprint features (:func:`footprint_goodness`), e.g. (K, 1, 5) for K candidates.
    raw : array_like, shape (..., 5)
        Raw trajectory metrics (:func:`trajectory_goodness`), e.g. (K, S, 5) for S slices.
    d_ref : array_like
        Straight ground distance (m) from the source to each footprint, e.g. (K, 1).
    w : jax.Array, shape (19,)
        ``ScoringWeights.to_array()``.

    Returns
    -------
    jax.Array, shape (..., 10)
        The five footprint goodnesses, then the five trajectory goodnesses
        (``planner.SCORE_TERMS``).

    Examples
    --------
    Two candidates with three paths (slices) each:

    >>> import jax.numpy as jnp
    >>> from footfall.planner import ScoringWeights
    >>> from footfall.tuning import couple_terms, enable_x64
    >>> enable_x64()
    >>> w = jnp.asarray(ScoringWeights().to_array())
    >>> features = jnp.zeros((2, 1, 5))
    >>> raw = jnp.broadcast_to(jnp.array([0.4, 1.0, 0.035, 0.1, 2000.0]), (2, 3, 5))
    >>> terms = couple_terms(features, raw, jnp.full((2, 1), 0.3), w)
    >>> terms.shape
    (2, 3, 10)
    >>> [round(float(g), 4) for g in terms[0, 0]]   # zero gap and obstacle distance: goodness 0
    [1.0, 1.0, 1.0, 0.0, 0.0, 0.75, 0.5, 0.5, 0.5, 0.5]
    """
    fp = footprint_goodness(features, w)
    tr = trajectory_goodness(raw, d_ref, w)
    fp = jnp.broadcast_to(fp, tr.shape[:-1] + fp.shape[-1:])
    return jnp.concatenate([fp, tr], axis=-1)


def couple_score(features, raw, d_ref, w):
    """(...,) couple score: weighted mean over all ten goodnesses.

    The score the runtime's search maximises over the couples (candidate footprint, slice);
    differentiable with respect to the weights ``w`` and the raw numbers.

    Parameters
    ----------
    features : array_like, shape (..., 5)
        Raw footprint features (:func:`footprint_goodness`); broadcasts against ``raw``.
    raw : array_like, shape (..., 5)
        Raw trajectory metrics (:func:`trajectory_goodness`).
    d_ref : array_like
        Straight ground distance (m) from the source to each footprint.
    w : jax.Array, shape (19,)
        ``ScoringWeights.to_array()``.

    Returns
    -------
    jax.Array, shape (...,)
        The couple score, in [0, 1].

    Examples
    --------
    The footprint of :func:`footprint_score` (weighted sum 4 over weights 7) and the path of
    :func:`trajectory_score` (3 over 5) give (4 + 3) / 12:

    >>> import jax
    >>> import jax.numpy as jnp
    >>> from footfall.planner import ScoringWeights
    >>> from footfall.tuning import couple_score, enable_x64
    >>> enable_x64()
    >>> w = jnp.asarray(ScoringWeights().to_array())
    >>> features = jnp.array([0.15, 0.06, 0.5, 0.025, jnp.inf])
    >>> raw = jnp.array([0.4, 1.0, 0.035, 0.1, 2000.0])
    >>> round(float(couple_score(features, raw, 0.3, w)), 4)
    0.5833

    Its gradient with respect to the weights is finite, even with an infinite feature; raising
    the weight of closeness (goodness 1/2, below the score) lowers the score:

    >>> grad = jax.jit(jax.grad(couple_score, argnums=3))(features, raw, 0.3, w)
    >>> grad.shape, bool(jnp.isfinite(grad).all()), bool(grad[0] < 0)
    ((19,), True, True)
    """
    return weighted_mean(couple_terms(features, raw, d_ref, w), w, 0, N_TERMS)
