"""numba kernels: leg forward kinematics and batched CCD inverse kinematics (paper §3).

The paper solves the legs with Cyclic Coordinate Descent: "it minimizes the error
between the actual end effector position and the desired one by iteratively
modifying the angle of the joints". Here every leg of every character is solved
in ONE kernel call (``nb.prange`` over legs; legs never share data, so the
serial and parallel kernels give bit-identical results).

Frames and rotation convention
------------------------------
Units metres and radians, world y up. The body frame is (forward, up, left), as
in ``scenarios/README.md``. A body pose's rotation is::

    R = R_yaw(psi) @ R_pitch(theta) @ R_roll(phi)        (body vector -> world vector)

    R_yaw(psi)     = [[cos psi, 0, -sin psi],   columns: world forward (cos psi, 0, sin psi),
                      [0,       1,  0      ],            world up (0, 1, 0),
                      [sin psi, 0,  cos psi]]            world left (-sin psi, 0, cos psi)
    R_pitch(theta) = [[cos t, -sin t, 0],       nose up positive: forward turns towards up
                      [sin t,  cos t, 0],       (rotation about the lateral axis)
                      [0,      0,     1]]
    R_roll(phi)    = [[1, 0,      0    ],       left side up positive: left turns towards up
                      [0, cos p,  sin p],       (rotation about the forward axis)
                      [0, -sin p, cos p]]

i.e. intrinsic yaw, then pitch about the yawed lateral axis, then roll about the
resulting forward axis. The columns of R are the body's forward, up and left
axes in world coordinates. The kernels take R itself, (B, 3, 3) per leg
(:func:`body_rotation` builds it from the angles).

Leg model
---------
A leg has S >= 2 segments and S + 1 joints, angles ``q = [azimuth, pitch_0, ...,
pitch_{S-1}]``:

* the azimuth joint at the hip turns the leg's vertical plane about the body's
  up axis. The plane's outward direction, in body (forward, left) coordinates,
  is ``(cos b, sin b)`` with ``b = rest_azimuth + q[0]`` (``rest_azimuth`` =
  direction from the hip to the rest foot, measured like a heading: from
  forward towards left). World outward ``u = R @ (cos b, 0, sin b)``, world
  up of the plane ``w = R[:, 1]``. Limits ``|q[0]| <= azimuth_limit``.
* a leg with ``plane_rolls`` (an upright leg beside the body: the quadruped's)
  has an abduction joint instead: its plane keeps the outward direction
  ``(cos a, 0, sin a)`` (``a = rest_azimuth``, forward for an upright leg) and
  rolls about it by ``q[0]``: plane up ``w = R @ (cos q0 (0, 1, 0) + sin q0 p)``
  with ``p = (-sin a, 0, cos a)``, the horizontal left of the outward
  direction (q0 > 0 swings the foot to the right of its outward direction).
  A foot passing under its hip needs no turn of the plane (a vertical plane
  through hip and foot turns half a circle as the foot passes beside the hip,
  and a plane turned under the body folds the knee across the other legs).
  Limits ``|q[0]| <= azimuth_limit`` as well.
* hinge j sits at the proximal end of segment j, axis normal to the leg plane
  (README convention): ``pitch_0`` is segment 0's angle below the outward
  horizontal, ``pitch_j`` (j > 0) the bend of segment j relative to segment
  j - 1, positive = downward. With ``phi_j = pitch_0 + ... + pitch_j`` segment j
  points along ``cos(phi_j) u - sin(phi_j) w``. Limits ``limits[j] = (min, max)``.

Joint positions (S + 1 points for :func:`forward_kinematics`): hip (where the
azimuth joint and hinge 0 both sit), the end of each segment (knees...), foot.
The batched kernels write (S + 2) points: one per joint of ``q`` (the pivot of
``q[k]`` is row k, so rows 0 and 1 are both the hip) and the foot last.

CCD
---
Every leg is solved independently (``_solve_one``). One *sweep* (one
iteration) visits the joints from the last hinge to the azimuth, and every
step is an exact minimiser of the foot-target distance over its joint(s):

* hinge j (j = S-1 ... 0): rotating one hinge moves the foot on a circle in the
  leg plane; its point nearest the target is where the foot and the target are
  aligned as seen from the hinge. Limits then keep the feasible angle that is
  circularly closest to that optimum (the distance only grows with the angle
  away from it), see :func:`nearest_in_limits`.
* right after hinge j, with ``pair_steps``, the two-hinge steps (i, j) for
  i = j-1 ... 0 (:func:`_pair_step`): hinges i and j together, the rest of the
  leg rigid, solved in closed form with the law of cosines (two mirror
  solutions, clamped to the limits; kept only if the foot ends closer by more
  than round-off, :data:`TIE`; from a warm start only the solution bent the
  same way, so a knee never flips to its mirror pose for a small target move).
  Single-joint CCD alone converges linearly and often slowly (a leg that must
  unfold or fold) and gets stuck at limits: from the nearest grid pose, 32
  plain sweeps bring only about 70-80 % of the built-in creatures' reachable
  targets within 0.1 mm (median 8-16 sweeps). With these "triangle" steps a sweep or two usually lands on
  the target. ``pair_steps=False`` gives plain CCD.
* the azimuth, analytically: point the leg plane at the target (away from it
  when the foot is behind the hip, its in-plane outward coordinate < 0),
  clamped to +-azimuth_limit; a rolling plane joint rolls the plane through
  the target (the foot on the side of the hip it is on, below it as a rule),
  clamped the same way.

A step is skipped when undefined (the foot or the target on the joint's
rotation axis: a target at the hip, a degenerate leg plane), so no NaN ever
arises. No step increases the distance, so the residual never grows in a
descent.

Each descent first takes the azimuth step (a warm-started leg whose target moved
sideways then solves in the right plane), and a sweep ends at the first step
that brings the foot within the tolerance: a stance leg following its foot
while the body moves usually converges within its first sweep. The chain's
planar points and angles are cached per descent and recomputed from the moved
hinge on only (:func:`_chain_from`, bit-identical to :func:`_planar_point`).

Start, restarts and stops: a warm start is first brought into the limits
(:func:`nearest_in_limits`); a cold start takes the grid pose nearest the
target instead. The grid has ``k ** S`` hinge poses, k evenly spaced angles
from each hinge's min to its max, both included (:func:`seed_levels`: at most
:data:`MAX_SEEDS`), each with its analytic azimuth. A descent stops once the
residual < tolerance (0 sweeps when the start already is), when the sweep
budget is spent, at an exact fixed point (a sweep changing no angle), or - while
restarts remain - at a stall (a sweep leaving more than :data:`STALL_RATIO` of
the residual: a joint limit, a local minimum). A stalled descent restarts from
the next grid pose, nearest first (at most ``restarts`` times). The first
descent's pose is kept unless a restart converges or ends closer by more than
the tolerance (no jump to another pose for nothing); the rest of the budget
polishes the kept pose when its descent was cut short. ``max_iterations``
bounds the sweeps of all descents together. Unreachable targets thus end at a
closest reachable pose found, with the distance reported as the residual
(never NaN, never an exception). Once a pose reaches the foot, nothing else
replaces it (not a pose closer by round-off: the same legs posed in a rotated
frame get the same angles). Restarts trade continuity for reach: a warm
start whose target left its reachable branch (e.g. past the azimuth limit) may
jump to another pose that reaches it; ``restarts=0`` never leaves the branch.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from footfall.planner._kernels_geometry import wrap_pi

TWO_PI = 2.0 * math.pi
EPS = 1e-12
"""Lengths (m) below this count as zero: the step is then undefined and skipped."""
TIE = 1e-10
"""Distances (m) closer than this count as equal in the two-hinge steps (round-off)."""
MAX_SEEDS = 256
"""Cold starts and restarts pick among a grid of at most this many hinge poses (see :func:`seed_levels`)."""
STALL_RATIO = 0.5
"""A sweep that leaves more than this fraction of the residual counts as a stall (time to restart)."""


@nb.njit(cache=True)
def body_rotation(yaw, pitch, roll):
    """(3, 3) R = R_yaw @ R_pitch @ R_roll (module docstring); columns = body forward, up, left in world."""
    cy, sy = math.cos(yaw), math.sin(yaw)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cr, sr = math.cos(roll), math.sin(roll)
    r = np.empty((3, 3), dtype=np.float64)
    # forward = R_yaw (cp, sp, 0)
    r[0, 0] = cy * cp
    r[1, 0] = sp
    r[2, 0] = sy * cp
    # up = R_yaw R_pitch (0, cr, -sr) = R_yaw (-sp cr, cp cr, -sr)
    r[0, 1] = -cy * sp * cr + sy * sr
    r[1, 1] = cp * cr
    r[2, 1] = -sy * sp * cr - cy * sr
    # left = R_yaw R_pitch (0, sr, cr) = R_yaw (-sp sr, cp sr, cr)
    r[0, 2] = -cy * sp * sr - sy * cr
    r[1, 2] = cp * sr
    r[2, 2] = -sy * sp * sr + cy * cr
    return r


@nb.njit(cache=True)
def nearest_in_limits(x, lo, hi):
    """The angle in [lo, hi] circularly nearest to ``x`` (``x`` itself when inside)."""
    if lo <= x <= hi:
        return x
    r = lo + (x - lo) % TWO_PI  # representative of x in [lo, lo + 2 pi)
    if r <= hi:
        return r
    if r - hi <= lo + TWO_PI - r:
        return hi
    return lo


@nb.njit(cache=True, inline="always")
def _across(df, dl, alpha):
    """The target's horizontal coordinate to the left of the direction ``alpha`` (body frame)."""
    return -df * math.sin(alpha) + dl * math.cos(alpha)


