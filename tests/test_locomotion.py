"""Legs that reach and gaits that change with speed (issue 13): stance windows, the speed cap,
the gait schedule, and what a walking creature realises per stride."""

import math
from pathlib import Path

import numpy as np
import pytest

from footfall.planner._gait_schedule import HYSTERESIS, GaitSchedule
from footfall.planner._ik import legs_of
from footfall.planner._timing import GRAVITY, GaitTiming, stride_length
from footfall.planner._workspace import WINDOW_HEIGHTS, WINDOW_MARGIN, WINDOW_SAMPLES, duty_ceiling, speed_cap, stance_centres, stance_windows
from footfall.scenarios import load_creature

UPRIGHT_LEG = """
name = "stilt"
standing_height = 0.30
body_thickness = 0.05
body_box = [0.4, 0.2]
foot = {{ length = 0.02, width = 0.02 }}

[leg_defaults]
segments = [0.2, 0.2]
joint_limits = [[-3.0, 3.0], [-3.0, 3.0]]

[[legs]]
name = "A"
hip = [0.1, 0.0, 0.1]
rest_foot = [0.1, 0.1]

[[legs]]
name = "B"
hip = [-0.1, 0.0, 0.1]
rest_foot = [-0.1, 0.1]

[[legs]]
name = "C"
hip = [0.0, 0.0, -0.1]
rest_foot = [0.0, -0.1]
"""


def test_the_stance_window_of_an_upright_two_segment_leg_is_its_reach_circle(tmp_path):
    # A foot straight under its hip, free azimuth, joints free: the leg reaches a ground point at
    # forward offset x when x^2 + d^2 <= (0.2 + 0.2)^2, d the depth below the hip. The window must
    # hold at the deepest height of WINDOW_HEIGHTS: d = 0.30 * (1 + 0.05) = 0.315, so
    # |x| <= sqrt(0.16 - 0.099225) = 0.24652; less the margin at each end.
    path = tmp_path / "stilt.toml"
    path.write_text(UPRIGHT_LEG.format())
    creature = load_creature(path)
    rest = np.asarray(creature.rest_feet)
    windows = stance_windows(creature, rest, np.asarray(creature.hips), legs_of(creature))
    depth = 0.30 * 1.05
    half = math.sqrt(0.4**2 - depth**2)
    step = 2 * 0.4 / (WINDOW_SAMPLES - 1)  # the sampling resolution of a window's ends
    for leg in range(3):
        lo, hi = windows[leg]
        length = hi - lo
        raw = length / (1.0 - 2 * WINDOW_MARGIN)
        assert abs(raw - 2 * half) <= 2 * step, (leg, raw, 2 * half)
        assert abs(0.5 * (lo + hi) - rest[leg, 0]) <= step, (leg, lo, hi)


def test_stance_centres_keep_the_sweep_inside_the_window():
    windows = np.array([[-0.3, 0.3], [-0.3, 0.3], [-0.1, 0.1], [0.0, 0.2]])
    rest = np.array([0.0, -0.28, 0.0, 0.19])
    sweep = np.array([0.2, 0.2, 0.3, 0.1])
    # free room 0.4 -> slack 0.04 at each end: centre in [-0.3 + 0.1 + 0.04, 0.3 - 0.1 - 0.04] = [-0.16, 0.16]
    # a sweep longer than its window: the window's middle; free room 0.1 -> slack 0.01: [0.06, 0.14]
    np.testing.assert_allclose(stance_centres(rest, windows, sweep), [0.0, -0.16, 0.0, 0.14])


def test_the_speed_cap_is_where_the_least_duty_factor_just_fits():
    timing = GaitTiming()
    for h, window in ((0.12, 0.1), (0.42, 0.3), (0.05, 0.04)):
        v = speed_cap(timing, h, window)
        sweep = timing.duty_min * stride_length(timing, v, h)
        assert sweep == pytest.approx(window, rel=1e-12)
        assert timing.duty_min * stride_length(timing, 1.01 * v, h) > window
    np.testing.assert_array_equal(duty_ceiling(0.3, [0.0, 0.6, 0.3]), [np.inf, 0.5, 1.0])


def _gait(name, starts):
    from types import SimpleNamespace

    return SimpleNamespace(name=name, leg_names=("a", "b", "c", "d"), swing_start=starts, swing_duration=[0.25] * 4)


