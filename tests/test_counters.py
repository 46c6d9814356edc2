"""Every safety counter reads a known non-zero value on a hand-made failure, and zero once the
failure is fixed; counters measure the rendered pose (issue 20, item 2)."""

import numpy as np
import pytest

from footfall.planner._counters import FrameCounters
from footfall.planner._crowd import init_crowd, stage_ik
from footfall.scenarios import load_creature, load_scenario
from footfall.scenarios._gait_schedule import gait_schedule


def _standing(scenario="crates", creature="spider"):
    s, c = load_scenario(scenario), load_creature(creature)
    model, state = init_crowd(s, c, gait_schedule(c), n_characters=2, seed=0)
    return model, state


def test_a_foot_inside_a_forbidden_box_is_one_collision_per_frame():
    model, state = _standing()
    counters = FrameCounters(model, state)
    counters.update(state)
    assert counters.collisions == 0
    # The hand-placed forbidden crate of `crates` stands at (-2.0, 0.1), 0.4 x 0.5 m, 0.3 m high.
    state.feet[1, 3] = (-2.0, 0.05, 0.1)
    state.ik_on[1] = False  # drawn where planned
    counters.update(state)
    assert counters.collisions == 1
    # Rendered, not planned: the IK puts the foot there too (the leg reaches as far as it can).
    state.ik_on[1] = True
    state.fk_feet[1, 3] = (-2.0, 0.05, 0.1)
    state.feet[1, 3] = (5.0, 0.0, 5.0)
    counters.update(state)
    assert counters.collisions == 2
    state.fk_feet[1, 3] = state.feet[1, 3]
    counters.update(state)
    assert counters.collisions == 2  # fixed: no more


def test_a_foot_standing_on_a_safe_box_is_no_collision_and_one_sunk_into_it_is():
    model, state = _standing()
    obs = model.raster.obstacles
    safe = int(np.flatnonzero(~np.asarray(obs.forbidden) & np.asarray(obs.is_static))[0])
    centre, size = np.asarray(obs.centres[safe]), np.asarray(obs.sizes[safe])
    top = centre[1] + 0.5 * size[1]
    counters = FrameCounters(model, state)
    state.ik_on[1] = True
    # Rendered within the IK's tolerance of a planned foot on the top (measured 6-18 um low): it stands on it.
    state.fk_feet[1, 3] = (centre[0], top - 20e-6, centre[2])
    counters.update(state)
    assert counters.collisions == 0
    state.fk_feet[1, 3] = (centre[0], top - 1e-3, centre[2])  # 1 mm into the box
    counters.update(state)
    assert counters.collisions == 1


def test_two_legs_whose_feet_swap_sides_cross_once():
    model, state = _standing("flat")
    counters = FrameCounters(model, state)
    counters.update(state)
    assert counters.leg_crossings == 0
    # Swap the feet of two neighbouring legs (L1, L2) of character 0 and let the IK place them:
    # their hip -> foot projections now cross each other and nothing else.
    state.feet[0, [0, 1]] = state.feet[0, [1, 0]]
    stage_ik(model, state, np.ones(2, np.bool_))
    assert np.all(state.residual[0, :2] < 1e-3)
    counters.update(state)
    assert counters.leg_crossings == 1
    state.feet[0, [0, 1]] = state.feet[0, [1, 0]]
    stage_ik(model, state, np.ones(2, np.bool_))
    counters.update(state)
    assert counters.leg_crossings == 1


def test_a_stance_foot_creeping_slowly_is_caught_against_its_touch_down_point():
    model, state = _standing("flat")
    counters = FrameCounters(model, state)
    # 0.1 mm per frame: no single frame moves 1 mm, 20 frames move 2 mm from the touch-down point.
    for _ in range(20):
        state.feet[0, 2, 0] += 1e-4
        state.fk_feet[0, 2, 0] += 1e-4
        counters.update(state)
    assert counters.max_stance_slip_m == pytest.approx(2e-3, rel=1e-9)
    # A foot that lifts and lands elsewhere does not slip.
    fresh = FrameCounters(model, state)
    state.in_stance[0, 2] = False
    fresh.update(state)
    state.feet[0, 2, 0] += 0.1
    state.fk_feet[0, 2, 0] += 0.1
    state.in_stance[0, 2] = True
    fresh.update(state)
    fresh.update(state)
    assert fresh.max_stance_slip_m == 0.0


