"""The gait manager (paper §3.3, Fig. 8-9) for a crowd: C characters x L legs in arrays.

Every character of a :class:`GaitManagerState` has the same number of legs
(one state per creature kind). Each character has a needle (its phase in the
stride cycle) and one disk per foot, the swing sector [start, start +
duration) (mod 1), phases being fractions of a cycle in [0, 1). One numba
kernel, :func:`planner._kernels_gait.advance_gaits`, steps the whole crowd per
frame; its doc gives the exact rules (entering a sector, transitions).

Typical frame::

    frequency = set_speed(state, timing, speed, hip_height)      # (C,) Hz; rescales the destination disks
    enter, fraction = advance(state, frequency, dt, in_stance)   # (C, L) bool, (C, L) float

``enter`` lists the stance feet that must start a swing now (the character
controller plans their footprints); ``fraction`` is each active foot's
progress through its sector (0 for feet outside their sector).

Gait changes (:func:`set_destination`) and speed changes (:func:`set_speed`)
set the *destination* disks; the disks in use move toward them only while
their foot is in stance, at ``transition_rate`` cycles of phase per second,
the start along the arc that avoids the destination's finish (Fig. 9).

The state is a plain struct of mutable arrays owned by the simulation; the
functions here validate their inputs and call the kernels, which write into
the state in place.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from collections.abc import Sequence
from typing import Any

import numpy as np

from footfall.planner._kernels_gait import active_feet, advance_gaits, retime_gaits
from footfall.planner._timing import GaitTiming, scaled_swing_durations

DEFAULT_TRANSITION_RATE = 0.5
"""Cycles of phase per second a disk's start moves during a gait transition (a half-cycle shift in 1 s)."""


@dataclass(eq=False)
class GaitManagerState:
    """Gait manager state of C characters with L legs each (mutable arrays, float64 unless noted).

    Attributes
    ----------
    needle:
        (C,) phase of each character's needle, in [0, 1).
    disk_start, disk_duration:
        (C, L) the disks in use: swing sector start in [0, 1) and swing fraction in (0, 1).
    dest_start, dest_duration:
        (C, L) the destination disks (equal to the disks in use when not transitioning):
        ``gait_start`` and ``gait_duration`` scaled to the last duty factor (:func:`set_speed`).
    transition_rate:
        (C,) cycles of phase per second a disk moves toward its destination (>= 0).
    gait_start, gait_duration:
        (C, L) the destination gait as authored, before speed scaling.
    duty_factor:
        (C,) duty factor the destination durations were scaled to; NaN = the gait as authored.
    leg_names:
        The legs' names when the gaits came as :class:`scenarios.Gait` values, else ``None``.

    Examples
    --------
    >>> from footfall.planner import init_gaits
    >>> from footfall.scenarios import default_gait, load_creature
    >>> state = init_gaits(default_gait(load_creature("spider")), 2)
    >>> state.n_characters, state.n_legs, state.needle.shape, state.disk_start.shape
    (2, 8, (2,), (2, 8))
    >>> state.leg_names[:4]
    ('L1', 'L2', 'L3', 'L4')
    >>> state.transitioning()                       # fresh from init_gaits: the disks are their destinations
    array([False, False])
    """

    needle: np.ndarray
    disk_start: np.ndarray
    disk_duration: np.ndarray
    dest_start: np.ndarray
    dest_duration: np.ndarray
    transition_rate: np.ndarray
    gait_start: np.ndarray
    gait_duration: np.ndarray
    duty_factor: np.ndarray
    leg_names: tuple[str, ...] | None = field(default=None)

    @property
    def n_characters(self) -> int:
        return self.disk_start.shape[0]

    @property
    def n_legs(self) -> int:
        return self.disk_start.shape[1]

    def copy(self) -> "GaitManagerState":
        """A deep copy (new arrays)."""
        arrays = {name: getattr(self, name).copy() for name in _ARRAY_FIELDS}
        return GaitManagerState(**arrays, leg_names=self.leg_names)

    def transitioning(self) -> np.ndarray:
        """(C,) bool: some disk of the character differs from its destination."""
        return np.any((self.disk_start != self.dest_start) | (self.disk_duration != self.dest_duration), axis=1)

    def active(self) -> np.ndarray:
        """(C, L) bool: the needle lies inside the foot's sector (the foot should swing)."""
        out = np.zeros(self.disk_start.shape, dtype=np.bool_)
        active_feet(self.needle, self.disk_start, self.disk_duration, out)
        return out


