"""Obstacles: oriented boxes (the paper's crates, §7), static or moving."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from footfall.scenarios._arrays import finite_float, frozen_array, invalid, readonly

STATIC = 0
"""``motion_kind`` of a box that never moves."""
VELOCITY = 1
"""``motion_kind`` of a box moving at constant velocity."""
WAYPOINTS = 2
"""``motion_kind`` of a box looping along a closed polyline at constant speed."""

_NO_WAYPOINTS = readonly(np.zeros((0, 3)))


@dataclass(frozen=True, eq=False)
class Obstacles:
    """``n`` oriented boxes (n may be 0), stored as one array per attribute.

    Box ``i`` at time t = 0 has its centre at ``centres[i]`` (world, m) and
    full extents ``sizes[i]`` (m) along its local (x, y, z) axes. It is turned
    by ``yaws[i]`` (radians) about +y: local x is world
    (cos yaw, 0, sin yaw) and local z is world (-sin yaw, 0, cos yaw), the
    same convention as a creature's (forward, lateral). Local y is world up.

    ``forbidden[i]`` is True when feet must go around the box, False when the
    box is safe to step on.

    Motion (``motion_kind[i]``): 0 static; 1 constant velocity
    ``velocities[i]`` (m/s); 2 looping along the closed polyline
    ``waypoints[i]`` ((k, 3) world points, k >= 2, ``waypoints[i][0] ==
    centres[i]``) at ``waypoint_speed[i]`` m/s, measured along the 3-D
    polyline, returning from the last point to the first. Yaw never changes.
    Unused motion data are zero: ``velocities[i]`` is (0, 0, 0) unless kind 1,
    ``waypoints[i]`` is (0, 3) and ``waypoint_speed[i]`` is 0 unless kind 2.

    Only ``centres``, ``sizes``, ``yaws`` and ``forbidden`` are required; the
    motion fields default to "all static". Every array is copied and made
    read-only.

    Attributes
    ----------
    centres : (n, 3) ndarray
        World box centres (m) at t = 0.
    sizes : (n, 3) ndarray
        Full extents (m) along each box's local (x, y, z), all > 0.
    yaws : (n,) ndarray
        Rotation (radians) about +y.
    forbidden : (n,) ndarray of bool
        True: feet go around the box; False: safe to step on.
    motion_kind : (n,) ndarray of int8
        0 static, 1 constant velocity, 2 waypoint loop.
    velocities : (n, 3) ndarray
        World velocity (m/s) of kind-1 boxes, else zero.
    waypoints : tuple of n (k, 3) ndarrays
        Closed loop of world points of kind-2 boxes, else (0, 3).
    waypoint_speed : (n,) ndarray
        Speed (m/s) along the loop of kind-2 boxes, else 0.

    Examples
    --------
    A static box, one sliding along +z at 0.5 m/s, and one looping between
    two points 1 m apart at 0.5 m/s (a 2 m loop: out and back in 4 s):

    >>> import numpy as np
    >>> from footfall.scenarios import Obstacles
    >>> boxes = Obstacles(
    ...     centres=[[0.0, 0.25, 0.0], [2.0, 0.1, 0.0], [0.0, 0.1, 2.0]],
    ...     sizes=[[0.5, 0.5, 0.5], [0.2, 0.2, 0.2], [0.2, 0.2, 0.2]],
    ...     yaws=[0.0, 0.3, 0.0],
    ...     forbidden=[False, True, True],
    ...     motion_kind=[0, 1, 2],
    ...     velocities=[[0.0, 0.0, 0.0], [0.0, 0.0, 0.5], [0.0, 0.0, 0.0]],
    ...     waypoints=[np.zeros((0, 3)), np.zeros((0, 3)), [[0.0, 0.1, 2.0], [1.0, 0.1, 2.0]]],
    ...     waypoint_speed=[0.0, 0.0, 0.5],
    ... )
    >>> len(boxes), boxes.is_static.tolist()
    (3, [True, False, False])
    >>> centres, yaws = boxes.poses_at(2.5)    # the loop: 1.25 m travelled, 0.25 m on the way back
    >>> centres.tolist()
    [[0.0, 0.25, 0.0], [2.0, 0.1, 1.25], [0.75, 0.1, 2.0]]
    >>> yaws.tolist()
    [0.0, 0.3, 0.0]
    >>> len(Obstacles.empty())
    0
    """

    centres: np.ndarray
    sizes: np.ndarray
    yaws: np.ndarray
    forbidden: np.ndarray
    motion_kind: np.ndarray | None = None
    velocities: np.ndarray | None = None
    waypoints: tuple[np.ndarray, ...] | None = None
    waypoint_speed: np.ndarray | None = None
    # The last few poses asked for, by time: a crowd asks for the same few times several times a frame
    # (now, the last frame, the threat horizon).
    _poses_memo: dict = field(init=False, repr=False, compare=False)
    # The looping boxes' loops padded to one array each (index, points, next points, arc lengths at each
    # waypoint, the closing segment included), so that every loop is walked at once (_points_on_loops).
    _loops: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        centres = frozen_array(_rows_of_3(self.centres), "centres", (None, 3))
        n = centres.shape[0]
        sizes = frozen_array(_rows_of_3(self.sizes), "sizes", (n, 3))
        for i in range(n):
            if np.any(sizes[i] <= 0.0):
                raise invalid(f"sizes[{i}]", "box extents must be > 0")
        yaws = frozen_array(self.yaws, "yaws", (n,))
        forbidden = frozen_array(self.forbidden, "forbidden", (n,), dtype=bool)

        kind = np.zeros(n, np.int8) if self.motion_kind is None else self.motion_kind
        kind = frozen_array(kind, "motion_kind", (n,), dtype=np.int8)
        for i in range(n):
            if kind[i] not in (STATIC, VELOCITY, WAYPOINTS):
                raise invalid(f"motion_kind[{i}]", "must be 0 (static), 1 (velocity) or 2 (waypoints)")
        velocities = np.zeros((n, 3)) if self.velocities is None else self.velocities
        velocities = frozen_array(_rows_of_3(velocities), "velocities", (n, 3))
        speeds = np.zeros(n) if self.waypoint_speed is None else self.waypoint_speed
        speeds = frozen_array(speeds, "waypoint_speed", (n,))
        raw_points = (_NO_WAYPOINTS,) * n if self.waypoints is None else tuple(self.waypoints)
        if len(raw_points) != n:
            raise invalid("waypoints", f"expected one array per box ({n}), got {len(raw_points)}")

        points: list[np.ndarray] = []
        loops: list[np.ndarray] = []
        for i in range(n):
            p = frozen_array(_rows_of_3(raw_points[i]), f"waypoints[{i}]", (None, 3))
            if kind[i] != VELOCITY and np.any(velocities[i] != 0.0):
                raise invalid(f"velocities[{i}]", "must be zero unless motion_kind is 1 (velocity)")
            if kind[i] == WAYPOINTS:
                if p.shape[0] < 2:
                    raise invalid(f"waypoints[{i}]", "a waypoint loop needs at least 2 points")
                if not speeds[i] > 0.0:
                    raise invalid(f"waypoint_speed[{i}]", "must be > 0 for a waypoint loop")
                if not np.allclose(p[0], centres[i], rtol=0.0, atol=1e-9):
                    raise invalid(f"waypoints[{i}]", "the first waypoint must equal the box centre")
                segment = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
                cumulative = readonly(np.concatenate(([0.0], np.cumsum(segment))))
                if not cumulative[-1] > 0.0:
                    raise invalid(f"waypoints[{i}]", "the waypoint loop has zero length")
                loops.append(cumulative)
            else:
                if p.shape[0] != 0:
                    raise invalid(f"waypoints[{i}]", "must be empty unless motion_kind is 2 (waypoints)")
                if speeds[i] != 0.0:
                    raise invalid(f"waypoint_speed[{i}]", "must be zero unless motion_kind is 2 (waypoints)")
                loops.append(_NO_WAYPOINTS[:, 0])
            points.append(p)

        object.__setattr__(self, "centres", centres)
        object.__setattr__(self, "sizes", sizes)
        object.__setattr__(self, "yaws", yaws)
        object.__setattr__(self, "forbidden", forbidden)
        object.__setattr__(self, "motion_kind", kind)
        object.__setattr__(self, "velocities", velocities)
        object.__setattr__(self, "waypoints", tuple(points))
        object.__setattr__(self, "waypoint_speed", speeds)
        object.__setattr__(self, "_poses_memo", {})
        object.__setattr__(self, "_loops", _padded_loops(np.flatnonzero(kind == WAYPOINTS), points, loops))

    @classmethod
    def empty(cls) -> Obstacles:
        """No obstacles at all.

        Examples
        --------
        >>> from footfall.scenarios import Obstacles
        >>> Obstacles.empty().centres.shape
        (0, 3)
        """
        return cls(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, bool))

    def __len__(self) -> int:
        """Number of boxes."""
        return self.centres.shape[0]

    @property
    def is_static(self) -> np.ndarray:
        """(n,) bool: True for boxes that never move (motion kind 0)."""
        return readonly(self.motion_kind == STATIC)

    def poses_at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Box centres (n, 3) (world, m) and yaws (n,) (radians) at time ``t`` (s).

        Static boxes stay at ``centres``; constant-velocity boxes are at
        ``centres + t * velocities`` (also for t < 0); waypoint boxes have
        travelled ``waypoint_speed * t`` metres along their closed loop,
        starting from waypoint 0 at t = 0. Returns fresh, writable arrays.

        Parameters
        ----------
        t : float
            Time (s), finite; may be negative.

        Returns
        -------
        centres : (n, 3) ndarray
            World box centres (m) at ``t``.
        yaws : (n,) ndarray
            Box yaws (radians); they never change.

        Examples
        --------
        >>> from footfall.scenarios import Obstacles
        >>> box = Obstacles([[0.0, 0.1, 0.0]], [[0.2, 0.2, 0.2]], [0.0], [True],
        ...                 motion_kind=[1], velocities=[[0.5, 0.0, 0.0]])
        >>> box.poses_at(-2.0)[0].tolist()
        [[-1.0, 0.1, 0.0]]
        """
        t = finite_float(t, "t")
        memo = self._poses_memo
        if t not in memo:
            centres = self.centres_over([t])[0]
            if len(memo) >= 8:
                memo.clear()
            memo[t] = centres
        return memo[t].copy(), np.array(self.yaws)

    def centres_over(self, times) -> np.ndarray:
        """Box centres (T, n, 3) at each of ``times`` (T,) s, by :meth:`poses_at`'s rule (which this
        computes; it has no memo: a character looking ahead asks for tens of times a frame, and
        :meth:`poses_at` memoises the few the crowd asks for again).

        Examples
        --------
        >>> from footfall.scenarios import Obstacles
        >>> box = Obstacles([[0.0, 0.1, 0.0]], [[0.2, 0.2, 0.2]], [0.0], [True],
        ...                 motion_kind=[1], velocities=[[0.5, 0.0, 0.0]])
        >>> box.centres_over([0.0, 1.0])[:, 0, 0].tolist()
        [0.0, 0.5]
        """
        times = np.asarray(times, dtype=np.float64).reshape(-1)
        centres = np.repeat(np.array(self.centres)[None], times.size, axis=0)
        moving = self.motion_kind == VELOCITY
        centres[:, moving] += times[:, None, None] * self.velocities[moving][None]
        index = self._loops[0]
        if index.size:
            centres[:, index] = _points_on_loops(self._loops, self.waypoint_speed[index][None, :] * times[:, None])
        return centres


