"""Terrain and style tunes (issue 18): targets files users write, runs that meet the terrain, the
terrain / style tune, and the preset x terrain matrix's rules."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import footfall_cli

from footfall import InputError

ROOT = Path(__file__).resolve().parents[1]
STYLES = ROOT / "tuning" / "data" / "styles"


# --------------------------------------------------------------------------- targets files


def _write(tmp_path, text, name="t.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_users_targets_file_overrides_the_stride_law_bands_and_states_a_style(tmp_path):
    from footfall.tuning._targets import load_tune_targets

    path = _write(tmp_path, """schema_version = 1
[sources]
lycosa = "Smith 2020: Lycosa trackways"
[stride_length]
coefficient = 2.0
exponent = 0.25
relative_tolerance = 0.1
source = "lycosa"
[duty_factor]
low = 0.62
high = 0.8
froude_max = 0.5
[style]
min_clearance_body_heights = 0.8
max_touchdown_slope_rad = 0.2
""")
    t = load_tune_targets(path, "spider")
    shipped = load_tune_targets(None, "spider")
    assert t.stride_law == (2.0, 0.25) and shipped.stride_law == (2.3, 0.3)
    assert t["stride_length"].citation.startswith("Smith 2020")
    assert t["duty_factor"].values == {"low": 0.62, "high": 0.8, "froude_max": 0.5}
    assert "user targets file" in t["duty_factor"].citation  # no source: the file itself
    assert t.style == {"min_clearance_body_heights": 0.8, "max_touchdown_slope_rad": 0.2}
    assert t.clearance_min_m == pytest.approx(0.8 * t.leg_length_m)  # the style's clearance, in body heights
    assert t["swing_jerk"] == shipped["swing_jerk"]  # the rest: the shipped targets
    # The runtime commands the file's law: the timing carries it, and the stride target follows it.
    timing = t.timing()
    assert (timing.stride_coefficient, timing.stride_exponent) == (2.0, 0.25)
    h = t.leg_length_m
    assert t.stride_length_m(0.3) == pytest.approx(2.0 * h * (0.09 / (9.81 * h)) ** 0.25, rel=1e-14)
    assert t.stride_law_text() == "2 h Fr^0.25"


def test_the_shipped_style_files_load():
    from footfall.tuning._targets import load_tune_targets

    for path in sorted(STYLES.glob("*.toml")):
        load_tune_targets(path, "spider")
    assert load_tune_targets(STYLES / "cautious.toml", "spider").style
    assert load_tune_targets(STYLES / "direct.toml", "spider").style


@pytest.mark.parametrize("text, field", [
    ("schema_version = 1\n[style]\nmin_clearance_body_heights = -1\n", "style.min_clearance_body_heights"),
    ("schema_version = 1\n[style]\nwobble = 1\n", "style.wobble"),
    ("schema_version = 1\n[stride_length]\ncoefficient = 2.0\n", "stride_length.exponent"),
    ("schema_version = 1\n[stride_length]\ncoefficient = 2.0\nexponent = 1.5\nrelative_tolerance = 0.1\n",
     "stride_length.exponent"),
    ("schema_version = 1\n[duty_factor]\nlow = 0.8\nhigh = 0.6\nfroude_max = 1.0\n", "duty_factor.high"),
    ("schema_version = 1\n[styel]\n", "styel"),
    ("schema_version = 2\n", "schema_version"),
    ("schema_version = [\n", "targets"),
    ("schema_version = 1\n[stride_length]\ncoefficient = 2.0\nexponent = 0.3\nrelative_tolerance = 0.1\n"
     "source = \"nobody\"\n", "stride_length.source"),
])
def test_a_malformed_targets_file_is_refused_naming_the_field(tmp_path, text, field):
    from footfall.tuning._targets import load_tune_targets

    path = _write(tmp_path, text)
    with pytest.raises(InputError) as error:
        load_tune_targets(path, "spider")
    assert error.value.file == str(path) and error.value.field == field


def test_cli_refuses_a_malformed_targets_file_with_one_line_and_exit_2(tmp_path):
    bad = _write(tmp_path, "schema_version = 1\n[style]\nmax_touchdown_slope_rad = 9\n")
    for args, field in (([f"--targets={bad}"], "style.max_touchdown_slope_rad"),
                        ([f"--targets={tmp_path / 'none.toml'}"], "targets"),
                        (["--scenarios=stairs,nowhere"], "scenario"),
                        # a variant's overrides stay with it: the second one is checked as hills'
                        # (read as a scenario of its own, it was "terrain.wavelength=-1: scenario: unknown")
                        (["--scenarios=hills@terrain.octaves=3,terrain.wavelength=-1,stairs"],
                         "hills@terrain.octaves=3,terrain.wavelength=-1: terrain.wavelength: must be > 0")):
        proc = footfall_cli("tune", "--creature", "spider", *args, "--out", tmp_path / "p.json", cwd=ROOT)
        assert proc.returncode == 2, proc.stderr
        assert field in proc.stderr and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
        assert not (tmp_path / "p.json").exists()


def test_the_stride_law_is_read_from_the_targets_file_not_written_in_the_code():
    """Issue 18, item 7: no literal 2.3 / 0.3 where the law is used; every use reads the targets file."""
    import re

    for relative in ("tuning/_exact.py", "tuning/_tune.py", "tuning/_tune_events.py", "tuning/_events.py",
                     "reports/_plots.py", "reports/_html.py"):
        code = [line.split("#")[0] for line in (ROOT / relative).read_text().splitlines()]
        # Outside docstrings and comments: a crude but strict reading (docstrings are prose lines).
        hits = [line for line in code if re.search(r"(?<![\w.])2\.3(?![\d])", line) and '"""' not in line
                and not line.strip().startswith(("*", "(", "``", "lambda"))]
        assert not [h for h in hits if "Fr" in h or "2.3 *" in h or "* 2.3" in h], (relative, hits)


