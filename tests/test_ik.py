"""CCD leg inverse kinematics (paper §3): forward kinematics by hand, convergence on
reachable targets of every built-in creature, closest poses for unreachable ones,
warm starts, serial == parallel bit for bit, frame invariance and input validation."""

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from footfall.planner._ik import (
    ABDUCTION_LIMIT,
    DEFAULT_AZIMUTH_LIMIT,
    UPRIGHT_LEG_OFFSET,
    DEFAULT_MAX_ITERATIONS,
    DEFAULT_TOLERANCE,
    body_rotation,
    clamp_angles,
    forward_legs,
    legs_of,
    rest_feet_body,
    rest_pose_angles,
    solve_legs,
)
from footfall.planner._kernels_ik import body_rotation as body_rotation_kernel
from footfall.planner._kernels_ik import forward_kinematics, nearest_in_limits
from footfall.scenarios import builtin_creature_names, load_creature

CREATURES = builtin_creature_names()
HALF_PI = 0.5 * math.pi


def tile(x, n):
    return np.ascontiguousarray(np.broadcast_to(x, (n,) + np.shape(x)))


def leg_batch(legs, idx):
    """Static per-leg arrays of the legs ``idx`` of a creature."""
    return (legs.rest_azimuths[idx], legs.segment_lengths[idx], legs.limits[idx], legs.azimuth_limits[idx])


def random_angles(rng, limits, azimuth_limits):
    n, s, _ = limits.shape
    angles = np.empty((n, s + 1))
    angles[:, 0] = rng.uniform(-azimuth_limits, azimuth_limits)
    angles[:, 1:] = rng.uniform(limits[..., 0], limits[..., 1])
    return angles


def random_bodies(rng, n):
    """World poses: pelvis (n, 3), rotation (n, 3, 3) from random yaw, pitch and roll."""
    pelvis = rng.uniform(-5.0, 5.0, (n, 3))
    rotation = body_rotation(rng.uniform(-math.pi, math.pi, n), rng.uniform(-0.5, 0.5, n), rng.uniform(-0.5, 0.5, n))
    return pelvis, rotation


def assert_within_limits(angles, limits, azimuth_limits):
    assert np.all(np.abs(angles[:, 0]) <= azimuth_limits)
    assert np.all(angles[:, 1:] >= limits[..., 0]) and np.all(angles[:, 1:] <= limits[..., 1])


def assert_consistent(result, hips, rotations, rest, lengths, targets):
    """Residual = |FK(angles) foot - target| and joints = FK(angles): the outputs agree."""
    joints = forward_legs(hips, rotations, rest, lengths, result.angles)
    np.testing.assert_allclose(result.joints, joints, rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.residual, np.linalg.norm(joints[:, -1] - targets, axis=1), rtol=0, atol=1e-12)
    assert np.isfinite(result.angles).all() and np.isfinite(result.residual).all()


# --------------------------------------------------------------------------- forward kinematics by hand

HIP = np.array([1.0, 2.0, 3.0])
LENGTHS = np.array([0.3, 0.2])


@pytest.mark.parametrize(
    "angles, expected",
    [
        ([0.0, 0.0, 0.0], [[1.0, 2.0, 3.0], [1.3, 2.0, 3.0], [1.5, 2.0, 3.0]]),  # straight out (forward)
        ([0.0, 0.0, HALF_PI], [[1.0, 2.0, 3.0], [1.3, 2.0, 3.0], [1.3, 1.8, 3.0]]),  # knee bent 90 deg down
        ([0.0, 0.0, -HALF_PI], [[1.0, 2.0, 3.0], [1.3, 2.0, 3.0], [1.3, 2.2, 3.0]]),  # knee bent 90 deg up
        ([0.0, HALF_PI, 0.0], [[1.0, 2.0, 3.0], [1.0, 1.7, 3.0], [1.0, 1.5, 3.0]]),  # hip pitched straight down
        ([0.0, HALF_PI, -HALF_PI], [[1.0, 2.0, 3.0], [1.0, 1.7, 3.0], [1.2, 1.7, 3.0]]),  # down, then out
        ([HALF_PI, 0.0, HALF_PI], [[1.0, 2.0, 3.0], [1.0, 2.0, 3.3], [1.0, 1.8, 3.3]]),  # plane turned left
        ([-HALF_PI, 0.0, 0.0], [[1.0, 2.0, 3.0], [1.0, 2.0, 2.7], [1.0, 2.0, 2.5]]),  # plane turned right
    ],
)
def test_forward_kinematics_by_hand(angles, expected):
    angles = np.array(angles)
    got = forward_kinematics(HIP, np.eye(3), 0.0, LENGTHS, angles)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-15)
    batch = forward_legs(HIP[None], np.eye(3)[None], [0.0], LENGTHS[None], angles[None])
    assert batch.shape == (1, 4, 3)
    np.testing.assert_array_equal(batch[0, 0], HIP)  # the azimuth joint's row: the hip
    np.testing.assert_array_equal(batch[0, 1:], got)


