"""Tests of the ``scenarios`` package: built-ins, file formats, geometry helpers, errors."""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from footfall import scenarios
from footfall._errors import InputError
from footfall.scenarios import (
    Camera,
    CrateRecipe,
    Creature,
    CrowdSpawn,
    Heightfield,
    Obstacles,
    Scenario,
    builtin_creature_names,
    builtin_scenario_names,
    flat_heightfield,
    hills_heightfield,
    load_creature,
    load_scenario,
    random_crates,
    stairs_heightfield,
)

SCENARIO_NAMES = ("crates", "crates-moving", "flat", "hills", "mixed", "stairs")
CREATURE_LEGS = {
    "spider": ("L1", "L2", "L3", "L4", "R1", "R2", "R3", "R4"),
    "ant": ("L1", "L2", "L3", "R1", "R2", "R3"),
    "quadruped": ("LF", "RF", "LH", "RH"),
    "robot5": ("leg0", "leg1", "leg2", "leg3", "leg4"),
}

# A small valid scenario; tests break one thing at a time.
MINIMAL = """\
name = "tiny"
seed = 1

[terrain]
kind = "flat"
size = [4.0, 4.0]
cell_size = 0.1

[crowd]
creature = "spider"
centre = [-1.0, 0.0]
goal = [1.5, 0.0]
"""

HEIGHTMAP_TERRAIN = """\
[terrain]
kind = "heightmap"
file = "{file}"
cell_size = 0.5
height_scale = {scale}
"""

MINIMAL_CREATURE = """\
name = "stick"
standing_height = 0.1
body_thickness = 0.03
body_box = [0.1, 0.06]
foot = {{ length = 0.02, width = 0.01 }}

[leg_defaults]
segments = [0.1, 0.1]
joint_limits = [[-1.0, 1.0], [0.0, 2.0]]

{legs}
"""

THREE_LEGS = """\
[[legs]]
name = "a"
hip = [0.05, 0.0, 0.03]
rest_foot = [0.1, 0.16]

[[legs]]
name = "b"
hip = [0.05, 0.0, -0.03]
rest_foot = [0.1, -0.16]

[[legs]]
name = "c"
hip = [-0.05, 0.0, 0.0]
rest_foot = [-0.15, 0.0]
"""


@pytest.fixture(scope="module")
def builtins() -> dict[str, Scenario]:
    return {name: load_scenario(name) for name in builtin_scenario_names()}


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def raises_input_error(load, source: Path | str, field: str) -> InputError:
    """Run ``load(source)``; check it raises a one-line InputError naming the file and ``field``."""
    with pytest.raises(InputError) as caught:
        load(source)
    message = str(caught.value)
    assert "\n" not in message
    assert str(source) in message, message
    assert field in message, message
    assert caught.value.field.startswith(field), message
    return caught.value


def minimal_with_heightmap(tmp_path: Path, file: str, scale: float = 1.0) -> Path:
    terrain = HEIGHTMAP_TERRAIN.format(file=file, scale=scale)
    text = MINIMAL.replace('[terrain]\nkind = "flat"\nsize = [4.0, 4.0]\ncell_size = 0.1\n', terrain)
    text = text.replace("centre = [-1.0, 0.0]", "centre = [0.0, 0.0]").replace("goal = [1.5, 0.0]", "goal = [0.5, 0.25]")
    return write(tmp_path / "map.toml", text)


def all_arrays(value) -> list[np.ndarray]:
    found = []
    for f in dataclasses.fields(value):
        item = getattr(value, f.name)
        if isinstance(item, np.ndarray):
            found.append(item)
        elif isinstance(item, tuple):
            found.extend(x for x in item if isinstance(x, np.ndarray))
        elif dataclasses.is_dataclass(item):
            found.extend(all_arrays(item))
    return found


# --------------------------------------------------------------------------- built-ins


def test_builtin_names_are_sorted_and_complete():
    assert builtin_scenario_names() == SCENARIO_NAMES
    assert builtin_creature_names() == tuple(sorted(CREATURE_LEGS))
    assert scenarios.DEFAULT_SCENARIO in builtin_scenario_names()


