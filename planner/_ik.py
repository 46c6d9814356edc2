"""Leg inverse kinematics (paper §3: Cyclic Coordinate Descent), thin API over ``_kernels_ik``.

Frames, the body rotation ``R = R_yaw(yaw) @ R_pitch(pitch) @ R_roll(roll)``,
the leg model and the CCD sweep are documented in :mod:`planner._kernels_ik`.
In short: world y up; body frame (forward, up, left); angles per leg are
``[azimuth, pitch_0, ..., pitch_{S-1}]``, the azimuth turning the leg's
vertical plane about the body's up axis away from the leg's rest azimuth, the
pitches following ``scenarios/README.md`` (joint 0 below the horizontal, the
others bends relative to the previous segment, positive = down).

Typical use for a crowd: stack every leg of every character (struct of arrays,
e.g. from :func:`legs_of` and :meth:`CreatureLegs.world_hips`) and call
:func:`solve_legs` once per frame with the previous frame's angles as
``warm_start`` (the first frame: :func:`rest_pose_angles`, or None for a cold
start from the grid pose nearest each target).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from footfall.planner._kernels_ik import (
    forward_kinematics_batch,
    nearest_in_limits,
    solve_legs_parallel,
    solve_legs_serial,
    solve_legs_two_bone_parallel,
    solve_legs_two_bone_serial,
)

DEFAULT_AZIMUTH_LIMIT = 1.2
"""Default limit (rad) of the leg-plane azimuth joint: |azimuth| <= 1.2."""
UPRIGHT_LEG_OFFSET = 0.25
"""A leg whose rest foot is closer to under its hip than this fraction of its reach is upright: its
azimuth is free, or, beside the body, its plane joint is an abduction (:data:`SIDED_HIP_OFFSET`)."""
SIDED_HIP_OFFSET = 0.05
"""An upright leg whose hip is off the body's midline by more than this fraction of its reach has an
abduction (the plane rolls about the body's forward axis, ``CreatureLegs.plane_rolls``) instead of an
azimuth joint: a foot passing beside its hip would turn a vertical leg plane half a circle, and a plane
turned under the body folds the knee across the other legs."""
ABDUCTION_LIMIT = 0.75
"""Limit (rad) of an upright leg's abduction joint: the foot up to about a third of its depth to
either side of the hip's fore-aft line."""
DEFAULT_MAX_ITERATIONS = 32
"""Default sweep budget per leg (all descents together)."""
DEFAULT_TOLERANCE = 1e-4
"""Default stop: residual below 0.1 mm."""
DEFAULT_RESTARTS = 8
"""Default number of grid restarts after a stalled descent."""
ROTATION_TOLERANCE = 1e-6
"""How far from a rotation (max |R^T R - I| entry, |det R - 1|) a body rotation may be."""
MAX_COORDINATE = 1e12
"""Positions and lengths beyond this many metres are refused (they would overflow squared distances)."""


@dataclass(frozen=True, eq=False)
class IKResult:
    """CCD solution of B legs with S segments.

    What :func:`solve_legs` returns.

    Attributes
    ----------
    angles : ndarray
        (B, S + 1) [azimuth, pitch_0, ..., pitch_{S-1}] (rad), within the limits.
    residual : ndarray
        (B,) |foot - target| (m) at ``angles``; never NaN.
    iterations : ndarray
        (B,) CCD sweeps used (0 when the start already was within tolerance).
    converged : ndarray
        (B,) residual < tolerance.
    joints : ndarray
        (B, S + 2, 3) world positions, one row per angle (its pivot; rows 0 and 1
        are both the hip), the foot last. ``joints[:, 1:]`` is the polyline
        hip, knees..., foot.
    feet : ndarray
        (B, 3) foot positions, ``joints[:, -1]``.

    Examples
    --------
    >>> from footfall.planner import solve_legs
    >>> result = solve_legs([[0.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]], [0.0], [[0.1, 0.1]],
    ...                     [[[-1.5, 1.5], [0.0, 2.5]]], 1.2, [[0.1, -0.1, 0.0]])
    >>> result.angles.shape, result.joints.shape, result.feet.shape   # B = 1 leg, S = 2 segments
    ((1, 3), (1, 4, 3), (1, 3))
    >>> result.joints[0, 1:].round(6).tolist()   # hip, knee, foot
    [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, -0.1, 0.0]]
    """

    angles: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray
    joints: np.ndarray

    @property
    def feet(self) -> np.ndarray:
        """(B, 3) foot positions."""
        return self.joints[:, -1]


@dataclass(frozen=True, eq=False)
class CreatureLegs:
    """Per-leg static arrays of a creature with L legs of S segments (body frame).

    hips:            (L, 3) hip positions, body frame (forward, up, left), m.
    rest_azimuths:   (L,) direction from hip to rest foot (rad, from forward towards left).
    segment_lengths: (L, S) m.
    limits:          (L, S, 2) hinge (min, max), rad (README convention).
    azimuth_limits:  (L,) limit of the plane joint (azimuth or abduction), rad.
    plane_rolls:     (L,) bool: the plane joint is an abduction (it rolls the leg plane about its
                     outward direction, forward for these legs; :mod:`planner._kernels_ik`).
    """

    hips: np.ndarray
    rest_azimuths: np.ndarray
    segment_lengths: np.ndarray
    limits: np.ndarray
    azimuth_limits: np.ndarray
    plane_rolls: np.ndarray

    @property
    def n_legs(self) -> int:
        return self.hips.shape[0]

    def world_hips(self, pelvis, body_rotation) -> np.ndarray:
        """(L, 3) world hips of a character: ``pelvis`` (3,) plus R @ hip, with ``body_rotation``
        a (3, 3) matrix or (yaw, pitch, roll)."""
        pelvis = _array("pelvis", pelvis, (3,))
        rotation = _rotations("body_rotation", body_rotation, None)
        return pelvis + self.hips @ rotation.T


def body_rotation(yaw, pitch=0.0, roll=0.0) -> np.ndarray:
    """(..., 3, 3) R = R_yaw(yaw) @ R_pitch(pitch) @ R_roll(roll) (see :mod:`planner._kernels_ik`).

    Columns: the body's forward, up and left axes in world coordinates. The arguments broadcast.

    Parameters
    ----------
    yaw : float or array_like
        Heading (rad) about world up: forward is ``(cos yaw, 0, sin yaw)`` on flat ground.
    pitch : float or array_like, optional
        Rotation (rad) about the body's left axis, positive raising the forward axis.
    roll : float or array_like, optional
        Rotation (rad) about the body's forward axis, positive raising the left axis.

    Returns
    -------
    ndarray
        (..., 3, 3) rotation matrices, ``...`` the broadcast shape of the arguments.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import body_rotation
    >>> bool(np.allclose(body_rotation(0.0), np.eye(3)))
    True
    >>> r = body_rotation(np.pi / 2)        # a quarter turn: forward is world +z, left is world -x
    >>> r[:, 0].round(6).tolist(), r[:, 2].round(6).tolist()
    ([0.0, 0.0, 1.0], [-1.0, 0.0, 0.0])
    >>> round(float(body_rotation(0.0, np.pi / 6)[1, 0]), 6)   # pitched up 30 degrees: forward rises by 1/2
    0.5
    >>> body_rotation([0.0, 0.1, 0.2], 0.05).shape
    (3, 3, 3)
    """
    yaw, pitch, roll = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in (yaw, pitch, roll)))
    cy, sy = np.cos(yaw), np.sin(yaw)
    cp, sp = np.cos(pitch), np.sin(pitch)
    cr, sr = np.cos(roll), np.sin(roll)
    r = np.empty(yaw.shape + (3, 3))
    r[..., 0, 0] = cy * cp
    r[..., 1, 0] = sp
    r[..., 2, 0] = sy * cp
    r[..., 0, 1] = -cy * sp * cr + sy * sr
    r[..., 1, 1] = cp * cr
    r[..., 2, 1] = -sy * sp * cr - cy * sr
    r[..., 0, 2] = -cy * sp * sr - sy * cr
    r[..., 1, 2] = cp * sr
    r[..., 2, 2] = -sy * sp * sr + cy * cr
    return r


