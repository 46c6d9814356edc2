"""Crowd simulation: the character controller of every character, batched (paper §3, §6, §7).

Static model vs changing state, as in MJX/brax: :class:`CrowdModel` holds what does
not change during a run (creature, gait, weights, world raster, LOD settings);
:class:`CrowdState` holds every character's state in arrays (C characters x L legs).
:func:`step` advances the state by one fixed time step (1/30 s); its stages are
batched over all characters (numpy or numba kernels), never a Python loop over
characters.

Stages of a frame (timed one by one):
1. ``steer``: pelvis speed and heading toward the next waypoint, pushed away from
   forbidden boxes ahead, moved on the ground plane; feet feedback (§3.2, Fig. 7).
2. ``gait``: the needle advances; feet whose swing sector starts enter swing (§3.3); a foot
   still in the air then keeps its turn for when it lands.
3. ``swing``: swinging feet move along their trajectories at constant speed; landings.
4. ``requests``: feet to plan: new swings; swinging feet to re-plan (turn, speed
   change, trajectory invalidated by a moving box); stance feet out of reach or
   about to be hit by a moving box (they step away).
5. ``maps``: local maps of the characters that plan this frame (one kernel; with LOD, one
   more for the far characters' compact maps, ``planner._far_planning``).
6. ``plan``: every request in one kernel call (numba prange over the cores), each with its
   character's LOD budget (with LOD, the far characters' requests in calls of their own,
   ``planner._far_planning``); a foot with no valid couple holds (stays in stance and asks
   again next frame).
7. ``pelvis``: height, pitch and roll from convex hulls over the ground and feet.
8. ``ik``: CCD for every leg of every character that needs it (LOD: not off-screen; far
   characters: the closed-form two-bone solve).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from footfall.planner._batch import FootBatch, plan_batch
from footfall.planner._kernels_body import pelvis_from_hulls
from footfall.planner._counters import rendered_joints
from footfall.planner._kernels_controller import (
    advance_swings,
    count_forbidden_landings,
    legs_crossed_by_turn,
    points_in_boxes,
    push_out_of_boxes,
    stance_legs_crossing,
    stance_threatened,
    swing_points,
    swings_invalidated,
    swings_meet_moving_boxes,
    uncrossed_turns,
)
from footfall.planner._kernels_geometry import bowed_legs_onto_lines
from footfall.planner._kernels_maps import build_local_maps
from footfall.planner._lod import (
    FULL_SEARCH,
    LEVEL_FAR,
    LEVEL_FULL,
    LEVEL_HIDDEN,
    LodConfig,
    frame_crowd,
    lod_budgets,
    lod_levels,
    visibility,
)
from footfall.planner._maps import WorldRaster
from footfall.planner._params import PlannerConfig, SearchBudget
from footfall.planner._timing import stance_lead
from footfall.planner._weights import ScoringWeights, default_weights
from footfall.planner.layout import CNT_BOXED, CNT_COUPLES_3D, CNT_EXPANDED, KIND_NEW_SWING, LEG_FOOT, N_LEG_COLUMNS

DT = 1.0 / 30.0
ESCAPE_FROUDE = 0.5
"""The Froude number of a creature's top speed (issue 13: every creature walks up to Fr 0.5)."""
STANCE_SLACK_FRAMES = 1.0
"""Frames of the body's travel kept free at the rear end of a stance window (planner._workspace.stance_centres)."""
STAGES = ("steer", "gait", "swing", "requests", "maps", "plan", "pelvis", "ik")


@dataclass(frozen=True)
class ControllerConfig:
    """Character controller settings (units per field).

    Tuning guide: ``turn_rate`` limits how fast a heading changes; ``replan_heading``
    and ``replan_speed`` are the turn (rad) and relative speed change after which a
    swinging foot re-plans (§3.2); ``feedback_threshold`` (fraction of the rest
    radius) is when the mean offset between preferred and chosen footprints is
    'significant' and moves the pelvis, at ``feedback_gain`` per second.

    Sustainable speed: a body held because a stance leg cannot follow (the legs cannot take
    the strides this speed asks for) lowers the character's speed limit to ``hold_backoff``
    times the speed it was held at; the limit grows back by ``limit_recovery`` times the
    desired speed per second. Without it a character asked for more than its legs can do
    walks stop-and-go at full speed, and its strides are those of the speed it was asked
    for, not of the speed it keeps (issue 4: realised stride vs speed); with it, it settles
    just under the fastest walk its legs sustain, with the gait of that speed. A step begun
    while the body stands takes the swing time of the walk it resumes (``stage_plan``), and a
    foot in the air when its sector starts keeps its turn (``stage_gait``).

    The defaults, and the measurements behind the switches that are off, are in the source
    beside each field.

    Attributes
    ----------
    turn_rate : float
        rad/s, the fastest a heading changes.
    acceleration : float
        m/s^2, the fastest the speed changes.
    arrive_radius : float
        m, distance at which a waypoint counts as reached.
    avoid_margin : float
        m beyond the rest radius within which forbidden boxes push the heading.
    replan_heading, replan_speed, replan_spacing : float
        The turn (rad), relative speed change and relative change of the feet spacing after
        which a swinging foot re-plans.
    feedback_threshold, feedback_gain : float
        Feet feedback: the mean offset (x rest radius) that moves the pelvis, and the rate (1/s)
        at which it does.
    step_height_factor : float
        The swings' preferred lift, x standing height.
    reach_margin : float
        A stance foot beyond this fraction of its leg's reach steps.
    threat_margin, threat_horizon : float
        A moving box within ``threat_margin`` m of a stance foot, now or ``threat_horizon`` s
        from now, makes it step.
    bob_factor : float
        Pelvis bobbing amplitude, x standing height.
    pelvis_lag : float
        s, time constant of the body following its support hull (default 0.1); 0: none (the paper's
        pose).
    lookahead_frames, lookahead_every : int
        Stance feet the IK cannot follow this many frames ahead step now; frames between two
        look-ahead checks of a character.
    ik_slip_margin : float
        m, IK residual that counts as 'cannot follow'.
    ik_iterations, ik_swing_iterations, ik_restarts : int
        CCD sweeps per stance leg and frame (restarts included), per swinging leg and frame,
        and restarts of a stalled stance leg.
    hold_backoff, limit_recovery : float
        Sustainable speed (above): the limit after a hold, x the speed held at, in (0, 1]; its
        growth, x the desired speed per second, > 0.
    others_in_maps : bool
        Other characters' bodies and feet are forbidden in the local maps.
    avoid_others_feet : bool
        Other characters' feet near a planned footprint keep a foot's room.
    navigate : bool
        Steer round the static boxes and the regions looping boxes sweep (``planner._navigation``).

    Examples
    --------
    >>> from footfall.planner import ControllerConfig, init_crowd
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> slow_turns = ControllerConfig(turn_rate=0.75)          # half the default rate
    >>> spider = load_creature("spider")
    >>> model, state = init_crowd(load_scenario("flat"), spider, default_gait(spider), n_characters=1,
    ...                           controller=slow_turns)
    >>> model.controller.turn_rate, model.controller.acceleration
    (0.75, 1.0)
    >>> ControllerConfig(hold_backoff=0.0)
    Traceback (most recent call last):
    ...
    ValueError: ControllerConfig.hold_backoff: expected a number in (0, 1], got 0.0
    """

    turn_rate: float = 1.5  # rad/s
    acceleration: float = 1.0  # m/s^2
    arrive_radius: float = 0.3  # m
    avoid_margin: float = 0.35  # m beyond the rest radius where forbidden boxes push the heading
    replan_heading: float = 0.2  # rad
    replan_speed: float = 0.25  # relative
    replan_spacing: float = 0.1  # relative change of the feet spacing (Fig. 6)
    feedback_threshold: float = 0.15  # x rest radius
    feedback_gain: float = 2.0  # 1/s
    step_height_factor: float = 0.3  # x standing height
    reach_margin: float = 0.95  # stance feet beyond this fraction of the reach step
    threat_margin: float = 0.04  # m, a moving box this close to a stance foot makes it step
    threat_horizon: float = 0.5  # s, ... or this close to it where the box will be this much later
    bob_factor: float = 0.03  # x standing height, pelvis bobbing amplitude
    # s, time constant of the body following its support hull (planner._kernels_body); 0: none, the
    # paper's pose, which jumps with the hull (a foot lifting off takes its stance point out). 0.1 s
    # takes the frames whose pitch or roll moves > 0.1 rad in one frame from 901 to 1 over stairs,
    # crates and hills x the four creatures (6 characters, 300 frames, seeds 1-2), with the crowd
    # promises (collisions, shared spots, overlaps, feet in boxes) held at 0 either way (docs/locomotion.md, the body that follows its hull).
    pelvis_lag: float = 0.1
    lookahead_frames: int = 4  # stance feet the IK cannot follow this many frames ahead step now
    lookahead_every: int = 2  # frames between two look-ahead checks of a character (< lookahead_frames)
    ik_slip_margin: float = 3e-4  # m, IK residual that counts as 'cannot follow'
    ik_iterations: int = 16  # CCD sweeps per stance leg and frame, restarts included (warm started)
    ik_swing_iterations: int = 4  # CCD sweeps per swinging leg and frame, no restarts
    ik_restarts: int = 2  # restarts of a stalled stance leg (each scans poses: the costly part)
    hold_backoff: float = 0.85  # speed limit after a hold, x the speed held at
    limit_recovery: float = 0.1  # growth of the speed limit, x desired speed per second
    # Other characters' bodies and feet (stance feet, and swinging feet where they will land) are forbidden
    # in the local maps. Off by default: on `footfall evaluate` (6 scenarios x 4 creatures x 2 seeds, 4
    # characters, 300 frames) it takes shared foot spots 408 -> 4 but runs over the per-stride error bar
    # 20 -> 34 (crowded feet step around each other's stamps).
    others_in_maps: bool = False
    # Other characters' feet near a planned footprint keep a foot's room (stage_plan, _with_neighbours_feet).
    avoid_others_feet: bool = True
    # Steering aims at the first corner of the shortest way round the static boxes and the regions that
    # looping boxes sweep (planner._navigation). On by default since 2026-11-26: crowds of 8, 16 and 64
    # spiders x 600 frames on `mixed` and `crates` (seeds 1-3) go from 628 foot-frames in boxes, 149
    # crossing frames and 473 stuck s to 0, 10 and 225 s (overlaps and shared spots 0 both ways); the crowds
    # bar set (`footfall evaluate --seeds 10 --seed-base 3000 --characters 6 --frames 300`): stuck 117 ->
    # 71 s, slipping runs 1 -> 0, crossing frames 0 -> 1, runs over the per-stride bars 90 -> 96. Off
    # (`--no-navigate`): ORCA and the box push alone.
    navigate: bool = True

    def __post_init__(self) -> None:
        if not (self.pelvis_lag >= 0.0 and math.isfinite(self.pelvis_lag)):
            raise ValueError(f"ControllerConfig.pelvis_lag: expected a number of seconds >= 0, got {self.pelvis_lag!r}")
        if not 0.0 < self.hold_backoff <= 1.0:
            raise ValueError(f"ControllerConfig.hold_backoff: expected a number in (0, 1], got {self.hold_backoff!r}")
        if not self.limit_recovery > 0.0:
            raise ValueError(f"ControllerConfig.limit_recovery: expected a number > 0, got {self.limit_recovery!r}")


def _rot_xz(heading, forward, lateral):
    c = np.cos(heading)
    s = np.sin(heading)
    return forward * c - lateral * s, forward * s + lateral * c


@dataclass(frozen=True)
class CrowdModel:
    """The static part of a crowd: what does not change during a run (creature, gait, weights,
    world raster, LOD settings). :func:`init_crowd` makes it; :func:`step` only reads it.

    Its fields are described where they are defined, in the source of ``footfall.planner._crowd``
    (``planner/_crowd.py``). The ones most often read:

    Attributes
    ----------
    creature : scenarios.Creature
        The characters' creature.
    gait, schedule : scenarios.Gait, GaitSchedule
        Its slowest gait, and its gaits by speed (``planner._gait_schedule``).
    timing : GaitTiming
        The gait timing (stride and duty laws).
    weights, config, controller : ScoringWeights, PlannerConfig, ControllerConfig
        The scoring weights, the planner parameters and the controller settings.
    lod, lod_mode : LodConfig, str
        The level-of-detail settings and mode (``"off"``, ``"on"`` or ``"zoomed"``).
    raster : WorldRaster
        The static world at the planner's cell size.
    dt : float
        s, the fixed time step (1/30 s).
    speed_asked, speed_cap : float
        m/s, the scenario's speed and the fastest the legs carry at the stride law.

    Examples
    --------
    >>> from footfall.planner import init_crowd, step
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> model.n_legs, model.hips_body.shape, round(model.dt, 4)
    (8, (8, 3), 0.0333)
    >>> model.lod_mode, model.config.cell_size, model.speed_asked
    ('off', 0.07, 0.3)
    """

    creature: object
    gait: object
    timing: object
    weights: ScoringWeights
    config: PlannerConfig
    controller: ControllerConfig
    lod: LodConfig
    lod_mode: str
    raster: WorldRaster
    camera: object  # scenarios.Camera (used by lod_mode 'on' only as the look direction hint)
    dt: float
    feet_spacing: float
    hips_body: np.ndarray  # (L, 3) forward, up, lateral
    rest_body: np.ndarray  # (L, 2) forward, lateral (scaled by feet_spacing)
    reach: np.ndarray  # (L,) leg reach, m
    leg_static: object  # IK statics (planner._ik)
    fixed_budget: SearchBudget | None = None  # with lod_mode 'off': every search gets this budget (evaluation sweeps)
    schedule: object = None  # planner._gait_schedule.GaitSchedule: the gaits by speed (gait: the slowest)
    stance_window: np.ndarray | None = None  # (L, 2) body-forward interval each leg carries a stance foot over
    speed_cap: float = math.inf  # m/s, the fastest speed the legs carry at the stride law (planner._workspace)
    # What sets speed_cap: 'windows' (the least duty factor's sweep fills the narrowest stance window),
    # 'frames' (a stride cycle would last under MIN_CYCLE_FRAMES), 'territories' (a sweep would reach a
    # neighbouring leg's territory) or 'neighbours' (a landing spot would come within a foot's room of the
    # neighbouring leg's lift-off spot): planner._workspace.
    speed_cap_reason: str = "windows"
    speed_asked: float = 0.0  # m/s, the scenario's speed before the cap
    step_height: float = 0.0  # m, the swings' preferred lift (paper §3.1 'step height')
    # m/s, the fastest a character walks to get out of the way (of a box, of another): its legs' escape cap
    # (CreatureWalk.escape_cap), at most Froude number ESCAPE_FROUDE. A box at least this fast cannot be escaped.
    top_speed: float = math.inf
    height_range: np.ndarray | None = None  # (L, 2) m, least and most pelvis height above each foot (planner._workspace)
    tuck_reach: np.ndarray | None = None  # (L, len(TUCK_REACHES)) the tuck points' reaches the legs reach (planner._workspace)
    # The far levels of detail's planner settings (planner._far_planning): the first try and the fallback,
    # both on compact maps; None with lod_mode 'off' (every character plans as the paper does).
    far_first: PlannerConfig | None = None
    far_fallback: PlannerConfig | None = None
    avoid_radius: float = math.nan  # m, the disc its characters keep clear of each other (avoid_radius)
    # With ControllerConfig.navigate: the static boxes and the regions looping boxes sweep, grown by the way's
    # clearance, and their visibility graph (planner._navigation, static_way_around): steering aims at the first
    # corner of the shortest way round them. None: straight at the route's points.
    way_around: object = None

    @property
    def n_legs(self) -> int:
        return int(self.hips_body.shape[0])

    @property
    def leg_height(self) -> float:
        """h of the Froude number: the mean hip height when standing, m."""
        from footfall.planner._timing import hip_height

        return hip_height(self.creature)

    @cached_property
    def other_legs(self) -> np.ndarray:
        """(L, L - 1) for each leg, the indices of the others."""
        n = self.n_legs
        return np.array([[j for j in range(n) if j != i] for i in range(n)], dtype=np.int64).reshape(n, n - 1)

    @cached_property
    def leg_sides(self) -> np.ndarray:
        """(L,) each leg's side of the body's midline: +1 left, -1 right, 0 for a hip on the midline
        (within 1e-3 rest radii: a robot5's front leg; planner._workspace.leg_sides)."""
        from footfall.planner._workspace import leg_sides

        return leg_sides(self.hips_body, self.rest_body)

    @property
    def rest_radius(self) -> float:
        return float(np.max(np.hypot(self.rest_body[:, 0], self.rest_body[:, 1])))


@dataclass
class CrowdState:
    """Every character's changing state, in arrays over C characters and L legs: pelvis pose and
    speed, route, feet and their swings, gait manager, joint angles, counters. :func:`init_crowd`
    makes it; :func:`step` changes it in place.

    Its fields are described where they are defined, in the source of ``footfall.planner._crowd``
    (``planner/_crowd.py``). The ones most often read:

    Attributes
    ----------
    t, frame : float, int
        Time (s) and the number of frames stepped.
    pelvis : ndarray, shape (C, 3)
        Pelvis positions, world (x, y, z).
    heading, pitch, roll, speed : ndarray, shape (C,)
        Body orientation (rad) and ground speed (m/s).
    feet : ndarray, shape (C, L, 3)
        Where each foot is, on the ground or in the air.
    in_stance : ndarray of bool, shape (C, L)
        The feet on the ground.
    gaits : GaitManagerState
        The gait manager of the crowd.
    angles : ndarray, shape (C, L, S + 1)
        Joint angles from the IK.
    counters : dict
        Running totals: ``steps``, ``plans``, ``holds``, ``replans``...

    Examples
    --------
    >>> from footfall.planner import init_crowd, step
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> state.pelvis.shape, state.feet.shape, state.in_stance.shape
    ((2, 3), (2, 8, 3), (2, 8))
    >>> state.frame, bool(state.in_stance.all())    # every foot stands at the start
    (0, True)
    """

    t: float
    frame: int
    pelvis: np.ndarray  # (C, 3)
    heading: np.ndarray  # (C,)
    pitch: np.ndarray
    roll: np.ndarray
    speed: np.ndarray
    desired_speed: np.ndarray
    route: np.ndarray  # (C, R, 2)
    route_index: np.ndarray  # (C,)
    feedback: np.ndarray  # (C, 2) mean chosen - preferred offset, EMA
    feet: np.ndarray  # (C, L, 3)
    in_stance: np.ndarray  # (C, L) bool
    wants_swing: np.ndarray  # (C, L) bool: the gait asked for a swing not yet planned
    sector_missed: np.ndarray  # (C, L) bool: the needle entered the foot's sector while it was in the air
    stalled_s: np.ndarray  # (C,) s the body's legs (not a hold) have kept it at rest while it asks to walk
    waited_s: np.ndarray  # (C,) s ORCA has held the character back for a walking neighbour (wait_for_others)
    right_of_way_s: np.ndarray  # (C,) s left of the right of way a wait of WAIT_LIMIT_S earned (planner._kernels_avoidance)
    swing_t: np.ndarray
    swing_T: np.ndarray
    trajectories: np.ndarray  # (C, L, K, 3)
    swing_target: np.ndarray  # (C, L, 3)
    plan_heading: np.ndarray  # (C, L)
    plan_speed: np.ndarray
    feet_spacing: np.ndarray  # (C,) scale of the rest feet, user-controlled (paper Fig. 6)
    plan_spacing: np.ndarray  # (C, L) the scale a swing was planned with
    foot_yaws: np.ndarray  # (C, L)
    gaits: object  # planner._gait.GaitManagerState
    angles: np.ndarray  # (C, L, S + 1)
    residual: np.ndarray  # (C, L)
    ik_on: np.ndarray  # (C,) bool, IK solved this frame
    fk_feet: np.ndarray  # (C, L, 3) feet where the IK put them
    pelvis_base: np.ndarray  # (C,) m, the pelvis height before the bob, which follows the hull with a lag
    pelvis_rise: np.ndarray  # (C,) m, change of pelvis height over the last frame
    body_held: np.ndarray  # (C,) bool: a stance foot could not follow and could not step: wait a frame
    speed_limit: np.ndarray  # (C,) m/s, the sustainable speed learnt from holds (inf: never held)
    last_move: np.ndarray  # (C, 2) m, the pelvis's move on the ground in the last steer stage
    cannot_follow: np.ndarray  # (C, L) bool: the last look-ahead found the leg cannot follow its stance foot
    unfollowed: np.ndarray  # (C, L) bool: a stance foot whose leg lost it (the pose was taken back): it steps next
    pose_before: np.ndarray  # (C, 7) pelvis x, y, z, heading, pitch, roll, base height at the start of the frame
    gait_index: np.ndarray  # (C,) int: the schedule's gait each character walks with (or moves toward)
    stride_frequency: np.ndarray  # (C,) Hz, the needle's rate at the last gait stage
    turn_wanted: np.ndarray  # (C,) rad, the turn the steering asked of the last frame, before the stance feet bound it
    turn_left: np.ndarray  # (C,) rad, the turn the steering still asks after the last frame's (stage_plan predicts it)
    turn_made: np.ndarray  # (C,) rad, the turn the last steer stage made (its stance feet may hold it under the rate)
    threatened: np.ndarray  # (C, L) bool: a moving box reaches the stance foot within the threat horizon
    tucked: np.ndarray  # (C, L) bool: a threatened foot with no footprint, held up near its hip (tuck_swings)
    escaping: np.ndarray  # (C,) bool: the last steer stage turned the character out of a moving box's lane
    shoved: np.ndarray  # (C,) bool: the last steer stage moved the body by a shove (shove_out_of_moving_boxes)
    shoved_onto_feet: np.ndarray  # (C, L) bool: a foot in the air the last shove carried onto another's foot (it re-plans)
    goal_speed: np.ndarray  # (C,) m/s: the speed the last steer stage headed for (0 at the goal; braking before it)
    speed_wanted: np.ndarray  # (C,) m/s: the speed the last steer stage asked after turns, avoidance and limits
    blocks_escape: np.ndarray  # (C, L) bool: a stance foot that stops an escaping character's turn
    crossed: np.ndarray  # (C, L, L) bool: pairs of legs standing at the start of the last frame drawn crossed at its end
    counters: dict = field(default_factory=dict)
    lod_level: np.ndarray | None = None  # (C,) int8: each character's level of detail (planner._lod, LEVEL_*)
    near_moving_box: np.ndarray | None = None  # (C,) bool: a moving box is near: it plans as a near character
    aim_node: np.ndarray | None = None  # (C,) int: the corner of the way round static boxes aimed at (-1: none)
    # (C, L, L) bool: [c, l, j] the swing of foot l was planned with foot j left out, as lifting before it lands
    # (lifted_before); while j still stands waiting for its own footprint, l plans again (stage_requests)
    counted_gone: np.ndarray | None = None


def hips_world(model: CrowdModel, state: CrowdState) -> np.ndarray:
    """(C, L, 3) hip positions: body-frame hips rotated by heading, pitch and roll
    (the rotation of :func:`planner._ik.body_rotation`)."""
    return state.pelvis[:, None, :] + _hip_offsets(model, state, slice(None))


def _hip_offsets(model: CrowdModel, state: CrowdState, chars) -> np.ndarray:
    """(len(chars), L, 3) the hips of characters ``chars`` (an index or a slice) from their pelvis."""
    from footfall.planner._ik import body_rotation

    # (C, 1, 3, 3): forward, up, left
    rotation = body_rotation(state.heading[chars], state.pitch[chars], state.roll[chars])[:, None]
    h = model.hips_body[None, :, None, :]  # (1, L, 1, 3)
    # R @ hip written out, in the order einsum summed it (x + z, then y: the same bits; einsum's order
    # follows its operands' memory layout), at two thirds of its cost for a crowd.
    return (rotation[..., 0] * h[..., 0] + rotation[..., 2] * h[..., 2]) + rotation[..., 1] * h[..., 1]


def sustained_speed(state: CrowdState) -> np.ndarray:
    """(C,) m/s: the speed each character heads for while it walks: the speed asked of it, held to the
    limit its legs showed they sustain (lowered by holds, ControllerConfig.hold_backoff).

    Parameters
    ----------
    state : CrowdState
        The crowd (its ``desired_speed`` and ``speed_limit``).

    Returns
    -------
    ndarray, shape (C,)
        m/s.

    Examples
    --------
    >>> from footfall.planner import init_crowd, sustained_speed
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> sustained_speed(state)                      # never held: the scenario's 0.3 m/s
    array([0.3, 0.3])
    >>> state.speed_limit[0] = 0.25                 # as a hold would lower it
    >>> sustained_speed(state)
    array([0.25, 0.3 ])
    """
    return np.minimum(state.desired_speed, state.speed_limit)


def _landing_feet(state: CrowdState) -> np.ndarray:
    """(C, L, 3) where each foot stands, or, swinging, lands."""
    return np.where(state.in_stance[..., None], state.feet, state.swing_target)


def _boxes_now(model: CrowdModel, t: float):
    obs = model.raster.obstacles
    if len(obs.yaws) == 0:
        z3 = np.zeros((0, 3))
        return z3, z3, np.zeros(0), np.zeros(0, np.bool_), np.zeros(0, np.bool_)
    centres, yaws = obs.poses_at(t)
    return (np.ascontiguousarray(centres, dtype=np.float64), np.ascontiguousarray(obs.sizes, dtype=np.float64),
            np.ascontiguousarray(yaws, dtype=np.float64), np.ascontiguousarray(obs.forbidden, dtype=np.bool_),
            np.ascontiguousarray(~np.asarray(obs.is_static), dtype=np.bool_))


def _planning_boxes(model: CrowdModel, state: CrowdState, boxes):
    """The boxes a foot is planned against: every box where it is now, and each moving box also where
    it will be ``threat_horizon`` from now (about a swing and the first frames of the stance that
    follows), so that a foot does not land where a crate is heading and is lifted again at once."""
    return _boxes_also_at(model, boxes, state.t + model.controller.threat_horizon)


def _boxes_also_at(model: CrowdModel, boxes, t: float):
    """``boxes`` (as :func:`_boxes_now` or this gives them) and, appended, each of the scenario's moving
    boxes where it is at time ``t``."""
    centres, sizes, yaws, forbidden, moving = boxes
    m = np.flatnonzero(moving[:len(model.raster.obstacles.yaws)])
    if not m.size:
        return boxes
    later_centres, _, later_yaws, _, _ = _boxes_now(model, t)
    return (np.ascontiguousarray(np.vstack([centres, later_centres[m]])), np.ascontiguousarray(np.vstack([sizes, sizes[m]])),
            np.ascontiguousarray(np.concatenate([yaws, later_yaws[m]])),
            np.ascontiguousarray(np.concatenate([forbidden, forbidden[m]])),
            np.ascontiguousarray(np.concatenate([moving, moving[m]])))


def _wrap(a):
    return (a + np.pi) % (2.0 * np.pi) - np.pi


