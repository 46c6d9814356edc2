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
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import Field

from footfall._errors import InputError
from scenarios import _schema as schema
from scenarios._arrays import UNATTRIBUTED, frozen_array, invalid, readonly
from scenarios._creatures import Creature
from scenarios._files import _read_toml, _resolve, _split_field, load_creature

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


# --------------------------------------------------------------------------- support rule


def required_stance_feet(n_legs: int) -> int:
    """Least number of feet that must be in stance at every phase: 2 if ``n_legs`` >= 3, else 1."""
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
    """(least number of feet in stance over the cycle, a phase where that happens)."""
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
    name:
        Gait name.
    leg_names:
        (L,) the legs, in the creature's order.
    swing_start:
        (L,) read-only float64, phase in [0, 1) at which each foot's swing begins.
    swing_duration:
        (L,) read-only float64, swing fraction of the cycle, in (0, 1).
    description:
        Free text.

    Construction checks ranges and the support rule (module doc) and raises
    :class:`InputError` naming ``swing_start[i]``, ``swing_duration[i]`` or ``swing``.
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
    """Names of the built-in gaits, sorted; with ``creature``, only those whose legs match it."""
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
    """The default built-in gait of a built-in creature (``spider`` -> ``spider-metachronal-wave``, ...).

    Accepts a :class:`Creature` too (its name is used). Raises
    :class:`InputError` for a creature without a default.
    """
    name = creature_name.name if isinstance(creature_name, Creature) else str(creature_name)
    if name not in DEFAULT_GAITS:
        raise InputError(name, "gait", f"no default gait for creature {name!r}; defaults exist for "
                         f"{', '.join(sorted(DEFAULT_GAITS))}; name a gait file")
    return DEFAULT_GAITS[name]


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
    """
    creature = _as_creature(creature)
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
