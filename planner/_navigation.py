"""The way round static boxes: steering's global part (a visibility graph).

ORCA (:mod:`planner._kernels_avoidance`) is local: it finds the velocity nearest the preferred one
that stays clear for its horizon. A character whose goal lies straight behind a forbidden crate
prefers a velocity into the crate, and ORCA's nearest admissible one slides along the crate's face
at a few cm/s: in the crowds issue's bar set (``footfall evaluate --seeds 10 --seed-base 3000
--characters 6 --frames 300``) every stuck character-second was such a character (quadrupeds on
``mixed``: 42 s, spiders on ``crates``: 30 s).

So with ``ControllerConfig.navigate`` (on by default; docs/crowds.md, the section on the way round static
boxes has what it gains and costs) steering aims at the first corner of the shortest way round the boxes, and at
the route's point itself whenever nothing is in the way. The boxes are the static ones, safe ones
included: a character walks round a crate where the way round is free, and over a safe one only when
none is (led over safe crates beside the forbidden ones it went round, robot5's legs could not follow
its body onto them: 311 foot-frames in crates over the bar set's 10 robot5 runs on ``crates-moving``,
0 with them in the graph). Each is grown by the character's clearance (its avoid radius and a
margin) into a rectangle its centre must not enter; the way is
the shortest polyline from the character to its route point through the grown rectangles' corners
(Lozano-Perez and Wesley's visibility graph: among convex obstacles the shortest path bends only at
their corners). A box that loops along waypoints is a fixed region to the way: the bounding box of
its loop grown by half its diagonal (``planner._crowd.static_way_around``). With static boxes only,
spiders on ``mixed`` were led round static crates into the loops of moving ones: over 18 runs of 8
spiders x 600 frames (seeds 1100-1111, 1200-1205) feet in boxes went 233 -> 384 and stuck time
stayed 187 s; with the loops' regions, 0 feet in boxes, 3 crossing frames (54 before), 10 s stuck.
Boxes moving at a constant velocity cross the world; the lane exit and ORCA, which look ahead along
their paths, keep out of their way.

Rules that keep the graph well defined:

* a corner inside another grown rectangle is no node (two boxes nearer than the clearance make one
  wall);
* a segment is blocked by the open interior of a grown rectangle: it may touch a corner or run along
  an edge (nodes sit :data:`NODE_EPS` outside their corners, so edges between them stay outside);
* a rectangle that contains the character (it stands closer to a box than the clearance) or the
  route point blocks the segments from it (or to it) only where they come nearer the box than ORCA's
  disc, or than it is if that is nearer: the way out of it and along it is open, a way ORCA would
  refuse is not; a box that contains it (a route point in a looping box's region) does not block
  them;
* with no way at all (the route point walled in), the aim is the route point (ORCA as before).

The node-to-node visibility is computed once per crowd (:func:`way_around`); per frame, a character
whose straight segment is clear costs one test per box, a blocked one a Dijkstra over the nodes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

NODE_EPS = 1e-6
"""m: how far outside its grown corner a node sits (edges between two nodes of one rectangle then run
outside it, whatever the rounding)."""
REFRESH_FRAMES = 4
"""Frames between two searches of one blocked character's way (staggered over the characters): searched
every frame, the ways of 1000 spiders on ``mixed`` (static boxes only) cost 6.4 ms a frame, 1.8 ms so."""
REACHED = 0.1
"""x the way's clearance: a corner this near is reached, and the way is searched again from there."""
CLEARANCE_FACTOR = 1.2
"""x avoid radius: how far the way keeps a character's centre from a forbidden box. ORCA keeps the
avoid disc itself clear; at exactly that distance its half-plane of the box's nearest point refused
part of the way along the face."""