@pytest.mark.parametrize("name", SCENARIO_NAMES)
def test_builtin_scenario_loads(builtins, name):
    scenario = builtins[name]
    assert scenario.name == name
    assert scenario.source == f"builtin:{name}"
    assert isinstance(scenario.terrain, Heightfield)
    assert isinstance(scenario.obstacles, Obstacles)
    assert isinstance(scenario.crowd, CrowdSpawn)
    assert isinstance(scenario.camera, Camera)
    (x0, x1), (z0, z1) = scenario.terrain.x_range, scenario.terrain.z_range
    assert x1 - x0 >= 19.9 and z1 - z0 >= 19.9
    assert scenario.terrain.cell_size <= 0.05
    assert load_creature(scenario.crowd.creature).n_legs >= 1


def test_builtin_scenario_contents(builtins):
    assert len(builtins["flat"].obstacles) == 0
    assert np.ptp(builtins["flat"].terrain.heights) == 0.0
    assert 0.2 <= np.ptp(builtins["hills"].terrain.heights) <= 0.5
    assert builtins["stairs"].terrain.cell_size < 0.05
    crates = builtins["crates"].obstacles
    assert 20 <= len(crates) <= 30 and crates.is_static.all()
    assert crates.forbidden.any() and not crates.forbidden.all()
    assert crates.sizes.min() >= 0.08 and crates.sizes.max() <= 0.6
    assert crates.sizes[~crates.forbidden, 1].max() <= 0.2  # safe crates are low enough to step on
    for name in ("crates-moving", "mixed"):
        boxes = builtins[name].obstacles
        moving = ~boxes.is_static
        assert 0.25 <= moving.mean() <= 0.4, name
        speeds = np.where(boxes.motion_kind == 1, np.linalg.norm(boxes.velocities, axis=1), boxes.waypoint_speed)
        assert np.all((speeds[moving] >= 0.1) & (speeds[moving] <= 0.4)), name
    assert set(builtins["crates-moving"].obstacles.motion_kind) == {0, 1, 2}
    assert np.ptp(builtins["mixed"].terrain.heights) > 0.2


@pytest.mark.parametrize("name", SCENARIO_NAMES)
def test_builtin_boxes_rest_on_terrain_and_spawn_is_clear(builtins, name):
    scenario = builtins[name]
    boxes, terrain = scenario.obstacles, scenario.terrain
    bottoms = boxes.centres[:, 1] - 0.5 * boxes.sizes[:, 1]
    np.testing.assert_allclose(bottoms, terrain.height_at(boxes.centres[:, 0], boxes.centres[:, 2]), atol=1e-9)
    creature = load_creature(scenario.crowd.creature)
    clear = scenario.crowd.radius + creature.rest_radius
    reach = np.hypot(*(boxes.centres[:, [0, 2]] - scenario.crowd.centre).T) - 0.5 * np.hypot(boxes.sizes[:, 0], boxes.sizes[:, 2])
    assert np.all(reach >= clear), name
    for i in np.flatnonzero(boxes.motion_kind == 2):
        np.testing.assert_array_equal(boxes.waypoints[i][0], boxes.centres[i])


@pytest.mark.parametrize("name", sorted(CREATURE_LEGS))
def test_builtin_creature_loads(name):
    creature = load_creature(name)
    assert creature.name == name
    assert creature.leg_names == CREATURE_LEGS[name]
    n = creature.n_legs
    s = creature.n_segments
    assert creature.hips.shape == (n, 3)
    assert creature.segment_lengths.shape == (n, s) and s >= 2
    assert creature.joint_limits.shape == (n, s, 2)
    assert creature.rest_feet.shape == (n, 2)
    assert creature.body_box.shape == (2,)
    assert creature.max_reach == pytest.approx(creature.leg_reach.max())
    feet = np.column_stack([creature.rest_feet[:, 0], np.full(n, -creature.standing_height), creature.rest_feet[:, 1]])
    assert np.all(np.linalg.norm(feet - creature.hips, axis=1) <= 0.98 * creature.leg_reach)
    # Left legs (lateral > 0) on the left: every creature is left/right symmetric.
    mirrored = creature.rest_feet * [1.0, -1.0]
    assert all(np.min(np.linalg.norm(creature.rest_feet - m, axis=1)) < 1e-6 for m in mirrored)