def test_the_schedule_moves_up_and_down_with_hysteresis():
    schedule = GaitSchedule((_gait("walk", [0, .25, .5, .75]), _gait("trot", [0, .5, .5, 0]),
                             _gait("gallop", [0, .1, .5, .6])), (0.3, 1.0))
    current = np.array([0, 0, 1, 1, 1, 2, 2, 0])
    froude = np.array([0.29, 0.31, 0.25, HYSTERESIS * 0.3 - 1e-9, 1.2, 0.9, 0.79, 2.0])
    # 0: stays walk; 1: up to trot; 2: inside the hysteresis band, stays trot; 3: just below 0.24,
    # back to walk; 4: up to gallop; 5: stays gallop (0.9 > 0.8); 6: below 0.8, down to trot;
    # 7: walk at Fr 2 goes up two gaits in one call.
    np.testing.assert_array_equal(schedule.select(current, froude), [0, 1, 1, 0, 2, 2, 1, 2])
    np.testing.assert_array_equal(schedule.initial(np.sqrt(np.array([0.1, 0.5, 3.0]) * GRAVITY * 0.5), 0.5),
                                  [0, 1, 2])
    with pytest.raises(ValueError, match="froude_up"):
        GaitSchedule((_gait("walk", [0, .25, .5, .75]), _gait("trot", [0, .5, .5, 0])), (0.5, 0.6))


# --------------------------------------------------------------------------- what a walker realises
# Every built-in creature at three speeds spanning its range (Froude numbers 0.05, 0.2, 0.5), one
# character on flat ground from a fresh start; fixed seeds plus a fresh one each session
# (conftest.fresh_seeds; a seed that ever failed joins FIXED_SEEDS). Issue 13's bars per stride:
# on flat median <= 5 %, p90 <= 15 %, the asked speed reached within 5 %; on hills median <= 10 %,
# p90 <= 25 %. (The tightest, the spider at Fr 0.2 on flat, reaches 97.7-98.8 % over seeds 0-5.)
from conftest import fresh_seeds  # noqa: E402

FIXED_SEEDS = (0, 1)
HILLS_SEEDS = (964266667, 0, 2, 5)  # every seed that failed (robot5 at Fr 0.05, p90 bar)
FROUDE = (0.05, 0.2, 0.5)
FLAT_BARS = dict(median=0.05, p90=0.15, reached=0.95)
HILLS_BARS = dict(median=0.10, p90=0.25)


def _walk(creature_name, scenario_name, froude, seed, frames=300):
    from footfall.planner._crowd import init_crowd
    from footfall.planner._simulation import simulate
    from footfall.planner._timing import hip_height
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_schedule import gait_schedule

    creature = load_creature(creature_name)
    speed = math.sqrt(froude * GRAVITY * hip_height(creature))
    scenario = load_scenario(f"{scenario_name}@crowd.speed={speed:.5f}")
    model, state = init_crowd(scenario, creature, gait_schedule(creature), n_characters=1, seed=seed)
    return simulate(model, state, frames)


@pytest.mark.slow
@pytest.mark.parametrize("creature_name", ("spider", "ant", "quadruped", "robot5"))
def test_every_creature_walks_its_speed_range_on_flat_ground(creature_name):
    for seed in fresh_seeds(FIXED_SEEDS, 1, salt=sum(map(ord, creature_name))):
        for froude in FROUDE:
            s = _walk(creature_name, "flat", froude, seed)
            where = f"{creature_name} at Fr {froude}, seed {seed}: {s}"
            goal = min(s.speed_asked, s.speed_cap or math.inf)
            assert s.strides_measured >= 10, where
            assert s.stride_rel_error_median <= FLAT_BARS["median"], where
            assert s.stride_rel_error_p90 <= FLAT_BARS["p90"], where
            assert s.speed_reached >= FLAT_BARS["reached"] * goal, where
            assert s.ik_residual_p95_m <= 2e-3, where
            assert s.max_stance_slip_m <= 1e-3, where


