"""Scenes of creatures for the renderer, and clips of a crowd walking (``footfall render``).

A recording (:mod:`reports._recording`) holds per frame the pelvis pose and the IK joint angles;
:func:`recording_scene` turns it into the renderer's scene (:mod:`reports._render`): the joints
of every leg by forward kinematics (:func:`planner._counters.rendered_joints`, the pose the
safety counters measure), the body rotations, the boxes at every frame, the creature's body size.
:func:`render_clip` draws it into a video in a subprocess (VTK may crash without GL; the caller
then gets one line, :class:`RenderError`) and writes the file atomically.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from footfall._errors import InputError

CLIP_SUFFIXES = (".mp4", ".gif")
CAMERAS = ("follow", "fixed")
DEFAULT_SIZE = (960, 540)
DEFAULT_SIMULATED_FRAMES = 90
MAX_DRAWN_CHARACTERS = 50
"""A bigger crowd is drawn up to this many characters (the first ones)."""
MAX_SIDE_PX = 4096
RENDER_TIMEOUT_S_PER_FRAME = 10.0
LEG_RADIUS_OF_BODY_WIDTH = 0.05
"""Leg tubes' radius as a fraction of the body box's width (at least 2 mm: thin legs vanish at a distance)."""


class RenderError(RuntimeError):
    """The renderer subprocess failed; the message is one line."""


def check_clip_options(out, frames: int | None, camera: str, width: int, height: int) -> Path:
    """The output path of a clip, or an :class:`InputError` naming the bad option (before any work)."""
    from footfall._atomic import unwritable_reason

    path = Path(out)
    if path.suffix.lower() not in CLIP_SUFFIXES:
        raise InputError("argument", "--out", f"expected a .mp4 or .gif path, got {str(out)!r}")
    if path.exists() and path.is_dir():
        raise InputError("argument", "--out", f"{out} is a folder")
    if frames is not None and frames < 1:
        raise InputError("argument", "--frames", f"expected an integer >= 1, got {frames}")
    if camera not in CAMERAS:
        raise InputError("argument", "--camera", f"expected one of {', '.join(CAMERAS)}, got {camera!r}")
    for option, value in (("--width", width), ("--height", height)):
        if not 1 <= value <= MAX_SIDE_PX:
            raise InputError("argument", option, f"expected a number of pixels from 1 to {MAX_SIDE_PX}, got {value}")
    reason = unwritable_reason(path.absolute().parent)
    if reason:
        raise InputError("argument", "--out", reason)
    return path


def joint_positions(recording, creature, characters: int | None = None) -> np.ndarray:
    """(F, C, L, S + 1, 3) hip, knees..., foot of every leg at every frame of ``recording`` (of its
    first ``characters`` characters: C; default all).

    Forward kinematics of the recorded IK angles through :func:`planner._counters.rendered_joints`
    (straight hip -> planned foot legs where the IK was off), fed the recording's frames as one
    crowd of F x C characters.
    """
    from footfall.planner._counters import rendered_joints
    from footfall.planner._ik import legs_of

    f, c, legs = recording.in_stance.shape
    c = c if characters is None else min(c, characters)
    segments = recording.segments
    if legs != creature.n_legs or segments != np.asarray(creature.segment_lengths).shape[1]:
        raise InputError(recording.path, "joint_angles", f"{legs} legs of {segments} segments do not match the "
                         f"creature {creature.name!r} ({creature.n_legs} legs of "
                         f"{np.asarray(creature.segment_lengths).shape[1]} segments)")
    model = SimpleNamespace(leg_static=legs_of(creature), hips_body=np.asarray(creature.hips, dtype=np.float64))
    def first(a: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(a[:, :c]).reshape((f * c,) + a.shape[2:])

    o = first(recording.orientation)
    state = SimpleNamespace(heading=o[:, 0].copy(), pitch=o[:, 1].copy(), roll=o[:, 2].copy(),
                            pelvis=first(recording.pelvis), in_stance=first(recording.in_stance),
                            angles=first(recording.joint_angles), ik_on=first(recording.ik_on),
                            feet=first(recording.feet))
    return rendered_joints(model, state).reshape(f, c, legs, -1, 3)


def recording_scene(recording, scenario, creature, max_characters: int | None = None) -> dict:
    """The renderer's scene (:mod:`reports._render`) of a recording: terrain, the boxes at every
    frame, the first ``max_characters`` characters' tracks, footprints, bodies and legs."""
    from footfall.planner._ik import body_rotation

    n = recording.characters if max_characters is None else min(max_characters, recording.characters)
    joints = joint_positions(recording, creature, n)
    o = recording.orientation[:, :n]
    feet = recording.feet[:, :n]
    stance = recording.in_stance[:, :n]
    down = np.zeros_like(stance)
    down[1:] = stance[1:] & ~stance[:-1]
    fk, ck, lk = np.nonzero(down)
    times = recording.times
    obstacles = scenario.obstacles
    poses = [obstacles.poses_at(float(t)) for t in times]
    centres_t = np.asarray([np.asarray(p[0], np.float64).reshape(-1, 3) for p in poses])
    yaws_t = np.asarray([np.asarray(p[1], np.float64).reshape(-1) for p in poses])
    t = scenario.terrain
    box = np.asarray(creature.body_box, dtype=np.float64)
    return {
        "terrain_heights": np.asarray(t.heights, np.float64), "terrain_origin": np.array([t.origin_x, t.origin_z]),
        "terrain_cell": float(t.cell_size),
        "box_centres": centres_t[-1], "box_sizes": np.asarray(obstacles.sizes, np.float64).reshape(-1, 3),
        "box_yaws": yaws_t[-1], "box_forbidden": np.asarray(obstacles.forbidden, bool).reshape(-1),
        "box_centres_t": centres_t, "box_yaws_t": yaws_t,
        "feet": feet, "pelvis": recording.pelvis[:, :n], "footprints": feet[fk, ck, lk], "footprint_frames": fk,
        "joints": joints, "rotations": body_rotation(o[..., 0], o[..., 1], o[..., 2]),
        "body_size": np.array([box[0], float(creature.body_thickness), box[1]]),
        "leg_radius": max(0.002, LEG_RADIUS_OF_BODY_WIDTH * float(box[1])),
        "dt": recording.dt,
        "title": f"{creature.name} on {scenario.name}, {n} of {recording.characters} characters"
                 if n < recording.characters else f"{n} x {creature.name} on {scenario.name}",
    }


