"""numba kernel: plan many feet in one call (the crowd runtime's planning stage).

All inputs are struct-of-arrays over feet, packed in a :data:`FootRequests` named tuple; the
characters' local maps are stacked. Each foot carries its own budget (the LOD of its character,
paper §6). The results go into the arrays of a :data:`FootResults` named tuple, row i for foot i.
"""

from __future__ import annotations

from collections import namedtuple

import numba as nb
import numpy as np

from footfall.planner._kernels_search import plan_foot_kernel

FootRequests = namedtuple("FootRequests", [
    "elevation", "ground", "forbidden", "origins",  # the characters' stacked local maps (C, N, N), origins (C, 2)
    "foot_char", "foot_shape", "sources", "preferred", "hips", "reach_xz", "step_height",  # per foot
    "legs", "legs_start", "block_radius",  # each foot's other legs (CSR) and the room it keeps from other feet
    "couples_after_first", "slice_size", "early",  # each foot's search budget
])
"""The planning requests of a batch, as the kernel reads them (``planner._batch.FootBatch`` fields)."""

FootResults = namedtuple("FootResults", [
    "valid", "target", "slice_index", "slice_level", "scores", "terms", "raw", "counters", "trajectory"])
"""The arrays the kernel writes its results into (``planner._batch.BatchResult`` fields)."""


@nb.njit(cache=True)
def plan_one_into(i, req, w, cfg, mode, out):
    """Plan foot ``i`` of ``req`` (:data:`FootRequests`) into row ``i`` of ``out`` (:data:`FootResults`)."""
    ch = req.foot_char[i]
    res = plan_foot_kernel(req.elevation[ch], req.ground[ch], req.forbidden[ch], req.origins[ch, 0],
                           req.origins[ch, 1], req.foot_shape[i], req.sources[i], req.preferred[i], req.hips[i], req.reach_xz[i],
                           req.step_height[i], req.legs[req.legs_start[i]:req.legs_start[i + 1]], req.block_radius[i], w,
                           cfg, req.couples_after_first[i], req.slice_size[i], req.early[i], mode)
    out.valid[i] = res.valid
    out.target[i, :] = res.target_xyz
    out.slice_index[i] = res.slice_index
    out.slice_level[i] = res.slice_level
    out.scores[i, :] = res.scores
    out.terms[i, :] = res.terms
    out.raw[i, :] = res.raw
    out.counters[i, :] = res.counters
    out.trajectory[i, :, :] = res.trajectory


@nb.njit(cache=True)
def plan_feet_serial(req, w, cfg, mode, out):
    """Plan every foot of ``req`` (:data:`FootRequests`) into ``out`` (:data:`FootResults`), in order."""
    for i in range(req.foot_char.size):
        plan_one_into(i, req, w, cfg, mode, out)


@nb.njit(cache=True, parallel=True)
def plan_feet_parallel(req, w, cfg, mode, out):
    """Same as :func:`plan_feet_serial`, feet spread over the cores (results identical)."""
    for k in nb.prange(req.foot_char.size):
        i = np.int64(k)  # prange indices are unsigned: a signed index avoids compiling plan_one_into twice
        plan_one_into(i, req, w, cfg, mode, out)