def test_a_pelvis_dropping_in_one_frame_is_its_largest_jump():
    model, state = _standing("flat")
    counters = FrameCounters(model, state)
    state.pelvis[1, 1] -= 0.5  # before the first frame drawn: no jump
    counters.update(state)
    for _ in range(20):  # 1 mm a frame: 20 mm lower, no frame jumps more than 1 mm
        state.pelvis[0, 1] -= 1e-3
        counters.update(state)
    assert counters.max_pelvis_jump_m == pytest.approx(1e-3, rel=1e-9)
    state.pelvis[1, 1] += 0.03
    counters.update(state)
    state.pelvis[1, 1] -= 0.01
    counters.update(state)
    assert counters.max_pelvis_jump_m == pytest.approx(0.03, rel=1e-9)


def test_a_target_out_of_reach_shows_in_the_ik_residual():
    model, state = _standing("flat")
    counters = FrameCounters(model, state)
    counters.update(state)
    assert counters.ik_residual_p95() < 1e-4
    reach = float(model.reach[0])
    state.feet[:, :, 1] -= 2.0 * reach  # every foot two reaches below its hip
    stage_ik(model, state, np.ones(2, np.bool_))
    counters.update(state)
    assert counters.ik_residual_p95() > reach  # p95 over both frames' legs: half of them are this far


def test_two_bodies_on_one_spot_overlap_once_per_frame_and_share_their_feet():
    model, state = _standing("flat")
    counters = FrameCounters(model, state)
    counters.update(state)
    assert (counters.body_overlaps, counters.shared_foot_spots) == (0, 0)
    # Character 1 stands exactly where character 0 stands: one overlapping pair, and each of the
    # 8 stance feet shares its spot with the other's twin (8 pairs).
    state.pelvis[1] = state.pelvis[0]
    state.feet[1] = state.feet[0]
    state.fk_feet[1] = state.fk_feet[0]
    state.heading[1] = state.heading[0]
    fresh = FrameCounters(model, state)
    fresh.update(state)
    assert fresh.body_overlaps == 1
    assert fresh.shared_foot_spots == model.n_legs
    # Side by side, bodies 1 mm apart (spider body box 0.25 x 0.15 m): no overlap.
    side = FrameCounters(model, state)
    lateral = np.array([-np.sin(state.heading[0]), 0.0, np.cos(state.heading[0])]) * (0.15 + 1e-3)
    state.pelvis[1] += lateral
    state.feet[1] += 10.0  # and the feet far away
    state.fk_feet[1] += 10.0
    side.update(state)
    assert (side.body_overlaps, side.shared_foot_spots) == (0, 0)


def test_a_character_that_does_not_move_for_three_seconds_is_stuck_for_one():
    model, state = _standing("flat")
    counters = FrameCounters(model, state)
    frames = int(round(3.0 / model.dt))
    for _ in range(frames):  # nobody moves: after the 2 s window fills, both are stuck for 1 s
        state.t += model.dt
        counters.update(state)
    assert counters.stuck_seconds == pytest.approx(2 * (frames - int(round(2.0 / model.dt)) + 1) * model.dt)
    moving = FrameCounters(model, state)
    for _ in range(frames):  # 0.5 x the asked speed: not stuck
        state.pelvis[:, 0] += 0.5 * state.desired_speed * model.dt
        moving.update(state)
    assert moving.stuck_seconds == 0.0


def test_a_foot_under_a_box_faster_than_the_creature_is_an_unavoidable_contact():
    import dataclasses

    model, state = _standing("crates-moving")
    # The first crate of `crates-moving` slides at 0.15 m/s from (0, -3): slower than the
    # spider's top speed, so a foot inside it is a collision the character could have avoided.
    assert 0.15 < model.top_speed
    centres, _ = model.raster.obstacles.poses_at(state.t)
    state.feet[0, 2] = (centres[0, 0], 0.0, centres[0, 2])
    state.ik_on[0] = False
    counters = FrameCounters(model, state)
    counters.update(state)
    assert (counters.collisions, counters.unavoidable_contacts) == (1, 0)
    # The same crate against a creature whose top speed is below 0.15 m/s: no escape existed.
    slow = FrameCounters(dataclasses.replace(model, top_speed=0.1), state)
    slow.update(state)
    assert (slow.collisions, slow.unavoidable_contacts) == (0, 1)


def _walker(rest, dt):
    """A stand-in model and state of one character with legs at ``rest`` (forward, lateral; m), asked
    for 0.3 m/s, standing at the origin facing +x: what :class:`StrideMeter` reads."""
    from types import SimpleNamespace

    from footfall.planner._timing import GaitTiming

    legs = len(rest)
    model = SimpleNamespace(dt=dt, timing=GaitTiming(), leg_height=0.12, speed_cap=np.inf,
                            rest_body=np.asarray(rest, dtype=np.float64))
    state = SimpleNamespace(desired_speed=np.array([0.3]), feet=np.zeros((1, legs, 3)), pelvis=np.zeros((1, 3)),
                            speed=np.zeros(1), in_stance=np.ones((1, legs), np.bool_), lod_level=None,
                            heading=np.zeros(1), feet_spacing=np.ones(1))
    return model, state


