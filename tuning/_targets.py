"""Biomechanics targets as data: ``tuning/data/targets.toml``, with their citations.

The file holds dimensionless targets (lengths over the leg length h, speeds as
Froude numbers) under ``[defaults.<quantity>]`` and per-creature overrides under
``[creatures.<name>.<quantity>]`` (an override replaces the whole entry). Each
entry names its ``source``, a key of ``[sources]``. :func:`load_targets` checks
everything and refuses a malformed file with an
:class:`~footfall._errors.InputError` naming the file and the field.

Quantities (fields; all numbers):

* ``stride_length``: ``coefficient``, ``exponent``, ``relative_tolerance`` --
  lambda / h = coefficient * Fr^exponent;
* ``duty_factor``: ``low``, ``high``, ``froude_max`` -- DF in [low, high] for Fr < froude_max;
* ``duty_factor_slope``: ``max_slope`` -- d DF / d(v / sqrt(g h)) <= max_slope;
* ``swing_jerk``: ``minimum``, ``maximum`` -- normalised jerk J* of a swing;
* ``curvature_energy``: ``maximum`` -- curvature energy of a swing path;
* ``clearance``: ``minimum`` -- horizontal path margin / h.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from footfall._errors import InputError

TARGETS_FILE = Path(__file__).resolve().parent / "data" / "targets.toml"
TARGETS_SCHEMA_VERSION = 1
GRAVITY = 9.81

# Per quantity: field -> (least, greatest, least is exclusive); None = unbounded.
_FIELDS: dict[str, dict[str, tuple[float | None, float | None, bool]]] = {
    "stride_length": {"coefficient": (0.0, None, True), "exponent": (0.0, 1.0, False),
                      "relative_tolerance": (0.0, None, True)},
    "duty_factor": {"low": (0.0, 1.0, True), "high": (0.0, 1.0, True), "froude_max": (0.0, None, True)},
    "duty_factor_slope": {"max_slope": (None, None, False)},
    "swing_jerk": {"minimum": (0.0, None, True), "maximum": (0.0, None, True)},
    "curvature_energy": {"maximum": (0.0, None, True)},
    "clearance": {"minimum": (0.0, None, True)},
}
QUANTITIES: tuple[str, ...] = tuple(_FIELDS)


@dataclass(frozen=True)
class Target:
    """One target: its dimensionless numbers and where they come from."""

    quantity: str
    values: dict[str, float]
    source: str  # key of [sources]
    citation: str


@dataclass(frozen=True)
class CreatureTargets:
    """Every quantity's target for one creature, with its leg length h (m)."""

    creature: str
    leg_length_m: float
    targets: dict[str, Target]

    def __getitem__(self, quantity: str) -> Target:
        return self.targets[quantity]

    def stride_length_m(self, speed):
        """Target stride lambda (m) at speed v (m/s): coefficient * h * Fr^exponent."""
        t = self.targets["stride_length"].values
        h = self.leg_length_m
        return t["coefficient"] * h * (speed * speed / (GRAVITY * h)) ** t["exponent"]

    @property
    def clearance_min_m(self) -> float:
        return self.targets["clearance"].values["minimum"] * self.leg_length_m

    @property
    def citations(self) -> dict[str, str]:
        return {q: t.citation for q, t in self.targets.items()}


def _number(file: str, field: str, value, bounds) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(file, field, f"expected a finite number, got {value!r}")
    least, greatest, exclusive = bounds
    value = float(value)
    if least is not None and (value <= least if exclusive else value < least):
        raise InputError(file, field, f"expected a number {'>' if exclusive else '>='} {least}, got {value!r}")
    if greatest is not None and value >= greatest:
        raise InputError(file, field, f"expected a number < {greatest}, got {value!r}")
    return value


