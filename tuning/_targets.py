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

A **user's targets file** (``footfall tune --targets FILE.toml``, :func:`load_tune_targets`) is
laid over these for the creature tuned. Every table is optional but ``schema_version``::

    schema_version = 1

    [sources]                    # citations that the entries below may name (optional)
    my_trackways = "Smith 2020: stride of Lycosa at a walk"

    [stride_length]              # the stride law lambda / h = coefficient Fr^exponent (species data)
    coefficient = 2.0
    exponent = 0.3
    relative_tolerance = 0.15
    source = "my_trackways"      # optional in a user file: the file itself is the source

    [duty_factor]                # the duty-factor band at walking speeds
    low = 0.6
    high = 0.8
    froude_max = 1.0

    [style]                      # how the creature should walk (each key optional)
    min_clearance_body_heights = 0.5   # swing paths keep this far (x body height h) from forbidden boxes
    curvature_p95_max = 0.02           # 95th percentile of the swing paths' curvature energy
    min_distance_ratio = 0.95          # distance walked / distance asked
    max_touchdown_slope_rad = 0.3      # mean slope under the touch-downs

Any quantity of the shipped file may be given the same way (it replaces the whole entry); a file
with a ``[defaults]`` table is read as a whole targets file instead (:func:`load_targets`). The
body height is the creature's hip height h standing (the leg length of the Froude number): the
style's clearance becomes the ``clearance`` target's minimum. Examples: ``tuning/data/styles/``.
"""

from __future__ import annotations

import dataclasses
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
STYLE_FIELDS: dict[str, tuple[float | None, float | None, bool]] = {
    "min_clearance_body_heights": (0.0, None, True),
    "curvature_p95_max": (0.0, None, True),
    "min_distance_ratio": (0.0, 1.5, True),
    "max_touchdown_slope_rad": (0.0, 1.5, True),
}
"""A style's keys (``[style]`` of a user's targets file) with their bounds."""


@dataclass(frozen=True)
class Target:
    """One target: its dimensionless numbers and where they come from.

    Attributes
    ----------
    quantity : str
        One of :data:`QUANTITIES`, e.g. ``"stride_length"``.
    values : dict of str to float
        The quantity's fields (module docstring), dimensionless.
    source : str
        The key of ``[sources]`` the numbers come from.
    citation : str
        That source's citation.

    Examples
    --------
    >>> from footfall.tuning import load_targets
    >>> target = load_targets(creatures=("spider",))["spider"]["duty_factor"]
    >>> target.quantity, target.values
    ('duty_factor', {'low': 0.6, 'high': 0.75, 'froude_max': 1.0})
    >>> target.source, target.citation
    ('spagna_2011', "Spagna, Valdivia & Mohan 2011, J Arachnol 39:84: spiders' duty factor ...")
    """

    quantity: str
    values: dict[str, float]
    source: str  # key of [sources]
    citation: str


@dataclass(frozen=True)
class CreatureTargets:
    """Every quantity's target for one creature, with its leg length h (m).

    ``targets[quantity]`` (or ``creature_targets[quantity]``) is that quantity's :class:`Target`;
    the methods turn the dimensionless numbers into metres with h.

    Attributes
    ----------
    creature : str
        The creature's name.
    leg_length_m : float
        h (m): the creature's hip height standing, the leg length of the Froude number.
    targets : dict of str to Target
        One target per quantity of :data:`QUANTITIES`.
    style : dict of str to float or None
        A user's style (``STYLE_FIELDS`` keys), or None when none is stated.
    file : str or None
        The targets file these came from (None: the shipped one).
    clearance_min_m : float
        The clearance target's minimum times h (m).
    stride_law : tuple of float
        (coefficient, exponent) of lambda / h = coefficient Fr^exponent.
    citations : dict of str to str
        The citation of each quantity's target.

    Examples
    --------
    At Fr = 1 (v = sqrt(g h)) the target stride is coefficient x h = 2.3 x 0.12 m:

    >>> from footfall.tuning import load_targets
    >>> spider = load_targets(creatures=("spider",))["spider"]
    >>> spider.creature, spider.leg_length_m, spider.stride_law
    ('spider', 0.12, (2.3, 0.3))
    >>> round(spider.stride_length_m((9.81 * 0.12) ** 0.5), 4)
    0.276
    >>> spider.stride_law_text(), round(spider.clearance_min_m, 4)        # clearance: 0.25 h
    ('2.3 h Fr^0.3', 0.03)
    >>> spider["swing_jerk"].values
    {'minimum': 720.0, 'maximum': 1000.0}
    >>> spider.timing().stride_coefficient       # a GaitTiming that commands the target law
    2.3
    """

    creature: str
    leg_length_m: float
    targets: dict[str, Target]
    style: dict | None = None  # STYLE_FIELDS -> number (None: no style stated)
    file: str | None = None  # the targets file these came from (None: the shipped one)

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
    def stride_law(self) -> tuple[float, float]:
        """(coefficient, exponent) of the stride law lambda / h = coefficient Fr^exponent."""
        t = self.targets["stride_length"].values
        return t["coefficient"], t["exponent"]

    def stride_law_text(self, html: bool = False) -> str:
        """The stride law as text, e.g. ``2.3 h Fr^0.3`` (the numbers of the targets file)."""
        c, e = self.stride_law
        return f"{c:g} h Fr<sup>{e:g}</sup>" if html else f"{c:g} h Fr^{e:g}"

    def timing(self, base=None):
        """``base`` (default ``GaitTiming()``) with the stride law of these targets: the runtime
        then commands the target law, and its per-stride error is measured against it."""
        import dataclasses

        from footfall.planner import GaitTiming

        c, e = self.stride_law
        return dataclasses.replace(base or GaitTiming(), stride_coefficient=c, stride_exponent=e)

    def to_json(self) -> dict:
        """The numbers (per quantity) and the style: what a preset's provenance records."""
        return {"file": self.file or "tuning/data/targets.toml", "leg_length_m": self.leg_length_m,
                **{q: dict(t.values, source=t.source) for q, t in self.targets.items()},
                "style": dict(self.style or {})}

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
    """Targets per creature (default: every built-in creature), with every quantity.

    The file's ``[defaults]`` apply to every creature; a ``[creatures.<name>.<quantity>]`` entry
    replaces that quantity's whole entry for that creature. Each creature's leg length h is its
    hip height standing (:func:`footfall.planner.hip_height`).

    Parameters
    ----------
    path : str or pathlib.Path, optional
        A whole targets file (default :data:`TARGETS_FILE`, the shipped one).
    creatures : sequence of str, optional
        Built-in creature names; None (default): every built-in creature.

    Returns
    -------
    dict of str to CreatureTargets
        Per creature name.

    Raises
    ------
    footfall.InputError
        If the file cannot be read or is malformed (naming the file and the field), or names an
        unknown creature.

    Examples
    --------
    >>> from footfall.tuning import load_targets
    >>> targets = load_targets()
    >>> sorted(targets)
    ['ant', 'quadruped', 'robot5', 'spider']
    >>> targets["ant"]["duty_factor"].values["low"], targets["robot5"]["duty_factor"].values["low"]   # override
    (0.45, 0.55)
    >>> load_targets("no_such_file.toml")
    Traceback (most recent call last):
        ...
    footfall._errors.InputError: no_such_file.toml: targets: cannot read file: No such file or directory
    """
    file = str(path)
    try:
        data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as error:
        raise InputError(file, "targets", f"cannot read file: {error.strerror or error}") from None
    except UnicodeDecodeError:
        raise InputError(file, "targets", "not UTF-8 text") from None
    except tomllib.TOMLDecodeError as error:
        raise InputError(file, "targets", f"invalid TOML: {str(error).splitlines()[0]}") from None
    return _whole_targets(data, file, creatures)