@nb.njit(cache=True)
def _in_plane_target(df, du, dl, alpha, q_plane, rolls):
    """Target (outward, up, normal) coordinates in the leg plane at plane angle ``q_plane``
    (rest azimuth ``alpha``; ``rolls``: the plane rolls about its outward axis, module docstring)."""
    if rolls:
        side = _across(df, dl, alpha)
        cr = math.cos(q_plane)
        sr = math.sin(q_plane)
        return df * math.cos(alpha) + dl * math.sin(alpha), du * cr + side * sr, -du * sr + side * cr
    beta = alpha + q_plane
    cb = math.cos(beta)
    sb = math.sin(beta)
    return df * cb + dl * sb, du, -df * sb + dl * cb


@nb.njit(cache=True)
def _planar_point(lengths, q, b, upto):
    """(outward, up, cumulative pitch) of the proximal end of segment ``upto`` (S: the foot), hip at 0."""
    phi = 0.0
    x = 0.0
    y = 0.0
    for k in range(upto):
        phi += q[b, k + 1]
        x += lengths[b, k] * math.cos(phi)
        y -= lengths[b, k] * math.sin(phi)
    return x, y, phi


# The chain cache of a descent: row k (0 <= k <= S) holds the proximal end of segment k
# (row S: the foot) in the leg plane, and, for k < S, the cumulative pitch phi_k of segment
# k with its cosine and sine. A step that moves hinge j recomputes rows j.. only, in the
# summation order of :func:`_planar_point`, so cached values are bit-identical to it: the
# cache only saves the trigonometry of the unchanged proximal segments (most of a sweep's cost).
CH_X, CH_Y, CH_PHI, CH_COS, CH_SIN = range(5)
N_CHAIN = 5