def test_rest_azimuth_and_body_rotation_by_hand():
    out = 0.5  # straight leg: foot 0.5 m from the hip along the plane's outward direction
    straight = np.zeros(3)
    # rest azimuth pi/2: the leg points left, world +z for an unrotated body
    np.testing.assert_allclose(forward_kinematics(HIP, np.eye(3), HALF_PI, LENGTHS, straight)[-1],
                               HIP + [0.0, 0.0, out], atol=1e-15)
    yaw, pitch, roll = 0.4, 0.3, 0.2
    # yaw: forward = (cos, 0, sin)
    np.testing.assert_allclose(forward_kinematics(HIP, body_rotation(yaw), 0.0, LENGTHS, straight)[-1],
                               HIP + out * np.array([math.cos(yaw), 0.0, math.sin(yaw)]), atol=1e-15)
    # pitch, nose up positive: a forward leg rises
    np.testing.assert_allclose(forward_kinematics(HIP, body_rotation(0.0, pitch), 0.0, LENGTHS, straight)[-1],
                               HIP + out * np.array([math.cos(pitch), math.sin(pitch), 0.0]), atol=1e-15)
    # roll, left side up positive: a left leg rises
    np.testing.assert_allclose(forward_kinematics(HIP, body_rotation(0.0, 0.0, roll), HALF_PI, LENGTHS, straight)[-1],
                               HIP + out * np.array([0.0, math.sin(roll), math.cos(roll)]), atol=1e-15)
    # the composition R = R_yaw @ R_pitch @ R_roll, columns = body forward, up, left
    r = body_rotation(yaw, pitch, roll)
    r_yaw = np.array([[math.cos(yaw), 0, -math.sin(yaw)], [0, 1, 0], [math.sin(yaw), 0, math.cos(yaw)]])
    r_pitch = np.array([[math.cos(pitch), -math.sin(pitch), 0], [math.sin(pitch), math.cos(pitch), 0], [0, 0, 1]])
    r_roll = np.array([[1, 0, 0], [0, math.cos(roll), math.sin(roll)], [0, -math.sin(roll), math.cos(roll)]])
    np.testing.assert_allclose(r, r_yaw @ r_pitch @ r_roll, atol=1e-15)
    np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-15)
    assert np.linalg.det(r) == pytest.approx(1.0)
    np.testing.assert_array_equal(body_rotation_kernel(yaw, pitch, roll), r)


def test_clamping_is_circular():
    assert nearest_in_limits(0.5, -1.0, 1.0) == 0.5
    assert nearest_in_limits(2.0, -1.0, 1.0) == 1.0
    assert nearest_in_limits(-2.0, -1.0, 1.0) == -1.0
    assert nearest_in_limits(3.5, -1.0, 1.0) == -1.0  # 3.5 rad is nearer -1 than 1 round the circle
    assert nearest_in_limits(2 * math.pi + 0.5, -1.0, 1.0) == pytest.approx(0.5)
    got = clamp_angles([[2.0, -3.0, 0.2]], [[[-1.0, 0.5], [0.0, 2.4]]], 1.2)
    np.testing.assert_allclose(got, [[1.2, -1.0, 0.2]])


# --------------------------------------------------------------------------- reachable targets

N_REACHABLE = 600


