"""Offscreen 3D pictures and clips of a scene (pyvista): terrain, boxes, the creatures, their tracks.

Run in its own process, so that a crash of VTK (no GL library on the machine) cannot take the
caller with it; the callers set ``VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow`` (headless EGL).

``python -m footfall.reports._render SCENE.npz OUT_DIR [--regions FILE.json]``
    Writes ``scene_overview.png`` (the whole run: every track, the crowd at the last frame) and
    ``scene_closeup.png`` (the first character at the last frame and what is around it) into
    OUT_DIR and prints their names as one JSON list on stdout. ``--regions`` also writes, per
    picture, each drawn character's screen box and the legend's, ``[left, top, right, bottom]``
    in pixels (the tests look for the creature's pixels there).
``python -m footfall.reports._render clip SCENE.npz OUT.mp4|OUT.gif --camera follow|fixed --width W --height H --fps F``
    Renders every frame of the scene into a video (H.264 in MP4 through imageio's ffmpeg
    plugin, whose package ships its own ffmpeg; or an animated GIF through Pillow). Prints
    ``frame K N`` after each frame and, last, one JSON object (path, frames, fps, size).

The scene is an ``.npz`` of arrays (F frames, C characters, L legs, J joints per leg, B boxes;
world metres, y up): ``terrain_heights`` (rows along z, columns along x), ``terrain_origin``
(x, z), ``terrain_cell``; ``box_centres`` (B, 3), ``box_sizes``, ``box_yaws``,
``box_forbidden`` (the boxes at the last frame); ``feet`` (F, C, L, 3); ``pelvis`` (F, C, 3);
``footprints`` (N, 3). Optional, for the creatures: ``joints`` (F, C, L, J, 3) hip, knees...,
foot of every leg (forward kinematics of the recorded IK angles, :mod:`reports._animation`),
``rotations`` (F, C, 3, 3) body rotations (columns forward, up, left), ``body_size``
(length, thickness, width) and ``leg_radius``. Optional, for clips: ``box_centres_t`` (F, B, 3)
and ``box_yaws_t`` (F, B) (moving boxes), ``footprint_frames`` (N,) (when each footprint is
made), ``dt``, ``title``. Without ``joints`` no creature is drawn.
"""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path

import numpy as np

from footfall.reports._box_mesh import box_corners, faces_of

WINDOW = (1024, 720)
MAX_TERRAIN_SAMPLES = 240  # per side: finer terrain adds nothing at this picture size
TRACK_LIFT_M = 0.004  # drawn just above the ground so lines are not hidden in it
VIEW_ANGLE_DEG = 30.0  # the camera's vertical field of view (VTK's default)
VIEW_DIRECTION = np.array([-math.cos(0.9), math.sin(0.9), -0.35])  # from the focus towards the camera
FRAME_MARGIN = 1.25  # the framed sphere fills 1 / FRAME_MARGIN of the narrower field of view
FOLLOW_SMOOTHING_FRAMES = 31  # the follow camera's centre is a moving average over about 1 s
# One colour per character (drawn in turn): vivid, and far from the terrain's greens and browns and
# from the forbidden boxes' red.
CHARACTER_COLOURS = ("#1f5fd6", "#ff7f0e", "#8e44ad", "#00a6c8", "#e84393", "#1a237e", "#f1c40f", "#00897b",
                     "#6d4c41", "#212121")
PELVIS_COLOUR = "#222222"
FORBIDDEN_COLOUR = "#c0392b"
SAFE_BOX_COLOUR = "#d9b26f"
LEGEND_CHARACTERS = 4  # characters listed one by one in the legend; more are summed up in one line


def character_colour(c: int) -> np.ndarray:
    """RGB in [0, 1] of character ``c``."""
    return hex_rgb(CHARACTER_COLOURS[c % len(CHARACTER_COLOURS)])


def hex_rgb(hex_colour: str) -> np.ndarray:
    h = hex_colour.lstrip("#")
    return np.array([int(h[i:i + 2], 16) / 255.0 for i in (0, 2, 4)])


def _lighter(rgb: np.ndarray, amount: float = 0.35) -> np.ndarray:
    return rgb + amount * (1.0 - rgb)