def _array(name: str, value, shape: tuple[int | None, ...], bound: float | None = None) -> np.ndarray:
    """``value`` as a fresh C-contiguous float64 array of ``shape`` (None: any length), finite
    (and within +-``bound``); otherwise ValueError naming ``name``."""
    try:
        a = np.array(value, dtype=np.float64, order="C")
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{name}: expected an array of numbers, got {type(value).__name__}") from None
    if a.ndim != len(shape) or any(want is not None and got != want for got, want in zip(a.shape, shape)):
        wanted = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"{name}: expected shape {wanted}, got {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name}: must be finite (no NaN or inf)")
    if bound is not None and a.size and np.abs(a).max() > bound:
        raise ValueError(f"{name}: values beyond +-{bound:g} m")
    return a


def _rotations(name: str, value, n: int | None) -> np.ndarray:
    """(n, 3, 3) rotations from (n, 3, 3) matrices or (n, 3) (yaw, pitch, roll); ``n`` None: one."""
    lead = () if n is None else (n,)
    if np.shape(value) == lead + (3,):
        angles = _array(name, value, lead + (3,))
        return np.ascontiguousarray(body_rotation(angles[..., 0], angles[..., 1], angles[..., 2]))
    rot = _array(name, value, lead + (3, 3))
    if rot.size:
        gram = np.swapaxes(rot, -1, -2) @ rot - np.eye(3)
        if np.abs(gram).max() > ROTATION_TOLERANCE or np.abs(np.linalg.det(rot) - 1.0).max() > ROTATION_TOLERANCE:
            raise ValueError(f"{name}: expected rotation matrices (orthonormal, det +1) "
                             "or (yaw, pitch, roll) angles")
    return rot


