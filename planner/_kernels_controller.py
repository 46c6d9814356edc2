"""numba kernels of the character controller's per-frame feet work (paper §3.2)."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from footfall.planner._kernels_geometry import rects_overlap, segments_cross


@nb.njit(cache=True)
def foot_box_conflict(x, y, z, foot_hx, foot_hz, foot_yaw, margin, box_centres, box_sizes, box_yaws, box_forbidden,
                      box_mask):
    """True when a foot at (x, y, z) (grown by ``margin``) overlaps a masked box below its
    top (any forbidden box counts at every height)."""
    # The two rectangles' circumscribed circles apart: no overlap (an exact cull of the box test).
    foot_r = math.hypot(foot_hx + margin, foot_hz + margin)
    for b in range(box_centres.shape[0]):
        if not box_mask[b]:
            continue
        dx = x - box_centres[b, 0]
        dz = z - box_centres[b, 2]
        reach = foot_r + 0.5 * math.hypot(box_sizes[b, 0], box_sizes[b, 2])
        if dx * dx + dz * dz > reach * reach:
            continue
        top = box_centres[b, 1] + 0.5 * box_sizes[b, 1]
        if not box_forbidden[b] and y >= top - 1e-9:
            continue
        if rects_overlap(x, z, foot_hx + margin, foot_hz + margin, foot_yaw, box_centres[b, 0], box_centres[b, 2],
                         0.5 * box_sizes[b, 0], 0.5 * box_sizes[b, 2], box_yaws[b]):
            return True
    return False


@nb.njit(cache=True, inline="always")
def swing_point(path, u, d):
    """Coordinate ``d`` of a swinging foot at fraction ``u`` (0..1) of its swing along ``path`` (K, 3): its
    samples are passed at a constant pace (the one definition :func:`advance_swings` moves feet by and
    :func:`swings_meet_moving_boxes` follows them by)."""
    k = path.shape[0]
    s = u * (k - 1)
    j = min(int(s), k - 2)
    a = s - j
    return path[j, d] + a * (path[j + 1, d] - path[j, d])


@nb.njit(cache=True)
def swing_points(paths, u, out):
    """Each foot's place at fraction ``u`` (F,) of its swing along ``paths`` (F, K, 3), into ``out`` (F, 3)."""
    for f in range(paths.shape[0]):
        for d in range(3):
            out[f, d] = swing_point(paths[f], min(max(u[f], 0.0), 1.0), d)


@nb.njit(cache=True, parallel=True)
def advance_swings(swing_t, swing_T, trajectories, in_stance, feet, dt, out_landed):
    """Move every swinging foot along its trajectory at constant speed; flag landings."""
    n_chars, n_legs, k, _ = trajectories.shape
    for c in nb.prange(n_chars):
        for i in range(n_legs):
            out_landed[c, i] = False
            if in_stance[c, i]:
                continue
            swing_t[c, i] += dt
            u = swing_t[c, i] / swing_T[c, i] if swing_T[c, i] > 0 else 1.0
            if u >= 1.0:
                for d in range(3):
                    feet[c, i, d] = trajectories[c, i, k - 1, d]
                out_landed[c, i] = True
                continue
            for d in range(3):
                feet[c, i, d] = swing_point(trajectories[c, i], u, d)


@nb.njit(cache=True, parallel=True)
def swings_invalidated(in_stance, swing_t, swing_T, trajectories, foot_hx, foot_hz, foot_yaws, box_centres,
                       box_sizes, box_yaws, box_forbidden, box_moving, near_radius, out):
    """Swinging feet whose remaining trajectory now runs into a moving box (paper §3.2:
    'something changed in the environment thus invalidating its current 3D trajectory')."""
    n_chars, n_legs, k, _ = trajectories.shape
    mask = np.zeros(box_centres.shape[0], dtype=np.bool_)
    for c in nb.prange(n_chars):
        local = mask.copy()
        for i in range(n_legs):
            out[c, i] = False
            if in_stance[c, i]:
                continue
            tx = trajectories[c, i, k - 1, 0]
            tz = trajectories[c, i, k - 1, 2]
            any_near = False
            for b in range(box_centres.shape[0]):
                local[b] = box_moving[b] and math.hypot(box_centres[b, 0] - tx, box_centres[b, 2] - tz) < near_radius
                any_near = any_near or local[b]
            if not any_near:
                continue
            u = swing_t[c, i] / swing_T[c, i] if swing_T[c, i] > 0 else 1.0
            j0 = min(k - 1, int(u * (k - 1)) + 1)
            for j in range(j0, k):
                if foot_box_conflict(trajectories[c, i, j, 0], trajectories[c, i, j, 1], trajectories[c, i, j, 2],
                                     foot_hx, foot_hz, foot_yaws[c, i], 0.0, box_centres, box_sizes, box_yaws,
                                     box_forbidden, local):
                    out[c, i] = True
                    break