def _whole_targets(data: dict, file: str, creatures) -> dict[str, CreatureTargets]:
    """:func:`load_targets` of a whole targets file's parsed ``data`` (``file`` names it in errors)."""
    from footfall.planner import hip_height
    from footfall.scenarios import builtin_creature_names, load_creature

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


def _read(path) -> dict:
    file = str(path)
    try:
        return tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(file, "targets", "file not found") from None
    except IsADirectoryError:
        raise InputError(file, "targets", "is a directory, not a targets .toml") from None
    except OSError as error:
        raise InputError(file, "targets", f"cannot read file: {error.strerror or error}") from None
    except UnicodeDecodeError:
        raise InputError(file, "targets", "not UTF-8 text") from None
    except tomllib.TOMLDecodeError as error:
        raise InputError(file, "targets", f"invalid TOML: {str(error).splitlines()[0]}") from None


def load_tune_targets(path: str | Path | None, creature: str) -> CreatureTargets:
    """The targets of one creature for ``footfall tune``: the shipped ones (``path`` None), a whole
    targets file (one with ``[defaults]``), or a user's file laid over the shipped ones (module
    docstring). A malformed file is refused with an :class:`InputError` naming it and the field."""
    from footfall.scenarios import load_creature

    name = load_creature(creature).name
    if path is None:
        return load_targets(creatures=(creature,))[name]
    file = str(path)
    data = _read(path)
    if "defaults" in data:  # a whole targets file, already read
        return dataclasses.replace(_whole_targets(data, file, (creature,))[name], file=file)
    allowed = ("schema_version", "sources", "style", *QUANTITIES)
    for key in data:
        if key not in allowed:
            raise InputError(file, key, f"unknown field; expected {', '.join(allowed)}")
    if data.get("schema_version") != TARGETS_SCHEMA_VERSION:
        raise InputError(file, "schema_version", f"expected {TARGETS_SCHEMA_VERSION}, got {data.get('schema_version')!r}")
    base = load_targets(creatures=(creature,))[name]
    shipped_sources = tomllib.loads(TARGETS_FILE.read_text(encoding="utf-8"))["sources"]
    sources = data.get("sources", {})
    if not isinstance(sources, dict):
        raise InputError(file, "sources", "expected a table of citations")
    for key, text in sources.items():
        if not isinstance(text, str) or not text.strip():
            raise InputError(file, f"sources.{key}", "expected a citation (non-empty text)")
    sources = {**shipped_sources, **sources, "this_file": f"user targets file {file}"}
    targets = dict(base.targets)
    for quantity in QUANTITIES:
        if quantity in data:
            entry = data[quantity]
            if isinstance(entry, dict) and "source" not in entry:
                entry = dict(entry, source="this_file")
            targets[quantity] = _target(file, quantity, quantity, entry, sources)
    style = None
    if "style" in data:
        table = data["style"]
        if not isinstance(table, dict):
            raise InputError(file, "style", "expected a table")
        style = {}
        for key, value in table.items():
            if key not in STYLE_FIELDS:
                raise InputError(file, f"style.{key}", f"unknown field; a style has {', '.join(STYLE_FIELDS)}")
            style[key] = _number(file, f"style.{key}", value, STYLE_FIELDS[key])
        if "min_clearance_body_heights" in style:
            targets["clearance"] = Target("clearance", {"minimum": style["min_clearance_body_heights"]}, "this_file",
                                          sources["this_file"])
    return CreatureTargets(base.creature, base.leg_length_m, targets, style, file)
