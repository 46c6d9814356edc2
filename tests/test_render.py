"""Renders with the creatures and ``footfall render`` clips (issue 16, items 1 and 2).

Every render runs in a subprocess (VTK may crash without GL), headless through EGL.
"""

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import footfall_cli

pytestmark = pytest.mark.slow  # pyvista renders in subprocesses (about 25 s)

CLI = [sys.executable, "-m", "footfall.cli"]
HEADLESS = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
CREATURE_KEYS = ("joints", "rotations", "body_size", "leg_radius")


def footfall(*args, timeout=300):
    return subprocess.run(CLI + list(args), capture_output=True, text=True, timeout=timeout, env=HEADLESS)


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A 60-frame recording of one spider on flat ground (the clip's minimum length)."""
    path = tmp_path_factory.mktemp("render") / "flat.npz"
    proc = footfall("simulate", "flat", "--frames", "60", "--record", str(path), "--json")
    assert proc.returncode == 0, proc.stderr
    return path


@pytest.fixture(scope="module")
def scene(recording):
    from footfall.reports._animation import recording_clip_scene

    return recording_clip_scene(recording)


def _pixels(path):
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB")).astype(np.int16)


def test_the_scene_puts_legs_on_the_body_and_feet_on_the_ground(scene, recording):
    from footfall.reports._recording import load_recording
    from footfall.scenarios import load_creature

    joints, pelvis, rotations = scene["joints"], scene["pelvis"], scene["rotations"]
    creature = load_creature("spider")
    assert joints.shape == (60, 1, creature.n_legs, creature.segment_lengths.shape[1] + 1, 3)
    # The hips sit on the body: pelvis + R @ hip of the creature.
    hips = pelvis[:, :, None, :] + np.einsum("fcij,lj->fcli", rotations, creature.hips)
    np.testing.assert_allclose(joints[:, :, :, 0], hips, atol=1e-6)
    # The feet end where the recording says they are (IK on: the FK foot; residual below 2 mm).
    run = load_recording(recording)
    assert run.ik_on.all()
    assert np.abs(joints[:, :, :, -1] - run.feet).max() < 5e-3
    # Segment lengths are the creature's.
    lengths = np.linalg.norm(np.diff(joints, axis=3), axis=-1)
    np.testing.assert_allclose(lengths, np.broadcast_to(creature.segment_lengths, lengths.shape), atol=1e-6)


def test_every_render_shows_the_creature(scene, tmp_path):
    """The same frame with and without the creatures: many pixels differ where the creature is."""
    from footfall.reports._animation import render_stills

    size = (320, 240)
    with_dir, without_dir = tmp_path / "with", tmp_path / "without"
    names = render_stills(scene, with_dir, regions=tmp_path / "regions.json", size=size)
    assert names == ["scene_overview.png", "scene_closeup.png"]
    bare = {k: v for k, v in scene.items() if k not in CREATURE_KEYS}
    assert render_stills(bare, without_dir, size=size) == names
    regions = json.loads((tmp_path / "regions.json").read_text())
    for name in names:
        a, b = _pixels(with_dir / name), _pixels(without_dir / name)
        left, top, right, bottom = regions[name]["characters"][0]
        assert 0 <= left < right <= size[0] and 0 <= top < bottom <= size[1], (name, regions[name])
        box = (slice(int(top), int(np.ceil(bottom))), slice(int(left), int(np.ceil(right))))
        changed = (np.abs(a - b).max(axis=2) > 40)
        inside = int(changed[box].sum())
        area = changed[box].size
        # The body and the legs cover a good part of the creature's box, in the overview too.
        assert inside >= 60 and inside >= 0.08 * area, (name, inside, area)
        # ... and little changes elsewhere (the framing is the same) but the legend's wording.
        outside = changed.copy()
        outside[box] = False
        l, t, r, b = regions[name]["legend"]
        outside[t:b, l:r] = False
        assert outside.sum() < 0.1 * inside, (name, int(outside.sum()), inside)


def test_render_writes_a_video_of_the_expected_length(recording, tmp_path):
    import imageio.v2 as imageio

    out = tmp_path / "clip.mp4"
    proc = footfall("render", "--recording", str(recording), "--out", str(out), "--frames", "60", "--width", "320",
                    "--height", "240", "--camera", "fixed")
    assert proc.returncode == 0, proc.stderr
    assert "60 frames, 2.00 s at 30 fps" in proc.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.mp4"]  # no temporary file left
    reader = imageio.get_reader(out, format="FFMPEG")
    meta = reader.get_meta_data()
    frames = [f for f in reader]
    reader.close()
    assert len(frames) == 60
    assert meta["fps"] == pytest.approx(30.0)
    assert meta["duration"] == pytest.approx(60 / 30.0, abs=0.05)
    assert frames[0].shape == (240, 320, 3)
    # It moves: the first and the last frame differ (the fixed camera holds still, the spider walks).
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).max(axis=2).__gt__(40).sum() > 200