@nb.njit(cache=True, parallel=True)
def swings_meet_moving_boxes(trajectories, swing_t, swing_T, dt, foot_hx, foot_hz, foot_yaws, frame_centres,
                             frame_yaws, box_sizes, box_forbidden, box_moving, out):
    """Swings (``trajectories`` (F, K, 3), at ``swing_t`` of ``swing_T`` s) whose foot, where
    :func:`advance_swings` puts it on each of the frames to come, overlaps a moving box where that box is
    then: ``frame_centres`` (J, B, 3), ``frame_yaws`` (J, B), the boxes 1..J frames from now. A path
    clear of the boxes' cells now can still graze one: a cell free of a box holds points a millimetre
    from it, the foot is not a point, and the box moves on during the swing. Into ``out`` (F,) bool."""
    n = trajectories.shape[0]
    n_frames = frame_centres.shape[0]
    for f in nb.prange(n):
        out[f] = False
        for j in range(1, n_frames + 1):
            u = (swing_t[f] + j * dt) / swing_T[f] if swing_T[f] > 0 else 1.0
            u = min(u, 1.0)
            x = swing_point(trajectories[f], u, 0)
            y = swing_point(trajectories[f], u, 1)
            z = swing_point(trajectories[f], u, 2)
            if foot_box_conflict(x, y, z, foot_hx, foot_hz, foot_yaws[f], 0.0, frame_centres[j - 1], box_sizes,
                                 frame_yaws[j - 1], box_forbidden, box_moving):
                out[f] = True
                break
            if u >= 1.0:
                break


@nb.njit(cache=True)
def points_in_boxes(points, foot_hx, foot_hz, foot_yaws, box_centres, box_sizes, box_yaws, box_forbidden, out):
    """Feet (a foot's box of half extents ``foot_hx``, ``foot_hz`` at each of ``points`` (F, 3), turned by
    ``foot_yaws`` (F,)) that overlap a box below its top (forbidden: at any height), into ``out`` (F,) bool."""
    every = np.ones(box_centres.shape[0], dtype=np.bool_)
    for f in range(points.shape[0]):
        out[f] = foot_box_conflict(points[f, 0], points[f, 1], points[f, 2], foot_hx, foot_hz, foot_yaws[f], 0.0,
                                   box_centres, box_sizes, box_yaws, box_forbidden, every)


@nb.njit(cache=True)
def push_out_of_boxes(points, foot_hx, foot_hz, foot_yaws, box_centres, box_sizes, box_yaws, box_forbidden, clearance,
                      rounds):
    """Move each of ``points`` (F, 3), in place, out of the boxes its foot overlaps (as
    :func:`points_in_boxes` counts them): across the box's nearest side, to the foot's circumscribed
    radius plus ``clearance`` from it. ``rounds`` passes, as one pushed out of a box may land in
    another; a point in a box after them is left where the last pass put it."""
    n_boxes = box_centres.shape[0]
    one = np.zeros(n_boxes, dtype=np.bool_)
    radius = math.hypot(foot_hx, foot_hz) + clearance
    for f in range(points.shape[0]):
        for _ in range(rounds):
            moved = False
            for b in range(n_boxes):
                one[b] = True
                hit = foot_box_conflict(points[f, 0], points[f, 1], points[f, 2], foot_hx, foot_hz, foot_yaws[f], 0.0,
                                        box_centres, box_sizes, box_yaws, box_forbidden, one)
                one[b] = False
                if not hit:
                    continue
                c, s = math.cos(box_yaws[b]), math.sin(box_yaws[b])
                dx, dz = points[f, 0] - box_centres[b, 0], points[f, 2] - box_centres[b, 2]
                lx, lz = c * dx + s * dz, -s * dx + c * dz
                ex, ez = 0.5 * box_sizes[b, 0] + radius, 0.5 * box_sizes[b, 2] + radius
                if ex - abs(lx) < ez - abs(lz):
                    lx = math.copysign(ex, lx)
                else:
                    lz = math.copysign(ez, lz)
                points[f, 0] = box_centres[b, 0] + c * lx - s * lz
                points[f, 2] = box_centres[b, 2] + s * lx + c * lz
                moved = True
            if not moved:
                break


