"""Scripted encounters: tiny deterministic scenarios whose right answer can be checked by hand
(issue 20, item 1).

Each builds a 12 x 12 m flat world with one crate and one spider, runs it frame by frame and
checks the promise on every frame with plain geometry written here (a point inside an oriented
rectangle), beside the simulator's own counters.
"""

import copy
import math

import numpy as np
import pytest

from conftest import fresh_seeds
from footfall.planner._counters import FrameCounters
from footfall.planner._crowd import DT, init_crowd, stage_steer, step
from footfall.planner._kernels_foot import ESCAPE_RISE
from footfall.scenarios import load_creature, load_scenario
from footfall.scenarios._gait_schedule import gait_schedule

WORLD = """
name = "{name}"
seed = 0
[terrain]
kind = "flat"
size = [12.0, 12.0]
cell_size = 0.05
{crate}
[crowd]
creature = "spider"
centre = {start}
heading = 0.0
speed = {speed}
goal = {goal}
spawn_clear_s = 0.0  # the spider starts where the encounter puts it, whatever the crate will do
"""
CRATE = """[[obstacles]]
centre = {centre}
size = [{width}, 0.3, {width}]
kind = "forbidden"
{motion}
"""


def _world(tmp_path, name, *, crate_centre, crate_width, start, goal, speed=0.3, velocity=None):
    motion = "" if velocity is None else f"motion = {{ kind = \"velocity\", velocity = {list(velocity)} }}"
    crate = CRATE.format(centre=list(crate_centre), width=crate_width, motion=motion)
    path = tmp_path / f"{name}.toml"
    path.write_text(WORLD.format(name=name, crate=crate, start=list(start), goal=list(goal), speed=speed))
    scenario, creature = load_scenario(str(path)), load_creature("spider")
    return init_crowd(scenario, creature, gait_schedule(creature), n_characters=1, seed=0)


def _inside(points_xz, centre_xz, half, yaw):
    """Points (n, 2) strictly inside the rectangle (centre, half extents along its yawed axes)."""
    d = np.asarray(points_xz, dtype=float) - np.asarray(centre_xz, dtype=float)
    c, s = math.cos(yaw), math.sin(yaw)
    along = d[:, 0] * c + d[:, 1] * s
    across = -d[:, 0] * s + d[:, 1] * c
    return (np.abs(along) < half[0]) & (np.abs(across) < half[1])


def _crate_now(model, t):
    centres, yaws = model.raster.obstacles.poses_at(t)
    size = model.raster.obstacles.sizes[0]
    return centres[0, [0, 2]], 0.5 * size[[0, 2]], float(yaws[0])


def _run(model, state, frames, each_frame):
    counters = FrameCounters(model, state)
    for _ in range(frames):
        step(model, state)
        counters.update(state)
        each_frame(state)
    return counters


def _run_feet_in_crate(model, state, frames, swing_heights=None):
    """Run ``frames`` frames; (rendered foot-frames inside the crate where it is, the run's counters).
    ``swing_heights``: a list that receives each frame's highest swinging (not tucked) foot, planned."""
    inside = []

    def check(s):
        c, h, y = _crate_now(model, s.t)
        feet = np.where(s.ik_on[0], s.fk_feet[0], s.feet[0])
        inside.append(int(_inside(feet[:, [0, 2]], c, h, y).sum()))
        swinging = ~s.in_stance[0] & ~s.tucked[0]
        if swing_heights is not None and swinging.any():
            swing_heights.append(float(s.feet[0, swinging, 1].max()))

    counters = _run(model, state, frames, check)
    return sum(inside), counters


def test_a_crate_driven_across_a_stance_foot_makes_it_step_away_before_contact(tmp_path):
    # A spider stands at its goal (0, 0), facing +x; its left feet rest about 0.3 m to its
    # left. A 0.16 m crate slides along z = 0.32 at 0.2 m/s from x = -1.5: it sweeps through
    # the left feet's spots (and never reaches the body, 0.075 m wide).
    model, state = _world(tmp_path, "across-stance", crate_centre=(-1.5, 0.32), crate_width=0.16, start=(0.0, 0.0),
                          goal=(0.0, 0.0), velocity=(0.2, 0.0))
    left = state.feet[0, :, 2] > 0.2
    centre, half, yaw = _crate_now(model, 7.5)
    assert _inside(state.feet[0][left][:, [0, 2]], centre, half, yaw).any(), "the crate must sweep a foot's spot"
    heights = []
    inside, counters = _run_feet_in_crate(model, state, 450, heights)
    assert inside == 0
    assert counters.collisions == 0
    assert state.counters["steps"] > 0
    assert counters.max_stance_slip_m <= 1e-3
    # A foot stepping out of the crate's way leaves through the cells where it is heading: drawn at most
    # ESCAPE_RISE step heights (+ the obstacle margin) over the flat ground, not over the 0.3 m crate.
    assert max(heights) <= ESCAPE_RISE * model.step_height + model.config.obstacle_margin_m + 1e-9, max(heights)


def test_a_crate_crossing_a_planned_swing_replans_it_the_same_frame(tmp_path, monkeypatch):
    # The spider walks +x from (-2, 0) at 0.3 m/s; a 0.2 m crate moving +z at 2 m/s (faster than the
    # spider's top speed, 0.77 m/s: it cannot get out of the way) crosses its path at x = -1.1 at t = 2 s,
    # where the spider's front feet are then: it runs through the swings in progress. (Feet are planned
    # against where a crate will be threat_horizon later too, so only a fast, narrow one gets between
    # those two poses onto a planned swing: this one must.) The body's avoidance (ORCA) is switched off
    # here: it keeps the feet clear of even this crate by waiting, and this test is about the swings.
    # So is the check of a new swing against where the crate will be on each of its frames
    # (swings_into_moving_boxes): with it no planned swing is ever crossed here (below).
    import footfall.planner._crowd as crowd

    monkeypatch.setattr(crowd, "_avoid", lambda model, state, preferred, *_: (
        preferred, np.zeros(preferred.shape[0], np.bool_), np.zeros(preferred.shape[0], np.bool_),
        (np.zeros(preferred.shape[0] + 1, np.int64), np.zeros(0, np.int64))))
    checked = crowd.swings_into_moving_boxes
    monkeypatch.setattr(crowd, "swings_into_moving_boxes", lambda *args: np.zeros(args[2].size, np.bool_))
    invalidated, blocked, counters, state = _crossing_swings(tmp_path, monkeypatch)
    assert sum(invalidated) > 0, "the crate must cross a planned swing"
    assert state.counters["replans"] >= sum(invalidated) > 0
    assert sum(blocked) == 0
    assert counters.collisions == 0
    assert state.pelvis[0, 0] > 2.0, "the spider walks on past the crate's path"
    # With the check, every swing is planned clear of where the crate will be: none is crossed.
    monkeypatch.setattr(crowd, "swings_into_moving_boxes", checked)
    invalidated, blocked, counters, state = _crossing_swings(tmp_path, monkeypatch)
    assert sum(invalidated) == 0 and sum(blocked) == 0 and counters.collisions == 0
    assert state.pelvis[0, 0] > 2.0, "the spider walks on past the crate's path"


def _crossing_swings(tmp_path, monkeypatch):
    """The run of :func:`test_a_crate_crossing_a_planned_swing_replans_it_the_same_frame`: (swings the
    runtime found invalidated per frame, swings left running through the crate after each frame, the
    run's counters, its final state)."""
    import footfall.planner._crowd as crowd

    model, state = _world(tmp_path, "across-swing", crate_centre=(-1.1, -4.0), crate_width=0.2, start=(-2.0, 0.0),
                          goal=(4.0, 0.0), velocity=(0.0, 2.0))
    from footfall.planner._kernels_controller import swings_invalidated as runtime_check

    invalidated = []

    def counted(*args):  # the runtime's own check, counted (its last argument is its output)
        runtime_check(*args)
        invalidated.append(int(args[-1].sum()))

    monkeypatch.setattr(crowd, "swings_invalidated", counted)
    blocked = []

    def check(s):
        # After every frame, no swinging foot's remaining path runs through the crate where it is now.
        c, h, y = _crate_now(model, s.t)
        for leg in np.flatnonzero(~s.in_stance[0]):
            k = s.trajectories.shape[2]
            u = s.swing_t[0, leg] / s.swing_T[0, leg]
            rest = s.trajectories[0, leg, int(u * (k - 1)):, :]
            low = rest[:, 1] < 0.3 + 1e-9  # under the crate's top
            blocked.append(int(_inside(rest[low][:, [0, 2]], c, h, y).any()))

    counters = _run(model, state, 600, check)
    return invalidated, blocked, counters, state


def _crate_from_behind(tmp_path, name, speed, width):
    """A spider walking +x at 0.3 m/s from (-2, 0); a crate (0.3 m high, ``width`` wide) starts 1.6 m behind
    it on its path and moves +x at ``speed`` (slower than the spider's 0.77 m/s top speed: an escape
    exists). Returns (foot-frames inside the crate, the run's counters)."""
    model, state = _world(tmp_path, name, crate_centre=(-3.6, 0.0), crate_width=width, start=(-2.0, 0.0),
                          goal=(4.0, 0.0), velocity=(speed, 0.0))
    assert speed < model.top_speed
    inside, counters = _run_feet_in_crate(model, state, 450)
    crate_x = _crate_now(model, state.t)[0][0]
    assert crate_x > state.pelvis[0, 0], "the crate must catch up with the spider and pass it"
    return inside, counters


def test_a_crate_catching_up_from_behind_passes_without_touching_a_foot(tmp_path):
    inside, counters = _crate_from_behind(tmp_path, "behind", speed=0.5, width=0.3)
    assert inside == 0
    assert counters.collisions == 0
    assert counters.max_stance_slip_m <= 1e-3


def test_a_wide_crate_catching_up_from_behind_passes_without_touching_a_foot(tmp_path):
    inside, counters = _crate_from_behind(tmp_path, "behind-wide", speed=0.45, width=0.5)
    assert inside == 0
    assert counters.collisions == 0


def test_a_spider_steered_straight_at_a_forbidden_crate_passes_around_it(tmp_path):
    # The straight line from (-3, 0) to the goal (3, 0) runs through a 0.5 m crate at the origin.
    model, state = _world(tmp_path, "straight-at", crate_centre=(0.0, 0.0), crate_width=0.5, start=(-3.0, 0.0),
                          goal=(3.0, 0.0))
    body = np.asarray(model.creature.body_box, dtype=float)
    gaps = []

    def check(s):
        c, h, _ = _crate_now(model, s.t)
        # Distance from the pelvis to the crate's square, less the body's half-width: the clearance.
        d = np.maximum(np.abs(s.pelvis[0, [0, 2]] - c) - h, 0.0)
        gaps.append(float(np.hypot(*d)) - 0.5 * body[1])

    counters = _run(model, state, 900, check)
    assert min(gaps) >= 0.0
    assert counters.collisions == 0
    assert counters.max_stance_slip_m <= 1e-3
    assert state.pelvis[0, 0] > 0.5, "the spider got past the crate"


