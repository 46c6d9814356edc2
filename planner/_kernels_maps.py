"""numba kernel: the local maps of many characters in one call (maps preparation).

Each character's maps are a window of the static world raster (so static objects
cost nothing per frame, paper §4: "we pre-compute the map's representation of
static objects") with the moving boxes whose bounding circle reaches the window
voxelised on top at the current time.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from planner._kernels_geometry import rasterise_boxes


@nb.njit(cache=True)
def _window(ground, static_top, static_forbidden, g_origin_x, g_origin_z, cell, cx, cz, out_elev, out_ground,
            out_forb, box_centres, box_sizes, box_yaws, box_forbidden, box_moving, selected):
    n = out_elev.shape[0]
    n_rows, n_cols = ground.shape
    half = n // 2
    gc0 = int(math.floor((cx - g_origin_x) / cell)) - half
    gr0 = int(math.floor((cz - g_origin_z) / cell)) - half
    for r in range(n):
        gr = gr0 + r
        grc = min(n_rows - 1, max(0, gr))
        for c in range(n):
            gc = gc0 + c
            gcc = min(n_cols - 1, max(0, gc))
            out_ground[r, c] = ground[grc, gcc]
            out_elev[r, c] = static_top[grc, gcc]
            if gr < 0 or gr >= n_rows or gc < 0 or gc >= n_cols:
                out_forb[r, c] = 1
            else:
                out_forb[r, c] = static_forbidden[grc, gcc]
    ox = g_origin_x + gc0 * cell
    oz = g_origin_z + gr0 * cell
    wx = ox + 0.5 * n * cell
    wz = oz + 0.5 * n * cell
    any_near = False
    for i in range(box_centres.shape[0]):
        selected[i] = False
        if not box_moving[i]:
            continue
        r_box = 0.5 * math.hypot(box_sizes[i, 0], box_sizes[i, 2])
        if math.hypot(box_centres[i, 0] - wx, box_centres[i, 2] - wz) <= r_box + 0.75 * n * cell:
            selected[i] = True
            any_near = True
    if any_near:
        rasterise_boxes(out_elev, out_forb, ox, oz, cell, box_centres, box_sizes, box_yaws, box_forbidden, selected)
    return ox, oz


@nb.njit(cache=True, parallel=True)
def build_local_maps(ground, static_top, static_forbidden, g_origin_x, g_origin_z, cell, centres, box_centres,
                     box_sizes, box_yaws, box_forbidden, box_moving, out_elev, out_ground, out_forb, out_origin):
    """Fill ``out_*[k]`` with the maps centred on ``centres[k]`` (world x, z)."""
    for k in nb.prange(centres.shape[0]):
        selected = np.zeros(box_centres.shape[0], dtype=np.bool_)
        ox, oz = _window(ground, static_top, static_forbidden, g_origin_x, g_origin_z, cell, centres[k, 0],
                         centres[k, 1], out_elev[k], out_ground[k], out_forb[k], box_centres, box_sizes, box_yaws,
                         box_forbidden, box_moving, selected)
        out_origin[k, 0] = ox
        out_origin[k, 1] = oz
