"""``footfall report``: the quick report end to end, its data, plots, renders and page; bad input."""

import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest
from conftest import footfall_cli

CLI = [sys.executable, "-m", "footfall.cli"]
HEADLESS = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")


def run(*args, timeout=600):
    return subprocess.run(CLI + list(args), capture_output=True, text=True, timeout=timeout, env=HEADLESS)


@pytest.fixture(scope="module")
def quick(main_job):
    """The quick report of the session's main job (``footfall run --quick``: the quick sweep and the
    recording's renders; conftest.main_job): (folder, summary as ``footfall report --json`` prints it,
    read back from its ``results.json``). Its wall time is a benchmark, not a test:
    ``python -m footfall.benchmarks.report_bench``."""
    job_out, job = main_job
    out = job_out / "report"
    summary = {k: v for k, v in json.loads((out / "results.json").read_text()).items() if k != "tasks"}
    return out, dict(summary, out=str(out), index=job["report"]["index"])


def _image_stats(path):
    """(pixel standard deviation, number of colours, fraction of near-black pixels)."""
    from PIL import Image

    a = np.asarray(Image.open(path).convert("RGB")).astype(np.float64)
    colours = np.unique(a.reshape(-1, 3), axis=0).shape[0]
    return float(a.std()), colours, float((a.max(axis=2) < 30).mean())


