"""Where each leg can carry its stance foot: the stance window, and the speed legs can carry.

A stance foot stays where it touched down while the body moves over it, so relative to the
body it slides backwards by the **stance sweep** ``s = v * T_stance = DF * lambda`` (speed v,
duty factor DF, stride lambda) between touch-down and lift-off. The leg must reach it along
the whole sweep. For each leg, the **stance window** is the interval of body-forward
coordinates ``[lo, hi]`` (m, pelvis frame, at the rest foot's lateral coordinate, on flat
ground at standing height) where the leg's inverse kinematics, with its joint limits, puts
the foot on the target; shrunk by :data:`WINDOW_MARGIN` of its length at each end so the
bobbing pelvis, uneven ground and a late lift-off keep inside it.

Two rules follow (issue 13, "legs that reach"):

* **Stance centre** (:func:`stance_centres`): the preferred footprint is the rest foot plus
  half a sweep ahead (Raibert's neutral point); a leg whose rest foot sits near one end of
  its window (a spider's hind legs trail far behind their hips) would run out of reach
  before lift-off, so the centre of its sweep moves into the window: ``clip(rest, lo + s/2,
  hi - s/2)``.
* **Duty ceiling and speed cap** (:func:`duty_ceiling`, :func:`speed_cap`): the sweep fits
  the narrowest window when ``DF <= window / lambda``; the duty factor is lowered to that
  ceiling (never below the timing's ``duty_min``: at least half the cycle on the ground).
  Past the speed where even ``duty_min * lambda`` does not fit, the legs cannot carry the
  stride law: the controller caps the speed there and says so.
"""

from __future__ import annotations

import math

import numpy as np

from footfall.planner._timing import GRAVITY

WINDOW_MARGIN = 0.08
"""Fraction of a stance window's length given up at each end."""
WINDOW_SAMPLES = 161
"""Forward positions sampled per leg and height when measuring a window."""
WINDOW_HEIGHTS = (-0.05, 0.0, 0.05)
"""Foot heights (fractions of the standing height, relative to flat ground) the window must reach at."""
CENTRE_SLACK = 0.1
"""Fraction of a window's free room (its length less the sweep) kept clear at each end of a sweep."""
REACH_TOLERANCE = 1e-4
"""A target counts as reached when the IK residual is below this (m)."""


_CACHE: dict = {}


def _cached(kind, creature, rest_body, hips_body, legs, compute):
    """Windows and steps depend only on the legs' geometry: computed once per geometry (each costs a
    few thousand IK solves), then shared by every crowd of that creature."""
    key = (kind, creature.name, float(creature.standing_height), np.asarray(creature.leg_reach).tobytes(),
           rest_body.tobytes(), hips_body.tobytes(), legs.segment_lengths.tobytes(), legs.limits.tobytes(),
           legs.rest_azimuths.tobytes(), np.asarray(legs.azimuth_limits).tobytes(), legs.plane_rolls.tobytes())
    if key not in _CACHE:
        _CACHE[key] = compute()
    value = _CACHE[key]
    return value.copy() if isinstance(value, np.ndarray) else value


def stance_windows(creature, rest_body: np.ndarray, hips_body: np.ndarray, legs) -> np.ndarray:
    """(L, 2) stance window ``[lo, hi]`` of every leg, in body-forward metres from the pelvis.

    Parameters
    ----------
    creature : scenarios.Creature
        Its ``standing_height`` and ``leg_reach`` are used.
    rest_body : (L, 2) array
        Rest feet (forward, lateral) in the body frame, feet spacing applied.
    hips_body : (L, 3) array
        Hips (forward, up, lateral) in the body frame.
    legs : planner._ik.CreatureLegs
        The legs' IK statics.

    Returns
    -------
    (L, 2) array
        The contiguous forward interval around the rest foot that the leg reaches at every
        height of :data:`WINDOW_HEIGHTS`, shrunk by :data:`WINDOW_MARGIN`. A leg that cannot
        reach its own rest foot gets the one-point window ``[rest, rest]``.
    """
    rest_body = np.ascontiguousarray(rest_body, dtype=np.float64)
    hips_body = np.ascontiguousarray(hips_body, dtype=np.float64)
    return _cached("windows", creature, rest_body, hips_body, legs,
                   lambda: _stance_windows(creature, rest_body, hips_body, legs))


def _reached(hips_body, legs, leg, targets) -> np.ndarray:
    """(n,) bool: the IK of leg ``leg[i]`` (joint limits included; level body, body frame) puts its
    foot on ``targets[i]`` (within :data:`REACH_TOLERANCE`)."""
    from footfall.planner._ik import solve_legs

    result = solve_legs(hips_body[leg], np.broadcast_to(np.eye(3), (leg.size, 3, 3)), legs.rest_azimuths[leg],
                        legs.segment_lengths[leg], legs.limits[leg], legs.azimuth_limits[leg], targets,
                        max_iterations=48, restarts=8, parallel=True, plane_rolls=legs.plane_rolls[leg])
    return result.residual < REACH_TOLERANCE


def _rest_feet_reached(rest_body, hips_body, legs, drops) -> np.ndarray:
    """(L, n) bool: each leg reaches its rest foot with the pelvis ``drops[j]`` (m) above it."""
    n_legs = rest_body.shape[0]
    targets = np.stack([np.repeat(rest_body[:, 0], drops.size), np.tile(-drops, n_legs),
                        np.repeat(rest_body[:, 1], drops.size)], axis=1)
    return _reached(hips_body, legs, np.repeat(np.arange(n_legs), drops.size), targets).reshape(n_legs, drops.size)


