"""numba kernels: everything the planner does for one foot (paper §4, §5).

Pipeline for one foot (all arrays are local to a region of interest, ROI, of the
character's local maps, padded by one ring so neighbour access needs no bounds
checks):

1. ``prepare_foot``: ROI = bounding box of the source and the candidate disc grown
   by ``roi_margin_cells``; foot-shape dilation of the forbidden cells ('size
   increase') and of the elevations; the other legs' projections and the other
   feet as blocked cells.
2. ``footprint_candidates``: potential footprints and their scores (§5.1).
3. ``slice_levels``: elevation slices (§5.2) over the height of obstacles above the
   terrain, deduplicated (two levels that block the same cells are one slice).
4. ``search``: the best footprint-trajectory couple (§5.2) with one shared
   wavefront per slice, 2D scores before 3D ones, the paper's early termination,
   an exact bound, and the budget (§6).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from footfall.planner._grid import cell_centre, cell_of
from footfall.planner._kernels_geometry import (
    rect_overlaps_aabb,
    segment_point_distance,
    segment_square_clip,
    segments_cross,
    supercover_visit,
)
from footfall.planner._kernels_wavefront import chamfer_distance
from footfall.planner._weights import (
    N_FOOTPRINT_TERMS,
    N_TERMS,
    W_CLEARANCE_REF,
    W_CLIMB_REF,
    W_CURVATURE_REF,
    W_DISTANCE_SCALE,
    W_JERK_REF,
    W_LEG_SPACING_REF,
    W_PROXIMITY_REF,
    W_SLOPE_CRITICAL,
    W_STEP_CRITICAL,
    falling_goodness,
    rational_goodness,
    rising_goodness,
)
# The raw trajectory metrics (RAW_*), footprint features (FEAT_*) and counters (CNT_*), in the order of the
# results: planner.layout.
from footfall.planner.layout import (  # noqa: F401  (re-exported: the kernels' callers read them from here too)
    CNT_BOXED,
    CNT_CANDIDATES,
    CNT_COUPLES_2D,
    CNT_COUPLES_3D,
    CNT_EXPANDED,
    CNT_SLICES,
    CNT_WAVEFRONTS,
    FEAT_DISTANCE,
    FEAT_LEG_GAP,
    FEAT_PROXIMITY,
    FEAT_ROUGHNESS,
    FEAT_SLOPE,
    FORBIDDEN_MOVING,
    LEG_FOOT,
    N_COUNTERS,
    N_FEATURES,
    N_RAW,
    RAW_CLEARANCE,
    RAW_CLIMB,
    RAW_CURVATURE,
    RAW_JERK,
    RAW_LENGTH,
)

# Codes of the per-foot obstacles' map (ROI).
FREE = 0
FORBIDDEN = 1  # a forbidden box, or outside the local map
SIZE_INCREASE = 2  # free, but a foot centred here would touch a forbidden cell
OTHER_LEG = 3  # another leg's projection or another foot
PAD = 4  # the padding ring around the ROI
MOVING_BOX = 5  # a moving forbidden box (planner.layout.FORBIDDEN_MOVING): FORBIDDEN, but a way out (_open_escape)


@nb.njit(cache=True)
def foot_blocked(c):
    """Whether a foot centred on a cell of code ``c`` touches a forbidden box (FORBIDDEN, MOVING_BOX,
    SIZE_INCREASE)."""
    return c == FORBIDDEN or c == MOVING_BOX or c == SIZE_INCREASE


ESCAPE_RISE = 2.0
"""A swing leaving the cells of a forbidden box is drawn at most this many step heights above its
source over them (:func:`drawn_heights`); it is scored as climbing the box."""
MIN_STEP_CELLS = 1e-3
"""A candidate footprint closer to the foot than this (cells) is no step (and no path)."""
# A footprint belongs to its own cell, borders included (footprint_point puts it on a border when the
# preferred footprint lies beyond). The chord that ends at it is checked up to this far before it, so
# that a cell it meets only at the footprint (the neighbour across the border, or the diagonal ones at
# a corner) does not refuse the couple; the floor convention of cell_of would put such a footprint in
# the neighbour, and whether it did depended on how (x - origin) / cell rounds.
END_PULLBACK_M = 1e-9
PUSH_BEYOND_M = 1e-9  # a footprint pushed out of another foot's room ends this far beyond it (out_of_other_feet)
SOURCE_GRACE = 0.5
"""x the foot's room (``feet_block_radius``, two half-diagonals of the foot): a swing's chord may pass a
cell of another leg's projection or another foot's room (``OTHER_LEG``) where it meets that cell only
within this distance of its source, the half-diagonal of the foot standing there (the disc the foot
covers in any yaw). A path so graced is then checked on the geometry: it crosses no other leg
(:func:`path_crosses_legs`). Cells are 7 cm: a source on a cell's border, beside such a cell, refused
the straight way that grazed the cell's corner by 1 mm for 1.5 cm, and the path's first kept point was
the centre of the cell behind, 4 cm back and out; the knee swept across the neighbouring leg's
(spider, ``stairs@terrain.rise=0.1,terrain.run=0.3``, spawn 0.45, seed 502, frame 130)."""
GRACED = 2  # segment_clear: clear thanks to SOURCE_GRACE
LEG_CLEARANCE = 0.5
"""x the foot's room (``feet_block_radius``): the least distance between a footprint and every other leg
(hip -> foot), and between every other foot and the leg to the footprint (the leg-gap feature). A leg
planned to pass 0.5-2 mm beside another's foot crossed it as soon as the body turned or moved on: on 72
crowded runs (crates-moving 12 x 600, mixed 8 x 600 frames) leg crossings 786 -> 120 pair-frames, feet
in crates 494 -> 223; the whole room (the rule of a footprint under another leg's projection) held
the feet so often that feet in crates tripled (1607)."""
BOXED_CELL_COST = 10.0
"""x a free cell's cost: what a cell of another foot's room, another leg's projection or a forbidden
box's foot-size ring costs the way out of a boxed-in foot (:func:`slice_maps` with ``boxed``), so
that way passes as few of them as it can. A foot whose every way to its candidates ran through them
(another foot beside it, the corner of a crate on its other side) found no couple, held, and held its
body: a spider's trailing foot stood 7 cm beside its neighbour's with a crate's corner in front and
the spider froze for 2 s (``crates``, seed 3007). The way is checked on the geometry itself: it
crosses no other leg (:func:`path_crosses_legs`) and the foot at none of its samples touches a
forbidden cell (:func:`path_touches_forbidden`; the ring is a foot centred *anywhere* in a cell, a
7 cm cell's centre is 2.5 cm from a crate for a spider's foot)."""
MAX_SLICES = 12
MAX_DENSE = 1024  # samples of one path; a longer path is refused
DENSE_SPACING = 0.35  # target spacing of dense samples, in cells
DENSE_SPACING_MAX = 0.40  # a chord between dense samples may not be longer (cells)
JERK_SAMPLES = 48
U_LO = 0.05  # curvature and jerk are evaluated for u in [U_LO, U_HI] (singular at the ends)
U_HI = 0.95


@nb.njit(cache=True)
def prepare_foot(elevation, ground, forbidden, origin_x, origin_z, cell, offsets, source_x, source_z, pref_x, pref_z,
                 radius, margin, other_legs, feet_block_radius):
    """Build the per-foot ROI maps. Returns (code, elev_dil, boxh_dil, elev_raw, r0, c0, hp, wp).

    ``r0, c0`` are the local-map row/col of ROI cell (0, 0); padded flat index of
    local cell (r, c) is ``(r - r0 + 1) * wp + (c - c0 + 1)``.
    """
    n_rows, n_cols = elevation.shape
    sr, sc = cell_of(source_x, source_z, origin_x, origin_z, cell)
    pr, pc = cell_of(pref_x, pref_z, origin_x, origin_z, cell)
    rad = int(math.ceil(radius / cell))
    r0 = max(0, min(sr, pr - rad) - margin)
    r1 = min(n_rows - 1, max(sr, pr + rad) + margin)
    c0 = max(0, min(sc, pc - rad) - margin)
    c1 = min(n_cols - 1, max(sc, pc + rad) + margin)
    hp = r1 - r0 + 3
    wp = c1 - c0 + 3
    n = hp * wp
    code = np.full(n, PAD, dtype=np.uint8)
    elev_dil = np.empty(n, dtype=np.float64)
    boxh_dil = np.empty(n, dtype=np.float64)
    elev_raw = np.empty(n, dtype=np.float64)
    for rr in range(hp):
        r = r0 - 1 + rr
        rcl = min(n_rows - 1, max(0, r))
        for cc in range(wp):
            c = c0 - 1 + cc
            ccl = min(n_cols - 1, max(0, c))
            p = rr * wp + cc
            emax = -np.inf
            hmax = 0.0
            touches_forbidden = False
            for k in range(offsets.shape[0]):
                r2 = r + offsets[k, 0]
                c2 = c + offsets[k, 1]
                if r2 < 0 or r2 >= n_rows or c2 < 0 or c2 >= n_cols:
                    touches_forbidden = True
                    continue
                e = elevation[r2, c2]
                if e > emax:
                    emax = e
                h = e - ground[r2, c2]
                if h > hmax:
                    hmax = h
                if forbidden[r2, c2]:
                    touches_forbidden = True
            elev_raw[p] = elevation[rcl, ccl]
            elev_dil[p] = emax if emax > -np.inf else elevation[rcl, ccl]
            boxh_dil[p] = hmax
            if 1 <= rr < hp - 1 and 1 <= cc < wp - 1:
                if forbidden[r, c]:
                    code[p] = MOVING_BOX if forbidden[r, c] == FORBIDDEN_MOVING else FORBIDDEN
                elif touches_forbidden:
                    code[p] = SIZE_INCREASE
                else:
                    code[p] = FREE
    # The other legs' projections (4-connected, so no 8-connected path slips across).
    cap = 4 * (hp + wp) + 8
    rows = np.empty(cap, dtype=np.int64)
    cols = np.empty(cap, dtype=np.int64)
    for j in range(other_legs.shape[0]):
        m = supercover_visit(other_legs[j, 0], other_legs[j, 1], other_legs[j, 2], other_legs[j, 3],
                             origin_x, origin_z, cell, rows, cols)
        for k in range(m):
            rr = rows[k] - r0 + 1
            cc = cols[k] - c0 + 1
            if 1 <= rr < hp - 1 and 1 <= cc < wp - 1:
                p = rr * wp + cc
                # A size-increase cell stays one: it is no footprint, and it seeds the proximity term.
                if code[p] == FREE:
                    code[p] = OTHER_LEG
        if other_legs[j, LEG_FOOT] == 0.0:
            continue  # a segment of a leg as drawn: no foot at its end
        # The other foot itself: every cell whose centre is within feet_block_radius.
        fx = other_legs[j, 2]
        fz = other_legs[j, 3]
        fr, fc = cell_of(fx, fz, origin_x, origin_z, cell)
        reach = int(math.ceil(feet_block_radius / cell)) + 1
        for dr in range(-reach, reach + 1):
            for dc in range(-reach, reach + 1):
                rr = fr + dr - r0 + 1
                cc = fc + dc - c0 + 1
                if 1 <= rr < hp - 1 and 1 <= cc < wp - 1:
                    x, z = cell_centre(fr + dr, fc + dc, origin_x, origin_z, cell)
                    if math.hypot(x - fx, z - fz) <= feet_block_radius:
                        p = rr * wp + cc
                        if code[p] == FREE:
                            code[p] = OTHER_LEG
    return code, elev_dil, boxh_dil, elev_raw, r0, c0, hp, wp


@nb.njit(cache=True, inline="always")
def _minmod(forward, backward):
    """The smaller in size of two one-sided differences of the same sign, else 0 (a slope limiter):
    the slope of the ground under a foot, where a central difference would see a step's edge beside it
    as a slope."""
    if forward * backward <= 0.0:
        return 0.0
    return forward if abs(forward) < abs(backward) else backward


@nb.njit(cache=True)
def footprint_features(p, x, z, elev_dil, elev_raw, prox_dt, wp, pref_x, pref_z, hip_x, hip_z, other_legs, cell,
                       features):
    """Fill ``features[:5]`` (FEAT_* order) with the raw footprint features of cell p; False if
    the leg hip -> (x, z) crosses another leg or a segment of one as drawn (``other_legs``,
    ``planner.layout.LEG_ROW``; the cell is refused outright, no features). The leg gap is the
    least distance from (x, z) to every row, and from every other foot to the leg hip -> (x, z)."""
    features[FEAT_DISTANCE] = math.hypot(x - pref_x, z - pref_z)
    e = elev_dil[p]
    rough = 0.0
    for q in (p - wp - 1, p - wp, p - wp + 1, p - 1, p + 1, p + wp - 1, p + wp, p + wp + 1):
        rough = max(rough, abs(elev_raw[q] - e))
    features[FEAT_ROUGHNESS] = rough
    gx = _minmod(elev_dil[p + 1] - elev_dil[p], elev_dil[p] - elev_dil[p - 1]) / cell
    gz = _minmod(elev_dil[p + wp] - elev_dil[p], elev_dil[p] - elev_dil[p - wp]) / cell
    features[FEAT_SLOPE] = math.atan(math.hypot(gx, gz))
    gap = np.inf
    for j in range(other_legs.shape[0]):
        hx = other_legs[j, 0]
        hz = other_legs[j, 1]
        fx = other_legs[j, 2]
        fz = other_legs[j, 3]
        if segments_cross(hip_x, hip_z, x, z, hx, hz, fx, fz):
            return False
        gap = min(gap, segment_point_distance(x, z, hx, hz, fx, fz))
        if other_legs[j, LEG_FOOT] != 0.0:
            gap = min(gap, segment_point_distance(fx, fz, hip_x, hip_z, x, z))
    features[FEAT_LEG_GAP] = gap
    features[FEAT_PROXIMITY] = prox_dt[p]
    return True


@nb.njit(cache=True)
def footprint_goodness(w, features, terms):
    """Fill ``terms[:5]`` with the footprint goodnesses in [0, 1] of raw features (the one
    definition: the search, the harvest and tuning/_scoring.py follow it term by term)."""
    terms[0] = max(0.0, falling_goodness(features[FEAT_DISTANCE], w[W_DISTANCE_SCALE]))
    terms[1] = max(0.0, falling_goodness(features[FEAT_ROUGHNESS], w[W_STEP_CRITICAL]))
    terms[2] = max(0.0, falling_goodness(features[FEAT_SLOPE], w[W_SLOPE_CRITICAL]))
    terms[3] = min(1.0, rising_goodness(features[FEAT_LEG_GAP], w[W_LEG_SPACING_REF]))
    terms[4] = min(1.0, rising_goodness(features[FEAT_PROXIMITY], w[W_PROXIMITY_REF]))


@nb.njit(cache=True)
def trajectory_goodness(w, terms, d_ref, length, curvature, clearance, climb, jerk):
    """Fill ``terms[5:10]`` with the trajectory goodnesses in [0, 1] of raw trajectory metrics."""
    terms[N_FOOTPRINT_TERMS + 0] = rising_goodness(d_ref, max(length, d_ref))
    terms[N_FOOTPRINT_TERMS + 1] = rational_goodness(curvature, w[W_CURVATURE_REF])
    terms[N_FOOTPRINT_TERMS + 2] = min(1.0, rising_goodness(clearance, w[W_CLEARANCE_REF]))
    terms[N_FOOTPRINT_TERMS + 3] = rational_goodness(climb, w[W_CLIMB_REF])
    terms[N_FOOTPRINT_TERMS + 4] = rational_goodness(jerk, w[W_JERK_REF])


@nb.njit(cache=True)
def weighted_mean(w, terms, lo, hi):
    """sum_k w_k terms_k / sum_k w_k over k in [lo, hi), summed in index order (0 if no weight)."""
    num = 0.0
    den = 0.0
    for k in range(lo, hi):
        num += w[k] * terms[k]
        den += w[k]
    return num / den if den > 0.0 else 0.0


@nb.njit(cache=True)
def _clear_of_other_feet(x, z, other_legs, leg_gap, feet_block_radius):
    """A footprint at (x, z) keeps ``feet_block_radius`` from every other leg (hip -> foot) and foot."""
    return leg_gap >= feet_block_radius and not _near_other_foot(x, z, other_legs, feet_block_radius)


@nb.njit(cache=True)
def _near_other_foot(x, z, other_legs, feet_block_radius):
    """A footprint at (x, z) within ``feet_block_radius`` of another foot (of the character or not)."""
    for j in range(other_legs.shape[0]):
        if other_legs[j, LEG_FOOT] == 0.0:
            continue  # a segment of a leg as drawn: no foot at its end
        if math.hypot(x - other_legs[j, 2], z - other_legs[j, 3]) <= feet_block_radius:
            return True
    return False


@nb.njit(cache=True)
def _nearest_on_leg(x, z, leg, whole_leg):
    """The point of another leg (hip -> foot; its foot only unless ``whole_leg``) nearest to (x, z)."""
    if not whole_leg:
        return leg[2], leg[3]
    dx = leg[2] - leg[0]
    dz = leg[3] - leg[1]
    ll = dx * dx + dz * dz
    t = 1.0
    if ll > 0.0:
        t = min(1.0, max(0.0, ((x - leg[0]) * dx + (z - leg[1]) * dz) / ll))
    return leg[0] + t * dx, leg[1] + t * dz


@nb.njit(cache=True)
def out_of_other_feet(x, z, cx, cz, cell, other_legs, feet_block_radius, whole_legs):
    """(ok, x, z): a footprint within ``feet_block_radius`` of another foot (with ``whole_legs``, of
    another leg, hip -> foot) moves straight away from the nearest one to just beyond that radius; ok
    when the point then lies in the cell's closed square (centre (cx, cz)) and keeps the radius from
    every foot (and leg). A footprint clear of them stays as it is.

    Rejecting the whole cell instead put feet that follow close behind another foot (a metachronal
    wave's legs) a cell or two short of their stride: the dodecapod's rear legs strode 30-60 % short.
    """
    nearest = -1
    best = feet_block_radius
    qx = qz = 0.0
    for j in range(other_legs.shape[0]):  # the nearest, the first of equals
        if not whole_legs and other_legs[j, LEG_FOOT] == 0.0:
            continue
        ax, az = _nearest_on_leg(x, z, other_legs[j], whole_legs)
        d = math.hypot(x - ax, z - az)
        if d <= feet_block_radius and (nearest < 0 or d < best):
            best = d
            nearest = j
            qx, qz = ax, az
    if nearest < 0:
        return True, x, z
    if best <= 1e-12:
        return False, x, z
    scale = (feet_block_radius + PUSH_BEYOND_M) / best
    nx, nz = qx + (x - qx) * scale, qz + (z - qz) * scale
    h = 0.5 * cell
    if abs(nx - cx) > h or abs(nz - cz) > h:
        return False, x, z
    for j in range(other_legs.shape[0]):
        if not whole_legs and other_legs[j, LEG_FOOT] == 0.0:
            continue
        ax, az = _nearest_on_leg(nx, nz, other_legs[j], whole_legs)
        if math.hypot(nx - ax, nz - az) <= feet_block_radius:
            return False, x, z
    return True, nx, nz


@nb.njit(cache=True)
def footprint_point(cx, cz, cell, pref_x, pref_z):
    """The footprint of the cell centred at (cx, cz): the point of its closed square nearest to
    the preferred footprint (so the preferred footprint itself when it lies in the cell). Strides
    are then continuous, not multiples of the cell (the foot-shape dilation holds for a foot
    centred anywhere in the cell, :func:`planner._kernels_geometry.foot_offsets`)."""
    h = 0.5 * cell
    return min(max(pref_x, cx - h), cx + h), min(max(pref_z, cz - h), cz + h)


@nb.njit(cache=True)
def footprint_candidates(code, elev_dil, elev_raw, r0, c0, hp, wp, origin_x, origin_z, cell, source_p, source_x,
                         source_z, pref_x, pref_z, radius, hip_x, hip_z, reach_xz, other_legs, feet_block_radius, w):
    """Potential footprints (§5.1): free cells in the disc, within reach, no leg crossing, and
    :data:`LEG_CLEARANCE` of the foot's room clear of every other leg and foot.

    The footprint of a candidate cell is a continuous point: the point of the cell's square
    nearest to the preferred footprint (the preferred footprint itself when its own cell is a
    candidate), see :func:`footprint_point`; reach, leg crossing, distance and leg gap are
    measured at that point (roughness, slope and proximity are the cell's).

    Returns (cells, terms (n, 5), scores, features (n, 5), points (n, 2)) sorted by descending
    footprint score, ties by ascending padded index (deterministic).
    """
    n = hp * wp
    seed = np.zeros(n, dtype=np.uint8)
    inside = np.zeros(n, dtype=np.uint8)
    for p in range(n):
        if code[p] != PAD:
            inside[p] = 1
            if foot_blocked(code[p]):
                seed[p] = 1
    prox_dt = np.empty(n, dtype=np.float64)
    chamfer_distance(seed, inside, hp, wp, cell, prox_dt)
    cells = np.empty(n, dtype=np.int64)
    terms = np.empty((n, N_FOOTPRINT_TERMS), dtype=np.float64)
    features = np.empty((n, N_FEATURES), dtype=np.float64)
    scores = np.empty(n, dtype=np.float64)
    buf = np.empty(N_TERMS, dtype=np.float64)
    feat = np.empty(N_FEATURES, dtype=np.float64)
    points = np.empty((n, 2), dtype=np.float64)
    m = 0
    for rr in range(1, hp - 1):
        for cc in range(1, wp - 1):
            p = rr * wp + cc
            # A cell touched by another leg's projection is a candidate too when the continuous
            # footprint in it keeps a foot's room from every other leg and foot (checked below):
            # blocking whole 7 cm cells moved feet a cell away from where they belong.
            if (code[p] != FREE and code[p] != OTHER_LEG) or p == source_p:
                continue
            cx, cz = cell_centre(r0 - 1 + rr, c0 - 1 + cc, origin_x, origin_z, cell)
            if math.hypot(cx - pref_x, cz - pref_z) > radius:
                continue  # the candidate disc is a set of cells (paper Fig. 13)
            x, z = footprint_point(cx, cz, cell, pref_x, pref_z)
            # A cell touched by another leg: only the preferred footprint's own cell (below).
            if code[p] == OTHER_LEG and (x != pref_x or z != pref_z):
                continue
            ok, x, z = out_of_other_feet(x, z, cx, cz, cell, other_legs, feet_block_radius, code[p] == OTHER_LEG)
            if not ok:
                continue
            if math.hypot(x - source_x, z - source_z) < MIN_STEP_CELLS * cell:
                continue  # a foot on a cell border: the neighbour's nearest point may be where it stands
            if math.hypot(x - hip_x, z - hip_z) > reach_xz:
                continue
            if not footprint_features(p, x, z, elev_dil, elev_raw, prox_dt, wp, pref_x, pref_z, hip_x, hip_z,
                                      other_legs, cell, feat):
                continue
            if feat[FEAT_LEG_GAP] < LEG_CLEARANCE * feet_block_radius:
                continue  # its leg passes (or another leg ends) too near: they cross at the next turn
            # ... only the cell of the preferred footprint itself (the one a blocked cell costs most;
            # opening every such cell doubled the candidates and the planning cost), its footprint
            # moved out of the other legs' room (out_of_other_feet) and keeping it both ways.
            if code[p] == OTHER_LEG and not _clear_of_other_feet(x, z, other_legs, feat[FEAT_LEG_GAP],
                                                                  feet_block_radius):
                continue
            # A free cell next to the cells around another foot: its continuous footprint (on the border
            # nearest the preferred one) can still be within a foot's room of that foot.
            if _near_other_foot(x, z, other_legs, feet_block_radius):
                continue
            footprint_goodness(w, feat, buf)
            cells[m] = p
            for k in range(N_FOOTPRINT_TERMS):
                terms[m, k] = buf[k]
                features[m, k] = feat[k]
            scores[m] = weighted_mean(w, buf, 0, N_FOOTPRINT_TERMS)
            points[m, 0] = x
            points[m, 1] = z
            m += 1
    order = np.argsort(-scores[:m], kind="mergesort")
    return (cells[:m][order].copy(), terms[:m][order].copy(), scores[:m][order].copy(), features[:m][order].copy(),
            points[:m][order].copy())


@nb.njit(cache=True)
def slice_levels(code, boxh_dil, slice_size, eps):
    """Slice levels (m above terrain), first +inf (no slices: go over everything), then
    descending levels, each blocking strictly more obstacle cells than the previous."""
    levels = np.empty(MAX_SLICES, dtype=np.float64)
    levels[0] = np.inf
    if slice_size <= 0.0:
        return levels[:1].copy()
    heights = np.empty(boxh_dil.size, dtype=np.float64)
    m = 0
    for p in range(boxh_dil.size):
        # Only free cells matter: forbidden and size-increase cells are blocked in every slice.
        if code[p] == FREE and boxh_dil[p] > eps:
            heights[m] = boxh_dil[p]
            m += 1
    if m == 0:
        return levels[:1].copy()
    hs = np.sort(heights[:m])
    n_levels = 1
    last_blocked = 0
    k = int(math.ceil(hs[-1] / slice_size))
    while k >= 0 and n_levels < MAX_SLICES:
        level = k * slice_size
        blocked = m - np.searchsorted(hs, level + eps, side="right")
        if blocked > last_blocked:
            levels[n_levels] = level
            n_levels += 1
            last_blocked = blocked
        k -= 1
    return levels[:n_levels].copy()


@nb.njit(cache=True)
def _open_escape(passable, blocked, inside, source_p, wp, code):
    """A foot standing in a blocked cell (a moving box ran into it) may leave through the
    blocked region around it: the 4-connected blocked cells reachable from the source are
    opened, so the wavefront finds the way out (the 3D path rises over them).

    The cells of a static forbidden box (or another body, or the map's edge) are opened only for a
    foot standing in one; a foot beside one (a size-increase cell) leaves through the cells beside
    it. Opened from there too, a static crate's cells let a far spider's swing cut 5 cm across the
    crate's corner, 0.28 m below its top (1000 spiders, ``mixed``, seed 1, frame 160). A moving box's
    cells stay a way out (it moves on): closed too, a foot beside a crate heading at it found no
    couple more often, was tucked, and the tucked legs crossed (ants on ``crates-moving``: crossing
    frames in 20 of 177 runs of the small crowded sets, 1 before)."""
    n = passable.size
    through_forbidden = code[source_p] == FORBIDDEN or code[source_p] == MOVING_BOX
    stack = np.empty(n, dtype=np.int64)
    seen = np.zeros(n, dtype=np.uint8)
    top = 0
    stack[top] = source_p
    top += 1
    seen[source_p] = 1
    while top > 0:
        top -= 1
        p = stack[top]
        passable[p] = 1
        blocked[p] = 0
        for q in (p - 1, p + 1, p - wp, p + wp):
            if inside[q] and not seen[q] and blocked[q] and (through_forbidden or code[q] != FORBIDDEN):
                seen[q] = 1
                stack[top] = q
                top += 1


@nb.njit(cache=True)
def swing_reach(r0, c0, hp, wp, origin_x, origin_z, cell, source_x, source_z, hip_x, hip_z, reach_xz, out):
    """``out`` (hp * wp,) uint8: the cells a swing may pass through, those whose centre lies within
    the leg's horizontal reach of the hip it lands under (or as far as the source, if that is
    further), grown by half a cell's diagonal (a path runs through cell centres).

    A foot cannot leave its leg's reach in the air: around a crate and another leg's
    projection, the wavefront of a spider's foot took a 1 m loop for a 0.29 m step, 0.93 m from
    its hip, and the foot drawn at the end of the stretched leg stood inside the crate."""
    radius = max(reach_xz, math.hypot(source_x - hip_x, source_z - hip_z)) + 0.5 * math.sqrt(2.0) * cell
    for p in range(hp * wp):
        rr = p // wp
        cx, cz = cell_centre(r0 - 1 + rr, c0 - 1 + (p - rr * wp), origin_x, origin_z, cell)
        out[p] = math.hypot(cx - hip_x, cz - hip_z) <= radius


@nb.njit(cache=True, inline="always")
def _boxed_way(c):
    """A cell a boxed-in foot's way out may pass (:data:`BOXED_CELL_COST`)."""
    return c == OTHER_LEG or c == SIZE_INCREASE


@nb.njit(cache=True)
def slice_maps(code, boxh_dil, level, eps, source_p, in_reach, hp, wp, cell, pot_range, pot_gain, passable, factor,
               dt, boxed=False):
    """Passable cells, potential-field cost factors and distance to blocked cells for one slice.

    A cell out of the swing's reach (``in_reach``, :func:`swing_reach`) is not passable, but it
    blocks nothing: the distance to obstacles (clearance, potential field) ignores it.

    ``boxed``: the way out of a boxed-in foot (no candidate reachable otherwise): the cells of other
    feet's room and other legs' projections (``OTHER_LEG``) and the foot-size ring of forbidden boxes
    (``SIZE_INCREASE``) within reach are passable too, at :data:`BOXED_CELL_COST` x their cost; they
    still count as obstacles for the clearance."""
    n = hp * wp
    inside = np.empty(n, dtype=np.uint8)
    blocked = np.empty(n, dtype=np.uint8)
    for p in range(n):
        inside[p] = code[p] != PAD
        ok = code[p] == FREE and boxh_dil[p] <= level + eps
        passable[p] = ((ok or (boxed and _boxed_way(code[p]))) and in_reach[p]) or p == source_p
        blocked[p] = inside[p] and not ok
    if code[source_p] != FREE or boxh_dil[source_p] > level + eps:
        _open_escape(passable, blocked, inside, source_p, wp, code)
    chamfer_distance(blocked, inside, hp, wp, cell, dt)
    for p in range(n):
        if pot_range > 0.0 and dt[p] < pot_range:
            g = 1.0 - dt[p] / pot_range
            factor[p] = 1.0 + pot_gain * g * g
        else:
            factor[p] = 1.0
        if boxed and _boxed_way(code[p]):
            factor[p] *= BOXED_CELL_COST


@nb.njit(cache=True)
def path_crosses_legs(points, n, col_z, other_legs):
    """The polyline ``points[:n]`` (x in column 0, z in ``col_z``) crosses a row of ``other_legs``
    (``planner.layout.LEG_ROW``: a leg's ground projection hip -> foot, or a segment of one as
    drawn). A boxed-in foot's way out passes cells of other legs' projections (:func:`slice_maps`),
    so its paths are checked on the segments themselves."""
    for i in range(n - 1):
        for j in range(other_legs.shape[0]):
            if segments_cross(points[i, 0], points[i, col_z], points[i + 1, 0], points[i + 1, col_z], other_legs[j, 0],
                              other_legs[j, 1], other_legs[j, 2], other_legs[j, 3]):
                return True
    return False


@nb.njit(cache=True)
def path_touches_forbidden(points, n, col_z, forbidden, origin_x, origin_z, cell, foot_shape):
    """The foot (``foot_shape``: length, width, yaw) centred at one of the samples ``points[:n]`` (x in
    column 0, z in ``col_z``) overlaps a forbidden cell's square (or leaves the map)."""
    hx = 0.5 * foot_shape[0]
    hz = 0.5 * foot_shape[1]
    yaw = foot_shape[2]
    reach = int(math.ceil(math.hypot(hx, hz) / cell)) + 1
    n_rows, n_cols = forbidden.shape
    for i in range(n):
        x = points[i, 0]
        z = points[i, col_z]
        r, c = cell_of(x, z, origin_x, origin_z, cell)
        for dr in range(-reach, reach + 1):
            for dc in range(-reach, reach + 1):
                cx, cz = cell_centre(r + dr, c + dc, origin_x, origin_z, cell)
                if not rect_overlaps_aabb(x, z, hx, hz, yaw, cx, cz, 0.5 * cell, 0.5 * cell):
                    continue
                if r + dr < 0 or r + dr >= n_rows or c + dc < 0 or c + dc >= n_cols or forbidden[r + dr, c + dc]:
                    return True
    return False


@nb.njit(cache=True, inline="always")
def _pulled_back(ax, az, bx, bz):
    """End point b moved END_PULLBACK_M toward a (b itself for a point segment)."""
    d = math.hypot(bx - ax, bz - az)
    back = END_PULLBACK_M / d if d > 0.0 else 0.0
    return bx - back * (bx - ax), bz - back * (bz - az)


@nb.njit(cache=True, inline="always")
def _within_source_grace(ax, az, bx, bz, cx, cz, half, sx, sz, grace):
    """The part of segment a-b inside the closed square of centre (cx, cz), half side ``half``, lies within
    ``grace`` of the source (sx, sz): both ends of the clipped part in the disc (a disc is convex). A
    segment that misses the square (by rounding: the supercover met the cell) is not forgiven."""
    t0, t1 = segment_square_clip(ax, az, bx, bz, cx, cz, half)
    if t0 > t1:
        return False
    dx = bx - ax
    dz = bz - az
    return (math.hypot(ax + t0 * dx - sx, az + t0 * dz - sz) <= grace
            and math.hypot(ax + t1 * dx - sx, az + t1 * dz - sz) <= grace)


@nb.njit(cache=True)
def segment_clear(ax, az, bx, bz, passable, code, source_p, source_x, source_z, grace, r0, c0, hp, wp, origin_x, origin_z,
                  cell, rows, cols):
    """Line of sight: every cell the segment touches is passable (or the source cell). Returns 0 (blocked),
    1 (clear) or :data:`GRACED` (clear but for cells of another leg or foot met only within ``grace`` of the
    source, :data:`SOURCE_GRACE`)."""
    m = supercover_visit(ax, az, bx, bz, origin_x, origin_z, cell, rows, cols)
    if m >= rows.size:
        return 0
    out = 1
    for k in range(m):
        rr = rows[k] - r0 + 1
        cc = cols[k] - c0 + 1
        if rr < 1 or rr >= hp - 1 or cc < 1 or cc >= wp - 1:
            return 0
        p = rr * wp + cc
        if p != source_p and not passable[p]:
            if code[p] != OTHER_LEG or grace <= 0.0:
                return 0
            cx, cz = cell_centre(rows[k], cols[k], origin_x, origin_z, cell)
            if not _within_source_grace(ax, az, bx, bz, cx, cz, 0.5 * cell, source_x, source_z, grace):
                return 0
            out = GRACED
    return out


@nb.njit(cache=True)
def naive_and_kept_points(parent, source_p, target_p, source_x, source_z, target_x, target_z, passable, code, grace, r0,
                          c0, hp, wp, origin_x, origin_z, cell, rows, cols):
    """Naive cells of the wavefront path, refined by line of sight (§4).

    Returns (kept, graced): the kept points (k, 2) in world x, z (the exact source, the cell centres
    kept, the exact target point: a continuous footprint inside the target cell), and whether a kept
    chord is clear only by the source's grace (:data:`SOURCE_GRACE`, ``grace`` in metres).
    """
    count = 1
    p = target_p
    while p != source_p:
        p = parent[p]
        count += 1
    naive = np.empty((count, 2), dtype=np.float64)
    p = target_p
    for i in range(count - 1, -1, -1):
        rr = p // wp
        cc = p - rr * wp
        x, z = cell_centre(r0 - 1 + rr, c0 - 1 + cc, origin_x, origin_z, cell)
        naive[i, 0] = x
        naive[i, 1] = z
        if i > 0:
            p = parent[p]
    naive[0, 0] = source_x
    naive[0, 1] = source_z
    naive[count - 1, 0] = target_x
    naive[count - 1, 1] = target_z
    kept_idx = np.empty(count, dtype=np.int64)
    kept_idx[0] = 0
    nk = 1
    i = 0
    graced = False
    while i < count - 1:
        j = count - 1
        while j > i + 1:
            ex, ez = naive[j, 0], naive[j, 1]
            if j == count - 1:  # the chord to the footprint: its own cell's border is its own
                ex, ez = _pulled_back(naive[i, 0], naive[i, 1], ex, ez)
            clear = segment_clear(naive[i, 0], naive[i, 1], ex, ez, passable, code, source_p, source_x, source_z,
                                  grace, r0, c0, hp, wp, origin_x, origin_z, cell, rows, cols)
            if clear:
                graced = graced or clear == GRACED
                break
            j -= 1
        kept_idx[nk] = j
        nk += 1
        i = j
    kept = np.empty((nk, 2), dtype=np.float64)
    for k in range(nk):
        kept[k, 0] = naive[kept_idx[k], 0]
        kept[k, 1] = naive[kept_idx[k], 1]
    return kept, graced


@nb.njit(cache=True)
def hermite_dense(kept, tau, cell, dense):
    """Sample the 2D Hermite curve through the kept points (Catmull-Rom tangents x tau).

    Writes samples into ``dense[:, :2]`` (x, z) and returns how many, or -1 when the
    curve needs more than MAX_DENSE samples.
    """
    nk = kept.shape[0]
    spacing = DENSE_SPACING * cell
    n = 0
    for i in range(nk - 1):
        p0x = kept[i, 0]
        p0z = kept[i, 1]
        p1x = kept[i + 1, 0]
        p1z = kept[i + 1, 1]
        if i == 0:
            t0x = p1x - p0x
            t0z = p1z - p0z
        else:
            t0x = 0.5 * (p1x - kept[i - 1, 0])
            t0z = 0.5 * (p1z - kept[i - 1, 1])
        if i == nk - 2:
            t1x = p1x - p0x
            t1z = p1z - p0z
        else:
            t1x = 0.5 * (kept[i + 2, 0] - p0x)
            t1z = 0.5 * (kept[i + 2, 1] - p0z)
        t0x *= tau
        t0z *= tau
        t1x *= tau
        t1z *= tau
        chord = math.hypot(p1x - p0x, p1z - p0z)
        est = chord + (math.hypot(t0x, t0z) + math.hypot(t1x, t1z)) / 3.0
        m = max(1, int(math.ceil(est / spacing)))
        last = m + 1 if i == nk - 2 else m
        if n + last > dense.shape[0]:
            return -1
        for j in range(last):
            t = j / m
            t2 = t * t
            t3 = t2 * t
            h00 = 2 * t3 - 3 * t2 + 1
            h10 = t3 - 2 * t2 + t
            h01 = -2 * t3 + 3 * t2
            h11 = t3 - t2
            dense[n, 0] = h00 * p0x + h10 * t0x + h01 * p1x + h11 * t1x
            dense[n, 1] = h00 * p0z + h10 * t0z + h01 * p1z + h11 * t1z
            n += 1
    dense[n - 1, 0] = kept[nk - 1, 0]
    dense[n - 1, 1] = kept[nk - 1, 1]
    return n


@nb.njit(cache=True)
def pchip_slopes(u, y):
    """Shape-preserving (monotone) cubic Hermite slopes (Fritsch-Carlson / PCHIP)."""
    n = u.size
    m = np.zeros(n, dtype=np.float64)
    if n == 2:
        s = (y[1] - y[0]) / (u[1] - u[0])
        m[0] = s
        m[1] = s
        return m
    h = np.empty(n - 1, dtype=np.float64)
    d = np.empty(n - 1, dtype=np.float64)
    for i in range(n - 1):
        h[i] = u[i + 1] - u[i]
        d[i] = (y[i + 1] - y[i]) / h[i]
    for i in range(1, n - 1):
        if d[i - 1] * d[i] > 0.0:
            w1 = 2 * h[i] + h[i - 1]
            w2 = h[i] + 2 * h[i - 1]
            m[i] = (w1 + w2) / (w1 / d[i - 1] + w2 / d[i])
    for end in range(2):
        if end == 0:
            h0, h1, d0, d1 = h[0], h[1], d[0], d[1]
        else:
            h0, h1, d0, d1 = h[n - 2], h[n - 3], d[n - 2], d[n - 3]
        s = ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1)
        if s * d0 <= 0.0:
            s = 0.0
        elif d0 * d1 <= 0.0 and abs(s) > abs(3 * d0):
            s = 3 * d0
        if end == 0:
            m[0] = s
        else:
            m[n - 1] = s
    return m


@nb.njit(cache=True)
def resample_by_arclength(poly, n_poly, k, out):
    """Resample a 3D polyline at k points of constant arc-length spacing. Returns its length."""
    cum = np.empty(n_poly, dtype=np.float64)
    cum[0] = 0.0
    for i in range(1, n_poly):
        dx = poly[i, 0] - poly[i - 1, 0]
        dy = poly[i, 1] - poly[i - 1, 1]
        dz = poly[i, 2] - poly[i - 1, 2]
        cum[i] = cum[i - 1] + math.sqrt(dx * dx + dy * dy + dz * dz)
    total = cum[n_poly - 1]
    j = 0
    for i in range(k):
        s = total * i / (k - 1)
        while j < n_poly - 2 and cum[j + 1] < s:
            j += 1
        seg = cum[j + 1] - cum[j]
        a = (s - cum[j]) / seg if seg > 0.0 else 0.0
        a = min(1.0, max(0.0, a))
        for d in range(3):
            out[i, d] = poly[j, d] + a * (poly[j + 1, d] - poly[j, d])
    for d in range(3):
        out[0, d] = poly[0, d]
        out[k - 1, d] = poly[n_poly - 1, d]
    return total


@nb.njit(cache=True)
def path_2d(kept, passable, dt, elev_dil, code, source_p, target_p, grace, r0, c0, hp, wp, origin_x, origin_z, cell,
            dense, dense_p, g_free, rows, cols):
    """2D Hermite path through the kept points, verified chord by chord.

    Tries Catmull-Rom tangents, then halved, then zero tangents (the refined
    polyline, clear by line of sight). Fills dense[:, :2] and dense_p (ROI index of
    each sample), G in dense[:, 2] and ``g_free`` (G over the cells clear of forbidden boxes
    only, :func:`drawn_heights`). Chords from the source ``kept[0]`` have its grace (``grace`` m,
    :data:`SOURCE_GRACE`). Returns (n_dense, length_2d, curvature_energy, clearance_m, graced);
    n_dense = -1 if none fits; graced: a chord is clear only by the source's grace.
    """
    chord_max = DENSE_SPACING_MAX * cell
    source_x = kept[0, 0]
    source_z = kept[0, 1]
    n = -1
    graced = False
    for attempt in range(3):
        graced = False
        tau = 1.0 if attempt == 0 else (0.5 if attempt == 1 else 0.0)
        n = hermite_dense(kept, tau, cell, dense)
        if n < 0:
            continue
        ok = True
        for i in range(n):
            if i == n - 1:
                dense_p[i] = target_p  # the footprint is in its own cell (END_PULLBACK_M)
            else:
                r, c = cell_of(dense[i, 0], dense[i, 1], origin_x, origin_z, cell)
                rr = r - r0 + 1
                cc = c - c0 + 1
                if rr < 1 or rr >= hp - 1 or cc < 1 or cc >= wp - 1:
                    ok = False
                    break
                dense_p[i] = rr * wp + cc
            if i > 0:
                if math.hypot(dense[i, 0] - dense[i - 1, 0], dense[i, 1] - dense[i - 1, 1]) > chord_max:
                    ok = False
                    break
                ex, ez = dense[i, 0], dense[i, 1]
                if i == n - 1:
                    ex, ez = _pulled_back(dense[i - 1, 0], dense[i - 1, 1], ex, ez)
                clear = segment_clear(dense[i - 1, 0], dense[i - 1, 1], ex, ez, passable, code, source_p, source_x,
                                      source_z, grace, r0, c0, hp, wp, origin_x, origin_z, cell, rows, cols)
                if not clear:
                    ok = False
                    break
                graced = graced or clear == GRACED
        if ok:
            break
        n = -1
    if n < 2:
        return -1, 0.0, 0.0, 0.0, False
    cum = np.empty(n, dtype=np.float64)
    cum[0] = 0.0
    for i in range(1, n):
        cum[i] = cum[i - 1] + math.hypot(dense[i, 0] - dense[i - 1, 0], dense[i, 1] - dense[i - 1, 1])
    length = cum[n - 1]
    # Curvature energy E = L * integral kappa^2 ds, discrete: kappa_i = turning angle / local ds.
    integral = 0.0
    clearance = np.inf
    for i in range(1, n - 1):
        u = cum[i] / length if length > 0 else 0.0
        # Samples in the footprint's own cell when it is blocked (a goal-only cell next to another leg)
        # or in the source cell when it is (a box moved onto the foot) are at 0 from a blocked cell by
        # definition: counting them scored every such footprint's path at clearance 0, and a spider's
        # middle-rear foot landed a cell short of its preferred footprint every other stride.
        # Samples in a cell the source's grace lets the path pass are at 0 by definition too.
        p = dense_p[i]
        in_grace = (code[p] == OTHER_LEG and not passable[p]
                    and math.hypot(dense[i, 0] - source_x, dense[i, 1] - source_z) <= grace)
        if not ((p == target_p or p == source_p or in_grace) and dt[p] == 0.0):
            clearance = min(clearance, dt[p])
        if u < U_LO or u > U_HI:
            continue
        ax = dense[i, 0] - dense[i - 1, 0]
        az = dense[i, 1] - dense[i - 1, 1]
        bx = dense[i + 1, 0] - dense[i, 0]
        bz = dense[i + 1, 1] - dense[i, 1]
        la = math.hypot(ax, az)
        lb = math.hypot(bx, bz)
        if la <= 0.0 or lb <= 0.0:
            continue
        cross = ax * bz - az * bx
        dot = ax * bx + az * bz
        theta = math.atan2(cross, dot)
        ds = 0.5 * (la + lb)
        integral += theta * theta / ds
    if clearance == np.inf:
        clearance = dt[dense_p[n - 1]]
    # Highest dilated elevation over the passable cells of the 3 x 3 block of each
    # sample: every point of a chord between two samples lies in a passable cell
    # (checked above) of both blocks (chords are shorter than a cell).
    for i in range(n):
        p = dense_p[i]
        g = elev_dil[p]
        gf = -np.inf if foot_blocked(code[p]) else elev_dil[p]
        for q in (p - wp - 1, p - wp, p - wp + 1, p - 1, p + 1, p + wp - 1, p + wp, p + wp + 1):
            if passable[q] or q == source_p:
                g = max(g, elev_dil[q])
                if not foot_blocked(code[q]):
                    gf = max(gf, elev_dil[q])
        dense[i, 2] = g
        g_free[i] = gf
    return n, length, length * integral, clearance, graced


@nb.njit(cache=True)
def drawn_heights(dense, g_free, n, ceiling, out):
    """``out[:n]``: the path ``dense[:n]`` with, in column 2, what the drawn swing keeps above: G, but over
    the cells of a forbidden box (and next to one) no more than ``ceiling`` (``g_free``: G over the
    others). Returns whether any sample is lower than in ``dense``.

    A swing passes such cells only to leave a box that ran onto its foot, or where one is heading
    (:func:`_open_escape`). It is scored as climbing the box (the climb and the 3D length send it to a
    footprint further away: three variants scored without the climb had 2-7 x the feet in crates over
    36-144 paired crowded runs), but a foot never climbs a forbidden box (forbidden at any height), and
    drawn over its top a spider's foot stepping 7 cm out of a crate's way rose 0.33 m, 0.2 m above its
    hip, and its folded leg crossed two others (crates-moving, 12 characters, seed 3, frame 252; over
    that 1200-frame run 125 swinging foot-frames were more than 10 cm above their hip, up to 0.48 m)."""
    lowered = False
    for i in range(n):
        out[i, 0] = dense[i, 0]
        out[i, 1] = dense[i, 1]
        g = max(g_free[i], min(dense[i, 2], ceiling))
        out[i, 2] = g
        if g < dense[i, 2]:
            lowered = True
    return lowered


@nb.njit(cache=True)
def elevate_3d(dense, n, length2d, source_y, target_y, step_height, margin, cell, poly):
    """3D trajectory over the 2D path (§4): a shape-preserving cubic Hermite height
    profile through elevated waypoints, never below the dilated elevation + margin.

    ``dense[:, 2]`` holds G (see ``path_2d``); ``poly`` receives (x, y, z). Returns the
    highest interior height.
    """
    cum = np.empty(n, dtype=np.float64)
    cum[0] = 0.0
    for i in range(1, n):
        cum[i] = cum[i - 1] + math.hypot(dense[i, 0] - dense[i - 1, 0], dense[i, 1] - dense[i - 1, 1])
    total = cum[n - 1] if cum[n - 1] > 0.0 else 1.0
    n_wp = min(n, max(3, int(math.ceil(length2d / (2.0 * cell))) + 1)) if n >= 3 else n
    idx = np.empty(n_wp, dtype=np.int64)
    for j in range(n_wp):
        idx[j] = int(round(j * (n - 1) / (n_wp - 1)))
    wu = np.empty(n_wp, dtype=np.float64)
    wy = np.empty(n_wp, dtype=np.float64)
    for j in range(n_wp):
        u = cum[idx[j]] / total
        wu[j] = u
        if j == 0:
            wy[j] = source_y
        elif j == n_wp - 1:
            wy[j] = target_y
        else:
            y = source_y + (target_y - source_y) * u + step_height * 4.0 * u * (1.0 - u)
            lo = max(1, idx[j - 1])
            hi = min(n - 2, idx[j + 1])
            for i in range(lo, hi + 1):
                y = max(y, dense[i, 2] + margin)
            wy[j] = y
    slopes = pchip_slopes(wu, wy)
    seg = 0
    top = -np.inf
    for i in range(n):
        u = cum[i] / total
        while seg < n_wp - 2 and u > wu[seg + 1]:
            seg += 1
        h = wu[seg + 1] - wu[seg]
        t = (u - wu[seg]) / h if h > 0.0 else 0.0
        t2 = t * t
        t3 = t2 * t
        y = ((2 * t3 - 3 * t2 + 1) * wy[seg] + (t3 - 2 * t2 + t) * h * slopes[seg]
             + (-2 * t3 + 3 * t2) * wy[seg + 1] + (t3 - t2) * h * slopes[seg + 1])
        if 0 < i < n - 1:
            y = max(y, dense[i, 2] + margin)
            top = max(top, y)
        poly[i, 0] = dense[i, 0]
        poly[i, 1] = y
        poly[i, 2] = dense[i, 1]
    poly[0, 1] = source_y
    poly[n - 1, 1] = target_y
    return top


@nb.njit(cache=True)
def geometric_jerk(poly, n, work):
    """J = L^3 * integral |d^3x/ds^3|^2 ds over u in [U_LO, U_HI] (scale free)."""
    length = resample_by_arclength(poly, n, JERK_SAMPLES, work)
    if length <= 0.0:
        return 0.0
    h = length / (JERK_SAMPLES - 1)
    acc = 0.0
    for k in range(1, JERK_SAMPLES - 2):
        u = k / (JERK_SAMPLES - 1)
        if u < U_LO or u > U_HI:
            continue
        s = 0.0
        for d in range(3):
            j3 = (work[k + 2, d] - 3.0 * work[k + 1, d] + 3.0 * work[k, d] - work[k - 1, d]) / (h * h * h)
            s += j3 * j3
        acc += s * h
    return length ** 3 * acc


@nb.njit(cache=True)
def path_length_3d(poly, n):
    total = 0.0
    for i in range(1, n):
        dx = poly[i, 0] - poly[i - 1, 0]
        dy = poly[i, 1] - poly[i - 1, 1]
        dz = poly[i, 2] - poly[i - 1, 2]
        total += math.sqrt(dx * dx + dy * dy + dz * dz)
    return total


@nb.njit(cache=True)
def couple_metrics_2d(parent, passable, dt, elev_dil, code, source_p, target_p, source_x, source_y, source_z, target_x,
                      target_y, target_z, step_height, r0, c0, hp, wp, origin_x, origin_z, cell, dense, dense_p, g_free,
                      rows, cols, other_legs, grace):
    """The 2D part of a (target, slice) couple: the path from the slice's wavefront tree, its
    2D metrics, and the 2D climb over the elevations under the path (the 3D trajectory stays
    above them, so climb_3d >= climb_2d, and with length_3d >= length_2d, score_3d <= score_2d).
    ``code`` (the ROI's cell codes) and ``g_free`` (filled) as in :func:`path_2d`; a path clear
    only by its source's grace (``grace`` m, :data:`SOURCE_GRACE`) crosses no row of ``other_legs``.
    Returns (n_dense, length_2d, curvature, clearance, climb_2d); n_dense < 2: no path."""
    # A goal-only target cell (next to another leg, see footprint_candidates) is passable for
    # the path that ends in it, and only for that path.
    was = passable[target_p]
    passable[target_p] = 1
    kept, graced_kept = naive_and_kept_points(parent, source_p, target_p, source_x, source_z, target_x, target_z,
                                              passable, code, grace, r0, c0, hp, wp, origin_x, origin_z, cell, rows,
                                              cols)
    nd, len2, curv, clear, graced = path_2d(kept, passable, dt, elev_dil, code, source_p, target_p, grace, r0, c0, hp,
                                            wp, origin_x, origin_z, cell, dense, dense_p, g_free, rows, cols)
    passable[target_p] = was
    if nd >= 2 and (graced or graced_kept) and path_crosses_legs(dense, nd, 1, other_legs):
        nd = -1
    if nd < 2:
        return nd, 0.0, 0.0, 0.0, 0.0
    ground_top = -np.inf
    for i in range(1, nd - 1):
        ground_top = max(ground_top, dense[i, 2])
    base = max(source_y, target_y) + step_height
    return nd, len2, curv, clear, max(0.0, ground_top - base)


@nb.njit(cache=True)
def couple_metrics_3d(dense, nd, len2, source_y, target_y, step_height, obstacle_margin, cell, poly, jerk_work):
    """The 3D part of a couple whose 2D part filled ``dense``: the trajectory in ``poly``.
    Returns (length_3d, climb_3d, jerk)."""
    top = elevate_3d(dense, nd, len2, source_y, target_y, step_height, obstacle_margin, cell, poly)
    base = max(source_y, target_y) + step_height
    return path_length_3d(poly, nd), max(0.0, top - base), geometric_jerk(poly, nd, jerk_work)
