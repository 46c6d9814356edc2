"""Gaits: the paper's "Gait/Tempo" parameter (§3.1) and the gait manager's disks (§3.3, Fig. 8).

A gait gives each leg of a creature one **swing sector** on its gait disk:
``start`` is the phase (a fraction of a cycle, in [0, 1)) at which the foot
lifts off, ``duration`` the fraction of the cycle it spends in the air, in
(0, 1). The sector is the half-open arc [start, start + duration) (mod 1);
the rest of the disk is stance. The gait manager's needle turns once per
stride and a foot enters its swing when the needle enters its sector.

Gait file (``scenarios/data/gaits/*.toml`` for the built-ins)::

    name = "ant-tripod"          # optional; defaults to the file name without .toml
    description = "free text"    # optional

    [swing]                      # one entry per leg of the creature, by leg name
    L1 = { start = 0.0, duration = 0.5 }
    R2 = { start = 0.0, duration = 0.5 }
    # ... every leg exactly once; the order does not matter

A gait names the legs it applies to; :func:`load_gait` matches them against
the creature's leg names and returns the arrays in the creature's leg order.

**Impossible gaits are refused** (:func:`check_support`): with L legs, at
every phase of the cycle at least :func:`required_stance_feet` (L) feet must
be in stance: 2 for L >= 3 (a support line, never a single foot or none),
1 for L <= 2 (never every foot in the air). The check is exact: the number
of feet in stance is piecewise constant between the sectors' starts and
finishes, so it is evaluated once on every such piece (pieces shorter than
:data:`SUPPORT_EPSILON` of a cycle are floating-point rounding, e.g. a sector
finishing at 2/3 and the next starting at 0.6666666666666666).

Built-in gaits (see each file for its biology): ``spider-alternating-tetrapod``,
``spider-metachronal-wave``, ``ant-tripod``, ``ant-tetrapod``,
``quadruped-walk``, ``quadruped-trot``, ``quadruped-pace``, ``robot5-wave``.
:func:`default_gait_name` gives each built-in creature's default gait.

**Any creature with 3 legs or more has a default gait** (:func:`default_gait`): the
built-in one for a built-in creature, otherwise one generated from its morphology
(:func:`generate_gait`). The gait name ``"default"`` (``--gait default``,
``[crowd] gait = "default"``) means that gait.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import permutations
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import Field

from footfall._errors import InputError
from footfall.scenarios import _schema as schema
from footfall.scenarios._arrays import UNATTRIBUTED, frozen_array, invalid, readonly
from footfall.scenarios._creatures import Creature
from footfall.scenarios._files import _read_toml, _resolve, _split_field, file_creature, load_creature

GAITS_DIR = Path(__file__).parent / "data" / "gaits"
"""Built-in gaits (``*.toml``)."""

SUPPORT_EPSILON = 1e-12
"""Pieces of the cycle shorter than this (fraction of a cycle) are rounding, not phases."""

DEFAULT_GAITS: dict[str, str] = {
    "spider": "spider-metachronal-wave",
    "ant": "ant-tripod",
    "quadruped": "quadruped-walk",
    "robot5": "robot5-wave",
}
"""Default gait of each built-in creature."""

DEFAULT_GAIT = "default"
"""Gait name meaning "the creature's default gait" (:func:`default_gait`)."""

GENERATED_DUTY_FACTOR = 0.72
"""Authored duty factor of a generated gait: the timing model's duty factor at rest
(``planner._timing.GaitTiming.duty_at_rest``); the run rescales it with speed like any gait's."""

CENTRELINE_FRACTION = 0.25
"""A hip whose |lateral| is below this fraction of the largest |lateral| is on the centreline."""

_RING_SEARCH_MAX = 7
"""Rings of at most this many legs try every order of phases; larger ones use the best rotation."""


# --------------------------------------------------------------------------- support rule


def required_stance_feet(n_legs: int) -> int:
    """Least number of feet that must be in stance at every phase: 2 if ``n_legs`` >= 3, else 1.

    Parameters
    ----------
    n_legs : int
        Number of legs L of the creature.

    Returns
    -------
    int

    Examples
    --------
    >>> from footfall.scenarios import required_stance_feet
    >>> required_stance_feet(6), required_stance_feet(2), required_stance_feet(1)
    (2, 1, 1)
    """
    return 2 if n_legs >= 3 else 1


