"""USD export of a simulation (issue 5, item 2): one layer, readable by any USD tool.

What the stage holds (y up, 1 unit = 1 m, one time code per frame, 30 per second;
time code k + 1 is recorded frame k, i.e. the simulated time in seconds is the time
code divided by ``timeCodesPerSecond``):

* ``/World`` - the default prim.
* ``/World/Terrain`` - the scenario's height field as a quad Mesh (downsampled when it
  has more than :data:`TERRAIN_MAX_SAMPLES` samples per side).
* ``/World/Obstacles/box_NNN`` - one Cube per box (translate, rotateY, scale); the
  translate of a moving box is sampled at every time code (:meth:`Obstacles.poses_at`).
* ``/World/Characters/character_NNN`` - per character:
  ``Rig`` (SkelRoot) with a ``Skeleton``, its ``Animation`` (SkelAnimation of the
  recorded IK joint angles and pelvis pose) and ``Legs`` (a box per body and leg
  segment, rigidly bound to its joint); ``FootPaths`` (BasisCurves, one linear curve
  per foot through its recorded positions) and ``Footprints`` (Points at the
  landings).

The skeleton reproduces the leg chain of :mod:`planner._kernels_ik` joint for joint, so
its forward kinematics puts every joint where :func:`planner._ik.forward_legs` puts it:

* ``pelvis`` (root): translation = pelvis, rotation = ``body_rotation(heading, pitch,
  roll)`` = R_y(-heading) R_z(pitch) R_x(-roll) in the usual right-handed axis
  rotations (body x forward, y up, z left);
* ``<leg>_hip`` (azimuth joint): translation = the hip (body frame), rotation
  R_y(-(rest_azimuth + azimuth)): its x axis is the leg plane's outward direction, z
  the plane's normal; an abduction joint (``plane_rolls``): R_y(-rest_azimuth)
  R_x(abduction), the plane rolled about its outward axis;
* ``<leg>_hinge0 .. hinge{S-1}``: rotation R_z(-pitch_j) (positive pitch bends down),
  translation (length of the previous segment, 0, 0) (hinge 0 sits at the hip);
* ``<leg>_tip``: the foot, (length of the last segment, 0, 0) along the last hinge's x.

The bind (and rest) pose is the creature's rest pose (:func:`planner.rest_pose_angles`)
with the pelvis at the origin.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from footfall._atomic import atomic_path, unwritable_reason
from footfall._errors import InputError
from footfall.planner._ik import legs_of, rest_pose_angles
from footfall.reports._box_mesh import BOX_CORNERS, faces_of
from footfall.reports._recording import Recording

USD_SUFFIXES = (".usda", ".usdc", ".usd")
"""Output extensions USD knows (it picks text or crate from the extension; .usd is crate)."""
TERRAIN_MAX_SAMPLES = 257
"""Height fields with more samples per side are subsampled (every k-th row and column, the
last ones always kept) so a 20 m terrain of 5 cm cells stays a light mesh."""
LEG_HALF_WIDTH_FEET = 0.25
"""Half the thickness of a leg segment's box, as a fraction of the creature's foot width."""
FOOT_PATH_WIDTH_FEET = 0.2
"""Width of a foot trajectory curve, as a fraction of the creature's foot width."""
BOX_FORBIDDEN_COLOUR = (0.75, 0.2, 0.15)
BOX_SAFE_COLOUR = (0.3, 0.6, 0.3)
TERRAIN_COLOUR = (0.55, 0.5, 0.42)
BODY_COLOUR = (0.2, 0.2, 0.25)
FOOTPRINT_COLOUR = (0.9, 0.75, 0.1)

# ----------------------------------------------------------------------------- skeleton
@dataclass(frozen=True, eq=False)
class SkeletonLayout:
    """Joints of a creature's skeleton (see the module docstring).

    joints:     (J,) UsdSkel joint paths, parents before children ("pelvis", "pelvis/L1_hip", ...).
    parents:    (J,) index of each joint's parent, -1 for the root.
    leg_joints: (L, S + 2) joint indices of each leg: [hip (azimuth), hinge 0 .. S-1, tip];
                row r is the joint at row r of :func:`planner._ik.forward_legs`.
    """

    joints: tuple[str, ...]
    parents: np.ndarray
    leg_joints: np.ndarray


