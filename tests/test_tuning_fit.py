"""Fit (issue 4, item 4): Levenberg-Marquardt on the target residuals, positive parameters."""

import numpy as np
import pytest

from planner import GaitTiming, ScoringWeights, harvest_situations
from planner._timing import GRAVITY, TIMING_FIELDS

N_STEPS = 6
TAU = 0.05
# The stride residual recomputed here from the same float64 numbers (one division order apart).
RESIDUAL_ATOL = 1e-12


@pytest.fixture(scope="module")
def problem():
    import tuning
    from tuning import _fit

    tuning.enable_x64()
    # Harvested with strides 30 % too long (stride_coefficient 3.0 for the law's 2.3), so that the fit
    # has something to fix: at the default timing the commanded stride is the law (zero residual,
    # zero gradient) and Levenberg-Marquardt rightly stays where it starts.
    harvest = harvest_situations(scenarios=("crates",), creatures=("spider", "ant"), seeds=(2,), frames=24,
                                 n_characters=2, timing=GaitTiming(stride_coefficient=3.0))
    situations = tuning.situations_from_harvest(harvest)
    return _fit.make_problem(situations, harvest.creatures, tuning.load_targets(creatures=harvest.creatures), TAU)


def test_the_stride_residuals_are_the_targets_law(problem):
    import tuning
    from tuning import _fit

    s = problem.situations
    r = np.asarray(_fit.residuals(_fit.initial_params(problem), problem))
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

    from tuning import _fit

    s = problem.situations
    mask = np.asarray(problem.stride_mask)
    c = np.linspace(0.8, 1.25, s.n_situations)
    corrected = dataclasses.replace(problem, stride_correction=jnp.asarray(c))
    r0 = np.asarray(_fit.residuals(_fit.initial_params(problem), problem))[:s.n_situations]
    r1 = np.asarray(_fit.residuals(_fit.initial_params(corrected), corrected))[:s.n_situations]
    tolerance = 0.15 * np.sqrt(mask.sum())  # relative_tolerance times the block normalisation
    # (c x / t - 1) / tol = c (x / t - 1) / tol + (c - 1) / tol
    np.testing.assert_allclose(r1[mask], c[mask] * r0[mask] + (c[mask] - 1.0) / tolerance, rtol=0, atol=1e-11)
    with pytest.raises(ValueError, match="stride_correction"):
        _fit.make_problem(s, ("spider", "ant"), _targets(), TAU, stride_correction=np.zeros(s.n_situations))


def test_the_duty_correction_shifts_the_duty_model(problem):
    """d = realised - commanded duty factor: the fit's duty model is DF(theta) + d."""
    import dataclasses

    import jax.numpy as jnp

    import tuning
    from tuning import _fit

    s = problem.situations
    mask = np.asarray(problem.duty_mask)
    assert mask.any()
    d = np.full(s.n_situations, -0.3)  # far below every band
    shifted = dataclasses.replace(problem, duty_correction=jnp.asarray(d))
    r = np.asarray(_fit.residuals(_fit.initial_params(shifted), shifted))
    block = r[s.n_situations:2 * s.n_situations]
    duty = np.asarray(tuning.duty_factor(s.timing0, s.speed, s.leg_height)) + d
    low, high = np.asarray(problem.duty_low), np.asarray(problem.duty_high)
    expected = np.maximum(low - duty, 0.0) / (high - low) / np.sqrt(mask.sum())
    np.testing.assert_allclose(block[mask], expected[mask], rtol=0, atol=1e-12)
    assert (block[mask] > 0).all()
    with pytest.raises(ValueError, match="duty_correction"):
        _fit.make_problem(s, ("spider", "ant"), _targets(), TAU, duty_correction=np.full(s.n_situations, 2.0))


def _targets():
    import tuning

    return tuning.load_targets(creatures=("spider", "ant"))


def test_levenberg_marquardt_lowers_the_loss_and_keeps_parameters_valid(problem):
    from tuning import _fit

    loss0 = float(_fit.loss(_fit.initial_params(problem), problem))
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
    from tuning import _fit

    with pytest.raises(ValueError, match="n_steps"):
        _fit.fit(problem, n_steps=0)
    with pytest.raises(ValueError, match="tau"):
        _fit.make_problem(problem.situations, ("spider", "ant"), {}, 0.0)