def test_render_writes_a_gif(recording, tmp_path):
    from PIL import Image

    out = tmp_path / "clip.gif"
    proc = footfall("render", "--recording", str(recording), "--out", str(out), "--frames", "6", "--width", "160",
                    "--height", "120")
    assert proc.returncode == 0, proc.stderr
    with Image.open(out) as gif:
        assert gif.n_frames == 6 and gif.size == (160, 120)


@pytest.mark.parametrize("args, field", [
    (["--out", "clip.avi"], "argument: --out"),
    (["--out", "clip.mp4", "--frames", "0"], "argument: --frames"),
    (["--out", "clip.mp4", "--camera", "orbit"], "argument: --camera"),
    (["--out", "clip.mp4", "--width", "0"], "argument: --width"),
    (["--out", "clip.mp4", "--height", "-5"], "argument: --height"),
    (["--out", "clip.mp4", "--recording", "missing.npz"], "missing.npz: file"),
    (["flat", "--out", "clip.mp4", "--recording", "RECORDING"], "argument: --recording"),
    (["--out", "clip.mp4", "--recording", "RECORDING", "--frames", "61"], "frames: expected 1 to 60 frames"),
])
def test_bad_input_is_one_line_and_exit_2(recording, tmp_path, args, field):
    args = [str(recording) if a == "RECORDING" else str(tmp_path / a) if a.endswith((".avi", ".mp4", ".npz"))
            else a for a in args]
    proc = footfall_cli("render", *args)  # refused before any rendering: in-process
    assert proc.returncode == 2, (proc.stdout, proc.stderr)
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("footfall: error: ") and field in lines[0], proc.stderr
    assert not any(p.suffix in (".mp4", ".avi") for p in tmp_path.iterdir())


def test_a_failing_renderer_is_one_line(tmp_path):
    from footfall.reports._animation import RenderError, run_renderer

    with pytest.raises(RenderError) as failure:
        run_renderer(["clip", str(tmp_path / "no-scene.npz"), str(tmp_path / "x.mp4")], timeout=120)
    message = str(failure.value)
    assert "\n" not in message and message.startswith("the renderer exited with code 1: ") and "no-scene" in message


def test_a_recording_of_a_scenario_file_finds_its_scenario_again(tmp_path):
    # `footfall render my.toml` simulated, then looked the scenario up by its name ("unknown scenario"):
    # a recording of a user's scenario file carries the file's path, and its scene is built from it.
    from footfall.reports._animation import recording_clip_scene
    from footfall.reports._recording import load_recording

    scenario = tmp_path / "my-walk.toml"  # a name no built-in has
    scenario.write_text('name = "my-walk"\nseed = 0\n[terrain]\nkind = "flat"\nsize = [6.0, 6.0]\ncell_size = 0.05\n'
                        '[crowd]\ncreature = "spider"\ncentre = [0.0, 0.0]\nheading = 0.0\nspeed = 0.2\n'
                        'goal = [1.0, 0.0]\n')
    path = tmp_path / "walk.npz"
    result = footfall_cli("simulate", scenario, "--frames", "60", "--record", path, "--json")
    assert result.returncode == 0, result.stderr
    run = load_recording(path)
    assert run.load_scenario().source == str(scenario.resolve())
    assert recording_clip_scene(path)  # built (it raised "unknown scenario")