_ARRAY_FIELDS = ("needle", "disk_start", "disk_duration", "dest_start", "dest_duration", "transition_rate",
                 "gait_start", "gait_duration", "duty_factor")


# --------------------------------------------------------------------------- validation helpers


def _check_disks(start: np.ndarray, duration: np.ndarray, what: str) -> None:
    if start.shape[-1] == 0:
        raise ValueError(f"{what}: a gait needs at least one leg")
    if not np.all(np.isfinite(start)) or np.any((start < 0.0) | (start >= 1.0)):
        raise ValueError(f"{what}: swing starts must be phases in [0, 1)")
    if not np.all(np.isfinite(duration)) or np.any((duration <= 0.0) | (duration >= 1.0)):
        raise ValueError(f"{what}: swing durations must be in (0, 1)")


def _is_gait(value: Any) -> bool:
    return hasattr(value, "swing_start") and hasattr(value, "swing_duration")


def _gait_rows(gaits: Any, n_rows: int, what: str) -> tuple[np.ndarray, np.ndarray, tuple[str, ...] | None]:
    """(start (n_rows, L), duration (n_rows, L), leg names or None) of one gait, a list of gaits or arrays.

    Accepted: a ``Gait`` (every row), a sequence of ``n_rows`` gaits, or a pair
    ``(start, duration)`` of (L,) or (n_rows, L) arrays.
    """
    names: tuple[str, ...] | None = None
    if _is_gait(gaits):
        start, duration = np.asarray(gaits.swing_start, float)[None, :], np.asarray(gaits.swing_duration, float)[None, :]
        names = tuple(getattr(gaits, "leg_names", ())) or None
    elif isinstance(gaits, Sequence) and len(gaits) > 0 and all(_is_gait(g) for g in gaits):
        if len(gaits) != n_rows:
            raise ValueError(f"{what}: expected one gait or {n_rows} gaits, got {len(gaits)}")
        lengths = {len(g.swing_start) for g in gaits}
        if len(lengths) != 1:
            raise ValueError(f"{what}: the gaits have different numbers of legs {sorted(lengths)}")
        leg_sets = {tuple(getattr(g, "leg_names", ())) for g in gaits}
        if len(leg_sets) != 1:
            raise ValueError(f"{what}: the gaits name different legs (or the same legs in another order)")
        start = np.array([g.swing_start for g in gaits], dtype=np.float64)
        duration = np.array([g.swing_duration for g in gaits], dtype=np.float64)
        names = leg_sets.pop() or None
    else:
        try:
            start_in, duration_in = gaits
            start = np.array(start_in, dtype=np.float64, ndmin=1)
            duration = np.array(duration_in, dtype=np.float64, ndmin=1)
        except (TypeError, ValueError):
            raise ValueError(f"{what}: expected a Gait, a list of Gaits or a (start, duration) pair of arrays") from None
        start = start[None, :] if start.ndim == 1 else start
        duration = duration[None, :] if duration.ndim == 1 else duration
    for array in (start, duration):
        if array.ndim != 2 or array.shape[0] not in (1, n_rows):
            raise ValueError(f"{what}: expected (L,) or ({n_rows}, L) arrays, got shape {array.shape}")
    if start.shape[1] != duration.shape[1]:
        raise ValueError(f"{what}: {start.shape[1]} starts but {duration.shape[1]} durations")
    _check_disks(start, duration, what)
    start = np.array(np.broadcast_to(start, (n_rows, start.shape[1])), dtype=np.float64)
    duration = np.array(np.broadcast_to(duration, (n_rows, duration.shape[1])), dtype=np.float64)
    return start, duration, names


def _per_character(value: Any, n: int, what: str, *, positive: bool = False) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64)
    if array.ndim > 1 or (array.ndim == 1 and array.shape[0] != n):
        raise ValueError(f"{what}: expected a number or an array of shape ({n},), got shape {array.shape}")
    array = np.ascontiguousarray(np.broadcast_to(array, (n,)), dtype=np.float64).copy()
    if not np.all(np.isfinite(array)) or np.any(array <= 0.0 if positive else array < 0.0):
        raise ValueError(f"{what}: expected finite numbers {'> 0' if positive else '>= 0'}")
    return array


