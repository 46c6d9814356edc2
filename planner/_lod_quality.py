"""The quality of each level of detail, measured on what is rendered (issue 15).

:class:`LevelMeter` reads the crowd after every frame of a run with a LOD mode and attributes what
it sees to the level of detail each character had in that frame (``planner._lod``):

* ``character_frames``: how many character-frames were at that level;
* ``stride_rel_error_median`` / ``_p90``: the steady strides (``planner._simulation.StrideMeter``)
  whose foot landed while its character was at that level;
* ``max_stance_slip_m``: the largest distance of a rendered stance foot from where it touched down;
* ``ik_residual_p95_m``: |rendered foot - planned foot| of the legs drawn from joint angles (the
  IK's residual: CCD near, the two-bone solve far);
* ``feet_in_boxes``: rendered feet overlapping a box below its top (a forbidden one at any height),
  summed over frames (the ``collisions`` counter of ``planner._counters``, per level);
* ``body_overlaps``: pairs of characters whose projected body boxes overlap, summed over frames
  (each pair at the level of its lower-indexed character);
* ``jump_max_m``: the largest frame-to-frame move of a rendered foot beyond the move of its planned
  foot, in frames without a level switch (the IK's own jitter, the background a pop is seen
  against).

and, over the run, ``pop_max_m``: the same jump in the frames where a character switched level
(the largest of all its feet), the pop a viewer would see, with ``switches``, how many there were.
"""

from __future__ import annotations

import numpy as np

from footfall.planner._counters import CONTACT_TOLERANCE_M
from footfall.planner._kernels_controller import count_body_overlaps, count_collisions
from footfall.planner._lod import LEVEL_NAMES


class LevelMeter:
    """Accumulates the per-level quality of the module doc over the frames of a run."""

    def __init__(self, model, state):
        self.model = model
        n_levels = len(LEVEL_NAMES)
        self.frames = np.zeros(n_levels, np.int64)
        self.slip = np.zeros(n_levels)
        self.jump = np.zeros(n_levels)
        self.in_boxes = np.zeros(n_levels, np.int64)
        self.overlaps = np.zeros(n_levels, np.int64)
        self.residuals: list[list[np.ndarray]] = [[] for _ in range(n_levels)]
        self.pop = 0.0
        self.switches = 0
        self._level = state.lod_level.copy()
        self._rendered = self._rendered_feet(state).copy()
        self._planned = state.feet.copy()
        self._anchor = self._rendered.copy()
        self._stance = state.in_stance.copy()
        self._per_char = np.zeros(state.pelvis.shape[0], np.int64)

    @staticmethod
    def _rendered_feet(state) -> np.ndarray:
        return np.where(state.ik_on[:, None, None], state.fk_feet, state.feet)

    def update(self, state) -> None:
        level = state.lod_level
        rendered = self._rendered_feet(state)
        n_levels = len(LEVEL_NAMES)
        self.frames += np.bincount(level, minlength=n_levels)
        # The move of each rendered foot beyond its planned foot's: the IK's error changing.
        jump = np.linalg.norm((rendered - self._rendered) - (state.feet - self._planned), axis=-1).max(axis=1)
        switched = level != self._level
        if switched.any():
            self.pop = max(self.pop, float(jump[switched].max()))
            self.switches += int(switched.sum())
        stayed = state.in_stance & self._stance
        slip = np.where(stayed, np.linalg.norm(rendered - self._anchor, axis=-1), 0.0).max(axis=1)
        landed = state.in_stance & ~self._stance
        self._anchor[landed] = rendered[landed]
        self._count_feet_in_boxes(state, rendered)
        in_boxes = self._per_char.copy()
        self._count_overlaps(state)
        for k in range(n_levels):
            mine = level == k
            if not mine.any():
                continue
            self.slip[k] = max(self.slip[k], float(slip[mine].max()))
            steady = mine & ~switched
            if steady.any():
                self.jump[k] = max(self.jump[k], float(jump[steady].max()))
            self.in_boxes[k] += int(in_boxes[mine].sum())
            self.overlaps[k] += int(self._per_char[mine].sum())  # pairs, each at its lower index
            drawn = mine & state.ik_on
            if drawn.any():
                self.residuals[k].append(np.linalg.norm(rendered[drawn] - state.feet[drawn], axis=-1).ravel())
        self._level = level.copy()
        self._rendered = rendered.copy()
        self._planned = state.feet.copy()
        self._stance = state.in_stance.copy()

    def _count_feet_in_boxes(self, state, rendered) -> None:
        model = self.model
        obs = model.raster.obstacles
        self._per_char[:] = 0
        if not len(obs.yaws):
            return
        centres, yaws = obs.poses_at(state.t)
        count_collisions(np.ascontiguousarray(rendered), 0.5 * model.creature.foot_length,
                         0.5 * model.creature.foot_width, state.foot_yaws, np.ascontiguousarray(centres),
                         np.ascontiguousarray(obs.sizes, dtype=np.float64), np.ascontiguousarray(yaws),
                         np.ascontiguousarray(obs.forbidden, dtype=np.bool_), self._per_char,
                         CONTACT_TOLERANCE_M)

    def _count_overlaps(self, state) -> None:
        self._per_char[:] = 0
        if state.pelvis.shape[0] < 2:
            return
        box = self.model.creature.body_box
        count_body_overlaps(np.ascontiguousarray(state.pelvis[:, [0, 2]]), np.ascontiguousarray(state.heading),
                            0.5 * float(box[0]), 0.5 * float(box[1]), self._per_char)

    def summary(self, stride_errors: np.ndarray, stride_levels: np.ndarray) -> dict:
        """{level name: metrics} (levels never used left out) and ``pop_max_m``, ``switches``."""
        out: dict = {}
        for k, name in enumerate(LEVEL_NAMES):
            if self.frames[k] == 0:
                continue
            errors = stride_errors[stride_levels == k]
            res = np.concatenate(self.residuals[k]) if self.residuals[k] else np.zeros(0)
            out[name] = {
                "character_frames": int(self.frames[k]),
                "stride_rel_error_median": float(np.median(errors)) if errors.size else None,
                "stride_rel_error_p90": float(np.percentile(errors, 90)) if errors.size else None,
                "strides_measured": int(errors.size),
                "max_stance_slip_m": float(self.slip[k]),
                "ik_residual_p95_m": float(np.percentile(res, 95)) if res.size else None,
                "feet_in_boxes": int(self.in_boxes[k]),
                "body_overlaps": int(self.overlaps[k]),
                "jump_max_m": float(self.jump[k]),
            }
        return {"levels": out, "pop_max_m": self.pop, "switches": self.switches}