@pytest.mark.parametrize("name", sorted(CREATURE_LEGS))
def test_builtin_rest_poses_respect_joint_limits(name):
    """Under the README's planar convention, some joint angles within limits put each foot at its rest spot."""
    creature = load_creature(name)
    rng = np.random.default_rng(0)
    feet = np.column_stack([creature.rest_feet[:, 0], np.full(creature.n_legs, -creature.standing_height),
                            creature.rest_feet[:, 1]])
    for leg in range(creature.n_legs):
        offset = feet[leg] - creature.hips[leg]
        outward, down = np.hypot(offset[0], offset[2]), offset[1]
        limits = creature.joint_limits[leg]
        angles = np.cumsum(rng.uniform(limits[:, 0], limits[:, 1], (40_000, creature.n_segments)), axis=1)
        lengths = creature.segment_lengths[leg]
        reached_out = (np.cos(angles) * lengths).sum(axis=1)
        reached_down = (-np.sin(angles) * lengths).sum(axis=1)
        assert np.hypot(reached_out - outward, reached_down - down).min() < 0.005, creature.leg_names[leg]


def test_builtin_creature_sizes():
    spider = load_creature("spider")
    assert (spider.n_segments, spider.standing_height) == (4, 0.12)
    assert np.all((np.linalg.norm(spider.rest_feet, axis=1) >= 0.29) & (np.linalg.norm(spider.rest_feet, axis=1) <= 0.36))
    assert (spider.foot_length, spider.foot_width) == (0.03, 0.02)
    assert load_creature("ant").max_reach == pytest.approx(0.21)
    quadruped = load_creature("quadruped")
    assert quadruped.standing_height == 0.45
    assert np.all(np.hypot(*(quadruped.rest_feet - quadruped.hips[:, [0, 2]]).T) < 0.05)  # legs nearly vertical
    robot = load_creature("robot5")
    angles = np.sort(np.arctan2(robot.hips[:, 2], robot.hips[:, 0]) % (2 * math.pi))
    np.testing.assert_allclose(np.diff(angles), 2 * math.pi / 5, atol=1e-3)


def test_readme_example_loads(tmp_path):
    text = (Path(scenarios.__file__).parent / "README.md").read_text()
    example = re.findall(r"```toml\n(.*?)```", text, re.S)[0]
    scenario = load_scenario(write(tmp_path / "example.toml", example))
    assert scenario.name == "example"
    assert len(scenario.obstacles) == 26
    np.testing.assert_array_equal(scenario.crowd.route, [[0.0, 2.0], [5.0, 0.0]])


# --------------------------------------------------------------------------- immutability and determinism


def test_everything_is_read_only(builtins):
    scenario = builtins["crates-moving"]
    arrays = all_arrays(scenario) + all_arrays(load_creature("spider"))
    assert len(arrays) > 15
    for array in arrays:
        assert not array.flags.writeable
        with pytest.raises(ValueError):
            array.flat[0] = 1
    with pytest.raises(dataclasses.FrozenInstanceError):
        scenario.seed = 2
    with pytest.raises(dataclasses.FrozenInstanceError):
        scenario.terrain.cell_size = 1.0


def test_constructors_copy_their_inputs():
    heights = np.zeros((2, 2))
    field = Heightfield(heights, 0.0, 0.0, 1.0)
    heights[0, 0] = 5.0
    assert field.heights[0, 0] == 0.0


@pytest.mark.parametrize("name", ["mixed", "crates-moving", "stairs"])
def test_loading_is_deterministic(builtins, tmp_path, name):
    source = Path(scenarios.__file__).parent / "data" / f"{name}.toml"
    copy = load_scenario(write(tmp_path / f"{name}.toml", source.read_text()))
    first = all_arrays(builtins[name])
    second = all_arrays(copy)
    assert len(first) == len(second)
    for a, b in zip(first, second):
        np.testing.assert_array_equal(a, b)