def test_the_sweep_follows_the_targets_stride_law(tmp_path):
    from footfall.tuning._exact import sweep_froude
    from footfall.tuning._targets import load_tune_targets

    longer = load_tune_targets(_write(tmp_path, "schema_version = 1\n[stride_length]\ncoefficient = 3.0\n"
                                                "exponent = 0.3\nrelative_tolerance = 0.15\n"), "spider")
    # A longer stride law reaches 1.5 cells at a lower Froude number (when above the floor).
    assert sweep_froude("quadruped", longer)[0] <= sweep_froude("quadruped")[0]
    assert sweep_froude("spider") == sweep_froude("spider", load_tune_targets(None, "spider"))


def test_the_reports_stride_law_text_is_the_targets_files():
    from footfall.reports._sweep import stride_law_text
    from footfall.tuning._targets import load_tune_targets

    t = load_tune_targets(None, "spider")
    c, e = t.stride_law
    assert stride_law_text("spider") == f"{c:g} h Fr^{e:g}" == t.stride_law_text()


# --------------------------------------------------------------------------- runs that meet the terrain


def test_a_spawn_along_the_route_is_a_variant_between_spawn_and_goal():
    from footfall.scenarios import load_scenario
    from footfall.tuning._events import spawn_variant

    assert spawn_variant("stairs", 0.0) == "stairs"
    name = spawn_variant("stairs@terrain.rise=0.1", 0.3)
    s = load_scenario(name)
    assert s.terrain is not None and name.startswith("stairs@terrain.rise=0.1,crowd.centre=")
    base = load_scenario("stairs").crowd
    expected = base.centre + 0.3 * (np.asarray(base.route)[-1] - base.centre)
    np.testing.assert_allclose(s.crowd.centre, expected)
    assert expected[0] != base.centre[0]


@pytest.fixture(scope="module")
def one_run():
    from footfall.planner._weights import ScoringWeights
    from footfall.tuning._events import EventSetup, event_tasks, run_event_task
    from footfall.tuning._targets import load_tune_targets

    targets = load_tune_targets(None, "spider")
    setup = EventSetup("spider", ("stairs",), seeds=(3,), frames=150, spawn_fractions=(0.3,))
    task = event_tasks(setup, ScoringWeights(), targets.timing())[0]
    return task, run_event_task(task), targets


