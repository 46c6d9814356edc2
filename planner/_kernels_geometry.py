"""numba kernels: rasterising boxes, feet and leg segments onto grids, and finding the points near
others with a grid (:func:`points_near`).

All kernels take the grid placement as (origin_x, origin_z, cell) with the
convention of :mod:`planner._grid` (rows along z, columns along x).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from footfall.planner.layout import FORBIDDEN_STATIC


@nb.njit(cache=True)
def rect_overlaps_aabb(cx, cz, hx, hz, yaw, ax, az, ahx, ahz):
    """Separating-axis test: oriented rectangle vs axis-aligned box in the x/z plane.

    The rectangle has centre (cx, cz), half extents (hx, hz) along its local axes
    u = (cos yaw, sin yaw) and v = (-sin yaw, cos yaw). The AABB has centre (ax, az)
    and half extents (ahx, ahz). Touching counts as overlapping (conservative).
    """
    cs = math.cos(yaw)
    sn = math.sin(yaw)
    acs = abs(cs)
    asn = abs(sn)
    dx = ax - cx
    dz = az - cz
    if abs(dx) > ahx + hx * acs + hz * asn:
        return False
    if abs(dz) > ahz + hx * asn + hz * acs:
        return False
    if abs(dx * cs + dz * sn) > hx + ahx * acs + ahz * asn:
        return False
    if abs(-dx * sn + dz * cs) > hz + ahx * asn + ahz * acs:
        return False
    return True


@nb.njit(cache=True)
def rasterise_boxes(top, forbidden, origin_x, origin_z, cell, centres, sizes, yaws, box_forbidden, selected,
                    mark=FORBIDDEN_STATIC):
    """Voxelise boxes onto a grid: raise ``top`` to each box's top and flag forbidden cells
    (``forbidden`` set to ``mark``: :data:`planner.layout.FORBIDDEN_STATIC`, or ``FORBIDDEN_MOVING`` for
    moving boxes; a cell already static stays static).

    A cell is covered when its square overlaps the box's footprint (conservative,
    rotated boxes included). Only boxes with ``selected[i]`` are drawn.
    """
    n_rows, n_cols = top.shape
    half = 0.5 * cell
    for i in range(centres.shape[0]):
        if not selected[i]:
            continue
        cx = centres[i, 0]
        cz = centres[i, 2]
        hx = 0.5 * sizes[i, 0]
        hz = 0.5 * sizes[i, 2]
        yaw = yaws[i]
        box_top = centres[i, 1] + 0.5 * sizes[i, 1]
        ex = hx * abs(math.cos(yaw)) + hz * abs(math.sin(yaw))
        ez = hx * abs(math.sin(yaw)) + hz * abs(math.cos(yaw))
        c0 = max(0, int(math.floor((cx - ex - origin_x) / cell)) - 1)
        c1 = min(n_cols - 1, int(math.floor((cx + ex - origin_x) / cell)) + 1)
        r0 = max(0, int(math.floor((cz - ez - origin_z) / cell)) - 1)
        r1 = min(n_rows - 1, int(math.floor((cz + ez - origin_z) / cell)) + 1)
        for r in range(r0, r1 + 1):
            az = origin_z + (r + 0.5) * cell
            for c in range(c0, c1 + 1):
                ax = origin_x + (c + 0.5) * cell
                if rect_overlaps_aabb(cx, cz, hx, hz, yaw, ax, az, half, half):
                    if box_top > top[r, c]:
                        top[r, c] = box_top
                    # A static mark stands: a moving box drawn over a static one's cells must not make
                    # them a way out of a moving box (planner._kernels_foot._open_escape).
                    if box_forbidden[i] and forbidden[r, c] != FORBIDDEN_STATIC:
                        forbidden[r, c] = mark


@nb.njit(cache=True)
def foot_offsets(foot_length, foot_width, foot_yaw, cell):
    """Cell offsets (d_row, d_col) of the 'size increase' stencil of a foot (paper Fig. 12).

    A foot centred anywhere in cell C overlaps an obstacle only if some forbidden cell
    lies at C + offset for an offset here: the offsets are the cells whose square,
    grown by half a cell, overlaps the foot rectangle (length along ``foot_yaw``).
    The stencil always contains the 3 x 3 block around the origin.
    """
    hx = 0.5 * foot_length
    hz = 0.5 * foot_width
    reach = int(math.ceil((math.hypot(hx, hz)) / cell)) + 1
    out = np.empty(((2 * reach + 1) ** 2, 2), dtype=np.int64)
    n = 0
    for dr in range(-reach, reach + 1):
        for dc in range(-reach, reach + 1):
            if rect_overlaps_aabb(0.0, 0.0, hx, hz, foot_yaw, dc * cell, dr * cell, cell, cell):
                out[n, 0] = dr
                out[n, 1] = dc
                n += 1
    return out[:n].copy()


@nb.njit(cache=True)
def supercover_visit(ax, az, bx, bz, origin_x, origin_z, cell, rows_out, cols_out):
    """Cells touched by segment a->b (every cell it passes through, corners included).

    Writes up to ``rows_out.size`` cells and returns how many were written. A segment
    through a cell corner marks both side cells, so the cells form a 4-connected chain
    that no 8-connected path can slip across.
    """
    u0 = (ax - origin_x) / cell
    v0 = (az - origin_z) / cell
    u1 = (bx - origin_x) / cell
    v1 = (bz - origin_z) / cell
    c = int(math.floor(u0))
    r = int(math.floor(v0))
    c_end = int(math.floor(u1))
    r_end = int(math.floor(v1))
    du = u1 - u0
    dv = v1 - v0
    step_c = 1 if du > 0 else -1
    step_r = 1 if dv > 0 else -1
    inf = 1e300
    if du != 0.0:
        t_max_c = ((c + (1 if du > 0 else 0)) - u0) / du
        t_delta_c = abs(1.0 / du)
    else:
        t_max_c = inf
        t_delta_c = inf
    if dv != 0.0:
        t_max_r = ((r + (1 if dv > 0 else 0)) - v0) / dv
        t_delta_r = abs(1.0 / dv)
    else:
        t_max_r = inf
        t_delta_r = inf
    cap = rows_out.size
    n = 0
    rows_out[n] = r
    cols_out[n] = c
    n += 1
    guard = abs(c_end - c) + abs(r_end - r) + 2
    for _ in range(2 * guard):
        if r == r_end and c == c_end:
            break
        if t_max_c > 1.0 and t_max_r > 1.0:
            break
        if abs(t_max_c - t_max_r) < 1e-9:
            # Through a corner: both side cells are touched.
            if n + 2 <= cap:
                rows_out[n] = r + step_r
                cols_out[n] = c
                rows_out[n + 1] = r
                cols_out[n + 1] = c + step_c
                n += 2
            r += step_r
            c += step_c
            t_max_c += t_delta_c
            t_max_r += t_delta_r
        elif t_max_c < t_max_r:
            c += step_c
            t_max_c += t_delta_c
        else:
            r += step_r
            t_max_r += t_delta_r
        if n < cap:
            rows_out[n] = r
            cols_out[n] = c
            n += 1
    return n


@nb.njit(cache=True)
def wrap_pi(x):
    """``x`` (rad) wrapped into [-pi, pi)."""
    return (x + math.pi) % (2.0 * math.pi) - math.pi


@nb.njit(cache=True)
def segment_point_distance(px, pz, ax, az, bx, bz):
    """Distance from point p to segment a-b in the plane."""
    dx = bx - ax
    dz = bz - az
    ll = dx * dx + dz * dz
    t = 0.0
    if ll > 0.0:
        t = ((px - ax) * dx + (pz - az) * dz) / ll
        t = min(1.0, max(0.0, t))
    ex = ax + t * dx - px
    ez = az + t * dz - pz
    return math.sqrt(ex * ex + ez * ez)


@nb.njit(cache=True)
def segment_square_clip(ax, az, bx, bz, cx, cz, half):
    """(t0, t1): the part of segment a-b (a + t (b - a), t in [0, 1]) inside the closed square of centre
    (cx, cz) and half side ``half`` (Liang-Barsky clipping); t0 > t1 when the segment misses it.

    >>> segment_square_clip(-1.0, 0.5, 2.0, 0.5, 0.5, 0.5, 0.5)  # x from -1 to 2 across [0, 1]
    (0.3333333333333333, 0.6666666666666666)
    >>> t0, t1 = segment_square_clip(-1.0, 2.0, 2.0, 2.0, 0.5, 0.5, 0.5)  # z = 2, above the square
    >>> bool(t0 > t1)
    True
    """
    t0 = 0.0
    t1 = 1.0
    dx = bx - ax
    dz = bz - az
    for k in range(4):
        if k == 0:
            p, q = -dx, ax - (cx - half)
        elif k == 1:
            p, q = dx, (cx + half) - ax
        elif k == 2:
            p, q = -dz, az - (cz - half)
        else:
            p, q = dz, (cz + half) - az
        if p == 0.0:
            if q < 0.0:
                return 1.0, 0.0  # parallel to this side and outside it
            continue
        t = q / p
        if p < 0.0:
            t0 = max(t0, t)
        else:
            t1 = min(t1, t)
        if t0 > t1:
            return t0, t1
    return t0, t1


@nb.njit(cache=True)
def segments_cross(ax, az, bx, bz, cx, cz, dx, dz):
    """True when segments a-b and c-d properly intersect (shared endpoints excluded)."""
    d1 = (bx - ax) * (cz - az) - (bz - az) * (cx - ax)
    d2 = (bx - ax) * (dz - az) - (bz - az) * (dx - ax)
    d3 = (dx - cx) * (az - cz) - (dz - cz) * (ax - cx)
    d4 = (dx - cx) * (bz - cz) - (dz - cz) * (bx - cx)
    return (d1 * d2 < 0.0) and (d3 * d4 < 0.0)


@nb.njit(cache=True)
def _bow(drawn, c, leg):
    """The largest distance of a point of polyline ``drawn[c, leg]`` (x in column 0, z in column 2)
    from the segment between its first and last points, m."""
    p = drawn.shape[2]
    ax = drawn[c, leg, 0, 0]
    az = drawn[c, leg, 0, 2]
    bx = drawn[c, leg, p - 1, 0]
    bz = drawn[c, leg, p - 1, 2]
    largest = 0.0
    for k in range(1, p - 1):
        largest = max(largest, segment_point_distance(drawn[c, leg, k, 0], drawn[c, leg, k, 2], ax, az, bx, bz))
    return largest


@nb.njit(cache=True)
def bowed_legs_onto_lines(drawn, chars, legs, straight, tolerance, n_columns):
    """(rows (R, ``n_columns``), start (F + 1,)): for each request i, the legs ``legs[i]`` of character
    ``chars[i]`` as drawn (``drawn`` (C, L, P, 3) polylines, hip first, foot last) whose inner points
    leave the segment between their ends by more than ``tolerance`` (m), moved onto the line
    ``straight[i, k]`` (hip x, z, foot x, z): each point by the move of the hip and the move of the
    foot, blended by its share of the polyline's length from the hip (the ends land on the line's
    ends; the shape between them is carried, not scaled). P - 1 segment rows (x0, z0, x1, z1, then
    zeros) per such leg, request by request."""
    f, k = legs.shape
    p = drawn.shape[2]
    keep = np.zeros((f, k), dtype=np.bool_)
    start = np.zeros(f + 1, dtype=np.int64)
    for i in range(f):
        n = 0
        for j in range(k):
            if _bow(drawn, chars[i], legs[i, j]) > tolerance:
                keep[i, j] = True
                n += p - 1
        start[i + 1] = start[i] + n
    rows = np.zeros((start[f], n_columns))
    share = np.empty(p)
    xs = np.empty(p)
    zs = np.empty(p)
    for i in range(f):
        r = start[i]
        c = chars[i]
        for j in range(k):
            if not keep[i, j]:
                continue
            leg = legs[i, j]
            share[0] = 0.0
            for q in range(1, p):
                share[q] = share[q - 1] + math.hypot(drawn[c, leg, q, 0] - drawn[c, leg, q - 1, 0],
                                                     drawn[c, leg, q, 2] - drawn[c, leg, q - 1, 2])
            total = share[p - 1]
            hx = straight[i, j, 0] - drawn[c, leg, 0, 0]
            hz = straight[i, j, 1] - drawn[c, leg, 0, 2]
            fx = straight[i, j, 2] - drawn[c, leg, p - 1, 0]
            fz = straight[i, j, 3] - drawn[c, leg, p - 1, 2]
            for q in range(p):
                u = share[q] / total if total > 0.0 else 0.0
                xs[q] = drawn[c, leg, q, 0] + (1.0 - u) * hx + u * fx
                zs[q] = drawn[c, leg, q, 2] + (1.0 - u) * hz + u * fz
            xs[p - 1] = straight[i, j, 2]  # the ends exactly (no rounding off the line's ends)
            zs[p - 1] = straight[i, j, 3]
            xs[0] = straight[i, j, 0]
            zs[0] = straight[i, j, 1]
            for q in range(p - 1):
                rows[r, 0] = xs[q]
                rows[r, 1] = zs[q]
                rows[r, 2] = xs[q + 1]
                rows[r, 3] = zs[q + 1]
                r += 1
    return rows, start


@nb.njit(cache=True)
def segments_cross_rows(p0, p1, q0, q1, out):
    """``out[k]``: :func:`segments_cross` of rows k of segments p0 -> p1 and q0 -> q1 ((N, 2) x, z each)."""
    for k in range(out.shape[0]):
        out[k] = segments_cross(p0[k, 0], p0[k, 1], p1[k, 0], p1[k, 1], q0[k, 0], q0[k, 1], q1[k, 0], q1[k, 1])


@nb.njit(cache=True)
def rects_overlap(ax, az, ahx, ahz, ayaw, bx, bz, bhx, bhz, byaw):
    """Separating-axis test of two oriented rectangles (touching does not count)."""
    dx = bx - ax
    dz = bz - az
    for k in range(4):
        yaw = ayaw if k < 2 else byaw
        if k % 2 == 0:
            ux = math.cos(yaw)
            uz = math.sin(yaw)
        else:
            ux = -math.sin(yaw)
            uz = math.cos(yaw)
        ra = ahx * abs(math.cos(ayaw) * ux + math.sin(ayaw) * uz) + ahz * abs(-math.sin(ayaw) * ux + math.cos(ayaw) * uz)
        rb = bhx * abs(math.cos(byaw) * ux + math.sin(byaw) * uz) + bhz * abs(-math.sin(byaw) * ux + math.cos(byaw) * uz)
        if abs(dx * ux + dz * uz) >= ra + rb - 1e-9:
            return False
    return True


GRID_CELLS_MAX = 1 << 22
"""Cells a :func:`points_near` grid may have at most (its cells grow beyond the radius to fit)."""


@nb.njit(cache=True)
def _bin_points(points, cell, x0, z0, width, height):
    """(start (cells + 1,), order (N,)): the points sorted by grid cell (row-major, counting sort;
    within a cell by index), each cell's points ``order[start[k]:start[k + 1]]``."""
    n = points.shape[0]
    key = np.empty(n, np.int64)
    start = np.zeros(width * height + 1, np.int64)
    for i in range(n):
        ix = min(max(int((points[i, 0] - x0) / cell), 0), width - 1)
        iz = min(max(int((points[i, 1] - z0) / cell), 0), height - 1)
        key[i] = iz * width + ix
        start[key[i] + 1] += 1
    for k in range(width * height):
        start[k + 1] += start[k]
    fill = start[:-1].copy()
    order = np.empty(n, np.int64)
    for i in range(n):
        order[fill[key[i]]] = i
        fill[key[i]] += 1
    return start, order


