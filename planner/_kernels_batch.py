"""numba kernel: plan many feet in one call (the crowd runtime's planning stage).

All inputs are struct-of-arrays over feet; the characters' local maps are stacked.
Each foot carries its own budget (the LOD of its character, paper §6).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from planner._kernels_geometry import foot_offsets
from planner._kernels_search import plan_foot_kernel
from planner._params import C_CELL


@nb.njit(cache=True)
def plan_one_into(i, elevation, ground, forbidden, origins, foot_char, foot_shape, sources, preferred, hips, reach_xz,
                  step_height, legs, legs_start, block_radius, w, cfg, couples_after_first, slice_size, early, mode,
                  out_valid, out_target, out_slice, out_level, out_scores, out_terms, out_raw, out_counters, out_traj):
    ch = foot_char[i]
    offsets = foot_offsets(foot_shape[i, 0], foot_shape[i, 1], foot_shape[i, 2], cfg[C_CELL])
    res = plan_foot_kernel(elevation[ch], ground[ch], forbidden[ch], origins[ch, 0], origins[ch, 1], offsets,
                           sources[i], preferred[i], hips[i], reach_xz[i], step_height[i],
                           legs[legs_start[i]:legs_start[i + 1]], block_radius[i], w, cfg, couples_after_first[i],
                           slice_size[i], early[i], mode)
    out_valid[i] = res.valid
    out_target[i, :] = res.target_xyz
    out_slice[i] = res.slice_index
    out_level[i] = res.slice_level
    out_scores[i, :] = res.scores
    out_terms[i, :] = res.terms
    out_raw[i, :] = res.raw
    out_counters[i, :] = res.counters
    out_traj[i, :, :] = res.trajectory


@nb.njit(cache=True)
def plan_feet_serial(elevation, ground, forbidden, origins, foot_char, foot_shape, sources, preferred, hips, reach_xz,
                     step_height, legs, legs_start, block_radius, w, cfg, couples_after_first, slice_size, early, mode,
                     out_valid, out_target, out_slice, out_level, out_scores, out_terms, out_raw, out_counters,
                     out_traj):
    for i in range(foot_char.size):
        plan_one_into(i, elevation, ground, forbidden, origins, foot_char, foot_shape, sources, preferred, hips,
                      reach_xz, step_height, legs, legs_start, block_radius, w, cfg, couples_after_first, slice_size,
                      early, mode, out_valid, out_target, out_slice, out_level, out_scores, out_terms, out_raw,
                      out_counters, out_traj)


@nb.njit(cache=True, parallel=True)
def plan_feet_parallel(elevation, ground, forbidden, origins, foot_char, foot_shape, sources, preferred, hips,
                       reach_xz, step_height, legs, legs_start, block_radius, w, cfg, couples_after_first, slice_size,
                       early, mode, out_valid, out_target, out_slice, out_level, out_scores, out_terms, out_raw,
                       out_counters, out_traj):
    """Same as :func:`plan_feet_serial`, feet spread over the cores (results identical)."""
    for k in nb.prange(foot_char.size):
        i = np.int64(k)  # prange indices are unsigned: a signed index avoids compiling plan_one_into twice
        plan_one_into(i, elevation, ground, forbidden, origins, foot_char, foot_shape, sources, preferred, hips,
                      reach_xz, step_height, legs, legs_start, block_radius, w, cfg, couples_after_first, slice_size,
                      early, mode, out_valid, out_target, out_slice, out_level, out_scores, out_terms, out_raw,
                      out_counters, out_traj)