def _stance_windows(creature, rest_body, hips_body, legs) -> np.ndarray:
    n_legs = rest_body.shape[0]
    reach = np.asarray(creature.leg_reach, dtype=np.float64)
    height = float(creature.standing_height)
    k = WINDOW_SAMPLES
    offsets = np.linspace(-1.0, 1.0, k)
    reached = np.ones((n_legs, k), dtype=np.bool_)
    forward = rest_body[:, 0:1] + offsets[None, :] * reach[:, None]
    for fraction in WINDOW_HEIGHTS:
        targets = np.stack([forward, np.full_like(forward, -height * (1.0 - fraction)),
                            np.broadcast_to(rest_body[:, 1:2], forward.shape)], axis=-1).reshape(-1, 3)
        reached &= _reached(hips_body, legs, np.repeat(np.arange(n_legs), k), targets).reshape(n_legs, k)
    windows = np.repeat(rest_body[:, 0:1], 2, axis=1).astype(np.float64)
    middle = k // 2
    for i in range(n_legs):
        if not reached[i, middle]:
            continue
        lo = middle
        while lo > 0 and reached[i, lo - 1]:
            lo -= 1
        hi = middle
        while hi < k - 1 and reached[i, hi + 1]:
            hi += 1
        a, b = forward[i, lo], forward[i, hi]
        shrink = WINDOW_MARGIN * (b - a)
        windows[i] = (a + shrink, b - shrink)
    return windows


def stance_centres(rest_forward: np.ndarray, windows: np.ndarray, sweep: np.ndarray, min_slack=0.0) -> np.ndarray:
    """Body-forward centre of each stance sweep: ``clip(rest, lo + s/2 + r, hi - s/2 - q)``,
    ``q = CENTRE_SLACK * (hi - lo - s)`` at the front end, ``r = max(q, min(min_slack, (hi - lo - s) / 2))``
    at the rear end (where the body runs out of a foot that lifts late).

    A sweep longer than its window is centred on the window.

    Examples
    --------
    >>> import numpy as np
    >>> stance_centres(np.array([0.05, 0.0]), np.array([[-0.3, 0.3], [-0.1, 0.1]]), np.array([0.1, 0.3]))
    array([0.05, 0.  ])
    >>> stance_centres(np.array([-0.28]), np.array([[-0.3, 0.3]]), np.array([0.1]))  # -0.3 + 0.05 + 0.05
    array([-0.2])
    """
    # Keep a tenth of the free room at each end when the window allows it, and at the rear end at
    # least ``min_slack`` (a distance the body covers in a frame or two): a stance can last longer
    # than planned (a gait change moving the foot's sector, a late landing, the lift-off frame). At
    # speed a tenth of a little free room is less than a frame's travel, and every late frame capped
    # the body's speed (robot5 at Fr 0.5 kept 0.89 of its asked speed).
    free = np.maximum(windows[..., 1] - windows[..., 0] - sweep, 0.0)
    slack = CENTRE_SLACK * free
    lo = windows[..., 0] + 0.5 * sweep + np.maximum(slack, np.minimum(min_slack, 0.5 * free))
    hi = windows[..., 1] - 0.5 * sweep - slack
    centre = np.minimum(np.maximum(rest_forward, lo), hi)
    return np.where(lo <= hi, centre, 0.5 * (windows[..., 0] + windows[..., 1]))


def duty_ceiling(window: float, stride) -> np.ndarray:
    """Largest duty factor whose stance sweep ``DF * stride`` fits ``window`` (inf where stride is 0).

    Examples
    --------
    >>> duty_ceiling(0.3, [0.0, 0.5])
    array([inf, 0.6])
    """
    stride = np.asarray(stride, dtype=np.float64)
    with np.errstate(divide="ignore"):
        return np.where(stride > 0.0, window / np.where(stride > 0.0, stride, 1.0), np.inf)


def speed_cap(timing, leg_height: float, window: float) -> float:
    """The fastest speed (m/s) whose stride ``lambda(v)`` the legs carry at the least duty factor.

    ``duty_min * lambda(v) <= window`` with ``lambda = c h Fr^e`` gives
    ``Fr <= (window / (duty_min c h))^(1/e)``; ``inf`` when the stride does not grow with speed
    (``e = 0``) and fits, ``0`` when it never fits.

    Examples
    --------
    >>> from footfall.planner._timing import GaitTiming
    >>> v = speed_cap(GaitTiming(), 0.42, 0.3)   # Fr = (0.3 / 0.5 / (2.3 * 0.42)) ** (1 / 0.3) = 0.2044
    >>> round(v, 3)                               # sqrt(0.2044 * 9.81 * 0.42)
    0.918
    """
    c = timing.stride_coefficient
    e = timing.stride_exponent
    longest = window / timing.duty_min
    if e == 0.0:
        return math.inf if c * leg_height <= longest else 0.0
    froude = (longest / (c * leg_height)) ** (1.0 / e)
    return math.sqrt(froude * GRAVITY * leg_height)