@pytest.mark.slow
@pytest.mark.parametrize("creature_name, froude", [(c, f) for c in ("spider", "ant", "quadruped", "robot5") for f in FROUDE])
def test_every_creature_walks_its_speed_range_on_hills(creature_name, froude):
    # Up and across the slopes of `hills`: strides follow the law, legs reach their feet, stance feet
    # stay put. (robot5 at Fr 0.05 used to crawl up at 57 % of its speed, strides 33-61 % off at p90:
    # a one-frame rise of the pelvis carried over the whole look-ahead held the body, and front feet
    # just landed ahead of a slowed body were forced to step again. On seed 964266667 it kept p90 26 %:
    # the uphill feet's own cells lay beyond the flat reach, and they landed a cell short, then long.)
    for seed in fresh_seeds(HILLS_SEEDS, 1, salt=7 * sum(map(ord, creature_name))):
        s = _walk(creature_name, "hills", froude, seed)
        where = f"{creature_name} on hills at Fr {froude}, seed {seed}: {s}"
        assert s.strides_measured >= 10, where
        assert s.stride_rel_error_median <= HILLS_BARS["median"], where
        assert s.stride_rel_error_p90 <= HILLS_BARS["p90"], where
        assert s.ik_residual_p95_m <= 2e-3, where
        assert s.max_stance_slip_m <= 1e-3, where


def test_duty_factor_falls_with_speed_and_the_quadruped_trots_when_fast():
    slow, fast = _walk("quadruped", "flat", 0.05, 0), _walk("quadruped", "flat", 0.5, 0)
    assert slow.duty_factor_mean > fast.duty_factor_mean >= 0.5 - 1e-9  # biomechanics: walk DF > 0.5
    assert slow.gait_fractions["quadruped-walk"] == 1.0
    assert fast.gait_fractions["quadruped-trot"] > 0.9


CREATURES = Path(__file__).parent / "data" / "creatures"  # creatures no built-in scenario names
BEETLE = CREATURES / "beetle.toml"
OFF_PREFERRED_M = 0.005  # a new swing's footprint this far from its preferred one counts as moved off it
OFF_PREFERRED_SHARE = 0.05  # on flat ground at most this share of new swings moves off (spider 2 %, ant 0 %)


def test_a_small_creature_alone_on_flat_ground_lands_on_its_preferred_footprints():
    # One creature walking straight on flat ground, nothing near: the preferred footprint (the stride law's)
    # is free, and each new swing should land there. The built-in creatures do (1 x 120 frames, seeds 0-2:
    # spider 2 % of new swings more than 5 mm off, robot5 2 %, ant and quadruped 0 %). The beetle, a
    # creature no session had tuned for, did not while the scoring's reference scales were the spider's
    # metres (16 %: its strides snapped to its 3 cm cells, the 7 cm clearance scale outvoting the distance
    # to the preferred footprint); with them sized to the creature (planner.default_weights) it does.
    import footfall.planner._crowd as crowd
    from footfall.planner import layout
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    scenario, creature = load_scenario("flat"), load_creature(str(BEETLE))
    gait, _, _ = resolve_gait(None, creature)
    off = []
    for seed in range(3):
        model, state = crowd.init_crowd(scenario, creature, gait, n_characters=1, seed=seed)
        for frame in range(120):
            plans = crowd.step(model, state).plans
            if plans is None or plans.batch is None or frame < 10:  # the first steps leave the spawn's pose
                continue
            new = plans.kinds == layout.KIND_NEW_SWING
            target, preferred = plans.result.target[new], plans.batch.preferred[new]
            off.extend(np.hypot(target[:, 0] - preferred[:, 0], target[:, 2] - preferred[:, 1]))
    off = np.array(off)
    assert off.size > 100, "the premise: the beetle walks and steps"
    share = float((off > OFF_PREFERRED_M).mean())
    assert share <= OFF_PREFERRED_SHARE, f"{share:.0%} of {off.size} new swings land over 5 mm off; largest {off.max():.4f} m"


LONE_STRIDE_TOLERANCE = 0.002  # a stride this close to the law counts as on it (rounding, not a frame)
LONE_WARM_UP_FRAMES = 60  # the first strides speed up from the spawn's standstill