def stance_profile(swing_start, swing_duration) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact number of feet in stance over the cycle, as pieces.

    Returns ``(begin, end, stance)``: the cycle [0, 1) cut at every sector start
    and finish into pieces [begin_k, end_k) (the last piece may wrap: its
    ``end`` is then > 1), and the number of feet in stance on each, which is
    constant on a piece. Pieces shorter than :data:`SUPPORT_EPSILON` are left out.
    """
    start = np.asarray(swing_start, dtype=np.float64).reshape(-1)
    duration = np.asarray(swing_duration, dtype=np.float64).reshape(-1)
    cuts = np.unique(np.concatenate([start, np.mod(start + duration, 1.0)]) % 1.0)
    begin = cuts
    end = np.append(cuts[1:], cuts[0] + 1.0)
    keep = end - begin > SUPPORT_EPSILON
    begin, end = begin[keep], end[keep]
    middle = np.mod(0.5 * (begin + end), 1.0)
    swinging = np.mod(middle[:, None] - start[None, :], 1.0) < duration[None, :]
    stance = start.size - swinging.sum(axis=1)
    return begin, end, stance


def min_stance_feet(swing_start, swing_duration) -> tuple[int, float]:
    """(least number of feet in stance over the cycle, a phase where that happens).

    Exact, as the module doc describes: the count is evaluated once on every piece of the
    cycle between the sectors' starts and finishes.

    Parameters
    ----------
    swing_start : array_like
        (L,) phase in [0, 1) at which each foot's swing begins.
    swing_duration : array_like
        (L,) swing fraction of the cycle of each foot, in (0, 1).

    Returns
    -------
    least : int
        Least number of feet in stance at any phase.
    phase : float
        The middle of the first piece of the cycle (in [0, 1)) with that few feet in stance.

    Examples
    --------
    A trot: diagonal pairs swing for 0.45 of a cycle, half a cycle apart. Two feet are
    down while a pair swings, from 0 to 0.45 (middle 0.225):

    >>> from footfall.scenarios import min_stance_feet
    >>> min_stance_feet([0.0, 0.5, 0.5, 0.0], [0.45, 0.45, 0.45, 0.45])
    (2, 0.225)

    Three legs, half a cycle each, a quarter apart: from 0.25 to 0.5 two of them swing.

    >>> min_stance_feet([0.0, 0.25, 0.5], [0.5, 0.5, 0.5])
    (1, 0.375)
    """
    begin, end, stance = stance_profile(swing_start, swing_duration)
    k = int(np.argmin(stance))
    return int(stance[k]), float(np.mod(0.5 * (begin[k] + end[k]), 1.0))


def check_support(leg_names, swing_start, swing_duration) -> None:
    """Refuse (``InputError`` on field ``swing``) a gait that breaks the support rule (see the module doc)."""
    names = tuple(leg_names)
    start = np.asarray(swing_start, dtype=np.float64)
    duration = np.asarray(swing_duration, dtype=np.float64)
    need = required_stance_feet(len(names))
    least, phase = min_stance_feet(start, duration)
    if least >= need:
        return
    swinging = np.mod(phase - start, 1.0) < duration
    down = [n for n, s in zip(names, swinging) if not s]
    if least == 0:
        reason = f"impossible gait: every foot swings at once around phase {phase:.4g}"
    else:
        reason = (f"impossible gait: only {least} foot in stance ({', '.join(down)}) around phase "
                  f"{phase:.4g}; a {len(names)}-legged gait needs at least {need} at every phase")
    raise invalid("swing", reason)


# --------------------------------------------------------------------------- the value


@dataclass(frozen=True, eq=False)
class Gait:
    """A gait: one swing sector per leg, in a creature's leg order.

    Attributes
    ----------
    name : str
        Gait name.
    leg_names : tuple of str
        (L,) the legs, in the creature's order.
    swing_start : (L,) ndarray
        Read-only float64, phase in [0, 1) at which each foot's swing begins.
    swing_duration : (L,) ndarray
        Read-only float64, swing fraction of the cycle, in (0, 1).
    description : str
        Free text.

    Construction checks ranges and the support rule (module doc) and raises
    :class:`InputError` naming ``swing_start[i]``, ``swing_duration[i]`` or ``swing``.

    Examples
    --------
    Gaits are usually loaded (:func:`load_gait`); one can also be written out:

    >>> from footfall import InputError
    >>> from footfall.scenarios import Gait
    >>> trot = Gait("trot", ("LF", "RF", "LH", "RH"), swing_start=[0.0, 0.5, 0.5, 0.0],
    ...             swing_duration=[0.4, 0.4, 0.4, 0.4])
    >>> trot.n_legs, round(trot.duty_factor, 2)
    (4, 0.6)
    >>> trot.swing_finish.tolist()
    [0.4, 0.9, 0.9, 0.4]
    >>> trot.phase_offsets("RF").tolist()    # relative to RF's swing start
    [0.5, 0.0, 0.0, 0.5]

    An impossible gait is refused:

    >>> try:
    ...     Gait("hop", ("A", "B", "C"), swing_start=[0.0, 0.0, 0.0], swing_duration=[0.5, 0.5, 0.5])
    ... except InputError as error:
    ...     print(error)
    argument: swing: impossible gait: every foot swings at once around phase 0.25
    """

    name: str
    leg_names: tuple[str, ...]
    swing_start: np.ndarray
    swing_duration: np.ndarray
    description: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise invalid("name", "must be a non-empty string")
        if not isinstance(self.description, str):
            raise invalid("description", "must be a string")
        names = tuple(self.leg_names)
        if not names:
            raise invalid("leg_names", "a gait needs at least one leg")
        for i, leg in enumerate(names):
            if not isinstance(leg, str) or not leg.strip():
                raise invalid(f"leg_names[{i}]", "must be a non-empty string")
            if leg in names[:i]:
                raise invalid(f"leg_names[{i}]", f"duplicate leg name {leg!r}")
        start = frozen_array(self.swing_start, "swing_start", (len(names),))
        duration = frozen_array(self.swing_duration, "swing_duration", (len(names),))
        for i in range(len(names)):
            if not 0.0 <= start[i] < 1.0:
                raise invalid(f"swing_start[{i}]", f"must be in [0, 1), got {start[i]:g}")
            if not 0.0 < duration[i] < 1.0:
                raise invalid(f"swing_duration[{i}]", f"must be in (0, 1), got {duration[i]:g}")
        check_support(names, start, duration)
        object.__setattr__(self, "leg_names", names)
        object.__setattr__(self, "swing_start", start)
        object.__setattr__(self, "swing_duration", duration)

    @property
    def n_legs(self) -> int:
        """Number of legs L."""
        return len(self.leg_names)

    @property
    def duty_factor(self) -> float:
        """Mean stance fraction of a cycle, 1 - mean(swing_duration)."""
        return 1.0 - float(self.swing_duration.mean())

    @property
    def swing_finish(self) -> np.ndarray:
        """(L,) phase in [0, 1) at which each foot's swing sector ends."""
        return readonly(np.mod(self.swing_start + self.swing_duration, 1.0))

    def phase_offsets(self, reference: str | int = 0) -> np.ndarray:
        """(L,) swing start of every leg relative to leg ``reference`` (name or index), in [0, 1)."""
        index = self.leg_names.index(reference) if isinstance(reference, str) else int(reference)
        return readonly(np.mod(self.swing_start - self.swing_start[index], 1.0))


