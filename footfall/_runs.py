"""One recorded crowd run: the piece ``simulate``, ``export-usd`` and the main job share."""

from __future__ import annotations

from pathlib import Path


def recorded_run(scenario, creature, gait, *, frames: int, characters: int | None = None, seed: int = 0,
                 preset=None, lod: str = "off", record: bool = True, progress=None):
    """Simulate ``frames`` frames of the scenario's crowd; returns (model, summary, recorder or None).

    ``preset``: a loaded :class:`planner.Preset` (its weights and timing), or None for the defaults.
    ``progress(k)`` is called after frame k.
    """
    from planner._crowd import init_crowd
    from planner._simulation import Recorder, simulate

    weights = preset.weights if preset is not None else None
    timing = preset.timing if preset is not None else None
    model, state = init_crowd(scenario, creature, gait, n_characters=characters, seed=seed, weights=weights,
                              timing=timing, lod_mode=lod)
    recorder = Recorder(model, state, frames) if record else None
    say_speed_cap(model)
    summary = simulate(model, state, frames, recorder, progress=progress)
    return model, summary, recorder


def say_speed_cap(model) -> None:
    """One note on stderr when the creature's legs cannot carry the asked speed (the controller caps it)."""
    import sys

    if model.speed_asked > model.speed_cap:
        print(f"footfall: note: {model.creature.name}: {model.speed_asked:g} m/s asked; speed capped at "
              f"{model.speed_cap:.3g} m/s, the fastest its legs carry at the stride law", file=sys.stderr)


def load_named_preset(value: str, creature: str):
    """``--preset``: a preset file, or the name of a shipped preset (``tuning/data/presets/<name>.json``:
    ``--preset spider``). Refused with one line naming the file and the field if it is for another
    creature, of another schema version, or malformed (``planner._presets.load_preset``)."""
    from pathlib import Path

    from footfall._errors import InputError
    from planner._presets import load_preset
    from tuning import PRESETS_DIR  # no JAX: tuning's __init__ re-exports lazily

    path = Path(value)
    if path.suffix != ".json" and len(path.parts) == 1 and not path.exists():
        shipped = sorted(p.stem for p in PRESETS_DIR.glob("*.json"))
        if value not in shipped:
            raise InputError("argument", "--preset",
                             f"{value!r} is neither a .json file nor a shipped preset ({', '.join(shipped)})")
        path = PRESETS_DIR / f"{value}.json"
    return load_preset(path, creature)


def recording_meta(scenario, seed: int, lod: str, gait) -> dict:
    """What a recording's header says about its run, beside the recorder's own fields."""
    meta = {"scenario": scenario.name, "seed": int(seed), "lod": lod, "gait": gait.name}
    if not scenario.source.startswith("builtin:"):  # a user's scenario file: where to find it again
        meta["scenario_file"] = str(Path(scenario.source).resolve())
    return meta


def resolve_gait(scenario, creature, option: str | None = None):
    """The gait a run walks with and where it came from: (gait, label, authored).

    ``--gait`` (``option``) wins over the scenario's ``[crowd] gait`` (``scenario`` None: not
    looked at, e.g. when ``--creature`` replaced the scenario's creature), which wins over the
    creature's default (:func:`scenarios.default_gait`: its built-in default, or one
    generated from its morphology). ``authored`` is True for a gait the user named (not
    ``"default"``): its duty factor is the user's, and :func:`duty_factor_note` may apply.
    """
    from scenarios import DEFAULT_GAIT, load_gait
    from scenarios._gait_schedule import gait_schedule

    reference = option if option is not None else None if scenario is None else scenario.crowd.gait
    if reference is None or reference == DEFAULT_GAIT:
        # The creature's gaits by speed (walk -> trot, ...; one gait for a creature with no schedule).
        return gait_schedule(creature), DEFAULT_GAIT, False
    return load_gait(reference, creature), reference, True


def duty_factor_note(gait, label: str, creature, speed: float, timing=None) -> str | None:
    """One line when the timing model changes an authored gait's duty factor at ``speed`` (m/s), else None.

    A run rescales every gait's swing durations so that their mean follows the duty factor
    of the speed (``planner._timing.duty_factor``, ``scaled_swing_durations``); the pattern
    of starts is kept. Differences under 0.005 are not worth a line.
    """
    from planner._timing import GaitTiming, duty_factor, hip_height

    imposed = float(duty_factor(timing or GaitTiming(), float(speed), hip_height(creature)))
    authored = gait.duty_factor
    if abs(imposed - authored) < 0.005:
        return None
    return (f"gait {label}: authored duty factor {authored:.2f} becomes {imposed:.2f} at {float(speed):.2f} m/s "
            "(swing durations follow the speed; see scenarios/README.md)")


def say_duty_factor(gait, label: str, authored: bool, creature, speed: float, timing=None) -> None:
    """Print :func:`duty_factor_note` on stderr (``footfall: note: ...``) for a gait the user authored."""
    import sys

    note = duty_factor_note(gait, label, creature, speed, timing) if authored else None
    if note:
        print(f"footfall: note: {note}", file=sys.stderr)
