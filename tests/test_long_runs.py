"""Long, crowded property runs (issue 20, item 3): every built-in scenario x creature x LOD mode.

Each run is a crowd of 8 spawned as :func:`planner._crowd.spawn_positions` promises, 600 frames
(20 s: long enough to meet the crates, the stairs' risers and the moving boxes), run exactly as
``footfall evaluate`` and ``footfall simulate`` run it (:func:`reports._evaluate.run_one`). The
safety promises are checked per frame and per foot on what is rendered (planner._counters): no
rendered foot inside a box, no landing on a forbidden box, no crossed legs, no overlapping bodies,
no two characters' stance feet on one spot, no stance foot moved more than 1 mm from its
touch-down until lift-off, IK residual p95 within 2 mm. (Stuck time, stride error and speed are
quality bars, reported by ``footfall evaluate``, not asserted here.)

Seeds: each cell runs one fresh seed per session (conftest.fresh_seeds) and, once it has no known
defect, every seed that ever failed in it (FIXED_SEEDS); a failure prints the seed and the command
that replays the run.

LOD: ``off`` and ``zoomed``. ``on`` frames a crowd of 8 at full detail, so its runs are those of
``off`` (48 runs, 8 x 600 frames, seeds 900-901: the same counters to the last one).
"""

import warnings

import pytest
from conftest import fresh_seeds

from footfall.reports._evaluate import replay_command, run_one
from footfall.scenarios import builtin_creature_names, builtin_scenario_names

FRAMES = 600
CHARACTERS = 8
LOD_MODES = ("off", "zoomed")
SAFETY = ("collisions", "forbidden_footprints", "leg_crossings", "body_overlaps", "shared_foot_spots",
          "stance_slip", "ik_residual")

# (scenario, creature) -> {promise: why it is not kept yet}: measured with footfall evaluate, 8
# characters x 600 frames, LOD off and zoomed, seeds 1000-1005 (and 900-901), on 0d9105f. A known
# violation is reported as a warning, not a failure; every other promise of the cell is asserted.
# When a defect is fixed, its entry goes and the cell's fixed seeds guard the fix.
_HELD = ("a crate runs down a character whose body is held by a foot it cannot follow: tucked feet end in the crate"
         " (traced on crates-moving, spider)")
_CROSS = "adjacent legs cross while the body turns or is held and the gait swings a neighbour (untraced per seed)"
_SLIP = ("a foot lands in the frame its body is held and its pose taken back: out of reach, it snaps on 2 frames later"
         " (traced on crates-moving, spider)")
_LOST_FOOT = ("a foot its leg cannot follow (the body held, IK 3.9 cm short) is drawn off its planned spot, 4 cm from"
              " another character's foot planned 7 cm away (seed 3458258, frames 200-201, found by a fresh seed of"
              " session 20's CI)")
_FRONT_SWINGS = ("both front legs swinging while the body turns, the right one's swing IK 6.7 cm off its path: their"
                 " drawn legs cross for a frame (seed 1242734951, frame 205, found by a fresh seed of session 20's CI)")
_CORNER = ("a swing clips the corner of a turned forbidden crate 3 mm above its top (seed 1005, frame 491: 1"
           " foot-frame in 16 runs; why its path passes there is untraced)")
_SWINGS_CROSS = ("two adjacent legs swinging at once (L2, L3) cross in the air for a frame at 0.22 m/s (seed"
                 " 1099286570, LOD zoomed, frame 576, found by the fresh seed of session 19's CI; untraced)")
_QUAD_FOOT_IN = ("a quadruped's rendered foot inside a crate for 1 foot-frame (seed 918250553, LOD zoomed, found by a"
                 " fresh seed of session 21's CI; untraced)")
_HIDDEN_SNAP = ("a stance foot its leg could not reach (the body held, the IK 8.4 mm short) is drawn where it was planned"
                " once its character goes off screen and its IK off: an 8.4 mm jump at the switch (stairs, ant, seed"
                " 88250359, LOD zoomed, frame 565, found by the fresh seed of session 25's CI; the same before that"
                " session's changes; traced; stairs, robot5, seed 956051917, LOD zoomed, frame 409, character 3, leg 4:"
                " a 2.0 mm jump, found by the fresh seed of session 29's CI, traced; the other way on mixed, robot5,"
                " seed 31018164, LOD zoomed, frame 432, character 2, leg 2: drawn as planned off screen, the foot is"
                " 10.3 mm from it once the IK comes on and the body is held, found by a fresh seed of session 34's suite"
                " after bodies stopped stepping into each other; 0.25 mm before that change; traced)")
_LIFT_OFF_CROSS = ("a leg lifting off while the body turns is drawn over its neighbour, its knee only, for a frame"
                   " (stairs, spider, seed 1479478811, LOD zoomed, frame 259, found by a fresh seed of session 22's"
                   " review; the same on the crates-moving 1200-frame bar; traced)")
