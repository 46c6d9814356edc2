"""``footfall report``: run the sweep, analyse it, draw it, write the folder atomically.

The whole report is written into a hidden temporary folder beside ``out`` and renamed
over it at the end, so ``out`` is either the previous report or the new one, never half
of one. An existing ``out`` is only replaced if it is empty or a footfall report.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import os
import shutil
import tempfile
import time
from pathlib import Path

from footfall._atomic import make_folder
from footfall._errors import InputError
from footfall._distribute import check_workers, run_tasks
from footfall.reports import _html, _lod_report, _pareto, _plots, _sweep

REPORT_FORMAT = "footfall-report"
REPORT_VERSION = 1
CLIP_SIZE = (640, 360)
CLIP_MIN_FRAMES = 60
"""Every clip of the report has at least this many frames (2 s), the quick sweep's scenes too."""
CLIP_MAX_FRAMES = 300


def _writable_out(out: Path) -> None:
    """Refuse an output folder that cannot be (re)placed, before any work."""
    if out.exists() and not out.is_dir():
        raise InputError("argument", "--out", f"{out} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()):
        marker = out / "results.json"
        try:
            ok = json.loads(marker.read_text()).get("format") == REPORT_FORMAT
        except (OSError, ValueError, AttributeError):
            ok = False
        if not ok:
            raise InputError("argument", "--out", f"{out} is a folder that is not a footfall report; "
                             "choose a new or empty folder")
    make_folder(out.parent, "argument", "--out")


def _make_temp(out: Path) -> Path:
    try:
        return Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial", dir=out.parent))
    except OSError as e:
        raise InputError("argument", "--out", f"cannot write in {out.parent}: {e.strerror or e}") from None


def _publish(tmp: Path, out: Path) -> None:
    """Put ``tmp`` in place of ``out`` (renames on the same file system)."""
    old = None
    if out.exists():
        old = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=out.parent))
        os.rmdir(old)
        os.rename(out, old)
    try:
        os.rename(tmp, out)
    except BaseException:
        if old is not None:
            os.rename(old, out)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def load_recording(path) -> dict:
    """A recording's header and arrays; InputError when it is not a footfall recording of the
    version this footfall reads (the checks of :func:`reports._recording.load_recording`)."""
    from footfall.reports._recording import load_recording as load_validated

    rec = load_validated(path)
    if not rec.header.get("scenario"):
        raise InputError(str(path), "header.scenario", "missing: the recording does not name its scenario")
    return {"header": rec.header, "feet": rec.feet, "pelvis": rec.pelvis, "in_stance": rec.in_stance,
            "recording": rec}


def render_run(recording, out_dir: Path, *, max_characters: int = 10) -> tuple[list[str], str | None, str | None]:
    """Pictures and a clip of a recorded run, rendered in subprocesses (a VTK crash must not end the
    report): (PNG names, clip name or None, error or None). The creatures are drawn from the
    recording's IK joints (:mod:`reports._animation`); at most ``max_characters`` of them and the
    first :data:`CLIP_MAX_FRAMES` frames."""
    from footfall.reports._animation import RenderError, render_clip, render_stills, run_scene

    out_dir.mkdir(parents=True, exist_ok=True)
    try:
        scene = run_scene(recording, min(recording.frames, CLIP_MAX_FRAMES), max_characters)
    except InputError as e:  # e.g. a creature file that is not at hand: the report goes on without pictures
        return [], None, f"cannot draw the run: {e}"
    try:
        names = render_stills(scene, out_dir)
    except RenderError as e:
        return [], None, str(e)
    try:
        render_clip(scene, out_dir / "clip.mp4", camera="follow", size=CLIP_SIZE)
    except RenderError as e:
        return names, None, str(e)
    return names, "clip.mp4", None


def _scene_recording(name: str, seed: int, characters: int, frames: int, work: Path):
    """A recorded run of the scenario's crowd for its pictures and clip (no LOD, default weights)."""
    from footfall.reports._runs import recorded_run, recording_meta
    from footfall.reports._recording import load_recording as load_validated

    scenario, creature, gait = _sweep._load_inputs(name)
    model, summary, recorder = recorded_run(scenario, creature, gait, frames=frames, characters=characters,
                                            seed=seed)
    path = work / f"clip-{len(list(work.iterdir()))}.npz"
    recorder.save(path, model, summary, recording_meta(scenario, seed, "off", gait))
    return load_validated(path)