def leg_sides(hips_body: np.ndarray, rest_body: np.ndarray) -> np.ndarray:
    """(L,) each leg's side of the body's midline: +1 left, -1 right, 0 for a hip on the midline
    (within 1e-3 rest radii of it: a robot5's front leg). ``CrowdModel.leg_sides``.

    Examples
    --------
    >>> import numpy as np
    >>> hips = np.array([[0.1, 0.0, 0.05], [0.1, 0.0, -0.05], [0.2, 0.0, 1e-5]])
    >>> leg_sides(hips, np.array([[0.2, 0.3], [0.2, -0.3], [0.4, 0.0]])).tolist()
    [1.0, -1.0, 0.0]
    """
    lateral = np.asarray(hips_body, dtype=np.float64)[:, 2]
    rest_radius = float(np.max(np.hypot(rest_body[:, 0], rest_body[:, 1])))
    return np.sign(lateral) * (np.abs(lateral) > 1e-3 * rest_radius)


def side_neighbours(rest_body: np.ndarray, hips_body: np.ndarray) -> list[tuple[int, int]]:
    """The (front, rear) pairs of legs next to each other on one side of the body (:func:`leg_sides`),
    ordered by their rest feet's forward coordinate; legs on the midline have none.

    Examples
    --------
    >>> import numpy as np
    >>> rest = np.array([[0.02, 0.05], [-0.02, 0.05], [0.0, -0.05], [0.06, 0.05]])
    >>> hips = np.array([[0.01, 0.0, 0.01], [-0.01, 0.0, 0.01], [0.0, 0.0, -0.01], [0.03, 0.0, 0.01]])
    >>> side_neighbours(rest, hips)
    [(3, 0), (0, 1)]
    """
    side = leg_sides(hips_body, rest_body)
    pairs = []
    for s in (-1.0, 1.0):
        legs = np.flatnonzero(side == s)
        legs = legs[np.argsort(-rest_body[legs, 0], kind="stable")]  # front to back
        pairs += [(int(front), int(rear)) for front, rear in zip(legs[:-1], legs[1:])]
    return pairs


def territory_bounds(rest_body: np.ndarray, hips_body: np.ndarray) -> np.ndarray:
    """(L, 2) each leg's **territory**: the body-forward interval, at its rest foot's lateral
    coordinate, between the lines that halve the gaps to its same-side neighbours.

    Two legs adjacent on one side (ordered by their rest feet's forward coordinate) share the line
    from the midpoint of their hips to the midpoint of their rest feet; the front leg's territory ends
    behind at it, the rear leg's ahead. Feet that keep to their territories keep their legs' straight
    lines on the ground apart (dense legs were drawn across each other otherwise: see
    :func:`territory_speed_cap`); legs drawn bowed, with knees out, can still pass near each other.
    ``-inf`` / ``inf`` where a leg has no neighbour on that side, for legs on the midline
    (:func:`leg_sides`) and for a shared line parallel to the body's axis.

    Parameters
    ----------
    rest_body : (L, 2) array
        Rest feet (forward, lateral), body frame.
    hips_body : (L, 3) array
        Hips (forward, up, lateral), body frame.

    Returns
    -------
    (L, 2) array
        ``[behind, ahead]`` bounds, body-forward metres from the pelvis.

    Examples
    --------
    Two legs on the left, hips 2 cm apart, rest feet 4 cm apart: the shared line runs from (0, 0.01)
    to (0, 0.05), straight out; on the right a single leg has no neighbour.

    >>> import numpy as np
    >>> rest = np.array([[0.02, 0.05], [-0.02, 0.05], [0.0, -0.05]])
    >>> hips = np.array([[0.01, 0.0, 0.01], [-0.01, 0.0, 0.01], [0.0, 0.0, -0.01]])
    >>> territory_bounds(rest, hips).tolist()
    [[0.0, inf], [-inf, 0.0], [-inf, inf]]

    Rest feet spread further back than the hips (0.03 and -0.05 from hips at 0.01 and -0.01): the line
    slants back, from (0, 0.01) to (-0.01, 0.05), and crosses the feet's lateral coordinate at -0.01.

    >>> rest = np.array([[0.03, 0.05], [-0.05, 0.05]])
    >>> np.round(territory_bounds(rest, hips[:2]), 6).tolist()
    [[-0.01, inf], [-inf, -0.01]]
    """
    rest_body = np.asarray(rest_body, dtype=np.float64)
    hips_body = np.asarray(hips_body, dtype=np.float64)
    bounds = np.tile(np.array([-np.inf, np.inf]), (rest_body.shape[0], 1))
    for front, rear in side_neighbours(rest_body, hips_body):
        hip = 0.5 * (hips_body[front, [0, 2]] + hips_body[rear, [0, 2]])
        foot = 0.5 * (rest_body[front] + rest_body[rear])
        if abs(foot[1] - hip[1]) < 1e-12:
            continue
        # Sorted along the side, each leg has one neighbour ahead and one behind: one line per end.
        for leg, end in ((front, 0), (rear, 1)):
            bounds[leg, end] = hip[0] + (rest_body[leg, 1] - hip[1]) / (foot[1] - hip[1]) * (foot[0] - hip[0])
    return bounds


TERRITORY_SPEED_STEP = 0.01
"""Relative step of the speeds :func:`territory_speed_cap` tries (1 %: the cap is within 1 % below the
speed where a sweep first leaves its territory)."""


