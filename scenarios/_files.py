"""Loading scenarios and creatures from TOML files and from the built-in catalogue.

See ``scenarios/README.md`` for the file formats.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from footfall._errors import InputError
from footfall.scenarios import _schema as schema
from footfall.scenarios._arrays import UNATTRIBUTED, one_line
from footfall.scenarios._creatures import Creature
from footfall.scenarios._generators import (
    CrateRecipe,
    flat_heightfield,
    hills_heightfield,
    random_crates,
    resting_y,
    stairs_heightfield,
    terrain_loop,
)
from footfall.scenarios._heightmaps import read_heightmap
from footfall.scenarios._obstacles import STATIC, VELOCITY, WAYPOINTS, Obstacles
from footfall.scenarios._scenario import Camera, CrowdSpawn, Scenario
from footfall.scenarios._terrain import Heightfield

DATA_DIR = Path(__file__).parent / "data"
"""Built-in scenarios (``*.toml``)."""
CREATURES_DIR = DATA_DIR / "creatures"
"""Built-in creatures (``*.toml``)."""

_DEFAULT_REGION_INSET = 0.5  # m: default [obstacles_random] region is the terrain minus this border
_DEFAULT_CAMERA_BACK = 4.0  # m behind the crowd
_DEFAULT_CAMERA_UP = 3.0  # m above the crowd
_DEFAULT_FOV = 0.9  # radians


# --------------------------------------------------------------------------- catalogue


def builtin_scenario_names() -> tuple[str, ...]:
    """Names of the built-in scenarios, sorted.

    Returns
    -------
    tuple of str
        The stems of ``scenarios/data/*.toml``; each is a name for :func:`load_scenario`.

    Examples
    --------
    >>> from footfall.scenarios import builtin_scenario_names
    >>> builtin_scenario_names()
    ('crates', 'crates-moving', 'flat', 'hills', 'mixed', 'stairs')
    """
    return tuple(sorted(path.stem for path in DATA_DIR.glob("*.toml")))


def builtin_creature_names() -> tuple[str, ...]:
    """Names of the built-in creatures, sorted.

    Returns
    -------
    tuple of str
        The stems of ``scenarios/data/creatures/*.toml``; each is a name for :func:`load_creature`.

    Examples
    --------
    >>> from footfall.scenarios import builtin_creature_names
    >>> builtin_creature_names()
    ('ant', 'quadruped', 'robot5', 'spider')
    """
    return tuple(sorted(path.stem for path in CREATURES_DIR.glob("*.toml")))


def _is_file(path: Path) -> bool:
    """``path.is_file()``, False for names the OS refuses (e.g. with a NUL byte)."""
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def _resolve(name_or_path: str | Path, directory: Path, builtins: tuple[str, ...], what: str) -> tuple[Path, str]:
    """(path to read, label for errors) of a built-in name or a file path.

    A ``Path`` is always a file path. A string is a built-in name if it is
    one, else a file path. Raises :class:`InputError` (file ``name_or_path``,
    field ``what``) when it is neither.
    """
    text = str(name_or_path)
    if isinstance(name_or_path, str) and name_or_path in builtins:
        return directory / f"{name_or_path}.toml", f"builtin:{name_or_path}"
    path = Path(name_or_path)
    if _is_file(path):
        return path, text
    if isinstance(name_or_path, Path) or path.suffix == ".toml" or "/" in text or "\\" in text:
        raise InputError(text, what, "file not found")
    raise InputError(text, what, f"unknown {what}; built-ins are: {', '.join(builtins)}")


def _read_text(path: Path, file: str, what: str) -> str:
    try:
        return path.read_bytes().decode("utf-8")
    except OSError as error:
        raise InputError(file, what, f"cannot read file: {one_line(error.strerror or error)}") from None
    except UnicodeDecodeError:
        raise InputError(file, what, "not UTF-8 text") from None


def _parse_toml(text: str, file: str, what: str) -> dict[str, Any]:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise InputError(file, what, f"invalid TOML: {one_line(error)}") from None


def _read_toml(path: Path, file: str, what: str) -> dict[str, Any]:
    return _parse_toml(_read_text(path, file, what), file, what)


_INDEXED = re.compile(r"^(\w+)((?:\[\d+\])*)$")


def _split_field(field: str) -> tuple[str, list[int]]:
    """``"rest_feet[2][1]"`` -> ``("rest_feet", [2, 1])``."""
    match = _INDEXED.match(field)
    if not match:
        return field, []
    return match.group(1), [int(i) for i in re.findall(r"\d+", match.group(2))]


# --------------------------------------------------------------------------- kinds of file

_KIND_KEYS = {
    "scenario": ("terrain", "crowd", "obstacles", "obstacles_random", "camera", "seed"),
    "creature": ("legs", "leg_defaults", "standing_height", "body_thickness", "body_box", "foot"),
    "gait": ("swing",),
}


def file_kind(name_or_path: str | Path) -> str:
    """``"scenario"``, ``"creature"`` or ``"gait"``: what a built-in name or a ``.toml`` file is.

    A built-in name is looked up among the scenarios, then the creatures, then the gaits;
    a variant ``NAME@key=value`` is a scenario. A file is told by its keys (``[swing]``: a
    gait; ``legs``, ``foot``, ``standing_height``, ...: a creature; ``[terrain]``,
    ``[crowd]``, ...: a scenario). Raises :class:`InputError` for a file with none of them.
    """
    from footfall.scenarios._gaits import builtin_gait_names

    text = str(name_or_path)
    if isinstance(name_or_path, str) and not _is_file(Path(text)):
        if text in builtin_scenario_names() or ("@" in text and text.partition("@")[0] in builtin_scenario_names()):
            return "scenario"
        if text in builtin_creature_names():
            return "creature"
        if text in builtin_gait_names():
            return "gait"
    if "@" in text and not _is_file(Path(text)):
        return "scenario"
    path, file = _resolve(name_or_path, DATA_DIR, builtin_scenario_names(), "file")
    data = _read_toml(path, file, "file")
    scores = {kind: sum(key in data for key in keys) for kind, keys in _KIND_KEYS.items()}
    kind = max(scores, key=lambda k: scores[k])
    if scores[kind] == 0:
        raise InputError(file, "(document)", "neither a scenario ([terrain], [crowd]), a creature (legs, foot, "
                         "standing_height) nor a gait ([swing]) file")
    return kind


# --------------------------------------------------------------------------- creatures


_FILE_CREATURES: dict[str, Creature] = {}
"""Creatures this process loaded from files, by name (the last one loaded under each name)."""


def file_creature(name: str) -> Creature | None:
    """The creature named ``name`` that this process last loaded from a file, or None.

    Lets code that only has a creature's name (e.g. :func:`scenarios.default_gait_name`)
    tell a user creature from a built-in one.
    """
    return _FILE_CREATURES.get(name)


def load_creature(name_or_path: str | Path) -> Creature:
    """A built-in creature by name (see :func:`builtin_creature_names`) or a creature ``.toml`` file.

    This is the one resolver of a creature reference: every command that takes a creature
    (``--creature``, ``[crowd] creature``) goes through it, so a file works wherever a name does.
    Raises :class:`InputError` naming the file and field on any problem.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A built-in creature name, or the path of a creature file (format: ``scenarios/README.md``).
        A string is looked up among the built-ins first; a ``Path`` is always a file.

    Returns
    -------
    Creature
        Named after the file's ``name``, else the file name without ``.toml``.

    Raises
    ------
    footfall.InputError
        One line ``FILE: FIELD: REASON``; FILE is the path as given, or ``builtin:NAME``.

    Examples
    --------
    >>> from pathlib import Path
    >>> import footfall.scenarios
    >>> from footfall import InputError
    >>> from footfall.scenarios import load_creature
    >>> spider = load_creature("spider")
    >>> spider.n_legs, spider.n_segments, round(spider.standing_height, 2)
    (8, 4, 0.12)

    A file (here the example creature shipped next to the package's data):

    >>> heptapod = load_creature(Path(footfall.scenarios.__file__).parent / "examples" / "heptapod.toml")
    >>> heptapod.name, heptapod.n_legs
    ('heptapod', 7)

    A name that is neither a built-in nor a file:

    >>> try:
    ...     load_creature("centipede")
    ... except InputError as error:
    ...     print(error)
    centipede: creature: unknown creature; built-ins are: ant, quadruped, robot5, spider
    """
    path, file = _resolve(name_or_path, CREATURES_DIR, builtin_creature_names(), "creature")
    return _creature_from_text(_read_text(path, file, "creature"), path.stem, file)


def load_creature_text(text: str, label: str) -> Creature:
    """A creature from the text of a creature file (a recording's ``creature_toml``); errors name ``label``.

    Parameters
    ----------
    text : str
        TOML text in the creature file format (``scenarios/README.md``).
    label : str
        The file name that errors name; without a ``name`` key the creature is named after it
        (without its folder and ``.toml``).

    Returns
    -------
    Creature

    Raises
    ------
    footfall.InputError
        One line ``LABEL: FIELD: REASON`` on any problem.

    Examples
    --------
    A one-legged creature: its foot rests 0.14 m from the hip, within 0.98 x its 0.2 m reach.

    >>> from footfall import InputError
    >>> from footfall.scenarios import load_creature_text
    >>> text = '''
    ... standing_height = 0.1
    ... body_thickness = 0.05
    ... body_box = [0.2, 0.1]
    ... foot = { length = 0.03, width = 0.02 }
    ... [[legs]]
    ... name = "A"
    ... hip = [0.0, 0.0, 0.05]
    ... rest_foot = [0.0, 0.15]
    ... segments = [0.1, 0.1]
    ... joint_limits = [[-1.0, 1.0], [0.0, 2.0]]
    ... '''
    >>> tiny = load_creature_text(text, "tiny.toml")
    >>> tiny.name, tiny.leg_names, tiny.leg_reach
    ('tiny', ('A',), array([0.2]))

    Bad input names the file and the field, as written in the file:

    >>> try:
    ...     load_creature_text(text.replace("rest_foot = [0.0, 0.15]", "rest_foot = [0.0, 0.5]"), "tiny.toml")
    ... except InputError as error:
    ...     print(error)  # doctest: +ELLIPSIS
    tiny.toml: legs[0].rest_foot: rest foot out of reach: 0.461 m from the hip, leg reach 0.200 m ...
    >>> try:
    ...     load_creature_text(text.replace("[0.2, 0.1]", "[0.2, -0.1]"), "tiny.toml")
    ... except InputError as error:
    ...     print(error)
    tiny.toml: body_box[1]: must be > 0
    """
    return _creature_from_text(text, Path(label).stem, label)


def _creature_from_text(text: str, stem: str, file: str) -> Creature:
    model: schema.CreatureFile = schema.validate(schema.CreatureFile, _parse_toml(text, file, "creature"), file)
    if not model.legs:
        raise InputError(file, "legs", "creature needs at least one leg")
    defaults = model.leg_defaults
    segments: list[list[float]] = []
    limits: list[list[list[float]]] = []
    segments_field: list[str] = []  # where each leg's segments / joint limits came from
    limits_field: list[str] = []
    for i, leg in enumerate(model.legs):
        own_segments = leg.segments is not None
        leg_segments = leg.segments if own_segments else defaults.segments
        segments_field.append(f"legs[{i}].segments" if own_segments else "leg_defaults.segments")
        if leg_segments is None:
            raise InputError(file, f"legs[{i}].segments", "required (or give leg_defaults.segments)")
        if len(leg_segments) < 2:
            raise InputError(file, segments_field[i], "a leg needs at least 2 segments")
        if len(leg_segments) != len(segments[0] if segments else leg_segments):
            raise InputError(file, segments_field[i],
                             f"every leg needs the same number of segments (legs[0] has {len(segments[0])})")
        own_limits = leg.joint_limits is not None
        leg_limits = leg.joint_limits if own_limits else defaults.joint_limits
        limits_field.append(f"legs[{i}].joint_limits" if own_limits else "leg_defaults.joint_limits")
        if leg_limits is None:
            raise InputError(file, f"legs[{i}].joint_limits", "required (or give leg_defaults.joint_limits)")
        if len(leg_limits) != len(leg_segments):
            raise InputError(file, limits_field[i],
                             f"expected one [min, max] per segment ({len(leg_segments)}), got {len(leg_limits)}")
        segments.append(leg_segments)
        limits.append(leg_limits)

    def file_field(field: str) -> str:
        name, index = _split_field(field)
        leg_fields = {"leg_names": "name", "hips": "hip", "rest_feet": "rest_foot"}
        if name == "leg_names" and not index:
            return "legs"
        if name in leg_fields and index:
            return f"legs[{index[0]}].{leg_fields[name]}"
        if name == "segment_lengths" and index:
            return segments_field[index[0]] + "".join(f"[{k}]" for k in index[1:])
        if name == "joint_limits" and index:
            return limits_field[index[0]] + "".join(f"[{k}]" for k in index[1:])
        return {"foot_length": "foot.length", "foot_width": "foot.width"}.get(name, field)

    try:
        creature = Creature(
            name=model.name or stem,
            leg_names=tuple(leg.name for leg in model.legs),
            hips=[leg.hip for leg in model.legs],
            segment_lengths=segments,
            joint_limits=limits,
            rest_feet=[leg.rest_foot for leg in model.legs],
            foot_length=model.foot.length,
            foot_width=model.foot.width,
            body_thickness=model.body_thickness,
            body_box=model.body_box,
            standing_height=model.standing_height,
            source_toml=None if file.startswith("builtin:") else text,
        )
    except InputError as error:
        if error.file != UNATTRIBUTED:
            raise
        raise InputError(file, file_field(error.field), error.reason) from None
    if not file.startswith("builtin:"):
        _FILE_CREATURES[creature.name] = creature
    return creature


# --------------------------------------------------------------------------- scenarios


def split_variant(spec: str) -> tuple[str, dict[str, Any]]:
    """``"NAME@key=value,key=value"`` -> (NAME, {dotted key: value}); values are TOML scalars.

    A *variant* is a scenario with a few of its file's values replaced, in memory: ``hills@seed=3``
    (the same kind of terrain from another seed), ``flat@crowd.speed=0.12``, ``stairs@crowd.centre=[-3.0,0.0]``
    (commas inside brackets belong to the value). It is a plain string, so a task sent to another
    machine carries it and loads the same scenario there.

    Parameters
    ----------
    spec : str
        ``NAME`` or ``NAME@key=value,...``; keys are the scenario file's dotted keys.

    Returns
    -------
    name : str
        The part before ``@`` (a built-in name or a path).
    overrides : dict
        Dotted key -> value (int, float, str, bool, list, ...), in the order given; empty without ``@``.

    Raises
    ------
    footfall.InputError
        On an item that is not ``key=value`` or a value that is not TOML (file ``spec``, field ``scenario``).

    Examples
    --------
    >>> from footfall.scenarios import split_variant
    >>> split_variant("hills@seed=3,crowd.centre=[-3.0, 0.0]")
    ('hills', {'seed': 3, 'crowd.centre': [-3.0, 0.0]})
    >>> split_variant("flat")
    ('flat', {})
    """
    name, _, rest = spec.partition("@")
    overrides: dict[str, Any] = {}
    for item in filter(None, _split_top_level(rest)):
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise InputError(spec, "scenario", f"variant {item!r}: expected key=value")
        try:
            overrides[key.strip()] = tomllib.loads(f"v = {value.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            raise InputError(spec, "scenario", f"variant {item!r}: {value.strip()!r} is not a TOML value") from None
    return name, overrides


def _split_top_level(text: str) -> list[str]:
    """``text`` split at the commas outside brackets and quotes."""
    items, depth, quote, start = [], 0, None, 0
    for i, ch in enumerate(text):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            items.append(text[start:i])
            start = i + 1
    items.append(text[start:])
    return items


def split_scenario_list(text: str) -> tuple[str, ...]:
    """``"A,B,..."`` (a command line's list of scenarios) -> its scenarios, a variant's overrides kept
    with it: an item ``key=value`` with no ``@`` before its ``=`` continues the variant before it.

    Parameters
    ----------
    text : str
        Built-in names, files and variants (:func:`split_variant`), separated by commas.

    Returns
    -------
    tuple of str
        One entry per scenario, stripped; empty items dropped.

    Examples
    --------
    >>> from footfall.scenarios import split_scenario_list
    >>> split_scenario_list("stairs,hills@terrain.octaves=3,terrain.wavelength=1.2,crates@seed=13")
    ('stairs', 'hills@terrain.octaves=3,terrain.wavelength=1.2', 'crates@seed=13')
    >>> split_scenario_list("stairs@crowd.centre=[-3.0,0.0], mixed")
    ('stairs@crowd.centre=[-3.0,0.0]', 'mixed')
    """
    names: list[str] = []
    for item in (part.strip() for part in _split_top_level(text)):
        continues = "=" in item and "@" not in item.partition("=")[0]
        if continues and names and "@" in names[-1]:
            names[-1] = f"{names[-1]},{item}"
        elif item:
            names.append(item)
    return tuple(names)


def variant_name(name: str, **overrides: Any) -> str:
    """The variant string of ``name`` with ``overrides`` (dotted keys as keyword names with ``__``
    for dots: ``variant_name("hills", seed=3, crowd__speed=0.1)``); floats written exactly.

    The inverse of :func:`split_variant`.

    Parameters
    ----------
    name : str
        A built-in scenario name or a path.
    **overrides
        Values to replace, by dotted key with ``__`` for each dot.

    Returns
    -------
    str
        ``name`` alone without overrides, else ``name@key=value,...``.

    Examples
    --------
    >>> from footfall.scenarios import split_variant, variant_name
    >>> variant_name("hills", seed=3, crowd__speed=0.1)
    'hills@seed=3,crowd.speed=0.1'
    >>> variant_name("flat")
    'flat'
    >>> split_variant(variant_name("stairs", crowd__centre=[-3.0, 0.0]))
    ('stairs', {'crowd.centre': [-3.0, 0.0]})
    """
    items = [f"{k.replace('__', '.')}={v!r}" for k, v in overrides.items()]
    return name + ("@" + ",".join(items) if items else "")


def _apply_overrides(data: dict[str, Any], overrides: dict[str, Any], file: str) -> dict[str, Any]:
    for key, value in overrides.items():
        *tables, leaf = key.split(".")
        node = data
        for t in tables:
            node = node.get(t)
            if not isinstance(node, dict):
                raise InputError(file, key, "no such table in the scenario to override")
        node[leaf] = value
    return data


def load_scenario(name_or_path: str | Path) -> Scenario:
    """A built-in scenario by name (see :func:`builtin_scenario_names`), a scenario ``.toml`` file, or
    a variant of either, ``NAME@key=value,...`` (:func:`split_variant`).

    Paths inside the file (height maps, creature files) are relative to the
    file. Raises :class:`InputError` naming the file and field on any problem.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A built-in scenario name, the path of a scenario file (format: ``scenarios/README.md``), or
        either followed by ``@key=value,...``. A string is looked up among the built-ins first; a
        ``Path`` is always a file.

    Returns
    -------
    Scenario
        Its ``source`` is the path as given or ``builtin:NAME``, followed by the variant's overrides.

    Raises
    ------
    footfall.InputError
        One line ``FILE: FIELD: REASON``, the field as written in the file (``obstacles[2].size[1]``).

    Examples
    --------
    >>> from footfall import InputError
    >>> from footfall.scenarios import load_scenario
    >>> hills = load_scenario("hills")
    >>> hills.source, hills.terrain.heights.shape
    ('builtin:hills', (401, 401))

    A variant: the same file with other values.

    >>> faster = load_scenario("flat@crowd.speed=0.12,seed=2")
    >>> faster.source, faster.crowd.speed, faster.seed
    ('builtin:flat@crowd.speed=0.12,seed=2', 0.12, 2)
    >>> try:
    ...     load_scenario("flat@crowd.goal=[50.0, 0.0]")
    ... except InputError as error:
    ...     print(error)
    builtin:flat@crowd.goal=[50.0, 0.0]: crowd.goal: outside the terrain (x in [-10, 10], z in [-10, 10])

    A file: 4 m x 4 m of flat ground, one box, one ant. The box rests on the ground (centre
    y = half its 0.3 m height); the camera, not given, looks at the crowd from 4 m behind and 3 m up.

    >>> import tempfile
    >>> from pathlib import Path
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = Path(folder.name) / "my.toml"
    >>> _ = path.write_text('''
    ... [terrain]
    ... kind = "flat"
    ... size = [4.0, 4.0]
    ... cell_size = 0.1
    ...
    ... [[obstacles]]
    ... centre = [1.0, 1.0]
    ... size = [0.4, 0.3, 0.5]
    ...
    ... [crowd]
    ... creature = "ant"
    ... goal = [1.5, 0.0]
    ... ''')
    >>> scenario = load_scenario(path)
    >>> scenario.name, scenario.crowd.creature, scenario.obstacles.centres.tolist()
    ('my', 'ant', [[1.0, 0.15, 1.0]])
    >>> scenario.camera.position.tolist()
    [-4.0, 3.0, 0.0]

    Bad input names the file and the field:

    >>> _ = path.write_text(path.read_text().replace("[0.4, 0.3, 0.5]", "[0.4, -0.3, 0.5]"))
    >>> try:
    ...     load_scenario(path)
    ... except InputError as error:
    ...     print("InputError:", error)  # doctest: +ELLIPSIS
    InputError: ...my.toml: obstacles[0].size[1]: must be > 0
    >>> folder.cleanup()
    """
    overrides: dict[str, Any] = {}
    if isinstance(name_or_path, str) and "@" in name_or_path and not _is_file(Path(name_or_path)):
        name_or_path, overrides = split_variant(name_or_path)
    path, file = _resolve(name_or_path, DATA_DIR, builtin_scenario_names(), "scenario")
    if overrides:
        file = variant_name(file, **{k.replace(".", "__"): v for k, v in overrides.items()})
    data = _apply_overrides(_read_toml(path, file, "scenario"), overrides, file)
    model: schema.ScenarioFile = schema.validate(schema.ScenarioFile, data, file)
    base = path.parent

    terrain = _attributed(file, "terrain", lambda: _build_terrain(model.terrain, model.seed, base, file))
    creature_ref, creature = _crowd_creature(model.crowd.creature, base, file)
    crowd = _attributed(file, "crowd", lambda: CrowdSpawn(
        creature=creature_ref,
        count=model.crowd.count,
        centre=model.crowd.centre,
        radius=model.crowd.radius,
        heading=model.crowd.heading,
        heading_mode=model.crowd.heading_mode,
        speed=model.crowd.speed,
        goal=model.crowd.goal,
        waypoints=model.crowd.waypoints,
        feet_spacing=model.crowd.feet_spacing,
        spawn_clear_s=model.crowd.spawn_clear_s,
        gait=None if model.crowd.gait is None else _crowd_gait(model.crowd.gait, creature, base, file),
    ))
    creature_radius = creature.rest_radius * crowd.feet_spacing
    _check_crowd_on_terrain(crowd, creature_radius, terrain, file)

    obstacles = _explicit_obstacles(model.obstacles, terrain, crowd, creature_radius, file)
    if model.obstacles_random is not None:
        generated = _random_obstacles(model.obstacles_random, model.seed, terrain, crowd, creature_radius, obstacles, file)
        obstacles = _concatenate(obstacles, generated)

    camera = _attributed(file, "camera", lambda: _build_camera(model.camera, crowd, terrain))
    return Scenario(
        name=model.name or path.stem,
        source=file,
        terrain=terrain,
        obstacles=obstacles,
        crowd=crowd,
        camera=camera,
        seed=model.seed,
        description=model.description,
    )


def _attributed(file: str, prefix: str, build: Any) -> Any:
    """``build()``, re-raising an unattributed :class:`InputError` as one about ``file`` / ``prefix.field``."""
    try:
        return build()
    except InputError as error:
        if error.file != UNATTRIBUTED:
            raise
        raise InputError(file, f"{prefix}.{error.field}", error.reason) from None


def _build_terrain(terrain: Any, seed: int, base: Path, file: str) -> Heightfield:
    if isinstance(terrain, schema.FlatTerrainFile):
        return flat_heightfield(tuple(terrain.size), terrain.cell_size, terrain.height)
    if isinstance(terrain, schema.HillsTerrainFile):
        return hills_heightfield(
            tuple(terrain.size),
            terrain.cell_size,
            terrain.amplitude,
            terrain.wavelength,
            terrain.octaves,
            terrain.persistence,
            seed if terrain.seed is None else terrain.seed,
        )
    if isinstance(terrain, schema.StairsTerrainFile):
        return stairs_heightfield(
            tuple(terrain.size),
            terrain.cell_size,
            terrain.rise,
            terrain.run,
            terrain.steps,
            terrain.start,
            terrain.direction,
            terrain.landing,
        )
    raw = read_heightmap(base / terrain.file, file, "terrain.file")
    rows, cols = raw.shape
    heights = raw * terrain.height_scale + terrain.height_offset
    if not np.all(np.isfinite(heights)):
        raise InputError(file, "terrain.height_scale", "scaled heights overflow")
    return Heightfield(
        heights,
        origin_x=-0.5 * (cols - 1) * terrain.cell_size,
        origin_z=-0.5 * (rows - 1) * terrain.cell_size,
        cell_size=terrain.cell_size,
    )


def _crowd_creature(reference: str, base: Path, file: str) -> tuple[str, Creature]:
    """(reference to store in :class:`CrowdSpawn`, loaded creature) for ``crowd.creature``."""
    names = builtin_creature_names()
    if reference in names:
        return reference, load_creature(reference)
    path = _file_next_to(reference, base, file, "crowd.creature", "creature", f"built-ins are: {', '.join(names)}")
    return str(path), _creature_from_text(_read_text(path, str(path), "creature"), path.stem, str(path))


def _file_next_to(reference: str, base: Path, file: str, field: str, kind: str, known: str) -> Path:
    """The file ``reference`` names (relative paths from the scenario file's folder ``base``), or
    one line on ``FILE: FIELD``: a path that leads nowhere, or a name that is not one of ``known``."""
    path = Path(reference)
    if not path.is_absolute():
        path = base / path
    if not _is_file(path):
        if path.suffix == ".toml" or "/" in reference or "\\" in reference:
            raise InputError(file, field, f"{kind} file not found: {path}")
        raise InputError(file, field, f"unknown {kind} {reference!r}; {known}")
    return path


def _crowd_gait(reference: str, creature: Creature, base: Path, file: str) -> str:
    """``crowd.gait`` resolved (a name, or a file path next to the scenario) and loaded once for ``creature``.

    A gait file's own problems name the gait file and its field; a name or path that leads
    nowhere, or a built-in gait that does not fit the creature, names ``FILE: crowd.gait``.
    """
    from footfall.scenarios._gaits import DEFAULT_GAIT, builtin_gait_names, load_gait

    names = builtin_gait_names()
    if reference == DEFAULT_GAIT or reference in names:
        resolved = reference
    else:
        resolved = str(_file_next_to(reference, base, file, "crowd.gait", "gait", f"built-ins are: {', '.join(names)}, "
                                     f"or {DEFAULT_GAIT!r} (the creature's default)"))
    try:
        load_gait(resolved, creature)
    except InputError as error:
        if error.file.startswith("builtin:") or error.file == creature.name:
            raise InputError(file, "crowd.gait", f"{error.file}: {error.field}: {error.reason}") from None
        raise
    return resolved


def _check_crowd_on_terrain(crowd: CrowdSpawn, creature_radius: float, terrain: Heightfield, file: str) -> None:
    (x0, x1), (z0, z1) = terrain.x_range, terrain.z_range
    extent = f"x in [{x0:g}, {x1:g}], z in [{z0:g}, {z1:g}]"
    if not terrain.contains(*crowd.centre):
        raise InputError(file, "crowd.centre", f"outside the terrain ({extent})")
    if not terrain.contains(*crowd.centre, margin=crowd.radius + creature_radius):
        raise InputError(file, "crowd.radius", "spawn disk (plus the creature's size) extends beyond the terrain")
    if not terrain.contains(*crowd.goal):
        raise InputError(file, "crowd.goal", f"outside the terrain ({extent})")
    for i, point in enumerate(crowd.waypoints):
        if not terrain.contains(*point):
            raise InputError(file, f"crowd.waypoints[{i}]", f"outside the terrain ({extent})")


def _box_touches_disk(centre_xz: np.ndarray, size: np.ndarray, yaw: float, disk_xz: np.ndarray, radius: float) -> bool:
    """Whether a box footprint (centre (x, z), extents, yaw) overlaps a disk."""
    dx, dz = disk_xz - centre_xz
    local_x = dx * math.cos(yaw) + dz * math.sin(yaw)
    local_z = -dx * math.sin(yaw) + dz * math.cos(yaw)
    nearest_x = min(max(local_x, -0.5 * size[0]), 0.5 * size[0])
    nearest_z = min(max(local_z, -0.5 * size[2]), 0.5 * size[2])
    return math.hypot(local_x - nearest_x, local_z - nearest_z) < radius


def _explicit_obstacles(
    entries: list[schema.ObstacleFile], terrain: Heightfield, crowd: CrowdSpawn, creature_radius: float, file: str
) -> Obstacles:
    n = len(entries)
    centres = np.zeros((n, 3))
    sizes = np.zeros((n, 3))
    yaws = np.zeros(n)
    forbidden = np.zeros(n, bool)
    kinds = np.zeros(n, np.int8)
    velocities = np.zeros((n, 3))
    waypoints: list[np.ndarray] = [np.zeros((0, 3))] * n
    speeds = np.zeros(n)
    spawn_radius = crowd.radius + creature_radius
    for i, entry in enumerate(entries):
        where = f"obstacles[{i}]"
        x, z = entry.centre
        if not terrain.contains(x, z):
            raise InputError(file, f"{where}.centre", "outside the terrain")
        sizes[i] = entry.size
        yaws[i] = entry.yaw
        forbidden[i] = entry.kind == "forbidden"
        centres[i] = (x, float(resting_y(terrain, x, z, sizes[i, 1], entry.lift)), z)
        if _box_touches_disk(np.array([x, z]), sizes[i], yaws[i], crowd.centre, spawn_radius):
            raise InputError(file, f"{where}.centre",
                             f"box overlaps the crowd spawn area ({spawn_radius:.2f} m around crowd.centre)")
        motion = entry.motion
        if isinstance(motion, schema.VelocityMotionFile):
            kinds[i] = VELOCITY
            velocities[i] = (motion.velocity[0], 0.0, motion.velocity[1])
        elif isinstance(motion, schema.WaypointsMotionFile):
            kinds[i] = WAYPOINTS
            for j, (px, pz) in enumerate(motion.points):
                if not terrain.contains(px, pz):
                    raise InputError(file, f"{where}.motion.points[{j}]", "outside the terrain")
            loop_xz = np.vstack([[x, z], motion.points])
            if not np.any(np.linalg.norm(loop_xz - loop_xz[0], axis=1) > 0.0):
                raise InputError(file, f"{where}.motion.points", "the loop has zero length (all points at centre)")
            loop = terrain_loop(terrain, loop_xz, sizes[i, 1], entry.lift)
            loop[0] = centres[i]
            waypoints[i] = loop
            speeds[i] = motion.speed
        else:
            kinds[i] = STATIC
    return Obstacles(centres, sizes, yaws, forbidden, kinds, velocities, tuple(waypoints), speeds)


def _random_obstacles(
    entry: schema.RandomObstaclesFile,
    seed: int,
    terrain: Heightfield,
    crowd: CrowdSpawn,
    creature_radius: float,
    existing: Obstacles,
    file: str,
) -> Obstacles:
    (x0, x1), (z0, z1) = terrain.x_range, terrain.z_range
    region_min = entry.region_min or [x0 + _DEFAULT_REGION_INSET, z0 + _DEFAULT_REGION_INSET]
    region_max = entry.region_max or [x1 - _DEFAULT_REGION_INSET, z1 - _DEFAULT_REGION_INSET]
    for name, (x, z) in (("region_min", region_min), ("region_max", region_max)):
        if not terrain.contains(x, z):
            raise InputError(file, f"obstacles_random.{name}", "outside the terrain")
    keep_out = [(*crowd.centre, crowd.radius + creature_radius + entry.keep_out)]
    keep_out += [(*point, creature_radius + entry.keep_out) for point in crowd.route]
    occupied = [
        (c[0], c[2], 0.5 * float(np.hypot(s[0], s[2])))
        for c, s in zip(existing.centres, existing.sizes)
    ]
    recipe = CrateRecipe(
        count=entry.count,
        region=(region_min[0], region_min[1], region_max[0], region_max[1]),
        footprint_range=tuple(entry.footprint_range),
        height_range=tuple(entry.height_range),
        safe_height_range=None if entry.safe_height_range is None else tuple(entry.safe_height_range),
        forbidden_fraction=entry.forbidden_fraction,
        moving_fraction=entry.moving_fraction,
        velocity_fraction=entry.velocity_fraction,
        speed_range=tuple(entry.speed_range),
        loop_radius_range=tuple(entry.loop_radius_range),
        min_gap=entry.min_gap,
    )
    field_names = {"region": "region_min"}
    try:
        return random_crates(terrain, recipe, seed if entry.seed is None else entry.seed, tuple(keep_out), tuple(occupied))
    except InputError as error:
        if error.file != UNATTRIBUTED:
            raise
        raise InputError(file, f"obstacles_random.{field_names.get(error.field, error.field)}", error.reason) from None


def _concatenate(first: Obstacles, second: Obstacles) -> Obstacles:
    return Obstacles(
        np.vstack([first.centres, second.centres]),
        np.vstack([first.sizes, second.sizes]),
        np.concatenate([first.yaws, second.yaws]),
        np.concatenate([first.forbidden, second.forbidden]),
        np.concatenate([first.motion_kind, second.motion_kind]),
        np.vstack([first.velocities, second.velocities]),
        first.waypoints + second.waypoints,
        np.concatenate([first.waypoint_speed, second.waypoint_speed]),
    )


def _build_camera(entry: schema.CameraFile | None, crowd: CrowdSpawn, terrain: Heightfield) -> Camera:
    if entry is not None:
        return Camera(entry.position, entry.target, entry.fov)
    cx, cz = crowd.centre
    target = np.array([cx, float(terrain.height_at(cx, cz)), cz])
    heading = crowd.heading if crowd.heading_mode == "fixed" else 0.0
    back = np.array([math.cos(heading), 0.0, math.sin(heading)]) * _DEFAULT_CAMERA_BACK
    position = target - back + np.array([0.0, _DEFAULT_CAMERA_UP, 0.0])
    return Camera(position, target, _DEFAULT_FOV)
