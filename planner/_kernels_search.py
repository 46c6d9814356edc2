"""numba kernel: the best footprint-trajectory couple for one foot (paper §5.2, §6).

Couple score
    weighted mean of the five footprint goodnesses and the five trajectory
    goodnesses (see :mod:`planner._weights`). The length goodness is the path's
    directness on the ground (2D path length against the straight distance to the
    couple's own footprint), the same in 2D and 3D. The 2D score of a couple
    replaces the 3D-only quantities by their best case (jerk goodness 1) and uses
    the elevations under the path for the climb, so for every couple
    ``score_3d <= score_2d``: a 2D score that does not beat the best couple proves
    the 3D one cannot either (§5.2 computes the 2D score first for this reason).

Search (``MODE_SEARCH``)
    candidates in descending footprint score; for each, the slices (no slices
    first, then ever lower levels that go around ever more obstacles); the
    wavefront of a slice is computed once, from the source, and stops when all
    candidates of that slice are settled: it serves every target. Stops:
    * the budget: ``couples_after_first`` 3D couples after the first valid one;
    * the paper's early termination: a target whose 3D couples did not beat the
      best ends the search (``paper_early_stop``);
    * an exact bound: no remaining candidate can beat the best even with perfect
      trajectory goodnesses.
    With no budget limit and no early termination the result is the optimum
    over all (target, slice) couples.

Boxed-in foot
    when no candidate is reachable in any slice, one more pass over the first
    slice lets the path through the room of other feet and the projections of
    other legs, and the foot-size ring of forbidden boxes, at
    :data:`planner._kernels_foot.BOXED_CELL_COST` x the cost (a path that
    crosses a leg's segment itself, or where the foot touches a forbidden cell,
    is refused); its couple counts in ``boxed_ways``. Without one the foot holds (the defined fallback).

``MODE_PER_TARGET`` is the same search with one wavefront per (target, slice)
(for benchmarks); ``MODE_BRUTE_FORCE`` scores every (target, slice) couple in
3D with no pruning (the reference the tests compare the search with).

Harvest (:func:`harvest_foot_kernel`, for tuning/)
    every (target, slice) couple in 3D with no pruning, like ``MODE_BRUTE_FORCE``,
    but returns them all: per candidate its raw features and goodnesses, per
    couple its raw trajectory metrics, goodnesses and scores. It reuses the
    search's pieces (``foot_setup``, ``couple_metrics_2d/3d``, the goodness
    functions of :mod:`planner._kernels_foot`), so its numbers are the search's.
    It has no boxed-in pass: a boxed foot's way out is a fallback, not a scored choice.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba as nb
import numpy as np

from footfall.planner._grid import cell_centre, cell_of
from footfall.planner._kernels_geometry import foot_offsets
from footfall.planner._kernels_foot import (
    CNT_BOXED,
    CNT_CANDIDATES,
    CNT_COUPLES_2D,
    CNT_COUPLES_3D,
    CNT_EXPANDED,
    CNT_SLICES,
    CNT_WAVEFRONTS,
    ESCAPE_RISE,
    JERK_SAMPLES,
    MAX_DENSE,
    N_COUNTERS,
    N_RAW,
    RAW_CLEARANCE,
    RAW_CLIMB,
    RAW_CURVATURE,
    RAW_JERK,
    RAW_LENGTH,
    SOURCE_GRACE,
    couple_metrics_2d,
    couple_metrics_3d,
    drawn_heights,
    elevate_3d,
    footprint_candidates,
    path_crosses_legs,
    path_touches_forbidden,
    prepare_foot,
    resample_by_arclength,
    slice_levels,
    slice_maps,
    swing_reach,
    trajectory_goodness,
    weighted_mean,
)
from footfall.planner._kernels_wavefront import wavefront
from footfall.planner._params import C_CELL, C_MARGIN, C_OBST_MARGIN, C_POT_GAIN, C_POT_RANGE, C_RADIUS, C_SAMPLES, C_SLICE_EPS
from footfall.planner._weights import N_FOOTPRINT_TERMS, N_TERMS
from footfall.planner.layout import (  # noqa: F401  (the search modes and the scores' order: planner.layout)
    MODE_BRUTE_FORCE,
    MODE_PER_TARGET,
    MODE_SEARCH,
    SCORE_COUPLE,
    SCORE_FOOTPRINT,
    SCORE_TRAJECTORY,
)


CoupleOut = namedtuple("CoupleOut", ["valid", "target_rc", "target_xyz", "slice_index", "slice_level", "scores",
                                     "terms", "raw", "counters", "trajectory", "candidate_rc", "candidate_scores"])
"""What :func:`plan_foot_kernel` returns, by name: valid, the target's cell (2,) and point (3,), the slice
and its level (m), the scores (3, ``planner.layout.SCORES`` order), the ten goodnesses, the raw metrics (5),
the counters (6), the trajectory (K, 3), and the candidates' cells (n, 2) and footprint scores (n,)."""


