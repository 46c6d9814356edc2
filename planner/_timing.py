"""The gait timing model: stride frequency and duty factor as functions of speed.

Notation (``/work/shared/biomechanics.md``): v = speed (m/s), h = hip height,
i.e. leg length (m), g = :data:`GRAVITY`, Fr = v^2 / (g h) the Froude number.

* **Stride length** (dynamic similarity, Alexander 1976; Alexander & Jayes 1983)::

      lambda(v) = stride_coefficient * h * Fr^stride_exponent        (defaults 2.3, 0.3)

  so lambda grows as v^0.6 and the stride frequency v / lambda as v^0.4.
* **Stride frequency**: f(v) = max(v / lambda(v), min_frequency_hz) for v > 0,
  and f(0) = 0. v / lambda tends to 0 with v (as v^(1 - 2 stride_exponent)),
  so at crawling speeds the feet keep stepping at ``min_frequency_hz`` with
  strides shorter than lambda (v / f); at v = 0 exactly the needle stops
  (no division by zero: lambda(0) = 0 is never divided by).
* **Duty factor** falls linearly with speed (Spagna, Valdivia & Mohan 2011 for
  spiders; Ting et al. 1994 for insects), in units of sqrt(Fr) = v / sqrt(g h)::

      DF(v) = clip(duty_at_rest - duty_slope * v / sqrt(g h), duty_min, duty_max)

  Defaults: a spider (h = 0.12 m) at 0.3 m/s gets DF = 0.66; DF reaches
  ``duty_min`` = 0.5 at Fr = 1 (the walk / run boundary) and stays there.
* **Speed and the gait disks** (:func:`scaled_swing_durations`): a gait keeps
  its pattern of swing starts and its *relative* swing durations, and its mean
  swing fraction follows the duty factor::

      duration_i(v) = clip((1 - DF(v)) * duration_i / mean(duration), SWING_MIN, SWING_MAX)

  The support rule of ``scenarios._gaits`` is checked on the gait as
  authored, not on the scaled disks. With ``duty_min`` >= 0.5 every built-in
  gait keeps it (tested); a lower ``duty_min`` can make e.g. a trot's
  diagonal pairs overlap so that every foot swings at once.

The tuning code fits these parameters: :meth:`GaitTiming.to_array` /
:meth:`GaitTiming.from_array` give a flat float64 vector in
:data:`TIMING_FIELDS` order, which the numba kernels
(:mod:`planner._kernels_gait`) read through the ``T_*`` index constants.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from numba.extending import register_jitable

from footfall.planner._flat import FlatParameters

GRAVITY = 9.81
"""g, m/s^2."""


# --------------------------------------------------------------------------- the laws, once
# Each formula of the model is written once, here: plain arithmetic that runs on floats and numpy
# arrays as written, is compiled into the numba kernels that call it (planner._kernels_gait), and is
# traced by JAX in the tuning proxies (tuning._proxies). Each caller adds only what its backend does
# differently: the cases (v = 0), the clips, and the square root of g h.


@register_jitable
def froude_law(v, h):
    """Fr = v^2 / (g h).

    Parameters
    ----------
    v : float or ndarray
        Speed (m/s).
    h : float or ndarray
        Hip height, i.e. leg length (m), > 0.

    Returns
    -------
    float or ndarray
        The Froude number (dimensionless); 1 at ``v = sqrt(g h)``, the walk / run boundary.

    Examples
    --------
    >>> import math
    >>> from footfall.planner import GRAVITY, froude_law
    >>> round(froude_law(math.sqrt(GRAVITY * 0.12), 0.12), 9)
    1.0
    >>> round(froude_law(0.3, 0.12), 4)   # a spider at 0.3 m/s: 0.09 / (9.81 * 0.12)
    0.0765
    """
    return v * v / (GRAVITY * h)


@register_jitable
def stride_law(coefficient, exponent, v, h):
    """lambda = coefficient * h * Fr^exponent (m), for v > 0 (at v = 0 there is no stride).

    The law alone: :func:`stride_length` adds the case ``v = 0`` and the checks.

    Parameters
    ----------
    coefficient : float
        lambda / h at Fr = 1 (``GaitTiming.stride_coefficient``), > 0.
    exponent : float
        Exponent of the Froude number (``GaitTiming.stride_exponent``).
    v : float or ndarray
        Speed (m/s), > 0.
    h : float or ndarray
        Hip height (m), > 0.

    Returns
    -------
    float or ndarray
        Stride length (m).

    Examples
    --------
    >>> import math
    >>> from footfall.planner import GRAVITY, stride_law
    >>> round(stride_law(2.3, 0.3, math.sqrt(GRAVITY * 0.12), 0.12), 6)   # Fr = 1: 2.3 * 0.12
    0.276
    """
    return coefficient * h * froude_law(v, h) ** exponent


@register_jitable
def duty_law(at_rest, slope, v, root_gh):
    """The duty factor before its clip: at_rest - slope * v / sqrt(g h), ``root_gh`` = sqrt(g h).

    The law alone: :func:`duty_factor` adds the clip to ``[duty_min, duty_max]`` and the checks.

    Parameters
    ----------
    at_rest : float
        Duty factor extrapolated to ``v = 0`` (``GaitTiming.duty_at_rest``).
    slope : float
        Fall of the duty factor per unit of ``v / sqrt(g h)`` (``GaitTiming.duty_slope``).
    v : float or ndarray
        Speed (m/s).
    root_gh : float or ndarray
        sqrt(g h) (m/s), h the hip height.

    Returns
    -------
    float or ndarray
        The unclipped duty factor (dimensionless).

    Examples
    --------
    >>> from footfall.planner import duty_law
    >>> round(duty_law(0.72, 0.22, 1.0, 1.0), 6)   # v = sqrt(g h), i.e. Fr = 1
    0.5
    >>> round(duty_law(0.72, 0.22, 2.0, 1.0), 6)   # Fr = 4: below any sensible duty_min, to be clipped
    0.28
    """
    return at_rest - slope * v / root_gh


@register_jitable
def stance_lead(stance):
    """How far a new swing's preferred footprint lies ahead of its hip at touchdown: half the stance
    to come, so that the stance sweeps the foot's window evenly about its rest point.

    One law for two users: the runtime places a footprint ``stance_lead(sweep)`` metres ahead of the
    touchdown pose (``planner._crowd.stage_plan``, ``sweep`` the distance the body covers during the
    stance), and the tuning's proxy takes the lead time ``t_swing + stance_lead(t_stance)`` seconds
    (``footfall.tuning.preferred_lead_time``: the steady-state limit, where distance = speed x time).

    Parameters
    ----------
    stance : float or ndarray
        The stance to come: a distance (m) or a duration (s).

    Returns
    -------
    float or ndarray
        Half of it, in the same unit.

    Examples
    --------
    >>> from footfall.planner import stance_lead
    >>> stance_lead(0.12)   # a 12 cm stance sweep: the footprint leads the touchdown hip by 6 cm
    0.06
    """
    return 0.5 * stance
SWING_MIN = 0.05
"""Least swing fraction of a speed-scaled disk."""
SWING_MAX = 0.95
"""Largest swing fraction of a speed-scaled disk."""


def _p(doc: str, default: float, *, unit: str = "-"):
    return field(default=default, metadata={"doc": doc, "unit": unit})


@dataclass(frozen=True)
class GaitTiming(FlatParameters):
    """Stride length, stride frequency and duty factor as functions of speed (module doc).

    Every value is stored as a float; a non-number, a non-finite value or one outside its
    range raises ValueError naming the field. :meth:`to_array` / :meth:`from_array` give the
    flat float64 vector the tuning fits and the numba kernels read.

    Attributes
    ----------
    stride_coefficient : float
        lambda / h at Fr = 1 in ``lambda = stride_coefficient * h * Fr^stride_exponent``, > 0
        (default 2.3).
    stride_exponent : float
        Exponent of the Froude number in the stride length, in [0, 0.5) (default 0.3).
    min_frequency_hz : float
        Least stride frequency (Hz) for ``v > 0``, > 0 (default 0.5).
    duty_at_rest : float
        Duty factor extrapolated to ``v = 0``, in (0, 1) (default 0.72).
    duty_slope : float
        Fall of the duty factor per unit of ``v / sqrt(g h)``, >= 0 (default 0.22).
    duty_min, duty_max : float
        Clip of the duty factor, ``0 < duty_min <= duty_max < 1`` (defaults 0.5, 0.85).

    Examples
    --------
    >>> from footfall.planner import GaitTiming, duty_factor
    >>> timing = GaitTiming(duty_min=0.6)
    >>> timing.to_array().tolist()
    [2.3, 0.3, 0.5, 0.72, 0.22, 0.6, 0.85]
    >>> GaitTiming.from_array(timing.to_array()) == timing
    True
    >>> duty_factor(timing, 5.0, 0.12)   # fast: clipped at duty_min
    0.6
    >>> GaitTiming(stride_exponent=0.5)
    Traceback (most recent call last):
        ...
    ValueError: GaitTiming.stride_exponent: must be in [0, 0.5), got 0.5
    """

    stride_coefficient: float = _p("lambda / h at Fr = 1: lambda = stride_coefficient * h * Fr^stride_exponent (> 0)", 2.3)
    stride_exponent: float = _p("exponent of the Froude number in the stride length, in [0, 0.5) so that f rises with v", 0.3)
    min_frequency_hz: float = _p("least stride frequency for v > 0 (at v = 0 the needle stops), > 0", 0.5, unit="Hz")
    duty_at_rest: float = _p("duty factor extrapolated to v = 0, in (0, 1)", 0.72)
    duty_slope: float = _p("fall of the duty factor per unit of v / sqrt(g h), >= 0", 0.22)
    duty_min: float = _p("least duty factor (fast speeds), in (0, duty_max]", 0.5)
    duty_max: float = _p("largest duty factor (slow speeds), in [duty_min, 1)", 0.85)

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise ValueError(f"GaitTiming.{f.name}: expected a number, got {type(value).__name__}")
            value = float(value)
            object.__setattr__(self, f.name, value)
            if not math.isfinite(value):
                raise ValueError(f"GaitTiming.{f.name}: must be finite, got {value!r}")
        if self.stride_coefficient <= 0.0:
            raise ValueError(f"GaitTiming.stride_coefficient: must be > 0, got {self.stride_coefficient!r}")
        if not 0.0 <= self.stride_exponent < 0.5:
            raise ValueError(f"GaitTiming.stride_exponent: must be in [0, 0.5), got {self.stride_exponent!r}")
        if self.min_frequency_hz <= 0.0:
            raise ValueError(f"GaitTiming.min_frequency_hz: must be > 0, got {self.min_frequency_hz!r}")
        if not 0.0 < self.duty_at_rest < 1.0:
            raise ValueError(f"GaitTiming.duty_at_rest: must be in (0, 1), got {self.duty_at_rest!r}")
        if self.duty_slope < 0.0:
            raise ValueError(f"GaitTiming.duty_slope: must be >= 0, got {self.duty_slope!r}")
        if not 0.0 < self.duty_min < 1.0:
            raise ValueError(f"GaitTiming.duty_min: must be in (0, 1), got {self.duty_min!r}")
        if not self.duty_min <= self.duty_max < 1.0:
            raise ValueError(f"GaitTiming.duty_max: must be in [duty_min, 1), got {self.duty_max!r}")


TIMING_FIELDS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(GaitTiming))
# Index constants into GaitTiming.to_array(), used by planner._kernels_gait.
(T_STRIDE_COEFFICIENT, T_STRIDE_EXPONENT, T_MIN_FREQUENCY, T_DUTY_AT_REST, T_DUTY_SLOPE, T_DUTY_MIN,
 T_DUTY_MAX) = range(len(TIMING_FIELDS))
assert TIMING_FIELDS[T_DUTY_MAX] == "duty_max" and TIMING_FIELDS[T_MIN_FREQUENCY] == "min_frequency_hz"


# --------------------------------------------------------------------------- vectorised model


def _speed_height(v, h) -> tuple[np.ndarray, np.ndarray, bool]:
    speed = np.asarray(v, dtype=np.float64)
    height = np.asarray(h, dtype=np.float64)
    if not np.all(np.isfinite(speed)) or np.any(speed < 0.0):
        raise ValueError("speed: expected finite numbers >= 0 (m/s)")
    if not np.all(np.isfinite(height)) or np.any(height <= 0.0):
        raise ValueError("height: expected finite numbers > 0 (m)")
    speed, height = np.broadcast_arrays(speed, height)
    return speed, height, speed.ndim == 0


def _out(values: np.ndarray, scalar: bool):
    return float(values) if scalar else values


def froude_number(v, h):
    """Fr = v^2 / (g h)."""
    speed, height, scalar = _speed_height(v, h)
    return _out(froude_law(speed, height), scalar)


def stride_length(timing: GaitTiming, v, h):
    """lambda = stride_coefficient * h * Fr^stride_exponent (m); 0 at v = 0. Broadcasts ``v`` and ``h``.

    Parameters
    ----------
    timing : GaitTiming
        The timing model.
    v : float or array_like
        Speed (m/s), finite and >= 0.
    h : float or array_like
        Hip height (m), finite and > 0 (e.g. :func:`hip_height`).

    Returns
    -------
    float or ndarray
        Stride length (m): a float when ``v`` and ``h`` are scalars, else their broadcast shape.

    Raises
    ------
    ValueError
        A speed < 0 or a height <= 0, or a value not finite.

    Examples
    --------
    >>> import math
    >>> from footfall.planner import GRAVITY, GaitTiming, stride_length
    >>> timing = GaitTiming()
    >>> round(stride_length(timing, math.sqrt(GRAVITY * 0.12), 0.12), 6)   # Fr = 1: 2.3 * 0.12
    0.276
    >>> stride_length(timing, [0.0, 0.3], 0.12).round(4).tolist()          # standing still: no stride
    [0.0, 0.1276]
    """
    speed, height, scalar = _speed_height(v, h)
    return _out(_stride_length(timing, speed, height), scalar)


def stride_frequency(timing: GaitTiming, v, h):
    """f = max(v / lambda, min_frequency_hz) where lambda > 0, else 0 (Hz): 0 at v = 0, and at the
    speeds so small that Fr^stride_exponent underflows to 0 (a body braking geometrically reached
    2e-177 m/s; v / 0 stopped the run). Broadcasts ``v`` and ``h``.

    Parameters
    ----------
    timing : GaitTiming
        The timing model.
    v : float or array_like
        Speed (m/s), finite and >= 0.
    h : float or array_like
        Hip height (m), finite and > 0.

    Returns
    -------
    float or ndarray
        Stride frequency (Hz): a float when ``v`` and ``h`` are scalars, else their broadcast shape.

    Raises
    ------
    ValueError
        A speed < 0 or a height <= 0, or a value not finite.

    Examples
    --------
    >>> import math
    >>> from footfall.planner import GRAVITY, GaitTiming, stride_frequency
    >>> timing = GaitTiming()
    >>> stride_frequency(timing, 0.0, 0.12), stride_frequency(timing, 0.001, 0.12)   # stopped; crawling
    (0.0, 0.5)
    >>> v = math.sqrt(GRAVITY * 0.12)                                                 # Fr = 1
    >>> round(stride_frequency(timing, v, 0.12), 4), round(v / (2.3 * 0.12), 4)
    (3.9311, 3.9311)
    """
    speed, height, scalar = _speed_height(v, h)
    return _out(_stride_frequency(timing, speed, height), scalar)


def _stride_length(timing: GaitTiming, speed: np.ndarray, height) -> np.ndarray:
    """:func:`stride_length` of speeds already checked (the runtime's per-frame calls skip the checks)."""
    with np.errstate(divide="ignore"):
        length = stride_law(timing.stride_coefficient, timing.stride_exponent, speed, height)
    # Fr^0 = 1 even at Fr = 0; a creature standing still has no stride.
    return np.where(speed > 0.0, length, 0.0)


def _stride_frequency(timing: GaitTiming, speed: np.ndarray, height) -> np.ndarray:
    """:func:`stride_frequency` of speeds already checked."""
    length = _stride_length(timing, speed, height)
    moving = length > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        natural = np.where(moving, speed / np.where(moving, length, 1.0), 0.0)
    return np.where(moving, np.maximum(natural, timing.min_frequency_hz), 0.0)


def duty_factor(timing: GaitTiming, v, h):
    """DF = clip(duty_at_rest - duty_slope * v / sqrt(g h), duty_min, duty_max). Broadcasts ``v`` and ``h``.

    Parameters
    ----------
    timing : GaitTiming
        The timing model.
    v : float or array_like
        Speed (m/s), finite and >= 0.
    h : float or array_like
        Hip height (m), finite and > 0.

    Returns
    -------
    float or ndarray
        Duty factor, the fraction of a stride a foot stands: a float when ``v`` and ``h`` are
        scalars, else their broadcast shape.

    Raises
    ------
    ValueError
        A speed < 0 or a height <= 0, or a value not finite.

    Examples
    --------
    >>> from footfall.planner import GaitTiming, duty_factor
    >>> timing = GaitTiming()
    >>> round(duty_factor(timing, 0.3, 0.12), 2)   # a spider at 0.3 m/s: 0.72 - 0.22 * 0.3 / 1.085
    0.66
    >>> duty_factor(timing, [0.0, 5.0], 0.12).tolist()   # at rest; fast, clipped at duty_min
    [0.72, 0.5]
    """
    speed, height, scalar = _speed_height(v, h)
    raw = duty_law(timing.duty_at_rest, timing.duty_slope, speed, np.sqrt(GRAVITY * height))
    return _out(np.clip(raw, timing.duty_min, timing.duty_max), scalar)


def scaled_swing_durations(swing_duration, duty) -> np.ndarray:
    """Swing fractions of a gait at duty factor ``duty``: (1 - duty) * d_i / mean(d), clipped to [0.05, 0.95].

    ``swing_duration`` is (..., L) (the gait as authored), ``duty`` broadcasts
    against its leading axes. The pattern of starts is not touched.
    """
    durations = np.asarray(swing_duration, dtype=np.float64)
    duty = np.asarray(duty, dtype=np.float64)
    if durations.ndim < 1 or not np.all(np.isfinite(durations)) or np.any(durations <= 0.0):
        raise ValueError("swing_duration: expected an array (..., L) of numbers > 0")
    if not np.all(np.isfinite(duty)) or np.any((duty <= 0.0) | (duty >= 1.0)):
        raise ValueError("duty: expected duty factors in (0, 1)")
    total = durations[..., 0].copy()
    for j in range(1, durations.shape[-1]):  # summed in leg order, as the kernel does (bitwise equal results)
        total += durations[..., j]
    mean = (total / durations.shape[-1])[..., None]
    return np.clip((1.0 - duty)[..., None] * durations / mean, SWING_MIN, SWING_MAX)


def hip_height(creature) -> float:
    """h of a ``scenarios.Creature``: mean hip height above flat ground (m) when standing.

    Parameters
    ----------
    creature : Creature
        A :class:`footfall.scenarios.Creature`.

    Returns
    -------
    float
        ``standing_height`` plus the mean height of the hips in the body frame (m).

    Examples
    --------
    >>> from footfall.planner import hip_height
    >>> from footfall.scenarios import load_creature
    >>> hip_height(load_creature("spider"))      # hips at the pelvis' height, 0.12 m
    0.12
    >>> round(hip_height(load_creature("quadruped")), 3)
    0.42
    """
    return float(creature.standing_height + np.mean(np.asarray(creature.hips)[:, 1]))
