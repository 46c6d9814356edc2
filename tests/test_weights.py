import dataclasses

import numpy as np
import pytest

from footfall.planner import WEIGHT_FIELDS, PlannerConfig, ScoringWeights, SearchBudget


def test_array_round_trip_is_lossless():
    rng = np.random.default_rng(0)
    for _ in range(100):
        values = rng.uniform(0.001, 10.0, size=len(WEIGHT_FIELDS))
        w = ScoringWeights.from_array(values)
        np.testing.assert_array_equal(w.to_array(), values)
        assert ScoringWeights.from_array(w.to_array()) == w


def test_field_order_is_the_array_order_and_documented():
    w = ScoringWeights()
    assert tuple(f.name for f in dataclasses.fields(w)) == WEIGHT_FIELDS
    for name, unit, doc in ScoringWeights.describe():
        assert unit and doc, name
    assert w.to_array()[WEIGHT_FIELDS.index("slope_critical_rad")] == w.slope_critical_rad


def test_default_weights_size_the_metre_scales_to_a_smaller_creature():
    """A creature of half the spider's rest radius: every metre-valued scale halves, by hand; the
    weights and the scale-free references stay. The spider's size, or a larger one (whose planner keeps
    the spider's 7 cm cells), gives ScoringWeights() exactly."""
    from footfall.planner import METRE_SCALE_FIELDS, REFERENCE_REST_RADIUS_M, default_weights
    from footfall.scenarios import load_creature

    assert METRE_SCALE_FIELDS == ("distance_scale_m", "step_critical_m", "leg_spacing_ref_m", "proximity_ref_m",
                                  "clearance_ref_m", "climb_ref_m")
    half = default_weights(0.5 * REFERENCE_REST_RADIUS_M)
    np.testing.assert_array_equal(half.to_array(), [3.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 0.5, 1.0, 0.5,
                                                    0.15, 0.06, 1.0, 0.025, 0.05, 1.0, 0.035, 0.05, 2000.0])
    assert default_weights(load_creature("spider").rest_radius) == ScoringWeights()
    assert default_weights(2 * REFERENCE_REST_RADIUS_M) == ScoringWeights()
    assert default_weights(load_creature("robot5").rest_radius) == ScoringWeights()  # 1.2 x the spider's
    for bad in (0.0, -0.1, float("nan"), float("inf"), "0.3", True):
        with pytest.raises(ValueError, match="rest_radius_m"):
            default_weights(bad)


def test_the_leg_spacing_reference_is_at_most_the_room_the_stride_law_leaves():
    """default_weights(r, leg_room_m): the leg-spacing reference is min(its size-scaled value,
    leg_room_m), every other field as without it; a bad room is refused naming the argument."""
    from footfall.planner import REFERENCE_REST_RADIUS_M, default_weights

    half = default_weights(0.5 * REFERENCE_REST_RADIUS_M)  # reference 0.025 m
    tight = default_weights(0.5 * REFERENCE_REST_RADIUS_M, 0.01)
    assert tight.leg_spacing_ref_m == 0.01
    assert dataclasses.replace(tight, leg_spacing_ref_m=0.025) == half
    assert default_weights(0.5 * REFERENCE_REST_RADIUS_M, 0.03) == half  # more room than asked: unchanged
    assert default_weights(REFERENCE_REST_RADIUS_M, 0.02).leg_spacing_ref_m == 0.02
    for bad in (0.0, -0.01, float("nan"), "0.02", True):
        with pytest.raises(ValueError, match="leg_room_m"):
            default_weights(REFERENCE_REST_RADIUS_M, bad)


def test_weights_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        ScoringWeights().footprint_distance = 2.0


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"footprint_slope": -1.0}, "footprint_slope"),
        ({"jerk_ref": 0.0}, "jerk_ref"),
        ({"climb_ref_m": float("nan")}, "climb_ref_m"),
        ({"trajectory_length": "big"}, "trajectory_length"),
        (
            {
                "footprint_distance": 0.0,
                "footprint_elevation": 0.0,
                "footprint_slope": 0.0,
                "footprint_leg_spacing": 0.0,
                "footprint_obstacle_proximity": 0.0,
            },
            "footprint weight",
        ),
    ],
)
def test_invalid_weights_are_refused_naming_the_field(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ScoringWeights(**kwargs)


def test_from_array_checks_the_shape():
    with pytest.raises(ValueError, match="shape"):
        ScoringWeights.from_array(np.ones(3))


def test_budget_and_config_validation():
    with pytest.raises(ValueError, match="couples_after_first"):
        SearchBudget(couples_after_first=-1)
    with pytest.raises(ValueError, match="slice_size_m"):
        SearchBudget(slice_size_m=0.0)
    with pytest.raises(ValueError, match="map_cells"):
        PlannerConfig(map_cells=1)
    assert SearchBudget(None, None, False).kernel_args() == (-1, -1.0, False)


@pytest.mark.parametrize("creature", ["ant", "quadruped", "robot5", "spider"])
def test_one_definition_of_a_creatures_default_weights(creature):
    """The runtime's default (init_crowd without weights), the tunes' starts and the tuning's
    creature_defaults are one set of numbers for each creature."""
    from footfall.planner import default_weights, init_crowd
    from footfall.scenarios import load_creature, load_scenario
    from footfall.scenarios._gait_choice import resolve_gait
    from footfall.tuning import creature_defaults
    from footfall.tuning._targets import load_tune_targets
    from footfall.tuning._tune import TuneConfig, _default_params, _start_params
    from footfall.tuning._tune_events import EventTuneConfig, _start

    c = load_creature(creature)
    gait, _, _ = resolve_gait(None, c)
    model, _ = init_crowd(load_scenario("flat"), c, gait, n_characters=1, seed=0)
    expected = default_weights(c.rest_radius)
    assert model.weights == expected == creature_defaults(creature)
    for params in (_start_params(TuneConfig(creature)), _default_params(TuneConfig(creature)),
                   _start(EventTuneConfig(creature), load_tune_targets(None, creature))):
        np.testing.assert_array_equal(params["weights"], expected.to_array())
    assert (expected == ScoringWeights()) == (creature in ("spider", "robot5"))  # not smaller than the spider