@nb.njit(cache=True)
def _chain_from(b, lengths, q, j, chain):
    """Recompute the chain cache from hinge ``j`` on (rows j + 1 .. S, and the angles of rows j ..)."""
    n_seg = lengths.shape[1]
    if j == 0:
        chain[0, CH_X] = 0.0
        chain[0, CH_Y] = 0.0
    phi = chain[j - 1, CH_PHI] if j > 0 else 0.0
    for k in range(j, n_seg):
        phi += q[b, k + 1]
        c = math.cos(phi)
        s = math.sin(phi)
        chain[k, CH_PHI] = phi
        chain[k, CH_COS] = c
        chain[k, CH_SIN] = s
        chain[k + 1, CH_X] = chain[k, CH_X] + lengths[b, k] * c
        chain[k + 1, CH_Y] = chain[k, CH_Y] - lengths[b, k] * s


@nb.njit(cache=True)
def _phi_before(chain, k):
    """Cumulative pitch before segment ``k`` (0 at the hip)."""
    return chain[k - 1, CH_PHI] if k > 0 else 0.0


@nb.njit(cache=True)
def _grid_angle(lo, hi, k, levels):
    """Level ``k`` of ``levels`` evenly spaced angles from lo to hi (both included, exactly:
    ``lo + 1.0 * (hi - lo)`` can round past hi)."""
    return min(hi, lo + k / (levels - 1) * (hi - lo))


@nb.njit(cache=True)
def _azimuth_for(fx, fy, q_az, df, du, dl, alpha, azimuth_limit, rolls):
    """Exact single-joint step of the plane joint, clamped: the leg plane towards the target (away if
    fx < 0); a rolling plane through the target, the foot on its side of the hip (below if fy < 0)."""
    if rolls:
        side = _across(df, dl, alpha)
        if math.hypot(du, side) < EPS or abs(fy) < EPS:
            return q_az
        want = math.atan2(-side, -du)
        if fy > 0.0:
            want += math.pi
        return nearest_in_limits(q_az + wrap_pi(want - q_az), -azimuth_limit, azimuth_limit)
    horizontal = math.hypot(df, dl)
    if horizontal < EPS or abs(fx) < EPS:
        return q_az
    want = math.atan2(dl, df) - alpha
    if fx < 0.0:
        want += math.pi
    # the wanted azimuth's representative nearest the current one, then the limits
    return nearest_in_limits(q_az + wrap_pi(want - q_az), -azimuth_limit, azimuth_limit)


@nb.njit(cache=True)
def seed_levels(n_seg):
    """Grid levels per hinge: the largest k >= 2 with k ** S <= MAX_SEEDS (S = 2: 16, 3: 6, 4: 4, 5: 3)."""
    k = 2
    while (k + 1) ** n_seg <= MAX_SEEDS:
        k += 1
    return k