# ----------------------------------------------------------------------------- stages
def stage_steer(model: CrowdModel, state: CrowdState, boxes) -> None:
    ctl = model.controller
    dt = model.dt
    n = state.pelvis.shape[0]
    rows = np.arange(n)
    last = state.route.shape[1] - 1
    target = state.route[rows, state.route_index]
    d = target - state.pelvis[:, [0, 2]]
    dist = np.hypot(d[:, 0], d[:, 1])
    advance = (dist < ctl.arrive_radius) & (state.route_index < last)
    if advance.any():
        state.route_index[advance] += 1
        target = state.route[rows, state.route_index]
        d = target - state.pelvis[:, [0, 2]]
        dist = np.hypot(d[:, 0], d[:, 1])
    arrived = (dist < ctl.arrive_radius) & (state.route_index == last)
    if model.way_around is not None and model.way_around.n_boxes:
        # Round the static boxes: aimed straight at a route point behind a forbidden one, ORCA slid the
        # character along its face at a few cm/s (planner._navigation).
        from footfall.planner._navigation import REFRESH_FRAMES, aim_points

        if state.aim_node is None:
            state.aim_node = np.full(n, -1, np.int64)
        aim, _ = aim_points(model.way_around, state.pelvis[:, [0, 2]], target, state.aim_node, state.frame,
                            REFRESH_FRAMES)
        to_aim = aim - state.pelvis[:, [0, 2]]
        direction = to_aim / np.maximum(np.hypot(to_aim[:, 0], to_aim[:, 1]), 1e-9)[:, None]
    else:
        direction = d / np.maximum(dist, 1e-9)[:, None]
    centres, sizes, yaws, forbidden, _ = boxes
    if forbidden.any():
        bc = centres[forbidden][:, [0, 2]]
        br = 0.5 * np.hypot(sizes[forbidden, 0], sizes[forbidden, 2])
        rel = state.pelvis[:, None, [0, 2]] - bc[None, :, :]  # (C, B, 2) box -> pelvis
        rn = np.maximum(np.hypot(rel[..., 0], rel[..., 1]), 1e-9)
        gap = rn - br[None, :] - model.rest_radius
        weight = np.clip(1.0 - gap / ctl.avoid_margin, 0.0, 1.0) ** 2
        ahead = (-(rel[..., 0] * direction[:, None, 0] + rel[..., 1] * direction[:, None, 1]) / rn) > -0.2
        push = ((weight * ahead)[..., None] * rel / rn[..., None]).sum(axis=1)
        # Keep right around boxes too: a box dead ahead pushes straight back, and the push and ORCA
        # would hold the character in front of it (a symmetric standstill).
        veer = (weight * ahead).max(axis=1) * math.tan(KEEP_RIGHT)
        push += veer[:, None] * np.column_stack([direction[:, 1], -direction[:, 0]])
        direction = direction + 1.5 * push
        direction /= np.maximum(np.hypot(direction[:, 0], direction[:, 1]), 1e-9)[:, None]
    # Out of a moving box's lane: a character the box will reach within LANE_HORIZON heads out of
    # its path, to the nearer side, before ORCA (which, for a walker that only goes forward, settles
    # on slowing down in the lane until the box is on it).
    box_velocity = _box_velocities(model, state.t, centres)
    direction, in_lane = _lane_exit(model, state, direction, boxes, box_velocity)
    # Reciprocal avoidance (ORCA) of the other characters and of forbidden or moving boxes: the
    # velocity closest to the preferred one that stays clear for the horizon.
    # Arriving: on the last leg of its route a character brakes in time (at its acceleration) to
    # stop within the arrive radius; braking only once inside it overshot the goal by a metre at a trot.
    braking = np.where(state.route_index == last, arrival_speed(dist, ctl.arrive_radius, ctl.acceleration), np.inf)
    goal_speed = np.where(arrived, 0.0, np.minimum(sustained_speed(state), braking))
    # Out of a moving box's lane faster than asked (FLEE_SPEED): an ant walking out of a 0.15 m/s
    # crate's lane at its asked 0.3 m/s was still in it when ORCA's velocity flipped and it stopped to
    # turn.
    if math.isfinite(model.top_speed):
        goal_speed = np.where(in_lane & ~arrived, np.maximum(goal_speed, FLEE_SPEED * model.top_speed), goal_speed)
    state.goal_speed = goal_speed
    preferred = direction * goal_speed[:, None]
    velocity, avoided, among_others, neighbours = _avoid(model, state, preferred, dist, boxes, box_velocity, in_lane)
    wait_for_others(model, state, preferred, velocity, neighbours)
    # An escaper whose ORCA velocity heads somewhere worse than its way, looked ahead against the boxes,
    # follows its way where that keeps it clear of the others (planner._escape: ORCA's velocity is
    # holonomic; for a body that walks along its heading it flipped from ahead to behind as a crate closed in).
    escapers = np.flatnonzero(in_lane & avoided & (goal_speed > 0.0))
    if escapers.size:
        from footfall.planner._escape import clear_of_others, orca_worse

        escapers = escapers[orca_worse(model, state, escapers, direction[escapers], velocity[escapers],
                                       goal_speed[escapers], escape_boxes(boxes))]
        escapers = escapers[clear_of_others(model, state, escapers, preferred[escapers])]
        velocity[escapers] = preferred[escapers]
        avoided[escapers] = False
    fast = np.hypot(velocity[:, 0], velocity[:, 1]) > 1e-6
    # Escaping a moving box's lane, ORCA's velocity can point back along the lane, away from the box:
    # as it crosses behind the character its angle flipped between +2.9 and -2.9 rad and the turn
    # with it (a spider turned back and forth on the spot for a second, head-on to a crate). Such a
    # character turns out of the lane, to the side the lane exit chose, and walks only as far along
    # its heading as ORCA's velocity goes.
    backward = in_lane & avoided & fast & ((velocity * direction).sum(axis=1) < 0.0)
    backward &= ~among_others
    # The heading follows ORCA's velocity wherever it is not the one asked: avoiding, or kept right of a
    # neighbour (_avoid) and otherwise unhindered. Following it only while avoiding, an ant walking
    # abreast of another on `stairs` turned +-0.05 rad every frame between its way and the kept-right
    # velocity, avoiding one frame and not the next (seed 3000, character 1, frames 15-140).
    steered = np.hypot(*(velocity - preferred).T) > 1e-9
    to_velocity = velocity / np.maximum(np.hypot(*velocity.T), 1e-12)[:, None]
    # A velocity more than a quarter turn off the way is a yield: the heading goes between it and the way,
    # by the share of its pace the velocity keeps (all the way to it at the pace, none at a standstill), and
    # the body walks along its heading only as far as the velocity goes. Turned to face a slow yielding
    # velocity, a walker faced away from its way once the other had passed and came round again at its
    # turn rate: a quadruped yielding to a neighbour at 0.1 m/s turned from its way to 2.6 rad off it and
    # back, 3.4 rad in all (crates-moving, seed 18102, character 4: stuck 0.13 s; docs/crowds.md has the
    # runs this and SEPARATION_S changed). Not for an escaper: its flight out of a lane has rules of its own
    # (above; among neighbours ORCA's velocity leads it).
    fwd_now = np.stack([np.cos(state.heading), np.sin(state.heading)], axis=1)
    retreat = steered & fast & ~in_lane & ((to_velocity * direction).sum(axis=1) < 0.0)
    if retreat.any():
        kept = np.clip(np.hypot(*velocity.T) / np.maximum(goal_speed, 1e-12), 0.0, 1.0)[:, None]
        between = kept * to_velocity + (1.0 - kept) * direction
        length = np.hypot(*between.T)
        # (opposite and at half the pace, the two cancel: the heading stays)
        between = np.where((length > 1e-6)[:, None], between / np.maximum(length, 1e-12)[:, None], fwd_now)
        to_velocity = np.where(retreat[:, None], between, to_velocity)
    along_now = (velocity * fwd_now).sum(axis=1)
    direction = np.where((steered & fast & ~backward)[:, None], to_velocity, direction)
    desired = np.arctan2(direction[:, 1], direction[:, 0])
    turn = _wrap(desired - state.heading)
    # A held body keeps its whole pose (a turn swings the hips away from the stance feet just as a
    # move does), and a character at its goal stops turning toward it.
    turn[state.body_held | (arrived & ~avoided)] = 0.0
    # One turn rate, standing or walking. A body turning on the spot swings its hips across its stance
    # feet, and it once turned at a quarter of the rate when standing; the stance feet's turn bounds
    # and the uncrossing turn below now keep its legs apart, and the slow turn left a quadruped
    # avoiding a neighbour, its way behind it, standing 2-7 s while it came round (crates-moving, every
    # seed of the bar set). Without it: the bar set's stuck 45 -> 30 s, per-stride runs 19 -> 16,
    # crossing frames 0 -> 0; the small crowded sets' stuck 981 -> 651 s, feet in boxes 36 -> 33.
    rate = ctl.turn_rate * dt
    state.escaping = in_lane
    state.turn_wanted = np.clip(turn, -rate, rate)
    lo, hi = stance_turn_bounds(model, state)
    applied = uncrossing_turn(model, state, np.clip(state.turn_wanted, lo, hi))
    # No turn into another body, as no step (bodies_apart): standing 7 cm beside another ant, one turned
    # its body into the other's (mixed, 64 ants, seed 3, characters 34 and 19, with the hysteresis on
    # can_make_way tried in session 52: docs/crowds.md, crowds and moving boxes).
    applied[~bodies_turn_clear(model, state, applied, neighbours)] = 0.0
    state.heading = _wrap(state.heading + applied)
    # What is left of the turn as far as the stance feet let it go on (they bound it each frame until
    # they lift): a quadruped's foot planned for the whole turn asked, its stance feet then holding the
    # body, landed across its midline (`crates-moving`, seed 4001, character 3, frame 176).
    state.turn_left = np.clip(turn, lo, hi) - applied
    state.turn_made = applied
    forward = np.cos(np.clip(turn, -np.pi / 2, np.pi / 2))
    # Unhindered, a character keeps walking (at least 30 %) while it turns, an escaper at its flee speed
    # held to FLEE_GAIN_MAX of the asked one; avoiding, it walks only as far along its heading as the
    # avoiding velocity goes (sideways into a neighbour is no way out).
    unhindered = np.where(in_lane, np.minimum(goal_speed, FLEE_GAIN_MAX * state.desired_speed), state.desired_speed)
    walked = np.where(retreat, np.maximum(along_now, 0.0), np.hypot(velocity[:, 0], velocity[:, 1]) * forward)
    v_des = np.where(avoided, walked,
                     np.where(arrived, 0.0, unhindered * np.maximum(0.3, forward)))
    along = velocity[:, 0] * np.cos(state.heading) + velocity[:, 1] * np.sin(state.heading)
    v_des = np.where(backward, np.maximum(along, 0.0), v_des)
    # The speed limit learnt from holds grows back (ControllerConfig: sustainable speed).
    free = ~state.body_held
    state.speed_limit[free] += ctl.limit_recovery * state.desired_speed[free] * dt
    v_des = np.minimum(v_des, np.where(avoided, np.maximum(state.speed_limit, v_des), state.speed_limit))
    v_des = np.minimum(v_des, braking)
    state.speed_wanted = v_des
    state.speed = state.speed + np.clip(v_des - state.speed, -ctl.acceleration * dt, ctl.acceleration * dt)
    # Legs that reach: no faster than keeps every stance foot inside its leg's stance window until
    # the needle lifts it (planner._workspace). The cap falls gradually as a foot nears the rear
    # of its window, so the body slows down instead of stopping dead on a hold.
    state.speed = np.minimum(state.speed, stance_speed_cap(model, state))
    # The body never outruns its legs: a character with a stance foot its leg cannot follow,
    # and no room to lift it, waits.
    state.speed[state.body_held] = 0.0
    fwd = np.stack([np.cos(state.heading), np.sin(state.heading)], axis=1)
    # No step into another body: ORCA's half-planes are linearised about each body's velocity along
    # its heading, and a walker still turning toward its preferred velocity walked into a spider
    # standing in its way (1000 spiders, mixed, seed 2: 122 overlapping frames).
    state.speed[~bodies_apart(model, state, fwd * (state.speed * dt)[:, None], neighbours)] = 0.0
    state.last_move = fwd * (state.speed * dt)[:, None]
    state.pelvis[:, [0, 2]] += state.last_move
    # A moving box that reaches a body anyway shoves it (the defined fallback when the escape failed:
    # the tucked feet go with the body, none is left under the box).
    shove_out_of_moving_boxes(model, state, boxes, neighbours)
    # Feet feedback (§3.2): a significant mean offset between preferred and chosen footprints moves the pelvis.
    fb = state.feedback
    significant = ((np.hypot(fb[:, 0], fb[:, 1]) > ctl.feedback_threshold * model.rest_radius) & ~state.body_held
                   & ~arrived)
    if significant.any():
        idx = np.flatnonzero(significant)
        move = np.zeros((n, 2))
        move[idx] = fb[idx] * min(1.0, ctl.feedback_gain * dt)
        # The feet's pull moves no body into another (it drew two standing spiders, each turning toward
        # the other, into one: 1000 spiders, mixed, seed 0).
        idx = idx[bodies_apart(model, state, move, neighbours)[idx]]
        move = move[idx]
        state.pelvis[idx, 0] += move[:, 0]
        state.pelvis[idx, 2] += move[:, 1]
        fb[idx] -= move


SHOVE_MARGIN = 0.01
"""m a shoved body's feet in the air keep from the box."""
SHOVE_ROUNDS = 3
"""Pushes per shoved body and frame: each measures the feet in the air again (a push along one face's
normal can leave a foot near a corner short of the margin)."""


def _box_gap_out(x, z, centre, half, yaw):
    """(signed gap of (x, z) to a box's rectangle, negative inside; (2,) unit direction from the box's
    nearest point (:func:`planner._kernels_avoidance._nearest_on_box`, ORCA's) out to it, or out of the
    nearer face from inside)."""
    from footfall.planner._kernels_avoidance import _nearest_on_box

    qx, qz, inside = _nearest_on_box(x, z, centre[0], centre[1], half[0], half[1], yaw)
    dx, dz = x - qx, z - qz
    norm = math.hypot(dx, dz)
    if norm <= 1e-12:  # on the boundary: out along the box's own x
        return 0.0, np.array([math.cos(yaw), math.sin(yaw)])
    sign = -1.0 if inside else 1.0
    return sign * norm, np.array([sign * dx / norm, sign * dz / norm])


def shove_out_of_moving_boxes(model: CrowdModel, state: CrowdState, boxes, neighbours=None) -> None:
    """A moving box (``boxes`` as :func:`_boxes_now` gives them) that a character's escape did not keep
    clear shoves it: where the box comes nearer to a foot in the air, or to the hip of its leg, than the
    foot's half diagonal and :data:`SHOVE_MARGIN`, the body and its feet in the air (their swings too) move
    straight out from the box's nearest point to the pelvis until every such foot and hip keeps that
    margin; feet in stance stay where they stand (a threatened one steps away or tucks:
    ``stage_requests``). Counted in ``state.counters["shoves"]`` (characters shoved, per frame;
    ``box_shoves`` in a run's summary).

    The hips since 2026-11-28: a tucked foot is held near its hip (:data:`TUCK_REACHES`), where the IK may
    draw it centimetres off its tuck point. With the feet alone, an ant between its neighbours and
    ``mixed``'s looping crate had its tucked feet drawn 0.5-3.4 cm inside the crate in 3 frames (64 ants,
    seed 2, character 34: the crowd bar's 3 feet in boxes on session 51's machine; 0 with the hips). The
    crowds issue's bar sets (seeds 3000-3009, 4000-4009) have no shove and ran bit for bit the same.

    Before it (2026-11-27), a tucked foot whose tuck points the box already covered stayed under the box
    while the body was still beside it: the crowd bar's 64 characters (``mixed`` and ``crates``, seeds
    1-3, 600 frames) had 56 foot-frames in boxes, all ``mixed`` ants beside its looping crates, nearly all
    tucked feet; with it, 5, all of one ant squeezed between two crates (a shove out of one is into the
    other). 64 ants and spiders on ``mixed``, fresh seeds 10-15 / 20-25: 104 / 36 -> 12 / 0 (crossing
    frames 4 / 1 -> 9 / 0, stuck 90 / 103 -> 113 / 116 s); the crowds issue's bar sets (seeds 3000-3009
    and 4000-4009) and 1000 spiders (seeds 0-5) count the same as without it.

    A tucked leg's hip keeps its innermost tuck point's distance from the box besides (2026-11-29): the
    folded leg reaches no nearer point, and an ant's IK drew its tucked foot 1-3 cm into the crate in two
    frames of the crowd bar (``mixed``, 64 ants, seed 2, character 34). Feet in the air that the shove
    carried onto another character's foot plan again (:func:`_landings_shoved_onto_feet`); the shoved
    characters are ``state.shoved``.

    A shoved body pushes the bodies it would run into (``neighbours``, CSR lists as :func:`_avoid` gives
    them) by the same move, and they theirs (:func:`_push_bodies`): shoved alone, an ant was pushed 6 cm
    into its neighbour's body over 10 frames (``mixed``, 64 ants, seed 3, character 19, frames 450-460,
    with the hysteresis on :func:`can_make_way` tried in session 52: docs/crowds.md, crowds and moving boxes)."""
    centres, sizes, yaws, _, moving = boxes
    state.shoved[:] = False
    state.shoved_onto_feet[:] = False
    index = np.flatnonzero(moving)
    if not index.size:
        return
    xz = state.pelvis[:, [0, 2]]
    half = 0.5 * sizes[index][:, [0, 2]]
    reach = model.rest_radius + np.hypot(half[:, 0], half[:, 1])
    close = np.hypot(*(xz[:, None, :] - centres[index][None, :, [0, 2]]).transpose(2, 0, 1)) < reach[None]
    need = 0.5 * model.creature.foot_room + SHOVE_MARGIN
    shoved = np.zeros(xz.shape[0], np.bool_)
    pairs = np.nonzero(close)
    if not pairs[0].size:
        return
    offsets = dict(zip(pairs[0].tolist(), _hip_offsets(model, state, pairs[0])))
    for c, k in zip(*pairs):  # few: the bodies a moving box is beside this frame
        b = index[k]
        air = np.flatnonzero(~state.in_stance[c])
        if not air.size:
            continue
        yaw, centre = float(yaws[b]), centres[b, [0, 2]]
        # A tucked leg's hip keeps its innermost tuck point's distance too: nearer, the folded leg reaches
        # no point clear of the box, and the IK drew the foot 1-3 cm into it (mixed, 64 ants, seed 2,
        # character 34, frames 424 and 430).
        legs = np.arange(model.n_legs)
        fold = np.where(state.tucked[c], np.hypot(*_tuck_offset(model, state.feet_spacing[c], legs,
                                                                model.tuck_reach[:, -1])), 0.0)
        for _ in range(SHOVE_ROUNDS):
            hips = state.pelvis[c] + offsets[int(c)]
            short = max(need - min(_box_gap_out(state.feet[c, j, 0], state.feet[c, j, 2], centre, half[k], yaw)[0],
                                   _box_gap_out(hips[j, 0], hips[j, 2], centre, half[k], yaw)[0] - fold[j]) for j in air)
            if short <= 0.0:
                break
            push = short * _box_gap_out(state.pelvis[c, 0], state.pelvis[c, 2], centre, half[k], yaw)[1]
            _move_body(state, int(c), push)
            if neighbours is not None:
                _push_bodies(model, state, int(c), push, neighbours)
            shoved[c] = True
    state.counters["shoves"] += int(shoved.sum())
    state.shoved |= shoved
    _landings_shoved_onto_feet(model, state)


def _landings_shoved_onto_feet(model: CrowdModel, state: CrowdState) -> None:
    """Mark (``state.shoved_onto_feet``) the feet in the air of shoved bodies whose landing spot, carried
    along by the shove, is now within a foot's room (``Creature.foot_room``, the search's) of another character's
    foot, where it stands or will land: they plan again (``stage_requests``). Re-planning every foot in
    the air of a shoved body instead made the pelvis jump 8-9 cm (it follows the landing spots), against
    2-3 cm (mixed, 64 ants, seeds 2 and 3)."""
    from footfall.planner._kernels_geometry import points_near

    state.shoved_onto_feet[:] = False
    cs, ls = np.nonzero(state.shoved[:, None] & ~state.in_stance)
    if not cs.size:
        return
    n_chars, n_legs = state.in_stance.shape
    support = np.ascontiguousarray(_landing_feet(state)[..., [0, 2]].reshape(-1, 2))
    owner = np.repeat(np.arange(n_chars), n_legs)
    start, _ = points_near(support, owner, np.ascontiguousarray(state.swing_target[cs, ls][:, [0, 2]]),
                           np.ascontiguousarray(cs, dtype=np.int64), model.creature.foot_room)
    taken = np.diff(start) > 0
    state.shoved_onto_feet[cs[taken], ls[taken]] = True


def _move_body(state: CrowdState, c: int, move: np.ndarray) -> None:
    """Move character ``c``'s body and its feet in the air (their swings too) by ``move`` (2,) on the
    ground; its stance feet stay where they stand."""
    air = np.flatnonzero(~state.in_stance[c])
    state.pelvis[c, [0, 2]] += move
    for d, p in ((0, move[0]), (2, move[1])):
        state.feet[c, air, d] += p
        state.trajectories[c, air, :, d] += p
        state.swing_target[c, air, d] += p


PUSH_DEPTH = 4
"""Bodies a shove passes on through (a shoved body pushes a neighbour, which pushes its own, ...)."""


def _push_bodies(model: CrowdModel, state: CrowdState, c: int, move: np.ndarray, neighbours) -> None:
    """Character ``c``, just moved by ``move`` (2,), pushes each neighbour whose body box its own now
    overlaps by the same move (their bodies keep the gap they had), and so on up to PUSH_DEPTH bodies
    deep; each body is pushed once."""
    from footfall.planner._kernels_geometry import rects_overlap

    start, index = neighbours
    hx, hz = 0.5 * float(model.creature.body_box[0]), 0.5 * float(model.creature.body_box[1])
    xz, heading = state.pelvis[:, [0, 2]], state.heading
    pushed, front = {c}, [c]
    for _ in range(PUSH_DEPTH):
        nxt = []
        for a in front:
            for j in index[start[a]:start[a + 1]].tolist():
                if j in pushed or not rects_overlap(xz[a, 0], xz[a, 1], hx, hz, heading[a], xz[j, 0], xz[j, 1],
                                                    hx, hz, heading[j]):
                    continue
                _move_body(state, j, move)
                state.shoved[j] = True
                xz[j] += move
                pushed.add(j)
                nxt.append(j)
        if not nxt:
            break
        front = nxt


AVOID_RADIUS = 1.0
"""x crowd radius: the most a character keeps clear of others and of forbidden and moving boxes: its
legs' span, so that the feet of neighbours walking in file or abreast do not compete for the same
spots (6 ants on flat ground, spawned 1.8 rest radii apart and kept so by a 0.6 disc: 10 % of their
strides were more than 15 % off the stride law, p90 15.7 %; 6.6 % with the full span)."""
AVOID_RADIUS_MIN = 0.6
"""x crowd radius: the least: the body. A crowd spawned denser than its legs' span (a big crowd in a
small world) keeps the spacing it was spawned at (:func:`avoid_radius`): ORCA pushes characters that
start inside each other's disc apart within a frame."""
YIELD_RADIUS = 0.6
"""x avoid radius: the disc a character that cannot make way (standing or held, :data:`MOBILE_FRACTION`)
keeps, for its own velocity, from one that can: with the legs' span as its disc, its body (the walker
still keeps its whole disc round it and takes the whole effort; :func:`bodies_apart` still refuses any
step into a body). Kept to its whole disc, a quadruped standing aside for a neighbour crossing its way
could not move while the neighbour walked 1.5 m round that disc's edge (their lines 1.03 m apart
against a 1.08 m disc) and on into its way: 1-3.4 s stuck in every seed of the bar set
(``crates-moving``). Measured 2026-11-27: the crowds issue's bar set (``footfall evaluate --seeds 10
--seed-base 3000 --characters 6 --frames 300``), stuck 28 counts (20.6 s) -> 5 (2.2 s), per-stride runs
7 -> 9, every other count 0 -> 0; crowds of 8 / 16 / 64 on ``mixed`` and ``crates`` (seeds 1-3, 600
frames), stuck 35 / 46 / 260 -> 31 / 37 / 176 s, feet in boxes 0 / 0 / 88 -> 0 / 3 / 45, crossing
frames 0 / 1 / 0 -> 0 / 1 / 7; 1000 spiders on ``mixed`` (LOD on, 300 frames; in a crowd that dense the discs
are the bodies, and a waiting spider keeps 0.6 of its own), seeds 0-2 / 3-5: stuck 294 / 300 -> 193 / 163 s,
crossing frames 56 / 55 -> 43 / 54, feet in boxes 1 / 0 -> 0 / 0, overlaps 0. At 0.7: the bar set's stuck
4 counts, per-stride runs 5 (seeds 4000-4009: 12 and 7, against 11 and 10 at 0.6), but 1000 spiders,
seeds 0-2: 56 feet in boxes and 207 crossing frames (3-5: 5 and 36), and 16 characters of the crowd bar
12 feet in boxes; at 0.5: stuck 3, per-stride 11."""
AVOID_HORIZON = 2.0
"""s: ORCA's time horizon between characters."""
AVOID_BOX_HORIZON = 1.5
"""s: ORCA's time horizon against boxes."""
AVOID_NEIGHBOURS = 10
"""Nearest characters each one avoids (ORCA's usual cap: the rest are further than these)."""
NEAR_RADII = 4.0
"""x avoid radius: a character with another this near is among neighbours: it aims KEEP_RIGHT right of
its way, and escaping a moving box it follows ORCA's velocity (both in :func:`_avoid`)."""
KEEP_RIGHT = 0.1
"""rad: a character with a neighbour near aims this much right of its way; ORCA alone can settle
in a symmetric standstill (two characters exactly head-on), a shared convention breaks the tie."""


MOBILE_FRACTION = 0.25
"""x goal speed: a character slower than this cannot make way; its neighbours avoid it alone."""
WAIT_LIMIT_S = 1.0
"""s: a character ORCA has held back this long for a walking neighbour gets the right of way for
RIGHT_OF_WAY_S (:func:`wait_for_others`)."""
RIGHT_OF_WAY_S = 1.0
"""s: how long a right of way lasts: its holder walks on, and its neighbours make way for it alone."""
HELD_PROGRESS = 0.5
"""x preferred speed: ORCA's velocity making less progress along the preferred one than this holds a
character back (:func:`wait_for_others`). At MOBILE_FRACTION (0.25) the count kept restarting: a
quadruped waiting for a neighbour to pass got 0.072-0.089 m/s of ORCA's velocity along its 0.3 m/s way
while its body, turning, stood (``crates-moving``, seed 4009)."""


