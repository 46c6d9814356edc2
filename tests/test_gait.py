"""Tests of the gait manager: gait files, the support rule, the timing model and the crowd runtime."""

from __future__ import annotations

import dataclasses
import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from footfall._errors import InputError
from footfall.planner._gait import GaitManagerState, advance, init_gaits, set_destination, set_speed
from footfall.planner._kernels_gait import duty_factor_k, scale_swing_durations_k, stride_frequency_k, stride_length_k
from footfall.planner._timing import (
    GRAVITY,
    SWING_MAX,
    SWING_MIN,
    TIMING_FIELDS,
    GaitTiming,
    duty_factor,
    hip_height,
    scaled_swing_durations,
    stride_frequency,
    stride_length,
)
from footfall.scenarios import (
    Gait,
    builtin_gait_names,
    default_gait_name,
    load_creature,
    load_gait,
    min_stance_feet,
    required_stance_feet,
)

GAIT_CREATURE = {
    "spider-alternating-tetrapod": "spider",
    "spider-metachronal-wave": "spider",
    "ant-tripod": "ant",
    "ant-tetrapod": "ant",
    "quadruped-walk": "quadruped",
    "quadruped-trot": "quadruped",
    "quadruped-pace": "quadruped",
    "robot5-wave": "robot5",
}


def wrap(x):
    return np.mod(x, 1.0)


def starts(gait: Gait) -> dict[str, float]:
    return dict(zip(gait.leg_names, map(float, gait.swing_start)))


def phase_gap(a: float, b: float) -> float:
    """b - a (mod 1), in [0, 1)."""
    return float(wrap(b - a))


def close_phase(a: float, b: float, tol: float = 1e-9) -> bool:
    gap = phase_gap(a, b)
    return min(gap, 1.0 - gap) <= tol


# --------------------------------------------------------------------------- built-in gaits


def test_builtin_names_and_defaults():
    assert builtin_gait_names() == tuple(sorted(GAIT_CREATURE))
    assert builtin_gait_names("ant") == ("ant-tetrapod", "ant-tripod")
    assert builtin_gait_names(load_creature("quadruped")) == ("quadruped-pace", "quadruped-trot", "quadruped-walk")
    expected = {"spider": "spider-metachronal-wave", "ant": "ant-tripod", "quadruped": "quadruped-walk",
                "robot5": "robot5-wave"}
    for creature, gait in expected.items():
        assert default_gait_name(creature) == gait
        assert default_gait_name(load_creature(creature)) == gait
        load_gait(default_gait_name(creature), creature)
    with pytest.raises(InputError, match="no default gait"):
        default_gait_name("octopus")


@pytest.mark.parametrize("name", sorted(GAIT_CREATURE))
def test_builtin_gait_loads_for_its_creature(name):
    creature = load_creature(GAIT_CREATURE[name])
    gait = load_gait(name, creature)
    assert gait.name == name and gait.description
    assert gait.leg_names == creature.leg_names
    for array in (gait.swing_start, gait.swing_duration):
        assert array.dtype == np.float64 and array.shape == (creature.n_legs,) and not array.flags.writeable
    assert np.all((gait.swing_start >= 0) & (gait.swing_start < 1))
    assert np.all((gait.swing_duration > 0) & (gait.swing_duration < 1))
    least, _ = min_stance_feet(gait.swing_start, gait.swing_duration)
    assert least >= required_stance_feet(creature.n_legs)
    with pytest.raises(dataclasses.FrozenInstanceError):
        gait.name = "x"


def swinging_at(gait: Gait, phase: float) -> set[str]:
    on = wrap(phase - gait.swing_start) < gait.swing_duration
    return {n for n, a in zip(gait.leg_names, on) if a}


def assert_groups(gait: Gait, groups: list[set[str]], spacing: float):
    """Each group swings together (same start and duration); consecutive groups ``spacing`` apart."""
    s = starts(gait)
    duration = dict(zip(gait.leg_names, gait.swing_duration))
    assert set().union(*groups) == set(gait.leg_names)
    heads = []
    for group in groups:
        first = min(group)
        assert all(close_phase(s[leg], s[first]) and duration[leg] == duration[first] for leg in group), group
        heads.append(s[first])
    for a, b in zip(heads, heads[1:] + heads[:1]):
        assert phase_gap(a, b) == pytest.approx(spacing, abs=1e-9)
    # and they really swing together: at the middle of a group's sector exactly that group is up
    # whenever sectors do not overlap
    if np.all(gait.swing_duration <= spacing + 1e-12):
        for group, head in zip(groups, heads):
            assert swinging_at(gait, head + 0.5 * duration[min(group)]) == group