def _joint_name(name: str) -> str:
    """A leg name as a USD path element (letters, digits and underscores)."""
    from pxr import Tf

    return Tf.MakeValidIdentifier(name)


def skeleton_layout(creature) -> SkeletonLayout:
    n_legs, n_segments = creature.n_legs, creature.n_segments
    joints = ["pelvis"]
    parents = [-1]
    leg_joints = np.zeros((n_legs, n_segments + 2), np.int64)
    prefixes = [_joint_name(name) for name in creature.leg_names]
    if len(set(prefixes)) < n_legs:  # distinct names may become equal identifiers ("L-1", "L_1")
        prefixes = [f"leg{leg}_{prefix}" for leg, prefix in enumerate(prefixes)]
    for leg, prefix in enumerate(prefixes):
        path = "pelvis"
        parent = 0
        for row, part in enumerate(["hip"] + [f"hinge{j}" for j in range(n_segments)] + ["tip"]):
            path = f"{path}/{prefix}_{part}"
            leg_joints[leg, row] = len(joints)
            joints.append(path)
            parents.append(parent)
            parent = len(joints) - 1
    return SkeletonLayout(joints=tuple(joints), parents=np.array(parents), leg_joints=leg_joints)


def _axis_quaternions(angles: np.ndarray, axis: int) -> np.ndarray:
    """(..., 4) quaternions (x, y, z, w) of right-handed rotations by ``angles`` about axis 0/1/2."""
    q = np.zeros(np.shape(angles) + (4,))
    q[..., axis] = np.sin(0.5 * np.asarray(angles))
    q[..., 3] = np.cos(0.5 * np.asarray(angles))
    return q


def _quaternion_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a b of (..., 4) quaternions (x, y, z, w): rotate by b, then by a."""
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz], axis=-1)


def joint_local_transforms(creature, layout: SkeletonLayout, pelvis, orientation, angles):
    """Local joint transforms for poses: ``pelvis`` (..., 3) m, ``orientation`` (..., 3)
    (heading, pitch, roll) rad, ``angles`` (..., L, S + 1) rad (:mod:`planner._ik`).

    Returns rotations (..., J, 4) quaternions (x, y, z, w) and translations (..., J, 3), m,
    each relative to the parent joint (UsdSkel: rotate, then translate).
    """
    legs = legs_of(creature)
    pelvis = np.asarray(pelvis, np.float64)
    orientation = np.asarray(orientation, np.float64)
    angles = np.asarray(angles, np.float64)
    lead = pelvis.shape[:-1]
    n_joints = len(layout.joints)
    n_segments = legs.segment_lengths.shape[1]
    rotations = np.zeros(lead + (n_joints, 4))
    rotations[..., 3] = 1.0
    translations = np.zeros(lead + (n_joints, 3))
    heading, pitch, roll = orientation[..., 0], orientation[..., 1], orientation[..., 2]
    rotations[..., 0, :] = _quaternion_product(_quaternion_product(_axis_quaternions(-heading, 1),
                                                                   _axis_quaternions(pitch, 2)),
                                               _axis_quaternions(-roll, 0))
    translations[..., 0, :] = pelvis
    for leg in range(legs.n_legs):
        hip, *hinges, tip = layout.leg_joints[leg]
        if legs.plane_rolls[leg]:
            # an abduction: the plane faces its rest azimuth and rolls about its outward (x) axis
            facing = np.full(angles.shape[:-2], -legs.rest_azimuths[leg])
            rotations[..., hip, :] = _quaternion_product(_axis_quaternions(facing, 1),
                                                         _axis_quaternions(angles[..., leg, 0], 0))
        else:
            rotations[..., hip, :] = _axis_quaternions(-(legs.rest_azimuths[leg] + angles[..., leg, 0]), 1)
        translations[..., hip, :] = legs.hips[leg]
        for j, joint in enumerate(hinges):
            rotations[..., joint, :] = _axis_quaternions(-angles[..., leg, j + 1], 2)
            if j > 0:
                translations[..., joint, 0] = legs.segment_lengths[leg, j - 1]
        translations[..., tip, 0] = legs.segment_lengths[leg, n_segments - 1]
    return rotations, translations


def _row_matrices(rotations: np.ndarray, translations: np.ndarray) -> np.ndarray:
    """(..., 4, 4) USD (row-vector) matrices of rotate-then-translate: p' = p M."""
    x, y, z, w = np.moveaxis(rotations, -1, 0)
    m = np.zeros(rotations.shape[:-1] + (4, 4))
    # column-vector rotation matrix of the quaternion, transposed for USD's row vectors
    m[..., 0, 0] = 1 - 2 * (y * y + z * z)
    m[..., 1, 0] = 2 * (x * y - z * w)
    m[..., 2, 0] = 2 * (x * z + y * w)
    m[..., 0, 1] = 2 * (x * y + z * w)
    m[..., 1, 1] = 1 - 2 * (x * x + z * z)
    m[..., 2, 1] = 2 * (y * z - x * w)
    m[..., 0, 2] = 2 * (x * z - y * w)
    m[..., 1, 2] = 2 * (y * z + x * w)
    m[..., 2, 2] = 1 - 2 * (x * x + y * y)
    m[..., 3, :3] = translations
    m[..., 3, 3] = 1.0
    return m