def territory_speed_cap(timing, leg_height: float, rest_body: np.ndarray, hips_body: np.ndarray,
                        windows: np.ndarray, fastest: float) -> float:
    """The fastest speed (m/s, at most ``fastest``) at which every leg's steady stance sweep stays in
    its territory (:func:`territory_bounds`); ``inf`` when none leaves it below ``fastest``.

    At speed v a stance foot sweeps ``s = min(DF(v) lambda(v), narrowest window)`` (the duty law,
    lowered to the duty ceiling), centred as the requests centre it (:func:`stance_centres` in the
    leg's stance window). Where the front end of one leg's sweep reaches past the line it shares with
    the leg ahead, or the rear end past the one behind, the two legs' lines on the ground cross
    during the stance: random creatures whose rest feet were 2-3 cm apart with 3-4 cm strides drew
    2,908 crossing frames in 48 runs. The speeds tried are ``fastest`` times powers of ``1 -``
    :data:`TERRITORY_SPEED_STEP`; a sweep already outside its territory at the slowest of them (a
    rest foot outside its own) gives no cap, since walking slower would not bring it in.

    Examples
    --------
    The legs of the first example of :func:`territory_bounds` share a line at 0 m; their stance
    windows (+-0.03 m round the rest feet) centre each sweep on its rest foot, 2 cm from the line: the
    sweeps leave their territories once they pass 4 cm, at 0.85 m/s for a 2.5 cm high creature.

    >>> import numpy as np
    >>> from footfall.planner._timing import GaitTiming, duty_factor, stride_length
    >>> rest = np.array([[0.02, 0.05], [-0.02, 0.05]])
    >>> hips = np.array([[0.01, 0.0, 0.01], [-0.01, 0.0, 0.01]])
    >>> windows = rest[:, :1] + np.array([[-0.03, 0.03]])
    >>> v = territory_speed_cap(GaitTiming(), 0.025, rest, hips, windows, 1.0)
    >>> round(v, 3), round(float(duty_factor(GaitTiming(), v, 0.025) * stride_length(GaitTiming(), v, 0.025)), 4)
    (0.851, 0.0398)
    >>> territory_speed_cap(GaitTiming(), 0.025, rest, hips, windows, 0.5)   # below it: no cap
    inf
    """
    bounds = territory_bounds(rest_body, hips_body)
    if not np.isfinite(bounds).any() or not math.isfinite(fastest) or fastest <= 0.0:
        return math.inf
    speeds = _speeds_up_to(fastest)
    sweep, centre = steady_sweeps(timing, leg_height, rest_body, windows, speeds)
    inside = ((centre + 0.5 * sweep <= bounds[:, 1]) & (centre - 0.5 * sweep >= bounds[:, 0])).all(axis=1)
    return _fastest_kept(speeds, inside)


def _speeds_up_to(fastest: float) -> np.ndarray:
    """The speeds the caps try, slowest first: ``fastest`` times powers of ``1 -``
    :data:`TERRITORY_SPEED_STEP`, down to a thousandth of it."""
    steps = int(math.ceil(math.log(1e-3) / math.log1p(-TERRITORY_SPEED_STEP)))
    return fastest * (1.0 - TERRITORY_SPEED_STEP) ** np.arange(steps)[::-1]


def _fastest_kept(speeds: np.ndarray, kept: np.ndarray) -> float:
    """The speed below the slowest of ``speeds`` (slowest first) where ``kept`` first fails; ``inf`` when
    it never fails, or already fails at the slowest (walking slower would not keep it)."""
    if not kept[0] or kept.all():
        return math.inf
    return float(speeds[int(np.argmin(kept)) - 1])


