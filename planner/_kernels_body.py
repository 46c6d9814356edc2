"""numba kernel: pelvis height, pitch and roll from convex hulls (paper §3.2, Fig. 4b).

For each character, two vertical slices through the pelvis: along its forward
axis and along its lateral axis. In each slice the points are the ground under
the body (at the body box's ends and centre) and the feet (stance feet where they
stand, swinging feet where they will land), as (offset along the axis, height).
The upper convex hull of those points is the support line; the pelvis sits
``standing_height`` above the forward hull at the body centre (plus a bobbing
from the feet phases); pitch and roll are the slopes of the hull segments under
the centre.

A tilt the legs carry: the hulls tilt the body toward a foot standing high (a foot on a crate's top),
and a tilted body can put another foot out of its leg's reach below a pelvis at standing height
(a robot5's ground foot 0.1 m out of reach, the pelvis falling 13 cm in a frame to reach it). The
body tilts the largest fraction of both hull slopes at which every support point reaches the
pelvis (:func:`carried_tilt`); where the paper's pose is reachable that fraction is 1, its pose.

Legs that reach: the pelvis stands, along the body's up axis, within each leg's height
range above its foot (:func:`planner._workspace.height_ranges`). On a hill the hull is
the uphill side and the ground falls away under the downhill feet; a pelvis on the hull
hung those feet below what their legs reach (holds, a crawl). Where the feet ask for
more than one height can give, the stance legs' folding wins (a landing point lowers no
pelvis below what the feet on the ground can fold to). The body never sinks into the
ground for it: the pelvis stays ``body_thickness`` above the highest ground under the
body box.

Smoothing (``ControllerConfig.pelvis_lag``, 0.1 s by default; 0 turns it off, see there for
what it buys): the hull moves in steps (a foot lifting off takes its stance point out, a landing point
changes when a swing re-plans), and a body set on it each frame jumps with it (up to 0.6 rad of
pitch and half a standing height in one frame, an ant on ``stairs``). With a lag, the body's
pitch, roll and base height (the pelvis's before the bob) go ``smoothing`` = 1 - exp(-dt / tau)
of the way from the last frame's values to this frame's per frame; the stance feet's height
ranges and the ground under the body stay hard limits, and a swinging foot's landing point is
approached through the lag. ``smoothing`` 1 is the paper's pose, exactly.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True)
def upper_hull_at_zero(s, y, n):
    """Height and slope at s = 0 of the upper convex hull of points (s[i], y[i]), i < n."""
    order = np.argsort(s[:n])
    hs = np.empty(n, dtype=np.float64)
    hy = np.empty(n, dtype=np.float64)
    m = 0
    for k in range(n):
        i = order[k]
        while m >= 2:
            # keep a right turn (upper hull, left to right)
            cross = (hs[m - 1] - hs[m - 2]) * (y[i] - hy[m - 2]) - (hy[m - 1] - hy[m - 2]) * (s[i] - hs[m - 2])
            if cross >= 0.0:
                m -= 1
            else:
                break
        hs[m] = s[i]
        hy[m] = y[i]
        m += 1
    if m == 1 or 0.0 <= hs[0]:
        return hy[0], 0.0 if m == 1 else (hy[1] - hy[0]) / max(hs[1] - hs[0], 1e-12)
    for k in range(m - 1):
        if hs[k] <= 0.0 <= hs[k + 1]:
            ds = hs[k + 1] - hs[k]
            if ds <= 1e-12:
                return max(hy[k], hy[k + 1]), 0.0
            slope = (hy[k + 1] - hy[k]) / ds
            return hy[k] + slope * (0.0 - hs[k]), slope
    slope = (hy[m - 1] - hy[m - 2]) / max(hs[m - 1] - hs[m - 2], 1e-12)
    return hy[m - 1], slope


@nb.njit(cache=True)
def _ground_along_up(y, s, t, sp, cpsr):
    """The height term of a support point at ground offsets ``s`` (ahead), ``t`` (left) and height ``y``
    under a body of pitch sine ``sp`` and cos(pitch) sin(roll) ``cpsr``: the pelvis stands within
    this + cos(pitch) cos(roll) x [least, most] of its leg's height range (:func:`pelvis_from_hulls`)."""
    return y - sp * s - cpsr * t


@nb.njit(cache=True)
def _reach_violation(tilt, slope, slope_l, s, y, t, m, in_stance_legs, heights_least, heights_most, target):
    """How far (m) a pelvis at ``target`` lies outside the height ranges of its support points
    (indices 3..m-1 of ``s``, ``y``, ``t``) with the hulls' slopes scaled by ``tilt``: the sum over the
    points of the distance below the least (stance feet only) and above the most."""
    pitch = math.atan(tilt * slope)
    roll = math.atan(tilt * slope_l)
    sp = math.sin(pitch)
    cpcr = math.cos(pitch) * math.cos(roll)
    cpsr = math.cos(pitch) * math.sin(roll)
    out = 0.0
    for k in range(3, m):
        foot = _ground_along_up(y[k], s[k], t[k], sp, cpsr)
        out += max(0.0, target - (foot + cpcr * heights_most[k]))
        if in_stance_legs[k]:
            out += max(0.0, foot + cpcr * heights_least[k] - target)
    return out


