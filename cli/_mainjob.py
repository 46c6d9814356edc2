"""The main job (``footfall run``): simulate -> tune -> report -> export, into one folder.

``OUT/`` after a run:

* ``recording.npz``: the scenario's crowd with the default weights (``footfall simulate --record``);
* ``preset.json``: the creature's weights and timing tuned to the biomechanics targets
  (``footfall tune``), with its provenance and losses;
* ``report/index.html``: the evaluation sweep (``footfall report``), which also renders the recording;
* ``clip.mp4``: the recorded crowd walking (the report's clip of the recording, ``footfall render``:
  bodies and legs from the IK joints, foot tracks, pelvis paths; 30 frames per second);
* ``scene.usdc``: the crowd walking with the tuned preset, as a USD scene (``footfall export-usd``);
* ``summary.json``: what each step measured and where its output is.

Every file is written atomically; a step that fails stops the job with one line, leaving
the outputs of the steps before it.
"""

from __future__ import annotations

import json
import shutil
import tempfile
import time
from pathlib import Path

from footfall._atomic import atomic_path, make_folder, write_text_atomic
from footfall._errors import InputError

STEPS = ("simulate", "tune", "report", "export")
QUICK_TUNE = {"rounds": 1, "exact_scenarios": ("flat", "hills@seed=1"), "exact_seeds": (0,), "exact_frames": 75,
              "exact_characters": 1, "holdout_seeds": (101,), "holdout_characters": 1}
"""``--quick``: one round on fewer, shorter exact runs of one character (a smoke test of the pipeline,
not a preset to ship)."""
SIMULATE_FRAMES = 300
EXPORT_FRAMES = 90
EXPORT_CHARACTERS = 4


def _writable_folder(out: Path) -> Path:
    out = Path(out).absolute()
    if out.exists() and not out.is_dir():
        raise InputError(out, "--out", "exists and is not a folder")
    return make_folder(out, out, "--out")


def run_main_job(scenario_name: str, out_dir, *, seed: int = 0, quick: bool = False, workers: int | None = None,
                 progress=None) -> dict:
    """Run the four steps; returns the summary (also written to ``OUT/summary.json``).

    ``quick``: a short simulation, one tuning round and the report's quick sweep (tests).
    ``progress(step, message)`` is called as the job advances.
    """
    from footfall.reports._runs import recorded_run, recording_meta
    from footfall.scenarios._gait_choice import resolve_gait, say_duty_factor
    from footfall.planner._presets import load_preset
    from footfall.reports._recording import load_recording
    from footfall.reports._report import CLIP_MAX_FRAMES, build_report
    from footfall.reports._usd import export_usd
    from footfall.scenarios import DEFAULT_SCENARIO, load_creature, load_scenario
    from footfall.tuning._tune import TuneConfig, check_creature, tune

    progress = progress or (lambda step, message: None)
    scenario = load_scenario(scenario_name)
    creature_ref = check_creature(scenario.crowd.creature)  # a built-in name or the creature file's path
    creature = load_creature(creature_ref)
    gait, gait_label, authored = resolve_gait(scenario, creature)
    say_duty_factor(gait, gait_label, authored, creature, scenario.crowd.speed)
    out = _writable_folder(out_dir)
    summary: dict = {"scenario": scenario.name, "creature": creature.name, "gait": gait.name, "seed": seed,
                     "quick": quick,
                     "seconds": {}}
    t_job = time.perf_counter()

    t0 = time.perf_counter()
    frames = 60 if quick else SIMULATE_FRAMES
    progress("simulate", f"{scenario.crowd.count} x {creature.name} on {scenario.name}, {frames} frames")
    model, sim, recorder = recorded_run(scenario, creature, gait, frames=frames, seed=seed)
    recording = out / "recording.npz"
    recorder.save(recording, model, sim, recording_meta(scenario, seed, "off", gait))
    summary["simulate"] = {k: v for k, v in sim.to_json().items() if k != "stage_ms_median"}
    summary["seconds"]["simulate"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    progress("tune", f"{creature.name}: harvest, fit, exact loss")
    config = TuneConfig(creature_ref, seed=seed, **(QUICK_TUNE if quick else {}))
    preset_path = out / "preset.json"
    tuned = tune(config, preset_path, progress=lambda what, done, total: progress("tune", what), workers=workers)
    summary["tune"] = dict(tuned.summary, wall_s=tuned.wall_s)
    summary["seconds"]["tune"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    progress("report", "evaluation sweep")
    # The default scenario gets the report's own sweep (it includes it); another one is swept alone.
    sweep = () if scenario.name == DEFAULT_SCENARIO else (scenario_name,)
    report = build_report(out / "report", preset="quick" if quick else "default", scenarios=sweep, seed=seed,
                          recording=str(recording), workers=workers,
                          progress=lambda what, done, total: progress("report", f"{what} ({done}/{total})"))
    summary["report"] = {"recommended_budget": report.get("recommended_budget"),
                         "index": str(out / "report" / "index.html")}
    # The report has rendered the recording's clip already: the job's clip.mp4 is a copy of it.
    clip = out / "clip.mp4"
    rendered = out / "report" / "renders" / "recording" / "clip.mp4"
    if rendered.is_file():
        with atomic_path(clip) as tmp:
            shutil.copyfile(rendered, tmp)
        summary["clip"] = {"path": str(clip), "frames": min(frames, CLIP_MAX_FRAMES)}
    else:
        clip = None
        summary["clip"] = {"path": None, "error": "; ".join(report.get("render_errors") or ["not rendered"])}
    summary["seconds"]["report"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    progress("export", "the crowd with the tuned preset, as USD")
    preset = load_preset(preset_path, creature.name)
    model, run_summary, recorder = recorded_run(scenario, creature, gait, frames=30 if quick else EXPORT_FRAMES,
                                                characters=min(EXPORT_CHARACTERS, scenario.crowd.count), seed=seed,
                                                preset=preset)
    with tempfile.TemporaryDirectory(prefix="footfall-run-") as folder:
        path = Path(folder) / "tuned.npz"
        recorder.save(path, model, run_summary, recording_meta(scenario, seed, "off", gait))
        scene = export_usd(load_recording(path), scenario, creature, out / "scene.usdc")
    summary["export"] = {"usd": str(scene), "collisions": run_summary.collisions,
                         "forbidden_footprints": run_summary.forbidden_footprints}
    summary["seconds"]["export"] = time.perf_counter() - t0

    summary["seconds"]["total"] = time.perf_counter() - t_job
    summary["outputs"] = {"recording": str(recording), "preset": str(preset_path),
                          "report": str(out / "report" / "index.html"), "clip": None if clip is None else str(clip),
                          "usd": str(scene),
                          "summary": str(out / "summary.json")}
    write_text_atomic(out / "summary.json", json.dumps(summary, indent=2))
    return summary