def near_pairs(model: CrowdModel, state: CrowdState, neighbours) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols): the pairs (character, neighbour) of the CSR ``neighbours`` lists (:func:`_avoid`)
    within NEAR_RADII avoid radii of each other."""
    start, index = neighbours
    rows = np.repeat(np.arange(state.pelvis.shape[0]), np.diff(start))
    xz = state.pelvis[:, [0, 2]]
    close = np.hypot(*(xz[index] - xz[rows]).T) < NEAR_RADII * model.avoid_radius
    return rows[close], index[close]


def can_make_way(state: CrowdState) -> np.ndarray:
    """(C,) bool: characters walking at MOBILE_FRACTION of their sustained speed or more, not held: the
    ones ORCA lets share the effort of avoiding (a slower one walks off only along its heading and turns
    slowly; its neighbours steer round it as round a box)."""
    return (state.speed >= MOBILE_FRACTION * sustained_speed(state)) & ~state.body_held


def wait_for_others(model: CrowdModel, state: CrowdState, preferred: np.ndarray, velocity: np.ndarray,
                    neighbours) -> None:
    """Count how long ORCA has held each character back for others to pass, and give the right of way
    (``state.right_of_way_s``, read by the next frame's ORCA) to one that has waited WAIT_LIMIT_S.

    Held back: standing aside (it cannot make way, :func:`can_make_way`), its ORCA velocity's progress
    along the preferred one under HELD_PROGRESS of the preferred speed, while a neighbour within
    NEAR_RADII avoid radii walks;
    ``neighbours``: the CSR lists :func:`_avoid` returns. Why: a neighbour crossing its way and steering
    round it as round a standing body orbits the waiting character's disc, and ORCA between them settles
    on waiting until the neighbour has passed, which at 0.3 m/s round a 1 m disc took 2.5-3 s
    (``crates-moving``, quadrupeds, bar seeds 3007, 4003, 4009: the stuck runs of the crowds issue's bar
    sets). With the right of way the waiting one walks on and the neighbour steers round it alone;
    :func:`bodies_apart` still refuses any step into a body. Only for one standing aside and only for
    walking neighbours: granted to any character with another near and ORCA's progress under
    MOBILE_FRACTION, it went to walkers in packs of ants and spiders that then jammed, and the stuck time of
    the crowds of 16 and 64 on ``crates`` and ``mixed`` (seeds 1-3, 600 frames) rose 5.5 -> 13.3 s and
    42.4 -> 83.1 s.
    """
    mobile = can_make_way(state)
    rows, cols = near_pairs(model, state, neighbours)
    passing = np.zeros(state.pelvis.shape[0], np.bool_)
    passing[rows[mobile[cols]]] = True
    dt = model.dt
    asked = np.hypot(preferred[:, 0], preferred[:, 1])
    progress = (velocity * preferred).sum(axis=1) / np.maximum(asked, 1e-12)
    held = passing & ~mobile & (asked > 0.0) & (progress < HELD_PROGRESS * asked)
    left = state.right_of_way_s - dt
    state.right_of_way_s = np.where(left > 1e-9, left, 0.0)  # whole frames: no float residue left over
    state.waited_s = np.where(held & (state.right_of_way_s <= 0.0), state.waited_s + dt, 0.0)
    earned = state.waited_s >= WAIT_LIMIT_S - 1e-9
    state.right_of_way_s[earned] = RIGHT_OF_WAY_S  # (its wait restarts from 0 after the right of way)

LANE_HORIZON = 3.0
"""s: a moving box that will reach a character within this time makes it leave the box's lane."""
FLEE_SPEED = 0.7
"""x top speed: the speed a character leaving a moving box's lane heads for (the asked speed if that
is faster). Measured 2026-11-26, none -> 0.7 (-> 1.0): 40 runs of 8 ants and 8 spiders x 600 frames on
``crates-moving`` and ``mixed`` (seeds 1100-1109): foot-frames in boxes 517 -> 430 (268), crossing
frames 8 -> 10 (4), overlaps 0; 1000 spiders x 300 frames on ``mixed``, LOD on, seeds 0-2: foot-frames
in boxes 882 -> 769 (1049), overlapping pair-frames 99 -> 23 (44), crossing frames 322 -> 273 (259);
the crowds bar set as before (stuck 71 -> 72 s, per-stride bars 96 -> 97 runs). Only for escapers with
no neighbour near (ORCA's near): 517 -> 484 and 882 -> 897. Single runs move by tens of foot-frames
either way (the escapes are chaotic: docs/crowds.md, crowds and moving boxes)."""


FLEE_GAIN_MAX = 1.25
"""x asked speed: the most an escaper that nothing hinders (ORCA's velocity its preferred one) walks at,
toward its flee speed (:data:`FLEE_SPEED`). Before 2026-11-27 only ORCA's velocity carried an escaper
faster than asked; unhindered, it walked at the asked speed: an ant crossing a 0.29 m/s crate's lane at
0.3 m/s (its flee speed 0.35) had its tucked foot caught (``mixed``, 16 ants, seed 3, frames 412-414).
Unheld, a quadruped (1.0 m/s against 0.3 asked) lifted three legs at once and crossed them: the bar
set's crossing frames 0 -> 18 (seeds 3000-3009); held to 1.5 x, seeds 4000-4009: 1 -> 6. Held to 1.25 x
(docs/crowds.md, crowds and moving boxes): 64 ants and spiders on ``mixed`` (600 frames), fresh seeds 10-15 /
20-25, feet in boxes 159 / 81 -> 104 / 36. The flee speed itself (ORCA's preferred speed, the look-ahead's
pace) is not held: held too, a spider asked to walk at 0.15 m/s fled a 0.2 m/s crate at 0.19 m/s and
stayed before it (tests/test_encounters.py, the head-on crate)."""


def _box_velocities(model: CrowdModel, t: float, centres: np.ndarray) -> np.ndarray:
    """(B, 2) m/s: each box's velocity on the ground over the next frame (``centres``: where it is at t)."""
    obs = model.raster.obstacles
    if not len(obs.yaws):
        return np.zeros((0, 2))
    later, _ = obs.poses_at(t + model.dt)
    return (later - centres)[:, [0, 2]] / model.dt


def _half_extents_along(half: np.ndarray, yaws: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """(B,) how far each box (half extents (B, 2) along its yawed axes) reaches along ``axis`` (B, 2)."""
    cos, sin = np.cos(yaws), np.sin(yaws)
    return (half[:, 0] * np.abs(cos * axis[:, 0] + sin * axis[:, 1])
            + half[:, 1] * np.abs(-sin * axis[:, 0] + cos * axis[:, 1]))


def flee_speed(model: CrowdModel, state: CrowdState, rows: np.ndarray) -> np.ndarray:
    """(R,) m/s: the speed characters ``rows`` ask for leaving a moving box's lane (stage_steer's goal speed
    for an escaper: :data:`FLEE_SPEED` x the top speed, or the asked speed if that is faster)."""
    if not math.isfinite(model.top_speed):
        return state.desired_speed[rows]
    return np.maximum(state.desired_speed[rows], FLEE_SPEED * model.top_speed)


def escape_boxes(boxes, moving: np.ndarray | None = None) -> np.ndarray:
    """(B,) bool: the boxes an escaper keeps clear of: the forbidden static ones and the moving ones
    (``moving``: only these indices of them). ``boxes`` as :func:`_boxes_now` gives them."""
    used = boxes[3] & ~boxes[4]
    if moving is None:
        used |= boxes[4]
    else:
        used[moving] = True
    return used


def _lane_exit(model: CrowdModel, state: CrowdState, direction: np.ndarray, boxes, box_velocity: np.ndarray):
    """(direction (C, 2), in_lane (C,)): each character's way, turned out of the lanes of the moving
    boxes slower than its top speed that will reach its feet (its rest radius and the threat margin) within
    :data:`LANE_HORIZON`: square out of the lane, to the side the character is on, keeping only the
    part of its way that runs ahead of the box, then checked by looking ahead (planner._escape:
    :func:`escape_ways`). ``boxes`` as :func:`_boxes_now` gives them,
    ``box_velocity`` from :func:`_box_velocities`."""
    n = state.pelvis.shape[0]
    centres, sizes, yaws, _, moving = boxes
    in_lane = np.zeros(n, np.bool_)
    if not moving.any():
        return direction, in_lane
    moving = np.flatnonzero(moving)
    velocity = box_velocity[moving]  # (B, 2)
    speed = np.hypot(velocity[:, 0], velocity[:, 1])
    # A box at least as fast as the creature's top speed has no escape (its contacts are counted as
    # unavoidable_contacts): the feet step away from it (stage_requests) and re-plan swings it crosses.
    go = (speed > 1e-6) & (speed < model.top_speed)
    if not go.any():
        return direction, in_lane
    moving, velocity, speed = moving[go], velocity[go], speed[go]
    u = velocity / speed[:, None]  # (B, 2) along the box's travel
    side_axis = np.column_stack([-u[:, 1], u[:, 0]])
    half = 0.5 * sizes[moving][:, [0, 2]]
    half_along = _half_extents_along(half, yaws[moving], u)
    half_across = _half_extents_along(half, yaws[moving], side_axis)
    room = model.rest_radius + model.controller.threat_margin
    # The box and the character close in at the box's speed plus the character's own toward it; the
    # nearer side, and a character dead centre takes the side its way leans to (a way with no part
    # across the lane: the side of -side_axis, a fixed convention so that the choice is deterministic).
    from footfall.planner._kernels_lanes import lane_threats

    n_boxes = moving.size
    threat = np.empty((n, n_boxes), np.bool_)
    side = np.empty((n, n_boxes))
    each_exit = np.empty((n, n_boxes, 2))
    exit_way = np.empty((n, 2))
    xz = np.ascontiguousarray(state.pelvis[:, [0, 2]])
    lane_threats(xz, state.speed, np.cos(state.heading), np.sin(state.heading), np.ascontiguousarray(direction),
                 np.ascontiguousarray(centres[moving][:, [0, 2]]), np.ascontiguousarray(u), np.ascontiguousarray(side_axis),
                 half_along, half_across, speed, room, LANE_HORIZON, threat, side, each_exit, exit_way)
    in_lane = threat.any(axis=1)
    if not in_lane.any():
        return direction, in_lane
    norm = np.hypot(exit_way[:, 0], exit_way[:, 1])
    turn = in_lane & (norm > 1e-9)
    own_way = direction
    direction = direction.copy()
    direction[turn] = exit_way[turn] / norm[turn, None]
    # Between two lanes the exits can cancel: the sum of two crates' exits led a spider toward the one
    # coming at it (mixed, 16 spiders, seed 0: 36 foot-frames in a crate). Where more than one box threatens,
    # the way out is the direction, of the sum and each box's two sides, that meets no box the longest
    # (or leaves the one it is in soonest).
    several = in_lane & (threat.sum(axis=1) > 1)
    # A static forbidden box beside the lane can wall off the side the geometry chose: a spider in a
    # crate's lane turned toward its exit, straight at a static crate 3 cm beyond its avoid radius, and
    # ORCA, refusing that way, held it still on the lane's edge until the crate ran over its feet
    # (crates-moving, 12 spiders, seed 11, frames 470-590). Such a character chooses its way out as a
    # character between two lanes does.
    static = np.flatnonzero(boxes[3] & ~boxes[4])  # forbidden and not moving (the masks of _boxes_now)
    walled = np.zeros(n, np.bool_)
    if static.size:
        walled[in_lane] = _static_contact(model, state, np.flatnonzero(in_lane), direction[in_lane][:, None],
                                          boxes, static)[:, 0] < LANE_HORIZON
    rows = np.flatnonzero(several | (walled & turn))
    if rows.size:
        turn[rows] = True
        sub = threat[rows]
        candidates = np.concatenate([direction[rows][:, None], each_exit[rows] / np.maximum(
            np.hypot(each_exit[rows, :, 0], each_exit[rows, :, 1]), 1e-12)[..., None],
            np.broadcast_to(-side_axis[None], (rows.size,) + side_axis.shape) * side[rows][..., None]], axis=1)
        rel = xz[rows][:, None] - centres[moving][None, :, [0, 2]]  # (R, B, 2) box -> pelvis
        contact = _time_to_contact(candidates, state.desired_speed[rows], rel, velocity, u, side_axis,
                                   half_along + room, half_across + room, sub)
        if static.size:
            contact = np.minimum(contact, _static_contact(model, state, rows, candidates, boxes, static))
        # Only the sides of the boxes that threaten: a far box's exit is a way out of nothing.
        contact[:, 1:] = np.where(np.concatenate([sub, sub], axis=1), contact[:, 1:], -np.inf)
        # Ties keep the earlier candidate: the sum first, as with one box.
        best = np.argmax(contact, axis=1)
        direction[rows] = candidates[np.arange(rows.size), best]
    # The way out, followed ahead against where the boxes will be, is kept unless another heading does
    # clearly better (planner._escape: the rule above ignores how long the body takes to turn).
    from footfall.planner._escape import escape_ways

    rows = np.flatnonzero(in_lane)
    direction[rows] = escape_ways(model, state, rows, direction[rows], own_way[rows], flee_speed(model, state, rows),
                                  escape_boxes(boxes, moving))
    return direction, in_lane


STATIC_CONTACT_STEP = 0.1
"""s: the step at which :func:`_static_contact` follows a character's way."""


def _static_contact(model: CrowdModel, state: CrowdState, rows, ways, boxes, static) -> np.ndarray:
    """(R, K) s: for characters ``rows`` (R,) walking at their asked speed along each of their ``ways``
    (R, K, 2), when the pelvis first comes within the avoid radius of one of the static forbidden boxes
    ``static`` (indices into ``boxes``, as :func:`_boxes_now` gives them), its true distance to the
    box's rectangle followed every :data:`STATIC_CONTACT_STEP` s up to ORCA's box horizon
    (:data:`AVOID_BOX_HORIZON`: a way ORCA refuses for that box); :data:`LANE_HORIZON` where it meets
    none by then (ORCA lets it walk that way, and steers round the box later). A box already that
    near counts where the way goes nearer to it."""
    radius = model.avoid_radius
    steps = np.arange(0.0, AVOID_BOX_HORIZON + 1e-9, STATIC_CONTACT_STEP)  # (T,)
    xz = state.pelvis[rows][:, [0, 2]]
    # Only the boxes some of these characters can reach within the horizon (the result is the same;
    # a crowd in a wide world has hundreds of crates and the arrays below grow with each).
    centres, sizes, yaws = boxes[0][static][:, [0, 2]], 0.5 * boxes[1][static][:, [0, 2]], boxes[2][static]
    reach = state.desired_speed[rows].max() * steps[-1] + radius + np.hypot(sizes[:, 0], sizes[:, 1])
    gap = np.hypot(*(xz[:, None, :] - centres[None]).transpose(2, 0, 1)).min(axis=0)
    keep = gap <= reach
    if not keep.any():
        return np.full(ways.shape[:2], LANE_HORIZON)
    centres, sizes, yaws = centres[keep], sizes[keep], yaws[keep]
    path = (xz[:, None, None, :]
            + state.desired_speed[rows][:, None, None, None] * steps[None, None, :, None] * ways[:, :, None, :])
    rel = path[..., None, :] - centres  # (R, K, T, B, 2)
    cos, sin = np.cos(yaws), np.sin(yaws)
    along = np.abs(rel[..., 0] * cos + rel[..., 1] * sin) - sizes[:, 0]
    across = np.abs(-rel[..., 0] * sin + rel[..., 1] * cos) - sizes[:, 1]
    distance = np.hypot(np.maximum(along, 0.0), np.maximum(across, 0.0))  # 0 inside
    near = distance < radius  # (R, K, T, B)
    # A box it is already within reach of counts only along ways that go nearer to it (ORCA lets it
    # walk away): a spider 6 mm inside a static crate's reach, beside a moving crate's lane, had its
    # exit chosen straight into it (crates-moving, 12 spiders, seed 3, frames 520-590).
    near &= ~near[:, :, :1] | (distance < distance[:, :, :1] - 1e-9)
    hit = near.any(axis=3)
    first = np.where(hit.any(axis=2), np.argmax(hit, axis=2), steps.size)
    return np.where(first < steps.size, steps[np.minimum(first, steps.size - 1)], LANE_HORIZON)


def _time_to_contact(ways, speed, rel, box_velocity, u, side_axis, reach_along, reach_across, threat):
    """(C, K) s: for each character walking at ``speed`` (C,) along each of its ``ways`` (C, K, 2), when
    it first comes within ``reach_along`` / ``reach_across`` (B,) of a threatening box's centre, along and
    across the box's travel ``u`` / ``side_axis`` (B, 2); ``rel`` (C, B, 2) box -> character, ``threat``
    (C, B) bool. :data:`LANE_HORIZON` where it meets none within that time; inside one's reach already,
    minus the time it takes to get out. The larger, the better the way."""
    relative = speed[:, None, None, None] * ways[:, :, None, :] - box_velocity[None, None]  # (C, K, B, 2)
    start = np.stack([(rel * u[None]).sum(-1), (rel * side_axis[None]).sum(-1)], axis=-1)[:, None]  # (C, 1, B, 2)
    rate = np.stack([(relative * u[None, None]).sum(-1), (relative * side_axis[None, None]).sum(-1)], axis=-1)
    reach = np.stack([reach_along, reach_across], axis=-1)[None, None]  # (1, 1, B, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = (-reach - start) / rate, (reach - start) / rate
    still = np.abs(rate) < 1e-12
    inside = np.abs(start) < reach
    lo = np.where(still, np.where(inside, -np.inf, np.inf), np.minimum(a, b))
    hi = np.where(still, np.where(inside, np.inf, -np.inf), np.maximum(a, b))
    enter = np.maximum(np.maximum(lo[..., 0], lo[..., 1]), 0.0)
    leave = np.minimum(hi[..., 0], hi[..., 1])
    # Inside a box's reach already: minus the time to get out (the sooner the better).
    when = np.where(enter > 0.0, enter, -leave)
    when = np.where((enter <= leave) & threat[:, None], when, np.inf)  # (C, K, B)
    return np.minimum(when.min(axis=2), LANE_HORIZON)


def _fastest(model: CrowdModel, state: CrowdState) -> float:
    """m/s: the fastest a character can walk: the creature's top speed, or (none known) the fastest asked."""
    return model.top_speed if math.isfinite(model.top_speed) else float(np.max(state.desired_speed, initial=0.0))


def _avoid(model: CrowdModel, state: CrowdState, preferred: np.ndarray, to_target: np.ndarray, boxes,
           box_velocity: np.ndarray, escaping: np.ndarray):
    """(velocity (C, 2), avoided (C,) bool, near (C,) bool): ORCA's velocity for every character, whether it
    differs from the preferred one (a neighbour or a box is in the way), and whether another character is
    within :data:`NEAR_RADII` avoid radii (among neighbours). ``boxes`` as
    :func:`_boxes_now` gives them, ``box_velocity`` from :func:`_box_velocities`; ``escaping`` (C,)
    bool: characters leaving a moving box's lane, whom their neighbours make way for."""
    from footfall.planner._kernels_avoidance import neighbour_lists, orca_velocities

    n = state.pelvis.shape[0]
    xz = np.ascontiguousarray(state.pelvis[:, [0, 2]])
    radius = model.avoid_radius
    top = _fastest(model, state)
    # The lists reach at least NEAR_RADII avoid radii, so the nearest other character, if that near, is in
    # its character's list: 'near' below is 'another character within NEAR_RADII avoid radii'.
    start, index = neighbour_lists(xz, max(2.0 * radius + 2.0 * top * AVOID_HORIZON, NEAR_RADII * radius),
                                   AVOID_NEIGHBOURS)
    near = np.zeros(n, np.bool_)
    near[near_pairs(model, state, (start, index))[0]] = True
    if near.any():
        c, s = math.cos(KEEP_RIGHT), math.sin(-KEEP_RIGHT)
        turn = near & (to_target > 1.0)
        p = preferred[turn]
        preferred = preferred.copy()
        preferred[turn] = np.column_stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]])
    centres, sizes, yaws, forbidden, moving = boxes
    # A moving box is kept clear of the feet, not only of the body: the character's rest radius
    # (a stance foot the box reaches must step away, and may find nowhere to go).
    pad = np.where(moving, max(model.rest_radius - radius, 0.0), 0.0)
    orca_boxes = (np.ascontiguousarray(centres[:, [0, 2]]), np.ascontiguousarray(0.5 * sizes[:, [0, 2]]), yaws,
                  np.ascontiguousarray(box_velocity), forbidden | moving, pad)
    velocity = np.stack([np.cos(state.heading), np.sin(state.heading)], axis=1) * state.speed[:, None]
    # Way is made only by those who can: a body standing (or held) walks off only along its heading
    # and turns slowly, so the others steer round it as round a box (left half the effort, or given
    # way by it when escaping a box's lane, one walked into a spider standing in its path at 0.29 m/s:
    # 63 overlapping frames, mixed, seed 1121411189).
    mobile = can_make_way(state)
    # ... and such a body, for its own velocity, keeps only part of its disc from those walking
    # (YIELD_RADIUS).
    out = np.empty((n, 2))
    orca_velocities(xz, np.ascontiguousarray(velocity), np.ascontiguousarray(preferred), np.full(n, radius),
                    np.full(n, top), start, index, *orca_boxes, AVOID_HORIZON, AVOID_BOX_HORIZON, model.dt,
                    np.ascontiguousarray(escaping), mobile, np.full(n, YIELD_RADIUS * radius), state.right_of_way_s > 0.0,
                    out)
    avoided = np.hypot(*(out - preferred).T) > 1e-9
    return out, avoided, near, (start, index)


BODY_GAP_FRAMES = 2.0
"""Frames of motion at top speed :func:`bodies_apart` keeps between two body boxes (half on each): both
bodies of a pair move in the same frame, each checked against where the other was."""


def bodies_apart(model: CrowdModel, state: CrowdState, move: np.ndarray, neighbours) -> np.ndarray:
    """(C,) bool: characters whose ``move`` (C, 2) on the ground keeps their body box out of their
    ``neighbours``' (CSR ``start, index`` as :func:`_avoid` gives them; :data:`BODY_GAP_FRAMES` apart),
    or at least brings it no nearer to the ones it overlaps."""
    from footfall.planner._kernels_controller import moves_into_bodies

    return _clear_of_bodies(model, state, moves_into_bodies, move, neighbours)


def _clear_of_bodies(model: CrowdModel, state: CrowdState, kernel, change: np.ndarray, neighbours,
                     grown: bool = True) -> np.ndarray:
    """(C,) bool: not ``kernel`` (``planner._kernels_controller.moves_into_bodies`` or ``turns_into_bodies``)
    for ``change`` (each character's move or turn), with the body box each character keeps out of the
    others': the body, ``grown`` by half of :data:`BODY_GAP_FRAMES` frames at top speed."""
    start, index = neighbours
    n = state.pelvis.shape[0]
    if index.size == 0:
        return np.ones(n, np.bool_)
    box = model.creature.body_box
    grow = 0.5 * BODY_GAP_FRAMES * _fastest(model, state) * model.dt if grown else 0.0
    into = np.empty(n, np.bool_)
    kernel(np.ascontiguousarray(state.pelvis[:, [0, 2]]), np.ascontiguousarray(state.heading),
           np.ascontiguousarray(change, dtype=np.float64), 0.5 * float(box[0]) + grow, 0.5 * float(box[1]) + grow,
           start, index, into)
    return ~into


def bodies_turn_clear(model: CrowdModel, state: CrowdState, turn: np.ndarray, neighbours) -> np.ndarray:
    """(C,) bool: characters whose ``turn`` (C,) rad on the spot keeps their body box out of the
    ``neighbours``' it was out of. The bodies themselves, not grown as :func:`bodies_apart` grows them: grown
    boxes 7 cm apart already overlap, and a standing ant turned into its neighbour (``mixed``, 64 ants,
    seed 3, characters 34 and 19, with the hysteresis tried in session 52)."""
    from footfall.planner._kernels_controller import turns_into_bodies

    return _clear_of_bodies(model, state, turns_into_bodies, turn, neighbours, grown=False)


def stance_room(model: CrowdModel, state: CrowdState) -> np.ndarray:
    """(C, L) m: how far each foot is in front of the rear end of its leg's stance window."""
    from footfall.planner._ik import body_rotation

    # Measured along the body's forward axis (the window's own frame): on a slope the body pitches.
    axis = body_rotation(state.heading, state.pitch, state.roll)[:, :, 0]  # (C, 3)
    forward = np.einsum("cli,ci->cl", state.feet - state.pelvis[:, None, :], axis)
    return forward - model.stance_window[None, :, 0]


def stance_speed_cap(model: CrowdModel, state: CrowdState) -> np.ndarray:
    """(C,) the fastest each body may move this frame so that every stance foot stays in front of
    the rear end of its leg's stance window until its sector starts (inf: no stance foot near)."""
    return leg_speed_caps(model, state).min(axis=1)


def walk_frequency(model: CrowdModel, speed: np.ndarray) -> np.ndarray:
    """(C,) Hz: the stride frequency of each character walking at ``speed`` (C,) m/s (the timing law)."""
    from footfall.planner._timing import _stride_frequency

    # Several calls a frame: the checks of the public stride_frequency cost as much as the formula.
    return _stride_frequency(model.timing, speed, model.leg_height)


def resume_frequency(model: CrowdModel, state: CrowdState) -> np.ndarray:
    """(C,) Hz: the stride frequency of the walk each character heads for (its goal speed, within its
    speed limit): the tempo of a body that stands, or speeds up, once it walks."""
    return walk_frequency(model, sustained_speed(state))


def leg_speed_caps(model: CrowdModel, state: CrowdState, room=None, lift=None) -> np.ndarray:
    """(C, L) the fastest the body may move for each stance foot (inf for swinging feet); ``room``
    (:func:`stance_room`) and ``lift`` (:func:`until_lift`) of this state if the caller has them."""
    room = stance_room(model, state) if room is None else room
    lift = until_lift(model, state) if lift is None else lift
    return np.where(state.in_stance, np.maximum(room, 0.0) / lift, np.inf)


def _until_sector(model: CrowdModel, state: CrowdState, frequency) -> np.ndarray:
    """(C, L) s until the needle, turning at ``frequency`` (C,) Hz (> 0), enters each foot's sector, and the frame
    the foot lifts on (it lifts the frame its sector starts)."""
    g = state.gaits
    return np.mod(g.disk_start - g.needle[:, None], 1.0) / frequency[:, None] + model.dt


def until_lift(model: CrowdModel, state: CrowdState) -> np.ndarray:
    """(C, L) s: how long each foot has until the needle lifts it (at least a frame)."""
    # A body standing has no tempo (0 Hz): its feet lift when it walks again, at the tempo of the walk
    # it resumes. Counting them a cycle of 0 Hz away made every stance foot 'hold the body' (cap 0):
    # forced steps of the feet just landed, again and again, while the feet at the rear end of their
    # windows never got their turn (a spider stood on a hill for good with four feet in the air).
    resume = resume_frequency(model, state)
    frequency = np.maximum(np.where(state.stride_frequency > 0.0, state.stride_frequency, resume), 1e-9)
    time = _until_sector(model, state, frequency)
    # A foot whose sector has started but which has not lifted yet (its plan is pending) lifts as
    # soon as it can: its next turn is not a cycle away.
    return np.where(state.wants_swing | state.sector_missed, model.dt, time)