def _count(name: str, value) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ValueError(f"{name}: expected an integer >= 0, got {value!r}")
    return int(value)


def _plane_rolls(plane_rolls, n: int) -> np.ndarray:
    """(n,) bool from None (no leg rolls) or an array of n booleans."""
    if plane_rolls is None:
        return np.zeros(n, dtype=np.bool_)
    rolls = np.asarray(plane_rolls)
    if rolls.shape != (n,) or rolls.dtype != np.bool_:
        raise ValueError(f"plane_rolls: expected ({n},) booleans, got {rolls.dtype} {rolls.shape}")
    return np.ascontiguousarray(rolls)


def _leg_statics(rest_azimuths, segment_lengths, limits, azimuth_limits):
    lengths = _array("segment_lengths", segment_lengths, (None, None), MAX_COORDINATE)
    n, s = lengths.shape
    if s < 2:
        raise ValueError(f"segment_lengths: a leg needs at least 2 segments, got {s}")
    if (lengths <= 0.0).any():
        raise ValueError("segment_lengths: must be > 0")
    rest = _array("rest_azimuths", rest_azimuths, (n,))
    lim = _array("limits", limits, (n, s, 2))
    if not (lim[..., 0] < lim[..., 1]).all():
        raise ValueError("limits: min must be < max for every joint")
    if np.ndim(azimuth_limits) == 0:
        az = _array("azimuth_limits", azimuth_limits, ())
        az = np.full(n, float(az))
    else:
        az = _array("azimuth_limits", azimuth_limits, (n,))
    if (az < 0.0).any():
        raise ValueError("azimuth_limits: must be >= 0")
    return rest, lengths, lim, az