@nb.njit(cache=True, parallel=True)
def stance_threatened(in_stance, feet, foot_hx, foot_hz, foot_yaws, margin, box_centres, box_sizes, box_yaws,
                      box_forbidden, box_moving, out):
    """Stance feet that a moving box is about to hit (within ``margin``): they step away."""
    n_chars, n_legs, _ = feet.shape
    for c in nb.prange(n_chars):
        for i in range(n_legs):
            out[c, i] = False
            if not in_stance[c, i]:
                continue
            if foot_box_conflict(feet[c, i, 0], feet[c, i, 1], feet[c, i, 2], foot_hx, foot_hz, foot_yaws[c, i],
                                 margin, box_centres, box_sizes, box_yaws, box_forbidden, box_moving):
                out[c, i] = True


@nb.njit(cache=True, parallel=True)
def count_collisions(feet, foot_hx, foot_hz, foot_yaws, box_centres, box_sizes, box_yaws, box_forbidden, out,
                     top_tolerance):
    """Per character, feet overlapping a box below its top (forbidden: at any height). A foot within
    ``top_tolerance`` below a box's top stands on it (a rendered foot is within the IK's tolerance of
    the planned one, which stands exactly on the top)."""
    n_chars, n_legs, _ = feet.shape
    everything = np.ones(box_centres.shape[0], dtype=np.bool_)
    for c in nb.prange(n_chars):
        n = 0
        for i in range(n_legs):
            if foot_box_conflict(feet[c, i, 0], feet[c, i, 1] + top_tolerance, feet[c, i, 2], foot_hx, foot_hz,
                                 foot_yaws[c, i], 0.0, box_centres, box_sizes, box_yaws, box_forbidden, everything):
                n += 1
        out[c] = n


@nb.njit(cache=True, parallel=True)
def count_leg_crossings(hips, feet, out):
    """Per character, pairs of legs whose ground projections (hip -> foot) cross."""
    n_chars, n_legs, _ = feet.shape
    for c in nb.prange(n_chars):
        n = 0
        for i in range(n_legs):
            for j in range(i + 1, n_legs):
                if segments_cross(hips[c, i, 0], hips[c, i, 2], feet[c, i, 0], feet[c, i, 2], hips[c, j, 0], hips[c, j, 2],
                          feet[c, j, 0], feet[c, j, 2]):
                    n += 1
        out[c] = n


@nb.njit(cache=True)
def count_forbidden_landings(landed, feet, foot_hx, foot_hz, foot_yaws, box_centres, box_sizes, box_yaws,
                             box_forbidden):
    """Feet that just landed on (or touching) a forbidden box."""
    n = 0
    for c in range(landed.shape[0]):
        for i in range(landed.shape[1]):
            if landed[c, i] and foot_box_conflict(feet[c, i, 0], feet[c, i, 1], feet[c, i, 2], foot_hx, foot_hz,
                                                  foot_yaws[c, i], 0.0, box_centres, box_sizes, box_yaws,
                                                  box_forbidden, box_forbidden):
                n += 1
    return n