def test_avoidance_keeps_a_forbidden_crate_clear_of_the_body_for_its_horizon(tmp_path):
    # ORCA against a box (van den Berg et al. 2011; planner/_kernels_avoidance.py): the box is seen as its
    # nearest point, and the body's disc (radius r) may not reach it within the box horizon tau: walking
    # straight at a crate face d ahead, at most (d - r) / tau toward it. Alone, the forbidden box's push
    # in stage_steer got a single spider round a crate (the test above) with or without it; in a crowd,
    # without it, neighbours pushed bodies to 5 cm from crates (12 spiders on crates, 600 frames).
    from footfall.planner._crowd import AVOID_BOX_HORIZON, _avoid, _box_velocities, _boxes_now

    model, state = _world(tmp_path, "orca-box", crate_centre=(0.9, 0.0), crate_width=0.5, start=(0.0, 0.0),
                          goal=(3.0, 0.0))
    boxes = _boxes_now(model, state.t)
    assert state.pelvis[0, 2] == 0.0 and state.heading[0] == 0.0
    d = 0.9 - 0.25 - state.pelvis[0, 0]  # to the crate's near face, straight ahead
    r = model.avoid_radius
    assert 0.0 < d - r < 0.3 * AVOID_BOX_HORIZON, "the crate must be near enough to bind a 0.3 m/s walk"
    preferred = np.array([[0.3, 0.0]])
    velocity, avoided, _, _ = _avoid(model, state, preferred, np.array([3.0]), boxes,
                                     _box_velocities(model, state.t, boxes[0]), np.zeros(1, np.bool_))
    assert avoided[0]
    assert velocity[0, 0] <= (d - r) / AVOID_BOX_HORIZON + 1e-9
    assert velocity[0, 0] == pytest.approx((d - r) / AVOID_BOX_HORIZON, abs=1e-6)  # no slower than it must
    # Walking away from it: nothing to avoid.
    velocity, avoided, _, _ = _avoid(model, state, -preferred, np.array([3.0]), boxes,
                                     _box_velocities(model, state.t, boxes[0]), np.zeros(1, np.bool_))
    assert not avoided[0] and velocity[0] == pytest.approx(-preferred[0])


def test_a_character_standing_still_is_avoided_with_the_whole_effort(tmp_path, monkeypatch):
    # ORCA shares the effort of avoiding between two characters, each taking half (van den Berg et al.
    # 2011). A walker standing still cannot take its half (it walks off only along its heading and turns
    # slowly): left half the effort, one spider walked into another standing in its way (mixed, seed
    # 1121411189: 63 overlapping frames). Walking at its preferred velocity, A's new velocity is v + s u
    # (s its share of the change u that leaves the velocity obstacle): s = 1 against a standing B, 1/2
    # once B counts as able to make way (MOBILE_FRACTION 0: any speed).
    import footfall.planner._crowd as crowd

    path = tmp_path / "pair.toml"
    path.write_text(WORLD.format(name="pair", crate=CRATE.format(centre=[5.0, 5.0], width=0.2, motion=""),
                                 start=[0.0, 0.0], goal=[3.0, 0.0], speed=0.3))
    creature = load_creature("spider")
    model, state = init_crowd(load_scenario(str(path)), creature, gait_schedule(creature), n_characters=2, seed=0)
    state.pelvis[:, [0, 2]] = [[0.0, 0.0], [1.0, 0.1]]
    state.heading[:] = [0.0, 0.5 * math.pi]
    state.speed[:] = [0.3, 0.0]
    state.body_held[:] = False
    boxes = (np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, np.bool_), np.zeros(0, np.bool_))
    preferred = np.array([[0.3, 0.0], [0.0, 0.0]])

    def a_velocity():
        # to_target under the keep-right distance: A's preferred velocity is its velocity.
        velocity, avoided, _, _ = crowd._avoid(model, state, preferred, np.array([0.5, 0.5]), boxes,
                                               np.zeros((0, 2)), np.zeros(2, np.bool_))
        assert avoided[0]
        return velocity[0] - preferred[0]

    whole = a_velocity()
    monkeypatch.setattr(crowd, "MOBILE_FRACTION", 0.0)
    half = a_velocity()
    assert np.hypot(*half) > 1e-3  # the premise: B is in A's way
    assert whole == pytest.approx(2.0 * half, abs=1e-12)


def test_feet_feedback_shifts_the_pelvis_by_the_gain_of_a_significant_offset(tmp_path):
    # Paper §5, Fig. 7: when the chosen footprints sit on average off the preferred ones by
    # more than the threshold, the pelvis moves toward them at feedback_gain per second.
    model, state = _world(tmp_path, "feedback", crate_centre=(5.0, 5.0), crate_width=0.2, start=(0.0, 0.0),
                          goal=(4.0, 0.0))
    ctl = model.controller
    boxes = (np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, np.bool_), np.zeros(0, np.bool_))
    offset = np.array([0.0, 0.08])  # 8 cm to the left, above the threshold (0.15 x rest radius ~ 5 cm)
    assert np.hypot(*offset) > ctl.feedback_threshold * model.rest_radius
    state.feedback[0] = offset
    before = state.pelvis[0].copy()
    stage_steer(model, state, boxes)
    moved = state.pelvis[0] - before
    gain = min(1.0, ctl.feedback_gain * DT)
    # The walk moves the pelvis along the heading (its move is state.last_move); the feedback adds gain x
    # offset on top.
    assert moved[2] == pytest.approx(state.last_move[0, 1] + gain * offset[1], abs=1e-12)
    assert moved[0] == pytest.approx(state.last_move[0, 0] + gain * offset[0], abs=1e-12)
    assert state.feedback[0] == pytest.approx((1.0 - gain) * offset, abs=1e-12)
    # Below the threshold, the pelvis makes the walk's own move only (it turns back toward the goal).
    state.feedback[0] = 0.5 * ctl.feedback_threshold * model.rest_radius * np.array([0.0, 1.0])
    before = state.pelvis[0].copy()
    stage_steer(model, state, boxes)
    assert state.pelvis[0, 2] == pytest.approx(before[2] + state.last_move[0, 1], abs=1e-12)


@pytest.mark.parametrize("walk, crate_width, crate_speed", [(0.15, 0.8, 0.2), (0.3, 0.5, 0.35)])
def test_a_crate_driven_head_on_at_a_walking_spider_is_evaded(tmp_path, walk, crate_width, crate_speed):
    # The spider walks +x from (-2, 0) toward (4, 0); a crate comes the other way along the same line,
    # slower than the spider's top speed (an escape exists). Slowing down in its lane, what ORCA alone
    # picks for a walker that only goes forward, ended with the crate on the feet (249 and 176
    # foot-frames); the spider must leave the lane, let the crate pass and walk on.
    model, state = _world(tmp_path, "head-on", crate_centre=(3.0, 0.0), crate_width=crate_width, start=(-2.0, 0.0),
                          goal=(4.0, 0.0), velocity=(-crate_speed, 0.0), speed=walk)
    assert crate_speed < model.top_speed
    inside, counters = _run_feet_in_crate(model, state, 900)
    assert _crate_now(model, state.t)[0][0] < state.pelvis[0, 0], "the crate must pass the spider"
    assert inside == 0
    assert counters.collisions == 0
    assert counters.max_stance_slip_m <= 1e-3
    assert state.pelvis[0, 0] > 0.5, "the spider walks on past the crate"


def test_a_character_in_a_crates_lane_heads_square_out_of_it_to_the_nearer_side(tmp_path, monkeypatch):
    # A 0.5 m crate at (1, 0) drives -x at 0.2 m/s at a spider standing at the origin (facing +x, its
    # way +x): the crate's front (0.75) reaches its feet (rest radius + threat margin, 0.38 m) in
    # 1.9 s, under 3 s, so its way turns square out of the lane. Dead
    # centre, it takes the side of its way's right (+z: the lane's side axis for a crate going -x is
    # (0, -1), and the way has no part along it, so the tie goes to +z); 0.1 m to -z, it takes -z.
    # Behind the crate, or beside its lane, the way is kept.
    # The lane exit's own rule: the look-ahead (planner._escape, tests/test_escape.py) keeps its way.
    monkeypatch.setattr("footfall.planner._escape.ESCAPE_KEEP", math.inf)
    from footfall.planner._crowd import _box_velocities, _boxes_now, _lane_exit

    def lane_exit(model, state, way):
        boxes = _boxes_now(model, state.t)
        return _lane_exit(model, state, way, boxes, _box_velocities(model, state.t, boxes[0]))

    model, state = _world(tmp_path, "lane", crate_centre=(1.0, 0.0), crate_width=0.5, start=(0.0, 0.0),
                          goal=(4.0, 0.0), velocity=(-0.2, 0.0))
    way = np.array([[1.0, 0.0]])
    for z, expected in ((0.0, [0.0, 1.0]), (-0.1, [0.0, -1.0]), (0.5 * 0.5 + model.rest_radius + 0.1, [1.0, 0.0])):
        state.pelvis[0, [0, 2]] = [0.0, z]
        direction, in_lane = lane_exit(model, state, way)
        np.testing.assert_allclose(direction[0], expected, atol=1e-12)
        assert in_lane[0] == (expected != [1.0, 0.0])
    state.pelvis[0, [0, 2]] = [2.0, 0.0]  # behind the crate
    assert not lane_exit(model, state, way)[1][0]


def test_a_character_in_a_crates_lane_heads_for_its_top_speed_and_beside_it_for_the_asked_one(tmp_path):
    # The crate and spider of the test above: in the lane, the steering heads for the spider's top
    # speed (FLEE_SPEED of it), not the scenario's 0.3 m/s; beside the lane, for the asked 0.3 m/s.
    from footfall.planner._crowd import FLEE_SPEED, _boxes_now, stage_steer

    model, state = _world(tmp_path, "flee", crate_centre=(1.0, 0.0), crate_width=0.5, start=(0.0, 0.0),
                          goal=(4.0, 0.0), velocity=(-0.2, 0.0))
    assert FLEE_SPEED * model.top_speed > 0.3  # premise: the top speed is faster than the asked one
    for z, goal in ((0.0, FLEE_SPEED * model.top_speed), (0.5 * 0.5 + model.rest_radius + 0.1, 0.3)):
        state.pelvis[0, [0, 2]] = [0.0, z]
        stage_steer(model, state, _boxes_now(model, state.t))
        assert state.escaping[0] == (z == 0.0)
        assert state.goal_speed[0] == pytest.approx(goal, abs=1e-12)


def test_an_escaper_nothing_hinders_walks_at_its_flee_speed(tmp_path, monkeypatch):
    # The crate and spider above, the spider in the lane and already facing the way out that the steering
    # chose, with ORCA changing nothing (its velocity the preferred one). It walks toward its flee speed
    # (0.54 m/s) as far as FLEE_GAIN_MAX of the asked 0.3 m/s: 0.375 m/s, not the asked 0.3 (an ant
    # crossing a crate's lane unhindered at 0.3 m/s had a foot caught: mixed, 16 ants, seed 3).
    from footfall.planner import _crowd as crowd

    model, state = _world(tmp_path, "unhindered", crate_centre=(1.0, 0.0), crate_width=0.5, start=(0.0, 0.0),
                          goal=(4.0, 0.0), velocity=(-0.2, 0.0))

    def no_one_in_the_way(model, state, preferred, *args):
        n = preferred.shape[0]
        return preferred.copy(), np.zeros(n, np.bool_), np.zeros(n, np.bool_), (np.zeros(n + 1, np.int64),
                                                                              np.zeros(0, np.int64))

    monkeypatch.setattr(crowd, "_avoid", no_one_in_the_way)
    pelvis, speed = state.pelvis.copy(), state.speed.copy()
    heading = float(state.heading[0])
    for _ in range(100):  # the same moment again, turned toward the way out until it faces it
        state.pelvis[:], state.speed[:], state.heading[0] = pelvis, speed, heading
        crowd.stage_steer(model, state, crowd._boxes_now(model, state.t))
        if abs(state.turn_wanted[0]) < 1e-9:
            break
        heading += float(state.turn_wanted[0])
    assert abs(state.turn_wanted[0]) < 1e-9
    assert state.escaping[0]
    assert state.goal_speed[0] == pytest.approx(crowd.FLEE_SPEED * model.top_speed, abs=1e-12)
    assert crowd.FLEE_SPEED * model.top_speed > crowd.FLEE_GAIN_MAX * 0.3  # premise: the gain holds it
    assert state.speed_wanted[0] == pytest.approx(crowd.FLEE_GAIN_MAX * 0.3, abs=1e-12)


