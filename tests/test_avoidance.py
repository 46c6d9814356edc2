"""ORCA kernel (planner._kernels_avoidance) on cases checkable by hand: one step worked out on
paper, two characters head-on, a crossing, a crowd through a doorway, a crate driven at a
character standing still. Every multi-step case integrates p += v dt at 30 Hz and checks every
frame."""

import math

import numpy as np
import pytest

from conftest import fresh_seeds
from footfall.planner._kernels_avoidance import neighbour_lists, orca_velocities

DT = 1.0 / 30.0
TAU = 2.0
NO_BOXES = (np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), np.zeros(0, np.bool_), np.zeros(0))


def _step(pos, vel, pref, radii, vmax, boxes=NO_BOXES, tau=TAU, box_tau=1.0, priority=None, mobile=None,
          yield_radii=None, right_of_way=None):
    start, index = neighbour_lists(pos, 10.0)
    out = np.empty_like(pos)
    priority = np.zeros(len(pos), np.bool_) if priority is None else priority
    mobile = np.ones(len(pos), np.bool_) if mobile is None else mobile
    yield_radii = radii if yield_radii is None else yield_radii
    right_of_way = np.zeros(len(pos), np.bool_) if right_of_way is None else right_of_way
    orca_velocities(pos, vel, pref, radii, vmax, start, index, *boxes, tau, box_tau, DT, priority, mobile, yield_radii,
                    right_of_way, out)
    return out


KEEP_RIGHT = 0.1
"""rad: far from its goal a walker aims this much to the right of it. ORCA alone can settle in a
symmetric standstill (two walkers exactly head-on, or crossing at right angles at equal
speeds); a shared 'keep right' convention in the preferred velocities breaks the tie, as the
steering of the crowd does."""


def _walk(pos, goals, radii, vmax, frames, boxes_at=None, box_tau=1.0, door=None):
    """Positions (frames + 1, C, 2) of characters walking at vmax toward their goals (through
    ``door`` first, if given: the route a global planner would give them)."""
    pos = np.array(pos, float)
    vel = np.zeros_like(pos)
    trail = [pos.copy()]
    through = np.zeros(pos.shape[0], bool)
    for f in range(frames):
        target = goals.copy()
        if door is not None:
            through |= (pos[:, 0] > door[0]) | (np.hypot(*(pos - door).T) < 0.1)
            target[~through] = door
        d = target - pos
        far = np.hypot(d[:, 0], d[:, 1]) > 0.5
        c, s = math.cos(KEEP_RIGHT), math.sin(-KEEP_RIGHT)
        d[far] = np.column_stack([c * d[far, 0] - s * d[far, 1], s * d[far, 0] + c * d[far, 1]])
        dist = np.hypot(d[:, 0], d[:, 1])[:, None]
        pref = np.where(dist > 1e-9, d / np.maximum(dist, 1e-9) * np.minimum(vmax[:, None], dist / DT), 0.0)
        boxes = NO_BOXES if boxes_at is None else boxes_at(f * DT)
        vel = _step(pos, vel, pref, radii, vmax, boxes, box_tau=box_tau)
        pos = pos + vel * DT
        trail.append(pos.copy())
    return np.array(trail)


def _min_pair_distance(trail):
    d = trail[:, :, None, :] - trail[:, None, :, :]
    dist = np.hypot(d[..., 0], d[..., 1])
    n = trail.shape[1]
    dist[:, np.arange(n), np.arange(n)] = np.inf
    return dist.min()