@dataclass(frozen=True)
class WayAround:
    """The grown static boxes and their visibility graph.

    Attributes
    ----------
    centres : ndarray, shape (B, 2)
        Box centres (x, z).
    half : ndarray, shape (B, 2)
        Grown half extents along the box's local x and z (m).
    cos_yaw, sin_yaw : ndarray, shape (B,)
        The boxes' yaws.
    nodes : ndarray, shape (N, 2)
        Corners outside every other grown box.
    visible : ndarray of bool, shape (N, N)
        Node pairs joined by a segment that enters no grown box.
    clearance : float
        m, how far the boxes were grown.
    """

    centres: np.ndarray
    half: np.ndarray
    cos_yaw: np.ndarray
    sin_yaw: np.ndarray
    nodes: np.ndarray
    visible: np.ndarray
    clearance: float = 0.0

    @property
    def n_boxes(self) -> int:
        return int(self.centres.shape[0])


def way_around(centres, sizes, yaws, clearance: float) -> WayAround:
    """The :class:`WayAround` of boxes (centres (B, 2) x, z; sizes (B, 2) along local x, z; yaws (B,))
    grown by ``clearance`` m.

    Examples
    --------
    One 1 m square box at the origin, grown by 0.5 m: four nodes at its grown corners, each seeing
    its two neighbours along the edges but not the opposite corner across the box.

    >>> import numpy as np
    >>> way = way_around(np.zeros((1, 2)), np.ones((1, 2)), np.zeros(1), 0.5)
    >>> np.round(way.nodes, 3).tolist()
    [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
    >>> way.visible.astype(int).tolist()
    [[0, 1, 0, 1], [1, 0, 1, 0], [0, 1, 0, 1], [1, 0, 1, 0]]
    """
    centres = np.ascontiguousarray(np.asarray(centres, dtype=np.float64).reshape(-1, 2))
    sizes = np.asarray(sizes, dtype=np.float64).reshape(-1, 2)
    yaws = np.asarray(yaws, dtype=np.float64).reshape(-1)
    if not (math.isfinite(clearance) and clearance >= 0.0):
        raise ValueError(f"way_around: clearance: expected a number >= 0, got {clearance!r}")
    half = np.ascontiguousarray(0.5 * sizes + clearance)
    cos_yaw, sin_yaw = np.cos(yaws), np.sin(yaws)
    corners = _corners(centres, half, cos_yaw, sin_yaw)
    keep = np.array([not _inside_any(corners[k, 0], corners[k, 1], centres, half, cos_yaw, sin_yaw)
                     for k in range(corners.shape[0])], dtype=np.bool_)
    nodes = np.ascontiguousarray(corners[keep])
    visible = np.zeros((nodes.shape[0], nodes.shape[0]), np.bool_)
    _node_visibility(nodes, centres, half, cos_yaw, sin_yaw, visible)
    return WayAround(centres, half, cos_yaw, sin_yaw, nodes, visible, float(clearance))


def _corners(centres, half, cos_yaw, sin_yaw) -> np.ndarray:
    """(4B, 2) every grown box's corners, NODE_EPS further out, counter-clockwise from (-x, -z)."""
    signs = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    local = signs[None, :, :] * (half[:, None, :] + NODE_EPS)  # (B, 4, 2) along the box's x and z
    # The box's local x is world (cos, sin) and its local z world (-sin, cos) in the (x, z) plane.
    x = centres[:, None, 0] + cos_yaw[:, None] * local[..., 0] - sin_yaw[:, None] * local[..., 1]
    z = centres[:, None, 1] + sin_yaw[:, None] * local[..., 0] + cos_yaw[:, None] * local[..., 1]
    return np.stack([x, z], axis=-1).reshape(-1, 2)


@nb.njit(cache=True)
def _local(px, pz, cx, cz, c, s):
    dx = px - cx
    dz = pz - cz
    return c * dx + s * dz, -s * dx + c * dz


@nb.njit(cache=True)
def _inside(px, pz, cx, cz, hx, hz, c, s):
    """Whether (px, pz) is in the open interior of a grown box."""
    u, v = _local(px, pz, cx, cz, c, s)
    return abs(u) < hx and abs(v) < hz


@nb.njit(cache=True)
def _inside_any(px, pz, centres, half, cos_yaw, sin_yaw):
    for b in range(centres.shape[0]):
        if _inside(px, pz, centres[b, 0], centres[b, 1], half[b, 0], half[b, 1], cos_yaw[b], sin_yaw[b]):
            return True
    return False


