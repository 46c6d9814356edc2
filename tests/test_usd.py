"""USD export (footfall export-usd): a valid stage whose skeletons walk where the IK put the legs."""

import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import footfall_cli
from pxr import Gf, Usd, UsdGeom, UsdSkel, UsdValidation

from footfall._errors import InputError
from footfall.planner import body_rotation, init_crowd, legs_of
from footfall.planner._ik import forward_legs
from footfall.planner._simulation import Recorder, simulate
from footfall.reports._recording import load_recording
from footfall.reports._usd import (
    _row_matrices,
    _world_matrices,
    bind_pose,
    export_usd,
    joint_local_transforms,
    leg_mesh,
    skeleton_layout,
)
from footfall.scenarios import builtin_creature_names, default_gait_name, load_creature, load_gait, load_scenario

SCENARIO = "mixed"  # hills (a terrain that is not flat) and crates looping along waypoints
CHARACTERS = 2
FRAMES = 20
FK_TOLERANCE_M = 1e-5
"""Exported skeleton vs the planner's forward kinematics. The recording stores angles and poses
in float32 and USD stores joint rotations (quatf) and translations (float3) in float32, ~10 m
from the origin: a few 1e-7 m of round-off. 1e-5 m is a tenth of the IK's own tolerance
(1e-4 m), so a wrong joint axis, sign or order (errors of mm to cm) cannot pass."""
POSE_TOLERANCE_M = 1e-9
"""Box translate, rotateY and scale are written in double precision, straight from
Obstacles.poses_at: only round-off remains."""
ROUND_OFF_M = 1e-12
"""Two float64 compositions of the same transforms (metres up to ~10 m): round-off only."""
FLOAT32_STORAGE_M = 1e-6
"""Positions stored as float32 (recording and USD point arrays), up to ~10 m from the origin:
half an ulp is 5e-7 m."""
CLI = [sys.executable, "-m", "footfall.cli"]