def test_one_step_against_a_standing_neighbour_equals_the_hand_computed_velocity():
    # A at (0, 0) moving and preferring (1, 0); B at (2, 0) at rest; radii 0.5 (r = 1), tau = 2.
    # w = v - p/tau = (1, 0) - (1, 0) = 0: the right leg is nearest. leg = sqrt(|p|^2 - r^2) = sqrt(3);
    # leg direction d = -(p_x leg, -p_x r) / |p|^2 = (-sqrt(3)/2, 1/2); u = (v.d) d - v
    # = (-sqrt(3)/2)(-sqrt(3)/2, 1/2) - (1, 0) = (-1/4, -sqrt(3)/4). A takes half: the line passes
    # through v + u/2 = (7/8, -sqrt(3)/8) along d; the preferred (1, 0) projects onto that point.
    pos = np.array([[0.0, 0.0], [2.0, 0.0]])
    vel = np.array([[1.0, 0.0], [0.0, 0.0]])
    pref = vel.copy()
    out = _step(pos, vel, pref, np.array([0.5, 0.5]), np.array([2.0, 2.0]))
    assert out[0] == pytest.approx([7.0 / 8.0, -math.sqrt(3.0) / 8.0], abs=1e-12)
    # B, at rest and preferring rest, takes the other half: v_B + u_B/2 with u_B = -u mirrored.
    assert out[1] == pytest.approx([1.0 / 8.0, math.sqrt(3.0) / 8.0], abs=1e-12)


def test_a_disc_that_overlaps_another_is_parted_within_the_separation_time_and_one_in_a_box_within_a_frame():
    # A at (0, 0) and B at (0.97, 0), both at rest and preferring rest, radii 0.5: the discs overlap by
    # 3 cm. w = v - p / T = (-0.97 / T, 0); u = (r / T - |w|) w / |w| = (-0.03 / T, 0); each takes half:
    # A's line passes through (-0.015 / T, 0), B's through (+0.015 / T, 0), and rest projects onto them.
    # T = SEPARATION_S (0.25 s): 6 cm/s each; parted within a frame, it asked 0.45 m/s, a velocity straight
    # behind a walker facing the other, which it followed by turning round on the spot.
    from footfall.planner._kernels_avoidance import SEPARATION_S

    pos = np.array([[0.0, 0.0], [0.97, 0.0]])
    rest = np.zeros((2, 2))
    out = _step(pos, rest, rest.copy(), np.array([0.5, 0.5]), np.array([2.0, 2.0]))
    assert SEPARATION_S == 0.25
    np.testing.assert_allclose(out, [[-0.015 / SEPARATION_S, 0.0], [0.015 / SEPARATION_S, 0.0]], rtol=0, atol=1e-12)
    # A box is no disc round a body: a box's nearest point at (0.47, 0) overlapping A's disc as much pushes it
    # out within a frame (A takes all of u: 0.03 / DT away). Parted from the boxes within T as well, ten
    # characters crowding a door came 1.7 cm into the walls (the doorway test below).
    def box(centre_x):
        return (np.array([[centre_x, 0.0]]), np.array([[0.1, 0.1]]), np.zeros(1), np.zeros((1, 2)),
                np.ones(1, np.bool_), np.zeros(1))

    one = (pos[:1], rest[:1], rest[:1].copy(), np.array([0.5]), np.array([2.0]))
    np.testing.assert_allclose(_step(*one, boxes=box(0.57)), [[-0.03 / DT, 0.0]], rtol=0, atol=1e-9)
    # A centre inside the box (x from -0.05 to 0.15) goes out through the nearest side (x = -0.05) within a
    # frame: (0.5 + 0.05) / DT = 16.5 m/s, held to the top speed, 2 m/s.
    np.testing.assert_allclose(_step(*one, boxes=box(0.05)), [[-2.0, 0.0]], rtol=0, atol=1e-9)


def test_a_character_with_priority_keeps_its_way_and_the_other_takes_the_whole_effort():
    # The case above with A escaping a crate's lane (priority): A's line passes through v + 0 u, so
    # its preferred velocity (1, 0) stays; B takes all of -u: (1/4, sqrt(3)/4). Both with priority
    # share as equals again.
    pos = np.array([[0.0, 0.0], [2.0, 0.0]])
    vel = np.array([[1.0, 0.0], [0.0, 0.0]])
    args = (pos, vel, vel.copy(), np.array([0.5, 0.5]), np.array([2.0, 2.0]))
    out = _step(*args, priority=np.array([True, False]))
    assert out[0] == pytest.approx([1.0, 0.0], abs=1e-12)
    assert out[1] == pytest.approx([1.0 / 4.0, math.sqrt(3.0) / 4.0], abs=1e-12)
    out = _step(*args, priority=np.array([True, True]))
    assert out[0] == pytest.approx([7.0 / 8.0, -math.sqrt(3.0) / 8.0], abs=1e-12)


