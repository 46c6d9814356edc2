"""Creature morphology: the paper's "multi-legged character morphology" (§3.1)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from footfall.scenarios._arrays import frozen_array, invalid, positive_float, readonly

REST_REACH_FRACTION = 0.98
"""A rest foot may be at most this fraction of its leg's reach from its hip."""


@dataclass(frozen=True, eq=False)
class Creature:
    """A multi-legged character's static morphology.

    Body frame: (forward, up, lateral) in m, origin at the pelvis (the body
    centre), lateral positive to the creature's left. ``L`` legs, each a chain
    of ``S`` segments (the same ``S`` for every leg).

    Attributes
    ----------
    name : str
        Creature name.
    leg_names : tuple of str
        (L,) unique leg names, e.g. ``("L1", ..., "R4")``.
    hips : (L, 3) ndarray
        Hip joint positions, body frame, m.
    segment_lengths : (L, S) ndarray
        m, hip to foot, S >= 2, all > 0.
    joint_limits : (L, S, 2) ndarray
        Radians, (min, max) of joint ``j`` at the proximal end of
        segment ``j``; min < max. Convention (see ``scenarios/README.md``):
        hinges in the leg's vertical plane; joint 0 is the pitch of segment 0
        below the horizontal, joint j > 0 the bend of segment j relative to
        segment j - 1, positive = downward.
    rest_feet : (L, 2) ndarray
        Default feet spacing: body-frame (forward, lateral) of each
        foot at rest, on flat ground ``standing_height`` below the pelvis.
    foot_length, foot_width : float
        Projected foot rectangle (m); its length runs along the leg's outward
        direction (hip to rest foot, see :attr:`foot_directions`).
    body_thickness : float
        Pelvis height above the support hull (m), <= ``standing_height``.
    body_box : (2,) ndarray
        Projected body bounding box (length along forward, width along
        lateral), m, centred on the pelvis.
    standing_height : float
        Nominal pelvis height above flat ground (m).

    Construction checks the creature file's rules (``scenarios/README.md``, "Checks") and raises
    :class:`footfall.InputError` naming the field, e.g. ``rest_feet[2]``.

    Examples
    --------
    A built-in creature (:func:`load_creature`):

    >>> from footfall.scenarios import Creature, load_creature
    >>> ant = load_creature("ant")
    >>> ant.n_legs, ant.n_segments, ant.leg_names
    (6, 3, ('L1', 'L2', 'L3', 'R1', 'R2', 'R3'))
    >>> ant.hips.shape, ant.joint_limits.shape
    ((6, 3), (6, 3, 2))
    >>> ant.hips.flags.writeable
    False

    One leg of two 0.1 m segments, its foot straight below the hip:

    >>> stilt = Creature(name="stilt", leg_names=("A",), hips=[[0.0, 0.0, 0.0]], segment_lengths=[[0.1, 0.1]],
    ...                  joint_limits=[[[-1.0, 1.0], [0.0, 2.0]]], rest_feet=[[0.0, 0.0]], foot_length=0.03,
    ...                  foot_width=0.02, body_thickness=0.05, body_box=[0.2, 0.1], standing_height=0.15)
    >>> stilt.leg_reach, stilt.max_reach
    (array([0.2]), 0.2)
    >>> stilt.foot_directions    # a foot below its hip points forward
    array([[1., 0.]])
    >>> round(stilt.rest_radius, 3)    # half the body box's diagonal, 0.5 * hypot(0.2, 0.1)
    0.112
    """

    name: str
    leg_names: tuple[str, ...]
    hips: np.ndarray
    segment_lengths: np.ndarray
    joint_limits: np.ndarray
    rest_feet: np.ndarray
    foot_length: float
    foot_width: float
    body_thickness: float
    body_box: np.ndarray
    standing_height: float
    # The creature file's text when it was loaded from a user's file (None for a built-in): a
    # recording carries it, so that it can be rendered and exported without the file.
    source_toml: str | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise invalid("name", "must be a non-empty string")
        names = tuple(self.leg_names)
        n_legs = len(names)
        if n_legs == 0:
            raise invalid("leg_names", "creature needs at least one leg")
        for i, leg in enumerate(names):
            if not isinstance(leg, str) or not leg.strip():
                raise invalid(f"leg_names[{i}]", "must be a non-empty string")
            if leg in names[:i]:
                raise invalid(f"leg_names[{i}]", f"duplicate leg name {leg!r}")
        hips = frozen_array(self.hips, "hips", (n_legs, 3))
        lengths = frozen_array(self.segment_lengths, "segment_lengths", (n_legs, None))
        n_segments = lengths.shape[1]
        if n_segments < 2:
            raise invalid("segment_lengths", "a leg needs at least 2 segments")
        limits = frozen_array(self.joint_limits, "joint_limits", (n_legs, n_segments, 2))
        rest = frozen_array(self.rest_feet, "rest_feet", (n_legs, 2))
        body_box = frozen_array(self.body_box, "body_box", (2,))
        if np.any(body_box <= 0.0):
            raise invalid("body_box", "length and width must be > 0")
        foot_length = positive_float(self.foot_length, "foot_length")
        foot_width = positive_float(self.foot_width, "foot_width")
        thickness = positive_float(self.body_thickness, "body_thickness")
        height = positive_float(self.standing_height, "standing_height")
        if thickness > height:
            raise invalid("body_thickness", f"must not exceed standing_height ({height:g} m)")

        for i in range(n_legs):
            for j in range(n_segments):
                if lengths[i, j] <= 0.0:
                    raise invalid(f"segment_lengths[{i}][{j}]", "must be > 0")
                if not limits[i, j, 0] < limits[i, j, 1]:
                    raise invalid(f"joint_limits[{i}][{j}]", "min must be < max")
            if hips[i, 1] <= -height:
                raise invalid(f"hips[{i}]", "hip is at or below the ground (up <= -standing_height)")
            foot = np.array([rest[i, 0], -height, rest[i, 1]])
            with np.errstate(over="ignore"):  # absurdly large inputs give inf, which the check below refuses
                distance = float(np.linalg.norm(foot - hips[i]))
                reach = float(lengths[i].sum())
            if not (np.isfinite(distance) and np.isfinite(reach)):
                raise invalid(f"rest_feet[{i}]", "leg dimensions are too large")
            if distance > REST_REACH_FRACTION * reach:
                raise invalid(
                    f"rest_feet[{i}]",
                    f"rest foot out of reach: {distance:.3f} m from the hip, "
                    f"leg reach {reach:.3f} m (at most {REST_REACH_FRACTION:g} x reach)",
                )

        object.__setattr__(self, "leg_names", names)
        object.__setattr__(self, "hips", hips)
        object.__setattr__(self, "segment_lengths", lengths)
        object.__setattr__(self, "joint_limits", limits)
        object.__setattr__(self, "rest_feet", rest)
        object.__setattr__(self, "body_box", body_box)
        object.__setattr__(self, "foot_length", foot_length)
        object.__setattr__(self, "foot_width", foot_width)
        object.__setattr__(self, "body_thickness", thickness)
        object.__setattr__(self, "standing_height", height)

    @property
    def n_legs(self) -> int:
        """Number of legs L."""
        return len(self.leg_names)

    @property
    def n_segments(self) -> int:
        """Segments per leg S."""
        return self.segment_lengths.shape[1]

    @property
    def leg_reach(self) -> np.ndarray:
        """(L,) m: each leg's fully stretched length (sum of its segments).

        Examples
        --------
        >>> from footfall.scenarios import load_creature
        >>> load_creature("quadruped").leg_reach    # 0.23 + 0.21 + 0.12 m per leg
        array([0.56, 0.56, 0.56, 0.56])
        """
        return readonly(self.segment_lengths.sum(axis=1))

    @property
    def max_reach(self) -> float:
        """Longest leg reach (m)."""
        return float(self.leg_reach.max())

    @property
    def foot_directions(self) -> np.ndarray:
        """(L, 2) unit body-frame (forward, lateral) direction from each hip to its rest foot.

        This is the direction along which :attr:`foot_length` runs. A rest foot
        straight below its hip gets (1, 0) (forward).

        Examples
        --------
        >>> from footfall.scenarios import load_creature
        >>> load_creature("ant").foot_directions[[1, 4]]    # the middle legs point straight left and right
        array([[ 0.,  1.],
               [ 0., -1.]])
        """
        offsets = self.rest_feet - self.hips[:, [0, 2]]
        norms = np.linalg.norm(offsets, axis=1, keepdims=True)
        safe = norms[:, 0] > 1e-9
        directions = np.tile([1.0, 0.0], (self.n_legs, 1))
        directions[safe] = offsets[safe] / norms[safe]
        return readonly(directions)

    @property
    def foot_room(self) -> float:
        """Room (m) a planned foot keeps from every other foot: the foot's diagonal (the footprint
        search's ``block_radius``, the disc the foot covers in any yaw, doubled)."""
        return math.hypot(self.foot_length, self.foot_width)

    @property
    def rest_radius(self) -> float:
        """Radius (m) of the horizontal disk around the pelvis that holds the body box and the rest feet."""
        body = 0.5 * float(np.hypot(*self.body_box))
        feet = float(np.linalg.norm(self.rest_feet, axis=1).max()) + 0.5 * max(self.foot_length, self.foot_width)
        return max(body, feet)