def _write_csv(path: Path, rows: list[dict], columns: list[str]) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in columns})


def task_columns(results: list[dict]) -> list[str]:
    """CSV columns of the per-run table: every scalar metric (the stride samples live in the JSON)."""
    return [k for k in results[0] if not isinstance(results[0][k], (list, dict))] if results else []


def build_report(out, *, preset: str = "default", scenarios: tuple[str, ...] | None = None, seed: int = 0,
                 recording: str | None = None, progress=None, warn=None, workers: int | None = None,
                 cluster: str | None = None) -> dict:
    """Run the sweep and write the report folder ``out``; returns the summary (JSON-ready).

    ``progress(description, completed, total)`` is called as work advances;
    ``warn(message)`` for problems that do not stop the report (a failed render).
    ``workers`` / ``cluster``: where the sweep's tasks run (:mod:`footfall._distribute`:
    one local worker process per core by default, ``workers=1`` in this process, or the
    workers of a Dask scheduler); the metrics do not depend on it.
    """
    from footfall import __version__

    if preset not in _sweep.PRESETS:
        raise InputError("argument", "--preset", f"expected one of {', '.join(_sweep.PRESETS)}, got {preset!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError("argument", "--seed", f"expected an integer >= 0, got {seed!r}")
    options = _sweep.PRESETS[preset]
    if scenarios:
        options = dataclasses.replace(options, scenarios=tuple(scenarios))
    options = dataclasses.replace(options, seeds=(int(seed),))
    _sweep.check_scenarios(options.scenarios)
    check_workers(workers, cluster)
    rec = load_recording(recording) if recording is not None else None
    if rec is not None:
        _sweep.check_scenarios([rec["header"]["scenario"]])
    out = Path(out).absolute()
    _writable_out(out)
    progress = progress or (lambda *a: None)
    warn = warn or (lambda m: None)
    tasks = _sweep.build_tasks(options)
    total = len(tasks) + 2 * len(options.scenarios) + (1 if rec is not None else 0) + 1
    done = 0
    t_start = time.perf_counter()
    tmp = _make_temp(out)
    try:
        with tempfile.TemporaryDirectory(prefix="footfall-report-") as work_dir:
            work = Path(work_dir)
            progress("sweep", done, total)
            results = run_tasks(_sweep.run_task, tasks, workers=workers, cluster=cluster,
                                progress=lambda task, k: progress(
                                    f"{task['scenario']} x{task['characters']} {task['setting']}", done + k, total))
            done += len(tasks)
            analysis = _pareto.analyse(results)
            _plots.pareto_plot(analysis, tmp / "pareto.png")
            runs = [r for r in results if r["kind"] not in ("paired", "lod-scaling")]
            scaling = [r for r in results if r["kind"] == "lod-scaling"]
            lod = _lod_report.analyse(runs, scaling)
            if scaling:
                _plots.lod_scaling_plot(scaling, tmp / "lod_scaling.png")
            _plots.stride_plot(runs, tmp / "stride.png")
            scenes = []
            scene_notes = []
            render_errors = []
            for name in options.scenarios:
                progress(f"scene {name}", done, total)
                scene = _sweep.run_scene(name, int(seed), options.scene_characters, options.scene_frames)
                done += 1
                sname = scene["scenario"]
                plots = [(f"gait_disks_{sname}.png", f"gait disks, {sname}")]
                _plots.gait_disks(scene, tmp / plots[0][0])
                caption = (f"{options.scene_characters} x {scene['creature']}, {options.scene_frames} frames, no LOD. "
                           "Gait disks at the last frame (paper Fig. 8). ")
                if scene["heatmap"] is not None:
                    plots.append((f"footprints_{sname}.png", f"footprint scores, {sname}"))
                    _plots.footprint_heatmap(scene, tmp / plots[-1][0])
                    caption += ("Footprint scores of the plan with the most candidates (paper Fig. 13), planned "
                                "again from its captured request; pink: the best trajectory to other candidates. ")
                clip_frames = min(max(CLIP_MIN_FRAMES, options.scene_frames), CLIP_MAX_FRAMES)
                caption += (f"3D pictures and clip: another run of the same crowd, {clip_frames} frames "
                            f"({clip_frames / 30:.0f} s), the creatures drawn from their IK joints, one colour "
                            "per character; the legend and the scale bar are in the pictures.")
                progress(f"rendering {name}", done, total)
                clip_run = _scene_recording(name, int(seed), options.scene_characters, clip_frames, work)
                names, clip, error = render_run(clip_run, tmp / "renders" / sname)
                done += 1
                if error:
                    warn(f"rendering {sname} failed: {error}")
                    render_errors.append(error)
                scene_notes.append({"scenario": sname, "renders": [f"renders/{sname}/{n}" for n in names],
                                    "clip": f"renders/{sname}/{clip}" if clip else None,
                                    "heatmap_matches_crowd": (scene["heatmap"] or {}).get("matches_crowd")})
                scenes.append({"scenario": sname, "caption": caption, "plots": plots,
                               "renders": [(f"renders/{sname}/{n}", f"{sname}: {n}") for n in names],
                               "clip": f"renders/{sname}/{clip}" if clip else None, "render_error": error})
            rec_page = None
            if rec is not None:
                progress("rendering the recording", done, total)
                names, clip, error = render_run(rec["recording"], tmp / "renders" / "recording")
                done += 1
                if error:
                    warn(f"rendering the recording failed: {error}")
                    render_errors.append(error)
                h = rec["header"]
                rec_page = {"name": Path(recording).name, "renders": [(f"renders/recording/{n}", n) for n in names],
                            "clip": f"renders/recording/{clip}" if clip else None, "render_error": error,
                            "caption": f"{h.get('creature')} on {h['scenario']}, {rec['feet'].shape[0]} frames, "
                                       f"{rec['feet'].shape[1]} characters (at most 10 drawn), LOD {h.get('lod')}; "
                                       f"the clip shows at most the first {CLIP_MAX_FRAMES} frames."}
            progress("writing", done, total)
            meta = {"format": REPORT_FORMAT, "version": REPORT_VERSION, "footfall": __version__, "preset": preset,
                    "seed": int(seed), "scenarios": list(options.scenarios), "sizes": list(options.sizes),
                    "settings": list(options.settings), "frames": options.frames, "warmup": options.warmup,
                    "wall_seconds": time.perf_counter() - t_start}
            _write_csv(tmp / "results.csv", runs, task_columns(runs))
            paired_rows = [{"scenario": r["scenario"], "seed": r["seed"], "characters": r["characters"],
                            "situations": r["situations"], **{k: v for k, v in b.items() if k != "cost_ratios"}}
                           for r in results if r["kind"] == "paired"
                           for b in r["budgets"]]
            if paired_rows:
                _write_csv(tmp / "paired.csv", paired_rows, list(paired_rows[0]))
            summary_columns = ([n for n, _, _ in _pareto.COLUMNS] + [n for n, _ in _pareto.PAIRED_COLUMNS]
                               + ["on_front", "recommended"])
            _write_csv(tmp / "summary.csv", analysis["rows"], summary_columns)
            if lod["levels"]:
                _write_csv(tmp / "lod_levels.csv", lod["levels"], list(lod["levels"][0]))
            if lod["scaling"]:
                _write_csv(tmp / "lod_scaling.csv", lod["scaling"], list(lod["scaling"][0]))
            summary = {**meta, "lod": lod, "recommended_budget": analysis["recommended_budget"], "front": analysis["front"],
                       "tolerance_pct": analysis["tolerance_pct"], "rows": analysis["rows"],
                       "scenes": scene_notes, "render_errors": render_errors}
            (tmp / "results.json").write_text(json.dumps({**summary, "tasks": results}, indent=1))
            _html.write_index(tmp / "index.html", analysis=analysis, results=runs, meta=meta, scenes=scenes,
                              recording=rec_page, lod=lod)
        _publish(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    done += 1
    progress("done", done, total)
    summary["out"] = str(out)
    summary["index"] = str(out / "index.html")
    return summary
