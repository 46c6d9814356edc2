"""The look-ahead of a way out of a moving box's lane (planner._escape, planner._kernels_escape):
the kernel's cost on grids small enough to add up by hand, and the two choices that use it."""

import math

import numpy as np
import pytest

from conftest import fresh_seeds
from footfall.planner._kernels_escape import escape_costs as kernel

REACH = 0.1
STEP = 0.1


def _costs(pelvis, heading, speed, pace, targets, paths, half, yaws=None, lane_cost=0.0, turn_step=10.0,
           accel_step=10.0):
    """The kernel on one character (R = 1); ``paths`` (T, B, 2)."""
    paths = np.ascontiguousarray(paths, dtype=np.float64)
    yaws = np.zeros(paths.shape[1]) if yaws is None else np.asarray(yaws, dtype=np.float64)
    out = np.empty((1, len(targets)))
    kernel(np.array([pelvis], dtype=np.float64), np.array([heading], dtype=np.float64),
           np.array([speed], dtype=np.float64), np.array([pace], dtype=np.float64),
           np.array([targets], dtype=np.float64), turn_step, accel_step, STEP, REACH, paths,
           np.ascontiguousarray(half, dtype=np.float64), np.cos(yaws), np.sin(yaws), lane_cost, out)
    return out[0]


def test_a_body_standing_within_reach_of_a_box_pays_its_depth_at_every_step_earlier_ones_more():
    # A static box (half extents 0.1) centred at x = 0.15: its face is at 0.05 from a body at the
    # origin that stands still (pace 0), 0.05 inside the reach 0.1. Three steps weighted 1 - j / 4:
    # 0.05 x (0.75 + 0.5 + 0.25) = 0.075 for either heading.
    paths = np.tile([[0.15, 0.0]], (3, 1, 1))
    np.testing.assert_allclose(_costs((0.0, 0.0), 0.0, 0.0, 0.0, [0.0, math.pi], paths, [[0.1, 0.1]]),
                               [0.075, 0.075], atol=1e-15)


def test_walking_toward_a_box_costs_the_steps_within_reach_and_walking_away_costs_nothing():
    # Walking at 0.4 m/s (already at pace, turns instant): after steps 1-3 at x = 0.04, 0.08, 0.12 toward
    # a face at 0.2: gaps 0.16, 0.12, 0.08, so only step 3 is 0.02 inside the reach: 0.02 x 0.25. Away
    # (pi): -0.04, -0.08, -0.12, gaps 0.24 and more: 0.
    paths = np.tile([[0.3, 0.0]], (3, 1, 1))
    np.testing.assert_allclose(_costs((0.0, 0.0), 0.0, 0.4, 0.4, [0.0, math.pi], paths, [[0.1, 0.1]]),
                               [0.005, 0.0], atol=1e-15)


def test_a_way_into_a_box_costs_the_full_reach_from_there_on():
    # At 1 m/s toward a wall 0.04 m thick (faces at x = 0.18 and 0.22): after step 1 (x = 0.1) the gap is
    # 0.08 (depth 0.02, weight 0.75); after step 2 (x = 0.2) the body is inside, and no body walks
    # through a box: steps 2 and 3 cost the full reach, 0.015 + 0.1 x (0.5 + 0.25) = 0.09. (Through it,
    # at x = 0.3 after step 3, 0.08 beyond, it would have cost 0.015 + 0.05 + 0.005 = 0.07.)
    paths = np.tile([[0.2, 0.0]], (3, 1, 1))
    np.testing.assert_allclose(_costs((0.0, 0.0), 0.0, 1.0, 1.0, [0.0], paths, [[0.02, 0.1]]), [0.09], atol=1e-15)


