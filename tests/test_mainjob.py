"""The main job (footfall run): simulate -> tune -> report -> export into one folder."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

CLI = [sys.executable, "-m", "footfall.cli"]


@pytest.mark.slow  # the whole main job (about 40 s; one run per session, conftest.main_job)
def test_run_writes_every_output_into_one_folder(main_job):
    from footfall.planner import load_preset
    from pxr import Usd, UsdSkel

    out, summary = main_job
    assert summary == json.loads((out / "summary.json").read_text())
    assert set(summary["seconds"]) == {"simulate", "tune", "report", "export", "total"}
    # the recording is the simulate step's run
    with np.load(out / "recording.npz") as rec:
        header = json.loads(str(rec["header"]))
        assert header["scenario"] == "mixed" and rec["feet"].shape[0] == summary["simulate"]["frames"]
    # the preset loads for the scenario's creature, and is what the export ran with
    preset = load_preset(out / "preset.json", "spider")
    assert preset.creature == "spider"
    # the report names the recommended budget and has its page
    assert (out / "report" / "index.html").is_file() and summary["report"]["recommended_budget"]
    # the USD scene has one skeleton per exported character
    stage = Usd.Stage.Open(str(out / "scene.usdc"))
    skeletons = [p for p in stage.Traverse() if p.IsA(UsdSkel.Skeleton)]
    assert len(skeletons) >= 1
    assert summary["export"]["collisions"] == 0 and summary["simulate"]["collisions"] == 0
    # the clip of the recorded crowd: at least 60 frames at 30 fps
    import imageio.v2 as imageio

    reader = imageio.get_reader(out / "clip.mp4", format="FFMPEG")
    frames = sum(1 for _ in reader)
    reader.close()
    assert frames >= 60 and summary["outputs"]["clip"] == str(out / "clip.mp4")
    names = {p.name for p in out.iterdir()}
    assert {"preset.json", "recording.npz", "report", "scene.usdc", "summary.json", "clip.mp4"} <= names
    assert not [n for n in names if n.startswith(".")], names  # no temporary file left behind


def test_run_refuses_an_output_that_is_a_file(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    proc = subprocess.run(CLI + ["run", "--quick", "--out", str(blocker)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "--out" in lines[0], proc.stderr
    assert blocker.read_text() == "x"