def _world_matrices(local: np.ndarray, parents: np.ndarray) -> np.ndarray:
    """(J, 4, 4) skeleton-space matrices from local ones (parents listed before children)."""
    world = np.empty_like(local)
    for j, parent in enumerate(parents):
        world[j] = local[j] if parent < 0 else local[j] @ world[parent]
    return world


@dataclass(frozen=True, eq=False)
class LegMesh:
    """The bound mesh of a creature in its bind pose: a box for the body and each leg segment.

    points:        (V, 3) bind-pose positions, m.
    face_counts:   (F,) vertices per face (4).
    face_indices:  (4 F,) corner indices.
    joint_indices: (V,) the one joint each vertex follows (rigid skinning).
    tips:          (L, 4) vertices of each leg's far end (the foot): their centre is the tip joint.
    """

    points: np.ndarray
    face_counts: np.ndarray
    face_indices: np.ndarray
    joint_indices: np.ndarray
    tips: np.ndarray


def bind_pose(creature, layout: SkeletonLayout) -> tuple[np.ndarray, np.ndarray]:
    """Rest (local) and bind (skeleton-space) (J, 4, 4) matrices of the rest pose, pelvis at the origin."""
    rotations, translations = joint_local_transforms(creature, layout, np.zeros(3), np.zeros(3),
                                                     rest_pose_angles(creature))
    rest = _row_matrices(rotations, translations)
    return rest, _world_matrices(rest, layout.parents)


def leg_mesh(creature, layout: SkeletonLayout, bind: np.ndarray) -> LegMesh:
    legs = legs_of(creature)
    half = LEG_HALF_WIDTH_FEET * float(creature.foot_width)
    blocks, joints = [], []
    body = np.array([creature.body_box[0], creature.body_thickness, creature.body_box[1]], np.float64)
    blocks.append((BOX_CORNERS - 0.5) * body)
    joints.append(0)
    tips = np.zeros((legs.n_legs, 4), np.int64)
    for leg in range(legs.n_legs):
        hinges = layout.leg_joints[leg, 1:-1]
        for j, joint in enumerate(hinges):
            # the segment runs along its hinge's x axis, from 0 to its length
            local = (BOX_CORNERS - [0.0, 0.5, 0.5]) * [legs.segment_lengths[leg, j], 2 * half, 2 * half]
            blocks.append(np.c_[local, np.ones(8)] @ bind[joint][:, :3])
            joints.append(joint)
        tips[leg] = 8 * (len(blocks) - 1) + np.flatnonzero(BOX_CORNERS[:, 0] == 1.0)
    n_boxes = len(blocks)
    return LegMesh(points=np.concatenate(blocks), face_counts=np.full(6 * n_boxes, 4),
                   face_indices=faces_of(n_boxes).ravel(),
                   joint_indices=np.repeat(joints, 8), tips=tips)


