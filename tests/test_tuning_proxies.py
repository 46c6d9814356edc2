"""Differentiable proxies: gradients match finite differences, tau -> 0 gives the hard choice."""

import numpy as np
import pytest

from footfall.planner import GaitTiming, ScoringWeights
from footfall.tuning import harvest_situations
from footfall.planner import _timing as runtime_timing
from footfall.planner._timing import TIMING_FIELDS
from footfall.planner._weights import WEIGHT_FIELDS

# At the harvest's timing the proxy recomputes the distance feature and d_ref with sqrt
# instead of hypot: a few ulps on goodnesses in [0, 1] (see tests/test_tuning_scoring.py).
AT_HARVEST_ATOL = 1e-12
# Derivatives are compared in log-parameter space and relative to each metric's value
# (d f / d log theta / |f|): dimensionless, O(1). Central differences with a log step of
# 1e-5 have a truncation error of order 1e-10 times the third log-derivative and a
# rounding error of order 1e-16 / 1e-5 = 1e-11: 1e-6 is far above both and far below
# any real disagreement (a missing or wrong term is O(1e-3) or more).
FD_LOG_STEP = 1e-5
FD_ATOL = 1e-6
TAU = 0.05  # soft enough that many couples share the probability (a demanding gradient test)
# Soft selection at tau = TIE_TAU_FRACTION x the smallest gap between a situation's best
# score and its next distinct one: every other couple weighs < exp(-50) (1e-22).
TIE_TAU_FRACTION = 0.02
LIMIT_RTOL = 1e-12


@pytest.fixture(scope="module")
def situations():
    from footfall import tuning

    tuning.enable_x64()
    harvest = harvest_situations(scenarios=("crates",), creatures=("spider", "ant", "quadruped", "robot5"),
                                 seeds=(1,), frames=30, n_characters=3)
    return harvest, tuning.situations_from_harvest(harvest)


@pytest.fixture(scope="module")
def point():
    """Weights off the defaults (no reference scale on a cell-size multiple, where a goodness
    has a kink), and the default timing."""
    rng = np.random.default_rng(12)
    w = ScoringWeights().to_array() * rng.uniform(0.8, 1.25, len(WEIGHT_FIELDS))
    return w, GaitTiming().to_array()


def test_the_timing_model_is_the_runtime_one():
    import jax.numpy as jnp

    from footfall import tuning

    tuning.enable_x64()
    timing = GaitTiming(stride_exponent=0.27, duty_slope=0.3)
    v = np.r_[np.linspace(0.0, 2.0, 41), 1e-200]  # and a speed whose stride underflows to 0
    h = np.full_like(v, 0.12)
    t = jnp.asarray(timing.to_array())
    for ours, theirs in ((tuning.stride_length, runtime_timing.stride_length),
                         (tuning.stride_frequency, runtime_timing.stride_frequency),
                         (tuning.duty_factor, runtime_timing.duty_factor)):
        np.testing.assert_allclose(np.asarray(ours(t, jnp.asarray(v), jnp.asarray(h))), theirs(timing, v, h),
                                   rtol=1e-14, atol=0.0)


def test_at_the_harvest_timing_the_proxy_sees_the_runtime_scores(situations, point):
    import jax.numpy as jnp

    from footfall import tuning

    harvest, sit = situations
    keep = harvest.has_couple
    np.testing.assert_array_equal(np.asarray(tuning.preferred_footprint(sit.timing0, sit)), harvest.preferred[keep])
    scores = np.asarray(tuning.couple_scores(jnp.asarray(harvest.weights), sit.timing0, sit))
    mask = harvest.couple_mask[keep]
    err = np.abs(scores[mask] - harvest.couple_scores[keep][..., 0][mask]).max()
    assert err <= AT_HARVEST_ATOL, err
    assert np.all(np.isneginf(scores[~mask]))


def _mean_metrics(sit, tau):
    import jax
    import jax.numpy as jnp

    from footfall import tuning

    n_w = len(WEIGHT_FIELDS)

    @jax.jit
    def f(log_params):
        params = jnp.exp(log_params)
        # Clearance is +inf for a path with nothing blocked around it; cap it (as the fit does) so that
        # its expectation and derivatives are finite numbers to compare.
        metrics = tuning.expected_metrics(params[:n_w], params[n_w:], sit, tau, clearance_cap_m=1.0)
        return jnp.stack([jnp.mean(metrics[k]) for k in tuning.PROXY_METRICS])

    return f


def test_proxy_gradients_match_central_differences(situations, point):
    import jax
    import jax.numpy as jnp

    from footfall import tuning

    _, sit = situations
    w, timing = point
    f = _mean_metrics(sit, TAU)
    x = jnp.log(jnp.asarray(np.concatenate([w, timing])))
    value = np.asarray(f(x))
    jac = np.asarray(jax.jacfwd(f)(x))  # (metrics, parameters): d metric / d log parameter
    assert np.isfinite(value).all() and np.isfinite(jac).all()
    names = WEIGHT_FIELDS + TIMING_FIELDS
    fd = np.empty_like(jac)
    for j in range(x.size):
        e = jnp.zeros_like(x).at[j].set(FD_LOG_STEP)
        fd[:, j] = (np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2.0 * FD_LOG_STEP)
    # A metric that is 0 in every situation (flat ground: no touch-down slope) is compared absolutely.
    scale = np.where(value == 0.0, 1.0, np.abs(value))[:, None]
    err = np.abs(jac - fd) / scale
    worst = np.unravel_index(np.argmax(err), err.shape)
    assert err.max() <= FD_ATOL, (tuning.PROXY_METRICS[worst[0]], names[worst[1]], err.max())
    # The gradients are not trivially zero: weights and timing both move the choice.
    step = tuning.PROXY_METRICS.index("step_length_m")
    assert np.abs(jac[step, :len(WEIGHT_FIELDS)]).max() / scale[step, 0] > 1e-3
    assert np.abs(jac[step, len(WEIGHT_FIELDS):]).max() / scale[step, 0] > 1e-3
    # A longer stride law puts the preferred footprint farther ahead: longer expected steps.
    assert jac[step, len(WEIGHT_FIELDS) + TIMING_FIELDS.index("stride_coefficient")] > 0.0