@nb.njit(cache=True, inline="always")
def _bbox_apart(joints, c, i, j):
    """The ground bounding boxes of polylines ``joints[c, i]`` and ``joints[c, j]`` do not meet."""
    ix0 = ix1 = joints[c, i, 0, 0]
    iz0 = iz1 = joints[c, i, 0, 2]
    jx0 = jx1 = joints[c, j, 0, 0]
    jz0 = jz1 = joints[c, j, 0, 2]
    for a in range(1, joints.shape[2]):
        ix0 = min(ix0, joints[c, i, a, 0])
        ix1 = max(ix1, joints[c, i, a, 0])
        iz0 = min(iz0, joints[c, i, a, 2])
        iz1 = max(iz1, joints[c, i, a, 2])
        jx0 = min(jx0, joints[c, j, a, 0])
        jx1 = max(jx1, joints[c, j, a, 0])
        jz0 = min(jz0, joints[c, j, a, 2])
        jz1 = max(jz1, joints[c, j, a, 2])
    return ix1 < jx0 or jx1 < ix0 or iz1 < jz0 or jz1 < iz0


@nb.njit(cache=True)
def polylines_cross(joints, c, i, j):
    """Leg i's ground projection (the polyline ``joints[c, i]``, P points, hip first) crosses leg j's:
    some segment pair intersects properly (a crossing at a shared hip does not count)."""
    n_points = joints.shape[2]
    # bounding boxes first: most leg pairs are apart
    if _bbox_apart(joints, c, i, j):
        return False
    for a in range(n_points - 1):
        for b in range(n_points - 1):
            if segments_cross(joints[c, i, a, 0], joints[c, i, a, 2], joints[c, i, a + 1, 0], joints[c, i, a + 1, 2],
                              joints[c, j, b, 0], joints[c, j, b, 2], joints[c, j, b + 1, 0], joints[c, j, b + 1, 2]):
                return True
    return False


@nb.njit(cache=True, parallel=True)
def count_polyline_crossings(joints, out):
    """Per character, pairs of legs whose rendered ground projections cross (:func:`polylines_cross`)."""
    n_chars, n_legs, _, _ = joints.shape
    for c in nb.prange(n_chars):
        n = 0
        for i in range(n_legs):
            for j in range(i + 1, n_legs):
                if polylines_cross(joints, c, i, j):
                    n += 1
        out[c] = n


@nb.njit(cache=True, parallel=True)
def crossing_pairs(joints, legs, out):
    """Per character, (L, L) bool: the pairs of legs of ``legs`` (C, L) bool whose rendered ground
    projections cross (:func:`polylines_cross`), both orders set; pairs with a leg not in ``legs``
    are False."""
    n_chars, n_legs, _, _ = joints.shape
    for c in nb.prange(n_chars):
        for i in range(n_legs):
            out[c, i, i] = False
            for j in range(i + 1, n_legs):
                crossed = legs[c, i] and legs[c, j] and polylines_cross(joints, c, i, j)
                out[c, i, j] = crossed
                out[c, j, i] = crossed


@nb.njit(cache=True, parallel=True)
def stance_legs_crossing(joints, in_stance, out):
    """Per character and leg, a stance leg whose rendered ground projection crosses another leg's
    (:func:`polylines_cross`): a body turning over its stance feet carries them across its other legs."""
    n_chars, n_legs, _, _ = joints.shape
    for c in nb.prange(n_chars):
        for i in range(n_legs):
            out[c, i] = False
        for i in range(n_legs):
            for j in range(i + 1, n_legs):
                if (in_stance[c, i] or in_stance[c, j]) and polylines_cross(joints, c, i, j):
                    out[c, i] = out[c, i] or in_stance[c, i]
                    out[c, j] = out[c, j] or in_stance[c, j]


@nb.njit(cache=True, parallel=True)
def count_body_overlaps(centres, headings, half_length, half_width, out):
    """Per character c, the other characters whose projected body box (an oriented rectangle of
    half extents ``half_length`` x ``half_width`` about its pelvis, along its heading) overlaps
    c's. Each overlapping pair is counted once, at its lower index (``out.sum()`` = pairs)."""
    n = centres.shape[0]
    reach = 2.0 * math.hypot(half_length, half_width)
    for c in nb.prange(n):
        k = 0
        for d in range(c + 1, n):
            dx = centres[d, 0] - centres[c, 0]
            dz = centres[d, 1] - centres[c, 1]
            if abs(dx) > reach or abs(dz) > reach:
                continue
            if rects_overlap(centres[c, 0], centres[c, 1], half_length, half_width, headings[c], centres[d, 0],
                             centres[d, 1], half_length, half_width, headings[d]):
                k += 1
        out[c] = k