@pytest.mark.parametrize("name", ("spider", str(BEETLE)))
def test_a_lone_walker_s_footprints_are_a_whole_cycle_apart_whatever_frame_each_foot_lifts_on(name):
    # One creature walking straight on flat ground at its asked speed: once up to speed, every stride it
    # measures is the stride law's, on each foot and each cycle. A foot lifts on the first frame past the
    # instant the gait's needle enters its sector; timed from that frame, consecutive footprints were 0 to 1 frame's travel
    # more or less than a cycle apart (the spider's strides 0.9 % off the law at the median, 3 % at p90;
    # the beetle's, a cycle of 12.7 frames, 3.6 % and 5.7 %). They are timed from the instant
    # (planner._crowd.lift_lateness).
    from footfall.planner._crowd import init_crowd
    from footfall.planner._simulation import StrideMeter, simulate
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    creature = load_creature(name)
    gait, _, _ = resolve_gait(None, creature)
    for seed in fresh_seeds(FIXED_SEEDS, 1, salt=11 * sum(map(ord, creature.name))):
        model, state = init_crowd(load_scenario("flat"), creature, gait, n_characters=1, seed=seed)
        errors = []
        update = StrideMeter.update

        def measured(meter, k, st, landed):
            before = len(meter.errors)
            update(meter, k, st, landed)
            if k >= LONE_WARM_UP_FRAMES:
                errors.extend(meter.errors[before:])

        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(StrideMeter, "update", measured)
            summary = simulate(model, state, 300)
        errors = np.concatenate(errors)
        where = f"{creature.name}, seed {seed}: {errors.size} strides, largest error {errors.max():.4f}"
        assert errors.size >= 100 and summary.speed_reached > 0.99 * summary.speed_asked, where
        assert errors.max() <= LONE_STRIDE_TOLERANCE, where


def test_a_lift_s_lateness_is_the_part_of_a_frame_since_the_needle_entered_its_sector():
    # By hand: a spider's needle 0.01 of a cycle past leg 2's sector start, at 1 Hz: 10 ms late; at 0.5 Hz
    # 20 ms; entered 0.1 s ago (at 0.1 Hz), more than a frame: an earlier frame's, so 0 (a lift that waited).
    from footfall.planner._crowd import DT, init_crowd, lift_lateness
    from footfall.scenarios import default_gait, load_scenario

    spider = load_creature("spider")
    model, state = init_crowd(load_scenario("flat"), spider, default_gait(spider), n_characters=2)
    state.gaits.needle[:] = state.gaits.disk_start[:, 2] + 0.01
    late = lift_lateness(model, state, np.array([0, 1, 0]), np.array([2, 2, 2]), np.array([1.0, 0.5, 0.1]))
    np.testing.assert_allclose(late, [0.01, 0.02, 0.0], rtol=0, atol=1e-12)
    assert DT > 0.02
    none = lift_lateness(model, state, np.array([0]), np.array([2]), np.array([0.0]))  # a needle standing still
    assert none.tolist() == [0.0]


MITE = CREATURES / "mite.toml"


def test_a_tiny_creature_is_capped_to_a_gait_the_frames_can_draw():
    # A 3 cm mite asked the scenarios' 0.3 m/s would step at 11.8 Hz, a stride cycle of 2.5 frames: its
    # swings last under a frame and its legs are drawn across each other (six mites, 300 frames on flat:
    # 65 crossing frames over seeds 13000-13004). Capped where a cycle lasts 4 frames (0.097 m/s): none.
    import footfall.planner._workspace as workspace
    from footfall.planner import GaitTiming, hip_height, stride_frequency
    from footfall.planner._crowd import DT, init_crowd
    from footfall.planner._simulation import simulate
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    mite = load_creature(str(MITE))
    gait, _, _ = resolve_gait(None, mite)
    model, state = init_crowd(load_scenario("flat"), mite, gait, n_characters=6, seed=1)
    f = stride_frequency(GaitTiming(), model.speed_cap, hip_height(mite))
    assert model.speed_cap < 0.3 and f * DT * workspace.MIN_CYCLE_FRAMES == pytest.approx(1.0)
    summary = simulate(model, state, 150)
    assert summary.leg_crossings == 0 and summary.speed_reached > 0.9 * model.speed_cap
    assert summary.stride_rel_error_p90 < 0.25


GIANT = CREATURES / "giant.toml"


def test_a_creature_too_large_for_the_papers_maps_gets_maps_that_hold_it():
    # The crab at 1.5 times its size plans its feet up to 2.02 m from its centre: with the paper's 70 x 70
    # maps of 7 cm (2.45 m either side, less the margin) init_crowd refused it; its maps now have 74 cells.
    from footfall import InputError
    from footfall.planner import PlannerConfig, planner_config_for
    from footfall.planner._crowd import init_crowd, planning_span
    from footfall.planner._simulation import simulate
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    giant = load_creature(str(GIANT))
    config = planner_config_for(giant)
    span = planning_span(giant, config)
    assert config.map_cells == 74 and config.cell_size == 0.07
    assert span + 8 * 0.07 <= 0.5 * 74 * 0.07 < span + 8 * 0.07 + 0.07  # the fewest even cells that hold it
    gait, _, _ = resolve_gait(None, giant)
    with pytest.raises(InputError, match="too large for its 70 x 70 local map"):
        init_crowd(load_scenario("flat"), giant, gait, n_characters=1, config=PlannerConfig())
    model, state = init_crowd(load_scenario("crates"), giant, gait, n_characters=2, seed=0)
    summary = simulate(model, state, 60)
    assert summary.finite and summary.collisions == 0 and summary.leg_crossings == 0 and summary.steps > 0