def _indices(state: GaitManagerState, character_indices: Any) -> np.ndarray:
    if isinstance(character_indices, slice):
        return np.arange(state.n_characters)[character_indices]
    indices = np.asarray(character_indices)
    if indices.dtype == np.bool_:
        if indices.shape != (state.n_characters,):
            raise ValueError(f"character_indices: a mask must have shape ({state.n_characters},)")
        return np.flatnonzero(indices)
    indices = indices.reshape(-1)
    if indices.size and (not np.issubdtype(indices.dtype, np.integer)
                         or indices.min() < -state.n_characters or indices.max() >= state.n_characters):
        raise ValueError(f"character_indices: expected integers in [0, {state.n_characters})")
    return indices.astype(np.int64) % state.n_characters


# --------------------------------------------------------------------------- public API


def init_gaits(gaits: Any, n_characters: int, rng_phase_offsets: Any = None, *,
               transition_rate: Any = DEFAULT_TRANSITION_RATE, duty_factor: Any = None) -> GaitManagerState:
    """The gait manager state of ``n_characters`` characters, not transitioning.

    A foot swings when the needle *enters* its sector: a foot whose sector
    already holds a character's initial needle waits for the next cycle,
    except a sector starting exactly at the needle, which the first
    :func:`advance` enters.

    Parameters
    ----------
    gaits : scenarios.Gait, list of scenarios.Gait, or (array_like, array_like)
        A ``scenarios.Gait`` (every character), a list of ``n_characters``
        gaits with the same legs, or a ``(start, duration)`` pair of (L,) or
        (C, L) arrays.
    n_characters : int
        C, at least 1.
    rng_phase_offsets : None, int, numpy.random.Generator or array_like, optional
        The needles' initial phases: ``None`` (all 0), an integer seed or a
        ``numpy.random.Generator`` (uniform in [0, 1) per character, so a crowd
        does not step in unison), or an array (C,) of phases in [0, 1).
    transition_rate : float or array_like, optional
        Cycles of phase per second (number or (C,)), >= 0.
    duty_factor : None, float or array_like, optional
        ``None``: the disks are the gaits as authored; else a duty factor in
        (0, 1) (number or (C,)) the durations are scaled to right away
        (:func:`planner._timing.scaled_swing_durations`).

    Returns
    -------
    GaitManagerState
        New arrays, owned by the caller.

    Raises
    ------
    ValueError
        For a malformed gait (swing starts outside [0, 1), durations outside (0, 1), gaits
        with different legs), a bad number of characters, phases or rates.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import init_gaits
    >>> from footfall.scenarios import default_gait, load_creature
    >>> gait = default_gait(load_creature("spider"))   # eight legs, every swing 0.35 of a cycle
    >>> state = init_gaits(gait, 3, rng_phase_offsets=0)
    >>> bool(((state.needle >= 0) & (state.needle < 1)).all()), np.unique(state.needle).size  # seeded phases
    (True, 3)
    >>> init_gaits(gait, 1, duty_factor=0.75).disk_duration[0, :3]   # swings scaled to 1 - 0.75
    array([0.25, 0.25, 0.25])

    Two legs given as arrays, swings [0, 0.4) and [0.5, 0.9), and the needles' phases:

    >>> state = init_gaits(([0.0, 0.5], [0.4, 0.4]), 2, [0.0, 0.7])
    >>> state.active()                              # whose sector holds the needle
    array([[ True, False],
           [False,  True]])
    """
    if isinstance(n_characters, bool) or not isinstance(n_characters, (int, np.integer)) or n_characters < 1:
        raise ValueError(f"n_characters: expected an integer >= 1, got {n_characters!r}")
    n = int(n_characters)
    start, duration, names = _gait_rows(gaits, n, "gaits")
    if rng_phase_offsets is None:
        needle = np.zeros(n)
    elif isinstance(rng_phase_offsets, np.random.Generator):
        needle = rng_phase_offsets.random(n)
    elif isinstance(rng_phase_offsets, (int, np.integer)) and not isinstance(rng_phase_offsets, bool):
        needle = np.random.default_rng(int(rng_phase_offsets)).random(n)
    else:
        needle = _per_character(rng_phase_offsets, n, "rng_phase_offsets")
        if np.any(needle >= 1.0):
            raise ValueError("rng_phase_offsets: phases must be in [0, 1)")
    rate = _per_character(transition_rate, n, "transition_rate")
    duty = np.full(n, np.nan)
    dest_duration = duration.copy()
    if duty_factor is not None:
        duty = _per_character(duty_factor, n, "duty_factor", positive=True)
        if np.any(duty >= 1.0):
            raise ValueError("duty_factor: expected duty factors in (0, 1)")
        dest_duration = scaled_swing_durations(duration, duty)
    return GaitManagerState(
        needle=np.ascontiguousarray(needle, dtype=np.float64),
        disk_start=start.copy(), disk_duration=dest_duration.copy(),
        dest_start=start.copy(), dest_duration=dest_duration,
        transition_rate=rate, gait_start=start, gait_duration=duration, duty_factor=duty, leg_names=names)


