"""The report's LOD quality columns, recomputed from a recording (issue 20, item 5).

A crowd walks with LOD zoomed, its levels set so that every level is used and characters switch
between them, while a forbidden crate faster than a spider sweeps through it (feet end inside it
at every level: the count must read non-zero to guard anything). The run is saved with
``Recorder`` and loaded back with ``load_recording``; from the file alone (the rendered feet by
forward kinematics of the recorded angles, :func:`reports._animation.joint_positions`) this test
recomputes, per level, what ``planner._lod_quality.LevelMeter`` measured during the run and what
the report's table (``reports._lod_report.level_rows``) shows, and asserts they agree.

The recomputation is written here, in plain numpy, from the definitions in the module doc of
``planner._lod_quality``; it shares with the runtime only the stride law, the two box-counting
kernels (checked on hand-made states in ``tests/test_counters.py``) and forward kinematics.
"""

import numpy as np
import pytest
from conftest import fresh_seeds

from footfall.planner._counters import CONTACT_TOLERANCE_M
from footfall.planner._crowd import init_crowd
from footfall.planner._kernels_controller import count_body_overlaps, count_collisions
from footfall.planner._lod import LEVEL_HIDDEN, LEVEL_NAMES, LodConfig
from footfall.planner._simulation import STEADY_BAND, Recorder, simulate
from footfall.planner._timing import stride_frequency
from footfall.reports._animation import joint_positions
from footfall.reports._lod_report import level_rows
from footfall.reports._recording import load_recording
from footfall.scenarios import default_gait_name, load_creature, load_gait, load_scenario

FRAMES = 90
CHARACTERS = 8
# A recording keeps positions and angles in float32: 2**-24 of a few metres is about 2e-7 m, and
# forward kinematics of float32 angles adds as much again; what the run measured in float64 must
# come back from the file within this.
RECORDING_TOL_M = 1e-5
STRIDE_REL_TOL = 1e-3  # the same for a per-stride error, a ratio of such lengths

SWEEP_TOML = """
name = "lod-sweep"
description = "A forbidden crate faster than a spider sweeps through a crowd of them: no escape."
seed = 1

[terrain]
kind = "flat"
size = [8.0, 8.0]
cell_size = 0.05

[[obstacles]]
centre = [0.0, -3.0]
size = [3.0, 0.3, 0.4]
kind = "forbidden"
motion = { kind = "velocity", velocity = [0.0, 1.5] }

[crowd]
creature = "spider"
count = 8
centre = [0.0, 0.0]
heading = 0.0
speed = 0.2
goal = [2.5, 0.0]
spawn_clear_s = 0.0  # spawned where the crate will sweep through
"""