STANCE_SIDE_MARGIN = 0.5
"""x the hip's lateral offset: the least a stance foot stays on its own side of the body's midline
while the body turns (:func:`stance_turn_bounds`)."""


def leg_turn_bounds(model: CrowdModel, state: CrowdState, lift=None) -> np.ndarray:
    """(C, L) rad: how far each body may turn this frame, toward the side its turn bound is on (its
    sign), so that the stance foot is not carried across the midline (to within
    ``STANCE_SIDE_MARGIN``) before the needle lifts it; ``nan`` where the foot gives no bound.

    A turn swings a stance foot ``f`` ahead of the pelvis sideways by about ``-f`` times the angle in
    the body's frame: a quadruped's front feet, 0.29 m ahead, cross under the body after 0.4 rad, and
    its legs cross. Each stance foot gives the room it has to its margin, spread over the time until
    it lifts (as :func:`leg_speed_caps` does for the speed); swinging feet and legs on the midline
    give no bound. ``lift``: :func:`until_lift` of this state if the caller has it.
    """
    lift = until_lift(model, state) if lift is None else lift
    side = model.leg_sides
    margin = STANCE_SIDE_MARGIN * np.abs(model.hips_body[:, 2])
    d = state.feet[:, :, [0, 2]] - state.pelvis[:, None, [0, 2]]
    forward, lateral = _rot_xz(-state.heading[:, None], d[..., 0], d[..., 1])  # the feet in the body's frame
    # Turning by a moves the foot's lateral coordinate by about -forward * a (a small).
    room = np.maximum(side * lateral - margin, 0.0) * model.dt / lift
    lever = side * forward
    bounded = state.in_stance & (side != 0.0) & (np.abs(lever) > 1e-9)
    return np.where(bounded, room / np.where(bounded, lever, 1.0), np.nan)


def stance_turn_bounds(model: CrowdModel, state: CrowdState) -> tuple[np.ndarray, np.ndarray]:
    """(C,), (C,) rad: the least and most each body may turn this frame (:func:`leg_turn_bounds`)."""
    bound = leg_turn_bounds(model, state)
    negative = np.signbit(bound)  # bounds a turn of negative angle (-0.0: no room for one)
    lo = np.where(negative & ~np.isnan(bound), bound, -np.inf).max(axis=1)
    hi = np.where(~negative & ~np.isnan(bound), bound, np.inf).min(axis=1)
    return lo, hi


def uncrossing_turn(model: CrowdModel, state: CrowdState, turn) -> np.ndarray:
    """(C,) rad: ``turn``, halved, then none, for a body it would turn across its legs: two legs
    whose ground lines (hip to foot; a swinging foot where it lands) would cross and do not now.

    The hips swing with a turn and the stance feet stay: a spider turning on the spot carried a
    middle foot across its neighbour's leg. The stance legs that would cross step
    (:func:`turn_crossed_legs`, ``stage_requests``) and the turn goes on."""
    out = np.empty(state.heading.shape, dtype=np.float64)
    uncrossed_turns(state.pelvis, state.heading, np.ascontiguousarray(turn, dtype=np.float64), model.hips_body,
                    _landing_feet(state), out)
    return out


def turn_crossed_legs(model: CrowdModel, state: CrowdState, turn) -> np.ndarray:
    """(C, L) bool: stance legs whose ground line would cross another stance leg's with the body
    turned by ``turn`` (C,) from its heading, and does not now."""
    out = np.empty(state.in_stance.shape, dtype=np.bool_)
    legs_crossed_by_turn(state.pelvis, state.heading, np.ascontiguousarray(turn, dtype=np.float64), model.hips_body,
                         state.feet, state.in_stance, out)
    return out


def stage_gait(model: CrowdModel, state: CrowdState):
    """Stride frequency and duty factor from the speed (the destination disks follow the
    duty factor, the disks in use move toward them while in stance), then the needle."""
    from footfall.planner._gait import advance, set_destination, set_speed
    from footfall.planner._timing import GRAVITY, stride_length
    from footfall.planner._workspace import duty_ceiling

    # Gait changes with speed (planner._gait_schedule): the new gait's disks are the destination.
    # The gait follows the speed the character heads for (its goal), not the speed of the moment:
    # a body slowed for a stride by its legs would otherwise flip gaits and restart transitions.
    schedule = model.schedule
    if len(schedule.gaits) > 1:
        goal = sustained_speed(state)
        froude = goal**2 / (GRAVITY * model.leg_height)
        index = schedule.select(state.gait_index, froude)
        for k in np.unique(index[index != state.gait_index]):
            set_destination(state.gaits, np.flatnonzero((index == k) & (index != state.gait_index)),
                            schedule.gaits[int(k)])
        state.gait_index = index
    # The stance sweep DF * lambda must fit the narrowest stance window (planner._workspace).
    stride = stride_length(model.timing, state.speed, model.leg_height)
    window = float(np.min(model.stance_window[:, 1] - model.stance_window[:, 0]))
    frequency = set_speed(state.gaits, model.timing, state.speed, model.leg_height,
                          duty_ceiling(max(window, 1e-9), stride))
    # A body its legs have kept at rest for STALL_S (a foot at the rear end of its window whose step found
    # no footprint: the stance cap, not a hold) keeps the needle turning at the tempo it will resume:
    # stopped with the body, the other legs never lifted, and the one in the way of the stopped foot's
    # step never moved (STALL_S).
    stalled = (state.speed <= 0.0) & (state.speed_wanted > 0.0) & ~state.body_held
    state.stalled_s = np.where(stalled, state.stalled_s + model.dt, 0.0)
    stalled &= state.stalled_s >= STALL_S
    if stalled.any():
        frequency = np.where(stalled, np.maximum(frequency, resume_frequency(model, state)), frequency)
    # A body turning on the spot (its way a quarter turn or more off its heading, so that it asks to
    # walk at ~0) steps at the tempo of the walk asked of it: at a standing body's tempo (the 0.5 Hz
    # floor) its stance feet bounded the turn to 0.2-0.3 rad/s until they swapped, and a quadruped
    # avoiding a neighbour stood ~2 s coming round (crates-moving, seed 4009; TURNING_FRACTION). The
    # asked walk, not the one its holds taught it to sustain: a robot5 held by a foot its leg could not
    # follow learnt a limit whose tempo (1.64 -> 0.8-1.0 Hz) bounded its turn to ~0.5 rad/s again.
    # A body all but standing (SPOT_FRACTION) steps at the tempo of its top walk instead: at the asked
    # walk's 0.98 Hz a quadruped came round at 0.6 rad/s, and each time the avoidance's velocity moved
    # (a right of way given and lapsing) it turned after it again without walking (crates-moving,
    # seeds 4000 and 8008: stuck 4.1 and 4.3 s).
    ctl = model.controller
    sustained = sustained_speed(state)
    turning = np.abs(state.turn_wanted) >= TURNING_FRACTION * ctl.turn_rate * model.dt
    turning &= (state.speed < TURNING_FRACTION * sustained) & ~state.body_held
    if turning.any():
        frequency = np.where(turning, np.maximum(frequency, walk_frequency(model, state.desired_speed)), frequency)
        spot = turning & (state.speed <= SPOT_FRACTION * sustained)
        if spot.any() and math.isfinite(model.top_speed):
            top = walk_frequency(model, np.full_like(state.desired_speed, model.top_speed))
            frequency = np.where(spot, np.maximum(frequency, top), frequency)
    state.stride_frequency = frequency
    in_air = ~state.in_stance
    enter, fraction = advance(state.gaits, frequency, model.dt, state.in_stance)
    # A foot still in the air when the needle enters its sector (a forced step, a late landing)
    # keeps its turn: it lifts again on landing while the sector lasts. Dropping the turn made it
    # skip a whole cycle: a stride of two cycles, and a foot left behind that must be forced again.
    g = state.gaits
    phase = np.mod(g.needle[:, None] - g.disk_start, 1.0)  # the needle past each sector's start
    sweep = (frequency * model.dt)[:, None]
    state.sector_missed |= in_air & ((phase < sweep) | (sweep >= 1.0))
    state.sector_missed &= phase < g.disk_duration  # the turn lapses with its sector
    return frequency, enter, fraction


TURNING_FRACTION = 0.5
"""A body turns on the spot (:func:`stage_gait`: its needle at the tempo of the walk asked of it) while the turn it
wants is at least this fraction of its turn rate and its speed under this fraction of the speed it heads
for. Measured 2026-11-28 (docs/crowds.md, crowds and moving boxes): the crowds issue's bar sets (seeds 3000-3009 /
4000-4009), stuck runs 0 / 8 -> 2 / 2 (4.1 -> 2.0 s in all), per-stride runs 3 / 3 -> 2 / 2, crossing
runs 0 / 1 -> 0 / 1; crowds of 8 / 16 / 64 on ``mixed`` and ``crates`` (spiders, ants), stuck
3.1 / 12.8 / 54.4 -> 2.0 / 5.5 / 42.0 s, crossing frames 0 / 0 / 4 -> 0; 1000 spiders on ``mixed`` (seeds
0-2 / 3-5), crossing frames 42 / 41 -> 13 / 19, stuck 77 / 95 -> 118 / 94 s, mean speed 0.19 -> 0.176 m/s.
Keyed to the asked speed (``speed_wanted``) instead, the bar sets had 5 stuck and 6 per-stride runs and a
crowd of 16 spiders a collision. At the asked walk's tempo rather than the sustained one's (session 44):
robot5 comes round on the spot in 66-78 frames on seeds 0-299 (67-109 before); the bar sets 10 -> 9
violations (stuck 4 -> 3, per-stride 4 -> 4, crossings 2 -> 2); the crowds of 8 / 16 / 64 the same but for
0.7 s more stuck at 64; 1000 spiders (seeds 0-2 / 3-5) stuck 118 / 94 -> 138 / 95 s, crossing frames
13 / 19 -> 19 / 18 (per-seed spread +-50 %)."""


SPOT_FRACTION = 0.25
"""A body turning on the spot (:func:`stage_gait`) whose speed is at most this fraction of the speed it heads
for steps at the tempo of its top walk (``CrowdModel.top_speed``, Froude 0.5: a quadruped 1.83 Hz against
0.98 Hz at 0.3 m/s). Measured 2026-11-29 (docs/crowds.md): the crowds issue's bar sets 4000 / 8000 / 9000,
failing runs 2 / 1 / 2 -> 0 / 0 / 1, and on the set 10000, run only once the rule was chosen, 1 -> 2 (stuck
s over the four 10.5 -> 5.3; the quadrupeds' per-stride p90 lower in each). For every turning body (no speed bound), stuck runs fell to 0 but the
quadrupeds' strides broke the per-stride bar in 14 runs: a body walking at 0.16 m/s at the top walk's
tempo takes strides half the law's; 0.1 left the quadruped of 8008 stuck 4.0 s (it turns while creeping)."""

STALL_S = 1.0
"""s a body its legs keep at rest while it asks to walk before its needle turns on without it, at the tempo
it will resume (:func:`stage_gait`). The needle's tempo follows the body's speed, so a body its stance cap
held at 0 m/s stopped its own gait: a spider on ``mixed`` (seed 4006, character 3) stood 6.8 s, its rear
leg 6 past its window's rear end, every cell of the forced step's search disc beyond leg 5's line (leg 5's
foot 3 cm from its preferred footprint), and leg 5 never lifted. Measured 2026-11-27 (README, crowds and
moving boxes): the crowds issue's bar sets, stuck counts 5 / 11 -> 4 / 4 (seeds 3000-3009 / 4000-4009;
the ``crates`` spider's walled-in foot of seed 3009 1.4 -> 0.07 s), per-stride runs and crossing frames
the same; 1000 spiders on ``mixed`` (seeds 0-2 / 3-5), crossing frames 38 / 49 -> 39 / 57, stuck
173 / 159 -> 168 / 154 s. With no wait (0 s), those 1000 spiders had 109 crossing frames on seeds 0-2: a
dense crowd's bodies stop for a moment often."""


def stage_swing(model: CrowdModel, state: CrowdState, boxes) -> np.ndarray:
    landed = np.zeros(state.in_stance.shape, dtype=np.bool_)
    advance_swings(state.swing_t, state.swing_T, state.trajectories, state.in_stance, state.feet, model.dt, landed)
    if landed.any():
        state.in_stance |= landed
        state.counters["steps"] += int(landed.sum())
        centres, sizes, yaws, forbidden, _ = boxes
        state.counters["forbidden_footprints"] += count_forbidden_landings(
            landed, state.feet, 0.5 * model.creature.foot_length, 0.5 * model.creature.foot_width, state.foot_yaws,
            centres, sizes, yaws, forbidden)
    return landed


def arrival_speed(distance, arrive_radius: float, acceleration: float):
    """The fastest a character ``distance`` (m) from its goal may walk and still stop, braking at
    ``acceleration`` (m/s^2), by the time it is ``arrive_radius`` from it: sqrt(2 a (d - r)).

    Examples
    --------
    >>> float(arrival_speed(2.5, 0.5, 1.0))   # 2 m to brake in at 1 m/s^2
    2.0
    >>> float(arrival_speed(0.2, 0.3, 1.0))
    0.0
    """
    return np.sqrt(2.0 * acceleration * np.maximum(np.asarray(distance, dtype=np.float64) - arrive_radius, 0.0))


TOUCHDOWN_TURN_MAX = 0.1
"""rad: the most of a turn a foot is planned ahead for (:func:`touchdown_turn`). A steering can turn
back (an escape, ORCA's velocity): quadrupeds' front feet planned for the 0.45 rad a turn at the full
rate makes over their 0.3 s swing, the turn then reversed, landed across their midline
(`crates-moving`, seeds 3000 and 4001, 6 and 6 crossing frames; none with the cap). 0.1 rad moves a
spider's foot at most 3 cm, a quadruped's front foot 2.7 cm: under half its hip's 0.1 m sideways offset."""


def touchdown_turn(turn_left, turn_made, dt, t):
    """rad: how far a body turns in ``t`` s (a swing): the turn its steering still asks, ``turn_left``,
    at the rate it turned in the last frame (``turn_made`` rad in ``dt`` s), no further than asked and
    at most :data:`TOUCHDOWN_TURN_MAX`. The rate is the one it made, not the controller's: a quadruped
    whose stance feet held its turn to a fiftieth of the rate, planned for the full rate over its 0.3 s
    swing, set a front foot across its body's midline (`mixed`, seed 3007, character 2, frame 112).

    Examples
    --------
    >>> from footfall.planner._crowd import touchdown_turn
    >>> float(touchdown_turn(1.0, 0.05, 0.03125, 0.0625))   # 1.6 rad/s for 0.0625 s
    0.1
    >>> float(touchdown_turn(1.0, 0.025, 0.03125, 0.0625))  # 0.8 rad/s
    0.05
    >>> float(touchdown_turn(1.0, 0.05, 0.03125, 0.25))   # ... for 0.25 s: 0.4, at most TOUCHDOWN_TURN_MAX
    0.1
    >>> float(touchdown_turn(-0.05, -0.05, 0.03125, 0.25)), float(touchdown_turn(1.0, 0.0, 0.03125, 0.25))
    (-0.05, 0.0)
    """
    limit = np.minimum(np.abs(turn_made) / dt * np.asarray(t, dtype=float), TOUCHDOWN_TURN_MAX)
    return np.clip(turn_left, -limit, limit)


def travel(speed, goal, acceleration: float, duration):
    """Distance (m) a body at ``speed`` covers in ``duration`` (s) while it changes speed toward
    ``goal`` at ``acceleration`` (m/s^2) and then keeps it (all broadcast).

    Examples
    --------
    >>> float(travel(0.0, 1.0, 1.0, 2.0))   # 0.5 m speeding up for 1 s, then 1 m at 1 m/s
    1.5
    >>> float(travel(1.0, 1.0, 1.0, 0.5))
    0.5
    """
    speed, goal, duration = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (speed, goal, duration)))
    ramp = np.minimum(np.abs(goal - speed) / acceleration, duration)
    sign = np.sign(goal - speed)
    return speed * ramp + 0.5 * sign * acceleration * ramp**2 + goal * (duration - ramp)


def _reach_xz(model: CrowdModel, legs=slice(None), drop=None) -> np.ndarray:
    """m, how far from its hip (horizontally) each leg reaches a foot ``drop`` below the hip (default:
    the ground on flat, the standing height below the pelvis), within the controller's reach margin."""
    reach = model.controller.reach_margin * model.reach[legs]
    dy = model.creature.standing_height + model.hips_body[legs, 1] if drop is None else drop
    return np.sqrt(np.maximum(reach**2 - dy**2, (0.2 * reach) ** 2))


def paths_through_body(model: CrowdModel, state: CrowdState, cs, ls, trajectories, valid) -> np.ndarray:
    """(F,) bool: valid plans of legs (``cs``, ``ls``) whose swing path (``trajectories`` (F, K, 3))
    passes, alongside the body (within half its body box's length of the pelvis, along the heading),
    further across its midline (the line through the pelvis along the heading, now) than both of its
    ends, and across it at all: a way under the body, between the hips. (Behind or in front of the
    body a path may cross: an ant's rear foot, standing 2 cm off the midline behind it, steps round
    a crate by 4 mm across; refused, it waited 15 frames.)

    The search keeps a path clear of the other legs' ground lines, not of the body: a quadruped's
    right front foot, its way ahead blocked by the left front foot (carried across the midline by a
    turn), was routed round that foot's hip, under the body, and its leg was drawn across the left
    one (``mixed``, 6 quadrupeds, seed 4009, frame 292). Such a plan waits a frame, as a conflicting
    one does (:func:`_same_frame_conflicts`). Legs on the midline (a robot5's front leg) have no side.
    A path starting (or ending) across, a foot coming back to its side, is not refused."""
    side = model.leg_sides[ls]
    d = trajectories[:, :, [0, 2]] - state.pelvis[cs][:, None, [0, 2]]
    forward, lateral = _rot_xz(-state.heading[cs][:, None], d[..., 0], d[..., 1])  # the path in the body's frame
    own_side = side[:, None] * lateral  # > 0: on the leg's own side
    alongside = np.abs(forward) <= 0.5 * model.creature.body_box[0]
    deepest = np.where(alongside, own_side, np.inf).min(axis=1)
    # A leg on the midline (side 0) has own_side 0 everywhere, never below its ends: never refused.
    return valid & (deepest < np.minimum(0.0, np.minimum(own_side[:, 0], own_side[:, -1])))


def swings_into_moving_boxes(model: CrowdModel, state: CrowdState, cs, ls, trajectories, swing_t, swing_T,
                             check, foot_yaws) -> np.ndarray:
    """(F,) bool: of the swings ``check`` of legs (``cs``, ``ls``) along ``trajectories`` (F, K, 3), at
    ``swing_t`` of ``swing_T`` s, those whose foot (turned by ``foot_yaws`` (F,), the yaw it swings
    with) meets a moving box on one of the frames to come, the box where it is then
    (:func:`swings_meet_moving_boxes`). A tucked ant's re-plan beside a crate moving
    at 0.34 m/s ran its foot 1 mm from the crate, and the next one into it (``mixed``, 64 ants, seed 1,
    frames 452-453): the map's cells are free of the crate, the points in them need not be."""
    out = np.zeros(cs.size, dtype=np.bool_)
    obs = model.raster.obstacles
    if not check.any() or len(obs.yaws) == 0 or bool(np.all(obs.is_static)):
        return out
    idx = np.flatnonzero(check)
    n_frames = max(1, int(math.ceil(float(np.max(swing_T[idx] - swing_t[idx])) / model.dt - 1e-9)))
    ahead = [_boxes_now(model, state.t + j * model.dt) for j in range(1, n_frames + 1)]
    centres = np.stack([b[0] for b in ahead])
    yaws = np.stack([b[2] for b in ahead])
    _, sizes, _, forbidden, moving = ahead[0]
    hit = np.zeros(idx.size, dtype=np.bool_)
    swings_meet_moving_boxes(np.ascontiguousarray(trajectories[idx]), np.ascontiguousarray(swing_t[idx], dtype=np.float64),
                             np.ascontiguousarray(swing_T[idx], dtype=np.float64), model.dt,
                             0.5 * model.creature.foot_length, 0.5 * model.creature.foot_width,
                             np.ascontiguousarray(foot_yaws[idx], dtype=np.float64), centres, yaws, sizes, forbidden,
                             moving, hit)
    out[idx] = hit
    return out


def _same_frame_conflicts(model: CrowdModel, cs, targets, valid, hips=None) -> np.ndarray:
    """(F,) bool: valid plans whose target lies within a foot's room of an earlier valid plan's target
    (this frame's plans): of another character, or of the same one (two legs of a character planned
    in one frame do not see each other's targets either: on a variant of the runtime, a spider's
    adjacent rear legs landed on one spot and crossed). With ``hips`` (F, 2) x, z at touchdown, also
    a plan whose ground line (hip to target) crosses an earlier plan's of the same character: a
    spider's two rear left legs, lifted together while it turned, were given targets whose lines
    crossed, and the legs were drawn crossed mid-swing (``mixed``, 3 spiders, seed 5)."""
    conflict = np.zeros(cs.size, dtype=np.bool_)
    if np.count_nonzero(valid) < 2:
        return conflict
    from scipy.spatial import cKDTree

    idx = np.flatnonzero(valid)
    radius = model.creature.foot_room
    pairs = cKDTree(targets[idx][:, [0, 2]]).query_pairs(radius, output_type="ndarray")
    if pairs.size:
        a, b = idx[pairs[:, 0]], idx[pairs[:, 1]]
        counted = (cs[a] == cs[b]) | model.controller.avoid_others_feet
        conflict[np.maximum(a, b)[counted]] = True
    if hips is not None:
        a, b = _same_character_pairs(cs, idx)
        if a.size:
            from footfall.planner._kernels_geometry import segments_cross_rows

            crossed = np.empty(a.size, np.bool_)
            segments_cross_rows(np.ascontiguousarray(hips[a]), np.ascontiguousarray(targets[a][:, [0, 2]]),
                                np.ascontiguousarray(hips[b]), np.ascontiguousarray(targets[b][:, [0, 2]]), crossed)
            conflict[b[crossed]] = True
    return conflict


def _same_character_pairs(cs, idx) -> tuple[np.ndarray, np.ndarray]:
    """(a, b): every pair of the plans ``idx`` (ascending) of one character, a before b."""
    order = idx[np.argsort(cs[idx], kind="stable")]
    a_parts, b_parts = [], []
    for d in range(1, order.size):
        same = cs[order[:-d]] == cs[order[d:]]
        if not same.any():
            break  # sorted by character: no group holds more than d plans
        a_parts.append(order[:-d][same])
        b_parts.append(order[d:][same])
    if not a_parts:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    a, b = np.concatenate(a_parts), np.concatenate(b_parts)
    return np.minimum(a, b), np.maximum(a, b)


DRAWN_LEG_TOLERANCE_M = 0.002
"""m: a leg whose drawn knees leave the segment between its drawn hip and foot by more than this is
kept clear of as drawn too (:func:`drawn_leg_segments`). A body pitched on a stair tilts its legs'
planes: a spider's knee was drawn 4 cm off its hip-to-foot line, and a landing clear of the line landed
across the knee (``stairs@terrain.rise=0.1,terrain.run=0.3``, seed 502, frames 6-7, legs 1 and 2)."""


def drawn_leg_segments(drawn, chars, legs, straight):
    """(rows (R, 5), start (F + 1,)): per planned foot, its other legs as drawn, where they leave a
    straight line: ``planner.layout.LEG_ROW`` rows that end in no foot.

    ``drawn`` (C, L, P, 3): the legs as drawn (:func:`rendered_joints`, hip first, foot last);
    ``chars`` (F,), ``legs`` (F, K): each planned foot's character and other legs; ``straight``
    (F, K, 4): the lines hip -> foot those legs are kept clear of at touchdown. A leg whose knees
    leave the segment between its drawn hip and foot by more than :data:`DRAWN_LEG_TOLERANCE_M`
    (a tilted body's legs; a quadruped's knee before or behind its hip) is moved onto its line: its
    hip to the line's hip, its foot to the line's foot, each knee by a blend of the two moves (its
    share of the leg's length from the hip), so its shape is carried, not scaled. A leg drawn along
    its line adds none (on flat ground, a spider's or an ant's).

    >>> drawn = np.zeros((1, 3, 3, 3))
    >>> drawn[0, 1, :, [0, 2]] = [[0.0, 0.05, 0.1], [0.0, 0.02, 0.0]]   # leg 1: its knee bows 2 cm
    >>> drawn[0, 2, :, 0] = [0.0, 0.05, 0.1]                            # leg 2: straight
    >>> straight = np.array([[[0.0, 1.0, 0.1, 1.0], [0.0, 0.0, 0.1, 0.0]]])  # leg 1 a metre on
    >>> rows, start = drawn_leg_segments(drawn, np.array([0]), np.array([[1, 2]]), straight)
    >>> rows.round(12).tolist(), start.tolist()     # leg 1's two segments, carried onto its line
    ([[0.0, 1.0, 0.05, 1.02, 0.0], [0.05, 1.02, 0.1, 1.0, 0.0]], [0, 2])
    """
    return bowed_legs_onto_lines(np.ascontiguousarray(drawn, dtype=np.float64), np.asarray(chars, dtype=np.int64),
                                 np.ascontiguousarray(legs, dtype=np.int64),
                                 np.ascontiguousarray(straight, dtype=np.float64), DRAWN_LEG_TOLERANCE_M,
                                 N_LEG_COLUMNS)