def solve_legs(hips, body_rotations, rest_azimuths, segment_lengths, limits, azimuth_limits, targets,
               warm_start=None, max_iterations: int = DEFAULT_MAX_ITERATIONS, tolerance: float = DEFAULT_TOLERANCE,
               parallel: bool = True, restarts: int = DEFAULT_RESTARTS, pair_steps: bool = True,
               two_bone: bool = False, plane_rolls=None) -> IKResult:
    """CCD inverse kinematics of B legs with S segments, in one kernel call.

    Never raises for an unreachable or degenerate target: the residual says how far the foot
    stays. Raises ValueError naming the offending argument for bad shapes or values.

    Parameters
    ----------
    hips : array_like
        (B, 3) world hip positions (m).
    body_rotations : array_like
        (B, 3, 3) rotation of each leg's body, or (B, 3) (yaw, pitch, roll) angles.
    rest_azimuths : array_like
        (B,) rest azimuth of each leg in its body frame (rad).
    segment_lengths : array_like
        (B, S) m, S >= 2, all > 0.
    limits : array_like
        (B, S, 2) hinge (min, max) (rad), min < max.
    azimuth_limits : float or array_like
        (B,) or a scalar, >= 0 (rad): |azimuth| <= limit.
    targets : array_like
        (B, 3) world foot targets (m).
    warm_start : array_like, optional
        (B, S + 1) starting angles (e.g. the previous frame's), brought into the
        limits first; None: cold start from the grid pose nearest each target.
    max_iterations : int, optional
        CCD sweeps per leg (restarts included), >= 0.
    tolerance : float, optional
        Stop below this residual (m), >= 0.
    parallel : bool, optional
        Spread the legs over the cores (bit-identical to the serial kernel).
    restarts : int, optional
        Grid restarts after a stalled descent (0: a single descent; with a warm
        start that keeps the pose continuous even when the target is out of reach).
    pair_steps : bool, optional
        Add the two-hinge closed-form steps to each sweep (False: plain CCD).
    two_bone : bool, optional
        The far characters' solve (level of detail): from the warm start (required),
        the azimuth and two hinges in closed form, one CCD sweep only where they
        cannot reach (:func:`planner._kernels_ik.solve_legs_two_bone_serial`);
        ``max_iterations``, ``restarts`` and ``pair_steps`` are not used.
    plane_rolls : array_like, optional
        (B,) bool, the plane joint is an abduction (``CreatureLegs.plane_rolls``);
        None: every leg has an azimuth joint.

    Returns
    -------
    IKResult
        Angles, residuals, sweeps used, convergence flags and joint positions of the B legs.

    Raises
    ------
    ValueError
        Bad shapes or values (not finite, a segment length <= 0, a hinge min >= max, a
        negative count or tolerance, ``two_bone`` without ``warm_start``); the message names
        the argument.

    Examples
    --------
    One leg of two 0.1 m segments, hip at the origin, body facing world +x: the target
    (0.1, -0.1, 0) is reached with the thigh horizontal and the knee bent down a right angle.

    >>> import numpy as np
    >>> from footfall.planner import solve_legs
    >>> leg = dict(hips=[[0.0, 0.0, 0.0]], body_rotations=[[0.0, 0.0, 0.0]], rest_azimuths=[0.0],
    ...            segment_lengths=[[0.1, 0.1]], limits=[[[-1.5, 1.5], [0.0, 2.5]]], azimuth_limits=1.2)
    >>> result = solve_legs(**leg, targets=[[0.1, -0.1, 0.0]])
    >>> bool(result.converged[0]), bool(np.allclose(result.angles, [[0.0, 0.0, np.pi / 2]]))
    (True, True)

    Out of reach, the leg stretches towards the target and the residual says how far it stays:

    >>> far = solve_legs(**leg, targets=[[0.5, 0.0, 0.0]])
    >>> bool(far.converged[0]), round(float(far.residual[0]), 6), far.feet.round(6).tolist()
    (False, 0.3, [[0.2, 0.0, 0.0]])
    """
    rest, lengths, lim, az = _leg_statics(rest_azimuths, segment_lengths, limits, azimuth_limits)
    n, s = lengths.shape
    hips = _array("hips", hips, (n, 3), MAX_COORDINATE)
    rotations = _rotations("body_rotations", body_rotations, n)
    targets = _array("targets", targets, (n, 3), MAX_COORDINATE)
    cold = warm_start is None
    warm = np.zeros((n, s + 1)) if cold else _array("warm_start", warm_start, (n, s + 1))
    max_iterations = _count("max_iterations", max_iterations)
    restarts = _count("restarts", restarts)
    try:
        tol = float(tolerance)
    except (TypeError, ValueError):
        raise ValueError(f"tolerance: expected a number of metres, got {tolerance!r}") from None
    if not (np.isfinite(tol) and tol >= 0.0):
        raise ValueError(f"tolerance: expected a finite number >= 0, got {tolerance!r}")
    if two_bone and cold:
        raise ValueError("warm_start: the two-bone solve starts from a pose (got None)")
    return _solve(hips, rotations, rest, _plane_rolls(plane_rolls, n), lengths, lim, az, targets, warm, cold,
                  max_iterations, restarts, tol, parallel, bool(pair_steps), two_bone)


def solve_legs_trusted(hips, body_angles, rest_azimuths, plane_rolls, segment_lengths, limits, azimuth_limits,
                       targets, warm_start, max_iterations: int, restarts: int, two_bone: bool = False) -> IKResult:
    """:func:`solve_legs` (parallel, pair steps, default tolerance, warm started) without checking its
    arguments: for the runtime's own arrays, checked once when the crowd was built (the checks cost
    about 0.1 ms a call, a few calls a frame). ``body_angles`` (B, 3) are (yaw, pitch, roll) and
    ``azimuth_limits`` is (B,); every array must already be float64."""
    rotations = body_rotation(body_angles[:, 0], body_angles[:, 1], body_angles[:, 2])
    c = np.ascontiguousarray
    return _solve(c(hips), rotations, c(rest_azimuths), c(plane_rolls), c(segment_lengths), c(limits), c(azimuth_limits),
                  c(targets), np.array(warm_start, dtype=np.float64, order="C"), False, int(max_iterations),
                  int(restarts), DEFAULT_TOLERANCE, True, True, two_bone)