def steady_sweeps(timing, leg_height: float, rest_body: np.ndarray, windows: np.ndarray,
                  speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sweep (n, 1), centre (n, L)) m: at each of ``speeds`` (n,), the steady stance sweep of every leg,
    ``min(DF(v) lambda(v), narrowest window)`` (the duty law, lowered to the duty ceiling), and its
    body-forward centre as the requests centre it (:func:`stance_centres` in the leg's window). A stance
    foot lands at ``centre + sweep / 2`` and lifts at ``centre - sweep / 2``."""
    from footfall.planner._timing import duty_factor, stride_length

    speeds = np.asarray(speeds, dtype=np.float64)
    narrowest = float(np.min(windows[:, 1] - windows[:, 0]))
    sweep = np.minimum(duty_factor(timing, speeds, leg_height) * stride_length(timing, speeds, leg_height),
                       narrowest)[:, None]
    centre = stance_centres(rest_body[:, 0], windows, np.broadcast_to(sweep, (speeds.size, rest_body.shape[0])))
    return sweep, centre


def _segment_point_distance(px, pz, ax, az, bx, bz):
    """Distance from points (px, pz) to segments a -> b (numpy, broadcast)."""
    dx, dz = bx - ax, bz - az
    length2 = dx * dx + dz * dz
    t = np.clip(((px - ax) * dx + (pz - az) * dz) / np.where(length2 > 0.0, length2, 1.0), 0.0, 1.0)
    return np.hypot(px - ax - t * dx, pz - az - t * dz)


def neighbour_gaps(timing, leg_height: float, rest_body: np.ndarray, hips_body: np.ndarray, windows: np.ndarray,
                   speeds, late_s: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(feet (n,), legs (n,)) m: at each of ``speeds``, the least gap, over the legs next to each other on
    a side (:func:`side_neighbours`), between the rear leg's steady landing spot and the front leg's
    lift-off spot (``feet``), and between each of those spots and the other leg's straight line, hip to
    spot (``legs``); ``inf`` without such legs. Spots at the rest feet's lateral coordinates
    (:func:`steady_sweeps`); a front foot lifting ``late_s`` seconds late stands ``speed * late_s``
    further back.

    In a wave gait the rear leg lands as its front neighbour is about to lift: at speed both stand at the
    ends of their sweeps that face each other. The search keeps a foot's room between feet and refuses
    half of it between a foot and a leg (``planner._kernels_foot.LEG_CLEARANCE``); the leg-spacing goodness
    asks a whole room (:func:`neighbour_speed_cap`).

    Examples
    --------
    Two legs on the left whose rest feet are 4 cm apart, their sweeps centred on them: at a standstill
    the feet stand 4 cm apart; each centimetre of sweep brings the two ends facing each other 1 cm nearer.

    >>> import numpy as np
    >>> from footfall.planner._timing import GaitTiming, duty_factor, stride_length
    >>> rest = np.array([[0.02, 0.05], [-0.02, 0.05]])
    >>> hips = np.array([[0.01, 0.0, 0.01], [-0.01, 0.0, 0.01]])
    >>> windows = rest[:, :1] + np.array([[-0.03, 0.03]])
    >>> feet, legs = neighbour_gaps(GaitTiming(), 0.025, rest, hips, windows, [0.0, 0.3])
    >>> sweep = float(duty_factor(GaitTiming(), 0.3, 0.025) * stride_length(GaitTiming(), 0.3, 0.025))
    >>> feet.round(4).tolist(), round(0.04 - sweep, 4)
    ([0.04, 0.015], 0.015)
    """
    speeds = np.atleast_1d(np.asarray(speeds, dtype=np.float64))
    feet = np.full(speeds.size, np.inf)
    legs = np.full(speeds.size, np.inf)
    pairs = side_neighbours(rest_body, hips_body)
    if not pairs:
        return feet, legs
    sweep, centre = steady_sweeps(timing, leg_height, rest_body, windows, speeds)
    for front, rear in pairs:
        lift_x, lift_z = centre[:, front] - 0.5 * sweep[:, 0] - speeds * late_s, rest_body[front, 1]
        land_x, land_z = centre[:, rear] + 0.5 * sweep[:, 0], rest_body[rear, 1]
        feet = np.minimum(feet, np.hypot(lift_x - land_x, lift_z - land_z))
        (fx, _, fz), (rx, _, rz) = hips_body[front], hips_body[rear]
        legs = np.minimum(legs, np.minimum(_segment_point_distance(land_x, land_z, fx, fz, lift_x, lift_z),
                                           _segment_point_distance(lift_x, lift_z, rx, rz, land_x, land_z)))
    return feet, legs


def neighbour_speed_cap(timing, leg_height: float, rest_body: np.ndarray, hips_body: np.ndarray,
                        windows: np.ndarray, fastest: float, foot_room: float, leg_share: float = 1.0) -> float:
    """The fastest speed (m/s, at most ``fastest``) at which the steady landing and lift-off spots of
    legs next to each other keep ``foot_room`` from each other and ``leg_share`` of it from the other leg's
    line (:func:`neighbour_gaps`); ``inf`` when they keep them up to ``fastest``, or keep them at no speed
    tried (:func:`territory_speed_cap`'s speeds).

    Past it, the rear leg's landing spot is refused or scored down beside its neighbour's foot, and the
    foot lands a cell short of the stride law: random creatures whose rest feet were 4 cm apart, walked at
    their territory cap, landed their rear feet 1.3-2.9 cm short of 5 cm strides (per-stride p90 0.28-0.69).
    A whole room from the other leg by default, not the half the search refuses under (``LEG_CLEARANCE``): the
    leg-spacing reference is at least a foot's room (:func:`leg_room`), so at a cap that kept only half of
    it the law's own spot scored half on leg spacing, and a spot a cell short won (random 6- and
    8-legged creatures at their caps, alone on flat ground: per-stride median 0.04-0.10, p90 0.21-0.36;
    0.00 and 0.01-0.14 with the whole room, the planner also leaving out the feet that lift before a foot
    lands, ``planner._crowd.lifted_before``). The steady spots only: a front foot lifting a frame late
    stands nearer still, but capping for it put the spider's cap (0.63 m/s) under its Fr 0.5 top speed
    (:func:`leg_room` allows for it instead). With ``leg_share`` ``LEG_CLEARANCE`` it is the fastest at which
    no law's spot is refused: how fast a character may flee (``planner._crowd.creature_walk``'s ``escape_cap``).

    Examples
    --------
    :func:`neighbour_gaps`' legs with a 1 cm foot room: the ends facing each other come within a room once
    the sweeps reach 3 cm (0.04 - 0.03 = 0.01 m); the spots keep more than that from the other leg.

    >>> import numpy as np
    >>> from footfall.planner._timing import GaitTiming, duty_factor, stride_length
    >>> rest = np.array([[0.02, 0.05], [-0.02, 0.05]])
    >>> hips = np.array([[0.01, 0.0, 0.01], [-0.01, 0.0, 0.01]])
    >>> windows = rest[:, :1] + np.array([[-0.03, 0.03]])
    >>> v = neighbour_speed_cap(GaitTiming(), 0.025, rest, hips, windows, 1.0, 0.01)
    >>> round(v, 3), round(float(duty_factor(GaitTiming(), v, 0.025) * stride_length(GaitTiming(), v, 0.025)), 4)
    (0.531, 0.03)
    """
    if not side_neighbours(rest_body, hips_body) or not math.isfinite(fastest) or fastest <= 0.0:
        return math.inf
    speeds = _speeds_up_to(fastest)
    feet, legs = neighbour_gaps(timing, leg_height, rest_body, hips_body, windows, speeds)
    return _fastest_kept(speeds, (feet >= foot_room) & (legs >= leg_share * foot_room))


MIN_CYCLE_FRAMES = 4
"""Frames a stride cycle lasts at least (:func:`frame_rate_cap`). A 3 cm mite asked 0.3 m/s steps at
11.8 Hz, a cycle of 2.5 frames of 1/30 s: its swings last under a frame, and six mites on ``flat`` and
``crates`` drew 65 and 124 crossing frames in 300 frames with per-stride p90 0.21-0.34; at 0.097 m/s,
4 frames a cycle, none and 0.0 (seeds 1-3). The beetle (12 cm) walks 0.3 m/s in 5.4 frames a cycle."""


def frame_rate_cap(timing, leg_height: float, dt: float, min_cycle_frames: float | None = None) -> float:
    """The fastest speed (m/s) whose stride cycle at the stride law lasts at least ``min_cycle_frames``
    (default :data:`MIN_CYCLE_FRAMES`) frames of ``dt`` s: a faster gait cannot be drawn, its swings
    lasting under a frame or two.

    ``f(v) = v / lambda(v) = (g h)^e v^(1 - 2e) / (c h)`` with ``lambda = c h Fr^e``; ``f(v) = 1 /
    (min_cycle_frames dt)`` gives ``v = (c h (g h)^-e / (min_cycle_frames dt))^(1 / (1 - 2e))``;
    ``inf`` when the frequency does not grow with speed (``e >= 1/2``).

    Examples
    --------
    >>> from footfall.planner._timing import GaitTiming
    >>> v = frame_rate_cap(GaitTiming(), 0.012, 1 / 30)   # a 1.2 cm high mite: 7.5 Hz at the cap
    >>> round(v, 4)
    0.097
    >>> from footfall.planner import stride_frequency
    >>> round(stride_frequency(GaitTiming(), v, 0.012), 6)
    7.5
    >>> round(frame_rate_cap(GaitTiming(), 0.12, 1 / 30), 2)  # the spider: 5.4 m/s, far above its walk
    5.45
    """
    c = timing.stride_coefficient
    e = timing.stride_exponent
    if e >= 0.5:
        return math.inf
    f_max = 1.0 / ((MIN_CYCLE_FRAMES if min_cycle_frames is None else min_cycle_frames) * dt)
    return (f_max * c * leg_height * (GRAVITY * leg_height) ** (-e)) ** (1.0 / (1.0 - 2.0 * e))


def leg_room(timing, leg_height: float, rest_body: np.ndarray, hips_body: np.ndarray, windows: np.ndarray,
             speed: float, foot_room: float, late_s: float = 0.0) -> float:
    """m: the room between neighbouring legs a footprint can be asked for at ``speed``
    (``planner.default_weights``' ``leg_room_m``): what the stride law's own landing spots leave
    (:func:`neighbour_gaps`' ``legs``, a front foot lifting up to ``late_s`` late), and at least
    ``foot_room``; ``inf`` without legs next to each other.

    At least a foot's room: asked for less (the half of it the search keeps at the least), dense
    creatures' feet landed where their legs were drawn across each other at the next turn (random
    creatures, 48 runs: crossing frames 91 -> 239).

    Examples
    --------
    :func:`neighbour_gaps`' legs walked at 0.3 m/s: the spots facing each other 1.5 cm apart, each
    further from the other leg's line; with 2 cm feet, a foot's room.

    >>> import numpy as np
    >>> from footfall.planner._timing import GaitTiming
    >>> rest = np.array([[0.02, 0.05], [-0.02, 0.05]])
    >>> hips = np.array([[0.01, 0.0, 0.01], [-0.01, 0.0, 0.01]])
    >>> windows = rest[:, :1] + np.array([[-0.03, 0.03]])
    >>> round(leg_room(GaitTiming(), 0.025, rest, hips, windows, 0.3, 0.01), 4)
    0.015
    >>> leg_room(GaitTiming(), 0.025, rest, hips, windows, 0.3, 0.02)
    0.02
    """
    _, legs = neighbour_gaps(timing, leg_height, rest_body, hips_body, windows, [speed], late_s)
    return max(float(legs[0]), foot_room)


SPEED_CAP_REASONS = {
    "windows": "its stance sweeps fit its legs' stance windows",
    "frames": f"a stride cycle lasts at least {MIN_CYCLE_FRAMES} frames",
    "territories": "each stance sweep keeps to its leg's territory, clear of the neighbouring legs",
    "neighbours": "each foot lands a foot's room clear of the neighbouring leg and its foot",
}
"""What sets each of :func:`speed_caps`' caps (:func:`speed_cap_why`)."""


def speed_cap_why(reason: str) -> str:
    """Why a creature walks no faster than its cap, in the words ``footfall check`` and the runs' stderr note
    both say (``reason``: a key of :data:`SPEED_CAP_REASONS`).

    >>> speed_cap_why("frames")
    'the fastest its legs carry at the stride law where a stride cycle lasts at least 4 frames'
    """
    return f"the fastest its legs carry at the stride law where {SPEED_CAP_REASONS[reason]}"


def speed_caps(timing, leg_height: float, rest_body: np.ndarray, hips_body: np.ndarray, windows: np.ndarray,
               dt: float, foot_room: float = 0.0) -> dict:
    """The speeds (m/s) past which the legs cannot carry the stride law, by what sets each:
    ``"windows"`` (:func:`speed_cap` of the narrowest stance window), ``"frames"``
    (:func:`frame_rate_cap`), ``"territories"`` (:func:`territory_speed_cap` below the other two) and
    ``"neighbours"`` (:func:`neighbour_speed_cap` with ``foot_room`` (m), below the other three). The crowd
    walks no faster than the least of them (``init_crowd``; ``CrowdModel.speed_cap`` and
    ``speed_cap_reason``).

    Examples
    --------
    The legs of :func:`territory_speed_cap`'s example four times as large (10 cm high), drawn at 30
    frames a second: their sweeps reach each other's territories first; with 4 cm feet, their landing and
    lift-off spots come within a foot's room of each other sooner still.

    >>> import numpy as np
    >>> from footfall.planner._timing import GaitTiming
    >>> rest = np.array([[0.08, 0.2], [-0.08, 0.2]])
    >>> hips = np.array([[0.04, 0.0, 0.04], [-0.04, 0.0, 0.04]])
    >>> caps = speed_caps(GaitTiming(), 0.1, rest, hips, rest[:, :1] + np.array([[-0.12, 0.12]]), 1 / 30, 0.04)
    >>> {name: round(v, 2) for name, v in caps.items()}
    {'windows': 3.38, 'frames': 3.96, 'territories': 1.7, 'neighbours': 1.06}
    """
    caps = {"windows": speed_cap(timing, leg_height, float(np.min(windows[:, 1] - windows[:, 0]))),
            "frames": frame_rate_cap(timing, leg_height, dt)}
    caps["territories"] = territory_speed_cap(timing, leg_height, rest_body, hips_body, windows, min(caps.values()))
    caps["neighbours"] = neighbour_speed_cap(timing, leg_height, rest_body, hips_body, windows, min(caps.values()),
                                             foot_room)
    return caps


def slope_scale(offset, drop, slope_forward, slope_left) -> np.ndarray:
    """Factor ``k`` on a foot's horizontal offset from its hip that keeps the hip-to-foot distance
    of flat ground on a sloped plane.

    A foot at horizontal offset ``o`` (forward, left; length r) from its hip stands ``drop`` below
    it on flat ground. On a plane of slopes ``(sf, sl)`` through the ground under the body, the
    ground at ``k o`` lies ``a k`` lower, ``a = -(sf o_f + sl o_l)``; ``k`` solves
    ``(k r)^2 + (drop + a k)^2 = r^2 + drop^2``:
    ``k = (-a drop + sqrt(a^2 drop^2 + r^2 (r^2 + a^2))) / (r^2 + a^2)`` (1 on flat, or for a
    foot under its hip).

    Examples
    --------
    >>> import numpy as np
    >>> slope_scale(np.array([[0.0, 0.3], [0.0, -0.3]]), 0.4, 0.0, np.array([0.0, 0.0]))
    array([1., 1.])
    >>> k = slope_scale(np.array([[0.0, -0.3]]), 0.4, 0.0, 0.5)   # downhill: a = 0.15
    >>> float(np.round(k[0], 4)), float(np.round(np.hypot(0.3 * k[0], 0.4 + 0.15 * k[0]), 4))
    (0.508, 0.5)
    """
    offset = np.asarray(offset, dtype=np.float64)
    a = -(np.asarray(slope_forward) * offset[..., 0] + np.asarray(slope_left) * offset[..., 1])
    r2 = offset[..., 0] ** 2 + offset[..., 1] ** 2
    drop = np.asarray(drop, dtype=np.float64)
    denominator = r2 + a * a
    with np.errstate(invalid="ignore", divide="ignore"):
        k = (-a * drop + np.sqrt(a * a * drop * drop + r2 * denominator)) / denominator
    return np.where(denominator > 1e-12, k, 1.0)


STEP_SAMPLES = 41
"""Heights sampled (from the ground up to the standing height) when measuring the highest step."""


HEIGHT_SAMPLES = 81
"""Pelvis heights above a rest foot sampled (0 to 1.5 x the standing height) when measuring a leg's height range."""
HEIGHT_RANGE_USE = 0.75
"""Fraction of a leg's reachable height range beyond the standing height the pelvis may use (the rest
keeps room for a foot away from its rest position)."""


def height_ranges(creature, rest_body: np.ndarray, hips_body: np.ndarray, legs) -> np.ndarray:
    """(L, 2) ``[least, most]`` height (m) of the pelvis above each leg's foot, along the body's up
    axis, that the pelvis keeps: the contiguous range around the standing height where the leg's IK
    (joint limits included) reaches its rest foot, :data:`HEIGHT_RANGE_USE` of it on each side of
    the standing height, and never less than the heights the stance windows are measured at
    (:data:`WINDOW_HEIGHTS`). A sprawled leg folds and stretches a lot; an upright one little.

    Examples
    --------
    >>> from footfall.scenarios import load_creature
    >>> from footfall.planner._ik import legs_of
    >>> q = load_creature("quadruped")
    >>> r = height_ranges(q, q.rest_feet, q.hips, legs_of(q))
    >>> bool((r[:, 0] <= 0.95 * q.standing_height + 1e-12).all() and (r[:, 1] >= 1.05 * q.standing_height - 1e-12).all())
    True
    """
    rest_body = np.ascontiguousarray(rest_body, dtype=np.float64)
    hips_body = np.ascontiguousarray(hips_body, dtype=np.float64)
    return _cached("heights", creature, rest_body, hips_body, legs,
                   lambda: _height_ranges(creature, rest_body, hips_body, legs))


def _height_ranges(creature, rest_body, hips_body, legs) -> np.ndarray:
    n_legs = rest_body.shape[0]
    height = float(creature.standing_height)
    drops = np.linspace(0.0, 1.5 * height, HEIGHT_SAMPLES)
    reached = _rest_feet_reached(rest_body, hips_body, legs, drops)
    out = np.empty((n_legs, 2))
    standing = int(np.argmin(np.abs(drops - height)))
    for i in range(n_legs):
        lo = hi = standing
        while lo > 0 and reached[i, lo - 1]:
            lo -= 1
        while hi < drops.size - 1 and reached[i, hi + 1]:
            hi += 1
        least = height - HEIGHT_RANGE_USE * (height - drops[lo]) if reached[i, standing] else height
        most = height + HEIGHT_RANGE_USE * (drops[hi] - height) if reached[i, standing] else height
        out[i] = (min(least, height * (1.0 - max(WINDOW_HEIGHTS))), max(most, height * (1.0 - min(WINDOW_HEIGHTS))))
    return out


def highest_step(creature, rest_body: np.ndarray, hips_body: np.ndarray, legs) -> float:
    """The highest box top (m above the ground the creature stands on) every leg reaches with its
    foot at its rest position, the pelvis at standing height; never above the standing height
    (a step onto something taller than the hips is a climb, which the planner does not do).

    A safe box taller than this counts as forbidden for the creature (issue 14: an ant that walks
    onto a crate three times its height cannot walk on)."""
    rest_body = np.ascontiguousarray(rest_body, dtype=np.float64)
    hips_body = np.ascontiguousarray(hips_body, dtype=np.float64)
    return _cached("step", creature, rest_body, hips_body, legs,
                   lambda: _highest_step(creature, rest_body, hips_body, legs))


def tuck_reaches(creature, rest_body: np.ndarray, hips_body: np.ndarray, legs, asked, lift: float) -> np.ndarray:
    """(L, K) the fractions of each leg's rest offset from its hip at which a tucked foot is held:
    for each of ``asked`` (K,), the least one from it up (in steps of :data:`TUCK_REACH_STEP`) whose
    point, ``lift`` of the hip's height above the ground under the hip, the leg's IK reaches (level
    body, joint limits included): a point nearer the hip than the folded leg reaches
    is drawn centimetres off by the IK (``planner._crowd.tuck_points``); where none is, the asked one.

    Parameters
    ----------
    creature, rest_body, hips_body, legs
        As :func:`stance_windows`.
    asked : sequence of float
        The wanted fractions, outermost first.
    lift : float
        The tuck point's height above the ground, as a fraction of the hip's height.
    """
    rest_body = np.ascontiguousarray(rest_body, dtype=np.float64)
    hips_body = np.ascontiguousarray(hips_body, dtype=np.float64)
    asked = tuple(float(a) for a in asked)
    return _cached(("tucks", asked, float(lift)), creature, rest_body, hips_body, legs,
                   lambda: _tuck_reaches(creature, rest_body, hips_body, legs, asked, lift))


def tuck_drop(creature, hips_up: np.ndarray, lift: float) -> np.ndarray:
    """(L,) m a tucked foot is held below its hip: ``lift`` of the hip's height (``hips_up``, m above the
    pelvis) above the ground, with the pelvis at the creature's standing height."""
    return (1.0 - lift) * (float(creature.standing_height) + hips_up)


TUCK_REACH_STEP = 0.05
"""Step (x the rest offset) in which :func:`tuck_reaches` moves an unreachable tuck point outwards."""


def _tuck_reaches(creature, rest_body, hips_body, legs, asked, lift) -> np.ndarray:
    n_legs = rest_body.shape[0]
    grid = np.round(np.arange(0.0, 1.0 + 1e-9, TUCK_REACH_STEP), 10)
    k = grid.size
    up = hips_body[:, 1] - tuck_drop(creature, hips_body[:, 1], lift)
    forward = hips_body[:, 0:1] + grid[None, :] * (rest_body[:, 0:1] - hips_body[:, 0:1])
    lateral = hips_body[:, 2:3] + grid[None, :] * (rest_body[:, 1:2] - hips_body[:, 2:3])
    targets = np.stack([forward, np.broadcast_to(up[:, None], forward.shape), lateral], axis=-1).reshape(-1, 3)
    reached = _reached(hips_body, legs, np.repeat(np.arange(n_legs), k), targets).reshape(n_legs, k)
    out = np.ones((n_legs, len(asked)))
    for i in range(n_legs):
        for j, a in enumerate(asked):
            ok = np.flatnonzero(reached[i] & (grid >= a - 1e-9))
            out[i, j] = grid[ok[0]] if ok.size else a
    return out


def _highest_step(creature, rest_body, hips_body, legs) -> float:
    n_legs = rest_body.shape[0]
    height = float(creature.standing_height)
    rises = np.linspace(0.0, height, STEP_SAMPLES)
    reached = _rest_feet_reached(rest_body, hips_body, legs, height - rises)
    best = height
    for i in range(n_legs):
        k = 0
        while k + 1 < rises.size and reached[i, k + 1]:
            k += 1
        best = min(best, float(rises[k]) if reached[i, 0] else 0.0)
    return best
