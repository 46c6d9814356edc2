"""``footfall bench tuning`` (benchmarks.tuning_bench): the JSON interface, what is counted (the
tune's checkpoint for the proxy method, candidates for CMA-ES), the stop rule, determinism.
Tiny settings: properties only, no timing assertions."""

import io
import json
import math

import numpy as np
import pytest

from footfall.benchmarks import tuning_bench as tb
from footfall import InputError
from footfall.planner import ScoringWeights

pytestmark = pytest.mark.slow  # tuning benches (about 10 s)

TINY = dict(exact_frames=60, harvest_frames=15, max_situations=80, froude=(0.01, 0.02), exact_scenarios=("flat",),
            fit_steps=3, exact_characters=1)
MAX_EVALS = 6
PUBLIC = ("wall_s", "exact_evals", "exact_loss")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Two runs with the same seed; the first keeps its tune folder (checkpoint) for inspection."""
    folder = tmp_path_factory.mktemp("bench-tuning")
    first = tb.run("spider", seed=0, max_evals=MAX_EVALS, config_overrides=TINY, workdir=folder)
    second = tb.run("spider", seed=0, max_evals=MAX_EVALS, config_overrides=TINY)
    return first, second, folder


@pytest.fixture(scope="module")
def tiny_setup():
    from footfall.tuning._targets import load_targets

    config = tb.make_config("spider", config_overrides=TINY)
    return config.exact_setup(), load_targets(creatures=("spider",))


def test_json_shape(runs):
    result = runs[0]
    json.dumps(result, allow_nan=False)
    assert {"proxy", "cmaes", "speedup"} <= set(result)
    for method in ("proxy", "cmaes"):
        assert set(PUBLIC) <= set(result[method])
        assert isinstance(result[method]["exact_evals"], int) and result[method]["exact_evals"] >= 1
        assert result[method]["wall_s"] >= 0.0
        assert math.isfinite(result[method]["exact_loss"])
    assert result["speedup"] > 0.0
    assert result["speedup"] == pytest.approx(result["cmaes"]["wall_s"] / result["proxy"]["wall_s"])


def test_proxy_counts_match_the_checkpoint(runs):
    from footfall.tuning._tune import checkpoint_path

    result, _, folder = runs
    proxy = result["proxy"]
    state = json.loads(checkpoint_path(folder / "bench-spider.json").read_text())
    line_search = sum(len(r["line_search"]) for r in state["history"])
    assert proxy["exact_evals"] == 1 + line_search
    assert len(proxy["history"]) == proxy["exact_evals"]
    assert proxy["exact_loss"] == state["best"]["exact"]["exact_loss"] == result["target_loss"]
    assert proxy["exact_loss"] <= state["start_exact"]["exact_loss"] == proxy["history"][0]
    # Guards off (TuneConfig.guards): every evaluated candidate below the best so far is accepted.
    assert proxy["exact_loss"] == min(proxy["history"])
    # the outer loop alone: no held-out evaluation, no preset written, nothing after it counted or timed
    assert proxy["timed_until"] == "end of the outer loop"
    assert not (folder / "bench-spider.json").exists()


def test_cmaes_budget_losses_and_reached(runs):
    result = runs[0]
    cmaes, target = result["cmaes"], result["target_loss"]
    history = cmaes["history"]
    assert 1 <= cmaes["exact_evals"] == len(history) <= MAX_EVALS
    assert all(math.isfinite(v) for v in history)
    assert cmaes["exact_loss"] == min(history)
    assert cmaes["reached"] == (cmaes["exact_loss"] <= target) == result["reached"]
    assert result["speedup_is_lower_bound"] == (not cmaes["reached"])
    assert all(v > target for v in history[:-1])  # stops at the first candidate that reaches the target
    if cmaes["reached"]:
        assert history[-1] <= target and cmaes["stopped_by"] == "target"
    else:
        assert cmaes["exact_evals"] == MAX_EVALS or cmaes["stopped_by"].startswith("cma")


def test_same_seed_same_evaluations(runs):
    first, second, _ = runs
    for method in ("proxy", "cmaes"):
        assert first[method]["history"] == second[method]["history"]
        assert first[method]["exact_evals"] == second[method]["exact_evals"]
        assert first[method]["exact_loss"] == second[method]["exact_loss"]
    assert first["reached"] == second["reached"]


def test_table_renders(runs):
    from rich.console import Console

    console = Console(file=io.StringIO(), width=120)
    console.print(tb.table(runs[0]))
    text = console.file.getvalue()
    assert "CMA-ES" in text and "optimistix" in text and "speedup" in text


def test_stop_rule(tiny_setup):
    setup, targets = tiny_setup
    never = tb.run_cmaes(setup, targets, target_loss=-1.0, max_evals=3, seed=0)
    assert never["exact_evals"] == 3 and not never["reached"] and never["stopped_by"] == "max_evals"
    first = tb.run_cmaes(setup, targets, target_loss=math.inf, max_evals=3, seed=0)
    assert first["exact_evals"] == 1 and first["reached"] and first["stopped_by"] == "target"
    assert first["history"] == never["history"][:1]  # seeded: the same first candidate


def test_search_space_starts_at_the_creatures_defaults():
    from footfall.planner._timing import GaitTiming
    from footfall.tuning import creature_defaults

    ant = creature_defaults("ant")
    x0, lower, upper = tb.search_space(ant)
    weights, timing = tb.decode(x0)
    np.testing.assert_allclose(weights.to_array(), ant.to_array(), rtol=1e-12)
    np.testing.assert_allclose(timing.to_array(), GaitTiming().to_array(), rtol=1e-12)
    assert np.all(x0 < upper) and np.all(x0 > lower)
    tb.decode(np.where(np.isfinite(upper), upper, x0))  # the bounds themselves are valid parameters


def test_both_methods_start_from_the_bench_setups_mis_tuned_timing():
    """CMA-ES's x0 and the tune's starting parameters are the same point: the default weights and
    the default timing with stride_coefficient 3.0 (strides 30 % too long)."""
    from footfall.planner._timing import GaitTiming
    from footfall.planner._weights import ScoringWeights

    config = tb.make_config("spider")
    start = config.start()
    assert start == GaitTiming(stride_coefficient=3.0)
    weights, timing = tb.decode(tb.search_space(ScoringWeights(), start)[0], start)
    np.testing.assert_allclose(weights.to_array(), ScoringWeights().to_array(), rtol=1e-12)
    np.testing.assert_allclose(timing.to_array(), start.to_array(), rtol=1e-12)
    with pytest.raises(InputError, match="start_timing"):
        tb.make_config("spider", config_overrides={"start_timing": (("stride_coeficient", 3.0),)})
    with pytest.raises(InputError, match="start_timing"):
        tb.make_config("spider", config_overrides={"start_timing": (("stride_exponent", 0.7),)})


def test_invalid_candidate_costs_the_penalty(tiny_setup):
    setup, targets = tiny_setup
    x0, _, upper = tb.search_space(ScoringWeights())
    bad = x0.copy()
    bad[np.isfinite(upper)] = 1.0  # duty_at_rest, stride_exponent = e > their limits
    loss, why = tb.exact_loss_of(setup, targets, bad)
    assert loss == tb.INVALID_LOSS and why.startswith("invalid parameters")


@pytest.mark.parametrize("kwargs, name", [
    (dict(max_evals=0), "max_evals"), (dict(max_evals=2.5), "max_evals"), (dict(max_evals=True), "max_evals"),
    (dict(seed=-1), "seed"), (dict(rounds=0), "rounds"),
    (dict(config_overrides={"no_such_field": 1}), "config_overrides"),
    (dict(config_overrides={"seed": 3}), "config_overrides"),
])
def test_bad_arguments_name_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=f"^{name}:"):
        tb.run("spider", **kwargs)


def test_the_terrain_tune_comparison_counts_both_methods_on_the_same_runs():
    """``footfall bench tuning --scenarios``: the proxies' tune of the weights and CMA-ES on the same
    runs' loss (issue 18, item 6), tiny here."""
    from footfall.benchmarks.tuning_bench import run_events, table

    result = run_events("spider", ("stairs",), max_evals=2, rounds=1,
                        config_overrides=dict(seeds=(0,), frames=90, spawn_fractions=(0.3,), harvest_frames=10,
                                              harvest_characters=1, max_situations=30, fit_steps=2))
    proxy, cmaes = result["proxy"], result["cmaes"]
    assert proxy["rounds_run"] == 1 and 2 <= proxy["exact_evals"] <= 4  # the defaults + a line search of 1-3
    assert proxy["exact_loss"] <= proxy["start_exact_loss"]
    assert 1 <= cmaes["exact_evals"] <= 2 and cmaes["dimension"] == 19
    assert cmaes["reached"] == (cmaes["exact_loss"] <= result["target_loss"])
    assert result["speedup_is_lower_bound"] == (not cmaes["reached"])
    table(result)