@nb.njit(cache=True)
def moves_into_bodies(centres, headings, moves, half_length, half_width, neighbour_start, neighbour_index, out):
    """Per character c, True when its ground ``moves`` [c] makes its body box (half extents
    ``half_length`` x ``half_width`` along its heading, about its pelvis) overlap a neighbour's
    (CSR ``neighbour_start``, ``neighbour_index``) at the neighbour's place before the move, and
    brings the two nearer."""
    n = centres.shape[0]
    for c in range(n):
        out[c] = False
        ax = centres[c, 0] + moves[c, 0]
        az = centres[c, 1] + moves[c, 1]
        for a in range(neighbour_start[c], neighbour_start[c + 1]):
            d = neighbour_index[a]
            bx = centres[d, 0]
            bz = centres[d, 1]
            before = (bx - centres[c, 0]) ** 2 + (bz - centres[c, 1]) ** 2
            if (bx - ax) ** 2 + (bz - az) ** 2 >= before:
                continue
            if rects_overlap(ax, az, half_length, half_width, headings[c], bx, bz, half_length, half_width,
                             headings[d]):
                out[c] = True
                break


@nb.njit(cache=True)
def turns_into_bodies(centres, headings, turns, half_length, half_width, neighbour_start, neighbour_index, out):
    """Per character c, True when turning its body box (half extents ``half_length`` x ``half_width``
    along its heading, about its pelvis) by ``turns`` [c] makes it overlap a neighbour's (CSR
    ``neighbour_start``, ``neighbour_index``) that it did not overlap before: :func:`moves_into_bodies`
    for a turn on the spot. Characters are taken in order; a neighbour before c is seen at its heading
    after its turn where that turn was let through, one after c at its heading before: of two bodies that
    would turn into each other in one frame, the later is refused."""
    n = centres.shape[0]
    # Two boxes further apart than twice their half diagonal cannot overlap at any headings.
    apart = 4.0 * (half_length * half_length + half_width * half_width)
    for c in range(n):
        out[c] = False
        if turns[c] == 0.0:
            continue
        ax = centres[c, 0]
        az = centres[c, 1]
        turned = headings[c] + turns[c]
        for a in range(neighbour_start[c], neighbour_start[c + 1]):
            d = neighbour_index[a]
            bx = centres[d, 0]
            bz = centres[d, 1]
            if (bx - ax) ** 2 + (bz - az) ** 2 >= apart:
                continue
            # A neighbour before it in order is seen turned, if its turn was let through: two bodies turning
            # into each other in one frame, each turn clear of the other's old heading, overlapped.
            hd = headings[d] + turns[d] if d < c and not out[d] else headings[d]
            if rects_overlap(ax, az, half_length, half_width, turned, bx, bz, half_length, half_width, hd) \
                    and not rects_overlap(ax, az, half_length, half_width, headings[c], bx, bz, half_length, half_width,
                                          hd):
                out[c] = True
                break


@nb.njit(cache=True)
def count_close_pairs(points, owner, radius):
    """Pairs of points closer than ``radius`` (ground plane) that belong to different owners,
    through a uniform grid of cell ``radius`` (sorted cell keys), so it stays near linear."""
    n = points.shape[0]
    if n < 2:
        return 0
    x0 = points[:, 0].min()
    z0 = points[:, 1].min()
    cols = int((points[:, 0].max() - x0) / radius) + 1
    keys = np.empty(n, dtype=np.int64)
    for i in range(n):
        keys[i] = int((points[i, 1] - z0) / radius) * cols + int((points[i, 0] - x0) / radius)
    order = np.argsort(keys, kind="mergesort")
    sorted_keys = keys[order]
    count = 0
    r2 = radius * radius
    for a in range(n):
        i = order[a]
        ci = int((points[i, 0] - x0) / radius)
        ri = int((points[i, 1] - z0) / radius)
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                cc = ci + dc
                rr = ri + dr
                if cc < 0 or cc >= cols or rr < 0:
                    continue
                key = rr * cols + cc
                lo = np.searchsorted(sorted_keys, key, side="left")
                hi = np.searchsorted(sorted_keys, key, side="right")
                for b in range(lo, hi):
                    j = order[b]
                    if j <= i or owner[j] == owner[i]:
                        continue
                    dx = points[j, 0] - points[i, 0]
                    dz = points[j, 1] - points[i, 1]
                    if dx * dx + dz * dz < r2:
                        count += 1
    return count