def _with_neighbours_feet(model: CrowdModel, state: CrowdState, cs, own, drawn_rows, drawn_start, preferred,
                          support):
    """(legs (M, 5), legs_start (F + 1,)): each planned foot's other legs (``own`` (F, K, 4), hip ->
    foot segments of its character), the feet of other characters near its preferred footprint, as
    zero-length legs (x, z, x, z): where they stand, or, swinging, where they will land
    (``support``, :func:`_landing_feet` of this state), then the segments of its other legs as
    drawn (``drawn_rows``, CSR by ``drawn_start``, :func:`drawn_leg_segments`). Rows are
    ``planner.layout.LEG_ROW``, those that end in a foot first: the order of
    :attr:`FootQuery.kernel_legs`, so a request rebuilt as a query plans the same.

    The search keeps a foot's room (``block_radius``) from every foot in the list, so a foot never lands
    on another character's foot (``shared_foot_spots``); a neighbour's foot also lowers the leg-spacing
    goodness like a foot of the character's own. Stamping whole cells around them in the maps (the
    ``others_in_maps`` option) blocked 20-30 cm around every foot and broke strides in crowds."""
    f, k = own.shape[0], own.shape[1]
    n_chars, n_legs = state.in_stance.shape
    n_drawn = np.diff(drawn_start)
    if not model.controller.avoid_others_feet or n_chars < 2 or f == 0:
        near = np.zeros(0, dtype=np.int64)
        counts = np.zeros(f, dtype=np.int64)
    else:
        from footfall.planner._kernels_geometry import points_near

        owner = np.repeat(np.arange(n_chars), n_legs)
        radius = model.config.search_radius_m + 2.0 * model.creature.foot_room
        # The other characters' feet only, ascending (a grid kernel: the k-d tree's lists of lists cost
        # 3.4 ms a frame for 1000 spiders).
        found_start, near = points_near(np.ascontiguousarray(support[..., [0, 2]].reshape(-1, 2)), owner,
                                        np.ascontiguousarray(preferred, dtype=np.float64),
                                        np.ascontiguousarray(cs, dtype=np.int64), radius)
        counts = np.diff(found_start)
    legs_start = np.zeros(f + 1, dtype=np.int64)
    np.cumsum(k + n_drawn + counts, out=legs_start[1:])
    legs = np.zeros((legs_start[-1], N_LEG_COLUMNS))
    mine = (legs_start[:-1, None] + np.arange(k)).ravel()
    legs[mine, :4] = own.reshape(-1, 4)
    legs[mine, LEG_FOOT] = 1.0
    if near.size:
        rows = _csr_rows(legs_start[:-1] + k, counts)
        legs[rows, :4] = support[..., [0, 2]].reshape(-1, 2)[near][:, [0, 1, 0, 1]]
        legs[rows, LEG_FOOT] = 1.0
    legs[_csr_rows(legs_start[:-1] + k + counts, n_drawn)] = drawn_rows
    return legs, legs_start


def at_neighbour_cap(model: CrowdModel) -> bool:
    """Whether the crowd walks at the speed where its legs' landing and lift-off spots keep no more than a foot's
    room from each other (``speed_cap_reason`` ``"neighbours"``, asked at least that speed): there a foot counted
    as standing when it has lifted (:func:`lifted_before`) takes the room the law's spots leave."""
    return model.speed_cap_reason == "neighbours" and model.speed_asked >= model.speed_cap


def _standing(state: CrowdState) -> np.ndarray:
    """(C,) bool: bodies that stand, held or stopped by their steering: their needles stop, and no foot lifts."""
    return state.body_held | (state.speed <= 0.0)


def lifted_before(model: CrowdModel, state: CrowdState, cs, others, t_land) -> np.ndarray:
    """(F, 2 K) bool, as :func:`_own_rows` orders them: which of each planned foot's other legs (``others``
    (F, K) of character ``cs`` (F,)) stand now and lift before the foot lands ``t_land`` (F,) s from now
    (:func:`until_lift`), twice over (the rows at touchdown, then the rows now).

    Such a foot stands nowhere when this one lands, so it keeps no foot's room from this one's leg: its
    leg's line still bounds the footprint. Counted as standing at touchdown, in a wave gait whose front
    foot lifts a few hundredths of a cycle before its rear neighbour lands, the front foot stood that much
    travel nearer the rear leg than it ever does, inside the room the neighbour speed cap keeps
    (``planner._workspace.neighbour_gaps``), and the rear foot landed a cell or two short, then long
    (random 8-legged creatures at their cap: per-stride p90 0.26-0.30 alone on flat ground).

    Only a lift the walk makes sure of: at the needle's present tempo, none for a body that stands (held,
    or stopped by its steering: its needle stops), and not a foot already waiting for a footprint
    (``wants_swing``, ``sector_missed``: it may wait on). A rear foot re-planned as its body stopped landed
    across its front neighbour's leg, which never lifted (a random 8-legged creature on ``mixed``: 33
    crossing frames); ``stage_plan`` leaves out such feet for new swings only, and only for a crowd at its
    neighbour cap (:func:`at_neighbour_cap`): below it the law's spots keep more than a room, and leaving them
    out changed the spider's crowded runs among crates for the worse (10 runs of 6 spiders on ``crates``: the
    per-stride median 0.026 -> 0.032, one run over the p90 bar), while on ``crates-moving`` it fell 0.014 -> 0.009."""
    c = cs[:, None]
    tempo = np.where(_standing(state), 0.0, state.stride_frequency)
    lift = np.where((tempo > 0.0)[:, None], _until_sector(model, state, np.maximum(tempo, 1e-300)), np.inf)[c, others]
    sure = state.in_stance[c, others] & ~state.wants_swing[c, others] & ~state.sector_missed[c, others]
    gone = sure & (lift < np.asarray(t_land)[:, None])
    return np.concatenate([gone, gone], axis=1)


def _own_rows(legs_start, k) -> np.ndarray:
    """(F, 2 k) the rows of each planned foot's own other legs in :func:`_with_neighbours_feet`' legs (its
    first ``2 k``: at touchdown, then now)."""
    return legs_start[:-1, None] + np.arange(2 * k)


def _csr_rows(first, counts) -> np.ndarray:
    """The rows ``first[i] .. first[i] + counts[i] - 1`` of every i, in order."""
    total = int(counts.sum())
    before = np.zeros(counts.size, dtype=np.int64)
    np.cumsum(counts[:-1], out=before[1:])
    return np.repeat(first - before, counts) + np.arange(total)


def _solve_feet(model: CrowdModel, state: CrowdState, cs, ls, hips, iterations: int, restarts: int,
                two_bone: bool = False):
    """CCD (or, with ``two_bone``, the closed-form solve of far characters) for legs (cs, ls)
    reaching for their feet from ``hips``, warm-started from the current angles (the one IK call
    of the controller's look-ahead and IK stages)."""
    from footfall.planner._ik import solve_legs_trusted

    legs = model.leg_static
    state.counters["ik_two_bone_legs" if two_bone else "ik_ccd_legs"] += int(cs.size)
    # The body poses as (yaw, pitch, roll): rotations built from angles need no orthonormality check.
    pose = np.column_stack([state.heading[cs], state.pitch[cs], state.roll[cs]])
    return solve_legs_trusted(hips, pose, legs.rest_azimuths[ls], legs.plane_rolls[ls], legs.segment_lengths[ls],
                              legs.limits[ls], np.broadcast_to(legs.azimuth_limits, legs.rest_azimuths.shape)[ls],
                              state.feet[cs, ls], state.angles[cs, ls], iterations, restarts, two_bone=two_bone)


def _stance_unreachable_ahead(model: CrowdModel, state: CrowdState, hips, frequency) -> np.ndarray:
    """(C, L) stance feet whose leg could not reach them ``lookahead_frames`` from now
    (IK with the hips carried forward; characters without IK are not checked)."""
    ctl = model.controller
    out = state.cannot_follow
    out &= state.in_stance  # a foot that stepped is followed again
    # Each character is checked every ``lookahead_every`` frames (in turns, so the cost is
    # spread); the look-ahead horizon covers the frames in between.
    turn = (np.arange(state.pelvis.shape[0]) + state.frame) % ctl.lookahead_every == 0
    far_chars = _characters_at(model, state, LEVEL_FAR)
    if model.lod_mode != "off":
        # A far character (LOD) looks ahead half as often, within the horizon the check covers.
        every = min(2 * ctl.lookahead_every, ctl.lookahead_frames)
        turn = np.where(far_chars, (np.arange(far_chars.size) + state.frame) % every == 0, turn)
    # A hidden character (LOD, off screen) is looked ahead too, with the two-bone solve: unchecked, its
    # body walked off a stance foot while hidden, and the first solve on screen missed it by 2-3 cm
    # (a 27-32 mm slip: crates-moving and mixed, quadrupeds, LOD zoomed).
    hidden = _characters_at(model, state, LEVEL_HIDDEN)
    cs, ls = np.nonzero(state.in_stance & ((state.ik_on | hidden) & turn)[:, None])
    if cs.size == 0:
        return out.copy()
    # Look no further than the foot's own lift-off: a foot whose sector starts within the horizon
    # leaves the ground before the body gets there (at speed, 4 frames are a third of a stride).
    g = state.gaits
    until_lift = np.mod(g.disk_start[cs, ls] - g.needle[cs], 1.0) / np.maximum(frequency[cs], 1e-9)
    horizon = np.minimum(ctl.lookahead_frames * model.dt, np.maximum(until_lift, model.dt))
    ahead = horizon * state.speed[cs]
    shifted = hips[cs, ls].copy()
    shifted[:, 0] += ahead * np.cos(state.heading[cs])
    shifted[:, 2] += ahead * np.sin(state.heading[cs])
    # Rising is what stretches a stance leg, so only a rise is carried forward: the last frame's,
    # and on up the slope the body walks (its pitch), at most the last frame's rise every frame.
    # Carrying a one-frame jump (a foot lifted off the hull's low side) on every frame of the
    # horizon predicted a rise of several cm that never came, and held the body: robot5 walked
    # up `hills` at 57 % of its asked speed at Fr 0.05, and every creature lost speed on `stairs`.
    rise = np.maximum(state.pelvis_rise[cs], 0.0)
    shifted[:, 1] += np.minimum((horizon / model.dt) * rise, rise + ahead * np.maximum(np.tan(state.pitch[cs]), 0.0))
    # A far character (LOD) looks ahead with its own IK, the two-bone solve; a hidden one too.
    two_bone = (far_chars | hidden)[cs]
    for far in (False, True) if two_bone.any() else (False,):
        k = np.flatnonzero(two_bone == far)
        if k.size == 0:
            continue
        res = _solve_feet(model, state, cs[k], ls[k], shifted[k], iterations=ctl.ik_iterations,
                          restarts=ctl.ik_restarts, two_bone=far)
        out[cs[k], ls[k]] = res.residual > ctl.ik_slip_margin
    return out.copy()


STEP_FOR_ASKED = 0.5
"""x the goal speed: the least asked speed a stance foot must carry the body at half of, or step out of
turn (stage_requests). With no floor (half of whatever the steering asks), the bar set's stuck count
went 4 -> 10 (seeds 3000-3009)."""


def stage_requests(model: CrowdModel, state: CrowdState, enter, boxes, hips, frequency, drawn=None) -> np.ndarray:
    """(C, L) int8 request kinds: 0 none, 1 new swing, 2 forced step, 3 re-plan. ``drawn``: the legs as
    drawn at ``hips`` (:func:`rendered_joints`; computed here unless the caller has them)."""
    ctl = model.controller
    waited = state.wants_swing & state.in_stance  # asked for a swing on an earlier frame, and still standing
    state.wants_swing |= (enter | state.sector_missed) & state.in_stance
    state.sector_missed &= ~state.in_stance
    kinds = np.zeros(state.in_stance.shape, dtype=np.int8)
    kinds[state.wants_swing & state.in_stance] = 1
    # A stance foot beyond its leg's horizontal reach steps, unless it is ahead of its hip and the
    # body walks (at least half its goal speed) toward it, so it comes back into reach (the IK
    # look-ahead below still holds a body whose leg cannot follow). Forcing those feet, just landed
    # ahead of a body slowed on a hill, made robot5's front legs step twice a cycle (strides 40-60 %
    # off the law). A body turning on the spot does not walk toward them, nor does one near a moving
    # box: it turns away from the box, off the heading the foot is ahead along.
    at_pace = state.speed >= 0.5 * sustained_speed(state)
    walking = at_pace & ~moving_box_near(model, state, boxes)
    dx, dz = state.feet[..., 0] - hips[..., 0], state.feet[..., 2] - hips[..., 2]
    ahead = walking[:, None] & (dx * np.cos(state.heading)[:, None] + dz * np.sin(state.heading)[:, None] > 0.0)
    far = (np.hypot(dx, dz) > _reach_xz(model)[None, :]) & ~ahead
    # A foot its leg lost in the last frame (the pose was taken back: the look-ahead missed the
    # hull's rise after a lift-off) steps too. The look-ahead alone, from a body held still, found
    # it reachable again: the body moved, lost it, and was held again, for good (a spider stood
    # 100 frames while a crate ran over it).
    state.unfollowed &= state.in_stance
    cannot_follow = _stance_unreachable_ahead(model, state, hips, frequency) | state.unfollowed
    # A stance foot at the rear end of its window steps now: the body cannot move on without it
    # (stance_speed_cap holds the body back), and its sector may be a cycle away.
    # A stance foot that holds the body under half its goal speed (stance_speed_cap) steps now too:
    # waiting for its sector, with the body slow and the needle slower, would freeze the walk. Half
    # the speed the steering asks, where a turn or a neighbour asks less (STEP_FOR_ASKED, never
    # under half the goal's half): held to half the goal, a `crates` spider turning at its full rate
    # (walking at 0.38 of its goal, median) lifted one foot in six out of turn; such a foot lands
    # mid-cycle, and the stride after it was half a stride (the bar set's per-stride runs).
    # A body at its goal (the steering's goal speed 0) does not move on: its feet need no room. Asked
    # for the walk's speed there, a spider at rest stepped one foot back and forth for good between a
    # spot past the rear of its window and one that capped the speed it was not going to walk.
    goal = state.goal_speed[:, None]
    room, lift = stance_room(model, state), until_lift(model, state)
    asked = np.maximum(np.minimum(state.goal_speed, state.speed_wanted), STEP_FOR_ASKED * state.goal_speed)[:, None]
    far |= cannot_follow | ((room <= 0.0) & (goal > 0.0)) | (leg_speed_caps(model, state, room, lift) < 0.5 * asked)
    # So does a stance foot that stops the body's turn (stance_turn_bounds: no room left), or holds the
    # turn of a slow body under half the turn asked: a body turning on the spot turns by stepping. Slow by
    # its speed alone: a body at its pace turns as its feet lift in their sectors, a moving box near or not.
    # Counted slow near one (as `walking` is, for the reach above), a quadruped walking at 0.27 m/s beside
    # a crate stepped its just-landed feet again a few frames later, strides 30-50 % short (crates-moving,
    # seed 20019, character 5): 40 seeds of crates-moving and 20 of mixed, the quadrupeds' per-stride p90
    # 0.143 -> 0.128 and 0.129 -> 0.093 (mean of the runs), the other creatures' runs unchanged.
    bound, wanted = leg_turn_bounds(model, state, lift), state.turn_wanted[:, None]
    holds_turn = (np.signbit(bound) == (wanted < 0.0)) & ~np.isnan(bound) & (wanted != 0.0)
    stops_turn = holds_turn & ((bound == 0.0) | ((np.abs(bound) < 0.5 * np.abs(wanted)) & ~at_pace[:, None]))
    far |= stops_turn
    # Such a foot of a character escaping a moving box's lane that finds no footprint tucks (stage_plan),
    # as a threatened one does: held, it kept the body from turning out of the lane until the box came.
    # So does a foot its leg cannot follow: with the box's path covering every spot within its reach, a
    # spider's three right legs planned no footprint for 25 frames, holding the body in the lane until
    # the crate ran over them (mixed, 8 spiders, seed 28: 161 foot-frames in the crate).
    state.blocks_escape = (stops_turn | cannot_follow) & state.escaping[:, None]
    # So does a stance leg the turn asked would carry across another (uncrossing_turn holds the turn).
    far |= turn_crossed_legs(model, state, state.turn_wanted)
    # A stance foot the body turned across another leg steps (its own side again).
    crossing = np.empty(state.in_stance.shape, dtype=np.bool_)
    if drawn is None:
        drawn = rendered_joints(model, state, hips)
    stance_legs_crossing(np.ascontiguousarray(drawn), state.in_stance, crossing)
    far |= crossing
    centres, sizes, yaws, forbidden, moving = boxes
    threatened = np.zeros(state.in_stance.shape, dtype=np.bool_)
    invalid = np.zeros(state.in_stance.shape, dtype=np.bool_)
    if moving.any():
        stance_threatened(state.in_stance, state.feet, 0.5 * model.creature.foot_length,
                          0.5 * model.creature.foot_width, state.foot_yaws, ctl.threat_margin, centres, sizes, yaws,
                          forbidden, moving, threatened)
        # A box on its way: where it will be ``threat_horizon`` from now. A foot needs a frame to
        # plan and a few to lift clear, and a crate at 0.4 m/s covers the 4 cm margin in 3 frames.
        later_centres, _, later_yaws, _, _ = _boxes_now(model, state.t + ctl.threat_horizon)
        threatened_later = np.zeros_like(threatened)
        stance_threatened(state.in_stance, state.feet, 0.5 * model.creature.foot_length,
                          0.5 * model.creature.foot_width, state.foot_yaws, ctl.threat_margin, later_centres, sizes,
                          later_yaws, forbidden, moving, threatened_later)
        threatened |= threatened_later
        swings_invalidated(state.in_stance, state.swing_t, state.swing_T, state.trajectories,
                           0.5 * model.creature.foot_length, 0.5 * model.creature.foot_width, state.foot_yaws,
                           centres, sizes, yaws, forbidden, moving, 2.0 * model.rest_radius + 1.0, invalid)
    state.threatened = threatened
    # Forced steps (out of reach, or a moving box coming): the worst first, and only while at
    # least half the feet stay on the ground.
    forced = state.in_stance & (far | threatened) & (kinds == 0)
    if forced.any():
        excess = np.where(forced, np.hypot(state.feet[..., 0] - hips[..., 0], state.feet[..., 2] - hips[..., 2])
                          + threatened + 10.0 * cannot_follow, -np.inf)
        rank = np.argsort(np.argsort(-excess, axis=1, kind="stable"), axis=1, kind="stable")
        spare = model.n_legs // 2 - (~state.in_stance).sum(axis=1)  # legs that may lift, gait and forced
        room = spare - (kinds == 1).sum(axis=1)
        # A foot about to be hit by a moving box lifts even past that limit.
        kinds[forced & ((rank < room[:, None]) | threatened)] = 2
        # A foot the body waits for (its leg cannot follow it) that found no room goes before the
        # gait's own swings: they wait, and the next landing makes room for it. Otherwise the other
        # legs stepped in turn on the spot, two in the air at any time, while the body waited for
        # good (robot5 over a low crate, crates-moving seed 0: 192 frames with a foot inside it).
        # Only where that makes room (a frame with no leg to spare changes nothing by waiting).
        starved = (cannot_follow & forced & (kinds == 0)).any(axis=1) & (spare > 0)
        if starved.any():
            kinds[starved[:, None] & (kinds == 1) & ~far] = 0  # a foot that must step anyway steps
            room = spare - (kinds == 1).sum(axis=1)
            kinds[forced & starved[:, None] & (rank < room[:, None])] = 2
    held = (cannot_follow & (kinds == 0)).any(axis=1)
    # Held from this frame on: take back this frame's move (the pelvis pose stays too).
    newly = held & ~state.body_held
    # A hold right after another one (the body barely moving again) says little about the speed the
    # legs sustain: one hold at most halves the limit.
    floor = 0.5 * np.minimum(state.speed_limit[newly], state.desired_speed[newly])
    state.speed_limit[newly] = np.minimum(state.speed_limit[newly],
                                          np.maximum(ctl.hold_backoff * state.speed[newly], floor))
    state.pelvis[newly, 0] -= state.last_move[newly, 0]
    state.pelvis[newly, 2] -= state.last_move[newly, 1]
    state.body_held = held
    swinging = ~state.in_stance
    turned = np.abs(_wrap(state.heading[:, None] - state.plan_heading)) > ctl.replan_heading
    scale = np.maximum(state.plan_speed, state.desired_speed[:, None])
    sped = np.abs(state.speed[:, None] - state.plan_speed) > ctl.replan_speed * scale
    # A foot about to land lands (re-planning it would only restart its swing), unless its
    # trajectory is now blocked.
    landing = state.swing_T - state.swing_t < 3.0 * model.dt
    respaced = np.abs(state.feet_spacing[:, None] - state.plan_spacing) > ctl.replan_spacing * state.plan_spacing
    # A tucked foot looks for a footprint every frame (the body moves on without it).
    # So does a foot in the air a shove carried onto another character's foot, landing or not (shoved by
    # the tuck distance, mixed, 64 ants, seed 2 had a foot spot shared with a neighbour in three frames).
    # A swing planned with a neighbour's foot left out as lifting first (lifted_before) whose neighbour still
    # stands, waiting since an earlier frame for a footprint it has not found, or held by a body that stopped:
    # the foot plans again with that foot standing. Landed on the plan, a rear foot stood across its front
    # neighbour's leg, which lifted 10 frames late (a random 6-legged creature on `crates`).
    late_lift = np.zeros_like(swinging)
    if state.counted_gone is not None and at_neighbour_cap(model):  # (empty below the cap: stage_plan)
        stopped = _standing(state)[:, None] & state.in_stance
        late_lift = swinging & (state.counted_gone & (waited | stopped)[:, None, :]).any(axis=2)
    kinds[swinging & (((turned | sped | respaced) & ~landing) | invalid | state.tucked | state.shoved_onto_feet
                      | late_lift)] = 3
    return kinds


def character_budgets(model: CrowdModel, state: CrowdState, boxes):
    """(couples_after_first (C,), slice_size (C,), on_screen (C,)) from the LOD mode and camera;
    with a LOD mode, each character's level of detail too (``state.lod_level``, planner._lod).
    ``boxes``: the frame's, as :func:`_boxes_now` gives them."""
    n = state.pelvis.shape[0]
    if model.lod_mode == "off":
        c, s, _ = (model.fixed_budget or FULL_SEARCH).kernel_args()
        return np.full(n, c, np.int64), np.full(n, s), np.ones(n, np.bool_)
    fov = float(model.camera.fov)
    if model.lod_mode == "on":
        camera = frame_crowd(state.pelvis, fov, fraction=1.0)
    else:
        camera = frame_crowd(state.pelvis, fov, fraction=0.5, focus=0)
    on_screen, distance = visibility(camera, state.pelvis)
    couples, slices = lod_budgets(on_screen, distance, model.lod)
    state.lod_level = lod_levels(on_screen, distance, state.lod_level, model.lod)
    # A moving box near a character makes its feet's choices matter whatever the camera sees: it
    # plans on the paper's maps and weighs at least ``moving_box_couples`` couples after the first
    # valid one (its IK keeps its level). With the first valid couple far feet stood in the crates'
    # way more often: 1000 spiders on mixed, 120 frames, seeds 0-2: 1031 feet in moving boxes,
    # 813 with LOD off, 839 with two couples near the crates.
    near = moving_box_near(model, state, boxes)
    state.near_moving_box = near
    couples = np.where(near, np.maximum(couples, model.lod.moving_box_couples), couples)
    return couples, slices, on_screen


def moving_box_near(model: CrowdModel, state: CrowdState, boxes) -> np.ndarray:
    """(C,) characters within ``LodConfig.moving_box_margin_m`` of a moving box's reach: the box's
    bounding circle grown by how far the character's feet plan (its rest radius, candidate disc and
    leg reach) and the margin. ``boxes``: the frame's, as :func:`_boxes_now` gives them."""
    centres, sizes, _, _, moving = boxes
    if not moving.any():
        return np.zeros(state.pelvis.shape[0], np.bool_)
    centres = centres[moving][:, [0, 2]]
    radius = 0.5 * np.hypot(sizes[moving, 0], sizes[moving, 2])
    span = model.rest_radius + model.config.search_radius_m + float(np.max(model.reach))
    reach = radius + span + model.lod.moving_box_margin_m  # (B,)
    d = np.hypot(state.pelvis[:, None, 0] - centres[None, :, 0], state.pelvis[:, None, 2] - centres[None, :, 1])
    return (d < reach[None, :]).any(axis=1)


def map_groups(model: CrowdModel, state: CrowdState, chars: np.ndarray) -> list[tuple[np.ndarray, bool]]:
    """The planning characters ``chars`` by how they plan: [(characters, far)], the near group
    first; one near group of them all with LOD off (the maps and the plan of the paper)."""
    if model.far_first is None:
        return [(chars, False)]
    far = (state.lod_level[chars] != LEVEL_FULL) & ~state.near_moving_box[chars]
    return [(g, flag) for g, flag in ((chars[~far], False), (chars[far], True)) if g.size]


def stage_maps(model: CrowdModel, state: CrowdState, chars: np.ndarray, boxes, config: PlannerConfig | None = None,
               count: bool = True):
    """Local maps of ``chars``, ``config.map_cells`` a side (the planner's by default; compact for the
    far characters, planner._far_planning): (elevation, ground, forbidden, origin). ``count``: add
    their cells to the work counters (not for maps built to measure a run, outside its frames)."""
    r = model.raster
    config = config or model.config
    n = config.map_cells
    k = chars.size
    if count:
        state.counters["map_cells_built"] += k * n * n
    elev = np.empty((k, n, n))
    ground = np.empty((k, n, n))
    forb = np.empty((k, n, n), dtype=np.uint8)
    origin = np.empty((k, 2))
    centres, sizes, yaws, forbidden, moving = boxes
    build_local_maps(r.ground, r.static_top, r.static_forbidden, r.frame.origin_x, r.frame.origin_z,
                     r.frame.cell_size, np.ascontiguousarray(state.pelvis[chars][:, [0, 2]]), centres, sizes, yaws,
                     forbidden, moving, elev, ground, forb, origin)
    if model.controller.others_in_maps:
        _stamp_others(model, state, chars, forb, origin, config)
    return elev, ground, forb, origin


def _stamp_others(model: CrowdModel, state: CrowdState, chars: np.ndarray, forb, origin, config: PlannerConfig) -> None:
    """Other characters' bodies and stance feet into the planning characters' obstacles' maps."""
    from scipy.spatial import cKDTree

    from footfall.planner._kernels_maps import stamp_other_characters

    n = state.pelvis.shape[0]
    if n < 2:
        return
    xz = np.ascontiguousarray(state.pelvis[:, [0, 2]])
    half_map = 0.5 * config.map_cells * config.cell_size
    radius = math.sqrt(2.0) * half_map + model.rest_radius + float(np.max(model.reach))
    lists = cKDTree(xz).query_ball_point(xz[chars], radius)
    counts = np.array([len(x) - 1 for x in lists], dtype=np.int64)
    start = np.zeros(chars.size + 1, dtype=np.int64)
    np.cumsum(counts, out=start[1:])
    index = np.empty(start[-1], dtype=np.int64)
    for k, (c, found) in enumerate(zip(chars, lists)):
        others = [j for j in found if j != c]
        index[start[k]:start[k + 1]] = sorted(others)
    box = model.creature.body_box
    # A swinging foot is stamped where it will land: two characters' feet planned a frame apart went
    # for the same spot, the later one not seeing the earlier one's target.
    support = _landing_feet(state)
    stamp_other_characters(forb, origin, config.cell_size, start, index, xz,
                           np.ascontiguousarray(state.heading), 0.5 * float(box[0]), 0.5 * float(box[1]),
                           np.ascontiguousarray(support[..., [0, 2]]), np.ones(state.in_stance.shape, np.bool_),
                           0.5 * float(model.creature.foot_length))


