"""Pydantic models of the scenario and creature TOML files, and their error messages.

The models check types, ranges and unknown keys only; cross-field rules
(e.g. "rest foot within reach") live in the loaders and the dataclasses.
Every model is strict: a number must be a TOML number (integers are
accepted where floats are expected), a string a TOML string, and NaN or inf
are refused.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from footfall._errors import InputError
from footfall.scenarios._arrays import one_line


class _Model(BaseModel):
    model_config = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False, frozen=True)


Number = float
Positive = Annotated[float, Field(gt=0.0)]
NonNegative = Annotated[float, Field(ge=0.0)]
Fraction = Annotated[float, Field(ge=0.0, le=1.0)]
Seed = Annotated[int, Field(ge=0)]
Vec2 = Annotated[list[float], Field(min_length=2, max_length=2)]
Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
PositiveVec2 = Annotated[list[Positive], Field(min_length=2, max_length=2)]
PositiveVec3 = Annotated[list[Positive], Field(min_length=3, max_length=3)]
Range = Annotated[list[Positive], Field(min_length=2, max_length=2)]
Text = Annotated[str, Field(min_length=1)]


# --------------------------------------------------------------------------- scenario files


class FlatTerrainFile(_Model):
    kind: Literal["flat"]
    size: PositiveVec2
    cell_size: Positive
    height: Number = 0.0


class HillsTerrainFile(_Model):
    kind: Literal["hills"]
    size: PositiveVec2
    cell_size: Positive
    amplitude: NonNegative
    wavelength: Positive
    octaves: Annotated[int, Field(ge=1, le=8)] = 3
    persistence: Annotated[float, Field(gt=0.0, le=1.0)] = 0.5
    seed: Seed | None = None


class StairsTerrainFile(_Model):
    kind: Literal["stairs"]
    size: PositiveVec2
    cell_size: Positive
    rise: Positive
    run: Positive
    steps: Annotated[int, Field(ge=1)]
    start: Number = 0.0
    direction: Number = 0.0
    landing: Positive | None = None


class HeightmapTerrainFile(_Model):
    kind: Literal["heightmap"]
    file: Text
    cell_size: Positive
    height_scale: Positive = 1.0
    height_offset: Number = 0.0


TerrainFile = Annotated[
    Union[FlatTerrainFile, HillsTerrainFile, StairsTerrainFile, HeightmapTerrainFile],
    Field(discriminator="kind"),
]


class StaticMotionFile(_Model):
    kind: Literal["static"]


class VelocityMotionFile(_Model):
    kind: Literal["velocity"]
    velocity: Vec2


class WaypointsMotionFile(_Model):
    kind: Literal["waypoints"]
    points: Annotated[list[Vec2], Field(min_length=1)]
    speed: Positive


MotionFile = Annotated[
    Union[StaticMotionFile, VelocityMotionFile, WaypointsMotionFile],
    Field(discriminator="kind"),
]


class ObstacleFile(_Model):
    centre: Vec2
    size: PositiveVec3
    yaw: Number = 0.0
    kind: Literal["forbidden", "safe"] = "forbidden"
    lift: Number = 0.0
    motion: MotionFile = StaticMotionFile(kind="static")


class RandomObstaclesFile(_Model):
    count: Annotated[int, Field(ge=0)]
    seed: Seed | None = None
    region_min: Vec2 | None = None
    region_max: Vec2 | None = None
    footprint_range: Range = [0.1, 0.6]
    height_range: Range = [0.1, 0.6]
    safe_height_range: Range | None = None
    forbidden_fraction: Fraction = 0.5
    moving_fraction: Fraction = 0.0
    velocity_fraction: Fraction = 0.5
    speed_range: Range = [0.1, 0.4]
    loop_radius_range: Range = [0.5, 1.5]
    keep_out: NonNegative = 0.5
    min_gap: NonNegative = 0.1


class CrowdFile(_Model):
    creature: Text
    count: Annotated[int, Field(ge=1)] = 1
    centre: Vec2 = [0.0, 0.0]
    radius: NonNegative = 0.0
    heading: Number = 0.0
    heading_mode: Literal["fixed", "random"] = "fixed"
    speed: Positive = 0.3
    goal: Vec2
    waypoints: list[Vec2] = []
    feet_spacing: Positive = 1.0
    gait: Text | None = None
    spawn_clear_s: NonNegative = 3.0


class CameraFile(_Model):
    position: Vec3
    target: Vec3
    fov: Annotated[float, Field(gt=0.0, lt=math.pi)] = 0.9


class ScenarioFile(_Model):
    name: Text | None = None
    description: str = ""
    seed: Seed = 0
    terrain: TerrainFile
    obstacles: list[ObstacleFile] = []
    obstacles_random: RandomObstaclesFile | None = None
    crowd: CrowdFile
    camera: CameraFile | None = None


# --------------------------------------------------------------------------- creature files


JointLimits = Annotated[list[Vec2], Field(min_length=1)]
Segments = Annotated[list[Positive], Field(min_length=1)]


class FootFile(_Model):
    length: Positive
    width: Positive


class LegDefaultsFile(_Model):
    segments: Segments | None = None
    joint_limits: JointLimits | None = None


class LegFile(_Model):
    name: Text
    hip: Vec3
    rest_foot: Vec2
    segments: Segments | None = None
    joint_limits: JointLimits | None = None


class CreatureFile(_Model):
    name: Text | None = None
    description: str = ""
    standing_height: Positive
    body_thickness: Positive
    body_box: PositiveVec2
    foot: FootFile
    leg_defaults: LegDefaultsFile = LegDefaultsFile()
    legs: list[LegFile] = []


# --------------------------------------------------------------------------- errors

# Fields holding a discriminated union: pydantic puts the tag into the error location.
_TAGGED_FIELDS = {"terrain", "motion"}

_REASONS = {
    "missing": "required",
    "extra_forbidden": "unknown key",
    "float_type": "expected a number",
    "float_parsing": "expected a number",
    "int_type": "expected an integer",
    "int_from_float": "expected an integer",
    "int_parsing": "expected an integer",
    "string_type": "expected a string",
    "bool_type": "expected true or false",
    "list_type": "expected an array",
    "model_type": "expected a table",
    "dict_type": "expected a table",
    "model_attributes_type": "expected a table",
    "finite_number": "must be a finite number (not nan or inf)",
    "string_too_short": "must not be empty",
    "union_tag_not_found": "required",
}


def _number(value: Any) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _reason(error: dict[str, Any]) -> str:
    kind = error["type"]
    ctx = error.get("ctx") or {}
    if kind in _REASONS:
        return _REASONS[kind]
    if kind == "greater_than":
        return f"must be > {_number(ctx['gt'])}"
    if kind == "greater_than_equal":
        return f"must be >= {_number(ctx['ge'])}"
    if kind == "less_than":
        return f"must be < {_number(ctx['lt'])}"
    if kind == "less_than_equal":
        return f"must be <= {_number(ctx['le'])}"
    if kind in ("too_short", "too_long"):
        low, high = ctx.get("min_length"), ctx.get("max_length")
        if kind == "too_short" and low is not None:
            return f"expected at least {low} item{'s' if low != 1 else ''}, got {ctx.get('actual_length')}"
        if high is not None:
            return f"expected at most {high} items, got {ctx.get('actual_length')}"
    if kind == "literal_error":
        return f"must be one of {ctx.get('expected')}"
    if kind == "union_tag_invalid":
        return f"unknown kind {ctx.get('tag')!r}; expected one of {ctx.get('expected_tags')}"
    return one_line(error.get("msg", "invalid value"))


def _field(loc: tuple[Any, ...], kind: str) -> str:
    """Dotted path (``obstacles[2].size[0]``) of a pydantic error location."""
    parts: list[str] = []
    skip_tag = False
    for item in loc:
        if skip_tag:
            skip_tag = False
            continue
        if isinstance(item, int):
            parts.append(f"[{item}]")
        else:
            parts.append(("." if parts else "") + str(item))
            skip_tag = item in _TAGGED_FIELDS
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        parts.append(".kind")
    return "".join(parts) or "(document)"


def pydantic_reason(error: dict[str, Any]) -> str:
    """The REASON of an error line for one pydantic error (``must be >= 1``, ``expected an integer``).

    Also used for the command line's option values, which typer validates with pydantic.
    """
    return _reason(error)


def _known_keys(model: Any, loc: tuple[Any, ...]) -> list[str] | None:
    """The keys a table at ``loc`` (a pydantic error location, tags included) may hold, or None.

    Walks the models down ``loc``: through optional values, lists (an index in ``loc``) and
    tagged unions (the tag in ``loc``, as pydantic reports it).
    """
    import types
    import typing

    annotation: Any = model
    items = list(loc)
    while True:
        origin = typing.get_origin(annotation)
        if origin is Annotated:
            annotation = typing.get_args(annotation)[0]
            continue
        if origin in (Union, types.UnionType):
            options = [a for a in typing.get_args(annotation) if a is not type(None)]
            tagged = {}
            for a in options:
                base = typing.get_args(a)[0] if typing.get_origin(a) is Annotated else a
                kind = getattr(base, "model_fields", {}).get("kind")
                if kind is not None and typing.get_origin(kind.annotation) is Literal:
                    tagged[typing.get_args(kind.annotation)[0]] = a
            if tagged and items and items[0] in tagged:
                annotation = tagged[items.pop(0)]
                continue
            if len(options) != 1:
                return None
            annotation = options[0]
            continue
        if origin is list:
            if not items or not isinstance(items[0], int):
                return None
            items.pop(0)
            annotation = typing.get_args(annotation)[0]
            continue
        fields = getattr(annotation, "model_fields", None)
        if fields is None:
            return None
        if not items:
            return list(fields)
        name = items.pop(0)
        if name not in fields:
            return None
        annotation = fields[name].annotation


def _unknown_key_error(model: Any, error: dict[str, Any], file: str) -> InputError:
    """``FILE: terain: unknown section; did you mean terrain?`` for a key the model does not have."""
    import difflib

    loc = tuple(error["loc"])
    name = str(loc[-1])
    what = "unknown section" if isinstance(error.get("input"), dict) else "unknown key"
    known = _known_keys(model, loc[:-1]) or []
    close = difflib.get_close_matches(name, known, n=1, cutoff=0.6)
    hint = f"; did you mean {close[0]}?" if close else (f"; expected one of {', '.join(known)}" if known else "")
    return InputError(file, _field(loc, error["type"]), what + hint)


def input_error(error: ValidationError, file: str, model: Any = None) -> InputError:
    """The :class:`InputError` for the first problem pydantic found in ``file``.

    An unknown key comes first: a misspelt section (``[terain]``) also makes the section it
    meant missing, and the misspelling is the problem to name.
    """
    errors = error.errors(include_url=False)
    unknown = [e for e in errors if e["type"] == "extra_forbidden"]
    if unknown and model is not None:
        return _unknown_key_error(model, unknown[0], file)
    first = (unknown or errors)[0]
    return InputError(file, _field(tuple(first["loc"]), first["type"]), _reason(first))


def validate(model: type[_Model], data: dict[str, Any], file: str) -> Any:
    """``model`` validated from the TOML ``data`` of ``file``; :class:`InputError` on the first problem."""
    try:
        return model.model_validate(data)
    except ValidationError as error:
        raise input_error(error, file, model) from None