def set_destination(state: GaitManagerState, character_indices: Any, gait: Any, *,
                    transition_rate: Any = None) -> None:
    """Start a transition of the given characters (indices, a boolean mask or a slice) toward ``gait``.

    ``gait`` is a ``scenarios.Gait``, a list of gaits (one per selected
    character) or a ``(start, duration)`` pair of (L,) or (k, L) arrays. The
    destination durations are scaled to each character's current duty factor
    (the last :func:`set_speed`). The disks in use move toward it in later
    :func:`advance` calls, only while their foot is in stance.

    Parameters
    ----------
    state : GaitManagerState
        Changed in place.
    character_indices : array_like of int or bool, or slice
        The characters to move: indices, a (C,) boolean mask or a slice.
    gait : scenarios.Gait, list of scenarios.Gait, or (array_like, array_like)
        The destination gait, with the characters' legs (same number, same names).
    transition_rate : float or array_like, optional
        New cycles of phase per second for these characters (number or (k,)); default: keep
        theirs.

    Returns
    -------
    None

    Raises
    ------
    ValueError
        For bad indices, or a gait whose legs differ from the characters'.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import advance, init_gaits, set_destination
    >>> state = init_gaits(([0.0, 0.5], [0.4, 0.4]), 1)   # two legs in antiphase
    >>> set_destination(state, [0], ([0.0, 0.25], [0.4, 0.4]))
    >>> state.transitioning(), state.dest_start
    (array([ True]), array([[0.  , 0.25]]))

    At the default rate, 0.5 cycles of phase per second, the second disk's start moves from
    0.5 to 0.25 in half a second while both feet stand:

    >>> for _ in range(10):
    ...     _ = advance(state, 1.0, 0.1, np.ones((1, 2), bool))
    >>> state.disk_start, state.transitioning()
    (array([[0.  , 0.25]]), array([False]))
    """
    rows = _indices(state, character_indices)
    if rows.size == 0:
        return
    start, duration, names = _gait_rows(gait, rows.size, "gait")
    if start.shape[1] != state.n_legs:
        raise ValueError(f"gait: has {start.shape[1]} legs, the characters have {state.n_legs}")
    if names is not None and state.leg_names is not None and names != state.leg_names:
        raise ValueError(f"gait: legs {names} differ from the characters' legs {state.leg_names}")
    if transition_rate is not None:
        rate = _per_character(transition_rate, rows.size, "transition_rate")
    state.gait_start[rows] = start
    state.gait_duration[rows] = duration
    state.dest_start[rows] = start
    duty = state.duty_factor[rows]
    scaled = ~np.isnan(duty)
    dest = duration.copy()
    if np.any(scaled):
        dest[scaled] = scaled_swing_durations(duration[scaled], duty[scaled])
    state.dest_duration[rows] = dest
    if transition_rate is not None:
        state.transition_rate[rows] = rate