@pytest.mark.parametrize("name", CREATURES)
def test_reachable_targets_converge_within_limits(name):
    """Targets = FK of random angles within the limits, bodies posed at random: all converge."""
    creature = load_creature(name)
    legs = legs_of(creature)
    rng = np.random.default_rng(7)
    idx = rng.integers(0, creature.n_legs, N_REACHABLE)
    rest, lengths, limits, az = leg_batch(legs, idx)
    pelvis, rotations = random_bodies(rng, N_REACHABLE)
    hips = pelvis + np.einsum("nij,nj->ni", rotations, legs.hips[idx])
    truth = random_angles(rng, limits, az)
    targets = forward_legs(hips, rotations, rest, lengths, truth)[:, -1]

    result = solve_legs(hips, rotations, rest, lengths, limits, az, targets)
    assert np.all(result.residual < DEFAULT_TOLERANCE), np.sort(result.residual)[-5:]
    assert result.converged.all()
    assert np.all((result.iterations >= 1) & (result.iterations <= DEFAULT_MAX_ITERATIONS))
    assert_within_limits(result.angles, limits, az)
    assert_consistent(result, hips, rotations, rest, lengths, targets)
    np.testing.assert_allclose(result.feet, targets, rtol=0, atol=DEFAULT_TOLERANCE)


@pytest.mark.parametrize("name", CREATURES)
def test_residual_never_grows_with_more_sweeps(name):
    """Every CCD step is an exact (clamped) minimiser: a single descent never moves away."""
    creature = load_creature(name)
    legs = legs_of(creature)
    rng = np.random.default_rng(11)
    n = 200
    idx = rng.integers(0, creature.n_legs, n)
    rest, lengths, limits, az = leg_batch(legs, idx)
    hips = legs.hips[idx]
    rotations = tile(np.eye(3), n)
    targets = hips + rng.normal(size=(n, 3)) * lengths.sum(axis=1, keepdims=True)
    warm = random_angles(rng, limits, az)
    previous = None
    for sweeps in range(6):
        result = solve_legs(hips, rotations, rest, lengths, limits, az, targets, warm_start=warm,
                            max_iterations=sweeps, tolerance=0.0, restarts=0)
        if previous is not None:
            assert np.all(result.residual <= previous + 1e-12)
        previous = result.residual


# --------------------------------------------------------------------------- unreachable and degenerate targets


def reachable_cloud(rng, legs, leg, n):
    """Feet of ``n`` random poses of one leg, many joints at a limit (where closest poses lie)."""
    limits = legs.limits[leg]
    a_lim = legs.azimuth_limits[leg]
    angles = random_angles(rng, tile(limits, n), tile(a_lim, n))
    lo = np.r_[-a_lim, limits[:, 0]]
    hi = np.r_[a_lim, limits[:, 1]]
    ends = np.where(rng.random(angles.shape) < 0.5, lo, hi)
    angles = np.where(rng.random(angles.shape) < 0.3, ends, angles)
    return forward_legs(tile(legs.hips[leg], n), tile(np.eye(3), n), tile(legs.rest_azimuths[leg], n),
                        tile(legs.segment_lengths[leg], n), angles)[:, -1]


@pytest.mark.parametrize("name", CREATURES)
def test_unreachable_targets_end_at_the_closest_reachable_point(name):
    """Random targets up to 2 reaches from the hip, mostly unreachable: within the limits, no
    NaN, and the residual (= the distance of the reported pose) matches a brute-force sample
    of the reachable set within 3 mm (measured: within 0.2 mm)."""
    creature = load_creature(name)
    legs = legs_of(creature)
    rng = np.random.default_rng(3)
    leg = 0
    n = 300
    tree = cKDTree(reachable_cloud(rng, legs, leg, 150_000))
    reach = legs.segment_lengths[leg].sum()
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    targets = legs.hips[leg] + direction * reach * rng.uniform(0.0, 2.0, (n, 1))
    best, _ = tree.query(targets)
    assert np.mean(best > 0.01) > 0.4  # the test is about unreachable targets

    hips = tile(legs.hips[leg], n)
    rotations = tile(np.eye(3), n)
    rest, lengths, limits, az = (tile(a, n) for a in leg_batch(legs, leg))
    result = solve_legs(hips, rotations, rest, lengths, limits, az, targets)
    assert_within_limits(result.angles, limits, az)
    assert_consistent(result, hips, rotations, rest, lengths, targets)
    assert np.all(result.residual <= best + 3e-3), np.max(result.residual - best)