@nb.njit(cache=True)
def _next_seed(b, lengths, limits, azimuth_limits, df, du, dl, alpha, rolls, levels, after_dist, after_code):
    """The grid pose after (``after_dist``, ``after_code``) in (squared distance, code) order.

    Grid: ``levels ** S`` hinge poses, each with its analytic azimuth. Returns
    (distance squared, code); code -1 when none is left. Start with (-1, -1).
    """
    n_seg = lengths.shape[1]
    total = 1
    for j in range(n_seg):
        total *= levels
    best_dist = np.inf
    best_code = -1
    for code in range(total):
        c = code
        phi = 0.0
        x = 0.0
        y = 0.0
        for j in range(n_seg):
            phi += _grid_angle(limits[b, j, 0], limits[b, j, 1], c % levels, levels)
            c //= levels
            x += lengths[b, j] * math.cos(phi)
            y -= lengths[b, j] * math.sin(phi)
        az = _azimuth_for(x, y, 0.0, df, du, dl, alpha, azimuth_limits[b], rolls)
        tx, ty, tn = _in_plane_target(df, du, dl, alpha, az, rolls)
        d = (x - tx) ** 2 + (y - ty) ** 2 + tn * tn
        if (d > after_dist or (d == after_dist and code > after_code)) and d < best_dist:
            best_dist = d
            best_code = code
    return best_dist, best_code


@nb.njit(cache=True)
def _set_grid_pose(b, code, levels, lengths, limits, azimuth_limits, df, du, dl, alpha, rolls, q):
    """q[b] = grid pose ``code`` with its analytic azimuth."""
    c = code
    for j in range(lengths.shape[1]):
        q[b, j + 1] = _grid_angle(limits[b, j, 0], limits[b, j, 1], c % levels, levels)
        c //= levels
    fx, fy, _ = _planar_point(lengths, q, b, lengths.shape[1])
    q[b, 0] = _azimuth_for(fx, fy, 0.0, df, du, dl, alpha, azimuth_limits[b], rolls)


@nb.njit(cache=True)
def _hinge_step(b, j, lengths, limits, q, fx, fy, tx, ty, chain):
    """Single-joint CCD step of hinge ``j`` (exact minimiser, clamped). Returns (changed, fx, fy)."""
    px = chain[j, CH_X]
    py = chain[j, CH_Y]
    ax = fx - px
    ay = fy - py
    bx = tx - px
    by = ty - py
    if ax * ax + ay * ay < EPS * EPS or bx * bx + by * by < EPS * EPS:
        return False, fx, fy
    # counter-clockwise angle (outward towards up) from foot to target; a positive pitch turns downward
    turn = math.atan2(ax * by - ay * bx, ax * bx + ay * by)
    old = q[b, j + 1]
    new = nearest_in_limits(old - turn, limits[b, j, 0], limits[b, j, 1])
    if new == old:
        return False, fx, fy
    q[b, j + 1] = new
    _chain_from(b, lengths, q, j, chain)
    n_seg = lengths.shape[1]
    return True, chain[n_seg, CH_X], chain[n_seg, CH_Y]