def test_a_run_is_footfall_simulate_and_its_metrics_are_the_simulations(one_run):
    """The per-event metrics reuse the simulation's summary (the run ``footfall simulate`` makes)."""
    from footfall.reports._runs import recorded_run
    from footfall.scenarios._gait_choice import resolve_gait
    from footfall.scenarios import load_creature, load_scenario

    task, result, _ = one_run
    assert task["scenario"] in result["replay"] and "--frames 150" in result["replay"]
    scenario = load_scenario(task["scenario"])
    creature = load_creature("spider")
    gait, _, _ = resolve_gait(scenario, creature)
    _, summary, _ = recorded_run(scenario, creature, gait, frames=150, characters=1, seed=3, record=False)
    s = summary.to_json()
    m = result["metrics"]
    assert m["stride_error"] == s["stride_rel_error_median"]
    assert m["holds_per_100_steps"] == 100.0 * s["holds"] / s["steps"]
    assert m["collisions"] == s["collisions"] + s["body_overlaps"]
    assert m["speed_ratio"] == s["speed_reached"] / min(s["speed_asked"], s["speed_cap"] or math.inf)
    # The spider spawned 1 m before the first riser climbs it: the plans see slopes and steps.
    assert m["touchdown_roughness_m"] > 0.0 and 0.0 < m["distance_ratio"] <= 1.05
    assert 0.0 < m["clearance_p05_h"] <= 10.0


def test_the_run_loss_is_its_formula(one_run):
    from footfall.tuning._events import COLLISION_PENALTY, HOLDS_REF, run_loss, style_terms

    _, result, targets = one_run
    m = dict(result["metrics"])
    tol = targets["stride_length"].values["relative_tolerance"]
    assert run_loss(m, targets) == pytest.approx((m["stride_error"] / tol) ** 2 + m["holds_per_100_steps"] / HOLDS_REF)
    m["collisions"] = 7  # a run with collisions costs the same whatever their count
    assert run_loss(m, targets) == pytest.approx((m["stride_error"] / tol) ** 2 + m["holds_per_100_steps"] / HOLDS_REF
                                                 + COLLISION_PENALTY)
    # A style's hinges: 0 when met, log ratio when not, each in its direction.
    m["near_box_share"] = 0.1
    m["touchdown_slope_rad"] = 0.08  # the run's own is 0 on 1 cm risers; a style's bound is > 0
    style = {"min_clearance_body_heights": 1.0, "max_touchdown_slope_rad": 0.5 * m["touchdown_slope_rad"],
             "min_distance_ratio": 0.5 * m["distance_ratio"]}
    terms = style_terms(m, style)
    assert terms["min_clearance_body_heights"] == pytest.approx(0.1 / 0.05)
    assert terms["max_touchdown_slope_rad"] == pytest.approx(math.log(2.0))
    assert terms["min_distance_ratio"] == 0.0


# --------------------------------------------------------------------------- the tune


def _tiny_config(**changes):
    from footfall.tuning._tune_events import EventTuneConfig

    settings = dict(scenarios=("stairs",), rounds=2, seeds=(0, 1), frames=120, spawn_fractions=(0.3,),
                    harvest_frames=15, harvest_characters=1, max_situations=60, fit_steps=3, holdout_seeds=(7, 8))
    settings.update(changes)
    return EventTuneConfig("spider", **settings)


@pytest.fixture(scope="module")
def tiny_tunes(tmp_path_factory):
    from footfall.tuning._tune_events import tune_events

    folder = tmp_path_factory.mktemp("events")
    config = _tiny_config()
    whole = tune_events(config, folder / "whole.json", workers=1)
    killed = tune_events(config, folder / "killed.json", workers=1, stop_after=1)
    resumed = tune_events(config, folder / "killed.json", workers=1, resume=True)
    return folder, config, whole, killed, resumed


@pytest.mark.slow  # tiny terrain tunes (about 15 s)
def test_a_tiny_terrain_tune_writes_a_preset_with_the_issues_json_keys(tiny_tunes):
    from footfall.planner import load_preset

    folder, config, whole, _, _ = tiny_tunes
    preset = load_preset(folder / "whole.json", "spider")
    for key in ("scenarios", "targets", "heldout_loss_default", "heldout_loss_tuned", "heldout_gain_se",
                "weights_max_rel_change", "spearman_metric_change"):
        assert key in whole.summary, key
    assert whole.summary["scenarios"] == ["stairs"]
    assert whole.summary["targets"]["stride_length"]["coefficient"] == preset.timing.stride_coefficient
    assert preset.provenance["summary"] == json.loads(json.dumps(whole.summary))
    if whole.summary["best_round"] < 0:
        assert whole.summary["weights_max_rel_change"] == 0.0
        assert whole.summary["heldout_loss_tuned"] == whole.summary["heldout_loss_default"]
    else:  # a tuned preset ships only if it does not lose on the held-out runs
        assert whole.summary["heldout_loss_tuned"] < whole.summary["heldout_loss_default"]
        assert whole.summary["weights_max_rel_change"] > 0.0


