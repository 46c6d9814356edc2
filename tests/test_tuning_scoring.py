"""Hard mode: tuning's JAX scoring equals the numba runtime's, over >= 1000 harvested candidate sets.

The candidate sets come from seeded crowd runs of every built-in creature on two
built-in scenarios (planner.harvest_situations). For each, the runtime's own
goodnesses and scores (the harvest kernel calls the search's scoring functions)
and the couple the exhaustive search picks are compared with tuning's JAX
functions evaluated on the harvest's raw features and metrics.
"""

import numpy as np
import pytest

from footfall.planner import FEATURES, RAW_METRICS
from footfall.tuning import harvest_situations
from footfall.planner._weights import FOOTPRINT_TERMS, N_FOOTPRINT_TERMS, SCORE_TERMS, TRAJECTORY_TERMS

MIN_CANDIDATE_SETS = 1000
# The JAX and numba formulas are the same float64 operations on the same inputs; only the
# order of a few operations may differ (XLA may turn a division by a broadcast weight into
# a multiplication by its reciprocal, or fuse a multiply-add), which moves a goodness or a
# weighted mean of numbers in [0, 1] by a few ulps (1 ulp of 1.0 = 2.2e-16). 1e-12 leaves
# room for that and for nothing else: a wrong term, weight or order of terms moves a score
# by more than 1e-4 on these situations.
HARD_MODE_ATOL = 1e-12
CREATURES = ("spider", "ant", "quadruped", "robot5")


@pytest.fixture(scope="module")
def harvest():
    # 8 characters per run so that some start next to crates (slices, forbidden-cell distances).
    return harvest_situations(scenarios=("crates", "mixed"), creatures=CREATURES, seeds=(0,), frames=40,
                              n_characters=8)


@pytest.fixture(scope="module")
def jax_scores(harvest):
    import jax.numpy as jnp

    from footfall import tuning

    tuning.enable_x64()
    w = jnp.asarray(harvest.weights)
    features = harvest.cand_features[:, :, None, :]
    d_ref = harvest.d_ref[:, :, None]
    return {
        "footprint_terms": np.asarray(tuning.footprint_goodness(harvest.cand_features, w)),
        "footprint_score": np.asarray(tuning.footprint_score(harvest.cand_features, w)),
        "couple_terms": np.asarray(tuning.couple_terms(features, harvest.couple_raw, d_ref, w)),
        "trajectory_score": np.asarray(tuning.trajectory_score(harvest.couple_raw, d_ref, w)),
        "couple_score": np.asarray(tuning.couple_score(features, harvest.couple_raw, d_ref, w)),
    }


def test_the_harvest_has_enough_candidate_sets_of_every_creature(harvest):
    assert harvest.has_couple.sum() >= MIN_CANDIDATE_SETS
    counts = np.bincount(harvest.creature[harvest.has_couple], minlength=len(CREATURES))
    assert (counts > 0).all(), dict(zip(CREATURES, counts))
    # Some situations have slices (a couple going around a crate and one going over it).
    assert (harvest.couple_mask.any(axis=1).sum(axis=1) > 1).any()
    assert harvest.cand_features.shape[-1] == len(FEATURES)
    assert harvest.couple_raw.shape[-1] == len(RAW_METRICS)


def test_footprint_goodnesses_and_scores_equal_the_runtime(harvest, jax_scores):
    mask = harvest.cand_mask
    assert mask.sum() > 10 * MIN_CANDIDATE_SETS
    for t, name in enumerate(FOOTPRINT_TERMS):
        err = np.abs(jax_scores["footprint_terms"][..., t][mask] - harvest.cand_terms[..., t][mask]).max()
        assert err <= HARD_MODE_ATOL, (name, err)
    err = np.abs(jax_scores["footprint_score"][mask] - harvest.cand_scores[mask]).max()
    assert err <= HARD_MODE_ATOL, err


def test_trajectory_goodnesses_and_couple_scores_equal_the_runtime(harvest, jax_scores):
    mask = harvest.couple_mask
    for t, name in enumerate(SCORE_TERMS):
        err = np.abs(jax_scores["couple_terms"][..., t][mask] - harvest.couple_terms[..., t][mask]).max()
        assert err <= HARD_MODE_ATOL, (name, err)
    for key, column in (("couple_score", 0), ("trajectory_score", 2)):
        err = np.abs(jax_scores[key][mask] - harvest.couple_scores[..., column][mask]).max()
        assert err <= HARD_MODE_ATOL, (key, err)
    # The trajectory goodnesses are not all saturated: the comparison sees every formula work.
    for t, name in enumerate(TRAJECTORY_TERMS):
        values = harvest.couple_terms[..., N_FOOTPRINT_TERMS + t][mask]
        assert values.min() < 1.0, name