def lift_lateness(model: CrowdModel, state: CrowdState, cs, ls, frequency) -> np.ndarray:
    """(F,) s since the needle entered the sector of foot ``ls`` of character ``cs`` (F,) in this frame: a
    foot lifts at the first frame past that instant (:func:`planner._gait.advance`), under ``model.dt``
    after it. 0 for a foot whose sector the needle entered in an earlier frame (a lift that waited: a
    hold, a conflict, a late landing). ``frequency`` (F,) Hz: the needle's tempo in this frame (0: it
    stood, no lateness).

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import init_crowd
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> spider = load_creature("spider")
    >>> model, state = init_crowd(load_scenario("flat"), spider, default_gait(spider), n_characters=1)
    >>> state.gaits.needle[0] = state.gaits.disk_start[0, 2] + 0.01   # 0.01 of a cycle past leg 2's sector start
    >>> lift_lateness(model, state, np.array([0]), np.array([2]), np.array([1.0])).round(4).tolist()   # at 1 Hz
    [0.01]
    >>> lift_lateness(model, state, np.array([0]), np.array([2]), np.array([0.1])).tolist()   # entered 0.1 s ago
    [0.0]
    """
    phase = np.mod(state.gaits.needle[cs] - state.gaits.disk_start[cs, ls], 1.0)
    late = phase / np.maximum(frequency, 1e-12)
    return np.where((frequency > 0.0) & (late < model.dt), late, 0.0)


def stage_plan(model: CrowdModel, state: CrowdState, kinds, frequency, budgets, maps, groups, hips, boxes=None,
               planning=None, drawn=None):
    """Plan every request, one kernel call per planning group (``groups`` and their ``maps``,
    :func:`map_groups`, :func:`stage_maps`; a far group's fallback is one more); apply the results.
    Returns (the batch of the one near group, or None, the results of every request, the requests'
    characters, legs, every planning call as :class:`FramePlans` ``calls`` holds them). ``boxes``:
    where they are now (:func:`_boxes_now`); the feet are planned against ``planning``,
    :func:`_planning_boxes` of them (computed here unless the caller, which built the maps against
    them, passes them). ``drawn``: the legs as drawn at ``hips`` (:func:`rendered_joints`; computed
    here unless the caller has them)."""
    if planning is None and boxes is not None:
        planning = _planning_boxes(model, state, boxes)
    cs, ls = np.nonzero(kinds)
    f = cs.size
    n_legs = model.n_legs
    resume = resume_frequency(model, state)[cs]
    # The needle's tempo sets when the foot lifts again (the stance); a body standing (a hold, the
    # first frame) has none yet and takes the tempo of the walk it will resume.
    freq = frequency[cs]
    freq = np.maximum(np.where(freq <= 0.0, resume, freq), 1e-3)
    # A body standing or speeding up swings with the tempo of the walk it heads for, not of the
    # speed of the moment: the slow tempo's swing time kept feet in the air for most of a second at
    # a start (the 0.5 Hz floor at rest) while the needle, speeding up, lifted the other legs: a
    # spider on one foot, its legs crossing.
    swing_freq = np.maximum(freq, resume)
    durations = np.asarray(state.gaits.disk_duration)[cs, ls]
    new = kinds[cs, ls] != 3
    # A re-plan keeps the swing's time left; a tucked foot's re-plan is a new step from its tuck point
    # and takes a whole swing (given the flinch's two frames left, an ant's tucked foot went 0.189 m in
    # two frames: mixed, 64 ants, seed 1, frame 452).
    whole = new | state.tucked[cs, ls]
    t_swing = np.where(whole, np.minimum(durations / swing_freq, 1.0),
                       np.maximum(state.swing_T[cs, ls] - state.swing_t[cs, ls], 2.0 * model.dt))
    # The needle entered the foot's sector part of a frame before this frame's time (lift_lateness): the
    # footprint is planned for where the body will be a swing after that instant, so consecutive
    # footprints of a foot are a whole cycle's travel apart whichever frames the lifts fell on (timed
    # from the frames, a 2.4 cm creature stepping every 4.5 frames took strides of 4 and 5 frames'
    # travel, +-11 % off the law), and its stance is planned from that landing. The swing itself keeps
    # its frames: shortened by the lateness (landing a frame sooner now and then), the quadrupeds of
    # crates-moving were stuck in twice as many runs (10 -> 20 of 106).
    late = np.where(kinds[cs, ls] == KIND_NEW_SWING, lift_lateness(model, state, cs, ls, frequency[cs]), 0.0)
    t_land = np.maximum(t_swing - late, 0.0)  # s from this frame to the landing the schedule times
    duty = state.gaits.duty_factor[cs]
    nominal = np.where(np.isfinite(duty), duty, 1.0 - durations)
    # The stance lasts until the needle next enters the foot's sector: during a gait transition
    # that is where the sector is heading (the destination start), not the nominal duty factor.
    g = state.gaits
    landing_phase = g.needle[cs] + t_land * freq  # the sector's end unless the swing is quicker
    until_next = np.mod(g.dest_start[cs, ls] - landing_phase, 1.0)
    t_stance = np.clip(until_next, 0.5 * nominal, 1.5 * nominal) / freq
    heading = state.heading[cs]
    # The heading at touchdown: the body goes on turning at the rate it turns while its steering still
    # asks a turn (touchdown_turn). Planned for the heading at lift-off, a turning spider's side feet
    # landed a stride's turn times their 0.3 m reach ahead of or behind their rest points.
    turn = touchdown_turn(state.turn_left[cs], state.turn_made[cs], model.dt, t_swing)
    v = state.speed[cs]
    # Where the body will be: it keeps accelerating toward the speed the steering asked (a foot planned
    # at the start of a speed-up would otherwise land for the slower speed and trail out of reach).
    # That speed is after turns, avoidance and limits: planned for the sustainable speed instead, a
    # `crates` spider's feet landed for a body 1 / 0.72 as fast as the one that walked.
    goal = state.speed_wanted[cs]
    travel_swing = travel(v, goal, model.controller.acceleration, t_land)
    # along the chord of the arc it turns on
    chord = np.stack([np.cos(heading + 0.5 * turn), np.sin(heading + 0.5 * turn)], axis=1)
    pred = state.pelvis[cs][:, [0, 2]] + chord * travel_swing[:, None]
    heading = heading + turn
    fwd = np.stack([np.cos(heading), np.sin(heading)], axis=1)
    spacing = state.feet_spacing[cs]
    # The stance sweep v * T_stance is centred inside the leg's stance window (planner._workspace):
    # a leg whose rest foot sits near an end of its window would run out of reach before lift-off.
    from footfall.planner._workspace import slope_scale, stance_centres

    sweep = travel(v, goal, model.controller.acceleration, t_land + t_stance) - travel_swing
    # No stance carries a foot further than its leg's window (stance_speed_cap steps it at the rear
    # end): a longer predicted sweep (a start from rest, whose slow tempo promises a long stance) put
    # a rear foot half a sweep ahead of its window, in front of the body, across the other legs.
    window = model.stance_window[ls]
    sweep = np.minimum(sweep, window[:, 1] - window[:, 0])
    centre = stance_centres(spacing * model.rest_body[ls, 0], window, sweep,
                            min_slack=STANCE_SLACK_FRAMES * model.dt * np.maximum(v, goal))
    hx, hz = _rot_xz(heading, model.hips_body[ls, 0], model.hips_body[ls, 2])
    hip_pred = pred + np.stack([hx, hz], axis=1)
    # On a slope the ground under a foot is not where it is on flat: a foot at its horizontal rest
    # offset lands a slope's drop further below its hip on the downhill side (out of reach for a
    # sprawled leg) and closer on the uphill side. The offset from the hip is scaled so that the
    # hip-to-foot distance stays the rest one (planner._workspace.slope_scale); a leg under its hip
    # (a quadruped's) has no offset to scale.
    offset = np.stack([centre - model.hips_body[ls, 0], spacing * model.rest_body[ls, 1] - model.hips_body[ls, 2]],
                      axis=1)
    drop = model.creature.standing_height + model.hips_body[ls, 1]
    # Kept within [0.5, 1.25]: for a leg nearly under its hip the distance is all drop, and keeping it
    # would pull a downhill foot under the hip and throw an uphill one far out (legs cross).
    slope_forward, slope_left = np.tan(state.pitch[cs]), np.tan(state.roll[cs])
    scale = np.clip(slope_scale(offset, drop, slope_forward, slope_left), 0.5, 1.25)
    # The reach is measured where the foot lands: on the uphill side the ground is nearer the hip
    # and the leg reaches further out. The flat reach refused the uphill foot's own cell (slope_scale
    # throws it out to keep the leg's length), and that foot landed a cell short, then a cell long.
    ground_drop = drop - scale * (slope_forward * offset[:, 0] + slope_left * offset[:, 1])
    ox, oz = _rot_xz(heading, scale * offset[:, 0], scale * offset[:, 1])
    preferred = hip_pred + np.stack([ox, oz], axis=1) + fwd * stance_lead(sweep)[:, None]
    foot_yaw = np.arctan2(preferred[:, 1] - hip_pred[:, 1], preferred[:, 0] - hip_pred[:, 0])
    # The other legs at touchdown time: their hips carried forward with the pelvis, their feet
    # where they stand (or will land). Mixing predicted and current hips would make legs
    # 'cross' at the hips.
    support = _landing_feet(state)
    oj = model.other_legs[ls]  # (F, L-1)
    # A swinging neighbour is blocked both where its foot is now and where it will land, so two
    # legs swinging side by side do not cut across each other.
    shift = pred - state.pelvis[cs][:, [0, 2]]
    hx = hips[cs[:, None], oj, 0] + shift[:, None, 0]
    hz = hips[cs[:, None], oj, 2] + shift[:, None, 1]
    later = np.stack([hx, hz, support[cs[:, None], oj, 0], support[cs[:, None], oj, 2]], axis=-1)
    now = np.stack([hx, hz, state.feet[cs[:, None], oj, 0], state.feet[cs[:, None], oj, 2]], axis=-1)
    own = np.concatenate([later, now], axis=1)  # (F, 2 (L - 1), 4)
    if drawn is None:
        drawn = rendered_joints(model, state, hips)
    drawn_rows, drawn_start = drawn_leg_segments(drawn, cs, oj, now)
    legs, legs_start = _with_neighbours_feet(model, state, cs, own, drawn_rows, drawn_start, preferred, support)
    # Only a crowd at its neighbour cap leaves feet out (lifted_before), and keeps which (counted_gone): below it
    # the rooms have slack, and counted_gone stays empty.
    leaves_out = at_neighbour_cap(model)
    if leaves_out:
        gone = lifted_before(model, state, cs, oj, t_land) & (kinds[cs, ls] == KIND_NEW_SWING)[:, None]
        legs[_own_rows(legs_start, oj.shape[1])[gone], LEG_FOOT] = 0.0
    couples, slices, _ = budgets
    request = FootBatch(
        elevation=None, ground=None, forbidden=None, origins=None, foot_char=None,
        foot_shape=np.stack([np.full(f, model.creature.foot_length), np.full(f, model.creature.foot_width), foot_yaw],
                            axis=1),
        sources=np.ascontiguousarray(state.feet[cs, ls]), preferred=np.ascontiguousarray(preferred),
        hips=np.ascontiguousarray(hip_pred), reach_xz=_reach_xz(model, ls, ground_drop),
        step_height=np.full(f, model.step_height),
        legs=legs, legs_start=legs_start,
        block_radius=np.full(f, model.creature.foot_room),
        couples_after_first=couples[cs], slice_size=slices[cs],
        # the paper's early termination (§5.2) always, unless a fixed budget says otherwise
        early=np.full(f, model.fixed_budget is None or model.fixed_budget.paper_early_stop, np.bool_))
    out, calls = _plan_groups(model, state, request, cs, maps, groups, planning)
    batch = calls[0][0] if len(calls) == 1 and not groups[0][1] else None
    # Feet planned in the same frame do not see each other's targets: of two that would land within a
    # foot's room of each other, or two legs of one character whose ground lines would cross, the later
    # one (in plan order) waits a frame and plans again, seeing the other's target.
    ok = out.valid & ~_same_frame_conflicts(model, cs, out.target, out.valid, hip_pred)
    ok &= ~paths_through_body(model, state, cs, ls, out.trajectory, ok)
    # A swing that meets a moving box on the way waits a frame (the box moves on); a foot whose swing
    # already does, its re-plan refused, is tucked (it went on into the box).
    # Every plan let through turns its foot to the plan's yaw (assigned below), a re-plan where the foot is
    # in the air; a refused re-plan's foot keeps its own yaw and path.
    ok &= ~swings_into_moving_boxes(model, state, cs, ls, out.trajectory, np.zeros(f), t_swing, ok, foot_yaw)
    ok &= ~replans_turned_into_boxes(model, state, cs, ls, ok & ~new, foot_yaw, boxes)
    meets = swings_into_moving_boxes(model, state, cs, ls, state.trajectories[cs, ls], state.swing_t[cs, ls],
                                     state.swing_T[cs, ls], ~ok & ~new & ~state.in_stance[cs, ls],
                                     state.foot_yaws[cs, ls])
    vc, vl = cs[ok], ls[ok]
    if leaves_out and state.counted_gone is not None:
        state.counted_gone[vc, vl] = False
        state.counted_gone[vc[:, None], vl[:, None], oj[ok]] = gone[ok, :oj.shape[1]]
    state.trajectories[vc, vl] = out.trajectory[ok]
    state.swing_t[vc, vl] = 0.0
    state.swing_T[vc, vl] = t_swing[ok]
    state.swing_target[vc, vl] = out.target[ok]
    state.in_stance[vc, vl] = False
    state.wants_swing[vc, vl] = False
    state.plan_heading[vc, vl] = state.heading[vc]  # at lift-off: a re-plan is for a turn off the plan's
    state.plan_speed[vc, vl] = v[ok]
    state.plan_spacing[vc, vl] = spacing[ok]
    state.foot_yaws[vc, vl] = foot_yaw[ok]
    # A threatened foot with no footprint (the box covers its disc, its own legs the rest) is tucked
    # up near its hip rather than left under the box: held by it, a spider waited 70 frames while
    # a crate ran over its feet. A tucked foot whose re-plan fails follows its tuck point. (Tucking
    # every forced step left without a footprint, as a way out of holds, crossed spiders' adjacent
    # legs on the straight way in: 29 -> 51 crossings, crates-moving, 4 runs of 12 x 600 frames.)
    tucked = state.tucked[cs, ls].copy()
    state.tucked[vc, vl] = False
    tuck = ~ok & ((~out.valid & new & (state.threatened | state.blocks_escape)[cs, ls]) | tucked | meets)
    if tuck.any():
        # A new tuck is a flinch (TUCK_FRAMES); a tucked foot whose re-plan fails goes on as it was.
        left = np.where(new, TUCK_FRAMES * model.dt, state.swing_T[cs, ls] - state.swing_t[cs, ls])
        tuck_swings(model, state, cs[tuck], ls[tuck], hips, left[tuck], boxes)
    fresh = ok & new
    if fresh.any():
        offset = out.target[fresh][:, [0, 2]] - preferred[fresh]
        np.add.at(state.feedback, cs[fresh], 0.3 * (offset - state.feedback[cs[fresh]]))
    state.counters["plans"] += int(f)
    state.counters["holds"] += int((~out.valid & new).sum())
    state.counters["replans"] += int((kinds[cs, ls] == 3).sum())
    state.counters["cells_expanded"] += int(out.counters[:, CNT_EXPANDED].sum())
    state.counters["couples_evaluated"] += int(out.counters[:, CNT_COUPLES_3D].sum())
    state.counters["boxed_ways"] += int(out.counters[new, CNT_BOXED].sum())
    return batch, out, cs, ls, calls


TUCK_REACH = 0.25
"""x the rest foot's offset from its hip: how far out a tucked foot is held (tuck_swings)."""
TUCK_LIFT = 0.5
"""x the hip's height: how high a tucked foot is held above the ground under its hip."""
TUCK_FRAMES = 3
"""Frames a foot takes to tuck: a flinch, the fewest that never land it (tuck_swings). At the pace
of a swing (0.3 s) a crate closing at 0.3 m/s caught a spider's foot on its way in (crates-moving,
12 spiders, 1200 frames, seed 3: 3 collisions, 0 with the flinch; over 20 other runs of 12 x 600
frames the counts moved within their noise)."""
TUCK_TURN_STEP = np.radians(5.0)
"""rad: the steps in which a tucked foot with no clear tuck point is turned about its hip (:func:`tuck_points`)."""
TUCK_TURNS = 6
"""Steps of TUCK_TURN_STEP, either way, a tucked foot is turned at most (30 degrees)."""
TUCK_CLEARANCE = 0.005
"""m: how far past a box's side, beyond the foot's circumscribed radius, a tucked foot with no clear
tuck point is pushed (:func:`tuck_points`)."""


TUCK_REACHES = (TUCK_REACH, 0.15, 0.05)
"""x the rest foot's offset from its hip: where a tucked foot may be held, outermost first; the first
whose foot is clear of every box (:func:`tuck_points`). A spider escaping along a crate's side held
its outer tuck points inside the crate's corner, its body 6 cm from the crate (crates-moving, 12
spiders, 1200 frames, seed 3: 41 foot-frames in the crate, 34 with these; over 192 runs of 8 x 600
frames on crates-moving and mixed, 3574 -> 3011, leg crossings 351 -> 355). Not under the hip (reach
0): the leg's plane is undefined there and its knee swung across a neighbour's leg; nor under the body
(negative), where legs crossed five times as often. The foot is checked without the threat margin:
with it, feet moved in that the box would not have touched, and their swings out again crossed it.
Each leg holds its foot at the nearest of these, out from it, that its folded leg reaches
(``CrowdModel.tuck_reach``, :func:`planner._workspace.tuck_reaches`): an ant reaches none of them (its
least is 0.3-0.35), and the IK drew its feet 2.5-3 cm off their tuck points, into the crate they were
kept clear of (``mixed``, 64 ants, seed 3). Spiders and 5-legged robots reach all three; a quadruped,
lifting its foot half its hip's height, none at any reach, and keeps these."""


def replans_turned_into_boxes(model: CrowdModel, state: CrowdState, cs, ls, replans, foot_yaws, boxes) -> np.ndarray:
    """(F,) bool: of the re-plans ``replans`` of legs (``cs``, ``ls``), the feet in the air that their plan's
    yaw ``foot_yaws`` (F,), taken where the foot is this frame, puts into one of ``boxes`` (as
    :func:`_boxes_now` gives them): such a re-plan waits a frame, as one whose path meets a moving box
    does. A re-plan turns its foot in place; the path from there was checked, not the turn (a spider's
    foot turned 70 degrees beside a crate, into it: 1000 spiders, mixed, LOD on, seed 5, character 828,
    frame 179). New swings are not asked: a foot lifting leaves the spot it stands on, which a box may
    already reach (a threatened foot must lift)."""
    out = np.zeros(len(cs), np.bool_)
    turned = replans & ~state.in_stance[cs, ls]
    if turned.any() and len(boxes[0]):
        out[turned] = feet_in_boxes(model, state.feet[cs[turned], ls[turned]], foot_yaws[turned], boxes)
    return out


def feet_in_boxes(model: CrowdModel, points, yaws, boxes) -> np.ndarray:
    """(F,) bool: the creature's feet at ``points`` (F, 3), turned by ``yaws`` (F,), that overlap one of
    ``boxes`` (as :func:`_boxes_now` gives them) below its top, or a forbidden one at any height
    (:func:`planner._kernels_controller.points_in_boxes`)."""
    out = np.empty(len(points), np.bool_)
    points_in_boxes(np.ascontiguousarray(points, dtype=np.float64), 0.5 * model.creature.foot_length,
                    0.5 * model.creature.foot_width, np.ascontiguousarray(yaws, dtype=np.float64), *boxes[:4], out)
    return out


def feet_pushed_out_of_boxes(model: CrowdModel, points, yaws, boxes) -> np.ndarray:
    """(F, 3) ``points`` with each foot (turned by ``yaws``) that overlaps one of ``boxes`` moved out across
    the box's nearest side, :data:`TUCK_CLEARANCE` past the foot's circumscribed radius
    (:func:`planner._kernels_controller.push_out_of_boxes`, 4 passes)."""
    out = np.array(points, dtype=np.float64, order="C")
    push_out_of_boxes(out, 0.5 * model.creature.foot_length, 0.5 * model.creature.foot_width,
                      np.ascontiguousarray(yaws, dtype=np.float64), *boxes[:4], TUCK_CLEARANCE, 4)
    return out


def _tuck_offset(model: CrowdModel, spacing, ls, reach):
    """(x, z) in the body frame (forward, left) of leg ``ls``'s tuck point from its hip: ``reach`` of its
    rest foot's offset at feet spacing ``spacing`` (each broadcast against ``ls``)."""
    return (reach * (model.rest_body[ls, 0] * spacing - model.hips_body[ls, 0]),
            reach * (model.rest_body[ls, 1] * spacing - model.hips_body[ls, 2]))


def tuck_points(model: CrowdModel, state: CrowdState, cs, ls, hips, boxes=None) -> np.ndarray:
    """(F, 3) where foot ``ls`` of character ``cs`` is held when tucked: TUCK_REACH of its rest
    offset from its hip, on its own side (its leg crosses no other), TUCK_LIFT of the hip's height
    above the ground under the hip. Where that point is inside one of ``boxes`` (where they are now,
    :func:`_boxes_now`), or of the moving ones where they are one frame on (where the foot is judged
    at the frame's end) or heading (:func:`_planning_boxes`), the first of :data:`TUCK_REACHES` that is
    clear (each as far out as the leg reaches: ``model.tuck_reach``). Where none is and the last is in
    a box now or one frame on, the last turned about the hip by the least of :data:`TUCK_TURNS` steps
    of :data:`TUCK_TURN_STEP` either way that is clear; where none is, the last pushed out of those
    boxes (:func:`push_out_of_boxes`, :data:`TUCK_CLEARANCE`). Why: an ant's folded legs reach no
    nearer point than the first, and its body, turning away from a crate that followed it, swung the
    tuck point of the leg on the crate's side into it (``mixed``, 64 ants, seed 1, character 29, frame
    419, with the hysteresis of session 52, docs/crowds.md)."""
    from footfall.planner._workspace import tuck_drop

    hip = hips[cs, ls]
    drop = tuck_drop(model.creature, model.hips_body[ls, 1], TUCK_LIFT)
    reaches = model.tuck_reach[ls]  # the reaches the folded legs reach (init_crowd)

    def at(level):
        ox, oz = _rot_xz(state.heading[cs], *_tuck_offset(model, state.feet_spacing[cs], ls, reaches[:, level]))
        return np.column_stack([hip[:, 0] + ox, hip[:, 1] - drop, hip[:, 2] + oz])

    points = at(0)
    if boxes is None or not len(boxes[0]):
        return points
    near = _boxes_also_at(model, boxes, state.t + model.dt)
    every = _boxes_also_at(model, near, state.t + model.controller.threat_horizon)
    yaw = state.foot_yaws[cs, ls]

    def inside(rows, boxes):
        return feet_in_boxes(model, points[rows], yaw[rows], boxes)

    blocked = np.flatnonzero(inside(np.arange(len(cs)), every))
    for level in range(1, len(TUCK_REACHES)):
        if not blocked.size:
            break
        points[blocked] = at(level)[blocked]
        blocked = blocked[inside(blocked, every)]
    blocked = blocked[inside(blocked, near)]
    # Turned about the hip first, as far out: the leg reaches it where it reached the last. Pushed, a
    # foot may come nearer the hip than an ant's folded leg reaches; the IK then draws it off its point,
    # 2 cm into the crate (mixed, 64 ants, seed 2, character 34, frame 424, where no turn was clear).
    base = points[blocked] - hip[blocked]
    for k in range(1, TUCK_TURNS + 1):
        for sign in (1.0, -1.0):
            if not blocked.size:
                break
            ox, oz = _rot_xz(sign * k * TUCK_TURN_STEP, base[:, 0], base[:, 2])
            points[blocked, 0] = hip[blocked, 0] + ox
            points[blocked, 2] = hip[blocked, 2] + oz
            still = inside(blocked, every)
            points[blocked[still]] = hip[blocked[still]] + base[still]
            blocked, base = blocked[still], base[still]
    if blocked.size:
        points[blocked] = feet_pushed_out_of_boxes(model, points[blocked], yaw[blocked], near)
    return points


def tuck_swings(model: CrowdModel, state: CrowdState, cs, ls, hips, duration, boxes=None) -> None:
    """Swing feet ``ls`` of characters ``cs`` toward their tuck points (:func:`tuck_points`) over
    ``duration`` s (at least TUCK_FRAMES frames, so a tucked foot never lands): up first, then in.

    The defined fallback for a stance foot a moving box will cover and that has no footprint: the
    body is no longer held by it (other legs may still hold it), and the foot looks for a
    footprint every frame (``stage_requests``), landing as soon as it has one. ``boxes``: where they
    are now (:func:`_boxes_now`); a foot the path puts in one at the frame's end is held out of it."""
    target = tuck_points(model, state, cs, ls, hips, boxes)
    source = state.feet[cs, ls]
    u = np.linspace(0.0, 1.0, state.trajectories.shape[2])
    rise = np.minimum(1.0, 3.0 * u)
    across = u * u * (3.0 - 2.0 * u)
    path = source[:, None, :] + across[None, :, None] * (target - source)[:, None, :]
    path[..., 1] = source[:, None, 1] + rise[None, :] * (target[:, None, 1] - source[:, None, 1])
    duration = np.maximum(duration, TUCK_FRAMES * model.dt)
    if boxes is not None and len(boxes[0]):
        # Where the path puts the foot at the frame's end, in a box where it is then (the way in to the
        # tuck point crosses the way of a crate): pushed out from there instead, and held. An ant's foot
        # on its way in met the corner of the crate it fled (mixed, 64 ants, seed 5, character 34, frame 437).
        then = np.empty((len(cs), 3))
        swing_points(path, model.dt / duration, then)
        near = _boxes_also_at(model, boxes, state.t + model.dt)
        yaw = state.foot_yaws[cs, ls]
        blocked = feet_in_boxes(model, then, yaw, near)
        if blocked.any():
            out = feet_pushed_out_of_boxes(model, then[blocked], yaw[blocked], near)
            path[blocked] = out[:, None, :]
            target[blocked] = out
    state.trajectories[cs, ls] = path
    state.swing_target[cs, ls] = target
    state.swing_t[cs, ls] = 0.0
    state.swing_T[cs, ls] = duration
    state.in_stance[cs, ls] = False
    state.wants_swing[cs, ls] = False
    state.tucked[cs, ls] = True
    state.plan_heading[cs, ls] = state.heading[cs]
    state.plan_speed[cs, ls] = state.speed[cs]
    state.plan_spacing[cs, ls] = state.feet_spacing[cs]