@nb.njit(cache=True)
def path_workspace(hp, wp):
    """Work buffers of the path construction for an ROI of hp x wp padded cells:
    (rows, cols) of a supercover walk, the dense 2D samples and their cells, the 3D polyline."""
    cap = 4 * (hp + wp) + 8
    return (np.empty(cap, dtype=np.int64), np.empty(cap, dtype=np.int64), np.empty((MAX_DENSE, 3), dtype=np.float64),
            np.empty(MAX_DENSE, dtype=np.int64), np.empty((MAX_DENSE, 3), dtype=np.float64))


@nb.njit(cache=True)
def foot_setup(elevation, ground, forbidden, origin_x, origin_z, foot_shape, source, preferred, hip, reach_xz,
               other_legs, feet_block_radius, w, cfg, slice_size):
    """ROI maps, potential footprints, slices and d_ref of one foot (shared by the search and the
    harvest; ``foot_shape``: length, width, yaw, whose size-increase stencil is
    :func:`planner._kernels_geometry.foot_offsets`). Returns (code, elev_dil, boxh_dil, r0, c0, hp, wp, source_p, cand, cand_terms,
    cand_scores, cand_features, cand_rc, levels, d_ref (n,), cand_xz, in_reach) - ``cand_xz`` (n, 2) the
    continuous footprints (:func:`planner._kernels_foot.footprint_point`), ``in_reach`` the cells a swing
    may pass (:func:`planner._kernels_foot.swing_reach`)."""
    cell = cfg[C_CELL]
    radius = cfg[C_RADIUS]
    pref_x = preferred[0]
    pref_z = preferred[1]
    offsets = foot_offsets(foot_shape[0], foot_shape[1], foot_shape[2], cell)
    code, elev_dil, boxh_dil, elev_raw, r0, c0, hp, wp = prepare_foot(
        elevation, ground, forbidden, origin_x, origin_z, cell, offsets, source[0], source[2], pref_x, pref_z, radius,
        int(cfg[C_MARGIN]), other_legs, feet_block_radius)
    sr, sc = cell_of(source[0], source[2], origin_x, origin_z, cell)
    source_p = (sr - r0 + 1) * wp + (sc - c0 + 1)
    cand, cand_terms, cand_scores, cand_features, cand_xz = footprint_candidates(
        code, elev_dil, elev_raw, r0, c0, hp, wp, origin_x, origin_z, cell, source_p, source[0], source[2], pref_x,
        pref_z, radius, hip[0], hip[1], reach_xz, other_legs, feet_block_radius, w)
    n_cand = cand.size
    cand_rc = np.empty((n_cand, 2), dtype=np.int64)
    for k in range(n_cand):
        rr = cand[k] // wp
        cand_rc[k, 0] = r0 - 1 + rr
        cand_rc[k, 1] = c0 - 1 + (cand[k] - rr * wp)
    levels = slice_levels(code, boxh_dil, slice_size, cfg[C_SLICE_EPS])
    d_ref = directness_references(cand_xz, source[0], source[2], cell)
    in_reach = np.empty(hp * wp, dtype=np.uint8)
    swing_reach(r0, c0, hp, wp, origin_x, origin_z, cell, source[0], source[2], hip[0], hip[1], reach_xz, in_reach)
    return (code, elev_dil, boxh_dil, r0, c0, hp, wp, source_p, cand, cand_terms, cand_scores, cand_features, cand_rc,
            levels, d_ref, cand_xz, in_reach)