def _solve(hips, rotations, rest, rolls, lengths, lim, az, targets, warm, cold, max_iterations, restarts, tol,
           parallel, pair_steps, two_bone) -> IKResult:
    n, s = lengths.shape
    angles = np.empty((n, s + 1))
    residual = np.empty(n)
    iterations = np.empty(n, dtype=np.int64)
    joints = np.empty((n, s + 2, 3))
    if two_bone:
        kernel = solve_legs_two_bone_parallel if parallel else solve_legs_two_bone_serial
        kernel(hips, rotations, rest, rolls, lengths, lim, az, targets, warm, tol, angles, residual, iterations, joints)
    else:
        kernel = solve_legs_parallel if parallel else solve_legs_serial
        kernel(hips, rotations, rest, rolls, lengths, lim, az, targets, warm, cold, restarts, pair_steps,
               max_iterations, tol, angles, residual, iterations, joints)
    return IKResult(angles=angles, residual=residual, iterations=iterations, converged=residual < tol,
                    joints=joints)


def forward_legs(hips, body_rotations, rest_azimuths, segment_lengths, angles, plane_rolls=None) -> np.ndarray:
    """(B, S + 2, 3) joint positions (rows as :attr:`IKResult.joints`) of B legs at ``angles`` (B, S + 1).

    The angles are used as given (no limits applied); ``plane_rolls`` as :func:`solve_legs`.
    """
    lengths = _array("segment_lengths", segment_lengths, (None, None), MAX_COORDINATE)
    n, s = lengths.shape
    rest = _array("rest_azimuths", rest_azimuths, (n,))
    hips = _array("hips", hips, (n, 3), MAX_COORDINATE)
    rotations = _rotations("body_rotations", body_rotations, n)
    angles = _array("angles", angles, (n, s + 1))
    joints = np.empty((n, s + 2, 3))
    forward_kinematics_batch(hips, rotations, rest, _plane_rolls(plane_rolls, n), lengths, angles, joints)
    return joints


def clamp_angles(angles, limits, azimuth_limits) -> np.ndarray:
    """``angles`` (B, S + 1) brought into the limits the way a warm start is.

    An angle inside its limits is kept; outside, the circularly nearest feasible angle is used
    (so 2 pi + 0.1 becomes 0.1 when 0.1 is allowed).
    """
    lim = _array("limits", limits, (None, None, 2))
    n, s, _ = lim.shape
    angles = _array("angles", angles, (n, s + 1))
    if np.ndim(azimuth_limits) == 0:
        az = np.full(n, float(_array("azimuth_limits", azimuth_limits, ())))
    else:
        az = _array("azimuth_limits", azimuth_limits, (n,))
    out = np.empty_like(angles)
    for b in range(n):
        out[b, 0] = nearest_in_limits(angles[b, 0], -az[b], az[b])
        for j in range(s):
            out[b, j + 1] = nearest_in_limits(angles[b, j + 1], lim[b, j, 0], lim[b, j, 1])
    return out