# ----------------------------------------------------------------------------- static geometry
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


def ground_height(scene, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Terrain height under world (x, z), nearest sample (for the scale bar), m."""
    h = scene["terrain_heights"]
    cell = float(scene["terrain_cell"])
    x0, z0 = scene["terrain_origin"]
    col = np.clip(np.rint((np.asarray(x) - x0) / cell).astype(int), 0, h.shape[1] - 1)
    row = np.clip(np.rint((np.asarray(z) - z0) / cell).astype(int), 0, h.shape[0] - 1)
    return h[row, col]


# ----------------------------------------------------------------------------- moving geometry
def _tracks(pv, feet, upto: int | None = None):
    """(F, C, L, 3) foot positions -> one polyline per foot up to frame ``upto``, RGB by character."""
    feet = feet if upto is None else feet[:upto + 1]
    f, c, legs, _ = feet.shape
    if f < 2:
        return None
    pts = feet.transpose(1, 2, 0, 3).reshape(-1, 3).copy()
    pts[:, 1] += TRACK_LIFT_M
    starts = np.arange(c * legs) * f
    lines = np.column_stack([np.full(c * legs, f), starts[:, None] + np.arange(f)[None, :]]).ravel()
    poly = pv.PolyData(pts, lines=lines)
    colours = np.array([_lighter(character_colour(k)) for k in range(c)])
    poly["rgb"] = (255 * np.repeat(colours, legs * f, axis=0)).astype(np.uint8)
    return poly


def _pelvis_paths(pv, pelvis, upto: int | None = None):
    pelvis = pelvis if upto is None else pelvis[:upto + 1]
    f, c, _ = pelvis.shape
    if f < 2:
        return None
    pts = pelvis.transpose(1, 0, 2).reshape(-1, 3)
    lines = np.column_stack([np.full(c, f), (np.arange(c) * f)[:, None] + np.arange(f)[None, :]]).ravel()
    return pv.PolyData(pts, lines=lines)


class CreatureShapes:
    """Meshes of the creatures at one frame: an ellipsoid body (the body box's length and width,
    the body thickness) about the pelvis, turned by the body rotation; a tube per leg segment
    through the joints; a ball per foot. Every part carries its character's colour."""

    def __init__(self, pv, scene):
        self.pv = pv
        length, thickness, width = (float(v) for v in scene["body_size"])
        body = pv.ParametricEllipsoid(0.5 * length, 0.5 * thickness, 0.5 * width, u_res=24, v_res=12, w_res=12)
        self.body_points = np.asarray(body.points, dtype=np.float64)  # body frame: forward, up, left
        self.body_faces = np.asarray(body.faces)
        self.leg_radius = float(scene["leg_radius"])
        self.foot = pv.Sphere(radius=1.6 * self.leg_radius, theta_resolution=10, phi_resolution=8)

    def mesh(self, pelvis: np.ndarray, rotations: np.ndarray, joints: np.ndarray):
        """One PolyData with an ``rgb`` array for C characters: pelvis (C, 3), rotations (C, 3, 3),
        joints (C, L, J, 3). The legs of all characters are one tube filter, their feet one glyph."""
        pv = self.pv
        c, legs, j, _ = joints.shape
        colours = np.array([255 * character_colour(k) for k in range(c)])
        parts = []
        # The body a shade darker than the legs, so its outline reads against them; the feet darker still.
        for k in range(c):
            body = pv.PolyData(pelvis[k] + self.body_points @ rotations[k].T, self.body_faces)
            body["rgb"] = np.tile((0.8 * colours[k]).astype(np.uint8), (body.n_points, 1))
            parts.append(body)
        chains = joints.reshape(-1, 3)
        starts = np.arange(c * legs) * j
        lines = np.column_stack([np.full(c * legs, j), starts[:, None] + np.arange(j)[None, :]]).ravel()
        skeleton = pv.PolyData(chains, lines=lines)
        skeleton["rgb"] = np.repeat(colours, legs * j, axis=0).astype(np.uint8)
        parts.append(skeleton.tube(radius=self.leg_radius, n_sides=8, capping=True))
        tips = pv.PolyData(joints[:, :, -1].reshape(-1, 3))
        tips["rgb"] = np.repeat(0.6 * colours, legs, axis=0).astype(np.uint8)
        parts.append(tips.glyph(geom=self.foot, scale=False, orient=False))
        for part in parts:
            for name in list(part.point_data.keys()):
                if name != "rgb":
                    del part.point_data[name]
        return pv.merge(parts)


# ----------------------------------------------------------------------------- camera
def framing(points: np.ndarray, aspect: float, min_radius: float) -> tuple[np.ndarray, float]:
    """(focus, camera distance) that keep every point of ``points`` (N, 3) in a view of ``aspect``
    (width / height) seen along :data:`VIEW_DIRECTION`."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = 0.5 * (lo + hi)
    radius = max(float(np.linalg.norm(points - centre, axis=1).max()), min_radius)
    return centre, distance_for(radius, aspect)


def distance_for(radius: float, aspect: float) -> float:
    half_v = math.radians(0.5 * VIEW_ANGLE_DEG)
    half_h = math.atan(math.tan(half_v) * aspect)
    return FRAME_MARGIN * radius / math.sin(min(half_v, half_h))


def _camera(focus: np.ndarray, distance: float):
    direction = VIEW_DIRECTION / np.linalg.norm(VIEW_DIRECTION)
    return [tuple(focus + distance * direction), tuple(focus), (0.0, 1.0, 0.0)]


def nice_length(span: float) -> float:
    """A round length (1, 2 or 5 x 10^k m) about a fifth of ``span``."""
    target = max(span / 5.0, 1e-3)
    k = math.floor(math.log10(target))
    for m in (5.0, 2.0, 1.0):
        if m * 10**k <= target:
            return m * 10**k
    return 10**k


def _label(length: float) -> str:
    return f"{length:g} m" if length >= 1 else f"{100 * length:g} cm"


# ----------------------------------------------------------------------------- the scene
class SceneView:
    """A plotter holding one scene; :meth:`show_frame` puts its moving parts at frame k."""

    def __init__(self, pv, scene: dict, size: tuple[int, int]):
        self.pv = pv
        self.scene = scene
        self.size = size
        self.frames = int(scene["pelvis"].shape[0])
        self.characters = int(scene["pelvis"].shape[1])
        self.has_creatures = "joints" in scene
        self.shapes = CreatureShapes(pv, scene) if self.has_creatures else None
        # Boxes are drawn again each frame only if some of them move.
        self.moving_boxes = "box_centres_t" in scene and len(scene["box_sizes"]) > 0 and bool(
            np.ptp(scene["box_centres_t"], axis=0).max() > 0 or np.ptp(scene["box_yaws_t"], axis=0).max() > 0)
        p = pv.Plotter(off_screen=True, window_size=list(size))
        p.set_background("#dfe9f3", top="#ffffff")
        terrain = _terrain(pv, scene)
        low, high = float(terrain["height_m"].min()), float(terrain["height_m"].max())
        span = max(high - low, 0.2)
        # The colour map's low end is water blue: start a quarter span lower so the ground (flat too) is green-brown.
        p.add_mesh(terrain, scalars="height_m", cmap="terrain", clim=(low - 0.35 * span, high + 0.05 * span),
                   show_scalar_bar=False, smooth_shading=True)
        self.plotter = p
        self._box_meshes = {}  # forbidden flag -> the drawn mesh of those boxes
        if not self.moving_boxes:
            self._add_boxes(scene["box_centres"], scene["box_yaws"])
        self._legend()

    def _font(self, base: int) -> int:
        return max(10, int(round(base * self.size[1] / 720)))

    def _add_boxes(self, centres, yaws) -> None:
        """The boxes at these poses, one mesh per colour; moving boxes are drawn again every frame,
        so a later call only moves the drawn meshes' corners (same boxes, same faces)."""
        s = self.scene
        for forbidden, colour in ((True, FORBIDDEN_COLOUR), (False, SAFE_BOX_COLOUR)):
            pick = np.asarray(s["box_forbidden"], dtype=bool) == forbidden
            if not pick.any():
                continue
            corners = box_corners(np.asarray(centres)[pick], np.asarray(s["box_sizes"])[pick],
                                  np.asarray(yaws)[pick]).reshape(-1, 3)
            shown = self._box_meshes.get(forbidden)
            if shown is not None:
                shown.points = corners
                continue
            faces = faces_of(int(pick.sum()))
            shown = self.pv.PolyData(corners, np.column_stack([np.full(len(faces), 4), faces]).ravel())
            self._box_meshes[forbidden] = shown
            self.plotter.add_mesh(shown, color=colour, show_edges=True, edge_color="#333333", opacity=0.9,
                                  name=f"boxes-{forbidden}", render=False)

    def _legend(self) -> None:
        """The legend as an RGBA overlay (Pillow: VTK's legend box writes each label in its entry's
        colour, unreadable for white footprints), pasted into the upper right of every picture."""
        from PIL import Image, ImageDraw, ImageFont

        entries = []
        shown = min(self.characters, LEGEND_CHARACTERS)
        what = "body, legs, foot tracks" if self.has_creatures else "foot tracks"
        for k in range(shown):
            entries.append((f"character {k + 1}: {what}", tuple(character_colour(k)), "box"))
        if self.characters > shown:
            entries.append((f"... {self.characters} characters, one colour each", (0.55, 0.55, 0.55), "box"))
        entries.append(("pelvis path", (0.13, 0.13, 0.13), "line"))
        if len(self.scene["footprints"]):
            entries.append(("footprint (touch-down)", (1.0, 1.0, 1.0), "dot"))
        forbidden = np.asarray(self.scene["box_forbidden"], bool)
        if forbidden.any():
            entries.append(("forbidden box", hex_rgb(FORBIDDEN_COLOUR), "box"))
        if (~forbidden).any():
            entries.append(("box (may be stepped on)", hex_rgb(SAFE_BOX_COLOUR), "box"))
        size = self._font(17)
        font = ImageFont.load_default(size=size)
        pad, row, swatch = size // 2, int(size * 1.35), size
        width = pad * 3 + swatch + max(int(font.getlength(text)) for text, _, _ in entries)
        height = 2 * pad + row * len(entries)
        img = Image.new("RGBA", (width, height), (255, 255, 255, 220))
        draw = ImageDraw.Draw(img)
        draw.rectangle([0, 0, width - 1, height - 1], outline=(90, 90, 90, 255))
        for i, (text, rgb, kind) in enumerate(entries):
            y = pad + i * row + (row - swatch) // 2
            fill = tuple(int(255 * v) for v in rgb) + (255,)
            box = [pad, y, pad + swatch, y + swatch]
            if kind == "box":
                draw.rectangle(box, fill=fill, outline=(60, 60, 60, 255))
            elif kind == "line":
                draw.line([pad, y + swatch // 2, pad + swatch, y + swatch // 2], fill=fill, width=max(2, size // 8))
            else:
                draw.ellipse([pad + swatch // 4, y + swatch // 4, pad + 3 * swatch // 4, y + 3 * swatch // 4],
                             fill=fill, outline=(60, 60, 60, 255))
            draw.text((2 * pad + swatch, pad + i * row + row // 2), text, fill=(20, 20, 20, 255), font=font,
                      anchor="lm")
        self.legend = np.asarray(img)
        self.title_font = font

    def overlay(self, img: np.ndarray, title: str = "") -> np.ndarray:
        """``img`` (H, W, 3) with the legend in its upper right corner and ``title`` in its upper left."""
        from PIL import Image, ImageDraw

        picture = Image.fromarray(np.ascontiguousarray(img[..., :3]))
        legend = Image.fromarray(self.legend)
        margin = max(4, self.size[1] // 60)
        left = max(0, picture.width - legend.width - margin)
        picture.paste(legend, (left, margin), legend)
        self.legend_box = [left, margin, left + legend.width, margin + legend.height]
        if title:
            draw = ImageDraw.Draw(picture, "RGBA")
            box = draw.textbbox((margin, margin), title, font=self.title_font)
            draw.rectangle([box[0] - 4, box[1] - 4, box[2] + 4, box[3] + 4], fill=(255, 255, 255, 200))
            draw.text((margin, margin), title, fill=(20, 20, 20, 255), font=self.title_font)
        return np.asarray(picture)

    def _scale_bar(self, focus: np.ndarray, distance: float) -> None:
        """A black and white bar of a round length on the ground in front of the focus, labelled."""
        pv, p = self.pv, self.plotter
        view_span = 2.0 * distance * math.tan(math.radians(0.5 * VIEW_ANGLE_DEG))
        length = nice_length(view_span)
        towards = VIEW_DIRECTION.copy()
        towards[1] = 0.0
        towards /= np.linalg.norm(towards)
        right = np.cross(np.array([0.0, 1.0, 0.0]), towards)  # screen right on the ground
        start = focus + 0.32 * view_span * towards - 0.45 * view_span * right
        t = np.linspace(0.0, length, 41)
        pts = start[None, :] + t[:, None] * right[None, :]
        pts[:, 1] = ground_height(self.scene, pts[:, 0], pts[:, 2]) + 0.5 * TRACK_LIFT_M + 0.004 * view_span
        radius = 0.006 * view_span
        halves = ((pts[:21], "black", "scale-a"), (pts[20:], "white", "scale-b"))
        for seg, colour, name in halves:
            p.add_mesh(pv.lines_from_points(seg).tube(radius=radius, n_sides=10), color=colour, name=name, render=False)
        p.add_point_labels(pts[-1:] + [0.0, 3 * radius, 0.0], [_label(length)], font_size=self._font(16),
                           text_color="black", shape_color="white", shape_opacity=0.85, show_points=False,
                           name="scale-label", always_visible=True, render=False)

    def show_frame(self, k: int, trails: bool) -> None:
        """Put the creatures, boxes and (``trails``: the tracks up to frame k; else the whole
        tracks) at frame ``k``."""
        s, p, pv = self.scene, self.plotter, self.pv
        upto = k if trails else None
        for name, mesh, kwargs in (
                ("tracks", _tracks(pv, s["feet"], upto), dict(scalars="rgb", rgb=True, line_width=2.0)),
                ("pelvis", _pelvis_paths(pv, s["pelvis"], upto), dict(color=PELVIS_COLOUR, line_width=1.5))):
            if mesh is None:
                p.remove_actor(name, render=False)
            else:
                p.add_mesh(mesh, name=name, render=False, **kwargs)
        prints = s["footprints"]
        if trails and "footprint_frames" in s:
            prints = prints[s["footprint_frames"] <= k]
        if len(prints):
            prints = prints.copy()
            prints[:, 1] += TRACK_LIFT_M
            p.add_points(prints, color="white", point_size=max(3, round(7 * self.size[1] / 720)),
                         render_points_as_spheres=True,
                         name="footprints", render=False)
        else:
            p.remove_actor("footprints", render=False)
        if self.moving_boxes:
            self._add_boxes(s["box_centres_t"][k], s["box_yaws_t"][k])
        if self.has_creatures:
            p.add_mesh(self.shapes.mesh(s["pelvis"][k], s["rotations"][k], s["joints"][k]), scalars="rgb", rgb=True,
                       smooth_shading=True, name="creatures", specular=0.3, render=False)

    def look(self, focus: np.ndarray, distance: float) -> None:
        self.plotter.camera_position = _camera(focus, distance)
        self.plotter.camera.view_angle = VIEW_ANGLE_DEG
        self._scale_bar(focus, distance)

    def screen_boxes(self, k: int) -> list[list[float]]:
        """Per character, its joints' screen box [left, top, right, bottom] (pixels, top-left origin) at frame k."""
        import vtk

        renderer = self.plotter.renderer
        coordinate = vtk.vtkCoordinate()
        coordinate.SetCoordinateSystemToWorld()
        height = self.size[1]
        boxes = []
        for c in range(self.characters):
            pts = np.concatenate([self.scene["joints"][k, c].reshape(-1, 3), self.scene["pelvis"][k, c][None]])
            xy = []
            for q in pts:
                coordinate.SetValue(*map(float, q))
                x, y = coordinate.GetComputedDoubleDisplayValue(renderer)
                xy.append((x, height - y))
            xy = np.array(xy)
            boxes.append([float(xy[:, 0].min()), float(xy[:, 1].min()), float(xy[:, 0].max()), float(xy[:, 1].max())])
        return boxes

    def close(self) -> None:
        self.plotter.close()


def _load(scene_path) -> dict:
    with np.load(scene_path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


def _creature_extent(scene) -> float:
    """Half the creature's size, m: its farthest foot from its pelvis at the last frame (the same
    with and without the creatures drawn, so that both pictures have the same framing)."""
    return float(np.linalg.norm(scene["feet"][-1, 0] - scene["pelvis"][-1, 0], axis=1).max())


def render(scene_path, out_dir, regions_path=None, size: tuple[int, int] = WINDOW) -> list[str]:
    """The two pictures of the module doc; returns their file names."""
    import pyvista as pv
    from PIL import Image

    scene = _load(scene_path)
    out_dir = Path(out_dir)
    last = int(scene["pelvis"].shape[0]) - 1
    reach = _creature_extent(scene)
    aspect = size[0] / size[1]
    # Overview: every track and the whole crowd; close-up: the first character at the last frame
    # with about three of its own sizes around it (its neighbours, the boxes it meets).
    # The framings use the feet and the pelvis only (the legs lie between them): a picture
    # without the creatures is framed the same way.
    everything = np.concatenate([scene["feet"].reshape(-1, 3), scene["pelvis"].reshape(-1, 3)])
    overview = framing(everything, aspect, min_radius=min(1.0, 8.0 * reach))
    own = np.concatenate([scene["feet"][last, 0], scene["pelvis"][last, :1]])
    closeup = framing(own, aspect, min_radius=max(min(0.3, 8.0 * reach), 2.5 * reach))
    written, regions = [], {}
    view = SceneView(pv, scene, size)
    try:
        view.show_frame(last, trails=False)
        for name, (focus, distance) in (("scene_overview.png", overview), ("scene_closeup.png", closeup)):
            view.look(focus, distance)
            view.plotter.render()
            title = f"{scene['title']}, t = {(last + 1) * float(scene['dt']):.2f} s" if "title" in scene else ""
            Image.fromarray(view.overlay(view.plotter.screenshot(return_img=True), title)).save(out_dir / name)
            written.append(name)
            if view.has_creatures:
                regions[name] = {"characters": view.screen_boxes(last), "legend": view.legend_box}
    finally:
        view.close()
    if regions_path is not None:
        Path(regions_path).write_text(json.dumps(regions))
    return written


# ----------------------------------------------------------------------------- clips
def camera_path(scene: dict, camera: str, aspect: float) -> tuple[np.ndarray, np.ndarray]:
    """(F, 3) focus and (F,) distance of every frame.

    ``fixed``: one view holding every character's every pose and track over the whole clip.
    ``follow``: the view of the crowd at each frame (its joints), its centre a moving average
    over :data:`FOLLOW_SMOOTHING_FRAMES` and its radius the largest over that window, so that it
    glides and never cuts a character off.
    """
    from scipy.ndimage import maximum_filter1d, uniform_filter1d

    frames = int(scene["pelvis"].shape[0])
    reach = _creature_extent(scene)
    # At least three of the creature's own sizes; the 0.4 m floor holds only for creatures that large
    # (a 4 cm mite's crowd filled a tenth of the picture).
    min_radius = max(min(0.4, 4.0 * reach), 3.0 * reach)
    poses = scene["joints"].reshape(frames, -1, 3) if "joints" in scene else scene["feet"].reshape(frames, -1, 3)
    poses = np.concatenate([poses, scene["pelvis"]], axis=1)
    if camera == "fixed":
        focus, distance = framing(poses.reshape(-1, 3), aspect, min_radius)
        return np.repeat(focus[None], frames, axis=0), np.full(frames, distance)
    lo, hi = poses.min(axis=1), poses.max(axis=1)
    centres = 0.5 * (lo + hi)
    size = min(FOLLOW_SMOOTHING_FRAMES, frames)
    smooth = uniform_filter1d(centres, size=size, axis=0, mode="nearest")
    # The radius about the smoothed centre, so the drift of the average is covered too.
    radius = np.linalg.norm(poses - smooth[:, None, :], axis=2).max(axis=1)
    radius = uniform_filter1d(maximum_filter1d(np.maximum(radius, min_radius), size=size, mode="nearest"),
                              size=size, mode="nearest")
    radius = np.maximum(radius, np.linalg.norm(poses - smooth[:, None, :], axis=2).max(axis=1))
    return smooth, np.array([distance_for(float(r), aspect) for r in radius])


def _writer(out: Path, fps: float, size: tuple[int, int]):
    """(append(rgb frame), close()) of the encoder for ``out``'s suffix."""
    if out.suffix.lower() == ".gif":
        from PIL import Image

        frames: list = []
        # GIF delays are whole centiseconds.
        delay_ms = 10 * max(2, round(100.0 / fps))

        def append(img):
            frames.append(Image.fromarray(img).quantize(colors=255, method=Image.Quantize.MEDIANCUT))

        def close():
            frames[0].save(out, format="GIF", save_all=True, append_images=frames[1:], duration=delay_ms, loop=0)

        return append, close
    import imageio.v2 as imageio

    # H.264, 4:2:0 (what every browser plays), the index first so that a page can start playing
    # before the whole file is there; sizes are padded to even numbers (4:2:0 needs them).
    writer = imageio.get_writer(out, format="FFMPEG", mode="I", fps=fps, codec="libx264", pixelformat="yuv420p",
                                macro_block_size=2, quality=7, ffmpeg_log_level="error",
                                output_params=["-movflags", "+faststart"])
    return writer.append_data, writer.close


def render_clip(scene_path, out_path, camera: str = "follow", size: tuple[int, int] = (960, 540),
                fps: float = 30.0, progress=None) -> dict:
    """Render every frame of the scene into ``out_path`` (.mp4 or .gif); returns what was written."""
    import pyvista as pv

    scene = _load(scene_path)
    out = Path(out_path)
    frames = int(scene["pelvis"].shape[0])
    focus, distance = camera_path(scene, camera, size[0] / size[1])
    dt = float(scene["dt"]) if "dt" in scene else 1.0 / fps
    title = str(scene["title"]) if "title" in scene else ""
    append, close = _writer(out, fps, size)
    view = SceneView(pv, scene, size)
    try:
        for k in range(frames):
            view.show_frame(k, trails=True)
            view.look(focus[k], float(distance[k]))
            view.plotter.render()
            clock = f"t = {(k + 1) * dt:5.2f} s"
            append(view.overlay(view.plotter.screenshot(return_img=True), f"{title}   {clock}" if title else clock))
            if progress is not None:
                progress(k + 1, frames)
    finally:
        view.close()
    close()
    if out.suffix.lower() == ".gif":
        fps = 100.0 / max(2, round(100.0 / fps))  # GIF delays are whole centiseconds
    return {"path": str(out), "frames": frames, "fps": fps, "width": size[0], "height": size[1], "camera": camera}


def main(argv: list[str]) -> int:
    import argparse

    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    if argv and argv[0] == "clip":
        parser = argparse.ArgumentParser(prog="python -m footfall.reports._render clip")
        parser.add_argument("scene")
        parser.add_argument("out")
        parser.add_argument("--camera", choices=("follow", "fixed"), default="follow")
        parser.add_argument("--width", type=int, default=960)
        parser.add_argument("--height", type=int, default=540)
        parser.add_argument("--fps", type=float, default=30.0)
        a = parser.parse_args(argv[1:])
        result = render_clip(a.scene, a.out, a.camera, (a.width, a.height), a.fps,
                             progress=lambda k, n: print(f"frame {k} {n}", flush=True))
        print(json.dumps(result), flush=True)
        return 0
    parser = argparse.ArgumentParser(prog="python -m footfall.reports._render")
    parser.add_argument("scene")
    parser.add_argument("out_dir")
    parser.add_argument("--regions", default=None)
    parser.add_argument("--width", type=int, default=WINDOW[0])
    parser.add_argument("--height", type=int, default=WINDOW[1])
    a = parser.parse_args(argv)
    print(json.dumps(render(a.scene, a.out_dir, a.regions, (a.width, a.height))))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