def test_generators_depend_on_seed_only():
    a = hills_heightfield((4.0, 4.0), 0.1, 0.4, 2.0, seed=5)
    b = hills_heightfield((4.0, 4.0), 0.1, 0.4, 2.0, seed=5)
    c = hills_heightfield((4.0, 4.0), 0.1, 0.4, 2.0, seed=6)
    np.testing.assert_array_equal(a.heights, b.heights)
    assert not np.array_equal(a.heights, c.heights)
    assert a.heights.min() == 0.0 and a.heights.max() == pytest.approx(0.4)
    terrain = flat_heightfield((10.0, 10.0), 0.1)
    recipe = CrateRecipe(count=12, region=(-4.0, -4.0, 4.0, 4.0), moving_fraction=0.5)
    one = random_crates(terrain, recipe, seed=9, keep_out=((0.0, 0.0, 1.0),))
    two = random_crates(terrain, recipe, seed=9, keep_out=((0.0, 0.0, 1.0),))
    for x, y in zip(all_arrays(one), all_arrays(two)):
        np.testing.assert_array_equal(x, y)
    assert np.all(np.hypot(one.centres[:, 0], one.centres[:, 2]) >= 1.0)


def test_stairs_profile():
    # Risers at d = 0, 0.5, 1.0; a 1 m top landing; down risers at 2.0, 2.5, 3.0.
    stairs = stairs_heightfield((10.0, 1.0), 0.05, rise=0.1, run=0.5, steps=3, start=0.0, landing=1.0)
    d = np.array([-0.5, 0.25, 0.75, 1.25, 1.9, 2.25, 2.75, 3.25, 4.0])
    np.testing.assert_allclose(stairs.height_at(d, 0.0), [0.0, 0.1, 0.2, 0.3, 0.3, 0.2, 0.1, 0.0, 0.0], atol=1e-12)
    turned = stairs_heightfield((1.0, 10.0), 0.05, rise=0.1, run=0.5, steps=3, direction=math.pi / 2)
    np.testing.assert_allclose(turned.height_at(0.0, d), [0.0, 0.1, 0.2, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3], atol=1e-12)


def test_crowd_initial_poses():
    crowd = CrowdSpawn("spider", 5, [1.0, 2.0], 1.5, 0.3, "fixed", 0.3, [5.0, 2.0])
    positions, headings = crowd.initial_poses(seed=0)
    assert positions.shape == (5, 2)
    np.testing.assert_array_equal(positions[0], [1.0, 2.0])
    assert np.all(np.hypot(*(positions - [1.0, 2.0]).T) <= 1.5)
    np.testing.assert_array_equal(headings, 0.3)
    randomised = dataclasses.replace(crowd, heading_mode="random")
    np.testing.assert_array_equal(randomised.initial_poses(4)[1], randomised.initial_poses(4)[1])
    np.testing.assert_array_equal(crowd.route, [[5.0, 2.0]])


# --------------------------------------------------------------------------- Heightfield


def test_height_at_is_bilinear_and_clamped():
    # heights[r, c]: rows along z (origin_z = 2.0), columns along x (origin_x = 1.0), 0.5 m cells.
    field = Heightfield(np.array([[0.0, 1.0, 2.0], [4.0, 5.0, 6.0]]), origin_x=1.0, origin_z=2.0, cell_size=0.5)
    assert field.x_range == (1.0, 2.0)
    assert field.z_range == (2.0, 2.5)
    x = np.array([1.0, 1.5, 1.25, 1.75, 1.25, 1.0, 10.0, -10.0, 1.25])
    z = np.array([2.0, 2.5, 2.0, 2.25, 2.25, 2.125, 2.5, -3.0, 99.0])
    expected = [0.0, 5.0, 0.5, 3.5, 2.5, 1.0, 6.0, 0.0, 4.5]
    np.testing.assert_array_equal(field.height_at(x, z), expected)
    assert field.height_at(1.25, 2.25).shape == ()
    assert field.height_at(np.full((2, 3), 1.5), 2.0).shape == (2, 3)
    assert np.isnan(field.height_at(np.nan, 2.0))


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(heights=np.zeros((1, 5))), "heights"),
        (dict(heights=np.zeros(4)), "heights"),
        (dict(heights=np.array([[0.0, np.nan], [0.0, 0.0]])), "heights"),
        (dict(cell_size=0.0), "cell_size"),
        (dict(origin_x=math.inf), "origin_x"),
    ],
)
def test_heightfield_validation(kwargs, field):
    arguments = dict(heights=np.zeros((2, 2)), origin_x=0.0, origin_z=0.0, cell_size=1.0) | kwargs
    with pytest.raises(InputError) as caught:
        Heightfield(**arguments)
    assert caught.value.field == field