DENSE8 = CREATURES / "dense8.toml"


def test_a_creature_s_cells_leave_room_between_its_nearest_feet():
    # dense8's nearest rest feet are 2.1 cm apart: a quarter of its rest radius (2 cm cells) put them a
    # cell apart, and the other legs' rooms blocked the cells round each footprint (alone on flat, seed
    # 13200: 77 holds, per-stride p90 0.90). Its cells are now 5 mm (MIN_CELL_M; 1 cm, the floor until
    # session 64, left 2.1 cells between those feet); the built-in creatures' are what a quarter of their
    # rest radius gives (their feet are 2.6-6.7 of those cells apart).
    from footfall.planner import planner_config_for
    from footfall.planner._crowd import FOOT_GAP_CELLS, MIN_CELL_M, init_crowd
    from footfall.planner._simulation import simulate
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    cells = {name: planner_config_for(load_creature(name)).cell_size for name in ("spider", "ant", "quadruped", "robot5")}
    assert cells == {"spider": 0.07, "ant": 0.04, "quadruped": 0.07, "robot5": 0.07}
    dense = load_creature(str(DENSE8))
    feet = np.asarray(dense.rest_feet)
    gap = min(np.hypot(*(a - b)) for i, a in enumerate(feet) for b in feet[i + 1:])
    assert planner_config_for(dense).cell_size == MIN_CELL_M == 0.005 and gap / MIN_CELL_M >= FOOT_GAP_CELLS
    gait, _, _ = resolve_gait(None, dense)
    model, state = init_crowd(load_scenario("flat"), dense, gait, n_characters=1, seed=13200)
    summary = simulate(model, state, 150)
    assert summary.holds < 20 and summary.leg_crossings == 0


SPLAY8 = CREATURES / "splay8.toml"


@pytest.mark.parametrize("name", ["splay8", "dense8"])
def test_dense_legs_walk_no_faster_than_their_feet_keep_clear_of_their_neighbours(name):
    # Legs 4-7 cm apart along a side (splay8) or 2-3 cm (dense8), whose stride law asks longer stance
    # sweeps: a hind foot landed in front of the next leg's line and the legs were drawn across each
    # other (four splay8 on flat, seed 2, 150 frames: 39 crossing frames, 15 holds). Capped where a sweep
    # first reached a neighbour's territory (planner._workspace.territory_speed_cap, 0.09 m/s), the legs
    # were drawn apart, but a rear foot's landing spot still stood within a foot's room of its front
    # neighbour's, about to lift: refused or scored down, it landed 1.3-2.9 cm short of 5 cm strides
    # (per-stride p90 0.28-0.69). The speed is now capped where the steady landing and lift-off spots
    # keep a foot's room (neighbour_speed_cap; from the other leg's line too since session 67), and the
    # leg-spacing reference is no more than the room they leave, and a foot's room (planner._workspace.leg_room).
    from footfall.planner import default_weights
    from footfall.planner._crowd import DT, ESCAPE_FROUDE, init_crowd
    from footfall.planner._kernels_foot import LEG_CLEARANCE
    from footfall.planner._simulation import simulate
    from footfall.planner._timing import hip_height
    from footfall.planner._workspace import leg_room, neighbour_gaps, neighbour_speed_cap, speed_caps
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    creature = load_creature(str(SPLAY8 if name == "splay8" else DENSE8))
    gait, _, _ = resolve_gait(None, creature)
    model, state = init_crowd(load_scenario("flat"), creature, gait, n_characters=4, seed=2)
    h, room = hip_height(creature), creature.foot_room
    caps = speed_caps(model.timing, h, model.rest_body, model.hips_body, model.stance_window, DT, room)
    assert model.speed_cap_reason == "neighbours" and model.speed_cap == caps["neighbours"] < caps["territories"] < 0.1
    # At the cap the spots keep a foot's room from each other and from the other leg; a tenth faster they do not.
    geometry = (model.timing, h, model.rest_body, model.hips_body, model.stance_window)
    feet, legs = neighbour_gaps(*geometry, [model.speed_cap, 1.1 * model.speed_cap])
    assert feet[0] >= room and legs[0] >= room
    assert feet[1] < room or legs[1] < room
    # The leg-spacing reference: the room the law leaves at the walk, under the size-scaled default.
    scaled = default_weights(creature.rest_radius).leg_spacing_ref_m
    assert model.weights.leg_spacing_ref_m == leg_room(*geometry, model.speed_cap, room, DT) < 0.6 * scaled
    # It flees no faster than keeps every law's spot allowed (half a room from the other leg), above its walk.
    others = min(v for reason, v in caps.items() if reason != "neighbours")
    flee = min(others, neighbour_speed_cap(*geometry, others, room, LEG_CLEARANCE))
    assert model.top_speed == min(flee, math.sqrt(ESCAPE_FROUDE * GRAVITY * h)) and flee > model.speed_cap
    summary = simulate(model, state, 150)
    assert summary.leg_crossings == 0 and summary.holds <= 2
    assert summary.speed_reached > 0.9 * model.speed_cap  # measured 1.0 (both)
    # Strides on the law: the median under the flat-ground bar of footfall evaluate (5 %); measured
    # 0.012-0.014 (splay8) and 0.039 (dense8), seeds 2-4; at the territory cap 0.11-0.12 and 0.076
    # (footfall evaluate flat, 4 characters x 300 frames, seeds 13000-13001).
    assert summary.stride_rel_error_median < 0.05