def _rows_of_3(value: object) -> object:
    """``value``, or a (0, 3) array if it is empty (so ``[]`` means "no rows")."""
    try:
        return np.zeros((0, 3)) if np.size(value) == 0 else value
    except (TypeError, ValueError):  # ragged input: let frozen_array report it
        return value


def _padded_loops(index: np.ndarray, points, cumulative) -> tuple:
    """(index (W,), points (W, K, 3), next points (W, K, 3), arc lengths (W, K + 1)) of the looping boxes
    ``index``: each loop's waypoints padded to the longest loop's K, the point after each (wrapping),
    and the arc length at each waypoint, the closing segment included, then +inf (so no padded
    waypoint is ever passed)."""
    k = max((points[i].shape[0] for i in index), default=1)
    here = np.zeros((index.size, k, 3))
    after = np.zeros((index.size, k, 3))
    lengths = np.full((index.size, k + 1), np.inf)
    for row, i in enumerate(index):
        n = points[i].shape[0]
        here[row, :n] = points[i]
        after[row, :n] = np.roll(points[i], -1, axis=0)
        lengths[row, :n + 1] = cumulative[i]
    return readonly(np.array(index)), readonly(here), readonly(after), readonly(lengths)


def _points_on_loops(loops: tuple, distances: np.ndarray) -> np.ndarray:
    """(T, W, 3): the points ``distances`` (T, W) m along each of the W closed polylines of ``loops``
    (:func:`_padded_loops`; wrapping, either direction)."""
    _, here, after, lengths = loops
    w = np.arange(here.shape[0])
    length = lengths[w, (lengths < np.inf).sum(axis=1) - 1]  # (W,) each loop's whole length
    s = np.mod(distances, length)
    s = np.where((s >= 0.0) & (s < length), s, 0.0)  # float modulo can round up to ``length``
    # The waypoint each point follows: the inner waypoints it has passed (the closing one never is).
    j = (lengths[None, :, 1:-1] <= s[..., None]).sum(axis=-1)  # (T, W)
    start_s = lengths[w, j]
    segment = lengths[w, j + 1] - start_s
    with np.errstate(divide="ignore", invalid="ignore"):
        fraction = np.where(segment <= 0.0, 0.0, np.clip((s - start_s) / segment, 0.0, 1.0))
    start = here[w, j]
    end = after[w, j]
    return start + fraction[..., None] * (end - start)