@nb.njit(cache=True)
def _pair_step(b, i, j, lengths, limits, q, fx, fy, tx, ty, mirror, chain):
    """Two-hinge closed-form step of hinges ``i < j`` (the rest of the leg rigid), kept only if closer.

    The rigid link from hinge i to hinge j (length A) and the rigid "virtual
    link" from hinge j to the foot (length V) form a triangle with the target:
    the law of cosines gives the two mirror solutions (straight or folded when
    the target is out of their range). In each, hinge j is brought into its
    limits, hinge i re-aimed exactly for it (the two links' sum towards the
    target) and clamped. The closer candidate (of two as close, the one moving the
    joints less) replaces the pose if it brings the foot closer to the target by
    more than :data:`TIE`. Without ``mirror`` only the solution bent the way the
    pair is bent now is considered (warm starts: no flip of a knee to its mirror
    pose for a small target move). Returns (changed, fx, fy).
    """
    px = chain[i, CH_X]
    py = chain[i, CH_Y]
    phi_before = _phi_before(chain, i)
    phi_j = chain[j, CH_PHI]
    # joint j itself sits at the end of segment j - 1 (from the end of segment j, as ever: same bits)
    jx = chain[j + 1, CH_X] - lengths[b, j] * chain[j, CH_COS]
    jy = chain[j + 1, CH_Y] + lengths[b, j] * chain[j, CH_SIN]
    ax = jx - px
    ay = jy - py
    a_len = math.hypot(ax, ay)
    vx = fx - jx
    vy = fy - jy
    v_len = math.hypot(vx, vy)
    dx = tx - px
    dy = ty - py
    d_len = math.hypot(dx, dy)
    if a_len < EPS or v_len < EPS or d_len < EPS:
        return False, fx, fy
    old_i = q[b, i + 1]
    old_j = q[b, j + 1]
    phi_i = phi_before + old_i
    # counter-clockwise angles of the links relative to their segments (direction angle -phi)
    offset_a = math.atan2(ay, ax) + phi_i
    offset_v = math.atan2(vy, vx) + phi_j
    middle = phi_j - phi_i - old_j  # bends strictly between hinges i and j (fixed)
    c = (d_len * d_len - a_len * a_len - v_len * v_len) / (2.0 * a_len * v_len)
    spread = math.acos(min(1.0, max(-1.0, c)))
    target_angle = math.atan2(dy, dx)
    current = math.sqrt((fx - tx) ** 2 + (fy - ty) ** 2)
    found = False
    best_i = old_i
    best_j = old_j
    best = current
    best_motion = 0.0
    bend = wrap_pi(offset_v - offset_a - middle - old_j)  # current psi (see below)
    for side in range(2):
        # psi: ccw angle of the virtual link relative to link A
        psi = spread if side == 0 else -spread
        if not mirror and psi * bend < 0.0:
            continue  # keep the triangle's orientation (no flip to the mirror pose)
        new_j = offset_v - offset_a - middle - psi
        new_j = nearest_in_limits(old_j + wrap_pi(new_j - old_j), limits[b, j, 0], limits[b, j, 1])
        psi = offset_v - offset_a - middle - new_j
        kappa = math.atan2(v_len * math.sin(psi), a_len + v_len * math.cos(psi))
        new_i = offset_a + kappa - target_angle - phi_before
        new_i = nearest_in_limits(old_i + wrap_pi(new_i - old_i), limits[b, i, 0], limits[b, i, 1])
        theta_a = offset_a - phi_before - new_i  # ccw direction of link A
        cx = px + a_len * math.cos(theta_a) + v_len * math.cos(theta_a + psi)
        cy = py + a_len * math.sin(theta_a) + v_len * math.sin(theta_a + psi)
        d = math.sqrt((cx - tx) ** 2 + (cy - ty) ** 2)
        motion = abs(new_i - old_i) + abs(new_j - old_j)
        # only improvements beyond round-off (TIE) count; between two candidates as close as
        # each other, the smaller motion wins: continuity, and no choice is left to round-off
        if d < current - TIE and (not found or d < best - TIE or (d <= best + TIE and motion < best_motion)):
            found = True
            best = d
            best_i = new_i
            best_j = new_j
            best_motion = motion
    if not found:
        return False, fx, fy
    q[b, i + 1] = best_i
    q[b, j + 1] = best_j
    _chain_from(b, lengths, q, i, chain)
    n_seg = lengths.shape[1]
    return True, chain[n_seg, CH_X], chain[n_seg, CH_Y]


@nb.njit(cache=True)
def _descend(b, lengths, limits, azimuth_limits, df, du, dl, alpha, rolls, pair_steps, mirror, budget, tolerance,
             stop_on_stall, q, chain):
    """CCD sweeps on q[b] from its current pose. Returns (residual, sweeps used, stopped by a stall).

    Stops below ``tolerance``, after ``budget`` sweeps, at a fixed point, or (with
    ``stop_on_stall``) after a sweep that left more than :data:`STALL_RATIO` of
    the residual.
    """
    n_seg = lengths.shape[1]
    _chain_from(b, lengths, q, 0, chain)
    fx = chain[n_seg, CH_X]
    fy = chain[n_seg, CH_Y]
    # The leg plane first: a warm-started leg whose target moved sideways (the body moved)
    # then solves in the right plane, and can stop within its first sweep.
    if budget > 0:
        q[b, 0] = _azimuth_for(fx, fy, q[b, 0], df, du, dl, alpha, azimuth_limits[b], rolls)
    tx, ty, tn = _in_plane_target(df, du, dl, alpha, q[b, 0], rolls)
    residual = math.sqrt((fx - tx) ** 2 + (fy - ty) ** 2 + tn * tn)
    used = 0
    while residual >= tolerance and used < budget:
        used += 1
        changed = False
        previous = residual
        # hinges, last to first: rotate the foot about hinge j towards the target, in the leg plane;
        # the sweep ends as soon as a step brings the foot within the tolerance
        reached = False
        tn2 = tn * tn
        for j in range(n_seg - 1, -1, -1):
            moved, fx, fy = _hinge_step(b, j, lengths, limits, q, fx, fy, tx, ty, chain)
            changed |= moved
            if moved and (fx - tx) ** 2 + (fy - ty) ** 2 + tn2 < tolerance * tolerance:
                reached = True
                break
            if pair_steps:
                for i in range(j - 1, -1, -1):
                    moved, fx, fy = _pair_step(b, i, j, lengths, limits, q, fx, fy, tx, ty, mirror, chain)
                    changed |= moved
                    if moved and (fx - tx) ** 2 + (fy - ty) ** 2 + tn2 < tolerance * tolerance:
                        reached = True
                        break
                if reached:
                    break
        if reached:
            return math.sqrt((fx - tx) ** 2 + (fy - ty) ** 2 + tn2), used, False
        # azimuth: analytic
        new = _azimuth_for(fx, fy, q[b, 0], df, du, dl, alpha, azimuth_limits[b], rolls)
        if new != q[b, 0]:
            q[b, 0] = new
            changed = True
            tx, ty, tn = _in_plane_target(df, du, dl, alpha, new, rolls)
        residual = math.sqrt((fx - tx) ** 2 + (fy - ty) ** 2 + tn * tn)
        if not changed:
            break
        if stop_on_stall and residual > STALL_RATIO * previous:
            return residual, used, True
    return residual, used, False