def test_between_two_crates_lanes_the_way_out_leads_away_from_both(tmp_path, monkeypatch):
    # Two 0.5 m crates drive -x at 0.2 m/s: A head-on at (1, 0), B passing beside the spider at (0, 0.6).
    # The spider stands at (0, 0.05), its way +x. A's nearer side is +z, B's is -z: summed, the two exits
    # cancel and the way (+x, into A) was kept. Walking at 0.3 m/s (rest radius + threat margin, 0.38 m,
    # added to each crate's half width, 0.63 m): +x meets A in 0.74 s and is inside B's reach for 1.26 s;
    # +z stays inside B's reach for 3.15 s; -z leaves it in 0.27 s and meets A only after 1.85 s. So -z.
    # The lane exit's own rule: the look-ahead (planner._escape, tests/test_escape.py) keeps its way.
    monkeypatch.setattr("footfall.planner._escape.ESCAPE_KEEP", math.inf)
    from footfall.planner._crowd import _box_velocities, _boxes_now, _lane_exit

    crates = "".join(CRATE.format(centre=list(c), width=0.5, motion='motion = { kind = "velocity", velocity = [-0.2, 0.0] }')
                     for c in ((1.0, 0.0), (0.0, 0.6)))
    path = tmp_path / "two.toml"
    path.write_text(WORLD.format(name="two", crate=crates, start=[-4.0, 0.0], goal=[4.0, 0.0], speed=0.3))
    model, state = init_crowd(load_scenario(str(path)), load_creature("spider"), gait_schedule(load_creature("spider")),
                              n_characters=1, seed=0)
    assert model.rest_radius + model.controller.threat_margin == pytest.approx(0.38, abs=0.005)
    state.pelvis[0, [0, 2]] = [0.0, 0.05]
    boxes = _boxes_now(model, state.t)
    direction, in_lane = _lane_exit(model, state, np.array([[1.0, 0.0]]), boxes, _box_velocities(model, state.t, boxes[0]))
    assert in_lane[0]
    np.testing.assert_allclose(direction[0], [0.0, -1.0], atol=1e-12)


@pytest.mark.parametrize("gap, expected", [(0.05, [0.0, 1.0]), (1.0, [0.0, -1.0])])
def test_a_lane_exit_walled_by_a_static_crate_takes_the_other_side(tmp_path, monkeypatch, gap, expected):
    # The first encounter's crate (0.5 m, from (1, 0) at -0.2 m/s) and a spider at (0, -0.1), its way +x:
    # the nearer side is -z. A static forbidden crate (0.4 m) stands beside it on that side, its face
    # ``gap`` beyond the spider's avoid radius r. Walking -z at 0.3 m/s it comes within r of that face
    # after gap / 0.3 s: 0.17 s with gap 0.05, inside ORCA's 1.5 s box horizon, so ORCA would refuse
    # that way (the spider stood still on the lane's edge until the crate came: crates-moving, seed 11).
    # The other side, +z, leaves the lane (0.63 m, from -0.1) in 2.43 s and meets the crate at 1.85 s
    # (its centre within 0.63 m along); the walled side scores 0.2 s (the first 0.1 s step within r).
    # So +z. With the face 1.0 m further (3.3 s), the wall is ORCA's business later: -z, as without it.
    # The lane exit's own rule: the look-ahead (planner._escape, tests/test_escape.py) keeps its way.
    monkeypatch.setattr("footfall.planner._escape.ESCAPE_KEEP", math.inf)
    from footfall.planner._crowd import _box_velocities, _boxes_now, _lane_exit

    spider = load_creature("spider")
    moving = CRATE.format(centre=[1.0, 0.0], width=0.5, motion='motion = { kind = "velocity", velocity = [-0.2, 0.0] }')

    def world(crates):
        path = tmp_path / "walled.toml"
        path.write_text(WORLD.format(name="walled", crate=crates, start=[-4.0, 3.0], goal=[4.0, 3.0], speed=0.3))
        return init_crowd(load_scenario(str(path)), spider, gait_schedule(spider), n_characters=1, seed=0)

    r = world(moving)[0].avoid_radius  # the spider's rest radius: 0.34 m
    model, state = world(moving + CRATE.format(centre=[0.0, -0.1 - (r + gap) - 0.2], width=0.4, motion=""))
    assert model.avoid_radius == r == pytest.approx(0.34, abs=0.005)
    state.pelvis[0, [0, 2]] = [0.0, -0.1]
    boxes = _boxes_now(model, state.t)
    direction, in_lane = _lane_exit(model, state, np.array([[1.0, 0.0]]), boxes, _box_velocities(model, state.t, boxes[0]))
    assert in_lane[0]
    np.testing.assert_allclose(direction[0], expected, atol=1e-12)


def test_a_foot_a_wide_crate_leaves_no_footprint_is_tucked_out_of_its_way(tmp_path, monkeypatch):
    # A spider stands at its goal (0, 0) facing +x. A 0.6 m crate slides +x at 0.2 m/s along z = 0.45:
    # it covers z 0.15..0.75, the left feet's spots (about 0.3 m to the left) and their candidate discs
    # (0.25 m about the same spots, down to z 0.05), but not the body. The left feet have nowhere to
    # step: each is tucked up near its hip (planner._crowd.tuck_swings, a quarter of its rest offset
    # out, z about 0.1) until the crate has passed, and lands again behind it.
    import footfall.planner._crowd as crowd

    def run():
        model, state = _world(tmp_path, "tuck", crate_centre=(-1.8, 0.45), crate_width=0.6, start=(0.0, 0.0),
                              goal=(0.0, 0.0), velocity=(0.2, 0.0))
        inside, tucked, flinch = [], [], []

        def check(s):
            c, h, y = _crate_now(model, s.t)
            feet = np.where(s.ik_on[0], s.fk_feet[0], s.feet[0])
            inside.append(int(_inside(feet[:, [0, 2]], c, h, y).sum()))
            new = s.tucked[0] & ~(tucked[-1] if tucked else np.zeros_like(s.tucked[0]))
            flinch.extend(s.swing_T[0, new] / model.dt)
            tucked.append(s.tucked[0].copy())

        counters = _run(model, state, 540, check)
        assert _crate_now(model, state.t)[0][0] - 0.3 > 0.5, "the crate must pass the spider"
        return sum(inside), np.array(tucked), counters, state, flinch

    inside, tucked, counters, state, flinch = run()
    assert tucked[:, state.feet[0, :, 2] > 0.2].any(), "a left foot must have been tucked"
    # A foot tucks in TUCK_FRAMES frames (a flinch), not at a swing's pace.
    assert flinch and np.allclose(flinch, crowd.TUCK_FRAMES), flinch
    assert not tucked[:, state.feet[0, :, 2] < -0.2].any(), "no right foot is in the crate's way"
    assert inside == 0
    assert state.in_stance[0].all() and not state.tucked[0].any(), "every foot lands again"
    assert counters.leg_crossings == 0
    assert counters.max_stance_slip_m <= 1e-3
    # Left in place (the hold it replaced), the same feet stand under the crate.
    monkeypatch.setattr(crowd, "tuck_swings", lambda *args: None)
    assert run()[0] > 0, "without the tuck the crate must run over a foot here"


def test_a_tucked_foot_rises_first_then_moves_in_to_its_tuck_point(tmp_path):
    from footfall.planner._crowd import TUCK_LIFT, TUCK_REACH, hips_world, tuck_points, tuck_swings

    model, state = _world(tmp_path, "tuck-point", crate_centre=(5.0, 5.0), crate_width=0.2, start=(0.0, 0.0),
                          goal=(4.0, 0.0))
    hips = hips_world(model, state)
    legs = np.array([0, 3])
    chars = np.zeros(2, np.int64)
    point = tuck_points(model, state, chars, legs, hips)
    rest = model.rest_body[legs]
    # Heading 0: body forward is +x and left is +z; the point is a quarter of the way from the hip
    # to the rest foot on the ground, halfway between the ground and the hip in height.
    np.testing.assert_allclose(point[:, 0], hips[0, legs, 0] + TUCK_REACH * (rest[:, 0] - model.hips_body[legs, 0]))
    np.testing.assert_allclose(point[:, 2], hips[0, legs, 2] + TUCK_REACH * (rest[:, 1] - model.hips_body[legs, 2]))
    height = model.creature.standing_height + model.hips_body[legs, 1]
    np.testing.assert_allclose(point[:, 1], hips[0, legs, 1] - (1.0 - TUCK_LIFT) * height)
    source = state.feet[0, legs].copy()
    tuck_swings(model, state, chars, legs, hips, np.full(2, 0.01))
    path = state.trajectories[0, legs]
    k = path.shape[1]
    np.testing.assert_allclose(path[:, 0], source)
    np.testing.assert_allclose(path[:, -1], point)
    third = int(np.ceil((k - 1) / 3.0))  # the first sample at or past a third of the way: risen
    np.testing.assert_allclose(path[:, third, 1], point[:, 1])
    assert (np.abs(path[:, third, [0, 2]] - source[:, [0, 2]]) < np.abs(point[:, [0, 2]] - source[:, [0, 2]])).all()
    assert state.tucked[0, legs].all() and not state.in_stance[0, legs].any()
    assert (state.swing_T[0, legs] == 3.0 * model.dt).all(), "a tuck lasts at least three frames: it never lands"