def _target(file: str, where: str, quantity: str, entry, sources: dict[str, str]) -> Target:
    if not isinstance(entry, dict):
        raise InputError(file, where, "expected a table")
    fields = _FIELDS[quantity]
    for key in entry:
        if key not in fields and key != "source":
            raise InputError(file, f"{where}.{key}", f"unknown field; {quantity} has {', '.join(fields)}, source")
    values = {}
    for key, bounds in fields.items():
        if key not in entry:
            raise InputError(file, f"{where}.{key}", "missing field")
        values[key] = _number(file, f"{where}.{key}", entry[key], bounds)
    source = entry.get("source")
    if not isinstance(source, str):
        raise InputError(file, f"{where}.source", "missing field (a key of [sources])")
    if source not in sources:
        raise InputError(file, f"{where}.source", f"unknown source {source!r}; [sources] has {', '.join(sources)}")
    if quantity == "duty_factor" and values["low"] >= values["high"]:
        raise InputError(file, f"{where}.high", f"expected high > low = {values['low']}, got {values['high']}")
    if quantity == "swing_jerk" and values["minimum"] > values["maximum"]:
        raise InputError(file, f"{where}.maximum",
                         f"expected maximum >= minimum = {values['minimum']}, got {values['maximum']}")
    return Target(quantity, values, source, sources[source])


def load_targets(path: str | Path = TARGETS_FILE, creatures=None) -> dict[str, CreatureTargets]:
    """Targets per creature (default: every built-in creature), with every quantity."""
    from planner._timing import hip_height
    from scenarios import builtin_creature_names, load_creature

    file = str(path)
    try:
        data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as error:
        raise InputError(file, "targets", f"cannot read file: {error.strerror or error}") from None
    except UnicodeDecodeError:
        raise InputError(file, "targets", "not UTF-8 text") from None
    except tomllib.TOMLDecodeError as error:
        raise InputError(file, "targets", f"invalid TOML: {str(error).splitlines()[0]}") from None
    for key in data:
        if key not in ("schema_version", "sources", "defaults", "creatures"):
            raise InputError(file, key, "unknown field; expected schema_version, sources, defaults, creatures")
    if data.get("schema_version") != TARGETS_SCHEMA_VERSION:
        raise InputError(file, "schema_version", f"expected {TARGETS_SCHEMA_VERSION}, got {data.get('schema_version')!r}")
    sources = data.get("sources")
    if not isinstance(sources, dict) or not sources:
        raise InputError(file, "sources", "expected a table of citations")
    for key, text in sources.items():
        if not isinstance(text, str) or not text.strip():
            raise InputError(file, f"sources.{key}", "expected a citation (non-empty text)")
    defaults = data.get("defaults")
    if not isinstance(defaults, dict):
        raise InputError(file, "defaults", "expected a table")
    base = {}
    for quantity in QUANTITIES:
        if quantity not in defaults:
            raise InputError(file, f"defaults.{quantity}", "missing field")
        base[quantity] = _target(file, f"defaults.{quantity}", quantity, defaults[quantity], sources)
    for key in defaults:
        if key not in _FIELDS:
            raise InputError(file, f"defaults.{key}", f"unknown quantity; expected one of {', '.join(QUANTITIES)}")
    overrides = data.get("creatures", {})
    if not isinstance(overrides, dict):
        raise InputError(file, "creatures", "expected a table")
    known = builtin_creature_names()
    per_creature: dict[str, dict[str, Target]] = {}
    for name, table in overrides.items():
        if name not in known:
            raise InputError(file, f"creatures.{name}", f"unknown creature; built-ins are: {', '.join(known)}")
        if not isinstance(table, dict):
            raise InputError(file, f"creatures.{name}", "expected a table")
        per_creature[name] = {}
        for quantity, entry in table.items():
            if quantity not in _FIELDS:
                raise InputError(file, f"creatures.{name}.{quantity}",
                                 f"unknown quantity; expected one of {', '.join(QUANTITIES)}")
            per_creature[name][quantity] = _target(file, f"creatures.{name}.{quantity}", quantity, entry, sources)
    out = {}
    for name in (known if creatures is None else creatures):
        creature = load_creature(name)
        targets = dict(base)
        targets.update(per_creature.get(creature.name, {}))
        out[creature.name] = CreatureTargets(creature.name, hip_height(creature), targets)
    return out