@nb.njit(cache=True, inline="always")
def _target_in_body(b, hips, rotations, targets):
    """Leg ``b``'s target relative to its hip, in body (forward, up, left) coordinates."""
    ex = targets[b, 0] - hips[b, 0]
    ey = targets[b, 1] - hips[b, 1]
    ez = targets[b, 2] - hips[b, 2]
    df = rotations[b, 0, 0] * ex + rotations[b, 1, 0] * ey + rotations[b, 2, 0] * ez
    du = rotations[b, 0, 1] * ex + rotations[b, 1, 1] * ey + rotations[b, 2, 1] * ez
    dl = rotations[b, 0, 2] * ex + rotations[b, 1, 2] * ey + rotations[b, 2, 2] * ez
    return df, du, dl


@nb.njit(cache=True, inline="always")
def _warm_into_limits(b, q, warm, limits, azimuth_limits, n_seg):
    """Row ``b`` of ``q``: the warm start brought into the azimuth and joint limits."""
    q[b, 0] = nearest_in_limits(warm[b, 0], -azimuth_limits[b], azimuth_limits[b])
    for j in range(n_seg):
        q[b, j + 1] = nearest_in_limits(warm[b, j + 1], limits[b, j, 0], limits[b, j, 1])


@nb.njit(cache=True)
def _solve_one(b, hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets, warm, cold,
               restarts, pair_steps, max_iterations, tolerance, out_angles, out_residual, out_iterations, out_joints):
    """CCD with restarts for leg ``b`` (module docstring); writes row ``b`` of every output."""
    n_seg = lengths.shape[1]
    q = out_angles
    df, du, dl = _target_in_body(b, hips, rotations, targets)
    alpha = rest_azimuths[b]
    rolls = plane_rolls[b]

    # warm start, brought into the limits (replaced by the nearest grid pose when cold)
    _warm_into_limits(b, q, warm, limits, azimuth_limits, n_seg)
    levels = seed_levels(n_seg)
    seed_dist = -1.0
    seed_code = -1
    need_seed = cold
    polish = False  # last round: more sweeps on the best pose, without stall stops
    best = np.empty(n_seg + 1, dtype=np.float64)
    chain = np.empty((n_seg + 1, N_CHAIN), dtype=np.float64)
    best_residual = np.inf
    have_best = False
    best_seeded = False  # the best pose descends from a grid pose (not from the warm start)
    best_cut = False  # the best pose's descent was stopped by a stall (it may still improve)
    used = 0
    attempt = 0  # restarts so far
    while True:
        if need_seed:
            seed_dist, seed_code = _next_seed(b, lengths, limits, azimuth_limits, df, du, dl, alpha, rolls, levels,
                                              seed_dist, seed_code)
            if seed_code < 0:
                break
            _set_grid_pose(b, seed_code, levels, lengths, limits, azimuth_limits, df, du, dl, alpha, rolls, q)
        # mirror solutions of the two-hinge steps only away from a warm start (continuity)
        seeded = need_seed or (polish and best_seeded)
        residual, sweeps, stalled = _descend(b, lengths, limits, azimuth_limits, df, du, dl, alpha, rolls,
                                             pair_steps, seeded, max_iterations - used, tolerance,
                                             attempt < restarts and not polish, q, chain)
        used += sweeps
        # a restart must converge or beat the best by more than the tolerance: no jump to another
        # pose for nothing (the polish continues the best pose, it never ends worse)
        better = residual < best_residual and (residual < tolerance or residual < best_residual - tolerance)
        if not have_best or polish or better:
            have_best = True
            best_seeded = seeded
            best_residual = residual
            best_cut = stalled
            for k in range(n_seg + 1):
                best[k] = q[b, k]
        if polish or used >= max_iterations:
            break
        if best_residual < tolerance:
            # Nothing replaces a pose that reaches its foot (not a pose closer by round-off: the same
            # legs posed in a rotated frame must get the same angles).
            break
        if attempt < restarts:
            # stalled or stuck: restart from the next grid pose, nearest first
            attempt += 1
            need_seed = True
        elif best_cut:
            polish = True
            need_seed = False
            for k in range(n_seg + 1):
                q[b, k] = best[k]
        else:
            break
    for k in range(n_seg + 1):
        q[b, k] = best[k]
    out_residual[b] = best_residual
    out_iterations[b] = used
    _joints_into(b, hips, rotations, rest_azimuths, plane_rolls, lengths, q, out_joints)