def set_speed(state: GaitManagerState, timing: GaitTiming, speed: Any, height: Any,
              duty_ceiling: Any = None) -> np.ndarray:
    """Stride frequencies (C,) at ``speed`` (m/s, number or (C,)) for hip height ``height`` (m, number or
    (C,)); records the duty factors and rescales every destination disk's duration to them
    (:mod:`planner._timing`). The disks in use follow at the transition rate while in stance.

    ``duty_ceiling`` ((C,), > 0; default none): the largest duty factor the legs carry
    at this speed (:func:`planner._workspace.duty_ceiling`); the duty factor never falls below the
    timing's ``duty_min`` for it.

    Parameters
    ----------
    state : GaitManagerState
        Changed in place: ``duty_factor``, ``dest_start`` and ``dest_duration``.
    timing : GaitTiming
        The timing model (stride law, duty law).
    speed : float or array_like
        m/s, >= 0, number or (C,).
    height : float or array_like
        h of the Froude number (the hip height, :func:`hip_height`), m, > 0, number or (C,).
    duty_ceiling : array_like, shape (C,), optional
        The largest duty factor each character's legs carry, > 0 (``inf``: no ceiling); default
        none. A single number is refused.

    Returns
    -------
    ndarray, shape (C,)
        Stride frequencies, Hz: the rate for :func:`advance`.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import GaitTiming, hip_height, init_gaits, set_speed
    >>> from footfall.scenarios import default_gait, load_creature
    >>> spider = load_creature("spider")
    >>> state = init_gaits(default_gait(spider), 2)
    >>> frequency = set_speed(state, GaitTiming(), [0.1, 0.3], hip_height(spider))
    >>> np.round(frequency, 3)                      # Hz: the faster character steps more often
    array([1.515, 2.351])
    >>> np.round(state.duty_factor, 3)              # ... and stands a smaller share of each cycle
    array([0.7  , 0.659])
    >>> np.round(state.dest_duration[:, 0], 3)      # the swings it heads for: 1 - duty factor here
    array([0.3  , 0.341])
    >>> state.transitioning()                       # the disks in use follow while their feet stand
    array([ True,  True])
    """
    n = state.n_characters
    v = _per_character(speed, n, "speed")
    h = _per_character(height, n, "height", positive=True)
    ceiling = np.full(n, np.inf) if duty_ceiling is None else np.asarray(duty_ceiling, dtype=np.float64)
    if ceiling.shape != (n,) or np.any(np.isnan(ceiling)) or np.any(ceiling <= 0.0):
        raise ValueError(f"duty_ceiling: expected numbers > 0 of shape ({n},)")
    frequency = np.empty(n)
    retime_gaits(timing.to_array(), v, h, np.ascontiguousarray(ceiling), state.gait_duration, frequency,
                 state.duty_factor, state.dest_duration)
    state.dest_start[...] = state.gait_start
    return frequency


def advance(state: GaitManagerState, frequency: Any, dt: float, in_stance: Any,
            out: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Step every character's needle by ``frequency * dt`` and its stance feet's disks toward the destination.

    Returns ``(enter_swing, swing_fraction)``, both (C, L): the stance feet
    whose sector the needle entered in this step (they must start a swing),
    and each foot's progress through its sector (0 outside its sector).

    Parameters
    ----------
    state : GaitManagerState
        Changed in place: the needles, and the disks of stance feet during a transition.
    frequency : float or array_like
        Hz, number or (C,), >= 0 (e.g. from :func:`set_speed`).
    dt : float
        Seconds, >= 0.
    in_stance : array_like of bool, shape (C, L)
        The feet on the ground at the start of the step.
    out : (ndarray, ndarray), optional
        A bool and a float64 array of shape (C, L) to write the results into.

    Returns
    -------
    enter_swing : ndarray of bool, shape (C, L)
        The stance feet whose sector the needle entered in this step.
    swing_fraction : ndarray, shape (C, L)
        Each foot's progress through its sector, in [0, 1) (0 outside its sector).

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import advance, init_gaits
    >>> state = init_gaits(([0.0, 0.5], [0.4, 0.4]), 1)   # swings [0, 0.4) and [0.5, 0.9)
    >>> advance(state, 1.0, 0.1, np.ones((1, 2), bool))    # 1 Hz for 0.1 s: foot 0 lifts
    (array([[ True, False]]), array([[0.25, 0.  ]]))
    >>> advance(state, 1.0, 0.5, [[False, True]])          # the needle reaches 0.6: foot 1 lifts
    (array([[False,  True]]), array([[0.  , 0.25]]))
    >>> state.needle
    array([0.6])
    """
    n, legs = state.disk_start.shape
    f = _per_character(frequency, n, "frequency")
    dt = float(dt)
    if not np.isfinite(dt) or dt < 0.0:
        raise ValueError(f"dt: expected a finite number >= 0, got {dt!r}")
    stance = np.asarray(in_stance)
    if stance.shape != (n, legs):
        raise ValueError(f"in_stance: expected shape ({n}, {legs}), got {stance.shape}")
    stance = np.ascontiguousarray(stance, dtype=np.bool_)
    if out is None:
        enter = np.zeros((n, legs), dtype=np.bool_)
        fraction = np.zeros((n, legs))
    else:
        enter, fraction = out
        if enter.shape != (n, legs) or enter.dtype != np.bool_ or fraction.shape != (n, legs) \
                or fraction.dtype != np.float64:
            raise ValueError(f"out: expected a bool and a float64 array of shape ({n}, {legs})")
    advance_gaits(state.needle, f, dt, state.disk_start, state.disk_duration, state.dest_start, state.dest_duration,
                  state.transition_rate, stance, enter, fraction)
    return enter, fraction