def test_a_way_that_ends_before_a_moving_box_in_its_lane_pays_the_lane_cost():
    # A box 0.2 m wide travels +x at 1 m/s along z = 0: after steps 1-3 its centre is at x = -0.42,
    # -0.32, -0.22, its face 0.12 from a body standing at the origin (never within the reach 0.1).
    # Standing there, in its lane and ahead of it, costs the lane cost; beside its lane (z = 0.25 > half
    # 0.1 + reach 0.1) or behind it (x = -3), nothing.
    paths = np.array([[[-0.52 + 0.1 * j, 0.0]] for j in range(1, 4)])
    for pelvis, expected in (((0.0, 0.0), 0.7), ((0.0, 0.25), 0.0), ((-3.0, 0.0), 0.0)):
        assert _costs(pelvis, 0.0, 0.0, 0.0, [0.0], paths, [[0.1, 0.1]], lane_cost=0.7)[0] == expected


def test_a_turn_takes_its_time_and_the_body_walks_only_as_far_as_it_faces_the_way():
    # Heading 0, way pi/2, at most 0.5 rad a step: after one step the heading is 0.5 with 1.07 rad still
    # to turn, so the body walks pace x cos(1.07) along its heading 0.5 (not along the way). A 2 m box
    # whose face is 0.05 beyond where that step ends, along +x, is 0.05 inside the reach: one step
    # weighted 1 - 1/2.
    heading, turn, pace = 0.0, 0.5, 0.4
    h = heading + turn
    v = pace * math.cos(math.pi / 2 - h)
    x, z = v * math.cos(h) * STEP, v * math.sin(h) * STEP
    paths = np.array([[[x + 0.05 + 1.0, z]]])
    got = _costs((0.0, 0.0), heading, 0.0, pace, [math.pi / 2], paths, [[1.0, 1.0]], turn_step=turn)
    np.testing.assert_allclose(got, [0.05 * 0.5], atol=1e-15)


@pytest.mark.parametrize("seed", fresh_seeds([0, 1, 2], 3, salt=331))
def test_the_kernel_is_the_rule_written_out_in_numpy(seed):
    # Random bodies, ways and boxes (static and moving, yawed), every cost against the module doc's
    # rule written out here step by step.
    rng = np.random.default_rng(seed)
    n_steps, n_boxes, n_ways = int(rng.integers(2, 8)), int(rng.integers(1, 5)), int(rng.integers(1, 6))
    pelvis, heading = rng.uniform(-0.5, 0.5, 2), rng.uniform(-math.pi, math.pi)
    speed, pace = rng.uniform(0.0, 0.5), rng.uniform(0.0, 0.5)
    targets = rng.uniform(-math.pi, math.pi, n_ways)
    start = rng.uniform(-1.0, 1.0, (n_boxes, 2))
    velocity = rng.uniform(-0.5, 0.5, (n_boxes, 2)) * (rng.random(n_boxes) < 0.7)[:, None]
    paths = start[None] + STEP * np.arange(1, n_steps + 1)[:, None, None] * velocity[None]
    half, yaws = rng.uniform(0.05, 0.3, (n_boxes, 2)), rng.uniform(-math.pi, math.pi, n_boxes)
    turn_step, accel_step, lane_cost = rng.uniform(0.05, 0.5), rng.uniform(0.01, 0.2), 0.3
    got = _costs(pelvis, heading, speed, pace, targets, paths, half, yaws, lane_cost, turn_step, accel_step)

    def gap(p, c, hb, yaw):
        d = p - c
        along = abs(d[0] * math.cos(yaw) + d[1] * math.sin(yaw)) - hb[0]
        across = abs(-d[0] * math.sin(yaw) + d[1] * math.cos(yaw)) - hb[1]
        return math.hypot(max(along, 0.0), max(across, 0.0))

    def wrap(a):
        return (a + math.pi) % (2 * math.pi) - math.pi

    for k, target in enumerate(targets):
        h, v, p, cost, blocked = heading, speed, pelvis.copy(), 0.0, False
        for j in range(n_steps):
            h += np.clip(wrap(target - h), -turn_step, turn_step)
            wanted = pace * max(math.cos(np.clip(wrap(target - h), -math.pi / 2, math.pi / 2)), 0.0)
            v += np.clip(wanted - v, -accel_step, accel_step)
            p = p + v * STEP * np.array([math.cos(h), math.sin(h)])
            depth = max([0.0] + [REACH - gap(p, paths[j, b], half[b], yaws[b]) for b in range(n_boxes)])
            weight = 1.0 - (j + 1) / (n_steps + 1)
            if depth >= REACH:
                cost += REACH * sum(1.0 - (i + 1) / (n_steps + 1) for i in range(j, n_steps))
                blocked = True
                break
            cost += depth * weight
        if not blocked:
            # Only the boxes the body could come within reach of (at most its pace or speed, whichever is faster).
            near = [b for b in range(n_boxes)
                    if any(np.hypot(*(paths[j, b] - pelvis)) - np.hypot(*half[b]) - max(pace, speed) * (j + 1) * STEP
                           < REACH for j in range(n_steps))]
            for b in near:
                u = paths[-1, b] - paths[-2, b]
                if np.hypot(*u) < 1e-6 * STEP:
                    continue
                u = u / np.hypot(*u)
                side = np.array([-u[1], u[0]])
                axes = np.array([[math.cos(yaws[b]), math.sin(yaws[b])], [-math.sin(yaws[b]), math.cos(yaws[b])]])
                along_reach = half[b] @ np.abs(axes @ u)
                across_reach = half[b] @ np.abs(axes @ side)
                rel = p - paths[-1, b]
                if abs(rel @ side) < across_reach + REACH and rel @ u > -(along_reach + REACH):
                    cost += lane_cost
                    break
        assert got[k] == pytest.approx(cost, abs=1e-12), f"seed {seed}, way {k}"


