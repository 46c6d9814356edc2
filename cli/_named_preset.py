"""``--preset``: a preset file or the name of a shipped preset."""

from __future__ import annotations

from pathlib import Path


def named_preset_path(value: str) -> Path:
    """The file ``--preset`` names: ``value`` itself, or a shipped preset's
    (``tuning/data/presets/<name>.json``: ``--preset spider``). An unknown name is refused in one line."""
    from footfall._errors import InputError
    from footfall.tuning import PRESETS_DIR, shipped_preset_paths  # no JAX: tuning's __init__ re-exports lazily

    path = Path(value)
    if path.suffix != ".json" and len(path.parts) == 1 and not path.exists():
        shipped = sorted(p.stem for p in shipped_preset_paths())
        if value not in shipped:
            raise InputError("argument", "--preset",
                             f"{value!r} is neither a .json file nor a shipped preset ({', '.join(shipped)})")
        path = PRESETS_DIR / f"{value}.json"
    return path


def load_named_preset(value: str, creature: str):
    """``--preset``: the preset :func:`named_preset_path` names, for ``creature``. Refused with one line
    naming the file and the field if it is for another creature, of another schema version, or
    malformed (``planner._presets.load_preset``)."""
    from footfall.planner._presets import load_preset

    return load_preset(named_preset_path(value), creature)