def save_scene(scene: dict, path: Path) -> Path:
    np.savez(path, **{k: np.asarray(v) for k, v in scene.items()})
    return path


def run_renderer(args: list[str], timeout: float, progress=None) -> dict | list:
    """Run ``python -m footfall.reports._render ARGS``; returns its last stdout line (JSON). ``progress(k, n)``
    for its ``frame K N`` lines. A crash, a timeout or no result raise :class:`RenderError` (one line)."""
    import threading

    env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW=os.environ.get("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow"))
    with tempfile.TemporaryFile(mode="w+") as err:
        proc = subprocess.Popen([sys.executable, "-m", "footfall.reports._render", *args], stdout=subprocess.PIPE,
                                stderr=err, text=True, env=env)
        timed_out = []

        def stop() -> None:
            timed_out.append(True)
            proc.kill()

        timer = threading.Timer(timeout, stop)
        timer.start()
        last = ""
        try:
            for line in proc.stdout:
                line = line.strip()
                if line.startswith("frame ") and progress is not None:
                    k, n = line.split()[1:3]
                    progress(int(k), int(n))
                elif line:
                    last = line
            code = proc.wait()
        finally:
            timer.cancel()
            proc.stdout.close()
        if timed_out:
            raise RenderError(f"the renderer did not finish in {timeout:.0f} s")
        if code != 0:
            err.seek(0)
            lines = [ln for ln in err.read().strip().splitlines() if ln.strip()]
            tail = re.sub(r"\x1b\[[0-9;]*m", "", lines[-1]).strip() if lines else ""  # VTK colours its log
            raise RenderError(f"the renderer exited with code {code}" + (f": {tail}" if tail else ""))
    try:
        return json.loads(last)
    except ValueError:
        raise RenderError("the renderer printed no result") from None


def render_clip(scene: dict, out, *, camera: str = "follow", size: tuple[int, int] = DEFAULT_SIZE,
                progress=None) -> dict:
    """Render ``scene`` (every frame) into ``out`` (.mp4 or .gif) atomically, at the recording's
    rate (1 / dt frames per second); returns ``{"path", "frames", "fps", "seconds", ...}``."""
    from footfall._atomic import atomic_path

    out = Path(out)
    frames = int(np.asarray(scene["pelvis"]).shape[0])
    fps = 1.0 / float(scene["dt"])
    with tempfile.TemporaryDirectory(prefix="footfall-clip-") as work:
        npz = save_scene(scene, Path(work) / "scene.npz")
        with atomic_path(out) as tmp:
            result = run_renderer(["clip", str(npz), str(tmp), "--camera", camera, "--width", str(size[0]),
                                   "--height", str(size[1]), "--fps", repr(fps)],
                                  timeout=60.0 + RENDER_TIMEOUT_S_PER_FRAME * frames, progress=progress)
            if not tmp.is_file() or tmp.stat().st_size == 0:
                raise RenderError("the renderer wrote no video")
    return dict(result, path=str(out), seconds=frames / float(result["fps"]))


def render_stills(scene: dict, out_dir, regions=None, size: tuple[int, int] | None = None) -> list[str]:
    """``scene_overview.png`` and ``scene_closeup.png`` of ``scene`` into ``out_dir`` (subprocess)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="footfall-stills-") as work:
        npz = save_scene(scene, Path(work) / "scene.npz")
        args = [str(npz), str(out_dir)] + (["--regions", str(regions)] if regions else [])
        if size:
            args += ["--width", str(size[0]), "--height", str(size[1])]
        names = run_renderer(args, timeout=180.0)
    missing = [n for n in names if not (out_dir / n).is_file()]
    if missing:
        raise RenderError(f"the renderer did not write {', '.join(missing)}")
    return names


def run_scene(run, frames: int | None = None, max_characters: int | None = MAX_DRAWN_CHARACTERS) -> dict:
    """The scene of the first ``frames`` frames of a loaded recording, its scenario from the file it
    was run from or by name (:meth:`Recording.load_scenario`) and its creature by name or from the
    creature file it carries (an :class:`InputError` when one is not at hand)."""
    if frames is not None:
        run = run.head(frames)
    return recording_scene(run, run.load_scenario(), run.load_creature(), max_characters)


def recording_clip_scene(recording_path, frames: int | None = None,
                         max_characters: int | None = MAX_DRAWN_CHARACTERS) -> dict:
    """The scene of the first ``frames`` frames of a recording (``footfall render --recording F``);
    an :class:`InputError` for a file that is not a recording of a known scenario and creature."""
    from footfall.reports._recording import load_recording

    run = load_recording(recording_path)
    if not run.scenario:
        raise InputError(run.path, "header.scenario", "missing: the recording does not name its scenario")
    return run_scene(run, frames, max_characters)