@pytest.mark.parametrize("name", ["tall8", "wave6"])
def test_a_dense_walker_at_its_neighbour_cap_takes_the_stride_law_s_strides(name):
    # Random 8- and 6-legged creatures (rest feet 8-12 cm apart along a side) walked at their neighbour caps,
    # alone on flat ground: their rear feet landed a cell short of the stride law, then long (per-stride
    # median 0.02-0.06, p90 0.26-0.36, seeds 0-2). Two causes: the cap kept half a foot's room between a
    # landing spot and the other leg, where the leg-spacing goodness asks a whole one, so the law's own spot
    # scored half on leg spacing and a spot a cell short won (planner._workspace.neighbour_speed_cap); and a
    # front foot that lifts a few hundredths of a cycle before its rear neighbour lands was counted as
    # standing at that touchdown, nearer the rear leg than it ever stands (planner._crowd.lifted_before).
    # Measured with both, seeds 0-5: median 0 (every run), p90 0-0.12 (tall8) and 0-0.05 (wave6). Once up to
    # speed, new swings more than 5 mm off their preferred footprints: tall8 3 % (9-14 % counting the feet
    # that lift first as standing), wave6 0-2 %.
    import footfall.planner._simulation as simulation
    from footfall.planner import layout
    from footfall.planner._crowd import init_crowd
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    creature = load_creature(str(CREATURES / f"{name}.toml"))
    gait, _, _ = resolve_gait(None, creature)
    for seed in fresh_seeds(FIXED_SEEDS, 1, salt=13 * sum(map(ord, name))):
        model, state = init_crowd(load_scenario("flat"), creature, gait, n_characters=1, seed=seed)
        assert model.speed_cap_reason == "neighbours", "the premise: it walks at its neighbour cap"
        off = []
        step = simulation.step

        def planned(model, state):
            record = step(model, state)
            plans = record.plans
            if plans is not None and plans.batch is not None and state.frame > LONE_WARM_UP_FRAMES:
                new = plans.kinds == layout.KIND_NEW_SWING
                target, preferred = plans.result.target[new], plans.batch.preferred[new]
                off.extend(np.hypot(target[:, 0] - preferred[:, 0], target[:, 2] - preferred[:, 1]))
            return record

        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(simulation, "step", planned)
            s = simulation.simulate(model, state, 300)
        off = np.array(off)
        where = (f"{name}, seed {seed}: {s.strides_measured} strides, median {s.stride_rel_error_median}, p90 "
                 f"{s.stride_rel_error_p90}; {(off > OFF_PREFERRED_M).mean():.0%} of {off.size} new swings off")
        assert s.strides_measured >= 40 and s.speed_reached >= FLAT_BARS["reached"] * model.speed_cap, where
        assert s.stride_rel_error_median <= 0.01, where
        assert s.stride_rel_error_p90 <= FLAT_BARS["p90"], where
        assert off.size >= 40 and (off > OFF_PREFERRED_M).mean() <= OFF_PREFERRED_SHARE, where


