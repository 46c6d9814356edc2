"""Fit (issue 4, item 4): Levenberg-Marquardt on the target residuals, positive parameters."""

import numpy as np
import pytest

from footfall.planner import GaitTiming, ScoringWeights
from footfall.tuning import harvest_situations
from footfall.planner._timing import GRAVITY, TIMING_FIELDS

N_STEPS = 6
TAU = 0.05
# The stride residual recomputed here from the same float64 numbers (one division order apart).
RESIDUAL_ATOL = 1e-12


def _start_residuals(problem):
    """``_fit.residuals`` at the harvest's parameters, as one compiled program: evaluated eagerly, each of
    its primitives compiles a program of its own (seconds per test on a cold compilation cache)."""
    import equinox as eqx

    from footfall.tuning import _fit

    return np.asarray(eqx.filter_jit(_fit.residuals)(_fit.initial_params(problem), problem))


@pytest.fixture(scope="module")
def problem():
    from footfall import tuning
    from footfall.tuning import _fit

    tuning.enable_x64()
    # Harvested with strides 30 % too long (stride_coefficient 3.0 for the law's 2.3), so that the fit
    # has something to fix: at the default timing the commanded stride is the law (zero residual,
    # zero gradient) and Levenberg-Marquardt rightly stays where it starts.
    harvest = harvest_situations(scenarios=("crates",), creatures=("spider", "ant"), seeds=(2,), frames=24,
                                 n_characters=2, timing=GaitTiming(stride_coefficient=3.0))
    situations = tuning.situations_from_harvest(harvest)
    return _fit.make_problem(situations, harvest.creatures, tuning.load_targets(creatures=harvest.creatures), TAU)


def test_the_stride_residuals_are_the_targets_law(problem):
    from footfall import tuning
    from footfall.tuning import _fit

    s = problem.situations
    r = _start_residuals(problem)
    mask = np.asarray(problem.stride_mask)
    assert mask.sum() > 10
    targets = tuning.load_targets(creatures=("spider", "ant"))
    names = ("spider", "ant")
    v = np.asarray(s.speed)
    law = np.array([targets[names[c]].stride_length_m(x) for c, x in zip(np.asarray(s.creature), v)])
    h = np.asarray(s.leg_height)
    # lambda = 2.3 h Fr^0.3 (Alexander), by hand.
    np.testing.assert_allclose(law, 2.3 * h * (v * v / (GRAVITY * h)) ** 0.3, rtol=1e-14)
    tolerance = np.array([targets[names[c]]["stride_length"].values["relative_tolerance"]
                          for c in np.asarray(s.creature)])
    # The commanded stride v / f, f = max(v / lambda_timing(v), min_frequency) (planner._timing), by hand.
    t = GaitTiming.from_array(np.asarray(s.timing0))
    timing_law = t.stride_coefficient * h * (v * v / (GRAVITY * h)) ** t.stride_exponent
    commanded = v / np.maximum(v / np.where(v > 0, timing_law, 1.0), t.min_frequency_hz)
    # Only the masked rows: the others include standing feet (v = 0, law = 0).
    expected = (commanded[mask] / law[mask] - 1.0) / tolerance[mask] / np.sqrt(mask.sum())
    np.testing.assert_allclose(r[:s.n_situations][mask], expected, rtol=0, atol=RESIDUAL_ATOL)
    assert (r[:s.n_situations][~mask] == 0.0).all()


def test_the_stride_correction_scales_the_commanded_stride(problem):
    """c = realised / commanded (output space mapping): the fit asks c lambda_cmd for the target."""
    import dataclasses

    import jax.numpy as jnp

    from footfall.tuning import _fit

    s = problem.situations
    mask = np.asarray(problem.stride_mask)
    c = np.linspace(0.8, 1.25, s.n_situations)
    corrected = dataclasses.replace(problem, stride_correction=jnp.asarray(c))
    r0 = _start_residuals(problem)[:s.n_situations]
    r1 = _start_residuals(corrected)[:s.n_situations]
    tolerance = 0.15 * np.sqrt(mask.sum())  # relative_tolerance times the block normalisation
    # (c x / t - 1) / tol = c (x / t - 1) / tol + (c - 1) / tol
    np.testing.assert_allclose(r1[mask], c[mask] * r0[mask] + (c[mask] - 1.0) / tolerance, rtol=0, atol=1e-11)
    with pytest.raises(ValueError, match="stride_correction"):
        _fit.make_problem(s, ("spider", "ant"), _targets(), TAU, stride_correction=np.zeros(s.n_situations))