def test_a_character_with_the_right_of_way_walks_on_and_the_other_takes_the_whole_effort():
    # The case above, A asking a little faster, (1.2, 0): with priority its line still passes through
    # v = (1, 0) along d = (-sqrt(3)/2, 1/2), and (1.2, 0) is on its forbidden side (det(d, (0.2, 0)) =
    # -0.1): A gets its projection, (1, 0) + (0.2, 0).d d = (1.15, -sqrt(3)/20). With the right of way
    # (a long wait, planner._crowd.wait_for_others) A leaves B's line out: (1.2, 0). B takes the whole
    # -u either way, (1/4, sqrt(3)/4).
    pos = np.array([[0.0, 0.0], [2.0, 0.0]])
    vel = np.array([[1.0, 0.0], [0.0, 0.0]])
    pref = np.array([[1.2, 0.0], [0.0, 0.0]])
    args = (pos, vel, pref, np.array([0.5, 0.5]), np.array([2.0, 2.0]))
    out = _step(*args, priority=np.array([True, False]))
    assert out[0] == pytest.approx([1.15, -math.sqrt(3.0) / 20.0], abs=1e-12)
    out = _step(*args, right_of_way=np.array([True, False]))
    assert out[0] == pytest.approx([1.2, 0.0], abs=1e-12)
    assert out[1] == pytest.approx([1.0 / 4.0, math.sqrt(3.0) / 4.0], abs=1e-12)
    # Both with it: equals again (the half shares of the first case, A's line through (7/8, -sqrt(3)/8)
    # along d, onto which (1.2, 0) projects at (7/8, -sqrt(3)/8) + ((1.2 - 7/8) (-sqrt(3)/2) + (sqrt(3)/8)(1/2)) d).
    out = _step(*args, right_of_way=np.array([True, True]))
    t = (1.2 - 7.0 / 8.0) * (-math.sqrt(3.0) / 2.0) + (math.sqrt(3.0) / 8.0) * 0.5
    expected = np.array([7.0 / 8.0, -math.sqrt(3.0) / 8.0]) + t * np.array([-math.sqrt(3.0) / 2.0, 0.5])
    assert out[0] == pytest.approx(expected, abs=1e-12)
    # B standing where it cannot make way (a walker at rest): the right of way still lets A walk on, where
    # without it A takes the whole -u (the case below). B, without it, takes the whole -u too. Kept to B's
    # line, two quadrupeds at their discs' edge stood 2.4 s, each holding the other (crates-moving, bar seed
    # 10007: the one with the right of way had to steer round the other as round a box, and turned back
    # and forth as the other's speed crossed MOBILE_FRACTION).
    out = _step(*args, right_of_way=np.array([True, False]), mobile=np.array([True, False]))
    assert out[0] == pytest.approx([1.2, 0.0], abs=1e-12)
    assert out[1] == pytest.approx([1.0 / 4.0, math.sqrt(3.0) / 4.0], abs=1e-12)
    # Priority (escaping a moving box) comes first: B escaping, A with the right of way, A takes it all,
    # its line through v + u = (3/4, -sqrt(3)/4) along d; (1.2, 0) projects onto (3/4, -sqrt(3)/4) + s d.
    out = _step(*args, priority=np.array([False, True]), right_of_way=np.array([True, False]))
    s = (1.2 - 0.75) * (-math.sqrt(3.0) / 2.0) + (math.sqrt(3.0) / 4.0) * 0.5
    expected = np.array([0.75, -math.sqrt(3.0) / 4.0]) + s * np.array([-math.sqrt(3.0) / 2.0, 0.5])
    assert out[0] == pytest.approx(expected, abs=1e-12)