def legs_of(creature, azimuth_limit: float = DEFAULT_AZIMUTH_LIMIT) -> CreatureLegs:
    """Per-leg static arrays of a :class:`scenarios.Creature` (body frame).

    Rest azimuths follow :attr:`Creature.foot_directions` (hip to rest foot; a rest foot
    straight below its hip points forward: azimuth 0). An upright leg (rest foot near under its
    hip, :data:`UPRIGHT_LEG_OFFSET`) beside the midline (:data:`SIDED_HIP_OFFSET`) gets an
    abduction joint within :data:`ABDUCTION_LIMIT` and a forward-facing plane; one on the
    midline a free azimuth.

    Parameters
    ----------
    creature : Creature
        A :class:`footfall.scenarios.Creature` with L legs of S segments.
    azimuth_limit : float, optional
        Limit (rad) of the azimuth joint of the legs that are not upright, finite and >= 0.

    Returns
    -------
    CreatureLegs
        ``hips`` (L, 3), ``rest_azimuths`` (L,), ``segment_lengths`` (L, S), ``limits``
        (L, S, 2), ``azimuth_limits`` (L,) and ``plane_rolls`` (L,) bool, the arguments of
        :func:`solve_legs` for one character (its ``world_hips`` gives the world hips).

    Examples
    --------
    >>> from footfall.planner import legs_of
    >>> from footfall.scenarios import load_creature
    >>> spider = legs_of(load_creature("spider"))
    >>> spider.n_legs, spider.segment_lengths.shape, spider.limits.shape
    (8, (8, 4), (8, 4, 2))
    >>> spider.azimuth_limits.tolist() == [1.2] * 8, bool(spider.plane_rolls.any())   # sprawled legs
    (True, False)
    >>> quadruped = legs_of(load_creature("quadruped"))   # upright legs beside the body: abductions
    >>> quadruped.plane_rolls.tolist(), quadruped.azimuth_limits.tolist()
    ([True, True, True, True], [0.75, 0.75, 0.75, 0.75])
    """
    try:
        limit = float(azimuth_limit)
    except (TypeError, ValueError):
        raise ValueError(f"azimuth_limit: expected a number of radians, got {azimuth_limit!r}") from None
    if not (np.isfinite(limit) and limit >= 0.0):
        raise ValueError(f"azimuth_limit: expected a finite number >= 0, got {azimuth_limit!r}")
    directions = np.asarray(creature.foot_directions, dtype=np.float64)
    # A leg whose rest foot stands (nearly) under its hip has no meaningful rest azimuth: the
    # foot passes on every side of the hip during a stride, so its azimuth is free.
    offset = np.hypot(creature.rest_feet[:, 0] - creature.hips[:, 0], creature.rest_feet[:, 1] - creature.hips[:, 2])
    reach = np.asarray(creature.leg_reach, dtype=np.float64)
    upright = offset < UPRIGHT_LEG_OFFSET * reach
    rolls = upright & (np.abs(creature.hips[:, 2]) > SIDED_HIP_OFFSET * reach)
    return CreatureLegs(
        hips=np.array(creature.hips, dtype=np.float64),
        # an abducting leg's plane faces forward (its knee bends in the body's fore-aft plane)
        rest_azimuths=np.where(rolls, 0.0, np.arctan2(directions[:, 1], directions[:, 0])),
        segment_lengths=np.array(creature.segment_lengths, dtype=np.float64),
        limits=np.array(creature.joint_limits, dtype=np.float64),
        azimuth_limits=np.where(rolls, ABDUCTION_LIMIT, np.where(upright, np.pi, limit)),
        plane_rolls=rolls,
    )


def rest_feet_body(creature) -> np.ndarray:
    """(L, 3) rest feet in the body frame: (forward, -standing_height, left)."""
    return np.column_stack([creature.rest_feet[:, 0], np.full(creature.n_legs, -creature.standing_height),
                            creature.rest_feet[:, 1]])


def rest_pose_angles(creature, azimuth_limit: float = DEFAULT_AZIMUTH_LIMIT) -> np.ndarray:
    """(L, S + 1) angles putting each foot on its rest position, pelvis at standing height.

    For warm starts. Solved by CCD in the body frame (identity rotation) from a cold start to
    1e-9 m, with the azimuth held within ``azimuth_limit`` even for legs whose azimuth is free
    (so the rest pose is the canonical one); every built-in creature's rest pose is reachable within
    its limits, and its azimuths come out 0 (up to round-off); an abducting leg's plane rolls
    through its rest foot.

    Parameters
    ----------
    creature : Creature
        A :class:`footfall.scenarios.Creature` with L legs of S segments.
    azimuth_limit : float, optional
        Limit (rad) of the azimuth joints, as in :func:`legs_of`.

    Returns
    -------
    ndarray
        (L, S + 1) [azimuth, pitch_0, ..., pitch_{S-1}] (rad) of each leg, in leg order.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import rest_pose_angles
    >>> from footfall.scenarios import load_creature
    >>> angles = rest_pose_angles(load_creature("spider"))
    >>> angles.shape                                # 8 legs of 4 segments
    (8, 5)
    >>> bool(np.abs(angles[:, 0]).max() < 1e-9)     # the azimuths come out 0
    True
    """
    legs = legs_of(creature, azimuth_limit)
    n = legs.n_legs
    result = solve_legs(legs.hips, np.broadcast_to(np.eye(3), (n, 3, 3)), legs.rest_azimuths, legs.segment_lengths,
                        legs.limits, np.minimum(legs.azimuth_limits, azimuth_limit), rest_feet_body(creature),
                        max_iterations=64, tolerance=1e-9, parallel=False, plane_rolls=legs.plane_rolls)
    return result.angles
