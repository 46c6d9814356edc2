"""numba kernels of the gait manager (paper §3.3, Fig. 8-9) and of the timing model.

Phases are fractions of a cycle in [0, 1). A foot's disk is its swing sector
[start, start + duration) (mod 1); the foot is *active* (should swing) while
the needle is inside it. One call of :func:`advance_gaits` steps every
character of a crowd by one frame.

Entering a sector
-----------------
Seen from a foot's sector, the needle moves by ``D = frequency * dt - delta``
in a step, where ``delta`` is how far the sector's start moved (transitions).
The step covers the half-open relative arc [u0, u0 + D), u0 = (needle - start)
mod 1 before the step; the foot *enters* when that arc contains the sector's
start (u0 == 0, or the arc wraps past 1), or when D >= 1 (a whole cycle in one
step: it triggers once). Consecutive steps cover consecutive half-open arcs,
so with a steady disk each foot enters exactly once per cycle, however the
frame times fall, and also when one step jumps over a whole short sector
(then the needle is already past the sector at the end of the step and its
swing fraction is 0). A start that a transition moves backwards across the
needle counts as the needle crossing it (the foot enters); a needle that ends
up inside a sector through its *finish* (the sector slid or grew over it)
does not make the foot enter: that foot has just swung.

Transitions (paper §3.3)
------------------------
Only while a foot is in stance, its disk moves toward the destination disk:
the start by at most ``transition_rate * dt`` per step along the circular
direction that does not pass through the destination's finish (destination
start + destination duration), i.e. forward when the start lies in the
destination's stance arc [finish, dest start), backward when it lies inside
the destination's sector. The duration follows linearly with the same fraction
of the remaining way, so both arrive together; when the start needs no move
the duration itself changes by at most ``transition_rate * dt`` per step. When
both are within :data:`SNAP` they snap to the destination. The direction is
decided anew every step from the current disk and destination, so a changed
destination (a new gait, a new speed) is followed at once. Swinging feet keep
their disk. ``transition_rate`` 0 freezes the disks.
"""

from __future__ import annotations

import math

import numba as nb

from footfall.planner._timing import (
    GRAVITY,
    SWING_MAX,
    SWING_MIN,
    T_DUTY_AT_REST,
    T_DUTY_MAX,
    T_DUTY_MIN,
    T_DUTY_SLOPE,
    T_MIN_FREQUENCY,
    T_STRIDE_COEFFICIENT,
    T_STRIDE_EXPONENT,
    duty_law,
    stride_law,
)

SNAP = 1e-9
"""A disk within this of its destination (start and duration) snaps to it."""


# --------------------------------------------------------------------------- timing model


@nb.njit(cache=True)
def stride_length_k(params, v, h):
    """Kernel twin of :func:`planner._timing.stride_length` for one speed ``v`` (m/s) and height ``h`` (m)."""
    if v <= 0.0:
        return 0.0
    return stride_law(params[T_STRIDE_COEFFICIENT], params[T_STRIDE_EXPONENT], v, h)


@nb.njit(cache=True)
def stride_frequency_k(params, v, h):
    """Kernel twin of :func:`planner._timing.stride_frequency` (Hz); 0 where the stride is 0."""
    length = stride_length_k(params, v, h)
    if length <= 0.0:
        return 0.0
    return max(v / length, params[T_MIN_FREQUENCY])


@nb.njit(cache=True)
def duty_factor_k(params, v, h):
    """Kernel twin of :func:`planner._timing.duty_factor`."""
    raw = duty_law(params[T_DUTY_AT_REST], params[T_DUTY_SLOPE], v, math.sqrt(GRAVITY * h))
    return min(max(raw, params[T_DUTY_MIN]), params[T_DUTY_MAX])


@nb.njit(cache=True)
def scale_swing_durations_k(durations, duty, out):
    """Kernel twin of :func:`planner._timing.scaled_swing_durations` for one (L,) row, into ``out``."""
    n = durations.shape[0]
    mean = 0.0
    for j in range(n):
        mean += durations[j]
    mean /= n
    for j in range(n):
        out[j] = min(max((1.0 - duty) * durations[j] / mean, SWING_MIN), SWING_MAX)


@nb.njit(cache=True)
def retime_gaits(params, speed, height, duty_ceiling, gait_duration, out_frequency, out_duty, dest_duration):
    """Per character c: stride frequency and duty factor at ``speed[c]``, ``height[c]``; the destination
    disks' durations = ``gait_duration[c]`` scaled to that duty factor.

    ``duty_ceiling[c]`` lowers the duty factor to what the character's legs carry (the stance sweep
    ``DF * lambda`` fits their stance window, :mod:`planner._workspace`), never below ``duty_min``."""
    for c in range(speed.shape[0]):
        out_frequency[c] = stride_frequency_k(params, speed[c], height[c])
        out_duty[c] = max(min(duty_factor_k(params, speed[c], height[c]), duty_ceiling[c]), params[T_DUTY_MIN])
        scale_swing_durations_k(gait_duration[c], out_duty[c], dest_duration[c])