def test_spider_alternating_tetrapod_pattern():
    gait = load_gait("spider-alternating-tetrapod", "spider")
    assert_groups(gait, [{"L1", "R2", "L3", "R4"}, {"R1", "L2", "R3", "L4"}], 0.5)


def test_spider_metachronal_wave_pattern():
    gait = load_gait("spider-metachronal-wave", "spider")
    s = starts(gait)
    latencies = []
    for side in "LR":
        # back to front: 4 -> 3 -> 2 -> 1, each a constant latency after the leg behind it
        wave = [s[f"{side}{k}"] for k in (4, 3, 2, 1)]
        gaps = [phase_gap(a, b) for a, b in zip(wave, wave[1:])]
        assert gaps == pytest.approx([gaps[0]] * 3, abs=1e-12)
        latencies.append(gaps[0])
        assert 0.0 < gaps[0] and 3 * gaps[0] < 1.0  # one wave per cycle, running from back to front
        # the front-to-back direction would need longer steps: this is not a 1 -> 4 wave
        assert phase_gap(s[f"{side}1"], s[f"{side}2"]) > 0.5
    assert latencies[0] == pytest.approx(latencies[1], abs=1e-12)
    for k in range(1, 5):  # left and right alternate
        assert phase_gap(s[f"L{k}"], s[f"R{k}"]) == pytest.approx(0.5, abs=1e-12)
    assert 0.6 <= gait.duty_factor <= 0.7


def test_ant_gait_patterns():
    tripod = load_gait("ant-tripod", "ant")
    assert_groups(tripod, [{"L1", "R2", "L3"}, {"R1", "L2", "R3"}], 0.5)
    assert tripod.duty_factor == pytest.approx(0.5, abs=0.05)
    s = starts(tripod)
    for a, b in (("L1", "L2"), ("L2", "L3"), ("R1", "R2"), ("L1", "R1"), ("L2", "R2"), ("L3", "R3")):
        assert phase_gap(s[a], s[b]) == pytest.approx(0.5)  # ipsilateral neighbours and contralateral pairs
    tetrapod = load_gait("ant-tetrapod", "ant")
    assert_groups(tetrapod, [{"L3", "R1"}, {"L2", "R3"}, {"L1", "R2"}], 1 / 3)
    assert tetrapod.duty_factor == pytest.approx(2 / 3, abs=1e-9)
    assert min_stance_feet(tetrapod.swing_start, tetrapod.swing_duration)[0] == 4


def test_quadruped_and_robot_patterns():
    walk = load_gait("quadruped-walk", "quadruped")
    s = starts(walk)
    order = ["LH", "LF", "RH", "RF"]
    for a, b in zip(order, order[1:] + order[:1]):
        assert phase_gap(s[a], s[b]) == pytest.approx(0.25)
    assert walk.duty_factor == pytest.approx(0.75, abs=0.03)
    assert_groups(load_gait("quadruped-trot", "quadruped"), [{"LF", "RH"}, {"RF", "LH"}], 0.5)
    assert_groups(load_gait("quadruped-pace", "quadruped"), [{"LF", "LH"}, {"RF", "RH"}], 0.5)
    wave = load_gait("robot5-wave", "robot5")
    s = starts(wave)
    for k in range(5):
        assert phase_gap(s[f"leg{k}"], s[f"leg{(k + 1) % 5}"]) == pytest.approx(0.2)


def test_gaits_keep_the_support_rule_when_scaled_by_speed():
    timing = GaitTiming()
    for name, creature in GAIT_CREATURE.items():
        gait = load_gait(name, creature)
        for duty in np.linspace(timing.duty_min, timing.duty_max, 9):
            scaled = scaled_swing_durations(gait.swing_duration, duty)
            assert min_stance_feet(gait.swing_start, scaled)[0] >= required_stance_feet(gait.n_legs), (name, duty)


# --------------------------------------------------------------------------- files and errors


SPIDER_LEGS = ("L1", "L2", "L3", "L4", "R1", "R2", "R3", "R4")


def gait_file(tmp_path: Path, swing: dict[str, str], extra: str = "", name: str = "g.toml") -> Path:
    lines = [extra, "[swing]"] + [f"{leg} = {{ {body} }}" for leg, body in swing.items()]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def tetrapod_swing(**changes: str) -> dict[str, str]:
    swing = {leg: f"start = {0.0 if leg in ('L1', 'R2', 'L3', 'R4') else 0.5}, duration = 0.45" for leg in SPIDER_LEGS}
    swing.update(changes)
    return swing