def test_degenerate_targets_and_warm_starts_give_no_nan():
    creature = load_creature("spider")
    legs = legs_of(creature)
    rest, lengths, limits, az = (tile(a, 6) for a in leg_batch(legs, 0))
    hip = legs.hips[0]
    hips = tile(hip, 6)
    rotations = tile(np.eye(3), 6)
    targets = np.array([
        hip,                          # exactly at the hip
        hip + [0.0, -0.2, 0.0],       # straight below: no horizontal direction for the leg plane
        hip + [0.0, 5.0, 0.0],        # far straight above
        hip + [0.0, -0.2, 0.0],
        hip + [1e-13, -0.2, 0.0],     # almost straight below
        hip + [0.3, -0.1, 0.2],
    ])
    warm = np.array([
        [0.0, 0.6, 1.0, 2.4, 1.2],    # folded
        [0.0, HALF_PI, 0.0, 0.0, 0.0],  # out of limits: clamped first
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [1.2, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.6, 1.0, 0.0, 0.0],
        [9.0, -7.0, 40.0, -2.0, 3.0],  # far outside the limits
    ])
    for warm_start in (warm, None):
        for restarts in (0, 8):
            result = solve_legs(hips, rotations, rest, lengths, limits, az, targets, warm_start=warm_start,
                                restarts=restarts)
            assert_within_limits(result.angles, limits, az)
            assert_consistent(result, hips, rotations, rest, lengths, targets)
    # no sweeps: the warm start brought into the limits, and its residual
    result = solve_legs(hips, rotations, rest, lengths, limits, az, targets, warm_start=warm, max_iterations=0)
    np.testing.assert_array_equal(result.angles, clamp_angles(warm, limits, az))
    assert np.all(result.iterations == 0)
    assert_consistent(result, hips, rotations, rest, lengths, targets)


# --------------------------------------------------------------------------- warm starts, determinism, frames


def test_warm_start_from_the_solution_needs_no_further_sweep():
    creature = load_creature("spider")
    legs = legs_of(creature)
    rng = np.random.default_rng(5)
    n = 400
    idx = rng.integers(0, creature.n_legs, n)
    rest, lengths, limits, az = leg_batch(legs, idx)
    hips = legs.hips[idx]
    rotations = tile(np.eye(3), n)
    targets = forward_legs(hips, rotations, rest, lengths, random_angles(rng, limits, az))[:, -1]
    first = solve_legs(hips, rotations, rest, lengths, limits, az, targets)
    again = solve_legs(hips, rotations, rest, lengths, limits, az, targets, warm_start=first.angles)
    assert np.all(again.iterations == 0)  # already within tolerance: converged with no sweep at all
    np.testing.assert_array_equal(again.angles, first.angles)
    np.testing.assert_array_equal(again.residual, first.residual)
    # the next frame: every target moved by 5 mm; without restarts the pose stays continuous
    step = rng.normal(size=(n, 3))
    moved = targets + 0.005 * step / np.linalg.norm(step, axis=1, keepdims=True)
    follow = solve_legs(hips, rotations, rest, lengths, limits, az, moved, warm_start=first.angles, restarts=0)
    assert follow.converged.mean() > 0.95  # the others left the reachable set (a joint at its limit)
    assert np.median(follow.iterations) == 1
    hinge_moves = np.abs(follow.angles - first.angles)[:, 1:].max(axis=1)
    assert np.percentile(hinge_moves, 99) < 0.5  # measured 0.41: no knee flips to a mirror pose


