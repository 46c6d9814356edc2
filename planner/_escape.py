"""The way out of a moving box's lane, checked by looking ahead (issue 14, item 2).

The lane exit (:func:`planner._crowd._lane_exit`) squares a threatened character out of a moving
box's lane, to the side it is on, and ORCA then bends that way round the boxes and the other
characters. Neither knows how long the body takes to turn, nor that it walks only along its heading:
an ant with a crate 0.42 m away coming at 0.29 m/s had its way out 2.7 rad behind it, and ORCA's
velocity, holonomic, flipped from ahead to behind as the crate closed in; turning on the spot, the
ant was run over (``mixed``, 16 ants, seed 1: 141 foot-frames in the crate).

So a way is followed ahead in time, with the body's own motion, against the boxes where their
scripts will put them (:func:`escape_costs`: for :data:`ESCAPE_HORIZON`, turning at
:data:`ESCAPE_TURN` x the turn rate, walking at :data:`ESCAPE_PACE` x the flee speed times the
cosine of the turn still to make; the kernel, :mod:`planner._kernels_escape`, holds the exact
steps). A way costs how deep and how early the pelvis comes nearer than the feet's reach plus
:data:`ESCAPE_MARGIN` to a moving box or a forbidden static one, everything after walking into one,
and :data:`LANE_COST` if it ends still before a moving box in its lane. Two choices use it:

* :func:`escape_ways`: the lane exit's way is kept unless another of :data:`ESCAPE_WAYS` headings (or
  the character's own way) costs clearly less;
* :func:`orca_worse`: where ORCA's velocity points elsewhere and costs clearly more than the way, the
  escaper follows the way, if that keeps it clear of the other characters for
  :data:`CLEAR_HORIZON` (:func:`clear_of_others`, within :data:`CLEAR_FRACTION` of ORCA's spacing;
  a dense crowd's escapers stay with ORCA).

Measured 2026-11-27 (foot-frames in boxes, 600 frames; the lane exit and ORCA alone -> with both
checks): 12 of each of 3 creatures on ``mixed`` and ``crates-moving``, seeds 1100-1103: 1 -> 0; 16
ants on ``mixed`` and ``crates``, seeds 1-3: 265 -> 48; 16 of 3 creatures on 3 scenarios, seeds 7-9:
30 -> 18; 8 of 4 creatures on 2 scenarios, seeds 20-22: 147 -> 0; 12 of 4 creatures on 2, seeds
500-507: 160 -> 9 (robot5's 9 in both); 12 ants on 2, seeds 700-715: 218 -> 1, body overlaps 59 -> 1.
Leg-crossing frames over these sets 33 -> 22, stuck seconds 729 -> 650. 1000 spiders on ``mixed``
(300 frames, LOD on, seeds 0-2): foot-frames in boxes 769 -> 405, overlapping pair-frames 23 -> 40,
crossing frames 273 -> 285, ms per frame 34.3 -> 37.2. The crowds bar set is unchanged (its 300 frames
meet few moving crates).
"""

from __future__ import annotations

import numpy as np