def expect_error(path: Path, creature: str, field: str, reason: str) -> InputError:
    with pytest.raises(InputError) as info:
        load_gait(path, creature)
    error = info.value
    assert error.file == str(path) and error.field == field, str(error)
    assert reason in error.reason, str(error)
    assert "\n" not in str(error) and str(error).startswith(f"{path}: {field}: ")
    return error


def test_a_valid_file_loads_in_the_creature_order(tmp_path):
    swing = dict(reversed(list(tetrapod_swing(L2="start = 0.5, duration = 0.4").items())))
    path = gait_file(tmp_path, swing, 'description = "mine"')
    gait = load_gait(path, "spider")
    assert gait.name == "g" and gait.description == "mine" and gait.leg_names == SPIDER_LEGS
    assert gait.swing_duration[1] == 0.4 and gait.swing_start[1] == 0.5


def test_file_errors_name_the_file_and_field(tmp_path):
    expect_error(gait_file(tmp_path, tetrapod_swing(L1="start = 0.0, duration = 1.0")), "spider",
                 "swing.L1.duration", "< 1")
    expect_error(gait_file(tmp_path, tetrapod_swing(L1="start = 0.0, duration = 0.0")), "spider",
                 "swing.L1.duration", "> 0")
    expect_error(gait_file(tmp_path, tetrapod_swing(R3="start = 1.0, duration = 0.4")), "spider",
                 "swing.R3.start", "< 1")
    expect_error(gait_file(tmp_path, tetrapod_swing(R3="start = -0.1, duration = 0.4")), "spider",
                 "swing.R3.start", ">= 0")
    expect_error(gait_file(tmp_path, tetrapod_swing(L2="start = nan, duration = 0.4")), "spider",
                 "swing.L2.start", "finite")
    expect_error(gait_file(tmp_path, tetrapod_swing(L2="start = 0.5, duration = 0.4, lift = 1")), "spider",
                 "swing.L2.lift", "unknown key")
    expect_error(gait_file(tmp_path, tetrapod_swing(), "speed = 2"), "spider", "speed", "unknown key")
    expect_error(gait_file(tmp_path, tetrapod_swing(L2='start = "half", duration = 0.4')), "spider",
                 "swing.L2.start", "expected a number")
    # unknown leg (same count), missing leg, a gait for another number of legs
    swing = tetrapod_swing()
    swing["L9"] = swing.pop("L4")
    expect_error(gait_file(tmp_path, swing), "spider", "swing.L9", "unknown leg 'L9'")
    swing = tetrapod_swing()
    del swing["L4"]
    expect_error(gait_file(tmp_path, swing), "spider", "swing.L4", "missing leg")
    expect_error(Path(load_gait.__globals__["GAITS_DIR"]) / "spider-metachronal-wave.toml", "ant", "swing",
                 "gives 8 legs")
    with pytest.raises(InputError, match=r"^builtin:ant-tripod: swing.L4: missing leg; creature 'spider' has 8"):
        load_gait("ant-tripod", "spider")
    with pytest.raises(InputError, match=r"^builtin:quadruped-walk: swing: the gait gives 4 legs"):
        load_gait("quadruped-walk", "robot5")
    with pytest.raises(InputError, match=r"^no-such-gait: gait: unknown gait"):
        load_gait("no-such-gait", "spider")
    bad = tmp_path / "bad.toml"
    bad.write_text("[swing\n")
    with pytest.raises(InputError, match="invalid TOML"):
        load_gait(bad, "spider")


def test_impossible_gaits_are_refused(tmp_path):
    # every foot in the air around phase 0.5: the two tetrapods overlap
    path = gait_file(tmp_path, {leg: f"start = {0.0 if leg in ('L1', 'R2', 'L3', 'R4') else 0.4}, duration = 0.6"
                                for leg in SPIDER_LEGS})
    expect_error(path, "spider", "swing", "every foot swings at once")
    # exact: tripods touching at 0.5 are fine, overlapping by 1e-6 of a cycle are not
    touching = {leg: f"start = {0.0 if leg in ('L1', 'R2', 'L3') else 0.5}, duration = 0.5"
                for leg in ("L1", "L2", "L3", "R1", "R2", "R3")}
    load_gait(gait_file(tmp_path, touching, name="touch.toml"), "ant")
    overlapping = {leg: body.replace("0.5,", "0.5000001,").replace("duration = 0.5", "duration = 0.5000001")
                   for leg, body in touching.items()}
    expect_error(gait_file(tmp_path, overlapping, name="over.toml"), "ant", "swing", "every foot swings at once")
    # a single foot down: three quadruped feet swing together at some phase
    one_down = {"LF": "start = 0.0, duration = 0.5", "RF": "start = 0.2, duration = 0.5",
                "LH": "start = 0.4, duration = 0.4", "RH": "start = 0.75, duration = 0.2"}
    error = expect_error(gait_file(tmp_path, one_down, name="one.toml"), "quadruped", "swing", "only 1 foot in stance")
    assert "needs at least 2" in error.reason
    # the rule for one- and two-legged gaits: never every foot up
    Gait("biped", ("a", "b"), [0.0, 0.5], [0.5, 0.5])
    with pytest.raises(InputError, match="every foot swings"):
        Gait("biped", ("a", "b"), [0.0, 0.4], [0.6, 0.6])
    assert required_stance_feet(1) == 1 and required_stance_feet(2) == 1 and required_stance_feet(3) == 2


