"""Properties of the couple search over >= 1000 seeded random obstacle layouts.

The checks are geometric and independent of the planner's own rasterisation:
a foot rectangle placed at any trajectory sample never overlaps a forbidden box,
and overlaps a safe box only from above its top; the chosen footprint does not
touch a forbidden box; trajectories run from the source to the target; they do
not cross the other legs; and the exhaustive search finds the brute-force optimum
over all (target, slice) couples.
"""

import math

import numpy as np
import pytest

from footfall.planner import EXHAUSTIVE, FIRST_VALID, DEFAULT_BUDGET, FootQuery, GridFrame, LocalMaps, PlannerConfig, plan_foot
from footfall.planner._kernels_geometry import foot_offsets, rasterise_boxes

N_LAYOUTS = 1000
N = 40
CELL = 0.07
TOUCH_TOL = 1e-9  # geometric overlap must exceed this (touching is not penetrating)


def rects_overlap(c1, h1, yaw1, c2, h2, yaw2, tol=TOUCH_TOL):
    """Separating-axis test of two oriented rectangles in the x/z plane (strict)."""
    axes = []
    for yaw in (yaw1, yaw2):
        axes.append((math.cos(yaw), math.sin(yaw)))
        axes.append((-math.sin(yaw), math.cos(yaw)))
    d = (c2[0] - c1[0], c2[1] - c1[1])
    for ax in axes:
        def radius(h, yaw):
            u = (math.cos(yaw), math.sin(yaw))
            v = (-math.sin(yaw), math.cos(yaw))
            return h[0] * abs(u[0] * ax[0] + u[1] * ax[1]) + h[1] * abs(v[0] * ax[0] + v[1] * ax[1])

        if abs(d[0] * ax[0] + d[1] * ax[1]) >= radius(h1, yaw1) + radius(h2, yaw2) - tol:
            return False
    return True