def test_a_character_steers_round_one_that_cannot_make_way_with_its_whole_effort():
    # The case above, B standing where it cannot make way (a walker at rest): A takes the whole -u
    # itself, its line through v + u = (3/4, -sqrt(3)/4) along d, onto which (1, 0) projects at that
    # point (v + u is the foot of the perpendicular from v, u being perpendicular to d). B, without
    # priority, still takes its whole share too.
    pos = np.array([[0.0, 0.0], [2.0, 0.0]])
    vel = np.array([[1.0, 0.0], [0.0, 0.0]])
    args = (pos, vel, vel.copy(), np.array([0.5, 0.5]), np.array([2.0, 2.0]))
    out = _step(*args, priority=np.array([True, False]), mobile=np.array([True, False]))
    assert out[0] == pytest.approx([3.0 / 4.0, -math.sqrt(3.0) / 4.0], abs=1e-12)
    assert out[1] == pytest.approx([1.0 / 4.0, math.sqrt(3.0) / 4.0], abs=1e-12)
    # Whether A can make way does not matter to A's own velocity.
    out = _step(*args, priority=np.array([True, False]), mobile=np.array([False, True]))
    assert out[0] == pytest.approx([1.0, 0.0], abs=1e-12)
    # Between equals the same: half the effort is left to a neighbour only if it can take it.
    out = _step(*args, mobile=np.array([True, False]))
    assert out[0] == pytest.approx([3.0 / 4.0, -math.sqrt(3.0) / 4.0], abs=1e-12)
    assert out[1] == pytest.approx([1.0 / 8.0, math.sqrt(3.0) / 8.0], abs=1e-12)


def test_one_that_cannot_make_way_keeps_only_its_body_from_one_that_can():
    """The case above, B's body 0.3 (its disc 0.5): for B's own velocity the pair's radius is 0.3 + 0.5 =
    0.8. By the same construction, w = 0 and the leg |p|^2 - r^2 = 3.36 away: B's change is
    u = (r^2 / 4, r sqrt(3.36) / 4), all of it B's (A has priority). A still keeps the whole disc round B."""
    pos = np.array([[0.0, 0.0], [2.0, 0.0]])
    vel = np.array([[1.0, 0.0], [0.0, 0.0]])
    args = (pos, vel, vel.copy(), np.array([0.5, 0.5]), np.array([2.0, 2.0]))
    out = _step(*args, priority=np.array([True, False]), mobile=np.array([True, False]),
                yield_radii=np.array([0.3, 0.3]))
    assert out[0] == pytest.approx([3.0 / 4.0, -math.sqrt(3.0) / 4.0], abs=1e-12)
    assert out[1] == pytest.approx([0.16, 0.2 * math.sqrt(3.36)], abs=1e-12)
    # Two that cannot make way, or two that can, keep their whole discs from each other.
    for mobile in ([False, False], [True, True]):
        both = _step(*args, priority=np.array([True, False]), mobile=np.array(mobile),
                     yield_radii=np.array([0.3, 0.3]))
        plain = _step(*args, priority=np.array([True, False]), mobile=np.array(mobile))
        np.testing.assert_array_equal(both, plain)


def test_a_free_character_keeps_its_preferred_velocity_capped_at_its_top_speed():
    pos = np.array([[0.0, 0.0]])
    out = _step(pos, np.zeros((1, 2)), np.array([[3.0, 4.0]]), np.array([0.2]), np.array([1.0]))
    assert out[0] == pytest.approx([0.6, 0.8], abs=1e-12)


def test_two_characters_head_on_pass_each_other_symmetrically_without_touching():
    # Exactly head-on: both keep right (KEEP_RIGHT), so the two paths mirror each other through
    # the origin.
    radii = np.array([0.2, 0.2])
    vmax = np.array([0.5, 0.5])
    trail = _walk([[-1.0, 0.0], [1.0, 0.0]], np.array([[1.0, 0.0], [-1.0, 0.0]]), radii, vmax, 180)
    assert _min_pair_distance(trail) >= 0.4 - 1e-6
    assert np.abs(trail[:, 0] + trail[:, 1]).max() < 1e-9  # point symmetry
    assert np.hypot(*(trail[-1] - [[1.0, 0.0], [-1.0, 0.0]]).T).max() < 0.05


