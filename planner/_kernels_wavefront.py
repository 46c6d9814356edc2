"""numba kernels: chamfer distance transform and the 8-connected wavefront.

Both work on *padded flat* grids: a (H+2) x (W+2) array flattened row-major,
whose outer ring is never passable, so neighbour offsets need no bounds checks
(the flat offsets are precomputed once, as in scikit-image's MCP).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

SQRT2 = math.sqrt(2.0)


@nb.njit(cache=True)
def neighbour_offsets(wp):
    """Flat offsets, row steps, column steps and lengths (cells) of the 8 neighbours."""
    dr = np.array([-1, -1, -1, 0, 0, 1, 1, 1], dtype=np.int64)
    dc = np.array([-1, 0, 1, -1, 1, -1, 0, 1], dtype=np.int64)
    flat = dr * wp + dc
    length = np.empty(8, dtype=np.float64)
    for k in range(8):
        length[k] = SQRT2 if (dr[k] != 0 and dc[k] != 0) else 1.0
    return flat, dr, dc, length


@nb.njit(cache=True)
def chamfer_distance(seed, inside, hp, wp, cell, out):
    """Distance (m) from each cell centre to the nearest seed cell centre.

    Two-pass chamfer transform with weights 1 and sqrt(2) (exact along rows, columns
    and diagonals). ``seed`` and ``inside`` are flat uint8 masks; cells outside
    ``inside`` are neither seeds nor updated (their distance stays inf).
    """
    inf = np.inf
    n = hp * wp
    for p in range(n):
        out[p] = 0.0 if (seed[p] and inside[p]) else inf
    for r in range(1, hp - 1):
        for c in range(1, wp - 1):
            p = r * wp + c
            if not inside[p] or out[p] == 0.0:
                continue
            d = out[p]
            d = min(d, out[p - 1] + 1.0, out[p - wp] + 1.0)
            d = min(d, out[p - wp - 1] + SQRT2, out[p - wp + 1] + SQRT2)
            out[p] = d
    for r in range(hp - 2, 0, -1):
        for c in range(wp - 2, 0, -1):
            p = r * wp + c
            if not inside[p] or out[p] == 0.0:
                continue
            d = out[p]
            d = min(d, out[p + 1] + 1.0, out[p + wp] + 1.0)
            d = min(d, out[p + wp + 1] + SQRT2, out[p + wp - 1] + SQRT2)
            out[p] = d
    for p in range(n):
        out[p] *= cell


@nb.njit(cache=True)
def _heap_push(keys, items, size, key, item):
    i = size
    keys[i] = key
    items[i] = item
    while i > 0:
        parent = (i - 1) >> 1
        if keys[parent] <= keys[i]:
            break
        keys[parent], keys[i] = keys[i], keys[parent]
        items[parent], items[i] = items[i], items[parent]
        i = parent
    return size + 1


@nb.njit(cache=True)
def _heap_pop(keys, items, size):
    key = keys[0]
    item = items[0]
    size -= 1
    keys[0] = keys[size]
    items[0] = items[size]
    i = 0
    while True:
        left = 2 * i + 1
        if left >= size:
            break
        child = left
        if left + 1 < size and keys[left + 1] < keys[left]:
            child = left + 1
        if keys[i] <= keys[child]:
            break
        keys[child], keys[i] = keys[i], keys[child]
        items[child], items[i] = items[i], items[child]
        i = child
    return key, item, size


@nb.njit(cache=True)
def wavefront(passable, cost_factor, wp, source, cell, stop_cells, dist, parent):
    """Single-source wavefront (Dijkstra) over an 8-connected padded grid.

    A move from cell a to neighbour b costs ``cell * length * cost_factor[b]``
    (length 1 or sqrt 2; ``cost_factor`` carries the potential field). A diagonal
    move needs both cells it passes between to be passable (no corner cutting), so
    the straight segment between the two centres stays in passable cells. The
    source is expanded even if it is not passable (a foot may stand on a cell that
    became blocked). A stop cell that is not passable is a goal only: it is reached
    (orthogonally, or diagonally between passable cells) but never expanded, so no path
    passes through it (a footprint next to another leg, planner._kernels_foot). Stops as
    soon as every cell of ``stop_cells`` is settled (or nothing is left to expand).
    Returns the number of cells expanded.

    ``dist`` (inf = not reached) and ``parent`` (-1 = none) are filled in place.
    """
    n = passable.size
    for p in range(n):
        dist[p] = np.inf
        parent[p] = -1
    settled = np.zeros(n, dtype=np.uint8)
    is_stop = np.zeros(n, dtype=np.uint8)
    remaining = 0
    for k in range(stop_cells.size):
        q = stop_cells[k]
        if is_stop[q] == 0:
            is_stop[q] = 1
            remaining += 1
    flat, dr, dc, length = neighbour_offsets(wp)
    capacity = 8 * n + 1
    keys = np.empty(capacity, dtype=np.float64)
    items = np.empty(capacity, dtype=np.int64)
    size = 0
    dist[source] = 0.0
    size = _heap_push(keys, items, size, 0.0, source)
    expanded = 0
    while size > 0 and remaining > 0:
        d, p, size = _heap_pop(keys, items, size)
        if settled[p] or d > dist[p]:
            continue
        settled[p] = 1
        expanded += 1
        if is_stop[p]:
            remaining -= 1
            if remaining == 0:
                break
        if not passable[p] and p != source:
            continue  # a goal-only cell
        for k in range(8):
            q = p + flat[k]
            if (not passable[q] and not is_stop[q]) or settled[q]:
                continue
            if dr[k] != 0 and dc[k] != 0:
                if not passable[p + dr[k] * wp] or not passable[p + dc[k]]:
                    continue
            nd = d + cell * length[k] * cost_factor[q]
            if nd < dist[q]:
                dist[q] = nd
                parent[q] = p
                size = _heap_push(keys, items, size, nd, q)
    return expanded


@nb.njit(cache=True)
def per_target_wavefronts(passable, factor, wp, source, cell, cands, dist, parent):
    """One wavefront per candidate, each stopping at its target (the baseline the shared
    wavefront is benchmarked against). Returns the cells expanded."""
    one = np.empty(1, dtype=np.int64)
    expanded = 0
    for k in range(cands.size):
        one[0] = cands[k]
        expanded += wavefront(passable, factor, wp, source, cell, one, dist, parent)
    return expanded