def test_gait_constructor_checks(tmp_path):
    with pytest.raises(InputError, match=r"swing_duration\[1\]"):
        Gait("g", ("a", "b", "c"), [0.0, 0.3, 0.6], [0.2, 1.2, 0.2])
    with pytest.raises(InputError, match=r"swing_start\[0\]"):
        Gait("g", ("a", "b", "c"), [1.0, 0.3, 0.6], [0.2, 0.2, 0.2])
    with pytest.raises(InputError, match=r"leg_names\[1\]: duplicate"):
        Gait("g", ("a", "a", "c"), [0.0, 0.3, 0.6], [0.2, 0.2, 0.2])
    with pytest.raises(InputError, match="swing_start: expected shape"):
        Gait("g", ("a", "b"), [0.0, 0.3, 0.6], [0.2, 0.2])


# --------------------------------------------------------------------------- timing model


def test_timing_round_trip_and_description():
    rng = np.random.default_rng(1)
    for _ in range(100):
        duty_min = rng.uniform(0.05, 0.6)
        values = np.array([rng.uniform(0.5, 4.0), rng.uniform(0.0, 0.49), rng.uniform(0.01, 2.0),
                           rng.uniform(0.05, 0.95), rng.uniform(0.0, 1.0), duty_min, rng.uniform(duty_min, 0.95)])
        timing = GaitTiming.from_array(values)
        np.testing.assert_array_equal(timing.to_array(), values)
        assert GaitTiming.from_array(timing.to_array()) == timing
    assert tuple(f.name for f in dataclasses.fields(GaitTiming)) == TIMING_FIELDS
    for name, unit, doc in GaitTiming.describe():
        assert unit and doc, name
    defaults = GaitTiming()
    assert (defaults.stride_coefficient, defaults.stride_exponent) == (2.3, 0.3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        defaults.duty_min = 0.2
    with pytest.raises(ValueError, match="shape"):
        GaitTiming.from_array(np.ones(3))


@pytest.mark.parametrize("kwargs, match", [
    ({"stride_coefficient": 0.0}, "stride_coefficient"),
    ({"stride_exponent": 0.5}, "stride_exponent"),
    ({"stride_exponent": -0.1}, "stride_exponent"),
    ({"min_frequency_hz": 0.0}, "min_frequency_hz"),
    ({"duty_at_rest": 1.0}, "duty_at_rest"),
    ({"duty_slope": -0.1}, "duty_slope"),
    ({"duty_min": 0.0}, "duty_min"),
    ({"duty_min": 0.7, "duty_max": 0.6}, "duty_max"),
    ({"duty_max": 1.0}, "duty_max"),
    ({"duty_slope": float("nan")}, "duty_slope"),
    ({"stride_coefficient": "big"}, "stride_coefficient"),
    ({"duty_min": True}, "duty_min"),
])
def test_invalid_timing_is_refused_naming_the_field(kwargs, match):
    with pytest.raises(ValueError, match=match):
        GaitTiming(**kwargs)


def test_stride_length_is_dynamic_similarity():
    timing = GaitTiming()
    v = np.linspace(0.01, 3.0, 200)[:, None]
    h = np.array([0.05, 0.12, 0.45])[None, :]
    froude = v ** 2 / (9.81 * h)
    np.testing.assert_array_equal(stride_length(timing, v, h), 2.3 * h * froude ** 0.3)
    np.testing.assert_allclose(stride_length(timing, v, h) / h, 2.3 * froude ** 0.3, rtol=1e-15)
    assert stride_length(timing, 0.0, 0.12) == 0.0
    assert isinstance(stride_length(timing, 0.3, 0.12), float)
    # f = v / lambda grows as v^0.4 above the floor; the floor holds at crawling speeds; f(0) = 0
    f = stride_frequency(timing, v, h)
    natural = v / stride_length(timing, v, h)
    np.testing.assert_allclose(f, np.maximum(natural, timing.min_frequency_hz), rtol=1e-15)
    fast = natural[-1] > timing.min_frequency_hz
    np.testing.assert_allclose(natural[-1] / natural[-2], np.full(3, (v[-1, 0] / v[-2, 0]) ** 0.4), rtol=1e-12)
    assert np.all(fast) and np.all(np.diff(f, axis=0) >= 0)
    assert stride_frequency(timing, 0.0, 0.12) == 0.0
    assert stride_frequency(timing, 1e-9, 0.12) == timing.min_frequency_hz
    # So slow that Fr^0.3 underflows: no stride, so no tempo (v / 0 stopped a run: robot5 on mixed,
    # 8 characters, LOD zoomed, seed 900, braked geometrically to 2e-177 m/s by frame 491).
    assert stride_length(timing, 1e-200, 0.12) == 0.0 and stride_frequency(timing, 1e-200, 0.12) == 0.0
    with pytest.raises(ValueError, match="speed"):
        stride_length(timing, -1.0, 0.12)
    with pytest.raises(ValueError, match="height"):
        stride_frequency(timing, 1.0, 0.0)


def test_duty_factor_falls_with_speed_within_bounds():
    timing = GaitTiming()
    v = np.linspace(0.0, 5.0, 501)
    for h in (0.05, 0.12, 0.42):
        df = duty_factor(timing, v, h)
        assert np.all(np.diff(df) <= 0) and df[0] > df[-1]
        assert np.all((df >= timing.duty_min) & (df <= timing.duty_max))
        unclipped = (df > timing.duty_min) & (df < timing.duty_max)
        slope = np.diff(df)[unclipped[1:] & unclipped[:-1]]
        np.testing.assert_allclose(slope, slope[0], rtol=1e-9)  # linear in v
        assert df[-1] == timing.duty_min
    assert 0.6 <= duty_factor(timing, 0.3, 0.12) <= 0.7  # a walking spider
    assert duty_factor(timing, math.sqrt(GRAVITY * 0.12), 0.12) == pytest.approx(0.5, abs=0.01)  # Fr = 1
    assert hip_height(load_creature("spider")) == pytest.approx(0.12)
    tight = GaitTiming(duty_at_rest=0.9, duty_max=0.8, duty_min=0.6)
    assert duty_factor(tight, 0.0, 0.12) == 0.8 and duty_factor(tight, 10.0, 0.12) == 0.6


def test_kernel_twins_match_numpy():
    rng = np.random.default_rng(2)
    for timing in (GaitTiming(), GaitTiming(stride_exponent=0.0, min_frequency_hz=0.1, duty_slope=0.0)):
        params = timing.to_array()
        for v, h in zip(np.r_[0.0, 1e-200, rng.uniform(0, 3, 50)], np.r_[0.12, 0.12, rng.uniform(0.03, 0.6, 50)]):
            assert stride_length_k(params, v, h) == pytest.approx(stride_length(timing, v, h), rel=1e-14, abs=0)
            assert stride_frequency_k(params, v, h) == pytest.approx(stride_frequency(timing, v, h), rel=1e-14)
            assert duty_factor_k(params, v, h) == pytest.approx(duty_factor(timing, v, h), rel=1e-14)
    durations = rng.uniform(0.05, 0.9, 7)
    out = np.empty(7)
    for duty in (0.05, 0.3, 0.6, 0.99):
        scale_swing_durations_k(durations, duty, out)
        np.testing.assert_array_equal(out, scaled_swing_durations(durations, duty))


def test_scaled_durations_keep_the_pattern_and_follow_the_duty_factor():
    durations = np.array([0.2, 0.3, 0.4, 0.3])
    scaled = scaled_swing_durations(durations, 0.6)
    assert scaled.mean() == pytest.approx(0.4)
    np.testing.assert_allclose(scaled / scaled[0], durations / durations[0])
    np.testing.assert_array_equal(scaled_swing_durations(durations, 0.999), np.full(4, SWING_MIN))
    assert scaled_swing_durations([0.1, 0.9], 0.01)[1] == SWING_MAX
    batch = scaled_swing_durations(np.tile(durations, (3, 1)), np.array([0.5, 0.6, 0.7]))
    np.testing.assert_allclose(batch.mean(axis=1), [0.5, 0.4, 0.3])


# --------------------------------------------------------------------------- runtime: needle


def controller(state: GaitManagerState, stance: np.ndarray, enter: np.ndarray) -> np.ndarray:
    """A minimal character controller: entering feet lift off; a swinging foot lands once the needle
    has left its sector."""
    new = stance & ~enter
    new |= ~stance & ~state.active()
    return new


def test_needle_triggers_each_foot_once_per_cycle():
    rng = np.random.default_rng(3)
    n_chars, n_legs = 16, 6
    start = rng.uniform(0, 1, (n_chars, n_legs))
    duration = rng.uniform(0.05, 0.6, (n_chars, n_legs))
    state = init_gaits((start, duration), n_chars, rng)
    frequency = rng.uniform(0.5, 3.0, n_chars)
    unwrapped = state.needle.copy()
    first = unwrapped.copy()
    stance = np.ones((n_chars, n_legs), dtype=bool)
    counts = np.zeros((n_chars, n_legs), dtype=np.int64)
    jumps = 0
    for _ in range(4000):
        sweep_max = rng.uniform(0.01, 0.38)  # up to longer than the shortest sectors, < 1 - longest
        dt = sweep_max / frequency.max()
        before = unwrapped.copy()
        enter, fraction = advance(state, frequency, dt, stance)
        unwrapped = unwrapped + frequency * dt
        np.testing.assert_allclose(wrap(unwrapped), state.needle, atol=1e-9)
        # a foot enters exactly when its start lies in the swept arc [before, after)
        crossed = np.ceil(unwrapped[:, None] - start) - np.ceil(before[:, None] - start) > 0
        np.testing.assert_array_equal(enter, crossed & stance)
        jumps += int(np.sum(enter & (fraction == 0.0)))
        counts += enter
        assert np.all(stance | ~crossed)  # the simple controller always has the foot down in time
        stance = controller(state, stance, enter)
        np.testing.assert_array_equal(state.disk_start, start)  # no transition: disks untouched
    cycles = np.ceil(unwrapped[:, None] - start) - np.ceil(first[:, None] - start)
    np.testing.assert_array_equal(counts, cycles)
    assert counts.min() >= 100
    assert jumps > 0  # some steps jumped over a whole sector and still triggered


def test_a_whole_cycle_in_one_step_triggers_once():
    gait = load_gait("ant-tripod", "ant")
    state = init_gaits(gait, 2, np.array([0.0, 0.3]))
    enter, _ = advance(state, np.array([1.0, 2.5]), 1.0, np.ones((2, 6), dtype=bool))
    assert enter.all()
    np.testing.assert_allclose(state.needle, [0.0, 0.8])
    enter, _ = advance(state, 0.0, 1.0, np.ones((2, 6), dtype=bool))
    assert not enter.any()  # the needle stopped (v = 0)


def test_swing_fraction_and_initial_trigger():
    gait = load_gait("quadruped-walk", "quadruped")  # LF 0.25, RF 0.75, LH 0.0, RH 0.5, each 0.25
    state = init_gaits(gait, 1)
    stance = np.ones((1, 4), dtype=bool)
    enter, fraction = advance(state, 1.0, 0.1, stance)
    np.testing.assert_array_equal(enter, [[False, False, True, False]])  # the needle starts on LH's start
    np.testing.assert_allclose(fraction, [[0.0, 0.0, 0.4, 0.0]])
    enter, fraction = advance(state, 1.0, 0.2, stance)
    np.testing.assert_array_equal(enter, [[True, False, False, False]])
    np.testing.assert_allclose(fraction, [[0.2, 0.0, 0.0, 0.0]])
    np.testing.assert_array_equal(state.active(), fraction > 0)


# --------------------------------------------------------------------------- runtime: transitions


def on_arc(current, source, dest_start, dest_duration, tol=1e-9):
    """Whether ``current`` lies on the arc from ``source`` to ``dest_start`` that avoids the
    destination's finish (independent of the kernel's code)."""
    finish = wrap(dest_start + dest_duration)
    forward = wrap(source - finish) < wrap(dest_start - finish)
    fwd_ok = wrap(current - source) <= wrap(dest_start - source) + tol
    bwd_ok = wrap(source - current) <= wrap(source - dest_start) + tol
    near = np.minimum(wrap(current - dest_start), 1 - wrap(current - dest_start)) <= tol
    near |= np.minimum(wrap(current - source), 1 - wrap(current - source)) <= tol
    return near | np.where(forward, fwd_ok, bwd_ok)


def arc_remaining(current, dest_start, direction_forward):
    return np.where(direction_forward, wrap(dest_start - current), wrap(current - dest_start))


def random_transition_crowd(rng, n_legs, n_chars, builtin_pairs=()):
    """(state, frequency, speed) for random source -> destination pairs at random speeds."""
    timing = GaitTiming()
    src_start = rng.uniform(0, 1, (n_chars, n_legs))
    src_duration = rng.uniform(0.1, 0.6, (n_chars, n_legs))
    dst_start = rng.uniform(0, 1, (n_chars, n_legs))
    dst_duration = rng.uniform(0.1, 0.6, (n_chars, n_legs))
    for i, (a, b) in enumerate(builtin_pairs):
        src_start[i], src_duration[i] = a.swing_start, a.swing_duration
        dst_start[i], dst_duration[i] = b.swing_start, b.swing_duration
    speed = rng.uniform(0.05, 1.0, n_chars)
    duty = duty_factor(timing, speed, 0.12)
    state = init_gaits((src_start, src_duration), n_chars, rng, transition_rate=rng.uniform(0.15, 1.5, n_chars),
                       duty_factor=duty)
    frequency = set_speed(state, timing, speed, 0.12)
    np.testing.assert_array_equal(state.duty_factor, duty)
    assert not state.transitioning().any()
    set_destination(state, np.arange(n_chars), (dst_start, dst_duration))
    return state, frequency


@pytest.mark.parametrize("n_legs, creature", [(8, "spider"), (6, "ant"), (5, None), (4, "quadruped")])
def test_transitions_never_start_a_swing_outside_the_allowed_arc(n_legs, creature):
    rng = np.random.default_rng(100 + n_legs)
    pairs = []
    if creature is not None:
        gaits = [load_gait(name, creature) for name in builtin_gait_names(creature)]
        pairs = list(itertools.permutations(gaits, 2))
    n_chars = 60
    state, frequency = random_transition_crowd(rng, n_legs, n_chars, pairs)
    source_start = state.disk_start.copy()
    source_duration = state.disk_duration.copy()
    dest_start, dest_duration = state.dest_start.copy(), state.dest_duration.copy()
    finish = wrap(dest_start + dest_duration)
    forward = wrap(source_start - finish) < wrap(dest_start - finish)
    total_start = arc_remaining(source_start, dest_start, forward)
    total_duration = dest_duration - source_duration
    assert state.transitioning().all()

    stance = np.ones((n_chars, n_legs), dtype=bool)
    triggers = moving_triggers = 0
    for step in range(4000):
        dt = rng.uniform(0.002, 0.008)  # (f + rate) dt < 5.3 Hz * dt < 0.05 <= the shortest sector
        before_start, before_duration = state.disk_start.copy(), state.disk_duration.copy()
        enter, fraction = advance(state, frequency, dt, stance)
        # swinging feet keep their disk
        np.testing.assert_array_equal(state.disk_start[~stance], before_start[~stance])
        np.testing.assert_array_equal(state.disk_duration[~stance], before_duration[~stance])
        # every start stays on the arc source -> destination that avoids the destination's finish
        assert on_arc(state.disk_start, source_start, dest_start, dest_duration).all()
        # a swing starts only with the needle inside the foot's current sector
        inside = wrap(state.needle[:, None] - state.disk_start) < state.disk_duration
        assert np.all(inside[enter]) and np.all(fraction[enter] < 1.0)
        triggers += int(enter.sum())
        moving_triggers += int(np.sum(enter & ((before_start != dest_start) | (before_duration != dest_duration))))
        # the duration follows the start linearly: remaining (start, duration) stay proportional
        rem_start = arc_remaining(state.disk_start, dest_start, forward)
        rem_start = np.where(rem_start > 1 - 1e-6, 0.0, rem_start)
        rem_duration = dest_duration - state.disk_duration
        np.testing.assert_allclose(rem_start * total_duration, rem_duration * total_start, atol=1e-9)
        # and moves by at most rate * dt per step
        moved = np.minimum(wrap(state.disk_start - before_start), 1 - wrap(state.disk_start - before_start))
        assert np.all(moved <= state.transition_rate[:, None] * dt + 1e-12)
        stance = controller(state, stance, enter)
        if step % 200 == 199 and not state.transitioning().any():
            break
    assert triggers > 20 * n_chars and moving_triggers > 5 * n_chars  # many swings began mid-transition
    # converged: the disks are exactly the destination
    assert not state.transitioning().any()
    np.testing.assert_array_equal(state.disk_start, dest_start)
    np.testing.assert_array_equal(state.disk_duration, dest_duration)


def one_foot(start, duration, dest_start, dest_duration, rate):
    """A 3-legged character whose first foot transitions; the needle is stopped."""
    state = init_gaits(([start, 0.0, 0.5], [duration, 0.1, 0.1]), 1, transition_rate=rate)
    set_destination(state, [0], ([dest_start, 0.0, 0.5], [dest_duration, 0.1, 0.1]))
    return state


def run(state, steps, dt, stance=True):
    history = []
    for _ in range(steps):
        advance(state, 0.0, dt, np.full((1, 3), stance))
        history.append((state.disk_start[0, 0], state.disk_duration[0, 0]))
    return np.array(history)


def test_transition_interpolates_linearly_and_snaps():
    state = one_foot(0.1, 0.2, 0.4, 0.3, rate=0.1)  # 0.1 lies in the destination's stance arc [0.7, 0.4)
    history = run(state, 40, 0.1)  # 0.01 cycle per step: 30 steps to go
    k = np.arange(1, 31)
    np.testing.assert_allclose(history[:30, 0], 0.1 + 0.01 * k, atol=1e-12)
    np.testing.assert_allclose(history[:30, 1], 0.2 + 0.1 * (0.01 * k / 0.3), atol=1e-12)
    assert tuple(history[-1]) == (0.4, 0.3) and not state.transitioning().any()
    # a start already in place: the duration alone moves at the transition rate
    state = one_foot(0.4, 0.2, 0.4, 0.3, rate=0.1)
    history = run(state, 12, 0.1)
    np.testing.assert_allclose(history[:10, 1], 0.2 + 0.01 * np.arange(1, 11), atol=1e-12)
    assert history[-1, 1] == 0.3


@pytest.mark.parametrize("start, dest_start, dest_duration, direction, distance", [
    (0.5, 0.4, 0.3, -1, 0.1),    # inside the destination sector: back to its start
    (0.9, 0.1, 0.3, +1, 0.2),    # in the destination's stance arc: forward across 0
    (0.45, 0.1, 0.3, +1, 0.65),  # the short way back would cross the finish 0.4: the long way forward
    (0.8, 0.1, 0.8, -1, 0.7),    # the short way forward would cross the finish 0.9: the long way back
])
def test_transition_direction_avoids_the_destination_finish(start, dest_start, dest_duration, direction, distance):
    state = one_foot(start, 0.2, dest_start, dest_duration, rate=0.01)
    history = run(state, 800, 0.1)  # 0.001 cycle per step
    first = history[0, 0]
    assert wrap(direction * (first - start)) == pytest.approx(0.001, abs=1e-12)
    steps = np.flatnonzero(history[:, 0] == dest_start)[0] + 1
    assert steps == math.ceil(round(distance / 0.001, 6))
    assert on_arc(history[:, 0], start, dest_start, dest_duration).all()


def test_swinging_feet_keep_their_disk():
    state = one_foot(0.1, 0.2, 0.4, 0.3, rate=1.0)
    history = run(state, 10, 0.1, stance=False)
    assert np.all(history == (0.1, 0.2)) and state.transitioning().all()


# --------------------------------------------------------------------------- API, determinism


def test_api_validation():
    gait = load_gait("ant-tripod", "ant")
    state = init_gaits(gait, 3)
    assert state.leg_names == gait.leg_names and state.n_characters == 3 and state.n_legs == 6
    with pytest.raises(ValueError, match="in_stance"):
        advance(state, 1.0, 0.01, np.ones((3, 5), dtype=bool))
    with pytest.raises(ValueError, match="dt"):
        advance(state, 1.0, -0.01, np.ones((3, 6), dtype=bool))
    with pytest.raises(ValueError, match="frequency"):
        advance(state, -1.0, 0.01, np.ones((3, 6), dtype=bool))
    with pytest.raises(ValueError, match="legs"):
        set_destination(state, [0], load_gait("spider-metachronal-wave", "spider"))
    with pytest.raises(ValueError, match="durations must be in"):
        init_gaits(([0.0, 0.5], [0.5, 1.5]), 2)
    with pytest.raises(ValueError, match="n_characters"):
        init_gaits(gait, 0)
    with pytest.raises(ValueError, match="rng_phase_offsets"):
        init_gaits(gait, 2, [0.2, 1.0])
    tetrapod = load_gait("ant-tetrapod", "ant")
    set_destination(state, np.array([False, True, False]), tetrapod)
    np.testing.assert_array_equal(state.transitioning(), [False, True, False])
    set_destination(state, [2, 0], [tetrapod, gait])
    np.testing.assert_array_equal(state.dest_start[2], tetrapod.swing_start)
    mixed = init_gaits([gait, tetrapod, gait], 3, 7)
    np.testing.assert_array_equal(mixed.disk_start[1], tetrapod.swing_start)


def simulate(seed: int) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(seed)
    state, frequency = random_transition_crowd(rng, 6, 20)
    stance = np.ones((20, 6), dtype=bool)
    log = []
    for _ in range(300):
        enter, _ = advance(state, frequency, rng.uniform(0.005, 0.02), stance)
        stance = controller(state, stance, enter)
        log.append(enter.copy())
    return state.needle, state.disk_start, state.disk_duration, np.array(log)


def test_determinism():
    first, second = simulate(11), simulate(11)
    for a, b in zip(first, second):
        np.testing.assert_array_equal(a, b)
    assert not np.array_equal(simulate(12)[1], first[1])
