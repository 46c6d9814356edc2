"""Running a crowd for many frames: metrics, timings and the recording.

Metrics are measured after each frame and are not part of the frame time:
* ``collisions``, ``leg_crossings``, ``max_stance_slip_m`` and ``ik_residual_p95_m`` are
  measured on the rendered pose by :class:`planner._counters.FrameCounters` (see there);
* ``forbidden_footprints``: landings touching a forbidden box;
* ``stride_rel_error_median`` / ``_p90``: per stride (one foot's consecutive touch-downs),
  |lambda_i / (s_i lambda*(v_i)) - 1|, lambda_i the ground distance between the two footprints, v_i
  the pelvis's ground speed between them, lambda*(v) = v / f(v) the stride the timing model
  commands (the target law lambda = c h Fr^e wherever the stride frequency is above its floor),
  s_i the foot's own share of the body's travel: how far its rest point (:func:`rest_points`)
  travelled between the touch-downs over how far the pelvis did (1 on a straight stride; in a turn
  the outer feet stride further, the inner ones less, at the one tempo of the gait);
  steady strides only: both touch-downs at between half and 1.5 times the character's goal
  speed (min(asked, speed_cap)), not in the start-up or the stop at the goal, and the body's
  speed within STEADY_BAND of v_i at every frame of the stride (``strides_measured``): the law
  relates a stride to one speed, and a stride through a dodge (0.3 -> 0.04 -> 0.3 m/s in 0.3 s
  while a neighbour passed) has none;
* ``speed_asked`` (the scenario's speed), ``speed_cap`` (the fastest the legs carry at the stride
  law, :mod:`planner._workspace`; ``None`` when no cap applies), ``speed_reached`` (median over
  characters of the pelvis's ground speed over the second half of the run, frames before it
  braked for its goal, :func:`cruising`), ``duty_factor_mean`` (stance fraction of foot-frames after the first
  second, walking characters), ``gait_fractions`` (share of character-frames in each gait of
  the creature's schedule).
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from footfall._atomic import atomic_path
from footfall.planner._crowd import STAGES, CrowdModel, CrowdState, _rot_xz, step
from footfall.planner._counters import FrameCounters
from footfall.planner._weights import N_TERMS
from footfall.planner.layout import COUNTERS, N_COUNTERS

RECORDING_FORMAT = "footfall-recording"
RECORDING_VERSION = 1


@dataclass(frozen=True)
class SimulationSummary:
    """What :func:`simulate` measured over a run: counts, safety and gait metrics, timings.

    The metrics are defined in the docstring of ``footfall.planner._simulation`` and in the
    README (``footfall simulate --json`` prints these fields, :meth:`to_json`); a recording's
    header carries them too.

    Attributes
    ----------
    frames, characters, steps : int
        Frames run, characters, footsteps taken (touch-downs).
    collisions, forbidden_footprints, leg_crossings, body_overlaps, shared_foot_spots : int
        Safety counts (on the rendered pose, :class:`planner._counters.FrameCounters`).
    unavoidable_contacts : int
        Feet inside a box too fast to escape (not counted as collisions).
    max_stance_slip_m, ik_residual_p95_m : float
        m: the largest distance of a stance foot from its touch-down point; the IK residual's
        95th percentile.
    stuck_seconds : float
        Character-seconds in which a character short of its goal moved less than 10 % of its
        asked speed over the last 2 s.
    max_pelvis_jump_m : float
        m: the largest change of a pelvis's height from one frame to the next.
    box_shoves : int
        Character-frames in which a moving box reached a foot in the air and shoved the body out of its
        way (its escape failed; :func:`planner._crowd.shove_out_of_moving_boxes`).
    ms_per_frame_median, ms_per_frame_mean : float
        Frame times, ms (the mean includes the first frame).
    ms_per_frame_warmup, ms_per_frame_steady : float or None
        ms of the first frame, where a fresh process loads or compiles the numba kernels, and
        the mean of the others (None for a one-frame run).
    stage_ms_median : dict of str to float
        Median ms of each stage of :func:`step`.
    plans, holds, replans, cells_expanded, couples_evaluated : int
        The planner's work: feet planned, new requests held for want of a couple, re-plans,
        wavefront cells expanded, couples scored.
    boxed_ways : int
        New steps whose couple is a boxed-in foot's way out, through other feet's room, other legs'
        projections or a forbidden box's foot-size ring (:data:`planner._kernels_foot.BOXED_CELL_COST`).
    finite : bool
        Every pose of the run was finite.
    stride_rel_error_median, stride_rel_error_p90 : float or None
        Per-stride error against the stride law over the steady strides (None: none measured).
    strides_measured : int
        The steady strides measured.
    speed_asked, speed_cap, speed_reached : float
        m/s: the scenario's speed, the legs' cap (None: no cap) and the median speed reached.
    duty_factor_mean : float or None
        Stance fraction of the walking characters' foot-frames after the first second.
    gait_fractions : dict of str to float
        Share of character-frames in each gait of the creature's schedule.
    lod_levels : dict or None
        With a LOD mode, the quality of each level of detail (``planner._lod_quality``), the
        largest jump of a rendered foot at a level switch (``pop_max_m``) and the ``switches``;
        None with LOD off.

    Examples
    --------
    >>> from footfall.planner import init_crowd, simulate
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> summary = simulate(model, state, 5)
    >>> summary.frames, summary.characters, summary.finite, summary.collisions
    (5, 2, True, 0)
    >>> summary.to_json()["frames"], summary.gait_fractions
    (5, {'spider-metachronal-wave': 1.0})
    """

    frames: int
    characters: int
    steps: int
    collisions: int
    forbidden_footprints: int
    leg_crossings: int
    max_stance_slip_m: float
    ik_residual_p95_m: float
    ms_per_frame_median: float
    ms_per_frame_mean: float
    stage_ms_median: dict
    plans: int
    holds: int
    replans: int
    cells_expanded: int
    couples_evaluated: int
    finite: bool
    stride_rel_error_median: float | None = None
    stride_rel_error_p90: float | None = None
    strides_measured: int = 0
    speed_asked: float = 0.0
    speed_cap: float | None = None
    speed_reached: float = 0.0
    duty_factor_mean: float | None = None
    gait_fractions: dict = field(default_factory=dict)
    boxed_ways: int = 0
    body_overlaps: int = 0
    shared_foot_spots: int = 0
    stuck_seconds: float = 0.0
    unavoidable_contacts: int = 0
    max_pelvis_jump_m: float = 0.0
    box_shoves: int = 0
    ms_per_frame_warmup: float | None = None
    """The first frame's ms: a fresh process loads (or, on a cold cache, compiles) the numba kernels
    there, so it can be 100x a steady frame; ``ms_per_frame_mean`` includes it."""
    ms_per_frame_steady: float | None = None
    """Mean ms of the frames after the first: the steady-state cost (None for a one-frame run)."""
    lod_levels: dict | None = None
    """With a LOD mode: the quality of each level of detail (planner._lod_quality), ``pop_max_m``
    (the largest jump of a rendered foot at a level switch) and ``switches``; None with LOD off."""

    def to_json(self) -> dict:
        return asdict(self)


class Recorder:
    """Per-frame arrays (float32) and planning events, saved as one .npz.

    Give it to :func:`simulate`, which calls :meth:`capture` after every frame; then
    :meth:`save` writes the file (format ``footfall-recording``, :data:`RECORDING_VERSION`).

    Parameters
    ----------
    model : CrowdModel
        The crowd's static part.
    state : CrowdState
        Its state before the first frame (for the arrays' shapes).
    frames : int
        Frames to record.

    Attributes
    ----------
    frames : int
        Frames the arrays hold.
    arrays : dict of str to ndarray
        One array per quantity, first axis the frame: ``pelvis`` (frames, C, 3), ``orientation``
        (heading, pitch, roll), ``feet`` (frames, C, L, 3), ``in_stance``, ``swing_phase``,
        ``joint_angles``, ``ik_on``, ``foot_yaw``, ``speed``, ``stage_seconds`` and, with a LOD
        level, ``lod_level``.
    events : list of ndarray
        One row per planned foot: frame, character, leg, kind, valid, target, scores, goodnesses,
        counters, slice level (the columns the header names).

    Examples
    --------
    >>> import json, os, tempfile
    >>> import numpy as np
    >>> from footfall.planner import Recorder, init_crowd, simulate
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> recorder = Recorder(model, state, 5)
    >>> summary = simulate(model, state, 5, recorder=recorder)
    >>> recorder.arrays["pelvis"].shape, recorder.arrays["feet"].shape
    ((5, 2, 3), (5, 2, 8, 3))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = os.path.join(folder, "run.npz")
    ...     recorder.save(path, model, summary, {"scenario": "flat"})
    ...     with np.load(path) as recording:
    ...         header = json.loads(str(recording["header"]))
    ...         shape = recording["in_stance"].shape
    >>> header["format"], header["scenario"], shape
    ('footfall-recording', 'flat', (5, 2, 8))
    """

    def __init__(self, model: CrowdModel, state: CrowdState, frames: int):
        c, l = state.in_stance.shape
        s = state.angles.shape[2]
        self.frames = frames
        self.arrays = {
            "pelvis": np.zeros((frames, c, 3), np.float32),
            "orientation": np.zeros((frames, c, 3), np.float32),  # heading, pitch, roll
            "feet": np.zeros((frames, c, l, 3), np.float32),
            "in_stance": np.zeros((frames, c, l), np.bool_),
            "swing_phase": np.zeros((frames, c, l), np.float32),
            "joint_angles": np.zeros((frames, c, l, s), np.float32),
            "ik_on": np.zeros((frames, c), np.bool_),
            # What the metering of a run reads besides the pose, so that its figures can be recomputed
            # from the file: the yaw each foot was planned with (the foot's rectangle), the body's
            # commanded speed (the stride meter's 'steady': in float64, as a speed that ramps in steps
            # of acceleration x dt lands on the meter's bounds, 0.5 and 1.5 x goal, within float32's
            # rounding), and with a LOD mode each character's level.
            "foot_yaw": np.zeros((frames, c, l), np.float32),
            "speed": np.zeros((frames, c), np.float64),
            "stage_seconds": np.zeros((frames, len(STAGES)), np.float64),
        }
        if state.lod_level is not None:
            self.arrays["lod_level"] = np.zeros((frames, c), np.int8)
        self.events: list[np.ndarray] = []

    def capture(self, k: int, state: CrowdState, record) -> None:
        """Frame ``k``: the state after it and what its step did (``record``, planner._crowd.StepRecord)."""
        a = self.arrays
        a["pelvis"][k] = state.pelvis
        a["orientation"][k] = np.stack([state.heading, state.pitch, state.roll], axis=1)
        a["feet"][k] = state.feet
        a["in_stance"][k] = state.in_stance
        a["swing_phase"][k] = np.where(state.in_stance, 0.0, state.swing_t / np.maximum(state.swing_T, 1e-9))
        a["joint_angles"][k] = state.angles
        a["ik_on"][k] = state.ik_on
        a["foot_yaw"][k] = state.foot_yaws
        a["speed"][k] = state.speed
        if "lod_level" in a:
            a["lod_level"][k] = state.lod_level
        a["stage_seconds"][k] = [record.timings[s] for s in STAGES]
        plans = record.plans
        if plans is not None:
            out = plans.result
            ev = np.column_stack([np.full(plans.chars.size, k), plans.chars, plans.legs, plans.kinds, out.valid,
                                  out.target, out.scores, out.terms, out.counters, out.slice_level])
            self.events.append(ev)

    def save(self, path, model: CrowdModel, summary: SimulationSummary, meta: dict) -> None:
        from footfall import __version__

        width = 5 + 3 + 3 + N_TERMS + N_COUNTERS + 1
        events = np.concatenate(self.events) if self.events else np.zeros((0, width))
        header = {"format": RECORDING_FORMAT, "version": RECORDING_VERSION, "footfall": __version__,
                  "dt": model.dt, "creature": model.creature.name, "leg_names": list(model.creature.leg_names),
                  "stages": list(STAGES), "summary": summary.to_json(),
                  "event_columns": ["frame", "character", "leg", "kind", "valid", "target_x", "target_y", "target_z",
                                    "couple_score", "footprint_score", "trajectory_score"]
                  + [f"term_{i}" for i in range(N_TERMS)]
                  + list(COUNTERS) + ["slice_level_m"], **meta}
        if model.creature.source_toml is not None:  # a user's creature file travels with its recording
            header["creature_toml"] = model.creature.source_toml
        with atomic_path(path, suffix=".npz") as tmp:
            with open(tmp, "wb") as fh:
                np.savez_compressed(fh, header=np.array(json.dumps(header)), events=events, **self.arrays)


def realised_strides(feet, in_stance, pelvis, dt: float):
    """(speed (n,), stride (n,)) of every pair of consecutive touch-downs of the same foot, from
    per-frame arrays (frames, C, L, 3) feet, (frames, C, L) in_stance and (frames, C, 3) pelvis:
    stride = horizontal distance between the two footprints (one cycle of that foot), speed =
    the pelvis's horizontal displacement over the same frames / their duration (m/s).

    Parameters
    ----------
    feet : ndarray, shape (frames, C, L, 3)
        Foot positions per frame (a recording's ``feet``).
    in_stance : ndarray of bool, shape (frames, C, L)
        The feet on the ground per frame.
    pelvis : ndarray, shape (frames, C, 3)
        Pelvis positions per frame.
    dt : float
        s between two frames.

    Returns
    -------
    speed : ndarray, shape (n,)
        m/s, the pelvis's mean ground speed over each stride.
    stride : ndarray, shape (n,)
        m, each stride's length, sorted by character, leg, then frame.

    Examples
    --------
    One foot touching down at frames 2 and 4, half a second apart, while the pelvis moves
    0.125 m a frame:

    >>> import numpy as np
    >>> from footfall.planner import realised_strides
    >>> feet = np.zeros((5, 1, 1, 3))
    >>> feet[:, 0, 0, 0] = [0.0, 0.0, 0.5, 0.5, 1.0]
    >>> in_stance = np.array([True, False, True, False, True]).reshape(5, 1, 1)
    >>> pelvis = np.zeros((5, 1, 3))
    >>> pelvis[:, 0, 0] = 0.125 * np.arange(5)
    >>> realised_strides(feet, in_stance, pelvis, dt=0.5)   # 0.25 m in 1 s; a 0.5 m stride
    (array([0.25]), array([0.5]))
    """
    down = in_stance[1:] & ~in_stance[:-1]  # touched down at frame k + 1
    frames, chars, legs = np.nonzero(down)
    order = np.lexsort((frames, legs, chars))
    frames, chars, legs = frames[order] + 1, chars[order], legs[order]
    same = np.flatnonzero((chars[1:] == chars[:-1]) & (legs[1:] == legs[:-1]))
    k0, k1, c, leg = frames[same], frames[same + 1], chars[same], legs[same]
    stride = np.hypot(feet[k1, c, leg, 0] - feet[k0, c, leg, 0], feet[k1, c, leg, 2] - feet[k0, c, leg, 2])
    moved = np.hypot(pelvis[k1, c, 0] - pelvis[k0, c, 0], pelvis[k1, c, 2] - pelvis[k0, c, 2])
    return (moved / ((k1 - k0) * dt)).astype(np.float64), stride.astype(np.float64)


def asked_speed(model: CrowdModel, state: CrowdState) -> np.ndarray:
    """(C,) m/s: the speed asked of each character, capped where even the least duty factor does not fit
    its legs' stance windows (``model.speed_cap``): what the stride and speed bars are measured against.

    Parameters
    ----------
    model : CrowdModel
        The crowd's static part (its ``speed_cap``).
    state : CrowdState
        The crowd (its ``desired_speed``).

    Returns
    -------
    ndarray, shape (C,)
        m/s.

    Examples
    --------
    >>> from footfall.planner import asked_speed, init_crowd
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> asked_speed(model, state)                   # the flat scenario's 0.3 m/s: far under the cap
    array([0.3, 0.3])
    >>> model.speed_cap > 0.3
    True
    """
    return np.minimum(state.desired_speed, model.speed_cap)


def rest_points(model: CrowdModel, pelvis_xz, heading, spacing, legs) -> np.ndarray:
    """(n, 2) m, where legs ``legs`` of bodies at ``pelvis_xz`` facing ``heading`` with feet spacing
    ``spacing`` have their rest feet on the ground (x, z).

    Examples
    --------
    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> model = SimpleNamespace(rest_body=np.array([[0.2, 0.1]]))   # 0.2 m ahead, 0.1 m to the left
    >>> rest_points(model, np.zeros((1, 2)), np.array([np.pi / 2]), np.ones(1), np.array([0])).round(3)
    array([[-0.1,  0.2]])
    """
    rest = model.rest_body[legs] * np.asarray(spacing)[:, None]
    x, z = _rot_xz(np.asarray(heading), rest[:, 0], rest[:, 1])
    return np.asarray(pelvis_xz) + np.stack([x, z], axis=1)


STEADY_BAND = 0.2
"""A measured stride's body speed stays within this fraction of its mean speed at every frame (module
doc). Only touch-downs were checked before: 9 of 16 crowded runs (crates, crates-moving, mixed; 6
characters x 300 frames) then failed the per-stride bar on strides through dodges and swerves,
0 with the band (the 26 % of strides through such speed changes have a p90 error of 0.6)."""


class StrideMeter:
    """Per-stride error against the commanded stride law, measured frame by frame (module doc)."""

    def __init__(self, model: CrowdModel, state: CrowdState):
        c, l = state.in_stance.shape
        self.model = model
        self.goal = asked_speed(model, state)
        self.last_frame = np.full((c, l), -1, np.int64)
        self.last_foot = np.zeros((c, l, 2))
        self.last_pelvis = np.zeros((c, l, 2))
        self.last_rest = np.zeros((c, l, 2))
        self.last_speed = np.zeros((c, l))
        # the body's slowest and fastest since each foot's last touch-down
        self.slowest = np.zeros((c, l))
        self.fastest = np.zeros((c, l))
        self.errors: list[np.ndarray] = []
        self.levels: list[np.ndarray] = []  # the LOD level of each measured stride's character at its landing

    def update(self, k: int, state: CrowdState, landed: np.ndarray) -> None:
        from footfall.planner._timing import stride_frequency

        np.minimum(self.slowest, state.speed[:, None], out=self.slowest)
        np.maximum(self.fastest, state.speed[:, None], out=self.fastest)
        if not landed.any():
            return
        cs, ls = np.nonzero(landed)
        foot = state.feet[cs, ls][:, [0, 2]]
        pelvis = state.pelvis[cs][:, [0, 2]]
        rest = rest_points(self.model, pelvis, state.heading[cs], state.feet_spacing[cs], ls)
        speed = state.speed[cs]
        goal = self.goal[cs]
        seen = self.last_frame[cs, ls] >= 0
        if seen.any():
            a, b = cs[seen], ls[seen]
            duration = (k - self.last_frame[a, b]) * self.model.dt
            stride = np.hypot(*(foot[seen] - self.last_foot[a, b]).T)
            travel = np.hypot(*(pelvis[seen] - self.last_pelvis[a, b]).T)
            v = travel / duration
            # The foot's own share of the body's travel: its rest point's (1 on a straight stride).
            share = np.hypot(*(rest[seen] - self.last_rest[a, b]).T) / np.maximum(travel, 1e-300)
            steady = ((self.last_speed[a, b] >= 0.5 * goal[seen]) & (speed[seen] >= 0.5 * goal[seen])
                      & (self.last_speed[a, b] <= 1.5 * goal[seen]) & (speed[seen] <= 1.5 * goal[seen]) & (v > 0)
                      & (self.slowest[a, b] >= (1.0 - STEADY_BAND) * v) & (self.fastest[a, b] <= (1.0 + STEADY_BAND) * v)
                      & (share > 0))
            if steady.any():
                f = stride_frequency(self.model.timing, v[steady], self.model.leg_height)
                self.errors.append(np.abs(stride[steady] * f / (v[steady] * share[steady]) - 1.0))
                if state.lod_level is not None:
                    self.levels.append(state.lod_level[a][steady])
        self.last_frame[cs, ls] = k
        self.last_foot[cs, ls] = foot
        self.last_pelvis[cs, ls] = pelvis
        self.last_rest[cs, ls] = rest
        self.last_speed[cs, ls] = speed
        self.slowest[cs, ls] = speed
        self.fastest[cs, ls] = speed

    def by_level(self) -> tuple[np.ndarray, np.ndarray]:
        """(errors (n,), their characters' LOD levels (n,)) of every measured stride."""
        if not self.errors:
            return np.zeros(0), np.zeros(0, np.int8)
        return np.concatenate(self.errors), np.concatenate(self.levels)

    def summary(self) -> tuple[float | None, float | None, int]:
        if not self.errors:
            return None, None, 0
        e = np.concatenate(self.errors)
        return float(np.median(e)), float(np.percentile(e, 90)), int(e.size)


def arrived(model: CrowdModel, state: CrowdState) -> np.ndarray:
    """(C,) characters within ``arrive_radius`` of the last point of their route.

    Parameters
    ----------
    model : CrowdModel
        The crowd's static part (``model.controller.arrive_radius``).
    state : CrowdState
        The crowd (pelvis, route and route index).

    Returns
    -------
    ndarray of bool, shape (C,)
        The characters on the last leg of their route and within the arrive radius of its end.

    Examples
    --------
    >>> from footfall.planner import arrived, init_crowd
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> arrived(model, state)
    array([False, False])
    >>> state.pelvis[0, [0, 2]] = state.route[0, -1]   # put character 0 on its goal (one waypoint here)
    >>> arrived(model, state)
    array([ True, False])
    """
    last = state.route.shape[1] - 1
    goal = state.route[:, last]
    near = np.hypot(*(state.pelvis[:, [0, 2]] - goal).T) < model.controller.arrive_radius
    return (state.route_index == last) & near


def cruising(model: CrowdModel, state: CrowdState, goal_speed: np.ndarray) -> np.ndarray:
    """(C,) characters walking toward their goal and not yet braking for it: not on the last leg of
    their route, or farther from its end than the arrive radius plus the braking distance of
    ``goal_speed`` (planner._crowd.arrival_speed)."""
    ctl = model.controller
    last = state.route.shape[1] - 1
    distance = np.hypot(*(state.pelvis[:, [0, 2]] - state.route[:, last]).T)
    brake = ctl.arrive_radius + goal_speed**2 / (2.0 * ctl.acceleration)
    return (state.route_index < last) | (distance > brake)


def simulate(model: CrowdModel, state: CrowdState, frames: int, recorder: Recorder | None = None,
             progress=None, on_step=None) -> SimulationSummary:
    """Run ``frames`` steps; never raises on a foot that cannot step (it holds).

    ``progress(done)`` is called after each frame with the frames done; ``on_step(done, record)`` also
    gets what the step did (planner._crowd.StepRecord: its timings and the feet it planned).

    The metrics (module docstring) are measured after each frame, outside the frame times.

    Parameters
    ----------
    model : CrowdModel
        The crowd's static part.
    state : CrowdState
        Advanced in place by ``frames`` steps.
    frames : int
        Frames to run.
    recorder : Recorder, optional
        Captures every frame.
    progress : callable, optional
        ``progress(done)``.
    on_step : callable, optional
        ``on_step(done, record)``, ``record`` a :class:`StepRecord`.

    Returns
    -------
    SimulationSummary
        What the run measured.

    Examples
    --------
    >>> from footfall.planner import init_crowd, simulate
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> done = []
    >>> summary = simulate(model, state, 5, progress=done.append)
    >>> done, state.frame
    ([1, 2, 3, 4, 5], 5)
    >>> summary.frames, summary.characters, summary.finite, summary.collisions, summary.speed_asked
    (5, 2, True, 0, 0.3)
    """
    frame_ms = np.zeros(frames)
    stage_s = np.zeros((frames, len(STAGES)))
    counters = FrameCounters(model, state)
    prev_stance = state.in_stance.copy()
    finite = True
    strides = StrideMeter(model, state)
    levels = None
    if model.lod_mode != "off":
        from footfall.planner._lod_quality import LevelMeter

        levels = LevelMeter(model, state)
    n_chars = state.pelvis.shape[0]
    travelled = np.zeros(n_chars)
    walking_frames = np.zeros(n_chars)
    stance_feet = 0
    walking_feet = 0
    gait_frames = np.zeros(len(model.schedule.gaits))
    first_second = int(round(1.0 / model.dt))
    for k in range(frames):
        before = state.pelvis[:, [0, 2]].copy()
        record = step(model, state)
        timings = record.timings
        landed = state.in_stance & ~prev_stance
        strides.update(k, state, landed)
        walking = ~arrived(model, state)
        if k >= frames // 2:
            cruise = walking & cruising(model, state, strides.goal)
            travelled += np.where(cruise, np.hypot(*(state.pelvis[:, [0, 2]] - before).T), 0.0)
            walking_frames += cruise
        if k >= first_second and walking.any():
            stance_feet += int(state.in_stance[walking].sum())
            walking_feet += int(state.in_stance[walking].size)
        gait_frames += np.bincount(state.gait_index, minlength=gait_frames.size)
        stage_s[k] = [timings[s] for s in STAGES]
        frame_ms[k] = 1e3 * sum(timings.values())
        # -- metrics (not timed), on the rendered pose (planner._counters) --
        counters.update(state)
        if levels is not None:
            levels.update(state)
        prev_stance[:] = state.in_stance
        finite = finite and bool(np.isfinite(state.pelvis).all() and np.isfinite(state.feet).all()
                                 and np.isfinite(state.angles).all())
        if recorder is not None:
            recorder.capture(k, state, record)
        if on_step is not None:
            on_step(k + 1, record)
        if progress is not None:
            progress(k + 1)
    c = state.counters
    median, p90, measured = strides.summary()
    moving = walking_frames > 0
    reached = float(np.median(travelled[moving] / (walking_frames[moving] * model.dt))) if moving.any() else 0.0
    return SimulationSummary(
        frames=frames, characters=int(state.pelvis.shape[0]), steps=int(c["steps"]), collisions=counters.collisions,
        forbidden_footprints=int(c["forbidden_footprints"]), leg_crossings=counters.leg_crossings, max_stance_slip_m=counters.max_stance_slip_m,
        ik_residual_p95_m=counters.ik_residual_p95(), ms_per_frame_median=float(np.median(frame_ms)), ms_per_frame_mean=float(np.mean(frame_ms)),
        stage_ms_median={s: float(1e3 * np.median(stage_s[:, i])) for i, s in enumerate(STAGES)},
        plans=int(c["plans"]), holds=int(c["holds"]), replans=int(c["replans"]), boxed_ways=int(c["boxed_ways"]),
        cells_expanded=int(c["cells_expanded"]), couples_evaluated=int(c["couples_evaluated"]), finite=finite,
        stride_rel_error_median=median, stride_rel_error_p90=p90, strides_measured=measured,
        speed_asked=float(model.speed_asked), speed_cap=None if math.isinf(model.speed_cap) else float(model.speed_cap),
        speed_reached=reached, duty_factor_mean=stance_feet / walking_feet if walking_feet else None,
        body_overlaps=counters.body_overlaps, shared_foot_spots=counters.shared_foot_spots,
        stuck_seconds=counters.stuck_seconds, unavoidable_contacts=counters.unavoidable_contacts,
        max_pelvis_jump_m=counters.max_pelvis_jump_m, box_shoves=int(c["shoves"]),
        ms_per_frame_warmup=float(frame_ms[0]) if frames else None,
        ms_per_frame_steady=float(np.mean(frame_ms[1:])) if frames > 1 else None,
        lod_levels=levels.summary(*strides.by_level()) if levels is not None else None,
        gait_fractions={name: float(n / max(gait_frames.sum(), 1)) for name, n in zip(model.schedule.names, gait_frames)})