@nb.njit(cache=True)
def _segment_enters(ax, az, bx, bz, cx, cz, hx, hz, c, s):
    """Whether segment a -> b passes through the open interior of a grown box (a stretch of positive
    length strictly inside both slabs; touching a corner or running along an edge does not count)."""
    au, av = _local(ax, az, cx, cz, c, s)
    bu, bv = _local(bx, bz, cx, cz, c, s)
    t0 = 0.0
    t1 = 1.0
    for k in range(2):
        a = au if k == 0 else av
        d = (bu - au) if k == 0 else (bv - av)
        h = hx if k == 0 else hz
        if abs(d) < 1e-15:
            if abs(a) >= h:
                return False
            continue
        ta = (-h - a) / d
        tb = (h - a) / d
        lo = min(ta, tb)
        hi = max(ta, tb)
        t0 = max(t0, lo)
        t1 = min(t1, hi)
        if t0 >= t1:
            return False
    return t1 - t0 > 1e-12


@nb.njit(cache=True)
def _depth_margin(px, pz, cx, cz, hx, hz, c, s, clearance):
    """m: how far a point inside a grown box is outside the box itself, along the box's axes (the
    larger of the two; 0 inside the box)."""
    u, v = _local(px, pz, cx, cz, c, s)
    return max(abs(u) - (hx - clearance), abs(v) - (hz - clearance), 0.0)


@nb.njit(cache=True)
def _clear(ax, az, bx, bz, centres, half, cos_yaw, sin_yaw, clearance, own_a, own_b):
    """Whether segment a -> b enters no grown box. With ``own_a`` (``own_b``), a grown box that contains
    a (b) blocks the segment only where it comes nearer the box than ORCA's disc (the clearance's
    1 / :data:`CLEARANCE_FACTOR`), or than a (b) is if that is nearer: a character standing nearer a box
    than the clearance may walk out of it or along it, but not where ORCA would not let it. (Blocked only
    where it entered the box itself, a robot5 0.42 m from a crate's face was sent straight past it
    0.12 m from its corner, which its 0.40 m disc cannot pass: it stood for 4 s, ``mixed``, seed 3005.
    Blocked wherever it came nearer than a is, the crowds bar set's stuck time was 97 s against 71 s:
    spiders on ``crates`` 21 s against 6, on ``crates-moving`` 26 against 10.)"""
    body = clearance / CLEARANCE_FACTOR  # ORCA's disc
    for k in range(centres.shape[0]):
        cx = centres[k, 0]
        cz = centres[k, 1]
        hx = half[k, 0]
        hz = half[k, 1]
        c = cos_yaw[k]
        s = sin_yaw[k]
        # A box whose bounding rectangle (x, z) the segment's misses is not entered: skipped before the
        # exact test (the same answers; most boxes of a scene are far from a given segment). A stretch
        # inside the box lies within ex, ez of its centre; 1e-9 m keeps round-off out of the question.
        ex = abs(c) * hx + abs(s) * hz
        ez = abs(s) * hx + abs(c) * hz
        if (max(ax, bx) < cx - ex - 1e-9 or min(ax, bx) > cx + ex + 1e-9 or max(az, bz) < cz - ez - 1e-9
                or min(az, bz) > cz + ez + 1e-9):
            continue
        grow = clearance
        if own_a and _inside(ax, az, cx, cz, hx, hz, c, s):
            grow = min(grow, body, _depth_margin(ax, az, cx, cz, hx, hz, c, s, clearance) - NODE_EPS)
        if own_b and _inside(bx, bz, cx, cz, hx, hz, c, s):
            grow = min(grow, body, _depth_margin(bx, bz, cx, cz, hx, hz, c, s, clearance) - NODE_EPS)
        if grow < 0.0:
            # An end inside the box itself (a route point or a character in a looping box's region):
            # the box does not block the way to or from it (blocked, no way existed, and the
            # character aimed straight at its route point through the other boxes too).
            continue
        if grow < clearance:
            hx = max(hx - clearance + grow, 0.0)
            hz = max(hz - clearance + grow, 0.0)
        if _segment_enters(ax, az, bx, bz, cx, cz, hx, hz, c, s):
            return False
    return True