@nb.njit(cache=True)
def directness_references(cand_xz, source_x, source_z, cell):
    """(n,) the length goodness's reference of each candidate: the straight ground distance from the
    source to the candidate's own footprint (at least a cell). Measured against the footprint the
    path ends at, not the preferred one, the term scores how direct a path is and not how short:
    every swing is longer than a reference to the preferred footprint by its lift, so such a
    reference rewarded any step shorter than the stride law asks for (strides alternated short and
    long by up to 30 %)."""
    out = np.empty(cand_xz.shape[0], dtype=np.float64)
    for k in range(cand_xz.shape[0]):
        out[k] = max(math.hypot(cand_xz[k, 0] - source_x, cand_xz[k, 1] - source_z), cell)
    return out


@nb.njit(cache=True)
def _boxed_way_refused(points, n, col_z, other_legs, forbidden, origin_x, origin_z, cell, foot_shape):
    """A boxed-in foot's way (its samples ``points[:n]``) crosses another leg or touches a forbidden cell."""
    return (path_crosses_legs(points, n, col_z, other_legs)
            or path_touches_forbidden(points, n, col_z, forbidden, origin_x, origin_z, cell, foot_shape))


@nb.njit(cache=True)
def plan_foot_kernel(elevation, ground, forbidden, origin_x, origin_z, foot_shape, source, preferred, hip, reach_xz,
                     step_height, other_legs, feet_block_radius, w, cfg, couples_after_first, slice_size,
                     paper_early_stop, mode):
    """Plan one foot (``foot_shape``: length, width, yaw). See the module docstring; returns a
    :data:`CoupleOut`."""
    cell = cfg[C_CELL]
    eps = cfg[C_SLICE_EPS]
    k_out = int(cfg[C_SAMPLES])
    source_x = source[0]
    source_y = source[1]
    source_z = source[2]
    grace = SOURCE_GRACE * feet_block_radius
    counters = np.zeros(N_COUNTERS, dtype=np.int64)
    (code, elev_dil, boxh_dil, r0, c0, hp, wp, source_p, cand, cand_terms, cand_scores, _, cand_rc, levels,
     d_ref, cand_xz, in_reach) = foot_setup(elevation, ground, forbidden, origin_x, origin_z, foot_shape, source,
                                            preferred, hip, reach_xz, other_legs, feet_block_radius, w, cfg,
                                            slice_size)
    n = hp * wp
    n_cand = cand.size
    counters[CNT_CANDIDATES] = n_cand
    n_slices = levels.size
    counters[CNT_SLICES] = n_slices

    # Exact bound: a candidate's couple score cannot exceed its footprint part plus
    # perfect trajectory goodnesses (length bounded by the straight-line distance).
    w_all = 0.0
    for k in range(N_TERMS):
        w_all += w[k]
    suffix_ub = np.empty(n_cand + 1, dtype=np.float64)
    suffix_ub[n_cand] = -np.inf
    tb = np.empty(N_TERMS, dtype=np.float64)
    for k in range(n_cand - 1, -1, -1):
        for t in range(N_FOOTPRINT_TERMS):
            tb[t] = cand_terms[k, t]
        for t in range(N_FOOTPRINT_TERMS, N_TERMS):
            tb[t] = 1.0  # a straight path (length goodness 1) and perfect others
        ub = weighted_mean(w, tb, 0, N_TERMS)
        suffix_ub[k] = max(ub, suffix_ub[k + 1])

    passable = np.empty((n_slices, n), dtype=np.uint8)
    factor = np.empty((n_slices, n), dtype=np.float64)
    dt = np.empty((n_slices, n), dtype=np.float64)
    dist = np.empty((n_slices, n), dtype=np.float64)
    parent = np.empty((n_slices, n), dtype=np.int64)
    ready = np.zeros(n_slices, dtype=np.uint8)
    one = np.empty(1, dtype=np.int64)
    stop = np.empty(max(n_cand, 1), dtype=np.int64)
    rows, cols, dense, dense_p, poly = path_workspace(hp, wp)
    g_free = np.empty(MAX_DENSE, dtype=np.float64)
    dense_drawn = np.empty((MAX_DENSE, 3), dtype=np.float64)
    poly_drawn = np.empty((MAX_DENSE, 3), dtype=np.float64)
    best_poly = np.empty((MAX_DENSE, 3), dtype=np.float64)
    jerk_work = np.empty((JERK_SAMPLES, 3), dtype=np.float64)
    terms = np.empty(N_TERMS, dtype=np.float64)
    best_terms = np.zeros(N_TERMS, dtype=np.float64)
    best_raw = np.zeros(N_RAW, dtype=np.float64)
    best_score = -1.0
    best_k = -1
    best_s = -1
    best_n = 0
    best_target_y = source_y
    first_found = False
    after_first = 0
    done = False
    boxed_pass = False

    for boxed in (False, True):
        if boxed:
            if best_k >= 0 or n_cand == 0:
                break
            # The way out of a boxed-in foot (planner._kernels_foot.BOXED_CELL_COST): no candidate was
            # reachable, so one more wavefront over everything (the first slice) may pass through the
            # room of other feet, the projections of other legs and the foot-size rings of forbidden
            # boxes, at a cost; its paths are checked on the geometry (_boxed_way_refused).
            pass_slices = 1
            ready[0] = 0
            done = False
            boxed_pass = True
        else:
            pass_slices = n_slices
        for k in range(n_cand):
            if done:
                break
            if mode != MODE_BRUTE_FORCE and best_k >= 0 and suffix_ub[k] <= best_score:
                break
            tp = cand[k]
            target_y = elev_dil[tp]
            tx = cand_xz[k, 0]
            tz = cand_xz[k, 1]
            evaluated_3d = False
            improved = False
            for s in range(pass_slices):
                if boxh_dil[tp] > levels[s] + eps:
                    continue  # the target itself is above this slice: not reachable in it
                if not ready[s]:
                    slice_maps(code, boxh_dil, levels[s], eps, source_p, in_reach, hp, wp, cell, cfg[C_POT_RANGE],
                               cfg[C_POT_GAIN], passable[s], factor[s], dt[s], boxed)
                    if mode == MODE_SEARCH:
                        m = 0
                        for q in range(n_cand):
                            if boxh_dil[cand[q]] <= levels[s] + eps:
                                stop[m] = cand[q]
                                m += 1
                        counters[CNT_EXPANDED] += wavefront(passable[s], factor[s], wp, source_p, cell, stop[:m], dist[s],
                                                            parent[s])
                        counters[CNT_WAVEFRONTS] += 1
                    ready[s] = 1
                if mode != MODE_SEARCH:
                    one[0] = tp
                    counters[CNT_EXPANDED] += wavefront(passable[s], factor[s], wp, source_p, cell, one, dist[s], parent[s])
                    counters[CNT_WAVEFRONTS] += 1
                if not math.isfinite(dist[s, tp]):
                    continue
                nd, len2, curv, clear, climb2 = couple_metrics_2d(
                    parent[s], passable[s], dt[s], elev_dil, code, source_p, tp, source_x, source_y, source_z, tx, target_y,
                    tz, step_height, r0, c0, hp, wp, origin_x, origin_z, cell, dense, dense_p, g_free, rows, cols,
                    other_legs, grace)
                if nd < 2 or (boxed and _boxed_way_refused(dense, nd, 1, other_legs, forbidden, origin_x, origin_z,
                                                           cell, foot_shape)):
                    continue
                counters[CNT_COUPLES_2D] += 1
                for t in range(N_FOOTPRINT_TERMS):
                    terms[t] = cand_terms[k, t]
                # 2D score: jerk at its best case (goodness 1), 2D length and climb (see module doc).
                trajectory_goodness(w, terms, d_ref[k], len2, curv, clear, climb2, 0.0)
                score2 = weighted_mean(w, terms, 0, N_TERMS)
                if mode != MODE_BRUTE_FORCE and score2 <= best_score:
                    continue
                len3, climb3, jerk = couple_metrics_3d(dense, nd, len2, source_y, target_y, step_height,
                                                       cfg[C_OBST_MARGIN], cell, poly, jerk_work)
                trajectory_goodness(w, terms, d_ref[k], len2, curv, clear, climb3, jerk)
                score3 = weighted_mean(w, terms, 0, N_TERMS)
                counters[CNT_COUPLES_3D] += 1
                evaluated_3d = True
                if first_found:
                    after_first += 1
                if score3 > best_score:
                    best_score = score3
                    best_k = k
                    best_s = s
                    best_n = nd
                    best_target_y = target_y
                    improved = True
                    for t in range(N_TERMS):
                        best_terms[t] = terms[t]
                    best_raw[RAW_LENGTH] = len2
                    best_raw[RAW_CURVATURE] = curv
                    best_raw[RAW_CLEARANCE] = clear
                    best_raw[RAW_CLIMB] = climb3
                    best_raw[RAW_JERK] = jerk
                    drawn = poly
                    if drawn_heights(dense, g_free, nd, source_y + ESCAPE_RISE * step_height, dense_drawn):
                        elevate_3d(dense_drawn, nd, len2, source_y, target_y, step_height, cfg[C_OBST_MARGIN], cell,
                                   poly_drawn)
                        drawn = poly_drawn
                    for i in range(nd):
                        best_poly[i, 0] = drawn[i, 0]
                        best_poly[i, 1] = drawn[i, 1]
                        best_poly[i, 2] = drawn[i, 2]
                first_found = True
                if mode != MODE_BRUTE_FORCE and couples_after_first >= 0 and after_first >= couples_after_first:
                    done = True
                    break
            if mode != MODE_BRUTE_FORCE and paper_early_stop and evaluated_3d and not improved:
                break

    trajectory = np.empty((k_out, 3), dtype=np.float64)
    target_rc = np.full(2, -1, dtype=np.int64)
    target_xyz = np.empty(3, dtype=np.float64)
    scores = np.zeros(3, dtype=np.float64)
    valid = best_k >= 0
    if valid:
        resample_by_arclength(best_poly, best_n, k_out, trajectory)
        # The chords between a boxed way's samples may cut a corner of its path across a leg.
        valid = not (boxed_pass and _boxed_way_refused(trajectory, k_out, 2, other_legs, forbidden, origin_x, origin_z,
                                                        cell, foot_shape))
    if valid:
        counters[CNT_BOXED] = boxed_pass
        target_rc[0] = cand_rc[best_k, 0]
        target_rc[1] = cand_rc[best_k, 1]
        target_xyz[0] = cand_xz[best_k, 0]
        target_xyz[1] = best_target_y
        target_xyz[2] = cand_xz[best_k, 1]
        scores[SCORE_COUPLE] = best_score
        scores[SCORE_FOOTPRINT] = cand_scores[best_k]
        scores[SCORE_TRAJECTORY] = weighted_mean(w, best_terms, N_FOOTPRINT_TERMS, N_TERMS)
        level = levels[best_s]
    else:
        # Defined fallback: the foot holds where it is.
        for i in range(k_out):
            trajectory[i, 0] = source_x
            trajectory[i, 1] = source_y
            trajectory[i, 2] = source_z
        target_xyz[0] = source_x
        target_xyz[1] = source_y
        target_xyz[2] = source_z
        level = np.nan
    return CoupleOut(valid, target_rc, target_xyz, best_s, level, scores, best_terms, best_raw, counters, trajectory,
                     cand_rc, cand_scores)