_ASTRIDE = ("robot5 walks onto the 0.17 m safe crate beside its spawn (crates-moving's box 18) and is held"
            " astride it: legs on its top and beside it cannot reach their feet (IK 1-4 cm short, 877 foot-frames over"
            " 2 mm, the body held 85 frames; seed 1481763854, LOD off, found by the fresh seed of session 24's CI;"
            " traced: the same crate holds character 2 for good with seed 1107)")
_SHORT_ONTO_TOP = ("robot5 plans a foot onto a 0.14 m safe crate's top its leg cannot reach (reach checked in xz only):"
                   " the drawn foot lands 6 cm short of the planned one, 1.6 cm below the top against the crate's side,"
                   " for a frame, then steps again (crates, seed 456603702, LOD zoomed, character 2, frame 282, box 9;"
                   " found by the fresh seed of session 28's CI; the same before that session's change; traced)")
_SWING_THROUGH = ("an ant's swing passes through the corner of a turned forbidden crate, 4 cm above the ground and"
                  " 1.3 cm inside it, for a frame: the 4 cm cell under the foot is forbidden in the raster, so the"
                  " drawn path leaves the cells its wavefront kept (seed 1914251834, LOD off, character 2, leg 4,"
                  " frame 590, box 2; found by the fresh seed of session 30's CI, on code whose default runs that"
                  " session left bit for bit; why the path enters the cell is untraced)")
_SWING_CLIPS_WALL = ("a spider's swing passes a forbidden 0.1 m wall 8 cm above the ground with its foot's rectangle"
                     " overlapping the wall's side, for a frame, as planned (drawn = planned: seed 594871979, LOD"
                     " zoomed, character 4, leg 0, frame 584, box 4, mid-swing; found by the fresh seed of session 32's"
                     " CI, on a runtime that session did not change; why the path passes there is untraced)")
# Since the way round static boxes became the default (2026-11-26), the fixed seeds of (mixed, spider) ran
# clean of every promise, and those of (crates, spider), (crates-moving, spider) and (mixed, robot5) of
# every promise but crossings: their entries keep only crossings (feet in boxes, overlaps and slip had
# been known there). (mixed, spider) had no entry for one CI: its fresh seed 2133522511 (LOD zoomed) drew
# one crossing frame. (crates-moving, spider) knows feet in boxes again since session 32's CI
# (_SWING_CLIPS_WALL, a different defect from the tucked feet it knew before).
KNOWN: dict[tuple[str, str], dict[str, str]] = {
    ("crates", "ant"): {"collisions": _SWING_THROUGH, "leg_crossings": _SWINGS_CROSS},
    ("crates", "quadruped"): {"collisions": _CORNER, "leg_crossings": _FRONT_SWINGS},
    ("crates", "robot5"): {"collisions": _SHORT_ONTO_TOP, "leg_crossings": _CROSS, "stance_slip": _SLIP},
    ("crates", "spider"): {"leg_crossings": _CROSS},
    # Overlaps and slip went with the look-ahead escapes (2026-11-27: none over the 16 fixed seeds and
    # seeds 5000-5009, both LOD modes); seed 5001 still put 18 foot-frames in a crate.
    ("crates-moving", "ant"): {"collisions": _HELD, "leg_crossings": _CROSS},
    # Overlaps went when a body stopped stepping into another (2026-11-27: none over the fixed seeds, 1014
    # and seeds 5000-5009, both LOD modes). Feet in crates went when a swinging leg's body stayed high
    # enough for it to fold to its foot and its IK got a stance leg's sweeps where its own left it off
    # (session 49: 6 of the cell's 11 fixed seeds had put a foot in a crate, each a quadruped stepping
    # off one; none after, nor over seeds 5000-5009 in both LOD modes). Stance slip: the known switch of
    # _HIDDEN_SNAP, found by session 49's second CI (seed 947983823, LOD zoomed, character 7, leg 0,
    # frame 333: the character comes on screen with its body held, the IK 3.6 mm short; the same on
    # a97be5c, before that session's changes; traced).
    ("crates-moving", "quadruped"): {"leg_crossings": _CROSS, "stance_slip": _HIDDEN_SNAP},
    ("crates-moving", "robot5"): {"collisions": _HELD, "leg_crossings": _CROSS, "stance_slip": _SLIP,
                                  "shared_foot_spots": _LOST_FOOT, "ik_residual": _ASTRIDE},
    ("crates-moving", "spider"): {"collisions": _SWING_CLIPS_WALL, "leg_crossings": _CROSS},
    # Feet in crates and overlaps went with the look-ahead escapes (2026-11-27: none over the 13 fixed
    # seeds and seeds 5000-5009, both LOD modes).
    ("mixed", "ant"): {"leg_crossings": _CROSS},
    ("mixed", "quadruped"): {"collisions": _QUAD_FOOT_IN, "leg_crossings": _CROSS},
    ("mixed", "robot5"): {"leg_crossings": _CROSS, "stance_slip": _HIDDEN_SNAP},
    ("mixed", "spider"): {"leg_crossings": _CROSS},
    ("stairs", "ant"): {"leg_crossings": _CROSS, "stance_slip": _HIDDEN_SNAP},
    ("stairs", "robot5"): {"stance_slip": _HIDDEN_SNAP},
    ("stairs", "spider"): {"leg_crossings": _LIFT_OFF_CROSS},
}