# --------------------------------------------------------------------------- files


class _SwingFile(schema._Model):
    start: Annotated[float, Field(ge=0.0, lt=1.0)]
    duration: Annotated[float, Field(gt=0.0, lt=1.0)]


class _GaitFile(schema._Model):
    name: schema.Text | None = None
    description: str = ""
    swing: dict[str, _SwingFile]


def builtin_gait_names(creature: Creature | str | None = None) -> tuple[str, ...]:
    """Names of the built-in gaits, sorted; with ``creature``, only those whose legs match it.

    Parameters
    ----------
    creature : Creature or str, optional
        A :class:`Creature`, or a name or file for :func:`load_creature`. None (default): every built-in gait.

    Returns
    -------
    tuple of str
        Names for :func:`load_gait` (the stems of ``scenarios/data/gaits/*.toml``).

    Examples
    --------
    >>> from footfall.scenarios import builtin_gait_names
    >>> len(builtin_gait_names())
    8
    >>> builtin_gait_names("quadruped")
    ('quadruped-pace', 'quadruped-trot', 'quadruped-walk')
    """
    names = tuple(sorted(path.stem for path in GAITS_DIR.glob("*.toml")))
    if creature is None:
        return names
    creature = _as_creature(creature)
    fitting = []
    for name in names:
        try:
            load_gait(name, creature)
        except InputError:
            continue
        fitting.append(name)
    return tuple(fitting)