def test_soft_selection_tends_to_the_hard_choice_as_tau_goes_to_zero(situations, point):
    import jax.numpy as jnp

    from footfall import tuning

    _, sit = situations
    w = jnp.asarray(point[0])
    timing = jnp.asarray(point[1])
    scores = np.asarray(tuning.couple_scores(w, timing, sit)).reshape(sit.n_situations, -1)
    top = scores.max(axis=1, keepdims=True)
    tied = scores == top
    # The hard choice, with exact ties shared equally (the softmax's limit; an exact tie is
    # one candidate reached in two slices by the same path: the same metrics).
    selection = (tied / tied.sum(axis=1, keepdims=True)).reshape(np.asarray(sit.couple_mask).shape)
    hard_tied = tuning._proxies._metrics_under(jnp.asarray(selection), jnp.asarray(scores.reshape(selection.shape)),
                                               timing, sit, jnp.inf)
    hard = tuning.hard_metrics(w, timing, sit)
    # Ties whose couples differ in a metric the score saturates on (two slices, both clearances
    # beyond clearance_ref_m) are shared by the softmax but not by the first-maximum pick: compare
    # the situations whose tied couples agree on every raw metric.
    raw = np.asarray(sit.couple_raw).reshape(sit.n_situations, -1, np.asarray(sit.couple_raw).shape[-1])
    same = np.array([np.unique(raw[i][tied[i]], axis=0).shape[0] == 1 for i in range(sit.n_situations)])
    assert same.mean() > 0.9
    for key in tuning.PROXY_METRICS:
        np.testing.assert_allclose(np.asarray(hard[key])[same], np.asarray(hard_tied[key])[same], rtol=LIMIT_RTOL,
                                   atol=0, err_msg=key)
    rest = np.where(tied, -np.inf, scores).max(axis=1)
    gaps = (top[:, 0] - rest)[np.isfinite(rest)]
    taus = (1e-1, 1e-2, 1e-3, 1e-4, TIE_TAU_FRACTION * gaps.min())
    softs = [tuning.expected_metrics(w, timing, sit, tau) for tau in taus]
    # Errors relative to each metric's largest magnitude, hard or softest (the hard climb
    # can be 0 in every situation: no chosen swing rises over its step height).
    scale = {k: max(float(np.abs(np.asarray(hard[k])).max()), float(np.abs(np.asarray(softs[0][k])).max()), 1e-300)
             for k in tuning.PROXY_METRICS}
    errors = []
    for soft in softs:
        errors.append(max(float(np.abs(np.asarray(soft[k]) - np.asarray(hard[k])).max()) / scale[k]
                          for k in tuning.PROXY_METRICS))
    assert errors[0] > 1e-3  # at tau = 0.1 the selection is really soft
    assert errors[-1] <= LIMIT_RTOL, errors
    # On the way, a situation's error is its softmax's weight off the top couples times how far
    # their metrics lie from the top's, at most: a bound that falls with tau (the largest error over
    # the situations need not: a far-off couple fading later than a near one raised it 1.0 -> 1.7
    # from tau 0.1 to 0.01 on one harvest).
    mask = np.asarray(sit.couple_mask)
    values = tuning._proxies._couple_metrics(jnp.asarray(scores.reshape(mask.shape)), timing, sit, jnp.inf)
    off_top = ~tied.reshape(mask.shape) & mask
    previous = np.inf
    for tau, soft in zip(taus, softs):
        p = np.asarray(tuning.soft_selection(jnp.asarray(scores.reshape(mask.shape)), sit.couple_mask, tau))
        weight_off = (p * off_top).sum(axis=(1, 2))
        assert (weight_off <= previous + 1e-15).all()
        previous = weight_off
        for k in tuning.PROXY_METRICS:
            v, h = np.asarray(values[k]), np.asarray(hard[k])
            spread = np.where(off_top, np.abs(v - h[:, None, None]), 0.0).max(axis=(1, 2))
            err = np.abs(np.asarray(soft[k]) - h)
            # uncapped clearances are infinite where nothing is near: no distance to bound there
            finite = same & np.isfinite(err) & np.isfinite(spread)
            size = max(float(np.abs(h[finite]).max(initial=0.0)), 1e-300)
            assert (err[finite] <= weight_off[finite] * spread[finite] + LIMIT_RTOL * size).all(), (k, tau)


def test_probabilities_are_a_distribution_over_the_valid_couples(situations, point):
    import jax.numpy as jnp

    from footfall import tuning

    _, sit = situations
    scores = tuning.couple_scores(jnp.asarray(point[0]), jnp.asarray(point[1]), sit)
    p = np.asarray(tuning.soft_selection(scores, sit.couple_mask, 0.03))
    mask = np.asarray(sit.couple_mask)
    assert (p[~mask] == 0.0).all() and (p >= 0.0).all()
    np.testing.assert_allclose(p.sum(axis=(1, 2)), 1.0, rtol=0, atol=1e-14)