@nb.njit(cache=True)
def _leg_points(hip, rotation, rest_azimuth, rolls, lengths, angles, out):
    """World positions (S + 1, 3) into ``out``: hip, end of each segment (knees..., foot)."""
    if rolls:
        # outward u = R (cos a, 0, sin a); plane up w = R (cos q0 (0, 1, 0) + sin q0 (-sin a, 0, cos a))
        cb = math.cos(rest_azimuth)
        sb = math.sin(rest_azimuth)
        cr = math.cos(angles[0])
        sr = math.sin(angles[0])
        wf = -sr * sb
        wl = sr * cb
        wx = rotation[0, 0] * wf + rotation[0, 1] * cr + rotation[0, 2] * wl
        wy = rotation[1, 0] * wf + rotation[1, 1] * cr + rotation[1, 2] * wl
        wz = rotation[2, 0] * wf + rotation[2, 1] * cr + rotation[2, 2] * wl
    else:
        beta = rest_azimuth + angles[0]
        cb = math.cos(beta)
        sb = math.sin(beta)
        # plane up w = R[:, 1]
        wx = rotation[0, 1]
        wy = rotation[1, 1]
        wz = rotation[2, 1]
    # outward u = R (cos b, 0, sin b)
    ux = rotation[0, 0] * cb + rotation[0, 2] * sb
    uy = rotation[1, 0] * cb + rotation[1, 2] * sb
    uz = rotation[2, 0] * cb + rotation[2, 2] * sb
    out[0, 0] = hip[0]
    out[0, 1] = hip[1]
    out[0, 2] = hip[2]
    phi = 0.0
    x = 0.0
    y = 0.0
    for j in range(lengths.shape[0]):
        phi += angles[j + 1]
        x += lengths[j] * math.cos(phi)
        y -= lengths[j] * math.sin(phi)
        out[j + 1, 0] = hip[0] + x * ux + y * wx
        out[j + 1, 1] = hip[1] + x * uy + y * wy
        out[j + 1, 2] = hip[2] + x * uz + y * wz


@nb.njit(cache=True)
def _joints_into(b, hips, rotations, rest_azimuths, plane_rolls, lengths, angles, out_joints):
    """``out_joints[b]`` (S + 2, 3): azimuth pivot (the hip), hinge 0 (the hip), knees..., foot."""
    for k in range(3):
        out_joints[b, 0, k] = hips[b, k]
    _leg_points(hips[b], rotations[b], rest_azimuths[b], plane_rolls[b], lengths[b], angles[b], out_joints[b, 1:])


@nb.njit(cache=True)
def forward_kinematics(hip, rotation, rest_azimuth, lengths, angles, rolls=False):
    """(S + 1, 3) world positions of one leg: hip, knees..., foot.

    ``hip`` (3,) world, ``rotation`` (3, 3) body rotation (module docstring),
    ``rest_azimuth`` (rad), ``lengths`` (S,), ``angles`` (S + 1,) = [azimuth,
    pitch_0, ..., pitch_{S-1}], used as given (no limits here); ``rolls``: the
    plane joint is an abduction (module docstring).
    """
    out = np.empty((lengths.shape[0] + 1, 3), dtype=np.float64)
    _leg_points(hip, rotation, rest_azimuth, rolls, lengths, angles, out)
    return out


@nb.njit(cache=True, parallel=True)
def forward_kinematics_batch(hips, rotations, rest_azimuths, plane_rolls, lengths, angles, out_joints):
    """Joint positions (B, S + 2, 3) of B legs, rows as in :func:`solve_legs_serial`, in place
    (legs spread over the cores: the controller draws every leg of the crowd every frame)."""
    for i in nb.prange(hips.shape[0]):
        b = np.int64(i)
        _joints_into(b, hips, rotations, rest_azimuths, plane_rolls, lengths, angles, out_joints)


@nb.njit(cache=True)
def solve_legs_serial(hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets, warm, cold,
                      restarts, pair_steps, max_iterations, tolerance, out_angles, out_residual, out_iterations,
                      out_joints):
    """CCD over B legs with S segments, one leg after the other (module docstring).

    Inputs (struct of arrays over legs, float64, C-contiguous; unchecked: the
    Python API validates): ``hips`` (B, 3) world; ``rotations`` (B, 3, 3) body
    rotation of each leg's character; ``rest_azimuths`` (B,); ``plane_rolls`` (B,)
    bool, the plane joint is an abduction (module docstring); ``lengths`` (B, S)
    > 0; ``limits`` (B, S, 2) hinge (min, max), min < max; ``azimuth_limits``
    (B,) >= 0; ``targets`` (B, 3) world; ``warm`` (B, S + 1) warm-start angles;
    ``cold`` (bool): ignore ``warm``, start from the nearest grid pose;
    ``restarts`` (int >= 0) grid restarts after stalls; ``pair_steps`` (bool)
    the two-hinge closed-form steps (False: plain single-joint CCD);
    ``max_iterations`` (int >= 0) sweeps per leg, all descents together;
    ``tolerance`` (m).

    Outputs, in place: ``out_angles`` (B, S + 1), within the limits;
    ``out_residual`` (B,) = |FK foot - target| (m); ``out_iterations`` (B,)
    sweeps used; ``out_joints`` (B, S + 2, 3): row k is the pivot of angle k
    (rows 0 and 1 are both the hip), the foot last.
    """
    for b in range(hips.shape[0]):
        _solve_one(b, hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets, warm,
                   cold, restarts, pair_steps, max_iterations, tolerance, out_angles, out_residual, out_iterations,
                   out_joints)


