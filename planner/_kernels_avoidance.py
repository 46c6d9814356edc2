"""Reciprocal collision avoidance of the characters' bodies (ORCA), batched as one numba kernel.

Optimal reciprocal collision avoidance (van den Berg, Guy, Lin and Manocha, "Reciprocal n-body
collision avoidance", 2011) on the ground plane (world x, z; m, s). For a character A and a
neighbour B the velocities of A that collide with B within ``time_horizon`` form a truncated
cone (the velocity obstacle); ``u`` is the smallest change of the relative velocity that leaves
it. A takes half of it (B, running the same rule, takes the other half): the permitted
velocities of A are the half-plane through ``v_A + u / 2`` whose normal is ``u``. Boxes do not
avoid anyone: against a box A takes all of ``u``; the box is seen from A as its nearest point
(a disc of radius 0 moving with the box), which for a convex box is exact where it matters (the
nearest point is where a collision starts). A character already overlapping a box is pushed out
within one time step, one overlapping a neighbour's disc within :data:`SEPARATION_S` (the discs are
a margin round the bodies, which ``planner._crowd.bodies_apart`` keeps apart). A character that has
waited too long for a neighbour to pass (the right of way, ``planner._crowd.wait_for_others``) leaves
that neighbour's half-plane out, and the neighbour takes the whole effort: ORCA alone can hold a waiting
character for seconds while a neighbour that steers round it orbits its disc.

The new velocity is the one closest to the preferred velocity inside every half-plane and the
disc of the character's top speed: an incremental 2-D linear program; where the half-planes
leave nothing, a 3-D linear program finds the velocity that violates them least (as in the
paper). Every character is solved independently (``prange``), so the result does not depend on
the thread count.

Conventions: a half-plane is (``point``, ``direction``); permitted velocities lie to its left,
``det(direction, v - point) >= 0``. A box's yaw turns its local x axis to (cos yaw, sin yaw) in
world (x, z), as everywhere in the planner (``planner._kernels_geometry.rects_overlap``).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

EPSILON = 1e-9
SEPARATION_S = 0.25
"""s: two characters whose discs overlap are parted within this time (RVO2 parts them within one time step).
Parted within a frame, a 3 cm overlap asked each of two quadrupeds at rest for 0.45 m/s straight away from
the other: a velocity behind a walker's heading, which it can only follow by turning round on the spot. Two
that had met at a corner of their ways stood 1-3 s turning away from each other and back (crates-moving,
quadrupeds, character 4 and its neighbour 2, in one run in ten). Measured 2026-12-02 with the heading rule
for a velocity that turns back from the way (``planner._crowd.stage_steer``), on 100 fresh seeds of that
scenario: failing runs 9 -> 4, stuck 12.7 -> 6.8 s, body overlaps 0 -> 0 (docs/crowds.md); with 0.1 / 0.5 s,
6 / 5 failing runs and 8.7 / 7.0 s. Boxes are no discs round a body: a disc overlapping one is pushed out
within a frame (parted within this time too, ten characters crowding a door came 1.7 cm into its walls:
tests/test_avoidance.py)."""


@nb.njit(cache=True)
def _det(ax, ay, bx, by):
    return ax * by - ay * bx


@nb.njit(cache=True)
def _line_program(points, directions, n_lines, i, radius, opt_x, opt_y, along_direction, result):
    """Best velocity on line ``i`` within the speed disc and the lines before ``i``; False if none."""
    px, py = points[i, 0], points[i, 1]
    dx, dy = directions[i, 0], directions[i, 1]
    dot = px * dx + py * dy
    discriminant = dot * dot + radius * radius - (px * px + py * py)
    if discriminant < 0.0:
        return False
    root = math.sqrt(discriminant)
    t_left = -dot - root
    t_right = -dot + root
    for j in range(i):
        denominator = _det(dx, dy, directions[j, 0], directions[j, 1])
        numerator = _det(directions[j, 0], directions[j, 1], px - points[j, 0], py - points[j, 1])
        if abs(denominator) <= EPSILON:
            if numerator < 0.0:  # parallel and on the forbidden side of line j
                return False
            continue
        t = numerator / denominator
        if denominator >= 0.0:
            t_right = min(t_right, t)
        else:
            t_left = max(t_left, t)
        if t_left > t_right:
            return False
    if along_direction:
        t = t_right if opt_x * dx + opt_y * dy > 0.0 else t_left
    else:
        t = min(max(dx * (opt_x - px) + dy * (opt_y - py), t_left), t_right)
    result[0] = px + t * dx
    result[1] = py + t * dy
    return True


@nb.njit(cache=True)
def _plane_program(points, directions, n_lines, radius, opt_x, opt_y, along_direction, result):
    """Velocity closest to the optimum inside all lines and the disc; returns the number of lines
    satisfied in order (``n_lines`` when all are)."""
    if along_direction:
        result[0] = opt_x * radius
        result[1] = opt_y * radius
    elif opt_x * opt_x + opt_y * opt_y > radius * radius:
        norm = math.hypot(opt_x, opt_y)
        result[0] = opt_x / norm * radius
        result[1] = opt_y / norm * radius
    else:
        result[0] = opt_x
        result[1] = opt_y
    keep = np.empty(2)
    for i in range(n_lines):
        if _det(directions[i, 0], directions[i, 1], points[i, 0] - result[0], points[i, 1] - result[1]) > 0.0:
            keep[0] = result[0]
            keep[1] = result[1]
            if not _line_program(points, directions, n_lines, i, radius, opt_x, opt_y, along_direction, result):
                result[0] = keep[0]
                result[1] = keep[1]
                return i
    return n_lines


@nb.njit(cache=True)
def _least_violation(points, directions, n_lines, n_box_lines, begin, radius, result):
    """The velocity that violates the lines from ``begin`` on least (box lines stay hard)."""
    distance = 0.0
    proj_points = np.empty((n_lines, 2))
    proj_dirs = np.empty((n_lines, 2))
    keep = np.empty(2)
    for i in range(begin, n_lines):
        dix, diy = directions[i, 0], directions[i, 1]
        if _det(dix, diy, points[i, 0] - result[0], points[i, 1] - result[1]) <= distance:
            continue
        m = 0
        for j in range(n_box_lines):
            proj_points[m] = points[j]
            proj_dirs[m] = directions[j]
            m += 1
        for j in range(n_box_lines, i):
            djx, djy = directions[j, 0], directions[j, 1]
            determinant = _det(dix, diy, djx, djy)
            if abs(determinant) <= EPSILON:
                if dix * djx + diy * djy > 0.0:
                    continue  # same direction: line j is no constraint on line i's violation
                qx = 0.5 * (points[i, 0] + points[j, 0])
                qy = 0.5 * (points[i, 1] + points[j, 1])
            else:
                s = _det(djx, djy, points[i, 0] - points[j, 0], points[i, 1] - points[j, 1]) / determinant
                qx = points[i, 0] + s * dix
                qy = points[i, 1] + s * diy
            ex, ey = djx - dix, djy - diy
            norm = math.hypot(ex, ey)
            proj_points[m, 0] = qx
            proj_points[m, 1] = qy
            proj_dirs[m, 0] = ex / norm
            proj_dirs[m, 1] = ey / norm
            m += 1
        keep[0] = result[0]
        keep[1] = result[1]
        if _plane_program(proj_points, proj_dirs, m, radius, -diy, dix, True, result) < m:
            # Numerically the 2-D program can only fail here by round-off: keep the last velocity.
            result[0] = keep[0]
            result[1] = keep[1]
        distance = _det(dix, diy, points[i, 0] - result[0], points[i, 1] - result[1])


@nb.njit(cache=True)
def _nearest_on_box(px, pz, cx, cz, hx, hz, yaw):
    """Nearest point of the box (centre, half extents, yaw) to (px, pz), and whether p is inside."""
    c = math.cos(yaw)
    s = math.sin(yaw)
    dx = px - cx
    dz = pz - cz
    a = dx * c + dz * s  # along the box's local x
    b = -dx * s + dz * c
    inside = abs(a) < hx and abs(b) < hz
    if inside:
        # The nearest point of the boundary: out through the closer side.
        if hx - abs(a) < hz - abs(b):
            a = hx if a >= 0.0 else -hx
        else:
            b = hz if b >= 0.0 else -hz
    else:
        a = min(max(a, -hx), hx)
        b = min(max(b, -hz), hz)
    return cx + a * c - b * s, cz + a * s + b * c, inside


@nb.njit(cache=True)
def _cone_line(px, py, vx, vy, r, tau, dt, share, ax, ay, out_point, out_dir, k):
    """Half-plane k of A's velocity from a neighbour at relative position p with relative
    velocity v (A's minus B's), combined radius r; A takes ``share`` of the change u. Overlapping
    already, A is parted from it within ``dt`` s."""
    dist_sq = px * px + py * py
    r_sq = r * r
    if dist_sq > r_sq:
        wx = vx - px / tau
        wy = vy - py / tau
        w_sq = wx * wx + wy * wy
        dot1 = wx * px + wy * py
        if dot1 < 0.0 and dot1 * dot1 > r_sq * w_sq:
            # Closest to the cut-off circle.
            w = math.sqrt(w_sq)
            ux, uy = wx / w, wy / w
            out_dir[k, 0] = uy
            out_dir[k, 1] = -ux
            scale = r / tau - w
            ux, uy = scale * ux, scale * uy
        else:
            # Closest to a leg of the cone.
            leg = math.sqrt(dist_sq - r_sq)
            if _det(px, py, wx, wy) > 0.0:
                out_dir[k, 0] = (px * leg - py * r) / dist_sq
                out_dir[k, 1] = (px * r + py * leg) / dist_sq
            else:
                out_dir[k, 0] = -(px * leg + py * r) / dist_sq
                out_dir[k, 1] = -(-px * r + py * leg) / dist_sq
            dot2 = vx * out_dir[k, 0] + vy * out_dir[k, 1]
            ux = dot2 * out_dir[k, 0] - vx
            uy = dot2 * out_dir[k, 1] - vy
    else:
        # Overlapping already: out within dt.
        wx = vx - px / dt
        wy = vy - py / dt
        w = math.hypot(wx, wy)
        if w < EPSILON:  # on top of each other and at rest: any direction, a fixed one
            wx, wy, w = -1.0, 0.0, 1.0
        ux, uy = wx / w, wy / w
        out_dir[k, 0] = uy
        out_dir[k, 1] = -ux
        scale = r / dt - w
        ux, uy = scale * ux, scale * uy
    out_point[k, 0] = ax + share * ux
    out_point[k, 1] = ay + share * uy


@nb.njit(cache=True, parallel=True)
def orca_velocities(positions, velocities, preferred, radii, max_speed, neighbour_start, neighbour_index,
                    box_centres, box_half, box_yaws, box_velocities, box_active, box_pad, time_horizon,
                    box_time_horizon, dt, priority, mobile, yield_radii, right_of_way, out):
    """New velocity (C, 2) of every character: closest to ``preferred`` among those that avoid
    every neighbour for ``time_horizon`` seconds (sharing the effort) and every active box for
    ``box_time_horizon`` seconds (alone), at most ``max_speed``.

    positions, velocities, preferred: (C, 2) world (x, z); radii, max_speed: (C,); neighbours in
    CSR form (character c's are ``neighbour_index[neighbour_start[c]:neighbour_start[c + 1]]``);
    boxes: centres (B, 2), half extents (B, 2) along their axes, yaws (B,), velocities (B, 2),
    ``box_active`` (B,) bool, ``box_pad`` (B,) m added to a character's radius against that box;
    ``priority`` (C,) bool: between a character with priority and one without, the one without
    takes the whole effort of avoiding (between equals, each takes half); ``mobile`` (C,) bool: a
    character that cannot make way (false: a walker standing still, which only walks off along its
    heading and turns slowly) is avoided by the other with its whole effort, as a box would be;
    ``yield_radii`` (C,) m: the radius such a character keeps, for its own velocity, from one that can
    make way (less than its disc, ``planner._crowd.YIELD_RADIUS``; the other still keeps the whole disc
    round it, ``radii``); ``right_of_way`` (C,) bool: a character that has waited too long for others to pass
    (``planner._crowd.WAIT_LIMIT_S``): against a neighbour without it and without priority, walking or
    standing, the other takes the whole effort and it leaves that other's half-plane out (it walks on; the
    other steers round it as round a box).
    """
    n = positions.shape[0]
    for c in nb.prange(n):
        pax, paz = positions[c, 0], positions[c, 1]
        vax, vaz = velocities[c, 0], velocities[c, 1]
        ra = radii[c]
        speed = max_speed[c]
        n_near = neighbour_start[c + 1] - neighbour_start[c]
        n_max = n_near + box_centres.shape[0]
        points = np.empty((max(n_max, 1), 2))
        directions = np.empty((max(n_max, 1), 2))
        k = 0
        # Boxes first: they stay hard constraints when the program is infeasible.
        for b in range(box_centres.shape[0]):
            if not box_active[b]:
                continue
            rb = ra + box_pad[b]
            qx, qz, inside = _nearest_on_box(pax, paz, box_centres[b, 0], box_centres[b, 1], box_half[b, 0],
                                             box_half[b, 1], box_yaws[b])
            rel_x, rel_z = qx - pax, qz - paz
            dist = math.hypot(rel_x, rel_z)
            reach = (speed + math.hypot(box_velocities[b, 0], box_velocities[b, 1])) * box_time_horizon + rb
            if not inside and dist > reach:
                continue
            if inside:
                # The centre is inside the box: out through the nearest side (outward normal n) as
                # fast as the character can, relative to the box.
                if dist < EPSILON:
                    rel_x, rel_z, dist = 1.0, 0.0, 1.0
                nx, nz = rel_x / dist, rel_z / dist
                out_speed = box_velocities[b, 0] * nx + box_velocities[b, 1] * nz + min((rb + dist) / dt, speed)
                directions[k, 0] = nz
                directions[k, 1] = -nx
                points[k, 0] = out_speed * nx
                points[k, 1] = out_speed * nz
            else:
                _cone_line(rel_x, rel_z, vax - box_velocities[b, 0], vaz - box_velocities[b, 1], rb,
                           box_time_horizon, dt, 1.0, vax, vaz, points, directions, k)
            k += 1
        n_box_lines = k
        for a in range(neighbour_start[c], neighbour_start[c + 1]):
            j = neighbour_index[a]
            # A character that cannot make way keeps only part of its disc from one that can: kept to
            # its whole disc, it stood while a walker went round that disc's edge and on into its way.
            combined = (yield_radii[c] if mobile[j] and not mobile[c] else ra) + radii[j]
            # The right of way lifts a standing neighbour's half-plane too (that one makes way alone, below):
            # kept, two quadrupeds at their discs' edge each held the other 2.4 s, the one with the right of
            # way steering round the other as round a box (planner._crowd.wait_for_others).
            if right_of_way[c] and not right_of_way[j] and not priority[j]:
                continue
            if not mobile[j]:
                share = 1.0
            elif priority[c] != priority[j]:
                share = 0.0 if priority[c] else 1.0
            elif right_of_way[c] != right_of_way[j]:
                if right_of_way[c]:
                    continue  # j makes way alone (the branch below, from j's side)
                share = 1.0
            else:
                share = 0.5
            _cone_line(positions[j, 0] - pax, positions[j, 1] - paz, vax - velocities[j, 0], vaz - velocities[j, 1],
                       combined, time_horizon, max(dt, SEPARATION_S), share, vax, vaz, points, directions, k)
            k += 1
        result = np.empty(2)
        failed = _plane_program(points, directions, k, speed, preferred[c, 0], preferred[c, 1], False, result)
        if failed < k:
            _least_violation(points, directions, k, n_box_lines, failed, speed, result)
        out[c, 0] = result[0]
        out[c, 1] = result[1]


def neighbour_lists(positions: np.ndarray, radius: float, max_neighbours: int | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The other characters within ``radius`` (m) of each one (at most the ``max_neighbours``
    nearest), in CSR form (start (C + 1,), index), each list sorted (deterministic). Uses a
    k-d tree: O(C log C), not O(C^2).

    >>> start, index = neighbour_lists(np.array([[0.0, 0.0], [1.0, 0.0], [5.0, 0.0]]), 2.0)
    >>> start.tolist(), index.tolist()
    ([0, 1, 2, 2], [1, 0])
    """
    from scipy.spatial import cKDTree

    positions = np.ascontiguousarray(positions, dtype=np.float64)
    n = positions.shape[0]
    if n == 0:
        return np.zeros(1, np.int64), np.zeros(0, np.int64)
    tree = cKDTree(positions)
    if max_neighbours is not None and max_neighbours < n - 1:
        # The nearest ones: k + 1 hits include the character itself (ties broken by index).
        dist, idx = tree.query(positions, k=max_neighbours + 1, distance_upper_bound=radius)
        rows = np.repeat(np.arange(n), max_neighbours + 1).reshape(n, -1)
        keep = np.isfinite(dist) & (idx != rows)
        found = np.where(keep, idx, n)
        found.sort(axis=1)
        counts = keep.sum(axis=1)
        start = np.zeros(n + 1, np.int64)
        np.cumsum(counts, out=start[1:])
        return start, np.ascontiguousarray(found[found < n], dtype=np.int64)
    pairs = tree.query_pairs(radius, output_type="ndarray")
    both = np.concatenate([pairs, pairs[:, ::-1]]) if pairs.size else np.zeros((0, 2), np.int64)
    order = np.lexsort((both[:, 1], both[:, 0]))
    both = both[order]
    start = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(both[:, 0], minlength=n), out=start[1:])
    return start, np.ascontiguousarray(both[:, 1], dtype=np.int64)