def test_a_tuck_point_inside_a_box_moves_in_to_the_first_clear_one(tmp_path):
    # Heading 0 (body forward +x, left +z). A tall box's near face runs along x, on the left, placed
    # so that the left feet at their first-choice tuck points (TUCK_REACH) would touch it and at the
    # next ones in would not; then closer, so that every choice touches it but the last.
    from footfall.planner._crowd import TUCK_LIFT, TUCK_REACHES, hips_world, tuck_points
    from footfall.planner._kernels_controller import foot_box_conflict

    model, state = _world(tmp_path, "tuck-box", crate_centre=(5.0, 5.0), crate_width=0.2, start=(0.0, 0.0),
                          goal=(4.0, 0.0))
    legs = np.arange(model.n_legs)
    chars = np.zeros(legs.size, np.int64)
    left = legs[model.rest_body[:, 1] > 0.0]
    hips = hips_world(model, state)
    height = model.creature.standing_height + model.hips_body[legs, 1]
    half_foot = (0.5 * model.creature.foot_length, 0.5 * model.creature.foot_width)

    def at(reach):
        rest = model.rest_body[legs]
        return np.column_stack([hips[0, legs, 0] + reach * (rest[:, 0] - model.hips_body[legs, 0]),
                                hips[0, legs, 1] - (1.0 - TUCK_LIFT) * height,
                                hips[0, legs, 2] + reach * (rest[:, 1] - model.hips_body[legs, 2])])

    assert TUCK_REACHES[0] == 0.25 and len(TUCK_REACHES) == 3
    for clear in (1, 2):
        width = 4.0
        # how far each foot reaches along z, its yaw included
        yaw = state.foot_yaws[0, legs]
        reach_z = half_foot[0] * np.abs(np.sin(yaw)) + half_foot[1] * np.abs(np.cos(yaw))
        face = float((at(TUCK_REACHES[clear])[:, 2] + reach_z)[left].max()) + 0.002  # clear by 2 mm
        boxes = (np.array([[0.0, 0.5, face + 0.5 * width]]), np.array([[width, 1.0, width]]), np.zeros(1),
                 np.ones(1, np.bool_), np.zeros(1, np.bool_))

        def touches(p, leg):
            return foot_box_conflict(*p, *half_foot, state.foot_yaws[0, leg], 0.0, *boxes[:4], np.ones(1, np.bool_))

        point = tuck_points(model, state, chars, legs, hips, boxes)
        # Each foot at its first choice that does not touch the box (here one always does).
        choices = [at(r) for r in TUCK_REACHES]
        chosen = [next((k for k in range(len(choices)) if not touches(choices[k][leg], leg)), len(choices) - 1)
                  for leg in legs]
        np.testing.assert_allclose(point, np.array([choices[k][leg] for leg, k in zip(legs, chosen)]), atol=1e-12)
        assert clear in chosen, "the case must need the rule up to this choice"
        assert not any(touches(point[leg], leg) for leg in legs)
        assert all(k == 0 for leg, k in zip(legs, chosen) if leg not in left), "the right feet stay out"
    # Without boxes (or with none near), every foot is held at the first choice.
    np.testing.assert_allclose(tuck_points(model, state, chars, legs, hips), at(TUCK_REACHES[0]), atol=1e-12)


def test_a_tucked_foot_is_pushed_out_of_a_box_across_its_nearest_side():
    # A point foot (no extent) 1 cm of clearance past the side: the boxes' sides by hand.
    from footfall.planner._kernels_controller import push_out_of_boxes

    def pushed(point, centre, size, yaw, forbidden=True, foot=(0.0, 0.0)):
        points = np.array([point], dtype=float)
        push_out_of_boxes(points, *foot, np.zeros(1), np.array([centre], dtype=float), np.array([size], dtype=float),
                          np.array([yaw]), np.array([forbidden]), 0.01, 4)
        return points[0]

    # Nearer the +x side (0.1 in) than the -z side (0.4 in): out across +x.
    np.testing.assert_allclose(pushed((0.4, 0.0, -0.1), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.0), [0.51, 0.0, -0.1])
    # Turned a quarter: the box's x axis runs along world +z, its z axis along world -x. The point is 0.2
    # in from the box's -z side (world +x) and 0.3 from its +x side (world +z): out across world +x.
    np.testing.assert_allclose(pushed((0.1, 0.0, 0.2), (0.0, 0.0, 0.0), (1.0, 1.0, 0.6), 0.5 * np.pi),
                               [0.31, 0.0, 0.2], atol=1e-12)
    # A foot 4 x 3 cm reaches its circumscribed radius (2.5 cm) past the side.
    np.testing.assert_allclose(pushed((0.4, 0.0, -0.1), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.0, foot=(0.02, 0.015)),
                               [0.535, 0.0, -0.1])
    # Above a box that is not forbidden, and outside one: left where it is.
    np.testing.assert_array_equal(pushed((0.4, 0.6, -0.1), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.0, forbidden=False),
                                  [0.4, 0.6, -0.1])
    np.testing.assert_array_equal(pushed((0.6, 0.0, -0.1), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.0), [0.6, 0.0, -0.1])


def _ants_walked_a_second(n):
    """(model, state) of ``n`` ants on flat ground after 30 frames of walking (LOD off)."""
    from footfall.planner import _crowd as crowd

    ant = load_creature("ant")
    model, state = init_crowd(load_scenario("flat"), ant, gait_schedule(ant), n_characters=n, seed=0, lod_mode="off")
    for _ in range(30):
        crowd.step(model, state)
    return model, state


def test_a_tucked_foot_rises_and_falls_with_its_body():
    # Tuck points are planned from the hips before the pelvis stage. A walking ant dropped 6 cm above its
    # pose: the pelvis stage brings it down (pelvis_rise < 0), and its tucked foot in the air comes down as
    # far (foot, swing path and target), so it keeps its height under the hip; an untucked foot in the air
    # and the stance feet stay where they were planned.
    from footfall.planner import _crowd as crowd

    model, state = _ants_walked_a_second(1)
    air = np.flatnonzero(~state.in_stance[0])
    assert air.size >= 2
    tucked, free = air[0], air[1]
    state.tucked[0, tucked] = True
    state.pelvis[0, 1] += 0.06
    before = (state.feet.copy(), state.trajectories.copy(), state.swing_target.copy())
    crowd.stage_pelvis(model, state)
    rise = float(state.pelvis_rise[0])
    assert rise < -0.03
    np.testing.assert_allclose(state.feet[0, tucked], before[0][0, tucked] + [0.0, rise, 0.0], atol=1e-12)
    np.testing.assert_allclose(state.trajectories[0, tucked], before[1][0, tucked] + [0.0, rise, 0.0], atol=1e-12)
    np.testing.assert_allclose(state.swing_target[0, tucked], before[2][0, tucked] + [0.0, rise, 0.0], atol=1e-12)
    others = np.arange(model.n_legs) != tucked
    np.testing.assert_array_equal(state.feet[0, others], before[0][0, others])
    np.testing.assert_array_equal(state.trajectories[0, free], before[1][0, free])


def test_a_body_lowers_as_far_as_a_foot_landing_next_frame_needs_to_be_in_reach():
    # Flat ground: the hull, and so the pelvis before the rule, do not depend on where on the ground a
    # landing point lies. A foot in the air whose landing point lies 1 cm too low for its hip (its
    # horizontal distance under the reach) lowers the body, when it lands within the next frame, until
    # it is LANDING_REACH_MARGIN inside the reach; three frames before its landing, or with the point
    # further across than the leg reaches, the body stays where the hull puts it.
    from footfall.planner import _crowd as crowd
    from footfall.planner._crowd import LANDING_REACH_MARGIN, hips_world

    model, state = _ants_walked_a_second(1)
    leg = int(np.flatnonzero(~state.in_stance[0] & ~state.tucked[0])[0])
    reach = float(model.reach[leg])
    dt = model.dt

    def pelvis_after(target_across, frames_left):
        s = copy.deepcopy(state)
        s.swing_t[0, leg] = s.swing_T[0, leg] - frames_left * dt
        hip = hips_world(model, s)[0, leg]
        s.swing_target[0, leg] = [hip[0] + target_across, 0.0, hip[2]]
        crowd.stage_pelvis(model, s, smoothing=1.0)
        return s, float(np.linalg.norm(hips_world(model, s)[0, leg] - s.swing_target[0, leg]))

    free, _ = pelvis_after(0.0, 0.0)
    height = float(hips_world(model, free)[0, leg, 1])  # the hip above the ground, as the hull puts it
    assert 0.01 < height < reach
    across = math.sqrt(reach ** 2 - (height - 0.01) ** 2)
    lowered, gap = pelvis_after(across, 1.0)
    assert gap == pytest.approx(reach - LANDING_REACH_MARGIN, abs=1e-9)
    drop = float(free.pelvis[0, 1] - lowered.pelvis[0, 1])
    assert drop == pytest.approx(height - math.sqrt((reach - LANDING_REACH_MARGIN) ** 2 - across ** 2), abs=1e-9)
    assert drop > 0.01
    assert float(lowered.pelvis_rise[0]) == pytest.approx(float(free.pelvis_rise[0]) - drop, abs=1e-12)
    assert lowered.counters["landing_drops"] == free.counters["landing_drops"] + 1
    early, gap = pelvis_after(across, 3.0)
    assert early.pelvis[0, 1] == free.pelvis[0, 1] and gap > reach
    beyond, gap = pelvis_after(reach + 0.001, 1.0)
    assert beyond.pelvis[0, 1] == free.pelvis[0, 1] and gap > reach
    assert early.counters["landing_drops"] == beyond.counters["landing_drops"] == free.counters["landing_drops"]


def _one_left_leg_tucked(tmp_path):
    """(model, state, chars, legs, hips, every tuck point of the spider's left middle leg (levels, 3) by
    reach, its hip, foot half extents, foot yaw): heading 0 (forward +x, left +z)."""
    from footfall.planner._crowd import TUCK_REACHES, hips_world, tuck_points

    model, state = _world(tmp_path, "tuck-one", crate_centre=(5.0, 5.0), crate_width=0.2, start=(0.0, 0.0),
                          goal=(4.0, 0.0))
    left = np.flatnonzero(model.rest_body[:, 1] > 0.0)
    leg = int(left[np.argmin(np.abs(model.rest_body[left, 0]))])
    chars, legs = np.zeros(1, np.int64), np.array([leg])
    hips = hips_world(model, state)
    reaches = model.tuck_reach.copy()
    levels = []
    for level in range(len(TUCK_REACHES)):
        model.tuck_reach[:] = reaches[:, [level] * reaches.shape[1]]
        levels.append(tuck_points(model, state, chars, legs, hips)[0])
    model.tuck_reach[:] = reaches
    half = (0.5 * model.creature.foot_length, 0.5 * model.creature.foot_width)
    return model, state, chars, legs, hips, np.array(levels), hips[0, leg], half, float(state.foot_yaws[0, leg])


def test_a_foot_with_no_clear_tuck_point_turns_about_its_hip_the_least_either_way(tmp_path):
    # The leg reaches no nearer than its first tuck point (as an ant's: every reach the first). A box 1 cm
    # wide along x, 3 mm ahead of it: the foot is held as far out, turned about its hip by the least
    # whole number of TUCK_TURN_STEPs that clears the box (here, back: the least turn ahead is greater).
    from footfall.planner._crowd import TUCK_TURN_STEP, TUCK_TURNS, _rot_xz, tuck_points
    from footfall.planner._kernels_controller import foot_box_conflict

    model, state, chars, legs, hips, levels, hip, half, yaw = _one_left_leg_tucked(tmp_path)
    model.tuck_reach[:] = model.tuck_reach[:, [0] * model.tuck_reach.shape[1]]
    levels[:] = levels[0]
    boxes = (np.array([[float(levels[0, 0]) + 0.003, 0.5, float(levels[0, 2])]]), np.array([[0.01, 1.0, 1.0]]), np.zeros(1),
             np.ones(1, np.bool_), np.zeros(1, np.bool_))

    def touches(p):
        return foot_box_conflict(*p, *half, yaw, 0.0, *boxes[:4], np.ones(1, np.bool_))

    def turned(angle):
        ox, oz = _rot_xz(angle, levels[-1, 0] - hip[0], levels[-1, 2] - hip[2])
        return np.array([hip[0] + ox, levels[-1, 1], hip[2] + oz])

    assert all(touches(p) for p in levels), "the case needs every reach covered"
    tries = [sign * k * TUCK_TURN_STEP for k in range(1, TUCK_TURNS + 1) for sign in (1.0, -1.0)]
    first = next(i for i, a in enumerate(tries) if not touches(turned(a)))
    assert first >= 2, "the case needs more than the least turn"
    assert touches(turned(-tries[first])), "the case needs one way alone"
    point = tuck_points(model, state, chars, legs, hips, boxes)[0]
    np.testing.assert_allclose(point, turned(tries[first]), atol=1e-12)
    assert not touches(point)