def test_a_right_angle_crossing_has_no_overlap_and_both_arrive():
    radii = np.array([0.25, 0.25])
    vmax = np.array([0.4, 0.4])
    goals = np.array([[2.0, 0.0], [0.0, 2.0]])
    trail = _walk([[-2.0, 0.0], [0.0, -2.0]], goals, radii, vmax, 450)
    assert _min_pair_distance(trail) >= 0.5 - 1e-6
    assert np.hypot(*(trail[-1] - goals).T).max() < 0.05


def test_a_crowd_passes_a_doorway_without_overlap_or_entering_the_walls():
    # Two 2 m walls (boxes) leave a 0.8 m door at x = 0; ten characters of radius 0.15 cross
    # from x < -1 to goals beyond the wall.
    half = np.array([[0.1, 1.0], [0.1, 1.0]])
    centres = np.array([[0.0, 1.4], [0.0, -1.4]])
    boxes = (centres, half, np.zeros(2), np.zeros((2, 2)), np.ones(2, np.bool_), np.zeros(2))
    rng = np.random.default_rng(3)
    start = np.column_stack([rng.uniform(-2.5, -1.2, 10), np.linspace(-1.5, 1.5, 10)])
    goals = np.column_stack([np.full(10, 2.0), np.linspace(-1.5, 1.5, 10)])
    # ORCA avoids with a 1 cm skin on the 0.15 m bodies: where ten crowd the door, the program
    # is infeasible for a few frames and its least violation may eat into the skin.
    radii = np.full(10, 0.16)
    vmax = np.full(10, 0.6)
    trail = _walk(start, goals, radii, vmax, 900, boxes_at=lambda t: boxes, door=np.array([0.3, 0.0]))
    assert _min_pair_distance(trail) >= 0.3 - 1e-6
    for c, h in zip(centres, half):
        # Distance from every centre at every frame to each wall, less the radius.
        d = np.maximum(np.abs(trail - c) - h, 0.0)
        assert np.hypot(d[..., 0], d[..., 1]).min() >= 0.15 - 1e-3
    assert (trail[-1, :, 0] > 1.5).all(), "every character got through the door"


def test_a_crate_driven_at_a_standing_character_is_evaded():
    # A 0.5 m crate at 0.2 m/s along +x runs over (0, 0) where a character (radius 0.2, top
    # speed 0.5) stands and wants to stay.
    half = np.array([[0.25, 0.25]])
    velocity = np.array([[0.2, 0.0]])

    def boxes_at(t):
        return (np.array([[-2.0 + 0.2 * t, 0.0]]), half, np.zeros(1), velocity, np.ones(1, np.bool_), np.zeros(1))

    trail = _walk([[0.0, 0.0]], np.array([[0.0, 0.0]]), np.array([0.2]), np.array([0.5]), 600, boxes_at=boxes_at,
                  box_tau=2.0)
    for f in range(trail.shape[0]):
        centre = boxes_at(f * DT)[0][0]
        d = np.maximum(np.abs(trail[f, 0] - centre) - half[0], 0.0)
        assert np.hypot(*d) >= 0.2 - 1e-3, f"frame {f}: the crate reached the character"
    assert np.hypot(*trail[-1, 0]) > 0.2, "it got out of the way"


def test_velocities_are_finite_and_never_above_the_top_speed_in_a_dense_crowd():
    rng = np.random.default_rng(0)
    pos = rng.uniform(-1.0, 1.0, (40, 2))
    pref = rng.normal(size=(40, 2))
    vmax = rng.uniform(0.2, 0.8, 40)
    out = _step(pos, np.zeros_like(pos), pref, np.full(40, 0.2), vmax)
    assert np.isfinite(out).all()
    assert (np.hypot(out[:, 0], out[:, 1]) <= vmax + 1e-9).all()