def _stride_walk(speeds, strides):
    """One foot of one character landing every 10 frames (dt 0.1 s) at the given strides (m), the body
    at ``speeds[k]`` in frame k: the per-stride errors the meter measures."""
    from footfall.planner._simulation import StrideMeter

    model, state = _walker([(0.0, 0.0)], 0.1)
    meter = StrideMeter(model, state)
    landings = {10 * (i + 1): float(x) for i, x in enumerate(np.cumsum(strides))}
    for k in range(len(speeds)):
        state.speed = np.array([speeds[k]])
        if k:
            state.pelvis = state.pelvis + [[speeds[k] * model.dt, 0.0, 0.0]]
        if k in landings:
            state.feet = np.array([[[landings[k], 0.0, 0.0]]])
        meter.update(k, state, np.full((1, 1), k == 0 or k in landings))
    return meter.summary()


def test_a_stride_through_a_dodge_is_not_measured_against_the_law():
    from footfall.planner._timing import GaitTiming, stride_frequency

    law = 0.3 / stride_frequency(GaitTiming(), 0.3, 0.12)  # the stride the law commands at 0.3 m/s
    steady = [0.3] * 31
    # three steady strides, 10 % long, exact, 20 % short: all measured
    median, p90, n = _stride_walk(steady, [1.1 * law, law, 0.8 * law])
    assert n == 3 and median == pytest.approx(0.1)
    # the second stride through a dodge (0.3 -> 0.05 -> 0.3 m/s; both touch-downs at 0.3): not measured
    dodge = steady[:13] + [0.05] * 4 + steady[17:]
    median, p90, n = _stride_walk(dodge, [1.1 * law, law, 0.8 * law])
    assert n == 2 and median == pytest.approx(0.15)


def _circling(turn_rate, rest, frames=41):
    """Per-stride errors of the feet of one body walking at 0.3 m/s and turning at ``turn_rate``
    (rad/s), each foot landing on its rest point every 10 frames, dt chosen so that 10 frames are one
    cycle of the law's tempo: every stride as long as the law asks of that foot."""
    from footfall.planner._simulation import StrideMeter, rest_points
    from footfall.planner._timing import GaitTiming, stride_frequency

    v, legs = 0.3, len(rest)
    model, state = _walker(rest, 0.1 / stride_frequency(GaitTiming(), v, 0.12))
    state.speed = np.array([v])
    meter = StrideMeter(model, state)
    for k in range(frames):
        t = k * model.dt  # on the arc (radius v / turn_rate) exactly, or the straight line
        state.heading = np.array([turn_rate * t])
        if turn_rate:
            radius = v / turn_rate
            state.pelvis = np.array([[radius * np.sin(turn_rate * t), 0.0, radius * (1.0 - np.cos(turn_rate * t))]])
        else:
            state.pelvis = np.array([[v * t, 0.0, 0.0]])
        landed = np.full((1, legs), k % 10 == 0)
        if landed.any():
            on_rest = rest_points(model, np.repeat(state.pelvis[:, [0, 2]], legs, axis=0), np.repeat(state.heading, legs),
                                  np.ones(legs), np.arange(legs))
            state.feet[0, :, 0], state.feet[0, :, 2] = on_rest[:, 0], on_rest[:, 1]
        meter.update(k, state, landed)
    return np.concatenate(meter.errors)


def test_in_a_turn_each_foot_is_measured_against_its_own_share_of_the_travel():
    from footfall.planner._timing import GaitTiming, stride_frequency

    rest = [(0.2, 0.25), (0.2, -0.25)]  # a left and a right foot
    assert np.abs(_circling(0.0, rest)).max() < 1e-12  # straight: every stride the law's
    # Turning left at 0.6 rad/s (a 0.5 m radius): the left foot's rest point walks a circle of
    # hypot(0.2, 0.25) = 0.32 m, the right one's of hypot(0.2, 0.75) = 0.78 m, 0.64 and 1.55 times the
    # body's travel; each is measured against that share. Left: the body's own error, which comes from
    # measuring its speed along the chord of its arc: |T f(v) - 1|, v = 2 R sin(w T / 2) / T.
    errors = _circling(0.6, rest)
    period = 1.0 / stride_frequency(GaitTiming(), 0.3, 0.12)
    v = 2 * 0.5 * np.sin(0.6 * period / 2) / period
    chord = abs(period * stride_frequency(GaitTiming(), v, 0.12) - 1.0)
    np.testing.assert_allclose(errors, np.full(8, chord), rtol=1e-9)
    assert 0 < chord < 0.002
