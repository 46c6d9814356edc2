"""``--preset``: a preset file or the name of a shipped preset."""

from __future__ import annotations


def load_named_preset(value: str, creature: str):
    """``--preset``: a preset file, or the name of a shipped preset (``tuning/data/presets/<name>.json``:
    ``--preset spider``). Refused with one line naming the file and the field if it is for another
    creature, of another schema version, or malformed (``planner._presets.load_preset``)."""
    from pathlib import Path

    from footfall._errors import InputError
    from footfall.planner._presets import load_preset
    from footfall.tuning import PRESETS_DIR, shipped_preset_paths  # no JAX: tuning's __init__ re-exports lazily

    path = Path(value)
    if path.suffix != ".json" and len(path.parts) == 1 and not path.exists():
        shipped = sorted(p.stem for p in shipped_preset_paths())
        if value not in shipped:
            raise InputError("argument", "--preset",
                             f"{value!r} is neither a .json file nor a shipped preset ({', '.join(shipped)})")
        path = PRESETS_DIR / f"{value}.json"
    return load_preset(path, creature)