def default_gait_name(creature_name: Creature | str) -> str:
    """The name of a creature's default gait, for :func:`load_gait`.

    A built-in creature (``spider`` -> ``spider-metachronal-wave``, ...) gets its built-in
    default. A :class:`Creature`, or the name of a creature this process loaded from a file,
    whose legs the built-in default does not fit gets :data:`DEFAULT_GAIT` (``"default"``):
    :func:`load_gait` then generates its gait (:func:`generate_gait`). Raises
    :class:`InputError` for the name of a creature that is neither.

    Parameters
    ----------
    creature_name : Creature or str
        A creature, or the name of a built-in creature or of one loaded from a file.

    Returns
    -------
    str
        A built-in gait name, or ``"default"``.

    Examples
    --------
    >>> from pathlib import Path
    >>> import footfall.scenarios
    >>> from footfall.scenarios import default_gait_name, load_creature
    >>> default_gait_name("spider")
    'spider-metachronal-wave'
    >>> default_gait_name(load_creature("ant"))
    'ant-tripod'
    >>> default_gait_name(load_creature(Path(footfall.scenarios.__file__).parent / "examples" / "heptapod.toml"))
    'default'
    """
    if isinstance(creature_name, Creature):
        creature = creature_name
    else:
        creature = file_creature(str(creature_name))
        if creature is None:
            name = str(creature_name)
            if name not in DEFAULT_GAITS:
                raise InputError(name, "gait", f"no default gait for creature {name!r}; defaults exist for "
                                 f"{', '.join(sorted(DEFAULT_GAITS))} and for creatures loaded from a file; "
                                 "name a gait file")
            return DEFAULT_GAITS[name]
    name = DEFAULT_GAITS.get(creature.name)
    if name is not None and _fits(name, creature):
        return name
    return DEFAULT_GAIT


def _fits(gait_name: str, creature: Creature) -> bool:
    try:
        load_gait(gait_name, creature)
    except InputError:
        return False
    return True


def default_gait(creature: Creature) -> Gait:
    """The gait ``creature`` walks with when none is named.

    The built-in default (:data:`DEFAULT_GAITS`) for a built-in creature whose legs it
    names; otherwise the gait generated from the morphology (:func:`generate_gait`).
    Deterministic: the same creature always gets the same gait.

    Parameters
    ----------
    creature : Creature
        Any creature; one with fewer than 3 legs and no fitting built-in gait is refused
        (:func:`generate_gait`).

    Returns
    -------
    Gait
        In the creature's leg order; it keeps the support rule (:func:`check_support`).

    Examples
    --------
    >>> from pathlib import Path
    >>> import footfall.scenarios
    >>> from footfall.scenarios import default_gait, load_creature
    >>> default_gait(load_creature("ant")).name
    'ant-tripod'
    >>> heptapod = load_creature(Path(footfall.scenarios.__file__).parent / "examples" / "heptapod.toml")
    >>> gait = default_gait(heptapod)
    >>> gait.name, gait.n_legs, round(gait.duty_factor, 2)
    ('heptapod-generated', 7, 0.72)
    """
    name = DEFAULT_GAITS.get(creature.name)
    if name is not None:
        try:
            return load_gait(name, creature)
        except InputError:  # a user creature borrowing a built-in name, with other legs
            pass
    return generate_gait(creature)


