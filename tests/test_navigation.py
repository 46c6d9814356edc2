"""The way round static boxes (``planner._navigation``): hand-checked graphs, random boxes, and the
stuck character it exists for."""

from __future__ import annotations

import math

import numpy as np
import pytest

from footfall.planner._navigation import NODE_EPS, _clear, aim_points, shortest_way, way_around
from conftest import fresh_seeds

UNIT = (np.zeros((1, 2)), np.ones((1, 2)), np.zeros(1))  # a 1 m square box at the origin


def test_a_clear_line_aims_at_the_target_itself():
    way = way_around(*UNIT, 0.5)
    aims, blocked = aim_points(way, np.array([[-3.0, 2.0], [-3.0, -1.0]]), np.array([[3.0, 2.0], [3.0, -1.0]]))
    # z = -1 runs along the grown box's edge (its half extent 0.5 + 0.5): touching is not entering.
    assert aims.tolist() == [[3.0, 2.0], [3.0, -1.0]]
    assert blocked.tolist() == [False, False]


def test_a_box_in_the_way_is_rounded_by_its_nearer_side():
    """Start (-3, 0), target (3, z): through the +z corners when the target is on that side, the -z
    ones otherwise; the way's length is the sum of its three segments."""
    way = way_around(*UNIT, 0.5)
    e = 1.0 + NODE_EPS
    up = shortest_way(way, (-3.0, 0.0), (3.0, 0.2))
    down = shortest_way(way, (-3.0, 0.0), (3.0, -0.2))
    np.testing.assert_allclose(up, [[-3.0, 0.0], [-e, e], [e, e], [3.0, 0.2]], atol=1e-12)
    np.testing.assert_allclose(down, [[-3.0, 0.0], [-e, -e], [e, -e], [3.0, -0.2]], atol=1e-12)
    aims, blocked = aim_points(way, np.array([[-3.0, 0.0]]), np.array([[3.0, 0.2]]))
    np.testing.assert_allclose(aims, [[-e, e]], atol=1e-12)
    assert blocked.tolist() == [True]


def test_a_rotated_box_turns_its_corners_with_it():
    # The unit box turned a quarter: its grown corners are the same square's, in another order.
    way = way_around(np.zeros((1, 2)), np.array([[1.0, 3.0]]), np.array([math.pi / 2]), 0.5)
    # Local x (1 m) now lies along world z and local z (3 m) along world x: the grown box spans x in
    # [-2, 2] and z in [-1, 1].
    np.testing.assert_allclose(np.sort(np.abs(way.nodes), axis=0), [[2.0, 1.0]] * 4, atol=1e-6)
    way_round = shortest_way(way, (-1.5, -3.0), (-1.5, 3.0))
    np.testing.assert_allclose(way_round[1:-1], [[-2.0, -1.0], [-2.0, 1.0]], atol=1e-5)


def test_two_boxes_closer_than_the_clearance_make_one_wall():
    """A 1 m box and a 2 m wide one 0.4 m apart, grown by 0.5 m: the gap between them is closed, the
    small box's two inner corners lie inside the wide one's grown box (no nodes), and the way goes
    round the outside of both."""
    way = way_around(np.array([[0.0, -0.7], [0.0, 0.7]]), np.array([[1.0, 1.0], [2.0, 1.0]]), np.zeros(2), 0.5)
    assert way.nodes.shape == (6, 2)
    path = shortest_way(way, (-3.0, 0.0), (3.0, 0.0))
    # Round the small box (|z| = 1.7 at x = +-1) rather than the wide one (|z| = 1.7 at x = +-1.5).
    np.testing.assert_allclose(path[1:-1], [[-1.0, -1.7], [1.0, -1.7]], atol=1e-5)