@nb.njit(cache=True)
def _node_visibility(nodes, centres, half, cos_yaw, sin_yaw, visible):
    n = nodes.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            ok = _clear(nodes[i, 0], nodes[i, 1], nodes[j, 0], nodes[j, 1], centres, half, cos_yaw, sin_yaw,
                        0.0, False, False)
            visible[i, j] = ok
            visible[j, i] = ok


@nb.njit(cache=True)
def _shortest_way(px, pz, qx, qz, nodes, visible, centres, half, cos_yaw, sin_yaw, clearance, path):
    """Dijkstra from p to q over the nodes (dense: a few dozen of them). Writes the way's node indices
    into ``path`` (from the first after p) and returns their count; -1 when no way exists."""
    n = nodes.shape[0]
    start = n
    goal = n + 1
    dist = np.full(n + 2, np.inf)
    prev = np.full(n + 2, -1, np.int64)
    done = np.zeros(n + 2, np.bool_)
    from_start = np.empty(n, np.bool_)
    to_goal = np.empty(n, np.bool_)
    for j in range(n):
        from_start[j] = _clear(px, pz, nodes[j, 0], nodes[j, 1], centres, half, cos_yaw, sin_yaw, clearance, True,
                               False)
        to_goal[j] = _clear(nodes[j, 0], nodes[j, 1], qx, qz, centres, half, cos_yaw, sin_yaw, clearance, False, True)
    dist[start] = 0.0
    while True:
        u = -1
        best = np.inf
        for k in range(n + 2):
            if not done[k] and dist[k] < best:
                best = dist[k]
                u = k
        if u < 0 or u == goal:
            break
        done[u] = True
        if u == start:
            for j in range(n):
                if from_start[j]:
                    d = math.hypot(nodes[j, 0] - px, nodes[j, 1] - pz)
                    if d < dist[j]:
                        dist[j] = d
                        prev[j] = start
            continue
        ux = nodes[u, 0]
        uz = nodes[u, 1]
        if to_goal[u]:
            d = best + math.hypot(qx - ux, qz - uz)
            if d < dist[goal]:
                dist[goal] = d
                prev[goal] = u
        for j in range(n):
            if visible[u, j] and not done[j]:
                d = best + math.hypot(nodes[j, 0] - ux, nodes[j, 1] - uz)
                if d < dist[j]:
                    dist[j] = d
                    prev[j] = u
    if not math.isfinite(dist[goal]):
        return -1
    m = 0
    k = prev[goal]
    while k != start:
        m += 1
        k = prev[k]
    k = prev[goal]
    for i in range(m - 1, -1, -1):
        path[i] = k
        k = prev[k]
    return m


@nb.njit(cache=True, parallel=True)
def _aim_points(positions, targets, nodes, visible, centres, half, cos_yaw, sin_yaw, clearance, frame,
                refresh_frames, reached_m, aim_node, out, blocked):
    for i in nb.prange(positions.shape[0]):
        px = positions[i, 0]
        pz = positions[i, 1]
        qx = targets[i, 0]
        qz = targets[i, 1]
        out[i, 0] = qx
        out[i, 1] = qz
        blocked[i] = False
        if _clear(px, pz, qx, qz, centres, half, cos_yaw, sin_yaw, clearance, True, True):
            aim_node[i] = -1
            continue
        blocked[i] = True
        k = aim_node[i]
        fresh = k < 0 or (frame + i) % refresh_frames == 0
        if not fresh:
            fresh = (math.hypot(nodes[k, 0] - px, nodes[k, 1] - pz) < reached_m
                     or not _clear(px, pz, nodes[k, 0], nodes[k, 1], centres, half, cos_yaw, sin_yaw, clearance, True,
                                   False))
        if fresh:
            path = np.empty(nodes.shape[0], np.int64)
            m = _shortest_way(px, pz, qx, qz, nodes, visible, centres, half, cos_yaw, sin_yaw, clearance, path)
            k = path[0] if m > 0 else -1
            aim_node[i] = k
        if k >= 0:
            out[i, 0] = nodes[k, 0]
            out[i, 1] = nodes[k, 1]