# --------------------------------------------------------------------------- generated gaits


def _evenly_around(points: np.ndarray) -> bool:
    """True for hips on a circle about their centre at evenly spread angles (a round body, whatever
    its orientation): radii within 10 % of their mean and every angular gap within 10 % of 2 pi / L."""
    n = points.shape[0]
    if n < 3:
        return False
    rel = points - points.mean(axis=0)
    radius = np.hypot(rel[:, 0], rel[:, 1])
    if radius.mean() <= 0.0 or np.any(np.abs(radius - radius.mean()) > 0.1 * radius.mean()):
        return False
    angles = np.sort(np.mod(np.arctan2(rel[:, 1], rel[:, 0]), 2.0 * np.pi))
    gaps = np.diff(np.append(angles, angles[0] + 2.0 * np.pi))
    return bool(np.all(np.abs(gaps - 2.0 * np.pi / n) <= 0.1 * 2.0 * np.pi / n))


def leg_sides(creature: Creature) -> tuple[tuple[int, ...], tuple[int, ...]] | None:
    """(left legs, right legs), each ordered back to front, or None for a round body.

    Hips evenly spread around a circle are a round body, whatever the body's orientation.
    Otherwise a creature is bilateral when no hip is on the centreline (|lateral| below
    :data:`CENTRELINE_FRACTION` of the largest |lateral|), each side has at least 2 legs
    and the two sides differ by at most one leg. A side is ordered by the hips' forward
    coordinate (ties by the rest feet's, then by leg index).
    """
    hips = np.asarray(creature.hips, dtype=np.float64)
    if _evenly_around(hips[:, [0, 2]]):
        return None
    lateral = hips[:, 2]
    widest = float(np.max(np.abs(lateral)))
    if widest <= 0.0 or np.any(np.abs(lateral) < CENTRELINE_FRACTION * widest):
        return None
    left = [i for i in range(creature.n_legs) if lateral[i] > 0.0]
    right = [i for i in range(creature.n_legs) if lateral[i] < 0.0]
    if min(len(left), len(right)) < 2 or abs(len(left) - len(right)) > 1:
        return None

    def back_to_front(legs: list[int]) -> tuple[int, ...]:
        return tuple(sorted(legs, key=lambda i: (hips[i, 0], creature.rest_feet[i, 0], i)))

    return back_to_front(left), back_to_front(right)


def wave_latency(n_side: int) -> float:
    """Phase (fraction of a cycle) between a leg's swing start and that of the leg behind it on its side.

    ``1/4`` for 2 legs a side (the lateral-sequence walk), ``1/n`` for 3 or 4 (one wave runs
    down the side per cycle), ``ceil(n/4)/n`` for more (several waves a side, as in millipedes,
    so that neighbours stay at least about a quarter of a cycle apart).
    """
    if n_side <= 2:
        return 0.25
    return math.ceil(n_side / 4) / n_side


def ring_order(creature: Creature) -> tuple[int, ...]:
    """Legs in order around the body, counter-clockwise seen from above (forward, then left, ...).

    The angle of a leg is that of its hip in the body's (forward, lateral) plane, or of its
    rest foot when the hip is at the centre; the leg nearest straight ahead comes first.
    """
    hips = np.asarray(creature.hips, dtype=np.float64)[:, [0, 2]]
    rest = np.asarray(creature.rest_feet, dtype=np.float64)
    where = np.where(np.linalg.norm(hips, axis=1, keepdims=True) > 1e-9, hips, rest)
    angle = np.mod(np.arctan2(where[:, 1], where[:, 0]), 2.0 * np.pi)
    angle = np.where(angle > 2.0 * np.pi - 1e-9, 0.0, angle)
    return tuple(int(i) for i in np.lexsort((np.arange(creature.n_legs), angle)))