def test_a_character_inside_a_grown_box_walks_out_and_a_walled_target_is_aimed_at():
    way = way_around(*UNIT, 0.5)
    # At 0.8 m from the centre the character is inside the grown box (1.0), 0.3 m from the box itself: it
    # may walk out (to the grown corners), but not through the box to a target beyond it.
    path = shortest_way(way, (-0.8, 0.1), (3.0, 0.1))
    e = 1.0 + NODE_EPS
    np.testing.assert_allclose(path[1:-1], [[-e, e], [e, e]], atol=1e-12)
    # Beside the box, 0.3 m off its face, its way to a target further along the face is straight ...
    assert shortest_way(way, (-0.8, 0.1), (-0.8, 3.0)).shape == (2, 2)
    # ... but not to one past the corner along a line 0.2 m off the next face: nearer the box than the
    # character is, where ORCA's disc (the clearance's 1 / 1.2) could not pass; it rounds the grown corner.
    path = shortest_way(way, (-0.8, 0.7), (3.0, 0.7))
    np.testing.assert_allclose(path[1:-1], [[-e, e], [e, e]], atol=1e-12)
    # A target inside a closed ring of boxes: no way; the aim is the target itself.
    ring = way_around(np.array([[0.0, 2.0], [0.0, -2.0], [2.0, 0.0], [-2.0, 0.0]]),
                      np.array([[5.0, 1.0], [5.0, 1.0], [1.0, 5.0], [1.0, 5.0]]), np.zeros(4), 0.3)
    assert shortest_way(ring, (-6.0, 0.0), (0.0, 0.0)) is None
    aims, blocked = aim_points(ring, np.array([[-6.0, 0.0]]), np.array([[0.0, 0.0]]))
    assert aims.tolist() == [[0.0, 0.0]] and blocked.tolist() == [True]


def test_a_kept_corner_is_searched_again_on_its_turn_or_when_reached():
    way = way_around(*UNIT, 0.5)
    node = np.full(1, -1, np.int64)
    start, target = np.array([[-3.0, 0.0]]), np.array([[3.0, 0.2]])
    aims, _ = aim_points(way, start, target, node, frame=0, refresh_frames=4)
    first = int(node[0])
    assert first >= 0
    # Moved to the other side of the box's axis: the kept corner is still aimed at until its turn ...
    moved = np.array([[-3.0, -0.5]])
    again, _ = aim_points(way, moved, target, node, frame=1, refresh_frames=4)
    np.testing.assert_array_equal(again, aims)
    # ... which comes every 4th frame (frame + index = 4): the way is searched again from where it
    # stands (now round the -z side: 6.39 m against 6.65 m round the +z side).
    fresh, _ = aim_points(way, moved, target, node, frame=4, refresh_frames=4)
    assert fresh[0, 1] < 0.0 and int(node[0]) != first
    with pytest.raises(ValueError, match="refresh_frames"):
        aim_points(way, start, target, node, refresh_frames=0)


@pytest.mark.parametrize("seed", fresh_seeds([0, 1, 2, 3], 2, salt=31))
def test_random_ways_enter_no_grown_box_and_are_no_longer_than_a_detour_bound(seed):
    """Random boxes, random start and target outside them: every segment of the way enters no grown box,
    the way is at least the straight distance, and its first corner is what aim_points aims at."""
    rng = np.random.default_rng(seed)
    b = int(rng.integers(1, 12))
    centres = rng.uniform(-5.0, 5.0, (b, 2))
    sizes = rng.uniform(0.1, 1.0, (b, 2))
    yaws = rng.uniform(-math.pi, math.pi, b)
    way = way_around(centres, sizes, yaws, float(rng.uniform(0.05, 0.5)))
    for _ in range(20):
        p, q = rng.uniform(-7.0, 7.0, 2), rng.uniform(-7.0, 7.0, 2)
        path = shortest_way(way, p, q)
        if path is None:
            continue
        for k in range(path.shape[0] - 1):
            a, c = path[k], path[k + 1]
            assert _clear(a[0], a[1], c[0], c[1], way.centres, way.half, way.cos_yaw, way.sin_yaw, way.clearance,
                          k == 0, k == path.shape[0] - 2), f"seed {seed}: segment {k} of {path.tolist()} enters a box"
        length = np.hypot(*np.diff(path, axis=0).T).sum()
        assert length >= np.hypot(*(q - p)) - 1e-9, f"seed {seed}"
        aims, _ = aim_points(way, p[None], q[None])
        np.testing.assert_array_equal(aims[0], path[1], err_msg=f"seed {seed}")


def _margins(points, centres, sizes, yaws):
    """(P, B) m: how far each point is outside each box itself along the box's axes (the larger of the
    two; 0 inside), computed here from the boxes' poses, not by the module."""
    rel = points[:, None, :] - centres[None, :, :]
    c, s = np.cos(yaws)[None, :], np.sin(yaws)[None, :]
    u = c * rel[..., 0] + s * rel[..., 1]
    v = -s * rel[..., 0] + c * rel[..., 1]
    return np.maximum(np.maximum(np.abs(u) - 0.5 * sizes[None, :, 0], np.abs(v) - 0.5 * sizes[None, :, 1]), 0.0)


