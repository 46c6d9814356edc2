"""Offscreen 3D pictures of a scene (pyvista): terrain, boxes, foot trajectories, footprints.

Run in its own process, ``python -m reports._render SCENE.npz OUT_DIR``, so that a
crash of VTK (no GL library on the machine) cannot take the report with it. The
report sets ``VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow`` (headless EGL). Writes
``scene_overview.png`` and ``scene_closeup.png`` into OUT_DIR and prints their names
as one JSON list on stdout. World y is up.
"""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path

import numpy as np

WINDOW = (1024, 720)
MAX_TERRAIN_SAMPLES = 240  # per side: finer terrain adds nothing at this picture size
TRACK_LIFT_M = 0.004  # drawn just above the ground so lines are not hidden in it


def _terrain(pv, scene):
    h = scene["terrain_heights"]
    step = max(1, math.ceil(max(h.shape) / MAX_TERRAIN_SAMPLES))
    h = h[::step, ::step]
    cell = float(scene["terrain_cell"]) * step
    x0, z0 = scene["terrain_origin"]
    xs = x0 + np.arange(h.shape[1]) * cell
    zs = z0 + np.arange(h.shape[0]) * cell
    x, z = np.meshgrid(xs, zs)
    grid = pv.StructuredGrid(x, h, z)
    grid["height_m"] = h.ravel(order="F")
    return grid


def _boxes(pv, scene, forbidden: bool):
    blocks = []
    for c, s, yaw, f in zip(scene["box_centres"], scene["box_sizes"], scene["box_yaws"], scene["box_forbidden"]):
        if bool(f) != forbidden:
            continue
        cube = pv.Cube(center=tuple(c), x_length=s[0], y_length=s[1], z_length=s[2])
        # Local x is world (cos yaw, 0, sin yaw): a turn of -yaw about +y (right-handed).
        blocks.append(cube.rotate_y(-math.degrees(float(yaw)), point=tuple(c)))
    return pv.merge(blocks) if blocks else None


def _tracks(pv, feet):
    """(F, C, L, 3) foot positions -> one polyline per foot, scalars = leg index."""
    f, c, legs, _ = feet.shape
    pts = feet.transpose(1, 2, 0, 3).reshape(-1, 3).copy()
    pts[:, 1] += TRACK_LIFT_M
    lines = []
    leg_of = []
    for k in range(c * legs):
        lines.append(np.concatenate([[f], np.arange(k * f, (k + 1) * f)]))
        leg_of.append(np.full(f, k % legs))
    poly = pv.PolyData(pts, lines=np.concatenate(lines))
    poly["leg"] = np.concatenate(leg_of).astype(np.float64)
    return poly


def _plotter(pv, scene, focus, distance):
    p = pv.Plotter(off_screen=True, window_size=WINDOW)
    p.set_background("#dfe9f3", top="#ffffff")
    terrain = _terrain(pv, scene)
    low, high = float(terrain["height_m"].min()), float(terrain["height_m"].max())
    span = max(high - low, 0.2)
    # The colour map's low end is water blue: start a quarter span lower so the ground (flat too) is green-brown.
    p.add_mesh(terrain, scalars="height_m", cmap="terrain", clim=(low - 0.35 * span, high + 0.05 * span),
               show_scalar_bar=False, smooth_shading=True)
    for forbidden, colour in ((True, "#c0392b"), (False, "#d9b26f")):
        boxes = _boxes(pv, scene, forbidden)
        if boxes is not None:
            p.add_mesh(boxes, color=colour, show_edges=True, edge_color="#333333", opacity=0.9)
    p.add_mesh(_tracks(pv, scene["feet"]), scalars="leg", cmap="tab10", line_width=2.5, show_scalar_bar=False)
    pelvis = scene["pelvis"]
    for c in range(pelvis.shape[1]):
        p.add_mesh(pv.lines_from_points(pelvis[:, c]), color="#222222", line_width=1.5)
    if len(scene["footprints"]):
        prints = scene["footprints"].copy()
        prints[:, 1] += TRACK_LIFT_M
        p.add_points(prints, color="white", point_size=7, render_points_as_spheres=True)
    direction = np.array([-math.cos(0.9), math.sin(0.9), -0.35])
    direction /= np.linalg.norm(direction)
    p.camera_position = [tuple(focus + distance * direction), tuple(focus), (0.0, 1.0, 0.0)]
    return p


def render(scene_path, out_dir) -> list[str]:
    import pyvista as pv

    with np.load(scene_path, allow_pickle=False) as data:
        scene = {k: data[k] for k in data.files}
    out_dir = Path(out_dir)
    pelvis = scene["pelvis"]
    tracks = scene["feet"].reshape(-1, 3)
    lo, hi = tracks.min(axis=0), tracks.max(axis=0)
    centre = 0.5 * (lo + hi)
    span = float(max(hi[0] - lo[0], hi[2] - lo[2], 1.0))
    written = []
    for name, focus, distance in (("scene_overview.png", centre, 1.6 * span + 2.0),
                                  ("scene_closeup.png", pelvis[-1, 0], 1.6)):
        p = _plotter(pv, scene, np.asarray(focus, dtype=np.float64), distance)
        p.screenshot(str(out_dir / name))
        p.close()
        written.append(name)
    return written


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print("usage: python -m reports._render SCENE.npz OUT_DIR", file=sys.stderr)
        return 2
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    print(json.dumps(render(argv[0], argv[1])))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