def _recompute(recording, creature, model, start, goal):
    """Per-level quality of the recorded run, from the recording and the state before its first
    frame (``start``): the definitions of ``planner._lod_quality``."""
    rendered = joint_positions(recording, creature)[..., -1, :]  # (F, C, L, 3), as drawn
    planned, stance, level = recording.feet, recording.in_stance, recording.lod_level
    f, c, _ = stance.shape
    rendered = np.concatenate([start["rendered"][None], rendered])
    planned = np.concatenate([start["planned"][None], planned])
    stance = np.concatenate([start["stance"][None], stance])
    level = np.concatenate([start["level"][None], level])
    n = len(LEVEL_NAMES)
    out = {k: {"character_frames": 0, "max_stance_slip_m": 0.0, "jump_max_m": 0.0, "feet_in_boxes": 0,
               "body_overlaps": 0, "residuals": [], "errors": []} for k in range(n)}
    pop, switches = 0.0, 0
    anchor = rendered[0].copy()
    last = {}  # (character, leg) -> (frame, foot xz, pelvis xz, rest point xz, speed) of its last landing
    slowest, fastest = {}, {}  # (character, leg) -> the body's slowest / fastest speed since that landing
    obstacles = model.raster.obstacles
    body = creature.body_box
    for k in range(1, f + 1):
        r, was = rendered[k], k - 1
        jump = np.linalg.norm((r - rendered[was]) - (planned[k] - planned[was]), axis=-1).max(axis=1)
        switched = level[k] != level[was]
        if switched.any():
            pop = max(pop, float(jump[switched].max()))
            switches += int(switched.sum())
        stayed = stance[k] & stance[was]
        slip = np.where(stayed, np.linalg.norm(r - anchor, axis=-1), 0.0).max(axis=1)
        landed = stance[k] & ~stance[was]
        anchor[landed] = r[landed]
        centres, yaws = obstacles.poses_at(k * model.dt)  # frame k - 1 of the file is at time k dt
        in_boxes = np.zeros(c, np.int64)
        count_collisions(np.ascontiguousarray(r), 0.5 * creature.foot_length, 0.5 * creature.foot_width,
                         np.ascontiguousarray(recording.foot_yaw[was]), np.ascontiguousarray(centres),
                         np.ascontiguousarray(obstacles.sizes, dtype=np.float64), np.ascontiguousarray(yaws),
                         np.ascontiguousarray(obstacles.forbidden, dtype=np.bool_), in_boxes, CONTACT_TOLERANCE_M)
        overlaps = np.zeros(c, np.int64)
        count_body_overlaps(np.ascontiguousarray(recording.pelvis[was][:, [0, 2]]),
                            np.ascontiguousarray(recording.orientation[was][:, 0]), 0.5 * float(body[0]),
                            0.5 * float(body[1]), overlaps)
        drawn = recording.ik_on[was]
        for ch in range(c):
            row = out[int(level[k, ch])]
            row["character_frames"] += 1
            row["max_stance_slip_m"] = max(row["max_stance_slip_m"], float(slip[ch]))
            if not switched[ch]:
                row["jump_max_m"] = max(row["jump_max_m"], float(jump[ch]))
            row["feet_in_boxes"] += int(in_boxes[ch])
            row["body_overlaps"] += int(overlaps[ch])
            if drawn[ch]:
                row["residuals"].extend(np.linalg.norm(r[ch] - planned[k, ch], axis=-1))
        # Steady strides (planner._simulation.StrideMeter): touch-down to touch-down of one foot,
        # the body's speed within STEADY_BAND of the stride's mean speed at every frame of it.
        for key in last:
            slowest[key] = min(slowest[key], recording.speed[was, key[0]])
            fastest[key] = max(fastest[key], recording.speed[was, key[0]])
        for ch, leg in zip(*np.nonzero(landed)):
            foot = planned[k, ch, leg, [0, 2]]
            pelvis = recording.pelvis[was, ch, [0, 2]]
            # the leg's rest point (feet spacing 1: the run changes none), turned with the heading
            heading = float(recording.orientation[was, ch, 0])
            ahead, side = model.rest_body[leg]
            rest = pelvis + [ahead * np.cos(heading) - side * np.sin(heading), ahead * np.sin(heading) + side * np.cos(heading)]
            speed = recording.speed[was, ch]
            if (ch, leg) in last:
                k0, foot0, pelvis0, rest0, speed0 = last[ch, leg]
                v = np.linalg.norm(pelvis - pelvis0) / ((k - k0) * model.dt)
                share = np.linalg.norm(rest - rest0) / np.linalg.norm(pelvis - pelvis0) if v > 0 else 0.0
                g = goal[ch]
                if (0.5 * g <= speed0 <= 1.5 * g and 0.5 * g <= speed <= 1.5 * g and v > 0 and share > 0
                        and (1.0 - STEADY_BAND) * v <= slowest[ch, leg] and fastest[ch, leg] <= (1.0 + STEADY_BAND) * v):
                    stride = np.linalg.norm(foot - foot0)
                    f_v = float(stride_frequency(model.timing, np.array([v]), model.leg_height)[0])
                    out[int(level[k, ch])]["errors"].append(abs(stride * f_v / (v * share) - 1.0))
            last[ch, leg] = (k, foot, pelvis, rest, speed)
            slowest[ch, leg] = fastest[ch, leg] = speed
    return out, pop, switches


