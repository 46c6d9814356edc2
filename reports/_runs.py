"""One recorded crowd run: the piece ``simulate``, ``export-usd``, ``evaluate``, the report and the main
job share."""

from __future__ import annotations

from pathlib import Path


def recorded_run(scenario, creature, gait, *, frames: int, characters: int | None = None, seed: int = 0,
                 preset=None, lod: str = "off", record: bool = True, progress=None, navigate: bool = True,
                 say_cap: bool = True):
    """Simulate ``frames`` frames of the scenario's crowd; returns (model, summary, recorder or None).

    ``preset``: a loaded :class:`planner.Preset` (its weights and timing), or None for the defaults.
    ``progress(k)`` is called after frame k. ``navigate``: ``ControllerConfig.navigate``. ``say_cap``:
    say on stderr when the creature's speed is capped (:func:`say_speed_cap`; a sweep of many runs says
    it once, from :func:`speed_cap_message`).
    """
    from footfall.planner._crowd import ControllerConfig, init_crowd
    from footfall.planner._simulation import Recorder, simulate

    weights = preset.weights if preset is not None else None
    timing = preset.timing if preset is not None else None
    model, state = init_crowd(scenario, creature, gait, n_characters=characters, seed=seed, weights=weights,
                              timing=timing, lod_mode=lod, controller=ControllerConfig(navigate=navigate))
    recorder = Recorder(model, state, frames) if record else None
    if say_cap:
        say_speed_cap(model)
    summary = simulate(model, state, frames, recorder, progress=progress)
    return model, summary, recorder


def speed_cap_message(model) -> str | None:
    """The note a run says when the creature's legs cannot carry the asked speed (the controller caps it),
    or None."""
    from footfall.planner._workspace import speed_cap_why

    if model.speed_asked <= model.speed_cap:
        return None
    return (f"footfall: note: {model.creature.name}: {model.speed_asked:g} m/s asked; speed capped at "
            f"{model.speed_cap:.3g} m/s, {speed_cap_why(model.speed_cap_reason)}")


def say_speed_cap(model) -> None:
    """:func:`speed_cap_message` on stderr, if any."""
    import sys

    message = speed_cap_message(model)
    if message is not None:
        print(message, file=sys.stderr)


def recording_meta(scenario, seed: int, lod: str, gait, navigate: bool = True) -> dict:
    """What a recording's header says about its run, beside the recorder's own fields (``navigate``:
    ``ControllerConfig.navigate``, on by default since 2026-11-26; a header without it was recorded
    before, without the way round)."""
    meta = {"scenario": scenario.name, "seed": int(seed), "lod": lod, "gait": gait.name, "navigate": bool(navigate)}
    if not scenario.source.startswith("builtin:"):  # a user's scenario file: where to find it again
        meta["scenario_file"] = str(Path(scenario.source).resolve())
    return meta