# ----------------------------------------------------------------------------- output path
def check_output_path(out_path: str | Path) -> Path:
    """``out_path`` as a Path if a USD file can be written there, else InputError (before any work)."""
    out = Path(out_path)
    if out.suffix.lower() not in USD_SUFFIXES:
        raise InputError(out, "out", f"expected a {', '.join(USD_SUFFIXES)} file name")
    if out.is_dir():
        raise InputError(out, "out", "is a directory")
    reason = unwritable_reason(out.parent)
    if reason:
        raise InputError(out, "out", reason)
    return out


# ----------------------------------------------------------------------------- stage
def _check_match(recording: Recording, scenario, creature) -> None:
    if recording.leg_names != tuple(creature.leg_names) or recording.segments != creature.n_segments:
        raise InputError(recording.path, "header.leg_names",
                         f"recorded legs {list(recording.leg_names)} with {recording.segments} segments do not "
                         f"match creature {creature.name!r} ({list(creature.leg_names)}, {creature.n_segments})")
    if recording.creature != creature.name:
        raise InputError(recording.path, "header.creature",
                         f"recorded with {recording.creature!r}, not {creature.name!r}")
    if recording.scenario is not None and recording.scenario != scenario.name:
        raise InputError(recording.path, "header.scenario",
                         f"recorded on {recording.scenario!r}, not {scenario.name!r}")


def _colour(prim, rgb) -> None:
    from pxr import Gf, UsdGeom

    UsdGeom.Gprim(prim).CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set([Gf.Vec3f(*rgb)])


def _terrain(stage, path: str, terrain) -> None:
    from pxr import UsdGeom, Vt

    heights = terrain.heights
    rows, cols = heights.shape
    stride = max(1, math.ceil((max(rows, cols) - 1) / (TERRAIN_MAX_SAMPLES - 1)))
    r = np.unique(np.r_[np.arange(0, rows, stride), rows - 1])
    c = np.unique(np.r_[np.arange(0, cols, stride), cols - 1])
    zz, xx = np.meshgrid(terrain.origin_z + r * terrain.cell_size, terrain.origin_x + c * terrain.cell_size,
                         indexing="ij")
    points = np.stack([xx, heights[np.ix_(r, c)], zz], axis=-1).reshape(-1, 3)
    n_c = c.size
    corner = (np.arange(r.size - 1)[:, None] * n_c + np.arange(n_c - 1)[None, :]).ravel()
    # (row, col), (row + 1, col), (row + 1, col + 1), (row, col + 1): counter-clockwise seen from above
    quads = np.stack([corner, corner + n_c, corner + n_c + 1, corner + 1], axis=1)
    mesh = UsdGeom.Mesh.Define(stage, path)
    points_f = points.astype(np.float32)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(points_f))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(quads), 4, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(quads.ravel().astype(np.int32)))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateExtentAttr(UsdGeom.PointBased.ComputeExtent(Vt.Vec3fArray.FromNumpy(points_f)))
    _colour(mesh.GetPrim(), TERRAIN_COLOUR)


def _obstacles(stage, path: str, obstacles, times: np.ndarray, time_codes: list[float]) -> None:
    from pxr import Gf, Sdf, UsdGeom

    UsdGeom.Xform.Define(stage, path)
    for i in range(len(obstacles)):
        cube = UsdGeom.Cube.Define(stage, f"{path}/box_{i:03d}")
        cube.CreateSizeAttr(1.0)
        cube.CreateExtentAttr([Gf.Vec3f(-0.5), Gf.Vec3f(0.5)])
        # double precision: the boxes are where the planner saw them, up to round-off
        double = UsdGeom.XformOp.PrecisionDouble
        translate = cube.AddTranslateOp(double)
        # a box's local x is world (cos yaw, 0, sin yaw): a right-handed turn of -yaw about y
        cube.AddRotateYOp(double).Set(-math.degrees(float(obstacles.yaws[i])))
        cube.AddScaleOp(double).Set(Gf.Vec3d(*obstacles.sizes[i].tolist()))
        if obstacles.is_static[i]:
            translate.Set(Gf.Vec3d(*obstacles.centres[i].tolist()))
        else:
            for t, code in zip(times, time_codes):
                translate.Set(Gf.Vec3d(*obstacles.poses_at(float(t))[0][i].tolist()), code)
        forbidden = bool(obstacles.forbidden[i])
        cube.GetPrim().CreateAttribute("footfall:forbidden", Sdf.ValueTypeNames.Bool, custom=True).Set(forbidden)
        _colour(cube.GetPrim(), BOX_FORBIDDEN_COLOUR if forbidden else BOX_SAFE_COLOUR)