# (scenario, creature, lod) -> every seed that failed a safety promise there (known or not). A cell
# with no known defect runs them all; a cell with one runs only its fresh seed (its fixed seeds would
# repeat what KNOWN tolerates, at a second a run; they run again once its entry goes).
FIXED_SEEDS: dict[tuple[str, str, str], tuple[int, ...]] = {
    ("crates", "ant", "off"): (1914251834,),
    ("crates", "ant", "zoomed"): (1099286570, 902059866),
    ("crates", "quadruped", "off"): (1005, 1242734951),
    ("crates", "robot5", "off"): (900, 901, 1001),
    ("crates", "robot5", "zoomed"): (900, 901, 1001, 456603702),
    ("crates", "spider", "off"): (900, 901, 1000, 1002, 1004, 1005),
    ("crates", "spider", "zoomed"): (1000, 1001, 1002, 1003),
    ("crates-moving", "ant", "off"): (900, 901, 1000, 1001, 1002, 1003, 1004, 1005, 5001),
    ("crates-moving", "ant", "zoomed"): (900, 901, 1000, 1001, 1002, 1003, 1004, 1005, 5001),
    ("crates-moving", "quadruped", "off"): (1002, 1003, 1005, 5008),
    ("crates-moving", "quadruped", "zoomed"): (1002, 1003, 1005, 556998574, 1855057847, 474212573, 340293196, 2132651497, 947983823),
    ("crates-moving", "robot5", "off"): (900, 901, 1000, 1001, 1002, 1003, 1004, 3458258, 1481763854, 1878522243),
    ("crates-moving", "robot5", "zoomed"): (900, 901, 1000, 1001, 1002, 1004, 1005, 1182161004, 1435258509),
    ("crates-moving", "spider", "off"): (900, 901, 1000, 1002, 1003, 1004, 1005, 1910660156),
    ("crates-moving", "spider", "zoomed"): (900, 901, 1000, 1001, 1002, 1003, 1004, 1005, 594871979, 1913662600),
    ("mixed", "ant", "off"): (900, 901, 1000, 1001, 1003, 1102, 5000),
    ("mixed", "ant", "zoomed"): (900, 1000, 1001, 1002, 1003, 1004, 1005),
    ("mixed", "quadruped", "off"): (901,),
    ("mixed", "quadruped", "zoomed"): (901, 918250553, 1619116989),
    ("mixed", "robot5", "off"): (900, 1000, 1001, 1002, 1003, 1004, 454058170),
    ("mixed", "robot5", "zoomed"): (900, 901, 1000, 1001, 1002, 1003, 1004, 1005, 31018164, 1626034960),
    ("mixed", "spider", "off"): (900, 901, 1000, 1001, 1002, 1004, 1005, 1121411189),
    ("mixed", "spider", "zoomed"): (900, 901, 1002, 1003, 1004, 1005, 666487550, 2133522511, 2095385597),
    ("stairs", "ant", "off"): (900,),
    ("stairs", "ant", "zoomed"): (1005, 88250359),
    ("stairs", "robot5", "zoomed"): (956051917,),
    ("stairs", "spider", "zoomed"): (1479478811,),
}


def _cells():
    for scenario in builtin_scenario_names():
        for creature in builtin_creature_names():
            for lod in LOD_MODES:
                yield pytest.param(scenario, creature, lod, id=f"{scenario}-{creature}-{lod}")


@pytest.mark.slow
@pytest.mark.parametrize("scenario, creature, lod", list(_cells()))
def test_a_long_crowded_run_keeps_every_safety_promise(scenario, creature, lod):
    known = KNOWN.get((scenario, creature), {})
    salt = sum(map(ord, f"{scenario}/{creature}/{lod}"))
    failures, tolerated = [], []
    fixed = FIXED_SEEDS.get((scenario, creature, lod), ())
    for seed in fresh_seeds(() if known else fixed, 1, salt=salt):
        run = run_one({"scenario": scenario, "creature": creature, "seed": seed, "characters": CHARACTERS,
                       "frames": FRAMES, "lod": lod})
        broken = {name: run["violations"][name] for name in SAFETY if run["violations"][name]}
        where = f"seed {seed}: {broken} -- replay: {replay_command(run)}"
        if set(broken) - set(known):
            failures.append(where)
        elif broken:
            tolerated.append(f"{where} -- known, not fixed yet: {'; '.join(sorted({known[n] for n in broken}))}")
    for where in tolerated:
        warnings.warn(where, stacklevel=1)
    assert not failures, "\n".join(failures)