def test_a_foot_no_turn_clears_is_pushed_out_of_the_box_across_its_nearest_side(tmp_path):
    # A slab 4 m along x, 1 m across, its near long side 2 mm beyond every point the leg could turn to:
    # the foot is pushed from its last tuck point across that side, to its circumscribed radius and
    # TUCK_CLEARANCE past it.
    from footfall.planner._crowd import TUCK_CLEARANCE, TUCK_TURN_STEP, TUCK_TURNS, _rot_xz, tuck_points
    from footfall.planner._kernels_controller import foot_box_conflict

    model, state, chars, legs, hips, levels, hip, half, yaw = _one_left_leg_tucked(tmp_path)
    radius = math.hypot(*half)
    angles = np.arange(-TUCK_TURNS, TUCK_TURNS + 1) * TUCK_TURN_STEP
    ox, oz = _rot_xz(angles[:, None], levels[None, :, 0] - hip[0], levels[None, :, 2] - hip[2])
    low = float((hip[2] + oz).min()) - radius - 0.002
    boxes = (np.array([[0.0, 0.5, low + 0.5]]), np.array([[4.0, 1.0, 1.0]]), np.zeros(1), np.ones(1, np.bool_),
             np.zeros(1, np.bool_))
    point = tuck_points(model, state, chars, legs, hips, boxes)[0]
    np.testing.assert_allclose(point, [levels[-1, 0], levels[-1, 1], low - radius - TUCK_CLEARANCE], atol=1e-12)
    assert not foot_box_conflict(*point, *half, yaw, 0.0, *boxes[:4], np.ones(1, np.bool_))


def test_a_tucked_foot_whose_way_in_meets_a_box_at_the_frames_end_is_pushed_out_and_held(tmp_path):
    # The left middle foot tucks from where it stands. A box 2 cm across, 4 m along x, lies over where its
    # way in puts it at the frame's end (2 mm on its inner side), clear of where it stands and of its tuck
    # point: the foot is held, for the whole tuck, at that point pushed out across the box's inner side.
    import copy

    from footfall.planner._crowd import DT, TUCK_CLEARANCE, TUCK_FRAMES, tuck_swings
    from footfall.planner._kernels_controller import foot_box_conflict, swing_point

    model, state, chars, legs, hips, levels, hip, half, yaw = _one_left_leg_tucked(tmp_path)
    leg = int(legs[0])
    duration = np.array([TUCK_FRAMES * DT])
    free = copy.deepcopy(state)
    tuck_swings(model, free, chars, legs, hips, duration)
    path = free.trajectories[0, leg]
    then = np.array([swing_point(path, 1.0 / TUCK_FRAMES, d) for d in range(3)])
    centre = float(then[2]) - 0.002
    boxes = (np.array([[0.0, 0.5, centre]]), np.array([[4.0, 1.0, 0.02]]), np.zeros(1), np.ones(1, np.bool_),
             np.zeros(1, np.bool_))

    def touches(p):
        return foot_box_conflict(*p, *half, yaw, 0.0, *boxes[:4], np.ones(1, np.bool_))

    assert touches(then) and not touches(path[0]) and not touches(path[-1]), "the case needs the way in alone"
    tuck_swings(model, state, chars, legs, hips, duration, boxes)
    held = np.array([then[0], then[1], centre + 0.01 + math.hypot(*half) + TUCK_CLEARANCE])
    np.testing.assert_allclose(state.trajectories[0, leg], np.broadcast_to(held, path.shape), atol=1e-12)
    np.testing.assert_allclose(state.swing_target[0, leg], held, atol=1e-12)
    assert state.tucked[0, leg] and state.swing_T[0, leg] == TUCK_FRAMES * DT


def test_a_tuck_point_a_moving_box_covers_one_frame_on_is_not_chosen(tmp_path):
    # A crate 4 m wide closing on the spider's left side at 1 m/s (3.3 cm a frame), read when its near
    # face is 1 cm clear of the left feet's first tuck points: one frame on, where the feet are judged,
    # it covers some. They take the next reach in; the others keep the first. (Where the crate heads,
    # threat_horizon on, is checked too: set to 0, the test sees the frame on alone.)
    import dataclasses

    from footfall.planner._crowd import _boxes_now, hips_world, tuck_points
    from footfall.planner._kernels_controller import foot_box_conflict

    width = 4.0
    model, state = _world(tmp_path, "tuck-closing", crate_centre=(0.0, 1.0 + 0.5 * width), crate_width=width,
                          start=(0.0, 0.0), goal=(4.0, 0.0), velocity=(0.0, -1.0))
    model = dataclasses.replace(model, controller=dataclasses.replace(model.controller, threat_horizon=0.0))
    legs = np.arange(model.n_legs)
    chars = np.zeros(legs.size, np.int64)
    hips = hips_world(model, state)
    first = tuck_points(model, state, chars, legs, hips)
    yaw = state.foot_yaws[0, legs]
    hx, hz = 0.5 * model.creature.foot_length, 0.5 * model.creature.foot_width
    face = float((first[:, 2] + hx * np.abs(np.sin(yaw)) + hz * np.abs(np.cos(yaw))).max()) + 0.01
    state.t = 1.0 - face  # the face, at z = 1 m at t = 0, is there then
    now = _boxes_now(model, state.t)
    later = _boxes_now(model, state.t + model.dt)
    np.testing.assert_allclose(now[0][0, 2] - 0.5 * width, face, atol=1e-12)

    def touches(p, leg, boxes):
        return foot_box_conflict(*p, hx, hz, yaw[leg], 0.0, *boxes[:4], np.ones(1, np.bool_))

    covered = np.array([touches(first[leg], leg, later) for leg in legs])
    assert covered.any() and not any(touches(first[leg], leg, now) for leg in legs), "the case needs the frame on"
    point = tuck_points(model, state, chars, legs, hips, now)
    np.testing.assert_array_equal(point[~covered], first[~covered])
    assert not (point[covered] == first[covered]).all(axis=1).any()
    assert not any(touches(point[leg], leg, later) or touches(point[leg], leg, now) for leg in legs)


def _every_plan_fails(monkeypatch):
    """From now on every foot planned finds no valid couple (a foot walled in)."""
    import footfall.planner._crowd as crowd

    original = crowd._plan_groups

    def no_footprint(*args, **kwargs):
        out, groups = original(*args, **kwargs)
        out.valid[:] = False
        return out, groups

    monkeypatch.setattr(crowd, "_plan_groups", no_footprint)


def _escape_step_without_footprints(tmp_path, monkeypatch, escaping, prepare):
    """A spider standing still with every foot down, facing +x, its goal ahead; ``prepare(model, state,
    hips)`` sets up one left front foot and returns its leg. Then one frame in which the steering says
    it is (``escaping``) or is not in a moving box's lane, to leave to its left (+z), and every plan
    fails. Returns (state, leg, heading before the frame)."""
    import footfall.planner._crowd as crowd
    from footfall.planner._crowd import hips_world

    model, state = _world(tmp_path, "escape", crate_centre=(5.0, 5.0), crate_width=0.2, start=(0.0, 0.0),
                          goal=(0.0, 0.0))
    for _ in range(30):  # every foot down
        step(model, state)
    state.heading[:] = 0.0
    state.route[0] = [4.0, 0.0]  # not at its goal: a character there stops turning
    state.in_stance[0] = True
    state.wants_swing[0] = False
    leg = prepare(model, state, hips_world(model, state))

    def lane_exit(model, state, direction, boxes, box_velocity):
        return np.array([[0.0, 1.0]]), np.array([escaping])

    monkeypatch.setattr(crowd, "_lane_exit", lane_exit)
    _every_plan_fails(monkeypatch)
    # At the asked speed: asked for its flee speed from standing, another leg's look-ahead fails too
    # (it cannot follow the body), and that foot, the worse, steps first: the case is the one foot.
    monkeypatch.setattr(crowd, "FLEE_SPEED", 0.0)
    heading = float(state.heading[0])
    step(model, state)
    monkeypatch.undo()
    return state, leg, heading


def _left_front_leg(model):
    return int(np.flatnonzero((model.hips_body[:, 0] > 0) & (model.hips_body[:, 2] > 0))[0])


def test_a_stance_foot_that_stops_an_escape_and_finds_no_footprint_is_tucked(tmp_path, monkeypatch):
    # Its left front foot stands on the midline margin (STANCE_SIDE_MARGIN of its hip's offset from
    # the midline): a left turn would carry it across, so it bounds the turn to 0 and must step. No
    # footprint is found anywhere (every plan fails). Escaping, the foot is tucked (it leaves the
    # ground, the turn is free of it); not escaping, it stays down (a hold) and keeps the turn at 0.
    from footfall.planner._crowd import STANCE_SIDE_MARGIN, leg_turn_bounds

    def on_the_margin(model, state, hips):
        leg = _left_front_leg(model)
        state.feet[0, leg, 2] = state.pelvis[0, 2] + STANCE_SIDE_MARGIN * model.hips_body[leg, 2]
        state.feet[0, leg, 0] = max(state.feet[0, leg, 0], hips[0, leg, 0] + 0.05)
        assert leg_turn_bounds(model, state)[0, leg] == 0.0  # premise: no room for a left turn
        return leg

    state, leg, _ = _escape_step_without_footprints(tmp_path, monkeypatch, True, on_the_margin)
    assert state.tucked[0, leg] and not state.in_stance[0, leg]
    assert state.blocks_escape[0, leg]
    # Only feet that stop the escape (bound it to 0, or below half the turn asked of a body standing).
    assert not (state.tucked[0] & ~state.blocks_escape[0]).any()
    state, leg, heading = _escape_step_without_footprints(tmp_path, monkeypatch, False, on_the_margin)
    assert state.in_stance[0, leg] and not state.tucked[0].any()
    assert state.heading[0] == heading


def test_a_foot_its_leg_cannot_follow_that_finds_no_footprint_is_tucked_when_escaping(tmp_path, monkeypatch):
    # Its left front leg lost its foot in the last frame (``unfollowed``: the pose was taken back), so
    # the foot must step, and no footprint is found. Escaping a moving box's lane, the foot is tucked:
    # held down it would hold the body in the lane (mixed, 8 spiders, seed 28: a crate's path covered
    # every spot three right legs could reach; they planned no footprint for 25 frames and the crate
    # ran over them). Not escaping, it stays down (a hold), as before.
    def lost(model, state, hips):
        leg = _left_front_leg(model)
        state.unfollowed[0, leg] = True
        return leg

    state, leg, _ = _escape_step_without_footprints(tmp_path, monkeypatch, True, lost)
    assert state.tucked[0, leg] and not state.in_stance[0, leg] and state.blocks_escape[0, leg]
    assert not (state.tucked[0] & ~state.blocks_escape[0]).any()
    state, leg, _ = _escape_step_without_footprints(tmp_path, monkeypatch, False, lost)
    assert state.in_stance[0, leg] and not state.tucked[0].any() and state.counters["holds"] > 0