# --------------------------------------------------------------------------- Obstacles


def test_poses_at_each_motion_kind():
    square = np.array([[0.0, 0.5, 0.0], [1.0, 0.5, 0.0], [1.0, 0.5, 1.0], [0.0, 0.5, 1.0]])
    boxes = Obstacles(
        centres=[[5.0, 0.5, 5.0], [0.0, 0.5, 0.0], [0.0, 0.5, 0.0]],
        sizes=np.ones((3, 3)),
        yaws=[0.1, 0.2, 0.3],
        forbidden=[True, False, True],
        motion_kind=[0, 1, 2],
        velocities=[[0.0, 0.0, 0.0], [0.5, 0.0, -0.25], [0.0, 0.0, 0.0]],
        waypoints=(np.zeros((0, 3)), np.zeros((0, 3)), square),
        waypoint_speed=[0.0, 0.0, 1.0],
    )
    np.testing.assert_array_equal(boxes.is_static, [True, False, False])
    for t, loop_point in [
        (0.0, [0.0, 0.5, 0.0]),
        (0.5, [0.5, 0.5, 0.0]),
        (1.5, [1.0, 0.5, 0.5]),
        (3.5, [0.0, 0.5, 0.5]),  # closing segment, back towards waypoint 0
        (4.25, [0.25, 0.5, 0.0]),  # wrapped around
        (-0.5, [0.0, 0.5, 0.5]),
    ]:
        centres, yaws = boxes.poses_at(t)
        np.testing.assert_array_equal(centres[0], [5.0, 0.5, 5.0])
        np.testing.assert_allclose(centres[1], [0.5 * t, 0.5, -0.25 * t], atol=1e-15)
        np.testing.assert_allclose(centres[2], loop_point, atol=1e-12)
        np.testing.assert_array_equal(yaws, [0.1, 0.2, 0.3])
    # Fresh arrays: the stored centres do not move.
    boxes.poses_at(7.0)[0][:] = 99.0
    np.testing.assert_array_equal(boxes.centres[1], [0.0, 0.5, 0.0])


def test_obstacles_defaults_and_empty():
    boxes = Obstacles([[1.0, 0.1, 2.0]], [[0.2, 0.2, 0.2]], [0.0], [True])
    assert len(boxes) == 1 and boxes.is_static.all()
    assert boxes.waypoints[0].shape == (0, 3)
    empty = Obstacles.empty()
    assert len(empty) == 0
    centres, yaws = empty.poses_at(1.0)
    assert centres.shape == (0, 3) and yaws.shape == (0,)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (dict(sizes=[[0.2, -0.1, 0.2]]), "sizes[0]"),
        (dict(motion_kind=[2], waypoint_speed=[1.0], waypoints=(np.array([[1.0, 0.1, 2.0]]),)), "waypoints[0]"),
        (dict(motion_kind=[2], waypoint_speed=[1.0], waypoints=(np.array([[0.0, 0.1, 0.0], [1.0, 0.1, 2.0]]),)),
         "waypoints[0]"),
        (dict(velocities=[[1.0, 0.0, 0.0]]), "velocities[0]"),
        (dict(motion_kind=[3]), "motion_kind[0]"),
    ],
)
def test_obstacles_validation(change, field):
    arguments = dict(centres=[[1.0, 0.1, 2.0]], sizes=[[0.2, 0.2, 0.2]], yaws=[0.0], forbidden=[True]) | change
    with pytest.raises(InputError) as caught:
        Obstacles(**arguments)
    assert caught.value.field == field


# --------------------------------------------------------------------------- malformed scenario files