@nb.njit(cache=True)
def carried_tilt(slope, slope_l, s, y, t, m, in_stance_legs, heights_least, heights_most, target):
    """The largest fraction in [0, 1] of the hulls' slopes at which every support point reaches a
    pelvis at ``target`` (:func:`_reach_violation` 0); where none does, the one that leaves the least
    violation (the larger on a tie). A grid of eighths, then a bisection between the last fraction
    that reaches and the next that does not, so the tilt moves smoothly with the feet."""
    best = 1.0
    best_v = _reach_violation(1.0, slope, slope_l, s, y, t, m, in_stance_legs, heights_least, heights_most, target)
    if best_v <= 0.0:
        return 1.0
    for j in range(7, -1, -1):
        a = j / 8.0
        v = _reach_violation(a, slope, slope_l, s, y, t, m, in_stance_legs, heights_least, heights_most, target)
        if v < best_v - 1e-12:
            best, best_v = a, v
        if v <= 0.0:
            # the tilt between this eighth (reaches) and the next (does not)
            lo_a, hi_a = a, a + 0.125
            for _ in range(6):
                mid = 0.5 * (lo_a + hi_a)
                if _reach_violation(mid, slope, slope_l, s, y, t, m, in_stance_legs, heights_least, heights_most,
                                    target) <= 0.0:
                    lo_a = mid
                else:
                    hi_a = mid
            return lo_a
    return best


@nb.njit(cache=True)
def _sample(top, origin_x, origin_z, cell, x, z):
    n_rows, n_cols = top.shape
    r = min(n_rows - 1, max(0, int(math.floor((z - origin_z) / cell))))
    c = min(n_cols - 1, max(0, int(math.floor((x - origin_x) / cell))))
    return top[r, c]