@pytest.mark.parametrize("neighbour", [False, True])
def test_an_escape_whose_orca_velocity_points_back_turns_to_the_lane_exits_side(tmp_path, monkeypatch, neighbour):
    # A spider standing dead centre in the lane of a 0.6 m crate that comes at it along -x, facing it
    # (heading +x): the lane exit squares its way out of the lane, to one side. ORCA's velocity
    # (stubbed here) points back along the lane and a little to the other side: as such a velocity
    # crossed behind the spider its angle flipped between +2.9 and -2.9 rad and the spider turned
    # back and forth on the spot while the crate came (34 foot-frames on the 1200-frame crates-moving
    # run). Alone, the spider turns to the exit's side and walks only as far along its heading as
    # that velocity goes (0: it points back). With a neighbour within four avoid radii, ORCA's
    # velocity (which knows of it) leads: the spider turns toward it, to the other side. (The lane exit's
    # own rule and ORCA's velocity: the look-ahead, planner._escape, keeps both.)
    monkeypatch.setattr("footfall.planner._escape.ESCAPE_KEEP", math.inf)
    import footfall.planner._crowd as crowd
    from footfall.planner._crowd import _boxes_now

    model, state = _world(tmp_path, "back", crate_centre=(1.0, 0.0), crate_width=0.6, start=(0.0, 0.0),
                          goal=(4.0, 0.0), velocity=(-0.25, 0.0))
    exits = []
    lane_exit = crowd._lane_exit

    def recorded_exit(*a, **k):
        direction, in_lane = lane_exit(*a, **k)
        exits.append(direction[0].copy())
        return direction, in_lane

    def back_to_the_other_side(*a, **k):
        side = np.sign(exits[-1][1])  # the exit's side along z (it squares out of a lane along x)
        return (np.array([[-0.2, -0.02 * side]]), np.array([True]), np.array([neighbour]),
                (np.zeros(2, np.int64), np.zeros(0, np.int64)))

    monkeypatch.setattr(crowd, "_lane_exit", recorded_exit)
    monkeypatch.setattr(crowd, "_avoid", back_to_the_other_side)
    stage_steer(model, state, _boxes_now(model, state.t))
    side = np.sign(exits[-1][1])
    assert state.escaping[0] and side != 0.0 and abs(exits[-1][0]) < 1e-12  # square out of the lane
    if neighbour:
        assert np.sign(state.turn_wanted[0]) == -side
    else:
        assert np.sign(state.turn_wanted[0]) == side
        assert state.speed[0] == 0.0


@pytest.mark.parametrize("seed", fresh_seeds([0, 1, 2], 3, salt=91))
def test_the_lane_kernel_is_the_lane_rule_written_out_in_numpy(seed):
    # planner._kernels_lanes.lane_threats against the rule written out here with whole arrays (as the
    # steering computed it before the kernel): random characters and boxes, every output bit for bit.
    from footfall.planner._kernels_lanes import lane_threats

    rng = np.random.default_rng(seed)
    n, b = int(rng.integers(1, 60)), int(rng.integers(1, 6))
    pelvis = rng.uniform(-3.0, 3.0, (n, 2))
    speed, heading = rng.uniform(0.0, 0.5, n) * (rng.random(n) > 0.2), rng.uniform(-np.pi, np.pi, n)
    way = rng.normal(size=(n, 2))
    way /= np.hypot(*way.T)[:, None]
    way[0] = [0.0, 1.0]  # a way with no part across a lane along x (the dead-centre tie)
    centres = rng.uniform(-3.0, 3.0, (b, 2))
    velocity = rng.normal(size=(b, 2)) * 0.3
    velocity[0] = [0.25, 0.0]
    pelvis[0] = centres[0] + [1.0, 0.0]  # dead centre of box 0's lane, ahead of it
    box_speed = np.hypot(*velocity.T)
    u = velocity / box_speed[:, None]
    side_axis = np.column_stack([-u[:, 1], u[:, 0]])
    half_along, half_across = rng.uniform(0.1, 0.5, b), rng.uniform(0.1, 0.5, b)
    room, horizon = 0.38, 3.0

    rel = pelvis[:, None] - centres[None]
    along, across = (rel * u[None]).sum(-1), (rel * side_axis[None]).sum(-1)
    walk = speed[:, None] * (np.cos(heading)[:, None] * u[None, :, 0] + np.sin(heading)[:, None] * u[None, :, 1])
    closing = box_speed[None] + np.maximum(-walk, 0.0)
    threat = ((np.abs(across) < half_across[None] + room) & (along > -(half_along[None] + room))
              & (along - half_along[None] - room < closing * horizon))
    way_side = (way[:, None, :] * side_axis[None]).sum(-1)
    side = np.where(np.abs(across) > 1e-6, np.sign(across), np.where(way_side > 0.0, 1.0, -1.0))
    ahead = np.maximum((way[:, None, :] * u[None]).sum(-1), 0.0)
    each_exit = side[..., None] * side_axis[None] + 0.5 * ahead[..., None] * u[None]
    exit_way = (each_exit * threat[..., None]).sum(axis=1)

    got = (np.empty((n, b), np.bool_), np.empty((n, b)), np.empty((n, b, 2)), np.empty((n, 2)))
    lane_threats(pelvis, speed, np.cos(heading), np.sin(heading), way, centres, u, side_axis, half_along, half_across,
                 box_speed, room, horizon, *got)
    assert threat[0, 0] and side[0, 0] == 1.0, "the dead-centre case is in the draw (its way leans to +z)"
    for name, mine, expected in zip(("threat", "side", "each_exit", "exit_way"), got, (threat, side, each_exit, exit_way)):
        np.testing.assert_array_equal(mine, expected, err_msg=f"seed {seed}: {name}")


def test_a_walker_never_steps_into_a_body_in_its_way_even_where_its_velocity_would(tmp_path, monkeypatch):
    # ORCA linearises each neighbour's velocity obstacle about the walker's velocity along its heading;
    # a walker still turning toward its preferred velocity walked into a spider standing in its way
    # (1000 spiders, mixed, seed 2: 122 overlapping frames). Here ORCA is stubbed to return the preferred
    # velocity, straight at B: A stops where its next step would bring the two body boxes (0.25 x 0.15
    # m, both facing +x; BODY_GAP_FRAMES frames at top speed apart) into each other, and not before.
    import footfall.planner._crowd as crowd

    path = tmp_path / "pair.toml"
    path.write_text(WORLD.format(name="pair", crate=CRATE.format(centre=[5.0, 5.0], width=0.2, motion=""),
                                 start=[0.0, 0.0], goal=[3.0, 0.0], speed=0.3))
    creature = load_creature("spider")
    real_avoid = crowd._avoid

    def no_orca(model, state, preferred, *rest):
        _, avoided, near, neighbours = real_avoid(model, state, preferred, *rest)
        return preferred.copy(), np.zeros_like(avoided), near, neighbours

    monkeypatch.setattr(crowd, "_avoid", no_orca)
    boxes = (np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, np.bool_), np.zeros(0, np.bool_))

    def a_step(air, pull=0.0):
        """A's move along x, B's body ``air`` m beyond the grown contact, A walking at 0.3 m/s at B (or,
        ``pull`` > 0, standing with its feet's feedback pulling it ``pull`` m toward B)."""
        model, state = init_crowd(load_scenario(str(path)), creature, gait_schedule(creature), n_characters=2, seed=0)
        grown = crowd.BODY_GAP_FRAMES * model.top_speed * model.dt
        places = np.array([[0.0, 0.0], [0.25 + grown + air, 0.0]])
        shift = places - state.pelvis[:, [0, 2]]
        state.pelvis[:, [0, 2]] += shift
        state.feet[:, :, [0, 2]] += shift[:, None, :]
        state.heading[:] = 0.0
        state.speed[:] = [0.0 if pull else 0.3, 0.0]
        state.desired_speed[:] = [0.0 if pull else 0.3, 0.0]
        state.body_held[:] = False
        state.feedback[:] = [[pull, 0.0], [0.0, 0.0]]
        before = state.pelvis[0, 0]
        crowd.stage_steer(model, state, boxes)
        return state.pelvis[0, 0] - before

    step = a_step(0.05)
    assert 0.002 < step < 0.05 * 0.5  # the premise: far enough, A walks on (a few mm a frame)
    assert a_step(0.5 * step) == 0.0  # half a step of air left: A stops
    assert a_step(1.5 * step) == pytest.approx(step, abs=1e-9)  # a step and a half: it takes its step
    # The feet's pull (feedback, paper §3.2) moves no body into another either.
    pull = 0.2  # well above the threshold (0.15 rest radius): moves the pelvis feedback_gain x dt of it
    moved = a_step(0.05, pull)
    assert 0.002 < moved < 0.05
    assert a_step(0.5 * moved, pull) == 0.0


def test_no_character_is_spawned_where_a_crate_will_be_within_the_spawn_horizon(tmp_path):
    # A 0.3 m crate at (-3, 0) moving +x at 0.5 m/s is at the spawn centre (-2, 0) at t = 2 s. Standing
    # still, it is 1 m away and the spider spawns on the centre (the spiral's first point); moving, every
    # spawn point stays its half diagonal + the crowd radius + 0.1 m from where it is over the crowd's
    # spawn_clear_s (the default, 3 s; the other encounters here set it to 0). A spider spawned 0.5 m before
    # a crate coming at it was run over in its first second (1000 spiders, mixed, seed 0).
    from footfall.planner._crowd import crowd_radius, spawn_positions

    creature = load_creature("spider")
    for velocity in (None, (0.5, 0.0)):
        path = tmp_path / f"spawn-{velocity is None}.toml"
        motion = "" if velocity is None else f"motion = {{ kind = \"velocity\", velocity = {list(velocity)} }}"
        world = WORLD.replace("spawn_clear_s = 0.0", "")
        path.write_text(world.format(name="spawn", crate=CRATE.format(centre=[-3.0, 0.0], width=0.3, motion=motion),
                                     start=[-2.0, 0.0], goal=[4.0, 0.0], speed=0.3))
        scenario = load_scenario(str(path))
        assert scenario.crowd.spawn_clear_s == 3.0
        spawned = spawn_positions(scenario, creature, 5)
        if velocity is None:
            assert spawned[0].tolist() == [-2.0, 0.0]
            continue
        times = np.linspace(0.0, scenario.crowd.spawn_clear_s, 301)
        crate = np.column_stack([-3.0 + 0.5 * times, np.zeros_like(times)])
        gap = np.hypot(*(spawned[:, None, :] - crate[None, :, :]).transpose(2, 0, 1)).min()
        # The crate moves 5 cm between the 0.1 s samples: up to half that nearer in between.
        assert gap > 0.5 * math.hypot(0.3, 0.3) + crowd_radius(creature) + 0.1 - 0.05 * 0.5
        assert not np.any(np.all(spawned == [-2.0, 0.0], axis=1))