def test_minimal_file_loads(tmp_path):
    scenario = load_scenario(write(tmp_path / "ok.toml", MINIMAL))
    assert scenario.name == "tiny" and scenario.source == str(tmp_path / "ok.toml")
    assert len(scenario.obstacles) == 0
    assert scenario.camera.fov == pytest.approx(0.9)


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda t: t + "colour = 3\n", "crowd.colour"),  # unknown key (in the last table, [crowd])
        (lambda t: "colour = 3\n" + t, "colour"),
        (lambda t: t.replace("cell_size = 0.1", "cell_size = 0.1\nbumpiness = 2"), "terrain.bumpiness"),
        (lambda t: t.replace("cell_size = 0.1", 'cell_size = "fine"'), "terrain.cell_size"),  # wrong type
        (lambda t: t.replace("seed = 1", "seed = 1.5"), "seed"),
        (lambda t: t.replace("cell_size = 0.1", "cell_size = true"), "terrain.cell_size"),
        (lambda t: t + "[[obstacles]]\ncentre = [1.0, 1.0]\nsize = [0.2, -0.1, 0.2]\n", "obstacles[0].size"),
        (lambda t: t.replace("goal = [1.5, 0.0]", "goal = [nan, 0.0]"), "crowd.goal"),
        (lambda t: t.replace("cell_size = 0.1", "cell_size = inf"), "terrain.cell_size"),
        (lambda t: t.replace('kind = "flat"', 'kind = "lava"'), "terrain.kind"),
        (lambda t: t.replace('"spider"', '"dragon"'), "crowd.creature"),  # unknown creature name
        (lambda t: t.replace('"spider"', '"bugs/dragon.toml"'), "crowd.creature"),
        (lambda t: t.replace("goal = [1.5, 0.0]", "goal = [9.0, 0.0]"), "crowd.goal"),
        (lambda t: t.replace("goal = [1.5, 0.0]", "goal = [1.5, 0.0]\nspawn_clear_s = -1.0"), "crowd.spawn_clear_s"),
        (lambda t: t.split("[crowd]")[0], "crowd"),
        (lambda t: t + "x = = 1\n", "scenario"),  # TOML syntax
        (lambda t: t + "[[obstacles]]\ncentre = [-0.9, 0.0]\nsize = [0.2, 0.2, 0.2]\n", "obstacles[0].centre"),
        (lambda t: t + "[[obstacles]]\ncentre = [1.0, 1.0]\nsize = [0.2, 0.1, 0.2]\nmotion = { kind = 'hop' }\n",
         "obstacles[0].motion.kind"),
        (lambda t: t + "[[obstacles]]\ncentre = [1.0, 1.0]\nsize = [0.2, 0.1, 0.2]\n"
         "motion = { kind = 'velocity', velocity = [1.0] }\n", "obstacles[0].motion.velocity"),
        (lambda t: t + "[[obstacles]]\ncentre = [1.0, 1.0]\nsize = [0.2, 0.1, 0.2]\n"
         "motion = { kind = 'waypoints', points = [[1.0, 1.0]], speed = 0.2 }\n", "obstacles[0].motion.points"),
        (lambda t: t + "[obstacles_random]\ncount = 400\n", "obstacles_random.count"),
        (lambda t: t + "[obstacles_random]\ncount = 3\nheight_range = [0.5, 0.1]\n", "obstacles_random.height_range"),
        (lambda t: t + "[camera]\nposition = [0.0, 1.0, 0.0]\ntarget = [1.0, 0.0, 0.0]\nfov = 4.0\n", "camera.fov"),
        (lambda t: t + "[camera]\nposition = [0.0, 1.0, 0.0]\ntarget = [0.0, 1.0, 0.0]\n", "camera.target"),
    ],
)
def test_malformed_scenario(tmp_path, edit, field):
    path = write(tmp_path / "bad.toml", edit(MINIMAL))
    raises_input_error(load_scenario, path, field)


def test_unknown_scenario_name_lists_builtins():
    error = raises_input_error(load_scenario, "no-such-scenario", "scenario")
    assert "built-ins are: crates, crates-moving, flat, hills, mixed, stairs" in str(error)
    raises_input_error(load_scenario, "missing/file.toml", "scenario")


def test_errors_of_builtins_name_the_builtin():
    with pytest.raises(InputError) as caught:
        load_creature("dragon")
    assert str(caught.value).startswith("dragon: creature: unknown creature; built-ins are: ant,")


# --------------------------------------------------------------------------- height maps


