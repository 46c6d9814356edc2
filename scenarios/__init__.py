"""Scenario inputs of footfall: terrain, obstacles, creatures, crowd spawns and camera.

Units: metres, seconds, radians. World y is up; the ground plane is x/z.
A creature's body frame is (forward, up, lateral), lateral positive to its
left; with heading psi, world forward is (cos psi, 0, sin psi) and world
lateral is (-sin psi, 0, cos psi).

Everything here is immutable: frozen dataclasses holding read-only NumPy
arrays. Bad input raises :class:`footfall._errors.InputError`. The TOML file
formats are described in ``scenarios/README.md``.
"""

from footfall.scenarios._creatures import Creature
from footfall.scenarios._files import (
    builtin_creature_names,
    builtin_scenario_names,
    load_creature,
    load_creature_text,
    load_scenario,
    split_scenario_list,
    split_variant,
    variant_name,
)
from footfall.scenarios._gaits import (
    DEFAULT_GAIT,
    Gait,
    builtin_gait_names,
    default_gait,
    default_gait_name,
    generate_gait,
    load_gait,
    min_stance_feet,
    required_stance_feet,
)
from footfall.scenarios._generators import (
    CrateRecipe,
    flat_heightfield,
    hills_heightfield,
    random_crates,
    stairs_heightfield,
)
from footfall.scenarios._obstacles import Obstacles
from footfall.scenarios._scenario import Camera, CrowdSpawn, Scenario
from footfall.scenarios._terrain import Heightfield

DEFAULT_SCENARIO = "mixed"
"""The scenario used when none is named."""

__all__ = [
    "DEFAULT_GAIT",
    "DEFAULT_SCENARIO",
    "Camera",
    "CrateRecipe",
    "Creature",
    "CrowdSpawn",
    "Gait",
    "Heightfield",
    "Obstacles",
    "Scenario",
    "builtin_creature_names",
    "builtin_gait_names",
    "builtin_scenario_names",
    "default_gait",
    "default_gait_name",
    "generate_gait",
    "flat_heightfield",
    "hills_heightfield",
    "load_creature",
    "load_creature_text",
    "load_gait",
    "load_scenario",
    "split_scenario_list",
    "split_variant",
    "variant_name",
    "min_stance_feet",
    "random_crates",
    "required_stance_feet",
    "stairs_heightfield",
]