def test_the_exhaustive_search_pick_is_the_jax_argmax_with_the_same_numbers(harvest, jax_scores):
    ok = harvest.has_couple
    assert (harvest.chosen[ok, 0] >= 0).all()  # a couple exists: the search finds one
    assert (harvest.chosen[~ok, 0] < 0).all()  # (a boxed-in foot's way out is no harvested couple: no pick)
    f = np.flatnonzero(ok)
    k, s = harvest.chosen[f, 0], harvest.chosen[f, 1]
    n_slices = harvest.couple_mask.shape[2]
    # The search's own numbers (plan_foot_kernel, exhaustive budget) against JAX at its pick.
    for column, key in ((0, "couple_score"), (2, "trajectory_score")):
        err = np.abs(jax_scores[key][f, k, s] - harvest.chosen_scores[f, column]).max()
        assert err <= HARD_MODE_ATOL, (key, err)
    err = np.abs(jax_scores["footprint_score"][f, k] - harvest.chosen_scores[f, 1]).max()
    assert err <= HARD_MODE_ATOL, ("footprint_score", err)
    for t, name in enumerate(SCORE_TERMS):
        err = np.abs(jax_scores["couple_terms"][f, k, s, t] - harvest.chosen_terms[f, t]).max()
        assert err <= HARD_MODE_ATOL, (name, err)
    # The harvest's raw metrics of that couple are the search's, bit for bit (same kernels).
    np.testing.assert_array_equal(harvest.couple_raw[f, k, s], harvest.chosen_raw[f])
    # First maximum in the search's order (candidates by footprint score, then slices).
    scores = np.where(harvest.couple_mask, jax_scores["couple_score"], -np.inf).reshape(len(harvest.kind), -1)[f]
    best = np.argmax(scores, axis=1)
    picked = k * n_slices + s
    differ = best != picked
    # A different argmax is only acceptable for a tie within the tolerance.
    gap = np.abs(scores[np.arange(f.size), best] - scores[np.arange(f.size), picked])
    assert (gap[differ] <= HARD_MODE_ATOL).all(), gap[differ]
    assert differ.sum() <= 0.01 * f.size, differ.sum()


def test_the_crowd_choice_is_never_better_than_the_exhaustive_one(harvest):
    # The crowd's budgeted search (paper early stop) may stop early; it never beats the optimum.
    ok = harvest.crowd_choice[:, 0] >= 0
    f = np.flatnonzero(ok)
    crowd = harvest.couple_scores[f, harvest.crowd_choice[f, 0], harvest.crowd_choice[f, 1], 0]
    assert (crowd <= harvest.chosen_scores[f, 0]).all()
    assert ok.sum() >= MIN_CANDIDATE_SETS


def test_the_harvest_is_deterministic_for_a_seed():
    kwargs = dict(scenarios=("crates",), creatures=("spider",), seeds=(3,), frames=12, n_characters=2)
    a = harvest_situations(**kwargs)
    b = harvest_situations(**kwargs)
    assert a.n_situations > 0
    for name in ("kind", "speed", "source", "preferred", "cand_features", "couple_raw", "couple_scores", "chosen"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_bad_harvest_arguments_name_the_argument():
    with pytest.raises(ValueError, match="frames"):
        harvest_situations(frames=0)
    with pytest.raises(ValueError, match="scenarios"):
        harvest_situations(scenarios="crates")


def test_harvest_foot_holds_the_brute_force_optimum_of_plan_foot():
    from footfall.planner import EXHAUSTIVE, PlannerConfig, WorldRaster, harvest_foot, plan_foot
    from footfall.planner._situations import stand, step_queries
    from footfall.scenarios import load_creature, load_scenario

    scenario = load_scenario("crates")
    spider = load_creature("spider")
    config = PlannerConfig()
    raster = WorldRaster.build(scenario.terrain, scenario.obstacles, config.cell_size)
    standing = stand(spider, raster, x=-2.5, z=0.1, heading=0.0)  # next to the first crate
    several_slices = 0
    for query in step_queries(spider, standing, step_length=0.12, step_height=0.04):
        foot = harvest_foot(standing.maps, query, budget=EXHAUSTIVE, config=config)
        several_slices += int(foot.couple_valid.any(axis=0).sum() > 1)
        best = plan_foot(standing.maps, query, budget=EXHAUSTIVE, config=config, mode="brute_force")
        assert best.valid == bool(foot.couple_valid.any())
        if not best.valid:
            continue
        scores = np.where(foot.couple_valid, foot.couple_scores[..., 0], -np.inf)
        k, s = np.unravel_index(np.argmax(scores), scores.shape)
        assert tuple(foot.cand_cells[k]) == best.target_cell and s == best.slice_index
        assert scores[k, s] == best.couple_score
        np.testing.assert_array_equal(foot.couple_raw[k, s], list(best.metrics.values()))
        np.testing.assert_array_equal(foot.cand_scores, best.candidate_scores)
    assert several_slices > 0  # the crate gives some feet a way over and a way around