def _plan_groups(model: CrowdModel, state: CrowdState, request: FootBatch, cs, maps, groups, boxes):
    """Plan the requests of ``request`` (a FootBatch without maps, one row per request of character
    ``cs``) with the maps of their character's group; a far group first tries near the preferred
    footprint, then the full first-valid search for the feet left without a valid couple
    (planner._far_planning). Returns (the results of every request, [(FootBatch, PlannerConfig,
    request rows, the characters of the batch's maps)] per planning call)."""
    n = state.pelvis.shape[0]
    done = []
    for (chars, far), (elev, ground, forb, origin) in zip(groups, maps):
        map_of = np.full(n, -1, np.int64)
        map_of[chars] = np.arange(chars.size)
        if len(groups) == 1:
            rows = np.arange(cs.size)
            sub = request
        else:
            rows = np.flatnonzero(map_of[cs] >= 0)
            sub = _take_requests(request, rows)
        batch = dataclasses.replace(sub, elevation=elev, ground=ground, forbidden=forb, origins=origin,
                                    foot_char=map_of[cs[rows]])
        config = model.far_first if far else model.config
        done.append((batch, config, rows, chars, plan_batch(batch, model.weights, config, parallel=True)))
        missed = np.flatnonzero(~done[-1][4].valid) if far else np.zeros(0, np.int64)
        if missed.size:
            # The fallback's larger maps, for the characters with a foot to retry only.
            again, foot_char = np.unique(batch.foot_char[missed], return_inverse=True)
            wide = stage_maps(model, state, chars[again], boxes, model.far_fallback)
            retry = dataclasses.replace(_take_requests(batch, missed), elevation=wide[0], ground=wide[1],
                                        forbidden=wide[2], origins=wide[3], foot_char=foot_char.astype(np.int64))
            done.append((retry, model.far_fallback, rows[missed], chars[again],
                         plan_batch(retry, model.weights, model.far_fallback, parallel=True)))
    if len(done) == 1:
        out = done[0][4]
    else:
        # A retried foot's result replaces its first try's; the work of both is counted.
        counters = np.zeros((cs.size,) + done[0][4].counters.shape[1:], np.int64)
        for _, _, rows, _, result in done:
            counters[rows] += result.counters
        out = _merge_results([(rows, result) for _, _, rows, _, result in done], cs.size)
        out.counters[:] = counters
    return out, [(batch, config, rows, chars) for batch, config, rows, chars, _ in done]


def _take_requests(request: FootBatch, rows: np.ndarray) -> FootBatch:
    """The requests ``rows`` of ``request`` (maps not set), each keeping its other legs."""
    starts = request.legs_start
    counts = starts[rows + 1] - starts[rows]
    legs_start = np.zeros(rows.size + 1, np.int64)
    np.cumsum(counts, out=legs_start[1:])
    leg_rows = _csr_rows(starts[rows], counts)
    per_foot = {name: np.ascontiguousarray(getattr(request, name)[rows])
                for name in ("foot_shape", "sources", "preferred", "hips", "reach_xz", "step_height", "block_radius",
                             "couples_after_first", "slice_size", "early")}
    return dataclasses.replace(request, legs=np.ascontiguousarray(request.legs[leg_rows]), legs_start=legs_start,
                               **per_foot)


def _merge_results(parts, n: int):
    """One BatchResult of ``n`` requests from [(rows, BatchResult of those rows)]."""
    from footfall.planner._batch import BatchResult

    first = parts[0][1]
    merged = BatchResult(**{name: np.zeros((n,) + getattr(first, name).shape[1:], getattr(first, name).dtype)
                            for name in BatchResult.__dataclass_fields__})
    for rows, result in parts:
        for name in BatchResult.__dataclass_fields__:
            getattr(merged, name)[rows] = getattr(result, name)
    return merged


def stage_pelvis(model: CrowdModel, state: CrowdState, smoothing: float | None = None) -> None:
    """Pelvis height, pitch and roll on the support hulls, followed with the controller's
    ``pelvis_lag`` (``smoothing`` 1: none, the first frame's pose)."""
    r = model.raster
    support = np.ascontiguousarray(_landing_feet(state))
    # A tucked foot lands nowhere: its tuck point, up by the hip, is no support (as one it moved the
    # body by 5-8 cm, and back in a frame when the foot found a footprint: crates-moving, 12 spiders,
    # seed 3).
    lands = state.in_stance | ~state.tucked
    bob = model.controller.bob_factor * model.creature.standing_height * np.sin(4.0 * np.pi * state.gaits.needle)
    if smoothing is None:
        smoothing = -math.expm1(-model.dt / model.controller.pelvis_lag) if model.controller.pelvis_lag > 0 else 1.0
    state.pelvis_rise[:] = -state.pelvis[:, 1]
    y = np.empty(state.pelvis.shape[0])
    pitch = np.empty_like(y)
    roll = np.empty_like(y)
    base = np.empty_like(y)
    pelvis_from_hulls(r.static_top, r.frame.origin_x, r.frame.origin_z, r.frame.cell_size, state.pelvis,
                      state.heading, support, np.ascontiguousarray(state.feet), state.in_stance, lands,
                      float(model.creature.body_box[0]),
                      float(model.creature.body_box[1]), float(model.creature.standing_height), model.height_range,
                      float(model.creature.body_thickness), bob, float(smoothing), state.pelvis_base, state.pitch, state.roll,
                      y, pitch, roll, base)
    # A held body (a stance leg at the end of its reach) keeps its whole pose until the leg steps.
    moving = ~state.body_held
    state.pelvis[moving, 1] = y[moving]
    state.pitch[moving] = pitch[moving]
    state.roll[moving] = roll[moving]
    state.pelvis_base[moving] = base[moving]
    state.pelvis_rise += y - lower_to_landings(model, state, moving)
    # A tucked foot is held by its hip (tuck_points: a height above the ground under the hip, planned from
    # the hips before this stage): it rises and falls with the body. Left where it was planned, a body
    # falling 7 cm in a frame left it 4.5 cm above its hip, out of the folded leg's reach, and the IK drew
    # it 1-1.1 cm into the crate beside it (mixed, 64 ants, seed 2, character 34, frames 411, 426, 441,
    # while every foot in the air of a shoved body re-planned: see _landings_shoved_onto_feet).
    cs, ls = np.nonzero(state.tucked & ~state.in_stance)
    if cs.size:
        rise = state.pelvis_rise[cs]
        state.feet[cs, ls, 1] += rise
        state.trajectories[cs, ls, :, 1] += rise[:, None]
        state.swing_target[cs, ls, 1] += rise


LANDING_REACH_MARGIN = 2e-4
"""m a foot landing within the next frame keeps inside its leg's reach (below the IK's 'cannot follow'
margin, ``ControllerConfig.ik_slip_margin``)."""


def lower_to_landings(model: CrowdModel, state: CrowdState, moving: np.ndarray) -> np.ndarray:
    """Lower each body in ``moving`` (C,) bool as far as its feet that land within the next frame need
    to lie within their legs' reach (LANDING_REACH_MARGIN inside it), where lowering can bring them there.
    Why: a foot is planned within reach of the hip it expects at touchdown, and the body's bob and a
    turn during the swing carried the hip 2 mm further: the foot landed out of reach, the IK drew it
    short, and a frame later, the hip back in reach, the drawn foot moved 1.9 mm on the ground
    (1000 spiders, mixed, LOD on, seed 3, character 155, leg 1, frame 93)."""
    dt = model.dt
    landing = ~state.in_stance & ~state.tucked & (state.swing_t + dt >= state.swing_T - 1e-9) & moving[:, None]
    lower = np.zeros(state.pelvis.shape[0])
    if not landing.any():
        return lower
    cs, ls = np.nonzero(landing)
    hips = state.pelvis[cs] + _hip_offsets(model, state, cs)[np.arange(cs.size), ls]
    gap = hips - state.swing_target[cs, ls]
    across = np.hypot(gap[:, 0], gap[:, 2])
    reach = model.reach[ls] - LANDING_REACH_MARGIN
    up = np.sqrt(np.maximum(reach * reach - across * across, 0.0))
    drop = np.where(across < reach, np.maximum(gap[:, 1] - up, 0.0), 0.0)
    np.maximum.at(lower, cs, drop)
    state.pelvis[:, 1] -= lower
    state.counters["landing_drops"] += int((lower > 0).sum())
    return lower


def stage_ik(model: CrowdModel, state: CrowdState, on_screen: np.ndarray) -> None:
    """CCD for every leg of the characters that need it, warm-started from the previous
    frame: stance legs with their full sweeps (a stance foot must be followed exactly), swinging
    legs with a few, and the full ones only where those leave a foot off its path
    (:func:`_solve_into_state`).

    With a LOD mode, a far character (``LEVEL_FAR``) is solved in closed form instead, from its
    previous pose: the azimuth and two hinges (``solve_legs(..., two_bone=True)``), exact wherever
    those reach, a few trigonometric calls per leg instead of a CCD sweep's dozens."""
    state.ik_on[:] = False
    if not on_screen.any():
        return
    hips = hips_world(model, state)
    ctl = model.controller
    far = _characters_at(model, state, LEVEL_FAR) & on_screen
    for stance in (True, False):
        cs, ls = np.nonzero((on_screen & ~far)[:, None] & (state.in_stance == stance))
        if cs.size:
            _solve_into_state(model, state, cs, ls, hips, stance, ctl.ik_restarts)
    if far.any():
        cs, ls = np.nonzero(np.broadcast_to(far[:, None], state.in_stance.shape))
        res = _solve_feet(model, state, cs, ls, hips[cs, ls], 1, 0, two_bone=True)
        # Where the closed form (and its one sweep) leaves a foot, the CCD of the near characters
        # takes over from the last pose: a far leg is never drawn short of a foot the CCD reaches.
        short = res.residual > ctl.ik_slip_margin
        state.angles[cs[~short], ls[~short]] = res.angles[~short]
        state.residual[cs[~short], ls[~short]] = res.residual[~short]
        state.fk_feet[cs[~short], ls[~short]] = res.feet[~short]
        if short.any():
            cs, ls = cs[short], ls[short]
            again = _solve_feet(model, state, cs, ls, hips[cs, ls], ctl.ik_iterations, ctl.ik_restarts)
            state.angles[cs, ls] = again.angles
            state.residual[cs, ls] = again.residual
            state.fk_feet[cs, ls] = again.feet
    state.ik_on[on_screen] = True
    _take_back_unfollowed_poses(model, state, on_screen)


def _characters_at(model: CrowdModel, state: CrowdState, level: int) -> np.ndarray:
    """(C,) the characters at LOD ``level`` (planner._lod.LEVEL_*); none without a LOD mode. LEVEL_FAR:
    those whose IK is the closed-form two-bone solve; LEVEL_HIDDEN: those off screen (no IK)."""
    if model.lod_mode == "off":
        return np.zeros(state.pelvis.shape[0], np.bool_)
    return state.lod_level == level


def _pose(state: CrowdState) -> np.ndarray:
    """(C, 7) pelvis x, y, z, heading, pitch, roll and base height (stage_pelvis)."""
    return np.column_stack([state.pelvis, state.heading, state.pitch, state.roll, state.pelvis_base])


def _take_back_unfollowed_poses(model: CrowdModel, state: CrowdState, on_screen: np.ndarray) -> None:
    """A stance foot stays where it touched down: a body whose new pose (a move, a turn, a
    pelvis that rose with the hull) leaves a stance leg unable to reach its foot takes the
    whole frame's pose back, and holds until that foot has stepped (the look-ahead of
    ``stage_requests`` misses what it does not predict, such as the hull after a lift-off)."""
    ctl = model.controller
    failed = state.in_stance & (state.residual > ctl.ik_slip_margin) & on_screen[:, None]
    bad = failed.any(axis=1)
    if not bad.any():
        return
    state.body_held[bad] = True
    state.cannot_follow[bad] |= failed[bad]
    state.unfollowed[bad] |= failed[bad]
    _take_back_poses(model, state, bad)
    state.counters["pose_takebacks"] += int(bad.sum())


def _take_back_crossing_poses(model: CrowdModel, state: CrowdState, stance_before: np.ndarray) -> None:
    """Two legs whose feet stood at the start of a frame (standing through it, or lifting in it: a swing
    starts where its foot stood) are never drawn crossed by the body's own motion: a body
    whose new pose (a turn, a move, a tilt) carries two such legs across each other takes the whole
    frame's pose back (``stage_requests`` then steps the legs the turn it asked would cross:
    :func:`turn_crossed_legs`). The turn check of the steering (:func:`uncrossing_turn`) sees the
    straight hip-to-foot lines of the pose before the move; the legs as drawn, with their knees, after
    the move and the tilt, crossed on turns on the spot (crates-moving, 12 spiders, seed 3).
    ``stance_before``: the stance feet at the start of the frame. Keeps ``state.crossed``."""
    from footfall.planner._counters import rendered_joints
    from footfall.planner._kernels_controller import crossing_pairs

    # The legs whose feet stood at the start of the frame: those that stand through it and those that
    # lift in it (a swing starts at its source, where the foot stood: the body's move alone drew it
    # across its neighbour, spider on crates@seed=13, seed 506, frame 29).
    n, L = state.in_stance.shape
    pairs = np.empty((n, L, L), np.bool_)
    crossing_pairs(np.ascontiguousarray(rendered_joints(model, state)), stance_before, pairs)
    new = pairs & ~state.crossed
    moved = np.any(_pose(state) != state.pose_before, axis=1)
    # Legs drawn by the IK only (as _take_back_unfollowed_poses): an off-screen character's legs are
    # not drawn, and taking its pose back would solve the IK the level of detail skips.
    bad = new.any(axis=(1, 2)) & moved & state.ik_on
    if bad.any():
        _take_back_poses(model, state, bad)
        redo = np.empty((int(bad.sum()), L, L), np.bool_)
        crossing_pairs(np.ascontiguousarray(rendered_joints(model, state)[bad]), stance_before[bad], redo)
        pairs[bad] = redo
        state.counters["crossing_takebacks"] += int(bad.sum())
    state.crossed = pairs


def _take_back_poses(model: CrowdModel, state: CrowdState, bad: np.ndarray) -> None:
    """Characters ``bad`` (C,) bool take the whole frame's pose back (``state.pose_before``), stand,
    and solve their legs' IK again for it."""
    ctl = model.controller
    before = state.pose_before[bad]
    state.pelvis[bad] = before[:, :3]
    state.heading[bad] = before[:, 3]
    state.pitch[bad] = before[:, 4]
    state.roll[bad] = before[:, 5]
    state.pelvis_base[bad] = before[:, 6]
    state.speed[bad] = 0.0
    hips = hips_world(model, state)
    for stance, restarts in ((True, ctl.ik_restarts), (False, 0)):
        cs, ls = np.nonzero(bad[:, None] & (state.in_stance == stance))
        if cs.size:
            _solve_into_state(model, state, cs, ls, hips, stance, restarts)


def _solve_into_state(model: CrowdModel, state: CrowdState, cs, ls, hips, stance: bool, restarts: int) -> None:
    """CCD for legs (cs, ls) from ``hips`` (C, L, 3), all standing (``stance``) or all swinging, into
    the state's angles, residuals and drawn feet: a stance leg gets ``ik_iterations`` sweeps; a swinging
    one ``ik_swing_iterations`` and, where those leave it over ``ik_slip_margin`` off its foot, a stance
    leg's sweeps and restarts from there. A swinging leg's few sweeps follow a foot that moves smoothly;
    where the body's pose jumps (the hull at a lift-off) they left a quadruped's foot 3.7 mm off its
    path, 4 mm inside the crate it lifted from (crates-moving, seed 5008, LOD off, character 1, leg 3,
    frame 380)."""
    ctl = model.controller
    for attempt in range(1 if stance else 2):
        iterations = ctl.ik_iterations if stance or attempt else ctl.ik_swing_iterations
        # _solve_feet starts from the state's angles: a second attempt goes on from the first's.
        res = _solve_feet(model, state, cs, ls, hips[cs, ls], iterations, restarts if not attempt else ctl.ik_restarts)
        state.angles[cs, ls] = res.angles
        state.residual[cs, ls] = res.residual
        state.fk_feet[cs, ls] = res.feet
        short = res.residual > ctl.ik_slip_margin
        if not short.any():
            break
        cs, ls = cs[short], ls[short]


# ----------------------------------------------------------------------------- set-up
def crowd_radius(creature, rest_radius: float | None = None) -> float:
    """m: the radius a character takes in a crowd: its rest radius (``rest_radius``, the creature's by
    default), or more for a body box that reaches beyond :data:`AVOID_RADIUS_MIN` of it (a quadruped's
    0.6 m body: the avoidance disc covers the body, and spawns 1.5 such radii apart cannot overlap).

    Examples
    --------
    >>> from footfall.scenarios import load_creature
    >>> spider, dog = load_creature("spider"), load_creature("quadruped")
    >>> crowd_radius(spider) == float(spider.rest_radius)
    True
    >>> round(AVOID_RADIUS_MIN * crowd_radius(dog), 3) == round(0.5 * float(np.hypot(*dog.body_box)), 3)
    True
    """
    rest = float(creature.rest_radius) if rest_radius is None else float(rest_radius)
    return max(rest, 0.5 * float(np.hypot(*creature.body_box)) / AVOID_RADIUS_MIN)


def avoid_radius(creature, rest_radius: float | None, positions: np.ndarray) -> float:
    """m: the disc a crowd's characters keep clear of each other: :data:`AVOID_RADIUS` x their crowd
    radius, or half the least spacing they were spawned at (a crowd spawned denser), at least
    :data:`AVOID_RADIUS_MIN` x it (the body).

    >>> from footfall.scenarios import load_creature
    >>> spider = load_creature("spider")
    >>> r = crowd_radius(spider)
    >>> avoid_radius(spider, None, np.array([[0.0, 0.0], [3.0 * r, 0.0]])) == r
    True
    >>> round(avoid_radius(spider, None, np.array([[0.0, 0.0], [1.5 * r, 0.0]])) / r, 3)
    0.742
    """
    radius = crowd_radius(creature, rest_radius)
    positions = np.asarray(positions, dtype=np.float64)
    if positions.shape[0] < 2:
        return AVOID_RADIUS * radius
    from scipy.spatial import cKDTree

    gap = float(cKDTree(positions).query(positions, k=2)[0][:, 1].min())
    return float(np.clip(0.5 * 0.99 * gap, AVOID_RADIUS_MIN * radius, AVOID_RADIUS * radius))


SPAWN_CLEAR_STEP = 0.1
"""s: the step at which the places of the boxes over the crowd's ``spawn_clear_s`` are taken."""


def spawn_positions(scenario, creature, n: int, spacing_factor: float = 2.1):
    """n start positions (x, z) on a sunflower spiral around the crowd centre, clear of the boxes
    over the crowd's first ``spawn_clear_s`` (scenarios.CrowdSpawn).

    Creatures are ``spacing_factor`` x their crowd radius (:func:`crowd_radius`, the rest radius
    for most) apart; when the world is too small the spacing shrinks (down to one radius: legs
    interleave). Raises ``InputError`` when even that does not fit.
    """
    from footfall._errors import InputError

    rest = crowd_radius(creature)
    obs = scenario.obstacles
    # Where each box will be over the crowd's spawn_clear_s (3 s by default, the lane exit's horizon): a
    # spider spawned 0.5 m before a crate coming at it spent its first second turning on the spot and was
    # run over (1000 spiders, mixed, seed 0: 151 of the run's 322 foot-frames in boxes; 8 after).
    # A static box is where it starts at every one of those times: it is checked once.
    spots = []  # (centres (B, 3), half diagonals (B,)) to keep clear of
    if len(obs.yaws):
        paths = obs.centres_over(np.arange(0.0, scenario.crowd.spawn_clear_s + 1e-9, SPAWN_CLEAR_STEP))
        box_r = 0.5 * np.hypot(obs.sizes[:, 0], obs.sizes[:, 2])
        still = np.asarray(obs.is_static)
        spots = [(paths[0, still], box_r[still])] + [(centres, box_r[~still]) for centres in paths[:, ~still]]
    x0, x1 = scenario.terrain.x_range
    z0, z1 = scenario.terrain.z_range
    golden = math.pi * (3.0 - math.sqrt(5.0))
    for factor in (spacing_factor, 1.5, 1.25, 1.0):
        spacing = factor * rest
        m = 8 * n + 64
        k = np.arange(m)
        r = spacing * np.sqrt(k / math.pi)  # sunflower spiral: neighbours about `spacing` apart
        a = k * golden
        pts = scenario.crowd.centre[None, :] + np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
        inside = (pts[:, 0] > x0 + rest + 0.5) & (pts[:, 0] < x1 - rest - 0.5) & (pts[:, 1] > z0 + rest + 0.5) & (
            pts[:, 1] < z1 - rest - 0.5)
        clear = np.ones(m, np.bool_)
        for centres, radii in spots:
            d = np.hypot(pts[:, None, 0] - centres[None, :, 0], pts[:, None, 1] - centres[None, :, 2])
            clear &= (d > radii[None, :] + rest + 0.1).all(axis=1)
        # The spiral's neighbours are only about `spacing` apart (its first two points 0.56 x):
        # keep a point only if it is at least `spacing` from every point kept before it.
        kept: list[int] = []
        for i in np.flatnonzero(inside & clear):
            if not kept or np.min(np.hypot(*(pts[kept] - pts[i]).T)) >= spacing - 1e-9:
                kept.append(int(i))
                if len(kept) == n:
                    return pts[kept]
    raise InputError(scenario.source, "crowd.count", f"no room for {n} x {creature.name} clear of the obstacles")


def set_feet_spacing(state: CrowdState, characters, scale) -> None:
    """Change the feet spacing (scale of the rest feet, > 0) of some characters at run time;
    their swinging feet re-plan (paper §3.2, Fig. 6)."""
    scale = np.asarray(scale, dtype=np.float64)
    if not (np.isfinite(scale).all() and (scale > 0).all()):
        raise ValueError(f"scale: expected positive numbers, got {scale!r}")
    state.feet_spacing[characters] = scale


def planning_span(creature, config: PlannerConfig) -> float:
    """How far (m) from its centre a creature's feet plan: its rest radius, the candidate disc and
    its longest leg's reach (what its local maps must hold, with a margin: ``init_crowd``)."""
    return float(creature.rest_radius) + config.search_radius_m + float(np.max(creature.leg_reach))


FOOT_GAP_CELLS = 2.5
"""Cells at least between a creature's two nearest rest feet (``planner_config_for``): with fewer, the
other legs' rooms block the cells round a preferred footprint. Random creatures of 6-8 legs with 0.9-1.4
cells between neighbouring rest feet failed 90 of 90 ``footfall evaluate`` runs (per-stride p90 0.43-0.62,
thousands of crossing frames; 80 with this rule, their crossing frames 17,155 -> 6,792); those with 2.6-3.3
cells, and every built-in creature (2.6-6.7; the mite 2.0 at the 1 cm floor then, 4.0 at MIN_CELL_M), few or none
(docs/locomotion.md, session 63)."""


MIN_CELL_M = 0.005
"""m, the finest cells ``planner_config_for`` gives. At 1 cm, two random creatures whose nearest rest feet
are 2.0 and 2.1 cm apart (``FOOT_GAP_CELLS`` asks 0.8-0.9 cm cells) had their footprints pushed a cell back
off their neighbours' rooms: per-stride p90 0.18-0.32 on every built-in scenario, 0.07-0.20 at 5 mm
(docs/locomotion.md, session 64)."""


def planner_config_for(creature) -> PlannerConfig:
    """The paper's 70 x 70 maps of 7 cm cells, with finer cells (and a smaller candidate disc)
    for creatures too small for 7 cm: about four cells from the body centre to a rest foot; and
    more cells for a creature too large for 70 (its feet plan further than the maps reach).

    Parameters
    ----------
    creature : scenarios.Creature
        Its ``rest_radius`` (m) sets the cell size: a quarter of it rounded to 5 mm, at most the
        nearest two rest feet's gap over :data:`FOOT_GAP_CELLS` (rounded down to 5 mm), between
        :data:`MIN_CELL_M` and 7 cm; the candidate disc's radius is 0.75 rest radii, at most 25 cm. Its
        :func:`planning_span` sets the cells per side: 70, or as many as hold it (a creature of
        0.82 m rest radius and 0.89 m legs: 74; the planning cost grows with their square).

    Returns
    -------
    PlannerConfig

    Examples
    --------
    >>> from footfall.planner import planner_config_for
    >>> from footfall.scenarios import load_creature
    >>> planner_config_for(load_creature("spider")).cell_size   # rest radius 0.36 m: the paper's 7 cm
    0.07
    >>> ant = planner_config_for(load_creature("ant"))          # rest radius 0.17 m: finer cells
    >>> ant.map_cells, ant.cell_size, round(ant.search_radius_m, 3)
    (70, 0.04, 0.125)
    """
    from footfall.planner._far_planning import map_cells_holding

    rest = float(creature.rest_radius)
    cell = round(rest / 4.0 / 0.005) * 0.005
    feet = np.asarray(creature.rest_feet, dtype=np.float64)
    if len(feet) > 1:
        gaps = np.hypot(feet[:, None, 0] - feet[None, :, 0], feet[:, None, 1] - feet[None, :, 1])
        gap = float(gaps[~np.eye(len(feet), dtype=np.bool_)].min())
        cell = min(cell, math.floor(gap / FOOT_GAP_CELLS / 0.005) * 0.005)
    cell = min(0.07, max(MIN_CELL_M, cell))
    config = PlannerConfig(cell_size=cell, search_radius_m=min(0.25, 0.75 * rest))
    cells = map_cells_holding(config, planning_span(creature, config))
    return config if cells <= config.map_cells else dataclasses.replace(config, map_cells=cells)


@dataclass(frozen=True)
class CreatureWalk:
    """What a creature's legs allow at the stride law, with its rest feet spaced by a scenario's
    ``feet_spacing`` and asked a speed (:func:`creature_walk`): what ``init_crowd`` builds a crowd with,
    ``footfall check`` says of a creature and ``tuning.creature_defaults`` starts from, computed once.

    Attributes
    ----------
    rest_body, hips_body : ndarray
        Rest feet (L, 2) and hips (L, 3), body frame, m.
    leg_static : object
        The legs' IK statics (``planner._ik.legs_of``).
    window : ndarray, shape (L, 2)
        Each leg's stance window (``planner._workspace.stance_windows``).
    caps : dict
        ``planner._workspace.speed_caps``: m/s by what sets each.
    cap_reason : str
        The least of them, ``cap`` its speed (m/s).
    escape_cap : float
        The fastest its legs carry with no law's landing spot refused (m/s): the caps with half a foot's room
        between a spot and a neighbouring leg (``planner._kernels_foot.LEG_CLEARANCE``), not the whole room
        that ``cap`` keeps so that the law's spot scores best. A character fleeing a box or making way walks
        up to it (``CrowdModel.top_speed``): held to ``cap``, large random creatures stood in crates' and
        each other's way longer (three of them 1.7 -> 10.5 s stuck over their 36 runs, session 67).
    speed : float
        The speed walked: the asked one, at most ``cap``.
    weights : ScoringWeights
        The default scoring weights (:func:`planner.default_weights` at the creature's rest radius and the
        leg room its law leaves at ``speed``, ``planner._workspace.leg_room``).

    Examples
    --------
    >>> from footfall.planner import GaitTiming, creature_walk
    >>> from footfall.scenarios import load_creature
    >>> walk = creature_walk(load_creature("ant"), GaitTiming(), 0.3)
    >>> walk.window.shape, walk.cap_reason   # an ant's cycle would last under 4 frames first
    ((6, 2), 'frames')
    """

    rest_body: np.ndarray
    hips_body: np.ndarray
    leg_static: object
    window: np.ndarray
    caps: dict
    cap_reason: str
    cap: float
    escape_cap: float
    speed: float
    weights: ScoringWeights