def test_the_duty_correction_shifts_the_duty_model(problem):
    """d = realised - commanded duty factor: the fit's duty model is DF(theta) + d."""
    import dataclasses

    import jax.numpy as jnp

    from footfall import tuning
    from footfall.tuning import _fit

    s = problem.situations
    mask = np.asarray(problem.duty_mask)
    assert mask.any()
    d = np.full(s.n_situations, -0.3)  # far below every band
    shifted = dataclasses.replace(problem, duty_correction=jnp.asarray(d))
    r = _start_residuals(shifted)
    block = r[s.n_situations:2 * s.n_situations]
    duty = np.asarray(tuning.duty_factor(s.timing0, s.speed, s.leg_height)) + d
    low, high = np.asarray(problem.duty_low), np.asarray(problem.duty_high)
    expected = np.maximum(low - duty, 0.0) / (high - low) / np.sqrt(mask.sum())
    np.testing.assert_allclose(block[mask], expected[mask], rtol=0, atol=1e-12)
    assert (block[mask] > 0).all()
    with pytest.raises(ValueError, match="duty_correction"):
        _fit.make_problem(s, ("spider", "ant"), _targets(), TAU, duty_correction=np.full(s.n_situations, 2.0))


def _targets():
    from footfall import tuning

    return tuning.load_targets(creatures=("spider", "ant"))


@pytest.mark.slow  # jit-compiled fits (about 7 s each)
def test_levenberg_marquardt_lowers_the_loss_and_keeps_parameters_valid(problem):
    from footfall.tuning import _fit

    loss0 = _fit.initial_loss(problem)
    weights, timing, history = _fit.fit(problem, n_steps=N_STEPS)
    assert history.shape == (N_STEPS,) and np.isfinite(history).all()
    assert history[-1] < loss0
    assert (np.diff(history) <= 1e-12 * loss0).all()  # LM only accepts steps that lower the loss
    assert (weights > 0).all() and np.isfinite(weights).all()
    ScoringWeights.from_array(weights)  # validated: positive weights and scales
    fitted = GaitTiming.from_array(timing)
    base = np.asarray(problem.situations.timing0)
    moved = [n for i, n in enumerate(TIMING_FIELDS) if timing[i] != base[i]]
    assert set(moved) <= set(_fit.FITTED_TIMING)
    assert fitted.stride_coefficient > 0 and fitted.duty_slope > 0


def test_fit_arguments_are_checked(problem):
    from footfall.tuning import _fit

    with pytest.raises(ValueError, match="n_steps"):
        _fit.fit(problem, n_steps=0)
    with pytest.raises(ValueError, match="tau"):
        _fit.make_problem(problem.situations, ("spider", "ant"), {}, 0.0)


# --------------------------------------------------------------------------- the weights' blocks (issue 18, item 2)
TERRAINS = ("stairs@terrain.start=-3.6", "crates", "hills", "mixed")
WEIGHTS_TAU = 0.01  # the terrain and style tunes' temperature (tuning._tune.TuneConfig.for_terrain)
# Central differences in log weights, step 1e-5: truncation ~1e-10, rounding ~1e-11 (see test_tuning_proxies).
FD_ATOL_REL = 1e-6


@pytest.fixture(scope="module")
def terrain_problems():
    """The spider's situations on stairs, crates, hills and mixed at the default parameters, as the
    legacy fit sees them and with the weights' blocks (and a style whose ceilings the defaults cross)."""
    import dataclasses

    from footfall import tuning
    from footfall.tuning import _fit

    tuning.enable_x64()
    harvest = harvest_situations(scenarios=TERRAINS, creatures=("spider",), seeds=(0,), frames=30, n_characters=2)
    situations = tuning.situations_from_harvest(harvest)
    targets = tuning.load_targets(creatures=("spider",))
    style = {"max_touchdown_slope_rad": 0.02, "curvature_p95_max": 1e-6, "min_distance_ratio": 1.2}
    styled = {"spider": dataclasses.replace(targets["spider"], style=style)}
    legacy = _fit.make_problem(situations, harvest.creatures, targets, WEIGHTS_TAU)
    weights = _fit.make_problem(situations, harvest.creatures, styled, WEIGHTS_TAU, weights_blocks=True,
                                fit_timing=False)
    return harvest, legacy, weights