ESCAPE_WAYS = 24
"""Headings tried, evenly spaced round the circle, besides the lane exit's way and the character's own."""
ESCAPE_HORIZON = 3.0
"""s: how far ahead a way is followed (the lane exit's own horizon, ``LANE_HORIZON``)."""
ESCAPE_STEP = 0.1
"""s: the step at which it is followed."""
ESCAPE_TURN = 0.7
"""x turn rate: how fast a body turns while its stance feet hold it (the ant above: 1.1 of 1.5 rad/s)."""
ESCAPE_PACE = 0.6
"""x flee speed: the pace a way is followed at. The legs' stance windows slow a body down: followed at
the full flee speed, the look-ahead led ants across a crate's lane at the last moment (0.5 and 0.8
did worse than 0.6 on the 16 ants above)."""
ESCAPE_MARGIN = 0.05
"""m beyond the feet's reach a box must stay."""
ESCAPE_KEEP = 0.005
"""A way in use stays unless another costs this much less (m x weighted steps: 5 mm for one step)."""
LANE_COST = 0.5
"""Added to a way that ends in a moving box's lane, not behind the box: without it the cheapest way
before a crate coming head-on ran ahead of it (clear for the horizon) and a spider walked backwards
before the crate for 30 s."""
CLEAR_HORIZON = 1.0
"""s: an escaper leaves ORCA's velocity for its way only if, walking that way while the others keep
their velocities, it stays two avoid radii from every other character for this long (with no such
check, 1000 spiders on ``mixed`` overlapped in 461 pair-frames instead of 23)."""
CLEAR_FRACTION = 0.9
"""x two avoid radii: how near the others an escaper following its way may come. ORCA holds neighbours
at two avoid radii, so with the full two an escaper with a neighbour at its side never left ORCA's
velocity: an ant turned on the spot toward it and a crate ran over its feet (``mixed``, 64 ants, seed 2:
153 foot-frames; 4 with 0.9, bodies never stepping into each other: ``planner._crowd.bodies_apart``)."""


def escape_costs(model, state, rows, targets, flee_speed, boxes_used) -> np.ndarray:
    """(R, K) the cost of each of ``targets`` (R, K) headings (rad) for characters ``rows`` (R,) fleeing at
    ``flee_speed`` (R,) m/s, against the boxes ``boxes_used`` (B,) bool (module doc)."""
    from footfall.planner._kernels_escape import escape_costs as kernel

    obstacles = model.raster.obstacles
    steps = np.arange(1, int(round(ESCAPE_HORIZON / ESCAPE_STEP)) + 1) * ESCAPE_STEP
    index = np.flatnonzero(boxes_used)
    paths = np.ascontiguousarray(obstacles.centres_over(state.t + steps)[:, index][..., [0, 2]])  # (T, B, 2)
    half = np.ascontiguousarray(0.5 * np.asarray(obstacles.sizes, dtype=np.float64)[index][:, [0, 2]])
    yaws = np.asarray(obstacles.yaws, dtype=np.float64)[index]
    ctl = model.controller
    cost = np.empty(targets.shape)
    kernel(np.ascontiguousarray(state.pelvis[rows][:, [0, 2]]), np.ascontiguousarray(state.heading[rows]),
           np.ascontiguousarray(state.speed[rows]), np.ascontiguousarray(ESCAPE_PACE * np.asarray(flee_speed, np.float64)),
           np.ascontiguousarray(targets, dtype=np.float64), ESCAPE_TURN * ctl.turn_rate * ESCAPE_STEP,
           ctl.acceleration * ESCAPE_STEP, ESCAPE_STEP, model.rest_radius + ctl.threat_margin + ESCAPE_MARGIN,
           paths, half, np.cos(yaws), np.sin(yaws), LANE_COST, cost)
    return cost