@pytest.mark.slow  # tiny terrain tunes (about 15 s)
def test_a_killed_terrain_tune_resumes_to_the_same_preset(tiny_tunes):
    folder, _, whole, killed, resumed = tiny_tunes
    assert not killed.finished
    assert (folder / "killed.json").read_bytes() == (folder / "whole.json").read_bytes()
    assert resumed.summary == whole.summary


@pytest.mark.slow  # tiny terrain tunes (about 15 s)
def test_a_checkpoint_of_other_settings_is_refused(tiny_tunes):
    from footfall.tuning._tune_events import tune_events

    folder, config, _, _, _ = tiny_tunes
    with pytest.raises(InputError, match="other settings"):
        tune_events(_tiny_config(rounds=3), folder / "whole.json", workers=1, resume=True)


def test_acceptance_needs_a_paired_gain_beyond_the_noise_and_no_more_collisions():
    from footfall.tuning._tune_events import accept

    def metrics(losses, collisions=0):
        return {"finite": True, "collisions": collisions, "exact_loss": float(np.mean(losses)),
                "runs": [{"run_loss": x, "collisions": collisions} for x in losses]}

    best = metrics([1.0, 1.0, 1.0, 1.0])
    assert accept(metrics([0.5, 0.5, 0.5, 0.6]), best, best, 2.0) == (True, "improved")
    ok, why = accept(metrics([0.2, 1.5, 0.3, 1.4]), best, best, 2.0)  # lower mean, within the noise
    assert not ok and "noise" in why
    ok, why = accept(metrics([0.5, 0.5, 0.5, 0.6], collisions=1), best, best, 2.0)
    assert not ok and "collisions" in why


# --------------------------------------------------------------------------- the matrix's rules


def _events(values, key="stride_error", collisions=0, crossings=0, **other):
    runs = [{key: v, "collisions": collisions if i == 0 else 0, "leg_crossings": crossings if i < 2 else 0,
             **{k: o[i] for k, o in other.items()}}
            for i, v in enumerate(values)]
    return {"runs": runs, "collisions": collisions}


def test_a_terrain_preset_passes_only_with_a_win_at_home_and_no_loss_elsewhere():
    from footfall.tuning._matrix import evaluate_cell, verdict

    rng = np.random.default_rng(0)
    base = 0.1 + 0.01 * rng.standard_normal(30)
    default = _events(base)
    better = _events(base - 0.02 + 0.005 * rng.standard_normal(30))
    same = _events(base + 0.002 * rng.standard_normal(30))
    worse = _events(base + 0.02 + 0.005 * rng.standard_normal(30))
    cells = {"stairs": evaluate_cell(default, better, {}), "crates": evaluate_cell(default, same, {})}
    assert cells["stairs"]["main"]["gain_se"] > 2.0
    assert verdict("spider-stairs", cells, {}, 0.5) == (True, [])
    # the same win from weights 18 % off the defaults at most: no preset of its own (issue 18: >= 20 %)
    passes, why = verdict("spider-stairs", cells, {}, 0.18)
    assert not passes and why == ["its weights differ from the defaults by 18.0% at most < 20%"]
    cells["crates"] = evaluate_cell(default, worse, {})
    passes, why = verdict("spider-stairs", cells, {}, 0.5)
    assert not passes and "crates" in why[0]
    cells = {"stairs": evaluate_cell(default, same, {}), "crates": evaluate_cell(default, same, {})}
    assert not verdict("spider-stairs", cells, {}, 0.5)[0]
    better_values = [r["stride_error"] for r in better["runs"]]
    collided = evaluate_cell(default, _events(better_values, collisions=1), {})  # one run with a collision
    assert collided["collisions_rise"]
    assert not verdict("spider-stairs", {"stairs": collided}, {}, 0.5)[0]
    # Two runs with crossing frames where the defaults' runs had none: refused, and it says why.
    crossed = evaluate_cell(default, _events(better_values, crossings=3), {})
    assert crossed["crossings_rise"] and (crossed["crossings_default"], crossed["crossings_preset"]) == (0, 6)
    assert verdict("spider-stairs", {"stairs": crossed}, {}, 0.5) == (
        False, ["stairs: leg crossings rise 0 -> 6 frames"])
    # The same crossings under both: no rise.
    both = evaluate_cell(_events(base, crossings=3), _events(better_values, crossings=3), {})
    assert not both["crossings_rise"] and verdict("spider-stairs", {"stairs": both}, {}, 0.5)[0]