def _character(stage, path: str, c: int, recording: Recording, creature, layout: SkeletonLayout,
               rest: np.ndarray, bind: np.ndarray, mesh_data: LegMesh, time_codes: list[float]) -> None:
    from pxr import Gf, Sdf, UsdGeom, UsdSkel, Vt

    UsdGeom.Xform.Define(stage, path)
    root = UsdSkel.Root.Define(stage, f"{path}/Rig")
    skeleton = UsdSkel.Skeleton.Define(stage, f"{path}/Rig/Skeleton")
    joints = Vt.TokenArray(list(layout.joints))
    skeleton.CreateJointsAttr(joints)
    skeleton.CreateJointNamesAttr(Vt.TokenArray([j.rsplit("/", 1)[-1] for j in layout.joints]))
    skeleton.CreateRestTransformsAttr(Vt.Matrix4dArray.FromNumpy(rest))
    skeleton.CreateBindTransformsAttr(Vt.Matrix4dArray.FromNumpy(bind))

    animation = UsdSkel.Animation.Define(stage, f"{path}/Rig/Animation")
    animation.CreateJointsAttr(joints)
    rotations, translations = joint_local_transforms(creature, layout, recording.pelvis[:, c],
                                                     recording.orientation[:, c], recording.joint_angles[:, c])
    rotation_attr = animation.CreateRotationsAttr()
    translation_attr = animation.CreateTranslationsAttr()
    for k, code in enumerate(time_codes):
        rotation_attr.Set(Vt.QuatfArray.FromNumpy(rotations[k].astype(np.float32)), code)
        translation_attr.Set(Vt.Vec3fArray.FromNumpy(translations[k].astype(np.float32)), code)
    animation.CreateScalesAttr(Vt.Vec3hArray.FromNumpy(np.ones((len(layout.joints), 3), np.float16)))
    UsdSkel.BindingAPI.Apply(skeleton.GetPrim()).CreateAnimationSourceRel().SetTargets([animation.GetPath()])

    mesh = UsdGeom.Mesh.Define(stage, f"{path}/Rig/Legs")
    points = Vt.Vec3fArray.FromNumpy(mesh_data.points.astype(np.float32))
    mesh.CreatePointsAttr(points)
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(mesh_data.face_counts.astype(np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(mesh_data.face_indices.astype(np.int32)))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateExtentAttr(UsdGeom.PointBased.ComputeExtent(points))
    _colour(mesh.GetPrim(), BODY_COLOUR)
    binding = UsdSkel.BindingAPI.Apply(mesh.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skeleton.GetPath()])
    binding.CreateJointIndicesPrimvar(False, 1).Set(Vt.IntArray.FromNumpy(mesh_data.joint_indices.astype(np.int32)))
    binding.CreateJointWeightsPrimvar(False, 1).Set(Vt.FloatArray.FromNumpy(
        np.ones(mesh_data.joint_indices.size, np.float32)))
    binding.CreateGeomBindTransformAttr(Gf.Matrix4d(1.0))

    # The SkelRoot's bounds follow the animation (the skinned mesh), one extent per frame.
    extent = root.CreateExtentAttr()
    for code in time_codes:
        extent.Set(UsdGeom.Boundable.ComputeExtentFromPlugins(root, code), code)

    feet = recording.feet[:, c]  # (F, L, 3)
    width = float(creature.foot_width)
    if recording.frames >= 2:  # a linear curve needs two points
        curves = UsdGeom.BasisCurves.Define(stage, f"{path}/FootPaths")
        curve_points = Vt.Vec3fArray.FromNumpy(np.swapaxes(feet, 0, 1).reshape(-1, 3).astype(np.float32))
        curves.CreateTypeAttr(UsdGeom.Tokens.linear)
        curves.CreateCurveVertexCountsAttr(Vt.IntArray([recording.frames] * recording.legs))
        curves.CreatePointsAttr(curve_points)
        curves.CreateWidthsAttr(Vt.FloatArray([FOOT_PATH_WIDTH_FEET * width]))
        curves.SetWidthsInterpolation(UsdGeom.Tokens.constant)
        curves.CreateExtentAttr(UsdGeom.Curves.ComputeExtent(curve_points, Vt.FloatArray([FOOT_PATH_WIDTH_FEET
                                                                                          * width])))
        _colour(curves.GetPrim(), FOOTPRINT_COLOUR)
    frames, characters, legs = recording.touchdowns()
    mine = characters == c
    if mine.any():
        prints = UsdGeom.Points.Define(stage, f"{path}/Footprints")
        print_points = Vt.Vec3fArray.FromNumpy(feet[frames[mine], legs[mine]].astype(np.float32))
        prints.CreatePointsAttr(print_points)
        prints.CreateWidthsAttr(Vt.FloatArray([width]))
        prints.SetWidthsInterpolation(UsdGeom.Tokens.constant)
        prints.CreateExtentAttr(UsdGeom.Points.ComputeExtent(print_points, Vt.FloatArray([width])))
        prints.GetPrim().CreateAttribute("footfall:landingTimeCodes", Sdf.ValueTypeNames.DoubleArray,
                                         custom=True).Set(Vt.DoubleArray([time_codes[k] for k in frames[mine]]))
        _colour(prints.GetPrim(), FOOTPRINT_COLOUR)