# ----------------------------------------------------------------------------- the quick report


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_quick_report_writes_a_complete_folder(quick):
    out, summary = quick
    for name in ("index.html", "results.csv", "summary.csv", "paired.csv", "results.json", "pareto.png",
                 "stride.png"):
        assert (out / name).is_file(), name
    # No temporary folder left beside it: it was renamed, not copied.
    assert not [p.name for p in out.parent.iterdir() if p.name.startswith(".")]
    assert summary["index"] == str(out / "index.html")
    assert summary["recommended_budget"] in {r["setting"] for r in summary["rows"]}
    assert summary["render_errors"] == []


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_csv_and_json_agree(quick):
    out, summary = quick
    data = json.loads((out / "results.json").read_text())
    runs = [t for t in data["tasks"] if t["kind"] not in ("paired", "lod-scaling")]
    with open(out / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(runs) > 0
    for row, task in zip(rows, runs):
        assert set(row) <= set(task)
        for key, text in row.items():
            value = task[key]
            if value is None:
                assert text == ""
            elif isinstance(value, bool):
                assert text == str(value)
            elif isinstance(value, (int, float)):
                assert math.isclose(float(text), value, rel_tol=1e-12, abs_tol=0.0), key
            else:
                assert text == str(value)
    with open(out / "summary.csv", newline="") as fh:
        summary_rows = list(csv.DictReader(fh))
    assert [r["setting"] for r in summary_rows] == [r["setting"] for r in data["rows"]]
    for row, ref in zip(summary_rows, data["rows"]):
        for key in ("paired_cost_vs_first_valid", "paired_cost_ci_low", "paired_cost_ci_high", "paired_us_per_foot",
                    "paired_loss_pct", "score_loss_pct", "ms_per_character"):
            if ref[key] is None:
                assert row[key] == ""
            else:
                assert math.isclose(float(row[key]), ref[key], rel_tol=1e-12), key
    assert data["rows"] == summary["rows"]


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_pareto_front_and_recommended_budget(quick):
    from footfall.reports._pareto import COST, LOSS, dominates

    _, summary = quick
    budgets = [r for r in summary["rows"] if r["kind"] == "budget"]
    assert len(budgets) >= 3
    front = [r for r in budgets if r["on_front"]]
    assert front and [r["setting"] for r in sorted(front, key=lambda r: (r[COST], r[LOSS]))] == summary["front"]
    for r in budgets:
        beaten = any(dominates(o, r, COST, LOSS) for o in budgets if o is not r)
        assert beaten != r["on_front"], r["setting"]
    rec = next(r for r in budgets if r["setting"] == summary["recommended_budget"])
    assert rec["recommended"]
    best = min(r[LOSS] for r in budgets)
    eligible = [r for r in budgets if r[LOSS] <= best + summary["tolerance_pct"]]
    assert rec in eligible
    # Cheaper only beyond the noise: the recommended budget's cost interval reaches the cheapest
    # eligible one's, and no budget that does so loses less.
    cheapest = min(eligible, key=lambda r: (r[COST], r[LOSS]))
    assert rec["paired_cost_ci_low"] <= cheapest["paired_cost_ci_high"]
    as_cheap = [r for r in eligible if r["paired_cost_ci_low"] <= cheapest["paired_cost_ci_high"]]
    assert rec[LOSS] == min(r[LOSS] for r in as_cheap)
    for r in budgets:
        assert r["paired_cost_ci_low"] <= r[COST] <= r["paired_cost_ci_high"], r["setting"]


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_lod_section_has_scaling_and_quality_per_level(quick):
    from footfall.reports._lod_report import LEVEL_TABLE

    out, summary = quick
    lod = summary["lod"]
    modes = {r["mode"] for r in lod["scaling"]}
    assert modes == {"on", "zoomed", "off"}
    assert {r["characters"] for r in lod["scaling"]} == {4, 24}
    for r in lod["scaling"]:
        assert r["ci_low"] <= r["ms_per_frame"] <= r["ci_high"]
        assert r["ratio_ci_low"] <= r["ratio_on_off"] <= r["ratio_ci_high"]
    assert {(r["mode"], r["level"]) for r in lod["levels"]} >= {("off", "full (no LOD)"), ("on", "full")}
    assert len(LEVEL_TABLE) <= 10
    page = (out / "index.html").read_text()
    assert "lod_scaling.png" in page and "lod_levels.csv" in page
    for name in ("lod_scaling.png", "lod_levels.csv", "lod_scaling.csv"):
        assert (out / name).is_file(), name


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_exhaustive_search_is_never_beaten(quick):
    out, _ = quick
    data = json.loads((out / "results.json").read_text())
    for task in data["tasks"]:
        if task["kind"] == "paired":
            for b in task["budgets"]:
                assert b["score_loss_pct"] >= -1e-9, b
        elif task["kind"] == "lod-scaling":
            continue
        else:
            assert task["situations"] > 0
            assert task["deficit_min"] >= -1e-9, task["setting"]
            assert task["missed_plans"] == 0
    # The unlimited budget with 10 cm slices is the paper's full search, i.e. LOD off: same decisions.
    by = {t["setting"]: t for t in data["tasks"] if t["kind"] not in ("paired", "lod-scaling")
          and t["characters"] == min(data["sizes"])}
    for key in ("planner_calls", "cells_expanded", "deficit_mean", "collisions", "leg_crossings", "steps"):
        assert by["budget-cinf-s0.10"][key] == by["lod-off"][key], key


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_fig13_situation_is_the_crowds_plan(quick):
    _, summary = quick
    assert summary["scenes"] and all(s["heatmap_matches_crowd"] for s in summary["scenes"])


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_report_pictures_are_not_blank(quick):
    out, summary = quick
    pictures = [out / "pareto.png", out / "stride.png"] + sorted(out.glob("gait_disks_*.png")) \
        + sorted(out.glob("footprints_*.png")) + [out / r for s in summary["scenes"] for r in s["renders"]]
    assert len([p for p in pictures if "renders" in str(p)]) == 2 * len(summary["scenes"])
    for p in pictures:
        std, colours, dark = _image_stats(p)
        assert std > 8.0 and colours > 16 and dark < 0.5, (p.name, std, colours, dark)


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_index_leads_with_a_short_table_and_keeps_the_full_one_behind_a_toggle(quick):
    out, summary = quick
    page = (out / "index.html").read_text(encoding="utf-8")
    quality = page[page.index("<h2>Quality vs cost</h2>"):page.index("<h2>Stride length vs speed</h2>")]
    tables = re.findall(r"<table>.*?</table>", quality, flags=re.S)
    assert len(tables) == 2
    short, full = (re.findall(r'<th title="[^"]*">(.*?)</th>', t) for t in tables)
    assert len(short) <= 10 and len(full) > len(short)
    assert short[:3] == ["setting", "cost (x first valid)", "loss %"]
    assert quality.index("<details>") < quality.index(tables[1])  # the full table only behind the toggle
    assert len(re.findall(r"<tr class", tables[0])) == len(summary["rows"])
    # Every scene plot says what its marks mean.
    for name in ("gait_disks_", "footprints_"):
        caption = re.search(rf'src="{name}[^"]*"[^>]*><figcaption>(.*?)</figcaption>', page)
        assert caption and len(caption.group(1)) > 200, name


# ----------------------------------------------------------------------------- the footprint and gait plots


def _heatmap(scores, chosen_end):
    """A Fig. 13 situation of a 3 x 3 candidate block on flat ground, the chosen trajectory ending at ``chosen_end``."""
    cell = 0.07
    xs, zs = np.meshgrid(np.arange(3) * cell, np.arange(3) * cell)
    cells = np.column_stack([xs.ravel(), zs.ravel()]) + 0.5
    chosen = np.array([[0.45, 0.0, 0.45], [chosen_end[0], 0.02, chosen_end[1]]])
    return {"cell_size": cell, "cells_xz": cells, "scores": np.asarray(scores, np.float64), "chosen": chosen,
            "others": [chosen + [0.0, 0.0, 0.05]], "source": np.array([0.45, 0.0, 0.45]),
            "preferred": np.array([0.55, 0.55]), "forbidden_xz": np.array([[0.5, 0.75]]),
            "elevation": np.zeros((40, 40)), "origin": np.array([-0.5, -0.5]), "couple_score": 0.9}


def test_footprint_plot_marks_the_chosen_cell_and_fits_its_colours_to_the_candidates(tmp_path):
    from footfall.reports import _plots

    scores = np.linspace(0.78, 0.93, 9)
    h = _heatmap(scores, chosen_end=(0.5 + 0.07 + 0.01, 0.5 + 0.14 - 0.02))
    assert _plots.chosen_cell(h) == 7  # the cell the trajectory ends in, (x 1, z 2) of the block
    assert _plots.chosen_cell(_heatmap(scores, chosen_end=(2.0, 2.0))) is None  # off every candidate: no mark
    assert _plots.score_range(scores) == (0.78, 0.93)  # the colours span the candidates, not 0-1
    lo, hi = _plots.score_range([0.9, 0.9])
    assert lo < 0.9 < hi
    path = tmp_path / "footprints.png"
    _plots.footprint_heatmap({"heatmap": h}, path)
    std, colours, _ = _image_stats(path)
    assert std > 8.0 and colours > 16


def test_gait_disk_states_name_feet_off_their_schedule(tmp_path):
    from footfall.reports import _plots

    # Needle at 0.3: sectors [0.2, 0.5) and [0.6, 0.9); each foot on the ground or in the air.
    scene = {"gait_needle": 0.3, "gait_start": np.array([0.2, 0.6, 0.2, 0.6]),
             "gait_duration": np.array([0.3, 0.3, 0.3, 0.3]), "gait_in_stance": np.array([False, True, True, False]),
             "leg_names": ["A", "B", "C", "D"], "creature": "test", "gait_name": "test-gait"}
    assert _plots.gait_disk_states(scene) == ["swing", "stance", "hold", "forced"]
    scene["gait_start"] = np.array([0.9, 0.9, 0.9, 0.9])  # a sector across 12 o'clock: [0.9, 1.2)
    assert _plots.gait_disk_states(scene)[:2] == ["forced", "stance"]
    _plots.gait_disks(scene, tmp_path / "disks.png")
    std, colours, _ = _image_stats(tmp_path / "disks.png")
    assert std > 8.0 and colours > 16


# ----------------------------------------------------------------------------- renders and the page


def _tiny_scene(path):
    """A flat 4 x 4 m terrain with a forbidden and a safe box and two feet tracks."""
    t = np.linspace(0.0, 1.0, 30)
    feet = np.zeros((30, 1, 2, 3))
    feet[:, 0, 0] = np.column_stack([-1.0 + 2.0 * t, 0.05 * np.sin(6 * t), 0.2 + 0 * t])
    feet[:, 0, 1] = np.column_stack([-1.0 + 2.0 * t, 0.05 * np.cos(6 * t), -0.2 + 0 * t])
    np.savez(path, terrain_heights=np.zeros((21, 21)), terrain_origin=np.array([-2.0, -2.0]), terrain_cell=0.2,
             box_centres=np.array([[0.5, 0.15, 0.8], [-0.5, 0.1, -0.8]]),
             box_sizes=np.array([[0.4, 0.3, 0.4], [0.5, 0.2, 0.3]]), box_yaws=np.array([0.3, 0.0]),
             box_forbidden=np.array([True, False]), feet=feet, pelvis=feet.mean(axis=2) + [0, 0.1, 0],
             footprints=feet[::10, 0, 0])


def test_render_subprocess_writes_pictures_that_are_not_blank(tmp_path):
    scene = tmp_path / "scene.npz"
    _tiny_scene(scene)
    proc = subprocess.run([sys.executable, "-m", "footfall.reports._render", str(scene), str(tmp_path)], capture_output=True,
                          text=True, timeout=300, env=HEADLESS)
    assert proc.returncode == 0, proc.stderr
    names = json.loads(proc.stdout.strip().splitlines()[-1])
    assert names == ["scene_overview.png", "scene_closeup.png"]
    for name in names:
        # Not blank, and not black: a flat terrain once came out black (a colour map over a zero range).
        std, colours, dark = _image_stats(tmp_path / name)
        assert std > 8.0 and colours > 16 and dark < 0.5, (name, std, colours, dark)


CHECK_SCRIPT = """<script>
window.addEventListener('load', function () {
  var images = Array.prototype.slice.call(document.images);
  var broken = images.filter(function (i) { return !(i.complete && i.naturalWidth > 0); })
                     .map(function (i) { return i.getAttribute('src'); });
  var pre = document.createElement('pre');
  pre.id = 'image-check';
  pre.textContent = JSON.stringify({images: images.length, broken: broken});
  document.body.appendChild(pre);
});
</script>"""


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
@pytest.mark.skipif(shutil.which("chromium") is None, reason="Debian chromium is not installed")
def test_every_image_loads_in_headless_chromium(quick, tmp_path):
    out, _ = quick
    # A copy elsewhere: the folder must stand on its own (relative links only).
    copy = tmp_path / "copied-report"
    shutil.copytree(out, copy)
    page = (copy / "index.html").read_text(encoding="utf-8")
    expected = len(re.findall(r"<img ", page))
    assert expected >= 6
    (copy / "check.html").write_text(page.replace("</body>", CHECK_SCRIPT + "</body>"), encoding="utf-8")
    profile = tmp_path / "profile"
    proc = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                           "--no-first-run", "--disable-background-networking", "--disable-component-update",
                           "--disable-sync", f"--user-data-dir={profile}", "--allow-file-access-from-files",
                           "--virtual-time-budget=10000", "--dump-dom", (copy / "check.html").as_uri()],
                          capture_output=True, text=True, timeout=180)
    found = re.search(r'<pre id="image-check">(.*?)</pre>', proc.stdout, re.S)
    assert found, proc.stderr[-2000:]
    result = json.loads(found.group(1).replace("&quot;", '"'))
    assert result["images"] == expected
    assert result["broken"] == []