# --------------------------------------------------------------------------- gait manager


@nb.njit(cache=True)
def wrap_phase(x):
    """``x`` mod 1 in [0, 1) (also for tiny negative ``x``, where ``x - floor(x)`` rounds to 1)."""
    r = x - math.floor(x)
    if r >= 1.0:
        r = 0.0
    return r


@nb.njit(cache=True)
def transition_direction(start, dest_start, dest_duration):
    """+1 (forward) or -1 (backward): how ``start`` moves toward ``dest_start`` without passing the
    destination's finish. Forward iff ``start`` lies in the destination's stance arc [finish, dest_start)."""
    finish = wrap_phase(dest_start + dest_duration)
    if wrap_phase(start - finish) < wrap_phase(dest_start - finish):
        return 1.0
    return -1.0


@nb.njit(cache=True)
def transition_step(start, duration, dest_start, dest_duration, step):
    """One transition step of a stance foot's disk: (new start, new duration, signed start move)."""
    forward = wrap_phase(dest_start - start)
    if forward <= SNAP or forward >= 1.0 - SNAP:
        distance = min(forward, 1.0 - forward)
        direction = 1.0 if forward <= 0.5 else -1.0
    else:
        direction = transition_direction(start, dest_start, dest_duration)
        distance = forward if direction > 0.0 else 1.0 - forward
    remaining_duration = dest_duration - duration
    largest = max(distance, abs(remaining_duration))
    if largest <= SNAP or step >= largest:
        return dest_start, dest_duration, direction * distance
    fraction = step / largest
    delta = direction * distance * fraction
    return wrap_phase(start + delta), duration + remaining_duration * fraction, delta


@nb.njit(cache=True)
def advance_gaits(needle, frequency, dt, disk_start, disk_duration, dest_start, dest_duration,
                  transition_rate, in_stance, out_enter_swing, out_swing_fraction):
    """Step C characters' gait managers by ``dt`` seconds (module doc).

    needle (C,) phase, updated in place: needle += frequency * dt (mod 1).
    frequency (C,) Hz >= 0; dt s >= 0.
    disk_start, disk_duration (C, L): the disks in use, updated in place (transitions of stance feet).
    dest_start, dest_duration (C, L): the destination disks (read only).
    transition_rate (C,) cycles of phase per second.
    in_stance (C, L) bool: the feet on the ground at the start of the step.
    out_enter_swing (C, L) bool: the stance feet whose sector the needle entered in this step.
    out_swing_fraction (C, L): (needle - start) mod 1 / duration for feet whose sector holds the
    needle after the step, else 0.
    """
    n_characters, n_legs = disk_start.shape
    for c in range(n_characters):
        sweep = frequency[c] * dt
        p0 = needle[c]
        p1 = wrap_phase(p0 + sweep)
        needle[c] = p1
        step = transition_rate[c] * dt
        for j in range(n_legs):
            s0 = disk_start[c, j]
            s1 = s0
            d1 = disk_duration[c, j]
            delta = 0.0
            stance = in_stance[c, j]
            if stance and (s0 != dest_start[c, j] or d1 != dest_duration[c, j]):
                s1, d1, delta = transition_step(s0, d1, dest_start[c, j], dest_duration[c, j], step)
                disk_start[c, j] = s1
                disk_duration[c, j] = d1
            u1 = wrap_phase(p1 - s1)
            enter = False
            if stance:
                relative = sweep - delta  # the needle's advance seen from the (moving) sector
                if relative >= 1.0:
                    enter = True
                elif relative > 0.0:
                    u0 = wrap_phase(p0 - s0)
                    if u0 == 0.0:
                        enter = True
                    elif u1 > 0.0:
                        # wrapped past the start iff u1 ~ u0 + relative - 1 rather than u0 + relative
                        enter = abs(u1 + 1.0 - u0 - relative) < abs(u1 - u0 - relative)
            out_enter_swing[c, j] = enter
            out_swing_fraction[c, j] = u1 / d1 if u1 < d1 else 0.0


@nb.njit(cache=True)
def active_feet(needle, disk_start, disk_duration, out_active):
    """out_active[c, j] = the needle of character c lies in foot j's sector."""
    n_characters, n_legs = disk_start.shape
    for c in range(n_characters):
        for j in range(n_legs):
            out_active[c, j] = wrap_phase(needle[c] - disk_start[c, j]) < disk_duration[c, j]