def test_an_abduction_joint_rolls_the_leg_plane_by_hand():
    # The quadruped's legs stand under their hips beside the body: their plane joint is an abduction.
    # The plane faces forward and rolls about the forward axis: a leg hanging straight down (pitch_0 =
    # pi/2, no bend) rolled by q0 puts its foot at hip + L (0, -cos q0, -sin q0) (q0 > 0: to the right).
    creature = load_creature("quadruped")
    legs = legs_of(creature)
    assert legs.plane_rolls.all() and np.all(legs.rest_azimuths == 0.0)
    leg = creature.leg_names.index("LF")
    length = legs.segment_lengths[leg].sum()
    for q0 in (0.0, 0.3, -0.45):
        angles = np.array([[q0, 0.5 * math.pi, 0.0, 0.0]])
        joints = forward_legs(legs.hips[leg][None], np.eye(3)[None], legs.rest_azimuths[leg:leg + 1],
                              legs.segment_lengths[leg:leg + 1], angles, plane_rolls=legs.plane_rolls[leg:leg + 1])
        np.testing.assert_allclose(joints[0, -1], legs.hips[leg] + length * np.array([0.0, -math.cos(q0), -math.sin(q0)]),
                                   atol=1e-12)
    # the same angles without the roll flag: an azimuth joint turning the plane about the up axis (the
    # leg hangs straight down whatever the azimuth)
    flat = forward_legs(legs.hips[leg][None], np.eye(3)[None], legs.rest_azimuths[leg:leg + 1],
                        legs.segment_lengths[leg:leg + 1], np.array([[0.3, 0.5 * math.pi, 0.0, 0.0]]))
    np.testing.assert_allclose(flat[0, -1], legs.hips[leg] + length * np.array([0.0, -1.0, 0.0]), atol=1e-12)


def test_an_upright_leg_keeps_its_knee_in_its_fore_aft_plane_as_its_foot_passes_the_hip():
    # A stance foot passes its hip from front to back, beside the hip's fore-aft line (outside and
    # inside it): a leg whose plane turned about the up axis swung its plane half a circle as the foot
    # passed, folding the knee under the body across the other legs. The abducting leg reaches every
    # target frame to frame (warm started, as the runtime does), its plane rolls by small steps and
    # its knee stays within a few cm of the hip's fore-aft line.
    creature = load_creature("quadruped")
    legs = legs_of(creature)
    leg = creature.leg_names.index("LF")
    hip = legs.hips[leg]
    angles = rest_pose_angles(creature)[leg:leg + 1]
    args = (hip[None], np.eye(3)[None], legs.rest_azimuths[leg:leg + 1], legs.segment_lengths[leg:leg + 1],
            legs.limits[leg:leg + 1], legs.azimuth_limits[leg:leg + 1])
    for lateral in (0.04, 0.0, -0.03):  # outside, on and inside the hip's fore-aft line
        pose = angles.copy()
        for forward in np.linspace(0.15, -0.15, 61):  # 5 mm a frame
            target = hip + np.array([forward, -0.40, lateral])
            result = solve_legs(*args, target[None], warm_start=pose, plane_rolls=legs.plane_rolls[leg:leg + 1])
            assert result.converged[0], (lateral, forward, result.residual)
            if forward < 0.15:  # from the first target on (the rest pose is farther)
                assert abs(result.angles[0, 0] - pose[0, 0]) < 0.02, (lateral, forward)  # the plane: no turn
            knee = result.joints[0, 2] - hip
            assert abs(knee[2]) < 0.05, (lateral, forward, knee)
            pose = result.angles


def test_serial_and_parallel_kernels_are_bit_identical():
    creature = load_creature("spider")
    legs = legs_of(creature)
    rng = np.random.default_rng(9)
    n = 1000
    idx = rng.integers(0, creature.n_legs, n)
    rest, lengths, limits, az = leg_batch(legs, idx)
    pelvis, rotations = random_bodies(rng, n)
    hips = pelvis + np.einsum("nij,nj->ni", rotations, legs.hips[idx])
    reachable = forward_legs(hips, rotations, rest, lengths, random_angles(rng, limits, az))[:, -1]
    wild = hips + rng.normal(size=(n, 3)) * 0.4
    targets = np.where(rng.random((n, 1)) < 0.5, reachable, wild)
    targets[::50] = hips[::50]  # some targets at the hip
    warm = random_angles(rng, limits, az)
    for warm_start in (None, warm):
        a = solve_legs(hips, rotations, rest, lengths, limits, az, targets, warm_start=warm_start, parallel=False)
        b = solve_legs(hips, rotations, rest, lengths, limits, az, targets, warm_start=warm_start, parallel=True)
        for field in ("angles", "residual", "iterations", "joints"):
            assert np.array_equal(getattr(a, field), getattr(b, field)), field
        assert a.angles.tobytes() == b.angles.tobytes()