def escape_ways(model, state, rows, exit_way, own_way, flee_speed, boxes_used) -> np.ndarray:
    """(R, 2) unit ways out of moving boxes' lanes for the threatened characters ``rows`` (R,): the lane
    exit's ``exit_way`` (R, 2) unless another heading costs at least :data:`ESCAPE_KEEP` less; then the
    cheapest, the nearest the character's ``own_way`` (R, 2) on a tie. ``flee_speed`` (R,) m/s,
    ``boxes_used`` (B,) bool: the boxes to keep clear of (moving ones and forbidden static ones).

    Examples
    --------
    A crate 0.45 m ahead comes straight at a spider at 0.3 m/s; the lane exit squares it out to the
    left (+z): the look-ahead keeps that way. Walking on (+x) into the crate costs more.

    >>> import dataclasses
    >>> import numpy as np
    >>> from footfall.planner import init_crowd
    >>> from footfall.scenarios import Obstacles, default_gait, load_creature, load_scenario
    >>> spider = load_creature("spider")
    >>> crate = Obstacles([[3.0, 0.1, 0.0]], [[0.2, 0.2, 0.2]], [0.0], [True],
    ...                   motion_kind=[1], velocities=[[-0.3, 0.0, 0.0]])
    >>> flat = dataclasses.replace(load_scenario("flat"), obstacles=crate)
    >>> model, state = init_crowd(flat, spider, default_gait(spider), n_characters=1)
    >>> state.t = 8.0  # the crate is at x = 0.6
    >>> state.pelvis[0, [0, 2]] = 0.0; state.heading[0] = 0.0; state.speed[0] = 0.0
    >>> one, exit_way, own_way = np.array([0]), np.array([[0.0, 1.0]]), np.array([[1.0, 0.0]])
    >>> escape_ways(model, state, one, exit_way, own_way, np.array([0.4]), np.array([True])).round(3).tolist()
    [[0.0, 1.0]]
    >>> ahead, left = escape_costs(model, state, one, np.array([[0.0, np.pi / 2]]), np.array([0.4]),
    ...                            np.array([True]))[0]
    >>> bool(ahead > left)
    True
    """
    r = rows.size
    if r == 0 or not np.any(boxes_used):
        return np.array(exit_way, dtype=np.float64, copy=True)
    exit_angle = np.arctan2(exit_way[:, 1], exit_way[:, 0])
    own_angle = np.arctan2(own_way[:, 1], own_way[:, 0])
    circle = np.arange(ESCAPE_WAYS) * (2.0 * np.pi / ESCAPE_WAYS)
    # Candidate 0 is the lane exit's way, 1 the character's own, then the circle.
    targets = np.concatenate([exit_angle[:, None], own_angle[:, None], np.broadcast_to(circle, (r, ESCAPE_WAYS))],
                             axis=1)
    cost = escape_costs(model, state, rows, targets, flee_speed, boxes_used)
    best = cost.min(axis=1)
    off_way = np.abs((targets - own_angle[:, None] + np.pi) % (2.0 * np.pi) - np.pi)
    choice = np.argmin(np.where(cost <= best[:, None] + 1e-12, off_way, np.inf), axis=1)
    choice = np.where(cost[:, 0] <= best + ESCAPE_KEEP, 0, choice)
    chosen = targets[np.arange(r), choice]
    return np.column_stack([np.cos(chosen), np.sin(chosen)])


def orca_worse(model, state, rows, way, velocity, flee_speed, boxes_used) -> np.ndarray:
    """(R,) bool: for characters ``rows`` (R,), ORCA's ``velocity`` (R, 2) heads somewhere that costs at
    least :data:`ESCAPE_KEEP` more than their ``way`` (R, 2)."""
    if rows.size == 0 or not np.any(boxes_used):
        return np.zeros(rows.size, np.bool_)
    targets = np.column_stack([np.arctan2(way[:, 1], way[:, 0]), np.arctan2(velocity[:, 1], velocity[:, 0])])
    cost = escape_costs(model, state, rows, targets, flee_speed, boxes_used)
    return cost[:, 1] > cost[:, 0] + ESCAPE_KEEP


def clear_of_others(model, state, rows, velocity) -> np.ndarray:
    """(R,) bool: characters ``rows`` (R,) walking at ``velocity`` (R, 2) while every other keeps its own
    (along its heading, at its speed) stay more than :data:`CLEAR_FRACTION` x two avoid radii from each for
    :data:`CLEAR_HORIZON`."""
    xz = state.pelvis[:, [0, 2]]
    others = np.stack([np.cos(state.heading), np.sin(state.heading)], axis=1) * state.speed[:, None]
    rel = xz[None, :, :] - xz[rows][:, None, :]  # (R, C, 2)
    closing = others[None, :, :] - velocity[:, None, :]
    when = np.clip(-(rel * closing).sum(-1) / np.maximum((closing * closing).sum(-1), 1e-12), 0.0, CLEAR_HORIZON)
    closest = np.hypot(*(rel + when[..., None] * closing).transpose(2, 0, 1))
    closest[np.arange(rows.size), rows] = np.inf
    return closest.min(axis=1) > CLEAR_FRACTION * 2.0 * model.avoid_radius