@nb.njit(cache=True, inline="always")
def _hip_xz(pelvis, hips_body, c, i, co, si):
    """(x, z) of leg i's hip of character c, the body's heading given by its cosine and sine."""
    return (pelvis[c, 0] + hips_body[i, 0] * co - hips_body[i, 2] * si,
            pelvis[c, 2] + hips_body[i, 0] * si + hips_body[i, 2] * co)


@nb.njit(cache=True)
def _lines_cross_turned(pelvis, heading, hips_body, feet, c, i, j):
    """Legs i and j of character c, the body at ``heading``: their ground lines (hip to foot, the
    hips swung with the body about the pelvis) cross properly."""
    co = math.cos(heading)
    si = math.sin(heading)
    ix, iz = _hip_xz(pelvis, hips_body, c, i, co, si)
    jx, jz = _hip_xz(pelvis, hips_body, c, j, co, si)
    return segments_cross(ix, iz, feet[c, i, 0], feet[c, i, 2], jx, jz, feet[c, j, 0], feet[c, j, 2])


@nb.njit(cache=True)
def _pair_newly_crossed(pelvis, heading, turn, hips_body, feet, c, i, j):
    """Legs i and j of character c cross with the body turned by ``turn`` from ``heading`` and not at it."""
    return (_lines_cross_turned(pelvis, heading + turn, hips_body, feet, c, i, j)
            and not _lines_cross_turned(pelvis, heading, hips_body, feet, c, i, j))


@nb.njit(cache=True)
def _turn_crosses(pelvis, heading, turn, hips_body, feet, c):
    """Some pair of character c's legs is newly crossed by ``turn`` (:func:`_pair_newly_crossed`)."""
    n_legs = feet.shape[1]
    for i in range(n_legs):
        for j in range(i + 1, n_legs):
            if _pair_newly_crossed(pelvis, heading[c], turn, hips_body, feet, c, i, j):
                return True
    return False


@nb.njit(cache=True, parallel=True)
def uncrossed_turns(pelvis, heading, turn, hips_body, feet, out):
    """Per character, ``turn`` kept, halved or dropped (the first that crosses no pair of legs that
    did not cross before: :func:`_turn_crosses`; ``feet`` where each leg stands or lands)."""
    for c in nb.prange(pelvis.shape[0]):
        out[c] = turn[c]
        if turn[c] == 0.0:
            continue
        if _turn_crosses(pelvis, heading, turn[c], hips_body, feet, c):
            out[c] = 0.5 * turn[c]
            if _turn_crosses(pelvis, heading, out[c], hips_body, feet, c):
                out[c] = 0.0


@nb.njit(cache=True, parallel=True)
def legs_crossed_by_turn(pelvis, heading, turn, hips_body, feet, legs, out):
    """Per character and leg, a leg of ``legs`` whose ground line would cross another's with the
    body turned by ``turn`` (C,), and did not before."""
    n_legs = feet.shape[1]
    for c in nb.prange(pelvis.shape[0]):
        for i in range(n_legs):
            out[c, i] = False
        if turn[c] == 0.0:
            continue
        for i in range(n_legs):
            for j in range(i + 1, n_legs):
                if legs[c, i] and legs[c, j] and _pair_newly_crossed(pelvis, heading[c], turn[c], hips_body, feet,
                                                                     c, i, j):
                    out[c, i] = True
                    out[c, j] = True