def test_a_style_preset_passes_when_its_metric_moves_toward_its_bound():
    from footfall.tuning._matrix import evaluate_cell, verdict

    rng = np.random.default_rng(1)
    near = 0.2 + 0.02 * rng.standard_normal(30)
    stride = np.full(30, 0.05)
    style = {"min_clearance_body_heights": 1.0}  # toward it: fewer touch-downs near a box
    default = _events(stride, near_box_share=near)
    up = _events(stride, near_box_share=near - 0.05 + 0.01 * rng.standard_normal(30))
    down = _events(stride, near_box_share=near + 0.05)
    good = {t: evaluate_cell(default, up, style) for t in ("crates", "mixed")}
    assert good["crates"]["style"]["min_clearance_body_heights"]["gain_se"] > 2.0
    assert verdict("spider-cautious", good, style, 0.5) == (True, [])
    bad = {t: evaluate_cell(default, down, style) for t in ("crates", "mixed")}
    assert not verdict("spider-cautious", bad, style, 0.5)[0]


def test_the_reports_matrix_section_shows_every_preset_its_cells_and_verdict():
    from footfall.reports._html import matrix_section
    from footfall.tuning._matrix import evaluate_cell, verdict

    rng = np.random.default_rng(2)
    base = 0.1 + 0.01 * rng.standard_normal(30)
    cell = evaluate_cell(_events(base), _events(base - 0.02), {})
    passes, why = verdict("spider-stairs", {"stairs": cell}, {}, 0.5)
    matrix = {"terrains": {"stairs": "stairs@terrain.rise=0.1,terrain.run=0.3"}, "runs_per_cell": 30, "win_se": 2.0,
              "loss_se": 1.0, "presets": {
                  "spider-stairs": {"found": True, "passes": passes, "why": why, "command": "footfall tune X",
                                    "cells": {"stairs": cell}},
                  "ant-crates": {"found": False, "passes": False, "why": ["kept the defaults"],
                                 "command": "footfall tune Y"}}}
    page = matrix_section(matrix)
    assert "spider-stairs" in page and "ant-crates" in page and "kept the defaults" in page
    assert f"{cell['main']['default']:.3f} &rarr; {cell['main']['preset']:.3f}" in page
    assert "footfall tune X" in page and "stairs@terrain.rise=0.1,terrain.run=0.3" in page
    assert "No matrix stored" in matrix_section(None)


def test_a_clearance_style_starts_from_a_proximity_reference_as_far_as_its_bound():
    """The proximity goodness min(1, d / proximity_ref_m) saturates at the reference (0.10 m): a style
    bound of 2 h starts the tune with the reference at 2 h, in metres; no bound, or one inside the
    reference, starts at the given weights."""
    import dataclasses

    from footfall.planner._weights import W_PROXIMITY_REF, ScoringWeights
    from footfall.tuning._targets import load_tune_targets
    from footfall.tuning._tune_events import style_start

    default = {"weights": list(ScoringWeights().to_array()), "timing": [1.0]}
    plain = load_tune_targets(None, "spider")
    assert style_start(default, plain) == default
    h = plain.leg_length_m
    far = dataclasses.replace(plain, style={"min_clearance_body_heights": 2.0})
    start = style_start(default, far)
    expected = list(default["weights"])
    expected[W_PROXIMITY_REF] = 2.0 * h  # 0.24 m for the spider (h = 0.12 m)
    assert start["weights"] == pytest.approx(expected, rel=0, abs=0) and start["timing"] == default["timing"]
    assert default["weights"][W_PROXIMITY_REF] == 0.10  # the input is not changed
    near = dataclasses.replace(plain, style={"min_clearance_body_heights": 0.5})  # 0.06 m < 0.10 m
    assert style_start(default, near) == default


