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

from footfall.planner._kernels_geometry import rasterise_boxes, rect_overlaps_aabb
from footfall.planner.layout import FORBIDDEN_MOVING, FORBIDDEN_STATIC


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
                out_forb[r, c] = FORBIDDEN_STATIC
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
        rasterise_boxes(out_elev, out_forb, ox, oz, cell, box_centres, box_sizes, box_yaws, box_forbidden, selected,
                        FORBIDDEN_MOVING)
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


@nb.njit(cache=True)
def _stamp_rect(forb, ox, oz, cell, cx, cz, hx, hz, yaw):
    n_rows, n_cols = forb.shape
    ex = hx * abs(math.cos(yaw)) + hz * abs(math.sin(yaw))
    ez = hx * abs(math.sin(yaw)) + hz * abs(math.cos(yaw))
    c0 = max(0, int(math.floor((cx - ex - ox) / cell)))
    c1 = min(n_cols - 1, int(math.floor((cx + ex - ox) / cell)))
    r0 = max(0, int(math.floor((cz - ez - oz) / cell)))
    r1 = min(n_rows - 1, int(math.floor((cz + ez - oz) / cell)))
    for r in range(r0, r1 + 1):
        az = oz + (r + 0.5) * cell
        for c in range(c0, c1 + 1):
            ax = ox + (c + 0.5) * cell
            if rect_overlaps_aabb(cx, cz, hx, hz, yaw, ax, az, 0.5 * cell, 0.5 * cell):
                forb[r, c] = FORBIDDEN_STATIC


@nb.njit(cache=True, parallel=True)
def stamp_other_characters(out_forb, out_origin, cell, neighbour_start, neighbour_index, pelvis_xz, headings,
                           body_half_length, body_half_width, feet_xz, in_stance, foot_half):
    """Flag, in map k, the projected bodies and the feet (those with ``in_stance``) of the characters listed in
    ``neighbour_index[neighbour_start[k]:neighbour_start[k + 1]]`` as forbidden (issue 14: a foot
    never lands on another's foot or inside another's body; swing paths go around them)."""
    for k in nb.prange(out_forb.shape[0]):
        ox = out_origin[k, 0]
        oz = out_origin[k, 1]
        for a in range(neighbour_start[k], neighbour_start[k + 1]):
            j = neighbour_index[a]
            _stamp_rect(out_forb[k], ox, oz, cell, pelvis_xz[j, 0], pelvis_xz[j, 1], body_half_length,
                        body_half_width, headings[j])
            for i in range(feet_xz.shape[1]):
                if in_stance[j, i]:
                    _stamp_rect(out_forb[k], ox, oz, cell, feet_xz[j, i, 0], feet_xz[j, i, 1], foot_half, foot_half,
                                0.0)
