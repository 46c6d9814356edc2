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
    """(..., 5) footprint goodnesses in [0, 1] (FOOTPRINT_TERMS order) of raw features (..., 5)."""
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
    ``d_ref`` broadcasts against the leading axes."""
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
    from ``lo``), summed in index order as the runtime does; 0 if the weights sum to 0."""
    num = 0.0
    den = 0.0
    for k in range(lo, hi):
        num = num + w[k] * terms[..., k - lo]
        den = den + w[k]
    safe = jnp.where(den > 0.0, den, 1.0)
    return jnp.where(den > 0.0, num / safe, 0.0)


def footprint_score(features, w):
    """(...,) footprint score: weighted mean of the five footprint goodnesses."""
    return weighted_mean(footprint_goodness(features, w), w, 0, N_FOOTPRINT_TERMS)


def trajectory_score(raw, d_ref, w):
    """(...,) trajectory score: weighted mean of the five trajectory goodnesses."""
    return weighted_mean(trajectory_goodness(raw, d_ref, w), w, N_FOOTPRINT_TERMS, N_TERMS)


def couple_terms(features, raw, d_ref, w):
    """(..., 10) all goodnesses (SCORE_TERMS order); ``features`` broadcasts against ``raw``."""
    fp = footprint_goodness(features, w)
    tr = trajectory_goodness(raw, d_ref, w)
    fp = jnp.broadcast_to(fp, tr.shape[:-1] + fp.shape[-1:])
    return jnp.concatenate([fp, tr], axis=-1)


def couple_score(features, raw, d_ref, w):
    """(...,) couple score: weighted mean over all ten goodnesses."""
    return weighted_mean(couple_terms(features, raw, d_ref, w), w, 0, N_TERMS)
