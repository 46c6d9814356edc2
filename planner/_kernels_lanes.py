"""The lanes of moving boxes, batched as one numba kernel (the steering's lane exit,
:func:`planner._crowd._lane_exit`, which holds the rule and says why).

Per character c and moving box b (slower than the creature's top speed), on the ground plane (x, z):
the box travels along ``u[b]`` (unit), ``side_axis[b]`` is ``u[b]`` turned left; ``half_along`` and
``half_across`` are how far the box reaches along those axes. The box threatens the character when
the character is within ``half_across + room`` of the lane's centre line and the box's front, closing
in at its speed plus the character's own walk toward it, reaches it within ``horizon``. The exit from
one box is the side the character is on (or, dead centre, the side its way leans to) plus half the
part of its way that runs ahead of the box.

The kernel writes what the numpy version computed, with the same operations in the same order, so
the results are bit for bit the same; the square roots and trigonometry stay with numpy in the caller.
"""

from __future__ import annotations

import numba as nb


@nb.njit(cache=True)
def lane_threats(pelvis_xz, speed, cos_heading, sin_heading, direction, centres_xz, u, side_axis, half_along,
                 half_across, box_speed, room, horizon, threat, side, each_exit, exit_way):
    """Fill ``threat`` (C, B) bool, ``side`` (C, B), ``each_exit`` (C, B, 2) and ``exit_way`` (C, 2), the
    sum of the threatening boxes' exits, for characters at ``pelvis_xz`` (C, 2) walking at ``speed``
    (C,) along their headings (cos, sin (C,)) with their ways ``direction`` (C, 2), and boxes (B) at
    ``centres_xz`` (B, 2) travelling along ``u`` (B, 2) at ``box_speed`` (B,)."""
    n_chars = pelvis_xz.shape[0]
    n_boxes = centres_xz.shape[0]
    for c in range(n_chars):
        for b in range(n_boxes):
            rx = pelvis_xz[c, 0] - centres_xz[b, 0]
            rz = pelvis_xz[c, 1] - centres_xz[b, 1]
            along = rx * u[b, 0] + rz * u[b, 1]
            across = rx * side_axis[b, 0] + rz * side_axis[b, 1]
            walk = speed[c] * (cos_heading[c] * u[b, 0] + sin_heading[c] * u[b, 1])
            closing = box_speed[b] + max(-walk, 0.0)
            threat[c, b] = ((abs(across) < half_across[b] + room) and (along > -(half_along[b] + room))
                            and (along - half_along[b] - room < closing * horizon))
            way_side = direction[c, 0] * side_axis[b, 0] + direction[c, 1] * side_axis[b, 1]
            if abs(across) > 1e-6:
                s = 1.0 if across > 0.0 else -1.0
            else:
                s = 1.0 if way_side > 0.0 else -1.0
            side[c, b] = s
            ahead = max(direction[c, 0] * u[b, 0] + direction[c, 1] * u[b, 1], 0.0)
            for k in range(2):
                each_exit[c, b, k] = s * side_axis[b, k] + 0.5 * ahead * u[b, k]
        # Summed over the threatening boxes in box order, as numpy's sum of (exit x threat) over them.
        for k in range(2):
            total = each_exit[c, 0, k] * (1.0 if threat[c, 0] else 0.0) if n_boxes else 0.0
            for b in range(1, n_boxes):
                total += each_exit[c, b, k] * (1.0 if threat[c, b] else 0.0)
            exit_way[c, k] = total