def build_stage(recording: Recording, scenario, creature, progress=None):
    """An in-memory Usd.Stage of ``recording`` on ``scenario`` (geometry from ``creature``).

    ``progress(done, total)`` is called after each part (terrain, boxes, each character).
    """
    from pxr import Usd, UsdGeom

    _check_match(recording, scenario, creature)
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, UsdGeom.LinearUnits.meters)
    rate = 1.0 / recording.dt
    stage.SetTimeCodesPerSecond(rate)
    stage.SetFramesPerSecond(rate)
    # time code = simulated time x rate: frame k (after k + 1 steps) is time code k + 1
    time_codes = [float(k + 1) for k in range(recording.frames)]
    stage.SetStartTimeCode(time_codes[0])
    stage.SetEndTimeCode(time_codes[-1])
    stage.GetRootLayer().documentation = (f"footfall: {recording.characters} x {creature.name} on {scenario.name}, "
                                          f"{recording.frames} frames")
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    total = 2 + recording.characters
    _terrain(stage, "/World/Terrain", scenario.terrain)
    if progress:
        progress(1, total)
    _obstacles(stage, "/World/Obstacles", scenario.obstacles, recording.times, time_codes)
    if progress:
        progress(2, total)
    layout = skeleton_layout(creature)
    rest, bind = bind_pose(creature, layout)
    mesh_data = leg_mesh(creature, layout, bind)
    UsdGeom.Xform.Define(stage, "/World/Characters")
    for c in range(recording.characters):
        _character(stage, f"/World/Characters/character_{c:03d}", c, recording, creature, layout, rest, bind,
                   mesh_data, time_codes)
        if progress:
            progress(3 + c, total)
    return stage


def export_usd(recording: Recording, scenario, creature, out_path: str | Path, progress=None) -> Path:
    """Write ``recording`` on ``scenario`` as a USD file (.usda text, .usdc/.usd crate); returns its path.

    Written atomically (a temporary file with the same extension beside the target, then
    renamed), so a failure never leaves a half-written file. Raises InputError for an
    output that cannot be written or a recording that does not match the scenario/creature.
    """
    from pxr import Tf

    out = check_output_path(out_path)
    stage = build_stage(recording, scenario, creature, progress)
    try:
        with atomic_path(out, suffix=out.suffix) as tmp:
            if not stage.GetRootLayer().Export(str(tmp)):
                raise OSError(f"USD could not write {out}")
    except OSError as e:
        raise InputError(out, "out", f"cannot write: {e.strerror or e}") from None
    except Tf.ErrorException as e:
        raise InputError(out, "out", f"cannot write: {str(e).strip().splitlines()[-1]}") from None
    return out