@pytest.mark.parametrize("seed", fresh_seeds([0, 1, 2, 3], 2, salt=131))
def test_a_way_from_near_a_box_never_comes_nearer_it_than_orcas_disc_or_the_start(seed):
    """A character nearer a box than the clearance: no point of its way's first segment comes nearer that
    box than ORCA's disc (the clearance / 1.2) or than the start itself, whichever is nearer; no point
    of the way enters another grown box; and a target inside a box is reached straight when nothing
    else is in the way. (Blocked only where it entered the box itself, a robot5 0.42 m from a crate
    was sent past the crate's corner 0.12 m from it, which its 0.40 m disc cannot pass, and stood.)"""
    from footfall.planner._navigation import CLEARANCE_FACTOR

    rng = np.random.default_rng(seed)
    b = int(rng.integers(1, 8))
    centres = rng.uniform(-4.0, 4.0, (b, 2))
    sizes = rng.uniform(0.2, 1.0, (b, 2))
    yaws = rng.uniform(-math.pi, math.pi, b)
    clearance = float(rng.uniform(0.2, 0.6))
    body = clearance / CLEARANCE_FACTOR
    way = way_around(centres, sizes, yaws, clearance)
    checked = 0
    for _ in range(40):
        k = int(rng.integers(b))
        # A start just off box k: on a random side, within the clearance.
        p = centres[k] + rng.uniform(-1.0, 1.0, 2) * (0.5 * sizes[k].max() + clearance)
        start = _margins(p[None], centres, sizes, yaws)[0]
        if not (0.0 < start[k] < clearance) or (start < clearance)[np.arange(b) != k].any():
            continue
        q = rng.uniform(-6.0, 6.0, 2)
        if (_margins(q[None], centres, sizes, yaws)[0] < clearance).any():
            continue
        path = shortest_way(way, p, q)
        if path is None:
            continue
        checked += 1
        t = np.linspace(0.0, 1.0, 201)[:, None]
        first = path[0] + t * (path[1] - path[0])
        near = _margins(first, centres, sizes, yaws)[:, k].min()
        assert near >= min(body, start[k]) - 1e-6, f"seed {seed}: {path.tolist()} comes {near:.4f} m near box {k}"
        rest = np.vstack([path[j] + t * (path[j + 1] - path[j]) for j in range(1, path.shape[0] - 1)] or [path[-1:]])
        assert (_margins(rest, centres, sizes, yaws) >= clearance - 1e-6).all(), f"seed {seed}: {path.tolist()}"
    assert checked >= 3, f"seed {seed}: only {checked} starts near a box"
    # A target inside a box, nothing else in the way: straight there (no way existed before).
    unit = way_around(*UNIT, 0.5)
    assert shortest_way(unit, (-3.0, 0.1), (0.0, 0.0)).tolist() == [[-3.0, 0.1], [0.0, 0.0]]


def test_bad_clearance_is_refused_naming_it():
    with pytest.raises(ValueError, match="clearance"):
        way_around(*UNIT, -1.0)


BEHIND_A_CRATE = """name = "behind-a-crate"
[terrain]
kind = "flat"
size = [12.0, 12.0]
cell_size = 0.05
[[obstacles]]
centre = [0.0, 0.0]
size = [0.6, 0.5, 2.0]
kind = "forbidden"
[crowd]
creature = "quadruped"
centre = [-2.0, 0.0]
heading = 0.0
speed = 0.3
goal = [2.5, 0.0]
"""


def _behind_a_crate(tmp_path, navigate: bool):
    from footfall.planner import init_crowd
    from footfall.scenarios import default_gait, load_creature, load_scenario

    from footfall.planner import ControllerConfig

    path = tmp_path / "behind-a-crate.toml"
    path.write_text(BEHIND_A_CRATE)
    quadruped = load_creature("quadruped")
    model, state = init_crowd(load_scenario(str(path)), quadruped, default_gait(quadruped), n_characters=1, seed=0,
                              controller=ControllerConfig(navigate=navigate))
    assert (model.way_around is not None and model.way_around.n_boxes == 1) if navigate else model.way_around is None
    return model, state