def _weights_jacobian(problem):
    """d residuals (the targets' rows, without the prior) / d log weights at the harvest's parameters."""
    import jax

    from footfall.tuning import _fit

    y0 = _fit.initial_params(problem)
    n_prior = y0[0].size + y0[1].size

    @jax.jit  # one program: evaluated eagerly, each primitive would compile its own (seconds, cold cache)
    def f(log_weights):
        return _fit.residuals((log_weights, y0[1]), problem)[:-n_prior]

    return f, y0[0], np.asarray(jax.jit(jax.jacfwd(f))(y0[0]))


@pytest.mark.slow  # jit-compiled fits (about 7 s each)
def test_at_the_defaults_only_the_weights_blocks_give_the_weights_a_gradient(terrain_problems):
    from footfall.planner._weights import N_TERMS

    _, legacy, weights = terrain_problems
    _, _, j_legacy = _weights_jacobian(legacy)
    _, _, j_new = _weights_jacobian(weights)
    # The legacy blocks: stride and duty read the timing alone; only the clearance hinge reaches a few
    # crate-side situations (issue 18: exactly 0 on the spider's own hills runs).
    before = np.linalg.norm(j_legacy[:, :N_TERMS])
    assert before < 0.05
    # With the weights' blocks every one of the ten scoring weights moves the residuals.
    per_weight = np.linalg.norm(j_new[:, :N_TERMS], axis=0)
    assert (per_weight > 1e-3).all(), per_weight
    assert np.linalg.norm(j_new[:, :N_TERMS]) > 100.0 * before


def test_the_weights_blocks_gradients_match_central_differences(terrain_problems):
    import jax.numpy as jnp

    import jax

    _, _, weights = terrain_problems
    f, x, _ = _weights_jacobian(weights)
    # Off the defaults: clearance_ref_m = 0.07 m is the spider's cell, and many paths pass exactly one
    # cell from a blocked one, where min(1, clearance / clearance_ref_m) has its kink.
    x = x + jnp.log(jnp.asarray(np.random.default_rng(12).uniform(0.8, 1.25, x.size)))
    jac = np.asarray(jax.jit(jax.jacfwd(f))(x))
    fd = np.empty_like(jac)
    step = 1e-5
    for j in range(x.size):
        e = jnp.zeros_like(x).at[j].set(step)
        fd[:, j] = (np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2.0 * step)
    scale = max(float(np.abs(jac).max()), 1e-300)
    assert np.abs(jac - fd).max() <= FD_ATOL_REL * scale, np.abs(jac - fd).max() / scale


def test_the_offset_block_is_the_expected_distance_to_the_preferred_footprint(terrain_problems):
    import equinox as eqx

    from footfall import tuning
    from footfall.tuning import _fit
    from footfall.tuning._proxies import compiled_expected_metrics

    harvest, _, problem = terrain_problems
    s = problem.situations
    r = _start_residuals(problem)
    n = s.n_situations
    start = 2 * n + 1 + 3  # stride, duty, slope, then jerk, curvature, clearance (one per creature)
    block = r[start:start + n]
    mask = np.asarray(problem.stride_mask)
    m = compiled_expected_metrics(s.weights0, s.timing0, s, WEIGHTS_TAU, clearance_cap_m=problem.clearance_min_m)
    # Only where a stride is asked (masked in): the others' target is 0 and their residual 0.
    expected = (np.asarray(m["offset_m"])[mask] / (0.15 * np.asarray(problem.stride_target_m)[mask])
                / np.sqrt(mask.sum()))
    np.testing.assert_allclose(block[mask], expected, rtol=1e-12, atol=0)
    assert (block[~mask] == 0).all() and (block[mask] > 0).all()
    # The offsets the hard choice makes: the soft expectation at this temperature is of the same size.
    hard = np.asarray(eqx.filter_jit(tuning.hard_metrics)(s.weights0, s.timing0, s)["offset_m"])[mask].mean()
    soft = np.asarray(m["offset_m"])[mask].mean()
    assert hard <= soft <= 2.0 * hard + 0.01, (hard, soft)


def test_a_weights_only_fit_moves_the_weights_and_holds_the_timing(terrain_problems):
    from footfall.tuning import _fit

    _, _, problem = terrain_problems
    loss0 = _fit.initial_loss(problem)
    weights, timing, history = _fit.fit(problem, n_steps=4)
    assert history[-1] < loss0
    np.testing.assert_array_equal(timing, np.asarray(problem.situations.timing0))
    change = np.abs(np.log(weights) - np.asarray(problem.log_weights0))
    assert change.max() > 0.05