@nb.njit(cache=True, parallel=True)
def pelvis_from_hulls(top, origin_x, origin_z, cell, pelvis, heading, support, feet_now, in_stance, lands, body_length,
                      body_width, standing_height, heights, body_thickness, bob, smoothing, last_base, last_pitch, last_roll,
                      out_y, out_pitch, out_roll, out_base):
    """Write pelvis height, pitch, roll and the base height (the pelvis's before the bob).

    ``support`` (C, L, 3): the feet used for the hull; ``feet_now`` (C, L, 3): where the feet are this
    frame (a swinging foot on its path); ``in_stance`` (C, L): the feet on the ground
    (a swinging foot's landing point lowers no pelvis: the stance legs would have to fold for it);
    ``lands`` (C, L): the feet that stand or will land (a foot tucked up, with no footprint, is no
    support point at all: as one it tilted the body by 5 degrees and dropped it by 2.4 cm);
    ``bob`` (C,) the bobbing offset;
    ``heights`` (L, 2) m: the least and most the pelvis stands above each leg's foot along its up
    axis (:func:`planner._workspace.height_ranges`; the least for stance feet only, the most for
    every support point; a swinging foot's leg also folds to where the foot is now, as far as the stance
    legs let the body rise);
    ``body_thickness`` (m): the least it stands above the ground under its body box;
    ``smoothing`` in (0, 1]: the fraction of the way from ``last_base``, ``last_pitch``, ``last_roll``
    (C,) to this frame's that the body goes (module doc).
    """
    n_chars = pelvis.shape[0]
    n_legs = support.shape[1]
    for c in nb.prange(n_chars):
        cs = math.cos(heading[c])
        sn = math.sin(heading[c])
        px = pelvis[c, 0]
        pz = pelvis[c, 2]
        s = np.empty(n_legs + 3, dtype=np.float64)
        y = np.empty(n_legs + 3, dtype=np.float64)
        t = np.empty(n_legs + 3, dtype=np.float64)
        yl = np.empty(n_legs + 3, dtype=np.float64)
        least = np.zeros(n_legs + 3, dtype=np.float64)
        most = np.zeros(n_legs + 3, dtype=np.float64)
        stance_point = np.zeros(n_legs + 3, dtype=np.bool_)
        for k in range(3):
            a = (k - 1) * 0.5 * body_length
            s[k] = a
            y[k] = _sample(top, origin_x, origin_z, cell, px + a * cs, pz + a * sn)
            b = (k - 1) * 0.5 * body_width
            t[k] = b
            yl[k] = _sample(top, origin_x, origin_z, cell, px - b * sn, pz + b * cs)
        m = 3
        for i in range(n_legs):
            if not lands[c, i]:
                continue
            dx = support[c, i, 0] - px
            dz = support[c, i, 2] - pz
            s[m] = dx * cs + dz * sn
            y[m] = support[c, i, 1]
            t[m] = -dx * sn + dz * cs
            yl[m] = support[c, i, 1]
            least[m] = heights[i, 0]
            most[m] = heights[i, 1]
            stance_point[m] = in_stance[c, i]
            m += 1
        h, slope = upper_hull_at_zero(s, y, m)
        hl, slope_l = upper_hull_at_zero(t, yl, m)
        # The paper's hull lies in the sagittal slice (Fig. 4b): all feet projected onto the
        # heading. On a side slope that slice's upper hull is the uphill feet, a slope's width above
        # the ground under the body, and the downhill legs cannot reach down that far. The lateral
        # slice's hull is the ground under the body there (and the sagittal one is on a slope
        # ahead), so the body stands on the lower of the two.
        h = min(h, hl)
        # The hulls tilt the body toward a foot standing high (a crate's top at nine tenths of the
        # standing height): pitched up by 0.46 rad, a robot5's front foot on the ground lay 0.1 m
        # out of its leg's reach below a pelvis at standing height, the pelvis fell 13 cm in one frame
        # to reach it, and rose 7 cm in the next a stance foot's folding asked for. The body tilts
        # only as far as every support point reaches a pelvis at standing height above the hull.
        tilt = carried_tilt(slope, slope_l, s, y, t, m, stance_point, least, most, h + standing_height)
        slope *= tilt
        slope_l *= tilt
        pitch = math.atan(slope)
        roll = math.atan(slope_l)
        if smoothing < 1.0:
            pitch = last_pitch[c] + smoothing * (pitch - last_pitch[c])
            roll = last_roll[c] + smoothing * (roll - last_roll[c])
        # A foot at body offset (f, u, l) lies sp f + cp cr u + cp sr l above the pelvis
        # (planner._ik.body_rotation), so -u stays within [least, most] while the pelvis is within
        # foot_y - sp f - cp sr l + cp cr [least, most] (f, l: its ground offsets along the heading).
        sp = math.sin(pitch)
        cpcr = math.cos(pitch) * math.cos(roll)
        cpsr = math.cos(pitch) * math.sin(roll)
        low = -np.inf
        high = np.inf
        reach = np.inf
        for k in range(3, m):
            foot = _ground_along_up(y[k], s[k], t[k], sp, cpsr)
            reach = min(reach, foot + cpcr * most[k])
            if stance_point[k]:
                low = max(low, foot + cpcr * least[k])
                high = min(high, foot + cpcr * most[k])
        # A foot stepping down off a crate leaves the hull at lift-off (its landing point is the support),
        # but it swings over the crate's top first: with the body dropped to the landing's hull, a
        # quadruped's leg could not fold to it, and the drawn foot passed 8 mm inside the crate's edge
        # (crates-moving, seed 2132651497, LOD zoomed, character 1, frame 243). The body stays high
        # enough for every swinging leg's least height over its foot now, where the stance legs allow.
        swing_low = -np.inf
        for i in range(n_legs):
            if lands[c, i] and not in_stance[c, i]:
                dx = feet_now[c, i, 0] - px
                dz = feet_now[c, i, 2] - pz
                foot = _ground_along_up(feet_now[c, i, 1], dx * cs + dz * sn, -dx * sn + dz * cs, sp, cpsr)
                swing_low = max(swing_low, foot + cpcr * heights[i, 0])
        base = max(min(h + standing_height, reach), low)
        if smoothing < 1.0:
            # The lag is the body's; the stance feet's reach and the ground under the body are hard
            # limits (a swinging foot's landing point asks, through the lag, before it lands).
            base = last_base[c] + smoothing * (base - last_base[c])
            y_body = min(base + bob[c], high)
        else:
            y_body = min(h + standing_height + bob[c], reach)
        y_body = max(y_body, low)
        y_body = max(y_body, min(swing_low, high))
        ground = max(max(y[0], y[1]), max(y[2], max(yl[0], yl[2])))
        y_body = max(y_body, ground + body_thickness)
        if smoothing < 1.0:
            # The lag starts from where the limits put the body: a limit that lifted it for a frame (a
            # swinging foot over a riser, the ground under it) lets it down through the lag, not at once.
            # Lagging behind them instead, an ant climbing 7 cm risers rose and fell 1-2.7 cm within
            # two to four frames as its feet swung over each one.
            base = y_body - bob[c]
        out_base[c] = base
        out_y[c] = y_body
        out_pitch[c] = pitch
        out_roll[c] = roll