def test_a_moving_box_that_reaches_a_foot_in_the_air_shoves_the_body_and_its_feet_in_the_air():
    # One spider at the origin, leg 0 in the air at (0.15, 0.05); a 0.2 m crate (moving, yaw 0) whose -x
    # face is 5 mm beyond that foot. The crate's nearest point to the pelvis is on that face, so the body
    # goes straight -x, by the foot's half diagonal and the margin less the 5 mm; the foot in the air
    # (and its swing) goes with it, the stance feet stay. A crate 1 cm further than that shoves nothing.
    from footfall.planner import _crowd as crowd

    spider = load_creature("spider")
    model, state = init_crowd(load_scenario("flat"), spider, gait_schedule(spider), n_characters=1, seed=0)
    state.pelvis[0, [0, 2]] = 0.0
    state.in_stance[0] = True
    state.in_stance[0, 0] = False
    state.feet[0, 0, [0, 2]] = [0.15, 0.05]
    state.trajectories[0, 0, :, 0], state.trajectories[0, 0, :, 2] = 0.15, 0.05
    state.swing_target[0, 0, [0, 2]] = [0.15, 0.05]
    need = 0.5 * math.hypot(spider.foot_length, spider.foot_width) + crowd.SHOVE_MARGIN

    def crate(gap):
        return (np.array([[0.15 + gap + 0.1, 0.1, 0.05]]), np.array([[0.2, 0.2, 0.2]]), np.zeros(1),
                np.ones(1, np.bool_), np.ones(1, np.bool_))

    before = (state.pelvis.copy(), state.feet.copy(), state.trajectories.copy(), state.swing_target.copy())
    crowd.shove_out_of_moving_boxes(model, state, crate(need + 0.01))
    assert state.counters["shoves"] == 0 and not state.shoved[0]
    np.testing.assert_array_equal(state.pelvis, before[0])
    np.testing.assert_array_equal(state.feet, before[1])

    crowd.shove_out_of_moving_boxes(model, state, crate(0.005))
    push = np.array([-(need - 0.005), 0.0])
    assert state.counters["shoves"] == 1 and state.shoved[0]
    np.testing.assert_allclose(state.pelvis[0, [0, 2]], before[0][0, [0, 2]] + push, atol=1e-12)
    assert state.pelvis[0, 1] == before[0][0, 1]
    np.testing.assert_allclose(state.feet[0, 0, [0, 2]], [0.15 + push[0], 0.05], atol=1e-12)
    np.testing.assert_allclose(state.trajectories[0, 0][:, [0, 2]], [[0.15 + push[0], 0.05]] * state.trajectories.shape[2],
                               atol=1e-12)
    np.testing.assert_allclose(state.swing_target[0, 0, [0, 2]], [0.15 + push[0], 0.05], atol=1e-12)
    np.testing.assert_array_equal(state.feet[0, 1:], before[1][0, 1:])  # the stance feet stay
    # The foot in the air now keeps exactly the margin from the crate's face.
    assert (0.15 + 0.005) - (0.15 + push[0]) == pytest.approx(need, abs=1e-12)


def test_a_foot_a_shove_carries_onto_another_characters_foot_plans_again():
    # A shove carries a landing foot's target along onto ground no one checked. Two walking ants; ant 0,
    # one foot a frame from landing, is shoved. With ant 1's stance foot just inside a foot's room (the
    # search's block radius) of that target, that foot, and no other, plans again (kind 3, landing or
    # not); just outside it, or with ant 0 not shoved, it lands as planned (kind 0).
    from footfall.planner import _crowd as crowd
    from footfall.planner._crowd import stage_requests

    model, state = _ants_walked_a_second(2)
    air = np.flatnonzero(~state.in_stance[0])
    assert air.size and state.in_stance[1].any()
    a, b = int(air[0]), int(np.flatnonzero(state.in_stance[1])[0])
    state.swing_t[0, air] = state.swing_T[0, air] - model.dt  # about to land: no re-plan for a turn or speed
    none = (np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, np.bool_), np.zeros(0, np.bool_))
    args = (np.zeros_like(state.in_stance), none, crowd.hips_world(model, state), np.array([1.0]))

    def kinds_after(shoved, gap):
        state.feet[1, b, [0, 2]] = state.swing_target[0, a, [0, 2]] + [gap, 0.0]
        state.shoved[:] = [shoved, False]
        crowd._landings_shoved_onto_feet(model, state)
        return stage_requests(model, state, *args)[0, air]

    room = model.creature.foot_room
    expected = np.where(air == a, 3, 0)
    np.testing.assert_array_equal(kinds_after(True, room - 0.001), expected)
    assert state.shoved_onto_feet.sum() == 1
    np.testing.assert_array_equal(kinds_after(True, room + 0.001), 0)
    np.testing.assert_array_equal(kinds_after(False, room - 0.001), 0)
    # The next shove stage clears the marks (a box far off shoves nothing).
    kinds_after(True, room - 0.001)
    far = (np.array([[50.0, 0.1, 0.0]]), np.array([[0.2, 0.2, 0.2]]), np.zeros(1), np.ones(1, np.bool_),
           np.ones(1, np.bool_))
    crowd.shove_out_of_moving_boxes(model, state, far)
    assert not state.shoved.any() and not state.shoved_onto_feet.any()


def _spider_standing_at_the_origin():
    """(model, state, need) of one spider at the origin, heading +x, every foot down; ``need``: how far a
    shove keeps a foot in the air or its hip from a box (the foot's half diagonal and SHOVE_MARGIN)."""
    from footfall.planner import _crowd as crowd

    spider = load_creature("spider")
    model, state = init_crowd(load_scenario("flat"), spider, gait_schedule(spider), n_characters=1, seed=0)
    state.pelvis[0, [0, 2]] = 0.0
    state.heading[0] = state.pitch[0] = state.roll[0] = 0.0
    state.in_stance[0] = True
    return model, state, 0.5 * math.hypot(spider.foot_length, spider.foot_width) + crowd.SHOVE_MARGIN


def _lift_leg_1_behind_its_hip(state, hip):
    """Leg 1 in the air, its foot (and swing) 0.1 m behind its hip ``hip`` (-x)."""
    state.in_stance[0, 1] = False
    state.feet[0, 1, [0, 2]] = [hip[0] - 0.1, hip[2]]
    state.trajectories[0, 1, :, 0], state.trajectories[0, 1, :, 2] = hip[0] - 0.1, hip[2]


def test_a_replan_that_turns_its_foot_into_a_box_where_it_is_waits():
    # A re-plan turns a foot in the air to the plan's yaw where it is. The spider's foot (3 x 2 cm) in the
    # air at (0.3, 0.05, 0.1); a forbidden box whose -z face is 1.2 cm beyond it. Along x (yaw 0) the foot
    # reaches 1 cm across: clear; turned a quarter (yaw pi/2) it reaches 1.5 cm: into the box, and that
    # re-plan waits. A new plan (a foot lifting, checked by its path) and a stance foot are not asked.
    from footfall.planner._crowd import replans_turned_into_boxes

    model, state, _ = _spider_standing_at_the_origin()
    state.in_stance[0, 1] = False
    state.feet[0, 1] = [0.3, 0.05, 0.1]
    state.feet[0, 0] = [0.3, 0.0, 0.1]  # a stance foot at the same spot
    box = (np.array([[0.3, 0.5, 0.1 + 0.012 + 0.1]]), np.array([[0.4, 1.0, 0.2]]), np.zeros(1),
           np.ones(1, np.bool_), np.zeros(1, np.bool_))
    cs, ls = np.zeros(4, np.int64), np.array([1, 1, 1, 0])
    replans = np.array([True, True, False, True])
    yaws = np.array([0.0, 0.5 * np.pi, 0.5 * np.pi, 0.5 * np.pi])
    np.testing.assert_array_equal(replans_turned_into_boxes(model, state, cs, ls, replans, yaws, box),
                                  [False, True, False, False])
    no_boxes = tuple(a[:0] for a in box)
    assert not replans_turned_into_boxes(model, state, cs, ls, replans, yaws, no_boxes).any()


def test_a_moving_box_that_reaches_the_hip_of_a_leg_in_the_air_shoves_the_body_as_far():
    # The same spider, leg 1 in the air (its hip at x = 0.02 m), its foot tucked in 0.1 m behind that hip
    # (-x); a crate 0.2 m deep and 1 m wide whose -x face is 5 mm beyond that hip (+x). The foot is 0.105 m
    # from the face, clear by far; the hip is not, and the IK draws a foot held near its hip anywhere about
    # it. The body goes straight -x until that hip keeps the foot's half diagonal and the margin from the
    # face. Only the legs in the air count: the stance legs 0 and 4, their hips at x = 0.045 m inside the
    # crate, would push it 2.5 cm further; with every foot down nothing moves.
    from footfall.planner import _crowd as crowd

    model, state, need = _spider_standing_at_the_origin()
    hips = crowd.hips_world(model, state)[0]
    hip = hips[1]
    assert abs(hip[2]) < 0.5 and hips[[0, 4], 0].min() > hip[0] + 0.02  # the pelvis projects onto the -x face
    crate = (np.array([[hip[0] + 0.005 + 0.1, 0.1, hip[2]]]), np.array([[0.2, 0.2, 1.0]]), np.zeros(1),
             np.ones(1, np.bool_), np.ones(1, np.bool_))
    crowd.shove_out_of_moving_boxes(model, state, crate)  # every foot on the ground: nothing to shove
    assert state.counters["shoves"] == 0 and state.pelvis[0, 0] == 0.0

    _lift_leg_1_behind_its_hip(state, hip)
    before = state.feet.copy()
    crowd.shove_out_of_moving_boxes(model, state, crate)
    assert state.counters["shoves"] == 1
    np.testing.assert_allclose(state.pelvis[0, [0, 2]], [-(need - 0.005), 0.0], atol=1e-12)
    np.testing.assert_allclose(state.feet[0, 1, [0, 2]], [hip[0] - 0.1 - (need - 0.005), hip[2]], atol=1e-12)
    np.testing.assert_array_equal(state.feet[0, [0, *range(2, 8)]], before[0, [0, *range(2, 8)]])  # stance feet stay
    # That hip now keeps exactly that distance from the face.
    moved = crowd.hips_world(model, state)[0, 1]
    assert (hip[0] + 0.005) - moved[0] == pytest.approx(need, abs=1e-12)


def test_a_moving_box_shoves_a_tucked_legs_hip_its_tuck_distance_clear():
    # The spider of the hip test, leg 1 in the air, its foot 0.1 m behind its hip. The crate's -x face is
    # the foot's half diagonal, the margin and 5 mm beyond that hip: untucked, nothing moves. Tucked, the
    # hip keeps its innermost tuck point's distance (reach x the rest offset from the hip) more: the body
    # goes straight -x by exactly what it lacks (the folded leg reaches no nearer point; nearer, the IK
    # drew an ant's tucked foot 1-3 cm into a crate: mixed, 64 ants, seed 2, character 34).
    from footfall.planner import _crowd as crowd

    model, state, need = _spider_standing_at_the_origin()
    hip = crowd.hips_world(model, state)[0, 1]
    _lift_leg_1_behind_its_hip(state, hip)
    fold = math.hypot(*crowd._tuck_offset(model, state.feet_spacing[0], 1, model.tuck_reach[1, -1]))
    assert fold > 0.01
    crate = (np.array([[hip[0] + need + 0.005 + 0.1, 0.1, hip[2]]]), np.array([[0.2, 0.2, 1.0]]), np.zeros(1),
             np.ones(1, np.bool_), np.ones(1, np.bool_))
    crowd.shove_out_of_moving_boxes(model, state, crate)
    assert state.counters["shoves"] == 0 and state.pelvis[0, 0] == 0.0
    state.tucked[0, 1] = True
    crowd.shove_out_of_moving_boxes(model, state, crate)
    assert state.counters["shoves"] == 1
    np.testing.assert_allclose(state.pelvis[0, [0, 2]], [-(fold - 0.005), 0.0], atol=1e-12)
    moved = crowd.hips_world(model, state)[0, 1]
    assert (hip[0] + need + 0.005) - moved[0] == pytest.approx(need + fold, abs=1e-12)