def test_a_foot_that_lifts_before_another_lands_stands_nowhere_at_that_touchdown():
    # By hand: a spider walking at 2 Hz, its needle at 0. Leg 1's sector starts at 0.1 of a cycle (it lifts
    # in 0.05 s, on the frame after: 0.05 + 1/30 = 0.083 s), leg 2's at 0.5 (0.283 s); leg 3 is in the air.
    # For a foot landing in 0.1 s, leg 1 is gone (both its rows: at touchdown, then now), leg 2 still
    # stands, leg 3 is no standing foot; landing in 0.05 s, every foot that stands now still stands then.
    from footfall.planner._crowd import DT, init_crowd, lifted_before
    from footfall.scenarios import default_gait, load_scenario

    spider = load_creature("spider")
    model, state = init_crowd(load_scenario("flat"), spider, default_gait(spider), n_characters=1)
    state.gaits.needle[:] = 0.0
    state.gaits.disk_start[0, 1:4] = [0.1, 0.5, 0.7]
    state.stride_frequency[:] = 2.0
    state.speed[:] = 0.3
    state.in_stance[:] = True
    state.in_stance[0, 3] = False
    state.wants_swing[:] = False
    state.sector_missed[:] = False
    cs, others = np.array([0, 0]), np.array([[1, 2, 3], [1, 2, 3]])
    assert 0.05 + DT < 0.1 < 0.25 + DT
    gone = lifted_before(model, state, cs, others, np.array([0.1, 0.05]))
    assert gone.tolist() == [[True, False, False, True, False, False], [False] * 6]
    # Only a lift the walk makes sure of: none while the body stands (its needle stops) or is held, nor for
    # a foot already waiting for a footprint.
    for stands in ("speed", "body_held", "wants_swing"):
        saved = getattr(state, stands).copy()
        getattr(state, stands)[:] = 0.0 if stands == "speed" else True
        assert not lifted_before(model, state, cs, others, np.array([0.1, 0.05])).any(), stands
        getattr(state, stands)[:] = saved


def test_a_swing_planned_on_a_lift_that_does_not_come_plans_again():
    # wave6 at its neighbour cap: a new swing leaves out the feet that lift before it lands (lifted_before) and
    # says which (CrowdState.counted_gone). If one of them still stands, waiting since an earlier frame for a
    # footprint of its own, or held by a body that stopped, the swing plans again with it standing: a rear foot
    # of a random 6-legged creature on `crates` landed across its front neighbour's leg, which lifted 10 frames
    # late.
    import copy

    import footfall.planner._crowd as crowd
    from footfall.planner.layout import KIND_REPLAN
    from footfall.scenarios import load_scenario
    from footfall.scenarios._gait_choice import resolve_gait

    creature = load_creature(str(CREATURES / "wave6.toml"))
    gait, _, _ = resolve_gait(None, creature)
    model, state = crowd.init_crowd(load_scenario("flat"), creature, gait, n_characters=1, seed=0)
    assert crowd.at_neighbour_cap(model)
    for _ in range(200):
        crowd.step(model, state)
        swinging = ~state.in_stance[0]
        counted = state.counted_gone[0] & swinging[:, None] & state.in_stance[0][None, :]
        if counted.any():
            break
    leg, other = map(int, np.argwhere(counted)[0])
    assert state.swing_T[0, leg] - state.swing_t[0, leg] > 3 * model.dt, "the premise: the swing is not landing"

    def kinds_next_frame(waits):
        s = copy.deepcopy(state)
        s.wants_swing[0, other] = waits  # asked for its swing on an earlier frame, and still standing
        boxes = crowd._boxes_now(model, s.t)
        frequency, enter, _ = crowd.stage_gait(model, s)
        hips = crowd.hips_world(model, s)
        return crowd.stage_requests(model, s, enter, boxes, hips, frequency)

    assert kinds_next_frame(True)[0, leg] == KIND_REPLAN
    assert kinds_next_frame(False)[0, leg] != KIND_REPLAN