@pytest.mark.parametrize("seed", fresh_seeds((1,), 1, salt=15))
def test_the_reports_lod_quality_columns_are_what_the_recording_shows(tmp_path, seed):
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP_TOML)
    scenario, creature = load_scenario(path), load_creature("spider")
    lod = LodConfig(near_m=0.0, far_m=2.0, hysteresis_m=0.05)  # about half the shown spiders far
    model, state = init_crowd(scenario, creature, load_gait(default_gait_name("spider"), creature),
                              n_characters=CHARACTERS, seed=seed, lod_mode="zoomed", lod=lod)
    start = {"rendered": np.where(state.ik_on[:, None, None], state.fk_feet, state.feet).copy(),
             "planned": state.feet.copy(), "stance": state.in_stance.copy(), "level": state.lod_level.copy()}
    goal = np.minimum(state.desired_speed, model.speed_cap)
    recorder = Recorder(model, state, FRAMES)
    summary = simulate(model, state, FRAMES, recorder)
    recorder.save(tmp_path / "run.npz", model, summary, {"scenario": str(path), "seed": seed, "lod": "zoomed"})
    recording = load_recording(tmp_path / "run.npz")
    assert (state.feet_spacing == 1.0).all()  # as _recompute takes it
    mine, pop, switches = _recompute(recording, creature, model, start, goal)
    where = f"seed {seed}"

    # The premise: every level used, characters switching, feet inside the crate (else nothing is guarded).
    levels = summary.lod_levels
    assert set(levels["levels"]) == set(LEVEL_NAMES), where
    assert switches >= 5, where
    assert sum(mine[k]["feet_in_boxes"] for k in range(len(LEVEL_NAMES))) > 0, where

    # Off screen the IK is skipped (the paper's Table 1, LOD zoomed): a hidden character is drawn with
    # straight legs to its planned feet, every shown one is solved.
    hidden = recording.lod_level == LEVEL_HIDDEN
    assert not recording.ik_on[hidden].any(), where
    assert recording.ik_on[~hidden].all(), where

    assert levels["switches"] == switches, where
    assert levels["pop_max_m"] == pytest.approx(pop, abs=RECORDING_TOL_M), where
    for k, name in enumerate(LEVEL_NAMES):
        got, want = levels["levels"][name], mine[k]
        assert got["character_frames"] == want["character_frames"], (where, name)
        assert got["feet_in_boxes"] == want["feet_in_boxes"], (where, name)
        assert got["body_overlaps"] == want["body_overlaps"], (where, name)
        assert got["max_stance_slip_m"] == pytest.approx(want["max_stance_slip_m"], abs=RECORDING_TOL_M), (where, name)
        assert got["jump_max_m"] == pytest.approx(want["jump_max_m"], abs=RECORDING_TOL_M), (where, name)
        residuals = np.array(want["residuals"])
        if residuals.size:
            assert got["ik_residual_p95_m"] == pytest.approx(np.percentile(residuals, 95), abs=RECORDING_TOL_M)
        else:
            assert got["ik_residual_p95_m"] is None, (where, name)
        errors = np.array(want["errors"])
        assert got["strides_measured"] == errors.size, (where, name)
        if errors.size:
            assert got["stride_rel_error_median"] == pytest.approx(np.median(errors), rel=STRIDE_REL_TOL), (where, name)
            assert got["stride_rel_error_p90"] == pytest.approx(np.percentile(errors, 90), rel=STRIDE_REL_TOL)

    # The report's table (reports._lod_report) shows the same numbers for this run.
    run_levels = {**levels, "levels": {name: {**row, "situations": 0, "score_loss_pct": None}
                                        for name, row in levels["levels"].items()}}
    rows = {row["level"]: row for row in level_rows([{"kind": "lod", "lod_mode": "zoomed", "lod_levels": run_levels}])}
    total = CHARACTERS * FRAMES
    for k, name in enumerate(LEVEL_NAMES):
        row, want = rows[name], mine[k]
        assert row["share"] == pytest.approx(want["character_frames"] / total, abs=1e-12), (where, name)
        assert row["feet_in_boxes"] == want["feet_in_boxes"], (where, name)
        assert row["body_overlaps"] == want["body_overlaps"], (where, name)
        assert row["max_stance_slip_mm"] == pytest.approx(1e3 * want["max_stance_slip_m"], abs=1e3 * RECORDING_TOL_M)
        assert row["pop_max_mm"] == pytest.approx(1e3 * pop, abs=1e3 * RECORDING_TOL_M), (where, name)
        if want["errors"]:
            assert row["stride_rel_error_median"] == pytest.approx(np.median(want["errors"]), rel=STRIDE_REL_TOL)