def test_a_swing_meets_a_moving_box_only_where_the_box_is_when_the_foot_gets_there():
    # A straight swing along x from 0 to 0.4 m on 5 samples, 0.4 s long, frames of 0.1 s: the foot is
    # at x = 0.1, 0.2, 0.3, 0.4 on the frames to come (advance_swings moves it at constant speed). A
    # 0.1 m box (forbidden: every height) whose near face is 5 mm from the swing's line overlaps the
    # 2 cm foot only where the foot is beside it on that frame.
    from footfall.planner._kernels_controller import swings_meet_moving_boxes

    path = np.zeros((1, 5, 3))
    path[0, :, 0] = np.linspace(0.0, 0.4, 5)
    far = np.array([9.0, 0.0, 9.0])

    def meets(box_on_frame, swing_t=0.0, moving=True):
        """The box at ``box_on_frame[j]`` (x) on frame j + 1 (far away when None)."""
        centres = np.array([[[far if x is None else [x, 0.0, 0.055]][0]] for x in box_on_frame], dtype=float)
        out = np.zeros(1, np.bool_)
        swings_meet_moving_boxes(path, np.array([swing_t]), np.array([0.4]), 0.1, 0.01, 0.01, np.zeros(1),
                                 centres, np.zeros((len(box_on_frame), 1)), np.array([[0.1, 1.0, 0.1]]),
                                 np.ones(1, np.bool_), np.array([moving]), out)
        return bool(out[0])

    assert meets([None, 0.2, None, None])  # beside the foot on frame 2, when the foot is at x = 0.2
    assert not meets([None, None, 0.2, None])  # there on frame 3: the foot is at 0.3, 4 cm past its face
    assert not meets([0.2, None, None, None])  # there on frame 1: the foot is at 0.1, 4 cm short of it
    assert meets([None, None, None, 0.4])  # on the landing spot when the foot lands
    assert not meets([None, 0.2, None, None], moving=False)  # static boxes are the maps' business
    # Half way through (swing_t 0.2 s) the frames to come put the foot at 0.3 and then 0.4.
    assert meets([0.3, None], swing_t=0.2)
    assert not meets([0.1, None], swing_t=0.2)
    assert not meets([None, 0.3], swing_t=0.2)


def test_a_tucked_foot_beside_a_moving_crate_never_swings_into_it():
    # 64 ants on mixed, seed 1: a tucked foot beside a crate moving at 0.34 m/s was re-planned on a path
    # a millimetre from the crate, and the next re-plan ran it in (frames 452-453, character 57).
    from footfall.scenarios._gait_choice import resolve_gait

    scenario, creature = load_scenario("mixed"), load_creature("ant")
    gait, _, _ = resolve_gait(None, creature)
    model, state = init_crowd(scenario, creature, gait, n_characters=64, seed=1)
    counters = FrameCounters(model, state)
    in_boxes = []
    for _ in range(470):
        before = counters.collisions
        step(model, state)
        counters.update(state)
        in_boxes.append(counters.collisions - before)
    assert sum(in_boxes) == 0, [f for f, n in enumerate(in_boxes) if n]


@pytest.mark.parametrize("name", ["ant", "spider", "robot5"])
def test_every_tuck_point_is_one_its_leg_reaches_and_the_nearest_such_to_the_asked(name):
    # A tucked foot is held TUCK_REACHES of its rest offset out from its hip, TUCK_LIFT of the hip's height
    # above the ground. An ant's folded leg does not reach that near its hip: at 0.05 the IK drew the foot
    # 2.5-3 cm off its tuck point, 0.6 cm into the crate the tuck point kept clear of (mixed, 64 ants, seed
    # 3, character 19, frame 439). Each leg's reaches (model.tuck_reach) are the asked ones where the IK
    # reaches them (the spider: all), else the nearest reached one out from them, in TUCK_REACH_STEP steps.
    from footfall.planner._crowd import TUCK_LIFT, TUCK_REACHES, hips_world, tuck_points
    from footfall.planner._ik import legs_of, solve_legs
    from footfall.planner._workspace import REACH_TOLERANCE, TUCK_REACH_STEP

    creature = load_creature(name)
    model, state = init_crowd(load_scenario("flat"), creature, gait_schedule(creature), n_characters=1, seed=0)
    legs = legs_of(creature)
    n = model.n_legs
    hips_body, rest = model.hips_body, model.rest_body
    up = hips_body[:, 1] - (1.0 - TUCK_LIFT) * (creature.standing_height + hips_body[:, 1])

    def missed(reach):
        """(L,) m: how far the IK (level body, body frame) leaves each foot from its tuck point at ``reach``."""
        target = np.column_stack([hips_body[:, 0] + reach * (rest[:, 0] - hips_body[:, 0]), up,
                                  hips_body[:, 2] + reach * (rest[:, 1] - hips_body[:, 2])])
        result = solve_legs(hips_body, np.broadcast_to(np.eye(3), (n, 3, 3)), legs.rest_azimuths, legs.segment_lengths,
                            legs.limits, legs.azimuth_limits, target, max_iterations=48, restarts=8,
                            plane_rolls=legs.plane_rolls)
        return result.residual

    reaches = model.tuck_reach
    assert reaches.shape == (n, len(TUCK_REACHES))
    for level, asked in enumerate(TUCK_REACHES):
        got = reaches[:, level]
        assert (got >= asked - 1e-12).all()
        assert (missed(got) < REACH_TOLERANCE).all(), (level, got)
        moved = got > asked + 1e-12
        assert (missed(got - TUCK_REACH_STEP)[moved] > REACH_TOLERANCE).all(), "not the nearest reached one"
    if name == "spider":
        np.testing.assert_array_equal(reaches, np.tile(TUCK_REACHES, (n, 1)))
    if name == "ant":
        assert (missed(np.full(n, TUCK_REACHES[-1])) > 0.01).all()  # the premise: the asked innermost one is not reached
    # tuck_points holds the feet there (heading 0: body forward +x, left +z; no box: the first reach).
    chars, every = np.zeros(n, np.int64), np.arange(n)
    hips = hips_world(model, state)
    point = tuck_points(model, state, chars, every, hips)
    np.testing.assert_allclose(point[:, [0, 2]] - hips[0, :, [0, 2]].T,
                               reaches[:, :1] * (rest - hips_body[:, [0, 2]]), atol=1e-12)


def test_a_shoved_body_pushes_the_bodies_it_runs_into_by_the_same_move():
    # Three spiders heading 0 (+x), placed by hand along -x: spider 0 at the origin with leg 0 in the air, spider 1 just behind it (its body box 1 mm clear of
    # 0's), spider 2 far behind. A crate 5 mm beyond 0's foot in the air shoves 0 straight -x by
    # need - 5 mm (as the test above): 0's body now overlaps 1's, so 1 goes by the same move (its feet in
    # the air too, its stance feet stay); 2, which 1 does not reach, stays. Without neighbours (or with
    # none near) only 0 moves.
    from footfall.planner import _crowd as crowd
    from footfall.planner._kernels_geometry import rects_overlap

    spider = load_creature("spider")
    model, state = init_crowd(load_scenario("flat"), spider, gait_schedule(spider), n_characters=3, seed=0)
    length = float(spider.body_box[0])
    state.heading[:] = 0.0
    state.pelvis[:, [0, 2]] = [[0.0, 0.0], [-(length + 0.001), 0.0], [-3.0, 0.0]]
    state.in_stance[:] = True
    state.in_stance[[0, 1], 0] = False
    state.feet[0, 0, [0, 2]] = [0.15, 0.05]
    state.trajectories[0, 0, :, 0], state.trajectories[0, 0, :, 2] = 0.15, 0.05
    need = 0.5 * math.hypot(spider.foot_length, spider.foot_width) + crowd.SHOVE_MARGIN
    crate = (np.array([[0.15 + 0.005 + 0.1, 0.1, 0.05]]), np.array([[0.2, 0.2, 0.2]]), np.zeros(1),
             np.ones(1, np.bool_), np.ones(1, np.bool_))
    neighbours = (np.array([0, 2, 4, 6]), np.array([1, 2, 0, 2, 0, 1]))  # everyone's neighbours: the others
    push = np.array([-(need - 0.005), 0.0])
    assert push[0] < -0.001  # the premise: 0's shove is more than the 1 mm gap

    def shoved(with_neighbours):
        s = crowd.CrowdState(**{f: (v.copy() if isinstance(v, np.ndarray) else v) for f, v in vars(state).items()})
        s.counters = dict(state.counters)
        crowd.shove_out_of_moving_boxes(model, s, crate, neighbours if with_neighbours else None)
        return s

    alone = shoved(False)
    np.testing.assert_allclose(alone.pelvis[0, [0, 2]] - state.pelvis[0, [0, 2]], push, atol=1e-12)
    np.testing.assert_array_equal(alone.pelvis[1:], state.pelvis[1:])
    hx, hz = 0.5 * length, 0.5 * float(spider.body_box[1])
    assert rects_overlap(*alone.pelvis[0, [0, 2]], hx, hz, 0.0, *alone.pelvis[1, [0, 2]], hx, hz, 0.0)  # 0 in 1

    both = shoved(True)
    for c in (0, 1):
        np.testing.assert_allclose(both.pelvis[c, [0, 2]] - state.pelvis[c, [0, 2]], push, atol=1e-12)
        np.testing.assert_allclose(both.feet[c, 0, [0, 2]] - state.feet[c, 0, [0, 2]], push, atol=1e-12)
        np.testing.assert_array_equal(both.feet[c, 1:], state.feet[c, 1:])  # the stance feet stay
    np.testing.assert_array_equal(both.pelvis[2], state.pelvis[2])
    np.testing.assert_array_equal(both.pelvis[:, 1], state.pelvis[:, 1])
    assert both.counters["shoves"] == 1  # the box shoved one body; the other was pushed
    assert not rects_overlap(*both.pelvis[0, [0, 2]], hx, hz, 0.0, *both.pelvis[1, [0, 2]], hx, hz, 0.0)


def test_a_standing_ant_may_not_turn_its_body_into_a_neighbour_7_cm_beside_it():
    # Two ants (bodies 0.12 x 0.04 m) side by side, both heading +x, 7 cm apart along z: 3 cm of air. Their
    # grown boxes (bodies_apart's, for steps) already touch, so a turn is checked on the bodies themselves.
    # Turned 0.3 rad toward the other, the front corner rises to 0.06 sin 0.3 + 0.02 cos 0.3 = 0.037 m,
    # short of the other's side at 0.05 m; turned 0.8 rad, to 0.043 + 0.014 = 0.057 m: into it (mixed, 64
    # ants, seed 3: a standing ant turned into its neighbour while the grown boxes let it).
    from footfall.planner import _crowd as crowd
    from footfall.planner._kernels_avoidance import neighbour_lists

    ant = load_creature("ant")
    model, state = init_crowd(load_scenario("flat"), ant, gait_schedule(ant), n_characters=2, seed=0)
    assert tuple(ant.body_box[:2]) == (0.12, 0.04)
    state.heading[:] = 0.0
    state.pelvis[:, [0, 2]] = [[0.0, 0.0], [0.0, 0.07]]
    neighbours = neighbour_lists(np.ascontiguousarray(state.pelvis[:, [0, 2]]), 1.0)
    assert not crowd.bodies_apart(model, state, np.array([[0.0, 0.001], [0.0, 0.0]]), neighbours)[0]  # grown: touching

    def clear(turn):
        return crowd.bodies_turn_clear(model, state, np.array([turn, 0.0]), neighbours).tolist()

    assert clear(0.3) == [True, True]
    assert clear(0.8) == [False, True]
    assert clear(-0.8) == [False, True]  # the back corner rises as far
    assert clear(0.0) == [True, True]