def _cli(*args):
    return subprocess.run(CLI + list(args), capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A tiny simulation kept in memory (its final state) and saved as a recording."""
    scenario = load_scenario(SCENARIO)
    creature = load_creature(scenario.crowd.creature)
    gait = load_gait(default_gait_name(creature.name), creature)
    model, state = init_crowd(scenario, creature, gait, n_characters=CHARACTERS, seed=0)
    recorder = Recorder(model, state, FRAMES)
    summary = simulate(model, state, FRAMES, recorder)
    path = tmp_path_factory.mktemp("recording") / "run.npz"
    recorder.save(path, model, summary, {"scenario": scenario.name, "seed": 0, "lod": "off", "gait": gait.name})
    return {"scenario": scenario, "creature": creature, "state": state, "path": path,
            "recording": load_recording(path)}


@pytest.fixture(scope="module", params=[".usda", ".usdc"])
def exported(request, run, tmp_path_factory):
    out = tmp_path_factory.mktemp("usd") / f"scene{request.param}"
    written = export_usd(run["recording"], run["scenario"], run["creature"], out)
    assert written == out and out.is_file()
    assert sorted(p.name for p in out.parent.iterdir()) == [out.name]  # no temporary file left
    return Usd.Stage.Open(str(out))


def test_every_validator_passes(exported):
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    assert len(validators) > 0
    errors = UsdValidation.ValidationContext(validators).Validate(exported)
    assert [f"{e.GetValidator().GetMetadata().name}: {e.GetName()}: {e.GetMessage()}" for e in errors] == []


def test_stage_metadata(exported, run):
    # authored, not the fallbacks (which are the same values)
    assert exported.HasAuthoredMetadata("upAxis") and exported.HasAuthoredMetadata("metersPerUnit")
    assert UsdGeom.GetStageUpAxis(exported) == UsdGeom.Tokens.y
    assert UsdGeom.GetStageMetersPerUnit(exported) == 1.0
    assert exported.GetDefaultPrim().GetPath() == "/World"
    assert exported.GetTimeCodesPerSecond() == pytest.approx(1.0 / run["recording"].dt)
    assert (exported.GetStartTimeCode(), exported.GetEndTimeCode()) == (1.0, float(FRAMES))
    skeletons = [p for p in exported.Traverse() if p.IsA(UsdSkel.Skeleton)]
    assert len(skeletons) == CHARACTERS
    terrain = UsdGeom.Mesh(exported.GetPrimAtPath("/World/Terrain"))
    heights = np.array(terrain.GetPointsAttr().Get())[:, 1]
    assert heights.min() == pytest.approx(run["scenario"].terrain.heights.min(), abs=0.05)
    assert np.ptp(heights) > 0.1  # the hills are there


def test_boxes_follow_their_motion(exported, run):
    obstacles = run["scenario"].obstacles
    times = run["recording"].times
    moving = np.flatnonzero(~obstacles.is_static)
    assert moving.size > 0 and moving.size < len(obstacles)
    for i in range(len(obstacles)):
        cube = UsdGeom.Cube(exported.GetPrimAtPath(f"/World/Obstacles/box_{i:03d}"))
        translate = cube.GetOrderedXformOps()[0]
        samples = translate.GetAttr().GetTimeSamples()
        if obstacles.is_static[i]:
            assert samples == []
            continue
        assert samples == [float(k + 1) for k in range(FRAMES)]
        for code, t in zip(samples, times):
            # a point on the box's local +x face, in the world: centre + half size along (cos yaw, 0, sin yaw)
            world = UsdGeom.XformCache(code).GetLocalToWorldTransform(cube.GetPrim())
            face = np.array(world.Transform(Gf.Vec3d(0.5, 0.0, 0.0)))
            centres, yaws = obstacles.poses_at(t)
            want = centres[i] + 0.5 * obstacles.sizes[i, 0] * np.array([np.cos(yaws[i]), 0.0, np.sin(yaws[i])])
            np.testing.assert_allclose(face, want, rtol=0, atol=POSE_TOLERANCE_M)


def _skeleton_query(stage, c):
    cache = UsdSkel.Cache()
    root = UsdSkel.Root(stage.GetPrimAtPath(f"/World/Characters/character_{c:03d}/Rig"))
    cache.Populate(root, Usd.PrimDefaultPredicate)
    skeleton = UsdSkel.Skeleton(root.GetPrim().GetChild("Skeleton"))
    mesh = root.GetPrim().GetChild("Legs")
    return cache.GetSkelQuery(skeleton), cache.GetSkinningQuery(mesh), UsdGeom.Mesh(mesh)


def test_skeleton_forward_kinematics_is_the_ik_chain(exported, run):
    recording, creature, state = run["recording"], run["creature"], run["state"]
    legs = legs_of(creature)
    layout = skeleton_layout(creature)
    mesh_data = leg_mesh(creature, layout, bind_pose(creature, layout)[1])
    assert recording.ik_on.all()  # LOD off: every leg solved every frame
    for c in range(CHARACTERS):
        skel_query, skinning_query, mesh = _skeleton_query(exported, c)
        assert list(skel_query.GetJointOrder()) == list(layout.joints)
        for k in range(FRAMES):
            code = float(k + 1)
            world = np.array(skel_query.ComputeJointWorldTransforms(UsdGeom.XformCache(code)))
            joints = world[layout.leg_joints, 3, :3]  # USD row-vector matrices: translation in row 3
            rotation = body_rotation(*recording.orientation[k, c])
            hips = recording.pelvis[k, c] + legs.hips @ rotation.T
            expected = forward_legs(hips, np.broadcast_to(rotation, (legs.n_legs, 3, 3)), legs.rest_azimuths,
                                    legs.segment_lengths, recording.joint_angles[k, c], legs.plane_rolls)
            np.testing.assert_allclose(joints, expected, rtol=0, atol=FK_TOLERANCE_M, err_msg=f"frame {k}")
        # last frame: the skinned mesh's foot ends are where the IK put the feet (its own float64 result)
        skinning = skel_query.ComputeSkinningTransforms(code)
        points = mesh.GetPointsAttr().Get()  # bind pose, skinned in place
        assert skinning_query.ComputeSkinnedPoints(skinning, points, code)
        tips = np.array(points)[mesh_data.tips].mean(axis=1)
        np.testing.assert_allclose(joints[:, -1], state.fk_feet[c], rtol=0, atol=FK_TOLERANCE_M)
        np.testing.assert_allclose(tips, state.fk_feet[c], rtol=0, atol=FK_TOLERANCE_M)
        # ... which is the recorded foot, up to the IK's residual
        gap = np.linalg.norm(joints[:, -1] - recording.feet[-1, c], axis=1)
        assert (gap <= state.residual[c] + FK_TOLERANCE_M).all()


@pytest.mark.parametrize("name", builtin_creature_names())
def test_skeleton_chain_of_every_creature_at_random_poses(name):
    """The joint transforms (composed here as UsdSkel composes them) against the planner's FK, for
    every built-in creature at random body poses and joint angles, beyond the spider's run above."""
    creature = load_creature(name)
    legs = legs_of(creature)
    layout = skeleton_layout(creature)
    rng = np.random.default_rng(7)
    for _ in range(20):
        pelvis = rng.uniform(-5.0, 5.0, 3)
        orientation = rng.uniform(-np.pi, np.pi, 3) * [1.0, 0.3, 0.3]
        angles = rng.uniform(-1.5, 1.5, (legs.n_legs, legs.segment_lengths.shape[1] + 1))
        rotations, translations = joint_local_transforms(creature, layout, pelvis, orientation, angles)
        world = _world_matrices(_row_matrices(rotations, translations), layout.parents)
        rotation = body_rotation(*orientation)
        expected = forward_legs(pelvis + legs.hips @ rotation.T, np.broadcast_to(rotation, (legs.n_legs, 3, 3)),
                                legs.rest_azimuths, legs.segment_lengths, angles, legs.plane_rolls)
        np.testing.assert_allclose(world[layout.leg_joints, 3, :3], expected, rtol=0, atol=ROUND_OFF_M)


def test_foot_paths_and_footprints(exported, run):
    recording = run["recording"]
    frames, characters, legs = recording.touchdowns()
    assert frames.size > 0
    for c in range(CHARACTERS):
        base = f"/World/Characters/character_{c:03d}"
        curves = UsdGeom.BasisCurves(exported.GetPrimAtPath(f"{base}/FootPaths"))
        assert list(curves.GetCurveVertexCountsAttr().Get()) == [FRAMES] * recording.legs
        np.testing.assert_allclose(np.array(curves.GetPointsAttr().Get()).reshape(recording.legs, FRAMES, 3),
                                   np.swapaxes(recording.feet[:, c], 0, 1), rtol=0, atol=FLOAT32_STORAGE_M)
        mine = characters == c
        prints = exported.GetPrimAtPath(f"{base}/Footprints")
        if not mine.any():
            assert not prints.IsValid()
            continue
        got = np.array(UsdGeom.Points(prints).GetPointsAttr().Get())
        np.testing.assert_allclose(got, recording.feet[frames[mine], c, legs[mine]], rtol=0, atol=FLOAT32_STORAGE_M)
        assert recording.in_stance[frames[mine], c, legs[mine]].all()
        assert not recording.in_stance[frames[mine] - 1, c, legs[mine]].any()


def _one_line_exit_2(proc):
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("footfall: error: "), proc.stderr
    return lines[0]


def test_cli_exports_a_recording(run, tmp_path):
    out = tmp_path / "deep" / "scene.usda"
    proc = _cli("export-usd", "--recording", str(run["path"]), "--frames", "5", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    assert str(out) in proc.stdout
    stage = Usd.Stage.Open(str(out))
    assert stage.GetEndTimeCode() == 5.0
    assert len([p for p in stage.Traverse() if p.IsA(UsdSkel.Skeleton)]) == CHARACTERS


@pytest.mark.slow  # two CLI runs (about 6 s)
def test_a_recording_of_a_users_creature_exports_without_its_file(tmp_path):
    # The recording carries the creature file's text: the file may be gone (or never shipped along).
    import shutil
    from pathlib import Path

    creature = tmp_path / "my-heptapod.toml"
    shutil.copy(Path(__file__).parents[1] / "scenarios" / "examples" / "heptapod.toml", creature)
    recording = tmp_path / "run.npz"
    proc = _cli("simulate", "flat", "--creature", str(creature), "--characters", "1", "--frames", "6",
                "--record", str(recording))
    assert proc.returncode == 0, proc.stderr
    creature.unlink()
    out = tmp_path / "scene.usda"
    proc = _cli("export-usd", "--recording", str(recording), "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    stage = Usd.Stage.Open(str(out))
    assert any(p.IsA(UsdSkel.Skeleton) for p in stage.Traverse())
    from footfall.reports._recording import load_recording
    from footfall.scenarios import load_creature

    loaded = load_recording(recording).load_creature()
    shipped = load_creature(str(Path(__file__).parents[1] / "scenarios" / "examples" / "heptapod.toml"))
    assert loaded.name == "heptapod" and loaded.n_legs == 7
    np.testing.assert_array_equal(loaded.hips, shipped.hips)
    np.testing.assert_array_equal(loaded.rest_feet, shipped.rest_feet)


def test_cli_unknown_scenario(tmp_path):
    line = _one_line_exit_2(footfall_cli("export-usd", "no-such-place", "--out", str(tmp_path / "x.usda")))
    assert "no-such-place" in line
    assert list(tmp_path.iterdir()) == []


def test_cli_unwritable_output_leaves_nothing(run, tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    line = _one_line_exit_2(footfall_cli("export-usd", "--recording", str(run["path"]), "--out",
                                 str(blocker / "scene.usda")))
    assert "a-file" in line
    assert [p.name for p in tmp_path.iterdir()] == ["a-file"] and blocker.read_text() == "not a folder"


def test_cli_recording_from_another_version(run, tmp_path):
    with np.load(run["path"]) as data:
        arrays = {k: data[k] for k in data.files}
    header = json.loads(str(arrays.pop("header")))
    header["version"] += 1
    old = tmp_path / "other.npz"
    np.savez_compressed(old, header=np.array(json.dumps(header)), **arrays)
    out = tmp_path / "scene.usdc"
    out.write_text("previous export")
    line = _one_line_exit_2(footfall_cli("export-usd", "--recording", str(old), "--out", str(out)))
    assert "header.version" in line
    assert out.read_text() == "previous export"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.npz", "scene.usdc"]


@pytest.mark.parametrize("change, field", [
    (lambda header, arrays: header.update(format="something-else"), "header.format"),
    (lambda header, arrays: header.update(version="1"), "header.version"),
    (lambda header, arrays: arrays.pop("joint_angles"), "joint_angles"),
    (lambda header, arrays: arrays.update(feet=arrays["feet"][:, :, :-1]), "feet"),
])
def test_load_recording_names_the_bad_field(run, tmp_path, change, field):
    with np.load(run["path"]) as data:
        arrays = {k: data[k] for k in data.files}
    header = json.loads(str(arrays.pop("header")))
    change(header, arrays)
    path = tmp_path / "bad.npz"
    np.savez_compressed(path, header=np.array(json.dumps(header)), **arrays)
    with pytest.raises(InputError) as error:
        load_recording(path)
    assert error.value.field == field and error.value.file == str(path)


def test_load_recording_refuses_a_file_that_is_no_archive(tmp_path):
    junk = tmp_path / "junk.npz"
    junk.write_text("not an archive")
    with pytest.raises(InputError, match="not a .npz archive"):
        load_recording(junk)
