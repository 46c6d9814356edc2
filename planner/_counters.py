"""The safety counters of a run, measured on what is rendered (issue 20, item 2).

Every frame, :class:`FrameCounters` reads the crowd state after :func:`planner._crowd.step` and
counts, on the **rendered** pose (the feet and leg segments where the IK put them; the planned
feet for characters whose IK is off, which is how they are drawn):

* ``collisions``: feet overlapping a box below its top (a forbidden box at any height);
* ``leg_crossings``: pairs of legs of a character whose ground projections cross (the legs'
  polylines, hip -> knees -> foot, from forward kinematics of the IK angles);
* ``max_stance_slip_m``: the largest distance between a stance foot and the point where it
  touched down, while it stays down (rendered foot; and the planned foot itself, which must not
  move at all): a foot that creeps with the body is caught however slowly it creeps;
* ``ik_residual``: |IK foot - target| of every solved leg (the summary takes its 95th percentile);
* ``body_overlaps``: pairs of characters whose projected body boxes (``body_box`` about the
  pelvis, along the heading) overlap, summed over frames;
* ``shared_foot_spots``: pairs of stance feet of different characters closer than a foot
  length, summed over frames;
* ``unavoidable_contacts``: rendered feet inside a box that moves at least as fast as the
  creature's top speed (``CrowdModel.top_speed``): no escape exists, so such a contact is
  counted apart from ``collisions``;
* ``stuck_seconds``: character-seconds in which a character that has not reached its goal
  moved less than 10 % of its asked speed over the last 2 s (:data:`STUCK_WINDOW_S`);
* ``max_pelvis_jump_m``: the largest change of a character's pelvis height from one frame to the
  next (a body on its support hulls moves in steps where the hulls do: a robot5 fell 13 cm in a
  frame beside a crate; :mod:`planner._kernels_body`). Reported, not a promise of ``evaluate``.

Each counter is tested on hand-made states where it must read a known non-zero value
(``tests/test_counters.py``).
"""

from __future__ import annotations

import numpy as np

from footfall.planner._ik import DEFAULT_TOLERANCE
from footfall.planner._kernels_controller import (
    count_body_overlaps,
    count_close_pairs,
    count_collisions,
    count_polyline_crossings,
)

CONTACT_TOLERANCE_M = DEFAULT_TOLERANCE
"""m: a rendered foot this close below a box's top stands on it. The IK places a foot within its
tolerance of the planned one, and a planned foot on a box stands exactly on its top: rendered 6-18 um
lower, feet standing on crates counted as collisions."""
STUCK_WINDOW_S = 2.0
"""Window over which a character's progress is measured for ``stuck_seconds``."""
STUCK_FRACTION = 0.1
"""A character moving less than this fraction of its asked speed over the window is stuck."""


def rendered_joints(model, state, hips=None) -> np.ndarray:
    """(C, L, S + 2, 3) joint positions as drawn: forward kinematics of the IK angles, the hip
    first and the foot last; for characters whose IK is off, a straight hip -> planned foot leg.
    ``hips``: the state's (C, L, 3) hips (:func:`planner._crowd.hips_world`) if the caller has them."""
    from footfall.planner._crowd import hips_world
    from footfall.planner._ik import body_rotation
    from footfall.planner._kernels_ik import forward_kinematics_batch

    c, l = state.in_stance.shape
    legs = model.leg_static
    if hips is None:
        hips = hips_world(model, state)
    rotations = np.repeat(body_rotation(state.heading, state.pitch, state.roll)[:, None], l, axis=1)
    # The kernel itself on the runtime's own arrays (checked when the crowd was built): the controller
    # calls this every frame, and forward_legs would check and copy them again (the kernel alone:
    # 0.74 ms for 1000 spiders' 8000 legs on 2 cores).
    joints = np.empty((c * l, legs.segment_lengths.shape[1] + 2, 3))
    forward_kinematics_batch(np.ascontiguousarray(hips.reshape(-1, 3)), rotations.reshape(-1, 3, 3),
                             np.tile(legs.rest_azimuths, c), np.tile(legs.plane_rolls, c),
                             np.tile(legs.segment_lengths, (c, 1)), np.ascontiguousarray(state.angles.reshape(c * l, -1)),
                             joints)
    joints = joints.reshape(c, l, -1, 3)[:, :, 1:]  # rows 0 and 1 are both the hip
    off = ~state.ik_on
    if off.any():
        straight = np.linspace(0.0, 1.0, joints.shape[2])[None, None, :, None]
        joints[off] = hips[off][:, :, None] + straight * (state.feet[off] - hips[off])[:, :, None]
    return joints