def test_neighbour_lists_are_sorted_symmetric_and_exclude_self():
    pos = np.array([[0.0, 0.0], [0.5, 0.0], [0.0, 0.5], [3.0, 3.0]])
    start, index = neighbour_lists(pos, 0.6)
    lists = [index[start[i]:start[i + 1]].tolist() for i in range(4)]
    assert lists == [[1, 2], [0], [0], []]


def test_neighbour_lists_keep_the_nearest_when_capped():
    pos = np.array([[0.0, 0.0], [0.3, 0.0], [0.0, 0.2], [0.5, 0.0], [9.0, 9.0]])
    start, index = neighbour_lists(pos, 1.0, max_neighbours=2)
    lists = [index[start[i]:start[i + 1]].tolist() for i in range(5)]
    assert lists == [[1, 2], [0, 3], [0, 1], [0, 1], []]


@pytest.mark.parametrize("pad, expected", [(0.0, 0.6), (0.3, 0.3)])
def test_a_box_pad_widens_the_disc_against_that_box(pad, expected):
    # A character of radius 0.2 at the origin wants 1 m/s toward a box whose near side is 0.8 m
    # ahead (centre (1, 0), half extents 0.2). Straight at it, ORCA's cut-off circle (centre p/tau,
    # radius r/tau, tau = 1 s) allows (0.8 - r) / tau: 0.6 m/s with the character's radius, 0.3 m/s
    # with a 0.3 m pad (a moving box is kept clear of the feet, not only of the body).
    boxes = (np.array([[1.0, 0.0]]), np.array([[0.2, 0.2]]), np.zeros(1), np.zeros((1, 2)), np.ones(1, np.bool_),
             np.array([pad]))
    out = _step(np.zeros((1, 2)), np.zeros((1, 2)), np.array([[1.0, 0.0]]), np.array([0.2]), np.array([2.0]),
                boxes, box_tau=1.0)
    np.testing.assert_allclose(out[0], [expected, 0.0], atol=1e-9)