@pytest.mark.slow  # the main job's quick report (conftest.main_job)
def test_the_reports_clips_play_in_headless_chromium(quick, tmp_path):
    # The real report page (not a page made for the test): every <video> loads, lasts at least 60 frames
    # (2 s at 30 fps) and shows a picture in its middle; every image is not blank.
    from test_report_browser import CHECK_SCRIPT as MEDIA_SCRIPT
    from test_report_browser import CHROMIUM, media_check

    if CHROMIUM is None:
        pytest.skip("Debian chromium is not installed (.ci/run installs it)")
    out, summary = quick
    copy = tmp_path / "copied-report"  # the main job's folder is shared with other tests: it is only read
    shutil.copytree(out, copy)
    page = (copy / "index.html").read_text(encoding="utf-8")
    clips = len(re.findall(r"<video ", page))
    # one per swept scenario (at least one), and the main job's recording
    assert (out / "renders" / "recording" / "clip.mp4").is_file()
    assert clips == len([s for s in summary["scenes"] if s.get("clip")]) + 1 >= 2
    (copy / "media-check.html").write_text(page.replace("</body>", MEDIA_SCRIPT + "</body>"), encoding="utf-8")
    media = media_check(copy / "media-check.html", tmp_path)
    assert len(media["videos"]) == clips
    for video in media["videos"]:
        assert "error" not in video, video
        assert video["duration"] >= 60 / 30.0 - 0.05, video
        assert video["frame_spread"] > 8.0, video
    for image in media["images"]:
        assert image["loaded"] and image["spread"] > 8.0, image