def _crate_world(tmp_path, crate_centre, velocity, width=0.2):
    from footfall.planner._crowd import init_crowd
    from footfall.scenarios import load_creature, load_scenario
    from footfall.scenarios._gait_schedule import gait_schedule
    from test_encounters import CRATE, WORLD

    motion = f'motion = {{ kind = "velocity", velocity = {[float(v) for v in velocity]} }}'
    path = tmp_path / "crate.toml"
    path.write_text(WORLD.format(name="crate", crate=CRATE.format(centre=[float(c) for c in crate_centre], width=width,
                                                                  motion=motion),
                                 start=[-4.0, 3.0], goal=[4.0, 3.0], speed=0.3))
    spider = load_creature("spider")
    return init_crowd(load_scenario(str(path)), spider, gait_schedule(spider), n_characters=1, seed=0)


def test_a_lane_exit_behind_the_body_gives_way_to_one_it_can_reach_in_time(tmp_path):
    # The ant of mixed, seed 1 (frame 370), drawn for a spider: a crate 0.2 m wide, 0.42 m away ahead
    # and to the left (+x, +z), comes at it at 0.29 m/s along (-0.56, -0.83). The spider faces +x.
    # Squared out of the lane to the side it is on, its way points 2.7 rad away from its heading: the
    # look-ahead finds that way runs into the crate (the turn takes 2.6 s at 0.7 x 1.5 rad/s) and picks
    # a cheaper heading, the cheapest of all it tries.
    from footfall.planner._crowd import flee_speed
    from footfall.planner._escape import ESCAPE_KEEP, escape_costs, escape_ways

    u = np.array([-0.56, -0.83]) / np.hypot(-0.56, -0.83)
    model, state = _crate_world(tmp_path, (0.0, 0.0), 0.29 * u)
    state.t = 0.0
    state.pelvis[0, [0, 2]] = -np.array([0.318, 0.277])  # the crate, at the origin now, is 0.42 m ahead-left
    state.heading[0], state.speed[0] = 0.0, 0.3
    rows, boxes = np.array([0]), np.array([True])
    side = np.array([-u[1], u[0]])
    behind = -side if (state.pelvis[0, [0, 2]] @ side) < 0 else side  # the side the body is on
    assert abs(math.atan2(behind[1], behind[0])) > 2.5  # premise: that way is behind the body
    own = np.array([[1.0, 0.0]])
    flee = flee_speed(model, state, rows)
    way = escape_ways(model, state, rows, behind[None], own, flee, boxes)[0]
    angles = np.array([[math.atan2(behind[1], behind[0]), math.atan2(way[1], way[0])]
                       + list(np.arange(24) * 2 * math.pi / 24)])
    cost = escape_costs(model, state, rows, angles, flee, boxes)[0]
    assert cost[0] > cost[1] + ESCAPE_KEEP
    assert cost[1] == pytest.approx(cost.min(), abs=1e-12)