@nb.njit(cache=True, parallel=True)
def solve_legs_parallel(hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets, warm,
                        cold, restarts, pair_steps, max_iterations, tolerance, out_angles, out_residual, out_iterations,
                        out_joints):
    """Same as :func:`solve_legs_serial`, legs spread over the cores (bit-identical results)."""
    for i in nb.prange(hips.shape[0]):
        b = np.int64(i)  # prange indices are unsigned: keep the serial kernel's signature (one compilation)
        _solve_one(b, hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets, warm,
                   cold, restarts, pair_steps, max_iterations, tolerance, out_angles, out_residual, out_iterations,
                   out_joints)


@nb.njit(cache=True)
def two_bone_pair(n_seg):
    """(i, j): the hinges the two-bone solve moves (the two longest bones of the built-in legs: the
    femur and the tibia of a four-segment leg, the first two hinges of a shorter one)."""
    i = max(0, n_seg - 3)
    return i, i + 1


@nb.njit(cache=True)
def _two_bone_one(b, hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets, warm,
                  tolerance, out_angles, out_residual, out_iterations, out_joints):
    """The analytic solve of leg ``b`` (:func:`solve_legs_two_bone_serial`); writes row ``b``."""
    n_seg = lengths.shape[1]
    q = out_angles
    df, du, dl = _target_in_body(b, hips, rotations, targets)
    alpha = rest_azimuths[b]
    rolls = plane_rolls[b]
    _warm_into_limits(b, q, warm, limits, azimuth_limits, n_seg)
    chain = np.empty((n_seg + 1, N_CHAIN), dtype=np.float64)
    _chain_from(b, lengths, q, 0, chain)
    fx = chain[n_seg, CH_X]
    fy = chain[n_seg, CH_Y]
    q[b, 0] = _azimuth_for(fx, fy, q[b, 0], df, du, dl, alpha, azimuth_limits[b], rolls)
    tx, ty, tn = _in_plane_target(df, du, dl, alpha, q[b, 0], rolls)
    i, j = two_bone_pair(n_seg)
    _, fx, fy = _pair_step(b, i, j, lengths, limits, q, fx, fy, tx, ty, False, chain)
    residual = math.sqrt((fx - tx) ** 2 + (fy - ty) ** 2 + tn * tn)
    used = 1
    if residual >= tolerance:
        # the two bones alone cannot reach (a limit, a target beyond their span): one CCD sweep of
        # the whole leg from there, no restart (the pose stays on its branch)
        residual, sweeps, _ = _descend(b, lengths, limits, azimuth_limits, df, du, dl, alpha, rolls, True, False, 1,
                                       tolerance, False, q, chain)
        used += sweeps
    out_residual[b] = residual
    out_iterations[b] = used
    _joints_into(b, hips, rotations, rest_azimuths, plane_rolls, lengths, q, out_joints)


@nb.njit(cache=True)
def solve_legs_two_bone_serial(hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets,
                               warm, tolerance, out_angles, out_residual, out_iterations, out_joints):
    """The far characters' IK (level of detail): from the warm start, the azimuth and then the two
    hinges of :func:`two_bone_pair` in closed form (:func:`_pair_step`, the bend kept: no flip),
    the other hinges rigid; one CCD sweep of the whole leg only when that leaves the foot beyond
    ``tolerance`` (a joint limit). Exact wherever the two bones reach, at a few trigonometric
    calls per leg instead of a CCD sweep's dozens. Arguments and outputs as
    :func:`solve_legs_serial` (warm starts only)."""
    for b in range(hips.shape[0]):
        _two_bone_one(b, hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets, warm,
                      tolerance, out_angles, out_residual, out_iterations, out_joints)


@nb.njit(cache=True, parallel=True)
def solve_legs_two_bone_parallel(hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits,
                                 targets, warm, tolerance, out_angles, out_residual, out_iterations, out_joints):
    """Same as :func:`solve_legs_two_bone_serial`, legs spread over the cores (bit-identical results)."""
    for i in nb.prange(hips.shape[0]):
        b = np.int64(i)
        _two_bone_one(b, hips, rotations, rest_azimuths, plane_rolls, lengths, limits, azimuth_limits, targets, warm,
                      tolerance, out_angles, out_residual, out_iterations, out_joints)