def test_npy_heightmap(tmp_path):
    heights = np.arange(12, dtype=np.float32).reshape(3, 4)
    np.save(tmp_path / "terrain.npy", heights)
    terrain = load_scenario(minimal_with_heightmap(tmp_path, "terrain.npy", scale=0.5)).terrain
    np.testing.assert_array_equal(terrain.heights, 0.5 * heights)
    assert terrain.cell_size == 0.5
    assert terrain.x_range == (-0.75, 0.75) and terrain.z_range == (-0.5, 0.5)
    assert terrain.height_at(-0.75, 0.5) == 0.5 * heights[2, 0]


def test_png16_heightmap_round_trip(tmp_path):
    values = (np.arange(12).reshape(3, 4) * 5000).astype(np.uint16)
    image = Image.fromarray(values)
    assert image.mode == "I;16"
    image.save(tmp_path / "terrain.png")
    terrain = load_scenario(minimal_with_heightmap(tmp_path, "terrain.png", scale=2.0)).terrain
    np.testing.assert_allclose(terrain.heights, values / 65535.0 * 2.0, rtol=0, atol=1e-12)
    assert terrain.heights.shape == (3, 4)


def test_missing_heightmap_file(tmp_path):
    raises_input_error(load_scenario, minimal_with_heightmap(tmp_path, "nowhere.npy"), "terrain.file")


def test_heightmap_with_nan(tmp_path):
    np.save(tmp_path / "terrain.npy", np.array([[0.0, 1.0], [np.nan, 2.0]]))
    error = raises_input_error(load_scenario, minimal_with_heightmap(tmp_path, "terrain.npy"), "terrain.file")
    assert "NaN" in error.reason


@pytest.mark.parametrize(
    "array",
    [np.zeros(5), np.zeros((1, 4)), np.zeros((2, 2, 2)), np.zeros((2, 2), dtype=bool), np.zeros((2, 2), dtype=complex)],
)
def test_heightmap_wrong_shape_or_dtype(tmp_path, array):
    np.save(tmp_path / "terrain.npy", array)
    raises_input_error(load_scenario, minimal_with_heightmap(tmp_path, "terrain.npy"), "terrain.file")


def test_heightmap_8bit_png(tmp_path):
    Image.fromarray(np.zeros((3, 3), dtype=np.uint8)).save(tmp_path / "terrain.png")
    error = raises_input_error(load_scenario, minimal_with_heightmap(tmp_path, "terrain.png"), "terrain.file")
    assert "16-bit" in error.reason


def test_heightmap_not_a_png(tmp_path):
    write(tmp_path / "terrain.png", "hello")
    raises_input_error(load_scenario, minimal_with_heightmap(tmp_path, "terrain.png"), "terrain.file")


# --------------------------------------------------------------------------- creature files


def test_creature_file_loads_and_scenario_can_use_it(tmp_path):
    path = write(tmp_path / "stick.toml", MINIMAL_CREATURE.format(legs=THREE_LEGS))
    creature = load_creature(path)
    assert creature.leg_names == ("a", "b", "c") and creature.n_segments == 2
    scenario_text = MINIMAL.replace('"spider"', '"stick.toml"')
    scenario = load_scenario(write(tmp_path / "uses.toml", scenario_text))
    assert load_creature(scenario.crowd.creature).name == "stick"


@pytest.mark.parametrize(
    ("legs", "field", "reason"),
    [
        ("", "legs", "creature needs at least one leg"),
        (THREE_LEGS.replace("rest_foot = [0.1, 0.16]", "rest_foot = [0.1, 0.9]"), "legs[0].rest_foot",
         "rest foot out of reach"),
        (THREE_LEGS.replace('name = "b"', 'name = "a"'), "legs[1].name", "duplicate"),
        (THREE_LEGS + "segments = [0.1, 0.1, 0.1]\n", "legs[2].segments", "same number of segments"),
        (THREE_LEGS + "joint_limits = [[1.0, -1.0], [0.0, 1.0]]\n", "legs[2].joint_limits[0]", "min must be < max"),
        (THREE_LEGS + "elbow = 3\n", "legs[2].elbow", "unknown key"),
        (THREE_LEGS.replace("hip = [0.05, 0.0, 0.03]", "hip = [0.05, 0.0]"), "legs[0].hip", "at least 3"),
    ],
)
def test_malformed_creature(tmp_path, legs, field, reason):
    path = write(tmp_path / "creature.toml", MINIMAL_CREATURE.format(legs=legs))
    error = raises_input_error(load_creature, path, field)
    assert reason in error.reason