def aim_points(way: WayAround, positions, targets, aim_node=None, frame: int = 0,
               refresh_frames: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """(aims (C, 2), blocked (C,) bool): where each character at ``positions`` (C, 2) steers on its
    way to ``targets`` (C, 2): the target itself when the straight segment enters no grown box,
    otherwise the first corner of the shortest way round (the target again when none exists).

    ``aim_node`` (C,) int, updated in place, keeps each character's corner (-1: none) between
    frames: a blocked character searches its way again only every ``refresh_frames`` frames (its
    turn given by ``frame`` and its index), or when its corner is reached (within :data:`REACHED`
    of the way's clearance) or out of sight; in between it keeps aiming at that corner.

    Examples
    --------
    A 1 m box at the origin grown by 0.5 m, a character 3 m before it and its target 3 m beyond, a
    little to the left (+z): it aims at the box's near left grown corner; with the box out of the
    way it aims at the target.

    >>> import numpy as np
    >>> way = way_around(np.zeros((1, 2)), np.ones((1, 2)), np.zeros(1), 0.5)
    >>> aims, blocked = aim_points(way, np.array([[-3.0, 0.0]]), np.array([[3.0, 0.1]]))
    >>> np.round(aims, 3).tolist(), blocked.tolist()
    ([[-1.0, 1.0]], [True])
    >>> aims, blocked = aim_points(way, np.array([[-3.0, 2.0]]), np.array([[3.0, 2.0]]))
    >>> aims.tolist(), blocked.tolist()
    ([[3.0, 2.0]], [False])
    """
    positions = np.ascontiguousarray(positions, dtype=np.float64)
    targets = np.ascontiguousarray(targets, dtype=np.float64)
    n = positions.shape[0]
    out = np.empty((n, 2))
    blocked = np.zeros(n, np.bool_)
    if aim_node is None:
        aim_node = np.full(n, -1, np.int64)
    if refresh_frames < 1:
        raise ValueError(f"aim_points: refresh_frames: expected an integer >= 1, got {refresh_frames!r}")
    if way.n_boxes == 0 or n == 0:
        out[:] = targets
        aim_node[:] = -1
        return out, blocked
    _aim_points(positions, targets, way.nodes, way.visible, way.centres, way.half, way.cos_yaw, way.sin_yaw,
                way.clearance, int(frame), int(refresh_frames), REACHED * way.clearance, aim_node, out, blocked)
    return out, blocked


def shortest_way(way: WayAround, start, target) -> np.ndarray | None:
    """(K, 2) the shortest way from ``start`` to ``target`` (both (2,)), both included, or None when
    there is none (for tests and pictures; steering needs only its first corner, :func:`aim_points`).

    Examples
    --------
    >>> import numpy as np
    >>> way = way_around(np.zeros((1, 2)), np.ones((1, 2)), np.zeros(1), 0.5)
    >>> np.round(shortest_way(way, (-3.0, 0.0), (3.0, 0.1)), 3).tolist()
    [[-3.0, 0.0], [-1.0, 1.0], [1.0, 1.0], [3.0, 0.1]]
    """
    px, pz = (float(v) for v in start)
    qx, qz = (float(v) for v in target)
    if way.n_boxes == 0 or _clear(px, pz, qx, qz, way.centres, way.half, way.cos_yaw, way.sin_yaw, way.clearance, True,
                                  True):
        return np.array([[px, pz], [qx, qz]])
    path = np.empty(way.nodes.shape[0], np.int64)
    m = _shortest_way(px, pz, qx, qz, way.nodes, way.visible, way.centres, way.half, way.cos_yaw, way.sin_yaw,
                      way.clearance, path)
    if m < 0:
        return None
    return np.vstack([[px, pz], way.nodes[path[:m]], [qx, qz]])