@nb.njit(cache=True)
def _near_one(points, owner, qx, qz, q_owner, radius, cell, x0, z0, width, height, start, order, out, m):
    """Points of other owners within ``radius`` of (qx, qz), written to out[m:] unsorted; the new m."""
    ix = int(math.floor((qx - x0) / cell))
    iz = int(math.floor((qz - z0) / cell))
    r_sq = radius * radius
    for cz in range(max(iz - 1, 0), min(iz + 2, height)):
        for cx in range(max(ix - 1, 0), min(ix + 2, width)):
            k = cz * width + cx
            for a in range(start[k], start[k + 1]):
                i = order[a]
                if owner[i] == q_owner:
                    continue
                dx = points[i, 0] - qx
                dz = points[i, 1] - qz
                if dx * dx + dz * dz <= r_sq:
                    out[m] = i
                    m += 1
    return m


@nb.njit(cache=True)
def points_near(points, owner, queries, query_owner, radius):
    """(start (Q + 1,), index): for each query point, the points (N, 2) of other owners within
    ``radius`` (distance <= radius), ascending, in CSR form (query q's are
    ``index[start[q]:start[q + 1]]``). A grid of cells at least ``radius`` wide: each query looks
    at its cell and the eight around it."""
    n = points.shape[0]
    nq = queries.shape[0]
    start = np.zeros(nq + 1, np.int64)
    if n == 0 or nq == 0:
        return start, np.zeros(0, np.int64)
    x0 = points[0, 0]
    x1 = x0
    z0 = points[0, 1]
    z1 = z0
    for i in range(n):
        x0 = min(x0, points[i, 0])
        x1 = max(x1, points[i, 0])
        z0 = min(z0, points[i, 1])
        z1 = max(z1, points[i, 1])
    cell = max(radius, 1e-9)
    while (int((x1 - x0) / cell) + 1) * (int((z1 - z0) / cell) + 1) > GRID_CELLS_MAX:
        cell *= 2.0
    width = int((x1 - x0) / cell) + 1
    height = int((z1 - z0) / cell) + 1
    bins, order = _bin_points(points, cell, x0, z0, width, height)
    scratch = np.empty(n, np.int64)
    for q in range(nq):
        start[q + 1] = start[q] + _near_one(points, owner, queries[q, 0], queries[q, 1], query_owner[q], radius,
                                            cell, x0, z0, width, height, bins, order, scratch, 0)
    index = np.empty(start[nq], np.int64)
    for q in range(nq):
        m = _near_one(points, owner, queries[q, 0], queries[q, 1], query_owner[q], radius, cell, x0, z0, width,
                      height, bins, order, index[start[q]:start[q + 1]], 0)
        index[start[q]:start[q] + m].sort()
    return start, index