def creature_walk(creature, timing, speed_asked: float, feet_spacing: float = 1.0) -> CreatureWalk:
    """The :class:`CreatureWalk` of ``creature``: what its legs allow at the stride law; no world is needed.

    Parameters
    ----------
    creature : scenarios.Creature
        The creature.
    timing : GaitTiming
        Its stride law and duty law.
    speed_asked : float
        The speed asked (m/s); walked at most at the cap.
    feet_spacing : float, optional
        The scenario's factor on the rest feet (default 1).

    Returns
    -------
    CreatureWalk

    Examples
    --------
    >>> from footfall.planner import ScoringWeights
    >>> from footfall.planner._timing import GaitTiming
    >>> from footfall.scenarios import load_creature
    >>> walk = creature_walk(load_creature("spider"), GaitTiming(), 0.3)
    >>> walk.cap_reason, round(walk.cap, 3), walk.speed   # its feet keep clear of each other up to 0.76 m/s
    ('neighbours', 0.757, 0.3)
    >>> round(walk.escape_cap, 3)                          # and none of its law's spots is refused up to 0.9
    0.898
    >>> walk.weights == ScoringWeights()                   # the room its law leaves is more than it asks
    True
    """
    from footfall.planner._ik import legs_of
    from footfall.planner._kernels_foot import LEG_CLEARANCE
    from footfall.planner._timing import hip_height
    from footfall.planner._workspace import leg_room, neighbour_speed_cap, speed_caps, stance_windows

    hips_body = np.asarray(creature.hips, dtype=np.float64)
    rest_body = float(feet_spacing) * np.asarray(creature.rest_feet, dtype=np.float64)
    leg_static = legs_of(creature)
    window = stance_windows(creature, rest_body, hips_body, leg_static)
    h = hip_height(creature)
    # Past this speed even the least duty factor's stance sweep does not fit the legs' windows, or a
    # stride cycle lasts under MIN_CYCLE_FRAMES frames (a tiny creature), or a stance sweep reaches
    # into a neighbouring leg's territory, or a landing spot within a foot's room of the neighbouring
    # leg's lift-off spot (dense legs): the controller caps the speed there (reported as speed_cap; the
    # CLI says so).
    caps = speed_caps(timing, h, rest_body, hips_body, window, DT, creature.foot_room)
    # How fast it may flee: every law's spot still allowed, if not scored best (CreatureWalk.escape_cap): the
    # neighbour cap again with half a room from the other leg, under the other caps.
    others = min(v for reason, v in caps.items() if reason != "neighbours")
    escape_cap = min(others, neighbour_speed_cap(timing, h, rest_body, hips_body, window, others, creature.foot_room,
                                                 LEG_CLEARANCE))
    cap_reason = min(caps, key=caps.get)
    speed = min(float(speed_asked), caps[cap_reason])
    # The leg-spacing reference no larger than the room the stride law leaves between neighbouring legs
    # at this walk (planner.default_weights).
    weights = default_weights(creature.rest_radius, leg_room(timing, h, rest_body, hips_body, window, speed,
                                                             creature.foot_room, DT))
    return CreatureWalk(rest_body, hips_body, leg_static, window, caps, cap_reason, caps[cap_reason], escape_cap, speed,
                        weights)


def init_crowd(scenario, creature, gait, *, n_characters: int | None = None, seed: int = 0,
               weights: ScoringWeights | None = None, timing=None, lod_mode: str = "off",
               config: PlannerConfig | None = None, controller: ControllerConfig | None = None,
               lod: LodConfig | None = None, raster: WorldRaster | None = None,
               budget: SearchBudget | None = None) -> tuple[CrowdModel, CrowdState]:
    """Build the static model and the initial state of a crowd (validated before any frame).

    ``budget``: one search budget for every character instead of the paper's full search
    (only with ``lod_mode='off'``: the LOD modes set their own budgets).

    The characters spawn around the scenario's crowd centre, clear of boxes, every foot at rest
    and on the ground, and each follows the scenario's route shifted by its spawn offset.

    Parameters
    ----------
    scenario : scenarios.Scenario
        The world (terrain, obstacles), the crowd's spawn, route and speed, and the camera.
    creature : scenarios.Creature
        The characters' creature.
    gait : scenarios.Gait or GaitSchedule
        One gait, walked at every speed, or the creature's gaits by speed (a
        ``planner._gait_schedule.GaitSchedule``, as ``scenarios._gait_schedule.gait_schedule``
        makes them).
    n_characters : int, optional
        Characters in the crowd; default ``scenario.crowd.count``.
    seed : int, optional
        Seeds the gait phases and, with ``crowd.heading_mode = "random"``, the headings.
    weights : ScoringWeights, optional
        Default ``default_weights(creature.rest_radius, leg_room)`` (:func:`planner.default_weights`:
        the reference scales sized to the creature, the leg-spacing one no more than the room its stride
        law leaves between neighbouring legs at the crowd's speed, ``planner._workspace.leg_room``).
    timing : GaitTiming, optional
        Default ``GaitTiming()``.
    lod_mode : {"off", "on", "zoomed"}, optional
        ``"off"``: every character runs the paper's full search and IK; ``"on"``: the camera frames
        the whole crowd; ``"zoomed"``: it follows character 0 (:mod:`planner._lod`).
    config : PlannerConfig, optional
        Default :func:`planner_config_for` the creature.
    controller : ControllerConfig, optional
        Default ``ControllerConfig()``.
    lod : LodConfig, optional
        Default ``LodConfig()``.
    raster : WorldRaster, optional
        A raster to reuse, at the planner's cell size; rebuilt unless it holds the scenario's
        boxes (compared by value).
    budget : SearchBudget, optional
        See above.

    Returns
    -------
    model : CrowdModel
        The static part.
    state : CrowdState
        Frame 0: every character standing at its spawn, at rest.

    Raises
    ------
    footfall._errors.InputError
        For an unknown ``lod_mode``, fewer than one character, a creature with no legs or too
        large for its local map, or no room to spawn the crowd.
    ValueError
        For a ``budget`` with a LOD mode, or a raster of another cell size.

    Examples
    --------
    >>> from footfall.planner import init_crowd, step
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> type(model).__name__, type(state).__name__, state.pelvis.shape
    ('CrowdModel', 'CrowdState', (2, 3))
    >>> state.desired_speed                         # the flat scenario's speed, under the legs' cap
    array([0.3, 0.3])
    >>> init_crowd(scenario, spider, default_gait(spider), lod_mode="fast")
    Traceback (most recent call last):
    ...
    footfall._errors.InputError: argument: --lod: expected on, zoomed or off, got 'fast'
    """
    from footfall._errors import InputError
    from footfall.planner._gait import init_gaits
    from footfall.planner._ik import rest_pose_angles
    from footfall.planner._timing import GaitTiming

    if lod_mode not in ("on", "zoomed", "off"):
        raise InputError("argument", "--lod", f"expected on, zoomed or off, got {lod_mode!r}")
    if budget is not None and lod_mode != "off":
        raise ValueError(f"budget: a fixed search budget needs lod_mode 'off', got {lod_mode!r}")
    config = config or planner_config_for(creature)
    controller = controller or ControllerConfig()
    timing = timing or GaitTiming()
    lod = lod or LodConfig()
    n = int(n_characters or scenario.crowd.count)
    if n < 1:
        raise InputError("argument", "--characters", "expected at least 1 character")
    if creature.n_legs < 1:
        raise InputError(creature.name, "legs", "a creature needs at least one leg")
    map_half = 0.5 * config.map_cells * config.cell_size
    span = planning_span(creature, config)
    if span + (config.roi_margin_cells + 2) * config.cell_size > map_half:
        raise InputError(creature.name, "legs", f"the creature (reach {span:.2f} m) is too large for its "
                         f"{config.map_cells} x {config.map_cells} local map of {config.cell_size} m cells")
    speed_asked = float(scenario.crowd.speed)
    spacing = float(scenario.crowd.feet_spacing)
    walk = creature_walk(creature, timing, speed_asked, spacing)
    hips_body, rest_body, leg_static, window = walk.hips_body, walk.rest_body, walk.leg_static, walk.window
    # A safe box taller than the creature can step onto is forbidden for it (it walks around).
    from footfall.planner._workspace import highest_step

    highest = highest_step(creature, rest_body, hips_body, leg_static)
    obstacles = _too_tall_forbidden(scenario.obstacles, highest)
    # The swing's lift stays well inside what the legs reach (half the highest step): a foot
    # lifted to the edge of its workspace mid-swing leaves the IK no continuous way there.
    step_height = min(controller.step_height_factor * float(creature.standing_height), 0.5 * highest)
    # A raster given for reuse is rebuilt unless its boxes are these, compared by value: compared by
    # identity, a raster cached from an earlier load of the same scenario kept its tall safe boxes
    # walkable, so the first run in a process differed from every later one.
    if raster is None or not _same_boxes(raster.obstacles, obstacles):
        raster = WorldRaster.build(scenario.terrain, obstacles, config.cell_size)
    if abs(raster.frame.cell_size - config.cell_size) > 1e-12:
        raise ValueError(f"raster: cell size {raster.frame.cell_size} differs from the planner's {config.cell_size}")
    from footfall.planner._gait_schedule import as_schedule
    from footfall.planner._timing import GRAVITY, hip_height
    from footfall.planner._workspace import height_ranges, tuck_reaches

    schedule = as_schedule(gait)
    cap_reason, cap, speed = walk.cap_reason, walk.cap, walk.speed
    if weights is None:
        weights = walk.weights
    escape = min(walk.escape_cap, math.sqrt(ESCAPE_FROUDE * GRAVITY * hip_height(creature)))
    far_first, far_fallback = None, None
    if lod_mode != "off":
        from footfall.planner._far_planning import far_configs

        far_first, far_fallback = far_configs(config, span, lod.far_radius_cells, lod.far_margin_cells,
                                              lod.far_fallback_margin_cells)
    model = CrowdModel(
        creature=creature, gait=schedule.gaits[0], timing=timing, weights=weights, config=config, controller=controller, lod=lod,
        lod_mode=lod_mode, raster=raster, camera=scenario.camera, dt=DT, feet_spacing=spacing,
        hips_body=hips_body, rest_body=rest_body, reach=np.asarray(creature.leg_reach, dtype=np.float64),
        leg_static=leg_static, fixed_budget=budget, schedule=schedule, stance_window=window, speed_cap=cap,
        speed_cap_reason=cap_reason,
        speed_asked=speed_asked, step_height=step_height, top_speed=max(escape, speed),
        height_range=height_ranges(creature, rest_body, hips_body, leg_static), far_first=far_first,
        tuck_reach=tuck_reaches(creature, rest_body, hips_body, leg_static, TUCK_REACHES, TUCK_LIFT),
        far_fallback=far_fallback)
    rng = np.random.default_rng(seed)
    positions = spawn_positions(scenario, creature, n)
    model = dataclasses.replace(model, avoid_radius=avoid_radius(creature, model.rest_radius, positions))
    if controller.navigate:
        model = dataclasses.replace(model, way_around=static_way_around(raster.obstacles, model.avoid_radius))
    if scenario.crowd.heading_mode == "random":
        headings = rng.uniform(-math.pi, math.pi, n)
    else:
        headings = np.full(n, float(scenario.crowd.heading))
    route = np.asarray(scenario.crowd.route, dtype=np.float64)
    offsets = positions - scenario.crowd.centre[None, :]
    x0, x1 = scenario.terrain.x_range
    z0, z1 = scenario.terrain.z_range
    routes = route[None, :, :] + offsets[:, None, :]
    routes[..., 0] = np.clip(routes[..., 0], x0 + 1.0, x1 - 1.0)
    routes[..., 1] = np.clip(routes[..., 1], z0 + 1.0, z1 - 1.0)
    L = creature.n_legs
    K = config.trajectory_samples
    feet = _initial_feet(model, positions, headings)
    ground = raster.ground
    gr, gc = raster.frame.world_to_cell(positions[:, 0], positions[:, 1])
    pelvis = np.column_stack([positions[:, 0], ground[np.clip(gr, 0, ground.shape[0] - 1),
                                                      np.clip(gc, 0, ground.shape[1] - 1)]
                              + creature.standing_height, positions[:, 1]])
    hx, hz = _rot_xz(headings[:, None], model.hips_body[None, :, 0], model.hips_body[None, :, 2])
    yaws = np.arctan2(feet[..., 2] - (pelvis[:, None, 2] + hz), feet[..., 0] - (pelvis[:, None, 0] + hx))
    angles = np.repeat(rest_pose_angles(creature)[None], n, axis=0)
    gait_index = schedule.initial(np.full(n, speed), hip_height(creature))
    state = CrowdState(
        t=0.0, frame=0, pelvis=pelvis, heading=headings.copy(), pitch=np.zeros(n), roll=np.zeros(n),
        speed=np.zeros(n), desired_speed=np.full(n, speed), route=routes, route_index=np.zeros(n, np.int64),
        feedback=np.zeros((n, 2)), feet=feet, in_stance=np.ones((n, L), np.bool_),
        wants_swing=np.zeros((n, L), np.bool_), sector_missed=np.zeros((n, L), np.bool_), stalled_s=np.zeros(n),
        waited_s=np.zeros(n), right_of_way_s=np.zeros(n), swing_t=np.zeros((n, L)), swing_T=np.zeros((n, L)),
        trajectories=np.repeat(feet[:, :, None, :], K, axis=2), swing_target=feet.copy(),
        plan_heading=np.repeat(headings[:, None], L, axis=1), plan_speed=np.zeros((n, L)),
        feet_spacing=np.ones(n), plan_spacing=np.ones((n, L)), foot_yaws=yaws,
        gaits=init_gaits([schedule.gaits[int(k)] for k in gait_index], n, rng.uniform(0.0, 1.0, n)), angles=angles, residual=np.zeros((n, L)),
        ik_on=np.zeros(n, np.bool_), fk_feet=feet.copy(), pelvis_base=np.zeros(n), pelvis_rise=np.zeros(n), body_held=np.zeros(n, np.bool_), speed_limit=np.full(n, np.inf), last_move=np.zeros((n, 2)), cannot_follow=np.zeros((n, L), np.bool_), unfollowed=np.zeros((n, L), np.bool_), pose_before=np.zeros((n, 7)),
        gait_index=gait_index, stride_frequency=np.zeros(n), turn_wanted=np.zeros(n), turn_left=np.zeros(n), turn_made=np.zeros(n),
        threatened=np.zeros((n, L), np.bool_), tucked=np.zeros((n, L), np.bool_),
        escaping=np.zeros(n, np.bool_), shoved=np.zeros(n, np.bool_), shoved_onto_feet=np.zeros((n, L), np.bool_), goal_speed=np.full(n, speed), speed_wanted=np.zeros(n), blocks_escape=np.zeros((n, L), np.bool_), crossed=np.zeros((n, L, L), np.bool_), counted_gone=np.zeros((n, L, L), np.bool_),
        counters={k: 0 for k in ("steps", "plans", "holds", "replans", "forbidden_footprints", "cells_expanded",
                                 "couples_evaluated", "pose_takebacks", "crossing_takebacks", "map_cells_built", "ik_ccd_legs", "ik_two_bone_legs", "shoves",
                                 "boxed_ways", "landing_drops")},
        lod_level=np.full(n, LEVEL_FULL, np.int8), near_moving_box=np.zeros(n, np.bool_),
        aim_node=np.full(n, -1, np.int64))
    stage_pelvis(model, state, smoothing=1.0)  # the first pose is the hull's own
    state.pelvis_rise[:] = 0.0
    state.pose_before = _pose(state)  # nothing to take back before the first frame
    stage_ik(model, state, np.ones(n, np.bool_))
    return model, state


def static_way_around(obstacles, avoid_radius: float):
    """The :class:`planner._navigation.WayAround` of ``obstacles`` for characters of ``avoid_radius``: every
    static box (safe ones included) and the region each box looping along waypoints sweeps (the bounding
    box of its loop grown by half the box's diagonal), grown by ``CLEARANCE_FACTOR`` avoid radii; None
    when there are none. Boxes moving at a constant velocity cross the world: the lane exit and ORCA keep
    out of their way."""
    from footfall.planner._navigation import CLEARANCE_FACTOR, way_around

    if len(obstacles.yaws) == 0:
        return None
    keep = np.asarray(obstacles.is_static, np.bool_)
    centres = [np.asarray(obstacles.centres)[keep][:, [0, 2]]]
    sizes = [np.asarray(obstacles.sizes)[keep][:, [0, 2]]]
    yaws = [np.asarray(obstacles.yaws)[keep]]
    # A looping box has its waypoints (every other box an empty list: scenarios.Obstacles).
    for b, points in enumerate(obstacles.waypoints or ()):
        if not len(points):
            continue
        xz = np.asarray(points)[:, [0, 2]]
        lo, hi = xz.min(axis=0), xz.max(axis=0)
        diagonal = float(np.hypot(*np.asarray(obstacles.sizes)[b, [0, 2]]))  # the box at any yaw
        centres.append((0.5 * (lo + hi))[None])
        sizes.append((hi - lo + diagonal)[None])
        yaws.append(np.zeros(1))
    centres, sizes, yaws = np.vstack(centres), np.vstack(sizes), np.concatenate(yaws)
    if centres.shape[0] == 0:
        return None
    return way_around(centres, sizes, yaws, CLEARANCE_FACTOR * avoid_radius)


def _same_boxes(a, b) -> bool:
    """Whether two obstacle sets hold the same boxes, moving the same way (every array equal)."""
    if a is b:
        return True
    for field in dataclasses.fields(a):
        if field.name.startswith("_"):  # derived from the others (and the poses' memo)
            continue
        x, y = getattr(a, field.name), getattr(b, field.name)
        if isinstance(x, (list, tuple)):
            if len(x) != len(y) or not all(np.array_equal(u, v) for u, v in zip(x, y)):
                return False
        elif not np.array_equal(np.asarray(x), np.asarray(y)):
            return False
    return True


def _too_tall_forbidden(obstacles, highest: float):
    """``obstacles`` with every safe box taller than ``highest`` (m) flagged forbidden (the same
    object when none is)."""
    import dataclasses

    if len(obstacles.yaws) == 0:
        return obstacles
    tall = ~np.asarray(obstacles.forbidden) & (np.asarray(obstacles.sizes)[:, 1] > highest + 1e-9)
    if not tall.any():
        return obstacles
    return dataclasses.replace(obstacles, forbidden=np.asarray(obstacles.forbidden) | tall)


def _initial_feet(model: CrowdModel, positions, headings):
    """Rest feet at their rest positions (footprints are continuous points), resting on the highest
    point of the world raster under the foot (its cell and the 8 around it) that it may stand on: a
    forbidden box's top is none (a spider spawned beside a 0.78 m forbidden crate stood a foot on its
    top, held by a leg it could not reach for the whole run; the ground under the foot where every
    cell around is forbidden). A rest foot within a foot's room of another character's (neighbours
    spawned close, their legs interleaved) moves straight away from it to just beyond that room
    (:func:`_spawned_feet_apart`)."""
    r = model.raster
    fx, fz = _rot_xz(headings[:, None], model.rest_body[None, :, 0], model.rest_body[None, :, 1])
    fx = fx + positions[:, None, 0]
    fz = fz + positions[:, None, 1]
    fx, fz = _spawned_feet_apart(fx, fz, model.creature.foot_room)
    rows, cols = r.frame.world_to_cell(fx, fz)
    rows = np.clip(rows, 1, r.frame.n_rows - 2)
    cols = np.clip(cols, 1, r.frame.n_cols - 2)
    top = np.full(rows.shape, -np.inf)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            allowed = r.static_forbidden[rows + dr, cols + dc] == 0
            top = np.maximum(top, np.where(allowed, r.static_top[rows + dr, cols + dc], -np.inf))
    top = np.where(np.isfinite(top), top, r.ground[rows, cols])
    return np.stack([fx, top, fz], axis=-1)


def _spawned_feet_apart(fx, fz, room: float, rounds: int = 4):
    """(fx, fz) (C, L) with every foot at least ``room`` (m) from the feet of the other characters:
    of two feet closer than that, the later character's moves straight away from the other's, a few
    rounds for chains. (Feet that started on one spot stood there until they stepped: 17 shared foot
    spots among 64 spiders spawned on `mixed`.)"""
    from scipy.spatial import cKDTree

    n_chars, n_legs = fx.shape
    owner = np.repeat(np.arange(n_chars), n_legs)
    x, z = fx.ravel().copy(), fz.ravel().copy()
    for _ in range(rounds):
        pairs = cKDTree(np.column_stack([x, z])).query_pairs(room, output_type="ndarray")
        if pairs.size == 0:
            break
        pairs = pairs[owner[pairs[:, 0]] != owner[pairs[:, 1]]]
        if pairs.size == 0:
            break
        for a, b in pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]:  # deterministic order
            a, b = (a, b) if owner[a] < owner[b] else (b, a)  # b, of the later character, moves
            dx, dz = x[b] - x[a], z[b] - z[a]
            d = math.hypot(dx, dz)
            if d >= room:
                continue
            ux, uz = (dx / d, dz / d) if d > 1e-12 else (1.0, 0.0)
            x[b], z[b] = x[a] + ux * room * (1.0 + 1e-6), z[a] + uz * room * (1.0 + 1e-6)
    return x.reshape(fx.shape), z.reshape(fz.shape)


# ----------------------------------------------------------------------------- the frame
@dataclass(frozen=True)
class FramePlans:
    """The feet a frame planned: request i is leg ``legs[i]`` of character ``chars[i]``, of kind
    ``kinds[i]`` (``planner.layout.KIND_*``), planned as ``result`` row i. ``batch``: the one
    planning call's requests when there was one on the paper's maps (what the tuning harvest
    re-scores; None when LOD split the frame); ``calls``: every planning call,
    ``(FootBatch, PlannerConfig, request rows, characters)``, rows indexing the requests.

    Attributes
    ----------
    chars, legs, kinds : ndarray of int, shape (n,)
        Character, leg and request kind of each planned foot.
    result : BatchResult
        The couples, row i for request i.
    batch : FootBatch or None
        The one planning call's requests, or None.
    calls : tuple
        Every planning call of the frame.

    Examples
    --------
    >>> from footfall.planner import init_crowd, step
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> plans = step(model, state).plans            # the first frame plans some feet
    >>> plans.chars.shape == plans.legs.shape == plans.kinds.shape == plans.result.valid.shape
    True
    >>> plans.batch.n_feet == plans.chars.size, len(plans.calls)   # LOD off: one call
    (True, 1)
    """

    chars: np.ndarray
    legs: np.ndarray
    kinds: np.ndarray
    result: object
    batch: object
    calls: tuple


@dataclass(frozen=True)
class StepRecord:
    """What :func:`step` did: the seconds each stage took (``timings``, :data:`STAGES` order) and the
    feet it planned (``plans``; None in a frame that planned none).

    Attributes
    ----------
    timings : dict of str to float
        Seconds per stage, keys :data:`STAGES` in order.
    plans : FramePlans or None
        The feet planned.

    Examples
    --------
    >>> from footfall.planner import init_crowd, step
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> record = step(model, state)
    >>> list(record.timings)
    ['steer', 'gait', 'swing', 'requests', 'maps', 'plan', 'pelvis', 'ik']
    >>> all(seconds >= 0 for seconds in record.timings.values())
    True
    """

    timings: dict
    plans: FramePlans | None


def step(model: CrowdModel, state: CrowdState) -> StepRecord:
    """Advance the crowd by one time step; returns what the step did (:class:`StepRecord`).

    Runs the stages (:data:`STAGES`, described in the docstring of ``footfall.planner._crowd``)
    in order, each batched over the characters; a foot with no valid couple holds and asks again
    next frame (``step`` never raises for it).

    Parameters
    ----------
    model : CrowdModel
        The static part of the crowd.
    state : CrowdState
        Advanced in place by ``model.dt``.

    Returns
    -------
    StepRecord
        The stages' timings and the feet planned.

    Examples
    --------
    >>> from footfall.planner import init_crowd, step
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> scenario = load_scenario("flat"); spider = load_creature("spider")
    >>> model, state = init_crowd(scenario, spider, default_gait(spider), n_characters=2, seed=0)
    >>> record = step(model, state)
    >>> state.frame, round(state.t, 4)
    (1, 0.0333)
    >>> for _ in range(44):                         # 1.5 s in all
    ...     record = step(model, state)
    >>> state.speed                                 # up to speed at 1 m/s^2, each kept right of the other
    array([0.3, 0.3])
    >>> import numpy as np
    >>> state.counters["steps"] > 0, bool(np.isfinite(state.pelvis).all())
    (True, True)
    """
    timings = {}
    clock = time.perf_counter
    state.t += model.dt
    state.frame += 1
    boxes = _boxes_now(model, state.t)

    t0 = clock()
    state.pose_before = _pose(state)
    stance_before = state.in_stance.copy()
    stage_steer(model, state, boxes)
    t1 = clock()
    frequency, enter, _ = stage_gait(model, state)
    t2 = clock()
    stage_swing(model, state, boxes)
    t3 = clock()
    hips = hips_world(model, state)
    # The legs as drawn at this frame's hips: the requests step a stance leg drawn across another, and
    # the plans keep landings off them (stage_requests, stage_plan).
    drawn = np.ascontiguousarray(rendered_joints(model, state, hips))
    kinds = stage_requests(model, state, enter, boxes, hips, frequency, drawn)
    budgets = character_budgets(model, state, boxes)
    t4 = clock()
    chars = np.unique(np.nonzero(kinds)[0])
    if chars.size:
        groups = map_groups(model, state, chars)
        planning = _planning_boxes(model, state, boxes)
        maps = [stage_maps(model, state, group, planning, model.far_first if far else None) for group, far in groups]
        t5 = clock()
        batch, out, cs, ls, calls = stage_plan(model, state, kinds, frequency, budgets, maps, groups, hips, boxes,
                                               planning, drawn)
        plans = FramePlans(cs, ls, kinds[cs, ls], out, batch, tuple(calls))
    else:
        t5 = clock()
        plans = None
    t6 = clock()
    stage_pelvis(model, state)
    t7 = clock()
    stage_ik(model, state, budgets[2])
    _take_back_crossing_poses(model, state, stance_before)
    t8 = clock()
    for name, (a, b) in zip(STAGES, ((t0, t1), (t1, t2), (t2, t3), (t3, t4), (t4, t5), (t5, t6), (t6, t7),
                                      (t7, t8))):
        timings[name] = b - a
    return StepRecord(timings, plans)