def _ring_slots(n: int) -> tuple[int, ...]:
    """Slots (phase = slot / n) for the legs of a ring of ``n``: ring neighbours as far apart in phase as can be.

    Maximises the least circular slot distance between ring neighbours (the ring closes):
    every order for small rings (the first leg fixed at slot 0, ties: the lexicographically
    first), else the best rotation ``slot_i = i k mod n`` with ``k`` coprime to ``n``.
    """

    def least_gap(slots) -> int:
        gaps = [(slots[(i + 1) % n] - slots[i]) % n for i in range(n)]
        return min(min(g, n - g) for g in gaps)

    if n <= _RING_SEARCH_MAX:
        best = max(((0,) + rest for rest in permutations(range(1, n))), key=least_gap)
        return tuple(best)
    ks = [k for k in range(1, n // 2 + 1) if math.gcd(k, n) == 1]
    k = max(ks)
    return tuple((i * k) % n for i in range(n))


def generate_gait(creature: Creature) -> Gait:
    """A gait for any creature with at least 3 legs, from its morphology alone.

    * **Bilateral body** (:func:`leg_sides`): on each side a metachronal wave runs back to
      front (each leg lifts :func:`wave_latency` of a cycle after the leg behind it, as in
      Wilson 1967's insects and spiders); the right side's back leg lifts half a cycle after
      the left's, so opposite legs alternate.
    * **Round body** (no clear sides: a hip on the centreline, or sides too unequal, e.g. a
      five-legged radial robot): the swings are spread evenly over the cycle, one every
      ``1/L``, in an order around the body (:func:`ring_order`, :func:`_ring_slots`) that
      keeps ring neighbours as far apart in phase as possible.

    Every leg swings once a cycle for the same duration: ``1 - GENERATED_DUTY_FACTOR``,
    shortened (never below a twentieth of a cycle) until ring or side neighbours are never
    in the air together and the support rule holds (:func:`check_support`).

    Parameters
    ----------
    creature : Creature
        A creature with at least 3 legs.

    Returns
    -------
    Gait
        Named ``"NAME-generated"``, in the creature's leg order; its description says which
        rule made it and its duty factor.

    Raises
    ------
    InputError
        On field ``gait`` for a creature with fewer than 3 legs.

    Examples
    --------
    The quadruped's legs are LF, RF, LH, RH: each side's wave runs back to front a quarter
    cycle apart (LH, then LF), the right side half a cycle after the left (the lateral-sequence walk):

    >>> from footfall.scenarios import generate_gait, load_creature
    >>> gait = generate_gait(load_creature("quadruped"))
    >>> gait.name, gait.swing_start.tolist()
    ('quadruped-generated', [0.25, 0.75, 0.0, 0.5])
    >>> gait.swing_duration.tolist(), round(gait.duty_factor, 2)
    ([0.25, 0.25, 0.25, 0.25], 0.75)
    """
    n = creature.n_legs
    if n < 3:
        raise InputError(creature.name, "gait", f"cannot generate a gait for {n} legs (needs 3 or more); "
                         "name a gait file")
    start = np.zeros(n)
    sides = leg_sides(creature)
    neighbour_gap = 1.0
    if sides is not None:
        for side, offset in zip(sides, (0.0, 0.5)):
            latency = wave_latency(len(side))
            for k, leg in enumerate(side):
                start[leg] = (offset + k * latency) % 1.0
            neighbour_gap = min(neighbour_gap, latency)
        kind = (f"metachronal wave back to front on each side ({len(sides[0])} left, {len(sides[1])} right), "
                "sides half a cycle apart")
    else:
        ring = ring_order(creature)
        slots = _ring_slots(n)
        for leg, slot in zip(ring, slots):
            start[leg] = slot / n
        gaps = [(slots[(i + 1) % n] - slots[i]) % n for i in range(n)]
        neighbour_gap = min(min(g, n - g) for g in gaps) / n
        kind = "swings spread evenly over the cycle, neighbours around the body far apart in phase"
    start = np.round(start, 12) % 1.0
    duration = min(1.0 - GENERATED_DUTY_FACTOR, neighbour_gap)
    while True:
        try:
            check_support(creature.leg_names, start, np.full(n, duration))
            break
        except InputError:
            if duration <= 0.05:
                raise
            duration = max(0.05, 0.9 * duration)
    return Gait(
        name=f"{creature.name}-generated",
        leg_names=creature.leg_names,
        swing_start=start,
        swing_duration=np.full(n, duration),
        description=f"Generated from the morphology: {kind}; DF {1.0 - duration:.2f}.",
    )
def _as_creature(creature: Creature | str | Path) -> Creature:
    return creature if isinstance(creature, Creature) else load_creature(creature)


def load_gait(name_or_path: str | Path, creature: Creature | str | Path) -> Gait:
    """A built-in gait by name (see :func:`builtin_gait_names`) or a gait ``.toml`` file, for ``creature``.

    ``creature`` is a :class:`Creature` or a creature name / file for
    :func:`scenarios.load_creature`. The returned arrays follow the creature's
    leg order. Raises :class:`InputError` naming the file and the field
    (``swing.L4.duration``, ``swing.LF``, ``swing``, ...) on any problem:
    bad TOML, unknown key, NaN, start outside [0, 1), duration outside (0, 1),
    unknown or missing leg, a different number of legs than the creature, or
    an impossible gait (support rule, module doc).

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A built-in gait name, ``"default"`` (:func:`default_gait`), or the path of a gait file.
        A string is looked up among the built-ins first; a ``Path`` is always a file.
    creature : Creature, str or pathlib.Path
        The creature the gait is for.

    Returns
    -------
    Gait
        Named after the file's ``name``, else the file name without ``.toml``.

    Raises
    ------
    footfall.InputError
        One line ``FILE: FIELD: REASON``; FILE is the path as given, or ``builtin:NAME``.

    Examples
    --------
    >>> from footfall import InputError
    >>> from footfall.scenarios import load_gait
    >>> trot = load_gait("quadruped-trot", "quadruped")
    >>> trot.leg_names, trot.swing_start.tolist(), round(trot.duty_factor, 2)
    (('LF', 'RF', 'LH', 'RH'), [0.0, 0.5, 0.5, 0.0], 0.55)
    >>> load_gait("default", "ant").name
    'ant-tripod'
    >>> try:
    ...     load_gait("ant-tripod", "quadruped")
    ... except InputError as error:
    ...     print(error)  # doctest: +ELLIPSIS
    builtin:ant-tripod: swing: the gait gives 6 legs (L1, R2, L3, R1, L2, R3) but creature 'quadruped' has 4 legs ...
    """
    creature = _as_creature(creature)
    if isinstance(name_or_path, str) and name_or_path == DEFAULT_GAIT:
        return default_gait(creature)
    path, file = _resolve(name_or_path, GAITS_DIR, builtin_gait_names(), "gait")
    model: _GaitFile = schema.validate(_GaitFile, _read_toml(path, file, "gait"), file)
    given = list(model.swing)
    wanted = creature.leg_names
    listing = f"creature {creature.name!r} has {len(wanted)} legs ({', '.join(wanted)})"
    unknown = [leg for leg in given if leg not in wanted]
    missing = [leg for leg in wanted if leg not in model.swing]
    if len(given) != len(wanted) and not unknown:
        raise InputError(file, f"swing.{missing[0]}",
                         f"missing leg; {listing}, the gait gives {len(given)} (missing {', '.join(missing)})")
    if len(given) != len(wanted):
        raise InputError(file, "swing", f"the gait gives {len(given)} legs ({', '.join(given)}) but {listing}")
    if unknown:
        raise InputError(file, f"swing.{unknown[0]}", f"unknown leg {unknown[0]!r}; {listing}")
    try:
        return Gait(
            name=model.name or path.stem,
            leg_names=wanted,
            swing_start=[model.swing[leg].start for leg in wanted],
            swing_duration=[model.swing[leg].duration for leg in wanted],
            description=model.description,
        )
    except InputError as error:
        if error.file != UNATTRIBUTED:
            raise
        raise InputError(file, _file_field(error.field, wanted), error.reason) from None


def _file_field(field: str, legs: tuple[str, ...]) -> str:
    """Gait dataclass field (``swing_start[3]``) -> gait file field (``swing.L4.start``)."""
    name, index = _split_field(field)
    keys = {"swing_start": "start", "swing_duration": "duration"}
    if name in keys and index:
        return f"swing.{legs[index[0]]}.{keys[name]}"
    return field