def test_a_stance_foot_that_slows_the_turn_of_a_body_at_its_pace_waits_for_its_sector_near_a_moving_box_too(
        monkeypatch):
    # A stance foot that bounds the turn asked to under half of it steps out of turn only for a slow body (it turns
    # on the spot by stepping); a body at its pace turns as its feet lift in their sectors. Counted slow near a
    # moving box as well, a quadruped walking at 0.27 m/s beside a crate stepped its just-landed feet again a few
    # frames later: strides 30-50 % short, its run over the per-stride bar (crates-moving, seed 20019, character 5).
    import copy

    import footfall.planner._crowd as crowd
    from footfall.planner.layout import KIND_FORCED_STEP, KIND_NONE
    from footfall.scenarios import default_gait, load_scenario

    quadruped = load_creature("quadruped")
    model, state = crowd.init_crowd(load_scenario("flat"), quadruped, default_gait(quadruped), n_characters=1, seed=0)
    for _ in range(60):
        crowd.step(model, state)
    while state.in_stance.sum() < 3:  # a leg to spare for a forced step
        crowd.step(model, state)
    foot = int(np.flatnonzero(state.in_stance[0])[0])
    # Every stance foot allows 0.007 rad of the 0.026 rad turn asked (under half of it).
    monkeypatch.setattr(crowd, "leg_turn_bounds", lambda m, s, lift=None: np.where(s.in_stance, -0.007, np.nan))

    def kind(speed, crate_at):
        s = copy.deepcopy(state)
        s.speed[:] = speed
        boxes = crowd._boxes_now(model, s.t)
        if crate_at is not None:  # a moving crate crate_at m ahead of the pelvis
            centre = s.pelvis[0] + [crate_at, 0.0, 0.0]
            boxes = (centre[None], np.array([[0.4, 0.3, 0.4]]), np.zeros(1), np.ones(1, np.bool_), np.ones(1, np.bool_))
            assert crowd.moving_box_near(model, s, boxes)[0]
        frequency, enter, _ = crowd.stage_gait(model, s)
        s.turn_wanted[:] = -0.026
        return int(crowd.stage_requests(model, s, enter, boxes, crowd.hips_world(model, s), frequency)[0, foot])

    pace = float(state.goal_speed[0])
    assert kind(0.3 * pace, None) == KIND_FORCED_STEP
    assert kind(0.3 * pace, 0.8) == KIND_FORCED_STEP
    assert kind(pace, None) == KIND_NONE
    assert kind(pace, 0.8) == KIND_NONE


def test_neighbour_gaps_of_two_legs_by_hand():
    """Two legs on the left, hips at (0.01, 0.01) and (-0.01, 0.01), rest feet at (0.02, 0.05) and
    (-0.02, 0.05), windows of +-3 cm round them. Standing (no sweep): the feet 4 cm apart; the rear foot
    to the front leg's line, hip to foot (0.01, 0.04): the foot of the perpendicular at t = 1.3 / 1.7,
    distance sqrt(0.037647^2 + 0.009412^2) = 0.038806 (the same the other way round, by symmetry). A
    sweep s centred on the rest feet brings the facing ends s nearer: 0.04 - s."""
    from footfall.planner._timing import duty_factor, stride_length
    from footfall.planner._workspace import neighbour_gaps, side_neighbours

    rest = np.array([[0.02, 0.05], [-0.02, 0.05], [0.0, -0.05]])
    hips = np.array([[0.01, 0.0, 0.01], [-0.01, 0.0, 0.01], [0.0, 0.0, -0.01]])
    windows = rest[:, :1] + np.array([[-0.03, 0.03]])
    assert side_neighbours(rest, hips) == [(0, 1)]  # the right leg has no neighbour
    feet, legs = neighbour_gaps(GaitTiming(), 0.025, rest, hips, windows, [0.0, 0.2])
    sweep = float(duty_factor(GaitTiming(), 0.2, 0.025) * stride_length(GaitTiming(), 0.2, 0.025))
    np.testing.assert_allclose(feet, [0.04, 0.04 - sweep], rtol=0, atol=1e-12)
    assert legs[0] == pytest.approx(0.038806, abs=1e-6)
    # A front foot lifting late (at 0.2 m/s, a frame of 1/30 s: 6.7 mm further back) comes that much nearer.
    late, _ = neighbour_gaps(GaitTiming(), 0.025, rest, hips, windows, [0.2], 1 / 30)
    assert late[0] == pytest.approx(0.04 - sweep - 0.2 / 30, abs=1e-12)
    # No neighbours: no gap.
    assert all(np.isinf(a).all() for a in neighbour_gaps(GaitTiming(), 0.025, rest[2:], hips[2:], windows[2:], [0.2]))