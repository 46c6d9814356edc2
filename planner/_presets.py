"""Weight presets: versioned JSON files the runtime loads (no JAX needed to read one).

Schema (version 1)::

    {
      "schema_version": 1,
      "creature": "spider",
      "gait": "spider-metachronal-wave",          # optional
      "weights": {<every ScoringWeights field>: number},
      "timing": {<every GaitTiming field>: number},  # optional
      "provenance": {...}                           # optional, free form
    }

A preset for another creature, of another schema version, or with missing or
extra fields is refused with an :class:`~footfall._errors.InputError` naming the
file and the field.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path

from footfall._errors import InputError
from footfall.planner._weights import WEIGHT_FIELDS, ScoringWeights

PRESET_SCHEMA_VERSION = 1
_TOP_FIELDS = {"schema_version", "creature", "gait", "weights", "timing", "provenance"}


@dataclass(frozen=True)
class Preset:
    """A validated weight preset, as :func:`load_preset` reads it (schema in the module docstring).

    Attributes
    ----------
    creature : str
        Name of the creature the preset was made for.
    weights : ScoringWeights
        The scoring weights.
    timing : GaitTiming or None
        The gait timing, or None when the file has none.
    gait : str or None
        Name of the gait the preset was made with, or None.
    provenance : dict
        Free-form record of how the preset was made (empty when the file has none).

    Examples
    --------
    >>> from footfall.planner import GaitTiming, Preset, ScoringWeights
    >>> preset = Preset("spider", ScoringWeights(), GaitTiming(), None, {})
    >>> preset.creature, preset.timing.duty_min
    ('spider', 0.5)
    """

    creature: str
    weights: ScoringWeights
    timing: object | None  # planner._timing.GaitTiming
    gait: str | None
    provenance: dict


def _numbers(path, section: str, values, fields: tuple[str, ...]) -> dict[str, float]:
    if not isinstance(values, dict):
        raise InputError(path, section, "expected an object of named numbers")
    missing = [f for f in fields if f not in values]
    extra = [k for k in values if k not in fields]
    if missing:
        raise InputError(path, f"{section}.{missing[0]}", "missing field")
    if extra:
        raise InputError(path, f"{section}.{extra[0]}", "unknown field")
    out = {}
    for f in fields:
        v = values[f]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise InputError(path, f"{section}.{f}", f"expected a finite number, got {v!r}")
        out[f] = float(v)
    return out


def load_preset(path: str | Path, creature: str | None = None) -> Preset:
    """Read and validate a preset; with ``creature``, refuse a preset made for another one.

    Parameters
    ----------
    path : str or Path
        The preset's JSON file (schema in the module docstring); the shipped ones are in
        ``footfall.tuning.PRESETS_DIR``.
    creature : str, optional
        Name of the creature the preset must be for; None accepts any.

    Returns
    -------
    Preset
        The creature's name, the weights, the timing (None when the file has none), the gait's
        name (or None) and the provenance (``{}`` when the file has none).

    Raises
    ------
    InputError
        The file is missing, unreadable or not JSON, a field is missing, unknown or of the
        wrong type or value, the schema version is not :data:`PRESET_SCHEMA_VERSION`, or the
        preset is for another creature than ``creature``; the message names the file and the
        field.

    Examples
    --------
    >>> from footfall.planner import ScoringWeights, load_preset
    >>> from footfall.tuning import PRESETS_DIR
    >>> preset = load_preset(PRESETS_DIR / "spider.json", creature="spider")
    >>> preset.creature, preset.gait
    ('spider', 'spider-metachronal-wave')
    >>> isinstance(preset.weights, ScoringWeights)
    True
    >>> load_preset(PRESETS_DIR / "spider.json", creature="ant")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    footfall._errors.InputError: .../spider.json: creature: preset is for 'spider', not 'ant'
    """
    from footfall.planner._timing import GaitTiming

    path = Path(path)
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(path, "preset", "file not found") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(path, "preset", f"cannot read: {e}") from None
    except json.JSONDecodeError as e:
        raise InputError(path, "preset", f"not JSON: {e.msg} at line {e.lineno}") from None
    if not isinstance(data, dict):
        raise InputError(path, "preset", "expected a JSON object")
    for key in data:
        if key not in _TOP_FIELDS:
            raise InputError(path, key, "unknown field")
    version = data.get("schema_version")
    if version != PRESET_SCHEMA_VERSION:
        raise InputError(path, "schema_version", f"expected {PRESET_SCHEMA_VERSION}, got {version!r}")
    name = data.get("creature")
    if not isinstance(name, str) or not name:
        raise InputError(path, "creature", "missing or not a string")
    if creature is not None and name != creature:
        raise InputError(path, "creature", f"preset is for {name!r}, not {creature!r}")
    try:
        weights = ScoringWeights(**_numbers(path, "weights", data.get("weights"), WEIGHT_FIELDS))
    except ValueError as e:
        if isinstance(e, InputError):
            raise
        raise InputError(path, "weights", str(e)) from None
    timing = None
    if "timing" in data:
        fields = tuple(f.name for f in dataclasses.fields(GaitTiming))
        try:
            timing = GaitTiming(**_numbers(path, "timing", data["timing"], fields))
        except ValueError as e:
            if isinstance(e, InputError):
                raise
            raise InputError(path, "timing", str(e)) from None
    gait = data.get("gait")
    if gait is not None and not isinstance(gait, str):
        raise InputError(path, "gait", "expected a gait name")
    provenance = data.get("provenance", {})
    if not isinstance(provenance, dict):
        raise InputError(path, "provenance", "expected an object")
    return Preset(name, weights, timing, gait, provenance)


def preset_dict(creature: str, weights: ScoringWeights, timing=None, gait: str | None = None,
                provenance: dict | None = None) -> dict:
    """The JSON object of a preset (schema version :data:`PRESET_SCHEMA_VERSION`), ready for
    ``json.dumps``; :func:`load_preset` reads the file back.

    Parameters
    ----------
    creature : str
        Name of the creature the preset is for.
    weights : ScoringWeights
        The scoring weights (every field is written).
    timing : GaitTiming, optional
        The gait timing; None leaves the ``"timing"`` section out.
    gait : str, optional
        Name of the gait; None leaves the ``"gait"`` field out.
    provenance : dict, optional
        Free-form record of how the preset was made; None writes ``{}``.

    Returns
    -------
    dict
        ``schema_version``, ``creature``, ``weights`` (a dict of floats), and ``gait``,
        ``timing`` (a dict of floats) when given, and ``provenance``.

    Examples
    --------
    >>> import json, pathlib, tempfile
    >>> from footfall.planner import GaitTiming, ScoringWeights, load_preset, preset_dict
    >>> data = preset_dict("spider", ScoringWeights(footprint_distance=4.0), timing=GaitTiming())
    >>> sorted(data), data["weights"]["footprint_distance"]
    (['creature', 'provenance', 'schema_version', 'timing', 'weights'], 4.0)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = pathlib.Path(folder) / "mine.json"
    ...     _ = path.write_text(json.dumps(data))
    ...     preset = load_preset(path, creature="spider")
    >>> preset.weights == ScoringWeights(footprint_distance=4.0), preset.timing == GaitTiming()
    (True, True)
    """
    out = {"schema_version": PRESET_SCHEMA_VERSION, "creature": creature, "weights": weights.to_dict()}
    if gait is not None:
        out["gait"] = gait
    if timing is not None:
        out["timing"] = {f.name: float(getattr(timing, f.name)) for f in dataclasses.fields(timing)}
    out["provenance"] = provenance or {}
    return out