def test_a_lane_exit_that_stays_clear_is_kept(tmp_path):
    # A crate coming head-on along -x at 0.3 m/s from 1.2 m: squared out to +z the way stays clear of it
    # (and ends out of its lane); the look-ahead keeps exactly that way.
    from footfall.planner._crowd import flee_speed
    from footfall.planner._escape import escape_costs, escape_ways

    model, state = _crate_world(tmp_path, (1.2, 0.0), (-0.3, 0.0))
    state.t = 0.0
    state.pelvis[0, [0, 2]] = 0.0
    state.heading[0], state.speed[0] = 0.0, 0.0
    rows = np.array([0])
    way = escape_ways(model, state, rows, np.array([[0.0, 1.0]]), np.array([[1.0, 0.0]]), flee_speed(model, state, rows),
                      np.array([True]))
    np.testing.assert_array_equal(way, [[math.cos(math.pi / 2), 1.0]])
    assert escape_costs(model, state, rows, np.array([[math.pi / 2]]), flee_speed(model, state, rows),
                        np.array([True]))[0, 0] == 0.0


def test_orca_is_left_only_for_a_way_that_costs_less_and_only_clear_of_the_others(tmp_path):
    from footfall.planner._crowd import flee_speed
    from footfall.planner._escape import clear_of_others, orca_worse

    model, state = _crate_world(tmp_path, (0.6, 0.0), (-0.3, 0.0))
    state.t = 0.0
    state.pelvis[0, [0, 2]] = 0.0
    state.heading[0], state.speed[0] = 0.0, 0.0
    rows, boxes = np.array([0]), np.array([True])
    flee = flee_speed(model, state, rows)
    # ORCA's velocity straight on into the crate is worse than the way out to +z; the same way is not.
    assert orca_worse(model, state, rows, np.array([[0.0, 1.0]]), np.array([[0.3, 0.0]]), flee, boxes).tolist() == [True]
    assert orca_worse(model, state, rows, np.array([[0.0, 1.0]]), np.array([[0.0, 0.3]]), flee, boxes).tolist() == [False]
    # Alone, any way is clear of the others.
    assert clear_of_others(model, state, rows, np.array([[1.0, 0.0]])).tolist() == [True]


def test_clear_of_others_is_the_closest_approach_within_the_horizon(tmp_path):
    # Two characters: 0 at the origin walks +x at 1 m/s, 1 stands at (2, 0) (speed 0). Their closest
    # approach within CLEAR_HORIZON (1 s) is at 1 s, 1.0 m apart: clear iff 1.0 > 2 avoid radii. Walking
    # -x instead they only part: clear.
    from footfall.planner._crowd import init_crowd
    from footfall.planner._escape import CLEAR_HORIZON, clear_of_others
    from footfall.scenarios import default_gait, load_creature, load_scenario

    assert CLEAR_HORIZON == 1.0
    spider = load_creature("spider")
    model, state = init_crowd(load_scenario("flat"), spider, default_gait(spider), n_characters=2, seed=0)
    state.pelvis[:, [0, 2]] = [[0.0, 0.0], [2.0, 0.0]]
    state.speed[:] = 0.0
    rows = np.array([0])
    assert clear_of_others(model, state, rows, np.array([[1.0, 0.0]]))[0] == (1.0 > 2.0 * model.avoid_radius)
    assert clear_of_others(model, state, rows, np.array([[-1.0, 0.0]]))[0]
    # Closer: 1 stands at (1.2, 0), so walking +x passes within 0.2 m (at 1 s the two are 0.2 apart).
    state.pelvis[1, [0, 2]] = [1.2, 0.0]
    assert not clear_of_others(model, state, rows, np.array([[1.0, 0.0]]))[0]