@nb.njit(cache=True)
def harvest_foot_kernel(elevation, ground, forbidden, origin_x, origin_z, foot_shape, source, preferred, hip, reach_xz,
                        step_height, other_legs, feet_block_radius, w, cfg, slice_size):
    """Every candidate couple of one foot (see the module docstring). Returns

    (cand_rc (n, 2), cand_xyz (n, 3) target points, cand_features (n, 5) FEAT_* order,
     cand_terms (n, 5), cand_scores (n,), levels (S,), d_ref (n,), couple_valid (n, S) bool,
     couple_raw (n, S, 5) RAW_* order, couple_terms (n, S, 10), couple_scores (n, S, 3)
     SCORE_* order)

    Candidates are in the search's order (descending footprint score), slices too, so
    the first maximum of ``couple_scores[..., SCORE_COUPLE]`` in row-major order is the
    couple the exhaustive search picks.
    """
    cell = cfg[C_CELL]
    eps = cfg[C_SLICE_EPS]
    source_x = source[0]
    source_y = source[1]
    source_z = source[2]
    grace = SOURCE_GRACE * feet_block_radius
    (code, elev_dil, boxh_dil, r0, c0, hp, wp, source_p, cand, cand_terms, cand_scores, cand_features, cand_rc, levels,
     d_ref, cand_xz, in_reach) = foot_setup(elevation, ground, forbidden, origin_x, origin_z, foot_shape, source,
                                            preferred, hip, reach_xz, other_legs, feet_block_radius, w, cfg,
                                            slice_size)
    n = hp * wp
    n_cand = cand.size
    n_slices = levels.size
    cand_xyz = np.empty((n_cand, 3), dtype=np.float64)
    for k in range(n_cand):
        cand_xyz[k, 0] = cand_xz[k, 0]
        cand_xyz[k, 1] = elev_dil[cand[k]]
        cand_xyz[k, 2] = cand_xz[k, 1]
    couple_valid = np.zeros((n_cand, n_slices), dtype=np.bool_)
    couple_raw = np.zeros((n_cand, n_slices, N_RAW), dtype=np.float64)
    couple_terms = np.zeros((n_cand, n_slices, N_TERMS), dtype=np.float64)
    couple_scores = np.zeros((n_cand, n_slices, 3), dtype=np.float64)
    passable = np.empty(n, dtype=np.uint8)
    factor = np.empty(n, dtype=np.float64)
    dt = np.empty(n, dtype=np.float64)
    dist = np.empty(n, dtype=np.float64)
    parent = np.empty(n, dtype=np.int64)
    stop = np.empty(max(n_cand, 1), dtype=np.int64)
    rows, cols, dense, dense_p, poly = path_workspace(hp, wp)
    g_free = np.empty(MAX_DENSE, dtype=np.float64)
    jerk_work = np.empty((JERK_SAMPLES, 3), dtype=np.float64)
    terms = np.empty(N_TERMS, dtype=np.float64)
    for s in range(n_slices):
        m = 0
        for q in range(n_cand):
            if boxh_dil[cand[q]] <= levels[s] + eps:
                stop[m] = cand[q]
                m += 1
        if m == 0:
            continue
        slice_maps(code, boxh_dil, levels[s], eps, source_p, in_reach, hp, wp, cell, cfg[C_POT_RANGE], cfg[C_POT_GAIN],
                   passable, factor, dt)
        wavefront(passable, factor, wp, source_p, cell, stop[:m], dist, parent)
        for k in range(n_cand):
            tp = cand[k]
            if boxh_dil[tp] > levels[s] + eps or not math.isfinite(dist[tp]):
                continue
            target_y = elev_dil[tp]
            nd, len2, curv, clear, climb2 = couple_metrics_2d(
                parent, passable, dt, elev_dil, code, source_p, tp, source_x, source_y, source_z, cand_xz[k, 0],
                target_y, cand_xz[k, 1], step_height, r0, c0, hp, wp, origin_x, origin_z, cell, dense, dense_p, g_free,
                rows, cols, other_legs, grace)
            if nd < 2:
                continue
            len3, climb3, jerk = couple_metrics_3d(dense, nd, len2, source_y, target_y, step_height,
                                                   cfg[C_OBST_MARGIN], cell, poly, jerk_work)
            for t in range(N_FOOTPRINT_TERMS):
                terms[t] = cand_terms[k, t]
            trajectory_goodness(w, terms, d_ref[k], len2, curv, clear, climb3, jerk)
            couple_valid[k, s] = True
            couple_raw[k, s, RAW_LENGTH] = len2
            couple_raw[k, s, RAW_CURVATURE] = curv
            couple_raw[k, s, RAW_CLEARANCE] = clear
            couple_raw[k, s, RAW_CLIMB] = climb3
            couple_raw[k, s, RAW_JERK] = jerk
            for t in range(N_TERMS):
                couple_terms[k, s, t] = terms[t]
            couple_scores[k, s, SCORE_COUPLE] = weighted_mean(w, terms, 0, N_TERMS)
            couple_scores[k, s, SCORE_FOOTPRINT] = cand_scores[k]
            couple_scores[k, s, SCORE_TRAJECTORY] = weighted_mean(w, terms, N_FOOTPRINT_TERMS, N_TERMS)
    return (cand_rc, cand_xyz, cand_features, cand_terms, cand_scores, levels, d_ref, couple_valid, couple_raw,
            couple_terms, couple_scores)
