"""numba kernel: the best footprint-trajectory couple for one foot (paper §5.2, §6).

Couple score
    weighted mean of the five footprint goodnesses and the five trajectory
    goodnesses (see :mod:`planner._weights`). The 2D score of a couple replaces the
    3D-only quantities by their best case (jerk goodness 1) and uses the 2D path
    length and the elevations under the path for the climb, so for every couple
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

``MODE_PER_TARGET`` is the same search with one wavefront per (target, slice)
(for benchmarks); ``MODE_BRUTE_FORCE`` scores every (target, slice) couple in
3D with no pruning (the reference the tests compare the search with).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from planner._grid import cell_centre, cell_of
from planner._kernels_foot import (
    CNT_CANDIDATES,
    CNT_COUPLES_2D,
    CNT_COUPLES_3D,
    CNT_EXPANDED,
    CNT_SLICES,
    CNT_WAVEFRONTS,
    JERK_SAMPLES,
    MAX_DENSE,
    N_COUNTERS,
    N_RAW,
    RAW_CLEARANCE,
    RAW_CLIMB,
    RAW_CURVATURE,
    RAW_JERK,
    RAW_LENGTH,
    elevate_3d,
    footprint_candidates,
    geometric_jerk,
    naive_and_kept_points,
    path_2d,
    path_length_3d,
    prepare_foot,
    resample_by_arclength,
    slice_levels,
    slice_maps,
    weighted_mean,
)
from planner._kernels_wavefront import wavefront
from planner._params import C_CELL, C_MARGIN, C_OBST_MARGIN, C_POT_GAIN, C_POT_RANGE, C_RADIUS, C_SAMPLES, C_SLICE_EPS
from planner._weights import N_FOOTPRINT_TERMS, N_TERMS, W_CLEARANCE_REF, W_CLIMB_REF, W_CURVATURE_REF, W_JERK_REF

MODE_SEARCH = 0
MODE_PER_TARGET = 1
MODE_BRUTE_FORCE = 2

SCORE_COUPLE, SCORE_FOOTPRINT, SCORE_TRAJECTORY = range(3)


@nb.njit(cache=True)
def _trajectory_terms(w, terms, d_ref, length, curvature, clearance, climb, jerk):
    terms[N_FOOTPRINT_TERMS + 0] = d_ref / max(length, d_ref)
    terms[N_FOOTPRINT_TERMS + 1] = 1.0 / (1.0 + curvature / w[W_CURVATURE_REF])
    terms[N_FOOTPRINT_TERMS + 2] = min(1.0, clearance / w[W_CLEARANCE_REF])
    terms[N_FOOTPRINT_TERMS + 3] = 1.0 / (1.0 + climb / w[W_CLIMB_REF])
    terms[N_FOOTPRINT_TERMS + 4] = 1.0 / (1.0 + jerk / w[W_JERK_REF])
    return weighted_mean(w, terms, 0, N_TERMS)


@nb.njit(cache=True)
def plan_foot_kernel(elevation, ground, forbidden, origin_x, origin_z, offsets, source, preferred, hip, reach_xz,
                     step_height, other_legs, feet_block_radius, w, cfg, couples_after_first, slice_size,
                     paper_early_stop, mode):
    """Plan one foot. See the module docstring; returns a tuple of result arrays:

    (valid, target_rc (2,), target_xyz (3,), slice_index, slice_level, scores (3,),
     terms (10,), raw (5,), counters (6,), trajectory (K, 3), candidate_rc (n, 2),
     candidate_scores (n,))
    """
    cell = cfg[C_CELL]
    radius = cfg[C_RADIUS]
    eps = cfg[C_SLICE_EPS]
    k_out = int(cfg[C_SAMPLES])
    source_x = source[0]
    source_y = source[1]
    source_z = source[2]
    pref_x = preferred[0]
    pref_z = preferred[1]
    counters = np.zeros(N_COUNTERS, dtype=np.int64)
    code, elev_dil, boxh_dil, elev_raw, r0, c0, hp, wp = prepare_foot(
        elevation, ground, forbidden, origin_x, origin_z, cell, offsets, source_x, source_z, pref_x, pref_z, radius,
        int(cfg[C_MARGIN]), other_legs, feet_block_radius)
    n = hp * wp
    sr, sc = cell_of(source_x, source_z, origin_x, origin_z, cell)
    source_p = (sr - r0 + 1) * wp + (sc - c0 + 1)
    cand, cand_terms, cand_scores = footprint_candidates(
        code, elev_dil, elev_raw, r0, c0, hp, wp, origin_x, origin_z, cell, source_p, pref_x, pref_z, radius,
        hip[0], hip[1], reach_xz, other_legs, w)
    n_cand = cand.size
    counters[CNT_CANDIDATES] = n_cand
    cand_rc = np.empty((n_cand, 2), dtype=np.int64)
    for k in range(n_cand):
        rr = cand[k] // wp
        cand_rc[k, 0] = r0 - 1 + rr
        cand_rc[k, 1] = c0 - 1 + (cand[k] - rr * wp)
    levels = slice_levels(code, boxh_dil, slice_size, eps)
    n_slices = levels.size
    counters[CNT_SLICES] = n_slices

    # Exact bound: a candidate's couple score cannot exceed its footprint part plus
    # perfect trajectory goodnesses (length bounded by the straight-line distance).
    d_ref = max(math.hypot(pref_x - source_x, pref_z - source_z), cell)
    w_all = 0.0
    for k in range(N_TERMS):
        w_all += w[k]
    suffix_ub = np.empty(n_cand + 1, dtype=np.float64)
    suffix_ub[n_cand] = -np.inf
    tb = np.empty(N_TERMS, dtype=np.float64)
    for k in range(n_cand - 1, -1, -1):
        for t in range(N_FOOTPRINT_TERMS):
            tb[t] = cand_terms[k, t]
        x, z = cell_centre(cand_rc[k, 0], cand_rc[k, 1], origin_x, origin_z, cell)
        straight = math.hypot(x - source_x, z - source_z)
        for t in range(N_FOOTPRINT_TERMS, N_TERMS):
            tb[t] = 1.0
        tb[N_FOOTPRINT_TERMS] = d_ref / max(straight, d_ref)
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
    cap = 4 * (hp + wp) + 8
    rows = np.empty(cap, dtype=np.int64)
    cols = np.empty(cap, dtype=np.int64)
    dense = np.empty((MAX_DENSE, 3), dtype=np.float64)
    dense_p = np.empty(MAX_DENSE, dtype=np.int64)
    poly = np.empty((MAX_DENSE, 3), dtype=np.float64)
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

    for k in range(n_cand):
        if done:
            break
        if mode != MODE_BRUTE_FORCE and best_k >= 0 and suffix_ub[k] <= best_score:
            break
        tp = cand[k]
        target_y = elev_dil[tp]
        tx, tz = cell_centre(cand_rc[k, 0], cand_rc[k, 1], origin_x, origin_z, cell)
        evaluated_3d = False
        improved = False
        for s in range(n_slices):
            if boxh_dil[tp] > levels[s] + eps:
                continue  # the target itself is above this slice: not reachable in it
            if not ready[s]:
                slice_maps(code, boxh_dil, levels[s], eps, source_p, hp, wp, cell, cfg[C_POT_RANGE], cfg[C_POT_GAIN],
                           passable[s], factor[s], dt[s])
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
            kept = naive_and_kept_points(parent[s], source_p, tp, source_x, source_z, passable[s], r0, c0, hp, wp,
                                         origin_x, origin_z, cell, rows, cols)
            nd, len2, curv, clear = path_2d(kept, passable[s], dt[s], elev_dil, source_p, r0, c0, hp, wp, origin_x,
                                            origin_z, cell, dense, dense_p, rows, cols)
            if nd < 2:
                continue
            counters[CNT_COUPLES_2D] += 1
            for t in range(N_FOOTPRINT_TERMS):
                terms[t] = cand_terms[k, t]
            ground_top = -np.inf
            for i in range(1, nd - 1):
                ground_top = max(ground_top, dense[i, 2])
            base = max(source_y, target_y) + step_height
            climb2 = max(0.0, ground_top - base)
            score2 = _trajectory_terms(w, terms, d_ref, len2, curv, clear, climb2, 0.0)
            if mode != MODE_BRUTE_FORCE and score2 <= best_score:
                continue
            top = elevate_3d(dense, nd, len2, source_y, target_y, step_height, cfg[C_OBST_MARGIN], cell, poly)
            len3 = path_length_3d(poly, nd)
            climb3 = max(0.0, top - base)
            jerk = geometric_jerk(poly, nd, jerk_work)
            score3 = _trajectory_terms(w, terms, d_ref, len3, curv, clear, climb3, jerk)
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
                best_raw[RAW_LENGTH] = len3
                best_raw[RAW_CURVATURE] = curv
                best_raw[RAW_CLEARANCE] = clear
                best_raw[RAW_CLIMB] = climb3
                best_raw[RAW_JERK] = jerk
                for i in range(nd):
                    best_poly[i, 0] = poly[i, 0]
                    best_poly[i, 1] = poly[i, 1]
                    best_poly[i, 2] = poly[i, 2]
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
        target_rc[0] = cand_rc[best_k, 0]
        target_rc[1] = cand_rc[best_k, 1]
        tx, tz = cell_centre(target_rc[0], target_rc[1], origin_x, origin_z, cell)
        target_xyz[0] = tx
        target_xyz[1] = best_target_y
        target_xyz[2] = tz
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
    return (valid, target_rc, target_xyz, best_s, level, scores, best_terms, best_raw, counters, trajectory, cand_rc,
            cand_scores)