def test_box_centres_over_many_times_by_hand():
    # Three boxes: static at (5, 0.1, 5); at 0.5 m/s along +x from the origin; looping at 1 m/s round the
    # unit square (0,0) -> (1,0) -> (1,1) -> (0,1) -> back (4 m). At t = -0.5, 0.5, 1.5, 2.999, 4.25 the mover
    # is at x = -0.25, 0.25, 0.75, 1.4995, 2.125 and the looper at (0, 0.5) (half a metre before closing the
    # loop), (0.5, 0), (1, 0.5), (0.001, 1) (a millimetre before the square's last corner), (0.25, 0).
    # A fourth loops at 2 m/s round a triangle of three waypoints (loops of different lengths walked at
    # once): (0,0) -> (3,0) -> (0,4) -> back (3 + 5 + 4 = 12 m), at 11, 1, 3 (its corner), 5.998 and 8.5 m:
    # (0, 1), (1, 0), (3, 0), (3 - 3 x 0.5996, 4 x 0.5996), (0, 3.5). poses_at gives each time's row.
    from footfall.scenarios import Obstacles

    square = [[0.0, 0.1, 0.0], [1.0, 0.1, 0.0], [1.0, 0.1, 1.0], [0.0, 0.1, 1.0]]
    triangle = [[0.0, 0.1, 0.0], [3.0, 0.1, 0.0], [0.0, 0.1, 4.0]]
    boxes = Obstacles([[5.0, 0.1, 5.0], [0.0, 0.1, 0.0], [0.0, 0.1, 0.0], [0.0, 0.1, 0.0]], [[0.2, 0.2, 0.2]] * 4,
                      [0.0] * 4, [True] * 4, motion_kind=[0, 1, 2, 2],
                      velocities=[[0.0] * 3, [0.5, 0.0, 0.0], [0.0] * 3, [0.0] * 3],
                      waypoints=[np.zeros((0, 3)), np.zeros((0, 3)), square, triangle],
                      waypoint_speed=[0.0, 0.0, 1.0, 2.0])
    times = [-0.5, 0.5, 1.5, 2.999, 4.25]
    expected = np.array([[[5.0, 0.1, 5.0], [-0.25, 0.1, 0.0], [0.0, 0.1, 0.5], [0.0, 0.1, 1.0]],
                         [[5.0, 0.1, 5.0], [0.25, 0.1, 0.0], [0.5, 0.1, 0.0], [1.0, 0.1, 0.0]],
                         [[5.0, 0.1, 5.0], [0.75, 0.1, 0.0], [1.0, 0.1, 0.5], [3.0, 0.1, 0.0]],
                         [[5.0, 0.1, 5.0], [1.4995, 0.1, 0.0], [0.001, 0.1, 1.0], [3.0 - 3.0 * 0.5996, 0.1, 4.0 * 0.5996]],
                         [[5.0, 0.1, 5.0], [2.125, 0.1, 0.0], [0.25, 0.1, 0.0], [0.0, 0.1, 3.5]]])
    np.testing.assert_allclose(boxes.centres_over(times), expected, atol=1e-12)
    for t, row in zip(times, expected):
        np.testing.assert_allclose(boxes.poses_at(t)[0], row, atol=1e-12)