def test_the_offset_block_is_off_only_for_a_style_with_a_clearance_bound():
    """Pulling the feet onto their preferred footprints works against a clearance bound beside boxes;
    against a slope ceiling or no style, the stride law is kept too."""
    import dataclasses

    from footfall.tuning._targets import load_tune_targets
    from footfall.tuning._tune_events import offset_weight

    plain = load_tune_targets(None, "spider")
    assert offset_weight(plain) == 1.0
    assert offset_weight(dataclasses.replace(plain, style={"max_touchdown_slope_rad": 0.03})) == 1.0
    assert offset_weight(dataclasses.replace(plain, style={"min_distance_ratio": 0.95})) == 1.0
    assert offset_weight(dataclasses.replace(plain, style={"max_touchdown_slope_rad": 0.03,
                                                           "min_clearance_body_heights": 2.0})) == 0.0
    for name, weight in (("cautious", 0.0), ("sure-footed", 1.0), ("direct", 1.0)):
        assert offset_weight(load_tune_targets(STYLES / f"{name}.toml", "spider")) == weight, name


def test_the_events_checkpoint_round_trips_and_names_a_broken_field(tmp_path):
    from footfall.tuning._tune import BestSoFar, TuneConfig, _default_params
    from footfall.tuning._tune_events import EventTuneCheckpoint

    params = _default_params(TuneConfig("spider"))
    metrics = {"exact_loss": 0.5, "stride_rel_error": math.nan, "collisions": 0, "finite": True,
               "means": {"stride_error": None}, "runs": [{"run_loss": 0.5, "stride_error": math.nan}]}
    state = EventTuneCheckpoint(config={"creature": "spider"}, round=1, stopped=True, current=params,
                                best=BestSoFar(params, metrics, 0), default_exact=metrics, history=({"round": 0},))
    data = json.loads(json.dumps(state.to_json(), allow_nan=False))  # NaN is written as null
    assert data["best"]["exact"]["stride_rel_error"] is None
    back = EventTuneCheckpoint.from_json(data, tmp_path / "e.json")
    assert back == state.through_json() and back.to_json() == data
    for change, field in ((dict(best={"params": params}), "best"), (dict(round=1.5), "round"),
                          (dict(history={}), "history"), (dict(current={"weights": [1.0]}), "params")):
        with pytest.raises(InputError, match=f"e.json: {field}: corrupt checkpoint"):
            EventTuneCheckpoint.from_json(dict(data, **change), tmp_path / "e.json")
    broken = {k: v for k, v in data.items() if k != "default_exact"}
    with pytest.raises(InputError, match="default_exact: corrupt checkpoint: missing field"):
        EventTuneCheckpoint.from_json(broken, tmp_path / "e.json")


def test_the_touchdown_slope_is_the_grounds_whatever_the_weights():
    """The touch-down slope is read on the terrain under the landed feet. Read back from the plans'
    goodnesses, x = (1 - s) slope_critical_rad, it was capped at the run's own critical value: a preset
    that lowered it 1.0 -> 0.32 cut its own metric 0.058 -> 0.036 rad on rough ground while its feet
    stood on ground as steep as the defaults' (session 48)."""
    from footfall.planner._weights import ScoringWeights
    from footfall.tuning._events import EventSetup, event_tasks, run_event_task
    from footfall.tuning._matrix import ROUGH_GROUND
    from footfall.tuning._targets import load_tune_targets

    targets = load_tune_targets(None, "spider")
    setup = EventSetup("spider", (ROUGH_GROUND,), seeds=(1,), frames=90, spawn_fractions=(0.3,))
    critical = 0.02
    task = event_tasks(setup, ScoringWeights(slope_critical_rad=critical), targets.timing())[0]
    m = run_event_task(task)["metrics"]
    # The defaults' touch-downs there stand on 0.07-0.09 rad; a capped reading could not exceed 0.02.
    assert m["touchdown_slope_rad"] > 2.0 * critical, m["touchdown_slope_rad"]
    assert 0.0 < m["touchdown_roughness_m"] < 0.05