def _segment_distance(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> float:
    """Least distance (m) between the 2-D segments p0-p1 and q0-q1."""
    def cross(a, b):
        return a[0] * b[1] - a[1] * b[0]

    d1, d2, r = p1 - p0, q1 - q0, q0 - p0
    denominator = cross(d1, d2)
    if abs(denominator) > 1e-15:
        t, u = cross(r, d2) / denominator, cross(r, d1) / denominator
        if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
            return 0.0

    def point_segment(p, a, b):
        ab = b - a
        length2 = float(ab @ ab)
        t = 0.0 if length2 == 0.0 else min(max(float((p - a) @ ab) / length2, 0.0), 1.0)
        return float(np.linalg.norm(p - (a + t * ab)))

    return min(point_segment(p0, q0, q1), point_segment(p1, q0, q1), point_segment(q0, p0, p1),
               point_segment(q1, p0, p1))


def leg_crossing_warnings(creature: Creature) -> tuple[str, ...]:
    """Pairs of legs whose rest poses are close enough to cross or collide, as messages.

    Seen from above (body frame (forward, lateral)), two legs are flagged when

    * their rest feet are closer than ``foot_length`` (centre to centre), or
    * their hip -> rest-foot segments pass within ``foot_width`` of each other (the segments
      start at the hips' projections; legs whose hips are already that close are only
      compared on the outer half of each segment).

    A warning, not an error: such a creature loads and walks, but its feet may collide or
    its legs cross (the run's counters say how often).

    Returns
    -------
    tuple of str
        One line per pair, e.g. ``legs L1 and L2: rest feet 0.031 m apart, closer than a
        foot length (0.05 m)``; empty when nothing is close.
    """
    hips = np.asarray(creature.hips, dtype=np.float64)[:, [0, 2]]
    feet = np.asarray(creature.rest_feet, dtype=np.float64)
    names = creature.leg_names
    out = []
    for i in range(creature.n_legs):
        for j in range(i + 1, creature.n_legs):
            pair = f"legs {names[i]} and {names[j]}"
            gap = float(np.linalg.norm(feet[i] - feet[j]))
            if gap < creature.foot_length:
                out.append(f"{pair}: rest feet {gap:.3g} m apart, closer than a foot length "
                           f"({creature.foot_length:g} m)")
                continue
            hi, hj = hips[i], hips[j]
            if float(np.linalg.norm(hi - hj)) < creature.foot_width:
                hi, hj = 0.5 * (hi + feet[i]), 0.5 * (hj + feet[j])
            gap = _segment_distance(hi, feet[i], hj, feet[j])
            if gap < creature.foot_width:
                what = "cross" if gap == 0.0 else f"pass {gap:.3g} m apart"
                out.append(f"{pair}: hip-to-rest-foot lines {what}, within a foot width "
                           f"({creature.foot_width:g} m)")
    return tuple(out)