@pytest.mark.parametrize("seed", fresh_seeds([0, 1, 2], 3, salt=78))
def test_neighbour_lists_equal_brute_force_on_random_crowds(seed):
    """Against a plain distance matrix: within the radius, the k nearest (ties by index), ascending."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 400))
    pos = rng.uniform(-6.0, 6.0, (n, 2))
    radius, k = float(rng.uniform(0.2, 15.0)), int(rng.integers(1, 12))
    start, index = neighbour_lists(pos, radius, max_neighbours=k)
    d = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
    for i in range(n):
        within = np.flatnonzero((d[i] <= radius) & (np.arange(n) != i))
        nearest = within[np.argsort(d[i, within], kind="stable")[:k]]
        assert index[start[i]:start[i + 1]].tolist() == sorted(nearest.tolist()), f"seed {seed}, character {i}"


def _into(kernel, centres, headings, changes, half_length, half_width):
    """``kernel`` (moves_into_bodies or turns_into_bodies) for every character, everyone a neighbour."""
    centres = np.asarray(centres, np.float64)
    start, index = neighbour_lists(centres, 10.0)
    out = np.empty(centres.shape[0], np.bool_)
    kernel(centres, np.asarray(headings, np.float64), np.asarray(changes, np.float64), half_length, half_width,
           start, index, out)
    return out.tolist()


def _moves_into(centres, headings, moves, half_length=0.1, half_width=0.05):
    from footfall.planner._kernels_controller import moves_into_bodies

    return _into(moves_into_bodies, centres, headings, moves, half_length, half_width)


def test_a_step_into_a_neighbours_body_is_refused_and_one_beside_or_away_is_not():
    # Two bodies 0.2 x 0.1, both facing +x, 0.21 m apart along x: 1 cm of air between them.
    centres, headings = [[0.0, 0.0], [0.21, 0.0]], [0.0, 0.0]
    assert _moves_into(centres, headings, [[0.02, 0.0], [0.0, 0.0]]) == [True, False]  # 1 cm into it
    assert _moves_into(centres, headings, [[0.005, 0.0], [0.0, 0.0]]) == [False, False]  # 5 mm of air left
    assert _moves_into(centres, headings, [[-0.02, 0.0], [0.02, 0.0]]) == [False, False]  # both away
    assert _moves_into(centres, headings, [[0.0, 0.02], [0.0, 0.0]]) == [False, False]  # sideways: farther
    # Turned across (+z), the neighbour is 0.05 m deep along x instead of 0.1: 6 cm of air.
    assert _moves_into(centres, [0.0, math.pi / 2], [[0.05, 0.0], [0.0, 0.0]]) == [False, False]
    assert _moves_into(centres, [0.0, math.pi / 2], [[0.07, 0.0], [0.0, 0.0]]) == [True, False]


def _turns_into(centres, headings, turns, half_length=0.1, half_width=0.02):
    from footfall.planner._kernels_controller import turns_into_bodies

    return _into(turns_into_bodies, centres, headings, turns, half_length, half_width)


def test_a_turn_on_the_spot_into_a_neighbours_body_is_refused_and_a_smaller_one_is_not():
    # Two bodies 0.2 x 0.04, both facing +x, side by side 6 cm apart along z: 2 cm of air between them.
    centres, headings = [[0.0, 0.0], [0.0, 0.06]], [0.0, 0.0]
    assert _turns_into(centres, headings, [math.pi / 2, 0.0]) == [True, False]  # across: through the other
    # Turned 0.1 rad, the front left corner rises to 0.1 sin 0.1 + 0.02 cos 0.1 = 0.030 m, short of the
    # other's side at 0.04; turned 0.3 rad, to 0.0296 + 0.0191 = 0.049 m: into it. Turned -0.3 rad, the
    # back left corner rises as far.
    assert _turns_into(centres, headings, [0.1, 0.0]) == [False, False]
    assert _turns_into(centres, headings, [0.3, 0.0]) == [True, False]
    assert _turns_into(centres, headings, [-0.3, 0.0]) == [True, False]
    assert _turns_into(centres, headings, [-0.1, 0.0]) == [False, False]
    assert _turns_into(centres, headings, [0.0, 0.0]) == [False, False]
    # Bodies that already overlap may turn (the turn is no new overlap; a step apart parts them).
    assert _turns_into([[0.0, 0.0], [0.0, 0.03]], headings, [0.3, 0.0]) == [False, False]


def test_bodies_already_overlapping_may_part_but_not_press_further():
    centres, headings = [[0.0, 0.0], [0.15, 0.0]], [0.0, 0.0]  # 5 cm into each other
    assert _moves_into(centres, headings, [[0.01, 0.0], [0.0, 0.0]]) == [True, False]
    assert _moves_into(centres, headings, [[-0.01, 0.0], [0.01, 0.0]]) == [False, False]


def test_two_bodies_turning_into_each_other_in_one_frame_see_each_other_turned():
    # The bodies of the test above, 2 cm of air between them. Turned 0.2 rad, body 0's front left corner
    # goes to (0.1 cos 0.2 - 0.02 sin 0.2, 0.1 sin 0.2 + 0.02 cos 0.2) = (0.094, 0.0395); turned -0.2 rad,
    # body 1's front right corner to (0.094, 0.06 - 0.0395) = (0.094, 0.0205). Each turn alone keeps clear
    # of the other's body (0.0395 < 0.04, 0.0205 > 0.02); together the corners pass each other. The later
    # one in order sees the earlier turned, and is refused.
    centres, headings = [[0.0, 0.0], [0.0, 0.06]], [0.0, 0.0]
    assert _turns_into(centres, headings, [0.2, 0.0]) == [False, False]
    assert _turns_into(centres, headings, [0.0, -0.2]) == [False, False]
    assert _turns_into(centres, headings, [0.2, -0.2]) == [False, True]
    # An earlier turn that is itself refused is not seen: body 0 turning across (into body 1) stays put.
    assert _turns_into(centres, headings, [math.pi / 2, -0.2]) == [True, False]