class FrameCounters:
    """Accumulates the counters of the module doc over the frames of a run."""

    def __init__(self, model, state):
        self.model = model
        self.collisions = 0
        self.unavoidable_contacts = 0
        self.leg_crossings = 0
        self.max_stance_slip_m = 0.0
        self.residuals: list[np.ndarray] = []
        self.body_overlaps = 0
        self.shared_foot_spots = 0
        self.stuck_frames = 0
        window = int(round(STUCK_WINDOW_S / model.dt))
        self._trail = np.repeat(state.pelvis[None, :, :][:, :, [0, 2]], window, axis=0)  # ring of positions
        self._frames = 0
        self._per_char = np.zeros(state.pelvis.shape[0], np.int64)
        self._stance = state.in_stance.copy()
        self._anchor = self._rendered_feet(state).copy()  # where each stance foot is (rendered)
        self._planned = state.feet.copy()
        self.max_pelvis_jump_m = 0.0
        self._pelvis_y = None  # the state a run starts from is never drawn: jumps from the first frame

    @staticmethod
    def _rendered_feet(state) -> np.ndarray:
        return np.where(state.ik_on[:, None, None], state.fk_feet, state.feet)

    def update(self, state) -> None:
        model = self.model
        feet = np.ascontiguousarray(self._rendered_feet(state))
        obs = model.raster.obstacles
        if len(obs.yaws):
            centres, yaws = obs.poses_at(state.t)
            # A box at least as fast as the creature's top speed cannot be escaped: its contacts
            # are unavoidable_contacts, the others collisions.
            previous, _ = obs.poses_at(state.t - model.dt)
            box_speed = np.hypot(*(centres - previous)[:, [0, 2]].T) / model.dt
            unstoppable = box_speed >= model.top_speed
            for mask, name in ((~unstoppable, "collisions"), (unstoppable, "unavoidable_contacts")):
                if not mask.any():
                    continue
                count_collisions(feet, 0.5 * model.creature.foot_length, 0.5 * model.creature.foot_width,
                                 state.foot_yaws, np.ascontiguousarray(centres[mask]),
                                 np.ascontiguousarray(obs.sizes[mask], dtype=np.float64),
                                 np.ascontiguousarray(yaws[mask]),
                                 np.ascontiguousarray(np.asarray(obs.forbidden)[mask], dtype=np.bool_), self._per_char,
                                 CONTACT_TOLERANCE_M)
                setattr(self, name, getattr(self, name) + int(self._per_char.sum()))
        count_polyline_crossings(np.ascontiguousarray(rendered_joints(model, state)), self._per_char)
        self.leg_crossings += int(self._per_char.sum())
        # Stance slip against the touch-down point: feet that stayed down keep their anchor, feet
        # that just landed take a new one.
        stayed = state.in_stance & self._stance
        if stayed.any():
            rendered = np.linalg.norm(feet[stayed] - self._anchor[stayed], axis=1).max()
            planned = np.linalg.norm(state.feet[stayed] - self._planned[stayed], axis=1).max()
            self.max_stance_slip_m = max(self.max_stance_slip_m, float(rendered), float(planned))
        landed = state.in_stance & ~self._stance
        self._anchor[landed] = feet[landed]
        self._planned[landed] = state.feet[landed]
        self._stance[:] = state.in_stance
        if self._pelvis_y is not None:
            self.max_pelvis_jump_m = max(self.max_pelvis_jump_m,
                                         float(np.abs(state.pelvis[:, 1] - self._pelvis_y).max(initial=0.0)))
        self._pelvis_y = state.pelvis[:, 1].copy()
        if state.ik_on.any():
            self.residuals.append(state.residual[state.ik_on].ravel().copy())
        self._crowd(state, feet)

    def _crowd(self, state, feet) -> None:
        model = self.model
        n = state.pelvis.shape[0]
        if n > 1:
            box = model.creature.body_box
            count_body_overlaps(np.ascontiguousarray(state.pelvis[:, [0, 2]]), np.ascontiguousarray(state.heading),
                                0.5 * float(box[0]), 0.5 * float(box[1]), self._per_char)
            self.body_overlaps += int(self._per_char.sum())
            cs, ls = np.nonzero(state.in_stance)
            self.shared_foot_spots += int(count_close_pairs(np.ascontiguousarray(feet[cs, ls][:, [0, 2]]), cs,
                                                            float(model.creature.foot_length)))
        # Stuck: not at the goal, and less than 10 % of the asked speed over the window.
        window = self._trail.shape[0]
        slot = self._frames % window
        since = np.hypot(*(state.pelvis[:, [0, 2]] - self._trail[slot]).T)
        self._trail[slot] = state.pelvis[:, [0, 2]]
        self._frames += 1
        if self._frames >= window:
            from footfall.planner._simulation import arrived

            asked = STUCK_FRACTION * state.desired_speed * STUCK_WINDOW_S
            self.stuck_frames += int(((since < asked) & ~arrived(model, state)).sum())

    @property
    def stuck_seconds(self) -> float:
        return self.stuck_frames * self.model.dt

    def ik_residual_p95(self) -> float:
        res = np.concatenate(self.residuals) if self.residuals else np.zeros(1)
        return float(np.percentile(res, 95))