def test_a_quadruped_whose_goal_lies_behind_a_forbidden_crate_walks_round_it(tmp_path):
    """The stuck case of the crowds issue's bar set, alone: a quadruped walking at a 2 m wide forbidden
    crate dead ahead, its goal straight behind it. Aimed round the crate it is well past it after 15 s
    (x 1.08); steered straight at the goal (``ControllerConfig.navigate`` off; on by default), ORCA held it
    at the crate's face for 2 s and slid it along, and it is 0.3 m behind (x 0.78; 0.41 while its feet
    were planned for the speed it headed for rather than the one the steering asked; in crowds such
    characters stalled)."""
    from footfall.planner import simulate

    runs = {}
    for navigate in (True, False):
        model, state = _behind_a_crate(tmp_path, navigate)
        runs[navigate] = (simulate(model, state, 450), float(state.pelvis[0, 0]))
    (summary, x), (straight, x_straight) = runs[True], runs[False]
    assert summary.stuck_seconds == 0.0 and summary.collisions == 0
    assert x > 1.0, f"past the crate (its far face at x = 0.3): x = {x:.2f}"
    assert x_straight < x - 0.25, "the case must be slower without the way round"


def test_the_crowds_way_rounds_static_boxes_and_the_region_a_looping_box_sweeps():
    """``static_way_around``: a static forbidden box, a safe one, a box looping round a 2 x 1 m rectangle
    (its region: the loop's bounding box grown by half the box's 0.5 m diagonal on each side) and a
    box moving at a constant velocity (not in the graph); every region grown by 1.2 avoid radii."""
    from footfall.planner._crowd import static_way_around
    from footfall.planner._navigation import CLEARANCE_FACTOR
    from footfall.scenarios import Obstacles

    boxes = Obstacles([[0.0, 0.1, 0.0], [3.0, 0.05, 0.0], [6.0, 0.1, 1.0], [0.0, 0.1, 5.0]],
                      [[0.4, 0.2, 0.2], [0.6, 0.1, 0.6], [0.3, 0.2, 0.4], [0.2, 0.2, 0.2]], [0.3, 0.0, 0.0, 0.0],
                      [True, False, True, True], motion_kind=[0, 0, 2, 1],
                      velocities=[[0, 0, 0], [0, 0, 0], [0, 0, 0], [0.3, 0.0, 0.0]],
                      waypoints=[np.zeros((0, 3)), np.zeros((0, 3)),
                                 np.array([[6.0, 0.1, 1.0], [8.0, 0.1, 1.0], [8.0, 0.1, 2.0], [6.0, 0.1, 2.0]]),
                                 np.zeros((0, 3))], waypoint_speed=[0.0, 0.0, 0.3, 0.0])
    way = static_way_around(boxes, 0.25)
    grow = CLEARANCE_FACTOR * 0.25
    np.testing.assert_allclose(way.centres, [[0.0, 0.0], [3.0, 0.0], [7.0, 1.5]])
    np.testing.assert_allclose(way.half, [[0.2 + grow, 0.1 + grow], [0.3 + grow, 0.3 + grow],
                                          [1.0 + 0.25 + grow, 0.5 + 0.25 + grow]])
    np.testing.assert_allclose(np.arctan2(way.sin_yaw, way.cos_yaw), [0.3, 0.0, 0.0])
    assert static_way_around(Obstacles.empty(), 0.25) is None


def test_simulate_and_evaluate_navigate_by_default_and_the_replay_says_when_not(tmp_path):
    import json

    from conftest import footfall_cli
    from footfall.reports._evaluate import replay_command

    for flags, on in (((), True), (("--navigate",), True), (("--no-navigate",), False)):
        path = tmp_path / f"run{len(flags)}{on}.npz"
        done = footfall_cli("simulate", "crates", "--frames", "20", "--characters", "2", *flags, "--record",
                            str(path), "--json")
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout)["frames"] == 20
        assert json.loads(str(np.load(path)["header"]))["navigate"] is on  # the recording says how it was run
    run = dict(scenario="crates", creature="spider", seed=3, characters=6, frames=300, lod="off")
    assert replay_command(run).endswith("--lod off --json")
    assert replay_command({**run, "navigate": True}).endswith("--lod off --json")
    assert replay_command({**run, "navigate": False}).endswith("--lod off --no-navigate --json")
