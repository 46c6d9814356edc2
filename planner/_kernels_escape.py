"""The look-ahead of a way out of a moving box's lane, as one numba kernel (the rule and why:
:mod:`planner._escape`).

Per character r and candidate heading k, on the ground plane (x, z): the body starts at
``pelvis_xz[r]`` with ``heading[r]`` and ``speed[r]``. Every ``step`` seconds, T times, its heading
turns toward ``targets[r, k]`` by at most ``turn_step``, its speed moves toward ``pace[r]`` x the
cosine of the turn still to make (0 beyond a quarter turn) by at most ``accel_step``, and it walks
that far along its heading. After step j the pelvis is compared with every box where
``box_paths[j]`` puts it:

* the depth by which it is nearer than ``reach`` to the box's rectangle, the deepest box, weighted by
  ``1 - (j + 1) / (T + 1)``, adds to the way's cost;
* inside a box's rectangle, the walk ends there: every step left costs the full ``reach`` (no body
  walks through a box);
* after the last step, a body still in the lane of a moving box it could have come within reach of
  (within ``reach`` of the box's swept rectangle, across its travel) and not behind the box adds
  ``lane_cost``: running before a box is no way out of its lane.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from footfall.planner._kernels_geometry import wrap_pi


@nb.njit(cache=True)
def _box_gap(px, pz, cx, cz, hx, hz, cos_yaw, sin_yaw):
    """Distance on the ground from (px, pz) to a box's rectangle (0 inside)."""
    rx = px - cx
    rz = pz - cz
    along = abs(rx * cos_yaw + rz * sin_yaw) - hx
    across = abs(-rx * sin_yaw + rz * cos_yaw) - hz
    return math.hypot(max(along, 0.0), max(across, 0.0))


@nb.njit(cache=True)
def _in_lane(px, pz, box_paths, b, half, cos_yaw, sin_yaw, step, reach):
    """Whether (px, pz) is in box b's lane, not behind it, after the last step (its travel: the last step's)."""
    last = box_paths.shape[0] - 1
    ux = box_paths[last, b, 0] - box_paths[last - 1, b, 0]
    uz = box_paths[last, b, 1] - box_paths[last - 1, b, 1]
    moved = math.hypot(ux, uz)
    if moved < 1e-6 * step:
        return False
    ux /= moved
    uz /= moved
    # How far the box reaches along and across its travel (its yawed half extents projected).
    along_reach = half[b, 0] * abs(cos_yaw[b] * ux + sin_yaw[b] * uz) + half[b, 1] * abs(-sin_yaw[b] * ux + cos_yaw[b] * uz)
    across_reach = half[b, 0] * abs(-cos_yaw[b] * uz + sin_yaw[b] * ux) + half[b, 1] * abs(sin_yaw[b] * uz + cos_yaw[b] * ux)
    rx = px - box_paths[last, b, 0]
    rz = pz - box_paths[last, b, 1]
    along = rx * ux + rz * uz
    across = -rx * uz + rz * ux
    return abs(across) < across_reach + reach and along > -(along_reach + reach)


@nb.njit(cache=True, parallel=True)
def escape_costs(pelvis_xz, heading, speed, pace, targets, turn_step, accel_step, step, reach, box_paths, half,
                 cos_yaw, sin_yaw, lane_cost, out):
    """Fill ``out`` (R, K) with each candidate heading's cost (module doc). ``box_paths`` (T, B, 2):
    box centres after each of the T steps; ``half`` (B, 2) half extents along the boxes' axes."""
    n_rows, n_ways = targets.shape
    n_steps, n_boxes = box_paths.shape[0], box_paths.shape[1]
    for r in nb.prange(n_rows):
        # Only the boxes this body could come within reach of (it walks at most this fast).
        fastest = max(pace[r], speed[r])
        near = np.zeros(n_boxes, np.bool_)
        for b in range(n_boxes):
            size = math.hypot(half[b, 0], half[b, 1])
            for j in range(n_steps):
                gap = math.hypot(box_paths[j, b, 0] - pelvis_xz[r, 0], box_paths[j, b, 1] - pelvis_xz[r, 1])
                if gap - size - fastest * (j + 1) * step < reach:
                    near[b] = True
                    break
        boxes = np.flatnonzero(near)
        for k in range(n_ways):
            h = heading[r]
            v = speed[r]
            px = pelvis_xz[r, 0]
            pz = pelvis_xz[r, 1]
            cost = 0.0
            blocked = False
            for j in range(n_steps):
                left = wrap_pi(targets[r, k] - h)
                h += min(max(left, -turn_step), turn_step)
                left = wrap_pi(targets[r, k] - h)
                wanted = pace[r] * max(math.cos(min(max(left, -0.5 * math.pi), 0.5 * math.pi)), 0.0)
                v += min(max(wanted - v, -accel_step), accel_step)
                px += v * math.cos(h) * step
                pz += v * math.sin(h) * step
                depth = 0.0
                for b in boxes:
                    d = reach - _box_gap(px, pz, box_paths[j, b, 0], box_paths[j, b, 1], half[b, 0], half[b, 1],
                                         cos_yaw[b], sin_yaw[b])
                    if d > depth:
                        depth = d
                if depth >= reach:
                    for i in range(j, n_steps):
                        cost += reach * (1.0 - (i + 1) / (n_steps + 1.0))
                    blocked = True
                    break
                cost += depth * (1.0 - (j + 1) / (n_steps + 1.0))
            if not blocked and lane_cost > 0.0 and n_steps > 1:
                for b in boxes:
                    if _in_lane(px, pz, box_paths, b, half, cos_yaw, sin_yaw, step, reach):
                        cost += lane_cost
                        break
            out[r, k] = cost