def test_creature_with_zero_legs_in_scenario_names_the_creature_file(tmp_path):
    write(tmp_path / "legless.toml", MINIMAL_CREATURE.format(legs=""))
    path = write(tmp_path / "s.toml", MINIMAL.replace('"spider"', '"legless.toml"'))
    with pytest.raises(InputError) as caught:
        load_scenario(path)
    assert caught.value.file == str(tmp_path / "legless.toml") and caught.value.field == "legs"


def test_creature_constructor_validation():
    spider = load_creature("spider")
    with pytest.raises(InputError) as caught:
        dataclasses.replace(spider, standing_height=0.5)  # feet now far below the hips
    assert caught.value.field.startswith("rest_feet[")
    with pytest.raises(InputError):
        dataclasses.replace(spider, leg_names=(), hips=np.zeros((0, 3)))
    assert isinstance(spider, Creature)


def test_a_variant_replaces_values_of_the_file_in_memory():
    base = load_scenario("hills")
    other = load_scenario("hills@seed=3")
    assert other.seed == 3 and base.seed != 3
    # Another terrain from the same generator: same kind and size, other heights.
    assert other.terrain.heights.shape == base.terrain.heights.shape
    assert not np.array_equal(other.terrain.heights, base.terrain.heights)
    again = load_scenario(scenarios.variant_name("hills", seed=3))
    assert np.array_equal(again.terrain.heights, other.terrain.heights)
    fast = load_scenario(scenarios.variant_name("hills", seed=3, crowd__speed=0.125))
    assert fast.crowd.speed == 0.125 and np.array_equal(fast.terrain.heights, other.terrain.heights)
    assert scenarios.split_variant("flat@crowd.speed=0.5,seed=2") == ("flat", {"crowd.speed": 0.5, "seed": 2})


@pytest.mark.parametrize("spec, field", [("hills@seed", "scenario"), ("hills@nope.x=1", "nope.x"),
                                         ("hills@crowd.speed=-1", "crowd.speed"), ("hills@seed=abc", "scenario"),
                                         ("hills@crowd.bogus=1", "bogus"), ("lava@seed=1", "scenario")])
def test_a_bad_variant_names_the_field(spec, field):
    with pytest.raises(InputError) as info:
        load_scenario(spec)
    assert field in info.value.field and spec.split("@")[0] in str(info.value)


def test_an_ant_foot_before_a_riser_of_the_builtin_stairs_lands_where_it_prefers():
    # The first riser is at x = -2.0, the lower tread at height 0. An ant foot 10 cm before it prefers a
    # footprint 3.5 cm before it (a 6.5 cm stride; the ant's planner cells are 4 cm, cell [-2.04, -2.0) the
    # last before the riser). A heightfield ramps a riser over one of its cells: at the built-in 1 cm the
    # cell [-2.08, -2.04) is flat and the foot lands in it, on the tread, within a quarter cell of its
    # preference.
    # At 2.5 cm the ramp (-2.025 to -2.0) raised the sample of the cell before the riser to 1.4 cm, the
    # dilation made the next cell back slope 0.34 rad: the foot landed a cell short (-2.08; in the crowd, also
    # on the riser's dilated top, 7 cm up in the air beside it), and the ant's strides across every riser
    # were 40-75 % off the law.
    from footfall.planner import FootQuery, WorldRaster, plan_foot, planner_config_for

    scenario = scenarios.load_scenario("stairs")
    ant = scenarios.load_creature("ant")
    config = planner_config_for(ant)
    world = WorldRaster.build(scenario.terrain, scenario.obstacles, config.cell_size)
    maps = world.local_maps(-2.1, 0.1, map_cells=config.map_cells)
    query = FootQuery(source=(-2.10, 0.0, 0.10), preferred=(-2.035, 0.10), hip=(-2.15, 0.18), reach_xz=0.18,
                      step_height=0.015, foot_length=0.015, foot_width=0.01, foot_yaw=0.0)
    result = plan_foot(maps, query, config=config)
    assert result.valid
    on_tread = result.target[1] == 0.0 and abs(result.target[0] + 2.035) <= config.cell_size / 4
    assert on_tread, f"the foot lands at {result.target.round(3)}"