@pytest.mark.parametrize("name", CREATURES)
def test_solving_in_a_rotated_frame_rotates_the_solution(name):
    """Same legs and targets in the body frame, then posed in the world by a yaw, pitch, roll
    and pelvis: the same angles, and the joints are the posed ones. (For unreachable targets
    the closest pose is often not unique - e.g. with the azimuth at its limit, every in-plane
    pose reaching the target's projection is as close - so there only the residual agrees.)"""
    creature = load_creature(name)
    legs = legs_of(creature)
    rng = np.random.default_rng(13)
    n = 240
    idx = rng.integers(0, creature.n_legs, n)
    rest, lengths, limits, az = leg_batch(legs, idx)
    body_hips = legs.hips[idx]
    body_targets = forward_legs(body_hips, tile(np.eye(3), n), rest, lengths, random_angles(rng, limits, az))[:, -1]
    far = np.arange(n) < n // 4
    body_targets[far] += rng.normal(size=(far.sum(), 3)) * 0.1  # mostly unreachable
    local = solve_legs(body_hips, tile(np.eye(3), n), rest, lengths, limits, az, body_targets)
    near = local.converged
    assert near[~far].all()
    for yaw, pitch, roll in [(0.7, 0.0, 0.0), (-2.5, 0.3, -0.2), (3.0, -0.4, 0.5)]:
        r = body_rotation(yaw, pitch, roll)
        pelvis = np.array([3.0, 0.5, -2.0])
        hips, targets = pelvis + body_hips @ r.T, pelvis + body_targets @ r.T
        world = solve_legs(hips, tile(r, n), rest, lengths, limits, az, targets)
        np.testing.assert_allclose(world.angles[near], local.angles[near], rtol=0, atol=1e-7)
        np.testing.assert_allclose(world.joints[near], pelvis + local.joints[near] @ r.T, rtol=0, atol=1e-9)
        np.testing.assert_allclose(world.residual, local.residual, rtol=0, atol=5e-4)  # measured <= 1e-4
        assert_consistent(world, hips, tile(r, n), rest, lengths, targets)
        # the same rotation given as (yaw, pitch, roll) angles
        by_angles = solve_legs(hips, tile([yaw, pitch, roll], n), rest, lengths, limits, az, targets)
        np.testing.assert_allclose(by_angles.angles[near], world.angles[near], rtol=0, atol=1e-9)


# --------------------------------------------------------------------------- creatures


@pytest.mark.parametrize("name", CREATURES)
def test_rest_pose_angles_put_every_foot_on_its_rest_spot(name):
    creature = load_creature(name)
    legs = legs_of(creature)
    n, s = creature.n_legs, creature.n_segments
    assert legs.hips.shape == (n, 3) and legs.segment_lengths.shape == (n, s)
    assert legs.limits.shape == (n, s, 2)
    # Legs standing under their hip beside the body (the quadruped's) get an abduction joint and a
    # forward-facing plane, the others an azimuth joint with the default limit, facing their rest foot.
    offset = np.hypot(creature.rest_feet[:, 0] - creature.hips[:, 0], creature.rest_feet[:, 1] - creature.hips[:, 2])
    upright = offset < UPRIGHT_LEG_OFFSET * creature.leg_reach
    np.testing.assert_array_equal(legs.plane_rolls, upright)
    np.testing.assert_array_equal(legs.azimuth_limits, np.where(upright, ABDUCTION_LIMIT, DEFAULT_AZIMUTH_LIMIT))
    assert upright.all() == (creature.name == 'quadruped') and upright.any() == (creature.name == 'quadruped')
    directions = np.column_stack([np.cos(legs.rest_azimuths), np.sin(legs.rest_azimuths)])
    np.testing.assert_allclose(directions, np.where(upright[:, None], [1.0, 0.0], creature.foot_directions),
                               atol=1e-12)

    angles = rest_pose_angles(creature)
    assert angles.shape == (n, s + 1)
    assert_within_limits(angles, legs.limits, legs.azimuth_limits)
    # rest feet lie along the rest azimuths; an abducting leg's plane rolls through its rest foot
    rest = rest_feet_body(creature) - legs.hips
    rolled = np.arctan2(-rest[:, 2], -rest[:, 1])
    np.testing.assert_allclose(angles[:, 0], np.where(upright, rolled, 0.0), atol=1e-9)
    feet = forward_legs(legs.hips, tile(np.eye(3), n), legs.rest_azimuths, legs.segment_lengths, angles,
                        legs.plane_rolls)[:, -1]
    np.testing.assert_allclose(feet, rest_feet_body(creature), rtol=0, atol=1e-8)
    # posed in the world: the same angles put the feet on the posed rest spots
    pelvis, r = np.array([1.0, 0.3, 2.0]), body_rotation(0.8, 0.1, -0.1)
    hips = legs.world_hips(pelvis, r)
    np.testing.assert_allclose(hips, legs.world_hips(pelvis, [0.8, 0.1, -0.1]), atol=1e-15)
    world = solve_legs(hips, tile(r, n), legs.rest_azimuths, legs.segment_lengths, legs.limits, legs.azimuth_limits,
                       pelvis + rest_feet_body(creature) @ r.T, warm_start=angles, plane_rolls=legs.plane_rolls)
    assert np.all(world.iterations == 0)