# ----------------------------------------------------------------------------- bad input


def _one_line_error(proc, *needles):
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("footfall: error: ") and "Traceback" not in proc.stderr
    for needle in needles:
        assert needle in lines[0]
    assert proc.stdout == ""


def test_report_json_prints_what_the_report_returns(tmp_path, monkeypatch):
    # The quick report's tests read the main job's report (conftest.main_job); the command's own --json
    # line is what build_report returns, passed its arguments as given.
    import footfall.reports._report as report_module

    calls = []

    def build_report(out, **kwargs):
        calls.append((out, kwargs))
        return {"index": str(tmp_path / "r" / "index.html"), "rows": [{"setting": "lod-on"}]}

    monkeypatch.setattr(report_module, "build_report", build_report)
    proc = footfall_cli("report", "--quick", "flat", "--seed", "3", "--workers", "1", "--out", str(tmp_path / "r"),
                        "--json")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == {"index": str(tmp_path / "r" / "index.html"), "rows": [{"setting": "lod-on"}]}
    ((out, kwargs),) = calls
    assert str(out) == str(tmp_path / "r") and kwargs["preset"] == "quick" and kwargs["scenarios"] == ("flat",)
    assert kwargs["seed"] == 3 and kwargs["workers"] == 1 and kwargs["recording"] is None