def segments_cross(a, b, c, d):
    def orient(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    return orient(a, b, c) * orient(a, b, d) < 0 and orient(c, d, a) * orient(c, d, b) < 0


def point_segment_distance(p, a, b):
    a, b, p = np.asarray(a), np.asarray(b), np.asarray(p)
    ab = b - a
    t = np.clip(np.dot(p - a, ab) / max(np.dot(ab, ab), 1e-300), 0, 1)
    return float(np.linalg.norm(a + t * ab - p))


def random_layout(rng):
    frame = GridFrame(0.0, 0.0, CELL, N, N)
    xs, zs = frame.cell_to_world(np.arange(N)[:, None], np.arange(N)[None, :])
    xs, zs = np.broadcast_arrays(xs, zs)
    kind = rng.integers(3)
    if kind == 0:
        ground = np.zeros((N, N))
    elif kind == 1:
        ground = rng.uniform(-0.15, 0.15) * xs + rng.uniform(-0.15, 0.15) * zs
    else:
        ground = 0.05 * np.sin(xs * rng.uniform(1, 4)) * np.cos(zs * rng.uniform(1, 4))
    elevation = ground.copy()
    forbidden = np.zeros((N, N), np.uint8)
    k = int(rng.integers(0, 8))
    boxes = []
    for _ in range(k):
        cx, cz = rng.uniform(0.5, 2.3, size=2)
        sx, sz = rng.uniform(0.05, 0.5, size=2)
        h = rng.uniform(0.02, 0.4)
        yaw = rng.uniform(-math.pi, math.pi)
        base = float(ground[int(cz / CELL), int(cx / CELL)])
        boxes.append((cx, base + h / 2, cz, sx, h, sz, yaw, bool(rng.random() < 0.5)))
    if boxes:
        b = np.array(boxes, dtype=np.float64)
        rasterise_boxes(elevation, forbidden, 0.0, 0.0, CELL, np.ascontiguousarray(b[:, 0:3]),
                        np.ascontiguousarray(b[:, 3:6]), np.ascontiguousarray(b[:, 6]), b[:, 7].astype(bool),
                        np.ones(len(boxes), bool))
    return LocalMaps(frame, elevation, ground, forbidden), boxes


def dilate(mask, offsets):
    out = np.zeros_like(mask, dtype=bool)
    n_rows, n_cols = mask.shape
    for r, c in np.argwhere(mask):
        for dr, dc in offsets:
            rr, cc = r - dr, c - dc
            if 0 <= rr < n_rows and 0 <= cc < n_cols:
                out[rr, cc] = True
    return out


def random_query(rng, maps):
    foot_length = float(rng.uniform(0.02, 0.08))
    foot_width = float(rng.uniform(0.02, 0.05))
    foot_yaw = float(rng.uniform(-math.pi, math.pi))
    offsets = foot_offsets(foot_length, foot_width, foot_yaw, CELL)
    inflated = dilate(maps.forbidden.astype(bool), offsets)
    free = np.argwhere(~inflated[12:28, 12:28]) + 12
    if len(free) == 0:
        return None, None
    r, c = free[rng.integers(len(free))]
    sx, sz = maps.frame.cell_to_world(r, c)
    rr = np.clip(r + offsets[:, 0], 0, N - 1)
    cc = np.clip(c + offsets[:, 1], 0, N - 1)
    sy = float(maps.elevation[rr, cc].max())
    heading = rng.uniform(-math.pi, math.pi)
    d = rng.uniform(0.1, 0.45)
    preferred = (sx + d * math.cos(heading), sz + d * math.sin(heading))
    hip = (sx - 0.2 * math.cos(heading + 0.5), sz - 0.2 * math.sin(heading + 0.5))
    legs = []
    for _ in range(int(rng.integers(0, 4))):
        for _try in range(10):
            hx, hz = hip[0] + rng.uniform(-0.1, 0.1), hip[1] + rng.uniform(-0.1, 0.1)
            fx, fz = hx + rng.uniform(-0.4, 0.4), hz + rng.uniform(-0.4, 0.4)
            if point_segment_distance((sx, sz), (hx, hz), (fx, fz)) > 0.11:
                legs.append((hx, hz, fx, fz))
                break
    q = FootQuery(source=(float(sx), sy, float(sz)), preferred=preferred, hip=hip, reach_xz=0.7,
                  step_height=float(rng.uniform(0.02, 0.1)), foot_length=foot_length, foot_width=foot_width,
                  foot_yaw=foot_yaw, other_legs=np.array(legs).reshape(-1, 4))
    return q, inflated


def check_couple(result, query, maps, boxes, inflated):
    if not result.valid:
        np.testing.assert_array_equal(result.target, query.source)
        return
    traj = result.trajectory
    np.testing.assert_array_equal(traj[0], query.source)
    np.testing.assert_array_equal(traj[-1], result.target)
    tr, tc = result.target_cell
    assert not maps.forbidden[tr, tc] and not inflated[tr, tc], "footprint on a forbidden or size-increase cell"
    # A continuous footprint: the point of the target cell nearest the preferred footprint, or, where that
    # point is within a foot's room of another foot or leg, a point of the cell's closed square pushed
    # out of that room (planner._kernels_foot.out_of_other_feet).
    cx, cz = maps.frame.cell_to_world(tr, tc)
    half = 0.5 * maps.frame.cell_size
    px, pz = query.preferred
    nearest = (min(max(px, cx - half), cx + half), min(max(pz, cz - half), cz + half))
    tx, tz = result.target[0], result.target[2]
    if nearest != (tx, tz):
        room = query.feet_block_radius
        legs = query.other_legs
        assert any(point_segment_distance(nearest, leg[:2], leg[2:]) <= room for leg in legs), "a footprint moved off the cell's nearest point"
        assert abs(tx - cx) <= half + 1e-12 and abs(tz - cz) <= half + 1e-12, "a pushed footprint left its cell"
        assert all(math.hypot(tx - leg[2], tz - leg[3]) > room for leg in legs), "a pushed footprint in a foot's room"
    half_foot = (0.5 * query.foot_length, 0.5 * query.foot_width)
    for cx, cy, cz, sx, h, sz, yaw, is_forbidden in boxes:
        top = cy + 0.5 * h
        for x, y, z in traj:
            if rects_overlap((x, z), half_foot, query.foot_yaw, (cx, cz), (0.5 * sx, 0.5 * sz), yaw):
                assert not is_forbidden, f"foot at {(x, y, z)} inside a forbidden box"
                assert y >= top - 1e-9, f"foot at {(x, y, z)} below the top {top} of a safe box"
    for hx, hz, fx, fz in query.other_legs:
        for a, b in zip(traj[:-1], traj[1:]):
            assert not segments_cross((a[0], a[2]), (b[0], b[2]), (hx, hz), (fx, fz)), "trajectory crosses a leg"
    assert np.isfinite(traj).all()
    assert 0.0 <= result.couple_score <= 1.0 and 0.0 <= result.footprint_score <= 1.0


def test_random_layouts():
    rng = np.random.default_rng(20121)
    layouts = 0
    valid = 0
    optimum_checked = 0
    while layouts < N_LAYOUTS:
        maps, boxes = random_layout(rng)
        query, inflated = random_query(rng, maps)
        if query is None:
            continue
        layouts += 1
        exhaustive = plan_foot(maps, query, budget=EXHAUSTIVE)
        brute = plan_foot(maps, query, budget=EXHAUSTIVE, mode="brute_force")
        assert exhaustive.valid == brute.valid
        if brute.valid:
            valid += 1
            assert exhaustive.couple_score == brute.couple_score
            assert (exhaustive.target_cell, exhaustive.slice_index) == (brute.target_cell, brute.slice_index)
            assert exhaustive.counters["couples_evaluated"] <= brute.counters["couples_evaluated"]
            optimum_checked += 1
        for result in (exhaustive, plan_foot(maps, query, budget=DEFAULT_BUDGET),
                       plan_foot(maps, query, budget=FIRST_VALID)):
            check_couple(result, query, maps, boxes, inflated)
    assert valid >= 0.8 * N_LAYOUTS, f"only {valid} of {N_LAYOUTS} layouts had a valid couple"
    assert optimum_checked == valid


def test_boxed_in_foot_holds():
    maps, _ = random_layout(np.random.default_rng(1))
    forbidden = np.ones((N, N), np.uint8)
    forbidden[20, 20] = 0
    boxed = LocalMaps(maps.frame, maps.elevation, maps.ground, forbidden)
    sx, sz = maps.frame.cell_to_world(20, 20)
    q = FootQuery(source=(sx, 0.0, sz), preferred=(sx + 0.2, sz), hip=(sx - 0.2, sz), reach_xz=0.7, step_height=0.05,
                  foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    r = plan_foot(boxed, q)
    assert not r.valid
    np.testing.assert_array_equal(r.target, q.source)
    np.testing.assert_array_equal(r.trajectory, np.repeat(q.source[None], len(r.trajectory), axis=0))


# A corridor along z 1.0-1.1 (row 10) of 0.1 m cells: forbidden rows 8 and 12, their foot-size rings
# rows 9 and 11. The foot stands at x 0.55 and steps to x 1.05 under a hip at x 0.85.
CORRIDOR_FORBIDDEN = np.zeros((20, 20), np.uint8)
CORRIDOR_FORBIDDEN[[8, 12], :] = 1


def _corridor_query(legs):
    return FootQuery(source=(0.55, 0.0, 1.05), preferred=(1.05, 1.05), hip=(0.85, 1.05), reach_xz=0.45,
                     step_height=0.05, foot_length=0.04, foot_width=0.02, foot_yaw=0.0,
                     other_legs=np.array(legs, float).reshape(-1, 4))


def _corridor(forbidden=CORRIDOR_FORBIDDEN):
    return LocalMaps(GridFrame(0.0, 0.0, 0.1, 20, 20), np.zeros((20, 20)), np.zeros((20, 20)), forbidden)


def test_a_boxed_in_foot_steps_past_another_foot_when_no_other_way_is_left():
    config = PlannerConfig(cell_size=0.1)
    free = plan_foot(_corridor(), _corridor_query([]), budget=EXHAUSTIVE, config=config)
    assert free.valid and free.counters["boxed_ways"] == 0
    # Another foot at x 0.75 closes the corridor (its room is cell (10, 7)): the only way to the
    # candidates passes over it. The foot takes it rather than hold (and hold its body) for good.
    foot = [(0.75, 1.05, 0.75, 1.05)]
    boxed = plan_foot(_corridor(), _corridor_query(foot), budget=EXHAUSTIVE, config=config)
    assert boxed.valid and boxed.counters["boxed_ways"] == 1
    np.testing.assert_array_equal(boxed.target, (1.05, 0.0, 1.05))
    np.testing.assert_allclose(boxed.trajectory[:, 2], 1.05, rtol=0, atol=1e-12)  # along the corridor, over the foot
    assert boxed.couple_score < free.couple_score  # its clearance is the other foot's room: none
    # A forbidden cell there instead: the way out passes beside it, through the foot-size rings of the
    # cell and of the corridor's wall (row 9, z 0.9-1.0, or row 11, z 1.1-1.2), where the 4 x 2 cm foot
    # touches neither.
    post = CORRIDOR_FORBIDDEN.copy()
    post[10, 7] = 1
    beside = plan_foot(_corridor(post), _corridor_query([]), budget=EXHAUSTIVE, config=config)
    assert beside.valid and beside.counters["boxed_ways"] == 1
    np.testing.assert_array_equal(beside.target, (1.05, 0.0, 1.05))
    at_post = np.abs(beside.trajectory[:, 0] - 0.75) <= 0.05 + 0.02  # samples whose foot may reach x 0.7-0.8
    side = 0.95 if beside.trajectory[at_post, 2].mean() < 1.05 else 1.15
    assert at_post.any() and np.all(np.abs(beside.trajectory[at_post, 2] - side) <= 0.05 - 0.01)
    # A wall across the corridor (rows 9-11 at x 0.7-0.8) is no way out: the foot holds.
    wall = post.copy()
    wall[9:12, 7] = 1
    held = plan_foot(_corridor(wall), _corridor_query([]), budget=EXHAUSTIVE, config=config)
    assert not held.valid and held.counters["boxed_ways"] == 0
    np.testing.assert_array_equal(held.target, (0.55, 0.0, 1.05))


def test_same_inputs_same_result():
    rng = np.random.default_rng(5)
    maps, _ = random_layout(rng)
    q, _ = random_query(rng, maps)
    a = plan_foot(maps, q)
    b = plan_foot(maps, q)
    np.testing.assert_array_equal(a.trajectory, b.trajectory)
    assert a.breakdown == b.breakdown and a.counters == b.counters


def test_source_outside_the_maps_is_an_argument_error():
    maps, _ = random_layout(np.random.default_rng(2))
    q = FootQuery(source=(-5.0, 0.0, 0.0), preferred=(0.0, 0.0), hip=(0.0, 0.0), reach_xz=0.5, step_height=0.05,
                  foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    with pytest.raises(ValueError, match="source"):
        plan_foot(maps, q)


def test_batch_kernel_equals_single_foot_calls():
    from footfall.planner import make_batch, plan_batch

    rng = np.random.default_rng(11)
    maps_list, requests, singles = [], [], []
    while len(requests) < 40:
        maps, _ = random_layout(rng)
        q, _ = random_query(rng, maps)
        if q is None:
            continue
        maps_list.append(maps)
        requests.append((len(maps_list) - 1, q))
        singles.append(plan_foot(maps, q))
    out = plan_batch(make_batch(maps_list, requests))
    for i, r in enumerate(singles):
        assert out.valid[i] == r.valid
        np.testing.assert_array_equal(out.trajectory[i], r.trajectory)
        np.testing.assert_array_equal(out.target[i], r.target)
        assert out.scores[i, 0] == r.couple_score



def _walled(rows):
    """A 25 x 25 map of 0.1 m cells, flat, with a forbidden wall in column 11 (x 1.1-1.2) over ``rows``."""
    forbidden = np.zeros((25, 25), np.uint8)
    forbidden[rows, 11] = 1
    return LocalMaps(GridFrame(0.0, 0.0, 0.1, 25, 25), np.zeros((25, 25)), np.zeros((25, 25)), forbidden)


# The foot stands at (0.95, 1.25), west of the wall; it lands under a hip at (1.25, 1.25), on the wall's
# line, preferred 0.3 m east of it; the leg reaches 0.45 m. A swing passes only within
# max(0.45, |source - hip| = 0.30) + half a cell's diagonal (0.0707) = 0.5207 m of the hip.
WALL_QUERY = FootQuery(source=(0.95, 0.0, 1.25), preferred=(1.55, 1.25), hip=(1.25, 1.25), reach_xz=0.45,
                       step_height=0.05, foot_length=0.04, foot_width=0.02, foot_yaw=0.0)
WALL_REACH = 0.45 + 0.05 * math.sqrt(2.0)
WALL_CONFIG = PlannerConfig(cell_size=0.1)


def test_a_swing_does_not_leave_its_legs_reach_to_go_round_a_wall():
    # Wall over z 0.6-1.9: the way round (inside the search's region, rows 4-20) passes z 0.45 or
    # 2.05, 0.8 m from the hip. No couple: the foot holds. (A spider's foot once looped 1 m round a
    # crate for a 0.29 m step, and was drawn inside the crate at the end of its stretched leg.)
    r = plan_foot(_walled(slice(6, 19)), WALL_QUERY, budget=EXHAUSTIVE, config=WALL_CONFIG)
    assert not r.valid
    # Wall over z 1.1-1.4 (its foot-size ring over z 1.0-1.5): the way round stays within reach.
    r = plan_foot(_walled(slice(11, 14)), WALL_QUERY, budget=EXHAUSTIVE, config=WALL_CONFIG)
    assert r.valid
    assert r.target[0] > 1.2  # east of the wall
    reach = np.hypot(r.trajectory[:, 0] - 1.25, r.trajectory[:, 2] - 1.25)
    assert reach.max() <= WALL_REACH
    assert np.abs(r.trajectory[:, 2] - 1.25).max() > 0.2  # it went round, not through