# --------------------------------------------------------------------------- validation


def good_args(n=3):
    creature = load_creature("ant")
    legs = legs_of(creature)
    idx = np.arange(n)
    return {"hips": legs.hips[idx], "body_rotations": tile(np.eye(3), n), "rest_azimuths": legs.rest_azimuths[idx],
            "segment_lengths": legs.segment_lengths[idx], "limits": legs.limits[idx],
            "azimuth_limits": legs.azimuth_limits[idx], "targets": rest_feet_body(creature)[idx]}


def test_good_args_solve():
    result = solve_legs(**good_args())
    assert result.angles.shape == (3, 4) and result.joints.shape == (3, 5, 3)
    assert result.iterations.dtype == np.int64 and result.converged.all()
    solve_legs(**{**good_args(), "azimuth_limits": 0.5})  # a scalar limit for every leg


def not_rotation():
    r = tile(np.eye(3), 3)
    r[1, 0, 0] = 2.0
    return r


def mirror():
    r = tile(np.eye(3), 3)
    r[2, 2, 2] = -1.0
    return r


@pytest.mark.parametrize(
    "argument, value",
    [
        ("hips", np.zeros((2, 3))),
        ("hips", np.zeros((3, 2))),
        ("hips", [[0.0, 0.0, np.nan]] * 3),
        ("hips", [[1e13, 0.0, 0.0]] * 3),
        ("body_rotations", np.zeros((3, 3, 2))),
        ("body_rotations", np.eye(3)),  # one matrix for 2 legs (see below)
        ("body_rotations", not_rotation()),
        ("body_rotations", mirror()),
        ("rest_azimuths", np.zeros(2)),
        ("rest_azimuths", [0.0, np.inf, 0.0]),
        ("segment_lengths", np.ones((3, 1))),
        ("segment_lengths", -np.ones((3, 3))),
        ("segment_lengths", np.ones(3)),
        ("limits", np.zeros((3, 3))),
        ("limits", np.tile([1.0, -1.0], (3, 3, 1))),
        ("azimuth_limits", -1.0),
        ("azimuth_limits", np.ones(4)),
        ("targets", np.zeros((3, 4))),
        ("targets", "far away"),
        ("warm_start", np.zeros((3, 3))),
        ("warm_start", np.full((3, 4), np.nan)),
        ("max_iterations", -1),
        ("max_iterations", 2.5),
        ("restarts", True),
        ("tolerance", -1e-3),
        ("tolerance", float("nan")),
        ("tolerance", "small"),
    ],
)
def test_bad_arguments_raise_value_error_naming_them(argument, value):
    args = good_args()
    if argument == "body_rotations" and np.shape(value) == (3, 3):
        args = good_args(2)  # for 3 legs, (3, 3) would read as 3 (yaw, pitch, roll) rows
    args[argument] = value
    with pytest.raises(ValueError, match=f"^{argument}: "):
        solve_legs(**args)


def test_forward_legs_and_legs_of_validate():
    with pytest.raises(ValueError, match="^angles: "):
        forward_legs(np.zeros((2, 3)), tile(np.eye(3), 2), np.zeros(2), np.ones((2, 2)), np.zeros((2, 2)))
    with pytest.raises(ValueError, match="^azimuth_limit: "):
        legs_of(load_creature("ant"), azimuth_limit=-0.1)
    with pytest.raises(ValueError, match="^pelvis: "):
        legs_of(load_creature("ant")).world_hips([0.0, 0.0], np.eye(3))