def test_unknown_scenario_is_one_line_and_nothing_is_written(tmp_path):
    out = tmp_path / "report"
    _one_line_error(footfall_cli("report", "--quick", "no-such-place", "--out", str(out)), "no-such-place")
    assert list(tmp_path.iterdir()) == []


def test_unwritable_out_is_one_line_and_nothing_is_left(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    _one_line_error(footfall_cli("report", "--quick", "--out", str(blocker / "report")), "--out")
    assert list(tmp_path.iterdir()) == [blocker] and blocker.read_text() == "not a folder"


def test_a_folder_that_is_not_a_report_is_not_replaced(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    _one_line_error(footfall_cli("report", "--quick", "--out", str(out)), "--out", "not a footfall report")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine"] and (out / "notes.txt").read_text() == "keep me"


def test_recording_from_another_version_is_refused(tmp_path):
    recording = tmp_path / "old.npz"
    header = {"format": "footfall-recording", "version": 99, "footfall": "9.9.9", "scenario": "flat", "dt": 1 / 30}
    np.savez(recording, header=np.array(json.dumps(header)), feet=np.zeros((2, 1, 8, 3)),
             pelvis=np.zeros((2, 1, 3)), in_stance=np.ones((2, 1, 8), bool))
    out = tmp_path / "report"
    _one_line_error(footfall_cli("report", "--quick", "--recording", str(recording), "--out", str(out)), str(recording),
                    "version 99")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.npz"]


def test_a_failure_midway_leaves_the_previous_report_untouched(tmp_path):
    from footfall.reports._report import REPORT_FORMAT, build_report

    out = tmp_path / "report"
    out.mkdir()
    (out / "results.json").write_text(json.dumps({"format": REPORT_FORMAT}))
    (out / "index.html").write_text("previous")
    calls = []

    def progress(what, done, total):
        calls.append(what)
        if len(calls) == 2:  # after the first run of the sweep
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        build_report(out, preset="quick", progress=progress, workers=1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]
    assert (out / "index.html").read_text() == "previous"


# ----------------------------------------------------------------------------- metrics


def test_curvature_energy_of_an_arc_is_its_turn_squared_and_of_a_line_zero():
    from footfall.reports._sweep import curvature_energy

    for theta, radius in ((0.5, 0.1), (1.2, 3.0)):
        a = np.linspace(0.0, theta, 2001)
        arc = np.column_stack([radius * np.cos(a), np.full(a.size, 0.7), radius * np.sin(a)])
        # Only the middle 90 % of the arc counts: (0.9 theta)^2 over the whole length 1 -> theta^2 * 0.9.
        assert curvature_energy(arc) == pytest.approx(0.9 * theta**2, rel=2e-3)
    line = np.column_stack([np.linspace(0, 1, 50), np.sin(np.linspace(0, 3, 50)), np.linspace(0, 2, 50)])
    assert curvature_energy(line) == pytest.approx(0.0, abs=1e-12)  # climbing does not bend it horizontally


def test_realised_strides_and_target():
    from footfall.reports._sweep import realised_strides, target_stride_length

    # One foot touching down every 30 frames 0.3 m further, the pelvis at 0.3 m/s (dt 1/30): stride 0.3 m at 0.3 m/s.
    frames = 100
    stance = np.ones((frames, 1, 1), bool)
    stance[[10, 40, 70], 0, 0] = False
    feet = np.zeros((frames, 1, 1, 3))
    for k in range(frames):
        feet[k, 0, 0, 0] = 0.3 * (1 + (k > 10) + (k > 40) + (k > 70))
    pelvis = np.zeros((frames, 1, 3))
    pelvis[:, 0, 0] = 0.01 * np.arange(frames)
    speeds, strides = realised_strides(feet, stance, pelvis, 1 / 30)
    assert np.allclose(strides, 0.3) and np.allclose(speeds, 0.3) and strides.size == 2
    h = 0.12
    v = np.sqrt(9.81 * h)  # Fr = 1: lambda = 2.3 h
    assert target_stride_length(v, h) == pytest.approx(2.3 * h)


def test_pareto_front_of_known_points():
    from footfall.reports._pareto import pareto_front, recommend

    rows = [{"setting": s, "c": c, "l": l} for s, c, l in
            (("a", 1.0, 5.0), ("b", 2.0, 1.0), ("c", 3.0, 1.0), ("d", 2.5, 0.5), ("e", 4.0, 0.4), ("f", 1.5, 6.0))]
    assert pareto_front(rows, "c", "l") == ["a", "b", "d", "e"]
    assert recommend(rows, 0.1, "c", "l") == "d"  # within 0.1 of 0.4: d (0.5) and e; d is cheaper
    assert recommend(rows, 0.0, "c", "l") == "e"
    assert recommend(rows, 10.0, "c", "l") == "a"


def test_tasks_are_deterministic_for_a_seed():
    from footfall.reports._sweep import parse_setting, run_task, without_timings

    task = {"scenario": "crates", "seed": 3, "characters": 2, "frames": 20, "warmup": 5,
            **parse_setting("budget-c1-s0.20")}
    a, b = run_task(dict(task)), run_task(dict(task))
    assert without_timings(a) == without_timings(b)
    assert "ms_per_frame" in a and "ms_per_frame" not in without_timings(a)
    assert a["planner_calls"] > 0 and a["couples_after_first"] == 1 and a["slice_size_m"] == 0.2
