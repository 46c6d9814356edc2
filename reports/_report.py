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
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from footfall._atomic import make_folder
from footfall._errors import InputError
from footfall._distribute import check_workers, run_tasks
from reports import _html, _pareto, _plots, _sweep

REPORT_FORMAT = "footfall-report"
REPORT_VERSION = 1
RENDER_TIMEOUT_S = 180
SCENE_ARRAYS = ("terrain_heights", "terrain_origin", "terrain_cell", "box_centres", "box_sizes", "box_yaws",
                "box_forbidden", "feet", "pelvis", "footprints")


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
    from reports._recording import load_recording as load_validated

    rec = load_validated(path)
    if not rec.header.get("scenario"):
        raise InputError(str(path), "header.scenario", "missing: the recording does not name its scenario")
    return {"header": rec.header, "feet": rec.feet, "pelvis": rec.pelvis, "in_stance": rec.in_stance}


def _recording_scene(recording: dict, max_characters: int = 10) -> dict:
    from scenarios import load_scenario

    header = recording["header"]
    scenario = load_scenario(header["scenario"])
    feet = recording["feet"].astype(np.float64)[:, :max_characters]
    stance = recording["in_stance"][:, :max_characters]
    down = np.zeros_like(stance)
    down[1:] = stance[1:] & ~stance[:-1]
    f, c, leg = np.nonzero(down)
    centres, yaws = scenario.obstacles.poses_at(feet.shape[0] * float(header["dt"]))
    t = scenario.terrain
    return {"scenario": scenario.name, "terrain_heights": np.asarray(t.heights),
            "terrain_origin": np.array([t.origin_x, t.origin_z]), "terrain_cell": float(t.cell_size),
            "box_centres": np.asarray(centres, np.float64).reshape(-1, 3),
            "box_sizes": np.asarray(scenario.obstacles.sizes, np.float64).reshape(-1, 3),
            "box_yaws": np.asarray(yaws, np.float64).reshape(-1),
            "box_forbidden": np.asarray(scenario.obstacles.forbidden, bool).reshape(-1),
            "feet": feet, "pelvis": recording["pelvis"].astype(np.float64)[:, :max_characters],
            "footprints": feet[f, c, leg]}


def render_scene(scene: dict, out_dir: Path, work: Path) -> tuple[list[str], str | None]:
    """Render in a subprocess (a VTK crash must not end the report): (PNG names, error or None)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    npz = work / f"scene-{len(list(work.iterdir()))}.npz"
    np.savez(npz, **{k: np.asarray(scene[k]) for k in SCENE_ARRAYS})
    env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
    try:
        proc = subprocess.run([sys.executable, "-m", "reports._render", str(npz), str(out_dir)], env=env,
                              capture_output=True, text=True, timeout=RENDER_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return [], f"the renderer did not finish in {RENDER_TIMEOUT_S} s"
    if proc.returncode != 0:
        tail = (proc.stderr.strip().splitlines() or [""])[-1]
        return [], f"the renderer exited with code {proc.returncode}" + (f": {tail}" if tail else "")
    try:
        names = json.loads(proc.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return [], "the renderer printed no file list"
    missing = [n for n in names if not (out_dir / n).is_file()]
    if missing:
        return [], f"the renderer did not write {', '.join(missing)}"
    return names, None


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
            runs = [r for r in results if r["kind"] != "paired"]
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
                caption += "3D: terrain, boxes (red forbidden, tan safe), foot tracks by leg, footprints in white."
                progress(f"rendering {name}", done, total)
                names, error = render_scene(scene, tmp / "renders" / sname, work)
                done += 1
                if error:
                    warn(f"rendering {sname} failed: {error}")
                    render_errors.append(error)
                scene_notes.append({"scenario": sname, "renders": [f"renders/{sname}/{n}" for n in names],
                                    "heatmap_matches_crowd": (scene["heatmap"] or {}).get("matches_crowd")})
                scenes.append({"scenario": sname, "caption": caption, "plots": plots,
                               "renders": [(f"renders/{sname}/{n}", f"{sname}: {n}") for n in names],
                               "render_error": error})
            rec_page = None
            if rec is not None:
                progress("rendering the recording", done, total)
                scene = _recording_scene(rec)
                names, error = render_scene(scene, tmp / "renders" / "recording", work)
                done += 1
                if error:
                    warn(f"rendering the recording failed: {error}")
                    render_errors.append(error)
                h = rec["header"]
                rec_page = {"name": Path(recording).name, "renders": [(f"renders/recording/{n}", n) for n in names],
                            "render_error": error,
                            "caption": f"{h.get('creature')} on {h['scenario']}, {rec['feet'].shape[0]} frames, "
                                       f"{rec['feet'].shape[1]} characters (at most 10 drawn), LOD {h.get('lod')}."}
            progress("writing", done, total)
            meta = {"format": REPORT_FORMAT, "version": REPORT_VERSION, "footfall": __version__, "preset": preset,
                    "seed": int(seed), "scenarios": list(options.scenarios), "sizes": list(options.sizes),
                    "settings": list(options.settings), "frames": options.frames, "warmup": options.warmup,
                    "wall_seconds": time.perf_counter() - t_start}
            _write_csv(tmp / "results.csv", runs, task_columns(runs))
            paired_rows = [{"scenario": r["scenario"], "seed": r["seed"], "characters": r["characters"],
                            "situations": r["situations"], **b} for r in results if r["kind"] == "paired"
                           for b in r["budgets"]]
            if paired_rows:
                _write_csv(tmp / "paired.csv", paired_rows, list(paired_rows[0]))
            summary_columns = ([n for n, _, _ in _pareto.COLUMNS] + [n for n, _ in _pareto.PAIRED_COLUMNS]
                               + ["on_front", "recommended"])
            _write_csv(tmp / "summary.csv", analysis["rows"], summary_columns)
            summary = {**meta, "recommended_budget": analysis["recommended_budget"], "front": analysis["front"],
                       "tolerance_pct": analysis["tolerance_pct"], "rows": analysis["rows"],
                       "scenes": scene_notes, "render_errors": render_errors}
            (tmp / "results.json").write_text(json.dumps({**summary, "tasks": results}, indent=1))
            _html.write_index(tmp / "index.html", analysis=analysis, results=runs, meta=meta, scenes=scenes,
                              recording=rec_page)
        _publish(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    done += 1
    progress("done", done, total)
    summary["out"] = str(out)
    summary["index"] = str(out / "index.html")
    return summary
